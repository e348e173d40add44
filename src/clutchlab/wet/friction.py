"""Asperity friction coefficient mu_f as a pluggable law.

Two interchangeable laws feed the torque model (Shin, Kim and Choi [1],
Eq. 4) and the compiled engagement kernel:

* :class:`ParametricFriction` -- the form the paper found (Sec. 4): linear in
  the friction-surface temperature and exponential in the slip speed,
  ``mu_f = mu0 + mu_t (T - T_ref) + mu_e exp(-|v| / v_s)``;
* :class:`FrictionMap` -- a measured map, tabulated over slip velocity,
  temperature and optionally pressing force, interpolated (multi-)linearly.

The paper's "negatively exponential to the slip speed" is read as a term in
``exp(-v/v_s)``; the sign of ``mu_e`` is free (``mu_e < 0``: friction rising
with slip towards a plateau, the usual paper-lining shape; ``mu_e > 0``:
falling).

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
"""

from __future__ import annotations

import dataclasses
import json
from typing import ClassVar

import numba
import numpy as np

from .._limits import as_numbers, short_repr
from ..errors import DataError
from ..params.base import FRICTION_COEFFICIENT_MAX
from ..numerics.interp import bracket
from ..params import ParameterSet, quantity
from ..numerics.layout import indices

__all__ = ["ParametricFriction", "FrictionMap", "KIND_PARAMETRIC", "KIND_TABLE", "mu_kernel"]

#: kinds of friction law
FRICTION_KINDS = ("parametric", "table")
KIND_PARAMETRIC, KIND_TABLE = indices(FRICTION_KINDS, "parametric", "table")


@dataclasses.dataclass(frozen=True)
class ParametricFriction(ParameterSet):
    """``mu_f(v, T) = mu0 + mu_t (T - t_ref) + mu_e exp(-|v|/v_s)``, clipped at 0 ([1], Sec. 4).

    Defaults are representative of a paper-based lining in ATF (clutchlab's
    choice, not from the paper, whose Fig. 15 has no printed numbers).
    """

    kind: ClassVar[str] = "friction"

    mu0: float = quantity(0.12, "1", "friction coefficient at t_ref and high slip", source="clutchlab")
    mu_t: float = quantity(5e-4, "1/K", "temperature slope of mu_f", source="clutchlab")
    mu_e: float = quantity(-0.02, "1", "amplitude of the slip-speed exponential", source="clutchlab")
    v_s: float = quantity(1.0, "m/s", "slip-velocity scale of the exponential", source="clutchlab", positive=True)
    t_ref: float = quantity(100.0, "degC", "reference temperature", source="clutchlab")

    @classmethod
    def bench_truth(cls) -> "ParametricFriction":
        """The map the virtual bench's clutch actually has (differs from the defaults on purpose)."""
        return cls(mu0=0.135, mu_t=8e-4, mu_e=-0.03, v_s=0.6, t_ref=100.0)

    def mu(self, slip_velocity, temperature_c, force=None):
        """Friction coefficient [-] at slip velocity [m/s] and temperature [degC] (force ignored)."""
        v = np.abs(np.asarray(slip_velocity, dtype=float))
        t = np.asarray(temperature_c, dtype=float)
        # the compiled law of the engagement model, evaluated on arrays
        out = np.asarray(parametric_mu_scalar.py_func(v, t, self.mu0, self.mu_t, self.mu_e, self.v_s, self.t_ref))
        return float(out) if out.ndim == 0 else out

    def kernel_data(self):
        """Arrays for :func:`mu_kernel`: (kind, coef, grid_v, grid_t, grid_f, table)."""
        coef = np.array([self.mu0, self.mu_t, self.mu_e, self.v_s, self.t_ref])
        z = np.zeros(1)
        return KIND_PARAMETRIC, coef, z, z, z, np.zeros(1)


def _check_grid(name, grid):
    g = as_numbers(grid, f"FrictionMap.{name}", DataError)
    if g.ndim > 1:
        raise DataError(f"FrictionMap.{name}: expected a list of values, got a table of shape {g.shape}")
    g = g.ravel()
    if g.size < 1 or not np.all(np.isfinite(g)):
        raise DataError(f"FrictionMap.{name}: needs finite values, got {grid!r}")
    if g.size > 1 and np.any(np.diff(g) <= 0):
        raise DataError(f"FrictionMap.{name}: must be strictly increasing")
    return g


