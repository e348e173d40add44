"""Wet-clutch performance, measured in one run.

1. A 1 s engagement (protocol (b): force rise, speed-controlled slip ramp-down,
   lock-up event, stick mode) with the integrator core (compiled Dormand-Prince
   5(4), events located on the dense output), against real
   time and against ``scipy.integrate.solve_ivp`` (RK45, the same Dormand-Prince
   pair) integrating the same equations with a Python right-hand side at the
   same tolerances, with the same lock-up / break-away events.
2. A batch of 10,000 engagements with varied parameters (``numba.prange``, one
   solver per variant), on all cores and on one thread.
3. Identification (friction map + k1, k2) of a 30 s friction-map record at 1 kHz.

Run: ``python benchmarks/bench_wet.py``.  Prints the measured ratios.
"""

from __future__ import annotations

import bisect
import math
import os
import time

import numba
import numpy as np
from scipy.integrate import solve_ivp

from clutchlab.wet import Bench, ParametricFriction, WetClutch, simulate_batch, simulate_engagement
from clutchlab.wet import system as W
from clutchlab.wet.bench import EngagementProtocol, MapProtocol, run_protocol
from clutchlab.wet.film import gw_table
from clutchlab.wet.identify import identify_friction_map, identify_thermal

RTOL = 1e-7


def best_of(fn, repeat):
    best = math.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


