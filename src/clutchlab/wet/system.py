"""The wet-clutch engagement model on the system contract (:mod:`clutchlab.system`).

The model of :mod:`clutchlab.wet.engagement` (Shin, Kim and Choi [1],
Eqs. 1-8, with the squeeze-film / asperity engagement dynamics of Deur et al.
[4]) written once against the contract:

* :class:`WetParams` -- every parameter, reference profile, table and per-run
  memory in one ``NamedTuple``, packed by :func:`pack_parameters` (the only
  place they are packed; :func:`with_scenario` swaps a packed scenario for
  another, tested equal to packing afresh);
* the compiled hooks (``rhs``, ``outputs``, ``update``, ``restart``,
  ``accept``, ``next_break``, ``jacobian``) registered for :class:`WetParams`
  with :func:`clutchlab.numerics.dispatch.register`; the integrator core
  (:mod:`clutchlab.numerics.core`) compiles them in;
* :func:`engagement_system` -- the :class:`~clutchlab.system.System` of one
  engagement (the model ``"wet"`` is it for a bench protocol,
  :func:`clutchlab.wet.bench.protocol_system`).

States, outputs and events
--------------------------
States (SI, temperatures in degC): piston position, actuator force, slip
speed, speed-controller integral, pack / reservoir / housing / thermistor
temperatures, and the energy integrals (friction work, heat to the oil, heat
to the housing, drive work).  Outputs: the 18 quantities of
:data:`OUTPUTS` (torques, forces, film, viscosity, references, powers).

Modes and their switching functions (located by the core on the dense
output, so nothing in the right-hand side has a kink inside a step):

* ``friction``: ``slip_positive`` / ``stick`` / ``slip_negative`` -- the
  sliding direction is part of the mode.  ``lockup``: the slip speed falls
  through zero while slipping; the clutch sticks if the static capacity
  ``R_eff N_c mu_f F_c`` holds the drive torque, otherwise the slip reverses
  (``slip_reversal``).  ``breakaway``: ``|T_drive| - capacity`` rises through
  zero while stuck.
* ``piston``: ``free`` / ``at_stop``.  The piston rests on its stop at
  ``x_p = 0`` while the force balance pushes it against the stop.
  ``piston_reaches_stop``: ``x_p`` falls through zero; ``piston_leaves_stop``:
  the free piston speed (the speed the force balance would give) rises
  through zero.  (The former kernel clipped ``dx_p/dt`` at the stop inside
  the right-hand side, an unlocated kink.)
* ``film``: ``open`` / ``contact`` -- the nominal separation ``h`` (Eq. 1)
  crosses zero (Fig. 3 (b) -> (c)): ``contact`` / ``separation``.
* ``piston_run``: ``settling`` / ``engaging`` / ``releasing`` -- whether a
  turn of the free piston is watched, and from which direction (no event is
  recorded for it).  The piston leaving its stop is ``engaging``;
  ``piston_runs``: ``|F_net|`` rises through ``PISTON_RUNNING c v_max``
  (76 % of the speed limit) while settling; ``piston_turns``: the net
  force of an engaging piston falls through zero, of a releasing one rises
  (the tanh of :func:`piston_speed` turns from one speed limit to the other
  within microseconds where the open film resists little; the step size
  starts afresh there, and the piston is ``settling``).  The hysteresis
  between the two keeps a piston settling on an equilibrium, its net force
  hovering at zero, from triggering a turn again and again.

The corners of the force and slip-speed reference profiles are break times
(``next_break``): steps end on them exactly.

Inputs
------
Two held inputs are added to the scenario's reference profiles:
``force_reference`` [N] and ``slip_speed_reference`` [rad/s].  They are
zero for a scenario run; the co-simulation (:mod:`clutchlab.fmu.cosim`)
sets them at every communication point with flat profiles.

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
.. [2] N. Patir, H. S. Cheng, J. Lubrication Technol. 101 (1979) 220-229.
.. [3] J. A. Greenwood, J. B. P. Williamson, Proc. R. Soc. Lond. A 295 (1966) 300-319.
.. [4] J. Deur, J. Petric, J. Asgari, D. Hrovat, "Modeling of wet clutch
   engagement including a thorough experimental validation", SAE Trans.
   (2005) 1013-1028, doi:10.4271/2005-01-0877
"""

from __future__ import annotations

import math
import struct
from typing import NamedTuple

import numba
import numpy as np

from ..errors import ParameterError
from ..numerics import dispatch
from ..numerics.core import RESTART, record
from ..numerics.interp import grid_waypoint
from ..numerics.layout import indices, slots
from ..system import System, variables
from .film import (asperity_force_scalar, effective_radius_scalar, film_scalar, gw_pressure_scale_scalar,
                   separation_scalar, slip_velocity_scalar, squeeze_film_coefficient_scalar, squeeze_film_force_scalar)
from .friction import KIND_PARAMETRIC, ParametricFriction, mu_kernel, parametric_mu_scalar
from .thermal import heat_balance_scalar, pack_heat_capacity_scalar
from .torque import asperity_torque_scalar, clutch_torque_scalar, viscous_torque_scalar
from .viscosity import viscosity_scalar

# WetParams, the parameters of the compiled hooks, is the kernel's internal: not API (#33)
__all__ = [
    "pack_parameters", "with_scenario", "fresh_buffers", "stacked_parameters", "new_work",
    "engagement_system", "initial_state",
    "initial_modes", "absolute_tolerance", "peak_temperature", "lockup_time", "piston_speed", "drive_torque", "tanh",
    "CONSTANTS", "STATE_SCALES", "STATES", "OUTPUTS", "BENCH_OUTPUTS", "INPUTS", "SWITCHING", "EVENTS", "MODE_NAMES", "MODE_VALUES",
]

# ----------------------------------------------------------------- layout
#: states: (name, unit, description)
STATES = (
    ("piston_position", "m", "piston position x_p, positive towards the pack (0: on its stop)"),
    ("actuator_force", "N", "actuator force (first-order lag of the reference)"),
    ("slip_speed", "rad_s", "slip speed = clutch shaft speed (outer plates held)"),
    ("controller_integral", "Nm", "integral term of the speed controller"),
    ("temperature", "C", "pack temperature T (Eq. 8)"),
    ("fluid_temperature", "C", "oil reservoir temperature"),
    ("housing_temperature", "C", "housing temperature"),
    ("thermistor_temperature", "C", "thermistor reading (first-order lag of T)"),
    ("friction_work", "J", "friction work, integral of tau * dw"),
    ("heat_to_fluid", "J", "heat from the pack to the oil, integral of k1 (T - T_fluid)"),
    ("heat_to_housing", "J", "heat from the pack to the housing, integral of k2 (T - T_housing)"),
    ("drive_work", "J", "work of the drive motor, integral of T_drive * dw"),
)
(S_X, S_FA, S_W, S_I, S_T, S_TF, S_TH, S_TM, S_EF, S_EK1, S_EK2, S_ED) = indices(
    STATES, "piston_position", "actuator_force", "slip_speed", "controller_integral", "temperature",
    "fluid_temperature", "housing_temperature", "thermistor_temperature", "friction_work", "heat_to_fluid",
    "heat_to_housing", "drive_work")
N_STATE = len(STATES)

