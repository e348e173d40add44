"""Describe a one-dimensional driveline network in Python and run it on the integrator core.

::

    from clutchlab.driveline import Driveline, Signal

    d = Driveline("test_friction")
    d.inertia("inertia", J=1.0)
    d.torque("torque", "inertia", Signal.sine(amplitude=10.0, frequency=1.0))
    d.bearing_friction("bearing_friction", "inertia", torque=1.0)
    result = d.simulate(1.1, output_step=1e-3)
    result.events            # time_s, event (stick / forward / backward / free), element

Every component has a unique name; flanges are named by their inertia (``None`` or ``"ground"`` is the
fixed ground).  Quantities are SI (kg m^2, N m/rad, N m s/rad, N, rad/s, N m).  The friction semantics
are those of the Modelica Standard Library (MSL 4.x, :mod:`clutchlab.driveline.kernel`).
"""

from __future__ import annotations

import copy
import functools
import hashlib
import inspect
import math
import pickle
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from .._limits import as_numbers, check_number
from ..errors import ParameterError
from ..numerics import core, outline
from ..params.base import ABSOLUTE_ZERO_C
from ..units import COLUMN_UNITS
from ..system import System, register_model, simulate as _simulate, start_checks_deferred
from . import kernel as K


__all__ = ["Driveline", "Signal", "GROUND", "ElementInfo", "InertiaInfo", "Arguments"]

GROUND = "ground"

#: per domain: the quantity names and units (column unit, unit for people) of an inertia's angle and speed,
#: of an element's torque and relative speed, and the units of inertia, stiffness and damping
DOMAINS = {
    "rotational": {"angle": ("phi", "rad", "rad"), "speed": ("w", "rad_s", "rad/s"), "torque": ("tau", "Nm", "N m"),
                   "relative": ("w_rel", "rad_s", "rad/s"), "inertia": ("J", "kg m^2"), "stiffness": "N m/rad",
                   "damping": "N m s/rad", "words": ("inertia", "angle", "torque")},
    "translational": {"angle": ("s", "m", "m"), "speed": ("v", "m_s", "m/s"), "torque": ("f", "N", "N"),
                      "relative": ("v_rel", "m_s", "m/s"), "inertia": ("m", "kg"), "stiffness": "N/m",
                      "damping": "N s/m", "words": ("mass", "position", "force")},
}


def _finite(component, name, value, *, positive=False, nonneg=False):
    return check_number(f"{component}: {name}", value, positive=positive, nonnegative=nonneg)


#: an efficiency within this of 1 (and no bearing friction) makes a gear ideal (:meth:`Driveline._is_lossy`)
ETA_IDEAL = 1e-12


