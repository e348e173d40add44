"""Benchmark: 1 s of E-clutch dynamics (actuator + Model 4 with stick-slip friction).

Measured in one run:

1. clutchlab's Rodas3 integrator core on the E-clutch system (``clutchlab.system.simulate`` of
   ``EClutch.as_system``, without outputs) and ``EClutch.simulate`` (outputs and tables), after compilation;
2. the **same equations** integrated by ``scipy.integrate.solve_ivp`` with a plain-Python right-hand side:
   the massless finger-tip node is solved by Newton inside the right-hand side (solve_ivp has no mass
   matrix), the friction state machine runs on terminal events with a restart after each, and the
   integration restarts at every input breakpoint -- what one would write with SciPy;
3. the accuracy of both against a tight-tolerance clutchlab run (rtol 1e-8), to show the tolerances match;
4. a batch of 1,000 variants (lever ratio x diaphragm stiffness scale), building included, with ``prange`` on all threads
   against one thread, outputs every 1 ms and every 10 ms.

Run:  python benchmarks/bench_eclutch_dynamics.py [--quick]  (``--clutchlab``: only clutchlab's two figures and their
error, no SciPy references and no batch)  (``--build``: only the time to build one variant;
``--batch [--quick]``: only the batch, building included)
"""

from __future__ import annotations

import math
import os
import platform
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

from clutchlab import system as contract
from clutchlab.eclutch import ActuatorParameters, ClutchModel, EClutch, EClutchParameters, FrictionParameters
from clutchlab.eclutch import system as S
from clutchlab.eclutch.dynamics import _as_table, simulate_batch

T_END = 1.0
INPUT = {"bearing_reference": ([0.0, 0.1, 0.3, 0.6, 0.8], [0.0, 0.0, 7e-3, 7e-3, 0.0])}
RTOL = 1e-3  # clutchlab's default; the reference gets the same rtol and atol


