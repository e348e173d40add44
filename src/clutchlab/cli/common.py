"""What every ``clutchlab`` sub-command shares: the ``--fixed-step`` option and the progress line."""

from __future__ import annotations

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
    if text is None:
        return None
    from ..units import to_si

    step = to_si(text, "s", name="--fixed-step")
    if not step > 0:
        raise ParameterError(f"--fixed-step = {text!r}: must be a time > 0 with its unit, e.g. '1 ms'")
    return step


def fixed_step_note(step: float) -> str:
    """The header line of a file written by a fixed-step run of ``step`` [s]."""
    return f"solver: fixed-step (real-time) mode, step {step:.6g} s (Rodas3 on the grid k * step)"


def progress(message: str) -> None:
    """Print a progress line to stderr (long runs say what they are doing)."""
    print(f"[clutchlab {time.strftime('%H:%M:%S')}] {message}", file=sys.stderr, flush=True)
