"""Measured records: read CSV, Parquet and ASAM MDF 4 into SI, write them back with units.

Every reader of a bench or vehicle record in clutchlab (wet-clutch bench,
E-clutch press rig and full clutch, EMTC FORC tables and inputs) goes through
:func:`read_measurement`, which

1. opens the file by its suffix (``.csv``, ``.parquet``/``.pq``, ``.mf4``/``.mdf``)
   or takes a DataFrame,
2. picks the channels named by a :class:`~clutchlab.io.channels.ChannelMap`
   (or all of them, under their own names),
3. checks each: present, unambiguous, numeric, finite, timestamps strictly
   increasing -- a :class:`~clutchlab.errors.DataError` names the file, the
   channel and the offending sample,
4. carries channels recorded at different rates onto one time base (the
   fastest channel's timestamps, a uniform ``rate`` or a given ``time_base``)
   by linear interpolation or sample-and-hold, and
5. converts every channel from the unit the file (or the map) states to the
   unit the clutchlab name states (rpm -> rad/s, kN -> N, degF -> degC).

:func:`write_measurement` writes CSV (a ``# units:`` comment line), Parquet
(units in the schema metadata) or MDF 4 (units in each channel), atomically and
never over an existing file unless ``overwrite=True``.
"""

from __future__ import annotations

import io
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Mapping, Sequence

import numpy as np
import pandas as pd

from .._limits import check_allocation, short_repr
from ..errors import DataError, ParameterError
from ..units import normalise_unit
from .dialect import CsvDialect, read_csv
from .channels import INTERPOLATIONS, ChannelMap, ChannelSpec, canonical_unit, unit_conversion
from .files import atomic_to_csv, atomic_write_bytes, check_writable
from .mdf import MDF_SUFFIXES, BusDatabase, MdfReader, RawChannel, write_mdf

__all__ = [
    "CSV_SUFFIXES",
    "PARQUET_SUFFIXES",
    "ChannelOrigin",
    "MeasurementSource",
    "Measurement",
    "read_measurement",
    "write_measurement",
    "resample",
]

CSV_SUFFIXES = (".csv", ".txt")
PARQUET_SUFFIXES = (".parquet", ".pq")
_UNITS_PREFIX = "units:"
_PARQUET_KEY = b"clutchlab"
#: largest magnitude a channel may have in its unit; beyond it the file is taken to be corrupted
PLAUSIBLE_MAGNITUDE = 1e15


@dataclass(frozen=True)
class ChannelOrigin:
    """Where a column of a :class:`Measurement` came from.

    Parameters
    ----------
    source : str
        Channel name in the file.
    source_unit : str
        Unit of the stored values (from the file, the map, or the name).
    unit : str
        Unit of the column.
    group : int or None
        MDF data group (``None`` for tables).
    samples : int
        Number of stored samples.
    rate_hz : float or None
        Mean sample rate of the stored channel [Hz] (``None`` without time).
    interpolation : str or None
        How it was carried onto the time base (``None`` if not resampled).
    """

    source: str
    source_unit: str
    unit: str
    group: int | None
    samples: int
    rate_hz: float | None
    interpolation: str | None = None


@dataclass(frozen=True)
class MeasurementSource:
    """Provenance of a :class:`Measurement`.

    Parameters
    ----------
    path : str or None
        File read (``None`` for a DataFrame).
    format : str
        ``"csv"``, ``"parquet"``, ``"mdf"`` or ``"frame"``.
    comments : tuple of str
        Header comment lines of the file (CSV ``#`` lines, Parquet metadata,
        MDF header comment).
    channels : mapping
        Column name -> :class:`ChannelOrigin`.
    time_base : str
        How the time base was chosen (``"as recorded"``, ``"resampled ..."``).
    skipped : mapping of str to str
        Channels (or MDF groups) of the file that a read without channel map
        left out, with the reason (unknown unit, non-numeric samples, raw bus
        frames, a name occurring several times); empty when reading with a map.
    dialect : CsvDialect or None
        How a text table was written (encoding, separator, decimal mark,
        name and unit rows), as detected or given; ``None`` for other formats.
    bus : str or None
        What the bus databases decoded from an MDF bus log (messages, IDs no
        database defines); ``None`` without databases.
    """

    path: str | None
    format: str
    comments: tuple[str, ...] = ()
    channels: Mapping[str, ChannelOrigin] = field(default_factory=dict)
    time_base: str = "as recorded"
    skipped: Mapping[str, str] = field(default_factory=dict)
    dialect: CsvDialect | None = None
    bus: str | None = None

    @property
    def synthetic(self) -> bool:
        """True if a header line says the data are synthetic (``synthetic: ...``)."""
        return any(line.strip().lower().startswith("synthetic") for line in self.comments)

    def describe(self) -> str:
        """A few lines of provenance for reports and file headers."""
        lines = [f"source: {self.path or 'in-memory table'} ({self.format}); time base {self.time_base}"]
        if self.dialect is not None:
            lines.append(f"read as {self.dialect.describe()}")
        if self.bus is not None:
            lines.append(f"bus log: {self.bus}")
        if self.synthetic:
            lines.append("synthetic data (not measured)")
        for name, o in self.channels.items():
            rate = f", {o.rate_hz:.6g} Hz" if o.rate_hz else ""
            grp = f", group {o.group}" if o.group is not None else ""
            conv = f" [{o.source_unit or '-'} -> {o.unit or '-'}]" if (o.source_unit or "") != (o.unit or "") else \
                f" [{o.unit or '-'}]"
            lines.append(f"{name} <- {o.source}{grp}{rate}{conv}")
        for what, reason in self.skipped.items():
            lines.append(f"skipped {what}: {reason}")
        return "\n".join(lines)


