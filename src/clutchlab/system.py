"""The system contract: how a compiled model describes itself, and the one way to run it.

A model (wet clutch, EMTC bench, E-clutch, a driveline) implements the
contract once, in its own package:

1. its parameters packed once into its own ``NamedTuple`` class of floats
   and arrays (numba caches code specialised on it across processes);
2. compiled hooks -- ``rhs``, ``outputs``, ``update``, ``restart``,
   ``accept``, ``next_break``, ``jacobian`` (see
   :mod:`clutchlab.numerics.dispatch`) -- registered for that class with
   :func:`clutchlab.numerics.dispatch.register`;
3. a :class:`System`: the named states, outputs, inputs, switching
   functions, events and modes with their units, the packed parameters, the
   initial state and the integration method.

Everything else is written once against the :class:`System`:
:func:`simulate` (returns a :class:`clutchlab.SimulationResult`),
:class:`Simulation` (resumable stepping for co-simulation and controllers in
the loop), :func:`simulate_batch` (one solver per variant in ``prange``, over
:class:`Variants`: the variants' parameters stacked along a first axis),
:func:`evaluate` (right-hand side, switching functions and outputs at one
point, for linearisation and tests).
"""

from __future__ import annotations

import collections
import contextlib
import contextvars
import dataclasses
import functools
import math
from typing import Callable

import numpy as np
import pandas as pd

from ._limits import check_allocation, short_repr
from .errors import ParameterError, SimulationError
from .numerics import status as st
from .numerics.calls import ADVANCE as _ADVANCE, OUTPUTS as _OUTPUTS, REPORT_KINDS, START as _START
from .result import SimulationResult

__all__ = ["Variable", "System", "Variants", "simulate", "Simulation", "simulate_batch", "batch_groups", "evaluate",
           "sample_grid",
           "checked_grid", "follow_rtol", "check_fixed_step", "check_fixed_step_span", "check_fixed_step_dynamics",
           "fastest_time_constant", "FixedStepWarning", "check_rtol", "check_atol", "RUN_OPTIONS",
           "RTOL_MIN", "MODELS", "register_model", "start_checked_later", "start_checks_deferred"]

_START_LATER = contextvars.ContextVar("clutchlab_start_checked_later", default=False)


@contextlib.contextmanager
def start_checked_later():
    """Within this context a model's build does not refuse an initial state that its compiled ``start`` hook refuses
    (a driveline's one-way clutch turning backward, a gear or motion source its flanges' initial speeds disagree
    with: :func:`clutchlab.driveline.kernel.driveline_start`, :mod:`clutchlab.numerics.dispatch`): whoever builds
    there runs ``start`` itself before the run and refuses the state then.  A native FMU's exporter builds its trial models so: the FMU
    runs the model's ``start`` at its initialisation with the start values the host set, so the range of each
    initial speed is not cut where it crosses another's at their start values (a constraint between two start
    values, which no range of one can state)."""
    token = _START_LATER.set(True)
    try:
        yield
    finally:
        _START_LATER.reset(token)


def start_checks_deferred() -> bool:
    """Whether a build runs inside :func:`start_checked_later`."""
    return _START_LATER.get()

#: rows recorded per chunk when every accepted step is kept (memory grows with the run, not with max_steps)
CHUNK_ROWS = 4096
#: rows of the first chunk of a step record (a short run allocates little; the chunks double up to CHUNK_ROWS)
FIRST_CHUNK_ROWS = 256
#: events a run keeps (more are counted as dropped)
EVENT_CAPACITY = 100_000


@dataclasses.dataclass(frozen=True)
class Variable:
    """A named quantity of a system with its unit.

    Parameters
    ----------
    name : str
        Canonical name (docs/nomenclature.md), without unit: ``"piston_position"``.
    unit : str
        Unit suffix of :data:`clutchlab.units.COLUMN_UNITS` (``"m"``, ``"rad_s"``, ``"Nm"``, ``"C"``,
        ``"1"`` for dimensionless).
    description : str
        One line for people.
    """

    name: str
    unit: str
    description: str = ""

    @property
    def column(self) -> str:
        """Column name with the unit suffix (``piston_position_m``)."""
        return f"{self.name}_{self.unit}"


def variables(spec) -> tuple:
    """``Variable`` tuple from ``(name, unit[, description])`` tuples (model packages use this)."""
    try:
        return _variables(tuple(spec))
    except TypeError:  # an unhashable entry (a list): not remembered
        return tuple(v if isinstance(v, Variable) else Variable(*v) for v in spec)


@functools.lru_cache(maxsize=256)
def _variables(spec: tuple) -> tuple:
    # a model's specs are module constants: converted once, not at every System (a run builds one)
    return tuple(v if isinstance(v, Variable) else Variable(*v) for v in spec)


@functools.lru_cache(maxsize=256)
def _columns(vars_: tuple) -> tuple:
    return tuple(v.column for v in vars_)


