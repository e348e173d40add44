"""Virtual manual press rig (Haramina et al. 2024, Section 4, Figs. 7-8)."""

import numpy as np
import pytest

from clutchlab.errors import ParameterError, SimulationError
from clutchlab.eclutch.pressrig import (
    RAMP_FRACTION,
    simulate_lever_tests,
    simulate_press_test,
    spindle_stroke,
    stop_operator,
)

QUIET = dict(force_noise_N=0.0, lvdt_noise_m=0.0)


def linear_law(k):
    return lambda s: k * np.asarray(s)


# ------------------------------------------------------------------ spindle motion
def test_spindle_stroke_is_smooth_monotone_and_closed():
    u = np.linspace(0.0, 1.0, 2001)
    p = spindle_stroke(u)
    assert p[0] == 0.0 and p[-1] == pytest.approx(1.0, abs=1e-15)
    assert np.all(np.diff(p) >= 0)
    v = np.gradient(p, u)
    assert abs(v[0]) < 1e-2 and abs(v[-1]) < 1e-2          # zero speed at the turning points
    mid = (u > RAMP_FRACTION + 0.01) & (u < 1 - RAMP_FRACTION - 0.01)
    np.testing.assert_allclose(v[mid], 1.0 / (1.0 - RAMP_FRACTION), rtol=1e-6)  # constant speed


def test_record_layout_rate_and_cycles():
    rec = simulate_press_test(linear_law(1e5), 4e-3, cycles=3, samples_per_stroke=200, rate_m_s=1e-3,
                              start_m=0.5e-3, friction_N=0.0, friction_rel=0.0, **QUIET)
    assert list(rec.columns) == ["time_s", "force_N", "displacement_m"]
    assert len(rec) == 2 * 3 * 200 + 1
    assert "synthetic" in rec.attrs["provenance"]
    x, t = rec["displacement_m"].to_numpy(), rec["time_s"].to_numpy()
    assert x.min() == pytest.approx(0.5e-3, abs=1e-15) and x.max() == pytest.approx(4.5e-3, rel=1e-12)
    assert np.max(np.abs(np.diff(x) / np.diff(t))) == pytest.approx(1e-3, rel=1e-9)  # spindle speed
    # three upper turning points
    tops = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:]))
    assert tops.size == 3


# ------------------------------------------------------------------ friction
def test_stop_operator_closed_form():
    x = np.concatenate([np.linspace(0, 1e-3, 101), np.linspace(1e-3, 0, 101)[1:]])
    z = stop_operator(x, 30.0, 1e6)
    # sticking: z = k*x until the limit at x = 30 um
    up = x[:101]
    np.testing.assert_allclose(z[:101], np.minimum(1e6 * up, 30.0), atol=1e-9)
    # after reversal: from +30 N down with the same stiffness, then sliding at -30 N
    down = x[101:]
    np.testing.assert_allclose(z[101:], np.maximum(30.0 - 1e6 * (1e-3 - down), -30.0), atol=1e-9)


def test_loading_and_unloading_branches_are_law_plus_minus_limit():
    law = linear_law(2e5)
    rec = simulate_press_test(law, 5e-3, cycles=2, friction_N=25.0, friction_rel=0.03,
                              stick_stiffness_N_per_m=5e7, **QUIET)
    x, f = rec["displacement_m"].to_numpy(), rec["force_N"].to_numpy()
    limit = 25.0 + 0.03 * np.abs(law(x))
    dx = np.gradient(x)
    sliding = (x > 0.5e-3) & (x < 4.5e-3)  # away from the sticking segments at the turning points
    np.testing.assert_allclose(f[sliding & (dx > 0)], (law(x) + limit)[sliding & (dx > 0)], rtol=1e-12)
    np.testing.assert_allclose(f[sliding & (dx < 0)], (law(x) - limit)[sliding & (dx < 0)], rtol=1e-12)
    assert np.all(np.abs(f - law(x)) <= limit + 1e-9)


def test_default_stick_stiffness_scales_with_the_component():
    """Default k_st = 10 x the largest tangent stiffness: sticking zone 2*limit/k_st after a reversal."""
    for k in (1e5, 1e8):
        travel = 2e3 / k        # 2 kN stroke
        rec = simulate_press_test(linear_law(k), travel, cycles=1, samples_per_stroke=4000, friction_N=30.0,
                                  friction_rel=0.0, **QUIET)
        x, f = rec["displacement_m"].to_numpy(), rec["force_N"].to_numpy()
        top = int(np.argmax(x))
        z = f[top:] - k * x[top:]
        sticking = x[top:][np.abs(z) < 30.0 - 1e-9]
        zone = x[top] - sticking.min()
        assert zone == pytest.approx(60.0 / (10 * k), rel=0.05)


