"""Cost of one call into a running session: a co-simulation step, ``Simulation.advance``/``outputs``.

What is measured (medians of 15 rounds, min-max in brackets, microseconds per call):

* **co-simulation step** of each model's co-simulation (:mod:`clutchlab.fmu.cosim`: wet bench with a free
  inertia and 3 kN held; EMTC drum bench, 300 N.m requested; E-clutch at a 4 mm bearing reference; the
  CoupledClutches driveline of ``examples/``), 1 ms communication steps after the first two:

  - ``do_step_array``: what the FMU slave calls at every ``fmi2DoStep`` (inputs and outputs as sequences);
  - ``do_step``: the Python API, inputs and outputs as dicts;
  - ``compiled``: the compiled work of the same steps alone -- the model's ``session`` entry (advance, then
    the outputs gathered; :mod:`clutchlab.numerics.session`) called for the same end times from a compiled
    loop, on a second co-simulation in the same state; its final state is checked equal, bit for bit;
  - **own Python part** = ``do_step_array`` - ``compiled``, per round (the median and range of the
    differences): everything that is not the compiled integration -- the checks of the step and of the
    inputs, writing the held inputs, the Python-to-compiled call (arguments in, status out), the event
    check, the return.  Goal of issue #14: <= 3 us.

* **E-clutch session held at 4 mm** (``EClutch.operating_point``): ``Simulation.advance`` to the time it
  is already at (nothing to integrate; the core still calls the model's ``restart`` and one right-hand
  side) and ``Simulation.outputs``, each with the same call from a compiled loop and the difference.

* **FMU slave** (pythonfmu's ``Fmi2Slave`` of the wet FMU, in process, without a host): ``do_step`` as
  pythonfmu calls it, which hands the step to clutchlab's model thread (docs/fmu.md, "Exit"), and the
  step on the calling thread (``_step``), for the size of that hand-off.  Skipped without pythonfmu.

On a tree without the packed sessions (``Simulation.step``; before issue #14) the lines that need them
print "n/a".  Run: ``python benchmarks/bench_session.py [wet emtc eclutch driveline idle slave]`` (default: all).
"""

from __future__ import annotations

import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROUNDS = 15
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _fmt(values) -> str:
    return (f"{1e6 * statistics.median(values):6.2f} us ({1e6 * min(values):.2f}-{1e6 * max(values):.2f})"
            if values else "   n/a")


_DRIVE = []


def _drive():
    """A compiled loop calling a session's compiled entry for the end times ``ends`` (compiled once per run)."""
    if not _DRIVE:
        import numba

        @numba.njit
        def drive(session, handle, ends, what):
            code = 0
            for k in range(ends.shape[0]):
                code = session(handle, ends[k], what)
                if code != 0 and code != 3:
                    break
            return code

        _DRIVE.append(drive)
    return _DRIVE[0]


def _session(sim):
    """(compiled ``session`` dispatcher, handle) of a packed Simulation, or None (no packed sessions here)."""
    fast = getattr(sim, "_fast", None)
    if not fast or fast[1] is None:
        return None
    method = sim._method()
    return sim._core.entry_points(type(sim.system.params), method).session, fast[1]


def _compiled(sim, ends, what) -> float | None:
    found = _session(sim)
    if found is None:
        return None
    ends = np.asarray(ends, dtype=float)
    t0 = time.perf_counter()
    _drive()(found[0], found[1], ends, what)
    return (time.perf_counter() - t0) / max(len(ends), 1)


# ------------------------------------------------------------------ the co-simulations
class Case:
    """A co-simulation, fresh and one step in, stepped ``n`` times by 1 ms."""

    dt = 1e-3
    n = 450

    first = 2  # steps before the timed ones (with initial_outputs, the session packs at its third call)

    def make(self):
        c = self.build()
        c.initial_outputs(dict(zip((v.name for v in c.inputs), self.u)))
        for k in range(self.first):
            c.do_step(k * self.dt, self.dt, dict(zip((v.name for v in c.inputs), self.u)))
        return c

    def steps(self):
        return range(self.first, self.first + self.n)

    def ends(self):
        return [k * self.dt + self.dt for k in self.steps()]

    def sim(self, c):
        return c.simulation


class Wet(Case):
    name = "wet"
    u = [3000.0, 1500 * np.pi / 30]

    def build(self):
        from clutchlab.fmu.wet import WetCoSimulation

        return WetCoSimulation(**{"scenario.free_inertia": 1.0})


class Emtc(Case):
    name = "EMTC"
    u = [300.0, 0.1, 8.0, 7.7]

    def build(self):
        from clutchlab.fmu.emtc import EmtcCoSimulation

        return EmtcCoSimulation()

    def ends(self):  # the EMTC's own: a point within 1e-9 sample times of a controller sample is that sample
        ts = 2e-3
        out = []
        for t_end in super().ends():
            k = round(t_end / ts)
            out.append(k * ts if abs(k * ts - t_end) <= 1e-9 * ts else t_end)
        return out


class EClutchCase(Case):
    name = "E-clutch"
    u = [4e-3, 0.0]
    n = 200

    def build(self):
        from clutchlab.fmu.eclutch import EClutchCoSimulation

        return EClutchCoSimulation()