@dataclass(frozen=True)
class Signal:
    """A time signal as in ``Modelica.Blocks.Sources``: constant, step, ramp, sine, pulse, trapezoid,
    exponentials or a table, or the product of signals (``Modelica.Blocks.Math.Product``).

    Build with the class methods; a plain number is a constant.

    Parameters
    ----------
    row : tuple
        The kind (``kernel.SIG_*``) and its parameters.
    points : tuple
        The breakpoints of a table signal: times, then values.
    breaks : tuple
        A sampled signal's corners (times [s]), the only points at which a step must end.
    factors : tuple
        A product's factors (signals, none of them a product: nested products are flattened).
    name : str
        The network input an input signal reads (:meth:`input`; "" for the others).
    """

    row: tuple
    points: tuple = ()
    breaks: tuple = ()
    factors: tuple = ()
    name: str = ""

    @classmethod
    def input(cls, name: str) -> "Signal":
        """The network input ``name`` (:meth:`Driveline.input`): the value its host holds -- a co-simulation
        master or an FMU's importer between communication points, a controller, :meth:`Driveline.simulate`'s
        ``inputs`` -- constant between two of its changes (a zero-order hold); in a :meth:`product` with other
        signals, a scaled or modulated input."""
        return cls((K.SIG_INPUT,), name=_word("input signal: name", name))

    def input_names(self) -> tuple:
        """The network inputs this signal reads (a product's factors' too)."""
        if self.row[0] == K.SIG_PRODUCT:
            return tuple(n for f in self.factors for n in f.input_names())
        return (self.name,) if self.row[0] == K.SIG_INPUT else ()

    def with_inputs(self, signals: dict) -> "Signal":
        """This signal with each input it reads replaced by ``signals[name]`` (a :class:`Signal`), those not in
        ``signals`` kept."""
        if self.row[0] == K.SIG_PRODUCT:
            out = self.factors[0].with_inputs(signals)
            for f in self.factors[1:]:
                out = Signal.product(out, f.with_inputs(signals))
            return out
        if self.row[0] == K.SIG_INPUT and self.name in signals:
            return signals[self.name]
        return self

    @classmethod
    def constant(cls, value: float) -> "Signal":
        """``value`` at all times."""
        return cls((K.SIG_CONST, _finite("signal", "value", value)))

    @classmethod
    def step(cls, height: float = 1.0, start: float = 0.0, offset: float = 0.0) -> "Signal":
        """``offset`` before ``start`` [s], ``offset + height`` from it (MSL ``Step``)."""
        return cls((K.SIG_STEP, _finite("step", "height", height), _finite("step", "start", start),
                    _finite("step", "offset", offset)))

    @classmethod
    def ramp(cls, height: float, duration: float, start: float = 0.0, offset: float = 0.0) -> "Signal":
        """Linear from ``offset`` at ``start`` to ``offset + height`` after ``duration`` [s] (MSL ``Ramp``)."""
        return cls((K.SIG_RAMP, _finite("ramp", "height", height), _finite("ramp", "duration", duration, positive=True),
                    _finite("ramp", "start", start), _finite("ramp", "offset", offset)))

    @classmethod
    def sine(cls, amplitude: float, frequency: float, phase: float = 0.0, offset: float = 0.0,
             start: float = 0.0) -> "Signal":
        """``offset + amplitude sin(2 pi f (t - start) + phase)`` from ``start`` [s], ``offset`` before (MSL ``Sine``)."""
        return cls((K.SIG_SINE, _finite("sine", "amplitude", amplitude), _finite("sine", "frequency", frequency, nonneg=True),
                    _finite("sine", "phase", phase), _finite("sine", "offset", offset), _finite("sine", "start", start)))

    @classmethod
    def pulse(cls, amplitude: float, width: float, period: float, nperiod: int = -1, offset: float = 0.0,
              start: float = 0.0) -> "Signal":
        """MSL ``Pulse``: ``offset + amplitude`` for the first ``width`` of each ``period`` [s] from ``start`` [s],
        ``offset`` otherwise, before ``start`` and after ``nperiod`` periods (< 0: unlimited).

        ``width`` is the fraction of the period the pulse is on, in (0, 1] (MSL's ``width`` is in percent:
        MSL ``width = 50`` is 0.5 here).  Every on and off instant is a break of the integrator.
        """
        w = _finite("pulse", "width", width)
        if not 0.0 < w <= 1.0:
            raise ParameterError(f"pulse: width = {width!r} must be in (0, 1] (the fraction of the period the "
                                 "pulse is on; MSL's width = 50 % is 0.5)")
        return cls((K.SIG_PULSE, _finite("pulse", "amplitude", amplitude), w,
                    _finite("pulse", "period", period, positive=True), _count("pulse", nperiod),
                    _finite("pulse", "offset", offset), _finite("pulse", "start", start)))

    @classmethod
    def trapezoid(cls, amplitude: float, rising: float, width: float, falling: float, period: float,
                  nperiod: int = -1, offset: float = 0.0, start: float = 0.0) -> "Signal":
        """MSL ``Trapezoid``: in each ``period`` [s] from ``start`` [s], linear from ``offset`` to ``offset +
        amplitude`` over ``rising`` [s], held for ``width`` [s], back to ``offset`` over ``falling`` [s], then
        ``offset`` to the period's end; ``offset`` before ``start`` and after ``nperiod`` periods (< 0:
        unlimited).  ``rising + width + falling <= period``; every corner is a break of the integrator."""
        rising = _finite("trapezoid", "rising", rising, nonneg=True)
        width = _finite("trapezoid", "width", width, nonneg=True)
        falling = _finite("trapezoid", "falling", falling, nonneg=True)
        period = _finite("trapezoid", "period", period, positive=True)
        if rising + width + falling > period:
            raise ParameterError(f"trapezoid: rising + width + falling = {rising:g} + {width:g} + {falling:g} s "
                                 f"must not exceed period = {period:g} s")
        return cls((K.SIG_TRAPEZOID, _finite("trapezoid", "amplitude", amplitude), rising, width, falling, period,
                    _count("trapezoid", nperiod), _finite("trapezoid", "offset", offset),
                    _finite("trapezoid", "start", start)))

    @classmethod
    def exponentials(cls, out_max: float, rise_time: float, rise_time_const: float, fall_time_const: float,
                     offset: float = 0.0, start: float = 0.0) -> "Signal":
        """MSL ``Exponentials``: from ``start`` [s], ``offset + out_max (1 - exp(-(t - start) / rise_time_const))``
        for ``rise_time`` [s], then that value at ``start + rise_time`` times ``exp(-(t - start - rise_time) /
        fall_time_const)`` (time constants [s] > 0); ``offset`` before ``start``.  Breaks at ``start`` and
        ``start + rise_time`` (its kinks)."""
        return cls((K.SIG_EXPONENTIALS, _finite("exponentials", "out_max", out_max),
                    _finite("exponentials", "rise_time", rise_time, nonneg=True),
                    _finite("exponentials", "rise_time_const", rise_time_const, positive=True),
                    _finite("exponentials", "fall_time_const", fall_time_const, positive=True),
                    _finite("exponentials", "offset", offset), _finite("exponentials", "start", start)))

    @classmethod
    def product(cls, a, b) -> "Signal":
        """The product ``a(t) b(t)`` of two signals (MSL ``Blocks.Math.Product`` of two sources); numbers are
        constants.  Its breaks are both factors'.  Products of products are flattened into one."""
        factors = []
        for what, f in (("a", a), ("b", b)):
            f = cls.of(f, f"product: {what}")
            factors.extend(f.factors if f.row[0] == K.SIG_PRODUCT else (f,))
        return cls((K.SIG_PRODUCT,), factors=tuple(factors))

    @classmethod
    def table(cls, times, values) -> "Signal":
        """Piecewise linear through ``(times [s], values)``, held beyond the ends."""
        t = as_numbers(times, "table signal: times").ravel()
        v = as_numbers(values, "table signal: values").ravel()
        if t.size < 1 or t.size != v.size or not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise ParameterError(f"table signal: times and values need the same non-zero length and finite values "
                                 f"({t.size} times, {v.size} values)")
        if t.size > 1 and np.any(np.diff(t) <= 0):
            raise ParameterError("table signal: times must be strictly increasing")
        return cls((K.SIG_TABLE,), tuple(t) + tuple(v))

    @classmethod
    def sampled(cls, times, values, breaks=()) -> "Signal":
        """Samples of a smooth signal, read linearly between them as :meth:`table`, but whose sample times are
        not corners of the signal: a step ends only at ``breaks`` [s] (its real corners) and at its ends, so a
        densely sampled trajectory does not cut the integrator's steps to the sampling interval."""
        sig = cls.table(times, values)
        b = as_numbers(breaks, "sampled signal: breaks").ravel()
        if not np.all(np.isfinite(b)):
            raise ParameterError("sampled signal: breaks must be finite times")
        return cls((K.SIG_SAMPLED,), sig.points, tuple(np.unique(b)))

    @classmethod
    def function(cls, fn, t_end: float, step: float, start: float = 0.0) -> "Signal":
        """A user function ``fn(t)`` of time [s], sampled every ``step`` from ``start`` to ``t_end`` into a
        :meth:`table` (piecewise linear between the samples, held beyond).

        The compiled network cannot call Python, so the function is read once here; its values must be
        finite numbers.  A jump of ``fn`` shows as a ramp over one ``step``; pass its corners in a
        :meth:`table` to keep them exact.
        """
        t_end = _finite("function signal", "t_end", t_end)
        step = _finite("function signal", "step", step, positive=True)
        start = _finite("function signal", "start", start)
        if t_end <= start:
            raise ParameterError(f"function signal: t_end = {t_end!r} must be after start = {start!r}")
        n = int(math.ceil((t_end - start) / step - 1e-9)) + 1
        if n > 1_000_000:
            raise ParameterError(f"function signal: {n} samples (t_end - start) / step; at most 1,000,000")
        times = np.minimum(start + step * np.arange(n), t_end)
        try:
            values = np.array([float(fn(float(t))) for t in times])
        except Exception as exc:   # the user's function: name it and its failure
            raise ParameterError(f"function signal: {getattr(fn, '__name__', fn)!r} failed at a sample: {exc}") from None
        if not np.all(np.isfinite(values)):
            k = int(np.flatnonzero(~np.isfinite(values))[0])
            raise ParameterError(f"function signal: {getattr(fn, '__name__', fn)!r}({times[k]:g}) = {values[k]!r} "
                                 "is not finite")
        return cls.table(times, values)

    def describe(self, unit: str = "") -> str:
        """One line for people: ``sine 10 N m at 5 Hz``, ``step to 1 at 0.4 s`` (``unit``: of the values)."""
        k, *a = self.row
        u = f" {unit}" if unit else ""
        if k == K.SIG_CONST:
            return f"{a[0]:g}{u}"
        if k == K.SIG_STEP:
            return f"step from {a[2]:g} to {a[2] + a[0]:g}{u} at {a[1]:g} s"
        if k == K.SIG_RAMP:
            return f"ramp from {a[3]:g} to {a[3] + a[0]:g}{u} over {a[1]:g} s from {a[2]:g} s"
        if k == K.SIG_SINE:
            off = f"{a[3]:g} + " if a[3] else ""
            return f"{off}{a[0]:g}{u} sine at {a[1]:g} Hz, phase {a[2]:g} rad" + (f", from {a[4]:g} s" if a[4] else "")
        if k == K.SIG_PULSE:
            count = "" if a[3] < 0 else f", {a[3]:g} periods"
            return (("" if a[4] == 0 else f"{a[4]:g} + ") + f"{a[0]:g}{u} pulse, {a[1] * 100:g} % of {a[2]:g} s{count}"
                    + (f", from {a[5]:g} s" if a[5] else ""))
        if k == K.SIG_TRAPEZOID:
            count = "" if a[5] < 0 else f", {a[5]:g} periods"
            return (("" if a[6] == 0 else f"{a[6]:g} + ") + f"{a[0]:g}{u} trapezoid, rising {a[1]:g} s, width {a[2]:g} s, falling {a[3]:g} s, "
                    f"period {a[4]:g} s{count}" + (f", from {a[7]:g} s" if a[7] else ""))
        if k == K.SIG_EXPONENTIALS:
            return (("" if a[4] == 0 else f"{a[4]:g} + ") + f"{a[0]:g}{u} exponentials, rising {a[1]:g} s (time constant {a[2]:g} s), "
                    f"falling with {a[3]:g} s" + (f", from {a[5]:g} s" if a[5] else ""))
        if k == K.SIG_PRODUCT:
            return " * ".join(f"({f.describe(unit if i == 0 else '')})" for i, f in enumerate(self.factors))
        if k == K.SIG_INPUT:
            return f"input {self.name}" + (f" [{unit}]" if unit else "")
        n = len(self.points) // 2
        what = "samples" if k == K.SIG_SAMPLED else "table of"
        return f"{what} {n} points from {self.points[0]:g} to {self.points[n - 1]:g} s"

    def value_and_rate(self, t: float, inputs=None) -> tuple:
        """Value and time derivative (from the right) at ``t`` [s], in Python (as the kernel's
        :func:`~clutchlab.driveline.kernel.signal_value` and :func:`~clutchlab.driveline.kernel.signal_rates`);
        ``inputs``: the held value of each network input by name (an input's rate is 0)."""
        k, *a = self.row
        if k == K.SIG_PRODUCT:   # the product rule, one factor at a time
            y, rate = 1.0, 0.0
            for f in self.factors:
                v, r = f.value_and_rate(t, inputs)
                y, rate = y * v, rate * v + y * r
            return y, rate
        if k == K.SIG_INPUT:
            if not inputs or self.name not in inputs:
                raise ParameterError(f"input signal {self.name!r}: no value held (declare it with Driveline.input)")
            return float(inputs[self.name]), 0.0
        if k == K.SIG_CONST:
            return a[0], 0.0
        if k == K.SIG_STEP:
            return a[2] + (a[0] if t >= a[1] else 0.0), 0.0
        if k in (K.SIG_PULSE, K.SIG_TRAPEZOID):
            return _periodic_value_and_rate(k, a, t)
        if k == K.SIG_EXPONENTIALS:
            out_max, rise, tc_rise, tc_fall, offset, start = a
            if t < start:
                return offset, 0.0
            if t < start + rise:
                return (offset - out_max * math.expm1(-(t - start) / tc_rise),
                        out_max / tc_rise * math.exp(-(t - start) / tc_rise))
            y = -out_max * math.expm1(-rise / tc_rise) * math.exp(-(t - (start + rise)) / tc_fall)
            return offset + y, -y / tc_fall
        if k == K.SIG_RAMP:
            height, duration, start, offset = a
            if t < start:
                return offset, 0.0
            if t >= start + duration:
                return offset + height, 0.0
            return offset + height * (t - start) / duration, height / duration
        if k == K.SIG_SINE:
            amp, freq, phase, offset, start = a
            if t < start:
                return offset, 0.0
            om = 2.0 * math.pi * freq
            arg = om * (t - start) + phase
            return offset + amp * math.sin(arg), amp * om * math.cos(arg)
        n = len(self.points) // 2
        ts, vs = np.array(self.points[:n]), np.array(self.points[n:])
        value = float(np.interp(t, ts, vs))
        if n < 2 or t < ts[0] or t >= ts[-1]:
            return value, 0.0
        lo = int(np.searchsorted(ts, t, side="right")) - 1
        return value, float((vs[lo + 1] - vs[lo]) / (ts[lo + 1] - ts[lo]))

    def bounds(self) -> tuple:
        """``(lowest, highest)`` value the signal takes at any time, or ``(None, None)`` where a network input
        decides it (a product's bounds: the extremes of its factors' bounds' products).  A component's declared
        range is checked against them (:mod:`clutchlab.driveline.description`: a throttle in [0, 1])."""
        k, *a = self.row
        if k == K.SIG_INPUT:
            return None, None
        if k == K.SIG_PRODUCT:
            lo, hi = 1.0, 1.0
            for f in self.factors:
                flo, fhi = f.bounds()
                if flo is None:
                    return None, None
                corners = (lo * flo, lo * fhi, hi * flo, hi * fhi)
                lo, hi = min(corners), max(corners)
            return lo, hi
        if k == K.SIG_CONST:
            ends = (a[0],)
        elif k == K.SIG_STEP:
            ends = (a[2], a[2] + a[0])
        elif k == K.SIG_RAMP:
            ends = (a[3], a[3] + a[0])
        elif k == K.SIG_SINE:
            ends = (a[3] - abs(a[0]), a[3] + abs(a[0]))
        elif k == K.SIG_PULSE:
            ends = (a[4], a[4] + a[0])
        elif k == K.SIG_TRAPEZOID:
            ends = (a[6], a[6] + a[0])
        elif k == K.SIG_EXPONENTIALS:   # (its peak, at the end of the rise)
            ends = (a[4], a[4] - a[0] * math.expm1(-a[1] / a[2]))
        else:
            ends = self.points[len(self.points) // 2:]
        return float(min(ends)), float(max(ends))

    def breakpoints(self, what: str, unit: str = "") -> tuple:
        """The corners ``(times [s], values)`` of a piecewise-linear signal (constant, ramp, table or sampled),
        as a model with its own piecewise-linear profile takes them; ``what`` names the signal in the error a
        step or sine raises (:class:`~clutchlab.errors.ParameterError`)."""
        kind = self.row[0]
        if self.input_names():
            raise ParameterError(f"{what} cannot be a network input ({self.describe(unit)}) yet: this component "
                                 "reads a piecewise-linear profile of its own (issue #31 makes its inputs ports)")
        if kind == K.SIG_CONST:
            return (0.0,), (self.row[1],)
        if kind == K.SIG_RAMP:
            height, duration, start, offset = self.row[1:5]
            return (start, start + duration), (offset, offset + height)
        if kind in (K.SIG_TABLE, K.SIG_SAMPLED):
            half = len(self.points) // 2
            return tuple(self.points[:half]), tuple(self.points[half:])
        raise ParameterError(f"{what} must be a constant, a ramp or a table (a piecewise-linear profile), not "
                             f"{self.describe(unit)}")

    @classmethod
    def of(cls, value, what: str) -> "Signal":
        """``value`` as a signal: a :class:`Signal` as it is, a number as a constant."""
        if isinstance(value, Signal):
            return value
        if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
            return cls.constant(value)
        raise ParameterError(f"{what} = {value!r}: expected a number or a Signal")


def _port_inputs(e) -> tuple:
    """The network inputs an element's ports read (an EMTC coupling's :meth:`Driveline.emtc` ports)."""
    if getattr(e, "emtc", None) is None:
        return ()
    return tuple(n for v in e.emtc["ports"].values() if v is not None for n in v.input_names())


#: an EMTC coupling's ports, in the order of its block's columns (:mod:`clutchlab.driveline.emtc`), and their units
EMTC_PORTS = (("torque_request", "N*m"), ("throttle", "1"), ("coil_current", "A"))


def _word(what: str, name) -> str:
    """``name`` if it is ASCII letters, digits and underscores (a component's or an input's name: part of column
    names and FMI variable names, which an FMI validator refuses in other characters), else a ParameterError
    starting with ``what``."""
    if not isinstance(name, str) or not name or not name.isascii() or not name.replace("_", "").isalnum():
        raise ParameterError(f"{what} {name!r} must be ASCII letters, digits and underscores")
    return name


def _count(component, value):
    """A number of periods: a whole number (< 0: unlimited, as MSL's ``nperiod = -1``), as a float."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if isinstance(value, bool) or not math.isfinite(v) or v != math.floor(v):
        raise ParameterError(f"{component}: nperiod = {value!r} must be a whole number (< 0: unlimited)")
    return -1.0 if v < 0 else v


def _periodic_value_and_rate(kind, a, t):
    """Python twin of the kernel's pulse and trapezoid (:func:`~clutchlab.driveline.kernel.signal_value`):
    value and rate (from the right) at ``t`` [s], with the same sums for the period's start and corners."""
    if kind == K.SIG_PULSE:
        amp, width, period, nper, offset, start = a
        tw = width * period
        corners = (tw, tw, tw)
    else:
        amp, rising, width, falling, period, nper, offset, start = a
        corners = (rising, rising + width, rising + width + falling)
    if t < start or nper == 0:
        return offset, 0.0
    k = math.floor((t - start) / period)
    if start + (k + 1.0) * period <= t:
        k += 1.0
    elif start + k * period > t:
        k -= 1.0
    if nper > 0 and k >= nper:
        return offset, 0.0
    tk = start + k * period
    c1, c2, c3 = corners
    if kind == K.SIG_PULSE:
        return offset + (amp if t < tk + c1 or width >= 1.0 else 0.0), 0.0
    if t < tk + c1:
        return offset + amp * (t - tk) / rising, amp / rising
    if t < tk + c2:
        return offset + amp, 0.0
    if t < tk + c3:
        return offset + amp * (tk + c3 - t) / falling, -amp / falling
    return offset, 0.0


def _curve_integrals(xs, fs, ds, kind):
    """Integral of a spring curve from its first point to each point (exact for linear and cubic Hermite).

    :meth:`Driveline.spring` shifts them so the stored energy is the integral from zero deflection."""
    h = np.diff(xs)
    if kind == 0:
        seg = 0.5 * h * (fs[:-1] + fs[1:])
    else:
        seg = h * (0.5 * (fs[:-1] + fs[1:]) + h * (ds[:-1] - ds[1:]) / 12.0)
    return np.concatenate([[0.0], np.cumsum(seg)])


def _curve_energy_py(table, m, kind, phi):
    """The curve's energy at ``phi`` as :func:`clutchlab.driveline.kernel._segment_energy` integrates it (at build
    time: the integration constants that make the stored energy 0 at zero deflection)."""
    xs, fs, ds, cs = table[:m], table[m:2 * m], table[2 * m:3 * m], table[3 * m:4 * m]
    if phi <= xs[0] or phi >= xs[-1]:
        end = 0 if phi <= xs[0] else m - 1
        if kind == 0:
            sl = (fs[1] - fs[0]) / (xs[1] - xs[0]) if end == 0 else (fs[-1] - fs[-2]) / (xs[-1] - xs[-2])
        else:
            sl = ds[end]
        dx = phi - xs[end]
        return float(cs[end] + fs[end] * dx + 0.5 * sl * dx * dx)
    lo = int(np.searchsorted(xs, phi, side="right")) - 1
    h = xs[lo + 1] - xs[lo]
    u = (phi - xs[lo]) / h
    if kind == 0:
        return float(cs[lo] + h * (fs[lo] * u + 0.5 * (fs[lo + 1] - fs[lo]) * u * u))
    return float(cs[lo] + h * (fs[lo] * (u - u ** 3 + 0.5 * u ** 4) + h * ds[lo] * (0.5 * u ** 2 - 2 * u ** 3 / 3 + 0.25 * u ** 4)
                               + fs[lo + 1] * (u ** 3 - 0.5 * u ** 4) + h * ds[lo + 1] * (0.25 * u ** 4 - u ** 3 / 3)))


def _check_motion_signal(name, what, sig):
    """A motion source's signal may not jump (an infinite torque) nor, for a position, have a speed jump."""
    kind, *a = sig.row
    if sig.input_names():
        raise ParameterError(f"{name}: a motion source cannot follow a network input ({sig.describe()}): a held input "
                             "jumps at every change, and a prescribed speed or position that jumps needs an infinite "
                             "torque; drive a torque source (or an engine's throttle) with it")
    if what == "speed":
        if kind == K.SIG_PRODUCT:   # continuous if every factor is
            for f in sig.factors:
                _check_motion_signal(name, what, f)
            return
        if kind == K.SIG_STEP:
            raise ParameterError(f"{name}: a speed step would need an infinite torque; use a ramp or a table")
        if kind == K.SIG_PULSE and a[0] != 0.0:
            raise ParameterError(f"{name}: a speed pulse jumps (an infinite torque); use a trapezoid with rising "
                                 "and falling > 0")
        if kind == K.SIG_TRAPEZOID and a[0] != 0.0 and (a[1] == 0.0 or a[3] == 0.0):
            raise ParameterError(f"{name}: the trapezoid jumps (rising = {a[1]:g} s, falling = {a[3]:g} s): a speed "
                                 "needs rising and falling > 0")
        if kind == K.SIG_SINE and a[4] > 0.0 and abs(a[0] * math.sin(a[2])) > 0.0:
            raise ParameterError(f"{name}: the sine jumps at its start ({a[4]:g} s); start it at 0 or with phase 0")
        return
    if kind not in (K.SIG_CONST, K.SIG_SINE):
        raise ParameterError(f"{name}: a position source needs a signal with a continuous speed (a constant or a "
                             f"sine); for a ramp or a table of positions, prescribe the speed with a speed source")
    if kind == K.SIG_SINE and a[4] != 0.0 and a[0] != 0.0:
        raise ParameterError(f"{name}: a position sine must start at t = 0 (start = {a[4]:g} s makes its speed jump)")


class _Groups:
    """Union-find over the inertias and the ground (-1), for the loops of gears and motion sources."""

    def __init__(self, n):
        self.parent = list(range(n + 1))

    def find(self, i):
        i += 1
        while self.parent[i] != i:
            self.parent[i] = self.parent[self.parent[i]]
            i = self.parent[i]
        return i

    def union(self, a, b):
        ra, rb = self.find(a), self.find(b)
        if ra == rb:
            return False
        self.parent[ra] = rb
        return True


@dataclass
class _Element:
    kind: int
    name: str
    a: str | None
    b: str | None
    coef: tuple = (0.0, 0.0, 0.0, 0.0)
    law: int = 0
    signal: Signal | None = None
    table: tuple = ()   # friction characteristic: speeds [rad/s], then values; a spring curve: its kernel data
    aux: int = 0        # a spring curve's kind (0 linear, 1 pchip)
    ncurve: tuple = ()  # a friction element's normal-force curve: inputs, then forces [N]
    liftoff: float = math.inf   # the input beyond which that force is 0
    levels: int = 0     # an E-clutch whose working point moves: its curve's shift levels (ncurve: kernel.shifted_curve)
    map_t: int = 0      # a friction map read at its heat port's temperature: its temperatures (table: kernel.friction_map)
    model: str = ""     # what built it (for describe)
    wet: dict | None = None   # a wet clutch: its clutch, bench, friction law, force profile and temperatures
    reference: Signal | None = None   # an E-clutch with its actuator: the bearing position reference
    emtc: dict | None = None  # an EMTC coupling: its magnet, scenario, vehicle and options
    ecl: dict | None = None   # an E-clutch with its actuator in the network: its model, actuator and pre-roll
    sup: str | None = None    # a gear's or converter's support (housing), a planetary's carrier; None: the ground
    fade: tuple = ()          # a friction element's factor over its heat port's temperature: temperatures, factors
    kind_name: str = ""       # what added it: a builder's name ("clutch", "brake", ...) or a component's type
    call: tuple = ()          # (the Driveline method that added it, its arguments by name: ElementInfo.arguments)


@dataclass(frozen=True)
class _ThermalMass:
    """A thermal mass (:meth:`Driveline.thermal_mass`): SI, temperatures in degC; read-only, as
    :attr:`Driveline.thermal_masses` lists them (``name``, ``capacity`` [J/K], ``T0`` [degC], ``conductance``
    [W/K], ``ambient`` [degC], ``heat_from``: the elements whose losses flow into it)."""
    name: str
    capacity: float      # [J/K]
    T0: float            # initial temperature [degC]
    conductance: float   # to its ambient [W/K]
    ambient: float       # the ambient's temperature [degC]
    heat_from: tuple     # the elements whose losses flow into it


@dataclass(frozen=True)
class _ThermalLink:
    """A thermal conductor between two thermal masses (:meth:`Driveline.thermal_conductor`)."""
    name: str
    a: str
    b: str
    conductance: float   # [W/K]


class Arguments(Mapping):
    """The arguments of the call that added an element or a body (:attr:`ElementInfo.arguments`,
    :attr:`InertiaInfo.arguments`): a read-only mapping of the method's parameter names to the values given (a copy;
    picklable, as the network is)."""

    __slots__ = ("_values",)

    def __init__(self, values=()):
        self._values = dict(values)

    def __getitem__(self, key):
        return self._values[key]

    def __iter__(self):
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __eq__(self, other):
        return dict(self._values) == dict(other) if isinstance(other, Mapping) else NotImplemented

    __hash__ = None

    def __repr__(self) -> str:
        return f"Arguments({self._values!r})"


@dataclass(frozen=True)
class ElementInfo:
    """One element of a :class:`Driveline`, as :attr:`Driveline.elements` lists it (a read-only view).

    ``name``: the element's name (its result columns' prefix); ``kind``: what added it, the name of the
    :class:`Driveline` method (``"clutch"``, ``"brake"``, ``"gear"``, ``"wet_clutch"``, ...) or of the
    component type of a driveline file (``"cone_clutch"``); ``flange_a``, ``flange_b``: the inertias it acts
    between (``"ground"`` for the fixed ground: a brake's ``flange_a`` is its support; a planetary set's are its
    sun and ring); ``support``: a gear's or a torque converter's housing inertia, a planetary set's carrier
    (``"ground"`` if fixed, ``None`` for other elements); ``summary``: its line of
    :meth:`Driveline.describe`; ``arguments``: the arguments of the method call that added it, by the method's
    parameter names (its name and flanges left out), defaults filled in, as given: SI numbers, :class:`Signal`
    objects, tables, parameter sets (a driveline file's loader calls the same methods with its values in SI, its
    parameter files read), a read-only mapping.  ``d.replace(name, mu=0.3)`` is a copy with some of them changed
    (:meth:`Driveline.replace`)."""

    name: str
    kind: str
    flange_a: str
    flange_b: str
    support: str | None
    summary: str
    arguments: Arguments = field(default_factory=Arguments, hash=False)


@dataclass(frozen=True)
class InertiaInfo:
    """One body of a :class:`Driveline`, as :attr:`Driveline.inertias` lists it (a read-only view): ``name``;
    ``kind``: ``"inertia"`` or ``"mass"`` (a translational network's); ``arguments``: ``J``, ``w0``, ``phi0`` [kg
    m^2, rad/s, rad] of :meth:`Driveline.inertia` (``m``, ``v0``, ``s0`` [kg, m/s, m] of :meth:`Driveline.mass`) as
    given, SI, ``None`` for a start value left out (the network derives it: :meth:`Driveline.derived_speeds`)."""

    name: str
    kind: str
    arguments: Arguments = field(default_factory=Arguments, hash=False)


def _converter_table(name, key, rows, ncol):
    """A torque converter's table (:meth:`Driveline.torque_converter`): ``ncol`` columns ``[SR, K, TR]`` (or ``[SR,
    K]``), checked: speed ratios in [0, 1) increasing, capacity factors and torque ratios finite and > 0."""
    what = "[SR, K, TR]" if ncol == 3 else "[SR, K]"
    try:
        t = np.asarray(rows, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: {key} = {rows!r} must be rows {what}") from None
    if t.ndim != 2 or t.shape[1] != ncol or t.shape[0] < 1 or not np.all(np.isfinite(t)):
        raise ParameterError(f"{name}: {key} must be rows of {ncol} finite numbers {what}, got shape {t.shape}")
    sr = t[:, 0]
    if sr[0] < 0.0 or sr[-1] >= 1.0 or np.any(np.diff(sr) <= 0.0):
        raise ParameterError(f"{name}: {key} speed ratios {sr.tolist()} must increase within [0, 1) (the capacity "
                             "falls to 0 at 1 by itself)")
    bad = t[np.any(t[:, 1:] <= 0.0, axis=1)]
    if bad.size:
        raise ParameterError(f"{name}: {key} row {bad[0].tolist()}: capacity factor and torque ratio must be > 0")
    return t


#: the arguments of an element's method that place it (its name and flanges): :class:`ElementInfo` names them
#: itself, so they are not among its :attr:`~ElementInfo.arguments` (:meth:`Driveline.replace` keeps them)
_PLACES = ("name", "a", "b", "flange", "support", "sun", "carrier", "ring")


def _adds(kind: str):
    """Marks a :class:`Driveline` method as adding elements of ``kind`` (:attr:`ElementInfo.kind`), and keeps the
    call on each element it adds: the method's name and its arguments by name, defaults filled in
    (:attr:`ElementInfo.arguments`; :meth:`Driveline.replace` calls it again with some changed)."""
    def wrap(method):
        signature = []   # (inspect.signature once, at the first call: not at import)

        @functools.wraps(method)
        def run(self, *args, **kwargs):
            n = len(self._elements)
            out = method(self, *args, **kwargs)
            if not signature:
                signature.append(inspect.signature(method))
            bound = signature[0].bind(self, *args, **kwargs)
            bound.apply_defaults()
            call = (method.__name__, dict(list(bound.arguments.items())[1:]))
            for e in self._elements[n:]:
                e.kind_name = kind
                e.call = call
            return out
        return run
    return wrap


#: the temperatures [degC] an expanding E-clutch's table spans (:meth:`Driveline.eclutch`): a dry clutch's linings
#: are destroyed long before its hottest end; a thermal mass leaving the span ends the run with an error
SHIFT_TEMPERATURES = (-50.0, 500.0)
#: an E-clutch's shift levels are added until the curve interpolated halfway between two of them is within this
#: fraction of its peak force of the axial model's own curve there (as close as the 161-point curve of an unshifted
#: clutch reads it)
SHIFT_TOLERANCE = 2e-4
#: the widest first spacing of the shift levels [m], and how many times an interval is halved at most
SHIFT_STEP, SHIFT_HALVINGS = 50e-6, 6


def _shifted_model(cm, s):
    """The axial model ``cm`` with its cushion pre-strain changed by ``s`` [m] (:func:`clutchlab.eclutch.dynamics.
    apply_wear_and_expansion`: wear ``-s`` where ``s < 0``, an expansion ``s`` where ``s > 0``)."""
    from ..eclutch.dynamics import apply_wear_and_expansion

    return apply_wear_and_expansion(cm, wear_m=max(-s, 0.0), temperature_rise_k=max(s, 0.0),
                                    expansion_coefficient=1.0, stack_height_m=1.0)


def _force(cm, u):
    return np.maximum(cm.static_curve(np.asarray(u, dtype=float))["normal_force_N"].to_numpy(), 0.0)


def _lift_off(name, cm, s, travel, points):
    """The release-bearing position [m] where the static curve of ``cm`` shifted by ``s`` reaches zero force: the
    first of ``points`` positions over ``[0, travel]`` with none, then narrowed three times between its neighbours
    (64 positions each: to 1e-5 of the spacing)."""
    m = _shifted_model(cm, s)
    u = np.linspace(0.0, travel, points)
    zero = np.flatnonzero(_force(m, u) <= 0.0)
    if not zero.size:
        raise ParameterError(f"{name}: at a working-point shift of {s * 1e6:.4g} um its static curve does not lift "
                             f"off within travel = {travel:g} m: choose a longer travel")
    if zero[0] == 0:
        raise ParameterError(f"{name}: at a working-point shift of {s * 1e6:.4g} um it is open at the engaged "
                             "position (worn through): lower wear_max")
    lo, hi = u[zero[0] - 1], u[zero[0]]
    for _ in range(3):
        uu = np.linspace(lo, hi, 65)
        j = int(np.flatnonzero(_force(m, uu) <= 0.0)[0])
        lo, hi = uu[j - 1], uu[j]
    return float(hi)


#: shift tables built in this process, by the hash of their axial model and span (:func:`_shift_table`); a sweep's
#: variants and an FMU export's parameter probes build the same network again and again
_SHIFT_TABLES: dict = {}
_SHIFT_TABLES_MAX = 16


def _shift_table(name, cm, travel, points, lo, hi):
    """The table of :func:`clutchlab.driveline.kernel.shifted_curve` for the axial model ``cm`` at shifts ``lo`` to
    ``hi`` [m]: ``(data, levels)`` (:func:`_build_shift_table`), kept for the same model, travel, points and span
    (0.5-1.5 s of static curves each)."""
    key = hashlib.sha1(pickle.dumps((cm, float(travel), int(points), float(lo), float(hi)))).hexdigest()
    if key not in _SHIFT_TABLES:
        if len(_SHIFT_TABLES) >= _SHIFT_TABLES_MAX:
            _SHIFT_TABLES.pop(next(iter(_SHIFT_TABLES)))
        _SHIFT_TABLES[key] = _build_shift_table(name, cm, travel, points, lo, hi)
    return _SHIFT_TABLES[key]


def _build_shift_table(name, cm, travel, points, lo, hi):
    """The table of :func:`clutchlab.driveline.kernel.shifted_curve` for the axial model ``cm`` at shifts ``lo`` to
    ``hi`` [m]: ``(data, levels)``.  Levels at most :data:`SHIFT_STEP` apart, each interval halved (up to
    :data:`SHIFT_HALVINGS` times) until the table's curve halfway is within :data:`SHIFT_TOLERANCE` of the peak
    force of the model's own there, on ``points`` positions over ``[0, travel]`` (kinks of the curve that move
    along the travel with the shift, not with its lift-off, need the halvings: Model 4's above about +50 um)."""
    n0 = max(2, int(math.ceil((hi - lo) / SHIFT_STEP)) + 1)
    levels = list(np.linspace(lo, hi, n0)) if hi > lo else [lo]
    lifts = {s: _lift_off(name, cm, s, travel, points) for s in levels}
    u = np.linspace(0.0, travel, points)

    def curve(s, grid):
        f = _force(_shifted_model(cm, s), lifts[s] + grid)
        f[-1] = 0.0
        return f

    peak = max(float(_force(_shifted_model(cm, s), [0.0])[0]) for s in (lo, hi))
    tol = SHIFT_TOLERANCE * peak
    todo = [(levels[i], levels[i + 1], 0) for i in range(len(levels) - 1)]
    while todo:
        a, b, depth = todo.pop()
        mid = 0.5 * (a + b)
        lifts[mid] = _lift_off(name, cm, mid, travel, points)
        lm = 0.5 * (lifts[a] + lifts[b])
        grid = np.linspace(-max(lifts[a], lifts[b]), 0.0, points)
        fa, fb = curve(a, grid), curve(b, grid)
        table = 0.5 * (np.interp(u - lm, grid, fa) + np.interp(u - lm, grid, fb))
        err = float(np.max(np.abs(table - _force(_shifted_model(cm, mid), u))))
        # (the floor: how closely the grid of distances reads each end's own curve; a kink of the curve between its
        # points is no matter of the levels, and halving them would not bring the middle closer than that)
        floor = max(float(np.max(np.abs(np.interp(u - lifts[q], grid, f) - _force(_shifted_model(cm, q), u))))
                    for q, f in ((a, fa), (b, fb)))
        if err > max(tol, 2.0 * floor) and depth < SHIFT_HALVINGS:
            levels.append(mid)
            todo += [(a, mid, depth + 1), (mid, b, depth + 1)]
        else:
            del lifts[mid]
    levels = sorted(levels)
    xi = np.linspace(-max(lifts[s] for s in levels), 0.0, points)
    rows = [curve(s, xi) for s in levels]
    data = (*levels, *(lifts[s] for s in levels), float(xi[0]), float(xi[1] - xi[0]), *np.concatenate(rows))
    return tuple(float(v) for v in data), len(levels)


def _shifted_liftoff(data, levels, s) -> float:
    """:func:`clutchlab.driveline.kernel.shifted_liftoff` in Python (for :meth:`Driveline.describe`)."""
    return float(np.interp(s, data[:levels], data[levels:2 * levels]))


class _LiveMap(tuple):
    """A friction map ``mu(|w|, T)`` read at the temperature of the element's heat port (:func:`clutchlab.driveline.
    kernel.friction_map`): its speeds, temperatures and values, one after the other; ``nt`` its temperatures."""

    def __new__(cls, values, nt):
        out = super().__new__(cls, values)
        out.nt = int(nt)
        return out


def _table_limit(table) -> str:
    """What a lossy gear's loss table (``table``: its columns one after the other) extrapolates to an efficiency <= 0
    beyond its last row: the message of its model error (:func:`clutchlab.driveline.kernel.table_error`)."""
    rows = np.asarray(table, dtype=float).reshape(5, -1).T
    w = rows[:, 0]
    where = []
    for col, label in ((1, "eta_mf1"), (2, "eta_mf2")):
        if len(w) >= 2:
            slope = (rows[-1, col] - rows[-2, col]) / (w[-1] - w[-2])
            if slope < 0.0:
                where.append(f"{label} reaches 0 at |w_a| = {w[-1] - rows[-1, col] / slope:.6g} rad/s")
    return (f"loss_table extrapolated beyond its last row (|w_a| = {w[-1]:.6g} rad/s, linear from the last two as "
            f"in MSL) gives an efficiency <= 0 ({', '.join(where) or 'no column'}), and the gear turned faster; give "
            "rows up to the speeds the run reaches")


class Driveline:
    """A driveline network: inertias, springs, dampers, backlash, gears, torque, speed and position sources,
    and friction elements (clutches, brakes, bearing friction, one-way clutches).

    Parameters
    ----------
    name : str
        Name of the model (shown in results and errors).
    domain : {"rotational", "translational"}
        Rotational (kg m^2, rad, rad/s, N m; columns ``phi_rad``, ``w_rad_s``, ``tau_Nm``) or translational
        (kg, m, m/s, N; columns ``s_m``, ``v_m_s``, ``f_N``; build with :meth:`mass` and :meth:`force`).  The
        elements and their equations are the same; a translational clutch's ``cgeo`` is 1 by default
        (force = fn * mu) and a gear is a lever.
    """

    def __init__(self, name: str = "driveline", domain: str = "rotational"):
        self.name = str(name)
        if domain not in DOMAINS:
            raise ParameterError(f"{self.name}: domain = {domain!r} (known: {', '.join(DOMAINS)})")
        self.domain = domain
        self._inertias: dict = {}
        self._elements: list = []
        self._inputs: dict = {}   # name -> (unit suffix, start value [SI], description)
        self._thermal: dict = {}  # name -> _ThermalMass (thermal_mass)
        self._links: list = []    # _ThermalLink (thermal_conductor)

    @property
    def _units(self):
        return DOMAINS[self.domain]

    # ---- inputs
    def input(self, name: str, unit: str = "1", start: float = 0.0, description: str = "") -> "Driveline":
        """Declare a network input ``name`` [``unit``, a column suffix of :data:`clutchlab.units.COLUMN_UNITS`:
        ``"Nm"``, ``"N"``, ``"1"``] starting at ``start`` (SI); a signal reads it with :meth:`Signal.input`.

        The input is a port of the network's :meth:`system`: held constant between two changes (a zero-order
        hold) by whatever drives it -- :meth:`simulate`'s ``inputs``, a co-simulation master or an FMU's importer
        (``DrivelineCoSimulation``, ``clutchlab export-fmu driveline``: an FMI input), a controller in
        :func:`clutchlab.control.closed_loop`, :func:`clutchlab.control.linearize` (its ``B`` and ``D`` columns).
        A change restarts the run: the stick/slip modes are decided again with the new value (a torque input that
        jumps beyond a stuck clutch's limit breaks it away at that instant).  Every declared input must drive
        something.
        """
        name = _word(f"{self.name}: input name", name)
        if name in self._inputs:
            raise ParameterError(f"{self.name}: input {name!r} is declared twice")
        if unit not in COLUMN_UNITS:
            raise ParameterError(f"{self.name}: input {name!r}: unit = {unit!r} is not a column unit "
                                 f"(e.g. Nm, N, 1, rad_s)")
        self._inputs[name] = (unit, _finite(f"input {name}", "start", start), str(description))
        return self

    def _input_starts(self) -> dict:
        return {n: v[1] for n, v in self._inputs.items()}

    @property
    def inputs(self) -> tuple:
        """The names of the network's inputs, in the order of its :meth:`system`'s ``u``."""
        return tuple(self._inputs)

    @property
    def input_units(self) -> dict:
        """Each network input's unit by name (a column suffix of :data:`clutchlab.units.COLUMN_UNITS`: ``"Nm"``,
        ``"1"``), in the order of :attr:`inputs`: its :meth:`system`'s input variables' units, without building it."""
        return {n: v[0] for n, v in self._inputs.items()}

    def _check_inputs(self) -> None:
        """Every input a signal reads is declared, and every declared input drives something."""
        used = set()
        for e in self._elements:
            for n in [*(e.signal.input_names() if e.signal is not None else ()), *_port_inputs(e)]:
                if n not in self._inputs:
                    known = ", ".join(self._inputs) or "none declared"
                    raise ParameterError(f"{e.name}: reads input {n!r}, which {self.name!r} does not declare "
                                         f"(inputs: {known})")
                used.add(n)
        unused = [n for n in self._inputs if n not in used]
        if unused:
            raise ParameterError(f"{self.name}: input {unused[0]!r} drives nothing (a signal reads it with "
                                 "Signal.input; or remove it)")

    def with_inputs(self, values: dict) -> "Driveline":
        """A copy of this network whose inputs named in ``values`` are replaced by signals: a number (held from
        t = 0), a :class:`Signal`, or ``(times, values)`` (a :meth:`Signal.table`); the others stay inputs."""
        signals = {}
        for n, v in dict(values).items():
            if n not in self._inputs:
                known = ", ".join(self._inputs) or "none"
                raise ParameterError(f"{self.name}: inputs: {n!r} is not an input of the network (inputs: {known})")
            if isinstance(v, tuple) and len(v) == 2:
                v = Signal.table(*v)
            signals[n] = Signal.of(v, f"{self.name}: inputs[{n!r}]")
        out = copy.copy(self)
        out._elements = [copy.copy(e) for e in self._elements]
        for e in out._elements:
            if _port_inputs(e):
                ports = {q: (None if v is None else v.with_inputs(signals)) for q, v in e.emtc["ports"].items()}
                e.emtc = dict(e.emtc, ports=ports)
            if e.signal is not None and e.signal.input_names():
                e.signal = e.signal.with_inputs(signals)
                if e.kind == K.K_MOTION:
                    _check_motion_signal(e.name, "speed" if e.law == K.MOTION_SPEED else "position", e.signal)
        out._inputs = {n: v for n, v in self._inputs.items() if n not in signals}
        return out

    # ---- components
    def _new_name(self, name):
        _word(f"{self.name}: component name", name)
        if name == GROUND or name in self._inertias or any(e.name == name for e in self._elements) or \
                name in self._thermal or any(link.name == name for link in self._links):
            raise ParameterError(f"{self.name}: component name {name!r} is used twice")
        return name

    def _flange(self, component, which, flange):
        if flange is None or flange == GROUND:
            return None
        if flange not in self._inertias:
            known = ", ".join(self._inertias) or "none"
            raise ParameterError(f"{component}: {which} = {flange!r} is not an inertia of {self.name!r} "
                                 f"(inertias: {known}; 'ground' for the fixed ground)")
        return flange

    def _two(self, name, a, b):
        a = self._flange(name, "flange a", a)
        b = self._flange(name, "flange b", b)
        if a == b:
            raise ParameterError(f"{name}: both flanges are {a or GROUND!r} (an element needs two different flanges)")
        return a, b

    def inertia(self, name: str, J: float, w0: float | None = None, phi0: float | None = None) -> "Driveline":
        """A rigid inertia ``J`` [kg m^2] starting at angle ``phi0`` [rad] and speed ``w0`` [rad/s].

        Left out, ``w0`` follows from the gears and motion sources that bind this inertia to another one
        (0 without any), ``phi0`` from a position source (0 without one); given, they must agree with them.
        """
        if self.domain != "rotational":
            raise ParameterError(f"{name}: a translational driveline has masses (mass(name, m, v0, s0)), not inertias")
        return self._body(name, (J, w0, phi0), ("J", "w0", "phi0"))

    def mass(self, name: str, m: float, v0: float | None = None, s0: float | None = None) -> "Driveline":
        """A rigid mass ``m`` [kg] starting at position ``s0`` [m] and speed ``v0`` [m/s] (translational
        drivelines; as :meth:`inertia`)."""
        if self.domain != "translational":
            raise ParameterError(f"{name}: a rotational driveline has inertias (inertia(name, J, w0, phi0)), not masses")
        return self._body(name, (m, v0, s0), ("m", "v0", "s0"))

    def _body(self, name, values, labels):
        name = self._new_name(name)
        J, w0, phi0 = values
        self._inertias[name] = (_finite(name, labels[0], J, positive=True),
                                None if w0 is None else _finite(name, labels[1], w0),
                                None if phi0 is None else _finite(name, labels[2], phi0))
        return self

    @_adds("force")
    def force(self, name: str, flange, signal, support=None) -> "Driveline":
        """A force source [N] pushing ``flange`` (translational drivelines; as :meth:`torque`)."""
        if self.domain != "translational":
            raise ParameterError(f"{name}: a rotational driveline has torque sources (torque(...)), not forces")
        return self.torque(name, flange, signal, support)

    @_adds("spring_damper")
    def spring_damper(self, name: str, a, b, c: float = 0.0, d: float = 0.0, phi_rel0: float = 0.0) -> "Driveline":
        """Spring ``c`` [N m/rad] and damper ``d`` [N m s/rad] in parallel between flanges a and b
        (``tau = c (phi_b - phi_a - phi_rel0) + d (w_b - w_a)``)."""
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        self._elements.append(_Element(K.K_SPRING, name, a, b, (_finite(name, "c", c, nonneg=True),
                                                                 _finite(name, "d", d, nonneg=True),
                                                                 _finite(name, "phi_rel0", phi_rel0), 0.0)))
        return self

    @_adds("spring")
    def spring(self, name: str, a, b, curve, d: float = 0.0, phi_rel0: float = 0.0) -> "Driveline":
        """A nonlinear spring and a damper ``d`` [N m s/rad] in parallel between flanges a and b:
        ``tau = curve(phi_b - phi_a - phi_rel0) + d (w_b - w_a)``.

        ``curve``: a :class:`~clutchlab.curves.Curve` (deflection [rad], torque [N m]; piecewise linear or
        monotone cubic, extrapolated with its end slopes -- an ``extrapolation="error"`` curve is refused)
        or rows ``[[phi_rad, tau_Nm], ...]`` (piecewise linear).  The stored energy is the exact integral
        of the curve, so the energy balance holds for any curve.
        """
        from ..curves import Curve

        name = self._new_name(name)
        a, b = self._two(name, a, b)
        if not isinstance(curve, Curve):
            arr = as_numbers(curve, f"{name}: curve") if not isinstance(curve, (str, bytes)) else np.empty(0)
            if arr.ndim != 2 or arr.shape[1] != 2:
                raise ParameterError(f"{name}: curve must be a Curve or rows [[phi_rad, tau_Nm], ...]")
            curve = Curve(arr[:, 0], arr[:, 1], name=name)
        if curve.extrapolation != "linear":
            raise ParameterError(f"{name}: curve {curve.name!r} has extrapolation={curve.extrapolation!r}; a "
                                 "driveline spring needs 'linear' (it may be deflected beyond its points)")
        xs, fs, ds, kind, _ext = curve.kernel_data()
        cs = _curve_integrals(xs, fs, ds, kind)
        m = xs.size
        cs = cs - _curve_energy_py(np.concatenate([xs, fs, ds, cs]), m, kind, 0.0)   # stored energy 0 at phi = 0
        table = tuple(xs) + tuple(fs) + tuple(ds) + tuple(cs)
        self._elements.append(_Element(K.K_SPRING, name, a, b, (0.0, _finite(name, "d", d, nonneg=True),
                                                                 _finite(name, "phi_rel0", phi_rel0), 0.0),
                                       law=K.SPRING_CURVE, table=table, aux=int(kind)))
        return self

    @_adds("backlash")
    def backlash(self, name: str, a, b, c: float, b_gap: float, d: float = 0.0, phi_rel0: float = 0.0,
                 damping_law: str = "kelvin_voigt") -> "Driveline":
        """A spring-damper behind a gap between flanges a and b (as MSL ``ElastoBacklash``): no torque in the
        gap ``|phi_b - phi_a - phi_rel0| < b_gap / 2``; in contact ``c`` [N m/rad] on the deflection past the
        gap's edge, ``tau_c``, and ``d`` [N m s/rad] on the relative speed, ``tau_d``.  ``c`` > 0, ``b_gap``
        [rad] > 0 (without a gap, use :meth:`spring_damper`).

        ``damping_law``: ``"kelvin_voigt"`` (default): ``tau = tau_c + tau_d``; contact begins at the edge (the
        damping torque steps in with the impact speed) and ends when the torque would pull; both are located
        events, ``contact`` and ``separate``.  A damped contact separates beyond its edge, moving back: it is
        released there (modes ``upper_released`` / ``lower_released``; the spring's energy stays stored and goes
        to its damper as the deflection falls back to the edge) until it reaches the edge or its torque pushes
        again (``contact``, beyond the edge).  ``"msl"``:
        MSL ``ElastoBacklash``'s law, ``tau = tau_c + min(tau_c, tau_d)`` beyond the upper edge and 0 where
        ``tau_c + tau_d <= 0`` (mirrored below), so the torque is continuous at impact and never pulls; its
        kinks are located events (no names), ``contact`` and ``separate`` are at the edge.  Its dissipation is
        the damping share ``(tau - tau_c) w_rel`` (MSL's ``lossPower`` is zero where the contact is unloaded;
        here the spring relaxes through its damper, so the energy balance closes).  Without damping the two
        laws are the same."""
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        gap = _finite(name, "b_gap", b_gap, positive=True)
        laws = {"kelvin_voigt": K.LASH_KELVIN_VOIGT, "msl": K.LASH_MSL}
        if damping_law not in laws:
            raise ParameterError(f"{name}: damping_law = {damping_law!r} (known: {', '.join(map(repr, laws))})")
        d = _finite(name, "d", d, nonneg=True)
        self._elements.append(_Element(K.K_SPRING, name, a, b, (_finite(name, "c", c, positive=True), d,
                                                                 _finite(name, "phi_rel0", phi_rel0), gap),
                                       law=K.SPRING_BACKLASH,
                                       aux=laws[damping_law] if d > 0.0 else K.LASH_KELVIN_VOIGT))
        return self

    @_adds("gear")
    def gear(self, name: str, a, b, ratio: float, efficiency: float = 1.0, loss_table=None,
             support=None) -> "Driveline":
        """A gear between flanges a and b on a support (MSL ``IdealGear``, ``LossyGear``): ``phi_a - phi_s = ratio
        (phi_b - phi_s)``.

        Ideal (``efficiency`` 1, no ``loss_table``): the torque on flange b is ``-ratio`` times the torque on flange
        a.  Lossy: MSL ``LossyGear`` (Pelchen, Otter and Schweiger 2002), a friction element whose relative speed
        is ``w_a - w_s``: rolling, ``flange_b.tau = -ratio (flange_a.tau - tauLoss)`` with the loss torque of its
        quadrant (mesh efficiency ``eta_mf1`` while flange a drives, ``eta_mf2`` while b drives, bearing friction
        ``tau_bf1``, ``tau_bf2``); at rest it is stuck while the loss torque it must hold lies within the band of
        its quadrants at zero speed, and rolls forward or backward (events ``forward``, ``backward``, ``stick``;
        ``a_drives``, ``b_drives`` when the driving flange changes) when it leaves it.  Self-locking (a worm gear
        with a small ``eta_mf2``) follows from those equations: no efficiency is refused.

        Parameters
        ----------
        name, a, b : str
            The gear and its flanges (inertias; "ground" for none).
        ratio : float
            ``w_a / w_b`` against the support [-], != 0 (negative reverses).
        efficiency : float
            Constant mesh efficiency in (0, 1] for both directions [-] (MSL ``lossTable = [0, eta, eta, 0, 0]``).
        loss_table : array_like, optional
            MSL ``lossTable``: rows ``[|w_a| rad/s, eta_mf1, eta_mf2, tau_bf1 N m, tau_bf2 N m]``, ``|w_a|``
            increasing from 0, linear between rows and extrapolated from the last two, within ``eta <= 1`` and
            ``tau_bf >= 0`` (an efficiency extrapolated to 0 or below ends a run with a model error naming the
            gear); give it or ``efficiency``.
        support : str, optional
            The inertia the gear's housing is (MSL ``useSupport``; its reaction torque acts there); default the
            ground.

        Gears and motion sources may not close a loop (the network would be over-constrained); the initial speeds
        of the inertias they bind follow from one of them.
        """
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        sup = self._flange(name, "support", support)
        if sup is not None and sup in (a, b):
            raise ParameterError(f"{name}: support = {sup!r} is also one of its flanges")
        ratio = _finite(name, "ratio", ratio)
        if ratio == 0.0:
            raise ParameterError(f"{name}: ratio = 0 (a gear needs a ratio != 0)")
        if loss_table is not None:
            if efficiency != 1.0:
                raise ParameterError(f"{name}: give efficiency or loss_table, not both")
            try:
                rows = np.asarray(loss_table, dtype=float)
            except (TypeError, ValueError):
                raise ParameterError(f"{name}: loss_table = {loss_table!r} must be rows of 5 numbers "
                                     "[w_rad_s, eta_mf1, eta_mf2, tau_bf1_Nm, tau_bf2_Nm]") from None
            if rows.ndim != 2 or rows.shape[1] != 5 or rows.shape[0] < 1 or not np.all(np.isfinite(rows)):
                raise ParameterError(f"{name}: loss_table must be rows of 5 finite numbers [w_rad_s, eta_mf1, eta_mf2, "
                                     f"tau_bf1_Nm, tau_bf2_Nm], got shape {rows.shape}")
            if rows[0, 0] < 0.0 or np.any(np.diff(rows[:, 0]) <= 0):
                raise ParameterError(f"{name}: loss_table speeds {rows[:, 0].tolist()} must start at >= 0 and increase")
            bad = rows[(rows[:, 1] <= 0) | (rows[:, 1] > 1) | (rows[:, 2] <= 0) | (rows[:, 2] > 1)]
            if bad.size:
                raise ParameterError(f"{name}: loss_table efficiencies must be in (0, 1], got row {bad[0].tolist()}")
            if np.any(rows[:, 3:] < 0):
                raise ParameterError(f"{name}: loss_table bearing friction torques must be >= 0")
            ideal_mesh = (rows[:, 1] == 1.0) & (rows[:, 2] == 1.0) & (rows[:, 3] != rows[:, 4])
            if np.any(ideal_mesh):
                raise ParameterError(
                    f"{name}: loss_table row {rows[ideal_mesh][0].tolist()}: with both efficiencies 1 the bearing "
                    "friction cannot be split between the sides (MSL halves tau_bf1, which makes the torque jump where "
                    "the driving side changes): give tau_bf1 = tau_bf2 there, or an efficiency below 1")
        else:
            eta = _finite(name, "efficiency", efficiency, positive=True)
            if not 0.0 < eta <= 1.0:
                raise ParameterError(f"{name}: efficiency = {eta!r} must be in (0, 1]")
            rows = np.array([[0.0, eta, eta, 0.0, 0.0]])
        table = tuple(rows.T.ravel())
        self._elements.append(_Element(K.K_GEAR, name, a, b, (ratio,), table=table, sup=sup))
        return self

    @_adds("planetary")
    def planetary(self, name: str, sun, carrier, ring, ratio: float, efficiency: float = 1.0,
                  loss_table=None) -> "Driveline":
        """A planetary gear set (MSL ``IdealPlanetary``): ``(1 + ratio) w_carrier = w_sun + ratio w_ring``, ``tau_ring
        = ratio tau_sun``, ``tau_carrier = -(1 + ratio) tau_sun``, ``ratio`` the ring's teeth over the sun's.

        It is the :meth:`gear` that the set is in its carrier's frame (Willis): flange a the sun, flange b the ring,
        the carrier its support, the stationary ratio ``(w_sun - w_c) / (w_ring - w_c) = -ratio``; so a held member
        (a brake on the sun, the carrier on the ground) and a clutch that locks two members together give a
        transmission's gears, and its losses are MSL ``LossyGear``'s in the carrier's frame (``efficiency`` the
        stationary train's, Pelchen, Otter and Schweiger 2002).  Its columns are the gear's: ``<name>.tau_Nm`` the
        torque on the sun (the ring's ``ratio`` times it, the carrier's ``-(1 + ratio)`` times it, when ideal),
        ``<name>.mode_1`` and ``<name>.dissipated_J`` with losses.

        Parameters
        ----------
        name, sun, carrier, ring : str
            The set and its three members' inertias ("ground" for a member held fixed).
        ratio : float
            Ring teeth over sun teeth [-], > 1 (MSL's ``ratio = 100/50``).
        efficiency, loss_table
            As :meth:`gear`'s, in the carrier's frame.
        """
        if self.domain != "rotational":
            raise ParameterError(f"{name}: a planetary gear set belongs to a rotational network")
        ratio = _finite(name, "ratio", ratio, positive=True)
        if ratio <= 1.0:
            raise ParameterError(f"{name}: ratio = {ratio:g}: a planetary set's ring has more teeth than its sun "
                                 "(ratio = ring teeth / sun teeth > 1)")
        return self.gear(name, sun, ring, -ratio, efficiency=efficiency, loss_table=loss_table, support=carrier)

    @_adds("torque_converter")
    def torque_converter(self, name: str, a, b, table, coast_table=None, support=None,
                         k_scale: float = 1.0) -> "Driveline":
        """A hydrodynamic torque converter: impeller on flange a, turbine on flange b, the stator's one-way clutch on
        a support (:func:`clutchlab.driveline.kernel.converter_torques`).

        Driving (``|w_p| >= |w_t|``, speeds against the support): impeller torque ``T_p = w_p |w_p| / K(SR)^2`` and
        turbine torque ``T_t = TR(SR) T_p`` at the speed ratio ``SR = w_t / w_p`` (capacity factor ``K`` and torque
        ratio ``TR``, SAE J643), the stator's reaction ``T_p - T_t`` on the support.  Coasting (the turbine faster)
        the stator free-wheels: ``TR = 1`` and ``K`` from ``coast_table`` at ``w_p / w_t`` (default the drive
        table's).  From the table's last speed ratio to 1 the capacity ``1/K^2`` falls linearly to 0 (no torque
        without slip).  The law is continuous at every pair of speeds, at rest included; its loss ``T_p w_p - T_t
        w_t`` (columns ``<name>.loss_power_W``, ``<name>.dissipated_J``) is >= 0.  A lock-up clutch is a
        :meth:`clutch` between the same flanges.

        Parameters
        ----------
        name, a, b : str
            The converter, its impeller's and its turbine's inertias.
        table : array_like
            Rows ``[SR, K, TR]``: speed ratio in [0, 1), increasing from its first row; capacity factor ``K`` > 0
            [rad/s/sqrt(N m)] (``K [rpm/sqrt(N m)] * pi/30``); torque ratio ``TR`` > 0, with ``TR SR <= 1`` at every
            speed ratio (the converter never generates power) and ``TR <= 1`` in the last row.
        coast_table : array_like, optional
            Rows ``[w_p / w_t, K]`` of the coast mode, as ``table``'s first two columns.
        support : str, optional
            The housing's inertia (the stator's reaction acts there); default the ground.
        k_scale : float
            Factor on both tables' ``K`` [-], > 0: a looser (> 1) or tighter converter, matched to an engine by a
            sweep or an FMU host (the torques scale with ``1/k_scale^2``).
        """
        if self.domain != "rotational":
            raise ParameterError(f"{name}: a torque converter belongs to a rotational network")
        k_scale = _finite(name, "k_scale", k_scale, positive=True)
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        sup = self._flange(name, "support", support)
        if sup is not None and sup in (a, b):
            raise ParameterError(f"{name}: support = {sup!r} is also one of its flanges")
        drive = _converter_table(name, "table", table, 3)
        sr, tr = drive[:, 0], drive[:, 2]
        # TR SR <= 1 on every segment: a product of two linear functions, largest at an end or at its vertex
        for lo in range(len(sr) - 1):
            s0, s1, t0, t1 = sr[lo], sr[lo + 1], tr[lo], tr[lo + 1]
            slope = (t1 - t0) / (s1 - s0)
            probes = [s0, s1]
            if slope < 0.0:
                vertex = 0.5 * (slope * s0 - t0) / slope
                if s0 < vertex < s1:
                    probes.append(vertex)
            for v in probes:
                if (t0 + slope * (v - s0)) * v > 1.0 + 1e-12:
                    raise ParameterError(f"{name}: table: TR * SR = {(t0 + slope * (v - s0)) * v:.6g} > 1 at SR = "
                                         f"{v:.6g}: the converter would generate power (its efficiency TR SR is at "
                                         "most 1)")
        if tr[-1] > 1.0:
            raise ParameterError(f"{name}: table: TR = {tr[-1]:g} > 1 in its last row (held up to SR = 1, where the "
                                 "efficiency TR SR must stay <= 1)")
        coast = () if coast_table is None else _converter_table(name, "coast_table", coast_table, 2)
        data = tuple(drive.T.ravel()) + (() if coast_table is None else tuple(coast.T.ravel()))
        self._elements.append(_Element(K.K_CONVERTER, name, a, b, (k_scale,), table=data, sup=sup,
                                       aux=0 if coast_table is None else len(coast)))
        return self

    @staticmethod
    def _is_lossy(e) -> bool:
        """A gear with losses (its loss table is not MSL's ideal ``[0, 1, 1, 0, 0]``).  Efficiencies within
        :data:`ETA_IDEAL` of 1 without bearing friction are ideal: such a gear's stuck band, ``2 (1 - eta)`` of the
        torque it carries, would be narrower than the rounding floor of its stick/slip decisions (``kernel.NOISE``,
        1e-12 of the torques), so that every decision on it is a rounding (random draws seed 2226: a gear of
        efficiency 1 - 1.1e-16 in a stuck loop, whose run stopped advancing at 0.795 s)."""
        if e.kind != K.K_GEAR:
            return False
        n = len(e.table) // 5
        t = np.asarray(e.table).reshape(5, n)
        return not (np.all(t[1:3] >= 1.0 - ETA_IDEAL) and np.all(t[3:] == 0.0))

    @property
    def _lossy(self) -> list:
        """The gears with losses, in mode order."""
        return [e for e in self._elements if self._is_lossy(e)]

    def _motion(self, name, flange, signal, law, what):
        name = self._new_name(name)
        b = self._flange(name, "flange", flange)
        if b is None:
            raise ParameterError(f"{name}: a {what} source needs an inertia as its flange, not the ground")
        sig = Signal.of(signal, f"{name}: {what}")
        _check_motion_signal(name, what, sig)
        self._elements.append(_Element(K.K_MOTION, name, None, b, law=law, signal=sig))
        return self

    @_adds("speed")
    def speed(self, name: str, flange, signal) -> "Driveline":
        """A speed source (MSL ``Speed`` with ``exact = true``): ``flange`` turns at ``signal(t)`` [rad/s]
        against the ground, whatever torque it takes (reported as the source's torque).  The signal must
        be continuous (a constant, ramp, table, or a sine starting at zero); its initial value is the
        flange's initial speed."""
        return self._motion(name, flange, signal, K.MOTION_SPEED, "speed")

    @_adds("position")
    def position(self, name: str, flange, signal) -> "Driveline":
        """A position source (MSL ``Position`` with ``exact = true``): ``flange`` follows ``signal(t)`` [rad].
        The signal must have a continuous speed: a constant or a sine starting at t = 0; its value and
        rate at 0 are the flange's initial angle and speed.  (For a ramp or table, prescribe the speed.)"""
        return self._motion(name, flange, signal, K.MOTION_POSITION, "position")

    def _source_flanges(self, name, flange, support):
        """A torque source's support and flange, ``(a, b)``: the flange an inertia, the support another or the
        ground."""
        b = self._flange(name, "flange", flange)
        if b is None:
            raise ParameterError(f"{name}: a torque source needs an inertia as its flange, not the ground")
        a = self._flange(name, "support", support)
        if a == b:
            raise ParameterError(f"{name}: flange and support are both {a!r}")
        return a, b

    @_adds("torque")
    def torque(self, name: str, flange, signal, support=None) -> "Driveline":
        """A torque source [N m] accelerating ``flange`` (its reaction on ``support``, default the ground)."""
        name = self._new_name(name)
        a, b = self._source_flanges(name, flange, support)
        self._elements.append(_Element(K.K_SOURCE, name, a, b, signal=Signal.of(signal, f"{name}: torque")))
        return self

    @_adds("speed_torque")
    def speed_torque(self, name: str, flange, tau_nominal: float, w_nominal: float, law: str = "quadratic",
                     torque_direction: bool = True, support=None) -> "Driveline":
        """A torque that depends on the flange's speed ``w`` against ``support`` (MSL ``Sources.
        LinearSpeedDependentTorque``, ``QuadraticSpeedDependentTorque``): accelerating ``tau_nominal |w /
        w_nominal|^k`` (``k`` 1 for ``law="linear"``, 2 for ``"quadratic"``) with ``torque_direction`` (MSL's
        ``TorqueDirection``: the same direction both ways round), else ``tau_nominal sign(w) |w / w_nominal|^k``.
        A negative ``tau_nominal`` is a load in positive rotation (a fan, a vehicle's air drag); its work is the
        source's ``work_J`` (negative for a load).

        Parameters
        ----------
        name, flange : str
            The source and the inertia it acts on.
        tau_nominal : float
            Torque at the nominal speed [N m].
        w_nominal : float
            Nominal speed [rad/s], > 0.
        law : str
            ``"linear"`` or ``"quadratic"``.
        torque_direction : bool
            The same direction of torque in both directions of rotation (MSL's default).
        support : str, optional
            The inertia the reaction acts on; default the ground.
        """
        name = self._new_name(name)
        a, b = self._source_flanges(name, flange, support)
        laws = {"linear": 1.0, "quadratic": 2.0}
        if law not in laws:
            raise ParameterError(f"{name}: law = {law!r} (known: 'linear', 'quadratic')")
        coef = (_finite(name, "tau_nominal", tau_nominal), _finite(name, "w_nominal", w_nominal, positive=True),
                laws[law], 1.0 if torque_direction else 0.0)
        self._elements.append(_Element(K.K_SOURCE, name, a, b, coef, K.SOURCE_SPEED, model=law))
        return self

    @_adds("engine")
    def engine(self, name: str, flange, torque_map, throttle=1.0, idle_speed: float | None = None,
               idle_kp: float = 2.0, idle_ki: float = 20.0, idle_torque_max: float = 50.0, support=None) -> "Driveline":
        """A combustion engine driving ``flange`` (its crankshaft inertia; reaction on ``support``, default ground).

        Torque ``T = map(w, throttle(t)) + T_idle`` [N m], ``w`` the crankshaft speed against the support.
        ``torque_map``: ``(speeds [rad/s], throttles [-], torques [N m] of shape (speeds, throttles))``, bilinear,
        held beyond the grids (full load at throttle 1, the drag torque, negative, at throttle 0); or a table
        ``[[w_rad_s, N m], ...]`` of the full-load curve, scaled by the throttle.  ``throttle``: a signal (0-1).
        ``idle_speed`` [rad/s]: the set speed of an idle-speed PI controller, ``T_idle = clip(idle_kp (w_idle -
        w) + I, 0, idle_torque_max)`` with ``dI/dt = idle_ki (w_idle - w)`` and back-calculation anti-windup (its
        integral ``I`` is a state, ``<name>.idle_integral_Nm``); None: no controller.  Gains in N m s/rad and N m/rad.
        """
        name = self._new_name(name)
        a, b = self._two(name, support, flange)
        if isinstance(torque_map, tuple) and len(torque_map) == 3:
            ws, th, tq = (as_numbers(v, f"{name}: torque_map {what}")
                          for v, what in zip(torque_map, ("speeds", "throttles", "torques")))
        else:
            rows = as_numbers(torque_map, f"{name}: torque_map")
            if rows.ndim != 2 or rows.shape[1] != 2:
                raise ParameterError(f"{name}: torque_map must be (speeds, throttles, torques) or rows [w_rad_s, N m]")
            ws, th = rows[:, 0], np.array([0.0, 1.0])
            tq = np.column_stack([np.zeros(len(rows)), rows[:, 1]])
        ws, th, tq = np.atleast_1d(ws), np.atleast_1d(th), np.atleast_2d(tq)
        if tq.shape != (ws.size, th.size):
            raise ParameterError(f"{name}: torque_map torques have shape {tq.shape}, expected (speeds, throttles) = "
                                 f"({ws.size}, {th.size})")
        for what, grid in (("speeds", ws), ("throttles", th)):
            if grid.size < 1 or not np.all(np.isfinite(grid)) or np.any(np.diff(grid) <= 0):
                raise ParameterError(f"{name}: torque_map {what} must be finite and strictly increasing")
        if not np.all(np.isfinite(tq)):
            raise ParameterError(f"{name}: torque_map torques must be finite")
        if idle_speed is None:
            coef = (0.0, 0.0, 0.0, 0.0)
        else:
            coef = (_finite(name, "idle_speed", idle_speed, positive=True), _finite(name, "idle_kp", idle_kp, nonneg=True),
                    _finite(name, "idle_ki", idle_ki, nonneg=True),
                    _finite(name, "idle_torque_max", idle_torque_max, positive=True))
        el = _Element(K.K_SOURCE, name, a, b, coef, K.SOURCE_ENGINE, Signal.of(throttle, f"{name}: throttle"),
                      tuple(ws) + tuple(th) + tuple(tq.ravel()), th.size)
        el.model = (f"engine map {ws.size} x {th.size} (speed x throttle)"
                    + ("" if idle_speed is None else f", idle controller at {idle_speed:g} rad/s"))
        self._elements.append(el)
        return self

    @property
    def _controllers(self) -> list:
        """The elements with a controller state (engines with an idle controller), in state order."""
        return [e for e in self._elements if e.kind == K.K_SOURCE and e.law == K.SOURCE_ENGINE and e.coef[3] > 0]

    def _friction(self, name, a, b, law, table, peak, fn_max=1.0, cgeo=1.0, normal=None, mu_temperature=None,
                  mu_scale=1.0):
        peak = _finite(name, "peak", peak)
        if peak < 1.0:
            raise ParameterError(f"{name}: peak = {peak!r} must be >= 1 (static limit = peak x sliding torque at rest)")
        coef = (_finite(name, "fn_max", fn_max, nonneg=True), _finite(name, "cgeo", cgeo, nonneg=True), peak, 0.0,
                0.0, self._mu_scale(name, mu_scale))
        sig = None if normal is None else Signal.of(normal, f"{name}: normal")
        map_t = table.nt if isinstance(table, _LiveMap) else 0
        if map_t and mu_temperature is not None:
            raise ParameterError(f"{name}: a friction map read at its heat port's temperature already depends on it; "
                                 "mu_temperature would count the temperature twice")
        self._elements.append(_Element(K.K_FRICTION, name, a, b, coef, law, sig, tuple(table),
                                       fade=self._fade(name, mu_temperature), map_t=map_t))
        return self

    @staticmethod
    def _fade(name, rows):
        """A factor over temperature, rows ``[[T_degC, factor], ...]`` (T increasing, factor >= 0), as (temperatures,
        factors); ``()`` for none."""
        if rows is None:
            return ()
        arr = as_numbers(rows, f"{name}: mu_temperature")
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1 or not np.all(np.isfinite(arr)):
            raise ParameterError(f"{name}: mu_temperature must be a table of rows [T_degC, factor]")
        if np.any(np.diff(arr[:, 0]) <= 0) or np.any(arr[:, 1] < 0) or np.any(arr[:, 0] <= ABSOLUTE_ZERO_C):
            raise ParameterError(f"{name}: mu_temperature must increase in T (above {ABSOLUTE_ZERO_C} degC) with "
                                 f"factors >= 0 (got {arr.tolist()!r})")
        return tuple(float(v) for v in arr[:, 0]) + tuple(float(v) for v in arr[:, 1])

    @staticmethod
    def _characteristic(name, what, value):
        """A constant or a table ``[[w, value], ...]`` (w >= 0 increasing) as (speeds, values)."""
        if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
            return (0.0, _finite(name, what, value, nonneg=True))
        arr = as_numbers(value, f"{name}: {what}")
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1 or not np.all(np.isfinite(arr)):
            raise ParameterError(f"{name}: {what} must be a number or a table of rows [w_rad_s, value]")
        if arr[0, 0] != 0.0 or np.any(np.diff(arr[:, 0]) <= 0) or np.any(arr[:, 1] < 0):
            raise ParameterError(f"{name}: {what} table must start at w = 0, increase in w and be >= 0")
        return tuple(arr[:, 0]) + tuple(arr[:, 1])

    @_adds("clutch")
    def clutch(self, name: str, a, b, fn_max: float, mu=0.5, peak: float = 1.0, cgeo: float = 1.0,
               normal=1.0, radius: float | None = None, temperature: float | None = None,
               mu_scale: float = 1.0, mu_temperature=None) -> "Driveline":
        """A clutch between flanges a and b (MSL ``Clutch``): sliding torque ``cgeo fn mu(|w_rel|)``,
        ``fn = fn_max * normal(t)`` [N] (free when ``<= 0``), static limit ``peak`` times the sliding
        torque at rest.  ``mu``: a number, a table ``[[w_rad_s, mu], ...]`` (linear between rows, extrapolated
        from the last two but never below 0), or a friction map
        ``mu(v, T)`` identified by :mod:`clutchlab.wet` (:class:`clutchlab.wet.friction.FrictionMap`) read
        at the slip velocity ``v = radius |w_rel|`` [m/s] and the constant friction-surface ``temperature``
        [degC] (``radius`` required with a map, both refused without one; :meth:`_map_characteristic`); without
        ``temperature`` the map is read at the temperature of the thermal mass the clutch's losses heat, as the
        run heats it (:func:`~clutchlab.driveline.kernel.friction_map`; it must heat one).  ``mu_scale``:
        a factor on the friction coefficient, whether a number, a table or a map (a sweep's friction level;
        ``mu_scale`` in [0, 2], a factor on a coefficient checked on its own).  ``mu_temperature``: rows
        ``[[T_degC, factor], ...]``, a factor on the sliding torque and the static limit over the temperature of the
        thermal mass its losses heat (linear between rows, held beyond them; fade): the element must be in that
        mass's ``heat_from`` (:meth:`thermal_mass`)."""
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        return self._friction(name, a, b, K.LAW_CLUTCH, self._mu(name, mu, radius, temperature), peak,
                              fn_max, cgeo, normal, mu_temperature, mu_scale)

    @_adds("brake")
    def brake(self, name: str, flange, fn_max: float, mu=0.5, peak: float = 1.0, cgeo: float = 1.0,
              normal=1.0, support=None, radius: float | None = None,
              temperature: float | None = None, mu_scale: float = 1.0, mu_temperature=None) -> "Driveline":
        """A brake between ``flange`` and ``support`` (default the ground), as :meth:`clutch` (MSL ``Brake``)."""
        name = self._new_name(name)
        a, b = self._two(name, support, flange)
        return self._friction(name, a, b, K.LAW_CLUTCH, self._mu(name, mu, radius, temperature), peak,
                              fn_max, cgeo, normal, mu_temperature, mu_scale)

    @classmethod
    def _mu(cls, name, mu, radius, temperature):
        """A clutch's or brake's friction characteristic: a number or table, or a map with its radius and
        temperature (its factor ``mu_scale`` is a column of its own: :meth:`_mu_scale`)."""
        # a FrictionMap exists only once its module is imported: not importing the wet package for a plain clutch
        # keeps a driveline file's start-up short (the package imports SciPy's special functions, 0.13 s)
        friction = sys.modules.get("clutchlab.wet.friction")
        if friction is not None and isinstance(mu, friction.FrictionMap):
            return cls._map_characteristic(name, mu, radius, temperature)
        for what, value in (("radius", radius), ("temperature", temperature)):
            if value is not None:
                raise ParameterError(f"{name}: {what} = {value!r} is for a friction map mu(v, T); mu is "
                                     f"{type(mu).__name__}")
        return cls._characteristic(name, "mu", mu)

    @staticmethod
    def _mu_scale(name, scale):
        """A friction element's factor on its friction coefficient, in [0, 2]: a sensitivity factor on a coefficient
        checked on its own (so a value in each declared range is taken together, as a sweep or an FMU's importer
        expects), kept in a column of its own (``kernel.C_MU_SCALE``: the sliding torque multiplies it), not
        multiplied into the characteristic, so a native FMU's host sets it and the coefficient alike."""
        from ..params.base import MU_SCALE_MAX

        scale = _finite(name, "mu_scale", scale, nonneg=True)
        if scale > MU_SCALE_MAX:
            raise ParameterError(f"{name}: mu_scale = {scale:g} is above {MU_SCALE_MAX:g} (a factor on a friction "
                                 "coefficient, not a coefficient)")
        return scale

    @staticmethod
    def _map_characteristic(name, fmap, radius, temperature):
        """The characteristic ``mu(|w|)`` of a friction map ``mu(v, T)`` (:class:`clutchlab.wet.friction.FrictionMap`,
        bilinear, constant beyond its grids) at ``v = radius |w|`` and a constant ``temperature`` [degC]: its
        speed nodes divided by ``radius`` [m], the map's value there at that temperature, held at the first
        node's value down to ``w = 0`` and beyond the last node (exact: at a fixed temperature the map is
        piecewise linear in ``v`` between its nodes).  A map over the pressing force too (3-D) is refused."""
        if radius is None:
            raise ParameterError(f"{name}: a friction map mu(v, T) needs radius [m] (v = radius |w_rel|) and "
                                 "temperature [degC], or no temperature and a thermal mass its losses heat")
        radius = _finite(name, "radius", radius, positive=True)
        if fmap.force_grid is not None:
            raise ParameterError(f"{name}: the friction map depends on the pressing force too "
                                 f"({fmap.force_grid.size} forces); a clutch takes a map mu(v, T) (the wet clutch "
                                 "element takes any)")
        if temperature is None:   # read at its heat port's temperature as the run goes (kernel.friction_map)
            v = np.asarray(fmap.speed_grid, dtype=float)
            temps = np.asarray(fmap.temperature_grid, dtype=float)
            values = np.asarray(fmap.values, dtype=float).reshape(temps.size, v.size)
            w = v / radius
            if w[0] > 0.0:
                w, values = np.concatenate([[0.0], w]), np.concatenate([values[:, :1], values], axis=1)
            if w.size == 1:   # (one speed: constant in w)
                w, values = np.array([0.0, 1.0]), np.concatenate([values, values], axis=1)
            return _LiveMap(tuple(float(q) for q in (*w, *temps, *values.ravel())), temps.size)
        temperature = _finite(name, "temperature", temperature)
        v = np.asarray(fmap.speed_grid, dtype=float)
        values = np.asarray(fmap.mu(v, np.full(v.shape, temperature)), dtype=float)
        w = v / radius
        if w[0] > 0.0:
            w, values = np.concatenate([[0.0], w]), np.concatenate([[values[0]], values])
        w = np.concatenate([w, [w[-1] + max(w[-1], 1.0)]])   # the last two equal: held beyond the grid
        values = np.concatenate([values, [values[-1]]])
        return tuple(float(q) for q in w) + tuple(float(q) for q in values)

    @_adds("bearing_friction")
    def bearing_friction(self, name: str, flange, torque=1.0, peak: float = 1.0, support=None) -> "Driveline":
        """Bearing friction of ``flange`` against ``support`` (default the ground; MSL ``BearingFriction``):
        sliding torque ``torque`` [N m], a number or a table ``[[w_rad_s, N m], ...]`` (linear between rows,
        extrapolated from the last two but never below 0); never free."""
        name = self._new_name(name)
        a, b = self._two(name, support, flange)
        return self._friction(name, a, b, K.LAW_TABLE, self._characteristic(name, "torque", torque), peak)

    @_adds("eclutch")
    def eclutch(self, name: str, a, b, position, model: int = 4, parameters=None, travel: float = 8e-3,
                points: int = 161, peak: float = 1.0, actuator=None, actuator_step: float = 1e-3,
                pre_roll: float = 1.0, settle: float = 0.5, mu_temperature=None, wear: float = 0.0,
                wear_rate: float = 0.0, wear_max: float = 1e-3, expansion: float = 0.0,
                reference_temperature: float = 20.0, actuator_in_network: bool | None = None) -> "Driveline":
        """The dry E-clutch of seed 000 between flanges a and b: sliding torque ``2 F_n r_eff mu`` ([1] Sec. 3.2,
        :func:`clutchlab.eclutch.models.torque_of_clamp_force`), ``r_eff`` and ``mu`` its axial model's.

        ``model`` (0-4) and ``parameters`` (an :class:`~clutchlab.eclutch.models.EClutchParameters`, or a
        path to an E-clutch parameter file) choose the axial model (:meth:`ClutchModel.preset`).  ``peak``
        scales the static limit.  The normal force ``F_n``:

        * without ``actuator``: from the model's static curve at the release bearing position ``position(t)``
          [m] (0 engaged, increasing to release; a signal), solved once at ``points`` positions over ``[0,
          travel]`` and read linearly between them (held beyond); free beyond the lift-off position (the first
          point whose force is 0);
        * with ``actuator`` (``True`` for the default :class:`~clutchlab.eclutch.actuator.ActuatorParameters`, or
          one): from the E-clutch dynamics ([1] Sec. 2-3: the electro-hydrostatic actuator under its position
          controller, the hydraulic line, the CSC and the axial model, :class:`~clutchlab.eclutch.dynamics.
          EClutch`), ``position`` being the bearing position *reference* (a constant, ramp or table).  The axial
          dynamics do not depend on the rotation (one-way coupling), so they are solved once, before the network,
          from rest through a ``pre_roll`` [s] holding the reference's first value (the actuator settles there
          before t = 0) to ``settle`` [s] past its last corner; ``F_n(t)`` is read linearly between samples
          ``actuator_step`` [s] apart (held after the run: the reference is constant there).
        * with ``actuator`` **in the network** (``actuator_in_network``; by default where ``position`` reads a
          network input, which cannot be solved ahead): the same dynamics as a component of the network
          (:mod:`clutchlab.driveline.eclutch`), its states integrated with the network's, its reference read at every
          evaluation, so a host, an FMU's importer or a controller drives the pedal (``position = { input =
          "pedal" }``).  The actuator starts as it would ahead: from rest through ``pre_roll`` [s] holding the
          reference's value at t = 0 (an input's start).  The network is then integrated by Rodas3 (the actuator is
          stiff and its massless nodes are algebraic rows): slower than the solve ahead (about 20 times for the launch
          example), exact for any reference.  ``actuator_step`` and ``settle`` are not used; ``mu_temperature`` is
          refused with it (not yet).

        ``mu_temperature``: a factor over the temperature of the thermal mass its losses heat, as :meth:`clutch`.

        **Wear and thermal expansion** move the working point ([1] Sec. 7, future work iii; :func:`clutchlab.eclutch.
        dynamics.apply_wear_and_expansion`): the cushion pre-strain changes by ``s = -w + e (T - T_ref)``, so the
        static curve shifts along the bearing travel.  ``wear`` [m]: the facing wear at the start (both faces);
        ``wear_rate`` [m/J]: wear per joule the clutch dissipates, ``w = wear + wear_rate E`` (wear proportional to
        the friction work: Archard's law at a constant friction coefficient); ``expansion`` [m/K]: the stack's
        growth per kelvin, ``alpha h`` (cast iron 12e-6 1/K over a 30 mm stack: 3.6e-7 m/K), at the temperature
        ``T`` [degC] of the thermal mass its losses heat (it must heat one), ``reference_temperature`` the
        temperature at which its curve is the model's.  With any of the three, its normal force is read from its
        static curves at shifts from ``-wear_max`` (and the coldest :data:`SHIFT_TEMPERATURES`) to the hottest,
        interpolated at the same distance to their lift-offs (:func:`~clutchlab.driveline.kernel.shifted_curve`;
        levels added until a midpoint's curve is within :data:`SHIFT_TOLERANCE` of the peak force); a run whose
        wear passes ``wear_max`` or whose temperature leaves that span ends with an error naming the clutch.  Not
        with ``actuator`` (its clamp force is solved before the network: a worn clutch's actuator is given
        ``apply_wear_and_expansion`` itself).
        """
        from ..eclutch.models import ClutchModel, EClutchParameters

        name = self._new_name(name)
        a, b = self._two(name, a, b)
        travel = _finite(name, "travel", travel, positive=True)
        if not isinstance(points, (int, np.integer)) or isinstance(points, bool) or not 3 <= points <= 10_000:
            raise ParameterError(f"{name}: points = {points!r} must be an integer from 3 to 10000")
        if model not in (0, 1, 2, 3, 4) or isinstance(model, bool):
            raise ParameterError(f"{name}: model = {model!r} must be one of the axial models 0-4")
        if parameters is None or isinstance(parameters, EClutchParameters):
            cm = ClutchModel.preset(int(model), parameters)
        else:
            cm = ClutchModel.from_toml(int(model), parameters)
        sig = Signal.of(position, f"{name}: position")
        cgeo = 2.0 * float(cm.r_eff)
        label = f"E-clutch Model {int(model)} (r_eff = {cm.r_eff:g} m, mu = {cm.mu:g})"
        wear = _finite(name, "wear", wear, nonneg=True)
        wear_rate = _finite(name, "wear_rate", wear_rate, nonneg=True)
        wear_max = _finite(name, "wear_max", wear_max, positive=True)
        expansion = _finite(name, "expansion", expansion, nonneg=True)
        t_ref = _finite(name, "reference_temperature", reference_temperature)
        lo_t, hi_t = SHIFT_TEMPERATURES
        if not lo_t <= t_ref <= hi_t:
            raise ParameterError(f"{name}: reference_temperature = {t_ref:g} degC must lie in [{lo_t:g}, {hi_t:g}]")
        shifted = wear > 0.0 or wear_rate > 0.0 or expansion > 0.0
        if shifted and wear > wear_max:
            raise ParameterError(f"{name}: wear = {wear:g} m is beyond wear_max = {wear_max:g} m")
        if actuator is None or actuator is False:
            self._friction(name, a, b, K.LAW_CLUTCH, (0.0, float(cm.mu)), peak, 1.0, cgeo, sig, mu_temperature)
            el = self._elements[-1]
            el.model = label
            if shifted:
                lo = -wear_max + expansion * (lo_t - t_ref)
                hi = expansion * (hi_t - t_ref)
                el.ncurve, el.levels = _shift_table(name, cm, travel, int(points), lo, hi)
                el.coef = el.coef + (float(el.levels), wear, wear_rate, expansion, t_ref)
                el.liftoff = _shifted_liftoff(el.ncurve, el.levels, -wear)
                el.model = (f"{label}, worn {wear * 1e6:g} um + {wear_rate:g} m/J, expanding {expansion:g} m/K "
                            f"from {t_ref:g} degC ({el.levels} shift levels)")
                return self
            u = np.linspace(0.0, travel, int(points))
            fn = np.maximum(cm.static_curve(u)["normal_force_N"].to_numpy(), 0.0)
            zero = np.flatnonzero(fn <= 0.0)
            liftoff = float(u[zero[0]]) if zero.size else math.inf
            el.ncurve = tuple(u) + tuple(fn)
            el.liftoff = liftoff
            return self
        if wear_rate > 0.0 or expansion > 0.0:
            raise ParameterError(f"{name}: wear_rate and expansion need the clutch without its actuator (its clamp "
                                 "force is solved before the network); a worn clutch's actuator takes wear")
        if wear > 0.0:
            from ..eclutch.dynamics import apply_wear_and_expansion

            cm = apply_wear_and_expansion(cm, wear_m=wear)
        if actuator_in_network is None:
            actuator_in_network = bool(sig.input_names())
        if actuator_in_network is not True and actuator_in_network is not False:
            raise ParameterError(f"{name}: actuator_in_network = {actuator_in_network!r} must be true or false")
        if actuator_in_network:
            return self._eclutch_in_network(name, a, b, cm, sig, actuator, peak, pre_roll, mu_temperature, label)
        if sig.input_names():
            raise ParameterError(f"{name}: position reads a network input: its actuator must be in the network "
                                 "(actuator_in_network = true), as an input cannot be solved ahead")
        times, fn, corners, info = self._eclutch_dynamics(name, cm, sig, actuator, actuator_step, pre_roll, settle)
        self._friction(name, a, b, K.LAW_CLUTCH, (0.0, float(cm.mu)), peak, 1.0, cgeo,
                       Signal.sampled(times, fn, corners), mu_temperature)
        el = self._elements[-1]
        el.model = f"{label} with its actuator ({info})"
        el.reference = sig
        return self

    def _eclutch_in_network(self, name, a, b, cm, sig, actuator, peak, pre_roll, mu_temperature, label):
        """:meth:`eclutch` with its actuator as a component of the network (:mod:`clutchlab.driveline.eclutch`)."""
        from ..eclutch.actuator import ActuatorParameters

        if actuator is True:
            actuator = ActuatorParameters()
        if not isinstance(actuator, ActuatorParameters):
            raise ParameterError(f"{name}: actuator must be True or ActuatorParameters, not {type(actuator).__name__}")
        if mu_temperature is not None:
            raise ParameterError(f"{name}: mu_temperature is not available with the actuator in the network (yet); "
                                 "solve the actuator ahead (actuator_in_network = false)")
        if self.domain != "rotational":
            raise ParameterError(f"{name}: an E-clutch turns: it belongs to a rotational driveline")
        pre_roll = _finite(name, "pre_roll", pre_roll, nonneg=True)
        lo, hi = sig.bounds()   # (None where a network input decides it: the actuator's reference limits hold it)
        for value in (lo, hi):
            if value is not None and not actuator.slave_min <= value <= actuator.slave_max:
                raise ParameterError(f"{name}: position = {sig.describe('m')}: the bearing reference reaches "
                                     f"{value:g} m, outside the CSC travel [{actuator.slave_min:g}, "
                                     f"{actuator.slave_max:g}] m (ActuatorParameters.slave_min, slave_max)")
        self._friction(name, a, b, K.LAW_EXTERNAL, (0.0, 0.0), peak, 0.0, 0.0, sig)
        el = self._elements[-1]
        el.ecl = dict(clutch=cm, actuator=actuator, pre_roll=pre_roll)
        el.model = f"{label} with its actuator in the network"
        el.reference = sig
        return self

    def _eclutch_parameters(self, rtol: float) -> list:
        """Per E-clutch with its actuator in the network: its element, its actuator's system (position mode, the held
        input: :meth:`clutchlab.eclutch.dynamics.EClutch.as_system`) and the state and modes it starts from (after its
        pre-roll holding the reference's value at t = 0); an empty list without one."""
        if all(el.ecl is None for el in self._elements):
            return []
        from ..eclutch.dynamics import EClutch
        from ..system import Simulation

        out = []
        starts = self._input_starts()
        for el in self._elements:
            if el.ecl is None:
                continue
            u0 = float(el.signal.value_and_rate(0.0, starts)[0])
            ec = EClutch(el.ecl["actuator"], el.ecl["clutch"])
            try:   # (as_system refuses a reference outside the CSC travel)
                system = ec.as_system({"bearing_reference": u0}, held_input=True, rtol=float(rtol))
            except ParameterError as exc:
                raise ParameterError(f"{el.name}: {exc}") from None
            x0, m0 = system.x0.copy(), system.m0.copy()
            key = (float(rtol), u0)
            known = el.ecl.get("start")   # (a run asked for again: its pre-roll is the same, not run again)
            if known is not None and known[0] == key:
                x0, m0 = known[1].copy(), known[2].copy()
            elif el.ecl["pre_roll"] > 0.0:   # (the actuator settles at the reference's start before t = 0)
                run = Simulation(system)
                run.advance(el.ecl["pre_roll"], np.array([u0]))
                x0, m0 = run.x.copy(), run.m.copy()
                for name in ("input_work", "dissipated", "friction_dissipated"):   # (its energies count from t = 0)
                    x0[system.state_index(name)] = 0.0
                el.ecl = dict(el.ecl, start=(key, x0.copy(), m0.copy()))
            out.append((el, ec, system, x0, m0))
        return out

    @staticmethod
    def _eclutch_dynamics(name, cm, sig, actuator, step, pre_roll, settle):
        """Normal force samples ``(times, F_n)`` of the E-clutch dynamics under the bearing reference ``sig``."""
        from ..eclutch.actuator import ActuatorParameters
        from ..eclutch.dynamics import EClutch

        step = _finite(name, "actuator_step", step, positive=True)
        pre_roll = _finite(name, "pre_roll", pre_roll, nonneg=True)
        settle = _finite(name, "settle", settle, positive=True)
        if actuator is True:
            actuator = ActuatorParameters()
        if not isinstance(actuator, ActuatorParameters):
            raise ParameterError(f"{name}: actuator must be True or ActuatorParameters, not {type(actuator).__name__}")
        t_ref, v_ref = (list(v) for v in sig.breakpoints(f"{name}: with an actuator, position (the bearing "
                                                         "reference)", "m"))
        if min(t_ref) < 0.0:
            raise ParameterError(f"{name}: the bearing reference starts at {min(t_ref):g} s (before t = 0)")
        times = np.array([0.0] + [t + pre_roll for t in t_ref]) if pre_roll > 0 else np.array(t_ref, dtype=float)
        values = np.array([v_ref[0]] + list(v_ref), dtype=float) if pre_roll > 0 else np.array(v_ref, dtype=float)
        keep = np.concatenate([[True], np.diff(times) > 0])
        times, values = times[keep], values[keep]
        t_end = pre_roll + max(t_ref[-1], 0.0) + settle
        n = int(math.ceil(t_end / step))
        if n > 5_000_000:
            raise ParameterError(f"{name}: {n} actuator samples ({t_end:g} s every {step:g} s): choose a larger "
                                 "actuator_step")
        try:
            run = EClutch(actuator, cm).simulate({"bearing_reference": (times, values)}, n * step, output_step=step)
        except ParameterError as exc:   # (e.g. a reference beyond the CSC travel: name the component)
            raise ParameterError(f"{name}: {exc}") from None
        df = run.to_dataframe()
        t = df["time_s"].to_numpy() - pre_roll
        fn = np.maximum(df["normal_force_N"].to_numpy(), 0.0)
        keep = t >= -1e-12
        t, fn = np.maximum(t[keep], 0.0), fn[keep]
        # the corners of F_n(t): where it leaves zero or falls to it (engagement, lift-off); elsewhere it is smooth
        on = fn > 0.0
        change = np.flatnonzero(on[1:] != on[:-1])
        corners = np.concatenate([t[change], t[change + 1]])
        return t, fn, corners, f"{len(t)} samples every {step * 1e3:g} ms, pre-roll {pre_roll:g} s"

    @_adds("wet_clutch")
    def wet_clutch(self, name: str, a, b, force, clutch=None, bench=None, friction=None,
                   temperature0: float = 80.0, fluid_temperature0: float = 80.0,
                   housing_temperature0: float = 80.0) -> "Driveline":
        """The wet clutch of seed 001 between flanges a (outer plates) and b (inner plates), with states of its
        own: actuator force, piston, squeeze film, pack, oil and housing temperatures (the engagement model of
        :mod:`clutchlab.wet.system`, Shin et al. Eqs. 1-8; :mod:`clutchlab.driveline.wet`).

        Its torque is the asperity torque ``R_eff N_c mu_f F_c`` (Eq. 4) plus the viscous torque (Eq. 5)
        while it slides, and at most ``R_eff N_c mu_f F_c`` while stuck; the network's friction state machine
        decides which.  ``force`` [N]: the actuator force reference, a port: any :class:`Signal` (a table, a
        sine, a pulse, a product, a network input ``Signal.input``) or a number, read at every evaluation; the
        actuator follows it with its lag.  A signal must stay within ``[0, bench.actuator_force_max]``; a network
        input is saturated there (the actuator only pushes: a negative reference releases it).  ``clutch``
        (:class:`~clutchlab.wet.params.WetClutch`, default ``WetClutch.paper()``), ``bench``
        (:class:`~clutchlab.wet.params.Bench`: actuator, oil loop and housing; default ``Bench()``; its drive
        is not used) and ``friction`` (a friction law or map of :mod:`clutchlab.wet.friction`, default the
        bench's): as :func:`clutchlab.wet.system.pack_parameters`.  ``temperature0``, ``fluid_temperature0``,
        ``housing_temperature0``: the temperatures [degC] at the start of the pack, the oil reservoir (also the
        heater's set point) and the housing.  Any number of wet clutches and EMTC couplings per network
        (:mod:`clutchlab.driveline.coupled`).
        """
        from ..wet.params import Bench, WetClutch, temperature_problem

        name = self._new_name(name)
        a, b = self._two(name, a, b)
        sig = Signal.of(force, f"{name}: force")
        temps = {}
        for what, value in (("temperature0", temperature0), ("fluid_temperature0", fluid_temperature0),
                            ("housing_temperature0", housing_temperature0)):
            temps[what] = _finite(name, what, value)
            problem = temperature_problem(temps[what])
            if problem:
                raise ParameterError(f"{name}: {what} = {temps[what]:g} degC: {problem}")
        from ..wet.friction import FrictionMap, ParametricFriction

        clutch = WetClutch.paper() if clutch is None else clutch
        bench = Bench() if bench is None else bench
        for what, value, cls, label in (("clutch", clutch, WetClutch, "WetClutch"), ("bench", bench, Bench, "Bench"),
                                        ("friction", friction, (ParametricFriction, FrictionMap, type(None)),
                                         "ParametricFriction or FrictionMap")):
            if not isinstance(value, cls):
                raise ParameterError(f"{name}: {what} must be a {label}, not {type(value).__name__}")
        lo, hi = sig.bounds()   # (None where a network input decides it: saturated at 0 and the maximum)
        if lo is not None and lo < 0.0:
            raise ParameterError(f"{name}: force = {sig.describe('N')}: the force reference reaches {lo:g} N; an "
                                 "actuator only pushes (a reference >= 0)")
        if hi is not None and hi > bench.actuator_force_max * (1.0 + 1e-12):
            raise ParameterError(f"{name}: force = {sig.describe('N')}: the force reference reaches {hi:g} N, "
                                 f"beyond the actuator's {bench.actuator_force_max:g} N (bench.actuator_force_max)")
        self._friction(name, a, b, K.LAW_EXTERNAL, (0.0, 0.0), 1.0, 0.0, 0.0, sig)
        el = self._elements[-1]
        el.wet = dict(clutch=clutch, bench=bench, friction=friction, **temps)
        el.model = f"wet clutch (seed 001, N_c = {clutch.n_c:g}, R_eff = {clutch.r_eff:g} m)"
        return self

    @_adds("emtc")
    def emtc(self, name: str, a, b, magnet=None, scenario=None, vehicle=None, options=None, *, torque_request=None,
             throttle=None, coil_current=None) -> "Driveline":
        """The electromagnetic torque-controlled coupling of seed 002 between flanges a (its input, front shaft)
        and b (its output, rear shaft), with states of its own: coil current lags, armature, Preisach magnet
        memory, and its controller (:mod:`clutchlab.emtc.system`, Processes 7 (2019) 557, Eqs. 1-26 and 31;
        :mod:`clutchlab.driveline.emtc`).

        Its torque is the slipping-mode torque of the three friction elements and the ball-cam (Eqs. 13-17)
        while its armature presses the primary clutch, the drag of Eq. 25 while it does not; stuck, it holds
        up to ``1.02 T_cap_L`` (Eq. 21 and the unlock margin of Fig. 11); the network's friction state machine
        decides which.  Its controller samples every ``scenario.sample_time`` the torque reference (the map of
        Eq. 31 at ``scenario``'s throttle ramp and the vehicle speed of flange a, or
        ``options.torque_reference``) and commands the coil current through the inverse Preisach model
        (Eqs. 6-7).  ``magnet`` (:class:`~clutchlab.hysteresis.Preisach`, default the bundled synthetic
        model), ``scenario`` (:class:`~clutchlab.emtc.bench.BenchScenario`: its throttle ramp, gear,
        temperature and sample time; its drum speeds are not used), ``vehicle``
        (:class:`~clutchlab.emtc.bench.VehicleParameters`: the map's vehicle speed and the drag of Eq. 25)
        and ``options`` (:class:`~clutchlab.emtc.system.BenchOptions`: actuator, coupling geometry, torque map,
        controller model, friction map, reference, memory capacity; LuGre friction is refused): as
        :func:`clutchlab.emtc.system.pack_parameters`.  Any number of EMTC couplings and wet clutches per network
        (:mod:`clutchlab.driveline.coupled`).

        Its ports (each a :class:`Signal` or a number; a network input with :meth:`Signal.input`, so a host, a
        controller or an FMU's importer drives it): ``torque_request`` [N m], the controller's torque reference,
        sampled every ``sample_time`` in place of the map of Eq. 31 and of ``options.torque_reference``;
        ``throttle`` [1], the map's throttle, sampled likewise in place of ``scenario``'s ramp; ``coil_current``
        [A], the set point of a current drive: the coil current lags of Fig. 15 follow it at once, with no torque
        controller (Eqs. 6-7 and 31 left out), as ``options.coil_drive = "current"`` in a co-simulation.  A port
        left out keeps what ``scenario`` and ``options`` say.
        """
        from ..emtc.bench import BenchScenario, VehicleParameters
        from ..emtc.system import BenchOptions
        from ..hysteresis import Preisach

        if self.domain != "rotational":
            raise ParameterError(f"{name}: an EMTC coupling turns: it belongs to a rotational driveline")
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        for what, value, cls, label in (("magnet", magnet, (Preisach, type(None)), "Preisach"),
                                        ("scenario", scenario, (BenchScenario, type(None)), "BenchScenario"),
                                        ("vehicle", vehicle, (VehicleParameters, type(None)), "VehicleParameters"),
                                        ("options", options, (BenchOptions, type(None)), "BenchOptions")):
            if not isinstance(value, cls):
                raise ParameterError(f"{name}: {what} must be a {label}, not {type(value).__name__}")
        if options is not None and options.lugre is not None:
            raise ParameterError(f"{name}: LuGre friction is not available in a driveline (its bristle state "
                                 "follows the drum bench's own lock-up logic); give a friction map or none")
        if a is None or b is None:
            raise ParameterError(f"{name}: an EMTC coupling sits between two inertias (its shafts), not on the ground")
        ports = {q: (None if v is None else Signal.of(v, f"{name}: {q}"))
                 for q, v in (("torque_request", torque_request), ("throttle", throttle), ("coil_current", coil_current))}
        if ports["torque_request"] is not None and ports["coil_current"] is not None:
            raise ParameterError(f"{name}: torque_request and coil_current: a current drive (coil_current) has no "
                                 "torque controller to take a torque request; give one of them")
        if ports["torque_request"] is not None and options is not None and options.torque_reference is not None:
            raise ParameterError(f"{name}: torque_request and options.torque_reference both give the controller's "
                                 "torque reference; give one of them")
        if ports["coil_current"] is not None and options is not None and options.coil_drive != "controller":
            raise ParameterError(f"{name}: coil_current with options.coil_drive = {options.coil_drive!r}: the port "
                                 "makes the drive a current drive; leave coil_drive at 'controller'")
        self._friction(name, a, b, K.LAW_EXTERNAL, (0.0, 0.0), 1.0, 0.0, 0.0)
        el = self._elements[-1]
        el.emtc = dict(magnet=magnet, scenario=scenario or BenchScenario(), vehicle=vehicle or VehicleParameters(),
                       options=options or BenchOptions(), ports=ports)
        el.model = "EMTC coupling (seed 002: three friction elements, ball-cam, Preisach magnet, controller)"
        return self

    def _emtc_parameters(self) -> list:
        """Per EMTC coupling: its element, packed parameters (:func:`clutchlab.emtc.system.pack_parameters`) and
        magnet (an empty list without one)."""
        out = []
        for el in self._elements:
            if el.emtc is not None:
                from ..emtc import system as S

                w = el.emtc
                magnet = w["magnet"]
                if magnet is None:
                    from ..emtc.magnet import bundled_magnet

                    magnet = bundled_magnet()
                packed = S.pack_parameters(magnet, w["scenario"], w["vehicle"], w["options"])
                ports = w["ports"]
                if ports["torque_request"] is not None:   # the controller samples the port (u) for its reference
                    packed = packed._replace(reference_source=S.REFERENCE_INPUT)
                if ports["coil_current"] is not None:     # a current drive: the lags follow the port (u) at once
                    packed = packed._replace(reference_source=S.REFERENCE_CURRENT)
                if ports["throttle"] is not None:         # the map's throttle read from the port (u), not a ramp
                    packed = packed._replace(throttle=np.zeros((2, 0)))
                if any(el.name in tm.heat_from for tm in self._thermal.values()):
                    # its losses heat a thermal mass: the friction map at that mass's temperature, the input
                    # coupling_temperature its network writes (clutchlab.driveline.emtc._coupling)
                    packed = packed._replace(temperature_source=S.TEMPERATURE_INPUT)
                out.append((el, packed, magnet))
        return out

    def _wet_parameters(self) -> list:
        """Per wet clutch: its element, packed parameters (:func:`clutchlab.wet.system.pack_parameters`, free
        shaft), initial state and clutch parameters (an empty list without one)."""
        if all(el.wet is None for el in self._elements):
            return []   # (without importing the wet package: a plain network starts sooner)
        from ..wet import system as W
        from ..wet.engagement import Scenario

        out = []
        for el in self._elements:
            if el.wet is None:
                continue
            w = el.wet
            # the model's own force profile is zero: the force reaches it through its port (its element's signal,
            # read by the block at every evaluation, driveline.wet.hold)
            scenario = Scenario(force_time=[0.0], force_value=[0.0], speed_time=[0.0], speed_value=[0.0],
                                duration=1.0, motor="free", initial_temperature_c=w["temperature0"],
                                fluid_temperature_c=w["fluid_temperature0"],
                                housing_temperature_c=w["housing_temperature0"])
            params = W.pack_parameters(w["clutch"], w["bench"], scenario, w["friction"])
            out.append((el, params, W.initial_state(scenario), w["clutch"]))
        return out

    @_adds("one_way_clutch")
    def one_way_clutch(self, name: str, a, b, fn_max: float = 0.0, mu=0.5, peak: float = 1.0, cgeo: float = 1.0,
                       normal=1.0, mu_scale: float = 1.0, mu_temperature=None) -> "Driveline":
        """A one-way clutch between flanges a and b (MSL ``OneWayClutch``: a freewheel in parallel with a clutch).

        Flange b may overrun flange a (``w_b > w_a``); the freewheel locks, holding any torque, when b would turn
        slower.  Without a normal force (``fn_max`` 0, the default) it overruns freely; with one, its clutch
        (``fn = fn_max * normal(t)``, ``cgeo``, ``mu`` and ``peak`` as :meth:`clutch`; no torque where ``fn <= 0``)
        holds up to ``peak * cgeo * fn * mu(0)`` against overrunning and slides with ``cgeo * fn * mu(w_rel)``
        while b overruns.  Events ``stick`` when it locks or its clutch holds, ``forward`` when b overruns; it
        never slides backward, so it may not start with ``w_b < w_a``.  ``mu_scale`` and ``mu_temperature`` as
        :meth:`clutch`."""
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        return self._friction(name, a, b, K.LAW_ONEWAY, self._characteristic(name, "mu", mu), peak, fn_max, cgeo,
                              None if fn_max == 0.0 else normal, mu_temperature, mu_scale)

    @_adds("synchronizer")
    def synchronizer(self, name: str, a, b, force, cone_radius: float, dog_capacity: float, mu=0.1,
                     cone_angle: float = math.radians(6.5), cones: int = 1, side: str = "positive") -> "Driveline":
        """A synchroniser between a shaft ``a`` and a gear's idler ``b`` on it: a cone clutch and a dog
        clutch on one shift sleeve, as an automated manual transmission (AMT) or a manual gearbox engages a gear.

        The sleeve's shift force ``force`` [N] (a signal: a shift actuator's force, or a network input) pushes it
        towards the gear while positive (negative, with ``side = "negative"``).  While the speeds differ the blocker ring holds the sleeve back and the
        cone slides with the torque ``cones mu F cone_radius / sin(cone_angle)`` (a clutch with ``cgeo = cones
        cone_radius / sin(cone_angle)`` and the normal force ``F``), which pulls the speeds together.  Where they
        meet the dogs engage (event ``stick``) and hold up to ``dog_capacity`` [N m] while the force keeps pushing:
        the gear is in.  A force of zero (or of the other sign) takes the sleeve out (neutral; event ``free``): a
        gear is held in by a pushing force, and a synchroniser at zero force never engages.  The sleeve's travel, the
        dogs' lash and the blocker's indexing take no time here
        (:func:`~clutchlab.driveline.kernel.static_limit`; docs/driveline.md, "Synchronisers").

        Parameters
        ----------
        name : str
            Its name (unique among the network's components).
        a, b : str
            The two bodies it joins: the shaft its sleeve's hub turns with and the gear's idler (a friction element
            acts alike both ways round).
        force : float, Signal, tuple or str
            The shift force [N] on the sleeve (a number, a :class:`Signal`, ``(times, values)`` or a network
            input's name).
        cone_radius : float
            Mean radius of the friction cone [m] (> 0).
        dog_capacity : float
            The most torque [N m] the engaged dogs hold (> 0; the element holds at least the cone's torque at rest,
            whichever is larger); beyond it the element slides at the cone's torque.
        mu : float or table
            Friction coefficient of the cone (oil-lubricated brass, carbon or molybdenum linings: 0.08-0.12), a
            number or rows ``[w_rad_s, mu]`` over the slip speed.
        cone_angle : float
            Half angle of the cone [rad] (default 6.5 degrees; in (0, pi/4]).  Where ``mu >= tan(cone_angle)``
            the cone would stay locked after the force is taken off; that is refused.
        cones : int
            Number of cone surfaces: 1 (single cone), 2 (double) or 3 (triple).
        side : str
            ``"positive"``: the positive values of ``force`` push the sleeve towards this gear; ``"negative"``: its
            negative values do (the shift force is then ``-force``).  A sleeve between two gears (a 1-2 sleeve)
            driven by one shift fork is two synchronisers on one signal, one on each side: the fork's force
            pushes towards one gear or the other, and zero is neutral.
        """
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        radius = _finite(name, "cone_radius", cone_radius, positive=True)
        dog = _finite(name, "dog_capacity", dog_capacity, positive=True)
        angle = _finite(name, "cone_angle", cone_angle, positive=True)
        if not angle <= math.pi / 4:
            raise ParameterError(f"{name}: cone_angle = {math.degrees(angle):g} deg must lie in (0, 45] deg (a "
                                 "synchroniser's cone half angle is 6-8 deg)")
        if isinstance(cones, bool) or not isinstance(cones, (int, np.integer)) or cones not in (1, 2, 3):
            raise ParameterError(f"{name}: cones = {cones!r} must be 1, 2 or 3 (cone surfaces)")
        table = self._characteristic(name, "mu", mu)
        mu_max = max(table[len(table) // 2:])
        if mu_max >= math.tan(angle):
            raise ParameterError(f"{name}: mu = {mu_max:g} is not below tan(cone_angle) = {math.tan(angle):.4g} "
                                 f"(cone_angle {math.degrees(angle):g} deg): the cone would lock itself and not "
                                 "release when the force is taken off; use a larger cone_angle or a smaller mu")
        if side not in ("positive", "negative"):
            raise ParameterError(f"{name}: side = {side!r} must be 'positive' or 'negative' (which sign of the "
                                 "force pushes the sleeve towards this gear)")
        cgeo = cones * radius / math.sin(angle)
        self._friction(name, a, b, K.LAW_CLUTCH, table, 1.0, 1.0, cgeo, Signal.of(force, f"{name}: force"))
        el = self._elements[-1]
        coef = list(el.coef) + [0.0] * (K.C_DOG + 1 - len(el.coef))
        coef[K.C_DOG] = dog
        coef[K.C_FN_MAX] = 1.0 if side == "positive" else -1.0   # (the shift force: fn_max times the signal)
        el.coef = tuple(coef)
        el.model = (f"synchroniser, {cones} cone{'s' if cones > 1 else ''} at {radius * 1e3:g} mm, "
                    f"{math.degrees(angle):g} deg, dogs {dog:g} N m" + (", pushed by -force" if side == "negative"
                                                                        else ""))
        return self

    # ---- the system
    # ---- heat
    def thermal_mass(self, name: str, capacity: float, T0: float = 20.0, conductance: float = 0.0,
                     ambient: float = 20.0, heat_from=()) -> "Driveline":
        """A thermal mass heated by the losses of elements of the network (MSL ``HeatCapacitor`` whose port the
        elements' heat ports join, ``useHeatPort = true``, with a ``ThermalConductor`` to a ``FixedTemperature``).

        ``C dT/dt = sum of the losses of heat_from - conductance (T - ambient) - the flows of its conductors``
        (:func:`~clutchlab.driveline.kernel.thermal_rates`).  Its states are ``<name>.temperature_C`` and
        ``<name>.heat_out_J`` (the heat given to its ambient since the start); its outputs ``<name>.loss_power_W``
        (what its elements dissipate into it) and ``<name>.heat_flow_W`` (to its ambient).  A friction element
        among ``heat_from`` with ``mu_temperature`` (:meth:`clutch`) fades with this temperature; otherwise the
        temperature is an output of the losses only.

        Parameters
        ----------
        name : str
            Its name (unique among the network's components).
        capacity : float
            Heat capacity [J/K] (> 0).
        T0 : float
            Initial temperature [degC].
        conductance : float
            Thermal conductance to its ambient [W/K] (>= 0; 0: insulated).
        ambient : float
            The ambient's temperature [degC].
        heat_from : sequence of str
            The elements whose losses heat it (springs and dampers, backlash, gears, clutches, brakes, bearing
            friction, one-way clutches, E-clutches, EMTC couplings), named here or added later: they are looked up
            when the network is packed.  An element heats at most one mass; sources dissipate nothing, and a wet
            clutch carries its own thermal model.  An EMTC coupling with a friction map reads it at this mass's
            temperature (instead of its scenario's ``temperature_c``; seed 002, Sec. 5: the coupling's thermal
            behaviour, its future work).
        """
        name = self._new_name(name)
        capacity = _finite(name, "capacity", capacity, positive=True)
        T0 = _finite(name, "T0", T0)
        conductance = _finite(name, "conductance", conductance, nonneg=True)
        ambient = _finite(name, "ambient", ambient)
        for t, what in ((T0, "T0"), (ambient, "ambient")):
            if t <= ABSOLUTE_ZERO_C:
                raise ParameterError(f"{name}: {what} = {t:g} degC is not above absolute zero ({ABSOLUTE_ZERO_C} degC)")
        if isinstance(heat_from, str):
            heat_from = (heat_from,)
        heat_from = tuple(heat_from)
        for e in heat_from:
            if not isinstance(e, str) or not e:
                raise ParameterError(f"{name}: heat_from = {heat_from!r}: expected names of elements")
        if len(set(heat_from)) != len(heat_from):
            raise ParameterError(f"{name}: heat_from = {list(heat_from)!r} names an element twice")
        self._thermal[name] = _ThermalMass(name, capacity, T0, conductance, ambient, heat_from)
        return self

    def thermal_conductor(self, name: str, a: str, b: str, conductance: float) -> "Driveline":
        """A thermal conductor between the thermal masses ``a`` and ``b`` (MSL ``ThermalConductor``): the heat flow
        ``conductance (T_a - T_b)`` [W] from ``a`` to ``b``; ``conductance`` [W/K] >= 0.  The masses may be added
        later (looked up when the network is packed)."""
        name = self._new_name(name)
        for which, v in (("a", a), ("b", b)):
            if not isinstance(v, str) or not v:
                raise ParameterError(f"{name}: {which} = {v!r}: expected the name of a thermal mass")
        if a == b:
            raise ParameterError(f"{name}: a and b are both {a!r} (a conductor joins two thermal masses)")
        self._links.append(_ThermalLink(name, a, b, _finite(name, "conductance", conductance, nonneg=True)))
        return self

    def _heat_rows(self) -> tuple:
        """``(heat, thermal, links)``: the thermal mass (row) each element's losses heat (-1 none), and the kernel's
        ``thermal`` and ``links`` tables (:data:`~clutchlab.driveline.kernel.THERMAL_COLUMNS`, ``LINK_COLUMNS``)."""
        rows = {e.name: r for r, e in enumerate(self._elements)}
        heat = np.full(len(self._elements), -1, dtype=np.int64)
        masses = list(self._thermal.values())
        o = self._thermal_offset()
        thermal = np.zeros((len(masses), K.N_THERMAL))
        for k, tm in enumerate(masses):
            thermal[k, K.T_CAP] = tm.capacity
            thermal[k, K.T_COND] = tm.conductance
            thermal[k, K.T_AMB] = tm.ambient
            thermal[k, K.T_INIT] = tm.T0
            thermal[k, K.T_STATE] = o + len(K.THERMAL_STATES) * k
            for name in tm.heat_from:
                if name not in rows:
                    known = ", ".join(e.name for e in self._elements) or "none"
                    raise ParameterError(f"{tm.name}: heat_from names {name!r}, not an element of {self.name!r} "
                                         f"(elements: {known})")
                e = self._elements[rows[name]]
                if e.kind in (K.K_SOURCE, K.K_MOTION):
                    raise ParameterError(f"{tm.name}: heat_from names {name!r}, a source: it does work and "
                                         "dissipates nothing")
                if e.wet is not None:
                    raise ParameterError(f"{tm.name}: heat_from names {name!r}, a wet clutch: it carries its own "
                                         "thermal model (pack, oil and housing, Eq. 8 of seed 001)")
                if heat[rows[name]] >= 0:
                    raise ParameterError(f"{tm.name}: heat_from names {name!r}, whose losses already heat "
                                         f"{masses[heat[rows[name]]].name!r} (an element heats one thermal mass)")
                heat[rows[name]] = k
        for r, e in enumerate(self._elements):
            if e.fade and heat[r] < 0:
                raise ParameterError(f"{e.name}: mu_temperature reads the temperature of the thermal mass its losses "
                                     f"heat, and none does: name {e.name!r} in a thermal mass's heat_from")
        index = {tm.name: k for k, tm in enumerate(masses)}
        links = np.zeros((len(self._links), K.N_LINK))
        for j, link in enumerate(self._links):
            for col, which, v in ((K.L_A, "a", link.a), (K.L_B, "b", link.b)):
                if v not in index:
                    known = ", ".join(index) or "none"
                    raise ParameterError(f"{link.name}: {which} = {v!r} is not a thermal mass of {self.name!r} "
                                         f"(thermal masses: {known})")
                links[j, col] = index[v]
            links[j, K.L_COND] = link.conductance
        for r, e in enumerate(self._elements):   # (what reads the temperature of its heat port: one must exist)
            if e.map_t and heat[r] < 0:
                raise ParameterError(f"{e.name}: a friction map without a temperature is read at the temperature of "
                                     "the thermal mass its losses heat: list it in a thermal_mass's heat_from, or "
                                     "give temperature")
            if e.levels:
                self._check_shift(e, e.coef, thermal[heat[r]] if heat[r] >= 0 else None)
        return heat, thermal, links

    def describe(self) -> str:
        """A text schematic: the inertias, the inputs, then every element between its flanges (``ground`` for
        none)."""
        fric = self.friction_names
        bodies = "masses" if self.domain == "translational" else "inertias"
        lines = [f"{self.name}: {len(self._inertias)} {bodies}, {len(self._elements)} elements "
                 f"({len(fric)} friction)"]
        x0 = self.initial_state()
        n = len(self._inertias)
        u = self._units
        (jn, ju), (an, _, au), (wn, _, wu) = u["inertia"], u["angle"], u["speed"]
        for i, (name, (J, _w0, _phi0)) in enumerate(self._inertias.items()):
            lines.append(f"  [{name}]  {jn} = {J:g} {ju}, {wn}0 = {x0[n + i]:g} {wu}, {an}0 = {x0[i]:g} {au}")
        for name, (unit, start, _d) in self._inputs.items():
            lines.append(f"  input {name} [{unit}], start {start:g}")
        for e in self._elements:
            lines.append("  " + self._element_line(e))
        for tm in self._thermal.values():
            lines.append(f"  thermal mass {tm.name}: C = {tm.capacity:g} J/K, T0 = {tm.T0:g} degC, "
                         f"G = {tm.conductance:g} W/K to {tm.ambient:g} degC, heated by "
                         + (", ".join(tm.heat_from) or "nothing"))
        for link in self._links:
            lines.append(f"  thermal conductor {link.name}: {link.a} - {link.b}, G = {link.conductance:g} W/K")
        return "\n".join(lines)

    def _element_line(self, e) -> str:
        """An element's line of :meth:`describe` (without its indent)."""
        u = self._units
        wn, wu, au, tu = u["speed"][0], u["speed"][2], u["angle"][2], u["torque"][2]
        st, dm = u["stiffness"], u["damping"]
        a, b = e.a or GROUND, e.b or GROUND
        if e.kind == K.K_SOURCE and e.law == K.SOURCE_ENGINE:
            return f"{a} --({e.name}: {e.model}, throttle {e.signal.describe()})--> [{b}]"
        if e.kind == K.K_SOURCE and e.law == K.SOURCE_SPEED:
            both = "both ways round" if e.coef[3] else "turning with the speed"
            return (f"{a} --({e.name}: {e.model} speed-dependent {u['words'][2]} {e.coef[0]:g} {tu} at "
                    f"{e.coef[1]:g} {wu}, {both})--> [{b}]")
        if e.kind == K.K_SOURCE:
            return f"{a} --({e.name}: {u['words'][2]} {e.signal.describe(tu)})--> [{b}]"
        if e.kind == K.K_MOTION:
            what, unit = ("speed", wu) if e.law == K.MOTION_SPEED else (u["words"][1], au)
            return f"{a} --({e.name}: {what} {e.signal.describe(unit)})--> [{b}]"
        if e.kind == K.K_GEAR:
            nrow = len(e.table) // 5
            what = f"gear, {wn}_a = {e.coef[0]:g} {wn}_b"
            if e.kind_name == "planetary":
                what = f"planetary, ring/sun teeth {-e.coef[0]:g}, sun {a}, ring {b}, carrier {e.sup or GROUND}"
            if self._is_lossy(e):
                what += (f", efficiency {e.table[nrow]:g}" if nrow == 1 and e.table[nrow] == e.table[2 * nrow]
                         and e.table[3 * nrow] == e.table[4 * nrow] == 0.0 else f", loss table of {nrow} rows")
            if e.sup is not None and e.kind_name != "planetary":
                what += f", on support {e.sup}"
        elif e.kind == K.K_CONVERTER:
            nd = (len(e.table) - 2 * e.aux) // 3
            what = (f"torque converter, K = {e.table[nd] * e.coef[0]:g} rad/s/sqrt(N m)"
                    + (f" (k_scale {e.coef[0]:g})" if e.coef[0] != 1.0 else "")
                    + f" and TR = {e.table[2 * nd]:g} at stall, table of {nd} rows"
                    + (f", coast table of {e.aux} rows" if e.aux else "")
                    + (f", on support {e.sup}" if e.sup is not None else ""))
        elif e.kind == K.K_SPRING and e.law == K.SPRING_CURVE:
            what = f"spring curve of {len(e.table) // 4} points, d = {e.coef[1]:g} {dm}"
        elif e.kind == K.K_SPRING and e.law == K.SPRING_BACKLASH:
            what = (f"backlash gap {e.coef[3]:g} {au}, c = {e.coef[0]:g} {st}, d = {e.coef[1]:g} {dm}"
                    + (", MSL damping law" if e.aux == K.LASH_MSL else ""))
        elif e.kind == K.K_SPRING:
            what = f"spring-damper c = {e.coef[0]:g} {st}, d = {e.coef[1]:g} {dm}"
        elif e.law == K.LAW_ONEWAY:
            n = len(e.table) // 2
            char = f"{e.table[n]:g}" if n == 1 else f"table of {n} points"
            normal = "" if e.signal is None else f", normal {e.signal.describe()}"
            what = ("one-way clutch (b overruns a freely)" if e.coef[0] == 0.0 else
                    f"one-way clutch (b overruns a), clutch fn_max = {e.coef[0]:g} N, mu {char}, "
                    f"peak {e.coef[2]:g}{normal}")
        elif e.law == K.LAW_EXTERNAL and e.emtc is not None:
            sc = e.emtc["scenario"]
            what = (f"{e.model}, gear {sc.gear}, throttle {sc.throttle_start:g} -> {sc.throttle_end:g} over "
                    f"{sc.ramp_start:g}-{sc.ramp_end:g} s, controller every {sc.sample_time * 1e3:g} ms")
            what += "".join(f", {q} {v.describe({'N*m': 'N m', '1': '', 'A': 'A'}[unit])}" for (q, unit), v in
                            zip(EMTC_PORTS, (e.emtc["ports"][q] for q, _ in EMTC_PORTS)) if v is not None)
        elif e.law == K.LAW_EXTERNAL:
            what = f"{e.model}, force reference {e.signal.describe('N')}"
        else:
            n = len(e.table) // 2
            char = f"{e.table[n]:g}" if n == 1 else f"table of {n} points"
            if e.map_t:
                nw = (len(e.table) - e.map_t) // (1 + e.map_t)
                char = f"map of {nw} speeds x {e.map_t} temperatures at its heat port's temperature"
            if e.coef[K.C_MU_SCALE] != 1.0 and e.law != K.LAW_TABLE:
                char += f" x mu_scale {e.coef[K.C_MU_SCALE]:g}"
            if e.law == K.LAW_TABLE:
                what = f"bearing friction {char} {tu}, peak {e.coef[2]:g}"
            elif len(e.coef) > K.C_DOG and e.coef[K.C_DOG] > 0.0:   # a synchroniser
                what = f"{e.model}, mu {char}, shift force {e.signal.describe('N')}"
            elif e.reference is not None:
                what = f"{e.model}, bearing reference {e.reference.describe('m')}"
            elif e.ncurve and e.levels:
                npt = (len(e.ncurve) - 2 * e.levels - 2) // e.levels
                what = (f"{e.model}, static curves of {npt} points, lift-off at {e.liftoff * 1e3:g} mm at the "
                        f"start, position {e.signal.describe('m')}")
            elif e.ncurve:
                what = (f"{e.model}, static curve of {len(e.ncurve) // 2} points, lift-off at "
                        f"{e.liftoff * 1e3:g} mm, position {e.signal.describe('m')}")
            else:
                normal = "" if e.signal is None else f", normal {e.signal.describe()}"
                what = f"friction fn_max = {e.coef[0]:g} N, mu {char}, peak {e.coef[2]:g}{normal}"
        return f"[{a}] --({e.name}: {what})-- [{b}]"

    def __repr__(self) -> str:
        try:
            return f"<Driveline {self.describe()}>"
        except ParameterError as exc:   # an inconsistent network still shows
            return f"<Driveline {self.name!r}: {exc}>"

    @property
    def friction_names(self) -> tuple:
        return tuple(e.name for e in self._elements if e.kind == K.K_FRICTION)

    @property
    def inertia_names(self) -> tuple:
        """The inertias' (masses') names in the order they were added: the order of their angles, then their
        speeds, at the head of the state vector."""
        return tuple(self._inertias)

    @property
    def elements(self) -> tuple:
        """The network's elements in the order they were added, each an :class:`ElementInfo` (name, kind,
        flanges, a gear's support, its :meth:`describe` line): a read-only view; change a network through its
        methods or its file."""
        return tuple(ElementInfo(e.name, e.kind_name, e.a or GROUND, e.b or GROUND,
                                 (e.sup or GROUND) if e.kind in (K.K_GEAR, K.K_CONVERTER) else None,
                                 self._element_line(e), self._arguments(e))
                     for e in self._elements)

    @staticmethod
    def _arguments(e):
        """The public arguments of the call that added element ``e`` (:attr:`ElementInfo.arguments`): its name and
        the flanges :class:`ElementInfo` names are left out."""
        return Arguments({k: v for k, v in e.call[1].items() if k not in _PLACES} if e.call else {})

    def _labels(self) -> tuple:
        """The argument names of a body: :meth:`inertia`'s or :meth:`mass`'s."""
        return ("J", "w0", "phi0") if self.domain == "rotational" else ("m", "v0", "s0")

    @property
    def inertias(self) -> tuple:
        """The network's bodies in the order they were added (the order of their angles, then speeds, in the state
        vector), each an :class:`InertiaInfo` (name, ``"inertia"`` or ``"mass"``, its arguments): a read-only view;
        :meth:`replace` changes one in a copy."""
        kind = "inertia" if self.domain == "rotational" else "mass"
        return tuple(InertiaInfo(n, kind, Arguments(zip(self._labels(), v)))
                     for n, v in self._inertias.items())

    def signal(self, name: str):
        """The :class:`Signal` element ``name`` reads, as the network holds it (``None`` for an element without
        one): a torque or motion source's; a clutch's, brake's or one-way clutch's normal-force factor; a
        synchroniser's shift force [N]; a wet clutch's actuator force reference [N]; an E-clutch's bearing position
        [m] or, with its actuator, the clamp force [N] the actuator's run gives, sampled (:meth:`Signal.sampled`:
        ``d.signal("clutch").breakpoints("clamp force")`` are its samples), which the network reads linearly
        between samples; with its actuator in the network, the bearing position reference [m] its actuator follows."""
        for e in self._elements:
            if e.name == name:
                return e.signal
        raise ParameterError(f"{self.name}: no element {name!r} (elements: {', '.join(self.element_names) or 'none'})")

    @property
    def element_names(self) -> tuple:
        """The elements' names in the order they were added."""
        return tuple(e.name for e in self._elements)

    def replace(self, name: str, **changes) -> "Driveline":
        """A copy of this network with some arguments of the inertia or element ``name`` changed (this one is left as
        it is): ``d.replace("clutch1", mu=0.3)``, ``d.replace("J1", w0=10.0)``.  The element is added again by the
        method that added it (:attr:`ElementInfo.arguments`), with its other arguments as they were, in its place, so
        it is checked as any new element is (its flanges may change too); a file's component keeps its kind.  An
        argument the method has not is refused naming the ones it has."""
        out = self.without()
        if name in self._inertias:
            labels = self._labels()
            self._refuse_unknown(name, "inertia" if self.domain == "rotational" else "mass", changes, labels)
            args = {**dict(zip(labels, self._inertias[name])), **changes}
            kept, out._inertias = list(out._inertias.items()), {}
            for n, v in kept:
                if n == name:
                    out._body(name, tuple(args[q] for q in labels), labels)
                else:
                    out._inertias[n] = v
            return out
        at = [k for k, e in enumerate(out._elements) if e.name == name]
        if not at:
            raise ParameterError(f"{self.name}: replace: no inertia or element {name!r}")
        old = out._elements.pop(at[0])
        method, args = old.call
        self._refuse_unknown(name, method, changes, [k for k in args if k != "name"])
        n = len(out._elements)
        getattr(out, method)(**{**args, **changes})
        added = out._elements[n:]
        del out._elements[n:]
        for e in added:
            e.kind_name = old.kind_name
        out._elements[at[0]:at[0]] = added
        return out

    @staticmethod
    def _refuse_unknown(name, what, changes, known) -> None:
        unknown = [k for k in changes if k not in known]
        if unknown:
            raise ParameterError(f"{name}: replace: {what} has no argument {unknown[0]!r} (it has "
                                 f"{', '.join(known)})")

    @property
    def thermal_masses(self) -> tuple:
        """The network's thermal masses in the order they were added, each a frozen record (``name``, ``capacity``
        [J/K], ``T0`` [degC], ``conductance`` [W/K], ``ambient`` [degC], ``heat_from``): a read-only view."""
        return tuple(self._thermal.values())

    def without(self, *names: str) -> "Driveline":
        """A copy of this network without the inertias and elements ``names`` (this one is left as it is): to run a
        network with and without a part of it (the unrelated-element property of issue #30, a what-if without a
        brake).  An element left in that acts on a removed inertia, or a thermal mass left in that a removed element
        heats, is refused naming both: leave it out too."""
        known = set(self._inertias) | {e.name for e in self._elements}
        unknown = [n for n in names if n not in known]
        if unknown:
            raise ParameterError(f"{self.name}: without: no inertia or element {unknown[0]!r}")
        gone = set(names)
        out = copy.copy(self)
        out._inertias = {k: v for k, v in self._inertias.items() if k not in gone}
        out._elements = [copy.copy(e) for e in self._elements if e.name not in gone]
        for e in out._elements:
            for flange in (e.a, e.b, e.sup):
                if flange in gone:
                    raise ParameterError(f"{self.name}: without {flange!r}: {e.name} acts on it (leave it out too)")
        for tm in self._thermal.values():
            heated = gone.intersection(tm.heat_from)
            if heated:
                raise ParameterError(f"{self.name}: without {sorted(heated)[0]!r}: the thermal mass {tm.name} takes "
                                     "its losses (leave the element in, or the mass out of the file)")
        out._inputs = dict(self._inputs)
        out._thermal = dict(self._thermal)
        out._links = list(self._links)
        return out

    def pack(self) -> K.DrivelineParams:
        """The packed parameters (:class:`~clutchlab.driveline.kernel.DrivelineParams`)."""
        return self._pack()[0]

    def _pack(self) -> tuple:
        """The packed parameters, each EMTC coupling's port rows (``{name: [signal row or -1 per port of
        EMTC_PORTS]}``, their signals packed after every element's: its block reads them, :meth:`_with_components`)
        and the modes the network starts from (:meth:`_initial_modes`, which also stores the start's energy)."""
        if not self._inertias:
            raise ParameterError(f"{self.name}: no inertia")
        index = {n: i for i, n in enumerate(self._inertias)}
        self._check_inputs()
        inputs = list(self._inputs)
        signals, data = [], []
        elem = np.zeros((len(self._elements), K.N_ELEM), dtype=np.int64)
        coef = np.zeros((len(self._elements), K.N_COEF))

        def signal_row(sig):
            """The signal's row (``K.N_SIG`` wide), its tables put in ``data``; a product's factor rows are put
            in ``data`` one after the other (the row: kind, their start, their number)."""
            row = list(sig.row)
            if row[0] in (K.SIG_TABLE, K.SIG_SAMPLED):
                n = len(sig.points) // 2
                row = [row[0], float(len(data)), float(n)]
                data.extend(sig.points)
                if row[0] == K.SIG_SAMPLED:   # its corners: the ends, then the breaks
                    corners = sorted({sig.points[0], sig.points[n - 1], *sig.breaks})
                    row += [float(len(data)), float(len(corners))]
                    data.extend(corners)
            elif row[0] == K.SIG_INPUT:   # held at the end of data (kernel.hold_inputs)
                row = [row[0], float(inputs.index(sig.name)), float(len(inputs))]
            elif row[0] == K.SIG_PRODUCT:
                rows = [signal_row(f) for f in sig.factors]
                row = [row[0], float(len(data)), float(len(rows))]
                for f in rows:
                    data.extend(f)
            return row + [0.0] * (K.N_SIG - len(row))

        def add_signal(sig):
            signals.append(signal_row(sig))
            return len(signals) - 1

        for r, e in enumerate(self._elements):
            elem[r, K.E_KIND] = e.kind
            elem[r, K.E_A] = -1 if e.a is None else index[e.a]
            elem[r, K.E_B] = -1 if e.b is None else index[e.b]
            elem[r, K.E_LAW] = e.law
            elem[r, K.E_SIGNAL] = -1 if e.signal is None else add_signal(e.signal)
            elem[r, K.E_SUP] = -1 if e.sup is None else index[e.sup]
            if e.table:
                elem[r, K.E_TABLE] = len(data)
                if e.kind == K.K_GEAR:
                    elem[r, K.E_TABLE_N] = len(e.table) // 5
                elif e.kind == K.K_CONVERTER:   # drive rows [SR, K, TR], then e.aux coast rows [SR, K]
                    elem[r, K.E_TABLE_N] = (len(e.table) - 2 * e.aux) // 3
                elif e.kind == K.K_SOURCE and e.law == K.SOURCE_ENGINE:
                    elem[r, K.E_TABLE_N] = (len(e.table) - e.aux) // (1 + e.aux)
                elif e.map_t:
                    elem[r, K.E_TABLE_N] = (len(e.table) - e.map_t) // (1 + e.map_t)
                    elem[r, K.E_MAP_T] = e.map_t
                else:
                    elem[r, K.E_TABLE_N] = len(e.table) // (4 if e.kind == K.K_SPRING else 2)
                data.extend(e.table)
            elem[r, K.E_AUX] = 0 if e.kind == K.K_GEAR else e.aux
            elem[r, K.E_MODE] = -1
            elem[r, K.E_STATE] = self._controllers.index(e) if e in self._controllers else -1
            coef[r, :len(e.coef)] = e.coef
            elem[r, K.E_FADE] = -1
            if e.fade:
                elem[r, K.E_FADE] = len(data)
                elem[r, K.E_FADE_N] = len(e.fade) // 2
                data.extend(e.fade)
            if e.ncurve:
                coef[r, K.C_NCURVE] = len(data)
                # (a shifted curve's lift-off follows its shift, kernel.shifted_liftoff: no word of its own, so its
                # initial wear stays a copy a native FMU writes)
                coef[r, K.C_LIFTOFF] = 0.0 if e.levels else e.liftoff
                elem[r, K.E_AUX] = (len(e.ncurve) - 2 * e.levels - 2) // e.levels if e.levels else len(e.ncurve) // 2
                data.extend(e.ncurve)
        # each EMTC coupling's ports, after every element's signal (its block reads them: _with_components)
        port_rows = {e.name: [-1 if e.emtc["ports"][q] is None else add_signal(e.emtc["ports"][q])
                              for q, _ in EMTC_PORTS]
                     for e in self._elements if e.emtc is not None}
        fric = np.array([r for r, e in enumerate(self._elements) if e.kind == K.K_FRICTION], dtype=np.int64)
        cons = np.array([r for r, e in enumerate(self._elements) if e.kind in (K.K_GEAR, K.K_MOTION)], dtype=np.int64)
        swit = np.array([r for r, e in enumerate(self._elements)
                         if e.kind == K.K_SPRING and e.law in (K.SPRING_BACKLASH, K.SPRING_CURVE)], dtype=np.int64)
        elem[swit, K.E_MODE] = fric.size + np.arange(swit.size)
        lossy = np.array([r for r, e in enumerate(self._elements) if self._is_lossy(e)], dtype=np.int64)
        elem[lossy, K.E_MODE] = fric.size + swit.size + np.arange(lossy.size)
        elem[:, K.E_HEAT], thermal, links = self._heat_rows()
        for r, (sign, depth, given) in self._speed_plan()[2].items():   # (kernel.derive_speeds)
            elem[r, K.E_SPREAD] = sign * depth
            elem[r, K.E_SPREAD_SUP] = int(given)
        n, ne = len(index), len(self._elements)
        nk = fric.size + cons.size + lossy.size
        ext = [r for r in fric if self._elements[r].law == K.LAW_EXTERNAL]
        elem[ext, K.E_AUX] = np.arange(len(ext))
        data.extend(v[1] for v in self._inputs.values())   # the inputs' held values, last (kernel.hold_inputs)
        sig = np.array(signals, dtype=float).reshape(-1, K.N_SIG)
        work = K.new_work(n, nk, ne, fric.size, len(ext), lossy.size, sig.shape[0], len(self._thermal))
        inertia = np.array([v[0] for v in self._inertias.values()])
        p = K.DrivelineParams(inertia, elem, coef, sig,
                              np.array(data, dtype=float), fric, cons, swit, lossy, work,
                              np.zeros(max(nk, 1), dtype=np.int64),
                              np.array([0.0, 0.0, float(sum(1 for e in self._elements if e.levels))]), thermal, links)
        m0 = self._initial_modes(p, self.initial_state())   # (and the start's stored energy, work[-1])
        return p, port_rows, m0

    def _thermal_offset(self) -> int:
        """Where the thermal masses' states start in the state vector: after the angles, the speeds, one energy per
        element and the engines' idle integrals (:func:`~clutchlab.driveline.kernel.driveline_rhs`)."""
        return 2 * len(self._inertias) + len(self._elements) + len(self._controllers)

    def _state_count(self) -> int:
        """The network's own states: angles, speeds, an energy per element, the controllers', the thermal masses'."""
        return self._thermal_offset() + len(K.THERMAL_STATES) * len(self._thermal)

    def initial_state(self) -> np.ndarray:
        """Angles, speeds, then the energy states (zero).

        Speeds left out follow from the motion sources and gears (a source sets its flange, a gear
        ``w_a = ratio w_b`` carries it on); speeds given are kept, and must agree with them to 1e-9 relative:
        :meth:`system` refuses a disagreement (the network's compiled start,
        :func:`~clutchlab.driveline.kernel.kinematic_error`, which a native FMU runs again on the speeds a host sets).
        The network's compiled start carries the speeds along the gears again
        (:func:`~clutchlab.driveline.kernel.derive_speeds`, from the plan :meth:`_speed_plan` packs), so a native
        FMU derives them from the given speeds and ratios a host set.
        Raises :class:`~clutchlab.errors.ParameterError` on a loop of gears and motion sources.
        """
        n = len(self._inertias)
        x = np.zeros(self._state_count())
        o = self._thermal_offset()
        for k, tm in enumerate(self._thermal.values()):   # (kernel.THERMAL_STATES: the temperature, the heat out)
            x[o + len(K.THERMAL_STATES) * k + K.TS_TEMP] = tm.T0
        value, phi, _, _ = self._speed_plan()
        for i in range(n):
            x[i] = 0.0 if phi[i] is None else phi[i]
            x[n + i] = value[i]
        return x

    def _speed_plan(self):
        """``(speeds, angles, rows, seeds)``: the initial speeds (given, or carried from the motion sources and gears
        that bind an inertia to another, else rest), the angles (given, a position source's, else None) and the
        gears that carry a speed left out, ``{row: (sign, depth, support given)}`` -- sign +1 where flange b's
        speed follows flange a's, -1 the other way, depth that of the derived flange below the speed it follows
        (the columns ``E_SPREAD`` and ``E_SPREAD_SUP`` of :func:`~clutchlab.driveline.kernel.derive_speeds`, which
        repeats this arithmetic in the network's start), and the seeds, the inertias (indices) whose speed, left
        out, a group follows.  The speed a group of bound inertias follows: its motion source or gear to the ground,
        else its first speed given, else its first inertia's, at rest (a seed)."""
        names = list(self._inertias)
        index = {nm: i for i, nm in enumerate(names)}
        n = len(names)
        w = [v[1] for v in self._inertias.values()]
        phi = [v[2] for v in self._inertias.values()]
        groups = _Groups(n)
        links = {i: [] for i in range(n)}
        fixed = {}
        for r, e in enumerate(self._elements):
            if e.kind not in (K.K_GEAR, K.K_MOTION):
                continue
            ia = -1 if e.a is None else index[e.a]
            ib = -1 if e.b is None else index[e.b]
            if not groups.union(ia, ib):
                raise ParameterError(f"{self.name}: {e.name} closes a loop of gears and motion sources "
                                     "(the network is over-constrained)")
            if e.kind == K.K_MOTION:
                v, rate = e.signal.value_and_rate(0.0)
                fixed[ib] = v if e.law == K.MOTION_SPEED else rate
                if e.law == K.MOTION_POSITION and phi[ib] is None:   # (a given one is checked by the start)
                    phi[ib] = v
            elif ia >= 0 and ib >= 0:   # w_a - w_s = ratio (w_b - w_s), the support at its own initial speed
                ratio = e.coef[0]
                given = e.sup is not None and w[index[e.sup]] is not None
                ws = w[index[e.sup]] if given else 0.0
                links[ia].append((ib, 1.0 / ratio, (1.0 - 1.0 / ratio) * ws, r, 1, given))   # w_b from w_a
                links[ib].append((ia, ratio, (1.0 - ratio) * ws, r, -1, given))               # w_a from w_b
            else:   # a gear to the ground holds its flange at rest
                fixed[ia if ia >= 0 else ib] = 0.0
        value = [None] * n
        depth = [0] * n
        rows = {}

        def spread(start):   # (a speed given is kept, and carried on: the start refuses a disagreement)
            todo = [start]
            while todo:
                i = todo.pop()
                for j, factor, offset, r, sign, given in links[i]:
                    if value[j] is None:
                        if w[j] is None:
                            value[j] = factor * value[i] + offset
                            depth[j] = depth[i] + 1
                            rows[r] = (sign, depth[j], given)
                        else:
                            value[j] = w[j]
                        todo.append(j)

        for i, v in fixed.items():
            value[i] = v if w[i] is None else w[i]
            spread(i)
        for i in range(n):   # the first speed given in each remaining group, else rest
            if value[i] is None and w[i] is not None:
                value[i] = w[i]
                spread(i)
        seeds = []
        for i in range(n):
            if value[i] is None:
                value[i] = 0.0
                seeds.append(i)
                spread(i)
        return value, phi, rows, seeds

    def _inertia_index(self, e, sign) -> int:
        """The index of the inertia a gear ``e`` derives (flange b for ``sign`` > 0, else a)."""
        return list(self._inertias).index(e.b if sign > 0 else e.a)

    def derived_speeds(self) -> list:
        """Names of the inertias whose initial speed the description leaves out and that follow another speed
        through gears, a motion source or a gear to the ground (:meth:`initial_state`; the network's start carries
        them along the gears again): not parameters of a native FMU, whose host sets the speeds they follow.  An
        inertia left out that nothing given binds is the one its group follows (at rest unless set)."""
        seeds = self._speed_plan()[3]
        return [nm for i, (nm, v) in enumerate(self._inertias.items()) if v[1] is None and i not in seeds]

    def _initial_modes(self, p, x0):
        """The modes a run starts from, guessed from the initial state (the restart at t0 settles them at the
        forces), and the stored energy the energy balance starts from, in ``p.work[-1]``: both by the compiled
        :func:`~clutchlab.driveline.kernel.driveline_start`, the run's own ``start`` (so a native FMU decides them
        again from the initial speeds a host sets).  A one-way clutch may not start turning backward."""
        m = np.zeros(p.fric.size + p.swit.size + p.lossy.size, dtype=np.int64)
        u0 = np.array([v[1] for v in self._inputs.values()], dtype=float)
        # (through the core's entry on the network's own parameters: a run calls only its loop, and this start entry
        # compiles in 0.3 s, where the start entry of the run's type, CoupledParams, links every coupled hook the
        # start may call, 3.3 s on a fresh machine: measured, fifty-seventh session)
        code = core.start(p, 0.0, np.ascontiguousarray(x0, dtype=float), u0, m)
        if code < 0 and not start_checks_deferred():
            raise ParameterError(self._start_refusal((-code - K.INV_BASE) // K.N_INV, p, x0))
        return m

    @staticmethod
    def _shift_message(el) -> str:
        """The model error of a shifted E-clutch whose working point left its table (``K.shift_error``)."""
        return (f"{el.name}: its wear and thermal expansion moved its working point beyond the table it was built "
                f"for (wear up to wear_max, temperatures {SHIFT_TEMPERATURES[0]:g} to {SHIFT_TEMPERATURES[1]:g} "
                "degC): raise wear_max, or check the wear rate and the heat it gets")

    def _check_shift(self, el, coef, thermal_row) -> None:
        """Refuse an E-clutch that expands without a heat port, or whose initial working point is off its table."""
        expansion, t_ref = coef[K.C_EXPANSION], coef[K.C_T_REF]
        if expansion > 0.0 and thermal_row is None:
            raise ParameterError(f"{el.name}: expansion = {expansion:g} m/K needs the temperature of a thermal mass its "
                                 "losses heat (list it in a thermal_mass's heat_from), or expansion = 0")
        temp = t_ref if thermal_row is None else float(thermal_row[K.T_INIT])
        lo_t, hi_t = SHIFT_TEMPERATURES
        if expansion > 0.0 and not lo_t <= temp <= hi_t:
            raise ParameterError(f"{el.name}: its thermal mass starts at {temp:g} degC, outside [{lo_t:g}, {hi_t:g}] "
                                 "degC, the span of its expansion's table")

    def _start_refusal(self, r, p, x0) -> str:
        """The message for element row ``r`` that the network's compiled start refused (``K.INV_START``): a gear or
        motion source its flanges' initial speeds (angles) disagree with, or a one-way clutch turning backward (or
        ``K.INV_TABLE``: a shifted E-clutch off its table)."""
        n, e, el = len(self._inertias), p.elem[r], self._elements[r]
        if el.levels:
            return self._shift_message(el)
        names = list(self._inertias)

        def w(i):
            return 0.0 if i < 0 else float(x0[n + i])

        if el.kind == K.K_GEAR:
            ws = w(e[K.E_SUP])
            if e[K.E_A] < 0 or e[K.E_B] < 0:
                i = max(e[K.E_A], e[K.E_B])
                return f"{names[i]}: w0 = {w(i):g} rad/s but {el.name} gives 0 rad/s"
            want = ws + (w(e[K.E_A]) - ws) / p.coef[r, K.C_RATIO]
            return f"{names[e[K.E_B]]}: w0 = {w(e[K.E_B]):g} rad/s but {el.name} from {names[e[K.E_A]]} gives {want:g} rad/s"
        if el.kind == K.K_MOTION:
            v, rate = el.signal.value_and_rate(0.0, self._input_starts())
            i = e[K.E_B]
            if el.law == K.MOTION_POSITION and not math.isclose(x0[i], v, rel_tol=1e-9, abs_tol=1e-12):
                return f"{names[i]}: phi0 = {x0[i]:g} rad but {el.name} starts it at {v:g} rad"
            return (f"{names[i]}: w0 = {w(i):g} rad/s but {el.name} gives "
                    f"{v if el.law == K.MOTION_SPEED else rate:g} rad/s")
        return f"{el.name}: {K.INVARIANTS[K.INV_START]}: w_b - w_a = {w(e[K.E_B]) - w(e[K.E_A]):g} rad/s"

    def variables(self):
        """States and outputs as ``(name, unit, description)`` (column ``<component>.<quantity>_<unit>``)."""
        u = self._units
        (an, au, _), (wn, wu, _), (tn, tu, _), (rn, ru, _) = u["angle"], u["speed"], u["torque"], u["relative"]
        word = u["words"][2]
        states = [(f"{i}.{an}", au, f"{u['words'][1]} of {i}") for i in self._inertias]
        states += [(f"{i}.{wn}", wu, f"speed of {i}") for i in self._inertias]
        outputs = []
        for e in self._elements:
            if e.kind in (K.K_SOURCE, K.K_MOTION):
                states.append((f"{e.name}.work", "J", f"work of the source {e.name}"))
                outputs.append((f"{e.name}.{tn}", tu, f"{word} of the source {e.name} on its flange"))
            elif e.kind == K.K_GEAR:
                states.append((f"{e.name}.dissipated", "J", f"energy lost in {e.name} (its mesh and bearing losses)"))
                outputs.append((f"{e.name}.{tn}", tu, f"{word} of {e.name} on flange a (on flange b: -ratio {tn})"))
            elif e.kind == K.K_CONVERTER:   # (kernel.driveline_outputs: tau, w_rel, tau_b, speed ratio, loss)
                states.append((f"{e.name}.dissipated", "J", f"energy lost in {e.name} (heat in its fluid)"))
                outputs += [(f"{e.name}.{tn}", tu, f"{word} of {e.name} on its impeller, flange a (-T_p driving)"),
                            (f"{e.name}.{rn}", ru, f"relative speed of {e.name}, turbine minus impeller"),
                            (f"{e.name}.{tn}_b", tu, f"{word} of {e.name} on its turbine, flange b (T_t driving)"),
                            (f"{e.name}.speed_ratio", "1", f"speed ratio of {e.name}, turbine over impeller "
                                                           "against its support (0 with the impeller at rest)"),
                            (f"{e.name}.loss_power", "W", f"power {e.name} dissipates, T_p w_p - T_t w_t")]
            else:
                states.append((f"{e.name}.dissipated", "J", f"energy dissipated in {e.name}"))
                outputs.append((f"{e.name}.{tn}", tu, f"{word} of {e.name} (on flange b: -{tn})"))
                outputs.append((f"{e.name}.{rn}", ru, f"relative speed of {e.name}, flange b minus flange a"))
        states += [(f"{e.name}.idle_integral", tu, f"integral of the idle-speed controller of {e.name}")
                   for e in self._controllers]
        states += [(f"{tm.name}.{q}", unit, what.format(tm.name)) for tm in self._thermal.values()
                   for q, unit, what in K.THERMAL_STATE_DECL]
        for name in self.friction_names:
            outputs.append((f"{name}.mode", "1", f"mode of {name}: 1 forward, 0 stuck, -1 backward, 2 free (MSL)"))
            outputs.append((f"{name}.fn", "N", f"normal force of {name}"))
        for e in self._lossy:
            outputs.append((f"{e.name}.mode", "1", f"mode of {e.name}: 1 forward rolling, 0 stuck, -1 backward rolling "
                                                   "(MSL LossyGear)"))
        outputs += [("kinetic_energy", "J", "kinetic energy of the inertias"),
                    ("spring_energy", "J", "energy stored in the springs"),
                    ("input_work", "J", "work of the sources since the start"),
                    ("dissipated_energy", "J", "energy dissipated since the start"),
                    ("energy_error", "J", "input work - dissipated - change of the stored energy")]
        outputs += [(f"{tm.name}.{q}", unit, what.format(tm.name)) for tm in self._thermal.values()
                    for q, unit, what in K.THERMAL_OUTPUT_DECL]
        return tuple(states), tuple(outputs)

    def system(self, rtol: float = 1e-8, check_invariants: bool = False) -> System:
        """The :class:`~clutchlab.system.System` of this network (Dormand-Prince 5(4), events to 1e-12 s).

        With wet clutches (:meth:`wet_clutch`) or EMTC couplings (:meth:`emtc`), any number of each, its
        parameters are a :class:`~clutchlab.driveline.coupled.CoupledParams` (one compiled kernel for every mix)
        and its states, outputs, switching functions, modes and events follow the network's, the wet clutches'
        first (named ``<component>.<quantity>``; a full hysteresis memory of a coupling's magnet is a model error
        naming the coupling).  That system holds the couplings' memories (magnet, controller) as the EMTC
        bench's does: one run per system (:meth:`simulate` builds one per call).  ``check_invariants``: check
        the invariants of every element at every accepted step (:func:`~clutchlab.driveline.kernel.check_invariants`; the energy balance to ``max(1e-7, 1000
        rtol)`` of the energy that flowed plus 1 J); a violation ends the run with a
        :class:`~clutchlab.errors.SimulationError` naming the element, the invariant and the time."""
        # the kernel functions called through their addresses, compiled or loaded here, on the calling thread: a
        # batch's worker threads then only look their addresses up (clutchlab.numerics.outline); the invariant
        # check only where it is asked for (a debug option: not compiled on every first use), the hooks of a network
        # with model components only for one (clutchlab.driveline.coupled)
        components = any(el.wet is not None or el.emtc is not None or el.ecl is not None for el in self._elements)
        actuators = any(el.ecl is not None for el in self._elements)
        outline.prepare(lazy=check_invariants, groups=(("coupled",) if components else ())
                        + (("eclutch_network",) if actuators else ()))
        p, port_rows, m0 = self._pack()
        if check_invariants:
            p.check[0] = 1.0
            p.check[1] = _check_tol(rtol)
        x0 = self.initial_state()
        states, outputs = self.variables()
        fric = self.friction_names
        switching = tuple((f"{f}.{what}", d) for f in fric for what, d in K.FRICTION_LAYOUT)
        swit = [self._elements[r] for r in p.swit]
        # (a switched spring's, by its law: kernel.BACKLASH_LAYOUT, kernel.CURVE_LAYOUT)
        switching += tuple((f"{e.name}.{side}", d) for e in swit
                           for side, d in (K.BACKLASH_LAYOUT if e.law == K.SPRING_BACKLASH else K.CURVE_LAYOUT))
        named = fric + tuple(e.name for e in swit) + tuple(e.name for e in self._lossy)
        switching += tuple((f"{e.name}.{what}", d) for e in self._lossy for what, d in K.GEAR_LAYOUT)
        # a torque converter's corners (kernel.converter_piece: a waypoint either way, in element order)
        switching += tuple((f"{e.name}.piece", 4) for e in self._elements if e.kind == K.K_CONVERTER)
        # an engine's corners (kernel.engine_corners: its map's speed and throttle nodes, its idle clip's edges)
        switching += tuple((f"{e.name}.{what}", d) for e in self._elements
                           if e.kind == K.K_SOURCE and e.law == K.SOURCE_ENGINE for what, d in K.ENGINE_LAYOUT)
        mode_names = named
        swit_values = tuple((K.LASH_MSL_VALUES if e.aux == K.LASH_MSL else K.LASH_KV_VALUES)
                            if e.law == K.SPRING_BACKLASH else tuple(f"segment {i}" for i in range(len(e.table) // 4 + 1)) for e in swit)
        mode_values = tuple(K.MODE_VALUES for _ in fric) + swit_values + tuple(K.GEAR_VALUES for _ in self._lossy)
        named_modes = m0   # (the network's own: driveline_start decides them)
        n = len(self._inertias)
        derived = sorted({self._inertia_index(self._elements[r], sign)
                          for r, (sign, _, _) in self._speed_plan()[2].items()})
        atol = float(rtol) * np.ones(self._state_count())
        events = K.EVENTS
        wet = self._wet_parameters()
        emtcs = self._emtc_parameters()
        ecls = self._eclutch_parameters(rtol)
        error_messages = None
        stiff = {}
        if wet or emtcs or ecls:
            from ..eclutch import system as ES
            from ..emtc import system as S
            from ..wet import system as W
            from . import eclutch as DA
            from . import emtc as DE
            from .wet import OUTPUTS as WET_OUTPUTS

            p, x0, m0, atol = self._with_components(p, x0, m0, atol, wet, emtcs, ecls, rtol, len(switching),
                                                    len(named), port_rows)
            for el, *_ in wet:
                states += tuple((f"{el.name}.{q}", unit, d) for q, unit, d in W.STATES)
                switching += tuple((f"{el.name}.{q}", d) for q, d in W.SWITCHING)
                named += (el.name, f"{el.name}.piston")
                mode_names += tuple(f"{el.name}.{q}" for q in W.MODE_NAMES)
                mode_values += W.MODE_VALUES
            for el, *_ in emtcs:
                states += tuple((f"{el.name}.{q}", unit, d) for q, unit, d in S.STATES)
                switching += tuple((f"{el.name}.{q}", d) for q, d in S.SWITCHING)
                named += tuple(f"{el.name}.{q}" for q in S.ELEMENTS)
                mode_names += tuple(f"{el.name}.{q}" for q in S.MODE_NAMES)
                mode_values += S.MODE_VALUES
            for el, ec, es, *_ in ecls:
                # (under <name>.actuator: the element's own dissipated energy is <name>.dissipated)
                states += tuple((f"{el.name}.actuator.{v.name}", v.unit, v.description) for v in es.states)
                switching += tuple((f"{el.name}.{q}", d) for q, d in es.switching)
                named += DA.element_names(el.name, ec.assembly)
                mode_names += tuple(f"{el.name}.{q}" for q in es.mode_names)
                mode_values += es.mode_values
            for el, *_ in wet:
                outputs += tuple((f"{el.name}.{q}", unit, d) for q, unit, d in WET_OUTPUTS)
            for el, *_ in emtcs:
                outputs += tuple((f"{el.name}.{q}", unit, d) for q, unit, d in DE.OUTPUTS)
            for el, *_ in ecls:
                outputs += tuple((f"{el.name}.{q}", unit, d) for q, unit, d in DA.OUTPUTS)
            events = K.EVENTS + W.EVENTS + S.EVENTS + ES.EVENTS
            error_messages = {code - DE.ERROR_STRIDE * j: f"{el.name}: {text}" for j, (el, *_) in enumerate(emtcs)
                              for code, text in S.ERROR_MESSAGES.items()}
            error_messages.update({code - DA.ERROR_STRIDE * j: f"{el.name}: {text}" for j, (el, *_) in enumerate(ecls)
                                   for code, text in ES.ERROR_MESSAGES.items()})
            if ecls:   # the actuators are stiff and have algebraic rows: Rodas3 with their mass matrix (eclutch.py)
                stiff = self._stiff_options(len(x0) - sum(len(es.x0) for _, _, es, *_ in ecls), ecls, atol)
        else:   # (one compiled kernel for every network: a plain one is a network with no component rows)
            from . import coupled as DC

            p = DC.CoupledParams.plain(p)

        names_rows = [e.name for e in self._elements]
        invariant_messages = {-(K.INV_BASE + K.N_INV * r + kind): f"invariant violated: {nm}: {what}"
                              for r, nm in enumerate(names_rows) for kind, what in enumerate(K.INVARIANTS)
                              if kind not in (K.INV_TABLE, K.INV_START)}
        for r, e in enumerate(self._elements):
            if e.kind == K.K_GEAR and self._is_lossy(e):
                invariant_messages[-(K.INV_BASE + K.N_INV * r + K.INV_TABLE)] = f"{e.name}: {_table_limit(e.table)}"
            if e.levels:
                invariant_messages[-(K.INV_BASE + K.N_INV * r + K.INV_TABLE)] = self._shift_message(e)
            if e.kind == K.K_FRICTION and e.law == K.LAW_ONEWAY:
                invariant_messages[-(K.INV_BASE + K.N_INV * r + K.INV_START)] = (
                    f"{e.name}: {K.INVARIANTS[K.INV_START]}")
            elif e.kind in (K.K_GEAR, K.K_MOTION):   # (kernel.kinematic_error)
                invariant_messages[-(K.INV_BASE + K.N_INV * r + K.INV_START)] = (
                    f"{e.name}: the initial speeds of its flanges disagree with its ratio (w_a - w_s = ratio (w_b - "
                    "w_s))" if e.kind == K.K_GEAR else
                    f"{e.name}: the initial speed (or angle) of its flange disagrees with the motion it imposes")
        invariant_messages[-(K.INV_BASE + K.N_INV * len(names_rows) + K.INV_ENERGY)] = (
            f"invariant violated: the network's {K.INVARIANTS[K.INV_ENERGY]} ({_check_tol(rtol):.3g} of the energy "
            "that flowed)")
        error_messages = {**invariant_messages, **(error_messages or {})}

        def element_name(code, element, _names=named):
            return _names[element] if 0 <= element < len(_names) else ""

        # the switching functions follow the sources: a step holds at most an eighth of a sine's period, so a
        # stuck element whose torque swings past its limit and back within one step is not stepped over
        freqs = [f.row[2] for e in self._elements if e.signal is not None
                 for f in (e.signal.factors or (e.signal,)) if f.row[0] == K.SIG_SINE]
        max_step = min((0.125 / f for f in freqs if f > 0), default=math.inf)
        # an actuator's own largest step (10 ms: its runs are tested with it), as the network's default
        max_step = min([max_step] + [es.max_step for _, _, es, *_ in ecls])
        inputs = tuple((n, unit, d or f"network input {n}") for n, (unit, _start, d) in self._inputs.items())
        u0 = np.array([v[1] for v in self._inputs.values()], dtype=float) if inputs else None
        return System(name=self.name, params=p, states=states, outputs=outputs, inputs=inputs, u0=u0, x0=x0,
                      m0=m0, atol=atol, switching=switching, events=events, mode_names=mode_names,
                      mode_values=mode_values, rtol=float(rtol), max_step=max_step, event_tol=1e-12,
                      **(stiff or {"method": "dopri"}),
                      element_name=element_name, error_messages=error_messages,
                      decided_at_start=(("m", 0, len(named_modes)),
                                        ("params.net.work", -1, None))
                      + tuple(("x", n + i, n + i + 1) for i in derived)   # (kernel.derive_speeds)
                      + (tuple((f"params.wet.params.constants.data.{name}", 0, None)
                               for name in W.DERIVED_CONSTANTS) if wet else ())
                      + (tuple((f"params.emtc.params.actuator.data.{name}", 0, None) for name in S.DERIVED_ACTUATOR)
                         + (("params.emtc.params.controller_table.data", 0, None),) if emtcs else ())
                      # (an actuator's start derives its compliances, line and master words and its master's mass
                      # and seal friction: clutchlab.eclutch.system.eclutch_start)
                      + ((("params.ecl.params.par.data", 0, None), ("params.ecl.params.coord.data", 0, None))
                         if ecls else ()))

    @staticmethod
    def _stiff_options(nx0, ecls, atol) -> dict:
        """The :class:`~clutchlab.system.System` options of a network with E-clutch actuators (``ecls``): Rodas3, the
        actuators' mass matrices (their massless nodes' rows algebraic) and finite-difference scales, the network's
        and other components' states first (``nx0`` of them; their scales the absolute tolerances ``atol``, as the
        System's default); the Jacobian's difference columns all but the actuators' energies; inputs that vary
        inside a step (the network's signals)."""
        nx = atol.size
        mass, scale, cols = np.ones(nx), np.maximum(atol, 1e-12), list(range(nx0))
        o = nx0
        for _el, _ec, es, *_ in ecls:
            n = len(es.x0)
            mass[o:o + n] = es.mass
            scale[o:o + n] = es.fd_scale
            cols += [o + c for c in es.jac_cols]
            o += n
        # the Jacobian kept for up to ten accepted steps, as the actuator's own runs do (refreshed after every event
        # and every rejected step): the launch example at rtol 1e-6 in 0.51 s against 1.7 s for a Jacobian at every
        # step, the engine's speed at 5 s 383.0665 against 383.0642 rad/s (the solve ahead: 383.0622)
        return dict(method="rodas", mass=mass, fd_scale=scale, jac_cols=np.array(cols, dtype=np.int64),
                    nonautonomous=True, jac_every=10)

    def _with_components(self, p, x0, m0, atol, wet, emtcs, ecls, rtol, ng, nel, port_rows):
        """The network's parameters, initial state and modes and absolute tolerances joined with its wet clutches'
        and EMTC couplings' (:class:`~clutchlab.driveline.coupled.CoupledParams`; the layout in
        :mod:`clutchlab.driveline.coupled`).  A coupling starts with its armature at rest, its coil current at its
        magnet's lowest grid current and its shaft speeds the flanges'."""
        from ..emtc import system as S
        from ..wet import system as W
        from . import coupled as DC
        from . import eclutch as DA
        from . import emtc as DE
        from . import wet as DW

        n = len(self._inertias)
        nx, nm, nw = x0.size, m0.size, len(wet)
        xs, ms, tols = [x0], [m0], [atol]

        def friction_index(el):
            r = self._elements.index(el)
            return r, int(np.flatnonzero(p.fric == r)[0])

        conf, packed = [], []
        for j, (el, wp, xw, clutch) in enumerate(wet):
            r, k = friction_index(el)
            w_rel = (x0[n + p.elem[r][K.E_B]] if p.elem[r][K.E_B] >= 0 else 0.0) - (
                x0[n + p.elem[r][K.E_A]] if p.elem[r][K.E_A] >= 0 else 0.0)
            xw = xw.copy()
            xw[W.S_W] = w_rel
            # the actuator starts at its reference's start (the inputs at their starts), saturated as the model does
            most = float(np.ravel(wp.constants["actuator_force_max"])[0])
            xw[W.S_FA] = min(max(el.signal.value_and_rate(0.0, self._input_starts())[0], 0.0), most)
            conf.append([k, r, nx + j * W.N_STATE, ng + j * W.N_SWITCH, nm + j * DW.N_MODE, len(K.EVENTS),
                         nel + 2 * j, p.elem[r][K.E_SIGNAL]])
            xs.append(xw)
            ms.append(W.initial_modes(xw, clutch.piston_h0))
            tols.append(W.absolute_tolerance(clutch, rtol))
            packed.append(wp)
        wblock = DW.block(packed, conf)
        nx += nw * W.N_STATE
        ng += nw * W.N_SWITCH
        nm += nw * DW.N_MODE
        nel += 2 * nw
        conf, packed = [], []
        for j, (el, ep, magnet) in enumerate(emtcs):
            r, k = friction_index(el)
            i0 = float(magnet.grid[0])
            xs.append(np.array([x0[n + p.elem[r][K.E_A]], x0[n + p.elem[r][K.E_B]], 0.0, 0.0, 0.0, i0, i0]))
            conf.append([k, r, nx + j * DE.N_STATE, ng + j * DE.N_SWITCH, nm + j * DE.N_MODE,
                         len(K.EVENTS) + len(W.EVENTS), nel + len(S.ELEMENTS) * j, *port_rows[el.name]])
            ms.append(np.array([DE._REST, DE._OPEN, DE._POSITIVE], dtype=np.int64))   # armature at rest, open
            # the bench's tolerances are for its rtol 1e-6; the shaft speeds and twist follow the network's
            ae = S.ATOL * (float(rtol) / 1e-6)
            ae[:3] = float(rtol)
            tols.append(ae)
            packed.append(ep)
        nx += len(emtcs) * DE.N_STATE
        ng += len(emtcs) * DE.N_SWITCH
        nm += len(emtcs) * DE.N_MODE
        nel += len(S.ELEMENTS) * len(emtcs)
        eblock = DE.block(packed, conf)
        conf, packed = [], []
        for j, (el, ec, es, xa, ma) in enumerate(ecls):
            r, k = friction_index(el)
            nxa, nga, nma = len(es.x0), len(es.switching), len(es.m0)
            conf.append([k, r, nx, ng, nm, len(K.EVENTS) + len(W.EVENTS) + len(S.EVENTS), nel,
                         p.elem[r][K.E_SIGNAL], nxa, nga, nma, len(ec.assembly.coord_names),
                         len(ec.assembly.element_names), len(es.outputs)])
            xs.append(xa)
            ms.append(ma)
            tols.append(es.atol)
            packed.append(es.params)
            nx, ng, nm = nx + nxa, ng + nga, nm + nma
            nel += len(DA.element_names(el.name, ec.assembly))
        params = DC.CoupledParams(p, wblock, eblock, DA.block(packed, conf))
        return params, np.concatenate(xs), np.concatenate(ms), np.concatenate(tols)

    def simulate(self, t_end: float, *, rtol: float = 1e-8, atol=None, max_step: float | None = None,
                 output_step: float | None = None, sample_times=None, fixed_step: float | None = None,
                 check_invariants: bool = False, inputs: dict | None = None):
        """Run the network from its initial state to ``t_end`` [s]; a :class:`~clutchlab.SimulationResult`.

        Parameters
        ----------
        t_end : float
            End time [s].
        rtol : float
            Relative tolerance of the Dormand-Prince 5(4) step control (:meth:`system`).
        atol : float or array_like, optional
            Absolute tolerance per state (default: the network's, from ``rtol``).
        max_step : float, optional
            Largest step [s] (default: an eighth of the period of the fastest sine source, none without one).
        output_step : float, optional
            Sample interval [s] of the result (default: every accepted step).
        sample_times : array_like, optional
            Explicit sample times [s] instead of ``output_step``.
        fixed_step : float, optional
            Fixed-step (real-time, HIL frame) mode with this step [s]: Rodas3 steps on the grid
            ``k * fixed_step``, the mode changes (stick, slip, reversal) at the first step end after them
            (:func:`clutchlab.system.simulate`); ``rtol``, ``atol`` and ``max_step`` are then unused.  None
            (default): step-size control.
        check_invariants : bool
            Debug option: check at every accepted step that every stuck element is within its static limit, every
            mode agrees with the sign of its relative speed, no one-way clutch transmits torque in its free
            direction, no lossy gear generates power and the energy balance holds (:meth:`system`); a violation
            raises :class:`~clutchlab.errors.SimulationError` naming the element, the invariant and the time.
        inputs : dict, optional
            What drives the network's inputs (:meth:`input`) in this run, by name: a number (held), a
            :class:`Signal` or ``(times, values)`` (a table); an input not named holds its ``start``.
        """
        net = self.with_inputs(inputs) if inputs else self
        return _simulate(net.system(rtol, check_invariants=check_invariants), t_end, atol=atol, max_step=max_step, output_step=output_step,
                         sample_times=sample_times, fixed_step=fixed_step)


def _check_tol(rtol: float) -> float:
    """The energy-balance tolerance of ``check_invariants`` [-]: ``max(1e-7, 1000 rtol)`` of the energy that flowed
    plus 1 J."""
    return max(1e-7, 1e3 * float(rtol))


def _example_system(rtol: float = 1e-8) -> System:
    """The registered factory: ModelicaTest's TestFriction bearing row (a default to run through the contract)."""
    d = Driveline("driveline")
    d.inertia("inertia", J=1.0)
    d.torque("torque", "inertia", Signal.sine(10.0, 1.0))
    d.bearing_friction("bearing_friction", "inertia", torque=1.0)
    return d.system(rtol)


register_model("driveline", _example_system)
