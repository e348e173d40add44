"""The compiled closed loop (clutchlab.numerics.sampled in each model's entry) against the Python loop.

Both loops do the same arithmetic, so a run must give the same samples (to the last bits of the
controller's sums), the same events and the same solver counters; the Python loop is itself checked against python-control's exact
sampled-data loop (test_design.py)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

control = pytest.importorskip("control")

from clutchlab.control.design import PI, ScheduledPI  # noqa: E402
from clutchlab.control.loop import closed_loop  # noqa: E402
from clutchlab.errors import ParameterError, SimulationError  # noqa: E402
from core_toys import linear_system  # noqa: E402

A = np.array([[0.0, 1.0], [-40.0, -3.0]])
B = np.array([[0.0], [40.0]])


def _same(a, b):
    # the compiled loop sums the controller's matrix-vector products in index order, numpy's BLAS may not:
    # a last-bit difference (1e-15 near a zero crossing) is allowed, no more
    pd.testing.assert_frame_equal(a.frame, b.frame, check_exact=False, rtol=1e-12, atol=1e-12)
    pd.testing.assert_frame_equal(a.events, b.events)
    assert a.stats == b.stats


@settings(deadline=None, max_examples=25)
@given(kp=st.floats(0.05, 2.0), ti=st.floats(0.02, 1.0), pole=st.floats(-0.9, 0.9), delay=st.sampled_from([0, 1]),
       limit=st.one_of(st.none(), st.floats(0.01, 0.5)), fixed=st.booleans())
def test_compiled_loop_equals_the_python_loop(kp, ti, pole, delay, limit, fixed):
    """Any discrete LTI controller (a PI in series with a first-order filter), with or without a delay,
    limits that bind or not, adaptive or fixed-step model."""
    Ts = 0.01
    s = linear_system(A, np.zeros(2), B)
    if limit is not None:
        s = s.replace(limits={"u0": (-limit, limit)})
    C = PI(kp, ti).discrete(Ts) * control.tf([1.0 - pole, 0.0], [1.0, -pole], Ts)
    run = dict(measure=["x0"], actuate=["u0"], reference=lambda t: 0.1 if t < 0.2 else -0.05, delay=delay,
               fixed_step=Ts / 4 if fixed else None)
    fast = closed_loop(s, C, Ts, 0.5, **run)
    slow = closed_loop(s, C, Ts, 0.5, compiled=False, **run)
    _same(fast, slow)
    if limit is not None:
        assert fast.frame["u0_1"].abs().max() <= limit


def test_compiled_loop_with_two_signals_and_two_inputs():
    """A MIMO controller: both states measured, both inputs actuated (matrix products in the loop)."""
    Ts = 0.01
    s = linear_system(A, np.zeros(2), np.array([[0.0, 0.2], [40.0, 0.0]]))
    K = control.ss([[0.5, 0.0], [0.1, 0.3]], [[1.0, 0.0], [0.0, 1.0]], [[0.2, 0.05], [0.0, 0.1]],
                   [[0.4, 0.0], [0.1, 0.2]], Ts)
    run = dict(measure=["x0", "x1"], actuate=["u0", "u1"], reference=[0.1, 0.0])
    _same(closed_loop(s, K, Ts, 0.3, **run), closed_loop(s, K, Ts, 0.3, compiled=False, **run))


def test_compiled_scheduled_pi_on_the_wet_engagement_measures_an_output():
    """The wet worked design's controller (gain-scheduled PI with feedforward and conditional integration)
    reading the torque sensor, an output of the model: compiled and Python loops give the same run."""
    from clutchlab.demo import control as demo
    from clutchlab.wet.bench import EngagementProtocol
    from clutchlab.wet.params import WetClutch
    from clutchlab.wet.system import engagement_system
    import dataclasses

    protocol = EngagementProtocol().scenario(WetClutch.paper(), "speed")
    s = engagement_system(dataclasses.replace(protocol, force_time=np.array([0.0, 1.0]),
                                              force_value=np.array([0.0, 0.0])))
    torques = np.array([5.0, 50.0, 100.0])
    ctrl = ScheduledPI(torques, np.full(3, 20.0), np.full(3, 0.05), np.array([900.0, 2500.0, 4000.0]), 1e-3,
                       demo._wet_reference, (0.0, 8000.0), 0.1)
    run = dict(measure=["sensor_torque"], actuate=["force_reference"], memory=[0.0])
    fast = closed_loop(s, ctrl, 1e-3, 0.5, **run)
    slow = closed_loop(s, ctrl, 1e-3, 0.5, compiled=False, **run)
    _same(fast, slow)
    assert fast.frame["force_reference_N"].max() > 1000.0  # the controller did act


def test_compiled_loop_refusals_and_failures():
    Ts = 0.01
    s = linear_system(A, np.zeros(2), B)
    with pytest.raises(ParameterError, match="runs in the Python loop"):
        closed_loop(s, lambda t, y, m: np.zeros(1), Ts, 0.1, measure=["x0"], actuate=["u0"], compiled=True)
    pi = ScheduledPI(np.array([0.0, 1.0]), np.ones(2), np.ones(2), None, Ts, lambda t: 1.0)
    with pytest.raises(ParameterError, match="one signal and actuates one input"):
        closed_loop(s, pi, Ts, 0.1, measure=["x0", "x1"], actuate=["u0"])
    # a diverging loop: the model's failure reaches the caller as from Simulation.advance
    unstable = PI(-1e6, 1e-4).discrete(Ts)
    with pytest.raises(SimulationError, match="linear"):
        closed_loop(s, unstable, Ts, 5.0, measure=["x0"], actuate=["u0"], reference=1.0, max_step=1e-3)


def test_compiled_loop_on_the_eclutch_with_friction_events():
    """The stiff E-clutch (Rodas3, index-1 rows, stick/slip events of the seals) under a PI designed on its
    linear model: LTI and scheduled forms, adaptive and fixed-step, the same run in both loops."""
    from clutchlab.control import linearize
    from clutchlab.control.design import pi_for_phase_margin
    from clutchlab.eclutch import EClutch

    op = EClutch().operating_point(4e-3)
    G = linearize(op, inputs=["motor_voltage"], outputs=["bearing_position"])
    pi = pi_for_phase_margin(G, 5.0, 60.0)
    lim = op.system.limits["motor_voltage"]
    run = dict(measure=["bearing_position"], actuate=["motor_voltage"])
    lti = dict(run, reference=4.3e-3)
    _same(closed_loop(op, pi.discrete(1e-3), 1e-3, 0.15, **lti),
          closed_loop(op, pi.discrete(1e-3), 1e-3, 0.15, compiled=False, **lti))
    sched = ScheduledPI(np.array([2e-3, 6e-3]), np.array([pi.kp, 0.5 * pi.kp]), np.array([pi.ti, pi.ti]), None,
                        1e-3, lambda t: 4.3e-3 if t < 0.08 else 3.9e-3, lim)
    for fixed in (None, 1e-3):
        fast = closed_loop(op, sched, 1e-3, 0.15, memory=[op.u[0]], fixed_step=fixed, **run)
        slow = closed_loop(op, sched, 1e-3, 0.15, memory=[op.u[0]], fixed_step=fixed, compiled=False, **run)
        _same(fast, slow)
        assert len(fast.events) > 0  # the seals stick and slip as the bearing moves
        x, t = fast.frame["bearing_position_m"], fast.frame["time_s"]
        assert x[t < 0.08].max() > 4.2e-3 and x.iloc[-1] < x[t < 0.08].max() - 0.05e-3  # it follows the reference


def _njit(fn):
    import numba

    return numba.njit(fn)


@_njit
def _pi_with_memory(t, y, memory):
    """A PI written by hand: memory[0] the integral, memory[1] counts the samples."""
    e = (0.1 if t < 0.2 else -0.05) - y[0]
    memory[0] += 0.01 * e / 0.1
    memory[1] += 1.0
    return np.array([0.3 * e + 0.3 * memory[0]])


@_njit
def _two_values(t, y, memory):
    return np.array([0.0, 1.0])


def test_compiled_function_controller_equals_the_python_loop():
    """A numba-compiled u = f(t, y, memory) runs in the compiled loop through its C entry: the same run as
    the Python loop calling the same function, its memory changed in place there as here."""
    Ts = 0.01
    s = linear_system(A, np.zeros(2), B)
    run = dict(measure=["x0"], actuate=["u0"], delay=1)
    fast = closed_loop(s, _pi_with_memory, Ts, 0.5, memory=[0.0, 0.0], **run)
    slow = closed_loop(s, _pi_with_memory, Ts, 0.5, memory=[0.0, 0.0], compiled=False, **run)
    _same(fast, slow)
    x = fast.frame["x0_1"]
    assert x.iloc[20] > 0.02 and x.iloc[-1] < x.iloc[20]  # up towards 0.1, then down towards -0.05
    tight = s.replace(limits={"u0": (-0.02, 0.02)})
    fast = closed_loop(tight, _pi_with_memory, Ts, 0.5, memory=[0.0, 0.0], **run)
    _same(fast, closed_loop(tight, _pi_with_memory, Ts, 0.5, memory=[0.0, 0.0], compiled=False, **run))
    assert fast.frame["saturated_1"].any() and fast.frame["u0_1"].abs().max() <= 0.02
    with pytest.raises(ParameterError, match="another number of values than the 1 actuated"):
        closed_loop(s, _two_values, Ts, 0.1, **run)


def test_a_tighter_rtol_brings_the_absolute_tolerances_down(monkeypatch):
    """``closed_loop(..., rtol=...)`` below the system's rtol runs with its absolute tolerances scaled in proportion
    (the contract's ``follow_rtol``, issue #30): with them at the system's, the error stopped at their floor."""
    import clutchlab.control.loop as loop

    seen = []
    real = loop.Simulation

    def spy(system, **options):
        seen.append(real(system, **options))
        return seen[-1]

    monkeypatch.setattr(loop, "Simulation", spy)
    s = linear_system(A, np.zeros(2), B)
    pi = PI(0.5, 0.2).discrete(1e-2)
    for rtol in (None, s.rtol * 1e-3, s.rtol * 10):
        closed_loop(s, pi, 1e-2, 0.1, measure=["x0"], actuate=["u0"], reference=1.0, rtol=rtol)
    np.testing.assert_array_equal(seen[0].options.atol, s.atol)
    np.testing.assert_allclose(seen[1].options.atol, s.atol * 1e-3, rtol=1e-12)
    np.testing.assert_array_equal(seen[2].options.atol, s.atol)
    with pytest.raises(ParameterError, match="rtol"):
        closed_loop(s, pi, 1e-2, 0.1, measure=["x0"], actuate=["u0"], rtol="x")
