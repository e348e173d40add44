"""Driveline section of ``clutchlab demo``: the bundled driveline examples, simulated and explained.

Every entry of :data:`EXAMPLES` is a description bundled in :mod:`clutchlab.driveline.data` (a copy of
``examples/driveline_NAME.toml``).  Each is loaded with :func:`~clutchlab.driveline.description.load_driveline`
and run with :meth:`Driveline.simulate <clutchlab.driveline.network.Driveline.simulate>` (the system
contract and the integrator core) with the settings of its ``[simulation]`` table; the section shows,
per example, the model (the file's header comment), the speeds with the events marked, the friction
torques, the modes of the friction elements, the energies and the energy-balance error, the events
table and a table of metrics.  Adding an example to the report is one line: its file name in
:data:`EXAMPLES` (and the file in ``clutchlab/driveline/data`` and ``examples/``).
"""

from __future__ import annotations

import re
import time

import numpy as np
import pandas as pd

from ..report import Figure, Section, Table, Text

__all__ = ["EXAMPLES", "PROVENANCE", "demo_section", "example_items", "run_example", "mode_intervals",
           "header_comment"]

#: bundled descriptions shown by the demo, in this order (files in ``clutchlab/driveline/data``)
EXAMPLES = ("coupled_clutches.toml", "eclutch_launch.toml", "dct_upshift.toml", "torque_converter.toml",
            "at_upshift.toml", "amt_upshift.toml")

PROVENANCE = ("Simulated (synthetic) data, not measured: clutchlab's driveline networks run from the descriptions "
              "bundled with clutchlab (clutchlab/driveline/data, the same files as examples/driveline_*.toml) on "
              "the integrator core; the reference models and their parameters are named in each example's text.")


def header_comment(path) -> str:
    """The comment block at the top of a TOML file, as one paragraph (``#`` and line breaks removed).

    Parameters
    ----------
    path : str or Path
        The file.
    """
    lines = []
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            if not line.startswith("#"):
                break
            lines.append(line[1:].strip())
    return " ".join(x for x in lines if x)


def _event_table(result) -> pd.DataFrame:
    """Events as ``clutchlab driveline simulate --events`` writes them: time_s, component, event."""
    return result.events.rename(columns={"element": "component"})[["time_s", "component", "event"]] \
        .reset_index(drop=True)


def mode_intervals(result, events=None) -> dict:
    """The modes of every friction element as intervals covering the run, switched at the exact event times.

    Parameters
    ----------
    result : SimulationResult
        A driveline run (its ``mode_names`` are the friction elements).
    events : pandas.DataFrame, optional
        Its events with ``time_s``, ``component`` and ``event`` (default: from ``result``).

    Returns
    -------
    dict
        Element name -> list of ``(start [s], stop [s], mode)``, consecutive, from the first to the last
        sample time.  An event is named for the mode it enters (``stick`` enters ``stuck``); an event of
        another name takes the mode sampled after it.
    """
    from ..driveline import kernel as K

    events = _event_table(result) if events is None else events
    entered = dict(zip(K.EVENTS, K.MODE_VALUES))
    time_s = np.asarray(result.time)
    t0, t1 = float(time_s[0]), float(time_s[-1])
    out = {}
    for name in result.mode_names:
        sampled = result.mode(name)
        current, start, spans = str(sampled[0]), t0, []
        mine = events[events["component"] == name].sort_values("time_s", kind="stable")
        for tt, ev in zip(mine["time_s"], mine["event"]):
            new = entered.get(ev)
            if new is None:
                new = str(sampled[min(int(np.searchsorted(time_s, tt, side="right")), len(sampled) - 1)])
            if new != current:
                spans.append((start, float(tt), current))
                start, current = float(tt), new
        spans.append((start, t1, current))
        out[name] = spans
    return out


