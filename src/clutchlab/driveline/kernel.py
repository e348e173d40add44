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
K_SPRING, K_FRICTION, K_SOURCE, K_GEAR, K_MOTION = 0, 1, 2, 3, 4
# friction laws
LAW_CLUTCH, LAW_TABLE, LAW_ONEWAY, LAW_EXTERNAL = 0, 1, 2, 3  # cgeo * fn * mu(|w|); table(|w|) (bearing friction);
# freewheel; a clutch model with states of its own (its sliding torque and static limit set by the model's hooks
# before each evaluation of the network: :func:`set_external`, :mod:`clutchlab.driveline.wet`)
# spring laws
SPRING_LINEAR, SPRING_CURVE, SPRING_BACKLASH = 0, 1, 2
# torque sources (K_SOURCE): a signal, or an engine (a torque map over speed and throttle plus an idle-speed PI
# controller whose integral is a state of the network: ``x[2 n + ne + elem[r, E_STATE]]``)
SOURCE_SIGNAL, SOURCE_ENGINE = 0, 1
# motion sources (K_MOTION): prescribed speed or position of flange b
MOTION_SPEED, MOTION_POSITION = 0, 1
# modes of a switched spring (after the friction elements' in the mode vector): a backlash in its gap, or in
# contact beyond either side; a curve spring: the segment of its curve it is on (0 below the first point, i
# between points i-1 and i, m above the last of m points)
LASH_GAP, LASH_UPPER, LASH_LOWER = 0, 1, 2
LASH_VALUES = ("gap", "upper", "lower")
# a backlash's damping law (``elem[r, E_AUX]``): Kelvin-Voigt in contact, or MSL ``ElastoBacklash``'s, whose contact
# has two more modes per side (odd: upper, even: lower): the damping torque limited to the spring torque
# (tau = 2 tau_c) and the contact unloaded (tau = 0, where tau_c + tau_d would pull)
LASH_KELVIN_VOIGT, LASH_MSL = 0, 1
LASH_UPPER_LIMITED, LASH_LOWER_LIMITED, LASH_UPPER_RELEASED, LASH_LOWER_RELEASED = 3, 4, 5, 6
LASH_MSL_VALUES = LASH_VALUES + ("upper_limited", "lower_limited", "upper_released", "lower_released")
# modes of a friction element (index into MODE_VALUES); MSL's codes are MODE_CODES
STUCK, FORWARD, BACKWARD, FREE = 0, 1, 2, 3
MODE_VALUES = ("stuck", "forward", "backward", "free")
MODE_CODES = np.array([0.0, 1.0, -1.0, 2.0])  # MSL PartialFriction: Stuck 0, Forward 1, Backward -1, Free 2
# events: named for the mode entered (friction), or for a backlash closing or opening its gap
EV_STICK, EV_FORWARD, EV_BACKWARD, EV_FREE, EV_CONTACT, EV_SEPARATE, EV_DRIVE_A, EV_DRIVE_B, EV_LOCKED = range(9)
EVENTS = ("stick", "forward", "backward", "free", "contact", "separate", "a_drives", "b_drives", "locked")
_EVENT_OF_MODE = np.array([EV_STICK, EV_FORWARD, EV_BACKWARD, EV_FREE])
# signals (rows of ``DrivelineParams.signals``, ``N_SIG`` wide: the kind and up to eight parameters)
SIG_CONST, SIG_STEP, SIG_RAMP, SIG_SINE, SIG_TABLE, SIG_SAMPLED = 0, 1, 2, 3, 4, 5
SIG_PULSE, SIG_TRAPEZOID, SIG_EXPONENTIALS, SIG_PRODUCT = 6, 7, 8, 9
N_SIG = 9
# columns of ``elem`` (ints) and ``coef`` (floats)
E_KIND, E_A, E_B, E_LAW, E_SIGNAL, E_TABLE, E_TABLE_N, E_AUX, E_MODE, E_STATE = range(10)  # E_AUX: a curve's kind
N_ELEM = 10      # (0 linear, 1 pchip), an engine map's throttle points; E_MODE: index in m; E_STATE: of a controller state
C_STIFF, C_DAMP, C_PHI0, C_GAP = 0, 1, 2, 3        # spring-damper (curve: its points at E_TABLE; backlash: gap)
C_FN_MAX, C_CGEO, C_PEAK = 0, 1, 2                 # friction (table: speed grid | values at E_TABLE)
C_NCURVE, C_LIFTOFF = 3, 4                         # friction with a normal-force curve (E_AUX points): its
C_RATIO, C_ETA = 0, 1                              # data offset and lift-off input; gear: w_a = ratio * w_b, efficiency
C_IDLE_W, C_IDLE_KP, C_IDLE_KI, C_IDLE_MAX = 0, 1, 2, 3   # an engine's idle controller: set speed [rad/s], gains
                                                   # [N m s/rad], [N m/rad], torque limit [N m]
N_COEF = 5
# modes of a lossy gear (after the switched springs' in the mode vector): the flange that drives (power flows
# from it into the gear)
DRIVE_A, DRIVE_B, DRIVE_LOCKED = 0, 1, 2
DRIVE_VALUES = ("a_drives", "b_drives", "locked")
# switching functions: three per friction element, then two per switched spring (``swit``: backlash and curves),
# then one per lossy gear (``lossy``: the power it takes from its driving flange)
G_STICK, G_BREAK, G_NORMAL = 0, 1, 2
N_G = 3


class DrivelineParams(NamedTuple):
    """Packed parameters of a driveline network (SI: kg m^2, N m/rad, N m s/rad, N, rad/s).

    Built by :func:`clutchlab.driveline.network.pack`.  ``inertia``: the inertias [kg m^2];
    ``elem`` (int64, one row per element, columns ``E_*``) and ``coef`` (float, ``C_*``): the
    elements; ``signals`` (one row per signal: kind, then up to ``N_SIG - 1`` parameters) and ``data`` (tables:
    friction characteristics, spring curves and signal tables); ``fric`` (int64): the element row of
    each friction element; ``cons``: of each constraint (gears and motion sources, always held);
    ``swit``: of each switched spring (backlash, curve spring; its place in the mode vector is
    ``elem[r, E_MODE]``); ``lossy``: of each gear with an efficiency below 1 (its mode, the driving flange, at
    ``elem[r, E_MODE]``); ``work`` and ``iwork`` (int64, the pivots of the constraint set's factorisation):
    scratch of the hooks (per run).
    """

    inertia: np.ndarray
    elem: np.ndarray
    coef: np.ndarray
    signals: np.ndarray
    data: np.ndarray
    fric: np.ndarray
    cons: np.ndarray
    swit: np.ndarray
    lossy: np.ndarray
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


@numba.njit(cache=True, nogil=True, inline="always")
def _period(start, period, t):
    """Index ``k`` [-] (a float) of the period holding ``t >= start``: ``start + k period <= t < start + (k + 1)
    period`` with exactly those sums, the break times of :func:`signal_break` (a floor of the quotient alone
    may round to the period before a break)."""
    k = math.floor((t - start) / period)
    if start + (k + 1.0) * period <= t:
        k += 1.0
    elif start + k * period > t:
        k -= 1.0
    return k


@numba.njit(cache=True, nogil=True, inline="always")
def _corners(sig):
    """Offsets [s] of a periodic signal's corners within its period: a pulse's end of the on-part (the width,
    a fraction, times the period); a trapezoid's ends of rising, width and falling (MSL ``T_rising``,
    ``T_width``, ``T_falling``)."""
    if int(sig[0]) == SIG_PULSE:
        tw = sig[2] * sig[3]
        return tw, tw, tw
    return sig[2], sig[2] + sig[3], sig[2] + sig[3] + sig[4]


