"""Sweep target ``"driveline"``: variants of a driveline description file, run as one compiled batch.

Used by ``clutchlab sweep`` (:mod:`clutchlab.sweep`).  The spec's scenario is a driveline description
(the ``clutchlab driveline simulate`` format, :mod:`clutchlab.driveline.description`; it needs
``[simulation] t_end``)::

    [sweep]
    model = "driveline"
    scenario = "driveline_test_friction.toml"
    outputs = ["clutch.last_stick_s", "clutch.dissipated_J", "inertia3.w_final_rad_s"]

    [grid]
    "clutch.fn_max" = ["0.8 N", "1 N", "1.2 N"]
    "inertia3.J" = ["1 kg m^2", "2 kg m^2"]

The files the description names (an E-clutch's or a wet clutch's parameter files) are read relative to
the description's folder, as ``clutchlab driveline simulate`` reads them -- not the spec's folder nor
the working directory; their bytes, and those of the curve files an E-clutch parameter file names, are
part of the sweep's hash (:func:`referenced_files`).

The parameters are the numeric fields of the file's components, ``<component>.<field>``
(:class:`~clutchlab.driveline.variants.DrivelineDocument`): ``J1.J``, ``J1.w0``, ``clutch1.fn_max``,
``clutch1.mu``, ``clutch1.peak``, a spring's ``c``, ..., and the start value of each network input,
``<input>.start`` (held through the run: ``[input.throttle] start``).  Written against the system contract: every
variant is the :class:`~clutchlab.system.System` of its :class:`~clutchlab.driveline.Driveline`, and all
variants of a chunk run in one :func:`clutchlab.system.simulate_batch` (one Dormand-Prince 5(4) solver
of the integrator core per variant, ``numba.prange``), with the file's ``rtol`` and ``max_step``, sampled
every ``[simulation] output_step`` (default ``t_end / 1000``).

Outputs per variant (names carry their unit, as the driveline's columns):

====================================  =====  =============================================================
``<inertia>.w_final_rad_s``           rad/s  speed of each inertia at ``t_end``
``<friction>.dissipated_J``           J      energy dissipated in each friction element over the run
``<friction>.last_stick_s``           s      time of the element's last ``stick`` event (NaN if none)
``<friction>.peak_tau_Nm``            N*m    maximum of ``abs(tau)`` of the element over the samples
``dissipated_energy_J``               J      energy dissipated in the whole network
``energy_error_J``                    J      largest ``abs(energy_error)`` over the samples (the balance)
``status``                            1      0 success; else the core's status code (outputs NaN)
``<variable>_min_<unit>``             unit   least value of a state or output over the samples
``<variable>_max_<unit>``             unit   largest value over the samples
``<variable>_final_<unit>``           unit   value at ``t_end``
``<speed>_jerk_<unit>3``              /s^2   largest ``abs(d^2 w / dt^2)`` of a speed over the samples
``shift.<metric>``                    unit   with a ``[shift]`` table in the file: the quality of its shift
                                             (:func:`clutchlab.driveline.shift.shift_quality`; NaN where the
                                             variant's shift does not complete)
====================================  =====  =============================================================

The metrics of the last four rows exist for every state and output of the network, named by its column
(:meth:`~clutchlab.driveline.Driveline.simulate`): ``engine.w_min_rad_s`` (the least engine speed of a
launch: a stall is below idle), ``clutch.temperature_max_C`` (a wet clutch's peak pack temperature),
``vehicle.w_jerk_rad_s3`` (the vehicle's jerk, in rad/s^3 at its inertia: times the tyre radius for m/s^3),
``clutch.tau_max_Nm``.  The jerk is the second derivative of the sampled speed by central differences
(``numpy.gradient`` twice, on the samples' times), so it is the jerk a rig's speed signal shows when sampled
every ``[simulation] output_step`` ``h``: an acceleration step (a clutch locking) reads as a jerk of about
``delta_a / (2 h)``; a shift-quality metric states its sample interval, as a measured one states its filter.

Besides the components' fields, the numbers of the signals the file gives are parameters,
``<component>.<field>.<parameter>`` (:attr:`~clutchlab.driveline.variants.DrivelineDocument.signal_parameters`):
a sine torque's ``torque.torque.amplitude``, a step of the normal force ``clutch.normal.start``, and a table
profile as a whole, stretched in time (``clutch.position.time_scale``) or scaled in value
(``clutch.position.value_scale``, ``wet.force.value_scale``): the clutch force profiles of a launch.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import ParameterError
from ..numerics.status import Status
from ..units import COLUMN_UNITS
from ..sweep.targets import check_outputs, nan_frame, rows
from ..system import batch_groups, simulate, simulate_batch
from ..driveline.shift import metric_names, shift_quality
from ..driveline.variants import DrivelineDocument

__all__ = ["run_batch", "describe", "check_variants", "referenced_files", "outputs_of", "metrics_of", "REDUCTIONS",
           "EVENT_CAPACITY"]

#: reductions of a state or output over the samples of a run, the outputs ``<variable>_<reduction>_<unit>``
REDUCTIONS = ("min", "max", "final")
#: unit suffixes of speeds, whose jerk is an output ``<speed>_jerk_<unit>3``
_SPEEDS = ("rad_s", "m_s")

#: events kept per variant in the batch; a variant with more runs again alone (it keeps 100,000)
EVENT_CAPACITY = 1024
#: accepted-step limit of each variant
MAX_STEPS = 5_000_000


def _base(scenario):
    """(document, its DrivelineFile) of the scenario; the base file is checked by the loader."""
    if scenario is None:
        raise ParameterError("the driveline sweep needs a scenario: [sweep] scenario = \"my_driveline.toml\" "
                             "(a driveline description, docs/driveline.md)")
    doc = DrivelineDocument(scenario, str(scenario.get("_source", "scenario")))
    base = doc.load()
    if base.t_end is None:
        raise ParameterError(f"{doc.source}: [simulation] t_end: needed by the driveline sweep (every variant runs "
                             "from 0 to t_end)")
    return doc, base


def metrics_of(system) -> dict:
    """The metrics of a network's states and outputs over a run: name -> (unit, "state" or "output", index,
    reduction), :data:`REDUCTIONS` of every variable but the mode codes, and ``"jerk"`` of every speed.

    Parameters
    ----------
    system : clutchlab.system.System
        The network's system (its variables name the metrics).
    """
    out = {}
    for kind, variables in (("state", system.states), ("output", system.outputs)):
        for i, v in enumerate(variables):
            if v.name.endswith(".mode") or v.unit not in COLUMN_UNITS:
                continue
            for r in REDUCTIONS:
                out[f"{v.name}_{r}_{v.unit}"] = (COLUMN_UNITS[v.unit][0], kind, i, r)
            if v.unit in _SPEEDS:
                out[f"{v.name}_jerk_{v.unit}3"] = (COLUMN_UNITS[v.unit + "3"][0], kind, i, "jerk")
    return out


def _metric(time, values, reduction) -> float:
    """One metric of a variable's samples ``values`` at ``time`` (:func:`metrics_of`)."""
    if reduction == "min":
        return float(np.min(values))
    if reduction == "max":
        return float(np.max(values))
    if reduction == "final":
        return float(values[-1])
    if values.size < 3 or not np.all(np.diff(time) > 0):
        return np.nan
    return float(np.max(np.abs(np.gradient(np.gradient(values, time), time))))


