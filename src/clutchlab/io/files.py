"""Atomic writes, output checks and validated reading of tables, TOML and JSON.

Nothing a user wrote is overwritten unless ``overwrite=True`` is given (the
CLI's ``--force``); every file is written to a hidden temporary sibling
(``.NAME.PID.XXXXXXXX.tmp``) and moved into place, so a crash never leaves
half a file behind, and the temporary file of a writer that was killed is
removed by the next write of the same output.  A folder assembled beside its
output (a report, :func:`temporary_folder`) is ``.NAME.PID.XXXXXXXX.tmp`` with a
marker file inside; the next write of that output removes it once process
``PID`` is gone (only a folder so named that holds a marker, or nothing).
"""

from __future__ import annotations

import errno
import json
import os
import re
import shutil
import tempfile
import tomllib
from pathlib import Path
from typing import Iterable

import numpy as np
import pandas as pd

from .._limits import check_allocation, format_bytes, short_repr
from ..errors import DataError, ParameterError

__all__ = ["OutputExistsError", "check_writable", "check_outputs", "atomic_write_text", "atomic_write_bytes",
           "atomic_to_csv", "read_table", "read_toml", "read_json", "temporary_sibling", "temporary_folder",
           "remove_stale_temporaries", "OutputSet"]

#: the file that marks a hidden temporary folder as clutchlab's (:func:`temporary_folder`)
TEMPORARY_MARKER = ".clutchlab-temporary"
#: the file that marks a report folder as clutchlab's (:data:`clutchlab.report.html.MARKER`); a report is
#: assembled in a temporary folder that holds it from the start
REPORT_MARKER = ".clutchlab-report"
#: a temporary folder of a writer that is gone is removed only if it holds one of these (or nothing)
_FOLDER_MARKERS = (TEMPORARY_MARKER, REPORT_MARKER)
#: the journal of an :class:`OutputSet`, in its first temporary folder: the moves still to make
_JOURNAL = ".clutchlab-commit"

#: a text document (TOML, JSON) larger than this many times the memory budget is refused unread
_DOCUMENT_EXPANSION = 20


class OutputExistsError(FileExistsError):
    """An output exists and replacing it was not asked for (``overwrite=True``, CLI ``--force``).

    ``str()`` gives the library wording (``pass overwrite=True``); the command
    line prints :attr:`cli_message` (``use --force``).
    """

    def __init__(self, path, what: str = "file"):
        super().__init__(errno.EEXIST, f"{what} exists", str(path))
        self.what = what

    def __str__(self) -> str:
        return f"{self.filename}: {self.what} exists; pass overwrite=True to replace it"

    @property
    def cli_message(self) -> str:
        """The message for the command line: ``PATH: file exists; use --force to replace it``."""
        return f"{self.filename}: {self.what} exists; use --force to replace it"


def _check_parent(path: Path) -> None:
    """Raise if the folder of ``path`` cannot be created or written to (no side effects)."""
    parent = path.parent
    probe = parent
    while not probe.exists():
        if probe.is_symlink():  # a dangling link
            raise NotADirectoryError(errno.ENOTDIR, "is a broken link, not a folder", str(probe))
        if probe.parent == probe:
            break
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, "is a file, not a folder; cannot write inside it", str(probe))
    if probe.exists() and not os.access(probe, os.W_OK | os.X_OK):
        raise PermissionError(errno.EACCES, "folder is not writable", str(probe))


def check_writable(path, overwrite: bool = False, *, what: str = "file") -> Path:
    """Check that ``path`` can be written, without creating anything.

    Parameters
    ----------
    path : str or Path
        Output to write.
    overwrite : bool
        Whether an existing output may be replaced.
    what : str
        What the output is, for messages (``"file"``, ``"folder"``).

    Returns
    -------
    Path
        ``Path(path)``.

    Raises
    ------
    OutputExistsError
        ``path`` exists and ``overwrite`` is false.
    IsADirectoryError
        ``path`` is a folder but a file is to be written.
    NotADirectoryError, PermissionError
        A parent of ``path`` is a file, or its folder is not writable.
    """
    path = Path(path)
    if what == "file" and path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a folder; give a file name", str(path))
    if (path.exists() or path.is_symlink()) and not overwrite:
        raise OutputExistsError(path, what)
    _check_parent(path)
    return path


def check_outputs(paths, overwrite: bool = False) -> list[Path]:
    """:func:`check_writable` for every output of a command (``None`` entries skipped), before any work."""
    checked = [check_writable(p, overwrite) for p in paths if p is not None]
    seen = {}
    for p in checked:
        key = os.path.abspath(p)
        if key in seen:
            raise ParameterError(f"{p}: given twice as an output")
        seen[key] = p
    return checked


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    except (OverflowError, ValueError, OSError):  # not a valid process id
        return False
    return True


