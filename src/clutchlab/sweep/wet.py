"""Sweep target ``"wet"``: wet-clutch engagements as one compiled ``prange`` batch per chunk.

Each variant is the bench protocol of the scenario file (the
``clutchlab wet simulate`` format: ``[protocol]`` with ``type``, optional
``[wet]``, ``[bench]``, ``[friction]`` tables; default: the bundled
engagement protocol, Fig. 14 of Shin et al.) with some parameters changed:

* ``clutch.<field>`` -- :class:`clutchlab.wet.WetClutch` (the ``[wet]`` table),
  e.g. ``clutch.r_outer``, ``clutch.k1``, ``clutch.sigma``; when a radius is
  swept and ``clutch.friction_area`` is not, the friction area follows the
  annulus ``pi (R_o^2 - R_i^2)`` ([1], Eq. (1')) with the base clutch's ratio
  of friction area to annulus (1 for the defaults: grooves neglected);
* ``bench.<field>`` -- :class:`clutchlab.wet.Bench`;
* ``friction.<field>`` -- :class:`clutchlab.wet.ParametricFriction` (the true
  friction law of the virtual bench, base :meth:`~ParametricFriction.bench_truth`);
* ``protocol.<field>`` -- the protocol (:class:`~clutchlab.wet.EngagementProtocol`
  or :class:`~clutchlab.wet.MapProtocol`), e.g. ``protocol.force``,
  ``protocol.initial_slip_speed``;
* ``batch.force_scale``, ``batch.mu_scale``, ``batch.speed_scale`` -- the
  per-variant multipliers of :func:`clutchlab.wet.simulate_batch`.

All variants of a chunk that share the reference profiles, the friction law
and the absolute tolerances (which scale with ``clutch.sigma``) run in one call
of the compiled batch kernel of :mod:`clutchlab.wet.engagement` (one DOPRI 5(4)
solver per variant, ``numba.prange``), with their own parameter vector
(``parameter_vector``) and initial state each -- so sweeping any clutch or
bench field keeps the whole chunk in one parallel batch.  The force and
slip-speed reference profiles are normalised to a peak of one and their
levels moved into the kernel's per-variant scale factors whenever a
``protocol.*`` parameter is swept, so sweeping ``protocol.force``,
``protocol.initial_slip_speed`` or the temperatures also keeps one batch.  Sweeping the timing of the protocol (rise, ramp,
duration), the friction law or ``clutch.sigma`` (the absolute tolerance of
the piston position scales with it) splits a chunk into one batch per
distinct value (a Monte Carlo over ``friction.mu0`` runs one variant per
batch call).  A variant's result does not depend on which other variants
share its batch.  It equals :func:`clutchlab.wet.simulate_batch` of the same
variant bit for bit when no ``protocol.*`` parameter is swept; otherwise the
normalised profiles (rounded to 1e-13 of the peak) change the step sequence
and the results agree within the integration tolerance (``rtol`` = 1e-6).

Outputs (per variant): ``engagement_time`` [s] (lock-up time, NaN if the
clutch did not lock), ``energy`` [J] (friction work, the integral of
``tau * omega`` over the run, [1] Eq. 8's heat source), ``peak_temperature_c``
and ``final_temperature_c`` [degC] (pack temperature, [1] Eq. 8),
``final_slip_speed`` [rad/s], ``n_steps`` (accepted steps) and ``status``
(0 success, 1 step limit, 2 step-size underflow; the physical outputs of a
failed variant are NaN).

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
"""

from __future__ import annotations

import functools
import math
from importlib import resources

import numpy as np
import pandas as pd

from ..errors import ParameterError
from ..params import load_toml
from ..wet.bench import PROTOCOL_TYPES, EngagementProtocol, MapProtocol
from ..wet.engagement import (
    P_FSCALE, P_MUSCALE, P_WSCALE, S_FA, _atol, _check_scenario, _integrate_batch, initial_state, parameter_vector,
)
from ..wet.film import gw_table
from ..wet.friction import ParametricFriction
from ..wet.params import Bench, WetClutch
from .targets import check_outputs, nan_frame, rows, sweepable_fields, vary_parameter_set

__all__ = ["run_batch", "describe", "check_variants", "OUTPUTS", "RTOL", "MAX_STEP", "MAX_STEPS"]

