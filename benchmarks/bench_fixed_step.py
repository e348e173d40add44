"""Benchmark: the fixed-step (real-time, HIL frame) mode of the integrator core.

For frames of 0.1, 0.2, 0.5, 1 and 2 ms, on

* the E-clutch (actuator + Model 4, stick-slip seals) under position control, released by 7 mm and
  re-engaged (the input of ``bench_eclutch_dynamics.py``), 1 s;
* the wet engagement (bench protocol b: piston stop, film contact, lock-up), 1 s;

measures

1. the error against a tight adaptive run (rtol 1e-10) at the frame ends
   (:func:`clutchlab.control.realtime.fixed_step_error`: the largest error of the chosen states divided by
   their largest magnitude; the E-clutch's bearing position, the wet clutch's slip speed, piston position
   and pack temperature), and the absolute error of the first of them;
2. the wall time per frame of a co-simulation advanced one frame at a time
   (:func:`clutchlab.control.realtime.time_steps`): median, 99th percentile and worst, over ``REPEATS``
   runs (printed as the median of the runs' figures with their min-max);
3. a work--precision plot, written to ``benchmarks/fixed_step.png``: error against the frame and against
   the median time per frame.

Run:  python benchmarks/bench_fixed_step.py [--quick]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import clutchlab.wet.system  # noqa: F401  (registers "wet")
from clutchlab.control.realtime import DEFAULT_FRAMES, fixed_step_error, time_steps
from clutchlab.eclutch import EClutch
from clutchlab.system import MODELS

T_END = 1.0
RAMP = {"bearing_reference": ([0.0, 0.1, 0.3, 0.6, 0.8], [0.0, 0.0, 7e-3, 7e-3, 0.0])}
REPEATS = 5


def cases():
    return [("E-clutch (position control)", EClutch().as_system(RAMP), ["bearing_position"], "bearing_position_m",
             1e6, "um"),
            ("wet engagement", MODELS["wet"](), ["slip_speed", "piston_position", "temperature"], "slip_speed_rad_s",
             1.0, "rad/s")]


def main(quick: bool = False):
    repeats = 2 if quick else REPEATS
    t_end = 0.3 if quick else T_END
    results = {}
    for name, system, states, column, factor, unit in cases():
        err = fixed_step_error(system, t_end, DEFAULT_FRAMES, states=states)
        rows = []
        for _, row in err.iterrows():
            h = row["frame_s"]
            runs = [time_steps(system, t_end, h) for _ in range(repeats)]
            fig = {k: np.array([getattr(r, k) for r in runs]) for k in ("median", "p99", "worst", "mean_in_run")}
            rows.append((h, row["error"], row[column] * factor, row["rhs_per_step"], fig))
        results[name] = rows
        print(f"\n{name}, {t_end:g} s; error against adaptive rtol 1e-10 (worst relative over {', '.join(states)}; "
              f"{column} absolute in {unit}); wall time per frame in us: median of {repeats} runs [min-max]")
        print(f"{'frame ms':>8} {'rel. error':>10} {'abs ' + unit:>10} {'rhs/step':>8} {'median':>18} {'p99':>18} "
              f"{'worst':>20} {'in-run mean':>18}")
        for h, e, a, nr, fig in rows:
            cells = []
            for k in ("median", "p99", "worst", "mean_in_run"):
                v = fig[k] * 1e6
                cells.append(f"{np.median(v):6.1f} [{v.min():.1f}-{v.max():.1f}]")
            print(f"{h * 1e3:8.1f} {e:10.2e} {a:10.3g} {nr:8.0f} {cells[0]:>18} {cells[1]:>18} {cells[2]:>20} "
                  f"{cells[3]:>18}")
    _plot(results, Path(__file__).with_name("fixed_step.png"))


def _plot(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for name, rows in results.items():
        h = np.array([r[0] for r in rows]) * 1e3
        e = np.array([r[1] for r in rows])
        med = np.array([np.median(r[4]["median"]) for r in rows]) * 1e6
        p99 = np.array([np.median(r[4]["p99"]) for r in rows]) * 1e6
        line, = ax1.loglog(h, e, "o-", label=name)
        ax2.loglog(med, e, "o-", color=line.get_color(), label=f"{name}: median")
        ax2.loglog(p99, e, "x:", color=line.get_color(), label=f"{name}: 99 %")
    ax1.set_xlabel("frame (fixed step) [ms]")
    ax1.set_ylabel("error against adaptive rtol 1e-10 (relative)")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=8)
    ax2.set_xlabel("wall time per frame [us]")
    ax2.set_ylabel("error (relative)")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=7)
    fig.suptitle("clutchlab fixed-step mode (Rodas3): work-precision, 1 s runs")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"\nwrote {path}")


if __name__ == "__main__":
    main("--quick" in sys.argv)