def outputs_of(driveline, shift=None) -> dict:
    """The sweep outputs of a driveline network, name -> unit.

    Parameters
    ----------
    driveline : Driveline
        The network of the scenario.
    shift : dict, optional
        The file's ``[shift]`` table (:attr:`~clutchlab.driveline.description.DrivelineFile.shift`): its shift's
        quality metrics are outputs ``shift.<metric>`` (:func:`clutchlab.driveline.shift.metric_names`).
    """
    system = driveline.system()
    out = {}
    for v in system.states:
        if v.name.endswith(".w"):
            out[f"{v.name[:-2]}.w_final_rad_s"] = "rad/s"
    for name in driveline.friction_names:
        out[f"{name}.dissipated_J"] = "J"
        out[f"{name}.last_stick_s"] = "s"
        out[f"{name}.peak_tau_Nm"] = "N*m"
    out.update({"dissipated_energy_J": "J", "energy_error_J": "J", "status": "1"})
    for name, (unit, *_) in metrics_of(system).items():
        out.setdefault(name, unit)
    if shift:
        for name, unit in metric_names("radius" in shift, "clutch" in shift).items():
            out[f"shift.{name}"] = COLUMN_UNITS[unit][0] if unit in COLUMN_UNITS else unit
    return out


def _shift_metrics(frame, shift, wanted) -> dict:
    """The ``shift.<metric>`` outputs of one variant: :func:`clutchlab.driveline.shift.shift_quality` of its samples
    (``frame()``: its run's :meth:`~clutchlab.result.SimulationResult.to_dataframe`, built only when a shift metric is
    wanted), NaN where its shift does not complete within the run (no hand-over or lock-up)."""
    if not any(name.startswith("shift.") for name in wanted):
        return {}
    try:
        q = shift_quality(frame(), **shift)
    except ParameterError:
        return {}
    return {f"shift.{k}": v for k, v in q.metrics.items()}