# ---------------------------------------------------------------- Python reference
def make_python_model(clutch, bench, scen, friction):
    """The engagement equations of clutchlab.wet.system (the model's rhs), transcribed to plain Python."""
    c = W.pack_parameters(clutch, bench, scen, friction).constants[0]
    p = {name: c[name].item() for name in c.dtype.names}
    g0, gdt, gv, gd = gw_table()
    gv = gv.tolist()
    gd = gd.tolist()
    ft, fv = scen.force_time.tolist(), scen.force_value.tolist()
    st, sv = scen.speed_time.tolist(), scen.speed_value.tolist()
    law = friction

    def pwl(t, tt, vv):
        if t <= tt[0]:
            return vv[0]
        if t >= tt[-1]:
            return vv[-1]
        i = bisect.bisect_right(tt, t) - 1
        return vv[i] + (t - tt[i]) / (tt[i + 1] - tt[i]) * (vv[i + 1] - vv[i])

    def gw(t):
        x = (t - g0) / gdt
        n = len(gv)
        if x >= n - 1:
            return 0.0
        if x < 0:
            return gv[0] + gd[0] * (t - g0)
        i = int(x)
        th = x - i
        t2, t3 = th * th, th * th * th
        return ((2 * t3 - 3 * t2 + 1) * gv[i] + (t3 - 2 * t2 + th) * gdt * gd[i]
                + (-2 * t3 + 3 * t2) * gv[i + 1] + (t3 - t2) * gdt * gd[i + 1])

    def film(h, s):
        t = h / s
        if t >= -8.0:
            return s * (0.5 * t * math.erfc(-t / math.sqrt(2)) + math.exp(-0.5 * t * t) / math.sqrt(2 * math.pi))
        u = 1 / (t * t)
        return s * math.exp(-0.5 * t * t) / math.sqrt(2 * math.pi) * u * (1 - 3 * u + 15 * u * u - 105 * u**3 + 945 * u**4)

    def terms(t, y, mode):
        nc = p["n_c"]
        x, fa, w, integ, temp, tf, th = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
        h = (p["piston_h0"] - x) / nc
        hbar = film(h, p["sigma"])
        muv = p["mu_v1"] * math.exp(p["mu_v2"] * temp) + p["mu_v3"] * math.exp(p["mu_v4"] * temp)
        fc = p["friction_area"] * p["gw_scale"] * gw(h / p["sigma"])
        v = p["r_eff"] * w
        # |v| as the sliding direction of the mode gives it (clutchlab's model): smooth through v = 0 in a
        # slip mode, so that a step ending past a lock-up sees no kink
        v_abs = v if mode == "slip+" else (-v if mode == "slip-" else abs(v))
        muf = max(law.mu0 + law.mu_t * (temp - law.t_ref) + law.mu_e * math.exp(-v_abs / law.v_s), 0.0)
        cap = p["r_eff"] * nc * muf * fc
        wref = pwl(t, st, sv)
        fref = min(pwl(t, ft, fv), p["actuator_force_max"])
        e = wref - w
        tcmd = p["speed_kp"] * e + integ
        tlim = p["drive_torque_max"]
        if abs(w) * tlim > p["motor_power_max"]:
            tlim = p["motor_power_max"] / abs(w)
        td = min(max(tcmd, -tlim), tlim)
        dint = p["speed_ki"] * e + p["speed_ki"] / p["speed_kp"] * (td - tcmd)
        if mode == "stick":
            tau, wdot, pf = td, 0.0, 0.0
        else:
            sgn = 1.0 if mode == "slip+" else -1.0
            tau = sgn * cap + p["r_eff"] * nc * muv * p["friction_area"] * v / hbar
            wdot = (td - tau) / p["total_inertia"]
            pf = tau * w
        fnet = fa - p["spring_preload"] - p["spring_stiffness"] * x - fc
        csq = p["squeeze_coefficient"] * muv / (nc * hbar**3)
        xdot = p["actuator_speed_max"] * math.tanh(fnet / (csq * p["actuator_speed_max"]))
        if x <= 0 and xdot < 0:
            xdot = 0.0
        qk1 = p["k1"] * (temp - tf)
        qk2 = p["k2"] * (temp - th)
        qh = min(max(p["heater_gain"] * (p["heater_setpoint"] - tf), 0.0), p["heater_power_max"])
        qfh = p["fluid_housing_conductance"] * (tf - th)
        dy = [xdot, (fref - fa) / p["actuator_time_constant"], wdot, dint, (pf - qk1 - qk2) / p["heat_capacity"],
              (qk1 + qh - p["reservoir_cooling"] * (tf - p["ambient_temperature"]) - qfh) / p["reservoir_heat_capacity"],
              (qk2 + qfh - p["housing_cooling"] * (th - p["ambient_temperature"])) / p["housing_heat_capacity"],
              (temp - y[7]) / p["thermistor_time_constant"], pf, qk1, qk2, td * w]
        return dy, td, cap

    return terms


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
def main():
    clutch = WetClutch.paper()
    bench = Bench()
    truth = ParametricFriction.bench_truth()
    proto = EngagementProtocol(duration=1.0)
    scen = proto.scenario(clutch, "speed")
    print(f"cores available: {os.cpu_count()}, numba threads: {numba.get_num_threads()}")

    # ---- 1. single engagement
    t0 = time.perf_counter()
    simulate_engagement(clutch, scen, bench=bench, friction=truth, rtol=RTOL)
    print(f"first call (incl. compilation or cache load): {time.perf_counter() - t0:.2f} s")
    t_kernel, res = best_of(lambda: simulate_engagement(clutch, scen, bench=bench, friction=truth, rtol=RTOL), 50)
    t_states, _ = best_of(lambda: simulate_engagement(clutch, scen, bench=bench, friction=truth, rtol=RTOL,
                                                      outputs=False), 50)
    print(f"[1] 1 s engagement, compiled: {t_kernel * 1e3:.3f} ms ({res.n_steps} steps, 1 kHz output, "
          f"events: {', '.join(f'{e.kind} {e.time:.4f} s' for e in res.events)})")
    print(f"    states only (no output evaluation, like solve_ivp's t_eval): {t_states * 1e3:.3f} ms")
    print(f"    faster than real time: {1.0 / t_kernel:,.0f}x with outputs, {1.0 / t_states:,.0f}x states only")
    t_eval = res.time
    t_ref, (tr, yr, ev_ref, y_end) = best_of(lambda: solve_reference(clutch, bench, scen, truth, t_eval), 3)
    lock_ref = [t for k, t in ev_ref if k == "lock-up"]
    print(f"    solve_ivp RK45 + Python RHS, same rtol={RTOL:g}/atol, same events: {t_ref * 1e3:.1f} ms")
    dev_w = np.max(np.abs(np.interp(t_eval, tr, yr[:, 2]) - res.state("slip_speed_rad_s")))
    dev_t = np.max(np.abs(np.interp(t_eval, tr, yr[:, 4]) - res.state("temperature_C")))
    print(f"    agreement: lock-up {res.lockup_time:.6f} s vs {lock_ref[0] if lock_ref else float('nan'):.6f} s, "
          f"max |slip diff| {dev_w:.2e} rad/s, max |T diff| {dev_t:.2e} K, friction work "
          f"{res.final_state[8]:.3f} vs {y_end[8]:.3f} J")
    print(f"    speed-up over solve_ivp (both states at 1 kHz): {t_ref / t_states:,.0f}x; "
          f"with the 18 outputs also evaluated at 1 kHz: {t_ref / t_kernel:,.0f}x")

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
    t_par, batch = best_of(lambda: simulate_batch(clutch, dyn_scen, variants, bench=bench, friction=truth), 2)
    numba.set_num_threads(1)
    t_ser, _ = best_of(lambda: simulate_batch(clutch, dyn_scen, variants, bench=bench, friction=truth), 1)
    numba.set_num_threads(nthreads)
    print(f"[2] batch of {m} 1 s engagements (inertia dynamometer, 6 parameters varied): "
          f"{t_par:.3f} s on {nthreads} threads, {t_ser:.3f} s on 1 thread -> parallel speed-up {t_ser / t_par:.2f}x; "
          f"{m / t_par:,.0f} engagements/s, all ok: {bool(np.all(batch.status == 0))}, "
          f"locked up: {int(np.sum(np.isfinite(batch.lockup_time)))}")

    # ---- 3. identification of a 30 s record at 1 kHz
    run = run_protocol(MapProtocol(), clutch, Bench(sample_rate=1000.0), truth)
    rec = run.record
    identify_friction_map(rec, clutch)  # imports scipy.optimize etc.
    identify_thermal(rec, clutch)
    t_id, (fmap, th) = best_of(lambda: (identify_friction_map(rec, clutch, sensor_time_constant=0.2),
                                        identify_thermal(rec, clutch, sensor_time_constant=0.2)), 5)
    print(f"[3] identification of a {rec['time_s'].iloc[-1]:.0f} s record at 1 kHz ({len(rec)} samples): "
          f"friction map + k1, k2 in {t_id:.3f} s (target < 1 s); mu_t = {fmap.law.mu_t:.3e} (true {truth.mu_t:.1e}), "
          f"k1 = {th.k1:.1f}, k2 = {th.k2:.2f} W/K (true {clutch.k1}, {clutch.k2})")


if __name__ == "__main__":
    main()