@numba.njit(cache=True, nogil=True, inline="always")
def _periodic_at(sig, t):
    """A pulse's or trapezoid's period at ``t``: ``(active, t_k)``, the start ``t_k`` [s] of the period holding
    ``t`` and whether that period is one of its ``nperiod`` (MSL: 0 before ``startTime``, after ``nperiod``
    periods, or with ``nperiod = 0``)."""
    if int(sig[0]) == SIG_PULSE:
        period, nper, start = sig[3], sig[4], sig[6]
    else:
        period, nper, start = sig[5], sig[6], sig[8]
    if t < start or nper == 0.0:
        return False, start
    k = _period(start, period, t)
    if nper > 0.0 and k >= nper:
        return False, start
    return True, start + k * period


@numba.njit(cache=True, nogil=True)
def _basic_value(sig, data, t):
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
    if kind == SIG_PULSE:   # MSL Pulse: amplitude while t < T_start + T_width
        on, tk = _periodic_at(sig, t)
        tw, _c2, _c3 = _corners(sig)
        return sig[5] + (sig[1] if on and (t < tk + tw or sig[2] >= 1.0) else 0.0)   # width 1: on throughout
    if kind == SIG_TRAPEZOID:   # MSL Trapezoid: rising, width, falling, then 0 to the period's end
        on, tk = _periodic_at(sig, t)
        if not on:
            return sig[7]
        c1, c2, c3 = _corners(sig)
        if t < tk + c1:
            return sig[7] + sig[1] * (t - tk) / sig[2]
        if t < tk + c2:
            return sig[7] + sig[1]
        if t < tk + c3:
            return sig[7] + sig[1] * (tk + c3 - t) / sig[4]
        return sig[7]
    if kind == SIG_EXPONENTIALS:   # MSL Exponentials: outMax (1 - exp(-t'/riseTimeConst)), then the fall
        if t < sig[6]:
            return sig[5]
        tr = sig[6] + sig[2]
        if t < tr:
            return sig[5] - sig[1] * math.expm1(-(t - sig[6]) / sig[3])
        return sig[5] - sig[1] * math.expm1(-sig[2] / sig[3]) * math.exp(-(t - tr) / sig[4])
    return _table(data, int(sig[1]), int(sig[2]), t)


@numba.njit(cache=True, nogil=True)
def signal_value(sig, data, t):
    """Value of one signal row at ``t`` (MSL ``Modelica.Blocks.Sources``: Constant, Step, Ramp, Sine, Pulse,
    Trapezoid, Exponentials, a table; ``Blocks.Math.Product`` of such signals).

    Rows (``N_SIG`` wide): ``[kind, p0 .. p7]``; constant ``[k, value]``; step ``[k, height, start, offset]``;
    ramp ``[k, height, duration, start, offset]``; sine ``[k, amplitude, frequency, phase, offset, start]``
    (zero plus offset before the start, as MSL's ``Sine``); pulse ``[k, amplitude, width (a fraction of the
    period), period, nperiod (< 0: unlimited), offset, start]``; trapezoid ``[k, amplitude, rising, width,
    falling, period, nperiod, offset, start]``; exponentials ``[k, outMax, riseTime, riseTimeConst,
    fallTimeConst, offset, start]``; table ``[k, start index, n]`` in ``data``; a sampled signal as a table,
    then ``[start, number]`` of its corners in ``data``; a product ``[k, start index, n]``: its ``n`` factors'
    rows, one after the other in ``data`` (none a product; ``Driveline.pack`` flattens nested ones).
    """
    if int(sig[0]) == SIG_PRODUCT:
        o, nf = int(sig[1]), int(sig[2])
        v = 1.0
        for i in range(nf):
            v *= _basic_value(data[o + i * N_SIG:o + (i + 1) * N_SIG], data, t)
        return v
    return _basic_value(sig, data, t)


@numba.njit(cache=True, nogil=True)
def _basic_break(sig, data, t):
    kind = int(sig[0])
    if kind == SIG_STEP:
        return sig[2] if sig[2] > t else np.inf
    if kind == SIG_RAMP:
        if sig[3] > t:
            return sig[3]
        return sig[3] + sig[2] if sig[3] + sig[2] > t else np.inf
    if kind == SIG_SINE:
        return sig[5] if sig[5] > t else np.inf
    if kind == SIG_PULSE or kind == SIG_TRAPEZOID:   # every corner of every period, then each period's start
        if kind == SIG_PULSE:
            period, nper, start = sig[3], sig[4], sig[6]
        else:
            period, nper, start = sig[5], sig[6], sig[8]
        if nper == 0.0:
            return np.inf
        if t < start:
            return start
        k = _period(start, period, t)
        if nper > 0.0 and k >= nper:
            return np.inf
        tk = start + k * period
        c1, c2, c3 = _corners(sig)
        if tk + c1 > t:
            return tk + c1
        if tk + c2 > t:
            return tk + c2
        if tk + c3 > t:
            return tk + c3
        return start + (k + 1.0) * period
    if kind == SIG_EXPONENTIALS:
        if sig[6] > t:
            return sig[6]
        return sig[6] + sig[2] if sig[6] + sig[2] > t else np.inf
    if kind == SIG_TABLE or kind == SIG_SAMPLED:   # every point of a table; a sampled signal's corners
        s = int(sig[1]) if kind == SIG_TABLE else int(sig[3])
        for i in range(s, s + int(sig[2] if kind == SIG_TABLE else sig[4])):
            if data[i] > t:
                return data[i]
    return np.inf


@numba.njit(cache=True, nogil=True)
def signal_break(sig, data, t):
    """Next time after ``t`` at which the signal has a jump or a kink (inf if none); a product's, the first of
    its factors'."""
    if int(sig[0]) == SIG_PRODUCT:
        o, nf = int(sig[1]), int(sig[2])
        tb = np.inf
        for i in range(nf):
            tb = min(tb, _basic_break(data[o + i * N_SIG:o + (i + 1) * N_SIG], data, t))
        return tb
    return _basic_break(sig, data, t)


@numba.njit(cache=True, nogil=True)
def _basic_rates(sig, data, t):
    kind = int(sig[0])
    if kind == SIG_RAMP:
        if sig[3] <= t < sig[3] + sig[2]:
            return sig[1] / sig[2], 0.0
        return 0.0, 0.0
    if kind == SIG_SINE:
        if t < sig[5]:
            return 0.0, 0.0
        om = 2.0 * math.pi * sig[2]
        arg = om * (t - sig[5]) + sig[3]
        return sig[1] * om * math.cos(arg), -sig[1] * om * om * math.sin(arg)
    if kind == SIG_TRAPEZOID:
        on, tk = _periodic_at(sig, t)
        if not on:
            return 0.0, 0.0
        c1, c2, c3 = _corners(sig)
        if t < tk + c1:
            return sig[1] / sig[2], 0.0
        if t < tk + c2:
            return 0.0, 0.0
        if t < tk + c3:
            return -sig[1] / sig[4], 0.0
        return 0.0, 0.0
    if kind == SIG_EXPONENTIALS:
        if t < sig[6]:
            return 0.0, 0.0
        tr = sig[6] + sig[2]
        if t < tr:
            r1 = sig[1] / sig[3] * math.exp(-(t - sig[6]) / sig[3])
            return r1, -r1 / sig[3]
        y = -sig[1] * math.expm1(-sig[2] / sig[3]) * math.exp(-(t - tr) / sig[4])
        return -y / sig[4], y / (sig[4] * sig[4])
    if kind == SIG_TABLE or kind == SIG_SAMPLED:
        s = int(sig[1])
        n = int(sig[2])
        if n < 2 or t < data[s] or t >= data[s + n - 1]:
            return 0.0, 0.0
        lo, _w = bracket(data[s:s + n], t)
        return (data[s + n + lo + 1] - data[s + n + lo]) / (data[s + lo + 1] - data[s + lo]), 0.0
    return 0.0, 0.0


