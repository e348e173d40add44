#!/usr/bin/env python
"""Standalone SciPy reference solution of the E-clutch launch ``examples/driveline_eclutch_launch.toml``.

Written from the documented equations, independent of clutchlab's driveline kernel, ``Driveline.simulate`` and
clutchlab's integrators.  The only thing taken from clutchlab is the clutch's clamp force F_n(t): the samples
(1 ms apart) that the built ``eclutch`` element stores as its ``Signal.sampled`` normal signal, computed once by
the E-clutch actuator run (``Driveline._eclutch_dynamics``).  They are read exactly as the network reads them:
linear between samples, held beyond the last one (``kernel._table``).

Sources of the equations
------------------------
docs/driveline.md, sections "Components", "Engines, the E-clutch actuator and the launch", "Friction semantics",
"Gears, motion sources and one-way clutches", "Backlash and nonlinear springs"; MSL 4.1
``Modelica.Mechanics.Rotational``: ``Interfaces.PartialFriction`` (stick/slip state machine), ``Components.Clutch``,
``Components.BearingFriction``, ``Components.SpringDamper``, ``Components.IdealGear``, ``Components.ElastoBacklash``
(geometry; the damping law is clutchlab's default Kelvin-Voigt contact, see below), ``Blocks.Continuous.LimPID``
(the idle controller's back-calculation anti-windup), ``Blocks.Sources.TimeTable`` (throttle).

Model (SI; the TOML's rpm -> rad/s with pi/30, deg -> rad with pi/180)
-----------------------------------------------------------------------
Inertias: engine 0.15, flywheel 0.08, input_shaft 0.02, output_shaft 0.05, axle 0.1, vehicle 139 kg m^2.
w(0) = 800 rpm on engine and flywheel, all others at rest (the gears carry the rest), all angles 0
(the driveshaft starts in the middle of its gap: phi_rel0 = 0).

Ideal gears (rigid): w_in = 3.5 w_out, w_out = 4.2 w_axle, so input_shaft, output_shaft and axle are one
degree of freedom, the axle's, with J_x = J_in G^2 + J_out 4.2^2 + J_axle, G = 14.7 (a torque tau on the
input shaft is G tau on the axle).  Four degrees of freedom: q = (engine, flywheel, axle, vehicle).

Engine (``ice`` on the engine inertia, reaction on the ground):
    T = map(w_e, throttle(t)) + T_idle, map bilinear in (speed, throttle), held beyond the grids
        speeds [0, 764, 1432, 2387, 3820, 6207] rpm, throttles [0, 1],
        torques [[-5, 60], [-10, 120], [-15, 180], [-20, 220], [-28, 230], [-40, 180]] N m
    throttle(t): table (0, 0), (0.4, 0), (1.0, 0.45), linear between, held after
    idle PI: e = w_idle - w_e, cmd = kp e + I, T_idle = clip(cmd, 0, T_max),
             dI/dt = ki e + (ki/kp) (T_idle - cmd)      (back-calculation; I(0) = 0)
    w_idle = 800 rpm, kp = 3 N m s/rad, ki = 30 N m/rad, T_max = 80 N m
Dual-mass flywheel ``dmf`` (SpringDamper a = engine, b = flywheel):
    tau = c (phi_f - phi_e) + d (w_f - w_e), c = 500, d = 1; +tau on the engine, -tau on the flywheel.
E-clutch ``clutch`` (a = flywheel, b = input_shaft), w_rel = w_in - w_f = G w_x - w_f:
    sliding torque 2 F_n r_eff mu (two faces, r_eff = 0.1026 m, mu = 0.27 constant: the Model 4 preset of
    ``EClutchParameters``), i.e. MSL Clutch with cgeo = 2 r_eff, fn = F_n(t), mu(w) = 0.27;
    static limit peak * tau0 with peak = 1 (the ``eclutch`` default): the same 2 F_n r_eff mu.
    free when F_n < 0, or F_n = 0 and not rising; the element torque tau acts +tau on flange a (flywheel),
    -tau on flange b (input shaft, i.e. -G tau on the axle degree of freedom).
    forward (w_rel > 0): tau = +tau0, backward: tau = -tau0, stuck: w_rel' = 0 with the torque it takes.
Driveshaft ``driveshaft`` (backlash a = axle, b = vehicle), phi_rel = phi_v - phi_x, w_rel = w_v - w_x,
    c = 10 kN m/rad, d = 50 N m s/rad, b_gap = 2 deg, clutchlab's default Kelvin-Voigt contact law:
    gap |phi_rel| < b/2: tau = 0; contact on side s (+1 upper, -1 lower): tau = c (phi_rel - s b/2) + d w_rel;
    contact begins at the edge moving into it (event ``contact``) and ends when s tau falls through 0 (the
    contact would pull; event ``separate``): beyond the edge (delta = s phi_rel - b/2 > 0) it is *released*
    (tau = 0) until delta falls to 0 (into the gap, no event) or s (c delta_signed + d w_rel) rises through 0
    (``contact`` again, beyond the edge); a separation at the edge itself goes into the gap.
    +tau on the axle, -tau on the vehicle.
Road ``road`` (BearingFriction, a = ground, b = vehicle, w_rel = w_v): sliding torque R(|w_v|), table
    [[0, 53], [10, 54.1], [20, 57.5], [40, 71.1], [80, 125.6]] N m (linear, extrapolated from the last two,
    never below 0); static limit peak R(0) = 53 N m (peak = 1); never free; -tau on the vehicle.

Friction state machine (docs "Friction semantics", MSL PartialFriction): a stuck element holds zero relative
acceleration with the torque the network needs (small linear system over the stuck set); it breaks away
(forward if that torque is positive, backward if negative) when |tau| reaches its static limit; a sliding
element whose relative speed reaches zero sticks if the torque needed to hold it is within its static limit,
otherwise it reverses; a clutch whose F_n leaves 0 engages in the direction of its relative speed.

Method: piecewise integration with ``solve_ivp`` (DOP853, rtol = atol = 1e-12) between restarts; the modes
are constant inside a segment.  Restarts at (i) every mode event, located with solve_ivp's terminal event
functions (slip zero crossings, break-away margins, backlash edges and contact torques), followed by a mode
decision at the event (fixed-point iteration: release the worst overloaded stuck element, stick a sliding
element at zero slip that accelerates against its direction), (ii) every kink of the right-hand side: each
F_n sample time where its slope changes (0.67 .. 3.5 s), the throttle's corners (0.4, 1.0 s), the engine
speed crossing a grid speed of the map, the idle command crossing 0 or T_max, the vehicle speed crossing a
road-table row.  Velocities stay states (a stuck element's slip drifts by the integration error only).

Usage:
    from launch_scipy import reference
    r = reference()   # dict: "events", "t", "engine.w_rad_s", "vehicle.w_rad_s", "idle_integral_Nm", ...
"""
import bisect
import math
import time as _time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