def describe(scenario) -> dict:
    """Sweepable parameters (name -> SI unit) and outputs (name -> unit) of the scenario's driveline.

    Parameters
    ----------
    scenario : dict
        The parsed driveline description (``_source`` = its path).
    """
    doc, base = _base(scenario)
    return {"parameters": {p.name: p.unit for p in (*doc.parameters.values(), *doc.input_starts.values(),
                                                    *doc.signal_parameters.values())},
            "outputs": outputs_of(base.driveline, base.shift)}


def referenced_files(scenario) -> list:
    """The driveline description and every file it names (their bytes are part of the sweep's hash).

    The files are those the loader reads, relative to the description's folder
    (:meth:`~clutchlab.driveline.variants.DrivelineDocument.referenced_files`): E-clutch and wet-clutch
    parameter files, a friction law or map, and the curve files an E-clutch parameter file names in turn.

    Parameters
    ----------
    scenario : dict
        The parsed driveline description (``_source`` = its path).
    """
    if not scenario or "_source" not in scenario:
        return []
    doc = DrivelineDocument(scenario, str(scenario["_source"]))
    return [scenario["_source"], *(f for ref in doc.referenced_files() for f in ref.files())]


def _system(doc, vid, row):
    try:
        spec = doc.load(row)
    except ParameterError as exc:
        raise ParameterError(f"variant {vid}: {exc}") from None
    return spec.driveline.system(spec.rtol)


def _systems(doc, variants: pd.DataFrame) -> list:
    """``[(variant id, row, System)]``: every variant built and checked."""
    doc.check_names(variants.columns)
    return [(vid, row, _system(doc, vid, row)) for vid, row in rows(variants)]


def check_variants(variants: pd.DataFrame, scenario) -> None:
    """Build every variant's driveline (names, values, the loader's checks); raise on the first bad one.

    Parameters
    ----------
    variants : pandas.DataFrame
        One row per variant, columns ``<component>.<field>`` [SI].
    scenario : dict
        The parsed driveline description (``_source`` = its path).
    """
    _systems(_base(scenario)[0], variants)


def _last_sticks(events) -> dict:
    """``{(variant, element): time of the last stick event}`` from an events frame (``variant`` column or 0)."""
    stick = events[events["event"] == "stick"]
    variant = stick["variant"] if "variant" in stick else pd.Series(0, index=stick.index)
    return stick.groupby([variant, stick["element"]])["time_s"].max().to_dict()


