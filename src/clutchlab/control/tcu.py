"""A transmission controller (TCU) for an automated manual transmission: a gear command, carried out by a sequence.

An automated manual transmission (AMT) shifts as a driver of a manual gearbox does: it takes the engine's torque
down, opens the clutch, moves the sleeve of the gear it leaves to neutral, pushes the sleeve of the gear it selects
until its synchroniser has pulled the speeds together and its dogs are in, and closes the clutch while the torque
comes back (docs/control.md, "A transmission controller").  Which steps wait for the drive train is what an open-loop
schedule cannot do: the sleeve comes out when the off-going synchroniser is free, and the clutch closes when the
on-coming one is engaged, however long its cone takes.

:class:`AmtController` is that sequence as a sampled controller for :func:`~clutchlab.control.closed_loop`: it reads
the synchronisers' modes (``s1.mode``: 2 free, 0 engaged), sets the network inputs of the engine's torque, the
clutch's normal-force factor and the shift forks' forces, and logs its phases by name
(:attr:`AmtController.phases`).  It is written against the system contract (names of inputs and outputs), not
against a driveline's internals: any model with those inputs and outputs takes it, and an FMU host that carries
out the same sequence drives the FMU's inputs of the same names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..errors import ParameterError, SimulationError
from ._checks import positive

__all__ = ["AmtGear", "AmtController", "GearCommand", "PHASES", "SAMPLE_TIME", "SHIFT_OWN"]

#: the controller's phases, in the order of a shift (``drive`` between shifts)
PHASES = ("drive", "torque_down", "clutch_open", "neutral", "synchronise", "clutch_close")
#: the controller's sample time [s] where a driveline file's ``[tcu]`` table gives none
SAMPLE_TIME = 1e-3
#: what each shift of a run gives :func:`~clutchlab.control.shift_quality` itself (:meth:`AmtController.shift_quality`):
#: a file's ``[shift]`` table's values of these are left out for it
SHIFT_OWN = ("offgoing", "oncoming", "start")
#: a synchroniser's modes as its ``<name>.mode`` output gives them (MSL's values, 2 for free)
_ENGAGED, _FREE = 0.0, 2.0


@dataclass(frozen=True)
class AmtGear:
    """One gear of an AMT: the synchroniser that engages it, the network input of the fork that moves its
    sleeve, the sign of that fork's force that pushes towards it (``+1`` or ``-1``: a 1-2 sleeve's fork pushes
    towards 1st with one sign and towards 2nd with the other; the synchroniser's ``side``), and its ratio, the
    clutch's driven speed over the output speed in this gear (needed where the controller matches the engine's speed,
    :class:`AmtController`'s ``speed_match``)."""

    synchronizer: str
    fork: str
    side: int = 1
    ratio: float | None = None

    def __post_init__(self):
        if self.side not in (1, -1):
            raise ParameterError(f"gear of {self.synchronizer}: side = {self.side!r} must be 1 or -1")
        if self.ratio is not None:
            try:
                r = float(self.ratio)
            except (TypeError, ValueError):
                r = math.nan
            if not (math.isfinite(r) and r != 0.0):
                raise ParameterError(f"gear of {self.synchronizer}: ratio = {self.ratio!r} must be a finite number, "
                                     "not 0")
            object.__setattr__(self, "ratio", r)


def _demand_profile(torque, who):
    """``(torque, (times, values))``: the driver's demand as given (a float, or a tuple of ``(time, torque)`` rows)
    and as arrays to interpolate; a :class:`~clutchlab.errors.ParameterError` naming what is wrong."""
    bad = ParameterError(f"{who}: torque = {torque!r} must be a finite number [N m], or rows (time [s], "
                         "torque [N m]) of finite numbers with increasing times")
    if isinstance(torque, (int, float, np.number)) and not isinstance(torque, bool):
        value = float(torque)
        if not math.isfinite(value):
            raise bad
        return value, (np.zeros(1), np.array([value]))
    try:
        rows = np.array([(float(a), float(b)) for a, b in torque], dtype=float)
    except (TypeError, ValueError):
        raise bad from None
    if rows.ndim != 2 or rows.shape[0] < 1 or not np.all(np.isfinite(rows)) or np.any(np.diff(rows[:, 0]) <= 0.0):
        raise bad
    return tuple(map(tuple, rows.tolist())), (rows[:, 0].copy(), rows[:, 1].copy())


