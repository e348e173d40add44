import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples
from scipy import integrate, special

from clutchlab.errors import ParameterError
from clutchlab.wet import (
    WetClutch, asperity_contact_pressure, effective_radius, gw_integral, mean_film_thickness, nominal_separation,
    slip_velocity, squeeze_film_coefficient, squeeze_film_force,
)
from clutchlab.wet.film import film_scalar, gw_scalar, gw_table

SIGMA = 6e-4  # Table 1


def test_effective_radius_reproduces_table1():
    # Table 1: R_o = 83.15 mm, R_i = 71.74 mm, R_eff = 0.07758 m
    r = effective_radius(0.08315, 0.07174)
    assert r == pytest.approx(0.07758, abs=1e-5)
    assert r == pytest.approx(0.0775850866, rel=1e-9)
    # the arithmetic mean radius would not give Table 1's value
    assert abs((0.08315 + 0.07174) / 2 - 0.07758) > 1e-4


def test_effective_radius_limits_and_vectorised():
    # thin ring -> mean radius; full disk -> 2/3 R
    assert effective_radius(1.0, 0.999999) == pytest.approx(0.9999995, rel=1e-9)
    assert effective_radius(0.1, 0.0) == pytest.approx(2 / 3 * 0.1, rel=1e-12)
    out = effective_radius(np.array([0.1, 0.2]), np.array([0.05, 0.1]))
    assert out.shape == (2,)


@pytest.mark.parametrize("ro, ri", [(0.07, 0.08), (0.08, 0.08), (-0.1, 0.05), (0.1, -0.01), (float("nan"), 0.05)])
def test_effective_radius_bad_input(ro, ri):
    with pytest.raises(ParameterError):
        effective_radius(ro, ri)


def test_slip_velocity_and_nominal_separation():
    assert slip_velocity(100.0, 0.07758) == pytest.approx(7.758)
    # Eq. 1: h = (x_h0 - x_p) / N_c
    assert nominal_separation(4e-3, 12e-3, 8) == pytest.approx(1e-3)
    assert nominal_separation(14e-3, 12e-3, 8) == pytest.approx(-0.25e-3)
    with pytest.raises(ParameterError, match="n_c"):
        nominal_separation(0.0, 1e-3, 0)
    with pytest.raises(ParameterError, match="n_c"):
        nominal_separation(0.0, 1e-3, 2.5)


def test_patir_cheng_limits():
    # h >> sigma -> h_bar -> h
    assert mean_film_thickness(10 * SIGMA, SIGMA) == pytest.approx(10 * SIGMA, rel=1e-15)
    # h = 0 -> sigma / sqrt(2 pi)
    assert mean_film_thickness(0.0, SIGMA) == pytest.approx(SIGMA / math.sqrt(2 * math.pi), rel=1e-14)
    # h << 0 -> 0+ (positive, vanishingly small)
    for k in (-5, -10, -20, -30):
        hb = mean_film_thickness(k * SIGMA, SIGMA)
        assert 0.0 < hb < SIGMA * math.exp(-0.5 * k * k)
    # Mills-ratio asymptote phi(t)/t^2 for t -> -inf
    t = -20.0
    asym = SIGMA * math.exp(-0.5 * t * t) / math.sqrt(2 * math.pi) / t**2
    assert mean_film_thickness(t * SIGMA, SIGMA) == pytest.approx(asym, rel=1e-2)


def test_patir_cheng_matches_printed_formula():
    h = np.linspace(-3, 3, 61) * SIGMA
    x = h / (math.sqrt(2) * SIGMA)
    printed = h / 2 * (1 + special.erf(x)) + SIGMA / math.sqrt(2 * math.pi) * np.exp(-x**2)  # [1], Eq. 2
    np.testing.assert_allclose(mean_film_thickness(h, SIGMA), printed, rtol=1e-12, atol=1e-20)


def test_patir_cheng_is_the_gaussian_mean_of_the_gap():
    # h_bar = E[max(h - z, 0)] for z ~ N(0, sigma^2) (its definition)
    for t in (-2.0, -0.5, 0.0, 1.3):
        val = integrate.quad(lambda z: (t - z) * math.exp(-z * z / 2) / math.sqrt(2 * math.pi), -np.inf, t)[0]
        assert mean_film_thickness(t * SIGMA, SIGMA) == pytest.approx(val * SIGMA, rel=1e-9)


