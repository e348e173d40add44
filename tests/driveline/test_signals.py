"""The MSL ``Blocks.Sources`` signals of a driveline -- pulse, trapezoid, exponentials and the product of two
signals -- against their closed forms written here from MSL's equations (``Modelica/Blocks/Sources.mo``:
``Pulse``, ``Trapezoid``, ``Exponentials``; ``Blocks/Math.mo``: ``Product``), in the compiled kernel and its
Python twin, with their breaks; networks driven by each against the closed-form integral; the TOML reader.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from clutchlab.driveline import Driveline, Signal
from clutchlab.driveline import kernel as K
from clutchlab.driveline.description import parse_driveline
from clutchlab.errors import ParameterError


# ----------------------------------------------------------------- MSL's equations, as closed forms
def msl_pulse(t, amplitude, width, period, nperiod=-1, offset=0.0, start=0.0):
    """MSL ``Pulse`` (``width`` here a fraction, MSL's ``width/100``): ``count = integer((time - startTime) /
    period)``, ``T_start = startTime + count period``; ``y = offset + (0 if time < startTime or nperiod == 0
    or (nperiod > 0 and count >= nperiod) else amplitude if time < T_start + T_width else 0)``."""
    if t < start or nperiod == 0:
        return offset
    count = math.floor((t - start) / period)
    if nperiod > 0 and count >= nperiod:
        return offset
    return offset + (amplitude if t < start + count * period + period * width else 0.0)


def msl_trapezoid(t, amplitude, rising, width, falling, period, nperiod=-1, offset=0.0, start=0.0, rate=False):
    """MSL ``Trapezoid``: ``amplitude (time - T_start) / rising`` before ``T_start + T_rising``, ``amplitude``
    before ``T_start + T_width``, ``amplitude (T_start + T_falling - time) / falling`` before ``T_start +
    T_falling``, else 0 (plus offset); with ``rate``, its time derivative instead."""
    if t < start or nperiod == 0:
        return 0.0 if rate else offset
    count = math.floor((t - start) / period)
    if nperiod > 0 and count >= nperiod:
        return 0.0 if rate else offset
    tau = t - (start + count * period)
    if tau < rising:
        return amplitude / rising if rate else offset + amplitude * tau / rising
    if tau < rising + width:
        return 0.0 if rate else offset + amplitude
    if tau < rising + width + falling:
        return -amplitude / falling if rate else offset + amplitude * (rising + width + falling - tau) / falling
    return 0.0 if rate else offset


def msl_exponentials(t, out_max, rise_time, rise_time_const, fall_time_const, offset=0.0, start=0.0, rate=0):
    """MSL ``Exponentials``: ``y_riseTime = outMax (1 - exp(-riseTime / riseTimeConst))``; ``y = offset + (0 if
    time < startTime else outMax (1 - exp(-(time - startTime) / riseTimeConst)) if time < startTime +
    riseTime else y_riseTime exp(-(time - startTime - riseTime) / fallTimeConst))``; ``rate`` 1 or 2: its
    first or second time derivative."""
    if t < start:
        return 0.0 if rate else offset
    if t < start + rise_time:
        e = math.exp(-(t - start) / rise_time_const)
        return (offset + out_max * (1.0 - e), out_max / rise_time_const * e,
                -out_max / rise_time_const ** 2 * e)[rate]
    y = out_max * (1.0 - math.exp(-rise_time / rise_time_const)) * math.exp(-(t - start - rise_time) / fall_time_const)
    return (offset + y, -y / fall_time_const, y / fall_time_const ** 2)[rate]


# their integrals from 0 (a torque source on an inertia J from rest: w(t) = integral / J)
def pulse_integral(t, amplitude, width, period, nperiod=-1, offset=0.0, start=0.0):
    total = offset * t
    if t <= start:
        return total
    k = math.floor((t - start) / period)
    full = k if nperiod < 0 else min(k, nperiod)
    partial = min(t - (start + k * period), width * period) if (nperiod < 0 or k < nperiod) else 0.0
    return total + amplitude * (full * width * period + partial)


def trapezoid_integral(t, amplitude, rising, width, falling, period, nperiod=-1, offset=0.0, start=0.0):
    total = offset * t
    if t <= start:
        return total
    area = amplitude * (0.5 * rising + width + 0.5 * falling)
    k = math.floor((t - start) / period)
    full = k if nperiod < 0 else min(k, nperiod)
    total += full * area
    if nperiod >= 0 and k >= nperiod:
        return total
    tau = t - (start + k * period)
    if tau < rising:
        return total + amplitude * tau ** 2 / (2.0 * rising)
    if tau < rising + width:
        return total + amplitude * (0.5 * rising + tau - rising)
    tf = rising + width + falling
    if tau < tf:
        return total + area - amplitude * (tf - tau) ** 2 / (2.0 * falling)
    return total + area


def exponentials_integral(t, out_max, rise_time, rise_time_const, fall_time_const, offset=0.0, start=0.0):
    total = offset * t
    if t <= start:
        return total
    s = t - start
    if s < rise_time:
        return total + out_max * (s - rise_time_const * (1.0 - math.exp(-s / rise_time_const)))
    y_rise = out_max * (1.0 - math.exp(-rise_time / rise_time_const))
    return (total + out_max * (rise_time - rise_time_const * (1.0 - math.exp(-rise_time / rise_time_const)))
            + y_rise * fall_time_const * (1.0 - math.exp(-(s - rise_time) / fall_time_const)))


PULSE = dict(amplitude=3.0, width=0.3, period=0.1, nperiod=4, offset=-1.0, start=0.05)
TRAPEZOID = dict(amplitude=2.0, rising=0.02, width=0.03, falling=0.04, period=0.13, nperiod=-1, offset=0.5,
                 start=0.01)
EXPONENTIALS = dict(out_max=4.0, rise_time=0.15, rise_time_const=0.05, fall_time_const=0.08, offset=0.25,
                    start=0.1)
T_END = 0.6


def _corners(kind):
    """The corners of each test signal in [0, T_END] (jumps and kinks), from MSL's parameters."""
    if kind == "pulse":
        p = PULSE
        return sorted({p["start"] + k * p["period"] + c for k in range(p["nperiod"])
                       for c in (0.0, p["width"] * p["period"])})
    if kind == "trapezoid":
        p = TRAPEZOID
        cs = (0.0, p["rising"], p["rising"] + p["width"], p["rising"] + p["width"] + p["falling"])
        return sorted({p["start"] + k * p["period"] + c for k in range(10) for c in cs
                       if p["start"] + k * p["period"] + c <= T_END})
    p = EXPONENTIALS
    return [p["start"], p["start"] + p["rise_time"]]