class GearCommand:
    """What a transmission controller of :mod:`clutchlab.control` shares (:class:`AmtController`,
    :class:`~clutchlab.control.dct.DctController`): its gear command, the log of its phases by name, its shifts and
    their quality, and the call of a function controller of :func:`~clutchlab.control.closed_loop`.  A subclass
    gives ``gears`` (``{number: gear}``), ``start_gear``, :attr:`measured`, :attr:`actuated`, ``_read`` (the
    measured values of a sample), ``_advance`` (the phase changes at a sample), ``_outputs`` (the inputs it sets)
    and ``_element`` (a gear's shifting element, named in :attr:`shifts`)."""

    #: the phases of its shifts, ``drive`` first (between shifts)
    PHASES: tuple = ("drive",)

    def _set_gears(self, gears, start_gear, commands, kind, least: int = 1) -> None:
        """Keep ``gears`` (``{number: kind}``, at least ``least`` of them), ``start_gear`` and the gear command,
        checked."""
        who = type(self).__name__
        if not isinstance(gears, dict) or len(gears) < least or not all(isinstance(g, kind) for g in gears.values()):
            fields = ", ".join(kind.__dataclass_fields__)
            raise ParameterError(f"{who}: gears must be {{gear number: {kind.__name__}({fields})}}"
                                 + (f", at least {least}" if least > 1 else ""))
        self.gears = dict(gears)
        if start_gear not in self.gears:
            raise ParameterError(f"{who}: start_gear = {start_gear!r} is not among the gears {sorted(self.gears)}")
        self.start_gear = start_gear
        self.commands = self._commands(commands)

    def _commands(self, commands) -> tuple:
        """The gear command as ``((time [s], gear), ...)`` in time order, checked against the gears."""
        who = type(self).__name__
        cmds = []
        for entry in commands:
            try:
                t, g = entry
            except (TypeError, ValueError):
                raise ParameterError(f"{who}: a command {entry!r} must be (time [s], gear)") from None
            if g not in self.gears:
                raise ParameterError(f"{who}: the command at {t!r} s selects gear {g!r}, not among the gears "
                                     f"{sorted(self.gears)}")
            try:
                t = float(t)
            except (TypeError, ValueError):
                t = math.nan
            if not math.isfinite(t):
                raise ParameterError(f"{who}: the command {entry!r}: its time must be a finite number [s]")
            cmds.append((t, g))
        return tuple(sorted(cmds, key=lambda c: c[0]))

    def _reset(self):
        self._gear, self._target = self.start_gear, None
        self._phase, self._since = "drive", 0.0
        self._next = 0       # the next command to take
        self._last = -math.inf
        self._log = [(0.0, "drive", self.start_gear)]

    def _enter(self, phase, t):
        self._phase, self._since = phase, t
        self._log.append((t, phase, self._target if self._target is not None else self._gear))

    def _command(self, t):
        """The gear of the next command due at ``t`` that selects another gear (those that select the gear engaged
        are taken and dropped), or None."""
        while self._next < len(self.commands) and self.commands[self._next][0] <= t:
            _, g = self.commands[self._next]
            self._next += 1
            if g != self._gear:
                return g
        return None

    @property
    def phases(self) -> pd.DataFrame:
        """The phases entered in the last run: ``time_s``, ``phase`` (:attr:`PHASES`) and ``gear`` (the gear
        selected: the one a shift goes to, from its first phase on)."""
        t, p, g = zip(*self._log)
        return pd.DataFrame({"time_s": np.array(t, dtype=float), "phase": list(p), "gear": list(g)})

    @property
    def shifts(self) -> pd.DataFrame:
        """The shifts of the last run, one row each: ``start_s`` (its command: its first phase), ``end_s`` (back in
        ``drive``; NaN where the run ended first), ``from_gear``, ``to_gear``, and the ``offgoing`` and
        ``oncoming`` elements (an AMT's synchronisers, a dual-clutch transmission's clutches)."""
        rows, current, before = [], None, "drive"
        for t, phase, gear in self._log:
            if phase != "drive" and before == "drive":
                current = [t, math.nan, rows[-1][3] if rows else self.start_gear, gear]
                rows.append(current)
            elif phase == "drive" and current is not None:
                current[1] = t
            before = phase
        return pd.DataFrame({"start_s": [r[0] for r in rows], "end_s": [r[1] for r in rows],
                             "from_gear": [r[2] for r in rows], "to_gear": [r[3] for r in rows],
                             "offgoing": [self._element(r[2]) for r in rows],
                             "oncoming": [self._element(r[3]) for r in rows]})

    def _quality_options(self, options) -> None:
        """Refuse what each shift gives :func:`~clutchlab.control.shift_quality` itself (:data:`SHIFT_OWN`)."""
        own = [k for k in SHIFT_OWN if k in options]
        if own:
            raise ParameterError(f"{type(self).__name__}.shift_quality: {', '.join(own)} come from each shift; leave "
                                 "them out")

    def shift_quality(self, frame, **options) -> list:
        """The quality of each shift of the last run that ended (:func:`clutchlab.control.shift_quality`):
        ``frame`` the loop's record (:attr:`~clutchlab.control.ClosedLoopResult.frame` with the columns the metrics
        read: the shifting elements' ``tau`` and ``w_rel``, the output's and the engine's speeds), ``options`` the
        function's (``output``, ``engine``, ``radius``, ``threshold``, ``settle``, ...; a driveline file's
        ``[shift]`` table).  Each shift is read on the record from the end of the one before (the start) to the
        start of the next (the end), with its own elements and its command as its start.  Returns a list of
        :class:`~clutchlab.control.ShiftQuality`, one per shift in :attr:`shifts` that ended."""
        from ..driveline.shift import shift_quality

        self._quality_options(options)
        shifts = self.shifts
        t = np.asarray(frame["time_s"], dtype=float)
        out = []
        for k, row in shifts.iterrows():
            if math.isnan(row.end_s):
                continue
            lo = shifts.end_s.iloc[k - 1] if k else -math.inf
            hi = shifts.start_s.iloc[k + 1] if k + 1 < len(shifts) else math.inf
            out.append(shift_quality(frame[(t >= lo) & (t < hi)], offgoing=row.offgoing, oncoming=row.oncoming,
                                     start=row.start_s, **options))
        return out

    def __call__(self, t: float, y, memory=None):
        """The inputs :attr:`actuated` at sample time ``t`` [s] from the measured values ``y`` (:attr:`measured`
        first)."""
        if t < self._last:
            self._reset()
        self._last = t
        y = np.asarray(y, dtype=float)
        if y.size < len(self.measured):
            raise ParameterError(f"{type(self).__name__}: it measures {len(self.measured)} signals first "
                                 f"({', '.join(self.measured)}); got {y.size}")
        seen = self._read(t, y)
        while True:   # (a phase whose condition holds at once hands over within the sample)
            before = self._phase
            self._advance(t, seen)
            if self._phase == before:
                break
        return self._outputs(t)

    def _ramp(self, t, duration):
        return min(max((t - self._since) / duration, 0.0), 1.0)

    def _set_demand(self, torque):
        """:attr:`torque` as given (a number, or rows ``(time [s], torque [N m])`` as a tuple) and the arrays
        :meth:`demand` interpolates."""
        self.torque, self._demand = _demand_profile(torque, type(self).__name__)

    def demand(self, t: float) -> float:
        """The driver's demand [N m] at ``t`` [s]: ``torque``, linear between its rows and held beyond them."""
        times, values = self._demand
        return float(np.interp(t, times, values))