@dataclass(frozen=True)
class Measurement:
    """A record in clutchlab's names and units.

    Parameters
    ----------
    frame : pandas.DataFrame
        The time column first (if any), then the channels, all float and in
        the unit their name states.
    units : mapping of str to str
        Column -> unit string (pint syntax; ``""`` dimensionless or unknown).
    source : MeasurementSource
        Where the data came from.
    time_column : str or None
        Name of the time column [s] (``None`` for a table without time).
    """

    frame: pd.DataFrame
    units: Mapping[str, str]
    source: MeasurementSource
    time_column: str | None = "time_s"

    @property
    def time(self) -> np.ndarray | None:
        """Time of the samples [s] (``None`` for a table without time)."""
        return None if self.time_column is None else self.frame[self.time_column].to_numpy()

    @property
    def channels(self) -> tuple[str, ...]:
        """Column names other than the time column."""
        return tuple(c for c in self.frame.columns if c != self.time_column)

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.frame.columns:
            raise DataError(f"{self.source.path or 'record'}: no channel {name!r} "
                            f"(has: {', '.join(map(str, self.frame.columns))})")
        return self.frame[name].to_numpy()

    def __len__(self) -> int:
        return len(self.frame)

    def to_dataframe(self) -> pd.DataFrame:
        """A copy of the frame, with the units in ``frame.attrs["units"]``."""
        out = self.frame.copy()
        out.attrs["units"] = dict(self.units)
        return out


# ---------------------------------------------------------------- raw sources

class _TableReader:
    """CSV, Parquet or DataFrame: columns sharing one row index."""

    def __init__(self, frame: pd.DataFrame, label: str, fmt: str, path, units: Mapping[str, str],
                 comments: Sequence[str]):
        self.frame = frame
        self.label = label
        self.format = fmt
        self.path = path
        self.units = {str(k): v for k, v in units.items() if v is not None}
        self.comments = tuple(comments)

    def channel_names(self) -> list[str]:
        return [str(c) for c in self.frame.columns]

    def has(self, name: str) -> bool:
        return name in self.frame.columns

    def load(self, name: str, *, target: str | None = None, allow_nan: bool = False,
             skip_nonnumeric: bool = False) -> RawChannel | None:
        if name not in self.frame.columns:
            what = repr(name) + (f" (for {target!r})" if target and target != name else "")
            raise DataError(f"{self.label}: missing column {what} (has: {', '.join(map(str, self.frame.columns))})")
        col = self.frame[name]
        values = pd.to_numeric(col, errors="coerce").to_numpy(dtype=float)
        text = np.isnan(values) & col.notna().to_numpy()  # present but not a number
        if text.any() and skip_nonnumeric:
            return None
        bad = ~np.isfinite(values) if not allow_nan else text
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            value = col.iloc[row]
            value = float(value) if isinstance(value, (np.floating, np.integer)) else value
            raise DataError(f"{self.label}: column {name!r} has a non-finite or non-numeric value "
                            f"{value!r} at row {row}")
        return RawChannel(name, values, None, self.units.get(name), None)

    def close(self):
        pass


def _read_csv(path: Path, label: str, dialect=None) -> _TableReader:
    """A CSV (or other text table) in any dialect :func:`clutchlab.io.dialect.read_csv` detects."""
    table = read_csv(path, label, dialect)
    reader = _TableReader(table.frame, label, "csv", path, table.units, table.comments)
    reader.dialect = table.dialect
    return reader


