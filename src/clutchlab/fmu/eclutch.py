"""The E-clutch as a co-simulation slave (FMI 2.0 co-simulation semantics, :mod:`clutchlab.fmu`).

Written against the system contract (:class:`~clutchlab.fmu.cosim.ContractCoSimulation`: the model gives its
System, its held input and where each output comes from; stepping, input checks and the FMU's fast path are the
contract's): ``do_step`` advances a resumable
:class:`clutchlab.system.Simulation` of the E-clutch system
(:meth:`clutchlab.eclutch.dynamics.EClutch.as_system` with a held input) over
one communication interval with the inputs held constant; the integrator's
state (positions, velocities, pressures, current, controller integral,
friction modes, step size) carries over from one interval to the next --
the E-clutch as a controller-design or HIL plant inside Simulink,
Dymola/OpenModelica or any FMI master.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..system import check_rtol
from ..fmu.cosim import (ContractCoSimulation, Variable, build_parameter_set, fixed_step_parameter,
                         fixed_step_variable, parameter_set_variables, rtol_variable)
from ..eclutch.actuator import ActuatorParameters
from ..eclutch.dynamics import EClutch, FrictionParameters
from ..eclutch.models import ClutchModel, EClutchParameters

__all__ = ["EClutchCoSimulation"]

_CLUTCH_SKIP = ("k_fl_model1",)
_INF = float("inf")


class EClutchCoSimulation(ContractCoSimulation):
    """E-clutch dynamics (actuator + axial Model 0-4 with stick-slip friction) stepped by a master.

    Inputs: ``bearing_reference`` [m] (tracked by the position controller when
    ``control_mode = 1``) and ``motor_voltage`` [V] (applied directly when
    ``control_mode = 0``).  Outputs: the rig's measured quantities and the
    clutch torque.  Parameters: ``model`` (0-4), ``control_mode``,
    ``friction_on`` and every field of :class:`EClutchParameters`
    (``clutch.*``), :class:`ActuatorParameters` (``actuator.*``) and
    :class:`FrictionParameters` (``friction.*``); ``solver.fixed_step`` > 0 runs the fixed-step mode of
    the core (a HIL frame).
    """

    name = "eclutch"
    native = True
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
        Variable("model", "1", 4.0, "axial model of Haramina et al. (2024), 0-4", 0.0, 4.0),
        Variable("control_mode", "1", 1.0, "1: bearing position control, 0: motor voltage", 0.0, 1.0),
        Variable("friction_on", "1", 1.0, "1: clutch friction elements R_f.ds, R_f.pp on", 0.0, 1.0),
        rtol_variable("rtol", 1e-3, "relative tolerance of the Rodas3 integrator"),
        fixed_step_variable(),
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
        check_rtol(self.rtol, "parameter rtol")
        self.fixed_step = fixed_step_parameter(values)
        self.simulation_options = {"fixed_step": self.fixed_step}
        self.input_name = "bearing_reference" if mode == 1.0 else "motor_voltage"
        self.eclutch = EClutch(actuator, ClutchModel.preset(int(model), clutch), friction)
        self._values = values
        self.reset()

    def build_system(self, values: dict):
        """The E-clutch's System at rest at t = 0 (clutch engaged, actuator at its rest stop), its one held input the
        bearing reference under position control, else the motor voltage."""
        key = "bearing_reference" if self.input_name == "bearing_reference" else "voltage"
        start = next(v.start for v in self.inputs if v.name == self.input_name)
        return self.eclutch.as_system({key: start}, rtol=self.rtol, held_input=True, at_start=True)

    def input_vector(self, inputs: dict) -> np.ndarray:
        """The held input: the bearing reference under position control, else the motor voltage (the other FMI
        input is unused)."""
        return np.array([inputs[self.input_name]])

    def output_sources(self) -> list:
        """The FMI outputs (in the order of :attr:`outputs`) from the E-clutch's states and outputs."""
        b0 = 2 * self.eclutch.assembly.nz
        return [("state", 1), ("output", 1), ("state", b0 + 2), ("state", b0), ("state", 0), ("state", b0 + 3),
                ("output", 0), ("output", 3), ("output", 4)]

    def reset(self) -> None:
        """Back to rest at t = 0: clutch engaged, actuator at its rest stop."""
        super().reset()
        self._held = self.simulation.u   # (the held input, written in place by the fast path)
        self._by_reference = self.input_name == "bearing_reference"

    def write_inputs(self, u) -> None:
        """The FMU's fast path: both inputs finite (the only check), the one the control mode reads written into the
        held input in place; anything else goes through the contract's checks for their error."""
        reference, voltage = u
        if -_INF < reference < _INF and -_INF < voltage < _INF:
            self._held[0] = reference if self._by_reference else voltage
        else:
            super().write_inputs(u)

    @property
    def t(self) -> float:
        """The model's time [s]."""
        return self.simulation.time
