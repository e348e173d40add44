"""``clutchlab wet`` sub-commands: a thin layer over :mod:`clutchlab.wet`.

``clutchlab wet simulate PROTOCOL.toml -o record.csv [--fixed-step STEP] [--plot record.png] [--force]``
    run a protocol on the virtual bench and write the measured record;
``clutchlab wet identify RECORDS... -o map.json [--plot map.png] [--force]``
    identify the friction map and k1, k2 from bench records;
``clutchlab wet params [-o wet.toml]``
    print (or write) the Table 1 parameter set.
"""

from __future__ import annotations

import io
import json
import sys

from .common import add_run_options
from ..errors import ParameterError

__all__ = ["register"]


def register(subparsers) -> None:
    """Add the ``wet`` command and its sub-commands."""
    wet = subparsers.add_parser("wet", help="wet multi-plate clutch: virtual bench and friction/thermal identification",
                                description="Wet multi-plate clutch after Shin, Kim and Choi: run test protocols "
                                            "on the virtual bench, identify the friction map and the thermal "
                                            "conductances from bench records, print the Table 1 parameters.",
                                epilog="Documentation: docs/wet.md")
    sub = wet.add_subparsers(dest="wet_command", metavar="SUBCOMMAND")
    sim = sub.add_parser("simulate", help="run a protocol TOML on the virtual bench and write a bench record CSV",
                         description="Run a test protocol (friction map, engagement or inertia dynamometer) on "
                                     "the virtual wet-clutch bench and write the record its sensors measure "
                                     "(with noise, labelled synthetic), optionally with a figure.",
                         epilog="Documentation: docs/wet.md (protocol format)")
    sim.add_argument("protocol", help="protocol file ([protocol] type = friction_map | engagement | inertia_dynamometer)")
    sim.add_argument("-o", "--output", required=True, help="record CSV to write")
    add_run_options(sim)
    sim.add_argument("--plot", help="also write a PNG figure of the record (slip, torque, force, temperatures)")
    sim.add_argument("--force", action="store_true", help="overwrite the outputs")
    sim.set_defaults(func=_simulate)
    ident = sub.add_parser("identify", help="identify the friction map and k1, k2 from bench records",
                           description="Identify the friction coefficient map mu(v, T) and the thermal "
                                       "conductances k1, k2 from one or more bench records; writes the map as "
                                       "JSON with its statistics.",
                           epilog="Documentation: docs/wet.md")
    ident.add_argument("records", nargs="+", help="bench record CSV files")
    ident.add_argument("-o", "--output", required=True, help="friction map JSON to write")
    ident.add_argument("--plot", help="also write the map surface as PNG")
    ident.add_argument("--clutch", help="clutch parameter TOML ([wet] table; default Table 1)")
    ident.add_argument("--sensor-lag", type=float, default=0.0, help="thermistor time constant to compensate [s]")
    ident.add_argument("--force", action="store_true", help="overwrite the outputs")
    ident.set_defaults(func=_identify)
    par = sub.add_parser("params", help="print the Table 1 parameter set, or write it as TOML",
                         description="Print the wet-clutch parameter set of Table 1 with units, or write it as "
                                     "a TOML file that loads back identically.",
                         epilog="Documentation: docs/wet.md, docs/parameters.md")
    par.add_argument("-o", "--output", help="TOML file to write")
    par.add_argument("--force", action="store_true", help="overwrite the output")
    par.set_defaults(func=_params)
    wet.set_defaults(func=lambda args: (wet.print_help(), 2)[1])