def _stale_folder(path) -> bool:
    """Whether the folder ``path`` is a temporary folder of clutchlab's whose writer is gone: named
    ``.NAME.PID.XXXXXXXX.tmp`` (:func:`temporary_folder`), not a link, process ``PID`` not running, and holding
    a marker file (:data:`_FOLDER_MARKERS`) or nothing.  A folder of the user's (no marker) never is."""
    path = os.fspath(path)
    match = re.fullmatch(r"\..+\.(\d+)\.[A-Za-z0-9_]{8}\.tmp", os.path.basename(path))
    if match is None or os.path.islink(path) or not os.path.isdir(path) or _pid_alive(int(match[1])):
        return False
    try:
        names = os.listdir(path)
    except OSError:
        return False
    return not names or any(os.path.isfile(os.path.join(path, m)) and not os.path.islink(os.path.join(path, m))
                            for m in _FOLDER_MARKERS if m in names)


def _marker(folder: Path) -> dict:
    """What the marker of a temporary folder of an :class:`OutputSet` says (``{}`` for any other)."""
    try:
        info = json.loads((folder / TEMPORARY_MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return info if isinstance(info, dict) else {}


def _settle(folder: Path) -> list[Path]:
    """Finish or remove the stale temporary folder ``folder`` (:func:`_stale_folder`) and those of its run.

    A folder of an :class:`OutputSet` names the run's first folder (its ``lead``), which lists the others;
    if the lead holds the run's journal, the run was killed while moving its outputs into place: the moves
    are finished first (every output of that run, complete, as it would have been).  Otherwise the run was
    killed before: its folders are removed, its outputs untouched.  Returns the folders removed.
    """
    info = _marker(folder)
    lead = Path(info["lead"]) if isinstance(info.get("lead"), str) and info["lead"] else folder
    if lead != folder and not _stale_folder(lead):
        lead = folder
    members = [Path(m) for m in _marker(lead).get("members", []) if isinstance(m, str)]
    journal = lead / _JOURNAL
    if journal.is_file():
        try:
            pairs = json.loads(journal.read_text(encoding="utf-8"))
            for staged, target in pairs:
                staged, target = Path(staged), Path(target)
                # (only a file of a temporary folder beside its own output moves)
                if (staged.name == target.name and staged.parent.parent == target.parent
                        and staged.parent.name.startswith(f".{target.name}.") and os.path.lexists(staged)):
                    os.replace(staged, target)
        except (OSError, ValueError, TypeError):
            return []   # (left as it is: the next run tries again)
    removed = []
    for f in dict.fromkeys([folder, *members, lead]):   # the lead (and its journal) last
        if _stale_folder(f):
            shutil.rmtree(f, ignore_errors=True)
            removed.append(f)
    return removed


def remove_stale_temporaries(path) -> list[Path]:
    """Remove hidden temporary siblings of ``path`` left by a writer that no longer runs.

    A writer's temporary file is ``.NAME.PID.XXXXXXXX.tmp`` (or ``.mf4``); it
    is stale if process ``PID`` is gone (killed before it could rename or
    remove the file).  A temporary folder (:func:`temporary_folder`,
    ``.NAME.PID.XXXXXXXX.tmp``) is removed under the same condition, and only
    if it holds a clutchlab marker file (or nothing); one of an
    :class:`OutputSet` killed while moving its outputs into place has those
    moves finished first.  Temporaries of running writers are left alone.

    Returns
    -------
    list of Path
        The files and folders removed.
    """
    path = Path(path)
    removed = []
    prefix = f".{path.name}."
    try:
        entries = list(os.scandir(path.parent))
    except OSError:
        return removed
    for entry in entries:
        name = entry.name
        if not name.startswith(prefix):
            continue
        try:
            if entry.is_dir(follow_symlinks=False):
                if _stale_folder(entry.path):
                    removed += _settle(Path(entry.path))
                continue
        except OSError:
            continue
        if not name.endswith((".tmp", ".mf4")):
            continue
        pid_text = name[len(prefix):].split(".", 1)[0]
        if pid_text.isdigit() and _pid_alive(int(pid_text)):
            continue
        try:
            if entry.is_file(follow_symlinks=False):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except OSError:
            pass
    return removed


def temporary_folder(path, marker: str = TEMPORARY_MARKER, note: str = "") -> Path:
    """Create a hidden temporary folder beside ``path`` (``.NAME.PID.XXXXXXXX.tmp``) holding the file ``marker``.

    Stale temporaries of ``path`` are removed first (:func:`remove_stale_temporaries`: a later run removes
    this folder too, if its process was killed before it could) and the parent folder is created if missing.
    The folder gets the usual permissions (``mkdtemp`` creates 0700); ``note`` is the marker's text.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    folder = Path(tempfile.mkdtemp(prefix=f".{path.name}.{os.getpid()}.", suffix=".tmp", dir=path.parent))
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(folder, 0o777 & ~umask)
        (folder / marker).write_text(note or "a temporary folder of clutchlab's: removed once its process is gone\n",
                                     encoding="utf-8")
    except BaseException:
        shutil.rmtree(folder, ignore_errors=True)
        raise
    return folder


def temporary_sibling(path: Path, suffix: str = ".tmp") -> tuple[int, str]:
    """Create a hidden temporary file beside ``path`` (``.NAME.PID.XXXXXXXX<suffix>``).

    Stale temporary files of ``path`` are removed first and the folder is
    created if missing.  Returns ``(fd, name)`` like :func:`tempfile.mkstemp`.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    return tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=suffix, dir=path.parent)


def atomic_write_bytes(path, data: bytes, overwrite: bool = False) -> Path:
    """Write ``data`` (bytes) to ``path`` atomically (temporary file + rename).

    Refuses to replace an existing file unless ``overwrite`` is true.
    """
    path = check_writable(path, overwrite)
    fd, tmp = temporary_sibling(path)
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file the usual permissions
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError) and exc.filename != str(path):  # disk full, read-only: name the output
            raise type(exc)(exc.errno, exc.strerror or str(exc), str(path)) from None
        raise
    return path


