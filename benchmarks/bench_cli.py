"""Start-up of the command line: ``clutchlab --help`` and friends, against Python's own start.

Run: ``python benchmarks/bench_cli.py [--quick]``.

Each command runs in a fresh process (``sys.executable -m clutchlab ...``), output discarded; the figure is
the wall time of the whole process, median and min-max of the repeats, next to ``python -c pass`` (the
floor) and ``python -c "import numpy"``.  ``clutchlab --help`` builds one line per command and imports no
model (tests/test_cli_help.py checks the imports); a command's own help imports its subsystem.
"""

from __future__ import annotations

import platform
import statistics
import subprocess
import sys
import time

RUNS = (
    ("python -c pass", [sys.executable, "-c", "pass"]),
    ("python -c 'import numpy'", [sys.executable, "-c", "import numpy"]),
    ("clutchlab --help", [sys.executable, "-m", "clutchlab", "--help"]),
    ("clutchlab --version", [sys.executable, "-m", "clutchlab", "--version"]),
    ("clutchlab driveline --help", [sys.executable, "-m", "clutchlab", "driveline", "--help"]),
    ("clutchlab eclutch --help", [sys.executable, "-m", "clutchlab", "eclutch", "--help"]),
)


def main(quick: bool = False):
    repeat = 5 if quick else 21
    print(f"command-line start-up; {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"medians of {repeat} fresh processes (min-max)")
    for label, cmd in RUNS:
        subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)  # warm the file cache
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
            times.append(time.perf_counter() - t0)
        print(f"  {label:30s} {statistics.median(times) * 1e3:7.1f} ms ({min(times) * 1e3:.1f}-{max(times) * 1e3:.1f})")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