#: outputs: (name, unit, description)
OUTPUTS = (
    ("clutch_torque", "Nm", "clutch torque tau = tau_c + tau_v (Eq. 3)"),
    ("contact_torque", "Nm", "asperity contact torque tau_c (Eq. 4); the drive torque while stuck"),
    ("viscous_torque", "Nm", "viscous torque tau_v (Eq. 5)"),
    ("contact_force", "N", "asperity contact force F_c (Greenwood-Williamson)"),
    ("squeeze_force", "N", "hydrodynamic squeeze-film force"),
    ("load_cell_force", "N", "force at the actuator load cell"),
    ("nominal_separation", "m", "nominal separation h per interface (Eq. 1)"),
    ("mean_film", "m", "Patir-Cheng mean film thickness h_bar (Eq. 2)"),
    ("friction_coefficient", "1", "asperity friction coefficient mu_f"),
    ("viscosity", "Pa_s", "oil viscosity mu_v (Eq. 7)"),
    ("drive_torque", "Nm", "drive motor torque at the clutch shaft"),
    ("slip_reference", "rad_s", "slip-speed reference of the speed controller"),
    ("force_reference", "N", "actuator force reference"),
    ("slip_acceleration", "rad_s2", "rate of change of the slip speed"),
    ("sensor_torque", "Nm", "torque at the shaft torque sensor"),
    ("friction_power", "W", "friction power tau * dw"),
    ("heater_power", "W", "reservoir heater power"),
    ("static_capacity", "Nm", "static torque capacity R_eff N_c mu_f F_c (Eq. 4)"),
)
(O_TAU, O_TC, O_TV, O_FC, O_FH, O_FLC, O_H, O_HBAR, O_MUF, O_MUV, O_TD, O_WREF, O_FREF, O_WDOT, O_TS,
 O_PF, O_QH, O_CAP) = indices(
    OUTPUTS, "clutch_torque", "contact_torque", "viscous_torque", "contact_force", "squeeze_force",
    "load_cell_force", "nominal_separation", "mean_film", "friction_coefficient", "viscosity", "drive_torque",
    "slip_reference", "force_reference", "slip_acceleration", "sensor_torque", "friction_power", "heater_power",
    "static_capacity")
#: the outputs that belong to the bench, not to the clutch (its drive motor, speed controller and slip
#: acceleration, torque sensor, load cell and reservoir heater): a clutch placed elsewhere (a driveline) has
#: none of them
BENCH_OUTPUTS = ("load_cell_force", "drive_torque", "slip_reference", "slip_acceleration", "sensor_torque",
                 "heater_power")
N_OUT = len(OUTPUTS)

#: held inputs, added to the scenario's reference profiles (zero in a scenario run)
INPUTS = (
    ("force_reference", "N", "actuator force reference, added to the scenario's force profile"),
    ("slip_speed_reference", "rad_s", "slip-speed reference, added to the scenario's speed profile"),
)
U_FORCE, U_SPEED = indices(INPUTS, "force_reference", "slip_speed_reference")

#: modes: friction, piston, film, and whether a turn of the free piston is watched (and from which direction)
MODE_NAMES = ("friction", "piston", "film", "piston_run")
MODE_VALUES = (("slip_positive", "stick", "slip_negative"), ("free", "at_stop"), ("open", "contact"),
               ("settling", "engaging", "releasing"))
M_FRICTION, M_PISTON, M_FILM, M_RUN = indices(MODE_NAMES, "friction", "piston", "film", "piston_run")
SLIP, STICK, SLIP_NEG = indices(MODE_VALUES[M_FRICTION], "slip_positive", "stick", "slip_negative")
FREE, AT_STOP = indices(MODE_VALUES[M_PISTON], "free", "at_stop")
OPEN, CONTACT = indices(MODE_VALUES[M_FILM], "open", "contact")
SETTLING, ENGAGING, RELEASING = indices(MODE_VALUES[M_RUN], "settling", "engaging", "releasing")
#: the piston runs (``piston_run`` engaging or releasing) once the argument of its speed law's tanh,
#: ``F_net / (c v_max)``, reaches this magnitude (tanh(1) = 0.76 of the speed limit); see :func:`piston_speed`
PISTON_RUNNING = 1.0

#: switching functions: (name, crossing direction)
#: (``friction_row``: a waypoint either way, direction 4, at each node of a friction map while sliding)
SWITCHING = (("lockup", -1), ("breakaway", 1), ("contact", 0), ("piston_leaves_stop", 1),
             ("piston_reaches_stop", -1), ("piston_runs", -1), ("piston_turns", -1), ("friction_row", 4))
G_LOCKUP, G_BREAKAWAY, G_CONTACT, G_LEAVES, G_REACHES, G_RUNS, G_TURNS, G_ROW = indices(
    SWITCHING, "lockup", "breakaway", "contact", "piston_leaves_stop", "piston_reaches_stop", "piston_runs",
    "piston_turns", "friction_row")
N_SWITCH = len(SWITCHING)

#: event names by code
EVENTS = ("contact", "separation", "lockup", "breakaway", "slip_reversal", "piston_reaches_stop",
          "piston_leaves_stop")
EV_CONTACT, EV_SEPARATION, EV_LOCKUP, EV_BREAKAWAY, EV_REVERSAL, EV_REACHES, EV_LEAVES = indices(
    EVENTS, "contact", "separation", "lockup", "breakaway", "slip_reversal", "piston_reaches_stop",
    "piston_leaves_stop")
#: elements an event concerns, and the element of each event
ELEMENTS = ("clutch", "piston")
EL_CLUTCH, EL_PISTON = indices(ELEMENTS, "clutch", "piston")
EVENT_ELEMENT = np.array([EL_CLUTCH, EL_CLUTCH, EL_CLUTCH, EL_CLUTCH, EL_CLUTCH, EL_PISTON, EL_PISTON])

#: scalar parameters: (field, unit, description) -- the named fields of ``WetParams.constants``
CONSTANTS = (
    ("n_c", "1", "number of clutches N_c (Table 1)"),
    ("r_eff", "m", "torque effective radius (Eq. (1'))"),
    ("sigma", "m", "RMS roughness (Table 1)"),
    ("friction_area", "m^2", "friction area of one face A_f"),
    ("piston_h0", "m", "piston position at zero separation"),
    ("mu_v1", "Pa*s", "viscosity parameter (Eq. 7)"),
    ("mu_v2", "1/K", "viscosity exponent (Eq. 7)"),
    ("mu_v3", "Pa*s", "viscosity parameter (Eq. 7)"),
    ("mu_v4", "1/K", "viscosity exponent (Eq. 7)"),
    ("heat_capacity", "J/K", "pack heat capacity (Eq. 8; derived by the start, wet_start)"),
    ("k1", "W/K", "conductance pack -> oil (Eq. 8)"),
    ("k2", "W/K", "conductance pack -> housing (Eq. 8)"),
    ("gw_scale", "Pa", "Greenwood-Williamson pressure scale (Eq. 11; derived by the start, wet_start)"),
    ("squeeze_coefficient", "m^4", "squeeze-film factor (groove factor x K)"),
    ("spring_stiffness", "N/m", "piston return spring"),
    ("spring_preload", "N", "return spring preload at x_p = 0"),
    ("total_inertia", "kg*m^2", "rotating inertia at the clutch shaft"),
    ("shaft_inertia", "kg*m^2", "inertia between torque sensor and clutch"),
    ("drive_torque_max", "N*m", "motor torque limit at the clutch shaft"),
    ("drive_speed_max", "rad/s", "motor speed limit at the clutch shaft (the slip-speed reference's range)"),
    ("motor_inertia", "kg*m^2", "motor and flywheel at the motor shaft (a copy: derive_drive)"),
    ("motor_torque_max", "N*m", "motor torque limit at the motor shaft (a copy: derive_drive)"),
    ("motor_speed_max", "rad/s", "motor speed limit at the motor shaft (a copy: derive_drive)"),
    ("gear_ratio", "1", "gear motor -> clutch shaft (a copy: derive_drive)"),
    ("motor_power_max", "W", "motor power limit"),
    ("speed_kp", "N*m*s/rad", "speed controller gain"),
    ("speed_ki", "N*m/rad", "speed controller integral gain"),
    ("actuator_time_constant", "s", "actuator force lag"),
    ("actuator_force_max", "N", "actuator force limit"),
    ("actuator_speed_max", "m/s", "actuator no-load speed"),
    ("thermistor_time_constant", "s", "thermistor lag"),
    ("reservoir_heat_capacity", "J/K", "oil reservoir"),
    ("heater_power_max", "W", "reservoir heater"),
    ("heater_gain", "W/K", "reservoir thermostat gain"),
    ("heater_setpoint", "degC", "reservoir thermostat set point"),
    ("reservoir_cooling", "W/K", "natural cooling of the reservoir"),
    ("housing_heat_capacity", "J/K", "housing"),
    ("housing_cooling", "W/K", "natural cooling of the housing"),
    ("fluid_housing_conductance", "W/K", "oil -> housing"),
    ("ambient_temperature", "degC", "laboratory"),
    ("r_outer", "m", "outer radius of the friction face R_o (Table 1)"),
    ("r_inner", "m", "inner radius of the friction face R_i (Table 1)"),
    ("squeeze_flow_factor", "1", "squeeze resistance of the grooved pack relative to a smooth annulus"),
    ("m_lining", "kg", "mass of one lining (Table 1)"),
    ("cp_lining", "J/(kg*K)", "specific heat capacity of the lining (Table 1)"),
    ("m_core", "kg", "mass of one core disk (Table 1)"),
    ("cp_core", "J/(kg*K)", "specific heat capacity of the core (Table 1)"),
    ("asperity_radius", "m", "asperity tip radius beta (Table 1)"),
    ("asperity_density", "1/m^2", "asperity density eta (Table 1)"),
    ("contact_modulus", "Pa", "composite elastic modulus E' of the asperities"),
    ("force_scale", "1", "factor on the force profile (batch variants)"),
    ("mu_scale", "1", "factor on mu_f (batch variants)"),
    ("speed_scale", "1", "factor on the slip-speed profile (batch variants)"),
    ("free_inertia", "1", "no motor torque (inertia dynamometer), a bool"),
    ("friction_kind", "1", "friction law: 0 parametric, 1 table (an int)"),
    ("force_start", "1", "force profile in data: times from here, then values (an int)"),
    ("force_n", "1", "breakpoints of the force profile (an int)"),
    ("speed_start", "1", "slip-speed profile in data (an int)"),
    ("speed_n", "1", "breakpoints of the slip-speed profile (an int)"),
    ("friction_start", "1", "coefficients of the friction law in data (an int)"),
    ("map_speed_start", "1", "friction map: slip-velocity grid in data (an int)"),
    ("map_speed_n", "1", "friction map: its length (an int)"),
    ("map_temperature_start", "1", "friction map: temperature grid in data (an int)"),
    ("map_temperature_n", "1", "friction map: its length (an int)"),
    ("map_force_start", "1", "friction map: force grid in data (an int)"),
    ("map_force_n", "1", "friction map: its length (an int)"),
    ("map_table_start", "1", "friction map: values in data (an int)"),
    ("map_table_n", "1", "friction map: their number (an int)"),
    ("derive_drive", "1", "1: the start derives the drive's numbers at the clutch shaft (total_inertia, "
                          "drive_torque_max, drive_speed_max) from the motor's and the gear (a co-simulation: "
                          "wet_start); 0: they are as packed, where a batch variant may override total_inertia "
                          "(an int)"),
)
_INT_CONSTANTS = ("derive_drive", "friction_kind", "force_start", "force_n", "speed_start", "speed_n", "friction_start",
                  "map_speed_start", "map_speed_n", "map_temperature_start", "map_temperature_n", "map_force_start",
                  "map_force_n", "map_table_start", "map_table_n")
