"""Vehicle with EMTC on the drum bench: speed vs real time and vs a solve_ivp reference.

Run: ``python benchmarks/bench_emtc.py``.

Scenario: 1 s of the slipping experiment (Fig. 16-like: drums 8 m/s and
7.7 m/s, throttle ramp, controller at 500 Hz with the inverse Preisach model,
airgap-dependent magnet identified from the bundled synthetic FORC data).

Times are medians of repeated runs with their min-max (the machine is shared and noisy); the error quoted
for clutchlab is against SciPy's DOP853 at rtol 1e-12 on the reference's equations (as ``wp_emtc.py``).

* clutchlab: :func:`clutchlab.emtc.simulate_bench` (the ``emtc_bench`` system run
  by the integrator core: Dormand-Prince 5(4), events located on the dense
  output, controller samples as break times), end to end including the
  DataFrame assembly, and the core run alone (``clutchlab.system.simulate``
  of a system built beforehand).
* reference: the same equations with a Python right-hand side integrated by
  ``scipy.integrate.solve_ivp`` (RK45, the same Dormand-Prince pair, same
  rtol/atol) between controller samples, with terminal events for the
  armature stops and the hysteresis memory committed once per accepted step.
  The magnet force calls clutchlab's compiled Preisach functions (a Python
  Preisach would make the reference slower still).
"""

from __future__ import annotations

import math
import os
import time

import numpy as np
from scipy.integrate import solve_ivp

from clutchlab.emtc import ActuatorParameters, BenchScenario, CouplingGeometry, VehicleParameters, TorqueMap, bundled_magnet, simulate_bench
from clutchlab.emtc import bench_system
from clutchlab.emtc.system import ATOL
from clutchlab.hysteresis import kernels as K
from clutchlab.system import simulate as core_simulate


