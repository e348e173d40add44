"""The E-clutch dynamics compiled with numba for LSODA (``numbalsoda``): the compiled peer of ``wp_eclutch.py``.

The same equations as ``PythonEClutch`` of ``bench_eclutch_dynamics.py`` (actuator + clutch network, the
massless network nodes solved by Newton inside the right-hand side, the stick-slip state machine on events,
restarts at the input table's corners), written once more as numba functions:

* :func:`rhs` -- a ``numba.cfunc`` with numbalsoda's signature ``(t, u, du, data)``.  Everything it needs is
  in one float64 ``data`` array (:func:`pack`): parameters, network, curve tables, input table, the friction
  modes (written by the driver before each call of LSODA) and the start guess of the massless nodes.  The
  state is scaled by the default absolute tolerances (``w = y / atol0``) so that LSODA's scalar ``atol``
  means the same per-state absolute tolerances as the other solvers (``atol = atol0 * atol_scale``).
* :func:`run` -- an ``numba.njit`` driver: LSODA (ODEPACK, switching to BDF when the problem is stiff) over
  chunks of a sub-grid, the switching functions checked at every sub-grid point, a sign change located by
  the Illinois method with short LSODA calls from the last grid point, the mode switched and LSODA restarted.
  numbalsoda is imported inside :func:`run`'s compilation only (``_driver``), so the right-hand side and
  the packing import without it (``tests/eclutch/test_peer_equations.py`` runs in CI without numbalsoda).

Friction modes (as ``PythonEClutch``): 0 no Coulomb friction, 1 slip forward, -1 slip backward, 2 stuck.
State machine (as clutchlab's ``update``/``restart``): a stuck coordinate breaks away when ``r_s F_c - |F|``
falls through zero (slips in the direction of its force, from rest); a slipping one whose velocity crosses
zero against its direction sticks if ``r_s F_c >= |F|``, else turns round; at every (re)start a stuck one
whose force exceeds the static limit breaks away and one slipping from rest against its force sticks or
turns round.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import types

from clutchlab.eclutch import system as S

#: numbalsoda's ``lsoda_sig`` (defined here too, so the right-hand side compiles without numbalsoda)
LSODA_SIG = types.void(types.double, types.CPointer(types.double), types.CPointer(types.double),
                       types.CPointer(types.double))

# header of the data array: sizes, then the offsets of the sections
(H_NZ, H_NEL, H_M, H_NIN, H_NY, H_PAR, H_MASS, H_FR, H_GA, H_GB, H_D0, H_SCALE, H_KIND, H_UNIL, H_OFF, H_CX,
 H_CF, H_CD, H_TIN, H_VIN, H_MASSIVE, H_SC, H_MODES, H_QALG, H_LEN) = range(25)
N_HEAD = 32
# rows of the friction section (nz each)
FR_ON, FR_C0, FR_MUN, FR_NIDX, FR_MUP, FR_PIDX, FR_RS, FR_C = range(8)
V_EPS = 1e-9  # slip-end switching function s v + V_EPS [m/s] (as PythonEClutch: a restart on v = 0 is no root)


def pack(ec, tin, vin) -> np.ndarray:
    """The ``data`` array of one E-clutch (position control with the input table ``tin, vin``)."""
    s = ec.assembly
    nz = s.nz
    n_el = len(s.element_names)
    massive = [j for j in range(nz) if s.mass[j] > 0.0]
    m = len(massive)
    ny = 2 * m + 5
    atol0 = np.array([s.atol[j] for j in massive] + [s.atol[nz + j] for j in massive]
                     + list(s.atol[2 * nz: 2 * nz + 5]))
    fr = np.concatenate([s.fr_on.astype(float), s.fr_c0, s.fr_mun, s.fr_nidx.astype(float), s.fr_mup,
                         s.fr_pidx.astype(float), s.fr_rs, s.fr_c])
    sections = [
        (H_PAR, np.asarray(s.par, float)), (H_MASS, np.asarray(s.mass, float)), (H_FR, fr),
        (H_GA, np.ascontiguousarray(s.asm["GA"], float).ravel()), (H_GB, np.asarray(s.asm["Gb"], float)),
        (H_D0, np.asarray(s.asm["d0"], float)), (H_SCALE, np.asarray(s.scale, float)),
        (H_KIND, np.asarray(s.kinds, float)), (H_UNIL, np.asarray(s.unilateral, float)),
        (H_OFF, np.asarray(s.offsets, float)), (H_CX, np.asarray(s.cx, float)), (H_CF, np.asarray(s.cf, float)),
        (H_CD, np.asarray(s.cd, float)), (H_TIN, np.asarray(tin, float)), (H_VIN, np.asarray(vin, float)),
        (H_MASSIVE, np.asarray(massive, float)), (H_SC, atol0), (H_MODES, np.zeros(nz)), (H_QALG, np.zeros(nz - 2)),
    ]
    head = np.zeros(N_HEAD)
    head[H_NZ], head[H_NEL], head[H_M], head[H_NIN], head[H_NY] = nz, n_el, m, len(tin), ny
    pos = N_HEAD
    for h, arr in sections:
        head[h] = pos
        pos += arr.size
    head[H_LEN] = pos
    return np.concatenate([head] + [a for _h, a in sections])


def initial(ec, data: np.ndarray):
    """Initial (unscaled) state, friction modes and start guess of the massless nodes (written into ``data``)."""
    s = ec.assembly
    nz = s.nz
    y_full, modes = s.initial_state(ec.rest_position)
    massive = [j for j in range(nz) if s.mass[j] > 0.0]
    y = np.array([y_full[j] for j in massive] + [y_full[nz + j] for j in massive] + list(y_full[2 * nz: 2 * nz + 5]))
    md = np.array([2.0 if modes[j] == S.STUCK else 0.0 for j in range(nz)])
    o = int(data[H_QALG])
    data[o: o + nz - 2] = y_full[2:nz]
    o = int(data[H_MODES])
    data[o: o + nz] = md
    return y, md


# ---------------------------------------------------------------------------------------------
# equations
# ---------------------------------------------------------------------------------------------
@numba.njit(cache=True, nogil=True)
def _curve(d, lo, hi, kind, x):
    """Curve ``lo:hi`` of the tables in ``d`` (linear or cubic Hermite, linear extrapolation): value, slope."""
    xs0 = int(d[H_CX])
    fs0 = int(d[H_CF])
    ds0 = int(d[H_CD])
    n = hi - lo
    if x <= d[xs0 + lo]:
        if kind:
            sl = d[ds0 + lo]
        else:
            sl = (d[fs0 + lo + 1] - d[fs0 + lo]) / (d[xs0 + lo + 1] - d[xs0 + lo])
        return d[fs0 + lo] + sl * (x - d[xs0 + lo]), sl
    last = lo + n - 1
    if x >= d[xs0 + last]:
        if kind:
            sl = d[ds0 + last]
        else:
            sl = (d[fs0 + last] - d[fs0 + last - 1]) / (d[xs0 + last] - d[xs0 + last - 1])
        return d[fs0 + last] + sl * (x - d[xs0 + last]), sl
    a = lo
    b = last
    while b - a > 1:
        mid = (a + b) // 2
        if d[xs0 + mid] <= x:
            a = mid
        else:
            b = mid
    h = d[xs0 + b] - d[xs0 + a]
    if not kind:
        sl = (d[fs0 + b] - d[fs0 + a]) / h
        return d[fs0 + a] + sl * (x - d[xs0 + a]), sl
    t = (x - d[xs0 + a]) / h
    t2 = t * t
    t3 = t2 * t
    fa, fb, da, db = d[fs0 + a], d[fs0 + b], d[ds0 + a], d[ds0 + b]
    val = (2 * t3 - 3 * t2 + 1) * fa + (t3 - 2 * t2 + t) * h * da + (-2 * t3 + 3 * t2) * fb + (t3 - t2) * h * db
    der = ((6 * t2 - 6 * t) / h * fa + (3 * t2 - 4 * t + 1) * da + (-6 * t2 + 6 * t) / h * fb
           + (3 * t2 - 2 * t) * db)
    return val, der


@numba.njit(cache=True, nogil=True)
def _element_forces(d, u, q, f, k):
    nel = int(d[H_NEL])
    nq = int(d[H_NZ]) - 2
    ga = int(d[H_GA])
    for e in range(nel):
        de = d[int(d[H_D0]) + e] + d[int(d[H_GB]) + e] * u
        for j in range(nq):
            de += d[ga + e * nq + j] * q[j]
        lo = int(d[int(d[H_OFF]) + e])
        hi = int(d[int(d[H_OFF]) + e + 1])
        fe, ke = _curve(d, lo, hi, d[int(d[H_KIND]) + e] != 0.0, de)
        sc = d[int(d[H_SCALE]) + e]
        fe *= sc
        ke *= sc
        if d[int(d[H_UNIL]) + e] != 0.0 and fe <= 0.0:
            fe = 0.0
            ke = 0.0
        f[e] = fe
        k[e] = ke


@numba.njit(cache=True, nogil=True)
def solve_nodes(d, u, q, f, k):
    """Newton (one coordinate at a time) on the massless nodes' force balance ``0 = -(GA^T f)_j``, in place."""
    nz = int(d[H_NZ])
    nel = int(d[H_NEL])
    nq = nz - 2
    ga = int(d[H_GA])
    mass = int(d[H_MASS])
    for _it in range(50):
        _element_forces(d, u, q, f, k)
        worst = 0.0
        for j in range(2, nz):
            if d[mass + j] != 0.0:
                continue
            jj = j - 2
            r = 0.0
            dr = 0.0
            for e in range(nel):
                g = d[ga + e * nq + jj]
                r -= g * f[e]
                dr -= g * g * k[e]
            if dr == 0.0:
                dr = -1.0
            q[jj] -= r / dr
            worst = max(worst, abs(r))
        if worst < 1e-9:
            break
    _element_forces(d, u, q, f, k)