#: the record type of ``WetParams.constants`` (floats, one bool, ints)
CONSTANTS_DTYPE = np.dtype([(n, np.float64) for n, _, _ in CONSTANTS if n not in _INT_CONSTANTS + ("free_inertia",)]
                           + [("free_inertia", np.bool_)] + [(n, np.int64) for n in _INT_CONSTANTS], align=True)

#: layout of the per-run buffer at the head of ``WetParams.data``: memories, then scratch for outputs,
#: derivative, switching values, and the segments of the force and slip-speed profiles found last
WORK = slots(("peak_temperature", 1),     # peak pack temperature [degC]
             ("first_lockup", 1),         # first lock-up time [s] (NaN: none yet)
             ("outputs", N_OUT), ("derivative", N_STATE), ("switching", N_SWITCH),
             ("force_segment", 1),        # index into data of the force profile's segment last read (0: none yet)
             ("speed_segment", 1))        # the same for the slip-speed profile
W_PEAK, W_LOCKUP, W_OUT, W_DX, W_G, W_FSEG, W_SSEG = WORK.of(
    "peak_temperature", "first_lockup", "outputs", "derivative", "switching", "force_segment", "speed_segment")
N_WORK = WORK.total


class WetParams(NamedTuple):
    """Packed parameters of one wet-clutch engagement (SI, temperatures in degC).

    Built by :func:`pack_parameters` only; its class selects the wet model's
    compiled hooks in the integrator core.  The scalars are the named fields
    of a one-element structured array (``constants``, fields
    :data:`CONSTANTS`); everything else is one float array (``data``): first
    the per-run buffer (memories and scratch, layout ``W_*``), then the
    reference profiles and the friction law (coefficients, or grids and
    values of a map), located by the ``*_start`` / ``*_n`` constants.  Build
    a fresh structure per run and per batch variant (:func:`fresh_buffers`,
    :func:`variant_parameters`).  The Greenwood-Williamson table is a
    constant of the compiled code (:func:`clutchlab.wet.film.asperity_force_scalar`).

    Two arrays on purpose (measured): numba passes the structure by value,
    field by field, to every hook call (six per step), and keeps an atomic
    reference count for every array read from it; with the thirteen arrays
    of a first layout that cost as much as the physics, and in a parallel
    batch arrays shared between variants make those counters contended.
    Each variant gets its own (small) arrays.
    """

    constants: np.ndarray               # one record, fields CONSTANTS [SI]
    data: np.ndarray                    # per-run buffer (N_WORK) | force profile | speed profile | friction law


#: how the hooks and the functions they call are compiled: without numba's reference counting (``_nrt=False``).
#: They allocate no array and keep none (the core lends them its arrays, the parameter record and tables are
#: the caller's); with it every evaluation made about a dozen reference-count calls -- each a real call,
#: numba keeps them out of line -- a quarter of the right-hand side's time (compiled loop over the states of
#: a run: 81 -> 62 ns per evaluation).  Nothing in them may allocate an array (numba refuses to compile it).
_HOOK = dict(cache=True, nogil=True, error_model="numpy", _nrt=False)