def reference(magnet, sc: BenchScenario, rtol=1e-6, atol=None, method="RK45", lugre=None, torque_reference=None,
              reversals=False):
    """The drum bench's equations with a Python right-hand side, solved by ``solve_ivp`` between the controller
    samples; returns ``(out, n_steps)``, ``out`` the samples' rows ``[t, omega_f, omega_r, theta, x, v, i1, i2]``.

    ``lugre`` (a :class:`clutchlab.emtc.LuGreParameters`): the three elements slip with the LuGre coefficient
    of [1] Eqs. 22-24 written out here, its bristle deflection ``z`` an eighth state of the ODE (stiff where
    the slip is fast: give a stiff ``method``, "Radau"); it starts at its steady state when the armature
    presses the clutch.  Without it, the coupling's kinetic coefficients ``mu_k``.

    ``torque_reference`` ``(times, torques)``: the reference of Eq. 31 read linearly from this table instead of the
    map (as :func:`clutchlab.emtc.simulate_bench`'s).  ``reversals``: the coil current's turning points
    (``i1 = i2``, Eq. 8's second lag at rest) are terminal events, so the magnet's memory is committed exactly at
    each (without them, at the step end after it: its turning point off by the current's curvature times the
    step's square).
    """
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

    def throttle(t):
        return float(np.interp(t, [0, sc.ramp_start, sc.ramp_end], [sc.throttle_start, sc.throttle_start, sc.throttle_end]))

    def magnet_force(i, x):
        K.gap_weights(gaps, min(max(d - x, gaps[0]), gaps[-1]), idx, w)
        i = min(max(i, grid[0]), grid[-1])
        return K.peek(tab, grid, pstack, ppref, mem["pl"], mem["pu"], i, idx, w)

    if lugre is not None:
        s0, s1, s2, mu_c, mu_p, v_s = (lugre.sigma0, lugre.sigma1, lugre.sigma2, lugre.mu_c, lugre.mu_p, lugre.v_s)

        def stribeck(v):
            return mu_c + (mu_p - mu_c) * math.exp(-((v / v_s) ** 2))  # [1], Eq. 24

    def rhs(t, y, arm, i_cmd):
        wf, wr, _, x, xd, i1, i2 = y[:7]
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
        dz = 0.0
        if arm == 2 and lugre is not None:
            z = y[7]
            dz = dw - s0 * abs(dw) / stribeck(dw) * z  # [1], Eq. 23
            mu = s0 * z + s1 * dz + s2 * dw  # [1], Eq. 22: the same coefficient on all three elements
            t1 = 2 / 3 * mu * geo_p.radius1 * fn1 * geo_p.pairs1  # Eq. 15, in the direction of mu
            den_mu = 3 * geo_p.cam_radius - 2 * geo_p.cam_ratio * abs(mu) * geo_p.radius3
            tc = t1 * (1 + (2 * geo_p.cam_ratio * abs(mu) * geo_p.radius2 * geo_p.pairs2
                            + 2 * geo_p.cam_ratio * abs(mu) * geo_p.radius3) / den_mu)
        elif arm == 2:
            t1 = 2 / 3 * geo_p.mu_k1 * geo_p.radius1 * fn1 * geo_p.pairs1 * math.copysign(1.0, dw)  # Eq. 15
            tc = t1 * gain
        else:
            tc = kdrag * dw  # Eqs. 25-26
        out = [(a_f - tc) / jf, (tc - a_r) / jr, 0.0, dx, dxd, (i_cmd - i1) / tau1, (i1 - i2) / tau2]
        return out if lugre is None else out + [dz]

    atol = np.array([1e-4, 1e-4, 1e-7, 1e-9, 1e-6, 1e-5, 1e-5]) if atol is None else atol
    y = np.array([vdf / rw * ic, vdr / rw * ic, 0, 0, 0, 0, 0], float)
    if lugre is not None:   # the bristles: about mu_p / sigma0 = 6.5e-5 rad at most
        atol = np.append(atol, 1e-9 * float(np.min(atol[:2])) / 1e-4)
        y = np.append(y, 0.0)
    arm = 0
    ts = sc.sample_time
    n = int(round(sc.duration / ts)) + 1
    out = np.zeros((n, 8))
    n_steps = 0
    for k in range(n):
        t = k * ts
        vx = y[0] / ic * rw
        t_ref = (tmap(throttle(t), vx) if torque_reference is None
                 else float(np.interp(t, torque_reference[0], torque_reference[1])))
        fn1_req = max(t_ref, 0) / gain / (2 / 3 * geo_p.mu_k1 * geo_p.radius1 * geo_p.pairs1)
        fm_req = fn1_req + fk0 + kspr * sigma if t_ref > 0 else 0.0
        i_cmd, _ = K.invert_one(tab, grid, cstack, cpref, mem["cl"], mem["cu"], fm_req, cidx, cw, 1e-9)
        mem["cl"] = K.commit(tab, grid, cstack, cpref, mem["cl"], mem["cu"], i_cmd)
        mem["cu"] = i_cmd
        out[k, 0] = t
        out[k, 1:] = y[:7]
        if k == n - 1:
            break
        t_end = t + ts
        turned = False
        while t < t_end - 1e-12:
            evs = []
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
            turn = reversals and not turned
            if turn:   # a turning point of i2: i1 - i2 through zero, either way (at most one between two samples,
                # where the command is constant: i1 relaxes monotonically towards it and i2 follows)
                e_turn = lambda tt, yy, *a: yy[5] - yy[6]
                e_turn.terminal, e_turn.direction = True, 0
                evs = evs + [e_turn]
            sol = solve_ivp(rhs, (t, t_end), y, method=method, rtol=rtol, atol=atol, args=(arm, i_cmd),
                            events=evs)
            n_steps += sol.t.size - 1
            for i2 in sol.y[6, 1:]:  # commit the magnet memory once per accepted step
                i2 = min(max(i2, grid[0]), grid[-1])
                mem["pl"] = K.commit(tab, grid, pstack, ppref, mem["pl"], mem["pu"], i2)
                mem["pu"] = i2
            y = sol.y[:, -1].copy()
            t = sol.t[-1]
            if sol.status == 1 and turn and sol.t_events[-1].size:
                turned = True
                continue   # a turning point: committed above, the run goes on in the same mode
            if sol.status == 1:
                if arm == 1 and sol.t_events[1].size:
                    arm, y[3], y[4] = 2, sigma, 0.0
                    if lugre is not None and y[0] != y[1]:   # bristles at their steady state (Eq. 23, dz/dt = 0)
                        y[7] = stribeck(y[0] - y[1]) / s0 * math.copysign(1.0, y[0] - y[1])
                elif arm == 1:
                    arm, y[3], y[4] = 0, 0.0, 0.0
                elif arm == 0:
                    arm = 1
                else:
                    arm = 1
    return out, n_steps


def _times(fn, reps):
    """Wall times [s] of ``reps`` calls (quoted as median and min-max: this 2-core machine is shared)."""
    out = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return np.array(out)


