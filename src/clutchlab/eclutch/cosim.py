"""The E-clutch as a co-simulation slave (FMI 2.0 co-simulation semantics, :mod:`clutchlab.fmu`).

``do_step`` continues the compiled Rodas3 integration of
:mod:`clutchlab.eclutch.dynamics` from the stored state (positions,
velocities, pressures, current, controller integral, friction modes) over one
communication interval with the inputs held constant -- the E-clutch as a
controller-design or HIL plant inside Simulink, Dymola/OpenModelica or any
FMI master.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError, SimulationError
from ..fmu.cosim import CoSimulation, Variable, build_parameter_set, parameter_set_variables
from . import _dynamics_kernel as K
from .actuator import ActuatorParameters
from .dynamics import EClutch, FrictionParameters
from .models import ClutchModel, EClutchParameters

__all__ = ["EClutchCoSimulation"]

_CLUTCH_SKIP = ("k_fl_model1",)


class EClutchCoSimulation(CoSimulation):
    """E-clutch dynamics (actuator + axial Model 0-4 with stick-slip friction) stepped by a master.

    Inputs: ``bearing_reference`` [m] (tracked by the position controller when
    ``control_mode = 1``) and ``motor_voltage`` [V] (applied directly when
    ``control_mode = 0``).  Outputs: the rig's measured quantities and the
    clutch torque.  Parameters: ``model`` (0-4), ``control_mode``,
    ``friction_on`` and every field of :class:`EClutchParameters`
    (``clutch.*``), :class:`ActuatorParameters` (``actuator.*``) and
    :class:`FrictionParameters` (``friction.*``).
    """

    name = "eclutch"
    inputs = (
        Variable("bearing_reference", "m", 5e-3, "bearing position reference (control_mode = 1)"),
        Variable("motor_voltage", "V", 0.0, "motor voltage (control_mode = 0)"),
    )
    outputs = (
        Variable("bearing_position", "m", 0.0, "release bearing (CSC piston) position"),
        Variable("bearing_force", "N", 0.0, "bearing force from the CSC pressure, p A_sl"),
        Variable("pressure", "Pa", 0.0, "CSC pressure (gauge)"),
        Variable("master_pressure", "Pa", 0.0, "master cylinder pressure (gauge)"),
        Variable("master_position", "m", 0.0, "master piston position"),
        Variable("motor_current", "A", 0.0, "motor current"),
        Variable("motor_voltage_applied", "V", 0.0, "voltage the drive applies (after limits)"),
        Variable("normal_force", "N", 0.0, "clamp force on the friction plate"),
        Variable("clutch_torque", "N.m", 0.0, "transmissible clutch torque 2 F_n r_eff mu"),
    )
    parameters = (
        Variable("model", "1", 4.0, "axial model of Haramina et al. (2024), 0-4"),
        Variable("control_mode", "1", 1.0, "1: bearing position control, 0: motor voltage"),
        Variable("friction_on", "1", 1.0, "1: clutch friction elements R_f.ds, R_f.pp on"),
        Variable("rtol", "1", 1e-3, "relative tolerance of the Rodas3 integrator"),
        *parameter_set_variables("clutch", EClutchParameters, skip=_CLUTCH_SKIP),
        *parameter_set_variables("actuator", ActuatorParameters),
        *parameter_set_variables("friction", FrictionParameters),
    )

    def __init__(self, **parameter_values):
        values = self.resolve_parameters(parameter_values)
        model = values["model"]
        if model not in (0.0, 1.0, 2.0, 3.0, 4.0):
            raise ParameterError(f"parameter model = {model!r}: expected 0, 1, 2, 3 or 4")
        mode = values["control_mode"]
        if mode not in (0.0, 1.0):
            raise ParameterError(f"parameter control_mode = {mode!r}: expected 0 or 1")
        if values["friction_on"] not in (0.0, 1.0):
            raise ParameterError(f"parameter friction_on = {values['friction_on']!r}: expected 0 or 1")
        clutch = build_parameter_set("clutch", EClutchParameters, values, skip=_CLUTCH_SKIP)
        actuator = build_parameter_set("actuator", ActuatorParameters, values)
        friction = build_parameter_set("friction", FrictionParameters, values) if values["friction_on"] else \
            FrictionParameters.off()
        self.rtol = values["rtol"]
        if not 1e-10 < self.rtol < 0.1:
            raise ParameterError(f"parameter rtol = {self.rtol!r}: expected a value in (1e-10, 0.1)")
        self.imode = K.POSITION if mode == 1.0 else K.VOLTAGE
        self.eclutch = EClutch(actuator, ClutchModel.preset(int(model), clutch), friction)
        self.reset()

    def reset(self) -> None:
        """Back to rest at t = 0: clutch engaged, actuator at its rest stop."""
        self.y, self.modes = self.eclutch.system.initial_state(self.eclutch.rest_position)
        self.t = 0.0

    def _outputs(self, t, inputs) -> dict:
        s = self.eclutch.system
        tin, vin = self._table(t, inputs)
        interp = 0 if self.imode == K.POSITION else 1
        aux, f = K.outputs(np.array([t]), self.y[None, :], self.modes[None, :], s.nz, self.imode, tin, vin, interp,
                           s.par, s.mass, *s.kernel_network(), *s.kernel_friction())
        nz = s.nz
        b0 = 2 * nz
        act = self.eclutch.actuator
        fn = float(f[0, s.element_names.index(self.eclutch.clutch.network.normal_force)])
        return {
            "bearing_position": float(self.y[1]),
            "bearing_force": float(self.y[b0 + 2] * act.slave_area),
            "pressure": float(self.y[b0 + 2]),
            "master_pressure": float(self.y[b0]),
            "master_position": float(self.y[0]),
            "motor_current": float(self.y[b0 + 3]),
            "motor_voltage_applied": float(aux[0, 0]),
            "normal_force": fn,
            "clutch_torque": 2.0 * fn * self.eclutch.clutch.r_eff * self.eclutch.clutch.mu,
        }

    def _table(self, t, inputs):
        u = self.resolve_inputs(inputs)
        value = u["bearing_reference"] if self.imode == K.POSITION else u["motor_voltage"]
        return np.array([t]), np.array([value])

    def initial_outputs(self, inputs: dict) -> dict:
        """Outputs at t = 0 (the rest state)."""
        return self._outputs(0.0, inputs)

    def do_step(self, t: float, dt: float, inputs: dict) -> dict:
        """Advance from ``t`` to ``t + dt`` with the inputs held; return the outputs at ``t + dt``."""
        if not (np.isfinite(dt) and dt > 0):
            raise ParameterError(f"communication step dt = {dt!r} s must be finite and > 0")
        if abs(t - self.t) > 1e-9 * max(1.0, abs(t)):
            raise SimulationError(f"do_step at t = {t!r} s but the E-clutch is at t = {self.t!r} s "
                                  "(steps must be contiguous; call reset() to start again)")
        s = self.eclutch.system
        tin, vin = self._table(t, inputs)
        interp = 0 if self.imode == K.POSITION else 1
        *_, stats, yf, mf = K.integrate(
            self.y, self.modes, float(t), float(t + dt), s.nz, self.imode, tin, vin, interp, np.empty(0), s.par,
            s.mass, s.mvec, s.typ, *s.kernel_network(), *s.kernel_friction(), float(self.rtol), s.atol,
            min(1e-5, dt), 0.01, 200_000, np.array([t + dt]), 1e-8, 10)
        if stats[4] != 0:
            raise SimulationError(f"E-clutch step from t = {t!r} s failed (status {int(stats[4])})")
        self.y = yf.copy()
        self.modes = mf.copy()
        self.t = t + dt
        return self._outputs(t + dt, inputs)
