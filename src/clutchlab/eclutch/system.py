"""The E-clutch dynamics as a system of the contract (:mod:`clutchlab.system`), implemented once.

Actuator ([1] Sec. 2.1, Fig. 5a) plus clutch axial Model 0-4 ([1] Figs. 5b,
10-11) with stick-slip friction: the parameters packed once into
:class:`EClutchParams` (:meth:`Assembly.params`), the compiled hooks of
:mod:`clutchlab.numerics.dispatch` registered for that class, and the
:class:`~clutchlab.system.System` factory :meth:`Assembly.system`
(registered as model ``"eclutch"``).  The integrator is the core's Rodas3
(:func:`clutchlab.numerics.core.advance_rodas`) with the diagonal mass
matrix of the massless network nodes (index-1 algebraic rows).  The
equations are the scalar compiled functions of
:mod:`clutchlab.eclutch.actuator`, :mod:`clutchlab.eclutch.network`,
:mod:`clutchlab.eclutch.friction` and :mod:`clutchlab.eclutch.models`; the
hooks here only assemble them and run the friction state machine.

State vector (``nz = 2 + n_q`` generalised coordinates: master piston,
CSC/bearing, then the network's free node coordinates)::

    x[0:nz]        positions z [m]
    x[nz:2nz]      velocities v [m/s]
    x[2nz + 0..4]  p_m [Pa], Q [m^3/s], p_s [Pa], i [A], controller integral action V_I [V]
    x[2nz + 5..7]  input work [J], dissipated energy [J], friction dissipation [J]

Mass-matrix rows are 1 except the position rows of massless network nodes
(0: algebraic force balance).  Modes: the friction mode per coordinate (the
Modelica Standard Library's friction state machine [2]): ``free`` (no Coulomb
friction), ``slip_forward``, ``stuck``, ``slip_backward``; then the active row
of the input table (``input_segment``, switched at each table corner).  When the bearing
motion is prescribed (:class:`~clutchlab.eclutch.dynamics.ClutchDynamics`),
the actuator is not simulated: the bearing position follows the input table
(its slope is integrated exactly and reset at every table corner) and the
actuator states stay at rest.

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, Trans. FAMENA
   48 (2024) 21-35, doi:10.21278/TOF.483057923
.. [2] M. Otter, H. Elmqvist, S. E. Mattsson, "Hybrid modeling in Modelica
   based on the synchronous data flow principle", CACSD 1999.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numba.core import types

from ..curves import curve_inverse_one
from ..errors import ParameterError
from ..numerics import dispatch
from ..numerics.core import RESTART, record
from ..numerics.interp import bracket
from ..numerics.layout import indices, slots
from ..numerics.outline import outlined, prepare
from ..system import System, start_checks_deferred, variables
from .actuator import (ActuatorParameters, cavitating_compliance, chamber_compliance, chamber_pressure_rate,
                       controller_integral_rate, controller_voltage, current_rate, drive_voltage, drive_voltage_slopes,
                       line_flow_rate, line_inertance, line_resistance, piston_area, reflected_mass, spindle_force,
                       spindle_ratio, stop_contact, stop_contact_slopes, vent_opening, vent_opening_slope)
from .friction import FrictionElement, kinetic_level, slip_force, static_margin
from .models import ClutchModel, torque_of_clamp_force
from .network import (GROUND, Lever, _static_path, _zeroing_residual, _zeroing_root, element_force,
                      element_force_segment, element_forces, solve_static)

# the compiled hooks (rhs, outputs, update, restart, accept, next_break, jacobian, time_derivative) and their
# EClutchParams are the kernel's internals, registered with numerics.dispatch below: not API (#33)
__all__ = ["Assembly", "EVENTS", "MODE_VALUES", "VOLTAGE", "POSITION", "PRESCRIBED"]

#: the actuator parameter vector (EClutchParams.par), in order: the fields of
#: :class:`~clutchlab.eclutch.actuator.ActuatorParameters` the hooks read (:func:`_actuator_vector` packs them;
#: ``snifting_edge`` is the port plus its width, ``cavitation_sharpness`` the fixed 1e3, the reference limits the
#: slave's travel limits)
ACTUATOR_VECTOR = (
    "master_area", "slave_area", "master_equivalent_mass", "slave_mass", "master_compliance", "slave_compliance",
    "line_inertance", "line_resistance", "snifting_conductance", "snifting_edge", "snifting_width",
    "vapour_pressure", "cavitation_sharpness", "resistance", "inductance", "torque_constant", "supply_voltage",
    "current_limit", "current_limit_gain", "spindle_ratio", "csc_preload", "csc_spring_rate", "slave_min",
    "slave_max", "master_stroke", "stop_stiffness", "stop_damping", "kp", "ki", "kd", "anti_windup",
    "reference_min", "reference_max",
    # the fields the start derives the compliances, the line's inertance and resistance and the snifting edge
    # from (:func:`derive_actuator`)
    "master_volume", "slave_volume", "bulk_modulus", "hose_compliance", "fluid_density", "fluid_viscosity",
    "line_length", "line_diameter", "snifting_port", "lead", "master_mass", "rotor_inertia", "master_diameter",
    "load_friction")
(P_VMC, P_VSL, P_BULK, P_HOSE, P_RHO, P_VISC, P_LLEN, P_DLINE, P_XPORT, P_LEAD, P_MMASS, P_JROT, P_DMC,
 P_LOADF) = indices(
    ACTUATOR_VECTOR, "master_volume", "slave_volume", "bulk_modulus", "hose_compliance", "fluid_density",
    "fluid_viscosity", "line_length", "line_diameter", "snifting_port", "lead", "master_mass", "rotor_inertia",
    "master_diameter", "load_friction")
#: the words the start derives (:func:`eclutch_start`; :attr:`clutchlab.system.System.decided_at_start`): of
#: ``par``, the master piston's area, the equivalent mass, the compliances, the line's inertance and resistance,
#: the snifting edge and the spindle ratio (:func:`derive_actuator`); of ``coord``, the master's mass
#: (``coord[CO_MASS, 0]``) and its seal's friction per pressure (``coord[CO_MU_PRESSURE, 0]``, the spindle's load
#: friction times the master area)
DERIVED_PAR = ("master_area", "master_equivalent_mass", "master_compliance", "slave_compliance", "line_inertance",
               "line_resistance", "snifting_edge", "spindle_ratio")
(P_AMC, P_ASL, P_MMC, P_MSL, P_CM, P_CS, P_LH, P_RH, P_GV, P_XSN, P_WSN, P_PCAV, P_CAVF, P_R, P_L, P_KT, P_VSUP,
 P_IMAX, P_KIL, P_NS, P_FPRE, P_KPRE, P_UMIN, P_UMAX, P_XMAX, P_KSTOP, P_CSTOP, P_KP, P_KI, P_KD, P_KAW, P_REFMIN,
 P_REFMAX) = indices(
    ACTUATOR_VECTOR, "master_area", "slave_area", "master_equivalent_mass", "slave_mass", "master_compliance",
    "slave_compliance", "line_inertance", "line_resistance", "snifting_conductance", "snifting_edge",
    "snifting_width", "vapour_pressure", "cavitation_sharpness", "resistance", "inductance", "torque_constant",
    "supply_voltage", "current_limit", "current_limit_gain", "spindle_ratio", "csc_preload", "csc_spring_rate",
    "slave_min", "slave_max", "master_stroke", "stop_stiffness", "stop_damping", "kp", "ki", "kd", "anti_windup",
    "reference_min", "reference_max")
N_PAR = len(ACTUATOR_VECTOR)

#: input modes: motor voltage (held between table rows), bearing reference (position control), prescribed bearing
INPUT_MODES = ("voltage", "position", "prescribed")
VOLTAGE, POSITION, PRESCRIBED = indices(INPUT_MODES, "voltage", "position", "prescribed")
#: the outputs of every assembly, in order: these, then the input of its input mode (:data:`INPUT_OUTPUTS`), the
#: force of each network element, the friction force of each friction output (:meth:`Assembly.output_variables`)
OUTPUTS = (("motor_voltage", "V", "voltage the drive applies (after saturation and current limit)"),
           ("bearing_force", "N", "bearing force from the CSC pressure, p A_sl"),
           ("bearing_force_clutch", "N", "force the clutch exerts on the release bearing"),
           ("normal_force", "N", "clamp force on the friction plate F_n"),
           ("torque", "Nm", "transmissible clutch torque 2 F_n r_eff mu"),
           ("motor_speed", "rpm", "motor speed"))
Y_VOLTAGE, Y_BEARING_FORCE, Y_BEARING_FORCE_CLUTCH, Y_NORMAL_FORCE, Y_TORQUE, Y_MOTOR_SPEED = indices(
    OUTPUTS, "motor_voltage", "bearing_force", "bearing_force_clutch", "normal_force", "torque", "motor_speed")
#: the output after :data:`OUTPUTS`: the input, by input mode (:data:`INPUT_MODES`)
INPUT_OUTPUTS = {"voltage": ("voltage_command", "V", "motor voltage commanded (input)"),
                 "position": ("reference", "m", "bearing position reference (input)"),
                 "prescribed": ("prescribed_position", "m", "prescribed bearing position (input)")}
#: the input's output and the first element force
Y_INPUT, Y_ELEMENTS = slots(("named", len(OUTPUTS)), ("input", 1), ("elements", 0)).of("input", "elements")
#: friction modes of a coordinate
MODE_VALUES = ("free", "slip_forward", "stuck", "slip_backward")
FREE, SLIP_FORWARD, STUCK, SLIP_BACKWARD = indices(MODE_VALUES, "free", "slip_forward", "stuck", "slip_backward")
#: event names by code (what the hooks record)
EVENTS = ("stick", "breakaway", "slip_reversal", "contact_close", "contact_open", "stop_hit", "stop_leave",
          "cavitation_start", "cavitation_end", "friction_free", "friction_engage")
(EV_STICK, EV_BREAKAWAY, EV_REVERSAL, EV_CONTACT_CLOSE, EV_CONTACT_OPEN, EV_STOP_HIT, EV_STOP_LEAVE,
 EV_CAVITATION_START, EV_CAVITATION_END) = indices(
    EVENTS, "stick", "breakaway", "slip_reversal", "contact_close", "contact_open", "stop_hit", "stop_leave",
    "cavitation_start", "cavitation_end")
#: a friction coordinate whose kinetic level F_c fell to exactly zero (free), or left zero (engages)
EV_FREE, EV_ENGAGE = indices(EVENTS, "friction_free", "friction_engage")
#: the four end stops and the two chambers (elements of stop and cavitation events)
STOPS = ("master_rest_stop", "master_stroke_end", "csc_engaged_stop", "csc_travel_end")
CHAMBERS = ("master_chamber", "csc_chamber")
#: switching functions after the friction coordinates and the network elements: end stops (4), cavitation (2),
#: current limit (1), snifting-port edges (2) -- the last three are kinks located so no step straddles them
OTHER_SWITCHING = STOPS + ("master_cavitation", "csc_cavitation", "current_limit", "snifting_port_closed",
                           "snifting_port_open")
N_OTHER = len(OTHER_SWITCHING)
#: a massless node closer than this to its equilibrium [m] is not moved before the outputs are read (_equilibrate)
EQUILIBRIUM_TOL = 1e-10
#: auxiliary values of the right-hand side, then the friction force of every coordinate
AUX = ("drive_voltage", "bearing_force", "reference", "bearing_position")
AUX_VDRIVE, AUX_FB, AUX_REF, AUX_UB = indices(AUX, "drive_voltage", "bearing_force", "reference", "bearing_position")
N_AUX = len(AUX)


# rows of the packed per-coordinate, per-element and scratch arrays of EClutchParams
COORD_ROWS = ("mass", "coulomb", "mu_normal", "mu_pressure", "static_ratio", "viscous")  # coord [float]
CO_MASS, CO_COULOMB, CO_MU_NORMAL, CO_MU_PRESSURE, CO_STATIC_RATIO, CO_VISCOUS = indices(
    COORD_ROWS, "mass", "coulomb", "mu_normal", "mu_pressure", "static_ratio", "viscous")
#: coord_int: Coulomb friction on, pressing element, chamber
COORD_INT_ROWS = ("friction", "normal", "pressure")
CI_FRICTION, CI_NORMAL, CI_PRESSURE = indices(COORD_INT_ROWS, "friction", "normal", "pressure")
NET_ROWS = ("pre_deflection", "input_gain", "stiffness_scale")  # net [float]
NE_D0, NE_GB, NE_SCALE = indices(NET_ROWS, "pre_deflection", "input_gain", "stiffness_scale")
#: net_int: curve offsets, kind, extrapolation, contact (unilateral)
NET_INT_ROWS = ("offsets", "kinds", "extrapolations", "unilateral")
NI_OFFSETS, NI_KINDS, NI_EXTRAPS, NI_UNILATERAL = indices(
    NET_INT_ROWS, "offsets", "kinds", "extrapolations", "unilateral")
#: work rows; "stiffness": element stiffnesses (rhs, jacobian); "key": the point (t, x, m) of the last rhs
#: evaluation; "segment": each element curve's segment at the last look-up (a search hint; integers as floats)
WORK_ROWS = ("force", "free", "coordinate_force", "aux", "derivative", "switching", "state", "stiffness", "key",
             "segment")
W_F, W_FREE, W_FZ, W_AUX, W_DX, W_G, W_X, W_K, W_KEY, W_SEG = indices(
    WORK_ROWS, "force", "free", "coordinate_force", "aux", "derivative", "switching", "state", "stiffness", "key",
    "segment")
N_WORK = len(WORK_ROWS)


#: absolute tolerance of the position controller's integral action ``K_i int(e) dt`` [V] (times 10 with the actuator:
#: 80 uV).  A voltage, bounded by the supply whatever the gain: until the thirty-ninth session it was ``1e-9 K_i``
#: (the same at the default gain, 8000 V/(m s)), which made a gain and the tolerance ``rtol`` (that the absolute
#: tolerances follow below the default) change one number, so a native FMU could take only one of them
INTEGRAL_ATOL = 8e-6

#: the numbers a preset derives its network from (``EClutchParams.clutch``; :func:`derive_clutch`), then the bearing
#: position the start finds at rest (:func:`start_at_rest`)
CLUTCH_VECTOR = ("bearing_preload", "lever_ratio", "k_fl", "support_scale", "rest_position")
CL_PRELOAD, CL_RATIO, CL_KFL, CL_SUPPORT_SCALE, CL_REST = indices(
    CLUTCH_VECTOR, "bearing_preload", "lever_ratio", "k_fl", "support_scale", "rest_position")
#: ``EClutchParams.clutch_int``: the preset's number (-1: a network of your own, nothing derived), whether the start
#: derives the network and the state at rest (1: a co-simulation, whose host may have set the parameters), then the
#: elements of the network and of Model 0 the derivation reads (-1: none)
CLUTCH_INT = ("number", "at_start", "bearing", "diaphragm", "lever", "return", "cushion", "pp_spring", "support",
              "model0_bearing", "model0_diaphragm", "model0_return", "model0_cushion")
(CLI_NUMBER, CLI_AT_START, CLI_BEARING, CLI_DIAPHRAGM, CLI_LEVER, CLI_RETURN, CLI_CUSHION, CLI_PP_SPRING, CLI_SUPPORT,
 CLI_M0_BEARING, CLI_M0_DIAPHRAGM, CLI_M0_RETURN, CLI_M0_CUSHION) = indices(
    CLUTCH_INT, "number", "at_start", "bearing", "diaphragm", "lever", "return", "cushion", "pp_spring", "support",
    "model0_bearing", "model0_diaphragm", "model0_return", "model0_cushion")
#: model errors of the start (:attr:`clutchlab.system.System.error_messages`)
ERR_ZEROING, ERR_REST, ERR_STATIC, ERR_PRESTRAIN, ERR_STROKE, ERR_MASTER_VOLUME = -3, -4, -5, -6, -7, -8
ERROR_MESSAGES = {
    ERR_STROKE: "actuator.snifting_port + actuator.snifting_width must be below actuator.master_stroke (the port must "
                "close within the stroke)",
    ERR_MASTER_VOLUME: "actuator.master_volume is smaller than the volume the master piston sweeps up to the snifting "
                       "port",
    ERR_ZEROING: "the clutch's bearing cannot be zeroed at clutch.bearing_preload: no pre-strain of the bearing "
                 "within [-0.05, 0.05] m gives that bearing force at bearing position 0",
    ERR_REST: "with actuator.csc_preload the CSC finds no rest position within its travel "
              "(clutch.bearing_preload and actuator.csc_preload should match)",
    ERR_STATIC: "no static equilibrium of the clutch at its rest position",
    ERR_PRESTRAIN: "a compliance's engaged load lies outside its characteristic (extrapolation 'error'): "
                   "no pre-strain carries it",
}


class EClutchParams(NamedTuple):
    """Packed parameters of one E-clutch run (:meth:`Assembly.params`; SI units).

    Scalars and C-contiguous arrays only: numba specialises the core on this
    class and caches it across processes.  Per-coordinate and per-element
    quantities are rows of a few 2-D arrays (``CO_*``, ``CI_*``, ``NE_*``,
    ``NI_*``): every compiled function that receives the structure unpacks
    it, so few fields keep compile time and call overhead low.  ``work`` holds
    the right-hand side's scratch rows (``W_*``): one structure per run or
    batch variant.
    """

    nz: int                  # generalised coordinates (master, bearing, free nodes)
    imode: int               # VOLTAGE, POSITION or PRESCRIBED
    interp: int              # input table: 0 linear, 1 held between rows
    tin: np.ndarray          # input table times [s] (empty: the held input u[0] is the input)
    vin: np.ndarray          # input table values [V] or [m]
    par: np.ndarray          # actuator parameters (P_* layout)
    coord: np.ndarray        # (6, nz): mass [kg] (0: massless node), Coulomb [N], per normal force [-],
    #                          per pressure [N/Pa], static ratio [-], viscous [N s/m]
    coord_int: np.ndarray    # (3, nz): friction on (0/1), pressing element (-1 none), chamber (0 none, 1, 2)
    friction_outputs: np.ndarray  # coordinates whose friction force is an output
    GA: np.ndarray           # (n_el, n_q) network assembly (node-aligned coordinates)
    net: np.ndarray          # (3, n_el): d0 [m], Gb [-], stiffness scale [-]
    net_int: np.ndarray      # (4, n_el + 1): curve offsets, kinds, extrapolation, unilateral (0/1)
    curve: np.ndarray        # (3, n_samples): deflections [m], forces [N], slopes [N/m] of all curves
    normal_element: int      # element carrying the clamp (normal) force
    r_eff: float             # effective friction radius [m]
    mu: float                # friction coefficient of the facings [-]
    work: np.ndarray         # (N_WORK, n): scratch rows W_*
    clutch: np.ndarray       # CL_* layout: what a preset derives its network from (derive_clutch)
    clutch_int: np.ndarray   # CLI_* layout: preset number, derive at start, the elements the derivation reads
    GA0: np.ndarray          # Model 0 (the engaged state's network): assembly as GA, net, net_int, curve
    net0: np.ndarray
    net0_int: np.ndarray
    curve0: np.ndarray


# ---------------------------------------------------------------- compiled hooks
@numba.njit(cache=True, nogil=True, inline="always")
def reference(t, u, tin, vin, interp, segment):
    """Input value and its slope at ``t`` on the table row ``segment - 1`` (or the held input ``u[0]``).

    The active row is a mode (``input_segment``, set by :func:`restart` at each corner), not looked up from
    ``t``: the Rodas3 stages of a step that ends on a corner are evaluated at the corner itself and must see
    the row the step integrates (a voltage step or a change of slope starts with the next step).
    ``segment`` 0 is before the table, ``k`` the row ``k - 1`` up to the next corner; beyond the last row the
    last value is held.
    """
    n = tin.shape[0]
    if n == 0:
        return u[0], 0.0
    k = segment - 1
    if k < 0:
        return vin[0], 0.0
    if k >= n - 1:
        return vin[n - 1], 0.0
    if interp == 1:
        return vin[k], 0.0
    slope = (vin[k + 1] - vin[k]) / (tin[k + 1] - tin[k])
    return vin[k] + slope * (t - tin[k]), slope


@numba.njit(cache=True, nogil=True)
def _segment(t, tin):
    """Mode ``input_segment`` at ``t``: 0 before the table, ``k + 1`` from row ``k`` on (right-continuous)."""
    n = tin.shape[0]
    if n == 0 or t < tin[0]:
        return 0
    lo, _w = bracket(tin, t) if n > 1 else (0, 0.0)
    k = lo
    while k + 1 < n and tin[k + 1] <= t:
        k += 1
    return k + 1


@numba.njit(cache=True, nogil=True, inline="always")
def _friction_level(j, x, nz, f, coord, coord_int):
    """Kinetic friction force F_c of coordinate ``j`` [N] (``f``: element forces of the current point)."""
    k = coord_int[CI_NORMAL, j]
    fnorm = f[k] if k >= 0 else 0.0
    pres = 0.0
    if coord_int[CI_PRESSURE, j] == 1:
        pres = x[2 * nz]
    elif coord_int[CI_PRESSURE, j] == 2:
        pres = x[2 * nz + 2]
    return kinetic_level(coord[CO_COULOMB, j], coord[CO_MU_NORMAL, j], fnorm, coord[CO_MU_PRESSURE, j], pres)


@numba.njit(cache=True, nogil=True)
def _network(p):
    """Views of the axial network in ``p``: ``(d0, Gb, scale, offsets, kinds, extraps, unilateral, cx, cf, cd)``."""
    net = p.net
    net_int = p.net_int
    curve = p.curve
    return (net[NE_D0], net[NE_GB], net[NE_SCALE], net_int[NI_OFFSETS], net_int[NI_KINDS], net_int[NI_EXTRAPS],
            net_int[NI_UNILATERAL], curve[0], curve[1], curve[2])


@numba.njit(cache=True, nogil=True, inline="always")
def _actuator_point(t, x, u, m, p):
    """The actuator's states and the bearing's motion at ``(t, x)``: master position [m] and velocity
    [m/s], master pressure [Pa], line flow [m^3/s], slave pressure [Pa], motor current [A], the input
    table's value and slope at ``t`` (its active row ``m[nz]``), and the bearing position [m] and velocity
    [m/s] (the table's, when the bearing motion is prescribed)."""
    nz = p.nz
    b0 = 2 * nz
    ref, ref_slope = reference(t, u, p.tin, p.vin, p.interp, m[nz])
    if p.imode == PRESCRIBED:
        ub = ref
        v_u = ref_slope
    else:
        ub = x[1]
        v_u = x[nz + 1]
    return x[0], x[nz], x[b0], x[b0 + 1], x[b0 + 2], x[b0 + 3], ref, ref_slope, ub, v_u


@numba.njit(cache=True, nogil=True)
def rhs(t, x, u, m, p, dx, g):
    """Right-hand side (residual on the algebraic rows) and switching functions of the E-clutch."""
    nz = p.nz
    GA = p.GA
    coord = p.coord
    coord_int = p.coord_int
    par = p.par
    work = p.work
    d0, Gb, scale, offsets, kinds, extraps, unilateral, cx, cf, cd = _network(p)
    f = work[W_F]
    free = work[W_FREE]
    Fz = work[W_FZ]
    aux = work[W_AUX]
    nq = nz - 2
    n_el = GA.shape[0]
    b0 = 2 * nz
    prescribed = p.imode == PRESCRIBED
    x_mc, v_mc, p_m, Q, p_s, cur, ref, ref_slope, ub, v_u = _actuator_point(t, x, u, m, p)
    # --- clutch network: element forces on the coordinates ([1] Figs. 5b, 10-11)
    q = x[2:nz]
    bearing_force = 0.0
    for j in range(nz):
        Fz[j] = 0.0
    kel = work[W_K]
    seg = work[W_SEG]
    for e in range(n_el):
        _d, fe, ke, fr, sg = element_force_segment(e, q, ub, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale,
                                                   unilateral, int(seg[e]))
        seg[e] = sg
        free[e] = fr
        f[e] = fe
        kel[e] = ke
        bearing_force += Gb[e] * fe
        for j in range(nq):
            Fz[2 + j] -= GA[e, j] * fe
    Fz[1] -= bearing_force
    # --- actuator ([1] Sec. 2.1, Fig. 5a; equations in clutchlab.eclutch.actuator)
    v_drive = 0.0
    dissip = 0.0
    if not prescribed:
        if p.imode == VOLTAGE:
            r = ref
            v_cmd = ref
        else:
            r = min(max(ref, par[P_REFMIN]), par[P_REFMAX])
            v_cmd = controller_voltage(r, ub, x[b0 + 4], v_u, par[P_KP], par[P_KD])
        v_drive = drive_voltage(v_cmd, cur, par[P_VSUP], par[P_IMAX], par[P_KIL])
        dx[b0 + 3] = current_rate(v_drive, cur, v_mc / par[P_NS], par[P_R], par[P_L], par[P_KT])
        if p.imode == POSITION:
            dx[b0 + 4] = controller_integral_rate(r, ub, v_drive, v_cmd, par[P_KI], par[P_KAW])
        else:
            dx[b0 + 4] = 0.0
        Fz[0] += spindle_force(cur, par[P_KT], par[P_NS]) - p_m * par[P_AMC]
        q_vent = par[P_GV] * vent_opening(x_mc, par[P_XSN], par[P_WSN]) * p_m
        cm = cavitating_compliance(p_m, par[P_CM], par[P_PCAV], par[P_CAVF])
        cs = cavitating_compliance(p_s, par[P_CS], par[P_PCAV], par[P_CAVF])
        dx[b0] = chamber_pressure_rate(par[P_AMC] * v_mc, Q + q_vent, cm)
        dx[b0 + 1] = line_flow_rate(p_m, p_s, Q, par[P_LH], par[P_RH])
        dx[b0 + 2] = chamber_pressure_rate(Q, par[P_ASL] * v_u, cs)
        Fz[1] += p_s * par[P_ASL] + par[P_FPRE] - par[P_KPRE] * ub
        dissip += par[P_R] * cur * cur + par[P_RH] * Q * Q + q_vent * p_m
        # end stops: master at 0 and its stroke, CSC at its travel limits
        ks = par[P_KSTOP]
        cst = par[P_CSTOP]
        fs, ds = stop_contact(-x_mc, -v_mc, ks, cst)
        Fz[0] += fs
        dissip += ds
        fs, ds = stop_contact(x_mc - par[P_XMAX], v_mc, ks, cst)
        Fz[0] -= fs
        dissip += ds
        fs, ds = stop_contact(par[P_UMIN] - ub, -v_u, ks, cst)
        Fz[1] += fs
        dissip += ds
        fs, ds = stop_contact(ub - par[P_UMAX], v_u, ks, cst)
        Fz[1] -= fs
        dissip += ds
        dx[b0 + 5] = v_drive * cur
    else:
        for k in range(5):
            dx[b0 + k] = 0.0
        dx[b0 + 5] = bearing_force * v_u  # mechanical work done on the clutch at the bearing
    # --- coordinates: kinematics, friction state machine, force balance
    fric_dissip = 0.0
    for j in range(nz):
        vj = x[nz + j]
        if coord_int[CI_FRICTION, j]:
            level = _friction_level(j, x, nz, f, coord, coord_int)
            if m[j] == STUCK:
                g[j] = static_margin(coord[CO_STATIC_RATIO, j], level, Fz[j])
                frc = -Fz[j]
            elif m[j] == FREE:
                # zero normal force: no Coulomb friction; the switching function jumps from +1 to -F_c when
                # the kinetic level leaves zero (a contact pressing the element closes), located as a root
                g[j] = 1.0 if level == 0.0 else -level
                frc = slip_force(0.0, level, coord[CO_VISCOUS, j], vj)
            else:
                g[j] = vj
                frc = slip_force(_direction(m[j]), level, coord[CO_VISCOUS, j], vj)
        else:
            g[j] = 1.0
            frc = slip_force(0.0, 0.0, coord[CO_VISCOUS, j], vj)
        aux[N_AUX + j] = frc
        mass = coord[CO_MASS, j]
        if prescribed and j < 2:
            # the actuator is not simulated; the bearing follows the prescribed motion
            dx[j] = v_u if j == 1 else 0.0
            dx[nz + j] = 0.0
        elif mass > 0.0:
            if coord_int[CI_FRICTION, j] and m[j] == STUCK:
                dx[j] = 0.0
                dx[nz + j] = 0.0
            else:
                dx[j] = vj
                dx[nz + j] = (Fz[j] + frc) / mass
                fric_dissip -= frc * vj
        else:
            dx[j] = Fz[j]  # algebraic: massless node in equilibrium
            dx[nz + j] = -vj
    dx[b0 + 6] = dissip + fric_dissip
    dx[b0 + 7] = fric_dissip
    # --- other switching functions: contacts of unilateral elements, end stops, kinks
    for e in range(n_el):
        g[nz + e] = free[e] if unilateral[e] else 1.0
    ne = nz + n_el
    if not prescribed:
        g[ne] = x_mc
        g[ne + 1] = par[P_XMAX] - x_mc
        g[ne + 2] = ub - par[P_UMIN]
        g[ne + 3] = par[P_UMAX] - ub
        g[ne + 4] = p_m - par[P_PCAV]
        g[ne + 5] = p_s - par[P_PCAV]
        g[ne + 6] = par[P_IMAX] - abs(cur)
        g[ne + 7] = x_mc - par[P_XSN]
        g[ne + 8] = x_mc - (par[P_XSN] - par[P_WSN])
    else:
        for k in range(N_OTHER):
            g[ne + k] = 1.0
    aux[AUX_VDRIVE] = v_drive
    aux[AUX_FB] = bearing_force
    aux[AUX_REF] = ref
    aux[AUX_UB] = ub
    _store_key(work[W_KEY], t, x, m)


@numba.njit(cache=True, nogil=True, inline="always")
def _store_key(key, t, x, m):
    """Remember the point ``(t, x, m)`` of an evaluation (in a work row)."""
    n = x.shape[0]
    key[0] = t
    for i in range(n):
        key[1 + i] = x[i]
    for i in range(m.shape[0]):
        key[1 + n + i] = m[i]


@numba.njit(cache=True, nogil=True, inline="always")
def _is_key(key, t, x, m):
    """True if the last evaluation was at exactly ``(t, x, m)`` (its element forces and stiffnesses hold)."""
    n = x.shape[0]
    if key[0] != t:
        return False
    for i in range(n):
        if key[1 + i] != x[i]:
            return False
    for i in range(m.shape[0]):
        if key[1 + n + i] != m[i]:
            return False
    return True


@numba.njit(cache=True, nogil=True)
def _equilibrate(x, ub, p, known):
    """Massless nodes of ``x`` moved into equilibrium (Newton on their force balance, in place).

    The state at a sample comes from the dense output of a step, which is linear in the algebraic rows and
    cubic in the others; the stiff release bearing turns that small mismatch into a force error.  The
    outputs are therefore evaluated with the massless nodes re-solved for the interpolated positions.

    ``known``: ``x`` is the point of the last right-hand side evaluation (a step end), whose element forces
    and stiffnesses are in the work rows.  If every massless node is then already within ``EQUILIBRIUM_TOL``
    of its equilibrium (one Newton step shorter than that: the force residual is below that times the
    node's stiffness, e.g. 0.01 N at 1e-10 m and 1e8 N/m), ``x`` is left as it is and True is returned: the
    outputs can be read from that evaluation.  Returns False after moving the nodes.
    """
    nz = p.nz
    GA = p.GA
    coord = p.coord
    work = p.work
    d0, Gb, scale, offsets, kinds, extraps, unilateral, cx, cf, cd = _network(p)
    q = x[2:nz]
    if known:
        close = True
        for j in range(2, nz):
            if coord[CO_MASS, j] > 0.0:
                continue
            r = 0.0
            dr = 0.0
            for e in range(GA.shape[0]):
                g = GA[e, j - 2]
                if g != 0.0:
                    r -= g * work[W_F, e]
                    dr -= g * g * work[W_K, e]
            if dr != 0.0 and not abs(r) <= EQUILIBRIUM_TOL * abs(dr):
                close = False
                break
        if close:
            return True
    for _it in range(6):
        worst = 0.0
        for j in range(2, nz):
            if coord[CO_MASS, j] > 0.0:
                continue
            r = 0.0
            dr = 0.0
            for e in range(GA.shape[0]):
                if GA[e, j - 2] == 0.0:
                    continue
                if known:
                    # the point of the last evaluation (a step end): its element forces and stiffnesses
                    fe = work[W_F, e]
                    ke = work[W_K, e]
                else:
                    _d, fe, ke, _fr = element_force(e, q, ub, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps,
                                                    scale, unilateral)
                r -= GA[e, j - 2] * fe
                dr -= GA[e, j - 2] * GA[e, j - 2] * ke
            if dr != 0.0:
                dq = r / dr
                x[j] -= dq
                worst = max(worst, abs(dq))
                known = False  # the point moved
        if worst <= 1e-9:  # [m]: Newton converges quadratically: after a step this small ~1e-17 m are left
            break
    return False


@numba.njit(cache=True, nogil=True)
def outputs(t, x, u, m, p, y):
    """Outputs (see :meth:`Assembly.output_variables`) at one point (massless nodes in equilibrium)."""
    nz = p.nz
    work = p.work
    xs = work[W_X]
    for i in range(x.shape[0]):
        xs[i] = x[i]
    if p.imode == PRESCRIBED:
        ub, _slope = reference(t, u, p.tin, p.vin, p.interp, m[nz])
    else:
        ub = x[1]
    if not _equilibrate(xs, ub, p, _is_key(work[W_KEY], t, x, m)):
        dispatch.rhs(t, xs, u, m, p, work[W_DX], work[W_G])  # the compiled rhs the core uses (one compilation)
    # (else: a step end already in equilibrium, the last evaluation's rows hold)
    aux = work[W_AUX]
    f = work[W_F]
    n_el = p.GA.shape[0]
    fn = f[p.normal_element]
    y[Y_VOLTAGE] = aux[AUX_VDRIVE]
    y[Y_BEARING_FORCE] = xs[2 * nz + 2] * p.par[P_ASL]  # F_b = p A_sl, as the rig measures it ([1] Sec. 6)
    y[Y_BEARING_FORCE_CLUTCH] = aux[AUX_FB]
    y[Y_NORMAL_FORCE] = fn
    y[Y_TORQUE] = torque_of_clamp_force(fn, p.r_eff, p.mu)
    y[Y_MOTOR_SPEED] = xs[nz] / p.par[P_NS] * 60.0 / (2.0 * math.pi)
    y[Y_INPUT] = aux[AUX_REF]
    for e in range(n_el):
        y[Y_ELEMENTS + e] = f[e]
    fo = p.friction_outputs
    for k in range(fo.shape[0]):
        y[Y_ELEMENTS + n_el + k] = aux[N_AUX + fo[k]]


@numba.njit(cache=True, nogil=True, inline="always")
def _slip_mode(force):
    return SLIP_FORWARD if force > 0.0 else SLIP_BACKWARD


@numba.njit(cache=True, nogil=True, inline="always")
def _direction(mode):
    """Slip direction s of a friction mode: +1 forward, -1 backward, 0 stuck or free."""
    if mode == SLIP_FORWARD:
        return 1.0
    if mode == SLIP_BACKWARD:
        return -1.0
    return 0.0


@numba.njit(cache=True, nogil=True, inline="always")
def _engaged_mode(velocity, level, force, static_ratio):
    """Mode of a free coordinate whose kinetic level ``level`` [N] just left zero.

    Moving, it slips in the direction of its velocity [m/s]; at rest it sticks if the static limit holds
    the force ``force`` [N] it must carry, else it breaks away in that force's direction ([2], the friction
    element's start from rest).
    """
    if velocity > 0.0:
        return SLIP_FORWARD
    if velocity < 0.0:
        return SLIP_BACKWARD
    if static_margin(static_ratio, level, force) >= 0.0:
        return STUCK
    return _slip_mode(force)


@numba.njit(cache=True, nogil=True)
def _free_unloaded(t, x, m, p, log):
    """Friction coordinates whose kinetic level is exactly zero become free (event ``friction_free``).

    A zero normal force (an open contact pressing the element, no Coulomb or pressure part) means no
    friction: the element neither sticks nor turns, whatever the force on its coordinate.  ``work`` holds
    the element forces of ``(t, x)``.  Returns True if a mode changed.
    """
    nz = p.nz
    changed = False
    for j in range(nz):
        if not p.coord_int[CI_FRICTION, j] or p.coord[CO_MASS, j] <= 0.0 or m[j] == FREE:
            continue
        if _friction_level(j, x, nz, p.work[W_F], p.coord, p.coord_int) == 0.0:
            m[j] = FREE
            record(log, t, EV_FREE, j)
            changed = True
    return changed


@numba.njit(cache=True, nogil=True)
def update(t, x, u, m, p, k, log):
    """The friction state machine and the named events when switching function ``k`` crossed zero."""
    nz = p.nz
    n_el = p.GA.shape[0]
    work = p.work
    dispatch.rhs(t, x, u, m, p, work[W_DX], work[W_G])  # the compiled rhs the core uses (one compilation)
    if k < nz:
        j = k
        if not p.coord_int[CI_FRICTION, j]:
            return 0
        force = work[W_FZ, j]
        level = _friction_level(j, x, nz, work[W_F], p.coord, p.coord_int)
        if m[j] == FREE:
            if level == 0.0:
                return 0
            # the normal force left zero: friction engages at once
            m[j] = _engaged_mode(x[nz + j], level, force, p.coord[CO_STATIC_RATIO, j])
            kind = EV_ENGAGE
        elif level == 0.0:
            # zero normal force means free (a stuck or slipping element that lost its load)
            m[j] = FREE
            kind = EV_FREE
        elif m[j] == STUCK:
            # break-away: slip in the direction of the applied force, exactly at rest (no spurious reversal)
            m[j] = _slip_mode(force)
            x[nz + j] = 0.0
            kind = EV_BREAKAWAY
        elif static_margin(p.coord[CO_STATIC_RATIO, j], level, force) >= 0.0:
            m[j] = STUCK
            x[nz + j] = 0.0
            kind = EV_STICK
        else:
            m[j] = _slip_mode(force)
            kind = EV_REVERSAL
        record(log, t, kind, j)
        # with the bearing prescribed (ClutchDynamics) a clutch mass that breaks away or sticks starts (or
        # ends) a lightly damped ringing on the stiff elements between it and the rig: the core restarts the
        # step size (issue #30: a first step of the stuck phase's length damped the pressure plate's physical
        # stick-slip micro-cycles away unseen, 1,227 of 13,953 events at rtol 1e-5).  Not with the actuator
        # simulated: there it cost EClutch's benchmark run 278 steps instead of 245 at the same error
        # against the SciPy reference (0.34 % of peak F_b, benchmarks/wp_eclutch.py)
        if p.imode == PRESCRIBED and (kind == EV_BREAKAWAY or kind == EV_STICK):
            return RESTART
        return 0
    gk = work[W_G, k]
    if k < nz + n_el:
        record(log, t, EV_CONTACT_OPEN if gk <= 0.0 else EV_CONTACT_CLOSE, k - nz)
        if gk <= 0.0:
            _free_unloaded(t, x, m, p, log)  # the contact may have pressed a friction element
        return 0
    s = k - nz - n_el
    if s < 4:
        record(log, t, EV_STOP_HIT if gk <= 0.0 else EV_STOP_LEAVE, s)
    elif s < 6:
        record(log, t, EV_CAVITATION_START if gk <= 0.0 else EV_CAVITATION_END, s - 4)
    return 0  # current limit and snifting-port edges: kinks, no event


@numba.njit(cache=True, nogil=True)
def restart(t, x, u, m, p, log):
    """Make the friction modes consistent with the forces at a (re)start or an input corner.

    A stuck coordinate whose needed force exceeds the static limit breaks away; a coordinate slipping
    from exactly zero velocity against its force sticks or turns round; a coordinate whose kinetic level
    is exactly zero (zero normal force) is free, and a free one whose level is positive engages
    (:func:`_engaged_mode`).  With a prescribed bearing motion the bearing position and velocity are set
    to the table's.
    """
    nz = p.nz
    work = p.work
    coord = p.coord
    coord_int = p.coord_int
    changed = False
    seg = _segment(t, p.tin)
    if m[nz] != seg:
        m[nz] = seg
        changed = True
    if p.imode == PRESCRIBED:
        ref, slope = reference(t, u, p.tin, p.vin, p.interp, seg)
        if x[1] != ref or x[nz + 1] != slope:
            x[1] = ref
            x[nz + 1] = slope
            changed = True
    dispatch.rhs(t, x, u, m, p, work[W_DX], work[W_G])  # the compiled rhs the core uses (one compilation)
    for j in range(nz):
        if not coord_int[CI_FRICTION, j] or coord[CO_MASS, j] <= 0.0:
            continue
        force = work[W_FZ, j]
        level = _friction_level(j, x, nz, work[W_F], coord, coord_int)
        kind = -1
        if m[j] == FREE:
            if level > 0.0:
                m[j] = _engaged_mode(x[nz + j], level, force, coord[CO_STATIC_RATIO, j])
                kind = EV_ENGAGE
        elif level == 0.0:
            m[j] = FREE  # zero normal force means free
            kind = EV_FREE
        elif m[j] == STUCK:
            if static_margin(coord[CO_STATIC_RATIO, j], level, force) < 0.0:
                m[j] = _slip_mode(force)
                x[nz + j] = 0.0
                kind = EV_BREAKAWAY
        elif x[nz + j] == 0.0:
            s = 1.0 if m[j] == SLIP_FORWARD else -1.0
            if (force - s * level) * s < 0.0:  # would accelerate against its slip direction
                if static_margin(coord[CO_STATIC_RATIO, j], level, force) >= 0.0:
                    m[j] = STUCK
                    kind = EV_STICK
                else:
                    m[j] = _slip_mode(force)
                    kind = EV_REVERSAL
        if kind >= 0:
            changed = True
            record(log, t, kind, j)
    return changed


@numba.njit(cache=True, nogil=True)
def accept(t, x, u, m, p):
    """After an accepted step: stuck coordinates have exactly zero velocity; 1 if a velocity was reset."""
    nz = p.nz
    changed = 0
    for j in range(nz):
        if m[j] == STUCK and x[nz + j] != 0.0:
            x[nz + j] = 0.0
            changed = 1
    return changed


@numba.njit(cache=True, nogil=True)
def next_break(t, m, p):
    """Next corner of the input table after ``t`` (the integrator never steps across one) [s]."""
    tin = p.tin
    k = m[p.nz]  # the next corner is row k (the active one is k - 1)
    while k < tin.shape[0] and tin[k] <= t:
        k += 1
    return tin[k] if k < tin.shape[0] else np.inf


@numba.njit(cache=True, nogil=True, inline="always")
def _force_row(j, nz, coord):
    """Row of the Jacobian that holds coordinate ``j``'s force balance: its velocity row, or its position row
    for a massless node (algebraic row)."""
    return nz + j if coord[CO_MASS, j] > 0.0 else j


@numba.njit(cache=True, nogil=True, inline="always")
def _stop_rows(J, fr, e_row, c_pos, c_vel, sign, pen, rate, ks, cst):
    """Add an end stop's force (``sign`` +1 pushes the coordinate forward) and dissipation to the Jacobian.

    ``pen``/``rate`` are the penetration and its rate as :func:`rhs` passes them; their derivatives with
    respect to the coordinate's position and velocity are ``-sign`` (a stop pushing forward is penetrated by
    moving backward).
    """
    dfd, dfr, dpd, dpr = stop_contact_slopes(pen, rate, ks, cst)
    J[fr, c_pos] -= dfd  # d(sign * F)/dz = sign * dF/dd * (-sign)
    J[fr, c_vel] -= dfr
    J[e_row, c_pos] -= sign * dpd
    J[e_row, c_vel] -= sign * dpr


@numba.njit(cache=True, nogil=True)
def jacobian(t, x, u, m, p, J):
    """Analytic Jacobian ``J = df/dx`` of :func:`rhs` in the modes ``m`` (mass-matrix form, residual rows).

    The derivative of every term of the right-hand side, assembled from the slopes of the same scalar
    equations: the elements' tangent stiffnesses from their curves ([1] Figs. 5b, 10-11;
    :func:`~clutchlab.eclutch.network.element_force`), the actuator's linear laws ([1] Sec. 2.1, Fig. 5a)
    and the slopes of its piecewise ones (:func:`~clutchlab.eclutch.actuator.drive_voltage_slopes`,
    :func:`~clutchlab.eclutch.actuator.vent_opening_slope`,
    :func:`~clutchlab.eclutch.actuator.stop_contact_slopes`), the kinetic friction's dependence on the
    normal force and the chamber pressure.  Inside a mode the right-hand side is smooth except at the kinks
    that are switching functions (contacts, stops, cavitation, the current limit, the snifting port); there
    the slope of the branch the point lies on is taken.  The compliance switch at the vapour pressure is
    piecewise constant (no slope).  The energy states enter no equation (zero columns).  Tested against
    central differences of :func:`rhs` at random states and modes (tests/eclutch/test_jacobian.py).
    Replaces the core's 17 finite-difference evaluations of the right-hand side per Jacobian.
    """
    nz = p.nz
    GA = p.GA
    coord = p.coord
    coord_int = p.coord_int
    par = p.par
    work = p.work
    d0, Gb, scale, offsets, kinds, extraps, unilateral, cx, cf, cd = _network(p)
    f = work[W_F]
    kel = work[W_K]
    work[W_KEY, 0] = np.nan  # the element rows are overwritten here: no longer those of the last rhs point
    n = x.shape[0]
    nq = nz - 2
    n_el = GA.shape[0]
    b0 = 2 * nz
    prescribed = p.imode == PRESCRIBED
    for i in range(n):
        for j in range(n):
            J[i, j] = 0.0
    x_mc, v_mc, p_m, Q, p_s, cur, ref, ref_slope, ub, v_u = _actuator_point(t, x, u, m, p)
    cu = -1 if prescribed else 1  # (prescribed: the bearing position is no state, no column)
    e_in = b0 + 5
    e_dis = b0 + 6
    e_fr = b0 + 7
    # --- network: dFz_j/dq_i = -sum_e GA_ej k_e GA_ei, dFz_1/dq_i = -sum_e Gb_e k_e GA_ei ([1] Figs. 5b, 10-11)
    q = x[2:nz]
    bearing_force = 0.0
    for e in range(n_el):
        _d, fe, ke, _fr = element_force(e, q, ub, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral)
        f[e] = fe
        kel[e] = ke
        bearing_force += Gb[e] * fe
        if ke == 0.0:
            continue
        for j in range(nq):
            gj = GA[e, j] * ke
            if gj == 0.0:
                continue
            fr = _force_row(2 + j, nz, coord)
            for i in range(nq):
                J[fr, 2 + i] -= gj * GA[e, i]
            if cu >= 0:
                J[fr, cu] -= gj * Gb[e]
        gb = Gb[e] * ke
        if gb != 0.0:
            fr = _force_row(1, nz, coord)
            for i in range(nq):
                J[fr, 2 + i] -= gb * GA[e, i]
            if cu >= 0:
                J[fr, cu] -= gb * Gb[e]
            if prescribed:  # input work F_b v_u
                for i in range(nq):
                    J[e_in, 2 + i] += v_u * gb * GA[e, i]
    # --- actuator ([1] Sec. 2.1, Fig. 5a)
    if not prescribed:
        fm = _force_row(0, nz, coord)  # master piston
        fb = _force_row(1, nz, coord)  # CSC piston and bearing
        dvc_u = 0.0  # d V_cmd / d(x_sl, v_sl, V_I)
        dvc_v = 0.0
        dvc_i = 0.0
        if p.imode == VOLTAGE:
            v_cmd = ref
        else:
            r = min(max(ref, par[P_REFMIN]), par[P_REFMAX])
            v_cmd = controller_voltage(r, ub, x[b0 + 4], v_u, par[P_KP], par[P_KD])
            dvc_u = -par[P_KP]
            dvc_v = -par[P_KD]
            dvc_i = 1.0
        v_drive = drive_voltage(v_cmd, cur, par[P_VSUP], par[P_IMAX], par[P_KIL])
        dv_cmd, dv_i = drive_voltage_slopes(v_cmd, cur, par[P_VSUP], par[P_IMAX], par[P_KIL])
        inv_l = 1.0 / par[P_L]
        # di/dt = (V - R i - k_t v_mc / n_s) / L
        J[b0 + 3, 1] += dv_cmd * dvc_u * inv_l
        J[b0 + 3, nz + 1] += dv_cmd * dvc_v * inv_l
        J[b0 + 3, b0 + 4] += dv_cmd * dvc_i * inv_l
        J[b0 + 3, b0 + 3] += (dv_i - par[P_R]) * inv_l
        J[b0 + 3, nz] -= par[P_KT] / par[P_NS] * inv_l
        if p.imode == POSITION:  # dV_I/dt = K_i [(r - x) + K_aw (V - V_cmd)]
            ki = par[P_KI]
            kaw = par[P_KAW]
            J[b0 + 4, 1] += ki * (-1.0 + kaw * (dv_cmd - 1.0) * dvc_u)
            J[b0 + 4, nz + 1] += ki * kaw * (dv_cmd - 1.0) * dvc_v
            J[b0 + 4, b0 + 4] += ki * kaw * (dv_cmd - 1.0) * dvc_i
            J[b0 + 4, b0 + 3] += ki * kaw * dv_i
        # input work V i
        J[e_in, 1] += cur * dv_cmd * dvc_u
        J[e_in, nz + 1] += cur * dv_cmd * dvc_v
        J[e_in, b0 + 4] += cur * dv_cmd * dvc_i
        J[e_in, b0 + 3] += cur * dv_i + v_drive
        # master piston: spindle force k_t i / n_s - p_m A_mc
        J[fm, b0 + 3] += par[P_KT] / par[P_NS]
        J[fm, b0] -= par[P_AMC]
        # snifting port flow G_v s(x_mc) p_m, chamber compliances (piecewise constant)
        vent = vent_opening(x_mc, par[P_XSN], par[P_WSN])
        dq_dx = par[P_GV] * vent_opening_slope(x_mc, par[P_XSN], par[P_WSN]) * p_m
        dq_dp = par[P_GV] * vent
        q_vent = dq_dp * p_m
        cm = cavitating_compliance(p_m, par[P_CM], par[P_PCAV], par[P_CAVF])
        cs = cavitating_compliance(p_s, par[P_CS], par[P_PCAV], par[P_CAVF])
        J[b0, nz] += par[P_AMC] / cm
        J[b0, b0 + 1] -= 1.0 / cm
        J[b0, 0] -= dq_dx / cm
        J[b0, b0] -= dq_dp / cm
        J[b0 + 1, b0] += 1.0 / par[P_LH]
        J[b0 + 1, b0 + 2] -= 1.0 / par[P_LH]
        J[b0 + 1, b0 + 1] -= par[P_RH] / par[P_LH]
        J[b0 + 2, b0 + 1] += 1.0 / cs
        J[b0 + 2, nz + 1] -= par[P_ASL] / cs
        # CSC: p_s A_sl + F_pre - k_pre x_sl
        J[fb, b0 + 2] += par[P_ASL]
        J[fb, 1] -= par[P_KPRE]
        # dissipation R i^2 + R_h Q^2 + q_vent p_m
        J[e_dis, b0 + 3] += 2.0 * par[P_R] * cur
        J[e_dis, b0 + 1] += 2.0 * par[P_RH] * Q
        J[e_dis, 0] += dq_dx * p_m
        J[e_dis, b0] += dq_dp * p_m + q_vent
        # end stops: master at 0 (pushes forward) and at its stroke (backward), CSC at its travel limits
        ks = par[P_KSTOP]
        cst = par[P_CSTOP]
        _stop_rows(J, fm, e_dis, 0, nz, 1.0, -x_mc, -v_mc, ks, cst)
        _stop_rows(J, fm, e_dis, 0, nz, -1.0, x_mc - par[P_XMAX], v_mc, ks, cst)
        _stop_rows(J, fb, e_dis, 1, nz + 1, 1.0, par[P_UMIN] - ub, -v_u, ks, cst)
        _stop_rows(J, fb, e_dis, 1, nz + 1, -1.0, ub - par[P_UMAX], v_u, ks, cst)
    # --- coordinates: friction, kinematics, mass or equilibrium rows
    for j in range(nz):
        vj = x[nz + j]
        mass = coord[CO_MASS, j]
        if prescribed and j < 2:
            for c in range(n):
                J[j, c] = 0.0
                J[nz + j, c] = 0.0
            continue
        if mass <= 0.0:
            J[nz + j, nz + j] = -1.0  # massless node: dv/dt = -v (the velocity is not used)
            continue  # its position row holds the force balance already
        stuck = coord_int[CI_FRICTION, j] and m[j] == STUCK
        if stuck:
            for c in range(n):
                J[j, c] = 0.0
                J[nz + j, c] = 0.0
            continue
        fr = nz + j
        # friction force -s F_c - c v (kinetic level F_c0 + mu_n |f_n| + mu_p |p|) and its dissipation -F_f v
        J[fr, nz + j] -= coord[CO_VISCOUS, j]
        J[e_dis, nz + j] += coord[CO_VISCOUS, j] * vj
        J[e_fr, nz + j] += coord[CO_VISCOUS, j] * vj
        if coord_int[CI_FRICTION, j]:
            s = _direction(m[j])
            level = _friction_level(j, x, nz, f, coord, coord_int)
            frc = -s * level - coord[CO_VISCOUS, j] * vj
            k = coord_int[CI_NORMAL, j]
            if k >= 0 and kel[k] != 0.0 and f[k] != 0.0:
                dl = coord[CO_MU_NORMAL, j] * (1.0 if f[k] > 0.0 else -1.0) * kel[k]
                for i in range(nq):
                    a = dl * GA[k, i]
                    J[fr, 2 + i] -= s * a
                    J[e_dis, 2 + i] += s * a * vj
                    J[e_fr, 2 + i] += s * a * vj
                if cu >= 0:
                    a = dl * Gb[k]
                    J[fr, cu] -= s * a
                    J[e_dis, cu] += s * a * vj
                    J[e_fr, cu] += s * a * vj
            pc = coord_int[CI_PRESSURE, j]
            if pc != 0:
                col = b0 if pc == 1 else b0 + 2
                pres = x[col]
                if pres != 0.0:
                    a = coord[CO_MU_PRESSURE, j] * (1.0 if pres > 0.0 else -1.0)
                    J[fr, col] -= s * a
                    J[e_dis, col] += s * a * vj
                    J[e_fr, col] += s * a * vj
        else:
            frc = -coord[CO_VISCOUS, j] * vj
        J[e_dis, nz + j] -= frc
        J[e_fr, nz + j] -= frc
        inv_m = 1.0 / mass
        for c in range(n):
            J[fr, c] *= inv_m
        J[j, nz + j] = 1.0
    return True


@numba.njit(cache=True, nogil=True)
def time_derivative(t, x, u, m, p, ft):
    """Analytic ``df/dt`` of :func:`rhs` at fixed state, with the actuator simulated (False otherwise).

    Time enters only through the input table's active row (a mode): the voltage command follows a linear
    voltage table, or the position controller follows a linear bearing reference (its proportional term,
    ``K_p dr/dt``, and its integral action, docs/eclutch_dynamics.md "Position controller"); both reach the
    motor current ([1] Sec. 2.1), the controller's integral and the input work through the drive's slope
    (:func:`~clutchlab.eclutch.actuator.drive_voltage_slopes`).  With a prescribed bearing motion the
    network moves with time: the core differences that case.
    """
    n = x.shape[0]
    for i in range(n):
        ft[i] = 0.0
    if p.imode == PRESCRIBED:
        return False
    nz = p.nz
    par = p.par
    b0 = 2 * nz
    ref, slope = reference(t, u, p.tin, p.vin, p.interp, m[nz])
    if slope == 0.0:
        return True
    cur = x[b0 + 3]
    if p.imode == VOLTAGE:
        v_cmd = ref
        dvc = slope
    else:
        if ref < par[P_REFMIN] or ref > par[P_REFMAX]:
            return True  # the clipped reference does not move
        v_cmd = controller_voltage(ref, x[1], x[b0 + 4], x[nz + 1], par[P_KP], par[P_KD])
        dvc = par[P_KP] * slope
    d_cmd, _d_i = drive_voltage_slopes(v_cmd, cur, par[P_VSUP], par[P_IMAX], par[P_KIL])
    ft[b0 + 3] = d_cmd * dvc / par[P_L]
    if p.imode == POSITION:
        ft[b0 + 4] = par[P_KI] * (slope + par[P_KAW] * (d_cmd - 1.0) * dvc)
    ft[b0 + 5] = cur * d_cmd * dvc
    return True


@numba.njit(cache=True, nogil=True, _nrt=False)
def derive_actuator(par):
    """The actuator's derived words of ``par`` (the ``P_*`` layout) from the fields packed beside them: the master
    piston's area (:func:`~clutchlab.eclutch.actuator.piston_area`), the chamber compliances
    ``C = V / beta + C_hose / 2`` (:func:`~clutchlab.eclutch.actuator.chamber_compliance`), the line's
    inertance and laminar resistance (:func:`~clutchlab.eclutch.actuator.line_inertance`,
    :func:`~clutchlab.eclutch.actuator.line_resistance`), the snifting port's closing edge (port + width), the
    spindle ratio ``lead / 2 pi`` and the master's equivalent mass ``m + J / n_s^2``
    (:func:`~clutchlab.eclutch.actuator.spindle_ratio`, :func:`~clutchlab.eclutch.actuator.reflected_mass`);
    [1] Sec. 2.1, Fig. 5a, [2].  Called by the packing and by the start (:func:`eclutch_start`)."""
    par[P_AMC] = piston_area(par[P_DMC])
    par[P_CM] = chamber_compliance(par[P_VMC], par[P_BULK], par[P_HOSE] / 2.0)
    par[P_CS] = chamber_compliance(par[P_VSL], par[P_BULK], par[P_HOSE] / 2.0)
    par[P_LH] = line_inertance(par[P_RHO], par[P_LLEN], par[P_DLINE])
    par[P_RH] = line_resistance(par[P_VISC], par[P_LLEN], par[P_DLINE])
    par[P_XSN] = par[P_XPORT] + par[P_WSN]
    par[P_NS] = spindle_ratio(par[P_LEAD])
    par[P_MMC] = reflected_mass(par[P_MMASS], par[P_JROT], par[P_NS])


@numba.njit(cache=True, nogil=True)
def network_arrays(GA, net, net_int, curve):
    """The arrays of the static solver (:meth:`clutchlab.eclutch.network.AxialNetwork.kernel_data`'s order and
    types) from a packed network (``GA``, ``net``, ``net_int``, ``curve``; ``NE_*``, ``NI_*`` rows), as copies:
    the pre-deflections ``d0`` (third) may be changed without touching the packing."""
    n_el = GA.shape[0]
    unilateral = np.empty(n_el, dtype=np.bool_)
    for e in range(n_el):
        unilateral[e] = net_int[NI_UNILATERAL, e] != 0
    return (GA.copy(), net[NE_GB].copy(), net[NE_D0].copy(), curve[0].copy(), curve[1].copy(), curve[2].copy(),
            net_int[NI_OFFSETS].copy(), net_int[NI_KINDS, :n_el].copy(), net_int[NI_EXTRAPS, :n_el].copy(),
            net[NE_SCALE].copy(), unilateral)


@numba.njit(cache=True, nogil=True)
def _path(u_grid, q0, data):
    """:func:`~clutchlab.eclutch.network._static_path` on :func:`network_arrays` (force 1e-7 N, step 1e-14 m, as
    :func:`~clutchlab.eclutch.network.solve_static`)."""
    GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral = data
    return _static_path(u_grid, q0, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, 1e-7, 1e-14)


@numba.njit(cache=True, nogil=True)
def _zeroing_residual_at(prestrain, k, force, data):
    u0 = np.zeros(1)
    q0 = np.zeros(data[0].shape[1])
    GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral = data
    return _zeroing_residual(prestrain, k, 0.0, Gb, force, u0, q0, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps,
                             scale, unilateral)


@numba.njit(cache=True, nogil=True)
def zeroed_prestrain(k, start, force, data):
    """The pre-strain [m] of element ``k`` (the bearing) at which the input force at input position 0 is ``force``
    [N] ([1] Sec. 3.2: the bearing's origin is the engaged clutch pressed by the CSC preload), as
    :func:`~clutchlab.eclutch.network.zero_input` finds it: secant steps from ``start``, else Brent's method on
    [-0.05, 0.05] m (tolerance 1e-13 m + 1e-12 relative).  ``data``: :func:`network_arrays` (its ``d0[k]`` is left
    at the root).  NaN where no pre-strain in that interval reaches the force."""
    u0 = np.zeros(1)
    q0 = np.zeros(data[0].shape[1])
    GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral = data
    p = _zeroing_root(start, start + 1e-6, -0.05, 0.05, 1e-13, 1e-12, k, 0.0, Gb, force, u0, q0, GA, Gb, d0, cx, cf,
                      cd, offsets, kinds, extraps, scale, unilateral)
    if np.isnan(p):
        p = _brent(0, k, force, 0.0, data, -0.05, 0.05, 1e-13, 2e-12)
    if not np.isnan(p):
        data[2][k] = p
    return p


@numba.njit(cache=True, nogil=True)
def _residual_of(which, x, k, force, rate, data):
    """The residual of a root the start finds: ``which`` 0, the bearing's zeroing (:func:`_zeroing_residual_at`,
    element ``k``, input force ``force``); 1, the rest position's (:func:`_rest_residual`, preload ``force``, rate
    ``rate``)."""
    if which == 0:
        return _zeroing_residual_at(x, k, force, data)
    return _rest_residual(x, force, rate, data)


@numba.njit(cache=True, nogil=True)
def _brent(which, k, force, rate, data, a, b, xtol, rtol):
    """Brent's method (scipy's ``brentq``'s bracketing; converged within ``rtol |x| + xtol / 2``) on
    :func:`_residual_of` over ``[a, b]``; NaN without a sign change or where the residual is not finite."""
    fa = _residual_of(which, a, k, force, rate, data)
    fb = _residual_of(which, b, k, force, rate, data)
    if not (np.isfinite(fa) and np.isfinite(fb)) or fa * fb > 0.0:
        return np.nan
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    c, fc, d, e = a, fa, b - a, b - a
    for _ in range(200):
        if fb * fc > 0.0:
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = rtol * abs(b) + 0.5 * xtol
        mid = 0.5 * (c - b)
        if abs(mid) <= tol or fb == 0.0:
            return b
        if abs(e) >= tol and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:
                pp = 2.0 * mid * s
                qq = 1.0 - s
            else:
                qa = fa / fc
                r = fb / fc
                pp = s * (2.0 * mid * qa * (qa - r) - (b - a) * (r - 1.0))
                qq = (qa - 1.0) * (r - 1.0) * (s - 1.0)
            if pp > 0.0:
                qq = -qq
            pp = abs(pp)
            if 2.0 * pp < min(3.0 * mid * qq - abs(tol * qq), abs(e * qq)):
                e = d
                d = pp / qq
            else:
                d = mid
                e = d
        else:
            d = mid
            e = d
        a, fa = b, fb
        b = b + (d if abs(d) > tol else (tol if mid > 0.0 else -tol))
        fb = _residual_of(which, b, k, force, rate, data)
        if not np.isfinite(fb):
            return np.nan
    return b


@numba.njit(cache=True, nogil=True)
def derive_clutch(clutch, clutch_int, GA0, net0, net0_int, curve0, net, net_int, curve, GA):
    """A preset's pre-deflections from its parameters ([1] Secs. 3.2, 5.1-5.4;
    :func:`clutchlab.eclutch.models.build_model`): Model 0's bearing zeroed at ``bearing_preload``
    (:func:`zeroed_prestrain`), Model 0's engaged state at bearing position 0 (the static solver), the loads of
    its rigid connections -- the lever ``F_b - F_ds``, the pressure plate ``F_cushion + F_return``, the support
    ``-(1 - i_ds) F_lever`` -- and the pre-strain at which each compliance a later model adds carries its load: the
    lever ``F_lever / k_fl`` (Eq. 1), the pressure-plate spring and the yoke support by their characteristics'
    inverses (the support's at ``F / support_scale``, Model 4), then Model 4's bearing zeroed again.  Writes the
    bearing's, the lever's, the pressure-plate spring's and the support's ``net[NE_D0]``.  The compiled twin of
    that chain in :func:`~clutchlab.eclutch.models.build_model` (in Python, on the networks' own assemblies; the two
    agree to 1e-17 m), for the start of a co-simulation (:func:`eclutch_start`), whose host may have set the
    parameters.  Returns 0, or :data:`ERR_ZEROING`, :data:`ERR_STATIC`, :data:`ERR_PRESTRAIN`."""
    number = clutch_int[CLI_NUMBER]
    if number < 0:
        return 0
    preload = clutch[CL_PRELOAD]
    data0 = network_arrays(GA0, net0, net0_int, curve0)
    k0 = clutch_int[CLI_M0_BEARING]
    pb = zeroed_prestrain(k0, data0[2][k0], preload, data0)
    if np.isnan(pb):
        return ERR_ZEROING
    _q, F, _d, status = _path(np.zeros(1), np.zeros(GA0.shape[1]), data0)
    if status:
        return ERR_STATIC
    f = F[0]
    lever = f[k0] - f[clutch_int[CLI_M0_DIAPHRAGM]]
    plate = f[clutch_int[CLI_M0_CUSHION]] + f[clutch_int[CLI_M0_RETURN]]
    support = -(1.0 - clutch[CL_RATIO]) * lever
    d0 = net[NE_D0]
    offsets = net_int[NI_OFFSETS]
    eb = clutch_int[CLI_BEARING]
    d0[eb] = pb
    if number >= 1:
        d0[clutch_int[CLI_LEVER]] = lever / clutch[CL_KFL]
    for e, load in ((clutch_int[CLI_PP_SPRING], plate), (clutch_int[CLI_SUPPORT], support / clutch[CL_SUPPORT_SCALE])):
        if e >= 0:
            lo, hi = offsets[e], offsets[e + 1]
            d = curve_inverse_one(curve[0, lo:hi], curve[1, lo:hi], curve[2, lo:hi], net_int[NI_KINDS, e],
                                  net_int[NI_EXTRAPS, e], load)
            if np.isnan(d):
                return ERR_PRESTRAIN
            d0[e] = d
    if number == 4:   # (the scaled diaphragm changes the engaged state: the bearing zeroed again)
        data = network_arrays(GA, net, net_int, curve)
        pb4 = zeroed_prestrain(eb, pb, preload, data)
        if np.isnan(pb4):
            return ERR_ZEROING
        d0[eb] = pb4
    return 0


@numba.njit(cache=True, nogil=True)
def static_state(u, data, q):
    """The clutch's static equilibrium at bearing position ``u`` [m] as
    :func:`~clutchlab.eclutch.network.solve_static` finds it for :meth:`Assembly.initial_state` (walked from the
    assembled state in 8 steps, then Newton there), in the node-aligned coordinates of the packing: the
    independent nodes' positions into ``q`` [m]; returns the bearing force [N] (NaN: not found).  ``data``:
    :func:`network_arrays`.  For the start of a co-simulation (:func:`start_at_rest`)."""
    for j in range(q.shape[0]):
        q[j] = 0.0
    if u != 0.0:
        pre = np.empty(9)
        for i in range(9):
            pre[i] = u * i / 8.0
        Qp, _f, _d, st = _path(pre, q, data)
        if st == 0:
            for j in range(q.shape[0]):   # (element by element: a slice assignment's error is built in Python)
                q[j] = Qp[8, j]
    uu = np.empty(1)
    uu[0] = u
    Q, F, _d, status = _path(uu, q, data)
    if status:
        return np.nan
    for j in range(q.shape[0]):
        q[j] = Q[0, j]
    s = 0.0
    for e in range(F.shape[1]):
        s += F[0, e] * data[1][e]
    return s


@numba.njit(cache=True, nogil=True)
def _rest_residual(u, preload, rate, data):
    q = np.empty(data[0].shape[1])
    return preload - rate * u - static_state(u, data, q)


@numba.njit(cache=True, nogil=True)
def rest_position(preload, rate, lo, hi, data):
    """Bearing position at rest [m]: the CSC preload spring (``preload - rate u`` [N]) balances the clutch's bearing
    force, the first stable root from position 0 within the travel ``[lo, hi]`` (201 positions towards release,
    40 towards the engaged stop, then Brent's method to 1e-13 m); 0 where the preload balances the bearing force
    there within 1e-9 N, NaN where no root lies in the travel.  ``data``: :func:`network_arrays`.  The compiled
    twin of :meth:`Assembly.rest_position` (the same grid and bracket), for the start of a co-simulation
    (:func:`start_at_rest`): calling it from the packing too would compile it as an entry of its own (18 s more
    at an E-clutch's first use)."""
    q = np.empty(data[0].shape[1])
    g0 = preload - static_state(0.0, data, q)
    if not np.isfinite(g0):
        return np.nan
    if abs(g0) < 1e-9:
        return 0.0
    n_up = 201
    up = np.empty(n_up)
    for i in range(n_up):
        up[i] = hi * i / (n_up - 1)
    Q, F, _d, status = _path(up, np.zeros(data[0].shape[1]), data)
    if status:
        return np.nan
    gu = np.empty(n_up)
    for i in range(n_up):
        s = 0.0
        for e in range(F.shape[1]):
            s += F[i, e] * data[1][e]
        gu[i] = preload - rate * up[i] - s
    a = b = np.nan
    if gu[0] > 0.0:   # pushed towards release: the first stable root (g from + to -) going up
        for i in range(n_up - 1):
            if gu[i] > 0.0 and gu[i + 1] <= 0.0:
                a, b = up[i], up[i + 1]
                break
    elif lo < 0.0:    # pulled towards the engaged side
        n_down = 40
        down = np.empty(n_down)
        for i in range(n_down):
            down[i] = lo * (i + 1) / n_down
        Qd, Fd, _d, status = _path(down, np.zeros(data[0].shape[1]), data)
        if status:
            return np.nan
        g_prev, u_prev = gu[0], 0.0
        for i in range(n_down):
            s = 0.0
            for e in range(Fd.shape[1]):
                s += Fd[i, e] * data[1][e]
            g = preload - rate * down[i] - s
            if g_prev <= 0.0 and g > 0.0:
                a, b = down[i], u_prev
                break
            g_prev, u_prev = g, down[i]
    if np.isnan(a):
        return np.nan
    return _brent(1, 0, preload, rate, data, a, b, 1e-13, 4.4e-16)


@numba.njit(cache=True, nogil=True)
def start_modes(u, q, m, GA, net, net_int, curve, coord, coord_int):
    """The friction modes at rest (bearing at ``u``, nodes at ``q``) into ``m[:nz]``: stuck where the kinetic level
    ``F_c + mu_n |F_n|`` is positive (the state machine breaks away if the force exceeds the limit), free where it
    is zero (no Coulomb part, the pressing element unloaded; the chambers start at 0 Pa)."""
    data = network_arrays(GA, net, net_int, curve)
    n_el = GA.shape[0]
    f = np.empty(n_el)
    k = np.empty(n_el)
    d = np.empty(n_el)
    GA_, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral = data
    element_forces(q, u, GA_, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f, k, d)
    for j in range(coord.shape[1]):
        m[j] = FREE
        if coord_int[CI_FRICTION, j]:
            e = coord_int[CI_NORMAL, j]
            fn = f[e] if e >= 0 else 0.0
            m[j] = STUCK if coord[CO_COULOMB, j] + coord[CO_MU_NORMAL, j] * abs(fn) > 0.0 else FREE


@numba.njit(cache=True, nogil=True)
def start_at_rest(x, m, par, coord, coord_int, GA, net, net_int, curve, clutch, imode):
    """The state at rest of a run whose host may have set the parameters (a co-simulation): the bearing at its rest
    position (:func:`rest_position` of ``csc_preload``, ``csc_spring_rate`` and the CSC travel) into ``x[1]`` and
    ``clutch[CL_REST]``, the nodes at the static equilibrium there (:func:`static_state`) into ``x[2:nz]``, the
    friction modes (:func:`start_modes`).  Returns 0, :data:`ERR_REST` or :data:`ERR_STATIC`."""
    data = network_arrays(GA, net, net_int, curve)
    if imode == PRESCRIBED:
        u = x[1]
    else:
        u = rest_position(par[P_FPRE], par[P_KPRE], par[P_UMIN], par[P_UMAX], data)
        if np.isnan(u):
            return ERR_REST
    q = np.empty(GA.shape[1])
    if np.isnan(static_state(u, data, q)):
        return ERR_STATIC
    clutch[CL_REST] = u
    x[1] = u
    for j in range(q.shape[0]):
        x[2 + j] = q[j]
    start_modes(u, q, m, GA, net, net_int, curve, coord, coord_int)
    return 0


@numba.njit(cache=True, nogil=True)
def clutch_at_start(x, m, par, coord, coord_int, GA, net, net_int, curve, clutch, clutch_int, GA0, net0, net0_int,
                    curve0, imode):
    """What a co-simulation's start derives beyond the actuator's words (:func:`eclutch_start`): the checks across
    the actuator's fields that :meth:`ActuatorParameters.check <clutchlab.eclutch.actuator.ActuatorParameters.check>`
    makes, the preset's pre-deflections (:func:`derive_clutch`) and the state at rest (:func:`start_at_rest`).
    Called through its address (:func:`clutchlab.numerics.outline.outlined`, :data:`_CLUTCH_AT_START`): compiled on
    its own the first time a co-simulation asks for it, not linked into every E-clutch session (linked, it added
    about 18 s to an E-clutch's first compilation).  Returns 0 or a model error (:data:`ERROR_MESSAGES`)."""
    if par[P_XSN] >= par[P_XMAX]:
        return ERR_STROKE
    if par[P_VMC] < par[P_AMC] * par[P_XPORT]:
        return ERR_MASTER_VOLUME
    code = derive_clutch(clutch, clutch_int, GA0, net0, net0_int, curve0, net, net_int, curve, GA)
    if code:
        return code
    return start_at_rest(x, m, par, coord, coord_int, GA, net, net_int, curve, clutch, imode)


_F1, _F2, _I1, _I2 = types.float64[::1], types.float64[:, ::1], types.int64[::1], types.int64[:, ::1]
#: :func:`clutch_at_start` called through its address, in the group ``"eclutch_cosim"`` (prepared by a co-simulation's
#: system, :meth:`Assembly.system` with ``at_start``)
_CLUTCH_AT_START = outlined(clutch_at_start, lambda: (_F1, _I1, _F1, _F2, _I2, _F2, _F2, _I2, _F2, _F1, _I1, _F2, _F2,
                                                      _I2, _F2, types.int64), types.int64, group="eclutch_cosim")


@numba.njit(cache=True, nogil=True)
def eclutch_start(t, x, u, m, p):
    """What a run derives from its parameters alone, once before its first restart (the core's ``start`` hook): the
    actuator's words of :func:`derive_actuator`, and the master coordinate's mass (its equivalent mass); in a
    co-simulation (``clutch_int[CLI_AT_START]``, whose host may have set the clutch's parameters) also the
    preset's pre-deflections (:func:`derive_clutch`) and the state at rest (:func:`start_at_rest`).  The packing
    derives the actuator's with the same function, the clutch's in Python
    (:func:`~clutchlab.eclutch.models.build_model`, :meth:`Assembly.rest_position`,
    :meth:`Assembly.initial_state`; the same to 1e-17 m); a native FMU runs the start again after a host set the
    volumes, the fluid, the line, the pre-strains, the lever ratio, the stiffnesses or the preloads, which it then
    writes as plain copies
    (:attr:`clutchlab.system.System.decided_at_start`).  Returns 0 or a model error (:data:`ERROR_MESSAGES`)."""
    par = p.par
    derive_actuator(par)
    p.coord[CO_MASS, 0] = par[P_MMC]   # (the master's coordinate carries the equivalent mass: Assembly)
    if p.imode != PRESCRIBED:   # (the master seal + spindle: actuator_friction_elements, the last on the master)
        p.coord[CO_MU_PRESSURE, 0] = par[P_LOADF] * par[P_AMC]
    if p.clutch_int[CLI_AT_START] == 0:
        return 0
    return _CLUTCH_AT_START(x, m, par, p.coord, p.coord_int, p.GA, p.net, p.net_int, p.curve, p.clutch, p.clutch_int,
                            p.GA0, p.net0, p.net0_int, p.curve0, p.imode)


dispatch.register(EClutchParams, rhs=rhs, outputs=outputs, update=update, restart=restart, accept=accept,
                  next_break=next_break, jacobian=jacobian, time_derivative=time_derivative, start=eclutch_start)


def params_template() -> EClutchParams:
    """An :class:`EClutchParams` of tiny arrays: the numba type of every packed E-clutch's (the types of a driveline's
    empty E-clutch block, :mod:`clutchlab.driveline.eclutch`; built without a compiled function or a model)."""
    f1, f2, i1, i2 = np.zeros(1), np.zeros((1, 1)), np.zeros(1, np.int64), np.zeros((1, 1), np.int64)
    return EClutchParams(0, 0, 0, f1, f1.copy(), f1.copy(), f2, i2, i1, f2.copy(), f2.copy(), i2.copy(), f2.copy(), 0,
                         0.0, 0.0, f2.copy(), f1.copy(), i1.copy(), f2.copy(), f2.copy(), i2.copy(), f2.copy())


# ---------------------------------------------------------------- packing and the System
def _node_aligned(network) -> dict:
    """Coordinates aligned with nodes: ``x = A q + b u + c`` with ``q`` = positions of the independent nodes.

    The input node and, for every rigid lever, one massless node are the
    dependent ones, so each mass (and each friction element) sits on one
    coordinate of its own and the mass matrix is diagonal.
    """
    a = network._assembly
    names = list(a["node_names"])
    idx = {n: i for i, n in enumerate(names)}
    mass = np.array([n.mass for n in network.nodes])
    G = a["G"]
    prestrain = a["d0"] - G @ a["c"]
    N = len(names)
    rows, ru, rc, dep = [], [], [], []
    r = np.zeros(N)
    r[idx[network.input]] = 1.0
    rows.append(r), ru.append(1.0), rc.append(0.0), dep.append(idx[network.input])
    for e in network.elements:
        if isinstance(e, Lever) and e.rigid:
            g = np.zeros(N)
            for node, coef in e.coefficients().items():
                if node != GROUND:
                    g[idx[node]] += coef
            cands = [i for i in np.flatnonzero(g) if i not in dep]
            cands.sort(key=lambda i: (mass[i] > 0, -abs(g[i])))
            if not cands:
                raise ParameterError(f"{network.name}: rigid lever {e.name!r} over-constrains the nodes")
            if mass[cands[0]] > 0:
                raise ParameterError(
                    f"{network.name}: rigid lever {e.name!r} ties two masses together; give one of its nodes zero mass")
            rows.append(g), ru.append(0.0), rc.append(-e.prestrain), dep.append(cands[0])
    C = np.array(rows)
    ind = [i for i in range(N) if i not in dep]
    CD = C[:, dep]
    CI = C[:, ind]
    inv = np.linalg.inv(CD)
    A = np.zeros((N, len(ind)))
    b = np.zeros(N)
    c = np.zeros(N)
    for k, i in enumerate(ind):
        A[i, k] = 1.0
    A[dep, :] = -inv @ CI
    b[dep] = inv @ np.array(ru)
    c[dep] = inv @ np.array(rc)
    GA = G @ A
    return dict(
        names=names, independent=[names[i] for i in ind], A=A, b=b, c=c,
        GA=np.ascontiguousarray(GA), Gb=np.ascontiguousarray(G @ b), d0=np.ascontiguousarray(prestrain + G @ c),
        mass=mass[ind].astype(float), elements=list(a["element_names"]),
    )


def _actuator_vector(a: ActuatorParameters) -> np.ndarray:
    par = np.zeros(N_PAR)
    par[P_AMC] = a.master_area
    par[P_ASL] = a.slave_area
    par[P_MSL] = a.slave_mass
    par[P_GV] = a.snifting_conductance
    par[P_WSN] = a.snifting_width
    par[P_PCAV] = a.vapour_pressure
    par[P_CAVF] = 1e3
    par[P_R] = a.resistance
    par[P_L] = a.inductance
    par[P_KT] = a.torque_constant
    par[P_VSUP] = a.supply_voltage
    par[P_IMAX] = a.current_limit
    par[P_KIL] = a.current_limit_gain
    par[P_FPRE] = a.csc_preload
    par[P_KPRE] = a.csc_spring_rate
    par[P_UMIN] = a.slave_min
    par[P_UMAX] = a.slave_max
    par[P_XMAX] = a.master_stroke
    par[P_KSTOP] = a.stop_stiffness
    par[P_CSTOP] = a.stop_damping
    par[P_KP] = a.kp
    par[P_KI] = a.ki
    par[P_KD] = a.kd
    par[P_KAW] = a.anti_windup
    par[P_REFMIN] = a.slave_min
    par[P_REFMAX] = a.slave_max
    par[P_VMC] = a.master_volume
    par[P_VSL] = a.slave_volume
    par[P_BULK] = a.bulk_modulus
    par[P_HOSE] = a.hose_compliance
    par[P_RHO] = a.fluid_density
    par[P_VISC] = a.fluid_viscosity
    par[P_LLEN] = a.line_length
    par[P_DLINE] = a.line_diameter
    par[P_XPORT] = a.snifting_port
    par[P_LEAD] = a.lead
    par[P_MMASS] = a.master_mass
    par[P_JROT] = a.rotor_inertia
    par[P_DMC] = a.master_diameter
    par[P_LOADF] = a.load_friction
    derive_actuator(par)   # (the words the start derives: written once)
    return par


class Assembly:
    """One E-clutch structure (clutch network + actuator + friction placement), packed for the compiled hooks.

    The only place the E-clutch's parameters are packed: :meth:`params` builds the
    :class:`EClutchParams` of a run, :meth:`system` the :class:`~clutchlab.system.System`.

    Parameters
    ----------
    model : ClutchModel
        Axial Model 0-4 or a variant.
    actuator : ActuatorParameters or None
        The actuator (None with a prescribed bearing: the defaults fill the unused fields).
    friction : list of FrictionElement
        Friction elements (clutch and actuator).
    prescribed : bool
        Bearing motion prescribed (the actuator is not simulated).
    """

    def __init__(self, model: ClutchModel, actuator: ActuatorParameters | None, friction, prescribed: bool):
        if not isinstance(model, ClutchModel):
            raise ParameterError(f"expected a ClutchModel, got {type(model).__name__}")
        self.model = model
        self.actuator = actuator
        self.prescribed = prescribed
        self._initial = {}  # bearing position -> static initial state and modes
        self._constant = None  # constant arrays of EClutchParams (_packed)
        self._names = {}  # cached Variable tuples and switching functions
        self._systems = {}  # the last systems built (system()), by their arguments
        net = model.network
        asm = _node_aligned(net)
        self.asm = asm
        self.nq = len(asm["independent"])
        self.nz = 2 + self.nq
        self.coord_names = ["master", "bearing"] + asm["independent"]
        kd = net.kernel_data()
        # curve data come from the network's own assembly (same element order)
        self.cx, self.cf, self.cd, self.offsets, self.kinds, self.extraps = kd[3], kd[4], kd[5], kd[6], kd[7], kd[8]
        self.scale = np.ascontiguousarray(kd[9], dtype=float)
        self.unilateral = np.ascontiguousarray(kd[10], dtype=np.bool_)
        self.element_names = asm["elements"]
        act = actuator or ActuatorParameters()
        mass = np.zeros(self.nz)
        mass[0] = act.master_equivalent_mass
        mass[1] = act.slave_mass
        mass[2:] = asm["mass"]
        self.mass = mass
        n = 2 * self.nz + 8
        self.n = n
        mvec = np.ones(n)
        for j in range(2, self.nz):
            if mass[j] == 0.0:
                mvec[j] = 0.0
        self.mvec = mvec
        self.par = _actuator_vector(act)
        self._friction(list(friction))
        ki = act.ki if act.ki > 0 else 1.0  # the integral state is the integral action K_i * int(e) [V]
        b0 = 2 * self.nz
        typ = np.empty(n)
        typ[: self.nz] = 1e-3
        typ[self.nz: b0] = 1e-2
        typ[b0: b0 + 8] = [1e5, 1e-6, 1e5, 1.0, 1e-4 * ki, 1.0, 1.0, 1.0]
        self.typ = typ
        atol = np.empty(n)
        atol[: self.nz] = 1e-8
        atol[self.nz: b0] = 1e-5
        # energy bookkeeping states: 10 nJ, so the energy balance of a small input (tens of uJ) closes too; the
        # controller's integral action in volts (INTEGRAL_ATOL: not scaled by the gain, whose integral of the
        # same voltage it is)
        atol[b0: b0 + 8] = [10.0, 1e-10, 10.0, 1e-4, INTEGRAL_ATOL, 1e-8, 1e-8, 1e-8]
        if not prescribed:
            # with the actuator: 0.1 um, 0.1 mm/s, 100 Pa, 1 mA, ... (far below what a rig resolves; tighter
            # values only resolve stick-slip micro-motions of the seals, see docs/eclutch_dynamics.md)
            atol[: b0 + 5] *= 10.0
        self.atol = atol
        nf = net.normal_force
        self.normal_element = self.element_names.index(nf)
        self.friction_outputs = np.array([j for j in range(self.nz) if self.fr_on[j] or self.fr_c[j] > 0],
                                         dtype=np.int64)
        self._derivation_arrays()

    def _derivation_arrays(self) -> None:
        """``clutch``, ``clutch_int`` and Model 0's assembly for :func:`derive_clutch` (a preset's; a network of
        your own derives nothing: number -1 and empty arrays)."""
        d = self.model.derivation
        self.clutch = np.zeros(len(CLUTCH_VECTOR))
        self.clutch_int = -np.ones(len(CLUTCH_INT), dtype=np.int64)
        self.clutch_int[CLI_AT_START] = 0
        if d is None or d.network is not self.model.network:
            self.model0 = (np.zeros((0, 0)), np.zeros((3, 0)), np.zeros((4, 1), dtype=np.int64), np.zeros((3, 0)))
            return
        self.clutch[[CL_PRELOAD, CL_RATIO, CL_KFL, CL_SUPPORT_SCALE]] = (d.bearing_preload, d.lever_ratio, d.k_fl,
                                                                         d.support_scale)
        self.clutch_int[CLI_NUMBER] = d.number
        names = self.element_names
        for slot, name in ((CLI_BEARING, "bearing"), (CLI_DIAPHRAGM, "diaphragm"), (CLI_LEVER, "lever"),
                           (CLI_RETURN, "return"), (CLI_CUSHION, "cushion"), (CLI_PP_SPRING, "pp_spring"),
                           (CLI_SUPPORT, "support")):
            self.clutch_int[slot] = names.index(name) if name in names else -1
        asm0 = _node_aligned(d.model0)
        kd = d.model0.kernel_data()
        names0 = asm0["elements"]
        for slot, name in ((CLI_M0_BEARING, "bearing"), (CLI_M0_DIAPHRAGM, "diaphragm"), (CLI_M0_RETURN, "return"),
                           (CLI_M0_CUSHION, "cushion")):
            self.clutch_int[slot] = names0.index(name)
        n0 = len(names0)
        net0_int = np.zeros((4, n0 + 1), dtype=np.int64)
        net0_int[NI_OFFSETS] = kd[6]
        net0_int[NI_KINDS, :n0] = kd[7]
        net0_int[NI_EXTRAPS, :n0] = kd[8]
        net0_int[NI_UNILATERAL, :n0] = kd[10]
        self.model0 = (np.ascontiguousarray(asm0["GA"], dtype=float),
                       np.ascontiguousarray(np.stack([asm0["d0"], asm0["Gb"], kd[9]]), dtype=float), net0_int,
                       np.ascontiguousarray(np.stack([kd[3], kd[4], kd[5]]), dtype=float))

    def _friction(self, elements):
        nz = self.nz
        self.fr_on = np.zeros(nz, dtype=np.bool_)
        self.fr_c0 = np.zeros(nz)
        self.fr_mun = np.zeros(nz)
        self.fr_nidx = -np.ones(nz, dtype=np.int64)
        self.fr_mup = np.zeros(nz)
        self.fr_pidx = np.zeros(nz, dtype=np.int64)
        self.fr_rs = np.ones(nz)
        self.fr_c = np.zeros(nz)
        self.friction_names = [""] * nz
        for el in elements:
            if not isinstance(el, FrictionElement):
                raise ParameterError(f"friction elements must be FrictionElement, got {type(el).__name__}")
            if el.node not in self.coord_names:
                raise ParameterError(
                    f"friction element {el.name!r}: node {el.node!r} is not a free coordinate "
                    f"(free: {self.coord_names})")
            j = self.coord_names.index(el.node)
            if self.prescribed and j < 2:
                continue  # the actuator is not simulated
            if self.mass[j] <= 0.0:
                raise ParameterError(f"friction element {el.name!r} acts on massless node {el.node!r}; give it a mass")
            self.fr_c[j] += el.viscous
            if not el.active:
                continue
            if self.fr_on[j]:
                # several elements on one coordinate: they stick and slip together
                if el.normal is not None and self.fr_nidx[j] >= 0:
                    raise ParameterError(f"node {el.node!r}: only one normal-force element per node is supported")
            self.fr_on[j] = True
            self.fr_c0[j] += el.coulomb
            if el.normal is not None:
                if el.normal not in self.element_names:
                    raise ParameterError(f"friction element {el.name!r}: normal = {el.normal!r} is not an elastic "
                                         f"element of {self.model.name} ({self.element_names})")
                self.fr_nidx[j] = self.element_names.index(el.normal)
                self.fr_mun[j] = el.coefficient
            if el.pressure is not None:
                self.fr_pidx[j] = 1 if el.pressure == "master" else 2
                self.fr_mup[j] = el.pressure_coefficient
            self.fr_rs[j] = max(self.fr_rs[j], el.static_ratio)
            self.friction_names[j] = (self.friction_names[j] + "+" if self.friction_names[j] else "") + el.name

    # ------------------------------------------------------------ names
    def state_variables(self) -> tuple:
        """Named states with units (order of the state vector)."""
        if "states" not in self._names:
            self._names["states"] = variables(self._state_spec())
        return self._names["states"]

    def _state_spec(self) -> tuple:
        pos = [("master_position", "m", "master piston position"),
               ("bearing_position", "m", "release bearing (CSC piston) position")]
        vel = [("master_velocity", "m_s", "master piston velocity"),
               ("bearing_velocity", "m_s", "release bearing velocity")]
        for node in self.asm["independent"]:
            pos.append((f"x_{node}", "m", f"position of network node {node}"))
            vel.append((f"v_{node}", "m_s", f"velocity of network node {node}"))
        return tuple(pos + vel + [
            ("master_pressure", "Pa", "master chamber pressure p_m (gauge)"),
            ("line_flow", "m3_s", "flow Q in the hydraulic line"),
            ("pressure", "Pa", "CSC chamber pressure p_s (gauge)"),
            ("motor_current", "A", "motor current i"),
            ("controller_integral", "V", "integral action of the position controller"),
            ("input_work", "J", "electrical energy into the motor (mechanical at the bearing if prescribed)"),
            ("dissipated", "J", "energy dissipated (resistances, vent, end stops, friction)"),
            ("friction_dissipated", "J", "energy dissipated by the friction elements"),
        ])

    def output_variables(self, imode: int) -> tuple:
        """Named outputs with units (order of the output vector)."""
        key = ("outputs", imode)
        if key not in self._names:
            self._names[key] = variables(self._output_spec(imode))
        return self._names[key]

    def _output_spec(self, imode: int) -> tuple:
        out = list(OUTPUTS) + [INPUT_OUTPUTS[INPUT_MODES[imode]]]
        out += [(f"force_{e}", "N", f"force of network element {e}") for e in self.element_names]
        out += [(f"friction_{self.coord_names[j]}", "N", f"friction force on {self.coord_names[j]}")
                for j in self.friction_outputs]
        return tuple(out)

    def switching(self) -> tuple:
        """Switching functions (name, direction) in the order of the right-hand side."""
        if "switching" not in self._names:
            self._names["switching"] = self._switching_spec()
        return self._names["switching"]

    def _switching_spec(self) -> tuple:
        return (tuple((f"friction_{c}", 0) for c in self.coord_names)
                + tuple((f"contact_{e}", 0) for e in self.element_names)
                + tuple((s, 0) for s in OTHER_SWITCHING))

    def element_name(self, code: int, index: int) -> str:
        """Which element an event concerns: the friction coordinate, network element, end stop or chamber."""
        if code in (EV_STICK, EV_BREAKAWAY, EV_REVERSAL, EV_FREE, EV_ENGAGE):
            return self.coord_names[index]
        if code in (EV_CONTACT_OPEN, EV_CONTACT_CLOSE):
            return self.element_names[index]
        if code in (EV_CAVITATION_START, EV_CAVITATION_END):
            return CHAMBERS[index]
        return STOPS[index]

    def signature(self) -> tuple:
        """What variants of one batch must share: the state, output and mode layout."""
        return (self.nz, tuple(self.coord_names), tuple(self.element_names), self.friction_outputs.tobytes())

    # ------------------------------------------------------------ initial state
    def initial_state(self, u0: float) -> tuple[np.ndarray, np.ndarray]:
        """Static equilibrium at bearing position ``u0`` with the actuator at rest; initial friction modes."""
        cached = self._initial.get(float(u0))
        if cached is not None:
            return cached[0].copy(), cached[1].copy()
        st = solve_static(self.model.network, np.array([u0]))
        X = st["node_positions"][0]
        names = st["node_names"]
        y = np.zeros(self.n)
        y[1] = u0
        for k, node in enumerate(self.asm["independent"]):
            y[2 + k] = X[names.index(node)]
        modes = np.zeros(self.nz, dtype=np.int64)
        # at rest: stuck (the state machine breaks away if the force exceeds the limit), or free where the
        # kinetic level is zero (no Coulomb part, the pressing element unloaded; the chambers start at 0 Pa)
        forces = st["forces"][0]
        for j in np.flatnonzero(self.fr_on):
            fn = forces[st["element_names"].index(self.element_names[self.fr_nidx[j]])] if self.fr_nidx[j] >= 0 else 0.0
            level = self.fr_c0[j] + self.fr_mun[j] * abs(fn)
            modes[j] = STUCK if level > 0.0 else FREE
        self._initial[float(u0)] = (y, modes)
        return y.copy(), modes.copy()

    def rest_position(self) -> float:
        """Bearing position at rest [m]: the CSC preload spring balances the clutch's bearing force.

        With the bundled parameters this is 0 (the bearing origin is set at the
        CSC preload); wear and thermal offsets or another preload move it.

        Raises
        ------
        ParameterError
            If no stable rest position lies within the CSC travel (e.g. a CSC
            preload above the clutch's bearing force everywhere: the clutch
            could not stay engaged).
        """
        a = self.actuator
        lo, hi = a.slave_min, a.slave_max

        def g(u):
            return a.csc_preload - a.csc_spring_rate * u - float(solve_static(self.model.network, [u])["input_force"][0])

        if abs(g(0.0)) < 1e-9:
            return 0.0
        grid = np.concatenate([np.linspace(0.0, hi, 201), np.linspace(0.0, lo, 41)[1:]])
        up = solve_static(self.model.network, grid[:201])["input_force"]
        down = solve_static(self.model.network, grid[201:])["input_force"] if lo < 0 else np.empty(0)
        gu = a.csc_preload - a.csc_spring_rate * grid[:201] - up
        gd = a.csc_preload - a.csc_spring_rate * grid[201:] - down
        from scipy.optimize import brentq

        if gu[0] > 0:  # pushed towards release: first stable root (g from + to -) going up
            k = np.flatnonzero((gu[:-1] > 0) & (gu[1:] <= 0))
            if k.size:
                return float(brentq(g, grid[k[0]], grid[k[0] + 1], xtol=1e-13))
        else:  # pulled towards the engaged side
            uu = np.concatenate([[0.0], grid[201:]])
            gg = np.concatenate([[gu[0]], gd])
            k = np.flatnonzero((gg[:-1] <= 0) & (gg[1:] > 0))
            if k.size:
                return float(brentq(g, uu[k[0] + 1], uu[k[0]], xtol=1e-13))
        if start_checks_deferred():   # (a native FMU's trial build: its start refuses it, start_at_rest)
            return 0.0
        raise ParameterError(
            f"inconsistent parameters: with csc_preload = {a.csc_preload!r} N the CSC finds no rest position within "
            f"its travel [{lo:g}, {hi:g}] m (the clutch's bearing force at position 0 is {a.csc_preload - g(0.0):.4g} N; "
            "EClutchParameters.bearing_preload and ActuatorParameters.csc_preload should match)")

    # ------------------------------------------------------------ packing
    def _packed(self) -> tuple:
        """The constant arrays of :class:`EClutchParams` (packed once per structure; read-only in the hooks)."""
        if self._constant is None:
            a = self.asm
            n_el = len(self.element_names)
            f64 = lambda v: np.ascontiguousarray(v, dtype=np.float64)  # noqa: E731
            coord = f64(np.stack([self.mass, self.fr_c0, self.fr_mun, self.fr_mup, self.fr_rs, self.fr_c]))
            coord_int = np.ascontiguousarray(np.stack([self.fr_on.astype(np.int64), self.fr_nidx, self.fr_pidx]),
                                             dtype=np.int64)
            net = f64(np.stack([a["d0"], a["Gb"], self.scale]))
            net_int = np.zeros((4, n_el + 1), dtype=np.int64)
            net_int[NI_OFFSETS] = self.offsets
            net_int[NI_KINDS, :n_el] = self.kinds
            net_int[NI_EXTRAPS, :n_el] = self.extraps
            net_int[NI_UNILATERAL, :n_el] = self.unilateral
            curve = f64(np.stack([self.cx, self.cf, self.cd]))
            # (a preset's derived pre-deflections are the network's, built in Python by build_model; a
            # co-simulation's start derives them again, compiled: derive_clutch, equal to 1e-17 m)
            self._constant = (f64(self.par), coord, coord_int, np.ascontiguousarray(self.friction_outputs, np.int64),
                              f64(a["GA"]), net, net_int, curve, self.clutch.copy(), self.clutch_int.copy())
        return self._constant

    def params(self, imode: int, tin, vin, interp: int, at_start: bool = False) -> EClutchParams:
        """The packed parameters of one run (fresh scratch arrays: one per run or batch variant).

        Parameters
        ----------
        imode : int
            :data:`VOLTAGE`, :data:`POSITION` or :data:`PRESCRIBED`.
        tin, vin : array_like
            Input table: times [s] and values [V or m]; empty: the held input ``u[0]`` is the input.
        interp : int
            0 linear between rows, 1 held.
        at_start : bool
            The start derives the preset's pre-deflections and the state at rest again (:func:`eclutch_start`; a
            co-simulation, whose host may set the parameters).
        """
        par, coord, coord_int, fo, GA, net, net_int, curve, clutch, clutch_int = self._packed()
        width = max(self.n, len(self.switching()), N_AUX + self.nz, 2 + self.n + self.nz)
        if at_start:   # (the start writes the pre-deflections and the rest position: this run's own copies)
            net, clutch, clutch_int = net.copy(), clutch.copy(), clutch_int.copy()
            clutch_int[CLI_AT_START] = 1
        return EClutchParams(
            int(self.nz), int(imode), int(interp), np.ascontiguousarray(tin, dtype=np.float64),
            np.ascontiguousarray(vin, dtype=np.float64), par, coord, coord_int, fo, GA, net, net_int, curve,
            int(self.normal_element), float(self.model.r_eff), float(self.model.mu), np.zeros((N_WORK, width)),
            clutch, clutch_int, *self.model0)

    def system(self, imode: int, tin, vin, interp: int, u0: float, *, held_input: bool = False,
               rtol: float = 1e-3, max_step: float = 0.01, event_tol: float = 1e-8, jac_every: int = 10,
               atol_scale: float = 1.0, first_step: float = 1e-5, at_start: bool = False) -> System:
        """The :class:`~clutchlab.system.System` of one run.

        Parameters
        ----------
        imode : int
            :data:`VOLTAGE`, :data:`POSITION` or :data:`PRESCRIBED`.
        tin, vin : ndarray
            Input table (times [s], values [V or m]); ignored with ``held_input``.
        interp : int
            0 linear between rows, 1 held.
        u0 : float
            Bearing position at the start [m] (static equilibrium of the clutch there).
        held_input : bool
            The input is the system's held input ``u[0]`` (co-simulation), not a table; its start value is
            ``vin[0]``.
        rtol, max_step, event_tol, first_step : float
            Defaults of the run: relative tolerance, largest step [s], event bracket [s], first step [s].
        jac_every : int
            Accepted steps a finite-difference Jacobian is kept.
        atol_scale : float
            Factor on the default absolute tolerances.
        at_start : bool
            The run's start derives the preset's pre-deflections, the rest position and the state at rest again
            (``u0`` must be the rest position; a co-simulation, whose host may set the parameters:
            :func:`eclutch_start`).
        """
        if not (np.isfinite(atol_scale) and atol_scale > 0):
            raise ParameterError(f"atol_scale = {atol_scale!r} must be finite and > 0")
        tin = np.asarray(tin, dtype=float)
        vin = np.asarray(vin, dtype=float)
        # a run asked for again (controller design, Monte Carlo by hand, benchmarks): the same System with a
        # fresh parameter structure (its scratch rows belong to one run), without building and checking the
        # System again (tens of microseconds against a run of about a millisecond)
        key = (int(imode), tin.tobytes(), vin.tobytes(), int(interp), float(u0), bool(held_input), float(rtol),
               float(max_step), float(event_tol), int(jac_every), float(atol_scale), float(first_step), bool(at_start))
        known = self._systems.get(key)
        if known is not None:
            params = known.params
            return known.variant(params=params._replace(work=np.zeros_like(params.work)))
        if at_start:   # (the start's clutch derivation, called through its address: compiled here, on this thread)
            prepare(groups=("eclutch_cosim",), ungrouped=False)
        system = self._build_system(imode, tin, vin, interp, u0, held_input, rtol, max_step, event_tol, jac_every,
                                    atol_scale, first_step, bool(at_start))
        if len(self._systems) >= 16:
            self._systems.pop(next(iter(self._systems)))
        self._systems[key] = system
        return system

    def _build_system(self, imode, tin, vin, interp, u0, held_input, rtol, max_step, event_tol, jac_every,
                      atol_scale, first_step, at_start) -> System:
        x0, m0 = self.initial_state(u0)
        name = {VOLTAGE: ("motor_voltage", "V"), POSITION: ("bearing_reference", "m"),
                PRESCRIBED: ("bearing_position", "m")}[imode]
        if held_input:
            inputs, u_start = (name,), np.array([float(vin[0])])
            params = self.params(imode, np.empty(0), np.empty(0), interp, at_start)
            nonauto = False
            segments = ("held input",)
        else:
            inputs, u_start = (), None
            params = self.params(imode, tin, vin, interp, at_start)
            # inputs that vary inside a step: a linear table (position reference, prescribed motion)
            nonauto = tin.size > 1 and (imode != VOLTAGE or interp == 0)
            segments = ("before the table",) + tuple(f"row {k} ({t:g} s)" for k, t in enumerate(tin))
        # the active row of the input table is a mode (see reference()); restart() sets it at t0
        m0 = np.append(m0, 0 if held_input else int(np.searchsorted(tin, 0.0, side="right")))
        n_jac = 2 * self.nz + 5  # the energy states enter no equation
        return System(
            name="eclutch" if not self.prescribed else "eclutch_clutch", params=params,
            states=self.state_variables(), outputs=self.output_variables(imode), x0=x0, m0=m0,
            atol=self.atol * atol_scale, switching=self.switching(), events=EVENTS,
            mode_names=tuple(f"friction_mode_{c}" for c in self.coord_names) + ("input_segment",),
            mode_values=tuple(MODE_VALUES for _ in self.coord_names) + (segments,), inputs=inputs, u0=u_start, method="rodas",
            mass=self.mvec, jac_cols=np.arange(n_jac), fd_scale=self.typ, nonautonomous=bool(nonauto),
            jac_every=int(jac_every), rtol=float(rtol), max_step=float(max_step), first_step=float(first_step),
            event_tol=float(event_tol), element_name=self.element_name, limits=self.limits(),
            decided_at_start=tuple(("params.par", k, k + 1) for k in indices(ACTUATOR_VECTOR, *DERIVED_PAR))
            + (("params.coord", CO_MASS * self.nz, CO_MASS * self.nz + 1),)   # (coord[CO_MASS, 0], C order)
            + ((("params.coord", CO_MU_PRESSURE * self.nz, CO_MU_PRESSURE * self.nz + 1),) if not self.prescribed
               else ())
            + (self._derived_at_start() if at_start else ()),
            error_messages=dict(ERROR_MESSAGES),
        )

    def _derived_at_start(self) -> tuple:
        """The words a co-simulation's start writes beyond the actuator's (:func:`eclutch_start`): the preset's
        derived pre-deflections (``net[NE_D0]`` of the bearing, the lever, the pressure-plate spring and the
        support), the rest position, the bearing's and the nodes' positions and the friction modes."""
        n_el = len(self.element_names)
        out = [("params.net", NE_D0 * n_el + e, NE_D0 * n_el + e + 1)
               for e in self.clutch_int[[CLI_BEARING, CLI_LEVER, CLI_PP_SPRING, CLI_SUPPORT]] if e >= 0]
        return tuple(out) + (("params.clutch", CL_REST, CL_REST + 1), ("x", 1, self.nz), ("m", 0, self.nz))

    def limits(self) -> dict:
        """Physical range of the actuator [SI]: CSC travel, master stroke, supply voltage, current limit."""
        a = self.actuator
        if a is None:  # the clutch alone, its bearing moved by a prescribed input
            return {}
        travel = (float(a.slave_min), float(a.slave_max))
        return {"bearing_position": travel, "bearing_reference": travel, "master_position": (0.0, float(a.master_stroke)),
                "motor_voltage": (-float(a.supply_voltage), float(a.supply_voltage)),
                "motor_current": (-float(a.current_limit), float(a.current_limit))}
