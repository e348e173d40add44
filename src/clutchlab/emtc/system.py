"""The AWD vehicle with the EMTC on the drum bench as a system of the core contract ([1], Secs. 3-4).

This module is the model, written once: the packed parameters (:class:`EmtcParams`, built only by
:func:`pack_parameters`), the equations as scalar compiled functions, the hooks of
:mod:`clutchlab.numerics.dispatch` and the :class:`~clutchlab.system.System` factory
:func:`bench_system` (registered as ``"emtc_bench"``).  :func:`simulate` is the uniform entry point;
:func:`clutchlab.emtc.simulate_bench` and :class:`clutchlab.fmu.emtc.EmtcCoSimulation` are thin layers
over it and over :class:`clutchlab.system.Simulation`.

States ``x``: ``omega_f``, ``omega_r`` (coupling input and output shaft speeds, Eq. 27), ``theta`` (Torsen
twist since the last lock-up, Eq. 30), ``x_armature``, ``v_armature`` (Eqs. 8-12), ``i1``, ``i2`` (the two
current lags of Fig. 15).  Modes ``m``: armature (``rest``, ``free``, ``contact``), coupling (``open``,
``slipping``, ``locked``), slip direction (``negative``, ``positive``).  Held inputs ``u``:
``torque_request``, ``throttle``, ``drum_speed_front``, ``drum_speed_rear``; each is used where the packed
parameters carry no profile for it (a co-simulation: all four; a scenario run: the drum speeds).

Hybrid structure:

* six switching functions (falling through zero): the armature reaches its rest stop or the primary clutch,
  the magnet overcomes the preload, the clamp force of Eq. 11 vanishes, the slip speed reaches zero
  (lock-up or slip reversal, Fig. 11), ``|T'_lock|`` exceeds ``1.02 T_cap_L`` (unlock);
* the controller samples (``sample_time``) are break times: :func:`_restart` runs the controller there
  (torque reference of Eq. 31 or the table or input, Eqs. 13/15 and 11 for the magnet force, the inverse
  Preisach model of Eqs. 6-7 on the controller's own memory), so a resumed run of any step size samples at
  the same instants;
* the plant magnet's hysteresis memory and the LuGre bristle state are committed once per accepted step
  (:func:`_accept`, or at an event before the mode changes), never inside the stages: stages evaluate the
  magnet with :func:`~clutchlab.hysteresis.kernels.peek_segment` (:func:`~clutchlab.hysteresis.kernels.peek`
  while the armature moves) and advance the bristles from their committed value along the slip's path from
  the step's start (:func:`~clutchlab.emtc.friction.lugre_advance_path`, anchored by :func:`_anchor_bristles`);
* a full hysteresis memory is a model error (codes in :data:`ERROR_MESSAGES`), not a solver status.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import NamedTuple

import numba
import numpy as np
from numba.core import types

from ..errors import ParameterError, SimulationError
from ..hysteresis.kernels import (GAP_TABLES, combine_tables, commit, gap_weights, invert_combined, invert_one,
                                   peek, peek_segment)
from ..numerics import FASTMATH, dispatch
from ..numerics.borrow import ByRef, borrow, byref, shaped
from ..numerics.core import record
from ..numerics.layout import indices, slots
from ..numerics.outline import hook_args, log_type, outlined, prepare
from ..system import System, follow_rtol, register_model, start_checks_deferred
from ._lookup import bilinear, interp1
from .friction import coupling_torque_scalar, drag_torque_scalar, lugre_advance_path, lugre_mu, stribeck_g
from .params import (GEOMETRY_TOLERANCE, ActuatorParameters, BenchScenario, TorqueMap, VehicleParameters, _default,
                     static_axle_load)
from .torque import UNLOCK_MARGIN, CouplingGeometry, _cam_force, _locked, _locked_capacity, _slipping

# EmtcParams, the parameters of the compiled hooks, is the kernel's internal: not API (#33)
__all__ = ["BenchOptions", "pack_parameters", "bench_system", "simulate", "STATES", "OUTPUTS",
           "INPUTS", "SWITCHING", "EVENTS", "EVENT_DESCRIPTIONS", "MODE_NAMES", "MODE_VALUES", "ERROR_MESSAGES",
           "memory_full", "run", "run_controller", "controller_log", "VEHICLE_DTYPE", "CouplingData", "ACTUATOR_DTYPE",
           "armature_acceleration", "primary_clamp_force", "bench_loads", "lock_torque", "commanded_magnet_force",
           "N_SWITCH", "grid_line_function"]

# ------------------------------------------------------------------ the self-description
STATES = (
    ("omega_f", "rad_s", "coupling input (front) shaft speed (Eq. 27)"),
    ("omega_r", "rad_s", "coupling output (rear) shaft speed (Eq. 27)"),
    ("theta", "rad", "Torsen twist angle since the last lock-up (Eq. 30)"),
    ("x_armature", "m", "armature displacement (Eqs. 8-12)"),
    ("v_armature", "m_s", "armature speed"),
    ("i1", "A", "first current lag (Fig. 15)"),
    ("i2", "A", "coil current, second lag (Fig. 15)"),
)
OUTPUTS = (
    ("slip_speed", "rad_s", "omega_f - omega_r"),
    ("airgap", "m", "magnetic airgap d - x (Eq. 12)"),
    ("magnet_force", "N", "plant Preisach magnet force (Eqs. 1-5)"),
    ("fn1", "N", "primary-clutch normal force (Eq. 11)"),
    ("fn2", "N", "ball-cam force on the secondary clutch and third element (Eq. 14)"),
    ("t1", "Nm", "primary-clutch torque"),
    ("t2", "Nm", "secondary-clutch torque"),
    ("t3", "Nm", "third-element torque"),
    ("coupling_torque", "Nm", "torque transferred by the coupling (Eqs. 17, 25-26, 30)"),
    ("lock_torque", "Nm", "torque that keeps the coupling locked, T_lock of Eq. 29"),
    ("transmission_torque", "Nm", "transmission output torque"),
    ("capacity_locked", "Nm", "locked capacity T_cap_L (Eq. 21)"),
    ("engine_torque", "Nm", "engine torque"),
    ("locked_case", "1", "distribution case of Fig. 12 while locked (code of torque.LOCKED_CASE_NAMES, -1 else)"),
    ("current_command", "A", "coil current command held since the last controller sample (Eqs. 6-7)"),
    ("torque_reference", "Nm", "torque reference T_cal sampled at the last controller sample (Eq. 31)"),
    ("throttle", "1", "throttle"),
    ("command_feasible", "1", "1 if the inverse magnet model reached the commanded force at the last sample"),
)
INPUTS = (
    ("torque_request", "Nm", "torque request T_cal (co-simulation: replaces the map of Eq. 31)"),
    ("throttle", "1", "throttle (co-simulation; a scenario gives its ramp)"),
    ("drum_speed_front", "m_s", "front drum surface speed"),
    ("drum_speed_rear", "m_s", "rear drum surface speed"),
    ("coil_current_command", "A", "coil current set point of the current drive (BenchOptions(coil_drive='current'): "
                                  "replaces the torque controller of Eqs. 6-7 and 31)"),
    ("coupling_temperature", "degC", "temperature of the coupling's friction pack, at which its friction map is "
                                     "read (BenchOptions(coupling_temperature='input'): a network's thermal mass "
                                     "that its losses heat, Sec. 5; else the scenario's temperature_c)"),
)
#: switching functions and their crossing direction (the mode changes of [1] Fig. 11: falling through zero)
SWITCHING = (
    ("armature_reaches_rest", -1),
    ("armature_reaches_clutch", -1),
    ("magnet_overcomes_preload", -1),
    ("clamp_force_vanishes", -1),
    ("slip_speed_zero", -1),
    ("lock_capacity_exceeded", -1),
    # the coil current crossing a line of the Preisach grid: a kink of the magnet force (Eqs. 2-5 interpolate the
    # Everett function between the lines), so that no step straddles one: a waypoint either way (direction 4: the
    # core ends a step just past the crossing, no event is located or named, no mode changes)
    ("coil_current_grid_line", 4),
    # the coil current turning (i1 = i2: the second current lag at rest): the Preisach output turns onto another
    # branch there, and the magnet's memory takes its turning point from the input it is committed at, a step's end
    # (commit): a waypoint either way, so that a step ends just past each turn (i1 - i2 beyond a band of TURN_BAND,
    # the side it was last on: rounding between two equal currents is no turn)
    ("coil_current_turn", 4),
)
N_SWITCH = len(SWITCHING)
G_GRID, G_TURN = indices(SWITCHING, "coil_current_grid_line", "coil_current_turn")
#: [A] how far the first current lag must pass the second before the coil current's turn counts (a turn is located
#: that much late: the turning point committed then lies (TURN_BAND / tau2)^2 / (2 |i2''|) below the true one, 1e-13 A
#: for tau2 = 1 ms and a turn as slow as 1 A/s^2)
TURN_BAND = 1e-9
#: event names by code (docs/nomenclature.md)
EVENTS = ("armature_rest", "armature_contact", "armature_leave_rest", "armature_leave_contact", "lockup",
          "slip_reversal", "unlock")
EVENT_DESCRIPTIONS = {
    "armature_rest": "armature at rest stop",
    "armature_contact": "armature contacts primary clutch (engaged)",
    "armature_leave_rest": "armature leaves rest stop",
    "armature_leave_contact": "armature leaves primary clutch (open)",
    "lockup": "lock-up (slip speed zero, capacity covers T_lock)",
    "slip_reversal": "slip reversal (capacity below T_lock)",
    "unlock": "unlock (|T_lock| > 1.02 T_cap)",
}
MODE_NAMES = ("armature_mode", "coupling_mode", "slip_direction")
MODE_VALUES = (("rest", "free", "contact"), ("open", "slipping", "locked"), ("negative", "positive"))
ELEMENTS = ("armature", "coupling")

EV_ARM_REST, EV_ARM_CONTACT, EV_ARM_LEAVE_REST, EV_ARM_LEAVE_CONTACT, EV_LOCK, EV_SLIP_REVERSAL, EV_UNLOCK = indices(
    EVENTS, "armature_rest", "armature_contact", "armature_leave_rest", "armature_leave_contact", "lockup",
    "slip_reversal", "unlock")
EL_ARMATURE, EL_COUPLING = indices(ELEMENTS, "armature", "coupling")
_M_ARM, _M_CPL, _M_DIR = indices(MODE_NAMES, "armature_mode", "coupling_mode", "slip_direction")
#: the shafts' speeds (the states the start writes from the drum speeds)
X_OMEGA_F, X_OMEGA_R = indices(STATES, "omega_f", "omega_r")
ARM_REST, ARM_FREE, ARM_CONTACT = indices(MODE_VALUES[_M_ARM], "rest", "free", "contact")
OPEN, SLIPPING, LOCKED = indices(MODE_VALUES[_M_CPL], "open", "slipping", "locked")
NEGATIVE, POSITIVE = indices(MODE_VALUES[_M_DIR], "negative", "positive")
U_TORQUE, U_THROTTLE, U_DRUM_FRONT, U_DRUM_REAR, U_COIL, U_TEMP = indices(
    INPUTS, "torque_request", "throttle", "drum_speed_front", "drum_speed_rear", "coil_current_command",
    "coupling_temperature")
#: the friction laws of ``EmtcParams.friction_mode`` and the torque-reference sources of ``reference_source``
#: (REFERENCE_CURRENT: the coil current from the input, no torque controller)
FRICTION_MODES = ("constant", "map", "lugre")
REFERENCE_SOURCES = ("map", "table", "input", "current")
FRICTION_CONSTANT, FRICTION_MAP, FRICTION_LUGRE = indices(FRICTION_MODES, "constant", "map", "lugre")
REFERENCE_MAP, REFERENCE_TABLE, REFERENCE_INPUT, REFERENCE_CURRENT = indices(
    REFERENCE_SOURCES, "map", "table", "input", "current")
#: where the friction map's temperature comes from (``EmtcParams.temperature_source``): the coupling's parameter
#: ``temperature_c``, or the input ``coupling_temperature`` (a heat port: [2] Sec. 5, the coupling's heat)
TEMPERATURE_SOURCES = ("parameter", "input")
TEMPERATURE_PARAMETER, TEMPERATURE_INPUT = indices(TEMPERATURE_SOURCES, "parameter", "input")
#: [degC] the range of the input coupling_temperature: the scenario's temperature_c's
TEMPERATURE_RANGE = tuple({f.name: f for f in dataclasses.fields(BenchScenario)}["temperature_c"].metadata["bounds"])

# model errors (negative codes of the hooks)
ERR_PLANT_MEMORY, ERR_CONTROLLER_MEMORY = -1, -2
# ... and the start's refusals of parameters no run can start from (a native FMU's host sets them one by one;
# clutchlab's own packing refuses them first, with their values)
ERR_GEAR, ERR_GEOMETRY, ERR_AIRGAP, ERR_AIRGAP_RANGE = -3, -4, -5, -6
ERROR_MESSAGES = {
    ERR_PLANT_MEMORY: "the plant magnet's hysteresis memory is full (BenchOptions.memory_capacity)",
    ERR_CONTROLLER_MEMORY: "the controller model's hysteresis memory is full (BenchOptions.memory_capacity)",
    ERR_GEAR: "scenario.gear must be a whole number from 1 to the vehicle's number of gear ratios",
    ERR_GEOMETRY: "vehicle.cg_to_front + vehicle.cg_to_rear must equal vehicle.wheelbase (within 1 mm)",
    ERR_AIRGAP: "actuator.airgap_open must exceed actuator.free_travel ([1], Eq. 12: d > sigma)",
    ERR_AIRGAP_RANGE: "the actuator's airgaps [airgap_open - free_travel, airgap_open] must lie within the magnet's "
                      "calibration airgaps",
}

#: per-run integer memories (EmtcParams.imem)
IMEM = slots(("plant_length", 1), ("controller_length", 1), ("next_sample", 1), ("error", 1),
             ("plant_table_index", GAP_TABLES), ("controller_table_index", GAP_TABLES),
             ("moving_table_index", GAP_TABLES),   # the plant tables' indices at the last evaluation, armature moving
             ("plant_version", 1),        # changes of the plant's hysteresis stack so far (its length)
             ("controller_version", 1),   # the same for the controller model's
             ("current_falling", 1))      # 1 if the coil current i2 fell at the last accepted step beyond TURN_BAND
IM_PLEN, IM_CLEN, IM_KNEXT, IM_ERROR, IM_GIDX, IM_CIDX, IM_FIDX, IM_PVER, IM_CVER, IM_FALLING = IMEM.of(
    "plant_length", "controller_length", "next_sample", "error", "plant_table_index", "controller_table_index",
    "moving_table_index", "plant_version", "controller_version", "current_falling")
N_IMEM = IMEM.total
#: the model intermediates of an evaluation (FMEM's "aux")
AUX = ("magnet_force", "fn1", "t1", "t2", "t3", "coupling_torque", "lock_torque", "transmission_torque",
       "capacity_locked", "locked_case", "fn2", "engine_torque", "throttle")
(AUX_FM, AUX_FN1, AUX_T1, AUX_T2, AUX_T3, AUX_TC, AUX_TLOCK, AUX_TTRANS, AUX_CAP, AUX_CASE, AUX_FN2, AUX_TE,
 AUX_THR) = indices(
    AUX, "magnet_force", "fn1", "t1", "t2", "t3", "coupling_torque", "lock_torque", "transmission_torque",
    "capacity_locked", "locked_case", "fn2", "engine_torque", "throttle")
N_AUX = len(AUX)
#: the point (t, x, modes, inputs) of an evaluation, as its key in the float memory (FMEM "key")
KEY = slots(("time", 1), ("states", len(STATES)), ("modes", len(MODE_NAMES)), ("inputs", len(INPUTS)))
#: per-run float memories and scratch (EmtcParams.fmem)
FMEM = slots(("plant_input", 1), ("controller_input", 1), ("command", 1), ("torque_reference", 1), ("feasible", 1),
             ("z", 1), ("t_last", 1), ("dw_last", 1), ("dv_last", 1),
             ("plant_weights", GAP_TABLES + 1),   # airgap weights of the plant tables, the airgap they are for
             ("controller_weights", GAP_TABLES),  # weights of the controller model's table (one at the engaged airgap)
             ("inputs_at_restart", len(INPUTS)),    # inputs seen at the last restart
             ("aux", N_AUX),              # model intermediates of the last evaluation (AUX)
             ("split", 6),                # element torques and capacities of the torque split
             ("derivative", len(STATES)), ("switching", len(SWITCHING)),     # scratch
             # the point (t, x, modes, inputs) of the last evaluation; NaN once a memory or mode may have changed
             ("key", KEY.total),
             ("last_derivative", len(STATES)), ("last_switching", len(SWITCHING)),   # of the last evaluation
             ("moving_weights", GAP_TABLES),      # airgap weights of the plant tables at the last evaluation, moving
             ("plant_segment", 9),        # the plant magnet's force as a quadratic in the coil current on the
             #                              stretch of the last evaluation (lo, hi, a0, a1, a2, kind:
             #                              hysteresis.kernels.peek_segment), the stack version (IM_PVER), last
             #                              input and airgap it is for
             ("controller_segment", 8))   # the controller model's rising stretch (hysteresis.kernels.invert_combined)
(FM_PU, FM_CU, FM_CMD, FM_TREF, FM_FEASIBLE, FM_Z, FM_TLAST, FM_DWLAST, FM_DVLAST, FM_GW, FM_CW, FM_ULAST, FM_AUX, FM_SPLIT,
 FM_DX, FM_G, FM_KEY, FM_DXM, FM_GM, FM_FW, FM_SEG, FM_CSEG) = FMEM.of(
    "plant_input", "controller_input", "command", "torque_reference", "feasible", "z", "t_last", "dw_last",
    "dv_last", "plant_weights", "controller_weights", "inputs_at_restart", "aux", "split", "derivative", "switching", "key",
    "last_derivative", "last_switching", "moving_weights", "plant_segment", "controller_segment")
#: where the point's time, states, modes and inputs lie in the key (``fmem[FM_KEY:]``)
KEY_X, KEY_M, KEY_U = KEY.of("states", "modes", "inputs")
N_STATE_KEY, N_MODE_KEY, N_INPUT_KEY = len(STATES), len(MODE_NAMES), len(INPUTS)
N_FMEM = FMEM.total
#: controller log (one row per sample, for the per-sample view of simulate_bench)
LOG_COLUMNS = ("command", "torque_reference", "throttle", "feasible")
LOG_CMD, LOG_TREF, LOG_THR, LOG_FEASIBLE = indices(LOG_COLUMNS, "command", "torque_reference", "throttle", "feasible")
#: the tables of EmtcParams.cold: (offset, size) pairs in EmtcParams.layout
#: (``plant_tables`` and ``controller_tables`` are fields of their own, ``EmtcParams.plant_tables`` and
#: ``controller_table``, empty here; the controller's table at its one airgap is derived by
#: :func:`derive_actuator` from the controller model's tables at its calibration airgaps,
#: ``controller_all_tables`` and ``controller_gaps``, and the gear ratio from ``gear_ratios``: read at the start)
TABLES = ("plant_tables", "plant_gaps", "controller_tables", "controller_grid", "controller_stack",
          "controller_prefix", "map_throttle", "map_speed", "map_torque", "reference_time", "reference_value",
          "friction_map_speed", "friction_map_temperature", "friction_map_mu", "log", "controller_all_tables",
          "controller_gaps", "gear_ratios")
(L_PLANT_TABLES, L_PLANT_GAPS, L_CTL_TABLES, L_CTL_GRID, L_CTL_STACK, L_CTL_PREFIX, L_MAP_THROTTLE,
 L_MAP_SPEED, L_MAP_TORQUE, L_REF_TIME, L_REF_VALUE, L_FMAP_SPEED, L_FMAP_TEMP, L_FMAP_MU, L_LOG, L_CTL_ALL,
 L_CTL_GAPS, L_GEAR_RATIOS) = indices(
    TABLES, "plant_tables", "plant_gaps", "controller_tables", "controller_grid", "controller_stack",
    "controller_prefix", "map_throttle", "map_speed", "map_torque", "reference_time", "reference_value",
    "friction_map_speed", "friction_map_temperature", "friction_map_mu", "log", "controller_all_tables",
    "controller_gaps", "gear_ratios")
N_LAYOUT = len(TABLES)

#: absolute tolerances of the states at rtol 1e-6 and above: omega_f, omega_r [rad/s], theta [rad], x [m],
#: v [m/s], i1, i2 [A]
ATOL = np.array([1e-4, 1e-4, 1e-7, 1e-9, 1e-6, 1e-5, 1e-5])
#: the relative tolerance below which the absolute tolerances shrink with it (the default rtol)
ATOL_RTOL = 1e-6


def absolute_tolerance(rtol: float = ATOL_RTOL) -> np.ndarray:
    """Absolute tolerance per state for a relative tolerance: :data:`ATOL` times ``min(1, rtol / 1e-6)``.

    At the default ``rtol`` (1e-6) and above these are the fixed tolerances the
    model has always used; below it they shrink with ``rtol``, so that the
    error control follows the tolerance.  With :data:`ATOL` fixed, the
    shaft speeds' 1e-4 rad/s set the error of every run from ``rtol`` 1e-7
    down (measured on ``examples/emtc_scenario.toml`` against SciPy's DOP853
    at rtol 1e-12: 1.3e-4 rad/s at rtol 1e-7, 1e-8, 1e-9 and 1e-10 alike;
    with the scaling 6.4e-6, 4.8e-7, 3.2e-7, 3.5e-7 rad/s, the last two set by an unlocated kink of the
    magnet force, see ``docs/emtc.md``, "Accuracy"; ``tests/emtc/test_accuracy.py``).

    Parameters
    ----------
    rtol : float
        Relative tolerance of the run.
    """
    return follow_rtol(ATOL, rtol, ATOL_RTOL)   # (the contract's one rule)


#: the vehicle and drum-bench numbers of a run (SI; [1] Table 1, Eqs. 27-30 and clutchlab's bench), one record
#: (``EmtcParams.vehicle``, shape ``(1,)``): the parameters as given (``axle_ratio`` is
#: ``VehicleParameters.rear_final_drive``, ``gear`` the scenario's, a whole number), then what
#: :func:`derive_vehicle` derives from them (:data:`DERIVED_VEHICLE`), at the packing and again at the start of
#: every run (a native FMU's host may have set the parameters)
VEHICLE_PARAMETERS = ("mass", "cg_to_front", "cg_to_rear", "wheelbase", "gear", "front_final_drive", "axle_ratio",
                      "tyre_radius", "inertia_front_axle", "inertia_rear_axle", "inertia_input_shaft",
                      "inertia_output_shaft", "rolling_resistance", "tyre_slip_stiffness", "slip_speed_floor",
                      "engine_torque_max", "engine_power", "torsen_stiffness", "torsen_damping", "drum_load_front",
                      "drum_load_rear")
#: a run option beside them: 1 where the start puts the shafts on the drums, free rolling at the drum speed inputs
#: (a co-simulation, whose host sets the drum speeds and the vehicle: :func:`bench_system`'s ``start_on_drums``); 0
#: where the run starts from the system's ``x0`` as given (an operating point's state, a resumed run)
VEHICLE_OPTIONS = ("start_on_drums",)
DERIVED_VEHICLE = ("gear_ratio",         # the scenario's gear's ratio
                   "inertia_front",      # J_F = J_sf + J_wf / i^2 ([1], Eq. 29)
                   "inertia_rear",       # J_R = J_sr + J_wr / i^2
                   "axle_load_front",    # static axle loads (Table 1's geometry)
                   "axle_load_rear",
                   "inv_axle_ratio",     # 1 / i, and below: the divisions of every evaluation, done once
                   "inv_inertia_front",
                   "inv_inertia_rear",
                   "lock_share_front",   # J_R / (J_F + J_R): the weight of A_f in T_lock (Eq. 29)
                   "lock_share_rear")    # J_F / (J_F + J_R)
VEHICLE_DTYPE = np.dtype([(name, np.float64) for name in VEHICLE_PARAMETERS + VEHICLE_OPTIONS + DERIVED_VEHICLE])


class CouplingData(NamedTuple):
    """Coupling scalars: drag of the open coupling (Eq. 25), unlock margin, temperature of the friction map."""

    drag_pairs: float
    oil_viscosity: float
    plate_clearance: float
    plate_outer_radius: float
    plate_inner_radius: float
    unlock_margin: float
    temperature_c: float


#: the armature, return spring and current lags ([1], Eqs. 8-12, Fig. 15), SI, one record
#: (``EmtcParams.actuator``, shape ``(1,)``): the parameters, then what :func:`derive_actuator` derives
ACTUATOR_PARAMETERS = ("mass", "stiffness", "preload", "damping", "free_travel", "airgap_open", "tau1", "tau2")
DERIVED_ACTUATOR = ("inv_tau1", "inv_tau2")   # 1 / tau1, 1 / tau2: the divisions of every evaluation, done once
ACTUATOR_DTYPE = np.dtype([(name, np.float64) for name in ACTUATOR_PARAMETERS + DERIVED_ACTUATOR])


class EmtcParams(NamedTuple):
    """Packed parameters and per-run memories of the EMTC drum-bench model (built by :func:`pack_parameters`).

    The vehicle's and the actuator's numbers are one record each (arrays of shape ``(1,)``, :data:`VEHICLE_DTYPE`,
    :data:`ACTUATOR_DTYPE`: the run's start writes what it derives there, :func:`emtc_start`), the coupling's
    drag scalars a NamedTuple (:class:`CouplingData`), the coupling geometry
    (:meth:`CouplingGeometry.kernel_data`) and the LuGre data tuples.  The core passes the structure to the hooks by
    reference with its arrays borrowed (no reference counting; see docs/architecture.md).  The arrays: the throttle
    profile and the plant magnet's memory (read on every evaluation), the controller model's table at its one airgap
    (``controller_table``, which the start derives), the integer and float memories of the run
    (``imem``, ``fmem``, offsets ``IM_*``, ``FM_*``), and one array ``cold`` with everything read only at controller
    samples, airgap changes or in the friction-map mode (offsets and sizes in ``layout``, indices ``L_*``).  One
    instance per run (or batch variant).
    """

    vehicle: np.ndarray
    coupling: CouplingData
    actuator: np.ndarray
    geometry: tuple
    lugre: tuple
    sample_time: float
    friction_mode: int
    reference_source: int
    temperature_source: int
    n_airgaps: int
    n_cells: int
    n_ctl_cells: int
    n_fmap_speed: int
    n_fmap_temp: int
    n_map_throttle: int
    n_map_speed: int
    layout: tuple
    throttle: np.ndarray
    plant_tables: np.ndarray
    plant_grid: np.ndarray
    plant_stack: np.ndarray
    plant_prefix: np.ndarray
    plant_comb: np.ndarray
    controller_table: np.ndarray
    imem: np.ndarray
    fmem: np.ndarray
    cold: np.ndarray


# ------------------------------------------------------------------ equations (one scalar function each)
@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def armature_acceleration(fm, x, v, a):
    """Acceleration of the free armature ([1], Eq. 9 with ``F_n0 = F_n1 = 0``) [m/s^2].

    ``m0 a = F_m - F_k0 - K x - c v`` with the magnet force ``fm`` [N], displacement ``x`` [m], speed
    ``v`` [m/s] and the armature data ``a`` (a record of :data:`ACTUATOR_DTYPE`).
    """
    return (fm - a.preload - a.stiffness * x - a.damping * v) / a.mass  # [1], Eq. 9


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def primary_clamp_force(fm, a):
    """Force of the armature on the primary clutch at ``x = sigma``: ``F_m - F_k0 - K sigma`` ([1], Eq. 11) [N].

    ``fm``: magnet force [N]; ``a``: a record of :data:`ACTUATOR_DTYPE`.  Negative values mean the armature leaves the
    clutch (the clamp force itself is ``max(., 0)``).
    """
    return fm - a.preload - a.stiffness * a.free_travel  # [1], Eq. 11


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def bench_loads(wf, wr, throttle, v_front, v_rear, v):
    """Loads on the two coupling shafts of the vehicle on the drum bench ([1], Eq. 27, rows 1+3 and 2+4).

    ``J_F dw_f/dt = A_f - T_c``, ``J_R dw_r/dt = T_c - A_r`` with ``A_f = (T_trans i0 - F_xf r - T_ff)/i``,
    ``A_r = (F_xr r + T_fr)/i`` at the shaft speeds ``wf``, ``wr`` [rad/s], throttle [-] and drum surface
    speeds [m/s]; ``v``: a record of :data:`VEHICLE_DTYPE`.  Tyre force on a drum
    ``F_x = 2 C_x r (w_w r - v_d)/max(|v_d|, v_floor)`` per axle, rolling resistance
    ``f_rr F_z r tanh(w_w / 0.5 rad/s)`` plus the drum load, engine torque ``throttle min(T_max, P/w_e)``
    (clutchlab's assumptions: the paper does not model the tyre-drum contact or the engine).
    Returns ``(A_f, A_r, T_e, T_trans)`` [N*m].
    """
    inv_ic = v.inv_axle_ratio  # 1 / i
    rw = v.tyre_radius
    wwf = wf * inv_ic
    wwr = wr * inv_ic
    kf = 2.0 * v.tyre_slip_stiffness * rw / max(abs(v_front), v.slip_speed_floor)
    kr = 2.0 * v.tyre_slip_stiffness * rw / max(abs(v_rear), v.slip_speed_floor)
    fxf = kf * (wwf * rw - v_front)  # tyre-drum longitudinal force, both wheels
    fxr = kr * (wwr * rw - v_rear)
    # tanh(w_w / 0.5 rad/s), without the call where it is +-1 in double precision (|z| >= 20: 1 - tanh is below
    # 1e-17, half an ulp of 1 is 5.5e-17: the library's value)
    zf = wwf * 2.0
    zr = wwr * 2.0
    tf = 1.0 if zf >= 20.0 else (-1.0 if zf <= -20.0 else math.tanh(zf))
    tr = 1.0 if zr >= 20.0 else (-1.0 if zr <= -20.0 else math.tanh(zr))
    rrf = v.rolling_resistance * v.axle_load_front * rw * tf + v.drum_load_front
    rrr = v.rolling_resistance * v.axle_load_rear * rw * tr + v.drum_load_rear
    we = max(abs(wwf) * v.front_final_drive * v.gear_ratio, 1.0)
    tmax = v.engine_torque_max
    te = throttle * (tmax if we * tmax <= v.engine_power else v.engine_power / we)  # min(T_max, P / w_e)
    ttrans = te * v.gear_ratio
    a_f = (ttrans * v.front_final_drive - fxf * rw - rrf) * inv_ic  # [1], Eq. 27: front loads at the coupling shaft
    a_r = (fxr * rw + rrr) * inv_ic
    return a_f, a_r, te, ttrans


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def lock_torque(a_f, a_r, v):
    """Torque that keeps both shafts at the same acceleration, ``(J_R A_f + J_F A_r)/(J_F + J_R)`` ([1], Eq. 29) [N*m].

    ``a_f``, ``a_r``: the loads of Eq. 27 [N*m]; ``v``: a record of :data:`VEHICLE_DTYPE`.
    """
    return v.lock_share_front * a_f + v.lock_share_rear * a_r  # [1], Eq. 29 (the shares J_R, J_F / (J_F + J_R))


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def commanded_magnet_force(t_ref, g, a, split):
    """Magnet force the controller asks for to transfer ``t_ref`` [N*m] in slipping mode ([1], Eqs. 13, 15, 11).

    ``F_n1 = T_ref / (T_c/F_n1)`` with the slipping-mode torque per newton of Eqs. 13-15 at the kinetic
    coefficients of the geometry ``g``, then ``F_m = F_n1 + F_k0 + K sigma`` (Eq. 11 solved for ``F_m``;
    ``a``: a record of :data:`ACTUATOR_DTYPE`); 0 for ``t_ref <= 0``.  ``split`` is scratch (3 values).  Returns [N].
    """
    if not t_ref > 0.0:
        return 0.0
    _slipping(1.0, 1.0, g, g[0], g[1], g[2], split)  # [1], Eqs. 13-15 per newton of F_n1
    return t_ref / (split[0] + split[1] + split[2]) + a.preload + a.stiffness * a.free_travel  # [1], Eq. 11


# ------------------------------------------------------------------ the model
@numba.njit(cache=True, nogil=True, inline="always")
def _cold(cold, layout, k):
    """Table ``k`` (``L_*``) of ``EmtcParams.cold`` as a 1-D view (``layout``: ``EmtcParams.layout``)."""
    o = layout[2 * k]
    return cold[o:o + layout[2 * k + 1]]


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def grid_line_function(i, grid):
    """A function of the coil current ``i`` [A] that changes sign at every line of the Preisach grid ``grid`` [A]
    (increasing) and nowhere else: ``(-1)**k (i - grid[k]) (grid[k+1] - i) / (grid[k+1] - grid[k])`` [A] in cell
    ``k``, ``i - grid[0]`` below the grid and ``(-1)**(n-1) (i - grid[n-1])`` above it.

    The plant magnet's force is the Preisach output of Eqs. 2-5 ([1]), whose Everett function is interpolated
    between the grid lines, and its input is clamped to the grid: the force's slope in ``i`` jumps at every line.
    An integrator step that straddles such a kink makes an error its error estimate does not see (the speeds
    were off by 4e-7 rad/s at rtol 1e-10 where ``i2`` crossed 1.5 A and 2.5 A, docs/emtc.md); as the switching
    function ``coil_current_grid_line`` (a waypoint either way) a step ends just past every line.
    Continuous, smooth inside each cell."""
    n = grid.shape[0]
    if i <= grid[0]:
        return i - grid[0]
    if i >= grid[n - 1]:
        return (i - grid[n - 1]) * (1.0 if (n - 1) % 2 == 0 else -1.0)
    k = 0
    hi = n - 1
    while hi - k > 1:   # (bisection: grid[k] <= i < grid[hi])
        mid = (k + hi) // 2
        if grid[mid] <= i:
            k = mid
        else:
            hi = mid
    v = (i - grid[k]) * (grid[k + 1] - i) / (grid[k + 1] - grid[k])
    return v if k % 2 == 0 else -v


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _switching(x, m, a, margin, aux, grid, falling, g):
    """Switching functions (:data:`SWITCHING`) from the state and the intermediates; inactive ones are +1.

    ``a``: a record of :data:`ACTUATOR_DTYPE`; ``margin``: unlock margin of Fig. 11; ``grid``: the plant's Preisach
    grid [A] (:func:`grid_line_function`); ``falling``: 1 if the coil current fell at the last accepted step
    (``imem[IM_FALLING]``, :func:`_commit`).
    """
    for k in range(N_SWITCH):
        g[k] = 1.0
    g[G_GRID] = grid_line_function(x[6], grid)
    # the turn: di2/dt = (i1 - i2) / tau2 through zero, TURN_BAND past it, from the side the current last moved
    g[G_TURN] = x[5] - x[6] + (-TURN_BAND if falling else TURN_BAND)
    arm = m[0]
    if arm == ARM_FREE:
        g[0] = x[3]  # reaches the rest stop
        g[1] = a.free_travel - x[3]  # reaches the primary clutch (x = sigma)
    elif arm == ARM_REST:
        g[2] = a.preload - aux[AUX_FM]  # the magnet overcomes the preload
    else:
        g[3] = primary_clamp_force(aux[AUX_FM], a)  # F_n1 of Eq. 11 drops to zero
    if m[1] == SLIPPING:
        g[4] = (1.0 if m[2] == POSITIVE else -1.0) * (x[0] - x[1])  # slip speed reaches zero
    elif m[1] == LOCKED:
        g[5] = margin * aux[AUX_CAP] - abs(aux[AUX_TC])  # |T'_lock| > 1.02 T_cap_L


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _evaluate_into(t, x, u, m, p):
    """The model at one point into the scratch of ``p.fmem`` (derivative, switching functions, ``aux``)."""
    fmem = p.fmem
    dispatch.rhs(t, x, u, m, p, fmem[FM_DX:FM_DX + 7], fmem[FM_G:FM_G + N_SWITCH])


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _evaluate(t, x, u, m, p):
    """The model at one point into the scratch of ``p.fmem`` (:func:`_evaluate_into`, called through its address at
    the hooks' signature); returns ``aux``, the intermediates (``AUX_*``)."""
    _evaluate_outlined(t, x, u, m, p)
    fmem = p.fmem
    return fmem[FM_AUX:FM_AUX + N_AUX]


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _switch(k, t, x, u, m, p, log):
    """Mode change when switching function ``k`` crossed at ``t`` ([1], Eqs. 8-11, Fig. 11); records the event."""
    fmem = p.fmem
    a = p.actuator[0]
    v = p.vehicle[0]
    if k == 0:
        if m[0] != ARM_FREE:
            return
        x[3] = 0.0  # plastic impact at the rest stop
        x[4] = 0.0
        m[0] = ARM_REST
        record(log, t, EV_ARM_REST, EL_ARMATURE)
    elif k == 1:
        if m[0] != ARM_FREE:
            return
        x[3] = a.free_travel  # plastic impact on the primary clutch: engaged
        x[4] = 0.0
        m[0] = ARM_CONTACT
        m[1] = SLIPPING
        dwe = x[0] - x[1]
        m[2] = POSITIVE if dwe >= 0.0 else NEGATIVE
        if p.friction_mode == FRICTION_LUGRE and dwe != 0.0:  # bristles start at their steady state
            fmem[FM_Z] = stribeck_g(dwe, p.lugre) / p.lugre[0] * (1.0 if dwe > 0.0 else -1.0)
        record(log, t, EV_ARM_CONTACT, EL_ARMATURE)
    elif k == 2:
        if m[0] != ARM_REST:
            return
        m[0] = ARM_FREE
        record(log, t, EV_ARM_LEAVE_REST, EL_ARMATURE)
    elif k == 3:
        if m[0] != ARM_CONTACT:
            return
        m[0] = ARM_FREE
        m[1] = OPEN
        x[2] = 0.0
        record(log, t, EV_ARM_LEAVE_CONTACT, EL_ARMATURE)
    elif k == 4:  # slip speed zero: lock if the static capacity covers the lock torque (Fig. 11)
        if m[1] != SLIPPING:
            return
        aux = _evaluate(t, x, u, m, p)
        if abs(aux[AUX_TLOCK]) <= aux[AUX_CAP]:
            wm = (x[0] * v.inertia_front + x[1] * v.inertia_rear) / (v.inertia_front + v.inertia_rear)
            x[0] = wm
            x[1] = wm
            x[2] = 0.0
            m[1] = LOCKED
            record(log, t, EV_LOCK, EL_COUPLING)
        else:
            m[2] = NEGATIVE if m[2] == POSITIVE else POSITIVE
            record(log, t, EV_SLIP_REVERSAL, EL_COUPLING)
    elif k == 5:  # |T'_lock| > 1.02 T_cap: slipping in the direction of the lock torque
        if m[1] != LOCKED:
            return
        aux = _evaluate(t, x, u, m, p)
        m[1] = SLIPPING
        m[2] = POSITIVE if aux[AUX_TC] >= 0.0 else NEGATIVE
        x[2] = 0.0
        if p.friction_mode == FRICTION_LUGRE:  # breakaway: bristles at full static deflection
            fmem[FM_Z] = p.lugre[4] / p.lugre[0] * (1.0 if m[2] == POSITIVE else -1.0)
        record(log, t, EV_UNLOCK, EL_COUPLING)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _commit(t, x, p):
    """Commit the plant magnet memory and the LuGre bristle state at the end of an accepted step (once per ``t``).

    ``p``: the parameters (the plant's Preisach tables and memory, the run's memories, the LuGre data); returns
    0 or :data:`ERR_PLANT_MEMORY`.
    """
    imem = p.imem
    fmem = p.fmem
    if t == fmem[FM_TLAST]:
        return 0
    grid = p.plant_grid
    stack = p.plant_stack
    inew = min(max(x[6], grid[0]), grid[grid.shape[0] - 1])
    plen = imem[IM_PLEN]
    if plen + 2 > stack.shape[0]:
        return ERR_PLANT_MEMORY
    pu = fmem[FM_PU]
    if not _stack_stays(stack, plen, pu, inew):
        new = commit(p.plant_tables, grid, stack, p.plant_prefix, plen, pu, inew)
        if new != plen:  # the stack changes only with its length
            imem[IM_PLEN] = new
            imem[IM_PVER] += 1
    fmem[FM_PU] = inew
    d = x[5] - x[6]   # (the side the coil current moves to, beyond TURN_BAND: the turn function's next side)
    if d > TURN_BAND:
        imem[IM_FALLING] = 0
    elif d < -TURN_BAND:
        imem[IM_FALLING] = 1
    tlast = fmem[FM_TLAST]
    if p.friction_mode == FRICTION_LUGRE and tlast == tlast:  # Eq. 23 over the step, as its stages saw it
        fmem[FM_Z] = lugre_advance_path(fmem[FM_Z], fmem[FM_DWLAST], x[0] - x[1], fmem[FM_DVLAST], t - tlast, p.lugre)
    fmem[FM_TLAST] = t
    return 0


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _stack_stays(stack, length, u, v):
    """True if moving a hysteresis memory from input ``u`` to ``v`` leaves its stack as it is (no turning point
    pushed, nothing wiped: :func:`~clutchlab.hysteresis.kernels.commit` would only move the last input)."""
    if v > u:
        return length % 2 == 0 and (length < 2 or v < stack[length - 2])
    if v < u:
        return length % 2 == 1 and (length < 3 or v > stack[length - 2])
    return True


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _controller(t, x, u, p):
    """One controller sample at ``t``: reference (Eq. 31, table or input), force (Eqs. 13, 15, 11), current (Eqs. 6-7)."""
    fmem = p.fmem
    imem = p.imem
    a = p.actuator[0]
    thr = u[U_THROTTLE] if p.throttle.shape[1] == 0 else interp1(p.throttle[0], p.throttle[1], t)
    if p.reference_source == REFERENCE_CURRENT:  # current drive: the coil's set point is an input, no controller
        fmem[FM_CMD] = u[U_COIL]
        fmem[FM_TREF] = np.nan
        fmem[FM_FEASIBLE] = 1.0
        k = imem[IM_KNEXT]
        log = _cold(p.cold, p.layout, L_LOG)
        if 4 * k + 3 < log.shape[0]:
            log[4 * k + LOG_CMD] = u[U_COIL]
            log[4 * k + LOG_TREF] = np.nan
            log[4 * k + LOG_THR] = thr
            log[4 * k + LOG_FEASIBLE] = 1.0
        return
    if p.reference_source == REFERENCE_INPUT:
        t_ref = u[U_TORQUE]
    elif p.reference_source == REFERENCE_TABLE:
        t_ref = interp1(_cold(p.cold, p.layout, L_REF_TIME), _cold(p.cold, p.layout, L_REF_VALUE), t)
    else:
        v = p.vehicle[0]
        vx = x[0] / v.axle_ratio * v.tyre_radius
        t_ref = bilinear(_cold(p.cold, p.layout, L_MAP_THROTTLE), _cold(p.cold, p.layout, L_MAP_SPEED),
                         shaped(_cold(p.cold, p.layout, L_MAP_TORQUE), (p.n_map_throttle, p.n_map_speed)), thr, vx)  # [1], Eq. 31
    fm_req = commanded_magnet_force(t_ref, p.geometry, a, fmem[FM_SPLIT:FM_SPLIT + 3])
    clen = imem[IM_CLEN]
    stack = _cold(p.cold, p.layout, L_CTL_STACK)
    if clen + 2 > stack.shape[0]:
        imem[IM_ERROR] = ERR_CONTROLLER_MEMORY  # reported by the next accepted step
        return
    # the controller's model at its one airgap, the engaged d - sigma: the airgap interpolation (Eqs. 2-5 are
    # linear in the table) applied to the cell coefficients once by pack_parameters, one table of weight 1
    tables = p.controller_table
    grid = _cold(p.cold, p.layout, L_CTL_GRID)
    prefix = shaped(_cold(p.cold, p.layout, L_CTL_PREFIX), (1, stack.shape[0] // 2 + 2))
    cidx = imem[IM_CIDX:IM_CIDX + GAP_TABLES]
    cw = fmem[FM_CW:FM_CW + GAP_TABLES]
    cu = fmem[FM_CU]
    i_new, ok = invert_combined(tables, grid, stack, prefix, clen, cu, fm_req, cidx, cw, 1e-9,
                                fmem[FM_CSEG:FM_CSEG + 8], imem[IM_CVER])  # [1], Eq. 7 on the kept stretch
    if i_new != i_new:
        i_new, ok = invert_one(tables, grid, stack, prefix, clen, cu, fm_req, cidx, cw, 1e-9)  # [1], Eqs. 6-7
    if not _stack_stays(stack, clen, cu, i_new):
        new = commit(tables, grid, stack, prefix, clen, cu, i_new)
        if new != clen:  # the stack changes only with its length
            imem[IM_CLEN] = new
            imem[IM_CVER] += 1
    fmem[FM_CU] = i_new
    fmem[FM_CMD] = i_new
    fmem[FM_TREF] = t_ref
    fmem[FM_FEASIBLE] = 1.0 if ok else 0.0
    k = imem[IM_KNEXT]
    log = _cold(p.cold, p.layout, L_LOG)
    if 4 * k + 3 < log.shape[0]:
        log[4 * k + LOG_CMD] = i_new
        log[4 * k + LOG_TREF] = t_ref
        log[4 * k + LOG_THR] = thr
        log[4 * k + LOG_FEASIBLE] = 1.0 if ok else 0.0


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _command(u, p):
    """Coil current command [A] of the current lags (Fig. 15): the held input ``coil_current_command`` in
    current drive (its changes act at once: a linear model has it as an input), else the controller's
    command held since its last sample (Eqs. 6-7)."""
    return u[U_COIL] if p.reference_source == REFERENCE_CURRENT else p.fmem[FM_CMD]


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _magnet_force(p, moving, gap, icoil):
    """The plant magnet's force [N] at the coil current ``icoil`` [A] and the airgap ``gap`` [m] where the stretch
    kept in ``fmem[FM_SEG:]`` does not hold: Preisach output for the next input, memory not committed ([1],
    Eqs. 1-5), interpolated over the calibration airgaps (Eq. 12).

    ``moving``: the armature is free, another airgap at every stage: the weighted output of the
    calibration tables around it (building the weighted cell table would cost more than the evaluation).  At a stop the
    airgap stays: the weighted cell table is built once per stop (Eqs. 2-5 are linear in it) and the stretch
    of :func:`~clutchlab.hysteresis.kernels.peek_segment` around ``icoil`` is kept with the stack version,
    last input and airgap it is for.
    """
    fmem = p.fmem
    grid = p.plant_grid
    pu = fmem[FM_PU]
    plen = p.imem[IM_PLEN]
    gaps = _cold(p.cold, p.layout, L_PLANT_GAPS)
    if moving:
        fidx = p.imem[IM_FIDX:IM_FIDX + GAP_TABLES]
        fw = fmem[FM_FW:FM_FW + GAP_TABLES]
        gap_weights(gaps, min(max(gap, gaps[0]), gaps[gaps.shape[0] - 1]), fidx, fw)
        return peek(p.plant_tables, grid, p.plant_stack, p.plant_prefix, plen, pu, icoil, fidx, fw)
    gw = fmem[FM_GW:FM_GW + GAP_TABLES + 1]
    gidx = p.imem[IM_GIDX:IM_GIDX + GAP_TABLES]
    if gap != gw[GAP_TABLES]:
        gap_weights(gaps, min(max(gap, gaps[0]), gaps[gaps.shape[0] - 1]), gidx, gw)
        combine_tables(p.plant_tables, gidx, gw, p.plant_comb)
        gw[GAP_TABLES] = gap
    seg = fmem[FM_SEG:FM_SEG + 9]
    fm = peek_segment(p.plant_comb, grid, p.plant_stack, p.plant_prefix, plen, pu, icoil, gidx, gw, seg)
    seg[6] = p.imem[IM_PVER]
    seg[7] = pu
    seg[8] = gap
    return fm


# ------------------------------------------------------------------ the hooks of the contract
@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _rhs(t, x, u, m, p, dx, g):
    """Right-hand side ``dx`` ([1], Eqs. 8-30, Fig. 15) and switching functions ``g`` in the modes ``m``.

    The one place the model is written (every other hook evaluates it through the core's ``rhs`` hook);
    the intermediates go to ``fmem[FM_AUX:]`` and the point of the evaluation to ``fmem[FM_KEY:]`` (an
    output sample at the end of a step reuses it).
    """
    a = p.actuator[0]
    fmem = p.fmem
    if abs(fmem[FM_KEY] - t) <= 4e-15 * max(1.0, abs(t)) and _same_point(t, x, u, m, fmem):  # (the time first)
        # the point of the last evaluation again (a controller sample at the end of a step): only the
        # current command may have changed since, and only the first current lag depends on it
        for i in range(7):
            dx[i] = fmem[FM_DXM + i]
        for k in range(N_SWITCH):
            g[k] = fmem[FM_GM + k]
        dx[5] = (_command(u, p) - x[5]) * a.inv_tau1
        return
    aux = fmem[FM_AUX:FM_AUX + N_AUX]
    v = p.vehicle[0]
    c = p.coupling
    geo = p.geometry
    arm = m[0]
    cpl = m[1]
    wf = x[0]
    wr = x[1]
    xa = x[3]
    xd = x[4]
    # magnet force of the plant: Preisach output for the next coil current, memory not committed ([1],
    # Eqs. 1-5), interpolated over the calibration airgaps at the airgap d - x (Eq. 12).  At a stop, while the
    # stack stays, the force is one quadratic in the coil current on the stretch where the same branch of
    # Eqs. 2-3 and the same cells hold: kept for the next stages and, while the current keeps its direction
    # (the stretch does not depend on the last input then), for the next steps (_magnet_force builds it)
    grid = p.plant_grid
    icoil = min(max(x[6], grid[0]), grid[grid.shape[0] - 1])
    gap = a.airgap_open - xa
    seg = fmem[FM_SEG:FM_SEG + 9]
    pu = fmem[FM_PU]
    kind = seg[5]
    if arm != ARM_FREE and seg[6] == p.imem[IM_PVER] and seg[8] == gap and seg[0] < icoil < seg[1] and (
            (kind == 1.0 and icoil > pu) or (kind == -1.0 and icoil < pu) or (kind == 0.0 and seg[7] == pu)):
        fm = seg[2] + icoil * (seg[3] + icoil * seg[4])
    else:
        fm = _magnet_force(p, arm == ARM_FREE, gap, icoil)
    fn1 = 0.0
    if arm == ARM_FREE:
        dx[3] = xd
        dx[4] = armature_acceleration(fm, xa, xd, a)
    else:
        dx[3] = 0.0
        dx[4] = 0.0
        if arm == ARM_CONTACT:
            fn1 = max(primary_clamp_force(fm, a), 0.0)
    # current control: two first-order lags in series ([1], Fig. 15)
    dx[5] = (_command(u, p) - x[5]) * a.inv_tau1
    dx[6] = (x[5] - x[6]) * a.inv_tau2
    thr = u[U_THROTTLE] if p.throttle.shape[1] == 0 else interp1(p.throttle[0], p.throttle[1], t)
    a_f, a_r, te, ttrans = bench_loads(wf, wr, thr, u[U_DRUM_FRONT], u[U_DRUM_REAR], v)
    tlock = lock_torque(a_f, a_r, v)
    dw = wf - wr
    s = fmem[FM_SPLIT:FM_SPLIT + 6]
    t1 = 0.0
    t2 = 0.0
    t3 = 0.0
    case = -1.0
    fn2 = 0.0
    t_drag = 0.0
    if cpl == OPEN:
        t_drag = drag_torque_scalar(c.drag_pairs, c.oil_viscosity, dw, c.plate_clearance, c.plate_outer_radius,
                                    c.plate_inner_radius)  # [1], Eq. 25
        t_fric = 0.0
        dx[2] = 0.0
    elif cpl == SLIPPING:
        # kinetic friction in the slip direction of the mode: the slip crossing zero is an event (lock-up or
        # reversal, Fig. 11) located by the core, not a sign change inside the mode (that would make the slip
        # slide along zero until a step happened to end past it; see docs/emtc.md)
        sl = 1.0 if m[2] == POSITIVE else -1.0
        if p.friction_mode == FRICTION_MAP:
            # at the coupling's temperature, or at its heat port's (the input coupling_temperature: a network's
            # thermal mass that the coupling's losses heat, the paper's future work, Sec. 5)
            temp = u[U_TEMP] if p.temperature_source == TEMPERATURE_INPUT else c.temperature_c
            m1 = bilinear(_cold(p.cold, p.layout, L_FMAP_SPEED), _cold(p.cold, p.layout, L_FMAP_TEMP),
                          shaped(_cold(p.cold, p.layout, L_FMAP_MU), (p.n_fmap_speed, p.n_fmap_temp)), abs(dw), temp)
            m2 = m1
            m3 = m1
        elif p.friction_mode == FRICTION_LUGRE:
            # [1], Eqs. 22-23: bristles advanced from their committed value at the step start along the slip
            # from there to this stage (the update _commit makes at the step's end: the last stage's friction is
            # the friction of the committed state)
            tlast = fmem[FM_TLAST]
            zb = lugre_advance_path(fmem[FM_Z], fmem[FM_DWLAST], dw, fmem[FM_DVLAST], t - tlast if tlast == tlast else 0.0,
                                    p.lugre)
            mu = lugre_mu(zb, dw, p.lugre)
            if mu != 0.0:
                sl = mu
            m1 = abs(mu)
            m2 = m1
            m3 = m1
        else:
            m1 = geo[0]
            m2 = geo[1]
            m3 = geo[2]
        _slipping(fn1, sl, geo, m1, m2, m3, s)  # [1], Eqs. 13-15
        t1 = s[0]
        t2 = s[1]
        t3 = s[2]
        t_fric = t1 + t2 + t3  # [1], Eq. 17
        fn2 = _cam_force(t1, t3, geo)  # [1], Eq. 14
        dx[2] = 0.0
    else:
        tl = tlock + v.torsen_stiffness * x[2] + v.torsen_damping * dw  # [1], Eq. 30
        code = _locked(fn1, tl, geo, c.unlock_margin, s)  # [1], Eqs. 18-21
        if code >= 0:
            t1 = s[0]
            t2 = s[1]
            t3 = s[2]
            case = code
        else:  # beyond the margin (only inside a step before the unlock event is located)
            t1 = tl
        t_fric = tl
        fn2 = _cam_force(t1, t3, geo)
        dx[2] = dw
    tc = coupling_torque_scalar(cpl != OPEN, t_drag, t_fric)  # [1], Eq. 26
    aux[AUX_FM] = fm
    aux[AUX_FN1] = fn1
    aux[AUX_T1] = t1
    aux[AUX_T2] = t2
    aux[AUX_T3] = t3
    aux[AUX_TC] = tc
    aux[AUX_TLOCK] = tlock
    aux[AUX_TTRANS] = ttrans
    aux[AUX_CAP] = _locked_capacity(fn1, geo)  # [1], Eq. 21
    aux[AUX_CASE] = case
    aux[AUX_FN2] = fn2
    aux[AUX_TE] = te
    aux[AUX_THR] = thr
    dx[0] = (a_f - tc) * v.inv_inertia_front  # [1], Eq. 27 (rows 1 and 3)
    dx[1] = (tc - a_r) * v.inv_inertia_rear  # [1], Eq. 27 (rows 2 and 4)
    _switching(x, m, a, c.unlock_margin, aux, grid, p.imem[IM_FALLING], g)
    fmem[FM_KEY] = t
    for i in range(N_STATE_KEY):
        fmem[FM_KEY + KEY_X + i] = x[i]
        fmem[FM_DXM + i] = dx[i]
    for i in range(N_MODE_KEY):
        fmem[FM_KEY + KEY_M + i] = m[i]
    for i in range(N_INPUT_KEY):
        fmem[FM_KEY + KEY_U + i] = u[i]
    for k in range(N_SWITCH):
        fmem[FM_GM + k] = g[k]


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _same_point(t, x, u, m, fmem):
    """True if ``aux`` in ``fmem`` comes from an evaluation at ``(t, x, u, m)`` with the memories as they are now.

    The inputs are part of the point: a run changes them only at a restart (which clears the key), but an
    evaluation through the contract (:func:`clutchlab.system.evaluate`: linearisation, trim) may ask for
    the same state with other inputs.

    The time is the same to rounding (4e-15 of it): the core evaluates the last stage of a step that ends on
    a break time at the inputs' left limit ``t1 - 1e-15 max(1, |t1|)`` (:mod:`clutchlab.numerics.core`), and
    the sample and the controller's restart at ``t1`` that follow read that evaluation (one evaluation per
    step less).  The right-hand side is continuous in ``t`` (its only time dependence is the throttle ramp,
    piecewise linear; the torque reference is read by the controller), so the two differ by a rounding error.
    """
    if not abs(fmem[FM_KEY] - t) <= 4e-15 * max(1.0, abs(t)):
        return False
    for i in range(N_STATE_KEY):
        if fmem[FM_KEY + KEY_X + i] != x[i]:
            return False
    for i in range(N_MODE_KEY):
        if fmem[FM_KEY + KEY_M + i] != m[i]:
            return False
    for i in range(N_INPUT_KEY):
        if fmem[FM_KEY + KEY_U + i] != u[i]:
            return False
    return True


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _outputs(t, x, u, m, p, y):
    fmem = p.fmem
    # a sample at the end of a step reuses the step's last evaluation (same point, memories not yet committed)
    aux = fmem[FM_AUX:FM_AUX + N_AUX] if _same_point(t, x, u, m, fmem) else _evaluate(t, x, u, m, p)
    y[0] = x[0] - x[1]
    y[1] = p.actuator[0].airgap_open - x[3]
    y[2] = aux[AUX_FM]
    y[3] = aux[AUX_FN1]
    y[4] = aux[AUX_FN2]
    y[5] = aux[AUX_T1]
    y[6] = aux[AUX_T2]
    y[7] = aux[AUX_T3]
    y[8] = aux[AUX_TC]
    y[9] = aux[AUX_TLOCK]
    y[10] = aux[AUX_TTRANS]
    y[11] = aux[AUX_CAP]
    y[12] = aux[AUX_TE]
    y[13] = aux[AUX_CASE]
    y[14] = _command(u, p)
    y[15] = fmem[FM_TREF]
    y[16] = aux[AUX_THR]
    y[17] = fmem[FM_FEASIBLE]


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _update(t, x, u, m, p, k, log):
    p.fmem[FM_KEY] = np.nan
    r = _commit(t, x, p)  # the memories see the state at the event, before the mode change
    if r < 0:
        return r
    _switch(k, t, x, u, m, p, log)
    _anchor_bristles(t, x, u, m, p)  # the bristles go on from the slip after the event (a lock-up sets it)
    return 0


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _anchor_bristles(t, x, u, m, p):
    """The start of the slip's path along which the stages advance the LuGre bristles ([1], Eq. 23): the slip
    speed and, with LuGre friction, the slip acceleration at ``(t, x)`` with the bristles committed there
    (:func:`~clutchlab.emtc.friction.lugre_advance_path`).  After every commit, event and restart."""
    fmem = p.fmem
    fmem[FM_DWLAST] = x[0] - x[1]
    fmem[FM_DVLAST] = 0.0
    if p.friction_mode == FRICTION_LUGRE and fmem[FM_TLAST] == t:
        fmem[FM_KEY] = np.nan
        _evaluate(t, x, u, m, p)
        fmem[FM_DVLAST] = fmem[FM_DX] - fmem[FM_DX + 1]


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _restart(t, x, u, m, p, log):
    fmem = p.fmem
    imem = p.imem
    changed = False
    first = fmem[FM_TLAST] != fmem[FM_TLAST]
    if first:  # first start: the memories begin here
        fmem[FM_TLAST] = t
    ts = p.sample_time
    k = imem[IM_KNEXT]
    if t >= k * ts - 1e-9 * ts:  # a controller sample is due (break time, or a resumed run that starts on it)
        _controller_outlined(t, x, u, p)   # (one compiled copy: the same command from every caller)
        k += 1
        if k * ts <= t + 1e-9 * ts:   # a run that starts far past the samples so far (a trim at t = 1e12 s, #33):
            k = int(np.floor((t + 1e-9 * ts) / ts))   # to the next sample at once, not one sample at a time
        while k * ts <= t + 1e-9 * ts:
            k += 1
        imem[IM_KNEXT] = k
        changed = True
    # held inputs that jumped (a resumed co-simulation step, or the start) may leave a mode inconsistent (not the
    # coupling's temperature: it moves the kinetic coefficient of its friction map only, which no mode's switching
    # function reads, and a network's heat port changes it at every restart)
    jumped = False
    for q in range(u.shape[0]):
        if q != U_TEMP and u[q] != fmem[FM_ULAST + q]:
            jumped = True
            fmem[FM_ULAST + q] = u[q]
    if jumped:
        fmem[FM_KEY] = np.nan  # the last evaluation was for other inputs
        for _ in range(3):
            _evaluate(t, x, u, m, p)
            gv = fmem[FM_G:FM_G + N_SWITCH]
            kk = -1
            if m[0] == ARM_REST and gv[2] < 0.0:
                kk = 2
            elif m[0] == ARM_CONTACT and gv[3] < 0.0:
                kk = 3
            elif m[1] == LOCKED and gv[5] < 0.0:
                kk = 5
            if kk < 0:
                break
            _switch(kk, t, x, u, m, p, log)
            changed = True
    if first or jumped:
        _anchor_bristles(t, x, u, m, p)
    return changed


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _accept(t, x, u, m, p):
    # (committing the magnet memory at the current coil current leaves the magnet force there unchanged)
    e = p.imem[IM_ERROR]
    if e != 0:
        return e
    r = _commit(t, x, p)
    if r < 0:
        p.imem[IM_ERROR] = r
        return r
    _anchor_bristles(t, x, u, m, p)
    # (the last stage advanced the bristles as the commit did: its derivative is the one at the new point)
    return 0


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _next_break(t, m, p):
    return p.imem[IM_KNEXT] * p.sample_time


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _jacobian(t, x, u, m, p, J):
    return False


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def run_controller(p, t, x, u):
    """Run the controller sample that is due at ``t`` (the last sample of a run, whose break never comes)."""
    p = byref(borrow(p))  # the hooks' own specialisation (compiled once, with the core's)
    k = p.imem[IM_KNEXT]
    if t >= k * p.sample_time - 1e-9 * p.sample_time:
        _controller_outlined(t, x, u, p)
        p.imem[IM_KNEXT] = k + 1


# ---- the model's evaluation at events and its event update, called through their addresses
# (:mod:`clutchlab.numerics.outline`).  Linked, :func:`_evaluate` (the whole model: the Preisach magnet's segment
# lookups of Eqs. 1-5, the ball-cam and the friction elements) was optimised and emitted again in every function of
# the core below a hook that evaluates at a point (outputs, the mode update, a restart), and the update with its
# memory commit in every function of the core that handles an event: counted on ``clutchlab warmup``'s EMTC group,
# the final modules held 4.3 times the code they define (256,000 instructions), 3.3 times (196,000) with these two
# outlined.  The hooks the core calls at every step or controller sample (the stages' right-hand side, ``accept``,
# ``restart``, ``outputs``) stay linked: outlined too (154,000 instructions) they cost the bench's 1 s run 9 %
# of its time, against 2 % for these two (docs/architecture.md).
def params_template() -> EmtcParams:
    """An :class:`EmtcParams` of tiny arrays: the numba type of every bench's (for the signatures of the functions
    called through their addresses, and the types of a driveline's empty EMTC block; built without a compiled
    function; ``tests/numerics/test_outline.py`` checks it against packed benches)."""
    f1, f2, f4, i1 = np.zeros(1), np.zeros((1, 1)), np.zeros((1, 1, 1, 1)), np.zeros(1, np.int64)

    def zeros(cls):
        return cls(*([0.0] * len(cls._fields)))

    def record(dtype):
        return np.zeros(1, dtype=dtype)

    geometry = (0.0,) * len(_default(CouplingGeometry).kernel_data())
    return EmtcParams(
        vehicle=record(VEHICLE_DTYPE), coupling=zeros(CouplingData), actuator=record(ACTUATOR_DTYPE),
        geometry=geometry, lugre=(0.0,) * 6, sample_time=0.0, friction_mode=0, reference_source=0,
        temperature_source=0,
        n_airgaps=0, n_cells=0, n_ctl_cells=0, n_fmap_speed=0, n_fmap_temp=0, n_map_throttle=0, n_map_speed=0,
        layout=(0,) * (2 * N_LAYOUT), throttle=f2, plant_tables=f4, plant_grid=f1, plant_stack=f1.copy(),
        plant_prefix=f2.copy(), plant_comb=f4.copy(), controller_table=f4.copy(), imem=i1, fmem=f1.copy(),
        cold=f1.copy())


@functools.lru_cache(maxsize=1)
def _params_type():
    """numba type of the reference to an :class:`EmtcParams` every hook takes."""
    return ByRef(numba.typeof(params_template()))


def _hook_args(*rest):
    """The types of a hook's arguments: ``(t, x, u, m, p, *rest)`` (:func:`~clutchlab.numerics.outline.hook_args`)."""
    return hook_args(_params_type(), *rest)


_log_type = log_type


_evaluate_outlined = outlined(_evaluate_into, lambda: _hook_args(), types.none, group="emtc")
_update_outlined = outlined(_update, lambda: _hook_args(types.int64, _log_type()), types.int64, group="emtc")


def _controller_args():
    """The types of :func:`_controller`'s arguments ``(t, x, u, p)``: those of a hook without ``m``."""
    t, x, u, _, p = _hook_args()
    return t, x, u, p


# The controller sample, called through its address from every function of the core that restarts (a run's start,
# its breaks, with either integrator) and from run_controller: one compiled copy.  Linked, each caller held its own
# copy, which LLVM optimised with the fast-math flags in that caller's context: two copies could round the command
# differently in its last bit (seen once in CI: a co-simulation stepping over sample instants and one stepping on
# them gave commands 1 ulp apart, tests/fmu/test_cosim.py).  A sample is rare (2 ms): the call costs nothing.
_controller_outlined = outlined(_controller, _controller_args, types.none, group="emtc")


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _update_hook(t, x, u, m, p, k, log):
    """:func:`_update` through its address."""
    return _update_outlined(t, x, u, m, p, k, log)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def coupling_shaft_inertia(j_shaft, j_axle, ratio):
    """Inertia of one side of the coupling at its shaft [kg*m^2]: ``J = J_s + J_w / i^2`` ([1], Eq. 29: ``J_F``
    from the input shaft's ``J_sf`` and the front axle's ``J_wf``, ``J_R`` from ``J_sr`` and ``J_wr``), the axle
    and wheels ``j_axle`` [kg*m^2] reflected through the axle ratio ``ratio`` (``i_f = i_r``, Eq. 28) onto the
    shaft ``j_shaft`` [kg*m^2].  Rigid drive shafts, no gear losses."""
    return j_shaft + j_axle / (ratio * ratio)   # [1], Eq. 29


@numba.njit(cache=True, nogil=True, error_model="numpy")
def free_rolling_speed(v_drum, tyre_radius, axle_ratio):
    """Speed of a coupling shaft whose wheels roll free on their drum [rad/s]: ``omega = v_drum / r_w * i`` (the
    drum bench of [1], Sec. 4: no tyre slip, the axle ratio ``i_f = i_r = i`` of Eq. 28), from the drum's surface
    speed ``v_drum`` [m/s], the tyre radius ``tyre_radius`` [m] and the axle ratio ``axle_ratio`` [-].  How a bench
    run starts (:func:`bench_system`, :func:`emtc_start`)."""
    return v_drum / tyre_radius * axle_ratio


@numba.njit(cache=True, nogil=True, error_model="numpy")
def derive_vehicle(vehicle, ratios):
    """What a run derives from the vehicle's parameters (:data:`DERIVED_VEHICLE`), written into its record
    ``vehicle[0]`` (:data:`VEHICLE_DTYPE`): the gear's ratio from ``ratios`` (``VehicleParameters.gear_ratios``),
    the shaft inertias ``J_F``, ``J_R`` ([1], Eq. 29, :func:`coupling_shaft_inertia`) and the lock torque's
    shares of them, the static axle loads (:func:`~clutchlab.emtc.params.static_axle_load`) and the reciprocals
    every evaluation uses.  Called by the packing and by every run's start (:func:`emtc_start`).

    Returns 0, or :data:`ERR_GEAR` (the gear is not a whole number from 1 to ``len(ratios)``) or
    :data:`ERR_GEOMETRY` (``cg_to_front + cg_to_rear`` is not ``wheelbase`` within 1 mm) with nothing written.
    """
    v = vehicle[0]
    if not (1.0 <= v.gear <= ratios.shape[0] and v.gear == math.floor(v.gear)):
        return ERR_GEAR
    if not abs(v.cg_to_front + v.cg_to_rear - v.wheelbase) <= GEOMETRY_TOLERANCE:
        return ERR_GEOMETRY
    v.gear_ratio = ratios[int(v.gear) - 1]
    jf = coupling_shaft_inertia(v.inertia_input_shaft, v.inertia_front_axle, v.axle_ratio)   # [1], Eq. 29, J_F
    jr = coupling_shaft_inertia(v.inertia_output_shaft, v.inertia_rear_axle, v.axle_ratio)   # [1], Eq. 29, J_R
    v.inertia_front = jf
    v.inertia_rear = jr
    v.axle_load_front = static_axle_load(v.mass, v.cg_to_rear, v.wheelbase)
    v.axle_load_rear = static_axle_load(v.mass, v.cg_to_front, v.wheelbase)
    v.inv_axle_ratio = 1.0 / v.axle_ratio
    v.inv_inertia_front = 1.0 / jf
    v.inv_inertia_rear = 1.0 / jr
    v.lock_share_front = jr / (jf + jr)
    v.lock_share_rear = jf / (jf + jr)
    return 0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _outside(gaps, lo, hi):
    """Whether the airgaps ``[lo, hi]`` [m] leave the calibration airgaps ``gaps`` (one airgap: never)."""
    n = gaps.shape[0]
    return n > 1 and (lo < gaps[0] - 1e-12 or hi > gaps[n - 1] + 1e-12)


# (reference-counted whoever compiles it first: numba compiles a callee with its caller's flags unless it declares
# its own, and it allocates; a driveline's component start, compiled without, failed on an empty cache once it
# was the first to compile it, fifty-seventh session)
@numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=True)
def derive_actuator(actuator, cold, layout, table):
    """What a run derives from the actuator's parameters (:data:`DERIVED_ACTUATOR`), written into its record
    ``actuator[0]`` (:data:`ACTUATOR_DTYPE`): the current lags' rates, and into ``table`` (``(1, N, N, 4)``,
    ``EmtcParams.controller_table``) the controller model's cell coefficients at its one airgap, the engaged
    ``d - sigma`` ([1], Eq. 12), interpolated over its calibration airgaps (Eqs. 2-5 are linear in the table:
    :func:`~clutchlab.hysteresis.kernels.gap_weights`, :func:`~clutchlab.hysteresis.kernels.combine_tables`),
    from the tables packed in ``cold`` (``controller_all_tables``, ``controller_gaps``; ``layout``:
    ``EmtcParams.layout``).  Called by the packing and by every run's start (:func:`emtc_start`).

    Returns 0, or :data:`ERR_AIRGAP` (``airgap_open <= free_travel``) or :data:`ERR_AIRGAP_RANGE` (the
    airgaps from ``airgap_open - free_travel`` to ``airgap_open`` leave the plant's or the controller's
    calibration airgaps) with nothing written.
    """
    a = actuator[0]
    if not a.airgap_open > a.free_travel:
        return ERR_AIRGAP
    lo = a.airgap_open - a.free_travel
    gaps = _cold(cold, layout, L_CTL_GAPS)
    if _outside(_cold(cold, layout, L_PLANT_GAPS), lo, a.airgap_open) or _outside(gaps, lo, a.airgap_open):
        return ERR_AIRGAP_RANGE
    a.inv_tau1 = 1.0 / a.tau1
    a.inv_tau2 = 1.0 / a.tau2
    ng = gaps.shape[0]
    n = table.shape[1]
    idx = np.zeros(GAP_TABLES, dtype=np.int64)
    w = np.zeros(GAP_TABLES)
    gap_weights(gaps, min(max(lo, gaps[0]), gaps[ng - 1]), idx, w)
    combine_tables(shaped(_cold(cold, layout, L_CTL_ALL), (ng, n, n, 4)), idx, w, table)
    return 0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def emtc_start(t, x, u, m, p):
    """What a run derives from its parameters and inputs alone, once before its first restart (the core's
    ``start`` hook): the vehicle's (:func:`derive_vehicle`) and the actuator's (:func:`derive_actuator`) derived
    numbers, and, where the vehicle record's ``start_on_drums`` is set (a co-simulation's system), the shafts' speeds
    of free rolling on the drums, ``omega = v_drum / r_w * i`` (the drum speed inputs ``u``), as :func:`bench_system`
    starts them; elsewhere the run starts from the state it is given (an operating point's).  So a native FMU,
    which runs it again after a host set parameters or the drum speeds' start values, writes the parameters as plain
    copies (:attr:`clutchlab.system.System.decided_at_start`).  Returns 0 or the refusal's negative code
    (:data:`ERROR_MESSAGES`)."""
    e = derive_vehicle(p.vehicle, _cold(p.cold, p.layout, L_GEAR_RATIOS))
    if e != 0:
        return e
    e = derive_actuator(p.actuator, p.cold, p.layout, p.controller_table)
    if e != 0:
        return e
    v = p.vehicle[0]
    if v.start_on_drums != 0.0:
        x[X_OMEGA_F] = free_rolling_speed(u[U_DRUM_FRONT], v.tyre_radius, v.axle_ratio)
        x[X_OMEGA_R] = free_rolling_speed(u[U_DRUM_REAR], v.tyre_radius, v.axle_ratio)
    return 0


#: the words :func:`emtc_start` writes (:attr:`clutchlab.system.System.decided_at_start`)
#: (each record's one element; the whole table; the two shafts' speeds, written where ``start_on_drums`` is set)
DECIDED_AT_START = tuple([(f"params.vehicle.{name}", 0, None) for name in DERIVED_VEHICLE]
                         + [(f"params.actuator.{name}", 0, None) for name in DERIVED_ACTUATOR]
                         + [("params.controller_table", 0, None), ("x", X_OMEGA_F, X_OMEGA_R + 1)])

dispatch.register(EmtcParams, inline_stages=True, rhs=_rhs, outputs=_outputs, update=_update_hook, restart=_restart,
                  accept=_accept, next_break=_next_break, jacobian=_jacobian, start=emtc_start)


# ------------------------------------------------------------------ packing (the only place)
@dataclasses.dataclass(frozen=True)
class BenchOptions:
    """Options of a drum-bench run besides the scenario, the magnet and the vehicle (all optional).

    Parameters
    ----------
    actuator : ActuatorParameters, optional
        Armature, spring and current control (default: :class:`~clutchlab.emtc.bench.ActuatorParameters`).
    coupling : CouplingGeometry, optional
        Friction elements and ball-cam (default: :class:`~clutchlab.emtc.torque.CouplingGeometry`).
    torque_map : TorqueMap, optional
        Reference map of Eq. 31 (default :class:`~clutchlab.emtc.bench.TorqueMap`).
    controller_model : Preisach, optional
        Model used by the open-loop compensation (Fig. 7); default: the plant magnet.
    friction_map : FrictionMap, optional
        Kinetic coefficient ``mu(|slip|, temperature)`` for the three elements.
    lugre : LuGreParameters, optional
        LuGre friction (Eqs. 22-24) in slipping mode instead of the constant kinetic coefficients.
    torque_reference : (times, torques), optional
        Prescribed reference [s], [N*m] instead of the map of Eq. 31.
    coil_drive : {"controller", "current"}
        ``"controller"``: the torque controller sets the coil current command at every sample (Eqs. 6-7,
        31); ``"current"``: the coil is driven at the held input ``coil_current_command`` [A] (a current
        amplifier on a test bench; trimming the coil at a current, a linear model from the command).
    coupling_temperature : {"parameter", "input"}
        Where the friction map's temperature comes from: ``"parameter"``, the scenario's ``temperature_c``;
        ``"input"``, the held input ``coupling_temperature`` [degC] (a heat port: a network's thermal mass that
        the coupling's losses heat, or a host's thermal model; [2] Sec. 5).  Without a friction map the
        temperature is read by nothing.
    memory_capacity : int
        Entries of each hysteresis memory stack (a run whose memory fills up is repeated with four
        times the capacity by :func:`simulate` and :func:`~clutchlab.emtc.simulate_bench`).
    """

    actuator: object = None
    coupling: object = None
    torque_map: object = None
    controller_model: object = None
    friction_map: object = None
    lugre: object = None
    torque_reference: object = None
    coil_drive: str = "controller"
    memory_capacity: int = 64
    coupling_temperature: str = "parameter"

    def __post_init__(self):
        if self.coil_drive not in ("controller", "current"):
            raise ParameterError(f"coil_drive = {self.coil_drive!r}: expected 'controller' or 'current'")
        if self.coupling_temperature not in TEMPERATURE_SOURCES:
            raise ParameterError(f"coupling_temperature = {self.coupling_temperature!r}: expected "
                                 f"{' or '.join(repr(q) for q in TEMPERATURE_SOURCES)}")
        if self.friction_map is not None and self.lugre is not None:
            raise ParameterError("give either friction_map or lugre, not both")
        if not (isinstance(self.memory_capacity, (int, np.integer)) and self.memory_capacity >= 4):
            raise ParameterError(f"memory_capacity = {self.memory_capacity!r}: expected a whole number >= 4")


def _f(a):
    return np.ascontiguousarray(a, dtype=np.float64)


class _Cold:
    """Builds ``EmtcParams.cold`` and its ``layout``: tables appended one after the other (C order)."""

    def __init__(self):
        self.parts = []
        self.layout = [0] * (2 * N_LAYOUT)
        self.size = 0

    def add(self, k, array):
        a = _f(array).ravel()
        self.layout[2 * k] = self.size
        self.layout[2 * k + 1] = a.size
        self.parts.append(a)
        self.size += a.size

    def array(self):
        return np.concatenate(self.parts) if self.parts else np.zeros(0)


def pack_parameters(magnet, scenario=None, vehicle=None, options: BenchOptions | None = None, *,
                    cosimulation: bool = False, n_samples: int = 0) -> EmtcParams:
    """Pack the drum-bench model's parameters and fresh per-run memories into :class:`EmtcParams`.

    The packed tables of the last few distinct requests are remembered (keyed on the magnet objects and
    the frozen parameter sets; a request with an unhashable part, e.g. a torque map, is packed anew):
    repeated runs of one bench copy only the per-run memories (packing took about 65 µs of a 1.4 ms run
    of 1 s).

    Parameters
    ----------
    magnet : clutchlab.hysteresis.Preisach
        Plant magnet force [N] vs coil current [A] (and airgap [m]).
    scenario : BenchScenario, optional
        Gear, drum loads, throttle ramp, temperature, sample time (default: the defaults).
    vehicle : VehicleParameters, optional
        Default: Table 1 of [1] and representative values.
    options : BenchOptions, optional
        Actuator, coupling, torque map, controller model, friction, reference, memory capacity.
    cosimulation : bool
        Throttle and torque request from the held inputs instead of the scenario's ramp and map
        (co-simulation).
    n_samples : int
        Rows of the per-sample controller log (0: none; see :func:`controller_log`).

    Returns
    -------
    EmtcParams
    """
    try:
        key = (id(magnet), scenario, vehicle, options, bool(cosimulation), int(n_samples))
        hash(key)
    except TypeError:
        key = None
    packed = _PACKED.get(key) if key is not None else None
    if packed is None:
        packed = _pack(magnet, scenario, vehicle, options, cosimulation, n_samples)
        if key is not None:
            if len(_PACKED) >= 8:
                _PACKED.pop(next(iter(_PACKED)))
            _PACKED[key] = packed  # (holds magnet and options: their ids stay theirs while remembered)
    return _fresh_memories(packed[-1])


#: (magnet id, scenario, vehicle, options, cosimulation, n_samples) -> (magnet, options, packed parameters)
_PACKED: dict = {}


def _fresh_memories(params: EmtcParams) -> EmtcParams:
    """``params`` with its own copy of every array a run writes (memories, stacks, the controller log, what its
    start derives)."""
    return params._replace(imem=params.imem.copy(), fmem=params.fmem.copy(), plant_stack=params.plant_stack.copy(),
                           plant_prefix=params.plant_prefix.copy(), plant_comb=params.plant_comb.copy(),
                           cold=params.cold.copy(), vehicle=params.vehicle.copy(), actuator=params.actuator.copy(),
                           controller_table=params.controller_table.copy())


def _pack(magnet, scenario, vehicle, options, cosimulation, n_samples):
    """:func:`pack_parameters` without the memory of earlier requests: ``(magnet, options, params)``."""

    given_options = options
    scenario = scenario or _default(BenchScenario)
    vehicle = vehicle or _default(VehicleParameters)
    options = options or BenchOptions()
    actuator = options.actuator or _default(ActuatorParameters)
    coupling = options.coupling or _default(CouplingGeometry)
    torque_map = options.torque_map or _default(TorqueMap)
    ctl = options.controller_model or magnet
    lo_gap = actuator.airgap_open - actuator.free_travel
    for name, model in (("magnet", magnet), ("controller_model", ctl)):
        if start_checks_deferred():
            break   # (a check across parameters the start makes again: its own refusal, ERR_AIRGAP_RANGE)
        if _outside(_f(model.airgaps), float(lo_gap), float(actuator.airgap_open)):   # (the start's own test)
            raise ParameterError(
                f"{name}: airgap range [{lo_gap:g}, {actuator.airgap_open:g}] m of the actuator is outside the "
                f"calibration airgaps [{model.airgaps[0]:g}, {model.airgaps[-1]:g}] m")
    ic = vehicle.rear_final_drive
    ratios = np.asarray(vehicle.gear_ratios, dtype=float)
    geo = [float(g) for g in coupling.kernel_data()]
    lugre = (0.0,) * 6
    fmap = (np.array([0.0, 1.0]), np.array([0.0, 1.0]), np.ones((2, 2)))
    fmode = FRICTION_CONSTANT
    if options.friction_map is not None:
        fm = options.friction_map
        fmap, fmode = (fm.slip_speed, fm.temperature_c, fm.mu), FRICTION_MAP
        # as for LuGre below: the locked capacity (Eq. 21) must cover the map's kinetic friction at zero slip, else
        # a slip that reaches zero can neither lock (its torque exceeds the capacity) nor reverse (the kinetic torque
        # then drives it back): the bench chattered and left the slip running the wrong way, the driveline missed
        # the crossing (issue #30).  Each element's static coefficient is at least the map's largest at zero slip
        geo[3:6] = [max(g, float(np.max(fm.mu[0]))) for g in geo[3:6]]
    elif options.lugre is not None:
        lugre = tuple(float(q) for q in options.lugre.kernel_data())
        # the locked capacity must use LuGre's own breakaway coefficient, else the friction just after
        # an unlock could exceed the lock capacity and the slip would reverse at once (chattering)
        geo[3:6] = [float(options.lugre.mu_p)] * 3
        fmode = FRICTION_LUGRE
    if options.torque_reference is not None:
        tr = np.asarray(options.torque_reference, float)
        if (tr.ndim != 2 or tr.shape[0] != 2 or tr.shape[1] < 2 or not np.all(np.isfinite(tr))
                or np.any(np.diff(tr[0]) <= 0)):
            raise ParameterError("torque_reference: expected (times, torques) with strictly increasing finite times")
        ref, ref_src = tr, REFERENCE_TABLE
    else:
        ref, ref_src = np.zeros((2, 1)), REFERENCE_MAP
    if cosimulation:
        throttle, ref_src = np.zeros((2, 0)), REFERENCE_INPUT
    if options.coil_drive == "current":
        ref_src = REFERENCE_CURRENT
    if not cosimulation:
        s = scenario
        throttle = np.array([[0.0, s.ramp_start, max(s.ramp_end, s.ramp_start + 1e-9), max(s.duration, s.ramp_end) + 1.0],
                             [s.throttle_start, s.throttle_start, s.throttle_end, s.throttle_end]])
    cap = int(options.memory_capacity)
    n = magnet.kernel_tables.shape[1]
    nc = ctl.kernel_tables.shape[1]
    cold = _Cold()
    cold.add(L_PLANT_TABLES, np.zeros(0))  # a field of its own (every accepted step reads it)
    cold.add(L_PLANT_GAPS, magnet.airgaps)
    cold.add(L_CTL_TABLES, np.zeros(0))  # a field of its own (derived from the two below by the start)
    cold.add(L_CTL_ALL, ctl.kernel_tables)
    cold.add(L_CTL_GAPS, ctl.airgaps)
    cold.add(L_GEAR_RATIOS, ratios)
    cold.add(L_CTL_GRID, ctl.grid)
    cold.add(L_CTL_STACK, np.zeros(cap))
    cold.add(L_CTL_PREFIX, np.zeros((1, cap // 2 + 2)))
    cold.add(L_MAP_THROTTLE, torque_map.throttle)
    cold.add(L_MAP_SPEED, torque_map.speed)
    cold.add(L_MAP_TORQUE, torque_map.torque)
    cold.add(L_REF_TIME, ref[0])
    cold.add(L_REF_VALUE, ref[1])
    cold.add(L_FMAP_SPEED, fmap[0])
    cold.add(L_FMAP_TEMP, fmap[1])
    cold.add(L_FMAP_MU, fmap[2])
    cold.add(L_LOG, np.zeros(4 * int(n_samples)))
    imem = np.zeros(N_IMEM, dtype=np.int64)
    fmem = np.zeros(N_FMEM)
    fmem[FM_CW] = 1.0  # (imem[IM_CIDX:] = 0: the controller's one table)
    fmem[FM_PU] = magnet.grid[0]
    fmem[FM_CU] = ctl.grid[0]
    fmem[FM_TLAST] = np.nan
    fmem[FM_GW + GAP_TABLES] = np.nan
    fmem[FM_ULAST:FM_ULAST + len(INPUTS)] = np.nan
    fmem[FM_KEY] = np.nan
    fmem[FM_SEG:FM_SEG + 9] = np.nan
    fmem[FM_CSEG:FM_CSEG + 8] = np.nan
    if not 1 <= scenario.gear <= len(vehicle.gear_ratios):
        raise ParameterError(f"BenchScenario: gear = {scenario.gear}: the vehicle has gears 1 to "
                             f"{len(vehicle.gear_ratios)} (VehicleParameters.gear_ratios)")
    given = dict(axle_ratio=ic, gear=scenario.gear, drum_load_front=scenario.drum_load_front,
                 drum_load_rear=scenario.drum_load_rear)
    veh = np.zeros(1, dtype=VEHICLE_DTYPE)
    for name in VEHICLE_PARAMETERS:
        veh[0][name] = float(given[name] if name in given else getattr(vehicle, name))
    cpl = CouplingData(
        drag_pairs=float(vehicle.drag_pairs), oil_viscosity=float(vehicle.oil_viscosity),
        plate_clearance=float(vehicle.plate_clearance), plate_outer_radius=float(vehicle.plate_outer_radius),
        plate_inner_radius=float(vehicle.plate_inner_radius), unlock_margin=float(UNLOCK_MARGIN),
        temperature_c=float(scenario.temperature_c))
    act = np.zeros(1, dtype=ACTUATOR_DTYPE)
    for name in ACTUATOR_PARAMETERS:
        act[0][name] = float(getattr(actuator, name))
    cold_array = cold.array()
    layout = tuple(int(q) for q in cold.layout)
    table = np.zeros((1, nc, nc, 4))
    # what the start derives, with its functions (the parameters were checked above, with their values, unless the
    # start is to refuse them: start_checked_later)
    refused = [e for e in (derive_vehicle(veh, ratios), derive_actuator(act, cold_array, layout, table)) if e]
    if refused and not start_checks_deferred():
        raise ParameterError(f"EMTC bench: {ERROR_MESSAGES[refused[0]]}")
    return magnet, given_options, EmtcParams(
        vehicle=veh, coupling=cpl, actuator=act, geometry=tuple(geo), lugre=tuple(lugre),
        sample_time=float(scenario.sample_time), friction_mode=int(fmode), reference_source=int(ref_src),
        temperature_source=int(TEMPERATURE_SOURCES.index(options.coupling_temperature)),
        n_airgaps=int(magnet.n_airgaps), n_cells=int(n), n_ctl_cells=int(nc),
        n_fmap_speed=int(np.shape(fmap[2])[0]), n_fmap_temp=int(np.shape(fmap[2])[1]),
        n_map_throttle=int(torque_map.torque.shape[0]), n_map_speed=int(torque_map.torque.shape[1]),
        layout=layout, throttle=_f(throttle), plant_tables=_f(magnet.kernel_tables),
        plant_grid=_f(magnet.grid),
        plant_stack=np.zeros(cap), plant_prefix=np.zeros((magnet.n_airgaps, cap // 2 + 2)),
        plant_comb=np.zeros((1, n, n, 4)), controller_table=table, imem=imem, fmem=fmem, cold=cold_array)


def controller_log(params: EmtcParams) -> np.ndarray:
    """The per-sample controller log of a run: ``(samples, 4)`` command [A], reference [N*m], throttle [-], feasible.

    ``params`` is the :class:`EmtcParams` of the run (``system.params``), packed with ``n_samples`` rows.
    """
    o, size = params.layout[2 * L_LOG], params.layout[2 * L_LOG + 1]
    return params.cold[o:o + size].reshape(-1, 4).copy()


def _element_name(code: int, element: int) -> str:
    return ELEMENTS[element] if 0 <= element < len(ELEMENTS) else ""


def bench_system(magnet=None, scenario=None, vehicle=None, options: BenchOptions | None = None, *,
                 cosimulation: bool = False, n_samples: int = 0, start_on_drums: bool = False) -> System:
    """The drum-bench model as a :class:`~clutchlab.system.System` (registered as ``"emtc_bench"``).

    Parameters
    ----------
    magnet : clutchlab.hysteresis.Preisach, optional
        Plant magnet (default: :func:`~clutchlab.emtc.magnet.bundled_magnet`).
    scenario, vehicle, options
        As :func:`pack_parameters`.
    cosimulation : bool
        Throttle, drum speeds and torque request from the held inputs (see :func:`pack_parameters`).
    n_samples : int
        Rows of the per-sample controller log (:func:`controller_log`).
    start_on_drums : bool
        The run's start puts the shafts on the drums at the drum speed inputs it holds then (:func:`emtc_start`:
        a co-simulation, whose host sets them and the vehicle); else the run starts from ``x0`` as given (the
        same shaft speeds unless a caller gives another state, as an operating point does).

    Returns
    -------
    System
        Initial state: shaft speeds of free rolling on the drums, armature at rest, coil current at the
        lowest grid current; modes ``rest``, ``open``, ``positive``; first trial step ``min(0.1 ms,
        sample_time)`` (a resumed run and an uninterrupted one take the same steps).
    """
    if magnet is None:
        from .magnet import bundled_magnet

        magnet = bundled_magnet()
    scenario = scenario or _default(BenchScenario)
    vehicle = vehicle or _default(VehicleParameters)
    params = pack_parameters(magnet, scenario, vehicle, options, cosimulation=cosimulation, n_samples=n_samples)
    params.vehicle[0]["start_on_drums"] = float(bool(start_on_drums))   # (a copy of its own: _fresh_memories)
    vf = scenario.drum_speed
    vr = scenario.drum_speed - scenario.speed_difference
    ic = vehicle.rear_final_drive
    # (free rolling on the drums: emtc_start writes the shafts' speeds again from the drum speeds in u0)
    x0 = np.array([free_rolling_speed(vf, vehicle.tyre_radius, ic), free_rolling_speed(vr, vehicle.tyre_radius, ic),
                   0.0, 0.0, 0.0,
                   magnet.grid[0], magnet.grid[0]])
    u0 = np.array([0.0, scenario.throttle_start, vf, vr, magnet.grid[0], scenario.temperature_c])
    first_step = min(1e-4, scenario.sample_time)
    # the coil current command within the magnet's calibrated currents (the drive's current limit)
    current_range = (float(magnet.grid[0]), float(magnet.grid[-1]))
    template = _TEMPLATES.get((first_step, current_range))
    if template is None:
        template = System("emtc_bench", params, STATES, OUTPUTS, x0, np.array([ARM_REST, OPEN, POSITIVE], dtype=np.int64),
                          ATOL.copy(), switching=SWITCHING, events=EVENTS, mode_names=MODE_NAMES,
                          mode_values=MODE_VALUES, inputs=INPUTS, u0=u0, method="dopri", rtol=1e-6,
                          first_step=first_step, event_tol=1e-12, element_name=_element_name,
                          error_messages=dict(ERROR_MESSAGES), limits={"coil_current_command": current_range,
                                                               "coupling_temperature": TEMPERATURE_RANGE},
                          decided_at_start=DECIDED_AT_START)
        if len(_TEMPLATES) < 64:
            _TEMPLATES[(first_step, current_range)] = template
    # the hooks called through their addresses, compiled (or loaded) here on the calling thread, not at a batch
    # worker's first call
    prepare(groups=("emtc",), ungrouped=False)
    # every run builds a system: the checked, constant parts are shared, the parameters and start are its own
    return template.variant(params=params, x0=x0, u0=u0)


#: (first trial step, coil current range) -> a checked System of the model (names, units, tolerances), the base of :func:`bench_system`
_TEMPLATES: dict = {}


register_model("emtc_bench", bench_system)


def memory_full(system: System) -> bool:
    """True if a run of ``system`` (an ``emtc_bench`` system) stopped because a hysteresis memory was full.

    ``system`` is the :class:`~clutchlab.system.System` whose run raised the model error; a run repeated
    with a larger ``BenchOptions.memory_capacity`` takes exactly the same steps.
    """
    return int(system.params.imem[IM_ERROR]) in (ERR_PLANT_MEMORY, ERR_CONTROLLER_MEMORY)


def run(build, t_end: float, **kwargs):
    """Simulate ``build(capacity)`` with :func:`clutchlab.system.simulate`; a full memory repeats the run larger.

    ``build(memory_capacity) -> System`` makes a fresh system; returns ``(system, result)``.  Without an
    ``atol``, a given ``rtol`` brings its :func:`absolute_tolerance`.
    """
    from ..system import check_rtol, simulate as core_simulate

    if kwargs.get("atol") is None and kwargs.get("rtol") is not None:
        check_rtol(kwargs["rtol"])
        kwargs["atol"] = absolute_tolerance(kwargs["rtol"])  # the error control follows rtol below its default
    cap = None
    while True:
        system = build(cap)
        try:
            return system, core_simulate(system, t_end, **kwargs)
        except SimulationError:
            if not memory_full(system):
                raise
            cap = 4 * system.params.plant_stack.shape[0]


def simulate(scenario=None, t_end: float | None = None, *, magnet=None, vehicle=None,
             options: BenchOptions | None = None, rtol: float | None = None, atol=None, max_step: float | None = None,
             output_step: float | None = None, fixed_step: float | None = None):
    """Simulate the vehicle with the EMTC on the drum bench ([1], Eqs. 8-31); the uniform entry point.

    Parameters
    ----------
    scenario : BenchScenario, optional
        Drum speeds, throttle ramp, gear, sample time, duration (default: the defaults).
    t_end : float, optional
        End time [s] (default: ``scenario.duration``).
    magnet : clutchlab.hysteresis.Preisach, optional
        Plant magnet (default: the model identified from the bundled synthetic FORC records).
    vehicle : VehicleParameters, optional
        Default: Table 1 of [1] and representative values.
    options : BenchOptions, optional
        Actuator, coupling, torque map, controller model, friction, reference.
    rtol : float, optional
        Relative tolerance (default 1e-6).
    atol : float or array_like, optional
        Absolute tolerance per state (default: :func:`absolute_tolerance` of ``rtol``, scaled to each
        state and shrinking with ``rtol`` below 1e-6).
    max_step : float, optional
        Largest step [s] (default: none besides the controller samples).
    output_step : float, optional
        Sample interval of the result [s] (default: ``scenario.sample_time``, the controller samples).
    fixed_step : float, optional
        Fixed-step (real-time, HIL frame) mode with this step [s] (:func:`clutchlab.system.simulate`); None
        (default): step-size control.

    Returns
    -------
    clutchlab.SimulationResult
        States, outputs (:data:`OUTPUTS`), modes and named events (:data:`EVENTS`).
    """
    scenario = scenario or _default(BenchScenario)
    if options is not None and not isinstance(options, BenchOptions):
        raise ParameterError(f"options = {options!r}: expected a BenchOptions")
    t_end = scenario.duration if t_end is None else t_end
    output_step = scenario.sample_time if output_step is None else output_step
    if magnet is None:
        from .magnet import bundled_magnet

        magnet = bundled_magnet()

    def build(cap):
        opts = options or BenchOptions()
        if cap is not None:
            opts = dataclasses.replace(opts, memory_capacity=cap)
        return bench_system(magnet, scenario, vehicle, opts)

    return run(build, t_end, rtol=rtol, atol=atol, max_step=max_step, output_step=output_step,
               fixed_step=fixed_step)[1]
