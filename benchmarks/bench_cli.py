"""Start-up of the command line: ``clutchlab --help`` and friends, against Python's own start.

Run: ``python benchmarks/bench_cli.py [--quick]``.

Each command runs in a fresh process (``sys.executable -m clutchlab ...``), output discarded; the figure is
the wall time of the whole process, median and min-max of the repeats, next to ``python -c pass`` (the
floor), ``python -c "import numpy"`` and ``python -c "import numpy, pandas, numba"``; and a warm
``clutchlab driveline simulate examples/driveline_coupled_clutches.toml`` against the last (issue #31: at most
1.3 times).  ``clutchlab --help`` builds one line per command and imports no
model (tests/test_cli_help.py checks the imports); a command's own help imports its subsystem.
"""

from __future__ import annotations

import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_OUT = Path(tempfile.mkdtemp(prefix="clutchlab_bench_cli_")) / "cc.csv"
_EXAMPLE = str(Path(__file__).resolve().parents[1] / "examples" / "driveline_coupled_clutches.toml")
#: issue #31's reference: a warm driveline run against the imports any such tool pays
_IMPORTS = "python -c 'import numpy, pandas, numba'"
_WARM_RUN = "clutchlab driveline simulate (warm)"
RUNS = (
    ("python -c pass", [sys.executable, "-c", "pass"]),
    ("python -c 'import numpy'", [sys.executable, "-c", "import numpy"]),
    (_IMPORTS, [sys.executable, "-c", "import numpy, pandas, numba"]),
    (_WARM_RUN, [sys.executable, "-m", "clutchlab", "driveline", "simulate", _EXAMPLE, "-o", str(_OUT), "--force"]),
    ("clutchlab --help", [sys.executable, "-m", "clutchlab", "--help"]),
    ("clutchlab --version", [sys.executable, "-m", "clutchlab", "--version"]),
    ("clutchlab driveline --help", [sys.executable, "-m", "clutchlab", "driveline", "--help"]),
    ("clutchlab eclutch --help", [sys.executable, "-m", "clutchlab", "eclutch", "--help"]),
)


def main(quick: bool = False):
    repeat = 5 if quick else 21
    print(f"command-line start-up; {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"medians of {repeat} fresh processes (min-max)")
    medians = {}
    for label, cmd in RUNS:
        # (a first run warms the file cache, and for the driveline run numba's and the unit conversions')
        subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
            times.append(time.perf_counter() - t0)
        medians[label] = statistics.median(times)
        print(f"  {label:40s} {medians[label] * 1e3:7.1f} ms ({min(times) * 1e3:.1f}-{max(times) * 1e3:.1f})")
    print(f"  warm driveline run / imports: {medians[_WARM_RUN] / medians[_IMPORTS]:.2f} (issue #31's goal: <= 1.3)")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
