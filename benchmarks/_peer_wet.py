"""The wet-clutch engagement as a compiled peer: LSODA (``numbalsoda``) with a numba-compiled right-hand side.

The equations of :mod:`clutchlab.wet.system` (``wet_rhs``), assembled once more from clutchlab's public
compiled scalar functions (film, viscosity, asperity force, friction law, torques, heat balance, piston
speed, drive torque), written for numbalsoda's C signature ``rhs(t, u, du, p)``, and a ``numba.njit``
driver that integrates a whole run with ``numbalsoda.lsoda`` called from compiled code.  Numbalsoda's
LSODA has no event location and no step-by-step interface, so the driver does what a user of it would:

* one ``lsoda`` call per mode, over the remaining sample grid (LSODA's own interpolation gives the
  samples); the switching functions of the mode (those of the model: lock-up, break-away, the piston
  leaving and reaching its stop; in the same crossing directions) are checked at the samples;
* at the first crossing, the event time is refined in the sample interval by the Illinois variant of
  regula falsi, each trial point a short ``lsoda`` call from the bracket's left end, down to a bracket of
  ``event_tol`` [s];
* the mode changes as clutchlab's ``wet_update`` changes it (lock-up: slip speed set to 0, stick if the
  static capacity holds the drive torque, else the slip reverses; break-away in the drive torque's
  direction; the piston stop), and ``lsoda`` restarts there.

The film ``contact`` event of clutchlab changes no equation (the contact and film functions are smooth
through ``h = 0``), so the peer does not stop there.  Nor does it stop at the corners of the reference
profiles (numbalsoda has no ``tcrit``); LSODA's error control handles those kinks, as SciPy's does.

States are integrated scaled by clutchlab's typical magnitudes (:data:`clutchlab.wet.system.STATE_SCALES`,
the piston by its travel to contact): numbalsoda takes one scalar ``atol``, and ``atol = min(rtol, 1e-7)``
on the scaled states is clutchlab's per-state absolute tolerance
(:func:`clutchlab.wet.system.absolute_tolerance`).

Layout of the parameter array ``p`` (float64): ``p[0]`` its length, ``p[1]`` the friction mode (0 slip
positive, 1 stick, 2 slip negative, clutchlab's codes), ``p[2]`` the piston mode (0 free, 1 on its stop),
``p[3:5]`` the held inputs (force, slip-speed reference; 0 in a scenario run), then the constants
(:data:`CONSTANT_NAMES`), the friction law's coefficients, state scales and their inverses, scratch for
the physical state and the switching values, and the two reference profiles (times, then values).

``numbalsoda`` is imported only by :func:`solve` (its driver is compiled on first use), so
:func:`model` and :data:`rhs` import and run without it (``tests/wet/test_peer_equations.py``).
"""

from __future__ import annotations

import math
import warnings

import numba
import numpy as np
from numba import types

from clutchlab.wet import system as W
from clutchlab.wet.film import (asperity_force_scalar, film_scalar, separation_scalar, slip_velocity_scalar,
                                squeeze_film_force_scalar)
from clutchlab.wet.friction import ParametricFriction, parametric_mu_scalar
from clutchlab.wet.system import drive_torque, piston_speed
from clutchlab.wet.thermal import heat_balance_scalar
from clutchlab.wet.torque import asperity_torque_scalar, clutch_torque_scalar, viscous_torque_scalar
from clutchlab.wet.viscosity import viscosity_scalar

#: numbalsoda's ``lsoda_sig`` (``void(double, double*, double*, double*)``), declared here so that the
#: right-hand side compiles without numbalsoda
LSODA_SIG = types.void(types.double, types.CPointer(types.double), types.CPointer(types.double),
                       types.CPointer(types.double))

N = W.N_STATE
#: the switching functions the peer watches: clutchlab's first five (not the piston's ``piston_runs`` and
#: ``piston_turns``, which change no equation: clutchlab ends a step at the turn for its error control)
NG = W.G_RUNS
SLIP, STICK, SLIP_NEG = W.SLIP, W.STICK, W.SLIP_NEG
FREE, AT_STOP = W.FREE, W.AT_STOP
G_LOCKUP, G_BREAKAWAY, G_CONTACT, G_LEAVES, G_REACHES = (W.G_LOCKUP, W.G_BREAKAWAY, W.G_CONTACT, W.G_LEAVES,
                                                         W.G_REACHES)
