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
    Right-hand side into ``dx`` and the switching functions into ``g``, at the stages of a step and
    in its Jacobian.  (The core calls it as ``rhs_stage`` at the stages of a Dormand-Prince step: the
    same hook, inlined there for a model registered with ``inline_stages=True``.)  The switching
    functions read there serve only the stages' look for a sign change within the step: a function
    that needs more than one evaluation may be left at 0.0 (never a sign change) and completed in
    ``watch``.
``rhs_event(t, x, u, m, p, dx, g)`` (optional)
    The same right-hand side where the core evaluates it at events (locating a root, the step to it,
    a break); ``rhs`` itself if not given.  A model whose right-hand side is large gives it called
    through its address (:mod:`clutchlab.numerics.outline`), so that the core's event-time functions
    do not each link and optimise it again (the driveline: docs/architecture.md).
``watch(t, x, u, m, p, dx, g, k)`` (optional)
    Completes the switching functions ``g`` just evaluated with ``dx`` at ``(t, x)`` wherever the core
    compares them across a step: every step end, the start of a run, after an event or a break, each
    probe locating a root, and :func:`~clutchlab.numerics.core.evaluate`; never at a step's stages.
    ``k``: the one function the core reads there (a probe locating its root), -1 for all.  For
    functions that cost more than one evaluation (the driveline: the rates of its stuck elements'
    margins near their limits, one more evaluation of the network, docs/driveline.md "Events").
    Nothing for a model that does not give it (compiled out).
``outputs(t, x, u, m, p, y)``
    Output vector into ``y``.
``update(t, x, u, m, p, k, log)``
    Discrete update when switching function ``k`` crossed zero at ``t``:
    may change ``m`` and ``x`` and record named events with
    :func:`clutchlab.numerics.core.record`; returns 0 to continue, 1 to stop
    the run (terminal event), 2 to continue with the step size started afresh
    from a short step (the dynamics changed abruptly: a speed that jumps to a
    limit within microseconds; Dormand-Prince) or a negative model error code.
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
``prepare(p)`` (optional)
    Called once by every entry of the core that takes the parameters (a run's loop, each call of
    :func:`~clutchlab.numerics.core.evaluate` and its siblings, each model-exchange call), before any other
    hook, with the reference the hooks get: a model derives there what stays fixed for the call from
    structures that may have been copied or rewritten since the last one (the driveline's EMTC couplings
    build each coupling's parameter structure from its stacked rows once per call, not at every
    evaluation: :mod:`clutchlab.driveline.emtc`).  Nothing for a model that does not give it.
