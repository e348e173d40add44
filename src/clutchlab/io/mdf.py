"""ASAM MDF 4 files through :mod:`asammdf`: open defensively, pick channels, write with units.

Only :mod:`clutchlab.io.measurements` calls these functions; users read and
write MDF files with :func:`~clutchlab.io.read_measurement` and
:func:`~clutchlab.io.write_measurement`.  :mod:`asammdf` is imported lazily.
"""

from __future__ import annotations

import io
import logging
import os
import re
import shutil
import tempfile
import warnings
from contextlib import contextmanager, redirect_stderr, redirect_stdout
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DataError, ParameterError
from .files import check_writable, temporary_sibling

__all__ = ["MDF_SUFFIXES", "UNFINALISED_ID", "BUS_TYPES", "BusDatabase", "RawChannel", "ChannelPlace", "MdfReader",
           "write_mdf"]

#: file name endings read and written as MDF
MDF_SUFFIXES = (".mf4", ".mdf")


@dataclass
class RawChannel:
    """One channel as stored in a file, before unit conversion and resampling.

    Attributes
    ----------
    name : str
        Name in the file.
    samples : ndarray
        Physical values (the file's conversion applied) [source unit].
    timestamps : ndarray or None
        Time of each sample [s]; ``None`` for tables without time.
    unit : str or None
        Unit stored in the file (``None`` if the file stores none).
    group : int or None
        MDF data group (``None`` for tables).
    index : int or None
        Channel index within the MDF group (``None`` for tables).
    """

    name: str
    samples: np.ndarray
    timestamps: np.ndarray | None
    unit: str | None
    group: int | None = None
    index: int | None = None


#: first bytes of an MDF 4 file a logger has not finalised (ASAM MDF 4.1, IDBLOCK id_file)
UNFINALISED_ID = b"UnFinMF "
#: MDF 4.1 channel-group flag of bus-event groups (raw CAN/LIN/FlexRay/Ethernet frames), cg_flags bit 1
_CG_BUS_EVENT = 1 << 1
#: structure channels of raw bus frames (ASAM MDF bus logging; fields follow as ``CAN_DataFrame.ID`` ...),
#: for groups written without the bus-event flag
_BUS_FRAMES = frozenset({"CAN_DataFrame", "CAN_RemoteFrame", "CAN_ErrorFrame", "CAN_OverloadFrame",
                         "LIN_Frame", "LIN_ChecksumError", "LIN_ReceiveError", "LIN_SyncError",
                         "LIN_TransmissionError", "FLX_Frame", "FLX_NullFrame", "FLX_StartCycle", "ETH_Frame"})


class _Captured:
    """What asammdf logged, printed or warned while a block of code ran (kept, never shown)."""

    def __init__(self):
        self.lines: list[str] = []

    def last(self) -> str:
        """The last captured line that says something (empty if none)."""
        for line in reversed(self.lines):
            if line.strip() and not line.startswith(("Traceback", "  ")):
                return " ".join(line.split())
        return ""


class _ListHandler(logging.Handler):
    def __init__(self, sink: _Captured):
        super().__init__(logging.DEBUG)
        self.sink = sink

    def emit(self, record):
        try:
            self.sink.lines.append(record.getMessage())
        except Exception:  # a record that cannot be formatted is not worth a second failure
            pass


@contextmanager
def _quiet_asammdf():
    """Keep asammdf's logging, prints and warnings away from the user's terminal.

    asammdf logs an ERROR before raising for ambiguous names and prints a
    traceback to stdout when it fails to finalise a file; clutchlab raises its
    own one-line :class:`~clutchlab.errors.DataError` instead.  The captured
    lines are yielded, for the message of that error.
    """
    sink = _Captured()
    log = logging.getLogger("asammdf")
    handler = _ListHandler(sink)
    saved = (log.level, log.propagate, log.handlers[:])
    log.handlers[:] = [handler]
    log.setLevel(logging.DEBUG)
    log.propagate = False
    out, err = io.StringIO(), io.StringIO()
    try:
        with warnings.catch_warnings(record=True) as caught, redirect_stdout(out), redirect_stderr(err):
            warnings.simplefilter("always")
            yield sink
    finally:
        log.setLevel(saved[0])
        log.propagate = saved[1]
        log.handlers[:] = saved[2]
        sink.lines.extend(out.getvalue().splitlines() + err.getvalue().splitlines())
        sink.lines.extend(str(w.message) for w in caught)


