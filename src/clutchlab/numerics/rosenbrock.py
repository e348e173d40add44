"""Rodas3: a stiffly accurate, L-stable Rosenbrock method for stiff ODEs and index-1 DAEs.

The E-clutch actuator couples a hydraulic line (sub-millisecond pressure
modes), a servomotor and a clutch whose stiffest component (the Model 4 yoke
support, ``k_ys.eq x 20``) vibrates at tens of kHz: an explicit method such as
Dormand-Prince would be held to micro-second steps by stability alone.  A
Rosenbrock (linearly implicit Runge-Kutta) method solves one linear system
per stage with the matrix ``M/(h gamma) - J`` and stays stable on the stiff
modes; because it is *stiffly accurate* it also integrates the algebraic
equations of massless nodes (mass-matrix rows equal to zero, index 1).

The method is Rodas3 of Sandu et al. [1] (4 stages, order 3, embedded order 2,
three new function evaluations per step) in the transformed form of Hairer &
Wanner [2], Sec. VI.4::

    (M/(h gamma) - J) K_i = f(t + alpha_i h, y + sum_j a_ij K_j)
                            + M sum_j (c_ij / h) K_j + h gamma_i df/dt
    y_new = y + sum_i m_i K_i,       error = K_4

Subsystem kernels call the cached helpers here (and the error norm of
:mod:`clutchlab.numerics.dopri`) (numba cannot cache a kernel
that receives another compiled function, so each subsystem writes its own
loop around its own right-hand side).

References
----------
.. [1] A. Sandu, J. G. Verwer, J. G. Blom, E. J. Spee, G. R. Carmichael,
   F. A. Potra, "Benchmarking stiff ODE solvers for atmospheric chemistry
   problems II: Rosenbrock solvers", Atmos. Environ. 31 (1997) 3459-3472.
.. [2] E. Hairer, G. Wanner, Solving Ordinary Differential Equations II, 2nd
   ed., Springer 1996, Sec. VI.4 (Rosenbrock methods, DAEs of index 1).
"""

from __future__ import annotations

import math

import numba
from numba import uintp as _u

from .borrow import shaped
from .layout import indices, slots

__all__ = ["GAMMA", "lu_factor", "lu_solve", "plan_reduction", "reduced_factor", "reduced_solve", "reduction_sizes",
           "rodas_next_step"]

#: diagonal coefficient gamma of Rodas3
GAMMA = 0.5
# a_ij (stage arguments): a21 = 0, a31 = 2, a32 = 0, a41 = 2, a42 = 0, a43 = 1
A31, A41, A43 = 2.0, 2.0, 1.0
# c_ij (stage couplings)
C21, C31, C32, C41, C42, C43 = 4.0, 1.0, -1.0, 1.0, -1.0, -8.0 / 3.0
# gamma_i (time-derivative weights) and alpha_i (stage times)
GAMMA1, GAMMA2 = 0.5, 1.5
ALPHA3, ALPHA4 = 1.0, 1.0
# solution weights m = (2, 0, 1, 1): y_new = Y4 + K4 (stiffly accurate); error estimate e = (0, 0, 0, 1)
ORDER_EST = 3  # local order of the error estimate (min(3, 2) + 1)

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 6.0


# Indices below are cast to unsigned (``_u``): numba wraps a negative signed index around (``a[-1]``), and
# LLVM cannot prove that indices such as ``range(k + 1, n)`` are non-negative, so every element access carried a
# test and an addition; unsigned indices are never wrapped.  Measured on an 11 x 11 factorisation and four
# solves: 24 % fewer instructions, bit-identical results.
@numba.njit(cache=True, nogil=True)
def lu_factor(a, piv):
    """In-place LU factorisation with partial pivoting of a small dense matrix.

    ``a`` receives the unit lower factor below the diagonal, U above it and the *reciprocals* of U's
    diagonal on it (:func:`lu_solve` multiplies by them: a division on the critical path of each row of a
    back substitution costs several multiplications).  Returns False if the matrix is singular to working
    precision.
    """
    n = a.shape[0]
    for k in range(n):
        uk = _u(k)
        p = k
        amax = abs(a[uk, uk])
        for i in range(k + 1, n):
            v = abs(a[_u(i), uk])
            if v > amax:
                amax = v
                p = i
        piv[uk] = p
        if amax == 0.0 or not math.isfinite(amax):
            return False
        if p != k:
            up = _u(p)
            for j in range(n):
                uj = _u(j)
                tmp = a[uk, uj]
                a[uk, uj] = a[up, uj]
                a[up, uj] = tmp
        inv = 1.0 / a[uk, uk]
        a[uk, uk] = inv
        for i in range(k + 1, n):
            ui = _u(i)
            lik = a[ui, uk] * inv
            a[ui, uk] = lik
            if lik != 0.0:
                for j in range(k + 1, n):
                    uj = _u(j)
                    a[ui, uj] -= lik * a[uk, uj]
    return True