# ----------------------------------------------------------------- model pieces (compiled, scalar)
#: tanh(x) = x + x^3 P(x^2) / Q(x^2) for |x| < 0.625 (Cephes ``tanh.c``, S. L. Moshier; Q's leading 1 implied)
_TANH_P = (-9.64399179425052238628e-1, -9.92877231001918586564e1, -1.61468768441708447952e3)
_TANH_Q = (1.12811678491632931402e2, 2.23548839060100448583e3, 4.84406305325125486048e3)


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def tanh(x):
    """Hyperbolic tangent, as accurate as ``math.tanh`` (at most 2 ulp from the exact value) and about half
    its cost where the wet piston needs it.

    glibc evaluates ``tanh`` through ``expm1`` (about 25 ns); the piston speed of every right-hand side and
    output row needs one, a tenth of a 1 s engagement's time.  Here: for ``|x| < 0.625`` the rational
    approximation of Cephes (``x + x^3 P(x^2)/Q(x^2)``, relative error 2.5e-16), else
    ``1 - 2 / (exp(2|x|) + 1)`` (no cancellation: the result is above 0.55), and +-1 beyond 22 (where
    ``1 - tanh`` is below half an ulp).  Tested against a 40-digit evaluation (``tests/wet/test_speed.py``).

    Parameters
    ----------
    x : float

    Returns
    -------
    float
    """
    z = abs(x)
    if z < 0.625:
        s = x * x
        num = (_TANH_P[0] * s + _TANH_P[1]) * s + _TANH_P[2]
        den = ((s + _TANH_Q[0]) * s + _TANH_Q[1]) * s + _TANH_Q[2]
        return x + x * s * (num / den)
    if z > 22.0:
        return 1.0 if x > 0.0 else -1.0
    r = 1.0 - 2.0 / (math.exp(2.0 * z) + 1.0)
    return r if x > 0.0 else -r


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def piston_speed(net_force, film_resistance, speed_max):
    """Piston speed from the quasi-static force balance with the actuator's speed limit [m/s].

    The massless piston moves at the speed at which the squeeze film carries
    the net force, ``F_net = c x_p'`` (Deur et al. [4]), saturated smoothly
    at the actuator's no-load speed: ``x_p' = v_max tanh(F_net / (c v_max))``.

    Parameters
    ----------
    net_force : float
        Actuator force minus return spring and asperity force [N].
    film_resistance : float
        Squeeze-film force per unit piston speed c [N*s/m].
    speed_max : float
        Actuator no-load speed v_max [m/s].
    """
    return speed_max * tanh(net_force / (film_resistance * speed_max))


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def drive_torque(slip_speed, reference, integral, torque_max, power_max, kp, ki):
    """Speed-controlled bench motor: PI with back-calculation anti-windup, torque and power limits.

    Parameters
    ----------
    slip_speed, reference : float
        Clutch shaft speed and its reference [rad/s].
    integral : float
        Controller integral state [N*m].
    torque_max, power_max : float
        Torque limit at the clutch shaft [N*m] and power limit [W].
    kp, ki : float
        Gains [N*m*s/rad], [N*m/rad].

    Returns
    -------
    (float, float)
        Drive torque at the clutch shaft [N*m] and the rate of the integral [N*m/s].
    """
    e = reference - slip_speed
    command = kp * e + integral
    limit = torque_max
    aw = abs(slip_speed)
    if aw * limit > power_max:
        limit = power_max / aw
    td = min(max(command, -limit), limit)
    kaw = ki / kp if kp > 0.0 else 0.0
    return td, ki * e + kaw * (td - command)


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _pwl(t, tables, start, n, memo):
    """Piecewise-linear reference profile at ``t`` (times ``tables[start:start+n]``, values after them),
    constant beyond the ends.

    ``tables[memo]`` holds the segment found last (the index of its first time): it is tried first, and
    bisection runs only if ``t`` is not in it.  The core's steps end on the profiles' corners
    (:func:`wet_next_break`), so every stage and sample of a step reads the segment of the step before
    (the bisection over a 42-corner profile was about 5 % of the right-hand side's own time).  The
    segment ``lo`` with ``tables[lo] <= t < tables[lo + 1]`` is unique, so the value is the bisection's.
    """
    v0 = start + n
    if t <= tables[start]:
        return tables[v0]
    if t >= tables[start + n - 1]:
        return tables[v0 + n - 1]
    lo = int(tables[memo])
    if not (start <= lo < start + n - 1 and tables[lo] <= t < tables[lo + 1]):
        lo = start
        hi = start + n - 1
        while hi - lo > 1:  # bisection: tables[lo] <= t < tables[hi]
            mid = (lo + hi) // 2
            if tables[mid] <= t:
                lo = mid
            else:
                hi = mid
        tables[memo] = lo
    w = (t - tables[lo]) / (tables[lo + 1] - tables[lo])
    return tables[lo + n] + w * (tables[lo + n + 1] - tables[lo + n])


# ----------------------------------------------------------------- hooks
@numba.njit(**_HOOK)
def wet_rhs(t, x, u, m, p, dx, g):
    """Right-hand side, switching functions and (into the scratch of ``p.data``) the outputs of the model."""
    wk = p.data
    _model(t, x, u, m, p, dx, g, wk[W_OUT:W_OUT + N_OUT])


@numba.njit(**_HOOK)
def _model(t, x, u, m, p, dx, g, y):
    """The model at one point: derivative ``dx``, switching values ``g``, outputs ``y`` (:data:`OUTPUTS`).

    One body for :func:`wet_rhs` (outputs into the scratch of ``p.data``, which the driveline's wet clutch
    and :func:`_evaluate` read) and :func:`wet_outputs` (outputs straight into the record's row; going
    through the scratch and a copy made an output row cost 15 ns more than a right-hand side).  Both pass
    arrays only, so that numba compiles it once (an integer offset passed as a module constant is a
    literal, and each literal a compilation of the whole body: 2.4 s more for the first run).
    """
    c = p.constants[0]
    tb = p.data
    nc = c.n_c
    xp = x[S_X]
    fa = x[S_FA]
    w = x[S_W]
    temp = x[S_T]
    tf = x[S_TF]
    th = x[S_TH]
    fmode = m[M_FRICTION]
    at_stop = m[M_PISTON] == AT_STOP
    h = separation_scalar(xp, c.piston_h0, nc)                                     # [1], Eq. 1
    hbar = film_scalar(h, c.sigma)                                                  # [1], Eq. 2
    muv = viscosity_scalar(temp, c.mu_v1, c.mu_v2, c.mu_v3, c.mu_v4)                # [1], Eq. 7
    fc = asperity_force_scalar(h, c.sigma, c.friction_area, c.gw_scale)              # [3], Eq. 11
    v = slip_velocity_scalar(w, c.r_eff)                                            # [1], Eq. (2')
    # |v| as the sliding direction of the mode gives it (v itself in slip_positive, -v in slip_negative, and
    # v = 0 while stuck): equal to |v| wherever the mode is the physical one, and smooth through v = 0, so
    # that the stages of a step that ends past a lock-up (located on the dense output) see no kink
    v_abs = -v if fmode == SLIP_NEG else (v if fmode == SLIP else abs(v))
    k = c.friction_start
    if c.friction_kind == KIND_PARAMETRIC:
        muf = c.mu_scale * parametric_mu_scalar(v_abs, temp, tb[k], tb[k + 1], tb[k + 2], tb[k + 3], tb[k + 4])
    else:  # a friction map: its grids and values are sliced out of the tables only here
        muf = c.mu_scale * mu_kernel(
            v_abs, temp, fc, c.friction_kind, tb[k:k + 5],
            tb[c.map_speed_start:c.map_speed_start + c.map_speed_n],
            tb[c.map_temperature_start:c.map_temperature_start + c.map_temperature_n],
            tb[c.map_force_start:c.map_force_start + c.map_force_n],
            tb[c.map_table_start:c.map_table_start + c.map_table_n])
    cap = asperity_torque_scalar(c.r_eff, nc, muf, fc)                              # [1], Eq. 4 (static)
    # references: scenario profiles plus the held inputs
    wref = c.speed_scale * _pwl(t, tb, c.speed_start, c.speed_n, W_SSEG) + u[U_SPEED]
    fref = min(c.force_scale * _pwl(t, tb, c.force_start, c.force_n, W_FSEG) + u[U_FORCE], c.actuator_force_max)
    # drive: speed-controlled motor or free inertia
    if c.free_inertia:
        td = 0.0
        dx[S_I] = 0.0
    else:
        td, dx[S_I] = drive_torque(w, wref, x[S_I], c.drive_torque_max, c.motor_power_max, c.speed_kp,
                                   c.speed_ki)
    # clutch torque, [1] Eqs. 3-6; the sliding direction is the mode's (smooth within a step)
    if fmode == STICK:
        tc = td
        tv = 0.0
        tau = td
        wdot = 0.0
        pf = 0.0
        g[G_LOCKUP] = 1.0
        g[G_BREAKAWAY] = abs(td) - cap
    else:
        sgn = 1.0 if fmode == SLIP else -1.0
        tau = clutch_torque_scalar(c.r_eff, nc, muf, fc, muv, c.friction_area, v, hbar, sgn)  # [1], Eqs. 3, 6
        tc = sgn * cap                                                                       # [1], Eq. 4
        tv = viscous_torque_scalar(c.r_eff, nc, muv, c.friction_area, v, hbar)               # [1], Eq. 5
        wdot = (td - tau) / c.total_inertia
        pf = tau * w
        g[G_LOCKUP] = sgn * w
        g[G_BREAKAWAY] = -1.0
    dx[S_W] = wdot
    # piston: quasi-static balance of actuator, spring, squeeze film and asperities
    fsp = c.spring_preload + c.spring_stiffness * xp
    # squeeze-film force per unit piston speed (dh/dt = -x_p'/N_c), the N_c films in series
    csq = squeeze_film_force_scalar(c.squeeze_coefficient, muv, -1.0 / nc, hbar)
    fnet = fa - fsp - fc
    vfree = piston_speed(fnet, csq, c.actuator_speed_max)
    run = m[M_RUN]
    if at_stop:
        xdot = 0.0
        g[G_LEAVES] = vfree
        g[G_REACHES] = 1.0
        g[G_RUNS] = 1.0
        g[G_TURNS] = 1.0
    else:
        xdot = vfree
        g[G_LEAVES] = -1.0
        g[G_REACHES] = xp
        # the turn of a running piston (its net force through zero) ends a step: the tanh of its speed law
        # turns from one speed limit to the other within microseconds there, faster than an error estimate
        # over a step sees; armed only once the piston runs (|F_net| >= PISTON_RUNNING c v_max), so that a
        # piston settling on an equilibrium, its net force hovering at zero, never triggers it
        if run == SETTLING:
            g[G_RUNS] = PISTON_RUNNING * csq * c.actuator_speed_max - abs(fnet)
            g[G_TURNS] = 1.0
        else:
            g[G_RUNS] = 1.0
            g[G_TURNS] = fnet if run == ENGAGING else -fnet
    g[G_CONTACT] = h
    # sliding on a friction map, the nodes of its grids (slip velocity, temperature, force; bilinear or trilinear,
    # held beyond): a waypoint, so that a step ends just past each node, where mu_f's slope jumps and the error
    # estimate does not bound the error (a coarse map's engagement was 1.2e-5 of the slip's range off at rtol 1e-7,
    # against 7e-8 with the parametric law, sixty-second session)
    if c.friction_kind == KIND_PARAMETRIC or fmode == STICK:
        g[G_ROW] = 1.0
    else:
        g[G_ROW] = (grid_waypoint(tb, c.map_speed_start, c.map_speed_n, v_abs)
                    * grid_waypoint(tb, c.map_temperature_start, c.map_temperature_n, temp)
                    * grid_waypoint(tb, c.map_force_start, c.map_force_n, fc))
    dx[S_X] = xdot
    dx[S_FA] = (fref - fa) / c.actuator_time_constant
    # thermal network
    qk1 = c.k1 * (temp - tf)
    qk2 = c.k2 * (temp - th)
    dx[S_T] = heat_balance_scalar(temp, pf, tf, th, c.heat_capacity, c.k1, c.k2)    # [1], Eq. 8
    qh = min(max(c.heater_gain * (c.heater_setpoint - tf), 0.0), c.heater_power_max)
    qfh = c.fluid_housing_conductance * (tf - th)
    dx[S_TF] = (qk1 + qh - c.reservoir_cooling * (tf - c.ambient_temperature) - qfh) / c.reservoir_heat_capacity
    dx[S_TH] = (qk2 + qfh - c.housing_cooling * (th - c.ambient_temperature)) / c.housing_heat_capacity
    dx[S_TM] = (temp - x[S_TM]) / c.thermistor_time_constant
    dx[S_EF] = pf
    dx[S_EK1] = qk1
    dx[S_EK2] = qk2
    dx[S_ED] = td * w
    # outputs
    fh = csq * xdot
    y[O_TAU] = tau
    y[O_TC] = tc
    y[O_TV] = tv
    y[O_FC] = fc
    y[O_FH] = fh
    y[O_FLC] = fa if at_stop else fsp + fc + fh
    y[O_H] = h
    y[O_HBAR] = hbar
    y[O_MUF] = muf
    y[O_MUV] = muv
    y[O_TD] = td
    y[O_WREF] = wref
    y[O_FREF] = fref
    y[O_WDOT] = wdot
    y[O_TS] = tau + c.shaft_inertia * wdot
    y[O_PF] = pf
    y[O_QH] = qh
    y[O_CAP] = cap