@dataclasses.dataclass(frozen=True)
class System:
    """A compiled model described once: what the integrator core and every tool built on it need.

    Attributes
    ----------
    name : str
        Model name (``"wet"``, ``"emtc_bench"``, ``"eclutch"``).
    params : NamedTuple
        Packed parameters; its class selects the model's compiled hooks.
    states, outputs, inputs : tuple of Variable
        Named, unit-carrying state, output and held-input vectors.
    switching : tuple of (str, int)
        Name and crossing direction (+1, -1, 0) of each switching function; +-2: the same direction, and a function
        the core looks at again at the earliest root of a step (a dip through zero and back before it is located);
        +-3: a waypoint, the same direction, whose crossing asks only for a step end just past it (no event: the
        Dormand-Prince step is taken again to 1 % past its root; the driveline's stuck elements coming near their
        limits); 4: a waypoint either way (the EMTC's coil current crossing a Preisach grid line, or turning); 5: a
        waypoint either way located even where an event function crosses later in the step (a backlash's gap centre,
        where its turning-point function changes its meaning: :data:`clutchlab.numerics.core.WAYPOINT_ALWAYS`).
    events : tuple of str
        Event names by code (what the hooks record).
    mode_names : tuple of str
        Names of the mode variables (entries of the mode vector).
    mode_values : tuple of tuple of str
        Names of the values of each mode variable.
    x0, m0, u0 : ndarray
        Initial state, initial modes (int), initial held inputs.
    atol : ndarray
        Absolute tolerance per state (default of :func:`simulate`).
    method : {"dopri", "rodas"}
        Dormand-Prince 5(4) or Rodas3 (stiff, with the mass matrix ``mass``).
    mass, jac_cols, fd_scale : ndarray, optional
        Diagonal mass matrix (0: algebraic row), the Jacobian's difference
        columns and their typical magnitudes (Rosenbrock).
    jac_pattern : ndarray of bool, optional
        Structural non-zeros of ``df/dx`` (``[row, column]``, valid in every mode); with it the
        difference columns are grouped so that columns sharing no row are perturbed together
        (greedy colouring, Curtis-Powell-Reid), one right-hand side per group.
    nonautonomous : bool
        Inputs vary inside a step (Rosenbrock: difference df/dt).
    jac_every : int
        Accepted steps a Jacobian is kept.
    rtol, max_step, first_step, event_tol : float
        Defaults of :func:`simulate` for this model.
    element_name : callable, optional
        ``element_name(event_code, element_index) -> str``: which element an event concerns.
    error_messages : dict
        Messages of the model's negative error codes.
    limits : dict
        Physical range ``name -> (low, high)`` [SI] of states, inputs or outputs (an actuator's travel,
        a drive's supply voltage): operating points outside it are refused
        (:func:`clutchlab.control.operating_point`).
    decided_at_start : tuple of (str, int, int or None)
        What the model's compiled ``start`` hook writes from the initial state (:mod:`clutchlab.numerics.dispatch`),
        and from the parameters alone, as ``(where, start, stop)`` slices: ``"m"`` the mode vector, ``"x"`` the
        state (the EMTC bench's shaft speeds, from its drum speed inputs),
        ``"params.<field>[.<field>...]"`` an array of the parameters or a field of a record array (the driveline:
        its network's modes and the stored energy it starts from, ``("params.work", -1, None)``; the wet clutch:
        the heat capacity and Greenwood-Williamson scale derived from its masses and roughness,
        ``("params.constants.heat_capacity", 0, None)``).  A run derives them again, so ``m0`` is not where a run starts from
        there; a native FMU's exporter does not look for a parameter's image in them (its ``start`` decides them
        again from the start values a host sets, :mod:`clutchlab.fmu.native.image`).
    """

    name: str
    params: tuple
    states: tuple
    outputs: tuple
    x0: np.ndarray
    m0: np.ndarray
    atol: np.ndarray
    switching: tuple = ()
    events: tuple = ()
    mode_names: tuple = ()
    mode_values: tuple = ()
    inputs: tuple = ()
    u0: np.ndarray | None = None
    method: str = "dopri"
    mass: np.ndarray | None = None
    jac_cols: np.ndarray | None = None
    jac_pattern: np.ndarray | None = None
    fd_scale: np.ndarray | None = None
    nonautonomous: bool = False
    jac_every: int = 1
    rtol: float = 1e-6
    max_step: float = math.inf
    first_step: float = 0.0
    event_tol: float = 1e-12
    element_name: Callable | None = None
    error_messages: dict = dataclasses.field(default_factory=dict)
    limits: dict = dataclasses.field(default_factory=dict)
    decided_at_start: tuple = ()

    def __post_init__(self):
        n = len(self.states)
        for field, arr, dtype in (("x0", self.x0, float), ("m0", self.m0, np.int64), ("atol", self.atol, float)):
            object.__setattr__(self, field, np.ascontiguousarray(arr, dtype=dtype))
        if self.x0.shape != (n,) or self.atol.shape != (n,):
            raise ParameterError(f"System {self.name!r}: x0 and atol need {n} entries (one per state)")
        if self.m0.shape != (len(self.mode_names),):
            raise ParameterError(f"System {self.name!r}: m0 needs {len(self.mode_names)} entries (one per mode)")
        u0 = np.zeros(len(self.inputs)) if self.u0 is None else np.ascontiguousarray(self.u0, dtype=float)
        if u0.shape != (len(self.inputs),):
            raise ParameterError(f"System {self.name!r}: u0 needs {len(self.inputs)} entries (one per input)")
        object.__setattr__(self, "u0", u0)
        if self.method not in ("dopri", "rodas"):
            raise ParameterError(f"System {self.name!r}: method = {self.method!r}: expected 'dopri' or 'rodas'")
        mass = np.ones(n) if self.mass is None else np.ascontiguousarray(self.mass, dtype=float)
        object.__setattr__(self, "mass", mass)
        cols = np.arange(n) if self.jac_cols is None else np.ascontiguousarray(self.jac_cols, dtype=np.int64)
        object.__setattr__(self, "jac_cols", cols)
        if self.jac_pattern is None:
            pattern = np.ones((n, n), dtype=np.bool_)
        else:
            pattern = np.ascontiguousarray(self.jac_pattern, dtype=np.bool_)
            if pattern.shape != (n, n):
                raise ParameterError(f"System {self.name!r}: jac_pattern must be {n} x {n}")
        object.__setattr__(self, "jac_pattern", pattern)
        scale = np.maximum(self.atol, 1e-12) if self.fd_scale is None else np.asarray(self.fd_scale, dtype=float)
        object.__setattr__(self, "fd_scale", np.ascontiguousarray(scale))
        object.__setattr__(self, "states", variables(self.states))
        object.__setattr__(self, "outputs", variables(self.outputs))
        object.__setattr__(self, "inputs", variables(self.inputs))
        self.state_columns, self.output_columns, self.input_columns, self._directions, self._option_memo  # noqa: B018

    @functools.cached_property
    def _jac_groups(self) -> np.ndarray:
        """Column groups of the finite-difference Jacobian (Rosenbrock only; one empty group for Dormand-Prince)."""
        if self.method != "rodas":
            return _NO_GROUPS
        return _colour_columns(self.jac_pattern, self.jac_cols)

    # ---- names (computed once: read by every run)
    @functools.cached_property
    def state_columns(self) -> tuple:
        return _columns(self.states)

    @functools.cached_property
    def output_columns(self) -> tuple:
        return _columns(self.outputs)

    @functools.cached_property
    def input_columns(self) -> tuple:
        return _columns(self.inputs)

    def state_index(self, name: str) -> int:
        return _index(self.states, name, "state", self.name)

    def output_index(self, name: str) -> int:
        return _index(self.outputs, name, "output", self.name)

    def input_index(self, name: str) -> int:
        return _index(self.inputs, name, "input", self.name)

    def replace(self, **changes) -> "System":
        """A copy with some fields replaced (``params``, ``x0``, ...)."""
        return dataclasses.replace(self, **changes)

    def variant(self, params=None, x0=None, m0=None, u0=None) -> "System":
        """A copy with other parameters and initial values, the rest shared and not checked again.

        For the many variants of a batch or repeated runs: :meth:`replace` checks and converts every
        field again (tens of microseconds), this only the ones given.

        Parameters
        ----------
        params : NamedTuple, optional
            Packed parameters of the same class as ``self.params``.
        x0, m0, u0 : array_like, optional
            Initial state, modes and held inputs, of this system's sizes.
        """
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)  # a shallow copy (copy.copy of a dataclass is slower)
        if params is not None:
            if type(params) is not type(self.params):
                raise ParameterError(f"System {self.name!r}: variant params must be a {type(self.params).__name__}")
            object.__setattr__(new, "params", params)
        for field, value, dtype in (("x0", x0, float), ("m0", m0, np.int64), ("u0", u0, float)):
            if value is not None:
                arr = np.ascontiguousarray(value, dtype=dtype)
                if arr.shape != getattr(self, field).shape:
                    raise ParameterError(f"System {self.name!r}: variant {field} needs shape {getattr(self, field).shape}")
                object.__setattr__(new, field, arr)
        return new

    # ---- options of the core
    @functools.cached_property
    def _option_memo(self) -> dict:
        """Options already built, by their arguments (shared with :meth:`variant` copies, which keep the tolerances)."""
        return {}

    def options(self, *, rtol=None, atol=None, max_step=None, max_steps=1_000_000, first_step=None,
                event_tol=None, fixed_step=None):
        """The core's :class:`~clutchlab.numerics.core.Options` from this system's defaults and overrides.

        Built once per set of arguments (without an ``atol`` array) and remembered: checking and
        converting them was a tenth of a short run's time.

        Parameters
        ----------
        rtol, atol, max_step, max_steps, first_step, event_tol
            As :func:`simulate` (defaults: this system's).
        fixed_step : float, optional
            Fixed-step mode's step [s] (:func:`simulate`); None for step-size control.
        """
        key = None
        if atol is None:
            key = (rtol, max_step, max_steps, first_step, event_tol, fixed_step)
            try:
                hit = self._option_memo.get(key)
            except TypeError:  # an unhashable argument: checked (and refused) below
                key = hit = None
            if hit is not None:
                return hit
        from .numerics.core import Options

        opt = self._build_options(Options, rtol, atol, max_step, max_steps, first_step, event_tol, fixed_step)
        if key is not None and len(self._option_memo) < 32:
            self._option_memo[key] = opt
        return opt

    def _build_options(self, Options, rtol, atol, max_step, max_steps, first_step, event_tol, fixed_step=None):
        fixed = check_fixed_step(fixed_step)
        rtol = check_rtol(self.rtol if rtol is None else rtol)
        if atol is None:   # below the system's rtol its absolute tolerances shrink in proportion (follow_rtol)
            atol_v = follow_rtol(self.atol, rtol, self.rtol)
        else:
            atol_v = check_atol(atol, self.atol.shape)
        max_step = self.max_step if max_step is None else max_step
        if not (max_step > 0):
            raise ParameterError(f"max_step = {short_repr(max_step)}: must be > 0 [s]")
        if int(max_steps) < 1:
            raise ParameterError(f"max_steps = {short_repr(max_steps)}: must be >= 1")
        first_step = self.first_step if first_step is None else first_step
        event_tol = self.event_tol if event_tol is None else event_tol
        if fixed == 0.0:
            return Options(float(rtol), np.ascontiguousarray(atol_v), float(min(max_step, 1e300)),
                           float(first_step), int(max_steps), float(event_tol), self._directions, self.mass,
                           self._jac_groups, self.jac_pattern, self.fd_scale,
                           int(self.jac_every), bool(self.nonautonomous))
        # fixed-step mode: the Rosenbrock loop for every model; a Dormand-Prince model gets difference columns
        # (all of them, grouped by its pattern) and df/dt (its inputs may vary inside a frame)
        groups = _colour_columns(self.jac_pattern, self.jac_cols) if self.method != "rodas" else self._jac_groups
        return Options(float(rtol), np.ascontiguousarray(atol_v), float(min(max_step, 1e300)), float(first_step),
                       int(max_steps), float(event_tol), self._directions, self.mass, groups,
                       self.jac_pattern, self.fd_scale, 1, bool(self.nonautonomous or self.method != "rodas"),
                       fixed)

    @functools.cached_property
    def _directions(self) -> np.ndarray:
        """Crossing direction of each switching function (``Options.gdir``)."""
        gdir = np.array([d for _, d in self.switching], dtype=np.int64)
        gdir.setflags(write=False)
        return gdir

    # ---- events
    def events_frame(self, times, codes, elements, variant=None) -> pd.DataFrame:
        """Named events as a DataFrame (``time_s``, ``event``, ``element``)."""
        names = [self.events[int(c)] if 0 <= int(c) < len(self.events) else f"event {int(c)}" for c in codes]
        if self.element_name is not None:
            elems = [self.element_name(int(c), int(e)) for c, e in zip(codes, elements)]
        else:
            elems = ["" if int(e) < 0 else str(int(e)) for e in elements]
        frame = pd.DataFrame({"time_s": np.asarray(times, dtype=float), "event": names, "element": elems})
        if variant is not None:
            frame.insert(0, "variant", variant)
        return frame


_NO_GROUPS = np.full((1, 1), -1, dtype=np.int64)
_NO_GROUPS.setflags(write=False)
_COLOURINGS: dict = {}