def _read_parquet(path: Path, label: str) -> _TableReader:
    import pyarrow.parquet as pq

    try:
        meta = pq.read_metadata(path)
        check_allocation(meta.num_rows, max(meta.num_columns, 1), f"{label}: Parquet file of {meta.num_rows} rows")
        # page checksums (written by write_measurement) catch corrupted data pages that still decode
        table = pq.read_table(path, page_checksum_verification=True)
    except ParameterError as exc:
        raise DataError(str(exc)) from None
    except Exception as exc:  # ArrowInvalid, OSError on truncated or corrupted files
        text = " ".join(str(exc).split())
        if "checksum" in text.lower():
            raise DataError(f"{label}: corrupted Parquet file (a data page fails its checksum)") from None
        raise DataError(f"{label}: not a readable Parquet file ({type(exc).__name__}: {short_repr(text, 160)})") \
            from None
    meta = table.schema.metadata or {}
    units, comments = {}, []
    if _PARQUET_KEY in meta:
        try:
            info = json.loads(meta[_PARQUET_KEY])
            units = dict(info.get("units", {}))
            comments = [str(c) for c in info.get("comments", [])]
        except (ValueError, TypeError, AttributeError):
            raise DataError(f"{label}: the clutchlab metadata of the Parquet schema is not valid JSON") from None
    for fld in table.schema:
        fm = fld.metadata or {}
        if b"unit" in fm:
            units.setdefault(fld.name, fm[b"unit"].decode("utf-8"))
    return _TableReader(table.to_pandas(), label, "parquet", path, units, comments)


def _open(source, name: str | None, dialect=None, databases=()):
    if isinstance(source, Measurement):
        frame = source.frame
        return _TableReader(frame, name or source.source.path or "record", "frame", source.source.path,
                            dict(source.units), source.source.comments)
    if isinstance(source, pd.DataFrame):
        return _TableReader(source, name or "record", "frame", None, dict(source.attrs.get("units", {})), ())
    if not isinstance(source, (str, Path)):
        raise DataError(f"record must be a file path or a pandas.DataFrame, got {type(source).__name__}")
    path = Path(source)
    label = name or str(path)
    if not path.exists():
        raise DataError(f"{label}: no such file")
    if path.is_dir():
        raise DataError(f"{label}: is a directory, not a record file")
    suffix = path.suffix.lower()
    if suffix in MDF_SUFFIXES:
        return MdfReader(path, label, databases)
    if suffix in PARQUET_SUFFIXES:
        return _read_parquet(path, label)
    if suffix in CSV_SUFFIXES or suffix == "":
        return _read_csv(path, label, dialect)
    raise DataError(f"{label}: unknown record format {path.suffix!r} (expected "
                    f"{', '.join(CSV_SUFFIXES + PARQUET_SUFFIXES + MDF_SUFFIXES)})")


# ---------------------------------------------------------------- checks and resampling

def _check_plausible(values: np.ndarray, unit: str, label: str, what: str, sample_word: str = "sample") -> None:
    """Reject values no sensor produces: magnitude above :data:`PLAUSIBLE_MAGNITUDE`, temperature below 0 K."""
    big = np.abs(values) > PLAUSIBLE_MAGNITUDE
    if big.any():
        k = int(np.flatnonzero(big)[0])
        raise DataError(f"{label}: {what} has an implausible value {float(values[k])!r} {unit} at {sample_word} {k} "
                        f"(magnitude above {PLAUSIBLE_MAGNITUDE:g}; corrupted file?)")
    if values.size and unit:
        try:
            scale, offset = unit_conversion(unit, "K", name=what, where=label)
        except DataError:
            return  # not a temperature
        cold = values * scale + offset < -1e-9
        if cold.any():
            k = int(np.flatnonzero(cold)[0])
            raise DataError(f"{label}: {what} has a temperature below absolute zero, {float(values[k])!r} {unit} "
                            f"at {sample_word} {k}")


def _check_time(t: np.ndarray, label: str, what: str, sample_word: str) -> None:
    """Raise :class:`DataError` naming ``label``, ``what`` and the sample if ``t`` is not finite and strictly
    increasing."""
    bad = ~np.isfinite(t)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise DataError(f"{label}: {what} has a non-finite time {float(t[k])!r} at {sample_word} {k}")
    dt = np.diff(t)
    if (dt <= 0).any():
        k = int(np.flatnonzero(dt <= 0)[0]) + 1
        raise DataError(f"{label}: {what} must increase strictly, but {sample_word} {k} has {float(t[k])!r} after "
                        f"{float(t[k - 1])!r} (time not strictly increasing)")


check_time = _check_time


