"""Electro-hydrostatic E-clutch actuator: servomotor, spindle, master cylinder, line, CSC.

Haramina et al. [1] (Sec. 2.1, Figs. 2-5a) describe the actuator of the
E-clutch and refer its validated bond-graph model (Fig. 5a) to Hoić et al.
[2]; the papers give its structure, not its equations or numbers.  clutchlab
writes the equations of that structure (docs/eclutch_dynamics.md)::

    motor      L di/dt   = V - R i - k_t omega_m             omega_m = v_mc / n_s
    spindle    F_m       = k_t i / n_s                       n_s = lead / (2 pi)
    master     m_eq a_mc = F_m - p_m A_mc - F_f.mc           m_eq = m_mc + J_m / n_s^2
    chamber    C_m dp_m/dt = A_mc v_mc - Q - G_v s(x_mc) p_m   (snifting port)
    line       L_h dQ/dt = p_m - p_s - R_h Q
    CSC        C_s dp_s/dt = Q - A_sl v_sl
               m_sl a_sl = p_s A_sl + F_pre - k_pre x_sl - F_b - F_f.sl

with ``C = V/beta_eff + C_hose/2`` (fluid with entrained air plus half the hose
at each end), ``L_h = rho l / A_line`` (fluid inertia) and
``R_h = 128 mu l / (pi d^4)`` (laminar Hagen-Poiseuille resistance).  The
release bearing couples the CSC piston to the clutch through the bearing
stiffness ``k_b`` of the axial models ([1] Sec. 3.2).  The measured bearing
force of [1] Sec. 6 is ``F_b = p A_sl``.

Every value here is representative of a passenger-car E-clutch, not taken
from [1] or [2] (which do not print them); sources are given per parameter.

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, Trans. FAMENA
   48 (2024) 21-35, doi:10.21278/TOF.483057923
.. [2] M. Hoić, M. Hrgetić, J. Deur, A. Tissot, "Design of a test rig in
   support of E-clutch dynamics characterization, modelling, and control",
   PMC 2018, Loughborough.
"""

from __future__ import annotations

import dataclasses
import math

import numba
import numpy as np

from ..errors import ParameterError
from ..params import ParameterSet, quantity
from ..system import start_checks_deferred

__all__ = [
    "ActuatorParameters", "spindle_ratio", "reflected_mass", "chamber_compliance", "line_inertance",
    "line_resistance", "snifting_opening", "motor_current_derivative", "static_pressure",
    # scalar compiled equations (the dynamics' right-hand side and the vectorised functions above call them)
    "current_rate", "spindle_force", "drive_voltage", "controller_voltage", "controller_integral_rate",
    "vent_opening", "cavitating_compliance", "chamber_pressure_rate", "line_flow_rate", "stop_contact",
    # their slopes (the analytic Jacobian of the dynamics)
    "drive_voltage_slopes", "vent_opening_slope", "stop_contact_slopes",
]

_REP = "representative passenger-car E-clutch actuator (docs/eclutch_dynamics.md)"
_HYD = "representative DOT 4 brake fluid at 20 degC (docs/eclutch_dynamics.md)"


