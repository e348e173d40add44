"""``clutchlab report RUN_DIR [-o OUT] [--force]``: HTML report of a results folder.

A thin layer over :func:`clutchlab.report.run.report_run_dir`; progress
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
    rep.add_argument("run_dir", metavar="RUN_DIR",
                     help="folder of results: CSV (with # comment headers), Parquet chunks, MDF4, *.toml, manifest.json")
    rep.add_argument("-o", "--output", help="report folder to write (default: RUN_DIR/report)")
    rep.add_argument("--title", help="page title (default: clutchlab report: <RUN_DIR name>)")
    rep.add_argument("--force", action="store_true", help="replace the report folder if it exists")
    rep.set_defaults(func=_report)


def _report(args) -> int:
    import time

    from ..cli import progress
    from .run import report_run_dir

    t0 = time.perf_counter()
    index = report_run_dir(args.run_dir, args.output, overwrite=args.force, progress=progress, title=args.title)
    progress(f"done in {time.perf_counter() - t0:.1f} s")
    print(index)
    return 0
