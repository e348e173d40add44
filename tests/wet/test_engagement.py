import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.errors import ParameterError
from clutchlab.wet import (
    Bench, ParametricFriction, Scenario, WetClutch, asperity_contact_pressure, mean_film_thickness,
    nominal_separation, simulate_batch, simulate_engagement, viscous_torque, atf_viscosity,
)
from clutchlab.wet.bench import EngagementProtocol

CLUTCH = WetClutch.paper()
BENCH = Bench()
TRUTH = ParametricFriction.bench_truth()


def dyno(force=3000.0, w0=157.0, clutch=CLUTCH, bench=BENCH, duration=1.2):
    proto = EngagementProtocol(force=force, initial_slip_speed=w0, duration=duration)
    return simulate_engagement(clutch, proto.scenario(clutch, "free"), bench=bench, friction=TRUTH)


def test_inertia_dynamometer_energy_balance():
    res = dyno()
    eb = res.energy_balance()
    kinetic = 0.5 * BENCH.total_inertia * 157.0**2
    # all kinetic energy is dissipated in the clutch (no motor torque) ...
    assert eb["friction_work"] == pytest.approx(kinetic, rel=5e-3)
    # ... and goes into the pack or out to oil and housing (Eq. 8)
    assert eb["heat_into_pack"] + eb["heat_out"] == pytest.approx(kinetic, rel=5e-3)
    assert eb["heat_into_pack"] > 0 and eb["heat_out"] > 0
    kinds = [e.kind for e in res.event_list]
    assert kinds == ["contact", "lock-up"]
    t_lock = res.lockup_time
    assert t_lock == pytest.approx(res.event_list[1].time)
    after = res.time > t_lock
    assert np.all(res.state("slip_speed_rad_s")[after] == 0.0) and np.all(res.slip_stick[after] == "stick")
    assert np.all(res.state("slip_speed_rad_s")[res.time < t_lock] > 0.0)


def test_bench_engagement_mechanical_energy_balance():
    proto = EngagementProtocol()
    res = simulate_engagement(CLUTCH, proto.scenario(CLUTCH, "speed"), bench=BENCH, friction=TRUTH)
    y = res.final_state
    d_kinetic = 0.5 * BENCH.total_inertia * (y[2] ** 2 - proto.initial_slip_speed**2)
    # drive work = change of kinetic energy + friction work
    assert y[11] == pytest.approx(d_kinetic + y[8], rel=5e-3, abs=5e-3 * y[8])
    assert res.energy_balance()["residual"] == pytest.approx(0.0, abs=5e-3)
    # the motor keeps the slip on the smoothed ramp-down reference
    err = res.state("slip_speed_rad_s") - res.output("slip_reference_rad_s")
    assert np.max(np.abs(err)) < 0.05 * proto.initial_slip_speed
    assert "lock-up" in [e.kind for e in res.event_list]
    # unlike the dynamometer, the bench's motor supplies positive torque while the clutch brakes
    assert res.output("drive_torque_Nm").max() > 50.0


def test_delayed_torque_rise_from_the_squeeze_film():
    fast = dyno(clutch=CLUTCH.replace(squeeze_flow_factor=0.02))
    slow = dyno(clutch=CLUTCH.replace(squeeze_flow_factor=1.0))

    def t_load(res):  # time at which the asperities carry 1800 N of the 3000 N force
        return res.time[np.argmax(res.output("contact_force_N") > 1800.0)]

    # contact starts after the free stroke; the stiffer film delays the asperity load and the torque
    assert fast.event_list[0].kind == "contact" and fast.event_list[0].time > 0.05
    assert t_load(slow) > t_load(fast) + 0.1
    assert slow.lockup_time > fast.lockup_time + 0.05
    assert slow.output("squeeze_force_N").max() > fast.output("squeeze_force_N").max()


def test_kernel_outputs_equal_the_pure_functions():
    res = dyno()
    x = res.state("piston_position_m")
    temp = res.state("temperature_C")
    w = res.state("slip_speed_rad_s")
    h = nominal_separation(x, CLUTCH.piston_h0, CLUTCH.n_c)
    hb = mean_film_thickness(h, CLUTCH.sigma)
    np.testing.assert_allclose(res.output("nominal_separation_m"), h, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(res.output("mean_film_m"), hb, rtol=1e-12)
    tv = viscous_torque(CLUTCH.r_eff, CLUTCH.n_c, atf_viscosity(temp, *CLUTCH.viscosity), CLUTCH.friction_area,
                        CLUTCH.r_eff * w, hb)
    slip = res.slip_stick == "slip"
    np.testing.assert_allclose(res.output("viscous_torque_Nm")[slip], tv[slip], rtol=1e-10, atol=1e-12)
    fc = CLUTCH.friction_area * asperity_contact_pressure(h, CLUTCH.sigma, CLUTCH.asperity_radius,
                                                          CLUTCH.asperity_density, CLUTCH.contact_modulus)
    np.testing.assert_allclose(res.output("contact_force_N"), fc, rtol=1e-6)
    mu = TRUTH.mu(CLUTCH.r_eff * w, temp)
    tc = CLUTCH.r_eff * CLUTCH.n_c * mu * fc
    np.testing.assert_allclose(res.output("contact_torque_Nm")[slip], tc[slip], rtol=1e-6)


def test_steady_film_force_balance():
    # force held: the squeeze film dies out and load cell = spring + asperity force
    scen = Scenario([0.0, 0.2], [0.0, 2000.0], [0.0], [0.0], duration=4.0)
    res = simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, sample_rate=10.0)
    x = res.state("piston_position_m")[-1]
    spring = CLUTCH.spring_preload + CLUTCH.spring_stiffness * x
    assert res.output("contact_force_N")[-1] + spring == pytest.approx(2000.0, rel=1e-3)
    assert abs(res.output("squeeze_force_N")[-1]) < 2.0
    assert np.all(res.slip_stick == "stick")