SIGNALS = {
    "pulse": (Signal.pulse(**PULSE), lambda t: msl_pulse(t, **PULSE)),
    "trapezoid": (Signal.trapezoid(**TRAPEZOID), lambda t: msl_trapezoid(t, **TRAPEZOID)),
    "exponentials": (Signal.exponentials(**EXPONENTIALS), lambda t: msl_exponentials(t, **EXPONENTIALS)),
}


def _packed(sig):
    """The kernel's row and data of ``sig`` (as the network packs it)."""
    d = Driveline("signal")
    d.inertia("J", J=1.0)
    d.torque("T", "J", sig)
    p = d.pack()
    return p.signals[0], p.data


def _times(corners):
    """Many times in [0, T_END], and just before and after every corner (none within rounding of a corner,
    where the closed form's sums and the kernel's may fall on either side: the corners themselves are checked
    at the kernel's break times)."""
    near = [c + s for c in corners for s in (-1e-7, -1e-10, 1e-10, 1e-7)]
    grid = [t for t in np.linspace(0.0, T_END, 1201) if min(abs(t - c) for c in corners) > 1e-12]
    return np.unique(np.concatenate([grid, near]))


def _right(t, corners):
    """Where a closed form is read at ``t``: just after a corner (a break time) ``t`` is on: the kernel's value
    and rate at a break are those after it."""
    return t + 1e-12 if min(abs(t - c) for c in corners) < 1e-13 else t


