"""The core's fixed-step (real-time, HIL frame) mode: order, stiff stability, events at step ends, cost.

Expected values are closed forms (the damped oscillator through the matrix exponential) or the adaptive
solution of the same system (event times: the fixed-step run sees a mode change at the first step end
after the adaptive run's located instant).  No timings: the "same cost every step" is the number of
right-hand-side evaluations per step from the run's counters.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

import core_toys as toys
from clutchlab.errors import ParameterError
import clutchlab.emtc.system  # noqa: F401  (registers "emtc_bench")
import clutchlab.wet.system  # noqa: F401  (registers "wet")
from clutchlab.system import MODELS, Simulation, simulate

A_OSC = np.array([[0.0, 1.0], [-100.0, -0.5]])  # x'' + 0.5 x' + 100 x = 0
X0 = np.array([1.0, 0.0])
RAMP = {"bearing_reference": ([0.0, 0.1, 0.3, 0.6, 0.8], [0.0, 0.0, 7e-3, 7e-3, 0.0])}


def _exact(t):
    return expm(A_OSC * t) @ X0


@pytest.mark.parametrize("method", ["rodas", "dopri"])
def test_converges_at_order_three_on_the_damped_oscillator(method):
    """Rodas3 is of order 3: halving the frame divides the end error by 8 (a Dormand-Prince model runs
    through the same Rosenbrock loop in fixed-step mode)."""
    system = toys.linear_system(A_OSC, X0, method=method)
    errors = []
    for h in (1e-2, 5e-3, 2.5e-3, 1.25e-3):
        res = simulate(system, 1.0, fixed_step=h)
        assert res.stats["accepted_steps"] == round(1.0 / h)
        errors.append(np.abs(res.stats["final_state"] - _exact(1.0)).max())
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 2.9) & (orders < 3.2)), orders
    assert errors[-1] < 3e-6


def test_steps_lie_on_the_grid_and_the_last_lands_on_t_end():
    system = toys.linear_system(A_OSC, X0, method="rodas")
    res = simulate(system, 0.0105, fixed_step=1e-3)
    assert res.stats["accepted_steps"] == 11
    np.testing.assert_allclose(res.time[:-1], np.arange(11) * 1e-3, rtol=0, atol=1e-15)
    assert res.time[-1] == 0.0105  # the shorter last step
    np.testing.assert_allclose(res.stats["final_state"], _exact(0.0105), atol=1e-6)


def test_a_simulation_advanced_frame_by_frame_equals_the_whole_run():
    system = toys.linear_system(A_OSC, X0, method="rodas")
    whole = simulate(system, 0.1, fixed_step=1e-3)
    sim = Simulation(system, fixed_step=1e-3)
    for k in range(1, 101):
        sim.advance(k * 1e-3)
    np.testing.assert_array_equal(sim.x, whole.stats["final_state"])
    assert sim.stats["accepted_steps"] == 100
    # an advance to a time off the grid ends with a shorter step; the next frame is back on the grid
    sim2 = Simulation(system, fixed_step=1e-3)
    sim2.advance(0.0025)
    sim2.advance(0.004)
    assert sim2.stats["accepted_steps"] == 5


@pytest.mark.parametrize("bad", [0.0, -1e-3, math.nan, math.inf, "1e-3", True])
def test_bad_fixed_step_is_refused_naming_the_value(bad):
    system = toys.linear_system(A_OSC, X0, method="rodas")
    with pytest.raises(ParameterError, match="fixed_step"):
        simulate(system, 1.0, fixed_step=bad)
    with pytest.raises(ParameterError, match="fixed_step = "):
        Simulation(system, fixed_step=bad)


def test_rhs_evaluations_per_step_are_the_same_every_step():
    """Jacobian, df/dt, stages and the step end: the same count every step, events and breaks included."""
    from clutchlab.eclutch import EClutch

    system = EClutch().as_system(RAMP)
    counts = []
    for t_end in (0.05, 0.5, 1.0):  # before, during and after the stick-slip events and the table corners
        res = simulate(system, t_end, fixed_step=1e-3, output_step=1e-2)
        steps = res.stats["accepted_steps"]
        counts.append((res.stats["rhs_evaluations"] - 1) / steps)  # (1: the start)
    assert counts[0] == counts[1] == counts[2] and counts[0] == int(counts[0])
    assert len(simulate(system, 1.0, fixed_step=1e-3).events) > 3  # with mode changes in the run


def test_stiff_eclutch_is_stable_at_1ms():
    """The E-clutch (actuator + Model 4, stick-slip seals, end stops) at a 1 ms frame: finite, bounded, and the
    bearing position within 10 um of the adaptive run (7.3 mm travel; the adaptive runs at rtol 1e-8 and 1e-10
    differ by 2 um themselves through the stick-slip of the bearing seal)."""
    from clutchlab.eclutch import EClutch

    system = EClutch().as_system(RAMP)
    grid = np.arange(0, 1001) * 1e-3
    ref = simulate(system, 1.0, rtol=1e-8, sample_times=grid)
    for h in (1e-3, 2e-3):
        res = simulate(system, 1.0, fixed_step=h, sample_times=grid)
        assert res.status.ok
        assert np.all(np.isfinite(res.states)) and np.all(np.isfinite(res.outputs))
        ib = system.state_index("bearing_position")
        assert np.abs(res.states[:, ib] - ref.states[:, ib]).max() < 1e-5
        ip = system.state_index("pressure")
        assert np.abs(res.states[:, ip]).max() < 2.0 * np.abs(ref.states[:, ip]).max()


@pytest.mark.parametrize("h", [1e-3, 2e-3])
def test_wet_engagement_events_at_the_first_step_end_after_the_located_time(h):
    """Piston leaving its stop, film contact and lock-up of the wet engagement: each at the first frame end
    after the adaptive run's root-found instant."""
    system = MODELS["wet"]()
    ref = simulate(system, 1.0, rtol=1e-10)
    res = simulate(system, 1.0, fixed_step=h)
    assert list(res.events["event"]) == list(ref.events["event"]) == ["piston_leaves_stop", "contact", "lockup"]
    for k, (t_fix, t_ref) in enumerate(zip(res.events["time_s"], ref.events["time_s"])):
        first = math.ceil(t_ref / h - 1e-9) * h
        if k == 0:
            assert t_fix == pytest.approx(first, abs=1e-12)
        else:
            # later events: the fixed-step trajectory carries the earlier events' delays (as in the driveline's
            # CoupledClutches, docs/architecture.md), and at 1 ms the film contact falls on a frame end in exact
            # arithmetic (its switching function is +-1e-18 there, the sign set by rounding): that frame or the next
            assert t_fix == pytest.approx(first, abs=1e-12) or t_fix == pytest.approx(first + h, abs=1e-12)
    # after the lock-up (projected to zero slip at the step end) the slip speed stays zero
    iw = system.state_index("slip_speed")
    assert res.stats["final_state"][iw] == 0.0
    grid_ref = simulate(system, 1.0, rtol=1e-10, output_step=h)
    grid_fix = simulate(system, 1.0, fixed_step=h, output_step=h)
    w_max = np.abs(grid_ref.states[:, iw]).max()
    assert np.abs(grid_fix.states[:, iw] - grid_ref.states[:, iw]).max() < 0.02 * w_max


