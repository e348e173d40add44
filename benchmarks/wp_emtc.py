"""Work-precision of the vehicle with EMTC on the drum bench (1 s, controller every 2 ms), issue #14.

Run: ``python benchmarks/wp_emtc.py`` (about 3-4 min; ``--quick``: under a minute, fewer tolerances and
SciPy methods).  Needs the bench extra (``numbalsoda``) for the compiled peer.

Scenario: as ``bench_emtc.py`` (drums 8 and 7.7 m/s, throttle ramp 0.1 -> 0.6 from 0.1 s to 0.9 s, 2nd gear,
controller with the inverse Preisach model at 500 Hz, airgap-dependent magnet from the bundled FORC data).

Solvers, each at rtol = 1e-3 ... 1e-8:

* clutchlab -- :func:`clutchlab.emtc.simulate_bench` end to end (result object), and the core run alone
  (``clutchlab.system.simulate`` of a system built beforehand, recorded at the samples), as ``bench_emtc.py``;
* SciPy -- ``solve_ivp`` with the Python right-hand side of ``bench_emtc.reference`` (restarted at every
  controller sample, terminal events for the armature stops, hysteresis memory committed per accepted
  step, magnet through clutchlab's compiled Preisach kernels) with RK45, DOP853, LSODA and Radau; "best
  SciPy" is the cheapest of them at each error;
* peer -- LSODA from ``numbalsoda`` with a numba ``cfunc`` right-hand side and an ``@njit`` driver
  (``_peer_emtc.py``; memory committed after each lsoda call at its sub-grid points, see there).

Absolute tolerances: the model's per-state ``ATOL`` (clutchlab.emtc.system) scaled with rtol,
``atol = ATOL * rtol / 1e-6`` (clutchlab's default at its default rtol 1e-6), for every solver; the peer
integrates ``y / ATOL`` with the scalar ``atol = rtol / 1e-6`` (the same per-state values).

Error: the worst |difference| of the front and rear coupling-shaft speeds omega_f, omega_r [rad/s] at the
501 controller samples against an independent tight reference: the SciPy reference with DOP853 at
rtol 1e-12 (atol = ATOL * 1e-6; it differs from DOP853 at rtol 1e-10 by about 1e-7 rad/s, and clutchlab at
rtol 1e-10 from it by about 3e-7 rad/s: errors below a few 1e-7 are not resolved).  The compiled solvers
(clutchlab, peer) also run at rtol 1e-9 and 1e-10 (cheap; they show where each one's error levels off).  Times: medians (min-max) of repeated runs after a warm-up (compile).
"""

from __future__ import annotations

import argparse
import datetime
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import _peer_emtc as peer  # noqa: E402  (first: see _peer_emtc._import_numbalsoda)
from _wp import Point, Series, cheapest_at, machine, plot, ratio_at_matched_error, row, timed  # noqa: E402

import math  # noqa: E402

from scipy.integrate import solve_ivp  # noqa: E402

from clutchlab.emtc import (ActuatorParameters, BenchScenario, CouplingGeometry, TorqueMap,  # noqa: E402
                            VehicleParameters, bench_system, bundled_magnet, simulate_bench)
from clutchlab.emtc.system import ATOL  # noqa: E402
from clutchlab.hysteresis import kernels as K  # noqa: E402
from clutchlab.system import simulate as core_simulate  # noqa: E402

SCENARIO = dict(duration=1.0, speed_difference=0.3, throttle_start=0.1, throttle_end=0.6, ramp_start=0.1,
                ramp_end=0.9, sample_time=0.002)
ERROR_LABEL = "max |omega_f, omega_r error| at the samples [rad/s]"


def atol_for(rtol):
    return ATOL * (rtol / 1e-6)


