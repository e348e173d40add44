"""``clutchlab control trim|linearize|bode|judder|design MODEL ...`` and ``clutchlab control shift SOURCE``: a thin
layer over :mod:`clutchlab.control`.

``clutchlab control trim eclutch --at "4 mm" -o op.json``
    the steady state holding the release bearing at 4 mm (motor voltage solved for);
``clutchlab control linearize eclutch --at "4 mm" -u motor_voltage -y bearing_position -o lin.json``
    the linear model there, matrices with their names and units (JSON or CSV);
``clutchlab control bode eclutch --at "0.5 mm" --at "4 mm" --at "8 mm" -u motor_voltage -y bearing_position -o bode.png``
    Bode diagram at several operating points (and ``--table`` its magnitude and phase as CSV, ``--poles``
    the poles at each point).
``clutchlab control judder driveline FILE.toml --run-to "0.3 s" -o modes.csv``
    the oscillating modes of the network in the mode its run is in at 0.3 s (frequency, damping ratio, growth
    rate) and the damping each sliding clutch adds to them: judder where a mode grows (``--run-to`` repeated:
    a timeline along the run);
``clutchlab control shift examples/driveline_dct_upshift.toml --offgoing c1 --oncoming c2 --shaft wheels``
    with ``--engine engine --radius "0.3 m" -o shift.json``: the phases and quality metrics of a clutch-to-clutch
    shift in the network's run (or in a record of a run or a rig; a driveline's [shift] table names the clutches);
    with ``--clutch``, an automated manual transmission's interrupted shift (``--offgoing``, ``--oncoming``: its
    synchronisers);
``clutchlab control design eclutch --at "4 mm" -u motor_voltage -y bearing_position --crossover "5 Hz" ...``
    with ``--phase-margin "60 deg" -o pi.json``: the PI for that margin (JSON); with ``--run run.csv --step
    "0.5 mm"`` also the nonlinear model run with it in the loop for a reference step.

Other models: ``wet``, ``emtc`` (their held inputs; ``--coil-drive current`` drives the EMTC's coil at
the input ``coil_current_command``) and ``driveline FILE.toml``, with the generic trim options
(``--set``, ``--hold``, ``--target``, ``--free``, ``--mode``, ``--time``, ``--settle``); ``--branch
i2=rising`` linearises a hysteretic element along one branch.
"""

from __future__ import annotations

import io

from ..errors import ParameterError

__all__ = ["register"]

MODELS = ("eclutch", "wet", "emtc", "driveline")


