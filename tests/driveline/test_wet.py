"""The wet clutch as a driveline element (:meth:`Driveline.wet_clutch`, :mod:`clutchlab.driveline.wet`).

The dedicated model (:mod:`clutchlab.wet`, its own shaft and stick/slip logic) is the independent
reference: the driveline replaces its shaft by a network inertia and its lock-up by the network's friction
state machine, so the two must agree to the solver's tolerance.  Energy is checked between two integrals
that share no code: the network's dissipation ``tau * w_rel`` and the wet model's friction work state.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from clutchlab.driveline import Driveline, Signal
from clutchlab.driveline.description import load_driveline, parse_driveline
from clutchlab.errors import ParameterError
from clutchlab.wet.bench import EngagementProtocol
from clutchlab.wet.engagement import simulate_engagement
from clutchlab.wet.params import Bench, WetClutch

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def bench_run():
    """The wet bench's own inertia-dynamometer run (protocol (c), SAE No. 2) at a tight tolerance."""
    clutch, bench = WetClutch.paper(), Bench()
    scenario = EngagementProtocol().scenario(clutch, "free")
    times = np.linspace(0.0, scenario.duration, 1201)
    ref = simulate_engagement(clutch, scenario, bench=bench, sample_times=times, rtol=1e-9)
    return clutch, bench, scenario, times, ref.result.to_dataframe(), ref.lockup_time


def test_sae2_example_equals_the_wet_bench(bench_run):
    """``examples/driveline_wet_sae2.toml`` reproduces the bench's inertia dynamometer: the same events
    (piston off its stop, film contact, lock-up) to 1e-7 s, speed, torque and pack temperature to the
    solver's tolerance, and the example's parameters are the bench's (inertia, speed, force, temperatures)."""
    clutch, bench, scenario, times, ref, lockup = bench_run
    f = load_driveline(EXAMPLES / "driveline_wet_sae2.toml")
    d = f.driveline
    dyno = {b.name: b for b in d.inertias}["dyno"].arguments
    assert dyno["J"] == bench.total_inertia
    assert math.isclose(dyno["w0"], scenario.initial_slip_speed, rel_tol=1e-14)
    r = d.simulate(f.t_end, rtol=1e-9, sample_times=times)
    df = r.to_dataframe()
    ev = r.events
    stick = ev[ev["event"] == "stick"]["time_s"].to_numpy()
    assert stick.size == 1 and abs(stick[0] - lockup) < 1e-7
    bev = simulate_engagement(clutch, scenario, bench=bench, sample_times=times, rtol=1e-9).result.events
    for name in ("piston_leaves_stop", "contact"):
        mine = ev[ev["event"] == name]["time_s"].to_numpy()
        theirs = bev[bev["event"] == name]["time_s"].to_numpy()
        assert mine.size == theirs.size == 1 and abs(mine[0] - theirs[0]) < 1e-7
    w_scale = scenario.initial_slip_speed
    assert np.max(np.abs(df["dyno.w_rad_s"] - ref["slip_speed_rad_s"])) < 1e-6 * w_scale
    tau_scale = np.max(np.abs(ref["clutch_torque_Nm"]))
    assert np.max(np.abs(df["clutch.tau_Nm"] - ref["clutch_torque_Nm"])) < 1e-6 * tau_scale
    assert np.max(np.abs(df["clutch.temperature_C"] - ref["temperature_C"])) < 1e-6
    # the torque is the paper's: asperity + viscous while slipping (Eq. 3)
    slip = df["time_s"] < lockup - 1e-3
    np.testing.assert_allclose(df["clutch.tau_Nm"][slip], (df["clutch.contact_torque_Nm"]
                                                          + df["clutch.viscous_torque_Nm"])[slip], rtol=1e-9, atol=1e-9)
    # energy: the kinetic energy all went into the clutch
    assert abs(df["dissipated_energy_J"].iloc[-1] - 0.5 * bench.total_inertia * w_scale ** 2) < 1e-6 * 0.5 * bench.total_inertia * w_scale ** 2


def _launch(force=None, **kw):
    """An engine (constant torque, inertia) driving a vehicle inertia with a road load through a wet clutch."""
    d = Driveline("wet_launch")
    d.inertia("engine", J=0.2, w0=150.0).inertia("vehicle", J=4.0)
    d.torque("engine_torque", "engine", 40.0)
    d.bearing_friction("road", "vehicle", torque=10.0)
    d.wet_clutch("clutch", "vehicle", "engine",
                 force=Signal.ramp(4000.0, 0.3, start=0.05) if force is None else force, **kw)
    return d