# ----------------------------------------------------------------------------- parameters (SI)
RPM = math.pi / 30.0
DEG = math.pi / 180.0

J_ENG, J_FLY, J_IN, J_OUT, J_AXLE, J_VEH = 0.15, 0.08, 0.02, 0.05, 0.1, 139.0
R_GEARBOX, R_FINAL = 3.5, 4.2
G = R_GEARBOX * R_FINAL                                    # input-shaft speed / axle speed
J_X = J_IN * G * G + J_OUT * R_FINAL * R_FINAL + J_AXLE    # input, output shaft and axle on the axle
JS = (J_ENG, J_FLY, J_X, J_VEH)
MINV = tuple(1.0 / j for j in JS)
W0_ENG = 800.0 * RPM

MAP_W = tuple(v * RPM for v in (0.0, 764.0, 1432.0, 2387.0, 3820.0, 6207.0))
MAP_TH = (0.0, 1.0)
MAP_T = ((-5.0, 60.0), (-10.0, 120.0), (-15.0, 180.0), (-20.0, 220.0), (-28.0, 230.0), (-40.0, 180.0))
THR_T, THR_V = (0.0, 0.4, 1.0), (0.0, 0.0, 0.45)
IDLE_W, IDLE_KP, IDLE_KI, IDLE_MAX = 800.0 * RPM, 3.0, 30.0, 80.0

