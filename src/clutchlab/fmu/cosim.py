"""Co-simulation wrappers: the models as step-by-step slaves (FMI 2.0 co-simulation semantics).

A :class:`CoSimulation` is what :mod:`clutchlab.fmu.export` wraps into an
FMU: named real inputs, outputs and parameters (:class:`Variable`), and
``do_step(t, dt, inputs)`` that advances the compiled model from ``t`` to
``t + dt`` with the inputs held constant (zero-order hold) and returns the
outputs at ``t + dt``.  Each step *continues* the compiled integration from
the stored state (states, mode, step size, hysteresis memories) -- nothing is
re-simulated from t = 0.

* :class:`WetCoSimulation` -- the wet-clutch bench of Shin, Kim and Choi
  ([1], Eqs. 1-8) with the engagement dynamics of
  :mod:`clutchlab.wet.engagement`; written against the system contract
  (a :class:`clutchlab.system.Simulation` of the ``"wet"`` system).
* :class:`EmtcCoSimulation` -- the AWD vehicle with the EMTC on the drum
  bench ([2], Eqs. 8-31), the ``emtc_bench`` system of
  :mod:`clutchlab.emtc.system` resumed step by step by a
  :class:`clutchlab.system.Simulation`.
* ``EClutchCoSimulation`` (``clutchlab.eclutch.cosim``) -- the E-clutch
  dynamics, written against the same protocol.

:data:`COSIMULATIONS` maps the model names to ``"module:Class"`` strings,
imported lazily by :func:`load_cosimulation`.

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
.. [2] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

import abc
import dataclasses
import importlib
import math
import sys

import numpy as np

from ..errors import ParameterError, SimulationError
from . import COSIMULATIONS

__all__ = [
    "Variable",
    "CoSimulation",
    "ContractCoSimulation",
    "WetCoSimulation",
    "EmtcCoSimulation",
    "COSIMULATIONS",
    "load_cosimulation",
    "parameter_set_variables",
    "build_parameter_set",
    "fmi_unit",
    "fixed_step_parameter",
    "FIXED_STEP_DOC",
]

def load_cosimulation(name: str) -> type:
    """The co-simulation class registered under ``name`` in :data:`COSIMULATIONS`.

    Raises
    ------
    ParameterError
        Unknown name, or the class cannot be imported.
    """
    if name not in COSIMULATIONS:
        raise ParameterError(f"model = {name!r}: unknown (known: {', '.join(COSIMULATIONS)})")
    module_name, _, class_name = COSIMULATIONS[name].partition(":")
    try:
        cls = getattr(importlib.import_module(module_name), class_name)
    except (ImportError, AttributeError) as exc:
        raise ParameterError(f"model = {name!r}: cannot import {COSIMULATIONS[name]} ({exc})") from None
    return cls


def fmi_unit(unit: str) -> str:
    """Unit string in the Modelica/FMI notation (``"N*m"`` -> ``"N.m"``, ``"kg*m^2"`` -> ``"kg.m2"``).

    Parameters
    ----------
    unit : str
        Unit in pint notation, as in the parameter-set field metadata.
    """
    return unit.replace("**", "").replace("*", ".").replace("^", "").replace(" ", "")


@dataclasses.dataclass(frozen=True)
class Variable:
    """A real, scalar variable of a co-simulation.

    Parameters
    ----------
    name : str
        FMI name (structured naming: ``clutch.k1``, ``vehicle.gear_ratios[2]``).
    unit : str
        Unit in Modelica notation (``"N.m"``, ``"rad/s"``, ``"degC"``, ``"1"``);
        values are SI except temperatures in degC, as everywhere in clutchlab.
    start : float
        Start (default) value in ``unit``.
    description : str
        One line for the modelDescription.
    """

    name: str
    unit: str
    start: float
    description: str = ""

    def __post_init__(self):
        if not self.name or not isinstance(self.name, str):
            raise ParameterError(f"Variable.name = {self.name!r}: expected a non-empty string")
        if not math.isfinite(float(self.start)):
            raise ParameterError(f"Variable {self.name!r}: start = {self.start!r} is not finite")
        object.__setattr__(self, "start", float(self.start))


class CoSimulation(abc.ABC):
    """Protocol of a model run step by step by a co-simulation master (an FMU).

    Construction ``Cls(**parameter_values)`` takes parameter values by
    :class:`Variable` name; missing ones take their ``start`` (the model's
    paper / bundled preset).  :meth:`reset` returns to the initial state at
    t = 0; :meth:`do_step` advances with the inputs held constant.

    A model built from a description file (the driveline) names that file
    in :attr:`description_file` and returns, from :meth:`for_description`,
    its class for one file, whose variables are those of the described
    model.

    Attributes
    ----------
    name : str
        Model name (``"wet"``, ``"emtc"``, ``"eclutch"``, ``"driveline"``); a class attribute.
    inputs, outputs, parameters : tuple of Variable
        Real, continuous inputs; outputs; parameters (tunable before
        initialisation, values in SI); class attributes.
    description_file : str
        What the model is built from (``"a driveline description (TOML)"``),
        ``""`` for a model that takes no file; a class attribute.
    experiment : tuple of float or None
        Default experiment ``(stop time, communication step)`` [s] written
        into the FMU (None: the exporter's default for the model).
    """

    name: str = ""
    inputs: tuple = ()
    outputs: tuple = ()
    parameters: tuple = ()
    description_file: str = ""
    experiment: tuple | None = None

    @abc.abstractmethod
    def __init__(self, **parameter_values):
        ...

    @abc.abstractmethod
    def reset(self) -> None:
        """Back to the initial state at t = 0 (same parameters)."""

    @abc.abstractmethod
    def do_step(self, t: float, dt: float, inputs: dict) -> dict:
        """Advance from t to t+dt with the inputs held constant (zero-order hold); return outputs at t+dt."""

    def do_step_array(self, t: float, dt: float, u) -> np.ndarray:
        """:meth:`do_step` as the FMU calls it at every communication step: values in order, no names.

        The models override it with their fast path -- the checks of :meth:`do_step`, the inputs written
        into the held input vector, and one compiled call that advances and gathers the outputs
        (:meth:`clutchlab.system.Simulation.step`), with no dictionary built per step; this default goes
        through :meth:`do_step`.

        Parameters
        ----------
        t, dt : float
            Communication point and step [s].
        u : sequence of float
            Input values in the order of :attr:`inputs`.

        Returns
        -------
        ndarray
            Output values at ``t + dt`` in the order of :attr:`outputs`: the model's own array, rewritten by
            its next successful step (copy it to keep it).

        Raises
        ------
        SimulationError, ParameterError
            As :meth:`do_step`.
        """
        out = self.do_step(t, dt, {v.name: x for v, x in zip(self.inputs, u)})
        return np.array([out[v.name] for v in self.outputs], dtype=float)

    # ------------------------------------------------------------- optional hooks and helpers
    @classmethod
    def for_description(cls, path) -> type:
        """The co-simulation class of the model described by the file at ``path``.

        Only for a model with a :attr:`description_file`; the class returned
        has the variables of the described model.

        Parameters
        ----------
        path : str or Path
            The description file.

        Raises
        ------
        ParameterError
            The model takes no description file (or the file is invalid).
        """
        raise ParameterError(f"model {cls.name!r} takes no description file (got {str(path)!r})")

    def initial_outputs(self, inputs: dict) -> dict:
        """Outputs at t = 0 for the given inputs (optional; default: the outputs' start values).

        The FMU reports these after initialisation, before the first step.
        """
        return {v.name: v.start for v in self.outputs}

    @classmethod
    def resolve_parameters(cls, values: dict) -> dict:
        """All parameter values by name: ``values`` checked (known, finite) over the start values.

        Raises
        ------
        ParameterError
            Unknown parameter name or non-finite value.
        """
        known = {v.name: v.start for v in cls.parameters}
        for key, val in values.items():
            if key not in known:
                raise ParameterError(f"{cls.__name__}: unknown parameter {key!r}")
            try:
                fv = float(val)
            except (TypeError, ValueError):
                raise ParameterError(f"{cls.__name__}: parameter {key!r} = {val!r} is not a number") from None
            if not math.isfinite(fv):
                raise ParameterError(f"{cls.__name__}: parameter {key!r} = {val!r} is not finite")
            known[key] = fv
        return known

    @classmethod
    def resolve_inputs(cls, inputs: dict) -> dict:
        """Input values by name: ``inputs`` checked (known, finite); missing inputs take their start value.

        Raises
        ------
        ParameterError
            Unknown input name or non-finite value.
        """
        out = {v.name: v.start for v in cls.inputs}
        for key, val in inputs.items():
            if key not in out:
                raise ParameterError(f"{cls.__name__}: unknown input {key!r} (known: {', '.join(out)})")
            fv = float(val)
            if not math.isfinite(fv):
                raise ParameterError(f"{cls.__name__}: input {key!r} = {val!r} is not finite")
            out[key] = fv
        return out


def parameter_set_variables(prefix: str, cls, skip=()) -> tuple:
    """Variables for the numeric fields of a :class:`~clutchlab.params.ParameterSet` class.

    Parameters
    ----------
    prefix : str
        Name prefix (``"clutch"`` gives ``clutch.k1``).
    cls : type
        ParameterSet subclass; its default instance gives the start values.
    skip : iterable of str
        Field names left out (e.g. sensor noise that the model does not use).

    Returns
    -------
    tuple of Variable
        Scalars as ``prefix.field``, tuples as ``prefix.field[i]`` (1-based,
        FMI structured naming); units and descriptions from the field metadata.
    """
    out = []
    default = cls()
    for f in dataclasses.fields(cls):
        if f.name in skip or "unit" not in f.metadata:
            continue
        value = getattr(default, f.name)
        unit = fmi_unit(f.metadata["unit"])
        doc = f.metadata.get("doc", "")
        if isinstance(value, tuple):
            for i, v in enumerate(value):
                out.append(Variable(f"{prefix}.{f.name}[{i + 1}]", unit, float(v), f"{doc} (element {i + 1})"))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out.append(Variable(f"{prefix}.{f.name}", unit, float(value), doc))
    return tuple(out)


def build_parameter_set(prefix: str, cls, values: dict, skip=()):
    """A ``cls`` instance from the ``prefix.*`` entries of ``values`` (inverse of :func:`parameter_set_variables`).

    Parameters
    ----------
    prefix : str
        Name prefix used by :func:`parameter_set_variables`.
    cls : type
        ParameterSet subclass to build (validated on construction).
    values : dict
        All parameter values by name (e.g. from :meth:`CoSimulation.resolve_parameters`).
    skip : iterable of str
        Field names left out (they keep their defaults).

    Returns
    -------
    ParameterSet
        The default instance itself when no value differs from it.

    Raises
    ------
    ParameterError
        A whole-number field given a fractional value, or the set's own validation.
    """
    default = cls()
    kwargs = {}
    for f in dataclasses.fields(cls):
        if f.name in skip or "unit" not in f.metadata:
            continue
        dv = getattr(default, f.name)
        if isinstance(dv, tuple):
            kwargs[f.name] = tuple(values[f"{prefix}.{f.name}[{i + 1}]"] for i in range(len(dv)))
        elif isinstance(dv, (int, float)) and not isinstance(dv, bool):
            v = values[f"{prefix}.{f.name}"]
            if isinstance(dv, int):
                if v != round(v):
                    raise ParameterError(f"parameter {prefix}.{f.name} = {v!r}: must be a whole number")
                v = int(round(v))
            kwargs[f.name] = v
    if all(kwargs[k] == getattr(default, k) for k in kwargs):
        return default
    return cls(**kwargs)


def _flag(name: str, value: float) -> bool:
    if value not in (0.0, 1.0):
        raise ParameterError(f"parameter {name} = {value!r}: expected 0 or 1")
    return value == 1.0


#: description of the ``solver.fixed_step`` parameter of the co-simulations
FIXED_STEP_DOC = ("fixed-step (real-time) mode: Rodas3 steps of this length [s] on the grid k * fixed_step, "
                   "events at step ends; 0 = step-size control")


def fixed_step_parameter(values: dict):
    """The ``solver.fixed_step`` parameter of a co-simulation: None for 0 (step-size control), else the step [s].

    Parameters
    ----------
    values : dict
        Parameter values by name (:meth:`CoSimulation.resolve_parameters`), with ``solver.fixed_step`` [s].

    Raises
    ------
    ParameterError
        A negative or non-finite value.
    """
    from ..system import check_fixed_step

    h = values["solver.fixed_step"]
    if h == 0.0:
        return None
    try:
        return check_fixed_step(h)
    except ParameterError:
        raise ParameterError(f"parameter solver.fixed_step = {h!r}: must be 0 (step-size control) or a step > 0 "
                             "[s]") from None


_INF = math.inf


def step_in_time(t_model: float, t: float, dt: float) -> bool:
    """True if a step of ``dt`` [s] from ``t`` [s] may start from the model at ``t_model`` [s]: the test of
    :func:`_check_time` as comparisons (NaN and infinities fail them), for the per-step fast paths."""
    d = abs(t - t_model)
    return 0.0 < dt < _INF and -_INF < t < _INF and (d <= 1e-9 or d <= 1e-9 * abs(t))


def _check_time(owner: str, t_model: float, t: float, dt: float):
    if not (math.isfinite(t) and math.isfinite(dt)) or dt <= 0:
        raise SimulationError(f"{owner}.do_step: step size dt = {dt!r} must be > 0 [s]")
    if abs(t - t_model) > 1e-9 * max(1.0, abs(t)):
        raise SimulationError(
            f"{owner}.do_step: called at t = {t!r} s but the model is at t = {t_model!r} s "
            "(steps must be contiguous; call reset() to start again)")


class ContractCoSimulation(CoSimulation):
    """A co-simulation written once against the system contract (:mod:`clutchlab.system`).

    A model's co-simulation subclasses this and supplies only :meth:`build_system` (its
    :class:`~clutchlab.system.System` from the parameter values), :meth:`input_vector` (the held
    inputs ``u`` from the FMI inputs) and :meth:`output_sources` (where each FMI output comes from: an
    output, state or mode of the system).  Stepping is the core's resumable ``advance``
    (:class:`clutchlab.system.Simulation`): each ``do_step`` continues the integration from the
    stored state, modes, step size and memories, with the inputs held (zero-order hold); the FMI
    outputs are gathered in the same compiled call (:meth:`~clutchlab.system.Simulation.step`).

    Attributes
    ----------
    simulation_options : dict
        Keyword arguments of :class:`~clutchlab.system.Simulation` (``rtol``, ``max_step``, ...);
        a class attribute.
    """

    simulation_options: dict = {}

    def __init__(self, **parameter_values):
        self._values = self.resolve_parameters(parameter_values)
        self.reset()

    @abc.abstractmethod
    def build_system(self, values: dict):
        """The model's System for the parameter values ``values`` (by :class:`Variable` name, SI)."""

    @abc.abstractmethod
    def input_vector(self, inputs: dict) -> np.ndarray:
        """Held inputs ``u`` of the System from the FMI input values ``inputs`` (all present, checked)."""

    @abc.abstractmethod
    def output_sources(self) -> list:
        """Where each FMI output comes from, in the order of :attr:`outputs`: ``("output", name)``,
        ``("state", name)`` or ``("mode", index)`` of the System (:meth:`clutchlab.system.Simulation.report`)."""

    def write_inputs(self, u) -> None:
        """Hold the FMI input values ``u`` (in the order of :attr:`inputs`), checked as :meth:`do_step` checks
        them: this default goes through :meth:`resolve_inputs` and :meth:`input_vector`."""
        self.simulation.set_inputs(self.input_vector(self.resolve_inputs(
            {v.name: x for v, x in zip(self.inputs, u)})))

    def reset(self) -> None:
        """Back to the initial state at t = 0 (same parameters)."""
        from ..system import Simulation

        self.system = self.build_system(self._values)
        self.simulation = Simulation(self.system, **self.simulation_options)
        self.simulation.report(self.output_sources())
        self._output_names = tuple(v.name for v in self.outputs)

    def _output_dict(self, values) -> dict:
        return dict(zip(self._output_names, values.tolist()))

    def initial_outputs(self, inputs: dict) -> dict:
        """Outputs at t = 0 with the given inputs held."""
        self.simulation.set_inputs(self.input_vector(self.resolve_inputs(inputs)))
        return self._output_dict(self.simulation.reported())

    def do_step(self, t: float, dt: float, inputs: dict) -> dict:
        """Advance from ``t`` to ``t + dt`` [s] with ``inputs`` held; outputs at ``t + dt``."""
        _check_time(type(self).__name__, self.simulation.time, t, dt)
        self.simulation.set_inputs(self.input_vector(self.resolve_inputs(inputs)))
        return self._output_dict(self.simulation.step(t + dt))

    def do_step_array(self, t: float, dt: float, u) -> np.ndarray:
        """:meth:`do_step` with the inputs and outputs in order (:meth:`CoSimulation.do_step_array`)."""
        sim = self.simulation
        t_model = sim.time
        if not step_in_time(t_model, t, dt):
            _check_time(type(self).__name__, t_model, t, dt)
        if len(u) or self.inputs:
            self.write_inputs(u)
        return sim.step(t + dt)


# ===================================================================== wet clutch
def _wet_variables():
    from ..wet.params import Bench, WetClutch
    from ..wet.thermal import steady_state_temperature

    clutch = parameter_set_variables("clutch", WetClutch)
    bench = parameter_set_variables("bench", Bench, skip=(
        "sample_rate", "noise_torque", "noise_speed", "noise_force", "noise_position", "noise_temperature",
        "noise_fluid_temperature", "seed"))
    scenario = (
        Variable("scenario.free_inertia", "1", 0.0,
                 "drive: 0 speed-controlled bench motor (Fig. 4), 1 free inertia (inertia dynamometer, SAE No. 2)"),
        Variable("scenario.initial_slip_speed", "rad/s", 1500 * math.pi / 30, "slip speed at t = 0"),
        Variable("scenario.initial_temperature", "degC",
                 steady_state_temperature(0.0, 80.0, 70.0, WetClutch().k1, WetClutch().k2),
                 "pack temperature at t = 0 (default: Eq. 8 equilibrium of fluid and housing)"),
        Variable("scenario.fluid_temperature", "degC", 80.0, "oil reservoir temperature at t = 0"),
        Variable("scenario.housing_temperature", "degC", 70.0, "housing temperature at t = 0"),
        Variable("scenario.heater_setpoint", "degC", 80.0, "reservoir thermostat set point"),
        Variable("scenario.mu_scale", "1", 1.0, "factor on the asperity friction coefficient mu_f"),
        Variable("solver.rtol", "1", 1e-7, "relative tolerance of the DOPRI 5(4) step control"),
        Variable("solver.max_step", "s", 0.01, "largest integration step"),
        Variable("solver.fixed_step", "s", 0.0, FIXED_STEP_DOC),
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


class WetCoSimulation(CoSimulation):
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

    Written against the system contract: the model is the ``"wet"``
    :class:`~clutchlab.system.System` (:func:`clutchlab.wet.system.engagement_system`)
    with flat reference profiles, run by a :class:`clutchlab.system.Simulation`
    whose held inputs are the two references.  Each :meth:`do_step`
    continues the integration (``Simulation.advance``) from the stored
    state, modes and step size; lock-up, break-away, contact and the piston
    stop inside the step are located as in the native run and kept in
    :attr:`events` (``result.events`` names of :func:`clutchlab.wet.simulate`
    are in :attr:`simulation` ``.events()``).

    Notes
    -----
    The friction law is the bench's true law
    (:meth:`~clutchlab.wet.friction.ParametricFriction.bench_truth`).  The
    integrator stops at every communication point, so the results differ
    from one uninterrupted :func:`~clutchlab.wet.engagement.simulate_engagement`
    run by the integration error (of order ``solver.rtol``), not more.
    """

    name = "wet"
    inputs = (
        Variable("force_reference", "N", 0.0, "actuator force reference (piston apply force)"),
        Variable("slip_speed_reference", "rad/s", 1500 * math.pi / 30,
                 "slip-speed reference of the speed-controlled drive motor"),
    )
    outputs = tuple(Variable(n, u, 0.0, d) for n, u, d, _ in _wet_output_table())
    parameters = _wet_variables()

    def __init__(self, **parameter_values):
        from ..wet import engagement as E
        from ..wet.params import Bench, WetClutch

        values = self.resolve_parameters(parameter_values)
        self.parameter_values = values
        self.clutch = build_parameter_set("clutch", WetClutch, values)
        self.bench = build_parameter_set("bench", Bench, values, skip=(
            "sample_rate", "noise_torque", "noise_speed", "noise_force", "noise_position", "noise_temperature",
            "noise_fluid_temperature", "seed"))
        free = _flag("scenario.free_inertia", values["scenario.free_inertia"])
        self.rtol = values["solver.rtol"]
        self.max_step = values["solver.max_step"]
        if not (0 < self.rtol < 1):
            raise ParameterError(f"parameter solver.rtol = {self.rtol!r}: must be in (0, 1)")
        if not self.max_step > 0:
            raise ParameterError(f"parameter solver.max_step = {self.max_step!r}: must be > 0 [s]")
        self.fixed_step = fixed_step_parameter(values)
        # flat (zero) profiles: the references are the held inputs of the system
        self.scenario = E.Scenario(
            force_time=[0.0], force_value=[0.0], speed_time=[0.0], speed_value=[0.0], duration=1.0,
            motor="free" if free else "speed", initial_slip_speed=values["scenario.initial_slip_speed"],
            initial_temperature_c=values["scenario.initial_temperature"],
            fluid_temperature_c=values["scenario.fluid_temperature"],
            housing_temperature_c=values["scenario.housing_temperature"],
            heater_setpoint_c=values["scenario.heater_setpoint"])
        self._mu_scale = values["scenario.mu_scale"]
        self._table = _wet_output_table()
        self._output_names = tuple(v.name for v in self.outputs)
        # the input checks of _inputs as two comparisons (NaN and infinities fail them as well)
        self._force_max = self.bench.actuator_force_max * (1 + 1e-12)
        self._speed_max = self.bench.drive_speed_max if self.scenario.motor == "speed" else sys.float_info.max
        self.reset()

    def reset(self) -> None:
        self.time = 0.0
        self.simulation = None  # created at the first step / initial_outputs (the actuator starts at its reference)
        self.events = []
        self._n_events = 0

    @property
    def state(self):
        """State vector of the wet system (order of ``clutchlab.wet.system.STATES``), None before the start."""
        return None if self.simulation is None else self.simulation.x

    @property
    def mode(self) -> int:
        """Friction mode: 0 slip (positive), 1 stick, 2 slip (negative); -1 before the start."""
        from ..wet import system as W

        return -1 if self.simulation is None else int(self.simulation.m[W.M_FRICTION])

    @property
    def n_steps(self) -> int:
        """Accepted integration steps since the start."""
        return 0 if self.simulation is None else self.simulation.stats["accepted_steps"]

    def _inputs(self, u):
        fmax = self.bench.actuator_force_max
        f = u["force_reference"]
        w = u["slip_speed_reference"]
        if f < 0 or f > fmax * (1 + 1e-12):
            raise ParameterError(f"input force_reference = {f!r} N: must be within [0, {fmax:g}] N (actuator limit)")
        if self.scenario.motor == "speed" and abs(w) > self.bench.drive_speed_max:
            raise ParameterError(f"input slip_speed_reference = {w!r} rad/s exceeds the bench's speed limit "
                                 f"{self.bench.drive_speed_max:.6g} rad/s")
        return np.array([f, w])

    def _start(self, u):
        from ..system import Simulation
        from ..wet import system as W

        x0 = W.initial_state(self.scenario)
        x0[W.S_FA] = u["force_reference"]  # the actuator force starts at its reference, as in the native run
        params = W.pack_parameters(self.clutch, self.bench, self.scenario, mu_scale=self._mu_scale)
        system = W.engagement_system(self.scenario, clutch=self.clutch, bench=self.bench, params=params, x0=x0,
                                     rtol=self.rtol)
        self.simulation = Simulation(system, max_step=self.max_step, max_steps=2_000_000_000,
                                     fixed_step=self.fixed_step)
        # the FMI outputs, gathered by the compiled step (a name lookup per output and step cost more than the
        # integration of a 1 ms step, and a dict of them as much again)
        self.simulation.report([src if src[0] != "stick" else ("mode_is", W.M_FRICTION, 1)
                                for _, _, _, src in self._table])
        self._held = self.simulation.u  # the held references, written in place by every step
        self._event_count = self.simulation.log.count
        self.simulation.set_inputs(self._inputs(u))

    def _outputs(self):
        return dict(zip(self._output_names, self.simulation.reported().tolist()))

    def initial_outputs(self, inputs: dict) -> dict:
        u = self.resolve_inputs(inputs)
        if self.simulation is None or self.time != 0.0:
            self.reset()
            self._start(u)
        self.simulation.set_inputs(self._inputs(u))
        return self._outputs()

    def do_step(self, t: float, dt: float, inputs: dict) -> dict:
        """Advance from ``t`` to ``t + dt`` with the references held; return the outputs at ``t + dt``.

        Raises
        ------
        SimulationError
            Non-contiguous step, step limit or step-size underflow.
        ParameterError
            Unknown or out-of-range input.
        """
        _check_time("WetCoSimulation", self.time, t, dt)
        u = self.resolve_inputs(inputs)
        y = self.do_step_array(t, dt, (u["force_reference"], u["slip_speed_reference"]))
        return dict(zip(self._output_names, y.tolist()))

    def do_step_array(self, t: float, dt: float, u) -> np.ndarray:
        """:meth:`do_step` with the inputs and outputs in order (:meth:`CoSimulation.do_step_array`)."""
        f, w = u
        if (self.simulation is None
                or not (step_in_time(self.time, t, dt) and 0.0 <= f <= self._force_max
                        and abs(w) <= self._speed_max)):
            return self._step_checked(t, dt, f, w)
        held = self._held
        held[0] = f
        held[1] = w
        return self._step(t, t + dt)

    def _step_checked(self, t, dt, f, w):
        # a step with every check of do_step, in its order (the first step, or one that fails a check)
        _check_time("WetCoSimulation", self.time, t, dt)
        u = self.resolve_inputs({"force_reference": f, "slip_speed_reference": w})
        if self.simulation is None:
            self._start(u)
        self.simulation.set_inputs(self._inputs(u))
        return self._step(t, t + dt)

    def _step(self, t, t_end):
        try:
            y = self.simulation.step(t_end)
        except SimulationError as exc:
            raise SimulationError(f"WetCoSimulation: between t = {t} and {t_end} s: {exc}") from None
        self.time = t_end
        if self._event_count[0] > self._n_events:  # new events only (a DataFrame per step cost more than the step)
            from ..wet import engagement as E

            log = self.simulation.log
            n = int(log.count[0])
            names = self.simulation.system.events
            for i in range(self._n_events, n):
                name = names[int(log.code[i])]
                if name in E.EVENT_KINDS:
                    self.events.append(E.Event(float(log.time[i]), E.EVENT_KINDS[name]))
            self._n_events = n
        return y


# ===================================================================== EMTC
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

    scen = BenchScenario()
    return (parameter_set_variables("vehicle", VehicleParameters)
            + parameter_set_variables("actuator", ActuatorParameters)
            + parameter_set_variables("coupling", CouplingGeometry)
            + (Variable("scenario.gear", "1", float(scen.gear), "engaged gear (1-6)"),
               Variable("scenario.drum_load_front", "N.m", scen.drum_load_front, "extra drum resistance, front axle"),
               Variable("scenario.drum_load_rear", "N.m", scen.drum_load_rear, "extra drum resistance, rear axle"),
               Variable("scenario.sample_time", "s", scen.sample_time,
                        "EMTC controller sample time (any communication step: the controller samples at its own instants)"),
               Variable("solver.rtol", "1", 1e-6, "relative tolerance of the DOPRI 5(4) step control"),
               Variable("solver.fixed_step", "s", 0.0, FIXED_STEP_DOC)))


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

    name = "emtc"
    inputs = (
        Variable("torque_request", "N.m", 0.0, "coupling torque request T_cal of the AWD controller"),
        Variable("throttle", "1", 0.1, "engine throttle (0-1)"),
        Variable("drum_speed_front", "m/s", 8.0, "front drum surface speed"),
        Variable("drum_speed_rear", "m/s", 7.7, "rear drum surface speed"),
    )
    outputs = tuple(Variable(n, u, 0.0, d) for n, u, d, _ in _EMTC_OUTPUTS)
    parameters = _emtc_variables()

    def __init__(self, **parameter_values):
        from ..emtc.bench import ActuatorParameters, BenchScenario, VehicleParameters
        from ..emtc.magnet import bundled_magnet
        from ..emtc.system import BenchOptions
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
        if not (0 < self.rtol < 1):
            raise ParameterError(f"parameter solver.rtol = {self.rtol!r}: must be in (0, 1)")
        self.magnet = bundled_magnet()
        self._scenario = BenchScenario(gear=int(gear), drum_load_front=values["scenario.drum_load_front"],
                                       drum_load_rear=values["scenario.drum_load_rear"],
                                       sample_time=self.sample_time, duration=max(4.0, self.sample_time))
        self._options = BenchOptions(actuator=self.actuator, coupling=self.coupling)
        self.fixed_step = fixed_step_parameter(values)
        self.simulation_options = {"rtol": self.rtol, "max_steps": 2_000_000, "fixed_step": self.fixed_step}
        super().__init__(**parameter_values)

    # ---- the contract
    def build_system(self, values: dict):
        """The ``emtc_bench`` system with the inputs held by the master (``values``: the parameters, by name)."""
        from ..emtc.system import bench_system

        return bench_system(self.magnet, self._scenario, self.vehicle, self._options, cosimulation=True)

    def input_vector(self, inputs: dict) -> np.ndarray:
        """``u = [torque_request, throttle, drum_speed_front, drum_speed_rear, coil_current_command]`` from the
        FMI ``inputs`` (the coil current command is unused: the FMU's coupling runs its torque controller)."""
        thr = inputs["throttle"]
        if not 0.0 <= thr <= 1.0:
            raise ParameterError(f"input throttle = {thr!r}: must be within [0, 1]")
        return np.array([inputs["torque_request"], thr, inputs["drum_speed_front"], inputs["drum_speed_rear"], 0.0])

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
        r = self.vehicle.tyre_radius
        ic = self.vehicle.rear_final_drive
        x = self.simulation.x  # free rolling at t = 0, as simulate_bench
        x[0] = u[2] / r * ic
        x[1] = u[3] / r * ic
        self._started = True

    def _advance(self, target, uv):
        """Advance to ``target`` with the inputs ``uv`` (a tuple); the outputs there (:meth:`Simulation.step`).

        A full memory replays the steps with a larger one."""
        while True:
            held = self.simulation.u
            held[0], held[1], held[2], held[3], held[4] = uv
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

    def initial_outputs(self, inputs: dict) -> dict:
        """Outputs at t = 0 with the given inputs held (the shaft speeds start free rolling on the drums)."""
        uv = self.input_vector(self.resolve_inputs(inputs))
        if self.time != 0.0 or not self._started:
            self.reset()
            self._start(uv)
        return super().initial_outputs(inputs)

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
            uv = (torque, throttle, front, rear, 0.0)  # (as input_vector)
        else:  # every check of do_step, in its order
            _check_time("EmtcCoSimulation", self.time, t, dt)
            uv = tuple(self.input_vector(self.resolve_inputs({v.name: x for v, x in zip(self.inputs, u)})).tolist())
        return self._step(t, dt, uv)

    def _step(self, t, dt, uv):
        if not self._started:
            self._start(uv)
        ts = self.sample_time
        t_end = t + dt
        k = round(t_end / ts)
        target = k * ts if abs(k * ts - t_end) <= 1e-9 * ts else t_end  # a sample instant counts as itself
        if target > self.simulation.time:
            y = self._advance(target, uv)
        else:  # (nothing to integrate: the outputs with the inputs held so far)
            y = self.simulation.reported()
        self.time = t_end
        return y
