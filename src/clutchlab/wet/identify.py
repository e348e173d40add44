"""Identification of the friction-coefficient map and the thermal conductances.

Shin, Kim and Choi [1], Sec. 4: from bench records (torque, slip speed,
pressing force, piston position, temperatures) the viscous torque (Eq. 5) is
computed from the piston position (Eqs. 1-2) and the temperature (Eq. 7)
and subtracted from the measured torque; the remainder divided by
``R_eff N_c F_c`` is the asperity friction coefficient (Eq. 4).  The samples
are tabulated over slip velocity and temperature where the records cover
them and fitted by the parametric form the paper found (linear in
temperature, exponential in slip speed).  The conductances k1, k2 of the
heat balance (Eq. 8) are found by linear least squares, with the
temperature derivative from a Savitzky-Golay filter applied identically to
every term of Eq. 8 (a linear filter commutes with the linear balance, so
smoothing introduces no bias).

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
.. [2] A. Savitzky, M. J. E. Golay, "Smoothing and differentiation of data by
   simplified least squares procedures", Anal. Chem. 36 (1964) 1627-1639.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..errors import DataError, IdentificationError, ParameterError
from .bench import read_bench_record
from .film import mean_film_thickness, nominal_separation
from .friction import FrictionMap, ParametricFriction
from .params import WetClutch
from .torque import viscous_torque
from .viscosity import atf_viscosity

__all__ = ["friction_samples", "identify_friction_map", "identify_thermal", "ThermalFit", "fit_parametric_friction"]


def _records(records):
    if isinstance(records, (str, pd.DataFrame)) or hasattr(records, "__fspath__"):
        records = [records]
    out = []
    for i, r in enumerate(records):
        label = f"record[{i}]" if isinstance(r, pd.DataFrame) else str(r)
        out.append((label, read_bench_record(r)))
    if not out:
        raise DataError("no bench records given")
    return out


def _savgol(frame: pd.DataFrame, window_s: float, label: str):
    from scipy.signal import savgol_filter

    t = frame["time_s"].to_numpy()
    dt = np.median(np.diff(t))
    if np.max(np.abs(np.diff(t) - dt)) > 1e-6 * max(dt, 1e-12) + 1e-9:
        raise DataError(f"{label}: thermal identification needs a uniformly sampled record (column 'time_s')")
    n = int(round(window_s / dt)) | 1
    n = max(n, 7)
    if n >= t.size:
        raise DataError(f"{label}: record of {t.size} samples is shorter than the smoothing window ({n})")
    return dt, n, (lambda x, d=0: savgol_filter(np.asarray(x, float), n, 3, deriv=d, delta=dt))


def _lag_corrected_temperature(frame, sensor_time_constant, window_s, label):
    """Friction-surface temperature and its derivative from the lagged thermistor [degC], [K/s]."""
    dt, n, sg = _savgol(frame, window_s, label)
    tm = frame["temperature_C"].to_numpy()
    temp = sg(tm)
    dtemp = sg(tm, 1)
    if sensor_time_constant > 0:
        temp = temp + sensor_time_constant * dtemp  # T = T_m + tau dT_m/dt (first-order sensor)
        dtemp = dtemp + sensor_time_constant * sg(tm, 2)
    return temp, dtemp, sg, n


#: Plausible range of a friction coefficient of a wet clutch (paper-based linings: about 0.1).
MU_RANGE = (0.0, 1.0)


def _check_time_constant(value) -> float:
    """The thermistor lag [s] as a float: finite and >= 0, else :class:`ParameterError`."""
    try:
        tau = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"sensor_time_constant = {value!r}: expected a number [s]") from None
    if not (math.isfinite(tau) and tau >= 0):
        raise ParameterError(f"sensor_time_constant = {value!r}: must be finite and >= 0 [s]")
    return tau


def friction_samples(records, clutch: WetClutch, *, min_slip_velocity: float = 0.05, min_force: float = 100.0,
                     sensor_time_constant: float = 0.0, window: float = 0.2) -> pd.DataFrame:
    """Asperity friction coefficient per sample, as the paper computes it (Sec. 4).

    ``mu_f = (|tau| - |tau_v|) / (R_eff N_c F_c)`` with ``tau_v`` from Eq. 5
    (h_bar from the piston position, Eqs. 1-2; mu_v(T), Eq. 7) and
    ``F_c = F - F_spring(x_p)``: the load-cell force minus the return-spring
    force (the film is kept steady, so the squeeze-film force is neglected).

    Parameters
    ----------
    records : path, DataFrame or list of them
        Bench records (:func:`read_bench_record` columns).
    clutch : WetClutch
        Geometry, film, viscosity and spring parameters of the tested clutch.
    min_slip_velocity : float
        Samples with slower slip [m/s] are dropped (stick, sign of friction undefined).
    min_force : float
        Samples with a smaller asperity force [N] are dropped.
    sensor_time_constant : float
        Thermistor lag [s] to compensate (0: use the reading as it is).
    window : float
        Savitzky-Golay window for the temperature [s].

    Returns
    -------
    pandas.DataFrame
        Columns ``slip_velocity_m_s, temperature_C, force_N, mu_f, viscous_torque_Nm, record``.
    """
    sensor_time_constant = _check_time_constant(sensor_time_constant)
    parts = []
    r_eff = clutch.r_eff
    for label, fr in _records(records):
        temp, _, _, _ = _lag_corrected_temperature(fr, sensor_time_constant, window, label)
        w = fr["slip_speed_rad_s"].to_numpy()
        v = r_eff * w                                                             # [1], Eq. (2')
        h = nominal_separation(fr["piston_position_m"].to_numpy(), clutch.piston_h0, clutch.n_c)  # [1], Eq. 1
        hbar = mean_film_thickness(h, clutch.sigma)                               # [1], Eq. 2
        muv = atf_viscosity(temp, *clutch.viscosity)                              # [1], Eq. 7
        tv = viscous_torque(r_eff, clutch.n_c, muv, clutch.friction_area, v, hbar)  # [1], Eq. 5
        fc = fr["force_N"].to_numpy() - (clutch.spring_preload + clutch.spring_stiffness * fr["piston_position_m"].to_numpy())
        tau = fr["torque_Nm"].to_numpy()
        keep = (np.abs(v) >= min_slip_velocity) & (fc >= min_force)
        with np.errstate(divide="ignore", invalid="ignore"):
            mu = (np.abs(tau) - np.abs(tv)) / (r_eff * clutch.n_c * fc)          # [1], Eq. 4 solved for mu_f
        parts.append(pd.DataFrame({"slip_velocity_m_s": np.abs(v[keep]), "temperature_C": temp[keep],
                                   "force_N": fc[keep], "mu_f": mu[keep], "viscous_torque_Nm": tv[keep],
                                   "record": label}))
    out = pd.concat(parts, ignore_index=True)
    if len(out) < 10:
        raise IdentificationError(
            f"only {len(out)} samples with slip velocity >= {min_slip_velocity} m/s and contact force >= {min_force} N")
    return out


def fit_parametric_friction(v, temp, mu, t_ref: float | None = None):
    """Least-squares fit of ``mu0 + mu_t (T - t_ref) + mu_e exp(-v/v_s)`` to samples.

    Initial guesses from the data: a linear regression of mu on T and v over
    the fast half of the samples (mu0, mu_t), the mean deficit at low speed
    (mu_e) and a third of the speed span (v_s).

    Parameters
    ----------
    v : array_like
        Slip velocity [m/s].
    temp : array_like
        Friction-surface temperature [degC].
    mu : array_like
        Friction-coefficient samples [-].
    t_ref : float, optional
        Reference temperature [degC] (default: the rounded mean).

    Returns
    -------
    (ParametricFriction, dict)
        The law and statistics (rmse, r2, stderr, correlation, n, initial guess).
    """
    from scipy.optimize import least_squares

    v = np.asarray(v, float)
    temp = np.asarray(temp, float)
    mu = np.asarray(mu, float)
    if t_ref is None:
        t_ref = float(np.round(np.mean(temp)))
    fast = v >= np.median(v)
    a = np.column_stack([np.ones(fast.sum()), temp[fast] - t_ref])
    (m0, mt), *_ = np.linalg.lstsq(a, mu[fast], rcond=None)
    slow = v <= np.quantile(v, 0.1)
    me = float(np.mean(mu[slow] - (m0 + mt * (temp[slow] - t_ref)))) if slow.any() else 0.0
    vs = max((v.max() - v.min()) / 3.0, 1e-3)
    x0 = np.array([m0, mt, me if abs(me) > 1e-4 else -1e-3, math.log(vs)])

    def model(x):
        return x[0] + x[1] * (temp - t_ref) + x[2] * np.exp(-v / math.exp(x[3]))

    sol = least_squares(lambda x: model(x) - mu, x0, method="lm", x_scale="jac")
    if not sol.success:
        raise IdentificationError(f"friction-law fit failed ({sol.message})")
    x = sol.x
    res = sol.fun
    n = mu.size
    dof = max(n - 4, 1)
    s2 = float(res @ res) / dof
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac) * s2
    except np.linalg.LinAlgError:
        cov = np.full((4, 4), np.nan)
    se = np.sqrt(np.clip(np.diag(cov), 0, None))
    se_vs = math.exp(x[3]) * se[3]
    d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    corr = cov / np.outer(d, d)
    law = ParametricFriction(mu0=float(x[0]), mu_t=float(x[1]), mu_e=float(x[2]), v_s=float(math.exp(x[3])),
                             t_ref=float(t_ref))
    ss_tot = float(np.sum((mu - mu.mean()) ** 2))
    stats = {
        "n_samples": int(n),
        "rmse": float(math.sqrt(np.mean(res**2))),
        "r2": float(1.0 - float(res @ res) / ss_tot) if ss_tot > 0 else float("nan"),
        "stderr": {"mu0": float(se[0]), "mu_t": float(se[1]), "mu_e": float(se[2]), "v_s": float(se_vs)},
        "correlation": corr.round(4).tolist(),
        "initial_guess": {"mu0": float(x0[0]), "mu_t": float(x0[1]), "mu_e": float(x0[2]), "v_s": float(vs)},
    }
    return law, stats


def _check_friction_law(law: ParametricFriction, stats: dict, v: np.ndarray) -> None:
    """Refuse a fitted law that the samples do not determine or that is not physical."""
    v_max = float(np.max(v))
    if law.v_s > v_max:
        corr = stats["correlation"][0][2]
        raise IdentificationError(
            f"friction law: v_s = {law.v_s:.3g} m/s lies beyond the fastest recorded slip velocity "
            f"{v_max:.3g} m/s, so the records do not show the decay of the exponential term and do not "
            f"determine mu0 = {law.mu0:.3g} and mu_e = {law.mu_e:.3g} (correlation {corr:.4f}); add "
            "friction-map records (protocol friction_map) over a wider slip-speed range")
    lo, hi = MU_RANGE
    for what, value in (("mu0 (high slip)", law.mu0), ("mu0 + mu_e (zero slip)", law.mu0 + law.mu_e)):
        if not lo < value <= hi:
            raise IdentificationError(
                f"friction law: {what} = {value:.4g} is not a friction coefficient ({lo:g} < mu <= {hi:g}); "
                "the records do not determine the law")


def identify_friction_map(records, clutch: WetClutch, *, speed_bins: int = 12, temperature_bins: int = 8,
                          min_count: int = 20, min_slip_velocity: float = 0.05, min_force: float = 100.0,
                          sensor_time_constant: float = 0.0) -> FrictionMap:
    """Friction-coefficient map mu_f(v, T) from bench records, as in Sec. 4 (Fig. 15).

    Parameters
    ----------
    records : path, DataFrame or list of them
        Friction-map experiments (protocol (a)); engagement records may be added.
    clutch : WetClutch
        Parameters of the clutch under test (geometry, film, viscosity, spring).
    speed_bins, temperature_bins : int
        Number of cells of the table over the covered slip-velocity and
        temperature ranges.
    min_count : int
        Samples a cell needs to count as covered.
    min_slip_velocity, min_force, sensor_time_constant
        See :func:`friction_samples`.

    Returns
    -------
    FrictionMap
        Table of cell means at the cell centres (uncovered cells filled from
        the parametric fit, marked in ``covered``), the fitted
        :class:`ParametricFriction` in ``law``, fit statistics in
        ``statistics`` and the covered region in ``region``.

    Raises
    ------
    ParameterError
        ``sensor_time_constant`` negative, NaN or infinite.
    IdentificationError
        Too few usable samples, fewer than 2 covered cells, or a fitted law
        the records do not determine: ``v_s`` beyond the fastest recorded
        slip velocity (the exponential term is then indistinguishable from
        a linear one), or a friction coefficient outside 0..1 at zero or
        high slip.
    """
    if speed_bins < 2 or temperature_bins < 1 or min_count < 1:
        raise ParameterError("speed_bins >= 2, temperature_bins >= 1 and min_count >= 1 are required")
    s = friction_samples(records, clutch, min_slip_velocity=min_slip_velocity, min_force=min_force,
                         sensor_time_constant=sensor_time_constant)
    v = s["slip_velocity_m_s"].to_numpy()
    temp = s["temperature_C"].to_numpy()
    mu = s["mu_f"].to_numpy()
    law, stats = fit_parametric_friction(v, temp, mu)
    _check_friction_law(law, stats, v)
    ve = np.linspace(v.min(), v.max(), speed_bins + 1)
    te = np.linspace(temp.min(), temp.max(), temperature_bins + 1)
    iv = np.clip(np.searchsorted(ve, v, side="right") - 1, 0, speed_bins - 1)
    it = np.clip(np.searchsorted(te, temp, side="right") - 1, 0, temperature_bins - 1)
    flat = it * speed_bins + iv
    count = np.bincount(flat, minlength=speed_bins * temperature_bins).reshape(temperature_bins, speed_bins)
    total = np.bincount(flat, weights=mu, minlength=speed_bins * temperature_bins).reshape(temperature_bins, speed_bins)
    # mean position of the samples in each cell: the cell mean of mu belongs there
    vsum = np.bincount(flat, weights=v, minlength=speed_bins * temperature_bins).reshape(temperature_bins, speed_bins)
    tsum = np.bincount(flat, weights=temp, minlength=speed_bins * temperature_bins).reshape(temperature_bins, speed_bins)
    covered = count >= min_count
    if covered.sum() < 2:
        raise IdentificationError(f"only {int(covered.sum())} map cells have >= {min_count} samples; "
                                  "record more operating points")
    vc = 0.5 * (ve[:-1] + ve[1:])
    tc = 0.5 * (te[:-1] + te[1:])
    with np.errstate(invalid="ignore", divide="ignore"):
        cell_mu = total / count
        cell_v = vsum / count
        cell_t = tsum / count
    # move each cell mean from the samples' centroid to the node with the fitted law's local slope
    vv, tt = np.meshgrid(vc, tc)
    shift = law.mu(vv, tt) - law.mu(np.where(covered, cell_v, vv), np.where(covered, cell_t, tt))
    table = np.where(covered, cell_mu + shift, law.mu(vv, tt))
    table = np.maximum(table, 0.0)
    res_cells = (cell_mu - law.mu(cell_v, cell_t))[covered]
    stats = dict(stats)
    stats["cells_covered"] = int(covered.sum())
    stats["cells_total"] = int(covered.size)
    stats["table_rms_deviation_from_law"] = float(np.sqrt(np.mean(res_cells**2)))
    region = {
        "slip_velocity_m_s": [float(v.min()), float(v.max())],
        "temperature_C": [float(temp.min()), float(temp.max())],
        "force_N": [float(s["force_N"].min()), float(s["force_N"].max())],
        "records": [str(r) for r in pd.unique(s["record"])],
    }
    return FrictionMap(vc, tc, table, covered=covered, law=law, statistics=stats, region=region)


@dataclass
class ThermalFit:
    """Result of :func:`identify_thermal`.

    Attributes
    ----------
    k1, k2 : float
        Conductances to the oil and to the housing [W/K] (Eq. 8).
    stderr : dict
        Standard errors [W/K], corrected for the correlation the smoothing
        window introduces between residuals.
    ci95 : dict
        95 % confidence intervals [W/K].
    correlation : float
        Correlation of the k1 and k2 estimates.
    rmse : float
        RMS residual of the heat balance [W].
    n_samples : int
    window : int
        Savitzky-Golay window [samples].
    """

    k1: float
    k2: float
    stderr: dict
    ci95: dict
    correlation: float
    rmse: float
    n_samples: int
    window: int
    residuals: np.ndarray = field(repr=False, default=None)

    def report(self) -> str:
        """Short text summary."""
        return (f"thermal identification (Eq. 8), {self.n_samples} samples, window {self.window}\n"
                f"  k1 = {self.k1:.4g} +/- {self.stderr['k1']:.2g} W/K  (95 %: {self.ci95['k1'][0]:.4g} .. {self.ci95['k1'][1]:.4g})\n"
                f"  k2 = {self.k2:.4g} +/- {self.stderr['k2']:.2g} W/K  (95 %: {self.ci95['k2'][0]:.4g} .. {self.ci95['k2'][1]:.4g})\n"
                f"  corr(k1, k2) = {self.correlation:.3f}, rms residual {self.rmse:.3g} W")


def identify_thermal(records, clutch: WetClutch, *, sensor_time_constant: float = 0.0,
                     window: float = 1.0) -> ThermalFit:
    """Conductances k1, k2 of the heat balance (Eq. 8) by linear least squares.

    ``C dT/dt - tau dw = -k1 (T - T_fluid) - k2 (T - T_housing)`` with the
    pack heat capacity C from the clutch parameters (Table 1).  Every term is
    passed through the same Savitzky-Golay filter [2] (cubic, ``window``
    seconds) and dT/dt is its derivative, so measurement noise is rejected
    without biasing the linear balance.

    Parameters
    ----------
    records : path, DataFrame or list of them
        Records in which the pack heats and cools (protocol (a)).
    clutch : WetClutch
        Provides the heat capacity ``N_c ((m c_p)_lining + (m c_p)_core)``.
    sensor_time_constant : float
        Thermistor lag to compensate [s] (``T = T_m + tau dT_m/dt``).
    window : float
        Smoothing window [s].

    Returns
    -------
    ThermalFit

    Raises
    ------
    ParameterError
        ``sensor_time_constant`` negative, NaN or infinite; ``window`` not > 0.
    IdentificationError
        If fluid and housing temperatures do not differ enough to separate
        k1 from k2 (the regressors are collinear), if a conductance comes out
        negative (non-physical) or its standard error is not smaller than
        its value (the records do not determine it).
    """
    from scipy import stats as sstats

    if not (math.isfinite(window) and window > 0):
        raise ParameterError(f"window = {window!r}: must be finite and > 0 [s]")
    sensor_time_constant = _check_time_constant(sensor_time_constant)
    cap = clutch.heat_capacity
    rows_a, rows_b = [], []
    nwin = 1
    for label, fr in _records(records):
        temp, dtemp, sg, nwin = _lag_corrected_temperature(fr, sensor_time_constant, window, label)
        power = sg(fr["torque_Nm"].to_numpy() * fr["slip_speed_rad_s"].to_numpy())  # tau * dw, [1], Eq. 8
        tf = sg(fr["fluid_temperature_C"].to_numpy())
        th = sg(fr["housing_temperature_C"].to_numpy())
        edge = nwin // 2
        sl = slice(edge, temp.size - edge)
        rows_a.append(np.column_stack([-(temp - tf)[sl], -(temp - th)[sl]]))
        rows_b.append((cap * dtemp - power)[sl])                                      # [1], Eq. 8
    a = np.vstack(rows_a)
    b = np.concatenate(rows_b)
    cond = np.linalg.cond(a)
    if not np.isfinite(cond) or cond > 1e6:
        raise IdentificationError(
            f"k1 and k2 cannot be separated (condition number {cond:.3g}): the fluid and housing "
            "temperatures must differ in the records")
    x, *_ = np.linalg.lstsq(a, b, rcond=None)
    res = b - a @ x
    n = b.size
    dof = max(n - 2, 1)
    s2 = float(res @ res) / dof
    cov = np.linalg.inv(a.T @ a) * s2 * nwin  # residuals are correlated over one window
    se = np.sqrt(np.diag(cov))
    q = sstats.t.ppf(0.975, max(n // nwin - 2, 1))
    corr = float(cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1]))
    for name, value, err in (("k1", x[0], se[0]), ("k2", x[1], se[1])):
        if value < 0 and not err > abs(value):
            raise IdentificationError(
                f"{name} = {value:.4g} +/- {err:.2g} W/K is negative, which a conductance cannot be: the heat "
                "balance (Eq. 8) does not describe the records (an engagement without a cooling phase, a wrong "
                "heat capacity or sensor lag?)")
        if not err < abs(value):
            raise IdentificationError(
                f"{name} = {value:.4g} +/- {err:.2g} W/K: the standard error is not smaller than the value, so "
                "the records do not determine it (record the pack heating and cooling well away from the "
                "fluid and housing temperatures)")
    return ThermalFit(float(x[0]), float(x[1]), {"k1": float(se[0]), "k2": float(se[1])},
                      {"k1": (float(x[0] - q * se[0]), float(x[0] + q * se[0])),
                       "k2": (float(x[1] - q * se[1]), float(x[1] + q * se[1]))},
                      corr, float(math.sqrt(np.mean(res**2))), int(n), int(nwin), res)
