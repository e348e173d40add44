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
           "remove_stale_temporaries"]

#: the file that marks a hidden temporary folder as clutchlab's (:func:`temporary_folder`)
TEMPORARY_MARKER = ".clutchlab-temporary"
#: the file that marks a report folder as clutchlab's (:data:`clutchlab.report.html.MARKER`); a report is
#: assembled in a temporary folder that holds it from the start
REPORT_MARKER = ".clutchlab-report"
#: a temporary folder of a writer that is gone is removed only if it holds one of these (or nothing)
_FOLDER_MARKERS = (TEMPORARY_MARKER, REPORT_MARKER)

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


def _stale_folder(entry, prefix: str) -> bool:
    """Whether the folder ``entry`` beside an output is a temporary folder of clutchlab's whose writer is gone:
    named ``PREFIX + PID.XXXXXXXX.tmp`` (:func:`temporary_folder`), not a link, process ``PID`` not running, and
    holding a marker file (:data:`_FOLDER_MARKERS`) or nothing.  A folder of the user's (no marker) never is."""
    match = re.fullmatch(r"(\d+)\.[A-Za-z0-9_]{8}\.tmp", entry.name[len(prefix):])
    if match is None or not entry.is_dir(follow_symlinks=False) or _pid_alive(int(match[1])):
        return False
    try:
        names = os.listdir(entry.path)
    except OSError:
        return False
    return not names or any(os.path.isfile(os.path.join(entry.path, m)) and
                            not os.path.islink(os.path.join(entry.path, m)) for m in _FOLDER_MARKERS if m in names)


def remove_stale_temporaries(path) -> list[Path]:
    """Remove hidden temporary siblings of ``path`` left by a writer that no longer runs.

    A writer's temporary file is ``.NAME.PID.XXXXXXXX.tmp`` (or ``.mf4``); it
    is stale if process ``PID`` is gone (killed before it could rename or
    remove the file).  A temporary folder (:func:`temporary_folder`,
    ``.NAME.PID.XXXXXXXX.tmp``) is removed under the same condition, and only
    if it holds a clutchlab marker file (or nothing).  Temporaries of running
    writers are left alone.

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
                if _stale_folder(entry, prefix):
                    shutil.rmtree(entry.path)
                    removed.append(Path(entry.path))
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