#: event codes of the peer's log (clutchlab's names, :data:`clutchlab.wet.system.EVENTS`)
EV_LOCKUP, EV_BREAKAWAY, EV_REVERSAL, EV_REACHES, EV_LEAVES = (W.EV_LOCKUP, W.EV_BREAKAWAY, W.EV_REVERSAL,
                                                               W.EV_REACHES, W.EV_LEAVES)

# ----------------------------------------------------------------- layout of p
P_LEN, P_FMODE, P_PMODE, P_UFORCE, P_USPEED = 0, 1, 2, 3, 4
#: constants taken from clutchlab's packed record (by name), in this order from P_C
CONSTANT_NAMES = (
    "n_c", "r_eff", "sigma", "friction_area", "piston_h0", "mu_v1", "mu_v2", "mu_v3", "mu_v4", "heat_capacity",
    "k1", "k2", "gw_scale", "squeeze_coefficient", "spring_stiffness", "spring_preload", "total_inertia",
    "drive_torque_max", "motor_power_max", "speed_kp", "speed_ki", "actuator_time_constant", "actuator_force_max",
    "actuator_speed_max", "thermistor_time_constant", "reservoir_heat_capacity", "heater_power_max", "heater_gain",
    "heater_setpoint", "reservoir_cooling", "housing_heat_capacity", "housing_cooling", "fluid_housing_conductance",
    "ambient_temperature", "force_scale", "mu_scale", "speed_scale", "free_inertia",
)
P_C = 5
(C_NC, C_REFF, C_SIGMA, C_AREA, C_H0, C_MUV1, C_MUV2, C_MUV3, C_MUV4, C_CAP, C_K1, C_K2, C_GW, C_SQ, C_KSP, C_F0,
 C_J, C_TDMAX, C_PMAX, C_KP, C_KI, C_TAUA, C_FAMAX, C_VMAX, C_TAUM, C_CR, C_QHMAX, C_KH, C_TSET, C_COOLR, C_CH,
 C_COOLH, C_GFH, C_TAMB, C_FSCALE, C_MUSCALE, C_WSCALE, C_FREE) = range(P_C, P_C + len(CONSTANT_NAMES))
P_MU = P_C + len(CONSTANT_NAMES)      # mu0, mu_t, mu_e, v_s, t_ref
P_SCALE = P_MU + 5                    # state scales
P_ISCALE = P_SCALE + N                # their inverses
P_X = P_ISCALE + N                    # scratch: physical state
P_G = P_X + N                         # scratch: switching values
P_FN, P_FSTART, P_SN, P_SSTART = P_G + NG, P_G + NG + 1, P_G + NG + 2, P_G + NG + 3
P_PROFILES = P_G + NG + 4


def pack(clutch, bench, scenario, friction=None) -> np.ndarray:
    """The peer's parameter array for one engagement (constants as clutchlab packs them)."""
    law = ParametricFriction.bench_truth() if friction is None else friction
    if not isinstance(law, ParametricFriction):
        raise TypeError("the peer implements the parametric friction law only")
    c = W.pack_parameters(clutch, bench, scenario, law).constants[0]
    ft, fv = np.asarray(scenario.force_time, float), np.asarray(scenario.force_value, float)
    st, sv = np.asarray(scenario.speed_time, float), np.asarray(scenario.speed_value, float)
    n = P_PROFILES + 2 * (ft.size + st.size)
    p = np.zeros(n)
    p[P_LEN] = n
    for i, name in enumerate(CONSTANT_NAMES):
        p[P_C + i] = float(c[name])
    p[P_MU:P_MU + 5] = law.mu0, law.mu_t, law.mu_e, law.v_s, law.t_ref
    scale = W.STATE_SCALES.copy()
    scale[W.S_X] = clutch.piston_h0
    p[P_SCALE:P_SCALE + N] = scale
    p[P_ISCALE:P_ISCALE + N] = 1.0 / scale
    p[P_FN], p[P_FSTART] = ft.size, P_PROFILES
    p[P_SN], p[P_SSTART] = st.size, P_PROFILES + 2 * ft.size
    k = P_PROFILES
    for a in (ft, fv, st, sv):
        p[k:k + a.size] = a
        k += a.size
    return p


