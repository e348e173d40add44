"""First run on a fresh machine: how long `clutchlab demo` spends compiling numba kernels.

Runs ``clutchlab demo`` twice in subprocesses sharing one empty numba cache folder
(``NUMBA_CACHE_DIR``): the first run compiles every kernel the demo uses (what a user sees on a fresh
machine), the second loads them from the cache.  The time the first run spends compiling is the
difference of the two wall times (the demo compiles its last section's kernels in a background process
while the first sections run, see clutchlab/warmup.py, so the compile time inside the main process alone,
also printed, undercounts the work).

Usage: ``python benchmarks/bench_compile.py``  (takes a few minutes on a 2-core machine).
Goal (issue #12): at most 45 s of compiling on the project's 2-core machine.
"""

from __future__ import annotations

import os
import platform
import re
import subprocess
import sys
import tempfile
import time


def run_demo(cache_dir: str, out_dir: str) -> tuple[float, float]:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir, CLUTCHLAB_COMPILE_REPORT="1", MPLBACKEND="Agg")
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "clutchlab", "demo", "-o", out_dir, "--force"], env=env,
                          capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"clutchlab demo failed:\n{proc.stderr[-2000:]}")
    match = re.findall(r"compile seconds ([0-9.]+)", proc.stderr)
    return wall, float(match[-1]) if match else float("nan")


def main() -> None:
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}")
    with tempfile.TemporaryDirectory() as tmp:
        cache = os.path.join(tmp, "numba-cache")
        cold_wall, cold_compile = run_demo(cache, os.path.join(tmp, "demo1"))
        warm_wall, warm_compile = run_demo(cache, os.path.join(tmp, "demo2"))
    spent = cold_wall - warm_wall
    print(f"first run (empty numba cache): {cold_wall:6.1f} s wall ({cold_compile:5.1f} s compiling in the main process)")
    print(f"second run (cache warm):       {warm_wall:6.1f} s wall ({warm_compile:5.1f} s compiling)")
    print(f"time the first run spends compiling (wall difference): {spent:6.1f} s")
    print(f"goal: <= 45 s compiling on the first run -> {'met' if spent <= 45 else 'NOT met'}")


if __name__ == "__main__":
    main()
