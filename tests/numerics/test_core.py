"""The integrator core on its own, as SciPy's test_ivp tests solve_ivp.

Toy systems (tests/_support/core_toys.py) implement the system contract like
the clutch models do; every expected value here is a closed form or computed
independently of the core (SciPy's brentq on a closed-form trajectory).
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

import core_toys as toys
from session_check import assert_packed_as_compiled
from hypothesis_budget import examples
from clutchlab import SimulationError
from clutchlab.numerics import core
from clutchlab.numerics.status import Status
from clutchlab.errors import ParameterError
from clutchlab.system import Simulation, Variants, evaluate, simulate, simulate_batch

METHODS = ("dopri", "rodas")
OSC = [[0.0, 1.0], [-1.0, 0.0]]  # x'' = -x


def _osc_error(method, rtol):
    res = simulate(toys.linear_system(OSC, [1.0, 0.0], method=method), 10.0, rtol=rtol, atol=rtol * 1e-2,
                   output_step=0.25)
    return np.max(np.abs(res.states[:, 0] - np.cos(res.time)) + np.abs(res.states[:, 1] + np.sin(res.time)))


@pytest.mark.parametrize("method", METHODS)
def test_error_follows_the_tolerance(method):
    """Error against the analytic solution shrinks with rtol and stays within a modest multiple of it."""
    tols = [1e-4, 1e-6, 1e-8] if method == "dopri" else [1e-3, 1e-5, 1e-7]
    errs = [_osc_error(method, r) for r in tols]
    for r, e in zip(tols, errs):
        assert e < 200 * r, (r, e)
    assert errs[0] > 10 * errs[1] > 100 * errs[2] * 0.1
    assert errs[2] < errs[1] < errs[0]


def _fixed_step_error(method, h):
    # huge tolerances accept every step; max_step == first_step fixes the step size
    res = simulate(toys.linear_system(OSC, [1.0, 0.0], method=method), 2.0, rtol=0.5, atol=1e3, max_step=h,
                   first_step=h, output_step=2.0)
    return abs(res.states[-1, 0] - math.cos(2.0))


@pytest.mark.parametrize("method, order", [("dopri", 5), ("rodas", 3)])
def test_observed_order_of_convergence(method, order):
    hs = [0.1, 0.05, 0.025]
    errs = [_fixed_step_error(method, h) for h in hs]
    slopes = [math.log(errs[i] / errs[i + 1]) / math.log(2.0) for i in range(2)]
    for s in slopes:
        assert order - 0.4 < s < order + 0.8, slopes


def _dense_errors(hs):
    """Largest error of samples half-way between fixed steps h (dense output), and of the located root of
    sin(t) at pi (an event on the dense output), against the closed forms."""
    dense, event = [], []
    for h in hs:
        ts = (np.arange(int(round(2.0 / h))) + 0.5) * h
        res = simulate(toys.linear_system(OSC, [1.0, 0.0]), 2.0, rtol=0.5, atol=1e3, max_step=h, first_step=h,
                       sample_times=ts)
        dense.append(np.max(np.abs(res.states[:, 0] - np.cos(res.time))))
        res = simulate(toys.sine_system(), 4.0, rtol=0.5, atol=1e3, max_step=2 * h, first_step=2 * h,
                       output_step=4.0)
        event.append(abs(res.events.time_s.iloc[0] - math.pi))
    return dense, event


def test_dense_output_and_events_have_the_order_of_the_steps():
    """Dormand-Prince's continuous extension is of order 4 (local error h^5, as the step's global error):
    samples between steps and event times converge at order 5 together with the steps.  The cubic Hermite
    interpolant alone converges at order 4 (measured 4.00 here) and put sampled wet-clutch results 1e-7
    off at rtol 1e-11."""
    hs = [0.1, 0.05, 0.025]
    dense, event = _dense_errors(hs)
    for errs in (dense, event):
        slopes = [math.log(errs[i] / errs[i + 1]) / math.log(2.0) for i in range(len(hs) - 1)]
        assert all(4.6 < s < 5.8 for s in slopes), (errs, slopes)
    assert dense[0] < 1e-8 and event[0] < 1e-7


def test_rodas_is_stable_on_a_stiff_system_with_large_steps():
    """x0' = -1e6 x0, x1' = -x1: Rodas3 takes steps far beyond the explicit stability limit (2.8e-6 s)."""
    a = [[-1e6, 0.0], [0.0, -1.0]]
    res = simulate(toys.linear_system(a, [1.0, 1.0], method="rodas"), 5.0, rtol=1e-6, atol=1e-9, output_step=0.5)
    assert res.stats["accepted_steps"] < 2000
    assert np.allclose(res.states[1:, 0], 0.0, atol=1e-9)
    assert np.allclose(res.states[:, 1], np.exp(-res.time), rtol=1e-4)


def test_rodas_index1_algebraic_row_with_the_mass_matrix():
    """x' = -x + y, 0 = y - x/2 (mass row 0): x = exp(-t/2), y = x/2 on the whole trajectory."""
    a = [[-1.0, 1.0], [-0.5, 1.0]]
    res = simulate(toys.linear_system(a, [1.0, 0.5], method="rodas", mass=[1.0, 0.0]), 4.0, rtol=1e-7, atol=1e-10,
                   output_step=0.5)
    assert np.allclose(res.states[:, 0], np.exp(-res.time / 2), rtol=1e-5)
    # the algebraic row is interpolated linearly between steps (the step points themselves are exact)
    assert np.allclose(res.states[:, 1], res.states[:, 0] / 2, rtol=1e-4)
    steps = simulate(toys.linear_system(a, [1.0, 0.5], method="rodas", mass=[1.0, 0.0]), 4.0, rtol=1e-7, atol=1e-10)
    assert np.allclose(steps.states[:, 1], steps.states[:, 0] / 2, rtol=1e-9)