# ---------------------------------------------------------------------------------------------
# plain-Python reference of the same equations
# ---------------------------------------------------------------------------------------------
class PythonEClutch:
    """The E-clutch right-hand side in plain Python (position control), for solve_ivp."""

    def __init__(self, ec: EClutch, tin, vin):
        s = ec.assembly
        self.s = s
        self.nz = s.nz
        self.GA = s.asm["GA"].tolist()
        self.Gb = s.asm["Gb"].tolist()
        self.d0 = s.asm["d0"].tolist()
        self.curves = []
        for e in range(len(s.element_names)):
            lo, hi = s.offsets[e], s.offsets[e + 1]
            self.curves.append((s.cx[lo:hi].tolist(), s.cf[lo:hi].tolist(), s.cd[lo:hi].tolist(), int(s.kinds[e]),
                                float(s.scale[e]), bool(s.unilateral[e])))
        self.par = s.par.tolist()
        self.mass = s.mass.tolist()
        self.massless = [j for j in range(2, s.nz) if s.mass[j] == 0.0]
        self.massive = [j for j in range(s.nz) if s.mass[j] > 0.0]
        self.fr = (s.fr_on.tolist(), s.fr_c0.tolist(), s.fr_mun.tolist(), s.fr_nidx.tolist(), s.fr_mup.tolist(),
                   s.fr_pidx.tolist(), s.fr_rs.tolist(), s.fr_c.tolist())
        self.tin = list(tin)
        self.vin = list(vin)
        self.q_alg = None

    @staticmethod
    def curve(c, x):
        xs, fs, ds, kind, scale, _ = c
        n = len(xs)
        if x <= xs[0]:
            s = ds[0] if kind else (fs[1] - fs[0]) / (xs[1] - xs[0])
            return scale * (fs[0] + s * (x - xs[0])), scale * s
        if x >= xs[-1]:
            s = ds[-1] if kind else (fs[-1] - fs[-2]) / (xs[-1] - xs[-2])
            return scale * (fs[-1] + s * (x - xs[-1])), scale * s
        lo, hi = 0, n - 1
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if xs[mid] <= x:
                lo = mid
            else:
                hi = mid
        h = xs[hi] - xs[lo]
        if not kind:
            s = (fs[hi] - fs[lo]) / h
            return scale * (fs[lo] + s * (x - xs[lo])), scale * s
        t = (x - xs[lo]) / h
        t2, t3 = t * t, t * t * t
        val = ((2 * t3 - 3 * t2 + 1) * fs[lo] + (t3 - 2 * t2 + t) * h * ds[lo] + (-2 * t3 + 3 * t2) * fs[hi]
               + (t3 - t2) * h * ds[hi])
        der = ((6 * t2 - 6 * t) / h * fs[lo] + (3 * t2 - 4 * t + 1) * ds[lo] + (-6 * t2 + 6 * t) / h * fs[hi]
               + (3 * t2 - 2 * t) * ds[hi])
        return scale * val, scale * der

    def ref(self, t):
        tin, vin = self.tin, self.vin
        if t <= tin[0]:
            return vin[0]
        for k in range(len(tin) - 1):
            if t <= tin[k + 1]:
                return vin[k] + (vin[k + 1] - vin[k]) * (t - tin[k]) / (tin[k + 1] - tin[k])
        return vin[-1]

    def element_forces(self, u, q):
        f, k = [], []
        for e, c in enumerate(self.curves):
            d = self.d0[e] + self.Gb[e] * u + sum(g * qq for g, qq in zip(self.GA[e], q))
            fe, ke = self.curve(c, d)
            if c[5] and fe < 0.0:
                fe, ke = 0.0, 0.0
            f.append(fe)
            k.append(ke)
        return f, k

    def solve_tip(self, u, q):
        """Newton on the massless coordinates: 0 = -(GA^T f)_j."""
        for _ in range(50):
            f, k = self.element_forces(u, q)
            worst = 0.0
            for j in self.massless:
                jj = j - 2
                r = -sum(self.GA[e][jj] * f[e] for e in range(len(f)))
                dr = -sum(self.GA[e][jj] ** 2 * k[e] for e in range(len(f)))
                if dr == 0.0:
                    dr = -1.0
                q[jj] -= r / dr
                worst = max(worst, abs(r))
            if worst < 1e-9:
                break
        return q

    def unpack(self, y):
        """Full coordinate/velocity lists from the ODE state (massless coordinates solved)."""
        nz = self.nz
        z = [0.0] * nz
        v = [0.0] * nz
        m = len(self.massive)
        for i, j in enumerate(self.massive):
            z[j] = y[i]
            v[j] = y[m + i]
        q = [z[j] for j in range(2, nz)]
        for j in self.massless:
            q[j - 2] = self.q_alg[j - 2]
        q = self.solve_tip(z[1], q)
        for j in self.massless:
            z[j] = q[j - 2]
        return z, v, q, list(y[2 * m:])

    def forces(self, t, y, modes):
        nz, p = self.nz, self.par
        z, v, q, (p_m, Q, p_s, cur, e_int) = self.unpack(y)
        u, v_u = z[1], v[1]
        f, _k = self.element_forces(u, q)
        Fz = [0.0] * nz
        fb = sum(self.Gb[e] * f[e] for e in range(len(f)))
        for j in range(2, nz):
            Fz[j] = -sum(self.GA[e][j - 2] * f[e] for e in range(len(f)))
        Fz[1] -= fb
        r = min(max(self.ref(t), p[S.P_REFMIN]), p[S.P_REFMAX])
        v_pid = p[S.P_KP] * (r - u) + e_int - p[S.P_KD] * v_u  # e_int: the integral action [V]
        v_drive = min(max(v_pid, -p[S.P_VSUP]), p[S.P_VSUP])
        exc = abs(cur) - p[S.P_IMAX]
        if exc > 0.0:
            v_drive -= p[S.P_KIL] * exc * (1.0 if cur > 0 else -1.0)
            v_drive = min(max(v_drive, -p[S.P_VSUP]), p[S.P_VSUP])
        x_mc, v_mc = z[0], v[0]
        di = (v_drive - p[S.P_R] * cur - p[S.P_KT] * v_mc / p[S.P_NS]) / p[S.P_L]
        de = p[S.P_KI] * ((r - u) + p[S.P_KAW] * (v_drive - v_pid))
        Fz[0] += p[S.P_KT] * cur / p[S.P_NS] - p_m * p[S.P_AMC]
        opening = min(max((p[S.P_XSN] - x_mc) / p[S.P_WSN], 0.0), 1.0)
        q_vent = p[S.P_GV] * opening * p_m
        cm = p[S.P_CM] * (p[S.P_CAVF] if p_m < p[S.P_PCAV] else 1.0)
        cs = p[S.P_CS] * (p[S.P_CAVF] if p_s < p[S.P_PCAV] else 1.0)
        dpm = (p[S.P_AMC] * v_mc - Q - q_vent) / cm
        dQ = (p_m - p_s - p[S.P_RH] * Q) / p[S.P_LH]
        dps = (Q - p[S.P_ASL] * v_u) / cs
        Fz[1] += p_s * p[S.P_ASL] + p[S.P_FPRE] - p[S.P_KPRE] * u
        ks, cst = p[S.P_KSTOP], p[S.P_CSTOP]
        for j, lo, hi in ((0, 0.0, p[S.P_XMAX]), (1, p[S.P_UMIN], p[S.P_UMAX])):
            dl = lo - z[j]
            if dl > 0.0:
                Fz[j] += max(ks * dl - cst * dl * v[j], 0.0)
            dh = z[j] - hi
            if dh > 0.0:
                Fz[j] -= max(ks * dh + cst * dh * v[j], 0.0)
        fn = []
        on, c0, mun, nidx, mup, pidx, rs, cv = self.fr
        for j in range(nz):
            val = c0[j]
            if nidx[j] >= 0:
                val += mun[j] * abs(f[nidx[j]])
            if pidx[j] == 1:
                val += mup[j] * abs(p_m)
            elif pidx[j] == 2:
                val += mup[j] * abs(p_s)
            fn.append(val)
        return z, v, Fz, fn, (di, de, dpm, dQ, dps)

    def rhs(self, t, y, modes):
        z, v, Fz, fn, (di, de, dpm, dQ, dps) = self.forces(t, y, modes)
        on, _c0, _mun, _nidx, _mup, _pidx, _rs, cv = self.fr
        m = len(self.massive)
        dy = [0.0] * len(y)
        for i, j in enumerate(self.massive):
            if on[j] and modes[j] == 2:
                continue
            frc = -cv[j] * v[j]
            if on[j]:
                frc -= (1.0 if modes[j] > 0 else -1.0) * fn[j]
            dy[i] = v[j]
            dy[m + i] = (Fz[j] + frc) / self.mass[j]
        dy[2 * m:] = [dpm, dQ, dps, di, de]
        return dy

    def event_values(self, t, y, modes):
        z, v, Fz, fn, _ = self.forces(t, y, modes)
        on, rs = self.fr[0], self.fr[6]
        # slipping: v crosses zero against the slip direction; the 1e-9 m/s offset keeps solve_ivp from
        # finding the restart point itself (v = 0 there) as a root again (the kernel ignores starts on zero)
        return [(rs[j] * fn[j] - abs(Fz[j])) if modes[j] == 2 else v[j] + (1e-9 if modes[j] > 0 else -1e-9)
                for j in range(self.nz) if on[j]]


