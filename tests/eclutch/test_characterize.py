"""Press-rig characterization (Haramina et al. 2024, Section 4, Eq. 1, Section 5.3)."""

import numpy as np
import pandas as pd
import pytest
from hypothesis import example, given, settings, strategies as st
from hypothesis_budget import examples

import clutchlab
from clutchlab.curves import Curve, series
from clutchlab.errors import DataError, IdentificationError, ParameterError
from clutchlab.eclutch.characterize import (
    CharacterizedCurve,
    characterize,
    lever_stiffness,
    yoke_support_equivalent,
)
from clutchlab.eclutch.pressrig import simulate_lever_tests, simulate_press_test


# ---------------------------------------------------------------- laws (test helpers)
def almen(s, k=4e5, h=8e-3, t=5e-3):
    """Almen-Laszlo-type degressive diaphragm law, interior maximum at s = 5.84 mm."""
    s = np.asarray(s, dtype=float)
    return k * s * ((h - s) * (h - s / 2) + t**2) / (h**2 + t**2)


CUSHION_B = 4.0 / 0.8e-3
CUSHION_A = 6000.0 / (np.exp(4.0) - 1.0)


def cushion(s):
    """Progressive cushion (woven) spring: 0..6 kN over 0..0.8 mm."""
    return CUSHION_A * (np.exp(CUSHION_B * np.asarray(s, dtype=float)) - 1.0)


def leaf(s):
    """Linear return (leaf) spring, 2e5 N/m."""
    return 2e5 * np.asarray(s, dtype=float)


def test_almen_helper_has_an_interior_maximum():
    s = np.linspace(0, 12e-3, 1201)
    f = almen(s)
    i = int(np.argmax(f))
    assert 0 < i < s.size - 1
    # closed form of the maximum: 1.5 s^2 - 3 h s + h^2 + t^2 = 0
    h, t = 8e-3, 5e-3
    s_max = (3 * h - np.sqrt(9 * h**2 - 6 * (h**2 + t**2))) / 3
    assert s[i] == pytest.approx(s_max, abs=1e-5)


CASES = {
    # law, travel, friction_N, interior tol [% of range], hysteresis tol [N]
    "diaphragm": (almen, 12e-3, 30.0, 0.4, 3.0),
    "cushion": (cushion, 0.8e-3, 45.0, 0.6, 20.0),
    "leaf": (leaf, 5e-3, 20.0, 0.4, 3.0),
}


def noisy_record(law, travel, friction, seed=1, **kw):
    return simulate_press_test(law, travel, friction_N=friction, friction_rel=0.0, force_noise_N=3.0,
                               lvdt_noise_m=3e-6, seed=seed, **kw)


@pytest.mark.parametrize("case", sorted(CASES))
def test_characterize_recovers_known_law_from_noisy_hysteretic_record(case):
    law, travel, friction, tol_pct, tol_hw = CASES[case]
    curve = characterize(noisy_record(law, travel, friction))
    assert isinstance(curve, CharacterizedCurve) and isinstance(curve, clutchlab.Curve)
    assert curve.n_cycles == 3
    x = curve.deflection
    truth = law(x)
    span = np.ptp(truth)
    err = np.abs(curve.force - truth)
    inner = slice(3, -3)
    # averaging removes the friction (+-friction on the raw branches)
    assert err[inner].max() < tol_pct / 100 * span
    # the turning-point correction keeps the ends within the same small error
    assert err.max() < 0.01 * span
    # the curve covers the travel (shared range of the branches)
    assert x[0] < 0.01 * travel and x[-1] > 0.99 * travel
    # hysteresis half-width = imposed friction
    np.testing.assert_allclose(curve.hysteresis_half_width[inner], friction, atol=tol_hw)
    # repeatable cycles: scatter at noise level only
    assert curve.cycle_scatter[inner].max() < max(10.0, 0.005 * span)
    # evaluation between the samples also follows the law
    xm = np.linspace(x[3], x[-4], 500)
    assert np.max(np.abs(curve(xm) - law(xm))) < 1.5 * tol_pct / 100 * span


