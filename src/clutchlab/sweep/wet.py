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

Written against the system contract: every variant is the ``"wet"``
:class:`~clutchlab.system.System` (:func:`clutchlab.wet.system.engagement_system`)
with its own packed parameters -- clutch, bench, friction law, reference
profiles, scale factors -- and initial state, and all variants of a chunk
that share the duration and the absolute tolerances (which scale with
``clutch.piston_h0``) run in one call of :func:`clutchlab.system.simulate_batch`
(one Dormand-Prince 5(4) solver per variant, ``numba.prange``).  Sweeping
any field, the protocol and the friction law included, therefore keeps a
chunk in one parallel batch; only ``protocol.duration`` or
``clutch.piston_h0`` split it.  A variant's result does not depend on which
other variants share its batch, and equals :func:`clutchlab.wet.simulate_batch`
of the same variant bit for bit.

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
from ..system import simulate_batch
from ..wet import system as W
from ..wet.bench import PROTOCOL_TYPES, EngagementProtocol, MapProtocol
from ..wet.engagement import check_scenario
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
#: per-variant multipliers -> the constants of the packed parameters they set
_BATCH = {"batch.force_scale": "force_scale", "batch.mu_scale": "mu_scale", "batch.speed_scale": "speed_scale"}

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
    """Per variant: (batch key, System) -- the key groups variants that can share one batch call."""
    protocol, ptype, clutch, bench, friction = _base(scenario)
    motor = "free" if ptype == "inertia_dynamometer" else "speed"
    built = []
    geometry = "clutch.r_outer" in variants.columns or "clutch.r_inner" in variants.columns
    follow_area = geometry and "clutch.friction_area" not in variants.columns
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
            check_scenario(b, scen)
        except ParameterError as exc:
            raise ParameterError(f"variant {vid}: {exc}") from None
        scales = {}
        for key, field in _BATCH.items():
            if key in row:
                if not row[key] > 0:
                    raise ParameterError(f"variant {vid}: {key} = {row[key]!r}: must be > 0")
                scales[field] = float(row[key])
        params = W.pack_parameters(c, b, scen, f, **scales)
        x0 = W.initial_state(scen)
        x0[W.S_FA] *= scales.get("force_scale", 1.0)  # as simulate_batch: the actuator starts at the scaled reference
        atol = W.absolute_tolerance(c, RTOL)
        built.append(((scen.duration, atol.tobytes()), (scen, c, b, f, params, x0)))
    return built


def _systems(items) -> list:
    """The systems of one batch: the first built in full, the others variants of it (same tolerances)."""
    scen, c, b, f, params, x0 = items[0]
    first = W.engagement_system(scen, clutch=c, bench=b, friction=f, params=params, x0=x0, rtol=RTOL)
    return [first] + [first.variant(params=params, x0=x0, m0=W.initial_modes(x0, c.piston_h0))
                      for scen, c, b, f, params, x0 in items[1:]]


def check_variants(variants: pd.DataFrame, scenario) -> None:
    """Build every variant (parameter sets, scenario, bench limits) without simulating; raise on the first bad one.

    ``variants``: one row per variant (SI); ``scenario``: parsed scenario dict or None.
    """
    _build(variants, scenario)


def run_batch(variants: pd.DataFrame, scenario, outputs) -> pd.DataFrame:
    """Simulate every variant's engagement; one compiled ``prange`` batch per duration and tolerance.

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
    for i, (key, _) in enumerate(built):
        groups.setdefault(key, []).append(i)
    for (duration, _), members in groups.items():
        systems = _systems([built[i][1] for i in members])
        res = simulate_batch(systems, float(duration), sample_times=[duration], max_step=MAX_STEP,
                             max_steps=MAX_STEPS, outputs=False)
        final = res.states[:, -1, :]
        part = summary[members]
        part[:, 0] = [W.lockup_time(s.params) for s in systems]
        part[:, 1] = final[:, W.S_EF]
        part[:, 2] = [W.peak_temperature(s.params) for s in systems]
        part[:, 3] = final[:, W.S_T]
        part[:, 4] = final[:, W.S_W]
        part[:, 5] = res.stats["accepted_steps"]
        part[:, 6] = res.status
        summary[members] = part
    out = nan_frame(variants.index, outputs)
    failed = summary[:, 6] != 0
    for name in outputs:
        col = summary[:, _SUMMARY_COLUMN[name]].copy()
        if name not in ("n_steps", "status"):
            col[failed] = np.nan
        out[name] = col
    return out
