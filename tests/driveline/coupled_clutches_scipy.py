#!/usr/bin/env python
"""Standalone SciPy reference solution of
Modelica.Mechanics.Rotational.Examples.CoupledClutches (MSL 4.x).

Model (all values from the MSL source):
    drive 10*sin(2*pi*5*t) -> J1 -clutch1- J2 -clutch2- J3 -clutch3- J4
    J1..J4 = 1 kg m^2, w(0) = [10, 0, 0, 0], phi(0) = 0
    clutch k: mu_pos = [0, 0.5], peak = 1.1, cgeo = 1, fn_max = 20
              -> sliding torque tau0 = 10*f_k, static limit tau0_max = 11*f_k
    f_1 = sin(2*pi*0.2*t + 1.570796326794897)   (free when <= 0)
    f_2 = step(t >= 0.4),  f_3 = step(t >= 0.9)
    w_rel_k = w_{k+1} - w_k, tau_k acts on flange_b (J_{k+1} gets -tau_k, J_k gets +tau_k)

Method: piecewise integration with solve_ivp (DOP853, rtol = atol = 1e-12) between
events; modes are held constant inside a segment. Stuck clutches are handled as
acceleration constraints (a_rel = 0) whose torques come from a small linear system;
the velocities stay states (no snapping unless snap=True). After every event the
mode decisions are iterated to a fixed point (release the worst violator of the
static limit, re-solve, ...), which mirrors the Modelica event iteration of
PartialFriction with w_small = 1e10.

Usage:
    from cc_scipy import reference
    r = reference()          # dict with "events", "final", "energy_error", ...
"""
import math
import time as _time

import numpy as np
from scipy.integrate import solve_ivp

# ----------------------------------------------------------------------------- parameters
J = np.array([1.0, 1.0, 1.0, 1.0])
W0 = np.array([10.0, 0.0, 0.0, 0.0])
MU0, PEAK, CGEO, FN_MAX = 0.5, 1.1, 1.0, 20.0
AMP_DRIVE, F_DRIVE = 10.0, 5.0
F_SIN2, PHASE_SIN2 = 0.2, 1.570796326794897          # literal phase from CoupledClutches.mo
T2, T3 = 0.4, 0.9
NAMES = ("clutch1", "clutch2", "clutch3")

FREE, FWD, STICK, BWD = "free", "forward", "stick", "backward"

# B[:, k]: generalized force of clutch torque tau_k on the inertias
#   upstream inertia k gets +tau_k, downstream inertia k+1 gets -tau_k
B = np.zeros((4, 3))
for _k in range(3):
    B[_k, _k] = 1.0
    B[_k + 1, _k] = -1.0
MINV = 1.0 / J

# state vector layout
IW = slice(0, 4)      # w1..w4
IP = slice(4, 8)      # phi1..phi4
IE_DRIVE = 8          # work of drive torque
IE_DISS = slice(9, 12)  # energy dissipated in clutch1..3 (integral of tau*w_rel)
NY = 12

# Dymola 2020x reference (MAP-LIB_ReferenceResults v4.0.0/v4.1.0, CoupledClutches.csv)
DYMOLA_EVENTS = [
    (0.4, "clutch2", BWD),
    (0.70962146, "clutch2", STICK),
    (0.79165828, "clutch1", STICK),
    (0.83110851, "clutch1", BWD),
    (0.9, "clutch3", BWD),
    (0.90684914, "clutch1", STICK),
    (1.00029586, "clutch1", BWD),
    (1.14396963, "clutch3", STICK),
    (1.25, "clutch1", FREE),
]
DYMOLA_FINAL = {  # last row (t = 1.5) of the reference CSV
    "J1.w": 3.2470345652406571,
    "clutch1.w_rel": -0.78382696434297217,
    "clutch2.w_rel": 6.1896017466106125e-16,
    "clutch3.w_rel": 7.9735789527515636e-12,
    "J1.phi": 7.4860921838966794,
    "clutch1.phi_rel": -3.3789424987018508,
    "clutch2.phi_rel": -1.3966728682610889,
    "clutch3.phi_rel": -1.5367256646014142,
}
DYMOLA_FINAL["J2.w"] = DYMOLA_FINAL["J1.w"] + DYMOLA_FINAL["clutch1.w_rel"]
DYMOLA_FINAL["J3.w"] = DYMOLA_FINAL["J2.w"] + DYMOLA_FINAL["clutch2.w_rel"]
DYMOLA_FINAL["J4.w"] = DYMOLA_FINAL["J3.w"] + DYMOLA_FINAL["clutch3.w_rel"]


# ----------------------------------------------------------------------------- inputs
def drive(t):
    return AMP_DRIVE * math.sin(2.0 * math.pi * F_DRIVE * t)