def _simulate(args) -> int:
    from .common import run_note, run_options
    from ..io.files import OutputSet
    from ..wet.bench import load_protocol, run_protocol, write_bench_record

    outputs = OutputSet([args.output, args.plot], args.force)   # checked before the run; written together
    options = run_options(args)
    protocol, ptype, clutch, bench, friction = load_protocol(args.protocol)
    run = run_protocol(protocol, clutch, bench, friction, protocol_type=ptype,
                       **{k: v for k, v in options.items() if v is not None})
    note = run_note(options)
    header = None if note is None else run.header() + "\n" + note
    with outputs:
        write_bench_record(run, outputs.staged(args.output), overwrite=args.force, header=header)
        if args.plot:
            from ..io import atomic_write_bytes
            from ..plotting import mark_synthetic
            from ..wet.plots import map_traces_figure

            fig = map_traces_figure(run.record, title=f"virtual bench, protocol {ptype}: {args.protocol} (synthetic)")
            mark_synthetic(fig)  # the virtual bench's data are synthetic: the stamp travels with the image
            buf = io.BytesIO()
            fig.savefig(buf, format="png", dpi=150, bbox_inches="tight")
            import matplotlib.pyplot as plt

            plt.close(fig)
            atomic_write_bytes(outputs.staged(args.plot), buf.getvalue(), overwrite=args.force)
    events = ", ".join(f"{e.kind} at {e.time:.4g} s" for e in run.result.event_list) or "none"
    frames = "" if options["fixed_step"] is None else f" in fixed steps of {options['fixed_step']:g} s"
    print(f"{args.output}: {len(run.record)} samples of protocol {ptype}{frames}; events: {events}")
    return 0


def _identify(args) -> int:
    from ..errors import IdentificationError
    from ..io import atomic_write_bytes, atomic_write_text
    from ..io.files import OutputSet
    from ..wet.identify import friction_samples, identify_friction_map, identify_thermal
    from ..wet.params import WetClutch

    outputs = OutputSet([args.output, args.plot], args.force)   # checked before the work; written together
    if not args.sensor_lag >= 0 or args.sensor_lag == float("inf"):  # NaN fails the first test
        raise ParameterError(f"--sensor-lag = {args.sensor_lag!r}: must be finite and >= 0 [s]")
    clutch = WetClutch.from_toml(args.clutch) if args.clutch else WetClutch.paper()
    fmap = identify_friction_map(args.records, clutch, sensor_time_constant=args.sensor_lag)
    data = fmap.to_dict()
    shudder = data["anti_shudder"] = fmap.shudder_summary()
    if shudder["intervals"] == 0:
        shudder_line = "anti-shudder: no measured speed interval"
    elif shudder["shudder_prone"]:
        shudder_line = (f"anti-shudder: mu falls with slip speed in {shudder['falling']} of {shudder['intervals']} "
                        f"measured intervals (steepest {shudder['min_dmu_dv_s_m']:.3g} s/m at "
                        f"{shudder['at_temperature_C']:g} degC, {shudder['at_speed_m_s']:.3g} m/s): shudder-prone")
    else:
        shudder_line = f"anti-shudder: mu rises with slip speed in all {shudder['intervals']} measured intervals"
    try:
        th = identify_thermal(args.records, clutch, sensor_time_constant=args.sensor_lag)
        data["thermal"] = {"k1_W_K": th.k1, "k2_W_K": th.k2, "stderr": th.stderr, "ci95": th.ci95,
                           "rmse_W": th.rmse, "n_samples": th.n_samples}
        thermal_line = f"k1 = {th.k1:.4g} ± {th.stderr['k1']:.2g} W/K, k2 = {th.k2:.4g} ± {th.stderr['k2']:.2g} W/K"
    except IdentificationError as exc:
        data["thermal"] = {"error": str(exc)}
        thermal_line = f"thermal identification skipped: {exc}"
    with outputs:
        atomic_write_text(outputs.staged(args.output), json.dumps(data, indent=1), overwrite=args.force)
        if args.plot:
            from ..wet.plots import friction_map_figure

            fig = friction_map_figure(fmap, samples=friction_samples(args.records, clutch,
                                                                     sensor_time_constant=args.sensor_lag))
            buf = io.BytesIO()
            fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
            import matplotlib.pyplot as plt

            plt.close(fig)
            atomic_write_bytes(outputs.staged(args.plot), buf.getvalue(), overwrite=args.force)
    law = fmap.law
    print(f"{args.output}: mu_f = {law.mu0:.4g} + {law.mu_t:.3g} (T - {law.t_ref:g}) + {law.mu_e:.3g} exp(-v/{law.v_s:.3g}); "
          f"rmse {fmap.statistics['rmse']:.2g}, {fmap.statistics['cells_covered']} covered cells; {thermal_line}; "
          f"{shudder_line}")
    return 0


def _params(args) -> int:
    from ..wet.params import WetClutch

    clutch = WetClutch.paper()
    if args.output:
        clutch.to_toml(args.output, overwrite=args.force)
        print(args.output)
    else:
        sys.stdout.write(clutch.describe() + "\n")
    return 0
