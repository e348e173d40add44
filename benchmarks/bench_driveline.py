"""Modelica's CoupledClutches as a clutchlab driveline: work against precision, and against SciPy.

Run: ``python benchmarks/bench_driveline.py [--quick]``.

Model: ``Modelica.Mechanics.Rotational.Examples.CoupledClutches`` (MSL 4.x), 1.5 s, nine mode changes
(``examples/driveline_coupled_clutches.toml``).

* clutchlab: :func:`clutchlab.system.simulate` of the driveline's system (Dormand-Prince 5(4), events
  on the order-4 dense output), sampled at the end only; the system is built once.
* SciPy: the independent solution of ``tests/driveline/coupled_clutches_scipy.py`` -- the same
  equations with a Python right-hand side, ``solve_ivp`` restarted at every event, event functions for
  every switching condition -- with RK45 (the same Dormand-Prince pair), DOP853 and LSODA, with the same
  largest step as clutchlab (an eighth of the drive's period).
* Compiled peer: the same SciPy drivers with the right-hand side and the torque of the switching
  functions compiled by numba (``_cc_compiled.py``): LSODA (ODEPACK's Fortran, Adams/BDF switching) and
  RK45 calling compiled code through a thin Python wrapper -- what a SciPy user gets by compiling their
  model.
* Accuracy: the largest error of the final speeds and of the nine event times against the SciPy
  solution at rtol = atol = 1e-12 (DOP853), which agrees with a closed-form check to 1e-13.

Each row: the tolerance, the error, the time (median and min-max of the repeats) and the speed against
real time.  Compare rows of matched error, not of matched tolerance.

Then the E-clutch launch (``examples/driveline_eclutch_launch.toml``, 5 s: engine map and idle controller,
dual-mass flywheel, E-clutch with its actuator dynamics, gearbox, final drive, driveshaft lash, vehicle):
the network's run at several tolerances, its error (final engine and vehicle speeds, lock-up time) against
the same network at rtol 1e-11, and separately the solve of the E-clutch's actuator dynamics (Rodas3, done
once when the element is built, :meth:`Driveline.eclutch`) -- the run of a built model is the network; a
new pedal profile costs both.  No SciPy row: the launch has no independent implementation here (the
network's equations are checked against SciPy on CoupledClutches above and against closed forms in
``tests/driveline``).  ``--launch`` runs only this part.

``--emtc`` runs only the EMTC drum bench as a network (``examples/driveline_emtc_awd.toml``) against the
EMTC package's own model of the same bench (:func:`emtc`).
"""

from __future__ import annotations

import platform
import statistics
import sys
import time
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "driveline"))
import coupled_clutches_scipy as ref_cc  # noqa: E402

sys.path.insert(0, str(ROOT / "benchmarks"))
import _cc_compiled as compiled_cc  # noqa: E402

from clutchlab.driveline.description import load_driveline  # noqa: E402
from clutchlab.system import simulate  # noqa: E402

T_END = 1.5
#: the largest step of both: an eighth of the 5 Hz drive's period (clutchlab's rule for sine sources)
MAX_STEP = 0.025
NAMES = ("J1", "J2", "J3", "J4")


def _error(events, final, ref):
    ev = max((abs(a - b[0]) for a, b in zip(events, ref["events"])), default=0.0)
    if len(events) != len(ref["events"]):
        ev = float("inf")
    w = max(abs(final[n] - ref["final"][f"{n}.w"]) for n in NAMES)
    return max(ev, w)


def _timed(fn, repeat):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return times, out


def _row(label, rtol, err, times):
    med = statistics.median(times)
    print(f"  {label:22s} rtol {rtol:7.0e}   error {err:8.1e}   {med * 1e3:9.3f} ms "
          f"({min(times) * 1e3:.3f}-{max(times) * 1e3:.3f})   {T_END / med:9.0f}x real time")


