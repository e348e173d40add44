"""Unit conversions: the one place where non-SI units enter or leave clutchlab.

Inside the package every quantity is SI (m, N, N·m, rad/s, Pa, Pa·s, kg, s);
temperatures are carried in °C where the name says so (``temperature_c``) and in
K otherwise.  Parameter files may carry units as strings (``"83.15 mm"``,
``"300 kPa"``); :func:`to_si` converts them once, at the edge, with :mod:`pint`.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache
from numbers import Real

import numpy as np

from ._limits import short_repr
from .errors import ParameterError

__all__ = [
    "rpm_to_rad_s",
    "rad_s_to_rpm",
    "celsius_to_kelvin",
    "kelvin_to_celsius",
    "bar_to_pa",
    "pa_to_bar",
    "to_si",
    "format_quantity",
]

_RPM = 2.0 * math.pi / 60.0
_NUMBER_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?nan|[-+]?inf)\s*(.*?)\s*$", re.I)


def rpm_to_rad_s(speed_rpm):
    """Convert a rotational speed from rev/min to rad/s.

    Parameters
    ----------
    speed_rpm : float or array_like
        Value(s) in rev/min.

    Returns
    -------
    float or ndarray
        Value(s) in rad/s.
    """
    return np.asarray(speed_rpm, dtype=float) * _RPM if np.ndim(speed_rpm) else float(speed_rpm) * _RPM


def rad_s_to_rpm(speed_rad_s):
    """Convert a rotational speed from rad/s to rev/min.

    Parameters
    ----------
    speed_rad_s : float or array_like
        Value(s) in rad/s.

    Returns
    -------
    float or ndarray
        Value(s) in rev/min.
    """
    return np.asarray(speed_rad_s, dtype=float) / _RPM if np.ndim(speed_rad_s) else float(speed_rad_s) / _RPM


def celsius_to_kelvin(temperature_c):
    """Convert a temperature from °C to K.

    Parameters
    ----------
    temperature_c : float or array_like
        Value(s) in °C.

    Returns
    -------
    float or ndarray
        Value(s) in K.
    """
    return np.asarray(temperature_c, dtype=float) + 273.15 if np.ndim(temperature_c) else float(temperature_c) + 273.15


def kelvin_to_celsius(temperature_k):
    """Convert a temperature from K to °C.

    Parameters
    ----------
    temperature_k : float or array_like
        Value(s) in K.

    Returns
    -------
    float or ndarray
        Value(s) in °C.
    """
    return np.asarray(temperature_k, dtype=float) - 273.15 if np.ndim(temperature_k) else float(temperature_k) - 273.15


def bar_to_pa(pressure_bar):
    """Convert a pressure from bar to Pa.

    Parameters
    ----------
    pressure_bar : float or array_like
        Value(s) in bar.

    Returns
    -------
    float or ndarray
        Value(s) in Pa.
    """
    return np.asarray(pressure_bar, dtype=float) * 1e5 if np.ndim(pressure_bar) else float(pressure_bar) * 1e5


def pa_to_bar(pressure_pa):
    """Convert a pressure from Pa to bar.

    Parameters
    ----------
    pressure_pa : float or array_like
        Value(s) in Pa.

    Returns
    -------
    float or ndarray
        Value(s) in bar.
    """
    return np.asarray(pressure_pa, dtype=float) / 1e5 if np.ndim(pressure_pa) else float(pressure_pa) / 1e5


@lru_cache(maxsize=1)
def _registry():
    import pint  # imported lazily: only parameter files need it

    return pint.UnitRegistry()


def to_si(value, unit: str, *, name: str = "value", source: str | None = None) -> float:
    """Convert a parameter value to the SI unit ``unit``.

    Parameters
    ----------
    value : float or str
        A plain number (taken to be already in ``unit``) or a string with a
        unit such as ``"83.15 mm"``, ``"300 kPa"`` or ``"40 degC"``.
    unit : str
        Target unit understood by pint (``"m"``, ``"N"``, ``"Pa*s"``, ``"degC"``,
        ``"1"`` for dimensionless).
    name : str
        Name of the parameter, used in error messages.
    source : str, optional
        File the value came from, used in error messages.

    Returns
    -------
    float
        The value in ``unit``.

    Raises
    ------
    ParameterError
        If the string cannot be parsed, the unit is unknown or has the wrong
        dimension, or the value is not finite.
    """
    where = f"{source}: " if source else ""
    if isinstance(value, bool):
        raise ParameterError(f"{where}{name} = {short_repr(value)}: expected a number or a quantity string")
    if isinstance(value, Real):
        out = float(value)
    elif isinstance(value, str):
        ureg = _registry()
        import pint

        m = _NUMBER_UNIT.match(value)
        try:
            if m is None:
                raise ValueError("expected '<number> <unit>'")
            q = ureg.Quantity(float(m.group(1)), m.group(2).strip() or "dimensionless")
        except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError, ValueError, TypeError, AttributeError) as exc:
            raise ParameterError(f"{where}{name} = {short_repr(value)}: cannot parse quantity ({exc})") from None
        except Exception as exc:  # pint raises assorted tokenizer errors
            raise ParameterError(f"{where}{name} = {short_repr(value)}: cannot parse quantity ({exc})") from None
        try:
            out = float(q.to(unit).magnitude)
        except pint.errors.DimensionalityError:
            raise ParameterError(
                f"{where}{name} = {short_repr(value)}: wrong unit, expected a quantity convertible to {unit!r}"
            ) from None
    else:
        raise ParameterError(f"{where}{name} = {short_repr(value)}: expected a number or a quantity string")
    if not math.isfinite(out):
        raise ParameterError(f"{where}{name} = {short_repr(value)}: not a finite number")
    return out


def format_quantity(value: float, unit: str) -> str:
    """Format an SI value with its unit for a parameter file (``"0.08315 m"``)."""
    if unit in ("", "1"):
        return repr(float(value))
    return f"{float(value)!r} {unit}"