def _colour_columns(pattern: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Groups of columns that share no structural row (greedy colouring), padded with -1.

    Remembered per (pattern, columns): the variants of a model share their structure.
    """
    key = (pattern.shape, pattern.tobytes(), cols.tobytes())
    hit = _COLOURINGS.get(key)
    if hit is None:
        if len(_COLOURINGS) > 256:
            _COLOURINGS.clear()
        hit = _COLOURINGS[key] = _colour(pattern, cols)
        hit.setflags(write=False)
    return hit


def _colour(pattern: np.ndarray, cols: np.ndarray) -> np.ndarray:
    groups: list[list[int]] = []
    rows: list[np.ndarray] = []
    for c in cols:
        for g, used in zip(groups, rows):
            if not np.any(used & pattern[:, c]):
                g.append(int(c))
                used |= pattern[:, c]
                break
        else:
            groups.append([int(c)])
            rows.append(pattern[:, c].copy())
    width = max((len(g) for g in groups), default=1)
    out = np.full((max(len(groups), 1), width), -1, dtype=np.int64)
    for i, g in enumerate(groups):
        out[i, :len(g)] = g
    return out


#: the options every entry point that runs a model takes, with one meaning each (docs/architecture.md, "One option
#: set"): relative tolerance, absolute tolerance per state [its unit], largest step [s], sample interval of the
#: result [s], step of the fixed-step mode [s]
RUN_OPTIONS = ("rtol", "atol", "max_step", "output_step", "fixed_step")
#: smallest relative tolerance a run accepts: 100 machine epsilons (SciPy's ``solve_ivp`` floor); below it no step
#: of a double-precision integrator can meet the tolerance, and a run would end in a step-size underflow
RTOL_MIN = 100.0 * float(np.finfo(float).eps)


def check_rtol(rtol, name: str = "rtol") -> float:
    """A relative tolerance, checked once for every model: finite, in (0, 1) and at least :data:`RTOL_MIN`.

    Parameters
    ----------
    rtol : float
        The relative tolerance [-].
    name : str
        How the caller names it in the message (``"rtol"``, ``"parameter solver.rtol"``, ``"simulation.rtol"``).

    Raises
    ------
    ParameterError
        Naming ``name`` and the value.
    """
    if isinstance(rtol, (bool, np.bool_)) or not isinstance(rtol, (int, float, np.integer, np.floating)) \
            or not 0.0 < float(rtol) < 1.0:
        raise ParameterError(f"{name} = {short_repr(rtol)}: must be in (0, 1)")
    if float(rtol) < RTOL_MIN:
        raise ParameterError(f"{name} = {short_repr(rtol)}: below {RTOL_MIN:.2g} (100 machine epsilons), which no "
                             "double-precision step can meet")
    return float(rtol)


def check_atol(atol, shape, name: str = "atol") -> np.ndarray:
    """Absolute tolerances per state, checked once for every model: finite and > 0, a scalar or one per state.

    Parameters
    ----------
    atol : float or array_like
        One tolerance for every state, or one per state [the state's unit].
    shape : tuple
        The shape of the state vector.
    name : str
        How the caller names it in the message.

    Returns
    -------
    ndarray
        ``atol`` broadcast to ``shape`` (a copy).

    Raises
    ------
    ParameterError
        Not numbers, the wrong number of them, not finite or not > 0.
    """
    try:
        v = np.broadcast_to(np.asarray(atol, dtype=float), shape).copy()
    except (TypeError, ValueError):
        raise ParameterError(f"{name} = {short_repr(atol)}: expected a number > 0 or one per state "
                             f"({shape[0] if shape else 1})") from None
    if not np.all(np.isfinite(v)) or np.any(v <= 0):
        raise ParameterError(f"{name} = {short_repr(atol)}: must be > 0")
    return v


def follow_rtol(atol, rtol: float, default_rtol: float):
    """The absolute tolerances of a run at ``rtol``: ``atol`` (the model's, set for its ``default_rtol``) at that
    tolerance and above, ``atol · rtol / default_rtol`` below it -- so that a tighter ``rtol`` brings the error
    down with it (issue #30: with ``atol`` fixed, the error of every model stopped at the floor its absolute
    tolerances set, 3.5e-4 for the E-clutch at rtol 1e-10 and 1e-13 alike).  The one rule of every run through
    the contract (:meth:`System.options` where no ``atol`` is given: :func:`simulate`, :class:`Simulation`,
    batches, co-simulations, closed loops and FMUs).

    Parameters
    ----------
    atol : float or numpy.ndarray
        The model's absolute tolerances (per state).
    rtol : float
        The run's relative tolerance.
    default_rtol : float
        The relative tolerance ``atol`` was set for (the system's ``rtol``).
    """
    return atol * min(1.0, float(rtol) / float(default_rtol))


def check_fixed_step(fixed_step) -> float:
    """The fixed step [s] of a run (0.0 for None: step-size control); :class:`ParameterError` unless finite and > 0.

    Parameters
    ----------
    fixed_step : float or None
        Step [s] of the fixed-step mode, or None.
    """
    if fixed_step is None:
        return 0.0
    if isinstance(fixed_step, (bool, np.bool_)) or not isinstance(fixed_step, (int, float, np.integer, np.floating)) \
            or not (math.isfinite(fixed_step) and fixed_step > 0):
        raise ParameterError(f"fixed_step = {short_repr(fixed_step)}: must be a finite step > 0 [s] (or None for "
                             "step-size control)")
    return float(fixed_step)


#: most steps of the fixed-step mode in one :meth:`Simulation.advance` (a co-simulation's communication step):
#: ``solver.fixed_step = 1e-12`` made one 1 ms step of an FMU take minutes (#33)
FIXED_STEP_BUDGET = 1e6


def check_fixed_step_span(fixed: float, t0: float, t_end: float, output_step=None) -> None:
    """A fixed step [s] no longer than the run and than its output step: a longer one is one step over the whole
    run (an E-clutch peak force of 0 N, a driveline's energy balance off by 1,300 times its input work, #33).

    Parameters
    ----------
    fixed : float
        The fixed step [s] (0: step-size control, nothing to check).
    t0, t_end : float
        Start and end of the run [s].
    output_step : float, optional
        Sample interval of the run [s].

    Raises
    ------
    ParameterError
        Naming the step and the span it exceeds.
    """
    if not fixed > 0.0:
        return
    span = float(t_end) - float(t0)
    if fixed > span * (1.0 + 1e-12):
        raise ParameterError(f"fixed_step = {fixed:g} s is longer than the run ({span:g} s): choose a step of a "
                             "fraction of the fastest dynamics, e.g. 1 ms")
    if output_step is not None and fixed > float(output_step) * (1.0 + 1e-12):
        raise ParameterError(f"fixed_step = {fixed:g} s is longer than the output step ({float(output_step):g} s): "
                             "the samples between two steps would hold one state; choose a step <= the output step")


#: a fixed step longer than this many times the fastest time constant at the start is said in a warning (#33)
FIXED_STEP_WARN_FACTOR = 100.0


class FixedStepWarning(UserWarning):
    """A fixed step far longer than the model's fastest time constant (:func:`check_fixed_step_dynamics`)."""


def fastest_time_constant(system: System, t: float = 0.0) -> float:
    """The fastest time constant [s] of ``system`` at its start: ``1 / max |lambda|`` over the eigenvalues of the
    linearisation at ``(t, x0, u0, m0)`` in its start modes (forward differences of :func:`evaluate`; with a mass
    matrix, the generalised eigenvalues of ``(J, M)``, whose algebraic rows give infinite ones, left out);
    ``inf`` where every eigenvalue is zero (free inertias).

    Parameters
    ----------
    system : System
        The system, at its initial state, inputs and modes.
    t : float
        The time [s] of the linearisation.
    """
    import scipy.linalg

    n = len(system.states)
    if n == 0:
        return math.inf
    opt = system.options()
    x0 = system.x0.astype(float)
    f0 = evaluate(system, t, x0)[0]
    scale = np.maximum(np.abs(x0), np.broadcast_to(opt.atol, (n,)) / opt.rtol)
    jac = np.empty((n, n))
    for j in range(n):
        h = math.sqrt(np.finfo(float).eps) * float(scale[j])
        x = x0.copy()
        x[j] += h
        jac[:, j] = (evaluate(system, t, x)[0] - f0) / h
    mass = np.asarray(opt.mass, dtype=float)
    with np.errstate(all="ignore"):
        lam = scipy.linalg.eigvals(jac, np.diag(mass) if mass.ndim == 1 and mass.size == n else None)
    lam = np.abs(lam[np.isfinite(lam)])
    top = float(lam.max()) if lam.size else 0.0
    return 1.0 / top if top > 0.0 else math.inf


def check_fixed_step_dynamics(system: System, fixed: float, t0: float = 0.0) -> None:
    """Warn (:class:`FixedStepWarning`) where a fixed step [s] is more than :data:`FIXED_STEP_WARN_FACTOR` times
    the model's fastest time constant at its start (:func:`fastest_time_constant`): Rodas3 is L-stable, so the
    run stays stable and damps what is faster than its step, but it does not resolve it (a transient of the
    actuator, a contact, a lock-up shorter than a step).  A HIL frame chosen on purpose may do this; the
    warning says so once per run.  Nothing for step-size control (``fixed`` 0).

    Parameters
    ----------
    system : System
        The system about to run.
    fixed : float
        Its fixed step [s] (0: step-size control).
    t0 : float
        The start time [s], where the time constants are taken.
    """
    if not fixed > 0.0:
        return
    tau = fastest_time_constant(system, t0)
    if fixed > FIXED_STEP_WARN_FACTOR * tau:
        import warnings

        warnings.warn(f"{system.name}: fixed_step = {fixed:g} s is {fixed / tau:.3g} times the model's fastest time "
                      f"constant at its start ({tau:.3g} s): the run stays stable but does not resolve what is "
                      f"faster than a step; for its transients choose a step near {10.0 * tau:.2g} s, or step-size "
                      "control", FixedStepWarning, stacklevel=3)


def _index(vars_, name, kind, model):
    for i, v in enumerate(vars_):
        if name in (v.name, v.column):
            return i
    known = ", ".join(v.column for v in vars_) or "none"
    raise ParameterError(f"{model}: unknown {kind} {name!r} (known: {known})")


_CORE = None
#: the statuses by code (calling the enum class costs a microsecond a run)
_STATUS = {int(s): s for s in st.Status}
#: the event log of a run without events (read-only, shared)
_NO_EVENTS = (np.empty(0), np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64))
for _a in _NO_EVENTS:
    _a.setflags(write=False)


def _numerics_core():
    """The integrator core, imported on first use (``import clutchlab`` stays light; an import
    statement in a function costs about 1.5 us a call, measured)."""
    global _CORE
    if _CORE is None:
        from .numerics import core

        _CORE = core
    return _CORE


#: sample grids checked once (:func:`checked_grid`), by ``id``; the dict holds them, so an ``id`` names one array
_CHECKED_GRIDS: "collections.OrderedDict[int, np.ndarray]" = collections.OrderedDict()
_CHECKED_GRIDS_SIZE = 64


def checked_grid(ts) -> np.ndarray:
    """Sample times checked once, for a grid a package builds once and passes to many runs.

    ``ts`` must be finite and increasing (else :class:`~clutchlab.errors.ParameterError`).  :func:`sample_grid`
    (hence :func:`simulate` and :func:`simulate_batch`) recognises the returned array by its identity and
    skips the pass over all its times that it makes for any other array (about 2 us for 1,001 times:
    a tenth of the Python around a 1 s wet engagement).  The array must not be changed afterwards.

    Parameters
    ----------
    ts : array_like
        Sample times [s].

    Returns
    -------
    ndarray
        ``ts`` as a contiguous float array (the same object if it already was one).
    """
    ts = np.ascontiguousarray(ts, dtype=float)
    if ts.ndim != 1:
        ts = ts.ravel()
    if not (bool(np.isfinite(ts).all()) and (ts.size < 2 or bool((ts[1:] >= ts[:-1]).all()))):
        raise ParameterError("sample_times: must be finite and increasing")
    _CHECKED_GRIDS[id(ts)] = ts
    while len(_CHECKED_GRIDS) > _CHECKED_GRIDS_SIZE:
        _CHECKED_GRIDS.popitem(last=False)  # (an array dropped here is just checked again when used)
    return ts


def sample_grid(t0: float, t_end: float, output_step: float | None, sample_times=None):
    """Sample times of a run: ``sample_times`` as given, an ``output_step`` grid, or ``None`` (every step).

    Parameters
    ----------
    t0, t_end : float
        Start and end of the run [s].
    output_step : float or None
        Grid interval [s]; the end time is always a sample.
    sample_times : array_like, optional
        Explicit, increasing sample times within ``[t0, t_end]`` [s] (takes precedence).
    """
    if sample_times is not None:
        checked = _CHECKED_GRIDS.get(id(sample_times)) is sample_times
        ts = sample_times if checked else np.ascontiguousarray(sample_times, dtype=float).ravel()
        # one comparison pass (NaN and infinities fail it as well), not for a grid checked before
        if ts.size and not (ts[0] >= t0 and ts[-1] <= t_end * (1 + 1e-12) + 1e-300
                            and (ts.size == 1 or checked or bool((ts[1:] >= ts[:-1]).all()))):
            raise ParameterError(f"sample_times: must be finite, increasing and within [{t0:g}, {t_end:g}] s")
        return ts
    if output_step is None:
        return None
    if not (isinstance(output_step, (int, float, np.floating)) and math.isfinite(output_step) and output_step > 0):
        raise ParameterError(f"output_step = {short_repr(output_step)}: must be > 0 [s]")
    n = int(math.floor((t_end - t0) / output_step + 1e-9)) + 1
    check_allocation(n, 1, f"output_step = {output_step!r} s over {t_end - t0:g} s")
    ts = t0 + np.arange(n) * output_step
    if ts[-1] < t_end - 1e-9 * output_step:
        ts = np.append(ts, t_end)
    return ts


def _check_status(system: System, code: int, si, t, check: bool):
    if not check or code in (st.SUCCESS, st.TERMINATED):
        return
    msg = st.message(code)
    if code == st.MODEL_ERROR:
        msg = system.error_messages.get(int(si[7]), msg)
    raise SimulationError(f"{system.name}: {msg} (at t = {t:.6g} s)")


def simulate(system: System, t_end: float, *, rtol: float | None = None, atol=None, max_step: float | None = None,
             output_step: float | None = None, sample_times=None, max_steps: int = 1_000_000,
             first_step: float | None = None, event_tol: float | None = None, outputs: bool = True,
             t0: float = 0.0, check: bool = True, fixed_step: float | None = None) -> SimulationResult:
    """Simulate a system from ``t0`` to ``t_end`` with the integrator core.

    Parameters
    ----------
    system : System
    t_end : float
        End time [s].
    rtol : float, optional
        Relative tolerance (default: the model's).
    atol : float or array_like, optional
        Absolute tolerance, per state in the state's unit (default: the model's).
    max_step : float, optional
        Largest step [s] (default: the model's).
    output_step : float, optional
        Sample interval [s] of the result (dense output); without it every accepted step is kept.
    sample_times : array_like, optional
        Explicit sample times [s] instead of ``output_step``.
    max_steps : int
        Accepted-step limit.
    first_step, event_tol : float, optional
        First trial step [s] and event bracket width [s] (defaults: the model's).
    outputs : bool
        Evaluate the outputs at the samples (otherwise NaN).
    t0 : float
        Start time [s].
    check : bool
        Raise :class:`~clutchlab.errors.SimulationError` for a failed run (otherwise the
        result carries the status).
    fixed_step : float, optional
        Fixed-step (real-time, HIL frame) mode with this step [s]: Rodas3 (linearly implicit, L-stable,
        order 3) for every model, steps on the grid ``t0 + k * fixed_step`` (the last one shorter if
        ``t_end`` is not on it), no error control, the Jacobian every step, mode changes and break times
        inside a step handled at its end (docs/architecture.md, "Fixed-step mode").  ``rtol``, ``atol``,
        ``max_step``, ``first_step`` and ``event_tol`` are accepted and unused.  None (default): step-size
        control.

    Returns
    -------
    SimulationResult
        ``stats`` holds the solver counters (``accepted_steps``, ``rhs_evaluations``, ...) and
        ``fixed_step`` (0.0 for step-size control).
    """
    core = _numerics_core()

    if not (isinstance(t_end, (int, float, np.floating)) and math.isfinite(t_end) and t_end > t0):
        raise ParameterError(f"t_end = {short_repr(t_end)}: must be finite and > t0 = {t0:g} s")
    opt = system.options(rtol=rtol, atol=atol, max_step=max_step, max_steps=max_steps, first_step=first_step,
                         event_tol=event_tol, fixed_step=fixed_step)
    check_fixed_step_span(opt.fixed_step, t0, t_end, output_step)
    check_fixed_step_dynamics(system, opt.fixed_step, t0)
    ts = sample_grid(t0, float(t_end), output_step, sample_times)
    nx, ny, nm = len(system.states), len(system.outputs), len(system.mode_names)
    x = system.x0.copy()
    m = system.m0.copy()
    u = system.u0.copy()
    log = core.new_log(EVENT_CAPACITY)
    advance = core.advance_rodas if system.method == "rodas" or opt.fixed_step > 0.0 else core.advance_dopri
    # (a record of every step may be resumed in new buffers: room for Rodas3 to keep its Jacobian across them,
    # core.RESUME_NOTE)
    sf, si = core.new_solver_state(float(t0), nx if ts is None and advance is core.advance_rodas else 0)
    if ts is not None:
        check_allocation(ts.size, nx + ny + nm + 1, f"{ts.size} samples of {system.name}")
        # every recorded row is written whole (time, states, modes and, if asked, outputs)
        rt = np.empty(ts.size)
        rx = np.empty((ts.size, nx))
        rm = np.empty((ts.size, nm), dtype=np.int64)
        ry = np.empty((ts.size if outputs else 1, ny))
        code = advance(system.params, x, m, u, float(t_end), sf, si, opt, log, ts, rt, rx, rm, ry, bool(outputs))
        n = int(si[core.SI_IREC])
        rt, rx, rm = rt[:n], rx[:n], rm[:n]
        ry = ry[:n] if outputs else np.full((n, ny), np.nan)
    else:
        empty = np.empty(0)
        chunks = []
        rows = FIRST_CHUNK_ROWS  # the record grows with the run: chunks of 256, 512, ... up to CHUNK_ROWS rows
        held = 0
        while True:
            # every recorded row is written whole (time, states, modes and, if asked, outputs): nothing to fill
            rt = np.empty(rows)
            rx = np.empty((rows, nx))
            rm = np.empty((rows, nm), dtype=np.int64)
            ry = np.empty((rows, ny)) if outputs else np.empty((1, ny))
            si[core.SI_IREC] = 0
            code = advance(system.params, x, m, u, float(t_end), sf, si, opt, log, empty, rt, rx, rm, ry,
                           bool(outputs))
            n = int(si[core.SI_IREC])
            held += n
            chunks.append((rt[:n], rx[:n], rm[:n], ry[:n] if outputs else None))
            if code != st.RECORD_FULL:
                break
            rows = min(2 * rows, CHUNK_ROWS)
            check_allocation(held + rows, nx + ny + nm + 1, f"the steps of {system.name}")
        if len(chunks) == 1:
            rt, rx, rm, ry = chunks[0]
        else:
            rt = np.concatenate([c[0] for c in chunks])
            rx = np.concatenate([c[1] for c in chunks])
            rm = np.concatenate([c[2] for c in chunks])
            ry = np.concatenate([c[3] for c in chunks]) if outputs else None
        if not outputs:
            ry = np.full((rt.size, ny), np.nan)
    code = int(code)
    t_final = float(sf[0])
    _check_status(system, code, si, t_final, check)
    counts = si.tolist()  # Python ints at once (an int() per NumPy element costs more)
    ne, dropped = log.count.tolist()
    # the events DataFrame is built when it is first read (SimulationResult takes a callable)
    events = functools.partial(system.events_frame, *((log.time[:ne].copy(), log.code[:ne].copy(),
                                                       log.element[:ne].copy()) if ne else _NO_EVENTS))
    stats = {"accepted_steps": counts[core.SI_ACCEPTED], "rejected_steps": counts[core.SI_REJECTED],
             "rhs_evaluations": counts[core.SI_NRHS], "jacobians": counts[core.SI_NJAC],
             "events_dropped": dropped, "final_state": x, "final_modes": m,  # this run's own copies
             "final_time": t_final, "fixed_step": opt.fixed_step}
    status = _STATUS[code] if code in _STATUS else st.Status(code)  # (SUCCESS is 0: falsy, so no `or` here)
    return SimulationResult(rt, rx, ry, rm, events, status, system.state_columns,
                            system.output_columns, tuple(system.mode_names), tuple(system.mode_values), stats,
                            system.name)


#: kinds of reported values (``clutchlab.numerics.calls.REPORT_*``) by the names :meth:`Simulation.report` takes
_REPORT_KINDS = {name: k for k, name in enumerate(REPORT_KINDS)}


def _held(name: str, doc: str) -> property:
    """An attribute of :class:`Simulation` packed into its compiled call: replacing it unpacks the call (the next
    call packs the objects again, through numba's dispatcher)."""
    key = "_held_" + name

    def get(self):
        return self.__dict__[key]

    def set_(self, value):
        self.__dict__[key] = value
        self.__dict__["_fast"] = None

    return property(get, set_, doc=doc)


class Simulation:
    """Resumable run of a system (co-simulation, controllers in the loop): ``advance(t_end, u)`` step by step.

    Parameters
    ----------
    system : System
    rtol, atol, max_step, max_steps, first_step, event_tol
        As :func:`simulate`; ``max_steps`` counts over the whole session.
    t0 : float
        Start time [s].
    fixed_step : float, optional
        Fixed-step mode (a HIL frame) with this step [s], as :func:`simulate`; the steps lie on the grid
        ``t0 + k * fixed_step`` whatever the times ``advance`` is called with (an advance to a time off the
        grid ends with a shorter step).  None: step-size control.

    Notes
    -----
    The session's objects -- the parameters, ``x``, ``m``, ``u``, the solver state, options, event log and
    buffers -- are packed once, at the third call (the first two go through numba's dispatcher, so that a
    session advanced once or twice compiles nothing more), into a table that the model's compiled ``session`` entry
    reads (:mod:`clutchlab.numerics.session`): a call passes one pointer and the end time instead of some
    thirty arrays that numba would unbox at every call.  Their contents may change between calls (``x[0] =
    ...``, ``u[:] = ...``); replacing one of ``system``, ``x``, ``m``, ``u`` or ``log`` by another object packs
    them again at the next call.
    """

    system = _held("system", "The simulated :class:`System`.")
    x = _held("x", "State vector [SI] (changed in place by every call).")
    m = _held("m", "Mode vector (int64, changed in place).")
    u = _held("u", "Held inputs (order of ``system.inputs``, SI).")
    log = _held("log", "Event log (:class:`clutchlab.numerics.core.EventLog`) of the session.")
    fixed_step = _held("fixed_step", "Step [s] of the fixed-step mode (0.0: step-size control).")
    _opt = _held("opt", "Options of the core.")
    #: pack the session's objects for the compiled ``session`` entry (False: every call goes through numba's
    #: dispatcher with all its arguments -- the general path, kept for comparison)
    _pack = _held("pack", "Pack the session's objects (False: the general path).")

    def __init__(self, system: System, *, rtol=None, atol=None, max_step=None, max_steps: int = 100_000_000,
                 first_step=None, event_tol=None, t0: float = 0.0, fixed_step=None):
        core = _numerics_core()

        self.system = system
        self._core = core
        self._opt = system.options(rtol=rtol, atol=atol, max_step=max_step, max_steps=max_steps,
                                   first_step=first_step, event_tol=event_tol, fixed_step=fixed_step)
        self.fixed_step = self._opt.fixed_step
        self.x = system.x0.copy()
        self.m = system.m0.copy()
        self.u = system.u0.copy()
        self._sf, self._si = core.new_solver_state(float(t0))
        self.log = core.new_log(EVENT_CAPACITY)
        self._empty = np.empty(0)
        self._rt = np.empty(0)
        self._rx = np.empty((0, len(system.states)))
        self._rm = np.empty((0, len(system.mode_names)), dtype=np.int64)
        self._ry = np.empty((1, len(system.outputs)))
        self._y = np.empty(len(system.outputs))
        ny = len(system.outputs)
        self._report_spec = np.zeros((ny, 3), dtype=np.int64)  # (kind, index, value) per reported value
        self._report_spec[:, 1] = np.arange(ny)
        self._r = np.empty(ny)
        self._pack = True
        #: calls that go through numba's dispatcher before the session packs its objects: a session advanced once
        #: or twice (a settling run, a trim) neither packs nor compiles the model's ``session`` entry
        self._pack_after = 2
        self._dispatched = 0
        self._fast = None  # (callable, handle): the packed call, or (self._general, None); None: not decided
        #: the longest advance of the fixed-step mode (FIXED_STEP_BUDGET steps), None for step-size control
        self._fixed_span = FIXED_STEP_BUDGET * self.fixed_step if self.fixed_step > 0.0 else None

    # ---- the compiled calls
    def _call(self, t: float, what: int) -> int:
        """One call of the session: ``what & _ADVANCE`` advances to ``t``; ``what & _OUTPUTS`` then evaluates
        the outputs and the report (if the advance succeeded or ended at a terminal event).  Returns the
        advance's status."""
        fast = self._fast
        if fast is None:
            if not self._pack:
                fast = self._fast = (self._general, None)
            elif self._dispatched < self._pack_after:
                self._dispatched += 1
                return self._general(None, t, what)
            else:
                fast = self._fast = self._open()
        return fast[0](fast[1], t, what)

    def _method(self) -> str:
        return "rodas" if self.system.method == "rodas" or self.fixed_step > 0.0 else "dopri"

    def _open(self):
        """Pack the session's objects for the model's compiled ``session`` entry; ``(entry, handle)``.

        The model's ``advance`` and ``evaluate_outputs`` are compiled (or loaded from numba's cache) for
        these objects' types by their dispatchers, exactly as a dispatched call would, and the session
        entry calls those overloads through their addresses.  Falls back to the general path if an
        overload does not have the expected form.
        """
        from .numerics import session as S

        opened = S.open_session(*self._session_parts())
        return opened if opened is not None else (self._general, None)

    def session(self, log_capacity: int | None = None) -> tuple:
        """The packed arguments of this run's compiled session, for code that runs the model's compiled session
        itself (a native FMU, :mod:`clutchlab.fmu.native`, copies them into its image).

        Parameters
        ----------
        log_capacity : int, optional
            First replace the event log with an empty one of this many events.

        Returns
        -------
        (module, outputs_module, args, method) : tuple
            The model's compiled entry points for the run's integrator and for its outputs (Dormand-Prince's),
            the arguments (:data:`clutchlab.numerics.session.FIELDS`, in that order) and the integrator,
            ``"dopri"`` or ``"rodas"`` (Rosenbrock for a stiff model or a fixed step).
        """
        if log_capacity is not None:
            self.log = self._core.new_log(int(log_capacity))
        return (*self._session_parts(), self._method())

    def _session_parts(self):
        """``(module, outputs_module, args)`` of the packed session (:func:`clutchlab.numerics.session.open_session`;
        a native FMU copies the same arguments, :mod:`clutchlab.fmu.native`)."""
        params = self.system.params
        return (self._core.entry_points(type(params), self._method()), self._core.entry_points(type(params), "dopri"),
                (params, self.x, self.m, self.u, self._sf, self._si, self._opt, self.log, self._empty,
                 self._rt, self._rx, self._rm, self._ry, False, self._y, self._report_spec, self._r))

    def _dispatch(self, name: str, method: str, args):
        """The compiled entry ``name`` of the model's entry module for ``method``, called as numba's dispatcher would
        (:func:`clutchlab.numerics.entry.fast_entry`)."""
        return self._core.fast_entry(type(self.system.params), method, name)(*args)

    def _general(self, _handle, t: float, what: int) -> int:
        """:meth:`_call` through numba's dispatcher with all the arguments (no packed table)."""
        code = st.SUCCESS
        if what & _START:
            started = int(self._dispatch("start", "dopri", (self.system.params, self.time, self.x, self.u, self.m)))
            if started < 0:   # (an initial state the model cannot start from: as the session entry reports it)
                self._si[self._core.SI_MODEL_CODE] = started
                self._si[self._core.SI_STATUS] = st.MODEL_ERROR
                return st.MODEL_ERROR
        if what & _ADVANCE:
            code = int(self._dispatch("advance", self._method(), (
                self.system.params, self.x, self.m, self.u, t, self._sf, self._si, self._opt, self.log, self._empty,
                self._rt, self._rx, self._rm, self._ry, False)))
            if code != st.SUCCESS and code != st.TERMINATED:
                return code
        if what & _OUTPUTS:
            self._dispatch("evaluate_outputs", "dopri", (self.system.params, self.time, self.x, self.u, self.m,
                                                         self._y))
            for k, (kind, i, value) in enumerate(self._report_spec.tolist()):
                self._r[k] = (self._y[i] if kind == 0 else self.x[i] if kind == 1 else self.m[i] if kind == 2
                              else float(self.m[i] == value))
        return code

    @property
    def time(self) -> float:
        """Current time [s]."""
        return float(self._sf[0])

    @property
    def options(self):
        """The core's :class:`~clutchlab.numerics.core.Options` this session runs with (its tolerances as they
        follow ``rtol``, :func:`follow_rtol`; read-only: a named tuple)."""
        return self._opt

    def set_inputs(self, u) -> None:
        """Hold new input values (``u`` in the order of ``system.inputs``, SI)."""
        u = np.asarray(u, dtype=float).ravel()
        if u.shape != self.u.shape:
            raise ParameterError(f"{self.system.name}: {u.size} inputs given, {self.u.size} expected")
        self.u[:] = u

    def advance(self, t_end: float, u=None) -> int:
        """Integrate to ``t_end`` [s] holding the inputs ``u``; returns the status code (raises on failure)."""
        if u is not None:
            self.set_inputs(u)
        if self._fixed_span is not None and t_end - self._sf[0] > self._fixed_span:
            self._refuse_span(t_end)
        code = self._call(float(t_end), _ADVANCE)
        if code:  # (SUCCESS is 0)
            _check_status(self.system, code, self._si, self.time, True)
        return code

    def step(self, t_end: float) -> np.ndarray:
        """Integrate to ``t_end`` [s] with the held inputs and return the reported values there (:meth:`report`).

        One compiled call: :meth:`advance` and the outputs at the time reached, for a co-simulation step.
        The array returned is the session's own, rewritten by the next :meth:`step` or :meth:`outputs`
        (copy it to keep it); it is written only by a step that succeeded.

        Raises
        ------
        SimulationError
            As :meth:`advance`.
        """
        if self._fixed_span is not None and t_end - self._sf[0] > self._fixed_span:
            self._refuse_span(t_end)
        code = self._call(float(t_end), _ADVANCE | _OUTPUTS)
        if code:
            _check_status(self.system, code, self._si, self.time, True)
        return self._r

    def _refuse_span(self, t_end):
        span = float(t_end) - self.time
        raise SimulationError(f"{self.system.name}: fixed_step = {self.fixed_step:g} s: an advance of {span:g} s "
                              f"would take {span / self.fixed_step:.3g} steps (more than {FIXED_STEP_BUDGET:.0e} "
                              "in one call); choose a longer fixed step or advance in shorter intervals")

    def reported(self, start: bool = False) -> np.ndarray:
        """The reported values (:meth:`report`) at the current point, without advancing; the array of :meth:`step`.

        ``start``: first decide what the run derives from its initial state at the inputs now held (the model's
        ``start`` hook: a driveline's start modes; what a native FMU reports after its initialisation).  For a run
        that has not advanced yet (its first advance decides them again, from the same state)."""
        if start and int(self._si[self._core.SI_STARTED]) != 0:
            raise SimulationError(f"{self.system.name}: reported(start=True) after the run has started")
        code = self._call(self.time, _OUTPUTS | _START if start else _OUTPUTS)
        if code != st.SUCCESS:   # (start refused the initial state: the model's message)
            _check_status(self.system, code, self._si, self.time, True)
        return self._r

    def report(self, sources) -> None:
        """Choose the values :meth:`step` returns: outputs, states or modes of the system, in a given order.

        Parameters
        ----------
        sources : sequence of tuple
            ``("output", i)``, ``("state", i)``, ``("mode", i)`` (the mode's value as a float) or
            ``("mode_is", i, value)`` (1.0 if mode ``i`` equals ``value``, else 0.0); ``i`` an index or a
            name (``"clutch_torque"``, ``"slip_speed_rad_s"``, a mode name).  By default the outputs, in order.
        """
        spec = []
        for src in sources:
            kind, key = src[0], src[1]
            if kind not in _REPORT_KINDS or len(src) != (3 if kind == "mode_is" else 2):
                raise ParameterError(f"report: {src!r}: expected (kind, index) with kind one of 'output', 'state', "
                                     "'mode', or ('mode_is', index, value)")
            if kind == "output":
                n, find = len(self.system.outputs), self.system.output_index
            elif kind == "state":
                n, find = len(self.system.states), self.system.state_index
            else:
                names = tuple(self.system.mode_names)
                n, find = len(names), (lambda name: names.index(name) if name in names else -1)
            i = find(key) if isinstance(key, str) else key
            if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < n:
                raise ParameterError(f"report: {src!r}: no {kind} {key!r} (the system has {n})")
            spec.append((_REPORT_KINDS[kind], int(i), int(src[2]) if kind == "mode_is" else 0))
        self._report_spec = np.array(spec, dtype=np.int64).reshape(len(spec), 3)
        self._r = np.empty(len(spec))
        self._fast = None  # (packed again at the next call)

    def run_sampled(self, T, R, meas_kind, meas_idx, act, lo, hi, delay, kind, f, A, B, C, D, xc, sched, par, memory,
                    u_op, Y, U, S) -> int:
        """Run a sampled controller in the compiled loop from sample ``T[0]`` (the current time) to ``T[-1]``.

        The arguments are those of :func:`clutchlab.numerics.core.closed_loop` after the model's own (its
        parameters, state, modes, inputs, solver state and event log are this session's and carry on);
        :func:`clutchlab.control.closed_loop` prepares them.  Returns the number of samples done; raises
        :class:`~clutchlab.errors.SimulationError` on a failed step, as :meth:`advance`.
        """
        method = "rodas" if self.system.method == "rodas" or self.fixed_step > 0.0 else "dopri"
        code, done = self._core.closed_loop(method, self.system.params, self.x, self.m, self.u, self._sf, self._si,
                                            self._opt, self.log, self._y, T, R, meas_kind, meas_idx, act, lo, hi,
                                            int(delay), int(kind), f, A, B, C, D, xc, sched, par, memory, u_op, Y, U,
                                            S)
        if int(code) == -1:
            raise ParameterError(f"the controller returned another number of values than the {act.size} actuated "
                                 f"inputs (at t = {T[done]:.6g} s)")
        _check_status(self.system, int(code), self._si, self.time, True)
        return int(done)

    def outputs(self) -> np.ndarray:
        """Output vector at the current point (order of ``system.outputs``)."""
        self._call(0.0, _OUTPUTS)
        return self._y.copy()

    def events(self) -> pd.DataFrame:
        """Events recorded so far."""
        n = int(self.log.count[0])
        return self.system.events_frame(self.log.time[:n], self.log.code[:n], self.log.element[:n])

    @property
    def stats(self) -> dict:
        """Solver counters of the session so far (as ``SimulationResult.stats``)."""
        si = self._si
        return {"accepted_steps": int(si[self._core.SI_ACCEPTED]), "rejected_steps": int(si[self._core.SI_REJECTED]),
                "rhs_evaluations": int(si[self._core.SI_NRHS]), "jacobians": int(si[self._core.SI_NJAC]),
                "events_dropped": int(self.log.count[1]), "fixed_step": self.fixed_step}


@dataclasses.dataclass(frozen=True, eq=False)
class Variants:
    """Variants of one system for :func:`simulate_batch`, their parameters stacked along a first axis.

    Every array of the parameter structure gets a leading variant axis (``params.data[v]`` is variant
    ``v``'s ``data``), so a model can build thousands of variants with a few vectorised NumPy operations
    instead of one :class:`System` and one parameter structure each.  The compiled batch takes variant
    ``v``'s structure as views of these arrays (:func:`clutchlab.numerics.borrow.take`); memories a model
    keeps in its parameters (a lock-up time, a peak temperature) are therefore written into ``params``.

    Parameters
    ----------
    system : System
        The base system: names, units, method, tolerances and the structure of the parameters.
    params : NamedTuple
        Of the class of ``system.params``; each array field ``f`` an array of shape
        ``(n,) + system.params.f.shape`` and the same dtype, a number field an array of shape ``(n,)``
        (float64, int64 or bool), a tuple field the same tuple of such stacked members.
    x0, m0, u0 : ndarray
        Initial states ``(n, n_x)``, modes ``(n, n_m)`` and held inputs ``(n, n_u)``.
    """

    system: System
    params: tuple
    x0: np.ndarray
    m0: np.ndarray
    u0: np.ndarray

    def __post_init__(self):
        base = self.system
        if type(self.params) is not type(base.params):
            raise ParameterError(f"Variants of {base.name!r}: params must be a stacked {type(base.params).__name__}")
        n = None
        for name, ref, arr in zip(base.params._fields, base.params, self.params):
            layout = _field_layout(ref)
            if layout is None:
                raise ParameterError(f"Variants of {base.name!r}: parameter field {name!r} is neither a number, an "
                                     "array of at least one dimension nor a tuple of those")
            first = arr
            while isinstance(first, tuple) and len(first):
                first = first[0]
            if n is None:
                n = getattr(first, "shape", (0,))[0] if getattr(first, "ndim", 0) >= 1 else 0
            if not _stacked_matches(arr, layout, n):
                raise ParameterError(f"Variants of {base.name!r}: stacked field {name!r} is not {n} variants of "
                                     f"the base system's field (each array with a leading variant axis of "
                                     f"length {n}, C-contiguous, of the same dtype)")
        for field, arr, dtype, width in (("x0", self.x0, float, base.x0.size), ("m0", self.m0, np.int64,
                                                                                 base.m0.size),
                                         ("u0", self.u0, float, base.u0.size)):
            arr = np.ascontiguousarray(arr, dtype=dtype)
            if arr.shape != (n, width):
                raise ParameterError(f"Variants of {base.name!r}: {field} needs shape ({n}, {width}), "
                                     f"got {arr.shape}")
            object.__setattr__(self, field, arr)

    def __len__(self) -> int:
        return self.x0.shape[0]

    @classmethod
    def stack(cls, systems) -> "Variants":
        """Stack a sequence of :class:`System` variants of one model (same parameter sizes)."""
        systems = list(systems)
        if not systems:
            raise ParameterError("simulate_batch: no variants")
        first = systems[0]
        for i, s in enumerate(systems[1:], start=1):
            if type(s.params) is not type(first.params) or s.x0.shape != first.x0.shape:
                raise ParameterError("simulate_batch: all variants must be the same model with the same structure "
                                     f"(variant {i} differs from variant 0)")
        check_allocation(len(systems), _nbytes(first.params) / 8, f"the parameters of {len(systems)} variants of "
                         f"{first.name!r}, stacked")
        fields = []
        for k, name in enumerate(first.params._fields):
            layout = _field_layout(first.params[k])
            if layout is None:
                raise ParameterError(f"simulate_batch: parameter field {name!r} of {first.name!r} is neither a "
                                     "number, an array of at least one dimension nor a tuple of those")
            for i, s in enumerate(systems):
                if _field_layout(s.params[k]) != layout:
                    raise ParameterError(f"simulate_batch: variant {i} of {first.name!r}: parameter {name!r} has "
                                         "other sizes than in variant 0 (variants of a batch need equal sizes)")
            fields.append(_stack_field([s.params[k] for s in systems], layout))
        return cls(first, type(first.params)(*fields), np.stack([s.x0 for s in systems]),
                   np.stack([s.m0 for s in systems]), np.stack([s.u0 for s in systems]))

    def params_of(self, v: int):
        """Variant ``v``'s parameter structure (views of the stacked arrays; numbers for number fields)."""
        return _row(self.params, v)


def _nbytes(value) -> int:
    """Bytes of the arrays and numbers of a parameter structure."""
    if isinstance(value, np.ndarray):
        return value.nbytes
    if isinstance(value, tuple):
        return sum(_nbytes(v) for v in value)
    return 8


def _row(stacked, v):
    if isinstance(stacked, np.ndarray):
        return stacked[v] if stacked.ndim > 1 else stacked[v].item()
    members = [_row(s_, v) for s_ in stacked]
    return type(stacked)(*members) if hasattr(stacked, "_fields") else tuple(members)


def batch_groups(systems) -> list:
    """The indices of ``systems`` grouped by structure (model, state size and every parameter's sizes), each group
    what one :func:`simulate_batch` takes together, in the order their first members appear.  A sweep over a field
    that changes a model's structure (an E-clutch's table of shift levels present or not, a curve's number of
    points) runs one batch per group instead of refusing the variants."""
    groups: dict = {}
    for i, s in enumerate(systems):
        key = (type(s.params), s.x0.shape, s.m0.shape, s.u0.shape,
               tuple(_field_layout(s.params[k]) for k in range(len(s.params))))
        groups.setdefault(key, []).append(i)
    return list(groups.values())


def _field_layout(value):
    """Layout of a parameter field as :class:`Variants` stacks it, or None if it cannot be stacked.

    ``("array", shape, dtype)`` for an array of at least one dimension, ``("number", dtype)`` for a number,
    ``("tuple", class, (member layouts))`` for a tuple or NamedTuple of such fields.
    """
    if isinstance(value, np.ndarray):
        return ("array", value.shape, value.dtype) if value.ndim >= 1 else None
    if isinstance(value, (bool, np.bool_)):
        return ("number", np.dtype(np.bool_))
    if isinstance(value, (int, np.integer)):
        return ("number", np.dtype(np.int64))
    if isinstance(value, (float, np.floating)):
        return ("number", np.dtype(np.float64))
    if isinstance(value, tuple) and len(value):
        members = tuple(_field_layout(v) for v in value)
        return None if any(m is None for m in members) else ("tuple", type(value), members)
    return None


def _stack_field(values, layout):
    """The values of one field over the variants, stacked (arrays with a leading variant axis)."""
    if layout[0] == "tuple":
        members = [_stack_field([v[k] for v in values], sub) for k, sub in enumerate(layout[2])]
        return layout[1](*members) if hasattr(layout[1], "_fields") else tuple(members)
    return np.stack([np.asarray(v, dtype=layout[-1]) for v in values])


def _stacked_matches(stacked, layout, n) -> bool:
    """True if ``stacked`` is ``n`` variants of a field of ``layout``."""
    if layout[0] == "tuple":
        return (type(stacked) is layout[1] and len(stacked) == len(layout[2])
                and all(_stacked_matches(s, sub, n) for s, sub in zip(stacked, layout[2])))
    shape = layout[1] if layout[0] == "array" else ()
    return (isinstance(stacked, np.ndarray) and stacked.shape == (n,) + shape and stacked.dtype == layout[-1]
            and stacked.flags.c_contiguous)


def _write_back(dst, src, v) -> None:
    """Copy variant ``v`` of the stacked ``src`` into the arrays of one variant's field ``dst``."""
    if isinstance(dst, np.ndarray):
        if dst.flags.writeable:
            dst[...] = src[v]
    elif isinstance(dst, tuple):
        for d, s_ in zip(dst, src):
            _write_back(d, s_, v)


def simulate_batch(systems, t_end: float, *, sample_times=None, output_step: float | None = None,
                   rtol=None, atol=None, max_step=None, max_steps: int = 1_000_000, outputs: bool = True,
                   event_capacity: int = 256, check: bool = False, fixed_step: float | None = None,
                   chunk: int = 32) -> SimulationResult:
    """Simulate variants of one model in parallel: one solver per variant (``numba.prange``).

    Parameters
    ----------
    systems : Variants, sequence of System or iterator of System
        Variants of one model with equal parameter sizes: a :class:`Variants` (parameters already
        stacked; memories the model keeps in them are written there), or systems, stacked here (their
        parameter arrays get the memories back after the run).  An **iterator** (a generator that builds
        each variant) is drawn in chunks of up to ``chunk``: each chunk runs in a background thread on all
        cores but one while the next is being built, so building the variants (Python) and simulating them
        (compiled, without the interpreter lock) overlap; the chunks left when the last variant is built
        run together on all cores.
    t_end : float
        End time [s].
    sample_times, output_step
        Common sample times [s] (default: the end time only).
    rtol, atol, max_step, max_steps
        As :func:`simulate`, shared by all variants (defaults: the base system's).
    outputs : bool
        Evaluate the outputs at the samples.
    event_capacity : int
        Events kept per variant.
    check : bool
        Raise if any variant failed (otherwise see ``status``).
    fixed_step : float, optional
        Fixed-step mode with this step [s] for every variant, as :func:`simulate`.
    chunk : int
        Variants per chunk when ``systems`` is an iterator (at most: the first chunks are smaller; default 32).

    Returns
    -------
    SimulationResult
        Stacked: ``states[v, i, :]``; ``status`` one code per variant; events with a ``variant`` column.
    """
    core = _numerics_core()
    if isinstance(systems, Variants) or hasattr(systems, "__len__"):
        batch, given = (systems, None) if isinstance(systems, Variants) else (None, list(systems))
        batch = batch if batch is not None else Variants.stack(given)
        if len(batch) == 0:
            raise ParameterError("simulate_batch: no variants")
        first = batch.system
        ts, opt = _batch_setup(first, t_end, sample_times, output_step, rtol, atol, max_step, max_steps, fixed_step)
        records = _run_stacked(core, batch, given, ts, opt, t_end, outputs, event_capacity)
    else:
        if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
            raise ParameterError(f"simulate_batch: chunk = {chunk!r} must be a positive integer")
        first, ts, opt, records = _run_pipelined(core, iter(systems), int(chunk), t_end, sample_times, output_step,
                                                 rtol, atol, max_step, max_steps, fixed_step, outputs, event_capacity)
    OX, OM, OY, STATS, EVT, EVC, EVE, EVN = records
    nv, ns, ny = OX.shape[0], ts.size, len(first.outputs)
    status = STATS[:, core.SI_STATUS].copy()
    if check:
        bad = np.flatnonzero(~np.isin(status, [st.SUCCESS, st.TERMINATED]))
        if bad.size:
            raise SimulationError(f"{first.name}: variant {bad[0]}: {st.message(status[bad[0]])}")
    held = np.arange(EVT.shape[1])[None, :] < EVN[:, :1]  # the events each variant holds, in order
    variants = np.broadcast_to(np.arange(nv)[:, None], held.shape)[held]
    # one DataFrame for all variants, built when it is first read
    events = functools.partial(first.events_frame, EVT[held], EVC[held], EVE[held], variant=variants)
    if not outputs:
        OY = np.full((nv, ns, ny), np.nan)
    stats = {"accepted_steps": STATS[:, core.SI_ACCEPTED].copy(), "rejected_steps": STATS[:, core.SI_REJECTED].copy(),
             "rhs_evaluations": STATS[:, core.SI_NRHS].copy(), "jacobians": STATS[:, core.SI_NJAC].copy(),
             "events_dropped": EVN[:, 1].copy()}
    return SimulationResult(ts, OX, OY, OM, events, status, first.state_columns, first.output_columns,
                            tuple(first.mode_names), tuple(first.mode_values), stats, first.name)


#: variants the records of a batch drawn from an iterator first reserve (memory is mapped only where the
#: runs write; the records double when more come)
_PIPELINE_RESERVE = 1024


def _run_pipelined(core, it, chunk, t_end, sample_times, output_step, rtol, atol, max_step, max_steps, fixed_step,
                   outputs, event_capacity):
    """Build the variants (this thread, Python) while the ones built run (a second thread, compiled code that
    releases the interpreter lock).

    While variants are still being built, each chunk runs on one thread fewer than the caller's numba
    threads (one core builds, the others simulate: no core is shared, so no thread of a parallel loop waits
    for a descheduled one); once the last variant is built, all the chunks still waiting are stacked into
    one run on all the threads.  The chunks grow from 8 variants to ``chunk`` (the first starts early).
    Every run writes into views of one set of records that grows by doubling (no concatenation at the
    end).  Returns ``(first system, sample times, options, records)``.
    """
    import queue
    import threading

    import numba

    threads = numba.get_num_threads()
    todo: queue.Queue = queue.Queue()
    failed: list = []
    building = threading.Event()
    building.set()
    cancel = threading.Event()  # the building failed: the chunks still waiting are dropped
    setup: list = []
    rec: list = []  # the records [capacity rows], grown by the worker
    ended: list = []  # the worker has taken the end mark

    def records(first, need):
        if rec and rec[0].shape[0] >= need:
            return rec
        cap = max(need, 2 * rec[0].shape[0] if rec else max(_PIPELINE_RESERVE, 16 * chunk))
        try:
            new = _records(first, cap, setup[0].size, outputs, event_capacity, "")
        except ParameterError:  # the reserve does not fit in the budget: what is needed only
            new = _records(first, need, setup[0].size, outputs, event_capacity,
                           f"{need} variants x {setup[0].size} samples")
        if rec:
            for dst, src in zip(new, rec):
                dst[:src.shape[0]] = src
        rec[:] = new
        return rec

    def run(first, start, given, batch, nthreads):
        stop = start + len(given)
        out = tuple(a[start:stop] for a in records(first, stop))
        numba.set_num_threads(nthreads)
        _run_stacked(core, batch, given, *setup, t_end, outputs, event_capacity, out=out)

    def consume():
        try:
            while True:
                item = todo.get()
                if item is None:
                    ended.append(True)
                    return
                if cancel.is_set():
                    continue
                start, given, batch = item
                if not building.is_set():  # everything is built: the chunks still waiting run at once
                    pooled, last = list(given), False
                    while True:
                        nxt = todo.get()
                        if nxt is None:
                            last = True
                            ended.append(True)
                            break
                        pooled.extend(nxt[1])
                    if len(pooled) > len(given):
                        given, batch = pooled, Variants.stack(pooled)
                    run(batch.system, start, given, batch, threads)
                    if last:
                        return
                    continue
                run(batch.system, start, given, batch, max(1, threads - 1))
        except BaseException as exc:  # reported by the caller's thread
            failed.append(exc)
            while not ended and todo.get() is not None:  # let the producer finish
                pass

    worker = threading.Thread(target=consume, name="clutchlab-batch", daemon=True)
    first, n, size = None, 0, min(8, chunk)
    try:
        while not failed:
            given = []
            for s in it:
                given.append(s)
                if len(given) == size:
                    break
            if not given:
                break
            size = min(2 * size, chunk)
            batch = Variants.stack(given)
            if first is None:
                first = batch.system
                setup.extend(_batch_setup(first, t_end, sample_times, output_step, rtol, atol, max_step,
                                          max_steps, fixed_step))
                worker.start()
            elif (batch.system.state_columns, batch.system.output_columns, batch.system.mode_names) != (
                    first.state_columns, first.output_columns, first.mode_names):
                raise ParameterError(f"simulate_batch: variant {n} has other states, outputs or modes than "
                                     f"variant 0 ({first.name!r})")
            todo.put((n, given, batch))
            n += len(given)
    except BaseException:
        cancel.set()
        raise
    finally:
        building.clear()
        todo.put(None)
        if worker.is_alive():
            worker.join()
    if failed:
        raise failed[0]
    if first is None:
        raise ParameterError("simulate_batch: no variants")
    return first, setup[0], setup[1], tuple(a[:n] for a in rec)


def _batch_setup(first, t_end, sample_times, output_step, rtol, atol, max_step, max_steps, fixed_step):
    """Sample times and solver options of a batch, from its first variant."""
    ts = sample_grid(0.0, float(t_end), output_step, sample_times)
    if ts is None:
        ts = np.array([float(t_end)])
    opt = first.options(rtol=rtol, atol=atol, max_step=max_step, max_steps=max_steps, fixed_step=fixed_step)
    check_fixed_step_span(opt.fixed_step, 0.0, t_end, output_step)
    check_fixed_step_dynamics(first, opt.fixed_step)
    return ts, opt


def _records(first, nv, ns, outputs, event_capacity, what):
    """Empty records of ``nv`` variants x ``ns`` samples: (states, modes, outputs, counters, event times,
    codes, elements, counts); the compiled loop writes every entry of the variants it runs."""
    core = _numerics_core()
    nx, ny, nm = len(first.states), len(first.outputs), len(first.mode_names)
    check_allocation(nv * ns, nx + ny + nm, what)
    return (np.empty((nv, ns, nx)), np.empty((nv, ns, nm), dtype=np.int64),
            np.empty((nv, ns, ny) if outputs else (nv, 1, ny)), np.zeros((nv, core.N_SI), dtype=np.int64),
            np.zeros((nv, event_capacity)), np.zeros((nv, event_capacity), dtype=np.int64),
            np.zeros((nv, event_capacity), dtype=np.int64), np.zeros((nv, 2), dtype=np.int64))


def _run_stacked(core, batch, given, ts, opt, t_end, outputs, event_capacity, out=None):
    """Run one stacked batch on all cores (the compiled loop releases the interpreter lock); returns
    (states, modes, outputs, counters, event times, codes, elements, counts) -- ``out``, views of larger
    records, if given.  The memories each variant's model kept go back into its own parameter arrays
    (``given``: the systems stacked, or None)."""
    first = batch.system
    if out is None:
        out = _records(first, len(batch), ts.size, outputs, event_capacity,
                       f"{len(batch)} variants x {ts.size} samples")
    OX, OM, OY, STATS, EVT, EVC, EVE, EVN = out
    # (empty: the compiled loop writes every sample, NaN after the last one a variant reached, in parallel)
    core.batch("rodas" if opt.fixed_step > 0.0 else first.method, batch.params, batch.x0.copy(), batch.m0.copy(),
               batch.u0, float(t_end), ts, opt, OX, OM, OY, bool(outputs), STATS, EVT, EVC, EVE, EVN)
    if given is not None:  # the memories each variant's model kept, back into its own parameter arrays
        for v, s in enumerate(given):
            for dst, src in zip(s.params, batch.params):
                _write_back(dst, src, v)
    return out


def evaluate(system: System, t: float = 0.0, x=None, u=None, m=None):
    """Right-hand side, switching functions and outputs of a system at one point (through the contract).

    Returns ``(dx, g, y)`` [SI].  Defaults: the initial state, inputs and modes.
    """
    core = _numerics_core()

    x = system.x0.copy() if x is None else np.ascontiguousarray(x, dtype=float)
    u = system.u0.copy() if u is None else np.ascontiguousarray(u, dtype=float)
    m = system.m0.copy() if m is None else np.ascontiguousarray(m, dtype=np.int64)
    # the compiled hooks read the declared positions without bounds checks: a short array is refused here
    for field, a, want in (("x", x, system.x0.shape), ("u", u, system.u0.shape), ("m", m, system.m0.shape)):
        if a.shape != want:
            raise ParameterError(f"evaluate: {field} of system {system.name!r} has shape {a.shape}, its "
                                 f"declaration {want}")
    dx = np.empty(len(system.states))
    g = np.empty(len(system.switching))
    y = np.empty(len(system.outputs))
    core.evaluate(system.params, float(t), x, u, m, dx, g)
    core.evaluate_outputs(system.params, float(t), x, u, m, y)
    return dx, g, y


# ---------------------------------------------------------------- the model registry
#: model name -> factory ``f(**kwargs) -> System`` (registered once by each model package)
MODELS: dict = {}


def register_model(name: str, factory: Callable) -> None:
    """Register a model's :class:`System` factory under ``name`` (the one registry of models)."""
    MODELS[name] = factory
