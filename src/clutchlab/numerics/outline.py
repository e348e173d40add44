"""Rare, large compiled functions called through an address, so that their callers do not link them.

numba links the code of every compiled callee into its caller, then optimises and emits machine code for
the whole once more; a function's compile time is that of everything below it, and a large callee below a
hook is compiled again in every function of the integrator core that calls the hook (docs/architecture.md).
The driveline's stuck-set repair and its event iteration are large, rare and below every hook: linked, they
doubled the driveline's first compilation (issue #30).

:func:`outlined` makes, for a compiled function and the one signature it is called with, a caller stub (a
numba intrinsic) that calls it through its address instead.  The function is compiled once, on its own (or
loaded from numba's cache), the first time a caller needs it in a process; callers link a few instructions.

How the address is found: each caller's code keeps it in a private global, NULL at first.  On the first
call, it asks :func:`_resolve` -- a C callback registered with LLVM under one fixed symbol when this module
is imported (no compilation at import) -- for the function whose key (a hash of its qualified name and
signature, the same in every process) it was compiled for.  The callback compiles or loads that overload
and returns its native address, the one numba itself calls (:func:`prepare` does so ahead, on the calling
thread: ``clutchlab warmup`` and every driveline's ``system()``).  A key it does not know (a cached caller older than the function) or a compilation that
fails make the call raise :class:`~clutchlab.errors.SimulationError` (a ``RuntimeError``) in the caller, never a
call through a bad address.

The call is the one numba would make (its calling convention: status, exception and return value), so an
exception raised in the function reaches the caller's caller as usual.  The cost per call is a load, a
test and an indirect call, and the function is never inlined into its caller: worth it for functions called
at events, or large beside their call (the driveline's stuck-set solve, called at each evaluation of a
network with a stuck set: its run time did not move beyond the noise, docs/architecture.md).
"""

from __future__ import annotations

import ctypes
import hashlib

import llvmlite.binding as ll
from llvmlite import ir
from numba import typeof as _typeof
from numba.core import cgutils, types
from numba.extending import intrinsic

from ..errors import SimulationError
from .core import new_log
from .session import native_address

__all__ = ["outlined", "prepare", "hook_args", "log_type", "RESOLVE_SYMBOL"]

#: the resolving callback's symbol (a new version of this protocol takes a new name)
RESOLVE_SYMBOL = "clutchlab_outline_resolve_v1"

#: key -> the text of the last failure to resolve it (for a debugger; the caller raises SimulationError)
_ERRORS: dict = {}


class _Entry:
    __slots__ = ("dispatcher", "signature", "returns", "label", "lazy", "group", "_sig", "ready")

    def __init__(self, dispatcher, signature, returns, label, lazy=False, group=None):
        self.dispatcher = dispatcher
        self.signature = signature
        self.returns = returns
        self.label = label
        self.lazy = lazy
        self.group = group
        self._sig = None
        self.ready = False   # compiled or loaded in this process (:func:`prepare`)

    def sig(self) -> tuple:
        if self._sig is None:
            self._sig = tuple(self.signature())
        return self._sig


_ENTRIES: list = []


def _key(label: str, sig) -> int:
    """A 63-bit key of a function and its argument types, the same in every process."""
    text = label + "(" + ", ".join(str(t) for t in sig) + ")"
    return int.from_bytes(hashlib.sha1(text.encode()).digest()[:8], "little") & 0x7FFF_FFFF_FFFF_FFFF


def _entry_of(key: int):
    for e in _ENTRIES:
        if _key(e.label, e.sig()) == key:
            return e
    return None


def _resolve(key: int) -> int:
    # a ctypes callback: it must not raise (ctypes would print and return NULL anyway)
    try:
        e = _entry_of(key)
        if e is None:
            _ERRORS[key] = "no outlined function has this key (a compiled caller older than clutchlab's code)"
            return 0
        address = native_address(e.dispatcher, e.sig(), e.returns)
        if not address:
            _ERRORS[key] = f"{e.label}{e.sig()} does not return {e.returns}"
        return address
    except BaseException as exc:  # noqa: BLE001 -- reported by the caller as SimulationError
        _ERRORS[key] = f"{type(exc).__name__}: {exc}"
        return 0


_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_int64)(_resolve)
ll.add_symbol(RESOLVE_SYMBOL, ctypes.cast(_CALLBACK, ctypes.c_void_p).value)


