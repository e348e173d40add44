"""Judder (clutch shudder): the torsional modes of a model in its active mode, the damping its sliding friction
elements add to them, and the oscillation a run or a measurement shows.

A clutch that slides with a friction coefficient falling with the slip speed acts on its driveline as a
negative damper.  Its torque ``tau = c_geo F_n mu(|w_rel|) sign(w_rel)`` (the driveline's friction law) changes
with the relative speed at the rate::

    d_f = d tau / d w_rel = c_geo F_n mu'(|w_rel|)      [N m s/rad]

so a falling ``mu`` (``mu' < 0``) feeds the torsional modes it takes part in, and a mode whose own damping it
outweighs grows until the clutch sticks and slips in turn (stick-slip judder).  The anti-shudder requirement on a
wet clutch's friction pairing, ``d mu / d v > 0`` over the slip speeds of an engagement, is that of Mäki et al.
(SAE 2005-01-0878, ref. of seed 001, whose introduction names shudder among the faults precise clutch control must
prevent); the seeds print no judder equation, so this is the linear stability reading of their friction laws
(docs/control.md, "Judder").

Closed form, the classic case: a disc of inertia ``J`` dragged by a clutch from a drive of constant speed and held
by a shaft ``k``, ``d`` to the ground obeys, while it slides, ``J phi'' + (d + d_f) phi' + k phi = tau_0``: the
mode ``lambda = -(d + d_f) / (2 J) +- i sqrt(k / J - ((d + d_f) / (2 J))^2)`` grows when ``d_f < -d``.

* :func:`judder_modes` -- the oscillating modes (frequency, damping ratio, growth rate, the state that moves most)
  and the sliding friction elements' ``d_f`` of any system of the contract at an operating point, a state it
  reaches in a run (``run_to``: frozen in its mode there) or its start: the matrices of :func:`clutchlab.control.
  linear.reduced_matrices`, also for a system without inputs;
* :func:`judder_timeline` -- the least damped mode and the friction elements' ``d_f`` along one run (a launch);
* :func:`friction_damping` -- the ``d_f`` of each sliding friction element at an operating point;
* :func:`oscillation` -- amplitude and frequency of the oscillation in a frequency band of a sampled column (a
  run's or a rig's), the time-domain measure of judder.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..driveline.shift import sample_interval
from ..errors import ParameterError
from ..system import Simulation, System
from ..trim import OperatingPoint, state_scale

__all__ = ["JudderModes", "judder_modes", "judder_timeline", "friction_damping", "oscillation", "Oscillation",
           "SLIDING"]

#: the mode values in which a friction element of a network slides (the driveline's friction state machine)
SLIDING = ("forward", "backward")

#: a pole is oscillating when its imaginary part exceeds this fraction of its magnitude, and a pole is zero when its
#: magnitude is below this fraction of the largest pole's: a free rotation's double pole at zero (a rigid body's
#: angle and speed) is split by the central differences' error ``delta ~ 4e-11`` of ``A`` into a pair of about
#: ``sqrt(delta) |A| ~ 6e-6 |A|`` (measured: 2e-5 Hz beside a 10 Hz mode), so the threshold keeps a margin of 16
OSCILLATING, ZERO = 1e-9, 1e-4


@dataclasses.dataclass(frozen=True)
class JudderModes:
    """The torsional (oscillating) modes of a system at an operating point, and its sliding friction elements.

    Attributes
    ----------
    operating_point : OperatingPoint
        Where: time, state, inputs and the active mode (kept fixed).
    table : pandas.DataFrame
        One row per oscillating mode (a pole pair, the one with positive imaginary part), by frequency:
        ``frequency_Hz`` (damped, ``Im(lambda) / 2 pi``), ``natural_frequency_Hz`` (``|lambda| / 2 pi``),
        ``damping_1`` (``-Re(lambda) / |lambda|``), ``growth_rate_1_s`` (``Re(lambda)``: the amplitude grows as
        ``exp(growth_rate t)``), ``state`` (the state that moves most in the mode, among the speeds where the
        system has any) and ``unstable`` (``growth_rate > 0``).
    friction : pandas.DataFrame
        :func:`friction_damping` at the point.
    poles : numpy.ndarray
        Every pole of the reduced linear model [1/s] (complex).
    """

    operating_point: OperatingPoint
    table: object
    friction: object
    poles: np.ndarray

    @property
    def unstable(self) -> bool:
        """True if an oscillating mode grows: judder."""
        return bool(len(self.table) and self.table["unstable"].any())

    def to_dict(self) -> dict:
        """Plain description (JSON): the time, the active mode, the modes and the friction elements."""
        op = self.operating_point
        return {"model": op.system.name, "time_s": float(op.t), "modes": op.modes, "unstable": self.unstable,
                "oscillating_modes": self.table.to_dict(orient="records"),
                "friction": self.friction.to_dict(orient="records")}

    def __str__(self) -> str:
        op = self.operating_point
        sliding = [f"{r.element} {r.mode} at {r.slip_rad_s:.4g} rad/s, d tau/d w_rel = {r.damping_Nms_rad:.4g} "
                   "N m s/rad" for r in self.friction.itertuples()]
        lines = [f"{op.system.name} at t = {op.t:g} s: {len(self.table)} oscillating mode"
                 f"{'' if len(self.table) == 1 else 's'}{'; JUDDER (a mode grows)' if self.unstable else ''}"]
        for r in self.table.itertuples():
            lines.append(f"  {r.frequency_Hz:10.4g} Hz  damping {r.damping_1:+.4f}  growth {r.growth_rate_1_s:+.4g} 1/s"
                         f"  {r.state}{'  UNSTABLE' if r.unstable else ''}")
        lines.extend(f"  friction: {text}" for text in sliding)
        return "\n".join(lines)


def _point(system, op, run_to, rtol) -> OperatingPoint:
    """The operating point asked for: ``op``, the state a run reaches at ``run_to``, or the start."""
    if isinstance(system, OperatingPoint):
        if op is not None or run_to is not None:
            raise ParameterError("judder_modes: an OperatingPoint is the point itself; give no op or run_to with it")
        return system
    if not isinstance(system, System):
        raise ParameterError(f"judder_modes: expected a System or an OperatingPoint, not {type(system).__name__} "
                             "(a Driveline's is driveline.system())")
    if op is not None and run_to is not None:
        raise ParameterError(f"{system.name}: give op or run_to, not both")
    if op is not None:
        return op
    if run_to is None:
        return OperatingPoint(system, 0.0, system.x0.copy(), system.u0.copy(), system.m0.copy())
    t = float(run_to)
    if not (math.isfinite(t) and t >= 0.0):
        raise ParameterError(f"{system.name}: run_to = {run_to!r} s must be a finite time >= 0")
    return _reached(Simulation(system, rtol=rtol), t)


def _reached(sim: Simulation, t: float) -> OperatingPoint:
    """The operating point a run reaches at ``t`` (advanced there if it is earlier): its state, inputs and modes."""
    if t > sim.time:
        sim.advance(t)   # (raises if the run fails)
    if abs(sim.time - t) > 1e-9 * max(1.0, t):
        raise ParameterError(f"{sim.system.name}: the run ended at {sim.time:g} s, before {t:g} s")
    return OperatingPoint(sim.system, t, sim.x.copy(), sim.u.copy(), sim.m.copy())


def friction_damping(op: OperatingPoint):
    """The damping ``d_f = d tau / d w_rel`` [N m s/rad] each sliding friction element adds between its flanges
    at ``op``: negative where its friction falls with the slip speed (it feeds the torsional modes: judder).

    An element is a mode variable of the system whose value at ``op`` is one of :data:`SLIDING` and whose outputs
    ``<name>.tau`` and ``<name>.w_rel`` the system declares (every friction element of a driveline network: clutches,
    brakes, E-clutches, wet clutches, EMTC couplings).  ``d_f`` is the ratio of the two outputs' derivatives along
    the state that moves ``w_rel`` most (central differences of the model's own outputs, :func:`clutchlab.control.
    linear.jacobians`): the slope of the element's friction law, read through the contract, with the normal force
    and temperatures held.

    Returns
    -------
    pandas.DataFrame
        ``element``, ``mode``, ``slip_rad_s`` (``w_rel``), ``tau_Nm`` and ``damping_Nms_rad``; no rows when
        nothing slides.
    """
    import pandas as pd

    from .linear import jacobians

    system = op.system
    outputs = {v.name: v for v in system.outputs}
    rows = []
    for k, name in enumerate(system.mode_names):
        values = system.mode_values[k] if k < len(system.mode_values) else ()
        mode = values[int(op.m[k])] if 0 <= int(op.m[k]) < len(values) else None
        if mode not in SLIDING or f"{name}.tau" not in outputs or f"{name}.w_rel" not in outputs:
            continue
        jac = jacobians(system, op, inputs=[], outputs=[f"{name}.tau", f"{name}.w_rel"])
        c_tau, c_w = jac["C"]
        j = int(np.argmax(np.abs(c_w)))
        if c_w[j] == 0.0:
            raise ParameterError(f"{system.name}: {name}'s relative speed moves with no state at t = {op.t:g} s")
        rows.append({"element": name, "mode": mode, "slip_rad_s": op.value(f"{name}.w_rel"),
                     "tau_Nm": op.value(f"{name}.tau"), "damping_Nms_rad": float(c_tau[j] / c_w[j]) + 0.0})   # (no -0)
    return pd.DataFrame(rows, columns=["element", "mode", "slip_rad_s", "tau_Nm", "damping_Nms_rad"])


def judder_modes(system, op: OperatingPoint | None = None, *, run_to: float | None = None,
                 rtol: float | None = None) -> JudderModes:
    """The oscillating modes of a system in its active mode, and what its sliding friction elements add to them.

    Parameters
    ----------
    system : System or OperatingPoint
        A system of the contract (a driveline's ``Driveline.system()``, any model), or an operating point
        (:func:`clutchlab.control.operating_point`, a trim).
    op : OperatingPoint, optional
        Where (default: the system's start, or ``run_to``).
    run_to : float, optional
        Run the system from its start to this time [s] and analyse the state, inputs and modes it reaches there,
        frozen (a launch's slipping clutch at 0.3 s: its modes as if the slip went on as it is at that instant).
    rtol : float, optional
        The run's relative tolerance (default the system's).

    Returns
    -------
    JudderModes
        The modes (frequency, damping ratio, growth rate), the friction elements' damping and every pole.

    Notes
    -----
    The matrices are :func:`clutchlab.control.linear.reduced_matrices` with no inputs and the system's outputs:
    the algebraic rows eliminated, the unread states (energy integrals) dropped; the modes stay fixed, so a
    sliding clutch is linearised sliding and a stuck one stuck (a stuck clutch joins its flanges: its modes are
    those of the joined driveline).  A point that is not a steady state (a run's instant) gives the frozen-time
    modes, the usual judder analysis of an engagement; they describe the growth over a few periods where the
    operating point moves slowly against them.
    """
    import pandas as pd

    from .linear import reduced_matrices

    point = _point(system, op, run_to, rtol)
    sys_ = point.system
    red = reduced_matrices(point, inputs=[])
    poles, vectors = np.linalg.eig(red.A) if red.A.size else (np.zeros(0, complex), np.zeros((0, 0), complex))
    speeds = [i for i, v in enumerate(red.states) if v.unit in ("rad_s", "m_s")]
    scale = state_scale(sys_, point.x)[[sys_.states.index(v) for v in red.states]] if red.states else np.zeros(0)
    rows = []
    largest = float(np.max(np.abs(poles))) if poles.size else 0.0
    for k, lam in enumerate(poles):
        mag = abs(lam)
        if not (lam.imag > OSCILLATING * mag and mag > ZERO * largest):
            continue
        v = np.abs(vectors[:, k])
        pick = speeds if speeds else list(range(len(red.states)))
        weights = v[pick] if speeds else v[pick] / scale[pick]
        rows.append({"frequency_Hz": float(lam.imag / (2 * math.pi)),
                     "natural_frequency_Hz": float(mag / (2 * math.pi)),
                     "damping_1": float(-lam.real / mag), "growth_rate_1_s": float(lam.real),
                     "state": red.states[pick[int(np.argmax(weights))]].column, "unstable": bool(lam.real > 0.0)})
    table = pd.DataFrame(rows, columns=["frequency_Hz", "natural_frequency_Hz", "damping_1", "growth_rate_1_s",
                                        "state", "unstable"])
    table = table.sort_values("frequency_Hz", ignore_index=True)
    return JudderModes(point, table, friction_damping(point), poles)


def judder_timeline(system: System, times, *, rtol: float | None = None):
    """The frozen-time judder analysis along one run: at each of ``times`` the least damped oscillating mode and the
    damping of every friction element that slides there (:func:`judder_modes` at the state the run reaches).

    Parameters
    ----------
    system : System
        A system of the contract, run once from its start (a launch).
    times : sequence of float
        Increasing times [s], each >= 0.
    rtol : float, optional
        The run's relative tolerance (default the system's).

    Returns
    -------
    pandas.DataFrame
        One row per time: ``time_s``, ``frequency_Hz``, ``damping_1``, ``growth_rate_1_s`` and ``state`` of the
        least damped oscillating mode (NaN and "" with none), ``unstable``, and ``<element>.damping_Nms_rad`` for
        each friction element that slides at some time (NaN where it does not: stuck, free).
    """
    import pandas as pd

    if not isinstance(system, System):
        raise ParameterError(f"judder_timeline: expected a System, not {type(system).__name__}")
    ts = np.asarray(times, dtype=float).ravel()
    if ts.size == 0 or not np.all(np.isfinite(ts)) or ts[0] < 0.0 or np.any(np.diff(ts) <= 0.0):
        raise ParameterError(f"{system.name}: judder_timeline needs increasing finite times >= 0 (got {times!r})")
    sim = Simulation(system, rtol=rtol)
    rows = []
    for t in ts:
        jm = judder_modes(_reached(sim, float(t)))
        row = {"time_s": float(t), "frequency_Hz": math.nan, "damping_1": math.nan, "growth_rate_1_s": math.nan,
               "state": "", "unstable": jm.unstable}
        if len(jm.table):
            least = jm.table.loc[jm.table.damping_1.idxmin()]
            row.update(frequency_Hz=float(least.frequency_Hz), damping_1=float(least.damping_1),
                       growth_rate_1_s=float(least.growth_rate_1_s), state=str(least.state))
        for f in jm.friction.itertuples():
            row[f"{f.element}.damping_Nms_rad"] = float(f.damping_Nms_rad)
        rows.append(row)
    return pd.DataFrame(rows)


@dataclasses.dataclass(frozen=True)
class Oscillation:
    """The oscillation of a sampled column in a frequency band (:func:`oscillation`).

    Attributes
    ----------
    column : str
        The column (its unit suffix is the unit of ``amplitude`` and ``rms``).
    amplitude : float
        The largest magnitude of the band-passed signal over the window [the column's unit]: half the peak-to-peak
        of a steady oscillation, the last peak of a growing one.
    rms : float
        Its root mean square over the window.
    frequency_Hz : float
        Its mean frequency: whole periods between the first and the last upward zero crossing (interpolated);
        nan with fewer than two crossings.
    band_Hz : tuple
        The band ``(low, high)`` [Hz].
    """

    column: str
    amplitude: float
    rms: float
    frequency_Hz: float
    band_Hz: tuple


def oscillation(frame, column: str, band_Hz, *, start: float | None = None, end: float | None = None) -> Oscillation:
    """The oscillation of one column of a sampled run or measurement in a frequency band: the time-domain measure
    of judder (a launch's vehicle or gearbox speed, a rig's torque).

    Parameters
    ----------
    frame : pandas.DataFrame or SimulationResult
        Samples with ``time_s`` at a constant interval (a run's ``output_step``, a rig's sample rate).
    column : str
        The column (``"vehicle.w_rad_s"``, ``"c.tau_Nm"``).
    band_Hz : (float, float)
        The band [Hz]: ``0 < low < high`` below the Nyquist frequency.  Judder lies between about 5 and 25 Hz in a
        car's driveline (its first torsional mode); a band keeps the launch's own acceleration and the engine's
        firing out.
    start, end : float, optional
        The window [s] (default: all samples).

    Returns
    -------
    Oscillation

    Notes
    -----
    The band-pass is a fourth-order Butterworth run forwards and backwards (``scipy.signal.sosfiltfilt``: no phase
    shift, eighth-order roll-off) over the whole column, then read over the window.  The column's ends have the
    filter's transients, so a window should keep a few periods of the band's low end from both ends of the column
    (from its last sample above all for a growing oscillation: the backward pass starts there, at its largest).
    """
    from scipy import signal

    if hasattr(frame, "to_dataframe"):
        frame = frame.to_dataframe()
    for name in ("time_s", column):
        if name not in frame.columns:
            raise ParameterError(f"oscillation: no column {name!r} (columns: {', '.join(map(str, frame.columns))})")
    t = frame["time_s"].to_numpy(dtype=float)
    y = frame[column].to_numpy(dtype=float)
    if t.size < 16 or not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        raise ParameterError(f"oscillation: {column} needs at least 16 finite samples (got {t.size})")
    h = sample_interval(t, f"oscillation: {column}")
    try:
        lo, hi = (float(b) for b in band_Hz)
    except (TypeError, ValueError):
        raise ParameterError(f"oscillation: band_Hz = {band_Hz!r}: expected (low, high) in Hz") from None
    nyquist = 0.5 / h
    if not 0.0 < lo < hi < nyquist:
        raise ParameterError(f"oscillation: band_Hz = ({lo:g}, {hi:g}) must satisfy 0 < low < high < the Nyquist "
                             f"frequency {nyquist:g} Hz of {column}'s samples")
    sos = signal.butter(4, (lo, hi), btype="bandpass", fs=1.0 / h, output="sos")
    z = signal.sosfiltfilt(sos, y - y.mean())
    t0 = t[0] if start is None else float(start)
    t1 = t[-1] if end is None else float(end)
    inside = (t >= t0 - 1e-12) & (t <= t1 + 1e-12)
    if inside.sum() < 2:
        raise ParameterError(f"oscillation: the window [{t0:g}, {t1:g}] s holds fewer than two samples of {column}")
    tw, zw = t[inside], z[inside]
    up = np.flatnonzero((zw[:-1] < 0.0) & (zw[1:] >= 0.0))
    crossings = tw[up] - zw[up] * (tw[up + 1] - tw[up]) / (zw[up + 1] - zw[up])
    freq = (crossings.size - 1) / (crossings[-1] - crossings[0]) if crossings.size >= 2 else math.nan
    return Oscillation(column, float(np.max(np.abs(zw))), float(np.sqrt(np.mean(zw ** 2))), float(freq), (lo, hi))
