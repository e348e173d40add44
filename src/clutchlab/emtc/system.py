"""The AWD vehicle with the EMTC on the drum bench as a system of the core contract ([1], Secs. 3-4).

This module is the model, written once: the packed parameters (:class:`EmtcParams`, built only by
:func:`pack_parameters`), the equations as scalar compiled functions, the hooks of
:mod:`clutchlab.numerics.dispatch` and the :class:`~clutchlab.system.System` factory
:func:`bench_system` (registered as ``"emtc_bench"``).  :func:`simulate` is the uniform entry point;
:func:`clutchlab.emtc.simulate_bench` and :class:`clutchlab.fmu.cosim.EmtcCoSimulation` are thin layers
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
  magnet with :func:`~clutchlab.hysteresis._kernels.peek_combined` and advance the bristles from their
  committed value;
* a full hysteresis memory is a model error (codes in :data:`ERROR_MESSAGES`), not a solver status.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numba
import numpy as np

from ..errors import ParameterError, SimulationError
from ..hysteresis._kernels import combine_tables, commit, gap_weights, invert_one, peek_combined
from ..numerics import FASTMATH, dispatch
from ..numerics.core import record
from ..system import System, register_model
from ._lookup import bilinear, interp1
from .friction import coupling_torque_scalar, drag_torque_scalar, lugre_advance, lugre_mu, stribeck_g
from .torque import UNLOCK_MARGIN, _cam_force, _locked, _locked_capacity, _slipping

__all__ = ["EmtcParams", "BenchOptions", "pack_parameters", "bench_system", "simulate", "STATES", "OUTPUTS",
           "INPUTS", "SWITCHING", "EVENTS", "EVENT_DESCRIPTIONS", "MODE_NAMES", "MODE_VALUES", "ERROR_MESSAGES",
           "memory_full", "run", "run_controller",
           "armature_acceleration", "primary_clamp_force", "bench_loads", "lock_torque", "commanded_magnet_force",
           "plant_magnet_force"]

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
)
#: switching functions and their crossing direction (all: falling through zero, [1] Fig. 11)
SWITCHING = (
    ("armature_reaches_rest", -1),
    ("armature_reaches_clutch", -1),
    ("magnet_overcomes_preload", -1),
    ("clamp_force_vanishes", -1),
    ("slip_speed_zero", -1),
    ("lock_capacity_exceeded", -1),
)
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

EV_ARM_REST, EV_ARM_CONTACT, EV_ARM_LEAVE_REST, EV_ARM_LEAVE_CONTACT, EV_LOCK, EV_SLIP_REVERSAL, EV_UNLOCK = range(7)
EL_ARMATURE, EL_COUPLING = 0, 1
ARM_REST, ARM_FREE, ARM_CONTACT = 0, 1, 2
OPEN, SLIPPING, LOCKED = 0, 1, 2
NEGATIVE, POSITIVE = 0, 1
U_TORQUE, U_THROTTLE, U_DRUM_FRONT, U_DRUM_REAR = range(4)
FRICTION_CONSTANT, FRICTION_MAP, FRICTION_LUGRE = 0, 1, 2
REFERENCE_MAP, REFERENCE_TABLE, REFERENCE_INPUT = 0, 1, 2

# model errors (negative codes of the hooks)
ERR_PLANT_MEMORY, ERR_CONTROLLER_MEMORY = -1, -2
ERROR_MESSAGES = {
    ERR_PLANT_MEMORY: "the plant magnet's hysteresis memory is full (BenchOptions.memory_capacity)",
    ERR_CONTROLLER_MEMORY: "the controller model's hysteresis memory is full (BenchOptions.memory_capacity)",
}

# per-run memories: integers and floats (see EmtcParams.imem / fmem)
IM_PLEN, IM_CLEN, IM_KNEXT, IM_ERROR = range(4)
N_IMEM = 4
FM_PU, FM_CU, FM_CMD, FM_TREF, FM_FEASIBLE, FM_Z, FM_TLAST, FM_DWLAST = range(8)
N_FMEM = 8
# model intermediates (EmtcParams.aux)
(AUX_FM, AUX_FN1, AUX_T1, AUX_T2, AUX_T3, AUX_TC, AUX_TLOCK, AUX_TTRANS, AUX_CAP, AUX_CASE, AUX_FN2, AUX_TE,
 AUX_THR) = range(13)
N_AUX = 13
# controller log (one row per sample, for the per-sample view of simulate_bench)
LOG_CMD, LOG_TREF, LOG_THR, LOG_FEASIBLE = range(4)

ATOL = np.array([1e-4, 1e-4, 1e-7, 1e-9, 1e-6, 1e-5, 1e-5])


class EmtcParams(NamedTuple):
    """Packed parameters and per-run memories of the EMTC drum-bench model (SI; built by :func:`pack_parameters`).

    Scalars are the vehicle (Table 1 of [1] and representative values), bench, actuator and controller
    data; arrays are the coupling geometry (:meth:`CouplingGeometry.kernel_data`), friction data, input
    profiles (an empty profile takes the held input), the torque map (Eq. 31), the plant and controller
    Preisach tables, and the mutable memories of one run: hysteresis stacks and prefix sums, ``imem``
    (memory lengths, next controller sample, error), ``fmem`` (last memory inputs, held command, bristle
    state), the airgap-weight cache and scratch arrays.  One instance per run (or batch variant).
    """

    front_final_drive: float
    axle_ratio: float
    gear_ratio: float
    inertia_front: float
    inertia_rear: float
    tyre_radius: float
    axle_load_front: float
    axle_load_rear: float
    rolling_resistance: float
    tyre_slip_stiffness: float
    slip_speed_floor: float
    engine_torque_max: float
    engine_power: float
    torsen_stiffness: float
    torsen_damping: float
    temperature_c: float
    drag_pairs: float
    oil_viscosity: float
    plate_clearance: float
    plate_outer_radius: float
    plate_inner_radius: float
    unlock_margin: float
    sample_time: float
    drum_load_front: float
    drum_load_rear: float
    armature_mass: float
    spring_stiffness: float
    spring_preload: float
    spring_damping: float
    free_travel: float
    airgap_open: float
    tau1: float
    tau2: float
    friction_mode: int
    reference_source: int
    geometry: np.ndarray
    lugre: np.ndarray
    fmap_speed: np.ndarray
    fmap_temperature: np.ndarray
    fmap_mu: np.ndarray
    throttle_time: np.ndarray
    throttle_value: np.ndarray
    drum_front_time: np.ndarray
    drum_front_value: np.ndarray
    drum_rear_time: np.ndarray
    drum_rear_value: np.ndarray
    map_throttle: np.ndarray
    map_speed: np.ndarray
    map_torque: np.ndarray
    reference_time: np.ndarray
    reference_value: np.ndarray
    plant_tables: np.ndarray
    plant_grid: np.ndarray
    plant_airgaps: np.ndarray
    plant_stack: np.ndarray
    plant_prefix: np.ndarray
    ctl_tables: np.ndarray
    ctl_grid: np.ndarray
    ctl_airgaps: np.ndarray
    ctl_stack: np.ndarray
    ctl_prefix: np.ndarray
    imem: np.ndarray
    fmem: np.ndarray
    u_last: np.ndarray
    gap_idx: np.ndarray
    gap_w: np.ndarray
    gap_comb: np.ndarray
    ctl_idx: np.ndarray
    ctl_w: np.ndarray
    aux: np.ndarray
    dxw: np.ndarray
    gw: np.ndarray
    split: np.ndarray
    ctl_log: np.ndarray


# ------------------------------------------------------------------ equations (one scalar function each)
@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def plant_magnet_force(current, gap, p):
    """Magnet force of the plant at a coil current and airgap, memory not committed ([1], Eqs. 1-5, Sec. 2.1).

    The Preisach output of the plant's memory for the next input ``current`` [A] (clamped to the grid),
    interpolated over the calibration airgaps at ``gap`` [m] (clamped to their range).  While the airgap
    does not change (armature at a stop) the airgap-weighted cell table is reused (``gap_w[3]`` holds the
    airgap it was built for).  Returns [N].
    """
    grid = p.plant_grid
    i = min(max(current, grid[0]), grid[grid.shape[0] - 1])
    w = p.gap_w
    if gap != w[3]:
        gaps = p.plant_airgaps
        gap_weights(gaps, min(max(gap, gaps[0]), gaps[gaps.shape[0] - 1]), p.gap_idx, w)
        combine_tables(p.plant_tables, p.gap_idx, w, p.gap_comb)
        w[3] = gap
    return peek_combined(p.gap_comb, grid, p.plant_stack, p.plant_prefix, p.imem[IM_PLEN], p.fmem[FM_PU], i,
                         p.gap_idx, w)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def armature_acceleration(fm, x, v, p):
    """Acceleration of the free armature ([1], Eq. 9 with ``F_n0 = F_n1 = 0``) [m/s^2].

    ``m0 a = F_m - F_k0 - K x - c v`` with the magnet force ``fm`` [N], displacement ``x`` [m] and speed
    ``v`` [m/s]; mass, spring and damping from ``p``.
    """
    return (fm - p.spring_preload - p.spring_stiffness * x - p.spring_damping * v) / p.armature_mass  # [1], Eq. 9


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def primary_clamp_force(fm, p):
    """Force of the armature on the primary clutch at ``x = sigma``: ``F_m - F_k0 - K sigma`` ([1], Eq. 11) [N].

    Negative values mean the armature leaves the clutch (the clamp force itself is ``max(., 0)``).
    """
    return fm - p.spring_preload - p.spring_stiffness * p.free_travel  # [1], Eq. 11


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def bench_loads(wf, wr, throttle, v_front, v_rear, p):
    """Loads on the two coupling shafts of the vehicle on the drum bench ([1], Eq. 27, rows 1+3 and 2+4).

    ``J_F dw_f/dt = A_f - T_c``, ``J_R dw_r/dt = T_c - A_r`` with ``A_f = (T_trans i0 - F_xf r - T_ff)/i``,
    ``A_r = (F_xr r + T_fr)/i`` at the shaft speeds ``wf``, ``wr`` [rad/s], throttle [-] and drum surface
    speeds [m/s].  Tyre force on a drum ``F_x = 2 C_x r (w_w r - v_d)/max(|v_d|, v_floor)`` per axle,
    rolling resistance ``f_rr F_z r tanh(w_w / 0.5 rad/s)`` plus the drum load, engine torque
    ``throttle min(T_max, P/w_e)`` (clutchlab's assumptions: the paper does not model the tyre-drum
    contact or the engine).  Returns ``(A_f, A_r, T_e, T_trans)`` [N*m].
    """
    ic = p.axle_ratio
    rw = p.tyre_radius
    wwf = wf / ic
    wwr = wr / ic
    kf = 2.0 * p.tyre_slip_stiffness * rw / max(abs(v_front), p.slip_speed_floor)
    kr = 2.0 * p.tyre_slip_stiffness * rw / max(abs(v_rear), p.slip_speed_floor)
    fxf = kf * (wwf * rw - v_front)  # tyre-drum longitudinal force, both wheels
    fxr = kr * (wwr * rw - v_rear)
    rrf = p.rolling_resistance * p.axle_load_front * rw * math.tanh(wwf / 0.5) + p.drum_load_front
    rrr = p.rolling_resistance * p.axle_load_rear * rw * math.tanh(wwr / 0.5) + p.drum_load_rear
    we = abs(wwf) * p.front_final_drive * p.gear_ratio
    te = throttle * min(p.engine_torque_max, p.engine_power / max(we, 1.0))
    ttrans = te * p.gear_ratio
    a_f = (ttrans * p.front_final_drive - fxf * rw - rrf) / ic  # [1], Eq. 27: front loads at the coupling shaft
    a_r = (fxr * rw + rrr) / ic
    return a_f, a_r, te, ttrans


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def lock_torque(a_f, a_r, p):
    """Torque that keeps both shafts at the same acceleration, ``(J_R A_f + J_F A_r)/(J_F + J_R)`` ([1], Eq. 29) [N*m]."""
    return (p.inertia_rear * a_f + p.inertia_front * a_r) / (p.inertia_front + p.inertia_rear)  # [1], Eq. 29


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def commanded_magnet_force(t_ref, p):
    """Magnet force the controller asks for to transfer ``t_ref`` [N*m] in slipping mode ([1], Eqs. 13, 15, 11).

    ``F_n1 = T_ref / (T_c/F_n1)`` with the slipping-mode torque per newton of Eqs. 13-15 at the kinetic
    coefficients, then ``F_m = F_n1 + F_k0 + K sigma`` (Eq. 11 solved for ``F_m``); 0 for ``t_ref <= 0``.
    Returns [N].
    """
    if not t_ref > 0.0:
        return 0.0
    g = p.geometry
    s = p.split
    _slipping(1.0, 1.0, g, g[0], g[1], g[2], s)  # [1], Eqs. 13-15 per newton of F_n1
    return t_ref / (s[0] + s[1] + s[2]) + p.spring_preload + p.spring_stiffness * p.free_travel  # [1], Eq. 11


# ------------------------------------------------------------------ the model
@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _profile(tx, ty, u, k, t):
    """Input profile at ``t``, or the held input ``u[k]`` where the profile is empty."""
    if tx.shape[0] == 0:
        return u[k]
    return interp1(tx, ty, t)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _model(t, x, u, m, p, dx, aux):
    """Right-hand side ``dx`` and intermediates ``aux`` ([1], Eqs. 8-30, Fig. 15) in the modes ``m``."""
    arm = m[0]
    cpl = m[1]
    wf = x[0]
    wr = x[1]
    xa = x[3]
    xd = x[4]
    fm = plant_magnet_force(x[6], p.airgap_open - xa, p)  # [1], Eq. 12: airgap d - x
    fn1 = 0.0
    if arm == ARM_FREE:
        dx[3] = xd
        dx[4] = armature_acceleration(fm, xa, xd, p)
    else:
        dx[3] = 0.0
        dx[4] = 0.0
        if arm == ARM_CONTACT:
            fn1 = max(primary_clamp_force(fm, p), 0.0)
    # current control: two first-order lags in series ([1], Fig. 15)
    dx[5] = (p.fmem[FM_CMD] - x[5]) / p.tau1
    dx[6] = (x[5] - x[6]) / p.tau2
    thr = _profile(p.throttle_time, p.throttle_value, u, U_THROTTLE, t)
    vdf = _profile(p.drum_front_time, p.drum_front_value, u, U_DRUM_FRONT, t)
    vdr = _profile(p.drum_rear_time, p.drum_rear_value, u, U_DRUM_REAR, t)
    a_f, a_r, te, ttrans = bench_loads(wf, wr, thr, vdf, vdr, p)
    tlock = lock_torque(a_f, a_r, p)
    dw = wf - wr
    g = p.geometry
    s = p.split
    t1 = 0.0
    t2 = 0.0
    t3 = 0.0
    case = -1.0
    fn2 = 0.0
    t_drag = 0.0
    if cpl == OPEN:
        t_drag = drag_torque_scalar(p.drag_pairs, p.oil_viscosity, dw, p.plate_clearance, p.plate_outer_radius,
                                    p.plate_inner_radius)  # [1], Eq. 25
        t_fric = 0.0
        dx[2] = 0.0
    elif cpl == SLIPPING:
        # kinetic friction in the slip direction of the mode: the slip crossing zero is an event (lock-up or
        # reversal, Fig. 11) located by the core, not a sign change inside the mode (that would make the slip
        # slide along zero until a step happened to end past it; see docs/emtc.md)
        sl = 1.0 if m[2] == POSITIVE else -1.0
        if p.friction_mode == FRICTION_MAP:
            m1 = bilinear(p.fmap_speed, p.fmap_temperature, p.fmap_mu, abs(dw), p.temperature_c)
            m2 = m1
            m3 = m1
        elif p.friction_mode == FRICTION_LUGRE:
            # [1], Eqs. 22-23: bristles advanced exactly from their committed value at the step start
            tlast = p.fmem[FM_TLAST]
            zb = lugre_advance(p.fmem[FM_Z], dw, t - tlast if tlast == tlast else 0.0, p.lugre)
            mu = lugre_mu(zb, dw, p.lugre)
            if mu != 0.0:
                sl = mu
            m1 = abs(mu)
            m2 = m1
            m3 = m1
        else:
            m1 = g[0]
            m2 = g[1]
            m3 = g[2]
        _slipping(fn1, sl, g, m1, m2, m3, s)  # [1], Eqs. 13-15
        t1 = s[0]
        t2 = s[1]
        t3 = s[2]
        t_fric = t1 + t2 + t3  # [1], Eq. 17
        fn2 = _cam_force(t1, t3, g)  # [1], Eq. 14
        dx[2] = 0.0
    else:
        tl = tlock + p.torsen_stiffness * x[2] + p.torsen_damping * dw  # [1], Eq. 30
        code = _locked(fn1, tl, g, p.unlock_margin, s)  # [1], Eqs. 18-21
        if code >= 0:
            t1 = s[0]
            t2 = s[1]
            t3 = s[2]
            case = code
        else:  # beyond the margin (only inside a step before the unlock event is located)
            t1 = tl
        t_fric = tl
        fn2 = _cam_force(t1, t3, g)
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
    aux[AUX_CAP] = _locked_capacity(fn1, g)  # [1], Eq. 21
    aux[AUX_CASE] = case
    aux[AUX_FN2] = fn2
    aux[AUX_TE] = te
    aux[AUX_THR] = thr
    dx[0] = (a_f - tc) / p.inertia_front  # [1], Eq. 27 (rows 1 and 3)
    dx[1] = (tc - a_r) / p.inertia_rear  # [1], Eq. 27 (rows 2 and 4)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _switching(x, m, p, aux, g):
    """Switching functions (:data:`SWITCHING`); inactive ones are +1."""
    for k in range(6):
        g[k] = 1.0
    arm = m[0]
    if arm == ARM_FREE:
        g[0] = x[3]  # reaches the rest stop
        g[1] = p.free_travel - x[3]  # reaches the primary clutch (x = sigma)
    elif arm == ARM_REST:
        g[2] = p.spring_preload - aux[AUX_FM]  # the magnet overcomes the preload
    else:
        g[3] = primary_clamp_force(aux[AUX_FM], p)  # F_n1 of Eq. 11 drops to zero
    if m[1] == SLIPPING:
        g[4] = (1.0 if m[2] == POSITIVE else -1.0) * (x[0] - x[1])  # slip speed reaches zero
    elif m[1] == LOCKED:
        g[5] = p.unlock_margin * aux[AUX_CAP] - abs(aux[AUX_TC])  # |T'_lock| > 1.02 T_cap_L


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _switch(k, t, x, u, m, p, log):
    """Mode change when switching function ``k`` crossed at ``t`` ([1], Eqs. 8-11, Fig. 11); records the event."""
    fmem = p.fmem
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
        x[3] = p.free_travel  # plastic impact on the primary clutch: engaged
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
        aux = p.aux
        _model(t, x, u, m, p, p.dxw, aux)
        if abs(aux[AUX_TLOCK]) <= aux[AUX_CAP]:
            wm = (x[0] * p.inertia_front + x[1] * p.inertia_rear) / (p.inertia_front + p.inertia_rear)
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
        aux = p.aux
        _model(t, x, u, m, p, p.dxw, aux)
        m[1] = SLIPPING
        m[2] = POSITIVE if aux[AUX_TC] >= 0.0 else NEGATIVE
        x[2] = 0.0
        if p.friction_mode == FRICTION_LUGRE:  # breakaway: bristles at full static deflection
            fmem[FM_Z] = p.lugre[4] / p.lugre[0] * (1.0 if m[2] == POSITIVE else -1.0)
        record(log, t, EV_UNLOCK, EL_COUPLING)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _commit(t, x, p):
    """Commit the plant magnet memory and the LuGre bristle state at the end of an accepted step (once per ``t``)."""
    fmem = p.fmem
    if t == fmem[FM_TLAST]:
        return 0
    grid = p.plant_grid
    inew = min(max(x[6], grid[0]), grid[grid.shape[0] - 1])
    plen = p.imem[IM_PLEN]
    if plen + 2 > p.plant_stack.shape[0]:
        return ERR_PLANT_MEMORY
    p.imem[IM_PLEN] = commit(p.plant_tables, grid, p.plant_stack, p.plant_prefix, plen, fmem[FM_PU], inew)
    fmem[FM_PU] = inew
    tlast = fmem[FM_TLAST]
    if p.friction_mode == FRICTION_LUGRE and tlast == tlast:  # exact update at the mid-step slip (Eq. 23)
        dw_mid = 0.5 * ((x[0] - x[1]) + fmem[FM_DWLAST])
        fmem[FM_Z] = lugre_advance(fmem[FM_Z], dw_mid, t - tlast, p.lugre)
    fmem[FM_TLAST] = t
    return 0


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=FASTMATH)
def _controller(t, x, u, p):
    """One controller sample at ``t``: reference (Eq. 31, table or input), force (Eqs. 13, 15, 11), current (Eqs. 6-7)."""
    thr = _profile(p.throttle_time, p.throttle_value, u, U_THROTTLE, t)
    if p.reference_source == REFERENCE_INPUT:
        t_ref = u[U_TORQUE]
    elif p.reference_source == REFERENCE_TABLE:
        t_ref = interp1(p.reference_time, p.reference_value, t)
    else:
        vx = x[0] / p.axle_ratio * p.tyre_radius
        t_ref = bilinear(p.map_throttle, p.map_speed, p.map_torque, thr, vx)  # [1], Eq. 31
    fm_req = commanded_magnet_force(t_ref, p)
    imem = p.imem
    fmem = p.fmem
    clen = imem[IM_CLEN]
    if clen + 2 > p.ctl_stack.shape[0]:
        imem[IM_ERROR] = ERR_CONTROLLER_MEMORY  # reported by the next accepted step
        return
    cg = p.ctl_airgaps
    gap_weights(cg, min(max(p.airgap_open - p.free_travel, cg[0]), cg[cg.shape[0] - 1]), p.ctl_idx, p.ctl_w)
    cu = fmem[FM_CU]
    i_new, ok = invert_one(p.ctl_tables, p.ctl_grid, p.ctl_stack, p.ctl_prefix, clen, cu, fm_req, p.ctl_idx,
                           p.ctl_w, 1e-9)  # [1], Eqs. 6-7 at the engaged airgap d - sigma
    imem[IM_CLEN] = commit(p.ctl_tables, p.ctl_grid, p.ctl_stack, p.ctl_prefix, clen, cu, i_new)
    fmem[FM_CU] = i_new
    fmem[FM_CMD] = i_new
    fmem[FM_TREF] = t_ref
    fmem[FM_FEASIBLE] = 1.0 if ok else 0.0
    k = imem[IM_KNEXT]
    if k < p.ctl_log.shape[0]:
        p.ctl_log[k, LOG_CMD] = i_new
        p.ctl_log[k, LOG_TREF] = t_ref
        p.ctl_log[k, LOG_THR] = thr
        p.ctl_log[k, LOG_FEASIBLE] = 1.0 if ok else 0.0


# ------------------------------------------------------------------ the hooks of the contract
@numba.njit(cache=True, nogil=True)
def _rhs(t, x, u, m, p, dx, g):
    _model(t, x, u, m, p, dx, p.aux)
    _switching(x, m, p, p.aux, g)


@numba.njit(cache=True, nogil=True)
def _outputs(t, x, u, m, p, y):
    aux = p.aux
    _model(t, x, u, m, p, p.dxw, aux)
    fmem = p.fmem
    y[0] = x[0] - x[1]
    y[1] = p.airgap_open - x[3]
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
    y[14] = fmem[FM_CMD]
    y[15] = fmem[FM_TREF]
    y[16] = aux[AUX_THR]
    y[17] = fmem[FM_FEASIBLE]


@numba.njit(cache=True, nogil=True)
def _update(t, x, u, m, p, k, log):
    r = _commit(t, x, p)  # the memories see the state at the event, before the mode change
    if r < 0:
        return r
    _switch(k, t, x, u, m, p, log)
    return 0


@numba.njit(cache=True, nogil=True)
def _restart(t, x, u, m, p, log):
    fmem = p.fmem
    imem = p.imem
    changed = False
    if fmem[FM_TLAST] != fmem[FM_TLAST]:  # first start: the memories begin here
        fmem[FM_TLAST] = t
        fmem[FM_DWLAST] = x[0] - x[1]
    ts = p.sample_time
    k = imem[IM_KNEXT]
    if t >= k * ts - 1e-9 * ts:  # a controller sample is due (break time, or a resumed run that starts on it)
        _controller(t, x, u, p)
        k += 1
        while k * ts <= t + 1e-9 * ts:
            k += 1
        imem[IM_KNEXT] = k
        changed = True
    # held inputs that jumped (a resumed co-simulation step, or the start) may leave a mode inconsistent
    jumped = False
    ul = p.u_last
    for q in range(u.shape[0]):
        if u[q] != ul[q]:
            jumped = True
            ul[q] = u[q]
    if jumped:
        for _ in range(3):
            _model(t, x, u, m, p, p.dxw, p.aux)
            _switching(x, m, p, p.aux, p.gw)
            gw = p.gw
            kk = -1
            if m[0] == ARM_REST and gw[2] < 0.0:
                kk = 2
            elif m[0] == ARM_CONTACT and gw[3] < 0.0:
                kk = 3
            elif m[1] == LOCKED and gw[5] < 0.0:
                kk = 5
            if kk < 0:
                break
            _switch(kk, t, x, u, m, p, log)
            changed = True
    return changed


@numba.njit(cache=True, nogil=True)
def _accept(t, x, u, m, p):
    e = p.imem[IM_ERROR]
    if e != 0:
        return e
    r = _commit(t, x, p)
    if r < 0:
        p.imem[IM_ERROR] = r
        return r
    p.fmem[FM_DWLAST] = x[0] - x[1]
    # the committed bristle state changes the friction: the derivative at the new point must be recomputed
    return 1 if p.friction_mode == FRICTION_LUGRE else 0


@numba.njit(cache=True, nogil=True)
def _next_break(t, m, p):
    return p.imem[IM_KNEXT] * p.sample_time


@numba.njit(cache=True, nogil=True)
def _jacobian(t, x, u, m, p, J):
    return False


@numba.njit(cache=True, nogil=True)
def run_controller(p, t, x, u):
    """Run the controller sample that is due at ``t`` (the last sample of a run, whose break never comes)."""
    k = p.imem[IM_KNEXT]
    if t >= k * p.sample_time - 1e-9 * p.sample_time:
        _controller(t, x, u, p)
        p.imem[IM_KNEXT] = k + 1


dispatch.register(EmtcParams, rhs=_rhs, outputs=_outputs, update=_update, restart=_restart, accept=_accept,
                  next_break=_next_break, jacobian=_jacobian)


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
    memory_capacity: int = 64

    def __post_init__(self):
        if self.friction_map is not None and self.lugre is not None:
            raise ParameterError("give either friction_map or lugre, not both")
        if not (isinstance(self.memory_capacity, (int, np.integer)) and self.memory_capacity >= 4):
            raise ParameterError(f"memory_capacity = {self.memory_capacity!r}: expected a whole number >= 4")


def _f(a):
    return np.ascontiguousarray(a, dtype=np.float64)


_EMPTY = np.zeros(0)


def pack_parameters(magnet, scenario=None, vehicle=None, options: BenchOptions | None = None, *,
                    cosimulation: bool = False, n_samples: int = 0) -> EmtcParams:
    """Pack the drum-bench model's parameters and fresh per-run memories into :class:`EmtcParams`.

    Parameters
    ----------
    magnet : clutchlab.hysteresis.Preisach
        Plant magnet force [N] vs coil current [A] (and airgap [m]).
    scenario : BenchScenario, optional
        Gear, drum speeds and loads, throttle ramp, temperature, sample time (default: the defaults).
    vehicle : VehicleParameters, optional
        Default: Table 1 of [1] and representative values.
    options : BenchOptions, optional
        Actuator, coupling, torque map, controller model, friction, reference, memory capacity.
    cosimulation : bool
        Throttle, drum speeds and torque request from the held inputs instead of the scenario's
        ramp and map (co-simulation).
    n_samples : int
        Rows of the per-sample controller log (0: none).

    Returns
    -------
    EmtcParams
    """
    from .bench import ActuatorParameters, BenchScenario, TorqueMap, VehicleParameters, _default
    from .torque import CouplingGeometry

    scenario = scenario or _default(BenchScenario)
    vehicle = vehicle or _default(VehicleParameters)
    options = options or BenchOptions()
    actuator = options.actuator or _default(ActuatorParameters)
    coupling = options.coupling or _default(CouplingGeometry)
    torque_map = options.torque_map or _default(TorqueMap)
    ctl = options.controller_model or magnet
    lo_gap = actuator.airgap_open - actuator.free_travel
    for name, model in (("magnet", magnet), ("controller_model", ctl)):
        if model.n_airgaps > 1 and (lo_gap < model.airgaps[0] - 1e-12
                                    or actuator.airgap_open > model.airgaps[-1] + 1e-12):
            raise ParameterError(
                f"{name}: airgap range [{lo_gap:g}, {actuator.airgap_open:g}] m of the actuator is outside the "
                f"calibration airgaps [{model.airgaps[0]:g}, {model.airgaps[-1]:g}] m")
    ic = vehicle.rear_final_drive
    fzf, fzr = vehicle.axle_loads()
    geo = _f(coupling.kernel_data())
    lugre = np.zeros(6)
    fmap = (np.array([0.0, 1.0]), np.array([0.0, 1.0]), np.ones((2, 2)))
    fmode = FRICTION_CONSTANT
    if options.friction_map is not None:
        fm = options.friction_map
        fmap, fmode = (fm.slip_speed, fm.temperature_c, fm.mu), FRICTION_MAP
    elif options.lugre is not None:
        lugre = _f(options.lugre.kernel_data())
        # the locked capacity must use LuGre's own breakaway coefficient, else the friction just after
        # an unlock could exceed the lock capacity and the slip would reverse at once (chattering)
        geo = geo.copy()
        geo[3:6] = options.lugre.mu_p
        fmode = FRICTION_LUGRE
    if options.torque_reference is not None:
        tr = np.asarray(options.torque_reference, float)
        if (tr.ndim != 2 or tr.shape[0] != 2 or tr.shape[1] < 2 or not np.all(np.isfinite(tr))
                or np.any(np.diff(tr[0]) <= 0)):
            raise ParameterError("torque_reference: expected (times, torques) with strictly increasing finite times")
        ref_t, ref_v, ref_src = _f(tr[0]), _f(tr[1]), REFERENCE_TABLE
    else:
        ref_t, ref_v, ref_src = _EMPTY, _EMPTY, REFERENCE_MAP
    if cosimulation:
        thr_t, thr_v, ref_src = _EMPTY, _EMPTY, REFERENCE_INPUT
    else:
        s = scenario
        thr_t = np.array([0.0, s.ramp_start, max(s.ramp_end, s.ramp_start + 1e-9), max(s.duration, s.ramp_end) + 1.0])
        thr_v = np.array([s.throttle_start, s.throttle_start, s.throttle_end, s.throttle_end])
    cap = int(options.memory_capacity)
    ntab = magnet.kernel_tables.shape[1]
    fmem = np.zeros(N_FMEM)
    fmem[FM_PU] = magnet.grid[0]
    fmem[FM_CU] = ctl.grid[0]
    fmem[FM_TLAST] = np.nan
    gap_w = np.zeros(4)
    gap_w[3] = np.nan
    return EmtcParams(
        front_final_drive=float(vehicle.front_final_drive), axle_ratio=float(ic),
        gear_ratio=float(vehicle.gear_ratios[scenario.gear - 1]),
        inertia_front=float(vehicle.inertia_input_shaft + vehicle.inertia_front_axle / ic**2),  # [1], Eq. 29, J_F
        inertia_rear=float(vehicle.inertia_output_shaft + vehicle.inertia_rear_axle / ic**2),  # [1], Eq. 29, J_R
        tyre_radius=float(vehicle.tyre_radius), axle_load_front=float(fzf), axle_load_rear=float(fzr),
        rolling_resistance=float(vehicle.rolling_resistance), tyre_slip_stiffness=float(vehicle.tyre_slip_stiffness),
        slip_speed_floor=float(vehicle.slip_speed_floor), engine_torque_max=float(vehicle.engine_torque_max),
        engine_power=float(vehicle.engine_power), torsen_stiffness=float(vehicle.torsen_stiffness),
        torsen_damping=float(vehicle.torsen_damping), temperature_c=float(scenario.temperature_c),
        drag_pairs=float(vehicle.drag_pairs), oil_viscosity=float(vehicle.oil_viscosity),
        plate_clearance=float(vehicle.plate_clearance), plate_outer_radius=float(vehicle.plate_outer_radius),
        plate_inner_radius=float(vehicle.plate_inner_radius), unlock_margin=float(UNLOCK_MARGIN),
        sample_time=float(scenario.sample_time), drum_load_front=float(scenario.drum_load_front),
        drum_load_rear=float(scenario.drum_load_rear),
        armature_mass=float(actuator.mass), spring_stiffness=float(actuator.stiffness),
        spring_preload=float(actuator.preload), spring_damping=float(actuator.damping),
        free_travel=float(actuator.free_travel), airgap_open=float(actuator.airgap_open),
        tau1=float(actuator.tau1), tau2=float(actuator.tau2),
        friction_mode=int(fmode), reference_source=int(ref_src),
        geometry=geo, lugre=_f(lugre), fmap_speed=_f(fmap[0]), fmap_temperature=_f(fmap[1]), fmap_mu=_f(fmap[2]),
        throttle_time=_f(thr_t), throttle_value=_f(thr_v),
        drum_front_time=_EMPTY, drum_front_value=_EMPTY, drum_rear_time=_EMPTY, drum_rear_value=_EMPTY,
        map_throttle=_f(torque_map.throttle), map_speed=_f(torque_map.speed), map_torque=_f(torque_map.torque),
        reference_time=ref_t, reference_value=ref_v,
        plant_tables=_f(magnet.kernel_tables), plant_grid=_f(magnet.grid), plant_airgaps=_f(magnet.airgaps),
        plant_stack=np.zeros(cap), plant_prefix=np.zeros((magnet.n_airgaps, cap // 2 + 2)),
        ctl_tables=_f(ctl.kernel_tables), ctl_grid=_f(ctl.grid), ctl_airgaps=_f(ctl.airgaps),
        ctl_stack=np.zeros(cap), ctl_prefix=np.zeros((ctl.n_airgaps, cap // 2 + 2)),
        imem=np.zeros(N_IMEM, dtype=np.int64), fmem=fmem, u_last=np.full(len(INPUTS), np.nan),
        gap_idx=np.zeros(3, dtype=np.int64), gap_w=gap_w, gap_comb=np.zeros((1, ntab, ntab, 4)),
        ctl_idx=np.zeros(3, dtype=np.int64), ctl_w=np.zeros(3), aux=np.zeros(N_AUX), dxw=np.zeros(len(STATES)),
        gw=np.zeros(len(SWITCHING)), split=np.zeros(6), ctl_log=np.zeros((int(n_samples), 4)))


def _element_name(code: int, element: int) -> str:
    return ELEMENTS[element] if 0 <= element < len(ELEMENTS) else ""


def bench_system(magnet=None, scenario=None, vehicle=None, options: BenchOptions | None = None, *,
                 cosimulation: bool = False, n_samples: int = 0) -> System:
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
        Rows of the per-sample controller log (``params.ctl_log``).

    Returns
    -------
    System
        Initial state: shaft speeds of free rolling on the drums, armature at rest, coil current at the
        lowest grid current; modes ``rest``, ``open``, ``positive``; first trial step ``min(0.1 ms,
        sample_time)`` (a resumed run and an uninterrupted one take the same steps).
    """
    from .bench import BenchScenario, VehicleParameters, _default

    if magnet is None:
        from .magnet import bundled_magnet

        magnet = bundled_magnet()
    scenario = scenario or _default(BenchScenario)
    vehicle = vehicle or _default(VehicleParameters)
    params = pack_parameters(magnet, scenario, vehicle, options, cosimulation=cosimulation, n_samples=n_samples)
    vf = scenario.drum_speed
    vr = scenario.drum_speed - scenario.speed_difference
    ic = vehicle.rear_final_drive
    x0 = np.array([vf / vehicle.tyre_radius * ic, vr / vehicle.tyre_radius * ic, 0.0, 0.0, 0.0,
                   magnet.grid[0], magnet.grid[0]])
    u0 = np.array([0.0, scenario.throttle_start, vf, vr])
    return System("emtc_bench", params, STATES, OUTPUTS, x0, np.array([ARM_REST, OPEN, POSITIVE], dtype=np.int64),
                  ATOL.copy(), switching=SWITCHING, events=EVENTS, mode_names=MODE_NAMES, mode_values=MODE_VALUES,
                  inputs=INPUTS, u0=u0, method="dopri", rtol=1e-6, first_step=min(1e-4, scenario.sample_time),
                  event_tol=1e-12, element_name=_element_name, error_messages=dict(ERROR_MESSAGES))


