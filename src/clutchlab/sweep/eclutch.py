"""Sweep target ``"eclutch"``: E-clutch dynamics (actuator + Model 0-4 with friction) per variant.

Used by ``clutchlab sweep`` (:mod:`clutchlab.sweep`): each variant is the
scenario of :mod:`clutchlab.eclutch.scenario` with some parameters changed --
``clutch.<field>`` (:class:`~clutchlab.eclutch.EClutchParameters`, e.g.
``clutch.lever_ratio``, ``clutch.diaphragm_scale``), ``actuator.<field>``
(:class:`~clutchlab.eclutch.ActuatorParameters`, e.g. ``actuator.kp``,
``actuator.bulk_modulus``) and ``friction.<field>``
(:class:`~clutchlab.eclutch.FrictionParameters`).  Variants that share the
model structure run as one compiled ``prange`` batch of the system contract
(:func:`clutchlab.system.simulate_batch` over
:meth:`~clutchlab.eclutch.dynamics.EClutch.as_system`), one solver per variant.

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
from ..numerics.status import Status
from ..params.base import model_fields
from ..sweep.targets import check_outputs
from ..system import simulate_batch
from ..eclutch.actuator import ActuatorParameters
from ..eclutch.dynamics import EClutch, FrictionParameters
from ..eclutch.models import ClutchModel, EClutchParameters
from ..eclutch.scenario import Scenario, scenario_from_dict

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
        for f in model_fields(cls):
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
        from ..eclutch.dynamics import apply_wear_and_expansion

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


def _reduce(res, k: int, position_mode: bool) -> dict:
    """The sweep outputs of variant ``k`` of a stacked :class:`~clutchlab.SimulationResult`."""
    t = res.time
    out = {name: res[name] for name in ("torque_Nm", "bearing_position_m", "bearing_force_N", "pressure_Pa",
                                         "motor_current_A", "friction_dissipated_J", "input_work_J")}
    if position_mode:
        out["reference_m"] = res["reference_m"]
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
    # variants with the same structure (state, output and mode layout) run together as one compiled batch
    groups: dict = {}
    for k, ec in enumerate(ecs):
        groups.setdefault(ec.assembly.signature(), []).append(k)
    for idx in groups.values():
        systems = [ecs[k].as_system({key: (t, v)}, rtol=sc.rtol) for k in idx]
        res = simulate_batch(systems, sc.t_end, output_step=sc.output_step, max_steps=500_000)
        for j, k in enumerate(idx):
            if not Status(int(res.status[j])).ok:
                continue
            got = _reduce(res, j, key == "bearing_reference")
            values[k] = [got[o] for o in outputs]
    return pd.DataFrame(values, index=variants.index, columns=list(outputs))