def test_wet_clutch_between_two_inertias_locks_and_conserves_energy():
    """Engine and vehicle are brought to one speed by the clutch, which then stays locked (its capacity at
    4 kN is far above the 30 N m it has to carry); the network's energy balance closes, and the clutch's
    dissipated energy (the network's ``tau * w_rel``) equals the wet model's friction work (its own state,
    ``tau * slip``) and the heat that went into the pack, oil and housing."""
    d = _launch()
    r = d.simulate(1.5, rtol=1e-9, output_step=1e-3)
    df = r.to_dataframe()
    ev = r.events
    stick = ev[(ev["element"] == "clutch") & (ev["event"] == "stick")]["time_s"].to_numpy()
    assert stick.size == 1 and 0.1 < stick[0] < 1.5
    after = df["time_s"] > stick[0] + 1e-3
    np.testing.assert_allclose(df["engine.w_rad_s"][after], df["vehicle.w_rad_s"][after], rtol=0, atol=1e-6)
    # stuck: the clutch carries the vehicle's share, tau = (J_v T_e + J_e T_road) / (J_e + J_v) (on flange b, the
    # engine: -tau)
    np.testing.assert_allclose(df["clutch.tau_Nm"][after], (4.0 * 40.0 + 0.2 * 10.0) / 4.2, rtol=1e-7)
    work = df["input_work_J"].iloc[-1]
    assert abs(df["energy_error_J"]).max() < 1e-7 * work
    diss = df["clutch.dissipated_J"].iloc[-1]
    assert diss > 100.0
    assert abs(diss - df["clutch.friction_work_J"].iloc[-1]) < 1e-6 * diss
    # Eq. 8: friction work = heat stored in the pack + heat to the oil + heat to the housing
    cp = WetClutch.paper().heat_capacity
    stored = cp * (df["clutch.temperature_C"].iloc[-1] - df["clutch.temperature_C"].iloc[0])
    heat = stored + df["clutch.heat_to_fluid_J"].iloc[-1] + df["clutch.heat_to_housing_J"].iloc[-1]
    assert abs(heat - diss) < 1e-6 * diss
    # the clutch's own outputs, not its bench's (#33: heater_power, load_cell_force were reported), each in its
    # place: the friction power is the network's |tau w_rel| while it slips, the clutch torque its tau
    from clutchlab.driveline.wet import BENCH_ONLY, OUTPUTS

    assert not [c for c in df.columns if any(c.startswith(f"clutch.{q}_") for q in BENCH_ONLY)]
    assert all(any(c.startswith(f"clutch.{q}_") for c in df.columns) for q, _, _ in OUTPUTS)
    slipping = (df["time_s"] > 0.01) & (df["time_s"] < stick[0] - 1e-3)
    np.testing.assert_allclose(df["clutch.friction_power_W"][slipping],
                               (df["clutch.tau_Nm"] * df["clutch.w_rel_rad_s"]).abs()[slipping], rtol=1e-6)
    np.testing.assert_allclose(df["clutch.clutch_torque_Nm"][slipping].abs(), df["clutch.tau_Nm"][slipping].abs(),
                               rtol=1e-9)


def test_wet_clutch_slides_backward_and_stays_open_without_force():
    """With the flanges swapped the slip is negative: the torque changes sign with it (the viscous drag of
    the open film and the asperity tail of the piston at its stop, Greenwood-Williamson), and the clutch never
    locks."""
    d = Driveline("drag")
    d.inertia("a", J=0.1, w0=100.0).inertia("b", J=0.1)
    d.wet_clutch("clutch", "a", "b", force=0.0)
    df = d.simulate(0.5, output_step=0.05).to_dataframe()
    assert (df["clutch.w_rel_rad_s"] < 0).all()
    assert (df["clutch.contact_force_N"] < 2.0).all()   # the piston stays on its stop
    assert (df["clutch.tau_Nm"] < 0).all()          # opposes the negative slip
    assert (df["clutch.mode_1"] == -1).all()        # backward (MSL code)
    np.testing.assert_allclose(df["clutch.tau_Nm"], df["clutch.contact_torque_Nm"] + df["clutch.viscous_torque_Nm"],
                               rtol=1e-12)
    # momentum: no external torque, so J_a w_a + J_b w_b stays 10 N m s
    np.testing.assert_allclose(0.1 * df["a.w_rad_s"] + 0.1 * df["b.w_rad_s"], 10.0, rtol=1e-9)


