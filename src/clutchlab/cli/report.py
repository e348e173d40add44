"""``clutchlab report RUN [RUN ...] [-o OUT] [--force]``: HTML report of a results folder, or a comparison.

A thin layer over :func:`clutchlab.report.run.report_run_dir` (one run) and
:func:`clutchlab.report.compare.compare_runs` (two or more); progress
messages go to stderr, the path of the written ``index.html`` to stdout.
"""

from __future__ import annotations

__all__ = ["register"]


def register(subparsers) -> None:
    """Add the ``report`` command."""
    rep = subparsers.add_parser(
        "report", help="write a self-contained HTML report (figures, metrics, parameters, provenance) of a results folder",
        description="Write a self-contained HTML page (readable offline) of a results folder: figures, metrics "
                    "tables, parameters and the provenance of every file (synthetic data labelled so).",
        epilog="Documentation: docs/report.md")
    rep.add_argument("run_dir", metavar="RUN", nargs="+",
                     help="folder of results: CSV (with # comment headers), Parquet chunks, MDF4, *.toml, "
                          "manifest.json; with two or more (folders or table files), a comparison: overlays, "
                          "differences against the first, metrics per run")
    rep.add_argument("--name", action="append", metavar="NAME",
                     help="legend name of each compared run, in order (repeat once per run; default: folder or "
                          "file names)")
    rep.add_argument("--units", choices=("engineers", "si"), default="engineers",
                     help="units of the figures and tables: rpm, km/h, bar, °C, mm, kN (engineers) or SI "
                          "(default: %(default)s); the files stay SI")
    rep.add_argument("-o", "--output", help="report folder to write (default: RUN_DIR/report)")
    rep.add_argument("--title", help="page title (default: clutchlab report: <RUN_DIR name>)")
    rep.add_argument("--force", action="store_true", help="replace the report folder if it exists")
    rep.set_defaults(func=_report)


def _report(args) -> int:
    import time

    from .common import progress
    from ..report.run import report_run_dir

    t0 = time.perf_counter()
    if len(args.run_dir) > 1:
        from ..report.compare import compare_runs

        index = compare_runs(args.run_dir, args.output, names=args.name, units=args.units, overwrite=args.force,
                             progress=progress, title=args.title)
    else:
        if args.name:
            from ..errors import ParameterError

            raise ParameterError("--name names the runs of a comparison: give two or more runs")
        index = report_run_dir(args.run_dir[0], args.output, overwrite=args.force, progress=progress,
                               title=args.title, units=args.units)
    progress(f"done in {time.perf_counter() - t0:.1f} s")
    print(index)
    return 0
