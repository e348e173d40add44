"""Discrete controllers in the loop with any model (through the core's resumable stepping).

A controller sampled every ``sample_time`` reads measured states or outputs of the model at the sample
instant ``t_k`` and sets the model's held inputs, which stay constant until the next sample (zero-order
hold, as a controller on an ECU or a HIL target drives its actuators). The model runs between samples in
its compiled integrator (:class:`clutchlab.system.Simulation`, resumed at every sample: its step size,
modes and hysteresis memories carry over); the controller is

* a python-control discrete ``StateSpace`` or ``TransferFunction`` with ``dt == sample_time``, acting on
  the error ``e = r - y`` and adding its output to the operating point's inputs:
  ``u_k = u_op + C x_k + D e_k``, ``x_{k+1} = A x_k + B e_k``;
* or a function ``u = f(t, y, memory)`` of the time [s], the measured vector ``y`` [SI] and a float
  array ``memory`` it may change in place (integrator states, the last output).

For an LTI controller, a :class:`~clutchlab.control.design.ScheduledPI` and a function compiled with
numba in nopython mode (called through a C entry, :func:`clutchlab.numerics.sampled.function_pointer`;
it must not raise) the whole loop -- measuring, the controller's update, the hold and the model -- runs
in the model's compiled entry
(:mod:`clutchlab.numerics.sampled`, cached per model; its first use compiles the integrator into it, as
:func:`clutchlab.system.simulate_batch` does); another function is called from a Python loop around
:meth:`clutchlab.system.Simulation.advance`, with the same arithmetic.

The output is limited to the model's physical range (:attr:`clutchlab.system.System.limits`, e.g. the
drive's supply voltage) when ``saturate=True``, as the drive would.  ``delay=1`` applies each output one
sample late (a controller that needs its frame to compute).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from .._limits import check_allocation
from ..errors import ParameterError
from ..system import Simulation, System
from ..trim import OperatingPoint, resolve

__all__ = ["ClosedLoopResult", "closed_loop", "discrete_matrices"]


@dataclasses.dataclass
class ClosedLoopResult:
    """A closed-loop run sampled at the controller's instants.

    Attributes
    ----------
    frame : pandas.DataFrame
        ``time_s``, each measured signal (its column name), ``reference_<column>`` (for a function
        controller only if a reference was given), each actuated input (its column name, the value applied
        from that sample on) and ``saturated_1`` (1 where the output was limited).
    events : pandas.DataFrame
        The model's events (time, element, event name).
    stats : dict
        Solver counters of the whole run.
    """

    frame: pd.DataFrame
    events: pd.DataFrame
    stats: dict


def discrete_matrices(controller, sample_time: float):
    """``(A, B, C, D)`` of a discrete python-control system sampled at ``sample_time``.

    Parameters
    ----------
    controller : control.StateSpace or control.TransferFunction
        Discrete (``dt`` equal to ``sample_time``, or ``True``).
    sample_time : float
        Controller period [s].

    Raises
    ------
    ParameterError
        A continuous controller (discretise it with ``control.c2d(C, sample_time)``) or another period.
    """
    import control

    dt = controller.dt
    if dt is None or dt == 0:
        raise ParameterError("the controller is continuous: discretise it, e.g. control.c2d(C, "
                             f"{sample_time:g}, 'tustin')")
    if dt is not True and abs(float(dt) - sample_time) > 1e-12 * sample_time:
        raise ParameterError(f"the controller's sample time dt = {dt:g} s differs from sample_time = "
                             f"{sample_time:g} s")
    ss = control.ss(controller)
    return (np.atleast_2d(np.asarray(ss.A, float)), np.atleast_2d(np.asarray(ss.B, float)),
            np.atleast_2d(np.asarray(ss.C, float)), np.atleast_2d(np.asarray(ss.D, float)))


def closed_loop(system: System | OperatingPoint, controller, sample_time: float, t_end: float, *, measure,
                actuate, reference=None, memory=None, saturate: bool = True, delay: int = 0, rtol=None,
                max_step=None, fixed_step=None, compiled=None) -> ClosedLoopResult:
    """Run ``system`` with a discrete ``controller`` in the loop from ``t = 0`` to ``t_end``.

    Parameters
    ----------
    system : System or OperatingPoint
        The model with held inputs (an operating point: started there, its inputs are ``u_op``).
    controller : control.StateSpace, control.TransferFunction or callable
        Discrete LTI controller acting on ``reference - measured`` (its output added to ``u_op``), or
        ``f(t, y, memory) -> u`` returning the actuated inputs (absolute values, SI).
    sample_time : float
        Controller period [s].
    t_end : float
        End time [s].
    measure : sequence of str
        States or outputs the controller reads (names with or without unit).
    actuate : sequence of str
        Held inputs the controller sets.
    reference : float, array_like or callable, optional
        Reference of each measured signal: a constant (per signal), ``r(t)`` returning one value per
        signal, or an array of shape ``(samples, signals)`` at ``t_k = k sample_time``. An LTI controller
        acts on ``reference - y`` (default: the measured values at the start); a function controller gets
        ``y`` and keeps its own reference: given here, it is only recorded (``reference_<signal>``
        columns, absent otherwise).
    memory : array_like, optional
        Initial memory of a function controller (default: 16 zeros).
    saturate : bool
        Limit the actuated inputs to the model's ``System.limits``.
    delay : {0, 1}
        Samples between reading ``y_k`` and applying ``u_k``.
    rtol, max_step : float, optional
        Integrator options (the system's defaults otherwise).  Below the system's ``rtol`` its absolute
        tolerances shrink in proportion, ``atol · rtol / system.rtol``, so that the error follows ``rtol``.
    fixed_step : float, optional
        Run the model in the core's fixed-step mode with this step [s] (a HIL target's frame; see
        :func:`clutchlab.system.simulate`), normally ``sample_time`` or an integer fraction of it.
    compiled : bool, optional
        Run the whole loop -- measurement, controller, hold and the model -- in the model's compiled entry
        (:mod:`clutchlab.numerics.sampled`): the default for a python-control discrete system, a
        :class:`~clutchlab.control.design.ScheduledPI` and a function compiled with numba; any other
        function runs in the Python loop (``compiled=True`` then raises).  The compiled loop's first use
        per model compiles the integrator into it (about 10 s on the 2-core machine; cached after that).
        ``False`` forces the Python loop
        (the same arithmetic; for debugging a controller).

    Returns
    -------
    ClosedLoopResult
    """
    op = system if isinstance(system, OperatingPoint) else None
    base = op.start() if op is not None else system
    if not (np.isfinite(sample_time) and sample_time > 0):
        raise ParameterError(f"sample_time = {sample_time!r} s must be finite and > 0")
    if not (np.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"t_end = {t_end!r} s must be finite and > 0")
    if delay not in (0, 1):
        raise ParameterError(f"delay = {delay!r}: expected 0 or 1 samples")
    meas = [resolve(base, n, ("state", "output")) for n in ([measure] if isinstance(measure, str) else measure)]
    act = [resolve(base, n, ("input",))[1] for n in ([actuate] if isinstance(actuate, str) else actuate)]
    n = int(np.floor(t_end / sample_time + 1e-9))
    check_allocation(n + 1, 2 * len(meas) + len(act) + 2,
                     what=f"closed loop of t_end = {t_end:g} s at sample_time = {sample_time:g} s")
    # (a tighter rtol brings the absolute tolerances down with it: the contract's follow_rtol)
    sim = Simulation(base, rtol=rtol, max_step=max_step, fixed_step=fixed_step)
    u_op = base.u0.copy()
    lo = np.array([base.limits.get(base.inputs[j].name, (-np.inf, np.inf))[0] for j in act])
    hi = np.array([base.limits.get(base.inputs[j].name, (-np.inf, np.inf))[1] for j in act])
    if not saturate:
        lo, hi = np.full(len(act), -np.inf), np.full(len(act), np.inf)
    state_idx = np.array([i for kind, i in meas if kind == "state"], dtype=np.int64)
    out_idx = np.array([i for kind, i in meas if kind == "output"], dtype=np.int64)
    is_state = np.array([kind == "state" for kind, _ in meas])

    def measured():
        y = np.empty(len(meas))
        if state_idx.size:
            y[is_state] = sim.x[state_idx]
        if out_idx.size:
            y[~is_state] = sim.outputs()[out_idx]
        return y

    y0 = measured()
    ref = _reference(reference, y0, n, sample_time)
    lti = hasattr(controller, "dt") and hasattr(controller, "ninputs")
    if not lti and not callable(controller):
        raise ParameterError(f"controller {type(controller).__name__}: expected a discrete python-control system "
                             "or a function f(t, y, memory)")
    if lti:
        Ad, Bd, Cd, Dd = discrete_matrices(controller, sample_time)
        if Bd.shape[1] != len(meas) or Cd.shape[0] != len(act):
            raise ParameterError(f"the controller has {Bd.shape[1]} inputs and {Cd.shape[0]} outputs; the loop "
                                 f"measures {len(meas)} and actuates {len(act)}")
        xc = np.zeros(Ad.shape[0])
    else:
        mem = np.zeros(16) if memory is None else np.array(memory, dtype=float).ravel()
    T = np.arange(n + 1) * sample_time
    Y = np.empty((n + 1, len(meas)))
    U = np.empty((n + 1, len(act)))
    S = np.zeros(n + 1)
    scheduled = _is_scheduled_pi(controller)
    jitted = hasattr(controller, "py_func") and hasattr(controller, "signatures")  # a numba-compiled function
    if compiled is None:
        compiled = lti or scheduled or jitted
    if compiled and not (lti or scheduled or jitted):
        raise ParameterError(f"compiled=True: a {type(controller).__name__} runs in the Python loop; the compiled "
                             "loop takes a python-control discrete system, a ScheduledPI or a numba-compiled "
                             "function")
    if compiled and scheduled and (len(meas) != 1 or len(act) != 1):
        raise ParameterError(f"a ScheduledPI measures one signal and actuates one input; the loop has {len(meas)} "
                             f"and {len(act)}")
    if compiled:
        _run_compiled(sim, controller, lti, T, ref, meas, act, lo, hi, delay, u_op, Ad if lti else None,
                      Bd if lti else None, Cd if lti else None, Dd if lti else None, None if lti else mem, Y, U, S)
    else:
        pending = u_op[act].copy()
        u = u_op.copy()
        for k in range(n + 1):
            y = measured()
            Y[k] = y
            if lti:
                e = ref[k] - y
                out = u_op[act] + Cd @ xc + Dd @ e
                xc = Ad @ xc + Bd @ e
            else:
                out = np.asarray(controller(T[k], y, mem), dtype=float).ravel()
                if out.shape != (len(act),):
                    raise ParameterError(f"the controller returned {out.size} values for {len(act)} actuated "
                                         "inputs")
            clipped = np.minimum(np.maximum(out, lo), hi)
            S[k] = float(np.any(clipped != out))
            applied = clipped if delay == 0 else pending
            pending = clipped
            u[act] = applied
            U[k] = applied
            if k < n:
                sim.advance(T[k + 1], u)
    cols = {"time_s": T}
    for q, (kind, i) in enumerate(meas):
        c = (base.states if kind == "state" else base.outputs)[i].column
        cols[c] = Y[:, q]
        if lti or reference is not None:  # a function controller keeps its reference to itself unless given
            cols[f"reference_{c}"] = ref[:, q]
    for q, j in enumerate(act):
        cols[base.inputs[j].column] = U[:, q]
    cols["saturated_1"] = S
    return ClosedLoopResult(pd.DataFrame(cols), sim.events(), sim.stats)


def _is_scheduled_pi(controller) -> bool:
    from .design import ScheduledPI

    return isinstance(controller, ScheduledPI) and type(controller).__call__ is ScheduledPI.__call__


def _run_compiled(sim, controller, lti, T, ref, meas, act, lo, hi, delay, u_op, Ad, Bd, Cd, Dd, mem, Y, U, S):
    """The loop of :func:`closed_loop` in the model's compiled entry (``clutchlab.numerics.sampled``)."""
    from ..numerics.sampled import FUNCTION, LTI, SCHEDULED_PI, function_pointer, placeholder

    f64 = lambda a: np.ascontiguousarray(a, dtype=float)  # noqa: E731
    kind = np.array([0 if k == "state" else 1 for k, _ in meas], dtype=np.int64)
    idx = np.array([i for _, i in meas], dtype=np.int64)
    act = np.asarray(act, dtype=np.int64)
    f, sched, par, R, memory = placeholder(), np.zeros((4, 1)), np.zeros(5), ref, mem  # (unused parts: empty)
    if lti:
        xc, memory, code = np.zeros(Ad.shape[0]), np.zeros(1), LTI
    else:
        Ad, Bd, Cd, Dd, xc = np.zeros((0, 0)), np.zeros((0, len(meas))), np.zeros((len(act), 0)), \
            np.zeros((len(act), len(meas))), np.zeros(0)
    if not lti and not _is_scheduled_pi(controller):
        f, code = function_pointer(controller), FUNCTION
    elif not lti:
        ff = controller.feedforward
        pts = f64(controller.points).ravel()
        sched = np.vstack([pts, f64(controller.kp).ravel(), f64(controller.ti).ravel(),
                           np.zeros(pts.size) if ff is None else f64(ff).ravel()])
        lo_c, hi_c = controller.limits
        par = np.array([controller.sample_time, 0.0 if ff is None else 1.0, controller.integrate_band, lo_c, hi_c],
                       dtype=float)
        R = np.array([[float(controller.reference(t))] for t in T])
        code = SCHEDULED_PI
    sim.run_sampled(T, f64(R), kind, idx, act, f64(lo), f64(hi), delay, code, f, f64(Ad), f64(Bd), f64(Cd), f64(Dd), xc,
                    f64(sched), f64(par), memory, f64(u_op[act]), Y, U, S)


def _reference(reference, y0, n, sample_time):
    T = np.arange(n + 1) * sample_time
    if reference is None:
        return np.tile(y0, (n + 1, 1))
    if callable(reference):
        R = np.array([np.broadcast_to(np.asarray(reference(t), dtype=float), y0.shape) for t in T])
    else:
        R = np.asarray(reference, dtype=float)
        if R.ndim <= 1 and R.size in (1, y0.size):
            R = np.tile(np.broadcast_to(R, y0.shape), (n + 1, 1))
        elif R.shape != (n + 1, y0.size):
            raise ParameterError(f"reference has shape {R.shape}; expected a value per signal or "
                                 f"({n + 1}, {y0.size}) samples")
    if not np.all(np.isfinite(R)):
        raise ParameterError("reference is not finite")
    return R
