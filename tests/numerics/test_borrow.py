"""The core's views without reference counting: ``take`` (one variant of stacked parameters), ``row`` (one of
several structures of different sizes, ``stack_rows``) and ``shaped``."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hypothesis_budget import examples
from clutchlab.numerics.borrow import byref, keep_row, kept_row, member, row, row_of, row_words, shaped, stack_rows, take


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
    p = take(byref(P), v)   # (through a reference: only the members the row needs are read)
    return p.table.sum() + p.gain + p.inner.k * p.inner.n + p.pair[0] - p.pair[1]


@numba.njit(cache=True)
def _write_variant(P, v, value):
    take(P, v).table[0, 0] = value


def test_take_gives_each_variants_row_of_arrays_numbers_and_nested_tuples():
    n = 3
    P = Stacked(np.arange(n * 6, dtype=float).reshape(n, 3, 2), np.array([1.0, 2.0, 3.0]),
                Inner(np.array([0.5, 1.5, 2.5]), np.array([2, 3, 4], dtype=np.int64)),
                (np.array([10.0, 20.0, 30.0]), np.array([1.0, 1.0, 2.0])))
    strided = P._replace(gain=np.array([1.0, -9.0, 2.0, -9.0, 3.0, -9.0])[::2])   # (a vector that is not contiguous)
    for v in range(n):
        expect = (P.table[v].sum() + P.gain[v] + P.inner.k[v] * P.inner.n[v] + P.pair[0][v] - P.pair[1][v])
        assert _sum_variant(P, v) == expect == _sum_variant(strided, v)
        assert _sum_variant_byref(P, v) == expect == _sum_variant_byref(strided, v)
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


# ---------------------------------------------------------------- rows of different sizes (stack_rows / row)
class Model(NamedTuple):
    inner: Inner
    pair: tuple
    curve: np.ndarray
    memory: np.ndarray
    grid: np.ndarray


@numba.njit(cache=True)
def _model_sum(p):
    """What a model's hook reads of its structure: numbers, nested tuples, array shapes and elements."""
    s = p.inner.k * p.inner.n + p.pair[0] - p.pair[1]
    for i in range(p.curve.shape[0]):
        for j in range(p.curve.shape[1]):
            s += (i + 1) * (j + 2) * p.curve[i, j]
    return s + p.memory.shape[0] * 1000.0 + p.grid[p.grid.shape[0] - 1]


@numba.njit(cache=True)
def _row_sum(P, j):
    return _model_sum(row(P, j))


@numba.njit(cache=True)
def _row_sum_byref(P, j):
    return _model_sum(row(byref(P), j))


class Holder(NamedTuple):
    params: Model
    rows: np.ndarray


@numba.njit(cache=True)
def _kept_sums(H):
    """Every row kept (built once into ``H.rows``), then each read back by reference."""
    for j in range(H.rows.shape[0]):
        keep_row(member(byref(H), "params"), H.rows, j)
    out = np.empty(H.rows.shape[0])
    for j in range(H.rows.shape[0]):
        out[j] = _model_sum_ref(kept_row(member(byref(H), "params"), H.rows, j))
    return out


@numba.njit(cache=True)
def _model_sum_ref(q):
    return q.inner.k * q.inner.n + q.pair[0] - q.pair[1] + q.curve.sum() * 7.0 + q.memory.shape[0] * 1000.0 \
        + q.grid[q.grid.shape[0] - 1]


@numba.njit(cache=True)
def _row_write(P, j, value):
    r = row(P, j)
    r.memory[r.memory.shape[0] - 1] = value


def _model(rng, a, b, m):
    return Model(Inner(float(rng.normal()), int(rng.integers(1, 9))), (float(rng.normal()), float(rng.normal())),
                 rng.normal(size=(a, b)), np.arange(m, dtype=np.int64), np.sort(rng.normal(size=a + 1)))


@settings(max_examples=examples(30), deadline=None)
@given(st.lists(st.tuples(st.integers(0, 4), st.integers(1, 5), st.integers(0, 6)), min_size=1, max_size=5),
       st.integers(0, 2 ** 32 - 1))
def test_row_gives_each_structure_back_whatever_its_sizes(sizes, seed):
    """``stack_rows`` of structures whose arrays differ in size (empty ones too), and ``row``: each row is its
    structure, to the bit, in compiled code (directly and through a reference) and in Python (``row_of``); a write
    into a row's array lands in that row's part only; and the row has the numba type of the structure, so a model's
    function compiled for one serves the rows unchanged."""
    rng = np.random.default_rng(seed)
    models = [_model(rng, *s) for s in sizes]
    P = stack_rows(models)
    for j, p in enumerate(models):
        assert _row_sum(P, j) == _model_sum(p) == _row_sum_byref(P, j)
        back = row_of(P, j)
        assert numba.typeof(back) == numba.typeof(p)
        assert np.array_equal(back.curve, p.curve) and np.array_equal(back.grid, p.grid)
        assert back.inner == p.inner and back.pair == p.pair
    assert len(_model_sum.signatures) == 1
    # rows kept once and read by reference (a model's ``prepare`` hook): the same values, each row in its own slot
    H = Holder(P, np.full((len(models), row_words(P)), np.nan))
    kept = _kept_sums(H)
    for j, p in enumerate(models):
        assert kept[j] == _model_sum_ref(p)   # (the same function on the structure itself: the same sums, bitwise)
    for j, p in enumerate(models):
        if p.memory.size:
            _row_write(P, j, -5)
            assert row_of(P, j).memory[-1] == -5
            assert all(np.array_equal(row_of(P, i).memory, q.memory) for i, q in enumerate(models) if i != j)
            P.memory.data[P.memory.start[j] + p.memory.size - 1] = p.memory[-1]


def test_stack_rows_of_none_has_the_type_of_any_number():
    """No structure (a network without that component), from a template: the same numba type as for any number of
    rows, so one compiled kernel serves them all; a structure of another kind is refused by name."""
    rng = np.random.default_rng(1)
    one, two = _model(rng, 2, 3, 4), _model(rng, 1, 1, 0)
    assert numba.typeof(stack_rows([], template=one)) == numba.typeof(stack_rows([one, two]))
    assert numba.typeof(stack_rows([one])) == numba.typeof(stack_rows([two, one, two]))
    with pytest.raises(TypeError, match="dimensions"):
        stack_rows([one, one._replace(curve=np.zeros(3))])
