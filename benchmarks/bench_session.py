"""Cost of one call into a running session: co-simulation ``do_step`` and ``Simulation.advance``/``outputs``.

* the wet co-simulation (:class:`clutchlab.fmu.cosim.WetCoSimulation`, free inertia, 3 kN held), 450
  communication steps of 1 ms: wall time per ``do_step`` (the compiled step plus clutchlab's Python around
  it: input checks, the session call, the outputs as a dict of 24 values);
* the E-clutch held at 4 mm (``EClutch.operating_point``): ``Simulation.advance`` to the time it is already
  at (nothing to integrate: the call's own cost) and ``Simulation.outputs``.

Medians of 15 rounds with min-max.  Run: ``python benchmarks/bench_session.py``.
"""

from __future__ import annotations

import platform
import statistics
import time


def _rounds(fn, n=15):
    fn()
    out = [fn() for _ in range(n)]
    return f"{1e6 * statistics.median(out):.2f} µs ({1e6 * min(out):.2f}-{1e6 * max(out):.2f})"


def main() -> None:
    from clutchlab.eclutch import EClutch
    from clutchlab.fmu.cosim import WetCoSimulation
    from clutchlab.system import Simulation

    def wet_run():
        c = WetCoSimulation(**{"scenario.free_inertia": 1.0})
        inp = {"force_reference": 3000.0}
        c.initial_outputs(inp)
        t0 = time.perf_counter()
        for k in range(450):
            c.do_step(k * 1e-3, 1e-3, inp)
        return (time.perf_counter() - t0) / 450

    op = EClutch().operating_point(4e-3)
    sim = Simulation(op.start())
    sim.advance(1e-3)

    def idle_advance():
        t0 = time.perf_counter()
        for _ in range(2000):
            sim.advance(1e-3)
        return (time.perf_counter() - t0) / 2000

    def outputs():
        t0 = time.perf_counter()
        for _ in range(2000):
            sim.outputs()
        return (time.perf_counter() - t0) / 2000

    print(f"machine: {platform.machine()}, Python {platform.python_version()}")
    print(f"wet do_step, 1 ms communication step: {_rounds(wet_run)}")
    print(f"E-clutch Simulation.advance with nothing to integrate: {_rounds(idle_advance)}")
    print(f"E-clutch Simulation.outputs: {_rounds(outputs)}")


if __name__ == "__main__":
    main()
