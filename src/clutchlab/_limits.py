"""Resource limits and short value representations for error messages.

Two helpers every edge of clutchlab uses:

* :func:`check_allocation` estimates the memory a table of ``rows`` x
  ``columns`` float64 values needs and raises a
  :class:`~clutchlab.errors.ParameterError` naming the field at fault and the
  estimate *before* anything is allocated, if it exceeds the memory budget
  (:func:`memory_budget`: half the memory available when asked, or the
  environment variable ``CLUTCHLAB_MEMORY_LIMIT``).
* :func:`short_repr` formats any value for an error message in at most a few
  dozen characters (arrays and long lists summarised), so a 10-million-element
  value never produces a 50 MB line.
"""

from __future__ import annotations

import math
import os
import re

from .errors import ParameterError

__all__ = ["MEMORY_ENV", "memory_budget", "check_allocation", "format_bytes", "short_repr", "one_line", "as_numbers"]

#: environment variable overriding the memory budget (bytes, or with a suffix: ``"512 MB"``, ``"2G"``)
MEMORY_ENV = "CLUTCHLAB_MEMORY_LIMIT"
#: fraction of the available memory a single table may take by default
MEMORY_FRACTION = 0.5
#: budget when the available memory cannot be determined [bytes]
_FALLBACK_BUDGET = 2 * 1024**3
#: tables this small pass without reading the available memory (unless CLUTCHLAB_MEMORY_LIMIT is set) [bytes]
_SMALL = 1024**2
#: tables this small always pass: no budget below it is meaningful, and reading the environment for a
#: missing variable raises and catches a KeyError inside ``os.environ`` (8 us in a short run, measured) [bytes]
_TINY = 64 * 1024
_SUFFIXES = {"": 1, "B": 1, "K": 1024, "KB": 1024, "KIB": 1024, "M": 1024**2, "MB": 1024**2, "MIB": 1024**2,
             "G": 1024**3, "GB": 1024**3, "GIB": 1024**3, "T": 1024**4, "TB": 1024**4, "TIB": 1024**4}
_SIZE = re.compile(r"^\s*(\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)\s*([A-Za-z]*)\s*$")


def _available_memory() -> int | None:
    """Memory the system can give this process now [bytes], or ``None`` if unknown."""
    try:  # Linux: MemAvailable counts reclaimable caches, unlike SC_AVPHYS_PAGES
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        return None


def memory_budget() -> int:
    """Largest single allocation clutchlab attempts [bytes].

    ``CLUTCHLAB_MEMORY_LIMIT`` if set (a number of bytes, optionally with a
    suffix K, M, G, T or KB, MB, GB, TB, all binary), else half of the
    memory available now (2 GiB if that cannot be determined).  Tables of
    at most 64 KiB are allocated without asking (:func:`check_allocation`).

    Raises
    ------
    ParameterError
        ``CLUTCHLAB_MEMORY_LIMIT`` is not a positive size.
    """
    raw = os.environ.get(MEMORY_ENV)
    if raw is not None and raw.strip():
        m = _SIZE.match(raw)
        factor = _SUFFIXES.get(m.group(2).upper()) if m else None
        value = float(m.group(1)) * factor if factor else float("nan")
        if not (math.isfinite(value) and value > 0):
            raise ParameterError(f"{MEMORY_ENV} = {short_repr(raw)}: expected a positive size such as 4G or 512MB")
        return int(value)
    avail = _available_memory()
    return int(avail * MEMORY_FRACTION) if avail else _FALLBACK_BUDGET


def format_bytes(n: float) -> str:
    """``n`` bytes as a short human-readable size (``"1.5 GB"``, binary prefixes)."""
    for unit in ("B", "KB", "MB", "GB", "TB", "PB"):
        if abs(n) < 1024 or unit == "PB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} PB"  # pragma: no cover


def check_allocation(rows, columns, what: str, *, itemsize: int = 8) -> int:
    """Raise before allocating a ``rows`` x ``columns`` table that would not fit in memory.

    Parameters
    ----------
    rows : int or float
        Number of rows (samples, points) the operation will create; may be a
        float estimate such as ``duration * rate`` (infinite counts fail).
    columns : int or float
        Number of values per row (states, outputs, channels).
    what : str
        What the user asked for, naming the field and its value, e.g.
        ``"--points 100000000"`` or ``"[scenario] duration = 1e6 s at 1 kHz"``.
    itemsize : int
        Bytes per value (8 for float64).

    Returns
    -------
    int
        The estimate [bytes].

    Raises
    ------
    ParameterError
        The estimate exceeds :func:`memory_budget`; the message names
        ``what``, the number of values, the estimate and the budget.
    """
    rows = float(rows)
    columns = float(columns)
    need = rows * max(columns, 1.0) * itemsize
    if not math.isfinite(need):
        raise ParameterError(f"{what}: the number of values is not finite ({short_repr(rows)} rows)")
    if need <= _TINY:
        return int(need)
    if need <= _SMALL and not os.environ.get(MEMORY_ENV, "").strip():
        return int(need)  # far below any default budget: no need to ask the system (a file read per call)
    budget = memory_budget()
    if need > budget:
        raise ParameterError(
            f"{what}: would need {rows:.3g} rows x {columns:.0f} values = {format_bytes(need)}, more than the "
            f"memory budget of {format_bytes(budget)} (set {MEMORY_ENV} to change it)")
    return int(need)


