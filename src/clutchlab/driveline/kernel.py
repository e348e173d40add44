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
from numba.core import types

from ..numerics import dispatch
from ..numerics.borrow import ByRef, borrow, shaped
from ..numerics.core import WAYPOINT_ALWAYS, record
from ..numerics.interp import bracket, bracket_range, grid_waypoint
from ..numerics.layout import indices, slots
from ..numerics.outline import log_type, outlined
from ..numerics.rosenbrock import lu_factor, lu_solve

#: an int64 zero: numba types a literal ``0`` (argument or first value of a counter) as ``Literal[int](0)`` and
#: compiles every callee once more for it, with all of that callee's callees linked in (issue #30's first compilation)
_ZERO = np.int64(0)

# Every integer below is generated from a declaration (:mod:`clutchlab.numerics.layout`): the position of a name
# in its tuple, or an offset of consecutive slots.
#: element kinds (DrivelineParams.elem[:, E_KIND])
ELEMENT_KINDS = ("spring", "friction", "source", "gear", "motion", "converter")
K_SPRING, K_FRICTION, K_SOURCE, K_GEAR, K_MOTION, K_CONVERTER = indices(
    ELEMENT_KINDS, "spring", "friction", "source", "gear", "motion", "converter")
#: friction laws: cgeo * fn * mu(|w|); table(|w|) (bearing friction); freewheel; a clutch model with states of its
#: own (its sliding torque and static limit set by the model's hooks before each evaluation of the network:
#: :func:`set_external`, :mod:`clutchlab.driveline.wet`)
FRICTION_LAWS = ("clutch", "table", "oneway", "external")
LAW_CLUTCH, LAW_TABLE, LAW_ONEWAY, LAW_EXTERNAL = indices(FRICTION_LAWS, "clutch", "table", "oneway", "external")
#: spring laws
SPRING_LAWS = ("linear", "curve", "backlash")
SPRING_LINEAR, SPRING_CURVE, SPRING_BACKLASH = indices(SPRING_LAWS, "linear", "curve", "backlash")
#: torque sources (K_SOURCE): a signal, or an engine (a torque map over speed and throttle plus an idle-speed PI
#: controller whose integral is a state of the network: ``x[2 n + ne + elem[r, E_STATE]]``), or a torque that
#: depends on the flange's speed (MSL ``Linear-``, ``QuadraticSpeedDependentTorque``: :func:`speed_torque`)
SOURCE_LAWS = ("signal", "engine", "speed")
SOURCE_SIGNAL, SOURCE_ENGINE, SOURCE_SPEED = indices(SOURCE_LAWS, "signal", "engine", "speed")
#: motion sources (K_MOTION): prescribed speed or position of flange b
MOTION_LAWS = ("speed", "position")
MOTION_SPEED, MOTION_POSITION = indices(MOTION_LAWS, "speed", "position")
# modes of a switched spring (after the friction elements' in the mode vector): a backlash in its gap, or in
# contact beyond either side; a curve spring: the segment of its curve it is on (0 below the first point, i
# between points i-1 and i, m above the last of m points)
LASH_VALUES = ("gap", "upper", "lower")
LASH_GAP, LASH_UPPER, LASH_LOWER = indices(LASH_VALUES, "gap", "upper", "lower")
# a backlash's damping law (``elem[r, E_AUX]``): Kelvin-Voigt in contact, or MSL ``ElastoBacklash``'s, whose contact
# has two more modes per side (odd: upper, even: lower): the damping torque limited to the spring torque
# (tau = 2 tau_c) and the contact unloaded (tau = 0, where tau_c + tau_d would pull)
LASH_DAMPING_LAWS = ("kelvin_voigt", "msl")
LASH_KELVIN_VOIGT, LASH_MSL = indices(LASH_DAMPING_LAWS, "kelvin_voigt", "msl")
LASH_MSL_VALUES = LASH_VALUES + ("upper_limited", "lower_limited", "upper_released", "lower_released")
LASH_UPPER_LIMITED, LASH_LOWER_LIMITED, LASH_UPPER_RELEASED, LASH_LOWER_RELEASED = indices(
    LASH_MSL_VALUES, "upper_limited", "lower_limited", "upper_released", "lower_released")
# (Kelvin-Voigt's contact has the unloaded modes too: a damped contact separates beyond its edge, moving back, and
# is released there until the deflection reaches the edge or its torque pushes again; it never enters the limited
# ones, which keep their names)
LASH_KV_VALUES = LASH_MSL_VALUES
# modes of a friction element (index into MODE_VALUES); MSL's codes are MODE_CODES
MODE_VALUES = ("stuck", "forward", "backward", "free")
STUCK, FORWARD, BACKWARD, FREE = indices(MODE_VALUES, "stuck", "forward", "backward", "free")
MODE_CODES = np.array([0.0, 1.0, -1.0, 2.0])  # MSL PartialFriction: Stuck 0, Forward 1, Backward -1, Free 2
# events: named for the mode entered (friction and lossy gears: stick, forward, backward; a lossy gear's driving
# flange: a_drives, b_drives), or for a backlash closing or opening its gap
EVENTS = ("stick", "forward", "backward", "free", "contact", "separate", "a_drives", "b_drives")
EV_STICK, EV_FORWARD, EV_BACKWARD, EV_FREE, EV_CONTACT, EV_SEPARATE, EV_DRIVE_A, EV_DRIVE_B = indices(
    EVENTS, "stick", "forward", "backward", "free", "contact", "separate", "a_drives", "b_drives")
_EVENT_OF_MODE = np.array([EV_STICK, EV_FORWARD, EV_BACKWARD, EV_FREE])
#: signal kinds (rows of ``DrivelineParams.signals``, ``N_SIG`` wide: the kind and up to eight parameters); an
#: input is a network input: ``[k, its number j, the number of inputs nu]``, held at ``data[-nu + j]``
SIGNAL_KINDS = ("const", "step", "ramp", "sine", "table", "sampled", "pulse", "trapezoid", "exponentials",
                "product", "input")
(SIG_CONST, SIG_STEP, SIG_RAMP, SIG_SINE, SIG_TABLE, SIG_SAMPLED, SIG_PULSE, SIG_TRAPEZOID, SIG_EXPONENTIALS,
 SIG_PRODUCT, SIG_INPUT) = indices(
    SIGNAL_KINDS, "const", "step", "ramp", "sine", "table", "sampled", "pulse", "trapezoid", "exponentials",
    "product", "input")
N_SIG = slots(("kind", 1), ("parameters", 8)).total
#: columns of ``elem`` (ints): "aux" is a curve's kind (0 linear, 1 pchip) or an engine map's throttle points;
#: "mode" the element's index in m; "state" that of a controller state; "support" a gear's or a torque converter's
#: support (housing)
#: inertia, -1 the ground; "heat" the thermal mass (row of ``thermal``) its losses flow into, -1 none; "fade" and
#: "fade_n" a friction element's factor over that mass's temperature: its table's start in ``data`` (-1 none) and
#: its number of rows (temperatures, then factors; :func:`fade_factor`) (a torque converter's table: E_TABLE,
#: E_TABLE_N drive rows, E_AUX coast rows, :func:`converter_torques`); "spread" a gear's part in the initial
#: speeds left out of the description (:func:`derive_speeds`): 0 none, +d its flange b's speed derived from flange
#: a's, -d flange a's from flange b's, d the derived flange's depth below the speed it follows; "spread_support" 1
#: where the gear's support speed enters that derivation (given in the description), 0 where it is taken as rest;
#: "map_t" a friction element's number of temperatures of a friction map mu(|w|, T) read at its heat port's
#: temperature (:func:`friction_map`), 0 for a characteristic of |w| alone
ELEM_COLUMNS = ("kind", "a", "b", "law", "signal", "table", "table_n", "aux", "mode", "state", "support", "heat",
                "fade", "fade_n", "spread", "spread_support", "map_t")
(E_KIND, E_A, E_B, E_LAW, E_SIGNAL, E_TABLE, E_TABLE_N, E_AUX, E_MODE, E_STATE, E_SUP, E_HEAT, E_FADE,
 E_FADE_N, E_SPREAD, E_SPREAD_SUP, E_MAP_T) = indices(ELEM_COLUMNS, "kind", "a", "b", "law", "signal", "table",
                                                      "table_n", "aux", "mode", "state", "support", "heat", "fade",
                                                      "fade_n", "spread", "spread_support", "map_t")
N_ELEM = len(ELEM_COLUMNS)
#: columns of ``thermal`` (one row per thermal mass, MSL ``Thermal.HeatTransfer.Components.HeatCapacitor`` with a
#: ``ThermalConductor`` to a ``FixedTemperature``): heat capacity [J/K], conductance to its ambient [W/K], the
#: ambient's temperature [degC], its initial temperature [degC], and the position of its temperature in the state
#: vector (its heat given to the ambient [J] follows it), a whole number held as a float
THERMAL_COLUMNS = ("capacity", "conductance", "ambient", "initial", "state")
T_CAP, T_COND, T_AMB, T_INIT, T_STATE = indices(THERMAL_COLUMNS, "capacity", "conductance", "ambient", "initial",
                                                "state")
N_THERMAL = len(THERMAL_COLUMNS)
#: states of a thermal mass, from its ``state`` column on: (quantity, unit, description of mass ``{}``), declared
#: once (the network's state columns are generated from it)
THERMAL_STATE_DECL = (("temperature", "C", "temperature of the thermal mass {}"),
                      ("heat_out", "J", "heat {} gave its ambient since the start"))
THERMAL_STATES = tuple(q for q, _unit, _what in THERMAL_STATE_DECL)
#: outputs of a thermal mass, in :func:`driveline_outputs`' order (as :data:`THERMAL_STATE_DECL`)
THERMAL_OUTPUT_DECL = (("loss_power", "W", "power the elements heating {} dissipate into it"),
                       ("heat_flow", "W", "heat flow from {} to its ambient"))
TS_TEMP, TS_OUT = indices(THERMAL_STATES, "temperature", "heat_out")
#: columns of ``links`` (one row per thermal conductor between two masses, MSL ``ThermalConductor``): the rows of
#: its masses in ``thermal`` (whole numbers held as floats) and its conductance [W/K]
LINK_COLUMNS = ("a", "b", "conductance")
L_A, L_B, L_COND = indices(LINK_COLUMNS, "a", "b", "conductance")
N_LINK = len(LINK_COLUMNS)
#: columns of ``coef`` (floats), their meaning by the element's kind: a spring-damper (a curve: its points at
#: E_TABLE; a backlash: its gap); a friction element (a table: speed grid | values at E_TABLE; with a normal-force
#: curve of E_AUX points: its data offset and lift-off input; the factor on its friction coefficient); a gear,
#: w_a = ratio * w_b (its loss table, MSL lossTable: E_TABLE_N rows of |w_a|, eta_mf1, eta_mf2, tau_bf1, tau_bf2,
#: stored column by column at E_TABLE); a torque converter's factor on its K (its tables at E_TABLE);
#: an engine's idle controller: set speed [rad/s], gains [N m s/rad], [N m/rad], torque limit [N m]
COEF_COLUMNS = {
    "spring": ("stiffness", "damping", "phi0", "gap"),
    "friction": ("fn_max", "cgeo", "peak", "ncurve", "liftoff", "mu_scale", "levels", "wear0", "wear_rate", "expansion",
                 "t_ref", "dog"),
    "gear": ("ratio",),
    "converter": ("k_scale",),
    "engine": ("idle_speed", "idle_kp", "idle_ki", "idle_max"),
    "speed_torque": ("tau_nominal", "w_nominal", "exponent", "same_direction"),
}
C_STIFF, C_DAMP, C_PHI0, C_GAP = indices(COEF_COLUMNS["spring"], "stiffness", "damping", "phi0", "gap")
C_FN_MAX, C_CGEO, C_PEAK, C_NCURVE, C_LIFTOFF, C_MU_SCALE = indices(
    COEF_COLUMNS["friction"], "fn_max", "cgeo", "peak", "ncurve", "liftoff", "mu_scale")
#: an E-clutch whose working point moves (:func:`shifted_curve`): its curve's number of shift levels (0: a plain
#: normal-force curve), its initial facing wear [m], its wear per joule it dissipates [m/J], its stack's thermal
#: expansion [m/K] and the temperature [degC] at which its curve is the model's
C_LEVELS, C_WEAR0, C_WEAR_RATE, C_EXPANSION, C_T_REF = indices(
    COEF_COLUMNS["friction"], "levels", "wear0", "wear_rate", "expansion", "t_ref")
#: a synchroniser (a cone clutch and a dog clutch on one sleeve): its dogs' torque capacity [N m], its static limit
#: while the sleeve is pushed in (0: a plain clutch, whose static limit is ``peak`` times its sliding torque at rest)
C_DOG = indices(COEF_COLUMNS["friction"], "dog")
C_RATIO = indices(COEF_COLUMNS["gear"], "ratio")
#: a torque converter's factor on its capacity factors K (both tables): a looser (> 1) or tighter converter
C_K_SCALE = indices(COEF_COLUMNS["converter"], "k_scale")
C_IDLE_W, C_IDLE_KP, C_IDLE_KI, C_IDLE_MAX = indices(
    COEF_COLUMNS["engine"], "idle_speed", "idle_kp", "idle_ki", "idle_max")
#: a speed-dependent torque source: its nominal torque [N m] at its nominal speed [rad/s], the exponent of the speed
#: (1 linear, 2 quadratic) and 1 where the torque keeps its direction in both directions of rotation (MSL's
#: ``TorqueDirection``), 0 where it turns with the speed
C_TAU_NOM, C_W_NOM, C_EXPONENT, C_SAME_DIRECTION = indices(
    COEF_COLUMNS["speed_torque"], "tau_nominal", "w_nominal", "exponent", "same_direction")
N_COEF = max(len(columns) for columns in COEF_COLUMNS.values())
# modes of a lossy gear (after the switched springs' in the mode vector; MSL LossyGear): stuck (locked), or rolling
# forward (w_a > 0) or backward, with the flange that drives (MSL's quadrants: tau_eta >= 0 forward is quadrant 1,
# flange a drives; < 0 quadrant 2, b drives; backward tau_eta >= 0 quadrant 4, b drives; < 0 quadrant 3, a drives)
GEAR_VALUES = ("stuck", "forward_a_drives", "forward_b_drives", "backward_a_drives", "backward_b_drives")
GEAR_STUCK, GEAR_FWD_A, GEAR_FWD_B, GEAR_BWD_A, GEAR_BWD_B = indices(
    GEAR_VALUES, "stuck", "forward_a_drives", "forward_b_drives", "backward_a_drives", "backward_b_drives")
GEAR_CODES = np.array([0.0, 1.0, 1.0, -1.0, -1.0])   # MSL LossyGear.mode: Stuck 0, Forward 1, Backward -1
# switching functions: six per friction element, then four per switched spring (``swit``: backlash and curves),
# then four per lossy gear (``lossy``: its stick or break-away function, its driving flange's, its turning point, its
# band's pieces or its loss table's rows)
FRICTION_SWITCHING = ("stick", "break", "normal", "turn", "near", "row")
G_STICK, G_BREAK, G_NORMAL, G_TURN, G_NEAR, G_ROW = indices(FRICTION_SWITCHING, "stick", "break", "normal", "turn",
                                                            "near", "row")
N_G = len(FRICTION_SWITCHING)
#: how a network's layout names each of them (``<element>.<name>``) and the way the core reads its crossing (-1/1:
#: falling/rising, 0: either, -2: falling with a second look at a turning point's root, -3/4: a waypoint falling/either
#: way), in the order of :data:`FRICTION_SWITCHING` (and so for :data:`GEAR_LAYOUT`, :data:`ENGINE_LAYOUT`)
FRICTION_LAYOUT = (("stick", -2), ("breakaway", -2), ("normal", 0), ("turn", 1), ("near", -3), ("row", 4))
#: a lossy gear's: its stick or break-away function, its driving flange's, its turning point, and (stuck) the piece
#: of its band (a waypoint where the torque it carries passes zero, its band's corner without bearing friction) or
#: (rolling) of its loss table (a waypoint at each speed row, :func:`gear_row`)
GEAR_SWITCHING = ("stick_or_break", "driving_flange", "turn", "piece")
N_GEAR_G = len(GEAR_SWITCHING)
GEAR_LAYOUT = (("stick", -2), ("quadrant", -1), ("turn", 1), ("piece", 4))
#: an engine's, after the torque converters' (waypoints either way, :func:`engine_corners`): the corners of its map
#: over its speed and over its throttle, and the edges of its idle controller's clip
ENGINE_SWITCHING = ("speed_row", "throttle_row", "idle_clip")
N_ENGINE_G = len(ENGINE_SWITCHING)
ENGINE_LAYOUT = tuple((name, 4) for name in ENGINE_SWITCHING)
GG_BREAK, GG_FLANGE, GG_TURN, GG_PIECE = indices(GEAR_SWITCHING, "stick_or_break", "driving_flange", "turn", "piece")
#: switching functions per switched spring (backlash, curve spring): its two edges (or segment ends), the turning
#: points of a backlash's deflection in its gap or of its contact's torque near separation (G_LASH_TURN), and in
#: contact the contact's torque less :data:`NEAR_SEPARATION` of the torques on its flanges (G_LASH_NEAR, a waypoint;
#: in the gap, the deflection from the gap's centre: a waypoint there, either way)
SPRING_SWITCHING = ("upper_edge", "lower_edge", "turn", "near")
N_SW = len(SPRING_SWITCHING)
#: their names and directions, by the spring's law: a backlash's edges fall through zero and get the core's second
#: look at the root of its turning point (rising: in the gap towards the nearer edge, in contact the contact torque's
#: minimum near separation), -2, so a touch of an edge or a separation within a step is located; its contact coming
#: near separation, and in the gap its centre, are waypoints either way that a later event does not skip
#: (WAYPOINT_ALWAYS).  A curve spring's segment ends fall through zero; its third and fourth are unused
BACKLASH_LAYOUT = (("gap_upper", -2), ("gap_lower", -2), ("turn", 1), ("near", WAYPOINT_ALWAYS))
CURVE_LAYOUT = (("segment_below", -1), ("segment_above", -1), ("turn", -1), ("near", -3))
G_LASH_TURN, G_LASH_NEAR = indices(SPRING_SWITCHING, "turn", "near")
# A sliding element's (and a rolling lossy gear's) turning function is its relative acceleration towards its
# sliding direction at every speed (G_TURN, GG_TURN; rising through zero: a minimum of its speed), so that a dip
# through zero shorter than a step is not stepped over: a brake decelerating a stuck group from 0.08 rad/s under
# ramps, whose speed is a parabola Dormand-Prince integrates exactly, was stepped from 0.08 rad/s across a 78 ms dip
# to -0.0096 rad/s and back, the brake driving the group backward (the thorough profile's seed 1407), where the
# function watched only speeds below 1e-2 of the largest.  It is continuous: a function that read 1 while fast and
# speeding up jumped from about 0 to 1 at its root, which the Illinois iteration brackets only by bisection after 40
# secant steps (numerics.core._illinois): CoupledClutches took 2,079 right-hand sides where it takes 1,279 now
#: relative size of rounding in the torques of the constraint set (the thresholds of the stick/slip decisions
#: and of the switching functions that watch them, which must agree: after a decision every function watching it
#: is > 0, so that its next crossing is seen)
NOISE = 1e-12


class DrivelineParams(NamedTuple):
    """Packed parameters of a driveline network (SI: kg m^2, N m/rad, N m s/rad, N, rad/s).

    Built by :func:`clutchlab.driveline.network.pack`.  ``inertia``: the inertias [kg m^2];
    ``elem`` (int64, one row per element, columns ``E_*``) and ``coef`` (float, ``C_*``): the
    elements; ``signals`` (one row per signal: kind, then up to ``N_SIG - 1`` parameters) and ``data`` (tables:
    friction characteristics, spring curves and signal tables); ``fric`` (int64): the element row of
    each friction element; ``cons``: of each constraint (gears and motion sources, always held);
    ``swit``: of each switched spring (backlash, curve spring; its place in the mode vector is
    ``elem[r, E_MODE]``); ``lossy``: of each gear with losses (MSL ``LossyGear``; its mode at ``elem[r, E_MODE]``);
    ``check``: ``[on, energy tolerance, shifted]``, the invariants checked at every accepted step
    (:func:`check_invariants`), and the number of E-clutches whose working point moves (:func:`_shifted`);
    ``work`` and ``iwork`` (int64, the pivots of the constraint set's factorisation):
    scratch of the hooks (per run); ``thermal`` (columns ``T_*``): the thermal masses the elements' losses heat
    (``elem[r, E_HEAT]``), ``links`` (``L_*``): the thermal conductors between them (:func:`thermal_rates`).
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
    check: np.ndarray
    thermal: np.ndarray
    links: np.ndarray


# ----------------------------------------------------------------- signals
@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _table(data, start, n, t):
    """Piecewise-linear table ``data[start:start+n]`` (times), ``data[start+n:start+2n]`` (values), held outside."""
    if n == 1:
        return data[start + 1]
    lo, w = bracket(data[start:start + n], t)
    return data[start + n + lo] + w * (data[start + n + lo + 1] - data[start + n + lo])


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
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


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _corners(sig):
    """Offsets [s] of a periodic signal's corners within its period: a pulse's end of the on-part (the width,
    a fraction, times the period); a trapezoid's ends of rising, width and falling (MSL ``T_rising``,
    ``T_width``, ``T_falling``)."""
    if int(sig[0]) == SIG_PULSE:
        tw = sig[2] * sig[3]
        return tw, tw, tw
    return sig[2], sig[2] + sig[3], sig[2] + sig[3] + sig[4]


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
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


@numba.njit(cache=True, nogil=True, _nrt=False)
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
    if kind == SIG_INPUT:   # held by the host (:func:`hold_inputs`): no break, no rate
        return data[data.shape[0] - int(sig[2]) + int(sig[1])]
    return _table(data, int(sig[1]), int(sig[2]), t)


@numba.njit(cache=True, nogil=True, _nrt=False)
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


@numba.njit(cache=True, nogil=True, _nrt=False)
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


@numba.njit(cache=True, nogil=True, _nrt=False)
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


@numba.njit(cache=True, nogil=True, _nrt=False)
def _jumps_at(p, s, t):
    """True if signal ``s`` has a jump or a kink at ``t`` (its next break after ``t`` less a rounding is ``t``)."""
    return signal_break(p.signals[s], p.data, t - 1e-12 * max(1.0, abs(t))) == t


@numba.njit(cache=True, nogil=True, _nrt=False)
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


@numba.njit(cache=True, nogil=True, _nrt=False)
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
@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _characteristic(data, start, n, w):
    """Table value at ``w >= 0``: linear between points, extrapolated from the last two (MSL's ``LastTwoPoints``) but
    never below 0 (every row is >= 0, checked when the element is built): a friction coefficient or a bearing
    friction torque extrapolated below 0 turned a brake into a motor -- 10 N m on an inertia at 100 rad/s with ``mu``
    0.5 at rest and 0.3 at 10 rad/s drove it to 117 rad/s in 1 s, #30."""
    if n == 1 or w <= data[start]:
        return data[start + n]
    if w >= data[start + n - 1]:
        x0, x1 = data[start + n - 2], data[start + n - 1]
        y0, y1 = data[start + 2 * n - 2], data[start + 2 * n - 1]
        return max(y1 + (y1 - y0) * (w - x1) / (x1 - x0), 0.0)
    return _table(data, start, n, w)


@numba.njit(cache=True, nogil=True, _nrt=False)
def friction_map(data, start, nw, nt, w, temp):
    """Friction coefficient [-] of a map ``mu(|w|, T)`` at the relative speed ``w`` [rad/s] and the temperature
    ``temp`` [degC] of the thermal mass the element's losses heat: a friction map ``mu(v, T)`` identified on the wet
    clutch's bench (seed 001, Sec. 5: :class:`clutchlab.wet.friction.FrictionMap`, its slip velocities over the
    element's radius), bilinear between its nodes and constant beyond them, as the map itself is read.  Layout at
    ``data[start:]``: ``nw >= 2`` speeds (increasing, the first 0), ``nt`` temperatures (increasing), then ``nt``
    rows of ``nw`` values."""
    iw, fw = bracket_range(data, start, start + nw, w)
    iw -= start
    q = start + nw
    v = q + nt
    a = data[v + iw] + fw * (data[v + iw + 1] - data[v + iw])
    if nt == 1:
        return a
    it, ft = bracket_range(data, q, q + nt, temp)
    it -= q
    j0 = v + it * nw + iw
    j1 = j0 + nw
    a = data[j0] + fw * (data[j0 + 1] - data[j0])
    b = data[j1] + fw * (data[j1 + 1] - data[j1])
    return a + ft * (b - a)


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _corner(data, start, first, nrows, clamp, i):
    """Corner ``i`` of :func:`row_waypoint`: the rows ``data[start + first:start + first + nrows]``, then ``clamp``."""
    return data[start + first + i] if i < nrows else clamp


@numba.njit(cache=True, nogil=True, _nrt=False)
def row_waypoint(data, start, first, nrows, clamp, s):
    """The waypoint function [-] of a law over a speed ``s >= 0`` [rad/s] whose slope jumps at its corners (the rows
    ``data[start + first:start + first + nrows]``, increasing, then ``clamp`` where it is finite, beyond them): zero
    at each corner and nowhere else, of alternating sign from one piece to the next (as a torque converter's,
    :func:`converter_piece`), so that a step ends just past each corner and the error follows the tolerance there.
    Piece ``k`` between corners ``lo`` and ``hi``: ``(-1)^k (s - lo)(hi - s)/(hi - lo)^2``; the first (from 0, no
    corner: a sliding element's speed there is its stick event) ``(hi - s)/hi``; beyond the last ``(-1)^k (s -
    lo)/s``.  1 (no waypoint) for a law without corners."""
    nc = nrows + (1 if clamp < np.inf else 0)
    if nc <= 0:
        return 1.0
    k = 0
    while k < nc and _corner(data, start, first, nrows, clamp, k) <= s:
        k += 1
    if k == 0:
        hi = _corner(data, start, first, nrows, clamp, 0)
        return (hi - s) / hi
    lo = _corner(data, start, first, nrows, clamp, k - 1)
    if k == nc:
        v = (s - lo) / s
    else:
        hi = _corner(data, start, first, nrows, clamp, k)
        v = (s - lo) * (hi - s) / ((hi - lo) * (hi - lo))
    return v if k % 2 == 0 else -v


@numba.njit(cache=True, nogil=True, _nrt=False)
def friction_row(p, r, w_abs):
    """The waypoint function [-] of sliding friction element row ``r`` at ``|w_rel| = w_abs`` [rad/s]
    (:func:`row_waypoint`): the corners of its sliding torque over the speed, where the slope jumps.  A table
    (:func:`_characteristic`): its first row where it is above 0 (held below it), its inner rows (linear between
    them) and the speed at which its extrapolation beyond the last two rows reaches 0 (held at 0 beyond it); a
    friction map (:func:`friction_map`): its speed nodes but the first (0; bilinear, held beyond the last); an
    external law (a wet clutch, an EMTC coupling: its own model), a constant or a two-row rising table: none (1).
    Until the sixty-second session a step spanned a corner and the error did not follow the tolerance there (a
    clutch with four rows sliding to lock-up: 1.1e-4 of the speeds' range at rtol 1e-6, #30)."""
    if p.elem[r, E_LAW] == LAW_EXTERNAL:
        return 1.0
    start, n = p.elem[r, E_TABLE], p.elem[r, E_TABLE_N]
    if p.elem[r, E_MAP_T] > 0:
        return row_waypoint(p.data, start, 1, n - 1, np.inf, w_abs)
    if n <= 1:
        return 1.0
    first = 0 if p.data[start] > 0.0 else 1
    clamp = np.inf
    y0, y1 = p.data[start + 2 * n - 2], p.data[start + 2 * n - 1]
    if y1 < y0:   # (falls to 0 beyond the last row, held there)
        x0, x1 = p.data[start + n - 2], p.data[start + n - 1]
        clamp = x1 + y1 * (x1 - x0) / (y0 - y1)
    return row_waypoint(p.data, start, first, n - 1 - first, clamp, w_abs)


@numba.njit(cache=True, nogil=True, _nrt=False)
def friction_temperature_row(p, r):
    """The waypoint function [-] of friction element row ``r`` over the temperature [degC] of the thermal mass its
    losses heat (:func:`grid_waypoint`: zero at each node, of alternating sign): its fade table's rows
    (``mu_temperature``, :func:`fade_factor`: linear between them, held beyond) times a friction map's temperature
    nodes (:func:`friction_map`: bilinear, held beyond).  1 without a heat port or either law.  Where the temperature
    crosses a row the sliding torque's slope jumps, as at a friction table's rows over the speed
    (:func:`friction_row`)."""
    if p.elem[r, E_HEAT] < 0 or p.elem[r, E_LAW] == LAW_EXTERNAL:
        return 1.0
    temp = temperatures(p)[p.elem[r, E_HEAT]]
    v = 1.0
    if p.elem[r, E_FADE] >= 0:
        v *= grid_waypoint(p.data, p.elem[r, E_FADE], p.elem[r, E_FADE_N], temp)
    if p.elem[r, E_MAP_T] > 1:
        v *= grid_waypoint(p.data, p.elem[r, E_TABLE] + p.elem[r, E_TABLE_N], p.elem[r, E_MAP_T], temp)
    return v


@numba.njit(cache=True, nogil=True, _nrt=False)
def gear_row(p, r, w_abs):
    """The waypoint function [-] of rolling lossy gear row ``r`` at ``|w_a| = w_abs`` [rad/s] (:func:`row_waypoint`):
    its loss table's speed rows where its law's slope jumps: the first where it is above 0 (held below it) and the
    inner ones (linear between them); 1 for a table of one row.  (An extrapolation beyond the last row that reaches
    an efficiency of 1 or a bearing friction of 0 is held there: a corner not watched.)"""
    start, n = p.elem[r, E_TABLE], p.elem[r, E_TABLE_N]
    if n <= 1:
        return 1.0
    first = 0 if p.data[start] > 0.0 else 1
    return row_waypoint(p.data, start, first, n - 1 - first, np.inf, w_abs)


@numba.njit(cache=True, nogil=True, _nrt=False)
def friction_torque(p, r, t, w_abs):
    """Sliding torque magnitude [N m] of friction element row ``r`` at relative speed ``|w|`` and time ``t``.

    Clutch and brake (MSL ``Clutch``/``Brake``): ``cgeo * fn * mu(|w|)`` with ``fn = fn_max * f(t)`` and
    ``mu`` the characteristic times ``mu_scale``; bearing friction (``BearingFriction``): the table itself; a
    one-way clutch (MSL ``OneWayClutch``: a freewheel in parallel with a clutch): its clutch's
    ``cgeo * max(fn, 0) * mu(|w|)`` while it overruns (none without a normal force).  At ``w = 0`` this is
    ``tau0``; the static limit is ``peak * tau0``.
    """
    law = p.elem[r, E_LAW]
    if law == LAW_EXTERNAL:
        return external_value(p, p.elem[r, E_AUX], 0, t)
    if p.elem[r, E_MAP_T] > 0:
        val = _friction_map_outlined(p.data, p.elem[r, E_TABLE], p.elem[r, E_TABLE_N], p.elem[r, E_MAP_T], w_abs,
                                     temperatures(p)[p.elem[r, E_HEAT]])
    else:
        val = _characteristic(p.data, p.elem[r, E_TABLE], p.elem[r, E_TABLE_N], w_abs)
    if law == LAW_TABLE:
        return val
    val *= p.coef[r, C_MU_SCALE]   # (a factor of its own, not in the table: a host or a sweep sets it with mu)
    fn = normal_force(p, r, t)
    if law == LAW_ONEWAY:
        fn = max(fn, 0.0)
    if p.elem[r, E_FADE] >= 0:
        val *= fade_factor(p, r)
    return p.coef[r, C_CGEO] * fn * val


@numba.njit(cache=True, nogil=True, _nrt=False)
def fade_factor(p, r):
    """Factor [-] on the friction of element row ``r`` at the temperature [degC] of the thermal mass its losses heat
    (``mu_temperature``: linear between its rows, held beyond them), read from the temperatures of the network's last
    evaluation (:func:`evaluate_network` keeps them: :func:`temperatures`).  The friction coefficient of a dry
    lining falls as it heats (fade); the factor scales the sliding torque and the static limit alike."""
    return _table(p.data, p.elem[r, E_FADE], p.elem[r, E_FADE_N], temperatures(p)[p.elem[r, E_HEAT]])


@numba.njit(cache=True, nogil=True, _nrt=False)
def _shift_bracket(data, o, nl, s):
    """The levels ``data[o:o+nl]`` (increasing) bracketing the shift ``s`` [m]: ``(i, w)``, ``s`` at ``(1 - w)
    s_i + w s_(i+1)``, held at the ends (:func:`shift_error` ends a run whose shift leaves them)."""
    if nl == 1:
        return 0, 0.0
    i, w = bracket_range(data, o, o + nl, s)
    return i - o, w


@numba.njit(cache=True, nogil=True, _nrt=False)
def shifted_liftoff(data, o, nl, s):
    """Lift-off position [m] of a shifted normal-force curve (:func:`shifted_curve`) at the shift ``s`` [m]: its
    levels' lift-offs, linear between them."""
    i, w = _shift_bracket(data, o, nl, s)
    if nl == 1:
        return data[o + nl]
    return (1.0 - w) * data[o + nl + i] + w * data[o + nl + i + 1]


@numba.njit(cache=True, nogil=True, _nrt=False)
def shifted_curve(data, o, nl, npt, s, u):
    """Normal force [N] of an E-clutch whose working point facing wear and thermal expansion moved by ``s`` [m] (the
    cushion pre-strain's change, ``-w + alpha dT h``: seed 000, Sec. 7, future work iii; :func:`clutchlab.eclutch.
    dynamics.apply_wear_and_expansion`), at the release-bearing position ``u`` [m].

    The table at ``data[o:]`` (:meth:`Driveline.eclutch <clutchlab.driveline.network.Driveline.eclutch>` builds it
    from the axial model's static curves): ``nl`` shifts ``s_i`` (increasing), their lift-off positions ``L_i``,
    the first and the step of a grid of ``npt`` distances to lift-off ``xi_k <= 0`` (the last 0), then for each
    level its force at ``L_i + xi_k``.  Between two levels the lift-off is linear in ``s`` and the force is linear
    in ``s`` at the same distance to lift-off ``u - L(s)``: the curves are interpolated aligned at their lift-offs,
    so the force is 0 exactly beyond ``L(s)`` (where the clutch is free) and the interpolation follows the curve's
    shift along the bearing travel.  Held beyond the grid's ends."""
    i, w = _shift_bracket(data, o, nl, s)
    lift = shifted_liftoff(data, o, nl, s)
    xi0 = data[o + 2 * nl]
    dxi = data[o + 2 * nl + 1]
    q = o + 2 * nl + 2
    z = (u - lift - xi0) / dxi
    if z >= npt - 1:
        return 0.0
    if z <= 0.0:
        k, v = 0, 0.0
    else:
        k = int(z)
        v = z - k
    f0 = data[q + i * npt + k] + v * (data[q + i * npt + k + 1] - data[q + i * npt + k])
    if nl == 1:
        return f0
    f1 = data[q + (i + 1) * npt + k] + v * (data[q + (i + 1) * npt + k + 1] - data[q + (i + 1) * npt + k])
    return (1.0 - w) * f0 + w * f1


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _shifted(p):
    """True if the network has a shifted E-clutch (:func:`shifted_curve`): ``check[2]``, written when the network is
    packed, so that a network without one reads nothing for it (a word of the work array, behind its layout's
    offsets, cost CoupledClutches and the launch 6-7 % at every evaluation)."""
    return p.check[2] > 0.0


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _shift(p, r):
    """The working point's shift [m] of friction element row ``r`` at the network's last evaluation
    (:func:`update_shifts`)."""
    return p.work[_offsets(p).shift + r]


@numba.njit(cache=True, nogil=True, _nrt=False)
def working_point_shift(p, r, x):
    """The working point's shift [m] of the shifted E-clutch at element row ``r`` in the state ``x``
    (:func:`shifted_curve`; seed 000, Sec. 7, future work iii): ``s = -(w0 + k_w E) + e (T - T_ref)``, its facing
    wear growing with the energy ``E`` [J] it dissipated (wear proportional to the friction work: Archard's law at a
    constant friction coefficient, ``k_w`` [m/J]) and its stack expanding ``e`` [m/K] with the temperature ``T``
    [degC] of the thermal mass its losses heat (``T_ref`` without one)."""
    temp = heat_port_temperature(p, r, x, p.coef[r, C_T_REF])
    wear = p.coef[r, C_WEAR0] + p.coef[r, C_WEAR_RATE] * max(x[2 * p.inertia.shape[0] + r], 0.0)
    return -wear + p.coef[r, C_EXPANSION] * (temp - p.coef[r, C_T_REF])


@numba.njit(cache=True, nogil=True, _nrt=False)
def update_shifts(p, x):
    """Each shifted E-clutch's working point at the state ``x`` (:func:`working_point_shift`), kept for the
    network's evaluations at that state (every evaluation of the network starts with this)."""
    o = _offsets(p).shift
    for k in range(p.fric.shape[0]):
        r = p.fric[k]
        if p.coef[r, C_LEVELS] > 0.0:
            p.work[o + r] = working_point_shift(p, r, x)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _liftoff(p, r):
    """The release-bearing position [m] beyond which friction element row ``r``'s normal-force curve is 0."""
    if p.coef[r, C_LEVELS] > 0.0:
        return _shifted_liftoff_outlined(p.data, np.int64(p.coef[r, C_NCURVE]), np.int64(p.coef[r, C_LEVELS]),
                                         _shift(p, r))
    return p.coef[r, C_LIFTOFF]


@numba.njit(cache=True, nogil=True, _nrt=False)
def normal_force(p, r, t):
    """Normal force [N] of friction element row ``r``: ``fn_max * f(t)`` (``fn_max`` alone without a signal);
    with a normal-force curve (``E_AUX`` points, an E-clutch's static curve), ``fn_max * curve(f(t))``:
    the signal is then the actuator input (the release bearing position [m]); a curve whose working point wear
    and thermal expansion move (``C_LEVELS`` levels) at its shift (:func:`shifted_curve`)."""
    f = 1.0 if p.elem[r, E_SIGNAL] < 0 else signal_at(p, p.elem[r, E_SIGNAL], t)
    if p.elem[r, E_AUX] > 0 and p.elem[r, E_LAW] == LAW_CLUTCH:
        if p.coef[r, C_LEVELS] > 0.0:
            f = _shifted_curve_outlined(p.data, np.int64(p.coef[r, C_NCURVE]), np.int64(p.coef[r, C_LEVELS]),
                                        p.elem[r, E_AUX], _shift(p, r), f)
        else:
            f = _table(p.data, int(p.coef[r, C_NCURVE]), p.elem[r, E_AUX], f)
    return p.coef[r, C_FN_MAX] * f


@numba.njit(cache=True, nogil=True, _nrt=False)
def _is_free(p, r, t):
    """A clutch or brake is free when its normal force is negative, or zero and not rising (a force that
    leaves zero upwards at ``t`` engages now: its switching function starts on zero, which is no crossing).
    A one-way clutch is never free (its freewheel locks whatever its clutch's force)."""
    if p.elem[r, E_LAW] != LAW_CLUTCH:
        return False
    if p.elem[r, E_AUX] > 0:   # a normal-force curve: free beyond its lift-off input, or at it and not coming back
        u = signal_at(p, p.elem[r, E_SIGNAL], t)
        lift = _liftoff(p, r)
        if u != lift:
            return u > lift
        rate, _d2 = signal_rates(p.signals[p.elem[r, E_SIGNAL]], p.data, t)
        return rate >= 0.0
    fn = normal_force(p, r, t)
    if fn != 0.0:
        return fn < 0.0
    if p.elem[r, E_SIGNAL] < 0:
        return True
    rate, _d2 = signal_rates(p.signals[p.elem[r, E_SIGNAL]], p.data, t)
    return p.coef[r, C_FN_MAX] * rate <= 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def static_limit(p, r, t):
    """Static limit ``peak * tau0`` [N m] of friction element row ``r`` at time ``t`` (a one-way clutch: its
    clutch's, the most it holds against overrunning).

    A synchroniser (a cone clutch and a dog clutch on one shift sleeve, ``C_DOG`` > 0; docs/driveline.md,
    "Synchronisers"; the seeds do not treat gearboxes): while the sleeve's shift force pushes it towards its gear
    the blocker ring holds the sleeve back as long as the cone slides, with the element's sliding torque
    ``cones mu F R_c / sin(alpha)`` (``cgeo = cones R_c / sin(alpha)``, the normal force the shift force ``F``).
    Where the speeds meet the dogs engage: stuck, it holds up to the dogs' capacity ``C_DOG`` [N m], and at least
    the cone's torque at rest (the cone is still pressed: a static limit below the sliding torque would let the
    element break away into a slip its torque then drives the other way, as a clutch with ``peak < 1``).  (Its
    ``fn_max`` is 1, or -1 for a synchroniser on a sleeve's other side: the shift force is then ``-force``.)  A
    force of zero or less takes the sleeve out: the element is free then, as a clutch without a normal force is
    (:func:`_is_free`), so its limit is never read there.  The sleeve's travel and the dogs' lash take no time."""
    if p.elem[r, E_LAW] == LAW_EXTERNAL:
        return external_value(p, p.elem[r, E_AUX], 1, t)
    if p.coef[r, C_DOG] > 0.0:
        return max(p.coef[r, C_DOG], friction_torque(p, r, t, 0.0))
    return p.coef[r, C_PEAK] * friction_torque(p, r, t, 0.0)


@numba.njit(cache=True, nogil=True, _nrt=False)
def holding_limit(p, r, t, tau):
    """Largest ``|tau|`` [N m] a stuck friction element row ``r`` holds in the direction of ``tau``: its static
    limit; a one-way clutch holds any torque against overrunning (``tau <= 0``) and its clutch's static limit
    (zero without a normal force) for it (``tau > 0``)."""
    if p.elem[r, E_LAW] == LAW_ONEWAY and tau <= 0.0:
        return np.inf
    return static_limit(p, r, t)


# ----------------------------------------------------------------- engines
@numba.njit(cache=True, nogil=True, _nrt=False)
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


@numba.njit(cache=True, nogil=True, _nrt=False)
def engine_corners(p, r, t, x, n):
    """The waypoint functions [-] of engine row ``r`` (:data:`ENGINE_SWITCHING`), where its torque's slope jumps:
    its map's speed nodes (:func:`grid_waypoint` at its crankshaft's speed against its support), its throttle nodes
    (at the throttle signal) and the edges of its idle controller's clip at 0 and ``T_idle,max``
    (``cmd (T_max - cmd)/T_max^2``, ``cmd = kp (w_idle - w) + I``: :func:`engine_torque`; 1 without the controller).
    Until the sixty-second session a step spanned them: an engine on a six-row full-load curve accelerating a damper
    was 6.4e-5 of its speed range off an independent solution at rtol 1e-6 and 2.0e-7 at 1e-9 (#30)."""
    w = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
    start, ns, nt = p.elem[r, E_TABLE], p.elem[r, E_TABLE_N], p.elem[r, E_AUX]
    g_speed = grid_waypoint(p.data, start, ns, w)
    g_throttle = grid_waypoint(p.data, start + ns, nt, signal_at(p, p.elem[r, E_SIGNAL], t)) if nt > 1 else 1.0
    top = p.coef[r, C_IDLE_MAX]
    if top <= 0.0:
        return g_speed, g_throttle, 1.0
    cmd = p.coef[r, C_IDLE_KP] * (p.coef[r, C_IDLE_W] - w) + x[2 * n + p.elem.shape[0] + p.elem[r, E_STATE]]
    return g_speed, g_throttle, cmd * (top - cmd) / (top * top)


@numba.njit(cache=True, nogil=True, _nrt=False)
def engine_torque(p, r, t, x, n):
    """Torque [N m] of engine row ``r`` on its flange, and the rate of its idle controller's integral [N m/s].

    ``T = map(w, throttle(t)) + T_idle`` with ``w = w_b - w_a`` (crankshaft against its support) and the
    idle-speed PI controller ``T_idle = clip(kp (w_idle - w) + I, 0, T_idle_max)``, ``dI/dt = ki (w_idle - w) +
    (ki / kp) (T_idle - kp (w_idle - w) - I)`` (back-calculation anti-windup: the integral tracks the clipped
    output, so the right-hand side is continuous).  The controller only adds torque (it cannot brake the
    engine)."""
    w = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
    thr = signal_at(p, p.elem[r, E_SIGNAL], t)
    tq = engine_map(p.data, p.elem[r, E_TABLE], p.elem[r, E_TABLE_N], p.elem[r, E_AUX], w, thr)
    if p.coef[r, C_IDLE_MAX] <= 0.0:
        return tq, 0.0
    err = p.coef[r, C_IDLE_W] - w
    integral = x[2 * n + p.elem.shape[0] + p.elem[r, E_STATE]]
    cmd = p.coef[r, C_IDLE_KP] * err + integral
    out = min(max(cmd, 0.0), p.coef[r, C_IDLE_MAX])
    # back-calculation anti-windup with the tracking gain ki/kp: the right-hand side stays continuous (a
    # conditional integration would switch on the clip's edge and chatter there: a sliding mode)
    kaw = p.coef[r, C_IDLE_KI] / p.coef[r, C_IDLE_KP] if p.coef[r, C_IDLE_KP] > 0.0 else p.coef[r, C_IDLE_KI]
    return tq + out, p.coef[r, C_IDLE_KI] * err + kaw * (out - cmd)


@numba.njit(cache=True, nogil=True, _nrt=False)
def source_torque(p, r, t, x, n):
    """Torque [N m] a torque source row ``r`` applies to its flange b (reaction on a): its signal, an engine's
    (:func:`engine_torque`) or a speed-dependent torque's (:func:`speed_torque`)."""
    if p.elem[r, E_LAW] == SOURCE_ENGINE:
        tq, _rate = engine_torque(p, r, t, x, n)
        return tq
    if p.elem[r, E_LAW] == SOURCE_SPEED:
        return speed_torque(p, r, _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A]))
    return signal_at(p, p.elem[r, E_SIGNAL], t)