@numba.njit(cache=True, nogil=True)
def signal_rates(sig, data, t):
    """First and second time derivatives of one signal row at ``t``.

    One-sided from the right at a corner (the slope of the segment that follows), so a ramp's, a trapezoid's
    or a table's rate is piecewise constant between the breaks of :func:`signal_break`.  A jump (a step's, a
    pulse's) has no rate here (speed sources refuse signals that jump).  A product ``y = prod f_i`` by the
    product rule, one factor at a time: ``(y f)' = y' f + y f'``, ``(y f)'' = y'' f + 2 y' f' + y f''``.
    """
    if int(sig[0]) == SIG_PRODUCT:
        o, nf = int(sig[1]), int(sig[2])
        y, d1, d2 = 1.0, 0.0, 0.0
        for i in range(nf):
            row = data[o + i * N_SIG:o + (i + 1) * N_SIG]
            f = _basic_value(row, data, t)
            f1, f2 = _basic_rates(row, data, t)
            d2 = d2 * f + 2.0 * d1 * f1 + y * f2
            d1 = d1 * f + y * f1
            y *= f
        return d1, d2
    return _basic_rates(sig, data, t)


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
    bearing friction (``BearingFriction``): the table itself; a one-way clutch (freewheel): none while it
    overruns.  At ``w = 0`` this is ``tau0``; the static limit is ``peak * tau0``.
    """
    e = p.elem[r]
    law = e[E_LAW]
    if law == LAW_ONEWAY:
        return 0.0
    if law == LAW_EXTERNAL:
        return _external(p)[3 * e[E_AUX]]
    c = p.coef[r]
    val = _characteristic(p.data, e[E_TABLE], e[E_TABLE_N], w_abs)
    if law == LAW_TABLE:
        return val
    return c[C_CGEO] * normal_force(p, r, t) * val


@numba.njit(cache=True, nogil=True)
def normal_force(p, r, t):
    """Normal force [N] of friction element row ``r``: ``fn_max * f(t)`` (``fn_max`` alone without a signal);
    with a normal-force curve (``E_AUX`` points, an E-clutch's static curve), ``fn_max * curve(f(t))``:
    the signal is then the actuator input (the release bearing position [m])."""
    e = p.elem[r]
    f = 1.0 if e[E_SIGNAL] < 0 else signal_value(p.signals[e[E_SIGNAL]], p.data, t)
    if e[E_AUX] > 0:
        f = _table(p.data, int(p.coef[r][C_NCURVE]), e[E_AUX], f)
    return p.coef[r][C_FN_MAX] * f


@numba.njit(cache=True, nogil=True)
def _is_free(p, r, t):
    """A clutch or brake is free when its normal force is negative, or zero and not rising (a force that
    leaves zero upwards at ``t`` engages now: its switching function starts on zero, which is no crossing)."""
    e = p.elem[r]
    if e[E_LAW] != LAW_CLUTCH:
        return False
    if e[E_AUX] > 0:   # a normal-force curve: free beyond its lift-off input, or at it and not coming back
        u = signal_value(p.signals[e[E_SIGNAL]], p.data, t)
        lift = p.coef[r][C_LIFTOFF]
        if u != lift:
            return u > lift
        rate, _d2 = signal_rates(p.signals[e[E_SIGNAL]], p.data, t)
        return rate >= 0.0
    fn = normal_force(p, r, t)
    if fn != 0.0:
        return fn < 0.0
    if e[E_SIGNAL] < 0:
        return True
    rate, _d2 = signal_rates(p.signals[e[E_SIGNAL]], p.data, t)
    return p.coef[r][C_FN_MAX] * rate <= 0.0


@numba.njit(cache=True, nogil=True)
def static_limit(p, r, t):
    """Static limit ``peak * tau0`` [N m] of friction element row ``r`` at time ``t`` (a one-way clutch: inf)."""
    if p.elem[r][E_LAW] == LAW_ONEWAY:
        return np.inf
    if p.elem[r][E_LAW] == LAW_EXTERNAL:
        return _external(p)[3 * p.elem[r][E_AUX] + 1]
    return p.coef[r][C_PEAK] * friction_torque(p, r, t, 0.0)


@numba.njit(cache=True, nogil=True)
def holding_limit(p, r, t, tau):
    """Largest ``|tau|`` [N m] a stuck friction element row ``r`` holds in the direction of ``tau``: its static
    limit; a one-way clutch holds any torque against overrunning (``tau <= 0``) and none for it (``tau > 0``)."""
    if p.elem[r][E_LAW] == LAW_ONEWAY:
        return 0.0 if tau > 0.0 else np.inf
    return static_limit(p, r, t)


# ----------------------------------------------------------------- engines
@numba.njit(cache=True, nogil=True)
def engine_map(data, start, ns, nt, w, throttle):
    """Full-load/part-load torque [N m] of an engine map at speed ``w`` [rad/s] and throttle [-]: bilinear in
    the speed grid ``data[start:start+ns]`` and the throttle grid (``nt`` points after it), the values row by
    speed (``ns x nt`` after the grids), held beyond the grids."""
    ws = data[start:start + ns]
    th = data[start + ns:start + ns + nt]
    v0 = start + ns + nt
    i, a = 0, 0.0
    if ns > 1:
        i, a = bracket(ws, min(max(w, ws[0]), ws[ns - 1]))
    j, b = 0, 0.0
    if nt > 1:
        j, b = bracket(th, min(max(throttle, th[0]), th[nt - 1]))
    i1 = min(i + 1, ns - 1)
    j1 = min(j + 1, nt - 1)
    f00 = data[v0 + i * nt + j]
    f01 = data[v0 + i * nt + j1]
    f10 = data[v0 + i1 * nt + j]
    f11 = data[v0 + i1 * nt + j1]
    return (1.0 - a) * ((1.0 - b) * f00 + b * f01) + a * ((1.0 - b) * f10 + b * f11)


@numba.njit(cache=True, nogil=True)
def engine_torque(p, r, t, x, n):
    """Torque [N m] of engine row ``r`` on its flange, and the rate of its idle controller's integral [N m/s].

    ``T = map(w, throttle(t)) + T_idle`` with ``w = w_b - w_a`` (crankshaft against its support) and the
    idle-speed PI controller ``T_idle = clip(kp (w_idle - w) + I, 0, T_idle_max)``, ``dI/dt = ki (w_idle - w) +
    (ki / kp) (T_idle - kp (w_idle - w) - I)`` (back-calculation anti-windup: the integral tracks the clipped
    output, so the right-hand side is continuous).  The controller only adds torque (it cannot brake the
    engine)."""
    e = p.elem[r]
    c = p.coef[r]
    w = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
    thr = signal_value(p.signals[e[E_SIGNAL]], p.data, t)
    tq = engine_map(p.data, e[E_TABLE], e[E_TABLE_N], e[E_AUX], w, thr)
    if c[C_IDLE_MAX] <= 0.0:
        return tq, 0.0
    err = c[C_IDLE_W] - w
    integral = x[2 * n + p.elem.shape[0] + e[E_STATE]]
    cmd = c[C_IDLE_KP] * err + integral
    out = min(max(cmd, 0.0), c[C_IDLE_MAX])
    # back-calculation anti-windup with the tracking gain ki/kp: the right-hand side stays continuous (a
    # conditional integration would switch on the clip's edge and chatter there: a sliding mode)
    kaw = c[C_IDLE_KI] / c[C_IDLE_KP] if c[C_IDLE_KP] > 0.0 else c[C_IDLE_KI]
    return tq + out, c[C_IDLE_KI] * err + kaw * (out - cmd)


@numba.njit(cache=True, nogil=True)
def source_torque(p, r, t, x, n):
    """Torque [N m] a torque source row ``r`` applies to its flange b (reaction on a): its signal, or an
    engine's (:func:`engine_torque`)."""
    e = p.elem[r]
    if e[E_LAW] == SOURCE_ENGINE:
        tq, _rate = engine_torque(p, r, t, x, n)
        return tq
    return signal_value(p.signals[e[E_SIGNAL]], p.data, t)


# ----------------------------------------------------------------- springs
@numba.njit(cache=True, nogil=True)
def _segment_value(data, s, m, kind, seg, phi):
    """Elastic torque [N m] of a curve spring on segment ``seg`` (0 below the first point, ``i`` between
    points ``i-1`` and ``i``, ``m`` above the last), the segment's polynomial continued beyond its points:
    the torque is smooth within a step and the kink at a point falls on a located event."""
    xs = data[s:s + m]
    fs = data[s + m:s + 2 * m]
    ds = data[s + 2 * m:s + 3 * m]
    if seg == 0 or seg == m:
        end = 0 if seg == 0 else m - 1
        if kind == 0:
            sl = (fs[1] - fs[0]) / (xs[1] - xs[0]) if seg == 0 else (fs[m - 1] - fs[m - 2]) / (xs[m - 1] - xs[m - 2])
        else:
            sl = ds[end]
        return fs[end] + sl * (phi - xs[end])
    lo = seg - 1
    h = xs[lo + 1] - xs[lo]
    u = (phi - xs[lo]) / h
    if kind == 0:
        return fs[lo] + (fs[lo + 1] - fs[lo]) * u
    u2 = u * u
    u3 = u2 * u
    return ((2.0 * u3 - 3.0 * u2 + 1.0) * fs[lo] + (u3 - 2.0 * u2 + u) * h * ds[lo] + (-2.0 * u3 + 3.0 * u2) * fs[lo + 1]
            + (u3 - u2) * h * ds[lo + 1])


@numba.njit(cache=True, nogil=True)
def _segment_energy(data, s, m, kind, seg, phi):
    """Integral of the curve from the first point to ``phi`` along segment ``seg``'s polynomial (as
    :func:`_segment_value`; the curve's own integral where ``phi`` lies on the segment) [J]."""
    xs = data[s:s + m]
    fs = data[s + m:s + 2 * m]
    ds = data[s + 2 * m:s + 3 * m]
    cs = data[s + 3 * m:s + 4 * m]
    if seg == 0 or seg == m:
        end = 0 if seg == 0 else m - 1
        if kind == 0:
            sl = (fs[1] - fs[0]) / (xs[1] - xs[0]) if seg == 0 else (fs[m - 1] - fs[m - 2]) / (xs[m - 1] - xs[m - 2])
        else:
            sl = ds[end]
        dx = phi - xs[end]
        return cs[end] + fs[end] * dx + 0.5 * sl * dx * dx
    lo = seg - 1
    h = xs[lo + 1] - xs[lo]
    u = (phi - xs[lo]) / h
    if kind == 0:
        return cs[lo] + h * (fs[lo] * u + 0.5 * (fs[lo + 1] - fs[lo]) * u * u)
    u2 = u * u
    u3 = u2 * u
    u4 = u3 * u
    return cs[lo] + h * (fs[lo] * (u - u3 + 0.5 * u4) + h * ds[lo] * (0.5 * u2 - 2.0 * u3 / 3.0 + 0.25 * u4)
                         + fs[lo + 1] * (u3 - 0.5 * u4) + h * ds[lo + 1] * (0.25 * u4 - u3 / 3.0))


@numba.njit(cache=True, nogil=True)
def _spring_deflection(p, r, x, n):
    e = p.elem[r]
    pa = 0.0 if e[E_A] < 0 else x[e[E_A]]
    pb = 0.0 if e[E_B] < 0 else x[e[E_B]]
    return pb - pa - p.coef[r][C_PHI0]




@numba.njit(cache=True, nogil=True, inline="always")
def _lash_side(mode):
    """The side of a backlash's contact mode: 1 upper (odd modes), -1 lower (even), 0 in the gap."""
    return 0.0 if mode == LASH_GAP else (1.0 if mode % 2 == 1 else -1.0)


@numba.njit(cache=True, nogil=True)
def _lash_msl(p, r):
    """Does backlash row ``r`` follow MSL ``ElastoBacklash``'s damping law (with damping: without, both laws are
    the same spring)?"""
    return p.elem[r][E_AUX] == LASH_MSL and p.coef[r][C_DAMP] > 0.0


@numba.njit(cache=True, nogil=True)
def spring_torque(p, r, x, n, m):
    """Torque [N m] of spring-damper row ``r`` and its elastic part, ``(tau, tau_c)``.

    Deflection ``phi = phi_b - phi_a - phi_rel0``, damping ``tau_d = d (w_b - w_a)``.  Linear:
    ``tau_c = c phi``; a curve: ``tau_c = curve(phi)`` (as :func:`clutchlab.curves.curve_eval`) on the
    segment of its mode (:func:`_segment_value`); backlash
    (total gap ``b``), by its contact mode (``m``): in contact above the gap ``tau_c = c (phi - b/2)``,
    below it ``c (phi + b/2)``, nothing in the gap.  The contact is a mode, entered at the gap's edge and
    left when the torque would pull (located events, :func:`driveline_update`), so the torque is smooth
    within a step.  ``tau = tau_c + tau_d``.  With MSL's damping law (``ElastoBacklash``, above the gap;
    mirrored below) ``tau = tau_c + min(tau_c, tau_d)``, and 0 where ``tau_c + tau_d <= 0``: three modes per
    side (``tau_c + tau_d``; ``2 tau_c`` while ``tau_d >= tau_c``; 0), changed at their kinks, located events.
    """
    e = p.elem[r]
    c = p.coef[r]
    phi = _spring_deflection(p, r, x, n)
    tau_d = c[C_DAMP] * (_speed(x, n, e[E_B]) - _speed(x, n, e[E_A]))
    law = e[E_LAW]
    if law == SPRING_CURVE:
        tc = _segment_value(p.data, e[E_TABLE], e[E_TABLE_N], e[E_AUX], m[e[E_MODE]], phi)
        return tc + tau_d, tc
    if law == SPRING_BACKLASH:
        mode = m[e[E_MODE]]
        if mode == LASH_GAP:
            return 0.0, 0.0
        tc = c[C_STIFF] * (phi - _lash_side(mode) * 0.5 * c[C_GAP])
        if mode <= LASH_LOWER:
            return tc + tau_d, tc
        # MSL ElastoBacklash: tau_c + min(tau_c, tau_d) (upper; max below) -- limited: 2 tau_c; released: 0
        return (2.0 * tc if mode <= LASH_LOWER_LIMITED else 0.0), tc
    tc = c[C_STIFF] * phi
    return tc + tau_d, tc


@numba.njit(cache=True, nogil=True)
def spring_energy(p, r, x, n, m):
    """Energy [J] stored in spring-damper row ``r`` (the integral of its elastic torque over the deflection;
    a backlash's in its contact mode ``m``)."""
    e = p.elem[r]
    c = p.coef[r]
    phi = _spring_deflection(p, r, x, n)
    law = e[E_LAW]
    if law == SPRING_CURVE:
        return _segment_energy(p.data, e[E_TABLE], e[E_TABLE_N], e[E_AUX], m[e[E_MODE]], phi)
    if law == SPRING_BACKLASH:
        mode = m[e[E_MODE]]
        if mode == LASH_GAP:
            return 0.0
        q = phi - _lash_side(mode) * 0.5 * c[C_GAP]
        return 0.5 * c[C_STIFF] * q * q
    return 0.5 * c[C_STIFF] * phi * phi


# ----------------------------------------------------------------- network evaluation
@numba.njit(cache=True, nogil=True)
def _speed(x, n, i):
    return 0.0 if i < 0 else x[n + i]


@numba.njit(cache=True, nogil=True)
def _coefficients(p, r):
    """Flange weights of element row ``r``: its relative speed is ``cb w_b - ca w_a``, its torque ``tau`` acts
    ``+ca tau`` on flange a and ``-cb tau`` on flange b.  A gear (MSL ``IdealGear``, ``w_a = ratio w_b``):
    ``ca = 1, cb = ratio``; a motion source: ``ca = 0`` (ground); others 1, 1."""
    e = p.elem[r]
    if e[E_KIND] == K_GEAR:
        return 1.0, p.coef[r][C_RATIO]
    if e[E_KIND] == K_MOTION:
        return 0.0, 1.0
    return 1.0, 1.0


@numba.njit(cache=True, nogil=True)
def _force_factor(p, r, m):
    """Factor on the torque a gear row ``r`` puts on flange b: its efficiency ``eta`` while flange a drives, ``1 /
    eta`` while b drives (a lossy gear's mode in ``m``); 1 for everything else."""
    e = p.elem[r]
    if e[E_KIND] != K_GEAR or e[E_MODE] < 0:
        return 1.0
    eta = p.coef[r][C_ETA]
    mode = m[e[E_MODE]]
    return eta if mode == DRIVE_A else (1.0 / eta if mode == DRIVE_B else 1.0)


@numba.njit(cache=True, nogil=True)
def gear_loss(p, r, m, w_a, tau):
    """Power [W] lost in a gear row ``r`` carrying ``tau`` (its torque on flange a) at flange a's speed ``w_a``:
    ``(1 - f) P_a`` with ``P_a = -tau w_a`` the power flange a delivers and ``f`` :func:`_force_factor` (zero for
    an ideal gear; non-negative in a consistent mode)."""
    return (1.0 - _force_factor(p, r, m)) * (-tau * w_a)


@numba.njit(cache=True, nogil=True)
def relative_speed(p, r, x, n):
    """Relative speed ``cb w_b - ca w_a`` [rad/s] of element row ``r`` (``w_b - w_a`` but for gears)."""
    e = p.elem[r]
    ca, cb = _coefficients(p, r)
    return cb * _speed(x, n, e[E_B]) - ca * _speed(x, n, e[E_A])


@numba.njit(cache=True, nogil=True)
def _apply(F, e, ca, cb, tq):
    if e[E_B] >= 0:
        F[e[E_B]] -= cb * tq
    if e[E_A] >= 0:
        F[e[E_A]] += ca * tq


@numba.njit(cache=True, nogil=True)
def evaluate_network(t, x, m, p, acc, tau):
    """Accelerations ``acc`` [rad/s^2] of the inertias and the torque ``tau`` [N m] of every element.

    Spring-dampers :func:`spring_torque`; torque sources: their signal (acting on flange b, positive
    accelerating it, so ``tau`` is stored with the element convention as minus the source torque);
    sliding friction ``+-friction_torque``; free friction 0; stuck friction, gears and motion sources:
    the solution of the constraint set (:func:`_solve_stuck`).  Returns the size of that set.
    """
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    nc = p.cons.shape[0]
    wk = p.work
    F = wk[0:n]
    for i in range(n):
        F[i] = 0.0
    for r in range(ne):
        e = p.elem[r]
        kind = e[E_KIND]
        if kind == K_SPRING:
            tq, _tc = spring_torque(p, r, x, n, m)
        elif kind == K_SOURCE:
            tq = -(signal_value(p.signals[e[E_SIGNAL]], p.data, t) if e[E_LAW] == SOURCE_SIGNAL
                   else source_torque(p, r, t, x, n))
        else:
            continue
        tau[r] = tq
        _apply(F, e, 1.0, 1.0, tq)
    # sliding and free friction; the constraint set: stuck friction, gears, motion sources
    ns = 0
    stuck = wk[n:n + _nk(p)]  # element rows of the set (as floats; -(row + 1): a locked gear's hold)
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
        _apply(F, e, 1.0, 1.0, tq)
    for k in range(nc):
        stuck[ns] = p.cons[k]
        ns += 1
    for j in range(p.lossy.shape[0]):   # a locked lossy gear holds flange a at rest (member -(row + 1))
        r = p.lossy[j]
        if m[p.elem[r][E_MODE]] == DRIVE_LOCKED:
            stuck[ns] = -(r + 1)
            ns += 1
    if ns > 0:
        _solve_stuck(t, p, m, stuck, ns, F, tau)
    for i in range(n):
        acc[i] = F[i] / p.inertia[i]
    return ns


@numba.njit(cache=True, nogil=True)
def _layout(n, nk, ne):
    """Offsets in ``DrivelineParams.work`` (``nk``: the largest constraint set): net torques F (n) | the set
    (nk) | A (nk^2) | A + eps D (nk^2) | right-hand side (nk) | its torques (nk) | weights (nk) | residual
    (nk) | flange a, ca, flange b, cb, force factor of each member (5 nk) | accelerations (n) | element torques (ne) |
    slack of each friction element's stick function (nf, :func:`settle`) | sliding torque, static limit and
    lock-up limit of each clutch model (3 per ``LAW_EXTERNAL`` element, :func:`set_external`) | initial stored
    energy (1)."""
    o_a = n + nk
    o_m = o_a + nk * nk
    o_b = o_m + nk * nk
    o_l = o_b + nk
    o_c = o_l + nk
    o_r = o_c + nk
    o_g = o_r + nk
    o_acc = o_g + 5 * nk
    o_tau = o_acc + n
    return o_a, o_m, o_b, o_l, o_c, o_r, o_g, o_acc, o_tau


def work_size(n, nk, ne, nf, nx=0):
    """Length of ``DrivelineParams.work`` for ``n`` inertias, ``nk`` friction elements and constraints, ``ne``
    elements, ``nf`` friction elements, ``nx`` clutch models with states of their own."""
    return 2 * n + 11 * nk + 2 * nk * nk + ne + nf + 3 * nx + 1


@numba.njit(cache=True, nogil=True, inline="always")
def _nk(p):
    """Largest constraint set: every friction element, every gear and motion source, and the hold of every lossy
    gear (``DRIVE_LOCKED``)."""
    return p.fric.shape[0] + p.cons.shape[0] + p.lossy.shape[0]


@numba.njit(cache=True, nogil=True)
def _acc_tau(p):
    n = p.inertia.shape[0]
    nk = _nk(p)
    ne = p.elem.shape[0]
    o = _layout(n, nk, ne)
    return p.work[o[7]:o[7] + n], p.work[o[8]:o[8] + ne]


@numba.njit(cache=True, nogil=True)
def _slack(p):
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    ne = p.elem.shape[0]
    o = _layout(n, _nk(p), ne)
    return p.work[o[8] + ne:o[8] + ne + nf]


@numba.njit(cache=True, nogil=True)
def _external(p):
    """The sliding torques, static limits and lock-up limits of the clutch models (``LAW_EXTERNAL``), three per
    model."""
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    ne = p.elem.shape[0]
    o = _layout(n, _nk(p), ne)
    return p.work[o[8] + ne + nf:p.work.shape[0] - 1]


@numba.njit(cache=True, nogil=True)
def set_external(p, j, slide, limit, lock):
    """Set clutch model ``j``'s (``elem[r, E_AUX] = j``) sliding torque magnitude ``slide`` [N m] at the present
    relative speed, its static limit ``limit`` [N m] (the torque it holds while stuck: beyond it, it breaks
    away) and its lock-up limit ``lock`` [N m] (the torque it must cover to stick when its relative speed
    reaches zero; MSL's friction elements use their static limit for both), for the network's evaluations at
    the present state.  Its model's hooks call this before every hook of the network."""
    ext = _external(p)
    ext[3 * j] = slide
    ext[3 * j + 1] = limit
    ext[3 * j + 2] = lock


@numba.njit(cache=True, nogil=True)
def _solve_stuck(t, p, m, stuck, ns, F, tau):
    """Torques of the constraint set -- stuck friction elements, gears, motion sources -- solved together.

    Each member ``k`` holds its relative acceleration ``g_k^T a`` (``g_k = cb e_b - ca e_a``) at its
    target: zero, or the prescribed acceleration of a motion source.  ``A lam = g^T M^-1 F - target``
    with ``A[k, j] = g_k^T M^-1 h_j``, ``h_j`` the flange weights of member ``j``'s torque: ``g_j``, but for
    a lossy gear (efficiency ``eta``, MSL ``LossyGear`` without bearing friction), whose torque on flange b
    is ``-ratio f lam`` with ``f = eta`` while flange a drives (mode ``DRIVE_A``) and ``1 / eta`` while b
    drives: the loss is taken from the driving side.  Where stuck elements lock the same relative motion (two clutches
    in parallel) ``A`` is singular: the torque is then split in proportion to the static limits, the
    solution minimising ``sum(lam_k^2 / limit_k)`` (one-way clutches, gears and motion sources weigh as
    the strongest friction element).  It comes from ``(A + eps D) lam = b`` with ``D = diag(max limit /
    limit_k)`` and ``eps`` 1e-8 of ``A``'s diagonal (whose solution has ``D lam`` in the range of ``A``:
    the proportional split), refined twice on the residual of ``A lam = b`` (the constraints hold to
    rounding; the split to about 1e-8).  ``F`` is updated with the torques.
    """
    n = p.inertia.shape[0]
    nk = _nk(p)
    ne = p.elem.shape[0]
    wk = p.work
    o_a, o_m, o_b, o_l, o_c, o_r, o_g, _, _ = _layout(n, nk, ne)
    A = wk[o_a:o_a + nk * nk].reshape((nk, nk))
    b = wk[o_b:o_b + nk]
    lam = wk[o_l:o_l + nk]
    cap = wk[o_c:o_c + nk]
    res = wk[o_r:o_r + nk]
    fa = wk[o_g:o_g + nk]
    ga = wk[o_g + nk:o_g + 2 * nk]
    fb = wk[o_g + 2 * nk:o_g + 3 * nk]
    gb = wk[o_g + 3 * nk:o_g + 4 * nk]
    hf = wk[o_g + 4 * nk:o_g + 5 * nk]
    cmax = 0.0
    for k in range(ns):
        rk = int(stuck[k])
        if rk < 0:   # a locked lossy gear's hold: flange a against the ground, at rest
            ek = p.elem[-rk - 1]
            fa[k] = -1
            fb[k] = ek[E_A]
            ga[k] = 0.0
            gb[k] = 1.0
            hf[k] = 1.0
            b[k] = F[ek[E_A]] / p.inertia[ek[E_A]] if ek[E_A] >= 0 else 0.0
            lam[k] = 0.0
            cap[k] = -1.0
            continue
        ek = p.elem[rk]
        ca, cb = _coefficients(p, rk)
        fa[k] = ek[E_A]
        fb[k] = ek[E_B]
        ga[k] = ca
        gb[k] = cb
        hf[k] = _force_factor(p, rk, m) if p.lossy.shape[0] > 0 else 1.0
        target = 0.0
        if ek[E_KIND] == K_MOTION:
            d1, d2 = signal_rates(p.signals[ek[E_SIGNAL]], p.data, t)
            target = d1 if ek[E_LAW] == MOTION_SPEED else d2
        s = -target
        if ek[E_B] >= 0:
            s += cb * F[ek[E_B]] / p.inertia[ek[E_B]]
        if ek[E_A] >= 0:
            s -= ca * F[ek[E_A]] / p.inertia[ek[E_A]]
        b[k] = s
        lam[k] = 0.0
        cap[k] = -1.0
        if ek[E_KIND] == K_FRICTION and ek[E_LAW] != LAW_ONEWAY:
            cap[k] = static_limit(p, rk, t)
            cmax = max(cmax, cap[k])
    scale = 0.0
    for k in range(ns):
        if cap[k] < 0.0:
            cap[k] = cmax if cmax > 0.0 else 1.0
        ak, bk = int(fa[k]), int(fb[k])
        for j in range(ns):
            aj, bj = int(fa[j]), int(fb[j])
            v = 0.0
            hb = gb[j] * hf[j]
            if bk >= 0 and bk == bj:
                v += gb[k] * hb / p.inertia[bk]
            if bk >= 0 and bk == aj:
                v -= gb[k] * ga[j] / p.inertia[bk]
            if ak >= 0 and ak == bj:
                v -= ga[k] * hb / p.inertia[ak]
            if ak >= 0 and ak == aj:
                v += ga[k] * ga[j] / p.inertia[ak]
            A[k, j] = v
        scale = max(scale, A[k, k])
    cmax = 0.0
    for k in range(ns):
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
        if rk < 0:   # the hold's torque acts on flange a (from the housing); it is not an element's torque
            ea = p.elem[-rk - 1][E_A]
            if ea >= 0:
                F[ea] -= lam[k]
            continue
        tau[rk] = lam[k]
        _apply(F, p.elem[rk], ga[k], gb[k] * hf[k], lam[k])


# ----------------------------------------------------------------- hooks
@numba.njit(cache=True, nogil=True)
def driveline_rhs(t, x, u, m, p, dx, g):
    """Angles and speeds of the inertias, work of the sources, energy dissipated by each element.

    States: ``phi`` (n), ``w`` (n), then one energy per element in element order [J]: a source's work
    ``tau_src * w_b`` (torque and motion sources), the dissipation of the others: ``tau * w_rel`` less
    the rate of the energy a spring stores (``(tau - tau_c) w_rel``; a gear's is zero but for drift); then
    the integral of each engine's idle controller [N m] (:func:`engine_torque`).  Switching functions, three per friction element: the relative speed of a sliding element in its
    direction (falls through zero: it sticks or reverses), the holding limit minus the torque of a stuck
    one (falls through zero: break-away; a one-way clutch's ``-tau``), the normalised normal force
    (either way: free or engaged); then two per switched spring.  A backlash, for its upper and lower
    side: in the gap the deflection minus and plus half the gap (contact when the edge is reached moving
    into it), in contact ``tau / c`` (separation when it falls through zero, as the torque would pull); with
    MSL's damping law, the two of its mode that fall through zero at its kinks (:func:`_lash_msl_switching`).  A
    curve spring: the deflection above the segment's lower point and below its upper one (either falling
    through zero moves it to the next segment).  Then one per lossy gear: the power its driving flange delivers
    plus a floor of 1e-12 of the largest torque times the largest speed (at least 1e-12 W) (falls through zero:
    the power flow reverses).
    """
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    acc, tau = _acc_tau(p)
    slack = _slack(p)
    evaluate_network(t, x, m, p, acc, tau)
    for i in range(n):
        dx[i] = x[n + i]
        dx[n + i] = acc[i]
    for r in range(ne):
        e = p.elem[r]
        kind = e[E_KIND]
        w_rel = relative_speed(p, r, x, n)
        if kind == K_SPRING:
            _tq, tc = spring_torque(p, r, x, n, m)
            dx[2 * n + r] = (tau[r] - tc) * w_rel
        elif kind == K_SOURCE or kind == K_MOTION:
            dx[2 * n + r] = -tau[r] * w_rel
            if kind == K_SOURCE and e[E_LAW] == SOURCE_ENGINE and e[E_STATE] >= 0:
                _tq, rate = engine_torque(p, r, t, x, n)
                dx[2 * n + ne + e[E_STATE]] = rate
        elif kind == K_GEAR:   # the power lost, and the (drift) work of the constraint
            dx[2 * n + r] = gear_loss(p, r, m, _speed(x, n, e[E_A]), tau[r]) + _force_factor(p, r, m) * tau[r] * w_rel
        else:
            dx[2 * n + r] = tau[r] * w_rel
    for k in range(nf):
        r = p.fric[k]
        e = p.elem[r]
        w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
        mk = m[k]
        g[N_G * k + G_STICK] = w_rel + slack[k] if mk == FORWARD else -w_rel + slack[k] if mk == BACKWARD else 1.0
        if mk != STUCK:
            g[N_G * k + G_BREAK] = 1.0
        elif e[E_LAW] == LAW_ONEWAY:
            g[N_G * k + G_BREAK] = -tau[r]
        else:
            g[N_G * k + G_BREAK] = static_limit(p, r, t) - abs(tau[r])
        if e[E_LAW] != LAW_CLUTCH or e[E_SIGNAL] < 0:
            g[N_G * k + G_NORMAL] = 1.0
        elif e[E_AUX] > 0:   # a normal-force curve: the input's distance to lift-off (the force is 0 beyond)
            g[N_G * k + G_NORMAL] = p.coef[r][C_LIFTOFF] - signal_value(p.signals[e[E_SIGNAL]], p.data, t)
        else:
            g[N_G * k + G_NORMAL] = signal_value(p.signals[e[E_SIGNAL]], p.data, t)
    for j in range(p.swit.shape[0]):
        r = p.swit[j]
        c = p.coef[r]
        e = p.elem[r]
        phi = _spring_deflection(p, r, x, n)
        mode = m[nf + j]
        if e[E_LAW] == SPRING_CURVE:   # the points bounding the segment: below (falls through) and above
            s0, mp = e[E_TABLE], e[E_TABLE_N]
            g[N_G * nf + 2 * j] = phi - p.data[s0 + mode - 1] if mode > 0 else 1.0
            g[N_G * nf + 2 * j + 1] = p.data[s0 + mode] - phi if mode < mp else 1.0
            continue
        b2 = 0.5 * c[C_GAP]
        if _lash_msl(p, r):
            g0, g1 = _lash_msl_switching(p, r, x, n, mode, phi)
            g[N_G * nf + 2 * j] = g0
            g[N_G * nf + 2 * j + 1] = g1
            continue
        # in the gap: the edges; in contact: the torque over c (it falls through zero: it would pull)
        lag = c[C_DAMP] / c[C_STIFF] * (_speed(x, n, e[E_B]) - _speed(x, n, e[E_A]))
        g[N_G * nf + 2 * j] = phi - b2 + (lag if mode == LASH_UPPER else 0.0)
        g[N_G * nf + 2 * j + 1] = phi + b2 + (lag if mode == LASH_LOWER else 0.0)
    nsw = p.swit.shape[0]
    nl = p.lossy.shape[0]
    if nl > 0:
        # the power the driving flange delivers, plus a rounding floor: it falls through zero when the power
        # reverses -- also when it grows from exactly zero (a network starting at rest) the wrong way, which a
        # function starting on zero would not show as a crossing
        tmax = 0.0
        for r in range(ne):
            tmax = max(tmax, abs(tau[r]))
        wmax = 0.0
        for i in range(n):
            wmax = max(wmax, abs(x[n + i]))
        floor = 1e-12 * max(1.0, tmax * wmax)
        for j in range(nl):
            r = p.lossy[j]
            e = p.elem[r]
            if m[e[E_MODE]] != DRIVE_LOCKED:
                pa = -tau[r] * _speed(x, n, e[E_A])
                g[N_G * nf + 2 * nsw + j] = (pa if m[e[E_MODE]] == DRIVE_A else -pa) + floor
        for j in range(nl):   # a locked gear: negative while it holds, rising through zero when released
            r = p.lossy[j]
            if m[p.elem[r][E_MODE]] == DRIVE_LOCKED:
                c_a, c_b = _drive_rates(t, x, m, p, j)   # (overwrites the scratch: after everything else)
                g[N_G * nf + 2 * nsw + j] = max(c_a, c_b) - 1e-12 * max(1.0, tmax * tmax)


@numba.njit(cache=True, nogil=True)
def _lash_msl_switching(p, r, x, n, mode, phi):
    """The two switching functions of a backlash with MSL's damping law in contact mode ``mode``, each positive
    within the mode and falling through zero at one of its ends (direction -1), in radians (torques over ``c``);
    ``s`` the contact's side, ``a = s tau_c``, ``b = s tau_d``:

    * gap: ``b/2 - phi`` (upper contact), ``phi + b/2`` (lower contact);
    * ``upper``/``lower`` (``tau_c + tau_d``): ``a - b`` (the damping reaches the spring torque: limited), ``a + b``
      (the torque reaches zero: released);
    * limited (``2 tau_c``): ``b - a`` (back to ``tau_c + tau_d``); none;
    * released (0): ``-(a + b)`` (the contact loads again), ``s phi - b/2`` (the gap's edge: separate).
    """
    e = p.elem[r]
    c = p.coef[r]
    b2 = 0.5 * c[C_GAP]
    if mode == LASH_GAP:
        return b2 - phi, phi + b2
    side = _lash_side(mode)
    a = side * (phi - side * b2)
    b = side * c[C_DAMP] / c[C_STIFF] * (_speed(x, n, e[E_B]) - _speed(x, n, e[E_A]))
    if mode <= LASH_LOWER:
        return a - b, a + b
    if mode <= LASH_LOWER_LIMITED:
        return b - a, 1.0
    return -(a + b), side * phi - b2


@numba.njit(cache=True, nogil=True)
def _lash_msl_update(p, r, x, n, mode, which):
    """The mode a backlash with MSL's damping law enters when its switching function ``which`` (0 or 1) of
    :func:`_lash_msl_switching` falls through zero in ``mode``; from the gap, the contact's mode at the edge
    (limited while ``s tau_d >= s tau_c``: moving in, the damping torque exceeds the spring's, which is zero)."""
    if mode == LASH_GAP:
        side = 1.0 if which == 0 else -1.0
        e = p.elem[r]
        c = p.coef[r]
        a = side * c[C_STIFF] * (_spring_deflection(p, r, x, n) - side * 0.5 * c[C_GAP])
        b = side * c[C_DAMP] * (_speed(x, n, e[E_B]) - _speed(x, n, e[E_A]))
        upper = which == 0
        if b >= a:
            return LASH_UPPER_LIMITED if upper else LASH_LOWER_LIMITED
        return LASH_UPPER if upper else LASH_LOWER
    upper = mode % 2 == 1
    if mode <= LASH_LOWER:
        if which == 0:
            return LASH_UPPER_LIMITED if upper else LASH_LOWER_LIMITED
        return LASH_UPPER_RELEASED if upper else LASH_LOWER_RELEASED
    if mode <= LASH_LOWER_LIMITED:
        return LASH_UPPER if upper else LASH_LOWER
    if which == 0:
        return LASH_UPPER if upper else LASH_LOWER
    return LASH_GAP


@numba.njit(cache=True, nogil=True)
def driveline_outputs(t, x, u, m, p, y):
    """Per element: torque [N m] (a source: its torque on flange b; a gear: ``tau``, on flange a) and, for
    springs and friction, the relative speed [rad/s]; per friction element also its MSL mode code [-] and
    normal force [N]; then kinetic and spring energy, the sources' work, the dissipated energy and the
    energy balance error [J]."""
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
        kind = e[E_KIND]
        if kind == K_SOURCE or kind == K_MOTION:
            y[q] = -tau[r]
            q += 1
            work += x[2 * n + r]
            continue
        lost += x[2 * n + r]
        y[q] = tau[r]
        q += 1
        if kind == K_GEAR:
            continue
        y[q] = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
        q += 1
        if kind == K_SPRING:
            spring += spring_energy(p, r, x, n, m)
    for k in range(nf):
        r = p.fric[k]
        y[q] = MODE_CODES[m[k]]
        y[q + 1] = normal_force(p, r, t) if p.elem[r][E_LAW] == LAW_CLUTCH else 0.0
        q += 2
    y[q] = kinetic
    y[q + 1] = spring
    y[q + 2] = work
    y[q + 3] = lost
    y[q + 4] = work - lost - (kinetic + spring - p.work[p.work.shape[0] - 1])


@numba.njit(cache=True, nogil=True)
def _drive_rates(t, x, m, p, j):
    """Rates of the power flange a of lossy gear ``j`` would deliver, were it released from rest into either
    driving mode: ``(c_a, c_b)`` with ``c_a = -lam_A acc_a`` (positive: flange a would drive) and ``c_b = lam_B
    acc_a`` (positive: flange b would drive), each from the network evaluated in that mode.  At most one is
    positive (the gear's torque has the same sign in both modes); neither is while the torques on its sides are
    within its loss band (a ratio in [eta, 1/eta]): it holds.  Overwrites the network's scratch."""
    n = p.inertia.shape[0]
    r = p.lossy[j]
    e = p.elem[r]
    mi = e[E_MODE]
    acc, tau = _acc_tau(p)
    keep = m[mi]
    m[mi] = DRIVE_A
    evaluate_network(t, x, m, p, acc, tau)
    c_a = -tau[r] * (acc[e[E_A]] if e[E_A] >= 0 else 0.0)
    m[mi] = DRIVE_B
    evaluate_network(t, x, m, p, acc, tau)
    c_b = tau[r] * (acc[e[E_A]] if e[E_A] >= 0 else 0.0)
    m[mi] = keep
    return c_a, c_b


@numba.njit(cache=True, nogil=True)
def _scales(x, p, tau):
    """Largest speed (at least 1) and torque of the network at its last evaluation."""
    n = p.inertia.shape[0]
    wmax = 1.0
    for i in range(n):
        wmax = max(wmax, abs(x[n + i]))
    tmax = 0.0
    for r in range(p.elem.shape[0]):
        tmax = max(tmax, abs(tau[r]))
    return wmax, tmax


@numba.njit(cache=True, nogil=True)
def _gear_mode_at(t, x, m, p, j):
    """The consistent mode of lossy gear ``j``: moving (``|w_a|`` above 1e-9 of the largest speed), the mode
    whose power flows the right way (its own, unless the power it carries has the wrong sign beyond rounding);
    at rest, the mode it would be released into (:func:`_drive_rates`), or ``DRIVE_LOCKED``."""
    n = p.inertia.shape[0]
    r = p.lossy[j]
    e = p.elem[r]
    mode = m[e[E_MODE]]
    acc, tau = _acc_tau(p)
    evaluate_network(t, x, m, p, acc, tau)
    wmax, tmax = _scales(x, p, tau)
    w_a = _speed(x, n, e[E_A])
    if abs(w_a) > 1e-9 * wmax:
        pa = -tau[r] * w_a
        noise = 1e-12 * max(1.0, tmax * wmax)
        if mode == DRIVE_LOCKED:
            return DRIVE_A if pa > 0.0 else DRIVE_B
        if mode == DRIVE_A and pa < -noise:
            return DRIVE_B
        if mode == DRIVE_B and pa > noise:
            return DRIVE_A
        return mode
    c_a, c_b = _drive_rates(t, x, m, p, j)
    floor = 1e-12 * max(1.0, tmax * tmax)
    if c_a > floor:
        return DRIVE_A
    if c_b > floor:
        return DRIVE_B
    return DRIVE_LOCKED


@numba.njit(cache=True, nogil=True)
def _gear_modes(t, x, m, p, log):
    """Every lossy gear in its consistent mode (:func:`_gear_mode_at`), one change at a time to a fixed point;
    an event (``a_drives``, ``b_drives``, ``locked``) per change.  Returns True if a mode changed."""
    nl = p.lossy.shape[0]
    if nl == 0:
        return False
    changed = False
    nf = p.fric.shape[0]
    nsw = p.swit.shape[0]
    for _it in range(3 * nl):
        flip = -1
        new = 0
        for j in range(nl):
            mode = _gear_mode_at(t, x, m, p, j)
            if mode != m[p.elem[p.lossy[j]][E_MODE]]:
                flip = j
                new = mode
                break
        if flip < 0:
            break
        m[p.elem[p.lossy[flip]][E_MODE]] = new
        record(log, t, EV_DRIVE_A + new, nf + nsw + flip)
        changed = True
    return changed


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
        elif m[k] == FREE:   # engaged: slides the way it moves, or sticks (then breaks away if it must)
            w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
            m[k] = FORWARD if w_rel > w_tol else BACKWARD if w_rel < -w_tol else STUCK
    ne = p.elem.shape[0]
    gears = _gear_modes(t, x, m, p, log)
    for _it in range(4 * nf + 4):
        evaluate_network(t, x, m, p, acc, tau)
        # torques below 1e-12 of the largest in the network are rounding (a stuck element that carries
        # nothing while its normal force rises from zero must not break away on them)
        t_noise = 0.0
        for r in range(ne):
            t_noise = max(t_noise, abs(tau[r]))
        t_noise *= 1e-12
        worst = -1
        ratio = 0.0
        for k in range(nf):
            if m[k] != STUCK:
                continue
            r = p.fric[k]
            lim = holding_limit(p, r, t, tau[r])
            if old[k] != STUCK and p.elem[r][E_LAW] == LAW_EXTERNAL:   # sticking now: its lock-up limit
                lim = _external(p)[3 * p.elem[r][E_AUX] + 2]
            # the same test as the break-away function, which has crossed when it reaches zero (the core's
            # convention): |tau| >= limit, a torque to carry (a ratio may round to exactly 1)
            if abs(tau[r]) >= lim and abs(tau[r]) > t_noise:
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
    if _gear_modes(t, x, m, p, log):   # the friction modes changed the torques the gears carry
        gears = True
    # an element that starts to slide from (about) rest may start a rounding's width on the wrong side of zero:
    # its stick function then watches the relative speed fall below -w_tol, not 0 (else, were it to stop at
    # once, the crossing would be missed); one that slides clearly watches 0
    slack = _slack(p)
    any_change = False
    for k in range(nf):
        if m[k] != old[k]:
            record(log, t, _EVENT_OF_MODE[m[k]], k)
            any_change = True
            e = p.elem[p.fric[k]]
            w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
            slack[k] = w_tol if abs(w_rel) <= w_tol else 0.0
    return any_change or gears


@numba.njit(cache=True, nogil=True)
def driveline_update(t, x, u, m, p, k, log):
    """Switching function ``k`` crossed: a sliding element reached zero relative speed (it sticks, or
    reverses if it cannot hold), a stuck one reached its holding limit, a normal force changed sign, or a
    backlash closed (``contact``) or opened (``separate``) its gap, or (MSL's damping law) reached a kink of
    its contact law (:func:`_lash_msl_update`, no event)."""
    nf = p.fric.shape[0]
    nsw = p.swit.shape[0]
    if k >= N_G * nf + 2 * nsw:   # a lossy gear's power reached zero: the other flange drives now
        j = k - N_G * nf - 2 * nsw
        mi = p.elem[p.lossy[j]][E_MODE]
        n = p.inertia.shape[0]
        acc, tau = _acc_tau(p)
        evaluate_network(t, x, m, p, acc, tau)
        wmax, _tmax = _scales(x, p, tau)
        if m[mi] != DRIVE_LOCKED and abs(_speed(x, n, p.elem[p.lossy[j]][E_A])) > 1e-9 * wmax:
            new = DRIVE_B if m[mi] == DRIVE_A else DRIVE_A   # its torque reversed while moving: the other side drives
        else:
            new = _gear_mode_at(t, x, m, p, j)                # at rest: released one way, or held
        if new != m[mi]:
            m[mi] = new
            record(log, t, EV_DRIVE_A + new, nf + nsw + j)
        settle(t, x, m, p, log, m.copy())
        return 0
    if k >= N_G * nf:
        j = (k - N_G * nf) // 2
        r = p.swit[j]
        n = p.inertia.shape[0]
        e = p.elem[r]
        if e[E_LAW] == SPRING_CURVE:   # onto the next segment, below or above (no event: not a mode of interest)
            m[nf + j] += -1 if (k - N_G * nf) % 2 == 0 else 1
            return 0
        if _lash_msl(p, r):   # MSL's damping law: its kinks change the mode silently; the edges are events
            old = m[nf + j]
            new = _lash_msl_update(p, r, x, n, old, (k - N_G * nf) % 2)
            if new == LASH_GAP:   # at the edge: what the spring holds is ~0 (as below)
                x[2 * n + r] += spring_energy(p, r, x, n, m)
            m[nf + j] = new
            if old == LASH_GAP or new == LASH_GAP:
                record(log, t, EV_CONTACT if new != LASH_GAP else EV_SEPARATE, nf + j)
            return 0
        side = LASH_UPPER if (k - N_G * nf) % 2 == 0 else LASH_LOWER   # phi - b/2: the gap's upper side
        w_rel = _speed(x, n, e[E_B]) - _speed(x, n, e[E_A])
        if m[nf + j] == LASH_GAP and ((side == LASH_UPPER and w_rel > 0.0) or (side == LASH_LOWER and w_rel < 0.0)):
            m[nf + j] = side
            record(log, t, EV_CONTACT, nf + j)
        elif m[nf + j] == side:
            # the energy left in the spring (a damped contact separates before the edge) is lost: the
            # massless spring relaxes through its damper
            x[2 * n + r] += spring_energy(p, r, x, n, m)
            m[nf + j] = LASH_GAP
            record(log, t, EV_SEPARATE, nf + j)
        else:
            return 0
        # the torque of a damped contact steps at impact: a stuck element may have to break away now (its
        # break-away function starts the next step beyond zero, which is no crossing)
        settle(t, x, m, p, log, m.copy())
        return 0
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