``start(t, x, u, m, p)`` (optional)
    Decides what a run derives from its initial state alone, once, before its first ``restart``: the modes
    it starts from and the quantities its outputs compare with the start (the driveline: each element's mode
    from the sign of its relative speed, and the stored energy its energy balance starts from).  The core
    calls it when a run has not started (:data:`~clutchlab.numerics.core.SI_STARTED`); a session and model
    exchange when asked (``START``, ``ME_START``: a native FMU at every call before its run, after a host may
    have set start values; a co-simulation's outputs before its first step).  Being
    compiled, it is also what the model's Python side calls for its initial modes, so the modes a run starts
    from are written once.  Returns 0, or a negative model error code where the initial state is one the model
    cannot start from (a one-way clutch turning backward): the run ends there with that error, as at a failed
    ``accept`` (a native FMU refuses the start values a host set, with the model's message).  0 for a model
    that does not give it.
``time_derivative(t, x, u, m, p, ft)`` (optional)
    Fills ``ft = df/dt`` at fixed state (inputs that vary within a step,
    for the Rosenbrock stages) and returns True; False (the default for a
    model that does not give it) lets the core difference ``rhs`` in time.
"""

from __future__ import annotations

import functools
import inspect

from numba.core import types
from numba.extending import overload

from .borrow import ByRef

__all__ = ["register", "registered", "inlines_stages", "hook_sources", "rhs", "rhs_stage", "rhs_event", "outputs", "update", "restart", "accept",
           "next_break", "jacobian", "time_derivative", "no_time_derivative", "watch", "no_watch", "start", "no_start"]

HOOKS = ("rhs", "outputs", "update", "restart", "accept", "next_break", "jacobian")
#: hooks a model may leave out (``time_derivative``: the core differences the right-hand side in time;
#: ``rhs_event``: the right-hand side where the core evaluates it at events, its ``rhs`` if not given;
#: ``watch``, ``prepare``, ``start``: nothing)
OPTIONAL_HOOKS = ("time_derivative", "rhs_event", "watch", "prepare", "start")


def no_time_derivative(t, x, u, m, p, ft):
    """What the ``time_derivative`` stub compiles to for a model without the hook: ``False`` (none analytic).

    Compiled into the caller, never cached on its own: a cached default would keep one index of every model
    that used it, and a process that cannot import one of them (a test's toy model) could not load it.
    """
    return False

# parameter NamedTuple class -> {hook name: compiled function}
_MODELS: dict = {}
# parameter classes whose right-hand side is inlined into the Dormand-Prince stages
_INLINE_STAGES: set = set()
_SOURCES: dict = {}


def register(params_cls, inline_stages: bool = False, **functions) -> None:
    """Register a model's compiled hooks for its parameter ``NamedTuple`` class.

    Every hook of :data:`HOOKS` must be given, as a ``numba.njit`` function; those of
    :data:`OPTIONAL_HOOKS` may be (without ``time_derivative`` the stub compiles to
    :func:`no_time_derivative`).
    Registering the same class again replaces the hooks (a reloaded module).
    Each hook is compiled into the core with its own ``error_model``,
    ``fastmath`` and ``_nrt`` options (:func:`_declare`): a hook declared with
    ``numba.njit(_nrt=False)`` is compiled without numba's reference counting
    (for hooks that allocate no array and keep none: the core lends them its
    arrays; the wet clutch's right-hand side made a dozen reference-count
    calls per evaluation, a quarter of its time).  ``inline_stages``: the
    right-hand side is inlined (LLVM ``alwaysinline``) into the six stage
    calls of a Dormand-Prince step: faster where the model's evaluation is
    cheap against a call (the EMTC bench: 10 %), at the price of compiling
    the right-hand side a second time (measured: several seconds for the
    EMTC bench), so off by default.
    """
    missing = [h for h in HOOKS if h not in functions]
    extra = [h for h in functions if h not in HOOKS + OPTIONAL_HOOKS]
    if missing or extra:
        raise TypeError(f"register({params_cls.__name__}): missing hooks {missing}, unknown hooks {extra}")
    functions = dict(functions)
    for fn in functions.values():
        _declare(_options_key(fn))
    _MODELS[params_cls] = dict(functions)
    if inline_stages:
        _INLINE_STAGES.add(params_cls)
    else:
        _INLINE_STAGES.discard(params_cls)
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


def inlines_stages(params_cls) -> bool:
    """True if a model was registered with ``inline_stages`` (its right-hand side inlined into the stages)."""
    return params_cls in _INLINE_STAGES


def registered(params_cls) -> bool:
    """True if a model has registered hooks for ``params_cls``."""
    return params_cls in _MODELS


def _options_key(fn) -> tuple:
    """``(error_model, fastmath, nrt)`` a hook was declared with (``njit`` options; defaults for a plain function)."""
    opts = getattr(fn, "targetoptions", {}) or {}
    fastmath = opts.get("fastmath", False)
    if isinstance(fastmath, (set, frozenset, list, tuple)):
        fastmath = frozenset(fastmath)
    elif isinstance(fastmath, dict):
        fastmath = frozenset(k for k, v in fastmath.items() if v)
    else:
        fastmath = bool(fastmath)
    return str(opts.get("error_model", "python")), fastmath, bool(opts.get("_nrt", True))


def _hook(p, name, key):
    if isinstance(p, ByRef):
        p = p.pointee
    if isinstance(p, types.BaseNamedTuple) and p.instance_class in _MODELS:
        hooks = _MODELS[p.instance_class]
        if name == "rhs_event" and name not in hooks:
            name = "rhs"
        fn = hooks.get(name)
        if fn is not None and _options_key(fn) == key:
            return fn.py_func
    return None


def _default_time_derivative(t, x, u, m, p, ft):
    """Typing of the ``time_derivative`` stub for a registered model that does not give the hook."""
    q = p.pointee if isinstance(p, ByRef) else p
    if isinstance(q, types.BaseNamedTuple) and q.instance_class in _MODELS \
            and "time_derivative" not in _MODELS[q.instance_class]:
        return no_time_derivative
    return None


# ---- stubs: the core calls these; numba resolves them per parameter type at compile time
def rhs(t, x, u, m, p, dx, g):  # pragma: no cover - replaced by the overload
    raise NotImplementedError


def rhs_stage(t, x, u, m, p, dx, g):  # pragma: no cover - replaced by the overload
    raise NotImplementedError


def rhs_event(t, x, u, m, p, dx, g):  # pragma: no cover - replaced by the overload
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


def time_derivative(t, x, u, m, p, ft):  # pragma: no cover
    raise NotImplementedError


# ---- the overloads: one set per option key, each returning only the hooks declared with its options
# (an overload compiles the function it returns with its own jit options, not with the options of the
# ``njit`` the hook was declared with; without this a hook's error_model and fastmath were silently dropped)
_DECLARED: set = set()


def _declare(key) -> None:
    """Declare the stubs' overloads for hooks with options ``key`` = ``(error_model, fastmath, nrt)`` (once)."""
    if key in _DECLARED:
        return
    _DECLARED.add(key)
    error_model, fastmath, nrt = key
    opts = {"cache": True, "error_model": error_model}
    if fastmath:
        opts["fastmath"] = set(fastmath) if isinstance(fastmath, frozenset) else True
    if not nrt:
        opts["_nrt"] = False
    for stub, hook in _STUBS:
        overload(stub, jit_options=opts)(_typing(stub, hook, key, inline=False if stub is rhs_stage else None))
    # the stage call of Dormand-Prince for the models registered with ``inline_stages``: the right-hand side
    # inlined by LLVM (docs/architecture.md).  Not cached on its own: numba's cache index keys a function by
    # its source and signature, not by its options, so it would load the plain ``rhs`` compiled from the same
    # source (or give it this one); the code is cached inside the entry points that inline it.
    overload(rhs_stage, jit_options=dict(opts, forceinline=True, cache=False))(
        _typing(rhs_stage, "rhs", key, inline=True))


def _typing(stub, hook, key, inline=None):
    """The overload's typing function for ``stub``: the hook ``hook`` of the model of ``p`` if declared with
    options ``key`` (and, for ``inline`` True/False, if the model is/is not registered with
    ``inline_stages``); it carries the stub's signature, which numba compares with the hook's."""
    i_p = list(inspect.signature(stub).parameters).index("p")

    @functools.wraps(stub)
    def typing(*args):
        if inline is not None:
            p = args[i_p].pointee if isinstance(args[i_p], ByRef) else args[i_p]
            if (getattr(p, "instance_class", None) in _INLINE_STAGES) != inline:
                return None
        return _hook(args[i_p], hook, key)

    return typing


def no_watch(t, x, u, m, p, dx, g, k):
    """What the ``watch`` stub compiles to for a model without the hook: nothing (compiled into the caller, as
    :func:`no_time_derivative`)."""
    return None


def _default_watch(t, x, u, m, p, dx, g, k):
    """Typing of the ``watch`` stub for a registered model that does not give the hook."""
    q = p.pointee if isinstance(p, ByRef) else p
    if isinstance(q, types.BaseNamedTuple) and q.instance_class in _MODELS and "watch" not in _MODELS[q.instance_class]:
        return no_watch
    return None


def watch(t, x, u, m, p, dx, g, k):  # pragma: no cover
    raise NotImplementedError


def no_prepare(p):
    """What the ``prepare`` stub compiles to for a model without the hook: nothing (compiled into the caller)."""
    return None


def _default_prepare(p):
    """Typing of the ``prepare`` stub for a registered model that does not give the hook."""
    q = p.pointee if isinstance(p, ByRef) else p
    if isinstance(q, types.BaseNamedTuple) and q.instance_class in _MODELS and "prepare" not in _MODELS[q.instance_class]:
        return no_prepare
    return None


def prepare(p):  # pragma: no cover
    raise NotImplementedError


def no_start(t, x, u, m, p):
    """What the ``start`` stub compiles to for a model without the hook: 0 (compiled into the caller)."""
    return 0


def _default_start(t, x, u, m, p):
    """Typing of the ``start`` stub for a registered model that does not give the hook."""
    q = p.pointee if isinstance(p, ByRef) else p
    if isinstance(q, types.BaseNamedTuple) and q.instance_class in _MODELS and "start" not in _MODELS[q.instance_class]:
        return no_start
    return None


def start(t, x, u, m, p):  # pragma: no cover
    raise NotImplementedError


# models without a ``watch`` hook: the stub compiles to nothing inside the caller
overload(watch, jit_options={"cache": False})(functools.wraps(watch)(_default_watch))
# models without a ``prepare`` hook: the same
overload(prepare, jit_options={"cache": False})(functools.wraps(prepare)(_default_prepare))
# models without a ``start`` hook: the same
overload(start, jit_options={"cache": False})(functools.wraps(start)(_default_start))

# models without a ``time_derivative`` hook: the stub compiles to ``return False`` inside the caller
overload(time_derivative, jit_options={"cache": False})(
    functools.wraps(time_derivative)(_default_time_derivative))

#: (stub, hook it resolves to)
_STUBS = ((rhs, "rhs"), (rhs_stage, "rhs"), (rhs_event, "rhs_event"), (outputs, "outputs"), (update, "update"), (restart, "restart"),
          (accept, "accept"), (next_break, "next_break"), (jacobian, "jacobian"),
          (time_derivative, "time_derivative"), (watch, "watch"), (prepare, "prepare"), (start, "start"))