def main(quick: bool = False):
    print(f"CoupledClutches, {T_END} s; {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}")
    ref = ref_cc.reference(T_END)  # rtol = atol = 1e-12, DOP853
    spec = load_driveline(ROOT / "examples" / "driveline_coupled_clutches.toml")
    tols = (1e-6, 1e-8, 1e-10) if quick else (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
    print("clutchlab (compiled core)")
    for rtol in tols:
        system = spec.driveline.system(rtol)
        res = simulate(system, T_END, sample_times=[T_END])  # compile / load once
        times, res = _timed(lambda: simulate(system, T_END, sample_times=[T_END]), 5 if quick else 21)
        final = {n: res.states[-1, system.state_index(f"{n}.w")] for n in NAMES}
        events = list(res.events.time_s)
        _row(f"{res.stats['accepted_steps']} steps", rtol, _error(events, final, ref), times)
    runs = [("RK45", "Python", {}), ("DOP853", "Python", {}), ("LSODA", "Python", {}),
            ("RK45", "compiled", dict(rhs_factory=compiled_cc.make_rhs, events_factory=compiled_cc.make_events)),
            ("LSODA", "compiled", dict(rhs_factory=compiled_cc.make_rhs, events_factory=compiled_cc.make_events))]
    for method, kind, factories in runs:
        print(f"SciPy solve_ivp {method}, restarted at every event ({kind} right-hand side)")
        for rtol in tols:
            def run():
                return ref_cc.reference(T_END, rtol=rtol, atol=rtol, method=method, max_step=MAX_STEP,
                                        **factories)

            if kind == "compiled":
                run()   # the compiled functions' types differ per integrator: compile outside the timing
            times, r = _timed(run, 1 if quick else 3)
            final = {n: r["final"][f"{n}.w"] for n in NAMES}
            _row(f"{r['nfev']} rhs", rtol, _error([e[0] for e in r["events"]], final, ref), times)


LAUNCH_T_END = 5.0


def launch(quick: bool = False):
    """The E-clutch launch: network run time and error at several tolerances, and the actuator's solve."""
    spec = load_driveline(ROOT / "examples" / "driveline_eclutch_launch.toml")
    d = spec.driveline
    print(f"E-clutch launch, {LAUNCH_T_END} s; {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}")

    def summary(res, system):
        ev = res.events
        lock = ev[(ev["element"] == "clutch") & (ev["event"] == "stick")]["time_s"].to_numpy()
        return (res.states[-1, system.state_index("engine.w")], res.states[-1, system.state_index("vehicle.w")],
                lock[0] if lock.size else float("nan"))

    tight = d.system(1e-11)
    ref = summary(simulate(tight, LAUNCH_T_END, sample_times=[LAUNCH_T_END]), tight)
    print("clutchlab network (compiled core), error = worst of final engine and vehicle speed [rad/s] and lock-up "
          "time [s] against rtol 1e-11")
    for rtol in ((1e-6, 1e-8) if quick else (1e-5, 1e-6, 1e-7, 1e-8)):
        system = d.system(rtol)
        res = simulate(system, LAUNCH_T_END, sample_times=[LAUNCH_T_END])
        times, res = _timed(lambda: simulate(system, LAUNCH_T_END, sample_times=[LAUNCH_T_END]), 5 if quick else 21)
        err = max(abs(a - b) for a, b in zip(summary(res, system), ref))
        med = statistics.median(times)
        print(f"  {res.stats['accepted_steps']:5d} steps          rtol {rtol:7.0e}   error {err:8.1e}   "
              f"{med * 1e3:9.3f} ms ({min(times) * 1e3:.3f}-{max(times) * 1e3:.3f})   "
              f"{LAUNCH_T_END / med:9.0f}x real time")
    # the actuator's solve as the element does it (Driveline.eclutch with actuator=True): the E-clutch dynamics
    # from rest under the file's bearing reference, held at its first value through the 1 s pre-roll, to 0.5 s
    # past its last corner, sampled every 1 ms
    from clutchlab.eclutch.dynamics import EClutch
    from clutchlab.eclutch.models import ClutchModel

    ecl = EClutch(clutch=ClutchModel.preset(4))
    reference = ([0.0, 1.0, 1.5, 1.7, 3.0, 4.0], [8e-3, 8e-3, 8e-3, 5.5e-3, 3e-3, 0.0])
    times, _ = _timed(lambda: ecl.simulate({"bearing_reference": reference}, 4.5, output_step=1e-3).to_dataframe(),
                      3 if quick else 11)
    med = statistics.median(times)
    print(f"  actuator dynamics (E-clutch, Rodas3 rtol 1e-3, 1 s pre-roll + 3 s + 0.5 s, 1 ms samples): "
          f"{med * 1e3:.2f} ms ({min(times) * 1e3:.2f}-{max(times) * 1e3:.2f})")


def emtc(quick: bool = False):
    """The EMTC in the AWD vehicle on the drum bench (``examples/driveline_emtc_awd.toml``, 1.5 s) as a network,
    against the EMTC package's own drum-bench model of the same scenario: run time and error (worst shaft speed
    [rad/s] over a 10 ms grid) against that model at rtol 1e-11 with tight absolute tolerances.  A system holds the
    coupling's memories (magnet, controller), so each timed run gets a system built beforehand (its build is
    timed apart)."""
    import numpy as np

    from clutchlab.emtc import system as S
    from clutchlab.emtc.bench import load_scenario

    spec = load_driveline(ROOT / "examples" / "driveline_emtc_awd.toml")
    bench = load_scenario(ROOT / "examples" / "emtc_scenario.toml")
    sc, veh, t_end = bench["scenario"], bench["vehicle"], spec.t_end
    print(f"EMTC AWD vehicle on the drum bench, {t_end} s; {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}")
    # the error: the worst difference of the two shaft speeds over a 10 ms grid (the final speeds alone sit
    # on the drums' quasi-steady state and say nothing), against the bench model at rtol 1e-11
    grid = np.arange(0.0, t_end + 1e-12, 0.01)
    tight = S.run(lambda cap: S.bench_system(None, sc, veh), t_end, rtol=1e-11, atol=S.ATOL * 1e-10,
                  sample_times=grid)[1]
    ref = [tight.states[:, tight.state_columns.index(c)] for c in ("omega_f_rad_s", "omega_r_rad_s")]
    repeat = 5 if quick else 21
    for label, build, names in (
            ("network", lambda rtol: spec.driveline.system(rtol), ("front_shaft.w", "rear_shaft.w")),
            ("EMTC bench model", lambda rtol: S.bench_system(None, sc, veh), ("omega_f", "omega_r"))):
        print(f"clutchlab {label} (compiled core)")
        for rtol in ((1e-6, 1e-8) if quick else (1e-6, 1e-7, 1e-8)):
            kw = dict(rtol=rtol)
            if label != "network":
                kw["atol"] = S.ATOL * rtol * 10   # its default absolute tolerances would cap its accuracy
            system = build(rtol)
            sampled = simulate(system, t_end, sample_times=grid, **kw)
            err = max(np.max(np.abs(sampled.states[:, system.state_index(n)] - r)) for n, r in zip(names, ref))
            builds, systems = _timed(lambda: [build(rtol) for _ in range(repeat)], 1)
            times = []
            for system in systems:
                t0 = time.perf_counter()
                res = simulate(system, t_end, sample_times=[t_end], **kw)
                times.append(time.perf_counter() - t0)
            med = statistics.median(times)
            print(f"  {res.stats['accepted_steps']:5d} steps          rtol {rtol:7.0e}   error {err:8.1e}   "
                  f"{med * 1e3:9.3f} ms ({min(times) * 1e3:.3f}-{max(times) * 1e3:.3f})   "
                  f"{t_end / med:9.0f}x real time   (build {builds[0] / repeat * 1e3:.2f} ms)")


if __name__ == "__main__":
    if "--emtc" in sys.argv:
        emtc(quick="--quick" in sys.argv)
        sys.exit(0)
    if "--launch" not in sys.argv:
        main(quick="--quick" in sys.argv)
    launch(quick="--quick" in sys.argv)