def test_plain_average_is_biased_at_the_turning_points_and_the_correction_removes_it():
    """Plain averaging ([1] Section 4) is exact only where both branches slide."""
    law, fr, rel = leaf, 40.0, 0.03
    rec = simulate_press_test(law, 5e-3, friction_N=fr, friction_rel=rel, stick_stiffness_N_per_m=2e6,
                              force_noise_N=1.0, lvdt_noise_m=1e-6, seed=6)
    plain = characterize(rec, turning_point_correction=False)
    fixed = characterize(rec)
    x = plain.deflection
    top_friction = fr + rel * law(x[-1])
    bias = plain.force - law(x)
    # upper turning point: the arriving loading branch (law + friction) dominates the mean
    assert 0.3 * top_friction < bias[-1] <= top_friction + 3.0
    # lower turning point: the arriving unloading branch (law - friction) dominates
    assert -(fr + 3.0) <= bias[0] < -0.3 * fr
    # the interior is unbiased in both
    np.testing.assert_allclose(plain.force[8:-8], law(x[8:-8]), atol=3.0)
    # corrected: the ends, too
    np.testing.assert_allclose(fixed.force, law(fixed.deflection), atol=4.0)
    np.testing.assert_allclose(fixed.force[8:-8], plain.force[8:-8], atol=1e-9)


def test_diaphragm_maximum_is_located():
    curve = characterize(noisy_record(almen, 12e-3, 30.0, seed=4), n_grid=80)
    i = int(np.argmax(curve.force))
    assert 0 < i < curve.deflection.size - 1
    assert curve.deflection[i] == pytest.approx(5.84e-3, abs=0.3e-3)
    assert curve.force[i] == pytest.approx(almen(5.84e-3), rel=0.005)


def test_friction_proportional_to_load_is_recovered():
    rec = simulate_press_test(leaf, 5e-3, friction_N=10.0, friction_rel=0.05, force_noise_N=3.0,
                              lvdt_noise_m=3e-6, seed=2)
    curve = characterize(rec)
    inner = slice(5, -5)
    x = curve.deflection[inner]
    np.testing.assert_allclose(curve.hysteresis_half_width[inner], 10.0 + 0.05 * leaf(x), atol=3.0)
    np.testing.assert_allclose(curve.force[inner], leaf(x), atol=5.0)


def test_rig_compliance_softens_the_measured_stiffness_as_in_series():
    k, c = 2e5, 1e-6   # spring 2e5 N/m, frame 1e-6 m/N -> measured 1/(1/k + c)
    rec = simulate_press_test(leaf, 4e-3, rig_compliance_m_per_N=c, friction_N=20.0, friction_rel=0.0,
                              force_noise_N=3.0, lvdt_noise_m=3e-6, seed=5)
    curve = characterize(rec)
    inner = slice(5, -5)
    slope = np.polyfit(curve.deflection[inner], curve.force[inner], 1)[0]
    assert slope == pytest.approx(1.0 / (1.0 / k + c), rel=0.005)
    assert slope < 0.9 * k


def test_recorded_displacement_is_the_deflection_axis_and_second_channel():
    rec = simulate_press_test(leaf, 3e-3, start_m=1e-3, friction_N=20.0, friction_rel=0.0, force_noise_N=2.0,
                              lvdt_noise_m=2e-6, seed=3,
                              extra={"displacement2_m": lambda x, f: x + 0.5e-3})
    c1 = characterize(rec)
    c2 = characterize(rec, channel="displacement2_m")
    assert c1.deflection[0] == pytest.approx(1e-3, abs=20e-6)
    assert c2.deflection[0] == pytest.approx(1.5e-3, abs=20e-6)
    assert c2.channel == "displacement2_m"
    np.testing.assert_allclose(c2(c1.deflection[5:-5] + 0.5e-3), c1.force[5:-5], atol=6.0)


