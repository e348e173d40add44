"""Compiled peer of the EMTC drum-bench model: LSODA (``numbalsoda``) with a numba ``cfunc`` right-hand side.

What a user with a compiled LSODA and no clutchlab integrator would write for the model of
:mod:`clutchlab.emtc.system` (the ``emtc_bench`` system; used by ``benchmarks/wp_emtc.py`` for
issue #14):

* :data:`rhs` -- the right-hand side as a ``numba.cfunc`` with numbalsoda's signature
  ``rhs(t, u, du, p)``.  Everything goes through one float64 ``data`` array (``p``): scalars, the modes,
  the held current command, the plant's Preisach tables, grid, airgaps and its hysteresis memory (stack,
  prefix sums, length, last committed input), so the memory can change between calls.  The magnet force
  is clutchlab's compiled Preisach ``peek`` (as in the SciPy reference of ``bench_emtc.py``); the rest of
  the equations (Eqs. 8-30 of the EMTC paper: armature, current lags, drum-bench loads, drag, slipping
  split, locked coupling with the Torsen twist) are written here again, so that
  ``tests/emtc/test_peer_equations.py`` can check them against clutchlab's model.
* The integrated state is scaled: ``z = y / S`` with ``S`` the model's per-state absolute tolerances
  (``clutchlab.emtc.system.ATOL``), because numbalsoda takes one scalar ``atol``; a scalar ``atol = a``
  on ``z`` is the per-state ``atol = a * S`` on ``y``.
* :func:`run` -- an ``@njit`` driver for the whole run: between controller samples it calls
  ``lsoda(rhs_address, z0, t_eval, data, rtol, atol)`` on a sub-grid of ``nsub`` intervals per sample,
  runs the controller (torque map of Eq. 31, Eqs. 13/15/11, inverse Preisach model on its own memory) at
  each sample, and handles the six switching functions of the model (armature at rest / at the clutch,
  magnet overcoming the preload, clamp force vanishing, slip speed zero, lock capacity exceeded) by a
  sign change (falling through zero) on the sub-grid, refined by Illinois regula falsi with short lsoda
  calls from the sub-grid point before the crossing, then the mode change and a restart.
* Hysteresis memory of the plant magnet: an LSODA user gets no callback per accepted step, so the memory
  is committed after each lsoda call (at the end of every controller sample and at each event) at every
  sub-grid point of the call in order, i.e. turning points of the coil current are recorded at the
  sub-grid resolution, and inside a call the right-hand side sees the memory as it was at the call's
  start (clutchlab and the SciPy reference commit once per accepted step).  The coil current is smooth
  (two lags), so this changes the magnet force only where the current turns inside a sample.

``numbalsoda`` is imported only for the driver: the right-hand side (and :func:`pack`) work without it.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import types

from clutchlab.hysteresis import kernels as K



def _import_numbalsoda():
    """``(lsoda, lsoda_sig)`` from numbalsoda (the ``bench`` extra)."""
    from numbalsoda import lsoda as _lsoda, lsoda_sig as _sig

    return _lsoda, _sig


try:  # numbalsoda is the benchmark's extra; the equations (and their test) do not need it
    lsoda, lsoda_sig = _import_numbalsoda()
    HAVE_NUMBALSODA = True
except ImportError:  # pragma: no cover - depends on the environment
    lsoda = None
    lsoda_sig = types.void(types.double, types.CPointer(types.double), types.CPointer(types.double),
                           types.CPointer(types.double))  # numbalsoda's
    HAVE_NUMBALSODA = False

NX = 7
# ---------------------------------------------------------------- layout of the data array
(D_LEN, D_ARM, D_CPL, D_DIR, D_ICMD, D_PLEN, D_PU,
 # vehicle
 D_IC, D_RW, D_I0, D_IG, D_JF, D_JR, D_FZF, D_FZR, D_FRR, D_CX, D_VFLOOR, D_TMAX, D_PWR, D_KS, D_DS, D_DLF, D_DLR,
 # actuator
 D_M0, D_KSPR, D_FK0, D_CSPR, D_SIGMA, D_DOPEN, D_TAU1, D_TAU2,
 # coupling (drag, Eq. 25; unlock margin)
 D_NPAIRS, D_VISC, D_CLEAR, D_RO, D_RI, D_MARGIN,
 # drum speeds (held inputs)
 D_VF, D_VR,
 # offsets and sizes of the arrays below
 D_O_TAB, D_NA, D_NG, D_O_GRID, D_O_GAPS, D_O_STACK, D_CAP, D_O_PREF, D_NPREF,
 D_GEO, ) = range(50)
D_THR = D_GEO + 13  # throttle profile: 4 times, 4 values
D_SCALE = D_THR + 8  # state scales S (z = y / S)
D_HEADER = D_SCALE + NX

ARM_REST, ARM_FREE, ARM_CONTACT = 0, 1, 2
OPEN, SLIPPING, LOCKED = 0, 1, 2
NEGATIVE, POSITIVE = 0, 1


def pack(magnet, scenario, vehicle=None, actuator=None, coupling=None, memory_capacity=4096, scale=None):
    """The ``data`` array of the peer for a bench scenario (fresh memory, modes rest/open/positive)."""
    from clutchlab.emtc import ActuatorParameters, CouplingGeometry, VehicleParameters
    from clutchlab.emtc.system import ATOL
    from clutchlab.emtc.torque import UNLOCK_MARGIN

    veh = vehicle or VehicleParameters()
    act = actuator or ActuatorParameters()
    geo = coupling or CouplingGeometry()
    sc = scenario
    tables = np.ascontiguousarray(magnet.kernel_tables, float)
    grid = np.ascontiguousarray(magnet.grid, float)
    gaps = np.ascontiguousarray(magnet.airgaps, float)
    na, ng = tables.shape[0], grid.size
    cap = int(memory_capacity)
    npref = cap // 2 + 2
    o_tab = D_HEADER
    o_grid = o_tab + tables.size
    o_gaps = o_grid + ng
    o_stack = o_gaps + gaps.size
    o_pref = o_stack + cap
    n = o_pref + na * npref
    d = np.zeros(n)
    ic = veh.rear_final_drive
    fzf, fzr = veh.axle_loads()
    d[D_LEN] = n
    d[D_ARM], d[D_CPL], d[D_DIR] = ARM_REST, OPEN, POSITIVE
    d[D_ICMD] = 0.0
    d[D_PLEN] = 0
    d[D_PU] = grid[0]
    d[D_IC:D_DLR + 1] = [ic, veh.tyre_radius, veh.front_final_drive, veh.gear_ratios[sc.gear - 1],
                         veh.inertia_input_shaft + veh.inertia_front_axle / ic**2,
                         veh.inertia_output_shaft + veh.inertia_rear_axle / ic**2, fzf, fzr, veh.rolling_resistance,
                         veh.tyre_slip_stiffness, veh.slip_speed_floor, veh.engine_torque_max, veh.engine_power,
                         veh.torsen_stiffness, veh.torsen_damping, sc.drum_load_front, sc.drum_load_rear]
    d[D_M0:D_TAU2 + 1] = act.kernel_data()
    d[D_NPAIRS:D_MARGIN + 1] = [veh.drag_pairs, veh.oil_viscosity, veh.plate_clearance, veh.plate_outer_radius,
                                veh.plate_inner_radius, UNLOCK_MARGIN]
    d[D_VF], d[D_VR] = sc.drum_speed, sc.drum_speed - sc.speed_difference
    d[D_O_TAB], d[D_NA], d[D_NG], d[D_O_GRID], d[D_O_GAPS] = o_tab, na, ng, o_grid, o_gaps
    d[D_O_STACK], d[D_CAP], d[D_O_PREF], d[D_NPREF] = o_stack, cap, o_pref, npref
    d[D_GEO:D_GEO + 13] = geo.kernel_data()
    d[D_THR:D_THR + 8] = [0.0, sc.ramp_start, max(sc.ramp_end, sc.ramp_start + 1e-9), max(sc.duration, sc.ramp_end) + 1.0,
                          sc.throttle_start, sc.throttle_start, sc.throttle_end, sc.throttle_end]
    d[D_SCALE:D_SCALE + NX] = ATOL if scale is None else scale
    d[o_tab:o_grid] = tables.ravel()
    d[o_grid:o_gaps] = grid
    d[o_gaps:o_stack] = gaps
    return d


# ---------------------------------------------------------------- views of the data array
@numba.njit(cache=True)
def _tables(d):
    o = int(d[D_O_TAB])
    na = int(d[D_NA])
    ng = int(d[D_NG])
    return d[o:o + na * (ng - 1) * (ng - 1) * 4].reshape((na, ng - 1, ng - 1, 4))


@numba.njit(cache=True)
def _grid(d):
    o = int(d[D_O_GRID])
    return d[o:o + int(d[D_NG])]


@numba.njit(cache=True)
def _gaps(d):
    o = int(d[D_O_GAPS])
    return d[o:o + int(d[D_NA])]


@numba.njit(cache=True)
def _stack(d):
    o = int(d[D_O_STACK])
    return d[o:o + int(d[D_CAP])]


@numba.njit(cache=True)
def _prefix(d):
    o = int(d[D_O_PREF])
    npref = int(d[D_NPREF])
    return d[o:o + int(d[D_NA]) * npref].reshape((int(d[D_NA]), npref))


@numba.njit(cache=True)
def magnet_force(d, i2, xa):
    """Plant magnet force [N] at coil current ``i2`` and armature position ``xa`` (memory not committed)."""
    grid = _grid(d)
    gaps = _gaps(d)
    idx = np.zeros(K.GAP_TABLES, dtype=np.int64)
    w = np.zeros(K.GAP_TABLES)
    gap = d[D_DOPEN] - xa
    K.gap_weights(gaps, min(max(gap, gaps[0]), gaps[gaps.shape[0] - 1]), idx, w)
    i = min(max(i2, grid[0]), grid[grid.shape[0] - 1])
    return K.peek(_tables(d), grid, _stack(d), _prefix(d), int(d[D_PLEN]), d[D_PU], i, idx, w)


@numba.njit(cache=True)
def _throttle(d, t):
    o = D_THR
    if t <= d[o]:
        return d[o + 4]
    for k in range(3):
        if t <= d[o + k + 1]:
            s = (t - d[o + k]) / (d[o + k + 1] - d[o + k])
            return d[o + 4 + k] + s * (d[o + 5 + k] - d[o + 4 + k])
    return d[o + 7]


@numba.njit(cache=True)
def _locked_capacity(d, fn1):
    g = D_GEO
    lam_r = d[g + 11] / d[g + 12]
    c1 = 2.0 / 3.0 * d[g + 3] * d[g + 6] * d[g + 9] * fn1
    a2 = 2.0 / 3.0 * d[g + 4] * d[g + 7] * d[g + 10] * lam_r
    a3 = 2.0 / 3.0 * d[g + 5] * d[g + 8] * lam_r
    return c1 * (1.0 + a2) / (1.0 - a3)  # Eq. 21


@numba.njit(cache=True)
def _slip_torque(d, fn1):
    g = D_GEO
    sl = 1.0 if int(d[D_DIR]) == POSITIVE else -1.0
    lam, rc = d[g + 11], d[g + 12]
    t1 = 2.0 / 3.0 * d[g + 0] * d[g + 6] * fn1 * d[g + 9] * sl  # Eq. 15: T1, T2, T3 summed (Eq. 17)
    den = 3.0 * rc - 2.0 * lam * d[g + 2] * d[g + 8]
    return t1 + 2.0 * lam * d[g + 1] * d[g + 7] * d[g + 10] / den * t1 + 2.0 * lam * d[g + 2] * d[g + 8] / den * t1


@numba.njit(cache=True)
def model(t, y, dy, gsw, d):
    """The model in the unscaled state ``y`` and the modes held in ``d``: ``dy`` (7) and the six switching
    functions ``gsw`` (inactive ones +1); returns ``(magnet force, coupling torque, T_lock of Eq. 29, F_n1)``."""
    arm = int(d[D_ARM])
    cpl = int(d[D_CPL])
    wf, wr, theta, xa, xd, i1, i2 = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
    fm = magnet_force(d, i2, xa)
    m0, kspr, fk0, cspr, sigma = d[D_M0], d[D_KSPR], d[D_FK0], d[D_CSPR], d[D_SIGMA]
    fn1 = 0.0
    if arm == ARM_FREE:
        dy[3] = xd
        dy[4] = (fm - fk0 - kspr * xa - cspr * xd) / m0  # Eq. 9
    else:
        dy[3] = 0.0
        dy[4] = 0.0
        if arm == ARM_CONTACT:
            fn1 = max(fm - fk0 - kspr * sigma, 0.0)  # Eq. 11
    dy[5] = (d[D_ICMD] - i1) / d[D_TAU1]  # Fig. 15
    dy[6] = (i1 - i2) / d[D_TAU2]
    # drum-bench loads (Eq. 27)
    ic, rw = d[D_IC], d[D_RW]
    vf, vr = d[D_VF], d[D_VR]
    wwf = wf / ic
    wwr = wr / ic
    fxf = 2.0 * d[D_CX] * rw / max(abs(vf), d[D_VFLOOR]) * (wwf * rw - vf)
    fxr = 2.0 * d[D_CX] * rw / max(abs(vr), d[D_VFLOOR]) * (wwr * rw - vr)
    rrf = d[D_FRR] * d[D_FZF] * rw * math.tanh(wwf / 0.5) + d[D_DLF]
    rrr = d[D_FRR] * d[D_FZR] * rw * math.tanh(wwr / 0.5) + d[D_DLR]
    we = abs(wwf) * d[D_I0] * d[D_IG]
    te = _throttle(d, t) * min(d[D_TMAX], d[D_PWR] / max(we, 1.0))
    a_f = (te * d[D_IG] * d[D_I0] - fxf * rw - rrf) / ic
    a_r = (fxr * rw + rrr) / ic
    jf, jr = d[D_JF], d[D_JR]
    tlock = (jr * a_f + jf * a_r) / (jf + jr)  # Eq. 29
    dw = wf - wr
    if cpl == OPEN:
        tc = d[D_NPAIRS] * math.pi * dw * d[D_VISC] / (2.0 * d[D_CLEAR]) * (d[D_RO]**4 - d[D_RI]**4)  # Eq. 25
        dy[2] = 0.0
    elif cpl == SLIPPING:
        tc = _slip_torque(d, fn1)  # Eqs. 13-15, 17
        dy[2] = 0.0
    else:
        tc = tlock + d[D_KS] * theta + d[D_DS] * dw  # Eq. 30
        dy[2] = dw
    dy[0] = (a_f - tc) / jf
    dy[1] = (tc - a_r) / jr
    for k in range(6):
        gsw[k] = 1.0
    if arm == ARM_FREE:
        gsw[0] = xa
        gsw[1] = sigma - xa
    elif arm == ARM_REST:
        gsw[2] = fk0 - fm
    else:
        gsw[3] = fm - fk0 - kspr * sigma
    if cpl == SLIPPING:
        gsw[4] = (1.0 if int(d[D_DIR]) == POSITIVE else -1.0) * dw
    elif cpl == LOCKED:
        gsw[5] = d[D_MARGIN] * _locked_capacity(d, fn1) - abs(tc)
    return fm, tc, tlock, fn1


@numba.njit(cache=True)
def scaled_rhs(t, z, dz, d):
    """``dz/dt`` of the scaled state ``z = y / S``."""
    y = np.empty(NX)
    dy = np.empty(NX)
    gsw = np.empty(6)
    for k in range(NX):
        y[k] = z[k] * d[D_SCALE + k]
    model(t, y, dy, gsw, d)
    for k in range(NX):
        dz[k] = dy[k] / d[D_SCALE + k]


@numba.cfunc(lsoda_sig, cache=True)
def rhs(t, u, du, p):
    head = numba.carray(p, (1,))
    d = numba.carray(p, (int(head[0]),))
    z = numba.carray(u, (NX,))
    dz = numba.carray(du, (NX,))
    scaled_rhs(t, z, dz, d)


# ---------------------------------------------------------------- the driver (needs numbalsoda)
@numba.njit(cache=True)
def _commit(d, i2):
    grid = _grid(d)
    v = min(max(i2, grid[0]), grid[grid.shape[0] - 1])
    plen = int(d[D_PLEN])
    if plen + 2 > int(d[D_CAP]):
        return False
    d[D_PLEN] = K.commit(_tables(d), grid, _stack(d), _prefix(d), plen, d[D_PU], v)
    d[D_PU] = v
    return True


@numba.njit(cache=True)
def _switch_g(t, z, d, gsw):
    y = np.empty(NX)
    dy = np.empty(NX)
    for k in range(NX):
        y[k] = z[k] * d[D_SCALE + k]
    model(t, y, dy, gsw, d)


@numba.njit(cache=True)
def _switch(k, t, z, d):
    """Mode change of switching function ``k`` at ``t`` (as clutchlab.emtc.system._switch); ``z`` scaled."""
    arm = int(d[D_ARM])
    cpl = int(d[D_CPL])
    S = d[D_SCALE:D_SCALE + NX]
    if k == 0 and arm == ARM_FREE:
        z[3] = 0.0
        z[4] = 0.0
        d[D_ARM] = ARM_REST
    elif k == 1 and arm == ARM_FREE:
        z[3] = d[D_SIGMA] / S[3]
        z[4] = 0.0
        d[D_ARM] = ARM_CONTACT
        d[D_CPL] = SLIPPING
        d[D_DIR] = POSITIVE if z[0] * S[0] - z[1] * S[1] >= 0.0 else NEGATIVE
    elif k == 2 and arm == ARM_REST:
        d[D_ARM] = ARM_FREE
    elif k == 3 and arm == ARM_CONTACT:
        d[D_ARM] = ARM_FREE
        d[D_CPL] = OPEN
        z[2] = 0.0
    elif k == 4 and cpl == SLIPPING:
        # slip speed zero: lock if the static capacity covers the lock torque of Eq. 29 (Fig. 11)
        y = np.empty(NX)
        dy = np.empty(NX)
        gsw = np.empty(6)
        for q in range(NX):
            y[q] = z[q] * S[q]
        _, _, tlock, fn1 = model(t, y, dy, gsw, d)
        if abs(tlock) <= _locked_capacity(d, fn1):
            jf, jr = d[D_JF], d[D_JR]
            wm = (y[0] * jf + y[1] * jr) / (jf + jr)
            z[0] = wm / S[0]
            z[1] = wm / S[1]
            z[2] = 0.0
            d[D_CPL] = LOCKED
        else:
            d[D_DIR] = NEGATIVE if int(d[D_DIR]) == POSITIVE else POSITIVE
    elif k == 5 and cpl == LOCKED:
        gsw = np.empty(6)
        dy = np.empty(NX)
        y = np.empty(NX)
        for q in range(NX):
            y[q] = z[q] * S[q]
        _, tc, _, _ = model(t, y, dy, gsw, d)
        d[D_CPL] = SLIPPING
        d[D_DIR] = POSITIVE if tc >= 0.0 else NEGATIVE
        z[2] = 0.0


@numba.njit(cache=True)
def _bilinear(xg, yg, z, x, y):
    nx = xg.shape[0]
    ny = yg.shape[0]
    if x <= xg[0]:
        i, s = 0, 0.0
    elif x >= xg[nx - 1]:
        i, s = nx - 2, 1.0
    else:
        i = 0
        while xg[i + 1] < x:
            i += 1
        s = (x - xg[i]) / (xg[i + 1] - xg[i])
    if y <= yg[0]:
        j, r = 0, 0.0
    elif y >= yg[ny - 1]:
        j, r = ny - 2, 1.0
    else:
        j = 0
        while yg[j + 1] < y:
            j += 1
        r = (y - yg[j]) / (yg[j + 1] - yg[j])
    return z[i, j] * (1 - s) * (1 - r) + z[i + 1, j] * s * (1 - r) + z[i, j + 1] * (1 - s) * r + z[i + 1, j + 1] * s * r


@numba.njit(cache=True)
def _controller(t, z, d, ctl_tab, ctl_grid, cstack, cpref, cmem, cidx, cw, map_thr, map_v, map_t):
    """One controller sample (Eq. 31, Eqs. 13/15/11, inverse Preisach model at the engaged airgap); sets the
    current command in ``d``.  ``cmem``: [length, last input] of the controller's memory."""
    thr = _throttle(d, t)
    vx = z[0] * d[D_SCALE] / d[D_IC] * d[D_RW]
    t_ref = _bilinear(map_thr, map_v, map_t, thr, vx)
    if t_ref > 0.0:
        g = D_GEO
        lam, rc = d[g + 11], d[g + 12]
        t1 = 2.0 / 3.0 * d[g + 0] * d[g + 6] * d[g + 9]
        den = 3.0 * rc - 2.0 * lam * d[g + 2] * d[g + 8]
        gain = t1 + 2.0 * lam * d[g + 1] * d[g + 7] * d[g + 10] / den * t1 + 2.0 * lam * d[g + 2] * d[g + 8] / den * t1
        fm_req = t_ref / gain + d[D_FK0] + d[D_KSPR] * d[D_SIGMA]
    else:
        fm_req = 0.0
    clen = int(cmem[0])
    i_new, ok = K.invert_one(ctl_tab, ctl_grid, cstack, cpref, clen, cmem[1], fm_req, cidx, cw, 1e-9)
    cmem[0] = K.commit(ctl_tab, ctl_grid, cstack, cpref, clen, cmem[1], i_new)
    cmem[1] = i_new
    d[D_ICMD] = i_new


