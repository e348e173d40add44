"""What a session call may be asked for, and the kinds of values it reports: declarations shared by the compiled
session (:mod:`clutchlab.numerics.session`) and the Python :class:`clutchlab.system.Simulation` that drives it.

A module of its own so that :mod:`clutchlab.system` reads them without importing the session's numba
extensions at its own import (a warm command line pays for every import).
"""

from __future__ import annotations

from .layout import bits, indices

__all__ = ["REQUESTS", "ADVANCE", "OUTPUTS", "START", "REPORT_KINDS", "REPORT_OUTPUT", "REPORT_STATE", "REPORT_MODE",
           "REPORT_MODE_IS"]

#: bits of ``what`` in a session call: advance to the end time; evaluate the outputs and fill the report; first
#: decide what the run derives from its initial state (the model's ``start``: a native FMU after a host set start
#: values, before the run's first advance, which would do it too)
REQUESTS = ("advance", "outputs", "start")
ADVANCE, OUTPUTS, START = bits(REQUESTS, "advance", "outputs", "start")

#: kinds of reported values (``report[k, 0]``; ``report[k, 1]`` is the index, ``report[k, 2]`` the value compared)
REPORT_KINDS = ("output", "state", "mode", "mode_is")
REPORT_OUTPUT, REPORT_STATE, REPORT_MODE, REPORT_MODE_IS = indices(REPORT_KINDS, "output", "state", "mode", "mode_is")
