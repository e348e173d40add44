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
``ME_STORE``
    after the others: ``g0 = g1`` (the functions an event is looked for against).
``ME_OUTPUTS``
    the outputs into ``y`` and the reported values into ``r`` (as :func:`clutchlab.numerics.session.call`).

``out[0]`` is set to the model's next break time (``next_break``: an input's corner, a controller sample;
the FMU's next time event).  The session's arguments are ``(p, x, m, u, sf, si, opt, log, dx, g0, g1, out,
y, report, r)``, packed in a table as a co-simulation session's are (:data:`FIELDS`); the time is
``sf[SF_T]``.
"""

from __future__ import annotations

from numba.extending import register_jitable

from . import dispatch as model
from .borrow import borrow, byref
from .core import SF_T, _apply_updates
from .session import _args, fill_report

__all__ = ["call", "FIELDS", "ME_DERIVATIVES", "ME_ACCEPT", "ME_EVENT", "ME_RESTART", "ME_STORE", "ME_OUTPUTS"]

ME_DERIVATIVES = 1
ME_ACCEPT = 2
ME_EVENT = 4
ME_RESTART = 8
ME_STORE = 16
ME_OUTPUTS = 32

#: members of a model-exchange session's packed arguments (a tuple, in this order)
FIELDS = ("p", "x", "m", "u", "sf", "si", "opt", "log", "dx", "g0", "g1", "out", "y", "report", "r")


@register_jitable
def call(s, what):
    """One model-exchange operation (module docstring) on the session ``s``; returns 0, the flag of
    ``accept``/``update`` (> 0), or a model error (< 0).  Compiled as each model's ``model_exchange`` entry."""
    p0, x, m, u, sf, si, opt, log, dx, g0, g1, out, y, report, r = _args(s)
    p = byref(borrow(p0))
    t = sf[SF_T]
    code = 0
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