def test_emtc_bench_runs_fixed_step():
    """The EMTC bench (a Dormand-Prince model, 2 ms controller samples as break times) through the
    Rosenbrock loop at 1 ms: the controller samples land on frame ends; the shaft speeds follow the adaptive run."""
    grid = np.arange(0, 501) * 1e-3
    ref = simulate(MODELS["emtc_bench"](), 0.5, rtol=1e-10, sample_times=grid)
    res = simulate(MODELS["emtc_bench"](), 0.5, fixed_step=1e-3, sample_times=grid)  # (fresh memories each)
    assert res.status.ok and np.all(np.isfinite(res.states))
    assert list(res.events["event"][:2]) == list(ref.events["event"][:2])
    for t_fix, t_ref in zip(res.events["time_s"][:2], ref.events["time_s"][:2]):
        assert t_ref <= t_fix + 1e-12 and t_fix < t_ref + 2e-3  # (the controller's sample may shift it a frame)
    for name in ("omega_f", "omega_r"):
        i = res.state_columns.index(f"{name}_rad_s")
        assert np.abs(res.states[:, i] - ref.states[:, i]).max() < 0.1  # rad/s, of speeds around 100 rad/s
    assert res.stats["accepted_steps"] == 500


def test_ball_bounces_at_step_ends():
    system = toys.ball_system(method="dopri")
    ref = simulate(system, 2.0)
    res = simulate(system, 2.0, fixed_step=1e-3)
    t_ref = ref.events["time_s"].to_numpy()
    t_fix = res.events["time_s"].to_numpy()
    assert len(t_fix) == 4 and res.status.name == "TERMINATED"
    assert t_fix[0] == pytest.approx(math.ceil(t_ref[0] / 1e-3) * 1e-3, abs=1e-12)
    assert np.all(t_fix >= t_ref - 1e-12)


def test_driveline_clutch_modes_change_at_the_first_step_end_after_the_located_time():
    """Modelica's CoupledClutches as a driveline network (a Dormand-Prince model): every stick, reversal and
    release of the three clutches is recorded at the first 1 ms frame end at or after the adaptive run's instant."""
    from pathlib import Path

    from clutchlab.driveline.description import load_driveline

    example = Path(__file__).resolve().parents[2] / "examples" / "driveline_coupled_clutches.toml"
    system = load_driveline(example).driveline.system()
    ref = simulate(system, 1.5, rtol=1e-10)
    h = 1e-3
    res = simulate(system, 1.5, fixed_step=h, output_step=0.01)
    assert list(res.events["event"]) == list(ref.events["event"]) and len(res.events) >= 8
    assert list(res.events["element"]) == list(ref.events["element"])
    firsts = [math.ceil(t_ref / h - 1e-9) * h for t_ref in ref.events["time_s"]]
    # the first located stick (0.7096 s, before any mode change came late): at the next frame end
    assert res.events["time_s"][1] == pytest.approx(firsts[1], abs=1e-12) and ref.events["time_s"][1] < firsts[1]
    # all: at the first frame end at or after the adaptive instant, or one frame later (the fixed-step trajectory
    # carries the earlier delays; a switching function that reaches zero exactly on a frame end, at the break
    # time 1.25 s, crosses in the next frame)
    for t_fix, first in zip(res.events["time_s"], firsts):
        assert first - 1e-12 <= t_fix <= first + h + 1e-12


