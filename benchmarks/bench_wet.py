"""Wet-clutch performance, measured in one run.

1. A 1 s engagement (protocol (b): force rise, speed-controlled slip ramp-down,
   the piston leaving its stop, film contact, lock-up, stick) through the public
   call ``simulate_engagement`` at rtol 1e-7 (compiled Dormand-Prince 5(4),
   events located on the dense output), with all 18 outputs at 1 kHz and with
   the states only; its error against a tight run of an independent solver
   (SciPy DOP853 at rtol 1e-11 on the Python right-hand side, the reference of
   ``wp_wet.py``, whose error measure it uses); and ``scipy.integrate.solve_ivp``
   RK45 (the same Dormand-Prince pair) on that Python right-hand side at the same
   tolerances and events, with its error.  Comparisons at matched accuracy over
   several tolerances, with the compiled peer: ``wp_wet.py``.
2. A batch of 10,000 engagements with varied parameters (``numba.prange``, one
   solver per variant), on all cores and on one thread.
3. Identification (friction map + k1, k2) of a 30 s friction-map record at 1 kHz.

Every time is the median of repeated runs with its min-max; the machine and its
load are printed (the load is that of the whole machine: other processes share it).

Run: ``python benchmarks/bench_wet.py [--quick]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numba
import numpy as np
from scipy.integrate import solve_ivp

from clutchlab.wet import Bench, ParametricFriction, WetClutch, simulate_batch, simulate_engagement
from clutchlab.wet import system as W
from clutchlab.wet.bench import EngagementProtocol, MapProtocol, run_protocol
from clutchlab.wet.identify import identify_friction_map, identify_thermal

from _python_wet import make_python_model  # noqa: E402

RTOL = 1e-7


def timed(fn, repeat):
    """Wall times [s] of ``repeat`` calls and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return times, out


def fmt(times, unit=1e3, digits=3):
    """``median (min-max)`` of ``times`` [s] in ms (``unit`` 1e3) or s (1)."""
    return (f"{statistics.median(times) * unit:.{digits}f} ({min(times) * unit:.{digits}f}-"
            f"{max(times) * unit:.{digits}f})")


# ---------------------------------------------------------------- Python reference
def solve_reference(clutch, bench, scen, friction, t_eval):
    terms = make_python_model(clutch, bench, scen, friction)
    atol = W.absolute_tolerance(clutch, RTOL)
    y = W.initial_state(scen)
    t = 0.0
    mode = "slip+" if y[2] > 0 else ("slip-" if y[2] < 0 else "stick")
    ts, ys, events = [], [], []
    while t < scen.duration - 1e-12:
        def f(tt, yy, mode=mode):
            return terms(tt, yy, mode)[0]

        if mode == "stick":
            def ev(tt, yy):
                _, td, cap = terms(tt, yy, "stick")
                return abs(td) - cap
            ev.direction = 1
        else:
            sd = 1.0 if mode == "slip+" else -1.0

            def ev(tt, yy, sd=sd):
                return sd * yy[2]
            ev.direction = -1
        ev.terminal = True
        te = t_eval[(t_eval >= t) & (t_eval <= scen.duration)]
        sol = solve_ivp(f, (t, scen.duration), y, method="RK45", rtol=RTOL, atol=atol, t_eval=te, events=ev,
                        max_step=0.01)
        ts.append(sol.t)
        ys.append(sol.y.T)
        if sol.status == 1:
            t = float(sol.t_events[0][0])
            y = sol.y_events[0][0].copy()
            if mode == "stick":
                _, td, _ = terms(t, y, "stick")
                mode = "slip+" if td > 0 else "slip-"
                events.append(("break-away", t))
            else:
                y[2] = 0.0
                _, td, cap = terms(t, y, "stick")
                mode = "stick" if abs(td) <= cap else ("slip-" if mode == "slip+" else "slip+")
                events.append(("lock-up", t))
            t = t + 1e-12
        else:
            t = scen.duration
            y = sol.y[:, -1]
    return np.concatenate(ts), np.vstack(ys), events, y