@dataclasses.dataclass(frozen=True)
class ActuatorParameters(ParameterSet):
    """Parameters of the electro-hydrostatic actuator ([1] Sec. 2.1, Fig. 5a; [2]).

    All values are SI; TOML files may give units (``lead = "4 mm"``,
    ``line_diameter = "4 mm"``, ``bulk_modulus = "500 MPa"``).
    """

    kind = "eclutch_actuator"

    # brushless DC servomotor and its drive
    resistance: float = quantity(0.2, "ohm", "motor winding resistance R (phase-to-phase, DC equivalent)", source=_REP, positive=True)
    inductance: float = quantity(2.5e-4, "H", "motor winding inductance L", source=_REP, positive=True)
    torque_constant: float = quantity(0.025, "N*m/A", "torque constant k_t = back-EMF constant k_e [V*s/rad]", source=_REP, positive=True)
    rotor_inertia: float = quantity(1.5e-5, "kg*m**2", "rotor and spindle nut inertia J_m", source=_REP, positive=True)
    supply_voltage: float = quantity(12.0, "V", "drive supply voltage: motor voltage saturates at +-V_sup", source=_REP, positive=True)
    current_limit: float = quantity(40.0, "A", "drive current limit i_max", source=_REP, positive=True)
    current_limit_gain: float = quantity(5.0, "V/A", "gain of the drive's current limiter above i_max", source=_REP, positive=True)
    # planetary spindle and master cylinder (HCA)
    lead: float = quantity(4e-3, "m", "spindle lead per motor revolution", source=_REP, positive=True)
    spindle_efficiency: float = quantity(0.85, "1", "spindle efficiency eta (load-dependent friction)", source=_REP, bounds=(0.05, 1.0))
    master_diameter: float = quantity(15.87e-3, "m", "master cylinder bore (5/8 in)", source=_REP, positive=True)
    master_mass: float = quantity(0.1, "kg", "master piston and spindle rod mass", source=_REP, positive=True)
    master_seal_friction: float = quantity(20.0, "N", "master seal and spindle Coulomb friction at zero load", source=_REP, nonnegative=True)
    master_stroke: float = quantity(40e-3, "m", "master piston stroke (end stop)", source=_REP, positive=True)
    snifting_port: float = quantity(1.0e-3, "m", "piston position at which the snifting port is closed", source=_REP, positive=True)
    snifting_width: float = quantity(0.3e-3, "m", "piston travel over which the port closes", source=_REP, positive=True)
    snifting_conductance: float = quantity(3e-11, "m**3/(s*Pa)", "port conductance G_v to the reservoir when open", source=_REP, positive=True)
    master_volume: float = quantity(3e-6, "m**3", "master chamber fluid volume", source=_REP, positive=True)
    # hydraulic line
    line_length: float = quantity(1.0, "m", "pipe length l", source=_REP, positive=True)
    line_diameter: float = quantity(5e-3, "m", "pipe inner diameter d", source=_REP, positive=True)
    hose_compliance: float = quantity(2e-13, "m**3/Pa", "volumetric compliance of the hose (half at each end)", source=_REP, nonnegative=True)
    bulk_modulus: float = quantity(5e8, "Pa", "effective bulk modulus beta_eff with entrained air", source=_HYD, positive=True)
    fluid_density: float = quantity(1050.0, "kg/m**3", "fluid density rho", source=_HYD, positive=True)
    fluid_viscosity: float = quantity(6e-3, "Pa*s", "dynamic viscosity mu", source=_HYD, positive=True)
    vapour_pressure: float = quantity(-0.95e5, "Pa", "gauge pressure below which the fluid cavitates", source=_HYD, bounds=(-1.01325e5, 0.0))
    # clutch slave cylinder (CSC) with release bearing
    slave_area: float = quantity(6.28e-4, "m**2", "CSC annular piston area A_sl", source=_REP, positive=True)
    slave_volume: float = quantity(6e-6, "m**3", "CSC chamber fluid volume at rest", source=_REP, positive=True)
    slave_mass: float = quantity(0.25, "kg", "CSC piston and release bearing mass m_sl", source=_REP, positive=True)
    slave_seal_friction: float = quantity(15.0, "N", "CSC seal Coulomb friction at zero pressure", source=_REP, nonnegative=True)
    seal_pressure_friction: float = quantity(2e-6, "N/Pa", "seal friction increase per unit pressure", source=_REP, nonnegative=True)
    csc_preload: float = quantity(80.0, "N", "CSC preload spring force at bearing position 0", source=_REP, nonnegative=True)
    csc_spring_rate: float = quantity(2000.0, "N/m", "CSC preload spring rate k_pre", source=_REP, nonnegative=True)
    slave_min: float = quantity(-1.5e-3, "m", "CSC end stop towards the engaged side", source=_REP)
    slave_max: float = quantity(10e-3, "m", "CSC end stop in the release direction (travel)", source=_REP, positive=True)
    stop_stiffness: float = quantity(2e7, "N/m", "end stop contact stiffness", source=_REP, positive=True)
    stop_damping: float = quantity(2e8, "N*s/m**2", "end stop Hunt-Crossley damping (force c*delta*v)", source=_REP, nonnegative=True)
    # bearing position controller (the E-clutch's own loop)
    kp: float = quantity(2000.0, "V/m", "position controller proportional gain", source=_REP, nonnegative=True)
    ki: float = quantity(8000.0, "V/(m*s)", "position controller integral gain", source=_REP, nonnegative=True)
    kd: float = quantity(0.0, "V*s/m", "position controller derivative gain (on measured velocity)", source=_REP, nonnegative=True)
    anti_windup: float = quantity(5e-4, "m/V", "back-calculation gain of the integrator", source=_REP, nonnegative=True)

    def check(self):
        """Cross-field consistency of the actuator."""
        if self.slave_min >= 0.0:
            raise ParameterError(f"slave_min = {self.slave_min!r} m must be < 0 (bearing position 0 is inside the travel)")
        if start_checks_deferred():   # (the checks across fields: a native FMU's start makes them, derive_actuator)
            return
        if self.snifting_port + self.snifting_width >= self.master_stroke:
            raise ParameterError(
                f"snifting_port + snifting_width = {self.snifting_port + self.snifting_width!r} m must be below "
                f"master_stroke = {self.master_stroke!r} m (the port must close within the stroke)")
        if self.master_volume < self.master_area * self.snifting_port:
            raise ParameterError(
                f"master_volume = {self.master_volume!r} m**3 is smaller than the volume swept up to the snifting port "
                f"({self.master_area * self.snifting_port:.3g} m**3)")

    # ---------------------------------------------------------------- derived
    @property
    def master_area(self) -> float:
        """Master piston area A_mc [m^2] (:func:`piston_area`, run as Python: the checks of every construction read it,
        also at import, which compiles nothing)."""
        return piston_area.py_func(self.master_diameter)

    @property
    def spindle_ratio(self) -> float:
        """Spindle ratio n_s = lead / 2 pi [m/rad]."""
        return spindle_ratio(self.lead)

    @property
    def master_equivalent_mass(self) -> float:
        """Master piston mass plus the reflected rotor inertia [kg]."""
        return reflected_mass(self.master_mass, self.rotor_inertia, self.spindle_ratio)

    @property
    def master_compliance(self) -> float:
        """Master chamber compliance C_m [m^3/Pa]."""
        return chamber_compliance(self.master_volume, self.bulk_modulus, self.hose_compliance / 2.0)

    @property
    def slave_compliance(self) -> float:
        """Slave chamber compliance C_s [m^3/Pa]."""
        return chamber_compliance(self.slave_volume, self.bulk_modulus, self.hose_compliance / 2.0)

    @property
    def line_inertance(self) -> float:
        """Fluid inertia of the line L_h [kg/m^4]."""
        return line_inertance(self.fluid_density, self.line_length, self.line_diameter)

    @property
    def line_resistance(self) -> float:
        """Laminar line resistance R_h [Pa*s/m^3]."""
        return line_resistance(self.fluid_viscosity, self.line_length, self.line_diameter)

    @property
    def load_friction(self) -> float:
        """Spindle loss as friction per unit axial load, ``1/eta - 1`` [-]."""
        return 1.0 / self.spindle_efficiency - 1.0

    def time_constants(self) -> dict[str, float]:
        """Characteristic times of the actuator [s] (electrical, line resonance, vent)."""
        return {
            "electrical L/R": self.inductance / self.resistance,
            "line resonance 2 pi sqrt(L_h C_s)": 2 * math.pi * math.sqrt(self.line_inertance * self.slave_compliance),
            "vent C_m / G_v": self.master_compliance / self.snifting_conductance,
        }