DMF_C, DMF_D = 500.0, 1.0

R_EFF, MU_CL, N_FACES, PEAK_CL = 0.1026, 0.27, 2.0, 1.0
CL_GAIN = N_FACES * R_EFF * MU_CL            # sliding torque per newton of clamp force

LASH_C, LASH_D, LASH_B = 10e3, 50.0, 2.0 * DEG
LASH_B2 = 0.5 * LASH_B

ROAD_W = (0.0, 10.0, 20.0, 40.0, 80.0)
ROAD_T = (53.0, 54.1, 57.5, 71.1, 125.6)
PEAK_ROAD = 1.0

# generalized-force direction of each friction element's torque tau on q = (engine, flywheel, axle, vehicle);
# its relative speed is -B . w (clutch: G w_x - w_f; road: w_v)
B_CL = (0.0, 1.0, -G, 0.0)
B_ROAD = (0.0, 0.0, 0.0, -1.0)
FRICTION = ("clutch", "road")
B_OF = {"clutch": B_CL, "road": B_ROAD}

FREE, FWD, STICK, BWD = "free", "forward", "stick", "backward"
GAP, UPPER, LOWER, UPPER_REL, LOWER_REL = "gap", "upper", "lower", "upper_released", "lower_released"
SIDE = {UPPER: 1.0, LOWER: -1.0, UPPER_REL: 1.0, LOWER_REL: -1.0, GAP: 0.0}

# state layout
IP = slice(0, 4)            # angles of (engine, flywheel, axle, vehicle)
IW = slice(4, 8)            # speeds
II = 8                      # idle integral [N m]
IWK = 9                     # engine work [J]
ID = slice(10, 14)          # dissipation of dmf, clutch, driveshaft (damper), road [J]
NY = 14

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "driveline_eclutch_launch.toml"


# ----------------------------------------------------------------------------- clamp force input
def clamp_force_samples(path=EXAMPLE):
    """The E-clutch's clamp-force samples ``(times [s], F_n [N])`` as the built ``eclutch`` element stores them
    (its normal signal, ``Signal.sampled``: times then values in ``points``).  Building the element runs the
    E-clutch actuator model once; nothing of the driveline kernel is used."""
    from clutchlab.driveline.description import load_driveline
    d = load_driveline(str(path)).driveline
    times, values = d.signal("clutch").breakpoints("the clamp force", "N")
    return np.array(times, dtype=float), np.array(values, dtype=float)


class ClampForce:
    """F_n(t): linear between samples, held beyond the ends (as ``kernel._table``)."""

    def __init__(self, times, values):
        self.t = [float(v) for v in times]
        self.v = [float(v) for v in values]
        self.n = len(self.t)
        sl = [(self.v[k + 1] - self.v[k]) / (self.t[k + 1] - self.t[k]) for k in range(self.n - 1)]
        # the kinks: sample times where the slope changes (all zero before engagement, held after the last)
        sl_ext = [0.0] + sl + [0.0]
        self.kinks = [self.t[k] for k in range(self.n) if sl_ext[k] != sl_ext[k + 1]]

    def __call__(self, t):
        return _lin(self.t, self.v, t)

    def rate_right(self, t):
        """Slope from the right at t."""
        if t < self.t[0] or t >= self.t[-1]:
            return 0.0
        k = bisect.bisect_right(self.t, t) - 1
        return (self.v[k + 1] - self.v[k]) / (self.t[k + 1] - self.t[k])


# ----------------------------------------------------------------------------- component laws
def _lin(xs, ys, x):
    """Linear between points, held beyond the ends."""
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    i = bisect.bisect_right(xs, x) - 1
    return ys[i] + (x - xs[i]) / (xs[i + 1] - xs[i]) * (ys[i + 1] - ys[i])


def throttle(t):
    return _lin(THR_T, THR_V, t)


