"""The core's views without reference counting: ``take`` (one variant of stacked parameters) and ``shaped``."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hypothesis_budget import examples
from clutchlab.numerics.borrow import byref, shaped, take


class Inner(NamedTuple):
    k: float
    n: int


class Stacked(NamedTuple):
    table: np.ndarray
    gain: float
    inner: Inner
    pair: tuple


@numba.njit(cache=True)
def _sum_variant(P, v):
    p = take(P, v)
    return p.table.sum() + p.gain + p.inner.k * p.inner.n + p.pair[0] - p.pair[1]


@numba.njit(cache=True)
def _sum_variant_byref(P, v):
    return take(byref(P), v).table[1, 0]


@numba.njit(cache=True)
def _write_variant(P, v, value):
    take(P, v).table[0, 0] = value


def test_take_gives_each_variants_row_of_arrays_numbers_and_nested_tuples():
    n = 3
    P = Stacked(np.arange(n * 6, dtype=float).reshape(n, 3, 2), np.array([1.0, 2.0, 3.0]),
                Inner(np.array([0.5, 1.5, 2.5]), np.array([2, 3, 4], dtype=np.int64)),
                (np.array([10.0, 20.0, 30.0]), np.array([1.0, 1.0, 2.0])))
    for v in range(n):
        expect = (P.table[v].sum() + P.gain[v] + P.inner.k[v] * P.inner.n[v] + P.pair[0][v] - P.pair[1][v])
        assert _sum_variant(P, v) == expect
        assert _sum_variant_byref(P, v) == P.table[v, 1, 0]
    _write_variant(P, 1, -7.0)  # a view: writes land in the stacked array, row 1 only
    assert P.table[1, 0, 0] == -7.0 and P.table[0, 0, 0] == 0.0 and P.table[2, 0, 0] == 12.0


@numba.njit(cache=True)
def _shaped_sum(flat, start, a, b):
    view = shaped(flat[start:start + a * b], (a, b))
    return view.copy(), view.strides, view[a - 1, b - 1]  # (a borrowed view never goes back to Python)


@settings(max_examples=examples(40), deadline=None)
@given(st.integers(0, 5), st.integers(1, 6), st.integers(1, 6))
def test_shaped_views_a_block_as_numpy_reshape_does(start, a, b):
    flat = np.arange(start + a * b + 3, dtype=float)
    view, strides, last = _shaped_sum(flat, start, a, b)
    ref = flat[start:start + a * b].reshape(a, b)
    assert np.array_equal(view, ref) and strides == ref.strides and last == ref[-1, -1]