#: outputs and their units
OUTPUTS = {
    "engagement_time": "s",
    "energy": "J",
    "peak_temperature_c": "degC",
    "final_temperature_c": "degC",
    "final_slip_speed": "rad/s",
    "n_steps": "1",
    "status": "1",
}
_SUMMARY_COLUMN = {"engagement_time": 0, "energy": 1, "peak_temperature_c": 2, "final_temperature_c": 3,
                   "final_slip_speed": 4, "n_steps": 5, "status": 6}
_BATCH = {"batch.force_scale": P_FSCALE, "batch.mu_scale": P_MUSCALE, "batch.speed_scale": P_WSCALE}

#: step control of every variant (the defaults of :func:`clutchlab.wet.simulate_batch`)
RTOL = 1e-6
MAX_STEP = 0.01
MAX_STEPS = 1_000_000


@functools.lru_cache(maxsize=1)
def _bundled_scenario() -> dict:
    path = resources.files("clutchlab.wet") / "data" / "engagement_protocol.toml"
    data = dict(load_toml(path))
    data["_source"] = "bundled clutchlab/wet/data/engagement_protocol.toml"
    return data


def _base(scenario):
    """(protocol, protocol type, clutch, bench, friction) of the scenario (as :func:`clutchlab.wet.load_protocol`)."""
    data = _bundled_scenario() if scenario is None else scenario
    src = str(data.get("_source", "scenario"))
    tables = {k: v for k, v in data.items() if not k.startswith("_")}
    unknown = [k for k in tables if k not in ("protocol", "wet", "bench", "friction")]
    if unknown:
        raise ParameterError(f"{src}: unknown table [{unknown[0]}] (known: protocol, wet, bench, friction)")
    if not isinstance(tables.get("protocol"), dict):
        raise ParameterError(f"{src}: missing [protocol] table")
    table = dict(tables["protocol"])
    ptype = table.pop("type", None)
    if ptype not in PROTOCOL_TYPES:
        raise ParameterError(f"{src}: [protocol] type = {ptype!r}: expected one of {', '.join(PROTOCOL_TYPES)}")
    cls = MapProtocol if ptype == "friction_map" else EngagementProtocol
    protocol = cls.from_dict(table, source=src)
    clutch = WetClutch.from_dict(tables.get("wet", {}), source=src)
    bench = Bench.from_dict(tables.get("bench", {}), source=src)
    truth = ParametricFriction.bench_truth()
    friction = ParametricFriction.from_dict(tables["friction"], source=src, base=truth) if "friction" in tables else truth
    return protocol, ptype, clutch, bench, friction


def describe(scenario) -> dict:
    """Sweepable parameters (name -> SI unit) and outputs (name -> unit) for ``scenario`` (dict or None)."""
    protocol, _, _, _, _ = _base(scenario)
    params = {}
    params.update(sweepable_fields("clutch", WetClutch))
    params.update(sweepable_fields("bench", Bench))
    params.update(sweepable_fields("friction", ParametricFriction))
    params.update(sweepable_fields("protocol", type(protocol)))
    params.update({k: "1" for k in _BATCH})
    return {"parameters": params, "outputs": dict(OUTPUTS)}


