"""Compile-time dispatch from the integrator core to a model's compiled functions.

numba cannot cache a kernel that receives a jitted function as an argument
(numba issue 6251): the dispatcher type is new in every process, so the
kernel would silently recompile in each one.  The core therefore never takes
functions as arguments (and is compiled into per-model entry points, see
:mod:`clutchlab.numerics.entry`).  It calls the stubs below with the model's parameter
structure ``p``; each model packs its parameters in its own ``NamedTuple``
class and registers its compiled functions for that class once
(:func:`register`).  At compile time the ``@overload`` of each stub looks at
the type of ``p`` and returns the model's own function (``py_func``), so
numba compiles the model into the core's specialisation for that parameter
type as if it were written there: no indirect call, and the specialisation
is cached across processes like any other.

Measured on the toy models of ``shared/notes/one-core-numba.md``: returning
the model's ``py_func`` costs nothing against a copied loop; a wrapper
``def impl(...): model(...)`` cost up to 46 %.

The model hooks (all compiled, all take the state ``x`` [float64 array],
the held inputs ``u`` [float64 array], the mode vector ``m`` [int64 array]
and the parameters ``p``):

``rhs(t, x, u, m, p, dx, g)``
    Right-hand side into ``dx`` and the switching functions into ``g``.
``outputs(t, x, u, m, p, y)``
    Output vector into ``y``.
``update(t, x, u, m, p, k, log)``
    Discrete update when switching function ``k`` crossed zero at ``t``:
    may change ``m`` and ``x`` and record named events with
    :func:`clutchlab.numerics.core.record`; returns 0 to continue, 1 to stop
    the run (terminal event) or a negative model error code.
``restart(t, x, u, m, p, log)``
    Makes the modes consistent with the forces at a (re)start: at t0, on
    every resumed ``advance`` (inputs may have jumped) and at every break
    time; returns True if it changed anything.
``accept(t, x, u, m, p)``
    Called after each accepted step (commit hysteresis memories, project
    stuck velocities); returns 0 or a negative model error code.
``next_break(t, m, p)``
    Next time > t at which a step must end and ``restart`` be called
    (input table corners, controller samples); ``inf`` if none.
``jacobian(t, x, u, m, p, J)``
    Fills ``J = df/dx`` and returns True where the model has an analytic
    Jacobian; returns False to let the core difference ``rhs``.
"""

from __future__ import annotations

import inspect

from numba.core import types
from numba.extending import overload

from .borrow import ByRef

__all__ = ["register", "registered", "hook_sources", "rhs", "outputs", "update", "restart", "accept", "next_break", "jacobian"]

HOOKS = ("rhs", "outputs", "update", "restart", "accept", "next_break", "jacobian")

# parameter NamedTuple class -> {hook name: compiled function}
_MODELS: dict = {}
_SOURCES: dict = {}


def register(params_cls, **functions) -> None:
    """Register a model's compiled hooks for its parameter ``NamedTuple`` class.

    Every hook of :data:`HOOKS` must be given, as a ``numba.njit`` function.
    Registering the same class again replaces the hooks (a reloaded module).
    """
    missing = [h for h in HOOKS if h not in functions]
    extra = [h for h in functions if h not in HOOKS]
    if missing or extra:
        raise TypeError(f"register({params_cls.__name__}): missing hooks {missing}, unknown hooks {extra}")
    _MODELS[params_cls] = dict(functions)
    files = set()
    for fn in functions.values():
        try:
            files.add(inspect.getsourcefile(getattr(fn, "py_func", fn)))
        except TypeError:
            pass
    _SOURCES[params_cls] = sorted(f for f in files if f)


def hook_sources(params_cls) -> list:
    """Source files of a model's registered hooks (part of the name of its compiled entry points)."""
    return list(_SOURCES.get(params_cls, ()))


def registered(params_cls) -> bool:
    """True if a model has registered hooks for ``params_cls``."""
    return params_cls in _MODELS


def _hook(p, name):
    if isinstance(p, ByRef):
        p = p.pointee
    if isinstance(p, types.BaseNamedTuple) and p.instance_class in _MODELS:
        return _MODELS[p.instance_class][name].py_func
    return None


# ---- stubs: the core calls these; numba resolves them per parameter type at compile time
def rhs(t, x, u, m, p, dx, g):  # pragma: no cover - replaced by the overload
    raise NotImplementedError


def outputs(t, x, u, m, p, y):  # pragma: no cover
    raise NotImplementedError


def update(t, x, u, m, p, k, log):  # pragma: no cover
    raise NotImplementedError


def restart(t, x, u, m, p, log):  # pragma: no cover
    raise NotImplementedError


def accept(t, x, u, m, p):  # pragma: no cover
    raise NotImplementedError


def next_break(t, m, p):  # pragma: no cover
    raise NotImplementedError


def jacobian(t, x, u, m, p, J):  # pragma: no cover
    raise NotImplementedError


@overload(rhs, jit_options={"cache": True})
def _ov_rhs(t, x, u, m, p, dx, g):
    return _hook(p, "rhs")


@overload(outputs, jit_options={"cache": True})
def _ov_outputs(t, x, u, m, p, y):
    return _hook(p, "outputs")


@overload(update, jit_options={"cache": True})
def _ov_update(t, x, u, m, p, k, log):
    return _hook(p, "update")


@overload(restart, jit_options={"cache": True})
def _ov_restart(t, x, u, m, p, log):
    return _hook(p, "restart")


@overload(accept, jit_options={"cache": True})
def _ov_accept(t, x, u, m, p):
    return _hook(p, "accept")


@overload(next_break, jit_options={"cache": True})
def _ov_next_break(t, m, p):
    return _hook(p, "next_break")


@overload(jacobian, jit_options={"cache": True})
def _ov_jacobian(t, x, u, m, p, J):
    return _hook(p, "jacobian")