def test_wet_clutch_errors():
    # the force is a port: any signal, but within [0, the actuator's maximum] where its range is known
    with pytest.raises(ParameterError, match=r"clutch: force = 100 N sine.*reaches -100 N; an actuator only pushes"):
        _launch(force=Signal.sine(100.0, 1.0))
    with pytest.raises(ParameterError, match="reaches -5 N"):
        _launch(force=Signal.table([0.0, 1.0], [0.0, -5.0]))
    with pytest.raises(ParameterError, match=r"reaches 18000 N, beyond the actuator's 16000 N"):
        _launch(force=Signal.product(Signal.constant(3000.0), Signal.step(5.0, 0.1, offset=1.0)))
    _launch(force=Signal.sine(100.0, 1.0, offset=100.0)).system()   # (touches 0: an actuator at rest)
    with pytest.raises(ParameterError, match="temperature0"):
        _launch(temperature0=math.nan)
    with pytest.raises(ParameterError, match="clutch: clutch must be a WetClutch, not Bench"):
        _launch(clutch=Bench())
    with pytest.raises(ParameterError, match="friction must be a ParametricFriction or FrictionMap, not float"):
        _launch(friction=0.3)
    assert "wet clutch (seed 001" in repr(_launch())


def test_wet_clutch_file_errors(tmp_path):
    doc = {"inertia": {"J": {"J": "1 kg m^2", "w0": "100 rad/s"}},
           "wet_clutch": {"c": {"a": "ground", "b": "J", "force": "2 kN", "temperature0": "80 N"}}}
    with pytest.raises(ParameterError, match=r"wet_clutch\.c\.temperature0"):
        parse_driveline(doc, "x.toml", tmp_path)
    doc["wet_clutch"]["c"]["temperature0"] = "60 degC"
    doc["wet_clutch"]["c"]["clutch"] = "missing.toml"
    with pytest.raises(ParameterError, match=r"wet_clutch\.c\.clutch = 'missing.toml': no such file"):
        parse_driveline(doc, "x.toml", tmp_path)
    (tmp_path / "c.toml").write_text('[wet]\nn_c = "-3"\n')
    doc["wet_clutch"]["c"]["clutch"] = "c.toml"
    with pytest.raises(ParameterError, match="n_c"):
        parse_driveline(doc, "x.toml", tmp_path)
    del doc["wet_clutch"]["c"]["clutch"]
    f = parse_driveline(doc, "x.toml", tmp_path)
    assert f.driveline.elements[0].arguments["temperature0"] == 60.0


def test_wet_clutch_in_the_co_simulation_and_the_sweep_variants():
    """The FMU's co-simulation class of the SAE No. 2 file steps the wet clutch's states through the contract
    (a chain of 10 ms steps ends on the one-run result to the solver's tolerance), and its parameters include
    the clutch's initial temperatures (a changed pack temperature changes the run as the Python network)."""
    from clutchlab.fmu.driveline import DrivelineCoSimulation

    path = EXAMPLES / "driveline_wet_sae2.toml"
    cls = DrivelineCoSimulation.for_description(path)
    names = {v.name for v in cls.parameters}
    assert {"clutch.temperature0", "clutch.fluid_temperature0", "dyno.J"} <= names
    sim = cls(**{"clutch.temperature0": 90.0})
    t, y = 0.0, None
    for _ in range(80):
        y = sim.do_step(t, 0.01, {})
        t += 0.01
    f = load_driveline(path)
    d = f.driveline.replace("clutch", temperature0=90.0)
    ref = d.simulate(0.8, rtol=f.rtol, sample_times=[0.8]).to_dataframe().iloc[-1]
    assert abs(y["dyno.w"] - ref["dyno.w_rad_s"]) < 1e-5
    assert abs(y["clutch.temperature"] - ref["clutch.temperature_C"]) < 1e-5
    assert y["clutch.mode"] == 0.0    # locked by 0.8 s