# ----------------------------------------------------------------- values, rates and breaks
@pytest.mark.parametrize("kind", list(SIGNALS))
def test_each_signal_is_msls_closed_form_in_the_kernel_and_its_python_twin(kind):
    sig, closed = SIGNALS[kind]
    row, data = _packed(sig)
    corners = _corners(kind)
    for t in _times(corners):
        want = closed(_right(t, corners))
        assert K.signal_value(row, data, t) == pytest.approx(want, abs=1e-9), (kind, t)
        assert sig.value_and_rate(t)[0] == pytest.approx(want, abs=1e-9), (kind, t)
    for c in _breaks(row, data, T_END):   # at a break itself: the value after it (a jump belongs to the next step)
        assert K.signal_value(row, data, c) == pytest.approx(closed(c + 1e-12), abs=1e-9), (kind, c)


def test_rates_are_the_derivatives_of_msls_equations_from_the_right():
    """Trapezoid: its slopes (from the right at a corner); exponentials: the first and second derivatives of
    its two exponentials; the pulse: none (a jump has no rate)."""
    for kind, rates in (("trapezoid", lambda t: (msl_trapezoid(t, **TRAPEZOID, rate=True), 0.0)),
                        ("exponentials", lambda t: (msl_exponentials(t, **EXPONENTIALS, rate=1),
                                                    msl_exponentials(t, **EXPONENTIALS, rate=2))),
                        ("pulse", lambda t: (0.0, 0.0))):
        sig, _ = SIGNALS[kind]
        row, data = _packed(sig)
        corners = _corners(kind)
        breaks = _breaks(row, data, T_END)
        for t in list(_times(corners)) + breaks:
            want = rates(_right(t, breaks))
            got = K.signal_rates(row, data, t)
            assert got[0] == pytest.approx(want[0], rel=1e-9, abs=1e-9), (kind, t)
            assert got[1] == pytest.approx(want[1], rel=1e-9, abs=1e-9), (kind, t)
            assert sig.value_and_rate(t)[1] == pytest.approx(want[0], rel=1e-9, abs=1e-9), (kind, t)


def _breaks(row, data, t_end):
    out, t = [], -1.0
    while True:
        t = K.signal_break(row, data, t)
        if t > t_end:
            return out
        out.append(t)


@pytest.mark.parametrize("kind", list(SIGNALS))
def test_every_corner_is_a_break(kind):
    """Every jump and kink is a break of the integrator (so it restarts there), and each break is a corner
    or the start of a period."""
    sig, _ = SIGNALS[kind]
    row, data = _packed(sig)
    got = _breaks(row, data, T_END)
    corners = _corners(kind)
    for c in corners:
        assert min(abs(b - c) for b in got) < 1e-12, (kind, c, got)
    if kind != "exponentials":
        p = PULSE if kind == "pulse" else TRAPEZOID
        starts = [p["start"] + k * p["period"] for k in range(20)]
        for b in got:
            assert min(abs(b - c) for c in corners + starts) < 1e-12, (kind, b)
    else:
        assert len(got) == 2
    assert np.all(np.diff(got) > 0)


def test_the_pulse_stops_after_nperiod_periods_and_never_starts_with_none():
    row, data = _packed(Signal.pulse(1.0, 0.5, 1.0, nperiod=2, offset=0.5))
    assert [K.signal_value(row, data, t) for t in (0.25, 0.75, 1.25, 2.25, 3.25)] == [1.5, 0.5, 1.5, 0.5, 0.5]
    assert K.signal_break(row, data, 1.6) == 2.0 and K.signal_break(row, data, 2.0) == np.inf
    row, data = _packed(Signal.pulse(1.0, 0.5, 1.0, nperiod=0))
    assert K.signal_value(row, data, 0.25) == 0.0 and K.signal_break(row, data, -1.0) == np.inf
    # width 1: on for the whole period
    row, data = _packed(Signal.pulse(2.0, 1.0, 0.1))
    assert all(K.signal_value(row, data, t) == 2.0 for t in np.linspace(0.0, 1.0, 1001))


def test_a_period_boundary_that_rounds_is_still_the_next_period():
    """``(0.3 - 0) / 0.1`` rounds to 2.9999999999999996: the period starting at ``0 + 3 * 0.1`` must still
    hold ``t = 0.3`` (value and break agree, so a step restarting at the break sees the new period)."""
    row, data = _packed(Signal.pulse(1.0, 0.5, 0.1))
    tb = K.signal_break(row, data, 0.26)
    assert tb == 3 * 0.1
    assert K.signal_value(row, data, tb) == 1.0 and K.signal_value(row, data, tb * (1 - 1e-15)) == 0.0


