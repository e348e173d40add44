"""ASAM MDF 4 files through :mod:`asammdf`: open defensively, pick channels, write with units.

Only :mod:`clutchlab.io.measurements` calls these functions; users read and
write MDF files with :func:`~clutchlab.io.read_measurement` and
:func:`~clutchlab.io.write_measurement`.  :mod:`asammdf` is imported lazily.
"""

from __future__ import annotations

import logging
import os
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DataError
from .files import check_writable, temporary_sibling

__all__ = ["MDF_SUFFIXES", "RawChannel", "MdfReader", "write_mdf"]

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
    """

    name: str
    samples: np.ndarray
    timestamps: np.ndarray | None
    unit: str | None
    group: int | None = None


@contextmanager
def _quiet_asammdf():
    # asammdf logs an ERROR before raising for ambiguous names; we raise our own error instead
    log = logging.getLogger("asammdf")
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        log.setLevel(level)


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


class MdfReader:
    """An open MDF file: its channel names, groups, header comment, and channel access.

    Parameters
    ----------
    path : str or Path
        The ``.mf4`` (or ``.mdf``) file.
    label : str
        How to call the file in error messages.

    Raises
    ------
    DataError
        Missing file, not an MDF file, truncated or otherwise unreadable.
    """

    def __init__(self, path, label: str):
        from asammdf import MDF

        self.path = Path(path)
        self.label = label
        if not self.path.exists():
            raise DataError(f"{label}: no such file")
        # open through a file object: asammdf then never leaves a half-built object that complains when collected
        self._fh = open(self.path, "rb")
        try:
            with _quiet_asammdf():
                self._mdf = MDF(self._fh)
        except Exception as exc:  # asammdf raises MdfException, ValueError, struct.error ... on damaged files
            _defuse(exc)
            self._fh.close()
            raise DataError(f"{label}: not a readable MDF file ({type(exc).__name__}: {exc})") from None
        self._masters = {(g, i) for g, i in self._mdf.masters_db.items()}
        self._occurrences: dict[str, list[tuple[int, int]]] = {}
        for name, entries in self._mdf.channels_db.items():
            for g, i in entries:
                if (g, i) not in self._masters:
                    self._occurrences.setdefault(name, []).append((g, i))

    def close(self) -> None:
        """Close the file."""
        try:
            self._mdf.close()
        finally:
            self._fh.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @property
    def comment(self) -> str:
        """The header comment (plain text)."""
        try:
            return str(self._mdf.header.description or "")
        except Exception:  # an odd XML comment is not worth failing a read
            return ""

    def channel_names(self) -> list[str]:
        """Names of the non-master channels, in file order (each name once)."""
        return list(self._occurrences)

    def groups_of(self, name: str) -> list[int]:
        """Data groups in which the channel ``name`` occurs."""
        return sorted({g for g, _ in self._occurrences.get(name, [])})

    def load(self, name: str, group: int | None = None, *, target: str | None = None,
             skip_nonnumeric: bool = False) -> RawChannel | None:
        """Read one channel with its conversion applied.

        Parameters
        ----------
        name : str
            Channel name in the file.
        group : int, optional
            Data group; required if ``name`` occurs in several groups.
        target : str, optional
            clutchlab name the channel is read for (for error messages).
        skip_nonnumeric : bool
            Return ``None`` for a channel of text or structured samples
            instead of raising.

        Raises
        ------
        DataError
            Channel missing (or not in ``group``), ambiguous, empty or not numeric.
        """
        what = f"channel {name!r}" + (f" (for {target!r})" if target and target != name else "")
        places = self._occurrences.get(name)
        if not places:
            import difflib

            close = difflib.get_close_matches(name, list(self._occurrences), n=3)
            hint = f"; did you mean {', '.join(map(repr, close))}?" if close else ""
            raise DataError(f"{self.label}: missing {what}{hint} (the file has {len(self._occurrences)} channels)")
        if group is not None:
            places = [p for p in places if p[0] == group]
            if not places:
                raise DataError(f"{self.label}: {what} is not in group {group} "
                                f"(it is in group {', '.join(map(str, self.groups_of(name)))})")
        if len(places) > 1:
            groups = ", ".join(str(g) for g, _ in places)
            raise DataError(f"{self.label}: {what} occurs in several groups ({groups}); "
                            f"give `group` in the channel map")
        g, i = places[0]
        try:
            with _quiet_asammdf():
                sig = self._mdf.get(name, group=g, index=i)
        except Exception as exc:
            raise DataError(f"{self.label}: cannot read {what} in group {g} ({type(exc).__name__}: {exc})") from None
        samples = np.asarray(sig.samples)
        if samples.dtype.kind not in "biuf" or samples.ndim != 1:
            if skip_nonnumeric:
                return None
            raise DataError(f"{self.label}: {what} in group {g} has non-numeric samples (dtype {samples.dtype}); "
                            "only numeric channels can be read")
        if samples.size == 0:
            raise DataError(f"{self.label}: {what} in group {g} has no samples")
        unit = sig.unit.strip() if isinstance(sig.unit, str) and sig.unit.strip() else None
        return RawChannel(name, samples.astype(float), np.asarray(sig.timestamps, dtype=float), unit, g)


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