# ---------------------------------------------------------------- the SciPy reference (bench_emtc.reference)
def reference(magnet, sc: BenchScenario, rtol=1e-6, atol=None, method="RK45"):
    """``bench_emtc.reference`` with the method and atol as arguments (same equations, same event and
    memory handling); returns ``(samples x 8: t and the states, accepted steps)``."""
    veh, act, geo_p, tmap = VehicleParameters(), ActuatorParameters(), CouplingGeometry(), TorqueMap()
    ic = veh.rear_final_drive
    jf = veh.inertia_input_shaft + veh.inertia_front_axle / ic**2
    jr = veh.inertia_output_shaft + veh.inertia_rear_axle / ic**2
    fzf, fzr = veh.axle_loads()
    rw, i0, ig = veh.tyre_radius, veh.front_final_drive, veh.gear_ratios[sc.gear - 1]
    kdrag = veh.drag_coefficient()
    m0, kspr, fk0, csp, sigma, d, tau1, tau2 = act.kernel_data()
    tab, grid, gaps = magnet.kernel_tables, magnet.grid, magnet.airgaps
    cap = 4096
    pstack, ppref = np.zeros(cap), np.zeros((magnet.n_airgaps, cap // 2 + 2))
    cstack, cpref = np.zeros(cap), np.zeros((magnet.n_airgaps, cap // 2 + 2))
    mem = {"pl": 0, "pu": grid[0], "cl": 0, "cu": grid[0]}
    idx, w = np.zeros(K.GAP_TABLES, dtype=np.int64), np.zeros(K.GAP_TABLES)
    cidx, cw = np.zeros(K.GAP_TABLES, dtype=np.int64), np.zeros(K.GAP_TABLES)
    K.gap_weights(gaps, d - sigma, cidx, cw)
    vdf = sc.drum_speed
    vdr = sc.drum_speed - sc.speed_difference
    den = 3 * geo_p.cam_radius - 2 * geo_p.cam_ratio * geo_p.mu_k3 * geo_p.radius3
    gain = 1 + (2 * geo_p.cam_ratio * geo_p.mu_k2 * geo_p.radius2 * geo_p.pairs2
                + 2 * geo_p.cam_ratio * geo_p.mu_k3 * geo_p.radius3) / den
    atol = atol_for(rtol) if atol is None else atol

    def throttle(t):
        return float(np.interp(t, [0, sc.ramp_start, sc.ramp_end], [sc.throttle_start, sc.throttle_start, sc.throttle_end]))

    def magnet_force(i, x):
        K.gap_weights(gaps, min(max(d - x, gaps[0]), gaps[-1]), idx, w)
        i = min(max(i, grid[0]), grid[-1])
        return K.peek(tab, grid, pstack, ppref, mem["pl"], mem["pu"], i, idx, w)

    def rhs(t, y, arm, i_cmd):
        wf, wr, _, x, xd, i1, i2 = y
        fm = magnet_force(i2, x)
        if arm == 1:
            dx, dxd, fn1 = xd, (fm - fk0 - kspr * x - csp * xd) / m0, 0.0  # Eq. 9
        else:
            dx, dxd = 0.0, 0.0
            fn1 = max(fm - fk0 - kspr * sigma, 0.0) if arm == 2 else 0.0  # Eq. 11
        wwf, wwr = wf / ic, wr / ic
        fxf = 2 * veh.tyre_slip_stiffness * rw / max(abs(vdf), veh.slip_speed_floor) * (wwf * rw - vdf)
        fxr = 2 * veh.tyre_slip_stiffness * rw / max(abs(vdr), veh.slip_speed_floor) * (wwr * rw - vdr)
        rrf = veh.rolling_resistance * fzf * rw * math.tanh(wwf / 0.5)
        rrr = veh.rolling_resistance * fzr * rw * math.tanh(wwr / 0.5)
        we = abs(wwf) * i0 * ig
        te = throttle(t) * min(veh.engine_torque_max, veh.engine_power / max(we, 1.0))
        a_f = (te * ig * i0 - fxf * rw - rrf) / ic
        a_r = (fxr * rw + rrr) / ic
        dw = wf - wr
        if arm == 2:
            t1 = 2 / 3 * geo_p.mu_k1 * geo_p.radius1 * fn1 * geo_p.pairs1 * math.copysign(1.0, dw)  # Eq. 15
            tc = t1 * gain
        else:
            tc = kdrag * dw  # Eqs. 25-26
        return [(a_f - tc) / jf, (tc - a_r) / jr, 0.0, dx, dxd, (i_cmd - i1) / tau1, (i1 - i2) / tau2]

    y = np.array([vdf / rw * ic, vdr / rw * ic, 0, 0, 0, grid[0], grid[0]], float)
    arm = 0
    ts = sc.sample_time
    n = int(round(sc.duration / ts)) + 1
    out = np.zeros((n, 8))
    n_steps = 0
    for k in range(n):
        t = k * ts
        vx = y[0] / ic * rw
        t_ref = tmap(throttle(t), vx)
        fn1_req = max(t_ref, 0) / gain / (2 / 3 * geo_p.mu_k1 * geo_p.radius1 * geo_p.pairs1)
        fm_req = fn1_req + fk0 + kspr * sigma if t_ref > 0 else 0.0
        i_cmd, _ = K.invert_one(tab, grid, cstack, cpref, mem["cl"], mem["cu"], fm_req, cidx, cw, 1e-9)
        mem["cl"] = K.commit(tab, grid, cstack, cpref, mem["cl"], mem["cu"], i_cmd)
        mem["cu"] = i_cmd
        out[k, 0] = t
        out[k, 1:] = y
        if k == n - 1:
            break
        t_end = t + ts
        while t < t_end - 1e-12:
            if arm == 1:
                e_rest = lambda tt, yy, *a: yy[3]
                e_rest.terminal, e_rest.direction = True, -1
                e_con = lambda tt, yy, *a: sigma - yy[3]
                e_con.terminal, e_con.direction = True, -1
                evs = [e_rest, e_con]
            elif arm == 0:
                e_leave = lambda tt, yy, *a: fk0 - magnet_force(yy[6], yy[3])
                e_leave.terminal, e_leave.direction = True, -1
                evs = [e_leave]
            else:
                e_open = lambda tt, yy, *a: magnet_force(yy[6], yy[3]) - fk0 - kspr * sigma
                e_open.terminal, e_open.direction = True, -1
                evs = [e_open]
            sol = solve_ivp(rhs, (t, t_end), y, method=method, rtol=rtol, atol=atol, args=(arm, i_cmd), events=evs)
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp {method} failed at t = {t}: {sol.message}")
            n_steps += sol.t.size - 1
            for i2 in sol.y[6, 1:]:  # commit the magnet memory once per accepted step
                i2 = min(max(i2, grid[0]), grid[-1])
                mem["pl"] = K.commit(tab, grid, pstack, ppref, mem["pl"], mem["pu"], i2)
                mem["pu"] = i2
            y = sol.y[:, -1].copy()
            t = sol.t[-1]
            if sol.status == 1:
                if arm == 1 and sol.t_events[1].size:
                    arm, y[3], y[4] = 2, sigma, 0.0
                elif arm == 1:
                    arm, y[3], y[4] = 0, 0.0, 0.0
                else:
                    arm = 1
    return out, n_steps


# ---------------------------------------------------------------- the runs
def error(states, ref):
    """Worst |omega_f|, |omega_r| difference [rad/s]; ``states``: (samples, >= 2) omega_f, omega_r."""
    return float(max(np.max(np.abs(states[:, 0] - ref[:, 1])), np.max(np.abs(states[:, 1] - ref[:, 2]))))


def peer_runner(magnet, sc):
    tm = TorqueMap()
    veh = VehicleParameters()
    n = int(round(sc.duration / sc.sample_time)) + 1
    ic, rw = veh.rear_final_drive, veh.tyre_radius
    y0 = np.array([sc.drum_speed / rw * ic, (sc.drum_speed - sc.speed_difference) / rw * ic, 0, 0, 0,
                   magnet.grid[0], magnet.grid[0]])
    address = peer.rhs.address
    tab, grid, gaps = magnet.kernel_tables, magnet.grid, magnet.airgaps

    def run(rtol, nsub=4):
        d = peer.pack(magnet, sc)
        out = np.zeros((n, 8))
        calls, events, ok = peer.run(address, d, y0 / d[peer.D_SCALE:peer.D_SCALE + 7], sc.sample_time, n, nsub,
                                     rtol, rtol / 1e-6, tab, grid, gaps, tm.throttle, tm.speed, tm.torque, out)
        if not ok:
            raise RuntimeError(f"peer: lsoda failed at rtol {rtol:g}")
        return out, calls
    return run


def repeats_for(seconds, budget, lo=1, hi=30):
    return int(min(hi, max(lo, budget / max(seconds, 1e-9))))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer tolerances and SciPy methods (under a minute)")
    ap.add_argument("--plot", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "wp_emtc.png"))
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    print(f"machine: {machine()}")
    print(f"date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC")
    magnet = bundled_magnet()
    sc = BenchScenario(**SCENARIO)
    n = int(round(sc.duration / sc.sample_time)) + 1
    samples = np.arange(n) * sc.sample_time
    if args.quick:
        rtols = [1e-3, 1e-5, 1e-7]
        rtols_compiled = rtols
        methods = ["RK45", "LSODA"]
        budget_fast, budget_slow = 0.3, 1.0
    else:
        rtols = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
        rtols_compiled = rtols + [1e-9, 1e-10]
        methods = ["RK45", "DOP853", "LSODA", "Radau"]
        budget_fast, budget_slow = 2.0, 4.0
    print(f"scenario: {sc.duration:g} s, controller every {sc.sample_time * 1e3:g} ms, {n} samples; "
          f"atol = ATOL * rtol / 1e-6 for every solver")

    t0 = time.perf_counter()
    ref, ref_steps = reference(magnet, sc, rtol=1e-12, atol=ATOL * 1e-6, method="DOP853")
    print(f"reference: SciPy DOP853 rtol 1e-12 atol ATOL*1e-6, {ref_steps} steps, {time.perf_counter() - t0:.1f} s")

    # warm-up: clutchlab's kernels (numba cache) and the peer (its driver cannot be cached: compiled here)
    res = simulate_bench(magnet, sc)
    kinds = set(str(k) for k in res.events["event"])
    if kinds - {"armature_rest", "armature_contact", "armature_leave_rest", "armature_leave_contact"}:
        print(f"WARNING: clutchlab's run has coupling events {sorted(kinds)} the SciPy reference does not model")
    t0 = time.perf_counter()
    run_peer = peer_runner(magnet, sc)
    run_peer(1e-6)
    print(f"peer compiled in {time.perf_counter() - t0:.1f} s (numbalsoda's lsoda in the driver: not cacheable)")

    series = []
    cl = Series("clutchlab simulate_bench")
    core = Series("clutchlab core run")
    pr = Series("peer: numbalsoda LSODA + numba cfunc")
    for rtol in rtols_compiled:
        atol = atol_for(rtol)
        r = simulate_bench(magnet, sc, rtol=rtol, atol=atol)
        tt, r = timed(lambda: simulate_bench(magnet, sc, rtol=rtol, atol=atol), 3)
        reps = repeats_for(min(tt), budget_fast, 5)
        tt, r = timed(lambda: simulate_bench(magnet, sc, rtol=rtol, atol=atol), reps)
        cl.points.append(Point(rtol, error(r.states[:, :2], ref), tt, f"{r.n_steps} steps"))
        systems = [bench_system(magnet, sc) for _ in range(reps + 1)]
        core_simulate(systems[0], float(samples[-1]), sample_times=samples, rtol=rtol, atol=atol)
        tk = []
        for system in systems[1:]:
            t1 = time.perf_counter()
            rr = core_simulate(system, float(samples[-1]), sample_times=samples, rtol=rtol, atol=atol)
            tk.append(time.perf_counter() - t1)
        core.points.append(Point(rtol, error(rr.states[:, :2], ref), tk))
        tt, (o, calls) = timed(lambda: run_peer(rtol), 3)
        reps = repeats_for(min(tt), budget_fast, 5)
        tt, (o, calls) = timed(lambda: run_peer(rtol), reps)
        pr.points.append(Point(rtol, error(o[:, 1:3], ref), tt, f"{calls} lsoda calls"))
    series += [cl, core, pr]
    scipy_series = []
    for method in methods:
        s = Series(f"SciPy {method} (Python RHS)")
        for rtol in rtols:
            tt, (o, steps) = timed(lambda: reference(magnet, sc, rtol=rtol, method=method), 1)
            reps = repeats_for(tt[0], budget_slow, 1, 5) - 1
            if reps > 0:
                t2, (o, steps) = timed(lambda: reference(magnet, sc, rtol=rtol, method=method), reps)
                tt += t2
            s.points.append(Point(rtol, error(o[:, 1:3], ref), tt, f"{steps} steps"))
        scipy_series.append(s)
    series += scipy_series

    print("\n--- work-precision (error = " + ERROR_LABEL + ")")
    for s in series:
        print(s.label)
        for p in s.points:
            print(row(s.label.split(" (")[0], p, sc.duration))

    best = Series("best SciPy", [p for s in scipy_series for p in s.points])
    for s in (cl, core):
        print(f"\n{s.label}: speed-up at matched error (the other's cheapest run at least as accurate)")
        vs_scipy = ratio_at_matched_error(s, best)
        vs_peer = ratio_at_matched_error(s, pr)
        for p, (e, a), (_, b) in zip(s.points, vs_scipy, vs_peer):
            fa = f"{a:7.1f}x" if a is not None else "   never as accurate"
            fb = f"{b:7.2f}x" if b is not None else "   never as accurate"
            print(f"  rtol {p.rtol:7.0e}  error {e:8.1e}: vs best SciPy {fa}   vs peer {fb}")

    levels = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    print("\n--- cheapest run reaching each error [ms, median] (rtol in brackets)")
    print(f"  {'error <=':>9s} {'clutchlab':>18s} {'core run':>18s} {'best SciPy':>30s} {'peer':>18s} "
          f"{'clutchlab/peer':>15s}")
    verdict = []
    for lev in levels:
        cells = []
        got = {}
        for key, ss in (("cl", cl), ("core", core), ("scipy", scipy_series), ("peer", pr)):
            c = cheapest_at(ss, lev)
            got[key] = c
            if c is None:
                cells.append("-")
            else:
                lab = c[0].replace("SciPy ", "").replace(" (Python RHS)", "") + " " if key == "scipy" else ""
                cells.append(f"{lab}{c[1].median * 1e3:.2f} ({c[1].rtol:.0e})")
        if got["cl"] and got["peer"]:
            ratio = got["peer"][1].median / got["cl"][1].median
            rs = f"{ratio:.2f}x"
            state = "faster" if ratio > 1.0 else "SLOWER"
        elif got["cl"]:
            rs, state = "peer never", "faster"
        else:
            rs, state = "-", "not reached by clutchlab"
        if 1e-6 <= lev <= 1e-3:
            verdict.append(f"{lev:.0e}: {state}")
        print(f"  {lev:9.0e} {cells[0]:>18s} {cells[1]:>18s} {cells[2]:>30s} {cells[3]:>18s} {rs:>15s}")
    print("\nclutchlab simulate_bench against the peer at the error levels 1e-3 ... 1e-6: " + "; ".join(verdict))
    plot(series, args.plot, f"EMTC on the drum bench, {sc.duration:g} s, controller {sc.sample_time * 1e3:g} ms "
                            f"(reference: SciPy DOP853 rtol 1e-12)", ERROR_LABEL)
    print(f"total {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    main()