def test_product_is_the_product_of_its_factors_with_both_breaks():
    a = Signal.trapezoid(**TRAPEZOID)
    b = Signal.exponentials(**EXPONENTIALS)
    prod = Signal.product(a, b)
    row, data = _packed(prod)
    corners = sorted(_corners("trapezoid") + _corners("exponentials"))
    for t in _times(corners):
        tr = _right(t, corners)
        ya, ra = msl_trapezoid(tr, **TRAPEZOID), msl_trapezoid(tr, **TRAPEZOID, rate=True)
        yb, rb = msl_exponentials(tr, **EXPONENTIALS), msl_exponentials(tr, **EXPONENTIALS, rate=1)
        rb2 = msl_exponentials(tr, **EXPONENTIALS, rate=2)
        assert K.signal_value(row, data, t) == pytest.approx(ya * yb, abs=1e-9)
        d1, d2 = K.signal_rates(row, data, t)
        assert d1 == pytest.approx(ra * yb + ya * rb, rel=1e-9, abs=1e-9)
        assert d2 == pytest.approx(2.0 * ra * rb + ya * rb2, rel=1e-9, abs=1e-9)   # the trapezoid's second is 0
        assert prod.value_and_rate(t)[1] == pytest.approx(ra * yb + ya * rb, rel=1e-9, abs=1e-9)
    got = _breaks(row, data, T_END)
    for c in corners:
        assert min(abs(x - c) for x in got) < 1e-12
    # nested products are one product of their factors; numbers are constants
    nested = Signal.product(Signal.product(2.0, Signal.sine(1.0, 1.0)), Signal.pulse(1.0, 0.5, 1.0))
    assert len(nested.factors) == 3 and nested.factors[0] == Signal.constant(2.0)
    row, data = _packed(nested)
    assert K.signal_value(row, data, 0.125) == pytest.approx(2.0 * math.sin(2 * math.pi * 0.125), abs=1e-15)
    assert K.signal_value(row, data, 0.625) == 0.0


# ----------------------------------------------------------------- networks driven by each signal
def _speed_of_torque(sig, J, times):
    d = Driveline("driven")
    d.inertia("J", J=J)
    d.torque("T", "J", sig)
    res = d.simulate(T_END, sample_times=times, rtol=1e-11)
    return res.to_dataframe()


def _sample_times():
    return np.linspace(0.0, T_END, 241)


@pytest.mark.parametrize("kind, integral", [
    ("pulse", lambda t: pulse_integral(t, **PULSE)),
    ("trapezoid", lambda t: trapezoid_integral(t, **TRAPEZOID)),
    ("exponentials", lambda t: exponentials_integral(t, **EXPONENTIALS)),
])
def test_a_torque_source_accelerates_an_inertia_by_the_signals_integral(kind, integral):
    """J dw/dt = signal(t) from rest: w(t) = (1/J) * the closed-form integral of MSL's signal, to 1e-8."""
    J = 0.5
    times = _sample_times()
    df = _speed_of_torque(SIGNALS[kind][0], J, times)
    want = np.array([integral(t) / J for t in times])
    assert np.max(np.abs(df["J.w_rad_s"].to_numpy() - want)) < 1e-8
    assert np.max(np.abs(df["energy_error_J"].to_numpy())) < 1e-8


def test_a_pulse_gated_sine_drives_as_the_sum_of_its_on_intervals():
    """The product of a sine torque (3 N m at 2 Hz, times 2) and a dimensionless pulse (on for 40 % of 0.15 s
    from 0.05 s): w = (1/J) sum over the on-intervals [a, b] of 6 (cos(w a) - cos(w b)) / w."""
    J, om = 0.4, 2.0 * math.pi * 2.0
    sig = Signal.product(Signal.product(Signal.sine(3.0, 2.0), 2.0), Signal.pulse(1.0, 0.4, 0.15, start=0.05))
    times = _sample_times()
    df = _speed_of_torque(sig, J, times)

    def integral(t):
        total, k = 0.0, 0
        while 0.05 + k * 0.15 < t:
            a = 0.05 + k * 0.15
            b = min(a + 0.06, t)
            total += 6.0 * (math.cos(om * a) - math.cos(om * b)) / om
            k += 1
        return total

    want = np.array([integral(t) / J for t in times])
    assert np.max(np.abs(df["J.w_rad_s"].to_numpy() - want)) < 1e-8


