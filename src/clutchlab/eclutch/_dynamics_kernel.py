"""Compiled right-hand side and Rodas3 integrator of the E-clutch dynamics.

Private module: the public API is :mod:`clutchlab.eclutch.dynamics`.  The
equations are documented there and in docs/eclutch_dynamics.md; this file
only arranges them for speed.

State vector (``nz = 2 + n_q`` generalised coordinates: master piston,
CSC/bearing, then the network's free node coordinates)::

    y[0:nz]        positions z [m]
    y[nz:2nz]      velocities v [m/s]
    y[2nz + 0..4]  p_m [Pa], Q [m^3/s], p_s [Pa], i [A], controller integral [m*s]
    y[2nz + 5..7]  input work [J], dissipated energy [J], friction dissipation [J]

Mass-matrix rows are 1 except the position rows of massless network nodes
(0: algebraic force balance, a DAE of index 1).  Friction modes per
coordinate: 0 smooth (viscous only), +1/-1 slipping forwards/backwards, 2
stuck (the Modelica Standard Library's friction state machine).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..curves import curve_eval
from ..numerics.dopri import error_norm
from ..numerics.interp import bracket
from ..numerics.rosenbrock import (A31, A41, A43, C21, C31, C32, C41, C42, C43, GAMMA, GAMMA1, GAMMA2, lu_factor,
                                   lu_solve, rodas_next_step)

# parameter vector layout
P_AMC, P_ASL, P_MMC, P_MSL, P_CM, P_CS, P_LH, P_RH, P_GV, P_XSN, P_WSN, P_PCAV, P_CAVF = range(13)
P_R, P_L, P_KT, P_VSUP, P_IMAX, P_KIL, P_NS, P_FPRE, P_KPRE, P_UMIN, P_UMAX, P_XMAX = range(13, 25)
P_KSTOP, P_CSTOP, P_KP, P_KI, P_KD, P_KAW, P_REFMIN, P_REFMAX = range(25, 33)
N_PAR = 33

# input modes
VOLTAGE, POSITION, PRESCRIBED = 0, 1, 2
# event kinds recorded
EV_STICK, EV_BREAKAWAY, EV_REVERSAL, EV_CONTACT_CLOSE, EV_CONTACT_OPEN, EV_STOP_HIT, EV_STOP_LEAVE = range(7)
EV_CAVITATION_START, EV_CAVITATION_END = 7, 8
N_OTHER_EVENTS = 9  # end stops (4), cavitation (2), current limit (1), snifting port edges (2)
N_AUX_FIXED = 4  # V_drive, bearing force of the clutch, reference, bearing position used


@numba.njit(cache=True, nogil=True, inline="always")
def _table(tin, vin, interp, t):
    """Value and slope of the input table at ``t`` (linear or zero-order hold)."""
    if tin.shape[0] == 1:
        return vin[0], 0.0
    lo, w = bracket(tin, t)
    if interp == 1:
        if w >= 1.0 and t >= tin[lo + 1]:
            return vin[lo + 1], 0.0
        return vin[lo], 0.0
    dt = tin[lo + 1] - tin[lo]
    if t < tin[0] or t > tin[tin.shape[0] - 1] or dt <= 0.0:
        return vin[lo] + w * (vin[lo + 1] - vin[lo]), 0.0
    return vin[lo] + w * (vin[lo + 1] - vin[lo]), (vin[lo + 1] - vin[lo]) / dt


@numba.njit(cache=True, nogil=True, inline="always")
def _stop(pen, rate, ks, cs):
    """Hunt-Crossley end stop: force ``max(k d + c d d', 0)`` [N] and dissipated power ``(F - k d) d'`` [W].

    ``pen`` is the penetration d [m] (no contact if <= 0), ``rate`` its rate d' [m/s].  The force pushes
    out of the stop; the stored energy is k d^2 / 2.
    """
    if pen <= 0.0:
        return 0.0, 0.0
    f = max(ks * pen + cs * pen * rate, 0.0)
    return f, (f - ks * pen) * rate


@numba.njit(cache=True, nogil=True)
def rhs(t, y, modes, out, g, aux, nz, imode, tin, vin, interp, par, mass,
        GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral,
        fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c, f, fraw, Fz):
    """Right-hand side ``f(t, y)`` (residual for algebraic rows), event functions ``g`` and outputs ``aux``."""
    nq = nz - 2
    n_el = GA.shape[0]
    b0 = 2 * nz
    x_mc = y[0]
    v_mc = y[nz]
    p_m = y[b0]
    Q = y[b0 + 1]
    p_s = y[b0 + 2]
    cur = y[b0 + 3]
    e_int = y[b0 + 4]
    ref, ref_slope = _table(tin, vin, interp, t)
    if imode == PRESCRIBED:
        u = ref
        v_u = ref_slope
    else:
        u = y[1]
        v_u = y[nz + 1]
    # --- clutch network: element deflections and forces ([1] Figs. 5b, 10-11)
    bearing_force = 0.0
    for j in range(nz):
        Fz[j] = 0.0
    for e in range(n_el):
        de = d0[e] + Gb[e] * u
        for j in range(nq):
            de += GA[e, j] * y[2 + j]
        lo = offsets[e]
        hi = offsets[e + 1]
        fe, _ke = curve_eval(cx[lo:hi], cf[lo:hi], cd[lo:hi], kinds[e], extraps[e], de)
        fe *= scale[e]
        fraw[e] = fe
        if unilateral[e] and fe < 0.0:
            fe = 0.0
        f[e] = fe
        bearing_force += Gb[e] * fe
        for j in range(nq):
            Fz[2 + j] -= GA[e, j] * fe
    Fz[1] -= bearing_force
    # --- actuator ([1] Sec. 2.1, Fig. 5a; equations in clutchlab.eclutch.actuator)
    v_drive = 0.0
    dissip = 0.0
    if imode != PRESCRIBED:
        if imode == VOLTAGE:
            v_cmd = ref
            v_pid = ref
        else:
            r = min(max(ref, par[P_REFMIN]), par[P_REFMAX])
            v_pid = par[P_KP] * (r - u) + par[P_KI] * e_int - par[P_KD] * v_u
            v_cmd = v_pid
        # the drive: supply saturation, then its current limiter pulls the voltage back above i_max
        v_drive = min(max(v_cmd, -par[P_VSUP]), par[P_VSUP])
        excess = abs(cur) - par[P_IMAX]
        if excess > 0.0:
            v_drive -= par[P_KIL] * excess * (1.0 if cur > 0.0 else -1.0)
            v_drive = min(max(v_drive, -par[P_VSUP]), par[P_VSUP])
        omega = v_mc / par[P_NS]
        # motor: L di/dt = V - R i - k_t omega
        out[b0 + 3] = (v_drive - par[P_R] * cur - par[P_KT] * omega) / par[P_L]
        if imode == POSITION:
            r = min(max(ref, par[P_REFMIN]), par[P_REFMAX])
            out[b0 + 4] = (r - u) + par[P_KAW] * (v_drive - v_pid)
        else:
            out[b0 + 4] = 0.0
        Fz[0] += par[P_KT] * cur / par[P_NS] - p_m * par[P_AMC]
        # snifting port: vents the master chamber to the reservoir near the rest position
        opening = min(max((par[P_XSN] - x_mc) / par[P_WSN], 0.0), 1.0)
        q_vent = par[P_GV] * opening * p_m
        cm = par[P_CM] * (par[P_CAVF] if p_m < par[P_PCAV] else 1.0)
        cs = par[P_CS] * (par[P_CAVF] if p_s < par[P_PCAV] else 1.0)
        out[b0] = (par[P_AMC] * v_mc - Q - q_vent) / cm
        out[b0 + 1] = (p_m - p_s - par[P_RH] * Q) / par[P_LH]
        out[b0 + 2] = (Q - par[P_ASL] * v_u) / cs
        Fz[1] += p_s * par[P_ASL] + par[P_FPRE] - par[P_KPRE] * u
        dissip += par[P_R] * cur * cur + par[P_RH] * Q * Q + q_vent * p_m
        # end stops (Hunt-Crossley contact): master at 0 and its stroke, CSC at its travel limits
        ks = par[P_KSTOP]
        cs_ = par[P_CSTOP]
        fs, ds = _stop(-x_mc, -v_mc, ks, cs_)
        Fz[0] += fs
        dissip += ds
        fs, ds = _stop(x_mc - par[P_XMAX], v_mc, ks, cs_)
        Fz[0] -= fs
        dissip += ds
        fs, ds = _stop(par[P_UMIN] - u, -v_u, ks, cs_)
        Fz[1] += fs
        dissip += ds
        fs, ds = _stop(u - par[P_UMAX], v_u, ks, cs_)
        Fz[1] -= fs
        dissip += ds
        out[b0 + 5] = v_drive * cur
    else:
        for k in range(5):
            out[b0 + k] = 0.0
        out[b0 + 5] = bearing_force * v_u  # mechanical work done on the clutch at the bearing
    # --- coordinates: kinematics, friction state machine, force balance
    fric_dissip = 0.0
    for j in range(nz):
        vj = y[nz + j]
        frc = 0.0
        if fr_on[j]:
            fn = fr_c0[j]
            if fr_nidx[j] >= 0:
                fn += fr_mun[j] * abs(f[fr_nidx[j]])
            if fr_pidx[j] == 1:
                fn += fr_mup[j] * abs(p_m)
            elif fr_pidx[j] == 2:
                fn += fr_mup[j] * abs(p_s)
            if modes[j] == 2:
                g[j] = fr_rs[j] * fn - abs(Fz[j])
                frc = -Fz[j]
            else:
                g[j] = vj
                s = 1.0 if modes[j] > 0 else -1.0
                frc = -s * fn - fr_c[j] * vj
        else:
            g[j] = 1.0
            frc = -fr_c[j] * vj
        aux[N_AUX_FIXED + j] = frc
        frozen = (j == 1 and imode == PRESCRIBED) or (j == 0 and imode == PRESCRIBED)
        if frozen:
            out[j] = 0.0
            out[nz + j] = 0.0
        elif mass[j] > 0.0:
            if fr_on[j] and modes[j] == 2:
                out[j] = 0.0
                out[nz + j] = 0.0
            else:
                out[j] = vj
                out[nz + j] = (Fz[j] + frc) / mass[j]
                fric_dissip -= frc * vj
        else:
            out[j] = Fz[j]  # algebraic: massless node in equilibrium
            out[nz + j] = -vj
    out[b0 + 6] = dissip + fric_dissip
    out[b0 + 7] = fric_dissip
    # --- other event functions: contacts of unilateral elements, end stops
    for e in range(n_el):
        g[nz + e] = fraw[e] if unilateral[e] else 1.0
    ne = nz + n_el
    if imode != PRESCRIBED:
        g[ne] = x_mc
        g[ne + 1] = par[P_XMAX] - x_mc
        g[ne + 2] = u - par[P_UMIN]
        g[ne + 3] = par[P_UMAX] - u
        # kinks located so that no step straddles them: cavitation in either chamber, the drive's
        # current limit, the two edges of the snifting port
        g[ne + 4] = p_m - par[P_PCAV]
        g[ne + 5] = p_s - par[P_PCAV]
        g[ne + 6] = par[P_IMAX] - abs(cur)
        g[ne + 7] = x_mc - par[P_XSN]
        g[ne + 8] = x_mc - (par[P_XSN] - par[P_WSN])
    else:
        for k in range(N_OTHER_EVENTS):
            g[ne + k] = 1.0
    aux[0] = v_drive
    aux[1] = bearing_force
    aux[2] = ref
    aux[3] = u


@numba.njit(cache=True, nogil=True, inline="always")
def _normal(j, f, y, nz, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx):
    """Kinetic friction force magnitude F_c of coordinate ``j`` [N]."""
    fn = fr_c0[j]
    if fr_nidx[j] >= 0:
        fn += fr_mun[j] * abs(f[fr_nidx[j]])
    if fr_pidx[j] == 1:
        fn += fr_mup[j] * abs(y[2 * nz])
    elif fr_pidx[j] == 2:
        fn += fr_mup[j] * abs(y[2 * nz + 2])
    return fn


@numba.njit(cache=True, nogil=True)
def _enforce_modes(t, y, modes, Fz, f, nz, mass, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs,
                   ev_t, ev_kind, ev_idx, n_ev, max_ev):
    """Make the friction modes consistent with the forces at a step start (input jumps, start of a run).

    A stuck coordinate whose needed force exceeds the static limit breaks away; a coordinate slipping
    from exactly zero velocity against its force sticks or turns round.  Returns (changed, n_ev).
    """
    changed = False
    for j in range(nz):
        if not fr_on[j] or mass[j] <= 0.0:
            continue
        fn = _normal(j, f, y, nz, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx)
        kind = -1
        if modes[j] == 2:
            if abs(Fz[j]) > fr_rs[j] * fn:
                modes[j] = 1 if Fz[j] > 0.0 else -1
                y[nz + j] = 0.0
                kind = EV_BREAKAWAY
        elif y[nz + j] == 0.0:
            s = 1.0 if modes[j] > 0 else -1.0
            if (Fz[j] - s * fn) * s < 0.0:  # would accelerate against its slip direction
                if abs(Fz[j]) <= fr_rs[j] * fn:
                    modes[j] = 2
                    kind = EV_STICK
                else:
                    modes[j] = 1 if Fz[j] > 0.0 else -1
                    kind = EV_REVERSAL
        if kind >= 0:
            changed = True
            n_ev = _record(ev_t, ev_kind, ev_idx, n_ev, t, kind, j)
    return changed, n_ev


@numba.njit(cache=True, nogil=True)
def _step(t, y, h, J, mvec, f0, ft, nonauto, modes, ynew, err, G, piv, K1, K2, K3, K4, ytmp, ftmp, gtmp, atmp,
          nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale,
          unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c, f, fraw, Fz):
    """One Rodas3 step of size ``h`` from ``(t, y)``; returns False if the matrix is singular or NaN appears."""
    n = y.shape[0]
    hg = 1.0 / (h * GAMMA)
    for i in range(n):
        for j in range(n):
            G[i, j] = -J[i, j]
        G[i, i] += mvec[i] * hg
    if not lu_factor(G, piv):
        return False
    # stage 1
    for i in range(n):
        K1[i] = f0[i] + (h * GAMMA1 * ft[i] if nonauto else 0.0)
    lu_solve(G, piv, K1)
    # stage 2 (same argument as stage 1: a21 = 0)
    for i in range(n):
        K2[i] = f0[i] + mvec[i] * (C21 / h) * K1[i] + (h * GAMMA2 * ft[i] if nonauto else 0.0)
    lu_solve(G, piv, K2)
    # stage 3 at t + h, y + 2 K1
    for i in range(n):
        ytmp[i] = y[i] + A31 * K1[i]
    rhs(t + h, ytmp, modes, ftmp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd,
        offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c, f,
        fraw, Fz)
    for i in range(n):
        K3[i] = ftmp[i] + mvec[i] * (C31 * K1[i] + C32 * K2[i]) / h
    lu_solve(G, piv, K3)
    # stage 4 at t + h, y + 2 K1 + K3
    for i in range(n):
        ytmp[i] = y[i] + A41 * K1[i] + A43 * K3[i]
    rhs(t + h, ytmp, modes, ftmp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd,
        offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c, f,
        fraw, Fz)
    for i in range(n):
        K4[i] = ftmp[i] + mvec[i] * (C41 * K1[i] + C42 * K2[i] + C43 * K3[i]) / h
    lu_solve(G, piv, K4)
    ok = True
    for i in range(n):
        ynew[i] = ytmp[i] + K4[i]
        err[i] = K4[i]
        if not math.isfinite(ynew[i]):
            ok = False
    return ok


@numba.njit(cache=True, nogil=True, inline="always")
def _record(ev_t, ev_kind, ev_idx, n_ev, t, kind, idx):
    """Append an event (time [s], kind, index) if there is room; returns the new count."""
    if n_ev < ev_t.shape[0]:
        ev_t[n_ev] = t
        ev_kind[n_ev] = kind
        ev_idx[n_ev] = idx
        n_ev += 1
    return n_ev


@numba.njit(cache=True, nogil=True)
def _new_modes(t, y, modes, g_old, g_new, nz, n_el, imode, fr_on, Fz_at, fn_at, fr_rs, ev_t, ev_kind, ev_idx,
               n_ev, max_ev):
    """Apply the friction state machine after an event; record every event that fired. Returns n_ev."""
    for j in range(nz):
        if not fr_on[j]:
            continue
        if g_old[j] * g_new[j] < 0.0 or (g_new[j] == 0.0 and g_old[j] != 0.0):
            if modes[j] == 2:
                # break-away: slip in the direction of the applied force
                modes[j] = 1 if Fz_at[j] > 0.0 else -1
                y[nz + j] = 0.0  # exactly at rest when it starts to slip (no spurious reversal)
                kind = EV_BREAKAWAY
            else:
                if abs(Fz_at[j]) <= fr_rs[j] * fn_at[j]:
                    modes[j] = 2
                    y[nz + j] = 0.0
                    kind = EV_STICK
                else:
                    modes[j] = 1 if Fz_at[j] > 0.0 else -1
                    kind = EV_REVERSAL
            n_ev = _record(ev_t, ev_kind, ev_idx, n_ev, t, kind, j)
    for e in range(n_el):
        k = nz + e
        if g_old[k] * g_new[k] < 0.0:
            kind = EV_CONTACT_OPEN if g_new[k] < 0.0 else EV_CONTACT_CLOSE
            n_ev = _record(ev_t, ev_kind, ev_idx, n_ev, t, kind, e)
    ne = nz + n_el
    for s in range(4):
        k = ne + s
        if g_old[k] * g_new[k] < 0.0:
            kind = EV_STOP_HIT if g_new[k] < 0.0 else EV_STOP_LEAVE
            n_ev = _record(ev_t, ev_kind, ev_idx, n_ev, t, kind, s)
    for s in range(2):
        k = ne + 4 + s
        if g_old[k] * g_new[k] < 0.0:
            kind = EV_CAVITATION_START if g_new[k] < 0.0 else EV_CAVITATION_END
            n_ev = _record(ev_t, ev_kind, ev_idx, n_ev, t, kind, s)
    return n_ev


@numba.njit(cache=True, nogil=True)
def _crossed(g0, g1, n):
    """True if any event function changed sign strictly (a start on zero does not count)."""
    for k in range(n):
        if g0[k] * g1[k] < 0.0 or (g1[k] == 0.0 and g0[k] != 0.0):
            return True
    return False


@numba.njit(cache=True, nogil=True)
def _first_root(g0, g1, n):
    """Event index with the earliest linear-interpolated crossing and its fraction."""
    best = -1
    th = 2.0
    for k in range(n):
        if g0[k] * g1[k] < 0.0 or (g1[k] == 0.0 and g0[k] != 0.0):
            tk = g0[k] / (g0[k] - g1[k])
            if tk < th:
                th = tk
                best = k
    return best, th


@numba.njit(cache=True, nogil=True)
def integrate(y0, modes0, t0, t_end, nz, imode, tin, vin, interp, breaks, par, mass, mvec, typ,
              GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral,
              fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c,
              rtol, atol, h0, h_max, max_steps, t_grid, t_event_tol, jac_every):
    """Adaptive Rodas3 integration with event location.

    If ``t_grid`` has points, states are recorded there (linear interpolation
    between accepted steps); otherwise at every accepted step.

    Returns ``(T, Y, AUX, MODES, ev_t, ev_kind, ev_idx, stats, y_final, modes_final)`` with
    ``stats = [accepted, rejected, rhs evaluations, jacobians, status]`` (status 0 ok, 1 too many steps,
    2 step size underflow).
    """
    n = y0.shape[0]
    n_el = GA.shape[0]
    n_g = nz + n_el + N_OTHER_EVENTS
    n_aux = N_AUX_FIXED + nz
    n_jac = 2 * nz + 5
    use_grid = t_grid.shape[0] > 0
    n_rec = t_grid.shape[0] if use_grid else max_steps + 1
    T = np.empty(n_rec)
    Y = np.empty((n_rec, n))
    AUX = np.empty((n_rec, n_aux))
    MODES = np.empty((n_rec, nz), dtype=np.int64)
    max_ev = 100000
    ev_t = np.empty(max_ev)
    ev_kind = np.empty(max_ev, dtype=np.int64)
    ev_idx = np.empty(max_ev, dtype=np.int64)
    n_ev = 0
    stats = np.zeros(5, dtype=np.int64)
    # work arrays
    y = y0.copy()
    modes = modes0.copy()
    f0 = np.empty(n)
    ft = np.zeros(n)
    fp = np.empty(n)
    g0 = np.empty(n_g)
    g1 = np.empty(n_g)
    gtmp = np.empty(n_g)
    aux0 = np.empty(n_aux)
    atmp = np.empty(n_aux)
    J = np.zeros((n, n))
    G = np.empty((n, n))
    piv = np.empty(n, dtype=np.int64)
    K1 = np.empty(n)
    K2 = np.empty(n)
    K3 = np.empty(n)
    K4 = np.empty(n)
    ytmp = np.empty(n)
    ftmp = np.empty(n)
    y1 = np.empty(n)
    ye = np.empty(n)
    err = np.empty(n)
    yp = np.empty(n)
    f = np.empty(n_el)
    fraw = np.empty(n_el)
    Fz = np.empty(nz)
    Fz_at = np.empty(nz)
    fn_at = np.empty(nz)
    t = t0
    n_rhs = 0
    # record the initial point
    rhs(t, y, modes, f0, g0, aux0, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd, offsets, kinds,
        extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c, f, fraw, Fz)
    n_rhs += 1
    i_rec = 0
    if use_grid:
        while i_rec < n_rec and t_grid[i_rec] <= t:
            T[i_rec] = t_grid[i_rec]
            Y[i_rec, :] = y
            AUX[i_rec, :] = aux0
            MODES[i_rec, :] = modes
            i_rec += 1
    else:
        T[0] = t
        Y[0, :] = y
        AUX[0, :] = aux0
        MODES[0, :] = modes
        i_rec = 1
    h = h0
    i_break = 0
    while i_break < breaks.shape[0] and breaks[i_break] <= t + 1e-15:
        i_break += 1
    need_jac = True
    rejected_before = False
    status = 0
    nonauto = imode != VOLTAGE or interp == 0
    en = 0.0
    jac_age = jac_every
    jac_stale = True
    while t < t_end:
        if stats[0] >= max_steps:
            status = 1
            break
        if need_jac:
            # f0 and events at (t, y) with the current modes
            rhs(t, y, modes, f0, g0, aux0, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd, offsets,
                kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c, f,
                fraw, Fz)
            n_rhs += 1
            changed, n_ev = _enforce_modes(t, y, modes, Fz, f, nz, mass, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup,
                                           fr_pidx, fr_rs, ev_t, ev_kind, ev_idx, n_ev, max_ev)
            if changed:
                jac_stale = True
                rhs(t, y, modes, f0, g0, aux0, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd,
                    offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs,
                    fr_c, f, fraw, Fz)
                n_rhs += 1
        if need_jac and (jac_age >= jac_every or jac_stale):
            n_extra = 0
            for c in range(n_jac):
                yp[:] = y
                dl = 1.5e-8 * max(abs(y[c]), typ[c])
                yp[c] = y[c] + dl
                rhs(t, yp, modes, fp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd,
                    offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs,
                    fr_c, f, fraw, Fz)
                if _crossed(g0, gtmp, n_g):
                    # the forward difference straddles a kink (cavitation, a contact, an end stop, the current
                    # limit, ...): difference on the side the state is on, or the Jacobian mixes two regimes
                    # (a x1000 compliance change gave entries ~1e14 that froze the chamber pressure)
                    dl = -dl
                    yp[c] = y[c] + dl
                    rhs(t, yp, modes, fp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf,
                        cd, offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup,
                        fr_pidx, fr_rs, fr_c, f, fraw, Fz)
                    n_extra += 1
                for r in range(n):
                    J[r, c] = (fp[r] - f0[r]) / dl
            n_rhs += n_jac + n_extra
            jac_age = 0
            jac_stale = False
            stats[3] += 1
        if need_jac:
            if nonauto:
                t_next = breaks[i_break] if i_break < breaks.shape[0] else t_end + 1.0
                dt = 1e-7 * max(1e-3, abs(t))
                if t + dt < t_next:
                    rhs(t + dt, y, modes, fp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf,
                        cd, offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx,
                        fr_rs, fr_c, f, fraw, Fz)
                    for r in range(n):
                        ft[r] = (fp[r] - f0[r]) / dt
                else:
                    rhs(t - dt, y, modes, fp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf,
                        cd, offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx,
                        fr_rs, fr_c, f, fraw, Fz)
                    for r in range(n):
                        ft[r] = (f0[r] - fp[r]) / dt
                n_rhs += 1
            need_jac = False
        # step size limits: end, breakpoints of the input, h_max
        t_stop = t_end
        if i_break < breaks.shape[0] and breaks[i_break] < t_stop:
            t_stop = breaks[i_break]
        if t_stop - t <= 1e-12 * max(1.0, abs(t_stop)):
            # an event landed on (or a hair before) an input breakpoint: step over it
            if t_stop >= t_end:
                break
            while i_break < breaks.shape[0] and breaks[i_break] <= t_stop + 1e-12 * max(1.0, abs(t_stop)):
                i_break += 1
            t = t_stop
            need_jac = True
            jac_stale = True
            continue
        h = min(h, h_max)
        hit_stop = False
        if t + h >= t_stop - 1e-14 * max(1.0, abs(t_stop)):
            h = t_stop - t
            hit_stop = True
        if h < 1e-14 * max(1.0, abs(t)):
            status = 2
            break
        ok = _step(t, y, h, J, mvec, f0, ft, nonauto, modes, y1, err, G, piv, K1, K2, K3, K4, ytmp, ftmp, gtmp,
                   atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps,
                   scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c, f, fraw, Fz)
        n_rhs += 2
        en = error_norm(err, y, y1, rtol, atol) if ok else np.inf
        if en > 1.0:
            stats[1] += 1
            h = rodas_next_step(h, en, rejected_before)
            rejected_before = True
            if jac_age > 0:  # a stale Jacobian may be the cause: refresh it before retrying
                jac_stale = True
                need_jac = True
            continue
        # event functions at the end of the candidate step
        rhs(t + h, y1, modes, ftmp, g1, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd,
            offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c,
            f, fraw, Fz)
        n_rhs += 1
        th_step = 1.0
        event = _crossed(g0, g1, n_g)
        if event:
            # locate the earliest crossing by re-stepping from (t, y) (illinois on the step fraction)
            k_ev, th_guess = _first_root(g0, g1, n_g)
            lo = 0.0
            hi = 1.0
            glo = g0[k_ev]
            ghi = g1[k_ev]
            side = 0
            ye[:] = y1
            for _it in range(60):
                if (hi - lo) * h <= t_event_tol:
                    break
                th = lo + (hi - lo) * glo / (glo - ghi) if glo != ghi else 0.5 * (lo + hi)
                th = min(max(th, lo + 0.01 * (hi - lo)), hi - 0.01 * (hi - lo))
                okt = _step(t, y, th * h, J, mvec, f0, ft, nonauto, modes, ytmp, err, G, piv, K1, K2, K3, K4, yp,
                            ftmp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd, offsets,
                            kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs,
                            fr_c, f, fraw, Fz)
                n_rhs += 2
                if not okt:
                    break
                rhs(t + th * h, ytmp, modes, ftmp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0,
                    cx, cf, cd, offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup,
                    fr_pidx, fr_rs, fr_c, f, fraw, Fz)
                n_rhs += 1
                if _crossed(g0, gtmp, n_g):
                    # an event (maybe another, earlier one) happened before th
                    k2, _th2 = _first_root(g0, gtmp, n_g)
                    if k2 != k_ev:
                        k_ev = k2
                        glo = g0[k_ev]
                    hi = th
                    ghi = gtmp[k_ev]
                    ye[:] = ytmp
                    g1[:] = gtmp
                    if side == 1:
                        glo *= 0.5
                    side = 1
                else:
                    lo = th
                    glo = gtmp[k_ev]
                    if side == -1:
                        ghi *= 0.5
                    side = -1
            th_step = hi
            y1[:] = ye
            hit_stop = False
        # accept
        t_new = t + th_step * h
        if hit_stop and not event:
            t_new = t_stop
        if event:
            # forces at the event point, then the friction state machine
            rhs(t_new, y1, modes, ftmp, gtmp, atmp, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd,
                offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs,
                fr_c, f, fraw, Fz)
            n_rhs += 1
            for j in range(nz):
                Fz_at[j] = Fz[j]
                fn_at[j] = _normal(j, f, y1, nz, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx)
            n_ev = _new_modes(t_new, y1, modes, g0, g1, nz, n_el, imode, fr_on, Fz_at, fn_at, fr_rs, ev_t, ev_kind,
                              ev_idx, n_ev, max_ev)
        # record
        if use_grid:
            while i_rec < n_rec and t_grid[i_rec] <= t_new:
                w = (t_grid[i_rec] - t) / (t_new - t) if t_new > t else 1.0
                T[i_rec] = t_grid[i_rec]
                for r in range(n):
                    Y[i_rec, r] = y[r] + w * (y1[r] - y[r])
                AUX[i_rec, :] = aux0  # outputs of the step start (recomputed exactly by the caller if needed)
                MODES[i_rec, :] = modes
                i_rec += 1
        t = t_new
        y[:] = y1
        for j in range(nz):
            if modes[j] == 2:
                y[nz + j] = 0.0
        stats[0] += 1
        if hit_stop and i_break < breaks.shape[0] and t >= breaks[i_break] - 1e-14 * max(1.0, abs(t)):
            while i_break < breaks.shape[0] and breaks[i_break] <= t + 1e-14 * max(1.0, abs(t)):
                i_break += 1
        need_jac = True
        jac_age += 1
        if event:
            jac_stale = True  # modes changed: the Jacobian's structure changed
        if not use_grid:
            rhs(t, y, modes, ftmp, gtmp, aux0, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd, offsets,
                kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c, f,
                fraw, Fz)
            n_rhs += 1
            T[i_rec] = t
            Y[i_rec, :] = y
            AUX[i_rec, :] = aux0
            MODES[i_rec, :] = modes
            i_rec += 1
        if not event:
            h_new = rodas_next_step(h, en, rejected_before)
            h = h_new if not hit_stop else max(h, h_new)
        rejected_before = False
    stats[2] = n_rhs
    stats[4] = status
    if use_grid:
        while i_rec < n_rec:  # grid points at/after an early stop: hold the last state
            T[i_rec] = t_grid[i_rec]
            Y[i_rec, :] = y
            AUX[i_rec, :] = aux0
            MODES[i_rec, :] = modes
            i_rec += 1
    return (T[:i_rec], Y[:i_rec], AUX[:i_rec], MODES[:i_rec], ev_t[:n_ev].copy(), ev_kind[:n_ev].copy(),
            ev_idx[:n_ev].copy(), stats, y, modes)


@numba.njit(cache=True, nogil=True)
def outputs(T, Y, MODES, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps,
            scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c):
    """Outputs (aux) and element forces at recorded points, evaluated exactly from the states."""
    n = Y.shape[1]
    n_el = GA.shape[0]
    n_g = nz + n_el + N_OTHER_EVENTS
    AUX = np.empty((T.shape[0], N_AUX_FIXED + nz))
    F = np.empty((T.shape[0], n_el))
    out = np.empty(n)
    g = np.empty(n_g)
    f = np.empty(n_el)
    fraw = np.empty(n_el)
    Fz = np.empty(nz)
    aux = np.empty(N_AUX_FIXED + nz)
    for i in range(T.shape[0]):
        rhs(T[i], Y[i], MODES[i], out, g, aux, nz, imode, tin, vin, interp, par, mass, GA, Gb, d0, cx, cf, cd,
            offsets, kinds, extraps, scale, unilateral, fr_on, fr_c0, fr_mun, fr_nidx, fr_mup, fr_pidx, fr_rs, fr_c,
            f, fraw, Fz)
        AUX[i, :] = aux
        F[i, :] = f
    return AUX, F


@numba.njit(cache=True, parallel=True)
def integrate_batch(Y0, MODES0, t_end, nz, imode, tin, vin, interp, breaks, PAR, MASS, mvec, typ,
                    GA_b, Gb_b, d0_b, cx, cf, cd, offsets, kinds, extraps, SCALE, unilateral,
                    fr_on, FR_C0, FR_MUN, fr_nidx, FR_MUP, fr_pidx, FR_RS, FR_C,
                    rtol, atol, h0, h_max, max_steps, t_grid, t_event_tol, jac_every):
    """Integrate many variants in parallel (``prange``), one solver per variant, recorded on ``t_grid``.

    Per-variant arrays carry a leading variant axis (``Y0``, ``MODES0``, ``PAR``, ``MASS``, ``GA_b``,
    ``Gb_b``, ``d0_b``, ``SCALE``, ``FR_*``); the structure (curves, friction placement) is shared.
    Returns states, outputs and element forces on the grid, statistics and event counts per variant.
    """
    nv = Y0.shape[0]
    n = Y0.shape[1]
    n_el = GA_b.shape[1]
    OUT = np.empty((nv, t_grid.shape[0], n))
    AUXB = np.empty((nv, t_grid.shape[0], N_AUX_FIXED + nz))
    FB = np.empty((nv, t_grid.shape[0], n_el))
    STATS = np.empty((nv, 5), dtype=np.int64)
    NEV = np.empty(nv, dtype=np.int64)
    for v in numba.prange(nv):
        T, Yv, _A, Mv, evt, _k, _i, st, _yf, _mf = integrate(
            Y0[v], MODES0[v], 0.0, t_end, nz, imode, tin, vin, interp, breaks, PAR[v], MASS[v], mvec, typ,
            GA_b[v], Gb_b[v], d0_b[v], cx, cf, cd, offsets, kinds, extraps, SCALE[v], unilateral,
            fr_on, FR_C0[v], FR_MUN[v], fr_nidx, FR_MUP[v], fr_pidx, FR_RS[v], FR_C[v], rtol, atol, h0, h_max,
            max_steps, t_grid, t_event_tol, jac_every)
        A, Fv = outputs(T, Yv, Mv, nz, imode, tin, vin, interp, PAR[v], MASS[v], GA_b[v], Gb_b[v], d0_b[v], cx, cf,
                        cd, offsets, kinds, extraps, SCALE[v], unilateral, fr_on, FR_C0[v], FR_MUN[v], fr_nidx,
                        FR_MUP[v], fr_pidx, FR_RS[v], FR_C[v])
        OUT[v] = Yv
        AUXB[v] = A
        FB[v] = Fv
        STATS[v] = st
        NEV[v] = evt.shape[0]
    return OUT, AUXB, FB, STATS, NEV
