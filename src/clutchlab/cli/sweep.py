"""``clutchlab sweep SPEC.toml -o results/``: a thin layer over :func:`clutchlab.sweep.run_sweep`.

Options: ``--workers N`` (worker processes), ``--scheduler tcp://HOST:PORT``
(a Dask cluster), ``--force`` (start over in a folder holding another sweep),
``--no-progress``, ``--no-plot``; ``--list-parameters`` prints what the spec's
model can sweep and report.
"""

from __future__ import annotations

import sys

__all__ = ["register"]


def _log(message: str) -> None:
    print(f"clutchlab sweep: {message}", file=sys.stderr, flush=True)


def _sweep(args) -> int:
    from ..sweep.runner import run_sweep
    from ..sweep.spec import check_scheduler, load_spec

    check_scheduler(args.scheduler)
    spec = load_spec(args.spec)
    if args.list_parameters:
        info = spec.target.describe(spec.scenario)
        print(f"model {spec.model!r} ({spec.target.origin})")
        for title, table in (("parameters", info.parameters), ("outputs", info.outputs)):
            print(f"{title}:")
            for name, unit in (table or {}).items():
                print(f"  {name:<40} [{unit}]")
        return 0
    if args.output is None:
        raise FileNotFoundError("no results folder given: use -o/--output DIR")
    # run_sweep logs the start line itself, after every check that can refuse the sweep: a refusal is one line
    result = run_sweep(spec, args.output, workers=args.workers, scheduler=args.scheduler, force=args.force,
                       progress=not args.no_progress, plot=not args.no_plot, log=_log)
    _log(f"done: {len(result.computed)} chunks computed, {len(result.reused)} reused")
    print(result.output / "results.parquet")
    return 0


def register(subparsers) -> None:
    """Add the ``sweep`` command."""
    p = subparsers.add_parser(
        "sweep", help="grid or Monte Carlo sweep of a model, in resumable Parquet chunks (local cores or Dask)",
        description="Run the variants of SPEC.toml (a grid or a Monte Carlo sample of a model's parameters) "
                    "as compiled batches in Parquet chunks, on local cores or a Dask cluster; an interrupted "
                    "sweep resumes where it stopped.",
        epilog="Documentation: docs/sweeps.md (spec format)")
    p.add_argument("spec", help="sweep spec TOML ([sweep] model/outputs/chunk_size, [grid] or [monte_carlo])")
    p.add_argument("-o", "--output", help="results folder (manifest.json, chunks/, results.parquet, summary.csv/png)")
    p.add_argument("--workers", type=int, default=None,
                   help="run chunks in N worker processes (default: this process, each chunk a compiled batch)")
    p.add_argument("--scheduler", default=None, help="Dask scheduler address, e.g. tcp://127.0.0.1:8786")
    p.add_argument("--force", action="store_true", help="start over in a folder that holds another sweep")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--no-plot", action="store_true", help="do not write summary.png")
    p.add_argument("--list-parameters", action="store_true", help="print the model's sweepable parameters and outputs")
    p.set_defaults(func=_sweep)
