"""Tests of clutchlab.Curve and the series/parallel combinations."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import clutchlab
from clutchlab import Curve
from clutchlab.curves import curve_eval, parallel, series
from clutchlab.errors import DataError, ParameterError

SETTINGS = settings(deadline=None)  # example count from the hypothesis profile (tests/conftest.py)


@st.composite
def monotone_curves(draw, increasing=True, kind=None):
    n = draw(st.integers(3, 12))
    steps_x = draw(st.lists(st.floats(1e-5, 1e-3), min_size=n - 1, max_size=n - 1))
    steps_f = draw(st.lists(st.floats(1.0, 1e3), min_size=n - 1, max_size=n - 1))
    x = np.concatenate([[draw(st.floats(-1e-3, 1e-3))], np.cumsum(steps_x)])
    x[1:] += x[0]
    f = np.concatenate([[draw(st.floats(-500, 500))], np.cumsum(steps_f)])
    f[1:] += f[0]
    if not increasing:
        f = -f
    kind = kind or draw(st.sampled_from(["linear", "pchip"]))
    return Curve(x, f, kind=kind)


def test_linear_interpolation_and_end_slope_extrapolation():
    c = Curve([0.0, 1e-3, 3e-3], [0.0, 100.0, 500.0])
    assert c(0.5e-3) == pytest.approx(50.0)
    assert c(2e-3) == pytest.approx(300.0)
    # end slopes: 1e5 N/m below, 2e5 N/m above
    assert c(-1e-3) == pytest.approx(-100.0)
    assert c(4e-3) == pytest.approx(700.0)
    assert c.stiffness(2e-3) == pytest.approx(2e5)
    np.testing.assert_allclose(c(np.array([0.0, 1e-3, 3e-3])), [0.0, 100.0, 500.0])


def test_error_extrapolation_policy():
    c = Curve([0.0, 1e-3], [0.0, 100.0], extrapolation="error", name="leaf")
    assert c(0.5e-3) == pytest.approx(50.0)
    with pytest.raises(ParameterError, match="leaf.*outside the measured range"):
        c(2e-3)
    with pytest.raises(ParameterError, match="outside"):
        c.inverse(150.0)
    xs, fs, ds, kind, extrap = c.kernel_data()
    assert np.isnan(curve_eval(xs, fs, ds, kind, extrap, 2e-3)[0])


@pytest.mark.parametrize(
    "x, f, match",
    [
        ([0.0, np.nan, 2.0], [0, 1, 2], r"deflection\[1\]"),
        ([0.0, 1.0, 2.0], [0, np.inf, 2], r"force\[1\]"),
        ([0.0, 2.0, 1.0], [0, 1, 2], "strictly increasing"),
        ([0.0, 1.0, 1.0], [0, 1, 2], "strictly increasing"),
        ([0.0], [0.0], "at least 2"),
        ([0.0, 1.0], [0.0, 1.0, 2.0], "2 deflection samples but 3"),
    ],
)
def test_bad_samples_raise_clear_errors(x, f, match):
    with pytest.raises(DataError, match=match):
        Curve(x, f, name="diaphragm")


def test_bad_options():
    with pytest.raises(ParameterError, match="kind"):
        Curve([0, 1], [0, 1], kind="spline")
    with pytest.raises(ParameterError, match="extrapolation"):
        Curve([0, 1], [0, 1], extrapolation="zero")
    with pytest.raises(ParameterError, match="scale factor"):
        Curve([0, 1], [0, 1]).scale(-2.0)


def test_pchip_reproduces_samples_and_keeps_interior_maximum():
    # Almen-Laszlo-like degressive curve with a maximum inside the travel
    x = np.linspace(0, 12e-3, 13)
    f = 4e5 * x * ((8e-3 - x) * (8e-3 - x / 2) + 25e-6) / (64e-6 + 25e-6)
    c = Curve(x, f, kind="pchip")
    np.testing.assert_allclose(c(x), f, rtol=1e-12, atol=1e-9)
    dense = np.linspace(0, 12e-3, 2001)
    # PCHIP never overshoots the data: the maximum is bounded by the sampled maximum
    assert c(dense).max() <= f.max() + 1e-9
    assert not c.is_monotone()
    with pytest.raises(ParameterError, match="not monotone"):
        c.inverse(500.0)


@SETTINGS
@given(monotone_curves(), st.floats(0.0, 1.0))
def test_compiled_kernel_matches_vectorised_evaluation(c, t):
    lo, hi = c.span
    x = lo - 1e-3 + t * (hi - lo + 2e-3)
    f, k = curve_eval(*c.kernel_data(), x)
    assert f == pytest.approx(c(x), rel=1e-12, abs=1e-9)
    assert k == pytest.approx(c.stiffness(x), rel=1e-10, abs=1e-6)


@SETTINGS
@given(monotone_curves(kind="pchip"))
def test_pchip_preserves_monotonicity(c):
    dense = np.linspace(*c.span, 997)
    assert np.all(np.diff(c(dense)) >= -1e-9)


@SETTINGS
@given(st.one_of(monotone_curves(increasing=True), monotone_curves(increasing=False)), st.floats(-0.2, 1.2))
def test_inverse_round_trip(c, t):
    lo, hi = min(c.force[0], c.force[-1]), max(c.force[0], c.force[-1])
    force = lo + t * (hi - lo)  # includes extrapolation on both sides
    x = c.inverse(force)
    assert c(x) == pytest.approx(force, rel=1e-9, abs=1e-7)


@SETTINGS
@given(monotone_curves(), monotone_curves(), st.floats(0.0, 1.0))
def test_series_adds_deflections_at_equal_force(a, b, t):
    s = series(a, b)
    lo = min(a.force[0], b.force[0])
    hi = max(a.force[-1], b.force[-1])
    force = lo + t * (hi - lo)
    expected = a.inverse(force) + b.inverse(force)
    # documented accuracy: rtol (1e-6) of the deflection range of the result, checked with a 4x margin
    span = abs((a.inverse(hi) + b.inverse(hi)) - (a.inverse(lo) + b.inverse(lo)))
    tol = 1e-9 * (span + 1e-3) if a.kind == b.kind == "linear" else 4e-6 * span + 1e-15
    assert s.inverse(force) == pytest.approx(expected, abs=tol)


@SETTINGS
@given(monotone_curves(), monotone_curves(), st.floats(0.0, 1.0))
def test_parallel_adds_forces_at_equal_deflection(a, b, t):
    p = parallel(a, b)
    lo = min(a.span[0], b.span[0])
    hi = max(a.span[1], b.span[1])
    x = lo + t * (hi - lo)
    expected = a(x) + b(x)
    # documented accuracy: rtol (1e-6) of the force range of the result, checked with a 4x margin
    span = abs((a(hi) + b(hi)) - (a(lo) + b(lo)))
    tol = 1e-9 * (span + 1.0) if a.kind == b.kind == "linear" else 4e-6 * span + 1e-12
    assert p(x) == pytest.approx(expected, abs=tol)


def test_series_and_parallel_of_linear_springs_closed_form():
    k1, k2, k3 = 2.0e5, 6.0e5, 3.0e5
    a, b, c = (Curve.linear(k) for k in (k1, k2, k3))
    s = series(a, b, c)
    k_series = 1.0 / (1 / k1 + 1 / k2 + 1 / k3)
    assert s.stiffness(0.5e-4) == pytest.approx(k_series, rel=1e-12)
    # beyond the measured range the end slope extrapolates the series law
    assert s.inverse(5e3) == pytest.approx(5e3 / k_series, rel=1e-12)
    assert parallel(a, b, c).stiffness(0.3e-3) == pytest.approx(k1 + k2 + k3, rel=1e-12)


def test_scale_shift_and_linearize():
    c = Curve.from_function(lambda x: 1e5 * x + 1e9 * x**2, np.linspace(0, 2e-3, 41))
    assert c.scale(20.0)(1e-3) == pytest.approx(20.0 * c(1e-3))
    assert c.scale(1.3).stiffness(1e-3) == pytest.approx(1.3 * c.stiffness(1e-3))
    pre = c.shift(0.5e-3)
    assert pre(0.0) == pytest.approx(c(0.5e-3))
    assert pre(0.25e-3) == pytest.approx(c(0.75e-3))
    # least-squares line of a quadratic over [a, b] has slope k + c*(a+b) (closed form)
    lin = c.linearize(0.5e-3, 1.5e-3)
    assert lin.stiffness(0.0) == pytest.approx(1e5 + 1e9 * 2e-3, rel=1e-6)
    exact = Curve.linear(3e5).linearize(0.0, 1e-3)
    assert exact.stiffness(0.7) == pytest.approx(3e5)
    with pytest.raises(ParameterError, match="empty"):
        c.linearize(1e-3, 1e-3)


def test_stiffness_matches_finite_difference():
    c = Curve.from_function(lambda x: np.sin(300 * x) * 1e3, np.linspace(0, 5e-3, 30), kind="pchip")
    x = np.linspace(0.1e-3, 4.9e-3, 50)
    h = 1e-9
    fd = (c(x + h) - c(x - h)) / (2 * h)
    np.testing.assert_allclose(c.stiffness(x), fd, rtol=1e-5, atol=1e-2)


def test_public_names():
    assert clutchlab.Curve is Curve
    assert clutchlab.curves.series is series and clutchlab.curves.parallel is parallel


def test_curve_errors_show_plain_numbers():
    """Array elements in messages read 0.002, not np.float64(0.002) (NumPy 2 repr)."""
    with pytest.raises(DataError) as info:
        Curve([0.0, 0.002, 0.002], [0.0, 1.0, 2.0], name="c")
    assert "deflection[2] = 0.002 <= deflection[1] = 0.002" in str(info.value)
    assert "np." not in str(info.value)
    with pytest.raises(ParameterError) as info:
        Curve([0.0, 1e-3], [0.0, 1.0], extrapolation="error", name="c")(np.array([0.5]))
    assert "deflection 0.5 m outside the measured range [0.0, 0.001]" in str(info.value)


def test_inverse_exact_at_a_sample_and_on_a_steep_segment():
    """Two cases hypothesis found: a force equal to the first sample's (the residual is zero at the first
    guess, which must be kept, not bisected away), and a 1e8 N/m segment, where a step bound of 1e-15 m
    left a 1e-7 N error."""
    c = Curve(np.array([0.0, 0.00079615, 0.00080615]), np.array([0.0, 1.0, 2.0]), kind="pchip")
    assert c.inverse(0.0) == 0.0
    xs = np.array([0.00064704, 0.00065704, 0.00066704, 0.00067704, 0.00068704, 0.00069704, 0.00070704,
                   0.00071704, 0.00072704, 0.00073704, 0.00074704, 0.00075704])
    fs = np.array([0.0, 940.0, 1338.0, 1339.0, 1340.0, 1341.0, 1342.0, 1343.0, 1344.0, 1345.0, 1873.0, 2873.0])
    steep = Curve(xs, fs, kind="pchip")
    force = 1.5e-5 * 2873.0
    assert abs(steep(steep.inverse(force)) - force) < 1e-9
    forces = np.linspace(1.0, 2872.0, 101)
    assert np.max(np.abs(steep(steep.inverse(forces)) - forces)) < 1e-9 * 2873.0


@pytest.mark.parametrize("kind", ["linear", "pchip"])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_the_compiled_inverse_of_one_force_is_the_curve_s_inverse(kind, sign):
    """``curve_inverse_one`` (the E-clutch's start derives pre-strains with it) equals :meth:`Curve.inverse` inside
    the samples and on the end slopes' extrapolation, for increasing and decreasing curves of both kinds; and it
    reaches the force it is asked for."""
    from clutchlab.curves import curve_inverse_one

    x = np.array([0.0, 1e-3, 2.5e-3, 4e-3, 6e-3])
    c = Curve(x, sign * np.array([0.0, 300.0, 1100.0, 1500.0, 2600.0]), kind=kind)
    xs, fs, ds, k, e = c.kernel_data()
    for force in sign * np.array([-200.0, 0.0, 150.0, 300.0, 1234.5, 2600.0, 3000.0]):
        got = curve_inverse_one(xs, fs, ds, k, e, force)
        assert got == pytest.approx(float(c.inverse(force)), rel=1e-13, abs=1e-18), force
        assert curve_eval(xs, fs, ds, k, 0, got)[0] == pytest.approx(force, rel=1e-12, abs=1e-9)


def test_the_compiled_inverse_refuses_what_the_curve_s_inverse_refuses():
    """NaN where :meth:`Curve.inverse` raises: a curve that is not monotone, a force outside the samples of a curve
    that may not be extrapolated, a force that is not finite."""
    from clutchlab.curves import curve_inverse_one

    bump = Curve([0.0, 1e-3, 2e-3], [0.0, 100.0, 50.0])
    with pytest.raises(ParameterError):
        bump.inverse(20.0)
    assert np.isnan(curve_inverse_one(*bump.kernel_data(), 20.0))
    strict = Curve([0.0, 1e-3, 2e-3], [0.0, 100.0, 150.0], extrapolation="error")
    with pytest.raises(ParameterError):
        strict.inverse(200.0)
    assert np.isnan(curve_inverse_one(*strict.kernel_data(), 200.0))
    assert curve_inverse_one(*strict.kernel_data(), 120.0) == pytest.approx(float(strict.inverse(120.0)), rel=1e-13)
    assert np.isnan(curve_inverse_one(*strict.kernel_data(), np.nan))