@numba.njit(cache=True, nogil=True, _nrt=False)
def piston_area(diameter):
    """Area of a piston of bore ``diameter`` [m], ``A = pi d^2 / 4`` [m^2] ([1] Sec. 2.1: the master cylinder).

    Compiled: the E-clutch's compiled start derives the master piston's area with it
    (:func:`clutchlab.eclutch.system.derive_actuator`).
    """
    return math.pi * diameter ** 2 / 4.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def spindle_ratio(lead):
    """Spindle transmission ``n_s = lead / (2 pi)`` [m/rad] ([1] Sec. 2.1: planetary spindle).

    Parameters
    ----------
    lead : float
        Axial travel per revolution [m].

    Compiled: the E-clutch's compiled start derives its spindle ratio with it
    (:func:`clutchlab.eclutch.system.derive_actuator`).
    """
    return lead / (2.0 * math.pi)


@numba.njit(cache=True, nogil=True, _nrt=False)
def reflected_mass(piston_mass, rotor_inertia, ratio):
    """Equivalent translational mass of piston and rotor, ``m + J / n_s^2`` [kg].

    Parameters
    ----------
    piston_mass : float
        Master piston (and rod) mass [kg].
    rotor_inertia : float
        Rotor plus spindle inertia [kg m^2].
    ratio : float
        Spindle ratio n_s [m/rad].

    Notes
    -----
    Assumes a rigid spindle (its compliance is far stiffer than the
    hydraulics); [1] Sec. 2.1.  Compiled, as :func:`spindle_ratio`.
    """
    return piston_mass + rotor_inertia / ratio ** 2


