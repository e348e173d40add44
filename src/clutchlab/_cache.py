"""clutchlab's cache folders: one place that decides where a cache lives (the compiled kernels' entry modules,
:func:`clutchlab.numerics.entry.kernel_dir`; the unit conversions a file used, :mod:`clutchlab.units`).

A cache is never an input: deleting it costs only time, and what is read from it is checked (a kernel folder must be
this user's own; a conversion must be a finite number).  Without numba or pint: it is read before either is imported.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

__all__ = ["cache_folder", "guard_stale_indexes"]


def cache_folder(name: str) -> Path:
    """The writable folder of cache ``name`` (created if needed), the first of: ``$NUMBA_CACHE_DIR/clutchlab-NAME``
    (numba's cache and clutchlab's together: one variable empties both), ``$XDG_CACHE_HOME/clutchlab/NAME``
    (``~/.cache`` without it), a private ``clutchlab-NAME-UID`` in the temporary folder (refused if it is a link or
    belongs to another user: a kernel folder's modules are imported from it).

    Raises
    ------
    OSError
        None of them can be written.
    """
    candidates = []
    if os.environ.get("NUMBA_CACHE_DIR"):
        candidates.append(Path(os.environ["NUMBA_CACHE_DIR"]) / f"clutchlab-{name}")
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    candidates.append(Path(xdg) / "clutchlab" / name)
    shared = Path(tempfile.gettempdir()) / f"clutchlab-{name}-{os.getuid() if hasattr(os, 'getuid') else 0}"
    candidates.append(shared)
    refused = ""
    for path in candidates:
        try:
            if path == shared:
                # in a folder every user writes to, another user could have made it first, or a link: its modules
                # are imported and numba's pickles read from it, so it must be this user's own and private
                refused = _private_folder(path)
                if refused:
                    continue
            else:
                path.mkdir(parents=True, exist_ok=True)
            if os.access(path, os.W_OK):
                return path
        except OSError:
            continue
    raise OSError(f"no writable folder for clutchlab's {name} cache (tried: "
                  + ", ".join(str(c) for c in candidates) + ")" + (f"; {refused}" if refused else "")
                  + ": set NUMBA_CACHE_DIR to a folder of your own")


def guard_stale_indexes() -> None:
    """Read a numba cache index that cannot be unpickled as an empty one (idempotent; compiles nothing).

    numba loads a cached function's index by unpickling it whole and only then compares the source file's stamp
    (``numba.core.caching.IndexDataCacheFile._load_index``), so an index written by an older clutchlab whose
    signatures name a class since removed or renamed raised instead of being the stale cache it is: ``AttributeError:
    Can't get attribute 'VehicleData' on <module 'clutchlab.emtc.system'>`` after an upgrade over an existing cache
    (an editable install after a pull, ``NUMBA_CACHE_DIR`` kept across versions; found when the EMTC's vehicle
    record replaced its NamedTuple).  Such an index is now a miss: numba compiles the function again and writes a
    fresh index over it.  The same for a cached function's data (``IndexDataCacheFile.load``): a function whose own
    file is unchanged keeps its index, and its data names the modules of the compiled functions it calls, whose
    environments numba rebuilds by importing them; a module an upgrade renamed raised ``ModuleNotFoundError: No
    module named 'clutchlab.hysteresis._kernels'`` (found when the Preisach kernels became
    ``clutchlab.hysteresis.kernels``: the wet clutch's network function, in an unchanged file, called them).  Such
    data is now a miss too.  Applies to every numba cache of the process, which gains the same robustness."""
    import pickle

    from numba.core import caching

    load_index = caching.IndexDataCacheFile._load_index
    if getattr(load_index, "_clutchlab_guard", False):
        return
    load = caching.IndexDataCacheFile.load
    stale = (AttributeError, ImportError, pickle.UnpicklingError, EOFError, IndexError, TypeError, ValueError)

    def _load_index(self):
        try:
            return load_index(self)
        except stale:
            return {}   # (an index of classes that no longer exist: stale, compiled again and overwritten)

    def _load(self, key):
        try:
            return load(self, key)
        except stale:
            return None   # (data naming a module or class that no longer exists: compiled again and overwritten)

    _load_index._clutchlab_guard = True
    _load_index.__doc__ = load_index.__doc__
    _load.__doc__ = load.__doc__
    caching.IndexDataCacheFile._load_index = _load_index
    caching.IndexDataCacheFile.load = _load


def _private_folder(path: Path) -> str:
    """Make ``path`` (in the shared temporary folder) this user's private folder: created with mode 0700, or,
    if it exists, a real folder (not a link) owned by this user, then set to 0700.  Returns "" if it is, else
    why it is refused."""
    try:
        path.mkdir(mode=0o700)
    except FileExistsError:
        pass
    st = os.lstat(path)
    if stat.S_ISLNK(st.st_mode) or not stat.S_ISDIR(st.st_mode):
        return f"{path} is not a folder of its own (a link or a file): refused"
    if hasattr(os, "getuid") and st.st_uid != os.getuid():
        return f"{path} belongs to another user (uid {st.st_uid}): refused"
    if stat.S_IMODE(st.st_mode) != 0o700:
        os.chmod(path, 0o700)
    return ""