def prepare(lazy: bool = False, groups=(), ungrouped: bool = True) -> None:
    """Compile (or load from numba's cache) every outlined function now, on the calling thread (``clutchlab
    warmup``; a driveline's :meth:`~clutchlab.driveline.Driveline.system`).  Cheap once done in a process.

    ``lazy``: the functions outlined with ``lazy=True`` too (a debug option's, such as the driveline's invariant
    check: compiled only where a run asks for it, not on every first use).  ``groups``: the functions outlined
    with one of these ``group`` names too (a kind of model the caller runs: ``"coupled"``, the hooks of a network
    with model components, which a plain network never calls; ``"emtc"``, the EMTC's hooks); ``None`` for every
    group (``clutchlab warmup``).  ``ungrouped``: the functions of no group too (``False``: a model that prepares
    only its own group, such as the EMTC bench, leaves the driveline's alone)."""
    for e in _ENTRIES:
        if e.lazy and not lazy:
            continue
        if e.ready or (e.group is None and not ungrouped):
            continue
        if e.group is not None and groups is not None and e.group not in groups:
            continue
        if not native_address(e.dispatcher, e.sig(), e.returns):
            raise TypeError(f"{e.label}{e.sig()} does not return {e.returns}")
        e.ready = True


def _codegen_call(context, builder, key, label, returns, argtys, args):
    mod = builder.module
    i8p = ir.IntType(8).as_pointer()
    name = f"clutchlab_outlined_{key:016x}"
    cell = mod.globals.get(name)
    if cell is None:
        cell = ir.GlobalVariable(mod, i8p, name)
        cell.linkage = "internal"
        cell.initializer = ir.Constant(i8p, None)
    address = cgutils.alloca_once_value(builder, builder.load(cell))
    with builder.if_then(cgutils.is_null(builder, builder.load(address)), likely=False):
        resolve = cgutils.get_or_insert_function(mod, ir.FunctionType(i8p, [ir.IntType(64)]), RESOLVE_SYMBOL)
        found = builder.call(resolve, [ir.Constant(ir.IntType(64), key)])
        builder.store(found, address)
        builder.store(found, cell)
        with builder.if_then(cgutils.is_null(builder, found), likely=False):
            context.call_conv.return_user_exc(
                builder, SimulationError,
                (f"clutchlab: the compiled function {label} is not available in this process "
                 "(clutchlab.numerics.outline; clear numba's cache if clutchlab was updated)",))
    fnty = context.call_conv.get_function_type(returns, argtys)
    fn = builder.bitcast(builder.load(address), fnty.as_pointer())
    status, res = context.call_conv.call_function(builder, fn, returns, argtys, args)
    with cgutils.if_unlikely(builder, status.is_error):
        context.call_conv.return_status_propagate(builder, status)
    return res


def outlined(dispatcher, signature, returns, lazy=False, group=None):
    """A compiled stub that calls ``dispatcher`` through its address.

    Parameters
    ----------
    dispatcher : numba dispatcher
        The function (``@numba.njit(cache=True)``).
    signature : callable
        Returns the numba types of its arguments (the signature called through the address; called lazily,
        once).  A call with other types compiles as an ordinary call, linked into its caller.
    returns : numba type
        Its return type (``types.none`` for none).
    lazy : bool
        Left out of :func:`prepare` unless asked for (``prepare(lazy=True)``): compiled on its first call, or by
        the caller that enables it (a debug option).
    group : str, optional
        Left out of :func:`prepare` unless its caller names the group (``prepare(groups=("coupled",))``): the
        functions of one kind of model, prepared by the caller that runs one.
    """
    label = f"{dispatcher.py_func.__module__}.{dispatcher.py_func.__qualname__}"
    entry = _Entry(dispatcher, signature, returns, label, lazy, group)
    _ENTRIES.append(entry)
    nargs = dispatcher.py_func.__code__.co_argcount
    names = ", ".join(f"a{i}" for i in range(nargs))

    def typer(typingctx, *argtys):
        expected = entry.sig()
        if tuple(argtys) != expected:   # another signature (a test's direct call): an ordinary, linked call
            fnty = types.Dispatcher(dispatcher)
            sig = fnty.get_call_type(typingctx, argtys, {})

            def linked(context, builder, sig, args):
                return context.get_function(fnty, sig)(builder, args)

            return sig, linked
        key = _key(label, expected)

        def codegen(context, builder, sig, args):
            return _codegen_call(context, builder, key, label, returns, expected, args)

        return returns(*expected), codegen

    # an intrinsic with the function's own arity (numba's intrinsics take no *args)
    scope = {"typer": typer}
    exec(f"def call(typingctx, {names}):\n    return typer(typingctx, {names})\n", scope)  # noqa: S102
    call = scope["call"]
    call.__name__ = call.__qualname__ = f"outlined_{dispatcher.py_func.__name__}"
    call.__doc__ = f"``{label}`` called through its address (:mod:`clutchlab.numerics.outline`)."
    return intrinsic(call)


_F1, _I1 = types.float64[::1], types.int64[::1]


def hook_args(params, *rest) -> tuple:
    """The numba types of a model hook's arguments, ``(t, x, u, m, p, *rest)``, for the type ``params`` of its
    parameter reference: the signature of a hook called through its address."""
    return (types.float64, _F1, _F1, _I1, params, *rest)


def log_type():
    """numba type of the core's event log (the ``log`` argument of the ``update`` and ``restart`` hooks)."""
    return _typeof(new_log(1))
