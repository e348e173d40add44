"""Identification of the Preisach FORC table from recorded current/force traces.

The experiment of [1], Sec. 2.1 and Figs. 2-4: starting from the lowest
current, the current rises to a reversal value alpha on the grid and falls
back to the lowest value, for every alpha of the grid (a first-order reversal
curve each), optionally repeated and at several airgaps.  This module cuts a
recorded trace into rising and falling segments, reads the force at every grid
current on each segment by a local straight-line fit, and averages repeated
readings into the table ``F(alpha, beta)`` with scatter statistics.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import pandas as pd

from ..errors import DataError, IdentificationError
from .preisach import Preisach

__all__ = ["forc_input", "identify_forc", "identify_forc_family", "ForcIdentification"]


def forc_input(grid, step=0.02, dwell=2):
    """Current sequence of a FORC experiment on ``grid`` ([1], Figs. 2-4).

    For every reversal value ``alpha = grid[1:]``: rise from ``grid[0]`` to
    alpha and fall back to ``grid[0]`` in increments of about ``step`` [A],
    holding ``dwell`` samples at each end.

    Returns
    -------
    numpy.ndarray
        Current samples [A].
    """
    grid = np.asarray(grid, dtype=float)
    parts = [np.full(dwell, grid[0])]
    for a in grid[1:]:
        n = max(2, int(np.ceil((a - grid[0]) / step)) + 1)
        up = np.linspace(grid[0], a, n)
        parts += [up[1:], np.full(dwell, a), up[::-1][1:], np.full(dwell, grid[0])]
    return np.concatenate(parts)


@numba.njit(cache=True)
def _turning_points(u, threshold):
    """Indices of reversal points: the input left its running extremum by more than ``threshold``."""
    n = u.shape[0]
    out = np.empty(n, dtype=np.int64)
    kinds = np.empty(n, dtype=np.int64)  # +1 maximum, -1 minimum
    m = 0
    direction = 1
    ext_i = 0
    for i in range(1, n):
        if direction > 0:
            if u[i] > u[ext_i]:
                ext_i = i
            elif u[ext_i] - u[i] > threshold:
                out[m] = ext_i
                kinds[m] = 1
                m += 1
                direction = -1
                ext_i = i
        else:
            if u[i] < u[ext_i]:
                ext_i = i
            elif u[i] - u[ext_i] > threshold:
                out[m] = ext_i
                kinds[m] = -1
                m += 1
                direction = 1
                ext_i = i
    out[m] = ext_i
    kinds[m] = direction
    return out[: m + 1], kinds[: m + 1]


def _line_fit(c, f, x):
    """Intercept at ``x`` and residual RMS of a least-squares line through (c, f)."""
    A = np.column_stack([np.ones(c.size), c - x])
    coef, *_ = np.linalg.lstsq(A, f, rcond=None)
    res = f - A @ coef
    return float(coef[0]), float(np.sqrt(np.mean(res**2)))


def _local_value(cur, force, x, window):
    """Force at current ``x`` read from samples within ``window``; (value, rms, n).

    A straight line is fitted on each side of ``x`` and the two intercepts are
    averaged, so a kink of the branch exactly at ``x`` (a grid point of a
    piecewise-linear characteristic) does not bias the reading.
    """
    sel = np.abs(cur - x) <= window
    n = int(sel.sum())
    if n == 0:
        return np.nan, np.nan, 0
    c, f = cur[sel], force[sel]
    vals, rmss = [], []
    for side in (c <= x, c >= x):
        cs, fs = c[side], f[side]
        if cs.size >= 2 and np.ptp(cs) > 0.2 * window:
            v, r = _line_fit(cs, fs, x)
            vals.append(v)
            rmss.append(r)
    if vals:
        return float(np.mean(vals)), float(np.mean(rmss)), n
    return float(f.mean()), float(f.std()), n


@dataclass
class ForcIdentification:
    """Result of :func:`identify_forc`.

    Attributes
    ----------
    model : Preisach
        The identified model.
    table : pandas.DataFrame
        One row per grid point: ``alpha``, ``beta`` [A], ``value`` [N] (mean of
        the readings), ``std`` [N] (scatter between repeated readings, NaN if
        read once), ``n_curves`` (readings), ``n_samples`` (samples used),
        ``rms_residual`` [N] (mean residual of the local line fits).
    n_reversals : int
        Number of first-order reversal curves found in the trace.
    """

    model: Preisach
    table: pd.DataFrame
    n_reversals: int

    def report(self) -> str:
        """Summary of the identification and its scatter."""
        t = self.table
        std = t["std"].dropna()
        lines = [
            f"Preisach FORC identification: {len(t)} grid points from {self.n_reversals} reversal curves",
            f"  grid {self.model.grid[0]:g} .. {self.model.grid[-1]:g} A ({self.model.grid.size} values)",
            f"  readings per point: min {int(t['n_curves'].min())}, median {float(t['n_curves'].median()):g}",
            f"  local-fit residual (RMS): median {float(t['rms_residual'].median()):.4g} N, "
            f"max {float(t['rms_residual'].max()):.4g} N",
        ]
        if len(std):
            lines.append(f"  scatter between readings (std): median {float(std.median()):.4g} N, max {float(std.max()):.4g} N")
        return "\n".join(lines)


def identify_forc(current, force, grid=None, *, window=None, name="FORC record") -> ForcIdentification:
    """Identify the FORC table of a Preisach model from a recorded trace ([1], Sec. 2.1, Figs. 2-4).

    Parameters
    ----------
    current : array_like
        Coil current samples [A]: a sequence of first-order reversal curves,
        each rising from the lowest current to a reversal value and falling back.
    force : array_like
        Measured force at each sample [N].
    grid : array_like, optional
        Current grid [A]; default: the lowest current and the reversal values found.
    window : float, optional
        Half-width [A] of the current window used to read the force at a grid
        value (default: 0.2 of the smallest grid step).
    name : str
        Name of the record in error messages.

    Returns
    -------
    ForcIdentification

    Raises
    ------
    DataError
        Non-finite or mismatched samples.
    IdentificationError
        A reversal value off the grid, or a grid point without readings.

    Notes
    -----
    ``F(alpha, beta)`` is read on the falling segment after the reversal at
    alpha; ``F(alpha, alpha)`` also on every rising segment that starts at the
    lowest current (the limiting ascending branch).  Repeated readings are
    averaged; their standard deviation is the scatter statistic.
    """
    cur = np.asarray(current, dtype=float).ravel()
    frc = np.asarray(force, dtype=float).ravel()
    if cur.size != frc.size:
        raise DataError(f"{name}: current and force have different lengths ({cur.size}, {frc.size})")
    if cur.size < 10:
        raise DataError(f"{name}: too few samples ({cur.size})")
    for label, arr in (("current", cur), ("force", frc)):
        bad = ~np.isfinite(arr)
        if bad.any():
            raise DataError(f"{name}: column {label!r} has a non-finite value at row {int(np.flatnonzero(bad)[0])}")
    span = float(np.ptp(cur))
    if span <= 0:
        raise IdentificationError(f"{name}: the current does not vary")
    idx, kinds = _turning_points(cur, 0.02 * span)
    maxima = idx[kinds == 1]
    u_low = float(cur.min())
    if grid is None:
        peaks = np.sort(cur[maxima])
        if peaks.size == 0:
            raise IdentificationError(f"{name}: no reversal found in the current trace")
        tol = 0.01 * span
        clusters = [[peaks[0]]]
        for p in peaks[1:]:
            if p - clusters[-1][-1] <= tol:
                clusters[-1].append(p)
            else:
                clusters.append([p])
        grid = np.array([u_low] + [float(np.mean(c)) for c in clusters])
    grid = np.asarray(grid, dtype=float)
    if grid.ndim != 1:
        raise DataError(f"{name}: grid must be a 1-D list of currents [A], got an array of shape {grid.shape}")
    if grid.size < 2 or np.any(np.diff(grid) <= 0):
        raise DataError(f"{name}: grid must be strictly increasing with at least two values")
    h = float(np.min(np.diff(grid)))
    window = 0.2 * h if window is None else float(window)
    snap = 0.25 * h
    n = grid.size
    readings = [[[] for _ in range(n)] for _ in range(n)]
    rms = [[[] for _ in range(n)] for _ in range(n)]
    counts = np.zeros((n, n), dtype=int)
    n_rev = 0
    bounds = np.concatenate([[0], idx, [cur.size - 1]])
    for s in range(bounds.size - 1):
        a, b = int(bounds[s]), int(bounds[s + 1])
        if b - a < 2:
            continue
        seg_c, seg_f = cur[a: b + 1], frc[a: b + 1]
        if np.ptp(seg_c) < snap:
            continue
        rising = seg_c[-1] > seg_c[0]
        if not rising:
            top = seg_c[0]
            i = int(np.argmin(np.abs(grid - top)))
            if abs(grid[i] - top) > snap:
                raise IdentificationError(
                    f"{name}: reversal at {top:.4g} A (row {a}) is not on the grid (nearest {grid[i]:g} A)")
            n_rev += 1
            for j in range(i + 1):
                val, r, m = _local_value(seg_c, seg_f, grid[j], window)
                if m:
                    readings[i][j].append(val)
                    rms[i][j].append(r)
                    counts[i, j] += m
        elif seg_c[0] <= grid[0] + snap:
            for i in range(n):
                if grid[i] <= seg_c[-1] + window:
                    val, r, m = _local_value(seg_c, seg_f, grid[i], window)
                    if m:
                        readings[i][i].append(val)
                        rms[i][i].append(r)
                        counts[i, i] += m
    rows = []
    table = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1):
            vals = readings[i][j]
            if not vals:
                raise IdentificationError(
                    f"{name}: no reading for F(alpha={grid[i]:g} A, beta={grid[j]:g} A); "
                    "the trace must contain a reversal curve at every grid value")
            v = np.asarray(vals)
            table[i, j] = v.mean()
            rows.append((grid[i], grid[j], v.mean(), v.std(ddof=1) if v.size > 1 else np.nan, v.size,
                         int(counts[i, j]), float(np.nanmean(rms[i][j]))))
    frame = pd.DataFrame(rows, columns=["alpha", "beta", "value", "std", "n_curves", "n_samples", "rms_residual"])
    return ForcIdentification(Preisach(grid, table), frame, n_rev)


def identify_forc_family(frame: pd.DataFrame, *, grid=None, window=None, name="FORC record"):
    """Identify one table per calibration airgap and combine them ([1], Sec. 2.1).

    Parameters
    ----------
    frame : pandas.DataFrame
        Columns ``current`` [A], ``force`` [N] and ``airgap`` [m] (constant
        within each experiment); without ``airgap`` a single model is identified.
    grid : array_like, optional
        Current grid [A] of the tables (default: from the turning points of the record).
    window : int, optional
        Smoothing window passed to :func:`identify_forc`.
    name : str
        Label of the record in messages.

    Returns
    -------
    (Preisach, list of (airgap, ForcIdentification))
    """
    if "airgap" not in frame.columns:
        res = identify_forc(frame["current"], frame["force"], grid, window=window, name=name)
        return res.model, [(None, res)]
    gaps = frame["airgap"].to_numpy(float)
    keys = np.unique(np.round(gaps, 9))
    results = []
    for g in keys:
        sel = np.abs(gaps - g) <= 1e-9
        sub = frame.loc[sel]
        res = identify_forc(sub["current"], sub["force"], grid, window=window, name=f"{name} (airgap {g:g} m)")
        if grid is None:
            grid = res.model.grid
        results.append((float(g), res))
    if len(results) == 1:
        return results[0][1].model, results
    model = Preisach.family([r.model for _, r in results], [g for g, _ in results])
    return model, results