def engine_map(w, thr):
    """Bilinear in (speed, throttle), held beyond the grids."""
    wc = min(max(w, MAP_W[0]), MAP_W[-1])
    i = min(bisect.bisect_right(MAP_W, wc) - 1, len(MAP_W) - 2)
    a = (wc - MAP_W[i]) / (MAP_W[i + 1] - MAP_W[i])
    b = min(max(thr, 0.0), 1.0)            # throttle grid [0, 1]
    (f00, f01), (f10, f11) = MAP_T[i], MAP_T[i + 1]
    return (1.0 - a) * ((1.0 - b) * f00 + b * f01) + a * ((1.0 - b) * f10 + b * f11)


def idle(w, integral):
    """Idle PI: (T_idle, dI/dt, cmd)."""
    err = IDLE_W - w
    cmd = IDLE_KP * err + integral
    out = min(max(cmd, 0.0), IDLE_MAX)
    return out, IDLE_KI * err + (IDLE_KI / IDLE_KP) * (out - cmd), cmd


def road_torque(w_abs):
    """Sliding torque of the road table at |w|: linear, extrapolated from the last two rows, never below 0."""
    if w_abs >= ROAD_W[-1]:
        x0, x1, y0, y1 = ROAD_W[-2], ROAD_W[-1], ROAD_T[-2], ROAD_T[-1]
        return max(y1 + (y1 - y0) * (w_abs - x1) / (x1 - x0), 0.0)
    return _lin(ROAD_W, ROAD_T, w_abs)


def lash_torque(y, mode):
    """Driveshaft torque (acts + on the axle, - on the vehicle) and its elastic part."""
    if mode in (GAP, UPPER_REL, LOWER_REL):
        return 0.0, 0.0
    s = SIDE[mode]
    phi = y[3] - y[2]
    tc = LASH_C * (phi - s * LASH_B2)
    return tc + LASH_D * (y[7] - y[6]), tc


def lash_delta(y, s):
    """Deflection beyond the edge of side s (> 0 beyond it)."""
    return s * (y[3] - y[2]) - LASH_B2


def lash_push(y, s):
    """The contact's torque over c, signed so that > 0 pushes (the Kelvin-Voigt law continued)."""
    return s * ((y[3] - y[2]) - s * LASH_B2 + LASH_D / LASH_C * (y[7] - y[6]))


# ----------------------------------------------------------------------------- mechanics
def limits(fn):
    return {"clutch": PEAK_CL * CL_GAIN * fn, "road": PEAK_ROAD * road_torque(0.0)}


def solve(t, y, modes, fnf):
    """Generalized accelerations, element torques and the idle rate for a fixed mode set.
    Stuck elements: B_S^T M^-1 (F0 + B_S tau_S) = 0 (zero relative acceleration)."""
    we = y[4]
    thr = throttle(t)
    tid, d_int, _ = idle(we, y[II])
    t_eng = engine_map(we, thr) + tid
    t_dmf = DMF_C * (y[1] - y[0]) + DMF_D * (y[5] - y[4])
    t_lash, _ = lash_torque(y, modes["driveshaft"])
    fn = fnf(t)
    F = [t_eng + t_dmf, -t_dmf, t_lash, -t_lash]
    tau = {}
    stuck = []
    for name in FRICTION:
        m = modes[name]
        if name == "clutch":
            slide = CL_GAIN * fn
        else:
            slide = road_torque(abs(y[7]))
        if m == FREE:
            tau[name] = 0.0
        elif m == FWD:
            tau[name] = slide
        elif m == BWD:
            tau[name] = -slide
        else:
            stuck.append(name)
            continue
        b = B_OF[name]
        for i in range(4):
            F[i] += b[i] * tau[name]
    if stuck:
        # A lam = rhs, A_jk = sum_i B_ij B_ik / J_i, rhs_j = -sum_i B_ij F_i / J_i
        k = len(stuck)
        A = [[sum(B_OF[p][i] * B_OF[q][i] * MINV[i] for i in range(4)) for q in stuck] for p in stuck]
        r = [-sum(B_OF[p][i] * F[i] * MINV[i] for i in range(4)) for p in stuck]
        if k == 1:
            lam = [r[0] / A[0][0]]
        else:
            det = A[0][0] * A[1][1] - A[0][1] * A[1][0]
            lam = [(r[0] * A[1][1] - A[0][1] * r[1]) / det, (A[0][0] * r[1] - A[1][0] * r[0]) / det]
        for name, v in zip(stuck, lam):
            tau[name] = v
            b = B_OF[name]
            for i in range(4):
                F[i] += b[i] * v
    acc = [F[i] * MINV[i] for i in range(4)]
    return acc, tau, {"engine": t_eng, "dmf": t_dmf, "driveshaft": t_lash, "idle_rate": d_int, "fn": fn}


