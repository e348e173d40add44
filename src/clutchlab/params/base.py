"""Base class of every clutchlab parameter set.

A parameter set is a frozen dataclass whose fields carry their SI unit, a
description and a source as metadata (declared with :func:`quantity`).  Values
are validated on construction (finite, sign, bounds); files are TOML in which
values may carry units (``r_outer = "83.15 mm"``), converted once with pint.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path
from typing import Any, ClassVar

from ..errors import ParameterError
from ..units import format_quantity, to_si

__all__ = ["quantity", "ParameterSet", "load_toml"]


def quantity(default, unit: str, doc: str, *, source: str = "", positive: bool = False,
             nonnegative: bool = False, bounds: tuple[float | None, float | None] = (None, None)):
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
        Optional inclusive bounds checked on construction.
    """
    meta = dict(unit=unit, doc=doc, source=source, positive=positive, nonnegative=nonnegative, bounds=bounds)
    if isinstance(default, (list, tuple)):
        default = tuple(float(v) for v in default)
    return dataclasses.field(default=default, metadata=meta)


def _check_number(cls_name, fname, value, meta, source):
    where = f"{source}: " if source else ""
    label = f"{where}{cls_name}.{fname}"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(f"{label} = {value!r}: expected a number")
    if not math.isfinite(value):
        raise ParameterError(f"{label} = {value!r}: not finite")
    if meta.get("positive") and not value > 0:
        raise ParameterError(f"{label} = {value!r}: must be > 0 [{meta['unit']}]")
    if meta.get("nonnegative") and value < 0:
        raise ParameterError(f"{label} = {value!r}: must be >= 0 [{meta['unit']}]")
    lo, hi = meta.get("bounds", (None, None))
    if lo is not None and value < lo:
        raise ParameterError(f"{label} = {value!r}: below the lower bound {lo} [{meta['unit']}]")
    if hi is not None and value > hi:
        raise ParameterError(f"{label} = {value!r}: above the upper bound {hi} [{meta['unit']}]")


@dataclasses.dataclass(frozen=True)
class ParameterSet:
    """Frozen, validated parameter set (subclass it with :func:`quantity` fields).

    Subclasses may override :meth:`check` for cross-field consistency
    (e.g. ``r_inner < r_outer``) and raise :class:`ParameterError`.
    """

    #: short name used in files and the CLI (``[eclutch]`` table in TOML)
    kind: ClassVar[str] = "parameters"

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
    def from_dict(cls, data: dict[str, Any], *, source: str | None = None, base: "ParameterSet | None" = None):
        """Build a set from a mapping whose values may carry units.

        Unknown keys, unparsable quantities and wrong units raise
        :class:`ParameterError` naming ``source``, the key and the value.
        Keys not given are taken from ``base`` (default: the class defaults).
        """
        info = cls.field_info()
        where = f"{source}: " if source else ""
        unknown = [k for k in data if k not in info]
        if unknown:
            raise ParameterError(
                f"{where}unknown parameter {unknown[0]!r} for {cls.__name__} (known: {', '.join(info)})"
            )
        values = {}
        for key, raw in data.items():
            unit = info[key]["unit"]
            if isinstance(raw, (list, tuple)):
                values[key] = tuple(to_si(v, unit, name=f"{key}[{i}]", source=source) for i, v in enumerate(raw))
            else:
                values[key] = to_si(raw, unit, name=key, source=source)
            default = getattr(base, key) if base is not None else dataclasses.fields(cls)[[f.name for f in dataclasses.fields(cls)].index(key)].default
            if isinstance(default, int) and not isinstance(default, bool):
                v = values[key]
                if v != int(v):
                    raise ParameterError(f"{where}{key} = {raw!r}: expected a whole number")
                values[key] = int(v)
        try:
            if base is not None:
                return dataclasses.replace(base, **values)
            return cls(**values)
        except ParameterError as exc:
            raise ParameterError(f"{where}{exc}") from None

    @classmethod
    def from_toml(cls, path, *, base: "ParameterSet | None" = None):
        """Load a set from a TOML file (top level, or the ``[<kind>]`` table)."""
        data = load_toml(path)
        if cls.kind in data and isinstance(data[cls.kind], dict):
            data = data[cls.kind]
        return cls.from_dict(data, source=str(path), base=base)

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
    """Read the TOML file at ``path``, turning a missing file and syntax errors into :class:`ParameterError`."""
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"{path}: no such parameter file")
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None