@numba.njit(**_HOOK)
def _evaluate(t, x, u, m, p):
    """The model at one point into the scratch space of ``p.data`` (hooks other than ``rhs``)."""
    wk = p.data
    wet_rhs(t, x, u, m, p, wk[W_DX:W_DX + N_STATE], wk[W_G:W_G + N_SWITCH])


@numba.njit(**_HOOK)
def wet_outputs(t, x, u, m, p, y):
    """Outputs at one point (:data:`OUTPUTS` order); the derivative and switching values into the scratch."""
    wk = p.data
    _model(t, x, u, m, p, wk[W_DX:W_DX + N_STATE], wk[W_G:W_G + N_SWITCH], y)


@numba.njit(**_HOOK)
def wet_update(t, x, u, m, p, k, log):
    """Mode change when switching function ``k`` crossed zero at ``t`` (events recorded by name).

    Returns :data:`~clutchlab.numerics.core.RESTART` when the piston leaves its stop (the core starts the
    step size afresh there), else 0.
    """
    wk = p.data
    code = -1  # the event to record (one call site: numba compiles ``record`` once, not per literal code)
    if k == G_LOCKUP:
        old = m[M_FRICTION]
        x[S_W] = 0.0
        m[M_FRICTION] = STICK
        _evaluate(t, x, u, m, p)
        if abs(wk[W_OUT + O_TD]) <= wk[W_OUT + O_CAP]:
            code = EV_LOCKUP
            if wk[W_LOCKUP] != wk[W_LOCKUP]:
                wk[W_LOCKUP] = t
        else:
            # the static capacity cannot hold the drive torque: the slip changes direction
            m[M_FRICTION] = SLIP_NEG if old == SLIP else SLIP
            code = EV_REVERSAL
    elif k == G_BREAKAWAY:
        _evaluate(t, x, u, m, p)
        m[M_FRICTION] = SLIP if wk[W_OUT + O_TD] > 0.0 else SLIP_NEG
        code = EV_BREAKAWAY
    elif k == G_CONTACT:
        if m[M_FILM] == OPEN:
            m[M_FILM] = CONTACT
            code = EV_CONTACT
        else:
            m[M_FILM] = OPEN
            code = EV_SEPARATION
    elif k == G_LEAVES:
        # off its stop the piston runs out towards the pack (its net force rose through zero): armed at once,
        # so that an engagement pays no located ``piston_runs``
        m[M_PISTON] = FREE
        m[M_RUN] = ENGAGING
        code = EV_LEAVES
    elif k == G_RUNS:
        # the piston reaches a speed near its limit: watch for its turn (no event recorded)
        _evaluate(t, x, u, m, p)
        m[M_RUN] = ENGAGING if wk[W_DX + S_X] > 0.0 else RELEASING
    elif k == G_TURNS:
        # the running piston turns: the step size starts afresh (no event recorded)
        m[M_RUN] = SETTLING
        return RESTART
    elif k == G_REACHES:
        x[S_X] = 0.0
        m[M_PISTON] = AT_STOP
        m[M_RUN] = SETTLING
        _evaluate(t, x, u, m, p)
        if wk[W_G + G_LEAVES] > 0.0:
            # the force balance pushes it off the stop again at once (a touch): stays free
            m[M_PISTON] = FREE
        else:
            code = EV_REACHES
    if code >= 0:
        record(log, t, code, EVENT_ELEMENT[code])
    # off its stop the piston reaches the actuator's speed limit within about a microsecond (the squeeze film
    # of the open pack resists little): the core restarts the step size there (RESTART)
    return RESTART if code == EV_LEAVES else 0