def _one_line(exc: BaseException, limit: int = 160) -> str:
    text = " ".join(str(exc).split())
    if len(text) > limit:
        text = text[:limit - 3] + "..."
    kind = type(exc).__name__
    if kind == "error":  # struct.error, zlib.error: say whose
        kind = f"{type(exc).__module__.lstrip('_')}.{kind}"
    return f"{kind}: {text}" if text else kind


def _defuse(exc: BaseException) -> None:
    """Stop half-built asammdf objects from failing again when collected.

    A constructor that raises leaves an object whose ``__del__`` calls
    ``close()`` on attributes never set, which prints an "Exception ignored"
    traceback at some later garbage collection.  The objects are found in the
    traceback's frames and given a no-op ``close``.
    """
    tb = exc.__traceback__
    while tb is not None:
        obj = tb.tb_frame.f_locals.get("self")
        if obj is not None and type(obj).__module__.startswith("asammdf") and hasattr(obj, "close"):
            try:
                obj.close = lambda: None
            except (AttributeError, TypeError):  # an object with __slots__: nothing to patch
                pass
        tb = tb.tb_next


def _unfinalised_flags(head: bytes) -> int | None:
    """Standard "unfinalised" flags of an MDF >= 4.10 identification block, ``None`` if finalised.

    Parameters
    ----------
    head : bytes
        The first 64 bytes of the file (the IDBLOCK: ``id_file`` char[8],
        ``id_vers`` char[8], ``id_prog`` char[8], reserved, ``id_ver`` uint16,
        reserved, ``id_unfin_flags`` uint16 at byte 60, ``id_custom_unfin_flags``
        uint16 at byte 62; ASAM MDF 4.1, IDBLOCK).
    """
    if len(head) < 64:
        return None
    version = head[8:16].decode("ascii", "replace").strip(" \0\t\r\n")
    flags = int.from_bytes(head[60:62], "little")
    if version >= "4.10" and (flags or head[:8] == UNFINALISED_ID):
        return flags
    return None


def _plain_comment(text, limit: int = 40) -> str:
    """First line of a channel comment, the text of an XML ``<CNcomment><TX>`` block if it is one."""
    text = str(text or "").strip()
    if text.startswith("<"):
        tx = re.search(r"<TX>(.*?)</TX>", text, re.S)
        text = tx.group(1) if tx else re.sub(r"<[^>]*>", " ", text)
    lines = [" ".join(line.split()) for line in text.splitlines() if line.strip()]
    return lines[0][:limit] if lines else ""


@dataclass(frozen=True)
class ChannelPlace:
    """Where a channel name occurs in an MDF file.

    Attributes
    ----------
    group : int
        Data group.
    index : int
        Channel index within the group (asammdf's numbering; the master is
        usually 0).
    unit : str
        Unit field (``""`` if none).
    comment : str
        Channel comment (first line, shortened).
    """

    group: int
    index: int
    unit: str
    comment: str

    def describe(self) -> str:
        """``group 1 index 3 [Nm] 'clutch torque'``."""
        text = f"group {self.group} index {self.index} [{self.unit or '-'}]"
        return text + (f" {self.comment!r}" if self.comment else "")


#: bus types asammdf's bus-logging extraction decodes, and the database formats canmatrix reads for them
BUS_TYPES = ("CAN", "LIN")
DATABASE_SUFFIXES = (".dbc", ".arxml", ".kcd", ".sym", ".ldf", ".xml")


