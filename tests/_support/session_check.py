"""A check shared by the tests of the packed sessions (clutchlab.numerics.session)."""

import struct

import numpy as np
from numba.core.registry import cpu_target

from clutchlab.numerics import core
from clutchlab.numerics import session as S


def assert_packed_as_compiled(sim):
    """The table a session writes from Python (clutchlab.numerics.session) holds, at every place it writes, the
    bytes numba's compiled packing (the model's ``session_pack``) writes there."""
    for _ in range(sim._pack_after + 1):
        sim.outputs()  # (packs at the call after the dispatched ones)
    handle = sim._fast[1]
    args_ty = handle.numba_type.args
    assert S._plan(args_ty) is not None  # (written from Python)
    context = cpu_target.target_context
    offsets = S._offsets(context, S._table_type(context, args_ty))
    fields = [(offsets[0], "Q"), (offsets[1], "Q")]
    assert S._flattener(context, args_ty, offsets[2], fields) is not None
    assert offsets[:2] == [0, 8] and len(fields) > 50
    fa, fo = struct.unpack_from("=QQ", handle.buffer, 0)
    compiled = np.zeros_like(handle.buffer)
    core.entry_points(type(sim.system.params), sim._method()).session_pack(compiled.ctypes.data, handle.owners, fa,
                                                                            fo)
    for offset, code in fields:
        assert struct.unpack_from("=" + code, compiled, offset) == struct.unpack_from("=" + code, handle.buffer,
                                                                                      offset), (offset, code)