def test_cycle_scatter_is_the_std_of_the_cycle_averages():
    rec = simulate_press_test(leaf, 2e-3, friction_N=20.0, friction_rel=0.0, force_noise_N=0.0,
                              lvdt_noise_m=0.0, samples_per_stroke=200)
    t = rec["time_s"].to_numpy()
    cycle2 = (t >= t[400]) & (t < t[800])   # samples of the second load cycle
    rec.loc[cycle2, "force_N"] *= 1.1
    curve = characterize(rec)
    x = curve.deflection[5:-5]
    f = leaf(x)
    expected = np.std(np.vstack([f, 1.1 * f, f]), axis=0, ddof=1)
    np.testing.assert_allclose(curve.cycle_scatter[5:-5], expected, rtol=0.01, atol=0.5)
    np.testing.assert_allclose(curve.force[5:-5], f * 3.1 / 3, rtol=0.005)


def test_branches_and_cycle_curves_for_plots():
    curve = characterize(noisy_record(almen, 12e-3, 30.0))
    br = curve.branches
    assert list(br.columns) == ["cycle", "branch", "time_s", "displacement_m", "force_N"]
    assert sorted(br["cycle"].unique()) == [1, 2, 3]
    assert set(br["branch"]) == {"loading", "unloading"}
    # loading lies above unloading in the middle of the travel (friction)
    mid = br[(br["displacement_m"] > 5e-3) & (br["displacement_m"] < 7e-3)]
    assert mid[mid.branch == "loading"].force_N.mean() > mid[mid.branch == "unloading"].force_N.mean() + 40
    cc = curve.cycle_curves
    assert len(cc) == 3 * curve.deflection.size
    np.testing.assert_allclose(cc.groupby("displacement_m").force_N.mean().to_numpy(), curve.force, rtol=1e-12)
    frame = curve.to_frame()
    assert list(frame.columns) == ["deflection_m", "force_N", "hysteresis_half_width_N", "cycle_scatter_N"]


def test_curve_methods_return_plain_curves():
    curve = characterize(noisy_record(leaf, 5e-3, 20.0))
    for derived in (curve.scale(2.0), curve.shift(1e-3), curve.linearize(1e-3, 4e-3), curve.as_curve(),
                    series(curve, Curve.linear(1e6))):
        assert type(derived) is Curve
    assert curve.scale(2.0)(2e-3) == pytest.approx(2 * curve(2e-3))
    assert curve.linearize(1e-3, 4e-3).stiffness(0.0) == pytest.approx(2e5, rel=0.01)
    assert curve.inverse(500.0) == pytest.approx(2.5e-3, rel=0.01)


def test_csv_with_comments_gives_the_same_curve(tmp_path):
    rec = noisy_record(leaf, 5e-3, 20.0)
    path = tmp_path / "leaf.csv"
    with open(path, "w") as fh:
        fh.write("# synthetic: clutchlab virtual press rig\n# leaf spring\n")
        rec.to_csv(fh, index=False, float_format="%.12g")
    from_file = characterize(path)
    from_frame = characterize(rec)
    assert from_file.name == "leaf"
    np.testing.assert_allclose(from_file.force, from_frame.force, rtol=1e-9, atol=1e-6)


# ---------------------------------------------------------------- bad input
def good():
    return noisy_record(leaf, 5e-3, 20.0)


def test_nan_is_rejected_naming_the_column_and_row():
    rec = good()
    rec.loc[17, "force_N"] = np.nan
    with pytest.raises(DataError, match="force_N.*row 17"):
        characterize(rec)


def test_missing_column_is_rejected():
    with pytest.raises(DataError, match="displacement_m"):
        characterize(good().drop(columns="displacement_m"))
    with pytest.raises(DataError, match="displacement2_m"):
        characterize(good(), channel="displacement2_m")


def test_unsorted_time_is_rejected_naming_the_row():
    rec = good()
    t = rec["time_s"].to_numpy().copy()
    t[100], t[101] = t[101], t[100]
    rec["time_s"] = t
    with pytest.raises(DataError, match="time_s.*row 101"):
        characterize(rec)


def test_too_short_record():
    with pytest.raises(DataError, match="too short"):
        characterize(good().iloc[:30])