@numba.njit(cache=True, nogil=True, _nrt=False)
def speed_torque(p, r, w):
    """Accelerating torque [N m] of speed-dependent torque source row ``r`` at its flange's speed ``w`` [rad/s]
    against its support (MSL ``Sources.LinearSpeedDependentTorque``, ``QuadraticSpeedDependentTorque``):
    ``tau_nominal |w / w_nominal|^k`` with ``TorqueDirection`` (the same direction both ways round: a fan's load
    with a negative ``tau_nominal`` in positive rotation), else ``tau_nominal sign(w) |w / w_nominal|^k``
    (``tau_nominal w / w_nominal`` for ``k = 1``, ``tau_nominal w |w| / w_nominal^2`` for ``k = 2``); ``k`` 1 or 2."""
    v = abs(w / p.coef[r, C_W_NOM])
    mag = p.coef[r, C_TAU_NOM] * (v if p.coef[r, C_EXPONENT] == 1.0 else v * v)
    if p.coef[r, C_SAME_DIRECTION] != 0.0 or w >= 0.0:
        return mag
    return -mag


# ----------------------------------------------------------------- springs
@numba.njit(cache=True, nogil=True, _nrt=False)
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


@numba.njit(cache=True, nogil=True, _nrt=False)
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


@numba.njit(cache=True, nogil=True, _nrt=False)
def _spring_deflection(p, r, x, n):
    pa = 0.0 if p.elem[r, E_A] < 0 else x[p.elem[r, E_A]]
    pb = 0.0 if p.elem[r, E_B] < 0 else x[p.elem[r, E_B]]
    return pb - pa - p.coef[r, C_PHI0]




@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _lash_side(mode):
    """The side of a backlash's contact mode: 1 upper (odd modes), -1 lower (even), 0 in the gap."""
    return 0.0 if mode == LASH_GAP else (1.0 if mode % 2 == 1 else -1.0)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _lash_msl(p, r):
    """Does backlash row ``r`` follow MSL ``ElastoBacklash``'s damping law (with damping: without, both laws are
    the same spring)?"""
    return p.elem[r, E_AUX] == LASH_MSL and p.coef[r, C_DAMP] > 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
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
    phi = _spring_deflection(p, r, x, n)
    tau_d = p.coef[r, C_DAMP] * (_speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A]))
    law = p.elem[r, E_LAW]
    if law == SPRING_CURVE:
        tc = _segment_value(p.data, p.elem[r, E_TABLE], p.elem[r, E_TABLE_N], p.elem[r, E_AUX], m[p.elem[r, E_MODE]], phi)
        return tc + tau_d, tc
    if law == SPRING_BACKLASH:
        mode = m[p.elem[r, E_MODE]]
        if mode == LASH_GAP:
            return 0.0, 0.0
        tc = p.coef[r, C_STIFF] * (phi - _lash_side(mode) * 0.5 * p.coef[r, C_GAP])
        if mode <= LASH_LOWER:
            return tc + tau_d, tc
        # MSL ElastoBacklash: tau_c + min(tau_c, tau_d) (upper; max below) -- limited: 2 tau_c; released: 0
        return (2.0 * tc if mode <= LASH_LOWER_LIMITED else 0.0), tc
    tc = p.coef[r, C_STIFF] * phi
    return tc + tau_d, tc


@numba.njit(cache=True, nogil=True, _nrt=False)
def _lash_contact(p, r, x, n, s):
    """Backlash row ``r``'s contact on side ``s`` (+1 upper, -1 lower edge): its deflection beyond that edge, ``s (phi
    - s b/2)`` [rad] (> 0 beyond it), and the contact's torque over ``c`` signed the same way, ``s (phi - s b/2 + d/c
    w_rel)`` [rad] (> 0: it pushes; the torque of :func:`spring_torque` in contact, over ``c``).  The one expression
    the switching functions, the separation and the invariant check use."""
    b2 = 0.5 * p.coef[r, C_GAP]
    phi = _spring_deflection(p, r, x, n)
    lag = p.coef[r, C_DAMP] / p.coef[r, C_STIFF] * (_speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A]))
    return s * (phi - s * b2), s * (phi - s * b2 + lag)


@numba.njit(cache=True, nogil=True, _nrt=False)
def spring_energy(p, r, x, n, m):
    """Energy [J] stored in spring-damper row ``r`` (the integral of its elastic torque over the deflection;
    a backlash's in its contact mode ``m``)."""
    phi = _spring_deflection(p, r, x, n)
    law = p.elem[r, E_LAW]
    if law == SPRING_CURVE:
        return _segment_energy(p.data, p.elem[r, E_TABLE], p.elem[r, E_TABLE_N], p.elem[r, E_AUX], m[p.elem[r, E_MODE]], phi)
    if law == SPRING_BACKLASH:
        mode = m[p.elem[r, E_MODE]]
        if mode == LASH_GAP:
            return 0.0
        q = phi - _lash_side(mode) * 0.5 * p.coef[r, C_GAP]
        return 0.5 * p.coef[r, C_STIFF] * q * q
    return 0.5 * p.coef[r, C_STIFF] * phi * phi


# ----------------------------------------------------------------- network evaluation
@numba.njit(cache=True, nogil=True, _nrt=False)
def _speed(x, n, i):
    return 0.0 if i < 0 else x[n + i]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _coefficients(p, r):
    """Flange weights of element row ``r``: its relative speed is ``cb w_b - ca w_a`` (a gear's, against its
    support: ``ratio (w_b - w_s) - (w_a - w_s)``), its torque ``tau`` acts ``+ca tau`` on flange a and ``-cb tau``
    on flange b.  A gear (MSL ``IdealGear``, ``w_a = ratio w_b``): ``ca = 1, cb = ratio``; a motion source:
    ``ca = 0`` (ground); others 1, 1."""
    if p.elem[r, E_KIND] == K_GEAR:
        return 1.0, p.coef[r, C_RATIO]
    if p.elem[r, E_KIND] == K_MOTION:
        return 0.0, 1.0
    return 1.0, 1.0


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _gear_column(data, start, n, col, w):
    """Column ``col`` (1 eta_mf1, 2 eta_mf2, 3 tau_bf1, 4 tau_bf2) of a gear's loss table at ``|w_a| = w``: linear
    between rows, extrapolated from the last two (MSL ``LossyGear``: ``LinearSegments``, ``LastTwoPoints``)."""
    if n == 1 or w <= data[start]:
        return data[start + col * n]
    if w >= data[start + n - 1]:
        x0, x1 = data[start + n - 2], data[start + n - 1]
        y0, y1 = data[start + col * n + n - 2], data[start + col * n + n - 1]
        return y1 + (y1 - y0) * (w - x1) / (x1 - x0)
    lo, wt = bracket(data[start:start + n], w)
    return data[start + col * n + lo] + wt * (data[start + col * n + lo + 1] - data[start + col * n + lo])


#: the smallest mesh efficiency a loss table's extrapolation beyond its last row gives the law [-] (it keeps the law
#: finite in the step that crosses an extrapolated efficiency of 0; the step's end is then a model error,
#: :func:`table_error`)
ETA_MIN = 1e-6


@numba.njit(cache=True, nogil=True, _nrt=False)
def gear_losses(p, r, w_abs):
    """Mesh efficiencies and bearing friction of lossy gear row ``r`` at ``|w_a| = w_abs`` [rad/s] (MSL
    ``LossyGear``): ``(eta_mf1, eta_mf2, tau_bf1, tau_bf2, tau_bf_a)``: efficiency while flange a drives [-], while
    b drives [-], the resultant bearing friction with respect to flange a in those two cases [N m] (absolute
    values), and the bearing friction on flange a's side, ``(tau_bf1 - tau_bf2) / (eta_mf1 - 1/eta_mf2)`` (half of
    ``tau_bf1`` where both efficiencies are 1: MSL's arbitrary split).  Beyond the table's last row, linear from its
    last two rows (MSL) but an efficiency within ``[ETA_MIN, 1]`` and a bearing friction ``>= 0``: a gear never
    generates power."""
    s, n = p.elem[r, E_TABLE], p.elem[r, E_TABLE_N]
    # (every row is within (0, 1] and >= 0, checked when the gear is built; extrapolated beyond the last row the
    # values are kept where a gear can be: an efficiency at most 1 (MSL's LastTwoPoints took a rising one beyond 1,
    # and the gear generated power, #30), a bearing friction at least 0 (MSL's abs turned a falling one around), an
    # efficiency at least ETA_MIN; one extrapolated to 0 or below is a model error, :func:`table_error`)
    eta1 = min(max(_gear_column(p.data, s, n, 1, w_abs), ETA_MIN), 1.0)
    eta2 = min(max(_gear_column(p.data, s, n, 2, w_abs), ETA_MIN), 1.0)
    bf1 = max(_gear_column(p.data, s, n, 3, w_abs), 0.0)
    bf2 = max(_gear_column(p.data, s, n, 4, w_abs), 0.0)
    if abs(eta1 - 1.0) <= 2.2e-16 and abs(eta2 - 1.0) <= 2.2e-16:
        bfa = 0.5 * bf1
    else:
        bfa = (bf1 - bf2) / (eta1 - 1.0 / eta2)
    return eta1, eta2, bf1, bf2, bfa


@numba.njit(cache=True, nogil=True, _nrt=False)
def gear_transfer(p, r, mode, w_abs):
    """Torque law of a rolling lossy gear row ``r`` in ``mode``: ``(f, c)`` with the torque on flange b's inertia
    ``ratio (f T_a - c)`` [N m], ``T_a = -tau`` the torque flange a's side applies to the gear (MSL
    ``flange_a.tau``), from MSL ``LossyGear``'s torque balance ``0 = flange_b.tau + ratio (flange_a.tau -
    tauLoss)`` with the loss torque of its quadrant: forward, flange a driving (quadrant 1, ``tauLoss = (1 - eta_mf1)
    T_a + tau_bf1``): ``f = eta_mf1, c = tau_bf1``; forward, b driving (quadrant 2, ``(1 - 1/eta_mf2) T_a +
    tau_bf2``): ``1/eta_mf2, tau_bf2``; backward, b driving (quadrant 4): ``1/eta_mf2, -tau_bf2``; backward, a
    driving (quadrant 3): ``eta_mf1, -tau_bf1``.  Stuck or ideal: ``1, 0``."""
    eta1, eta2, bf1, bf2, _bfa = gear_losses(p, r, w_abs)
    if mode == GEAR_FWD_A:
        return eta1, bf1
    if mode == GEAR_FWD_B:
        return 1.0 / eta2, bf2
    if mode == GEAR_BWD_B:
        return 1.0 / eta2, -bf2
    if mode == GEAR_BWD_A:
        return eta1, -bf1
    return 1.0, 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def gear_band(p, r, t_a):
    """The loss torques that bound a stuck lossy gear row ``r`` carrying ``T_a`` [N m] on flange a (MSL
    ``LossyGear``, from the table at ``w_a = 0``): ``(tauLossMin_m, tauLossMax_p)``.  It rolls forward when the
    loss torque it holds exceeds ``tauLossMax_p`` (``quadrant1_p`` if ``T_a - tau_bf_a0 > 0`` else
    ``quadrant2_p``) and backward when it falls below ``tauLossMin_m`` (``quadrant4_m`` if ``T_a + tau_bf_a0 > 0``
    else ``quadrant3_m``)."""
    eta1, eta2, bf1, bf2, bfa = gear_losses(p, r, 0.0)
    hi = (1.0 - eta1) * t_a + bf1 if t_a - bfa > 0.0 else (1.0 - 1.0 / eta2) * t_a + bf2
    lo = (1.0 - 1.0 / eta2) * t_a - bf2 if t_a + bfa > 0.0 else (1.0 - eta1) * t_a - bf1
    return lo, hi


@numba.njit(cache=True, nogil=True, _nrt=False)
def gear_margin(p, r, t_a, hold, noise):
    """How far the loss torque ``hold`` [N m] a stuck lossy gear row ``r`` carrying ``T_a`` holds is inside its band
    (:func:`gear_band`, widened by ``noise``): ``(margin, width, direction)``, ``margin <= 0`` where it must roll,
    forward (``direction`` +1) beyond the upper edge, backward (-1) below the lower one.  The one expression both
    the switching function and :func:`settle` use, so that their decisions agree to the last bit."""
    lo, hi = gear_band(p, r, t_a)
    up = (hi + noise) - hold
    down = hold - (lo - noise)
    return min(up, down), hi - lo + noise, 1 if up < down else -1


@numba.njit(cache=True, nogil=True, _nrt=False)
def gear_tau_eta(p, r, mode, t_a, w_abs):
    """MSL ``LossyGear.tau_eta`` [N m] of a rolling gear: ``T_a - tau_bf_a`` forward, ``T_a + tau_bf_a``
    backward; its sign decides the quadrant (which flange drives)."""
    _e1, _e2, _b1, _b2, bfa = gear_losses(p, r, w_abs)
    return t_a - bfa if mode == GEAR_FWD_A or mode == GEAR_FWD_B else t_a + bfa


@numba.njit(cache=True, nogil=True, _nrt=False)
def gear_speed(p, r, x, n):
    """Speed of flange a against the gear's support ``w_a - w_s`` [rad/s] (MSL ``LossyGear.w_a``)."""
    return _speed(x, n, p.elem[r, E_A]) - _speed(x, n, p.elem[r, E_SUP])


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _converter_row(data, start, n, col, s):
    """Capacity ``C = 1/K^2`` [N m s^2/rad^2] and column ``col`` (the torque ratio; -1: none, 1) of a torque
    converter's table of ``n`` rows at ``data[start:]`` (speed ratios in [0, 1), then capacity factors ``K``
    [rad/s/sqrt(N m)], then torque ratios), at speed ratio ``0 <= s <= 1``: ``K`` and ``TR`` linear between the
    rows (as the tables are measured, SAE J643), held below the first; from the last row to ``s = 1`` the capacity
    falls linearly to 0 with ``TR`` held (no torque without slip: near ``s = 1`` a fluid coupling's torque is
    proportional to its slip)."""
    last = data[start + n - 1]
    if s >= last:
        k = data[start + 2 * n - 1]
        tr = 1.0 if col < 0 else data[start + col * n + n - 1]
        return (1.0 - s) / (1.0 - last) / (k * k), tr
    if s <= data[start]:
        k = data[start + n]
        return 1.0 / (k * k), 1.0 if col < 0 else data[start + col * n]
    lo, w = bracket(data[start:start + n], s)
    k = data[start + n + lo] + w * (data[start + n + lo + 1] - data[start + n + lo])
    o = start + col * n + lo
    tr = 1.0 if col < 0 else data[o] + w * (data[o + 1] - data[o])
    return 1.0 / (k * k), tr


@numba.njit(cache=True, nogil=True, _nrt=False)
def converter_torques(p, r, x, n):
    """Torques [N m] of torque converter row ``r`` on its impeller (flange a), its turbine (flange b) and its
    support (the stator's one-way clutch to the housing), and its speed ratio [-]: ``(tau_a, tau_b, sr)``, the
    support taking ``-(tau_a + tau_b)``.

    Speeds against the support, ``w_p = w_a - w_s``, ``w_t = w_b - w_s``.  Drive (``|w_p| >= |w_t|``, the impeller
    drives; speed ratio ``SR = w_t / w_p``): the impeller torque ``T_p = w_p |w_p| / K(SR)^2`` (the capacity factor
    ``K = w_p / sqrt(T_p)``, SAE J643) and the turbine torque ``T_t = TR(SR) T_p``: ``tau_a = -T_p``, ``tau_b =
    T_t``, the stator's reaction ``T_p - T_t`` on the support.  Coast (``|w_t| > |w_p|``, the turbine drives; its
    ratio ``s = w_p / w_t``): the stator free-wheels, ``TR = 1``, and ``T = w_t |w_t| / K_c(s)^2`` brakes the turbine
    and drives the impeller (``tau_b = -T``, ``tau_a = T``), ``K_c`` the coast table's or, without one, the drive
    table's at ``s`` (Chrono's reflection).  Both tables' ``K`` are multiplied by the converter's ``k_scale``
    (``coef[r, C_K_SCALE]``).  A driven member turning against its driver (``SR`` or ``s`` in [-1, 0),
    a car rolling back against an idling engine) keeps the capacity at ``SR = 0`` and brings ``TR`` linearly to 1 at
    ``-1``, and the coast capacity linearly to the drive table's at ``SR = 0``: the law is continuous at every speed
    pair (homogeneous of degree 2), with ``tau = 0`` at equal speeds and at rest, and its loss ``-(tau_a w_p + tau_b
    w_t) = T_p w_p (1 - TR SR)`` is >= 0 wherever ``TR(SR) SR <= 1`` (checked when the converter is built)."""
    ws = _speed(x, n, p.elem[r, E_SUP])
    wp = _speed(x, n, p.elem[r, E_A]) - ws
    wt = _speed(x, n, p.elem[r, E_B]) - ws
    start, nd, nc = p.elem[r, E_TABLE], p.elem[r, E_TABLE_N], p.elem[r, E_AUX]
    scale = 1.0 / (p.coef[r, C_K_SCALE] * p.coef[r, C_K_SCALE])   # (K times k_scale: the capacity over its square)
    sr = wt / wp if wp != 0.0 else 0.0
    if wp == 0.0 and wt == 0.0:
        return 0.0, 0.0, sr
    if abs(wp) >= abs(wt):   # drive: the impeller drives
        s = wt / wp
        if s >= 0.0:
            c, tr = _converter_row(p.data, start, nd, 2, s)
        else:
            c, tr0 = _converter_row(p.data, start, nd, 2, 0.0)
            tr = tr0 + (tr0 - 1.0) * s
        tp = scale * c * wp * abs(wp)
        return -tp, tr * tp, sr
    s = wp / wt   # coast: the turbine drives
    cstart, cn = (start + 3 * nd, nc) if nc > 0 else (start, nd)
    if s >= 0.0:
        c, _one = _converter_row(p.data, cstart, cn, -1, s)
    else:
        cc0, _one = _converter_row(p.data, cstart, cn, -1, 0.0)
        cd0, _tr = _converter_row(p.data, start, nd, 2, 0.0)
        c = cc0 + (cc0 - cd0) * s
    tc = scale * c * wt * abs(wt)
    return tc, -tc, sr


@numba.njit(cache=True, nogil=True, _nrt=False)
def converter_power(p, r, x, n):
    """Power [W] torque converter row ``r`` dissipates: what its three flanges give it, ``-(tau_a (w_a - w_s) + tau_b
    (w_b - w_s))`` (:func:`converter_torques`; the support's torque is the rest of the balance)."""
    ta, tb, _sr = converter_torques(p, r, x, n)
    ws = _speed(x, n, p.elem[r, E_SUP])
    return -(ta * (_speed(x, n, p.elem[r, E_A]) - ws) + tb * (_speed(x, n, p.elem[r, E_B]) - ws))


@numba.njit(cache=True, nogil=True, _nrt=False)
def _piece_of(data, start, nrows, s):
    """``(k, lo, hi)``: the piece of ``[-1, 1]`` holding the speed ratio ``s`` between the corners of a converter
    table's law (:func:`_converter_row` and :func:`converter_torques`): -1, 0, the table's speed ratios inside ``(0,
    1)``, 1; ``k`` the piece's number (0 the one from -1 to 0), ``lo`` and ``hi`` its ends."""
    if s < 0.0:
        return 0, -1.0, 0.0
    k = 1
    lo = 0.0
    for i in range(nrows):
        b = data[start + i]
        if b <= 0.0 or b >= 1.0:
            continue
        if s < b:
            return k, lo, b
        k += 1
        lo = b
    return k, lo, 1.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _pieces(data, start, nrows):
    """The number of pieces :func:`_piece_of` counts on ``[-1, 1]``."""
    k = 2
    for i in range(nrows):
        b = data[start + i]
        if 0.0 < b < 1.0:
            k += 1
    return k


@numba.njit(cache=True, nogil=True, _nrt=False)
def converter_piece(p, r, x, n):
    """The waypoint function of torque converter row ``r`` [-]: zero at each corner of its law, of alternating sign
    from one piece to the next (a waypoint either way: a step ends just past each corner, where the law's slope
    jumps, so that the error follows the tolerance there; docs/driveline.md, "Torque converter").

    The law depends on the direction of ``(w_p, w_t)`` only (homogeneous of degree 2).  Around that circle: drive
    with ``w_p > 0`` (``SR = w_t/w_p`` from -1 to 1), coast with ``w_t > 0`` (``s = w_p/w_t`` from 1 to -1), drive
    with ``w_p < 0``, coast with ``w_t < 0``; the corners of each at -1, 0, its table's speed ratios and 1 (where
    drive and coast meet).  Piece ``k`` around the circle, between corners ``lo`` and ``hi`` of its ratio ``s``:
    ``(-1)^k (s - lo)(hi - s) / (hi - lo)^2``.  The pieces are even in number (the law is odd: the corners come in
    opposite pairs), so the sign alternates all the way round.  1 (no waypoint) where both speeds are within
    1000 times their rounding width of the support's (a converter at rest: its direction is a rounding)."""
    ws = _speed(x, n, p.elem[r, E_SUP])
    wp = _speed(x, n, p.elem[r, E_A]) - ws
    wt = _speed(x, n, p.elem[r, E_B]) - ws
    if max(abs(wp), abs(wt)) <= 1e3 * _item_wtol(p, r, x, n):
        return 1.0
    start, nd, nc = p.elem[r, E_TABLE], p.elem[r, E_TABLE_N], p.elem[r, E_AUX]
    cstart, cn = (start + 3 * nd, nc) if nc > 0 else (start, nd)
    pd = _pieces(p.data, start, nd)
    pc = _pieces(p.data, cstart, cn)
    if abs(wp) >= abs(wt):   # drive: increasing s around the circle
        s = wt / wp
        k, lo, hi = _piece_of(p.data, start, nd, s)
        if wp < 0.0:
            k += pd + pc
    else:                    # coast: decreasing s around the circle
        s = wp / wt
        k, lo, hi = _piece_of(p.data, cstart, cn, s)
        k = pd + (pc - 1 - k)
        if wt < 0.0:
            k += pd + pc
    v = (s - lo) * (hi - s) / ((hi - lo) * (hi - lo))
    return v if k % 2 == 0 else -v


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _has_support(kind):
    """Does an element of ``kind`` act on a support (its ``E_SUP`` column): a gear and a torque converter."""
    return kind == K_GEAR or kind == K_CONVERTER


@numba.njit(cache=True, nogil=True, _nrt=False)
def _gear_mode(p, r, m):
    """The mode of gear row ``r`` (``GEAR_STUCK`` for an ideal one, which has none)."""
    mi = p.elem[r, E_MODE]
    return m[mi] if mi >= 0 else GEAR_STUCK


@numba.njit(cache=True, nogil=True, _nrt=False)
def relative_speed(p, r, x, n):
    """Relative speed ``cb w_b - ca w_a`` [rad/s] of element row ``r`` (``w_b - w_a`` but for gears, whose
    constraint speed is ``ratio (w_b - w_s) - (w_a - w_s)``, zero but for drift)."""
    ca, cb = _coefficients(p, r)
    v = cb * _speed(x, n, p.elem[r, E_B]) - ca * _speed(x, n, p.elem[r, E_A])
    if p.elem[r, E_KIND] == K_GEAR:
        v += (ca - cb) * _speed(x, n, p.elem[r, E_SUP])
    return v


@numba.njit(cache=True, nogil=True, _nrt=False)
def _apply(F, Fa, elem, r, ca, cb, tq):
    """Torque ``tq`` of element row ``r`` on its inertias (``+ca tq`` on flange a, ``-cb tq`` on b), and its magnitude
    into ``Fa``."""
    b = elem[r, E_B]
    a = elem[r, E_A]
    if b >= 0:
        F[b] -= cb * tq
        Fa[b] += abs(cb * tq)
    if a >= 0:
        F[a] += ca * tq
        Fa[a] += abs(ca * tq)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _add(F, i, v):
    if i >= 0:
        F[i] += v


@numba.njit(cache=True, nogil=True, _nrt=False)
def evaluate_network(t, x, m, p, acc, tau):
    """Accelerations ``acc`` [rad/s^2] of the inertias and the torque ``tau`` [N m] of every element.

    Spring-dampers :func:`spring_torque`; torque converters :func:`converter_torques` (on flanges a, b and the
    support); torque sources: their signal (acting on flange b, positive
    accelerating it, so ``tau`` is stored with the element convention as minus the source torque);
    sliding friction ``+-friction_torque``; free friction 0; the bearing-friction part of a rolling lossy gear
    (its constant torques ``-ratio c`` on flange b and ``+ratio c`` on the support, :func:`gear_transfer`);
    stuck friction, gears, stuck lossy gears' holds and motion sources: the solution of the constraint set
    (:func:`_solve_stuck`).  Returns the size of that set.
    """
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    nc = p.cons.shape[0]
    wk = p.work
    refresh_signals(p, t)
    if p.thermal.shape[0] > 0:   # (the temperatures the fading friction laws read)
        temp = temperatures(p)
        for k in range(p.thermal.shape[0]):
            temp[k] = x[int(p.thermal[k, T_STATE]) + TS_TEMP]
    if _shifted(p):   # (a shifted E-clutch's working point at this state)
        update_shifts(p, x)
    F = wk[0:n]
    Fa = _torque_magnitudes(p)
    for i in range(n):
        F[i] = 0.0
        Fa[i] = 0.0
    for r in range(ne):
        kind = p.elem[r, E_KIND]
        if kind == K_SPRING:
            tq, _tc = spring_torque(p, r, x, n, m)
        elif kind == K_SOURCE:
            tq = -(signal_at(p, p.elem[r, E_SIGNAL], t) if p.elem[r, E_LAW] == SOURCE_SIGNAL
                   else source_torque(p, r, t, x, n))
        elif kind == K_CONVERTER:   # three torques: impeller, turbine, the stator's reaction on the support
            ta, tb, _sr = converter_torques(p, r, x, n)
            tau[r] = ta
            for i, v in ((p.elem[r, E_A], ta), (p.elem[r, E_B], tb), (p.elem[r, E_SUP], -(ta + tb))):
                _add(F, i, v)
                _add(Fa, i, abs(v))
            continue
        else:
            continue
        tau[r] = tq
        _apply(F, Fa, p.elem, r, 1.0, 1.0, tq)
    # sliding and free friction; the constraint set: stuck friction, gears, motion sources
    ns = _ZERO   # (an int64 from the start: a literal 0 would compile the callees once more for it)
    stuck = wk[n:n + _nk(p)]  # element rows of the set (as floats; -(row + 1): a stuck lossy gear's hold)
    for k in range(nf):
        r = p.fric[k]
        mk = m[k]
        if mk == STUCK:
            stuck[ns] = r
            ns += 1
            continue
        if mk == FREE:
            tq = 0.0
        else:
            w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
            tq = friction_torque(p, r, t, abs(w_rel))
            if mk == BACKWARD:
                tq = -tq
        tau[r] = tq
        _apply(F, Fa, p.elem, r, 1.0, 1.0, tq)
    for k in range(nc):
        stuck[ns] = p.cons[k]
        ns += 1
    for j in range(p.lossy.shape[0]):
        r = p.lossy[j]
        mode = m[p.elem[r, E_MODE]]
        if mode == GEAR_STUCK:   # a stuck gear holds flange a against its support (member -(row + 1))
            stuck[ns] = -(r + 1)
            ns += 1
        else:                    # the bearing friction of a rolling gear: constant torques on b and the support
            _f, c = gear_transfer(p, r, mode, abs(gear_speed(p, r, x, n)))
            ratio = p.coef[r, C_RATIO]
            _add(F, p.elem[r, E_B], -ratio * c)
            _add(F, p.elem[r, E_SUP], ratio * c)
            _add(Fa, p.elem[r, E_B], abs(ratio * c))
            _add(Fa, p.elem[r, E_SUP], abs(ratio * c))
    hold = _holds(p)
    for j in range(hold.shape[0]):
        hold[j] = 0.0
    if ns > 0:
        _solve_stuck_outlined(t, x, p, m, stuck, ns, F, tau, _ZERO)
    for i in range(n):
        acc[i] = F[i] / p.inertia[i]
    return ns


#: the warm start of :func:`_repair_space`, per combination of the stuck lossy gears' band pieces (at most 16; with
#: three or more gears, slot 0 the current pieces', slot 1 the last combination that held the set, slot 2 its code)
SPACE_SLOTS = 16


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def space_hint(nk):
    """Words of one combination's warm start of :func:`_repair_space` in a network whose largest constraint set has
    ``nk`` members (so at most ``nk`` null directions): the bounds of its largest margin's vertex (the rank of the
    bounds' span, then up to ``nk + 1`` bounds) and the active set of its nearest split (its size, then up to ``nk``
    bounds)."""
    return 1 + (nk + 1) + 1 + nk


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def space_cache(nk):
    """Words of the warm start of :func:`_repair_space`: :data:`SPACE_SLOTS` combinations of :func:`space_hint`."""
    return SPACE_SLOTS * space_hint(nk)


class WorkLayout(NamedTuple):
    """Offsets of the blocks of ``DrivelineParams.work`` (:func:`_layout`): the constraint set's matrix ``a``, its
    regularised copy ``m``, right-hand side ``b``, multipliers ``l``, weights ``c``, residual ``r``, member flanges
    and weights ``g``, bounds and scratch ``lim``; accelerations ``acc``, element torques ``tau``, stick-function
    slack ``slack``, torque magnitudes ``fabs``, gear holds ``hold``, signal cache ``sig``, null-vector cache ``nv``,
    the last search's instant ``inst``, the warm start of the split of a statically indeterminate set ``sp``
    (:func:`_repair_space`), the thermal masses' temperatures ``temp``, the elements' working-point shifts ``shift``,
    clutch models ``ext``."""
    a: int
    m: int
    b: int
    l: int
    c: int
    r: int
    g: int
    lim: int
    acc: int
    tau: int
    slack: int
    fabs: int
    hold: int
    sig: int
    nv: int
    inst: int
    sp: int
    temp: int
    shift: int
    ext: int