@dataclass(frozen=True)
class BusDatabase:
    """A bus database (DBC, ARXML, ...) that decodes the raw frames of an MDF bus log into signals.

    Parameters
    ----------
    path : str or Path
        The database file (``.dbc``, ``.arxml``, ``.kcd``, ``.sym``; ``.ldf`` for LIN).
    bus : {"CAN", "LIN"}
        Bus type of the frames it decodes.
    channel : int
        Bus channel it applies to (the frames' ``BusChannel``); 0 for every channel.
    """

    path: Path
    bus: str = "CAN"
    channel: int = 0

    def __post_init__(self):
        if not isinstance(self.path, (str, Path)) or not str(self.path):
            raise ParameterError(f"bus database = {self.path!r}: expected a file path")
        object.__setattr__(self, "path", Path(self.path))
        bus = self.bus.upper() if isinstance(self.bus, str) else self.bus
        if bus not in BUS_TYPES:
            raise ParameterError(f"bus database {self.path}: bus = {self.bus!r}, expected one of "
                                 f"{', '.join(BUS_TYPES)}")
        object.__setattr__(self, "bus", bus)
        if isinstance(self.channel, bool) or not isinstance(self.channel, int) or self.channel < 0:
            raise ParameterError(f"bus database {self.path}: channel = {self.channel!r} must be a bus channel "
                                 "number (0 for every channel)")

    @classmethod
    def coerce(cls, value, base: Path | None = None, bus: str = "CAN") -> "BusDatabase":
        """A path, ``{"file": ..., "channel": ...}`` (a TOML table) or a BusDatabase; relative paths from ``base``."""
        if isinstance(value, BusDatabase):
            return value
        if isinstance(value, (str, Path)):
            path, channel = value, 0
        elif isinstance(value, dict):
            unknown = [k for k in value if k not in ("file", "channel")]
            if unknown or "file" not in value:
                raise ParameterError(f"bus database {value!r}: expected a file name or a table with 'file' and "
                                     "optionally 'channel'")
            path, channel = value["file"], value.get("channel", 0)
        else:
            raise ParameterError(f"bus database = {value!r}: expected a file name or a table with 'file'")
        if not isinstance(path, (str, Path)):
            raise ParameterError(f"bus database file = {path!r}: expected a file name")
        path = Path(path)
        if base is not None and not path.is_absolute():
            path = base / path
        return cls(path, bus, channel)

    def load(self):
        """The database as a :class:`canmatrix.CanMatrix`, or a :class:`DataError` naming the file."""
        if not self.path.is_file():
            raise DataError(f"{self.path}: no such bus database file")
        if self.path.suffix.lower() not in DATABASE_SUFFIXES:
            raise DataError(f"{self.path}: unknown bus database format {self.path.suffix!r} (expected "
                            f"{', '.join(DATABASE_SUFFIXES)})")
        try:
            import canmatrix.formats

            with _quiet_asammdf():
                matrix = canmatrix.formats.loadp_flat(str(self.path))
        except Exception as exc:   # canmatrix raises assorted parser errors
            raise DataError(f"{self.path}: cannot read the bus database ({_one_line(exc)})") from None
        if matrix is None or not matrix.frames:
            raise DataError(f"{self.path}: the bus database defines no messages")
        return matrix