def test_loading_only_record_has_no_unloading_branch():
    rec = good()
    with pytest.raises(IdentificationError, match="no unloading branch"):
        characterize(rec.iloc[:400])


def test_missing_file_and_min_cycles(tmp_path):
    with pytest.raises(DataError, match="no such file"):
        characterize(tmp_path / "absent.csv")
    with pytest.raises(IdentificationError, match="min_cycles"):
        characterize(good(), min_cycles=4)


def test_noise_does_not_create_extra_cycles():
    rec = simulate_press_test(leaf, 0.3e-3, friction_N=5.0, friction_rel=0.0, force_noise_N=3.0,
                              lvdt_noise_m=5e-6, seed=9)   # noise 1.7 % of the travel
    assert characterize(rec).n_cycles == 3


def test_record_starting_at_the_top_pairs_loading_with_the_following_unloading():
    rec = good().iloc[400:]            # starts at the upper turning point of cycle 1
    curve = characterize(rec)
    assert curve.n_cycles == 2
    assert curve.branches.groupby("cycle").branch.first().tolist() == ["loading", "loading"]
    x = curve.deflection[3:-3]
    np.testing.assert_allclose(curve.force[3:-3], leaf(x), atol=4.0)


def test_operator_pause_mid_stroke_does_not_split_a_branch():
    """A hand-turned spindle may stop: noise on a constant displacement is no reversal."""
    from clutchlab.eclutch.pressrig import spindle_stroke, stop_operator

    rng = np.random.default_rng(0)
    p = spindle_stroke(np.linspace(0, 1, 400, endpoint=False))
    paused = np.concatenate([p[:160], np.full(150, p[160]), p[160:]])
    x = 5e-3 * np.concatenate([p, 1 - p, paused, 1 - p, [0.0]])
    force = leaf(x) + stop_operator(x, 20.0, 1e7) + 3.0 * rng.standard_normal(x.size)
    rec = pd.DataFrame({"time_s": 0.01 * np.arange(x.size), "force_N": force,
                        "displacement_m": x + 3e-6 * rng.standard_normal(x.size)})
    curve = characterize(rec)
    assert curve.n_cycles == 2
    np.testing.assert_allclose(curve.force, leaf(curve.deflection), atol=4.0)
    np.testing.assert_allclose(curve.hysteresis_half_width[5:-5], 20.0, atol=2.0)


# ---------------------------------------------------------------- property tests
@settings(max_examples=examples(15), deadline=None)
@given(a=st.floats(5e4, 5e6), b_rel=st.floats(0.0, 3.0), travel=st.floats(0.5e-3, 10e-3),
       friction=st.floats(0.0, 60.0))
@example(a=50000.0, b_rel=0.0, travel=0.0005, friction=50.0)  # sticking samples leaked through a Gaussian kernel
def test_noise_free_quadratic_law_is_recovered(a, b_rel, travel, friction):
    b = b_rel * a / travel   # force = a s + b s^2, monotone
    law = lambda s: a * s + b * s * s  # noqa: E731
    rec = simulate_press_test(law, travel, friction_N=friction, friction_rel=0.0, force_noise_N=0.0,
                              lvdt_noise_m=0.0, samples_per_stroke=150, stick_stiffness_N_per_m=1e9)
    curve = characterize(rec, n_grid=40)
    span = law(travel) - law(0.0)
    inner = slice(2, -2)
    np.testing.assert_allclose(curve.force[inner], law(curve.deflection[inner]), atol=2e-4 * span + 1e-9)
    np.testing.assert_allclose(curve.hysteresis_half_width[inner], friction, atol=2e-4 * span + 1e-6)


@settings(max_examples=examples(10), deadline=None)
@given(f1=st.floats(0.0, 80.0), f2=st.floats(0.0, 80.0), seed=st.integers(0, 2**16))
def test_averaged_curve_does_not_depend_on_the_friction(f1, f2, seed):
    """The friction is symmetric on both branches, so the average is friction-free (Section 4)."""
    kw = dict(force_noise_N=3.0, lvdt_noise_m=3e-6, seed=seed, friction_rel=0.0)
    c1 = characterize(simulate_press_test(almen, 12e-3, friction_N=f1, **kw))
    c2 = characterize(simulate_press_test(almen, 12e-3, friction_N=f2, **kw))
    x = np.linspace(1e-3, 11e-3, 50)
    np.testing.assert_allclose(c1(x), c2(x), atol=3.0)