@settings(max_examples=examples(60), deadline=None)
@given(st.floats(-40, 40), st.floats(-40, 40))
def test_patir_cheng_monotone_and_bounded(a, b):
    lo, hi = sorted((a, b))
    h_lo, h_hi = mean_film_thickness(lo * SIGMA, SIGMA), mean_film_thickness(hi * SIGMA, SIGMA)
    assert h_lo <= h_hi
    assert h_lo >= max(lo * SIGMA, 0.0) * (1 - 1e-14)
    # compiled scalar form equals the vectorised one
    assert film_scalar(lo * SIGMA, SIGMA) == pytest.approx(h_lo, rel=1e-12, abs=1e-300)


def test_patir_cheng_bad_input():
    with pytest.raises(ParameterError, match="sigma"):
        mean_film_thickness(0.0, 0.0)
    with pytest.raises(ParameterError, match="h"):
        mean_film_thickness(float("nan"), SIGMA)


def test_gw_integral_against_quadrature():
    assert gw_integral(0.0) == pytest.approx(0.43002, abs=1e-5)  # F_3/2(0), Greenwood & Williamson
    for t in (-4.0, -1.0, 0.7, 3.0):
        q = integrate.quad(lambda s: (s - t) ** 1.5 * math.exp(-s * s / 2) / math.sqrt(2 * math.pi), t, np.inf)[0]
        assert gw_integral(t) == pytest.approx(q, rel=1e-8)


def test_gw_table_lookup_matches_closed_form():
    t0, dt, vals, ders = gw_table()
    t = np.linspace(-11.9, 7.9, 397) + 0.003
    looked = np.array([gw_scalar(x, t0, dt, vals, ders) for x in t])
    np.testing.assert_allclose(looked, gw_integral(t), rtol=1e-7, atol=1e-12)


def test_contact_pressure_scale_and_monotone():
    c = WetClutch.paper()
    h = np.linspace(-3, 3, 50) * c.sigma
    p = asperity_contact_pressure(h, c.sigma, c.asperity_radius, c.asperity_density, c.contact_modulus)
    assert np.all(np.diff(p) < 0) and np.all(p > 0)
    expected0 = 4 / 3 * c.contact_modulus * c.asperity_density * math.sqrt(c.asperity_radius) * c.sigma**1.5 * 0.4300199936610785
    assert asperity_contact_pressure(0.0, c.sigma, c.asperity_radius, c.asperity_density, c.contact_modulus) == \
        pytest.approx(expected0, rel=1e-9)
    with pytest.raises(ParameterError, match="contact_modulus"):
        asperity_contact_pressure(0.0, c.sigma, c.asperity_radius, c.asperity_density, -1.0)


def test_squeeze_film_coefficient_from_reynolds_pressure():
    ro, ri, mu, h, v = 0.08315, 0.07174, 0.01, 1e-4, -1e-3  # closing at 1 mm/s
    a = 3 * mu * (-v) / h**3
    c1 = a * (ro**2 - ri**2) / math.log(ro / ri)

    def p(r):  # Reynolds: p = a (ro^2 - r^2) - c1 ln(ro / r), zero at both rims
        return a * (ro**2 - r**2) - c1 * math.log(ro / r)

    assert abs(p(ri)) < 1e-6 * a * ro**2
    w = integrate.quad(lambda r: 2 * math.pi * r * p(r), ri, ro)[0]
    assert squeeze_film_force(h, v, mu, ro, ri) == pytest.approx(w, rel=1e-8)
    assert squeeze_film_coefficient(ro, ri) * mu * 1e-3 / h**3 == pytest.approx(w, rel=1e-8)
    # opening gives suction of the same size
    assert squeeze_film_force(h, -v, mu, ro, ri) == pytest.approx(-w, rel=1e-12)


def test_the_gw_table_is_made_where_a_kernel_is_compiled_not_at_import():
    """The compiled asperity law's Greenwood-Williamson table needs ``scipy.special`` (a quarter of a second to import,
    which every network paid once the coupled parameter type, with its wet block, became every network's): importing
    clutchlab's wet and driveline packages does not import it, and the compiled law reads the table of
    :func:`gw_table` (a fresh process)."""
    import subprocess
    import sys

    code = ("import sys, clutchlab.wet, clutchlab.driveline, clutchlab.driveline.coupled\n"
            "print('scipy.special' in sys.modules)\n"
            "from clutchlab.wet.film import asperity_force_scalar, gw_table, gw_lookup\n"
            "t0, dt, v, d = gw_table()\n"
            "want = 0.01 * 1e6 * gw_lookup.py_func(2.0, t0, dt, v, 0, d, 0, v.shape[0])\n"
            "print(asperity_force_scalar(2e-6, 1e-6, 0.01, 1e6) == want)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["False", "True"]