class AmtController(GearCommand):
    """The shift sequence of an AMT's controller, as a function controller ``f(t, y, memory) -> u`` of
    :func:`~clutchlab.control.closed_loop`.

    Parameters
    ----------
    gears : dict
        ``{gear number: AmtGear(synchronizer, fork, side)}``: the gears it selects.
    start_gear : int
        The gear engaged at the start (its synchroniser stuck, its fork pushing).
    commands : sequence of (float, int)
        The gear command: ``(time [s], gear)`` pairs.  A command comes into effect at the first sample at or
        after its time once the shift before it has ended (a driver's lever, a shift map's output); a command of
        the gear engaged is no shift.
    clutch_input, torque_input : str
        The network inputs of the clutch's normal-force factor (1 closed, 0 open) and of the engine's torque [N m].
    torque : float or sequence of (float, float)
        The engine's torque while in gear [N m] (the driver's demand): a number, or rows ``(time [s], torque [N m])``
        with increasing times, linear between them and held beyond (:meth:`demand`).
    drag : float
        The engine's torque while the clutch is open [N m] (a fuel cut's drag, <= 0: the engine slows towards the
        new gear's speed).
    fork_force : float
        The fork's force on an engaged sleeve and while synchronising [N] (> 0).
    torque_down, clutch_open, fork_ramp, clutch_close : float
        Durations [s] (> 0) of the ramps: the torque to 0, the clutch's factor to 0 (while the torque goes to the
        drag), each fork force to 0 or to its push, the clutch's factor back to 1 (while the torque comes back).
    sync_timeout : float
        The longest a synchronisation may take [s]: beyond it the run stops with a
        :class:`~clutchlab.errors.SimulationError` naming the synchroniser (a fork too weak for its cone, a
        gear that cannot be reached).
    speed_match : float
        The gain [N m s/rad] (>= 0; 0, the default: off) of the engine's speed matching while the clutch is open
        (``neutral`` and ``synchronise``): the engine's torque ``T = clip(speed_match * (ratio * w_out - w_e),
        drag, torque_max)`` pulls the engine's speed ``w_e`` to the speed the clutch's driven side will turn at in
        the selected gear (its :attr:`AmtGear.ratio` times the output speed ``w_out``), so that the clutch closes
        with little slip: on a downshift the throttle blip, on an upshift the drag held only until the engine
        has come down to the new gear's speed.  While the clutch closes the torque is blended from the matching's to
        ``torque`` (``(1 - s) T_match + s torque`` as the clutch's factor ``s`` rises from 0 to 1).  With the sample
        time ``h`` and the engine's inertia ``J_e`` the sampled loop shrinks a speed error by ``1 - speed_match h /
        J_e`` a sample: stable below 2, without overshoot below 1.
    engine_speed, output_speed : str, optional
        The outputs it reads for the speed matching (needed with ``speed_match``): the engine's speed [rad/s]
        (e.g. ``"engine.w"``) and the output speed the gears' ratios refer to (e.g. ``"output_shaft.w"``).
    torque_max : float, optional
        The most torque the speed matching commands [N m] (the engine's full-load torque at those speeds;
        default the largest demand, or 0).

    The controller measures its synchronisers' modes and, matching speeds, the engine's and the output speed,
    :attr:`measured` (the first entries of ``measure``; more may follow, for the record), and actuates
    :attr:`actuated`.  Each phase change is logged by name with its time and gear, :attr:`phases`; the phases of a
    shift are :data:`PHASES`.  A new run (a sample at ``t`` below the last one) starts it again from ``start_gear``.
    """

    PHASES = PHASES

    def __init__(self, gears: dict, start_gear: int, commands, *, clutch_input: str, torque_input: str,
                 torque: float, drag: float = 0.0, fork_force: float = 600.0, torque_down: float = 0.3,
                 clutch_open: float = 0.07, fork_ramp: float = 0.03, clutch_close: float = 0.4,
                 sync_timeout: float = 0.5, speed_match: float = 0.0, engine_speed: str | None = None,
                 output_speed: str | None = None, torque_max: float | None = None):
        self._set_gears(gears, start_gear, commands, AmtGear)
        self.clutch_input, self.torque_input = str(clutch_input), str(torque_input)
        self._set_demand(torque)
        self.drag = float(drag)
        if not (math.isfinite(self.drag) and self.drag <= 0.0):
            raise ParameterError(f"AmtController: drag = {drag!r} must be finite and <= 0 (the engine's drag while "
                                 "the clutch is open)")
        self.fork_force = positive("fork_force", fork_force)
        self.torque_down = positive("torque_down", torque_down)
        self.clutch_open = positive("clutch_open", clutch_open)
        self.fork_ramp = positive("fork_ramp", fork_ramp)
        self.clutch_close = positive("clutch_close", clutch_close)
        self.sync_timeout = positive("sync_timeout", sync_timeout)
        self.speed_match = positive("speed_match", speed_match, zero=True)
        self.torque_max = (max(float(self._demand[1].max()), 0.0) if torque_max is None else
                           positive("torque_max", torque_max, zero=True))
        self.engine_speed, self.output_speed = engine_speed, output_speed
        if self.speed_match:
            for what, v in (("engine_speed", engine_speed), ("output_speed", output_speed)):
                if not isinstance(v, str) or not v:
                    raise ParameterError(f"AmtController: speed_match = {speed_match!r} needs {what}, the name of an "
                                         f"output (got {v!r})")
            unknown = sorted(g for g, spec in self.gears.items() if spec.ratio is None)
            if unknown:
                raise ParameterError(f"AmtController: speed_match needs every gear's ratio; gear(s) {unknown} have "
                                     "none (AmtGear(..., ratio=...))")
        synchros = [g.synchronizer for g in self.gears.values()]
        if len(set(synchros)) != len(synchros):
            raise ParameterError(f"AmtController: two gears share a synchroniser ({synchros})")
        #: the outputs it reads, in this order: each gear's synchroniser's mode (then, matching speeds, the engine's
        #: speed and the output speed)
        self.measured = tuple(f"{s}.mode" for s in synchros) + (
            (engine_speed, output_speed) if self.speed_match else ())
        forks = list(dict.fromkeys(g.fork for g in self.gears.values()))
        #: the inputs it sets, in this order: the engine's torque, the clutch's factor, each fork's force
        self.actuated = (self.torque_input, self.clutch_input, *forks)
        self._fork_at = {f: 2 + k for k, f in enumerate(forks)}
        self._mode_at = {g: k for k, g in enumerate(self.gears)}
        self._reset()

    @classmethod
    def from_table(cls, table: dict) -> "AmtController":
        """The controller of a driveline file's ``[tcu]`` table as its loader reads it
        (:attr:`clutchlab.driveline.description.DrivelineFile.tcu`: SI, gears as ``{number: (synchronizer, fork,
        side, ratio)}``, the ratio None where the file gives none; its ``sample_time`` is the loop's, not the
        controller's)."""
        kw = {k: v for k, v in table.items() if k not in ("sample_time", "type")}
        kw["gears"] = {g: AmtGear(*spec) for g, spec in kw["gears"].items()}
        return cls(**kw)

    def _reset(self):
        super()._reset()
        self._speeds = (0.0, 0.0)   # the engine's and the output speed at the last sample [rad/s] (speed matching)

    def _element(self, gear):
        return self.gears[gear].synchronizer

    def shift_quality(self, frame, **options) -> list:
        """The quality of each shift of the last run that ended (:func:`clutchlab.control.shift_quality`, an
        interrupted shift): ``frame`` the loop's record (:attr:`~clutchlab.control.ClosedLoopResult.frame` with the
        columns the metrics read: the clutch's and the two synchronisers' ``tau`` and ``w_rel``, the output's and
        the engine's speeds), ``options`` the function's (``clutch``, ``output``, ``engine``, ``radius``,
        ``threshold``, ``settle``, ...; a driveline file's ``[shift]`` table).  Each shift is read on the record
        from the end of the one before (the start) to the start of the next (the end), with its own synchronisers
        and its command as its start.  Returns a list of :class:`~clutchlab.control.ShiftQuality`, one per shift
        in :attr:`shifts` that ended."""
        self._quality_options(options)
        if "clutch" not in options:
            raise ParameterError("AmtController.shift_quality: give clutch, the main clutch's element (its torque "
                                 "and slip columns)")
        return super().shift_quality(frame, **options)

    def _read(self, t, y):
        """The synchronisers' modes by gear (and, matching speeds, the speeds kept)."""
        if self.speed_match:
            n = len(self._mode_at)
            self._speeds = (float(y[n]), float(y[n + 1]))
            if not all(math.isfinite(w) for w in self._speeds):
                raise SimulationError(f"AmtController: the measured speeds {self.engine_speed} = {self._speeds[0]!r}, "
                                      f"{self.output_speed} = {self._speeds[1]!r} at {t:.6g} s")
        return {g: y[k] for g, k in self._mode_at.items()}

    def _match(self):
        """The engine's torque while the clutch is open [N m]: ``drag``, or with ``speed_match`` the torque that
        pulls the engine to the selected gear's speed, within ``[drag, torque_max]``."""
        if not self.speed_match:
            return self.drag
        w_e, w_out = self._speeds
        gap = self.gears[self._target].ratio * w_out - w_e
        return min(max(self.speed_match * gap, self.drag), self.torque_max)

    def _advance(self, t, mode):
        phase = self._phase
        if phase == "drive":
            g = self._command(t)
            if g is not None:
                self._target = g
                self._enter("torque_down", t)
        elif phase == "torque_down" and self._ramp(t, self.torque_down) >= 1.0:
            self._enter("clutch_open", t)
        elif phase == "clutch_open" and self._ramp(t, self.clutch_open) >= 1.0:
            self._enter("neutral", t)
        elif phase == "neutral" and self._ramp(t, self.fork_ramp) >= 1.0 and mode[self._gear] == _FREE:
            self._enter("synchronise", t)
        elif phase == "synchronise":
            if mode[self._target] == _ENGAGED:
                self._enter("clutch_close", t)
            elif t - self._since > self.sync_timeout:
                g = self.gears[self._target]
                raise SimulationError(f"AmtController: {g.synchronizer} has not engaged gear {self._target} within "
                                      f"sync_timeout = {self.sync_timeout:g} s of the push at {self._since:.6g} s "
                                      f"(at {t:.6g} s: mode {mode[self._target]:g}); a stronger fork_force or a "
                                      "longer sync_timeout")
        elif phase == "clutch_close" and self._ramp(t, self.clutch_close) >= 1.0:
            self._gear, self._target = self._target, None
            self._enter("drive", t)

    def _outputs(self, t):
        u = np.zeros(len(self.actuated))
        phase = self._phase
        demand = self.demand(t)
        torque, clutch = demand, 1.0
        held = self._gear          # the gear whose fork pushes (the one engaged, until neutral)
        push = 1.0
        if phase == "torque_down":
            torque = demand * (1.0 - self._ramp(t, self.torque_down))
        elif phase == "clutch_open":
            s = self._ramp(t, self.clutch_open)
            torque, clutch = self.drag * s, 1.0 - s
        elif phase == "neutral":
            torque, clutch, push = self._match(), 0.0, 1.0 - self._ramp(t, self.fork_ramp)
        elif phase == "synchronise":
            torque, clutch, held, push = self._match(), 0.0, self._target, self._ramp(t, self.fork_ramp)
        elif phase == "clutch_close":
            s = self._ramp(t, self.clutch_close)
            torque, clutch, held = (1.0 - s) * self._match() + s * demand, s, self._target
        u[0], u[1] = torque, clutch
        gear = self.gears[held]
        u[self._fork_at[gear.fork]] = gear.side * self.fork_force * push
        return u