# ---------------------------------------------------------------- Eq. 1: finger stiffness
I_DS = -3.5
K_FL0 = 2e6


def finger(F):
    """Mildly nonlinear finger deflection F / k_fl(F), k_fl rising by 30 % per 1.5 kN."""
    F = np.asarray(F, dtype=float)
    return F / (K_FL0 * (1.0 + 0.3 * F / 1500.0))


LEVER_LAWS = dict(finger_law=finger, rotation_law=lambda F: -F / 1.2e6, support_law=lambda F: F / 2e7)


def true_linearised(result):
    pts = result.points[result.points.fitted]
    f = pts.force_N.to_numpy()
    return np.polyfit(finger(f), f, 1)[0]   # same force samples, exact finger deflection


def test_lever_stiffness_recovers_finger_stiffness_from_noisy_records():
    rb, rc = simulate_lever_tests(lever_ratio=I_DS, travel_m=5e-3, friction_N=20.0, friction_rel=0.01,
                                  force_noise_N=3.0, lvdt_noise_m=3e-6, seed=11, **LEVER_LAWS)
    res = lever_stiffness(rb, rc, I_DS)
    k_true = true_linearised(res)
    assert res.value == pytest.approx(k_true, rel=0.02)
    assert 0 < res.standard_error < 0.05 * res.value
    lo, hi = res.force_range
    assert lo > 0 and hi > lo
    # the finger characteristic follows the nonlinear law
    F = np.linspace(lo, hi, 50)
    np.testing.assert_allclose(res.curve.inverse(F), finger(F), rtol=0.05, atol=3e-6)
    assert "k_fl" in res.report()
    # Section 5.2 reading (force and tips of record c) gives the same here
    res_c = lever_stiffness(rb, rc, I_DS, reference="c")
    assert res_c.value == pytest.approx(k_true, rel=0.02)


def test_lever_stiffness_exact_on_noise_free_linear_data():
    rb, rc = simulate_lever_tests(lever_ratio=-4.0, travel_m=5e-3, finger_law=lambda F: F / 3e6,
                                  rotation_law=lambda F: -F / 1e6, support_law=lambda F: F / 3e7,
                                  friction_N=0.0, friction_rel=0.0, force_noise_N=0.0, lvdt_noise_m=0.0)
    res = lever_stiffness(rb, rc, -4.0, force_range=(200.0, 900.0))
    assert res.value == pytest.approx(3e6, rel=1e-9)
    assert res.force_range == (200.0, 900.0)
    assert res.standard_error < 1e-6 * res.value


def test_lever_stiffness_with_the_wrong_lever_ratio_is_wrong():
    rb, rc = simulate_lever_tests(lever_ratio=-4.0, travel_m=5e-3, finger_law=lambda F: F / 3e6,
                                  rotation_law=lambda F: -F / 1e6, support_law=lambda F: F / 3e7,
                                  friction_N=0.0, friction_rel=0.0, force_noise_N=0.0, lvdt_noise_m=0.0)
    # denominator = s_b.ds - i*s_pp.ds: with i = -3 the rotation is only partly removed
    # finger(F) + (-4 + 3) * (-F/1e6) = F (1/3e6 + 1/1e6)
    res = lever_stiffness(rb, rc, -3.0)
    assert res.value == pytest.approx(1.0 / (1 / 3e6 + 1 / 1e6), rel=1e-9)


def test_rig_compliance_lowers_the_lever_stiffness_in_series():
    c = 2e-7
    rb, rc = simulate_lever_tests(lever_ratio=-4.0, travel_m=5e-3, finger_law=lambda F: F / 3e6,
                                  rotation_law=lambda F: -F / 1e6, support_law=lambda F: F / 3e7,
                                  rig_compliance_m_per_N=c, friction_N=20.0, friction_rel=0.0,
                                  force_noise_N=3.0, lvdt_noise_m=3e-6, seed=3)
    res = lever_stiffness(rb, rc, -4.0)
    assert res.value == pytest.approx(1.0 / (1 / 3e6 + c), rel=0.02)