def _build(variants: pd.DataFrame, scenario):
    """Per variant: parameter vector, initial state, and the batch key (profiles, friction, tolerances)."""
    protocol, ptype, clutch, bench, friction = _base(scenario)
    motor = "free" if ptype == "inertia_dynamometer" else "speed"
    built = []
    geometry = "clutch.r_outer" in variants.columns or "clutch.r_inner" in variants.columns
    follow_area = geometry and "clutch.friction_area" not in variants.columns
    # only when the protocol is swept do the profiles differ between variants (decided per spec, not per chunk)
    normalise = any(str(col).startswith("protocol.") for col in variants.columns)
    area_ratio = clutch.friction_area / (math.pi * (clutch.r_outer**2 - clutch.r_inner**2))
    for vid, row in rows(variants):
        if follow_area:  # the friction area follows the annulus (same land fraction as the base clutch)
            ro = row.get("clutch.r_outer", clutch.r_outer)
            ri = row.get("clutch.r_inner", clutch.r_inner)
            row["clutch.friction_area"] = area_ratio * math.pi * max(ro**2 - ri**2, 0.0) or clutch.friction_area
        c = vary_parameter_set(clutch, "clutch", row, vid)
        b = vary_parameter_set(bench, "bench", row, vid)
        f = vary_parameter_set(friction, "friction", row, vid)
        pr = vary_parameter_set(protocol, "protocol", row, vid)
        try:
            scen = pr.scenario(c) if ptype == "friction_map" else pr.scenario(c, motor=motor)
            _check_scenario(b, scen)
        except ParameterError as exc:
            raise ParameterError(f"variant {vid}: {exc}") from None
        p = parameter_vector(c, b, scen)
        for key, col in _BATCH.items():
            if key in row:
                if not row[key] > 0:
                    raise ParameterError(f"variant {vid}: {key} = {row[key]!r}: must be > 0")
                p[col] = row[key]
        y = initial_state(scen)
        y[S_FA] *= p[P_FSCALE]  # as simulate_batch: the actuator starts at the scaled reference
        # reference profiles normalised to a peak of 1, their amplitudes carried by the per-variant scale
        # factors of the kernel: variants differing only in force or speed level share one batch
        fv, sv = scen.force_value, scen.speed_value
        f_amp = float(np.max(np.abs(fv))) if normalise else 0.0
        s_amp = float(np.max(np.abs(sv))) if normalise else 0.0
        if f_amp > 0:
            fv = np.round(fv / f_amp, 13)  # rounded so that levels of one shape give identical arrays
            p[P_FSCALE] *= f_amp
        if s_amp > 0:
            sv = np.round(sv / s_amp, 13)
            p[P_WSCALE] *= s_amp
        fdata = f.kernel_data()
        atol = _atol(c)
        key = (scen.duration, scen.force_time.tobytes(), fv.tobytes(), scen.speed_time.tobytes(), sv.tobytes(),
               fdata[1].tobytes(), atol.tobytes())
        built.append((key, p, y, (scen.duration, scen.force_time, fv, scen.speed_time, sv), fdata, atol))
    return built


def check_variants(variants: pd.DataFrame, scenario) -> None:
    """Build every variant (parameter sets, scenario, bench limits) without simulating; raise on the first bad one.

    ``variants``: one row per variant (SI); ``scenario``: parsed scenario dict or None.
    """
    _build(variants, scenario)


def run_batch(variants: pd.DataFrame, scenario, outputs) -> pd.DataFrame:
    """Simulate every variant's engagement; one compiled ``prange`` batch per group of shared profiles.

    Parameters
    ----------
    variants : pandas.DataFrame
        Index ``variant_id``; columns as listed by :func:`describe` [SI].
    scenario : dict or None
        Parsed protocol TOML (``_source`` = its path) or None for the bundled engagement.
    outputs : list of str
        Names from :data:`OUTPUTS`.

    Returns
    -------
    pandas.DataFrame
        Same index, one column per output.
    """
    check_outputs("wet", outputs, OUTPUTS)
    built = _build(variants, scenario)
    m = len(built)
    summary = np.full((m, 8), np.nan)
    groups: dict = {}
    for i, item in enumerate(built):
        groups.setdefault(item[0], []).append(i)
    g0, gdt, gv, gd = gw_table()
    for members in groups.values():
        _, _, _, (duration, ft, fv, st, sv), fdata, atol = built[members[0]]
        pmat = np.ascontiguousarray(np.array([built[i][1] for i in members]))
        ymat = np.ascontiguousarray(np.array([built[i][2] for i in members]))
        ts = np.array([duration])
        out_y = np.zeros((len(members), 1, ymat.shape[1]))
        part = np.zeros((len(members), 8))
        fk, fc, fgv, fgt, fgf, ftab = fdata
        _integrate_batch(pmat, ymat, float(duration), ts, RTOL, atol, MAX_STEP, MAX_STEPS,
                         int(fk), fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, out_y, part)
        summary[members] = part
    out = nan_frame(variants.index, outputs)
    failed = summary[:, 6] != 0
    for name in outputs:
        col = summary[:, _SUMMARY_COLUMN[name]].copy()
        if name not in ("n_steps", "status"):
            col[failed] = np.nan
        out[name] = col
    return out
