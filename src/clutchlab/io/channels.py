"""Channel maps: from a logger's channel names and units to clutchlab's names and SI units.

A data logger calls the clutch torque ``TQ_Clutch`` and records it in ``Nm``
at 1 kHz; clutchlab calls it ``torque_Nm`` and computes in N·m.  A
:class:`ChannelMap` states that correspondence once, in a TOML file or a
mapping::

    [channels.torque_Nm]
    source = "TQ_Clutch"          # the logger's channel name
    source_unit = "kN*m"          # optional: overrides the unit stored in the file

    [channels.slip_speed_rad_s]
    source = "N_Slip"             # recorded in rpm (or "U/min", "1/min"): converted to rad/s
    group = 2                     # optional: MDF data group, if the name occurs in several groups
    index = 4                     # optional: channel index in the group, if it occurs twice there

    [channels.gear]
    source = "Gear_Act"
    unit = "1"                    # no unit suffix in the name: say the unit
    interpolation = "previous"    # a state: hold, do not interpolate
    optional = true               # absent channels are skipped, not an error

    [csv]                         # optional: how the logger writes text files, where detection needs help
    encoding = "cp1252"           # (see clutchlab.io.dialect; every field may be left out and is then detected)
    separator = ";"
    decimal = ","
    header_row = 2                # line of the column names, counted from 1
    units_row = 3                 # line of the units, 0 for none

    [bus]                         # optional: decode the raw CAN/LIN frames of an MDF bus log into signals
    can = ["powertrain.dbc", {file = "chassis.arxml", channel = 2}]   # paths from the map's folder

The target unit of an entry is the one its clutchlab name states (``_Nm`` ->
N·m, ``_rad_s`` -> rad/s, ``_C`` -> °C, see :func:`canonical_unit`); names
without a unit suffix need ``unit``.  Unit strings are parsed with pint
(through :mod:`clutchlab.units`), after the logger spellings in
:data:`~clutchlab.units.UNIT_ALIASES` (``Nm``, ``°C``, ``U/  min``, ``1/min``,
``-``) are translated by :func:`~clutchlab.units.normalise_unit`, so ``"Nm"``
is a newton metre and not a nanometre, and ``"U/min"`` revolutions per minute,
not enzyme units.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Iterator, Mapping

from ..errors import ClutchlabError, DataError, ParameterError
from ..units import UNIT_ALIASES

__all__ = [
    "UNIT_ALIASES",
    "INTERPOLATIONS",
    "canonical_unit",
    "unit_conversion",
    "ChannelSpec",
    "ChannelMap",
]

#: how a channel recorded at its own timestamps is carried onto another time base
INTERPOLATIONS = ("linear", "previous")

def canonical_unit(name: str) -> str | None:
    """The unit a clutchlab column name states, or ``None`` if it states none.

    Parameters
    ----------
    name : str
        Column name following the nomenclature (``torque_Nm``,
        ``slip_speed_rad_s``, ``temperature_C``, ``time_s``) or one of the bare
        names ``time``, ``current``, ``force``, ``airgap``, ``torque``; the
        suffixes are those of :data:`clutchlab.units.COLUMN_UNITS`.

    Returns
    -------
    str or None
        Unit string for pint (``"N*m"``, ``"rad/s"``, ``"degC"``, ``"s"``).
    """
    from ..units import column_unit

    return column_unit(name)  # one suffix table for files, axis labels and reports: clutchlab.units.COLUMN_UNITS


def _conversion(source: str, target: str) -> tuple[float, float]:
    from ..units import affine_conversion

    return affine_conversion(source, target)   # (a frequency in Hz counts cycles where an angle is meant)


def unit_conversion(source: str, target: str, *, name: str = "channel", where: str = "",
                    error: type[ClutchlabError] = DataError) -> tuple[float, float]:
    """Scale and offset converting values in ``source`` units to ``target`` units.

    Every conversion between units of one dimension is affine, so
    ``target_value = scale * source_value + offset`` (the offset is non-zero
    only for temperatures: degF -> degC, degC -> K).

    Parameters
    ----------
    source, target : str
        Unit strings (pint syntax or a logger spelling of :data:`UNIT_ALIASES`;
        ``""`` is dimensionless).
    name : str
        Channel the units belong to, for error messages.
    where : str
        File or map the units come from, for error messages.
    error : type
        Exception class raised (``DataError`` for units found in a file,
        ``ParameterError`` for units written in a channel map).

    Returns
    -------
    (scale, offset) : tuple of float

    Raises
    ------
    DataError or ParameterError
        Unknown unit, or units of different dimension.
    """
    prefix = f"{where}: " if where else ""
    import pint

    for u in (source, target):
        try:
            _conversion(u, u)
        except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError, AttributeError, TypeError,
                ValueError, AssertionError):
            raise error(f"{prefix}channel {name!r}: unknown unit {u!r}") from None
        except Exception:  # pint's tokenizer raises assorted errors
            raise error(f"{prefix}channel {name!r}: unknown unit {u!r}") from None
    try:
        scale, offset = _conversion(source, target)
    except pint.errors.DimensionalityError:
        raise error(f"{prefix}channel {name!r}: unit {source!r} cannot be converted to {target!r} "
                    "(different dimension)") from None
    if not (math.isfinite(scale) and math.isfinite(offset)) or scale == 0.0:
        raise error(f"{prefix}channel {name!r}: unit {source!r} cannot be converted to {target!r}")
    return scale, offset


@dataclass(frozen=True)
class ChannelSpec:
    """One entry of a channel map: where a clutchlab channel comes from.

    Parameters
    ----------
    name : str
        clutchlab column name (``torque_Nm``).
    source : str
        The logger's channel name (default: ``name``).
    unit : str
        Unit of the clutchlab column (default: the unit ``name`` states, see
        :func:`canonical_unit`; required for names without a unit suffix).
    source_unit : str, optional
        Unit of the logged values, overriding the unit stored in the file (use
        it for files that store none or a wrong one).
    group : int, optional
        MDF data group holding the channel, needed when the name occurs in
        several groups.
    index : int, optional
        Index of the channel within ``group`` (as asammdf numbers them; the
        error for an ambiguous name lists the candidates), needed when the
        name occurs twice in one group.  The channel found there must be
        called ``source``.  Requires ``group``.
    interpolation : {"linear", "previous"}, optional
        How the channel is carried onto another time base (default: the
        reader's ``interpolation``); ``"previous"`` holds the last sample (for
        gears, flags, set points).
    optional : bool
        Skip the channel if the file lacks it instead of raising.
    """

    name: str
    source: str | None = None
    unit: str | None = None
    source_unit: str | None = None
    group: int | None = None
    index: int | None = None
    interpolation: str | None = None
    optional: bool = False

    def __post_init__(self):
        where = f"channel map entry {self.name!r}"
        if not isinstance(self.name, str) or not self.name.strip():
            raise ParameterError(f"channel map: channel name {self.name!r} must be a non-empty string")
        if self.source is None:
            object.__setattr__(self, "source", self.name)
        if not isinstance(self.source, str) or not self.source:
            raise ParameterError(f"{where}: source = {self.source!r} must be a non-empty string")
        stated = canonical_unit(self.name)
        if self.unit is None:
            if stated is None:
                raise ParameterError(f"{where}: the name states no unit; give unit = '...' "
                                     "(e.g. '1' for a dimensionless channel)")
            object.__setattr__(self, "unit", stated)
        elif not isinstance(self.unit, str):
            raise ParameterError(f"{where}: unit = {self.unit!r} must be a string")
        else:
            scale, offset = unit_conversion(self.unit, self.unit, name=self.name, where="channel map",
                                            error=ParameterError)
            if stated is not None:
                scale, offset = unit_conversion(self.unit, stated, name=self.name, where="channel map",
                                                error=ParameterError)
                if not (math.isclose(scale, 1.0, rel_tol=1e-12) and abs(offset) < 1e-12):
                    raise ParameterError(f"{where}: unit = {self.unit!r} contradicts the unit the name states "
                                         f"({stated!r}); clutchlab names carry their unit")
        if self.source_unit is not None:
            if not isinstance(self.source_unit, str):
                raise ParameterError(f"{where}: source_unit = {self.source_unit!r} must be a string")
            unit_conversion(self.source_unit, self.unit, name=self.name, where="channel map", error=ParameterError)
        if self.group is not None and (isinstance(self.group, bool) or not isinstance(self.group, int)
                                       or self.group < 0):
            raise ParameterError(f"{where}: group = {self.group!r} must be a non-negative whole number")
        if self.index is not None:
            if isinstance(self.index, bool) or not isinstance(self.index, int) or self.index < 0:
                raise ParameterError(f"{where}: index = {self.index!r} must be a non-negative whole number")
            if self.group is None:
                raise ParameterError(f"{where}: index = {self.index} needs group (the index counts within a group)")
        if self.interpolation is not None and self.interpolation not in INTERPOLATIONS:
            raise ParameterError(f"{where}: interpolation = {self.interpolation!r}; expected one of "
                                 f"{', '.join(INTERPOLATIONS)}")
        if not isinstance(self.optional, bool):
            raise ParameterError(f"{where}: optional = {self.optional!r} must be true or false")


_SPEC_KEYS = tuple(f.name for f in dataclasses.fields(ChannelSpec) if f.name != "name")


class ChannelMap:
    """An ordered set of :class:`ChannelSpec`: the logger's channels as clutchlab reads them.

    Parameters
    ----------
    channels : iterable of ChannelSpec
        The entries, in the order the columns of the result should have.
    name : str
        How to call the map in error messages (its file name).
    csv : CsvDialect or mapping, optional
        How the logger writes its text files (a ``[csv]`` table:
        :class:`~clutchlab.io.dialect.CsvDialect`); fields left out are detected.
    bus : iterable of BusDatabase, optional
        Bus databases decoding the raw CAN/LIN frames of an MDF bus log (a
        ``[bus]`` table: :class:`~clutchlab.io.mdf.BusDatabase`).

    Examples
    --------
    >>> cmap = ChannelMap.from_dict({"torque_Nm": "TQ_Clutch",
    ...                              "slip_speed_rad_s": {"source": "N_Slip", "source_unit": "rpm"}})
    >>> [c.source for c in cmap]
    ['TQ_Clutch', 'N_Slip']
    """

    def __init__(self, channels: Iterable[ChannelSpec], name: str = "channel map", csv=None, bus=()):
        from .dialect import CsvDialect
        from .mdf import BusDatabase

        self.name = name
        #: how the logger writes its text files (:class:`~clutchlab.io.dialect.CsvDialect`), or None: detected
        self.csv = None if csv is None else CsvDialect.coerce(csv, f"{name}: [csv]")
        #: bus databases decoding the raw CAN/LIN frames of an MDF bus log (:class:`~clutchlab.io.mdf.BusDatabase`)
        self.bus = tuple(BusDatabase.coerce(b) for b in bus)
        specs = list(channels)
        seen: dict[str, ChannelSpec] = {}
        for spec in specs:
            if not isinstance(spec, ChannelSpec):
                raise ParameterError(f"{name}: entries must be ChannelSpec, got {type(spec).__name__}")
            if spec.name in seen:
                raise ParameterError(f"{name}: channel {spec.name!r} is mapped twice")
            seen[spec.name] = spec
        self._specs = seen

    @classmethod
    def from_dict(cls, mapping: Mapping, name: str = "channel map", base: Path | None = None) -> "ChannelMap":
        """Build a map from ``{name: source}`` or ``{name: {"source": ..., "unit": ..., ...}}``.

        Parameters
        ----------
        mapping : mapping
            clutchlab name -> logger name, or clutchlab name -> table with the
            keys of :class:`ChannelSpec` (``source``, ``unit``,
            ``source_unit``, ``group``, ``index``, ``interpolation``, ``optional``).  A
            mapping with the key ``"channels"`` (the TOML layout, optionally with a ``"csv"`` table) is
            accepted too.
        name : str
            How to call the map in error messages.
        base : Path, optional
            Folder that relative bus-database paths of a ``[bus]`` table start
            from (the map file's folder).
        """
        if not isinstance(mapping, Mapping):
            raise ParameterError(f"{name}: expected a mapping of channel names, got {type(mapping).__name__}")
        csv, bus = None, []
        if "channels" in mapping and isinstance(mapping["channels"], Mapping):
            unknown = [k for k in mapping if k not in ("channels", "csv", "bus")]
            if unknown:
                raise ParameterError(f"{name}: unknown table {unknown[0]!r} (expected [channels.<name>] and "
                                     "optionally [csv] and [bus])")
            csv = mapping.get("csv")
            if csv is not None and not isinstance(csv, Mapping):
                raise ParameterError(f"{name}: csv = {csv!r} must be a table ([csv] with encoding, separator, "
                                     "decimal, header_row, units_row, thousands)")
            table = mapping.get("bus", {})
            if not isinstance(table, Mapping):
                raise ParameterError(f"{name}: bus = {table!r} must be a table ([bus] with can = [...], lin = [...])")
            for key, entries in table.items():
                if key.upper() not in ("CAN", "LIN"):
                    raise ParameterError(f"{name}: [bus] has unknown key {key!r} (expected can, lin)")
                if isinstance(entries, (str, Mapping)):
                    entries = [entries]
                if not isinstance(entries, list):
                    raise ParameterError(f"{name}: [bus] {key} = {entries!r} must be a list of database files")
                from .mdf import BusDatabase

                bus += [BusDatabase.coerce(e, base, key.upper()) for e in entries]
            mapping = mapping["channels"]
        specs = []
        for key, entry in mapping.items():
            if isinstance(entry, str):
                specs.append(ChannelSpec(str(key), source=entry))
            elif isinstance(entry, Mapping):
                unknown = [k for k in entry if k not in _SPEC_KEYS]
                if unknown:
                    raise ParameterError(f"{name}: channel {key!r} has unknown key {unknown[0]!r} "
                                         f"(expected {', '.join(_SPEC_KEYS)})")
                specs.append(ChannelSpec(str(key), **dict(entry)))
            else:
                raise ParameterError(f"{name}: channel {key!r} = {entry!r}: expected a source name or a table")
        return cls(specs, name=name, csv=csv, bus=bus)

    @classmethod
    def from_toml(cls, path) -> "ChannelMap":
        """Read a channel map from a TOML file with ``[channels.<name>]`` tables.

        Parameters
        ----------
        path : str or Path
            The TOML file (layout in the module docstring).
        """
        from .files import read_toml

        return cls.from_dict(read_toml(path, ParameterError), name=str(path), base=Path(path).parent)

    @classmethod
    def coerce(cls, value) -> "ChannelMap | None":
        """Accept ``None``, a :class:`ChannelMap`, a mapping or a TOML path.

        Parameters
        ----------
        value : None, ChannelMap, mapping, str or Path
            What a reader was given as its ``channel_map``.
        """
        if value is None or isinstance(value, ChannelMap):
            return value
        if isinstance(value, Mapping):
            return cls.from_dict(value)
        if isinstance(value, (str, Path)):
            return cls.from_toml(value)
        raise ParameterError(f"channel_map = {value!r}: expected a ChannelMap, a mapping or a TOML file")

    def __iter__(self) -> Iterator[ChannelSpec]:
        return iter(self._specs.values())

    def __len__(self) -> int:
        return len(self._specs)

    def __contains__(self, name) -> bool:
        return name in self._specs

    def __getitem__(self, name: str) -> ChannelSpec:
        try:
            return self._specs[name]
        except KeyError:
            raise ParameterError(f"{self.name}: no channel {name!r} (has: {', '.join(self._specs)})") from None

    @property
    def names(self) -> tuple[str, ...]:
        """clutchlab names of the entries, in order."""
        return tuple(self._specs)

    def to_dict(self) -> dict:
        """The map as the nested dict of its TOML layout (``{"channels": {name: {...}}}``)."""
        out = {}
        for spec in self:
            entry = {k: getattr(spec, k) for k in _SPEC_KEYS
                     if getattr(spec, k) is not None and not (k == "optional" and not spec.optional)}
            out[spec.name] = entry
        table = {}
        if self.csv is not None and self.csv.to_dict():
            table["csv"] = self.csv.to_dict()
        for b in self.bus:
            table.setdefault("bus", {}).setdefault(b.bus.lower(), []).append(
                {"file": str(b.path), "channel": b.channel} if b.channel else str(b.path))
        table["channels"] = out
        return table

    def __repr__(self) -> str:
        return f"ChannelMap({', '.join(f'{s.name}<-{s.source}' for s in self)})"