def test_lever_stiffness_bad_input():
    rb, rc = simulate_lever_tests(lever_ratio=I_DS, travel_m=3e-3, **LEVER_LAWS)
    with pytest.raises(ParameterError, match="lever_ratio"):
        lever_stiffness(rb, rc, 3.5)
    with pytest.raises(ParameterError, match="force_range"):
        lever_stiffness(rb, rc, I_DS, force_range=(500.0, 100.0))
    with pytest.raises(DataError, match="displacement2_m"):
        lever_stiffness(rb.drop(columns="displacement2_m"), rc, I_DS)
    with pytest.raises(IdentificationError, match="force_range"):
        lever_stiffness(rb, rc, I_DS, force_range=(1e5, 2e5))
    # Eq. 1 matches the records at equal force: a record whose force is not monotone cannot be matched
    belleville = simulate_press_test(almen, 12e-3, extra={"displacement2_m": lambda x, f: -x / 3.5})
    with pytest.raises(IdentificationError, match="not increasing"):
        lever_stiffness(rb, belleville, I_DS)


# ---------------------------------------------------------------- Model 3: yoke support
def test_yoke_support_two_linear_springs_in_series_beyond_the_measured_range():
    k1, k2 = 5e7, 4e6
    ring = Curve.linear(k1, span=(0.0, 40e-6))     # measured up to 2 kN
    spring = Curve.linear(k2, span=(0.0, 0.5e-3))  # measured up to 2 kN
    eq = yoke_support_equivalent(ring, spring, max_force_N=12e3)
    assert type(eq) is Curve and eq.name == "yoke support (eq.)"
    assert eq.force[-1] == pytest.approx(12e3)
    x = np.array([1e-3, 2e-3, eq.deflection[-1]])
    np.testing.assert_allclose(eq.stiffness(x), 1.0 / (1 / k1 + 1 / k2), rtol=1e-9)
    assert eq.inverse(10e3) == pytest.approx(10e3 / k1 + 10e3 / k2, rel=1e-9)


def test_yoke_support_nonlinear_components_and_end_slope():
    ring = Curve.from_function(lambda s: 5e7 * s + 2e12 * s**2, np.linspace(0, 40e-6, 21), name="ring")
    spring = Curve.from_function(lambda s: 3e6 * s * (1 + 200 * s), np.linspace(0, 0.6e-3, 21), name="spring")
    eq = yoke_support_equivalent(ring, spring, max_force_N=8e3)
    F = np.linspace(100.0, 1800.0, 9)
    np.testing.assert_allclose(eq.inverse(F), ring.inverse(F) + spring.inverse(F), rtol=2e-3)
    # series() covers the union of the force ranges (each spring extrapolated by its end slope);
    # beyond it: straight continuation up to max_force_N
    top = max(ring.force[-1], spring.force[-1])
    assert eq.force[-1] == pytest.approx(8e3)
    beyond = eq.force >= top
    assert beyond.sum() >= 3
    slopes = np.diff(eq.force[beyond]) / np.diff(eq.deflection[beyond])
    np.testing.assert_allclose(slopes, slopes[0], rtol=1e-9)
    # the end slope is the series stiffness at the top of the range (within the fit window)
    assert slopes[0] == pytest.approx(eq.stiffness(eq.inverse(top) - 1e-9), rel=0.05)


