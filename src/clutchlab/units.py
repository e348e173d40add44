"""Unit conversions: the one place where non-SI units enter or leave clutchlab.

Inside the package every quantity is SI (m, N, N·m, rad/s, Pa, Pa·s, kg, s);
temperatures are carried in °C where the name says so (``temperature_c``) and in
K otherwise.  Parameter files may carry units as strings (``"83.15 mm"``,
``"300 kPa"``); :func:`to_si` converts them once, at the edge, with :mod:`pint`.

pint builds its registry of units in about 0.3 s and imports in about as long: more than a warm
``clutchlab driveline simulate`` spends simulating.  So the factor of every multiplicative conversion
pint made (a unit as written and the SI unit it was converted to, ``"mm" -> "m": 0.001``) is kept in a
small JSON file of clutchlab's cache (:func:`clutchlab._cache.cache_folder`, one file per pint version),
and a later process converts the same unit without importing pint.  pint converts a magnitude as
``value * factor`` (``PlainRegistry._convert``), so the kept factor gives the same number to the last
bit; a unit with an offset (``degF``), a number inside the unit (``"N/(10 mm)"``) or a conversion that
fails goes to pint every time, and pint writes every error message.
"""

from __future__ import annotations

import json
import math
import os
import re
import threading
from functools import lru_cache
from numbers import Real

import numpy as np

from ._limits import short_repr
from .errors import ParameterError

