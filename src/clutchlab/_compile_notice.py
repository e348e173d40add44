"""Tell the user, once per process, that clutchlab's compiled kernels are being built.

clutchlab's hot loops are numba functions compiled on first use and cached on
disk (``cache=True``), so the first run on a fresh machine (or after an upgrade)
spends tens of seconds compiling and later runs load the machine code in a
fraction of a second.  Without a word that first run looks like a hang.

numba announces every real compilation (never a load from its cache) as a
``numba:compile`` event.  :func:`install` registers one listener for it; the
first compilation of a clutchlab function prints a single line on stderr, and
the wall time spent compiling clutchlab functions is accumulated so that
reports can quote run times *after* compilation and the compile time on its own
(:func:`compile_seconds`).

Set the environment variable ``CLUTCHLAB_COMPILE_NOTICE=0`` to silence the line.
"""

from __future__ import annotations

import os
import sys
import threading
import time

__all__ = ["install", "compile_seconds", "NOTICE"]

#: the line printed (once per process) when clutchlab compiles its first kernel
NOTICE = (
    "clutchlab: compiling the numerical kernels for first use; this happens once "
    "(later runs load them from numba's cache)"
)

_lock = threading.Lock()
_state = {"installed": False, "announced": False, "depth": 0, "t0": 0.0, "seconds": 0.0}


def compile_seconds() -> float:
    """Wall time [s] this process has spent compiling clutchlab kernels so far."""
    return _state["seconds"]


def _is_clutchlab(event) -> bool:
    disp = (event.data or {}).get("dispatcher")
    func = getattr(disp, "py_func", None)
    # a function made by exec (numbalsoda's, for one) has __module__ None
    return (getattr(func, "__module__", None) or "").startswith("clutchlab.")


def install() -> None:
    """Register the compile listener (idempotent; compiles nothing)."""
    with _lock:
        if _state["installed"]:
            return
        _state["installed"] = True
    from numba.core import event as ev

    class _Listener(ev.Listener):
        # compilations nest (a kernel compiles the functions it calls): time the outermost one
        def on_start(self, event):
            if not _is_clutchlab(event):
                return
            with _lock:
                if _state["depth"] == 0:
                    _state["t0"] = time.perf_counter()
                _state["depth"] += 1
                announce = not _state["announced"]
                _state["announced"] = True
            if announce and os.environ.get("CLUTCHLAB_COMPILE_NOTICE", "1") != "0":
                print(NOTICE, file=sys.stderr, flush=True)

        def on_end(self, event):
            if not _is_clutchlab(event):
                return
            with _lock:
                _state["depth"] -= 1
                if _state["depth"] == 0:
                    _state["seconds"] += time.perf_counter() - _state["t0"]

    ev.register("numba:compile", _Listener())
    if os.environ.get("CLUTCHLAB_COMPILE_REPORT", "0") == "1":
        import atexit

        # benchmarks/bench_compile.py reads this line: total compile wall time of the process
        atexit.register(lambda: print(f"clutchlab: compile seconds {compile_seconds():.2f}", file=sys.stderr,
                                      flush=True))
