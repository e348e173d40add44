"""A running session's arguments packed once: one pointer per call into the compiled core.

A :class:`clutchlab.system.Simulation` calls the same compiled entries (the model's ``advance`` and
``evaluate_outputs``) with the same objects at every step -- the parameter structure, the state,
modes, inputs, solver state, options, event log and buffers -- and only the end time changes.  Passed
from Python, every array among them is unboxed at every call (a reference to the Python object, an
owner record allocated and freed, the shape and strides read): about thirty arrays, 5 us per call.

Here they are unboxed once per session.  :func:`open_session` writes them, borrowed (the owners set to
NULL as :func:`~clutchlab.numerics.borrow.borrow` does; the session keeps the originals alive), into one
table together with the addresses of the two compiled functions -- from Python, in the layout of numba's
data model, or for a type that this does not know with the compiled :func:`pack`; :class:`Handle` is the
Python object that carries the table's address, and numba unboxes it as one pointer
(:class:`SessionType`, which also carries the arguments' types).  :func:`call` (compiled into each
model's entry module as ``session``) loads the arguments from the table and calls the model's
``advance`` and ``evaluate_outputs`` through their addresses, then copies the values the session reports
(outputs, states, modes) into its report array.

Why addresses, not calls: a compiled function that calls ``advance`` links the whole loop into itself
and numba optimises and emits it once more (2-3.5 s per model, docs/architecture.md); called through
its address, the loop is compiled once, and the session entry compiles in a fraction of a second.  The
address is that of the native function of the very overload found for the session's argument types (in
this process: numba loads it from its cache or compiles it), so the call is the one numba would make.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import NativeValue, intrinsic, models, register_jitable, register_model, typeof_impl, unbox

from . import dispatch as model
from .borrow import _strip, byref
from .calls import ADVANCE, OUTPUTS, START, REPORT_KINDS, REPORT_MODE, REPORT_MODE_IS, REPORT_OUTPUT, REPORT_STATE  # noqa: F401
from .core import SI_MODEL_CODE, SI_STATUS
from .status import MODEL_ERROR, SUCCESS, TERMINATED

__all__ = ["SessionType", "Handle", "open_session", "native_address", "pack", "call", "table_bytes", "table_layout",
           "FIELDS",
           "ADVANCE", "OUTPUTS", "START", "REPORT_OUTPUT", "REPORT_STATE", "REPORT_MODE", "REPORT_MODE_IS"]

# the bits of ``what`` in :func:`call` (ADVANCE, OUTPUTS, START) and the kinds of reported values (REPORT_*):
# clutchlab.numerics.calls, declared there once

#: members of the packed arguments (a tuple, in this order)
FIELDS = ("p", "x", "m", "u", "sf", "si", "opt", "log", "ts", "rt", "rx", "rm", "ry", "want_y", "y", "report", "r")


class SessionType(types.Type):
    """A pointer to a session's table: the addresses of ``advance`` and ``evaluate_outputs``, then the
    packed arguments, of the tuple type ``args``."""

    def __init__(self, args):
        self.args = args
        super().__init__(name=f"Session({args})")

    @property
    def key(self):
        return self.args


@register_model(SessionType)
class _SessionModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, ir.IntType(8).as_pointer())


class Handle:
    """The Python side of a session's table: its address (``address``), the buffer that holds it and the
    objects its borrowed arrays belong to (kept alive with it)."""

    __slots__ = ("address", "numba_type", "buffer", "owners")

    def __init__(self, buffer, numba_type, owners):
        self.buffer = buffer
        self.address = int(buffer.ctypes.data)
        self.numba_type = numba_type
        self.owners = owners


@typeof_impl.register(Handle)
def _typeof_handle(val, c):
    return val.numba_type


@unbox(SessionType)
def _unbox_handle(typ, obj, c):
    builder = c.builder
    slot = cgutils.alloca_once_value(builder, cgutils.voidptr_t(None))
    address = c.pyapi.object_getattr_string(obj, "address")
    with builder.if_then(cgutils.is_not_null(builder, address), likely=True):
        builder.store(c.pyapi.long_as_voidptr(address), slot)
        c.pyapi.decref(address)
    return NativeValue(builder.load(slot), is_error=cgutils.is_not_null(builder, c.pyapi.err_occurred()))


def _table_type(context, args_ty):
    i8p = ir.IntType(8).as_pointer()
    return ir.LiteralStructType([i8p, i8p, context.get_value_type(args_ty)])


def table_bytes(args_ty) -> int:
    """Bytes of the table of a session whose packed arguments have the numba type ``args_ty``."""
    from numba.core.registry import cpu_target

    context = cpu_target.target_context
    return context.get_abi_sizeof(_table_type(context, args_ty))


@intrinsic
def _store(typingctx, address, args, advance_at, outputs_at):
    if not isinstance(args, types.BaseTuple):
        return None
    sig = types.none(address, args, advance_at, outputs_at)

    def codegen(context, builder, signature, llargs):
        addr, value, fa, fo = llargs
        tab_ty = _table_type(context, args)
        table = builder.inttoptr(addr, tab_ty.as_pointer())
        i8p = ir.IntType(8).as_pointer()
        builder.store(builder.inttoptr(fa, i8p), cgutils.gep_inbounds(builder, table, 0, 0))
        builder.store(builder.inttoptr(fo, i8p), cgutils.gep_inbounds(builder, table, 0, 1))
        builder.store(_strip(context, builder, args, value), cgutils.gep_inbounds(builder, table, 0, 2))
        return context.get_dummy_value()

    return sig, codegen


@register_jitable
def pack(address, args, advance_at, outputs_at):
    """Write the table of a session at ``address`` (:func:`table_bytes` long): the addresses of ``advance`` and
    ``evaluate_outputs``, then ``args`` with their arrays borrowed."""
    _store(address, args, advance_at, outputs_at)


@intrinsic
def _args(typingctx, s):
    """The packed arguments of the session ``s`` (their arrays borrowed)."""
    if not isinstance(s, SessionType):
        return None
    sig = s.args(s)

    def codegen(context, builder, signature, llargs):
        table = builder.bitcast(llargs[0], _table_type(context, s.args).as_pointer())
        return builder.load(cgutils.gep_inbounds(builder, table, 0, 2))

    return sig, codegen


def _native_call(context, builder, s, slot, restype, argtys, args):
    table = builder.bitcast(args[0], _table_type(context, s.args).as_pointer())
    fnty = context.call_conv.get_function_type(restype, argtys)
    fn = builder.bitcast(builder.load(cgutils.gep_inbounds(builder, table, 0, slot)), fnty.as_pointer())
    status, res = context.call_conv.call_function(builder, fn, restype, argtys, args[1:])
    with cgutils.if_unlikely(builder, status.is_error):
        context.call_conv.return_status_propagate(builder, status)
    return res


@intrinsic
def _advance(typingctx, s, p, x, m, u, t_end, sf, si, opt, log, ts, rt, rx, rm, ry, want_y):
    """``advance(p, x, m, u, t_end, ...)`` of the session ``s``, called through its address."""
    if not isinstance(s, SessionType):
        return None
    argtys = (p, x, m, u, t_end, sf, si, opt, log, ts, rt, rx, rm, ry, want_y)
    sig = types.int64(s, *argtys)

    def codegen(context, builder, signature, llargs):
        return _native_call(context, builder, s, 0, types.int64, argtys, llargs)

    return sig, codegen


@intrinsic
def _outputs(typingctx, s, p, t, x, u, m, y):
    """``evaluate_outputs(p, t, x, u, m, y)`` of the session ``s``, called through its address."""
    if not isinstance(s, SessionType):
        return None
    argtys = (p, t, x, u, m, y)
    sig = types.none(s, *argtys)

    def codegen(context, builder, signature, llargs):
        _native_call(context, builder, s, 1, types.none, argtys, llargs)
        return context.get_dummy_value()

    return sig, codegen


def call(s, t_end, what):
    """One call of a session: the model's ``start`` at the present time and state (``what & START``), then
    advance to ``t_end`` (``what & ADVANCE``), then, if the advance succeeded (or ended at a terminal event), the
    outputs at the time reached and the report (``what & OUTPUTS``).

    Returns the advance's status (``SUCCESS`` without an advance; ``MODEL_ERROR`` where ``start`` refused the
    initial state, its code in the solver state's ``model_code``).  Compiled as each model's ``session``
    entry (:mod:`clutchlab.numerics.entry`, the function itself rehomed into the generated module).
    """
    p, x, m, u, sf, si, opt, log, ts, rt, rx, rm, ry, want_y, y, report, r = _args(s)
    code = SUCCESS
    if what & START:
        pr = byref(p)
        model.prepare(pr)
        started = model.start(sf[0], x, u, m, pr)
        if started < 0:   # (an initial state the model cannot start from: its error, as a run's)
            si[SI_MODEL_CODE] = started
            si[SI_STATUS] = MODEL_ERROR
            return MODEL_ERROR
    if what & ADVANCE:
        code = _advance(s, p, x, m, u, t_end, sf, si, opt, log, ts, rt, rx, rm, ry, want_y)
        if code != SUCCESS and code != TERMINATED:
            return code
    if what & OUTPUTS:
        _outputs(s, p, sf[0], x, u, m, y)
        fill_report(report, y, x, m, r)
    return code


@register_jitable
def fill_report(report, y, x, m, r):
    """The reported values ``r`` from the outputs ``y``, state ``x`` and modes ``m`` as ``report`` chooses them
    (``report[k] = (kind, index, value)``, :data:`REPORT_OUTPUT` ...)."""
    for k in range(r.shape[0]):
        kind = report[k, 0]
        i = report[k, 1]
        if kind == REPORT_OUTPUT:
            r[k] = y[i]
        elif kind == REPORT_STATE:
            r[k] = x[i]
        elif kind == REPORT_MODE:
            r[k] = m[i]
        else:
            r[k] = 1.0 if m[i] == report[k, 2] else 0.0


# ---------------------------------------------------------------- Python side
#: return types of the overloads called through their addresses
ADVANCE_RETURNS = types.int64
OUTPUTS_RETURNS = types.none


_ADDRESSES: dict = {}


def native_address(dispatcher, sig, returns) -> int:
    """Address of the native function of ``dispatcher``'s overload for the argument types ``sig`` (compiled, or
    loaded from numba's cache, as a call would); 0 if that overload does not return ``returns``."""
    key = (dispatcher, sig)
    address = _ADDRESSES.get(key)
    if address is None:
        dispatcher.compile(sig)
        cres = dispatcher.overloads.get(sig)
        address = 0
        if cres is not None and cres.signature.return_type == returns:
            address = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)
        _ADDRESSES[key] = address
    return address


