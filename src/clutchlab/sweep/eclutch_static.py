"""Sweep target ``"eclutch-static"``: static release curves of the E-clutch axial models, per variant.

Each variant is :meth:`clutchlab.eclutch.ClutchModel.static_curve` (Newton
continuation of the axial network along the bearing travel, Haramina et al.
[1], Secs. 3-5) of Model ``n`` built from :class:`~clutchlab.eclutch.EClutchParameters`
with some fields changed (``clutch.<field>``: ``clutch.lever_ratio``,
``clutch.k_fl_model2``, ``clutch.diaphragm_prestrain``, ``clutch.mu`` ...).
There is no batch kernel (each network is rebuilt from the changed
parameters), so a chunk runs its variants in a loop; ``--workers N`` or Dask
spreads chunks over cores.

Scenario file (optional)::

    [eclutch]              # EClutchParameters, values may carry units
    lever_ratio = -3.8
    [eclutch.curves]       # optional folder of component CSV files, relative to this file
    folder = "curves/"
    [static]
    model = 4              # Model 0-4 of [1] (default 4)
    travel = "9 mm"        # release travel from the engaged clutch (default 9 mm)
    points = 181           # positions on the travel (default 181)

Outputs (per variant): ``engaged_normal_force`` [N] and ``engaged_torque``
[N*m] (``M_cl = 2 F_n r_eff mu``, [1] Sec. 3.2) at bearing position 0,
``peak_bearing_force`` [N] and ``peak_bearing_force_position`` [m] (maximum of
the release force over the travel, on the sampled positions),
``lift_off_position`` [m] (where the clamp force reaches zero, the secant of
the last two clamped samples extended to zero, see :func:`lift_off_position`;
NaN if the clutch does not open within the travel) and ``end_bearing_force`` [N] (at full travel).

References
----------
.. [1] Haramina et al., Trans. FAMENA 48 (2024) 21-35.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pandas as pd

from ..eclutch.models import COMPONENTS, MODEL_NUMBERS, ClutchModel, ComponentCurves, EClutchParameters
from ..errors import ParameterError
from ..units import to_si
from .targets import check_outputs, file_digest, nan_frame, rows, sweepable_fields, vary_parameter_set

__all__ = ["run_batch", "describe", "check_variants", "referenced_files", "OUTPUTS", "lift_off_position"]

OUTPUTS = {
    "engaged_normal_force": "N",
    "engaged_torque": "N*m",
    "peak_bearing_force": "N",
    "peak_bearing_force_position": "m",
    "lift_off_position": "m",
    "end_bearing_force": "N",
}
_STATIC_KEYS = ("model", "travel", "points")


@functools.lru_cache(maxsize=4)
def _curves(folder: str | None, digests: tuple = ()):  # keyed by content too: edited curves are read again
    return ComponentCurves.bundled() if folder is None else ComponentCurves.from_folder(folder)


def _curve_files(folder) -> list:
    return [Path(folder) / f"{name}.csv" for name in COMPONENTS]


def _curves_folder(data):
    """Absolute curves folder named by ``[eclutch.curves] folder`` (None: the bundled curves)."""
    spec = (data.get("eclutch") or {}).get("curves") if isinstance(data.get("eclutch"), dict) else None
    if spec is None:
        return None
    src = str(data.get("_source", "bundled defaults"))
    if not isinstance(spec, dict) or set(spec) != {"folder"} or not isinstance(spec["folder"], str):
        raise ParameterError(f"{src}: [eclutch.curves] must contain exactly one key 'folder' (a folder name)")
    return (Path(src).parent / spec["folder"]).resolve()


def referenced_files(scenario) -> list:
    """Files the scenario makes this target read: the component curves of ``[eclutch.curves] folder``, if any."""
    folder = _curves_folder(scenario or {})
    return [] if folder is None else _curve_files(folder)


def _base(scenario):
    data = {} if scenario is None else scenario
    src = str(data.get("_source", "bundled defaults"))
    tables = {k: v for k, v in data.items() if not k.startswith("_")}
    unknown = [k for k in tables if k not in ("eclutch", "static")]
    if unknown:
        raise ParameterError(f"{src}: unknown table [{unknown[0]}] (known: eclutch, static)")
    table = dict(tables.get("eclutch", {}))
    folder = _curves_folder(data)
    table.pop("curves", None)
    digests = ()
    if folder is not None:
        missing = [p for p in _curve_files(folder) if not p.is_file()]
        if missing:
            raise ParameterError(f"{src}: [eclutch.curves] folder = {str(folder)!r}: no file {missing[0].name}")
        digests = tuple(file_digest(p) for p in _curve_files(folder))
        folder = str(folder)
    params = EClutchParameters.from_dict(table, source=src)
    static = dict(tables.get("static", {}))
    bad = [k for k in static if k not in _STATIC_KEYS]
    if bad:
        raise ParameterError(f"{src}: [static] unknown key {bad[0]!r} (known: {', '.join(_STATIC_KEYS)})")
    model = static.get("model", 4)
    if isinstance(model, bool) or model not in MODEL_NUMBERS:
        raise ParameterError(f"{src}: [static] model = {model!r}: Haramina et al. define Models 0, 1, 2, 3 and 4")
    travel = to_si(static.get("travel", "9 mm"), "m", name="[static] travel", source=src)
    if not travel > 0:
        raise ParameterError(f"{src}: [static] travel = {static.get('travel')!r}: must be > 0")
    points = static.get("points", 181)
    if isinstance(points, bool) or not isinstance(points, int) or points < 3:
        raise ParameterError(f"{src}: [static] points = {points!r}: expected a whole number >= 3")
    return params, _curves(folder, digests), int(model), np.linspace(0.0, travel, points)


def describe(scenario) -> dict:
    """Sweepable parameters (name -> SI unit) and outputs (name -> unit) for ``scenario`` (dict or None)."""
    _base(scenario)
    return {"parameters": sweepable_fields("clutch", EClutchParameters), "outputs": dict(OUTPUTS)}


def check_variants(variants: pd.DataFrame, scenario) -> None:
    """Build every variant's parameter set; raise on the first one rejected.

    ``variants``: one row per variant (SI); ``scenario``: parsed scenario dict or None.
    """
    params, _, _, _ = _base(scenario)
    for vid, row in rows(variants):
        vary_parameter_set(params, "clutch", row, vid)


def lift_off_position(position, normal_force) -> float:
    """Bearing position [m] where the clamp force first reaches zero; NaN if it never does.

    Where the samples change sign the zero is interpolated linearly between
    them; where the force is clipped at zero (the contact opened, as in the
    axial network), the secant through the last two clamped samples is
    extended to zero and kept within the bracketing samples -- exact for a
    clamp force linear in the position over the last two clamped samples.

    Parameters
    ----------
    position : array_like
        Increasing bearing positions [m].
    normal_force : array_like
        Clamp force on the friction plate at those positions [N].
    """
    x = np.asarray(position, dtype=float)
    fn = np.asarray(normal_force, dtype=float)
    if fn[0] <= 0.0:
        return float(x[0])
    hit = np.flatnonzero(fn <= 0.0)
    if hit.size == 0:
        return float("nan")
    i = int(hit[0])
    if fn[i] < 0.0 or i < 2 or not fn[i - 2] > fn[i - 1]:
        # a sign change (or too few clamped samples): linear between the bracketing samples
        return float(x[i - 1] + fn[i - 1] / (fn[i - 1] - fn[i]) * (x[i] - x[i - 1]))
    # the model clips the clamp force at zero (contact opens): extend the secant of the last two
    # clamped samples to zero, kept within the bracket [x[i-1], x[i]]
    xz = x[i - 1] + fn[i - 1] * (x[i - 1] - x[i - 2]) / (fn[i - 2] - fn[i - 1])
    return float(min(max(xz, x[i - 1]), x[i]))


def run_batch(variants: pd.DataFrame, scenario, outputs) -> pd.DataFrame:
    """Static release curve of every variant, reduced to scalar outputs.

    Parameters
    ----------
    variants : pandas.DataFrame
        Index ``variant_id``; columns ``clutch.<field>`` [SI].
    scenario : dict or None
        Parsed scenario TOML (``_source`` = its path) or None for the defaults.
    outputs : list of str
        Names from :data:`OUTPUTS`.

    Returns
    -------
    pandas.DataFrame
        Same index, one column per output.
    """
    check_outputs("eclutch-static", outputs, OUTPUTS)
    params, curves, number, travel = _base(scenario)
    out = nan_frame(variants.index, outputs)
    values = np.full((len(variants), len(outputs)), np.nan)
    for k, (vid, row) in enumerate(rows(variants)):
        p = vary_parameter_set(params, "clutch", row, vid)
        curve = ClutchModel.preset(number, p, curves).static_curve(travel)
        x = curve["bearing_position_m"].to_numpy()
        fb = curve["bearing_force_N"].to_numpy()
        fn = curve["normal_force_N"].to_numpy()
        j = int(np.argmax(fb))
        got = {
            "engaged_normal_force": float(fn[0]),
            "engaged_torque": float(curve["torque_Nm"].iloc[0]),  # [1], Sec. 3.2: M_cl = 2 F_n r_eff mu
            "peak_bearing_force": float(fb[j]),
            "peak_bearing_force_position": float(x[j]),
            "lift_off_position": lift_off_position(x, fn),
            "end_bearing_force": float(fb[-1]),
        }
        values[k] = [got[name] for name in outputs]
    out.loc[:, :] = values
    return out