def _interp_weights(grid, x):
    """Indices and weights of linear interpolation with constant extrapolation."""
    if grid.size == 1:
        i = np.zeros(np.shape(x), dtype=int)
        return i, i, np.zeros(np.shape(x))
    xc = np.clip(x, grid[0], grid[-1])
    j = np.clip(np.searchsorted(grid, xc, side="right") - 1, 0, grid.size - 2)
    w = (xc - grid[j]) / (grid[j + 1] - grid[j])
    return j, j + 1, w


class FrictionMap:
    """Tabulated friction coefficient ``mu_f(v, T[, F])`` with its provenance.

    Parameters
    ----------
    speed_grid : array_like
        Slip-velocity nodes [m/s], increasing.
    temperature_grid : array_like
        Friction-surface temperature nodes [degC], increasing.
    values : array_like
        mu_f at the nodes, shape ``(n_T, n_v)`` or ``(n_F, n_T, n_v)``.
    force_grid : array_like, optional
        Pressing-force nodes [N] for a 3-D map.
    covered : array_like of bool, optional
        Nodes supported by measurements (same shape as ``values``); the rest
        were filled from ``law``.
    law : ParametricFriction, optional
        Parametric fit of the same data.
    statistics : dict, optional
        Fit statistics (rmse, r2, standard errors, sample counts).
    region : dict, optional
        Covered region (min/max of v, T, F in the data).

    Notes
    -----
    Linear interpolation in each axis, constant beyond the grid.
    """

    def __init__(self, speed_grid, temperature_grid, values, force_grid=None, covered=None, law=None,
                 statistics=None, region=None):
        self.speed_grid = _check_grid("speed_grid", speed_grid)
        self.temperature_grid = _check_grid("temperature_grid", temperature_grid)
        self.force_grid = _check_grid("force_grid", force_grid) if force_grid is not None else None
        vals = as_numbers(values, "FrictionMap.values", DataError)
        shape = (self.temperature_grid.size, self.speed_grid.size)
        if self.force_grid is not None:
            shape = (self.force_grid.size,) + shape
        if vals.shape != shape:
            raise DataError(f"FrictionMap.values: shape {vals.shape} does not match the grids {shape}")
        if not np.all(np.isfinite(vals)):
            raise DataError(f"FrictionMap.values: must be finite (got {float(vals[~np.isfinite(vals)][0])!r})")
        if np.any(vals < 0) or np.any(vals > FRICTION_COEFFICIENT_MAX):
            bad = vals[~((vals >= 0) & (vals <= FRICTION_COEFFICIENT_MAX))][0]
            raise DataError(f"FrictionMap.values: {float(bad):g} is not a friction coefficient in [0, "
                            f"{FRICTION_COEFFICIENT_MAX:g}] (params.base.FRICTION_COEFFICIENT_MAX)")
        self.values = vals
        if covered is None:
            self.covered = np.ones(shape, bool)
        else:
            cov = as_numbers(covered, "FrictionMap.covered", DataError)
            if cov.shape != shape or not np.all((cov == 0) | (cov == 1)):
                raise DataError(f"FrictionMap.covered: expected 0 or 1 for each value, shape {shape}; got shape "
                                f"{cov.shape}")
            self.covered = cov.astype(bool)
        if law is not None and not isinstance(law, ParametricFriction):
            raise DataError(f"FrictionMap.law: expected a ParametricFriction or None, not {type(law).__name__}")
        for what, value in (("statistics", statistics), ("region", region)):
            if value is not None and not isinstance(value, dict):
                raise DataError(f"FrictionMap.{what} = {short_repr(value)}: expected a table of named values (a "
                                f"JSON object), not {type(value).__name__}")
        self.law = law
        self.statistics = dict(statistics or {})
        self.region = dict(region or {})

    def mu(self, slip_velocity_m_s, temperature_c, force=None):
        """Friction coefficient [-] at slip velocity [m/s], temperature [degC] and force [N] (vectorised)."""
        v = np.abs(np.asarray(slip_velocity_m_s, dtype=float))
        t = np.asarray(temperature_c, dtype=float)
        v, t = np.broadcast_arrays(v, t)
        iv0, iv1, wv = _interp_weights(self.speed_grid, v)
        it0, it1, wt = _interp_weights(self.temperature_grid, t)

        def plane(tab):
            return ((1 - wt) * ((1 - wv) * tab[it0, iv0] + wv * tab[it0, iv1])
                    + wt * ((1 - wv) * tab[it1, iv0] + wv * tab[it1, iv1]))

        if self.force_grid is None:
            out = plane(self.values)
        else:
            if force is None:
                raise DataError("FrictionMap.mu: this map depends on force; pass force=[N]")
            f = np.broadcast_to(np.asarray(force, dtype=float), v.shape)
            i0, i1, wf = _interp_weights(self.force_grid, f)
            lo = np.array([plane(self.values[k]) for k in range(self.force_grid.size)])
            flat = lo.reshape(self.force_grid.size, -1)
            idx = np.arange(flat.shape[1])
            out = ((1 - wf.ravel()) * flat[i0.ravel(), idx] + wf.ravel() * flat[i1.ravel(), idx]).reshape(v.shape)
        return float(out) if np.ndim(out) == 0 else out

    __call__ = mu

    def speed_slopes(self):
        """The map's slope over the slip velocity, ``d mu_f / d v`` [s/m] between neighbouring speed nodes, per
        temperature (and force) row: the anti-shudder criterion of a friction pairing.

        A pairing whose friction falls with the slip speed (``d mu_f / d v < 0``) damps a driveline's torsional
        modes negatively while it slides, by ``c_geo F_n r d mu_f / d v`` per rad/s at the radius ``r`` (docs/
        control.md, "Judder"); Mäki et al. (SAE 2005-01-0878, reference of seed 001) require ``d mu / d v > 0``
        over the engagement's slip speeds.  The map is linear between its nodes, so these are its slopes, not
        estimates.

        Returns
        -------
        pandas.DataFrame
            ``force_N`` (a 3-D map only), ``temperature_C``, ``speed_from_m_s``, ``speed_to_m_s``, ``dmu_dv_s_m``
            and ``covered`` (both nodes measured, not filled from the law).
        """
        import pandas as pd

        values = self.values.reshape(-1, *self.values.shape[-2:])   # (a 2-D map as one force row)
        covered = self.covered.reshape(values.shape)
        v = self.speed_grid
        rows = []
        for k in range(values.shape[0]):
            for i, temp in enumerate(self.temperature_grid):
                for j in range(v.size - 1):
                    row = {} if self.force_grid is None else {"force_N": float(self.force_grid[k])}
                    row.update(temperature_C=float(temp), speed_from_m_s=float(v[j]), speed_to_m_s=float(v[j + 1]),
                               dmu_dv_s_m=float((values[k, i, j + 1] - values[k, i, j]) / (v[j + 1] - v[j])),
                               covered=bool(covered[k, i, j] and covered[k, i, j + 1]))
                    rows.append(row)
        columns = ([] if self.force_grid is None else ["force_N"]) + [
            "temperature_C", "speed_from_m_s", "speed_to_m_s", "dmu_dv_s_m", "covered"]
        return pd.DataFrame(rows, columns=columns)

    def shudder_summary(self) -> dict:
        """The anti-shudder verdict over the map's measured intervals (:meth:`speed_slopes` with ``covered``):
        ``intervals`` (how many), ``falling`` (how many with ``d mu_f / d v < 0``), ``shudder_prone`` (any
        falling), and the steepest fall, ``min_dmu_dv_s_m`` with its ``at_temperature_C`` and ``at_speed_m_s`` (the
        interval's middle); None for those three with no measured interval."""
        table = self.speed_slopes()
        table = table[table.covered]
        out = {"intervals": int(len(table)), "falling": int((table.dmu_dv_s_m < 0).sum()),
               "shudder_prone": bool((table.dmu_dv_s_m < 0).any()), "min_dmu_dv_s_m": None,
               "at_temperature_C": None, "at_speed_m_s": None}
        if len(table):
            row = table.loc[table.dmu_dv_s_m.idxmin()]
            out.update(min_dmu_dv_s_m=float(row.dmu_dv_s_m), at_temperature_C=float(row.temperature_C),
                       at_speed_m_s=0.5 * float(row.speed_from_m_s + row.speed_to_m_s))
        return out

    def kernel_data(self):
        """Arrays for :func:`mu_kernel`: (kind, coef, grid_v, grid_t, grid_f, table)."""
        gf = self.force_grid if self.force_grid is not None else np.zeros(1)
        tab = self.values if self.force_grid is not None else self.values[None, :, :]
        return (KIND_TABLE, np.zeros(5), self.speed_grid.copy(), self.temperature_grid.copy(), gf.copy(),
                np.ascontiguousarray(tab).ravel())

    # ------------------------------------------------------------ files
    def to_dict(self) -> dict:
        """JSON-ready dict (SI units; temperature in degC)."""
        return {
            "format": "clutchlab.wet.FrictionMap/1",
            "units": {"speed_grid": "m/s", "temperature_grid": "degC", "force_grid": "N", "values": "1"},
            "speed_grid": self.speed_grid.tolist(),
            "temperature_grid": self.temperature_grid.tolist(),
            "force_grid": None if self.force_grid is None else self.force_grid.tolist(),
            "values": self.values.tolist(),
            "covered": self.covered.astype(int).tolist(),
            "law": None if self.law is None else self.law.to_dict(),
            "statistics": self.statistics,
            "region": self.region,
        }

    def to_json(self, path, overwrite: bool = False):
        """Write the map as JSON, atomically (refuses to overwrite by default)."""
        from ..io import atomic_write_text

        return atomic_write_text(path, json.dumps(self.to_dict(), indent=1), overwrite=overwrite)

    @classmethod
    def from_dict(cls, data: dict, source: str = "map") -> "FrictionMap":
        """Rebuild a map from :meth:`to_dict` output."""
        if not isinstance(data, dict):
            raise DataError(f"{source}: expected a friction map (a JSON object), got {type(data).__name__}")
        missing = [k for k in ("speed_grid", "temperature_grid", "values") if k not in data]
        if missing:
            raise DataError(f"{source}: friction map lacks the key {missing[0]!r}")
        law = data.get("law")
        if law is not None and not isinstance(law, dict):
            raise DataError(f"{source}: FrictionMap.law = {short_repr(law)}: expected the parameters of a "
                            "ParametricFriction (a JSON object) or null")
        law = ParametricFriction.from_dict(law, source=source) if law else None
        try:
            return cls(data["speed_grid"], data["temperature_grid"], data["values"], data.get("force_grid"),
                       data.get("covered"), law, data.get("statistics"), data.get("region"))
        except DataError as exc:   # (a field of the file: name the file)
            raise DataError(f"{source}: {exc}") from None

    @classmethod
    def from_json(cls, path) -> "FrictionMap":
        """Read a map written by :meth:`to_json`."""
        from ..io.files import read_json

        return cls.from_dict(read_json(path, DataError), source=str(path))


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _lin_index(grid, x):
    n = grid.shape[0]
    if n == 1:
        return 0, 0.0
    return bracket(grid, x)