def test_yoke_support_from_characterized_records_and_bad_input():
    ring_law = lambda s: 5e7 * np.asarray(s)        # noqa: E731
    spring_law = lambda s: 4e6 * np.asarray(s)      # noqa: E731
    kw = dict(friction_N=10.0, friction_rel=0.0, force_noise_N=3.0, lvdt_noise_m=0.3e-6, seed=2)
    ring = characterize(simulate_press_test(ring_law, 60e-6, **kw), n_grid=25)
    spring = characterize(simulate_press_test(spring_law, 0.75e-3, **kw), n_grid=25)
    eq = yoke_support_equivalent(ring, spring, max_force_N=10e3)
    assert eq(eq.inverse(9e3)) == pytest.approx(9e3)
    assert eq.stiffness(eq.deflection[-1]) == pytest.approx(1 / (1 / 5e7 + 1 / 4e6), rel=0.03)
    with pytest.raises(ParameterError, match="ring"):
        yoke_support_equivalent(np.array([1.0, 2.0]), spring)
    falling = Curve([0.0, 1e-3], [100.0, 0.0], name="falling")
    with pytest.raises(ParameterError, match="falling"):
        yoke_support_equivalent(falling, spring)


def test_yoke_support_accepts_a_noisy_ring_that_wiggles():
    """A stiff ring measured with LVDT noise may wiggle; it is made monotone (isotonic) first."""
    x = np.linspace(0.0, 40e-6, 21)
    f = 5e7 * x
    f[10] = f[11] + 5.0                      # one violation of monotonicity, 55 N
    ring = Curve(x, f, name="ring")
    spring = Curve.linear(4e6, span=(0.0, 0.5e-3))
    eq = yoke_support_equivalent(ring, spring)
    assert np.all(np.diff(eq.force) > 0)
    smooth = yoke_support_equivalent(Curve(x, 5e7 * x), spring)
    F = np.linspace(100.0, 1900.0, 20)
    np.testing.assert_allclose(eq.inverse(F), smooth.inverse(F), atol=2e-6)


def test_characterized_curve_validates_its_statistics():
    with pytest.raises(DataError, match="hysteresis_half_width"):
        CharacterizedCurve([0.0, 1.0], [0.0, 1.0], hysteresis_half_width=[1.0, 2.0, 3.0])
    plain = CharacterizedCurve([0.0, 1.0], [0.0, 1.0])
    np.testing.assert_array_equal(plain.cycle_scatter, [0.0, 0.0])
    with pytest.raises(ValueError):
        plain.hysteresis_half_width[0] = 1.0   # read-only, like the samples


def test_yoke_support_is_computed_once_per_content():
    """Building model variants reuses the series sum: the same curves (by content: the bundled curves are read
    anew by every preset) give the same object, other contents or arguments a new result, and a result from
    memory equals a fresh computation."""
    import importlib

    ch = importlib.import_module("clutchlab.eclutch.characterize")   # (the package exports a function of that name)
    ring = Curve.linear(5e7, span=(0.0, 40e-6))
    spring = Curve.linear(4e6, span=(0.0, 0.5e-3))
    first = yoke_support_equivalent(ring, spring, max_force_N=12e3)
    again = yoke_support_equivalent(Curve.linear(5e7, span=(0.0, 40e-6)), Curve.linear(4e6, span=(0.0, 0.5e-3)),
                                    max_force_N=12e3)
    assert again is first
    fresh = ch._yoke_support_equivalent(ring, spring, 12e3, 0.2, "yoke support (eq.)")
    np.testing.assert_array_equal(fresh.deflection, first.deflection)
    np.testing.assert_array_equal(fresh.force, first.force)
    stiffer = yoke_support_equivalent(ring.scale(2.0), spring, max_force_N=12e3)
    assert stiffer is not first and stiffer.inverse(5e3) < first.inverse(5e3)
    higher = yoke_support_equivalent(ring, spring, max_force_N=20e3)
    assert higher.force[-1] == pytest.approx(20e3) and first.force[-1] == pytest.approx(12e3)
    # Model 4 variants of the bundled curves: one series sum for all
    from clutchlab.eclutch import ClutchModel, EClutchParameters

    ch._SUPPORT_EQUIVALENTS.clear()
    a = ClutchModel.preset(4, EClutchParameters(lever_ratio=-4.0))
    b = ClutchModel.preset(4, EClutchParameters(lever_ratio=-3.9))
    assert len(ch._SUPPORT_EQUIVALENTS) == 1
    assert a.network.element("support").curve is b.network.element("support").curve