def run_reference(ec: EClutch, method: str, rtol: float):
    """Integrate with solve_ivp; restarts at breakpoints and friction events.  Returns (t, bearing force)."""
    tin, vin = _as_table(INPUT["bearing_reference"], "bearing_reference")
    py = PythonEClutch(ec, tin, vin)
    s = ec.assembly
    y_full, modes = s.initial_state(ec.rest_position)
    modes = modes.tolist()
    nz = s.nz
    py.q_alg = [y_full[2 + j] for j in range(nz - 2)]
    massive = py.massive
    y = [y_full[j] for j in massive] + [y_full[nz + j] for j in massive] + list(y_full[2 * nz: 2 * nz + 5])
    atol = np.array([s.atol[j] for j in massive] + [s.atol[nz + j] for j in massive]
                    + list(s.atol[2 * nz: 2 * nz + 5]))
    fr_idx = [j for j in range(nz) if s.fr_on[j]]
    m = len(massive)
    breaks = [b for b in tin if 0.0 < b < T_END] + [T_END]
    t0 = 0.0
    T, FB = [0.0], [y[2 * m + 2] * ec.actuator.slave_area]
    n_rhs = 0

    def fun(t, yy):
        nonlocal n_rhs
        n_rhs += 1
        return py.rhs(t, yy, modes)

    for t_stop in breaks:
        while t0 < t_stop - 1e-12:
            evs = []
            for k, j in enumerate(fr_idx):
                def ev(t, yy, k=k):
                    return py.event_values(t, yy, modes)[k]
                ev.terminal = True
                # stuck: F_s - |F| falls through zero; slipping with sign s: v crosses zero against s
                ev.direction = -1.0 if modes[j] == 2 else -float(np.sign(modes[j]))
                evs.append(ev)
            # consistency of the modes at the start (the kernel's _enforce_modes)
            z, v, Fz, fn, _ = py.forces(t0, y, modes)
            for j in fr_idx:
                i = massive.index(j)
                if modes[j] == 2:
                    if abs(Fz[j]) > py.fr[6][j] * fn[j]:
                        modes[j] = 1 if Fz[j] > 0 else -1
                        y[m + i] = 0.0
                elif y[m + i] == 0.0:
                    sgn = 1.0 if modes[j] > 0 else -1.0
                    if (Fz[j] - sgn * fn[j]) * sgn < 0.0:
                        if abs(Fz[j]) <= py.fr[6][j] * fn[j]:
                            modes[j] = 2
                        else:
                            modes[j] = 1 if Fz[j] > 0 else -1
            sol = solve_ivp(fun, (t0, t_stop), y, method=method, rtol=rtol, atol=atol, events=evs)
            T.extend(sol.t[1:].tolist())
            FB.extend((sol.y[2 * m + 2, 1:] * ec.actuator.slave_area).tolist())
            y = sol.y[:, -1].tolist()
            t0 = float(sol.t[-1])
            if sol.status == 1:
                z, v, Fz, fn, _ = py.forces(t0, y, modes)
                for k, j in enumerate(fr_idx):
                    if len(sol.t_events[k]):
                        i = massive.index(j)
                        y[m + i] = 0.0
                        if modes[j] == 2:  # break-away
                            modes[j] = 1 if Fz[j] > 0 else -1
                        # a slipping mass stopped: the consistency check at the restart sticks or turns it
            elif sol.status < 0:
                raise RuntimeError(sol.message)
            py.q_alg = py.unpack(y)[2]
    return np.array(T), np.array(FB), n_rhs


