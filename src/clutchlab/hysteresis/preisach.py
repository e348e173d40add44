"""Classical Preisach model from first-order reversal (FORC) values.

The model of the EMTC magnet force as a function of the coil current ([1],
Sec. 2): relays with switching-up input alpha and switching-down input beta
(beta <= alpha) on a triangle; the weights are not needed explicitly because
the output is written with the measured FORC values ``F(alpha, beta)`` (the
output after the input rises from the lowest grid value to alpha and falls to
beta), Eqs. 2-3, interpolated between grid points by Eqs. 4-5.  The inverse
(Eqs. 6-7) gives the current that produces a desired force (open-loop
hysteresis compensation, Fig. 7).  One table per calibration airgap, with
second-order polynomial interpolation between them ([1], Sec. 2.1): the two
quadratics of an interval blended linearly across it, continuous with its
slope (:func:`~clutchlab.hysteresis.kernels.gap_weights`); the hysteresis
memory is in the current only.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
.. [2] I. D. Mayergoyz, Mathematical Models of Hysteresis, Springer 1991,
   Ch. 1 (wiping-out, congruency, Everett function).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .._limits import as_numbers
from ..errors import DataError, ParameterError
from ..params.base import PLAUSIBLE_LIMITS

#: The largest FORC value [N] a model may hold: the plausibility limit of a force (``params.base``)
FORCE_LIMIT_N = PLAUSIBLE_LIMITS["N"][0]
#: The largest air gap [m]: an electromagnet's gap is millimetres; a metre is a slip of unit
GAP_LIMIT_M = 1.0
from . import kernels as K

__all__ = ["Preisach", "PreisachState", "InverseResult", "forc_table_from_masses"]

_GRID_RTOL = 1e-9


@dataclass(frozen=True)
class PreisachState:
    """Hysteresis memory: alternating dominant extrema and the present input.

    Attributes
    ----------
    extrema : numpy.ndarray
        ``[M1, m1, M2, m2, ...]`` [A]; odd length means the input is falling.
    input : float
        Present input [A].
    """

    extrema: np.ndarray
    input: float


@dataclass
class InverseResult:
    """Result of :meth:`Preisach.invert`.

    Attributes
    ----------
    target : numpy.ndarray
        Requested output [N].
    input : numpy.ndarray
        Input sequence found [A].
    output : numpy.ndarray
        Output the model produces for ``input`` [N] (equal to ``target`` where feasible).
    feasible : numpy.ndarray of bool
        False where the target lies outside the output reachable from the memory at that step.
    reachable_low, reachable_high : numpy.ndarray
        Output reachable at the lowest / highest grid input from the memory before each step [N].
    """

    target: np.ndarray
    input: np.ndarray
    output: np.ndarray
    feasible: np.ndarray
    reachable_low: np.ndarray
    reachable_high: np.ndarray

    @property
    def all_feasible(self) -> bool:
        """True if every target sample was reproduced."""
        return bool(self.feasible.all())

    def report(self) -> str:
        """Human-readable summary naming the infeasible samples."""
        n = self.target.size
        bad = np.flatnonzero(~self.feasible)
        lines = [f"inverse Preisach: {n - bad.size} of {n} target samples feasible"]
        if bad.size:
            err = np.abs(self.output - self.target)
            lines.append(f"max deviation where infeasible: {err[bad].max():.6g}")
            for i in bad[:10]:
                lines.append(
                    f"  sample {i}: target {self.target[i]:.6g} outside the reachable range "
                    f"[{self.reachable_low[i]:.6g}, {self.reachable_high[i]:.6g}] -> output {self.output[i]:.6g}"
                )
            if bad.size > 10:
                lines.append(f"  ... and {bad.size - 10} more")
        return "\n".join(lines)

    def to_dataframe(self) -> pd.DataFrame:
        """Columns ``target``, ``current``, ``force``, ``feasible``, ``reachable_low``, ``reachable_high``."""
        return pd.DataFrame({"target": self.target, "current": self.input, "force": self.output,
                             "feasible": self.feasible, "reachable_low": self.reachable_low,
                             "reachable_high": self.reachable_high})


def _as_1d(name, values):
    arr = as_numbers(values, name, DataError)
    if arr.ndim > 1:  # never flattened silently: a table passed as a grid is a mistake
        raise DataError(f"{name}: expected a 1-D list of values, got an array of shape {arr.shape}")
    arr = arr.ravel()
    if arr.size == 0:
        raise DataError(f"{name}: empty")
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise DataError(f"{name}[{i}] = {float(arr[i])!r}: not finite")
    return arr


def forc_table_from_masses(grid, cell_mass, line_mass, offset=0.0):
    """FORC table ``F(u_i, u_j)`` of a Preisach model with given relay masses.

    Parameters
    ----------
    grid : array_like
        Input grid [A] (N+1 values).
    cell_mass : array_like, shape (N, N)
        Mass of relays in square cell ``(p, q)``, ``p > q`` (alpha in cell p,
        beta in cell q) [N]; entries with ``p <= q`` are ignored. Must be >= 0.
    line_mass : array_like, shape (N,)
        Mass of non-hysteretic relays (alpha = beta) in diagonal cell p [N].
    offset : float
        Output with every relay off [N].

    Returns
    -------
    numpy.ndarray, shape (N+1, N+1)
        ``F[i, j] = offset + P(u_i, u_0) - P(u_i, u_j)`` with ``P(a, b)`` the
        mass of the triangle ``b <= beta <= alpha <= a`` ([2], Ch. 1).
    """
    grid = np.asarray(grid, float)
    n = grid.size
    M = np.tril(np.asarray(cell_mass, float), -1)
    d = np.asarray(line_mass, float)
    C = np.concatenate([np.zeros((n - 1, 1)), np.cumsum(M, axis=1)], axis=1)  # C[p, k] = sum_{q<k} M[p, q]
    P = np.zeros((n, n))
    for j in range(n):
        p = np.arange(j, n - 1)
        row = C[p, p] - C[p, j] + d[p]  # mass with alpha in cell p and beta >= u_j
        P[j + 1:, j] = np.cumsum(row)
    F = offset + P[:, [0]] - P
    return np.tril(F)


class Preisach:
    """Classical Preisach model given by first-order reversal values on a triangle grid.

    Build it with :meth:`from_forc_table` (one airgap) or :meth:`family`
    (one table per calibration airgap).  ``simulate`` starts from the initial
    memory (input at the lowest grid value, all relays off); ``step``
    continues from the stored :attr:`state`.

    Parameters
    ----------
    grid : array_like
        Input grid ``u_0 < u_1 < ... < u_N`` [A] (any spacing).
    tables : array_like, shape (K, N+1, N+1)
        ``tables[k, i, j] = F(u_i, u_j)`` for ``j <= i`` at airgap ``k`` [N];
        entries above the diagonal are ignored.
    airgaps : array_like of length K, optional
        Calibration airgaps [m] (required when K > 1), strictly increasing.
    """

    def __init__(self, grid, tables, airgaps=None):
        grid = _as_1d("grid", grid)
        if grid.size < 2:
            raise DataError("grid: at least two input values are needed")
        if np.any(np.diff(grid) <= 0):
            i = int(np.flatnonzero(np.diff(grid) <= 0)[0])
            raise DataError(f"grid: not strictly increasing at index {i + 1} ({float(grid[i])!r} -> {float(grid[i + 1])!r})")
        tables = as_numbers(tables, "tables", DataError)
        if tables.ndim == 2:
            tables = tables[None]
        n = grid.size
        if tables.ndim != 3 or tables.shape[1:] != (n, n):
            raise DataError(f"tables: expected shape (K, {n}, {n}), got {tables.shape}")
        low = np.tril(np.ones((n, n), dtype=bool))
        for k in range(tables.shape[0]):
            if not np.all(np.isfinite(tables[k][low])):
                raise DataError(f"table {k}: non-finite FORC value on or below the diagonal")
            top = float(np.max(np.abs(tables[k][low])))
            if top > FORCE_LIMIT_N:   # (the plausibility limit of a force: a slip of unit or exponent)
                raise DataError(f"table {k}: FORC value of magnitude {top:g} N is implausible for a magnet's force "
                                f"(above {FORCE_LIMIT_N:g} N); check the unit and the exponent")
        tables = np.where(low[None], tables, 0.0)
        if airgaps is None:
            if tables.shape[0] != 1:
                raise ParameterError(f"{tables.shape[0]} tables need {tables.shape[0]} airgaps")
            gaps = np.array([0.0])
            self._has_gap = False
        else:
            gaps = _as_1d("airgaps", airgaps)
            if np.any(gaps > GAP_LIMIT_M):
                raise ParameterError(f"airgaps: {float(np.max(gaps)):g} m is implausible for an air gap (above "
                                     f"{GAP_LIMIT_M:g} m); check the unit and the exponent")
            if gaps.size != tables.shape[0]:
                raise ParameterError(f"airgaps: {gaps.size} values for {tables.shape[0]} tables")
            if np.any(np.diff(gaps) <= 0):
                raise ParameterError(f"airgaps: not strictly increasing ({gaps.tolist()})")
            if np.any(gaps <= 0):
                raise ParameterError(f"airgaps: must be > 0 [m] ({gaps.tolist()})")
            self._has_gap = True
        self.grid = np.ascontiguousarray(grid)
        self.tables = np.ascontiguousarray(tables)
        self.airgaps = np.ascontiguousarray(gaps)
        self._coef = np.ascontiguousarray(np.array([K.cell_coefficients(grid, t) for t in tables]))
        self.reset()

    # ------------------------------------------------------------- builders
    @classmethod
    def from_forc_table(cls, alpha, beta, value) -> "Preisach":
        """Build the model from FORC values listed point by point.

        Parameters
        ----------
        alpha, beta : array_like
            Reversal input and end input of each point [A]; the set of values
            forms the grid and every pair ``beta <= alpha`` of grid values must
            appear exactly once (the triangle T of [1], Fig. 3).
        value : array_like
            ``F(alpha, beta)`` [N]: output after rising from the lowest grid
            value to ``alpha`` and falling to ``beta`` ([1], Sec. 2.1).

        Raises
        ------
        DataError
            NaN, ``beta > alpha``, duplicates, or a missing grid point.
        """
        a = _as_1d("alpha", alpha)
        b = _as_1d("beta", beta)
        f = _as_1d("value", value)
        if not (a.size == b.size == f.size):
            raise DataError(f"alpha, beta, value: lengths differ ({a.size}, {b.size}, {f.size})")
        above = b > a * (1 + _GRID_RTOL) + _GRID_RTOL
        if above.any():
            i = int(np.flatnonzero(above)[0])
            raise DataError(f"FORC point {i}: beta = {float(b[i])!r} > alpha = {float(a[i])!r} (not a triangle grid)")
        grid = np.unique(np.concatenate([a, b]))
        n = grid.size
        ia = np.searchsorted(grid, a)
        ib = np.searchsorted(grid, b)
        table = np.full((n, n), np.nan)
        seen = np.zeros((n, n), dtype=bool)
        for p in range(a.size):
            if seen[ia[p], ib[p]]:
                raise DataError(f"FORC point ({a[p]:g}, {b[p]:g}) given twice")
            seen[ia[p], ib[p]] = True
            table[ia[p], ib[p]] = f[p]
        low = np.tril(np.ones((n, n), dtype=bool))
        missing = low & ~seen
        if missing.any():
            i, j = np.argwhere(missing)[0]
            raise DataError(
                f"FORC table is not a full triangle: missing F(alpha={grid[i]:g}, beta={grid[j]:g}) "
                f"({int(missing.sum())} point(s) missing)"
            )
        return cls(grid, table)

    @classmethod
    def family(cls, models, airgaps) -> "Preisach":
        """Combine single-airgap models (same current grid) into an airgap-dependent model.

        Parameters
        ----------
        models : sequence of Preisach
            One model per calibration airgap.
        airgaps : array_like
            Calibration airgaps [m], strictly increasing ([1]: 0.2-1.4 mm in 0.2 mm steps).
        """
        models = list(models)
        if not models:
            raise ParameterError("family: no models given")
        grid = models[0].grid
        for k, m in enumerate(models):
            if m.tables.shape[0] != 1:
                raise ParameterError(f"family: model {k} is already a family")
            if m.grid.shape != grid.shape or not np.allclose(m.grid, grid, rtol=0, atol=1e-12):
                raise ParameterError(f"family: model {k} has a different current grid")
        return cls(grid, np.concatenate([m.tables for m in models]), airgaps)

    def anhysteretic(self) -> "Preisach":
        """The same characteristic without hysteresis: ``F(alpha, beta) = g(beta)`` on every table.

        ``g(u) = (F(u, u) + F(u_max, u)) / 2`` is the mean of the limiting ascending and descending
        branches of the major loop ([1], Sec. 2.1) at each grid current (and airgap table). The model it
        gives is single-valued: its output depends on the present input only, and its inverse
        (:meth:`invert`) is the static inverse characteristic a compensator without a hysteresis model
        uses -- the "without inverse Preisach compensation" case of [1], Fig. 7.

        Returns
        -------
        Preisach
            Same grid and airgaps.
        """
        n = self.grid.size
        tables = np.empty_like(self.tables)
        for k in range(self.tables.shape[0]):
            t = self.tables[k]
            g = 0.5 * (np.diag(t) + t[n - 1, :])  # ascending F(u, u), descending F(u_max, u)
            tables[k] = np.tril(np.broadcast_to(g, (n, n))) + np.triu(np.full((n, n), np.nan), 1)
        return Preisach(self.grid, tables, self.airgaps if self._has_gap else None)

    # ------------------------------------------------------------- state
    def reset(self) -> None:
        """Return to the initial memory: input at the lowest grid value, all relays off."""
        self._alloc(16)
        self._length = 0
        self._u = float(self.grid[0])

    def _alloc(self, cap, keep=0):
        stack = np.zeros(cap)
        pref = np.zeros((self.tables.shape[0], cap // 2 + 2))
        if keep:
            stack[:keep] = self._stack[:keep]
            pref[:, : keep // 2 + 1] = self._pref[:, : keep // 2 + 1]
        self._stack, self._pref = stack, pref

    @property
    def state(self) -> PreisachState:
        """The present memory (a copy); assign a :class:`PreisachState` to restore it."""
        return PreisachState(self._stack[: self._length].copy(), self._u)

    @state.setter
    def state(self, value: PreisachState) -> None:
        ext = np.asarray(value.extrema, dtype=float)
        self._check_inputs("state.extrema", ext) if ext.size else None
        self._check_inputs("state.input", np.array([value.input]))
        mx, mn = ext[0::2], ext[1::2]
        if np.any(np.diff(mx) >= 0) or np.any(np.diff(mn) <= 0) or (mn.size and mx.min() <= mn.max()):
            raise ParameterError("state.extrema: not an alternating sequence of dominant maxima and minima")
        self._alloc(max(16, 2 * ext.size + 4))
        self._stack[: ext.size] = ext
        self._length = ext.size
        self._u = float(value.input)
        K.rebuild_prefix(self._coef, self.grid, self._stack, self._length, self._pref)

    @property
    def kernel_tables(self) -> np.ndarray:
        """Cell coefficients ``(K, N, N, 4)`` of Eqs. 4-5 used by the compiled kernels."""
        return self._coef

    @property
    def n_airgaps(self) -> int:
        """Number of calibration airgaps (1 for a single table)."""
        return self.tables.shape[0]

    # ------------------------------------------------------------- checks
    def _check_inputs(self, name, u):
        u = np.asarray(u, dtype=float)
        bad = ~np.isfinite(u)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise DataError(f"{name}[{i}] = {float(u.ravel()[i])!r}: not finite")
        lo, hi = self.grid[0], self.grid[-1]
        tol = 1e-9 * (hi - lo)
        out = (u < lo - tol) | (u > hi + tol)
        if out.any():
            i = int(np.flatnonzero(out.ravel())[0])
            raise DataError(f"{name}[{i}] = {float(u.ravel()[i])!r} A outside the Preisach grid [{lo:g}, {hi:g}] A")
        return np.ascontiguousarray(np.clip(u, lo, hi))

    def _gap_array(self, airgap, n):
        if not self._has_gap:
            if airgap is not None:
                raise ParameterError("airgap given for a model without airgap tables")
            return np.zeros(1)
        if airgap is None:
            raise ParameterError("this model has airgap tables: pass airgap= [m]")
        g = np.atleast_1d(np.asarray(airgap, dtype=float))
        if g.size not in (1, n):
            raise DataError(f"airgap: {g.size} values for {n} inputs")
        bad = ~np.isfinite(g)
        if bad.any():
            raise DataError(f"airgap[{int(np.flatnonzero(bad)[0])}]: not finite")
        lo, hi = self.airgaps[0], self.airgaps[-1]
        out = (g < lo - 1e-12) | (g > hi + 1e-12)
        if out.any():
            i = int(np.flatnonzero(out)[0])
            raise DataError(f"airgap[{i}] = {float(g[i])!r} m outside the calibration range [{lo:g}, {hi:g}] m")
        return np.ascontiguousarray(g)

    # ------------------------------------------------------------- forward
    def _run(self, u, gaps):
        out = np.empty(u.size)
        start = 0
        while True:
            done, length, last = K.simulate_kernel(self._coef, self.grid, self.airgaps, self._stack, self._pref,
                                                   self._length, self._u, u, gaps, out, start)
            self._length, self._u = int(length), float(last)
            if done >= u.size:
                return out
            self._alloc(2 * self._stack.size, keep=self._length)
            start = int(done)

    def simulate(self, u, airgap=None) -> np.ndarray:
        """Output for an input sequence from the initial memory ([1], Eqs. 2-3).

        Parameters
        ----------
        u : array_like
            Input (coil current) samples [A], within the grid.
        airgap : float or array_like, optional
            Airgap [m] (scalar or one per sample); required for a family.

        Returns
        -------
        numpy.ndarray
            Output (magnet force) [N] after each sample.

        Notes
        -----
        The model's own memory is left at the end of the sequence (continue
        with :meth:`step`).  Cost per sample is O(1) amortised; the memory
        grows only with the number of nested dominant extrema.
        """
        u = self._check_inputs("u", np.atleast_1d(u))
        gaps = self._gap_array(airgap, u.size)
        self.reset()
        return self._run(u, gaps)

    def step(self, u, airgap=None) -> np.ndarray | float:
        """Continue from the present memory with one or more input samples; returns the output [N]."""
        scalar = np.ndim(u) == 0
        arr = self._check_inputs("u", np.atleast_1d(u))
        out = self._run(arr, self._gap_array(airgap, arr.size))
        return float(out[0]) if scalar else out

    def output(self, airgap=None) -> float:
        """Output for the present memory and input [N] (without changing it)."""
        gaps = self._gap_array(airgap, 1)
        idx = np.zeros(K.GAP_TABLES, dtype=np.int64)
        w = np.zeros(K.GAP_TABLES)
        K.gap_weights(self.airgaps, gaps[0], idx, w)
        return float(K.weighted_output(self._coef, self.grid, self._stack, self._length, self._pref, self._u, idx, w))

    def forc(self, alpha, beta, airgap=None) -> np.ndarray:
        """Interpolated reversal value ``F(alpha, beta)`` [N] ([1], Eqs. 4-5), broadcasting."""
        a, b = np.broadcast_arrays(np.asarray(alpha, float), np.asarray(beta, float))
        a = self._check_inputs("alpha", a.ravel())
        b = self._check_inputs("beta", b.ravel())
        if np.any(b > a + 1e-12):
            raise DataError("forc: beta must not exceed alpha")
        gaps = self._gap_array(airgap, 1)
        idx = np.zeros(K.GAP_TABLES, dtype=np.int64)
        w = np.zeros(K.GAP_TABLES)
        K.gap_weights(self.airgaps, gaps[0], idx, w)
        out = np.zeros(a.size)
        for q in range(K.GAP_TABLES):
            if w[q] != 0.0:
                k = int(idx[q])
                out += w[q] * np.array([K.forc_value(self._coef, k, self.grid, x, y) for x, y in zip(a, b)])
        return out.reshape(np.broadcast(np.asarray(alpha), np.asarray(beta)).shape)

    # ------------------------------------------------------------- inverse
    def invert(self, target, airgap=None, *, state: PreisachState | None = None, tol=None) -> InverseResult:
        """Input sequence reproducing a target output sequence ([1], Eqs. 6-7, Fig. 7).

        Parameters
        ----------
        target : array_like
            Desired output (magnet force) [N].
        airgap : float or array_like, optional
            Airgap [m]; required for a family.
        state : PreisachState, optional
            Memory to start from (default: the initial memory, as :meth:`simulate`).
        tol : float, optional
            Output tolerance [N] (default ``1e-12`` of the table range).

        Returns
        -------
        InverseResult
            Input found, output it produces, feasibility mask and reachable
            range per sample; infeasible targets are met as closely as the
            grid ends allow and listed by :meth:`InverseResult.report`.

        Notes
        -----
        The model's memory is left at the end of the found input sequence.
        """
        t = _as_1d("target", np.atleast_1d(target))
        gaps = self._gap_array(airgap, t.size)
        if state is None:
            self.reset()
        else:
            self.state = state
        if tol is None:
            span = float(np.ptp(self.tables)) or 1.0
            tol = 1e-12 * span
        n = t.size
        out_u, out_f = np.empty(n), np.empty(n)
        feas = np.zeros(n, dtype=np.bool_)
        lo, hi = np.empty(n), np.empty(n)
        start = 0
        while True:
            done, length, last = K.invert_kernel(self._coef, self.grid, self.airgaps, self._stack, self._pref,
                                                 self._length, self._u, t, gaps, out_u, out_f, feas, lo, hi,
                                                 float(tol), start)
            self._length, self._u = int(length), float(last)
            if done >= n:
                break
            self._alloc(2 * self._stack.size, keep=self._length)
            start = int(done)
        return InverseResult(t, out_u, out_f, feas, lo, hi)

    # ------------------------------------------------------------- helpers
    def major_loop(self, n=101, airgap=None) -> pd.DataFrame:
        """Limiting ascending branch ``F(u, u)`` and descending branch ``F(u_max, u)`` [N]."""
        u = np.linspace(self.grid[0], self.grid[-1], n)
        up = self.forc(u, u, airgap)
        down = self.forc(np.full(n, self.grid[-1]), u, airgap)
        return pd.DataFrame({"current": u, "ascending": up, "descending": down})

    def to_forc_frame(self) -> pd.DataFrame:
        """Long table ``airgap, alpha, beta, value`` of every stored grid point."""
        i, j = np.tril_indices(self.grid.size)
        rows = []
        for k in range(self.tables.shape[0]):
            rows.append(pd.DataFrame({"airgap": self.airgaps[k] if self._has_gap else np.nan,
                                      "alpha": self.grid[i], "beta": self.grid[j], "value": self.tables[k][i, j]}))
        return pd.concat(rows, ignore_index=True)

    def to_json(self, path, overwrite=False) -> Path:
        """Save the model (grid, tables, airgaps) as JSON, atomically."""
        from ..io import atomic_write_text

        i, j = np.tril_indices(self.grid.size)
        body = {
            "kind": "clutchlab.preisach",
            "version": 1,
            "grid_A": self.grid.tolist(),
            "airgaps_m": self.airgaps.tolist() if self._has_gap else None,
            "tables_N": [t[i, j].tolist() for t in self.tables],
            "note": "tables_N[k] lists F(alpha_i, beta_j) for i >= j in numpy.tril_indices order",
        }
        return atomic_write_text(path, json.dumps(body, indent=1), overwrite=overwrite)

    @classmethod
    def from_json(cls, path) -> "Preisach":
        """Load a model written by :meth:`to_json`."""
        from .._limits import check_allocation
        from ..io.files import read_json

        path = Path(path)
        body = read_json(path, DataError)
        if not isinstance(body, dict) or body.get("kind") != "clutchlab.preisach":
            raise DataError(f"{path}: not a clutchlab Preisach model (missing kind='clutchlab.preisach')")
        try:
            grid = as_numbers(body["grid_A"], f"{path}: grid_A", DataError)
            if grid.ndim != 1:
                raise DataError(f"{path}: grid_A must be a 1-D list of currents [A], got an array of shape "
                                f"{grid.shape}")
            n = grid.size
            check_allocation(n, n * (1 + len(body["tables_N"])), f"{path}: grid_A of {n} currents")
            i, j = np.tril_indices(n)
            tabs = []
            for k, vals in enumerate(body["tables_N"]):
                t = np.zeros((n, n))
                t[i, j] = as_numbers(vals, f"{path}: tables_N[{k}]", DataError)
                tabs.append(t)
            gaps = body.get("airgaps_m")
            if gaps is not None:
                gaps = _as_1d(f"{path}: airgaps_m", gaps)
        except DataError:
            raise
        except (KeyError, TypeError, ValueError) as exc:
            raise DataError(f"{path}: malformed Preisach model ({exc})") from None
        try:
            return cls(grid, np.array(tabs), gaps)
        except (DataError, ParameterError) as exc:  # name the file
            raise type(exc)(f"{path}: {exc}") from None

    def __repr__(self) -> str:
        g = f", {self.n_airgaps} airgaps {self.airgaps[0]:g}..{self.airgaps[-1]:g} m" if self._has_gap else ""
        return f"Preisach(grid {self.grid[0]:g}..{self.grid[-1]:g} A, {self.grid.size} points{g})"