__all__ = [
    "ENGINEERS_UNITS",
    "engineers_unit",
    "affine_conversion",
    "rpm_to_rad_s",
    "rad_s_to_rpm",
    "celsius_to_kelvin",
    "kelvin_to_celsius",
    "bar_to_pa",
    "pa_to_bar",
    "to_si",
    "format_quantity",
    "UNIT_ALIASES",
    "normalise_unit",
    "COLUMN_UNITS",
    "column_unit",
    "unit_label",
    "column_label",
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


#: logger spellings of units, translated before pint parses them (after whitespace and Unicode are
#: normalised by :func:`normalise_unit`); pint alone would read ``Nm`` as nanometre, ``U/min`` as
#: enzyme units per minute, ``1/min`` as 1/60 Hz (not 2 pi/60 rad/s) and ``mNm`` as "millinumber metre"
UNIT_ALIASES = {
    # torque
    "Nm": "N*m", "N.m": "N*m", "N m": "N*m", "N-m": "N*m", "NM": "N*m", "Nmm": "N*mm",
    "kNm": "kN*m", "mNm": "mN*m", "kN.m": "kN*m", "kN m": "kN*m",
    # temperature
    "°C": "degC", "° C": "degC", "deg C": "degC", "Grad C": "degC", "°F": "degF", "° F": "degF",
    "deg F": "degF", "°K": "K", "°": "deg",
    # rotational speed: revolutions per minute, never enzyme units (U) or cycles per minute (1/min)
    "rpm": "rpm", "U/min": "rpm", "UpM": "rpm", "Upm": "rpm", "1/min": "rpm", "min-1": "rpm", "min^-1": "rpm",
    "min**-1": "rpm", "r/min": "rpm", "rev/min": "rpm", "revs/min": "rpm", "tr/min": "rpm", "r/mn": "rpm",
    "U/s": "rps", "1/s": "1/s", "r/s": "rps", "rev/s": "rps", "rps": "rps",
    # speed, pressure
    "kmh": "km/h", "kph": "km/h", "barg": "bar", "bar(g)": "bar", "mbarg": "mbar",
    # dimensionless
    "-": "", "[-]": "", "--": "", "1": "", "none": "", "%": "percent", "‰": "permille",
}
# spellings looked up without regard to case (RPM, Rpm, u/min, NM, DEGC ...)
_CASELESS = {k.lower(): v for k, v in UNIT_ALIASES.items()
             if v in ("rpm", "rps", "degC", "degF", "km/h")} | {"degc": "degC", "degf": "degF"}
_UNICODE = {"µ": "u", "μ": "u", "²": "**2", "³": "**3", "⁻¹": "**-1", "·": "*", "⋅": "*", "×": "*",
            "Ω": "ohm", "℃": "degC", "℉": "degF", "\u00a0": " "}
_SPACES_AROUND_OPERATORS = re.compile(r"\s*([/*^])\s*")


def normalise_unit(unit: str | None) -> str:
    """Translate a unit as data loggers spell it into pint syntax.

    Whitespace is collapsed (``"U/  min"`` -> ``"U/min"``), surrounding square
    brackets are dropped (``"[Nm]"``), Unicode signs are spelled out
    (``µ``, ``²``, ``·``, ``℃``), and the logger spellings of
    :data:`UNIT_ALIASES` are translated (``Nm`` -> ``N*m``, ``U/min`` and
    ``1/min`` -> ``rpm``, ``°C`` -> ``degC``, ``-`` -> dimensionless).  Unknown
    spellings are returned (normalised) for pint to judge.

    Parameters
    ----------
    unit : str or None
        Unit string as stored in a file or written in a channel map.

    Returns
    -------
    str
        Unit string for pint; ``""`` means dimensionless (or no unit).
    """
    if unit is None:
        return ""
    text = str(unit)
    for sign, spelled in _UNICODE.items():
        text = text.replace(sign, spelled)
    text = " ".join(text.split())
    if len(text) >= 2 and text[0] == "[" and text[-1] == "]":
        text = " ".join(text[1:-1].split())
    if text in UNIT_ALIASES:
        return UNIT_ALIASES[text]
    compact = _SPACES_AROUND_OPERATORS.sub(r"\1", text)
    for candidate in (compact, compact.replace(" ", "")):
        if candidate in UNIT_ALIASES:
            return UNIT_ALIASES[candidate]
        if candidate.lower() in _CASELESS:
            return _CASELESS[candidate.lower()]
    return compact


@lru_cache(maxsize=1)
def _registry():
    import pint  # imported lazily: only parameter files need it

    return pint.UnitRegistry()


def _radians(q) -> int:
    """The power of the angle in the pint quantity ``q`` (rad/s: 1, rpm: 1, N*m/rad: -1, Hz: 0)."""
    return int(dict(q.to_root_units().unit_items()).get("radian", 0))


def _hertz(q) -> int:
    """The power of hertz (any prefix) in the units ``q`` is written in."""
    return int(sum(e for n, e in q.unit_items() if n.endswith("hertz")))


def convert(q, target: str) -> float:
    """The magnitude of the pint quantity ``q`` in the unit ``target``, a frequency counting cycles.

    pint takes the radian as 1, so alone it reads ``1 Hz`` as 1 rad/s and ``60 rpm`` as 6.28 Hz.  Here a
    frequency in hertz counts cycles of 2 pi rad wherever one side of the conversion has an angle and the
    other has hertz in its place: ``1 Hz`` is 2 pi rad/s (a speed in Hz is revolutions per second, as
    ``1 rps``), ``60 rpm`` and ``2 pi rad/s`` are 1 Hz (a frequency from an angular speed); ``1/s`` stays
    1 rad/s (the SI radian), and every conversion with the same angle on both sides is pint's.

    Raises
    ------
    pint.errors.DimensionalityError
        The units do not convert.
    """
    ureg = _registry()
    cycles_in, cycles_out = _cycles(str(q.units), target)
    if cycles_in:      # cycles per second where an angle per second is meant
        return float((q * ureg.turn ** cycles_in).to(target).magnitude)
    if cycles_out:     # an angle per second where cycles per second are meant
        return float(q.to(ureg.Unit(target) * ureg.turn ** cycles_out).magnitude)
    return float(q.to(target).magnitude)


@lru_cache(maxsize=512)
def _cycles(source: str, target: str) -> tuple[int, int]:
    """How :func:`convert` reads hertz between the units ``source`` and ``target`` (pint spellings): the power
    of the turn to multiply the quantity by, or to add to the target; (0, 0) for pint's own conversion."""
    ureg = _registry()
    s, t = ureg.Quantity(1.0, source), ureg.Quantity(1.0, target)
    k = _radians(t) - _radians(s)
    if k and _hertz(s) == k:
        return k, 0
    if k and _hertz(t) == -k:
        return 0, -k
    return 0, 0


# ---------------------------------------------------------------- conversions kept between processes
#: a unit as written that may be kept: no number in it but an exponent (``m^2``, ``m**-1``): pint folds other
#: numbers (``N/(10 mm)``) into the magnitude, and the product would then round differently
_KEEPABLE = re.compile(r"^(?:[^\d]|(?<=\^)-?\d+|(?<=\*\*)-?\d+|(?<=\d)\d)*$")
_KEPT: dict | None = None   # "unit as written|target" -> factor (loaded on first use)
_KEPT_FORMAT = 1


def _kept_file():
    """The file of kept factors for the installed pint (None where there is no cache folder or no pint)."""
    from importlib import metadata

    from ._cache import cache_folder

    try:
        version = metadata.version("pint")
        return cache_folder("units") / f"conversions-pint{version}-v{_KEPT_FORMAT}.json"
    except (OSError, metadata.PackageNotFoundError):
        return None


def _kept() -> dict:
    """The kept factors, read once per process; a file that is not a mapping of names to finite numbers (damaged,
    written by hand) is ignored and later replaced."""
    global _KEPT
    if _KEPT is None:
        _KEPT = {}
        path = _kept_file()
        try:
            data = json.loads(path.read_text(encoding="utf-8")) if path is not None else {}
        except (OSError, ValueError):
            data = {}
        if isinstance(data, dict):
            _KEPT = {k: float(v) for k, v in data.items() if isinstance(k, str) and type(v) in (int, float)
                     and math.isfinite(v) and v != 0.0}
    return _KEPT


def _keep(text: str, unit: str, factor: float) -> None:
    """Keep pint's factor from ``text`` to ``unit``, for this process and the next (written atomically: a temporary
    file renamed over the old one; where that fails, only for this process)."""
    key = f"{text}|{unit}"
    kept = _kept()
    if kept.get(key) == factor:
        return
    kept[key] = factor
    path = _kept_file()
    if path is None:
        return
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")   # (one per writer)
    try:
        tmp.write_text(json.dumps(kept, sort_keys=True), encoding="utf-8")
        os.replace(tmp, path)
    except OSError:
        try:
            tmp.unlink()
        except OSError:
            pass


def _factor(ureg, text: str, unit: str) -> float | None:
    """pint's multiplicative factor from ``text`` to ``unit`` if the conversion is one (``f(x) = x * f(1)``, no
    offset), else None."""
    try:
        zero = convert(ureg.Quantity(0.0, text), unit)
        one = convert(ureg.Quantity(1.0, text), unit)
        three = convert(ureg.Quantity(3.0, text), unit)
    except Exception:  # noqa: BLE001 (an offset unit in a product, ...: not kept)
        return None
    if zero != 0.0 or not math.isfinite(one) or one == 0.0 or three != 3.0 * one:
        return None
    return one


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
        m = _NUMBER_UNIT.match(value)
        text = (m.group(2).strip() or "dimensionless") if m is not None else ""
        factor = _kept().get(f"{text}|{unit}") if m is not None else None
        if factor is not None:   # (a conversion pint made before: its factor, without importing pint)
            out = float(m.group(1)) * factor
            if not math.isfinite(out):
                raise ParameterError(f"{where}{name} = {short_repr(value)}: not a finite number")
            return out
        ureg = _registry()
        import pint

        try:
            if m is None:
                raise ValueError("expected '<number> <unit>'")
            q = ureg.Quantity(float(m.group(1)), m.group(2).strip() or "dimensionless")
        except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError, ValueError, TypeError, AttributeError) as exc:
            raise ParameterError(f"{where}{name} = {short_repr(value)}: cannot parse quantity ({exc})") from None
        except Exception as exc:  # pint raises assorted tokenizer errors
            raise ParameterError(f"{where}{name} = {short_repr(value)}: cannot parse quantity ({exc})") from None
        try:
            out = convert(q, unit)
        except pint.errors.DimensionalityError:
            raise ParameterError(
                f"{where}{name} = {short_repr(value)}: wrong unit, expected a quantity convertible to {unit!r}"
            ) from None
        if _KEEPABLE.match(text) and math.isfinite(out):
            factor = _factor(ureg, text, unit)
            if factor is not None and float(m.group(1)) * factor == out:
                _keep(text, unit, factor)
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