register_model("emtc_bench", bench_system)


def memory_full(system: System) -> bool:
    """True if a run of ``system`` (an ``emtc_bench`` system) stopped because a hysteresis memory was full.

    ``system`` is the :class:`~clutchlab.system.System` whose run raised the model error; a run repeated
    with a larger ``BenchOptions.memory_capacity`` takes exactly the same steps.
    """
    return int(system.params.imem[IM_ERROR]) in (ERR_PLANT_MEMORY, ERR_CONTROLLER_MEMORY)


def run(build, t_end: float, **kwargs):
    """Simulate ``build(capacity)`` with :func:`clutchlab.system.simulate`; a full memory repeats the run larger.

    ``build(memory_capacity) -> System`` makes a fresh system; returns ``(system, result)``.
    """
    from ..system import simulate as core_simulate

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
             output_step: float | None = None):
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
        Absolute tolerance per state (default scaled to each state).
    max_step : float, optional
        Largest step [s] (default: none besides the controller samples).
    output_step : float, optional
        Sample interval of the result [s] (default: ``scenario.sample_time``, the controller samples).

    Returns
    -------
    clutchlab.SimulationResult
        States, outputs (:data:`OUTPUTS`), modes and named events (:data:`EVENTS`).
    """
    from .bench import BenchScenario, _default

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

    return run(build, t_end, rtol=rtol, atol=atol, max_step=max_step, output_step=output_step)[1]