@numba.njit(cache=True, nogil=True)
def lu_solve(lu, piv, b):
    """Solve ``A x = b`` in place (``b`` becomes ``x``) from :func:`lu_factor` output."""
    n = lu.shape[0]
    for k in range(n):
        uk = _u(k)
        p = piv[uk]
        if p != k:
            up = _u(p)
            tmp = b[uk]
            b[uk] = b[up]
            b[up] = tmp
    for i in range(n):
        ui = _u(i)
        s = b[ui]
        for j in range(i):
            uj = _u(j)
            s -= lu[ui, uj] * b[uj]
        b[ui] = s
    for ii in range(n):
        i = n - 1 - ii
        ui = _u(i)
        s = b[ui]
        for j in range(i + 1, n):
            uj = _u(j)
            s -= lu[ui, uj] * b[uj]
        b[ui] = s * lu[ui, ui]  # (the reciprocal of U's diagonal: lu_factor)


# ---------------------------------------------------------------- the linear systems of a step, reduced
# The iteration matrix G = M/(h gamma) - J of a mechanical model has two kinds of rows that need no
# pivoting: *kinematic* rows (dz/dt = v: one entry off the diagonal) and *trailing* states (integrals of
# energies, a massless node's unused velocity: nothing depends on them, their columns are zero off the
# diagonal).  Eliminating the kinematic rows first (each changes one column of the rows that use the
# position: the usual effective stiffness k h gamma / m of an implicit mass-spring step) and solving the
# trailing rows last leaves a smaller dense system for the partial-pivoting LU.  On the E-clutch (20 states):
# 5 kinematic, 4 trailing, 11 kept; an LU of 20 x 20 and four solves were most of a step's cost.
#: the kinds of rows (``plan_reduction``)
ROW_KINDS = ("keep", "kinematic", "trailing")
KEEP, KINEMATIC, TRAILING = indices(ROW_KINDS, "keep", "kinematic", "trailing")
#: the head of the plan's integer work (the row lists follow it): the counts of kept, kinematic and trailing
#: rows, whether the reduction is used, whether the dense factors are current; three spare slots
PLAN_HEAD = slots(("kept", 1), ("kinematic", 1), ("trailing", 1), ("reduced", 1), ("dense_now", 1), ("spare", 3))
_NK, _NKIN, _NTR, _MODE, _DENSE_NOW = PLAN_HEAD.of("kept", "kinematic", "trailing", "reduced", "dense_now")
_HEAD = PLAN_HEAD.total


@numba.njit(cache=True, nogil=True)
def reduction_sizes(n):
    """Lengths ``(int work, float work)`` of the arrays :func:`plan_reduction` and :func:`reduced_factor` use."""
    return _HEAD + 6 * n + 2 + 2 * n * n, 2 * n * n + 2 * n


@numba.njit(cache=True, nogil=True, inline="always")
def _plan_views(iw, n):
    """The plan's index lists in ``iw`` (layout of :func:`plan_reduction`): partner, order, position among
    the kept rows, the kept rows' sparse pattern (pointers, rows) and the trailing rows' (pointers, columns)."""
    return (iw[_HEAD + n:_HEAD + 2 * n], iw[_HEAD + 2 * n:_HEAD + 3 * n], iw[_HEAD + 3 * n:_HEAD + 4 * n],
            iw[_HEAD + 4 * n:_HEAD + 5 * n + 1], iw[_HEAD + 5 * n + 1:_HEAD + 5 * n + 1 + n * n],
            iw[_HEAD + 5 * n + 1 + n * n:_HEAD + 6 * n + 2 + n * n], iw[_HEAD + 6 * n + 2 + n * n:])


