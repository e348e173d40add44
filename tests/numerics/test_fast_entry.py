"""The compiled entries called without numba's per-call typing (:class:`clutchlab.numerics.entry._FastEntry`).

The fast path calls a remembered overload only for the very parameter structure of an earlier call and arguments
whose fingerprint was seen with it: these tests change each of those and check the overload that runs is the one
numba's dispatcher would choose (a wrong overload reads an int64 array as float64 and gives a wrong number).
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numba
import numpy as np
import pytest

from clutchlab.numerics import entry
from clutchlab.numerics.entry import _FAST_KEEP, _FastEntry, fast_entry


class _P(NamedTuple):
    scale: np.ndarray
    shift: float


@numba.njit
def _weighted(p, a, k):
    return p.scale[0] * a.sum() * k + p.shift


def _p(scale=2.0, shift=0.5):
    return _P(np.array([scale]), shift)


def test_the_second_call_with_the_same_structure_runs_the_overload_numba_chose():
    fast = _FastEntry(_weighted)
    p = _p()
    a = np.arange(4.0)
    assert fast(p, a, 3.0) == _weighted.py_func(p, a, 3.0)
    remembered = fast.known[id(p)][1]
    assert len(remembered) == 1
    (call,) = remembered.values()
    sig = tuple(_weighted.typeof_pyval(v) for v in (p, a, 3.0))
    assert call is _weighted.overloads[sig].entry_point
    assert fast(p, a + 1.0, 2.0) == _weighted.py_func(p, a + 1.0, 2.0)


def test_other_argument_types_are_typed_again_not_reinterpreted():
    fast = _FastEntry(_weighted)
    p = _p()
    assert fast(p, np.arange(4.0), 3.0) == 2.0 * 6.0 * 3.0 + 0.5
    ints = np.arange(4, dtype=np.int64)
    assert fast(p, ints, 3.0) == 2.0 * 6.0 * 3.0 + 0.5   # int64 data read as float64 would be ~1e-322
    assert fast(p, ints, 3) == 2.0 * 6.0 * 3 + 0.5        # an int where a float was: a new overload
    assert fast(p, np.arange(4.0)[::2], 1.0) == 2.0 * 2.0 + 0.5   # a strided view: another layout
    assert len(fast.known[id(p)][1]) == 4


def test_a_new_structure_goes_through_the_dispatcher_and_few_are_kept():
    fast = _FastEntry(_weighted)
    a = np.ones(3)
    kept = [_p(scale=float(j)) for j in range(_FAST_KEEP + 3)]
    for j, p in enumerate(kept):
        assert fast(p, a, 1.0) == 3.0 * j + 0.5
    assert len(fast.known) == _FAST_KEEP
    assert all(hit[0] is kept[-1 - j] for j, hit in enumerate(reversed(list(fast.known.values()))))
    # a structure of another type (an int shift: another numba type) with the id of none kept
    other = _P(np.array([2.0]), 1)
    assert fast(other, a, 1.0) == 7.0


def test_a_conversion_is_never_remembered():
    """An argument the dispatcher converts (no exact overload) is typed at every call."""
    @numba.njit("float64(float64)")
    def twice(x):
        return 2.0 * x

    fast = _FastEntry(twice)
    p = 3          # an int where the only overload takes a float64
    assert fast(p) == 6.0
    assert fast.known == {}


def test_without_numbas_fingerprint_every_call_goes_through_the_dispatcher(monkeypatch):
    monkeypatch.setattr(entry, "_fingerprint", None)
    fast = _FastEntry(_weighted)
    p = _p()
    assert fast(p, np.arange(4.0), 1.0) == 12.5
    assert fast.known == {}


_REC = np.dtype([("a", np.float64), ("b", np.float64)])
_REC_SWAPPED = np.dtype([("b", np.float64), ("a", np.float64)])


class _R(NamedTuple):
    rec: np.ndarray
    shift: float


@numba.njit
def _record_sum(p, a):
    r = p.rec[0]
    return r.a * a.sum() + r.b + p.shift


def test_a_record_array_is_typed_once_and_an_equal_dtype_anew_never_mistaken(monkeypatch):
    """numba's ``typeof_pyval`` builds a record array's type anew at every call (0.17 ms each: a new EMTC bench
    run's two records cost 20 % of a 1 s run); the entry remembers types by numba's own fingerprint, in which a
    structured dtype is its canonical copy.  A new structure of the same types is then not typed again in
    Python, and one whose record has its fields in another order (another type, another layout of the bytes)
    is typed and read as itself."""
    calls = []
    original = _record_sum.typeof_pyval
    monkeypatch.setattr(_record_sum, "typeof_pyval", lambda v: calls.append(v) or original(v))
    entry._TYPES.clear()
    fast = _FastEntry(_record_sum)
    a = np.arange(3.0)

    def rec(dtype, x, y):
        out = np.zeros(1, dtype=dtype)
        out[0]["a"], out[0]["b"] = x, y
        return out

    assert fast(_R(rec(_REC, 2.0, 5.0), 0.5), a) == 2.0 * 3.0 + 5.0 + 0.5   # (compiled: typed by numba)
    calls.clear()
    # a new structure with new arrays of the same dtypes: no typing in Python (it was two calls, one per
    # argument, to remember the overload), the same overload
    assert fast(_R(rec(np.dtype(_REC.descr), 3.0, 1.0), 0.25), a + 1.0) == 3.0 * 6.0 + 1.0 + 0.25
    assert calls == []
    # the fields in the other order: another type, typed, and its bytes read as its own fields
    assert fast(_R(rec(_REC_SWAPPED, 3.0, 1.0), 0.0), a) == 3.0 * 3.0 + 1.0
    assert calls
    assert len(_record_sum.overloads) == 2


@pytest.mark.parametrize("method", ["dopri", "rodas"])
def test_a_model_run_twice_through_the_fast_entry_gives_the_same_record(method):
    """A network run twice with its own parameter structure (the second call the remembered overload) records
    exactly what the first did, and the fast entry names that overload (Rosenbrock: the fixed-step mode)."""
    from clutchlab.driveline.description import load_driveline
    from clutchlab.system import simulate

    f = load_driveline(Path(__file__).parents[2] / "examples" / "driveline_coupled_clutches.toml")
    system = f.driveline.system(f.rtol)
    kw = dict(output_step=0.05, fixed_step=1e-3 if method == "rodas" else None)
    first = simulate(system, 0.5, **kw)
    second = simulate(system, 0.5, **kw)
    np.testing.assert_array_equal(first.states, second.states)
    np.testing.assert_array_equal(first.modes, second.modes)
    assert first.states[-1, 0] != first.states[0, 0]
    hit = fast_entry(type(system.params), method, "advance").known.get(id(system.params))
    assert hit is not None and hit[0] is system.params and len(hit[1]) >= 1


class _Outer(NamedTuple):
    inner: _P
    shared: _P


@numba.njit
def _nested(q, a):
    return q.inner.scale[0] * a.sum() + q.shared.scale[0] + q.inner.shift + q.shared.shift


def test_a_structure_of_structures_is_typed_from_its_members_and_never_reinterpreted():
    """A structure not seen before, whose members are (a plain network: its own, and the empty component blocks every
    network shares), is typed from its members' remembered types and runs the overload numba would choose; a member of
    another type (int64 data, a strided view) is typed again: a wrong overload would read int64 data as float64."""
    fast = _FastEntry(_nested)
    shared = _p(3.0, 0.25)
    a = np.arange(4.0)
    for k in range(6):   # new structures, one member shared by all of them
        q = _Outer(_p(2.0 + k, 0.5), shared)
        assert fast(q, a) == _nested.py_func(q, a)
    assert len(_nested.overloads) == 1
    q = _Outer(_P(np.array([2]), 0.5), shared)   # int64 scale: another type, another overload
    assert fast(q, a) == 2 * 6.0 + 3.0 + 0.75
    q = _Outer(_P((np.arange(4.0) + 2.0)[::2], 0.5), shared)   # a strided view: another layout
    assert fast(q, a) == 2.0 * 6.0 + 3.0 + 0.75
    assert len(_nested.overloads) == 3
    for args in ((q, a), (_Outer(_p(5.0, 0.5), shared), a), (_Outer(_p(5.0, 0.5), shared), np.arange(4))):
        assert fast(*args) == _nested.py_func(*args)   # each overload found again by its type, not mistaken
    assert entry._typeof_structure(_nested, q) == _nested.typeof_pyval(q)
