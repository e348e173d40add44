"""The split of a statically indeterminate stuck set (``kernel._repair_space``) is searched warm: each combination
of the lossy gears' band pieces keeps the vertex of its largest margin and the active set of its nearest split from
the last evaluation, and takes them (or a set one bound away) where their optimality conditions hold, enumerating
only where they fail.  These tests check, against SciPy (HiGHS for the linear programme, SLSQP for the quadratic
one), that the answer is the optimum whatever the hint: none, a stale one, garbage, or the last optimum of a
neighbouring problem; in two to five dimensions (a stuck set's null directions: the warm start's words grow with
the network's largest constraint set, ``kernel.space_hint``)."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples, pinned
from scipy.optimize import linprog, minimize

from clutchlab.driveline import kernel as K

TOL = 1e-12


def _problem(seed: int, m: int, d: int, shift: float = 0.0):
    """``G z + theta w <= h``: ``m`` random bounds in ``d`` dimensions, some violated at ``z = 0``, inside a box of
    2 d bounds (so that the largest margin is finite)."""
    rng = np.random.default_rng(seed)
    G = np.vstack([rng.normal(size=(m, d)), np.eye(d), -np.eye(d)])
    h = np.concatenate([rng.normal(size=m) + 0.3, np.full(2 * d, 5.0)]) + shift
    w = rng.uniform(0.1, 1.0, m + 2 * d)
    return np.ascontiguousarray(G), h, w


def _hint(d):
    """A new warm start for a ``d``-dimensional problem (a network whose largest constraint set has ``d`` members,
    ``kernel.space_hint``): the vertex's rank and bounds from 0, the active set's size and bounds from :func:`_at`."""
    return np.zeros(K.space_hint(d))


def _at(d):
    """Where the nearest split's active set starts in a warm start of :func:`_hint` (as ``kernel._repair_space``
    places it)."""
    return d + 2


def _scratch(m, d):
    """The cold solves' scratch (``kernel._repair_space``'s ``sc``)."""
    return np.zeros((2, max(m, d + 1)))


def _margin(G, h, w, hint, small=None):
    m, d = G.shape
    small = d <= K.ENUMERATED_DIMENSIONS if small is None else small
    R, GR, zt = np.zeros((d, d)), np.zeros((m, d)), np.zeros(d + 1)
    nr = K._span_basis(G, m, d, R, GR, zt)
    idx, base, y = np.zeros(d + 1, np.int64), np.zeros(d + 1, np.int64), np.zeros(d + 1)
    M, b = np.zeros((d + 1, d + 1)), np.zeros(d + 1)
    return K._combo_margin(GR, w, h, nr, m, idx, base, M, b, y, _scratch(m, d), np.zeros((d + 1, d + 1)), hint, 0,
                           TOL, small)


def _nearest(G, h, w, theta, hint, small=None):
    m, d = G.shape
    small = d <= K.ENUMERATED_DIMENSIONS if small is None else small
    idx, base = np.zeros(d + 1, np.int64), np.zeros(d + 1, np.int64)
    M, b, zt, z = np.zeros((d + 1, d + 1)), np.zeros(d + 1), np.zeros(d + 1), np.zeros(d)
    nz = K._combo_nearest(G, d, h, w, theta, m, idx, base, M, b, zt, z, _scratch(m, d), np.zeros((d + 1, d + 1)), hint,
                          _at(d), TOL, small)
    return nz, z.copy()


def _scipy_margin(G, h, w):
    m, d = G.shape
    res = linprog(np.r_[np.zeros(d), -1.0], A_ub=np.column_stack([G, w]), b_ub=h,
                  bounds=[(None, None)] * (d + 1), method="highs")
    assert res.status == 0
    return -res.fun


def _scipy_nearest(G, h, w, theta):
    d = G.shape[1]
    best = None
    for z0 in (np.zeros(d), np.linalg.lstsq(G, h - theta * w, rcond=None)[0]):
        res = minimize(lambda z: z @ z, z0, jac=lambda z: 2 * z, method="SLSQP",
                       constraints=[{"type": "ineq", "fun": lambda z: h - theta * w - G @ z, "jac": lambda z: -G}],
                       options={"ftol": 1e-15, "maxiter": 500})
        if np.all(G @ res.x + theta * w <= h + 1e-9) and (best is None or res.x @ res.x < best @ best):
            best = res.x
    return best


def _hints(rng, m, d, k1, last):
    """Hints to try: none (a new work array's zeros), garbage, a valid random set, and the last optimum."""
    out = [_hint(d), rng.uniform(-3, 40, _hint(d).size)]
    h = _hint(d)
    h[0] = d
    h[1:1 + k1] = np.sort(rng.choice(m, k1, replace=False))
    kk = int(rng.integers(0, min(d, m) + 1))
    h[_at(d)] = kk
    h[_at(d) + 1:_at(d) + 1 + kk] = np.sort(rng.choice(m, kk, replace=False))
    out.append(h)
    out.append(last.copy())
    return out


def _feasible_sets(G, h, w, theta=None):
    """Hints that are feasible but need not be optimal: every vertex of the largest-margin programme that keeps every
    bound (``theta`` None: rank, then ``d + 1`` bounds), or every active set whose split at ``theta`` keeps them."""
    m, d = G.shape
    A = np.column_stack([G, w])
    out = []
    for k in ([d + 1] if theta is None else range(1, d + 1)):
        for S in itertools.combinations(range(m), k):
            S = list(S)
            hint = _hint(d)
            try:
                if theta is None:
                    x = np.linalg.solve(A[S], h[S])
                    ok = np.all(G @ x[:d] + x[d] * w <= h + 1e-9)
                    hint[0], hint[1:1 + k] = d, S
                else:
                    mu = np.linalg.solve(G[S] @ G[S].T, h[S] - theta * w[S])
                    ok = np.all(G @ (G[S].T @ mu) + theta * w <= h + 1e-9)
                    hint[_at(d)], hint[_at(d) + 1:_at(d) + 1 + k] = k, S
            except np.linalg.LinAlgError:
                continue
            if ok:
                out.append(hint)
    return out


@settings(max_examples=examples(40), deadline=None, derandomize=pinned())
@given(seed=st.integers(0, 2**32 - 1), m=st.integers(2, 8), d=st.integers(2, 5),
       shift=st.floats(-0.05, 0.05), small=st.booleans())
def test_the_warm_split_search_finds_the_optimum_whatever_its_hint(seed, m, d, shift, small):
    """Largest margin and nearest split equal SciPy's optima from every hint: none, garbage, a random set, every
    feasible vertex or active set (which only the optimality conditions tell from the optimum), and the hint left
    behind by a neighbouring problem (``shift``: the torques moved), as between two evaluations of a run; by either
    search (``small``: the neighbours of the hint and the enumeration, the kernel's up to ``ENUMERATED_DIMENSIONS``
    null directions; else the simplex and active-set methods from the hint or their cold start)."""
    m = min(m, 10 - d)   # (every feasible vertex is tried as a hint: C(m + 2 d, d + 1) solves)
    rng = np.random.default_rng(seed + 1)
    G0, h0, w0 = _problem(seed, m, d)
    last = _hint(d)
    theta0 = _margin(G0, h0, w0, last, small)   # (leaves its optimum's vertex in last[:d + 2])
    if theta0 >= 0.0:
        _nearest(G0, h0, w0, 0.5 * theta0, last, small)   # (and its active set in last[d + 2:])
    G, h, w = _problem(seed, m, d, shift)
    mt = G.shape[0]
    best = _scipy_margin(G, h, w)
    for hint in _hints(rng, mt, d, d + 1, last) + _feasible_sets(G, h, w):
        assert abs(_margin(G, h, w, hint, small) - best) <= 1e-9 * max(1.0, abs(best))
    if best < 0.0:
        return
    theta = 0.5 * best
    z_ref = _scipy_nearest(G, h, w, theta)
    assert z_ref is not None
    for hint in _hints(rng, mt, d, d + 1, last) + _feasible_sets(G, h, w, theta):
        nz, z = _nearest(G, h, w, theta, hint, small)
        assert np.all(G @ z + theta * w <= h + 1e-9)
        assert nz <= z_ref @ z_ref + 1e-9
        assert np.allclose(z, z_ref, atol=1e-6)
        assert 0 <= hint[_at(d)] <= d   # the optimum's set is left as the hint


def test_a_hint_one_pivot_away_is_taken_without_enumerating():
    """The optimum's vertex moved by one bound between two evaluations: the set one bound away from the hint is
    found and becomes the hint (the enumeration would also find it; this checks the hint path itself)."""
    G = np.ascontiguousarray(np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 1.0]]))
    w = np.ones(5)
    h = np.array([1.0, 1.0, 1.0, 1.0, 1.9])
    hint = _hint(2)
    first = _margin(G, h, w, hint)
    assert abs(first - _scipy_margin(G, h, w)) < 1e-12
    kept = hint.copy()
    h2 = h.copy()
    h2[4] = 0.5           # the diagonal bound now cuts the square: the optimum's vertex changes
    second = _margin(G, h2, w, hint)
    assert abs(second - _scipy_margin(G, h2, w)) < 1e-12
    assert not np.array_equal(hint[1:4], kept[1:4])