def test_lockup_time_converges_with_tolerance():
    proto = EngagementProtocol()
    scen = proto.scenario(CLUTCH, "free")
    a = simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, rtol=1e-5).lockup_time
    b = simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, rtol=1e-10).lockup_time
    assert a == pytest.approx(b, abs=1e-4)


def test_break_away_event_when_drive_exceeds_capacity():
    # clutch pressed at standstill, then the motor is asked to turn: stick until the torque exceeds capacity
    scen = Scenario([0.0, 0.2], [0.0, 1500.0], [0.0, 1.0, 1.5], [0.0, 0.0, 20.0], duration=2.5)
    res = simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, sample_rate=200.0)
    kinds = [e.kind for e in res.event_list]
    assert "break-away" in kinds
    t_b = res.event_list[kinds.index("break-away")].time
    assert 1.0 < t_b < 2.5
    before = res.time < t_b
    assert np.all(res.state("slip_speed_rad_s")[before] == 0.0)
    # at the located event the drive torque equals the static capacity of Eq. 4
    at = simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, sample_times=[t_b])
    assert abs(at.output("drive_torque_Nm")[0]) == pytest.approx(at.output("static_capacity_Nm")[0], rel=1e-6)
    assert np.all(np.abs(res.output("drive_torque_Nm")[before]) <= res.output("static_capacity_Nm")[before] + 1e-9)


@settings(max_examples=examples(8), deadline=None)
@given(st.floats(800.0, 8000.0), st.floats(30.0, 300.0))
def test_energy_conservation_property(force, w0):
    res = dyno(force=force, w0=w0, duration=2.0)
    eb = res.energy_balance()
    # the kinetic energy lost (a light force may not lock the clutch within 2 s) is the friction work
    w_end = res.final_state[res.state_names.index("slip_speed_rad_s")]
    assert eb["friction_work"] == pytest.approx(0.5 * BENCH.total_inertia * (w0**2 - w_end**2), rel=5e-3)
    assert abs(eb["residual"]) < 5e-3
    assert np.all(res.output("friction_power_W") >= -1e-9)


def test_batch_equals_single_runs_and_conserves_energy():
    proto = EngagementProtocol(duration=1.5)
    scen = proto.scenario(CLUTCH, "free")
    inertias = np.array([0.2, 0.33, 0.5])
    batch = simulate_batch(CLUTCH, scen, {"total_inertia": inertias, "force_scale": [1.0, 1.2, 0.8]},
                           bench=BENCH, friction=TRUTH)
    assert np.all(batch.status == 0)
    np.testing.assert_allclose(batch.friction_work, 0.5 * inertias * proto.initial_slip_speed**2, rtol=5e-3)
    # a batch row equals the single run with the same parameters
    single = simulate_engagement(CLUTCH, scen, bench=BENCH.replace(motor_inertia=(0.5 - BENCH.shaft_inertia) / 4),
                                 friction=TRUTH, rtol=1e-6)
    b2 = simulate_batch(CLUTCH, scen, {"total_inertia": [0.5]}, bench=BENCH, friction=TRUTH)
    np.testing.assert_allclose(b2.samples[0, -1], single.final_state, rtol=1e-9, atol=1e-9)
    assert b2.lockup_time[0] == pytest.approx(single.lockup_time, abs=1e-9)
    assert list(batch.to_dataframe().columns)[:2] == ["total_inertia", "force_scale"]


def test_bad_input():
    with pytest.raises(ParameterError, match="force"):
        Scenario([0.0, 1.0], [0.0, -5.0], [0.0], [0.0], duration=1.0)
    with pytest.raises(ParameterError, match="increasing"):
        Scenario([0.0, 0.0], [0.0, 5.0], [0.0], [0.0], duration=1.0)
    with pytest.raises(ParameterError, match="duration"):
        Scenario([0.0], [0.0], [0.0], [0.0], duration=-1.0)
    with pytest.raises(ParameterError, match="motor"):
        Scenario([0.0], [0.0], [0.0], [0.0], duration=1.0, motor="turbo")
    fast = Scenario([0.0], [0.0], [0.0], [400.0], duration=1.0)
    with pytest.raises(ParameterError, match="speed limit"):
        simulate_engagement(CLUTCH, fast)
    strong = Scenario([0.0], [2e4], [0.0], [0.0], duration=1.0)
    with pytest.raises(ParameterError, match="16000"):
        simulate_engagement(CLUTCH, strong)
    ok = Scenario([0.0], [0.0], [0.0], [0.0], duration=1.0)
    with pytest.raises(ParameterError, match="cannot vary"):
        simulate_batch(CLUTCH, ok, {"colour": [1.0]})
    with pytest.raises(ParameterError, match="lengths"):
        simulate_batch(CLUTCH, ok, {"k1": [1.0, 2.0], "k2": [1.0]})
    with pytest.raises(ParameterError, match="friction"):
        simulate_engagement(CLUTCH, ok, friction="dry")
