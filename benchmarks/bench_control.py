"""Control design on the E-clutch: cost of trim, linearisation and a controller in the loop.

Measures (medians of repeated runs after the kernels are loaded, min-max in brackets):

* ``EClutch.operating_point(4 mm)``: the position-controlled settle (0.5 s) plus Newton's method;
* ``linearize`` of that point (motor voltage -> bearing position), central differences over 20 states;
* ``closed_loop``: 1 s of the nonlinear E-clutch with a discrete PI at 1 kHz (1,000 samples), adaptive
  and in the core's fixed-step mode at 1 ms, in the compiled loop (the default for an LTI controller) and
  in the Python loop (``compiled=False``: one ``Simulation.advance`` per sample); the same PI written as a
  ``numba.njit`` function (compiled loop, through its C entry).

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
    import numba

    Cs = __import__("control").ss(C)
    a, b, c, d = (float(np.squeeze(M)) for M in (Cs.A, Cs.B, Cs.C, Cs.D))
    u_op = float(op.u[op.system.input_index("motor_voltage")])

    @numba.njit
    def pi(t, y, memory):  # the same discrete PI as a function: memory[0] its state
        e = 4.2e-3 - y[0]
        out = u_op + c * memory[0] + d * e
        memory[0] = a * memory[0] + b * e
        return np.array([out])

    frun = dict(measure=["bearing_position"], actuate=["motor_voltage"], memory=[0.0])
    for compiled in (True, False):
        closed_loop(op, C, 1e-3, 1.0, compiled=compiled, **run)
        closed_loop(op, C, 1e-3, 1.0, fixed_step=1e-3, compiled=compiled, **run)
    closed_loop(op, pi, 1e-3, 1.0, **frun)
    print(f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, Python {platform.python_version()}")
    for label, fn in (
        ("operating point at 4 mm", lambda: ec.operating_point(4e-3)),
        ("linearize (20 states)", lambda: linearize(op, inputs=["motor_voltage"], outputs=["bearing_position"])),
        ("closed loop 1 s at 1 kHz, adaptive, compiled loop", lambda: closed_loop(op, C, 1e-3, 1.0, **run)),
        ("closed loop 1 s at 1 kHz, adaptive, Python loop",
         lambda: closed_loop(op, C, 1e-3, 1.0, compiled=False, **run)),
        ("closed loop 1 s at 1 kHz, fixed step 1 ms, compiled loop",
         lambda: closed_loop(op, C, 1e-3, 1.0, fixed_step=1e-3, **run)),
        ("closed loop 1 s at 1 kHz, fixed step 1 ms, Python loop",
         lambda: closed_loop(op, C, 1e-3, 1.0, fixed_step=1e-3, compiled=False, **run)),
        ("closed loop 1 s at 1 kHz, adaptive, numba function controller", lambda: closed_loop(op, pi, 1e-3, 1.0, **frun)),
    ):
        med, lo, hi = _timed(fn, repeat)
        print(f"{label}: {1e3 * med:.1f} ms ({1e3 * lo:.1f}-{1e3 * hi:.1f}), medians of {repeat}")
    fast = closed_loop(op, C, 1e-3, 1.0, **run).frame
    slow = closed_loop(op, C, 1e-3, 1.0, compiled=False, **run).frame
    func = closed_loop(op, pi, 1e-3, 1.0, **frun).frame
    print("compiled and Python loops: largest bearing-position difference "
          f"{np.max(np.abs(fast['bearing_position_m'] - slow['bearing_position_m'])):.2e} m; the function "
          f"controller {np.max(np.abs(fast['bearing_position_m'] - func['bearing_position_m'])):.2e} m")

if __name__ == "__main__":
    main()