def _bounce_times(h0, e, n, g=9.81):
    t = math.sqrt(2 * h0 / g)
    v = g * t
    out = [t]
    for _ in range(n - 1):
        v *= e
        out.append(out[-1] + 2 * v / g)
    return np.array(out)


@pytest.mark.parametrize("method", METHODS)
def test_bouncing_ball_event_times_and_terminal_event(method):
    res = simulate(toys.ball_system(method=method), 10.0)
    assert res.status == Status.TERMINATED and res.ok
    assert list(res.events.event) == ["bounce"] * 4
    assert np.allclose(res.events.time_s, _bounce_times(1.0, 0.5, 4), rtol=0, atol=1e-9)
    assert res.stats["final_time"] == pytest.approx(_bounce_times(1.0, 0.5, 4)[-1], abs=1e-9)


@settings(max_examples=examples(40), deadline=None)
@given(y0=st.lists(st.floats(-1e3, 1e3).filter(lambda v: v == 0.0 or abs(v) > 1e-30), min_size=1, max_size=4),
       scale=st.sampled_from([1e-12, 1e-6, 1.0, 1e6, 1e12]), rtol=st.sampled_from([1e-3, 1e-6, 1e-9]),
       span=st.sampled_from([1e-9, 1e-3, 1.0, 100.0]), seed=st.integers(0, 2**16))
def test_the_starting_step_is_hairer_and_wanners_rule_as_scipy_writes_it(y0, scale, rtol, span, seed):
    """``dopri.initial_step`` + ``dopri.starting_step`` against SciPy's own ``select_initial_step`` (RK45: error
    order 4) on a linear right-hand side ``f(y) = A y + b``, capped as the core caps it (a tenth of the span,
    10 ms), with no floor (``h_min = 0``).  Before #30's fix the core used the first guess ``0.01 d0 / d1`` alone, 1e-14 s for a state of
    4e-12 against a derivative of 4 at rtol 1e-9 (the driveline's stall)."""
    from scipy.integrate._ivp.common import select_initial_step

    from clutchlab.numerics import dopri

    rng = np.random.default_rng(seed)
    n = len(y0)
    y0 = np.array(y0)
    A = rng.normal(size=(n, n)) * scale
    b = rng.normal(size=n) * scale
    atol = np.full(n, rtol * 1e-3)

    def fun(t, y):
        return A @ y + b

    f0 = fun(0.0, y0)
    expected = select_initial_step(fun, 0.0, y0, span, min(span / 10.0, 1e-2), f0, 1.0, 4, rtol, atol)
    h0 = dopri.initial_step(y0, f0, rtol, atol, span, 4)
    got = dopri.starting_step(h0, y0, f0, fun(h0, y0 + h0 * f0), rtol, atol, span, 4, 0.0)
    assert got == pytest.approx(expected, rel=1e-12)


def test_a_tiny_state_against_a_large_derivative_starts_above_the_time_resolution():
    """The stall #30's thorough profile found (two driveline inertias, one at 4e-12 rad/s, the other driven by
    4 N m): a tiny state against a large derivative made the first guess ``0.01 d0 / d1`` fall to the core's
    floor, here 1e-17 s, and the run stopped at t = 0 (STEP_UNDERFLOW).  Hairer and Wanner's whole rule is not
    enough here (``100 h0`` = 1e-15 s); its growth limit raised to 100 floors is: the run goes to the closed
    form ``x1 = 4 t``, ``x0`` unchanged."""
    sim = Simulation(toys.linear_system([[0.0, 0.0], [0.0, 0.0]], [4e-15, 0.0], b=[[0.0], [4.0]]), rtol=1e-9)
    sim.advance(1.0, [1.0])
    assert sim.time == 1.0
    assert sim.x[1] == pytest.approx(4.0, rel=1e-12)
    assert sim.x[0] == 4e-15


@settings(max_examples=examples(15), deadline=None)
@given(h0=st.floats(0.05, 5.0), e=st.floats(0.2, 0.9))
def test_bouncing_ball_any_height_and_restitution(h0, e):
    res = simulate(toys.ball_system(h0, e), 60.0)
    assert np.allclose(res.events.time_s, _bounce_times(h0, e, 4), rtol=0, atol=1e-8)


def _belt_closed_form(m=1.0, k=100.0, vb=0.1, fn=10.0, mu_s=0.5, mu_k=0.3):
    """Break-away, stick and next break-away times of the belt oscillator, from its closed-form trajectory."""
    w = math.sqrt(k / m)
    t_b = mu_s * fn / (k * vb)
    xb = mu_s * fn / k
    xeq = mu_k * fn / k
    a = xb - xeq

    def v(tau):  # slipping: x = xeq + a cos(w tau) + vb/w sin(w tau)
        return -a * w * math.sin(w * tau) + vb * math.cos(w * tau)

    # first return of the speed to the belt speed: bracket on a fine grid, then brentq
    taus = np.linspace(1e-6, 2 * math.pi / w, 20001)
    vals = np.array([v(t) - vb for t in taus])
    i = np.flatnonzero((vals[:-1] < 0) & (vals[1:] >= 0))[0]
    tau = brentq(lambda t: v(t) - vb, taus[i], taus[i + 1], xtol=1e-15)
    x_stick = xeq + a * math.cos(w * tau) + vb / w * math.sin(w * tau)
    t_stick = t_b + tau
    t_b2 = t_stick + (xb - x_stick) / vb
    return t_b, t_stick, t_b2, x_stick