def rel_speed(y, name):
    b = B_OF[name]
    return -sum(b[i] * y[4 + i] for i in range(4))


def rel_acc(acc, name):
    b = B_OF[name]
    return -sum(b[i] * acc[i] for i in range(4))


def make_rhs(modes, fnf):
    def rhs(t, y):
        acc, tau, o = solve(t, y, modes, fnf)
        dy = np.empty(NY)
        dy[0:4] = y[4:8]
        dy[4:8] = acc
        dy[II] = o["idle_rate"]
        dy[IWK] = o["engine"] * y[4]
        dy[10] = DMF_D * (y[5] - y[4]) ** 2
        dy[11] = tau["clutch"] * rel_speed(y, "clutch")
        dy[12] = (0.0 if modes["driveshaft"] in (GAP,) else
                  (LASH_D * (y[7] - y[6]) ** 2 if modes["driveshaft"] in (UPPER, LOWER)
                   else -LASH_C * (y[3] - y[2] - SIDE[modes["driveshaft"]] * LASH_B2) * (y[7] - y[6])))
        dy[13] = tau["road"] * y[7]
        return dy
    return rhs


# ----------------------------------------------------------------------------- events
def make_events(modes, regions, fnf):
    """[(function, tag)], every one terminal.  Mode events and kinks of the right-hand side."""
    evs = []

    def add(fun, direction, tag):
        fun.terminal = True
        fun.direction = direction
        evs.append((fun, tag))

    for name in FRICTION:
        m = modes[name]
        if m in (FWD, BWD):
            def g(t, y, name=name):
                return rel_speed(y, name)
            add(g, -1.0 if m == FWD else 1.0, ("wrel", name))
        elif m == STICK:
            def gf(t, y, name=name):
                _, tau, o = solve(t, y, modes, fnf)
                return tau[name] - limits(o["fn"])[name]

            def gb(t, y, name=name):
                _, tau, o = solve(t, y, modes, fnf)
                return -tau[name] - limits(o["fn"])[name]
            add(gf, 1.0, ("break", name, FWD))
            add(gb, 1.0, ("break", name, BWD))
    lm = modes["driveshaft"]
    if lm == GAP:
        add(lambda t, y: lash_delta(y, 1.0), 1.0, ("lash_contact", UPPER))
        add(lambda t, y: lash_delta(y, -1.0), 1.0, ("lash_contact", LOWER))
    elif lm in (UPPER, LOWER):
        s = SIDE[lm]
        add(lambda t, y, s=s: lash_push(y, s), -1.0, ("lash_separate", lm))
    else:
        s = SIDE[lm]
        add(lambda t, y, s=s: lash_delta(y, s), -1.0, ("lash_gap", lm))
        add(lambda t, y, s=s: lash_push(y, s), 1.0, ("lash_contact", UPPER if s > 0 else LOWER))

    # kinks: crossings of a grid level, watched on both sides of the present region
    def level_events(key, levels, value):
        i = regions[key]
        if i >= 0:
            add(lambda t, y, L=levels[i]: value(t, y) - L, -1.0, ("kink", key, i - 1))
        if i + 1 < len(levels):
            add(lambda t, y, L=levels[i + 1]: value(t, y) - L, 1.0, ("kink", key, i + 1))

    level_events("engine_w", MAP_W, lambda t, y: y[4])
    level_events("idle_cmd", (0.0, IDLE_MAX), lambda t, y: idle(y[4], y[II])[2])
    if modes["road"] in (FWD, BWD):
        level_events("road_w", ROAD_W[1:], lambda t, y: abs(y[7]))
    return evs


