"""``clutchlab params``: show and check parameter files.

``clutchlab params show {eclutch,wet,emtc} [--paper] [--toml] [-o FILE] [--force]``
    print every parameter set of a model (name, value, unit, source,
    description), or a self-documenting TOML file that loads back identically;
``clutchlab params check FILE.toml [--model M]``
    validate a model parameter file; errors name the file, ``[table] key``
    and the value at fault.
"""

from __future__ import annotations

import sys

__all__ = ["register"]


def register(subparsers) -> None:
    """Add the ``params`` command and its sub-commands."""
    from ..params.registry import MODELS

    par = subparsers.add_parser("params", help="show the parameter sets of a model, write or check parameter files",
                                description="Show every parameter set of a model with values, units and sources, "
                                            "write it as a self-documenting TOML file, or check a parameter file.",
                                epilog="Documentation: docs/parameters.md")
    sub = par.add_subparsers(dest="params_command", metavar="SUBCOMMAND")
    show = sub.add_parser("show", help="print a model's parameters with units and sources (or as TOML)",
                          description="Print a model's parameter sets (the defaults, or the paper's values with "
                                      "--paper): name, value, SI unit, source and description; or a TOML file "
                                      "that loads back identically.",
                          epilog="Documentation: docs/parameters.md")
    show.add_argument("model", choices=list(MODELS), help="model whose parameter sets to show")
    show.add_argument("--paper", action="store_true", help="the paper's values (paper() presets) with their sources")
    show.add_argument("--toml", action="store_true", help="print a self-documenting TOML file instead of a table")
    show.add_argument("-o", "--output", help="write the TOML file here instead of printing it (implies --toml)")
    show.add_argument("--force", action="store_true", help="overwrite the output")
    show.set_defaults(func=_show)
    check = sub.add_parser("check", help="validate a parameter file (units, types, ranges, consistency)",
                           description="Validate a TOML parameter file: known tables and keys, units, types, "
                                       "signs and ranges; errors name the file, the key and the value.",
                           epilog="Documentation: docs/parameters.md")
    check.add_argument("file", help="TOML parameter file (one table per parameter set)")
    check.add_argument("--model", choices=list(MODELS), help="model the file belongs to (default: from the file)")
    check.set_defaults(func=_check)
    par.set_defaults(func=lambda args: (par.print_help(), 2)[1])


def _show(args) -> int:
    from ..io import atomic_write_text
    from ..params.registry import model_toml, show_table

    if args.output:
        atomic_write_text(args.output, model_toml(args.model, paper=args.paper), overwrite=args.force)
        print(args.output)
    elif args.toml:
        sys.stdout.write(model_toml(args.model, paper=args.paper))
    else:
        sys.stdout.write(show_table(args.model, paper=args.paper))
    return 0


def _check(args) -> int:
    from ..params.registry import load_model_file

    model, sets = load_model_file(args.file, args.model)
    counts = ", ".join(f"[{t}] {len(s.field_info())} fields" for t, s in sets.items())
    print(f"{args.file}: valid {model} parameters ({counts or 'no tables: all defaults'})")
    return 0