@pytest.mark.parametrize("method", METHODS)
def test_coulomb_stick_slip_against_the_closed_form(method):
    t_b, t_s, t_b2, x_s = _belt_closed_form()
    res = simulate(toys.belt_system(method=method), t_b2 + 0.1, output_step=1e-3, rtol=1e-10 if method == "dopri"
                   else 1e-8)
    ev = res.events
    assert list(ev.event[:3]) == ["breakaway", "stick", "breakaway"]
    tol = 1e-8 if method == "dopri" else 1e-6
    assert ev.time_s.iloc[0] == pytest.approx(t_b, abs=tol)
    assert ev.time_s.iloc[1] == pytest.approx(t_s, abs=tol)
    assert ev.time_s.iloc[2] == pytest.approx(t_b2, abs=tol)
    # stuck: the mass moves with the belt, exactly
    stuck = (res.time > t_s + 1e-6) & (res.time < t_b2 - 1e-6)
    assert np.all(res.mode("friction")[stuck] == "stick")
    assert np.allclose(res.states[stuck, 1], 0.1, atol=1e-12)
    assert np.allclose(res.states[stuck, 0], x_s + 0.1 * (res.time[stuck] - t_s), atol=1e-7)


@pytest.mark.parametrize("direction, expected", [(0, [math.pi, 2 * math.pi, 3 * math.pi]),
                                                 (1, [2 * math.pi]), (-1, [math.pi, 3 * math.pi])])
def test_event_direction_flags(direction, expected):
    res = simulate(toys.sine_system(direction), 10.0)
    assert np.allclose(res.events.time_s, expected, atol=1e-9)


@pytest.mark.parametrize("direction, roots", [(4, [math.pi, 2 * math.pi, 3 * math.pi]), (3, [2 * math.pi]),
                                              (-3, [math.pi, 3 * math.pi])])
def test_a_waypoint_ends_a_step_just_past_its_root_and_records_nothing(direction, roots):
    """A waypoint (direction +3 rising, -3 falling, 4 either way: the EMTC's coil current crossing a Preisach grid
    line or turning) ends a Dormand-Prince step just past each crossing in its direction, within 1 % of that step,
    and is no event; crossings the other way are stepped over."""
    free = simulate(toys.sine_system(0), 10.0)   # (every step recorded: no output grid)
    res = simulate(toys.sine_system(direction), 10.0)
    assert len(res.events) == 0 and len(free.events) == 3
    t = res.time
    assert np.allclose(res.states[:, 0], np.sin(t), atol=1e-8)
    for r in (math.pi, 2 * math.pi, 3 * math.pi):
        k = int(np.searchsorted(t, r))   # the first step end at or past the root
        located = 0.0 <= t[k] - r <= 0.0101 * (t[k] - t[k - 1])
        assert located == (r in roots), (direction, r, t[k - 1], t[k])


@pytest.mark.parametrize("method", METHODS)
def test_break_times_end_steps_and_restart_the_model(method):
    res = simulate(toys.sine_system(0, period=0.25, method=method), 2.0, output_step=0.5)
    # restart runs at t0 and at each of the 7 break times before the end (0.25 ... 1.75)
    assert res.stats["final_modes"][0] == 8
    assert np.allclose(res.states[:, 0], np.sin(res.time), atol=1e-8)


@pytest.mark.parametrize("method", METHODS)
def test_a_run_recorded_at_every_step_goes_on_across_its_buffers_without_a_restart(method):
    """A run recorded at every accepted step fills buffers of 256, 512, 1024, ... rows and the core resumes it in a
    new one each time (``RECORD_FULL``).  Before issue #30's seed 2074 each resumption called the model's
    ``restart`` as an input change would: the toy counted 11 (Dormand-Prince) and 34 (Rodas3) restarts where its
    breaks give 8, and a driveline
    searched its stuck sets again at a buffer's end, so its result depended on where the buffers ended.  Now the
    run goes on as one call (``core.RESUME_NOTE``): the restarts are those of the breaks, and the states are the
    sampled run's to the last bit."""
    system = toys.sine_system(0, period=0.25, method=method)
    every = simulate(system, 2.0, max_step=1e-3, first_step=1e-3)   # 2,000 steps: four buffers
    assert every.stats["accepted_steps"] > 256 + 512 + 1024
    sampled = simulate(system, 2.0, max_step=1e-3, first_step=1e-3, output_step=0.5)
    assert every.stats["final_modes"][0] == sampled.stats["final_modes"][0] == 8   # t0 and 7 breaks
    assert every.stats["final_state"][0] == sampled.stats["final_state"][0]
    assert np.all(np.diff(every.modes[:, 0]) >= 0) and every.modes[-1, 0] == 8


@pytest.mark.parametrize("method", METHODS)
def test_a_record_full_at_a_break_leaves_the_break_to_no_one(method):
    """The first buffer of an every-step record (256 rows: the start and 255 steps) fills at the toy's first break,
    0.25 s, where steps of 0.25/255 s end.  A call that ended there with ``RECORD_FULL`` before taking the break, and
    a resumption that takes no restart, skipped it: the restarts counted 7, not 8 (the sixtieth session's seed 2090,
    a brake whose normal force stepped on at that instant was left free until the next break).  The break is taken
    before the call ends."""
    system = toys.sine_system(0, period=0.25, method=method)
    h = 0.25 / 255
    every = simulate(system, 2.0, max_step=h, first_step=h, rtol=1e-6, atol=1e-6)   # (steps of max_step)
    assert np.any(np.abs(every.time[255:257] - 0.25) == 0.0)   # (the buffer's last row or the next one's first)
    assert every.stats["final_modes"][0] == 8   # t0 and 7 breaks