def resample(timestamps, samples, time_base, interpolation: str = "linear") -> np.ndarray:
    """Carry a channel from its own timestamps onto ``time_base``.

    Parameters
    ----------
    timestamps : array_like
        Sample times of the channel [s], strictly increasing.
    samples : array_like
        Channel values at ``timestamps``.
    time_base : array_like
        Times at which values are wanted [s], within
        ``[timestamps[0], timestamps[-1]]``.
    interpolation : {"linear", "previous"}
        Linear interpolation between neighbouring samples, or the last sample
        at or before each time (sample-and-hold, for states and set points).

    Returns
    -------
    ndarray
        Values at ``time_base``.
    """
    ts = np.asarray(timestamps, dtype=float)
    ys = np.asarray(samples, dtype=float)
    tb = np.asarray(time_base, dtype=float)
    if interpolation == "linear":
        return np.interp(tb, ts, ys)
    if interpolation == "previous":
        idx = np.searchsorted(ts, tb, side="right") - 1
        return ys[np.clip(idx, 0, ts.size - 1)]
    raise ParameterError(f"interpolation = {interpolation!r}; expected one of {', '.join(INTERPOLATIONS)}")


def _rate(t: np.ndarray | None) -> float | None:
    if t is None or t.size < 2 or t[-1] <= t[0]:
        return None
    return float((t.size - 1) / (t[-1] - t[0]))


# ---------------------------------------------------------------- reading

def read_measurement(source, channel_map=None, *, required: Iterable[str] = (), time: str | None = "time_s",
                     rate: float | None = None, time_base=None, interpolation: str = "linear",
                     allow_nan: Iterable[str] = (), name: str | None = None, csv=None,
                     databases=()) -> Measurement:
    """Read a record from CSV, Parquet or MDF 4 into clutchlab's names and SI units.

    Parameters
    ----------
    source : str, Path, pandas.DataFrame or Measurement
        ``.csv``/``.txt`` in any dialect rig software writes (encoding,
        separator, decimal comma, title, name and unit rows detected:
        :mod:`clutchlab.io.dialect`; ``#`` comment lines skipped, an optional
        ``# units: a=s, b=N*m`` line read), ``.parquet`` (units from the schema metadata),
        ``.mf4``/``.mdf`` (ASAM MDF, units from the channels, conversions
        applied), or an in-memory table (units from ``frame.attrs["units"]``).
    channel_map : ChannelMap, mapping, str or Path, optional
        Which channels to read and under which names (a TOML file or a
        mapping, see :class:`~clutchlab.io.channels.ChannelMap`).  Without a
        map every channel is read under its own name; a name with a unit
        suffix is converted to that unit.
    required : iterable of str
        clutchlab names that must be present (with a map: must also be
        entries of the map).
    time : str or None
        Name of the time column [s] (default ``"time_s"``).  In a CSV or
        Parquet file it is the column of that name (or the map's entry of that
        name); in an MDF file the groups' master channels.  ``None`` reads a
        table without time (an MDF file still yields ``time_s``).
    rate : float, optional
        Resample every channel onto a uniform time base with this rate [Hz],
        over the interval all channels cover.
    time_base : array_like, optional
        Resample onto these times [s] instead (strictly increasing, within
        every channel's span).  Give ``rate`` or ``time_base``, not both.
        Without either, channels sharing one time base keep it and channels of
        different rates go onto the fastest channel's timestamps within the
        interval all channels cover.
    interpolation : {"linear", "previous"}
        Default resampling method (a map entry may set its own).
    allow_nan : iterable of str
        clutchlab names in which NaN samples are allowed.
    name : str, optional
        How to call the source in error messages (default: the path).
    csv : CsvDialect or mapping, optional
        How a text table is written (``encoding``, ``separator``, ``decimal``,
        ``header_row``, ``units_row``, ``thousands``); the fields not given
        are detected (:mod:`clutchlab.io.dialect`), and what was read is in
        ``result.source.dialect``.  Fields given here win over the channel
        map's ``[csv]`` table.
    databases : iterable of str, Path or BusDatabase
        Bus databases (DBC, ARXML; CAN unless a :class:`BusDatabase` says
        LIN) decoding the raw frames of an MDF bus log into signals, which
        are then read like any channel (by their signal names); added to the
        channel map's ``[bus]`` databases.  What was decoded is in
        ``result.source.bus``.

    Returns
    -------
    Measurement
        The frame (time first), its units and its provenance.

    Raises
    ------
    DataError
        Missing or unreadable file, unknown format, missing or ambiguous
        channel, unknown unit or unit of the wrong dimension, non-numeric or
        NaN sample, time not strictly increasing, channels without common time
        span -- each naming the file and the channel.
    ParameterError
        Invalid channel map, ``interpolation``, ``rate`` or ``time_base``.
    """
    cmap = ChannelMap.coerce(channel_map)
    required = [str(r) for r in required]
    allow_nan = set(allow_nan)
    if interpolation not in INTERPOLATIONS:
        raise ParameterError(f"interpolation = {interpolation!r}; expected one of {', '.join(INTERPOLATIONS)}")
    if rate is not None and time_base is not None:
        raise ParameterError("give rate or time_base, not both")
    if rate is not None:
        number = isinstance(rate, (int, float, np.number)) and not isinstance(rate, bool)
        if not (number and np.isfinite(rate) and rate > 0):
            raise ParameterError(f"rate = {rate!r} Hz: must be a positive number")
        rate = float(rate)
    if cmap is not None:
        unmapped = [r for r in required if r not in cmap and r != time]
        if unmapped:
            raise ParameterError(f"{cmap.name}: required channel {unmapped[0]!r} is not in the channel map "
                                 f"(has: {', '.join(cmap.names)})")

    dialect = CsvDialect.coerce(csv, "csv")
    if cmap is not None and cmap.csv is not None:
        dialect = cmap.csv.merged(dialect)
    if isinstance(databases, (str, Path, BusDatabase)):
        databases = [databases]
    buses = list(cmap.bus if cmap is not None else ()) + [BusDatabase.coerce(d) for d in databases]
    reader = _open(source, name, dialect, buses)
    try:
        return _read(reader, cmap, required, time, rate, time_base, interpolation, allow_nan)
    finally:
        reader.close()