class MdfReader:
    """An open MDF file: its channel names, groups, header comment, and channel access.

    Unfinalised MDF 4.1x files (as CAN loggers leave them: identification
    ``UnFinMF``, cycle counters or the last data block's length not yet
    written) are copied to an anonymous temporary file that asammdf finalises;
    the user's file is only ever read.  asammdf's logging, prints and warnings
    are captured; every failure is one :class:`~clutchlab.errors.DataError`.

    Parameters
    ----------
    path : str or Path
        The ``.mf4`` (or ``.mdf``) file.
    label : str
        How to call the file in error messages.
    databases : iterable of BusDatabase, optional
        Bus databases decoding the raw CAN/LIN frames of a bus log into
        signals (asammdf's bus-logging extraction, canmatrix's parsers): the
        decoded signals become channels beside the file's own, in groups
        numbered after them, and :attr:`decoding` says what was decoded.

    Raises
    ------
    DataError
        Missing file, not an MDF file, truncated, unfinalised beyond repair or
        otherwise unreadable; an unreadable bus database.
    """

    def __init__(self, path, label: str, databases=()):
        from asammdf import MDF

        self.path = Path(path)
        self.label = label
        if not self.path.exists():
            raise DataError(f"{label}: no such file")
        # open through a file object: asammdf then never leaves a half-built object that complains when collected
        try:
            self._fh = open(self.path, "rb")
        except OSError as exc:
            raise DataError(f"{label}: cannot open ({exc.strerror or type(exc).__name__})") from None
        head = self._fh.read(64)
        self._fh.seek(0)
        if not head.startswith((b"MDF", UNFINALISED_ID)):
            self._fh.close()
            shown = "it is empty" if not head else f"it starts with {head[:8]!r}, not b'MDF     '"
            raise DataError(f"{label}: not a readable MDF file ({shown})")
        self.unfinalised_flags = _unfinalised_flags(head)
        if self.unfinalised_flags:
            # asammdf finalises in place: give it a writable copy, never the user's file
            copy = tempfile.TemporaryFile(prefix="clutchlab-unfinalised-", suffix=".mf4")
            try:
                shutil.copyfileobj(self._fh, copy, 1 << 20)
                copy.seek(0)
            except OSError as exc:
                copy.close()
                self._fh.close()
                raise DataError(f"{label}: unfinalised MDF file, and no room to finalise a temporary copy "
                                f"({exc.strerror or type(exc).__name__})") from None
            self._fh.close()
            self._fh = copy
        try:
            with _quiet_asammdf():
                self._mdf = MDF(self._fh)
        except Exception as exc:  # asammdf raises MdfException, ValueError, struct.error ... on damaged files
            _defuse(exc)
            self._fh.close()
            if self.unfinalised_flags:
                raise DataError(f"{label}: unfinalised MDF file (flags 0x{self.unfinalised_flags:02x}) that asammdf "
                                f"cannot finalise ({_one_line(exc)})") from None
            raise DataError(f"{label}: not a readable MDF file ({_one_line(exc)})") from None
        groups = self._mdf.groups
        self.bus_groups = {g for g, grp in enumerate(groups)
                           if getattr(grp.channel_group, "flags", 0) & _CG_BUS_EVENT
                           or any(ch.name.split(".", 1)[0] in _BUS_FRAMES for ch in grp.channels)}
        #: (asammdf MDF, number of its first group): the file, then the signals decoded from its bus frames
        self._parts = [(self._mdf, 0)]
        #: what the bus databases decoded (one line), or None without databases
        self.decoding: str | None = None
        databases = list(databases or ())
        if databases:
            try:
                self._decode(databases)
            except BaseException:
                self.close()
                raise
        self._masters = set()
        self._occurrences: dict[str, list[tuple[int, int]]] = {}
        for mdf, first in self._parts:
            self._masters |= {(first + g, i) for g, i in mdf.masters_db.items()}
            for name, entries in mdf.channels_db.items():
                for g, i in entries:
                    g += first
                    if (g, i) not in self._masters and (g, i) not in self._occurrences.get(name, []):
                        self._occurrences.setdefault(name, []).append((g, i))
        for places in self._occurrences.values():
            places.sort()

    def _decode(self, databases) -> None:
        """Decode the raw bus frames with ``databases`` (asammdf ``extract_bus_logging``) into a second part."""
        names = ", ".join(d.path.name + (f" (channel {d.channel})" if d.channel else "") for d in databases)
        matrices = [(d, d.load()) for d in databases]
        if not self.bus_groups:
            self.decoding = f"no raw bus frames in the file to decode with {names}"
            return
        files = {}
        for d, _ in matrices:
            files.setdefault(d.bus, []).append((str(d.path), d.channel))
        try:
            with _quiet_asammdf():
                decoded = self._mdf.extract_bus_logging(database_files=files)
        except Exception as exc:   # asammdf/canmatrix errors on odd frames or databases
            _defuse(exc)
            raise DataError(f"{self.label}: cannot decode the bus frames with {names} ({_one_line(exc)})") from None
        info = getattr(self._mdf, "last_call_info", None) or {}
        found, unknown = [], set()
        for bus in files:
            part = info.get(bus, {}) or {}
            for entries in (part.get("found_ids") or {}).values():
                for ident, message in entries:
                    number = ident[0] if isinstance(ident, tuple) else ident
                    found.append(f"{message} 0x{int(number):X}")
            unknown |= {u[0] if isinstance(u, tuple) else u for u in (part.get("unknown_ids") or ())}
        found = sorted(set(found))
        if decoded.groups:
            self._parts.append((decoded, len(self._mdf.groups)))
        else:
            decoded.close()
        text = (f"{len(found)} message{'s' if len(found) != 1 else ''} decoded with {names}"
                + (f": {', '.join(found[:8])}{', ...' if len(found) > 8 else ''}" if found else ""))
        if unknown:
            ids = sorted(int(u) for u in unknown)
            shown = ", ".join(f"0x{u:X}" for u in ids[:8]) + (", ..." if len(ids) > 8 else "")
            text += f"; {len(ids)} ID{'s' if len(ids) != 1 else ''} of the log in no database: {shown}"
        self.decoding = text

    def close(self) -> None:
        """Close the file (and delete a temporary finalised copy)."""
        try:
            with _quiet_asammdf():
                for mdf, _ in getattr(self, "_parts", [(self._mdf, 0)]):
                    mdf.close()
        finally:
            self._fh.close()

    def _part(self, g: int):
        """(asammdf MDF, group number within it) of the reader's group ``g``."""
        for mdf, first in reversed(self._parts):
            if g >= first:
                return mdf, g - first
        raise IndexError(g)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @property
    def comment(self) -> str:
        """The header comment (plain text)."""
        try:
            with _quiet_asammdf():
                return str(self._mdf.header.description or "")
        except Exception:  # an odd XML comment is not worth failing a read
            return ""

    def channel_names(self) -> list[str]:
        """Names of the non-master channels, in file order (each name once)."""
        return list(self._occurrences)

    def groups_of(self, name: str) -> list[int]:
        """Data groups in which the channel ``name`` occurs."""
        return sorted({g for g, _ in self._occurrences.get(name, [])})

    def places(self, name: str) -> list[ChannelPlace]:
        """Every (group, index) at which the non-master channel ``name`` occurs, with unit and comment."""
        out = []
        for g, i in self._occurrences.get(name, []):
            mdf, local = self._part(g)
            ch = mdf.groups[local].channels[i]
            comment = _plain_comment(getattr(ch, "comment", ""))
            out.append(ChannelPlace(g, i, str(getattr(ch, "unit", "") or "").strip(), comment))
        return out

    def has(self, name: str, group: int | None = None, index: int | None = None) -> bool:
        """True if ``name`` occurs (in ``group``, at ``index`` if given)."""
        return any((group is None or g == group) and (index is None or i == index)
                   for g, i in self._occurrences.get(name, []))

    def locate(self, name: str, group: int | None = None, index: int | None = None, *,
               target: str | None = None) -> tuple[int, int]:
        """The (group, index) of the channel ``name``, unambiguous or an error listing the candidates.

        Parameters
        ----------
        name : str
            Channel name in the file.
        group : int, optional
            Data group; needed if ``name`` occurs in several groups.
        index : int, optional
            Channel index within ``group``; needed if ``name`` occurs twice in
            that group.
        target : str, optional
            clutchlab name the channel is read for (for error messages).

        Raises
        ------
        DataError
            Missing, not at the given place, or ambiguous (the message lists
            group, index, unit and comment of every candidate).
        """
        what = f"channel {name!r}" + (f" (for {target!r})" if target and target != name else "")
        places = self._occurrences.get(name)
        if not places:
            import difflib

            close = difflib.get_close_matches(name, list(self._occurrences), n=3)
            hint = f"; did you mean {', '.join(map(repr, close))}?" if close else ""
            if self.decoding is None and self.bus_groups:
                hint += "; its raw bus frames are not decoded: give a bus database (--dbc, or [bus] in the map)"
            elif self.decoding is not None:
                hint += f"; bus log: {self.decoding}"
            raise DataError(f"{self.label}: missing {what}{hint} (the file has {len(self._occurrences)} channels)")
        found = [p for p in places if (group is None or p[0] == group) and (index is None or p[1] == index)]
        if not found:
            where = f"group {group}" + (f" index {index}" if index is not None else "")
            there = "; ".join(p.describe() for p in self.places(name))
            raise DataError(f"{self.label}: {what} is not at {where} (it is at {there})")
        if len(found) > 1:
            candidates = "; ".join(p.describe() for p in self.places(name) if (p.group, p.index) in found)
            need = "`group` and `index`" if len({g for g, _ in found}) == 1 else "`group` (and `index`)"
            inside = f" in group {group}" if group is not None else ""
            raise DataError(f"{self.label}: {what} occurs {len(found)} times{inside} ({candidates}); "
                            f"give {need} in the channel map")
        return found[0]

    def load(self, name: str, group: int | None = None, index: int | None = None, *, target: str | None = None,
             skip_nonnumeric: bool = False) -> RawChannel | None:
        """Read one channel with its conversion applied.

        Parameters
        ----------
        name : str
            Channel name in the file.
        group : int, optional
            Data group; required if ``name`` occurs in several groups.
        index : int, optional
            Channel index within ``group``; required if ``name`` occurs twice
            in that group.
        target : str, optional
            clutchlab name the channel is read for (for error messages).
        skip_nonnumeric : bool
            Return ``None`` for a channel of text or structured samples
            instead of raising.

        Raises
        ------
        DataError
            Channel missing (or not at ``group``/``index``), ambiguous, empty,
            not numeric or unreadable.
        """
        what = f"channel {name!r}" + (f" (for {target!r})" if target and target != name else "")
        g, i = self.locate(name, group, index, target=target)
        try:
            mdf, local = self._part(g)
            with _quiet_asammdf():
                sig = mdf.get(name, group=local, index=i)
        except Exception as exc:
            raise DataError(f"{self.label}: cannot read {what} in group {g} ({_one_line(exc)})") from None
        samples = np.asarray(sig.samples)
        if samples.dtype.kind not in "biuf" or samples.ndim != 1:
            if skip_nonnumeric:
                return None
            kind = f"dtype {samples.dtype}" if samples.ndim == 1 else f"{samples.ndim}-D samples"
            frames = (" (raw bus frames: decode them with a DBC file first, --dbc or [bus])" if g in self.bus_groups
                      else "")
            raise DataError(f"{self.label}: {what} in group {g} has non-numeric samples ({kind}){frames}; "
                            "only numeric channels can be read")
        if samples.size == 0:
            raise DataError(f"{self.label}: {what} in group {g} has no samples")
        unit = sig.unit.strip() if isinstance(sig.unit, str) and sig.unit.strip() else None
        return RawChannel(name, samples.astype(float), np.asarray(sig.timestamps, dtype=float), unit, g, i)


