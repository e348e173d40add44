"""Engagement dynamics of a wet multi-plate clutch on a speed- or inertia-driven shaft.

The steady-state torque model of Shin, Kim and Choi [1] (Eqs. 1-8) is
extended to the transient engagement the way Deur et al. [4] do:

* the piston (force-controlled linear actuator of the bench, Fig. 4) moves
  against the return spring, the hydrodynamic squeeze-film force of the
  ``N_c`` interfaces in series (Reynolds equation for an annulus with the
  Patir-Cheng mean film h_bar, Eq. 2 [2]) and the Greenwood-Williamson
  asperity contact force [3].  The piston mass is neglected (quasi-static
  force balance), the actuator has a first-order force lag and a no-load
  speed limit (smooth ``tanh`` saturation);
* the clutch torque is Eq. 6 with the asperity force ``F_c = A_f p_c(h)``;
* one rotating inertia (motor, flywheel, gear, shaft referred to the clutch
  shaft) is driven by the speed-controlled motor (PI with back-calculation
  anti-windup, torque and power limits) or coasts freely (inertia
  dynamometer, SAE No. 2); the outer plates are held by the housing, so the
  shaft speed is the slip speed;
* the pack temperature follows Eq. 8; oil reservoir (2 kW heater with
  thermostat, natural cooling) and housing are lumped nodes; the thermistor
  is a first-order lag;
* the energy terms (friction work, heat to oil, heat to housing, drive work)
  are integrated as states, so the energy balance can be audited.

Lock-up (slip speed reaching zero while the static capacity holds the drive
torque) and break-away are events located inside the step on the dense
output and switch the mode between *slip* and *stick*; the contact event
(nominal separation crossing zero, Fig. 3 (b) -> (c)) is recorded.

The integrator is a compiled Dormand-Prince 5(4) loop
(:mod:`clutchlab.numerics.dopri`); :func:`simulate_batch` runs one solver
per variant in parallel with ``numba.prange``.

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

import functools
import math
from dataclasses import dataclass

import numba
import numpy as np
import pandas as pd

from .._limits import check_allocation, short_repr
from ..errors import ParameterError, SimulationError
from ..numerics.interp import bracket
from ..numerics.dopri import (
    A21, A31, A32, A41, A42, A43, A51, A52, A53, A54, A61, A62, A63, A64, A65,
    B1, B3, B4, B5, B6, C2, C3, C4, C5, E1, E3, E4, E5, E6, E7,
    dense_hermite, error_norm, initial_step, next_step,
)
from .film import film_scalar, gw_scalar, gw_table
from .friction import ParametricFriction, mu_kernel
from .params import Bench, WetClutch

__all__ = [
    "Scenario",
    "Event",
    "EngagementResult",
    "BatchResult",
    "simulate_engagement",
    "simulate_batch",
    "STATE_NAMES",
    "OUTPUT_NAMES",
    "BATCH_VARIABLES",
]

# ----------------------------------------------------------------- layout
(P_NC, P_REFF, P_SIGMA, P_AREA, P_XH0, P_MU1, P_MU2, P_MU3, P_MU4, P_CPACK, P_K1, P_K2, P_GW, P_KSQ,
 P_KS, P_F0, P_J, P_JSHAFT, P_TMAX, P_PMAX, P_KP, P_KI, P_MOTOR, P_TAUA, P_FMAX, P_VMAX, P_TAUTH,
 P_CRES, P_QMAX, P_GHEAT, P_TSET, P_KRA, P_CH, P_KHA, P_KFH, P_TAMB, P_FSCALE, P_MUSCALE, P_WSCALE,
 N_PAR) = range(40)

STATE_NAMES = (
    "piston_position_m", "actuator_force_N", "slip_speed_rad_s", "controller_integral_Nm", "temperature_C",
    "fluid_temperature_C", "housing_temperature_C", "thermistor_temperature_C", "friction_work_J",
    "heat_to_fluid_J", "heat_to_housing_J", "drive_work_J",
)
(S_X, S_FA, S_W, S_I, S_T, S_TF, S_TH, S_TM, S_EF, S_EK1, S_EK2, S_ED) = range(12)
N_STATE = 12

OUTPUT_NAMES = (
    "clutch_torque_Nm", "contact_torque_Nm", "viscous_torque_Nm", "contact_force_N", "squeeze_force_N",
    "load_cell_force_N", "nominal_separation_m", "mean_film_m", "mu_f", "viscosity_Pa_s", "drive_torque_Nm",
    "slip_reference_rad_s", "force_reference_N", "slip_acceleration_rad_s2", "sensor_torque_Nm",
    "friction_power_W", "heater_power_W", "static_capacity_Nm",
)
(A_TAU, A_TC, A_TV, A_FC, A_FH, A_FLC, A_H, A_HBAR, A_MUF, A_MUV, A_TD, A_WREF, A_FREF, A_WDOT, A_TS,
 A_PF, A_QH, A_CAP) = range(18)
N_AUX = 18

SLIP, STICK, SLIP_NEG = 0, 1, 2  # SLIP: positive slip direction; SLIP_NEG: negative
EV_CONTACT, EV_SEPARATION, EV_LOCKUP, EV_BREAKAWAY, EV_REVERSAL = range(5)
_MODE_NAMES = np.array(["slip", "stick", "slip"])
EVENT_KINDS = ("contact", "separation", "lock-up", "break-away", "slip reversal")
MAX_EVENTS = 64

#: scenario/parameter names that :func:`simulate_batch` can vary per variant
BATCH_VARIABLES = ("force_scale", "mu_scale", "speed_scale", "initial_slip_speed", "initial_temperature_c",
                   "fluid_temperature_c", "total_inertia", "k1", "k2")


# ----------------------------------------------------------------- scenario
def _profile(name, t, v):
    t = np.asarray(t, dtype=float).ravel()
    v = np.asarray(v, dtype=float).ravel()
    if t.size < 1 or t.size != v.size:
        raise ParameterError(f"Scenario.{name}: time and value need the same, non-zero length ({t.size} vs {v.size})")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
        raise ParameterError(f"Scenario.{name}: non-finite breakpoint")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        raise ParameterError(f"Scenario.{name}: breakpoint times must be strictly increasing")
    return t, v


@dataclass(frozen=True)
class Scenario:
    """Inputs of one engagement: reference profiles, drive mode and initial conditions.

    Parameters
    ----------
    force_time, force_value : array_like
        Breakpoints of the actuator force reference [s], [N] (piecewise
        linear, constant beyond the ends).
    speed_time, speed_value : array_like
        Breakpoints of the slip-speed reference [s], [rad/s] for the speed
        controller (ignored with ``motor="free"``).
    duration : float
        Simulated time [s].
    motor : {"speed", "free"}
        ``"speed"``: the bench motor tracks the slip reference (Fig. 4);
        ``"free"``: no motor torque, inertia dynamometer (SAE No. 2).
    initial_slip_speed : float
        Slip speed at t = 0 [rad/s]; 0 starts in the stick mode.
    initial_temperature_c, fluid_temperature_c, housing_temperature_c : float
        Initial pack, reservoir and housing temperatures [degC].
    heater_setpoint_c : float, optional
        Reservoir thermostat set point [degC] (default: the initial fluid temperature).
    """

    force_time: np.ndarray
    force_value: np.ndarray
    speed_time: np.ndarray
    speed_value: np.ndarray
    duration: float
    motor: str = "speed"
    initial_slip_speed: float = 0.0
    initial_temperature_c: float = 80.0
    fluid_temperature_c: float = 80.0
    housing_temperature_c: float = 80.0
    heater_setpoint_c: float | None = None

    def __post_init__(self):
        ft, fv = _profile("force", self.force_time, self.force_value)
        st, sv = _profile("speed", self.speed_time, self.speed_value)
        if np.any(fv < 0):
            raise ParameterError(f"Scenario.force_value: negative force {short_repr(fv[fv < 0][0])} [N]")
        object.__setattr__(self, "force_time", ft)
        object.__setattr__(self, "force_value", fv)
        object.__setattr__(self, "speed_time", st)
        object.__setattr__(self, "speed_value", sv)
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise ParameterError(f"Scenario.duration = {self.duration!r}: must be > 0 [s]")
        if self.motor not in ("speed", "free"):
            raise ParameterError(f"Scenario.motor = {self.motor!r}: expected 'speed' or 'free'")
        for name in ("initial_slip_speed", "initial_temperature_c", "fluid_temperature_c", "housing_temperature_c"):
            if not math.isfinite(getattr(self, name)):
                raise ParameterError(f"Scenario.{name} = {getattr(self, name)!r}: not finite")

    @property
    def setpoint_c(self) -> float:
        return self.fluid_temperature_c if self.heater_setpoint_c is None else float(self.heater_setpoint_c)


# ----------------------------------------------------------------- compiled model
@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _pwl(t, tt, vv):
    n = tt.shape[0]
    if t <= tt[0]:
        return vv[0]
    if t >= tt[n - 1]:
        return vv[n - 1]
    lo, w = bracket(tt, t)
    return vv[lo] + w * (vv[lo + 1] - vv[lo])


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _model(t, y, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, dy, aux):
    """Right-hand side and outputs of the engagement model (see module docstring).

    Inlined into the stage loop of the integrator (the hot call site);
    :func:`_rhs` is the out-of-line copy used everywhere else.
    """
    nc = p[P_NC]
    x = y[S_X]
    fa = y[S_FA]
    w = y[S_W]
    temp = y[S_T]
    h = (p[P_XH0] - x) / nc                                            # [1], Eq. 1
    hbar = film_scalar(h, p[P_SIGMA])                                   # [1], Eq. 2 (Patir-Cheng)
    muv = p[P_MU1] * math.exp(p[P_MU2] * temp) + p[P_MU3] * math.exp(p[P_MU4] * temp)  # [1], Eq. 7
    fc_ = p[P_AREA] * p[P_GW] * gw_scalar(h / p[P_SIGMA], g0, gdt, gv, gd)  # GW [3], Eq. 11
    v = p[P_REFF] * w                                                  # [1], Eq. (2')
    muf = p[P_MUSCALE] * mu_kernel(abs(v), temp, fc_, fk, fc, fgv, fgt, fgf, ftab)
    cap = p[P_REFF] * nc * muf * fc_                                   # [1], Eq. 4 (static capacity)
    # drive: speed-controlled motor or free inertia
    wref = p[P_WSCALE] * _pwl(t, st, sv)
    fref = p[P_FSCALE] * _pwl(t, ft, fv)
    if fref > p[P_FMAX]:
        fref = p[P_FMAX]
    if p[P_MOTOR] == 0.0:
        e = wref - w
        tcmd = p[P_KP] * e + y[S_I]
        aw = abs(w)
        tlim = p[P_TMAX]
        if aw * tlim > p[P_PMAX]:
            tlim = p[P_PMAX] / aw
        td = min(max(tcmd, -tlim), tlim)
        kaw = p[P_KI] / p[P_KP] if p[P_KP] > 0.0 else 0.0
        dy[S_I] = p[P_KI] * e + kaw * (td - tcmd)
    else:
        td = 0.0
        dy[S_I] = 0.0
    # clutch torque, [1], Eqs. 3-6
    if mode != STICK:
        # the sliding direction is part of the mode (changes only at located events),
        # so the right-hand side stays smooth across dw = 0 within a step
        sgn = 1.0 if mode == SLIP else -1.0
        tc = sgn * cap                                                 # [1], Eq. 4
        tv = p[P_REFF] * nc * muv * p[P_AREA] * v / hbar               # [1], Eq. 5
        tau = tc + tv                                                  # [1], Eq. 3
        wdot = (td - tau) / p[P_J]
        pf = tau * w
    else:
        tc = td
        tv = 0.0
        tau = td
        wdot = 0.0
        pf = 0.0
    dy[S_W] = wdot
    # piston: quasi-static balance of actuator, spring, squeeze film and asperities
    fsp = p[P_F0] + p[P_KS] * x
    fnet = fa - fsp - fc_
    csq = p[P_KSQ] * muv / (nc * hbar * hbar * hbar)                  # squeeze film, per piston velocity
    vmax = p[P_VMAX]
    xdot = vmax * math.tanh(fnet / (csq * vmax))
    at_stop = x <= 0.0 and xdot < 0.0
    if at_stop:
        xdot = 0.0
    dy[S_X] = xdot
    dy[S_FA] = (fref - fa) / p[P_TAUA]
    # thermal network
    qk1 = p[P_K1] * (temp - y[S_TF])
    qk2 = p[P_K2] * (temp - y[S_TH])
    dy[S_T] = (pf - qk1 - qk2) / p[P_CPACK]                            # [1], Eq. 8
    qh = p[P_GHEAT] * (p[P_TSET] - y[S_TF])
    qh = min(max(qh, 0.0), p[P_QMAX])
    qfh = p[P_KFH] * (y[S_TF] - y[S_TH])
    dy[S_TF] = (qk1 + qh - p[P_KRA] * (y[S_TF] - p[P_TAMB]) - qfh) / p[P_CRES]
    dy[S_TH] = (qk2 + qfh - p[P_KHA] * (y[S_TH] - p[P_TAMB])) / p[P_CH]
    dy[S_TM] = (temp - y[S_TM]) / p[P_TAUTH]
    dy[S_EF] = pf
    dy[S_EK1] = qk1
    dy[S_EK2] = qk2
    dy[S_ED] = td * w
    aux[A_TAU] = tau
    aux[A_TC] = tc
    aux[A_TV] = tv
    aux[A_FC] = fc_
    fh = csq * xdot
    aux[A_FH] = fh
    aux[A_FLC] = fa if at_stop else fsp + fc_ + fh
    aux[A_H] = h
    aux[A_HBAR] = hbar
    aux[A_MUF] = muf
    aux[A_MUV] = muv
    aux[A_TD] = td
    aux[A_WREF] = wref
    aux[A_FREF] = fref
    aux[A_WDOT] = wdot
    aux[A_TS] = tau + p[P_JSHAFT] * wdot
    aux[A_PF] = pf
    aux[A_QH] = qh
    aux[A_CAP] = cap


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _rhs(t, y, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, dy, aux):
    """Out-of-line right-hand side (samples, events, step restarts)."""
    _model(t, y, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, dy, aux)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _integrate(p, y0, t_end, ts, rtol, atol, hmax, max_steps,
               fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv,
               out_y, out_aux, out_mode, ev_t, ev_k, want_aux):
    """Dormand-Prince 5(4) with event location on the dense output.

    Integrates from t = 0 to ``t_end`` starting from ``y0`` (overwritten with
    the final state), writes states (and outputs if ``want_aux``) at ``ts``
    and the located events into ``ev_t``/``ev_k``.  Returns (number of events,
    accepted steps, status, peak pack temperature, first lock-up time or NaN);
    status 0 ok, 1 step limit, 2 step-size underflow.  The starting mode
    follows the sign of the initial slip speed; see :func:`_integrate_from`.
    """
    nev, steps, status, peak, t_lock, mode, hstep = _integrate_from(
        p, y0, 0.0, -1, 0.0, t_end, ts, rtol, atol, hmax, max_steps,
        fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv,
        out_y, out_aux, out_mode, ev_t, ev_k, want_aux)
    return nev, steps, status, peak, t_lock


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _integrate_from(p, y0, t0, mode0, h0, t_end, ts, rtol, atol, hmax, max_steps,
                    fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv,
                    out_y, out_aux, out_mode, ev_t, ev_k, want_aux):
    """Dormand-Prince 5(4) from ``(t0, y0, mode0)`` to ``t_end`` (resumable form of :func:`_integrate`).

    ``mode0`` < 0 derives the starting mode from the sign of the slip speed
    (the fresh start of :func:`_integrate`); ``mode0`` in {SLIP, STICK,
    SLIP_NEG} resumes a run stopped earlier in that mode (co-simulation,
    :mod:`clutchlab.fmu`).  On a resume in *stick* the break-away condition
    is checked at ``t0`` itself, because a step of the slip reference at the
    communication point can raise the drive torque above the static capacity
    at once.  ``h0`` > 0 is the first trial step (the step size proposed at
    the end of the previous call), else it is estimated.  Returns (number of
    events, accepted steps, status, peak pack temperature, first lock-up
    time or NaN, mode at ``t_end``, proposed next step).
    """
    n = N_STATE
    y = y0.copy()
    if mode0 >= 0:
        mode = mode0
    elif y[S_W] > 0.0:
        mode = SLIP
    elif y[S_W] < 0.0:
        mode = SLIP_NEG
    else:
        mode = STICK
    t = t0
    kk = np.zeros((7, n))
    k1 = kk[0]
    k3 = kk[2]
    k4 = kk[3]
    k5 = kk[4]
    k6 = kk[5]
    k7 = kk[6]
    tab_a = np.zeros((7, 6))
    tab_a[1, 0] = A21
    tab_a[2, 0] = A31
    tab_a[2, 1] = A32
    tab_a[3, 0] = A41
    tab_a[3, 1] = A42
    tab_a[3, 2] = A43
    tab_a[4, 0] = A51
    tab_a[4, 1] = A52
    tab_a[4, 2] = A53
    tab_a[4, 3] = A54
    tab_a[5, 0] = A61
    tab_a[5, 1] = A62
    tab_a[5, 2] = A63
    tab_a[5, 3] = A64
    tab_a[5, 4] = A65
    tab_a[6, 0] = B1
    tab_a[6, 2] = B3
    tab_a[6, 3] = B4
    tab_a[6, 4] = B5
    tab_a[6, 5] = B6
    tab_c = np.array([0.0, C2, C3, C4, C5, 1.0, 1.0])
    yt = np.empty(n)
    yn = np.empty(n)
    err = np.empty(n)
    ye = np.empty(n)
    de = np.empty(n)
    aux = np.empty(N_AUX)
    aux1 = np.empty(N_AUX)
    auxn = np.empty(N_AUX)
    _rhs(t, y, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, k1, aux)
    nev = 0
    if mode0 == STICK and abs(aux[A_TD]) > aux[A_CAP]:
        # resumed in stick with the drive torque already above the capacity: break away at t0
        mode = SLIP if aux[A_TD] > 0.0 else SLIP_NEG
        if nev < ev_t.shape[0]:
            ev_t[nev] = t
            ev_k[nev] = EV_BREAKAWAY
            nev += 1
        _rhs(t, y, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, k1, aux)
    if h0 > 0.0:
        hstep = h0
    else:
        hstep = initial_step(y, k1, rtol, atol, t_end - t, 5)
    if hstep > hmax:
        hstep = hmax
    ns = ts.shape[0]
    isamp = 0
    while isamp < ns and ts[isamp] <= t:
        out_y[isamp, :] = y
        if want_aux:
            out_aux[isamp, :] = aux
        out_mode[isamp] = mode
        isamp += 1
    steps = 0
    status = 0
    prev_rej = False
    peak = y[S_T]
    t_lock = np.nan
    while t < t_end:
        if steps >= max_steps:
            status = 1
            break
        if hstep > (t_end - t) * (1.0 - 1e-9):
            # last step: also stretched by up to 1e-9 relative so that no rounding remainder is left
            # (a resumed run whose end time is one ulp past t + max_step would otherwise underflow)
            hstep = t_end - t
        if hstep < 1e-14 * max(1.0, t):
            status = 2
            break
        hh = hstep
        # stages 2..7 (k7 at the new point, FSAL) with one inlined call site
        for stg in range(1, 7):
            for i in range(n):
                acc = 0.0
                for j in range(stg):
                    acc += tab_a[stg, j] * kk[j, i]
                yt[i] = y[i] + hh * acc
            if stg == 6:
                for i in range(n):
                    yn[i] = yt[i]
            _model(t + tab_c[stg] * hh, yt, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv,
                   kk[stg], auxn)
        for i in range(n):
            err[i] = hh * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
        en = error_norm(err, y, yn, rtol, atol)
        if not (en <= 1.0):
            if en != en:
                hstep = 0.2 * hh
            else:
                hstep = next_step(hh, en, False)
            prev_rej = True
            continue
        steps += 1
        # ---- terminal events: lock-up (slip) / break-away (stick)
        theta_e = 2.0
        kind_e = -1
        if mode != STICK:
            sd = 1.0 if mode == SLIP else -1.0
            w0 = sd * y[S_W]
            w1 = sd * yn[S_W]
            if w0 >= 0.0 and w1 < 0.0:
                lo = 0.0
                hi = 1.0
                for _ in range(60):
                    mid = 0.5 * (lo + hi)
                    dense_hermite(mid, hh, y, k1, yn, k7, ye)
                    if sd * ye[S_W] > 0.0:
                        lo = mid
                    else:
                        hi = mid
                theta_e = hi
                kind_e = EV_LOCKUP
        else:
            g0_ = abs(aux[A_TD]) - aux[A_CAP]
            g1_ = abs(auxn[A_TD]) - auxn[A_CAP]
            if g0_ <= 0.0 and g1_ > 0.0:
                lo = 0.0
                hi = 1.0
                for _ in range(60):
                    mid = 0.5 * (lo + hi)
                    dense_hermite(mid, hh, y, k1, yn, k7, ye)
                    _rhs(t + mid * hh, ye, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, de, aux1)
                    if abs(aux1[A_TD]) - aux1[A_CAP] <= 0.0:
                        lo = mid
                    else:
                        hi = mid
                theta_e = hi
                kind_e = EV_BREAKAWAY
        # ---- non-terminal: contact / separation (h crosses 0)
        h0 = p[P_XH0] - y[S_X]
        h1 = p[P_XH0] - yn[S_X]
        if (h0 > 0.0) != (h1 > 0.0):
            lo = 0.0
            hi = 1.0
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                dense_hermite(mid, hh, y, k1, yn, k7, ye)
                if ((p[P_XH0] - ye[S_X]) > 0.0) == (h0 > 0.0):
                    lo = mid
                else:
                    hi = mid
            if hi <= theta_e and nev < ev_t.shape[0]:
                ev_t[nev] = t + hi * hh
                ev_k[nev] = EV_CONTACT if h0 > 0.0 else EV_SEPARATION
                nev += 1
        t_new = t + hh if kind_e < 0 else t + theta_e * hh
        # ---- samples in (t, t_new]
        while isamp < ns and ts[isamp] <= t_new:
            th = (ts[isamp] - t) / hh
            dense_hermite(th, hh, y, k1, yn, k7, ye)
            out_y[isamp, :] = ye
            if want_aux:
                _rhs(ts[isamp], ye, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, de, aux1)
                out_aux[isamp, :] = aux1
            out_mode[isamp] = mode
            isamp += 1
        if kind_e >= 0:
            dense_hermite(theta_e, hh, y, k1, yn, k7, ye)
            for i in range(n):
                y[i] = ye[i]
            t = t_new
            if kind_e == EV_LOCKUP:
                y[S_W] = 0.0
                _rhs(t, y, STICK, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, de, aux1)
                if abs(aux1[A_TD]) <= aux1[A_CAP]:
                    mode = STICK
                    if t_lock != t_lock:
                        t_lock = t
                else:
                    kind_e = EV_REVERSAL
                    mode = SLIP_NEG if mode == SLIP else SLIP
            else:
                _rhs(t, y, STICK, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, de, aux1)
                mode = SLIP if aux1[A_TD] > 0.0 else SLIP_NEG
            if nev < ev_t.shape[0]:
                ev_t[nev] = t
                ev_k[nev] = kind_e
                nev += 1
            _rhs(t, y, mode, p, fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv, k1, aux)
            prev_rej = False
        else:
            for i in range(n):
                y[i] = yn[i]
                k1[i] = k7[i]
            for i in range(N_AUX):
                aux[i] = auxn[i]
            t = t + hh
            hstep = next_step(hh, en, prev_rej)
            if hstep > hmax:
                hstep = hmax
            prev_rej = False
        if y[S_T] > peak:
            peak = y[S_T]
    for i in range(n):
        y0[i] = y[i]
    return nev, steps, status, peak, t_lock, mode, hstep


@numba.njit(cache=True, parallel=True, error_model="numpy")
def _integrate_batch(pmat, y0mat, t_end, ts, rtol, atol, hmax, max_steps,
                     fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv,
                     out_y, summary):
    """One DOPRI solver per variant (rows of ``pmat``/``y0mat``), in parallel."""
    m = pmat.shape[0]
    ns = ts.shape[0]
    for j in numba.prange(m):
        oy = np.empty((ns, N_STATE))
        oa = np.empty((1, N_AUX))
        om = np.empty(ns, dtype=np.int64)
        et = np.empty(MAX_EVENTS)
        ek = np.empty(MAX_EVENTS, dtype=np.int64)
        y = y0mat[j].copy()
        nev, steps, status, peak, tl = _integrate(pmat[j], y, t_end, ts, rtol, atol, hmax, max_steps,
                                                   fk, fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd, ft, fv, st, sv,
                                                   oy, oa, om, et, ek, False)
        out_y[j] = oy
        summary[j, 0] = tl
        summary[j, 1] = y[S_EF]
        summary[j, 2] = peak
        summary[j, 3] = y[S_T]
        summary[j, 4] = y[S_W]
        summary[j, 5] = steps
        summary[j, 6] = status
        summary[j, 7] = nev


# ----------------------------------------------------------------- Python layer
def parameter_vector(clutch: WetClutch, bench: Bench, scenario: Scenario) -> np.ndarray:
    """Flat parameter vector of the compiled kernel (SI units)."""
    p = np.zeros(N_PAR)
    p[P_NC] = clutch.n_c
    p[P_REFF] = clutch.r_eff
    p[P_SIGMA] = clutch.sigma
    p[P_AREA] = clutch.friction_area
    p[P_XH0] = clutch.piston_h0
    p[P_MU1], p[P_MU2], p[P_MU3], p[P_MU4] = clutch.viscosity
    p[P_CPACK] = clutch.heat_capacity
    p[P_K1] = clutch.k1
    p[P_K2] = clutch.k2
    p[P_GW] = clutch.gw_scale
    p[P_KSQ] = clutch.squeeze_coefficient
    p[P_KS] = clutch.spring_stiffness
    p[P_F0] = clutch.spring_preload
    p[P_J] = bench.total_inertia
    p[P_JSHAFT] = bench.shaft_inertia
    p[P_TMAX] = bench.drive_torque_max
    p[P_PMAX] = bench.motor_power_max
    p[P_KP] = bench.speed_kp
    p[P_KI] = bench.speed_ki
    p[P_MOTOR] = 0.0 if scenario.motor == "speed" else 1.0
    p[P_TAUA] = bench.actuator_time_constant
    p[P_FMAX] = bench.actuator_force_max
    p[P_VMAX] = bench.actuator_speed_max
    p[P_TAUTH] = bench.thermistor_time_constant
    p[P_CRES] = bench.reservoir_heat_capacity
    p[P_QMAX] = bench.heater_power_max
    p[P_GHEAT] = bench.heater_gain
    p[P_TSET] = scenario.setpoint_c
    p[P_KRA] = bench.reservoir_cooling
    p[P_CH] = bench.housing_heat_capacity
    p[P_KHA] = bench.housing_cooling
    p[P_KFH] = bench.fluid_housing_conductance
    p[P_TAMB] = bench.ambient_temperature
    p[P_FSCALE] = 1.0
    p[P_MUSCALE] = 1.0
    p[P_WSCALE] = 1.0
    return p


def initial_state(scenario: Scenario) -> np.ndarray:
    """State at t = 0: piston at its stop, actuator force at the reference, no energy yet."""
    y = np.zeros(N_STATE)
    y[S_FA] = np.interp(0.0, scenario.force_time, scenario.force_value)
    y[S_W] = scenario.initial_slip_speed
    y[S_T] = scenario.initial_temperature_c
    y[S_TF] = scenario.fluid_temperature_c
    y[S_TH] = scenario.housing_temperature_c
    y[S_TM] = scenario.initial_temperature_c
    return y


def _atol(clutch: WetClutch) -> np.ndarray:
    a = np.empty(N_STATE)
    a[S_X] = 1e-4 * clutch.sigma
    a[S_FA] = 1e-3
    a[S_W] = 1e-5
    a[S_I] = 1e-5
    a[S_T:S_TM + 1] = 1e-6
    a[S_EF:] = 1e-4
    return a


def _check_scenario(bench: Bench, scenario: Scenario):
    if scenario.motor == "speed":
        top = float(np.max(np.abs(scenario.speed_value)))
        if top > bench.drive_speed_max:
            raise ParameterError(
                f"Scenario.speed_value: {top:.6g} rad/s exceeds the bench's speed limit {bench.drive_speed_max:.6g} rad/s "
                f"(motor 6000 rpm through the 1:{bench.gear_ratio:g} gear)")
    if float(np.max(scenario.force_value)) > bench.actuator_force_max * (1 + 1e-12):
        raise ParameterError(f"Scenario.force_value: {np.max(scenario.force_value):.6g} N exceeds the actuator's "
                             f"{bench.actuator_force_max:.6g} N")


@dataclass
class Event:
    """A mode change or contact transition located inside an integration step.

    Attributes
    ----------
    time : float
        Event time [s], located on the step's dense output.
    kind : str
        What happened: contact, separation, lock-up, break-away, slip reversal.
    """

    time: float
    kind: str


@dataclass
class EngagementResult:
    """Result of :func:`simulate_engagement`.

    Attributes
    ----------
    time : numpy.ndarray
        Sample times [s].
    states : numpy.ndarray
        ``(n, 12)`` states, columns :data:`STATE_NAMES` (SI, temperatures in degC).
    outputs : numpy.ndarray
        ``(n, 18)`` outputs, columns :data:`OUTPUT_NAMES`.
    modes : numpy.ndarray
        Mode per sample: ``"slip"`` or ``"stick"``.
    events : list of Event
        Contact, separation, lock-up, break-away in time order.
    n_steps : int
        Accepted integration steps.
    final_state : numpy.ndarray
        State at ``duration``.
    heat_capacity : float
        Heat capacity of the pack used in Eq. 8 [J/K].
    state_names, output_names : tuple of str
        Column names of ``states`` and ``outputs``.
    peak_temperature_c : float
        Highest pack temperature [degC].
    lockup_time : float
        Time of lock-up [s] (NaN if the clutch did not lock).
    """

    time: np.ndarray
    states: np.ndarray
    outputs: np.ndarray
    modes: np.ndarray
    events: list
    n_steps: int
    final_state: np.ndarray
    heat_capacity: float
    state_names: tuple = STATE_NAMES
    output_names: tuple = OUTPUT_NAMES
    peak_temperature_c: float = float("nan")
    lockup_time: float = float("nan")

    def state(self, name: str) -> np.ndarray:
        """One state trace by name."""
        return self.states[:, self.state_names.index(name)]

    def output(self, name: str) -> np.ndarray:
        """One output trace by name."""
        return self.outputs[:, self.output_names.index(name)]

    def to_dataframe(self) -> pd.DataFrame:
        """All samples as a DataFrame with ``time_s``, states, outputs and ``mode``."""
        frame = pd.DataFrame(self.states, columns=list(self.state_names))
        frame = pd.concat([frame, pd.DataFrame(self.outputs, columns=list(self.output_names))], axis=1)
        frame.insert(0, "time_s", self.time)
        frame["mode"] = self.modes
        return frame

    def energy_balance(self) -> dict:
        """Friction work against heat into the pack plus heat out, from the final state [J].

        ``W_f = C (T_end - T_0) + Q_fluid + Q_housing`` holds exactly for Eq. 8;
        ``residual`` is the relative integration error.
        """
        y = self.final_state
        wf = y[S_EF]
        stored = self.heat_capacity * (y[S_T] - self.states[0, S_T])
        out = y[S_EK1] + y[S_EK2]
        return {"friction_work": wf, "heat_into_pack": stored, "heat_out": out,
                "residual": (wf - stored - out) / max(abs(wf), 1e-300)}


@dataclass
class BatchResult:
    """Result of :func:`simulate_batch` (one row per variant).

    ``variants`` maps each varied input to its array of values; ``time`` [s]
    are the sample times and ``samples`` the states at ``time`` per variant
    (``(m, n, 12)``).  Per variant: ``lockup_time`` [s] (NaN where the clutch
    did not lock), ``friction_work`` [J], ``peak_temperature_c`` and
    ``final_temperature_c`` [degC], ``final_slip_speed`` [rad/s], ``n_steps``
    (accepted steps) and ``status`` (0 success, 1 step limit, 2 step-size
    underflow).
    """

    variants: dict
    time: np.ndarray
    samples: np.ndarray
    lockup_time: np.ndarray
    friction_work: np.ndarray
    peak_temperature_c: np.ndarray
    final_temperature_c: np.ndarray
    final_slip_speed: np.ndarray
    n_steps: np.ndarray
    status: np.ndarray

    def to_dataframe(self) -> pd.DataFrame:
        """Summary per variant with the varied inputs."""
        frame = pd.DataFrame({k: np.asarray(v) for k, v in self.variants.items()})
        for name in ("lockup_time", "friction_work", "peak_temperature_c", "final_temperature_c",
                     "final_slip_speed", "n_steps", "status"):
            frame[name] = getattr(self, name)
        return frame


@functools.lru_cache(maxsize=1)
def _default_bench() -> Bench:
    return Bench()


@functools.lru_cache(maxsize=1)
def _truth_data():
    return ParametricFriction.bench_truth().kernel_data()


def _friction_data(friction):
    if friction is None:
        return _truth_data()
    if not hasattr(friction, "kernel_data"):
        raise ParameterError(f"friction = {friction!r}: expected a ParametricFriction or a FrictionMap")
    return friction.kernel_data()


def _sample_times(duration, sample_rate, sample_times):
    if sample_times is not None:
        ts = np.asarray(sample_times, dtype=float).ravel()
        if ts.size and (np.any(np.diff(ts) < 0) or ts[0] < 0 or ts[-1] > duration * (1 + 1e-12)):
            raise ParameterError("sample_times: must be increasing within [0, duration]")
        return ts
    if not (sample_rate > 0):
        raise ParameterError(f"sample_rate = {sample_rate!r}: must be > 0 [Hz]")
    # the record: states, auxiliaries and the noisy bench channels, each about N_STATE + N_AUX values a sample
    check_allocation(duration * sample_rate + 1, 2 * (N_STATE + N_AUX),
                     f"duration = {duration!r} s at sample_rate = {sample_rate!r} Hz")
    n = int(math.floor(duration * sample_rate + 1e-9)) + 1
    return np.arange(n) / sample_rate


def simulate_engagement(clutch: WetClutch, scenario: Scenario, *, bench: Bench | None = None, friction=None,
                        sample_rate: float = 1000.0, sample_times=None, rtol: float = 1e-7,
                        max_step: float = 0.01, max_steps: int = 2_000_000, outputs: bool = True) -> EngagementResult:
    """Simulate one engagement (or any bench run) of the wet clutch.

    Parameters
    ----------
    clutch : WetClutch
        Clutch parameters (Table 1 of Shin et al. [1] plus documented choices).
    scenario : Scenario
        Force and slip references, drive mode, initial temperatures.
    bench : Bench, optional
        Drive, actuator, sensors and oil loop (default ``Bench()``).
    friction : ParametricFriction or FrictionMap, optional
        Asperity friction law mu_f (default: the bench's true law,
        :meth:`ParametricFriction.bench_truth`).
    sample_rate : float
        Output rate [Hz] when ``sample_times`` is not given.
    sample_times : array_like, optional
        Explicit output times [s].
    rtol : float
        Relative tolerance of the DOPRI 5(4) step control.
    max_step : float
        Largest step [s] (keeps reference-profile corners resolved).
    max_steps : int
        Accepted-step limit (a :class:`SimulationError` beyond it).
    outputs : bool
        Evaluate the outputs (torques, forces, film, ...) at the samples; with
        ``False`` only the states are kept and ``outputs`` is all NaN.

    Returns
    -------
    EngagementResult

    Raises
    ------
    ParameterError
        References outside the bench's limits, bad tolerances.
    SimulationError
        Step limit reached or step size underflow.
    """
    bench = _default_bench() if bench is None else bench
    _check_scenario(bench, scenario)
    if not (0 < rtol < 1):
        raise ParameterError(f"rtol = {rtol!r}: must be in (0, 1)")
    ts = _sample_times(scenario.duration, sample_rate, sample_times)
    p = parameter_vector(clutch, bench, scenario)
    y = initial_state(scenario)
    y0 = y.copy()
    fk, fc, fgv, fgt, fgf, ftab = _friction_data(friction)
    g0, gdt, gv, gd = gw_table()
    ns = ts.size
    oy = np.zeros((ns, N_STATE))
    oa = np.full((ns, N_AUX) if outputs else (1, N_AUX), np.nan)
    om = np.zeros(ns, dtype=np.int64)
    et = np.zeros(MAX_EVENTS)
    ek = np.zeros(MAX_EVENTS, dtype=np.int64)
    nev, steps, status, peak, tl = _integrate(
        p, y, float(scenario.duration), ts, float(rtol), _atol(clutch), float(max_step), int(max_steps),
        int(fk), fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd,
        scenario.force_time, scenario.force_value, scenario.speed_time, scenario.speed_value,
        oy, oa, om, et, ek, bool(outputs))
    if not outputs:
        oa = np.full((ns, N_AUX), np.nan)
    if status == 1:
        raise SimulationError(f"simulate_engagement: step limit {max_steps} reached before t = {scenario.duration} s")
    if status == 2:
        raise SimulationError("simulate_engagement: step size underflow (stiff or discontinuous input?)")
    events = [Event(float(et[i]), EVENT_KINDS[int(ek[i])]) for i in range(nev)]
    events.sort(key=lambda e: e.time)
    if ns and oy[0, S_T] != y0[S_T]:
        oy[0] = y0
    modes = _MODE_NAMES[om]
    return EngagementResult(ts, oy, oa, modes, events, int(steps), y, clutch.heat_capacity,
                            peak_temperature_c=float(peak), lockup_time=float(tl))


def simulate_batch(clutch: WetClutch, scenario: Scenario, variants: dict, *, bench: Bench | None = None,
                   friction=None, sample_times=None, rtol: float = 1e-6, max_step: float = 0.01,
                   max_steps: int = 1_000_000) -> BatchResult:
    """Simulate many variants of one scenario in parallel (``numba.prange``, one solver each).

    Parameters
    ----------
    clutch, scenario, bench, friction
        As in :func:`simulate_engagement` (the base case).
    variants : dict of str -> array_like
        Per-variant values, all of the same length, for names in
        :data:`BATCH_VARIABLES`: ``force_scale`` and ``speed_scale`` (scale the
        references), ``mu_scale`` (scales mu_f), ``initial_slip_speed``
        [rad/s], ``initial_temperature_c`` and ``fluid_temperature_c`` [degC],
        ``total_inertia`` [kg*m^2], ``k1``, ``k2`` [W/K].
    sample_times : array_like, optional
        Times [s] at which the states of every variant are kept (default: the end).
    rtol, max_step, max_steps
        Step control as in :func:`simulate_engagement`, per variant; a
        variant that fails reports it in ``status`` instead of raising.

    Returns
    -------
    BatchResult
    """
    bench = _default_bench() if bench is None else bench
    _check_scenario(bench, scenario)
    if not variants:
        raise ParameterError("simulate_batch: variants is empty")
    unknown = [k for k in variants if k not in BATCH_VARIABLES]
    if unknown:
        raise ParameterError(f"simulate_batch: cannot vary {unknown[0]!r} (known: {', '.join(BATCH_VARIABLES)})")
    vals = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in variants.items()}
    m = {v.size for v in vals.values()}
    if len(m) != 1:
        raise ParameterError(f"simulate_batch: variants have different lengths {sorted(m)}")
    m = m.pop()
    for k, v in vals.items():
        if not np.all(np.isfinite(v)):
            raise ParameterError(f"simulate_batch: variant {k!r} has a non-finite value")
        if k in ("force_scale", "mu_scale", "total_inertia") and np.any(v <= 0):
            raise ParameterError(f"simulate_batch: variant {k!r} must be > 0")
        if k in ("k1", "k2") and np.any(v < 0):
            raise ParameterError(f"simulate_batch: variant {k!r} must be >= 0")
    ts = np.array([scenario.duration]) if sample_times is None else _sample_times(scenario.duration, 1.0, sample_times)
    p = parameter_vector(clutch, bench, scenario)
    y = initial_state(scenario)
    pmat = np.tile(p, (m, 1))
    ymat = np.tile(y, (m, 1))
    col = {"force_scale": P_FSCALE, "mu_scale": P_MUSCALE, "speed_scale": P_WSCALE, "total_inertia": P_J,
           "k1": P_K1, "k2": P_K2}
    for k, v in vals.items():
        if k in col:
            pmat[:, col[k]] = v
        elif k == "initial_slip_speed":
            ymat[:, S_W] = v
        elif k == "initial_temperature_c":
            ymat[:, S_T] = v
            ymat[:, S_TM] = v
        elif k == "fluid_temperature_c":
            ymat[:, S_TF] = v
            pmat[:, P_TSET] = v
    ymat[:, S_FA] *= pmat[:, P_FSCALE]
    fk, fc, fgv, fgt, fgf, ftab = _friction_data(friction)
    g0, gdt, gv, gd = gw_table()
    out_y = np.zeros((m, ts.size, N_STATE))
    summary = np.zeros((m, 8))
    _integrate_batch(pmat, ymat, float(scenario.duration), ts, float(rtol), _atol(clutch), float(max_step),
                     int(max_steps), int(fk), fc, fgv, fgt, fgf, ftab, g0, gdt, gv, gd,
                     scenario.force_time, scenario.force_value, scenario.speed_time, scenario.speed_value,
                     out_y, summary)
    return BatchResult(vals, ts, out_y, summary[:, 0], summary[:, 1], summary[:, 2], summary[:, 3], summary[:, 4],
                       summary[:, 5].astype(int), summary[:, 6].astype(int))