@pytest.mark.parametrize("kind", ["trapezoid", "exponentials"])
def test_a_speed_source_takes_the_torque_of_the_signals_rate(kind):
    """A speed source following a trapezoid (rising and falling > 0) or exponentials holds the inertia's
    speed on the signal, with the torque J times its rate (MSL's derivative, from the right at corners)."""
    J = 0.3
    sig, closed = SIGNALS[kind]
    rate = ((lambda t: msl_trapezoid(t, **TRAPEZOID, rate=True)) if kind == "trapezoid"
            else (lambda t: msl_exponentials(t, **EXPONENTIALS, rate=1)))
    d = Driveline("driven")
    d.inertia("J", J=J)
    d.speed("drive", "J", sig)
    corners = _corners(kind)
    times = np.array([t for t in _sample_times() if min(abs(t - c) for c in corners) > 1e-6])
    df = d.simulate(T_END, sample_times=times, rtol=1e-10).to_dataframe()
    # measured: speed 1.7e-9 rad/s (the speed integrates the prescribed acceleration), torque 1e-10 N m
    assert np.max(np.abs(df["J.w_rad_s"].to_numpy() - [closed(t) for t in times])) < 1e-8
    assert np.max(np.abs(df["drive.tau_Nm"].to_numpy() - [J * rate(t) for t in times])) < 1e-7


def test_motion_sources_refuse_signals_that_jump():
    d = Driveline("m")
    d.inertia("J", J=1.0)
    with pytest.raises(ParameterError, match="speed pulse jumps"):
        d.speed("s1", "J", Signal.pulse(1.0, 0.5, 1.0))
    with pytest.raises(ParameterError, match="trapezoid jumps"):
        d.speed("s2", "J", Signal.trapezoid(1.0, 0.0, 0.2, 0.1, 1.0))
    with pytest.raises(ParameterError, match="speed step"):
        d.speed("s3", "J", Signal.product(Signal.step(1.0, 0.5), Signal.sine(1.0, 1.0)))
    with pytest.raises(ParameterError, match="continuous speed"):
        d.position("s4", "J", Signal.exponentials(1.0, 0.5, 0.1, 0.1))


def test_a_sine_inside_a_product_limits_the_step():
    d = Driveline("m")
    d.inertia("J", J=1.0)
    d.torque("T", "J", Signal.product(Signal.sine(1.0, 4.0), Signal.pulse(1.0, 0.5, 1.0)))
    assert d.system().max_step == pytest.approx(0.125 / 4.0)


def test_describe_names_each_signal():
    assert Signal.pulse(2.0, 0.25, 0.1, nperiod=3).describe("N m") == "2 N m pulse, 25 % of 0.1 s, 3 periods"
    assert "trapezoid, rising 0.02 s, width 0.03 s, falling 0.04 s, period 0.13 s" in SIGNALS["trapezoid"][0].describe()
    assert "exponentials" in SIGNALS["exponentials"][0].describe()
    assert Signal.product(Signal.sine(1.0, 2.0), Signal.pulse(1.0, 0.5, 1.0)).describe("N m").count(") * (") == 1


# ----------------------------------------------------------------- TOML
_TOML = """
[inertia.J]
J = "1 kg m^2"

[torque.T1]
flange = "J"
torque = { pulse = { amplitude = "3 N m", width = "30 %", period = "100 ms", nperiod = 4, offset = "-1 N m", start = "50 ms" } }

[torque.T2]
flange = "J"
torque = { trapezoid = { amplitude = 2, rising = "20 ms", width = "30 ms", falling = "40 ms", period = "130 ms", nperiod = -1, offset = 0.5, start = "10 ms" } }

[torque.T3]
flange = "J"
torque = { exponentials = { out_max = "4 N m", rise_time = "150 ms", rise_time_const = "50 ms", fall_time_const = "80 ms", offset = 0.25, start = 0.1 } }

[torque.T4]
flange = "J"
torque = { product = [{ sine = { amplitude = "3 N m", frequency = "2 Hz" } }, { pulse = { amplitude = 1, width = 0.4, period = 0.15, start = 0.05 } }] }

[torque.T5]
flange = "J"
torque = { product = ["2 N m", { exponentials = { out_max = 1, rise_time = 0.15, rise_time_const = 0.05, fall_time_const = 0.08 } }] }
"""


