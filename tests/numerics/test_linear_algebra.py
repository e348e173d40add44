"""The linear algebra of a Rosenbrock step (``clutchlab.numerics.rosenbrock``): dense LU and the reduced solve.

The reduced solve (kinematic rows eliminated first, trailing states solved last, a partial-pivoting LU of the
rest) must give the solution of the whole system, whatever the structure: checked against NumPy on matrices
drawn with kinematic rows (one entry off the diagonal), trailing columns (zero off the diagonal), algebraic rows
(mass 0) and dense blocks, at step sizes from 1e-7 to 1 s.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hypothesis_budget import examples

from clutchlab.numerics.rosenbrock import (GAMMA, KEEP, KINEMATIC, TRAILING, lu_factor, lu_solve, plan_reduction,
                                           reduced_factor, reduced_solve, reduction_sizes)

_HEAD = 8  # layout of the plan (rosenbrock._HEAD): counts, then the kind of every state


def _plan(J, mass):
    n = J.shape[0]
    ni, nf = reduction_sizes(n)
    iw = np.zeros(ni, dtype=np.int64)
    fw = np.zeros(nf)
    plan_reduction(np.ascontiguousarray(J), np.ascontiguousarray(mass, dtype=float), iw)
    return iw, fw


def _solve(J, mass, h, b):
    """``(M/(h gamma) - J) y = b`` through the plan; (ok, y, dense fallback used)."""
    n = J.shape[0]
    iw, fw = _plan(J, mass)
    G = np.full((n, n), np.nan)  # only the entries the solves read are written
    piv = np.zeros(n, dtype=np.int64)
    ok = reduced_factor(np.ascontiguousarray(J), np.ascontiguousarray(mass, dtype=float), 1.0 / (h * GAMMA), G, iw,
                        fw, piv)
    y = b.copy()
    if ok:
        reduced_solve(G, iw, fw, piv, y)
    return ok, y, bool(iw[4])


@st.composite
def structured(draw):
    n = draw(st.integers(1, 14))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    J = rng.standard_normal((n, n)) * (rng.uniform(size=(n, n)) < rng.uniform(0.1, 0.7))
    J *= 10.0 ** rng.uniform(-2, 6, size=(n, 1))  # rows of very different scales (stiff springs, compliances)
    mass = (rng.uniform(size=n) < 0.85).astype(float)
    for r in range(n):
        u = rng.uniform()
        if u < 0.3:  # kinematic: dz/dt = v
            J[r] = 0.0
            s = int(rng.integers(0, n))
            if s != r:
                J[r, s] = 1.0
            mass[r] = 1.0
        elif u < 0.45:  # trailing: nothing depends on it (an energy integral)
            J[:, r] = 0.0
            J[r, r] = 0.0 if rng.uniform() < 0.7 else -rng.uniform(0.1, 1.0)
            mass[r] = 1.0
    h = 10.0 ** draw(st.floats(-7, 0))
    b = rng.standard_normal(n)
    return J, mass, h, b


@settings(max_examples=examples(300), deadline=None)
@given(structured())
def test_reduced_solve_equals_the_whole_system(case):
    J, mass, h, b = case
    n = J.shape[0]
    G = -J.copy()
    G[np.diag_indices(n)] += mass / (h * GAMMA)
    cond = np.linalg.cond(G)
    ok, y, _dense = _solve(J, mass, h, b)
    if not np.isfinite(cond) or cond > 1e12:
        return  # (singular or nearly: nothing to compare)
    assert ok
    ref = np.linalg.solve(G, b)
    # forward error of a backward-stable solve: a few units of cond * eps
    assert np.abs(y - ref).max() <= 1e-13 * cond * max(np.abs(ref).max(), 1e-300) + 1e-300
    # and the residual is small against the matrix and the solution (backward stable)
    assert np.abs(G @ y - b).max() <= 1e-12 * np.abs(G).max() * max(np.abs(y).max(), 1e-300) + 1e-12 * np.abs(b).max()


def test_plan_of_a_mass_spring_chain_with_energy_integrals():
    """Positions are kinematic, the velocities kept, the energy integral trailing."""
    # states: x1, x2, v1, v2, E   (x' = v, m v' = -k x - c v, E' = c v^2)
    k, c = 1e6, 10.0
    J = np.zeros((5, 5))
    J[0, 2] = J[1, 3] = 1.0
    J[2, 0], J[2, 1], J[2, 2] = -2 * k, k, -c
    J[3, 0], J[3, 1], J[3, 3] = k, -k, -c
    J[4, 2], J[4, 3] = 2 * c * 0.1, 2 * c * 0.2
    iw, _ = _plan(J, np.ones(5))
    kinds = list(iw[_HEAD:_HEAD + 5])
    assert kinds == [KINEMATIC, KINEMATIC, KEEP, KEEP, TRAILING]
    assert list(iw[:3]) == [2, 2, 1]
    ok, y, dense = _solve(J, np.ones(5), 1e-3, np.arange(1.0, 6.0))
    assert ok and not dense
    G = -J + np.eye(5) / (1e-3 * GAMMA)
    np.testing.assert_allclose(y, np.linalg.solve(G, np.arange(1.0, 6.0)), rtol=1e-13)


def test_a_kinematic_row_needing_a_pivot_falls_back_to_the_whole_lu():
    """At a step so long that the diagonal 1/(h gamma) is smaller than the row's other entry, the kinematic
    elimination would divide by the smaller entry: the whole matrix is factored with partial pivoting."""
    J = np.array([[0.0, 1.0], [-4.0, -0.1]])
    ok, y, dense = _solve(J, np.ones(2), 10.0, np.array([1.0, 2.0]))
    assert ok and dense
    G = -J + np.eye(2) / (10.0 * GAMMA)
    np.testing.assert_allclose(y, np.linalg.solve(G, [1.0, 2.0]), rtol=1e-14)


def test_chains_of_kinematic_rows_are_not_eliminated():
    """x' = y, y' = z, z' = -5 x: every row has one entry off the diagonal; a row whose partner is itself
    eliminated is kept, so no kinematic row leans on another (here x and y are kept, z eliminated)."""
    J = np.zeros((3, 3))
    J[0, 1] = 1.0
    J[1, 2] = 1.0
    J[2, 0] = -5.0
    iw, _ = _plan(J, np.ones(3))
    kinds = list(iw[_HEAD:_HEAD + 3])
    partners = list(iw[_HEAD + 3:_HEAD + 6])
    assert kinds == [KEEP, KEEP, KINEMATIC] and partners[2] == 0
    for r in range(3):
        if kinds[r] == KINEMATIC and partners[r] >= 0:
            assert kinds[partners[r]] == KEEP
    ok, y, _ = _solve(J, np.ones(3), 0.01, np.array([1.0, -1.0, 0.5]))
    np.testing.assert_allclose(y, np.linalg.solve(-J + np.eye(3) / (0.01 * GAMMA), [1.0, -1.0, 0.5]), rtol=1e-13)


@pytest.mark.parametrize("n", [1, 3, 11, 20])
def test_dense_lu_matches_numpy(n):
    rng = np.random.default_rng(n)
    A = rng.standard_normal((n, n)) + n * np.eye(n) * 0.1
    b = rng.standard_normal(n)
    lu = A.copy()
    piv = np.zeros(n, dtype=np.int64)
    assert lu_factor(lu, piv)
    x = b.copy()
    lu_solve(lu, piv, x)
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-10, atol=1e-12)


def test_singular_matrices_are_reported():
    piv = np.zeros(2, dtype=np.int64)
    assert not lu_factor(np.array([[1.0, 2.0], [2.0, 4.0]]), piv)
    # a trailing state with a zero diagonal (algebraic, nothing depends on it): singular
    J = np.zeros((2, 2))
    J[1, 0] = 1.0
    ok, _y, _dense = _solve(J, np.array([1.0, 0.0]), 1e-3, np.ones(2))
    assert not ok
