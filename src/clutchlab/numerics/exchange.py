"""A model's equations for an external integrator: FMI 2.0 Model Exchange (a native FMU, :mod:`clutchlab.fmu.native`).

In co-simulation the integrator core (:mod:`clutchlab.numerics.core`) integrates the model and handles its
events itself.  In model exchange the importing tool's solver does (Dymola's, OpenModelica's, CVode in
FMPy): it asks for the derivatives and the switching functions (*event indicators*) at the points it chooses,
locates their sign changes, and lets the model update its modes at each event.  :func:`call` gives a
session's model exactly those operations, compiled as each model's ``model_exchange`` entry
(:mod:`clutchlab.numerics.entry`), with the same hooks the core calls and in the same order:

``ME_DERIVATIVES``
    ``rhs`` and ``watch`` at ``(t, x, u, m)``: the derivatives into ``dx``, the switching functions into
    ``g1`` (as the core compares them).
``ME_ACCEPT``
    a step the solver completed: the model's ``accept`` (its value, > 0 asking for the functions again, is
    returned; < 0 is a model error).
``ME_EVENT``
    at an event: ``update`` for every switching function that crossed from ``g0`` (stored at the last
    completed step) to its value now, in its direction (``opt.gdir``), as the core's ``_apply_updates``;
    returns its flag (1 terminal, 2 restart of the step size, < 0 a model error).
``ME_RESTART``
    the modes decided again from the state and inputs (initialisation, a time event, inputs changed):
    the model's ``restart``, then ``rhs_event`` and ``watch`` as at the core's breaks.
``ME_START``
    before the others: the model's ``start`` (what it derives from its initial state alone: its start modes),
    at the initialisation, again after a host set a start value.
``ME_STORE``
    after the others: ``g0 = g1`` (the functions an event is looked for against).
``ME_OUTPUTS``
    the outputs into ``y`` and the reported values into ``r`` (as :func:`clutchlab.numerics.session.call`).

``out[0]`` is set to the model's next break time (``next_break``: an input's corner, a controller sample;
the FMU's next time event).  The session's arguments are ``(p, x, m, u, sf, si, opt, log, dx, g0, g1, out,
y, report, r, alg, jac, sub, piv, xp, fp, gp, dls)``, packed in a table as a co-simulation session's are
(:data:`FIELDS`); the time is ``sf[SF_T]``.

**Algebraic states** (a zero in the mass matrix ``opt.mass``: the E-clutch's massless nodes, whose rows say
that their forces balance, ``0 = f_a(x_d, x_a)``; index 1) are not given to the external integrator: it
integrates the differential states ``x_d`` only, and before every evaluation :func:`_consistent` solves the
algebraic rows for ``x_a`` by Newton's method from their last values (the Jacobian block ``df_a/dx_a`` from
the model's analytic ``jacobian`` or by differences, factored by
:func:`~clutchlab.numerics.rosenbrock.lu_factor`), to rounding: ``|dx_a| <= 1e-12 (atol + |x_a|)``, or, where
rounding in the residual stops the steps shrinking, within a thousandth of the model's own tolerance
``atol + rtol |x_a|``.  (FMI 2.0 does not tell the FMU the host's tolerance; an algebraic error at the
model's tolerance is noise in the derivatives that a host integrating more tightly cannot get through.)
The host then integrates the ODE ``x_d' = f_d(x_d, x_a(x_d))`` (the state-space form of an index-1 DAE;
Hairer & Wanner II, VI.1).
``alg`` lists the algebraic rows; ``jac`` (n x n), ``sub`` and ``piv`` (n_a) and ``xp``, ``fp``, ``gp``,
``dls`` are its work arrays (empty for a model without algebraic rows).  A Newton iteration that does not
converge in :data:`NEWTON_ITERATIONS` returns :data:`ALGEBRAIC_FAILED`.
"""

from __future__ import annotations

import numpy as np
from numba.extending import register_jitable

from . import dispatch as model
from .borrow import borrow, byref
from .core import SF_T, _apply_updates, _fd_jacobian
from .layout import bits
from .rosenbrock import lu_factor, lu_solve
from .session import _args, fill_report

__all__ = ["call", "FIELDS", "ME_DERIVATIVES", "ME_ACCEPT", "ME_EVENT", "ME_RESTART", "ME_STORE", "ME_OUTPUTS", "ME_START",
           "ALGEBRAIC_FAILED", "NEWTON_ITERATIONS", "workspace"]

#: what a model-exchange call may be asked for, one bit each (a native FMU's C layer gets them as #defines)
ME_REQUESTS = ("derivatives", "accept", "event", "restart", "store", "outputs", "start")
ME_DERIVATIVES, ME_ACCEPT, ME_EVENT, ME_RESTART, ME_STORE, ME_OUTPUTS, ME_START = bits(
    ME_REQUESTS, "derivatives", "accept", "event", "restart", "store", "outputs", "start")

#: a model error of the exchange itself: the algebraic rows' Newton iteration did not converge
ALGEBRAIC_FAILED = -9001
#: Newton iterations allowed for the algebraic rows at one evaluation
NEWTON_ITERATIONS = 30
#: the Newton step, relative to the state (plus its absolute tolerance), below which the rows are solved: to
#: rounding, whatever tolerance the host integrates with (FMI 2.0 does not tell the FMU)
NEWTON_TIGHT = 1e-12
#: where the steps stop shrinking (rounding in the residual), they are accepted below this fraction of the
#: model's own tolerance ``atol + rtol |x|``
NEWTON_LOOSE = 1e-3

