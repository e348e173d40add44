"""Compiled kernels of the classical Preisach model (forward and inverse).

Memory representation
---------------------
The hysteresis memory is the alternating sequence of dominant input extrema
``M1 > M2 > ...`` and ``m1 < m2 < ...`` stored as one stack
``S = [M1, m1, M2, m2, ...]`` of length ``L`` ([1], Sec. 2.1, Eqs. 2-3).  An
even ``L`` means the input is rising from the last minimum (or from the
virtual minimum ``m0`` below the grid when ``L == 0``); an odd ``L`` means it
is falling from the last maximum ``S[L-1]``.  A new input that rises above a
stored maximum (or falls below a stored minimum) wipes that maximum together
with the minimum after it (the wiping-out property).

``pref[k, p]`` holds, for table ``k``, the sum of the completed pair terms
``F(M_j, m_j) - F(M_j, m_{j-1})`` for ``j <= p`` ([1], Eq. 2, the sum), so the
output costs O(1) per step plus the amortised stack maintenance; the stack is
only ever pushed or popped at its end.

``F(M1, m0)`` with the virtual minimum ``m0`` is taken as zero: this is the
reading of Eqs. 2-3 under which the model reproduces every measured
first-order reversal value ``F(alpha, beta)`` exactly, including a non-zero
force left at the lowest grid input (remanence).

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

import numba
import numpy as np

from ..numerics import FASTMATH


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def locate(grid, x):
    """Index ``i`` of the grid cell ``[grid[i], grid[i+1]]`` containing ``x`` (clamped).

    Starts from the index of a uniform grid with the same ends and walks to
    the right cell: one step for uniform grids, a few for moderately uneven ones.
    """
    n = grid.shape[0]
    if x <= grid[0]:
        return 0
    if x >= grid[n - 1]:
        return n - 2
    i = int((x - grid[0]) * (n - 1) / (grid[n - 1] - grid[0]))
    if i > n - 2:
        i = n - 2
    while i > 0 and grid[i] > x:
        i -= 1
    while i < n - 2 and grid[i + 1] <= x:
        i += 1
    return i


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def forc_value_ij(tables, k, grid, a, i, b, j):
    """``F(a, b)`` of table ``k`` with the cells ``i`` of ``a`` and ``j`` of ``b`` located (``b <= a``).

    ``tables[k, i, j] = (C0, C1, C2, C3)`` of the cell: ``C0 + C1*a + C2*b + C3*a*b``
    in square cells ([1], Eq. 4) and ``C3 = 0`` in the triangular cells on the
    diagonal ([1], Eq. 5); see :func:`cell_coefficients`.  Scalar indexing only
    (no array views, no reference counting in the hot loop).
    """
    if b > a:
        b = a
    if j > i:
        j = i
    return (tables[k, i, j, 0] + tables[k, i, j, 1] * a + tables[k, i, j, 2] * b  # [1], Eqs. 4-5
            + tables[k, i, j, 3] * a * b)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def forc_value(tables, k, grid, a, b):
    """Interpolated first-order reversal value ``F(a, b)`` (``b <= a``) of table ``k``, Eqs. 4-5 of [1]."""
    return forc_value_ij(tables, k, grid, a, locate(grid, a), b, locate(grid, b))


#: calibration tables an airgap's interpolation weighs at most (:func:`gap_weights`): the four around its interval
GAP_TABLES = 4


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _add_quadratic(gaps, s, gap, scale, idx, w, q0):
    """Add ``scale`` times the quadratic Lagrange weights through calibration airgaps ``s, s+1, s+2`` at ``gap``
    into slots ``q0, q0+1, q0+2`` (whose table indices are ``s, s+1, s+2``)."""
    x0 = gaps[s]
    x1 = gaps[s + 1]
    x2 = gaps[s + 2]
    idx[q0] = s
    idx[q0 + 1] = s + 1
    idx[q0 + 2] = s + 2
    w[q0] += scale * (gap - x1) * (gap - x2) / ((x0 - x1) * (x0 - x2))
    w[q0 + 1] += scale * (gap - x0) * (gap - x2) / ((x1 - x0) * (x1 - x2))
    w[q0 + 2] += scale * (gap - x0) * (gap - x1) / ((x2 - x0) * (x2 - x1))


@numba.njit(cache=True, nogil=True, inline="always")
def _weights_read(idx, w):
    """How many airgap weights a reader of ``idx``, ``w`` takes: :data:`GAP_TABLES`, or as many as a shorter array
    holds (:func:`gap_weights` gave such arrays NaN weights: the output is NaN, and nothing is read past their
    end, where a table index would be garbage)."""
    return min(GAP_TABLES, idx.shape[0], w.shape[0])


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def gap_weights(gaps, gap, idx, w):
    """Airgap interpolation weights over the calibration airgaps ``gaps`` ([1], Sec. 2.1: "second-order
    polynomial interpolation" between the seven calibration airgaps), read so that the force is continuous
    with a continuous derivative in the airgap (C1).

    In the interval ``[gaps[j], gaps[j+1]]`` the two quadratic Lagrange interpolants through
    ``j-1, j, j+1`` and ``j, j+1, j+2`` are blended linearly across it, ``(1 - s) Q_left + s Q_right`` with
    ``s = (gap - gaps[j]) / (gaps[j+1] - gaps[j])`` (a cubic through four tables; in the first and last
    interval the one quadratic that exists).  Both interpolants pass through every calibration airgap of
    theirs, so the blend does (each table's own output at its airgap), and at ``gaps[j+1]`` its slope is the
    slope of the quadratic the next interval starts from.  (The quadratic through the *nearest* three, read
    until the twenty-fifth session, jumps where the nearest three change, at the middle of every interval:
    an armature parked there has no force balance, docs/emtc.md.)

    Fills ``idx[0:GAP_TABLES]`` (table indices) and ``w[0:GAP_TABLES]`` (weights; unused slots get weight 0).
    Three tables: the quadratic through them; two: linear interpolation; one: weight 1.  ``gap`` is clamped
    by the caller to the calibration range.  Arrays shorter than ``GAP_TABLES`` (a caller sized for the
    three tables of the reading before: compiled code does not check bounds, and the writes past their end
    corrupted memory) get NaN weights, which every force read with them carries, and nothing is written or
    read past their end (the readers take :func:`_weights_read` weights).
    """
    if idx.shape[0] < GAP_TABLES or w.shape[0] < GAP_TABLES:
        for q in range(idx.shape[0]):
            idx[q] = 0
        for q in range(w.shape[0]):
            w[q] = np.nan
        return
    k = gaps.shape[0]
    for q in range(GAP_TABLES):
        idx[q] = 0
        w[q] = 0.0
    if k == 1:
        w[0] = 1.0
        return
    if k == 2:
        t = (gap - gaps[0]) / (gaps[1] - gaps[0])
        idx[0] = 0
        idx[1] = 1
        w[0] = 1.0 - t
        w[1] = t
        return
    j = locate(gaps, gap)
    left = j >= 1            # the quadratic through j-1, j, j+1 exists
    right = j + 2 <= k - 1   # the one through j, j+1, j+2
    if left and right:
        s = (gap - gaps[j]) / (gaps[j + 1] - gaps[j])
        _add_quadratic(gaps, j - 1, gap, 1.0 - s, idx, w, 0)
        _add_quadratic(gaps, j, gap, s, idx, w, 1)
    elif left:
        _add_quadratic(gaps, j - 1, gap, 1.0, idx, w, 0)
    else:
        _add_quadratic(gaps, j, gap, 1.0, idx, w, 0)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def table_output(tables, k, grid, stack, length, pref, v):
    """Output of table ``k`` for the memory ``stack[:length]`` and current input ``v``.

    Rising (``length`` even): ``sum + F(v, v) - F(v, m_last)`` ([1], Eq. 3);
    falling (``length`` odd): ``sum + F(M_n, v) - F(M_n, m_{n-1})`` ([1], Eq. 2).
    """
    base = pref[k, length // 2]
    iv = locate(grid, v)
    if length % 2 == 0:
        f = base + forc_value_ij(tables, k, grid, v, iv, v, iv)  # [1], Eq. 3
        if length > 0:
            m = stack[length - 1]
            f -= forc_value_ij(tables, k, grid, v, iv, m, locate(grid, m))
        return f
    mx = stack[length - 1]
    im = locate(grid, mx)
    f = base + forc_value_ij(tables, k, grid, mx, im, v, iv)  # [1], Eq. 2
    if length > 1:
        m = stack[length - 2]
        f -= forc_value_ij(tables, k, grid, mx, im, m, locate(grid, m))
    return f


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def weighted_output(tables, grid, stack, length, pref, v, idx, w):
    """Airgap-weighted output of up to three tables for the same current memory.

    The cells of the input and of the stored extrema are located once for all
    tables (they share the current grid).
    """
    iv = locate(grid, v)
    rising = length % 2 == 0
    if rising:
        a = v
        ia = iv
        if length > 0:
            b2 = stack[length - 1]
        else:
            b2 = v
    else:
        a = stack[length - 1]
        ia = locate(grid, a)
        if length > 1:
            b2 = stack[length - 2]
        else:
            b2 = v
    ib2 = locate(grid, b2)
    p = length // 2
    f = 0.0
    for q in range(_weights_read(idx, w)):
        if w[q] != 0.0:
            k = idx[q]
            g = pref[k, p] + forc_value_ij(tables, k, grid, a, ia, v, iv)  # [1], Eq. 3 (rising) or Eq. 2 (falling)
            if length > (0 if rising else 1):
                g -= forc_value_ij(tables, k, grid, a, ia, b2, ib2)
            f += w[q] * g
    return f


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def commit(tables, grid, stack, pref, length, u, v):
    """Move the memory from input ``u`` to input ``v``; return the new length.

    Returns -1 if the stack is full (the caller grows it and repeats the step).
    Turning points are pushed, dominated extrema are wiped out ([1], Sec. 2.1).
    """
    cap = stack.shape[0]
    if v > u:
        if length % 2 == 1:  # was falling: u is a new minimum
            if length >= cap:
                return -1
            stack[length] = u
            length += 1
            p = length // 2
            mx = stack[length - 2]
            im = locate(grid, mx)
            iu = locate(grid, u)
            prev = stack[length - 3] if length >= 3 else 0.0
            ip = locate(grid, prev)
            for k in range(tables.shape[0]):
                term = forc_value_ij(tables, k, grid, mx, im, u, iu)  # [1], Eq. 2, pair term
                if length >= 3:
                    term -= forc_value_ij(tables, k, grid, mx, im, prev, ip)
                pref[k, p] = pref[k, p - 1] + term
        while length >= 2 and v >= stack[length - 2]:  # wiping-out of (M, m)
            length -= 2
    elif v < u:
        if length % 2 == 0:  # was rising: u is a new maximum
            if length >= cap:
                return -1
            stack[length] = u
            length += 1
        while length >= 3 and v <= stack[length - 2]:  # wiping-out of (m, M)
            length -= 2
    return length


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def simulate_kernel(tables, grid, gaps, stack, pref, length, u, inputs, airgaps, out, start):
    """Forward model over ``inputs[start:]``; returns ``(n_done, length, u)``.

    ``airgaps`` has the length of ``inputs`` or length 1 (constant airgap).
    Stops early (``n_done < len``) only when the stack is full.
    """
    idx = np.zeros(GAP_TABLES, dtype=np.int64)
    w = np.zeros(GAP_TABLES)
    n = inputs.shape[0]
    const_gap = airgaps.shape[0] == 1
    single = tables.shape[0] == 1
    if const_gap:
        gap_weights(gaps, airgaps[0], idx, w)
    for i in range(start, n):
        v = inputs[i]
        new_len = commit(tables, grid, stack, pref, length, u, v)
        if new_len < 0:
            return i, length, u
        length = new_len
        u = v
        if const_gap:
            if single:
                out[i] = table_output(tables, 0, grid, stack, length, pref, v)
                continue
        else:
            gap_weights(gaps, airgaps[i], idx, w)
        out[i] = weighted_output(tables, grid, stack, length, pref, v, idx, w)
    return n, length, u


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def peek(tables, grid, stack, pref, length, u, v, idx, w):
    """Output for the next input ``v`` without changing the memory (nothing is written).

    Same result as ``commit`` followed by ``weighted_output``; a turning point
    that ``commit`` would push is handled virtually.
    """
    L = length
    if v > u:
        if L % 2 == 1:
            mx = stack[L - 1]
            if v < mx:  # u becomes a minimum that is not wiped
                im = locate(grid, mx)
                iu = locate(grid, u)
                iv = locate(grid, v)
                prev = stack[L - 2] if L >= 3 else u
                ip = locate(grid, prev)
                f = 0.0
                for q in range(_weights_read(idx, w)):
                    if w[q] != 0.0:
                        k = idx[q]
                        term = forc_value_ij(tables, k, grid, mx, im, u, iu)
                        if L >= 3:
                            term -= forc_value_ij(tables, k, grid, mx, im, prev, ip)
                        f += w[q] * (pref[k, (L - 1) // 2] + term + forc_value_ij(tables, k, grid, v, iv, v, iv)
                                     - forc_value_ij(tables, k, grid, v, iv, u, iu))
                return f
            L -= 1
        while L >= 2 and v >= stack[L - 2]:
            L -= 2
    elif v < u:
        if L % 2 == 0:
            if L < 2 or v > stack[L - 1]:  # u becomes a maximum that is not wiped
                iu = locate(grid, u)
                iv = locate(grid, v)
                prev = stack[L - 1] if L >= 1 else v
                ip = locate(grid, prev)
                f = 0.0
                for q in range(_weights_read(idx, w)):
                    if w[q] != 0.0:
                        k = idx[q]
                        g = pref[k, L // 2] + forc_value_ij(tables, k, grid, u, iu, v, iv)
                        if L >= 1:
                            g -= forc_value_ij(tables, k, grid, u, iu, prev, ip)
                        f += w[q] * g
                return f
            L -= 1
        while L >= 3 and v <= stack[L - 2]:
            L -= 2
    return weighted_output(tables, grid, stack, L, pref, v, idx, w)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def invert_one(tables, grid, stack, pref, length, u, target, idx, w, tol):
    """Input ``v`` whose output from the current memory equals ``target`` ([1], Eqs. 6-7).

    Between consecutive breakpoints (grid points and stored extrema, where the
    wiping changes the branch) the output is linear in the next input, so the
    inverse ``G^-1`` of Eqs. 6-7 is solved exactly on the first segment whose
    end reaches the target.  Returns ``(v, feasible)``; an infeasible target
    (beyond the output reachable from this memory at the grid ends) returns the
    grid end and ``False``.  The memory is not changed (call ``commit``).
    """
    n = grid.shape[0]
    f0 = weighted_output(tables, grid, stack, length, pref, u, idx, w)
    if abs(target - f0) <= tol:
        return u, True
    x0 = u
    if target > f0:
        while True:
            # next breakpoint above x0: a grid point or a stored maximum
            b = grid[n - 1]
            j = locate(grid, x0)
            for jj in range(j, n):
                if grid[jj] > x0:
                    b = grid[jj]
                    break
            for q in range(0, length, 2):
                if stack[q] > x0 and stack[q] < b:
                    b = stack[q]
            if length % 2 == 1 and stack[length - 1] > x0 and stack[length - 1] < b:
                b = stack[length - 1]
            fb = peek(tables, grid, stack, pref, length, u, b, idx, w)
            if fb >= target - tol:
                if fb - f0 > 0.0:
                    v = x0 + (target - f0) * (b - x0) / (fb - f0)  # [1], Eq. 7
                else:
                    v = b
                return min(max(v, x0), b), True
            if b >= grid[n - 1]:
                return grid[n - 1], False
            x0 = b
            f0 = fb
    else:
        while True:
            b = grid[0]
            j = locate(grid, x0)
            for jj in range(j + 1, -1, -1):
                if jj < n and grid[jj] < x0:
                    b = grid[jj]
                    break
            for q in range(1, length, 2):
                if stack[q] < x0 and stack[q] > b:
                    b = stack[q]
            fb = peek(tables, grid, stack, pref, length, u, b, idx, w)
            if fb <= target + tol:
                if f0 - fb > 0.0:
                    v = x0 - (f0 - target) * (x0 - b) / (f0 - fb)  # [1], Eq. 6
                else:
                    v = b
                return min(max(v, b), x0), True
            if b <= grid[0]:
                return grid[0], False
            x0 = b
            f0 = fb


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def invert_kernel(tables, grid, gaps, stack, pref, length, u, targets, airgaps, out_u, out_f, feasible,
                  lo_reach, hi_reach, tol, start):
    """Inverse model over ``targets[start:]`` (open-loop compensation, [1], Fig. 7).

    Returns ``(n_done, length, u)``; stops early only when the stack is full.
    ``lo_reach``/``hi_reach`` receive the output reachable at the grid ends
    from the memory before each step.
    """
    idx = np.zeros(GAP_TABLES, dtype=np.int64)
    w = np.zeros(GAP_TABLES)
    n = targets.shape[0]
    const_gap = airgaps.shape[0] == 1
    if const_gap:
        gap_weights(gaps, airgaps[0], idx, w)
    for i in range(start, n):
        if not const_gap:
            gap_weights(gaps, airgaps[i], idx, w)
        if length + 2 > stack.shape[0]:
            return i, length, u
        lo_reach[i] = peek(tables, grid, stack, pref, length, u, grid[0], idx, w)
        hi_reach[i] = peek(tables, grid, stack, pref, length, u, grid[grid.shape[0] - 1], idx, w)
        v, ok = invert_one(tables, grid, stack, pref, length, u, targets[i], idx, w, tol)
        length = commit(tables, grid, stack, pref, length, u, v)
        u = v
        out_u[i] = v
        feasible[i] = ok
        out_f[i] = weighted_output(tables, grid, stack, length, pref, v, idx, w)
    return n, length, u


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def rebuild_prefix(tables, grid, stack, length, pref):
    """Recompute the pair sums ``pref`` for a given memory stack."""
    for k in range(tables.shape[0]):
        pref[k, 0] = 0.0
        for p in range(1, length // 2 + 1):
            mx = stack[2 * p - 2]
            term = forc_value(tables, k, grid, mx, stack[2 * p - 1])
            if p >= 2:
                term -= forc_value(tables, k, grid, mx, stack[2 * p - 3])
            pref[k, p] = pref[k, p - 1] + term


def cell_coefficients(grid, table):
    """Per-cell coefficients ``(C0, C1, C2, C3)`` of the interpolation of [1], Eqs. 4-5.

    Square cells (alpha cell ``i`` > beta cell ``j``): the bilinear interpolant
    through the four vertex values; triangular cells (``i == j``): the plane
    through ``(u_i, u_i)``, ``(u_i+1, u_i+1)``, ``(u_i+1, u_i)``.  Returns an
    array of shape ``(N, N, 4)`` (entries with ``j > i`` unused).
    """
    g = np.asarray(grid, dtype=float)
    F = np.asarray(table, dtype=float)
    n = g.size - 1
    out = np.zeros((n, n, 4))
    i, j = np.tril_indices(n, -1)
    ai, bj = g[i], g[j]
    ha, hb = g[i + 1] - g[i], g[j + 1] - g[j]
    A = F[i, j]
    B = F[i + 1, j] - F[i, j]
    C = F[i, j + 1] - F[i, j]
    D = F[i + 1, j + 1] - F[i + 1, j] - F[i, j + 1] + F[i, j]
    hh = ha * hb
    out[i, j, 3] = D / hh
    out[i, j, 1] = B / ha - D * bj / hh
    out[i, j, 2] = C / hb - D * ai / hh
    out[i, j, 0] = A - B * ai / ha - C * bj / hb + D * ai * bj / hh
    k = np.arange(n)
    h = g[k + 1] - g[k]
    fa, fb, fc = F[k, k], F[k + 1, k + 1], F[k + 1, k]
    c1 = (fc - fa) / h
    c2 = (fb - fc) / h
    out[k, k, 1] = c1
    out[k, k, 2] = c2
    out[k, k, 0] = fa - (c1 + c2) * g[k]
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def combine_tables(tables, idx, w, out):
    """``out[0] = sum_q w[q] * tables[idx[q]]``: one coefficient table for a fixed airgap.

    The output is linear in the tables for a given memory, so the airgap
    interpolation can be applied to the coefficients once per airgap change.
    """
    n = tables.shape[1]
    nw = _weights_read(idx, w)
    for i in range(n):
        for j in range(i + 1):
            for c in range(4):
                acc = 0.0
                for q in range(nw):
                    if w[q] != 0.0:
                        acc += w[q] * tables[idx[q], i, j, c]
                out[0, i, j, c] = acc


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _wpref(pref, p, idx, w):
    acc = 0.0
    for q in range(_weights_read(idx, w)):
        if w[q] != 0.0:
            acc += w[q] * pref[idx[q], p]
    return acc


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def peek_combined(comb, grid, stack, pref, length, u, v, idx, w):
    """:func:`peek` with the airgap-combined table ``comb`` (from :func:`combine_tables`)."""
    L = length
    if v > u:
        if L % 2 == 1:
            mx = stack[L - 1]
            if v < mx:  # u becomes a minimum that is not wiped
                im = locate(grid, mx)
                iu = locate(grid, u)
                iv = locate(grid, v)
                term = forc_value_ij(comb, 0, grid, mx, im, u, iu)
                if L >= 3:
                    prev = stack[L - 2]
                    term -= forc_value_ij(comb, 0, grid, mx, im, prev, locate(grid, prev))
                return (_wpref(pref, (L - 1) // 2, idx, w) + term + forc_value_ij(comb, 0, grid, v, iv, v, iv)
                        - forc_value_ij(comb, 0, grid, v, iv, u, iu))
            L -= 1
        while L >= 2 and v >= stack[L - 2]:
            L -= 2
    elif v < u:
        if L % 2 == 0:
            if L < 2 or v > stack[L - 1]:  # u becomes a maximum that is not wiped
                iu = locate(grid, u)
                iv = locate(grid, v)
                g = _wpref(pref, L // 2, idx, w) + forc_value_ij(comb, 0, grid, u, iu, v, iv)
                if L >= 1:
                    prev = stack[L - 1]
                    g -= forc_value_ij(comb, 0, grid, u, iu, prev, locate(grid, prev))
                return g
            L -= 1
        while L >= 3 and v <= stack[L - 2]:
            L -= 2
    # memory after wiping, output of Eqs. 2-3 with the combined table
    base = _wpref(pref, L // 2, idx, w)
    return base + table_output(comb, 0, grid, stack, L, pref, v) - pref[0, L // 2]


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def peek_segment(comb, grid, stack, pref, length, u, v, idx, w, seg):
    """:func:`peek_combined` as a quadratic in the next input on the stretch of inputs around ``v``.

    For a given memory ``stack[:length]`` (last input ``u``) the output for the next input ``v`` is, on each
    stretch of inputs where the same branch of Eqs. 2-3 holds (no further wiping, the input in the same grid
    cell), a quadratic ``a0 + a1 v + a2 v**2``: the interpolation of Eqs. 4-5 is bilinear in a cell and the
    input enters one or both of its arguments.  Writes ``seg[0:6] = (lo, hi, a0, a1, a2, kind)`` for the
    stretch whose open interior ``lo < v < hi`` holds ``v`` and returns the quadratic at ``v``: any input
    strictly inside the same stretch gets the same polynomial, so a caller may keep ``seg`` for later inputs
    while the memory and the table stay (inputs on a stretch's ends, and ``v == u``, are evaluated afresh:
    ``v == u`` gives the output of the memory as it is, Eq. 3 for an even length, Eq. 2 for an odd one, and
    an empty ``seg``, ``lo = hi = v``).  Equal to :func:`peek_combined` to rounding.

    ``kind`` says whether the polynomial depends on the last input ``u``: +1 for a rising stretch that does
    not (the output of Eq. 3 with the stored extrema after wiping: ``u`` only bounds it, so it holds for
    ``max(lo, u') < v < hi`` for any later last input ``u'`` reached without changing the stack), -1 for a
    falling one that does not (Eq. 2: ``lo < v < min(hi, u')``), 0 where ``u`` becomes a new extremum
    (the polynomial holds for this ``u`` only).
    """
    L = length
    iv = locate(grid, v)
    lo = grid[iv]
    hi = grid[iv + 1]
    if v > u or (v == u and L % 2 == 0):
        a = u  # the second argument of the first-order reversal value subtracted: u (a new minimum) or m_last
        const = 0.0
        if L % 2 == 1 and v < stack[L - 1]:
            # u becomes a minimum that is not wiped ([1], Eq. 3 with the pair (M_last, u) completed)
            mx = stack[L - 1]
            im = locate(grid, mx)
            iu = locate(grid, u)
            const = _wpref(pref, (L - 1) // 2, idx, w) + forc_value_ij(comb, 0, grid, mx, im, u, iu)
            if L >= 3:
                prev = stack[L - 2]
                const -= forc_value_ij(comb, 0, grid, mx, im, prev, locate(grid, prev))
            hi = min(hi, mx)
            lo = max(lo, u)
            ib = iu
            sub = True
            kind = 0.0
        else:
            if L % 2 == 1:
                L -= 1
            while L >= 2 and v >= stack[L - 2]:  # wiping-out of (M, m)
                L -= 2
            if L < length:
                lo = max(lo, stack[L])  # the largest maximum wiped (or the maximum the input rose past)
            lo = max(lo, u)
            if L >= 2:
                hi = min(hi, stack[L - 2])  # the next maximum to wipe
            const = _wpref(pref, L // 2, idx, w)  # [1], Eq. 3
            ib = 0
            kind = 1.0
            sub = L > 0
            if sub:
                a = stack[L - 1]
                ib = locate(grid, a)
        # F(v, v) on the diagonal cell of v ([1], Eqs. 4-5: C0 + (C1 + C2) v + C3 v^2), minus F(v, a) on the
        # cell (v, a) (none with the virtual minimum: L == 0, rising)
        a0 = const + comb[0, iv, iv, 0]
        a1 = comb[0, iv, iv, 1] + comb[0, iv, iv, 2]
        a2 = comb[0, iv, iv, 3]
        if sub:
            jb = min(ib, iv)
            a0 -= comb[0, iv, jb, 0] + comb[0, iv, jb, 2] * a
            a1 -= comb[0, iv, jb, 1] + comb[0, iv, jb, 3] * a
    else:
        if L % 2 == 0 and (L < 2 or v > stack[L - 1]):
            # u becomes a maximum that is not wiped ([1], Eq. 2 with M_n = u)
            top = u
            const = _wpref(pref, L // 2, idx, w)
            if L >= 1:
                prev = stack[L - 1]
                const -= forc_value_ij(comb, 0, grid, u, locate(grid, u), prev, locate(grid, prev))
                lo = max(lo, prev)
            hi = min(hi, u)
            kind = 0.0
        else:
            if L % 2 == 0:
                L -= 1
            while L >= 3 and v <= stack[L - 2]:  # wiping-out of (m, M)
                L -= 2
            if L < length:
                hi = min(hi, stack[L])  # the smallest minimum wiped (or the minimum the input fell past)
            hi = min(hi, u)
            if L >= 3:
                lo = max(lo, stack[L - 2])  # the next minimum to wipe
            top = stack[L - 1]
            const = _wpref(pref, L // 2, idx, w)  # [1], Eq. 2
            kind = -1.0
            if L > 1:
                m = stack[L - 2]
                const -= forc_value_ij(comb, 0, grid, top, locate(grid, top), m, locate(grid, m))
        # F(top, v) on the cell (top, v): linear in v
        it = locate(grid, top)
        jv = min(iv, it)
        a0 = const + comb[0, it, jv, 0] + comb[0, it, jv, 1] * top
        a1 = comb[0, it, jv, 2] + comb[0, it, jv, 3] * top
        a2 = 0.0
    if v == u:  # the memory as it is: evaluated afresh every time (no stretch)
        lo = v
        hi = v
        kind = 0.0
    seg[0] = lo
    seg[1] = hi
    seg[2] = a0
    seg[3] = a1
    seg[4] = a2
    seg[5] = kind
    return a0 + v * (a1 + v * a2)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def invert_combined(comb, grid, stack, pref, length, u, target, idx, w, tol, seg, version):
    """:func:`invert_one` for an airgap-combined table (:func:`combine_tables`), keeping the rising stretch.

    While the memory only rises from an even-length stack (no turning point pushed, none wiped: the usual
    course of a slowly growing command), the output for inputs above ``u`` is one line on a stretch of
    :func:`peek_segment` that does not depend on ``u`` itself ([1], Eq. 3 with the stored extrema fixed,
    ``kind`` +1), so the inverse of Eq. 7 is solved on it without locating anything.  ``seg`` (8 values:
    :func:`peek_segment`'s six, then ``version``, the count of the memory's changes it was built for) is kept
    by the caller between calls; the caller counts a change whenever :func:`commit` changes the length (the
    stack changes only then).  Returns ``(v, feasible)`` as :func:`invert_one`, to rounding, or ``(NaN,
    False)`` in any other case (falling, a target beyond the stretch): the caller then calls
    :func:`invert_one` (not called from here: every compiled function's code is linked with its callees).
    """
    n = grid.shape[0]
    if u < grid[n - 1]:
        if not (seg[6] == version and seg[5] == 1.0 and seg[0] <= u < seg[1]):
            iu = locate(grid, u)
            top = grid[iu + 1]
            if length % 2 == 1:
                top = -1.0  # (falling from the last maximum: u would become a new minimum, kind 0)
            elif length >= 2 and stack[length - 2] < top:
                top = stack[length - 2]  # the next maximum to wipe
            seg[6] = -1.0
            if top > u:
                peek_segment(comb, grid, stack, pref, length, u, 0.5 * (u + top), idx, w, seg)
                seg[6] = version
        if seg[6] == version and seg[5] == 1.0 and seg[0] <= u < seg[1] and seg[4] == 0.0 and seg[3] > 0.0:
            a0 = seg[2]
            a1 = seg[3]
            f0 = a0 + a1 * u  # the output now ([1], Eq. 3 at v = u)
            if abs(target - f0) <= tol:
                return u, True
            if target > f0:
                v = (target - a0) / a1  # [1], Eq. 7 on the stretch
                if v < seg[1]:
                    return max(v, u), True
    return np.nan, False