@numba.njit(cache=True, nogil=True, _nrt=False)
def _layout(n, nk, ne, nf=0, nl=0, nsig=0, nt=0):
    """Offsets in ``DrivelineParams.work`` (``nk``: the largest constraint set): net torques F (n) | the set (nk) | A
    (nk^2) | A + eps D (nk^2) | right-hand side (nk) | its torques (nk) | weights (nk) | residual (nk) | three
    flanges, their constraint and torque weights of each member (9 nk) | lower and upper bounds, null vector, its
    scratch, a trial split, breakpoints (11 nk + 2), a copy of A (nk^2), one block's members, split, bounds and the
    block of each member (5 nk, :func:`_repair_blocks`) | accelerations (n) | element torques (ne) | slack of each
    friction element's and lossy gear's stick function (nf + nl, :func:`settle`), then of its break-away function
    (nf + nl, :func:`_break_slack`) | the sum of the magnitudes of the
    torques on each inertia (n, the local scale of rounding, :func:`_item_noise`) | the loss torque each lossy gear
    holds or carries (nl) | the time and the values of the signals at the last evaluation (1 + nsig,
    :func:`signal_at`) | the last null-vector search: its set size, result, matrix and vector (2 + nk^2 + nk,
    :func:`_null_vector_cached`) | the instant of the last stick/slip search, the event count before it and the
    friction elements' and lossy gears' modes before it (2 + nf + nl, :func:`settle`), the last break time given to
    the core (1, :func:`_break_marker`) | the warm start of :func:`_repair_space` (:func:`space_cache`), then whether an
    observer evaluates the network (1, :func:`observe`) | the thermal
    masses' temperatures at the last evaluation (nt, :func:`temperatures`) | each element's working-point shift at
    the last evaluation (ne, :func:`update_shifts`; an E-clutch's wear and thermal expansion) | sliding torque,
    static limit and lock-up limit of each clutch model, their rates and the time of those (``N_EXT`` per
    ``LAW_EXTERNAL`` element, :func:`set_external`, :func:`set_external_rates`) | the
    scratch of the rates of stuck margins: the moved state, its derivative and switching functions, and the
    accelerations, torques, holds and torque magnitudes saved meanwhile (:func:`rate_size`, :func:`_margin_rates`,
    addressed from the end) | initial stored energy (1). Returns the offsets as a :class:`WorkLayout`."""
    o_a = n + nk
    o_m = o_a + nk * nk
    o_b = o_m + nk * nk
    o_l = o_b + nk
    o_c = o_l + nk
    o_r = o_c + nk
    o_g = o_r + nk
    o_lim = o_g + 9 * nk
    o_acc = o_lim + 16 * nk + 2 + nk * nk
    o_tau = o_acc + n
    o_slack = o_tau + ne
    o_fabs = o_slack + 2 * (nf + nl)
    o_hold = o_fabs + n
    o_sig = o_hold + nl
    o_nv = o_sig + 1 + nsig
    o_inst = o_nv + 2 + nk * nk + nk
    o_sp = o_inst + 3 + nf + nl
    o_temp = o_sp + space_cache(nk) + 1
    o_shift = o_temp + nt
    o_ext = o_shift + ne
    return WorkLayout(o_a, o_m, o_b, o_l, o_c, o_r, o_g, o_lim, o_acc, o_tau, o_slack, o_fabs, o_hold, o_sig, o_nv,
                      o_inst, o_sp, o_temp, o_shift, o_ext)


def work_size(n, nk, ne, nf, nx=0, nl=0, nsig=0, nt=0):
    """Length of ``DrivelineParams.work`` for ``n`` inertias, ``nk`` members of the largest constraint set, ``ne``
    elements, ``nf`` friction elements, ``nx`` clutch models with states of their own, ``nl`` lossy gears, ``nsig``
    signals, ``nt`` thermal masses (the layout of :func:`_layout`)."""
    return _layout.py_func(n, nk, ne, nf, nl, nsig, nt).ext + N_EXT * nx + rate_size.py_func(n, ne, nf, nl, nt) + 1


@numba.njit(cache=True, nogil=True, _nrt=False)
def state_bound(n, ne, nt):
    """Most states a network of ``n`` inertias, ``ne`` elements and ``nt`` thermal masses has: angles, speeds,
    energies, engine integrals (at most one per element), the thermal masses' (:data:`THERMAL_STATES`)."""
    return 2 * n + 2 * ne + len(THERMAL_STATES) * nt


@numba.njit(cache=True, nogil=True, _nrt=False)
def rate_size(n, ne, nf, nl, nt):
    """Length of the scratch of :func:`_margin_rates` at the end of the work array: a state and its derivative (at
    most :func:`state_bound` each), the switching functions (at most ``N_G nf + N_SW ne + N_GEAR_G nl``), and the
    accelerations, torques, holds, torque magnitudes and temperatures (``2 n + ne + nl + nt``), and a label per
    inertia (``n``, :func:`_edge_rate`)."""
    return 2 * state_bound(n, ne, nt) + (N_G * nf + N_SW * ne + N_GEAR_G * nl) + 3 * n + ne + nl + nt


def new_work(n, nk, ne, nf, nx=0, nl=0, nsig=0, nt=0):
    """A zeroed ``DrivelineParams.work`` of :func:`work_size` with its signal cache empty (:func:`signal_at`)."""
    work = np.zeros(work_size(n, nk, ne, nf, nx, nl, nsig, nt))
    lay = _layout.py_func(n, nk, ne, nf, nl, nsig, nt)
    work[lay.sig] = np.nan
    work[lay.inst] = np.nan
    work[lay.inst + 2 + nf + nl] = np.nan
    return work


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _nk(p):
    """Largest constraint set: every friction element, every gear and motion source, and the hold of every lossy
    gear (``GEAR_STUCK``)."""
    return p.fric.shape[0] + p.cons.shape[0] + p.lossy.shape[0]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _offsets(p):
    return _layout(p.inertia.shape[0], _nk(p), p.elem.shape[0], p.fric.shape[0], p.lossy.shape[0],
                   p.signals.shape[0], p.thermal.shape[0])


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def temperatures(p):
    """The thermal masses' temperatures [degC] at the network's last evaluation (:func:`evaluate_network`), which
    the friction laws that fade read (:func:`fade_factor`)."""
    o = _offsets(p)
    return p.work[o.temp:o.shift]


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def heat_port_temperature(p, r, x, default):
    """Temperature [degC] in the state ``x`` of the thermal mass element row ``r``'s losses heat (its heat port:
    ``elem[r, E_HEAT]``), ``default`` where they heat none."""
    h = p.elem[r, E_HEAT]
    if h < 0:
        return default
    return x[int(p.thermal[h, T_STATE]) + TS_TEMP]


@numba.njit(cache=True, nogil=True, _nrt=False)
def observe(p, on):
    """Mark the evaluations of the network that follow as an observer's (``on`` True: the outputs at a sample, the
    invariant check, the margin rates' probe) or not: an observer's evaluation leaves the warm start of
    :func:`_repair_space` as it was, so that the decisions of a run do not depend on where it is sampled or whether
    it is checked."""
    p.work[_offsets(p).sp + space_cache(_nk(p))] = 1.0 if on else 0.0


@numba.njit(cache=True, nogil=True, _nrt=True)
def _acc_tau(p):
    o = _offsets(p)
    return borrow((p.work[o.acc:o.acc + p.inertia.shape[0]], p.work[o.tau:o.tau + p.elem.shape[0]]))


@numba.njit(cache=True, nogil=True, _nrt=True)
def _slack(p):
    """Slack of the stick functions: the friction elements', then the lossy gears'."""
    o = _offsets(p)
    return borrow(p.work[o.slack:o.slack + p.fric.shape[0] + p.lossy.shape[0]])


@numba.njit(cache=True, nogil=True, _nrt=True)
def _break_slacks(p):
    """Slack of the break-away functions of stuck items (:func:`_break_slack`): the friction elements', then the
    lossy gears'.  Apart from the stick functions' (:func:`_slack`): an item stuck and released again within one
    instant keeps the stick slack it had before it (:func:`_one_search_per_instant`), and a break slack written over
    it changed the next stick decision of a one-way clutch (#30)."""
    o = _offsets(p)
    ni = p.fric.shape[0] + p.lossy.shape[0]
    return borrow(p.work[o.slack + ni:o.slack + 2 * ni])


@numba.njit(cache=True, nogil=True, _nrt=True)
def _holds(p):
    """The loss torque [N m] each lossy gear holds (stuck: the multiplier of its hold) at the last evaluation."""
    o = _offsets(p)
    return borrow(p.work[o.hold:o.hold + p.lossy.shape[0]])


@numba.njit(cache=True, nogil=True, _nrt=True)
def _torque_magnitudes(p):
    """The sum of the magnitudes of every torque on each inertia at the last evaluation [N m]."""
    o = _offsets(p)
    return borrow(p.work[o.fabs:o.fabs + p.inertia.shape[0]])


@numba.njit(cache=True, nogil=True, _nrt=True)
def _instant(p):
    """The instant [s] of the last stick/slip search, the event count before it, and the modes of the friction
    elements and lossy gears before it (:func:`settle`)."""
    o = _offsets(p)
    return borrow(p.work[o.inst:o.inst + 2 + p.fric.shape[0] + p.lossy.shape[0]])


@numba.njit(cache=True, nogil=True, _nrt=True)
def _break_marker(p):
    """The break time :func:`driveline_next_break` last gave the core (NaN once a restart has taken it): a restart
    at that time is a signal's jump, not a start or a resume (:func:`driveline_restart`)."""
    o = _offsets(p)
    k = o.inst + 2 + p.fric.shape[0] + p.lossy.shape[0]
    return borrow(p.work[k:k + 1])


#: words per clutch model in the work array: its sliding torque, static limit and lock-up limit, then their rates,
#: then the time those rates start from (:func:`set_external`, :func:`set_external_rates`)
N_EXT = slots(("limits", 3), ("rates", 3), ("rate_start", 1)).total


@numba.njit(cache=True, nogil=True, _nrt=True)
def _external(p):
    """The clutch models' words (``LAW_EXTERNAL``, :data:`N_EXT` per model): the sliding torques, static limits and
    lock-up limits (three per model), then their rates (three per model), then the time of each model's rates."""
    o = _offsets(p)
    return borrow(p.work[o.ext:p.work.shape[0] - 1 - rate_size(p.inertia.shape[0], p.elem.shape[0],
                                                                    p.fric.shape[0], p.lossy.shape[0],
                                                                    p.thermal.shape[0])])


@numba.njit(cache=True, nogil=True, _nrt=False)
def refresh_signals(p, t):
    """Evaluate every signal of the network at ``t`` once (:func:`signal_value`) into the signal cache, unless it
    already holds them at ``t``; every evaluation of the network starts with this, and :func:`signal_at` reads from
    it at that time.  A signal is a function of time and of ``p.data`` alone, and whatever changes ``p.data`` (a
    held input, :func:`hold_inputs`) or starts a run (:func:`driveline_restart`) empties the cache
    (:func:`forget_signals`), so a cache at ``t`` is that time's values: a component's port that read its signal
    before the network (a wet clutch's force, an EMTC's ports) fills it once for both."""
    o = _offsets(p).sig
    w = p.work
    if w[o] == t:
        return
    for s in range(p.signals.shape[0]):
        w[o + 1 + s] = signal_value(p.signals[s], p.data, t)
    w[o] = t


@numba.njit(cache=True, nogil=True, _nrt=False)
def forget_signals(p):
    """Empty the signal cache (a run starts, or a signal's parameters change)."""
    p.work[_offsets(p).sig] = np.nan


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def hold_inputs(data, u):
    """Hold the network's inputs ``u`` (in the order of :meth:`Driveline.inputs
    <clutchlab.driveline.network.Driveline.inputs>`, SI) where its input signals read them (:data:`SIG_INPUT`: the
    last ``u.size`` numbers of ``data``, the network's ``p.data``); True if a value changed, and the caller then
    empties the signal cache (:func:`forget_signals`).  Every hook of the core that evaluates the network does this
    first, and only for a network with inputs (inlined there: a call that takes the parameters cost CoupledClutches
    40 %), so whatever evaluates it (a step, an event, the outputs, the stuck-set searches at a restart) reads the
    inputs the core holds."""
    nu = u.shape[0]
    o = data.shape[0] - nu
    changed = False
    for j in range(nu):
        if data[o + j] != u[j]:
            data[o + j] = u[j]
            changed = True
    return changed


@numba.njit(cache=True, nogil=True, _nrt=False)
def signal_at(p, s, t):
    """Value of signal ``s`` of the network at ``t``: from the cache of the last evaluation if it was at ``t``
    (:func:`refresh_signals`), else :func:`signal_value` itself.  The same value either way: a signal is a
    function of time alone."""
    o = _offsets(p).sig
    if p.work[o] == t:
        return p.work[o + 1 + s]
    return signal_value(p.signals[s], p.data, t)


@numba.njit(cache=True, nogil=True, _nrt=False)
def set_external(p, j, slide, limit, lock):
    """Set clutch model ``j``'s (``elem[r, E_AUX] = j``) sliding torque magnitude ``slide`` [N m] at the present
    relative speed, its static limit ``limit`` [N m] (the torque it holds while stuck: beyond it, it breaks
    away) and its lock-up limit ``lock`` [N m] (the torque it must cover to stick when its relative speed
    reaches zero; MSL's friction elements use their static limit for both), for the network's evaluations at
    the present state.  Its model's hooks call this before every hook of the network."""
    ext = _external(p)
    nx = ext.shape[0] // N_EXT
    ext[3 * j] = slide
    ext[3 * j + 1] = limit
    ext[3 * j + 2] = lock
    for q in range(3):
        ext[3 * nx + 3 * j + q] = 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def set_external_rates(p, j, t0, d_slide, d_limit, d_lock):
    """Clutch model ``j``'s rates [N m/s] of the three numbers :func:`set_external` gave at ``t0`` (until its next
    call, which sets them to zero): the network's evaluations at another time (the tie-break of :func:`settle` at
    ``t + T_TIE``, the margin rates at ``t + T_RATE``) then see the model's torques move, as a source's signal moves.
    Without them a bearing friction beside a wet clutch whose drag grew past the bearing's limit was judged holding
    at its break-away instant (its load looked to fall with a falling sine torque, the clutch's rise unseen) and
    stayed stuck at twice its limit (issue #31)."""
    ext = _external(p)
    nx = ext.shape[0] // N_EXT
    ext[3 * nx + 3 * j] = d_slide
    ext[3 * nx + 3 * j + 1] = d_limit
    ext[3 * nx + 3 * j + 2] = d_lock
    ext[6 * nx + j] = t0


@numba.njit(cache=True, nogil=True, _nrt=False)
def copy_component(dx, g, b, xo, go, nx, ng, bdx, bg):
    """A model component's derivatives ``b[bdx:bdx + nx]`` and switching values ``b[bg:bg + ng]`` (its scratch) into
    the whole system's ``dx`` from ``xo`` and ``g`` from ``go`` on (:mod:`clutchlab.driveline.coupled`; the
    component then overwrites what the network decides for it)."""
    for i in range(nx):
        dx[xo + i] = b[bdx + i]
    for i in range(ng):
        g[go + i] = b[bg + i]


# ---- what a model component's block reads of the network (driveline.coupled, driveline.wet, driveline.emtc): it
# gives its torques with set_external/set_external_rates and its derivatives with copy_component, and reads these

#: the speed [rad/s] of inertia ``i`` in the state ``x`` of a network of ``n`` inertias (0 for the ground, ``i < 0``)
flange_speed = _speed


@numba.njit(cache=True, nogil=True, _nrt=True)
def accelerations(p):
    """The inertias' accelerations [rad/s^2] of the network's last evaluation (its right-hand side), borrowed."""
    return _acc_tau(p)[0]


@numba.njit(cache=True, nogil=True, _nrt=True)
def external_count(p):
    """The number of clutch models (``LAW_EXTERNAL`` elements) whose torques :func:`set_external` sets."""
    return _external(p).shape[0] // N_EXT


@numba.njit(cache=True, nogil=True, _nrt=False)
def external_value(p, j, which, t):
    """Clutch model ``j``'s number ``which`` (0 sliding torque, 1 static limit, 2 lock-up limit) [N m] at time ``t``:
    as :func:`set_external` gave it, moved by its rate (:func:`set_external_rates`) from the time of the rate (never
    below zero)."""
    ext = _external(p)
    nx = ext.shape[0] // N_EXT
    v = ext[3 * j + which]
    rate = ext[3 * nx + 3 * j + which]
    if rate != 0.0:
        v = max(0.0, v + (t - ext[6 * nx + j]) * rate)
    return v


@numba.njit(cache=True, nogil=True, _nrt=False)
def _member(p, m, x, n, rk, fl, gc, hc, k):
    """Flanges (three, -1 for none or the ground; stored as floats), constraint weights ``g`` and torque weights
    ``h`` of constraint member ``k`` (element row ``rk``, or ``-(row + 1)`` for a stuck lossy gear's hold): the
    member holds ``g . alpha`` at its target and its multiplier ``lam`` puts the torques ``-lam h`` on the inertias.

    Friction, motion sources: ``g = h = cb e_b - ca e_a``.  A gear against its support ``s`` (MSL ``IdealGear``,
    ``LossyGear`` with ``phi_a - phi_s = ratio (phi_b - phi_s)``): ``g = ratio e_b - e_a + (1 - ratio) e_s``, ``lam =
    -T_a`` the torque on flange a, ``h = ratio f e_b - e_a + (1 - ratio f) e_s`` with ``f`` of its mode
    (:func:`gear_transfer`; 1 ideal or stuck).  The hold of a stuck lossy gear: ``g = e_a - e_s`` (flange a at rest
    on its support), its multiplier the loss torque ``tauLoss`` the gear holds, ``h = ratio (e_b - e_s)`` (MSL:
    ``flange_b.tau = -ratio (flange_a.tau - tauLoss)``)."""
    o = 3 * k
    if rk < 0:
        r = -rk - 1
        ratio = p.coef[r, C_RATIO]
        fl[o], fl[o + 1], fl[o + 2] = p.elem[r, E_A], p.elem[r, E_B], p.elem[r, E_SUP]
        gc[o], gc[o + 1], gc[o + 2] = 1.0, 0.0, -1.0
        hc[o], hc[o + 1], hc[o + 2] = 0.0, ratio, -ratio
        return
    ca, cb = _coefficients(p, rk)
    fl[o], fl[o + 1], fl[o + 2] = p.elem[rk, E_A], p.elem[rk, E_B], -1
    gc[o], gc[o + 1], gc[o + 2] = -ca, cb, 0.0
    hc[o], hc[o + 1], hc[o + 2] = -ca, cb, 0.0
    if p.elem[rk, E_KIND] == K_GEAR:
        f = 1.0
        if p.elem[rk, E_MODE] >= 0 and m[p.elem[rk, E_MODE]] != GEAR_STUCK:
            f, _c = gear_transfer(p, rk, m[p.elem[rk, E_MODE]], abs(gear_speed(p, rk, x, n)))
        fl[o + 2] = p.elem[rk, E_SUP]
        gc[o + 2] = ca - cb
        hc[o + 1] = cb * f
        hc[o + 2] = ca - cb * f


@numba.njit(cache=True, nogil=True, _nrt=False)
def _in_band(p, r, t_a, hold, tol):
    """True if a stuck lossy gear row ``r`` carrying ``T_a`` holds the loss torque ``hold`` within its band (to
    ``tol``)."""
    lo, hi = gear_band(p, r, t_a)
    return lo - tol <= hold <= hi + tol


@numba.njit(cache=True, nogil=True, _nrt=False)
def _gear_member(stuck, ns, r):
    """Index in the stuck set of lossy gear row ``r``'s own member (its kinematic constraint; its hold is
    ``-(r + 1)``), -1 if it is not in the set."""
    q = -1
    for qq in range(ns):
        if int(stuck[qq]) == r:
            q = qq
    return q


@numba.njit(cache=True, nogil=True, _nrt=False)
def _feasible(p, stuck, ns, lam, lo, hi, tol):
    """True if every bounded member of the set is within its bounds (a stuck lossy gear's hold within its band)."""
    for k in range(ns):
        rk = int(stuck[k])
        if rk < 0:
            r = -rk - 1
            for q in range(ns):
                if int(stuck[q]) == r:
                    if not _in_band(p, r, -lam[q], lam[k], tol):
                        return False
                    break
        elif lam[k] < lo[k] - tol or lam[k] > hi[k] + tol:
            return False
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _eliminate(A, ns, S, cp):
    """Gaussian elimination with complete pivoting of ``A[:ns, :ns]`` into ``S`` (its columns in the order ``cp``):
    the rank, a pivot below 1e-13 of the first taken as zero (0 for a zero matrix).  The first ``rank`` rows of
    ``S`` are then upper triangular, the rest zero to that threshold."""
    for k in range(ns):
        cp[k] = k
        for j in range(ns):
            S[k, j] = A[k, j]
    first = 0.0
    for c in range(ns):
        bi, bj, bv = c, c, -1.0
        for i in range(c, ns):
            for j in range(c, ns):
                if abs(S[i, j]) > bv:
                    bi, bj, bv = i, j, abs(S[i, j])
        if c == 0:
            first = bv
            if first == 0.0:
                return 0
        if bv <= 1e-13 * first:
            return c
        for j in range(ns):
            S[c, j], S[bi, j] = S[bi, j], S[c, j]
        for i in range(ns):
            S[i, c], S[i, bj] = S[i, bj], S[i, c]
        cp[c], cp[bj] = cp[bj], cp[c]
        for i in range(c + 1, ns):
            f = S[i, c] / S[c, c]
            if f != 0.0:
                for j in range(c, ns):
                    S[i, j] -= f * S[c, j]
    return ns


@numba.njit(cache=True, nogil=True, _nrt=False)
def _null_vector(A, ns, S, cp, v, y):
    """The null vector ``v`` of ``A[:ns, :ns]`` if its rank is ``ns - 1`` (:func:`_eliminate`): 1, ``v`` scaled to a
    largest entry of 1; 0 for full rank or a zero matrix, 2 for more than one null direction (``v`` untouched).
    ``S``, ``cp`` and ``y`` are scratch (a copy of ``A``, the column order, the permuted vector)."""
    if ns < 2:
        return 0
    rank = _eliminate_outlined(A, ns, S, cp)
    if rank == 0 or rank == ns:
        return 0
    if rank != ns - 1:
        return 2
    # U y = 0 with y[ns-1] = 1, back substitution; v[cp[i]] = y[i]
    y[ns - 1] = 1.0
    for i in range(ns - 2, -1, -1):
        acc_ = 0.0
        for j in range(i + 1, ns):
            acc_ += S[i, j] * y[j]
        y[i] = -acc_ / S[i, i]
    big = 0.0
    for i in range(ns):
        big = max(big, abs(y[i]))
    for i in range(ns):
        v[cp[i]] = y[i] / big
    return 1


@numba.njit(cache=True, nogil=True, _nrt=False)
def _searched_before(p, A, ns):
    """True if the last null-vector search (:func:`_null_vector_cached`) was of exactly this ``A[:ns, :ns]``."""
    o = _offsets(p).nv
    nk = _nk(p)
    w = p.work
    if w[o] != ns:
        return False
    for k in range(ns):
        for j in range(ns):
            if w[o + 2 + k * nk + j] != A[k, j]:
                return False
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _full_rank_known(p, A, ns):
    """True if the last null-vector search was of exactly this ``A`` and found it of full rank (nothing to
    repair)."""
    return _searched_before(p, A, ns) and p.work[_offsets(p).nv + 1] == 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _several_null_known(p, A, ns):
    """True if the last null-vector search was of exactly this ``A`` and found more than one null direction."""
    return _searched_before(p, A, ns) and _several_null_last(p)


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _several_null_last(p):
    """True if the last null-vector search (:func:`_null_vector_cached`, whatever ``A`` it was of: in
    :func:`driveline_rhs`, the evaluation's own stuck set where it has two members or more) found more than one null
    direction."""
    return p.work[_offsets(p).nv + 1] == 2.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _null_vector_cached(p, A, ns, S, cp, v, y):
    """:func:`_null_vector` of ``A[:ns, :ns]``, reusing the last search's result when ``A`` is exactly the matrix it
    searched (a stuck set evaluated again: the same set, the same ``A`` but for speed-dependent gear losses), so the
    answer is the same bit for bit."""
    o = _offsets(p).nv
    nk = _nk(p)
    w = p.work
    if _searched_before(p, A, ns):
        if w[o + 1] != 1.0:
            return False
        for k in range(ns):
            v[k] = w[o + 2 + nk * nk + k]
        return True
    code = _null_vector(A, ns, S, cp, v, y)
    found = code == 1
    w[o] = ns
    w[o + 1] = float(code)
    for k in range(ns):
        for j in range(ns):
            w[o + 2 + k * nk + j] = A[k, j]
        if found:
            w[o + 2 + nk * nk + k] = v[k]
    return found


@numba.njit(cache=True, nogil=True, _nrt=False)
def _rank_full(p, A, ns, S, v, y):
    """True if ``A[:ns, :ns]`` is of full rank (:func:`_null_vector_cached`: searched once while ``A`` is the same;
    its column order goes to ``p.iwork``, free before the factorisation)."""
    _null_vector_cached(p, A, ns, S, p.iwork, v, y)
    return _full_rank_known(p, A, ns)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _rolling_gear_in(p, m, stuck, ns):
    """True if a member of the constraint set is a rolling lossy gear (its torque weights ``h`` are not its
    constraint weights ``g``, :func:`_member`, so ``A`` is not symmetric)."""
    for k in range(ns):
        rk = int(stuck[k])
        if rk >= 0 and p.elem[rk, E_KIND] == K_GEAR and p.elem[rk, E_MODE] >= 0 and \
                m[p.elem[rk, E_MODE]] != GEAR_STUCK:
            return True
    return False


@numba.njit(cache=True, nogil=True, _nrt=False)
def _split_limit(p, A, ns, S, cp, lam, d, v, u, y):
    """The regularised split of a set with one null direction, moved along it onto its own limit (``eps`` -> 0).

    ``(A + eps D) lam = b`` gives ``u . D lam = 0`` for every ``eps``, ``u`` the left null vector of ``A`` (``u A =
    0``, and ``u . b = 0`` for a consistent ``b``), and so does each refinement on the residual: that condition picks
    the split among ``lam + z v`` (``v`` the right null vector), the minimum of ``sum(lam_k^2 D_k)`` where ``A`` is
    symmetric.  In floating point the residual's rounding (1e-17 of the torques) has a component along ``u``
    that the solve divides by ``eps`` (1e-8 of ``A``): the split lands 1e-9 of the torques off its limit along ``v``.
    Where ``A`` is not symmetric (a rolling lossy gear in a rigid loop) that moves the gear's torque, which the
    split may leave at zero, by 1e-9 N m of either sign: its quadrant followed the residue, its loss power came out
    negative, and its quadrant changed back and forth (#30).  Here ``z = u . D lam / u . D v`` is taken off, so the
    split is its limit to rounding.  ``d`` holds ``D``'s diagonal; ``S``, ``cp``, ``y`` are scratch; ``A`` is
    transposed in place for ``u`` and back (exact)."""
    if not _null_vector_cached(p, A, ns, S, cp, v, y):
        return
    for k in range(ns):
        for j in range(k + 1, ns):
            A[k, j], A[j, k] = A[j, k], A[k, j]
    code = _null_vector(A, ns, S, cp, u, y)
    for k in range(ns):
        for j in range(k + 1, ns):
            A[k, j], A[j, k] = A[j, k], A[k, j]
    if code != 1:
        return
    num = 0.0
    den = 0.0
    mag = 0.0
    for k in range(ns):
        num += u[k] * d[k] * lam[k]
        den += u[k] * d[k] * v[k]
        mag += abs(u[k] * d[k] * v[k])
    if abs(den) <= 1e-8 * mag:
        return
    z = num / den
    for k in range(ns):
        lam[k] -= z * v[k]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _repair(p, stuck, ns, A, S, cp, lam, lo, hi, v, tmp, cand, trial, tol):
    """Move a statically indeterminate split into the stuck members' bounds (one redundant loop).

    Where stuck members lock the same motion (a bearing and a stuck lossy gear on one shaft, two clutches in
    parallel) ``A`` has a null vector ``v`` and every ``lam + z v`` balances the network.  The members hold as long
    as some ``z`` keeps each within its bounds (a lossy gear's hold within its band, which depends on the torque
    it carries); ``z`` is kept at 0 (the split of the regularised solution) unless that leaves the feasible
    segment of ``z`` nearest to it or comes within 1 % of its width of an edge: it is then clamped there, so every
    member keeps a margin until the segment closes (the group must slip).  ``v`` is the null vector of ``A`` from
    Gaussian elimination with complete pivoting (:func:`_null_vector`, exact to rounding, so ``lam + z v`` keeps the
    constraints); a set without a null direction, or with more than one, is left as it is.  Returns True if ``lam``
    changed."""
    if not _null_vector_cached(p, A, ns, S, cp, v, tmp):
        return False
    # breakpoints of every bound along z (each bound is piecewise linear in z); the feasible segments lie between
    nb = 0
    for k in range(ns):
        rk = int(stuck[k])
        if rk < 0:
            r = -rk - 1
            q = _gear_member(stuck, ns, r)
            if q < 0:
                continue
            eta1, eta2, bf1, bf2, bfa = gear_losses(p, r, 0.0)
            # T_a(z) = -(lam_q + z v_q); L(z) = lam_k + z v_k; pieces L - P(T_a) = 0 and the kinks of P
            for (sl, c0) in ((1.0 - eta1, bf1), (1.0 - 1.0 / eta2, bf2), (1.0 - 1.0 / eta2, -bf2), (1.0 - eta1, -bf1)):
                den = v[k] + sl * v[q]
                if den != 0.0:
                    cand[nb] = -(lam[k] + sl * lam[q] - c0) / den
                    nb += 1
            if v[q] != 0.0:
                cand[nb] = (-bfa - lam[q]) / v[q]
                cand[nb + 1] = (bfa - lam[q]) / v[q]
                nb += 2
        elif v[k] != 0.0:
            if np.isfinite(lo[k]):
                cand[nb] = (lo[k] - lam[k]) / v[k]
                nb += 1
            if np.isfinite(hi[k]):
                cand[nb] = (hi[k] - lam[k]) / v[k]
                nb += 1
    if nb == 0:
        return False
    cs = cand[:nb]
    for i in range(1, nb):   # ascending (insertion sort: a handful of breakpoints, and no allocation)
        c = cs[i]
        j = i - 1
        while j >= 0 and cs[j] > c:
            cs[j + 1] = cs[j]
            j -= 1
        cs[j + 1] = c
    # the segment containing z = 0, or the nearest feasible one: scan the gaps between breakpoints
    best_lo, best_hi, best_d = 0.0, 0.0, np.inf
    for i in range(nb + 1):
        a = -np.inf if i == 0 else cs[i - 1]
        b = np.inf if i == nb else cs[i]
        if b - a <= 0.0:
            continue
        if a == -np.inf:
            zm = b - max(1.0, abs(b))
        elif b == np.inf:
            zm = a + max(1.0, abs(a))
        else:
            zm = 0.5 * (a + b)
        for k in range(ns):
            trial[k] = lam[k] + zm * v[k]
        if not _feasible(p, stuck, ns, trial, lo, hi, tol):
            continue
        # merge with the neighbouring feasible gaps (a breakpoint that is no edge)
        d = 0.0 if a <= 0.0 <= b else min(abs(a), abs(b))
        if d < best_d:
            best_d, best_lo, best_hi = d, a, b
    if best_d == np.inf:
        # no segment: the feasible set may be a single point (a lossy gear whose output is free holds only while
        # it carries nothing); the nearest feasible breakpoint, where the members sit on their bounds (the noise
        # floor of their switching functions keeps those > 0)
        zp, dp = 0.0, np.inf
        for i in range(nb):
            for k in range(ns):
                trial[k] = lam[k] + cs[i] * v[k]
            if _feasible(p, stuck, ns, trial, lo, hi, tol) and abs(cs[i]) < dp:
                zp, dp = cs[i], abs(cs[i])
        if dp == np.inf or zp == 0.0:
            return False
        for k in range(ns):
            lam[k] += zp * v[k]
        return True
    # extend across breakpoints that are not edges of the feasible set
    for i in range(nb):
        if cs[i] == best_hi and i + 1 <= nb:
            nxt = np.inf if i + 1 == nb else cs[i + 1]
            zm = 0.5 * (cs[i] + nxt) if nxt != np.inf else cs[i] + max(1.0, abs(cs[i]))
            for k in range(ns):
                trial[k] = lam[k] + zm * v[k]
            if _feasible(p, stuck, ns, trial, lo, hi, tol):
                best_hi = nxt
    for i in range(nb - 1, -1, -1):
        if cs[i] == best_lo:
            prv = -np.inf if i == 0 else cs[i - 1]
            zm = 0.5 * (cs[i] + prv) if prv != -np.inf else cs[i] - max(1.0, abs(cs[i]))
            for k in range(ns):
                trial[k] = lam[k] + zm * v[k]
            if _feasible(p, stuck, ns, trial, lo, hi, tol):
                best_lo = prv
    if best_lo == -np.inf and best_hi == np.inf:
        return False
    if best_lo != -np.inf and best_hi != np.inf:
        margin = 0.01 * (best_hi - best_lo)
        z = min(max(0.0, best_lo + margin), best_hi - margin)
    elif best_lo != -np.inf:
        z = max(0.0, best_lo + 0.01 * abs(best_lo))
    else:
        z = min(0.0, best_hi - 0.01 * abs(best_hi))
    if z == 0.0:
        return False
    for k in range(ns):
        lam[k] += z * v[k]
    return True


#: the margin [-] a split moved within a statically indeterminate set's bounds keeps from each of them, of its
#: limit's width (:func:`_repair_space`; :func:`_repair` keeps 1 % of the feasible segment's width)
SPACE_MARGIN = 1e-2


@numba.njit(cache=True, nogil=True, _nrt=True)
def _small_solve(M, b, k):
    """Solve ``M[:k, :k] x = b[:k]`` in place into ``b`` (Gaussian elimination with partial pivoting; small ``k``:
    a vertex or an active set of :func:`_repair_space`, at most one more than its null directions);
    False if the matrix is singular to 1e-12 of its largest entry."""
    big = 0.0
    for i in range(k):
        for j in range(k):
            big = max(big, abs(M[i, j]))
    if big == 0.0:
        return False
    for c in range(k):
        piv, pv = c, abs(M[c, c])
        for i in range(c + 1, k):
            if abs(M[i, c]) > pv:
                piv, pv = i, abs(M[i, c])
        if pv <= 1e-12 * big:
            return False
        if piv != c:
            for j in range(k):
                M[c, j], M[piv, j] = M[piv, j], M[c, j]
            b[c], b[piv] = b[piv], b[c]
        for i in range(c + 1, k):
            f = M[i, c] / M[c, c]
            for j in range(c, k):
                M[i, j] -= f * M[c, j]
            b[i] -= f * b[c]
    _back_substitute(M, b, k)
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _back_substitute(U, b, k):
    """Solve ``U[:k, :k] x = b[:k]`` in place into ``b``, ``U`` upper triangular (:func:`_small_solve`'s
    elimination, :func:`_project`'s QR)."""
    for i in range(k - 1, -1, -1):
        acc_ = b[i]
        for j in range(i + 1, k):
            acc_ -= U[i, j] * b[j]
        b[i] = acc_ / U[i, i]


@numba.njit(cache=True, nogil=True, _nrt=True)
def _next_subset(idx, k, m):
    """The next ``k``-subset of ``range(m)`` after ``idx[:k]`` in lexicographic order; False after the last."""
    q = k - 1
    while q >= 0 and idx[q] == m - k + q:
        q -= 1
    if q < 0:
        return False
    idx[q] += 1
    for j in range(q + 1, k):
        idx[j] = idx[j - 1] + 1
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _keeps(G, nc, z, theta, w, h, m, tol):
    """True if ``z`` keeps every one of the ``m`` bounds ``G[i, :nc] . z + theta w[i] <= h[i]`` (to ``tol``, and to
    the rounding of the programme itself: 1e-15 of its largest bound plus ``|z|``, for ``G``'s rows are of unit
    size).  (``tol`` is relative to the torques, which may be 1e-5 N m where the bounds are 1 N m: the solution of an
    active set then misses its own bounds by 1e-16, and no split was taken -- a rigid loop at rest under a 6e-5 N m
    load kept the regularised split, a one-way clutch 2.4e-6 N m the free way at one sample and 0.49 N m the other
    way at the next, #30.)"""
    big = 0.0
    for i in range(m):
        big = max(big, abs(h[i]))
    for f in range(nc):
        big += abs(z[f])
    tol_ = tol + 1e-15 * big
    for i in range(m):
        v_ = theta * w[i]
        for f in range(nc):
            v_ += G[i, f] * z[f]
        if v_ > h[i] + tol_:
            return False
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _hint_at(hint, o, k, m, idx):
    """Read ``k`` bound indices from ``hint[o:o + k]`` into ``idx``; False unless they increase and are below ``m`` (a
    hint of another set, or none yet: the zeros of a new work array)."""
    prev = -1
    for a in range(k):
        v_ = hint[o + a]
        if not (v_ >= 0.0 and v_ < m):
            return False
        i = int(v_)
        if i <= prev or i != v_:
            return False
        idx[a] = i
        prev = i
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _set_hint(hint, o, head, idx, k):
    """Keep ``head`` (a rank or a set's size) and the bounds ``idx[:k]`` as the hint at ``hint[o]``."""
    hint[o] = head
    for a in range(k):
        hint[o + 1 + a] = idx[a]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _span_basis(G, m, d, R, GR, zt):
    """An orthonormal basis ``R[:, :nr]`` of the span of the rows of ``G[:m, :d]`` (Gram-Schmidt, twice) and the rows
    in it, ``GR[:m, :nr]``; returns ``nr``.  (A direction of ``z`` no bound sees -- a member without bounds, a gear's
    torque where its band does not reach -- leaves the largest-margin programme without vertices, so it is solved in
    the span.)"""
    gmax = 0.0
    for i in range(m):
        for f in range(d):
            gmax = max(gmax, abs(G[i, f]))
    nr = 0
    for i in range(m):
        if nr == d:
            break
        for f in range(d):
            zt[f] = G[i, f]
        for _twice in range(2):
            for j in range(nr):
                dot = 0.0
                for f in range(d):
                    dot += zt[f] * R[f, j]
                for f in range(d):
                    zt[f] -= dot * R[f, j]
        nrm = 0.0
        for f in range(d):
            nrm += zt[f] * zt[f]
        nrm = math.sqrt(nrm)
        if nrm > 1e-9 * gmax:
            for f in range(d):
                R[f, nr] = zt[f] / nrm
            nr += 1
    for i in range(m):
        for j in range(nr):
            v_ = 0.0
            for f in range(d):
                v_ += G[i, f] * R[f, j]
            GR[i, j] = v_
    return nr