def register(subparsers) -> None:
    """Add the ``control`` command and its sub-commands."""
    top = subparsers.add_parser(
        "control", help="operating points, linear models and Bode diagrams of any model (python-control)",
        description="Control design on the models: steady states (trim), linear state-space models within "
                    "the active mode, and frequency responses and poles over operating points.",
        epilog="Documentation: docs/control.md")
    sub = top.add_subparsers(dest="control_command", metavar="SUBCOMMAND")
    trim = sub.add_parser("trim", help="find a steady state and write it (JSON)",
                          description="Steady state of a model for given inputs, or the inputs that hold given "
                                      "outputs; written as JSON with every state, input and output and its unit.",
                          epilog="Documentation: docs/control.md")
    _common(trim)
    trim.add_argument("-o", "--output", required=True, help="JSON file of the operating point")
    trim.set_defaults(func=_trim)
    lin = sub.add_parser("linearize", help="linear state-space model at an operating point (JSON or CSV)",
                         description="Linearise a model at a steady state within its active mode and write A, B, "
                                     "C, D with the names and units of states, inputs and outputs.",
                         epilog="Documentation: docs/control.md")
    _common(lin)
    _signals(lin)
    lin.add_argument("-o", "--output", required=True, help="file to write: .json or .csv")
    lin.set_defaults(func=_linearize)
    bode = sub.add_parser("bode", help="Bode diagram (PNG) at one or more operating points",
                          description="Frequency response of the linear model at each operating point (each "
                                      "--at of the E-clutch), as a figure; optionally the table and the poles.",
                          epilog="Documentation: docs/control.md")
    _common(bode)
    _signals(bode)
    bode.add_argument("-o", "--output", required=True, help="PNG figure to write")
    bode.add_argument("--table", help="also write magnitude and phase as CSV")
    bode.add_argument("--poles", help="also write the poles at each operating point as CSV")
    bode.add_argument("--over", default=None, metavar="NAME",
                      help="plot the other outputs over this one (one input), e.g. -y pressure -y motor_current "
                           "--over motor_current: pressure per motor current")
    bode.add_argument("--fmin", default="0.1 Hz", help="lowest frequency (default 0.1 Hz)")
    bode.add_argument("--fmax", default="2 kHz", help="highest frequency (default 2 kHz)")
    bode.set_defaults(func=_bode)
    jud = sub.add_parser("judder", help="oscillating modes and the damping of sliding clutches (judder)",
                         description="The torsional modes of a model in its active mode (frequency, damping ratio, "
                                     "growth rate) and the damping d tau/d w_rel each sliding friction element adds "
                                     "(negative where its friction falls with the slip speed), at a steady state "
                                     "(the trim options) or at the state a run reaches (--run-to); exit status 0 "
                                     "either way (the verdict is printed and written).",
                         epilog="Documentation: docs/control.md (Judder)")
    _common(jud)
    jud.add_argument("--run-to", metavar="TIME", action="append", default=[],
                     help="run the model from its start to TIME (e.g. '0.3 s') and analyse the state it reaches there, "
                          "frozen in its mode (instead of a trim); repeat for a timeline along the run (the least "
                          "damped mode and the sliding elements' damping at each time)")
    jud.add_argument("-o", "--output", help="file to write: .json (modes, friction elements, verdict; a timeline's "
                                            "rows) or .csv (the modes; a timeline's rows)")
    jud.add_argument("--plot", metavar="PNG", help="with --run-to repeated: also write the timeline's figure (damping "
                                                   "ratio and frequency of the least damped mode, the sliding "
                                                   "elements' damping; where a mode grows shaded)")
    jud.set_defaults(func=_judder)
    shift = sub.add_parser("shift", help="shift quality of a clutch-to-clutch gear shift (a run or a rig's record)",
                           description="The phases (torque phase, inertia phase) and the quality metrics of one "
                                       "clutch-to-clutch shift: its times, the output's acceleration dip, jerk and "
                                       "vibration dose value, the lock-up slip rate, the off-going clutch's flare "
                                       "and tie-up and each clutch's heat. SOURCE is a driveline (TOML: simulated "
                                       "with its [simulation] settings; its [shift] table names the clutches) or a "
                                       "record of a run or a rig (CSV, Parquet, MDF 4) with the clutches' "
                                       "<name>.tau_Nm and <name>.w_rel_rad_s, the output's speed and time_s at a "
                                       "constant interval.",
                           epilog="Documentation: docs/control.md (Shift quality)")
    shift.add_argument("source", help="driveline description (.toml), or a record (.csv, .parquet, .mf4)")
    shift.add_argument("--channel-map", metavar="MAP.toml",
                       help="a record's channels to clutchlab names and SI units (as for clutchlab convert): "
                            "<clutch>.tau_Nm, <clutch>.w_rel_rad_s, the output's speed, time_s")
    shift.add_argument("--rate", default=None, help="resample the record onto a uniform time base at this rate, "
                                                    "e.g. '1 kHz' (a record logged at several rates)")
    shift.add_argument("--dbc", action="append", metavar="DATABASE",
                       help="CAN database (.dbc, .arxml) decoding an MDF bus log's frames (repeatable)")
    shift.add_argument("--offgoing", metavar="CLUTCH",
                       help="the off-going clutch, e.g. c1 (a driveline: default its [shift] table's)")
    shift.add_argument("--oncoming", metavar="CLUTCH",
                       help="the on-coming clutch, e.g. c2 (a driveline: default its [shift] table's)")
    shift.add_argument("--shaft", metavar="NAME",
                       help="the output's speed (the output shaft's or the wheels'): an inertia (its <name>.w_rad_s) "
                            "or a column, e.g. wheels (a driveline: default its [shift] table's output)")
    shift.add_argument("--engine", default=None, metavar="NAME", help="the engine's speed, drawn in the figure")
    shift.add_argument("--clutch", default=None, metavar="CLUTCH",
                       help="an automated manual transmission's clutch: the shift is an interrupted one, "
                            "--offgoing and --oncoming its synchronisers (a driveline: default its [shift] table's)")
    shift.add_argument("--radius", default=None,
                       help="travel per radian of the output (tyre radius over the axle ratio behind it), e.g. "
                            "'0.3 m': the acceleration in m/s^2 (default: the output's angular acceleration)")
    shift.add_argument("--start", default=None, help="the shift's start, e.g. '0.5 s' (default: from the columns)")
    shift.add_argument("--threshold", type=float, default=None,
                       help="share of the largest torque and slip below which a clutch carries nothing or is "
                            "locked (default 0.02)")
    shift.add_argument("--settle", default=None, help="read the acceleration this long after the shift's end "
                                                      "(default 0.3 s)")
    shift.add_argument("--filter", default=None, help="low-pass the output's speed at this frequency before it is "
                                                      "differentiated, for a rig's record, e.g. '20 Hz'")
    shift.add_argument("-o", "--output", dest="write", default=None,
                       help="file to write: .json (phases and metrics) or .csv (the metrics' table)")
    shift.add_argument("--plot", metavar="PNG", help="also write the shift's figure: speeds, clutch torques, "
                                                     "acceleration and jerk, its phases shaded")
    shift.add_argument("--force", action="store_true", help="overwrite the files")
    shift.set_defaults(func=_shift)
    tcu = sub.add_parser("tcu", help="a transmission's gear command (an AMT's or a DCT's), carried out by its "
                                     "controller",
                         description="Run a driveline whose [tcu] table declares a transmission's controller: an "
                                     "automated manual transmission's (AmtController in Python: torque down, clutch "
                                     "open, neutral, synchronise, clutch closed, waiting on the synchronisers) or, "
                                     "with type = \"dct\", a dual-clutch transmission's (DctController: power "
                                     "shifts, the hand-over where the off-going clutch carries nothing), in the loop "
                                     "with the network at its sample time. Prints the phases and, with a [shift] "
                                     "table (the output, the engine, the radius; an AMT's clutch), every shift's "
                                     "quality.",
                         epilog="Documentation: docs/control.md (A transmission controller for the AMT, A "
                                "power-shift controller for the DCT)")
    tcu.add_argument("source", help="driveline description (.toml) with a [tcu] table")
    tcu.add_argument("-o", "--output", dest="write", default=None,
                     help="the run at the controller's samples (.csv): every state and output, and the inputs it set")
    tcu.add_argument("--events", default=None, help="the network's events (.csv): time_s, event, element")
    tcu.add_argument("--phases", default=None, help="the controller's phases (.csv): time_s, phase, gear")
    tcu.add_argument("--quality", default=None, help="every shift's quality (.json: a list, as control shift's); "
                                                     "needs a [shift] table")
    tcu.add_argument("--t-end", default=None, help="end time, e.g. '3 s' (default: [simulation] t_end)")
    tcu.add_argument("--force", action="store_true", help="overwrite the files")
    tcu.set_defaults(func=_tcu)
    design = sub.add_parser("design", help="PI for a phase margin at an operating point, and its closed-loop run",
                            description="Linearise the model at a steady state (one input, one output), design "
                                        "the PI C(s) = Kp (1 + 1/(Ti s)) giving the phase margin at the crossover "
                                        "(loop shaping, Åström and Murray Ch. 11), check the closed loop's poles, "
                                        "and write the controller as JSON; with --run, discretise it at "
                                        "--sample-time and run the nonlinear model with it in the loop from the "
                                        "operating point for a step of the reference.",
                            epilog="Documentation: docs/control.md ('From the command line: design')")
    _common(design)
    design.add_argument("-u", "--u", dest="inputs", action="append", required=True, metavar="INPUT",
                        help="the input the PI drives (one), e.g. motor_voltage")
    design.add_argument("-y", "--y", dest="outputs", action="append", required=True, metavar="NAME",
                        help="the state or output it controls (one), e.g. bearing_position")
    design.add_argument("--branch", action="append", default=[], metavar="NAME=rising|falling",
                        help="linearise a hysteretic element along one branch (as for linearize)")
    design.add_argument("--crossover", required=True, help="gain crossover frequency, e.g. '10 Hz'")
    design.add_argument("--phase-margin", required=True, help="phase margin, e.g. '60 deg' (0 to 90)")
    design.add_argument("-o", "--output", required=True, help="JSON file of the controller")
    design.add_argument("--run", metavar="RUN.csv",
                        help="also run the closed loop (nonlinear model, discrete PI) and write it as CSV")
    design.add_argument("--sample-time", default="1 ms", help="controller period of the run (default 1 ms)")
    design.add_argument("--step", default="0", help="step of the reference at t = 0 in the output's unit, e.g. "
                                                     "'0.5 mm' (default 0: the operating point held)")
    design.add_argument("--t-end", default="0.5 s", help="length of the run (default 0.5 s)")
    design.set_defaults(func=_design)
    top.set_defaults(func=lambda args: (top.print_help(), 2)[1])