def f1(t):
    return math.sin(2.0 * math.pi * F_SIN2 * t + PHASE_SIN2)


def df1(t):
    return 2.0 * math.pi * F_SIN2 * math.cos(2.0 * math.pi * F_SIN2 * t + PHASE_SIN2)


def f_norm(t):
    return (f1(t), 1.0 if t >= T2 else 0.0, 1.0 if t >= T3 else 0.0)


def tau0(f):
    """Sliding torque at w_rel = 0 (constant mu table) for normalized force f."""
    return MU0 * CGEO * FN_MAX * f


def tau0_max(f):
    return PEAK * tau0(f)


def w_rel(y):
    w = y[IW]
    return w[1:] - w[:-1]


# ----------------------------------------------------------------------------- mechanics
def solve_torques(t, y, modes):
    """Clutch torques (3,), inertia accelerations (4,) and relative accelerations (3,)
    for a fixed mode vector. Stuck torques solve B_S^T M^-1 (F + B_S tau_S) = 0."""
    f = f_norm(t)
    tau = np.zeros(3)
    stuck = []
    for k in range(3):
        m = modes[k]
        if m == FWD:
            tau[k] = tau0(f[k])
        elif m == BWD:
            tau[k] = -tau0(f[k])
        elif m == STICK:
            stuck.append(k)
        # FREE: 0
    F = np.zeros(4)
    F[0] = drive(t)
    F0 = F + B @ tau
    if stuck:
        BS = B[:, stuck]
        A = BS.T @ (MINV[:, None] * BS)
        rhs = -BS.T @ (MINV * F0)
        tau[stuck] = np.linalg.solve(A, rhs)
    a = MINV * (F + B @ tau)
    arel = a[1:] - a[:-1]
    return tau, a, arel


def make_rhs(modes):
    def rhs(t, y):
        tau, a, _ = solve_torques(t, y, modes)
        w = y[IW]
        dy = np.empty(NY)
        dy[IW] = a
        dy[IP] = w
        dy[IE_DRIVE] = drive(t) * w[0]
        dy[IE_DISS] = tau * (w[1:] - w[:-1])
        return dy
    return rhs


def make_events(modes):
    """List of (event_function, description). Every event is terminal."""
    evs = []

    def add(fun, direction, desc):
        fun.terminal = True
        fun.direction = direction
        evs.append((fun, desc))

    for k in range(3):
        m = modes[k]
        if m in (FWD, BWD):
            def g(t, y, k=k):
                return y[k + 1] - y[k]
            # forward: w_rel falls through 0; backward: w_rel rises through 0
            add(g, -1.0 if m == FWD else 1.0, ("wrel", k))
        elif m == STICK:
            def gf(t, y, k=k):
                tau, _, _ = solve_torques(t, y, modes)
                return tau[k] - tau0_max(f_norm(t)[k])
            def gb(t, y, k=k):
                tau, _, _ = solve_torques(t, y, modes)
                return -tau[k] - tau0_max(f_norm(t)[k])
            add(gf, 1.0, ("break", k, FWD))
            add(gb, 1.0, ("break", k, BWD))

    def gfree(t, y):
        return f1(t)
    add(gfree, 0.0, ("f1",))
    return evs


# ----------------------------------------------------------------------------- mode logic
def free_after(t, k):
    """Is clutch k free (fn <= 0) right after time t (relation as evaluated at an event)?"""
    if k == 0:
        v = f1(t)
        if abs(v) < 1e-12:          # at the zero crossing: use the direction of change
            return df1(t) < 0.0
        return v <= 0.0
    return f_norm(t)[k] <= 0.0


def engage_mode(wr):
    if wr > 0.0:
        return FWD
    if wr < 0.0:
        return BWD
    return STICK


def settle(t, y, modes, log, tol=1e-12, max_iter=50):
    """Fixed-point iteration of the mode decisions at time t (state y fixed).
    Mutates modes, appends (t, element, new_mode) to log for every transition."""
    def setm(k, m):
        if modes[k] != m:
            modes[k] = m
            log.append((t, NAMES[k], m))

    wr = w_rel(y)
    # free / engage according to the normal force
    for k in range(3):
        if free_after(t, k):
            setm(k, FREE)
        elif modes[k] == FREE:
            setm(k, engage_mode(wr[k]))
    for _ in range(max_iter):
        tau, _, arel = solve_torques(t, y, modes)
        f = f_norm(t)
        # 1) stuck elements whose holding torque exceeds the static limit: release worst
        worst, worst_exc = None, 0.0
        for k in range(3):
            if modes[k] == STICK:
                lim = tau0_max(f[k])
                exc = abs(tau[k]) - lim
                if exc > tol * max(1.0, lim) and exc > worst_exc:
                    worst, worst_exc = k, exc
        if worst is not None:
            setm(worst, FWD if tau[worst] > 0 else BWD)
            continue
        # 2) an element sliding at w_rel ~ 0 must accelerate in its sliding direction
        bad = None
        for k in range(3):
            if modes[k] in (FWD, BWD) and abs(wr[k]) < 1e-9:
                s = 1.0 if modes[k] == FWD else -1.0
                if s * arel[k] < -tol:
                    bad = k
                    break
        if bad is not None:
            setm(bad, STICK)
            continue
        return modes
    raise RuntimeError("mode iteration did not converge at t=%r" % t)