# ---------------------------------------------------------------- units of column names
#: unit suffixes of clutchlab column names (docs/nomenclature.md, "Unit suffixes"):
#: suffix -> (unit for files and pint, unit for people).  The longest matching suffix of a name wins.
COLUMN_UNITS: dict[str, tuple[str, str]] = {
    "s": ("s", "s"), "ms": ("ms", "ms"),
    "m": ("m", "m"), "mm": ("mm", "mm"), "m2": ("m**2", "m²"), "m3": ("m**3", "m³"),
    "m_s": ("m/s", "m/s"), "m_s2": ("m/s**2", "m/s²"), "m_s3": ("m/s**3", "m/s³"), "m3_s": ("m**3/s", "m³/s"), "m_per_N": ("m/N", "m/N"),
    "rad": ("rad", "rad"), "rad_s": ("rad/s", "rad/s"), "rad_s2": ("rad/s**2", "rad/s²"),
    "rad_s3": ("rad/s**3", "rad/s³"), "rpm": ("rpm", "rpm"),
    "N": ("N", "N"), "kN": ("kN", "kN"), "N_m": ("N/m", "N/m"), "Nm": ("N*m", "N·m"),
    "Pa": ("Pa", "Pa"), "kPa": ("kPa", "kPa"), "MPa": ("MPa", "MPa"), "bar": ("bar", "bar"), "Pa_s": ("Pa*s", "Pa·s"),
    "C": ("degC", "°C"), "c": ("degC", "°C"), "degC": ("degC", "°C"), "K": ("K", "K"), "deg": ("deg", "°"),
    "kg": ("kg", "kg"), "kg_m2": ("kg*m**2", "kg·m²"),
    "A": ("A", "A"), "V": ("V", "V"), "W": ("W", "W"), "kW": ("kW", "kW"), "J": ("J", "J"), "Hz": ("Hz", "Hz"),
    "W_K": ("W/K", "W/K"), "J_K": ("J/K", "J/K"), "ohm": ("ohm", "Ω"), "H": ("H", "H"), "T": ("T", "T"),
    "Wb": ("Wb", "Wb"), "pct": ("percent", "%"), "1": ("1", "dimensionless"),
}
#: bare column names with a fixed unit (EMTC FORC tables, generic time)
NAME_UNITS: dict[str, str] = {"time": "s", "current": "A", "force": "N", "airgap": "m", "torque": "N*m"}
_HUMAN = {file_unit: human for file_unit, human in COLUMN_UNITS.values()}
_HUMAN.update({"N*m": "N·m", "degC": "°C", "": "dimensionless"})


