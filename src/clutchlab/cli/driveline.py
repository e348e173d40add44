"""``clutchlab driveline`` sub-commands: a thin layer over :mod:`clutchlab.driveline`.

``clutchlab driveline simulate FILE.toml -o OUT.csv [--input NAME=VALUE ...] [--output-step STEP] [--fixed-step STEP] [--check-invariants] [--events EVENTS.csv] [--plot fig.png] [--force]``
    run a driveline network and write its states and outputs (and its events);
``clutchlab driveline describe FILE.toml``
    print a text schematic of the network;
``clutchlab driveline components [KIND]``
    list the component kinds a network file can use (built in, and registered by installed packages), or
    the fields of one: kind, unit, default, range and description (:mod:`clutchlab.component`).
"""

from __future__ import annotations

import io

from .common import add_run_options
from ..errors import DataError, ParameterError

__all__ = ["register"]


def register(subparsers) -> None:
    """Add the ``driveline`` command and its sub-commands."""
    dl = subparsers.add_parser("driveline", help="driveline networks: inertias, springs, sources and clutches with "
                                                 "exact stick/slip",
                               description="One-dimensional driveline networks (inertias, spring-dampers, torque "
                                           "sources, clutches, brakes and bearing friction between two flanges) "
                                           "with the friction semantics of the Modelica Standard Library.",
                               epilog="Documentation: docs/driveline.md")
    sub = dl.add_subparsers(dest="driveline_command", metavar="SUBCOMMAND")
    sim = sub.add_parser("simulate", help="run a driveline TOML and write its states and outputs as CSV",
                         description="Run a driveline network described in a TOML file from its initial state "
                                     "and write every state and output with unit-suffixed columns "
                                     "(<component>.<quantity>_<unit>), optionally the events and a figure.",
                         epilog="Documentation: docs/driveline.md (file format)")
    sim.add_argument("file", help="driveline description (TOML with units)")
    sim.add_argument("-o", "--output", required=True, help="CSV of the states and outputs to write")
    sim.add_argument("--input", action="append", default=[], metavar="NAME=VALUE",
                     help="drive the network input [input.NAME] in this run (repeatable): a value held from t = 0 "
                          "in the unit of the fields it drives, e.g. 'throttle=0.3' or 'load=20 N m', or a CSV "
                          "file of time_s and one value column named with its unit suffix (load_Nm), read "
                          "linearly between samples and held beyond them (default: the input's start)")
    sim.add_argument("--t-end", help="end time, e.g. '1.5 s' (default: [simulation] t_end)")
    add_run_options(sim)
    sim.add_argument("--check-invariants", action="store_true",
                     help="debug: check at every step that stuck elements are within their limits, modes agree "
                          "with the relative speeds, one-way clutches never drive their free direction, lossy "
                          "gears never generate and the energy balance holds; a violation names the element")
    sim.add_argument("--events", help="CSV of the events to write (time_s, component, event)")
    sim.add_argument("--plot", help="also write a PNG figure (speeds, friction torques, modes, energy)")
    sim.add_argument("--force", action="store_true", help="overwrite the outputs")
    sim.set_defaults(func=_simulate)
    des = sub.add_parser("describe", help="print a text schematic of a driveline TOML",
                         description="Read a driveline description, check it and print its inertias and every "
                                     "element between its two flanges with its parameters.",
                         epilog="Documentation: docs/driveline.md")
    des.add_argument("file", help="driveline description (TOML with units)")
    des.set_defaults(func=_describe)
    comp = sub.add_parser("components", help="list the component kinds of driveline files, or one kind's fields",
                          description="List the component kinds a driveline file can use (the built-in ones and "
                                      "those that installed packages add), or print the fields of one kind: kind, "
                                      "unit, default, physical range and description.",
                          epilog="Documentation: docs/components.md")
    comp.add_argument("kind", nargs="?", help="a component kind (the table name: clutch, gear, wet_clutch, ...)")
    comp.set_defaults(func=_components)
    dl.set_defaults(func=lambda args: (dl.print_help(), 2)[1])