@pytest.mark.parametrize("method", METHODS)
def test_resumed_advance_matches_one_run(method):
    system = toys.belt_system(method=method)
    one = simulate(system, 1.5, rtol=1e-9, output_step=0.5)
    sim = Simulation(system, rtol=1e-9)
    for t in np.linspace(0.01, 1.5, 150):
        sim.advance(t)
    assert sim.time == pytest.approx(1.5)
    assert np.allclose(sim.x, one.states[-1], atol=1e-6)
    ev = sim.events()
    assert list(ev.event) == list(one.events.event)
    assert np.allclose(ev.time_s, one.events.time_s, atol=1e-8)
    y = sim.outputs()
    assert np.allclose(y, sim.x)


@pytest.mark.parametrize("method", METHODS)
def test_packed_session_calls_equal_dispatched_ones(method):
    """A session packs its objects once and calls the model through one compiled entry
    (clutchlab.numerics.session): the same steps, events, outputs and reports, bit for bit, as a session whose
    calls all go through numba's dispatcher with every argument; replaced arrays, inputs and reports are
    packed again at the next call."""
    system = toys.belt_system(method=method)
    packed, plain = Simulation(system, rtol=1e-9), Simulation(system, rtol=1e-9)
    plain._pack = False  # (every call of this one dispatches)
    assert packed._pack_after == 2
    packed._pack_after = 0  # (packed from the first call)
    for sim in (packed, plain):
        sim.report([("state", 1), ("output", 0), ("mode", 0), ("mode_is", 0, 1), ("state", "position")])
    for k, t in enumerate(np.linspace(0.01, 1.5, 150)):
        if k % 3:
            packed.advance(t)
            plain.advance(t)
            r_packed, r_plain = packed.outputs(), plain.outputs()
        else:
            r_packed, r_plain = packed.step(t).copy(), plain.step(t).copy()
            assert np.array_equal(r_packed, [packed.x[1], packed.outputs()[0], packed.m[0], packed.m[0] == 1,
                                             packed.x[0]])
        assert np.array_equal(packed.x, plain.x) and np.array_equal(packed.m, plain.m)
        assert np.array_equal(r_packed, r_plain) and packed.time == plain.time
        if k == 70:
            packed.x = packed.x.copy()  # a new array of the same type: packed again, and then used
            assert packed._fast is None
    assert packed._fast[1].owners[1] is packed.x and plain._fast[1] is None
    assert packed.stats == plain.stats
    pd_packed, pd_plain = packed.events(), plain.events()
    assert list(pd_packed.event) == list(pd_plain.event) and np.array_equal(pd_packed.time_s, pd_plain.time_s)


@pytest.mark.parametrize("system", [toys.belt_system(), toys.ball_system(1.0, 0.5, method="rodas"),
                                    toys.linear_system(OSC, [1.0, 0.0]), toys.chain_system(pattern=True)],
                         ids=["belt", "ball", "linear", "chain"])
def test_a_session_table_written_from_python_equals_the_compiled_one(system):
    assert_packed_as_compiled(Simulation(system))


def test_a_session_packed_by_the_compiled_packing_runs_the_same(monkeypatch):
    """A structure the Python packing does not know is packed by the model's compiled session_pack."""
    from clutchlab.numerics import session as S

    system = toys.belt_system()
    python, compiled = Simulation(system, rtol=1e-9), Simulation(system, rtol=1e-9)
    python._pack_after = compiled._pack_after = 0
    python.advance(0.5)
    monkeypatch.setattr(S, "_plan", lambda args_ty: None)
    compiled.advance(0.5)
    assert compiled._fast[1] is not None
    assert np.array_equal(python.x, compiled.x) and np.array_equal(python.outputs(), compiled.outputs())


def test_the_session_codes_of_system_and_numerics_agree():
    from clutchlab import system as contract
    from clutchlab.numerics import session as S

    assert (contract._ADVANCE, contract._OUTPUTS) == (S.ADVANCE, S.OUTPUTS)
    assert contract._REPORT_KINDS == {"output": S.REPORT_OUTPUT, "state": S.REPORT_STATE, "mode": S.REPORT_MODE,
                                      "mode_is": S.REPORT_MODE_IS}


def test_a_session_packs_at_its_third_call():
    """A session advanced once or twice (a settling run, a trim) goes through numba's dispatcher and compiles
    nothing more; the third call packs it."""
    sim = Simulation(toys.belt_system())
    sim.advance(0.1)
    sim.outputs()
    assert sim._fast is None
    sim.advance(0.2)
    assert sim._fast[1] is not None


def test_report_chooses_values_by_name_or_index():
    sim = Simulation(toys.belt_system())
    sim.report([("state", "velocity_m_s"), ("mode", "friction"), ("output", 0)])
    r = sim.step(0.2)
    assert np.array_equal(r, [sim.x[1], sim.m[0], sim.outputs()[0]]) and sim.reported() is r
    for bad in ([("state", 2)], [("output", "nope")], [("mode", "nope")], [("modes", 0)], [("mode_is", 0)],
                [("state", True)]):
        with pytest.raises(ParameterError, match="report|unknown"):
            sim.report(bad)


def test_a_failed_step_leaves_the_report_of_the_last_good_one():
    sim = Simulation(toys.belt_system(), max_steps=40)
    r = sim.step(0.01).copy()
    with pytest.raises(SimulationError, match="step limit|steps"):
        sim.step(10.0)
    assert np.array_equal(sim._r, r)


