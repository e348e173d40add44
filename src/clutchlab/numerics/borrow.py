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

from numba.core import cgutils, types
from numba.core.imputils import impl_ret_borrowed, lower_getattr_generic
from numba.core.typing.templates import AttributeTemplate, infer_getattr
from numba.extending import intrinsic, models, register_model

__all__ = ["borrow", "byref", "ByRef"]


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