@numba.njit(cache=True, nogil=True, _nrt=False)
def _basis_rows(GR, w, nr, idx, M, transpose):
    """``M[:nr + 1, :nr + 1]``: the rows ``(GR_i, w_i)`` of the bounds ``idx[:nr + 1]`` (their transpose if
    ``transpose``)."""
    for a in range(nr + 1):
        ri = idx[a]
        for f in range(nr + 1):
            v_ = GR[ri, f] if f < nr else w[ri]
            if transpose:
                M[f, a] = v_
            else:
                M[a, f] = v_


@numba.njit(cache=True, nogil=True, _nrt=False)
def _margin_vertex(GR, w, h, nr, m, idx, M, b, tol):
    """The margin ``theta`` of the vertex where the bounds ``idx[:nr + 1]`` hold with equality (``GR zeta + theta w =
    h``, solved into ``b``: ``zeta``, then ``theta``) if it keeps every bound; -inf if it does not, or if they meet in
    no single point."""
    k1 = nr + 1
    _basis_rows(GR, w, nr, idx, M, False)
    for a in range(k1):
        b[a] = h[idx[a]]
    if _small_solve_outlined(M, b, k1) and _keeps(GR, nr, b, b[nr], w, h, m, tol):
        return b[nr]
    return -np.inf


@numba.njit(cache=True, nogil=True, _nrt=False)
def _margin_optimal(GR, w, nr, idx, M, y):
    """True if the vertex of the bounds ``idx[:nr + 1]`` has the largest margin of its linear programme (max ``theta``
    with ``GR zeta + theta w <= h``): its dual multipliers, ``sum_a y_a (GR_a, w_a) = (0, 1)``, are all >= 0 (to
    rounding)."""
    k1 = nr + 1
    _basis_rows(GR, w, nr, idx, M, True)
    for a in range(k1):
        y[a] = 0.0
    y[nr] = 1.0
    if not _small_solve_outlined(M, y, k1):
        return False
    big = 0.0
    for a in range(k1):
        big = max(big, abs(y[a]))
    for a in range(k1):
        if y[a] < -1e-12 * big:
            return False
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _swapped(base, k, a, r, idx):
    """``idx[:k]``: the bounds ``base[:k]`` with ``base[a]`` replaced by ``r`` (``a == k``: ``r`` added; ``r < 0``:
    ``base[a]`` dropped), in increasing order (the order the enumeration solves them in, so that a set gives the same
    numbers bit for bit however it was found); returns the new size, or -1 if ``r`` is one of ``base`` already."""
    n = 0
    for c in range(k):
        if base[c] == r:
            return -1
        if c != a:
            idx[n] = base[c]
            n += 1
    if r >= 0:
        j = n
        while j > 0 and idx[j - 1] > r:
            idx[j] = idx[j - 1]
            j -= 1
        idx[j] = r
        n += 1
    return n


@numba.njit(cache=True, nogil=True, _nrt=False)
def _margin_at(GR, w, h, nr, m, idx, M, b, y, tol):
    """The margin of the vertex of the bounds ``idx[:nr + 1]`` if it is the optimum (:func:`_margin_vertex`,
    :func:`_margin_optimal`), else -inf."""
    th = _margin_vertex(GR, w, h, nr, m, idx, M, b, tol)
    if th > -np.inf and _margin_optimal(GR, w, nr, idx, M, y):
        return th
    return -np.inf


#: the largest dimension in which the split search enumerates its vertices and active sets where its hint fails (the
#: search every test and thorough draw before the forty-first session was checked against: the largest margin
#: over every vertex that keeps the bounds, which at a band of nearly zero width -- a lossy gear carrying 1e-14 N m
#: -- is the most favourable of vertices that differ by rounding); above it the simplex and active-set methods
#: (:func:`_lp_max`, :func:`_qp_nearest`), whose vertex there may round 1e-8 the other way
ENUMERATED_DIMENSIONS = 3
#: steps of :func:`_lp_max` and :func:`_qp_nearest` per variable and bound before they give up (then the vertices
#: are enumerated): each step adds or drops one bound, so a solve takes about as many steps as it has bounds
ACTIVE_STEPS = 8
#: the rows of the cold solves (:func:`_row_at`): a bound's directions alone (the nearest split), with its width
#: (the largest margin), or with a unit width for the bounds of zero width only (the margin's first phase)
ROW_KINDS = ("plain", "width", "phase_one")
ROWS_PLAIN, ROWS_WIDTH, ROWS_PHASE_ONE = indices(ROW_KINDS, "plain", "width", "phase_one")


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _row_at(A, wv, i, f, nc, mode):
    """Entry ``f`` of bound ``i``'s row: ``A[i, f]`` for the ``nc`` columns of ``A``, then (``mode`` not
    ``ROWS_PLAIN``) its width ``wv[i]``, or 1 in the first phase (:data:`ROWS_PHASE_ONE`)."""
    if f < nc:
        return A[i, f]
    return wv[i] if mode == ROWS_WIDTH else 1.0


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _ncols(nc, mode):
    """The rows' length (:func:`_row_at`)."""
    return nc if mode == ROWS_PLAIN else nc + 1


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _skipped(wv, i, mode):
    """True for a bound the first phase leaves out (one of nonzero width: any margin low enough keeps it)."""
    return mode == ROWS_PHASE_ONE and wv[i] > 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _orthogonalise(Q, j, n, R, record):
    """Column ``j`` of ``Q[:n]`` made orthogonal to its columns before it (Gram-Schmidt, twice; the coefficients
    added into ``R[:j, j]`` where ``record``); returns the norm left of it (:func:`_qr`, :func:`_repair_space`'s
    null-space basis)."""
    for _twice in range(2):
        for i in range(j):
            dot = 0.0
            for f in range(n):
                dot += Q[f, i] * Q[f, j]
            if record:
                R[i, j] += dot
            for f in range(n):
                Q[f, j] -= dot * Q[f, i]
    nrm = 0.0
    for f in range(n):
        nrm += Q[f, j] * Q[f, j]
    return math.sqrt(nrm)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _qr(A, wv, nc, mode, W, k, Q, R):
    """``A_W^T = Q R`` for the rows ``W[:k]`` (:func:`_row_at`): ``Q[:n, :k]`` orthonormal columns, ``R[:k, :k]``
    upper triangular (modified Gram-Schmidt, twice).  False if a row depends on those before it (what is left of it
    below 1e-13 of its norm).  (Not the normal equations: a lossy gear's band of nearly zero width gives two bounds
    of nearly opposite rows, whose normal matrix is singular to rounding where their QR is not.)"""
    n = _ncols(nc, mode)
    for j in range(k):
        nrm0 = 0.0
        for f in range(n):
            v_ = _row_at(A, wv, W[j], f, nc, mode)
            Q[f, j] = v_
            nrm0 += v_ * v_
        nrm0 = math.sqrt(nrm0)
        for i in range(k):
            R[i, j] = 0.0
        nrm = _orthogonalise(Q, j, n, R, True)
        if not nrm > 1e-13 * nrm0:
            return False
        R[j, j] = nrm
        for f in range(n):
            Q[f, j] /= nrm
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _project(A, wv, nc, mode, W, k, v, p, u, Q, R, known):
    """``p``: ``v`` projected onto the null space of the rows ``W[:k]`` (:func:`_row_at`), ``u`` the multipliers of
    that projection (``v - p = A_W^T u``; where ``p`` is zero, ``v = A_W^T u``; ``v`` and ``p`` may be one array),
    through their QR (:func:`_qr`; ``known``: ``Q``, ``R`` hold it already).  False if the rows are dependent."""
    n = _ncols(nc, mode)
    if not known and not _qr(A, wv, nc, mode, W, k, Q, R):
        return False
    for a in range(k):
        t_ = 0.0
        for f in range(n):
            t_ += Q[f, a] * v[f]
        u[a] = t_
    for f in range(n):
        s_ = v[f]
        for a in range(k):
            s_ -= Q[f, a] * u[a]
        p[f] = s_
    _back_substitute(R, u, k)   # R u = Q^T v
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _polish(A, wv, h, nc, mode, W, k, x, u, Q, R, known):
    """``x`` moved onto the bounds held, ``W[:k]``, by the least correction (``x += Q y``, ``R^T y = h_W - A_W x``),
    twice: the steps leave their rounding in ``x``, and the ratio tests read it.  Their QR from :func:`_qr` (or
    ``Q``, ``R`` where ``known``); returns True if ``Q``, ``R`` hold it after (the next projection then reuses it)."""
    n = _ncols(nc, mode)
    if k == 0 or not (known or _qr(A, wv, nc, mode, W, k, Q, R)):
        return False
    for _twice in range(2):
        for a in range(k):
            s_ = h[W[a]]
            for f in range(n):
                s_ -= _row_at(A, wv, W[a], f, nc, mode) * x[f]
            for c in range(a):
                s_ -= R[c, a] * u[c]
            u[a] = s_ / R[a, a]
        for f in range(n):
            for a in range(k):
                x[f] += Q[f, a] * u[a]
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _kept(A, wv, h, nc, mode, m, x, tol):
    """True if ``x`` keeps every bound to ``tol`` and the rounding of the bounds' and the point's sizes (1e-15 of
    them: :func:`_keeps`'s test, which the enumeration applies to its vertices; the invariant check holds a stuck
    member to its limit within the torques' rounding)."""
    n = _ncols(nc, mode)
    big = 0.0
    for i in range(m):
        big = max(big, abs(h[i]))
    for f in range(n):
        big += abs(x[f])
    for i in range(m):
        if _skipped(wv, i, mode):
            continue
        v_ = 0.0
        for f in range(n):
            v_ += _row_at(A, wv, i, f, nc, mode) * x[f]
        if v_ > h[i] + tol + 1e-15 * big:
            return False
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _blocking(A, wv, h, nc, mode, m, W, k, x, p, pn):
    """The ratio test of a step ``x + alpha p`` (``|p| = pn``) within the bounds ``row_i . x <= h_i``: the first bound
    not in ``W[:k]`` it reaches (the lowest index among ties: Bland's rule) and ``alpha``; ``(-1, inf)`` if none
    lies ahead."""
    n = _ncols(nc, mode)
    alpha = np.inf
    j = -1
    for i in range(m):
        if _skipped(wv, i, mode):
            continue
        inw = False
        for a in range(k):
            if W[a] == i:
                inw = True
        if inw:
            continue
        ap = 0.0
        ax = 0.0
        an = 0.0
        for f in range(n):
            r_ = _row_at(A, wv, i, f, nc, mode)
            ap += r_ * p[f]
            ax += r_ * x[f]
            an += r_ * r_
        if ap <= 1e-13 * math.sqrt(an) * pn:
            continue
        a_ = max(h[i] - ax, 0.0) / ap
        if a_ < alpha:
            alpha = a_
            j = i
    return j, alpha


@numba.njit(cache=True, nogil=True, _nrt=False)
def _norm(p, n):
    """The Euclidean norm of ``p[:n]``."""
    s_ = 0.0
    for f in range(n):
        s_ += p[f] * p[f]
    return math.sqrt(s_)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _leaving(A, wv, nc, mode, u, W, k, scale):
    """The bound held whose multiplier is negative, the one of lowest index (Bland's rule); -1 if none (optimal).
    Negative: ``u_a |row_a| < -1e-12 scale``, ``scale`` the size of the gradient the multipliers balance (1 for the
    margin, ``|z|`` for the nearest split): a multiplier's own size follows its row's, and relative to the largest
    multiplier (the test before) a truly negative one was taken for zero where two nearly opposite bounds (a lossy
    gear's band of nearly zero width) held multipliers of 1e12, and a vertex 5e-9 below the optimum was kept."""
    n = _ncols(nc, mode)
    q = -1
    for a in range(k):
        rn = 0.0
        for f in range(n):
            r_ = _row_at(A, wv, W[a], f, nc, mode)
            rn += r_ * r_
        if u[a] * math.sqrt(rn) < -1e-12 * scale and (q < 0 or W[a] < W[q]):
            q = a
    return q


@numba.njit(cache=True, nogil=True, _nrt=False)
def _sort_ints(idx, k):
    """``idx[:k]`` in increasing order (insertion sort: a hint's bounds, :func:`_hint_at`)."""
    for a in range(1, k):
        v_ = idx[a]
        c = a
        while c > 0 and idx[c - 1] > v_:
            idx[c] = idx[c - 1]
            c -= 1
        idx[c] = v_


@numba.njit(cache=True, nogil=True, _nrt=False)
def _step_onto(A, wv, h, nc, mode, W, k, x, p, alpha, j, u, M, R):
    """A step of :func:`_ascend` or :func:`_qp_nearest`: ``x += alpha p`` onto bound ``j``, which joins the bounds
    held (``W[k]``), and ``x`` put back on them (:func:`_polish`); returns their number and whether ``M``, ``R``
    hold their QR."""
    for f in range(_ncols(nc, mode)):
        x[f] += alpha * p[f]
    W[k] = j
    return k + 1, _polish(A, wv, h, nc, mode, W, k + 1, x, u, M, R, False)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _ascend(A, wv, h, nc, mode, m, stop, W, k, x, p, u, M, R, tol):
    """The simplex steps of :func:`_lp_max` from ``x`` (which keeps every bound) holding ``W[:k]``: ``(theta, k)``."""
    n = nc + 1
    known = False   # (whether M, R hold the QR of the bounds held: computed once per set of them)
    for _it in range(ACTIVE_STEPS * (m + n) + 20):
        if x[nc] >= stop:
            if not _kept(A, wv, h, nc, mode, m, x, tol):
                return np.nan, 0
            return x[nc], k
        for f in range(n):
            p[f] = 0.0
        p[nc] = 1.0
        if not _project(A, wv, nc, mode, W, k, p, p, u, M, R, known):
            return np.nan, 0
        known = True
        pn = _norm(p, n)   # (|c| = 1)
        if k >= n or pn <= 1e-10:   # the gradient lies in the span of the bounds held: their multipliers decide
            q = _leaving(A, wv, nc, mode, u, W, k, 1.0)
            if q < 0:   # (the point on the bounds held, free of the path's rounding: at a vertex, its solution)
                _polish(A, wv, h, nc, mode, W, k, x, u, M, R, True)
                if not _kept(A, wv, h, nc, mode, m, x, tol):
                    return np.nan, 0
                return x[nc], k
            W[q] = W[k - 1]
            k -= 1
            known = False
            continue
        j, alpha = _blocking(A, wv, h, nc, mode, m, W, k, x, p, pn)
        if j < 0:
            if stop < np.inf:   # (unbounded: step to the margin asked for)
                alpha = (stop - x[nc]) / p[nc]
                for f in range(n):
                    x[f] += alpha * p[f]
                x[nc] = stop
                return stop, k
            return np.inf, 0
        k, known = _step_onto(A, wv, h, nc, mode, W, k, x, p, alpha, j, u, M, R)
    return np.nan, 0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _lp_max(A, wv, h, nc, m, stop, W, x, p, u, M, R, tol):
    """``max theta`` over ``x = (zeta, theta)`` with ``A_i . zeta + theta wv_i <= h_i`` for the ``m`` bounds
    (``wv >= 0``), by the primal active-set (simplex) method with Bland's rule.  A first phase finds a ``zeta``
    that keeps the bounds of zero width (a one-way clutch's free side: no margin relaxes it), the same method on
    them alone with unit widths, from ``zeta = 0``; none: ``-inf`` (no split holds).  Then from that ``zeta`` and the
    largest margin there, which keeps every bound: a step along the objective's gradient projected onto the bounds
    held (``W``) to the first bound it reaches, which joins them; where the gradient lies in their span, the one of
    lowest index whose multiplier is negative leaves them (none: optimal).  Stops early once ``theta >= stop``.
    Returns ``(theta, k)``, ``W[:k]`` the bounds held at the end (``k = nc + 1``: a vertex), ``x`` the point;
    ``(inf, 0)`` if unbounded; ``(nan, 0)`` if it did not end within :data:`ACTIVE_STEPS` steps per variable and
    bound, met dependent bounds or ended off its bounds (the caller then enumerates).

    The cold start of :func:`_combo_margin` and :func:`_combo_nearest` where their hints fail (forty-first
    session): a few steps of small solves, where enumerating the vertices costs ``C(m, nc + 1)`` of them (four
    null directions and more)."""
    n = nc + 1
    for f in range(n):
        x[f] = 0.0
    t0 = np.inf
    j = -1
    for i in range(m):
        if wv[i] <= 0.0 and h[i] < t0:
            t0 = h[i]
            j = i
    if t0 < 0.0:   # a bound of zero width fails at zeta = 0: the first phase
        x[nc] = t0
        W[0] = j
        t1, k = _ascend(A, wv, h, nc, ROWS_PHASE_ONE, m, 0.0, W, 1, x, p, u, M, R, tol)
        if t1 != t1:
            return np.nan, 0
        if t1 < 0.0:
            return -np.inf, 0
    th = np.inf
    j = -1
    for i in range(m):
        if wv[i] > 0.0:
            v_ = h[i]
            for f in range(nc):
                v_ -= A[i, f] * x[f]
            if v_ / wv[i] < th:
                th = v_ / wv[i]
                j = i
    if j < 0:
        return np.inf, 0   # (no bound has a width: any margin)
    x[nc] = th
    W[0] = j
    return _ascend(A, wv, h, nc, ROWS_WIDTH, m, stop, W, 1, x, p, u, M, R, tol)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _qp_nearest(G, hb, d, m, W, k, z, p, u, M, R, tol):
    """The least ``|z|`` with ``G_i . z <= hb_i`` for the ``m`` bounds, by the primal active-set method from ``z``
    (which keeps every bound) holding ``W[:k]``: a step to the least ``|z|`` on the bounds held (``z`` projected
    onto their null space), shortened to the first bound it reaches, which joins them; where it does not move, the
    bound of lowest index whose multiplier has the wrong sign leaves them (none: optimal; the programme is strictly
    convex, so that optimum is the one).  Returns ``(|z|^2, k)``, ``W[:k]`` the bounds held at the optimum; ``(nan,
    0)`` if it did not end within :data:`ACTIVE_STEPS` steps per variable and bound, met dependent bounds or ended
    off its bounds."""
    big = 0.0   # (the problem's scale: the bounds' rows are of unit size, so the splits are of the bounds' size)
    for i in range(m):
        big = max(big, abs(hb[i]))
    known = False   # (whether M, R hold the QR of the bounds held)
    for _it in range(ACTIVE_STEPS * (m + d) + 20):
        for f in range(d):
            p[f] = -z[f]
        if not _project(G, hb, d, ROWS_PLAIN, W, k, p, p, u, M, R, known):
            return np.nan, 0
        known = True
        pn = _norm(p, d)
        scale = max(_norm(z, d), big)
        if k >= d or pn <= 1e-13 * scale:
            # at the least |z| on the bounds held (to the rounding of the problem's size, not of |z|: a split at
            # 1e-14 N m beside bounds of 1 N m moved by rounding noise onto a bound opposite one held, which then
            # could not join it); -z = G_W^T u, and a held bound with u < 0 pulls the wrong way
            q = _leaving(G, hb, d, ROWS_PLAIN, u, W, k, scale)
            if q < 0:
                if not _kept(G, hb, hb, d, ROWS_PLAIN, m, z, tol):
                    return np.nan, 0
                return _norm(z, d) ** 2, k
            W[q] = W[k - 1]
            k -= 1
            known = False
            continue
        j, alpha = _blocking(G, hb, hb, d, ROWS_PLAIN, m, W, k, z, p, pn)
        if alpha >= 1.0 or j < 0:
            for f in range(d):
                z[f] += p[f]
            continue
        if k >= d:   # (no bound can join d independent ones: rounding)
            return np.nan, 0
        k, known = _step_onto(G, hb, hb, d, ROWS_PLAIN, W, k, z, p, alpha, j, u, M, R)
    return np.nan, 0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _combo_margin(GR, w, h, nr, m, idx, base, M, b, y, sc, R, hint, o, tol, small):
    """The largest margin ``theta`` any split keeps under one combination of pieces: a linear programme in ``(zeta,
    theta)`` over ``m`` bounds in ``nr`` dimensions, solved at a vertex.  Warm: the vertex of the hint (``hint[o]``
    the rank, ``hint[o + 1:o + nr + 2]`` its bounds) is taken where it is the optimum, certified by its dual
    multipliers (:func:`_margin_at`).  Where it is not: for a set of at most :data:`ENUMERATED_DIMENSIONS` null
    directions (``small``), the vertices one bound away from it (the optimum moved by one pivot), then every
    vertex; for more, the simplex method from the hint where
    it keeps every bound (:func:`_ascend`: a pivot or two, the torques having moved a little), else from its cold
    start (:func:`_lp_max`; ``sc[0]`` and ``R`` their scratch), and every vertex only where that fails (enumerating
    costs ``C(m, nr + 1)`` solves: 3 s for one simulated second of a loop with six null directions).  The optimum's
    bounds become the hint.  +inf with fewer bounds than ``nr + 1`` (independent bounds: any margin is kept)."""
    k1 = nr + 1
    if m < k1:
        return np.inf
    if hint[o] == nr and _hint_at(hint, o + 1, k1, m, base):
        for c in range(k1):
            idx[c] = base[c]
        th = _margin_at(GR, w, h, nr, m, idx, M, b, y, tol)
        if th > -np.inf:
            return th
        if small:
            for a in range(k1):
                for r in range(m):
                    if _swapped(base, k1, a, r, idx) < 0:
                        continue
                    th = _margin_at(GR, w, h, nr, m, idx, M, b, y, tol)
                    if th > -np.inf:
                        _set_hint(hint, o, nr, idx, k1)
                        return th
        else:
            for c in range(k1):
                idx[c] = base[c]
            if _margin_vertex(GR, w, h, nr, m, idx, M, b, tol) > -np.inf:
                th, k = _ascend(GR, w, h, nr, ROWS_WIDTH, m, np.inf, idx, k1, b, sc[0], y, M, R, tol)
                if th == th:
                    if k == k1:
                        _sort_ints(idx, k)
                        _set_hint(hint, o, nr, idx, k1)
                    return th
    if not small:
        th, k = _lp_max(GR, w, h, nr, m, np.inf, idx, b, sc[0], y, M, R, tol)
        if th == th:
            if k == k1:
                _sort_ints(idx, k)
                _set_hint(hint, o, nr, idx, k1)
            return th
    best = -np.inf
    for j in range(k1):
        idx[j] = j
    while True:
        th = _margin_vertex(GR, w, h, nr, m, idx, M, b, tol)
        if th > best:
            best = th
            _set_hint(hint, o, nr, idx, k1)
        if not _next_subset(idx, k1, m):
            break
    return best


@numba.njit(cache=True, nogil=True, _nrt=False)
def _active_split(G, d, h, w, theta, idx, k, M, b, z):
    """The least ``z`` on which the bounds ``idx[:k]`` hold with margin ``theta`` exactly: ``z = G_S^T mu`` with
    ``(G_S G_S^T) mu = h_S - theta w_S`` (``mu`` into ``b``); False if those bounds are dependent."""
    for a in range(k):
        for c in range(k):
            v_ = 0.0
            for f in range(d):
                v_ += G[idx[a], f] * G[idx[c], f]
            M[a, c] = v_
        b[a] = h[idx[a]] - theta * w[idx[a]]
    if not _small_solve_outlined(M, b, k):
        return False
    for f in range(d):
        v_ = 0.0
        for a in range(k):
            v_ += G[idx[a], f] * b[a]
        z[f] = v_
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _nearest_at(G, d, h, w, theta, m, idx, k, M, b, z, tol):
    """``|z|^2`` of the split on which the bounds ``idx[:k]`` hold with margin ``theta`` (:func:`_active_split`; ``k
    = 0``: ``z = 0``) if it is the optimum of :func:`_combo_nearest`: it keeps every bound and its multipliers have
    the optimum's sign (``z = -G_S^T nu`` with ``nu >= 0``, the Karush-Kuhn-Tucker conditions of a convex programme);
    else inf."""
    for f in range(d):
        z[f] = 0.0
    if k > 0:
        if not _active_split(G, d, h, w, theta, idx, k, M, b, z):
            return np.inf
        big = 0.0
        for a in range(k):
            big = max(big, abs(b[a]))
        for a in range(k):
            if b[a] > 1e-12 * big:
                return np.inf
    if not _keeps(G, d, z, theta, w, h, m, tol):
        return np.inf
    nz = 0.0
    for f in range(d):
        nz += z[f] * z[f]
    return nz


@numba.njit(cache=True, nogil=True, _nrt=False)
def _nearest_from(G, d, h, w, theta, m, idx, k, M, b, z, sc, R, hint, o, tol):
    """:func:`_qp_nearest` from the split ``z`` (which keeps every bound at margin ``theta``) holding ``idx[:k]``, the
    bounds shifted by the margin into ``sc[1]``; its optimum's set becomes the hint.  Returns ``|z|^2`` (nan: it
    failed)."""
    hb = sc[1]
    for i in range(m):
        hb[i] = h[i] - theta * w[i]
    nz, k = _qp_nearest(G, hb, d, m, idx, k, z, sc[0], b, M, R, tol)
    if nz == nz:
        _sort_ints(idx, k)
        _set_hint(hint, o, k, idx, k)
    return nz


@numba.njit(cache=True, nogil=True, _nrt=False)
def _combo_nearest(G, d, h, w, theta, m, idx, base, M, b, zt, z, sc, R, hint, o, tol, small):
    """The nearest split that keeps margin ``theta`` under one combination of pieces: the least ``|z|`` with ``G z +
    theta w <= h`` (a convex quadratic programme in ``d`` dimensions), into ``z``; returns ``|z|^2`` (inf: no
    split keeps it).  Warm: the hint's active set (``hint[o]`` its size, ``hint[o + 1:]`` its bounds) is taken where
    its split is the optimum (:func:`_nearest_at`).  Where it is not: for a set of at most
    :data:`ENUMERATED_DIMENSIONS` null directions (``small``, as :func:`_combo_margin`), the sets one bound away
    from it (one bound dropped, added or swapped); for more, the active-set method from the hint's split where it
    keeps every bound (:func:`_qp_nearest`).  Else ``z = 0`` where it keeps every bound; else, where ``small``, the
    least ``|z|`` over the active sets of 1..d bounds, and for more the active-set method from a split that keeps
    ``theta``, found by :func:`_lp_max` (``sc[0]``, ``sc[1]``, ``R``: their scratch), enumerating only where that
    fails.  The optimum's set becomes the hint."""
    kh = hint[o]
    if kh >= 0.0 and kh <= d and kh == math.floor(kh) and _hint_at(hint, o + 1, int(kh), m, base):
        k = int(kh)
        for c in range(k):
            idx[c] = base[c]
        nz = _nearest_at(G, d, h, w, theta, m, idx, k, M, b, z, tol)
        if nz < np.inf:
            return nz
        if small:
            for a in range(k + 1):
                for r in range(-1, m):
                    if a == k and (r < 0 or k == d):
                        continue
                    kk = _swapped(base, k, a, r, idx)
                    if kk < 0:
                        continue
                    nz = _nearest_at(G, d, h, w, theta, m, idx, kk, M, b, z, tol)
                    if nz < np.inf:
                        _set_hint(hint, o, kk, idx, kk)
                        return nz
        else:
            for c in range(k):
                idx[c] = base[c]
            for f in range(d):
                z[f] = 0.0
            if (k == 0 or _active_split(G, d, h, w, theta, idx, k, M, b, z)) and _keeps(G, d, z, theta, w, h, m,
                                                                                           tol):
                nz = _nearest_from(G, d, h, w, theta, m, idx, k, M, b, z, sc, R, hint, o, tol)
                if nz == nz:
                    return nz
    for f in range(d):
        z[f] = 0.0
    if _keeps(G, d, z, theta, w, h, m, tol):
        hint[o] = 0.0
        return 0.0
    th, k = (np.nan, 0) if small else _lp_max(G, w, h, d, m, theta, idx, zt, sc[0], b, M, R, tol)
    if th == th and th < np.inf:
        if th < theta:
            return np.inf   # (no split keeps theta)
        for f in range(d):
            z[f] = zt[f]
        nz = _nearest_from(G, d, h, w, theta, m, idx, 0, M, b, z, sc, R, hint, o, tol)
        if nz == nz:
            return nz
    best = np.inf
    for k in range(1, d + 1):
        if m < k:
            break
        for j in range(k):
            idx[j] = j
        while True:
            if _active_split(G, d, h, w, theta, idx, k, M, b, zt):
                nz = 0.0
                for f in range(d):
                    nz += zt[f] * zt[f]
                if nz < best and _keeps(G, d, zt, theta, w, h, m, tol):
                    best = nz
                    for f in range(d):
                        z[f] = zt[f]
                    _set_hint(hint, o, k, idx, k)
            if not _next_subset(idx, k, m):
                break
    return best


