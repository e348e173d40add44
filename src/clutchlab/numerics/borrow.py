"""Borrowed views: arrays without reference counting inside the compiled core.

numba reference-counts every array it passes to a function that LLVM does not
inline: an atomic increment on entry and a decrement on exit, per array, and a
tuple argument counts each array in it.  The integrator core calls the model's
hooks several times per stage with the parameter structure, the state, the
inputs and work arrays; measured on the EMTC bench (9 arrays in its
parameters), these atomic operations were a fifth of the run time.

:func:`borrow` returns the same value (same numba type, same data) with the
owner (``meminfo``) of every array in it set to NULL, so numba's reference
counting of the copies is a null test.  The caller must keep the original
alive while the borrowed value is used: the core borrows only its own
arguments (held by its caller for the whole call) and work arrays whose
owners it passes to its last call (so numba keeps them to the end).  A borrowed array must never be
returned to Python or stored beyond the call.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numba.core import cgutils, types
from numba.core.imputils import impl_ret_borrowed, lower_getattr_generic
from numba.core.typing.templates import AttributeTemplate, infer_getattr
from numba.extending import intrinsic, models, register_model
from numba.np.arrayobj import load_item

__all__ = ["borrow", "byref", "ByRef", "member", "take", "shaped", "Ragged", "stack_rows", "row", "row_of", "row_words",
           "keep_row", "kept_row", "keep_rows", "block_row"]


def _has_arrays(ty) -> bool:
    if isinstance(ty, types.Array):
        return True
    if isinstance(ty, types.BaseTuple):
        return any(_has_arrays(t) for t in ty)
    return False


def _strip(context, builder, ty, value):
    if isinstance(ty, types.Array):
        ary = context.make_array(ty)(context, builder, value=value)
        ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
        ary.parent = cgutils.get_null_value(ary.parent.type)
        return ary._getvalue()
    if isinstance(ty, types.BaseTuple):
        out = value
        for i, member in enumerate(ty):
            if _has_arrays(member):
                out = builder.insert_value(out, _strip(context, builder, member, builder.extract_value(value, i)), i)
        return out
    return value


@intrinsic
def borrow(typingctx, value):
    """``value`` (an array, or a tuple/NamedTuple holding arrays) with its arrays' owners set to NULL."""
    sig = value(value)

    def codegen(context, builder, signature, args):
        return _strip(context, builder, signature.args[0], args[0])

    return sig, codegen


# ---------------------------------------------------------------- parameters passed by reference
class ByRef(types.Type):
    """A pointer to a tuple/NamedTuple value held in the frame of the function that made it (:func:`byref`).

    Attribute access ``p.name`` reads the member through the pointer, so functions taking ``p`` look the same
    whether they get the structure or a reference to it.
    """

    def __init__(self, pointee):
        self.pointee = pointee
        super().__init__(name=f"ByRef({pointee})")

    @property
    def key(self):
        return self.pointee


@register_model(ByRef)
class _ByRefModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, dmm.lookup(fe_type.pointee).get_value_type().as_pointer())


@infer_getattr
class _ByRefAttributes(AttributeTemplate):
    key = ByRef

    def generic_resolve(self, typ, attr):
        pointee = typ.pointee
        fields = getattr(pointee, "fields", ())
        if attr in fields:
            return pointee.types[fields.index(attr)]
        return None


@lower_getattr_generic(ByRef)
def _byref_getattr(context, builder, typ, value, attr):
    pointee = typ.pointee
    i = pointee.fields.index(attr)
    member = builder.load(cgutils.gep_inbounds(builder, value, 0, i))
    return impl_ret_borrowed(context, builder, pointee.types[i], member)


@intrinsic
def byref(typingctx, value):
    """A :class:`ByRef` to ``value`` (a tuple or NamedTuple), stored once in the calling function's frame.

    numba passes a tuple to a function as one argument per scalar it holds; a model's parameter structure is
    hundreds of words, copied at every hook call.  A reference is one pointer.  Valid while the calling
    function runs: the core makes it at the start of a run and passes it to the hooks only.
    """
    if not isinstance(value, types.BaseTuple):
        return None
    sig = ByRef(value)(value)

    def codegen(context, builder, signature, args):
        return cgutils.alloca_once_value(builder, args[0])

    return sig, codegen