def snap_stuck(y, modes):
    """Optional: put every rigid group (inertias joined by stuck clutches) on its
    momentum-weighted mean speed, so that stuck w_rel are exactly 0."""
    y = y.copy()
    w = y[IW]
    groups, cur = [], [0]
    for k in range(3):
        if modes[k] == STICK:
            cur.append(k + 1)
        else:
            groups.append(cur)
            cur = [k + 1]
    groups.append(cur)
    for g in groups:
        if len(g) > 1:
            wm = float(np.dot(J[g], w[g]) / J[g].sum())
            w[g] = wm
    y[IW] = w
    return y


# ----------------------------------------------------------------------------- driver
def reference(t_end=1.5, snap=False, rtol=1e-12, atol=1e-12, max_step=0.01,
              return_trajectory=False, method="DOP853", rhs_factory=None, events_factory=None):
    """Simulate CoupledClutches and return
    {"events": [(t, element, mode), ...],   # every mode change after t=0
     "final": {"J1.w": ..., "J2.w": ..., "J3.w": ..., "J4.w": ...,
               "clutch1.w_rel": ..., "clutch2.w_rel": ..., "clutch3.w_rel": ...,
               "J1.phi": ..., "clutchk.phi_rel": ..., "clutchk.tau": ...},
     "energy_error": KE(t_end) - KE(0) - W_drive + sum(D_k),
     "energy": {...}, "initial_modes": [...], "final_modes": {...},
     "n_segments": ..., "nfev": ...}
    snap=True: before every segment, put inertias joined by stuck clutches on their
    momentum-weighted mean speed (stuck w_rel exactly 0).
    rhs_factory / events_factory: replacements of make_rhs / make_events (the same equations, e.g.
    compiled: benchmarks/_cc_compiled.py)."""
    y = np.zeros(NY)
    y[IW] = W0
    t = 0.0
    wr0 = w_rel(y)
    # initialisation: free if fn <= 0, else direction of w_rel (stuck if 0)
    modes = [FREE if free_after(t, k) else engage_mode(wr0[k]) for k in range(3)]
    init_log = []
    settle(t, y, modes, init_log)          # also resolves a stuck initial element
    initial_modes = list(modes)
    log = []
    breaks = [tb for tb in (T2, T3) if 0.0 < tb < t_end] + [t_end]
    nseg, nfev = 0, 0
    traj_t, traj_y = [], []
    disabled = set()                        # events to ignore in the current segment
    while t < t_end:
        t_stop = min(tb for tb in breaks if tb > t)
        if snap:
            y = snap_stuck(y, modes)
        evs = [e for e in (events_factory or make_events)(modes) if e[1] not in disabled]
        sol = solve_ivp((rhs_factory or make_rhs)(modes), (t, t_stop), y, method=method,
                        rtol=rtol, atol=atol, max_step=max_step,
                        events=[e[0] for e in evs])
        nseg += 1
        nfev += sol.nfev
        if sol.status < 0:
            raise RuntimeError(sol.message)
        if return_trajectory:
            traj_t.append(sol.t)
            traj_y.append(sol.y)
        if sol.status == 1:                 # terminal event
            te = sol.t[-1]
            ye = sol.y[:, -1].copy()
            hit = [evs[i][1] for i in range(len(evs))
                   if len(sol.t_events[i]) and abs(sol.t_events[i][-1] - te) <= 1e-13]
            if te - t < 1e-13:              # spurious event at the segment start
                disabled.update(hit)
                continue
            disabled = set()
            for h in hit:
                if h[0] == "wrel":
                    k = h[1]
                    modes[k] = STICK
                    log.append((te, NAMES[k], STICK))
                elif h[0] == "break":
                    k, m = h[1], h[2]
                    modes[k] = m
                    log.append((te, NAMES[k], m))
                # "f1": handled by settle()
            settle(te, ye, modes, log)
            t, y = te, ye
        else:                               # reached a time event / the end
            t = sol.t[-1]
            y = sol.y[:, -1].copy()
            disabled = set()
            if t < t_end:
                settle(t, y, modes, log)

    tau, _, _ = solve_torques(t, y, modes)
    w = y[IW]
    ke = 0.5 * float(np.dot(J, w * w))
    ke0 = 0.5 * float(np.dot(J, W0 * W0))
    wd = float(y[IE_DRIVE])
    diss = [float(v) for v in y[IE_DISS]]
    err = ke - ke0 - wd + sum(diss)
    wr = w_rel(y)
    phi = y[IP]
    final = {"J%d.w" % (i + 1): float(w[i]) for i in range(4)}
    final.update({"%s.w_rel" % NAMES[k]: float(wr[k]) for k in range(3)})
    final["J1.phi"] = float(phi[0])
    final.update({"%s.phi_rel" % NAMES[k]: float(phi[k + 1] - phi[k]) for k in range(3)})
    final.update({"%s.tau" % NAMES[k]: float(tau[k]) for k in range(3)})
    out = {"events": log, "final": final, "energy_error": err,
           "final_modes": dict(zip(NAMES, modes)),
           "energy": {"KE0": ke0, "KE": ke, "W_drive": wd, "dissipated": diss},
           "initial_modes": initial_modes, "n_segments": nseg, "nfev": nfev}
    if return_trajectory:
        out["trajectory"] = (np.concatenate(traj_t), np.concatenate(traj_y, axis=1))
    return out