@numba.njit(cache=True, nogil=True, _nrt=False)
def chamber_compliance(volume, bulk_modulus, extra=0.0):
    """Hydraulic capacitance ``C = V / beta_eff + C_extra`` [m^3/Pa].

    Parameters
    ----------
    volume : float
        Fluid volume [m^3].
    bulk_modulus : float
        Effective bulk modulus including entrained air [Pa].
    extra : float
        Additional wall/hose compliance [m^3/Pa].

    Notes
    -----
    Constant volume and bulk modulus (small-signal); the change of volume with
    piston travel is neglected.  Actuator model of [1] Fig. 5a ([2]).  Compiled: the E-clutch's compiled start
    derives its chambers' compliances with it (:func:`clutchlab.eclutch.system.start`).
    """
    return volume / bulk_modulus + extra


@numba.njit(cache=True, nogil=True, _nrt=False)
def line_inertance(density, length, diameter):
    """Fluid inertia of a pipe ``L_h = rho l / A`` [kg/m^4] (one-dimensional plug flow; [1] Fig. 5a, [2]): density
    [kg/m^3], length [m], inner diameter [m].  Compiled, as :func:`chamber_compliance`."""
    return density * length / (math.pi * diameter ** 2 / 4.0)


@numba.njit(cache=True, nogil=True, _nrt=False)
def line_resistance(viscosity, length, diameter):
    """Laminar (Hagen-Poiseuille) pipe resistance ``R_h = 128 mu l / (pi d^4)`` [Pa s/m^3].

    Notes
    -----
    Valid for Reynolds numbers below about 2000: a 5 mm line at 3e-5 m^3/s
    (a fast release) has Re ~ 1350 with DOT 4 fluid.  Viscosity [Pa s], length and inner diameter [m]; [1]
    Fig. 5a, [2].  Compiled, as :func:`chamber_compliance`.
    """
    return 128.0 * viscosity * length / (math.pi * diameter ** 4)


def snifting_opening(x_mc, port, width):
    """Open fraction of the snifting (compensation) port, 1 at rest, 0 once closed [-].

    Parameters
    ----------
    x_mc : array_like
        Master piston position from its rest stop [m].
    port : float
        Position at which the port is fully covered by the seal [m].
    width : float
        Travel over which it closes [m] (linear area law).

    Notes
    -----
    Vectorised :func:`vent_opening` (the one implementation of the law).
    """
    return _apply(_vent_opening_array, x_mc, port, width)