def _png(fig) -> bytes:
    """A figure as PNG bytes (120 dpi, tight), the figure closed: written with its command's other outputs."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def _common(p) -> None:
    p.add_argument("model", choices=MODELS, help="model (its bundled parameters; a driveline from its FILE)")
    p.add_argument("file", nargs="?", default=None, help="driveline description (TOML); the others take none")
    p.add_argument("--at", action="append", default=[],
                   help="E-clutch: bearing position of the operating point, e.g. '4 mm' (bode: repeat for "
                        "several)")
    p.add_argument("--input", dest="eclutch_input", choices=("voltage", "bearing_reference"), default="voltage",
                   help="E-clutch: held input, motor voltage (open loop, default) or the position controller's "
                        "reference (closed loop)")
    p.add_argument("--direction", choices=("slip_forward", "slip_backward"), default="slip_forward",
                   help="E-clutch: friction mode, the direction the bearing last moved in (default slip_forward)")
    p.add_argument("--set", action="append", default=[], metavar="INPUT=VALUE",
                   help="hold an input, e.g. 'force_reference=300 N'")
    p.add_argument("--hold", action="append", default=[], metavar="STATE=VALUE",
                   help="keep a state at a value instead of requiring it steady, e.g. 'temperature=80 degC'")
    p.add_argument("--target", action="append", default=[], metavar="NAME=VALUE",
                   help="require a state or output value (one --free input each)")
    p.add_argument("--free", action="append", default=[], metavar="INPUT", help="an input solved for")
    p.add_argument("--mode", action="append", default=[], metavar="MODE=VALUE",
                   help="mode of a hybrid model, e.g. 'piston=free'")
    p.add_argument("--coil-drive", choices=("controller", "current"), default=None,
                   help="EMTC: the coil driven by its torque controller (default) or at the held input "
                        "coil_current_command (current drive: --set coil_current_command='1.5 A')")
    p.add_argument("--time", default="0 s", help="time of the operating point (models with profiles)")
    p.add_argument("--settle", default="0 s", help="simulate this long with the inputs held before Newton's method")
    p.add_argument("--force", action="store_true", help="overwrite the outputs")


def _signals(p) -> None:
    p.add_argument("-u", "--u", dest="inputs", action="append", default=None, metavar="INPUT",
                   help="input of the linear model (repeat; default: all held inputs)")
    p.add_argument("-y", "--y", dest="outputs", action="append", default=None, metavar="NAME",
                   help="state or output of the linear model (repeat; default: all outputs)")
    p.add_argument("--branch", action="append", default=[], metavar="NAME=rising|falling",
                   help="linearise a hysteretic element along one branch, e.g. 'i2=rising' (the EMTC magnet "
                        "driven up); default: the mean of both slopes")


def _system(args):
    from ..system import MODELS as REGISTRY

    if args.model != "driveline" and args.file is not None:
        raise ParameterError(f"control {args.model} takes no file (got {args.file!r}); only driveline does")
    if args.model != "eclutch" and args.at:
        raise ParameterError(f"--at is the E-clutch's bearing position; for {args.model} use --target/--set")
    if args.model != "emtc" and args.coil_drive is not None:
        raise ParameterError(f"--coil-drive is the EMTC's; {args.model} has no coil")
    if args.model == "eclutch":
        from ..eclutch import EClutch

        ec = EClutch()
        key = "voltage" if args.eclutch_input == "voltage" else "bearing_reference"
        return ec, ec.as_system({key: 0.0}, held_input=True)
    if args.model == "wet":
        import clutchlab.wet  # noqa: F401  (registers the model)

        return None, REGISTRY["wet"]()
    if args.model == "emtc":
        from ..emtc.system import BenchOptions, bench_system

        return None, bench_system(cosimulation=True, options=BenchOptions(coil_drive=args.coil_drive or "controller"))
    if args.file is None:
        raise ParameterError("control ... driveline needs its description: clutchlab control trim driveline FILE.toml")
    from ..driveline.description import load_driveline

    return None, load_driveline(args.file).driveline.system()


def _name_values(items, flag: str, form: str) -> dict:
    """``{NAME: VALUE}`` from ``NAME=VALUE`` arguments of ``flag`` (strings; ``form`` names the form in errors)."""
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep:
            raise ParameterError(f"{flag} {item!r}: expected {form}")
        out[name.strip()] = value.strip()
    return out


def _branches(args) -> dict:
    return _name_values(args.branch, "--branch", "NAME=rising or NAME=falling")


def _pairs(system, items, kinds, flag):
    from ..units import to_si
    from ..trim import resolve

    out = {}
    for name, value in _name_values(items, flag, "NAME=VALUE").items():
        kind, i = resolve(system, name, kinds)
        var = {"state": system.states, "output": system.outputs, "input": system.inputs}[kind][i]
        out[var.name] = to_si(value, _unit_of(var, ""), name=f"{flag} {name}")
    return out


def _points(args):
    """The operating points the arguments ask for: ``[(label, value, OperatingPoint)]``."""
    from ..units import to_si
    from ..trim import operating_point

    ec, system = _system(args)
    if ec is not None and args.at:
        if any((args.set, args.hold, args.target, args.free, args.mode)):
            raise ParameterError("--at trims the E-clutch by itself; drop --set/--hold/--target/--free/--mode")
        out = []
        for at in args.at:
            pos = to_si(at, "m", name="--at")
            out.append((f"bearing at {pos * 1e3:g} mm", pos,
                        ec.operating_point(pos, input=args.eclutch_input, friction=args.direction)))
        return out
    modes = _name_values(args.mode, "--mode", "MODE=VALUE")
    op = operating_point(system, inputs=_pairs(system, args.set, ("input",), "--set"),
                         states=_pairs(system, args.hold, ("state",), "--hold"),
                         targets=_pairs(system, args.target, ("state", "output"), "--target"),
                         free_inputs=args.free, modes=modes, t=to_si(args.time, "s", name="--time"),
                         settle=to_si(args.settle, "s", name="--settle"))
    return [(system.name, 0.0, op)]


def _trim(args) -> int:
    import json

    from ..io.files import atomic_write_text, check_writable

    check_writable(args.output, args.force)
    points = _points(args)
    if len(points) != 1:
        raise ParameterError("trim writes one operating point: give one --at")
    op = points[0][2]
    atomic_write_text(args.output, json.dumps(op.to_dict(), indent=1), overwrite=args.force)
    print(f"{op.system.name}: steady in mode {op.modes} after {op.iterations} Newton iterations -> {args.output}")
    return 0


def _linearize(args) -> int:
    from ..io.files import check_writable
    from ..control.linear import linearize, write_linear_model

    check_writable(args.output, args.force)
    branches = _branches(args)
    points = _points(args)
    if len(points) != 1:
        raise ParameterError("linearize writes one model: give one --at")
    sys = linearize(points[0][2], inputs=args.inputs, outputs=args.outputs, directions=branches)
    write_linear_model(sys, args.output, force=args.force)
    print(f"{sys.nstates} states, {sys.ninputs} inputs, {sys.noutputs} outputs -> {args.output}")
    return 0


def _judder(args) -> int:
    import json

    from ..io.files import OutputSet, atomic_to_csv, atomic_write_bytes, atomic_write_text
    from ..units import to_si
    from ..control.judder import judder_modes, judder_timeline

    if args.output is not None and not args.output.lower().endswith((".json", ".csv")):
        raise ParameterError(f"-o {args.output}: expected a .json or .csv file")
    if args.plot is not None and len(args.run_to) < 2:
        raise ParameterError("--plot draws a timeline: give --run-to two or more times")
    outputs = OutputSet([args.output, args.plot], args.force)   # checked before the run; written together
    if args.run_to:
        if any((args.at, args.set, args.hold, args.target, args.free, args.mode)):
            raise ParameterError("--run-to analyses the state a run reaches; drop the trim options "
                                 "(--at/--set/--hold/--target/--free/--mode)")
        _, system = _system(args)
        times = [to_si(t, "s", name="--run-to") for t in args.run_to]
        if len(times) > 1:
            if any(b <= a for a, b in zip(times, times[1:])):
                raise ParameterError(f"--run-to: a timeline's times must increase (got {', '.join(args.run_to)})")
            table = judder_timeline(system, times)
            png = None
            if args.plot is not None:
                from ..control.plots import judder_figure

                png = _png(judder_figure(table, title=f"{system.name}: judder along the run"))
            with outputs:
                if args.output is not None and args.output.lower().endswith(".json"):
                    rows = table.astype(object).where(table.notna(), None).to_dict(orient="records")   # NaN: null
                    atomic_write_text(outputs.staged(args.output), json.dumps(
                        {"model": system.name, "timeline": rows}, indent=1, allow_nan=False), overwrite=args.force)
                elif args.output is not None:
                    atomic_to_csv(table, outputs.staged(args.output), overwrite=args.force)
                if png is not None:
                    atomic_write_bytes(outputs.staged(args.plot), png, overwrite=args.force)
            print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
            return 0
        result = judder_modes(system, run_to=times[0])
    else:
        points = _points(args)
        if len(points) != 1:
            raise ParameterError("judder analyses one operating point: give one --at")
        result = judder_modes(points[0][2])
    with outputs:
        if args.output is not None and args.output.lower().endswith(".json"):
            atomic_write_text(outputs.staged(args.output), json.dumps(result.to_dict(), indent=1),
                              overwrite=args.force)
        elif args.output is not None:
            atomic_to_csv(result.table, outputs.staged(args.output), overwrite=args.force)
    print(result)
    return 0


def _shift(args) -> int:
    """``control shift``: the phases and metrics of a clutch-to-clutch shift in a simulated network or a record."""
    import json

    from ..driveline.shift import shift_quality
    from ..io.files import OutputSet, atomic_to_csv, atomic_write_bytes, atomic_write_text
    from ..units import to_si

    if args.write is not None and not args.write.lower().endswith((".json", ".csv")):
        raise ParameterError(f"-o {args.write}: expected a .json or .csv file")
    if args.plot is not None and not args.plot.lower().endswith(".png"):
        raise ParameterError(f"--plot {args.plot}: expected a .png file")
    outputs = OutputSet([args.write, args.plot], args.force)   # checked before the run; written together
    given = dict(offgoing=args.offgoing, oncoming=args.oncoming, output=args.shaft, engine=args.engine,
                 clutch=args.clutch,
                 threshold=args.threshold, settle=None if args.settle is None else to_si(args.settle, "s",
                                                                                         name="--settle"),
                 radius=None if args.radius is None else to_si(args.radius, "m", name="--radius"),
                 start=None if args.start is None else to_si(args.start, "s", name="--start"),
                 filter_Hz=None if args.filter is None else to_si(args.filter, "Hz", name="--filter"))
    if args.source.lower().endswith(".toml") and (args.channel_map or args.rate or args.dbc):
        raise ParameterError("--channel-map, --rate and --dbc read a record; a driveline's run has clutchlab's names")
    if args.source.lower().endswith(".toml"):
        from ..driveline.description import load_driveline

        spec = load_driveline(args.source)
        if spec.t_end is None or spec.output_step is None:
            raise ParameterError(f"{args.source}: shift quality needs [simulation] t_end and output_step (samples at "
                                 "a constant interval)")
        source = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, max_step=spec.max_step,
                                         output_step=spec.output_step)
        file_shift = spec.shift or {}
    elif args.source.lower().endswith((".csv", ".txt", ".parquet", ".mf4", ".mdf")):
        from ..io import read_measurement

        rate = None if args.rate is None else to_si(args.rate, "Hz", name="--rate")
        source = read_measurement(args.source, args.channel_map, rate=rate, databases=tuple(args.dbc or ()))
        file_shift = {}
    else:
        raise ParameterError(f"{args.source}: expected a driveline description (.toml) or a record (.csv, "
                             ".parquet, .mf4)")
    options = {**file_shift, **{k: v for k, v in given.items() if v is not None}}   # (the options win over the file)
    missing = [flag for flag, key in (("--offgoing", "offgoing"), ("--oncoming", "oncoming"), ("--shaft", "output"))
               if key not in options]
    if missing:
        raise ParameterError(f"{args.source}: give {', '.join(missing)} (or a [shift] table in the driveline file)")
    q = shift_quality(source, **options)
    png = None
    if args.plot is not None:
        from pathlib import Path

        from ..control.plots import shift_figure

        png = _png(shift_figure(q, title=f"{Path(args.source).name}: {q.order}, {q.columns['offgoing']} to "
                                         f"{q.columns['oncoming']}"))
    with outputs:
        if png is not None:
            atomic_write_bytes(outputs.staged(args.plot), png, overwrite=args.force)
        if args.write is not None and args.write.lower().endswith(".json"):
            atomic_write_text(outputs.staged(args.write), json.dumps(q.to_dict(), indent=1, allow_nan=False),
                              overwrite=args.force)
        elif args.write is not None:
            atomic_to_csv(q.table(), outputs.staged(args.write), overwrite=args.force)
    print(q)
    return 0


def _tcu(args) -> int:
    """``control tcu``: a driveline's gear command carried out by its [tcu] table's controller, in the loop."""
    import json

    from ..control.loop import closed_loop
    from ..control.dct import DctController
    from ..control.tcu import SAMPLE_TIME, SHIFT_OWN, AmtController
    from ..driveline.description import load_driveline
    from ..io.files import OutputSet, atomic_to_csv, atomic_write_text
    from ..units import to_si

    for flag, path, end in (("-o", args.write, ".csv"), ("--events", args.events, ".csv"),
                            ("--phases", args.phases, ".csv"), ("--quality", args.quality, ".json")):
        if path is not None and not path.lower().endswith(end):
            raise ParameterError(f"{flag} {path}: expected a {end} file")
    spec = load_driveline(args.source)
    if args.quality is not None and spec.shift is None:
        raise ParameterError(f"{args.source}: --quality needs a [shift] table (its clutch, output, engine, radius)")
    outputs = OutputSet([args.write, args.events, args.phases, args.quality], args.force)   # checked before the run
    if spec.tcu is None:
        raise ParameterError(f"{args.source}: no [tcu] table (the controller's type, gears, start_gear, commands, "
                             "inputs and torque: docs/control.md)")
    t_end = to_si(args.t_end, "s", name="--t-end") if args.t_end is not None else spec.t_end
    if t_end is None or not t_end > 0.0:
        raise ParameterError(f"{args.source}: give --t-end or [simulation] t_end (> 0)")
    try:
        controller = (DctController if spec.tcu.get("type") == "dct" else AmtController).from_table(spec.tcu)
    except ParameterError as exc:
        raise ParameterError(f"{args.source}: [tcu] {exc}") from None
    system = spec.driveline.system(spec.rtol)
    record = [v.name for v in (*system.states, *system.outputs) if v.name not in controller.measured]
    res = closed_loop(system, controller, spec.tcu.get("sample_time", SAMPLE_TIME), t_end,
                      measure=[*controller.measured, *record], actuate=list(controller.actuated),
                      max_step=spec.max_step)
    phases = controller.phases
    qualities = []
    if spec.shift is not None:   # every shift's, with its own synchronisers and start ([shift]: the rest)
        qualities = controller.shift_quality(res.frame, **{k: v for k, v in spec.shift.items()
                                                            if k not in SHIFT_OWN})
    with outputs:
        if args.write is not None:
            atomic_to_csv(res.frame, outputs.staged(args.write), overwrite=args.force)
        if args.events is not None:
            atomic_to_csv(res.events, outputs.staged(args.events), overwrite=args.force)
        if args.phases is not None:
            atomic_to_csv(phases, outputs.staged(args.phases), overwrite=args.force)
        if args.quality is not None:
            atomic_write_text(outputs.staged(args.quality), json.dumps([q.to_dict() for q in qualities], indent=1,
                                                                       allow_nan=False), overwrite=args.force)
    print(f"{args.source}: {len(phases)} phases of {controller.__class__.__name__}")
    for t, phase, gear in zip(phases.time_s, phases.phase, phases.gear):
        print(f"  {t:9.4f} s  {phase:<13s} gear {gear}")
    for q in qualities:
        print(q)
    return 0


def _bode(args) -> int:
    import numpy as np

    from ..io.files import OutputSet, atomic_to_csv, atomic_write_bytes
    from ..units import to_si
    from ..control.linear import frequency_table, linearize, pole_sweep

    outputs = OutputSet([args.output, args.table, args.poles], args.force)   # checked first; written together
    fmin, fmax = to_si(args.fmin, "Hz", name="--fmin"), to_si(args.fmax, "Hz", name="--fmax")
    if not 0 < fmin < fmax:
        raise ParameterError(f"--fmin {args.fmin!r} and --fmax {args.fmax!r}: need 0 < fmin < fmax")
    branches = _branches(args)
    points = _points(args)
    f = np.logspace(np.log10(fmin), np.log10(fmax), 400)
    models = [(label, value, op, linearize(op, inputs=args.inputs, outputs=args.outputs, directions=branches))
              for label, value, op in points]
    if models[0][3].ninputs == 0:
        raise ParameterError(f"{points[0][2].system.name} has no held inputs: no frequency response")
    over = None
    if args.over is not None:
        from ..trim import resolve

        kind, i = resolve(points[0][2].system, args.over, ("state", "output"))
        over = (points[0][2].system.states if kind == "state" else points[0][2].system.outputs)[i].column
    tables = []
    for label, value, _, sys in models:
        t = frequency_table(sys, f, over=over)
        t.insert(0, "operating_point", label)
        tables.append(t)
    import pandas as pd

    from ..control.plots import bode_figure

    png = _png(bode_figure([(label, sys) for label, _, _, sys in models], f, over=over))
    with outputs:
        atomic_write_bytes(outputs.staged(args.output), png, overwrite=args.force)
        if args.table:
            atomic_to_csv(pd.concat(tables, ignore_index=True), outputs.staged(args.table), overwrite=args.force)
        if args.poles:
            name = "bearing_position_m" if args.model == "eclutch" and args.at else "operating_point_1"
            poles = pole_sweep([(value, op) for _, value, op, _ in models], inputs=args.inputs,
                               outputs=args.outputs, directions=branches, name=name)
            atomic_to_csv(poles, outputs.staged(args.poles), overwrite=args.force)
    print(args.output)
    return 0


def _unit_of(var, dimensionless: str = "1") -> str:
    """The pint unit of a system variable (its ``unit`` may be a column suffix: ``rad_s``); ``dimensionless`` for
    none."""
    from ..units import COLUMN_UNITS

    return COLUMN_UNITS.get(var.unit, (var.unit,))[0] or dimensionless


def _per(num: str, den: str) -> str:
    """``num`` per ``den`` as a unit: ``V/m``, ``V/(rad/s)``."""
    return f"{num}/{den}" if den.replace("_", "").isalnum() else f"{num}/({den})"


def _design(args) -> int:
    """``control design``: trim, linearise (SISO), PI for the margin; optionally the closed-loop run."""
    import json

    import numpy as np

    from ..io.files import OutputSet, atomic_to_csv, atomic_write_text
    from ..units import to_si
    from ..control.design import pi_for_phase_margin
    from ..control.linear import linearize
    from ..control.loop import closed_loop
    from ..trim import resolve

    outputs = OutputSet([args.output, args.run], args.force)   # checked first; the two written together
    if len(args.inputs) != 1 or len(args.outputs) != 1:
        raise ParameterError(f"a PI drives one input from one output: got -u {args.inputs} and -y {args.outputs}")
    crossover = to_si(args.crossover, "Hz", name="--crossover")
    margin = to_si(args.phase_margin, "deg", name="--phase-margin")
    sample_time = to_si(args.sample_time, "s", name="--sample-time")
    t_end = to_si(args.t_end, "s", name="--t-end")
    if args.run is not None and not (sample_time > 0 and t_end >= sample_time):
        raise ParameterError(f"--sample-time {args.sample_time!r} and --t-end {args.t_end!r}: need 0 < sample time "
                             "<= t_end")
    if args.run is not None and crossover >= 0.5 / sample_time:
        raise ParameterError(f"--crossover {args.crossover!r} at or above the Nyquist frequency "
                             f"{0.5 / sample_time:g} Hz of --sample-time {args.sample_time!r}")
    points = _points(args)
    if len(points) != 1:
        raise ParameterError("design works at one operating point: give one --at")
    label, _, op = points[0]
    system = op.system
    plant = linearize(op, inputs=args.inputs, outputs=args.outputs, directions=_branches(args))
    pi = pi_for_phase_margin(plant, crossover, margin)
    _, ui = resolve(system, args.inputs[0], ("input",))
    ykind, yi = resolve(system, args.outputs[0], ("state", "output"))
    u, y = system.inputs[ui], (system.states if ykind == "state" else system.outputs)[yi]
    import control

    loop = control.ss(pi.tf()) * control.ss(plant)
    margins = control.stability_margins(loop)   # (gm, pm, sm, w at -180 deg, gain crossover w, w of sm)
    gm, pm, wp = margins[0], margins[1], margins[4]
    poles = control.feedback(loop, 1).poles()
    doc = {"controller": "PI", "law": "C(s) = Kp (1 + 1/(Ti s)) acting on reference - measured",
           "kp": pi.kp, "kp_unit": _per(_unit_of(u), _unit_of(y)), "ti_s": pi.ti,
           "input": u.column, "output": y.column, "operating_point": label, "at_time_s": op.t,
           "operating_input": float(op.u[ui]), "operating_output": op.value(y.name),
           "crossover_Hz": crossover, "phase_margin_deg": margin,
           "achieved": {"phase_margin_deg": float(pm), "crossover_Hz": float(wp) / (2 * np.pi),
                        "gain_margin": None if not np.isfinite(gm) else float(gm)},
           "closed_loop_poles": [[float(p.real), float(p.imag)] for p in poles]}
    frame = None
    if args.run is not None:
        step = to_si(args.step, _unit_of(y), name="--step")
        target = doc["operating_output"] + step
        result = closed_loop(op, pi.discrete(sample_time), sample_time, t_end, measure=[y.name], actuate=[u.name],
                             reference=target)
        frame = result.frame
    with outputs:   # the PI file and its closed-loop run replace the old ones together
        atomic_write_text(outputs.staged(args.output), json.dumps(doc, indent=1), overwrite=args.force)
        if frame is not None:
            atomic_to_csv(frame, outputs.staged(args.run), overwrite=args.force,
                          header_comment=f"closed loop of {system.name} at {label} with the PI of {args.output} "
                                         f"(Kp = {pi.kp:.6g}, Ti = {pi.ti:.6g} s, Tustin at {sample_time:g} s), "
                                         f"reference step {args.step} at t = 0; written by clutchlab control design")
    print(f"{system.name} at {label}: Kp = {pi.kp:.6g} {doc['kp_unit']}, Ti = {pi.ti:.6g} s for {margin:g} deg at "
          f"{crossover:g} Hz (achieved {pm:.2f} deg at {wp / (2 * np.pi):.4g} Hz) -> {args.output}")
    if frame is None:
        return 0
    out = frame[y.column].to_numpy()
    rise = target - doc["operating_output"]
    over = (np.max((out - target) * np.sign(rise)) / abs(rise) * 100.0) if rise else 0.0
    print(f"{args.run}: {len(frame)} samples to {t_end:g} s; final error {out[-1] - target:.3g} "
          f"{_unit_of(y)}" + (f", overshoot {max(over, 0.0):.1f} %" if rise else "")
          + f", input limited in {int(frame['saturated_1'].sum())} samples")
    return 0
