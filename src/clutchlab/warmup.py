"""Compile clutchlab's numba kernels ahead of use, in parallel processes.

clutchlab's kernels are compiled on first use and cached on disk (numba's
``cache=True``; the integrator core's per-model entry points in
:func:`clutchlab.numerics.entry.kernel_dir`).  numba compiles one function at a
time in a process (a global compiler lock), so on a fresh machine the first run
of the demo spends most of its time compiling, on one core.  The kernels of the
models are independent: compiling each group in its own process uses every
core, and the processes share the cache on disk (numba writes its files
atomically), so the process that runs the model later loads them.

``clutchlab warmup`` compiles every group (``--jobs`` processes); ``clutchlab
demo`` compiles the groups of its later sections in a background process while
its first section runs (:func:`start`; they end with the process that started them, even one killed with
SIGKILL).  Each group exercises the same compiled
functions as its model's demo section, on tiny problems.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

from .errors import ParameterError, SimulationError

__all__ = ["GROUPS", "LOTS", "lots", "warm", "start", "run_parallel", "main"]


def _warm_eclutch() -> None:
    import numpy as np

    from .eclutch import ClutchModel, EClutch, EClutchParameters, FrictionParameters

    model = ClutchModel.preset(4, EClutchParameters())
    model.static_curve(np.linspace(0.0, 8e-3, 5))
    inputs = {"bearing_reference": ([0.0, 0.005, 0.01], [0.0, 1e-3, 1e-3])}
    EClutch(clutch=model, friction=FrictionParameters()).simulate(inputs, 0.01, output_step=1e-3)


def _warm_wet() -> None:
    from .wet import Bench, EngagementProtocol, ParametricFriction, WetClutch, simulate_engagement

    clutch = WetClutch.paper()
    scenario = EngagementProtocol(duration=0.05).scenario(clutch, "speed")
    simulate_engagement(clutch, scenario, bench=Bench(), friction=ParametricFriction.bench_truth())


def _warm_emtc() -> None:
    import numpy as np

    from .emtc.bench import BenchScenario, simulate_bench
    from .emtc.magnet import bundled_magnet

    model = bundled_magnet()
    u = np.linspace(0.0, 2.0, 20)
    model.simulate(u, airgap=0.8e-3)
    model.invert(np.linspace(100.0, 300.0, 20), airgap=0.8e-3)
    simulate_bench(model, BenchScenario(duration=0.01), controller_model=model).outputs  # (its last sample too)


def _warm_driveline() -> None:
    from .driveline import Driveline, Signal

    d = Driveline("warmup")
    d.inertia("J1", J=1.0, w0=1.0).inertia("J2", J=1.0)
    d.torque("T", "J1", Signal.sine(1.0, 5.0))
    d.clutch("c", "J1", "J2", fn_max=1.0, normal=Signal.step(1.0, 0.01))
    d.spring_damper("k", "J2", None, c=1.0, d=0.1)
    d.simulate(0.02, output_step=0.01)   # (its system() also prepares the kernels called through their addresses)


def _warm_components() -> None:
    # the components' own functions (wet clutches and EMTC couplings, any number and mix: their hooks and equations,
    # called through their addresses by the one kernel of every network, clutchlab.driveline.coupled, which the
    # driveline group compiles)
    from .driveline import Driveline, Signal

    d = Driveline("warmup_components")
    d.inertia("a", J=1.0, w0=10.0).inertia("b", J=1.0).inertia("c", J=1.0)
    d.wet_clutch("w", "a", "b", force=Signal.ramp(1000.0, 0.01))
    d.emtc("e", "b", "c")
    d.simulate(0.01, output_step=0.005)
    # the E-clutch with its actuator in the network: the network on Rodas3, the actuator's hooks (group
    # eclutch_network) and its run with a held reference (its pre-roll)
    d = Driveline("warmup_actuator")
    d.inertia("a", J=1.0, w0=10.0).inertia("b", J=1.0)
    d.eclutch("x", "a", "b", Signal.ramp(-1e-3, 0.01, offset=8e-3), actuator=True, pre_roll=0.01,
              actuator_in_network=True)
    d.simulate(0.01, rtol=1e-4, output_step=0.005)


def _warm_control() -> None:
    # what control design adds to the E-clutch's and the EMTC's kernels: the point evaluations of the
    # contract (right-hand side, outputs, analytic Jacobian) that trim and linearisation call
    import numpy as np

    from .eclutch import EClutch
    from .numerics.core import evaluate_jacobian
    from .system import evaluate

    system = EClutch().as_system({"voltage": 0.0}, held_input=True)
    evaluate(system)
    evaluate_jacobian(system.params, 0.0, system.x0, system.u0, system.m0, np.zeros((system.x0.size,) * 2))


#: compile groups: name -> function that runs the group's kernels once on a tiny problem
GROUPS = {"eclutch": _warm_eclutch, "wet": _warm_wet, "emtc": _warm_emtc, "driveline": _warm_driveline,
          "components": _warm_components, "control": _warm_control}


#: groups that compile many of the same functions, dealt to one process together and in this order, so that the later
#: ones load what the first compiled instead of compiling it again in another process at the same time: the
#: components' functions run in the driveline's one kernel (every network's; with the stuck-set solve and the event
#: iteration it calls), and the control group evaluates the E-clutch's and the EMTC's kernels (17 s alone, 2.4 s after them)
LOTS = (("driveline", "components"), ("eclutch", "emtc", "control"), ("wet",))

#: each group's first compilation after the groups before it in its lot [s of one core] (2-core VM, 2026-12-03, empty
#: cache, one process per lot; the driveline's and the components' scaled by the fifty-sixth session's measurement of
#: one kernel for every network, docs/architecture.md): how :func:`run_parallel` deals the lots to its processes
COSTS = {"driveline": 90.0, "components": 42.0, "emtc": 41.0, "eclutch": 36.0, "wet": 15.0, "control": 2.4}


def lots(names) -> list:
    """``names`` in lots (:data:`LOTS`: groups sharing functions together, in their order), each a list."""
    out = [[g for g in lot if g in names] for lot in LOTS]
    out += [[g] for g in names if not any(g in lot for lot in LOTS)]
    return [lot for lot in out if lot]


def _check(names) -> None:
    unknown = [g for g in names if g not in GROUPS]
    if unknown:
        raise ParameterError(f"unknown kernel group(s) {unknown}; known: {', '.join(GROUPS)}")


def warm(groups=None, full: bool = False) -> dict:
    """Compile (or load) the kernels of ``groups`` (default: all) in this process; seconds per group.

    ``full``: also the rare paths compiled only on their first call (:func:`clutchlab.numerics.outline.outlined`
    with ``lazy=True``: the driveline's repair of a stuck set over several null directions, its invariant check),
    so that no run compiles anything afterwards (``clutchlab warmup``).  Without it, each group compiles what its
    demo section runs (the demo's background processes)."""
    names = list(GROUPS) if groups is None else list(groups)
    _check(names)
    seconds = {}
    for name in names:
        t0 = time.perf_counter()
        GROUPS[name]()
        if full:
            from .numerics import outline

            outline.prepare(lazy=True, groups=None)   # (the lazy functions of the modules this group imported)
        seconds[name] = time.perf_counter() - t0
    return seconds


def start(groups, full: bool = False) -> subprocess.Popen:
    """Compile ``groups`` in a background process (same interpreter and environment); returns the process.

    ``full`` as in :func:`warm`.  Its output is discarded: a failure only means that the process that uses the
    kernels compiles them itself.  Call ``.wait()`` before running those groups, so that they are not compiled
    twice.  The process ends when this one does, even when this one is killed with SIGKILL
    (:func:`clutchlab._process.die_with_parent`; #33: a killed demo's compile processes ran on).
    """
    env = dict(os.environ, CLUTCHLAB_COMPILE_NOTICE="0", MPLBACKEND="Agg")
    return subprocess.Popen([sys.executable, "-m", "clutchlab.warmup", f"--parent={os.getpid()}",
                             *(["--full"] if full else []), *groups],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL)


def run_parallel(groups=None, jobs: int | None = None, progress=None) -> float:
    """Compile ``groups`` (default: all) in up to ``jobs`` processes (default: the cores), each in full (:func:`warm`:
    the rare paths too, so that later runs compile nothing); wall seconds (``clutchlab warmup``).  With fewer processes
    than groups, the groups of a lot (:data:`LOTS`) go to one process, in their order."""
    names = list(GROUPS) if groups is None else list(groups)
    _check(names)
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(names)))
    t0 = time.perf_counter()
    # deal the lots (groups sharing functions, kept together) to the processes, the costliest first, each to the
    # least loaded (by their measured costs); with a process for every group, each group alone (the wall time is then
    # the longest group's, where its lot's would be longer: the cores pay for the functions compiled twice)
    units = lots(names) if jobs < len(names) else [[g] for g in names]
    jobs = min(jobs, len(units))
    dealt, load = [[] for _ in range(jobs)], [0.0] * jobs
    for unit in sorted(units, key=lambda u: -sum(COSTS.get(g, 10.0) for g in u)):
        i = load.index(min(load))
        dealt[i].extend(unit)
        load[i] += sum(COSTS.get(g, 10.0) for g in unit)
    procs = [start(lot, full=True) for lot in dealt if lot]
    failed = [lot for lot, p in zip(dealt, procs) if p.wait() != 0]
    if failed:
        raise SimulationError(f"compiling kernel group(s) {failed} failed; run 'python -m clutchlab.warmup "
                           f"{' '.join(failed[0])}' to see why")
    if progress is not None:
        progress(f"kernels of {', '.join(names)} ready in {time.perf_counter() - t0:.1f} s")
    return time.perf_counter() - t0


def main(argv=None) -> int:
    """``python -m clutchlab.warmup [--parent=PID] [--full] [group ...]``: :func:`warm` in this process.

    ``--parent=PID`` (:func:`start` gives its own): end when process PID does, before anything is imported
    or compiled."""
    names = sys.argv[1:] if argv is None else list(argv)
    parents = [n for n in names if n.startswith("--parent=")]
    for option in parents:
        from ._process import die_with_parent

        value = option.partition("=")[2]
        if not value.isdigit():
            raise ParameterError(f"{option}: expected --parent=PID")
        die_with_parent(int(value), name="clutchlab-warmup-parent-watchdog")
    full = "--full" in names
    names = [n for n in names if n != "--full" and n not in parents]
    warm(names or None, full=full)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
