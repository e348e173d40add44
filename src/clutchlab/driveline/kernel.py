"""Compiled hooks of a one-dimensional driveline network (the system contract of :mod:`clutchlab.system`).

The network: rigid inertias (states: angle and speed), ground, spring-dampers, torque sources and
friction elements between two flanges (or a flange and ground) with the friction state machine of the
Modelica Standard Library (``Modelica.Mechanics.Rotational.Interfaces.PartialFriction``, MSL 4.x):

* a **stuck** element holds zero relative *acceleration* (the relative speed stays a state and is not
  reset, as in MSL) with the torque the network needs; it breaks away, forward or backward, when that
  torque exceeds its static limit ``peak * tau0``;
* a **sliding** element (forward: relative speed > 0, backward: < 0) carries its sliding
  characteristic; when its relative speed reaches zero it sticks, or reverses at once if the torque
  needed to hold it exceeds the static limit;
* a **free** element (normal force <= 0) carries nothing; when the force returns it slides in the
  direction of its relative speed (sticks if that is exactly zero).

Several elements may be stuck at once: their torques are solved together from one small linear system
(:func:`_solve_stuck`); after any mode change the modes are settled to a fixed point (:func:`settle`).
Where stuck elements constrain the same relative motion (two clutches in parallel), the system is
singular; the torque is then split in proportion to the static limits (the solution minimising
``sum(tau_k^2 / limit_k)``, from a regularisation of relative size 1e-12), so a parallel group breaks
away together when the total reaches the sum of its limits.

Conventions: the relative speed of an element is ``w_rel = w_b - w_a`` (flange b minus flange a, ground
has speed 0); its torque ``tau`` acts as ``-tau`` on flange b and ``+tau`` on flange a, so a positive
``tau`` opposes a positive ``w_rel`` (MSL's ``flange_b.tau = tau``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from ..numerics import dispatch
from ..numerics.core import record
from ..numerics.interp import bracket
from ..numerics.rosenbrock import lu_factor, lu_solve

# element kinds (DrivelineParams.elem[:, E_KIND])
K_SPRING, K_FRICTION, K_SOURCE = 0, 1, 2
# friction laws
LAW_CLUTCH, LAW_TABLE = 0, 1          # torque = cgeo * fn * mu(|w|);  torque = table(|w|) (bearing friction)
# modes of a friction element (index into MODE_VALUES); MSL's codes are MODE_CODES
STUCK, FORWARD, BACKWARD, FREE = 0, 1, 2, 3
MODE_VALUES = ("stuck", "forward", "backward", "free")
MODE_CODES = np.array([0.0, 1.0, -1.0, 2.0])  # MSL PartialFriction: Stuck 0, Forward 1, Backward -1, Free 2
# events: named for the mode entered
EV_STICK, EV_FORWARD, EV_BACKWARD, EV_FREE = 0, 1, 2, 3
EVENTS = ("stick", "forward", "backward", "free")
_EVENT_OF_MODE = np.array([EV_STICK, EV_FORWARD, EV_BACKWARD, EV_FREE])
# signals
SIG_CONST, SIG_STEP, SIG_RAMP, SIG_SINE, SIG_TABLE = 0, 1, 2, 3, 4
# columns of ``elem`` (ints) and ``coef`` (floats)
E_KIND, E_A, E_B, E_LAW, E_SIGNAL, E_TABLE, E_TABLE_N, E_INDEX = range(8)
C_STIFF, C_DAMP, C_PHI0 = 0, 1, 2                  # spring-damper
C_FN_MAX, C_CGEO, C_PEAK = 0, 1, 2                 # friction (table: speed grid | values at E_TABLE)
# switching functions per friction element
G_STICK, G_BREAK, G_NORMAL = 0, 1, 2
N_G = 3


class DrivelineParams(NamedTuple):
    """Packed parameters of a driveline network (SI: kg m^2, N m/rad, N m s/rad, N, rad/s).

    Built by :func:`clutchlab.driveline.network.pack`.  ``inertia``: the inertias [kg m^2];
    ``elem`` (int64, one row per element, columns ``E_*``) and ``coef`` (float, ``C_*``): the
    elements; ``signals`` (one row per signal: kind, then up to 6 parameters) and ``data`` (tables:
    friction characteristics and signal tables); ``fric`` (int64): the element row of each friction
    element; ``work`` and ``iwork`` (int64, the pivots of the stuck set's factorisation): scratch of
    the hooks (per run).
    """

    inertia: np.ndarray
    elem: np.ndarray
    coef: np.ndarray
    signals: np.ndarray
    data: np.ndarray
    fric: np.ndarray
    work: np.ndarray
    iwork: np.ndarray


# ----------------------------------------------------------------- signals
@numba.njit(cache=True, nogil=True, inline="always")
def _table(data, start, n, t):
    """Piecewise-linear table ``data[start:start+n]`` (times), ``data[start+n:start+2n]`` (values), held outside."""
    if n == 1:
        return data[start + 1]
    lo, w = bracket(data[start:start + n], t)
    return data[start + n + lo] + w * (data[start + n + lo + 1] - data[start + n + lo])


@numba.njit(cache=True, nogil=True)
def signal_value(sig, data, t):
    """Value of one signal row at ``t`` (MSL ``Modelica.Blocks.Sources``: Constant, Step, Ramp, Sine, table).

    Rows: ``[kind, p0 .. p5]``; constant ``[k, value]``; step ``[k, height, start, offset]``; ramp
    ``[k, height, duration, start, offset]``; sine ``[k, amplitude, frequency, phase, offset, start]``
    (zero plus offset before the start, as MSL's ``Sine``); table ``[k, start index, n]`` in ``data``.
    """
    kind = int(sig[0])
    if kind == SIG_CONST:
        return sig[1]
    if kind == SIG_STEP:
        return sig[3] + (sig[1] if t >= sig[2] else 0.0)
    if kind == SIG_RAMP:
        if t < sig[3]:
            return sig[4]
        if t >= sig[3] + sig[2]:
            return sig[4] + sig[1]
        return sig[4] + sig[1] * (t - sig[3]) / sig[2]
    if kind == SIG_SINE:
        if t < sig[5]:
            return sig[4]
        return sig[4] + sig[1] * math.sin(2.0 * math.pi * sig[2] * (t - sig[5]) + sig[3])
    return _table(data, int(sig[1]), int(sig[2]), t)


@numba.njit(cache=True, nogil=True)
def signal_break(sig, data, t):
    """Next time after ``t`` at which the signal has a jump or a kink (inf if none)."""
    kind = int(sig[0])
    if kind == SIG_STEP:
        return sig[2] if sig[2] > t else np.inf
    if kind == SIG_RAMP:
        if sig[3] > t:
            return sig[3]
        return sig[3] + sig[2] if sig[3] + sig[2] > t else np.inf
    if kind == SIG_SINE:
        return sig[5] if sig[5] > t else np.inf
    if kind == SIG_TABLE:
        s = int(sig[1])
        for i in range(s, s + int(sig[2])):
            if data[i] > t:
                return data[i]
    return np.inf


# ----------------------------------------------------------------- friction characteristic
@numba.njit(cache=True, nogil=True, inline="always")
def _characteristic(data, start, n, w):
    """Table value at ``w >= 0``: linear between points, extrapolated from the last two (MSL's ``LastTwoPoints``)."""
    if n == 1 or w <= data[start]:
        return data[start + n]
    if w >= data[start + n - 1]:
        x0, x1 = data[start + n - 2], data[start + n - 1]
        y0, y1 = data[start + 2 * n - 2], data[start + 2 * n - 1]
        return y1 + (y1 - y0) * (w - x1) / (x1 - x0)
    return _table(data, start, n, w)


@numba.njit(cache=True, nogil=True)
def friction_torque(p, r, t, w_abs):
    """Sliding torque magnitude [N m] of friction element row ``r`` at relative speed ``|w|`` and time ``t``.

    Clutch and brake (MSL ``Clutch``/``Brake``): ``cgeo * fn * mu(|w|)`` with ``fn = fn_max * f(t)``;
    bearing friction (``BearingFriction``): the table itself.  At ``w = 0`` this is ``tau0``; the static
    limit is ``peak * tau0``.
    """
    e = p.elem[r]
    c = p.coef[r]
    val = _characteristic(p.data, e[E_TABLE], e[E_TABLE_N], w_abs)
    if e[E_LAW] == LAW_TABLE:
        return val
    return c[C_CGEO] * normal_force(p, r, t) * val


@numba.njit(cache=True, nogil=True)
def normal_force(p, r, t):
    """Normal force [N] of friction element row ``r``: ``fn_max * f(t)`` (``fn_max`` alone without a signal)."""
    e = p.elem[r]
    f = 1.0 if e[E_SIGNAL] < 0 else signal_value(p.signals[e[E_SIGNAL]], p.data, t)
    return p.coef[r][C_FN_MAX] * f


@numba.njit(cache=True, nogil=True)
def _is_free(p, r, t):
    e = p.elem[r]
    if e[E_LAW] == LAW_TABLE:
        return False
    return normal_force(p, r, t) <= 0.0


# ----------------------------------------------------------------- network evaluation
@numba.njit(cache=True, nogil=True)
def _speed(x, n, i):
    return 0.0 if i < 0 else x[n + i]


@numba.njit(cache=True, nogil=True)
def evaluate_network(t, x, m, p, acc, tau):
    """Accelerations ``acc`` [rad/s^2] of the inertias and the torque ``tau`` [N m] of every element.

    Spring-dampers ``tau = c (phi_b - phi_a - phi0) + d (w_b - w_a)``; sources: their signal (acting on
    flange b, positive accelerating it, so ``tau`` is stored with the element convention as minus the
    source torque); sliding friction ``+-friction_torque``; free friction 0; stuck friction the
    solution of the stuck set.  Returns the number of stuck elements.
    """
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    wk = p.work
    F = wk[0:n]
    for i in range(n):
        F[i] = 0.0
    for r in range(ne):
        e = p.elem[r]
        kind = e[E_KIND]
        a = e[E_A]
        b = e[E_B]
        if kind == K_SPRING:
            c = p.coef[r]
            pa = 0.0 if a < 0 else x[a]
            pb = 0.0 if b < 0 else x[b]
            tq = c[C_STIFF] * (pb - pa - c[C_PHI0]) + c[C_DAMP] * (_speed(x, n, b) - _speed(x, n, a))
        elif kind == K_SOURCE:
            tq = -signal_value(p.signals[e[E_SIGNAL]], p.data, t)
        else:
            continue
        tau[r] = tq
        if b >= 0:
            F[b] -= tq
        if a >= 0:
            F[a] += tq
    # sliding and free friction; the stuck set
    ns = 0
    stuck = wk[n:n + nf]  # element rows of the stuck set (as floats)
    for k in range(nf):
        r = p.fric[k]
        e = p.elem[r]
        mk = m[k]
        if mk == STUCK:
            stuck[ns] = r
            ns += 1
            continue
        if mk == FREE:
            tq = 0.0
        else:
            w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
            tq = friction_torque(p, r, t, abs(w_rel))
            if mk == BACKWARD:
                tq = -tq
        tau[r] = tq
        if e[E_B] >= 0:
            F[e[E_B]] -= tq
        if e[E_A] >= 0:
            F[e[E_A]] += tq
    if ns > 0:
        _solve_stuck(t, p, stuck, ns, F, tau)
    for i in range(n):
        acc[i] = F[i] / p.inertia[i]
    return ns


@numba.njit(cache=True, nogil=True)
def _layout(n, nf, ne):
    """Offsets in ``DrivelineParams.work``: net torques F (n) | stuck set (nf) | A (nf^2) | A + eps D (nf^2)
    | right-hand side (nf) | torques of the stuck set (nf) | static limits (nf) | residual (nf) |
    accelerations (n) | element torques (ne) | initial stored energy (1)."""
    o_a = n + nf
    o_m = o_a + nf * nf
    o_b = o_m + nf * nf
    o_l = o_b + nf
    o_c = o_l + nf
    o_r = o_c + nf
    o_acc = o_r + nf
    o_tau = o_acc + n
    return o_a, o_m, o_b, o_l, o_c, o_r, o_acc, o_tau


def work_size(n, nf, ne):
    """Length of ``DrivelineParams.work`` for ``n`` inertias, ``nf`` friction elements, ``ne`` elements."""
    return 2 * n + 5 * nf + 2 * nf * nf + ne + 1


@numba.njit(cache=True, nogil=True)
def _acc_tau(p):
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    ne = p.elem.shape[0]
    o = _layout(n, nf, ne)
    return p.work[o[6]:o[6] + n], p.work[o[7]:o[7] + ne]


@numba.njit(cache=True, nogil=True)
def _solve_stuck(t, p, stuck, ns, F, tau):
    """Torques of the stuck elements: zero relative acceleration for each, solved together.

    ``A lam = g^T M^-1 F`` with ``A[k, j] = g_k^T M^-1 g_j`` (``g = e_b - e_a``).  Where stuck elements
    lock the same relative motion (two clutches in parallel) ``A`` is singular: the torque is then split
    in proportion to the static limits, the solution minimising ``sum(lam_k^2 / limit_k)``.  It comes
    from ``(A + eps D) lam = b`` with ``D = diag(max limit / limit_k)`` and ``eps`` 1e-8 of ``A``'s
    diagonal (whose solution has ``D lam`` in the range of ``A``: the proportional split), refined twice
    on the residual of ``A lam = b`` (the constraints hold to rounding; the split to about 1e-8).
    ``F`` is updated with the stuck torques.
    """
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    ne = p.elem.shape[0]
    wk = p.work
    o_a, o_m, o_b, o_l, o_c, o_r, _, _ = _layout(n, nf, ne)
    A = wk[o_a:o_a + nf * nf].reshape((nf, nf))
    b = wk[o_b:o_b + nf]
    lam = wk[o_l:o_l + nf]
    cap = wk[o_c:o_c + nf]
    res = wk[o_r:o_r + nf]
    scale = 0.0
    cmax = 0.0
    for k in range(ns):
        rk = int(stuck[k])
        ek = p.elem[rk]
        ak, bk = ek[E_A], ek[E_B]
        s = 0.0
        if bk >= 0:
            s += F[bk] / p.inertia[bk]
        if ak >= 0:
            s -= F[ak] / p.inertia[ak]
        b[k] = s
        lam[k] = 0.0
        for j in range(ns):
            rj = int(stuck[j])
            ej = p.elem[rj]
            aj, bj = ej[E_A], ej[E_B]
            v = 0.0
            if bk >= 0 and bk == bj:
                v += 1.0 / p.inertia[bk]
            if bk >= 0 and bk == aj:
                v -= 1.0 / p.inertia[bk]
            if ak >= 0 and ak == bj:
                v -= 1.0 / p.inertia[ak]
            if ak >= 0 and ak == aj:
                v += 1.0 / p.inertia[ak]
            A[k, j] = v
        scale = max(scale, A[k, k])
        cap[k] = static_limit(p, rk, t)
        cmax = max(cmax, cap[k])
    M = wk[o_m:o_m + ns * ns].reshape((ns, ns))
    for k in range(ns):
        for j in range(ns):
            M[k, j] = A[k, j]
        c = max(cap[k], 1e-6 * cmax, 1e-300)
        M[k, k] += 1e-8 * scale * (cmax / c if cmax > 0.0 else 1.0)
    lu_factor(M, p.iwork)
    for _it in range(3):  # the regularised solution, then two refinements on the residual
        for k in range(ns):
            r = b[k]
            for j in range(ns):
                r -= A[k, j] * lam[j]
            res[k] = r
        lu_solve(M, p.iwork, res)
        for k in range(ns):
            lam[k] += res[k]
    for k in range(ns):
        rk = int(stuck[k])
        ek = p.elem[rk]
        tq = lam[k]
        tau[rk] = tq
        if ek[E_B] >= 0:
            F[ek[E_B]] -= tq
        if ek[E_A] >= 0:
            F[ek[E_A]] += tq


@numba.njit(cache=True, nogil=True)
def static_limit(p, r, t):
    """Static limit ``peak * tau0`` [N m] of friction element row ``r`` at time ``t``."""
    return p.coef[r][C_PEAK] * friction_torque(p, r, t, 0.0)


# ----------------------------------------------------------------- hooks
@numba.njit(cache=True, nogil=True)
def driveline_rhs(t, x, u, m, p, dx, g):
    """Angles and speeds of the inertias, work of the sources, energy dissipated by each element.

    States: ``phi`` (n), ``w`` (n), then one energy per element in element order [J]: a source's work
    ``tau_src * w_b``, a spring-damper's dissipation ``d w_rel^2``, a friction element's
    ``tau * w_rel``.  Switching functions, three per friction element: the relative speed of a
    sliding element in its direction (falls through zero: it sticks or reverses), the static limit
    minus the torque of a stuck one (falls through zero: break-away), the normalised normal force
    (either way: free or engaged).
    """
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    acc, tau = _acc_tau(p)
    evaluate_network(t, x, m, p, acc, tau)
    for i in range(n):
        dx[i] = x[n + i]
        dx[n + i] = acc[i]
    for r in range(ne):
        e = p.elem[r]
        w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
        if e[E_KIND] == K_SPRING:
            d = p.coef[r][C_DAMP]
            dx[2 * n + r] = d * w_rel * w_rel
        elif e[E_KIND] == K_SOURCE:
            dx[2 * n + r] = -tau[r] * w_rel
        else:
            dx[2 * n + r] = tau[r] * w_rel
    for k in range(nf):
        r = p.fric[k]
        e = p.elem[r]
        w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
        mk = m[k]
        g[N_G * k + G_STICK] = w_rel if mk == FORWARD else -w_rel if mk == BACKWARD else 1.0
        g[N_G * k + G_BREAK] = static_limit(p, r, t) - abs(tau[r]) if mk == STUCK else 1.0
        if e[E_LAW] == LAW_TABLE or e[E_SIGNAL] < 0:
            g[N_G * k + G_NORMAL] = 1.0
        else:
            g[N_G * k + G_NORMAL] = signal_value(p.signals[e[E_SIGNAL]], p.data, t)


@numba.njit(cache=True, nogil=True)
def driveline_outputs(t, x, u, m, p, y):
    """Per element: torque [N m] (a source: its torque on flange b), relative speed [rad/s]; per
    friction element also its MSL mode code [-] and normal force [N]; then kinetic and spring
    energy, the sources' work, the dissipated energy and the energy balance error [J]."""
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    acc, tau = _acc_tau(p)
    evaluate_network(t, x, m, p, acc, tau)
    q = 0
    kinetic = 0.0
    for i in range(n):
        kinetic += 0.5 * p.inertia[i] * x[n + i] ** 2
    spring = 0.0
    work = 0.0
    lost = 0.0
    for r in range(ne):
        e = p.elem[r]
        w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
        if e[E_KIND] == K_SOURCE:
            y[q] = -tau[r]
            q += 1
            work += x[2 * n + r]
            continue
        y[q] = tau[r]
        y[q + 1] = w_rel
        q += 2
        if e[E_KIND] == K_SPRING:
            c = p.coef[r]
            pa = 0.0 if e[E_A] < 0 else x[e[E_A]]
            pb = 0.0 if e[E_B] < 0 else x[e[E_B]]
            spring += 0.5 * c[C_STIFF] * (pb - pa - c[C_PHI0]) ** 2
        lost += x[2 * n + r]
    for k in range(nf):
        r = p.fric[k]
        y[q] = MODE_CODES[m[k]]
        y[q + 1] = 0.0 if p.elem[r][E_LAW] == LAW_TABLE else normal_force(p, r, t)
        q += 2
    y[q] = kinetic
    y[q + 1] = spring
    y[q + 2] = work
    y[q + 3] = lost
    y[q + 4] = work - lost - (kinetic + spring - p.work[p.work.shape[0] - 1])


@numba.njit(cache=True, nogil=True)
def settle(t, x, m, p, log, old):
    """Modes consistent with the forces at ``t``: free or engaged by the normal force, then break-away of
    stuck elements (the worst violation first) and re-sticking of an element released against its
    acceleration, to a fixed point.  An event per element whose mode now differs from ``old`` (the modes
    before the event), named for the mode entered.  Returns True if a mode changed."""
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    acc, tau = _acc_tau(p)
    wscale = 1.0
    for i in range(n):
        wscale = max(wscale, abs(x[n + i]))
    w_tol = 1e-9 * wscale
    for k in range(nf):
        r = p.fric[k]
        e = p.elem[r]
        if _is_free(p, r, t):
            m[k] = FREE
        elif m[k] == FREE:
            w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
            m[k] = FORWARD if w_rel > 0.0 else BACKWARD if w_rel < 0.0 else STUCK
    for _it in range(4 * nf + 4):
        evaluate_network(t, x, m, p, acc, tau)
        worst = -1
        ratio = 0.0
        for k in range(nf):
            if m[k] != STUCK:
                continue
            r = p.fric[k]
            lim = static_limit(p, r, t)
            # the same test as the break-away function, which has crossed when it reaches zero (the core's
            # convention): |tau| >= limit, a torque to carry (a ratio may round to exactly 1)
            if abs(tau[r]) >= lim and abs(tau[r]) > 0.0:
                q = abs(tau[r]) / lim if lim > 0.0 else np.inf
                if q >= ratio:
                    ratio = q
                    worst = k
        if worst >= 0:
            m[worst] = FORWARD if tau[p.fric[worst]] > 0.0 else BACKWARD
            continue
        # an element released (relative speed still ~0) must move the way it slides
        changed = False
        for k in range(nf):
            if m[k] != FORWARD and m[k] != BACKWARD:
                continue
            r = p.fric[k]
            e = p.elem[r]
            w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
            if abs(w_rel) > w_tol:
                continue
            a_rel = (0.0 if e[E_B] < 0 else acc[e[E_B]]) - (0.0 if e[E_A] < 0 else acc[e[E_A]])
            if (m[k] == FORWARD and a_rel < 0.0) or (m[k] == BACKWARD and a_rel > 0.0):
                m[k] = STUCK
                changed = True
                break
        if not changed:
            break
    any_change = False
    for k in range(nf):
        if m[k] != old[k]:
            record(log, t, _EVENT_OF_MODE[m[k]], k)
            any_change = True
    return any_change


@numba.njit(cache=True, nogil=True)
def driveline_update(t, x, u, m, p, k, log):
    """Switching function ``k`` crossed: a sliding element reached zero relative speed (it sticks, or
    reverses if it cannot hold), a stuck one reached its static limit, or a normal force changed sign."""
    old = m.copy()
    kf = k // N_G
    if k % N_G == G_STICK and (m[kf] == FORWARD or m[kf] == BACKWARD):
        m[kf] = STUCK
    settle(t, x, m, p, log, old)
    return 0


@numba.njit(cache=True, nogil=True)
def driveline_restart(t, x, u, m, p, log):
    """Modes consistent with the forces at a start, a resume or a signal's jump."""
    return settle(t, x, m, p, log, m.copy())


@numba.njit(cache=True, nogil=True)
def driveline_accept(t, x, u, m, p):
    """Nothing to commit (the network has no memories)."""
    return 0


@numba.njit(cache=True, nogil=True)
def driveline_next_break(t, m, p):
    """Next jump or kink of any signal (steps, ramp corners, table points, a sine's start)."""
    tb = np.inf
    for s in range(p.signals.shape[0]):
        v = signal_break(p.signals[s], p.data, t)
        if v < tb:
            tb = v
    return tb


@numba.njit(cache=True, nogil=True)
def driveline_jacobian(t, x, u, m, p, J):
    """No analytic Jacobian (Dormand-Prince)."""
    return False


dispatch.register(DrivelineParams, rhs=driveline_rhs, outputs=driveline_outputs, update=driveline_update,
                  restart=driveline_restart, accept=driveline_accept, next_break=driveline_next_break,
                  jacobian=driveline_jacobian)