@intrinsic
def member(typingctx, ref, name):
    """A :class:`ByRef` to member ``name`` (a literal string) of the tuple a :class:`ByRef` points to: its address,
    nothing loaded.  ``ref.name`` loads the member, and in reference-counted code counts every array in it (a model's
    stacked parameters: about sixty calls); this passes it on as one pointer (``row(member(e, "params"), j)``)."""
    if not isinstance(ref, ByRef) or not isinstance(name, types.StringLiteral):
        return None
    pointee = ref.pointee
    fields = getattr(pointee, "fields", ())
    if name.literal_value not in fields:
        return None
    i = fields.index(name.literal_value)
    sig = ByRef(pointee.types[i])(ref, name)

    def codegen(context, builder, signature, args):
        return cgutils.gep_inbounds(builder, args[0], 0, i)

    return sig, codegen


# ---------------------------------------------------------------- one variant of stacked parameters
def _row_type(ty, ragged=False):
    """Type of one variant of a stacked structure (None if ``ty`` is not one).

    An array becomes the array of one less dimension (its row), a one-dimensional array the scalar of
    its dtype (a number field), a tuple/NamedTuple the tuple of its members' rows; with ``ragged``, a
    :class:`Ragged` member the C-contiguous array of its ``ndim`` (:func:`row`).
    """
    if ragged and _is_ragged(ty):
        return types.Array(ty.types[0].dtype, ty.instance_class.ndim, "C")
    if isinstance(ty, types.Array):
        if ty.ndim == 1:
            return ty.dtype
        return ty.copy(ndim=ty.ndim - 1, layout="C" if ty.layout == "C" else "A")
    if not isinstance(ty, types.BaseTuple) or not len(ty.types):
        return None
    members = [_row_type(t, ragged) for t in ty.types]
    if any(m is None for m in members):
        return None
    if isinstance(ty, types.BaseNamedTuple):  # as numba types a NamedTuple object
        if all(m == members[0] for m in members[1:]):
            return types.NamedUniTuple(members[0], len(members), ty.instance_class)
        return types.NamedTuple(members, ty.instance_class)
    return types.Tuple(members)


def _take_row(context, builder, ty, row_ty, value, idx):
    if isinstance(row_ty, types.Array) and _is_ragged(ty):   # (only row() types a Ragged member as an array)
        return _ragged_row(context, builder, ty, row_ty, value, idx)
    if isinstance(ty, types.Array):
        src = context.make_array(ty)(context, builder, value=value)
        shape = cgutils.unpack_tuple(builder, src.shape)
        strides = cgutils.unpack_tuple(builder, src.strides)
        data = cgutils.pointer_add(builder, src.data, builder.mul(idx, strides[0]))
        if ty.ndim == 1:
            return load_item(context, builder, ty, data)
        out = context.make_array(row_ty)(context, builder)
        context.populate_array(out, data=data, shape=cgutils.pack_array(builder, shape[1:]),
                               strides=cgutils.pack_array(builder, strides[1:]), itemsize=src.itemsize,
                               meminfo=None)
        return out._getvalue()
    members = [_take_row(context, builder, t, r, builder.extract_value(value, k), idx)
               for k, (t, r) in enumerate(zip(ty.types, row_ty.types))]
    return context.make_tuple(builder, row_ty, members)


def _take_row_ref(context, builder, ty, row_ty, ptr, idx):
    """:func:`_take_row` of the value ``ptr`` points to (a :class:`ByRef`), reading only what the row needs: the
    data pointer of each stacked array (and the starts and shapes of a :class:`Ragged`), never the whole stacked
    structure (hundreds of array headers loaded as one value at every row: measured on an EMTC network, 2 % of its
    run)."""
    if isinstance(row_ty, types.Array) and _is_ragged(ty):
        return _ragged_row_ref(context, builder, ty, row_ty, ptr, idx)
    if isinstance(ty, types.Array):
        src = context.make_array(ty)(context, builder, ref=ptr)
        if ty.ndim == 1:
            if ty.layout == "C":
                data = cgutils.gep_inbounds(builder, src.data, idx)
            else:
                stride = builder.extract_value(src.strides, 0)
                data = cgutils.pointer_add(builder, src.data, builder.mul(idx, stride))
            return load_item(context, builder, ty, data)
        return _take_row(context, builder, ty, row_ty, builder.load(ptr), idx)
    members = [_take_row_ref(context, builder, t, r, cgutils.gep_inbounds(builder, ptr, 0, k), idx)
               for k, (t, r) in enumerate(zip(ty.types, row_ty.types))]
    return context.make_tuple(builder, row_ty, members)


