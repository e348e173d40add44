"""Sweep target ``"eclutch"``: E-clutch dynamics (actuator + Model 0-4 with friction) per variant.

Used by ``clutchlab sweep`` (:mod:`clutchlab.sweep`): each variant is the
scenario of :mod:`clutchlab.eclutch.scenario` with some parameters changed --
``clutch.<field>`` (:class:`~clutchlab.eclutch.EClutchParameters`, e.g.
``clutch.lever_ratio``, ``clutch.diaphragm_scale``), ``actuator.<field>``
(:class:`~clutchlab.eclutch.ActuatorParameters`, e.g. ``actuator.kp``,
``actuator.bulk_modulus``) and ``friction.<field>``
(:class:`~clutchlab.eclutch.FrictionParameters`).  Variants that share the
model structure run as one compiled ``prange`` batch
(:func:`~clutchlab.eclutch.dynamics.simulate_batch`), one solver per variant.

Outputs per variant:

============================  =====  =====================================================
``peak_bearing_force``        N      maximum of ``p A_sl``
``peak_pressure``             Pa     maximum CSC pressure
``release_time``              s      first time the clutch torque falls below 5 % of its
                                     engaged value (NaN if it never does)
``reengage_time``             s      first time after the release that the torque is back
                                     above 95 % (NaN if it is not)
``final_bearing_position``    m      at the end of the run
``max_current``               A      maximum of ``|i|``
``friction_dissipated``       J      energy dissipated by every friction element
``input_work``                J      electrical energy into the motor
``tracking_error_rms``        m      RMS of reference minus position (position control)
============================  =====  =====================================================
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from ..errors import ParameterError
from ..sweep.targets import check_outputs
from .actuator import ActuatorParameters
from .dynamics import EClutch, FrictionParameters, simulate_batch
from .models import ClutchModel, EClutchParameters
from .scenario import Scenario, scenario_from_dict

__all__ = ["run_batch", "describe", "check_variants", "OUTPUTS"]

OUTPUTS = {
    "peak_bearing_force": "N",
    "peak_pressure": "Pa",
    "release_time": "s",
    "reengage_time": "s",
    "final_bearing_position": "m",
    "max_current": "A",
    "friction_dissipated": "J",
    "input_work": "J",
    "tracking_error_rms": "m",
}
_SETS = (("clutch", EClutchParameters, "clutch"), ("actuator", ActuatorParameters, "actuator"),
         ("friction", FrictionParameters, "friction"))


def _scenario(scenario) -> Scenario:
    if scenario is None:
        return Scenario(output_step=1e-3)
    src = str(scenario.get("_source", "scenario"))
    sc = scenario_from_dict(scenario, source=src)
    if sc.input_kind == "bearing_position":
        raise ParameterError(f"{src}: the 'eclutch' sweep simulates the actuator; use input kind voltage, "
                             "bearing_reference or pedal")
    return sc if sc.output_step is not None else dataclasses.replace(sc, output_step=1e-3)


def describe(scenario) -> dict:
    """Sweepable parameters (name -> SI unit) and outputs (name -> unit)."""
    _scenario(scenario)
    params = {}
    for prefix, cls, _ in _SETS:
        for f in dataclasses.fields(cls):
            if "unit" in f.metadata:
                params[f"{prefix}.{f.name}"] = f.metadata["unit"]
    return {"parameters": params, "outputs": dict(OUTPUTS)}


def _variant(sc: Scenario, row: dict, vid) -> EClutch:
    sets = {"clutch": sc.clutch, "actuator": sc.actuator, "friction": sc.friction}
    changes = {k: {} for k in sets}
    for name, value in row.items():
        prefix, _, field = name.partition(".")
        if prefix not in sets:
            raise ParameterError(f"variant {vid}: parameter {name!r} (use clutch.*, actuator.*, friction.*)")
        changes[prefix][field] = value
    try:
        built = {k: (sets[k].replace(**changes[k]) if changes[k] else sets[k]) for k in sets}
    except ParameterError as exc:
        raise ParameterError(f"variant {vid}: {exc}") from None
    model = ClutchModel.preset(sc.model, built["clutch"])
    if sc.wear_m or sc.temperature_rise_k:
        from .dynamics import apply_wear_and_expansion

        model = apply_wear_and_expansion(model, wear_m=sc.wear_m, temperature_rise_k=sc.temperature_rise_k)
    actuator = built["actuator"]
    if "actuator.csc_preload" not in row:
        actuator = actuator.replace(csc_preload=built["clutch"].bearing_preload)
    return EClutch(actuator, model, built["friction"])


def check_variants(variants: pd.DataFrame, scenario) -> None:
    """Build every variant; raise on the first one rejected."""
    sc = _scenario(scenario)
    for vid, row in zip(variants.index, variants.to_dict("records")):
        _variant(sc, row, vid)


def _reduce(t, out: dict, k: int, position_mode: bool) -> dict:
    tq = out["torque_Nm"][k]
    t0 = tq[0]
    rel = np.flatnonzero(tq < 0.05 * t0)
    release = float(t[rel[0]]) if rel.size else np.nan
    reeng = np.nan
    if rel.size:
        back = np.flatnonzero((tq >= 0.95 * t0) & (np.arange(tq.size) > rel[0]))
        reeng = float(t[back[0]]) if back.size else np.nan
    err = np.nan
    if position_mode:
        e = out["reference_m"][k] - out["bearing_position_m"][k]
        err = float(np.sqrt(np.mean(e ** 2)))
    return {
        "peak_bearing_force": float(out["bearing_force_N"][k].max()),
        "peak_pressure": float(out["pressure_Pa"][k].max()),
        "release_time": release,
        "reengage_time": reeng,
        "final_bearing_position": float(out["bearing_position_m"][k][-1]),
        "max_current": float(np.abs(out["motor_current_A"][k]).max()),
        "friction_dissipated": float(out["friction_dissipated_J"][k][-1]),
        "input_work": float(out["input_work_J"][k][-1]),
        "tracking_error_rms": err,
    }


def run_batch(variants: pd.DataFrame, scenario, outputs) -> pd.DataFrame:
    """Simulate every variant (compiled batch) and reduce it to the requested outputs.

    Parameters
    ----------
    variants : pandas.DataFrame
        Index ``variant_id``; columns ``clutch.*``, ``actuator.*``, ``friction.*`` in SI units.
    scenario : dict or None
        Parsed scenario TOML (``_source`` = its path) or None (pedal press and release, Model 4).
    outputs : list of str
        Names from :data:`OUTPUTS`.
    """
    check_outputs("eclutch", outputs, OUTPUTS)
    sc = _scenario(scenario)
    ecs = [_variant(sc, row, vid) for vid, row in zip(variants.index, variants.to_dict("records"))]
    t, v = sc.input_table()
    key = "voltage" if sc.input_kind == "voltage" else "bearing_reference"
    values = np.full((len(ecs), len(outputs)), np.nan)
    # variants with the same structure run together (component curves may differ, e.g. support_max_force)
    groups: dict = {}
    for k, ec in enumerate(ecs):
        s = ec.system
        sig = (s.nz, s.cx.tobytes(), s.cf.tobytes(), s.fr_on.tobytes(), s.fr_nidx.tobytes(), s.fr_pidx.tobytes())
        groups.setdefault(sig, []).append(k)
    for idx in groups.values():
        res = simulate_batch([ecs[k] for k in idx], {key: (t, v)}, sc.t_end, output_step=sc.output_step,
                             rtol=sc.rtol)
        for j, k in enumerate(idx):
            if res.stats["status"].iloc[j] != 0:
                continue
            got = _reduce(res.time, res.outputs, j, key == "bearing_reference")
            values[k] = [got[o] for o in outputs]
    return pd.DataFrame(values, index=variants.index, columns=list(outputs))
