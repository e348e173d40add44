"""``clutchlab emtc ...``: Preisach identification/run and drum-bench simulation (thin layer over the API)."""

from __future__ import annotations

__all__ = ["register"]

from pathlib import Path

import numpy as np

from .._limits import short_repr
from .common import add_run_options, run_note, run_options
from ..errors import DataError
from ..io import atomic_to_csv, check_writable, read_measurement, read_table
from ..io.files import OutputSet, check_outputs


def _identify(args) -> int:
    from ..hysteresis import identify_forc_family

    check_writable(args.output, args.force)
    grid = None
    if args.grid:
        try:
            grid = np.array([float(v) for v in args.grid.split(",")])
        except ValueError:
            grid = None
        if grid is None or not np.all(np.isfinite(grid)):
            raise DataError(f"--grid {short_repr(args.grid)}: expected comma-separated finite currents in A")
    frame = read_measurement(args.forc, required=["current", "force"], time=None, name=str(args.forc)).frame
    if "airgap" in frame.columns:
        frame = read_table(frame, ["current", "force", "airgap"], name=str(args.forc))
    model, results = identify_forc_family(frame, grid=grid, name=str(args.forc))
    model.to_json(args.output, overwrite=args.force)
    for gap, res in results:
        if gap is not None:
            print(f"airgap {gap * 1e3:g} mm:")
        print(res.report())
    print(args.output)
    return 0


def _run(args) -> int:
    from ..hysteresis import Preisach

    check_writable(args.output, args.force)
    model = Preisach.from_json(args.model)
    has_gap = model.n_airgaps > 1
    if args.inverse:
        required = ["force"] + (["airgap"] if has_gap else [])
        frame = read_measurement(args.input, required=required, time=None, name=str(args.input)).frame
        res = model.invert(frame["force"].to_numpy(), frame["airgap"].to_numpy() if has_gap else None)
        out = frame.copy()
        out["current"] = res.input
        out["force_model"] = res.output
        out["feasible"] = res.feasible
        if not res.all_feasible:
            print(res.report())
    else:
        required = ["current"] + (["airgap"] if has_gap else [])
        frame = read_measurement(args.input, required=required, time=None, name=str(args.input)).frame
        out = frame.copy()
        out["force_model"] = model.simulate(frame["current"].to_numpy(), frame["airgap"].to_numpy() if has_gap else None)
    atomic_to_csv(out, args.output, overwrite=args.force,
                  header_comment=f"clutchlab emtc preisach run: model {args.model}, input {args.input}")
    print(args.output)
    return 0


def _simulate(args) -> int:
    from ..hysteresis import Preisach
    from ..emtc.bench import load_scenario, simulate_bench
    from ..emtc.magnet import bundled_magnet

    outputs = OutputSet([args.output, args.plot], args.force)   # checked before the run; written together
    options = run_options(args)
    sc = load_scenario(args.scenario)
    magnet = Preisach.from_json(sc["magnet"]) if sc["magnet"] is not None else bundled_magnet()
    res = simulate_bench(magnet, sc["scenario"], vehicle=sc["vehicle"], actuator=sc["actuator"], coupling=sc["coupling"],
                         **{k: v for k, v in options.items() if v is not None})
    frame = res.to_dataframe()
    from .. import __version__
    from ..io import write_measurement

    magnet_src = sc["magnet"] or "bundled synthetic FORC data"
    comment = (f"synthetic: simulated by clutchlab {__version__} (emtc simulate {args.scenario}; magnet: "
               f"{magnet_src}); model output, not a measurement")
    note = run_note(options)
    if note is not None:
        comment += "\n" + note
    with outputs:
        write_measurement(frame, outputs.staged(args.output), comment=comment, overwrite=args.force)
        if len(res.events):
            print(res.events[["time_s", "event", "description", "coupling_mode"]].to_string(index=False))
        if args.plot:
            from ..io import atomic_write_bytes
            from ..plotting import mark_synthetic
            from ..report.html import DPI
            from ..demo.emtc import bench_figure
            import io

            import matplotlib.pyplot as plt

            fig = mark_synthetic(bench_figure(res, "EMTC drum-bench simulation"))
            buf = io.BytesIO()
            try:
                fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
            finally:
                plt.close(fig)  # a CLI run (or many in one process) must not leave figures open
            atomic_write_bytes(outputs.staged(args.plot), buf.getvalue(), overwrite=args.force)
            print(args.plot)
    print(args.output)
    return 0