def _has(reader, spec_or_name) -> bool:
    """True if the reader has the channel (an MDF spec: at its group and index, if given)."""
    if not isinstance(spec_or_name, ChannelSpec):
        return reader.has(spec_or_name)
    if isinstance(reader, MdfReader):
        return reader.has(spec_or_name.source, spec_or_name.group, spec_or_name.index)
    return reader.has(spec_or_name.source)


def _dimensionless(unit: str) -> bool:
    try:
        unit_conversion(unit, "", name="", error=DataError)
    except DataError:
        return False
    return True


def _table_time(reader, time: str, time_spec: ChannelSpec | None) -> np.ndarray:
    """The time column of a table, converted to s and checked."""
    tsrc = time_spec.source if time_spec is not None else time
    traw = reader.load(tsrc, target=time)
    tunit = (time_spec.source_unit if time_spec is not None else None) or traw.unit or canonical_unit(tsrc) or "s"
    scale, offset = unit_conversion(tunit, "s", name=tsrc, where=reader.label)
    t = traw.samples * scale + offset
    _check_time(t, reader.label, time if tsrc == time else f"{tsrc} (time)", "row")
    try:
        _check_plausible(t, "s", reader.label, f"time column {tsrc!r}", "row")
    except DataError as exc:
        raise DataError(f"{exc}; if it is a UNIX time in ns, us or ms, state the unit (a '# units: {tsrc}=ns' "
                        "line, or source_unit in a channel map)") from None
    return t


def _group_list(groups: list[int]) -> str:
    """``group 3`` or ``groups 0-60, 64`` (runs of consecutive numbers joined)."""
    runs: list[list[int]] = []
    for g in groups:
        if runs and g == runs[-1][1] + 1:
            runs[-1][1] = g
        else:
            runs.append([g, g])
    text = ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in runs)
    return f"group{'s' if len(groups) > 1 else ''} {text}"


def _mdf_identity(reader: MdfReader, required, time, skipped: dict[str, str]) -> list[ChannelSpec]:
    """Channels of an identity read of an MDF file; raw bus frames and ambiguous names go to ``skipped``."""
    if reader.bus_groups and reader.decoding is None:
        bus = sorted(reader.bus_groups)
        names = sorted({n for n in reader.channel_names() if set(reader.groups_of(n)) & reader.bus_groups})
        shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
        skipped[_group_list(bus)] = (f"raw bus frames ({shown}), not signals; decode them with a DBC or ARXML "
                                     "file (--dbc, [bus] in a channel map, databases=) or map their fields "
                                     "explicitly")
    specs = []
    for n in reader.channel_names():
        if n == time:
            continue
        places = reader.places(n)
        if n not in required:
            if not n.strip():
                skipped[repr(n)] = "a channel without name"
                continue
            if all(p.group in reader.bus_groups for p in places):
                continue  # reported per group above
            if len(places) > 1:
                skipped[n] = (f"occurs {len(places)} times ({'; '.join(p.describe() for p in places)}); "
                              "map it with group and index")
                continue
        specs.append(ChannelSpec(n, unit=canonical_unit(n) or "", optional=n not in required))
    return specs


