"""Base class of every clutchlab parameter set.

A parameter set is a frozen dataclass whose fields carry their SI unit, a
description and a source as metadata (declared with :func:`quantity`).  Values
are validated on construction (finite, sign, bounds); files are TOML in which
values may carry units (``r_outer = "83.15 mm"``), converted once with pint.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
from pathlib import Path
from typing import Any, ClassVar

from .._limits import short_repr
from ..errors import ParameterError
from ..units import format_quantity, to_si

__all__ = ["quantity", "ParameterSet", "load_toml", "registered_sets", "field_range"]

#: every ParameterSet subclass, in definition order (filled by ``ParameterSet.__init_subclass__``)
_REGISTERED: list[type] = []


def quantity(default, unit: str, doc: str, *, source: str = "", positive: bool = False,
             nonnegative: bool = False, bounds: tuple[float | None, float | None] = (None, None),
             reference: bool = False):
    """Declare a parameter field with its SI unit and documentation.

    Parameters
    ----------
    default : float or tuple of float
        Default value in SI units.
    unit : str
        SI unit (pint syntax: ``"m"``, ``"N/m"``, ``"Pa*s"``, ``"degC"``, ``"1"``).
    doc : str
        One-line description.
    source : str
        Where the default comes from (paper table, reasoning).
    positive, nonnegative : bool
        Sign constraints checked on construction.
    bounds : (low, high)
        Optional inclusive bounds checked on construction.  Without them the
        magnitude must not exceed the plausibility limit of the unit
        (:data:`PLAUSIBLE_LIMITS`, else :data:`MAGNITUDE_LIMIT`).
    reference : bool
        A number of the paper's tables that the model's equations do not read (a core disk's thickness beside
        its mass): kept in the set and its files for the record, but no parameter of an FMU, a sweep or a
        network (:func:`is_reference`), where changing it would change nothing.
    """
    meta = dict(unit=unit, doc=doc, source=source, positive=positive, nonnegative=nonnegative, bounds=bounds,
                reference=reference)
    if isinstance(default, (list, tuple)):
        default = tuple(float(v) for v in default)
    return dataclasses.field(default=default, metadata=meta)


def is_reference(field) -> bool:
    """Whether a parameter-set field (a :class:`dataclasses.Field`) is a reference number the model does not read
    (:func:`quantity`'s ``reference``)."""
    return bool(field.metadata.get("reference", False))


def model_fields(cls) -> tuple:
    """The fields of a :class:`ParameterSet` class (or instance) that a model reads: those declared with
    :func:`quantity` (a unit), less the reference numbers (:func:`is_reference`).  The parameters an FMU, a sweep
    and a network take from a set are these."""
    return tuple(f for f in dataclasses.fields(cls) if "unit" in f.metadata and not is_reference(f))


#: Largest magnitude [SI] a parameter of each unit may have: generous limits for the clutches and
#: drivelines of road vehicles (a factor of 10-1000 above the largest value any model uses), so a
#: slip of the unit or the exponent (``r_outer = 1e300``, ``"83 km"``) is refused on construction
#: instead of overflowing or giving a silently absurd result.  A field's own ``bounds`` replace the
#: limit; units not listed get :data:`MAGNITUDE_LIMIT`.
PLAUSIBLE_LIMITS = {
    "m": (100.0, "a length"),                      # largest used: a wheelbase, 2.7 m
    "m^2": (100.0, "an area"),
    "m**2": (100.0, "an area"),
    "m**3": (10.0, "a volume"),
    "kg": (1e5, "a mass"),                         # a 100 t vehicle
    "kg*m^2": (1e4, "a moment of inertia"),
    "kg*m**2": (1e4, "a moment of inertia"),
    "s": (1e6, "a time"),                          # 11 days
    "N": (1e7, "a force"),
    "N*m": (1e6, "a torque"),
    "W": (1e8, "a power"),
    "rad/s": (1e5, "an angular speed"),            # ~1e6 rpm
    "m/s": (1e3, "a speed"),
    "Pa": (1e12, "a pressure or modulus"),         # above the modulus of diamond
    "Pa*s": (1e3, "a dynamic viscosity"),
    "N/m": (1e15, "a stiffness"),                 # a rigid link is modelled as 1e13 N/m
    "degC": (1e4, "a temperature"),
    "K": (1e4, "a temperature difference"),
    "W/K": (1e7, "a thermal conductance"),
    "J/(kg*K)": (1e5, "a specific heat capacity"),
}
#: Limit of the units not in :data:`PLAUSIBLE_LIMITS` (and of dimensionless numbers): products of a
#: few such values stay far from float overflow.
MAGNITUDE_LIMIT = 1e15
#: No temperature [degC] lies below the absolute zero.
ABSOLUTE_ZERO_C = -273.15
#: The temperatures [degC] the wet clutch's model takes (pack, oil and housing, at the start and as the heater's
#: set point): from about the pour point of automatic-transmission fluids (-40 to -50 degC; below it there is no
#: film to squeeze) to well above the destruction of paper friction linings (about 300-400 degC) and the oil's
#: flash point (about 200-250 degC), so that a slip of unit or exponent ("1e6 degC") is refused while any
#: temperature a bench or a vehicle reaches is taken.  One range: the scenario, the driveline's wet clutch and
#: its declaration read it (a light module, so reading it imports no model).
WET_TEMPERATURES_C = (-60.0, 600.0)
#: The largest friction coefficient a clutch, brake or friction map may have: dry and wet clutch linings run at
#: 0.05-0.6, clean metals in vacuum reach about 1-1.5; above 2 it is a typing or unit slip (a percentage, a
#: torque).  The clutch's declared range and the friction map's check read it.
FRICTION_COEFFICIENT_MAX = 2.0
#: The largest ``mu_scale`` of a driveline's clutch, brake or one-way clutch: a sweep's factor on a friction
#: coefficient (a number, a table or a map) that is checked on its own.
MU_SCALE_MAX = 2.0


def _number_problem(value, meta) -> str | None:
    """Why ``value`` is not acceptable for a field with metadata ``meta`` (None if it is)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return "expected a number"
    if not math.isfinite(value):
        return "not finite"
    lo, hi = meta.get("bounds", (None, None))
    if lo is None and hi is None:
        unit = meta.get("unit", "1")
        limit, what = PLAUSIBLE_LIMITS.get(unit, (MAGNITUDE_LIMIT, "a value"))
        if abs(value) > limit:
            return f"implausible for {what} (magnitude above {limit:g} {unit}); check the unit and the exponent"
        if unit == "degC" and value < ABSOLUTE_ZERO_C:
            return f"below the absolute zero ({ABSOLUTE_ZERO_C} degC)"
    if meta.get("positive") and not value > 0:
        return f"must be > 0 [{meta['unit']}]"
    if meta.get("nonnegative") and value < 0:
        return f"must be >= 0 [{meta['unit']}]"
    if lo is not None and value < lo:
        return f"below the lower bound {lo} [{meta['unit']}]"
    if hi is not None and value > hi:
        return f"above the upper bound {hi} [{meta['unit']}]"
    return None


def field_range(meta) -> tuple:
    """``(minimum, maximum, positive)`` a field with metadata ``meta`` (:func:`quantity`) accepts: its
    ``bounds``, else the plausibility limit of its unit (:data:`PLAUSIBLE_LIMITS`, the absolute zero for a
    temperature), ``nonnegative`` as a minimum of 0, ``positive`` as a strict lower bound of 0.  An FMU writes it
    as a parameter's ``min`` and ``max``.

    Parameters
    ----------
    meta : mapping
        The field's metadata (``dataclasses.fields(cls)[i].metadata``).
    """
    lo, hi = meta.get("bounds", (None, None))
    if lo is None and hi is None:
        unit = meta.get("unit", "1")
        limit = PLAUSIBLE_LIMITS.get(unit, (MAGNITUDE_LIMIT, ""))[0]
        lo, hi = (ABSOLUTE_ZERO_C if unit == "degC" else -limit), limit
    if meta.get("nonnegative") or meta.get("positive"):
        lo = 0.0 if lo is None else max(float(lo), 0.0)
    return (None if lo is None else float(lo)), (None if hi is None else float(hi)), bool(meta.get("positive"))


def _check_number(cls_name, fname, value, meta, source):
    where = f"{source}: " if source else ""
    problem = _number_problem(value, meta)
    if problem is not None:
        raise ParameterError(f"{where}{cls_name}.{fname} = {value!r}: {problem}")


def show_value(raw) -> str:
    """Format a value as it is written in a TOML file (``"83.15 mm"``, ``4``, ``[1, 2]``), long ones shortened."""
    if isinstance(raw, (list, tuple)) and len(raw) > 8 or isinstance(raw, str) and len(raw) > 80:
        return short_repr(raw, 80)
    if isinstance(raw, str):
        return repr(raw)  # a TOML literal string when it has no quote inside
    if isinstance(raw, bool):
        return "true" if raw else "false"
    if isinstance(raw, (list, tuple)):
        return "[" + ", ".join(show_value(v) for v in raw) + "]"
    if isinstance(raw, dict):
        return "{...}"
    return repr(raw)


#: SI units whose dimension has a name in error messages
_DIMENSION_NAMES = (
    ("1", "dimensionless"), ("m", "a length"), ("kg", "a mass"), ("s", "a time"), ("K", "a temperature"),
    ("Pa", "a pressure"), ("N", "a force"), ("N*m", "a torque (or energy)"), ("m/s", "a speed"),
    ("rad/s", "an angular speed (or frequency)"), ("N/m", "a stiffness"), ("m^2", "an area"),
    ("kg*m^2", "a moment of inertia"), ("W", "a power"), ("Pa*s", "a dynamic viscosity"),
    ("W/K", "a thermal conductance"), ("J/K", "a heat capacity"), ("J/(kg*K)", "a specific heat capacity"),
    ("1/K", "a temperature coefficient"), ("N*s/m", "a damping coefficient"), ("1/m^2", "a density per area"),
    ("m/N", "a compliance"), ("A", "a current"), ("V", "a voltage"), ("T", "a magnetic flux density"),
)
_NUMBER = re.compile(r"^\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?\s*")


def _dimension_name(dimensionality, ureg) -> str | None:
    for unit, name in _DIMENSION_NAMES:
        if ureg.Quantity(1.0, unit).dimensionality == dimensionality:
            return name
    return None


def _unit_mismatch(raw, unit: str) -> str | None:
    """If ``raw`` is a quantity string whose unit has the wrong dimension, say so in words."""
    if not isinstance(raw, str):
        return None
    from ..units import _registry

    ureg = _registry()
    given = _NUMBER.sub("", raw, count=1).strip()
    try:
        q_given = ureg.Quantity(1.0, given or "dimensionless")
        q_target = ureg.Quantity(1.0, unit)
    except Exception:  # unparsable unit: to_si's own message says so
        return None
    if q_given.dimensionality == q_target.dimensionality:
        return None
    want = _dimension_name(q_target.dimensionality, ureg) or f"convertible to {unit}"
    got = _dimension_name(q_given.dimensionality, ureg)
    return f"wrong unit: {given or '(none)'} is not {want}" + (f" (it is {got}; expected {unit})" if got else f" (expected {unit})")


def _convert(raw, unit: str, label: str, where: str) -> float:
    """``to_si`` with an error message naming the file, the (table and) key and the value as written."""
    try:
        return to_si(raw, unit, name="value")
    except ParameterError as exc:
        reason = str(exc).removeprefix(f"value = {raw!r}: ")
        reason = _unit_mismatch(raw, unit) or reason
        raise ParameterError(f"{where}{label} = {show_value(raw)}: {reason}") from None


@dataclasses.dataclass(frozen=True)
class ParameterSet:
    """Frozen, validated parameter set (subclass it with :func:`quantity` fields).

    Subclasses may override :meth:`check` for cross-field consistency
    (e.g. ``r_inner < r_outer``) and raise :class:`ParameterError`.
    """

    #: short name used in files and the CLI (``[eclutch]`` table in TOML)
    kind: ClassVar[str] = "parameters"

    def __init_subclass__(cls, **kwargs):
        # every subclass is registered, so clutchlab.params.registry finds the sets of each model
        super().__init_subclass__(**kwargs)
        _REGISTERED.append(cls)

    def __post_init__(self):
        for f in dataclasses.fields(self):
            if "unit" not in f.metadata:
                continue
            value = getattr(self, f.name)
            if isinstance(value, (list, tuple)):
                value = tuple(float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v for v in value)
                object.__setattr__(self, f.name, value)
                for k, v in enumerate(value):
                    _check_number(type(self).__name__, f"{f.name}[{k}]", v, f.metadata, None)
            else:
                if isinstance(value, int) and not isinstance(value, bool) and not isinstance(f.default, int):
                    object.__setattr__(self, f.name, float(value))
                _check_number(type(self).__name__, f.name, getattr(self, f.name), f.metadata, None)
        self.check()

    def check(self) -> None:
        """Cross-field physical consistency; override in subclasses."""

    # ------------------------------------------------------------------ access
    @classmethod
    def field_info(cls) -> dict[str, dict[str, Any]]:
        """Return ``{name: metadata}`` for every parameter field."""
        return {f.name: dict(f.metadata) for f in dataclasses.fields(cls) if "unit" in f.metadata}

    def to_dict(self, with_units: bool = False) -> dict[str, Any]:
        """Return the parameters as a dict (SI values, or ``"value unit"`` strings)."""
        out = {}
        for name, meta in self.field_info().items():
            value = getattr(self, name)
            if with_units:
                if isinstance(value, tuple):
                    value = [format_quantity(v, meta["unit"]) for v in value]
                else:
                    value = format_quantity(value, meta["unit"])
            out[name] = value
        return out

    def replace(self, **changes) -> "ParameterSet":
        """Return a copy with some fields changed (validated again)."""
        unknown = set(changes) - set(self.field_info())
        if unknown:
            raise ParameterError(f"{type(self).__name__}: unknown parameter(s) {sorted(unknown)}")
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------------ files
    @classmethod
    def from_dict(cls, data: dict[str, Any], *, source: str | None = None, base: "ParameterSet | None" = None,
                  table: str | None = None):
        """Build a set from a mapping whose values may carry units.

        Unknown keys, values of the wrong type or shape (a string that is no
        quantity, a list for a scalar), unparsable quantities, wrong units and
        out-of-range values raise :class:`ParameterError` naming ``source``
        (the file), ``[table] key`` and the value as written, e.g.
        ``wet.toml: [wet] r_outer = '83.15 kg': wrong unit: kg is not a length``.
        Keys not given are taken from ``base`` (default: the class defaults).
        """
        info = cls.field_info()
        where = f"{source}: " if source else ""
        prefix = f"[{table}] " if table else ""
        if not isinstance(data, dict):
            raise ParameterError(f"{where}{prefix or cls.__name__ + ': '}expected a table of parameters, got {show_value(data)}")
        unknown = [k for k in data if k not in info]
        if unknown:
            close = difflib.get_close_matches(unknown[0], list(info), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ParameterError(
                f"{where}{prefix}unknown parameter {unknown[0]!r} for {cls.__name__}{hint} (known: {', '.join(info)})"
            )
        defaults = {f.name: f.default for f in dataclasses.fields(cls)}
        values = {}
        for key, raw in data.items():
            meta = info[key]
            unit = meta["unit"]
            label = f"{prefix}{key}"
            default = getattr(base, key) if base is not None else defaults[key]
            if isinstance(default, tuple):
                if not isinstance(raw, (list, tuple)):
                    raise ParameterError(f"{where}{label} = {show_value(raw)}: expected a list of values [{unit}]")
                items = [(f"{label}[{i}]", v) for i, v in enumerate(raw)]
            else:
                if isinstance(raw, (list, tuple, dict)):
                    raise ParameterError(f"{where}{label} = {show_value(raw)}: expected a single value [{unit}]")
                items = [(label, raw)]
            converted = []
            for item_label, item in items:
                v = _convert(item, unit, item_label, where)
                if isinstance(default, int) and not isinstance(default, bool):
                    if v != int(v):
                        raise ParameterError(f"{where}{item_label} = {show_value(item)}: expected a whole number")
                    v = int(v)
                problem = _number_problem(v, meta)
                if problem is not None:  # the SI value, and the value as written where it differs
                    written = "" if show_value(item) == repr(v) else f" (written {show_value(item)})"
                    raise ParameterError(f"{where}{item_label} = {v!r}: {problem}{written}")
                converted.append(v)
            values[key] = tuple(converted) if isinstance(default, tuple) else converted[0]
        try:
            if base is not None:
                return dataclasses.replace(base, **values)
            return cls(**values)
        except ParameterError as exc:
            raise ParameterError(f"{where}{prefix}{exc}") from None

    @classmethod
    def from_toml(cls, path, *, base: "ParameterSet | None" = None):
        """Load a set from a TOML file (top level, or the ``[<kind>]`` table)."""
        data = load_toml(path)
        table = None
        if cls.kind in data and isinstance(data[cls.kind], dict):
            data = data[cls.kind]
            table = cls.kind
        return cls.from_dict(data, source=str(path), base=base, table=table)

    def to_toml(self, path, overwrite: bool = False) -> Path:
        """Write the set to TOML with units, atomically (refuses to overwrite by default)."""
        import tomli_w

        from ..io.files import atomic_write_text

        body = {self.kind: self.to_dict(with_units=True)}
        return atomic_write_text(path, tomli_w.dumps(body), overwrite=overwrite)

    def describe(self) -> str:
        """Human-readable table of name, value, unit, description and source."""
        lines = []
        for name, meta in self.field_info().items():
            value = getattr(self, name)
            val = ", ".join(f"{v:.6g}" for v in value) if isinstance(value, tuple) else f"{value:.6g}"
            src = f"  [{meta['source']}]" if meta.get("source") else ""
            lines.append(f"{name:<22} {val:>14} {meta['unit']:<8} {meta['doc']}{src}")
        return "\n".join(lines)


def load_toml(path) -> dict[str, Any]:
    """Read the TOML file at ``path``; a missing, unreadable, non-UTF-8, invalid or too deeply nested file
    raises :class:`ParameterError` naming it (:func:`clutchlab.io.files.read_toml`)."""
    from ..io.files import read_toml

    if not Path(path).exists():
        raise ParameterError(f"{path}: no such parameter file")
    return read_toml(path, ParameterError)


def registered_sets() -> tuple[type, ...]:
    """Every :class:`ParameterSet` subclass defined so far, in definition order."""
    return tuple(_REGISTERED)