def test_batch_runs_fixed_step_like_simulate():
    from clutchlab.system import simulate_batch

    systems = [toys.linear_system(A_OSC * s, X0, method="dopri") for s in (0.5, 1.0, 2.0)]
    batch = simulate_batch(systems, 0.2, output_step=0.01, fixed_step=1e-3, check=True)
    for v, system in enumerate(systems):
        one = simulate(system, 0.2, output_step=0.01, fixed_step=1e-3)
        np.testing.assert_array_equal(batch.states[v], one.states)
    assert np.all(batch.stats["accepted_steps"] == 200)


def test_a_fixed_step_longer_than_the_run_or_the_output_step_is_refused():
    """``--fixed-step "1000 s"`` was one step over the whole run, a silent wrong answer (an E-clutch peak force of
    0 N; #33): a fixed step longer than the run, or than the output step, is refused by name; equal is a run."""
    from clutchlab.system import simulate_batch

    system = toys.linear_system(A_OSC, X0)
    with pytest.raises(ParameterError, match=r"fixed_step = 2 s is longer than the run \(1 s\)"):
        simulate(system, 1.0, fixed_step=2.0)
    with pytest.raises(ParameterError, match=r"fixed_step = 0.02 s is longer than the output step \(0.01 s\)"):
        simulate(system, 1.0, fixed_step=0.02, output_step=0.01)
    with pytest.raises(ParameterError, match=r"longer than the run"):
        simulate_batch([system, system], 0.5, fixed_step=1.0)
    res = simulate(system, 1.0, fixed_step=0.01, output_step=0.01)
    assert res.stats["accepted_steps"] == 100
    assert simulate(system, 1.0, fixed_step=1.0).stats["accepted_steps"] == 1


@pytest.mark.parametrize("command", [["driveline", "simulate", "driveline_coupled_clutches.toml"],
                                     ["eclutch", "simulate", "eclutch_launch.toml"],
                                     ["wet", "simulate", "wet_engagement.toml"],
                                     ["emtc", "simulate", "emtc_scenario.toml"]], ids=lambda c: c[0])
def test_every_simulate_command_refuses_a_fixed_step_longer_than_its_run(tmp_path, capsys, command):
    from pathlib import Path

    from clutchlab.cli import main

    examples = Path(__file__).resolve().parents[2] / "examples"
    out = tmp_path / "out.csv"
    code = main([*command[:2], str(examples / command[2]), "-o", str(out), "--fixed-step", "1000 s"])
    err = capsys.readouterr().err.strip().splitlines()   # (the E-clutch says what it builds first)
    assert code == 2 and "Traceback" not in "\n".join(err)
    assert err[-1].startswith("clutchlab: error: fixed_step = 1000 s is longer than the run"), err
    assert not out.exists()


def test_an_advance_of_more_than_a_million_fixed_steps_is_refused_at_once():
    """``solver.fixed_step = 1e-12`` made one 1 ms FMU step take minutes (#33): an advance that needs more than
    ``FIXED_STEP_BUDGET`` fixed steps is refused before it starts, through ``advance`` and ``step`` (the
    co-simulations' path), and the session stays usable."""
    import time

    from clutchlab.errors import SimulationError
    from clutchlab.system import FIXED_STEP_BUDGET

    sim = Simulation(toys.linear_system(A_OSC, X0), fixed_step=1e-12)
    t0 = time.perf_counter()
    with pytest.raises(SimulationError, match=r"fixed_step = 1e-12 s: an advance of 0.001 s would take 1e\+09 steps"):
        sim.advance(1e-3)
    with pytest.raises(SimulationError, match="more than 1e\\+06 in one call"):
        sim.step(1e-3)
    assert time.perf_counter() - t0 < 5.0 and sim.time == 0.0
    sim.advance(FIXED_STEP_BUDGET * 1e-12)      # the budget itself runs
    assert sim.time == pytest.approx(1e-6) and sim.stats["accepted_steps"] == FIXED_STEP_BUDGET


def test_an_fmu_co_simulation_with_a_tiny_fixed_step_fails_its_step_not_its_host():
    from clutchlab.errors import SimulationError
    from clutchlab.fmu.eclutch import EClutchCoSimulation

    c = EClutchCoSimulation(**{"solver.fixed_step": 1e-12})
    c.initial_outputs({v.name: v.start for v in c.inputs})
    with pytest.raises(SimulationError, match="would take 1e\\+09 steps"):
        c.do_step(0.0, 1e-3, {v.name: v.start for v in c.inputs})
