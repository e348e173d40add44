"""Sweep target ``"emtc"``: the EMTC drum-bench vehicle simulation, a batch of variants.

Written against the system contract: each variant is the ``emtc_bench``
system (:func:`clutchlab.emtc.system.bench_system`, its own packed parameters
and hysteresis memories); variants with the same duration and sample time
run as one :func:`clutchlab.system.simulate_batch` (one solver per variant in
``prange``), recorded at the controller samples exactly as
:func:`clutchlab.emtc.simulate_bench` records them (the same compiled code,
the same numbers).  A variant whose hysteresis memory fills up is repeated
alone with a larger memory; any other failed variant raises
:class:`~clutchlab.errors.SimulationError` naming it.

Each variant is the scenario file (the ``clutchlab emtc simulate`` format:
``[scenario]``, ``[vehicle]``, ``[actuator]``, ``[coupling]``, ``[magnet]``;
default: all defaults and the bundled synthetic magnet) with some parameters
changed: ``scenario.<field>`` (:class:`~clutchlab.emtc.bench.BenchScenario`),
``vehicle.<field>``, ``actuator.<field>``, ``coupling.<field>`` (scalar fields).

Outputs (per variant), from the coupling torque ``T_c`` of [1] Eqs. 13-21
and the speeds of Eq. 27: ``peak_coupling_torque`` and
``mean_coupling_torque`` and ``final_coupling_torque`` [N*m] (max of
``|T_c|``, time mean over the output samples, last sample),
``peak_slip_speed`` and ``final_slip_speed`` [rad/s] (``omega_f - omega_r``),
``lock_time`` [s] (first lock-up event, NaN if none), ``peak_magnet_force``
[N] (Preisach force, Eqs. 6-7) and ``n_steps``.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557, doi:10.3390/pr7090557
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pandas as pd

from .._limits import check_allocation
from ..errors import ParameterError, SimulationError
from ..emtc.bench import ActuatorParameters, BenchScenario, VehicleParameters, simulate_bench
from ..emtc.system import BenchOptions, bench_system, memory_full
from ..emtc.torque import CouplingGeometry
from ..numerics.status import Status
from .targets import check_outputs, file_digest, nan_frame, rows, sweepable_fields, vary_parameter_set

__all__ = ["run_batch", "describe", "check_variants", "referenced_files", "OUTPUTS"]

OUTPUTS = {
    "peak_coupling_torque": "N*m",
    "mean_coupling_torque": "N*m",
    "final_coupling_torque": "N*m",
    "peak_slip_speed": "rad/s",
    "final_slip_speed": "rad/s",
    "lock_time": "s",
    "peak_magnet_force": "N",
    "n_steps": "1",
}
_SETS = (("scenario", BenchScenario), ("vehicle", VehicleParameters), ("actuator", ActuatorParameters),
         ("coupling", CouplingGeometry))


@functools.lru_cache(maxsize=1)
def _bundled_magnet():
    from ..emtc.magnet import bundled_magnet

    return bundled_magnet()


@functools.lru_cache(maxsize=4)
def _magnet_from(path: str, digest: str):  # keyed by content too: an edited file is read again
    from ..hysteresis import Preisach

    return Preisach.from_json(path)


def _base(scenario):
    data = {} if scenario is None else scenario
    src = str(data.get("_source", "bundled defaults"))
    tables = {k: v for k, v in data.items() if not k.startswith("_")}
    known = ("scenario", "vehicle", "actuator", "coupling", "magnet")
    unknown = [k for k in tables if k not in known]
    if unknown:
        raise ParameterError(f"{src}: unknown table [{unknown[0]}] (known: {', '.join(known)})")
    sets = {name: cls.from_dict(tables.get(name, {}), source=src) for name, cls in _SETS}
    mag = tables.get("magnet", {})
    if mag:
        if not isinstance(mag, dict) or set(mag) != {"model"}:
            raise ParameterError(f"{src}: [magnet] takes only model = 'path/to/model.json'")
        if not isinstance(mag["model"], str):
            raise ParameterError(f"{src}: [magnet] model = {mag['model']!r}: expected a file name")
        path = _magnet_path(data)
        if not path.is_file():
            raise ParameterError(f"{src}: [magnet] model = {mag['model']!r}: no such file {path}")
        sets["magnet"] = _magnet_from(str(path), file_digest(path))
    else:
        sets["magnet"] = _bundled_magnet()
    return sets


def _magnet_path(data) -> Path:
    return (Path(str(data.get("_source", "."))).parent / data["magnet"]["model"]).resolve()


def referenced_files(scenario) -> list:
    """Files the scenario makes this target read: the Preisach model of ``[magnet] model``, if any."""
    mag = (scenario or {}).get("magnet")
    return [_magnet_path(scenario)] if isinstance(mag, dict) and isinstance(mag.get("model"), str) else []


def describe(scenario) -> dict:
    """Sweepable parameters (name -> SI unit) and outputs (name -> unit) for ``scenario`` (dict or None)."""
    _base(scenario)
    params = {}
    for name, cls in _SETS:
        params.update(sweepable_fields(name, cls))
    return {"parameters": params, "outputs": dict(OUTPUTS)}


def _variants(variants, scenario):
    base = _base(scenario)
    for vid, row in rows(variants):
        sets = {name: vary_parameter_set(base[name], name, row, vid) for name, _ in _SETS}
        yield vid, sets, base["magnet"]


def check_variants(variants: pd.DataFrame, scenario) -> None:
    """Build every variant's parameter sets; raise on the first one rejected.

    ``variants``: one row per variant (SI); ``scenario``: parsed scenario dict or None.
    """
    for _ in _variants(variants, scenario):
        pass


def run_batch(variants: pd.DataFrame, scenario, outputs) -> pd.DataFrame:
    """Simulate every variant on the drum bench (batches of the core) and reduce to scalar outputs.

    Parameters
    ----------
    variants : pandas.DataFrame
        Index ``variant_id``; columns as listed by :func:`describe` [SI].
    scenario : dict or None
        Parsed scenario TOML (``_source`` = its path) or None for the defaults.
    outputs : list of str
        Names from :data:`OUTPUTS`.

    Returns
    -------
    pandas.DataFrame
        Same index, one column per output.
    """
    from ..system import simulate_batch

    check_outputs("emtc", outputs, OUTPUTS)
    out = nan_frame(variants.index, outputs)
    items = list(_variants(variants, scenario))
    groups: dict = {}
    for k, (_, sets, _) in enumerate(items):
        sc = sets["scenario"]
        groups.setdefault((sc.duration, sc.sample_time), []).append(k)
    values = np.full((len(items), len(outputs)), np.nan)
    for (duration, sample_time), members in groups.items():
        check_allocation(len(members) * (duration / sample_time + 1), 32,
                         f"{len(members)} variants x duration = {duration!r} s at sample_time = {sample_time!r} s")
        samples = np.arange(int(round(duration / sample_time)) + 1) * sample_time
        systems = []
        for k in members:
            _, sets, magnet = items[k]
            systems.append(bench_system(magnet, sets["scenario"], sets["vehicle"],
                                        BenchOptions(actuator=sets["actuator"], coupling=sets["coupling"])))
        res = simulate_batch(systems, float(samples[-1]), sample_times=samples)
        names = res.output_columns
        tc_all = res.outputs[:, :, names.index("coupling_torque_Nm")]
        slip_all = res.outputs[:, :, names.index("slip_speed_rad_s")]
        fm_all = res.outputs[:, :, names.index("magnet_force_N")]
        for j, k in enumerate(members):
            vid, sets, magnet = items[k]
            if not Status(int(res.status[j])).ok:
                if not memory_full(systems[j]):
                    raise SimulationError(f"variant {vid}: emtc_bench: {Status(int(res.status[j])).message}")
                # a full hysteresis memory: this variant alone, with a memory that grows as needed
                alone = simulate_bench(magnet, sets["scenario"], vehicle=sets["vehicle"], actuator=sets["actuator"],
                                       coupling=sets["coupling"])
                tc = alone["coupling_torque_Nm"]
                slip = alone["slip_speed_rad_s"]
                fm = alone["magnet_force_N"]
                ev = alone.events
                n_steps = alone.n_steps
            else:
                tc, slip, fm = tc_all[j], slip_all[j], fm_all[j]
                ev = res.events[res.events["variant"] == j]
                n_steps = int(res.stats["accepted_steps"][j])
            locks = ev["time_s"].to_numpy()[ev["event"].to_numpy() == "lockup"]
            got = {
                "peak_coupling_torque": float(np.max(np.abs(tc))),
                "mean_coupling_torque": float(np.mean(tc)),
                "final_coupling_torque": float(tc[-1]),
                "peak_slip_speed": float(np.max(np.abs(slip))),
                "final_slip_speed": float(slip[-1]),
                "lock_time": float(locks[0]) if locks.size else np.nan,
                "peak_magnet_force": float(np.max(fm)),
                "n_steps": float(n_steps),
            }
            values[k] = [got[name] for name in outputs]
    out.loc[:, :] = values
    return out