def region_of(levels, v):
    """Index i with levels[i] <= v < levels[i+1] (-1 below the first)."""
    return bisect.bisect_right(levels, v) - 1


# ----------------------------------------------------------------------------- mode decisions
def settle(t, y, modes, fnf, tol=1e-12, max_iter=20):
    """Fixed-point iteration of the friction modes at t (state fixed); backlash modes are left alone."""
    fn = fnf(t)
    # the clutch: free when F_n < 0, or F_n = 0 and not rising; engages in the direction of its slip
    free = fn < 0.0 or (fn == 0.0 and fnf.rate_right(t) <= 0.0)
    if free:
        modes["clutch"] = FREE
    elif modes["clutch"] == FREE:
        wr = rel_speed(y, "clutch")
        modes["clutch"] = FWD if wr > 0 else BWD if wr < 0 else STICK
    for _ in range(max_iter):
        acc, tau, o = solve(t, y, modes, fnf)
        lim = limits(o["fn"])
        worst, worst_exc = None, 0.0
        for name in FRICTION:
            if modes[name] == STICK:
                exc = abs(tau[name]) - lim[name]
                if exc > tol * max(1.0, lim[name]) and exc > worst_exc:
                    worst, worst_exc = name, exc
        if worst is not None:
            modes[worst] = FWD if tau[worst] > 0 else BWD
            continue
        bad = None
        for name in FRICTION:
            if modes[name] in (FWD, BWD):
                wr = rel_speed(y, name)
                scale = max(1.0, max(abs(v) for v in y[4:8]))
                if abs(wr) < 1e-9 * scale:
                    s = 1.0 if modes[name] == FWD else -1.0
                    if s * rel_acc(acc, name) < -tol * scale:
                        bad = name
                        break
        if bad is not None:
            modes[bad] = STICK
            continue
        return modes
    raise RuntimeError("mode iteration did not converge at t=%r" % t)


