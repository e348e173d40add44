"""Checks of the controllers' parameters, shared by the transmission controllers (:mod:`.tcu`, :mod:`.dct`); not part
of the public API."""

from __future__ import annotations

import math

from ..errors import ParameterError

__all__ = ["positive"]


def positive(name, value, zero=False, who="AmtController"):
    """``value`` as a float, finite and > 0 (``zero``: >= 0), or a :class:`~clutchlab.errors.ParameterError` naming
    the controller ``who``, the parameter ``name`` and the value given."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{who}: {name} = {value!r} must be a number") from None
    if not (math.isfinite(v) and (v >= 0.0 if zero else v > 0.0)):
        raise ParameterError(f"{who}: {name} = {value!r} must be finite and {'>=' if zero else '>'} 0")
    return v