@numba.njit(cache=True)
def _first_crossing(ga, gb):
    """Index of the switching function that falls through zero between ``ga`` and ``gb`` (-1: none); the one
    with the earliest linear-interpolated crossing."""
    best = -1
    best_s = 2.0
    for k in range(6):
        if ga[k] > 0.0 and gb[k] <= 0.0:
            s = ga[k] / (ga[k] - gb[k])
            if s < best_s:
                best_s = s
                best = k
    return best


@numba.njit  # not cache=True: numbalsoda's lsoda is a ctypes pointer, which numba cannot cache (compiles in ~5 s)
def run(funcptr, d, z0, ts, n_samples, nsub, rtol, atol, ctl_tab, ctl_grid, ctl_gaps, map_thr, map_v, map_t,
        out, event_tol=1e-12):
    """The whole run: ``n_samples`` controller samples every ``ts`` from t = 0; writes the unscaled states at the
    samples into ``out`` (n_samples, 8: t and the 7 states).  Returns (lsoda calls, events, ok)."""
    cap = cstack_cap = 4096
    cstack = np.zeros(cstack_cap)
    cpref = np.zeros((ctl_tab.shape[0], cap // 2 + 2))
    cmem = np.zeros(2)
    cmem[1] = ctl_grid[0]
    cidx = np.zeros(K.GAP_TABLES, dtype=np.int64)
    cw = np.zeros(K.GAP_TABLES)
    lo_gap = d[D_DOPEN] - d[D_SIGMA]
    K.gap_weights(ctl_gaps, min(max(lo_gap, ctl_gaps[0]), ctl_gaps[ctl_gaps.shape[0] - 1]), cidx, cw)
    S = d[D_SCALE:D_SCALE + NX].copy()
    z = z0.copy()
    ga = np.empty(6)
    gb = np.empty(6)
    gc = np.empty(6)
    n_calls = 0
    n_events = 0
    ok = True
    for k in range(n_samples):
        t = k * ts
        _controller(t, z, d, ctl_tab, ctl_grid, cstack, cpref, cmem, cidx, cw, map_thr, map_v, map_t)
        out[k, 0] = t
        for q in range(NX):
            out[k, 1 + q] = z[q] * S[q]
        if k == n_samples - 1:
            break
        t_end = (k + 1) * ts
        while t < t_end - 1e-12 * ts:
            # the sub-grid from t to the sample end
            m = max(1, int(math.ceil((t_end - t) / ts * nsub - 1e-9)))
            te = np.empty(m + 1)
            for q in range(m + 1):
                te[q] = t + (t_end - t) * q / m
            te[m] = t_end
            usol, good = lsoda(funcptr, z, te, d, rtol, atol)
            n_calls += 1
            if not good:
                return n_calls, n_events, False
            # first sub-interval with a falling crossing
            _switch_g(te[0], usol[0], d, ga)
            hit = -1
            j = 0
            for j in range(1, m + 1):
                _switch_g(te[j], usol[j], d, gb)
                hit = _first_crossing(ga, gb)
                if hit >= 0:
                    break
                ga[:] = gb
            if hit < 0:
                for q in range(1, m + 1):  # commit the memory at the sub-grid points of the call
                    _commit(d, usol[q, 6] * S[6])
                z = usol[m].copy()
                t = t_end
                break
            # refine the crossing of function `hit` in [te[j-1], te[j]] (Illinois), lsoda from te[j-1]
            ta = te[j - 1]
            tb = te[j]
            za = usol[j - 1].copy()
            zb = usol[j].copy()
            fa = ga[hit]
            fb = gb[hit]
            side = 0
            tc = tb
            zc = zb
            pair = np.empty(2)
            while tb - ta > event_tol:
                tc = (ta * fb - tb * fa) / (fb - fa)
                if not (tc > ta and tc < tb):
                    tc = 0.5 * (ta + tb)
                pair[0] = te[j - 1]
                pair[1] = tc
                us, good = lsoda(funcptr, usol[j - 1], pair, d, rtol, atol)
                n_calls += 1
                zc = us[1].copy()
                _switch_g(tc, zc, d, gc)
                fc = gc[hit]
                if fc > 0.0:
                    ta, za, fa = tc, zc, fc
                    if side == -1:
                        fb *= 0.5
                    side = -1
                else:
                    tb, zb, fb = tc, zc, fc
                    if side == 1:
                        fa *= 0.5
                    side = 1
                if fc == 0.0:
                    break
            # the event at tb (the first point at or past the crossing)
            for q in range(1, j):
                _commit(d, usol[q, 6] * S[6])
            z = zb.copy()
            t = tb
            _commit(d, z[6] * S[6])  # the memory sees the state at the event, before the mode change
            _switch(hit, t, z, d)
            n_events += 1
    return n_calls, n_events, ok