# ----------------------------------------------------------------------------- driver
def reference(t_end=5.0, rtol=1e-12, grid=None, atol=None, fn_samples=None, max_step=np.inf,
              return_trajectory=False):
    """Simulate the launch; returns
    {"events": [(t, element, event), ...]  (clutchlab's names: stick/forward/backward/free, contact/separate),
     "t": grid, "<q>.w_rad_s" for q in engine, flywheel, axle, vehicle (+ input_shaft, output_shaft),
     "idle_integral_Nm" on the grid, "idle_integral_final_Nm", "final": {...}, "energy_error_J", ...}
    fn_samples: (times, F_n) of the clamp force; default: from the built element (:func:`clamp_force_samples`)."""
    atol = rtol if atol is None else atol
    grid = np.arange(501) * 0.01 if grid is None else np.asarray(grid, dtype=float)
    fnf = ClampForce(*(fn_samples if fn_samples is not None else clamp_force_samples()))
    y = np.zeros(NY)
    y[4] = W0_ENG
    y[5] = W0_ENG
    t = 0.0
    modes = {"clutch": FWD, "road": STICK, "driveshaft": GAP}
    wr = rel_speed(y, "clutch")
    modes["clutch"] = FWD if wr > 0 else BWD if wr < 0 else STICK
    modes["road"] = STICK if y[7] == 0.0 else (FWD if y[7] > 0 else BWD)
    settle(t, y, modes, fnf)
    initial_modes = dict(modes)
    acc0 = solve(t, y, modes, fnf)[0]
    _, _, cmd0 = idle(y[4], y[II])
    regions = {"engine_w": region_of(MAP_W, y[4]),
               "idle_cmd": (region_of((0.0, IDLE_MAX), cmd0) if cmd0 != 0.0 else
                            (0 if -IDLE_KP * acc0[0] >= 0 else -1)),
               "road_w": region_of(ROAD_W[1:], abs(y[7]))}
    breaks = sorted(set([tb for tb in list(fnf.kinks) + list(THR_T) if 0.0 < tb < t_end] + [t_end]))
    out = np.full((NY, grid.size), np.nan)
    log = []
    disabled = set()
    nseg = nfev = nkink = 0
    traj_t, traj_y = [], []
    while t < t_end:
        t_stop = breaks[bisect.bisect_right(breaks, t)] if t < breaks[-1] else t_end
        evs = [e for e in make_events(modes, regions, fnf) if e[1] not in disabled]
        sol = solve_ivp(make_rhs(modes, fnf), (t, t_stop), y, method="DOP853", rtol=rtol, atol=atol,
                        max_step=max_step, events=[e[0] for e in evs], dense_output=True)
        nseg += 1
        nfev += sol.nfev
        if sol.status < 0:
            raise RuntimeError(sol.message)
        t1 = sol.t[-1]
        sel = (grid >= t) & (grid <= t1)
        if sel.any():
            out[:, sel] = sol.sol(grid[sel])
        if return_trajectory:
            traj_t.append(sol.t)
            traj_y.append(sol.y)
        if sol.status == 1:
            te, ye = t1, sol.y[:, -1].copy()
            hit = [evs[i][1] for i in range(len(evs))
                   if len(sol.t_events[i]) and abs(sol.t_events[i][-1] - te) <= 1e-14 * max(1.0, te)]
            mode_hits = [h for h in hit if h[0] != "kink"]
            for h in hit:
                if h[0] == "kink":
                    regions[h[1]] = h[2]
                    nkink += 1
            if mode_hits and te - t < 1e-13:     # spurious event at the segment start
                disabled.update(mode_hits)
                t, y = te, ye
                continue
            disabled = set()
            if mode_hits:
                before = dict(modes)
                lash_log = []
                for h in mode_hits:
                    if h[0] == "wrel":
                        modes[h[1]] = STICK
                    elif h[0] == "break":
                        modes[h[1]] = h[2]
                    elif h[0] == "lash_contact":
                        modes["driveshaft"] = h[1]
                        lash_log.append("contact")
                    elif h[0] == "lash_separate":
                        s = SIDE[h[1]]
                        modes["driveshaft"] = ((UPPER_REL if s > 0 else LOWER_REL)
                                               if lash_delta(ye, s) > 0.0 else GAP)
                        lash_log.append("separate")
                    elif h[0] == "lash_gap":
                        modes["driveshaft"] = GAP
                settle(te, ye, modes, fnf)
                for ev in lash_log:
                    log.append((te, "driveshaft", ev))
                for name in FRICTION:
                    if modes[name] != before[name]:
                        log.append((te, name, modes[name]))
                if modes["road"] in (FWD, BWD) and before["road"] == STICK:
                    regions["road_w"] = region_of(ROAD_W[1:], abs(ye[7]))
            t, y = te, ye
        else:
            t, y = t1, sol.y[:, -1].copy()
            disabled = set()
            if t < t_end:
                before = dict(modes)
                settle(t, y, modes, fnf)
                for name in FRICTION:
                    if modes[name] != before[name]:
                        log.append((t, name, modes[name]))
    acc, tau, o = solve(t, y, modes, fnf)
    ke = 0.5 * sum(JS[i] * y[4 + i] ** 2 for i in range(4))
    ke0 = 0.5 * (J_ENG + J_FLY) * W0_ENG ** 2
    lm = modes["driveshaft"]
    pe = 0.5 * DMF_C * (y[1] - y[0]) ** 2
    if lm != GAP:
        pe += 0.5 * LASH_C * lash_delta(y, SIDE[lm]) ** 2
    diss = float(np.sum(y[ID]))
    res = {"events": log, "t": grid,
           "engine.w_rad_s": out[4], "flywheel.w_rad_s": out[5], "axle.w_rad_s": out[6],
           "input_shaft.w_rad_s": out[6] * G, "output_shaft.w_rad_s": out[6] * R_FINAL,
           "vehicle.w_rad_s": out[7], "idle_integral_Nm": out[II],
           "idle_integral_final_Nm": float(y[II]),
           "final": {"t": t, "engine.w_rad_s": float(y[4]), "flywheel.w_rad_s": float(y[5]),
                     "axle.w_rad_s": float(y[6]), "vehicle.w_rad_s": float(y[7]),
                     "clutch.tau_Nm": tau["clutch"], "road.tau_Nm": tau["road"],
                     "driveshaft.tau_Nm": o["driveshaft"], "ice.tau_Nm": o["engine"]},
           "final_modes": dict(modes), "initial_modes": initial_modes,
           "energy": {"KE0": ke0, "KE": ke, "spring": pe, "input_work": float(y[IWK]),
                      "dissipated": {k: float(v) for k, v in zip(("dmf", "clutch", "driveshaft", "road"), y[ID])}},
           "energy_error_J": float(y[IWK]) - diss - (ke + pe - ke0),
           "n_segments": nseg, "n_kinks": nkink, "nfev": nfev}
    if return_trajectory:
        res["trajectory"] = (np.concatenate(traj_t), np.concatenate(traj_y, axis=1))
    return res