#: members of a model-exchange session's packed arguments (a tuple, in this order)
FIELDS = ("p", "x", "m", "u", "sf", "si", "opt", "log", "dx", "g0", "g1", "out", "y", "report", "r",
          "alg", "jac", "sub", "piv", "xp", "fp", "gp", "dls")


def workspace(mass, n_switch):
    """The model-exchange session's work arrays ``(alg, jac, sub, piv, xp, fp, gp, dls)`` for a model with
    the mass-matrix diagonal ``mass`` and ``n_switch`` switching functions (module docstring; all empty
    where no row is algebraic)."""
    mass = np.asarray(mass, dtype=float)
    alg = np.flatnonzero(mass == 0.0).astype(np.int64)
    n = mass.size if alg.size else 0
    return (alg, np.zeros((n, n)), np.zeros((alg.size, alg.size)), np.zeros(alg.size, dtype=np.int64),
            np.zeros(n), np.zeros(n), np.zeros(n_switch if alg.size else 0), np.zeros(n))


@register_jitable
def _consistent(p, t, x, u, m, opt, dx, g, alg, jac, sub, piv, xp, fp, gp, dls):
    """Solve the algebraic rows ``alg`` (``dx[alg] = 0``) for ``x[alg]`` by Newton's method (module docstring),
    leaving ``rhs`` evaluated at the solution in ``dx`` and ``g``.  Returns 0, or :data:`ALGEBRAIC_FAILED`."""
    na = alg.shape[0]
    model.rhs(t, x, u, m, p, dx, g)
    if na == 0:
        return 0
    before = np.inf
    for _ in range(NEWTON_ITERATIONS):
        if not model.jacobian(t, x, u, m, p, jac):
            _fd_jacobian(p, t, x, u, m, dx, g, opt, jac, xp, fp, gp, dls, False)
        for i in range(na):
            for j in range(na):
                sub[i, j] = jac[alg[i], alg[j]]
            xp[i] = -dx[alg[i]]
        if not lu_factor(sub, piv):
            return ALGEBRAIC_FAILED
        step = xp[:na]
        lu_solve(sub, piv, step)
        tight = True
        loose = True
        size = 0.0
        for i in range(na):
            k = alg[i]
            if not abs(step[i]) <= NEWTON_TIGHT * (opt.atol[k] + abs(x[k])):
                tight = False
            if not abs(step[i]) <= NEWTON_LOOSE * (opt.atol[k] + opt.rtol * abs(x[k])):
                loose = False
            size = max(size, abs(step[i]) / (opt.atol[k] + abs(x[k])))
            x[k] += step[i]
        model.rhs(t, x, u, m, p, dx, g)
        # solved to rounding; or the steps stopped shrinking (rounding in the residual) well inside the model's
        # own tolerance
        if tight or (loose and size >= 0.5 * before):
            return 0
        before = size
    return ALGEBRAIC_FAILED


@register_jitable
def call(s, what):
    """One model-exchange operation (module docstring) on the session ``s``; returns 0, the flag of
    ``accept``/``update`` (> 0), or a model error (< 0).  Compiled as each model's ``model_exchange`` entry."""
    p0, x, m, u, sf, si, opt, log, dx, g0, g1, out, y, report, r, alg, jac, sub, piv, xp, fp, gp, dls = _args(s)
    p = byref(borrow(p0))
    model.prepare(p)
    t = sf[SF_T]
    code = 0
    if what & ME_START:
        code = model.start(t, x, u, m, p)
        if code < 0:   # (an initial state the model cannot start from)
            return code
    if alg.shape[0] and what & (ME_DERIVATIVES | ME_EVENT | ME_RESTART | ME_OUTPUTS):
        # (the algebraic rows solved for the differential states the host set; again after an event or a
        # restart that moved them or changed the modes)
        if _consistent(p, t, x, u, m, opt, dx, g1, alg, jac, sub, piv, xp, fp, gp, dls) < 0:
            return ALGEBRAIC_FAILED
    if what & ME_ACCEPT:
        code = model.accept(t, x, u, m, p)
        if code < 0:
            return code
    if what & ME_EVENT:
        model.rhs(t, x, u, m, p, dx, g1)
        model.watch(t, x, u, m, p, dx, g1, -1)
        code = _apply_updates(p, t, x, u, m, g0, g1, opt.gdir, log)
        if code < 0:
            return code
    if what & ME_RESTART:
        model.restart(t, x, u, m, p, log)
        model.rhs_event(t, x, u, m, p, dx, g1)
        model.watch(t, x, u, m, p, dx, g1, -1)
    if alg.shape[0] and what & (ME_EVENT | ME_RESTART):
        if _consistent(p, t, x, u, m, opt, dx, g1, alg, jac, sub, piv, xp, fp, gp, dls) < 0:
            return ALGEBRAIC_FAILED
    if what & (ME_DERIVATIVES | ME_EVENT):
        model.rhs(t, x, u, m, p, dx, g1)
        model.watch(t, x, u, m, p, dx, g1, -1)
    if what & ME_STORE:
        for k in range(g1.shape[0]):
            g0[k] = g1[k]
    if what & ME_OUTPUTS:
        model.outputs(t, x, u, m, p, y)
        fill_report(report, y, x, m, r)
    out[0] = model.next_break(t, m, p)
    return code
