"""What every ``clutchlab`` sub-command shares: the ``--fixed-step`` option and the progress line."""

from __future__ import annotations

__all__ = ["add_fixed_step_option", "fixed_step_option", "fixed_step_note", "progress", "add_run_options", "run_options", "run_note"]

import math
import re
import sys
import time

from ..errors import ParameterError


#: help of ``--fixed-step`` on the simulate commands
FIXED_STEP_HELP = ("run in the fixed-step (real-time, HIL frame) mode with steps of this length, e.g. '1 ms': "
                   "Rodas3 on the grid k * STEP, mode changes at step ends (default: step-size control)")


def add_fixed_step_option(parser) -> None:
    """Add ``--fixed-step STEP`` (a time with its unit) to a simulate command's ``parser``.

    A value that starts with a minus sign and a digit (``--fixed-step -1ms``) is taken as the option's value,
    to be refused by :func:`fixed_step_option` in one line, not as an unknown option.
    """
    parser.add_argument("--fixed-step", metavar="STEP", help=FIXED_STEP_HELP)
    parser._negative_number_matcher = re.compile(r"^-\.?\d")  # (argparse: "-1ms" is not an option)


def fixed_step_option(text):
    """The step [s] of ``--fixed-step TEXT`` (a time with its unit, ``"1 ms"``); None without the option.

    Raises
    ------
    ParameterError
        Not a time with its unit, not finite, or not > 0 -- naming the option and the value.
    """
    return None if text is None else _time("--fixed-step", text)


def fixed_step_note(step: float) -> str:
    """The header line of a file written by a fixed-step run of ``step`` [s]."""
    return f"solver: fixed-step (real-time) mode, step {step:.6g} s (Rodas3 on the grid k * step)"


def progress(message: str) -> None:
    """Print a progress line to stderr (long runs say what they are doing)."""
    print(f"[clutchlab {time.strftime('%H:%M:%S')}] {message}", file=sys.stderr, flush=True)


#: the run options of every ``simulate`` command: the API's one option set (:data:`clutchlab.system.RUN_OPTIONS`)
RUN_OPTION_HELP = {
    "rtol": "relative tolerance of the step-size control, e.g. 1e-6 (default: the model's or the file's)",
    "atol": "absolute tolerance of every state, in its SI unit, e.g. 1e-9 (default: the model's, per state)",
    "max_step": "largest step, a time with its unit, e.g. '1 ms' (default: the model's)",
    "output_step": "sample interval of the written results, e.g. '1 ms' (default: the model's or the file's)",
}


def add_run_options(parser) -> None:
    """Add ``--rtol``, ``--atol``, ``--max-step``, ``--output-step`` and ``--fixed-step`` to a simulate command's
    ``parser`` (read by :func:`run_options`)."""
    parser.add_argument("--rtol", metavar="RTOL", help=RUN_OPTION_HELP["rtol"])
    parser.add_argument("--atol", metavar="ATOL", help=RUN_OPTION_HELP["atol"])
    parser.add_argument("--max-step", metavar="STEP", help=RUN_OPTION_HELP["max_step"])
    parser.add_argument("--output-step", metavar="STEP", help=RUN_OPTION_HELP["output_step"])
    add_fixed_step_option(parser)


def _number(option: str, text) -> float:
    from ..units import to_si

    value = to_si(text, "1", name=option)
    if not math.isfinite(value):
        raise ParameterError(f"{option} = {text!r}: must be a finite number")
    return value


def _time(option: str, text) -> float:
    from ..units import to_si

    value = to_si(text, "s", name=option)
    if not (math.isfinite(value) and value > 0):
        raise ParameterError(f"{option} = {text!r}: must be a time > 0 with its unit, e.g. '1 ms'")
    return value


def run_options(args) -> dict:
    """The run options a simulate command was given, in SI: ``{"rtol": ..., "atol": ..., "max_step": ...,
    "output_step": ..., "fixed_step": ...}`` with None for each one not given (the model's or the file's default).

    Raises
    ------
    ParameterError
        A value that is not a number (a time with its unit for the steps), naming the option; a tolerance out of
        its range (:func:`clutchlab.system.check_rtol`, :func:`~clutchlab.system.check_atol`).
    """
    from ..system import check_atol, check_rtol

    out = {"rtol": None, "atol": None, "max_step": None, "output_step": None,
           "fixed_step": fixed_step_option(getattr(args, "fixed_step", None))}
    if getattr(args, "rtol", None) is not None:
        out["rtol"] = check_rtol(_number("--rtol", args.rtol), "--rtol")
    if getattr(args, "atol", None) is not None:
        out["atol"] = float(check_atol(_number("--atol", args.atol), (), "--atol"))
    if getattr(args, "max_step", None) is not None:
        out["max_step"] = _time("--max-step", args.max_step)
    if getattr(args, "output_step", None) is not None:
        out["output_step"] = _time("--output-step", args.output_step)
    return out


def run_note(options: dict) -> str | None:
    """The header lines of a file written with solver options given on the command line (``rtol``, ``atol``,
    ``max_step``, ``fixed_step``; the samples show the ``output_step``), or None for none."""
    given = [f"{k} = {v:g}" + ("" if k in ("rtol", "atol") else " s") for k, v in options.items()
             if v is not None and k in ("rtol", "atol", "max_step")]
    notes = ([f"solver options: {', '.join(given)}"] if given else []) + \
        ([fixed_step_note(options["fixed_step"])] if options.get("fixed_step") is not None else [])
    return "\n".join(notes) or None