def _reduce(system, time, states, outputs, last_stick, status, wanted=(), metrics=None, shift=None, frame=None):
    """Outputs of one variant: its samples ``states`` (n, n_x), ``outputs`` (n, n_y) at ``time``, ``{element: last
    stick}``, and the metrics of :func:`metrics_of` named in ``wanted`` (``metrics``: those of ``system``, or of
    any variant of the same network: the variants share their variables); with the file's ``[shift]`` table
    (``shift``), its ``shift.<metric>`` from ``frame()``, the variant's samples as a DataFrame."""
    got = {"status": float(status)}
    if not Status(int(status)).ok:
        return got
    metrics = metrics_of(system) if metrics is None else metrics
    for name in wanted:
        if name in metrics:
            _, kind, i, reduction = metrics[name]
            got[name] = _metric(time, (states if kind == "state" else outputs)[:, i], reduction)
    friction = set(system.mode_names)
    for i, v in enumerate(system.states):
        if v.name.endswith(".w"):
            got[f"{v.name[:-2]}.w_final_rad_s"] = states[-1, i]
        elif v.name.endswith(".dissipated") and v.name[:-11] in friction:
            got[f"{v.name[:-11]}.dissipated_J"] = states[-1, i]
    for i, v in enumerate(system.outputs):
        element = v.name[:-4] if v.name.endswith(".tau") else None
        if element in friction:
            got[f"{element}.peak_tau_Nm"] = float(np.max(np.abs(outputs[:, i])))
    for element in friction:
        got[f"{element}.last_stick_s"] = last_stick.get(element, np.nan)
    got["dissipated_energy_J"] = outputs[-1, system.output_index("dissipated_energy")]
    got["energy_error_J"] = float(np.max(np.abs(outputs[:, system.output_index("energy_error")])))
    if shift:
        got.update(_shift_metrics(frame, shift, wanted))
    return got


def run_batch(variants: pd.DataFrame, scenario, outputs) -> pd.DataFrame:
    """Simulate every variant of the scenario's driveline in one compiled batch and reduce it.

    Parameters
    ----------
    variants : pandas.DataFrame
        Index ``variant_id``; columns ``<component>.<field>`` in SI units.
    scenario : dict
        The parsed driveline description (``_source`` = its path), with ``[simulation] t_end``.
    outputs : list of str
        Names from :func:`describe` (``J1.w_final_rad_s``, ``clutch1.last_stick_s``, ...).

    Returns
    -------
    pandas.DataFrame
        Same index, one column per output (NaN where a variant failed or has no value).
    """
    doc, base = _base(scenario)
    check_outputs("driveline", outputs, outputs_of(base.driveline, base.shift))
    built = _systems(doc, variants)
    if not built:
        return nan_frame(variants.index, outputs)
    t_end = base.t_end
    step = base.output_step if base.output_step is not None else t_end / 1000.0
    options = {"output_step": step, "max_step": base.max_step, "max_steps": MAX_STEPS}
    values = np.full((len(built), len(outputs)), np.nan)
    # (one batch per structure: a field that changes the network's sizes, an E-clutch's wear from zero, splits them)
    for group in batch_groups([system for _, _, system in built]):
        res = simulate_batch([built[k][2] for k in group], t_end, event_capacity=EVENT_CAPACITY, **options)
        sticks = _last_sticks(res.events)
        metrics = metrics_of(built[group[0]][2])   # (every variant has the same states and outputs)
        dropped = res.stats["events_dropped"]
        for j, k in enumerate(group):
            vid, row, system = built[k]
            if dropped[j]:  # more events than the batch keeps: this variant again, alone, with every event
                one = simulate(_system(doc, vid, row), t_end, check=False, **options)
                alone = {e: t for (_, e), t in _last_sticks(one.events).items()}
                got = _reduce(system, one.time, one.states, one.outputs, alone, int(one.status), outputs, metrics,
                              base.shift, one.to_dataframe)
            else:
                mine = {e: sticks[(j, e)] for e in system.mode_names if (j, e) in sticks}
                got = _reduce(system, res.time, res.states[j], res.outputs[j], mine, int(res.status[j]), outputs,
                              metrics, base.shift, lambda j=j: res.to_dataframe(variant=j))
            values[k] = [got.get(name, np.nan) for name in outputs]
    return pd.DataFrame(values, index=variants.index, columns=list(outputs))