def best_of(fn, n):
    best = math.inf
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def reference_only():
    """Time one solve_ivp reference run per method (for checking the reference itself)."""
    ec = EClutch(clutch=ClutchModel.preset(4), friction=FrictionParameters())
    for method in ("Radau", "BDF", "LSODA"):
        t0 = time.perf_counter()
        T, FB, n = run_reference(ec, method, RTOL)
        print(method, f"{time.perf_counter() - t0:.2f} s", n, "RHS", len(T), "points", flush=True)


def frictionless_actuator():
    return ActuatorParameters(master_seal_friction=0.0, slave_seal_friction=0.0, seal_pressure_friction=0.0,
                              spindle_efficiency=1.0)


def timed(fn, n):
    """Median, min and max wall time of ``n`` calls [s], and the last result."""
    import statistics

    ts = []
    out = None
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), min(ts), max(ts), out


def compare(ec: EClutch, label: str, methods, repeats: int, n: int = 201):
    """Time clutchlab and the solve_ivp reference on one configuration; print the ratios (clutchlab: medians of
    ``n`` runs with min-max; the references: best of ``repeats``)."""
    ec.simulate(INPUT, T_END)  # compile / load cache
    system = ec.as_system(INPUT, rtol=RTOL)
    t_kernel, k_lo, k_hi, out = timed(lambda: contract.simulate(system, T_END, outputs=False, max_steps=500_000), n)
    stats = out.stats
    print(f"[{label}]")
    print(f"  clutchlab core (Rodas3, rtol {RTOL:g}): {t_kernel * 1e3:.3f} ms ({k_lo * 1e3:.3f}-{k_hi * 1e3:.3f}) -> "
          f"{T_END / t_kernel:,.0f}x real time ({stats['accepted_steps']} steps, {stats['rejected_steps']} rejected, "
          f"{stats['rhs_evaluations']} RHS, {stats['jacobians']} Jacobians, {len(out.events)} events)")
    t_sim, s_lo, s_hi, res = timed(lambda: ec.simulate(INPUT, T_END, rtol=RTOL), n)
    print(f"  clutchlab EClutch.simulate incl. outputs: {t_sim * 1e3:.3f} ms ({s_lo * 1e3:.3f}-{s_hi * 1e3:.3f}) -> "
          f"{T_END / t_sim:,.0f}x real time (medians of {n} runs, min-max)")
    tight = ec.simulate(INPUT, T_END, rtol=1e-8, atol_scale=1e-2)
    grid = np.linspace(0.0, T_END, 2001)
    fb_tight = np.interp(grid, tight.outputs_table.time_s, tight.outputs_table.bearing_force_N)
    peak = np.abs(fb_tight).max()
    err_cl = np.abs(np.interp(grid, res.outputs_table.time_s, res.outputs_table.bearing_force_N) - fb_tight).max() / peak
    print(f"  clutchlab error vs an rtol 1e-8 run: max |dF_b| = {err_cl * 100:.3f} % of peak; energy balance "
          f"residual {res.energy_balance()['relative']:.1e} of the input work")
    for method in methods:
        try:
            t_ref, (T, FB, n_rhs) = best_of(lambda: run_reference(ec, method, RTOL), repeats)
        except Exception as exc:  # report, do not hide
            print(f"  solve_ivp {method}: failed ({exc})")
            continue
        err_ref = np.abs(np.interp(grid, T, FB) - fb_tight).max() / peak
        print(f"  solve_ivp {method} (Python RHS, same rtol and atol): {t_ref:.2f} s, {n_rhs} RHS; "
              f"error {err_ref * 100:.3f} % of peak; clutchlab is {t_ref / t_sim:,.0f}x faster "
              f"({t_ref / t_kernel:,.0f}x kernel alone)")