def atomic_write_text(path, text: str, overwrite: bool = False) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; an existing file only with ``overwrite``."""
    return atomic_write_bytes(path, text.encode("utf-8"), overwrite)


def atomic_to_csv(frame: pd.DataFrame, path, overwrite: bool = False, header_comment: str | None = None) -> Path:
    """Write the DataFrame ``frame`` as CSV to ``path`` atomically.

    ``header_comment`` lines are prefixed with ``#`` (readers skip them); an
    existing file is replaced only with ``overwrite``.
    """
    text = frame.to_csv(index=False, float_format="%.9g")
    if header_comment:
        text = "".join(f"# {line}\n" for line in header_comment.splitlines()) + text
    return atomic_write_text(path, text, overwrite)


class OutputSet:
    """The outputs of one run, replaced together: all of them or none (#33).

    Parameters
    ----------
    paths : iterable of str or Path
        The run's outputs (``None`` entries skipped), checked at once (:func:`check_outputs`) -- after
        what an interrupted run of the same outputs left was settled (:func:`remove_stale_temporaries`).
    overwrite : bool
        Whether existing outputs may be replaced (the CLI's ``--force``).

    Each output is written, by any writer, to :meth:`staged` ``(path)``: the same name in a hidden
    temporary folder beside it (:func:`temporary_folder`).  At the end of a ``with`` block
    (:meth:`commit`) the run's journal is written, every staged file is moved into place and the folders
    are removed; an exception in the block removes them and leaves the outputs as they were.  So a run
    killed while it writes leaves every old output (its folders are removed by the next write of one of
    them), and one killed while moving them into place leaves its journal: the next write of any of them
    finishes the moves first, and all outputs are that run's.  Never a mix of two runs.

    Examples
    --------
    >>> outputs = OutputSet([csv, events], overwrite=False)      # before the run: checked
    >>> with outputs:                                            # doctest: +SKIP
    ...     atomic_to_csv(frame, outputs.staged(csv))
    ...     atomic_to_csv(table, outputs.staged(events))
    """

    def __init__(self, paths, overwrite: bool = False):
        self.paths = [Path(p) for p in paths if p is not None]
        for p in self.paths:
            remove_stale_temporaries(p)
        check_outputs(self.paths, overwrite)
        self.overwrite = overwrite
        self._targets = {os.path.abspath(p): p for p in self.paths}
        self._folders: dict[str, Path] = {}
        self._lead: Path | None = None
        self._moving = False

    def staged(self, path) -> Path:
        """The path to write the output ``path`` to (in its temporary folder, created on the first call)."""
        key = os.path.abspath(path)
        if key not in self._targets:
            raise ValueError(f"{path}: not an output of this set ({', '.join(map(str, self.paths))})")
        if key not in self._folders:
            target = self._targets[key]
            lead = "" if self._lead is None else str(self._lead)
            folder = Path(os.path.abspath(temporary_folder(target, note=json.dumps({"lead": lead}) + "\n")))
            self._folders[key] = folder
            if self._lead is None:
                self._lead = folder
            members = [str(f) for f in self._folders.values() if f != self._lead]
            atomic_write_text(self._lead / TEMPORARY_MARKER, json.dumps({"lead": "", "members": members}) + "\n",
                              overwrite=True)
        return self._folders[key] / self._targets[key].name

    def commit(self) -> list[Path]:
        """Move every staged output into place (after writing the journal); returns the outputs replaced."""
        pairs = [(folder / self._targets[key].name, self._targets[key]) for key, folder in self._folders.items()
                 if os.path.lexists(folder / self._targets[key].name)]
        try:
            for _, target in pairs:
                check_writable(target, self.overwrite)   # (again: one may have appeared during the run)
            if len(pairs) > 1:
                atomic_write_text(self._lead / _JOURNAL,
                                  json.dumps([[str(a), os.path.abspath(b)] for a, b in pairs]) + "\n")
            self._moving = True   # from here on only forward: a failure leaves the journal to the next run
            for staged, target in pairs:
                os.replace(staged, target)
            self._moving = False
        finally:
            self.discard()
        return [target for _, target in pairs]

    def discard(self) -> None:
        """Remove the temporary folders (the staged outputs with them); the outputs stay as they were."""
        if self._moving:
            return
        for folder in [f for f in self._folders.values() if f != self._lead] + [self._lead]:
            if folder is not None:
                shutil.rmtree(folder, ignore_errors=True)
        self._folders.clear()
        self._lead = None

    def __enter__(self) -> "OutputSet":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()


def read_table(source, required: Iterable[str], *, name: str | None = None, allow_nan: Iterable[str] = ()) -> pd.DataFrame:
    """Read a CSV file (or accept a DataFrame) and validate its columns.

    Parameters
    ----------
    source : str, Path or pandas.DataFrame
        CSV file (lines starting with ``#`` are comments; the encoding, separator, decimal mark and
        header rows are detected, :mod:`clutchlab.io.dialect`) or a DataFrame.
    required : iterable of str
        Columns that must be present, finite and numeric.
    name : str, optional
        How to call the source in error messages (defaults to the path).
    allow_nan : iterable of str
        Required columns in which NaN is allowed.

    Raises
    ------
    DataError
        Missing file, missing column, non-numeric or NaN values, naming the
        source, the column and the first offending row.
    """
    if isinstance(source, pd.DataFrame):
        frame = source.copy()
        label = name or "record"
    else:
        path = Path(source)
        label = name or str(path)
        if not path.exists():
            raise DataError(f"{label}: no such file")
        if path.is_dir():
            raise DataError(f"{label}: is a directory, not a CSV file")
        from .dialect import read_csv

        frame = read_csv(path, label).frame  # any dialect rig software writes (clutchlab.io.dialect)
    allow_nan = set(allow_nan)
    for col in required:
        if col not in frame.columns:
            raise DataError(f"{label}: missing column {col!r} (has: {', '.join(map(str, frame.columns))})")
        values = pd.to_numeric(frame[col], errors="coerce")
        bad = ~np.isfinite(values.to_numpy(dtype=float))
        if col not in allow_nan and bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise DataError(f"{label}: column {col!r} has a non-finite or non-numeric value {short_repr(frame[col].iloc[row])} at row {row}")
        frame[col] = values.astype(float)
    return frame


def _read_document(path, kind: str, parse, error) -> object:
    """Read a UTF-8 text document and parse it; every way it can be bad becomes ``error`` naming the file."""
    path = Path(path)
    if not path.exists():
        raise error(f"{path}: no such {kind} file")
    if path.is_dir():
        raise error(f"{path}: is a folder, not a {kind} file")
    try:
        size = path.stat().st_size
        check_allocation(size, _DOCUMENT_EXPANSION / 8, f"{path}: {kind} file of {format_bytes(size)}")
        raw = path.read_bytes()
    except PermissionError:
        raise error(f"{path}: cannot read the {kind} file (permission denied)") from None
    except OSError as exc:
        raise error(f"{path}: cannot read the {kind} file ({exc.strerror or type(exc).__name__})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not a UTF-8 text file (byte {raw[exc.start:exc.start + 1]!r} at offset {exc.start}); "
                    f"save it as UTF-8") from None
    try:
        return parse(text)
    except RecursionError:
        raise error(f"{path}: {kind} nested too deeply to read") from None
    except (ValueError, TypeError) as exc:  # TOMLDecodeError and JSONDecodeError are ValueErrors
        msg = " ".join(str(exc).split())
        raise error(f"{path}: not valid {kind} ({short_repr(msg, 160)})") from None


def read_toml(path, error=ParameterError) -> dict:
    """Read the TOML file at ``path``.

    Parameters
    ----------
    path : str or Path
        TOML file (UTF-8).
    error : type
        Exception class to raise (a :class:`~clutchlab.errors.ClutchlabError`).

    Raises
    ------
    ParameterError (or ``error``)
        Missing or unreadable file, not UTF-8, not valid TOML, nested too
        deeply, or larger than the memory budget allows -- naming the file.
    """
    return _read_document(path, "TOML", tomllib.loads, error)


def read_json(path, error=DataError):
    """Read the JSON file at ``path`` (see :func:`read_toml` for the errors; default :class:`DataError`)."""
    return _read_document(path, "JSON", json.loads, error)