@numba.njit(cache=True, nogil=True)
def plan_reduction(J, mass, iw):
    """Classify the states from the non-zeros of the Jacobian ``J`` (once per Jacobian) into ``iw``.

    *Trailing*: column zero off the diagonal (nothing depends on the state).  *Kinematic*: a row with a
    positive mass and at most one non-zero off the diagonal, at a column that is kept (a position whose
    derivative is a velocity; a stuck coordinate's rows, zero).  *Kept*: the rest, factored densely.
    ``iw`` (int64, :func:`reduction_sizes`) receives the counts, the kind and partner column of every state,
    the order kept - kinematic - trailing and the position of each kept state in the reduced matrix.
    """
    n = J.shape[0]
    kind = iw[_HEAD:_HEAD + n]
    partner, order, posk, _mptr, _mrow, tptr, tcol = _plan_views(iw, n)
    for c in range(n):
        trailing = True
        for r in range(n):
            if r != c and J[r, c] != 0.0:
                trailing = False
                break
        kind[c] = TRAILING if trailing else KEEP
        partner[c] = -1
    for r in range(n):
        if kind[r] == TRAILING or not mass[r] > 0.0:
            continue
        s = -1
        cnt = 0
        for c in range(n):
            if c != r and J[r, c] != 0.0:
                cnt += 1
                s = c
                if cnt > 1:
                    break
        if cnt <= 1 and (s < 0 or kind[s] != TRAILING):
            kind[r] = KINEMATIC
            partner[r] = s
    for r in range(n):  # a kinematic row's partner must be kept (no chains)
        if kind[r] == KINEMATIC and partner[r] >= 0 and kind[partner[r]] == KINEMATIC:
            kind[r] = KEEP
            partner[r] = -1
    nk = 0
    for want in (KEEP, KINEMATIC, TRAILING):
        for i in range(n):
            if kind[i] == want:
                if want == KEEP:
                    posk[i] = nk
                order[nk] = i
                nk += 1
    n_keep = 0
    n_kin = 0
    for i in range(n):
        if kind[i] == KEEP:
            n_keep += 1
        elif kind[i] == KINEMATIC:
            n_kin += 1
    iw[_NK] = n_keep
    iw[_NKIN] = n_kin
    iw[_NTR] = n - n_keep - n_kin
    iw[_MODE] = 1 if n_keep < n else 0
    # the trailing rows' non-zero columns off the diagonal (their back-substitution)
    e = 0
    for q in range(n - n_keep - n_kin):
        c = order[n_keep + n_kin + q]
        tptr[q] = e
        for j in range(n):
            if j != c and J[c, j] != 0.0:
                tcol[e] = j
                e += 1
    tptr[n - n_keep - n_kin] = e


@numba.njit(cache=True, nogil=True)
def _whole(J, mass, hg, G, piv):
    """``G = diag(mass) hg - J`` built whole and factored by :func:`lu_factor`."""
    n = J.shape[0]
    for i in range(n):
        for j in range(n):
            G[i, j] = -J[i, j]
        G[i, i] += mass[i] * hg
    return lu_factor(G, piv)