def motor_current_derivative(voltage, current, speed, resistance, inductance, torque_constant):
    """``di/dt = (V - R i - k_t omega) / L`` [A/s] (brushless DC motor as a DC machine).

    Parameters
    ----------
    voltage : float
        Terminal voltage V [V].
    current : float
        Current i [A].
    speed : float
        Rotor speed omega [rad/s].
    resistance, inductance, torque_constant : float
        R [ohm], L [H], k_t = k_e [V s/rad].

    Notes
    -----
    The electronically commutated motor is represented by its DC-equivalent
    circuit (commutation ripple neglected), as in the actuator model of [2].
    Vectorised :func:`current_rate` (the one implementation of the equation,
    also used by the dynamics); array arguments broadcast.
    """
    return _apply(_current_rate_array, voltage, current, speed, resistance, inductance, torque_constant)


def _apply(loop, *args):
    """Broadcast the arguments, run a compiled element-wise loop, return a float for scalar input."""
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in args))
    shape = arrays[0].shape
    flat = [np.ascontiguousarray(a).ravel() for a in arrays]
    out = np.empty(flat[0].size)
    loop(*flat, out)
    return float(out[0]) if shape == () else out.reshape(shape)


# ---------------------------------------------------------------------------
# scalar compiled equations of the actuator ([1] Sec. 2.1, Fig. 5a; [2]; docs/eclutch_dynamics.md Sec. 2).
# One function per equation: the E-clutch right-hand side (clutchlab.eclutch.system) and the vectorised
# public functions above call these, so every equation is written once.
# ---------------------------------------------------------------------------

@numba.njit(cache=True, nogil=True)
def current_rate(voltage, current, speed, resistance, inductance, torque_constant):
    """Motor current derivative ``di/dt = (V - R i - k_t omega_m) / L`` [A/s].

    [1] Sec. 2.1, Fig. 5a ([2]): the brushless DC servomotor as its DC-equivalent circuit (commutation ripple
    neglected, k_e = k_t).  Arguments: voltage V [V], current i [A], rotor speed omega_m [rad/s], R [ohm],
    L [H], k_t [V s/rad].
    """
    return (voltage - resistance * current - torque_constant * speed) / inductance


@numba.njit(cache=True, nogil=True)
def spindle_force(current, torque_constant, ratio):
    """Axial force of the motor on the master piston through the spindle, ``F_m = k_t i / n_s`` [N].

    [1] Sec. 2.1 (planetary spindle, rigid, losses as load-dependent friction on the piston, see
    :func:`clutchlab.eclutch.dynamics.actuator_friction_elements`).  Arguments: current i [A], k_t [N m/A],
    spindle ratio n_s [m/rad].
    """
    return torque_constant * current / ratio


@numba.njit(cache=True, nogil=True)
def drive_voltage(command, current, supply, current_limit, limit_gain):
    """Voltage the drive applies [V]: the command saturated at the supply, pulled back above the current limit.

    ``V = clip(V_cmd, +-V_sup)``; above ``i_max`` the drive's current limiter subtracts
    ``K_il (|i| - i_max) sign(i)`` and the result is clipped again (docs/eclutch_dynamics.md Sec. 2, "drive").
    Arguments: command V_cmd [V], current i [A], supply V_sup [V], i_max [A], K_il [V/A].

    Notes
    -----
    A representative drive, not printed in [1] or [2]: a proportional current limiter, no PWM ripple.
    """
    v = min(max(command, -supply), supply)
    excess = abs(current) - current_limit
    if excess > 0.0:
        v -= limit_gain * excess * (1.0 if current > 0.0 else -1.0)
        v = min(max(v, -supply), supply)
    return v