def check_number(name: str, value, *, positive: bool = False, nonnegative: bool = False) -> float:
    """``value`` as a finite float, or a :class:`ParameterError` naming ``name`` and the value.

    Parameters
    ----------
    name : str
        What the value is, as the message should say it (``"clutch1: fn_max"``).
    value : object
        The value given.
    positive, nonnegative : bool
        Also require ``> 0`` or ``>= 0``.
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} = {value!r} is not a number") from None
    if not math.isfinite(v):
        raise ParameterError(f"{name} = {value!r} is not finite")
    if positive and not v > 0:
        raise ParameterError(f"{name} = {value!r} must be > 0")
    if nonnegative and v < 0:
        raise ParameterError(f"{name} = {value!r} must be >= 0")
    return v


def short_repr(value, limit: int = 60) -> str:
    """A representation of ``value`` of at most about ``limit`` characters.

    Arrays and long sequences are summarised by their type, length and first
    elements (``array(shape=(10000000,), [0.0, 1.0, 2.0, ...])``); long strings
    and other long representations are cut in the middle with ``...``.  A NumPy
    scalar shows as the plain number (``1.5``, not ``np.float64(1.5)``).

    Parameters
    ----------
    value : object
        Anything.
    limit : int
        Characters to aim at.

    Returns
    -------
    str
    """
    shape = getattr(value, "shape", None)
    if shape == () and hasattr(value, "item"):  # a NumPy scalar or 0-d array: 1.5, not np.float64(1.5)
        try:
            value, shape = value.item(), None
        except Exception:  # pragma: no cover - an exotic scalar type: keep it as it is
            pass
    if shape is not None and hasattr(value, "ravel") and getattr(value, "size", 0) > 3:
        try:
            head = ", ".join(short_repr(v.item() if hasattr(v, "item") else v, 12) for v in value.ravel()[:3])
        except Exception:  # an exotic array type: fall back to its repr
            head = "..."
        return f"{type(value).__name__}(shape={tuple(shape)}, [{head}, ...])"
    if isinstance(value, (list, tuple)) and len(value) > 3:
        head = ", ".join(short_repr(v, 12) for v in value[:3])
        open_, close = ("[", "]") if isinstance(value, list) else ("(", ")")
        text = f"{open_}{head}, ... ({len(value)} items){close}"
        if len(text) <= limit:
            return text
        return f"{type(value).__name__} of {len(value)} items"
    if isinstance(value, dict) and len(value) > 3:
        return f"{{... {len(value)} keys}}"
    try:
        text = repr(value)
    except Exception:
        text = f"<{type(value).__name__}>"
    text = " ".join(text.split())
    if len(text) > limit:
        keep = max(limit // 2 - 2, 4)
        text = text[:keep] + "..." + text[-keep:]
    return text


def one_line(text: str, limit: int = 300) -> str:
    """``text`` on one line of at most ``limit`` characters (whitespace runs collapsed, the middle cut)."""
    text = " ".join(str(text).split())
    if len(text) > limit:
        keep = (limit - 5) // 2
        text = text[:keep] + " ... " + text[-keep:]
    return text


def as_numbers(value, what: str, error=ParameterError):
    """``value`` as a float array, or ``error`` naming ``what`` and the value: the one conversion of a user's
    list or table of numbers at the edge (not NumPy's ``could not convert string to float`` or "inhomogeneous
    shape", and never a string of digits read as a number).

    Parameters
    ----------
    value : array_like
        A number, a list or nested lists of numbers (every row of one length), or an array.
    what : str
        What to name in the error (the file and the field, or the argument).
    error : type
        The exception class (:class:`~clutchlab.errors.ParameterError` for parameters, ``DataError`` for
        files of data).
    """
    import numpy as np

    if isinstance(value, (str, bytes, dict, set)) or value is None:
        raise error(f"{what} = {short_repr(value)}: expected numbers (a list or table of numbers), not "
                    f"{type(value).__name__}")
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise error(f"{what} = {short_repr(value)}: expected numbers (a list or table of numbers, every row "
                    "of the same length)") from None