@numba.njit(cache=True, nogil=True, _nrt=False)
def _piece_bound(t, piece, gk, gq, gl, gw, V, lam, d, row, G, h, w):
    """Bound ``t`` of the stuck lossy gears (``t // 2`` the gear; even: its band's upper edge, odd: the lower) on
    its piece ``piece`` (0 or 1: the edge's first or second line, :func:`gear_band`), into row ``row`` of ``G z <=
    h`` with width ``w``: the hold ``L = lam_k + V_k z`` within ``s T_a + c`` of the line, ``T_a = -(lam_q + V_q
    z)``."""
    j = t // 2
    k, q = gk[j], gq[j]
    if t % 2 == 0:
        sl, c0 = gl[j, piece, 0], gl[j, piece, 1]
        for f in range(d):
            G[row, f] = V[k, f] + sl * V[q, f]
        h[row] = c0 - lam[k] - sl * lam[q]
    else:
        sl, c0 = gl[j, 2 + piece, 0], gl[j, 2 + piece, 1]
        for f in range(d):
            G[row, f] = -(V[k, f] + sl * V[q, f])
        h[row] = lam[k] + sl * lam[q] - c0
    w[row] = gw[j]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _combo_bounds(comb, ng, gk, gq, gl, gw, gc, V, lam, d, mf, G, h, w):
    """The stuck lossy gears' bounds under combination ``comb`` of their band pieces (per gear two digits in base 2,
    its upper and lower edge's line: :func:`_pieces_code`; -1: the pieces of the torques they carry now, ``gc``),
    into rows ``mf`` on of ``G z <= h`` with widths ``w`` (:func:`_piece_bound`)."""
    cc = comb
    for j in range(ng):
        if comb >= 0:
            up, dn = cc % 2, (cc // 2) % 2
        else:
            up, dn = gc[2 * j], gc[2 * j + 1]
        cc //= 4
        _piece_bound(2 * j, up, gk, gq, gl, gw, V, lam, d, mf + 2 * j, G, h, w)
        _piece_bound(2 * j + 1, dn, gk, gq, gl, gw, V, lam, d, mf + 2 * j + 1, G, h, w)


#: the largest margin a stuck set keeps (:func:`_repair_space`, a fraction of its members' widths) below which it is
#: a rounding of zero: the split found (or, where none keeps half of it, the split that holds with no margin) is
#: looked at for a lossy gear whose band is closed there (a self-locking gear whose output is free holds only while
#: it carries nothing), which then keeps its band with no margin while the others keep theirs (:func:`_close_bands`).
#: Asked to keep half of the 9e-33 the rounding left, the nearest-split programme found none and the split was left
#: outside the bands: a gear between two self-locking ones was released and rolled at zero speed, pinned by its
#: neighbours, at four tolerances of five (random draws seed 2125, #30)
THETA_FLOOR = 1e-12
#: a largest margin below zero by less than this is a rounding of zero (:func:`_repair_space`)
THETA_ROUND = 1e-24


#: the largest margin the search over every gear's pieces (:func:`_pieces_margin`) needs to know: beyond twice
#: ``SPACE_MARGIN`` the margin kept is ``SPACE_MARGIN`` whatever it is (a bound ``theta <= PIECES_CAP``, which also
#: keeps the programmes of its partial combinations, where a gear's edge is not yet bounded, from growing without
#: bound)
PIECES_CAP = 2.0 * SPACE_MARGIN


@numba.njit(cache=True, nogil=True, _nrt=False)
def _pieces_margin(ng, gk, gq, gl, gw, V, lam, d, mf, G, h, w, best, dig, idx, base, M, b, yb, zt, R, GR, sc, Rq,
                   bh, tol, small):
    """The largest margin (up to :data:`PIECES_CAP`) any split keeps over **every** combination of the pieces of
    three or more stuck lossy gears (``4**ng`` linear programmes: :func:`_combo_margin`), by branch and bound: a
    depth-first search over the gears' edges, one digit (the edge's line) at a time, each partial combination's
    programme (the bounds chosen so far, the gears' other edges dropped: a relaxation, so its margin bounds every
    combination below it) pruned where it cannot beat ``best`` (the margin of the pieces of the torques the gears
    carry now, or the last combination that held the set), and where it cannot hold the set (below zero: only
    whether any combination holds it matters there).  Rows: the friction members' ``mf``, the cap, then
    one per digit.  The programmes start cold (``bh``: a scratch warm start, cleared before each).  Returns the
    largest margin found above ``best`` and its combination's code (:func:`_pieces_code`), else ``best`` and -1."""
    nd = 2 * ng
    row0 = mf + 1
    for f in range(d):
        G[mf, f] = 0.0
    h[mf] = PIECES_CAP
    w[mf] = 1.0
    for t in range(nd):
        dig[t] = -1
    code = -1
    depth = 0
    while depth >= 0:
        if best >= PIECES_CAP:
            break
        dig[depth] += 1
        if dig[depth] > 1:
            dig[depth] = -1
            depth -= 1
            continue
        _piece_bound(depth, dig[depth], gk, gq, gl, gw, V, lam, d, row0 + depth, G, h, w)
        m = row0 + depth + 1
        nr = _span_basis(G, m, d, R, GR, zt)
        bh[0] = -1.0
        th = _combo_margin(GR, w, h, nr, m, idx, base, M, b, yb, sc, Rq, bh, 0, tol, small)
        if not (th > best and th >= 0.0):
            continue   # (nothing below it beats the best or holds the set: pruned)
        if depth == nd - 1:
            best = th
            code = _pieces_code(ng, dig)
            continue
        depth += 1
    return best, code


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _pieces_code(ng, dig):
    """The code of a combination of the pieces of ``ng`` stuck lossy gears, ``dig[2 j]`` the line of gear ``j``'s
    upper edge and ``dig[2 j + 1]`` its lower edge's: ``sum (up + 2 dn) 4**j`` (:func:`_combo_bounds` reads it)."""
    code = 0
    scale = 1
    for j in range(ng):
        code += (dig[2 * j] + 2 * dig[2 * j + 1]) * scale
        scale *= 4
    return code


@numba.njit(cache=True, nogil=True, _nrt=False)
def _close_bands(p, stuck, ng, gk, gq, gw, V, lam, z, d, tol):
    """Zero width (:func:`_repair_space`'s second round) for each stuck lossy gear whose band is closed, to 1e3 ``tol``,
    at the split ``lam + V z``: a self-locking gear whose output is free can carry only nothing, its band's two edges
    meeting there, so every split that holds the set keeps it on its band with no margin, and a margin asked of it
    asks none of the others (the largest margin the set keeps is then 0).  A bound of zero width is kept with no
    margin, as a one-way clutch's free side (:func:`_lp_max`), and the margin is the other members'.  Returns True
    if a width changed.  (Random draws seed 2125: such a gear beside a non-locking gear between two self-locking
    ones; with no margin the nearest split put the middle gear on its band's edge, and it was released there, at
    one tolerance of five, to roll at zero speed pinned by its neighbours, #30.)"""
    changed = False
    for j in range(ng):
        if gw[j] == 0.0:
            continue
        k, q = gk[j], gq[j]
        r = -int(stuck[k]) - 1
        ta = lam[q]
        for f in range(d):
            ta += V[q, f] * z[f]
        lo, hi = gear_band(p, r, -ta)
        # (closed to a thousand of the repair's roundings: the split the probe finds holds the others a rounding of
        # their widths beyond their bounds, which left such a gear's band 1.5 roundings wide, read as open, and the
        # set slipping at one evaluation in ten of its stuck state, random draws seed 2261's search)
        if hi - lo <= 1e3 * tol:
            gw[j] = 0.0
            changed = True
    return changed


@numba.njit(cache=True, nogil=True, _nrt=True)
def _repair_space(p, stuck, ns, A, lam, lo, hi, tol):
    """:func:`_repair` where a statically indeterminate set has two or more null directions (a rigid loop with a
    bearing friction and two stuck lossy gears: seven members on four inertias, three; a second bearing friction on
    it, four).

    Every ``lam + V z`` (``V`` an orthonormal basis of ``A``'s null space) balances the network.  The bounds are
    linear in ``z``: a friction member's ``lo <= lam <= hi``; a stuck lossy gear's hold within its band, whose upper
    edge is the larger of two lines in the torque it carries and whose lower edge the smaller (:func:`gear_band`),
    so that the band is the union of four convex pieces, each bounded by one line per edge: every combination of
    the gears' pieces is searched (with up to two stuck lossy gears one by one, each with its warm start; with more,
    the pieces of the torques they carry now, where they keep less than :data:`PIECES_CAP` the last combination
    that held the set, and where that keeps less too every combination by branch and bound, :func:`_pieces_margin`:
    before the forty-second session only the current pieces were searched, and a gear rolled where another piece
    held the set; the margin kept and the nearest split are then those of the combination found).  The split is
    kept where it keeps ``theta`` of each member's width (its limit's span, its band's width) from its bounds,
    ``theta`` 1 % or half the largest margin any split has (a linear programme over ``z`` and ``theta`` per combination,
    :func:`_combo_margin`; where that is below :data:`THETA_FLOOR`, a rounding of zero, a gear whose band is closed
    at the split found keeps it with no margin, and the others keep theirs, in a second round: :func:`_close_bands`),
    and otherwise moved to the nearest split that does (the least ``|V z|``, a quadratic
    programme per combination, :func:`_combo_nearest`): continuous in the torques while one combination of pieces
    holds the set (it may move to another where that one closes), and every member keeps a margin until no split
    holds (the group must slip; the split is then left as it is, for :func:`settle` to decide).

    Both programmes start warm: each combination's last optimal vertex and active set (``WorkLayout.sp``) are tried
    first and kept where their optimality conditions hold (the dual multipliers' signs), so that the answer is the
    optimum whatever the hint.  Where they fail: with at most :data:`ENUMERATED_DIMENSIONS` null directions, the
    sets one bound away, then every vertex and active set; with more (the work array's warm start is sized for any
    number, :func:`space_hint`), the simplex and active-set methods from the hint where it keeps every bound, else
    from their cold start (:func:`_lp_max`, :func:`_qp_nearest`), enumerating only where those fail (forty-first
    session; before, a set of more than three null directions kept its regularised split, and a member was
    released while another split held the set).  The optimum is certified only to ``tol``, so at a group's
    edge whether it holds may follow the hints: an observer's evaluation (the outputs at a sample, the invariant
    check: :func:`observe`) reads them from a copy and leaves them as they were, so that no sample and no check
    changes a decision.  Returns True if ``lam`` changed."""
    if ns < 3:
        return False
    # ---- an orthonormal basis of the null space
    S = np.empty((ns, ns))
    cp = np.empty(ns, dtype=np.int64)
    rank = _eliminate_outlined(A, ns, S, cp)
    if rank == 0:
        return False
    d = ns - rank
    if d < 2:
        return False
    V = np.zeros((ns, d))
    y = np.empty(ns)
    for f in range(d):
        for i in range(ns):
            y[i] = 0.0
        y[rank + f] = 1.0
        for i in range(rank - 1, -1, -1):
            acc_ = 0.0
            for j in range(i + 1, ns):
                acc_ += S[i, j] * y[j]
            y[i] = -acc_ / S[i, i]
        for i in range(ns):
            V[cp[i], f] = y[i]
    for f in range(d):
        nrm = _orthogonalise(V, f, ns, V, False)
        if nrm == 0.0:
            return False
        for i in range(ns):
            V[i, f] /= nrm
    # ---- the bounds G z <= h, each with its width w: the friction members' first (fixed), then two per stuck lossy
    # gear: its band's upper edge is the larger of two lines in the torque it carries, the lower the smaller, so
    # the band is the union of four convex pieces (one line each): every combination of pieces is searched
    mm = 2 * ns + 1   # (and a row for the search over every gear's pieces: _pieces_margin's cap)
    G = np.zeros((mm, d))
    h = np.empty(mm)
    w = np.empty(mm)
    gk = np.empty(ns, dtype=np.int64)     # per stuck lossy gear: its hold member, its gear member
    gq = np.empty(ns, dtype=np.int64)
    gl = np.empty((ns, 4, 2))            # its lines (slope, offset): upper 1, upper 2, lower 1, lower 2
    gw = np.empty(ns)
    gc = np.empty(2 * ns, dtype=np.int64)    # the pieces of the torque it carries now (gear_band's choice):
    #                                          its upper edge's line, its lower edge's (:func:`_pieces_code`)
    ng = 0
    m = 0
    inside = True
    for k in range(ns):
        rk = int(stuck[k])
        if rk >= 0:
            span = (hi[k] - lo[k]) if np.isfinite(lo[k]) and np.isfinite(hi[k]) else \
                (abs(hi[k]) if np.isfinite(hi[k]) else abs(lo[k]))
            for side in range(2):
                bound = lo[k] if side == 0 else hi[k]
                if not np.isfinite(bound):
                    continue
                sg = -1.0 if side == 0 else 1.0
                for f in range(d):
                    G[m, f] = sg * V[k, f]
                h[m] = sg * (bound - lam[k])
                w[m] = span
                if h[m] < SPACE_MARGIN * w[m]:
                    inside = False
                m += 1
        else:
            r = -rk - 1
            q = _gear_member(stuck, ns, r)
            if q < 0:
                continue
            eta1, eta2, bf1, bf2, bfa = gear_losses(p, r, 0.0)
            lo0, hi0 = gear_band(p, r, -lam[q])
            gk[ng], gq[ng] = k, q
            gc[2 * ng] = 0 if -lam[q] - bfa > 0.0 else 1
            gc[2 * ng + 1] = 0 if -lam[q] + bfa > 0.0 else 1
            gl[ng, 0, 0], gl[ng, 0, 1] = 1.0 - eta1, bf1
            gl[ng, 1, 0], gl[ng, 1, 1] = 1.0 - 1.0 / eta2, bf2
            gl[ng, 2, 0], gl[ng, 2, 1] = 1.0 - 1.0 / eta2, -bf2
            gl[ng, 3, 0], gl[ng, 3, 1] = 1.0 - eta1, -bf1
            gw[ng] = hi0 - lo0 + tol
            if min(hi0 - lam[k], lam[k] - lo0) < SPACE_MARGIN * gw[ng]:
                inside = False
            ng += 1
    mf = m
    m = mf + 2 * ng
    if m == 0 or inside:   # (z = 0 keeps the full margin: left as it is)
        return False
    ncomb = 1
    if ng <= 2:
        for _g in range(ng):
            ncomb *= 4
    hint = p.work
    o_sp = _offsets(p).sp
    nk = _nk(p)
    size = space_hint(nk)   # (one combination's warm start: a vertex of up to nk + 1 bounds, an active set of nk)
    if hint[o_sp + space_cache(nk)] != 0.0:
        # an observer's evaluation (:func:`observe`): the hints from a copy, so that it leaves them as they were (a
        # sample's outputs moved them, and at a group's edge, where the optimum is certified only to ``tol``, a
        # self-locking chain sampled every 2 ms then stayed stuck beyond its limit, #30)
        hint = p.work[o_sp:o_sp + space_cache(nk)].copy()
        o_sp = 0
    M = np.empty((d + 1, d + 1))
    b = np.empty(d + 1)
    yb = np.empty(d + 1)
    idx = np.empty(d + 1, dtype=np.int64)
    base = np.empty(d + 1, dtype=np.int64)
    zt = np.empty(d + 1)
    zc = np.empty(d)
    zb = np.zeros(d)
    R = np.zeros((d, d))
    GR = np.zeros((mm, d))
    sc = np.zeros((2, max(mm, d + 1)))   # (the cold solves' step and shifted bounds: _lp_max, _qp_nearest)
    Rq = np.zeros((d + 1, d + 1))        # (and the triangle of their QR, M holding its Q)
    small = d <= ENUMERATED_DIMENSIONS   # (enumerated where the hints fail; above, the simplex and active sets)
    # (two rounds where the first finds no margin beyond rounding: a stuck lossy gear whose band is closed at the
    # nearest split that holds -- it can carry only what it carries there -- keeps its band with no margin in the
    # second, whose margin is then the other members': :func:`_close_bands`, :data:`THETA_FLOOR`)
    n1 = np.inf          # (the first round's nearest split, where it found one and a second round follows)
    z1 = np.zeros(d)
    for rnd in range(2):
        # the largest margin any split keeps, per combination of pieces (with three or more stuck lossy gears, the
        # pieces of the torques they carry now first: combination -1)
        deep = ng > 2
        thc = np.empty(ncomb)
        best_theta = -np.inf
        for comb in range(ncomb):
            _combo_bounds(-1 if deep else comb, ng, gk, gq, gl, gw, gc, V, lam, d, mf, G, h, w)
            nr = _span_basis(G, m, d, R, GR, zt)
            thc[comb] = _combo_margin(GR, w, h, nr, m, idx, base, M, b, yb, sc, Rq, hint, o_sp + size * comb, tol,
                                      small)
            best_theta = max(best_theta, thc[comb])
        # with three or more (4**ng combinations): where the current pieces keep less than PIECES_CAP (a margin near
        # zero is not enough: at 1e-15 no split keeping half of it is found), the last combination that held the set
        # (its warm start in slot 1, its code + 1 in slot 2), and where that keeps less too, every combination by branch
        # and bound
        pick = -1
        dig = np.empty(2 * ng, dtype=np.int64)   # (the branch and bound's digits)
        if deep and best_theta < PIECES_CAP:
            o_code = o_sp + 2 * size
            last = int(hint[o_code]) - 1
            if last >= 0 and last != _pieces_code(ng, gc):
                _combo_bounds(last, ng, gk, gq, gl, gw, gc, V, lam, d, mf, G, h, w)
                nr = _span_basis(G, m, d, R, GR, zt)
                th = _combo_margin(GR, w, h, nr, m, idx, base, M, b, yb, sc, Rq, hint, o_sp + size, tol, small)
                if th > best_theta:
                    best_theta, pick = th, last
            if best_theta < PIECES_CAP:
                th, code = _pieces_margin(ng, gk, gq, gl, gw, V, lam, d, mf, G, h, w, best_theta, dig, idx, base, M, b,
                                          yb, zt, R, GR, sc, Rq, np.empty(size), tol, small)
                if code >= 0:
                    best_theta, pick = th, code
                    hint[o_code] = code + 1.0
                    hint[o_sp + size] = -1.0            # (its warm start: found anew at its next use)
                    hint[o_sp + size + nk + 2] = -1.0
        # (a rounding of 0 below it, THETA_ROUND: the largest margin of a set with a closed band read -6e-33 and
        # -7e-49, and the group was let slip, at 5 evaluations in 4,000 of its stuck state, random draws seed 2261's
        # search, #30; looked at as the probe below is, for a closed band, and else not taken.  A group's edge located
        # to the resolution of its time reads at least 1e-17 below: THETA_FLOOR there held a loop past its edge)
        probe = rnd == 0 and -THETA_ROUND <= best_theta < 0.0
        if probe:
            best_theta = 0.0
        if not best_theta >= 0.0:
            best_n = np.inf   # no split holds: the group must slip (but where the first round held: below)
            break
        theta = min(SPACE_MARGIN, 0.5 * best_theta)
        for attempt in range(2):
            # the nearest split that keeps theta, over the combinations that can keep it (with three or more stuck
            # lossy gears, in the combination that keeps the largest margin found: the current pieces', or ``pick``)
            best_n = np.inf
            if deep:
                _combo_bounds(pick, ng, gk, gq, gl, gw, gc, V, lam, d, mf, G, h, w)
                best_n = _combo_nearest(G, d, h, w, theta, m, idx, base, M, b, zt, zb, sc, Rq, hint,
                                        o_sp + (size if pick >= 0 else 0) + nk + 2, tol, small)
            for comb in range(0 if deep else ncomb):
                if not thc[comb] >= theta:
                    continue
                _combo_bounds(comb, ng, gk, gq, gl, gw, gc, V, lam, d, mf, G, h, w)
                nz = _combo_nearest(G, d, h, w, theta, m, idx, base, M, b, zt, zc, sc, Rq, hint,
                                    o_sp + size * comb + nk + 2, tol, small)
                if nz < best_n:
                    best_n = nz
                    for f in range(d):
                        zb[f] = zc[f]
            if best_n < np.inf or rnd == 1 or theta < 0.0 or not best_theta < THETA_FLOOR:
                break
            # (none keeps half a margin below THETA_FLOOR, a rounding of 0: the split that holds with none, to look
            # for a gear whose band is closed there; asked for a margin of exactly none, where the set's splits are a
            # single point, the nearest-split programme found none by rounding at one evaluation in ten of seed
            # 2261's search: a rounding beyond the bounds, THETA_FLOOR of their widths, is allowed it)
            theta = -THETA_FLOOR
            probe = True
        # where the largest margin is a rounding of 0 and a gear's band is closed at the split found (or, where none
        # keeps half of it, at the split that holds with none), that gear keeps its band with no margin and the others
        # keep theirs, in a second round, whose split is taken where it finds one and the first's where not.  Where no
        # band is closed the set is at its group's edge and is left as before: the probe's split is not taken (at a
        # loop's edge, held there with no margin, a one-way clutch carried 1.9 N m the free way at the next evaluation)
        if rnd == 0 and best_n < np.inf and best_theta < THETA_FLOOR and \
                _close_bands(p, stuck, ng, gk, gq, gw, V, lam, zb, d, tol):
            n1 = best_n
            for f in range(d):
                z1[f] = zb[f]
            continue
        if probe:
            return False
        break
    if best_n == np.inf:   # (no split keeps the margin asked: the first round's, where it held and a second followed)
        if not n1 < np.inf:
            return False
        best_n = n1
        for f in range(d):
            zb[f] = z1[f]
    if best_n == 0.0:
        return False   # (the split already keeps theta)
    for k in range(ns):
        v_ = 0.0
        for f in range(d):
            v_ += V[k, f] * zb[f]
        lam[k] += v_
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _repair_blocks(p, stuck, ns, A, lam, lo, hi, flf, v, tmp, cand, trial, scale):
    """:func:`_repair` for each block of a stuck set whose members fall into blocks that share no inertia (stuck
    members in linked groups of their own, :func:`_components`): ``A`` is then block-diagonal, with a null
    direction per redundant block, and the whole set's null space has more than one dimension, so :func:`_repair`
    on it did nothing (a lossy gear at its band's edge held beyond it, its network's split moved by a second brake
    applied elsewhere, #30).  Each block of two or more members is repaired on its own, as in a network of that
    block alone, to the tolerance of its own torques: ``scale[k]`` [N m] is member ``k``'s torque and the largest
    on its inertias, and is replaced by the largest of its block (the repair's tolerance is ``NOISE`` times it).
    Returns False (nothing done) if the set is one block."""
    nk = _nk(p)
    wk = p.work
    lay = _offsets(p)
    o = lay.lim + 11 * nk + 2 + nk * nk
    sub = wk[o:o + nk]
    lam_c = wk[o + nk:o + 2 * nk]
    lo_c = wk[o + 2 * nk:o + 3 * nk]
    hi_c = wk[o + 3 * nk:o + 4 * nk]
    lab = wk[o + 4 * nk:o + 5 * nk]
    # the blocks: members linked through shared inertias (labels: the lowest member of the block)
    for k in range(ns):
        lab[k] = k
    changed = True
    while changed:
        changed = False
        for k in range(ns):
            for j in range(k + 1, ns):
                if lab[k] == lab[j]:
                    continue
                share = False
                for q in range(3):
                    i = flf[3 * k + q]
                    if i < 0.0:
                        continue
                    for qq in range(3):
                        if flf[3 * j + qq] == i:
                            share = True
                if share:
                    lo_lab = min(lab[k], lab[j])
                    lab[k] = lo_lab
                    lab[j] = lo_lab
                    changed = True
    # (each member's scale the largest of its block's: a block's split is moved into its bounds to its own
    # torques' rounding, not to a block's elsewhere carrying newton metres -- repaired to 2e-12 N m, the
    # tolerance of a gear's 2 N m elsewhere in the set, a lossy gear at rest beside a bearing held a loss 3e-13
    # N m beyond its band as its load passed zero, so its break-away function, widened by its own rounding of
    # 1e-12 N m, dipped below zero for a few microseconds: a step that ended in the dip released it and it
    # rolled at zero speed for the rest of the run, a step that spanned the dip kept it stuck; random draws
    # seed 2106, #30)
    for k in range(ns):
        for j in range(ns):
            if lab[j] == lab[k] and scale[j] > scale[k]:
                scale[k] = scale[j]
    one = True
    for k in range(ns):
        if lab[k] != 0.0:
            one = False
    if one:
        return False
    for b in range(ns):
        nc = 0
        tol = 0.0
        for k in range(ns):
            if lab[k] == b:
                nc += 1
                tol = NOISE * scale[k]
        if nc < 2:
            continue
        Ac = shaped(wk[lay.m:lay.m + nc * nc], (nc, nc))
        Sc = shaped(wk[lay.lim + 11 * nk + 2:lay.lim + 11 * nk + 2 + nc * nc], (nc, nc))
        c = 0
        for k in range(ns):
            if lab[k] != b:
                continue
            sub[c] = stuck[k]
            lam_c[c] = lam[k]
            lo_c[c] = lo[k]
            hi_c[c] = hi[k]
            cj = 0
            for j in range(ns):
                if lab[j] == b:
                    Ac[c, cj] = A[k, j]
                    cj += 1
            c += 1
        changed = _repair_outlined(p, sub, nc, Ac, Sc, p.iwork, lam_c, lo_c, hi_c, v, tmp, cand, trial, tol)
        if not changed and _several_null_known(p, Ac, nc):
            changed = _repair_space_outlined(p, sub, nc, Ac, lam_c, lo_c, hi_c, tol)
        if changed:
            c = 0
            for k in range(ns):
                if lab[k] == b:
                    lam[k] = lam_c[c]
                    c += 1
    return True


def params_template() -> DrivelineParams:
    """A :class:`DrivelineParams` of tiny arrays: the types of every network's (for the signatures of the functions
    called through their addresses, :mod:`clutchlab.numerics.outline`)."""
    i1, i2, f1, f2 = (np.zeros(1, np.int64), np.zeros((1, 1), np.int64), np.zeros(1), np.zeros((1, 1)))
    return DrivelineParams(f1, i2, f2, f2, f1, i1, i1, i1, i1, f1, i1, np.zeros(3), f2, f2)


def _params_type():
    """numba type of the :class:`DrivelineParams` reference every kernel function takes (one type for every network)."""
    return ByRef(numba.typeof(params_template()))


_F1, _F2, _I1 = types.float64[::1], types.float64[:, ::1], types.int64[::1]

#: :func:`_repair` called through its address (:mod:`clutchlab.numerics.outline`): it runs only where a stuck set is
#: statically indeterminate, and linked it was compiled again into every function of the core below a hook (13 s of
#: the driveline's first compilation)
#: :func:`_repair_space` called through its address (it allocates its scratch: compiled with reference counting,
#: apart from the kernel), lazily: it runs only where a stuck set loses its split along several null directions (a
#: rare path), so it is compiled or loaded at its first call, not with every driveline (``prepare(lazy=True)`` and
#: ``clutchlab warmup`` compile it ahead; the driveline group's first compilation 98.8 s against 114.3 s, medians of
#: three alternated runs on the 2-core VM, 2026-11-30)
_repair_space_outlined = outlined(_repair_space, lambda: (_params_type(), _F1, types.int64, _F2, _F1, _F1, _F1,
                                                          types.float64), types.boolean, lazy=True)

_repair_outlined = outlined(_repair, lambda: (_params_type(), _F1, types.int64, _F2, _F2, _I1, _F1, _F1, _F1, _F1, _F1,
                                              _F1, _F1, types.float64), types.boolean)
_split_limit_outlined = outlined(_split_limit, lambda: (_params_type(), _F2, types.int64, _F2, _I1, _F1, _F1, _F1, _F1,
                                                      _F1), types.none)
#: :func:`_eliminate` (the stuck set's rank and null vector, :func:`_repair_space`'s null space) and
#: :func:`_small_solve` (the vertex and active-set searches of :func:`_repair_space`, lazily with it) called through
#: their addresses: each elimination is O(ns^3) work beside the call, and linked they were optimised and emitted
#: again in every function that reaches them (8 and 9 copies, 16,300 of the driveline group's 247,000 instructions;
#: docs/architecture.md)
_eliminate_outlined = outlined(_eliminate, lambda: (_F2, types.int64, _F2, _I1), types.int64)
_small_solve_outlined = outlined(_small_solve, lambda: (_F2, _F1, types.int64), types.boolean, lazy=True)
# the laws of an E-clutch whose working point moves and of a friction map read at a heat port's temperature: called
# through their addresses, so that the friction laws every network evaluates stay as small as before them (linked,
# their code in the normal force and the sliding torque cost CoupledClutches and the launch 5-10 %), and compiled
# only for a network that has such an element
_shifted_curve_outlined = outlined(shifted_curve, lambda: (_F1, types.int64, types.int64, types.int64, types.float64,
                                                           types.float64), types.float64, lazy=True)
_shifted_liftoff_outlined = outlined(shifted_liftoff, lambda: (_F1, types.int64, types.int64, types.float64),
                                     types.float64, lazy=True)
_friction_map_outlined = outlined(friction_map, lambda: (_F1, types.int64, types.int64, types.int64, types.float64,
                                                         types.float64), types.float64, lazy=True)


#: refinements of the stuck set's regularised solution at most (:func:`_solve_stuck`: three always, then while the
#: residual of the members' relative accelerations is above ``REFINE_TOL`` of the largest of ``b`` and ``A lam``)
REFINE_MAX = 40
REFINE_TOL = 1e-13


@numba.njit(cache=True, nogil=True, _nrt=False)
def _solve_stuck(t, x, p, m, stuck, ns, F, tau, speeds):
    """Torques of the constraint set -- stuck friction elements, gears, stuck lossy gears' holds, motion sources
    -- solved together.  (``speeds`` = 1: ``F`` holds the momenta ``J w`` and the set is solved for the impulses that
    put every member's relative speed to zero, a motion source's left as it is: :func:`_project_speeds`.)

    Each member ``k`` holds its relative acceleration ``g_k . alpha`` at its target (zero, or the prescribed
    acceleration of a motion source) with a multiplier ``lam_k`` that puts ``-lam_k h_k`` on the inertias
    (:func:`_member`): ``A lam = g M^-1 F - target`` with ``A[k, j] = g_k . M^-1 h_j``.  Where stuck elements
    lock the same relative motion (two clutches in parallel) ``A`` is singular: the regularised solution splits
    the torque in proportion to the static limits (minimising ``sum(lam_k^2 / limit_k)``; one-way clutches,
    gears and motion sources weigh as the strongest friction element on their own inertias, else in the set),
    from ``(A + eps D) lam = b`` with ``D = diag(max limit / limit_k)`` and ``eps`` 1e-8 of ``A``'s diagonal (``eps``
    = 0 where ``A`` is of full rank, :func:`_rank_full`), refined twice on the residual of ``A lam = b``; where a
    rolling lossy gear makes ``A`` unsymmetric, :func:`_split_limit` takes off what the rounding left along the null
    direction; then :func:`_repair` moves that split within the members' bounds where it would leave them while
    another split holds.  ``F`` is updated with the torques; a stuck lossy gear's hold goes to :func:`_holds`.
    """
    n = p.inertia.shape[0]
    nk = _nk(p)
    wk = p.work
    lay = _offsets(p)
    o_a, o_m, o_b, o_l, o_c, o_r, o_g, o_lim = lay.a, lay.m, lay.b, lay.l, lay.c, lay.r, lay.g, lay.lim
    A = shaped(wk[o_a:o_a + nk * nk], (nk, nk))
    b = wk[o_b:o_b + nk]
    lam = wk[o_l:o_l + nk]
    cap = wk[o_c:o_c + nk]
    res = wk[o_r:o_r + nk]
    flf = wk[o_g:o_g + 3 * nk]
    gc = wk[o_g + 3 * nk:o_g + 6 * nk]
    hc = wk[o_g + 6 * nk:o_g + 9 * nk]
    lo = wk[o_lim:o_lim + nk]
    hi = wk[o_lim + nk:o_lim + 2 * nk]
    vnull = wk[o_lim + 2 * nk:o_lim + 3 * nk]
    vtmp = wk[o_lim + 3 * nk:o_lim + 4 * nk]
    trial = wk[o_lim + 4 * nk:o_lim + 5 * nk]
    cand = wk[o_lim + 5 * nk:o_lim + 11 * nk + 2]
    S = shaped(wk[o_lim + 11 * nk + 2:o_lim + 11 * nk + 2 + ns * ns], (ns, ns))
    cmax = 0.0
    bounded = False
    for k in range(ns):
        rk = int(stuck[k])
        _member(p, m, x, n, rk, flf, gc, hc, k)
        s = 0.0
        target = 0.0
        motion = rk >= 0 and p.elem[rk, E_KIND] == K_MOTION
        if motion and speeds == 0:
            d1, d2 = signal_rates(p.signals[p.elem[rk, E_SIGNAL]], p.data, t)
            target = d1 if p.elem[rk, E_LAW] == MOTION_SPEED else d2
        s = -target
        for q in range(3):
            i = int(flf[3 * k + q])
            if i >= 0:
                s += gc[3 * k + q] * F[i] / p.inertia[i]
        b[k] = 0.0 if motion and speeds != 0 else s
        lam[k] = 0.0
        cap[k] = -1.0
        lo[k] = -np.inf
        hi[k] = np.inf
        if rk >= 0 and p.elem[rk, E_KIND] == K_FRICTION:
            lim = static_limit(p, rk, t)
            if p.elem[rk, E_LAW] != LAW_ONEWAY:
                cap[k] = lim
                cmax = max(cmax, cap[k])
                lo[k] = -lim
            hi[k] = lim
            bounded = True
        elif rk < 0:
            bounded = True
    # a member without a limit of its own (a gear, a stuck lossy gear's hold, a one-way clutch, a motion source)
    # weighs as the strongest friction element on its own inertias, else as the strongest in the set: local, so an
    # element elsewhere in the network does not move a split here (#30)
    for k in range(ns):
        c = cap[k]
        if c < 0.0:
            for j in range(ns):
                if cap[j] < 0.0:
                    continue
                for q in range(3):
                    i = int(flf[3 * k + q])
                    if i < 0:
                        continue
                    for qq in range(3):
                        if int(flf[3 * j + qq]) == i:
                            c = max(c, cap[j])
            if c < 0.0:
                c = cmax if cmax > 0.0 else 1.0
        res[k] = c
    scale = 0.0
    for k in range(ns):
        cap[k] = res[k]
        for j in range(ns):
            v = 0.0
            for q in range(3):
                i = int(flf[3 * k + q])
                if i < 0 or gc[3 * k + q] == 0.0:
                    continue
                for qq in range(3):
                    if int(flf[3 * j + qq]) == i:
                        v += gc[3 * k + q] * hc[3 * j + qq] / p.inertia[i]
            A[k, j] = v
        scale = max(scale, A[k, k])
    cmax = 0.0
    for k in range(ns):
        cmax = max(cmax, cap[k])
    # a set of full rank (:func:`_null_vector`'s elimination, cached while ``A`` is the same) has one solution:
    # solved without the regularisation, which biased it where ``A`` is ill-conditioned (a loop whose gear ratios
    # multiply to 1 - 1e-4 locks it; its last pivot, about 1e-8 of the first, is the regularisation's size, and the
    # break-away came nine times late, #30)
    exact = ns > 1 and scale > 0.0 and _rank_full(p, A, ns, S, vnull, vtmp)
    M = shaped(wk[o_m:o_m + ns * ns], (ns, ns))
    for k in range(ns):
        for j in range(ns):
            M[k, j] = A[k, j]
        c = max(cap[k], 1e-6 * cmax, 1e-300)
        if not exact:
            M[k, k] += 1e-8 * scale * (cmax / c if cmax > 0.0 else 1.0)
    lu_factor(M, p.iwork)
    # the regularised solution, then two refinements on the residual; and more while the members' relative
    # accelerations are not held to rounding (at most REFINE_MAX): each refinement takes the residual down by about
    # eps D / (A's smallest non-zero eigenvalue + eps D), and where a member's limit is 1e-6 of the set's largest (a
    # clutch whose force falls through zero) eps D is 1e-2 of A's diagonal -- two left a stuck ring's members apart
    # at 1e-6 of their acceleration, and in a step that reached a clutch's free event the members' speeds parted by
    # 1e-6 rad/s while labelled stuck (#30)
    for _it in range(REFINE_MAX):
        big = 0.0
        worst = 0.0
        for k in range(ns):
            r = b[k]
            for j in range(ns):
                r -= A[k, j] * lam[j]
            res[k] = r
            worst = max(worst, abs(r))
            big = max(big, abs(b[k]), scale * abs(lam[k]))
        if _it >= 3 and not worst > REFINE_TOL * big:
            break
        lu_solve(M, p.iwork, res)
        for k in range(ns):
            lam[k] += res[k]
    if ns > 1 and speeds == 0 and _rolling_gear_in(p, m, stuck, ns) and not _full_rank_known(p, A, ns):
        for k in range(ns):   # (D's diagonal, as in M above)
            res[k] = cmax / max(cap[k], 1e-6 * cmax, 1e-300) if cmax > 0.0 else 1.0
        _split_limit_outlined(p, A, ns, S, p.iwork, lam, res, vnull, trial, vtmp)
    # (not for the impulses of a projection: they are of the residue's size, and moved along a null direction into
    # the torque limits they grew to the split's own size, 5e-3 N m s where a lossy gear rolling in a loop makes a
    # null direction with a net impulse, and the projection gave the loop a speed of its own, #30)
    if bounded and ns > 1 and speeds == 0 and not _full_rank_known(p, A, ns):
        # (the torques on the members' own inertias, not on every inertia: an inertia elsewhere, braked with 2 N m,
        # made the tolerance 2e-12 N m where this set carries 1e-11, and a lossy gear holding nothing was left with
        # 4e-12 N m of a bearing's load and rolled at the first step with that inertia beside the network and not
        # without it, #30)
        # (``res``, free here: each member's torque and the largest on its inertias, then its block's largest,
        # :func:`_repair_blocks`)
        big = 0.0
        for k in range(ns):
            bk = abs(lam[k])
            for q in range(3):
                i = int(flf[3 * k + q])
                if i >= 0:
                    bk = max(bk, abs(F[i]))
            res[k] = bk
            big = max(big, bk)
        # (relative to the torques only: a split is moved into the bounds before the switching functions, whose
        # floor is NOISE (1 + torque), see it leave them -- else which comes first is a rounding, and a stuck lossy
        # gear beside a bearing rolled or held by the step sequence, #30)
        tol = NOISE * big
        # (the column order of the elimination in iwork: the factorisation's pivots are not needed any more; lam + z
        # v keeps the constraints, v being A's null vector to rounding)
        if not _repair_blocks(p, stuck, ns, A, lam, lo, hi, flf, vnull, vtmp, cand, trial, res):
            if not _repair_outlined(p, stuck, ns, A, S, p.iwork, lam, lo, hi, vnull, vtmp, cand, trial, tol) and \
                    _several_null_known(p, A, ns):
                _repair_space_outlined(p, stuck, ns, A, lam, lo, hi, tol)
        # a member the split leaves on its bound to within the repair's tolerance is put on it exactly: the split is
        # the network's choice here, and "on its limit" must not read as "beyond it" by a rounding (the tie-break in
        # settle keeps a member exactly on its limit at t + T_TIE stuck, while another member takes the growth, #30)
        for k in range(ns):
            tk = NOISE * res[k]   # (its block's tolerance, as the repair's)
            if hi[k] < lam[k] <= hi[k] + tk:
                lam[k] = hi[k]
            elif lo[k] - tk <= lam[k] < lo[k]:
                lam[k] = lo[k]
    hold = _holds(p)
    Fa = _torque_magnitudes(p)
    for k in range(ns):
        rk = int(stuck[k])
        if rk < 0:
            r = -rk - 1
            hold[_lossy_index(p, r)] = lam[k]
        else:
            tau[rk] = lam[k]
        for q in range(3):
            i = int(flf[3 * k + q])
            if i >= 0:
                F[i] -= hc[3 * k + q] * lam[k]
                Fa[i] += abs(hc[3 * k + q] * lam[k])


#: :func:`_solve_stuck` called through its address (:mod:`clutchlab.numerics.outline`): large beside the rest of an
#: evaluation of the network, which every function of the core links (4 s of the driveline's first compilation; the
#: indirect call at each evaluation with a stuck set is within the run time's noise, docs/architecture.md)
_solve_stuck_outlined = outlined(_solve_stuck, lambda: (types.float64, _F1, _params_type(), _I1, _F1, types.int64, _F1,
                                                      _F1, types.int64), types.none)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _lossy_index(p, r):
    for j in range(p.lossy.shape[0]):
        if p.lossy[j] == r:
            return j
    return -1




# ----------------------------------------------------------------- the stick/slip items: friction elements and lossy gears
@numba.njit(cache=True, nogil=True, _nrt=False)
def _flanges_max(v, elem, r):
    """The largest of ``|v|`` over element row ``r``'s flanges (a, b and a gear's support; 0 for the ground)."""
    out = 0.0
    a = elem[r, E_A]
    b = elem[r, E_B]
    if a >= 0:
        out = max(out, abs(v[a]))
    if b >= 0:
        out = max(out, abs(v[b]))
    if _has_support(elem[r, E_KIND]) and elem[r, E_SUP] >= 0:
        out = max(out, abs(v[elem[r, E_SUP]]))
    return out


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_noise(p, r, tau):
    """Rounding floor [N m] of the stick/slip decisions of element row ``r``: ``NOISE`` times one plus its torque and
    the torques on its own inertias at the last evaluation (local: an element elsewhere in the network does not move
    a decision here)."""
    scale = max(abs(tau[r]), _flanges_max(_torque_magnitudes(p), p.elem, r))
    if p.elem[r, E_KIND] == K_GEAR and p.elem[r, E_MODE] >= 0:
        scale = max(scale, abs(_holds(p)[_lossy_index(p, r)]))
    return NOISE * (1.0 + scale)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_wtol(p, r, x, n):
    """Rounding width [rad/s] of a relative speed of element row ``r``: 1e-9 of the largest speed of its inertias
    (at least 1 rad/s)."""
    n_ = p.inertia.shape[0]
    w = 1.0
    for i in (p.elem[r, E_A], p.elem[r, E_B], p.elem[r, E_SUP] if _has_support(p.elem[r, E_KIND]) else -1):
        if i >= 0:
            w = max(w, abs(x[n_ + i]))
    return 1e-9 * w


#: the rounding width [rad/s] of element row ``r``'s relative speed (1e-9 of its inertias' largest speed, >= 1 rad/s;
#: a model component's block reads it, driveline.coupled)
speed_tolerance = _item_wtol


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_row(p, i):
    nf = p.fric.shape[0]
    return p.fric[i] if i < nf else p.lossy[i - nf]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_stuck(p, m, i):
    """True if item ``i`` (a friction element, then the lossy gears) is stuck in the modes ``m``."""
    nf = p.fric.shape[0]
    if i < nf:
        return m[i] == STUCK
    return m[p.elem[p.lossy[i - nf], E_MODE]] == GEAR_STUCK


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_set(p, m, i, direction):
    """Put item ``i`` (a friction element, then the lossy gears) in a mode: stuck (``direction`` 0), sliding or
    rolling forward (+1) or backward (-1; a lossy gear with flange a driving, its quadrant fixed by
    :func:`_evaluate`)."""
    nf = p.fric.shape[0]
    if i < nf:
        m[i] = STUCK if direction == 0 else (FORWARD if direction > 0 else BACKWARD)
    else:
        m[p.elem[p.lossy[i - nf], E_MODE]] = GEAR_STUCK if direction == 0 else (GEAR_FWD_A if direction > 0
                                                                                 else GEAR_BWD_A)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_way(p, m, i):
    """The way item ``i`` (a friction element, then the lossy gears) moves in its mode: 0 stuck (or free), +1
    forward, -1 backward (the inverse of :func:`_item_set`)."""
    nf = p.fric.shape[0]
    if i < nf:
        return np.int64(1) if m[i] == FORWARD else np.int64(-1) if m[i] == BACKWARD else _ZERO
    return np.int64(GEAR_CODES[m[p.elem[p.lossy[i - nf], E_MODE]]])


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_speed(p, x, n, i):
    """Relative speed [rad/s] of item ``i``: a friction element's ``w_b - w_a``, a lossy gear's ``w_a - w_s``."""
    r = _item_row(p, i)
    if i < p.fric.shape[0]:
        return _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
    return gear_speed(p, r, x, n)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_passed_rest(p, m, x, n, i, acc):
    """True if sliding (rolling) item ``i`` has passed zero relative speed the wrong way for its mode, or passes it
    within :data:`T_INSTANT`: its stick function (the speed in its direction plus its slack) is at or below zero, or
    falls to it at its rate (the relative acceleration ``acc`` gives, the evaluation at the instant) within that
    time.  Two items on one relative motion (a bearing and a brake on one inertia) reach zero together; the event is
    located for the first, and the other's speed at the located instant may lie a hair past zero, beyond the
    rounding width (the root is bracketed to the event tolerance in time): it is at rest too.  Or a hair before it:
    two clutches on either side of an inertia whose neighbours are stuck, started together with one slack, reach
    zero 6e-17 s apart (the neighbours' drift speeds, 2e-16 rad/s); counted at rest only from its zero on, the
    second slid on the wrong way, driving the inertia with its 7 N m, at one tolerance (#30)."""
    nf = p.fric.shape[0]
    if i < nf:
        mode = m[i]
        if mode != FORWARD and mode != BACKWARD:
            return False
        d = 1.0 if mode == FORWARD else -1.0
    else:
        mode = m[p.elem[p.lossy[i - nf], E_MODE]]
        if mode == GEAR_STUCK:
            return False
        d = 1.0 if mode == GEAR_FWD_A or mode == GEAR_FWD_B else -1.0
    return d * _item_speed(p, x, n, i) + _slack(p)[i] <= max(-d * _item_acc(p, acc, i), 0.0) * T_INSTANT


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_acc(p, acc, i):
    """Relative acceleration [rad/s^2] of item ``i`` (as :func:`_item_speed`)."""
    r = _item_row(p, i)
    if i < p.fric.shape[0]:
        return (0.0 if p.elem[r, E_B] < 0 else acc[p.elem[r, E_B]]) - (0.0 if p.elem[r, E_A] < 0 else acc[p.elem[r, E_A]])
    return (0.0 if p.elem[r, E_A] < 0 else acc[p.elem[r, E_A]]) - (0.0 if p.elem[r, E_SUP] < 0 else acc[p.elem[r, E_SUP]])


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_excess(t, p, tau, i, sticking):
    """How far stuck item ``i`` is beyond what it holds at the last evaluation, and the way it would move.

    Returns ``(excess, direction)``: ``excess >= 0`` [-] if it must break away (its torque, or a lossy gear's held
    loss torque, at or beyond its limit, ``noise`` at least; relative to the limit: the test of the switching
    function that watches it, which has crossed when it reaches zero), else ``< 0``; ``direction``
    +1 forward, -1 backward (the sign of its torque; a gear's: the side of its band the held loss is nearer).
    ``sticking``: the element is sticking now (a clutch model then covers its lock-up limit)."""
    nf = p.fric.shape[0]
    r = _item_row(p, i)
    noise = _item_noise(p, r, tau)
    if i < nf:
        tq = tau[r]
        lim = holding_limit(p, r, t, tq)
        if sticking and p.elem[r, E_LAW] == LAW_EXTERNAL:
            lim = external_value(p, p.elem[r, E_AUX], 2, t)
        thr = max(lim, noise)
        d = 1 if tq > 0.0 else -1
        if thr == np.inf:   # (a one-way clutch loaded the way it locks: it holds any torque; (|tau| - inf)/inf
            return -1.0, d  # was NaN, which every reader took as "holds" only because NaN >= 0 is False)
        return (abs(tq) - thr) / thr, d
    margin, width, d = gear_margin(p, r, -tau[r], _holds(p)[i - nf], noise)
    return -margin / width, d


@numba.njit(cache=True, nogil=True, _nrt=False)
def _evaluate(t, x, m, p, acc, tau):
    """The network at ``t`` with every rolling lossy gear in the quadrant its torque puts it in (MSL
    ``LossyGear.tau_eta``'s sign: which flange drives): evaluated, a gear whose quadrant disagrees beyond the noise
    flipped, evaluated again, to a fixed point (the gear's torque law is continuous and monotone across the flip,
    so there is one).  Returns 0.0 (the rounding floors are per element: :func:`_item_noise`)."""
    n = p.inertia.shape[0]
    nl = p.lossy.shape[0]
    evaluate_network(t, x, m, p, acc, tau)
    for _it in range(2 * nl + 2):
        flipped = False
        for j in range(nl):
            r = p.lossy[j]
            mi = p.elem[r, E_MODE]
            mode = m[mi]
            if mode == GEAR_STUCK:
                continue
            te = gear_tau_eta(p, r, mode, -tau[r], abs(gear_speed(p, r, x, n)))
            noise = _item_noise(p, r, tau)
            if (mode == GEAR_FWD_A or mode == GEAR_BWD_B) and te <= -noise:
                m[mi] = GEAR_FWD_B if mode == GEAR_FWD_A else GEAR_BWD_A
                flipped = True
            elif (mode == GEAR_FWD_B or mode == GEAR_BWD_A) and te >= noise:
                m[mi] = GEAR_FWD_A if mode == GEAR_FWD_B else GEAR_BWD_B
                flipped = True
        if not flipped:
            break
        evaluate_network(t, x, m, p, acc, tau)
    return 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _consistent(t, x, m, p, acc, tau, cand, nc, dirs, old, forced):
    """True if the modes of the candidates (items at rest) agree with the forces of the last evaluation: every
    stuck one within what it holds, every released one accelerating its way (not against it beyond rounding), a
    released lossy gear in the quadrant its torque puts it in (in a rigid loop a gear's torque may change sign with
    its quadrant: then neither is, and it must hold)."""
    nf = p.fric.shape[0]
    n = p.inertia.shape[0]
    for c in range(nc):
        i = cand[c]
        if _item_stuck(p, m, i):
            if forced[i] != 0:
                return False
            ex, _d = _item_excess(t, p, tau, i, not _item_stuck(p, old, i))
            if (ex >= 0.0 and not _tied(t, p, tau, i)) or _item_slips(p, acc, i):
                return False
        elif _item_acc(p, acc, i) * dirs[c] < -_item_anoise(p, _item_row(p, i), acc):
            return False
        elif i >= nf:   # a released lossy gear: in the quadrant its torque puts it in (else none is: stuck)
            r = _item_row(p, i)
            mode = m[p.elem[r, E_MODE]]
            te = gear_tau_eta(p, r, mode, -tau[r], abs(_item_speed(p, x, n, i)))
            noise = _item_noise(p, r, tau)
            if ((mode == GEAR_FWD_A or mode == GEAR_BWD_B) and te <= -noise) or \
                    ((mode == GEAR_FWD_B or mode == GEAR_BWD_A) and te >= noise):
                return False
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_slips(p, acc, i):
    """True if stuck item ``i`` does not hold its relative acceleration at zero (a motion source prescribes the
    motion it would hold: the constraints contradict each other, the stuck set is no solution)."""
    return abs(_item_acc(p, acc, i)) > 1e3 * _item_anoise(p, _item_row(p, i), acc)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _start_slack(w, w_tol, d, was_stuck):
    """Slack [rad/s] of the stick function ``d w + slack`` of an item that starts to move in direction ``d`` at
    relative speed ``w``: ``w_tol`` if it starts from (about) rest, so that it watches the speed fall below
    ``-w_tol`` the wrong way, not 0 (else, were it to stop at once, the crossing would be missed), 0 if it moves
    clearly.  Released from stuck, its speed is the drift of the stuck constraint (held in acceleration, its speed
    is what the located stick instant left: a few 1e-10 rad/s, times the ratios of gears between) and may lie the
    wrong way beyond ``w_tol``: the slack then covers it, so the function starts positive and a motion the wrong
    way is still seen."""
    if was_stuck:
        return w_tol + max(0.0, -d * w)
    # (within two widths: an item that reverses where its stick function crossed, one width past zero, is about at
    # rest; with one width, whether it watched -w_tol or 0 next was a rounding, and so its next reversal's instant
    # changed by 30 ms with an unrelated element in a network turning at 1e-9 rad/s, #30)
    return w_tol if abs(w) <= 2.0 * w_tol else 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _item_anoise(p, r, acc):
    """Rounding floor [rad/s^2] of a relative acceleration of element row ``r``: 1e-10 of one plus the largest
    acceleration of its inertias."""
    return 1e-10 * (1.0 + _flanges_max(acc, p.elem, r))


@numba.njit(cache=True, nogil=True, _nrt=False)
def _flip_released(p, m, acc, cand, dirs, pick, s, nf):
    """Turn every released item of ``pick`` that accelerates against its direction the other way (a one-way clutch
    cannot); True if one turned.  ``dirs`` follows."""
    turned = False
    for q in range(s):
        c = pick[q]
        i = cand[c]
        if _item_acc(p, acc, i) * dirs[c] < -_item_anoise(p, _item_row(p, i), acc):
            if i < nf and p.elem[p.fric[i], E_LAW] == LAW_ONEWAY:
                continue
            dirs[c] = -dirs[c]
            _item_set(p, m, i, dirs[c])
            turned = True
    return turned


#: what :func:`_probe` finds: the subset holds beyond ``t``; it fails there; it fails, and released items at zero
#: acceleration that turn back there were turned the other way (try the subset again)
PROBE_OUTCOMES = ("holds", "fails", "turned")
PROBE_HOLDS, PROBE_FAILS, PROBE_TURNED = indices(PROBE_OUTCOMES, "holds", "fails", "turned")


@numba.njit(cache=True, nogil=True, _nrt=True)
def _probe(t, x, xp, m, p, acc, tau, cand, nc, dirs, pick, s, stuck_too, turn):
    """:data:`PROBE_FAILS` if a released item of ``pick`` whose relative acceleration at ``t`` is within
    :data:`TIE_BAND` rounding floors of zero accelerates against its direction at ``t + T_TIE`` (angles and speeds
    advanced by the decided motion, as the tie-break in :func:`settle`): its way is a tie at first order that the
    load's rate decides, and this subset is no solution beyond ``t``.  (A loop clutch released at the instant its
    torque reached its limit, with the loop's one-way clutch stuck, started at zero acceleration and slid backward
    against its forward torque for 68 us, the one-way clutch then stuck 8 N m deep, until its slip crossed the
    rounding width; the solution is the one-way clutch overrunning with the loop clutch stuck, #30.)
    ``stuck_too``: probe in any case, and fail too if a stuck candidate is beyond its limit there (not at it to
    rounding).  Else :data:`PROBE_HOLDS`.

    ``turn``: every such item that turns back is turned the other way (``m`` and ``dirs``; a one-way clutch cannot),
    and :data:`PROBE_TURNED` returned if one was, for the search to try the subset again.  An item released from
    rest with no torque and no acceleration at the instant (a clutch whose capacity is below the rounding floor,
    where a backlash closes: the contact's torque starts at zero) is released the way the sign of its torque's
    rounding points; without the turn no subset agreed, and the search's last resort released it the rounding's
    way: it slid ``backward`` for 10 us, then ``forward``, in one run, and ``forward`` at once in the run with an
    unrelated inertia (random draws seed 2120, sixty-first session).

    It leaves the work array (the evaluation at ``t``: accelerations, torques, holds, the splits' warm starts) and
    the quadrants as it found them (but those it turns).  (Evaluated at ``t`` again instead, a set at its group's
    edge that held in the search's evaluation held no more -- at the edge the split follows the warm starts, which
    the probe had moved -- and a lossy gear was kept stuck 0.11 N m beyond its band.)"""
    nf = p.fric.shape[0]
    tie = stuck_too
    near = np.zeros(s, dtype=np.bool_)
    for q in range(s):
        i = cand[pick[q]]
        near[q] = abs(_item_acc(p, acc, i)) <= TIE_BAND * _item_anoise(p, _item_row(p, i), acc)
        tie = tie or near[q]
    if not tie:
        return PROBE_HOLDS
    saved = p.work.copy()
    _evaluate_ahead(t, x, xp, m, p, acc, tau, np.empty(p.lossy.shape[0], dtype=np.int64))
    turns = False
    turned = False
    for q in range(s):
        c = pick[q]
        i = cand[c]
        if near[q] and _item_acc(p, acc, i) * dirs[c] < -_item_anoise(p, _item_row(p, i), acc):
            turns = True
            if turn and not (i < nf and p.elem[p.fric[i], E_LAW] == LAW_ONEWAY):
                dirs[c] = -dirs[c]
                _item_set(p, m, i, dirs[c])
                turned = True
    if stuck_too:
        for c in range(nc):
            i = cand[c]
            if _item_stuck(p, m, i) and _item_excess(t + T_TIE, p, tau, i, False)[0] >= 0.0 and \
                    not _tied(t + T_TIE, p, tau, i):
                turns = True
    _put_back(p, saved)
    return PROBE_TURNED if turned else PROBE_FAILS if turns else PROBE_HOLDS


@numba.njit(cache=True, nogil=True, _nrt=False)
def _evaluate_ahead(t, x, xp, m, p, acc, tau, quad):
    """The network evaluated at ``t + T_TIE`` into the work array (``acc``, ``tau``), with angles, speeds and the
    thermal masses' temperatures advanced by the motion decided at ``t`` (``xp``: ``x`` plus ``T_TIE`` times its rates,
    an error of order ``T_TIE**2``)
    and each lossy gear's quadrant kept as decided at ``t``: the probe of the tie-break in :func:`settle` and of
    :func:`_probe`.  (A released gear whose quadrant flips by ``t + T_TIE`` keeps the one decided at ``t`` --
    taken over, a gear released in a rigid loop carried the other quadrant's split at ``t``, which put a one-way
    clutch 0.63 N m the free way, #30.)  ``quad``: room for the quadrants (one per lossy gear), the caller's:
    compiled without reference counting, this function allocates nothing (docs/architecture.md)."""
    n = p.inertia.shape[0]
    nl = p.lossy.shape[0]
    for j in range(nl):
        quad[j] = m[p.elem[p.lossy[j], E_MODE]]
    nt = p.thermal.shape[0]
    if nt > 0:
        # the thermal masses' temperatures too, by their rates at t (``xp`` holds the rates first: the elements'
        # loss powers, then :func:`thermal_rates`): a limit that fades as its lining heats moves with them, and a
        # brake at its faded limit is then beyond it at t + T_TIE as it is a moment later
        ne = p.elem.shape[0]
        for r in range(ne):
            kind = p.elem[r, E_KIND]
            xp[2 * n + r] = 0.0 if kind == K_SOURCE or kind == K_MOTION else loss_power(p, r, x, n, m, tau[r])
        thermal_rates(p, x, n, xp)
        for k in range(nt):
            s = int(p.thermal[k, T_STATE]) + TS_TEMP
            xp[s] = x[s] + T_TIE * xp[s]
    for q in range(xp.shape[0]):
        if nt > 0 and _is_temperature(p, q):
            continue
        xp[q] = x[q]
    for j in range(n):
        xp[j] = x[j] + T_TIE * x[n + j]
        xp[n + j] = x[n + j] + T_TIE * acc[j]
    _evaluate(t + T_TIE, xp, m, p, acc, tau)
    for j in range(nl):
        m[p.elem[p.lossy[j], E_MODE]] = quad[j]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _is_temperature(p, q):
    """True if state ``q`` is a thermal mass's temperature."""
    for k in range(p.thermal.shape[0]):
        if int(p.thermal[k, T_STATE]) + TS_TEMP == q:
            return True
    return False


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _put_back(p, saved):
    """The work array as ``saved`` (a copy taken before a probe: the evaluation at ``t``, its holds and the splits'
    warm starts), element by element: a slice assignment's size check calls Python on its error path, which a
    native FMU cannot link."""
    for q in range(saved.shape[0]):
        p.work[q] = saved[q]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _apply_subset(p, m, cand, nc, dirs, pick, s):
    for c in range(nc):
        _item_set(p, m, cand[c], _ZERO)
    for q in range(s):
        c = pick[q]
        _item_set(p, m, cand[c], dirs[c])


#: a stuck item that would break away within this time [s] of the instant is released at it (the tie-break in :func:`settle`)
T_TIE = 1e-8
#: Crossings closer than this [s] are one instant (:func:`_one_search_per_instant`): four times the event location's
#: tolerance of a driveline run (1e-12 s), within which the locator cannot tell two crossings apart
T_INSTANT = 4e-12


#: a stuck item whose margin to its limit is below this many rounding floors (:func:`_item_noise`: 1e-6 of the
#: torques on its inertias) is decided by where its load goes (the tie-break in :func:`settle`)
TIE_BAND = 1e6


@numba.njit(cache=True, nogil=True, _nrt=False)
def _near_limit(t, p, tau, i):
    """True if stuck item ``i`` holds within :data:`TIE_BAND` rounding floors of its limit (a friction element's
    holding limit; a lossy gear's band edge) at the last evaluation."""
    nf = p.fric.shape[0]
    r = _item_row(p, i)
    noise = _item_noise(p, r, tau)
    if i < nf:
        tq = tau[r]
        return max(holding_limit(p, r, t, tq), noise) - abs(tq) < TIE_BAND * noise
    margin, _width, _d = gear_margin(p, r, -tau[r], _holds(p)[i - nf], noise)
    return margin < TIE_BAND * noise


@numba.njit(cache=True, nogil=True, _nrt=False)
def _past_limit(t, p, tau, i):
    """How far [N m] stuck item ``i`` is beyond its limit at the last evaluation (a friction element's holding
    limit, a lossy gear's band edge, each at least its rounding floor), and how far beyond the rounding a stuck item
    is allowed (a friction element ``1e-9`` of its limit plus one floor, a lossy gear's hold two floors): the
    invariant's test (:func:`check_invariants`, beyond it where the second is > 0) and the tie's (:func:`_tied`)."""
    nf = p.fric.shape[0]
    r = _item_row(p, i)
    noise = _item_noise(p, r, tau)
    if i < nf:
        tq = tau[r]
        lim = max(holding_limit(p, r, t, tq), noise)
        over = abs(tq) - lim
        return over, over - (1e-9 * lim + noise)
    margin, _width, _d = gear_margin(p, r, -tau[r], _holds(p)[i - nf], noise)   # (widened by one floor already)
    return -margin, -margin - noise


@numba.njit(cache=True, nogil=True, _nrt=False)
def _tied(t, p, tau, i):
    """True if stuck item ``i`` is at or beyond its limit at the last evaluation by no more than the rounding the
    invariants allow a stuck item (:func:`_past_limit`): at its limit to rounding, which side of it is a rounding, so
    the tie-break in :func:`settle` decides it by where its load goes, as for one just inside its limit."""
    if i < p.fric.shape[0] and p.elem[_item_row(p, i), E_LAW] == LAW_EXTERNAL:
        return False
    over, allowed = _past_limit(t, p, tau, i)
    return over >= 0.0 and allowed < 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _one_search_per_instant(t, m, p, log, old):
    """Several switching functions crossing at one instant call :func:`settle` once each (the core updates every
    crossed function); each search must then start from the modes before the instant, not from those the one
    before left, and its events replace the earlier search's: the result is one search over every function's own
    change, independent of their order (a second search from the first's modes could undo it: a gear put stuck by
    the first released by the second).  The first search at a new instant stores the friction elements' and lossy
    gears' modes in ``old`` and the event count; a later one at the same instant puts them back into ``old`` and
    drops the events the earlier searches recorded (theirs only: a backlash's contact is kept).  Instants within
    :data:`T_INSTANT` of the first are one (two crossings the locator put 1e-12 s apart: a bearing reversed for
    1e-12 s before the loop it is in locked, at some tolerances and not at others, #30).  A restart (a
    run's start, a resume, a signal's jump) begins a new instant (:func:`driveline_restart`)."""
    nf = p.fric.shape[0]
    nl = p.lossy.shape[0]
    nsw = p.swit.shape[0]
    inst = _instant(p)
    if abs(t - inst[0]) <= T_INSTANT:
        for k in range(nf):
            old[k] = np.int64(inst[2 + k])
        for j in range(nl):
            old[p.elem[p.lossy[j], E_MODE]] = np.int64(inst[2 + nf + j])
        n0 = np.int64(inst[1])
        w = n0
        for q in range(n0, log.count[0]):
            e = log.element[q]
            c = log.code[q]
            ours = ((e >= 0 and e < nf and c <= EV_FREE) or
                    (e >= nf + nsw and e < nf + nsw + nl and (c <= EV_BACKWARD or c == EV_DRIVE_A or c == EV_DRIVE_B)))
            if not ours:
                log.time[w] = log.time[q]
                log.code[w] = log.code[q]
                log.element[w] = log.element[q]
                w += 1
        log.count[0] = w
        return
    inst[0] = t
    inst[1] = float(log.count[0])
    for k in range(nf):
        inst[2 + k] = float(old[k])
    for j in range(nl):
        inst[2 + nf + j] = float(old[p.elem[p.lossy[j], E_MODE]])


@numba.njit(cache=True, nogil=True, _nrt=False)
def _flange(p, r, q):
    """Inertia of flange ``q`` of element row ``r``: 0 flange a, 1 flange b, 2 a gear's or a torque converter's
    support; -1 for the ground (or no support)."""
    if q == 0:
        return p.elem[r, E_A]
    if q == 1:
        return p.elem[r, E_B]
    return p.elem[r, E_SUP] if _has_support(p.elem[r, E_KIND]) else -1


@numba.njit(cache=True, nogil=True, _nrt=False)
def _components(p, comp):
    """The linked groups of inertias: ``comp[i]`` the lowest inertia linked to inertia ``i`` through elements
    (any element between two inertias, a gear's support included; the ground links nothing, it does not move).
    ``comp``: int64, or a float scratch of the work array (:func:`_margin_rates`)."""
    n = p.inertia.shape[0]
    for i in range(n):
        comp[i] = i
    changed = True
    while changed:   # (a handful of passes: networks are small)
        changed = False
        for r in range(p.elem.shape[0]):
            lo = n
            for q in range(3):
                i = _flange(p, r, q)
                if i >= 0:
                    lo = min(lo, comp[i])
            for q in range(3):
                i = _flange(p, r, q)
                if i >= 0 and comp[i] != lo:
                    comp[i] = lo
                    changed = True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _reach(t, p, comp, origin, reach):
    """Mark in ``reach`` (by :func:`_components`' label) the linked groups of inertias a search at ``t`` decides:
    those element row ``origin`` acts on (an event of its own); with ``origin`` -2 (a signal's jump) those of every
    element whose signal jumps or kinks at ``t``; with ``origin`` -1 (a start or a resume), or a jump no element's
    signal shows, every group."""
    n = p.inertia.shape[0]
    for i in range(n):
        reach[i] = origin == -1
    if origin == -1:
        return
    found = False
    for r in range(p.elem.shape[0]):
        if origin >= 0:
            mine = r == origin
        else:
            s = p.elem[r, E_SIGNAL]
            mine = s >= 0 and _jumps_at(p, s, t)
        if mine:
            for q in range(3):
                i = _flange(p, r, q)
                if i >= 0:
                    reach[comp[i]] = True
                    found = True
    if not found and origin == -2:
        for i in range(n):
            reach[i] = True


@numba.njit(cache=True, nogil=True, _nrt=False)
def _linked(p, comp, reach, r):
    """True if element row ``r`` acts on an inertia of a linked group marked in ``reach`` (:func:`_reach`)."""
    for q in range(3):
        i = _flange(p, r, q)
        if i >= 0 and reach[comp[i]]:
            return True
    return False


@numba.njit(cache=True, nogil=True, _nrt=False)
def _project_speeds(t, x, m, p, comp, reach):
    """Put the relative speed of every member of the constraint set of the modes ``m`` (stuck friction elements,
    gears, stuck lossy gears' holds) to zero, by the impulses along the members' torque directions that do it (the
    set of :func:`evaluate_network` solved by :func:`_solve_stuck` for momenta instead of torques: ``A mu = g . w``,
    ``w -= M^-1 h mu``, the regularised split of ``mu`` as it is: the members' torque limits bound no impulse, and
    moved into them along a null direction the impulses grew to the split's size).

    The set holds its relative accelerations at zero, not its speeds: a stuck member keeps the speed the located
    event left it (the stick function's root, up to its rounding width :func:`_item_wtol` the wrong way) and the
    integration's drift.  Left there, that residue is a relative speed of the elements beside it: a clutch that
    reaches rest next to a gear stuck 1e-9 rad/s off rest sees 1e-9 rad/s of slip and is at rest or sliding by a
    rounding, which then decides the network's motion (a loop of clutches around a lossy gear, #30).  The impulses
    are of that residue's size; the kinetic energy they change is of its square (below 1e-15 J), left out of the
    balance.  A stuck member beyond 1e3 rounding widths (what :func:`check_invariants` allows) is no residue but a
    mode forced by hand: nothing is moved, and the check names it.  Every residue is removed, however small:
    leaving those below 1e-4 of the width in place (to leave the E-clutch launch's states untouched where its
    clutch locks, 1e-11 rad/s) brought back decisions that differ with the tolerance in the loop of
    ``test_a_clutch_reaching_rest_beside_a_stuck_gear_decides_by_the_forces_not_the_tolerance``; the launch's final
    engine speed at rtol 1e-8 moves by 3e-5 rad/s of 383 with it (its driveshaft backlash's contact sequence
    amplifies any change: the engine's inertia changed by 1e-11 of itself moves it by 8.5e-6, docs/driveline.md).
    Only the members linked to the elements the search is for (``reach``, :func:`_reach`, :func:`_linked`): a stuck
    set elsewhere keeps its residue until an event of its own, as in a network without the element whose event this
    is."""
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    wk = p.work
    F = wk[0:n]
    stuck = wk[n:n + _nk(p)]
    ns = _ZERO
    for k in range(nf):
        r = p.fric[k]
        if m[k] == STUCK and _linked(p, comp, reach, r):
            w, w_tol = abs(_item_speed(p, x, n, k)), _item_wtol(p, r, x, n)
            if w > 1e3 * w_tol:
                return   # beyond a residue (a mode forced by hand): left for the invariant check to name
            stuck[ns] = r
            ns += 1
    for k in range(p.cons.shape[0]):
        if _linked(p, comp, reach, p.cons[k]):
            stuck[ns] = p.cons[k]
            ns += 1
    for j in range(p.lossy.shape[0]):
        r = p.lossy[j]
        if m[p.elem[r, E_MODE]] == GEAR_STUCK and _linked(p, comp, reach, r):
            w, w_tol = abs(_item_speed(p, x, n, nf + j)), _item_wtol(p, r, x, n)
            if w > 1e3 * w_tol:
                return
            stuck[ns] = -(r + 1)
            ns += 1
    if ns == 0:
        return
    for i in range(n):
        F[i] = p.inertia[i] * x[n + i]
    _solve_stuck_outlined(t, x, p, m, stuck, ns, F, _acc_tau(p)[1], np.int64(1))
    for i in range(n):
        x[n + i] = F[i] / p.inertia[i]


@numba.njit(cache=True, nogil=True, _nrt=True)
def settle(t, x, m, p, log, old, origin):
    """Modes consistent with the forces at ``t`` (the event iteration of MSL's friction elements and ``LossyGear``).

    Friction elements are free or engaged by their normal force.  The items at rest -- friction elements and lossy
    gears that are stuck or whose relative speed is within 1e-9 of the largest speed -- are put stuck; if one of them is then beyond
    what it holds, the fewest of them that must slide are found: subsets of growing size, the most overloaded
    first, each released the way its torque pushes it, until every stuck one holds and every released one
    accelerates its own way (up to ten items at rest; beyond, or if none agrees, the most overloaded is released
    until the rest hold).  The decision depends only on the forces, not on the order of the elements or on
    elements elsewhere in the network (beyond rounding, :data:`NOISE`; overloads within 1e-6 of each other, which
    rounding would order, are taken lossy gears first, then in element order).  An event per item whose mode now differs
    from ``old`` (the modes before the event), named for the mode entered (a lossy gear's quadrant: ``a_drives``,
    ``b_drives``).  ``origin``: the element row whose event this is, -2 at a signal's jump, -1 at a start or a
    resume.  Only the items linked to that element (to the elements whose signals jump; every item at a start) are
    searched, and only their stuck speeds put to rest (:func:`_reach`, :func:`_linked`, :func:`_project_speeds`): a
    stuck item elsewhere holds or breaks away at its own function's crossing, and a sliding one goes on until its
    own function crosses, as in a network without the element whose event this is.  Returns True if a mode
    changed."""
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    nl = p.lossy.shape[0]
    nsw = p.swit.shape[0]
    acc, tau = _acc_tau(p)
    _one_search_per_instant(t, m, p, log, old)
    entry = m.copy()   # (the modes the update left: an item its own crossing put stuck is released from stuck)
    for k in range(nf):
        r = p.fric[k]
        if _is_free(p, r, t):
            m[k] = FREE
        elif m[k] == FREE:   # engaged: slides the way it moves, or is at rest (decided below)
            w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
            w_tol = _item_wtol(p, r, x, n)
            m[k] = FORWARD if w_rel > w_tol else BACKWARD if w_rel < -w_tol else STUCK
    ni = nf + nl
    # (the items this search put at rest, in any pass: their speeds were put to rest with the stuck ones', so one it
    # released starts from rest, as one its own crossing put stuck does: the slack below)
    searched = np.zeros(ni, dtype=np.bool_)
    comp = np.empty(n, dtype=np.int64)
    _components(p, comp)
    reach = np.empty(n, dtype=np.bool_)
    _reach(t, p, comp, origin, reach)
    # (a second pass where the stuck speeds' projection brought a sliding item linked to them to rest: the search
    # decides it too, else it would go on sliding at zero speed, labelled by the rounding its speed had before)
    for _pass in range(ni + 1):
        # the items at rest
        cand = np.empty(ni, dtype=np.int64)
        dirs = np.zeros(ni, dtype=np.int64)
        exc = np.empty(ni)
        nc = _ZERO
        # (an item moving slower than its rounding width is at rest for a search on its own motion -- a restart, or an
        # event of an element it is linked to -- not for an event elsewhere: there it goes on until its own function
        # crosses, as in a network without that element)
        for i in range(ni):
            if i < nf and m[i] == FREE:
                continue
            # (only items linked to the element whose event this is: a stuck item elsewhere holds or breaks away at
            # its own function's crossing, as in a network without that element -- searched again at an unrelated
            # event, a lossy gear at its band's edge came out rolling where it had stayed stuck, #30)
            if not _linked(p, comp, reach, _item_row(p, i)):
                continue
            if _item_stuck(p, m, i) or _item_passed_rest(p, m, x, n, i, acc) or \
                    abs(_item_speed(p, x, n, i)) <= _item_wtol(p, _item_row(p, i), x, n):
                cand[nc] = i
                searched[i] = True
                nc += 1
                _item_set(p, m, i, _ZERO)
        forced = np.zeros(ni, dtype=np.int64)
        marks_order = np.empty(nc + 1, dtype=np.int64)   # (the items the tie-break marked, in the order it did)
        nmarks = _ZERO
        xp = np.empty(x.shape[0])
        for _tie in range(nc + 1):
            # ---- the search over the candidates (every one stuck first; ``forced`` items count as overloaded)
            for c in range(nc):
                _item_set(p, m, cand[c], _ZERO)
            _evaluate(t, x, m, p, acc, tau)
            worst = -np.inf
            for c in range(nc):
                ex, d = _item_excess(t, p, tau, cand[c], not _item_stuck(p, old, cand[c]))
                if forced[cand[c]] != 0:   # it would break away within T_TIE (the tie-break below): overloaded
                    ex = max(ex, 0.0)
                    if abs(forced[cand[c]]) == 2:   # the way its load goes there (here that way is a rounding)
                        d = forced[cand[c]] // 2
                elif ex >= 0.0 and _tied(t, p, tau, cand[c]):   # at its limit to rounding: the tie-break decides
                    ex = -1e-300
                if _item_slips(p, acc, cand[c]):   # held against a prescribed motion: it must move, the way it is driven
                    a = _item_acc(p, acc, cand[c])
                    ex, d = max(ex, 0.0), (1 if a > 0.0 else -1)
                exc[c] = ex
                dirs[c] = d
                if cand[c] < nf and p.elem[p.fric[cand[c]]][E_LAW] == LAW_ONEWAY and d < 0:
                    # a one-way clutch never slides backward; released, it slides forward, and the subset is kept only if
                    # it then accelerates forward (_consistent).  (Its torque with every candidate stuck says nothing where
                    # that set contradicts a prescribed motion.)
                    dirs[c] = 1
                worst = max(worst, ex)
            if worst >= 0.0:
                # the candidates, most overloaded first; overloads within 1e-6 of each other are a tie (two members of a
                # statically indeterminate group reach their limits together: which one's excess is the larger is a
                # rounding), taken lossy gears first, then in element order (a gear rolling while a bearing holds its
                # shaft, or the bearing sliding while the gear holds, are one motion: the labels then do not change
                # with the tolerance, #30)
                key = np.empty(nc)
                for c in range(nc):
                    i = cand[c]
                    key[c] = -np.round(min(max(exc[c], -1e6), 1e6) * 1e6) * (2.0 * ni) + (i - nf if i >= nf else nl + i)
                order = np.argsort(key)
                cs = cand[:nc][order].copy()
                ds = dirs[:nc][order].copy()
                for c in range(nc):
                    cand[c] = cs[c]
                    dirs[c] = ds[c]
                found = False
                pick = np.empty(max(nc, 1), dtype=np.int64)
                smax = nc if nc <= 10 else 2
                # (a second attempt where none agrees with the items marked to break away (``forced``, taken from the
                # all-stuck set at t + T_TIE): the search again with them free to hold, each subset kept only if it
                # holds at t + T_TIE as well -- a loop clutch marked so, because the loop's one-way clutch held, was
                # released with everything else for 74 ps where it holds once the one-way clutch overruns, #30)
                marks = forced
                for attempt in range(2):
                    if attempt == 1:
                        if found:
                            break
                        marks = np.zeros(ni, dtype=np.int64)
                        anyf = False
                        for c in range(nc):
                            if forced[cand[c]] != 0:
                                anyf = True
                        if not anyf:
                            break
                    for s in range(1, smax + 1):
                        for q in range(s):
                            pick[q] = q
                        while True:
                            ok = True
                            for q in range(s):
                                if dirs[pick[q]] == 0:
                                    ok = False
                            if ok:
                                _apply_subset(p, m, cand, nc, dirs, pick, s)
                                _evaluate(t, x, m, p, acc, tau)
                                # released together, an item may move against the way its own torque pushed it (two
                                # gears coupled through a reversing ratio): flip those to the way they accelerate, a
                                # few times
                                for _flip in range(s + 1):
                                    if _consistent(t, x, m, p, acc, tau, cand, nc, dirs, old, marks):
                                        probe = _probe(t, x, xp, m, p, acc, tau, cand, nc, dirs, pick, s,
                                                       attempt == 1, True)
                                        if probe == PROBE_FAILS:
                                            break   # not a solution beyond t (one turns back, or one breaks away)
                                        if probe == PROBE_TURNED:   # (one at zero acceleration turned: again)
                                            _evaluate(t, x, m, p, acc, tau)
                                            continue
                                        found = True
                                        break
                                    if not _flip_released(p, m, acc, cand, dirs, pick, s, nf):
                                        break
                                    _evaluate(t, x, m, p, acc, tau)
                                if found:
                                    break
                            # the next combination of s out of nc
                            q = s - 1
                            while q >= 0 and pick[q] == nc - s + q:
                                q -= 1
                            if q < 0:
                                break
                            pick[q] += 1
                            for qq in range(q + 1, s):
                                pick[qq] = pick[qq - 1] + 1
                        if found:
                            break
                if not found:   # release the most overloaded until the rest hold
                    for c in range(nc):
                        _item_set(p, m, cand[c], _ZERO)
                    for _it in range(nc):
                        _evaluate(t, x, m, p, acc, tau)
                        best, bi, bd = -np.inf, _ZERO - 1, _ZERO
                        for c in range(nc):
                            i = cand[c]
                            if not _item_stuck(p, m, i):
                                continue
                            ex, d = _item_excess(t, p, tau, i, not _item_stuck(p, old, i))
                            if forced[i] != 0:
                                ex = max(ex, 0.0)
                                if abs(forced[i]) == 2:
                                    d = forced[i] // 2
                            if _item_slips(p, acc, i):   # held against a prescribed motion (as above)
                                ex, d = max(ex, 0.0), (1 if _item_acc(p, acc, i) > 0.0 else -1)
                            if i < nf and p.elem[p.fric[i], E_LAW] == LAW_ONEWAY and d < 0:
                                continue
                            if ex >= 0.0 and ex > best:
                                best, bi, bd = ex, i, d
                        if bi < 0:
                            break
                        _item_set(p, m, bi, bd)
                    _evaluate(t, x, m, p, acc, tau)
            # ---- the second-order tie-break (T_TIE, TIE_BAND): a stuck candidate within TIE_BAND of its limit is
            # evaluated again at t + T_TIE (angles and speeds advanced by the decided motion, an error of order
            # T_TIE**2); one beyond what it holds there (its static limit, not its lock-up limit) is marked forced and
            # the search repeated.  Without it the decision at such an instant followed the sign the rounding left,
            # so it changed with the tolerance or with an unrelated element (a self-locking gear stuck for 1.6 ps, or
            # 0.6 ns, in one run and rolling in the other: issue #30).  (Written out here, as the search above: as
            # functions of their own they compiled 2.5 s more; the probe's evaluation is :func:`_evaluate_ahead`, as
            # in :func:`_probe`.)
            near = False
            marked = False
            for c in range(nc):
                i = cand[c]
                if forced[i] == 0 and _item_stuck(p, m, i) and _near_limit(t, p, tau, i):
                    near = True
            if near:
                exs = np.empty(nc)
                near_ = np.zeros(nc, dtype=np.bool_)
                flat = np.zeros(nc, dtype=np.bool_)
                for c in range(nc):
                    exs[c] = _item_excess(t, p, tau, cand[c], False)[0]
                    if exs[c] >= 0.0 and _tied(t, p, tau, cand[c]):
                        exs[c] = -1e-300
                    near_[c] = _near_limit(t, p, tau, cand[c])
                    if cand[c] >= nf:   # a gear whose band is within TIE_BAND floors wide (it carries ~no torque)
                        r = _item_row(p, cand[c])
                        noise = _item_noise(p, r, tau)
                        flat[c] = gear_margin(p, r, -tau[r], _holds(p)[cand[c] - nf], noise)[1] <= TIE_BAND * noise
                    else:   # a friction element carrying no more than its rounding floor (its load has no sign at t)
                        r = _item_row(p, cand[c])
                        flat[c] = abs(tau[r]) <= _item_noise(p, r, tau)
                dt = T_TIE
                saved = p.work.copy()
                _evaluate_ahead(t, x, xp, m, p, acc, tau, np.empty(p.lossy.shape[0], dtype=np.int64))
                # (the one most beyond its limit there, one per round: whether the others hold is decided again with
                # it released -- marked together from one set, a brake beside a gear at its band's edge was released
                # with it and slid for 2 ms where it holds once the gear rolls)
                # (beyond by amounts within 1e-6 of each other: a tie, taken lossy gears first, then in element
                # order, as in the search)
                ex1s = np.full(nc, -np.inf)
                d1s = np.zeros(nc, dtype=np.int64)
                worst1 = -np.inf
                for c in range(nc):
                    i = cand[c]
                    ex0 = exs[c]
                    if forced[i] != 0 or not _item_stuck(p, m, i) or not ex0 < 0.0 or not near_[c]:
                        continue
                    ex1s[c], d1s[c] = _item_excess(t + dt, p, tau, i, False)
                    if i < nf and ex1s[c] >= 0.0 and _past_limit(t + dt, p, tau, i)[0] <= 0.0:
                        # (exactly on its limit there, not beyond: the split of its statically indeterminate group was
                        # moved onto its bound (:func:`_repair`) while another member takes the load's growth, so it
                        # holds.  Marked, a clutch beside a brake was released at its limit and the group broke away 2
                        # ms early, or the brake "slid" at zero speed while the clutch held its inertia, #30.  An item
                        # whose load grows beyond its limit is beyond it there by the growth over T_TIE, and one left
                        # stuck here has its break-away function >= 0, so its next crossing is seen)
                        ex1s[c] = -1e-300
                    worst1 = max(worst1, ex1s[c])
                iw = -1
                dw = _ZERO
                if worst1 >= 0.0:
                    for c in range(nc):
                        i = cand[c]
                        if ex1s[c] >= 0.0 and ex1s[c] >= worst1 - 1e-6 and \
                                (iw < 0 or (i >= nf) > (iw >= nf) or ((i >= nf) == (iw >= nf) and i < iw)):
                            iw = i
                            dw = 2 * d1s[c] if flat[c] else 1
                if iw >= 0:
                    # (a gear whose band is about no width at t is marked with the way it breaks away there (2 forward,
                    # -2 backward): which side of its band it is on at t is a rounding; released the way the rounding
                    # left, a gear at efficiency 0.5 driven from flange b by a backlash closing rolled forward for 33
                    # us in one run and backward in another, #30.  So is a friction element that carries no more than
                    # its rounding floor at t: a clutch of 3e-8 N m behind a backlash, at rest, carried half the
                    # contact's 6e-14 N m at the contact, beyond its capacity 10 ns later; released the way that
                    # rounding pointed, it slid backward against its own torque for 18 us in one run and forward in
                    # the other, random draws seed 2195, sixty-fifth session.  Any other item keeps the way the search at t finds
                    # (1): its load has a sign there, and taken from t + T_TIE, the way of a gear carrying torque in a
                    # loop moved the loop's clutch 1e-7 beyond its limit in the next round, slipping it for 0.7 ns)
                    forced[iw] = dw
                    marks_order[nmarks] = iw
                    nmarks += 1
                    marked = True
                # (the work array as the probe found it -- evaluated at t again instead, the splits' warm starts
                # the probe had moved stayed moved, as in :func:`_probe`)
                _put_back(p, saved)
            if not marked:
                break
        # ---- the fewest released.  The tie-break marks one item per round, the one beyond its limit at t + T_TIE
        # with those marked before released; a later one's release may take away the load that put an earlier one
        # beyond (a one-way clutch that overruns once a self-locking gear at efficiency 0.5 rolls: the gear, marked
        # first because it shared the clutch's load with a brake, then carries nothing).  Each marked item, the last
        # first, is put stuck again where the modes then agree with the forces at t (:func:`_consistent`) and at t +
        # T_TIE (:func:`_probe`, the stuck ones included), and it is not beyond its limit there by the test
        # that marked it.  Without it, whether such a gear rolled on at zero speed or stayed stuck depended on
        # whether the clutch's own crossing fell in the same search: with an unrelated element or without it (random
        # draws seed 2097, sixty-first session; docs/driveline.md)
        for q in range(nmarks - 1, -1, -1):
            i = marks_order[q]
            if _item_stuck(p, m, i):
                continue
            mq = m.copy()
            saved = p.work.copy()
            fi = forced[i]
            forced[i] = 0
            _item_set(p, m, i, _ZERO)
            _evaluate(t, x, m, p, acc, tau)
            pk = np.empty(max(nc, 1), dtype=np.int64)
            npk = _ZERO
            for c in range(nc):
                dirs[c] = _item_way(p, m, cand[c])
                if dirs[c] != 0:
                    pk[npk] = c
                    npk += 1
            ok = _consistent(t, x, m, p, acc, tau, cand, nc, dirs, old, forced) and \
                _probe(t, x, xp, m, p, acc, tau, cand, nc, dirs, pk, npk, True, False) == PROBE_HOLDS
            if ok:
                # (and within what it holds at t + T_TIE by the test that marked it: not beyond, where the probe
                # allows a stuck item the rounding.  With the probe's test alone, a gear beyond its band by less than
                # that at t + T_TIE was kept stuck and crossed again 1.5 us later, then 0.34, 0.15, 0.07 us ...:
                # eight searches, each interval about half the last, before it rolled, random draws seed 2106)
                again = p.work.copy()
                _evaluate_ahead(t, x, xp, m, p, acc, tau, np.empty(p.lossy.shape[0], dtype=np.int64))
                ex1 = _item_excess(t + T_TIE, p, tau, i, False)[0]
                if i < nf and ex1 >= 0.0 and _past_limit(t + T_TIE, p, tau, i)[0] <= 0.0:
                    ex1 = -1e-300   # (exactly on its limit there: it holds, as the tie-break reads it)
                ok = not ex1 >= 0.0   # (as marked: the test the tie-break marks with)
                _put_back(p, again)
            if not ok:
                for k in range(m.shape[0]):
                    m[k] = mq[k]
                forced[i] = fi
                _put_back(p, saved)
        for j in range(n):
            xp[j] = x[n + j]
        _project_speeds(t, x, m, p, comp, reach)
        rest = False
        moved = False
        for j in range(n):
            if x[n + j] != xp[j]:
                moved = True
        for i in range(ni):
            if (i < nf and m[i] == FREE) or _item_stuck(p, m, i):
                continue
            taken = False
            for c in range(nc):
                if cand[c] == i:
                    taken = True
            if not taken and abs(_item_speed(p, x, n, i)) <= _item_wtol(p, _item_row(p, i), x, n) and \
                    _linked(p, comp, reach, _item_row(p, i)):
                rest = True
        if not rest and moved:
            # (the projection moved speeds, and a damper's or a speed-dependent law's torque with them: a stuck
            # candidate beyond what it holds in the projected state is decided again there.  Decided before the
            # projection only, a lossy gear at efficiency 0.5 with a free output reached rest carrying 1.5e-12 N m,
            # inside its band; the projection took the 1e-9 rad/s its rolling had left from its input, the damper
            # beside it then loaded it with 1e-9 N m, a third of its band's width beyond its edge, and it stayed
            # stuck there, its break-away function below zero, for half a second, #30)
            mq = m.copy()
            saved = p.work.copy()
            _evaluate(t, x, m, p, acc, tau)
            for c in range(nc):
                i = cand[c]
                if _item_stuck(p, m, i):
                    ex, _d = _item_excess(t, p, tau, i, not _item_stuck(p, old, i))
                    if ex >= 0.0 and not _tied(t, p, tau, i):
                        rest = True
            if not rest:   # (the modes and the work array as the search left them)
                for q in range(m.shape[0]):
                    m[q] = mq[q]
                _put_back(p, saved)
        if not rest:
            break
    # an item that starts to move from (about) rest may start a rounding's width on the wrong side of zero: its
    # stick function then watches the relative speed fall below -w_tol, not 0 (else, were it to stop at once, the
    # crossing would be missed); one that moves clearly watches 0
    slack = _slack(p)
    any_change = False
    # (an item its own crossing put stuck (``entry``) and the search released the way it moved before the instant
    # starts from stuck too, though no event names it: its speed at the located root is a rounding past zero, maybe
    # the wrong way, which the slack covers.  Without it, a lossy gear whose speed reached zero as a group broke away
    # rolled on "backward" with its stick function below zero from the start, so its forward motion was never seen
    # (0.46 ms, random draws seed 2072, fifty-eighth session))
    # An item the search put at rest and released the way it slid before (no event: the same mode) starts from rest
    # too: its speed was put to rest with the stuck set's, so its stick function, left at the slack of its earlier
    # motion, started on zero and the motion the wrong way that followed was no crossing.  Random draws seed 2146 (the
    # sixty-third session): a clutch whose normal force rises from zero at the start, its sides 1e-9 rad/s apart
    # (within its rounding width), put at rest and released ``forward`` (its capacity zero at the instant), slid on
    # ``forward`` while its slip ran backward under its own growing friction torque for 0.5 s, dissipating -0.024 J.
    for k in range(nf):
        released = m[k] != STUCK and m[k] != FREE and (entry[k] == STUCK or searched[k])
        if m[k] != old[k] or released:
            w_rel = _item_speed(p, x, n, k)
            w_tol = _item_wtol(p, p.fric[k], x, n)
            d = 1.0 if m[k] == FORWARD else -1.0 if m[k] == BACKWARD else 0.0
            slack[k] = _start_slack(w_rel, w_tol, d, old[k] == STUCK or released)
        if m[k] != old[k]:
            record(log, t, _EVENT_OF_MODE[m[k]], k)
            any_change = True
    for j in range(nl):
        mi = p.elem[p.lossy[j], E_MODE]
        new, was = m[mi], old[mi]
        if new != GEAR_STUCK and (entry[mi] == GEAR_STUCK or searched[nf + j]) and GEAR_CODES[new] == GEAR_CODES[was]:
            slack[nf + j] = _start_slack(_item_speed(p, x, n, nf + j), _item_wtol(p, p.lossy[j], x, n),
                                         GEAR_CODES[new], True)
        if new == was:
            continue
        any_change = True
        if GEAR_CODES[new] != GEAR_CODES[was]:
            ev = EV_STICK if new == GEAR_STUCK else (EV_FORWARD if GEAR_CODES[new] > 0 else EV_BACKWARD)
            w_a = _item_speed(p, x, n, nf + j)
            w_tol = _item_wtol(p, p.lossy[j], x, n)
            slack[nf + j] = _start_slack(w_a, w_tol, GEAR_CODES[new], was == GEAR_STUCK or searched[nf + j])
        else:
            ev = EV_DRIVE_A if new == GEAR_FWD_A or new == GEAR_BWD_A else EV_DRIVE_B
        record(log, t, ev, nf + nsw + j)
    _break_slack(t, x, m, p, comp, reach)
    return any_change


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def friction_break(p, r, t, tq, noise):
    """Break-away function of stuck friction element row ``r`` carrying ``tq`` [N m], without its slack, and the
    limit it uses: ``lim + noise - |tq|`` (a one-way clutch ``- tq``: it holds any torque against overrunning) with
    ``lim`` its static limit, at least its rounding floor ``noise``.  The one expression the switching function
    (:func:`driveline_rhs`) and :func:`_break_slack` use, as :func:`gear_margin` is a lossy gear's."""
    lim = max(static_limit(p, r, t), noise)
    return lim + noise - (tq if p.elem[r, E_LAW] == LAW_ONEWAY else abs(tq)), lim


@numba.njit(cache=True, nogil=True, _nrt=True)
def _break_slack(t, x, m, p, comp, reach):
    """The slack of the break-away function of every stuck item :func:`settle` decided (those linked to its event,
    :func:`_linked`): 0, but for one left stuck with its function at or below zero -- at its limit to rounding
    (:func:`_tied`), kept by the tie-break because its load does not grow beyond the limit by ``t + T_TIE`` -- half
    the way from where it is to the edge of what the invariants allow a stuck item (:func:`_past_limit`).  The
    function then starts above zero and falls through it where the load has grown by half that room, so the core sees
    the next crossing, and the item never leaves that band unseen.  (Without it, a lossy gear at efficiency 0.5 with a
    free output, its load 2e-12 N m, the integrator's rounding at rtol 1e-10, crossed its band's edge as that
    rounding turned; kept stuck with its function at -2e-21 it never crossed again, and held its growing load until
    an unrelated break-away half a second later, #30.)  The evaluation it takes leaves the work array as it found
    it, its own slacks aside."""
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    ni = nf + p.lossy.shape[0]
    new = np.zeros(ni)
    any_stuck = False
    for i in range(ni):
        if _item_stuck(p, m, i) and _linked(p, comp, reach, _item_row(p, i)):
            any_stuck = True
    if not any_stuck:
        return
    acc, tau = _acc_tau(p)
    saved = p.work.copy()
    evaluate_network(t, x, m, p, acc, tau)
    for i in range(ni):
        r = _item_row(p, i)
        if not _item_stuck(p, m, i) or not _linked(p, comp, reach, r):
            continue
        if i < nf and p.elem[r, E_LAW] == LAW_EXTERNAL:
            continue
        noise = _item_noise(p, r, tau)
        if i < nf:
            f0 = friction_break(p, r, t, tau[r], noise)[0]
        else:
            f0 = gear_margin(p, r, -tau[r], _holds(p)[i - nf], noise)[0]
        if f0 <= 0.0:
            allowed = _past_limit(t, p, tau, i)[1]
            if allowed < 0.0:
                new[i] = -f0 - 0.5 * allowed
    _put_back(p, saved)
    slack = _break_slacks(p)
    for i in range(ni):
        if _item_stuck(p, m, i) and _linked(p, comp, reach, _item_row(p, i)):
            slack[i] = new[i]


_log_type = log_type


#: :func:`settle` called through its address (:mod:`clutchlab.numerics.outline`): it runs at events only, and linked
#: it was compiled again into the update and restart hooks and every function of the core that calls them
settle_outlined = outlined(settle, lambda: (types.float64, _F1, _I1, _params_type(), _log_type(), _I1, types.int64),
                          types.boolean)


#: a stuck friction element whose margin to its holding limit is below this share of the limit is watched for the
#: turning point of that margin (:func:`_margin_rates`); a step ends where the margin comes into that band
NEAR_LIMIT = 0.1
#: time step [s] of the difference that gives a stuck element's margin rate (:func:`_margin_rates`)
T_RATE = 1e-6


@numba.njit(cache=True, nogil=True, _nrt=False)
def _stuck_breaks(p, m, j):
    """Index of the break-away function of item ``j`` (a friction element, then the lossy gears) and its element row
    (:func:`_item_row`), or ``(-1, -1)`` where the item is not stuck (:func:`_item_stuck`)."""
    if not _item_stuck(p, m, j):
        return -1, -1
    nf = p.fric.shape[0]
    q = N_G * j + G_BREAK if j < nf else N_G * nf + N_SW * p.swit.shape[0] + N_GEAR_G * (j - nf) + GG_BREAK
    return q, _item_row(p, j)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _turn_index(p, j):
    """Index of the turning-point function of item ``j`` (a friction element's, then ``nf +`` a lossy gear's)."""
    nf = p.fric.shape[0]
    if j < nf:
        return N_G * j + G_TURN
    return N_G * nf + N_SW * p.swit.shape[0] + N_GEAR_G * (j - nf) + GG_TURN


@numba.njit(cache=True, nogil=True, _nrt=False)
def _group_beyond(p, m, g, lab, c):
    """Whether a stuck item of the linked group of inertias ``c`` has its break-away function below zero at ``t``
    (its set past its edge within a step)."""
    for j in range(p.fric.shape[0] + p.lossy.shape[0]):
        q, r = _stuck_breaks(p, m, j)
        if q >= 0 and g[q] < 0.0 and _group_of(p, r, lab) == c:
            return True
    return False


@numba.njit(cache=True, nogil=True, _nrt=False)
def _group_of(p, r, lab):
    """The label (:func:`_components`, into a float scratch) of element row ``r``'s linked group of inertias (-1: it
    links only the ground)."""
    for q in range(3):
        i = _flange(p, r, q)
        if i >= 0:
            return lab[i]
    return -1.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _edge_rate(p, m, g, gs, lab, c):
    """The lowest rate [N m/s] over :data:`T_RATE` of the break-away functions of the stuck items of the linked group
    of inertias ``c`` (labels ``lab``, :func:`_group_of`) that the probe of :func:`_margin_rates` finds past zero
    where they were not at ``t``, or inf.

    In a statically indeterminate stuck set the margin of each member is that of the split chosen, not a function of
    the state alone: past the set's edge (no split holds) the regularised split is no longer moved into the bounds,
    and a member's margin jumps.  Near a loop's edge the probe at ``t + T_RATE`` of a member's margin rate crossed it:
    a one-way clutch's margin jumped to -0.65 N m while the margin of the loop's clutch near its limit jumped up by
    4.7 N m, so its turning-point function read a rising margin, the step's end stayed clear of the set's 6 ms
    overload and its break-away was stepped over (the one-way clutch's samples in the window held 0.65 N m the free
    way; random draws seed 2257, #30).  A member near its limit reads its group's falling edge instead."""
    best = np.inf
    for j in range(p.fric.shape[0] + p.lossy.shape[0]):
        q, r = _stuck_breaks(p, m, j)
        if q >= 0 and g[q] >= 0.0 and gs[q] < 0.0 and _group_of(p, r, lab) == c:
            best = min(best, (gs[q] - g[q]) / T_RATE)
    return best


@numba.njit(cache=True, nogil=True, _nrt=False)
def _margin_rates(t, x, u, m, p, dx, g):
    """The turning points of the margins of the stuck friction elements near their limits and of the stuck lossy
    gears: ``g[.. G_TURN]``, ``g[.. GG_TURN]`` (which :func:`driveline_rhs` marks with 0.0) become
    the margin's rate [N m/s] (rising through zero at its minimum), by a difference over :data:`T_RATE` along ``dx``.
    In a statically indeterminate stuck set a member's margin is that of the split chosen, which jumps where the set
    reaches its edge (no split holds): there the rate is its group's falling edge where the probe crosses it
    (:func:`_edge_rate`), and 1 where its group is past it at ``t`` (the turning point found is then the edge).

    While a network is stuck nothing moves, and its steps grow to the limit its signals set (an eighth of a sine's
    period): a load beyond an element's limit for less than the gap between two step ends (a brake at 1.0005 times
    its limit under a 3 Hz sine is beyond it for 3.4 ms of every 42 ms step) was stepped over, the element stayed
    stuck.  The root of the margin's rate ends a step at the peak load, and the core looks at the break-away
    function there (its second look, ``numerics.core._locate``): a brief overload is found, as a slow sliding
    speed's dip through zero is.  Called only where the core compares switching functions across a step (the
    ``watch`` hook: step ends, events, probes), never at the stages: one more evaluation of the network (the
    right-hand side through its address, at ``t + T_RATE`` and the state moved by ``T_RATE dx`` in a scratch
    copy), after which the accelerations, torques, holds, torque magnitudes and temperatures of the evaluation at
    ``t`` are put back from the work array, bit for bit; the warm start of the split search is left as it was (an
    observer's evaluation, :func:`observe`), so that the network evaluated at ``t`` again decides as it did."""
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    nl = p.lossy.shape[0]
    nx = x.shape[0]
    ng = g.shape[0]
    wk = p.work
    nb = state_bound(n, ne, p.thermal.shape[0])
    o = wk.shape[0] - 1 - rate_size(n, ne, nf, nl, p.thermal.shape[0])
    xs = wk[o:o + nx]
    o += nb
    ds = wk[o:o + nx]
    o += nb
    gs = wk[o:o + ng]
    o += N_G * nf + N_SW * ne + N_GEAR_G * nl
    acc, tau = _acc_tau(p)
    hold = _holds(p)
    fabs = _torque_magnitudes(p)
    for i in range(n):
        wk[o + i] = acc[i]
        wk[o + n + i] = fabs[i]
    for r in range(ne):
        wk[o + 2 * n + r] = tau[r]
    for j in range(nl):
        wk[o + 2 * n + ne + j] = hold[j]
    temp = temperatures(p)
    for k in range(temp.shape[0]):
        wk[o + 2 * n + ne + nl + k] = temp[k]
    # (the angles, speeds and the thermal masses' states move; the energies and integrals, which nothing reads, do not)
    th0 = int(p.thermal[0, T_STATE]) if p.thermal.shape[0] > 0 else nx
    for i in range(nx):
        xs[i] = x[i] + T_RATE * dx[i] if i < 2 * n or i >= th0 else x[i]
    observe(p, True)   # (a probe: the warm start of the split search is left as the evaluation at t left it)
    _rhs_outlined(t + T_RATE, xs, u, m, p, ds, gs)
    observe(p, False)
    lab = wk[o + 2 * n + ne + nl + p.thermal.shape[0]:o + 3 * n + ne + nl + p.thermal.shape[0]]
    _components(p, lab)
    for j in range(nf + nl):
        q = _turn_index(p, j)
        qb, r = _stuck_breaks(p, m, j)
        if qb < 0 or g[q] != 0.0:
            continue
        c = _group_of(p, r, lab)
        if _group_beyond(p, m, g, lab, c):
            # (its group is past its edge at t: positive, so that the turning point found is the edge, where the
            # core's second look at the break-away functions finds them below zero)
            g[q] = 1.0
            continue
        rate = min((gs[qb] - g[qb]) / T_RATE, _edge_rate(p, m, g, gs, lab, c))
        # (plus ten rounding floors over the difference's step: a margin that stays put has no turning point)
        g[q] = rate + 10.0 * _item_noise(p, r, tau) / T_RATE
    for i in range(n):
        acc[i] = wk[o + i]
        fabs[i] = wk[o + n + i]
    for r in range(ne):
        tau[r] = wk[o + 2 * n + r]
    for j in range(nl):
        hold[j] = wk[o + 2 * n + ne + j]
    for k in range(temp.shape[0]):
        temp[k] = wk[o + 2 * n + ne + nl + k]
    if _shifted(p):   # (a shifted E-clutch's working point back at x: the probe moved its mass's temperature)
        update_shifts(p, x)


# ----------------------------------------------------------------- hooks
@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_rhs(t, x, u, m, p, dx, g):
    """Angles and speeds of the inertias, work of the sources, energy dissipated by each element.

    States: ``phi`` (n), ``w`` (n), then one energy per element in element order [J]: a source's work
    ``tau_src * w_b`` (torque and motion sources), the dissipation of the others: ``tau * w_rel`` less
    the rate of the energy a spring stores (``(tau - tau_c) w_rel``; a gear's is zero but for drift); then
    the integral of each engine's idle controller [N m] (:func:`engine_torque`); then each thermal mass's temperature
    [degC] and heat given to its ambient [J] (:func:`thermal_rates`).  Switching functions, six per friction element: the relative speed of a sliding element in its
    direction (falls through zero: it sticks or reverses), the holding limit minus the torque of a stuck
    one (falls through zero: break-away; a one-way clutch's ``-tau``), the normalised normal force
    (either way: free or engaged), the turning point of a sliding speed, or of a stuck one's margin near its
    limit (0.0 here, its rate from :func:`driveline_watch`: a brief overload is found), and a stuck one's margin less
    :data:`NEAR_LIMIT` of its limit (a waypoint: a step ends as the margin comes near), and a sliding one's corners of
    its law over the speed (:func:`friction_row`: a table's rows; a waypoint either way); then four per switched
    spring.  A
    backlash, for its upper and lower side, each falling through zero: in the gap the distance to the edge
    (``b/2 - phi``, ``phi + b/2``: contact), in contact ``tau / c`` signed positive (separation, as the torque would
    pull); released beyond an edge (Kelvin-Voigt's damped separation), first ``tau / c`` signed positive while it
    would pull (contact again), then the distance beyond the edge (into the gap); with MSL's damping law, the two
    of its mode that fall through zero at its kinks
    (:func:`_lash_msl_switching`); third, in the gap, the relative speed signed towards the nearer edge less its
    rounding width (rising through zero just past an extreme: a step ends there, and the edges' functions get the
    core's second look, so a touch of an edge within a step is found), in contact near separation the contact
    torque's turning point; fourth, in contact, the waypoint of its torque coming near separation
    (:func:`_lash_near`), in the gap the waypoint of its centre, where the third changes its edge (both located
    even where a later event ends the step: :data:`clutchlab.numerics.core.WAYPOINT_ALWAYS`).  A curve spring: the
    deflection above the segment's lower point and below its upper one (either falling through zero moves it to
    the next segment), third and fourth unused.  Then
    four per lossy gear: stuck, the margin of the loss torque it holds within its band (:func:`gear_band`; falls
    through zero: it rolls); rolling, its speed in its direction (falls through zero: it sticks or reverses) and
    ``+-tau_eta`` (falls through zero: the other flange drives); the turning point of a slow rolling speed; stuck,
    ``T_a`` of one without bearing friction (a waypoint either way: a step ends where its band closes; 1 within a
    rounding floor of zero or in a set with several null directions), rolling, the rows of its loss table
    (:func:`gear_row`: a waypoint either way).  Then one per torque converter
    (:func:`converter_piece`: zero at each corner of its law, alternating in sign; a waypoint either way).  Then
    three per engine (:func:`engine_corners`: its map's speed and throttle nodes, its idle clip's edges; waypoints).
    Every threshold is the one :func:`settle` decides with, so after a decision each function is > 0 (but the
    waypoints, of either sign).
    """
    if u.shape[0] > 0 and hold_inputs(p.data, u):
        forget_signals(p)
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    acc, tau = _acc_tau(p)
    slack = _slack(p)
    bslack = _break_slacks(p)
    evaluate_network(t, x, m, p, acc, tau)
    for i in range(n):
        dx[i] = x[n + i]
        dx[n + i] = acc[i]
    for r in range(ne):
        kind = p.elem[r, E_KIND]
        if kind == K_SOURCE or kind == K_MOTION:
            dx[2 * n + r] = -tau[r] * relative_speed(p, r, x, n)
            if kind == K_SOURCE and p.elem[r, E_LAW] == SOURCE_ENGINE and p.elem[r, E_STATE] >= 0:
                _tq, rate = engine_torque(p, r, t, x, n)
                dx[2 * n + ne + p.elem[r, E_STATE]] = rate
        else:
            dx[2 * n + r] = loss_power(p, r, x, n, m, tau[r])
    if p.thermal.shape[0] > 0:
        thermal_rates(p, x, n, dx)
    for k in range(nf):
        r = p.fric[k]
        w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
        mk = m[k]
        g[N_G * k + G_STICK] = w_rel + slack[k] if mk == FORWARD else -w_rel + slack[k] if mk == BACKWARD else 1.0
        # the turning point of a sliding speed (rising through zero: the relative acceleration turns towards the
        # sliding direction), located so that a dip of the speed through zero within a step is seen (G_TURN)
        g[N_G * k + G_TURN] = 1.0
        g[N_G * k + G_NEAR] = 1.0
        # sliding, the corners of its law over the speed (a friction table's rows) and over its heat port's temperature
        # (its fade table's rows, a friction map's temperature nodes): a waypoint either way, zero at each (a product)
        g[N_G * k + G_ROW] = (friction_row(p, r, abs(w_rel)) * friction_temperature_row(p, r)
                              if (mk == FORWARD or mk == BACKWARD) else 1.0)
        if mk != STUCK:
            g[N_G * k + G_BREAK] = 1.0
        else:
            noise = _item_noise(p, r, tau)
            f_break, lim = friction_break(p, r, t, tau[r], noise)
            # (a one-way clutch holds any torque against overrunning, its clutch's limit for it; plus the rounding floor,
            # as a lossy gear's margin: a member a statically indeterminate split pins on its limit is at 0 to a
            # rounding, which the core counts as a crossing (falling to <= 0), and the waypoint of another member
            # coming near its own limit was dropped for it -- a group's 33 ms overload stepped over at one tolerance,
            # #30; crossed only beyond the floor, the decision at the crossing is the tie-break's, _tied)
            # (plus its slack: 0 but where the tie-break kept it stuck at its limit, :func:`_break_slack`)
            g[N_G * k + G_BREAK] = f_break + bslack[k]
            if lim > 1e3 * noise and lim < np.inf:
                # a stuck element with a limit of its own watches its margin near that limit: the margin less
                # NEAR_LIMIT of the limit (a waypoint, falling through zero: a step ends just past it as the load
                # comes near), and inside that band the margin's rate in its turn function (rising through zero: the
                # margin's minimum, where the core looks at the break-away function again), taken where the core
                # compares the functions (driveline_watch: _margin_rates; 0.0 here, at a step's stages).  A clutch
                # model's too (a wet clutch, an EMTC coupling: its limit moves with its own states, whose rates the
                # coupled watch takes with the network's, coupled._watch_rates): without it a wet clutch whose load
                # outran its growing capacity for 5 ms inside one 25 ms step held up to 1 % beyond it, stuck
                # (random draws, fifty-seventh session)
                g[N_G * k + G_NEAR] = g[N_G * k + G_BREAK] - NEAR_LIMIT * lim
                if g[N_G * k + G_NEAR] < 0.0:
                    g[N_G * k + G_TURN] = 0.0
        if (mk == FORWARD or mk == BACKWARD) and p.elem[r, E_LAW] != LAW_EXTERNAL:
            a_rel = (0.0 if p.elem[r, E_B] < 0 else acc[p.elem[r, E_B]]) - (0.0 if p.elem[r, E_A] < 0 else acc[p.elem[r, E_A]])
            # (plus the rounding of an acceleration: a speed held at rest by other elements has no turning point)
            g[N_G * k + G_TURN] = (a_rel if mk == FORWARD else -a_rel) + _item_anoise(p, r, acc)
        if p.elem[r, E_LAW] != LAW_CLUTCH or p.elem[r, E_SIGNAL] < 0:
            g[N_G * k + G_NORMAL] = 1.0
        elif p.elem[r, E_AUX] > 0:   # a normal-force curve: the input's distance to lift-off (the force is 0 beyond)
            g[N_G * k + G_NORMAL] = _liftoff(p, r) - signal_at(p, p.elem[r, E_SIGNAL], t)
        else:
            g[N_G * k + G_NORMAL] = signal_at(p, p.elem[r, E_SIGNAL], t)
    fabs = _torque_magnitudes(p)
    for j in range(p.swit.shape[0]):
        r = p.swit[j]
        phi = _spring_deflection(p, r, x, n)
        mode = m[nf + j]
        q = N_G * nf + N_SW * j
        g[q + G_LASH_TURN] = 1.0
        g[q + G_LASH_NEAR] = 1.0
        if p.elem[r, E_LAW] == SPRING_CURVE:   # the points bounding the segment: below (falls through) and above
            s0, mp = p.elem[r, E_TABLE], p.elem[r, E_TABLE_N]
            g[q] = phi - p.data[s0 + mode - 1] if mode > 0 else 1.0
            g[q + 1] = p.data[s0 + mode] - phi if mode < mp else 1.0
            continue
        b2 = 0.5 * p.coef[r, C_GAP]
        if mode == LASH_GAP:
            # the turning points of the deflection in the gap towards the nearer edge (rising through zero: the
            # relative speed signed towards that edge falls through zero at the extreme), located so that a touch of
            # an edge within a step (the deflection crosses it and comes back: free flight is a parabola the step
            # control does not see) is found: the edges' functions get the core's second look at the turning
            # point's root.  Less the rounding width of the speed (the root lies just past the extreme; a gap at
            # rest has none).  (An extreme away from the nearer edge touches nothing; at phi = 0 the function
            # falls, which is no crossing)
            w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
            wt = _item_wtol(p, r, x, n)
            g[q + G_LASH_TURN] = -w_rel - wt if phi > 0.0 else w_rel - wt
            # where the deflection passes the gap's centre that function jumps (the nearer edge changes), so a step
            # across the centre and the extreme beyond it sees it fall and rise again, its ends of one sign: the
            # centre is a waypoint either way, located even where a later event ends the step
            # (numerics.core.WAYPOINT_ALWAYS; issue #30, random draws seed 2137)
            g[q + G_LASH_NEAR] = phi
        elif mode == LASH_UPPER or mode == LASH_LOWER:
            # in contact near separation: a waypoint as the contact's torque comes near zero, and inside that band
            # the turning point of that torque, so that a dip through zero shorter than a step is found
            # (:func:`_lash_near`)
            g[q + G_LASH_NEAR], g[q + G_LASH_TURN] = _lash_near(p, r, x, n, _lash_side(mode), acc, fabs)
        if _lash_msl(p, r):
            g0, g1 = _lash_msl_switching(p, r, x, n, mode, phi)
            g[q] = g0
            g[q + 1] = g1
            continue
        # in the gap: the distances to the edges; in contact: the torque over c, signed to be positive in the
        # contact (each falls through zero: contact with that edge; separation, as the torque would pull)
        if mode == LASH_UPPER_RELEASED or mode == LASH_LOWER_RELEASED:
            # released beyond its edge (a damped contact separated there, moving back): the contact's torque over c,
            # signed to be positive while it would pull (falls through zero: it pushes again, contact), and the
            # distance beyond the edge (falls through zero: into the gap)
            beyond, push = _lash_contact(p, r, x, n, 1.0 if mode == LASH_UPPER_RELEASED else -1.0)
            g[q] = -push
            g[q + 1] = beyond
            continue
        g[q] = _lash_contact(p, r, x, n, 1.0)[1] if mode == LASH_UPPER else b2 - phi
        g[q + 1] = _lash_contact(p, r, x, n, -1.0)[1] if mode == LASH_LOWER else phi + b2
    nsw = p.swit.shape[0]
    hold = _holds(p)
    for j in range(p.lossy.shape[0]):
        r = p.lossy[j]
        mode = m[p.elem[r, E_MODE]]
        q = N_G * nf + N_SW * nsw + N_GEAR_G * j
        noise = _item_noise(p, r, tau)
        g[q + GG_TURN] = 1.0
        g[q + GG_PIECE] = 1.0
        if mode == GEAR_STUCK:
            # (plus its slack: _break_slack)
            g[q + GG_BREAK] = gear_margin(p, r, -tau[r], hold[j], noise)[0] + bslack[nf + j]
            g[q + GG_FLANGE] = 1.0
            # the margin's rate in its turn function, as a stuck friction element's near its limit (0.0 here:
            # driveline_watch, _margin_rates): a dip of the margin below zero between two step ends is found at its
            # minimum.  Without it three self-locking gears in a chain between two sines, a set with two null
            # directions (no waypoint at its band's corners, below), held through a 14 ms overload its stages did not
            # fall in, at one tolerance (random draws seed 2261, #30).  At every margin, not only near the band's edge
            # as a friction element's: a gear has no waypoint where its margin comes near (its band's width follows
            # its load), and a step from outside such a band across the overload and out again saw no turning point
            # (the same seed's next draw)
            g[q + GG_TURN] = 0.0
            # the corners of its band's edges (gear_band: the upper edge's pieces meet where T_a = tau_bf_a0, the
            # lower edge's where T_a = -tau_bf_a0; without bearing friction both at T_a = 0, where the band closes to
            # a point and any loss held is beyond it): the margin is V-shaped there, and a V-shaped dip below zero
            # shorter than the gap between a step's stages was stepped over where everything is at rest and the steps
            # are an eighth of a sine's period (a self-locking gear between two sines held stuck through the 25 ms
            # it must roll, #30).  Where the gear has no bearing friction, a waypoint either way where T_a passes zero:
            # a step ends there, where the break-away function is read.  It is 1 (no waypoint) within a rounding
            # floor of zero (a gear holding nothing carries T_a = 0 to a rounding, whose sign would end every step),
            # and where the stuck set has several null directions (the last null-vector search, this evaluation's
            # where its set has two members or more): its split is then :func:`_repair_space`'s optimum, whose vertex
            # may move with its warm start, and T_a with it, so a waypoint on it ended every step (a bearing and three
            # stuck gears: 3,284 steps and 4,072 retries where 22 and 7 do, 44 s).  With bearing friction the band
            # keeps a width at its corners (T_a = +-tau_bf_a0), so the margin is not forced below zero there, and no
            # waypoint is set
            ta = -tau[r]
            if abs(ta) > noise and not _several_null_last(p) and abs(gear_losses(p, r, 0.0)[4]) <= noise:
                g[q + GG_PIECE] = ta
            continue
        w_a = gear_speed(p, r, x, n)
        forward = mode == GEAR_FWD_A or mode == GEAR_FWD_B
        g[q] = (w_a if forward else -w_a) + slack[nf + j]
        a_a = _item_acc(p, acc, nf + j)
        g[q + GG_TURN] = (a_a if forward else -a_a) + _item_anoise(p, r, acc)
        te = gear_tau_eta(p, r, mode, -tau[r], abs(w_a))
        g[q + GG_FLANGE] = (te + noise) if mode == GEAR_FWD_A or mode == GEAR_BWD_B else (noise - te)
        # rolling, the corners of its loss table over |w_a| (its speed rows: a waypoint either way)
        g[q + GG_PIECE] = gear_row(p, r, abs(w_a))
    # then one per torque converter, in element order: the corners of its law (a waypoint either way)
    q = N_G * nf + N_SW * nsw + N_GEAR_G * p.lossy.shape[0]
    for r in range(p.elem.shape[0]):
        if p.elem[r, E_KIND] == K_CONVERTER:
            g[q] = converter_piece(p, r, x, n)
            q += 1
    # then three per engine, in element order: the corners of its map and the edges of its idle clip (waypoints)
    for r in range(p.elem.shape[0]):
        if p.elem[r, E_KIND] == K_SOURCE and p.elem[r, E_LAW] == SOURCE_ENGINE:
            g[q], g[q + 1], g[q + 2] = engine_corners(p, r, t, x, n)
            q += N_ENGINE_G


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")   # (in the right-hand side's loop: no call per element)
def loss_power(p, r, x, n, m, tau):
    """Power [W] element row ``r`` (not a source) dissipates, MSL ``lossPower``, with ``tau`` its torque: the rate of
    its dissipated energy: a friction element's ``tau w_rel``; a spring-damper's ``(tau - tau_c) w_rel``, its
    damper's part (``tau_c`` the spring's); a gear's :func:`gear_power` (its mesh and bearing losses, zero for an
    ideal or a stuck one but for the constraints' drift); a torque converter's :func:`converter_power`."""
    kind = p.elem[r, E_KIND]
    w_rel = relative_speed(p, r, x, n)
    if kind == K_SPRING:
        _tq, tc = spring_torque(p, r, x, n, m)
        return (tau - tc) * w_rel
    if kind == K_GEAR:   # the power the gear takes from its flanges
        return gear_power(p, r, x, n, m, tau)
    if kind == K_CONVERTER:   # the power its three flanges give it
        return converter_power(p, r, x, n)
    return tau * w_rel


@numba.njit(cache=True, nogil=True, _nrt=False)
def thermal_rates(p, x, n, dx):
    """Rates of the thermal masses' states, from the elements' loss rates already in ``dx[2 n + r]``.

    A thermal mass ``k`` (MSL ``HeatCapacitor``, its port joined to the heat ports of the elements whose losses flow
    into it, ``useHeatPort = true``, ``heatPort.Q_flow = -lossPower``; a ``ThermalConductor`` to a
    ``FixedTemperature`` ambient; ``ThermalConductor`` links to other masses)::

        C_k dT_k/dt = sum_{r -> k} P_r - G_k (T_k - T_amb,k) - sum_{links l at k} G_l (T_k - T_other)
        dQ_out,k/dt = G_k (T_k - T_amb,k)

    with ``P_r`` the power element ``r`` dissipates (MSL ``lossPower``: a friction element's ``tau w_rel``, a
    damper's ``d w_rel^2``, a lossy gear's mesh and bearing losses).  ``T`` [degC], ``C`` [J/K], ``G`` [W/K],
    ``P`` [W], ``Q_out`` [J] (the heat given to the ambient since the start).  The losses leave the mechanical
    network as the dissipated energies do, so the heat the masses store plus what they gave their ambients equals
    the energy their elements dissipated (a linear invariant of the states, kept by the integrator to rounding).
    """
    th = p.thermal
    nt = th.shape[0]
    for k in range(nt):
        s = int(th[k, T_STATE])
        q = th[k, T_COND] * (x[s + TS_TEMP] - th[k, T_AMB])
        dx[s + TS_TEMP] = -q
        dx[s + TS_OUT] = q
    for r in range(p.elem.shape[0]):
        h = p.elem[r, E_HEAT]
        if h >= 0:
            dx[int(th[h, T_STATE]) + TS_TEMP] += dx[2 * n + r]
    for j in range(p.links.shape[0]):
        sa = int(th[int(p.links[j, L_A]), T_STATE])
        sb = int(th[int(p.links[j, L_B]), T_STATE])
        q = p.links[j, L_COND] * (x[sa + TS_TEMP] - x[sb + TS_TEMP])
        dx[sa + TS_TEMP] -= q
        dx[sb + TS_TEMP] += q
    for k in range(nt):
        s = int(th[k, T_STATE])
        dx[s + TS_TEMP] /= th[k, T_CAP]


@numba.njit(cache=True, nogil=True, _nrt=False)
def dissipate(p, x, n, r, energy):
    """Energy ``energy`` [J] dissipated by element row ``r`` at an instant (what a spring held as its contact
    opens): into its dissipated energy and, where its losses heat a thermal mass, into that mass's temperature."""
    x[2 * n + r] += energy
    h = p.elem[r, E_HEAT]
    if h >= 0:
        x[int(p.thermal[h, T_STATE]) + TS_TEMP] += energy / p.thermal[h, T_CAP]


@numba.njit(cache=True, nogil=True, _nrt=False)
def gear_power(p, r, x, n, m, tau):
    """Power [W] gear row ``r`` takes from the inertias it joins, ``-(sum of its torques on them times their
    speeds)``: its loss ``tauLoss (w_a - w_s)`` (MSL ``LossyGear.lossPower``), zero for an ideal or a stuck gear but
    for the drift of the constraints.  ``tau`` its torque on flange a (``-T_a``)."""
    ratio = p.coef[r, C_RATIO]
    mode = _gear_mode(p, r, m)
    if mode == GEAR_STUCK:
        tb = -ratio * tau
        if p.elem[r, E_MODE] >= 0:
            tb -= ratio * _holds(p)[_lossy_index(p, r)]
    else:
        f, c = gear_transfer(p, r, mode, abs(gear_speed(p, r, x, n)))
        tb = -ratio * (f * tau + c)
    ts = -tau - tb
    return -(tau * _speed(x, n, p.elem[r, E_A]) + tb * _speed(x, n, p.elem[r, E_B]) + ts * _speed(x, n, p.elem[r, E_SUP]))


#: a backlash in contact whose contact torque is below this share of the largest sum of torque magnitudes on its
#: flanges is near separation (:func:`_lash_near`): a step ends as it comes into that band, and inside it the
#: contact torque's turning points are located
NEAR_SEPARATION = 0.1


@numba.njit(cache=True, nogil=True, _nrt=False)
def _lash_near(p, r, x, n, s, acc, fabs):
    """The two switching functions of backlash row ``r`` in contact on side ``s`` (+1 upper, -1 lower) that watch
    its separation within a step: ``(near, turn)``.

    ``near`` [rad]: the contact's torque over ``c`` (:func:`_lash_contact`, > 0 while it pushes) less
    :data:`NEAR_SEPARATION` of the larger sum of torque magnitudes on its flanges over ``c`` (a waypoint, falling
    through zero: a step ends as the contact comes near separation).  ``turn`` [rad/s]: inside that band, the
    contact torque's rate over ``c``, ``s (w_rel + d/c a_rel)``, plus the rounding of a speed and of an
    acceleration (rising through zero just past its minimum, where the core looks at the separation function again:
    a dip of the torque through zero and back within one step is found; a contact at rest has none); 1 outside it.
    Without them a contact whose torque dipped below zero for 0.7 ms inside one step was held while it pulled
    (random draws, fifty-seventh session); watched at every extreme, the E-clutch launch's driveshaft took 27 % more
    right-hand sides, so only the extremes near separation are (fifty-eighth session)."""
    push = _lash_contact(p, r, x, n, s)[1]
    c = p.coef[r, C_STIFF]
    a, b = p.elem[r, E_A], p.elem[r, E_B]
    scale = max(fabs[a] if a >= 0 else 0.0, fabs[b] if b >= 0 else 0.0)
    near = push - NEAR_SEPARATION * scale / c
    if near >= 0.0:
        return near, 1.0
    lag = p.coef[r, C_DAMP] / c
    w_rel = _speed(x, n, b) - _speed(x, n, a)
    a_rel = (0.0 if b < 0 else acc[b]) - (0.0 if a < 0 else acc[a])
    return near, s * (w_rel + lag * a_rel) + _item_wtol(p, r, x, n) + lag * _item_anoise(p, r, acc)


@numba.njit(cache=True, nogil=True, _nrt=False)
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
    b2 = 0.5 * p.coef[r, C_GAP]
    if mode == LASH_GAP:
        return b2 - phi, phi + b2
    side = _lash_side(mode)
    a = side * (phi - side * b2)
    b = side * p.coef[r, C_DAMP] / p.coef[r, C_STIFF] * (_speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A]))
    if mode <= LASH_LOWER:
        return a - b, a + b
    if mode <= LASH_LOWER_LIMITED:
        return b - a, 1.0
    return -(a + b), side * phi - b2