@numba.njit(**_HOOK)
def wet_restart(t, x, u, m, p, log):
    """Modes consistent with the forces at a (re)start: break-away, piston on or off its stop, film contact.

    Called at t0, on every resumed ``advance`` (inputs may have jumped) and
    at every corner of the reference profiles; only the checks that can
    change a mode evaluate the model.
    """
    c = p.constants[0]
    wk = p.data
    changed = False
    film = CONTACT if separation_scalar(x[S_X], c.piston_h0, c.n_c) <= 0.0 else OPEN
    if m[M_FILM] != film:
        m[M_FILM] = film
        changed = True
    _evaluate(t, x, u, m, p)
    code = -1
    for check in range(2):  # the friction, then the piston; one call site of ``record``
        code = -1
        if check == 0 and m[M_FRICTION] == STICK and abs(wk[W_OUT + O_TD]) > wk[W_OUT + O_CAP]:
            # stuck with the drive torque above the capacity (a jump of an input at a resume)
            m[M_FRICTION] = SLIP if wk[W_OUT + O_TD] > 0.0 else SLIP_NEG
            code = EV_BREAKAWAY
        elif check == 1 and m[M_PISTON] == AT_STOP and wk[W_G + G_LEAVES] > 0.0:
            m[M_PISTON] = FREE
            m[M_RUN] = ENGAGING  # (as in ``wet_update``)
            code = EV_LEAVES
        elif check == 1 and m[M_PISTON] == FREE and x[S_X] <= 0.0 and wk[W_DX + S_X] <= 0.0:
            x[S_X] = 0.0
            m[M_PISTON] = AT_STOP
            code = EV_REACHES
        if code >= 0:
            record(log, t, code, EVENT_ELEMENT[code])
            changed = True
    # whether the piston runs (its net force, continuous across a restart, decides; at t0 or a set state
    # it may start running): settling on its stop, running one way at its speed limit, or armed no more
    run = m[M_RUN]
    if m[M_PISTON] == AT_STOP:
        run = SETTLING
    else:
        if code >= 0:
            _evaluate(t, x, u, m, p)
        if run != SETTLING and wk[W_G + G_TURNS] < 0.0:
            run = SETTLING
            m[M_RUN] = run
            _evaluate(t, x, u, m, p)
        if run == SETTLING and wk[W_G + G_RUNS] < 0.0:
            run = ENGAGING if wk[W_DX + S_X] > 0.0 else RELEASING
    if m[M_RUN] != run:
        m[M_RUN] = run
        changed = True
    return changed


@numba.njit(**_HOOK)
def wet_accept(t, x, u, m, p):
    """After each accepted step: track the peak pack temperature."""
    wk = p.data
    if x[S_T] > wk[W_PEAK]:
        wk[W_PEAK] = x[S_T]
    return 0


@numba.njit(**_HOOK)
def _next_corner(tables, start, n, t, i0):
    """First time of a profile after ``t``; the search starts at ``i0``, the segment read last (see
    :func:`_pwl`), when that segment does not begin after ``t`` (no earlier time can then be after it).
    (``i0`` is read by the caller: an index of the buffer passed here would be a literal, and numba would
    compile this once per literal.)"""
    if not (start <= i0 < start + n and tables[i0] <= t):
        i0 = start
    for i in range(i0, start + n):
        if tables[i] > t:
            return tables[i]
    return np.inf


@numba.njit(**_HOOK)
def wet_next_break(t, m, p):
    """Next corner of the force (and, with the motor, the slip-speed) reference profile after ``t``."""
    c = p.constants[0]
    tb = _next_corner(p.data, c.force_start, c.force_n, t, int(p.data[W_FSEG]))
    if not c.free_inertia:
        ts = _next_corner(p.data, c.speed_start, c.speed_n, t, int(p.data[W_SSEG]))
        if ts < tb:
            tb = ts
    return tb


@numba.njit(**_HOOK)
def wet_jacobian(t, x, u, m, p, J):
    """No analytic Jacobian (Dormand-Prince does not need one)."""
    return False


@numba.njit(**_HOOK)
def wet_start(t, x, u, m, p):
    """What a run derives from its parameters alone, once before its first restart (the core's ``start`` hook): the
    pack's heat capacity ([1], Eq. 8: :func:`~clutchlab.wet.thermal.pack_heat_capacity_scalar`), the
    Greenwood-Williamson pressure scale ([3], Eq. 11: :func:`~clutchlab.wet.film.gw_pressure_scale_scalar`), the
    effective radius ([1], Eq. (1'): :func:`~clutchlab.wet.film.effective_radius_scalar`) and the squeeze-film
    coefficient ([4]: :func:`~clutchlab.wet.film.squeeze_film_coefficient_scalar`) from the masses, heat
    capacities, roughness parameters and radii packed beside them, with the functions the Python side
    computes them with (the same numbers).  So a native FMU, which runs it again after a host set those
    parameters, writes them as plain copies (:attr:`clutchlab.system.System.decided_at_start`).  Where
    ``derive_drive`` is 1 (a co-simulation's run: :class:`~clutchlab.fmu.wet.WetCoSimulation`), also the bench's
    drive at the clutch shaft from the motor's numbers and the gear (:class:`~clutchlab.wet.params.Bench`'s
    ``total_inertia = shaft_inertia + motor_inertia gear_ratio^2``, ``drive_torque_max = motor_torque_max
    gear_ratio``, ``drive_speed_max = motor_speed_max / gear_ratio``; [1] Sec. 3.1: a 1:2 gear from the motor);
    elsewhere a batch variant may override ``total_inertia`` as packed.  Returns 0."""
    c = p.constants[0]
    c.heat_capacity = pack_heat_capacity_scalar(c.n_c, c.m_lining, c.cp_lining, c.m_core, c.cp_core)
    c.gw_scale = gw_pressure_scale_scalar(c.sigma, c.asperity_radius, c.asperity_density, c.contact_modulus)
    c.r_eff = effective_radius_scalar(c.r_outer, c.r_inner)
    c.squeeze_coefficient = c.squeeze_flow_factor * squeeze_film_coefficient_scalar(c.r_outer, c.r_inner)
    if c.derive_drive == 1:   # (the bench's drive referred to the clutch shaft: Bench's properties, Sec. 3.1)
        c.total_inertia = c.shaft_inertia + c.motor_inertia * c.gear_ratio ** 2
        c.drive_torque_max = c.motor_torque_max * c.gear_ratio
        c.drive_speed_max = c.motor_speed_max / c.gear_ratio
    return 0


#: the constants :func:`wet_start` derives
DERIVED_CONSTANTS = ("heat_capacity", "gw_scale", "r_eff", "squeeze_coefficient")
#: ... as words of a run's parameters (:attr:`clutchlab.system.System.decided_at_start`)
DERIVED_AT_START = tuple((f"params.constants.{name}", 0, None) for name in DERIVED_CONSTANTS)
#: the constants :func:`wet_start` derives where ``derive_drive`` is 1, as words of a run's parameters
DERIVED_DRIVE_AT_START = tuple((f"params.constants.{name}", 0, None)
                               for name in ("total_inertia", "drive_torque_max", "drive_speed_max"))
#: ... and what each is derived from (an override of one would be replaced at the start: refused)
_DERIVED_FROM = {"heat_capacity": "n_c, m_lining, cp_lining, m_core, cp_core",
                 "gw_scale": "sigma, asperity_radius, asperity_density, contact_modulus",
                 "r_eff": "r_outer, r_inner", "squeeze_coefficient": "squeeze_flow_factor, r_outer, r_inner"}


def _refuse_derived(overrides, where):
    for name in overrides:
        if name in _DERIVED_FROM:
            raise ParameterError(f"{where}: {name} is derived at the start of a run from {_DERIVED_FROM[name]} "
                                 "(wet_start): override those")

dispatch.register(WetParams, rhs=wet_rhs, outputs=wet_outputs, update=wet_update, restart=wet_restart,
                  accept=wet_accept, next_break=wet_next_break, jacobian=wet_jacobian, start=wet_start)


# ----------------------------------------------------------------- packing
def _array(values) -> np.ndarray:
    return np.array(values, dtype=np.float64, order="C").ravel()


