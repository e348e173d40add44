"""Command-line interface: a thin layer over clutchlab's public API.

Each subsystem registers its own sub-command from ``clutchlab.<subsystem>.cli``
(a ``register(subparsers)`` function that adds a parser whose handler is set
with ``set_defaults(func=...)``).  Every :class:`~clutchlab.errors.ClutchlabError`,
missing, unreadable or unwritable file (any ``OSError``), refused overwrite,
undecodable or too deeply nested input, and as a last resort a
``MemoryError``, becomes one line of at most 400 characters (``MESSAGE_LIMIT``) on stderr
and exit code 2 -- never a traceback.
"""

from __future__ import annotations

__all__ = ["main", "build_parser", "error_message"]

import argparse
import errno
import importlib
import os
import sys
import time
import warnings

from .. import __version__
from .._limits import one_line
from ..errors import ClutchlabError, ParameterError
from .common import progress

#: the sub-commands of the subsystems: command -> (module that registers it with ``register(subparsers)``, the
#: one line ``clutchlab --help`` lists).  A command's parser is built only when that command runs (its module
#: imports its models), so ``clutchlab --help`` imports none (tests/test_cli_help.py: the lines equal the
#: modules' own).
COMMANDS = {
    "eclutch": ("clutchlab.cli.eclutch", "dry clutch-by-wire (E-clutch): press-rig characterisation, Models 0-4"),
    "wet": ("clutchlab.cli.wet", "wet multi-plate clutch: virtual bench and friction/thermal identification"),
    "emtc": ("clutchlab.cli.emtc", "electromagnetic torque-controlled coupling (Processes 2019)"),
    "driveline": ("clutchlab.cli.driveline",
                  "driveline networks: inertias, springs, sources and clutches with exact stick/slip"),
    "control": ("clutchlab.cli.control", "operating points, linear models and Bode diagrams of any model "
                                         "(python-control)"),
    "params": ("clutchlab.cli.params", "show the parameter sets of a model, write or check parameter files"),
    "export-fmu": ("clutchlab.cli.fmu", "build an FMI 2.0 (or 3.0) FMU of a model or of a driveline file "
                                        "(native: nothing needed where it runs)"),
    "sweep": ("clutchlab.cli.sweep", "grid or Monte Carlo sweep of a model, in resumable Parquet chunks (local cores "
                                     "or Dask)"),
    "report": ("clutchlab.cli.report", "write a self-contained HTML report (figures, metrics, parameters, "
                                       "provenance) of a results folder"),
    "convert": ("clutchlab.cli.io", "convert a measurement file (CSV, Parquet, MDF 4) to clutchlab names and SI "
                                    "units"),
}
#: modules that contribute a sub-command (``register(subparsers)``), in the order of ``clutchlab --help``
SUBSYSTEM_CLIS = tuple(dict.fromkeys(module for module, _ in COMMANDS.values()))
#: functions that contribute a section to ``clutchlab demo`` (``demo_section(workdir, progress)``)
DEMO_SECTIONS = ("clutchlab.demo.eclutch", "clutchlab.demo.wet", "clutchlab.demo.emtc", "clutchlab.demo.driveline",
                 "clutchlab.demo.control")
#: longest error line the CLI prints [characters]; longer messages lose their middle (file names stay whole
#: at the start, the reason at the end)
MESSAGE_LIMIT = 400


def _optional_module(name: str):
    """Import a subsystem module; ``None`` only if that module itself does not exist."""
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        if exc.name is not None and name.startswith(exc.name):
            return None
        raise


def _demo(args) -> int:
    from pathlib import Path

    from ..io.files import check_writable, remove_stale_temporaries
    from ..report import check_report_folder, write_report

    check_writable(args.output, args.force, what="folder")  # before minutes of simulation
    check_report_folder(args.output, args.force)             # (only a folder clutchlab wrote is replaced)
    remove_stale_temporaries(Path(args.output).resolve())    # what a killed demo left beside it

    sections = []
    t0 = time.perf_counter()
    progress("the first run compiles numba kernels (about a minute on a fresh machine; cached afterwards)")
    # the kernels of the later sections compile in background processes while the first section runs
    # (numba compiles one function at a time per process; clutchlab.warmup).  One process per section even
    # on two cores: the operating system shares the cores among the compilations, which balances them
    # better than any fixed split (measured on the 2-core machine, benchmarks/README.md)
    background = {}
    if (os.cpu_count() or 1) >= 2:
        from .. import warmup

        for name in DEMO_SECTIONS[1:]:
            short = name.rsplit(".", 1)[1]
            if short in warmup.GROUPS and _optional_module(name) is not None:
                background[short] = warmup.start([short])
    try:
        for name in DEMO_SECTIONS:
            mod = _optional_module(name)
            if mod is None:
                continue
            short = name.rsplit('.', 1)[1]
            if short in background:
                background.pop(short).wait()
            progress(f"running {short} demo ...")
            sections.append(mod.demo_section(progress=progress))
    finally:
        for proc in background.values():
            proc.kill()
            proc.wait()
    index = write_report(sections, args.output, title="clutchlab demo report (synthetic data)", overwrite=args.force)
    progress(f"done in {time.perf_counter() - t0:.1f} s")
    print(index)
    return 0