@numba.njit(cache=True, nogil=True, _nrt=False)
def _lash_msl_update(p, r, x, n, mode, which):
    """The mode a backlash with MSL's damping law enters when its switching function ``which`` (0 or 1) of
    :func:`_lash_msl_switching` falls through zero in ``mode``; from the gap, the contact's mode at the edge
    (limited while ``s tau_d >= s tau_c``: moving in, the damping torque exceeds the spring's, which is zero)."""
    if mode == LASH_GAP:
        side = 1.0 if which == 0 else -1.0
        a = side * p.coef[r, C_STIFF] * (_spring_deflection(p, r, x, n) - side * 0.5 * p.coef[r, C_GAP])
        b = side * p.coef[r, C_DAMP] * (_speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A]))
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


@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_outputs(t, x, u, m, p, y):
    """Per element: torque [N m] (a source: its torque on flange b; a gear: ``tau``, on flange a) and, for
    springs and friction, the relative speed [rad/s]; per friction element also its MSL mode code [-] and
    normal force [N]; then kinetic and spring energy, the sources' work, the dissipated energy and the
    energy balance error [J]; then per thermal mass the power its elements dissipate into it and the heat flow to
    its ambient [W] (:func:`thermal_rates`)."""
    if u.shape[0] > 0 and hold_inputs(p.data, u):
        forget_signals(p)
    n = p.inertia.shape[0]
    ne = p.elem.shape[0]
    nf = p.fric.shape[0]
    acc, tau = _acc_tau(p)
    observe(p, True)   # (an observer: the warm start of the split search is left as it was)
    evaluate_network(t, x, m, p, acc, tau)
    observe(p, False)
    q = 0
    kinetic = 0.0
    for i in range(n):
        kinetic += 0.5 * p.inertia[i] * x[n + i] ** 2
    spring = 0.0
    work = 0.0
    lost = 0.0
    for r in range(ne):
        kind = p.elem[r, E_KIND]
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
        y[q] = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
        q += 1
        if kind == K_CONVERTER:   # the turbine's torque, the speed ratio, the loss power
            _ta, tb, sr = converter_torques(p, r, x, n)
            y[q] = tb
            y[q + 1] = sr
            y[q + 2] = converter_power(p, r, x, n)
            q += 3
        if kind == K_SPRING:
            spring += spring_energy(p, r, x, n, m)
    for k in range(nf):
        r = p.fric[k]
        y[q] = MODE_CODES[m[k]]
        y[q + 1] = normal_force(p, r, t) if p.elem[r, E_LAW] in (LAW_CLUTCH, LAW_ONEWAY) else 0.0
        q += 2
    for j in range(p.lossy.shape[0]):
        y[q] = GEAR_CODES[m[p.elem[p.lossy[j], E_MODE]]]
        q += 1
    y[q] = kinetic
    y[q + 1] = spring
    y[q + 2] = work
    y[q + 3] = lost
    y[q + 4] = work - lost - (kinetic + spring - p.work[p.work.shape[0] - 1])
    q += 5
    th = p.thermal
    for k in range(th.shape[0]):   # per thermal mass: the power its elements dissipate into it, the heat flow out
        y[q] = 0.0
        y[q + 1] = th[k, T_COND] * (x[int(th[k, T_STATE]) + TS_TEMP] - th[k, T_AMB])
        q += 2
    for r in range(ne):
        h = p.elem[r, E_HEAT]
        if h >= 0:
            y[q - 2 * th.shape[0] + 2 * h] += loss_power(p, r, x, n, m, tau[r])


