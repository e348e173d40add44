"""``clutchlab eclutch ...`` sub-commands (thin layer over :mod:`clutchlab.eclutch`)."""

from __future__ import annotations

__all__ = ["register"]

import io
from pathlib import Path

import numpy as np

from .._limits import check_allocation
from .common import add_run_options
from ..errors import DataError, ParameterError
from ..io import atomic_to_csv, atomic_write_bytes, check_writable
from ..io.files import OutputSet, check_outputs
from .io import add_csv_options, csv_options
from ..units import to_si


def _save_figure(fig, path, overwrite):
    import matplotlib.pyplot as plt

    check_writable(path, overwrite)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=150, bbox_inches="tight")
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue(), overwrite=overwrite)


def _model(args):
    from ..eclutch.models import ClutchModel

    if getattr(args, "network", None):
        from ..eclutch.models import EClutchParameters
        from ..eclutch.variants import load_variant

        params = EClutchParameters.from_toml(args.params) if args.params else None
        return load_variant(args.network, params)
    if args.model is None:
        raise ParameterError("give --model N (0-4) or --network VARIANT.toml")
    if args.params:
        return ClutchModel.from_toml(args.model, args.params)
    return ClutchModel.preset(args.model)


def _characterize(args) -> int:
    from ..io import read_measurement
    from ..plotting import mark_synthetic, press_characterization
    from ..eclutch.characterize import characterize

    outputs = OutputSet([args.output, args.plot], args.force)   # checked before the work; written together
    # one read: the channel map (if any) renames the logger's channels, units in the file become SI
    try:
        meas = read_measurement(args.record, args.channel_map, required=["force_N", args.channel], time=None,
                                name=str(args.record), csv=csv_options(args))
    except DataError as exc:
        if args.channel_map or "missing column" not in str(exc):
            raise
        raise DataError(f"{exc}; map the logger's channel names with --channel-map MAP.toml "
                        "(docs/measurements.md)") from None
    curve = characterize(meas, channel=args.channel, n_grid=args.points, name=Path(args.record).stem,
                         sample_rate=args.sample_rate)
    if meas.source.dialect is not None:
        print(f"{args.record}: read as {meas.source.dialect.describe()}")
    mapped = f" with channel map {args.channel_map}" if args.channel_map else ""
    comment = f"characterised from {args.record}{mapped} by clutchlab eclutch characterize"
    if meas.source.synthetic:  # the record's own "synthetic: ..." lines travel with the curve
        comment = "\n".join([c for c in meas.source.comments if c.lower().startswith("synthetic")] + [comment])
    with outputs:
        atomic_to_csv(curve.to_frame(), outputs.staged(args.output), overwrite=args.force, header_comment=comment)
        if args.plot:
            fig = press_characterization([dict(title=str(args.record), record=meas.frame, curve=curve,
                                               channel=args.channel)], ncols=1)
            _save_figure(mark_synthetic(fig) if meas.source.synthetic else fig, outputs.staged(args.plot),
                         args.force)
    print(f"{args.output}: {curve.deflection.size} samples, {curve.n_cycles} cycles, "
          f"hysteresis half-width {np.median(curve.hysteresis_half_width):.3g} N, "
          f"cycle scatter <= {np.max(curve.cycle_scatter):.3g} N")
    return 0


def _static(args) -> int:
    from ..plotting import static_curves_panels

    outputs = OutputSet([args.output, args.plot], args.force)   # checked before the work; written together
    travel = to_si(args.travel, "m", name="--travel")
    if not travel > 0:
        raise ParameterError(f"--travel = {args.travel!r}: must be > 0")
    if args.points < 2:
        raise ParameterError(f"--points = {args.points}: need at least 2")
    model = _model(args)
    # node positions, element forces and deflections at every point
    check_allocation(args.points, 3 * len(model.network.elements) + 8, f"--points {args.points}")
    df = model.static_curve(np.linspace(0.0, travel, args.points), extrapolate=args.extrapolate)
    note = ("\n--extrapolate: characteristics may be continued linearly beyond their measured range (an assumption, "
            "not a measurement)") if args.extrapolate else ""
    with outputs:
        atomic_to_csv(df, outputs.staged(args.output), overwrite=args.force,
                      header_comment=f"static curves of {model.name} (friction off), clutchlab eclutch static{note}")
        if args.plot:
            from ..eclutch.validation import read_full_clutch_record

            record = read_full_clutch_record(args.record) if args.record else None
            fig = static_curves_panels({model.name: df}, record, title=f"{model.name}: static curves (friction off)")
            _save_figure(fig, outputs.staged(args.plot), args.force)
    peak = df["bearing_force_N"].max()
    print(f"{args.output}: {model.name}, {len(df)} points, peak bearing force {peak:.1f} N, "
          f"engaged torque {df['torque_Nm'].iloc[0]:.1f} N*m")
    return 0