@numba.njit(cache=True, nogil=True)
def _reference(d, t):
    n = int(d[H_NIN])
    ti = int(d[H_TIN])
    vi = int(d[H_VIN])
    if n == 0:
        return 0.0
    if t <= d[ti]:
        return d[vi]
    for k in range(n - 1):
        if t <= d[ti + k + 1]:
            return d[vi + k] + (d[vi + k + 1] - d[vi + k]) * (t - d[ti + k]) / (d[ti + k + 1] - d[ti + k])
    return d[vi + n - 1]


@numba.njit(cache=True, nogil=True)
def forces(d, t, y, z, v, Fz, fn, rates):
    """Unscaled state ``y`` -> coordinates ``z`` (massless nodes solved), velocities ``v``, generalised forces
    ``Fz`` (without friction), friction levels ``fn`` and the actuator's rates ``rates`` (dp_m, dQ, dp_s, di,
    dV_I).  The massless nodes start from the guess in ``data`` and leave their solution there."""
    nz = int(d[H_NZ])
    nel = int(d[H_NEL])
    m = int(d[H_M])
    nq = nz - 2
    par = int(d[H_PAR])
    mi = int(d[H_MASSIVE])
    qa = int(d[H_QALG])
    ga = int(d[H_GA])
    gb = int(d[H_GB])
    fr = int(d[H_FR])
    for j in range(nz):
        z[j] = 0.0
        v[j] = 0.0
        Fz[j] = 0.0
    for i in range(m):
        j = int(d[mi + i])
        z[j] = y[i]
        v[j] = y[m + i]
    q = np.empty(nq)
    mass = int(d[H_MASS])
    for jj in range(nq):
        q[jj] = d[qa + jj] if d[mass + 2 + jj] == 0.0 else z[2 + jj]
    f = np.empty(nel)
    k = np.empty(nel)
    u = z[1]
    solve_nodes(d, u, q, f, k)
    for jj in range(nq):
        if d[mass + 2 + jj] == 0.0:
            z[2 + jj] = q[jj]
            d[qa + jj] = q[jj]
    fb = 0.0
    for e in range(nel):
        fb += d[gb + e] * f[e]
        for jj in range(nq):
            Fz[2 + jj] -= d[ga + e * nq + jj] * f[e]
    Fz[1] -= fb
    p_m = y[2 * m]
    Q = y[2 * m + 1]
    p_s = y[2 * m + 2]
    cur = y[2 * m + 3]
    e_int = y[2 * m + 4]
    P = d[par: par + S.N_PAR]
    v_u = v[1]
    r = min(max(_reference(d, t), P[S.P_REFMIN]), P[S.P_REFMAX])
    v_pid = P[S.P_KP] * (r - u) + e_int - P[S.P_KD] * v_u
    v_drive = min(max(v_pid, -P[S.P_VSUP]), P[S.P_VSUP])
    exc = abs(cur) - P[S.P_IMAX]
    if exc > 0.0:
        v_drive -= P[S.P_KIL] * exc * (1.0 if cur > 0 else -1.0)
        v_drive = min(max(v_drive, -P[S.P_VSUP]), P[S.P_VSUP])
    x_mc = z[0]
    v_mc = v[0]
    rates[3] = (v_drive - P[S.P_R] * cur - P[S.P_KT] * v_mc / P[S.P_NS]) / P[S.P_L]
    rates[4] = P[S.P_KI] * ((r - u) + P[S.P_KAW] * (v_drive - v_pid))
    Fz[0] += P[S.P_KT] * cur / P[S.P_NS] - p_m * P[S.P_AMC]
    opening = min(max((P[S.P_XSN] - x_mc) / P[S.P_WSN], 0.0), 1.0)
    q_vent = P[S.P_GV] * opening * p_m
    cm = P[S.P_CM] * (P[S.P_CAVF] if p_m < P[S.P_PCAV] else 1.0)
    cs = P[S.P_CS] * (P[S.P_CAVF] if p_s < P[S.P_PCAV] else 1.0)
    rates[0] = (P[S.P_AMC] * v_mc - Q - q_vent) / cm
    rates[1] = (p_m - p_s - P[S.P_RH] * Q) / P[S.P_LH]
    rates[2] = (Q - P[S.P_ASL] * v_u) / cs
    Fz[1] += p_s * P[S.P_ASL] + P[S.P_FPRE] - P[S.P_KPRE] * u
    ks = P[S.P_KSTOP]
    cst = P[S.P_CSTOP]
    for j in range(2):
        lo = 0.0 if j == 0 else P[S.P_UMIN]
        hi = P[S.P_XMAX] if j == 0 else P[S.P_UMAX]
        dl = lo - z[j]
        if dl > 0.0:
            Fz[j] += max(ks * dl - cst * dl * v[j], 0.0)
        dh = z[j] - hi
        if dh > 0.0:
            Fz[j] -= max(ks * dh + cst * dh * v[j], 0.0)
    for j in range(nz):
        val = d[fr + FR_C0 * nz + j]
        ni = int(d[fr + FR_NIDX * nz + j])
        if ni >= 0:
            val += d[fr + FR_MUN * nz + j] * abs(f[ni])
        pi = int(d[fr + FR_PIDX * nz + j])
        if pi == 1:
            val += d[fr + FR_MUP * nz + j] * abs(p_m)
        elif pi == 2:
            val += d[fr + FR_MUP * nz + j] * abs(p_s)
        fn[j] = val


