"""A transmission controller (TCU) for a dual-clutch transmission: a gear command carried out as a power shift.

A dual-clutch transmission (DCT) shifts without interrupting the drive: one clutch hands the engine's torque over to
the other (the *torque phase*), and a clutch's slip brings the engine to the new gear's speed (the *inertia phase*).
Where the engine's own torque moves it away from the new gear's speed (a power-on upshift, a coast downshift), the
torque phase comes first and the on-coming clutch then pulls the engine over; where its torque moves it towards that
speed (a power-on downshift, a coast upshift), the inertia phase comes first, the off-going clutch slipping, and the
hand-over follows once the engine has reached the new gear's speed (docs/control.md, "A power-shift controller for
the DCT").  The two things an open-loop pressure schedule
cannot know, and this controller waits for, are when the on-coming clutch has taken over the torque (the off-going
clutch's torque has fallen to zero: released earlier the engine flares, later the two clutches fight, the tie-up) and
when the engine has reached the new gear's speed.

:class:`DctController` is that sequence as a sampled controller for :func:`~clutchlab.control.closed_loop`, written
against the system contract: it reads each gear clutch's ``mode`` and ``tau`` outputs and the engine's and the output
speed, and sets the network inputs of the engine's torque and of each clutch's normal-force factor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SimulationError
from ._checks import positive
from .tcu import GearCommand

__all__ = ["DctGear", "DctController", "DCT_PHASES"]

#: the phases of a DCT's shifts: an upshift ``torque_phase``, ``inertia_phase``, ``lock``; a downshift
#: ``inertia_phase``, ``torque_phase`` (``drive`` between shifts)
DCT_PHASES = ("drive", "torque_phase", "inertia_phase", "lock")
#: a friction element's ``mode`` output while it is stuck (MSL's code)
_STUCK = 0.0


@dataclass(frozen=True)
class DctGear:
    """One gear of a DCT: the clutch that engages it (an element of the network, whose ``mode`` and ``tau`` outputs
    the controller reads), the network input of that clutch's normal-force factor (0 open, 1 closed), and the gear's
    ratio, the clutch's driven speed over the output speed in this gear."""

    clutch: str
    input: str
    ratio: float

    def __post_init__(self):
        for what in ("clutch", "input"):
            if not isinstance(getattr(self, what), str) or not getattr(self, what):
                raise ParameterError(f"DctGear: {what} = {getattr(self, what)!r} must be a name")
        try:
            r = float(self.ratio)
        except (TypeError, ValueError):
            r = math.nan
        if not (math.isfinite(r) and r > 0.0):
            raise ParameterError(f"gear of {self.clutch}: ratio = {self.ratio!r} must be a finite number > 0")
        object.__setattr__(self, "ratio", r)