def test_inputs_are_held_over_an_advance():
    """x' = u with u switched per call: a ramp of the held values."""
    system = toys.linear_system([[0.0]], [0.0], b=[[1.0]])
    sim = Simulation(system)
    sim.advance(1.0, [2.0])
    sim.advance(3.0, [-1.0])
    assert sim.x[0] == pytest.approx(2.0 * 1.0 - 1.0 * 2.0, abs=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_batch_equals_single_runs(method):
    systems = [toys.ball_system(h0, e, method=method) for h0, e in [(1.0, 0.5), (2.0, 0.7), (0.3, 0.4)]]
    batch = simulate_batch(systems, 3.0, output_step=0.1, event_capacity=16)
    assert batch.batch and batch.states.shape == (3, 31, 2)
    for v, s in enumerate(systems):
        single = simulate(s, 3.0, output_step=0.1)
        n = single.time.size
        assert np.array_equal(batch.states[v, :n], single.states)
        ev = batch.events[batch.events.variant == v]
        assert np.array_equal(ev.time_s.to_numpy(), single.events.time_s.to_numpy())
    assert list(batch.status) == [Status.TERMINATED] * 3


@pytest.mark.parametrize("chunk", [1, 2, 64])
def test_batch_from_a_generator_equals_the_list(chunk):
    """Variants drawn from a generator run chunk by chunk while the next chunk is built: the same states,
    events (numbered across the chunks), counters and memories as the list of the same systems."""
    cases = [(1.0, 0.5), (2.0, 0.7), (0.3, 0.4), (1.5, 0.6), (0.8, 0.3)]
    listed = simulate_batch([toys.ball_system(h0, e) for h0, e in cases], 3.0, output_step=0.1, event_capacity=16)
    built = []

    def make():
        for h0, e in cases:
            built.append((h0, e))
            yield toys.ball_system(h0, e)

    drawn = simulate_batch(make(), 3.0, output_step=0.1, event_capacity=16, chunk=chunk)
    assert built == cases
    assert np.array_equal(drawn.states, listed.states, equal_nan=True) and np.array_equal(drawn.modes, listed.modes)
    assert drawn.events.equals(listed.events) and set(drawn.events.variant) == set(range(len(cases)))
    for key in listed.stats:
        assert np.array_equal(drawn.stats[key], listed.stats[key]), key
    assert list(drawn.status) == list(listed.status)


def test_batch_from_a_generator_grows_its_records(monkeypatch):
    """Records reserved for fewer variants than come double (the runs before keep their rows); a variant
    that fails has NaN after the last sample it reached (the records are allocated empty)."""
    import clutchlab.system as system_module

    monkeypatch.setattr(system_module, "_PIPELINE_RESERVE", 2)
    cases = [(1.0 + 0.1 * k, 0.3 + 0.05 * k) for k in range(11)]
    listed = simulate_batch([toys.ball_system(h0, e) for h0, e in cases], 3.0, output_step=0.1, event_capacity=16)
    drawn = simulate_batch((toys.ball_system(h0, e) for h0, e in cases), 3.0, output_step=0.1, event_capacity=16,
                           chunk=1)
    assert drawn.states.shape == listed.states.shape == (11, 31, 2)
    assert np.array_equal(drawn.states, listed.states, equal_nan=True) and drawn.events.equals(listed.events)
    # (3 steps: the balls fall and bounce four times in 7 since the core's starting step is Hairer and Wanner's
    # whole rule, #30)
    short = simulate_batch((toys.ball_system(h0, e) for h0, e in cases[:3]), 3.0, output_step=0.1, max_steps=3,
                           chunk=1)
    assert all(s == Status.STEP_LIMIT for s in short.status)
    reached = ~np.isnan(short.states[:, :, 0])
    assert reached[:, 0].all() and not reached[:, -1].any()
    assert np.array_equal(np.isnan(short.outputs).all(axis=2), ~reached)


def test_batch_from_a_generator_that_fails_stops_its_runs():
    """An error raised while building a variant reaches the caller (no run left waiting)."""
    def make():
        yield toys.ball_system(1.0, 0.5)
        yield toys.ball_system(2.0, 0.7)
        raise ValueError("variant 2 cannot be built")

    with pytest.raises(ValueError, match="variant 2 cannot be built"):
        simulate_batch(make(), 3.0, output_step=0.1, chunk=1)


def test_batch_from_a_generator_refuses_bad_requests():
    with pytest.raises(ParameterError, match="no variants"):
        simulate_batch(iter(()), 1.0)
    with pytest.raises(ParameterError, match="chunk = 0"):
        simulate_batch(iter([toys.linear_system([[-1.0]], [1.0])]), 1.0, chunk=0)
    mixed = iter([toys.linear_system([[-1.0]], [1.0]), toys.linear_system(OSC, [1.0, 0.0])])
    with pytest.raises(ParameterError, match="variant 1 has other states"):
        simulate_batch(mixed, 1.0, chunk=1)

def test_stacked_variants_equal_single_runs_and_the_list_of_systems():
    """A batch given as :class:`Variants` (parameters stacked along a first axis) runs each variant on its row.

    x' = -k x with k per variant: each variant's end state is exp(-k t_end), the same as its own run and as
    the batch of the same systems given as a list.
    """
    rates = np.array([0.5, 1.0, 2.0, 4.0])
    base = toys.linear_system([[-1.0]], [1.0])
    stacked = toys.LinearParams(-rates.reshape(4, 1, 1).copy(), np.zeros((4, 1, 0)))
    batch = Variants(base, stacked, np.ones((4, 1)), np.zeros((4, 0), np.int64), np.zeros((4, 0)))
    assert len(batch) == 4 and np.array_equal(batch.params_of(2).a, [[-2.0]])
    res = simulate_batch(batch, 1.5, output_step=0.5)
    assert res.states.shape == (4, 4, 1)
    np.testing.assert_allclose(res.states[:, -1, 0], np.exp(-1.5 * rates), rtol=1e-7)
    systems = [toys.linear_system([[-k]], [1.0]) for k in rates]
    listed = simulate_batch(systems, 1.5, output_step=0.5)
    assert np.array_equal(listed.states, res.states)
    for v, s in enumerate(systems):
        assert np.array_equal(simulate(s, 1.5, output_step=0.5).states, res.states[v])


def test_batch_refuses_variants_it_cannot_stack():
    """Parameters of other sizes, or stacked arrays of the wrong shape, are refused with the field named."""
    a = toys.linear_system(OSC, [1.0, 0.0])
    b = toys.linear_system(OSC, [1.0, 0.0], b=[[0.0], [1.0]])  # an input more: b is (2, 1), not (2, 0)
    with pytest.raises(ParameterError, match="parameter 'b'"):
        simulate_batch([a, b], 1.0)
    stacked = toys.LinearParams(np.zeros((3, 2, 2)), np.zeros((2, 2, 0)))  # b stacked for 2 variants, a for 3
    with pytest.raises(ParameterError, match="stacked field 'b'"):
        Variants(a, stacked, np.zeros((3, 2)), np.zeros((3, 0), np.int64), np.zeros((3, 0)))


def test_every_step_recording_grows_in_chunks():
    """Without output_step every accepted step is kept, across several record chunks."""
    res = simulate(toys.linear_system(OSC, [1.0, 0.0]), 200.0, rtol=1e-10, atol=1e-12)
    assert res.time.size == res.stats["accepted_steps"] + 1 > 4096
    assert np.all(np.diff(res.time) > 0)
    assert np.allclose(res.states[:, 0], np.cos(res.time), atol=1e-7)


def test_step_limit_is_a_status_and_an_error():
    system = toys.linear_system(OSC, [1.0, 0.0])
    with pytest.raises(SimulationError, match="step limit"):
        simulate(system, 10.0, max_steps=5)
    res = simulate(system, 10.0, max_steps=5, check=False)
    assert res.status == Status.STEP_LIMIT and not res.ok


def test_result_columns_carry_units_and_events_have_names():
    res = simulate(toys.ball_system(), 2.0, output_step=0.1)
    frame = res.to_dataframe()
    assert list(frame.columns) == ["time_s", "height_m", "velocity_m_s", "bounces"]
    assert res["height_m"].shape == res.time.shape
    assert set(res.events.columns) == {"time_s", "event", "element"}
    with pytest.raises(KeyError, match="not a state or output"):
        res["nothing_m"]


def test_evaluate_through_the_contract():
    dx, g, y = evaluate(toys.ball_system(), 0.0, [0.5, -1.0])
    assert np.allclose(dx, [-1.0, -9.81]) and np.allclose(g, [0.5]) and np.allclose(y, [0.5, -1.0])


@pytest.mark.parametrize("field", ["x", "m"])
def test_evaluate_refuses_arrays_shorter_than_the_declaration(field):
    """The compiled hooks read declared positions unchecked: a state or mode array of the wrong length (a
    caller written before a model declared one more mode) is refused by name, not read past its end."""
    system = toys.ball_system()
    short = {"x": dict(x=[0.5]), "m": dict(m=np.zeros(system.m0.size + 1, dtype=np.int64))}[field]
    with pytest.raises(ValueError, match=rf"evaluate: {field} of system 'ball' has shape"):
        evaluate(system, 0.0, **short)


def test_nan_error_norm_rejects_the_step():
    """x' = -sqrt(x) style blow-up: a NaN trial step is rejected and the run still ends correctly."""
    # x' = -50 x on [0, 1] started with a huge first step: the trial overflows to inf/NaN and must be rejected
    res = simulate(toys.linear_system([[-50.0]], [1.0]), 1.0, first_step=1e3, rtol=1e-8, output_step=0.5)
    assert res.ok
    assert res.states[-1, 0] == pytest.approx(math.exp(-50.0), abs=1e-11)


_TOY_MODULE = """
import numba, numpy as np
from typing import NamedTuple
from clutchlab.numerics import dispatch
from clutchlab.system import System, simulate

class DecayParams(NamedTuple):
    rate: float

@numba.njit(cache=True)
def rhs(t, x, u, m, p, dx, g):
    dx[0] = -RATE * p.rate * x[0]

@numba.njit(cache=True)
def out(t, x, u, m, p, y):
    y[0] = x[0]

@numba.njit(cache=True)
def upd(t, x, u, m, p, k, log):
    return 0

@numba.njit(cache=True)
def rst(t, x, u, m, p, log):
    return False

@numba.njit(cache=True)
def acc(t, x, u, m, p):
    return 0

@numba.njit(cache=True)
def brk(t, m, p):
    return np.inf

@numba.njit(cache=True)
def jac(t, x, u, m, p, J):
    return False

dispatch.register(DecayParams, rhs=rhs, outputs=out, update=upd, restart=rst, accept=acc, next_break=brk, jacobian=jac)
res = simulate(System("decay", DecayParams(1.0), (("x", "1"),), (("x", "1"),), np.ones(1), np.zeros(0, np.int64),
                      np.full(1, 1e-12), rtol=1e-10), 1.0)
print("decay", res.states[-1, 0])
"""

_BALL = ("import core_toys as T; from clutchlab.system import simulate; "
         "print('ball', simulate(T.ball_system(), 1.0).events.time_s.iloc[0])")


def _run(code, env, cwd=None):
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=cwd)
    assert out.returncode == 0, out.stderr[-3000:]
    seconds = [float(x) for x in __import__("re").findall(r"compile seconds ([0-9.]+)", out.stderr)]
    return out.stdout, seconds[-1] if seconds else None