def _source_units(spec: ChannelSpec, raw: RawChannel, label: str, identity: bool) -> tuple[str, str, float, float]:
    """(source unit, target unit, scale, offset) of one channel, or a DataError."""
    src_unit = spec.source_unit or raw.unit or canonical_unit(spec.source)
    target_unit = spec.unit
    if identity and not target_unit:
        # a name without unit suffix: keep the file's unit, in pint spelling ("-", "[-]" -> "1")
        target_unit = normalise_unit(raw.unit) or ("1" if raw.unit else "")
    if src_unit is None:
        if spec.source == spec.name or _dimensionless(target_unit):
            src_unit = target_unit  # no unit in the file: the clutchlab name's (or a pure number) taken as is
        else:
            raise DataError(f"{label}: channel {spec.source!r} (for {spec.name!r}) carries no unit; "
                            f"give source_unit in the channel map")
    scale, offset = unit_conversion(src_unit, target_unit, name=spec.source, where=label)
    return src_unit, target_unit, scale, offset


def _read(reader, cmap, required, time, rate, time_base, interpolation, allow_nan) -> Measurement:
    label = reader.label
    is_mdf = isinstance(reader, MdfReader)
    if is_mdf and time is None:
        time = "time_s"  # an MDF file always has a time base
    if isinstance(reader, _TableReader) and reader.path is not None and len(reader.frame) == 0:
        raise DataError(f"{label}: no samples (the file has column names but no data rows)")
    skipped: dict[str, str] = {}
    if cmap is None:
        for r in required:
            if r != time and not _has(reader, r):
                reader.load(r, target=r)  # raises the reader's "missing channel/column" error
        if is_mdf:
            specs = _mdf_identity(reader, required, time, skipped)
        else:
            specs = [ChannelSpec(n, unit=canonical_unit(n) or "", optional=n not in required)
                     for n in reader.channel_names() if n != time]
        # channels nobody asked for: skipped (with the reason in the provenance) if they cannot be converted
        lenient = {s.name for s in specs if s.optional}
    else:
        specs = list(cmap)
        lenient = set()
    time_spec = next((s for s in specs if s.name == time), None)
    specs = [s for s in specs if s.name != time]
    if not is_mdf and time_spec is not None and (time_spec.group is not None or time_spec.index is not None):
        raise ParameterError(f"channel map entry {time!r}: group and index only apply to MDF files")

    # ---- channels as stored, checked, with their unit conversion
    table_t = _table_time(reader, time, time_spec) if (not is_mdf and time is not None) else None
    raws: dict[str, RawChannel] = {}
    conversions: dict[str, tuple[str, str, float, float]] = {}
    used: list[ChannelSpec] = []
    for spec in specs:
        if spec.optional and not _has(reader, spec):
            continue
        nan_ok = spec.name in allow_nan or spec.name in lenient
        try:
            if is_mdf:
                raw = reader.load(spec.source, spec.group, spec.index, target=spec.name,
                                  skip_nonnumeric=spec.name in lenient)
                if raw is None:
                    skipped[spec.source] = "non-numeric samples (text, structures or arrays)"
                    continue
                bad = ~np.isfinite(raw.samples)
                if bad.any() and not nan_ok:
                    k = int(np.flatnonzero(bad)[0])
                    raise DataError(f"{label}: channel {spec.source!r} (group {raw.group}) has a non-finite value "
                                    f"{float(raw.samples[k])!r} at sample {k} (t = {float(raw.timestamps[k])!r} s)")
                _check_time(raw.timestamps, label, f"timestamps of channel {spec.source!r} (group {raw.group})",
                            "sample")
            else:
                if spec.group is not None or spec.index is not None:
                    raise ParameterError(f"channel map entry {spec.name!r}: group and index only apply to MDF "
                                         f"files, but {label} is a {reader.format} table")
                raw = reader.load(spec.source, target=spec.name, allow_nan=nan_ok,
                                  skip_nonnumeric=spec.name in lenient)
                if raw is None:
                    continue  # a text column of an identity read: passed through below
                raw.timestamps = table_t
            conversions[spec.name] = _source_units(spec, raw, label, cmap is None)
        except DataError as exc:
            if spec.name not in lenient:
                raise
            reason = str(exc)
            for prefix in (f"{label}: ", f"channel {spec.source!r}: "):
                reason = reason[len(prefix):] if reason.startswith(prefix) else reason
            skipped[spec.source] = reason
            continue
        raws[spec.name] = raw
        used.append(spec)

    if not used and skipped:
        what, reason = next(iter(skipped.items()))
        raise DataError(f"{label}: no channel could be read ({len(skipped)} skipped; {what}: {reason})")

    # ---- one time base
    resampled = False
    how = "as recorded"
    if time is None:
        timeline = None
        how = "no time column"
        if rate is not None or time_base is not None:
            raise ParameterError(f"{label}: resampling needs a time column, but time=None")
    else:
        stamps = [raws[s.name].timestamps for s in used] or ([table_t] if table_t is not None else [])
        if not stamps:
            raise DataError(f"{label}: no numeric channels to read")
        same = all(ts is stamps[0] or (ts.size == stamps[0].size and np.array_equal(ts, stamps[0])) for ts in stamps)
        t_lo = max(float(ts[0]) for ts in stamps)
        t_hi = min(float(ts[-1]) for ts in stamps)
        if time_base is not None:
            timeline = np.asarray(time_base, dtype=float)
            if timeline.ndim != 1 or timeline.size == 0:
                raise ParameterError(f"time_base: expected a non-empty 1-D array, got shape {timeline.shape}")
            try:
                _check_time(timeline, "time_base", "time_base", "element")
            except DataError as exc:
                raise ParameterError(str(exc)) from None
            for spec in used:
                ts = raws[spec.name].timestamps
                if timeline[0] < ts[0] - 1e-12 or timeline[-1] > ts[-1] + 1e-12:
                    raise DataError(f"{label}: time_base [{float(timeline[0])!r}, {float(timeline[-1])!r}] s "
                                    f"exceeds the span of "
                                    f"channel {spec.source!r} [{float(ts[0])!r}, {float(ts[-1])!r}] s")
            resampled, how = True, f"given time base ({timeline.size} points)"
        elif rate is not None or not same:
            if not t_hi > t_lo:
                spans = ", ".join(f"{s.source} [{raws[s.name].timestamps[0]:g}, {raws[s.name].timestamps[-1]:g}] s"
                                  for s in used)
                raise DataError(f"{label}: the channels share no common time span ({spans})")
            if rate is not None:
                check_allocation((t_hi - t_lo) * rate + 1, len(used) + 1,
                                 f"{label}: rate = {rate:g} Hz over {t_hi - t_lo:g} s")
                n = int(np.floor((t_hi - t_lo) * rate * (1 + 1e-12))) + 1
                if n < 2:
                    raise ParameterError(f"{label}: rate = {rate:g} Hz gives a single sample over the "
                                         f"{t_hi - t_lo:g} s of the record; need at least 2")
                timeline = t_lo + np.arange(n) / rate
                how = f"resampled at {rate:g} Hz over [{t_lo:g}, {t_hi:g}] s"
            else:
                fastest = max(used, key=lambda s: _rate(raws[s.name].timestamps) or 0.0)
                ts = raws[fastest.name].timestamps
                timeline = ts[(ts >= t_lo) & (ts <= t_hi)]
                how = (f"resampled onto the timestamps of {fastest.source!r} ({_rate(ts):.6g} Hz) over "
                       f"[{t_lo:g}, {t_hi:g}] s")
            resampled = True
        else:
            timeline = stamps[0]

    # ---- units, resampling, assembly
    columns: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    origins: dict[str, ChannelOrigin] = {}
    if timeline is not None:
        columns[time] = np.array(timeline, dtype=float)
        units[time] = "s"
    for spec in used:
        raw = raws[spec.name]
        src_unit, target_unit, scale, offset = conversions[spec.name]
        grp = f" (group {raw.group})" if raw.group is not None else ""
        try:
            with np.errstate(over="ignore"):   # an overflow to inf is what the check reports
                converted = raw.samples * scale + offset if (scale != 1.0 or offset != 0.0) else raw.samples
            _check_plausible(converted, target_unit, label, f"channel {spec.source!r}{grp}",
                             "row" if raw.group is None else "sample")
        except DataError as exc:
            if spec.name not in lenient:
                raise
            # a channel nobody asked for with values no sensor gives (a UNIX time in ns, an overflow to inf in
            # the conversion): left out with the reason, the rest of the file is read (#33)
            skipped[spec.source] = str(exc).removeprefix(f"{label}: channel {spec.source!r}{grp} has ")
            continue
        values = raw.samples
        method = None
        if resampled:
            method = spec.interpolation or interpolation
            values = resample(raw.timestamps, values, timeline, method)
        columns[spec.name] = values * scale + offset if (scale != 1.0 or offset != 0.0) else np.array(values)
        units[spec.name] = target_unit
        origins[spec.name] = ChannelOrigin(spec.source, src_unit, target_unit, raw.group, int(raw.samples.size),
                                           _rate(raw.timestamps), method)
    if not origins and skipped:
        what, reason = next(iter(skipped.items()))
        raise DataError(f"{label}: no channel could be read ({len(skipped)} skipped; {what}: {reason})")
    frame = pd.DataFrame(columns)
    if isinstance(reader, _TableReader) and cmap is None:
        # identity read of a table: other (non-numeric) columns pass through untouched, in the file's order
        for c in reader.frame.columns:
            if c not in frame.columns and c not in skipped:
                frame[c] = reader.frame[c].to_numpy()
        order = [c for c in reader.frame.columns if c in frame.columns]
        if time is not None:
            order = [time] + [c for c in order if c != time]
        frame = frame.loc[:, order]
    if is_mdf:
        comments = tuple(line.strip() for line in reader.comment.splitlines() if line.strip())
        path = str(reader.path)
    else:
        comments = reader.comments
        path = None if reader.path is None else str(reader.path)
    src = MeasurementSource(path, "mdf" if is_mdf else reader.format, comments, origins, how, skipped,
                            getattr(reader, "dialect", None), getattr(reader, "decoding", None))
    return Measurement(frame.reset_index(drop=True), units, src, time if timeline is not None else None)