@numba.njit(cache=True, nogil=True)
def controller_voltage(reference, position, integral, velocity, kp, kd):
    """Voltage command of the bearing position controller, ``V_cmd = K_p (r - x) + V_I - K_d v`` [V].

    The E-clutch's own PI(D) loop (docs/eclutch_dynamics.md, "Position controller"): ``V_I`` is the
    integral action (state ``controller_integral_V``), the derivative acts on the measured CSC velocity.
    Arguments: reference r [m] (already clipped to the CSC travel), position x [m], V_I [V], velocity v [m/s],
    K_p [V/m], K_d [V s/m].
    """
    return kp * (reference - position) + integral - kd * velocity


@numba.njit(cache=True, nogil=True)
def controller_integral_rate(reference, position, applied, command, ki, anti_windup):
    """Rate of the controller's integral action, ``dV_I/dt = K_i [(r - x) + K_aw (V - V_cmd)]`` [V/s].

    Integral action with back-calculation anti-windup (docs/eclutch_dynamics.md, "Position controller"):
    the difference between the applied (saturated, current-limited) voltage V and the command V_cmd
    bleeds the integrator.  Arguments: reference r [m], position x [m], V [V], V_cmd [V], K_i [V/(m s)],
    K_aw [m/V].
    """
    return ki * ((reference - position) + anti_windup * (applied - command))


@numba.njit(cache=True, nogil=True)
def vent_opening(x_mc, port, width):
    """Open fraction of the snifting port, ``clip((x_port - x_mc) / w, 0, 1)`` [-].

    Linear area law over the seal width w; 1 at rest (vented to the reservoir), 0 once the seal covers the
    port at ``x_port`` [m].  Arguments: master piston position x_mc [m], x_port [m], w [m].
    """
    return min(max((port - x_mc) / width, 0.0), 1.0)


@numba.njit(cache=True, nogil=True)
def cavitating_compliance(pressure, compliance, vapour_pressure, factor):
    """Chamber compliance [m^3/Pa], ``factor`` times larger below the vapour pressure (cavitation).

    docs/eclutch_dynamics.md Sec. 2: when the motor pulls a piston back faster than the line refills the
    chamber, the fluid cavitates and the pressure stays bounded; modelled as a compliance 1000x larger
    (``factor``) below ``p_v``.  Arguments: gauge pressure p [Pa], compliance C [m^3/Pa], p_v [Pa], factor [-].
    """
    return compliance * (factor if pressure < vapour_pressure else 1.0)


@numba.njit(cache=True, nogil=True)
def chamber_pressure_rate(inflow, outflow, compliance):
    """Pressure derivative of a hydraulic chamber, ``dp/dt = (Q_in - Q_out) / C`` [Pa/s].

    [1] Fig. 5a ([2]): master chamber ``C_m dp_m/dt = A_mc v_mc - Q - G_v s(x_mc) p_m`` and CSC chamber
    ``C_s dp_s/dt = Q - A_sl v_sl`` (constant volume, small-signal compliance).  Arguments: inflow and
    outflow [m^3/s], compliance C [m^3/Pa] (:func:`cavitating_compliance`).
    """
    return (inflow - outflow) / compliance


@numba.njit(cache=True, nogil=True)
def line_flow_rate(upstream, downstream, flow, inertance, resistance):
    """Flow derivative of the hydraulic line, ``L_h dQ/dt = p_m - p_s - R_h Q`` [m^3/s^2].

    [1] Fig. 5a ([2]): one-dimensional plug flow with fluid inertia ``L_h = rho l / A``
    (:func:`line_inertance`) and laminar Hagen-Poiseuille resistance (:func:`line_resistance`).
    Arguments: p_m, p_s [Pa], Q [m^3/s], L_h [kg/m^4], R_h [Pa s/m^3].
    """
    return (upstream - downstream - resistance * flow) / inertance