def run_example(name: str) -> dict:
    """Load the bundled description ``name`` and run it with its ``[simulation]`` settings.

    The run is done twice: the first call loads (or, without a warm cache, compiles) the kernels, the
    second is timed.

    Parameters
    ----------
    name : str
        File name in :mod:`clutchlab.driveline.data` (e.g. ``"coupled_clutches.toml"``).

    Returns
    -------
    dict
        ``spec`` (:class:`~clutchlab.driveline.description.DrivelineFile`), ``result``
        (:class:`~clutchlab.SimulationResult`), ``frame`` (its DataFrame), ``events`` (time_s, component,
        event), ``intervals`` (:func:`mode_intervals`), ``seconds`` (wall time of the timed run) and
        ``path`` of the file.
    """
    from ..errors import ParameterError
    from ..driveline.data import path
    from ..driveline.description import load_driveline

    file = path(name)
    spec = load_driveline(file)
    if spec.t_end is None:
        raise ParameterError(f"{file}: the demo needs [simulation] t_end")

    def run():
        return spec.driveline.simulate(spec.t_end, rtol=spec.rtol, max_step=spec.max_step,
                                       output_step=spec.output_step)

    run()  # loads the compiled kernels (compiles them on a cold cache)
    t = time.perf_counter()
    result = run()
    seconds = time.perf_counter() - t
    events = _event_table(result)
    return dict(spec=spec, result=result, frame=result.to_dataframe(), events=events,
                intervals=mode_intervals(result, events), seconds=seconds, path=file)


def _relative_error(frame) -> float:
    """Largest energy-balance error over the energy dissipated in the run."""
    return float(frame["energy_error_J"].abs().max()) / max(float(frame["dissipated_energy_J"].iloc[-1]), 1e-300)


def _metrics(run: dict) -> pd.DataFrame:
    frame, result = run["frame"], run["result"]
    last = frame.iloc[-1]
    rows = []
    for col in frame.columns:
        if col.endswith(".w_rad_s") and col in result.state_columns:
            rows.append((f"final speed of {col.removesuffix('.w_rad_s')} [rad/s]", last[col]))
    for col in frame.columns:
        if col.endswith(".dissipated_J"):
            rows.append((f"energy dissipated in {col.removesuffix('.dissipated_J')} [J]", last[col]))
    stored = frame["kinetic_energy_J"] + frame["spring_energy_J"]
    err = float(frame["energy_error_J"].abs().max())
    stats = result.stats
    rows += [("work of the sources [J]", last["input_work_J"]),
             ("energy dissipated, all elements [J]", last["dissipated_energy_J"]),
             ("stored energy at the start [J]", stored.iloc[0]),
             ("stored energy at the end [J]", stored.iloc[-1]),
             ("max |energy-balance error| [J]", err),
             ("max |energy-balance error| / energy dissipated [-]", _relative_error(frame)),
             ("events [-]", float(len(run["events"]))),
             ("accepted steps [-]", float(stats.get("accepted_steps", np.nan))),
             ("rejected steps [-]", float(stats.get("rejected_steps", np.nan))),
             ("run time, kernels loaded [ms]", 1e3 * run["seconds"])]
    return pd.DataFrame(rows, columns=["quantity", "value"])


def _network_parameters(stem: str, driveline) -> dict:
    """The components of a network as report parameters, one entry per line of ``Driveline.describe``."""
    params = {}
    for i, line in enumerate(driveline.describe().splitlines()[1:]):
        m = re.search(r"\((\w+): ", line) or re.match(r"\s*\[(\w+)\]", line)
        key = f"{stem}: {m.group(1) if m else f'line {i + 1}'}"
        params[key] = line.strip()
    return params