def pack_parameters(clutch, bench, scenario, friction=None, **overrides) -> WetParams:
    """Pack clutch, bench, scenario and friction law into a :class:`WetParams` (the one packing function).

    Parameters
    ----------
    clutch : WetClutch
        Clutch parameters.
    bench : Bench
        Drive, actuator and oil loop.
    scenario : Scenario
        Reference profiles, drive mode, heater set point.
    friction : ParametricFriction or FrictionMap, optional
        Asperity friction law (default: :meth:`ParametricFriction.bench_truth`).
    **overrides
        Values of fields of :data:`CONSTANTS` that replace the packed ones
        (batch variants: ``force_scale``, ``mu_scale``, ``speed_scale``,
        ``total_inertia``, ``k1``, ``k2``, ``heater_setpoint``; a co-simulation:
        ``derive_drive=1``, :func:`wet_start`).

    Returns
    -------
    WetParams
        With a fresh per-run ``work`` buffer (peak temperature from the
        scenario's initial pack temperature, no lock-up yet).
    """
    law = ParametricFriction.bench_truth() if friction is None else friction
    kind, coef, gv, gt, gf, table = law.kernel_data()
    parts = [_array(scenario.force_time), _array(scenario.force_value), _array(scenario.speed_time),
             _array(scenario.speed_value), _array(coef), _array(gv), _array(gt), _array(gf), _array(table)]
    starts = N_WORK + np.concatenate([[0], np.cumsum([a.size for a in parts])])  # after the per-run buffer
    values = dict(
        n_c=clutch.n_c, r_eff=clutch.r_eff, sigma=clutch.sigma, friction_area=clutch.friction_area,
        piston_h0=clutch.piston_h0, mu_v1=clutch.mu_v1, mu_v2=clutch.mu_v2, mu_v3=clutch.mu_v3, mu_v4=clutch.mu_v4,
        heat_capacity=clutch.heat_capacity, k1=clutch.k1, k2=clutch.k2, gw_scale=clutch.gw_scale,
        squeeze_coefficient=clutch.squeeze_coefficient, spring_stiffness=clutch.spring_stiffness,
        spring_preload=clutch.spring_preload, total_inertia=bench.total_inertia, shaft_inertia=bench.shaft_inertia,
        drive_torque_max=bench.drive_torque_max, drive_speed_max=bench.drive_speed_max,
        motor_inertia=bench.motor_inertia, motor_torque_max=bench.motor_torque_max,
        motor_speed_max=bench.motor_speed_max, gear_ratio=bench.gear_ratio, derive_drive=0,
        motor_power_max=bench.motor_power_max, speed_kp=bench.speed_kp,
        speed_ki=bench.speed_ki, actuator_time_constant=bench.actuator_time_constant,
        actuator_force_max=bench.actuator_force_max, actuator_speed_max=bench.actuator_speed_max,
        thermistor_time_constant=bench.thermistor_time_constant,
        reservoir_heat_capacity=bench.reservoir_heat_capacity, heater_power_max=bench.heater_power_max,
        heater_gain=bench.heater_gain, heater_setpoint=scenario.setpoint_c, reservoir_cooling=bench.reservoir_cooling,
        housing_heat_capacity=bench.housing_heat_capacity, housing_cooling=bench.housing_cooling,
        fluid_housing_conductance=bench.fluid_housing_conductance, ambient_temperature=bench.ambient_temperature,
        r_outer=clutch.r_outer, r_inner=clutch.r_inner, squeeze_flow_factor=clutch.squeeze_flow_factor,
        m_lining=clutch.m_lining, cp_lining=clutch.cp_lining, m_core=clutch.m_core, cp_core=clutch.cp_core,
        asperity_radius=clutch.asperity_radius, asperity_density=clutch.asperity_density,
        contact_modulus=clutch.contact_modulus,
        force_scale=1.0, mu_scale=1.0, speed_scale=1.0,
        free_inertia=scenario.motor == "free", friction_kind=int(kind),
        force_start=int(starts[0]), force_n=parts[0].size, speed_start=int(starts[2]), speed_n=parts[2].size,
        friction_start=int(starts[4]), map_speed_start=int(starts[5]), map_speed_n=parts[5].size,
        map_temperature_start=int(starts[6]), map_temperature_n=parts[6].size, map_force_start=int(starts[7]),
        map_force_n=parts[7].size, map_table_start=int(starts[8]), map_table_n=parts[8].size,
    )
    unknown = [k for k in overrides if k not in values]
    if unknown:
        raise TypeError(f"pack_parameters: unknown field {unknown[0]!r} (known: {', '.join(values)})")
    _refuse_derived(overrides, "pack_parameters")
    if overrides.get("derive_drive"):
        for name in ("total_inertia", "drive_torque_max", "drive_speed_max"):
            if name in overrides:
                raise ParameterError(f"pack_parameters: {name} is derived at the start of a run with derive_drive "
                                     "from the motor's numbers and the gear: override those")
    values.update(overrides)
    constants = np.array([tuple(values[n] for n in CONSTANTS_DTYPE.names)], dtype=CONSTANTS_DTYPE)
    return WetParams(constants, np.concatenate([new_work(scenario.initial_temperature_c)] + parts))


#: constants that locate the friction law in ``WetParams.data`` (they move with the profiles' lengths)
_LAW_STARTS = ("friction_start", "map_speed_start", "map_temperature_start", "map_force_start", "map_table_start")
#: (byte offset, packer) of each field of a constants record: a new scenario's fields are written into a copy
#: of the record's bytes (a structured-array copy takes 15 us and each field assignment 0.5 us, measured)
_FIELD = {name: (offset, struct.Struct("=" + np.dtype(dtype).char))
          for name, (dtype, offset) in CONSTANTS_DTYPE.fields.items()}
_FRESH_WORK = np.zeros(N_WORK)
_FRESH_WORK[W_LOCKUP] = math.nan


def _set(raw: bytearray, name: str, value) -> None:
    offset, packer = _FIELD[name]
    packer.pack_into(raw, offset, value)


def _get(raw, name: str):
    offset, packer = _FIELD[name]
    return packer.unpack_from(raw, offset)[0]


def with_scenario(params: WetParams, scenario) -> WetParams:
    """Parameters packed for another scenario of the same clutch, bench and friction law.

    Equal to ``pack_parameters(clutch, bench, scenario, friction)`` when ``params``
    came from ``pack_parameters(clutch, bench, other_scenario, friction)`` without
    overrides: the scenario's fields (profiles, heater set point, drive mode) are
    replaced, the clutch, bench and law are copied, and the per-run buffer is
    fresh.  Measured: a fifth of :func:`pack_parameters`' time, which is most of
    a short run's set-up (benchmarks/README.md, "fresh scenario").

    Parameters
    ----------
    params : WetParams
        Packed by :func:`pack_parameters` (any constants overridden there stay).
    scenario : Scenario
        The new run's references, drive mode, heater set point and initial pack temperature.

    Returns
    -------
    WetParams
        New arrays; ``params`` is not changed.
    """
    raw = bytearray(params.constants.tobytes())
    old_start = _get(raw, "friction_start")
    nf, ns = scenario.force_time.size, scenario.speed_time.size
    shift = N_WORK + 2 * (nf + ns) - old_start  # the law follows the new profiles
    if shift:
        for name in _LAW_STARTS:
            _set(raw, name, _get(raw, name) + shift)
    _set(raw, "force_start", N_WORK)
    _set(raw, "force_n", nf)
    _set(raw, "speed_start", N_WORK + 2 * nf)
    _set(raw, "speed_n", ns)
    _set(raw, "heater_setpoint", scenario.setpoint_c)
    _set(raw, "free_inertia", scenario.motor == "free")
    constants = np.frombuffer(raw, dtype=CONSTANTS_DTYPE).reshape(params.constants.shape)
    if not constants.flags.aligned:  # the compiled hooks are typed for aligned records
        constants = constants.copy()
    data = np.concatenate((_FRESH_WORK, scenario.force_time, scenario.force_value, scenario.speed_time,
                           scenario.speed_value, params.data[old_start:]))
    data[W_PEAK] = scenario.initial_temperature_c
    return WetParams(constants, data)


def new_work(initial_temperature_c):
    """Fresh per-run buffer(s): the peak memory starts at the initial pack temperature, no lock-up yet.

    Parameters
    ----------
    initial_temperature_c : float or array_like
        Pack temperature at the start [degC]; an array gives one buffer (row) per value.
    """
    temp = np.asarray(initial_temperature_c, dtype=float)
    work = np.zeros(temp.shape + (N_WORK,))
    work[..., W_PEAK] = temp
    work[..., W_LOCKUP] = math.nan
    return work


def fresh_buffers(params: WetParams, initial_temperature_c: float, **overrides) -> WetParams:
    """A copy of packed parameters with a new per-run buffer and some constants replaced.

    Parameters
    ----------
    params : WetParams
        Packed by :func:`pack_parameters`.
    initial_temperature_c : float
        Pack temperature at the start [degC] (starts the peak memory).
    **overrides
        Values of fields of :data:`CONSTANTS` to replace.
    """
    constants = params.constants
    if overrides:
        _refuse_derived(overrides, "fresh_buffers")
        constants = constants.copy()
        for name, value in overrides.items():
            constants[name] = value
    data = params.data.copy()
    data[:N_WORK] = _FRESH_WORK                   # (what new_work gives, without building it: every run does this)
    data[W_PEAK] = initial_temperature_c
    return WetParams(constants, data)


