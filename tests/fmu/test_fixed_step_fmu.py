"""The co-simulation FMUs in the core's fixed-step (real-time) mode: parameter ``solver.fixed_step``."""

from pathlib import Path

import numpy as np
import pytest

from clutchlab.errors import ParameterError
from clutchlab.fmu.emtc import EmtcCoSimulation
from clutchlab.fmu.wet import WetCoSimulation

fmpy = pytest.importorskip("fmpy")


def _wet_inputs(n):
    k = np.arange(n + 1)
    return {"force_reference": np.where(k < 5, 0.0, np.where(k < 30, 3000.0, 1500.0)),
            "slip_speed_reference": np.where(k < 40, 157.0796326794897, 100.0)}


def test_wet_fmu_runs_fixed_step(build_fmu, run_fmu, run_cosim):
    """A 1 ms frame inside 10 ms communication steps: the FMU reproduces the in-process co-simulation
    in fixed-step mode, which takes exactly ten steps per communication step and follows the adaptive run."""
    dt, n = 0.01, 60
    inputs = _wet_inputs(n)
    names = ["clutch_torque", "slip_speed", "temperature", "actuator_force"]
    start = {"solver.fixed_step": 1e-3}
    fmu = run_fmu(build_fmu("wet"), inputs, dt, n, names, start)
    cosim = WetCoSimulation(**start)
    fixed = run_cosim(cosim, inputs, dt, n)
    assert cosim.n_steps == 10 * n
    adaptive = run_cosim(WetCoSimulation(), inputs, dt, n)
    for name in names:
        np.testing.assert_allclose(fmu[name], fixed[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(fixed[name])),
                                   err_msg=name)
    assert np.max(np.abs(fixed["slip_speed"] - adaptive["slip_speed"])) < 0.01 * 157.08
    assert np.max(fixed["clutch_torque"]) > 100.0


def test_emtc_cosimulation_runs_fixed_step(run_cosim):
    dt, n = 0.01, 30
    inputs = {"torque_request": np.full(n + 1, 300.0), "throttle": np.full(n + 1, 0.6),
              "drum_speed_front": np.full(n + 1, 8.0), "drum_speed_rear": np.full(n + 1, 7.7)}
    fixed_c = EmtcCoSimulation(**{"solver.fixed_step": 1e-3})
    fixed = run_cosim(fixed_c, inputs, dt, n)
    adaptive = run_cosim(EmtcCoSimulation(), inputs, dt, n)
    assert fixed_c.n_steps == 10 * n
    assert np.all(np.isfinite(fixed["coupling_torque"]))
    scale = np.max(np.abs(adaptive["coupling_torque"]))
    assert scale > 50.0
    assert np.max(np.abs(fixed["coupling_torque"] - adaptive["coupling_torque"])) < 0.1 * scale


@pytest.mark.parametrize("bad", [-1e-3, float("inf")])
def test_bad_fixed_step_parameter_is_refused(bad):
    with pytest.raises(ParameterError, match="solver.fixed_step"):
        WetCoSimulation(**{"solver.fixed_step": bad})


def test_eclutch_cosimulation_runs_fixed_step(run_cosim):
    """The E-clutch (stiff, Rodas3 anyway) in 1 ms frames inside 5 ms communication steps follows its adaptive run."""
    from clutchlab.fmu.eclutch import EClutchCoSimulation

    dt, n = 5e-3, 60
    k = np.arange(n + 1)
    inputs = {"bearing_reference": np.where(k < 10, 0.0, 5e-3), "motor_voltage": np.zeros(n + 1)}
    fixed_c = EClutchCoSimulation(**{"solver.fixed_step": 1e-3})
    fixed = run_cosim(fixed_c, inputs, dt, n)
    adaptive = run_cosim(EClutchCoSimulation(), inputs, dt, n)
    assert fixed_c.simulation.stats["accepted_steps"] == 5 * n
    assert np.all(np.isfinite(fixed["bearing_position"]))
    assert np.max(fixed["bearing_position"]) > 3e-3
    assert np.max(np.abs(fixed["bearing_position"] - adaptive["bearing_position"])) < 2e-5


# ----------------------------------------------------------------- the driveline (a network from its description file)
COUPLED_CLUTCHES = Path(__file__).resolve().parents[2] / "examples" / "driveline_coupled_clutches.toml"


def _driveline_chain(cls, dt, n, start=None):
    """The co-simulation of ``cls`` stepped ``n`` times by ``dt``; outputs at ``0, dt, ..., n dt`` and the right-hand
    side evaluations of each step."""
    sim = cls(**(start or {}))
    rows = [sim.initial_outputs({})]
    rhs = [sim.simulation.stats["rhs_evaluations"]]
    for k in range(n):
        t = k * dt
        rows.append(sim.do_step(t, (k + 1) * dt - t, {}))
        rhs.append(sim.simulation.stats["rhs_evaluations"])
    return sim, {v.name: np.array([r[v.name] for r in rows]) for v in cls.outputs}, np.diff(rhs)