@settings(max_examples=examples(60), deadline=None, derandomize=pinned())
@given(seed=st.integers(0, 2**32 - 1), m=st.integers(1, 30), d=st.integers(1, 8), zero=st.integers(0, 3),
       shift=st.floats(-2.0, 2.0))
def test_the_cold_solves_find_scipy_s_optima_in_up_to_eight_dimensions(seed, m, d, zero, shift):
    """The cold start of the split search (``kernel._lp_max``, the simplex method, and ``kernel._qp_nearest``, the
    active-set method), which replaced the enumeration of every vertex (``C(m, d + 1)`` solves: a stuck set with four
    null directions and more), against SciPy's HiGHS and SLSQP, with bounds of zero width (a one-way clutch's free
    side: its bound holds whatever the margin) and problems where no split keeps a margin."""
    rng = np.random.default_rng(seed)
    G = np.ascontiguousarray(np.vstack([rng.normal(size=(m, d)), np.eye(d), -np.eye(d)]))
    mt = G.shape[0]
    h = np.concatenate([rng.normal(size=m) + shift, np.full(2 * d, 5.0)])
    w = rng.uniform(0.1, 1.0, mt)
    w[:min(zero, m)] = 0.0
    W, x, p, u, M, R = (np.zeros(d + 1, np.int64), np.zeros(d + 1), np.zeros(d + 1), np.zeros(d + 1),
                        np.zeros((d + 1, d + 1)), np.zeros((d + 1, d + 1)))
    theta, k = K._lp_max(G, w, h, d, mt, np.inf, W, x, p, u, M, R, TOL)
    res = linprog(np.r_[np.zeros(d), -1.0], A_ub=np.column_stack([G, w]), b_ub=h,
                  bounds=[(None, None)] * (d + 1), method="highs")
    if res.status == 2:   # the zero-width bounds alone hold nowhere: no split holds, at any margin
        assert theta < -1e6
        return
    assert res.status == 0
    assert abs(theta - (-res.fun)) <= 1e-9 * max(1.0, abs(res.fun)), (theta, -res.fun)
    assert np.all(G @ x[:d] + x[d] * w <= h + 1e-9)          # its point keeps every bound at its margin
    if theta < 0.0:
        return
    target = 0.5 * theta
    th2, _ = K._lp_max(G, w, h, d, mt, target, W, x, p, u, M, R, TOL)    # (stopped at the first split keeping target)
    assert th2 >= target
    hb = h - target * w
    z = x[:d].copy()
    assert np.all(G @ z <= hb + 1e-9)
    nz, k = K._qp_nearest(G, hb, d, mt, W, 0, z, p, u, M, R, TOL)
    z_ref = _scipy_nearest(G, h, w, target)
    assert z_ref is not None
    assert np.all(G @ z <= hb + 1e-9)
    assert abs(nz - z @ z) <= 1e-12 * max(1.0, nz)
    assert nz <= z_ref @ z_ref + 1e-9
    assert np.allclose(z, z_ref, atol=1e-6)
    assert 0 <= k <= d and np.allclose(G[W[:k]] @ z, hb[W[:k]], atol=1e-9)   # the bounds it holds
