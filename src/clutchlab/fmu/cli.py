"""``clutchlab export-fmu {eclutch,wet,emtc} -o NAME.fmu``: thin layer over :func:`clutchlab.fmu.export.export_fmu`."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

from . import COSIMULATIONS


def _export(args) -> int:
    from .export import export_fmu

    from ..io.files import check_writable

    output = args.output if args.output is not None else Path(f"{args.model}.fmu")
    check_writable(output, args.force)  # before the build
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UserWarning)
        path = export_fmu(args.model, output, overwrite=args.force)
    for w in caught:  # e.g. no C compiler for the fmi2Error shim: one line each
        print(f"clutchlab: warning: {w.message}", file=sys.stderr)
    print(path)
    return 0


def register(subparsers) -> None:
    """Add the ``export-fmu`` sub-command."""
    p = subparsers.add_parser(
        "export-fmu",
        help="build an FMI 2.0 co-simulation FMU of a model (needs pythonfmu; runs with clutchlab installed)",
        description="Build an FMI 2.0 co-simulation FMU exposing the model's inputs, outputs and parameters (with "
                    "units). The FMU runs the model through pythonfmu: the importing tool needs a Python with "
                    "clutchlab installed.",
        epilog="Documentation: docs/fmu.md")
    p.add_argument("model", choices=sorted(COSIMULATIONS), help="model to export")
    p.add_argument("-o", "--output", type=Path, default=None, help="FMU file to write (default: MODEL.fmu)")
    p.add_argument("--force", action="store_true", help="replace the FMU if it exists")
    p.set_defaults(func=_export)