def initial_modes(x0, piston_h0: float):
    """(friction mode, piston mode) at t = 0, by clutchlab's rule (``wet.system.initial_modes``)."""
    m = W.initial_modes(np.asarray(x0, float), piston_h0)
    return int(m[W.M_FRICTION]), int(m[W.M_PISTON])


# ----------------------------------------------------------------- the equations
@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _pwl(t, p, start, n):
    """Piecewise-linear profile (times ``p[start:start+n]``, values after them), constant beyond its ends."""
    v0 = start + n
    if t <= p[start]:
        return p[v0]
    if t >= p[start + n - 1]:
        return p[v0 + n - 1]
    lo = start
    hi = start + n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if p[mid] <= t:
            lo = mid
        else:
            hi = mid
    w = (t - p[lo]) / (p[lo + 1] - p[lo])
    return p[lo + n] + w * (p[lo + n + 1] - p[lo + n])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def model(t, x, p, dx, g):
    """Right-hand side ``dx`` and switching values ``g`` (clutchlab's order) at physical state ``x`` in the
    modes held in ``p``; returns (drive torque, static capacity) [N*m] for the mode logic."""
    nc = p[C_NC]
    r_eff = p[C_REFF]
    sigma = p[C_SIGMA]
    area = p[C_AREA]
    xp = x[0]
    fa = x[1]
    w = x[2]
    temp = x[4]
    tf = x[5]
    th = x[6]
    fmode = int(p[P_FMODE])
    at_stop = p[P_PMODE] == 1.0
    h = separation_scalar(xp, p[C_H0], nc)                                   # Eq. 1
    hbar = film_scalar(h, sigma)                                             # Eq. 2
    muv = viscosity_scalar(temp, p[C_MUV1], p[C_MUV2], p[C_MUV3], p[C_MUV4])  # Eq. 7
    fc = asperity_force_scalar(h, sigma, area, p[C_GW])                      # Greenwood-Williamson
    v = slip_velocity_scalar(w, r_eff)
    v_abs = -v if fmode == SLIP_NEG else (v if fmode == SLIP else abs(v))  # |v| signed by the mode (clutchlab's)
    muf = p[C_MUSCALE] * parametric_mu_scalar(v_abs, temp, p[P_MU], p[P_MU + 1], p[P_MU + 2], p[P_MU + 3],
                                              p[P_MU + 4])
    cap = asperity_torque_scalar(r_eff, nc, muf, fc)                         # Eq. 4, static
    wref = p[C_WSCALE] * _pwl(t, p, int(p[P_SSTART]), int(p[P_SN])) + p[P_USPEED]
    fref = min(p[C_FSCALE] * _pwl(t, p, int(p[P_FSTART]), int(p[P_FN])) + p[P_UFORCE], p[C_FAMAX])
    if p[C_FREE] != 0.0:
        td = 0.0
        dx[3] = 0.0
    else:
        td, dx[3] = drive_torque(w, wref, x[3], p[C_TDMAX], p[C_PMAX], p[C_KP], p[C_KI])
    if fmode == STICK:
        wdot = 0.0
        pf = 0.0
        g[G_LOCKUP] = 1.0
        g[G_BREAKAWAY] = abs(td) - cap
    else:
        sgn = 1.0 if fmode == SLIP else -1.0
        tau = clutch_torque_scalar(r_eff, nc, muf, fc, muv, area, v, hbar, sgn)  # Eqs. 3-6
        wdot = (td - tau) / p[C_J]
        pf = tau * w
        g[G_LOCKUP] = sgn * w
        g[G_BREAKAWAY] = -1.0
    dx[2] = wdot
    fsp = p[C_F0] + p[C_KSP] * xp
    csq = squeeze_film_force_scalar(p[C_SQ], muv, -1.0 / nc, hbar)
    vfree = piston_speed(fa - fsp - fc, csq, p[C_VMAX])
    if at_stop:
        dx[0] = 0.0
        g[G_LEAVES] = vfree
        g[G_REACHES] = 1.0
    else:
        dx[0] = vfree
        g[G_LEAVES] = -1.0
        g[G_REACHES] = xp
    g[G_CONTACT] = h
    dx[1] = (fref - fa) / p[C_TAUA]
    qk1 = p[C_K1] * (temp - tf)
    qk2 = p[C_K2] * (temp - th)
    dx[4] = heat_balance_scalar(temp, pf, tf, th, p[C_CAP], p[C_K1], p[C_K2])  # Eq. 8
    qh = min(max(p[C_KH] * (p[C_TSET] - tf), 0.0), p[C_QHMAX])
    qfh = p[C_GFH] * (tf - th)
    dx[5] = (qk1 + qh - p[C_COOLR] * (tf - p[C_TAMB]) - qfh) / p[C_CR]
    dx[6] = (qk2 + qfh - p[C_COOLH] * (th - p[C_TAMB])) / p[C_CH]
    dx[7] = (temp - x[7]) / p[C_TAUM]
    dx[8] = pf
    dx[9] = qk1
    dx[10] = qk2
    dx[11] = td * w
    return td, cap


