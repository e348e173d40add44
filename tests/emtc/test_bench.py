"""Vehicle with EMTC on the drum bench: actuator (Eqs. 8-12, Fig. 15), mode logic (Fig. 11), Eqs. 27-30."""

import math

import numpy as np
import pytest

from clutchlab.emtc import (
    ActuatorParameters,
    BenchScenario,
    CouplingGeometry,
    VehicleParameters,
    bundled_magnet,
    load_scenario,
    locked_torques,
    simulate_bench,
    slipping_torques,
)
from clutchlab.emtc.magnet import synthetic_magnet
from clutchlab.errors import ParameterError, SimulationError


@pytest.fixture(scope="module")
def magnet():
    return bundled_magnet()


@pytest.fixture(scope="module")
def slipping_run(magnet):
    return simulate_bench(magnet, BenchScenario(duration=2.0, speed_difference=0.3, throttle_start=0.1,
                                                throttle_end=0.6, ramp_start=0.2, ramp_end=1.8))


@pytest.fixture(scope="module")
def locked_run(magnet):
    sc = BenchScenario(duration=3.0, speed_difference=0.0, throttle_start=0.0, throttle_end=0.9, ramp_start=0.3,
                       ramp_end=2.8)
    return simulate_bench(magnet, sc, torque_reference=([0.0, 10.0], [250.0, 250.0]))


def test_current_follows_two_first_order_lags(magnet):
    """Coil current = command through tau1 then tau2 (Fig. 15), exact for a sample-and-hold command."""
    act = ActuatorParameters()
    sc = BenchScenario(duration=0.3, sample_time=0.005)
    ref = ([0.0, 0.1, 0.1001, 0.3], [50.0, 50.0, 250.0, 100.0])
    res = simulate_bench(magnet, sc, torque_reference=ref)
    df = res.to_dataframe()
    u, i1, i2 = df["current_command_A"].to_numpy(), df["i1_A"].to_numpy(), df["i2_A"].to_numpy()
    h, t1, t2 = sc.sample_time, act.tau1, act.tau2
    e1, e2 = math.exp(-h / t1), math.exp(-h / t2)
    p1 = u[:-1] + (i1[:-1] - u[:-1]) * e1
    p2 = u[:-1] + (i2[:-1] - u[:-1]) * e2 + (i1[:-1] - u[:-1]) * t1 / (t1 - t2) * (e1 - e2)
    np.testing.assert_allclose(i1[1:], p1, atol=2e-5)
    np.testing.assert_allclose(i2[1:], p2, atol=2e-5)


def test_armature_clamp_force_eq11_and_airgap_eq12(slipping_run):
    act = ActuatorParameters()
    df = slipping_run.to_dataframe()
    at_clutch = df["armature_mode"] == "contact"
    assert at_clutch.mean() > 0.9
    d = df[at_clutch]
    np.testing.assert_allclose(d["fn1_N"], d["magnet_force_N"] - act.preload - act.stiffness * act.free_travel, atol=1e-9)
    np.testing.assert_allclose(d["airgap_m"], act.airgap_open - act.free_travel, atol=1e-12)
    before = df[df["armature_mode"] == "rest"]
    assert (before["fn1_N"] == 0).all() and (before["magnet_force_N"] <= act.preload + 1e-9).all()


