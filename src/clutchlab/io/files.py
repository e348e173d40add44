"""Atomic writes and validated table reading.

Nothing a user wrote is overwritten unless ``overwrite=True`` is given; every
file is written to a temporary sibling and moved into place, so a crash never
leaves half a file behind.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Iterable

import numpy as np
import pandas as pd

from ..errors import DataError

__all__ = ["check_writable", "atomic_write_text", "atomic_write_bytes", "atomic_to_csv", "read_table"]


def check_writable(path, overwrite: bool = False) -> Path:
    """Return ``Path(path)`` or raise if it exists and ``overwrite`` is false."""
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass overwrite=True (CLI: --force) to replace it")
    if path.parent and not path.parent.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
    return path


def atomic_write_bytes(path, data: bytes, overwrite: bool = False) -> Path:
    """Write ``data`` (bytes) to ``path`` atomically (temporary file + rename).

    Refuses to replace an existing file unless ``overwrite`` is true.
    """
    path = check_writable(path, overwrite)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file the usual permissions
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
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
        CSV file (lines starting with ``#`` are comments) or a DataFrame.
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
        try:
            frame = pd.read_csv(path, comment="#")
        except Exception as exc:  # pandas raises several parser errors
            raise DataError(f"{label}: cannot read as CSV ({exc})") from None
    allow_nan = set(allow_nan)
    for col in required:
        if col not in frame.columns:
            raise DataError(f"{label}: missing column {col!r} (has: {', '.join(map(str, frame.columns))})")
        values = pd.to_numeric(frame[col], errors="coerce")
        bad = ~np.isfinite(values.to_numpy(dtype=float))
        if col not in allow_nan and bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise DataError(f"{label}: column {col!r} has a non-finite or non-numeric value {frame[col].iloc[row]!r} at row {row}")
        frame[col] = values.astype(float)
    return frame
