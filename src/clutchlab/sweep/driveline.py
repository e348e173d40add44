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
====================================  =====  =============================================================
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import ParameterError
from ..numerics.status import Status
from ..sweep.targets import check_outputs, nan_frame, rows
from ..system import simulate, simulate_batch
from ..driveline.variants import DrivelineDocument

__all__ = ["run_batch", "describe", "check_variants", "referenced_files", "outputs_of", "EVENT_CAPACITY"]

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


def outputs_of(driveline) -> dict:
    """The sweep outputs of a driveline network, name -> unit.

    Parameters
    ----------
    driveline : Driveline
        The network of the scenario.
    """
    out = {}
    for v in driveline.system().states:
        if v.name.endswith(".w"):
            out[f"{v.name[:-2]}.w_final_rad_s"] = "rad/s"
    for name in driveline.friction_names:
        out[f"{name}.dissipated_J"] = "J"
        out[f"{name}.last_stick_s"] = "s"
        out[f"{name}.peak_tau_Nm"] = "N*m"
    out.update({"dissipated_energy_J": "J", "energy_error_J": "J", "status": "1"})
    return out


def describe(scenario) -> dict:
    """Sweepable parameters (name -> SI unit) and outputs (name -> unit) of the scenario's driveline.

    Parameters
    ----------
    scenario : dict
        The parsed driveline description (``_source`` = its path).
    """
    doc, base = _base(scenario)
    return {"parameters": {p.name: p.unit for p in (*doc.parameters.values(), *doc.input_starts.values())},
            "outputs": outputs_of(base.driveline)}


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


def _reduce(system, states, outputs, last_stick, status):
    """Outputs of one variant: its samples ``states`` (n, n_x), ``outputs`` (n, n_y), ``{element: last stick}``."""
    got = {"status": float(status)}
    if not Status(int(status)).ok:
        return got
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
    check_outputs("driveline", outputs, outputs_of(base.driveline))
    built = _systems(doc, variants)
    if not built:
        return nan_frame(variants.index, outputs)
    t_end = base.t_end
    step = base.output_step if base.output_step is not None else t_end / 1000.0
    options = {"output_step": step, "max_step": base.max_step, "max_steps": MAX_STEPS}
    res = simulate_batch([system for _, _, system in built], t_end, event_capacity=EVENT_CAPACITY, **options)
    sticks = _last_sticks(res.events)
    dropped = res.stats["events_dropped"]
    values = np.full((len(built), len(outputs)), np.nan)
    for k, (vid, row, system) in enumerate(built):
        if dropped[k]:  # more events than the batch keeps: this variant again, alone, with every event
            one = simulate(_system(doc, vid, row), t_end, check=False, **options)
            alone = {e: t for (_, e), t in _last_sticks(one.events).items()}
            got = _reduce(system, one.states, one.outputs, alone, int(one.status))
        else:
            mine = {e: sticks[(k, e)] for e in system.mode_names if (k, e) in sticks}
            got = _reduce(system, res.states[k], res.outputs[k], mine, int(res.status[k]))
        values[k] = [got.get(name, np.nan) for name in outputs]
    return pd.DataFrame(values, index=variants.index, columns=list(outputs))