def main(quick: bool = False, friction_reference: bool = False):
    print("E-clutch dynamics benchmark: 1 s, position control (release 7 mm and re-engage), Model 4")
    methods = ("Radau", "BDF", "LSODA")
    compare(EClutch(frictionless_actuator(), ClutchModel.preset(4), FrictionParameters.off()),
            "no friction anywhere (no events): the same smooth equations for both", methods, 1 if quick else 2)
    compare(EClutch(clutch=ClutchModel.preset(4), friction=FrictionParameters()),
            "friction on (seals, spindle, R_f.ds, R_f.pp)", methods if friction_reference else (), 1)
    if not friction_reference:
        print("  (solve_ivp with friction restarts at every stick/slip event: several minutes per run, "
              "pass --friction-reference to measure it)")

    # batch of 1,000 variants
    batch_timing(quick)
    batch_timing(quick, output_step=1e-2)


def batch_timing(quick: bool = False, rounds: int = 7, output_step: float = 1e-3) -> None:
    """A batch of variants (lever ratio x diaphragm scale), friction on, **building included**: one thread
    (build them all, then run them on one numba thread) against two (a list built, then run on two
    threads; and a generator: chunks of up to 32 run on one thread while the next ones are built on the
    other core, the rest on both once the last is built).  Alternating rounds after one round not counted
    (it maps the memory of the records, ~0.36 GB a run at the 1 ms output grid), medians (min-max)."""
    import statistics

    import numba

    n_r, n_s = (10, 10) if quick else (40, 25)
    ratios = np.linspace(-4.4, -3.6, n_r)
    scales = np.linspace(1.0, 1.5, n_s)

    def variants():
        return (EClutch(clutch=ClutchModel.preset(4, EClutchParameters(lever_ratio=r, diaphragm_scale=d)),
                        friction=FrictionParameters()) for r in ratios for d in scales)

    simulate_batch(list(variants())[:2], INPUT, T_END, output_step=1e-3)  # compile / load cache
    threads = numba.get_num_threads()
    times = {"1 thread (build, then run)": [], f"{threads} threads (build, then run)": [],
             f"{threads} threads (built while running)": []}
    for r in range(rounds + 1):
        for label in times:
            numba.set_num_threads(1 if label.startswith("1 ") else threads)
            t0 = time.perf_counter()
            b = simulate_batch(variants() if "while" in label else list(variants()), INPUT, T_END,
                               output_step=output_step)
            if r:
                times[label].append(time.perf_counter() - t0)
            finished = int((b.stats.status == 0).sum())
            del b
    numba.set_num_threads(threads)
    n = n_r * n_s
    print(f"batch of {n} variants with friction, outputs every {1e3 * output_step:g} ms, building included, "
          f"medians of {rounds} alternating rounds:")
    base = statistics.median(times["1 thread (build, then run)"])
    for label, ts in times.items():
        med = statistics.median(ts)
        print(f"  {label:40s} {med:6.2f} s ({min(ts):.2f}-{max(ts):.2f})  {base / med:4.2f}x the one thread; "
              f"{n * T_END / med:,.0f} simulated seconds per second")
    print(f"  {finished} of {n} finished (the last run)")