@intrinsic
def take(typingctx, stacked, v):
    """Variant ``v`` of stacked parameters: ``stacked`` with every array ``a`` replaced by ``a[v]`` (borrowed).

    ``stacked`` is a tuple/NamedTuple (or a :class:`ByRef` to one) of arrays or of such tuples, each array
    with a leading variant axis;
    the result is the structure of one variant: a one-dimensional array gives a scalar (a number field of the
    structure), an array with more dimensions a view without owner (as :func:`borrow`), valid while
    ``stacked`` is alive; nested tuples are taken member by member.  ``v`` is not bounds-checked: the caller
    iterates over the variant axis.
    """
    ref = isinstance(stacked, ByRef)
    sty = stacked.pointee if ref else stacked
    if not isinstance(sty, types.BaseTuple) or not isinstance(v, types.Integer) or not len(sty.types):
        return None
    row = _row_type(sty)
    if row is None:
        return None
    sig = row(stacked, v)

    def codegen(context, builder, signature, args):
        value, idx = args
        idx = context.cast(builder, idx, signature.args[1], types.intp)
        if ref:  # (a parallel loop takes the structure by reference: its gufunc cannot pass nested tuples)
            return _take_row_ref(context, builder, sty, signature.return_type, value, idx)
        return _take_row(context, builder, sty, signature.return_type, value, idx)

    return sig, codegen


# ---------------------------------------------------------------- rows of different sizes
class Ragged(NamedTuple):
    """One array field of several structures whose arrays differ in size (:func:`stack_rows`): the arrays
    flattened one after the other into ``data``, row ``j``'s first element ``start[j]`` and its shape
    ``shape[j]`` (int64, ``(n, ndim)``).  Its subclasses (:func:`_ragged_class`) carry ``ndim`` for the compiler."""

    data: np.ndarray
    start: np.ndarray
    shape: np.ndarray


class Ragged1(Ragged):
    """Rows of one-dimensional arrays."""
    __slots__ = ()
    ndim = 1


class Ragged2(Ragged):
    """Rows of two-dimensional arrays."""
    __slots__ = ()
    ndim = 2


class Ragged3(Ragged):
    """Rows of three-dimensional arrays."""
    __slots__ = ()
    ndim = 3


class Ragged4(Ragged):
    """Rows of four-dimensional arrays."""
    __slots__ = ()
    ndim = 4


_RAGGED = {1: Ragged1, 2: Ragged2, 3: Ragged3, 4: Ragged4}


def _ragged_class(ndim: int) -> type:
    """The :class:`Ragged` subclass of arrays of ``ndim`` dimensions (module-level classes: cached kernels and
    pickles name them)."""
    if ndim not in _RAGGED:
        raise TypeError(f"stack_rows: arrays of {ndim} dimensions (at most 4)")
    return _RAGGED[ndim]


def _is_ragged(ty) -> bool:
    return isinstance(ty, types.BaseNamedTuple) and issubclass(ty.instance_class, Ragged)


def _ragged_row(context, builder, ty, row_ty, value, idx):
    """Row ``idx`` of a :class:`Ragged` member: a borrowed C-contiguous view of its part of ``data``."""
    data_ty, start_ty, shape_ty = ty.types
    data = context.make_array(data_ty)(context, builder, value=builder.extract_value(value, 0)).data
    start = context.make_array(start_ty)(context, builder, value=builder.extract_value(value, 1)).data
    shp = context.make_array(shape_ty)(context, builder, value=builder.extract_value(value, 2)).data
    return _ragged_view(context, builder, data_ty, row_ty, data, start, shp, idx)