def test_toml_signals_are_the_python_ones():
    d = parse_driveline(tomllib.loads(_TOML), "signals.toml").driveline
    got = {name: d.signal(name) for name in d.element_names}
    assert got["T1"] == SIGNALS["pulse"][0]
    assert got["T2"] == SIGNALS["trapezoid"][0]
    assert got["T3"] == SIGNALS["exponentials"][0]
    assert got["T4"] == Signal.product(Signal.sine(3.0, 2.0), Signal.pulse(1.0, 0.4, 0.15, start=0.05))
    assert got["T5"] == Signal.product(2.0, Signal.exponentials(1.0, 0.15, 0.05, 0.08))
    assert "pulse, 30 % of 0.1 s, 4 periods" in d.describe()


_BASE = '[inertia.J]\nJ = 1\n[torque.T]\nflange = "J"\ntorque = '


@pytest.mark.parametrize("signal, words", [
    ("{ pulse = { amplitude = 1, width = 0, period = 1 } }", ["torque.T.torque", "width = 0.0", "(0, 1]"]),
    ("{ pulse = { amplitude = 1, width = \"150 %\", period = 1 } }", ["torque.T.torque", "width = 1.5", "(0, 1]"]),
    ("{ pulse = { amplitude = 1, width = 0.5, period = 0 } }", ["torque.T.torque", "period = 0.0", "> 0"]),
    ("{ pulse = { amplitude = 1, width = 0.5, period = -1 } }", ["period = -1.0", "> 0"]),
    ("{ pulse = { amplitude = 1, width = 0.5, period = 1, nperiod = 1.5 } }",
     ["torque.T.torque.pulse.nperiod = 1.5", "whole number"]),
    ("{ pulse = { amplitude = 1, period = 1 } }", ["torque.T.torque", "pulse needs width"]),
    ("{ pulse = { amplitude = 1, width = 0.5, period = \"1 m\" } }", ["torque.T.torque.pulse.period"]),
    ("{ trapezoid = { amplitude = 1, rising = 0.3, width = 0.5, falling = 0.3, period = 1 } }",
     ["torque.T.torque", "rising + width + falling = 0.3 + 0.5 + 0.3 s", "period = 1 s"]),
    ("{ trapezoid = { amplitude = 1, rising = -0.1, width = 0.5, falling = 0.3, period = 1 } }",
     ["torque.T.torque", "rising = -0.1", ">= 0"]),
    ("{ exponentials = { out_max = 1, rise_time = 0.1, rise_time_const = 0, fall_time_const = 1 } }",
     ["torque.T.torque", "rise_time_const = 0.0", "> 0"]),
    ("{ exponentials = { out_max = 1, rise_time = 0.1, rise_time_const = 0.1 } }",
     ["torque.T.torque", "exponentials needs fall_time_const"]),
    ("{ product = [1, 2, 3] }", ["torque.T.torque.product", "expected two signals"]),
    ("{ product = [1, \"2 N m\"] }", ["torque.T.torque.product[1]", "2 N m"]),
    ("{ product = [1, { pulse = { amplitude = 1, width = 2, period = 1 } }] }",
     ["torque.T.torque.product[1]", "width = 2.0"]),
])
def test_bad_signal_values_are_refused_naming_the_key_and_value(signal, words):
    with pytest.raises(ParameterError) as exc:
        parse_driveline(tomllib.loads(_BASE + signal + "\n"), "bad.toml")
    msg = str(exc.value)
    assert "bad.toml" in msg
    for w in words:
        assert w in msg, (w, msg)


def test_bad_python_arguments_are_refused():
    with pytest.raises(ParameterError, match=r"pulse: nperiod = True must be a whole number"):
        Signal.pulse(1.0, 0.5, 1.0, nperiod=True)
    with pytest.raises(ParameterError, match=r"product: b = 'x'"):
        Signal.product(1.0, "x")
    with pytest.raises(ParameterError, match="exponentials: fall_time_const"):
        Signal.exponentials(1.0, 0.5, 0.1, -0.1)