def test_two_wet_clutches_each_equal_their_own_bench(bench_run):
    """Two SAE No. 2 dynamometers in one network (different speeds, forces, temperatures and clutches: the
    second has 6 plates): each gives its own bench run's lock-up, speed and temperature, and the events and
    columns are named per clutch."""
    clutch, bench, scenario, times, ref, lockup = bench_run
    clutch6 = WetClutch.paper(n_c=6)
    d = Driveline("two_dynos")
    d.inertia("dyno1", J=bench.total_inertia, w0=scenario.initial_slip_speed)
    d.inertia("dyno2", J=bench.total_inertia, w0=120.0)
    d.wet_clutch("c1", "ground", "dyno1", force=Signal.table(scenario.force_time, scenario.force_value), clutch=clutch,
                 bench=bench, temperature0=scenario.initial_temperature_c, fluid_temperature0=scenario.fluid_temperature_c,
                 housing_temperature0=scenario.housing_temperature_c)
    d.wet_clutch("c2", "ground", "dyno2", force=Signal.ramp(2500.0, 0.3, start=0.1), clutch=clutch6,
                 temperature0=60.0, fluid_temperature0=60.0, housing_temperature0=60.0)
    r = d.simulate(1.2, rtol=1e-9, sample_times=times)
    df = r.to_dataframe()
    np.testing.assert_allclose(df["dyno1.w_rad_s"], ref["slip_speed_rad_s"], rtol=0, atol=1e-6 * scenario.initial_slip_speed)
    np.testing.assert_allclose(df["c1.temperature_C"], ref["temperature_C"], rtol=0, atol=1e-6)
    ev = r.events
    assert abs(ev[(ev.element == "c1") & (ev.event == "stick")].time_s.iloc[0] - lockup) < 1e-7
    # the second against its own single-clutch network and its own bench run (6 plates, 60 degC)
    from clutchlab.wet.engagement import Scenario

    sc2 = Scenario(force_time=[0.1, 0.4], force_value=[0.0, 2500.0], speed_time=[0.0], speed_value=[0.0],
                   duration=1.2, motor="free", initial_slip_speed=120.0, initial_temperature_c=60.0,
                   fluid_temperature_c=60.0, housing_temperature_c=60.0)
    ref2 = simulate_engagement(clutch6, sc2, bench=bench, sample_times=times, rtol=1e-9)
    r2 = ref2.result.to_dataframe()
    np.testing.assert_allclose(df["dyno2.w_rad_s"], r2["slip_speed_rad_s"], rtol=0, atol=1e-6 * 120.0)
    np.testing.assert_allclose(df["c2.clutch_torque_Nm"], r2["clutch_torque_Nm"], rtol=0,
                               atol=1e-6 * np.abs(r2["clutch_torque_Nm"]).max())
    assert abs(ev[(ev.element == "c2") & (ev.event == "stick")].time_s.iloc[0] - ref2.lockup_time) < 1e-7
    assert {"c1.piston", "c2.piston"} <= set(ev.element)


def test_a_periodic_force_port_equals_the_bench_run_of_its_corners():
    """The force is a port (:func:`clutchlab.driveline.wet.hold`): a network signal read at every evaluation, so any
    signal drives the clutch.  A trapezoid (MSL ``Blocks.Sources.Trapezoid``: the network evaluates its formula)
    pressing the clutch of a spinning dynamometer twice, and the same trapezoid as the product of a constant and a
    dimensionless one, each equal the wet bench's own model run with the trapezoid's corners as its
    piecewise-linear profile (an independent reading of the same reference): speed, torque and pack temperature
    to the solver's tolerance, piston and film events to 1e-7 s."""
    from clutchlab.wet.engagement import Scenario

    clutch, bench = WetClutch.paper(), Bench()
    # 0 -> 900 N over 0.05 s from 0.05 s, held 0.1 s, back to 0 over 0.05 s; every 0.4 s, twice
    trap = Signal.trapezoid(900.0, 0.05, 0.1, 0.05, 0.4, nperiod=2, start=0.05)
    unit = Signal.trapezoid(1.0, 0.05, 0.1, 0.05, 0.4, nperiod=2, start=0.05)
    corners_t, corners_f = [0.0], [0.0]
    for k in range(2):
        t0 = 0.05 + 0.4 * k
        corners_t += [t0, t0 + 0.05, t0 + 0.15, t0 + 0.2]
        corners_f += [0.0, 900.0, 900.0, 0.0]
    sc = Scenario(force_time=corners_t, force_value=corners_f, speed_time=[0.0], speed_value=[0.0], duration=0.9,
                  motor="free", initial_slip_speed=150.0, initial_temperature_c=60.0, fluid_temperature_c=60.0,
                  housing_temperature_c=60.0)
    times = np.linspace(0.0, 0.9, 181)
    ref = simulate_engagement(clutch, sc, bench=bench, sample_times=times, rtol=1e-9)
    R = ref.result.to_dataframe()
    assert R["contact_force_N"].max() > 100.0   # (the film closes)
    for force in (trap, Signal.product(Signal.constant(900.0), unit)):
        d = Driveline("pulsed")
        d.inertia("dyno", J=bench.total_inertia, w0=150.0)
        d.wet_clutch("c", "ground", "dyno", force=force, clutch=clutch, bench=bench, temperature0=60.0,
                     fluid_temperature0=60.0, housing_temperature0=60.0)
        r = d.simulate(0.9, rtol=1e-9, sample_times=times)
        df = r.to_dataframe()
        np.testing.assert_allclose(df["dyno.w_rad_s"], R["slip_speed_rad_s"], rtol=0, atol=1e-6 * 150.0)
        tau = np.abs(R["clutch_torque_Nm"]).max()
        np.testing.assert_allclose(df["c.clutch_torque_Nm"], R["clutch_torque_Nm"], rtol=0, atol=1e-6 * tau)
        np.testing.assert_allclose(df["c.temperature_C"], R["temperature_C"], rtol=0, atol=1e-6)
        np.testing.assert_allclose(df["c.actuator_force_N"], R["actuator_force_N"], rtol=0, atol=1e-6 * 900.0)
        bev, ev = ref.result.events, r.events
        for name in ("piston_leaves_stop", "contact", "separation", "piston_reaches_stop"):
            mine = ev[ev["event"] == name]["time_s"].to_numpy()
            theirs = bev[bev["event"] == name]["time_s"].to_numpy()
            assert mine.size == theirs.size, name
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-7, err_msg=name)
        assert (ev["event"] == "contact").sum() == 2   # (pressed twice)