def write_mdf(path, time: np.ndarray, channels: dict[str, np.ndarray], units: dict[str, str], *,
              comment: str = "", overwrite: bool = False) -> Path:
    """Write channels sharing one time base as an MDF 4.10 file, atomically.

    Parameters
    ----------
    path : str or Path
        Target ``.mf4`` file.
    time : ndarray
        Time base [s], strictly increasing.
    channels : dict of str to ndarray
        Channel name -> values (same length as ``time``).
    units : dict of str to str
        Channel name -> unit written into the channel's unit field.
    comment : str
        Header comment (provenance, e.g. ``synthetic: ...`` lines).
    overwrite : bool
        Replace an existing file.
    """
    from asammdf import MDF, Signal

    path = check_writable(path, overwrite)
    mdf = MDF(version="4.10")
    signals = [Signal(np.asarray(v, dtype=float), np.asarray(time, dtype=float), name=k, unit=units.get(k, "") or "")
               for k, v in channels.items()]
    if signals:
        mdf.append(signals, comment="clutchlab")
    mdf.header.comment = comment
    fd, tmp = temporary_sibling(path, ".mf4")
    os.close(fd)
    try:
        written = Path(mdf.save(tmp, overwrite=True))
        mdf.close()
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(written, 0o666 & ~umask)
        os.replace(written, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError) and exc.filename != str(path):  # disk full, read-only: name the output
            raise type(exc)(exc.errno, exc.strerror or str(exc), str(path)) from None
        raise
    return path
