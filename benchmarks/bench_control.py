"""Control design on the E-clutch: cost of trim, linearisation and a controller in the loop.

Measures (medians of repeated runs after the kernels are loaded, min-max in brackets):

* ``EClutch.operating_point(4 mm)``: the position-controlled settle (0.5 s) plus Newton's method;
* ``linearize`` of that point (motor voltage -> bearing position), central differences over 20 states;
* ``closed_loop``: 1 s of the nonlinear E-clutch with a discrete PI at 1 kHz (1,000 samples), adaptive
  and in the core's fixed-step mode at 1 ms; the share of the compiled model (``Simulation.advance``'s
  compiled call) in the loop's time, from a profile.

No SciPy reference: python-control cannot integrate the E-clutch (an index-1 DAE with events); the
loop's own overhead against the compiled model is the figure of interest.

Run: ``python benchmarks/bench_control.py``.
"""

from __future__ import annotations

import platform
import statistics
import time

import numpy as np


def _timed(fn, repeat):
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return statistics.median(out), min(out), max(out)


def main(repeat: int = 11) -> None:
    from clutchlab.control import linearize
    from clutchlab.control.design import pi_for_phase_margin
    from clutchlab.control.loop import closed_loop
    from clutchlab.eclutch import EClutch

    ec = EClutch()
    op = ec.operating_point(4e-3)  # loads (or compiles) the kernels
    G = linearize(op, inputs=["motor_voltage"], outputs=["bearing_position"])
    C = pi_for_phase_margin(G, 5.0, 60.0).discrete(1e-3)
    run = dict(measure=["bearing_position"], actuate=["motor_voltage"], reference=4.2e-3)
    closed_loop(op, C, 1e-3, 1.0, **run)
    closed_loop(op, C, 1e-3, 1.0, fixed_step=1e-3, **run)
    print(f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, Python {platform.python_version()}")
    for label, fn in (
        ("operating point at 4 mm", lambda: ec.operating_point(4e-3)),
        ("linearize (20 states)", lambda: linearize(op, inputs=["motor_voltage"], outputs=["bearing_position"])),
        ("closed loop 1 s at 1 kHz, adaptive", lambda: closed_loop(op, C, 1e-3, 1.0, **run)),
        ("closed loop 1 s at 1 kHz, fixed step 1 ms", lambda: closed_loop(op, C, 1e-3, 1.0, fixed_step=1e-3, **run)),
    ):
        med, lo, hi = _timed(fn, repeat)
        print(f"{label}: {1e3 * med:.1f} ms ({1e3 * lo:.1f}-{1e3 * hi:.1f}), medians of {repeat}")
    import cProfile
    import pstats

    prof = cProfile.Profile()
    prof.enable()
    closed_loop(op, C, 1e-3, 1.0, **run)
    prof.disable()
    stats = pstats.Stats(prof)
    total = sum(v[2] for v in stats.stats.values())
    compiled = sum(v[2] for k, v in stats.stats.items() if k[2] == "advance" and "kernels" in k[0])
    print(f"share of the compiled model in the adaptive loop's time: {100 * compiled / total:.0f} %")


if __name__ == "__main__":
    main()
