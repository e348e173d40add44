"""A sampled controller in the compiled loop: measurement, controller update and zero-order hold.

Each model's entry module (:mod:`clutchlab.numerics.entry`) has a cached ``closed_loop`` function that
runs the model with a discrete controller from sample to sample without returning to Python: at every
sample instant ``t_k`` it reads the measured states or outputs (:func:`measure`), computes the
controller's output (:func:`lti_update`, :func:`scheduled_pi_update` or a compiled function), limits
it, holds it and advances the model to ``t_{k+1}`` with the core's loop (its step size, modes and
memories carry over, as in :class:`clutchlab.system.Simulation`).
:func:`clutchlab.control.loop.closed_loop` chooses this path for a python-control discrete LTI system, a
:class:`clutchlab.control.design.ScheduledPI` and a numba-compiled function; its Python loop, for any
other function, does the same arithmetic in the same order, so both give the same run (tests compare
them).

Controller kinds (``kind``):

* ``LTI`` -- ``u_k = u_op + C x_k + D e_k``, ``x_{k+1} = A x_k + B e_k`` with ``e_k = r_k - y_k``;
* ``FUNCTION`` -- a numba-compiled function ``u = f(t, y, memory)`` called through its C entry
  (:func:`function_pointer`): a typed function pointer, so the cached loop needs no recompilation for
  another controller;
* ``SCHEDULED_PI`` -- the gain-scheduled PI with feedforward, anti-windup and conditional integration of
  :class:`~clutchlab.control.design.ScheduledPI` (one measured signal, one actuated input):
  ``sched`` rows are the scheduling points, ``kp``, ``ti`` and the feedforward; ``par`` is
  ``(sample_time, has_feedforward, integrate_band, low limit, high limit)``; ``memory[0]`` the integral.
"""

from __future__ import annotations

import weakref

import numpy as np
from numba import types
from numba.extending import intrinsic, register_jitable

from . import core as _core
from .layout import indices

__all__ = ["LTI", "SCHEDULED_PI", "FUNCTION", "SIGNATURE", "measure", "lti_update", "scheduled_pi_update", "hold",
           "function_pointer", "placeholder"]

#: kinds of sampled controller
CONTROLLER_KINDS = ("lti", "scheduled_pi", "function")
LTI, SCHEDULED_PI, FUNCTION = indices(CONTROLLER_KINDS, "lti", "scheduled_pi", "function")

#: C signature of a function controller's entry: ``status = f(t, y address, len(y), memory address,
#: len(memory), u address, len(u))``; status 0, or 1 if the function returned another number of values.
SIGNATURE = types.int64(types.float64, types.uintp, types.int64, types.uintp, types.int64, types.uintp, types.int64)

_POINTERS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
_PLACEHOLDER: list = []


@intrinsic
def _as_pointer(typingctx, address):
    """The address (an integer) as a ``float64*`` (for ``numba.carray``)."""
    sig = types.CPointer(types.float64)(address)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], context.get_value_type(signature.return_type))

    return sig, codegen


def function_pointer(fn):
    """The C entry (a numba ``cfunc`` of :data:`SIGNATURE`) of a compiled controller ``u = fn(t, y, memory)``.

    ``fn`` is a numba-compiled function (``@numba.njit``) of the time [s], the measured vector and the
    memory array (changed in place), returning the actuated inputs as an array.  The entry views the
    loop's arrays (``numba.carray``) and copies the returned values.  The compiled closed loop of every
    model takes this one signature, so its cached code serves every such controller; the entry itself is
    compiled once per controller and process (a fraction of a second) and kept while ``fn`` lives.
    An exception raised inside ``fn`` cannot cross the C entry: a compiled controller must not raise.
    """
    entry = _POINTERS.get(fn)
    if entry is None:
        import numba

        @numba.cfunc(SIGNATURE)
        def entry(t, y_at, ny, memory_at, nm, u_at, nu):  # pragma: no cover (compiled)
            out = fn(t, numba.carray(_as_pointer(y_at), (ny,)), numba.carray(_as_pointer(memory_at), (nm,)))
            if out.shape[0] != nu:
                return 1
            u = numba.carray(_as_pointer(u_at), (nu,))
            for i in range(nu):
                u[i] = out[i]
            return 0

        _POINTERS[fn] = entry
    return entry


def placeholder():
    """The C entry passed for the LTI and scheduled-PI controllers (never called)."""
    if not _PLACEHOLDER:
        import numba

        @numba.cfunc(SIGNATURE, cache=True)
        def nothing(t, y_at, ny, memory_at, nm, u_at, nu):  # pragma: no cover (compiled)
            return 0

        _PLACEHOLDER.append(nothing)
    return _PLACEHOLDER[0]


@register_jitable
def measure(p, t, x, u, m, kind, idx, ybuf, y):
    """The measured vector ``y`` at ``(t, x, u, m)``: ``y[q] = x[idx[q]]`` (``kind[q] == 0``) or output ``idx[q]``."""
    need = False
    for q in range(kind.shape[0]):
        if kind[q] != 0:
            need = True
    if need:
        _core._evaluate_outputs(p, t, x, u, m, ybuf)
    for q in range(kind.shape[0]):
        y[q] = x[idx[q]] if kind[q] == 0 else ybuf[idx[q]]


@register_jitable
def _row_products(M, v, N, w, i):
    """``(M[i] . v, N[i] . w)``, each summed in index order (as numpy's matrix-vector product of these sizes)."""
    s = 0.0
    for j in range(v.shape[0]):
        s += M[i, j] * v[j]
    s2 = 0.0
    for j in range(w.shape[0]):
        s2 += N[i, j] * w[j]
    return s, s2


@register_jitable
def lti_update(A, B, C, D, xc, r, y, u_op, out, e, xn):
    """One sample of a discrete LTI controller on ``e = r - y``: ``out = u_op + C xc + D e``; ``xc`` advanced."""
    for q in range(y.shape[0]):
        e[q] = r[q] - y[q]
    for i in range(out.shape[0]):
        s, s2 = _row_products(C, xc, D, e, i)
        out[i] = (u_op[i] + s) + s2
    for i in range(xc.shape[0]):
        s, s2 = _row_products(A, xc, B, e, i)
        xn[i] = s + s2
    for i in range(xc.shape[0]):
        xc[i] = xn[i]


@register_jitable
def scheduled_pi_update(sched, par, r, y, memory):
    """One sample of the scheduled PI (:class:`clutchlab.control.design.ScheduledPI`); returns its output."""
    x = y
    kp = np.interp(x, sched[0], sched[1])
    ti = np.interp(x, sched[0], sched[2])
    e = r - x
    u_ff = np.interp(r, sched[0], sched[3]) if par[1] != 0.0 else 0.0
    integral = memory[0] + kp * par[0] / ti * e
    u = u_ff + kp * e + integral
    lo = par[3]
    hi = par[4]
    band = par[2]
    if lo <= u <= hi and (band == np.inf or abs(e) <= band * abs(r)):
        memory[0] = integral
    return min(max(u, lo), hi)


@register_jitable
def hold(out, lo, hi, clipped):
    """``clipped = min(max(out, lo), hi)``; returns 1.0 if any value was limited."""
    sat = 0.0
    for i in range(out.shape[0]):
        c = min(max(out[i], lo[i]), hi[i])
        if c != out[i]:
            sat = 1.0
        clipped[i] = c
    return sat