def example_items(name: str, progress=None) -> tuple:
    """The report items of one bundled example and its parameters.

    Parameters
    ----------
    name : str
        File name in :mod:`clutchlab.driveline.data`.
    progress : callable, optional
        Told what is being done (a message string).

    Returns
    -------
    tuple
        ``(items, parameters, run)``: the Text, Figure and Table items, the parameters for the section
        (component lines and run settings, keyed ``<name>: ...``) and the run (:func:`run_example`).
    """
    from ..driveline.plots import energy_figure, friction_torques_figure, modes_figure, speeds_figure

    say = progress or (lambda message: None)
    stem = name.removesuffix(".toml")
    say(f"driveline: simulating the bundled example {name}")
    run = run_example(name)
    spec, result, frame, events = run["spec"], run["result"], run["frame"], run["events"]
    d = spec.driveline
    fric = list(result.mode_names)
    speeds = [c for c in result.state_columns if c.endswith(".w_rad_s")]
    metrics = _metrics(run)
    err = float(frame["energy_error_J"].abs().max())
    stats = result.stats
    items = [
        Text(f"Example {d.name!r} (clutchlab/driveline/data/{name}, the same file as "
             f"examples/driveline_{name}): {header_comment(run['path'])}"),
        Text(f"Simulated, not measured: clutchlab's driveline network of this description "
             f"({len(speeds)} inertias, {len(fric)} friction elements) run for {spec.t_end:g} s on the integrator "
             f"core (Dormand-Prince 5(4), rtol = {spec.rtol:g} from the file's [simulation] table) with the friction "
             f"state machine of the Modelica Standard Library: every change between stuck, sliding forward, sliding "
             f"backward and free is an event located to 1e-12 s, and the elements stuck at the same time are solved "
             f"together. With the kernels loaded the run took {1e3 * run['seconds']:.1f} ms "
             f"({stats.get('accepted_steps', 0)} steps, {len(events)} events)."),
        Figure(f"driveline_{stem}_speeds", speeds_figure(frame, events, columns=speeds,
                                                          title=f"{d.name}: inertia speeds and events"),
               "Speeds of the inertias; the vertical lines mark the events, styled by the mode entered "
               "(stick, forward, backward, free)."),
        Figure(f"driveline_{stem}_torques", friction_torques_figure(frame, fric, title=f"{d.name}: friction torques"),
               "Torques of the friction elements (on flange a; flange b gets the opposite)."),
        Figure(f"driveline_{stem}_modes", modes_figure(run["intervals"], title=f"{d.name}: modes of the friction "
                                                                                  f"elements"),
               "Mode of every friction element over time, switched at the exact event times."),
        Figure(f"driveline_{stem}_energy", energy_figure(frame, title=f"{d.name}: energy"),
               "Work of the sources, energy dissipated per element and in all, energy stored (kinetic + springs); "
               "below, the energy-balance error: input work - dissipated - change of the stored energy."),
        Table(f"driveline_{stem}_events", events, f"Events of {d.name!r} in time order (the mode entered)",
              float_format="{:.6f}"),
        Table(f"driveline_{stem}_metrics", metrics, f"Metrics of {d.name!r}", float_format="{:.5g}"),
        Text(f"The energy balance closes to {err:.2g} J over the run ({_relative_error(frame):.1e} of the energy "
             f"dissipated): the integrator's error at rtol = {spec.rtol:g}, not a modelling error (the energy "
             f"states are integrated with the motion)."),
    ]
    if spec.shift:   # (a file with a [shift] table: the shift's figure and its metrics)
        items += _shift_items(stem, d.name, result, spec.shift)
    for e in d.elements:   # (a torque converter: its operating points over the speed ratio)
        if e.kind == "torque_converter":
            items += _converter_items(stem, d.name, frame, e)
    params = _network_parameters(stem, d)
    step = "every accepted step" if spec.output_step is None else f"{spec.output_step:g} s"
    params[f"{stem}: simulation"] = f"t_end = {spec.t_end:g} s, output step {step}, rtol = {spec.rtol:g}"
    return items, params, run


def _shift_items(stem: str, name: str, result, arguments: dict) -> list:
    """The shift quality of an example with a ``[shift]`` table (a clutch-to-clutch or an AMT's interrupted shift):
    its figure, metrics and a text."""
    from ..control.plots import shift_figure
    from ..driveline.shift import shift_quality

    q = shift_quality(result, **arguments)
    m = q.metrics
    a, j = ("m_s2", "m_s3") if "acceleration_dip_m_s2" in m else ("rad_s2", "rad_s3")   # (with a radius: the vehicle's)
    au, ju = a.replace("_s", "/s^"), j.replace("_s", "/s^")
    table = Table(f"driveline_{stem}_shift_quality", q.table()[["metric", "value", "unit", "description"]],
                  f"Shift quality of {name!r} (clutchlab.control.shift_quality, from the run's columns)",
                  float_format="{:.4g}")
    if q.kind == "interrupted":
        return [
            Figure(f"driveline_{stem}_shift", shift_figure(q, title=f"{name}: shift quality"),
                   f"The automated manual transmission's {q.order} from {arguments['offgoing']} to "
                   f"{arguments['oncoming']} through the clutch {arguments['clutch']}: the engine's speed, the "
                   "clutch's and the synchronisers' slips and torques, the vehicle's acceleration (its level before "
                   "the shift and its dip marked) and jerk; the release (the engine's torque taken down, the clutch "
                   "opened), the neutral and synchronisation (the old sleeve out, the new cone pulling the input "
                   "shaft onto the new gear's speed until its dogs engage) and the closing shaded."),
            table,
            Text(f"Shift quality (docs/control.md, \"Shift quality\"): the drive is interrupted for "
                 f"{1e3 * m['torque_interruption_s']:.0f} ms of the shift's {1e3 * m['shift_time_s']:.0f} ms; the "
                 f"synchroniser {arguments['oncoming']} takes {1e3 * m['synchronisation_time_s']:.0f} ms and "
                 f"{m['synchroniser_energy_J']:.0f} J to bring its gear to speed; the vehicle's acceleration dips "
                 f"by {m['acceleration_dip_' + a]:.2f} {au} from {m['acceleration_before_' + a]:.2f} {au} (the "
                 f"torque hole), and the clutch, closing onto a slip that falls at "
                 f"{m['lockup_slip_rate_rad_s2']:.0f} rad/s^2 as it locks, takes {m['clutch_energy_J'] / 1e3:.1f} "
                 f"kJ; the jerk peaks at {m['jerk_peak_' + j]:.0f} {ju}."),
        ]
    return [
        Figure(f"driveline_{stem}_shift", shift_figure(q, title=f"{name}: shift quality"),
               f"The {q.order} from {arguments['offgoing']} to {arguments['oncoming']}: the engine's speed and the "
               "clutches' slips, their torques, the vehicle's acceleration (its level before the shift and its dip "
               "marked) and jerk; the torque phase (the on-coming clutch takes the engine's torque) and the inertia "
               "phase (it pulls the engine down to the new gear's speed) shaded."),
        table,
        Text(f"Shift quality (docs/control.md, \"Shift quality\"): the torque phase lasts "
             f"{1e3 * m['torque_phase_s']:.0f} ms and the inertia phase {1e3 * m['inertia_phase_s']:.0f} ms; the "
             f"output's acceleration dips by {m['acceleration_dip_' + a]:.2f} {au} from "
             f"{m['acceleration_before_' + a]:.2f} {au}, the jerk peaks at {m['jerk_peak_' + j]:.0f} {ju} where "
             f"the on-coming clutch locks (its slip falling at {m['lockup_slip_rate_rad_s2']:.0f} rad/s^2) and the "
             f"half shafts ring, and the on-coming clutch takes {m['oncoming_energy_J'] / 1e3:.1f} kJ."),
    ]