def _suffix(name: str) -> str | None:
    parts = str(name).split("_")
    for k in range(1, len(parts)):  # longest suffix first: "line_flow_m3_s" -> "m3_s", not "s"
        suffix = "_".join(parts[k:])
        if suffix in COLUMN_UNITS:
            return suffix
    return None


def column_unit(name: str) -> str | None:
    """The unit a column name states, as written in a file's units line (``"N*m"``, ``"m**3/s"``).

    Parameters
    ----------
    name : str
        Column name following docs/nomenclature.md (``torque_Nm``,
        ``line_flow_m3_s``, ``temperature_C``, ``throttle_1``) or one of the
        bare names ``time``, ``current``, ``force``, ``airgap``, ``torque``.

    Returns
    -------
    str or None
        A unit string pint understands (``"1"`` for dimensionless), or
        ``None`` if the name states no unit.
    """
    name = str(name)
    if name in NAME_UNITS:
        return NAME_UNITS[name]
    suffix = _suffix(name)
    return None if suffix is None else COLUMN_UNITS[suffix][0]


def unit_label(unit: str) -> str:
    """A unit for people: a column suffix or a file unit written as in print (``rad_s`` -> ``rad/s``).

    Parameters
    ----------
    unit : str
        A suffix of :data:`COLUMN_UNITS` (``"rad_s"``, ``"C"``, ``"m3_s"``,
        ``"Nm"``, ``"1"``) or a unit string as :func:`column_unit` returns it
        (``"rad/s"``, ``"degC"``, ``"N*m"``).

    Returns
    -------
    str
        ``"rad/s"``, ``"°C"``, ``"m³/s"``, ``"N·m"``, ``"dimensionless"``;
        any other pint spelling as printed (``"N*m/rad"`` -> ``"N·m/rad"``).
    """
    unit = str(unit)
    if unit in COLUMN_UNITS:
        return COLUMN_UNITS[unit][1]
    if unit in _HUMAN:
        return _HUMAN[unit]
    # a pint spelling not in the tables, as printed (N*m/rad -> N·m/rad, kg*m**2 -> kg·m²; #33)
    for spelled, printed in (("**-1", "⁻¹"), ("**2", "²"), ("**3", "³"), ("^2", "²"), ("^3", "³"), ("*", "·")):
        unit = unit.replace(spelled, printed)
    return unit