class DctController(GearCommand):
    """The power shifts of a dual-clutch transmission's controller, as a function controller ``f(t, y, memory) -> u``
    of :func:`~clutchlab.control.closed_loop`.

    Parameters
    ----------
    gears : dict
        ``{gear number: DctGear(clutch, input, ratio)}``: at least two, each with its own clutch (a gear's clutch may
        serve several gears where synchronisers preselect them; here each gear is one clutch's).
    start_gear : int
        The gear engaged at the start (its clutch closed, the others open).
    commands : sequence of (float, int)
        The gear command: ``(time [s], gear)`` pairs, taken as :class:`~clutchlab.control.AmtController` takes them
        (a command during a shift waits for it to end; one of the gear engaged is no shift).
    torque_input : str
        The network input of the engine's torque [N m].
    torque : float or sequence of (float, float)
        The engine's torque, the driver's demand [N m]: a number, or rows ``(time [s], torque [N m])`` with
        increasing times, linear between them and held beyond (a tip-in or a tip-out: :meth:`demand`).
    engine_speed, output_speed : str
        The outputs it reads: the engine's speed [rad/s] (e.g. ``"engine.w"``) and the output speed the gears' ratios
        refer to (e.g. ``"output_shaft.w"``).
    fill : float
        The on-coming clutch's factor at the end of a torque phase that comes first (0, 1]: enough capacity to take
        the engine's torque over (default 0.7).
    handover : float
        The duration [s] (> 0) of the torque phase's ramps: the on-coming clutch's factor up, and on a downshift the
        off-going clutch's down (default 0.1).
    rise : float
        The duration [s] (> 0) of the on-coming clutch's factor's rise from ``fill`` to 1 in an upshift's inertia
        phase: its capacity beyond the engine's torque pulls the engine down to the new gear's speed (default 0.15).
    restore : float
        The duration [s] (> 0) of an upshift's ``lock``: the engine's torque back to ``torque`` (default 0.15).
    torque_cut : float
        The fraction [0, 1) of the engine's torque taken away through an upshift's inertia phase (ignition retard):
        the on-coming clutch's excess capacity pulls the engine down faster and dissipates less (default 0).
    slip : float
        A power-on downshift's off-going factor in its inertia phase [0, 1): the off-going clutch is ramped from 1 down
        to it over ``handover``, below the engine's torque, so that the engine speeds up towards the new gear (default
        0.3).
    coast_slip : float
        The same for a coast upshift [0, 1): the off-going clutch's capacity must fall below the engine's drag for the
        drag to slow the engine down (default 0: the off-going clutch opens).
    shift_timeout : float
        The longest a phase that waits on the drive train may take [s] (> 0): beyond it the run stops with a
        :class:`~clutchlab.errors.SimulationError` naming the phase and the clutches (default 1).

    The sequence (docs/control.md, "A power-shift controller for the DCT"), ``s`` each ramp's fraction; a shift is
    *power-on* where the demand at its command is above 0 (the engine drives), a *coast* shift where it is not (the
    engine's drag), and keeps that sequence to its end; ``torque`` below is the demand at each sample:

    * **torque phase first** (a power-on upshift, the new gear's ratio lower; a coast downshift, higher): the engine's
      torque moves it away from the new gear's speed, so the on-coming clutch, sliding, can take the drive over at
      once.  ``torque_phase``: the on-coming factor ``fill s`` over ``handover``, the off-going closed, until the
      off-going clutch's torque has fallen to zero (its sign at the command's sample, or it is no longer stuck):
      then it opens at once; ``inertia_phase``: the on-coming factor ``f_h + (1 - f_h) s`` over ``rise``, from the
      factor ``f_h`` it had at the hand-over (``fill`` at the most: a coast downshift's drag is handed over early, at
      a low factor), and the engine's torque ``(1 - torque_cut) torque``, until the on-coming clutch sticks;
      ``lock``: the factor 1 and the torque back over ``restore``.
    * **inertia phase first** (a power-on downshift; a coast upshift): the engine's torque moves it towards the new
      gear's speed once the off-going clutch slips.  ``inertia_phase``: the off-going factor ``1 - (1 - slip) s``
      (``coast_slip`` in a coast upshift) over ``handover`` until the engine has reached the new gear's speed,
      ``ratio w_out`` (from below in a downshift, from above in an upshift); ``torque_phase``: the on-coming factor
      ``s`` and the off-going factor from where the inertia phase left it down to 0 over ``handover``.

    It measures :attr:`measured` (each gear clutch's ``mode``, then each one's ``tau``, then the two speeds; more may
    follow, for the record) and actuates :attr:`actuated` (the engine's torque, then each gear clutch's factor).  Each
    phase change is logged by name, :attr:`phases`; :attr:`shifts` and :meth:`shift_quality` (clutch to clutch) as
    :class:`~clutchlab.control.AmtController`'s.
    """

    PHASES = DCT_PHASES

    def __init__(self, gears: dict, start_gear: int, commands, *, torque_input: str, torque: float,
                 engine_speed: str, output_speed: str, fill: float = 0.7, handover: float = 0.1, rise: float = 0.15,
                 restore: float = 0.15, torque_cut: float = 0.0, slip: float = 0.3, coast_slip: float = 0.0,
                 shift_timeout: float = 1.0):
        self._set_gears(gears, start_gear, commands, DctGear, least=2)
        clutches = [g.clutch for g in self.gears.values()]
        inputs = [g.input for g in self.gears.values()]
        if len(set(clutches)) != len(clutches) or len(set(inputs)) != len(inputs):
            raise ParameterError(f"DctController: each gear needs a clutch and an input of its own (clutches "
                                 f"{clutches}, inputs {inputs})")
        for what, v in (("torque_input", torque_input), ("engine_speed", engine_speed),
                        ("output_speed", output_speed)):
            if not isinstance(v, str) or not v:
                raise ParameterError(f"DctController: {what} = {v!r} must be a name")
        self.torque_input, self.engine_speed, self.output_speed = torque_input, engine_speed, output_speed
        self._set_demand(torque)
        who = "DctController"
        self.fill = positive("fill", fill, who=who)
        self.handover = positive("handover", handover, who=who)
        self.rise = positive("rise", rise, who=who)
        self.restore = positive("restore", restore, who=who)
        self.torque_cut = positive("torque_cut", torque_cut, zero=True, who=who)
        self.slip = positive("slip", slip, zero=True, who=who)
        self.coast_slip = positive("coast_slip", coast_slip, zero=True, who=who)
        self.shift_timeout = positive("shift_timeout", shift_timeout, who=who)
        for what, v, hi in (("fill", self.fill, 1.0), ("torque_cut", self.torque_cut, 1.0 - 1e-12),
                            ("slip", self.slip, 1.0 - 1e-12), ("coast_slip", self.coast_slip, 1.0 - 1e-12)):
            if v > hi:
                raise ParameterError(f"DctController: {what} = {v!r} must be {'<= 1' if what == 'fill' else '< 1'}")
        #: the outputs it reads, in this order: each gear clutch's mode, each one's torque, the engine's speed, the
        #: output speed
        self.measured = (*(f"{c}.mode" for c in clutches), *(f"{c}.tau" for c in clutches), engine_speed,
                         output_speed)
        #: the inputs it sets, in this order: the engine's torque, each gear clutch's factor
        self.actuated = (torque_input, *inputs)
        self._at = {g: k for k, g in enumerate(self.gears)}
        self._reset()

    @classmethod
    def from_table(cls, table: dict) -> "DctController":
        """The controller of a driveline file's ``[tcu]`` table with ``type = "dct"`` as its loader reads it
        (:attr:`clutchlab.driveline.description.DrivelineFile.tcu`: SI, gears as ``{number: (clutch, input,
        ratio)}``; its ``sample_time`` is the loop's, not the controller's)."""
        kw = {k: v for k, v in table.items() if k not in ("sample_time", "type")}
        kw["gears"] = {g: DctGear(*spec) for g, spec in kw["gears"].items()}
        return cls(**kw)

    def _reset(self):
        super()._reset()
        self._drive_sign = 1.0   # the sign of the off-going clutch's torque while it drives (at the command)
        self._from = 1.0         # the off-going factor where the last ramp started
        self._handed = 0.0       # the on-coming factor at the hand-over (a torque phase that comes first)
        self._power_on = True    # the shift under way is a power-on one (the demand at its command above 0)

    def _element(self, gear):
        return self.gears[gear].clutch

    def _read(self, t, y):
        n = len(self.gears)
        seen = {"mode": {g: y[k] for g, k in self._at.items()}, "tau": {g: y[n + k] for g, k in self._at.items()},
                "w_e": float(y[2 * n]), "w_out": float(y[2 * n + 1])}
        if not (math.isfinite(seen["w_e"]) and math.isfinite(seen["w_out"])):
            raise SimulationError(f"DctController: the measured speeds {self.engine_speed} = {seen['w_e']!r}, "
                                  f"{self.output_speed} = {seen['w_out']!r} at {t:.6g} s")
        return seen

    def _up(self):
        return self.gears[self._target].ratio < self.gears[self._gear].ratio

    def _torque_first(self):
        """The shift under way does its torque phase first: the engine's torque moves it away from the new gear's
        speed (a power-on upshift, a coast downshift)."""
        return self._power_on == self._up()

    def _reached(self, seen):
        """The engine has reached the new gear's speed ``ratio w_out``: from below in a downshift, from above in an
        upshift (an inertia phase that comes first)."""
        gap = seen["w_e"] - self.gears[self._target].ratio * seen["w_out"]
        return gap <= 0.0 if self._up() else gap >= 0.0

    def _slip(self):
        """The off-going factor an inertia phase that comes first ramps down to."""
        return self.slip if self._power_on else self.coast_slip

    def _timeout(self, t, what):
        if t - self._since > self.shift_timeout:
            old, new = self.gears[self._gear].clutch, self.gears[self._target].clutch
            raise SimulationError(f"DctController: the shift from gear {self._gear} ({old}) to {self._target} ({new}) "
                                  f"has not {what} within shift_timeout = {self.shift_timeout:g} s of {self._since:.6g}"
                                  f" s (at {t:.6g} s); a larger fill or slip, or a longer shift_timeout")

    def _advance(self, t, seen):
        phase = self._phase
        if phase == "drive":
            g = self._command(t)
            if g is not None:
                self._target = g
                self._drive_sign = 1.0 if seen["tau"][self._gear] >= 0.0 else -1.0
                self._power_on = self.demand(t) > 0.0
                self._enter("torque_phase" if self._torque_first() else "inertia_phase", t)
        elif phase == "torque_phase" and self._torque_first():
            # the on-coming clutch has taken the torque over: the off-going one carries none (or slides)
            if seen["tau"][self._gear] * self._drive_sign <= 0.0 or seen["mode"][self._gear] != _STUCK:
                self._handed = self.fill * self._ramp(t, self.handover)
                self._enter("inertia_phase", t)
            else:
                self._timeout(t, "handed the torque over (the off-going clutch still carries it)")
        elif phase == "inertia_phase" and self._torque_first():
            if seen["mode"][self._target] == _STUCK:
                self._enter("lock", t)
            else:
                self._timeout(t, "locked the on-coming clutch")
        elif phase == "lock" and self._ramp(t, self.restore) >= 1.0:
            self._finish(t)
        elif phase == "inertia_phase":   # (first: the engine to the new gear's speed under its own torque)
            if self._reached(seen):
                self._from = 1.0 - (1.0 - self._slip()) * self._ramp(t, self.handover)
                self._enter("torque_phase", t)
            else:
                self._timeout(t, "brought the engine to the new gear's speed")
        elif phase == "torque_phase" and self._ramp(t, self.handover) >= 1.0:   # (the hand-over after it, done)
            self._finish(t)

    def _finish(self, t):
        self._gear, self._target = self._target, None
        self._enter("drive", t)

    def _outputs(self, t):
        u = np.zeros(len(self.actuated))
        phase, demand = self._phase, self.demand(t)
        torque = demand
        f = {g: 0.0 for g in self.gears}
        if phase == "drive":
            f[self._gear] = 1.0
        else:
            old, new = self._gear, self._target
            if phase == "torque_phase" and self._torque_first():
                f[old], f[new] = 1.0, self.fill * self._ramp(t, self.handover)
            elif phase == "inertia_phase" and self._torque_first():
                f[new] = self._handed + (1.0 - self._handed) * self._ramp(t, self.rise)
                torque = (1.0 - self.torque_cut) * demand
            elif phase == "lock":
                f[new] = 1.0
                torque = (1.0 - self.torque_cut * (1.0 - self._ramp(t, self.restore))) * demand
            elif phase == "inertia_phase":
                f[old] = 1.0 - (1.0 - self._slip()) * self._ramp(t, self.handover)
            else:   # (the torque phase after an inertia phase)
                s = self._ramp(t, self.handover)
                f[old], f[new] = self._from * (1.0 - s), s
        u[0] = torque
        for g, k in self._at.items():
            u[1 + k] = f[g]
        return u
