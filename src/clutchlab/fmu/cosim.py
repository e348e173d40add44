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
* ``EClutchCoSimulation`` (``clutchlab.fmu.eclutch``) -- the E-clutch
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

import numpy as np

from ..errors import ParameterError, SimulationError
from ..component import range_problem, range_text
from ..params.base import field_range, model_fields
from .registry import COSIMULATIONS

__all__ = [
    "snap_to_grid",
    "Variable",
    "CoSimulation",
    "ContractCoSimulation",
    "COSIMULATIONS",
    "load_cosimulation",
    "parameter_set_variables",
    "field_variable",
    "rtol_variable",
    "fixed_step_variable",
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
    minimum, maximum : float, optional
        Range of a parameter (inclusive, in ``unit``): the modelDescription's ``min`` and ``max``; a value
        outside it is refused when the model is instantiated (a component's declared range,
        :class:`clutchlab.component.Field`).
    positive : bool
        The value must be > 0 (written as ``min="0"``, the bound itself refused).
    """

    name: str
    unit: str
    start: float
    description: str = ""
    minimum: float | None = None
    maximum: float | None = None
    positive: bool = False

    @property
    def fmi_bounds(self) -> tuple:
        """``(min, max)`` as the modelDescription writes them (None: no attribute): a strict ``> 0`` as min 0."""
        low = 0.0 if self.positive and (self.minimum is None or self.minimum < 0.0) else self.minimum
        return low, self.maximum

    def __post_init__(self):
        if not self.name or not isinstance(self.name, str):
            raise ParameterError(f"Variable.name = {self.name!r}: expected a non-empty string")
        if not math.isfinite(float(self.start)):
            raise ParameterError(f"Variable {self.name!r}: start = {self.start!r} is not finite")
        object.__setattr__(self, "start", float(self.start))


def snap_to_grid(t_end: float, grid: float) -> float:
    """``t_end`` [s], or the instant ``k * grid`` it lies within ``1e-9 * grid`` of (:attr:`CoSimulation.
    step_grid_parameter`; the native FMU's ``fmi2DoStep`` computes the same, ``floor(t_end / grid + 0.5) * grid``).

    Parameters
    ----------
    t_end : float
        A step's end [s].
    grid : float
        The grid's period [s] (``<= 0``: none).
    """
    if not grid > 0.0:
        return t_end
    k = math.floor(t_end / grid + 0.5)
    return k * grid if abs(k * grid - t_end) <= 1e-9 * grid else t_end


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
    #: the class can become a native FMU (:mod:`clutchlab.fmu.native`): after ``hold_inputs(inputs)`` (the
    #: inputs by name, missing ones at their start; nothing evaluated), an instance runs a
    #: :class:`~clutchlab.system.Simulation` (``simulation``) that reports the outputs in order and holds the
    #: inputs; an optional ``input_bound_words()`` gives ``{input: (path, symmetric, label)}`` where an input's
    #: range follows the parameters: its upper bound is the packed model's number at ``path`` (a
    #: :attr:`~clutchlab.system.System.decided_at_start` path), its lower bound ``-`` that where ``symmetric``
    native: bool = False
    #: the parameter whose value [s] is the grid a step's end snaps to, a sampled controller's period (the EMTC's
    #: ``scenario.sample_time``): a communication point within ``1e-9`` of a period from an instant ``k * period``
    #: counts as that instant (:func:`snap_to_grid`), so a master's rounding of ``t + dt`` never moves a step
    #: across a sample; None: no grid.  A native FMU applies the same rule to the parameter's current value.
    step_grid_parameter: str | None = None

    @classmethod
    def for_native(cls) -> type:
        """The class a native FMU is built from (itself; a model whose Python co-simulation grows a buffer at
        run time, which compiled code cannot, gives a subclass that starts with a larger one: the EMTC)."""
        return cls

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
        declared = {v.name: v for v in cls.parameters}
        for key, val in values.items():
            if key not in known:
                raise ParameterError(f"{cls.__name__}: unknown parameter {key!r}")
            try:
                fv = float(val)
            except (TypeError, ValueError):
                raise ParameterError(f"{cls.__name__}: parameter {key!r} = {val!r} is not a number") from None
            if not math.isfinite(fv):
                raise ParameterError(f"{cls.__name__}: parameter {key!r} = {val!r} is not finite")
            v = declared[key]
            if range_problem(fv, v.minimum, v.maximum, v.positive) is not None:
                raise ParameterError(f"{cls.__name__}: parameter {key!r} = {val!r} is outside its range "
                                     f"{range_text(v.minimum, v.maximum, v.positive)} [{v.unit}]")
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
        FMI structured naming); units, descriptions and ranges (:func:`clutchlab.params.base.field_range`)
        from the field metadata.
    """
    out = []
    default = cls()
    for f in model_fields(cls):
        if f.name in skip:
            continue
        value = getattr(default, f.name)
        unit = fmi_unit(f.metadata["unit"])
        doc = f.metadata.get("doc", "")
        limits = field_range(f.metadata)   # the set's own checks, as the FMU's min and max
        if isinstance(value, tuple):
            for i, v in enumerate(value):
                out.append(Variable(f"{prefix}.{f.name}[{i + 1}]", unit, float(v), f"{doc} (element {i + 1})",
                                    *limits))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out.append(Variable(f"{prefix}.{f.name}", unit, float(value), doc, *limits))
    return tuple(out)


def field_variable(name: str, cls, field: str, description: str | None = None) -> Variable:
    """The :class:`Variable` of one field of a :class:`~clutchlab.params.ParameterSet` class: its default as the
    start value, its unit, its description and its range (:func:`clutchlab.params.base.field_range`).

    Parameters
    ----------
    name : str
        FMI name (``"scenario.gear"``).
    cls : type
        The ParameterSet subclass.
    field : str
        The field's name in it.
    description : str, optional
        Instead of the field's own.
    """
    meta = {f.name: f for f in dataclasses.fields(cls)}[field].metadata
    return Variable(name, fmi_unit(meta["unit"]), float(getattr(cls(), field)),
                    meta.get("doc", "") if description is None else description, *field_range(meta))


def rtol_variable(name: str, start: float, description: str) -> Variable:
    """A relative-tolerance parameter in [RTOL_MIN, 1] (:func:`clutchlab.system.check_rtol`, which also refuses 1).

    Parameters
    ----------
    name : str
        FMI name.
    start : float
        Its start value.
    description : str
        One line.
    """
    from ..system import RTOL_MIN

    return Variable(name, "1", start, description, RTOL_MIN, 1.0)


def fixed_step_variable() -> Variable:
    """The ``solver.fixed_step`` parameter [s] of every co-simulation, >= 0 (0: step-size control)."""
    return Variable("solver.fixed_step", "s", 0.0, FIXED_STEP_DOC, 0.0)


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
    for f in model_fields(cls):   # (a reference number has no variable: it keeps its default)
        if f.name in skip:
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
    output, state or mode of the system); and, where the inputs held at the start decide a state,
    :meth:`start_state`.  Every model's co-simulation is one: the wet bench, the EMTC, the E-clutch and any
    driveline.  Stepping is the core's resumable ``advance``
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
    native = True

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

    def start_state(self, x: np.ndarray, inputs: dict) -> None:
        """The states that the inputs decide at the start, written into ``x`` (the run's state at t = 0, in place):
        called with the inputs held (by name, checked) until the first step succeeds, so the last inputs held before
        it decide them.  Nothing by default; the wet bench's actuator force starts at its reference, as in the
        model's own run.  (A native FMU writes such an input into its state until initialisation ends.)"""

    def _hold(self, inputs: dict) -> None:
        """Hold the checked FMI ``inputs`` (all present), and before the first step the states they decide."""
        u = self.input_vector(inputs)
        if self._at_start:
            self.start_state(self.simulation.x, inputs)
        self.simulation.set_inputs(u)

    def write_inputs(self, u) -> None:
        """Hold the FMI input values ``u`` (in the order of :attr:`inputs`), checked as :meth:`do_step` checks
        them: this default goes through :meth:`resolve_inputs` and :meth:`input_vector`."""
        self._hold(self.resolve_inputs({v.name: x for v, x in zip(self.inputs, u)}))

    def reset(self) -> None:
        """Back to the initial state at t = 0 (same parameters)."""
        from ..system import Simulation

        self.system = self.build_system(self._values)
        self.simulation = Simulation(self.system, **self.simulation_options)
        self.simulation.report(self.output_sources())
        self._output_names = tuple(v.name for v in self.outputs)
        self._at_start = True

    def _output_dict(self, values) -> dict:
        return dict(zip(self._output_names, values.tolist()))

    def hold_inputs(self, inputs: dict) -> None:
        """Hold the FMI ``inputs`` (by name; missing ones at their start), evaluating nothing."""
        self._hold(self.resolve_inputs(inputs))

    def initial_outputs(self, inputs: dict) -> dict:
        """Outputs at t = 0 with the given inputs held, the modes the run starts from decided at them (the model's
        ``start``, as a native FMU decides them at its initialisation)."""
        self.hold_inputs(inputs)
        return self._output_dict(self.simulation.reported(start=True))

    def do_step(self, t: float, dt: float, inputs: dict) -> dict:
        """Advance from ``t`` to ``t + dt`` [s] with ``inputs`` held; outputs at ``t + dt``."""
        _check_time(type(self).__name__, self.simulation.time, t, dt)
        self._hold(self.resolve_inputs(inputs))
        y = self.simulation.step(t + dt)
        self._at_start = False
        return self._output_dict(y)

    def do_step_array(self, t: float, dt: float, u) -> np.ndarray:
        """:meth:`do_step` with the inputs and outputs in order (:meth:`CoSimulation.do_step_array`)."""
        sim = self.simulation
        t_model = sim.time
        if not step_in_time(t_model, t, dt):
            _check_time(type(self).__name__, t_model, t, dt)
        if len(u) or self.inputs:
            self.write_inputs(u)
        y = sim.step(t + dt)
        self._at_start = False
        return y
