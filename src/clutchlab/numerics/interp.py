"""Compiled table look-up shared by the kernels (curves, maps, input profiles)."""

from __future__ import annotations

import numba


@numba.njit(cache=True, nogil=True, inline="always")
def bracket(grid, x):
    """Segment of a strictly increasing ``grid`` (at least 2 points) holding ``x``.

    Returns ``(lo, w)`` with ``grid[lo] <= x <= grid[lo + 1]`` and the fraction
    ``w = (x - grid[lo]) / (grid[lo + 1] - grid[lo])``; outside the grid the
    end segment is returned with ``w`` clamped to 0 or 1.  Binary search,
    O(log n).
    """
    n = grid.shape[0]
    if x <= grid[0]:
        return 0, 0.0
    if x >= grid[n - 1]:
        return n - 2, 1.0
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if grid[mid] <= x:
            lo = mid
        else:
            hi = mid
    return lo, (x - grid[lo]) / (grid[lo + 1] - grid[lo])
