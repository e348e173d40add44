"""The wet clutch on its bench as an FMI co-simulation slave (:class:`WetCoSimulation`).

Its variables are the bench's parameter sets, the protocol's force and slip profile and the engagement
outputs; the model is :func:`clutchlab.wet.system.engagement_system` run by the integrator core.
"""

from __future__ import annotations

import math
import sys

import numpy as np

from ..errors import ParameterError, SimulationError
from ..params.base import ABSOLUTE_ZERO_C
from ..system import check_rtol
from .cosim import (ContractCoSimulation, Variable, _check_time, _flag, build_parameter_set, fixed_step_parameter,
                    fixed_step_variable, parameter_set_variables, rtol_variable, step_in_time)

__all__ = ["WetCoSimulation"]


def _wet_variables():
    from ..wet.params import BENCH_SENSORS, Bench, WetClutch
    from ..wet.thermal import steady_state_temperature

    clutch = parameter_set_variables("clutch", WetClutch)
    bench = parameter_set_variables("bench", Bench, skip=BENCH_SENSORS)
    scenario = (
        Variable("scenario.free_inertia", "1", 0.0,
                 "drive: 0 speed-controlled bench motor (Fig. 4), 1 free inertia (inertia dynamometer, SAE No. 2)",
                 0.0, 1.0),
        Variable("scenario.initial_slip_speed", "rad/s", 1500 * math.pi / 30, "slip speed at t = 0"),
        Variable("scenario.initial_temperature", "degC",
                 steady_state_temperature(0.0, 80.0, 70.0, WetClutch().k1, WetClutch().k2),
                 "pack temperature at t = 0 (default: Eq. 8 equilibrium of fluid and housing)", ABSOLUTE_ZERO_C),
        Variable("scenario.fluid_temperature", "degC", 80.0, "oil reservoir temperature at t = 0", ABSOLUTE_ZERO_C),
        Variable("scenario.housing_temperature", "degC", 70.0, "housing temperature at t = 0", ABSOLUTE_ZERO_C),
        Variable("scenario.heater_setpoint", "degC", 80.0, "reservoir thermostat set point", ABSOLUTE_ZERO_C),
        Variable("scenario.mu_scale", "1", 1.0, "factor on the asperity friction coefficient mu_f", 0.0),
        rtol_variable("solver.rtol", 1e-7, "relative tolerance of the DOPRI 5(4) step control"),
        Variable("solver.max_step", "s", 0.01, "largest integration step", positive=True),
        fixed_step_variable(),
    )
    return clutch + bench + scenario


#: (output name, unit, description, source) -- source: ("output", system output) or ("state", system state)
#: or ("stick",)
def _wet_output_table():
    return (
        ("clutch_torque", "N.m", "clutch torque tau = T_c + T_v (Eq. 3)", ("output", "clutch_torque")),
        ("contact_torque", "N.m", "asperity contact torque T_c (Eq. 4)", ("output", "contact_torque")),
        ("viscous_torque", "N.m", "viscous torque T_v (Eq. 5)", ("output", "viscous_torque")),
        ("slip_speed", "rad/s", "slip speed = clutch shaft speed", ("state", "slip_speed")),
        ("drive_torque", "N.m", "motor torque at the clutch shaft", ("output", "drive_torque")),
        ("sensor_torque", "N.m", "torque at the shaft torque sensor", ("output", "sensor_torque")),
        ("static_capacity", "N.m", "static torque capacity r_eff N_c mu_f F_c", ("output", "static_capacity")),
        ("contact_force", "N", "asperity contact force F_c (Greenwood-Williamson)", ("output", "contact_force")),
        ("squeeze_force", "N", "hydrodynamic squeeze-film force", ("output", "squeeze_force")),
        ("load_cell_force", "N", "force at the actuator load cell", ("output", "load_cell_force")),
        ("actuator_force", "N", "actuator force (first-order lag of the reference)", ("state", "actuator_force")),
        ("piston_position", "m", "piston position x_p", ("state", "piston_position")),
        ("nominal_separation", "m", "nominal film thickness h per interface (Eq. 1)", ("output", "nominal_separation")),
        ("mean_film", "m", "Patir-Cheng mean film thickness h_bar (Eq. 2)", ("output", "mean_film")),
        ("mu_f", "1", "asperity friction coefficient", ("output", "friction_coefficient")),
        ("viscosity", "Pa.s", "oil viscosity mu_v (Eq. 7)", ("output", "viscosity")),
        ("friction_power", "W", "friction power tau * omega", ("output", "friction_power")),
        ("heater_power", "W", "reservoir heater power", ("output", "heater_power")),
        ("temperature", "degC", "pack temperature T (Eq. 8)", ("state", "temperature")),
        ("fluid_temperature", "degC", "oil reservoir temperature", ("state", "fluid_temperature")),
        ("housing_temperature", "degC", "housing temperature", ("state", "housing_temperature")),
        ("thermistor_temperature", "degC", "thermistor reading (first-order lag of T)", ("state", "thermistor_temperature")),
        ("friction_work", "J", "friction work since t = 0", ("state", "friction_work")),
        ("stick", "1", "1 while the clutch is locked (stick mode), 0 while slipping", ("stick",)),
    )