def test_compiled_entry_points_are_per_model_and_follow_edits(tmp_path):
    """A model defined outside clutchlab neither poisons the cache for others nor runs stale code after an edit."""
    support = str(Path(__file__).parents[1] / "_support")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), CLUTCHLAB_COMPILE_NOTICE="0",
               CLUTCHLAB_COMPILE_REPORT="1", PYTHONPATH=os.pathsep.join([support, str(tmp_path)] + sys.path))
    (tmp_path / "toy_decay.py").write_text(_TOY_MODULE.replace("RATE", "1.0"))
    out, _ = _run("import toy_decay; " + _BALL.split("; ", 1)[1].replace("T.", "__import__('core_toys')."),
                  env)
    assert "decay 0.3678794" in out and "ball 0.4515" in out
    # another process that cannot import toy_decay still loads its own cached code
    env_b = dict(env, PYTHONPATH=os.pathsep.join([support] + sys.path))
    out, seconds = _run(_BALL, env_b)
    assert "ball 0.4515" in out
    assert seconds == 0.0, "the ball's cached entry points were not reused"
    # unchanged toy: reused from the cache
    out, seconds = _run("import toy_decay", env)
    assert "decay 0.3678794" in out and seconds == 0.0
    # edited toy (twice the rate): the new code runs
    time.sleep(0.01)
    (tmp_path / "toy_decay.py").write_text(_TOY_MODULE.replace("RATE", "2.0"))
    out, seconds = _run("import toy_decay", env)
    assert "decay 0.1353352" in out and seconds > 0.0