@numba.njit(cache=True, nogil=True)
def stop_contact(penetration, rate, stiffness, damping):
    """Hunt-Crossley end stop: force ``max(k d + c d d', 0)`` [N] and dissipated power ``(F - k d) d'`` [W].

    ``penetration`` is the penetration d [m] (no contact if <= 0), ``rate`` its rate d' [m/s], k [N/m],
    c [N s/m^2].  The force pushes out of the stop; the stored energy is k d^2 / 2.  Representative end stops of
    the master piston and the CSC (docs/eclutch_dynamics.md Sec. 2).
    """
    if penetration <= 0.0:
        return 0.0, 0.0
    f = max(stiffness * penetration + damping * penetration * rate, 0.0)
    return f, (f - stiffness * penetration) * rate


# ---------------------------------------------------------------------------
# slopes of the piecewise equations above, for the analytic Jacobian of the dynamics
# (clutchlab.eclutch.system.jacobian); each is the derivative of the function it names, on the branch the
# point lies on (at a kink the branch of the function's own comparison, as a one-sided difference would see it)
# ---------------------------------------------------------------------------

@numba.njit(cache=True, nogil=True)
def drive_voltage_slopes(command, current, supply, current_limit, limit_gain):
    """Partial derivatives of :func:`drive_voltage`: ``(dV/dV_cmd [-], dV/di [V/A])``.

    Inside the supply range the voltage follows the command (slope 1) and, above the current limit,
    falls with ``K_il`` per ampere of excess; once clipped at ``+-V_sup`` it depends on neither.
    Arguments as :func:`drive_voltage`.
    """
    v = command
    d_cmd = 1.0
    if v < -supply or v > supply:
        v = min(max(v, -supply), supply)
        d_cmd = 0.0
    d_i = 0.0
    excess = abs(current) - current_limit
    if excess > 0.0:
        v -= limit_gain * excess * (1.0 if current > 0.0 else -1.0)
        d_i = -limit_gain
        if v < -supply or v > supply:
            d_cmd = 0.0
            d_i = 0.0
    return d_cmd, d_i


@numba.njit(cache=True, nogil=True)
def vent_opening_slope(x_mc, port, width):
    """Derivative of :func:`vent_opening` with respect to the master position, ``-1/w`` inside the port [1/m]."""
    s = (port - x_mc) / width
    return -1.0 / width if 0.0 < s < 1.0 else 0.0


@numba.njit(cache=True, nogil=True)
def stop_contact_slopes(penetration, rate, stiffness, damping):
    """Partial derivatives of :func:`stop_contact`: ``(dF/dd, dF/dd', dP/dd, dP/dd')``.

    Units: N/m, N s/m, W/m, W s/m.  In contact with a pushing force, ``F = k d + c d d'`` and
    ``P = c d d'^2``; when the damping would pull (``F`` clipped at 0), ``F = 0`` and ``P = -k d d'``.
    """
    if penetration <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    if stiffness * penetration + damping * penetration * rate > 0.0:
        return (stiffness + damping * rate, damping * penetration, damping * rate * rate,
                2.0 * damping * penetration * rate)
    return 0.0, 0.0, -stiffness * rate, -stiffness * penetration


@numba.njit(cache=True, nogil=True)
def _current_rate_array(voltage, current, speed, resistance, inductance, torque_constant, out):
    for i in range(out.shape[0]):
        out[i] = current_rate(voltage[i], current[i], speed[i], resistance[i], inductance[i], torque_constant[i])


@numba.njit(cache=True, nogil=True)
def _vent_opening_array(x_mc, port, width, out):
    for i in range(out.shape[0]):
        out[i] = vent_opening(x_mc[i], port[i], width[i])


def static_pressure(bearing_force, bearing_position, params: ActuatorParameters):
    """CSC pressure in a steady state without friction [Pa].

    ``p = (F_b - F_pre + k_pre x) / A_sl``: the CSC piston balances the
    clutch's bearing force ``F_b`` with the pressure and its preload spring.
    """
    return (np.asarray(bearing_force) - params.csc_preload + params.csc_spring_rate * np.asarray(bearing_position)) / params.slave_area