def check_parameters(driveline):
    """Cross-check the constants above against a built clutchlab network (its element parameters, not its
    kernel): raises AssertionError naming the first that differs."""
    from clutchlab.eclutch.models import ClutchModel

    el = {e.name: e.arguments for e in driveline.elements}
    inert = {b.name: b.arguments for b in driveline.inertias}
    for nm, j in (("engine", J_ENG), ("flywheel", J_FLY), ("input_shaft", J_IN), ("output_shaft", J_OUT),
                  ("axle", J_AXLE), ("vehicle", J_VEH)):
        assert math.isclose(inert[nm]["J"], j, rel_tol=1e-15), nm
    assert math.isclose(inert["engine"]["w0"], W0_ENG, rel_tol=1e-15)
    ice = el["ice"]
    assert math.isclose(ice["idle_speed"], IDLE_W, rel_tol=1e-15)
    assert (ice["idle_kp"], ice["idle_ki"], ice["idle_torque_max"]) == (IDLE_KP, IDLE_KI, IDLE_MAX)
    speeds, throttles, torques = ice["torque_map"]
    assert np.allclose(speeds, MAP_W, rtol=1e-15) and tuple(throttles) == MAP_TH
    assert np.allclose(torques, MAP_T, rtol=0)
    assert (el["dmf"]["c"], el["dmf"]["d"]) == (DMF_C, DMF_D)
    clutch = el["clutch"]   # (its friction radius and coefficient are its axial model's)
    model = ClutchModel.preset(clutch["model"], clutch["parameters"])
    assert math.isclose(N_FACES * model.r_eff, N_FACES * R_EFF, rel_tol=1e-15) and clutch["peak"] == PEAK_CL
    assert model.mu == MU_CL and clutch["actuator"] is True
    assert (el["gearbox"]["ratio"], el["final_drive"]["ratio"]) == (R_GEARBOX, R_FINAL)
    assert el["gearbox"]["efficiency"] == el["final_drive"]["efficiency"] == 1.0
    c = el["driveshaft"]
    assert (c["c"], c["d"], c["phi_rel0"], c["damping_law"]) == (LASH_C, LASH_D, 0.0, "kelvin_voigt")
    assert math.isclose(c["b_gap"], LASH_B, rel_tol=1e-15)
    assert np.array_equal(np.asarray(el["road"]["torque"]).T.ravel(), ROAD_W + ROAD_T) \
        and el["road"]["peak"] == PEAK_ROAD
    return True


if __name__ == "__main__":
    t0 = _time.time()
    r = reference()
    print("reference at rtol 1e-12: %.1f s, %d segments (%d kinks), %d rhs evaluations"
          % (_time.time() - t0, r["n_segments"], r["n_kinks"], r["nfev"]))
    for e in r["events"]:
        print("  %.9f  %-11s %s" % e)
    print("final:", r["final"])
    print("idle integral at t_end: %.12g N m" % r["idle_integral_final_Nm"])
    print("energy balance error: %.3e J (input work %.6f J)" % (r["energy_error_J"], r["energy"]["input_work"]))
