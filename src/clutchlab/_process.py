"""Child processes that end with the process that started them, even when it is killed with SIGKILL.

The sweep's worker processes (:mod:`clutchlab.sweep.runner`) and the demo's and ``clutchlab warmup``'s
compile processes (:mod:`clutchlab.warmup`) call :func:`die_with_parent` first thing: a parent killed with
SIGKILL runs no ``finally`` that could stop them.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

__all__ = ["PR_SET_PDEATHSIG", "die_with_parent"]

PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def die_with_parent(parent_pid: int, poll: float = 0.5, name: str = "clutchlab-parent-watchdog") -> None:
    """End this process when ``parent_pid`` dies, even by SIGKILL.

    On Linux the kernel sends SIGKILL on the parent's death
    (``prctl(PR_SET_PDEATHSIG)``; it is the death of the parent's *thread* that started this process, so
    start such processes from a thread that lives as long as they should); everywhere a daemon thread
    (named ``name``) also polls the parent pid every ``poll`` seconds (``os.getppid`` changes when the
    process is re-parented) and exits.  If the parent is already gone, exit at once.
    """
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # pragma: no cover - no prctl: the watchdog remains
            pass
    if os.getppid() != parent_pid:
        os._exit(1)

    def watch():
        while True:
            time.sleep(poll)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name=name, daemon=True).start()
