"""``clutchlab convert``: measurement files between CSV, Parquet and MDF 4 (thin layer over clutchlab.io)."""

from __future__ import annotations

__all__ = ["register", "add_csv_options", "csv_options"]


def _convert(args) -> int:
    from ..io.files import check_writable
    from ..io.measurements import read_measurement, write_measurement

    check_writable(args.output, args.force)  # refuse before reading a large file
    time = None if args.no_time else args.time
    meas = read_measurement(args.input, args.channel_map, rate=args.rate, time=time,
                            interpolation=args.interpolation, csv=csv_options(args), databases=args.dbc or ())
    out = write_measurement(meas, args.output, overwrite=args.force,
                            comment=f"converted from {args.input} by clutchlab convert; {meas.source.time_base}")
    print(meas.source.describe())
    _warn_skipped(args.input, meas.source.skipped)
    print(f"{out}: {len(meas)} samples, {len(meas.channels)} channels")
    return 0


def csv_options(args) -> dict:
    """The text-table dialect set on the command line (``--encoding`` ...), as ``read_measurement(csv=...)``."""
    keys = {"csv_encoding": "encoding", "csv_separator": "separator", "csv_decimal": "decimal",
            "csv_header_row": "header_row", "csv_units_row": "units_row"}
    return {key: getattr(args, attr) for attr, key in keys.items() if getattr(args, attr, None) is not None}


def add_csv_options(p) -> None:
    """``--encoding``, ``--separator``, ``--decimal``, ``--header-row``, ``--units-row`` on a command reading records."""
    g = p.add_argument_group("text tables (CSV)", "detected from the file and printed; set them where detection "
                                                  "needs help (docs/measurements.md, 'CSV dialects')")
    g.add_argument("--encoding", dest="csv_encoding", metavar="CODEC",
                   help="text encoding, e.g. utf-8, utf-16, cp1252, iso-8859-1 (default: detected)")
    g.add_argument("--separator", dest="csv_separator", metavar="SEP",
                   help="field separator: ',', ';', tab or '|' (default: detected)")
    g.add_argument("--decimal", dest="csv_decimal", choices=(".", ","), help="decimal mark (default: detected)")
    g.add_argument("--header-row", dest="csv_header_row", type=int, metavar="LINE",
                   help="line (from 1) of the column names, 0 for none (default: detected)")
    g.add_argument("--units-row", dest="csv_units_row", type=int, metavar="LINE",
                   help="line (from 1) of the units, 0 for none (default: detected)")


#: at most this many "skipped" warning lines, then one summary line
MAX_SKIP_WARNINGS = 10


def _warn_skipped(source, skipped) -> None:
    """One stderr line per channel a read without map left out (the provenance lists them all)."""
    import sys

    items = list(skipped.items())
    for what, reason in items[:MAX_SKIP_WARNINGS]:
        print(f"clutchlab: warning: {source}: skipped {what}: {reason}", file=sys.stderr)
    if len(items) > MAX_SKIP_WARNINGS:
        print(f"clutchlab: warning: {source}: ... and {len(items) - MAX_SKIP_WARNINGS} more skipped "
              "(all listed in the provenance above)", file=sys.stderr)


def register(subparsers) -> None:
    """Add ``clutchlab convert`` to the command-line parser.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-command collection of the ``clutchlab`` parser.
    """
    p = subparsers.add_parser(
        "convert", help="convert a measurement file (CSV, Parquet, MDF 4) to clutchlab names and SI units",
        description="Read a record (.csv, .parquet, .mf4), map the logger's channels to clutchlab names with "
                    "--channel-map, convert units to those the names state, put channels logged at different "
                    "rates onto one time base, and write .csv, .parquet or .mf4 with the units in the file.",
        epilog="Documentation: docs/measurements.md")
    p.add_argument("input", help="record to read (.csv, .parquet, .mf4/.mdf)")
    p.add_argument("-o", "--output", required=True, help="file to write (.csv, .parquet, .mf4)")
    p.add_argument("--channel-map", metavar="MAP.toml",
                   help="TOML file with [channels.<name>] tables: source, unit, source_unit, group, index, "
                        "interpolation, and optionally [csv] and [bus] tables (without a map: every channel that "
                        "can be converted; the others are skipped with a warning)")
    p.add_argument("--rate", type=float, metavar="HZ", help="resample onto a uniform time base at this rate")
    p.add_argument("--interpolation", choices=("linear", "previous"), default="linear",
                   help="resampling between samples (default: %(default)s)")
    p.add_argument("--time", default="time_s", help="name of the time column (default: %(default)s)")
    p.add_argument("--no-time", action="store_true", help="the input is a table without a time column")
    p.add_argument("--force", action="store_true", help="replace the output file if it exists")
    p.add_argument("--dbc", action="append", metavar="DATABASE",
                   help="CAN database (.dbc, .arxml) decoding the raw CAN frames of an MDF bus log into signals "
                        "(repeatable; LIN databases and bus-channel filters go in the map's [bus] table)")
    add_csv_options(p)
    p.set_defaults(func=_convert)