@numba.njit(cache=True, nogil=True, _nrt=True)
def driveline_update(t, x, u, m, p, k, log):
    """Switching function ``k`` crossed: a sliding element reached zero relative speed (it sticks, or
    reverses if it cannot hold), a stuck one reached its holding limit, a normal force changed sign, or a
    backlash closed (``contact``) or opened (``separate``) its gap, or (MSL's damping law) reached a kink of
    its contact law (:func:`_lash_msl_update`, no event)."""
    if u.shape[0] > 0 and hold_inputs(p.data, u):
        forget_signals(p)
    nf = p.fric.shape[0]
    nsw = p.swit.shape[0]
    if k >= N_G * nf + N_SW * nsw + N_GEAR_G * p.lossy.shape[0]:   # a torque converter's or an engine's corner: a
        return 0                                                     # step ends there
    if k >= N_G * nf + N_SW * nsw:   # a lossy gear: stopped (it sticks or reverses), overloaded, or its quadrant
        j = (k - N_G * nf - N_SW * nsw) // N_GEAR_G
        which = (k - N_G * nf - N_SW * nsw) % N_GEAR_G
        if which == GG_TURN or which == GG_PIECE:   # a turning point, a corner of a stuck one's band or of a
            return 0                                   # rolling one's loss table: a step ends there, nothing changes
        mi = p.elem[p.lossy[j], E_MODE]
        old = m.copy()
        mode = m[mi]
        if mode != GEAR_STUCK:
            if which == 0:
                m[mi] = GEAR_STUCK
            else:   # the other flange drives now
                m[mi] = (GEAR_FWD_B if mode == GEAR_FWD_A else GEAR_FWD_A if mode == GEAR_FWD_B else
                         GEAR_BWD_B if mode == GEAR_BWD_A else GEAR_BWD_A)
        settle_outlined(t, x, m, p, log, old, p.lossy[j])
        return 0
    if k >= N_G * nf:
        j = (k - N_G * nf) // N_SW
        if (k - N_G * nf) % N_SW == G_LASH_TURN or (k - N_G * nf) % N_SW == G_LASH_NEAR:
            return 0   # a backlash's turning point, or its contact coming near separation: a step ends there
        r = p.swit[j]
        n = p.inertia.shape[0]
        if p.elem[r, E_LAW] == SPRING_CURVE:   # onto the next segment, below or above (no event: not a mode of interest)
            m[nf + j] += -1 if (k - N_G * nf) % N_SW == 0 else 1
            return 0
        if _lash_msl(p, r):   # MSL's damping law: its kinks change the mode silently; the edges are events
            old = m[nf + j]
            new = _lash_msl_update(p, r, x, n, old, (k - N_G * nf) % N_SW)
            if new == LASH_GAP:   # at the edge: what the spring holds is ~0 (as below)
                dissipate(p, x, n, r, spring_energy(p, r, x, n, m))
            m[nf + j] = new
            if old == LASH_GAP or new == LASH_GAP:
                record(log, t, EV_CONTACT if new != LASH_GAP else EV_SEPARATE, nf + j)
            return 0
        side = LASH_UPPER if (k - N_G * nf) % N_SW == 0 else LASH_LOWER   # b/2 - phi: the gap's upper side
        w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
        mode = m[nf + j]
        if mode == LASH_UPPER_RELEASED or mode == LASH_LOWER_RELEASED:
            if (k - N_G * nf) % N_SW == 1:   # the edge, inward: into the gap (no event: it separated already)
                m[nf + j] = LASH_GAP
                return 0
            m[nf + j] = LASH_UPPER if mode == LASH_UPPER_RELEASED else LASH_LOWER   # it pushes again
            record(log, t, EV_CONTACT, nf + j)
        elif mode == LASH_GAP and ((side == LASH_UPPER and w_rel > 0.0) or (side == LASH_LOWER and w_rel < 0.0)):
            m[nf + j] = side
            record(log, t, EV_CONTACT, nf + j)
        elif mode == side:
            # a damped contact separates beyond its edge, moving back (its damper pulls first): released there, the
            # spring still deflected, its energy stored until it goes to the damper on the way to the edge
            # (spring_torque), or the contact closes again where it would push.  At (or, by the event's bracket,
            # inside) the edge: into the gap, the energy left in the spring (~0) counted as dissipated
            if _lash_contact(p, r, x, n, 1.0 if side == LASH_UPPER else -1.0)[0] > 0.0:
                m[nf + j] = LASH_UPPER_RELEASED if side == LASH_UPPER else LASH_LOWER_RELEASED
            else:
                dissipate(p, x, n, r, spring_energy(p, r, x, n, m))
                m[nf + j] = LASH_GAP
            record(log, t, EV_SEPARATE, nf + j)
        else:
            return 0
        # the torque of a damped contact steps at impact: a stuck element may have to break away now (its
        # break-away function starts the next step beyond zero, which is no crossing)
        settle_outlined(t, x, m, p, log, m.copy(), r)
        return 0
    kf = k // N_G
    if k % N_G == G_TURN or k % N_G == G_NEAR or k % N_G == G_ROW:
        # a sliding speed's or a stuck margin's turning point, a stuck element coming near its limit, or a corner of a
        # sliding one's law: a step ends there, nothing changes
        return 0
    old = m.copy()
    if k % N_G == G_STICK and (m[kf] == FORWARD or m[kf] == BACKWARD):
        m[kf] = STUCK
    settle_outlined(t, x, m, p, log, old, p.fric[kf])
    return 0