def _ragged_view(context, builder, data_ty, row_ty, data, start, shp, idx):
    """The borrowed C-contiguous view of row ``idx`` of a :class:`Ragged` from its three data pointers."""
    intp = context.get_value_type(types.intp)
    first = builder.load(cgutils.gep_inbounds(builder, start, idx))
    ndim = row_ty.ndim
    base = builder.mul(idx, context.get_constant(types.intp, ndim))
    dims = [builder.load(cgutils.gep_inbounds(builder, shp,
                                              builder.add(base, context.get_constant(types.intp, d))))
            for d in range(ndim)]
    dims = [builder.sext(d, intp) if d.type.width < intp.width else d for d in dims]
    itemsize = context.get_constant(types.intp, context.get_abi_sizeof(context.get_data_type(data_ty.dtype)))
    strides, step = [], itemsize
    for d in reversed(dims):
        strides.append(step)
        step = builder.mul(step, d)
    strides.reverse()
    ptr = cgutils.gep_inbounds(builder, data, first)
    out = context.make_array(row_ty)(context, builder)
    context.populate_array(out, data=ptr, shape=cgutils.pack_array(builder, dims),
                           strides=cgutils.pack_array(builder, strides), itemsize=itemsize, meminfo=None)
    return out._getvalue()


def _ragged_row_ref(context, builder, ty, row_ty, ptr, idx):
    """:func:`_ragged_row` of the :class:`Ragged` ``ptr`` points to (its three data pointers read, nothing else)."""
    data_ty, start_ty, shape_ty = ty.types
    data = context.make_array(data_ty)(context, builder, ref=cgutils.gep_inbounds(builder, ptr, 0, 0)).data
    start = context.make_array(start_ty)(context, builder, ref=cgutils.gep_inbounds(builder, ptr, 0, 1)).data
    shp = context.make_array(shape_ty)(context, builder, ref=cgutils.gep_inbounds(builder, ptr, 0, 2)).data
    return _ragged_view(context, builder, data_ty, row_ty, data, start, shp, idx)


def _stack_member(values, template, what):
    """The values of one member over the rows (numbers: a vector, arrays: a :class:`Ragged`, tuples: member-wise)."""
    if isinstance(template, np.ndarray):
        arrays = [np.ascontiguousarray(v) for v in values]
        for v in arrays:
            if v.ndim != template.ndim or v.dtype != template.dtype:
                raise TypeError(f"{what}: an array of {v.ndim} dimensions of {v.dtype} where the first row has "
                                f"{template.ndim} of {template.dtype}")
        sizes = np.array([v.size for v in arrays], dtype=np.int64)
        start = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64) if len(arrays) else sizes
        data = (np.concatenate([v.ravel() for v in arrays]) if arrays else np.zeros(0, dtype=template.dtype))
        shape = (np.array([v.shape for v in arrays], dtype=np.int64).reshape(len(arrays), template.ndim))
        return _ragged_class(template.ndim)(np.ascontiguousarray(data), start, np.ascontiguousarray(shape))
    if isinstance(template, tuple):
        members = [_stack_member([v[k] for v in values], t, f"{what}[{k}]") for k, t in enumerate(template)]
        return type(template)(*members) if hasattr(template, "_fields") else tuple(members)
    if isinstance(template, (bool, np.bool_)):
        dtype = np.bool_
    elif isinstance(template, (int, np.integer)):
        dtype = np.int64
    elif isinstance(template, (float, np.floating)):
        dtype = np.float64
    else:
        raise TypeError(f"{what}: {type(template).__name__} is neither a number, an array nor a tuple")
    return np.array(values, dtype=dtype).reshape(len(values))