@numba.njit(cache=True, nogil=True)
def derivatives(d, t, y, dy):
    """Unscaled right-hand side ``dy = f(t, y)`` with the friction modes in ``data``."""
    nz = int(d[H_NZ])
    m = int(d[H_M])
    mi = int(d[H_MASSIVE])
    md = int(d[H_MODES])
    fr = int(d[H_FR])
    mass = int(d[H_MASS])
    z = np.empty(nz)
    v = np.empty(nz)
    Fz = np.empty(nz)
    fn = np.empty(nz)
    rates = np.empty(5)
    forces(d, t, y, z, v, Fz, fn, rates)
    for i in range(m):
        j = int(d[mi + i])
        on = d[fr + FR_ON * nz + j] != 0.0
        mode = d[md + j]
        if on and mode == 2.0:
            dy[i] = 0.0
            dy[m + i] = 0.0
            continue
        frc = -d[fr + FR_C * nz + j] * v[j]
        if on:
            frc -= (1.0 if mode > 0 else -1.0) * fn[j]
        dy[i] = v[j]
        dy[m + i] = (Fz[j] + frc) / d[mass + j]
    for k in range(5):
        dy[2 * m + k] = rates[k]


@numba.njit(cache=True, nogil=True)
def switching(d, t, y, g):
    """Switching function of every friction coordinate (``nz`` entries; 1 where friction is off): stuck:
    ``r_s F_c - |F|``; slipping with sign s: ``s v`` (the event is its crossing below zero)."""
    nz = int(d[H_NZ])
    md = int(d[H_MODES])
    fr = int(d[H_FR])
    z = np.empty(nz)
    v = np.empty(nz)
    Fz = np.empty(nz)
    fn = np.empty(nz)
    rates = np.empty(5)
    forces(d, t, y, z, v, Fz, fn, rates)
    for j in range(nz):
        mode = d[md + j]
        if d[fr + FR_ON * nz + j] == 0.0:
            g[j] = 1.0
        elif mode == 2.0:
            g[j] = d[fr + FR_RS * nz + j] * fn[j] - abs(Fz[j])
        else:
            g[j] = (1.0 if mode > 0 else -1.0) * v[j] + V_EPS
    return Fz, fn


