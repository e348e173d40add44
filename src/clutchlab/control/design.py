"""Controller design on linear models: a PI for a phase margin, gain scheduling over an operating range.

The design is the loop-shaping one of a control textbook (Åström and Murray, *Feedback Systems*, 2nd ed.,
Ch. 11-12): at the crossover frequency ``w_c`` the open loop ``L = C G`` must have ``|L| = 1`` and phase
``-180° + phase margin``. A PI ``C(s) = Kp (1 + 1 / (Ti s))`` contributes ``-atan(1 / (Ti w_c))`` of
phase (between -90° and 0°), so

``Ti = 1 / (w_c tan(-phi_C))``, ``phi_C = -180° + PM - arg G(j w_c)``, ``Kp = 1 / (|G(j w_c)| |1 - j/(Ti w_c)|)``.

Where ``phi_C`` falls outside (-90°, 0°) a PI cannot give the margin at that crossover: a clear error
says so. The closed loop is checked for stability (its poles, not only the margin: the E-clutch beyond
the diaphragm spring's force peak is open-loop unstable).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import ParameterError

__all__ = ["PI", "pi_for_phase_margin", "ScheduledPI"]


@dataclasses.dataclass(frozen=True)
class PI:
    """A PI controller ``C(s) = Kp (1 + 1 / (Ti s))``.

    Attributes
    ----------
    kp : float
        Proportional gain [input unit per output unit, e.g. V/m].
    ti : float
        Integral time [s].
    """

    kp: float
    ti: float

    def tf(self):
        """The continuous transfer function (python-control)."""
        import control

        return control.tf([self.kp * self.ti, self.kp], [self.ti, 0.0])

    def discrete(self, sample_time: float, method: str = "tustin"):
        """The discrete controller at ``sample_time`` [s] (``control.c2d``; ``method`` as there)."""
        import control

        return control.c2d(self.tf(), sample_time, method)


def pi_for_phase_margin(plant, crossover_hz: float, phase_margin_deg: float) -> PI:
    """The PI giving ``plant`` the phase margin ``phase_margin_deg`` at the crossover ``crossover_hz``.

    Parameters
    ----------
    plant : control.StateSpace or control.TransferFunction
        Single-input single-output plant (e.g. :func:`clutchlab.control.linearize` of motor voltage to
        bearing position).
    crossover_hz : float
        Gain crossover frequency [Hz].
    phase_margin_deg : float
        Phase margin [deg], in (0, 90).

    Returns
    -------
    PI

    Raises
    ------
    ParameterError
        Not SISO; a margin a PI cannot reach at that crossover; an unstable closed loop.
    """
    import control

    if plant.ninputs != 1 or plant.noutputs != 1:
        raise ParameterError(f"the plant has {plant.ninputs} inputs and {plant.noutputs} outputs: a PI needs one each")
    if not (0 < phase_margin_deg < 90):
        raise ParameterError(f"phase_margin_deg = {phase_margin_deg!r}: expected a value in (0, 90)")
    if not (np.isfinite(crossover_hz) and crossover_hz > 0):
        raise ParameterError(f"crossover_hz = {crossover_hz!r}: must be > 0")
    w = 2 * np.pi * crossover_hz
    g = complex(np.squeeze(plant(1j * w)))
    phi_c = np.degrees(np.angle(np.exp(1j * np.radians(-180.0 + phase_margin_deg) - 1j * np.angle(g))))
    if not -90.0 < phi_c < 0.0:
        raise ParameterError(
            f"at {crossover_hz:g} Hz the plant's phase is {np.degrees(np.angle(g)):.1f} deg: a PI (phase -90 to 0 "
            f"deg) cannot give a {phase_margin_deg:g} deg margin there (it would need {phi_c:.1f} deg); choose "
            "another crossover")
    ti = 1.0 / (w * np.tan(np.radians(-phi_c)))
    kp = 1.0 / (abs(g) * abs(1.0 - 1j / (ti * w)))
    pi = PI(float(kp), float(ti))
    poles = control.feedback(control.ss(pi.tf()) * control.ss(plant), 1).poles()
    if np.any(poles.real >= 0):
        raise ParameterError(f"the PI for {phase_margin_deg:g} deg at {crossover_hz:g} Hz leaves the closed loop "
                             f"unstable (poles with real part up to {poles.real.max():.3g} 1/s)")
    return pi


@dataclasses.dataclass
class ScheduledPI:
    """A discrete PI whose gains follow the measured value (gain scheduling) with a feedforward.

    Call it as the controller of :func:`clutchlab.control.loop.closed_loop`: ``u = f(t, y, memory)`` with
    ``y[0]`` the measured value (and scheduling variable), ``memory[0]`` the integral term.  There it runs in
    the model's compiled loop (:func:`clutchlab.numerics.sampled.scheduled_pi_update`, the same arithmetic
    as :meth:`__call__`).

    Attributes
    ----------
    points : ndarray
        Scheduling values (e.g. bearing positions [m]), increasing.
    kp, ti : ndarray
        Gains at the points (linear interpolation between, held beyond).
    feedforward : ndarray or None
        Steady-state input at the points (e.g. the trimmed motor voltage [V]), interpolated at the
        reference; ``None``: no feedforward (the integral term starts at ``memory[0]``, e.g. the operating
        point's input).
    sample_time : float
        Period [s] (the integral is summed by the backward rectangle rule).
    reference : callable
        ``r(t)`` [SI].
    limits : tuple of float
        Output range (anti-windup: the integral stops while the output is limited).
    integrate_band : float
        Conditional integration: the integral runs only while ``|r - y| <= integrate_band * |r|`` (a
        reference ramp or a fill phase the plant cannot follow does not wind it up); default: always.
    """

    points: np.ndarray
    kp: np.ndarray
    ti: np.ndarray
    feedforward: np.ndarray
    sample_time: float
    reference: object
    limits: tuple = (-np.inf, np.inf)
    integrate_band: float = np.inf

    def __call__(self, t, y, memory):
        """One sample: ``t`` [s], measured ``y``, ``memory`` (the integral term, changed in place)."""
        r = float(self.reference(t))
        x = float(y[0])
        kp = np.interp(x, self.points, self.kp)
        ti = np.interp(x, self.points, self.ti)
        e = r - x
        u_ff = 0.0 if self.feedforward is None else np.interp(r, self.points, self.feedforward)
        integral = memory[0] + kp * self.sample_time / ti * e
        u = u_ff + kp * e + integral
        lo, hi = self.limits
        if lo <= u <= hi and (self.integrate_band == np.inf or abs(e) <= self.integrate_band * abs(r)):
            memory[0] = integral  # anti-windup: integrate only while the output is not limited (and near r)
        return np.array([min(max(u, lo), hi)])