class WetCoSimulation(ContractCoSimulation):
    """The wet-clutch bench of Shin, Kim and Choi [1] as a co-simulation slave.

    Inputs are the two references of the bench (Fig. 4): the actuator force
    reference [N] (the bench presses the piston with a force-controlled
    linear actuator; a piston pressure command is ``p * A_piston``) and the
    slip-speed reference [rad/s] of the speed-controlled drive motor
    (ignored with ``scenario.free_inertia = 1``).  Parameters are every
    numeric field of :class:`~clutchlab.wet.params.WetClutch` (``clutch.*``,
    Table 1 of [1] plus documented choices) and of
    :class:`~clutchlab.wet.params.Bench` (``bench.*``, without the sensor
    noise), the initial conditions (``scenario.*``, defaults of
    :class:`~clutchlab.wet.bench.EngagementProtocol`) and the step control
    (``solver.*``; ``solver.fixed_step`` > 0 runs the fixed-step mode of the core, a HIL frame).  Outputs: torques (Eqs. 3-6), forces, film thickness
    (Eqs. 1-2), viscosity (Eq. 7), temperatures (Eq. 8), friction work and
    the stick flag.

    Written against the system contract (:class:`~clutchlab.fmu.cosim.ContractCoSimulation`): the model is
    the ``"wet"`` :class:`~clutchlab.system.System` (:func:`clutchlab.wet.system.engagement_system`) with
    flat reference profiles, whose held inputs are the two references; this class gives only the System,
    the input vector with its range checks, where each output comes from and the one state the inputs
    decide at the start (the actuator force starts at its reference, :meth:`start_state`).  Each
    :meth:`do_step` continues the integration from the stored state, modes and step size; lock-up,
    break-away, contact and the piston stop inside the step are located as in the native run and listed in
    :attr:`events` (``result.events`` names of :func:`clutchlab.wet.simulate` are in :attr:`simulation`
    ``.events()``).

    Notes
    -----
    The friction law is the bench's true law
    (:meth:`~clutchlab.wet.friction.ParametricFriction.bench_truth`).  The
    integrator stops at every communication point, so the results differ
    from one uninterrupted :func:`~clutchlab.wet.engagement.simulate_engagement`
    run by the integration error (of order ``solver.rtol``), not more.
    """

    name = "wet"
    native = True
    inputs = (
        Variable("force_reference", "N", 0.0, "actuator force reference (piston apply force)", 0.0),
        Variable("slip_speed_reference", "rad/s", 1500 * math.pi / 30,
                 "slip-speed reference of the speed-controlled drive motor"),
    )
    outputs = tuple(Variable(n, u, 0.0, d) for n, u, d, _ in _wet_output_table())
    parameters = _wet_variables()

    def __init__(self, **parameter_values):
        from ..wet import engagement as E
        from ..wet.params import BENCH_SENSORS, Bench, WetClutch

        values = self.resolve_parameters(parameter_values)
        self.parameter_values = values
        self.clutch = build_parameter_set("clutch", WetClutch, values)
        self.bench = build_parameter_set("bench", Bench, values, skip=BENCH_SENSORS)
        free = _flag("scenario.free_inertia", values["scenario.free_inertia"])
        self.rtol = values["solver.rtol"]
        self.max_step = values["solver.max_step"]
        check_rtol(self.rtol, "parameter solver.rtol")
        if not self.max_step > 0:
            raise ParameterError(f"parameter solver.max_step = {self.max_step!r}: must be > 0 [s]")
        self.fixed_step = fixed_step_parameter(values)
        self.simulation_options = {"max_step": self.max_step, "max_steps": 2_000_000_000,
                                   "fixed_step": self.fixed_step}
        # flat (zero) profiles: the references are the held inputs of the system
        self.scenario = E.Scenario(
            force_time=[0.0], force_value=[0.0], speed_time=[0.0], speed_value=[0.0], duration=1.0,
            motor="free" if free else "speed", initial_slip_speed=values["scenario.initial_slip_speed"],
            initial_temperature_c=values["scenario.initial_temperature"],
            fluid_temperature_c=values["scenario.fluid_temperature"],
            housing_temperature_c=values["scenario.housing_temperature"],
            heater_setpoint_c=values["scenario.heater_setpoint"])
        self._mu_scale = values["scenario.mu_scale"]
        # the input checks of input_vector as two comparisons (NaN and infinities fail them as well)
        self._force_max = self.bench.actuator_force_max * (1 + 1e-12)
        self._speed_max = self.bench.drive_speed_max if self.scenario.motor == "speed" else sys.float_info.max
        self._values = values
        self.reset()

    def build_system(self, values: dict):
        """The ``"wet"`` System of the bench with flat reference profiles (the references are its held inputs)."""
        from ..wet import system as W

        # (the drive at the clutch shaft derived by the start from the motor's numbers and the gear, so a native
        # FMU's host sets those: wet_start's derive_drive)
        params = W.pack_parameters(self.clutch, self.bench, self.scenario, mu_scale=self._mu_scale, derive_drive=1)
        return W.engagement_system(self.scenario, clutch=self.clutch, bench=self.bench, params=params,
                                   x0=W.initial_state(self.scenario), rtol=self.rtol)

    def input_vector(self, inputs: dict) -> np.ndarray:
        """The two references, checked: the force within the actuator's limit, the slip speed within the drive's
        when the drive holds it."""
        f = inputs["force_reference"]
        w = inputs["slip_speed_reference"]
        if not 0.0 <= f <= self._force_max:
            raise ParameterError(f"input force_reference = {f!r} N: must be within "
                                 f"[0, {self.bench.actuator_force_max:g}] N (actuator limit)")
        if not abs(w) <= self._speed_max:
            raise ParameterError(f"input slip_speed_reference = {w!r} rad/s exceeds the bench's speed limit "
                                 f"{self.bench.drive_speed_max:.6g} rad/s")
        return np.array([f, w])

    def output_sources(self) -> list:
        """The FMI outputs from the system's outputs and states, and the stick flag from its friction mode."""
        from ..wet import system as W

        return [src if src[0] != "stick" else ("mode_is", W.M_FRICTION, 1) for _, _, _, src in _wet_output_table()]

    def start_state(self, x: np.ndarray, inputs: dict) -> None:
        """The actuator force starts at its reference, as in the model's own run."""
        from ..wet import system as W

        x[W.S_FA] = inputs["force_reference"]

    @property
    def time(self) -> float:
        """The model's time [s]."""
        return self.simulation.time

    @property
    def state(self):
        """State vector of the wet system (order of ``clutchlab.wet.system.STATES``)."""
        return self.simulation.x

    @property
    def mode(self) -> int:
        """Friction mode: 0 slip (positive), 1 stick, 2 slip (negative)."""
        from ..wet import system as W

        return int(self.simulation.m[W.M_FRICTION])

    @property
    def n_steps(self) -> int:
        """Accepted integration steps since the start."""
        return self.simulation.stats["accepted_steps"]

    @property
    def events(self) -> list:
        """Lock-up, break-away, contact, separation and slip reversal so far, as :class:`clutchlab.wet.engagement.
        Event` in time order (the piston-stop events are in :attr:`simulation` ``.events()``)."""
        from ..wet import engagement as E

        log = self.simulation.log
        names = self.system.events
        n = min(int(log.count[0]), log.time.shape[0])
        return [E.Event(float(log.time[i]), E.EVENT_KINDS[names[int(log.code[i])]]) for i in range(n)
                if names[int(log.code[i])] in E.EVENT_KINDS]

    def input_bound_words(self) -> dict:
        """The inputs whose range follows the parameters, ``{input: (path, symmetric, label)}``: the force reference
        within ``[0, actuator_force_max]`` and, when the drive holds the slip speed, the slip-speed reference within
        ``+-drive_speed_max`` (the motor's limit through the gear, derived by the model's start): a native FMU reads
        those numbers of the packed model to check them (:mod:`clutchlab.fmu.native`), as :meth:`input_vector`
        checks the bench's."""
        out = {"force_reference": ("params.constants.actuator_force_max", False, "bench.actuator_force_max")}
        if self.scenario.motor == "speed":
            out["slip_speed_reference"] = ("params.constants.drive_speed_max", True,
                                           "bench.motor_speed_max / bench.gear_ratio")
        return out

    def do_step(self, t: float, dt: float, inputs: dict) -> dict:
        """Advance from ``t`` to ``t + dt`` with the references held; return the outputs at ``t + dt``.

        Raises
        ------
        SimulationError
            Non-contiguous step, step limit or step-size underflow.
        ParameterError
            Unknown or out-of-range input.
        """
        _check_time("WetCoSimulation", self.simulation.time, t, dt)
        self._hold(self.resolve_inputs(inputs))
        return self._output_dict(self._step(t, t + dt))

    def do_step_array(self, t: float, dt: float, u) -> np.ndarray:
        """:meth:`do_step` with the inputs and outputs in order (:meth:`CoSimulation.do_step_array`)."""
        f, w = u
        sim = self.simulation
        if not (step_in_time(sim.time, t, dt) and 0.0 <= f <= self._force_max and abs(w) <= self._speed_max):
            out = self.do_step(t, dt, {"force_reference": f, "slip_speed_reference": w})   # (every check, in order)
            return np.array([out[n] for n in self._output_names])
        held = sim.u
        held[0] = f
        held[1] = w
        if self._at_start:
            self.start_state(sim.x, {"force_reference": f})
        return self._step(t, t + dt)

    def _step(self, t: float, t_end: float) -> np.ndarray:
        try:
            y = self.simulation.step(t_end)
        except SimulationError as exc:
            raise SimulationError(f"WetCoSimulation: between t = {t} and {t_end} s: {exc}") from None
        self._at_start = False
        return y