def test_rig_compliance_enters_lvdt1_and_extra_channels_get_true_deflection_and_force():
    law = linear_law(3e5)
    c = 2e-8
    rec = simulate_press_test(law, 2e-3, rig_compliance_m_per_N=c, friction_N=10.0, friction_rel=0.0,
                              extra={"displacement2_m": lambda x, force: x}, **QUIET)
    f, d1, d2 = (rec[k].to_numpy() for k in ("force_N", "displacement_m", "displacement2_m"))
    np.testing.assert_allclose(d1 - d2, c * f, atol=1e-15)          # LVDT 1 = x + c*F
    assert np.all(np.abs(f - law(d2)) <= 10.0 + 1e-9)               # true deflection in the extra channel


def test_noise_levels_and_seed():
    law = linear_law(1e5)
    kw = dict(friction_N=0.0, friction_rel=0.0)
    a = simulate_press_test(law, 3e-3, force_noise_N=3.0, lvdt_noise_m=0.0, seed=7, **kw)
    exact = law(a["displacement_m"].to_numpy())
    assert np.std(a["force_N"] - exact) == pytest.approx(3.0, rel=0.1)
    b = simulate_press_test(law, 3e-3, force_noise_N=0.0, lvdt_noise_m=4e-6, seed=7, **kw)
    assert np.std(b["displacement_m"] - b["force_N"] / 1e5) == pytest.approx(4e-6, rel=0.1)
    again = simulate_press_test(law, 3e-3, force_noise_N=3.0, lvdt_noise_m=0.0, seed=7, **kw)
    other = simulate_press_test(law, 3e-3, force_noise_N=3.0, lvdt_noise_m=0.0, seed=8, **kw)
    assert a.equals(again) and not a.equals(other)


@pytest.mark.parametrize("kwargs, field", [
    (dict(travel_m=-1e-3), "travel_m"),
    (dict(cycles=0), "cycles"),
    (dict(samples_per_stroke=3), "samples_per_stroke"),
    (dict(rig_compliance_m_per_N=-1e-9), "rig_compliance_m_per_N"),
    (dict(friction_N=float("nan")), "friction_N"),
    (dict(extra={"force_N": lambda x, f: x}), "force_N"),
])
def test_bad_parameters_name_the_field(kwargs, field):
    args = dict(travel_m=1e-3)
    args.update(kwargs)
    with pytest.raises(ParameterError, match=field):
        simulate_press_test(linear_law(1e5), **args)


def test_law_returning_nan_is_a_simulation_error():
    with pytest.raises(SimulationError, match="law"):
        simulate_press_test(lambda s: np.where(s > 1e-3, np.nan, s), 2e-3)


# ------------------------------------------------------------------ lever tests (Fig. 8b-c)
def test_lever_test_kinematics():
    i_ds = -3.5
    finger = lambda F: F / 2.5e6   # noqa: E731
    rotation = lambda F: -F / 1.2e6  # noqa: E731
    support = lambda F: F / 2e7  # noqa: E731
    rb, rc = simulate_lever_tests(lever_ratio=i_ds, finger_law=finger, rotation_law=rotation,
                                  support_law=support, travel_m=4e-3, friction_N=0.0, friction_rel=0.0, **QUIET)
    f = rb["force_N"].to_numpy()
    tip = rb["displacement_m"].to_numpy()
    np.testing.assert_allclose(rc["displacement_m"], tip, atol=1e-15)     # same drive in both tests
    np.testing.assert_allclose(rc["force_N"], f, atol=1e-9)
    np.testing.assert_allclose(rb["displacement2_m"], support(f), atol=1e-12)
    np.testing.assert_allclose(rc["displacement2_m"], support(f) + rotation(f), atol=1e-12)
    # tip = support + i_ds*edge rotation + finger bending (the model behind Eq. 1)
    np.testing.assert_allclose(tip, support(f) + i_ds * rotation(f) + finger(f), atol=1e-12)
    assert tip.max() == pytest.approx(4e-3, rel=1e-12)


def test_lever_test_rejects_positive_ratio_and_wrong_rotation_sign():
    laws = dict(finger_law=lambda F: F / 2e6, support_law=lambda F: F / 2e7, travel_m=2e-3)
    with pytest.raises(ParameterError, match="lever_ratio"):
        simulate_lever_tests(lever_ratio=3.0, rotation_law=lambda F: -F / 1e6, **laws)
    # rotation with the sign of the tips and strong enough to reverse the tip motion
    with pytest.raises(SimulationError, match="not increasing"):
        simulate_lever_tests(lever_ratio=-3.0, rotation_law=lambda F: F / 1e5, **laws)