def _validate(args) -> int:
    import pandas as pd

    from ..eclutch.models import MODEL_NUMBERS, ClutchModel, EClutchParameters
    from ..eclutch.validation import compare, read_full_clutch_record

    check_outputs([args.output], args.force)
    record = read_full_clutch_record(args.record, name=str(args.record))
    params = EClutchParameters.from_toml(args.params) if args.params else EClutchParameters()
    rows = [{"model": n, **compare(ClutchModel.preset(n, params), record)} for n in MODEL_NUMBERS]
    table = pd.DataFrame(rows)
    if args.output:
        atomic_to_csv(table, args.output, overwrite=args.force)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    return 0


def _lever(args) -> int:
    from ..eclutch.characterize import lever_stiffness

    check_outputs([args.output], args.force)
    result = lever_stiffness(args.record_b, args.record_c, args.ratio, reference=args.reference)
    print(result.report())
    if args.output:
        atomic_to_csv(result.points, args.output, overwrite=args.force,
                      header_comment=result.report())
    return 0


def _simulate(args) -> int:
    from .. import __version__
    from .common import progress, run_note, run_options
    from ..io import write_measurement
    from ..plotting import eclutch_response, hysteresis_loop, mark_synthetic
    from ..eclutch.scenario import load_scenario, run_scenario

    outputs = OutputSet([args.output, args.plot], args.force)   # checked before the run; written together
    options = run_options(args)
    fixed_step = options["fixed_step"]
    scenario = load_scenario(args.scenario)
    res = run_scenario(scenario, progress=progress, **options)
    frame = res.to_dataframe()
    comment = (f"synthetic: simulated by clutchlab {__version__} (E-clutch Model {scenario.model}, scenario "
               f"{args.scenario}); model output, not a measurement")
    note = run_note(options)
    if note is not None:
        comment += "\n" + note
    with outputs:
        write_measurement(frame, outputs.staged(args.output), comment=comment, overwrite=args.force)
        if args.plot:
            if scenario.input_kind == "bearing_position":
                static = scenario.clutch_model().static_curve(
                    np.linspace(frame.bearing_position_m.min(), frame.bearing_position_m.max(), 200))
                fig = hysteresis_loop({f"Model {scenario.model}": frame}, static,
                                      title=f"Model {scenario.model}: bearing force over the prescribed cycle")
            else:
                fig = eclutch_response(res.outputs_table, title=f"E-clutch, Model {scenario.model}: {args.scenario}")
            _save_figure(mark_synthetic(fig), outputs.staged(args.plot), args.force)
    st = res.stats
    steps = (f"({st['rejected_steps']} rejected)" if fixed_step is None else
             f"(fixed steps of {fixed_step:g} s)")
    print(f"{args.output}: {len(frame)} points over {scenario.t_end:g} s, {st['accepted_steps']} steps "
          f"{steps}, {len(res.events)} events; "
          f"peak bearing force {frame.get('bearing_force_N', frame['bearing_force_clutch_N']).max():.1f} N")
    return 0


def _describe(args) -> int:
    print(_model(args).network.describe())
    return 0