_SESSION = ("import core_toys as T; from clutchlab.system import Simulation; "
            "s = Simulation(T.belt_system({method!r})); s.advance(0.5); y = s.outputs(); r = s.step(1.0); "
            "print('belt', repr(float(y[1])), repr(float(r[0])), s.stats['accepted_steps'])")


@pytest.mark.parametrize("method", METHODS)
def test_packed_session_entries_are_reused_by_a_second_process(tmp_path, method):
    """The compiled session entries (clutchlab.numerics.session: packing, the call through the overloads'
    addresses) are cached like the rest: a second process loads them and compiles nothing."""
    support = str(Path(__file__).parents[1] / "_support")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), CLUTCHLAB_COMPILE_NOTICE="0",
               CLUTCHLAB_COMPILE_REPORT="1", PYTHONPATH=os.pathsep.join([support] + sys.path))
    first, seconds = _run(_SESSION.format(method=method), env)
    assert first.startswith("belt") and seconds > 0.0
    again, seconds = _run(_SESSION.format(method=method), env)
    assert again == first
    assert seconds == 0.0, "the session's cached entries were not reused"


def test_grouped_finite_difference_jacobian_matches_the_dense_one():
    """A declared sparsity pattern groups the difference columns: same solution, fewer right-hand sides."""
    dense = simulate(toys.chain_system(pattern=False), 0.2, output_step=0.01)
    grouped = simulate(toys.chain_system(pattern=True), 0.2, output_step=0.01)
    assert np.allclose(grouped.states, dense.states, rtol=0, atol=1e-9)
    assert grouped.stats["accepted_steps"] == dense.stats["accepted_steps"]
    per_jac_dense = 16
    per_jac_grouped = toys.chain_system(pattern=True)._jac_groups.shape[0]
    assert per_jac_grouped <= 6
    saved = dense.stats["rhs_evaluations"] - grouped.stats["rhs_evaluations"]
    assert saved >= (per_jac_dense - per_jac_grouped) * grouped.stats["jacobians"]


# ---- a hook's njit options (error model) hold inside the core too
_DIVISION_MODULE = """
import numba, numpy as np
from typing import NamedTuple
from clutchlab.numerics import dispatch
from clutchlab.system import System, evaluate

class NumpyErr(NamedTuple):
    scale: float

class PythonErr(NamedTuple):
    scale: float

def hooks(**options):
    @numba.njit(cache=True, **options)
    def rhs(t, x, u, m, p, dx, g):
        dx[0] = p.scale / (x[0] - x[0])  # a division by zero: inf under NumPy's error model

    @numba.njit(cache=True, **options)
    def out(t, x, u, m, p, y):
        y[0] = p.scale / (x[0] - x[0])

    @numba.njit(cache=True, **options)
    def upd(t, x, u, m, p, k, log):
        return 0

    @numba.njit(cache=True, **options)
    def rst(t, x, u, m, p, log):
        return False

    @numba.njit(cache=True, **options)
    def acc(t, x, u, m, p):
        return 0

    @numba.njit(cache=True, **options)
    def brk(t, m, p):
        return np.inf

    @numba.njit(cache=True, **options)
    def jac(t, x, u, m, p, J):
        return False

    return dict(rhs=rhs, outputs=out, update=upd, restart=rst, accept=acc, next_break=brk, jacobian=jac)

dispatch.register(NumpyErr, **hooks(error_model="numpy"))
dispatch.register(PythonErr, **hooks())

def system(params):
    return System("division", params, (("x", "1"),), (("y", "1"),), np.ones(1), np.zeros(0, np.int64),
                  np.full(1, 1e-9))

dx, _, y = evaluate(system(NumpyErr(2.0)))
print("numpy", dx[0], y[0])
try:
    evaluate(system(PythonErr(2.0)))
    print("python no error")
except ZeroDivisionError:
    print("python ZeroDivisionError")
# the same error out of a session, packed or through the dispatcher
from clutchlab.system import Simulation
for pack in (True, False):
    sim = Simulation(system(PythonErr(2.0)))
    sim._pack = pack
    sim._pack_after = 0  # (packed from the first call)
    for call in (lambda: sim.advance(1.0), sim.outputs, lambda: sim.step(1.0)):
        try:
            call()
            print("session no error")
        except ZeroDivisionError as exc:
            print("session", type(exc).__name__, exc)
"""


