"""The integrator core: one compiled hybrid integrator for every clutchlab model.

Two methods, each written once:

* :func:`advance_dopri` -- explicit Dormand-Prince 5(4) (SciPy's ``RK45``
  tableau, FSAL) with cubic Hermite dense output, for non-stiff models
  (wet clutch, EMTC bench);
* :func:`advance_rodas` -- Rodas3, a linearly implicit, stiffly accurate,
  L-stable Rosenbrock method (Sandu et al. 1997) with a diagonal mass matrix
  (zero rows are algebraic equations of index 1), for stiff models
  (E-clutch actuator + clutch).  Jacobian from the model (analytic) or by
  forward differences over the columns named in ``Options.jac_groups``
  (columns that share no row of the sparsity pattern are perturbed
  together, one right-hand side per group), each group differenced backwards when the forward perturbation crosses a
  switching function (a kink).

Both share the hybrid logic:

* every switching function ``g_k`` returned by the model's ``rhs`` is
  watched; a crossing in the direction ``Options.gdir[k]`` (+1 rising
  through zero, -1 falling, 0 either; a start exactly on zero does not
  count) is located by root finding (Illinois) on the step's dense output,
  the step is cut at the earliest root (Dormand-Prince: moved to where the
  function crosses on the step's own order-5 solution of that length, the
  state the run restarts from, :func:`_root_on_step`; Rodas3: one step of
  the located length), and the model's ``update`` is called
  for every function that crossed there, which changes the modes and records
  named events (:func:`record`);
* a run that has not started calls the model's ``start`` (what it derives
  from its initial state alone: the modes it starts from) before its first
  ``restart``;
* ``next_break`` times (input table corners, controller samples) end a step
  exactly and call the model's ``restart``;
* after every accepted step the model's ``accept`` runs (hysteresis memory
  commit, projection of stuck velocities);
* a fixed-step mode of :func:`advance_rodas` (``Options.fixed_step`` > 0,
  a HIL frame: the same work every step, events and breaks at the step end;
  docs/architecture.md);
* stepping is resumable: :func:`advance_dopri` / :func:`advance_rodas`
  continue from the solver state ``(sf, si)`` to ``t_end`` (co-simulation,
  controller sampling, chunked recording).

One step-size controller per method, one NaN-safe error norm
(:func:`clutchlab.numerics.dopri.error_norm`, a non-finite norm rejects the
step with the smallest factor), one status enumeration
(:mod:`clutchlab.numerics.status`).

The model is never passed as a function: the core calls the stubs of
:mod:`clutchlab.numerics.dispatch`, resolved at compile time from the type of
the parameter structure ``p`` (see docs/architecture.md).

References
----------
.. [1] J. R. Dormand, P. J. Prince, J. Comput. Appl. Math. 6 (1980) 19-26.
.. [2] A. Sandu et al., Atmos. Environ. 31 (1997) 3459-3472 (Rodas3).
.. [3] E. Hairer, G. Wanner, Solving Ordinary Differential Equations I/II,
   Springer 1993/1996 (step control II.4, Rosenbrock methods VI.4).
.. [4] SciPy ``integrate._ivp`` (RK45 tableau, event handling).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numba.extending import register_jitable

from . import dispatch as model
from .borrow import borrow, byref
from .layout import indices
from .dopri import (
    A21, A31, A32, A41, A42, A43, A51, A52, A53, A54, A61, A62, A63, A64, A65,
    B1, B3, B4, B5, B6, C2, C3, C4, C5, E1, E3, E4, E5, E6, E7,
    dense_correction, dense_hermite, error_norm, initial_step, next_step, starting_step,
)
from .rosenbrock import (A31 as R_A31, A41 as R_A41, A43 as R_A43, C21 as R_C21, C31 as R_C31, C32 as R_C32,
                         C41 as R_C41, C42 as R_C42, C43 as R_C43, GAMMA as R_GAMMA, GAMMA1 as R_GAMMA1,
                         GAMMA2 as R_GAMMA2, plan_reduction, reduced_factor, reduced_solve, reduction_sizes,
                         rodas_next_step)
from .status import MODEL_ERROR, RECORD_FULL, SINGULAR, STEP_LIMIT, STEP_UNDERFLOW, SUCCESS, TERMINATED

__all__ = ["Options", "EventLog", "new_log", "record", "new_solver_state", "advance_dopri", "advance_rodas",
           "batch", "evaluate", "evaluate_jacobian", "evaluate_outputs", "outputs_at",
           "SF_T", "SF_H", "SF_T0", "SI_ACCEPTED", "SI_REJECTED", "SI_NRHS", "SI_NJAC", "SI_STATUS", "SI_IREC",
           "SI_STARTED", "SI_MODEL_CODE", "N_SF", "N_SI", "TERMINAL", "RESTART"]

# ---- solver state (resumable): float and int vectors
#: its floats: time, step size, start of the run (origin of a fixed-step grid)
SOLVER_FLOATS = ("time", "step", "start")
SF_T, SF_H, SF_T0 = indices(SOLVER_FLOATS, "time", "step", "start")
N_SF = len(SOLVER_FLOATS)
#: what Rodas3 keeps after them for a record resumed in a new buffer (``RECORD_FULL``, :data:`RESUME_NOTE`), where the
#: caller made room (:func:`new_solver_state` with ``n``): the age of its Jacobian in accepted steps, whether it is
#: stale (1.0) or not (0.0), then the Jacobian itself, ``n * n`` numbers row by row
RODAS_KEPT = ("jacobian_age", "jacobian_stale")
SK_AGE, SK_STALE = indices(RODAS_KEPT, "jacobian_age", "jacobian_stale")
N_SK = len(RODAS_KEPT)
#: its integers: steps accepted and rejected, right-hand sides and Jacobians evaluated, the status, the next row of
#: the record, whether the run has started, the model's error code
SOLVER_INTS = ("accepted", "rejected", "rhs_evaluations", "jacobians", "status", "record_row", "started",
               "model_code")
SI_ACCEPTED, SI_REJECTED, SI_NRHS, SI_NJAC, SI_STATUS, SI_IREC, SI_STARTED, SI_MODEL_CODE = indices(
    SOLVER_INTS, "accepted", "rejected", "rhs_evaluations", "jacobians", "status", "record_row", "started",
    "model_code")
N_SI = len(SOLVER_INTS)
#: what a model's ``update`` returns besides 0 (go on) and negative error codes: end the run (1), or go on with
#: the step size started afresh from a short step (2; Dormand-Prince only, see :func:`advance_dopri`)
TERMINAL, RESTART = 1, 2


class Options(NamedTuple):
    """Step control and event options of one run (all SI).

    Attributes
    ----------
    rtol : float
        Relative tolerance [1].
    atol : ndarray
        Absolute tolerance per state, in the state's unit.
    max_step : float
        Largest step [s].
    first_step : float
        First trial step [s]; 0 estimates it (Hairer & Wanner II.4).
    max_steps : int
        Accepted-step limit of the whole run (status ``STEP_LIMIT``).
    event_tol : float
        Width [s] to which an event time is bracketed.
    gdir : ndarray of int64
        Direction of each switching function's crossing that is an event:
        +1 rising through zero, -1 falling, 0 either.
    mass : ndarray
        Diagonal of the mass matrix (Rosenbrock only; 0 marks an algebraic row).
    jac_groups : ndarray of int64, shape (n_groups, width)
        Columns of the finite-difference Jacobian (Rosenbrock; the others are
        zero), in groups perturbed together (padding -1); columns in a group
        share no row of ``jac_pattern``.
    jac_pattern : ndarray of bool, shape (n, n)
        Structural non-zeros of the Jacobian (all True without a pattern).
    fd_scale : ndarray
        Typical magnitude of each state for the difference increment.
    jac_every : int
        Accepted steps a Jacobian is reused for (refreshed at once after a
        rejection or a mode change).
    nonautonomous : bool
        Difference df/dt for the Rosenbrock stages (inputs that vary within a step).
    fixed_step : float
        0 for step-size control; > 0 [s]: the Rosenbrock loop takes steps of exactly this length on the
        grid ``t0 + k * fixed_step`` (a HIL frame; see :func:`advance_rodas`).
    """

    rtol: float
    atol: np.ndarray
    max_step: float
    first_step: float
    max_steps: int
    event_tol: float
    gdir: np.ndarray
    mass: np.ndarray
    jac_groups: np.ndarray
    jac_pattern: np.ndarray
    fd_scale: np.ndarray
    jac_every: int
    nonautonomous: bool
    fixed_step: float = 0.0


class EventLog(NamedTuple):
    """Events recorded by the models' ``update``/``restart`` hooks.

    ``time`` [s], ``code`` (index into the model's event names), ``element``
    (index of the element concerned, -1 for none); ``count[0]`` events held,
    ``count[1]`` events dropped because the log was full.
    """

    time: np.ndarray
    code: np.ndarray
    element: np.ndarray
    count: np.ndarray


def new_log(capacity: int) -> EventLog:
    """An empty event log holding up to ``capacity`` events (only the first ``count[0]`` entries are ever read)."""
    ints = np.empty(2 * capacity, dtype=np.int64)  # codes and elements: one allocation
    return EventLog(np.empty(capacity), ints[:capacity], ints[capacity:], np.zeros(2, dtype=np.int64))


def new_solver_state(t0: float, n: int = 0):
    """Solver state ``(sf, si)`` of a run that starts at ``t0``.  ``n`` > 0: room after the floats for Rodas3 to keep
    the Jacobian of a model of ``n`` states across a record resumed in a new buffer (:data:`RODAS_KEPT`,
    :data:`RESUME_NOTE`); a Dormand-Prince run ignores it."""
    sf = np.zeros(N_SF + (N_SK + n * n if n > 0 else 0))
    sf[SF_T] = t0
    return sf, np.zeros(N_SI, dtype=np.int64)


@numba.njit(cache=True, nogil=True, inline="always")
def record(log, t, code, element):
    """Append a named event (model hooks call this)."""
    n = log.count[0]
    if n < log.time.shape[0]:
        log.time[n] = t
        log.code[n] = code
        log.element[n] = element
        log.count[0] = n + 1
    else:
        log.count[1] += 1


#: a switching function whose value at an earlier root is within this fraction of its values at the step's ends
#: reads zero to its rounding there, and is read again just before (:func:`_locate`)
ZERO_READ = 1e-9

#: the direction of a waypoint either way (as 4) that is located even where an event function crosses later in
#: the same step (a waypoint of direction +-3 or 4 is not: that event ends the step anyway).  A backlash's
#: turning-point function in its gap is signed towards the nearer edge, so it falls where the twist passes the gap's
#: centre and rises at the extreme that follows: both in one step, its ends of one sign, and the touch of the edge
#: beyond that extreme was stepped over where a friction element's event ended the step (issue #30, random draws
#: seed 2137: a 12 ms contact missed at rtol 1e-10 and found at 1e-7 to 1e-9 and 1e-11).  No one function can
#: show both (whatever falls at the centre either way turns at the extremes too), so the centre is a waypoint of
#: its own, of this direction: a step ends there whatever else crosses after it.
WAYPOINT_ALWAYS = 5


@numba.njit(cache=True, nogil=True, inline="always")
def _crossed(a, b, d):
    """True if a switching value went from ``a`` to ``b`` through zero in direction ``d`` (4 and
    :data:`WAYPOINT_ALWAYS`: waypoints either way)."""
    if d == 4 or d == WAYPOINT_ALWAYS:
        d = 0
    if d >= 0 and a < 0.0 and b >= 0.0:
        return True
    if d <= 0 and a > 0.0 and b <= 0.0:
        return True
    return False


@numba.njit(cache=True, nogil=True, inline="always")
def _store(rec_t, rec_x, rec_m, i, t, x, m):
    rec_t[i] = t
    for q in range(x.shape[0]):
        rec_x[i, q] = x[q]
    for q in range(m.shape[0]):
        rec_m[i, q] = m[q]


@numba.njit(cache=True, nogil=True, forceinline=True)
def _dense(theta, h, x0, f0, x1, f1, rc, mass, out):
    """Dense output: cubic Hermite plus ``theta^2 (1 - theta)^2 rc`` (Dormand-Prince's order-4 term,
    :func:`~clutchlab.numerics.dopri.dense_correction`; zeros for Rodas3, whose order is 3); linear in the
    algebraic rows (``mass`` = 0); the step end itself at ``theta`` = 1."""
    if theta == 1.0:
        for i in range(x0.shape[0]):
            out[i] = x1[i]
        return
    dense_hermite(theta, h, x0, f0, x1, f1, out)
    w = theta * (1.0 - theta)
    w = w * w
    for i in range(x0.shape[0]):
        if mass[i] == 0.0:
            out[i] = x0[i] + theta * (x1[i] - x0[i])
        else:
            out[i] += w * rc[i]


@register_jitable
def _may_cross(g0, g1, gdir):
    """False if no switching function can have crossed in the step (then :func:`_locate` is skipped).

    A function that starts exactly on zero may return through zero within the step: that needs
    :func:`_locate`'s probe.
    """
    for k in range(g0.shape[0]):
        if _crossed(g0[k], g1[k], gdir[k]) or (g0[k] == 0.0 and g1[k] != 0.0):
            return True
    return False


@register_jitable
def _locate(p, t, h, x0, f0, x1, f1, rc, u, m, g0, g1, gdir, mass, event_tol, xe, fe, ge, ga, waypoints):
    """Earliest root of the crossed switching functions on the dense output of the step.

    Illinois iteration per crossed function on the step fraction; returns
    ``(theta, n_rhs, k)`` with ``theta`` the bracket end just past the earliest
    root (so that the crossing shows at the returned point), or 2.0 if none
    crossed, and ``k`` the function whose root it is.  A *waypoint* (direction
    +-3, or 4 either way: a function whose crossing only asks for a step end just past it, no
    event) is located to 1 % of the step, and not at all with ``waypoints``
    False or where another function crossed in the step.  ``ga`` receives the value each function starts the step with:
    ``g0``, except that a function starting exactly on zero (after the event
    that put it there: a ball on the ground, a clutch that just broke away)
    takes its sign from a probe just after the start (``theta`` = 1e-6), so a
    return through zero later in the same step is still seen.  A function
    located after an earlier root is looked for only before it; one that reads
    zero to its rounding there (:data:`ZERO_READ`) is read again just before.
    """
    best = 2.0
    kbest = -1
    n_rhs = 0
    ng = g0.shape[0]
    probed = False
    th0 = 1e-6
    for k in range(ng):
        ga[k] = g0[k]
        if g0[k] == 0.0 and g1[k] != 0.0:
            if not probed:
                _dense(th0, h, x0, f0, x1, f1, rc, mass, xe)
                model.rhs_event(t + th0 * h, xe, u, m, p, fe, ge)
                model.watch(t + th0 * h, xe, u, m, p, fe, ge, -1)
                n_rhs += 1
                probed = True
            ga[k] = ge[k]
    # (a waypoint is not looked at where another function has crossed in the step: that event ends the step anyway,
    # and its cost was the waypoint's, a stuck element's entry into its band just before its break-away; but a
    # waypoint of direction 5 is, unless this step is the one taken again to end past a waypoint: a step end that
    # another function's meaning turns on, which a later event in the same step must not skip, WAYPOINT_ALWAYS)
    retaken = not waypoints
    for k in range(ng):
        if abs(gdir[k]) < 3 and _crossed(ga[k], g1[k], gdir[k]):
            waypoints = False
    for k in range(ng):
        if not _crossed(ga[k], g1[k], gdir[k]) or (abs(gdir[k]) >= 3 and not waypoints and
                                                   (abs(gdir[k]) != WAYPOINT_ALWAYS or retaken)):
            continue
        lo = th0 if g0[k] == 0.0 else 0.0
        hi = min(1.0, best)
        glo = ga[k]
        if hi < 1.0:
            # an earlier root is known: only look before it.  A function that reads zero to its rounding there may
            # have crossed before and come back to it: read again just before (a stuck element's break-away function,
            # lim + noise - |tau|, beyond an E-clutch's lift-off, where its limit is 0: its load passed through zero
            # at the instant a one-way clutch's turning point, driven by the same torque, was the earliest root, and
            # the break-away 86 us before it was stepped over; random draws, fifty-seventh session).  One call site
            # for the evaluation (the right-hand side is linked into this function for some models)
            probe = hi
            found = False
            for _pass in range(2):
                _dense(probe, h, x0, f0, x1, f1, rc, mass, xe)
                model.rhs_event(t + probe * h, xe, u, m, p, fe, ge)
                model.watch(t + probe * h, xe, u, m, p, fe, ge, k)
                n_rhs += 1
                if _crossed(glo, ge[k], gdir[k]):
                    found = True
                    break
                if abs(ge[k]) > ZERO_READ * max(abs(glo), abs(g1[k])):
                    break
                probe = hi - max(1e-6, 64.0 * event_tol / h)
                if probe <= lo:
                    break
            if not found:
                continue
            hi = probe
            ghi = ge[k]
        else:
            ghi = g1[k]
        hi, nr = _illinois(p, t, h, x0, f0, x1, f1, rc, u, m, mass,
                           event_tol if abs(gdir[k]) < 3 else max(event_tol, 1e-2 * h), xe, fe, ge, k, lo, hi, glo,
                           ghi, ga[k], gdir[k])
        n_rhs += nr
        if hi < best:
            best = hi
            kbest = k
    # a function that had not crossed by the step's end may have crossed before the earliest root and come back
    # (a dip through zero that the root of a turning-point function reveals): look again at the earliest root and
    # locate any such crossing before it
    for _round in range(4):
        if best >= 1.0:
            break
        _dense(best, h, x0, f0, x1, f1, rc, mass, xe)
        model.rhs_event(t + best * h, xe, u, m, p, fe, ge)
        model.watch(t + best * h, xe, u, m, p, fe, ge, -1)
        n_rhs += 1
        earliest = best
        gb = ge.copy()   # (rare: a step with an event; the searches below overwrite ge)
        for k in range(ng):
            # (only the functions a model marks for it, direction +-2, that started the step clear of zero: a
            # driveline element's relative speed, whose dip through zero its turning-point function reveals)
            if (abs(gdir[k]) != 2 or g0[k] == 0.0 or _crossed(ga[k], g1[k], gdir[k])
                    or not _crossed(ga[k], gb[k], gdir[k])):
                continue
            root, nr = _illinois(p, t, h, x0, f0, x1, f1, rc, u, m, mass, event_tol, xe, fe, ge, k, 0.0, best, ga[k],
                                 gb[k], ga[k], gdir[k])
            n_rhs += nr
            # (a root within the event tolerance's reach of the step's start is the last event's, not a new one; a
            # share of the step would drop a crossing a microsecond after a step end that a window's entry put
            # just before it: the slip of a statically indeterminate pair found 6 ms late, #30)
            if root * h > 64.0 * event_tol and root < earliest:
                earliest = root
                kbest = k
        if earliest >= best:
            break
        best = earliest
    return best, n_rhs, kbest


@register_jitable
def _illinois(p, t, h, x0, f0, x1, f1, rc, u, m, mass, event_tol, xe, fe, ge, k, lo, hi, glo, ghi, gref, gdir_k):
    """Root of switching function ``k`` within the step fraction ``[lo, hi]`` (``glo``, ``ghi`` its values there,
    crossed from ``gref`` in direction ``gdir_k``) on the dense output, by the Illinois iteration to ``event_tol``
    [s]: ``(theta, n_rhs)``, ``theta`` the bracket end just past the root."""
    n_rhs = 0
    side = 0
    for _it in range(200):
        if (hi - lo) * h <= event_tol:
            break
        if glo != ghi and _it < 40:
            th = lo + (hi - lo) * glo / (glo - ghi)
        else:   # (a function that jumps at its root converges only by 1 % a step: bisect after 40 steps)
            th = 0.5 * (lo + hi)
        span = hi - lo
        th = min(max(th, lo + 0.01 * span), hi - 0.01 * span)
        _dense(th, h, x0, f0, x1, f1, rc, mass, xe)
        model.rhs_event(t + th * h, xe, u, m, p, fe, ge)
        model.watch(t + th * h, xe, u, m, p, fe, ge, k)
        n_rhs += 1
        if _crossed(gref, ge[k], gdir_k):
            hi = th
            ghi = ge[k]
            if side == 1:
                glo *= 0.5
            side = 1
        else:
            lo = th
            glo = ge[k]
            if side == -1:
                ghi *= 0.5
            side = -1
    return hi, n_rhs


@register_jitable
def _root_on_step(p, t, h, x, k1, x1, f1, rc, mass, g0, g1, ga, gdir, u, m, event_tol, theta, Ks, xt, xs, fe, ge, gs,
                  gd):
    """The event located on the step's own solution: the root ``theta`` found on the dense output moved to where the
    switching function crosses on a Dormand-Prince step of the fraction, so that the state a run restarts from is an
    order-5 solution on which the crossing shows (the dense output's order-4 error, which the step control does not
    see, is not carried past the event: docs/driveline.md "Energy").

    The function followed: one that has crossed at ``theta`` on the step's solution (preferring one that crossed
    there on the dense output too), else one whose root on the dense output ``theta`` is (it crosses just after
    ``theta`` on the step; this includes a dip through zero that is back by the step's end, such as a backlash's
    touch of an edge).  Its value on the step's solution at ``theta`` and its slope on the dense output predict the
    root (a Newton step; the two solutions differ by the step's error, so the prediction is good to far below
    ``event_tol``); where the function has crossed just past the prediction (0.01 ``event_tol``, then 8 times as far,
    up to four times), that is the event (mostly two steps of the fraction and two evaluations, 14 in all); else
    the Illinois iteration on the step's solution goes on from the bracket found.

    ``(theta, n_rhs, ok)``: ``ok`` False leaves the dense output's root and state (the crossing does not show on the
    step's solution where it can be bracketed: a dip through zero seen on the dense output only).  ``xs`` receives
    the state, ``Ks`` and ``fe`` the stages and end slope of the step to it (its dense output for the samples).

    Written as one loop with one evaluation of each kind (the dense output, a step of a fraction) and no helper
    functions: the right-hand side is linked at two call sites in one compiled function (its compilation
    dominates the core's: three helpers cost 4 s more of the driveline's first compilation).
    """
    ng = g0.shape[0]
    n_rhs = 0
    if theta >= 1.0:
        return theta, 0, False
    tol = event_tol / h
    d = max(1e-6, 64.0 * tol)
    # the dense output at theta (which functions cross there) and d before it (their slopes)
    for j in range(2):
        th = theta if j == 0 else theta - d
        if th <= 0.0:
            break
        _dense(th, h, x, k1, x1, f1, rc, mass, xt)
        model.rhs_event(t + th * h, xt, u, m, p, fe, ge)
        model.watch(t + th * h, xt, u, m, p, fe, ge, -1)
        n_rhs += 1
        for k in range(ng):
            if j == 0:
                gd[k] = ge[k]
            else:
                gs[k] = (gd[k] - ge[k]) / d   # (the slopes, until the step's values overwrite them)
    slope_ok = theta - d > 0.0
    # the evaluations on the step's solution: phase 0 at theta, 1 the probes past the Newton prediction, 2 the
    # Illinois iteration, 3 the final state
    kk = -1
    at_theta = False
    lo = glo = hi = ghi = 0.0
    pred = off = 0.0
    slope = 0.0
    phase = 0
    side = 0
    n_probe = 0
    n_it = 0
    th = theta
    last = -1.0
    n = x.shape[0]
    k2 = Ks[0]
    k3 = Ks[1]
    k4 = Ks[2]
    k5 = Ks[3]
    k6 = Ks[4]
    for _ev in range(220):
        # the Dormand-Prince order-5 solution of a step of th * h from (t, x) into xs, its stages 2-6 into Ks, the
        # right-hand side and switching functions at its end into fe, ge (the error estimate is not needed: the
        # fraction of an accepted step is as accurate as the step); the stages written out as in _advance_dopri,
        # with one call of the right-hand side
        hh = th * h
        for stg in range(1, 7):
            if stg == 1:
                for i in range(n):
                    xt[i] = x[i] + hh * (A21 * k1[i])
                c = C2
            elif stg == 2:
                for i in range(n):
                    xt[i] = x[i] + hh * (A31 * k1[i] + A32 * k2[i])
                c = C3
            elif stg == 3:
                for i in range(n):
                    xt[i] = x[i] + hh * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
                c = C4
            elif stg == 4:
                for i in range(n):
                    xt[i] = x[i] + hh * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
                c = C5
            elif stg == 5:
                for i in range(n):
                    xt[i] = x[i] + hh * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
                c = 1.0
            else:
                for i in range(n):
                    xt[i] = x[i] + hh * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
                    xs[i] = xt[i]
                c = 1.0
            model.rhs_event(t + c * hh, xt, u, m, p, fe if stg == 6 else Ks[stg - 1], ge)
        # (the functions at the fraction's end: every one read in phase 0, then only the one followed)
        model.watch(t + hh, xs, u, m, p, fe, ge, -1 if phase == 0 else kk)
        n_rhs += 6
        last = th
        if phase == 0:
            # the function whose root on the dense output theta is (crossed there, not d before it), preferring one
            # that has crossed on the step's solution too: another function that shows crossed at theta on the step
            # but not there on the dense output, or already d before it, is no root at theta (a backlash at rest in
            # its gap, whose turning-point function flips with the rounding sign of its deflection, was followed
            # instead of a contact located at theta, and the contact was taken 48 ms late at the step's end, #30)
            kr = -1
            if slope_ok:
                for k in range(ng):
                    if _crossed(ga[k], gd[k], gdir[k]) and not _crossed(ga[k], gd[k] - d * gs[k], gdir[k]):
                        if kr < 0 or (_crossed(ga[k], ge[k], gdir[k]) and not _crossed(ga[kr], ge[kr], gdir[kr])):
                            kr = k
            if kr >= 0:
                kk = kr
            else:
                for k in range(ng):
                    if _crossed(ga[k], ge[k], gdir[k]):
                        if kk < 0 or (_crossed(ga[k], gd[k], gdir[k]) and not _crossed(ga[kk], gd[kk], gdir[kk])):
                            kk = k
            at_theta = kk >= 0 and _crossed(ga[kk], ge[kk], gdir[kk])
            if not at_theta and kr < 0:
                for k in range(ng):
                    if _crossed(ga[k], gd[k], gdir[k]):
                        kk = k
                        break
                if kk < 0:
                    return theta, n_rhs, False
            slope = gs[kk]
            # the bracket known so far on the step's solution: lo (not crossed), hi (crossed; -1 not known yet)
            if at_theta:
                lo = 1e-6 if g0[kk] == 0.0 else 0.0
                glo = ga[kk]
                hi = theta
                ghi = ge[kk]
            else:
                # it crosses just after theta on the step: bracketed by the probes past the prediction, or not at
                # all (the dense output's root and state are kept).  (Not by the step's end: a function that
                # jumps, such as a backlash's turning point at rest in its gap, was followed by the iteration up
                # to 0.54 of the step, past another function's root, and a contact was taken 48 ms late, #30)
                lo = theta
                glo = ge[kk]
                hi = -1.0
            phase = 1
            if slope_ok and slope != 0.0:
                # the value on the step's solution, the slope on the dense output: a Newton step to the root
                pred = theta - ge[kk] / slope
                off = 0.01 * tol
            else:
                n_probe = 4
        elif phase == 1:
            if _crossed(ga[kk], ge[kk], gdir[kk]):
                hi, ghi = th, ge[kk]
                lo = max(lo, th - tol)
                n_probe = 4
            else:
                lo, glo = th, ge[kk]
                off *= 8.0
                n_probe += 1
        elif phase == 2:
            if _crossed(ga[kk], ge[kk], gdir[kk]):
                hi, ghi = th, ge[kk]
                if side == 1:
                    glo *= 0.5
                side = 1
            else:
                lo, glo = th, ge[kk]
                if side == -1:
                    ghi *= 0.5
                side = -1
            n_it += 1
        else:
            break
        # the next point
        if phase == 1:
            q = pred + off
            if n_probe < 4 and lo < q and (hi < 0.0 or q < hi) and q < 1.0:
                th = q
                continue
            if hi < 0.0:
                # a dip through zero on the dense output that the step's solution does not show where looked for
                return theta, n_rhs, False
            phase = 2
        if phase == 2 and (hi - lo) * h > event_tol and n_it < 200:
            if glo != ghi and n_it < 40:
                th = lo + (hi - lo) * glo / (glo - ghi)
            else:   # (a function that jumps at its root: bisect)
                th = 0.5 * (lo + hi)
            span = hi - lo
            th = min(max(th, lo + 0.01 * span), hi - 0.01 * span)
            continue
        # located: the state at hi
        if hi >= 1.0:
            for i in range(x.shape[0]):
                xs[i] = x1[i]
            return 1.0, n_rhs, True
        if last == hi:
            return hi, n_rhs, True
        phase = 3
        th = hi
    return hi, n_rhs, True


@register_jitable(forceinline=True)
def _apply_updates(p, t, x, u, m, g0, g1, gdir, log):
    """Call the model's ``update`` for every switching function that crossed.

    Returns a model error (< 0) at once, else 1 if an update ended the run (terminal), else 2 if one asked
    for a restart of the step size (:data:`RESTART`), else 0.
    """
    flag = 0
    for k in range(g0.shape[0]):
        if _crossed(g0[k], g1[k], gdir[k]):
            r = model.update(t, x, u, m, p, k, log)
            if r < 0:
                return r
            if r == TERMINAL or (r == RESTART and flag == 0):
                flag = r
    return flag


@register_jitable(forceinline=True)
def _record_held(p, t, t_limit, x, u, m, ts, rec_t, rec_x, rec_m, rec_y, want_y, i_rec):
    """Record the samples ``ts[i_rec:] <= t_limit`` holding the state at ``t``; returns the next sample index.

    The outputs are written by the model straight into their row of ``rec_y`` (a copy through a work
    vector read the model's scalar stores back as vectors, a store-forwarding stall per sample).
    """
    while i_rec < ts.shape[0] and ts[i_rec] <= t_limit:
        _store(rec_t, rec_x, rec_m, i_rec, ts[i_rec], x, m)
        if want_y:
            model.outputs(t, x, u, m, p, rec_y[i_rec])
        i_rec += 1
    return i_rec


@register_jitable(forceinline=True)
def _record_dense(p, t, h, x0, f0, x1, f1, rc, mass, t_limit, u, m, ts, rec_t, rec_x, rec_m, rec_y, want_y,
                  xe, i_rec):
    """Record the samples in ``(t, t_limit]`` on the dense output of a step of length ``h``; returns the next index.

    The model's outputs are written straight into their row of ``rec_y`` (see :func:`_record_held`).  They are evaluated at the work copy ``xe`` of the recorded state, not at its row
    of ``rec_x``: with the row the recorded states of the EMTC AWD driveline example changed (by 4e-11), so a
    hook may not leave the state it is given untouched.
    """
    while i_rec < ts.shape[0] and ts[i_rec] <= t_limit:
        th = (ts[i_rec] - t) / h if h > 0.0 else 1.0
        _dense(th, h, x0, f0, x1, f1, rc, mass, xe)
        _store(rec_t, rec_x, rec_m, i_rec, ts[i_rec], xe, m)
        if want_y:
            model.outputs(ts[i_rec], xe, u, m, p, rec_y[i_rec])
        i_rec += 1
    return i_rec


@register_jitable(forceinline=True)
def _record_step(p, t, x, u, m, rec_t, rec_x, rec_m, rec_y, want_y, i_rec):
    """Record the point ``(t, x, m)`` in the step record if it has room; returns the next row (outputs
    written straight into their row of ``rec_y``: see :func:`_record_held`)."""
    if i_rec < rec_t.shape[0]:
        _store(rec_t, rec_x, rec_m, i_rec, t, x, m)
        if want_y:
            model.outputs(t, x, u, m, p, rec_y[i_rec])
        i_rec += 1
    return i_rec


# ============================================================ shared by both methods
# (helpers that do not call the model are ordinary cached functions: compiled once, not once per model)
#
# The helpers called once per step or per break carry ``forceinline=True`` (LLVM ``alwaysinline``): a call
# takes the model's arrays as dozens of argument words, with a reference-count call for each array read
# from a tuple; inlined, the EMTC bench with a 2 ms controller (one break per step) ran in 1.14 ms instead
# of 1.35 ms, the first compilation took as long as before within the machine's noise (docs/architecture.md).
@numba.njit(cache=True, nogil=True, forceinline=True)
def _run_limit(si, opt, grid, cap, i_rec):
    """Status that ends a run before its next step (step limit, every-step record full), else ``SUCCESS``."""
    if si[SI_ACCEPTED] >= opt.max_steps:
        return STEP_LIMIT
    if not grid and cap > 0 and i_rec >= cap:
        return RECORD_FULL
    return SUCCESS


@register_jitable(forceinline=True)
def _at_break(p, t, x, u, m, log, f, g, si):
    """At a break time ``t`` (input corner, controller sample): the model's ``restart``, then ``f`` and ``g``
    at ``t``; returns the next break time."""
    model.restart(t, x, u, m, p, log)
    model.rhs_event(t, x, u, m, p, f, g)
    model.watch(t, x, u, m, p, f, g, -1)
    si[SI_NRHS] += 1
    return model.next_break(t, m, p)


@numba.njit(cache=True, nogil=True, forceinline=True)
def _clip_step(h, t, t_stop, max_step):
    """Step size within ``max_step`` that ends exactly on ``t_stop`` if it would reach it; ``(h, last)``."""
    if h > max_step:
        h = max_step
    if h >= (t_stop - t) * (1.0 - 1e-9):
        return t_stop - t, True
    return h, False


#: Why a call resumed after ``RECORD_FULL`` skips the model's ``restart``.  A run recorded at every accepted step
#: (``simulate`` without samples) fills buffers of 256, 512, ... rows and is resumed in a new one each time.  A
#: restart there is no event of the model: a driveline searched its stuck sets again and its first derivative was
#: evaluated anew, so the run's result depended on where its buffers ended (two torque converters in series, issue
#: #30's seed 2074: the final speeds 7.8e-9 apart, sampled or not, from the buffer's end at step 256 on).  A resumed
#: record now goes on as one call would (a call ends with ``RECORD_FULL`` only after the break at its last instant,
#: if there is one, is taken: a resumption at a break skipped it, the sixtieth session's seed 2090, a brake applied
#: at 0.5 s left free until the next break at 0.75 s): with Dormand-Prince to the last bit (its first stage is the same
#: evaluation at the same point), and with Rodas3 where the solver state has room for its Jacobian
#: (:data:`RODAS_KEPT`; ``simulate`` makes it): the resumed call takes up the Jacobian, its age and staleness where the
#: call before left them (``Options.jac_every``) and factors the iteration matrix again from it, which gives the
#: same numbers as the one call's reuse.  Without that room it evaluated its Jacobian anew at every resumption, as at
#: the start of any call: ``ClutchDynamics(ClutchModel.preset(0))`` under issue #30's 0-8-0 mm profile (847 steps,
#: one resumption, its rtol 1e-5) took 218 Jacobians against 217 sampled and ended 1.2e-7 J of its 9.8 J input work
#: and 1e-10 m/s from its sampled run (the sixty-fourth session; now the same to the last bit).
RESUME_NOTE = "a record resumed after RECORD_FULL goes on as one run: no restart"


@numba.njit(cache=True, nogil=True, forceinline=True)
def _save_state(sf, si, t, h, i_rec, status, owners):
    """End of an ``advance``: the solver state saved; ``owners`` (the loop's work arrays) live until here."""
    sf[SF_T] = t
    sf[SF_H] = h
    si[SI_IREC] = i_rec
    si[SI_STATUS] = status
    return status


# ============================================================ Dormand-Prince 5(4)
@register_jitable
def _starting_step(p, t, x, u, m, k1, rtol, atol, span, xt, fe, ge):
    """The starting step of Hairer & Wanner's rule: the guess ``0.01 d0 / d1``, one evaluation of the
    right-hand side at its Euler step (the events' evaluation, ``rhs_event``; into the scratch ``xt``, ``fe``,
    ``ge``), then ``min(100 h0, h1)`` from the second derivative (:func:`.dopri.starting_step`), its growth limit
    never below 100 times the core's floor (``1e-14 max(1, |t|)``, where a step is ``STEP_UNDERFLOW``).  The
    guess alone fell to that floor when a state is tiny but not zero, and the run stopped (docs/driveline.md,
    #30)."""
    h0 = initial_step(x, k1, rtol, atol, span, 4)
    if h0 <= 0.0:
        return h0
    for i in range(x.shape[0]):
        xt[i] = x[i] + h0 * k1[i]
    model.rhs_event(t + h0, xt, u, m, p, fe, ge)
    return starting_step(h0, x, k1, fe, rtol, atol, span, 4, 1e-12 * max(1.0, abs(t)))


@register_jitable
def _advance_dopri(p, x, m, u, t_end, sf, si, opt, log, ts, rec_t, rec_x, rec_m, rec_y, want_y):
    """Advance a model with Dormand-Prince 5(4) from the solver state to ``t_end`` (resumable).

    Compiled into each model's entry points; arguments and result as in :func:`advance_dopri`.
    """
    p, x, m, u, sf, si, opt, log, ts, rec_t, rec_x, rec_m, rec_y = borrow(
        (p, x, m, u, sf, si, opt, log, ts, rec_t, rec_x, rec_m, rec_y))
    p = byref(p)  # (after borrow: the members read through the reference are not reference-counted)
    model.prepare(p)
    n = x.shape[0]
    ng = opt.gdir.shape[0]
    grid = ts.shape[0] > 0
    cap = rec_t.shape[0]
    K = np.empty((7, n))
    xt = np.empty(n)
    xn = np.empty(n)
    xe = np.empty(n)
    fe = np.empty(n)
    err = np.empty(n)
    rc = np.empty(n)
    g0 = np.empty(ng)
    g1 = np.empty(ng)
    ge = np.empty(ng)
    ga = np.empty(ng)
    tab_c = np.array([0.0, C2, C3, C4, C5, 1.0, 1.0])
    Ks = np.empty((5, n))
    xs = np.empty(n)
    gs = np.empty(ng)
    gd = np.empty(ng)
    # work arrays without reference counting (their owners are kept alive to the end of the run)
    owners = (K, xt, xn, xe, fe, err, rc, g0, g1, ge, ga, tab_c, Ks, xs, gs, gd)
    K, xt, xn, xe, fe, err, rc, g0, g1, ge, ga, tab_c, Ks, xs, gs, gd = borrow(owners)
    k1 = K[0]
    k2 = K[1]
    k3 = K[2]
    k4 = K[3]
    k5 = K[4]
    k6 = K[5]
    k7 = K[6]
    t = sf[SF_T]
    h = sf[SF_H]
    rtol = opt.rtol
    atol = opt.atol
    mass = opt.mass
    status = SUCCESS
    if si[SI_STARTED] == 0:   # what the run derives from its initial state (the model's start modes)
        r = model.start(t, x, u, m, p)
        if r < 0:   # (an initial state the model cannot start from)
            si[SI_MODEL_CODE] = r
            return _save_state(sf, si, t, h, si[SI_IREC], MODEL_ERROR, owners)
    if si[SI_STATUS] != RECORD_FULL:   # (a record resumed in a new buffer: RESUME_NOTE)
        model.restart(t, x, u, m, p, log)
    model.rhs(t, x, u, m, p, k1, g0)
    model.watch(t, x, u, m, p, k1, g0, -1)
    si[SI_NRHS] += 1
    i_rec = si[SI_IREC]
    if si[SI_STARTED] == 0:
        si[SI_STARTED] = 1
        if grid:
            i_rec = _record_held(p, t, t, x, u, m, ts, rec_t, rec_x, rec_m, rec_y, want_y, i_rec)
        else:
            i_rec = _record_step(p, t, x, u, m, rec_t, rec_x, rec_m, rec_y, want_y, i_rec)
        if opt.first_step > 0.0:
            h = opt.first_step
        else:
            h = _starting_step(p, t, x, u, m, k1, rtol, atol, t_end - t, xt, fe, ge)
            si[SI_NRHS] += 1
    if h <= 0.0:
        h = _starting_step(p, t, x, u, m, k1, rtol, atol, t_end - t, xt, fe, ge)
        si[SI_NRHS] += 1
    tb = model.next_break(t, m, p)
    prev_rej = False
    n_dips = 0
    waypoint_retry = False
    while t < t_end:
        t_stop = t_end if t_end < tb else tb
        if t_stop - t <= 1e-12 * max(1.0, abs(t_stop)):
            t = t_stop
            if t >= t_end:
                break
            tb = _at_break(p, t, x, u, m, log, k1, g0, si)
            continue
        # (after the break at t, not before it: a call that ends here with RECORD_FULL leaves no break to the call
        # that resumes it, which does not restart: RESUME_NOTE)
        status = _run_limit(si, opt, grid, cap, i_rec)
        if status != SUCCESS:
            break
        h, last = _clip_step(h, t, t_stop, opt.max_step)
        for k in range(ng):   # (per function: the first inner stage it changed sign at; _locate sets ga anew)
            ga[k] = 2.0
        if h < 1e-14 * max(1.0, abs(t)):
            status = STEP_UNDERFLOW
            break
        t1 = t_stop if last else t + h  # the step end, exactly as the step will end (stages with c = 1)
        # a step cut at a break evaluates its c = 1 stages at the inputs' left limits: a jump there (a step of a
        # torque, the corner of a prescribed speed's ramp) belongs to the next step, which restarts at the break
        t1s = t1 - 1e-15 * max(1.0, abs(t1)) if last else t1
        for stg in range(1, 7):
            # the stage points written out (a loop over a coefficient table makes each state's sum one chain
            # of dependent additions through memory: measured as most of the loop's own time); the sums run
            # in the tableau's order, as the table loop did, so results are the same to the last bit
            if stg == 1:
                for i in range(n):
                    xt[i] = x[i] + h * (A21 * k1[i])
            elif stg == 2:
                for i in range(n):
                    xt[i] = x[i] + h * (A31 * k1[i] + A32 * k2[i])
            elif stg == 3:
                for i in range(n):
                    xt[i] = x[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
            elif stg == 4:
                for i in range(n):
                    xt[i] = x[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
            elif stg == 5:
                for i in range(n):
                    xt[i] = x[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
            else:
                for i in range(n):
                    xt[i] = x[i] + h * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
            if stg == 6:
                for i in range(n):
                    xn[i] = xt[i]
            model.rhs_stage(t1s if tab_c[stg] == 1.0 else t + tab_c[stg] * h, xt, u, m, p, K[stg], g1)
            if stg <= 4:
                for k in range(ng):
                    if ga[k] > 1.0 and ((g0[k] > 0.0 and g1[k] < 0.0) or (g0[k] < 0.0 and g1[k] > 0.0)):
                        ga[k] = tab_c[stg]
        si[SI_NRHS] += 6
        for i in range(n):
            err[i] = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
        en = error_norm(err, x, xn, rtol, atol)
        if not (en <= 1.0):
            si[SI_REJECTED] += 1
            if en != en or not math.isfinite(en):
                h = 0.2 * h
            else:
                h = next_step(h, en, False)
            prev_rej = True
            continue
        model.watch(t1s, xn, u, m, p, k7, g1, -1)   # (the accepted step end's functions, compared with the start's)
        # a switching function that changed sign at an inner stage but not by the step's end may have crossed
        # zero and come back within the step (a stuck clutch's slip dipping through zero): the step is retried
        # shorter, at most 4 times in a row, so that its end falls in the dip and the crossing is located.  Every
        # function is looked at, also where another crosses by the step's end (its root may lie past the dip):
        # only the first to change sign at a stage was, and not where any function crossed, so a lossy gear's
        # margin in a group of stuck members whose split ran out of room, negative at a 0.125 s step's stages and
        # positive again at its end, was stepped over and the group's slip missed at rtol 1e-7 (#30; with the
        # crossings still excluded, a table gear in a loop of clutches was released at one tolerance only, at the
        # run's last instant).  CoupledClutches: 3 more steps at rtol 1e-6 and 1e-8 of 67 and 134
        retry = False
        c_dip = 2.0
        if n_dips < 4 and h > 64.0 * opt.event_tol:
            for k in range(ng):
                if ga[k] < c_dip and g0[k] * g1[k] > 0.0:
                    c_dip = ga[k]
            retry = c_dip <= 1.0
        if retry:
            n_dips += 1
            si[SI_REJECTED] += 1
            h = 0.9 * c_dip * h
            continue
        n_dips = 0
        # ---- events on the dense output (its order-4 term only where it is read)
        samples = grid and i_rec < ts.shape[0] and ts[i_rec] <= t1
        if _may_cross(g0, g1, opt.gdir):
            dense_correction(h, k1, k3, k4, k5, k6, k7, rc)
            samples = grid
            theta, nr, kw = _locate(p, t, h, x, k1, xn, k7, rc, u, m, g0, g1, opt.gdir, mass, opt.event_tol, xe, fe,
                                    ge, ga, not waypoint_retry)
        else:
            theta, nr, kw = 2.0, 0, -1
            if samples:
                dense_correction(h, k1, k3, k4, k5, k6, k7, rc)
        si[SI_NRHS] += nr
        if theta < 1.0 and kw >= 0 and abs(opt.gdir[kw]) >= 3:
            # the earliest root is a waypoint (a stuck element coming near its limit): the step is taken again,
            # ending just past it on its own solution, with no event and no waypoint looked at (a precise event
            # there cost CoupledClutches 17 % at rtol 1e-6)
            si[SI_REJECTED] += 1
            h = theta * h
            waypoint_retry = True
            continue
        waypoint_retry = False
        on_step = False
        if theta < 1.0:
            # the root moved to the step's own solution, the state the run restarts from
            theta, nr, on_step = _root_on_step(p, t, h, x, k1, xn, k7, rc, mass, g0, g1, ga, opt.gdir, u, m,
                                               opt.event_tol, theta, Ks, xt, xs, fe, ge, gs, gd)
            si[SI_NRHS] += nr
        if theta <= 1.0:
            t_new = t + theta * h
        elif last:
            t_new = t_stop
        else:
            t_new = t + h
        # ---- samples in (t, t_new] on the dense output (modes of the step; the test here saves a call per step)
        if samples and i_rec < ts.shape[0] and ts[i_rec] <= t_new:
            if on_step and theta < 1.0:
                # on the dense output of the step to the event (its stages are in Ks, its end slope in fe), which
                # ends on the state the run restarts from: samples and restart on one solution
                dense_correction(theta * h, k1, Ks[1], Ks[2], Ks[3], Ks[4], fe, rc)
                i_rec = _record_dense(p, t, theta * h, x, k1, xs, fe, rc, mass, t_new, u, m, ts, rec_t, rec_x, rec_m,
                                      rec_y, want_y, xe, i_rec)
            else:
                i_rec = _record_dense(p, t, h, x, k1, xn, k7, rc, mass, t_new, u, m, ts, rec_t, rec_x, rec_m, rec_y,
                                      want_y, xe, i_rec)
        si[SI_ACCEPTED] += 1
        if theta <= 1.0:
            if on_step:
                for i in range(n):
                    x[i] = xs[i]
            else:
                _dense(theta, h, x, k1, xn, k7, rc, mass, xe)
                for i in range(n):
                    x[i] = xe[i]
            t = t_new
            model.rhs(t, x, u, m, p, fe, g1)
            model.watch(t, x, u, m, p, fe, g1, -1)
            si[SI_NRHS] += 1
            flag = _apply_updates(p, t, x, u, m, ga, g1, opt.gdir, log)
            r = model.accept(t, x, u, m, p)
            if flag < 0 or r < 0:
                si[SI_MODEL_CODE] = flag if flag < 0 else r
                status = MODEL_ERROR
                break
            model.rhs(t, x, u, m, p, k1, g0)
            model.watch(t, x, u, m, p, k1, g0, -1)
            si[SI_NRHS] += 1
            if flag == RESTART:
                # the dynamics changed abruptly at the event (a speed jumping to a limit within microseconds):
                # the step before the event says nothing about the next one, and an error estimate over a
                # transient shorter than the stages' spacing misses it; start again from a step as short as
                # the event's bracket allows and let the controller grow it (at most tenfold per step)
                h = min(h, 64.0 * opt.event_tol)
            if flag == 1:
                status = TERMINATED
                if not grid:
                    i_rec = _record_step(p, t, x, u, m, rec_t, rec_x, rec_m, rec_y, want_y, i_rec)
                break
        else:
            for i in range(n):
                x[i] = xn[i]
                k1[i] = k7[i]
            for k in range(ng):
                g0[k] = g1[k]
            t = t_new
            r = model.accept(t, x, u, m, p)
            if r < 0:
                si[SI_MODEL_CODE] = r
                status = MODEL_ERROR
                break
            if r > 0:
                model.rhs(t, x, u, m, p, k1, g0)
                model.watch(t, x, u, m, p, k1, g0, -1)
                si[SI_NRHS] += 1
            h = next_step(h, en, prev_rej)
        prev_rej = False
        if not grid:
            i_rec = _record_step(p, t, x, u, m, rec_t, rec_x, rec_m, rec_y, want_y, i_rec)
    if grid and status == SUCCESS:  # samples at the end time itself (rounding) hold the final state
        i_rec = _record_held(p, t, min(t_end * (1.0 + 1e-12), t + 1e-9), x, u, m, ts, rec_t, rec_x, rec_m, rec_y,
                             want_y, i_rec)
    return _save_state(sf, si, t, h, i_rec, status, owners)


# ============================================================ Rosenbrock (Rodas3)
@register_jitable
def _rodas_step(p, t, x, h, u, m, J, mass, f0, ft, nonauto, xnew, err, G, piv, iw, fw, K1, K2, K3, K4, xtmp, ftmp,
                gtmp, refactor):
    """One Rodas3 step of size ``h`` from ``(t, x)``; False if the matrix is singular or NaN appears.

    The linear systems are solved along the reduction planned for ``J`` (``iw``, ``fw``:
    :func:`~clutchlab.numerics.rosenbrock.plan_reduction`): kinematic rows eliminated first, trailing states
    solved last, a partial-pivoting LU of the rest.  ``refactor`` False: the iteration matrix of the previous
    step is still the one for ``h`` and ``J`` (the same step size, the Jacobian kept), and its factors are
    used again.
    """
    n = x.shape[0]
    if refactor and not reduced_factor(J, mass, 1.0 / (h * R_GAMMA), G, iw, fw, piv):
        return False
    for i in range(n):
        K1[i] = f0[i] + (h * R_GAMMA1 * ft[i] if nonauto else 0.0)
    reduced_solve(G, iw, fw, piv, K1)
    for i in range(n):
        K2[i] = f0[i] + mass[i] * (R_C21 / h) * K1[i] + (h * R_GAMMA2 * ft[i] if nonauto else 0.0)
    reduced_solve(G, iw, fw, piv, K2)
    for i in range(n):
        xtmp[i] = x[i] + R_A31 * K1[i]
    model.rhs(t + h, xtmp, u, m, p, ftmp, gtmp)
    for i in range(n):
        K3[i] = ftmp[i] + mass[i] * (R_C31 * K1[i] + R_C32 * K2[i]) / h
    reduced_solve(G, iw, fw, piv, K3)
    for i in range(n):
        xtmp[i] = x[i] + R_A41 * K1[i] + R_A43 * K3[i]
    model.rhs(t + h, xtmp, u, m, p, ftmp, gtmp)
    for i in range(n):
        K4[i] = ftmp[i] + mass[i] * (R_C41 * K1[i] + R_C42 * K2[i] + R_C43 * K3[i]) / h
    reduced_solve(G, iw, fw, piv, K4)
    ok = True
    for i in range(n):
        xnew[i] = xtmp[i] + K4[i]
        err[i] = K4[i]
        if not math.isfinite(xnew[i]):
            ok = False
    return ok


@register_jitable(forceinline=True)
def _time_derivative(p, t, x, u, m, f0, tb, fp, gp, ft):
    """df/dt at ``t`` into ``ft``: the model's own (``time_derivative`` hook), else a forward difference
    (backward if a break time is within the difference); returns the number of ``rhs`` calls."""
    if model.time_derivative(t, x, u, m, p, ft):
        return 0
    dt = 1e-7 * max(1e-3, abs(t))
    if t + dt < tb:
        model.rhs(t + dt, x, u, m, p, fp, gp)
        for r in range(x.shape[0]):
            ft[r] = (fp[r] - f0[r]) / dt
    else:
        model.rhs(t - dt, x, u, m, p, fp, gp)
        for r in range(x.shape[0]):
            ft[r] = (f0[r] - fp[r]) / dt
    return 1


@register_jitable
def _fd_jacobian(p, t, x, u, m, f0, g0, opt, J, xp, fp, gp, dls, kinks):
    """Forward-difference Jacobian by column groups; backward where the forward step crosses a kink.

    The columns of one group of ``opt.jac_groups`` share no row of
    ``opt.jac_pattern`` and are perturbed together (one ``rhs`` call per
    group; column ``c`` fills only its pattern rows).  A forward perturbation
    that changes the sign of a switching function differences across a kink
    (cavitation, a contact, an end stop): that group is differenced
    backwards (only with ``kinks``: the fixed-step mode differences forwards always, so that every
    Jacobian costs the same).  Returns the number of ``rhs`` calls.
    """
    n = x.shape[0]
    ng = g0.shape[0]
    groups = opt.jac_groups
    pattern = opt.jac_pattern
    nr = 0
    for gi in range(groups.shape[0]):
        for i in range(n):
            xp[i] = x[i]
        for q in range(groups.shape[1]):
            c = groups[gi, q]
            if c < 0:
                break
            dls[c] = 1.5e-8 * max(abs(x[c]), opt.fd_scale[c])
            xp[c] = x[c] + dls[c]
        model.rhs(t, xp, u, m, p, fp, gp)
        nr += 1
        kink = False
        for k in range(ng if kinks else 0):
            if g0[k] * gp[k] < 0.0 or (gp[k] == 0.0 and g0[k] != 0.0):
                kink = True
                break
        if kink:
            for q in range(groups.shape[1]):
                c = groups[gi, q]
                if c < 0:
                    break
                dls[c] = -dls[c]
                xp[c] = x[c] + dls[c]
            model.rhs(t, xp, u, m, p, fp, gp)
            nr += 1
        for q in range(groups.shape[1]):
            c = groups[gi, q]
            if c < 0:
                break
            for r in range(n):
                J[r, c] = (fp[r] - f0[r]) / dls[c] if pattern[r, c] else 0.0
    return nr


@register_jitable(forceinline=True)
def _step_after_break(h, f_before, f_after, x, mass, rtol, atol, h_min):
    """Rodas3's step size after a break time at which the derivative jumped (an input corner that makes a
    prescribed velocity or a held voltage jump, a state reset by ``restart``).

    The step before the break says nothing about the next one: a jump excites fast transients (a mass on
    a stiff element rings) that an L-stable step much longer than them damps in both its solutions, so
    its error estimate does not see them and the step is accepted, while the dense output inside it, a
    cubic through the derivative of the start, is wrong by the jump times the step (issue #30: 3.1 % of
    the peak bearing force of a clutch whose bearing reverses, at every rtol).  A step that moves the
    solution by ``h (f_after - f_before)`` more than the tolerances allows is therefore restarted from
    ``h / jump`` (``jump``: that move in the error norm), at least ``h_min``, and grown again by the
    controller (at most ``MAX_FACTOR`` a step).  A continuous derivative (a kink of a reference that a
    controller follows) keeps the step.  Rows of zero mass (algebraic residuals) do not count.
    """
    s = 0.0
    n = x.shape[0]
    for i in range(n):
        if mass[i] == 0.0:
            continue
        r = h * (f_after[i] - f_before[i]) / (atol[i] + rtol * abs(x[i]))
        s += r * r
    jump = math.sqrt(s / n)
    if jump > 1.0:
        return max(h / jump, min(h, h_min))
    return h


@register_jitable
def _advance_rodas(p, x, m, u, t_end, sf, si, opt, log, ts, rec_t, rec_x, rec_m, rec_y, want_y):
    """Advance a model with Rodas3 from the solver state to ``t_end`` (resumable).

    Compiled into each model's entry points; arguments and result as in :func:`advance_rodas`.
    """
    p, x, m, u, sf, si, opt, log, ts, rec_t, rec_x, rec_m, rec_y = borrow(
        (p, x, m, u, sf, si, opt, log, ts, rec_t, rec_x, rec_m, rec_y))
    p = byref(p)  # (after borrow: the members read through the reference are not reference-counted)
    model.prepare(p)
    n = x.shape[0]
    ng = opt.gdir.shape[0]
    grid = ts.shape[0] > 0
    cap = rec_t.shape[0]
    mass = opt.mass
    rtol = opt.rtol
    atol = opt.atol
    f0 = np.empty(n)
    f1 = np.empty(n)
    ft = np.zeros(n)
    fp = np.empty(n)
    g0 = np.empty(ng)
    g1 = np.empty(ng)
    gp = np.empty(ng)
    ga = np.empty(ng)
    J = np.zeros((n, n))
    G = np.empty((n, n))
    piv = np.empty(n, dtype=np.int64)
    n_iw, n_fw = reduction_sizes(n)
    iw = np.zeros(n_iw, dtype=np.int64)
    fw = np.empty(n_fw)
    K1 = np.empty(n)
    K2 = np.empty(n)
    K3 = np.empty(n)
    K4 = np.empty(n)
    xtmp = np.empty(n)
    ftmp = np.empty(n)
    x1 = np.empty(n)
    xe = np.empty(n)
    xp = np.empty(n)
    err = np.empty(n)
    dls = np.empty(n)
    rc0 = np.zeros(n)  # no order-4 term in the dense output: Rodas3 is of order 3
    # work arrays without reference counting (their owners are kept alive to the end of the run)
    owners = (f0, f1, ft, fp, g0, g1, gp, ga, J, G, piv, iw, fw, K1, K2, K3, K4, xtmp, ftmp, x1, xe, xp, err, dls,
              rc0)
    (f0, f1, ft, fp, g0, g1, gp, ga, J, G, piv, iw, fw, K1, K2, K3, K4, xtmp, ftmp, x1, xe, xp, err, dls,
     rc0) = borrow(owners)
    t = sf[SF_T]
    h = sf[SF_H]
    status = SUCCESS
    if si[SI_STARTED] == 0:   # what the run derives from its initial state (the model's start modes)
        r = model.start(t, x, u, m, p)
        if r < 0:   # (an initial state the model cannot start from)
            si[SI_MODEL_CODE] = r
            return _save_state(sf, si, t, h, si[SI_IREC], MODEL_ERROR, owners)
    if si[SI_STATUS] != RECORD_FULL:   # (a record resumed in a new buffer: RESUME_NOTE)
        model.restart(t, x, u, m, p, log)
    model.rhs(t, x, u, m, p, f0, g0)
    model.watch(t, x, u, m, p, f0, g0, -1)
    si[SI_NRHS] += 1
    i_rec = si[SI_IREC]
    if si[SI_STARTED] == 0:
        si[SI_STARTED] = 1
        if grid:
            i_rec = _record_held(p, t, t, x, u, m, ts, rec_t, rec_x, rec_m, rec_y, want_y, i_rec)
        else:
            i_rec = _record_step(p, t, x, u, m, rec_t, rec_x, rec_m, rec_y, want_y, i_rec)
        h = opt.first_step if opt.first_step > 0.0 else 1e-5
        sf[SF_T0] = t
    if h <= 0.0:
        h = 1e-5
    tb = model.next_break(t, m, p)
    need_jac = True
    jac_stale = True
    jac_age = opt.jac_every
    rejected_before = False
    en = 0.0
    h_fact = 0.0  # the step size of the factored iteration matrix (0: none)
    hf = opt.fixed_step
    fixed = hf > 0.0
    # a record resumed in a new buffer takes up the Jacobian where the call before left it (RESUME_NOTE), where the
    # solver state has room for it; the iteration matrix is factored again from it (h_fact 0): the same numbers
    kept = sf.shape[0] >= N_SF + N_SK + n * n
    if kept and si[SI_STATUS] == RECORD_FULL:
        jac_age = np.int64(sf[N_SF + SK_AGE])
        jac_stale = sf[N_SF + SK_STALE] != 0.0
        o = N_SF + N_SK
        for i in range(n):
            for j in range(n):
                J[i, j] = sf[o + i * n + j]
        plan_reduction(J, mass, iw)
    while t < t_end:
        if fixed:
            status = _run_limit(si, opt, grid, cap, i_rec)   # (its breaks are taken within its steps)
            if status != SUCCESS:
                break
            # ---- fixed-step mode (a HIL frame): one step to the next point of the grid t0 + k hf (t_end if it
            # comes first), the same work every step: Jacobian, df/dt, two stages and two right-hand sides;
            # no error control; switching functions and break times are looked at the step end only
            kf = math.floor((t - sf[SF_T0]) / hf + 1e-6) + 1.0
            t_new = sf[SF_T0] + kf * hf
            if t_new >= t_end - 1e-6 * hf:
                t_new = t_end
            h = t_new - t
            if h <= 1e-9 * hf:  # t_end within rounding of t: the run is there
                t = t_end
                break
            if not model.jacobian(t, x, u, m, p, J):
                si[SI_NRHS] += _fd_jacobian(p, t, x, u, m, f0, g0, opt, J, xp, fp, gp, dls, False)
            plan_reduction(J, mass, iw)
            si[SI_NJAC] += 1
            if opt.nonautonomous:
                si[SI_NRHS] += _time_derivative(p, t, x, u, m, f0, tb, fp, gp, ft)
            ok = _rodas_step(p, t, x, h, u, m, J, mass, f0, ft, opt.nonautonomous, x1, err, G, piv, iw, fw, K1, K2,
                             K3, K4, xtmp, ftmp, gp, True)
            si[SI_NRHS] += 2
            if not ok:
                status = SINGULAR
                break
            model.rhs(t_new, x1, u, m, p, f1, g1)
            model.watch(t_new, x1, u, m, p, f1, g1, -1)
            si[SI_NRHS] += 1
            if grid and i_rec < ts.shape[0] and ts[i_rec] <= t_new:
                i_rec = _record_dense(p, t, h, x, f0, x1, f1, rc0, mass, t_new, u, m, ts, rec_t, rec_x, rec_m,
                                      rec_y, want_y, xe, i_rec)
            si[SI_ACCEPTED] += 1
            for i in range(n):
                x[i] = x1[i]
            t = t_new
            # mode changes at the step end, as a HIL target sees them: no root finding
            flag = _apply_updates(p, t, x, u, m, g0, g1, opt.gdir, log)
            r = model.accept(t, x, u, m, p)
            if flag < 0 or r < 0:
                si[SI_MODEL_CODE] = flag if flag < 0 else r
                status = MODEL_ERROR
                break
            if tb <= t + 1e-6 * hf:  # a break time inside the step or on its end: restart at the step end
                model.restart(t, x, u, m, p, log)
                tb = model.next_break(t, m, p)
            # the derivative at the step end again, always (modes, restart or accept may have changed it):
            # every step evaluates the same number of right-hand sides
            model.rhs(t, x, u, m, p, f0, g0)
            model.watch(t, x, u, m, p, f0, g0, -1)
            si[SI_NRHS] += 1
            if not grid:
                i_rec = _record_step(p, t, x, u, m, rec_t, rec_x, rec_m, rec_y, want_y, i_rec)
            if flag == 1:
                status = TERMINATED
                break
            continue
        t_stop = t_end if t_end < tb else tb
        if t_stop - t <= 1e-12 * max(1.0, abs(t_stop)):
            t = t_stop
            if t >= t_end:
                break
            for i in range(n):
                fp[i] = f0[i]  # the derivative before the break
            tb = _at_break(p, t, x, u, m, log, f0, g0, si)
            h = _step_after_break(h, fp, f0, x, mass, rtol, atol, 64.0 * opt.event_tol)
            need_jac = True
            jac_stale = True
            continue
        status = _run_limit(si, opt, grid, cap, i_rec)   # (after the break at t: as Dormand-Prince's)
        if status != SUCCESS:
            break
        if need_jac:
            if jac_age >= opt.jac_every or jac_stale:
                if not model.jacobian(t, x, u, m, p, J):
                    si[SI_NRHS] += _fd_jacobian(p, t, x, u, m, f0, g0, opt, J, xp, fp, gp, dls, True)
                plan_reduction(J, mass, iw)
                h_fact = 0.0  # a new Jacobian: factor again
                jac_age = 0
                jac_stale = False
                si[SI_NJAC] += 1
            if opt.nonautonomous:
                si[SI_NRHS] += _time_derivative(p, t, x, u, m, f0, tb, fp, gp, ft)
            need_jac = False
        h, hit_stop = _clip_step(h, t, t_stop, opt.max_step)
        if h < 1e-14 * max(1.0, abs(t)):
            status = STEP_UNDERFLOW
            break
        ok = _rodas_step(p, t, x, h, u, m, J, mass, f0, ft, opt.nonautonomous, x1, err, G, piv, iw, fw, K1, K2, K3,
                         K4, xtmp, ftmp, gp, h != h_fact)
        h_fact = h
        si[SI_NRHS] += 2
        en = error_norm(err, x, x1, rtol, atol) if ok else np.inf
        if not (en <= 1.0):
            si[SI_REJECTED] += 1
            h = rodas_next_step(h, en, rejected_before)
            rejected_before = True
            if jac_age > 0:
                jac_stale = True
                need_jac = True
            continue
        # step end: derivative (dense output, next step's f0) and switching functions
        model.rhs(t + h, x1, u, m, p, f1, g1)
        model.watch(t + h, x1, u, m, p, f1, g1, -1)
        si[SI_NRHS] += 1
        if _may_cross(g0, g1, opt.gdir):
            theta, nr, _kw = _locate(p, t, h, x, f0, x1, f1, rc0, u, m, g0, g1, opt.gdir, mass, opt.event_tol, xe,
                                     ftmp, gp, ga, True)
        else:
            theta, nr = 2.0, 0
        si[SI_NRHS] += nr
        event = False
        if theta <= 1.0:
            # land on the located instant with one step of that length (consistent algebraic rows)
            hs = theta * h
            ok2 = _rodas_step(p, t, x, hs, u, m, J, mass, f0, ft, opt.nonautonomous, xe, err, G, piv, iw, fw, K1, K2,
                              K3, K4, xtmp, ftmp, gp, True)
            h_fact = hs
            si[SI_NRHS] += 2
            if ok2:
                model.rhs(t + hs, xe, u, m, p, ftmp, gp)
                model.watch(t + hs, xe, u, m, p, ftmp, gp, -1)
                si[SI_NRHS] += 1
                for i in range(n):
                    x1[i] = xe[i]
                    f1[i] = ftmp[i]
                for k in range(ng):
                    g1[k] = gp[k]
                h_acc = hs
                event = True
            else:
                h_acc = h
        else:
            h_acc = h
        t_new = t + h_acc
        if hit_stop and not event:
            t_new = t_stop
        if grid and i_rec < ts.shape[0] and ts[i_rec] <= t_new:
            i_rec = _record_dense(p, t, h_acc, x, f0, x1, f1, rc0, mass, t_new, u, m, ts, rec_t, rec_x, rec_m, rec_y,
                                  want_y, xe, i_rec)
        si[SI_ACCEPTED] += 1
        for i in range(n):
            x[i] = x1[i]
            f0[i] = f1[i]
        t = t_new
        flag = 0
        if event:
            flag = _apply_updates(p, t, x, u, m, ga, g1, opt.gdir, log)
            jac_stale = True
        r = model.accept(t, x, u, m, p)
        if flag < 0 or r < 0:
            si[SI_MODEL_CODE] = flag if flag < 0 else r
            status = MODEL_ERROR
            break
        if event or r > 0:
            model.rhs(t, x, u, m, p, f0, g0)
            model.watch(t, x, u, m, p, f0, g0, -1)
            si[SI_NRHS] += 1
            if flag == RESTART:
                # the model says the dynamics changed at the event (a mass breaking away from its stuck
                # phase): the trial step of the mode before says nothing about the next one, and one much
                # longer than the ringing the new mode starts would damp it unseen (L-stable stages, issue
                # #30); start afresh as after a break time at which the derivative jumps
                h = _step_after_break(h, f1, f0, x, mass, rtol, atol, 64.0 * opt.event_tol)
        else:
            for k in range(ng):
                g0[k] = g1[k]
        need_jac = True
        jac_age += 1
        if not grid:
            i_rec = _record_step(p, t, x, u, m, rec_t, rec_x, rec_m, rec_y, want_y, i_rec)
        if flag == 1:
            status = TERMINATED
            break
        if not event:
            h_new = rodas_next_step(h, en, rejected_before)
            h = h_new if not hit_stop else max(h, h_new)
        rejected_before = False
    if grid and status == SUCCESS:  # samples at the end time itself (rounding) hold the final state
        i_rec = _record_held(p, t, min(t_end * (1.0 + 1e-12), t + 1e-9), x, u, m, ts, rec_t, rec_x, rec_m, rec_y,
                             want_y, i_rec)
    if kept and status == RECORD_FULL:   # (for the call that resumes the record: above)
        sf[N_SF + SK_AGE] = jac_age
        sf[N_SF + SK_STALE] = 1.0 if jac_stale else 0.0
        o = N_SF + N_SK
        for i in range(n):
            for j in range(n):
                sf[o + i * n + j] = J[i, j]
    return _save_state(sf, si, t, h, i_rec, status, owners)


# ============================================================ evaluation through the contract
@register_jitable
def _evaluate(p, t, x, u, m, dx, g):
    p = byref(borrow(p))  # the same specialisation of the hooks as the loops'
    model.prepare(p)
    model.rhs(t, x, u, m, p, dx, g)
    model.watch(t, x, u, m, p, dx, g, -1)   # (the switching functions as the core compares them)


@register_jitable
def _evaluate_jacobian(p, t, x, u, m, J):
    p = byref(borrow(p))
    model.prepare(p)
    return model.jacobian(t, x, u, m, p, J)


@register_jitable
def _start(p, t, x, u, m):
    """The model's ``start`` at ``(t, x, u)``: the modes ``m`` (and what else it derives) from the state alone, as a run
    that has not started decides them (a co-simulation's outputs before its first step)."""
    p = byref(borrow(p))
    model.prepare(p)
    return model.start(t, x, u, m, p)


@register_jitable
def _evaluate_outputs(p, t, x, u, m, y):
    p = byref(borrow(p))
    model.prepare(p)
    model.outputs(t, x, u, m, p, y)


@register_jitable
def _outputs_at(p, T, X, u, M, Y):
    p = byref(borrow(p))
    model.prepare(p)
    y = np.empty(Y.shape[1])
    for i in range(T.shape[0]):
        model.outputs(T[i], X[i], u, M[i], p, y)
        for q in range(y.shape[0]):
            Y[i, q] = y[q]


# ============================================================ Python entry points (compiled per model)
def advance_dopri(p, x, m, u, t_end, sf, si, opt, log, ts, rec_t, rec_x, rec_m, rec_y, want_y):
    """Advance a model with Dormand-Prince 5(4) from the solver state to ``t_end`` (resumable).

    Parameters
    ----------
    p : NamedTuple
        The model's packed parameters (selects the model).
    x, m, u : ndarray
        State [SI], mode vector (int64) and held inputs; ``x`` and ``m`` are
        updated in place.
    t_end : float
        End of this call [s].
    sf, si : ndarray
        Solver state from :func:`new_solver_state` (time, step, counters, status).
    opt : Options
    log : EventLog
    ts : ndarray
        Sample times [s]; empty records every accepted step into the record
        buffers until they are full (status ``RECORD_FULL``: resume with
        ``si[SI_IREC] = 0``); record buffers of length 0 record nothing.
        A resumed record goes on as one run: every other call starts with
        the model's ``restart`` (the inputs may have changed), a call after
        ``RECORD_FULL`` does not (:data:`RESUME_NOTE`).
    rec_t, rec_x, rec_m, rec_y : ndarray
        Record buffers (time, states, modes, outputs); ``rec_y`` is written
        only if ``want_y``.
    want_y : bool

    Returns
    -------
    int
        Status (:mod:`clutchlab.numerics.status`), also in ``si[SI_STATUS]``.

    Notes
    -----
    After an event the next step is tried with the step size of the step that found it, unless an
    ``update`` returned :data:`RESTART`: then from ``64 * event_tol``, grown by the controller.  (A fast
    transient right after an event -- the wet clutch's piston reaching the actuator's speed limit within a
    microsecond of leaving its stop -- is shorter than the spacing of the stages of a step of the old size;
    the error estimate missed it and the piston lagged 2.6e-7 m behind for the rest of the run, at every
    ``rtol`` from 1e-3 to 1e-7.)
    """
    return fast_entry(type(p), "dopri", "advance")(p, x, m, u, t_end, sf, si, opt, log, ts, rec_t, rec_x, rec_m,
                                                   rec_y, want_y)


def advance_rodas(p, x, m, u, t_end, sf, si, opt, log, ts, rec_t, rec_x, rec_m, rec_y, want_y):
    """Advance a model with Rodas3 from the solver state to ``t_end`` (resumable).

    The Jacobian is the model's analytic one where its ``jacobian`` hook
    returns True, else a finite-difference one grouped by the sparsity
    pattern, reused for ``opt.jac_every`` accepted steps and refreshed after
    a rejection or a mode change.  The state at a located event comes from
    one Rodas3 step of the located length from the step start, so the
    algebraic rows stay consistent.

    With ``opt.fixed_step`` > 0 (the fixed-step mode, a HIL frame) the loop
    takes steps of exactly that length on the grid ``t0 + k * fixed_step``
    (``t0`` the run's start, ``sf[SF_T0]``; an end off the grid ends with a
    shorter step), without error control, with the Jacobian every step
    (forward differences only) and the same number of right-hand sides every
    step; switching functions are looked at the step end (``update`` there,
    no root finding) and break times inside a step call ``restart`` at its
    end.  Any model can run so, also one registered for Dormand-Prince.

    Parameters
    ----------
    p : NamedTuple
        The model's packed parameters (selects the model).
    x, m, u : ndarray
        State [SI], mode vector (int64) and held inputs; ``x`` and ``m`` are updated in place.
    t_end : float
        End of this call [s].
    sf, si : ndarray
        Solver state from :func:`new_solver_state`.
    opt : Options
    log : EventLog
    ts : ndarray
        Sample times [s] (empty: every accepted step, see :func:`advance_dopri`).
    rec_t, rec_x, rec_m, rec_y : ndarray
        Record buffers (time, states, modes, outputs).
    want_y : bool
        Evaluate the outputs into ``rec_y``.

    Returns
    -------
    int
        Status (:mod:`clutchlab.numerics.status`).

    Notes
    -----
    After an event the next step is tried with the step size of the step that found it, unless an
    ``update`` returned :data:`RESTART`: then it starts afresh as after a break time at which the derivative
    jumps (``_step_after_break``: from ``h / jump``, at least ``64 * event_tol``), grown by the controller.
    (The E-clutch's clutch alone asks for it at every stick and break-away: a first step of the stuck
    phase's length damped the pressure plate's stick-slip ringing away unseen, issue #30.)
    """
    return fast_entry(type(p), "rodas", "advance")(p, x, m, u, t_end, sf, si, opt, log, ts, rec_t, rec_x, rec_m,
                                                   rec_y, want_y)


def batch(method, P, X0, M0, U, t_end, ts, opt, OUT_X, OUT_M, OUT_Y, want_y, STATS, EV_T, EV_C, EV_E, EV_N):
    """One solver per variant, in parallel (``prange``), recorded on ``ts``.

    Parameters
    ----------
    method : {"dopri", "rodas"}
    P : NamedTuple
        The variants' parameter structures stacked: every array with a leading variant axis
        (:class:`clutchlab.system.Variants`); variant ``v`` runs on views of row ``v``.
    X0, M0, U : ndarray
        Initial states, modes and held inputs, one row per variant.
    t_end : float
        End time [s].
    ts : ndarray
        Sample times [s].
    opt : Options
        Step control shared by all variants.
    OUT_X, OUT_M, OUT_Y : ndarray
        Records ``(variant, sample, column)``; ``OUT_Y`` written only if ``want_y``.
    want_y : bool
    STATS : ndarray
        Solver counters per variant (``SI_*``).
    EV_T, EV_C, EV_E, EV_N : ndarray
        Events per variant: time, code, element; ``EV_N[v]`` = (held, dropped).
    """
    entry_points(type(P), method).batch(P, X0, M0, U, t_end, ts, opt, OUT_X, OUT_M, OUT_Y, want_y, STATS, EV_T, EV_C,
                                        EV_E, EV_N)


def closed_loop(method, p, x, m, u, sf, si, opt, log, ybuf, T, R, meas_kind, meas_idx, act, lo, hi, delay, kind, f, A,
                B, C, D, xc, sched, par, memory, u_op, Y, U, S):
    """Run a model with a sampled controller in the compiled loop (:mod:`clutchlab.numerics.sampled`).

    Parameters
    ----------
    method : {"dopri", "rodas"}
        The loop advancing the model between samples ("rodas" for the fixed-step mode).
    p, x, m, u, sf, si, opt, log
        As :func:`advance_rodas` (``x``, ``m``, ``u``, ``sf``, ``si``, ``log`` updated in place).
    ybuf : ndarray
        Work array of the model's outputs.
    T : ndarray
        Sample instants [s], ``T[0]`` the solver state's time.
    R : ndarray
        References ``(samples, measured)``.
    meas_kind, meas_idx : ndarray
        Measured signals: 0 a state, 1 an output, and its index.
    act : ndarray
        Indices of the actuated inputs.
    lo, hi : ndarray
        Limits of the actuated inputs.
    delay : int
        0 or 1 samples between reading and applying.
    kind : int
        ``sampled.LTI``, ``sampled.SCHEDULED_PI`` or ``sampled.FUNCTION``.
    f : numba.core.ccallback.CFunc
        The compiled function controller's C entry (:func:`clutchlab.numerics.sampled.function_pointer`;
        a placeholder for the other kinds).
    A, B, C, D, xc : ndarray
        The LTI controller's matrices and state (``xc`` updated).
    sched, par, memory : ndarray
        The scheduled PI's tables, parameters and memory (``memory`` updated).
    u_op : ndarray
        Operating-point values of the actuated inputs (LTI) or the held values before the first sample.
    Y, U, S : ndarray
        Records per sample: measured values, applied inputs, saturation flag.

    Returns
    -------
    tuple of int
        Status of the last advance (-1: the function controller returned the wrong number of values) and
        the number of samples done.
    """
    return fast_entry(type(p), method, "closed_loop")(p, x, m, u, sf, si, opt, log, ybuf, T, R, meas_kind, meas_idx,
                                                      act, lo, hi, delay, kind, f, A, B, C, D, xc, sched, par, memory,
                                                      u_op, Y, U, S)


def evaluate(p, t, x, u, m, dx, g):
    """The model's right-hand side ``dx`` and switching functions ``g`` at one point (linearisation, tests)."""
    fast_entry(type(p), "dopri", "evaluate")(p, t, x, u, m, dx, g)


def evaluate_jacobian(p, t, x, u, m, J):
    """The model's analytic Jacobian ``df/dx`` at one point ``(t, x, u, m)`` of parameters ``p``, into ``J``.

    Returns ``False`` (``J`` untouched) if the model has none (the core then differences ``rhs``).
    """
    return bool(fast_entry(type(p), "dopri", "evaluate_jacobian")(p, t, x, u, m, J))


def evaluate_outputs(p, t, x, u, m, y):
    """The model's outputs ``y`` at one point ``(t, x, u, m)``."""
    fast_entry(type(p), "dopri", "evaluate_outputs")(p, t, x, u, m, y)


def start(p, t, x, u, m):
    """The model's ``start`` at ``(t, x, u)``: the modes ``m`` a run starts from (and what else the model derives from
    its initial state alone), as the run itself decides them; nothing for a model without the hook.  Returns 0, or
    the model error code of an initial state the model cannot start from (:mod:`clutchlab.numerics.dispatch`)."""
    return int(fast_entry(type(p), "dopri", "start")(p, t, x, u, m))


def outputs_at(p, T, X, u, M, Y):
    """Outputs at recorded points ``(T[i], X[i], M[i])`` into ``Y[i]``."""
    fast_entry(type(p), "dopri", "outputs_at")(p, T, X, u, M, Y)


from .entry import entry_points, fast_entry  # noqa: E402  (entry imports this module's names lazily)