def test_slipping_torques_follow_eq15(slipping_run):
    g = CouplingGeometry()
    df = slipping_run.to_dataframe()
    slip = df[df["coupling_mode"] == "slipping"]
    assert len(slip) > 0.9 * len(df)
    assert (slip["slip_speed_rad_s"] > 0).all()  # the drums hold the speed difference: no lock-up
    expect = np.array([slipping_torques(f, 1.0, g) for f in slip["fn1_N"]])
    np.testing.assert_allclose(slip[["t1_Nm", "t2_Nm", "t3_Nm"]].to_numpy(), expect, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(slip["coupling_torque_Nm"], expect.sum(axis=1), rtol=1e-12)
    assert slipping_run.events["description"].str.contains("lock").sum() == 0


def test_torque_reference_tracking_through_inverse_preisach(slipping_run):
    """In slipping mode the transferred torque follows T_cal through the inverse magnet model (Eqs. 6-7, 31)."""
    df = slipping_run.to_dataframe()
    late = df[(df["time_s"] > 0.3) & df["command_feasible"]]
    # the plant is the model itself: only the two current lags delay the torque
    err = (late["coupling_torque_Nm"] - late["torque_reference_Nm"]).abs()
    assert err.median() < 0.02 * late["torque_reference_Nm"].abs().median()


def test_locked_mode_logic_fig11(locked_run):
    ev = locked_run.events
    names = list(ev["description"])
    lock = [i for i, n in enumerate(names) if n.startswith("lock-up")]
    unlock = [i for i, n in enumerate(names) if n.startswith("unlock")]
    assert len(lock) == 1 and len(unlock) == 1  # no chattering
    t_lock, t_unlock = ev["time_s"][lock[0]], ev["time_s"][unlock[0]]
    assert t_unlock - t_lock > 1.0
    df = locked_run.to_dataframe()
    locked = df[(df["time_s"] > t_lock) & (df["time_s"] < t_unlock)]
    assert (locked["coupling_mode"] == "locked").all()
    assert locked["slip_speed_rad_s"].abs().max() < 1e-6 * df["omega_f_rad_s"].mean()
    np.testing.assert_allclose(locked[["t1_Nm", "t2_Nm", "t3_Nm"]].sum(axis=1), locked["coupling_torque_Nm"], rtol=1e-10, atol=1e-9)
    # the locked split is the one of Eqs. 18-21 for the lock torque
    g = CouplingGeometry()
    for _, row in locked.iloc[::50].iterrows():
        assert locked_torques(row["fn1_N"], row["coupling_torque_Nm"], g, margin=1.02) == pytest.approx(
            (row["t1_Nm"], row["t2_Nm"], row["t3_Nm"]), rel=1e-9, abs=1e-9)
    # the split passes through several cases of Fig. 12
    assert len(set(locked["locked_case"])) >= 3
    # unlock exactly where |T_lock| reaches 1.02 T_cap
    last = locked.iloc[-1]
    assert abs(last["coupling_torque_Nm"]) == pytest.approx(1.02 * last["capacity_locked_Nm"], rel=2e-2)
    after = df[df["time_s"] > t_unlock]
    assert (after["coupling_mode"] == "slipping").all()  # stays slipping: no relock
    assert (after["slip_speed_rad_s"] > 0).all()


def test_results_converge_with_tolerance(magnet):
    sc = BenchScenario(duration=1.0, speed_difference=0.3, throttle_end=0.5, ramp_start=0.1, ramp_end=0.9)
    a = simulate_bench(magnet, sc, rtol=1e-6).to_dataframe()
    b = simulate_bench(magnet, sc, rtol=1e-9).to_dataframe()
    for col in ("omega_f_rad_s", "omega_r_rad_s", "coupling_torque_Nm", "i2_A", "x_armature_m"):
        np.testing.assert_allclose(a[col], b[col], rtol=1e-4, atol=1e-4 * b[col].abs().max())


def test_step_limit_raises(magnet):
    with pytest.raises(SimulationError, match="max_steps"):
        simulate_bench(magnet, BenchScenario(duration=0.5), max_steps=50)


def test_open_coupling_transfers_drag_torque_eq25_26(magnet):
    veh = VehicleParameters()
    res = simulate_bench(magnet, BenchScenario(duration=0.2, speed_difference=0.5), torque_reference=([0, 1], [0, 0]))
    df = res.to_dataframe()
    assert (df["coupling_mode"] == "open").all()
    np.testing.assert_allclose(df["coupling_torque_Nm"], veh.drag_coefficient() * df["slip_speed_rad_s"], rtol=1e-12)


def test_plant_model_mismatch_runs_with_separate_controller_model(magnet):
    truth = synthetic_magnet()
    res = simulate_bench(truth, BenchScenario(duration=1.0), controller_model=magnet)
    df = res.to_dataframe()
    late = df[df["time_s"] > 0.5]
    rel = (late["coupling_torque_Nm"] - late["torque_reference_Nm"]).abs().median() / late["torque_reference_Nm"].median()
    assert rel < 0.05  # identification error of the model only


def test_parameters_table1_and_toml(tmp_path):
    v = VehicleParameters()
    assert v.mass == 2162.0 and v.wheelbase == 2.7
    assert v.gear_ratios == (4.044, 2.371, 1.556, 1.159, 0.852, 0.672)
    assert (v.front_final_drive, v.rear_final_drive, v.reverse_ratio) == (3.75, 2.533, 3.19)
    assert v.engine_power == 125e3
    assert v.tyre_radius == pytest.approx(0.5 * 17 * 0.0254 + 0.65 * 0.225, abs=1e-4)
    fzf, fzr = v.axle_loads()
    assert fzf + fzr == pytest.approx(2162 * 9.80665)
    p = v.to_toml(tmp_path / "v.toml")
    assert VehicleParameters.from_toml(p) == v
    with pytest.raises(ParameterError, match="wheelbase"):
        VehicleParameters(cg_to_front=1.0)
    with pytest.raises(ParameterError, match="airgap_open"):
        ActuatorParameters(airgap_open=0.4e-3)
    with pytest.raises(ParameterError, match="mass"):
        VehicleParameters(mass=-1.0)


def test_load_scenario(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text('[scenario]\nduration = "0.5 s"\ndrum_speed = "36 km/h"\n[vehicle]\nmass = "2000 kg"\n')
    sc = load_scenario(p)
    assert sc["scenario"].drum_speed == pytest.approx(10.0)
    assert sc["vehicle"].mass == 2000.0 and sc["magnet"] is None
    p.write_text("[scenrio]\nduration = 1.0\n")
    with pytest.raises(ParameterError, match="unknown table"):
        load_scenario(p)
    p.write_text("[scenario]\ngear = 9\n")
    with pytest.raises(ParameterError, match="gear"):
        load_scenario(p)


from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples


@settings(max_examples=examples(12), deadline=None)
@given(thr_end=st.floats(0.0, 1.0), ref=st.floats(20.0, 400.0), dv=st.floats(-0.2, 0.2))
def test_no_chattering_property(thr_end, ref, dv):
    """Whatever the load and reference, lock/unlock events never alternate rapidly (Fig. 11 logic)."""
    sc = BenchScenario(duration=1.5, speed_difference=dv, throttle_start=0.0, throttle_end=thr_end,
                       ramp_start=0.1, ramp_end=1.4)
    res = simulate_bench(_MAGNET, sc, torque_reference=([0.0, 2.0], [ref, ref]))
    ev = res.events
    mode_ev = ev[ev["description"].str.startswith(("lock-up", "unlock", "slip reversal"))]
    assert len(mode_ev) <= 6
    if len(mode_ev) > 1:
        assert np.diff(mode_ev["time_s"].to_numpy()).min() > 0.01
    df = res.to_dataframe()
    # locked samples have zero slip; slipping samples never carry more than the kinetic capacity
    locked = df[df["coupling_mode"] == "locked"]
    assert (locked["slip_speed_rad_s"].abs() < 1e-6 * df["omega_f_rad_s"].abs().max()).all()
    assert (locked["coupling_torque_Nm"].abs() <= 1.02 * locked["capacity_locked_Nm"] * (1 + 1e-9) + 1e-9).all()


_MAGNET = bundled_magnet()


def _eq15(fn1, mu, g):
    """Eq. 15 with one kinetic coefficient for the three elements."""
    lam, R = g.cam_ratio, g.cam_radius
    t1 = 2 / 3 * mu * g.radius1 * fn1 * g.pairs1
    den = 3 * R - 2 * lam * mu * g.radius3
    return np.column_stack([t1, 2 * lam * mu * g.radius2 * g.pairs2 / den * t1, 2 * lam * mu * g.radius3 / den * t1])


def test_friction_map_in_bench(magnet):
    from clutchlab.emtc import FrictionMap

    g = CouplingGeometry()
    fm = FrictionMap([0.0, 5.0, 50.0], [0.0, 100.0], [[0.10, 0.09], [0.08, 0.07], [0.06, 0.05]])
    sc = BenchScenario(duration=0.6, speed_difference=0.3, temperature_c=50.0)
    df = simulate_bench(magnet, sc, friction_map=fm).to_dataframe()
    slip = df[(df["coupling_mode"] == "slipping") & (df["time_s"] > 0.1)]
    mu = np.array([fm(v, 50.0) for v in slip["slip_speed_rad_s"]])
    np.testing.assert_allclose(slip[["t1_Nm", "t2_Nm", "t3_Nm"]].to_numpy(), _eq15(slip["fn1_N"].to_numpy(), mu, g), rtol=1e-9)


def test_the_friction_map_is_read_at_the_input_temperature_with_that_source(magnet):
    """BenchOptions(coupling_temperature="input"): the map is read at the held input coupling_temperature (a heat
    port's, [2] Sec. 5), not at the scenario's temperature_c; the run equals a run at that scenario temperature."""
    from clutchlab.emtc import FrictionMap
    from clutchlab.emtc.system import BenchOptions, U_TEMP, bench_system
    from clutchlab.system import simulate

    g = CouplingGeometry()
    fm = FrictionMap([0.0, 5.0, 50.0], [0.0, 100.0], [[0.10, 0.06], [0.08, 0.05], [0.06, 0.04]])
    opts = dict(friction_map=fm, coupling=g)

    def run(temperature_c, source, u_temp=None):
        s = bench_system(magnet, BenchScenario(duration=0.4, speed_difference=0.3, temperature_c=temperature_c),
                         options=BenchOptions(coupling_temperature=source, **opts))
        if u_temp is not None:
            u0 = s.u0.copy()
            u0[U_TEMP] = u_temp
            s = s.variant(u0=u0)
        return simulate(s, 0.4, output_step=0.01).to_dataframe()

    at_input = run(20.0, "input", u_temp=80.0)
    np.testing.assert_array_equal(at_input["t1_Nm"], run(80.0, "parameter")["t1_Nm"])
    at_parameter = run(20.0, "parameter", u_temp=80.0)   # (the input unread with the parameter source)
    np.testing.assert_array_equal(at_parameter["t1_Nm"], run(20.0, "parameter")["t1_Nm"])
    slip = at_input[(at_input["coupling_mode"] == "slipping") & (at_input["time_s"] > 0.1)]
    assert len(slip) > 10
    mu = np.array([fm(v, 80.0) for v in slip["slip_speed_rad_s"]])
    np.testing.assert_allclose(slip[["t1_Nm", "t2_Nm", "t3_Nm"]].to_numpy(), _eq15(slip["fn1_N"].to_numpy(), mu, g),
                               rtol=1e-9)
    assert not np.allclose(slip["t1_Nm"], at_parameter.loc[slip.index, "t1_Nm"], rtol=0.1)
    with pytest.raises(ParameterError, match="coupling_temperature = 'port'"):
        BenchOptions(coupling_temperature="port")


def test_lugre_in_bench_reaches_stribeck_steady_state(magnet):
    from clutchlab.emtc import LuGreParameters, lugre_steady_state

    g = CouplingGeometry()
    lp = LuGreParameters()
    sc = BenchScenario(duration=0.6, speed_difference=0.3)
    res = simulate_bench(magnet, sc, lugre=lp)
    df = res.to_dataframe()
    slip = df[(df["coupling_mode"] == "slipping") & (df["time_s"] > 0.1)]
    mu_ss, _ = lugre_steady_state(slip["slip_speed_rad_s"].to_numpy(), lp)
    fn1 = slip["fn1_N"].to_numpy()
    mu_eff = slip["t1_Nm"].to_numpy() / (2 / 3 * g.radius1 * fn1 * g.pairs1)
    # quasi-steady slip: the LuGre coefficient sits on the Stribeck curve (bristle lag ~ g/(sigma0 |v|) = 30 us)
    np.testing.assert_allclose(mu_eff, mu_ss, rtol=5e-3)
    np.testing.assert_allclose(slip[["t1_Nm", "t2_Nm", "t3_Nm"]].to_numpy(), _eq15(fn1, mu_eff, g), rtol=1e-9)
    with pytest.raises(ParameterError, match="either"):
        from clutchlab.emtc import FrictionMap

        simulate_bench(magnet, sc, lugre=lp, friction_map=FrictionMap([0, 1], [0, 1], np.ones((2, 2)) * 0.1))


def test_lugre_lock_and_unlock_without_chattering(magnet):
    from clutchlab.emtc import LuGreParameters

    sc = BenchScenario(duration=3.0, speed_difference=0.0, throttle_start=0.0, throttle_end=0.9, ramp_start=0.3,
                       ramp_end=2.8)
    res = simulate_bench(magnet, sc, torque_reference=([0.0, 10.0], [150.0, 150.0]), lugre=LuGreParameters())
    names = list(res.events["description"])
    assert sum(n.startswith("lock-up") for n in names) == 1
    assert sum(n.startswith("unlock") for n in names) == 1
    assert not any(n.startswith("slip reversal") for n in names)
    df = res.to_dataframe()
    after = df[df["time_s"] > res.events["time_s"].iloc[-1]]
    assert (after["slip_speed_rad_s"] > 0).all() and (after["coupling_mode"] == "slipping").all()


def test_magnet_force_is_the_preisach_output_at_coil_current_and_airgap(magnet):
    """Rising current from zero: the plant force is the limiting ascending branch F(i, i) at the airgap."""
    act = ActuatorParameters()
    res = simulate_bench(magnet, BenchScenario(duration=0.5, speed_difference=0.3),
                         torque_reference=([0.0, 0.5], [20.0, 300.0]))
    df = res.to_dataframe()
    assert np.all(np.diff(df["i2_A"]) >= -1e-12)  # monotone coil current
    at = df[df["armature_mode"] == "contact"]
    gap = act.airgap_open - act.free_travel
    np.testing.assert_allclose(at["magnet_force_N"], magnet.forc(at["i2_A"], at["i2_A"], airgap=gap), rtol=1e-10, atol=1e-9)
    rest = df[df["armature_mode"] == "rest"]
    np.testing.assert_allclose(rest["magnet_force_N"], magnet.forc(rest["i2_A"], rest["i2_A"], airgap=act.airgap_open),
                               rtol=1e-10, atol=1e-9)
