"""Exception hierarchy of clutchlab.

Every error a user can provoke with bad input is a :class:`ClutchlabError`;
the command-line tool turns it into one line and a non-zero exit code.
"""

from __future__ import annotations

__all__ = [
    "ClutchlabError",
    "ParameterError",
    "DataError",
    "SimulationError",
    "IdentificationError",
]


class ClutchlabError(Exception):
    """Base class of all errors raised for bad input or failed computations."""


class ParameterError(ClutchlabError, ValueError):
    """A parameter is missing, of the wrong type or unit, or physically inconsistent."""


class DataError(ClutchlabError, ValueError):
    """A measurement record is malformed (missing column, NaN, non-monotonic time, ...)."""


class SimulationError(ClutchlabError, RuntimeError):
    """A simulation or equilibrium solve failed to converge."""


class IdentificationError(ClutchlabError, RuntimeError):
    """An identification (fit, characterization) could not be carried out."""