@pytest.fixture(scope="module")
def driveline():
    """Modelica's CoupledClutches (examples/driveline_coupled_clutches.toml) over 1.5 s in 1 ms communication steps:
    the adaptive co-simulation and the one in 1 ms frames (``solver.fixed_step = 1e-3``)."""
    from clutchlab.fmu.driveline import DrivelineCoSimulation

    cls = DrivelineCoSimulation.for_description(COUPLED_CLUTCHES)
    fixed = _driveline_chain(cls, 1e-3, 1500, {"solver.fixed_step": 1e-3})
    adaptive = _driveline_chain(cls, 1e-3, 1500)
    return cls, fixed, adaptive


def test_driveline_cosimulation_runs_fixed_step(driveline):
    """The driveline in 1 ms frames: a parameter of the FMU, one Rodas3 step of the same cost per frame (stick,
    reversal and release steps included), and the adaptive run followed within the delay of the mode changes.

    Tolerances, measured: the speeds differ from the adaptive run's by at most 4.0e-3 of their range (J4, after the
    last clutch closes; J1 3.5e-4), the source's work by 3.1e-4 of its range; bounds 6e-3 and 1e-3.  The torques and
    modes jump at the mode changes, which the fixed-step run takes at the first frame end at or after the adaptive
    run's located instant or one frame later (tests/numerics/test_fixed_step.py): a mode differs only within two
    frames after an adaptive event of its element."""
    cls, (sim, fixed, rhs), (sim_a, adaptive, rhs_a) = driveline
    param = {v.name: v for v in cls.parameters}["solver.fixed_step"]
    assert (param.unit, param.start) == ("s", 0.0) and "fixed-step" in param.description
    assert sim.fixed_step == 1e-3 and sim.simulation.fixed_step == 1e-3 and sim.simulation.stats["fixed_step"] == 1e-3
    assert sim_a.fixed_step is None and sim_a.simulation.stats["fixed_step"] == 0.0
    assert sim.simulation.stats["accepted_steps"] == 1500 and sim.simulation.stats["rejected_steps"] == 0
    assert len(set(rhs.tolist())) == 1  # the same work every frame
    assert len(set(rhs_a.tolist())) > 1  # (the adaptive run's varies with the events and its step size)
    for name in ("J1.w", "J2.w", "J3.w", "J4.w"):
        scale = np.max(np.abs(adaptive[name]))
        assert np.all(np.isfinite(fixed[name])) and np.max(np.abs(fixed[name] - adaptive[name])) < 6e-3 * scale, name
    work = np.max(np.abs(adaptive["torque.work"]))
    assert np.max(np.abs(fixed["torque.work"] - adaptive["torque.work"])) < 1e-3 * work
    events = sim_a.simulation.events()
    got = sim.simulation.events()
    assert list(zip(got.element, got.event)) == list(zip(events.element, events.event)) and len(got) == 9
    t = np.arange(1501) * 1e-3
    for element in ("clutch1", "clutch2", "clutch3"):
        differ = t[fixed[f"{element}.mode"] != adaptive[f"{element}.mode"]]
        when = events.time_s[events.element == element].to_numpy()
        assert all(np.any((when <= s + 1e-12) & (s < when + 2e-3)) for s in differ), (element, differ)


def test_driveline_frames_do_not_depend_on_the_communication_step(driveline, run_fmu, tmp_path):
    """The frames lie on the grid k * 1 ms whatever the communication step: 10 ms steps give the 1 ms steps' values
    bit for bit; the FMU (FMPy, parameter solver.fixed_step) gives the in-process co-simulation's to 1e-12."""
    from clutchlab.fmu.export import export_fmu

    cls, (_, fixed, _), _ = driveline
    sim10, coarse, _ = _driveline_chain(cls, 1e-2, 150, {"solver.fixed_step": 1e-3})
    assert sim10.simulation.stats["accepted_steps"] == 1500
    for name in fixed:
        np.testing.assert_array_equal(coarse[name], fixed[name][::10], err_msg=name)
    path = export_fmu("driveline", tmp_path / "cc.fmu", description=COUPLED_CLUTCHES)
    names = ["J1.w", "J4.w", "clutch2.tau", "clutch3.mode", "energy_error"]
    fmu = run_fmu(path, {}, 1e-2, 150, names, {"solver.fixed_step": 1e-3})
    for name in names:
        np.testing.assert_allclose(fmu[name], coarse[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(coarse[name])),
                                   err_msg=name)


@pytest.mark.parametrize("bad", [-1e-3, float("nan"), float("inf")])
def test_bad_driveline_fixed_step_is_refused(driveline, bad):
    cls = driveline[0]
    with pytest.raises(ParameterError, match=r"solver\.fixed_step"):
        cls(**{"solver.fixed_step": bad})
