"""Keep the core's cached machine code in step with the models compiled into it.

numba checks only the source file of a cached function.  The core's
specialisations (:mod:`clutchlab.numerics.core`) contain each model's
equations, compiled in through :mod:`clutchlab.numerics.dispatch`; after an
edit of a model file, numba would happily load the old machine code (measured:
shared/notes/one-core-numba.md).  Before every core run, :func:`ensure_fresh`
compares the stamp (size, modification time) of each source file that can be
compiled into the core -- every ``.py`` file of the clutchlab package and the
file of every registered model hook, also models outside the package -- with
the stamps recorded beside the core's cache.  If one differs, it deletes the
core's cache files, so the core recompiles with the current models, and
records the new stamps.  Each file is checked once per process (one ``stat``,
about 1 ms for the package); an installed package never changes.
"""

from __future__ import annotations

import glob
import json
import os
from pathlib import Path

__all__ = ["ensure_fresh", "source_stamp", "STAMP_NAME"]

STAMP_NAME = "clutchlab-core-sources.json"
_CHECKED: set = set()
_PACKAGE_DONE = False


def _stamp(path: str) -> str | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return f"{st.st_size}|{st.st_mtime_ns}"


def _package_files() -> list:
    root = Path(__file__).resolve().parents[1]
    return sorted(str(p) for p in root.rglob("*.py"))


def source_stamp() -> str:
    """One string summarising the stamps of every clutchlab source file (changes with any edit)."""
    import hashlib

    digest = hashlib.sha1()
    for f in _package_files():
        digest.update(f"{f}|{_stamp(f)}\n".encode())
    return digest.hexdigest()


def _core_cache_paths() -> set:
    from . import core

    paths = set()
    for obj in vars(core).values():
        cache = getattr(obj, "_cache", None)
        if cache is not None and getattr(getattr(obj, "py_func", None), "__module__", "") == core.__name__:
            path = getattr(cache, "_cache_path", None)
            if path:
                paths.add(path)
    return paths


def _model_files() -> set:
    from . import dispatch

    return set(dispatch.model_sources())


def ensure_fresh() -> None:
    """Delete the core's cached code if a source compiled into it changed since (cheap after the first call)."""
    global _PACKAGE_DONE
    files = set()
    if not _PACKAGE_DONE:
        files.update(_package_files())
        _PACKAGE_DONE = True
    files.update(f for f in _model_files() if f not in _CHECKED)
    files -= _CHECKED
    if not files:
        return
    _CHECKED.update(files)
    current = {f: _stamp(f) for f in files}
    for path in _core_cache_paths():
        record_file = os.path.join(path, STAMP_NAME)
        try:
            with open(record_file, encoding="utf-8") as fh:
                recorded = json.load(fh)
            if not isinstance(recorded, dict):
                recorded = {}
        except (OSError, ValueError):
            recorded = {}
        stale = any(f in recorded and recorded[f] != s for f, s in current.items())
        if not recorded and glob.glob(os.path.join(path, "core.*.nbi")):
            stale = True  # code cached before any stamp was recorded: unknown provenance
        if stale:
            for f in glob.glob(os.path.join(path, "core.*.nb[ic]")):
                try:
                    os.remove(f)
                except OSError:
                    pass
            recorded = {}
        changed = stale or any(recorded.get(f) != s for f, s in current.items())
        if not changed:
            continue
        recorded.update(current)
        try:
            os.makedirs(path, exist_ok=True)
            tmp = f"{record_file}.{os.getpid()}.tmp"
            with open(tmp, "w", encoding="utf-8") as fh:
                json.dump(recorded, fh)
            os.replace(tmp, record_file)
        except OSError:
            pass