def stack_rows(structures, template=None):
    """Several structures of one kind (a model's parameter NamedTuple) as one structure of rows, whatever the sizes
    of their arrays: a number field becomes a vector, an array a :class:`Ragged`, a tuple is stacked member by
    member.  Its numba type does not depend on the number of rows or on their sizes, so a compiled function that
    takes it serves any number of them (a network's wet clutches or EMTC couplings).  ``template``: a structure
    of the kind, giving the types where ``structures`` is empty.  :func:`row` (compiled) and :func:`row_of`
    (Python) give row ``j`` back as views."""
    structures = list(structures)
    if template is None:
        if not structures:
            raise ValueError("stack_rows: no structures and no template")
        template = structures[0]
    return _stack_member(structures, template, type(template).__name__)


def row_of(stacked, j: int):
    """Row ``j`` of :func:`stack_rows`'s result in Python: the structure with views of its arrays."""
    if isinstance(stacked, Ragged):
        first, shape = int(stacked.start[j]), tuple(int(d) for d in stacked.shape[j])
        return stacked.data[first:first + int(np.prod(shape, dtype=np.int64))].reshape(shape)
    if isinstance(stacked, np.ndarray):
        return stacked[j].item()
    members = [row_of(s, j) for s in stacked]
    return type(stacked)(*members) if hasattr(stacked, "_fields") else tuple(members)


@intrinsic
def row(typingctx, stacked, j):
    """Row ``j`` of :func:`stack_rows`'s result (or a :class:`ByRef` to it): the structure of that row, its arrays
    borrowed views of their parts of the :class:`Ragged` data (C-contiguous, the row's own shape), its numbers
    scalars; valid while ``stacked`` is alive.  ``j`` is not bounds-checked.  The row has the numba type of the
    structure it was stacked from, so the model's compiled functions serve it unchanged."""
    ref = isinstance(stacked, ByRef)
    sty = stacked.pointee if ref else stacked
    if not isinstance(sty, types.BaseTuple) or not isinstance(j, types.Integer) or not len(sty.types):
        return None
    row_ty = _row_type(sty, ragged=True)
    if row_ty is None:
        return None
    sig = row_ty(stacked, j)

    def codegen(context, builder, signature, args):
        value, idx = args
        idx = context.cast(builder, idx, signature.args[1], types.intp)
        if ref:
            return _take_row_ref(context, builder, sty, signature.return_type, value, idx)
        return _take_row(context, builder, sty, signature.return_type, value, idx)

    return sig, codegen


# ---------------------------------------------------------------- rows built once, read by reference
# Building a row (:func:`row`) reads each of its numbers from its own stacked vector and each array's place in its
# Ragged: for an EMTC coupling about 110 values, a tenth of a network's run when done at every evaluation.  A
# model builds its rows once per call of the core instead (its ``prepare`` hook, :mod:`clutchlab.numerics.dispatch`)
# into a float64 array of :func:`row_words` words per row (:func:`keep_row`) and its hooks read them by reference
# (:func:`kept_row`).  A kept row holds the addresses of the stacked arrays: valid while they are alive and unmoved,
# so it is built again at every entry of the core (a copied or rewritten structure is never read stale).
def _row_bytes(stacked_type) -> int:
    from numba.core.registry import cpu_target

    row_ty = _row_type(stacked_type, ragged=True)
    if row_ty is None:
        raise TypeError(f"row_words: {stacked_type} is not a structure of stacked rows")
    context = cpu_target.target_context
    return int(context.get_abi_sizeof(context.get_value_type(row_ty)))