@numba.njit(cache=True, nogil=True)
def reduced_factor(J, mass, hg, G, iw, fw, piv):
    """Factor ``G = diag(mass) hg - J`` (``hg = 1/(h gamma)``) along the plan of :func:`plan_reduction`.

    With a reduction: the kept rows and columns are taken from ``J`` into ``fw`` with the kinematic rows
    eliminated (their multipliers kept for the solves) and factored by :func:`lu_factor`; of ``G`` only the
    entries the solves read are written (the kinematic rows' diagonal and partner, the trailing rows'
    non-zeros), so the whole matrix is never built.  Without a reduction, or when a kinematic row's diagonal
    is not the larger entry of its row at this step size (it would need pivoting), ``G`` is built whole and
    factored in place.  Returns False if the matrix is singular.
    """
    n = J.shape[0]
    iw[_DENSE_NOW] = 1
    if iw[_MODE] == 0:
        return _whole(J, mass, hg, G, piv)
    nk = iw[_NK]
    nkin = iw[_NKIN]
    ntr = iw[_NTR]
    partner, order, posk, mptr, mrow, tptr, tcol = _plan_views(iw, n)
    mval = fw[n * n:2 * n * n]
    rdiag = fw[2 * n * n + n:2 * n * n + 2 * n]  # reciprocals of the kinematic and trailing rows' diagonals
    for q in range(nkin):
        r = _u(order[_u(nk + q)])
        s = partner[r]
        grr = mass[r] * hg - J[r, r]
        G[r, r] = grr
        if s >= 0:
            G[r, _u(s)] = -J[r, _u(s)]
        if grr == 0.0 or not math.isfinite(grr) or (s >= 0 and abs(grr) < abs(G[r, _u(s)])):
            return _whole(J, mass, hg, G, piv)
        rdiag[r] = 1.0 / grr
    for q in range(ntr):
        c = _u(order[_u(nk + nkin + q)])
        gcc = mass[c] * hg - J[c, c]
        if gcc == 0.0 or not math.isfinite(gcc):
            return False
        G[c, c] = gcc
        rdiag[c] = 1.0 / gcc
        for e in range(tptr[q], tptr[q + 1]):
            j = _u(tcol[_u(e)])
            G[c, j] = -J[c, j]
    gr = shaped(fw[:nk * nk], (nk, nk))
    for a in range(nk):
        i = _u(order[a])
        for b in range(nk):
            gr[a, b] = -J[i, _u(order[b])]
        gr[a, a] += mass[i] * hg
    cnt = 0
    for q in range(nkin):
        r = _u(order[_u(nk + q)])
        s = partner[r]
        mptr[q] = cnt
        for a in range(nk):
            jir = J[_u(order[a]), r]
            if jir != 0.0:
                lir = -jir * rdiag[r]
                mrow[_u(cnt)] = a
                mval[_u(cnt)] = lir
                cnt += 1
                if s >= 0:
                    gr[a, _u(posk[_u(s)])] -= lir * G[r, _u(s)]
    mptr[nkin] = cnt
    iw[_DENSE_NOW] = 0
    return lu_factor(gr, piv)


@numba.njit(cache=True, nogil=True)
def reduced_solve(G, iw, fw, piv, b):
    """Solve ``G y = b`` in place from :func:`reduced_factor` (kept block, then kinematic and trailing rows;
    ``G``: as :func:`reduced_factor` left it)."""
    n = G.shape[0]
    if iw[_DENSE_NOW] == 1:
        lu_solve(G, piv, b)
        return
    nk = iw[_NK]
    nkin = iw[_NKIN]
    partner, order, _posk, mptr, mrow, tptr, tcol = _plan_views(iw, n)
    mval = fw[n * n:2 * n * n]
    gr = shaped(fw[:nk * nk], (nk, nk))
    bk = fw[2 * n * n:2 * n * n + nk]
    rdiag = fw[2 * n * n + n:2 * n * n + 2 * n]
    for a in range(nk):
        bk[a] = b[_u(order[a])]
    for q in range(nkin):
        br = b[_u(order[_u(nk + q)])]
        if br != 0.0:
            for c in range(mptr[q], mptr[q + 1]):
                uc = _u(c)
                bk[_u(mrow[uc])] -= mval[uc] * br
    lu_solve(gr, piv, bk)
    for a in range(nk):
        b[_u(order[a])] = bk[a]
    for q in range(nkin):
        r = _u(order[_u(nk + q)])
        s = partner[r]
        v = b[r]
        if s >= 0:
            v -= G[r, _u(s)] * b[_u(s)]
        b[r] = v * rdiag[r]
    for q in range(iw[_NTR]):
        c = _u(order[_u(nk + nkin + q)])
        v = b[c]
        for e in range(tptr[q], tptr[q + 1]):
            j = _u(tcol[_u(e)])
            v -= G[c, j] * b[j]
        b[c] = v * rdiag[c]


@numba.njit(cache=True, nogil=True)
def rodas_next_step(h, err_norm, rejected_before):
    """New step size from the error norm (order-3 estimate; Hairer & Wanner II.4)."""
    if err_norm == 0.0 or not math.isfinite(err_norm):
        factor = MAX_FACTOR if err_norm == 0.0 else MIN_FACTOR
    else:
        factor = SAFETY * err_norm ** (-1.0 / ORDER_EST)
    factor = min(MAX_FACTOR, max(MIN_FACTOR, factor))
    if rejected_before and factor > 1.0:
        factor = 1.0
    return h * factor