# ---------------------------------------------------------------- writing

def _units_for(frame: pd.DataFrame, units: Mapping[str, str] | None) -> dict[str, str]:
    given = dict(frame.attrs.get("units", {}))
    given.update(units or {})
    out = {}
    for c in frame.columns:
        u = given.get(c)
        if u is None:
            u = canonical_unit(str(c))
        out[str(c)] = "" if u is None else str(u)
    return out


def write_measurement(data, path, *, units: Mapping[str, str] | None = None, comment: str | None = None,
                      time: str | None = None, overwrite: bool = False) -> Path:
    """Write a record as CSV, Parquet or MDF 4 (by the suffix of ``path``), with units, atomically.

    Parameters
    ----------
    data : Measurement or pandas.DataFrame
        The record.  A Measurement keeps its units and its header comments
        (``synthetic: ...`` lines stay).
    path : str or Path
        ``.csv``: ``#`` comment lines, then ``# units: name=unit, ...``, then
        the table.  ``.parquet``: units in the schema metadata (per field and
        as JSON under the key ``clutchlab``).  ``.mf4``: one channel group,
        every column a channel with its unit, the comment in the header.
    units : mapping of str to str, optional
        Units of columns (default: those of the Measurement, of
        ``frame.attrs["units"]``, or the unit the column name states).
    comment : str, optional
        Provenance lines appended to the header.
    time : str, optional
        Time column [s] (default: the Measurement's, else ``"time_s"``); an
        MDF file needs one.
    overwrite : bool
        Replace an existing file.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    FileExistsError
        ``path`` exists and ``overwrite`` is false.
    DataError
        Unknown suffix, no time column for MDF, non-numeric column for MDF.
    """
    if isinstance(data, Measurement):
        frame = data.frame
        all_units = dict(data.units)
        all_units.update(units or {})
        comments = list(data.source.comments)
        time = time or data.time_column
    elif isinstance(data, pd.DataFrame):
        frame = data
        all_units = units
        comments = []
        time = time or "time_s"
    else:
        raise DataError(f"write_measurement: expected a Measurement or a pandas.DataFrame, got {type(data).__name__}")
    if comment:
        comments.extend(line for line in str(comment).splitlines())
    col_units = _units_for(frame, all_units)
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in CSV_SUFFIXES:
        header = "\n".join(comments + [_UNITS_PREFIX + " " + ", ".join(f"{k}={v}" for k, v in col_units.items())])
        return atomic_to_csv(frame, path, overwrite=overwrite, header_comment=header)
    if suffix in PARQUET_SUFFIXES:
        import pyarrow as pa
        import pyarrow.parquet as pq

        check_writable(path, overwrite)
        table = pa.Table.from_pandas(frame, preserve_index=False)
        fields = [f.with_metadata({b"unit": col_units.get(f.name, "").encode("utf-8")}) for f in table.schema]
        meta = dict(table.schema.metadata or {})
        meta[_PARQUET_KEY] = json.dumps({"units": col_units, "comments": comments}).encode("utf-8")
        table = table.cast(pa.schema(fields, metadata=meta))
        buf = io.BytesIO()
        pq.write_table(table, buf, write_page_checksum=True)
        return atomic_write_bytes(path, buf.getvalue(), overwrite=overwrite)
    if suffix in MDF_SUFFIXES:
        if time is None or time not in frame.columns:
            raise DataError(f"{path}: an MDF file needs a time column; {time!r} is not one of "
                            f"{', '.join(map(str, frame.columns))}")
        t = pd.to_numeric(frame[time], errors="coerce").to_numpy(dtype=float)
        _check_time(t, str(path), time, "row")
        channels = {}
        for c in frame.columns:
            if c == time:
                continue
            values = pd.to_numeric(frame[c], errors="coerce").to_numpy(dtype=float)
            if (np.isnan(values) & frame[c].notna().to_numpy()).any():
                raise DataError(f"{path}: column {c!r} is not numeric; MDF channels must be")
            channels[str(c)] = values
        return write_mdf(path, t, channels, col_units, comment="\n".join(comments), overwrite=overwrite)
    raise DataError(f"{path}: unknown record format {path.suffix!r} (expected "
                    f"{', '.join(CSV_SUFFIXES + PARQUET_SUFFIXES + MDF_SUFFIXES)})")