def test_a_wet_clutch_s_parameter_sets_are_parameters_of_its_network(tmp_path):
    """A description's wet clutch takes its ``clutch`` and ``bench`` from files (or their defaults); their numeric
    fields are parameters of the network (``<component>.clutch.<field>``, ``<component>.bench.<field>``: a sweep's
    and a native FMU's), the bench's drive and the virtual rig's sensors left out (the network is the drive).
    Changed by name they give the run a file carrying those values gives (the same numbers, bit for bit); a
    whole-number field takes whole numbers only, and the set's own checks name the parameter."""
    from clutchlab.driveline.variants import DrivelineDocument
    from clutchlab.wet.params import BENCH_DRIVE, Bench, WetClutch

    example = Path(__file__).resolve().parents[2] / "examples" / "driveline_wet_sae2.toml"
    doc = DrivelineDocument.read(example)
    params = doc.parameters
    paper, bench = WetClutch.paper(), Bench()
    assert params["clutch.clutch.r_outer"].value == paper.r_outer and params["clutch.clutch.r_outer"].unit == "m"
    assert params["clutch.bench.actuator_time_constant"].value == bench.actuator_time_constant
    assert not any(f"clutch.bench.{f}" in params for f in BENCH_DRIVE) and "clutch.bench.seed" not in params
    changes = {"clutch.clutch.r_outer": 0.085, "clutch.clutch.n_c": 7.0, "clutch.clutch.m_lining": 0.0019,
               "clutch.bench.actuator_time_constant": 0.03}
    loaded = doc.load(changes)
    wet = next(e for e in loaded.driveline.elements if e.kind == "wet_clutch").arguments
    assert wet["clutch"] == paper.replace(r_outer=0.085, n_c=7, m_lining=0.0019)
    assert wet["bench"] == bench.replace(actuator_time_constant=0.03)
    # the same values from files the description names (an independent route: the sets' own readers)
    folder = tmp_path / "files"
    folder.mkdir()
    paper.replace(r_outer=0.085, n_c=7, m_lining=0.0019).to_toml(folder / "pack.toml")
    bench.replace(actuator_time_constant=0.03).to_toml(folder / "bench.toml")
    text = example.read_text().replace('[wet_clutch.clutch]\n', '[wet_clutch.clutch]\nclutch = "pack.toml"\n'
                                                                 'bench = "bench.toml"\n')
    (folder / "wet.toml").write_text(text)
    from_files = DrivelineDocument.read(folder / "wet.toml")
    assert from_files.parameters["clutch.clutch.n_c"].value == 7.0   # (a file's value is the parameter's start)
    a = loaded.driveline.simulate(0.3, rtol=1e-8, output_step=1e-3).to_dataframe()
    b = from_files.load().driveline.simulate(0.3, rtol=1e-8, output_step=1e-3).to_dataframe()
    assert a.equals(b)
    plain = doc.load().driveline.simulate(0.3, rtol=1e-8, output_step=1e-3).to_dataframe()
    assert not a.equals(plain)
    with pytest.raises(ParameterError, match=r"clutch\.clutch\.n_c = 6\.5: must be a whole number"):
        doc.load({"clutch.clutch.n_c": 6.5})
    with pytest.raises(ParameterError, match=r"clutch\.clutch"):
        doc.load({"clutch.clutch.r_inner": 0.09})   # (beyond r_outer: the set's own check)