def row_words(stacked) -> int:
    """The float64 words one row of ``stacked`` (:func:`stack_rows`'s result) takes as numba holds it in memory: the
    width of the array :func:`keep_row` fills."""
    return -(-_row_bytes(numba.typeof(stacked)) // 8)


def _kept_slot(context, builder, row_ty, rows_ty, rows, idx):
    """The address of row ``idx``'s slot in ``rows`` (a C-contiguous float64 array, a row per slot), as a pointer
    to the row's value type."""
    ary = context.make_array(rows_ty)(context, builder, value=rows)
    stride = builder.extract_value(ary.strides, 0)
    ptr = cgutils.pointer_add(builder, ary.data, builder.mul(idx, stride))
    return builder.bitcast(ptr, context.get_value_type(row_ty).as_pointer())


def _rows_args(stacked, rows, j):
    if not (isinstance(stacked, ByRef) and isinstance(stacked.pointee, types.BaseTuple)
            and isinstance(rows, types.Array) and rows.ndim == 2 and rows.dtype == types.float64
            and rows.layout == "C" and isinstance(j, types.Integer)):
        return None
    return _row_type(stacked.pointee, ragged=True)


@intrinsic
def keep_row(typingctx, stacked, rows, j):
    """Build row ``j`` of the stacked structure ``stacked`` refers to (:func:`row`) into slot ``j`` of ``rows``
    (float64, ``(n, row_words)``, C-contiguous): :func:`kept_row` reads it by reference until the stacked arrays
    change.  The caller sized ``rows`` with :func:`row_words`."""
    row_ty = _rows_args(stacked, rows, j)
    if row_ty is None:
        return None
    sig = types.none(stacked, rows, j)

    def codegen(context, builder, signature, args):
        ref, rows_v, idx = args
        idx = context.cast(builder, idx, signature.args[2], types.intp)
        value = _take_row_ref(context, builder, signature.args[0].pointee, row_ty, ref, idx)
        builder.store(value, _kept_slot(context, builder, row_ty, signature.args[1], rows_v, idx))
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def kept_row(typingctx, stacked, rows, j):
    """A :class:`ByRef` to row ``j`` of ``stacked`` as :func:`keep_row` built it into ``rows``: its address,
    nothing loaded or built (the row has the numba type :func:`row` gives)."""
    row_ty = _rows_args(stacked, rows, j)
    if row_ty is None:
        return None
    sig = ByRef(row_ty)(stacked, rows, j)

    def codegen(context, builder, signature, args):
        _ref, rows_v, idx = args
        idx = context.cast(builder, idx, signature.args[2], types.intp)
        return _kept_slot(context, builder, row_ty, signature.args[1], rows_v, idx)

    return sig, codegen


@numba.njit(cache=True, nogil=True, _nrt=False)
def keep_rows(block):
    """Every row of a block kept (:func:`keep_row`): ``block`` a :class:`ByRef` to a structure with members
    ``params`` (:func:`stack_rows`'s result) and ``rows`` (float64, a slot of :func:`row_words` words per row), the
    driveline's blocks of model components.  A component's ``prepare`` hook, once per call of the core."""
    for j in range(block.rows.shape[0]):
        keep_row(member(block, "params"), block.rows, j)


@numba.njit(cache=True, nogil=True, _nrt=False)
def block_row(block, j):
    """A :class:`ByRef` to row ``j`` of a block as :func:`keep_rows` built it."""
    return kept_row(member(block, "params"), block.rows, j)


# ---------------------------------------------------------------- a contiguous block viewed with a shape
@intrinsic
def shaped(typingctx, flat, shape):
    """The C-contiguous one-dimensional array ``flat`` viewed with ``shape`` (a tuple of integers), borrowed.

    numba's ``reshape`` calls a C helper at every call (measured: a tenth of a microsecond, three times
    per EMTC controller sample); this builds the view directly.  The caller guarantees that the product of
    ``shape`` is at most ``flat.size`` (the tables packed in a model's parameters, with their sizes).
    """
    if not (isinstance(flat, types.Array) and flat.ndim == 1 and flat.layout == "C"
            and isinstance(shape, types.BaseTuple) and len(shape) >= 1
            and all(isinstance(t, types.Integer) for t in shape)):
        return None
    out_ty = flat.copy(ndim=len(shape), layout="C")
    sig = out_ty(flat, shape)

    def codegen(context, builder, signature, args):
        arr = context.make_array(signature.args[0])(context, builder, value=args[0])
        dims = [context.cast(builder, builder.extract_value(args[1], k), signature.args[1][k], types.intp)
                for k in range(len(signature.args[1]))]
        strides = []
        step = arr.itemsize
        for d in reversed(dims):
            strides.append(step)
            step = builder.mul(step, d)
        strides.reverse()
        out = context.make_array(signature.return_type)(context, builder)
        context.populate_array(out, data=arr.data, shape=cgutils.pack_array(builder, dims),
                               strides=cgutils.pack_array(builder, strides), itemsize=arr.itemsize, meminfo=None)
        return out._getvalue()

    return sig, codegen