@numba.cfunc(LSODA_SIG, cache=True, nogil=True, error_model="numpy")
def rhs(t, u, du, p):
    """numbalsoda's right-hand side: scaled states ``u`` -> their rates ``du``; parameters and modes in ``p``."""
    d = numba.carray(p, (int(p[0]),))
    uu = numba.carray(u, (N,))
    dd = numba.carray(du, (N,))
    x = d[P_X:P_X + N]
    for i in range(N):
        x[i] = uu[i] * d[P_SCALE + i]
    model(t, x, d, dd, d[P_G:P_G + NG])
    for i in range(N):
        dd[i] *= d[P_ISCALE + i]


# ----------------------------------------------------------------- the driver (needs numbalsoda)
# numbalsoda's ``lsoda`` calls its C library through a ctypes function, whose address numba bakes into the
# caller: the driver cannot be cached and compiles in every process (numba says so once per process)
warnings.filterwarnings("ignore", message='Cannot cache compiled function "_integrate"',
                        category=numba.NumbaWarning)
lsoda = None  # numbalsoda.lsoda, bound by _load() before the driver is first compiled


def _load():
    """Import numbalsoda (once) and bind its ``lsoda`` for the driver."""
    global lsoda
    if lsoda is None:
        # Importing numbalsoda compiles a jitclass accessor whose ``__module__`` is None; clutchlab's
        # compile listener (clutchlab._compile_notice._is_clutchlab) calls ``.startswith`` on it and
        # raises AttributeError, failing the import.  Until that is fixed in src/, the listener is
        # set aside while numbalsoda is imported (nothing of clutchlab compiles meanwhile).
        from numba.core import event as ev

        kept = [x for x in list(ev._registered["numba:compile"])
                if type(x).__module__ == "clutchlab._compile_notice"]
        for x in kept:
            ev.unregister("numba:compile", x)
        try:
            from numbalsoda import lsoda as _lsoda  # noqa: PLC0415 (only the driver needs numbalsoda)
        finally:
            for x in kept:
                ev.register("numba:compile", x)
        lsoda = _lsoda
    return lsoda


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _switching(t, u, p, xs, dxs, g):
    """Switching values at scaled state ``u`` (only the functions that are not constant in the mode are
    evaluated through the model; the others are read off the state)."""
    fmode = int(p[P_FMODE])
    at_stop = p[P_PMODE] == 1.0
    if fmode == STICK or at_stop:
        for i in range(N):
            xs[i] = u[i] * p[P_SCALE + i]
        model(t, xs, p, dxs, g)
    else:
        g[G_LOCKUP] = (1.0 if fmode == SLIP else -1.0) * u[2]
        g[G_BREAKAWAY] = -1.0
        g[G_LEAVES] = -1.0
        g[G_REACHES] = u[0]


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _crossed(ga, gb, k):
    """Switching function ``k`` crossed zero from ``ga`` to ``gb`` in clutchlab's direction for it."""
    if k == G_LOCKUP or k == G_REACHES:  # falling
        return ga > 0.0 and gb <= 0.0
    return ga < 0.0 and gb >= 0.0        # rising (break-away, piston leaves its stop)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _first_crossing(ga, gb):
    for k in (G_LOCKUP, G_BREAKAWAY, G_LEAVES, G_REACHES):
        if _crossed(ga[k], gb[k], k):
            return k
    return -1


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _update(t, u, p, k, xs, dxs, g):
    """Mode change at switching function ``k`` (clutchlab's ``wet_update``); returns the event code or -1."""
    if k == G_LOCKUP:
        old = int(p[P_FMODE])
        u[2] = 0.0
        p[P_FMODE] = STICK
        for i in range(N):
            xs[i] = u[i] * p[P_SCALE + i]
        td, cap = model(t, xs, p, dxs, g)
        if abs(td) <= cap:
            return EV_LOCKUP
        p[P_FMODE] = SLIP_NEG if old == SLIP else SLIP
        return EV_REVERSAL
    if k == G_BREAKAWAY:
        for i in range(N):
            xs[i] = u[i] * p[P_SCALE + i]
        td, cap = model(t, xs, p, dxs, g)
        p[P_FMODE] = SLIP if td > 0.0 else SLIP_NEG
        return EV_BREAKAWAY
    if k == G_LEAVES:
        p[P_PMODE] = FREE
        return EV_LEAVES
    if k == G_REACHES:
        u[0] = 0.0
        p[P_PMODE] = AT_STOP
        for i in range(N):
            xs[i] = u[i] * p[P_SCALE + i]
        model(t, xs, p, dxs, g)
        if g[G_LEAVES] > 0.0:  # pushed off again at once: stays free
            p[P_PMODE] = FREE
            return -1
        return EV_REACHES
    return -1


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _integrate(address, x0, fmode, pmode, p, grid, rtol, atol, event_tol, window, out, ev_t, ev_code, stats):
    """A whole run on the sample ``grid``: states at the samples into ``out``, events into ``ev_t``/``ev_code``.

    ``stats``: [lsoda calls, events, status (0 ok, 1 lsoda failed, 2 event log full)].  ``window`` [s]:
    the longest span of one ``lsoda`` call (``inf``: to the end of the grid).
    """
    n = grid.shape[0]
    scale = p[P_SCALE:P_SCALE + N]
    iscale = p[P_ISCALE:P_ISCALE + N]
    xs = np.empty(N)
    dxs = np.empty(N)
    ga = np.empty(NG)
    gb = np.empty(NG)
    gm = np.empty(NG)
    u = np.empty(N)
    for i in range(N):
        u[i] = x0[i] * iscale[i]
        out[0, i] = x0[i]
    p[P_FMODE] = fmode
    p[P_PMODE] = pmode
    t = grid[0]
    j = 1                   # next sample to fill
    calls = 0
    nev = 0
    te = np.empty(n)
    two = np.empty(2)
    while j < n:
        # this call's outputs: t, then the samples after it up to the window's end
        m = 1
        te[0] = t
        while j + m - 1 < n and (m == 1 or grid[j + m - 1] - t <= window):
            te[m] = grid[j + m - 1]
            m += 1
        usol, ok = lsoda(address, u, te[:m], data=p, rtol=rtol, atol=atol, mxstep=100000)
        calls += 1
        if not ok:
            stats[0], stats[1], stats[2] = calls, nev, 1
            return
        _switching(t, u, p, xs, dxs, ga)
        hit = -1
        k = -1
        for i in range(1, m):
            _switching(te[i], usol[i], p, xs, dxs, gb)
            k = _first_crossing(ga, gb)
            if k >= 0:
                hit = i
                break
            ga[:] = gb
        if hit < 0:
            for i in range(1, m):
                for q in range(N):
                    out[j, q] = usol[i, q] * scale[q]
                j += 1
            t = te[m - 1]
            u[:] = usol[m - 1]
            continue
        for i in range(1, hit):
            for q in range(N):
                out[j, q] = usol[i, q] * scale[q]
            j += 1
        # Illinois: bracket [ta, tb] of switching function k; lsoda from (ta, ua) to each trial point
        ta = te[hit - 1]
        tb = te[hit]
        ua = usol[hit - 1].copy()
        ub = usol[hit].copy()
        fa = ga[k]
        fb = gb[k]
        side = 0
        while tb - ta > event_tol:
            tm = tb - fb * (tb - ta) / (fb - fa)
            lo = ta + 0.01 * (tb - ta)
            hi = tb - 0.01 * (tb - ta)
            if not (tm > lo):
                tm = lo
            elif not (tm < hi):
                tm = hi
            two[0] = ta
            two[1] = tm
            us, ok = lsoda(address, ua, two, data=p, rtol=rtol, atol=atol, mxstep=100000)
            calls += 1
            if not ok:
                stats[0], stats[1], stats[2] = calls, nev, 1
                return
            _switching(tm, us[1], p, xs, dxs, gm)
            if _crossed(fa, gm[k], k):   # crossing in [ta, tm]
                tb = tm
                ub[:] = us[1]
                fb = gm[k]
                if side == -1:
                    fa *= 0.5
                side = -1
            else:
                ta = tm
                ua[:] = us[1]
                fa = gm[k]
                if side == 1:
                    fb *= 0.5
                side = 1
        t = tb
        u[:] = ub
        code = _update(t, u, p, k, xs, dxs, gm)
        if code >= 0:
            if nev >= ev_t.shape[0]:
                stats[0], stats[1], stats[2] = calls, nev, 2
                return
            ev_t[nev] = t
            ev_code[nev] = code
            nev += 1
        if grid[j] - t <= 1e-14:  # an event on a sample
            for q in range(N):
                out[j, q] = u[q] * scale[q]
            j += 1
    stats[0], stats[1], stats[2] = calls, nev, 0