def _warmup(args) -> int:
    from .. import warmup

    unknown = [g for g in args.groups if g not in warmup.GROUPS]
    if unknown:
        raise ParameterError(f"warmup: unknown group {unknown[0]!r} (known: {', '.join(warmup.GROUPS)})")
    if args.jobs is not None and args.jobs < 1:
        raise ParameterError(f"warmup: --jobs = {args.jobs}: must be >= 1")
    warmup.run_parallel(args.groups or None, args.jobs, progress=progress)
    return 0


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """Return the argument parser.

    ``command``: None, every sub-command's whole parser (every subsystem imported); the name of a subsystem's
    command (:data:`COMMANDS`), that command's whole parser and one line for each other; ``""``, one line for
    each (what ``clutchlab --help`` shows, importing no model).
    """
    parser = argparse.ArgumentParser(
        prog="clutchlab",
        description="Model, simulate and identify automotive clutches (E-clutch, wet multi-plate, EMTC).",
        epilog="Documentation: README.md and docs/index.md (one page per subsystem). "
               "'clutchlab COMMAND --help' describes each command.",
    )
    parser.add_argument("--version", action="version", version=f"clutchlab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    demo = sub.add_parser("demo", help="run every subsystem's demo on bundled synthetic data and write an HTML report",
                          description="Run the E-clutch, wet-clutch, EMTC and driveline demos on the bundled synthetic "
                                      "data (characterisation, identification, simulation against the virtual rigs, "
                                      "driveline examples with stick/slip events) and write one self-contained "
                                      "HTML report with figures and tables.",
                          epilog="Documentation: docs/report.md")
    demo.add_argument("-o", "--output", default="clutchlab-demo", help="report folder to write (default: %(default)s)")
    demo.add_argument("--force", action="store_true", help="replace the report folder if it exists")
    demo.set_defaults(func=_demo)
    warm = sub.add_parser("warmup", help="compile every numba kernel ahead of use, in parallel processes",
                          description="Compile (or load from the cache) the numerical kernels of every model in "
                                      "parallel processes (groups that share functions in one, in order), rare "
                                      "paths included (the driveline's repair over several null directions, its "
                                      "invariant check), so that later runs start at once.",
                          epilog="Documentation: docs/architecture.md")
    warm.add_argument("groups", nargs="*", metavar="GROUP",
                      help="eclutch, wet, emtc, driveline, components, control (default: all)")
    warm.add_argument("-j", "--jobs", type=int, default=None, help="processes (default: the number of cores)")
    warm.set_defaults(func=_warmup)
    registered = set()
    for cmd, (name, summary) in COMMANDS.items():
        if command is not None and cmd != command:
            sub.add_parser(cmd, help=summary)   # its whole parser when it is the command given
        elif name not in registered:
            registered.add(name)
            mod = _optional_module(name)
            if mod is not None:
                mod.register(sub)
    return parser


#: library wording for "replace it" -> the command line's
_API_HINTS = (("pass overwrite=True (CLI: --force)", "use --force"), ("pass force=True (CLI: --force)", "use --force"),
              ("pass overwrite=True", "use --force"), ("overwrite=True", "--force"), ("force=True", "--force"))


def error_message(exc: BaseException) -> str:
    """The one line (at most ``MESSAGE_LIMIT`` characters) the command line prints for ``exc``.

    :class:`~clutchlab.errors.ClutchlabError` messages are printed as they
    are (they name file, field and value); operating-system errors name the
    path and the reason; the library's ``overwrite=True`` becomes ``--force``.
    """

    if isinstance(exc, FileExistsError) and hasattr(exc, "cli_message"):
        msg = exc.cli_message
    elif isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        reason = exc.strerror
        if exc.errno == errno.ENOSPC:
            reason = "no space left on the device"
        elif exc.errno == errno.EROFS:
            reason = "read-only file system"
        elif isinstance(exc, FileExistsError):
            reason = "exists; use --force to replace it"
        msg = f"{exc.filename}: {reason}"
    elif isinstance(exc, UnicodeDecodeError):
        msg = f"input is not UTF-8 text (byte {exc.object[exc.start:exc.start + 1]!r} at offset {exc.start})"
    elif isinstance(exc, RecursionError):
        msg = "input nested too deeply to read"
    elif isinstance(exc, MemoryError):
        msg = ("out of memory: the requested size is too large for this machine "
               "(reduce the number of points, the duration or the rate)")
    else:
        msg = str(exc) or type(exc).__name__
    for api, cli in _API_HINTS:
        msg = msg.replace(api, cli)
    return one_line(msg, MESSAGE_LIMIT)


def main(argv=None) -> int:
    """Entry point of the ``clutchlab`` command."""
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    # the command is the first word that is not an option (the top level takes no option with a value)
    command = next((a for a in argv if not a.startswith("-")), "")
    parser = build_parser(command if command in COMMANDS else "")
    args = parser.parse_args(argv)
    if not hasattr(args, "func"):
        parser.print_help()
        return 2
    shown = warnings.showwarning
    # a warning of clutchlab's is one line, as its errors are (not Python's file:line and source line)
    warnings.showwarning = lambda message, category, *rest, **kw: print(
        f"clutchlab: warning: {one_line(str(message), MESSAGE_LIMIT)}", file=sys.stderr)
    try:
        return int(args.func(args) or 0)
    except (ClutchlabError, OSError, UnicodeDecodeError, RecursionError, MemoryError) as exc:
        # OSError: read-only or full disk, a parent that is a file, a refused overwrite (FileExistsError)
        print(f"clutchlab: error: {error_message(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("clutchlab: interrupted", file=sys.stderr)
        return 130
    finally:
        warnings.showwarning = shown


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