@numba.njit(cache=True, nogil=True, inline="always")
def parametric_mu_scalar(v_abs, temperature_c, mu0, mu_t, mu_e, v_s, t_ref):
    """Parametric asperity friction ``mu_f = mu0 + mu_t (T - t_ref) + mu_e exp(-|v|/v_s)``, clipped at 0 ([1], Sec. 4).

    Compiled scalar form used by :func:`mu_kernel`;
    :meth:`ParametricFriction.mu` evaluates the same function body on arrays.

    Parameters
    ----------
    v_abs : float
        Slip velocity magnitude |v| [m/s].
    temperature_c : float
        Friction-surface temperature [degC].
    mu0, mu_t, mu_e, v_s, t_ref : float
        The law's parameters ([-], [1/K], [-], [m/s], [degC]).
    """
    mu = mu0 + mu_t * (temperature_c - t_ref) + mu_e * np.exp(-v_abs / v_s)  # [1], Sec. 4
    return np.maximum(mu, 0.0)


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def mu_kernel(v_abs, temperature_c, force, kind, coef, gv, gt, gf, table):
    """Compiled friction law: parametric (kind 0) or (tri)linear table (kind 1) ([1], Eq. 4 input).

    Parameters
    ----------
    v_abs : float
        Slip velocity magnitude [m/s].
    temperature_c : float
        Friction-surface temperature [degC].
    force : float
        Pressing force [N] (3-D maps only).
    kind, coef, gv, gt, gf, table
        The arrays of ``kernel_data()`` of a :class:`ParametricFriction` or :class:`FrictionMap`.
    """
    if kind == 0:
        return parametric_mu_scalar(v_abs, temperature_c, coef[0], coef[1], coef[2], coef[3], coef[4])
    nv = gv.shape[0]
    nt = gt.shape[0]
    iv, wv = _lin_index(gv, v_abs)
    it, wt = _lin_index(gt, temperature_c)
    i_f, wf = _lin_index(gf, force)
    iv1 = iv + 1 if nv > 1 else iv
    it1 = it + 1 if nt > 1 else it
    if_1 = i_f + 1 if gf.shape[0] > 1 else i_f
    out = 0.0
    for a in range(2):
        fi = i_f if a == 0 else if_1
        wa = (1.0 - wf) if a == 0 else wf
        if wa == 0.0:
            continue
        base = fi * nt * nv
        m00 = table[base + it * nv + iv]
        m01 = table[base + it * nv + iv1]
        m10 = table[base + it1 * nv + iv]
        m11 = table[base + it1 * nv + iv1]
        out += wa * ((1.0 - wt) * ((1.0 - wv) * m00 + wv * m01) + wt * ((1.0 - wv) * m10 + wv * m11))
    return out