class Peer:
    """One engagement set up for the compiled peer: ``solve(rtol)`` integrates it on ``grid``."""

    def __init__(self, clutch, bench, scenario, friction=None, grid=None):
        self.p = pack(clutch, bench, scenario, friction)
        self.x0 = W.initial_state(scenario)
        self.modes = initial_modes(self.x0, clutch.piston_h0)
        self.grid = (np.arange(int(round(scenario.duration * 1000.0)) + 1) / 1000.0 if grid is None
                     else np.ascontiguousarray(grid, dtype=float))
        self.out = np.empty((self.grid.size, N))
        self.ev_t = np.empty(64)
        self.ev_code = np.empty(64, dtype=np.int64)
        self.stats = np.zeros(3, dtype=np.int64)
        _load()
        self.address = rhs.address

    def solve(self, rtol, atol=None, event_tol=None, window=math.inf):
        """States at the grid (``self.out``, physical units) and the events ``[(code, time)]``.

        ``atol`` applies to the scaled states (default ``min(rtol, 1e-7)``: clutchlab's absolute
        tolerances); ``event_tol`` [s] the width of the final event bracket (default ``1e-3 rtol`` s).
        """
        atol = min(rtol, 1e-7) if atol is None else atol
        event_tol = 1e-3 * rtol if event_tol is None else event_tol
        _integrate(self.address, self.x0, self.modes[0], self.modes[1], self.p, self.grid, float(rtol),
                   float(atol), float(event_tol), float(window), self.out, self.ev_t, self.ev_code, self.stats)
        if self.stats[2] != 0:
            raise RuntimeError(f"peer run failed (status {int(self.stats[2])}) after {int(self.stats[0])} lsoda calls")
        return self.out

    def events(self):
        """The last run's events as (name, time) (clutchlab's event names)."""
        return [(W.EVENTS[int(c)], float(t)) for c, t in zip(self.ev_code[:self.stats[1]], self.ev_t[:self.stats[1]])]

    def lockup_time(self) -> float:
        """The last run's first lock-up time [s] (NaN if none)."""
        for name, t in self.events():
            if name == "lockup":
                return t
        return math.nan