def build_timing(repeat: int = 21) -> None:
    """Building one variant (``ClutchModel.preset(4, ...)`` + ``EClutch``, friction on), lever ratio and
    diaphragm scale varied at every build (nothing reused from an identical request): medians of
    ``repeat`` rounds of 20 builds each, per build, with min-max."""
    import statistics

    def build(r, d):
        return EClutch(clutch=ClutchModel.preset(4, EClutchParameters(lever_ratio=r, diaphragm_scale=d)),
                       friction=FrictionParameters())

    build(-4.0, 1.0)  # the bundled curves read and the kernels loaded
    out = []
    for k in range(repeat):
        ratios = np.linspace(-4.4, -3.6, 20) + 1e-4 * k
        scales = np.linspace(1.0, 1.5, 20)
        t0 = time.perf_counter()
        for r, d in zip(ratios, scales):
            build(r, d)
        out.append((time.perf_counter() - t0) / 20)
    print(f"building one variant: {1e3 * statistics.median(out):.2f} ms ({1e3 * min(out):.2f}-{1e3 * max(out):.2f}), "
          f"medians of {repeat} rounds of 20")


if __name__ == "__main__":
    if "--clutchlab" in sys.argv:
        print(f"machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}")
        compare(EClutch(clutch=ClutchModel.preset(4), friction=FrictionParameters()),
                "friction on (seals, spindle, R_f.ds, R_f.pp)", (), 1)
    elif "--build" in sys.argv:
        build_timing()
    elif "--batch" in sys.argv:
        batch_timing(quick="--quick" in sys.argv)
        batch_timing(quick="--quick" in sys.argv, output_step=1e-2)
    elif "--reference-only" in sys.argv:
        reference_only()
    else:
        main(quick="--quick" in sys.argv, friction_reference="--friction-reference" in sys.argv)
