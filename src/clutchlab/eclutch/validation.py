"""Validation of the axial models against a full-clutch record ([1] Section 6, Fig. 12).

:func:`compare` evaluates a model's friction-free static curves at the
recorded bearing positions and returns error metrics; :func:`fit_model4_scales`
identifies the two Model 4 stiffness factors that [1] Section 5.4 tuned by
hand (20 for the yoke support, 1.3 for the diaphragm spring) by least squares
on the record instead.

References
----------
.. [1] K. Haramina et al., Trans. FAMENA 48 (2024) 21-35, doi:10.21278/TOF.483057923
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from ..errors import DataError, IdentificationError, SimulationError
from ..io import read_measurement
from .models import ClutchModel, ComponentCurves, EClutchParameters

__all__ = ["FULL_CLUTCH_COLUMNS", "read_full_clutch_record", "compare", "Model4Fit", "fit_model4_scales"]

FULL_CLUTCH_COLUMNS = ("time_s", "bearing_position_m", "bearing_force_N", "torque_Nm")


def read_full_clutch_record(source, name: str | None = None, channel_map=None, *,
                            rate: float | None = None) -> pd.DataFrame:
    """Read and validate a full-clutch record (CSV, Parquet or MDF 4 file, or DataFrame).

    Required columns: ``time_s``, ``bearing_position_m``, ``bearing_force_N``,
    ``torque_Nm`` (``pressure_Pa`` optional); time must increase strictly.
    Read through :func:`clutchlab.io.read_measurement`, so units stored in the
    file are converted to the ones the names state, and ``channel_map`` maps a
    logger's channel names (and units) onto these names.

    Parameters
    ----------
    source : str, Path or pandas.DataFrame
        The record.
    name : str, optional
        How to call it in error messages (default: the path).
    channel_map : ChannelMap, mapping or TOML path, optional
        Logger channel names and units -> the names above.
    rate : float, optional
        Resample onto a uniform time base [Hz].
    """
    frame = read_measurement(source, channel_map, required=FULL_CLUTCH_COLUMNS, rate=rate, name=name).frame
    frame.attrs["name"] = name if name is not None else (str(source) if not isinstance(source, pd.DataFrame)
                                                         else "record")
    return frame


def compare(model: ClutchModel, record: pd.DataFrame) -> dict[str, float]:
    """Error metrics of a model's static curves against a full-clutch record.

    The model (friction off) is evaluated at every recorded bearing position,
    release and engagement branches alike, so the metrics include the
    hysteresis that a friction-free model cannot describe.

    Returns
    -------
    dict
        ``rmse_force_N``, ``rmse_torque_Nm``, ``peak_force_N`` (model),
        ``peak_force_error_N`` (model peak minus recorded peak of the release
        branch), ``peak_force_error_pct``, ``max_torque_Nm``.

    Raises
    ------
    DataError
        If the record has no excitation: a constant bearing position, or no
        positive bearing force on the release branch (an all-zero record, or
        a force of reversed sign).
    """
    name = record.attrs.get("name", "record")
    u = record["bearing_position_m"].to_numpy()
    if not np.ptp(u) > 0:
        raise DataError(f"{name}: bearing_position_m is constant ({float(u[0]):g} m): the record has no release travel "
                        "to validate the models on")
    f_rec = record["bearing_force_N"].to_numpy()
    release = np.arange(u.size) <= int(np.argmax(u))
    if not f_rec[release].max() > 0:
        raise DataError(f"{name}: bearing_force_N is never > 0 on the release branch (max "
                        f"{float(f_rec[release].max()):g} N): no force was recorded, or its sign is reversed")
    sim = model.static_curve(u)
    e_f = sim["bearing_force_N"].to_numpy() - record["bearing_force_N"].to_numpy()
    e_t = sim["torque_Nm"].to_numpy() - record["torque_Nm"].to_numpy()
    measured_peak = float(f_rec[release].max())
    model_peak = float(sim["bearing_force_N"].max())
    return {
        "rmse_force_N": float(np.sqrt(np.mean(e_f**2))),
        "rmse_torque_Nm": float(np.sqrt(np.mean(e_t**2))),
        "peak_force_N": model_peak,
        "peak_force_error_N": model_peak - measured_peak,
        "peak_force_error_pct": 100.0 * (model_peak - measured_peak) / measured_peak,
        "max_torque_Nm": float(sim["torque_Nm"].max()),
    }


@dataclasses.dataclass(frozen=True)
class Model4Fit:
    """Result of :func:`fit_model4_scales`.

    Attributes
    ----------
    support_scale, diaphragm_scale : float
        Best stiffness factors of the yoke support and the diaphragm spring [-].
    standard_errors : tuple of float
        Their standard errors from the Jacobian at the optimum [-].
    correlation : float
        Correlation coefficient of the two estimates [-].
    rmse_force_N, rmse_torque_Nm : float
        Residual statistics at the optimum.
    params : EClutchParameters
        The parameter set with the fitted factors.
    at_bound : tuple of bool
        Whether each factor ended on a bound of the search (then the record
        does not determine it, and its standard error is not meaningful).
    """

    support_scale: float
    diaphragm_scale: float
    standard_errors: tuple
    correlation: float
    rmse_force_N: float
    rmse_torque_Nm: float
    params: EClutchParameters
    at_bound: tuple = (False, False)

    def report(self) -> str:
        """Readable summary."""
        flag = [" (at the search bound: not determined by the record)" if b else "" for b in self.at_bound]
        return (f"Model 4 stiffness factors (least squares on the full-clutch record)\n"
                f"  support_scale   = {self.support_scale:.4g} +/- {self.standard_errors[0]:.2g}{flag[0]}\n"
                f"  diaphragm_scale = {self.diaphragm_scale:.4g} +/- {self.standard_errors[1]:.2g}{flag[1]}\n"
                f"  correlation     = {self.correlation:+.3f}\n"
                f"  RMSE force {self.rmse_force_N:.4g} N, torque {self.rmse_torque_Nm:.4g} N*m")


def fit_model4_scales(record: pd.DataFrame, params: EClutchParameters | None = None,
                      curves: ComponentCurves | None = None, *, torque_weight: float | None = None,
                      n_points: int = 120, bounds=((0.2, 0.3), (200.0, 3.0))) -> Model4Fit:
    """Identify the Model 4 stiffness factors of the yoke support and diaphragm spring.

    [1] Section 5.4 scaled ``k_ys.eq`` by 20 and ``k_ds`` by 1.3 until Model 4
    matched the full-clutch curves; this does the same by bounded nonlinear
    least squares (``scipy.optimize.least_squares``, trust-region reflective)
    on the bearing force and the torque of the record, each residual
    normalised by its range (or weighted by ``torque_weight``).  The factors are
    fitted in log space, starting from the paper's values.

    Parameters
    ----------
    record : pandas.DataFrame
        Full-clutch record (see :func:`read_full_clutch_record`).
    params, curves :
        Model parameters and component curves (defaults: bundled).
    torque_weight : float, optional
        Weight of torque residuals [N per N*m]; default: ratio of the ranges.
    n_points : int
        Number of record samples used (evenly spaced in index).
    bounds : ((low_support, low_diaphragm), (high_support, high_diaphragm))
        Bounds of the factors [-].

    Raises
    ------
    IdentificationError
        If the optimiser fails.
    """
    from scipy.optimize import least_squares

    params = params or EClutchParameters()
    curves = curves or ComponentCurves.bundled()
    idx = np.unique(np.linspace(0, len(record) - 1, n_points).astype(int))
    sub = record.iloc[idx]
    u = sub["bearing_position_m"].to_numpy()
    f_meas = sub["bearing_force_N"].to_numpy()
    t_meas = sub["torque_Nm"].to_numpy()
    w = torque_weight if torque_weight is not None else np.ptp(f_meas) / max(np.ptp(t_meas), 1e-9)

    def residual(logs):
        p = params.replace(support_scale=float(np.exp(logs[0])), diaphragm_scale=float(np.exp(logs[1])))
        try:
            sim = ClutchModel.preset(4, p, curves).static_curve(u, extrapolate=True)
        except SimulationError:
            return np.full(2 * u.size, 1e6)
        return np.concatenate([sim["bearing_force_N"].to_numpy() - f_meas, w * (sim["torque_Nm"].to_numpy() - t_meas)])

    lo = np.log(bounds[0])
    hi = np.log(bounds[1])
    x0 = np.clip(np.log([params.support_scale, params.diaphragm_scale]), lo + 1e-9, hi - 1e-9)
    sol = least_squares(residual, x0, bounds=(lo, hi), x_scale=1.0, diff_step=1e-4)
    if not sol.success:
        raise IdentificationError(f"Model 4 scale fit failed: {sol.message}")
    scales = np.exp(sol.x)
    r = sol.fun
    n, m = r.size, sol.x.size
    s2 = float(r @ r) / max(n - m, 1)
    try:
        cov_log = np.linalg.inv(sol.jac.T @ sol.jac) * s2
        se = scales * np.sqrt(np.diag(cov_log))  # delta method from log space
        corr = float(cov_log[0, 1] / np.sqrt(cov_log[0, 0] * cov_log[1, 1]))
    except np.linalg.LinAlgError:
        se, corr = np.array([np.nan, np.nan]), float("nan")
    k = u.size
    return Model4Fit(
        support_scale=float(scales[0]), diaphragm_scale=float(scales[1]), standard_errors=(float(se[0]), float(se[1])),
        correlation=corr, rmse_force_N=float(np.sqrt(np.mean(r[:k] ** 2))),
        rmse_torque_Nm=float(np.sqrt(np.mean((r[k:] / w) ** 2))),
        params=params.replace(support_scale=float(scales[0]), diaphragm_scale=float(scales[1])),
        at_bound=tuple(bool(min(x - l, h - x) < 1e-6) for x, l, h in zip(sol.x, lo, hi)),
    )