def register(subparsers) -> None:
    """Add ``clutchlab eclutch`` with its sub-commands."""
    p = subparsers.add_parser("eclutch", help="dry clutch-by-wire (E-clutch): press-rig characterisation, Models 0-4",
                              description="E-clutch (dry clutch-by-wire) after Haramina et al., Trans. FAMENA 48 "
                                          "(2024) 21-35: characterise component curves from press-rig records, "
                                          "build the axial Models 0-4 from them, compute static curves, validate "
                                          "against a full-clutch record and simulate actuator and clutch dynamics.",
                              epilog="Documentation: docs/eclutch.md, docs/pressrig.md, docs/eclutch_dynamics.md")
    sub = p.add_subparsers(dest="eclutch_command", metavar="COMMAND", required=True)

    c = sub.add_parser("characterize", help="characteristic curve from a raw press-rig record (CSV, Parquet, MDF 4)",
                       description="Turn a raw press-rig record (force and displacement over several load "
                                   "cycles) into a component characteristic: find the cycles, average the "
                                   "loading and unloading branches (removing the friction hysteresis) and the "
                                   "cycles (Haramina et al. 2024, Sec. 4). A channel map reads a logger's "
                                   "own channel names and units. The output curve can replace a component "
                                   "of the models ([eclutch.curves] in a parameter file).",
                       epilog="Documentation: docs/pressrig.md (characterisation), docs/measurements.md "
                              "(channel maps), docs/eclutch.md (using your own component curve)")
    c.add_argument("record", help="record (.csv, .parquet, .mf4) with force_N, displacement_m and optionally time_s, "
                                  "or the logger's channels named in --channel-map; units in the file are converted")
    c.add_argument("-o", "--output", required=True, help="curve CSV to write")
    c.add_argument("--channel", default="displacement_m", help="displacement column (default: %(default)s)")
    c.add_argument("--channel-map", metavar="MAP.toml",
                   help="TOML map from the logger's channel names and units to time_s, force_N and the "
                        "displacement channel (docs/measurements.md)")
    c.add_argument("--points", type=int, default=60, help="samples of the returned curve (default: %(default)s)")
    c.add_argument("--plot", help="also write a PNG figure of raw record and curve")
    c.add_argument("--sample-rate", type=float, metavar="HZ",
                   help="sample rate of a record without time column (only labels the raw branches; the "
                        "characterisation needs just the order of the samples)")
    c.add_argument("--force", action="store_true", help="overwrite existing output files")
    add_csv_options(c)
    c.set_defaults(func=_characterize)

    s = sub.add_parser("static", help="static curves (bearing force, normal force, torque) of Model N",
                       description="Static curves of an E-clutch model with friction off: bearing force, normal "
                                   "(clamp) force and clutch torque over the release bearing travel, by Newton "
                                   "continuation of the static equilibrium. Give a paper model (--model, "
                                   "optionally with a --params file that may replace component curves) or a "
                                   "model variant (--network).",
                       epilog="Documentation: docs/eclutch.md")
    s.add_argument("--model", type=int, help="model number 0-4 (Haramina et al. 2024)")
    s.add_argument("--network", help="TOML description of a model variant (docs/eclutch.md)")
    s.add_argument("--params", help="TOML parameter file ([eclutch] table; values may carry units)")
    s.add_argument("--travel", default="9 mm", help="release travel, with unit (default: %(default)s)")
    s.add_argument("--points", type=int, default=200, help="number of bearing positions (default: %(default)s)")
    s.add_argument("--extrapolate", action="store_true",
                   help="continue a measured characteristic linearly beyond its range where the travel needs it "
                        "(said in the file's header); without it such a travel is refused")
    s.add_argument("-o", "--output", required=True, help="CSV to write")
    s.add_argument("--plot", help="also write a PNG figure: bearing force, normal force and torque over the travel")
    s.add_argument("--record", help="full-clutch record CSV to draw in the figure")
    s.add_argument("--force", action="store_true", help="overwrite existing output files")
    s.set_defaults(func=_static)

    v = sub.add_parser("validate", help="errors of Models 0-4 against a full-clutch record (Fig. 12)",
                       description="Compare the static curves of Models 0-4 with a full-clutch release and "
                                   "re-engagement record (Haramina et al. 2024, Fig. 12): RMSE of bearing "
                                   "force and torque, peak force and its error, printed as a table.",
                       epilog="Documentation: docs/eclutch.md")
    v.add_argument("record", help="CSV with time_s, bearing_position_m, bearing_force_N, torque_Nm")
    v.add_argument("--params", help="TOML parameter file")
    v.add_argument("-o", "--output", help="CSV of the metrics")
    v.add_argument("--force", action="store_true", help="overwrite the output file")
    v.set_defaults(func=_validate)

    lv = sub.add_parser("lever", help="finger (lever) stiffness k_fl from the two multi-LVDT records (Eq. 1)",
                        description="Identify the diaphragm finger (lever) stiffness k_fl with Eq. (1) of "
                                    "Haramina et al. 2024 from the two press tests with LVDTs at the tips, the support and the "
                                    "pressure-plate edge (tests 8b and 8c).",
                        epilog="Documentation: docs/pressrig.md")
    lv.add_argument("record_b", help="test 8b: displacement_m at the tips, displacement2_m at the support")
    lv.add_argument("record_c", help="test 8c: displacement_m at the tips, displacement2_m at the pressure-plate edge")
    lv.add_argument("--ratio", type=float, required=True, help="lever ratio i_ds (< 0)")
    lv.add_argument("--reference", choices=("b", "c"), default="b",
                    help="record giving force and tip travel: b for Model 1 (Sec. 5.1), c for Models 2-4 (Sec. 5.2)")
    lv.add_argument("-o", "--output", help="CSV of the Eq. (1) points")
    lv.add_argument("--force", action="store_true", help="overwrite the output file")
    lv.set_defaults(func=_lever)

    sm = sub.add_parser("simulate", help="simulate actuator and clutch dynamics from a scenario TOML",
                        description="Simulate the E-clutch actuator (motor, spindle, hydraulics) with an axial "
                                    "Model 0-4 and stick-slip friction for a scenario: pedal, position "
                                    "reference or prescribed bearing cycle, with optional parameter tables.",
                        epilog="Documentation: docs/eclutch_dynamics.md (scenario format)")
    sm.add_argument("scenario", help="scenario TOML ([scenario], [input], optional parameter tables)")
    sm.add_argument("-o", "--output", required=True, help="results to write: .csv, .parquet or .mf4")
    add_run_options(sm)
    sm.add_argument("--plot", help="also write a PNG figure (time response, or hysteresis loop)")
    sm.add_argument("--force", action="store_true", help="overwrite existing output files")
    sm.set_defaults(func=_simulate)

    d = sub.add_parser("describe", help="print the nodes and elements of Model N",
                       description="Print the nodes (with masses) and elements (springs, contacts, levers with "
                                   "pre-strains and scales) of a paper model or a model variant.",
                       epilog="Documentation: docs/eclutch.md")
    d.add_argument("--model", type=int, help="model number 0-4")
    d.add_argument("--network", help="TOML description of a model variant")
    d.add_argument("--params", help="TOML parameter file")
    d.set_defaults(func=_describe)
