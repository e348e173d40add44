"""One status enumeration for every run of the integrator core, with its messages."""

from __future__ import annotations

import enum

from .layout import indices

__all__ = ["Status", "SUCCESS", "STEP_LIMIT", "STEP_UNDERFLOW", "TERMINATED", "RECORD_FULL", "SINGULAR",
           "MODEL_ERROR", "message"]

#: the statuses in the order of their codes (the C layer of a native FMU reads them from here too)
STATUSES = ("success", "step_limit", "step_underflow", "terminated", "record_full", "singular", "model_error")
# plain ints for the compiled core (numba reads module-level ints as constants)
SUCCESS, STEP_LIMIT, STEP_UNDERFLOW, TERMINATED, RECORD_FULL, SINGULAR, MODEL_ERROR = indices(
    STATUSES, "success", "step_limit", "step_underflow", "terminated", "record_full", "singular", "model_error")


class Status(enum.IntEnum):
    """How a run of the integrator core ended (``SimulationResult.status``)."""

    SUCCESS = SUCCESS
    STEP_LIMIT = STEP_LIMIT
    STEP_UNDERFLOW = STEP_UNDERFLOW
    TERMINATED = TERMINATED
    RECORD_FULL = RECORD_FULL
    SINGULAR = SINGULAR
    MODEL_ERROR = MODEL_ERROR

    @property
    def ok(self) -> bool:
        """True for a run that reached its end time or a terminal event."""
        return self in (Status.SUCCESS, Status.TERMINATED)

    @property
    def message(self) -> str:
        return _MESSAGES[self]


_MESSAGES = {
    Status.SUCCESS: "the end time was reached",
    Status.STEP_LIMIT: "the step limit (max_steps) was reached before the end time",
    Status.STEP_UNDERFLOW: "the step size fell below the resolution of the time (stiff or discontinuous input?)",
    Status.TERMINATED: "a terminal event stopped the run",
    Status.RECORD_FULL: "the record buffer is full (internal: the caller resumes with a new buffer)",
    Status.SINGULAR: "the iteration matrix was singular or the state became non-finite at the smallest step",
    Status.MODEL_ERROR: "the model reported an error (see the model's message)",
}


def message(status: int) -> str:
    """Message of a status code (unknown codes are named as such)."""
    try:
        return Status(int(status)).message
    except ValueError:
        return f"unknown status {status}"