def _converter_items(stem: str, name: str, frame, converter) -> list:
    """A torque converter's operating points in the run (:func:`~clutchlab.driveline.plots.converter_figure`) and a
    text with its largest torque ratio and the share of the impeller's work it passed on (``converter`` its
    :class:`~clutchlab.driveline.ElementInfo`)."""
    from ..driveline.plots import converter_figure, converter_points

    c = converter.name
    pts = converter_points(frame, c)
    t = frame["time_s"].to_numpy()
    ws = 0.0 if converter.support == "ground" else frame[f"{converter.support}.w_rad_s"].to_numpy()
    power = -frame[f"{c}.tau_Nm"].to_numpy() * (frame[f"{converter.flange_a}.w_rad_s"].to_numpy() - ws)
    taken = float(np.sum(0.5 * np.diff(t) * (power[1:] + power[:-1])))   # [J] the impeller's work (trapezoids)
    lost = float(frame[f"{c}.dissipated_J"].iloc[-1])
    text = f"The torque converter {c!r} "
    if len(pts):
        text += (f"multiplied the engine's torque by up to {pts['torque_ratio_1'].max():.2f} (at the speed ratio "
                 f"{pts['speed_ratio_1'].min():.2f}); ")
    text += (f"its impeller took {taken / 1e3:.1f} kJ, of which it passed {100.0 * (1.0 - lost / taken):.0f} % to "
             f"the turbine and turned {lost / 1e3:.1f} kJ into heat in its fluid (docs/driveline.md, \"Torque "
             "converter\")." if taken > 0.0 else "its impeller took no work in this run.")
    return [
        Figure(f"driveline_{stem}_{c}", converter_figure(frame, c, title=f"{name}: {c}"),
               "The converter's capacity factor K = ω_p/√T_p, torque ratio T_t/T_p and efficiency over the speed "
               "ratio ω_t/ω_p at the run's samples where the impeller drove, coloured by time: its table's "
               "characteristic as the run went through it, read from the run's columns."),
        Text(text),
    ]


def demo_section(progress=None) -> Section:
    """The driveline section of ``clutchlab demo``: every example of :data:`EXAMPLES`, simulated.

    Parameters
    ----------
    progress : callable, optional
        Told what is being done (a message string).
    """
    import matplotlib

    items, params = [], {}
    # (the section's figures stay open until the report renders and closes them: more than pyplot's 20)
    with matplotlib.rc_context({"figure.max_open_warning": 0}):
        for name in EXAMPLES:
            more, p, _ = example_items(name, progress)
            items += more
            params.update(p)
    return Section("Drivelines: friction elements with exact stick/slip (simulated)", items,
                   provenance=PROVENANCE, parameters=params, synthetic=True)
