"""The EMTC on its drum bench as an FMI co-simulation slave (:class:`EmtcCoSimulation`).

Written on :class:`~clutchlab.fmu.cosim.ContractCoSimulation` over
:func:`clutchlab.emtc.system.bench_system`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import ParameterError, SimulationError
from ..system import check_rtol
from .cosim import (ContractCoSimulation, Variable, _check_time, build_parameter_set, field_variable,
                    fixed_step_parameter, fixed_step_variable, parameter_set_variables, rtol_variable, snap_to_grid,
                    step_in_time)

__all__ = ["EmtcCoSimulation"]

_INF = math.inf


_EMTC_OUTPUTS = (
    # name, unit, description, source in the emtc_bench system: ("state" | "output", column) or ("mode", index)
    ("coupling_torque", "N.m", "torque transferred by the EMTC T_c (Eqs. 17, 25, 30)", ("output", "coupling_torque_Nm")),
    ("front_shaft_speed", "rad/s", "coupling input shaft speed omega_f (Eq. 27)", ("state", "omega_f_rad_s")),
    ("rear_shaft_speed", "rad/s", "coupling output shaft speed omega_r (Eq. 27)", ("state", "omega_r_rad_s")),
    ("slip_speed", "rad/s", "omega_f - omega_r", ("output", "slip_speed_rad_s")),
    ("magnet_force", "N", "magnet force F_m from the plant Preisach model (Eq. 1)", ("output", "magnet_force_N")),
    ("primary_clamp_force", "N", "primary clutch normal force F_n1 (Eq. 11)", ("output", "fn1_N")),
    ("main_clamp_force", "N", "main clutch normal force F_n2 from the ball cam (Eq. 14)", ("output", "fn2_N")),
    ("torque_capacity", "N.m", "locked-mode torque capacity (Eq. 21)", ("output", "capacity_locked_Nm")),
    ("lock_torque", "N.m", "torque needed to keep the coupling locked (Eq. 29)", ("output", "lock_torque_Nm")),
    ("engine_torque", "N.m", "engine torque", ("output", "engine_torque_Nm")),
    ("armature_position", "m", "armature displacement x (Eqs. 8-12)", ("state", "x_armature_m")),
    ("armature_speed", "m/s", "armature speed", ("state", "v_armature_m_s")),
    ("airgap", "m", "magnetic airgap d (Eq. 12)", ("output", "airgap_m")),
    ("coil_current", "A", "coil current (second lag of Fig. 15)", ("state", "i2_A")),
    ("current_command", "A", "coil current command applied over the last controller sample (Eqs. 6-7)",
     ("output", "current_command_A")),
    ("torsen_twist", "rad", "Torsen twist angle since lock-up (Eq. 30)", ("state", "theta_rad")),
    ("armature_mode", "1", "0 at the rest stop, 1 free, 2 pressing the primary clutch", ("mode", 0)),
    ("coupling_mode", "1", "0 open, 1 slipping, 2 locked", ("mode", 1)),
)


def _emtc_variables():
    from ..emtc.bench import ActuatorParameters, BenchScenario, VehicleParameters
    from ..emtc.torque import CouplingGeometry

    return (parameter_set_variables("vehicle", VehicleParameters)
            + parameter_set_variables("actuator", ActuatorParameters)
            + parameter_set_variables("coupling", CouplingGeometry)
            + (field_variable("scenario.gear", BenchScenario, "gear"),
               field_variable("scenario.drum_load_front", BenchScenario, "drum_load_front",
                              "extra drum resistance, front axle"),
               field_variable("scenario.drum_load_rear", BenchScenario, "drum_load_rear",
                              "extra drum resistance, rear axle"),
               field_variable("scenario.sample_time", BenchScenario, "sample_time",
                              "EMTC controller sample time (any communication step: the controller samples at its "
                              "own instants)"),
               rtol_variable("solver.rtol", 1e-6, "relative tolerance of the DOPRI 5(4) step control"),
               fixed_step_variable()))


class EmtcCoSimulation(ContractCoSimulation):
    """The AWD vehicle with the EMTC on the drum bench [2] as a co-simulation slave.

    Inputs: the coupling torque request ``T_cal`` [N*m] of the AWD controller
    (replaces the map of Eq. 31, as ``simulate_bench(torque_reference=...)``),
    the throttle [-] and the front and rear drum surface speeds [m/s].  The
    EMTC controller samples the torque request every
    ``scenario.sample_time``, converts it to a primary-clutch force (Eqs. 13,
    15), a magnet force (Eq. 11) and a coil current through the inverse
    Preisach model (Eqs. 6-7); the current follows the two lags of Fig. 15.
    Parameters: every numeric field of
    :class:`~clutchlab.emtc.bench.VehicleParameters` (``vehicle.*``, Table 1
    of [2]), :class:`~clutchlab.emtc.bench.ActuatorParameters`
    (``actuator.*``) and :class:`~clutchlab.emtc.torque.CouplingGeometry`
    (``coupling.*``), gear, drum loads, sample time, tolerance.  The friction
    coefficients are the constant ones of the coupling geometry (no friction
    map, no LuGre).
    The magnet is the Preisach family identified from the bundled synthetic
    FORC records (:func:`clutchlab.emtc.magnet.bundled_magnet`).

    A :class:`ContractCoSimulation` of the ``emtc_bench`` system
    (:func:`clutchlab.emtc.system.bench_system` with the inputs held by the
    master): each :meth:`do_step` is one ``advance`` of the integrator core,
    which continues with the states, modes, step size and both hysteresis
    memories (plant magnet and controller model).  The controller samples are
    break times of the model, so a chain of steps reproduces one
    uninterrupted :func:`~clutchlab.emtc.bench.simulate_bench` run exactly
    when the communication points are controller samples and the plant
    inputs (throttle, drum speeds) are held (see ``docs/fmu.md``).

    Notes
    -----
    Any communication step is accepted: the controller samples at its own
    instants ``k * scenario.sample_time`` inside or across steps and holds
    its command in between.  A step that is a whole multiple of the sample
    time, starting on a sample, is the case reproduced exactly.  Inputs that
    change at a communication point apply from that point on (the model's
    restart makes the modes consistent with them, e.g. an unlock).  The shaft
    speeds start at the free-rolling speeds of the drum-speed inputs at t = 0.
    """

    #: the controller's sample instants: a step's end within 1e-9 of a period of one counts as it (the native FMU too)
    step_grid_parameter = "scenario.sample_time"

    name = "emtc"
    inputs = (
        Variable("torque_request", "N.m", 0.0, "coupling torque request T_cal of the AWD controller"),
        Variable("throttle", "1", 0.1, "engine throttle (0-1)", 0.0, 1.0),
        Variable("drum_speed_front", "m/s", 8.0, "front drum surface speed"),
        Variable("drum_speed_rear", "m/s", 7.7, "rear drum surface speed"),
    )
    outputs = tuple(Variable(n, u, 0.0, d) for n, u, d, _ in _EMTC_OUTPUTS)
    parameters = _emtc_variables()
    #: turning points each hysteresis memory starts with (``BenchOptions.memory_capacity``); a full memory
    #: replays the run with four times as many (:meth:`_advance`)
    memory_capacity = 64
    #: ... and a native FMU's, which cannot grow its memory at run time (:meth:`for_native`)
    NATIVE_MEMORY_CAPACITY = 1024

    @classmethod
    def for_native(cls) -> type:
        """The class a native FMU is built from: memories of :data:`NATIVE_MEMORY_CAPACITY` turning points
        (16 times the start of this class's, which replays with a larger one when full; the results do not
        depend on the size)."""
        return type(cls.__name__, (cls,), {"memory_capacity": cls.NATIVE_MEMORY_CAPACITY,
                                           "__doc__": cls.__doc__, "__module__": cls.__module__})

    def __init__(self, **parameter_values):
        from ..emtc.bench import ActuatorParameters, BenchScenario, VehicleParameters
        from ..emtc.magnet import bundled_magnet
        from ..emtc.system import BenchOptions, absolute_tolerance
        from ..emtc.torque import CouplingGeometry

        values = self.resolve_parameters(parameter_values)
        self.parameter_values = values
        self.vehicle = build_parameter_set("vehicle", VehicleParameters, values)
        self.actuator = build_parameter_set("actuator", ActuatorParameters, values)
        self.coupling = build_parameter_set("coupling", CouplingGeometry, values)
        gear = values["scenario.gear"]
        if gear not in (1.0, 2.0, 3.0, 4.0, 5.0, 6.0):
            raise ParameterError(f"parameter scenario.gear = {gear!r}: expected 1-6")
        self.sample_time = values["scenario.sample_time"]
        if not self.sample_time > 0:
            raise ParameterError(f"parameter scenario.sample_time = {self.sample_time!r}: must be > 0 [s]")
        self.rtol = values["solver.rtol"]
        check_rtol(self.rtol, "parameter solver.rtol")
        self.magnet = bundled_magnet()
        self._scenario = BenchScenario(gear=int(gear), drum_load_front=values["scenario.drum_load_front"],
                                       drum_load_rear=values["scenario.drum_load_rear"],
                                       sample_time=self.sample_time, duration=max(4.0, self.sample_time))
        self._options = BenchOptions(actuator=self.actuator, coupling=self.coupling,
                                     memory_capacity=self.memory_capacity)
        self.fixed_step = fixed_step_parameter(values)
        # (the absolute tolerances follow rtol below its default, as the bench's own runs do: with them fixed the
        # co-simulation's error stopped following rtol, issue #30)
        self.simulation_options = {"rtol": self.rtol, "atol": absolute_tolerance(self.rtol), "max_steps": 2_000_000,
                                   "fixed_step": self.fixed_step}
        super().__init__(**parameter_values)

    # ---- the contract
    def build_system(self, values: dict):
        """The ``emtc_bench`` system with the inputs held by the master (``values``: the parameters, by name)."""
        from ..emtc.system import bench_system

        return bench_system(self.magnet, self._scenario, self.vehicle, self._options, cosimulation=True,
                            start_on_drums=True)

    def input_vector(self, inputs: dict) -> np.ndarray:
        """``u = [torque_request, throttle, drum_speed_front, drum_speed_rear, coil_current_command,
        coupling_temperature]`` from the FMI ``inputs`` (the coil current command and the temperature are unused:
        the FMU's coupling runs its torque controller, with the constant friction coefficients)."""
        thr = inputs["throttle"]
        if not 0.0 <= thr <= 1.0:
            raise ParameterError(f"input throttle = {thr!r}: must be within [0, 1]")
        return np.array([inputs["torque_request"], thr, inputs["drum_speed_front"], inputs["drum_speed_rear"], 0.0,
                         self._scenario.temperature_c])

    def output_sources(self) -> list:
        """The FMI outputs: outputs, states (by column) and modes of the ``emtc_bench`` system."""
        return [src for _, _, _, src in _EMTC_OUTPUTS]

    # ---- what the EMTC adds: the initial speeds, sample instants, named events, memories that grow
    def reset(self) -> None:
        """Back to the initial state at t = 0 (same parameters)."""
        super().reset()
        self.time = 0.0
        self.events = []
        self._history = []  # (model time reached, inputs): replayed if a hysteresis memory must grow
        self._n_logged = 0
        self._started = False

    @property
    def n_steps(self) -> int:
        """Accepted integration steps since the start."""
        return self.simulation.stats["accepted_steps"]

    def _start(self, u):
        from ..emtc.system import U_DRUM_FRONT, U_DRUM_REAR, X_OMEGA_F, X_OMEGA_R, free_rolling_speed

        r = self.vehicle.tyre_radius
        ic = self.vehicle.rear_final_drive
        x = self.simulation.x  # free rolling at t = 0, as simulate_bench (and the model's start, start_on_drums)
        x[X_OMEGA_F] = free_rolling_speed(u[U_DRUM_FRONT], r, ic)
        x[X_OMEGA_R] = free_rolling_speed(u[U_DRUM_REAR], r, ic)
        self._started = True

    def _advance(self, target, uv):
        """Advance to ``target`` with the inputs ``uv`` (a tuple); the outputs there (:meth:`Simulation.step`).

        A full memory replays the steps with a larger one."""
        while True:
            held = self.simulation.u
            held[:] = uv
            try:
                y = self.simulation.step(target)
                break
            except SimulationError as exc:
                from ..emtc.system import memory_full

                if not memory_full(self.system):
                    raise SimulationError(f"EmtcCoSimulation: {exc}") from None
                # the same steps again with four times the memory (the run does not depend on its size)
                self._options = dataclasses.replace(self._options, memory_capacity=4 * self._options.memory_capacity)
                history = self._history
                super().reset()
                self._start(history[0][1] if history else uv)
                for t_done, u_done in history:
                    self.simulation.advance(t_done, u_done)
                self._n_logged = int(self.simulation.log.count[0])
        self._history.append((target, uv))
        log = self.simulation.log
        if log.count[0] > self._n_logged:
            from ..emtc.system import EVENT_DESCRIPTIONS, EVENTS

            n = int(log.count[0])
            self.events.extend((float(log.time[i]), EVENT_DESCRIPTIONS[EVENTS[int(log.code[i])]])
                               for i in range(self._n_logged, n))
            self._n_logged = n
        return y

    @property
    def bench_options(self):
        """The :class:`~clutchlab.emtc.system.BenchOptions` the run uses (its magnets' memories start with
        :attr:`memory_capacity` turning points and grow fourfold when a run fills them)."""
        return self._options

    def hold_inputs(self, inputs: dict) -> None:
        """Hold the FMI ``inputs`` (by name; missing ones at their start), starting the run with them at t = 0:
        the shaft speeds start free rolling on the drums (:meth:`initial_outputs`; a native FMU takes the
        drum speeds' start values until initialisation ends)."""
        uv = self.input_vector(self.resolve_inputs(inputs))
        if self.time != 0.0 or not self._started:
            self.reset()
            self._start(uv)
        super().hold_inputs(inputs)

    def do_step(self, t: float, dt: float, inputs: dict) -> dict:
        """Advance from ``t`` to ``t + dt`` (any step > 0); outputs at ``t + dt``.

        The controller runs at its own sample instants ``k * scenario.sample_time``
        that fall in ``[t, t + dt)``, with this step's inputs; between them the
        coil-current command is held, also across communication points.  A
        communication point within ``1e-9 * sample_time`` of a sample instant
        counts as that instant.

        Raises
        ------
        SimulationError
            Non-contiguous or non-positive step, step limit or step-size underflow.
        ParameterError
            Unknown or out-of-range input.
        """
        _check_time("EmtcCoSimulation", self.time, t, dt)
        return self._output_dict(self._step(t, dt, tuple(self.input_vector(self.resolve_inputs(inputs)).tolist())))

    def do_step_array(self, t: float, dt: float, u) -> np.ndarray:
        """:meth:`do_step` with the inputs and outputs in order (:meth:`CoSimulation.do_step_array`)."""
        torque, throttle, front, rear = u
        if (step_in_time(self.time, t, dt) and -_INF < torque < _INF
                and 0.0 <= throttle <= 1.0 and -_INF < front < _INF and -_INF < rear < _INF):
            uv = (torque, throttle, front, rear, 0.0, self._scenario.temperature_c)  # (as input_vector)
        else:  # every check of do_step, in its order
            _check_time("EmtcCoSimulation", self.time, t, dt)
            uv = tuple(self.input_vector(self.resolve_inputs({v.name: x for v, x in zip(self.inputs, u)})).tolist())
        return self._step(t, dt, uv)

    def _step(self, t, dt, uv):
        if not self._started:
            self._start(uv)
        t_end = t + dt
        target = snap_to_grid(t_end, self.sample_time)   # a sample instant counts as itself
        if target > self.simulation.time:
            y = self._advance(target, uv)
        else:  # (nothing to integrate: the outputs with the inputs held so far)
            y = self.simulation.reported()
        self.time = t_end
        return y