# ----------------------------------------------------------------------------- report
def compare_events(events, ref=DYMOLA_EVENTS):
    rows = []
    n = max(len(events), len(ref))
    for i in range(n):
        e = events[i] if i < len(events) else None
        r = ref[i] if i < len(ref) else None
        rows.append((e, r, None if (e is None or r is None) else e[0] - r[0],
                     e is not None and r is not None and e[1:] == r[1:]))
    return rows


def _print_result(res, title):
    print("=" * 78)
    print(title)
    print("=" * 78)
    print("initial modes:", dict(zip(NAMES, res["initial_modes"])))
    print("\nmode changes (this solution vs Dymola reference, which has 8 digits):")
    print("  %-16s %-8s %-9s | %-11s %-8s %-9s | %s" %
          ("t [s]", "elem", "mode", "Dymola t", "elem", "mode", "dt"))
    for e, r, dt, same in compare_events(res["events"]):
        es = "%-16.9f %-8s %-9s" % e if e else " " * 35
        rs = "%-11.8f %-8s %-9s" % r if r else " " * 30
        ds = ("%+.2e" % dt) if dt is not None else ""
        print("  %s | %s | %s%s" % (es, rs, ds, "" if same else "  MISMATCH"))
    print("\nfinal values at t = 1.5 s:")
    f = res["final"]
    for key in ("J1.w", "J2.w", "J3.w", "J4.w", "clutch1.w_rel", "clutch2.w_rel",
                "clutch3.w_rel", "J1.phi", "clutch1.phi_rel", "clutch2.phi_rel",
                "clutch3.phi_rel"):
        print("  %-16s % .13e   Dymola % .13e   diff % .2e" %
              (key, f[key], DYMOLA_FINAL[key], f[key] - DYMOLA_FINAL[key]))
    print("  clutch torques:", ", ".join("%s=%.6g" % (NAMES[k], f["%s.tau" % NAMES[k]])
                                       for k in range(3)))
    en = res["energy"]
    print("\nenergy: KE0=%.12f KE=%.12f W_drive=%.12f dissipated=%s" %
          (en["KE0"], en["KE"], en["W_drive"], ["%.12f" % d for d in en["dissipated"]]))
    print("energy balance error KE - KE0 - W_drive + sum(D) = %.3e J" % res["energy_error"])
    print("segments: %d, rhs evaluations: %d" % (res["n_segments"], res["nfev"]))


if __name__ == "__main__":
    t0 = _time.time()
    res = reference(1.5)
    t1 = _time.time()
    _print_result(res, "CoupledClutches, velocities kept as states (no snapping)  [%.1f s]"
                  % (t1 - t0))
    res_s = reference(1.5, snap=True)
    t2 = _time.time()
    _print_result(res_s, "Variant: stuck velocities snapped at every restart  [%.1f s]"
                  % (t2 - t1))
    print("\nsnap vs no-snap:")
    print("  max |dt_event| = %.2e s" % max(abs(a[0] - b[0]) for a, b in
                                            zip(res["events"], res_s["events"])))
    for key in ("J1.w", "J2.w", "J3.w", "J4.w", "clutch1.w_rel", "clutch2.w_rel",
                "clutch3.w_rel"):
        print("  %-14s diff %.2e" % (key, res_s["final"][key] - res["final"][key]))
