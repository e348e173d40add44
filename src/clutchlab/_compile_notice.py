"""Tell the user, once per process, that clutchlab's compiled kernels are being built.

clutchlab's hot loops are numba functions compiled on first use and cached on
disk (``cache=True``), so the first run on a fresh machine (or after an upgrade)
spends tens of seconds compiling and later runs load the machine code in a
fraction of a second.  Without a word that first run looks like a hang.

numba announces every real compilation (never a load from its cache) as a
``numba:compile`` event.  :func:`install` registers one listener for it:

- the first compilation of a clutchlab function in a process prints
  :data:`NOTICE` on stderr (why the run is slow, and that it happens once);
- every later compilation that is still running after :data:`ANNOUNCE_AFTER`
  seconds says what is compiling (``clutchlab: compiling driveline kernel
  (dopri): advance ...``), so a second model kind compiling for a minute does
  not look like a hang either;
- each compilation announced so says, when it ends, how long it took
  (``clutchlab: compiled ... in 23.4 s; numba caches it for later runs``);
- the wall time spent compiling clutchlab functions is accumulated so that
  reports can quote run times *after* compilation and the compile time on its
  own (:func:`compile_seconds`).

Compilations nest (a kernel compiles the functions it calls); only the
outermost is announced and timed.  Set the environment variable
``CLUTCHLAB_COMPILE_NOTICE=0`` to silence the lines.
"""

from __future__ import annotations

import os
import sys
import threading
import time

__all__ = ["install", "compile_seconds", "describe", "NOTICE", "ANNOUNCE_AFTER"]

#: the line printed (once per process) when clutchlab compiles its first kernel
NOTICE = (
    "clutchlab: compiling the numerical kernels for first use; this happens once "
    "(later runs load them from numba's cache)"
)

#: a compilation still running after this many seconds is announced with what is compiling [s]
ANNOUNCE_AFTER = 2.0

_lock = threading.Lock()
_state = {"installed": False, "announced": False, "depth": 0, "t0": 0.0, "seconds": 0.0, "what": "",
          "said": False, "generation": 0, "timer": None}


def describe(func) -> str:
    """What a compiling clutchlab function is, for people: ``driveline kernel (dopri): advance``.

    Parameters
    ----------
    func : function
        The Python function numba compiles (``dispatcher.py_func``).
    """
    module = getattr(func, "__module__", None) or ""
    name = getattr(func, "__qualname__", None) or getattr(func, "__name__", "?")
    prefix = "clutchlab.numerics._kernels.k_"
    if module.startswith(prefix):
        # a generated kernel module: k_<model module>_<params type>_<method>_<hash>
        parts = module[len(prefix):].split("_")[:-1]
        method = parts.pop() if parts and parts[-1] in ("dopri", "rodas", "fixed") else ""
        body = [p for p in parts if p not in ("clutchlab",) and not p[:1].isupper()]
        kind = " ".join(body) or "model"
        return f"{kind} ({method}): {name}" if method else f"{kind}: {name}"
    return f"{module.removeprefix('clutchlab.')}.{name}"


def _quiet() -> bool:
    return os.environ.get("CLUTCHLAB_COMPILE_NOTICE", "1") == "0"


def _say_compiling(generation: int) -> None:
    with _lock:
        if _state["generation"] != generation or _state["depth"] == 0 or _state["said"]:
            return
        _state["said"] = True
        what = _state["what"]
    print(f"clutchlab: compiling {what} ...", file=sys.stderr, flush=True)


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
            first = timer = None
            with _lock:
                if _state["depth"] == 0:
                    _state["t0"] = time.perf_counter()
                    _state["generation"] += 1
                    _state["what"] = describe(event.data["dispatcher"].py_func)
                    first = not _state["announced"]
                    _state["announced"] = True
                    _state["said"] = bool(first)
                    if not first and not _quiet():
                        timer = threading.Timer(ANNOUNCE_AFTER, _say_compiling, (_state["generation"],))
                        timer.daemon = True
                        _state["timer"] = timer
                _state["depth"] += 1
            if first and not _quiet():
                print(NOTICE, file=sys.stderr, flush=True)
            if timer is not None:
                timer.start()

        def on_end(self, event):
            if not _is_clutchlab(event):
                return
            done = None
            with _lock:
                _state["depth"] -= 1
                if _state["depth"] == 0:
                    took = time.perf_counter() - _state["t0"]
                    _state["seconds"] += took
                    if _state["timer"] is not None:
                        _state["timer"].cancel()
                        _state["timer"] = None
                    if _state["said"]:
                        done = f"clutchlab: compiled {_state['what']} in {took:.1f} s; numba caches it for later runs"
                    _state["said"] = False
            if done is not None and not _quiet():
                print(done, file=sys.stderr, flush=True)

    ev.register("numba:compile", _Listener())
    if os.environ.get("CLUTCHLAB_COMPILE_REPORT", "0") == "1":
        import atexit

        # benchmarks/bench_compile.py reads this line: total compile wall time of the process
        atexit.register(lambda: print(f"clutchlab: compile seconds {compile_seconds():.2f}", file=sys.stderr,
                                      flush=True))