def _simulate(args) -> int:
    from .common import run_note, run_options
    from ..io.files import OutputSet, atomic_to_csv, atomic_write_bytes
    from ..units import to_si
    from ..driveline.description import load_driveline

    outputs = OutputSet([args.output, args.events, args.plot], args.force)   # checked before the run
    options = run_options(args)
    fixed_step = options["fixed_step"]
    spec = load_driveline(args.file)
    t_end = to_si(args.t_end, "s", name="--t-end") if args.t_end is not None else spec.t_end
    if t_end is None:
        raise ParameterError(f"{args.file}: no end time: give --t-end or [simulation] t_end")
    step = spec.output_step if options["output_step"] is None else options["output_step"]
    if not t_end > 0:
        raise ParameterError(f"end time = {t_end!r} s: must be > 0")
    inputs = _inputs(args.input, spec.driveline, args.file)
    res = spec.driveline.simulate(t_end, rtol=spec.rtol if options["rtol"] is None else options["rtol"],
                                  atol=options["atol"],
                                  max_step=spec.max_step if options["max_step"] is None else options["max_step"],
                                  output_step=step, fixed_step=fixed_step, check_invariants=args.check_invariants,
                                  inputs=inputs)
    frame = res.to_dataframe()
    events = res.events.rename(columns={"element": "component"})[["time_s", "component", "event"]]
    with outputs:   # the CSV, the events and the figure replace the old ones together, or none does
        # a fixed-step run says so in a comment line (an adaptive run's file has none: plain CSV, as before)
        atomic_to_csv(frame, outputs.staged(args.output), overwrite=args.force,
                      header_comment=run_note(options))
        if args.events:
            atomic_to_csv(events, outputs.staged(args.events), overwrite=args.force)
        if args.plot:
            from ..driveline.plots import driveline_figure

            fig = driveline_figure(frame, events, title=f"{spec.driveline.name}: {args.file}")
            buf = io.BytesIO()
            fig.savefig(buf, format="png", dpi=130, bbox_inches="tight")
            import matplotlib.pyplot as plt

            plt.close(fig)
            atomic_write_bytes(outputs.staged(args.plot), buf.getvalue(), overwrite=args.force)
    err = float(frame["energy_error_J"].abs().max())
    mode = "" if fixed_step is None else f" in fixed steps of {fixed_step:g} s"
    print(f"{args.output}: {len(frame)} samples to {t_end:g} s{mode}; {len(events)} events; "
          f"energy balance within {err:.2g} J of {float(frame['input_work_J'].abs().max()):.4g} J input work "
          f"and {float(frame['dissipated_energy_J'].abs().max()):.4g} J dissipated")
    return 0


def _inputs(items, driveline, file) -> dict:
    """``--input NAME=VALUE`` options as :meth:`~clutchlab.driveline.Driveline.simulate`'s ``inputs``: a number
    (SI) or a quantity in the input's unit, held; or ``(times, values)`` from a CSV trace."""
    from pathlib import Path

    from ..units import COLUMN_UNITS, to_si

    units = driveline.input_units   # (not from driveline.system(): that would build the network twice)
    out = {}
    for item in items:
        name, sep, value = (x.strip() for x in str(item).partition("="))
        if not sep or not name or not value:
            raise ParameterError(f"--input {item!r}: expected NAME=VALUE (e.g. throttle=0.3, load='20 N m' or "
                                 "load=trace.csv)")
        if name not in units:
            raise ParameterError(f"--input {name}: {file} has no input {name!r} (inputs: "
                                 f"{', '.join(units) or 'none; declare one with [input.NAME]'})")
        if name in out:
            raise ParameterError(f"--input {name}: given twice")
        unit = COLUMN_UNITS[units[name]][0]
        if value.lower().endswith(".csv") or Path(value).is_file():
            out[name] = _trace(Path(value), unit, f"--input {name}")
            continue
        try:
            out[name] = float(value)        # a plain number: SI, as in the description file
        except ValueError:
            out[name] = to_si(value, unit, name=f"--input {name}")
        if out[name] != out[name] or abs(out[name]) == float("inf"):
            raise ParameterError(f"--input {name} = {value!r}: not a finite number")
    return out


def _trace(path, unit: str, what: str):
    """``(times [s], values [unit])`` of a CSV trace: ``time_s`` and one value column whose name ends in its unit
    suffix (``load_Nm``, ``clutch_1``); lines starting with ``#`` are comments.  Read and checked (finite
    numbers) by :func:`clutchlab.io.read_table`."""
    import numpy as np

    from ..io import read_table
    from ..io.channels import unit_conversion
    from ..units import column_unit

    label = f"{what}: {path}"
    try:
        frame = read_table(path, ["time_s"], name=label)
        others = [c for c in frame.columns if c != "time_s"]
        if len(others) != 1:
            raise ParameterError(f"{label}: expected the columns time_s and one value column (found "
                                 f"{', '.join(map(str, frame.columns)) or 'none'})")
        column = str(others[0])
        frame = read_table(frame, [column], name=label)
    except DataError as exc:
        raise ParameterError(str(exc)) from None
    source = column_unit(column)
    if source is None:
        raise ParameterError(f"{label}: column {column!r} does not name its unit: end it with the unit's suffix "
                             f"(e.g. {column}_Nm, {column}_1)")
    scale, offset = unit_conversion(source, unit, name=column, where=label, error=ParameterError)
    times, values = frame["time_s"].to_numpy(dtype=float), frame[column].to_numpy(dtype=float)
    if times.size == 0 or np.any(np.diff(times) <= 0):
        raise ParameterError(f"{label}: time_s must hold strictly increasing times (at least one)")
    return times, scale * values + offset


def _components(args) -> int:
    from ..component import component_table, components
    from ..driveline import BUILTIN

    if args.kind is not None:
        print(component_table(args.kind), end="")
        return 0
    builtin = {c.kind for c in BUILTIN}
    known = components()
    width = max(len(k) for k in known)
    for kind, comp in known.items():
        where = "" if kind in builtin else f"  [{getattr(comp.build, '__module__', '?')}]"
        print(f"{kind:<{width}}  {comp.description}{where}")
    return 0


def _describe(args) -> int:
    from ..driveline.description import load_driveline

    spec = load_driveline(args.file)
    try:   # every check simulate makes before its run (a one-way clutch started backward)
        spec.driveline.system(spec.rtol)
    except ParameterError as exc:
        raise ParameterError(f"{args.file}: {exc}") from None
    print(spec.driveline.describe())
    return 0