#: the unit engineers read each quantity in, by the SI (file) unit of the column: figures and tables of reports
#: may show these; the columns and files stay SI (docs/report.md, "Engineers' units")
ENGINEERS_UNITS: dict[str, str] = {
    "rad/s": "rpm", "m/s": "km/h", "Pa": "bar", "kPa": "bar", "MPa": "bar", "m": "mm", "N": "kN",
    "K": "degC", "rad": "deg", "W": "kW", "J": "kJ", "m**3/s": "l/min", "s": "s",
}


def engineers_unit(unit: str) -> tuple[str, float, float]:
    """The engineers' unit of an SI column unit and the affine map to it.

    Parameters
    ----------
    unit : str
        The column's unit as :func:`column_unit` returns it (``"rad/s"``, ``"Pa"``, ``"N"``).

    Returns
    -------
    (unit, scale, offset) : tuple
        ``shown = scale * value + offset`` in ``unit`` (``("rpm", 9.549..., 0.0)`` for rad/s,
        ``("degC", 1.0, -273.15)`` for K); the unit itself with ``(1, 0)`` where engineers read SI (N·m, °C).
    """
    target = ENGINEERS_UNITS.get(str(unit))
    if not target or target == unit:
        return str(unit), 1.0, 0.0
    scale, offset = affine_conversion(unit, target)
    return target, scale, offset


@lru_cache(maxsize=512)
def affine_conversion(source: str, target: str) -> tuple[float, float]:
    """``(scale, offset)`` with ``target_value = scale * source_value + offset`` (pint, logger spellings allowed).

    Parameters
    ----------
    source, target : str
        Unit strings (``""`` dimensionless); a frequency in Hz counts cycles where an angle is meant
        (:func:`convert`).

    Raises
    ------
    pint.errors.PintError
        Unknown unit, or units of different dimension (:func:`clutchlab.io.unit_conversion` turns these
        into clutchlab's errors naming the channel and the file).
    """
    ureg = _registry()
    src = normalise_unit(source) or "dimensionless"
    tgt = normalise_unit(target) or "dimensionless"
    zero = convert(ureg.Quantity(0.0, src), tgt)
    one = convert(ureg.Quantity(1.0, src), tgt)
    return float(one - zero), float(zero)


def column_label(name: str) -> str:
    """Axis or table label of a column: its name and its unit (``slip_speed_rad_s`` -> ``slip_speed [rad/s]``).

    The name is kept as it is spelled (``ice.idle_kp`` stays ``ice.idle_kp``): it is what people type
    in a spec, a parameter file or a query, so a label must not turn its underscores into spaces (#33).
    Only the unit suffix is taken off and written as people read it.

    Parameters
    ----------
    name : str
        Column name following docs/nomenclature.md.

    Returns
    -------
    str
        ``"<name without its unit suffix> [<unit>]"``; a name without a unit suffix is returned as
        it is (``coupling_mode`` -> ``coupling_mode``).
    """
    name = str(name)
    if name in NAME_UNITS:
        return f"{name} [{unit_label(NAME_UNITS[name])}]"
    suffix = _suffix(name)
    if suffix is None:
        return name
    return f"{name[: -len(suffix) - 1]} [{COLUMN_UNITS[suffix][1]}]"