# ---------------------------------------------------------------- benchmarks
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats, no batch on one thread")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import _wp  # noqa: PLC0415 (the shared pieces of the work-precision scripts)
    import wp_wet  # noqa: PLC0415 (its reference and error measure; it imports this module's Python model)

    clutch = WetClutch.paper()
    bench = Bench()
    truth = ParametricFriction.bench_truth()
    proto = EngagementProtocol(duration=1.0)
    scen = proto.scenario(clutch, "speed")
    print(f"machine: {_wp.machine()}")
    print(f"cores available: {os.cpu_count()}, numba threads: {numba.get_num_threads()}")
    n_fast = 200 if args.quick else 1000

    # ---- 1. single engagement
    t0 = time.perf_counter()
    simulate_engagement(clutch, scen, bench=bench, friction=truth, rtol=RTOL)
    print(f"first call (incl. compilation or cache load): {time.perf_counter() - t0:.2f} s")

    def run(outputs=True):
        return simulate_engagement(clutch, scen, bench=bench, friction=truth, rtol=RTOL, outputs=outputs)

    t_all, res = timed(run, n_fast)
    t_states, _ = timed(lambda: run(False), n_fast)
    med_all, med_states = statistics.median(t_all), statistics.median(t_states)
    stats = res.result.stats
    print(f"[1] 1 s engagement through simulate_engagement, rtol {RTOL:g}, medians (min-max) of {n_fast} calls:")
    print(f"    all 18 outputs at 1 kHz: {fmt(t_all)} ms = {1.0 / med_all:,.0f}x real time; states only "
          f"(like solve_ivp's t_eval): {fmt(t_states)} ms = {1.0 / med_states:,.0f}x")
    print(f"    {stats['accepted_steps']} steps ({stats['rejected_steps']} rejected), "
          f"{stats['rhs_evaluations']} right-hand sides + {res.time.size} output rows; events: "
          f"{', '.join(f'{e.kind} {e.time:.6f} s' for e in res.events)}")
    terms = make_python_model(clutch, bench, scen, truth)
    x0 = W.initial_state(scen)
    ref = wp_wet.reference(terms, x0, scen, res.time, clutch, bench, truth, check=False)
    e, ew, et = wp_wet.error_of(res.state("slip_speed_rad_s"), res.lockup_time, ref)
    print(f"    error against the reference: {e:.1e} (slip speed {ew:.1e} of {ref['w_range']:.0f} rad/s, "
          f"lock-up time {et:.1e} of 1 s; the measure of wp_wet.py)")
    atol = W.absolute_tolerance(clutch, RTOL)
    t_ivp, (ys, lock, nfev) = timed(
        lambda: wp_wet.solve_scipy(terms, x0, scen.duration, res.time, "RK45", RTOL, atol), 1 if args.quick else 5)
    e_ivp, _, _ = wp_wet.error_of(ys[:, W.S_W], lock, ref)
    print(f"    solve_ivp RK45 + Python RHS, same rtol/atol and events: {fmt(t_ivp, digits=1)} ms, "
          f"{nfev} evaluations, error {e_ivp:.1e}")
    print(f"    at the same tolerance solve_ivp takes {statistics.median(t_ivp) / med_states:,.0f}x the states-only "
          f"time, {statistics.median(t_ivp) / med_all:,.0f}x the time with all outputs (at matched error, "
          f"against every SciPy method and the compiled peer: wp_wet.py)")

    # ---- 2. batch of 10,000 engagements
    m = 10_000
    rng = np.random.default_rng(1)
    variants = {
        "force_scale": rng.uniform(0.6, 1.6, m),
        "mu_scale": rng.uniform(0.85, 1.15, m),
        "initial_slip_speed": rng.uniform(80.0, 200.0, m),
        "speed_scale": rng.uniform(0.5, 1.2, m),
        "initial_temperature_c": rng.uniform(40.0, 110.0, m),
        "k1": rng.uniform(90.0, 150.0, m),
    }
    dyn_scen = proto.scenario(clutch, "free")
    simulate_batch(clutch, dyn_scen, {k: v[:4] for k, v in variants.items()}, bench=bench, friction=truth)
    nthreads = numba.get_num_threads()
    def batch_run():
        return simulate_batch(clutch, dyn_scen, variants, bench=bench, friction=truth)

    t_par, batch = timed(batch_run, 3)
    line = (f"[2] batch of {m} 1 s engagements (inertia dynamometer, 6 parameters varied), medians (min-max) of "
            f"3 runs: {fmt(t_par, 1)} s on {nthreads} threads")
    if not args.quick:
        numba.set_num_threads(1)
        t_ser, _ = timed(batch_run, 3)
        numba.set_num_threads(nthreads)
        line += (f", {fmt(t_ser, 1)} s on 1 thread -> parallel speed-up "
                 f"{statistics.median(t_ser) / statistics.median(t_par):.2f}x")
    print(line + f"; {m / statistics.median(t_par):,.0f} engagements/s, all ok: {bool(np.all(batch.status == 0))}, "
          f"locked up: {int(np.sum(np.isfinite(batch.lockup_time)))}")

    # ---- 3. identification of a 30 s record at 1 kHz
    run = run_protocol(MapProtocol(), clutch, Bench(sample_rate=1000.0), truth)
    rec = run.record
    identify_friction_map(rec, clutch)  # imports scipy.optimize etc.
    identify_thermal(rec, clutch)
    t_id, (fmap, th) = timed(lambda: (identify_friction_map(rec, clutch, sensor_time_constant=0.2),
                                      identify_thermal(rec, clutch, sensor_time_constant=0.2)), 5)
    print(f"[3] identification of a {rec['time_s'].iloc[-1]:.0f} s record at 1 kHz ({len(rec)} samples), median "
          f"(min-max) of 5: friction map + k1, k2 in {fmt(t_id, 1)} s (target < 1 s); mu_t = {fmap.law.mu_t:.3e} "
          f"(true {truth.mu_t:.1e}), k1 = {th.k1:.1f}, k2 = {th.k2:.2f} W/K (true {clutch.k1}, {clutch.k2})")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"load at the end: {load:.2f}")


if __name__ == "__main__":
    main()