def test_hooks_keep_their_error_model_inside_the_core(tmp_path):
    """A hook declared with ``error_model="numpy"`` divides by zero to inf in the core; the default raises.

    (The core compiles each hook through an ``@overload``, which compiles with its own options: the hooks'
    were once silently replaced by numba's defaults.)  Run in a fresh process and cache, so that no hook
    compiled earlier with other options is loaded from the cache.
    """
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), CLUTCHLAB_COMPILE_NOTICE="0",
               PYTHONPATH=os.pathsep.join([str(tmp_path)] + sys.path))
    (tmp_path / "toy_division.py").write_text(_DIVISION_MODULE)
    out, _ = _run("import toy_division", env)
    assert "numpy inf inf" in out
    assert "python ZeroDivisionError" in out
    # an exception raised by a hook leaves a session as it leaves numba's dispatcher
    session = [line for line in out.splitlines() if line.startswith("session")]
    assert len(session) == 6 and session[:3] == session[3:] and "ZeroDivisionError" in session[0], out


def _ramp_error(res, sysm):
    p = sysm.params
    z = (res.time - p.t_event) / p.tau
    exact = np.where(z > 0, p.v_max * p.tau * (np.abs(z) - math.log(2.0) + np.log1p(np.exp(-2.0 * np.abs(z)))), 0.0)
    return float(np.max(np.abs(res.states[:, 0] - exact)))


def test_update_asks_for_a_restart_of_the_step_size():
    """An ``update`` that returns ``core.RESTART``: the step after the event starts from ``64 event_tol``, so
    a speed that reaches its limit within microseconds of the event is resolved.  Without it the step is
    cut down from its old size only until the error estimate, which cannot see a transient that lies
    between the first two stages, lets it pass, and x lags behind for good (what the wet clutch's piston
    did, 2.6e-7 m, at every rtol from 1e-3 to 1e-7)."""
    kept = toys.ramp_system(codes=(0, 0))
    restarted = toys.ramp_system(codes=(core.RESTART, 0))
    res_kept = simulate(kept, 0.2, output_step=0.01)
    res_restarted = simulate(restarted, 0.2, output_step=0.01)
    assert list(res_restarted.events.event) == ["start", "start_too"]
    err_kept, err_restarted = _ramp_error(res_kept, kept), _ramp_error(res_restarted, restarted)
    # measured: 6.4e-10 m with the restart, 6.2e-7 m without (atol 1e-8 m; v_max tau ln 2 = 6.9e-8 m)
    assert err_restarted < 1e-9 < 1e-7 < err_kept
    # and the first step after the event is the short one
    steps = simulate(restarted, 0.2)
    after = steps.time[steps.time > restarted.params.t_event]
    assert after[0] - restarted.params.t_event <= 64.0 * restarted.event_tol * (1.0 + 1e-9)


def test_a_terminal_update_wins_over_a_restart_at_the_same_event():
    """Two switching functions crossing at one instant: one update asks for a restart, the other ends the run."""
    for codes in ((core.RESTART, core.TERMINAL), (core.TERMINAL, core.RESTART)):
        res = simulate(toys.ramp_system(codes=codes), 0.2, check=False)
        assert res.status == Status.TERMINATED, codes
        assert res.time[-1] == pytest.approx(0.0723, abs=1e-9)


def test_a_checked_grid_is_checked_once_and_runs_like_any_grid():
    """``checked_grid``: refused if not finite and increasing; a run on it is the run on a copy of it (which
    ``sample_grid`` checks again), and ``sample_grid`` hands the very array on."""
    from clutchlab.system import checked_grid, sample_grid

    for bad in ([0.0, 0.2, 0.1], [0.0, float("nan"), 0.3], [0.0, float("inf")]):
        with pytest.raises(ParameterError, match="finite and increasing"):
            checked_grid(bad)
    ts = checked_grid(np.arange(41) / 20.0)
    assert sample_grid(0.0, 2.0, None, ts) is ts
    with pytest.raises(ParameterError, match="within"):   # the bounds of the run are still checked
        sample_grid(0.0, 1.0, None, ts)
    a = simulate(toys.ball_system(), 2.0, sample_times=ts)
    b = simulate(toys.ball_system(), 2.0, sample_times=ts.copy())
    assert np.array_equal(a.time, b.time) and np.array_equal(a.states, b.states)
    assert a.time is not ts


@pytest.mark.parametrize("method", METHODS)
def test_hooks_without_reference_counting_run_like_the_others(method):
    """Hooks declared with ``numba.njit(_nrt=False)`` are compiled into the core so (the options key of
    ``dispatch``) and give the same run, bit for bit, as the same hooks with numba's reference counting."""
    from clutchlab.numerics import dispatch

    sysm = toys.linear_system_no_refcount(OSC, [1.0, 0.0], method=method)
    assert dispatch._options_key(dispatch._MODELS[type(sysm.params)]["rhs"])[2] is False
    a = simulate(sysm, 10.0, output_step=0.25)
    b = simulate(toys.linear_system(OSC, [1.0, 0.0], method=method), 10.0, output_step=0.25)
    assert np.array_equal(a.states, b.states) and np.array_equal(a.outputs, b.outputs)
    assert a.stats["rhs_evaluations"] == b.stats["rhs_evaluations"]