@numba.njit(cache=True, nogil=True, _nrt=True)
def driveline_restart(t, x, u, m, p, log):
    """Modes consistent with the forces at a start, a resume or a signal's jump (the signal cache emptied first:
    :func:`forget_signals`).  At the break time last given to the core (:func:`_break_marker`) it is a signal's
    jump: only the items linked to the elements whose signals jump are searched (:func:`settle`, origin -2); else
    every item."""
    if u.shape[0] > 0 and hold_inputs(p.data, u):
        forget_signals(p)
    forget_signals(p)
    _instant(p)[0] = np.nan   # a new instant (:func:`_one_search_per_instant`)
    mark = _break_marker(p)
    origin = _ZERO - 2 if t == mark[0] else _ZERO - 1
    mark[0] = np.nan
    return settle_outlined(t, x, m, p, log, m.copy(), origin)


@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_start(t, x, u, m, p):
    """What a run derives from its initial state alone (the core's ``start`` hook, before its first restart; the
    network's Python side calls it for the modes a :class:`~clutchlab.system.System` starts from, and a native FMU
    again after a host set an initial speed or angle): the modes below, then the stored energy (kinetic and elastic,
    [J]) the energy balance starts from, in the last word of ``p.work``.  The modes are a guess from the state that
    the restart at the start settles at the forces (:func:`driveline_restart`):

    * a friction element free where its normal force is negative, or zero and not rising (:func:`_is_free`), else
      sliding the way it turns, stuck at zero relative speed;
    * a backlash in contact beyond the edge of its gap (at the edge, if moving into it); with MSL's damping law,
      limited where its damping torque would exceed the elastic one; beyond the edge where the contact would pull,
      released (either law);
    * a curve spring on the segment it lies on (at a point, the one it moves onto);
    * a lossy gear rolling the way its flange a turns on its support, or stuck.

    Returns 0, or the model error code ``-(INV_BASE + N_INV r + INV_START)`` of the first element (row ``r``) whose
    initial state no run can start from: a gear or a motion source whose flanges' speeds (angles) disagree with it
    (:func:`kinematic_error`), else a one-way clutch whose flange b turns slower than its flange a (it never slides
    backward: MSL ``OneWayClutch`` locks that way, so no mode of it holds that state).  The run does not start; a
    native FMU refuses the start values a host set with the element's message.
    """
    if u.shape[0] > 0:
        hold_inputs(p.data, u)
    forget_signals(p)   # (a host may have set a signal's parameters since the cache was filled)
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    derive_speeds(x, p)
    update_shifts(p, x)   # (a shifted E-clutch's lift-off at the initial state: whether it starts free)
    code = kinematic_error(t, x, p)
    if code == 0:
        code = shift_error(x, p)
    for j in range(p.lossy.shape[0]):
        r = p.lossy[j]
        w_a = _speed(x, n, p.elem[r, E_A]) - _speed(x, n, p.elem[r, E_SUP])
        m[p.elem[r, E_MODE]] = GEAR_FWD_A if w_a > 0.0 else GEAR_BWD_A if w_a < 0.0 else GEAR_STUCK
    for j in range(p.swit.shape[0]):
        r = p.swit[j]
        phi = _spring_deflection(p, r, x, n)
        w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
        k = p.elem[r, E_MODE]
        if p.elem[r, E_LAW] == SPRING_CURVE:
            s = p.elem[r, E_TABLE]
            xs = p.data[s:s + p.elem[r, E_TABLE_N]]
            m[k] = np.searchsorted(xs, phi, side="left") if w_rel < 0.0 else np.searchsorted(xs, phi, side="right")
            continue
        b2 = 0.5 * p.coef[r, C_GAP]
        upper = phi > b2 or (phi == b2 and w_rel > 0.0)
        lower = phi < -b2 or (phi == -b2 and w_rel < 0.0)
        m[k] = LASH_UPPER if upper else LASH_LOWER if lower else LASH_GAP
        if upper or lower:   # which part of the law: side * tau_c = a, side * tau_d = b
            side = 1.0 if upper else -1.0
            a = side * p.coef[r, C_STIFF] * (phi - side * b2)
            b = side * p.coef[r, C_DAMP] * w_rel
            if p.elem[r, E_AUX] == LASH_MSL and b >= a:
                m[k] = LASH_UPPER_LIMITED if upper else LASH_LOWER_LIMITED
            elif a + b <= 0.0 and a > 0.0:   # beyond the edge, the contact would pull: released (both laws)
                m[k] = LASH_UPPER_RELEASED if upper else LASH_LOWER_RELEASED
    for k in range(nf):
        r = p.fric[k]
        w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
        m[k] = FREE if _is_free(p, r, t) else FORWARD if w_rel > 0.0 else BACKWARD if w_rel < 0.0 else STUCK
        if code == 0 and p.elem[r, E_LAW] == LAW_ONEWAY and w_rel < 0.0:
            code = -(INV_BASE + N_INV * r + INV_START)   # (it never slides backward: no state to start from)
    stored = 0.0
    for i in range(n):
        stored += 0.5 * p.inertia[i] * x[n + i] ** 2
    for r in range(p.elem.shape[0]):
        if p.elem[r, E_KIND] == K_SPRING:
            stored += spring_energy(p, r, x, n, m)
    p.work[p.work.shape[0] - 1] = stored
    return code


@numba.njit(cache=True, nogil=True, _nrt=False)
def kinematic_error(t, x, p):
    """0, or the model error code ``-(INV_BASE + N_INV r + INV_START)`` of the first gear or motion source (row
    ``r``) that the state ``x`` at ``t`` breaks: a gear's flanges turn ``w_a - w_s = ratio (w_b - w_s)`` about its
    support (MSL ``IdealGear``; a flange on the ground at rest), a speed source's flange at its signal's value, a
    position source's at its signal's value [rad] and rate [rad/s] -- each to 1e-9 relative, 1e-12 absolute (as
    :func:`math.isclose`).  A network's initial speeds follow from these where they are left out
    (:meth:`~clutchlab.driveline.Driveline.initial_state`); where given, they must agree (a native FMU's host may set
    any of them: the FMU's ``start`` refuses a disagreement)."""
    n = p.inertia.shape[0]
    for r in range(p.elem.shape[0]):
        kind = p.elem[r, E_KIND]
        if kind == K_GEAR:
            ws = _speed(x, n, p.elem[r, E_SUP])
            a = _speed(x, n, p.elem[r, E_A]) - ws
            b = p.coef[r, C_RATIO] * (_speed(x, n, p.elem[r, E_B]) - ws)
            if not _isclose(a, b):
                return -(INV_BASE + N_INV * r + INV_START)
        elif kind == K_MOTION:
            i = p.elem[r, E_B]
            s = p.elem[r, E_SIGNAL]
            if p.elem[r, E_LAW] == MOTION_SPEED:
                if not _isclose(_speed(x, n, i), signal_at(p, s, t)):
                    return -(INV_BASE + N_INV * r + INV_START)
            else:
                rate = signal_rates(p.signals[s], p.data, t)[0]
                if not (_isclose(x[i], signal_at(p, s, t)) and _isclose(_speed(x, n, i), rate)):
                    return -(INV_BASE + N_INV * r + INV_START)
    return 0


@numba.njit(cache=True, nogil=True, _nrt=False)
def derive_speeds(x, p):
    """The initial speeds the description left out, carried from the ones it gives along the gears (MSL
    ``IdealGear``: ``w_a - w_s = ratio (w_b - w_s)``), into ``x`` (part of :func:`driveline_start`).

    Each gear with ``elem[r, E_SPREAD] = +d`` sets its flange b's speed from flange a's, ``-d`` flange a's from
    flange b's, in order of depth ``d`` (a flange at depth d follows one at d - 1, given or derived before), with the
    support's speed where ``elem[r, E_SPREAD_SUP]`` is 1 and rest otherwise: the arithmetic of
    :meth:`~clutchlab.driveline.Driveline.initial_state`, which fills those columns (so a run's speeds are the
    description's to the last bit), again at the start of every run.  A native FMU so derives them from the speeds
    and ratios a host set (a gear's ratio and a given speed are parameters; a speed left out is not).  The speeds a
    motion source or a gear to the ground sets are not derived here: :func:`kinematic_error` checks them."""
    n = p.inertia.shape[0]
    deepest = 0
    for r in range(p.elem.shape[0]):
        deepest = max(deepest, abs(p.elem[r, E_SPREAD]))
    for d in range(1, deepest + 1):
        for r in range(p.elem.shape[0]):
            s = p.elem[r, E_SPREAD]
            if s != d and s != -d:
                continue
            ratio = p.coef[r, C_RATIO]
            ws = x[n + p.elem[r, E_SUP]] if p.elem[r, E_SPREAD_SUP] == 1 else 0.0
            if s > 0:   # w_b from w_a
                factor = 1.0 / ratio
                x[n + p.elem[r, E_B]] = factor * x[n + p.elem[r, E_A]] + (1.0 - 1.0 / ratio) * ws
            else:       # w_a from w_b
                x[n + p.elem[r, E_A]] = ratio * x[n + p.elem[r, E_B]] + (1.0 - ratio) * ws


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _isclose(a, b):
    """``math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-12)``."""
    return abs(a - b) <= max(1e-9 * max(abs(a), abs(b)), 1e-12)


# invariants a run must keep (:func:`check_invariants`): the model error code of a violation is
# -(INV_BASE + N_INV * row + kind), the row of the element (the network's energy balance: row = the element count)
# (the last two are not invariants but model errors every run checks, without "invariant violated" in their messages:
# "table", :func:`table_error`; "start", an initial state no mode holds, :func:`driveline_start`)
INVARIANT_NAMES = ("limit", "mode", "oneway", "loss", "energy", "gap", "table", "start")
INV_LIMIT, INV_MODE, INV_ONEWAY, INV_LOSS, INV_ENERGY, INV_GAP, INV_TABLE, INV_START = indices(
    INVARIANT_NAMES, "limit", "mode", "oneway", "loss", "energy", "gap", "table", "start")
INVARIANTS = ("stuck beyond its static limit", "mode inconsistent with the sign of its relative speed",
              "one-way clutch transmits torque in its free direction", "negative loss (power generated)",
              "energy balance beyond its tolerance",
              "backlash in its gap beyond an edge moving outward, or released where its contact would push (a "
              "contact missed), or in contact where it pulls (a separation missed)",
              "its loss table, extrapolated beyond its last row, gives an efficiency <= 0 at the speed the gear "
              "turns at; give rows up to the speeds the run reaches",
              "a one-way clutch cannot start with flange b slower than flange a (it never slides backward)")
INV_BASE = 100
N_INV = len(INVARIANT_NAMES)


@numba.njit(cache=True, nogil=True, _nrt=False)
def check_invariants(t, x, m, p):
    """The invariants of the network at an accepted step: 0, or the model error code of the first violated.

    * a stuck friction element carries at most what it holds (its static limit, a one-way clutch any torque against
      overrunning), a stuck lossy gear's loss torque within its band, to the decision's rounding floor (:data:`NOISE`)
      and 1e-9 relative;
    * modes agree with the relative speeds: forward >= 0, backward <= 0, stuck ~0 (to 1e-6 of the largest speed of
      the element's inertias, what the event location and a stuck element's drift leave);
    * a one-way clutch never transmits torque in its free direction (beyond its clutch's) and never turns backward;
    * every rolling lossy gear's loss torque opposes its motion, so its loss power is >= 0 (to rounding), and so does
      every sliding friction element's (its law's magnitude is >= 0) and every torque converter's;
    * a backlash in its gap is not beyond an edge moving on outward, and one released beyond an edge (a damped contact
      that separated there) is not where its contact would push (either: a contact missed); one in contact does not
      pull (a separation missed);
    * the energy balance (input work - dissipated - change of the stored energy) within ``check[1]`` of the energy
      that flowed plus 1 J (the integrator's absolute error in the energy states while little has flowed), and the
      thermal masses' heat balance (heat stored plus heat given to the ambients against the energy their elements
      dissipated, :func:`thermal_rates`) within ``check[1]`` of those plus 1 J.
    """
    n = p.inertia.shape[0]
    nf = p.fric.shape[0]
    ne = p.elem.shape[0]
    for s in range(p.signals.shape[0]):   # a step ending on a signal's jump: the restart there settles the modes
        if _jumps_at(p, s, t):
            return 0
    acc, tau = _acc_tau(p)
    evaluate_network(t, x, m, p, acc, tau)
    for k in range(nf):
        r = p.fric[k]
        noise = _item_noise(p, r, tau)
        w_tol = 1e3 * _item_wtol(p, r, x, n)
        w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
        mk = m[k]
        tq = tau[r]
        if mk == STUCK:
            if _past_limit(t, p, tau, k)[1] > 0.0:
                return -(INV_BASE + N_INV * r + (INV_ONEWAY if p.elem[r, E_LAW] == LAW_ONEWAY else INV_LIMIT))
            if abs(w_rel) > w_tol:
                return -(INV_BASE + N_INV * r + INV_MODE)
        elif (mk == FORWARD and w_rel < -w_tol) or (mk == BACKWARD and w_rel > w_tol):
            return -(INV_BASE + N_INV * r + INV_MODE)
        elif (mk == FORWARD or mk == BACKWARD) and p.elem[r, E_LAW] != LAW_EXTERNAL and \
                friction_torque(p, r, t, abs(w_rel)) < -10.0 * noise:
            # sliding: the torque opposes the slip with the law's magnitude, so its loss power is that magnitude
            # times |w_rel|, >= 0 only while the magnitude is (a model component's law is its own)
            return -(INV_BASE + N_INV * r + INV_LOSS)
        if p.elem[r, E_LAW] == LAW_ONEWAY:
            cap = max(static_limit(p, r, t), friction_torque(p, r, t, abs(w_rel)), noise)
            if mk == BACKWARD or w_rel < -w_tol or tq > cap * (1.0 + 1e-9) + noise:
                return -(INV_BASE + N_INV * r + INV_ONEWAY)
    for j in range(p.lossy.shape[0]):
        r = p.lossy[j]
        mode = m[p.elem[r, E_MODE]]
        w_a = gear_speed(p, r, x, n)
        noise = _item_noise(p, r, tau)
        w_tol = 1e3 * _item_wtol(p, r, x, n)
        if mode == GEAR_STUCK:
            if _past_limit(t, p, tau, nf + j)[1] > 0.0:
                return -(INV_BASE + N_INV * r + INV_LIMIT)
            if abs(w_a) > w_tol:
                return -(INV_BASE + N_INV * r + INV_MODE)
        else:
            if GEAR_CODES[mode] * w_a < -w_tol:
                return -(INV_BASE + N_INV * r + INV_MODE)
            # rolling: MSL's lossPower = tauLoss w_a >= 0, the loss torque of its quadrant opposing the motion
            # (with the mode agreeing with the speed, checked above; at rest a drift of w_a has either sign)
            f, c = gear_transfer(p, r, mode, abs(w_a))
            if ((1.0 - f) * (-tau[r]) + c) * GEAR_CODES[mode] < -10.0 * noise:
                return -(INV_BASE + N_INV * r + INV_LOSS)
    for r in range(ne):   # a torque converter's loss (its tables were checked for TR SR <= 1; rounding aside)
        if p.elem[r, E_KIND] == K_CONVERTER:
            ta, tb, _sr = converter_torques(p, r, x, n)
            scale = (abs(ta) + abs(tb)) * 1e9 * _item_wtol(p, r, x, n)   # [W]: its torques times its fastest speed
            if converter_power(p, r, x, n) < -1e-12 * scale:
                return -(INV_BASE + N_INV * r + INV_LOSS)
    for j in range(p.swit.shape[0]):
        r = p.swit[j]
        if p.elem[r, E_LAW] == SPRING_BACKLASH and m[nf + j] == LASH_GAP:
            b2 = 0.5 * p.coef[r, C_GAP]
            phi = _spring_deflection(p, r, x, n)
            w_rel = _speed(x, n, p.elem[r, E_B]) - _speed(x, n, p.elem[r, E_A])
            w_tol = 1e3 * _item_wtol(p, r, x, n)
            tol = 1e-8 * max(1.0, b2)
            # (a damped contact separates beyond its edge into its released mode, not into the gap)
            if (phi > b2 + tol and w_rel > w_tol) or (phi < -b2 - tol and w_rel < -w_tol):
                return -(INV_BASE + N_INV * r + INV_GAP)
        elif p.elem[r, E_LAW] == SPRING_BACKLASH and (m[nf + j] == LASH_UPPER_RELEASED or
                                                       m[nf + j] == LASH_LOWER_RELEASED):
            # released beyond an edge: never where its contact would push (tau / c past zero the contact's way)
            _beyond, push = _lash_contact(p, r, x, n, 1.0 if m[nf + j] == LASH_UPPER_RELEASED else -1.0)
            if push > 1e-6 * max(1.0, 0.5 * p.coef[r, C_GAP]) + p.coef[r, C_DAMP] / p.coef[r, C_STIFF] * 1e3 * \
                    _item_wtol(p, r, x, n):
                return -(INV_BASE + N_INV * r + INV_GAP)
        elif p.elem[r, E_LAW] == SPRING_BACKLASH and (m[nf + j] == LASH_UPPER or m[nf + j] == LASH_LOWER):
            # in contact (either damping law): never where it pulls (tau / c past zero the other way, the same width)
            _beyond, push = _lash_contact(p, r, x, n, _lash_side(m[nf + j]))
            if push < -(1e-6 * max(1.0, 0.5 * p.coef[r, C_GAP]) + p.coef[r, C_DAMP] / p.coef[r, C_STIFF] * 1e3 *
                        _item_wtol(p, r, x, n)):
                return -(INV_BASE + N_INV * r + INV_GAP)
    if p.check[1] > 0.0:
        kinetic, spring, work, lost = 0.0, 0.0, 0.0, 0.0
        for i in range(n):
            kinetic += 0.5 * p.inertia[i] * x[n + i] ** 2
        for r in range(ne):
            kind = p.elem[r, E_KIND]
            if kind == K_SOURCE or kind == K_MOTION:
                work += x[2 * n + r]
            else:
                lost += x[2 * n + r]
            if kind == K_SPRING:
                spring += spring_energy(p, r, x, n, m)
        e0 = p.work[p.work.shape[0] - 1]
        flow = abs(work) + abs(lost) + kinetic + spring + e0
        if abs(work - lost - (kinetic + spring - e0)) > p.check[1] * (flow + 1.0):
            return -(INV_BASE + N_INV * ne + INV_ENERGY)
        if p.thermal.shape[0] > 0:
            # the heat balance of the thermal masses: what they store and gave their ambients is what their
            # elements dissipated (the links move heat between them)
            heat, given = 0.0, 0.0
            for k in range(p.thermal.shape[0]):
                s = int(p.thermal[k, T_STATE])
                heat += p.thermal[k, T_CAP] * (x[s + TS_TEMP] - p.thermal[k, T_INIT]) + x[s + TS_OUT]
            for r in range(ne):
                if p.elem[r, E_HEAT] >= 0:
                    given += x[2 * n + r]
            if abs(heat - given) > p.check[1] * (abs(heat) + abs(given) + 1.0):
                return -(INV_BASE + N_INV * ne + INV_ENERGY)
    return 0


#: :func:`check_invariants` called through its address (:mod:`clutchlab.numerics.outline`): a debugging option, kept
#: out of the compilation of the accept hook and the core that calls it at every step
_check_outlined = outlined(check_invariants, lambda: (types.float64, _F1, _I1, _params_type()), types.int64,
                           lazy=True)   # (a debug option: compiled where a run asks for it)


@numba.njit(cache=True, nogil=True, _nrt=False)
def table_error(x, p):
    """0, or the model error code (``-(INV_BASE + N_INV r + INV_TABLE)``) of the first lossy gear row ``r`` whose loss
    table, extrapolated beyond its last row (MSL ``LossyGear``: linear from the last two rows), gives a mesh
    efficiency ``<= 0`` at the speed ``|w_a|`` [rad/s] it turns at in state ``x``: no gear has one, and the law
    (:func:`gear_losses`) holds it at :data:`ETA_MIN` only within the step that crosses it."""
    n = p.inertia.shape[0]
    for j in range(p.lossy.shape[0]):
        r = p.lossy[j]
        s, k = p.elem[r, E_TABLE], p.elem[r, E_TABLE_N]
        if k < 2:
            continue
        w = abs(gear_speed(p, r, x, n))
        if w <= p.data[s + k - 1]:
            continue
        if _gear_column(p.data, s, k, 1, w) <= 0.0 or _gear_column(p.data, s, k, 2, w) <= 0.0:
            return -(INV_BASE + N_INV * r + INV_TABLE)
    return 0


@numba.njit(cache=True, nogil=True, _nrt=False)
def shift_error(x, p):
    """0, or the model error code (``-(INV_BASE + N_INV r + INV_TABLE)``) of the first shifted E-clutch (row ``r``,
    :func:`shifted_curve`) whose working point's shift at the state ``x`` (:func:`update_shifts`) left the levels
    its table was built for (by more than a micrometre's thousandth): its wear beyond ``wear_max`` or its
    temperature beyond the table's span.  Held at the last level, its force would be a silent guess."""
    if not _shifted(p):
        return 0
    for k in range(p.fric.shape[0]):
        r = p.fric[k]
        nl = int(p.coef[r, C_LEVELS])
        if nl <= 0:
            continue
        s = working_point_shift(p, r, x)
        o = int(p.coef[r, C_NCURVE])
        if s < p.data[o] - 1e-9 or s > p.data[o + nl - 1] + 1e-9:
            return -(INV_BASE + N_INV * r + INV_TABLE)
    return 0


@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_accept(t, x, u, m, p):
    """Nothing to commit (the network has no memories); a lossy gear whose loss table's extrapolation reached an
    efficiency <= 0 ends the run with a model error naming it (:func:`table_error`); with ``check[0]`` set, the
    invariants (:func:`check_invariants`): a violation ends the run with a model error naming the element."""
    if u.shape[0] > 0 and hold_inputs(p.data, u):
        forget_signals(p)
    if p.lossy.shape[0] > 0:
        code = table_error(x, p)
        if code != 0:
            return code
    code = shift_error(x, p)
    if code != 0:
        return code
    if p.check[0] != 0.0:
        observe(p, True)   # (a debug option: it changes no decision)
        code = _check_outlined(t, x, m, p)
        observe(p, False)
        return code
    return 0


@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_next_break(t, m, p):
    """Next jump or kink of any signal (steps, ramp corners, table points, a sine's start)."""
    tb = np.inf
    for s in range(p.signals.shape[0]):
        v = signal_break(p.signals[s], p.data, t)
        if v < tb:
            tb = v
    _break_marker(p)[0] = tb
    return tb


@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_jacobian(t, x, u, m, p, J):
    """No analytic Jacobian (Dormand-Prince)."""
    return False


#: :func:`driveline_rhs` called through its address (:mod:`clutchlab.numerics.outline`) where the core evaluates it
#: at events (locating a root, the step to it, a break): each of those functions of the core would otherwise link the
#: network's evaluation and optimise it again (docs/architecture.md); the step's stages call it directly
_rhs_outlined = outlined(driveline_rhs, lambda: (types.float64, _F1, _F1, _I1, _params_type(), _F1, _F1), types.none)
#: :func:`_margin_rates` through its address: it runs only while a stuck element is near its limit, and linked it was
#: optimised and emitted again in the watch hook and in every function of the core that calls it (seven copies,
#: 16,700 of the driveline group's 263,000 instructions; docs/architecture.md)
_margin_rates_outlined = outlined(_margin_rates, lambda: (types.float64, _F1, _F1, _I1, _params_type(), _F1, _F1),
                                  types.none)


@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_rhs_event(t, x, u, m, p, dx, g):
    """:func:`driveline_rhs` through its address (the core's ``rhs_event`` hook)."""
    _rhs_outlined(t, x, u, m, p, dx, g)


@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_watch(t, x, u, m, p, dx, g, k):
    """The core's ``watch`` hook (where it compares the switching functions across a step, never at a step's
    stages): the margin rates of the stuck elements near their limits (:func:`_margin_rates`, through its address),
    one more evaluation of the network while one is, and only where the core reads one of them (``k`` a stuck
    element's turn function, or -1 for all: a probe locating a break-away reads only that); nothing else."""
    if u.shape[0] > 0 and hold_inputs(p.data, u):
        forget_signals(p)
    if wants_rates(p, m, g, k):
        _margin_rates_outlined(t, x, u, m, p, dx, g)


@numba.njit(cache=True, nogil=True, _nrt=False)
def wants_rates(p, m, g, k):
    """True where :func:`driveline_watch` takes margin rates: a stuck item's turn function marked 0.0 by
    :func:`driveline_rhs` (a friction element near its limit, a stuck lossy gear), the one read
    (``k``) or any (``k < 0``).  (A network with model components asks the same before it moves their states,
    :mod:`clutchlab.driveline.coupled`: a gear's mark left at 0.0 there read as a crossing at every step)"""
    for j in range(p.fric.shape[0] + p.lossy.shape[0]):
        q = _turn_index(p, j)
        if (k < 0 or k == q) and g[q] == 0.0 and _stuck_breaks(p, m, j)[0] >= 0:
            return True
    return False


#: :func:`driveline_start` through its address: it runs once per run (and per call of a session or model exchange
#: that asks for it), so it is compiled once, not into each entry of the core that may start a run
_start_outlined = outlined(driveline_start, lambda: (types.float64, _F1, _F1, _I1, _params_type()), types.int64)


@numba.njit(cache=True, nogil=True, _nrt=False)
def driveline_start_hook(t, x, u, m, p):
    """:func:`driveline_start` through its address (the core's ``start`` hook)."""
    return _start_outlined(t, x, u, m, p)


# the network's own hooks for its own parameter type (a System on a bare DrivelineParams runs them);
# Driveline.system runs every network on clutchlab.driveline.coupled.CoupledParams, whose hooks are these for a
# network without model components (one compiled kernel for every network)
dispatch.register(DrivelineParams, rhs=driveline_rhs, outputs=driveline_outputs, update=driveline_update,
                  restart=driveline_restart, accept=driveline_accept, next_break=driveline_next_break,
                  jacobian=driveline_jacobian, rhs_event=driveline_rhs_event, watch=driveline_watch,
                  start=driveline_start_hook)
