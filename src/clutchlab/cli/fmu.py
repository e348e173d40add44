"""``clutchlab export-fmu MODEL [FILE] -o NAME.fmu``: thin layer over :func:`clutchlab.fmu.native.export_native_fmu`
and :func:`clutchlab.fmu.export.export_fmu`.

Every model is exported as a **native** FMU by default (``--backend native``: compiled code, nothing of
Python on the importing machine); ``--backend python`` wraps the model with pythonfmu (the importing machine
then needs Python and clutchlab).

``clutchlab export-fmu {eclutch,wet,emtc} -o NAME.fmu`` exports a model with its bundled parameters;
``clutchlab export-fmu driveline FILE.toml -o NAME.fmu`` the driveline that ``FILE.toml`` describes (with
``--backend python`` the FMU carries the file and every file it names,
:func:`clutchlab.fmu.export.bundle_description`).
"""

from __future__ import annotations

__all__ = ["register"]

import sys
import warnings
from pathlib import Path

from ..errors import ParameterError
from ..fmu.registry import COSIMULATIONS

#: what ``--backend python`` costs, said at every such export (docs/fmu.md, "Hosts: exit, re-instantiation")
PYTHON_BACKEND_WARNING = ("a pythonfmu FMU needs Python and clutchlab where it runs, and its host process may "
                          "abort at exit after correct results (a latent heap corruption in that layer, "
                          "docs/fmu.md); the default native FMU has neither limit")


def _export(args) -> int:
    from ..fmu.cosim import load_cosimulation
    from ..fmu.export import export_fmu

    from ..io.files import check_writable

    cls = load_cosimulation(args.model)
    if cls.description_file and args.file is None:
        raise ParameterError(f"export-fmu {args.model} needs a description file, {cls.description_file}: "
                             f"clutchlab export-fmu {args.model} FILE.toml")
    if args.file is not None and not cls.description_file:
        raise ParameterError(f"export-fmu {args.model} takes no description file (got {args.file!r}); "
                             f"only {', '.join(m for m in COSIMULATIONS if load_cosimulation(m).description_file)}"
                             " does")
    default = Path(args.file).stem if args.file is not None else args.model
    output = args.output if args.output is not None else Path(f"{default}.fmu")
    check_writable(output, args.force)  # before the build
    native = cls.native
    backend = args.backend or ("native" if native else "python")
    if backend == "native":
        if not native:
            raise ParameterError(f"export-fmu {args.model}: no native FMU for this model (its co-simulation "
                                 "is not on the system contract); use --backend python")
        from ..fmu.native import export_native_fmu

        if args.file is not None:
            cls = cls.for_description(args.file)
        path = export_native_fmu(cls, output, overwrite=args.force, platforms=args.platform,
                                 fmi_version=args.fmi_version,
                                 report=lambda text: print(f"clutchlab: {text}", file=sys.stderr))
        print(path)
        return 0
    if args.fmi_version != "2.0":
        raise ParameterError(f"export-fmu --backend python: FMI {args.fmi_version} is built by the native backend "
                             "only (pythonfmu writes FMI 2.0)")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UserWarning)
        packed = []
        path = export_fmu(args.model, output, overwrite=args.force, description=args.file, packed=packed)
    for w in caught:  # e.g. no C compiler for the fmi2Error shim: one line each
        print(f"clutchlab: warning: {w.message}", file=sys.stderr)
    print(f"clutchlab: warning: {PYTHON_BACKEND_WARNING}", file=sys.stderr)
    for source, name in packed:   # what of the user's files went into the FMU (#33)
        print(f"{path.name}: packed {source} as {name}")
    print(path)
    return 0


def register(subparsers) -> None:
    """Add the ``export-fmu`` sub-command."""
    p = subparsers.add_parser(
        "export-fmu",
        help="build an FMI 2.0 (or 3.0) FMU of a model or of a driveline file (native: nothing needed where "
             "it runs)",
        description="Build an FMI 2.0 co-simulation and model-exchange FMU (--fmi-version 3.0: an FMI 3.0 "
                    "co-simulation FMU) exposing the model's inputs, outputs and parameters (with "
                    "units). Every model becomes a native FMU by default: the model's compiled code "
                    "with an FMI layer, for linux64 (and win64 where the MinGW-w64 cross compiler is installed); "
                    "the importing tool needs nothing, the exporting machine a C and C++ compiler. "
                    "'--backend python' runs the model through pythonfmu: the "
                    "importing tool then needs a Python with clutchlab installed, and a driveline's FMU carries "
                    "its description file with a copy of every file it names. A driveline is exported from its "
                    "description file: 'export-fmu driveline FILE.toml'.",
        epilog="Documentation: docs/fmu.md (drivelines: docs/driveline.md)")
    p.add_argument("model", choices=sorted(COSIMULATIONS), help="model to export")
    p.add_argument("file", nargs="?", default=None,
                   help="description file of a model built from one (driveline: its TOML); the others take none")
    p.add_argument("-o", "--output", type=Path, default=None,
                   help="FMU file to write (default: MODEL.fmu, for a driveline FILE's name with .fmu)")
    p.add_argument("--force", action="store_true", help="replace the FMU if it exists")
    p.add_argument("--backend", choices=("native", "python"), default=None,
                   help="native (default): compiled, no Python where the FMU runs; python: through pythonfmu (the "
                        "importing machine needs Python and clutchlab)")
    p.add_argument("--platform", action="append", choices=("linux64", "win64"), default=None,
                   help="platform of a native FMU's binary (repeat for several; default: linux64, and win64 "
                        "where its cross compiler is installed)")
    p.add_argument("--fmi-version", choices=("2.0", "3.0"), default="2.0",
                   help="2.0 (default): co-simulation and model exchange; 3.0: co-simulation (native backend)")
    p.set_defaults(func=_export)