@numba.cfunc(LSODA_SIG, cache=True)
def rhs(t, w, dw, p):
    """numbalsoda's right-hand side on the scaled state ``w = y / atol0``."""
    head = numba.carray(p, (N_HEAD,))
    d = numba.carray(p, (int(head[H_LEN]),))
    ny = int(d[H_NY])
    sc = int(d[H_SC])
    y = np.empty(ny)
    for i in range(ny):
        y[i] = w[i] * d[sc + i]
    dy = np.empty(ny)
    derivatives(d, t, y, dy)
    for i in range(ny):
        dw[i] = dy[i] / d[sc + i]


def bearing_force(ec, y):
    """F_b = p_s A_sl from (unscaled) states, rows = time."""
    m = (y.shape[-1] - 5) // 2
    return y[..., 2 * m + 2] * ec.actuator.slave_area


@numba.njit(cache=True)
def _restart_modes(d, t, y):
    """Make the modes consistent at a (re)start (the kernel's restart); True if one changed."""
    nz = int(d[H_NZ])
    m = int(d[H_M])
    mi = int(d[H_MASSIVE])
    md = int(d[H_MODES])
    fr = int(d[H_FR])
    g = np.empty(nz)
    Fz, fn = switching(d, t, y, g)
    changed = False
    for i in range(m):
        j = int(d[mi + i])
        if d[fr + FR_ON * nz + j] == 0.0:
            continue
        rs = d[fr + FR_RS * nz + j]
        mode = d[md + j]
        if mode == 2.0:
            if abs(Fz[j]) > rs * fn[j]:
                d[md + j] = 1.0 if Fz[j] > 0 else -1.0
                y[m + i] = 0.0
                changed = True
        elif y[m + i] == 0.0:
            sg = 1.0 if mode > 0 else -1.0
            if (Fz[j] - sg * fn[j]) * sg < 0.0:
                d[md + j] = 2.0 if abs(Fz[j]) <= rs * fn[j] else (1.0 if Fz[j] > 0 else -1.0)
                changed = True
    return changed

