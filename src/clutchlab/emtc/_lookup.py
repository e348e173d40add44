"""Compiled table look-ups of the EMTC model: time profiles and 2-D maps (linear, clamped at the ends).

One function per kind of table, used by the model hooks (:mod:`clutchlab.emtc.system`) and by the public
callables that evaluate the same tables (:class:`~clutchlab.emtc.bench.TorqueMap`,
:class:`~clutchlab.emtc.friction.FrictionMap`).
"""

from __future__ import annotations

import numba

from ..numerics import FASTMATH
from ..numerics.interp import bracket


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def interp1(tx, ty, t):
    """Piecewise-linear profile ``ty(tx)`` at ``t``, held at the end values outside ``tx`` (one point: constant)."""
    n = tx.shape[0]
    if n == 1:
        return ty[0]
    i, s = bracket(tx, t)
    return ty[i] + s * (ty[i + 1] - ty[i])


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def bilinear(xg, yg, z, x, y):
    """Bilinear map ``z[i, j]`` on the grids ``xg`` x ``yg`` at ``(x, y)``, clamped to the map's edges."""
    i, s = bracket(xg, x)
    j, r = bracket(yg, y)
    return z[i, j] * (1 - s) * (1 - r) + z[i + 1, j] * s * (1 - r) + z[i, j + 1] * (1 - s) * r + z[i + 1, j + 1] * s * r


@numba.njit(cache=True, nogil=True)
def bilinear_many(xg, yg, z, x, y, out):
    """:func:`bilinear` at the points ``(x[k], y[k])`` into ``out[k]`` (the vectorised public callables)."""
    for k in range(x.shape[0]):
        out[k] = bilinear(xg, yg, z, x[k], y[k])
