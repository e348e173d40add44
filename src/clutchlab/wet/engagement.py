"""Engagement dynamics of a wet multi-plate clutch on a speed- or inertia-driven shaft.

The steady-state torque model of Shin, Kim and Choi [1] (Eqs. 1-8) is
extended to the transient engagement the way Deur et al. [4] do:

* the piston (force-controlled linear actuator of the bench, Fig. 4) moves
  against the return spring, the hydrodynamic squeeze-film force of the
  ``N_c`` interfaces in series (Reynolds equation for an annulus with the
  Patir-Cheng mean film h_bar, Eq. 2 [2]) and the Greenwood-Williamson
  asperity contact force [3].  The piston mass is neglected (quasi-static
  force balance), the actuator has a first-order force lag and a no-load
  speed limit (smooth ``tanh`` saturation); the piston rests on its stop
  while the force balance pushes it there;
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

The model is written once against the system contract, in
:mod:`clutchlab.wet.system` (parameters, compiled hooks, modes and events),
and integrated by the one integrator core (:mod:`clutchlab.numerics.core`,
Dormand-Prince 5(4) with events located on the dense output): lock-up,
break-away, slip reversal, contact, separation and the piston reaching and
leaving its stop are located events that switch the modes; the corners of
the reference profiles are stepped on exactly.  This module holds the
scenario and the public entry points: :func:`simulate` (returns a
:class:`clutchlab.SimulationResult`), and the thin wrappers
:func:`simulate_engagement` (:class:`EngagementResult`) and
:func:`simulate_batch` (:class:`BatchResult`, on
:func:`clutchlab.system.simulate_batch`: one solver per variant in
``numba.prange``).

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

import collections
import functools
import math
import threading
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .._limits import check_allocation, short_repr
from ..errors import ParameterError
from ..result import BuiltOnFirstAccess, SimulationResult
from ..system import check_rtol, checked_grid, sample_grid, simulate as run
from . import system as W
from .friction import ParametricFriction
from .params import Bench, WetClutch, temperature_problem

__all__ = [
    "Scenario",
    "Event",
    "EngagementResult",
    "BatchResult",
    "simulate",
    "simulate_engagement",
    "simulate_batch",
    "check_scenario",
    "STATE_NAMES",
    "OUTPUT_NAMES",
    "BATCH_VARIABLES",
    "EVENT_KINDS",
]

#: column names of :attr:`EngagementResult.states` (those of the system's states)
STATE_NAMES = tuple(f"{n}_{u}" for n, u, _ in W.STATES)
#: column names of :attr:`EngagementResult.outputs` (the system's, ``mu_f`` for ``friction_coefficient_1``)
OUTPUT_NAMES = tuple("mu_f" if n == "friction_coefficient" else f"{n}_{u}" for n, u, _ in W.OUTPUTS)
#: the event kinds of :attr:`EngagementResult.event_list`, by the system's event name
EVENT_KINDS = {"contact": "contact", "separation": "separation", "lockup": "lock-up", "breakaway": "break-away",
               "slip_reversal": "slip reversal"}
_MODE_NAMES = np.array(["slip", "stick", "slip"])

#: scenario/parameter names that :func:`simulate_batch` can vary per variant
BATCH_VARIABLES = ("force_scale", "mu_scale", "speed_scale", "initial_slip_speed", "initial_temperature_c",
                   "fluid_temperature_c", "total_inertia", "k1", "k2")


# ----------------------------------------------------------------- scenario
def _profile(name, t, v):
    t = np.array(t, dtype=float).ravel()  # copies: the scenario owns its profiles
    v = np.array(v, dtype=float).ravel()
    if t.size < 1 or t.size != v.size:
        raise ParameterError(f"Scenario.{name}: time and value need the same, non-zero length ({t.size} vs {v.size})")
    if t.size <= 16:  # short profiles (most): Python floats beat NumPy's reductions (measured 5 -> 2 us)
        tl = t.tolist()
        finite = all(map(math.isfinite, tl)) and all(map(math.isfinite, v.tolist()))
        increasing = all(a < b for a, b in zip(tl, tl[1:]))
    else:
        finite = np.isfinite(t).all() and np.isfinite(v).all()
        increasing = (t[1:] > t[:-1]).all()
    if not finite:
        raise ParameterError(f"Scenario.{name}: non-finite breakpoint")
    if not increasing:
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
        for arr in (ft, fv, st, sv):
            arr.setflags(write=False)  # a frozen scenario: its profiles cannot change under a cached model
        if fv.min() < 0:
            raise ParameterError(f"Scenario.force_value: negative force {short_repr(fv[fv < 0][0])} [N]")
        object.__setattr__(self, "force_time", ft)
        object.__setattr__(self, "force_value", fv)
        object.__setattr__(self, "speed_time", st)
        object.__setattr__(self, "speed_value", sv)
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise ParameterError(f"Scenario.duration = {self.duration!r}: must be > 0 [s]")
        if self.motor not in ("speed", "free"):
            raise ParameterError(f"Scenario.motor = {self.motor!r}: expected 'speed' or 'free'")
        if not math.isfinite(self.initial_slip_speed):
            raise ParameterError(f"Scenario.initial_slip_speed = {self.initial_slip_speed!r}: not finite")
        for name in ("initial_temperature_c", "fluid_temperature_c", "housing_temperature_c", "heater_setpoint_c"):
            problem = None if getattr(self, name) is None else temperature_problem(float(getattr(self, name)))
            if problem:
                raise ParameterError(f"Scenario.{name} = {getattr(self, name)!r}: {problem}")

    @property
    def setpoint_c(self) -> float:
        return self.fluid_temperature_c if self.heater_setpoint_c is None else float(self.heater_setpoint_c)


def check_scenario(bench: Bench, scenario: Scenario) -> None:
    """Refuse references outside the bench's limits (drive speed, actuator force).

    Parameters
    ----------
    bench : Bench
        The bench whose limits apply.
    scenario : Scenario
        The run's references.

    Raises
    ------
    ParameterError
        A slip-speed reference above the drive's speed limit (motor ``"speed"``)
        or a force reference above the actuator's.
    """
    if scenario.motor == "speed":
        top = float(np.abs(scenario.speed_value).max())
        if top > bench.drive_speed_max:
            raise ParameterError(
                f"Scenario.speed_value: {top:.6g} rad/s exceeds the bench's speed limit {bench.drive_speed_max:.6g} rad/s "
                f"(motor 6000 rpm through the 1:{bench.gear_ratio:g} gear)")
    if float(scenario.force_value.max()) > bench.actuator_force_max * (1 + 1e-12):
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


def _mode_names(result: SimulationResult) -> np.ndarray:
    return _MODE_NAMES[result.modes[:, W.M_FRICTION]] if result.modes.shape[0] else np.array([], dtype="<U5")


def _event_list(result: SimulationResult) -> list:
    ev = result.events
    events = [Event(float(t), EVENT_KINDS[name]) for t, name in zip(ev["time_s"], ev["event"]) if name in EVENT_KINDS]
    events.sort(key=lambda e: e.time)
    return events


@dataclass(repr=False)
class EngagementResult(SimulationResult):
    """Result of :func:`simulate_engagement`: the :class:`~clutchlab.SimulationResult` of the ``"wet"`` model with
    what the engagement adds.

    Every field of a :class:`~clutchlab.SimulationResult` is the core's run: ``states`` ``(n, 12)`` and ``outputs``
    ``(n, 18)`` with their unit-suffixed ``state_columns`` and ``output_columns`` (temperatures in degC, ``_C``),
    ``modes`` the mode codes per sample with ``mode_names`` and ``mode_values``, ``events`` the named events
    (``lockup``, ``breakaway``, ``piston_leaves_stop``, ...; ``time_s``, ``event``, ``element``), ``stats``.

    Attributes
    ----------
    heat_capacity : float
        Heat capacity of the pack used in Eq. 8 [J/K].
    peak_temperature_c : float
        Highest pack temperature [degC] over the accepted steps.
    lockup_time : float
        Time of the first lock-up [s] (NaN if the clutch did not lock).
    n_steps : int
        Accepted integration steps.
    final_state : numpy.ndarray
        State at ``duration``.
    slip_stick : numpy.ndarray of str
        ``"slip"`` or ``"stick"`` per sample.
    event_list : list of Event
        Contact, separation, lock-up, break-away, slip reversal in time order (the piston-stop events are in
        ``events``).
    state_names, output_names : tuple of str
        The columns of ``states`` and ``outputs`` (``mu_f`` for ``friction_coefficient_1``: :meth:`output`
        takes either).
    """

    heat_capacity: float = float("nan")
    peak_temperature_c: float = float("nan")
    lockup_time: float = float("nan")

    @classmethod
    def from_result(cls, result: SimulationResult, heat_capacity: float, peak_temperature_c: float,
                    lockup_time: float) -> "EngagementResult":
        """The engagement result of a :class:`~clutchlab.SimulationResult` of the ``"wet"`` model.

        Parameters
        ----------
        result : SimulationResult
            A single run of :func:`simulate`.
        heat_capacity : float
            Pack heat capacity [J/K].
        peak_temperature_c, lockup_time : float
            The run's peak pack temperature [degC] and first lock-up time [s].
        """
        return cls(**SimulationResult.fields_of(result), heat_capacity=float(heat_capacity),
                   peak_temperature_c=float(peak_temperature_c), lockup_time=float(lockup_time))

    @property
    def result(self) -> "EngagementResult":
        """The run itself (an :class:`EngagementResult` is a :class:`~clutchlab.SimulationResult`; kept for code
        that read the run from here)."""
        return self

    @property
    def n_steps(self) -> int:
        return int(self.stats["accepted_steps"])

    @property
    def final_state(self) -> np.ndarray:
        return np.array(self.stats["final_state"])

    state_names = STATE_NAMES
    output_names = OUTPUT_NAMES

    @property
    def slip_stick(self) -> np.ndarray:
        return _mode_names(self)

    @property
    def event_list(self) -> list:
        return _event_list(self)

    def state(self, name: str) -> np.ndarray:
        """One state trace by name."""
        return self.states[:, self.state_names.index(name)]

    def output(self, name: str) -> np.ndarray:
        """One output trace by name (``mu_f`` or ``friction_coefficient_1``)."""
        cols = self.output_names if name in self.output_names else self.output_columns
        return self.outputs[:, cols.index(name)]

    def energy_balance(self) -> dict:
        """Friction work against heat into the pack plus heat out, from the final state [J].

        ``W_f = C (T_end - T_0) + Q_fluid + Q_housing`` holds exactly for Eq. 8;
        ``residual`` is the relative integration error.
        """
        y = self.final_state
        wf = y[W.S_EF]
        stored = self.heat_capacity * (y[W.S_T] - self.states[0, W.S_T])
        out = y[W.S_EK1] + y[W.S_EK2]
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
    (accepted steps) and ``status`` (:class:`clutchlab.numerics.status.Status`
    codes: 0 success, 1 step limit, 2 step-size underflow).  ``result`` is the
    stacked :class:`~clutchlab.SimulationResult` of
    :func:`clutchlab.system.simulate_batch` (sampled at ``time`` and at the
    end time).
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
    result: SimulationResult | None = None

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


def _check_friction(friction):
    if friction is not None and not hasattr(friction, "kernel_data"):
        raise ParameterError(f"friction = {friction!r}: expected a ParametricFriction or a FrictionMap")


#: samples per second of :func:`simulate_engagement` without ``sample_times``, ``output_step`` or ``sample_rate``
SAMPLE_RATE = 1000.0


def _sample_times(duration, sample_rate, sample_times, output_step=None):
    """The sample times: as given (checked by :func:`clutchlab.system.sample_grid`), every ``output_step`` or at
    ``sample_rate`` (at most one of the three; default :data:`SAMPLE_RATE`)."""
    given = [n for n, v in (("sample_times", sample_times), ("output_step", output_step),
                            ("sample_rate", sample_rate)) if v is not None]
    if len(given) > 1:
        raise ParameterError(f"{' and '.join(given)}: give one of them (they all set the samples)")
    if sample_times is not None:
        return sample_times
    if output_step is not None:
        return sample_grid(0.0, float(duration), output_step)
    sample_rate = SAMPLE_RATE if sample_rate is None else sample_rate
    if not (sample_rate > 0):
        raise ParameterError(f"sample_rate = {sample_rate!r}: must be > 0 [Hz]")
    return _rate_grid(float(duration), float(sample_rate))


@functools.lru_cache(maxsize=16)
def _rate_grid(duration: float, sample_rate: float) -> np.ndarray:
    """``k / sample_rate`` up to ``duration``, built and checked once per pair (:func:`clutchlab.system.checked_grid`;
    building and checking it was a fifth of the Python around a 1 s engagement).  Never handed out: the runs
    read it, the results hold their own copy of the times."""
    # the record: states, auxiliaries and the noisy bench channels, each about N_STATE + N_OUT values a sample
    check_allocation(duration * sample_rate + 1, 2 * (W.N_STATE + W.N_OUT),
                     f"duration = {duration!r} s at sample_rate = {sample_rate!r} Hz")
    n = int(math.floor(duration * sample_rate + 1e-9)) + 1
    return checked_grid(np.arange(n) / sample_rate)


#: systems built recently, one entry per (clutch, bench, friction law, rtol) by identity: later runs skip the packing
_RECENT: "collections.OrderedDict" = collections.OrderedDict()
_RECENT_SIZE = 16
_RECENT_LOCK = threading.Lock()


class _Recent:
    """The system built for one clutch, bench and law (``base``) and the one of the last scenario run with them."""

    __slots__ = ("clutch", "bench_given", "friction", "bench", "base", "last")

    def __init__(self, clutch, bench_given, friction, bench, system, scenario):
        self.clutch, self.bench_given, self.friction, self.bench = clutch, bench_given, friction, bench
        self.base = system
        self.last = (scenario, system)  # replaced whole (one assignment: threads read a consistent pair)


def _run_system(clutch, scenario, bench, friction, rtol):
    """The system of one run with its own per-run buffers; the packing is reused for the same inputs.

    Clutch, bench, scenario and a parametric friction law are frozen, so a
    system built for the same objects is still right; a friction map is
    mutable, so a run with one always packs afresh.  A new scenario for a
    known clutch, bench and law takes the known system with this scenario's
    parameters and initial values (:func:`~clutchlab.wet.system.with_scenario`):
    names, tolerances and checks stay.  Measured: building the system again
    was a third of a short run's time (benchmarks/README.md, "fresh scenario").
    """
    if not (friction is None or isinstance(friction, ParametricFriction)) \
            or not isinstance(rtol, (int, float, np.floating)):
        return _system(clutch, scenario, bench, friction, rtol)  # (a bad rtol is refused there)
    key = (id(clutch), id(bench), id(friction), float(rtol))
    with _RECENT_LOCK:
        entry = _RECENT.get(key)
        if entry is not None and entry.clutch is clutch and entry.bench_given is bench and entry.friction is friction:
            _RECENT.move_to_end(key)
        else:
            entry = None
    if entry is None:
        system = _system(clutch, scenario, bench, friction, rtol)
        with _RECENT_LOCK:
            _RECENT[key] = _Recent(clutch, bench, friction, _default_bench() if bench is None else bench, system,
                                   scenario)
            while len(_RECENT) > _RECENT_SIZE:
                _RECENT.popitem(last=False)
        return system
    last_scenario, last = entry.last
    if last_scenario is scenario:  # the system's buffers were written by that run: fresh ones
        return last.variant(params=W.fresh_buffers(last.params, scenario.initial_temperature_c))
    check_scenario(entry.bench, scenario)
    x0 = W.initial_state(scenario)
    system = entry.base.variant(params=W.with_scenario(entry.base.params, scenario), x0=x0,
                                m0=W.initial_modes(x0, clutch.piston_h0))
    entry.last = (scenario, system)
    return system


def _system(clutch, scenario, bench, friction, rtol):
    bench = _default_bench() if bench is None else bench
    check_scenario(bench, scenario)
    _check_friction(friction)
    check_rtol(rtol)
    return W.engagement_system(scenario, clutch=clutch, bench=bench, friction=friction, rtol=rtol)


def simulate(scenario: Scenario, t_end: float | None = None, *, clutch: WetClutch | None = None,
             bench: Bench | None = None, friction=None, rtol: float = 1e-7, atol=None,
             max_step: float = math.inf, output_step: float | None = None,
             fixed_step: float | None = None) -> SimulationResult:
    """Simulate one wet-clutch run: the uniform entry point, returning a :class:`~clutchlab.SimulationResult`.

    Parameters
    ----------
    scenario : Scenario
        Force and slip references, drive mode, initial temperatures.
    t_end : float, optional
        End time [s] (default ``scenario.duration``).
    clutch : WetClutch, optional
        Clutch parameters (default :meth:`WetClutch.paper`, Table 1 of [1]).
    bench : Bench, optional
        Drive, actuator, sensors and oil loop (default ``Bench()``).
    friction : ParametricFriction or FrictionMap, optional
        Asperity friction law (default :meth:`ParametricFriction.bench_truth`).
    rtol : float
        Relative tolerance of the Dormand-Prince 5(4) step control.
    atol : float or array_like, optional
        Absolute tolerance per state in its unit (default: ``rtol`` times the
        states' typical magnitudes, :func:`clutchlab.wet.system.absolute_tolerance`).
    max_step : float
        Largest step [s] (the reference corners are break times, so no limit is needed).
    output_step : float, optional
        Sample interval [s]; without it every accepted step (and event) is kept.
    fixed_step : float, optional
        Fixed-step (real-time, HIL frame) mode with this step [s] (:func:`clutchlab.system.simulate`); None
        (default): step-size control.

    Returns
    -------
    SimulationResult
        States and outputs with unit-suffixed columns, modes ``friction``,
        ``piston``, ``film``, named events (``contact``, ``separation``,
        ``lockup``, ``breakaway``, ``slip_reversal``, ``piston_reaches_stop``,
        ``piston_leaves_stop``).

    Raises
    ------
    ParameterError
        References outside the bench's limits, bad tolerances.
    SimulationError
        Step limit reached or step-size underflow.
    """
    clutch = WetClutch.paper() if clutch is None else clutch
    t_end = scenario.duration if t_end is None else t_end
    return run(_run_system(clutch, scenario, bench, friction, rtol), t_end, atol=atol, max_step=max_step,
               output_step=output_step, fixed_step=fixed_step)


def simulate_engagement(clutch: WetClutch, scenario: Scenario, *, bench: Bench | None = None, friction=None,
                        sample_rate: float | None = None, sample_times=None, rtol: float = 1e-7, atol=None,
                        max_step: float = 0.01, output_step: float | None = None, max_steps: int = 2_000_000,
                        outputs: bool = True, fixed_step: float | None = None) -> EngagementResult:
    """Simulate one engagement (or any bench run) of the wet clutch.

    A thin wrapper of :func:`clutchlab.system.simulate` on
    :func:`clutchlab.wet.system.engagement_system`; ``result.result`` holds
    the :class:`~clutchlab.SimulationResult`.

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
    sample_rate : float, optional
        Output rate [Hz] (default :data:`SAMPLE_RATE`, 1 kHz, when neither ``sample_times`` nor
        ``output_step`` is given).
    sample_times : array_like, optional
        Explicit output times [s].
    rtol : float
        Relative tolerance of the DOPRI 5(4) step control; the absolute
        tolerances follow it (``rtol`` times the states' typical magnitudes,
        :func:`clutchlab.wet.system.absolute_tolerance`).
    atol : float or array_like, optional
        Absolute tolerance per state in its unit (default: those that follow ``rtol``).
    max_step : float
        Largest step [s].
    output_step : float, optional
        Sample interval [s] (the end time is always a sample); one of ``sample_rate``, ``sample_times`` and
        ``output_step``.
    max_steps : int
        Accepted-step limit (a :class:`SimulationError` beyond it).
    outputs : bool
        Evaluate the outputs (torques, forces, film, ...) at the samples; with
        ``False`` only the states are kept and ``outputs`` is all NaN.
    fixed_step : float, optional
        Fixed-step (real-time, HIL frame) mode with this step [s]: Rodas3
        steps on the grid ``k * fixed_step``, the events (piston stop,
        contact, lock-up, break-away) at the first step end after them
        (:func:`clutchlab.system.simulate`; ``rtol`` and ``max_step`` are then
        unused).  None (default): step-size control.

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
    sysm = _run_system(clutch, scenario, bench, friction, rtol)
    ts = _sample_times(scenario.duration, sample_rate, sample_times, output_step)
    res = run(sysm, float(scenario.duration), atol=atol, max_step=max_step, max_steps=max_steps, sample_times=ts,
              outputs=outputs, fixed_step=fixed_step)
    return EngagementResult.from_result(res, clutch.heat_capacity, W.peak_temperature(sysm.params),
                                        W.lockup_time(sysm.params))


def simulate_batch(clutch: WetClutch, scenario: Scenario, variants: dict, *, bench: Bench | None = None,
                   friction=None, sample_times=None, rtol: float = 1e-6, max_step: float = 0.01,
                   max_steps: int = 1_000_000) -> BatchResult:
    """Simulate many variants of one scenario in parallel (``numba.prange``, one solver each).

    Runs on :func:`clutchlab.system.simulate_batch`; each variant has its own
    packed parameters and initial state.

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
    from ..system import sample_grid, simulate_batch as run_batch

    base = _system(clutch, scenario, bench, friction, rtol)
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
    duration = float(scenario.duration)
    ts = np.array([duration]) if sample_times is None else sample_grid(0.0, duration, None, sample_times)
    # the end time is always sampled (final state of each variant), then dropped if not asked for
    grid = ts if ts.size and ts[-1] >= duration else np.append(ts, duration)
    batch = _variants(base, vals, m)
    res = run_batch(batch, duration, sample_times=grid, max_step=max_step, max_steps=max_steps, outputs=False)
    final = res.states[:, -1, :]
    work = batch.params.data[:, :W.N_WORK]  # each variant's memories
    status = np.asarray(res.status, dtype=int)
    return BatchResult(vals, ts, res.states[:, :ts.size, :], work[:, W.W_LOCKUP].copy(), final[:, W.S_EF],
                       work[:, W.W_PEAK].copy(), final[:, W.S_T], final[:, W.S_W],
                       np.asarray(res.stats["accepted_steps"], dtype=int), status, result=res)


#: batch variable -> WetParams field it overrides
_PARAM_FIELDS = {"force_scale": "force_scale", "mu_scale": "mu_scale", "speed_scale": "speed_scale",
                 "total_inertia": "total_inertia", "k1": "k1", "k2": "k2", "fluid_temperature_c": "heater_setpoint"}


def _variants(base, vals: dict, m: int):
    """The variants of a batch, stacked (:class:`~clutchlab.system.Variants`): constants, initial states, buffers."""
    from ..system import Variants

    x0 = np.tile(base.x0, (m, 1))
    for k, v in vals.items():
        if k == "initial_slip_speed":
            x0[:, W.S_W] = v
        elif k == "initial_temperature_c":
            x0[:, W.S_T] = v
            x0[:, W.S_TM] = v
        elif k == "fluid_temperature_c":
            x0[:, W.S_TF] = v
    if "force_scale" in vals:
        x0[:, W.S_FA] *= vals["force_scale"]  # the actuator starts at the scaled reference
    constants = np.repeat(base.params.constants, m)
    for k, v in vals.items():
        if k in _PARAM_FIELDS:
            constants[_PARAM_FIELDS[k]] = v
    work = W.new_work(x0[:, W.S_T])
    piston_h0 = float(constants["piston_h0"][0])
    m0 = W.initial_modes(x0, piston_h0)
    return Variants(base, W.stacked_parameters(base.params, constants, work), x0, m0, np.tile(base.u0, (m, 1)))


