"""Compiled simulation of the AWD vehicle with EMTC on a drum bench ([1], Secs. 3-4).

States ``y``: ``[omega_f, omega_r, theta, x, xdot, i1, i2]`` -- coupling input
and output shaft speeds [rad/s], Torsen twist angle since the last lock-up
[rad] (Eq. 30), armature displacement [m] and speed [m/s] (Eqs. 8-12), and the
two first-order current lags [A] (Fig. 15).  Integrated with Dormand-Prince
5(4); the hysteresis memories (plant magnet, controller model) are committed
once per accepted step, never inside the stages (stages evaluate the plant
magnet force with :func:`peek`).  Mode changes are events located on the
dense output inside the step:

* armature: at the rest stop (0), free (1), pressing the primary clutch (2);
* coupling: open (0, drag torque, Eq. 25-26), slipping (1), locked (2).

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..numerics import FASTMATH

from ..hysteresis._kernels import combine_tables, commit, gap_weights, invert_one, peek_combined
from ..numerics.dopri import (
    A21, A31, A32, A41, A42, A43, A51, A52, A53, A54, A61, A62, A63, A64, A65,
    B1, B3, B4, B5, B6, C2, C3, C4, C5, E1, E3, E4, E5, E6, E7,
    dense_hermite, error_norm, next_step,
)
from ..numerics.interp import bracket
from .torque import _locked, _slipping

NY = 7
N_OUT = 26
N_AUX = 12
# aux indices
AUX_FM, AUX_FN1, AUX_T1, AUX_T2, AUX_T3, AUX_TC, AUX_TLOCK, AUX_TTRANS, AUX_CAP, AUX_CASE, AUX_FN2, AUX_TE = range(12)
# event kinds
EV_ARM_REST, EV_ARM_CONTACT, EV_ARM_LEAVE_REST, EV_ARM_LEAVE_CONTACT, EV_LOCK, EV_SLIP_REVERSAL, EV_UNLOCK = range(7)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _interp(tx, ty, t):
    n = tx.shape[0]
    if n == 1:
        return ty[0]
    i, s = bracket(tx, t)  # clamped to the end values outside the profile
    return ty[i] + s * (ty[i + 1] - ty[i])


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _bilinear(xg, yg, z, x, y):
    i, s = bracket(xg, x)  # clamped to the map's edges
    j, r = bracket(yg, y)
    return z[i, j] * (1 - s) * (1 - r) + z[i + 1, j] * s * (1 - r) + z[i, j + 1] * (1 - s) * r + z[i + 1, j + 1] * s * r


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _stribeck_pv(v, pv):
    return pv[27] + (pv[28] - pv[27]) * math.exp(-((v / pv[29]) ** 2))  # [1], Eq. 24


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _lugre_advance_pv(z, v, h, pv):
    """Exact bristle update of Eq. 23 at constant slip (see friction.lugre_advance); parameters in pv[24:30]."""
    if v == 0.0 or h <= 0.0:
        return z
    g = _stribeck_pv(v, pv)
    zss = g / pv[24] * (1.0 if v > 0.0 else -1.0)
    return zss + (z - zss) * math.exp(-pv[24] * abs(v) * h / g)


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy", fastmath=FASTMATH)
def _rhs(t, y, dy, aux, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
         thr_t, thr_v, vf_t, vf_v, vr_t, vr_v,
         ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb):
    """Right-hand side ([1], Eqs. 8-12, 13-21, 25-30, Fig. 15); fills ``aux``."""
    arm = imode[0]
    cpl = imode[1]
    sdir = imode[2]
    i_cmd = pv[21]
    wf = y[0]
    wr = y[1]
    x = y[3]
    xd = y[4]
    # --- magnet force from the plant Preisach model at the coil current and airgap (Eq. 1, Eq. 12)
    icoil = min(max(y[6], pgrid[0]), pgrid[pgrid.shape[0] - 1])
    gap = pa[5] - x  # [1], Eq. 12
    if gap != pw[3]:  # airgap weights and combined table cached while the airgap is constant (armature at a stop)
        gap_weights(pgaps, min(max(gap, pgaps[0]), pgaps[pgaps.shape[0] - 1]), pidx, pw)
        combine_tables(ptab, pidx, pw, pcomb)
        pw[3] = gap
    fm = peek_combined(pcomb, pgrid, pstack, ppref, plen, pu, icoil, pidx, pw)
    aux[AUX_FM] = fm
    # --- armature (Eqs. 8-11)
    m0, kspr, fk0, csp, sigma = pa[0], pa[1], pa[2], pa[3], pa[4]
    fn1 = 0.0
    if arm == 1:
        dy[3] = xd
        dy[4] = (fm - fk0 - kspr * x - csp * xd) / m0  # [1], Eq. 9 with F_n0 = F_n1 = 0
    else:
        dy[3] = 0.0
        dy[4] = 0.0
        if arm == 2:
            fn1 = max(fm - fk0 - kspr * sigma, 0.0)  # [1], Eq. 11
    aux[AUX_FN1] = fn1
    # --- current control: two first-order lags (Fig. 15)
    dy[5] = (i_cmd - y[5]) / pa[6]
    dy[6] = (y[5] - y[6]) / pa[7]
    # --- driveline loads (Eq. 27)
    i0, ic, ig = pv[0], pv[1], pv[2]
    jf, jr, rw = pv[3], pv[4], pv[5]
    wwf = wf / ic
    wwr = wr / ic
    vdf = _interp(vf_t, vf_v, t)
    vdr = _interp(vr_t, vr_v, t)
    kf = 2.0 * pv[9] * rw / max(abs(vdf), pv[10])
    kr = 2.0 * pv[9] * rw / max(abs(vdr), pv[10])
    fxf = kf * (wwf * rw - vdf)  # tyre-drum longitudinal force, both wheels
    fxr = kr * (wwr * rw - vdr)
    rrf = pv[8] * pv[6] * rw * math.tanh(wwf / 0.5) + pv[19]
    rrr = pv[8] * pv[7] * rw * math.tanh(wwr / 0.5) + pv[20]
    thr = _interp(thr_t, thr_v, t)
    we = abs(wwf) * i0 * ig
    te = thr * min(pv[11], pv[12] / max(we, 1.0))
    ttrans = te * ig
    aux[AUX_TTRANS] = ttrans
    aux[AUX_TE] = te
    a_f = (ttrans * i0 - fxf * rw - rrf) / ic  # front loads at the coupling shaft
    a_r = (fxr * rw + rrr) / ic
    tlock = (jr * a_f + jf * a_r) / (jf + jr)  # [1], Eq. 29
    dw = wf - wr
    aux[AUX_TLOCK] = tlock
    t1 = 0.0
    t2 = 0.0
    t3 = 0.0
    cap = 0.0
    case = -1.0
    fn2 = 0.0
    lam_r = geo[11] / geo[12]
    if cpl == 0:
        tc = pv[16] * dw  # [1], Eqs. 25-26 (open: drag)
        dy[2] = 0.0
    elif cpl == 1:
        sl = dw if dw != 0.0 else float(sdir)
        if fric_mode == 1:
            mu = _bilinear(fmap_v, fmap_t, fmap_mu, abs(dw), pv[15])
            m1 = mu
            m2 = mu
            m3 = mu
        elif fric_mode == 2:
            # LuGre (Eqs. 22-23): bristle state advanced exactly from the committed value at the step start
            zb = _lugre_advance_pv(pv[31], dw, t - pv[30], pv)
            zdot = dw - pv[24] * abs(dw) / _stribeck_pv(dw, pv) * zb
            mu = pv[24] * zb + pv[25] * zdot + pv[26] * dw  # [1], Eq. 22
            if mu != 0.0:
                sl = mu
            m1 = abs(mu)
            m2 = m1
            m3 = m1
        else:
            m1 = geo[0]
            m2 = geo[1]
            m3 = geo[2]
        _slipping(fn1, sl, geo, m1, m2, m3, tmp3)  # [1], Eq. 15
        t1 = tmp3[0]
        t2 = tmp3[1]
        t3 = tmp3[2]
        tc = t1 + t2 + t3  # [1], Eq. 17
        fn2 = lam_r * abs(t1 + t3)  # [1], Eq. 14
        dy[2] = 0.0
    else:
        tl = tlock + pv[13] * y[2] + pv[14] * dw  # [1], Eq. 30
        code = _locked(fn1, tl, geo, pv[17], tmp3)
        if code >= 0:
            t1 = tmp3[0]
            t2 = tmp3[1]
            t3 = tmp3[2]
            case = code
        else:  # beyond the margin (only inside a step before the unlock event is located)
            t1 = tl
        tc = tl
        fn2 = lam_r * abs(t1 + t3)
        dy[2] = dw
    c1 = 2.0 / 3.0 * geo[3] * geo[6] * geo[9] * fn1
    a2 = 2.0 / 3.0 * geo[4] * geo[7] * geo[10] * lam_r
    a3 = 2.0 / 3.0 * geo[5] * geo[8] * lam_r
    cap = c1 * (1.0 + a2) / (1.0 - a3)  # [1], Eq. 21
    aux[AUX_T1] = t1
    aux[AUX_T2] = t2
    aux[AUX_T3] = t3
    aux[AUX_TC] = tc
    aux[AUX_CAP] = cap
    aux[AUX_CASE] = case
    aux[AUX_FN2] = fn2
    dy[0] = (a_f - tc) / jf  # [1], Eq. 27 (rows 1 and 3)
    dy[1] = (tc - a_r) / jr  # [1], Eq. 27 (rows 2 and 4)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _events(y, aux, imode, pv, pa, gv):
    """Event functions; an event occurs when one goes from > 0 to <= 0."""
    for k in range(6):
        gv[k] = 1.0
    arm = imode[0]
    fm = aux[AUX_FM]
    if arm == 1:
        gv[0] = y[3]  # reaches the rest stop
        gv[1] = pa[4] - y[3]  # reaches the primary clutch (x = sigma)
    elif arm == 0:
        gv[2] = pa[2] - fm  # magnet overcomes the preload
    else:
        gv[3] = fm - pa[2] - pa[1] * pa[4]  # F_n1 drops to zero (Eq. 11)
    if imode[1] == 1:
        gv[4] = imode[2] * (y[0] - y[1])  # slip speed reaches zero
    elif imode[1] == 2:
        gv[5] = pv[17] * aux[AUX_CAP] - abs(aux[AUX_TC])  # 1.02 T_cap < |T_lock|


#: layout of the ``carry`` vector of :func:`bench_advance` (what survives between two calls)
CARRY_T, CARRY_H, CARRY_PLEN, CARRY_PU, CARRY_CLEN, CARRY_CU, CARRY_FRESH = range(7)
CARRY_K1 = 7
CARRY_AUX = CARRY_K1 + NY
#: co-simulation steps that do not end on a sample (zero in a plain run): CARRY_HOLD = 1 -- the call starts
#: between two samples, so the first row keeps the held command (no controller); CARRY_STOP > 0 -- the last
#: row is at this time (between samples k0 + n - 2 and k0 + n - 1) instead of at sample k0 + n - 1
CARRY_HOLD = CARRY_AUX + N_AUX
CARRY_STOP = CARRY_HOLD + 1
N_CARRY = CARRY_STOP + 1


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def bench_kernel(y0, t_end, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                 thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, tm_thr, tm_v, tm_t, t_ref_override,
                 ptab, pgrid, pgaps, pstack, ppref,
                 ctab, cgrid, cgaps, cstack, cpref,
                 rtol, atol, out, ev, imode0, max_steps):
    """Integrate the bench model; returns ``(n_out, n_events, n_steps, status)``.

    ``out[k]`` holds the state and outputs at each controller sample; ``ev[k]``
    = (time, kind, arm mode after, coupling mode after).  status 0: done,
    1: hysteresis memory full, 2: step size underflow, 3: more than ``max_steps`` steps.
    A fresh run of :func:`bench_advance` from t = 0 (empty hysteresis memories).
    """
    y = y0.copy()
    imode = imode0.copy()
    carry = np.zeros(N_CARRY)
    carry[CARRY_H] = min(1e-4, pv[18])
    carry[CARRY_PU] = pgrid[0]
    carry[CARRY_CU] = cgrid[0]
    carry[CARRY_FRESH] = 1.0
    return bench_advance(y, imode, carry, 0, True, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                         thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, tm_thr, tm_v, tm_t, t_ref_override,
                         ptab, pgrid, pgaps, pstack, ppref, ctab, cgrid, cgaps, cstack, cpref,
                         rtol, atol, out, ev, max_steps)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def bench_advance(y, imode, carry, k0, control_last, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                  thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, tm_thr, tm_v, tm_t, t_ref_override,
                  ptab, pgrid, pgaps, pstack, ppref,
                  ctab, cgrid, cgaps, cstack, cpref,
                  rtol, atol, out, ev, max_steps):
    """Advance the bench model over ``out.shape[0]`` controller samples from sample ``k0`` (resumable).

    ``y`` (states) and ``imode`` (armature mode, coupling mode, slip
    direction) are updated in place, ``carry`` (see ``CARRY_*``: time, step
    size, hysteresis-memory lengths and last inputs, derivative and outputs
    at the current point) too; ``pv[21:23]`` and ``pv[30:32]`` (command,
    torque reference, LuGre memory) and the memory stacks persist in their
    arrays.  Row ``k`` of ``out`` is sample ``k0 + k`` at ``(k0 + k) *
    sample_time``.  With ``control_last`` false the controller does not run
    at the last sample (it is left to the next call, whose inputs may
    differ), so a chain of calls with ``control_last=False`` reproduces one
    uninterrupted call exactly.  ``carry[CARRY_FRESH]`` = 1 evaluates the
    derivative at the first sample (a fresh start).  ``carry[CARRY_HOLD]``
    and ``carry[CARRY_STOP]`` let a call start and end between samples (a
    co-simulation step that is not a multiple of the sample time); both are
    cleared on return.  Returns ``(n_out, n_events, n_steps, status)`` as
    :func:`bench_kernel`.
    """
    ts = pv[18]
    n_samples = out.shape[0]
    dy = np.zeros(NY)
    aux = np.zeros(N_AUX)
    tmp3 = np.zeros(6)
    k1 = np.zeros(NY)
    for q in range(NY):
        k1[q] = carry[CARRY_K1 + q]
    for q in range(N_AUX):
        aux[q] = carry[CARRY_AUX + q]
    fresh = carry[CARRY_FRESH] > 0.5
    k2 = np.zeros(NY)
    k3 = np.zeros(NY)
    k4 = np.zeros(NY)
    k5 = np.zeros(NY)
    k6 = np.zeros(NY)
    k7 = np.zeros(NY)
    yt = np.zeros(NY)
    ynew = np.zeros(NY)
    err = np.zeros(NY)
    ym = np.zeros(NY)
    gv0 = np.zeros(6)
    gv1 = np.zeros(6)
    gvm = np.zeros(6)
    auxm = np.zeros(N_AUX)
    dym = np.zeros(NY)
    idx = np.zeros(3, dtype=np.int64)
    w = np.zeros(3)
    pidx = np.zeros(3, dtype=np.int64)
    pw = np.zeros(4)
    pw[3] = np.nan
    pcomb = np.zeros((1, ptab.shape[1], ptab.shape[2], 4))
    plen = int(carry[CARRY_PLEN])
    pu = carry[CARRY_PU]
    clen = int(carry[CARRY_CLEN])
    cu = carry[CARRY_CU]
    n_ev = 0
    n_steps = 0
    t = carry[CARRY_T]
    h = carry[CARRY_H]
    gain = 1.0 + (2.0 * geo[11] * geo[1] * geo[7] * geo[10] + 2.0 * geo[11] * geo[2] * geo[8]) / (
        3.0 * geo[12] - 2.0 * geo[11] * geo[2] * geo[8])  # T_c / T_k1 by Eq. 15
    gap_c = pa[5] - pa[4]
    for ks in range(n_samples):
        t_s = (k0 + ks) * ts
        # ---- controller sample: torque reference (Eq. 31) -> F_n1 -> magnet force -> inverse Preisach (Eqs. 6-7)
        vx = y[0] / pv[1] * pv[5]
        thr = _interp(thr_t, thr_v, t_s)
        if t_ref_override.shape[0] > 0:
            t_ref = _interp(t_ref_override[0], t_ref_override[1], t_s)
        else:
            t_ref = _bilinear(tm_thr, tm_v, tm_t, thr, vx)
        tk1 = max(t_ref, 0.0) / gain
        fn1_req = tk1 / (2.0 / 3.0 * geo[0] * geo[6] * geo[9])  # [1], Eq. 13
        fm_req = fn1_req + pa[2] + pa[1] * pa[4] if t_ref > 0.0 else 0.0  # [1], Eq. 11 solved for F_m
        if (ks < n_samples - 1 or control_last) and not (ks == 0 and carry[CARRY_HOLD] > 0.5):
            gap_weights(cgaps, min(max(gap_c, cgaps[0]), cgaps[cgaps.shape[0] - 1]), idx, w)
            if clen + 2 > cstack.shape[0] or plen + 2 > pstack.shape[0]:
                return ks, n_ev, n_steps, 1
            i_new, ok = invert_one(ctab, cgrid, cstack, cpref, clen, cu, fm_req, idx, w, 1e-9)
            clen = commit(ctab, cgrid, cstack, cpref, clen, cu, i_new)
            cu = i_new
            pv[21] = i_new
            pv[22] = t_ref
        else:  # the next call runs the controller at this sample with its own inputs (or: between samples, held)
            i_new = pv[21]
            t_ref = pv[22]
            ok = True
        # ---- record the sample.  After the first sample, k1 and aux already hold the derivative and the
        # outputs at (t, y) from the last stage of the previous step; only dy[5] depends on the new command
        if ks == 0 and fresh:
            _rhs(t, y, dy, aux, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                 thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
        else:
            for q in range(NY):
                dy[q] = k1[q]
            dy[5] = (i_new - y[5]) / pa[6]  # Fig. 15, first lag: the only term that uses the command
        row = out[ks]
        row[0] = t
        for q in range(NY):
            row[1 + q] = y[q]
        for q in range(N_AUX):
            row[1 + NY + q] = aux[q]
        row[20] = imode[0]
        row[21] = imode[1]
        row[22] = i_new
        row[23] = t_ref
        row[24] = thr
        row[25] = 1.0 if ok else 0.0
        if ks == n_samples - 1:
            break
        t_next = (k0 + ks + 1) * ts
        if ks == n_samples - 2 and carry[CARRY_STOP] > 0.0:
            t_next = carry[CARRY_STOP]
        # ---- integrate to the next sample (the recorded evaluation is the first stage)
        for q in range(NY):
            k1[q] = dy[q]
        _events(y, aux, imode, pv, pa, gv0)
        rejected = False
        while t < t_next - 1e-12 * ts:
            h = min(h, t_next - t)
            pv[30] = t
            if h < 1e-12:
                return ks, n_ev, n_steps, 2
            for q in range(NY):
                yt[q] = y[q] + h * A21 * k1[q]
            _rhs(t + C2 * h, yt, k2, auxm, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                 thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
            for q in range(NY):
                yt[q] = y[q] + h * (A31 * k1[q] + A32 * k2[q])
            _rhs(t + C3 * h, yt, k3, auxm, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                 thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
            for q in range(NY):
                yt[q] = y[q] + h * (A41 * k1[q] + A42 * k2[q] + A43 * k3[q])
            _rhs(t + C4 * h, yt, k4, auxm, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                 thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
            for q in range(NY):
                yt[q] = y[q] + h * (A51 * k1[q] + A52 * k2[q] + A53 * k3[q] + A54 * k4[q])
            _rhs(t + C5 * h, yt, k5, auxm, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                 thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
            for q in range(NY):
                yt[q] = y[q] + h * (A61 * k1[q] + A62 * k2[q] + A63 * k3[q] + A64 * k4[q] + A65 * k5[q])
            _rhs(t + h, yt, k6, auxm, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                 thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
            for q in range(NY):
                ynew[q] = y[q] + h * (B1 * k1[q] + B3 * k3[q] + B4 * k4[q] + B5 * k5[q] + B6 * k6[q])
            _rhs(t + h, ynew, k7, auxm, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                 thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
            for q in range(NY):
                err[q] = h * (E1 * k1[q] + E3 * k3[q] + E4 * k4[q] + E5 * k5[q] + E6 * k6[q] + E7 * k7[q])
            en = error_norm(err, y, ynew, rtol, atol)
            if en > 1.0:
                h = next_step(h, en, rejected)
                rejected = True
                continue
            n_steps += 1
            if n_steps > max_steps:
                return ks, n_ev, n_steps, 3
            # ---- events inside the step (located on the dense output)
            _events(ynew, auxm, imode, pv, pa, gv1)
            kind = -1
            theta_ev = 1.0
            for e in range(6):
                if gv0[e] > 0.0 and gv1[e] <= 0.0:
                    lo = 0.0
                    hi = 1.0
                    for _ in range(48):
                        mid = 0.5 * (lo + hi)
                        dense_hermite(mid, h, y, k1, ynew, k7, ym)
                        _rhs(t + mid * h, ym, dym, auxm, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                             thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
                        _events(ym, auxm, imode, pv, pa, gvm)
                        if gvm[e] <= 0.0:
                            hi = mid
                        else:
                            lo = mid
                        if (hi - lo) * h < 1e-12:
                            break
                    if hi < theta_ev:
                        theta_ev = hi
                        kind = e
            if kind >= 0:
                dense_hermite(theta_ev, h, y, k1, ynew, k7, ym)
                for q in range(NY):
                    ynew[q] = ym[q]
                h_taken = theta_ev * h
            else:
                h_taken = h
            t = t + h_taken
            dw_start = y[0] - y[1]
            for q in range(NY):
                y[q] = ynew[q]
            # ---- commit the plant hysteresis memory once per accepted step
            inew = min(max(y[6], pgrid[0]), pgrid[pgrid.shape[0] - 1])
            if plen + 2 > pstack.shape[0]:
                return ks, n_ev, n_steps, 1
            plen = commit(ptab, pgrid, pstack, ppref, plen, pu, inew)
            pu = inew
            if fric_mode == 2:  # commit the LuGre bristle state once per accepted step
                dw_mid = 0.5 * ((y[0] - y[1]) + dw_start)
                pv[31] = _lugre_advance_pv(pv[31], dw_mid, h_taken, pv)
                pv[30] = t
            if kind >= 0:
                # apply the mode change
                code = -1
                if kind == 0:  # rest stop reached: plastic impact
                    y[3] = 0.0
                    y[4] = 0.0
                    imode[0] = 0
                    code = EV_ARM_REST
                elif kind == 1:  # primary clutch reached: engaged
                    y[3] = pa[4]
                    y[4] = 0.0
                    imode[0] = 2
                    imode[1] = 1
                    dwe = y[0] - y[1]
                    imode[2] = 1 if dwe >= 0.0 else -1
                    if fric_mode == 2 and dwe != 0.0:  # bristles start at their steady state for the slip
                        pv[31] = _stribeck_pv(dwe, pv) / pv[24] * imode[2]
                    code = EV_ARM_CONTACT
                elif kind == 2:
                    imode[0] = 1
                    code = EV_ARM_LEAVE_REST
                elif kind == 3:
                    imode[0] = 1
                    imode[1] = 0
                    y[2] = 0.0
                    code = EV_ARM_LEAVE_CONTACT
                elif kind == 4:  # slip speed zero: lock if the static capacity covers the lock torque (Fig. 11)
                    _rhs(t, y, dym, auxm, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                         thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
                    if abs(auxm[AUX_TLOCK]) <= auxm[AUX_CAP]:
                        wm = (y[0] * pv[3] + y[1] * pv[4]) / (pv[3] + pv[4])
                        y[0] = wm
                        y[1] = wm
                        y[2] = 0.0
                        imode[1] = 2
                        code = EV_LOCK
                    else:
                        imode[2] = -imode[2]
                        code = EV_SLIP_REVERSAL
                elif kind == 5:  # |T_lock| > 1.02 T_cap: slipping in the direction of the lock torque
                    imode[1] = 1
                    imode[2] = 1 if auxm[AUX_TC] >= 0.0 else -1
                    y[2] = 0.0
                    if fric_mode == 2:  # breakaway: bristles at full static deflection in the slip direction
                        pv[31] = pv[28] / pv[24] * imode[2]
                    code = EV_UNLOCK
                if n_ev < ev.shape[0]:
                    ev[n_ev, 0] = t
                    ev[n_ev, 1] = code
                    ev[n_ev, 2] = imode[0]
                    ev[n_ev, 3] = imode[1]
                    n_ev += 1
                h = max(h_taken, 1e-6)
                rejected = False
                _rhs(t, y, k1, aux, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                     thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
                _events(y, aux, imode, pv, pa, gv0)
            elif fric_mode == 2:  # the committed bristle state differs from the one used in k7
                h = next_step(h, en, rejected)
                rejected = False
                _rhs(t, y, k1, aux, imode, pv, pa, geo, fmap_v, fmap_t, fmap_mu, fric_mode,
                     thr_t, thr_v, vf_t, vf_v, vr_t, vr_v, ptab, pgrid, pgaps, pstack, ppref, plen, pu, tmp3, pidx, pw, pcomb)
                _events(y, aux, imode, pv, pa, gv0)
            else:
                h = next_step(h, en, rejected)
                rejected = False
                # first-same-as-last: k7 is the derivative at the new point; the committed
                # memory changes the magnet force only through the current already used in k7
                for q in range(NY):
                    k1[q] = k7[q]
                for q in range(6):
                    gv0[q] = gv1[q]
                for q in range(N_AUX):
                    aux[q] = auxm[q]
    carry[CARRY_T] = t
    carry[CARRY_H] = h
    carry[CARRY_PLEN] = plen
    carry[CARRY_PU] = pu
    carry[CARRY_CLEN] = clen
    carry[CARRY_CU] = cu
    carry[CARRY_FRESH] = 0.0
    carry[CARRY_HOLD] = 0.0
    carry[CARRY_STOP] = 0.0
    for q in range(NY):
        carry[CARRY_K1 + q] = dy[q]
    for q in range(N_AUX):
        carry[CARRY_AUX + q] = aux[q]
    return n_samples, n_ev, n_steps, 0