def _ms(t):
    return f"{np.median(t) * 1e3:.3f} ms ({np.min(t) * 1e3:.3f}-{np.max(t) * 1e3:.3f})"


def measure(magnet, sc, reps=301):
    res = simulate_bench(magnet, sc)  # compile (or load the numba cache)
    t_cl = _times(lambda: simulate_bench(magnet, sc), reps)
    t_df = _times(lambda: simulate_bench(magnet, sc).to_dataframe(), max(reps // 5, 5))
    # the core run alone: systems (fresh hysteresis memories each) built beforehand, recorded at the samples
    n = int(round(sc.duration / sc.sample_time)) + 1
    samples = np.arange(n) * sc.sample_time
    systems = [bench_system(magnet, sc) for _ in range(reps)]
    times = []
    for system in systems:
        t1 = time.perf_counter()
        core_simulate(system, float(samples[-1]), sample_times=samples)
        times.append(time.perf_counter() - t1)
    t_kernel = np.array(times)
    ref, n_ref_steps = reference(magnet, sc)
    t_ref = _times(lambda: reference(magnet, sc), 3)
    # the error against a tight independent solution: SciPy DOP853 at rtol 1e-12 on the same Python equations
    # (the error of benchmarks/wp_emtc.py: the worst front/rear shaft speed at the samples)
    tight, n_tight = reference(magnet, sc, rtol=1e-12, atol=ATOL * 1e-6, method="DOP853")
    df = res.to_dataframe()
    err_w = max(np.max(np.abs(df["omega_f_rad_s"] - ref[:, 1])), np.max(np.abs(df["omega_r_rad_s"] - ref[:, 2])))
    err_i = np.max(np.abs(df["i2_A"] - ref[:, 7]))
    err_tight = max(np.max(np.abs(df["omega_f_rad_s"] - tight[:, 1])), np.max(np.abs(df["omega_r_rad_s"] - tight[:, 2])))
    err_ref = max(np.max(np.abs(ref[:, 1] - tight[:, 1])), np.max(np.abs(ref[:, 2] - tight[:, 2])))
    med_cl, med_df, med_k, med_ref = (float(np.median(t)) for t in (t_cl, t_df, t_kernel, t_ref))
    print(f"--- {sc.duration:g} s simulated, controller/output every {sc.sample_time * 1e3:g} ms, rtol 1e-6 "
          f"(medians of {reps}, min-max in brackets; load {os.getloadavg()[0]:.2f})")
    print(f"clutchlab simulate_bench (result object): {_ms(t_cl)}, {sc.duration / med_cl:.0f}x faster than real time; "
          f"{res.n_steps} steps")
    print(f"  with to_dataframe(): {_ms(t_df)} ({sc.duration / med_df:.0f}x); core run alone {_ms(t_kernel)} "
          f"({sc.duration / med_k:.0f}x)")
    print(f"  error against SciPy DOP853 rtol 1e-12 ({n_tight} steps): max |omega_f, omega_r error| {err_tight:.2e} rad/s")
    print(f"solve_ivp reference (Python RHS, RK45 rtol 1e-6): {_ms(t_ref)}, {n_ref_steps} steps, its error "
          f"{err_ref:.2e} rad/s")
    print(f"agreement with it: max |omega difference| {err_w:.2e} rad/s, max |coil current difference| {err_i:.2e} A")
    print(f"speed-up vs solve_ivp: {med_ref / med_cl:.0f}x (simulate_bench), {med_ref / med_df:.0f}x (with "
          f"to_dataframe), {med_ref / med_k:.0f}x core run")
    print(f"targets (issue #14, medians): >= 2000x real time: {'met' if sc.duration / med_cl >= 2000 else 'NOT met'} "
          f"(simulate_bench), {'met' if sc.duration / med_k >= 2000 else 'NOT met'} core run; >= 100x solve_ivp: "
          f"{'met' if med_ref / med_cl >= 100 else 'NOT met'} (simulate_bench)")


def main():
    magnet = bundled_magnet()
    for ts in (0.002, 0.01):
        sc = BenchScenario(duration=1.0, speed_difference=0.3, throttle_start=0.1, throttle_end=0.6,
                           ramp_start=0.1, ramp_end=0.9, sample_time=ts)
        measure(magnet, sc)


if __name__ == "__main__":
    main()