def stacked_parameters(params: WetParams, constants: np.ndarray, work: np.ndarray) -> WetParams:
    """Parameters of the variants of a batch, stacked (:class:`clutchlab.system.Variants`).

    Parameters
    ----------
    params : WetParams
        The base case.
    constants : ndarray
        The variants' constants, an array of ``m`` records of :data:`CONSTANTS`.
    work : ndarray
        Their per-run buffers, ``(m, N_WORK)`` (:func:`new_work`).

    Returns
    -------
    WetParams
        ``constants`` of shape ``(m, 1)``, ``data`` ``(m, n)``: row ``v`` is variant ``v``'s, its
        per-run buffer (lock-up time, peak temperature) written by the run.
    """
    m = len(constants)
    data = np.tile(params.data, (m, 1))
    data[:, :N_WORK] = work
    return WetParams(np.ascontiguousarray(constants, dtype=CONSTANTS_DTYPE).reshape(m, 1), data)


def peak_temperature(params: WetParams) -> float:
    """Highest pack temperature [degC] over the accepted steps of the run that used ``params``.

    Parameters
    ----------
    params : WetParams
        After the run.
    """
    return float(params.data[W_PEAK])


def lockup_time(params: WetParams) -> float:
    """First lock-up time [s] of the run that used ``params`` (NaN if the clutch did not lock).

    Parameters
    ----------
    params : WetParams
        After the run.
    """
    return float(params.data[W_LOCKUP])


def initial_state(scenario) -> np.ndarray:
    """State at t = 0: piston on its stop, actuator force at the reference, no energy yet.

    Parameters
    ----------
    scenario : Scenario
        Initial slip speed and temperatures, force profile.
    """
    x = np.zeros(N_STATE)
    ft, fv = scenario.force_time, scenario.force_value
    x[S_FA] = fv[0] if ft[0] >= 0.0 else np.interp(0.0, ft, fv)  # (the profile is constant before its start)
    x[S_W] = scenario.initial_slip_speed
    x[S_T] = scenario.initial_temperature_c
    x[S_TF] = scenario.fluid_temperature_c
    x[S_TH] = scenario.housing_temperature_c
    x[S_TM] = scenario.initial_temperature_c
    return x


def initial_modes(x0, piston_h0: float) -> np.ndarray:
    """Modes at t = 0 from the initial state: slip direction, piston on its stop, film contact.

    Parameters
    ----------
    x0 : ndarray
        Initial state, or initial states ``(m, n)`` (one row per variant: modes ``(m, 4)``).
    piston_h0 : float
        Piston position at zero separation [m] (Eq. 1).
    """
    x0 = np.asarray(x0, dtype=float)
    if x0.ndim == 1:  # one run (the same rules as below, without the array machinery)
        w, xp = float(x0[S_W]), float(x0[S_X])
        return np.array([SLIP if w > 0.0 else SLIP_NEG if w < 0.0 else STICK, AT_STOP if xp <= 0.0 else FREE,
                         CONTACT if piston_h0 - xp <= 0.0 else OPEN, SETTLING], dtype=np.int64)
    m = np.zeros(x0.shape[:-1] + (len(MODE_NAMES),), dtype=np.int64)
    w = x0[..., S_W]
    m[..., M_FRICTION] = np.where(w > 0.0, SLIP, np.where(w < 0.0, SLIP_NEG, STICK))
    m[..., M_PISTON] = np.where(x0[..., S_X] <= 0.0, AT_STOP, FREE)
    m[..., M_FILM] = np.where(piston_h0 - x0[..., S_X] <= 0.0, CONTACT, OPEN)
    m[..., M_RUN] = SETTLING  # (the restart at t0 arms a piston that starts running)
    return m


#: typical magnitude of each state except the piston position (whose scale is the piston travel to contact)
STATE_SCALES = np.array([np.nan, 1e4, 100.0, 100.0, 10.0, 10.0, 10.0, 10.0, 1e3, 1e3, 1e3, 1e3])


def absolute_tolerance(clutch, rtol: float = 1e-7) -> np.ndarray:
    """Absolute tolerance per state: ``min(rtol, 1e-7)`` times the state's typical magnitude.

    The magnitudes are the piston travel to contact ``x_{p,h0}`` [m], 1e4 N,
    100 rad/s, 100 N*m, 10 K and 1e3 J (:data:`STATE_SCALES`).  For
    ``rtol >= 1e-7`` (the default) these are the former kernel's fixed
    absolute tolerances (1e-3 N, 1e-5 rad/s, 1e-6 K, 1e-4 J), except the
    piston position's (1.2e-9 m instead of 6e-8 m: with the stop located, the
    first step off the stop, where the piston reaches the actuator's speed
    limit within a microsecond, set the error of the whole stroke).  Below
    1e-7 they shrink with ``rtol``, so that the whole error control follows
    the tolerance: with fixed absolute tolerances an ``rtol`` below about
    1e-8 changed nothing.

    Parameters
    ----------
    clutch : WetClutch
        For the piston travel ``piston_h0``.
    rtol : float
        Relative tolerance of the run.
    """
    scale = STATE_SCALES.copy()
    scale[S_X] = clutch.piston_h0
    return min(float(rtol), 1e-7) * scale


_STATE_VARIABLES, _OUTPUT_VARIABLES, _INPUT_VARIABLES = variables(STATES), variables(OUTPUTS), variables(INPUTS)


def _element_name(code: int, element: int) -> str:
    return ELEMENTS[element] if 0 <= element < len(ELEMENTS) else ""


def engagement_system(scenario, *, clutch=None, bench=None, friction=None, params=None, x0=None,
                      rtol: float = 1e-7) -> System:
    """The :class:`~clutchlab.system.System` of one wet-clutch engagement.

    The model ``"wet"`` of :data:`clutchlab.system.MODELS` is this system for a bench protocol
    (:func:`clutchlab.wet.bench.protocol_system`).

    Parameters
    ----------
    scenario : Scenario
        Inputs of the run (:class:`~clutchlab.wet.engagement.Scenario`; a bench protocol's:
        :meth:`clutchlab.wet.bench.EngagementProtocol.scenario`).
    clutch : WetClutch, optional
        Default :meth:`WetClutch.paper`.
    bench : Bench, optional
        Default ``Bench()``.
    friction : ParametricFriction or FrictionMap, optional
        Default :meth:`ParametricFriction.bench_truth`.
    params : WetParams, optional
        Already packed parameters (they must come from the same clutch,
        bench and scenario); default: :func:`pack_parameters`.
    x0 : array_like, optional
        Initial state (default :func:`initial_state`).
    rtol : float
        The system's default relative tolerance; its absolute tolerances are
        :func:`absolute_tolerance` at this ``rtol``.

    Returns
    -------
    System
        Dormand-Prince 5(4), event bracket 1e-12 s.
    """
    from .params import Bench, WetClutch

    clutch = WetClutch.paper() if clutch is None else clutch
    bench = Bench() if bench is None else bench
    if params is None:
        params = pack_parameters(clutch, bench, scenario, friction)
    x0 = initial_state(scenario) if x0 is None else np.asarray(x0, dtype=float)
    return System(
        name="wet", params=params, states=_STATE_VARIABLES, outputs=_OUTPUT_VARIABLES, inputs=_INPUT_VARIABLES, x0=x0,
        m0=initial_modes(x0, clutch.piston_h0), atol=absolute_tolerance(clutch, rtol), switching=SWITCHING,
        events=EVENTS, mode_names=MODE_NAMES, mode_values=MODE_VALUES, method="dopri", rtol=float(rtol), event_tol=1e-12,
        element_name=_element_name,
        decided_at_start=DERIVED_AT_START + (DERIVED_DRIVE_AT_START if params.constants["derive_drive"][0] else ()))
