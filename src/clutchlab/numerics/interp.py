"""Compiled table look-up shared by the kernels (curves, maps, input profiles)."""

from __future__ import annotations

import numba
from numba import uintp as _u


@numba.njit(cache=True, nogil=True, inline="always")
def bracket(grid, x):
    """Segment of a strictly increasing ``grid`` (at least 2 points) holding ``x``.

    Returns ``(lo, w)`` with ``grid[lo] <= x <= grid[lo + 1]`` and the fraction
    ``w = (x - grid[lo]) / (grid[lo + 1] - grid[lo])``; outside the grid the
    end segment is returned with ``w`` clamped to 0 or 1.  Binary search,
    O(log n).
    """
    return bracket_range(grid, 0, grid.shape[0], x)


@numba.njit(cache=True, nogil=True, inline="always")
def bracket_range(grid, start, stop, x):
    """:func:`bracket` on the part ``grid[start:stop]`` of a packed array (at least 2 points), without a slice.

    Returns ``(lo, w)`` with ``lo`` an index into ``grid`` itself (``start <= lo < stop - 1``).  A slice
    builds a new array structure at every call (the E-clutch's curve look-ups, several per right-hand side).
    ``start`` and ``stop`` must be non-negative (indices are read as unsigned: no wrap-around test).
    """
    if x <= grid[_u(start)]:
        return start, 0.0
    if x >= grid[_u(stop - 1)]:
        return stop - 2, 1.0
    lo = segment_range(grid, start, stop, x)
    return lo, (x - grid[_u(lo)]) / (grid[_u(lo + 1)] - grid[_u(lo)])


@numba.njit(cache=True, nogil=True, inline="always")
def segment_range(grid, start, stop, x):
    """Segment of ``grid[start:stop]`` holding ``x`` inside it: ``lo`` with ``grid[lo] <= x < grid[lo + 1]``.

    The binary search of :func:`bracket_range` without the fraction (the caller computes it with its own
    reciprocal of the segment length); ``grid[start] < x < grid[stop - 1]`` is the caller's to check.
    """
    lo = start
    hi = stop - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if grid[_u(mid)] <= x:
            lo = mid
        else:
            hi = mid
    return lo


@numba.njit(cache=True, nogil=True, _nrt=False)
def grid_waypoint(data, start, n, s):
    """The waypoint function [-] of a law read on the grid ``data[start:start + n]`` (increasing) at ``s``, linear
    between its nodes and held beyond both ends, so that its slope jumps at every node: zero at each node and nowhere
    else, of alternating sign from one piece to the next (as a torque converter's corners,
    :func:`clutchlab.driveline.kernel.converter_piece`).  Piece ``k`` between nodes ``lo`` and ``hi``:
    ``(-1)^k (s - lo)(hi - s)/(hi - lo)^2``; before the first node ``(c0 - s)/(c0 - s + w)``, beyond the last
    ``(-1)^n (s - c)/(s - c + w)``, ``w`` the grid's width.  1 for a grid of one node (a law constant in ``s``).  A waypoint switching function (direction 4): a step ends just past each node, so that the
    error of a law read on a grid (a friction table or map, an engine map) follows the tolerance there."""
    if n < 2:
        return 1.0
    first = data[start]
    last = data[start + n - 1]
    width = last - first
    k = 0
    while k < n and data[start + k] <= s:
        k += 1
    if k == 0:
        v = (first - s) / ((first - s) + width)
    elif k == n:
        v = (s - last) / ((s - last) + width)
    else:
        lo = data[start + k - 1]
        hi = data[start + k]
        v = (s - lo) * (hi - s) / ((hi - lo) * (hi - lo))
    return v if k % 2 == 0 else -v