class Driveline(Case):
    name = "driveline"
    u = []
    n = 300

    def build(self):
        from clutchlab.fmu.driveline import DrivelineCoSimulation

        return DrivelineCoSimulation.for_description(EXAMPLES / "driveline_coupled_clutches.toml")()


def _steps(case, c, array: bool) -> float:
    dt, u = case.dt, case.u
    names = [v.name for v in c.inputs]
    if array:
        step = c.do_step_array
        t0 = time.perf_counter()
        for k in case.steps():
            step(k * dt, dt, u)
    else:
        step = c.do_step
        inputs = dict(zip(names, u))
        t0 = time.perf_counter()
        for k in case.steps():
            step(k * dt, dt, inputs)
    return (time.perf_counter() - t0) / case.n


def bench_cosimulation(case) -> None:
    arr, dic, comp, own = [], [], [], []
    for r in range(ROUNDS + 1):
        a = case.make()
        ta = _steps(case, a, True) if hasattr(a, "do_step_array") else None
        d = case.make()
        td = _steps(case, d, False)
        b = case.make()
        tb = _compiled(case.sim(b), case.ends(), 3)
        if ta is not None and tb is not None and not np.array_equal(case.sim(a).x, case.sim(b).x):
            raise AssertionError(f"{case.name}: the compiled loop did not take the same steps")
        if r == 0:
            continue  # (warm-up: compiles the compiled loop)
        dic.append(td)
        if ta is not None:
            arr.append(ta)
        if tb is not None:
            comp.append(tb)
            if ta is not None:
                own.append(ta - tb)
    print(f"{case.name:9s} do_step_array {_fmt(arr)} | do_step (dicts) {_fmt(dic)} | compiled {_fmt(comp)} "
          f"| own Python part {_fmt(own)}")


# ------------------------------------------------------------------ an E-clutch session with nothing to do
def bench_idle() -> None:
    from clutchlab.eclutch import EClutch
    from clutchlab.system import Simulation

    op = EClutch().operating_point(4e-3)
    sim = Simulation(op.start())
    sim.advance(1e-3)
    sim.outputs()
    n = 2000
    ends = np.full(n, 1e-3)

    def loop(fn, *args):
        t0 = time.perf_counter()
        for _ in range(n):
            fn(*args)
        return (time.perf_counter() - t0) / n

    rows = {"advance": ([], [], []), "outputs": ([], [], [])}
    for r in range(ROUNDS + 1):
        for name, fn, args, what in (("advance", sim.advance, (1e-3,), 1), ("outputs", sim.outputs, (), 2)):
            tp = loop(fn, *args)
            tc = _compiled(sim, ends, what)
            if r:
                rows[name][0].append(tp)
                if tc is not None:
                    rows[name][1].append(tc)
                    rows[name][2].append(tp - tc)
    for name, (tp, tc, own) in rows.items():
        label = f"Simulation.{name}" + (" (nothing to integrate)" if name == "advance" else "")
        print(f"E-clutch {label:42s} {_fmt(tp)} | compiled {_fmt(tc)} | own Python part {_fmt(own)}")


# ------------------------------------------------------------------ the FMU slave in process
def bench_slave() -> None:
    try:
        from clutchlab.fmu.export import _slave_base
        base = _slave_base()
    except ImportError:
        print("FMU slave: pythonfmu not installed, skipped")
        return

    class Slave(base):
        model_key = "wet"

    def run(on_thread: bool):
        s = Slave(instance_name="bench")
        s.values["scenario.free_inertia"] = 1.0
        force = next(vr for vr, v in s.vars.items() if v.name == "force_reference")
        s.set_real([force], [3000.0])
        s.exit_initialization_mode()
        outs = [vr for vr, v in s.vars.items() if v.causality.name == "output"]
        step = s.do_step if on_thread else s._step
        step(0.0, 1e-3)
        step(1e-3, 1e-3)  # (the session packs at its third call)
        t0 = time.perf_counter()
        for k in range(2, 452):
            if not step(k * 1e-3, 1e-3):
                raise AssertionError("the slave refused a step")
            s.get_real(outs)
        return (time.perf_counter() - t0) / 450

    on, off = [], []
    for r in range(ROUNDS + 1):
        a, b = run(True), run(False)
        if r:
            on.append(a)
            off.append(b)
    print(f"wet FMU slave do_step + get_real (24 outputs), on the model thread {_fmt(on)} | on the calling "
          f"thread {_fmt(off)}")


def main() -> None:
    import clutchlab

    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"clutchlab from {Path(clutchlab.__file__).parent}")
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    parts = {"wet": lambda: bench_cosimulation(Wet()), "emtc": lambda: bench_cosimulation(Emtc()),
             "eclutch": lambda: bench_cosimulation(EClutchCase()), "driveline": lambda: bench_cosimulation(Driveline()),
             "idle": bench_idle, "slave": bench_slave}
    chosen = sys.argv[1:] or list(parts)
    unknown = [p for p in chosen if p not in parts]
    if unknown:
        raise SystemExit(f"unknown part {unknown[0]!r} (parts: {', '.join(parts)})")
    for name in chosen:
        parts[name]()
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
