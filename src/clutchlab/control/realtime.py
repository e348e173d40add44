"""Fixed-step (real-time) runs: the cost of a HIL frame and the error against the adaptive solution.

The integrator core's fixed-step mode (``simulate(system, t_end, fixed_step=h)``,
``Simulation(system, fixed_step=h)``; docs/architecture.md, "Fixed-step mode") takes steps of Rodas3
(linearly implicit, L-stable, order 3) of exactly ``h`` with the same work every step, as a
hardware-in-the-loop target runs a model.  This module measures what such a target needs to know:

* :func:`time_steps` -- the wall time of each frame of a co-simulation advanced one frame at a time
  (median, 99th percentile, worst);
* :func:`fixed_step_error` -- the error of fixed-step runs at several frames against a tight adaptive
  run of the same system (a work--precision table).

Models keep per-run memories in their parameter structure (the EMTC's controller and hysteresis
memories, lock-up times): every run here works on its own deep copy of ``system.params``, so the
system passed in is left as it was and every run starts from the same memories.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import time

import numpy as np
import pandas as pd

from ..errors import ParameterError
from ..system import Simulation, System, check_fixed_step, simulate

__all__ = ["StepTiming", "time_steps", "fixed_step_error", "DEFAULT_FRAMES"]

#: the frames of the issue's work--precision study [s]: 0.1 to 2 ms
DEFAULT_FRAMES = (1e-4, 2e-4, 5e-4, 1e-3, 2e-3)


def _fresh(system: System) -> System:
    """The system with its own copy of the parameters (memories a run writes stay in the copy)."""
    return system.variant(params=copy.deepcopy(system.params))


def _check_end(t_end, fixed_step):
    if not (isinstance(t_end, (int, float, np.floating)) and math.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"t_end = {t_end!r}: must be finite and > 0 [s]")
    if t_end < fixed_step:
        raise ParameterError(f"t_end = {t_end!r} s is shorter than one frame (fixed_step = {fixed_step!r} s)")


@dataclasses.dataclass(frozen=True)
class StepTiming:
    """Measured wall time per fixed step (one frame of a :class:`~clutchlab.system.Simulation`).

    Attributes
    ----------
    fixed_step : float
        The frame [s].
    step_times : ndarray
        Wall time of each frame's ``Simulation.advance`` [s] (compiled step plus the Python call around it).
    median, p99, worst : float
        Median, 99th percentile and largest of ``step_times`` [s].
    mean_in_run : float
        Wall time of one whole ``simulate(..., fixed_step=...)`` run without outputs, per step [s] (the
        compiled loop alone, without the per-frame Python call).
    rhs_per_step : float
        Right-hand-side evaluations per step of that run (the same every step; the run's first
        evaluation at its start is not counted).
    """

    fixed_step: float
    step_times: np.ndarray
    median: float
    p99: float
    worst: float
    mean_in_run: float
    rhs_per_step: float

    def real_time_factor(self) -> float:
        """Worst frame time over the frame: below 1 the model keeps up with real time on this machine."""
        return self.worst / self.fixed_step


def time_steps(system: System, t_end: float, fixed_step: float, *, inputs=None) -> StepTiming:
    """Time every frame of a fixed-step co-simulation of ``system`` from 0 to ``t_end``.

    A :class:`~clutchlab.system.Simulation` in fixed-step mode is advanced one frame at a time (as a
    HIL loop or an FMU master calls it) and each ``advance`` is timed with :func:`time.perf_counter_ns`.
    The model is compiled and warmed up by a run of a few frames first (not timed).

    Parameters
    ----------
    system : System
        The model (left unchanged: the runs use a copy of its parameters).
    t_end : float
        End of the timed run [s]; ``round(t_end / fixed_step)`` frames.
    fixed_step : float
        The frame [s].
    inputs : array_like, optional
        Held inputs in the order of ``system.inputs`` (default: ``system.u0``).

    Returns
    -------
    StepTiming
    """
    h = check_fixed_step(fixed_step)
    _check_end(t_end, h)
    n = max(1, int(round(t_end / h)))
    u = system.u0.copy() if inputs is None else np.ascontiguousarray(inputs, dtype=float).ravel()
    warm = Simulation(_fresh(system), fixed_step=h)
    for k in range(1, min(n, 5) + 1):
        warm.advance(k * h, u)
    sim = Simulation(_fresh(system), fixed_step=h)
    sim.set_inputs(u)
    times = np.empty(n, dtype=np.int64)
    clock = time.perf_counter_ns
    advance = sim.advance
    for k in range(n):
        t_next = (k + 1) * h
        a = clock()
        advance(t_next)
        times[k] = clock() - a
    run_system = _fresh(system)
    a = clock()
    res = simulate(run_system, n * h, fixed_step=h, outputs=False, sample_times=np.array([n * h]))
    whole = (clock() - a) * 1e-9
    steps = max(1, res.stats["accepted_steps"])
    secs = times * 1e-9
    return StepTiming(h, secs, float(np.median(secs)), float(np.percentile(secs, 99)), float(secs.max()),
                      whole / steps, (res.stats["rhs_evaluations"] - 1) / steps)


def fixed_step_error(system: System, t_end: float, frames=DEFAULT_FRAMES, *, states=None,
                     reference_rtol: float = 1e-10) -> pd.DataFrame:
    """Error of fixed-step runs against a tight adaptive run, one row per frame (a work--precision table).

    Each fixed-step run is compared with the reference at its own step ends (the grid ``k * frame`` up
    to ``t_end``; the reference is sampled there on its dense output).  The error of a state is the
    largest absolute difference over the run; the worst error is the largest over the chosen states of
    that error divided by the state's scale, its largest magnitude in the reference plus its absolute
    tolerance (``system.atol``): a relative error that treats every state alike.

    Parameters
    ----------
    system : System
        The model (left unchanged: every run uses a copy of its parameters).
    t_end : float
        End time [s].
    frames : sequence of float
        Fixed steps [s] (default 0.1, 0.2, 0.5, 1 and 2 ms).
    states : sequence of str, optional
        Names (or columns) of the states the worst error is taken over (default: all).
    reference_rtol : float
        Relative tolerance of the adaptive reference run (the system's absolute tolerances scaled by
        ``reference_rtol / system.rtol``, at most the system's).

    Returns
    -------
    DataFrame
        ``frame_s``, ``steps``, ``rhs_per_step``, ``error`` (the worst scaled error), and the largest
        absolute error of every state (its column name with unit, e.g. ``bearing_position_m``).
    """
    frames = [check_fixed_step(f) for f in frames]
    if not frames:
        raise ParameterError("frames: at least one fixed step is needed")
    _check_end(t_end, max(frames))
    idx = np.arange(len(system.states)) if states is None else np.array([system.state_index(s) for s in states])
    grids = [np.arange(1, int(math.floor(t_end / f + 1e-9)) + 1) * f for f in frames]
    union = np.unique(np.concatenate(grids + [np.array([0.0])]))
    union = union[union <= t_end * (1 + 1e-12)]
    ref = simulate(_fresh(system), t_end, rtol=reference_rtol, sample_times=union, outputs=False,
                   max_steps=50_000_000)
    scale = np.abs(ref.states).max(axis=0) + system.atol
    rows = []
    for f, grid in zip(frames, grids):
        run = simulate(_fresh(system), t_end, fixed_step=f, sample_times=grid, outputs=False,
                       max_steps=50_000_000)
        at = np.searchsorted(union, grid - 1e-12 * max(1.0, t_end))
        err = np.abs(run.states - ref.states[at]).max(axis=0)
        steps = run.stats["accepted_steps"]
        row = {"frame_s": f, "steps": steps, "rhs_per_step": (run.stats["rhs_evaluations"] - 1) / max(1, steps),
               "error": float((err[idx] / scale[idx]).max())}
        row.update({c: float(e) for c, e in zip(system.state_columns, err)})
        rows.append(row)
    return pd.DataFrame(rows)