def register(subparsers) -> None:
    """Add ``emtc`` with ``preisach identify``, ``preisach run`` and ``simulate``."""
    p = subparsers.add_parser("emtc", help="electromagnetic torque-controlled coupling (Processes 2019)",
                              description="Electromagnetic torque-controlled coupling (Processes 7 (2019) 557): "
                                          "identify and run the Preisach hysteresis model of the magnet force, "
                                          "and simulate the vehicle with its EMTC on the drum bench.",
                              epilog="Documentation: docs/emtc.md")
    sub = p.add_subparsers(dest="emtc_command", metavar="COMMAND")
    sub.required = True
    pre = sub.add_parser("preisach", help="Preisach hysteresis model of the magnet force",
                         description="Identify a Preisach hysteresis model from first-order reversal curve "
                                     "(FORC) records, or run one forward (current to force) or inverse.",
                         epilog="Documentation: docs/emtc.md")
    psub = pre.add_subparsers(dest="preisach_command", metavar="COMMAND")
    psub.required = True
    ident = psub.add_parser("identify", help="identify the FORC table(s) from recorded current/force traces",
                            description="Identify the FORC table of a Preisach model (one per airgap if the "
                                        "record has an airgap column) from recorded current and force traces, "
                                        "print the fit report and write the model as JSON.",
                            epilog="Documentation: docs/emtc.md")
    ident.add_argument("forc", type=Path, help="CSV with columns current [A], force [N] (and airgap [m])")
    ident.add_argument("-o", "--output", type=Path, required=True, help="model JSON to write")
    ident.add_argument("--grid", help="comma-separated current grid [A] (default: from the reversal points)")
    ident.add_argument("--force", action="store_true", help="overwrite the output")
    ident.set_defaults(func=_identify)
    run = psub.add_parser("run", help="run a model on an input CSV (current -> force, or --inverse force -> current)",
                          description="Run an identified Preisach model on an input record: the magnet force "
                                      "for a current trace, or with --inverse the current that produces a "
                                      "wanted force.",
                          epilog="Documentation: docs/emtc.md")
    run.add_argument("model", type=Path, help="model JSON from 'identify'")
    run.add_argument("input", type=Path, help="CSV with current [A] (or force [N] with --inverse), airgap [m] for a family")
    run.add_argument("-o", "--output", type=Path, required=True, help="CSV to write")
    run.add_argument("--inverse", action="store_true", help="compute the current that produces the force column")
    run.add_argument("--force", action="store_true", help="overwrite the output")
    run.set_defaults(func=_run)
    sim = sub.add_parser("simulate", help="simulate the vehicle with EMTC on the drum bench",
                         description="Simulate the vehicle with its EMTC on the drum bench for a scenario "
                                     "(drum speeds, throttle ramp, gear; optional vehicle, actuator, coupling "
                                     "and magnet tables) and write the run with its mode events.",
                         epilog="Documentation: docs/emtc.md (scenario format)")
    sim.add_argument("scenario", type=Path, help="TOML with [scenario], [vehicle], [actuator], [coupling], [magnet]")
    sim.add_argument("-o", "--output", type=Path, required=True, help="CSV of the run")
    add_run_options(sim)
    sim.add_argument("--plot", type=Path, help="PNG figure of the run")
    sim.add_argument("--force", action="store_true", help="overwrite the outputs")
    sim.set_defaults(func=_simulate)
