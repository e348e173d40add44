"""Shared pieces of the work-precision benchmarks (``wp_*.py``): timing, the machine, rows and the plot.

A work-precision curve is one series of (error, time) points per solver, one point per tolerance; the
error is measured against a tight-tolerance run of an independent solver, so that solvers are compared
at matched accuracy, not at matched ``rtol``.  Times are medians of repeated runs, quoted with their
min-max; every script prints the machine it ran on.
"""

from __future__ import annotations

import os
import platform
import statistics
import time
from dataclasses import dataclass, field


@dataclass
class Point:
    """One run of one solver at one tolerance: its error and its wall times [s]."""

    rtol: float
    error: float
    times: list
    note: str = ""

    @property
    def median(self) -> float:
        return statistics.median(self.times)


@dataclass
class Series:
    """One solver's work-precision curve."""

    label: str
    points: list = field(default_factory=list)


def machine() -> str:
    """The machine, as quoted in ``benchmarks/README.md``."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"load {load:.2f} at the start")


def timed(fn, repeat: int):
    """Run ``fn`` ``repeat`` times; returns (wall times [s], the last result)."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return times, out


def row(label: str, p: Point, t_end: float) -> str:
    """One printed row: tolerance, error, median time (min-max) and speed against real time."""
    med = p.median
    return (f"  {label:34s} rtol {p.rtol:7.0e}  error {p.error:8.1e}  {med * 1e3:10.3f} ms "
            f"({min(p.times) * 1e3:.3f}-{max(p.times) * 1e3:.3f})  {t_end / med:9.0f}x real time"
            + (f"  {p.note}" if p.note else ""))


def ratio_at_matched_error(fast: Series, slow: Series):
    """For each point of ``fast``: the median time of the cheapest point of ``slow`` whose error is at
    most the ``fast`` point's, divided by the ``fast`` point's; ``None`` where ``slow`` never got that
    accurate.  Returns a list of (error, ratio or None)."""
    out = []
    for p in fast.points:
        cands = [q.median for q in slow.points if q.error <= p.error]
        out.append((p.error, min(cands) / p.median if cands else None))
    return out


def plot(series, path, title: str, error_label: str) -> None:
    """Work-precision plot: time [ms] against error, log-log, one line per series."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for s in series:
        pts = sorted((p for p in s.points if p.error > 0), key=lambda p: p.error)
        if not pts:
            continue
        ax.loglog([p.error for p in pts], [p.median * 1e3 for p in pts], "o-", label=s.label)
    ax.set_xlabel(error_label)
    ax.set_ylabel("wall time, median [ms]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"\nwrote {path}")


def cheapest_at_error(series: Series, error: float):
    """The point of ``series`` with the lowest median time among those whose error is at most ``error``
    (``None`` if no point is that accurate): a solver's cost at a fixed error level."""
    cands = [p for p in series.points if p.error <= error]
    return min(cands, key=lambda p: p.median) if cands else None
