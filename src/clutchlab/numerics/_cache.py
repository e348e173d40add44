"""Keep the core's cached machine code in step with the models compiled into it.

numba checks only the source file of a cached function.  The core's
specialisations (:mod:`clutchlab.numerics.core`) contain each model's
equations, compiled in through :mod:`clutchlab.numerics.dispatch`; after an
edit of a model file, numba would happily load the old machine code.  Before
the first core call in a process, :func:`ensure_fresh` compares a stamp of
every source file of the package (path, size, modification time) with the
stamp stored beside the core's cache; if they differ it deletes the core's
cache files, so the core recompiles with the current models.  An installed
package never changes, so this costs one ``stat`` per file (about 1 ms).
"""

from __future__ import annotations

import glob
import hashlib
import os
from pathlib import Path

__all__ = ["ensure_fresh", "source_stamp"]

_DONE = False
_STAMP_NAME = "clutchlab-core-sources.stamp"


def source_stamp() -> str:
    """Hash of (relative path, size, mtime) of every ``.py`` file of the clutchlab package."""
    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha1()
    for path in sorted(root.rglob("*.py")):
        try:
            st = path.stat()
        except OSError:
            continue
        digest.update(f"{path.relative_to(root)}|{st.st_size}|{st.st_mtime_ns}\n".encode())
    return digest.hexdigest()


def _core_dispatchers():
    from . import core

    return [obj for obj in vars(core).values() if hasattr(obj, "_cache") and hasattr(obj, "py_func")
            and getattr(obj.py_func, "__module__", "") == core.__name__]


def ensure_fresh() -> None:
    """Delete the core's cached code if any clutchlab source changed since it was compiled (once per process)."""
    global _DONE
    if _DONE:
        return
    _DONE = True
    stamp = source_stamp()
    dispatchers = _core_dispatchers()
    paths = set()
    for d in dispatchers:
        path = getattr(d._cache, "_cache_path", None)
        if path:
            paths.add(path)
    for path in paths:
        stamp_file = os.path.join(path, _STAMP_NAME)
        try:
            with open(stamp_file, encoding="ascii") as fh:
                old = fh.read().strip()
        except OSError:
            old = None
        if old == stamp:
            continue
        if old is not None or glob.glob(os.path.join(path, "core.*.nbi")):
            for f in glob.glob(os.path.join(path, "core.*.nb[ic]")):
                try:
                    os.remove(f)
                except OSError:
                    pass
        try:
            os.makedirs(path, exist_ok=True)
            tmp = f"{stamp_file}.{os.getpid()}.tmp"
            with open(tmp, "w", encoding="ascii") as fh:
                fh.write(stamp)
            os.replace(tmp, stamp_file)
        except OSError:
            pass