@numba.njit(cache=True)
def _event(d, t, y, j, i):
    """Switching function ``j`` (massive index ``i``) crossed: switch its mode (the kernel's update)."""
    nz = int(d[H_NZ])
    m = int(d[H_M])
    md = int(d[H_MODES])
    fr = int(d[H_FR])
    g = np.empty(nz)
    Fz, fn = switching(d, t, y, g)
    y[m + i] = 0.0
    if d[md + j] == 2.0:
        d[md + j] = 1.0 if Fz[j] > 0 else -1.0  # break-away
    elif d[fr + FR_RS * nz + j] * fn[j] - abs(Fz[j]) >= 0.0:
        d[md + j] = 2.0  # stick
    else:
        d[md + j] = 1.0 if Fz[j] > 0 else -1.0  # turn round


# ---------------------------------------------------------------------------------------------
# driver (numbalsoda imported here only)
# ---------------------------------------------------------------------------------------------
_DRIVER = {}


def import_lsoda():
    """``numbalsoda.lsoda`` (the ``bench`` extra)."""
    from numbalsoda import lsoda

    return lsoda


def _driver():
    if "run" in _DRIVER:
        return _DRIVER["run"]
    lsoda = import_lsoda()

    # not cached: these call numbalsoda's ctypes entry (numba cannot cache that), and the closure holds it
    @numba.njit
    def _step(funcptr, d, t0, w0, t1, rtol, atol):
        te = np.array([t0, t1])
        out, ok = lsoda(funcptr, w0.copy(), te, data=d, rtol=rtol, atol=atol, mxstep=500000)
        return out[1].copy(), ok

    @numba.njit
    def run(funcptr, d, y0, t_end, grid, chunk, rtol, atol, t_tol):
        """Integrate from ``y0`` (unscaled) to ``t_end``; the switching functions are checked on ``grid`` (sorted,
        containing the table's corners and ``t_end``), LSODA restarted every ``chunk`` grid intervals, at the
        corners and at events.  Returns (times, unscaled states, event log (time, coordinate, new mode), ok)."""
        nz = int(d[H_NZ])
        m = int(d[H_M])
        ny = int(d[H_NY])
        mi = int(d[H_MASSIVE])
        sc = int(d[H_SC])
        nin = int(d[H_NIN])
        ti = int(d[H_TIN])
        cap = grid.shape[0] + 4096
        T = np.empty(cap)
        Y = np.empty((cap, ny))
        nout = 0
        w = np.empty(ny)
        y = y0.copy()
        t = grid[0]
        T[0] = t
        Y[0] = y
        nout = 1
        n_ev = 0
        gi = 0  # index of the last grid point <= t
        ga = np.empty(nz)
        gb = np.empty(nz)
        EV = np.empty((4096, 3))  # event log: time, coordinate, new mode
        ok_all = True
        while t < t_end and nout < cap - 2:
            _restart_modes(d, t, y)
            # the next corner of the input table (or the end)
            t_stop = t_end
            for k in range(nin):
                if d[ti + k] > t + 1e-14 and d[ti + k] < t_stop:
                    t_stop = d[ti + k]
            # grid points of this chunk: (t, ...] up to chunk intervals, not beyond t_stop
            j1 = gi + 1
            while j1 < grid.shape[0] and grid[j1] <= t:
                j1 += 1
            j2 = min(j1 + chunk, grid.shape[0])
            while j2 > j1 and grid[j2 - 1] > t_stop + 1e-14:
                j2 -= 1
            te = np.empty(j2 - j1 + 1)
            te[0] = t
            te[1:] = grid[j1:j2]
            for i in range(ny):
                w[i] = y[i] / d[sc + i]
            out, ok = lsoda(funcptr, w.copy(), te, data=d, rtol=rtol, atol=atol, mxstep=500000)
            if not ok:
                ok_all = False
                break
            switching(d, t, y, ga)
            # first grid point where a switching function crossed
            hit = -1
            yb = np.empty(ny)
            for r in range(1, te.shape[0]):
                for i in range(ny):
                    yb[i] = out[r, i] * d[sc + i]
                switching(d, te[r], yb, gb)
                for jj in range(m):
                    j = int(d[mi + jj])
                    if ga[j] >= 0.0 and gb[j] < 0.0:
                        hit = r
                if hit >= 0:
                    break
                T[nout] = te[r]
                Y[nout] = yb
                nout += 1
                for j in range(nz):
                    ga[j] = gb[j]
                t = te[r]
                y = yb.copy()
                gi = j1 + r - 1
            if hit < 0:
                continue
            # locate: the crossing in (t, te[hit]]: Illinois on the earliest crossing function
            ta = t
            tb = te[hit]
            wa = np.empty(ny)
            for i in range(ny):
                wa[i] = y[i] / d[sc + i]
            # which function: the earliest linear estimate
            jev = -1
            best = 1e300
            for jj in range(m):
                j = int(d[mi + jj])
                if ga[j] >= 0.0 and gb[j] < 0.0:
                    est = ta + (tb - ta) * ga[j] / (ga[j] - gb[j])
                    if est < best:
                        best = est
                        jev = j
            fa = ga[jev]
            fb = gb[jev]
            side = 0
            wb = out[hit].copy()
            gm = np.empty(nz)
            for _it in range(60):
                if tb - ta <= t_tol:
                    break
                tm = ta + (tb - ta) * fa / (fa - fb)
                tm = min(max(tm, ta + 0.01 * (tb - ta)), tb - 0.01 * (tb - ta))
                wm, ok = _step(funcptr, d, ta, wa, tm, rtol, atol)
                for i in range(ny):
                    yb[i] = wm[i] * d[sc + i]
                switching(d, tm, yb, gm)
                if gm[jev] < 0.0:
                    tb = tm
                    fb = gm[jev]
                    wb = wm
                    if side == -1:
                        fa *= 0.5
                    side = -1
                else:
                    ta = tm
                    fa = gm[jev]
                    wa = wm
                    if side == 1:
                        fb *= 0.5
                    side = 1
            # stop just after the crossing (tb), switch every function that crossed there
            t = tb
            for i in range(ny):
                y[i] = wb[i] * d[sc + i]
            switching(d, t, y, gb)
            for jj in range(m):
                j = int(d[mi + jj])
                if ga[j] >= 0.0 and gb[j] < 0.0:
                    _event(d, t, y, j, jj)
                    if n_ev < EV.shape[0]:
                        EV[n_ev, 0] = t
                        EV[n_ev, 1] = j
                        EV[n_ev, 2] = d[int(d[H_MODES]) + j]
                    n_ev += 1
            T[nout] = t
            Y[nout] = y
            nout += 1
        return T[:nout].copy(), Y[:nout].copy(), EV[:min(n_ev, EV.shape[0])].copy(), ok_all

    _DRIVER["run"] = run
    return run