# -- the table written from Python, in the layout of numba's data model
_LEAF_CODES = {"i1": "?", "i8": "b", "i16": "h", "i32": "i", "i64": "q", "double": "d", "float": "f"}
_SIZES: dict = {}


def _size_align(context, llty):
    """ABI size and alignment of the LLVM type ``llty``: C layout of (non-packed) structs and arrays over the
    sizes the target gives for the scalars and pointers."""
    if isinstance(llty, ir.ArrayType):
        size, align = _size_align(context, llty.element)
        return size * llty.count, align
    if isinstance(llty, ir.BaseStructType):
        at, align = 0, 1
        for element in llty.elements:
            size, a = _size_align(context, element)
            at = -(-at // a) * a + size
            align = max(align, a)
        return -(-at // align) * align, align
    key = str(llty)
    hit = _SIZES.get(key)
    if hit is None:
        hit = _SIZES[key] = (context.get_abi_sizeof(llty), context.get_abi_alignment(llty))
    return hit


def _offsets(context, llty):
    """Byte offsets of the elements of the LLVM struct or array type ``llty``."""
    if isinstance(llty, ir.ArrayType):
        size = _size_align(context, llty.element)[0]
        return [k * size for k in range(llty.count)]
    offsets, at = [], 0
    for element in llty.elements:
        size, align = _size_align(context, element)
        at = -(-at // align) * align
        offsets.append(at)
        at += size
    return offsets


def _flattener(context, ty, base, fields):
    """Append the ``(offset, struct code)`` of the scalars of the native, borrowed form of a value of numba
    type ``ty`` at byte ``base`` to ``fields``; return ``flat(value, out)``, which appends their values in
    the same order -- or None for a type this does not know."""
    llty = context.get_value_type(ty)
    if isinstance(ty, types.Array):
        model = context.data_model_manager.lookup(ty)
        if model._fields != ("meminfo", "parent", "nitems", "itemsize", "data", "shape", "strides"):
            return None
        for member, at in zip(model._members, _offsets(context, llty)):
            if _flattener(context, member, base + at, fields) is None:
                return None

        def flat(v, out):
            out += (0, 0, v.size, v.itemsize, v.__array_interface__["data"][0])  # (no owner, no parent: borrowed)
            out += v.shape
            out += v.strides

        return flat
    if isinstance(ty, types.BaseTuple):
        if isinstance(llty, ir.BaseStructType) and llty.packed:
            return None
        offsets = _offsets(context, llty)
        if len(offsets) != len(ty.types):
            return None
        subs = [_flattener(context, t, base + at, fields) for t, at in zip(ty.types, offsets)]
        if any(f is None for f in subs):
            return None

        def flat(v, out):
            for f, x in zip(subs, v):
                f(x, out)

        return flat
    if isinstance(ty, (types.MemInfoPointer, types.CPointer, types.PyObject, types.RawPointer)):
        fields.append((base, "Q"))
        return lambda v, out: out.append(v)
    code = _LEAF_CODES.get(str(llty))
    if code is None or not isinstance(ty, (types.Boolean, types.Integer, types.Float)):
        return None
    if isinstance(ty, types.Integer) and not ty.signed:
        code = code.upper()
    fields.append((base, code))
    convert = bool if code == "?" else float if code in "df" else int
    return lambda v, out: out.append(convert(v))


_PLANS: dict = {}


def table_layout(args_ty):
    """``(bytes, fields, flat)`` of the table of a session with packed arguments of numba type ``args_ty``, or
    None (a type this does not know, or a layout that is not numba's).

    ``fields`` lists ``(offset, struct code)`` of every scalar of the table in order: the addresses of
    ``advance`` and ``evaluate_outputs``, then the arguments' scalars (an array: its owner, parent, size,
    item size, data pointer, shape and strides; pointers have the code ``"Q"``); ``flat(args, out)``
    appends their values in the same order.  A native FMU (:mod:`clutchlab.fmu.native`) writes the table
    from the same layout.  Worked out once per type (an FMU's export builds the model's image a thousand
    times: the layout was four fifths of its time)."""
    if args_ty in _LAYOUTS:
        return _LAYOUTS[args_ty]
    _LAYOUTS[args_ty] = layout = _table_layout(args_ty)
    return layout


#: args type -> :func:`table_layout`
_LAYOUTS: dict = {}


def _table_layout(args_ty):
    from numba.core.registry import cpu_target

    context = cpu_target.target_context
    table = _table_type(context, args_ty)
    offsets = _offsets(context, table)
    fields = [(offsets[0], "Q"), (offsets[1], "Q")]
    flat = _flattener(context, args_ty, offsets[2], fields)
    nbytes = context.get_abi_sizeof(table)
    if flat is None or _size_align(context, table)[0] != nbytes:
        return None
    return nbytes, fields, flat


def _plan(args_ty):
    """``(bytes, struct, flat)`` that writes the table of a session with packed arguments of type ``args_ty``
    from Python, or None (a type this does not know, or a layout that is not numba's)."""
    if args_ty in _PLANS:
        return _PLANS[args_ty]
    import struct

    layout = table_layout(args_ty)
    plan = None
    if layout is not None:
        nbytes, fields, flat = layout
        fmt, at = "=", 0
        for offset, code in fields:
            if offset < at:
                break
            fmt += "x" * (offset - at) + code
            at = offset + struct.calcsize("=" + code)
        else:
            plan = (nbytes, struct.Struct(fmt), flat)
    _PLANS[args_ty] = plan
    return plan


def open_session(module, outputs_module, args):
    """Pack a session's ``args`` (:data:`FIELDS`) into a new table; ``(call, handle)``, where ``call(handle,
    t_end, what)`` is the entry of the compiled ``session`` overload (:func:`call`), or None if an overload
    does not have the form the table's call expects.

    ``module`` is the model's entry module of the session's method (``advance``, ``session``,
    ``session_pack``), ``outputs_module`` that of ``evaluate_outputs``; their overloads for the types of
    ``args`` are compiled, or loaded from numba's cache, here.  The table is written from Python in the
    layout of numba's data model (the arrays' native structures with their owners NULL); for a type that
    this does not know, by the compiled ``session_pack`` (a compiled function whose argument is the whole
    tuple: 0.5-2 s of compiling per model, for a table written once per session).
    """
    args_ty = module.session.typeof_pyval(args)
    a = args_ty.types
    advance_at = native_address(module.advance, a[:4] + (types.float64,) + a[4:14], ADVANCE_RETURNS)
    outputs_at = native_address(outputs_module.evaluate_outputs, (a[0], types.float64, a[1], a[3], a[2], a[14]),
                                OUTPUTS_RETURNS)
    if not (advance_at and outputs_at):
        return None
    plan = _plan(args_ty)
    if plan is not None:
        buffer = np.zeros(-(-plan[0] // 8), dtype=np.float64)  # (8-byte aligned)
        values = [advance_at, outputs_at]
        plan[2](args, values)
        plan[1].pack_into(buffer, 0, *values)
    else:
        buffer = np.zeros(-(-table_bytes(args_ty) // 8), dtype=np.float64)
        module.session_pack(buffer.ctypes.data, args, advance_at, outputs_at)
    handle = Handle(buffer, SessionType(args_ty), args)
    sig = (handle.numba_type, types.float64, types.int64)
    entry = module.session.overloads.get(sig)
    if entry is None:
        module.session.compile(sig)
        entry = module.session.overloads[sig]
    return entry.entry_point, handle
