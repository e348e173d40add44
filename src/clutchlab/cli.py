"""Command-line interface: a thin layer over clutchlab's public API.

Each subsystem registers its own sub-command from ``clutchlab.<subsystem>.cli``
(a ``register(subparsers)`` function that adds a parser whose handler is set
with ``set_defaults(func=...)``).  Every :class:`~clutchlab.errors.ClutchlabError`,
missing file or refused overwrite becomes one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time

from . import __version__
from .errors import ClutchlabError

#: modules that contribute a sub-command (``register(subparsers)``)
SUBSYSTEM_CLIS = (
    "clutchlab.eclutch.cli",
    "clutchlab.wet.cli",
    "clutchlab.emtc.cli",
    "clutchlab.params.cli",  # clutchlab params show|check
    "clutchlab.fmu.cli",  # clutchlab export-fmu
    "clutchlab.sweep.cli",  # clutchlab sweep
    "clutchlab.report.cli",  # clutchlab report RUN_DIR
    "clutchlab.io.cli",  # clutchlab convert (measurement files)
)
#: functions that contribute a section to ``clutchlab demo`` (``demo_section(workdir, progress)``)
DEMO_SECTIONS = ("clutchlab.eclutch.demo", "clutchlab.wet.demo", "clutchlab.emtc.demo")


def _optional_module(name: str):
    """Import a subsystem module; ``None`` only if that module itself does not exist."""
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        if exc.name is not None and name.startswith(exc.name):
            return None
        raise


def progress(message: str) -> None:
    """Print a progress line to stderr (long runs say what they are doing)."""
    print(f"[clutchlab {time.strftime('%H:%M:%S')}] {message}", file=sys.stderr, flush=True)


def _demo(args) -> int:
    from .report import write_report

    sections = []
    t0 = time.perf_counter()
    progress("the first run compiles numba kernels (several minutes on a fresh machine; cached afterwards)")
    for name in DEMO_SECTIONS:
        mod = _optional_module(name)
        if mod is None:
            continue
        progress(f"running {name.split('.')[1]} demo ...")
        sections.append(mod.demo_section(progress=progress))
    index = write_report(sections, args.output, title="clutchlab demo report (synthetic data)", overwrite=args.force)
    progress(f"done in {time.perf_counter() - t0:.1f} s")
    print(index)
    return 0


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser with every available sub-command."""
    parser = argparse.ArgumentParser(
        prog="clutchlab",
        description="Model, simulate and identify automotive clutches (E-clutch, wet multi-plate, EMTC).",
        epilog="Documentation: README.md and docs/index.md (one page per subsystem). "
               "'clutchlab COMMAND --help' describes each command.",
    )
    parser.add_argument("--version", action="version", version=f"clutchlab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    demo = sub.add_parser("demo", help="run every subsystem's demo on bundled synthetic data and write an HTML report",
                          description="Run the E-clutch, wet-clutch and EMTC demos on the bundled synthetic data "
                                      "(characterisation, identification, simulation against the virtual rigs) and "
                                      "write one self-contained HTML report with figures and tables.",
                          epilog="Documentation: docs/report.md")
    demo.add_argument("-o", "--output", default="clutchlab-demo", help="report folder to write (default: %(default)s)")
    demo.add_argument("--force", action="store_true", help="replace the report folder if it exists")
    demo.set_defaults(func=_demo)
    for name in SUBSYSTEM_CLIS:
        mod = _optional_module(name)
        if mod is not None:
            mod.register(sub)
    return parser


def main(argv=None) -> int:
    """Entry point of the ``clutchlab`` command."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "func"):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except (ClutchlabError, FileExistsError, FileNotFoundError, PermissionError, IsADirectoryError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(f"clutchlab: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("clutchlab: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