def make_grid(t_end, dt, tin):
    """Sub-grid of the switching functions: step ``dt``, the table's corners and ``t_end`` added."""
    g = np.linspace(0.0, t_end, int(round(t_end / dt)) + 1)
    extra = [t for t in tin if 0.0 < t < t_end]
    return np.unique(np.concatenate([g, extra]))


def simulate(ec, tin, vin, t_end, rtol, atol_scale=1.0, dt=1e-4, chunk=5, t_tol=1e-9, data=None, log=None):
    """One peer run: (times, bearing force F_b [N], events, ok).  ``data`` from :func:`pack` (packed here if
    None); the state is scaled by the default absolute tolerances, LSODA's scalar atol is ``atol_scale``.
    ``log``: a list that gets the events (rows: time [s], coordinate, new mode).

    ``dt`` and ``chunk``: the switching functions are checked every ``dt`` (0.1 ms) and LSODA is restarted every
    ``chunk`` sub-grid intervals (0.5 ms).  Longer chunks are slower and worse: after an event the rest of the
    chunk is thrown away, and LSODA's large steps interpolated at the grid points put noise of the order of the
    velocity atol (0.1 mm/s) on slowly creeping coordinates, which the slip-end test reads as spurious
    crossings (1e-6: 74 events with chunks of 5, 1,987 with 10, 0.28 s against 1.1 s)."""
    if data is None:
        data = pack(ec, tin, vin)
    y0, _md = initial(ec, data)
    run = _driver()
    T, Y, EV, ok = run(rhs.address, data, y0, float(t_end), make_grid(t_end, dt, tin), int(chunk), float(rtol),
                         float(atol_scale), float(t_tol))
    if log is not None:
        log.append(EV)
    return T, bearing_force(ec, Y), len(EV), ok
