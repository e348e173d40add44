"""Unit conversions and quantity parsing."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab import units
from clutchlab.errors import ParameterError


def test_closed_form_conversions():
    assert units.rpm_to_rad_s(6000.0) == pytest.approx(6000 * 2 * math.pi / 60)
    assert units.celsius_to_kelvin(40.0) == pytest.approx(313.15)
    assert units.bar_to_pa(3.0) == pytest.approx(3e5)
    np.testing.assert_allclose(units.rad_s_to_rpm(np.array([math.pi])), [30.0])


@settings(max_examples=examples(50), deadline=None)
@given(st.floats(-1e6, 1e6, allow_nan=False))
def test_round_trips(x):
    assert units.rad_s_to_rpm(units.rpm_to_rad_s(x)) == pytest.approx(x, abs=1e-9)
    assert units.kelvin_to_celsius(units.celsius_to_kelvin(x)) == pytest.approx(x, abs=1e-9)
    assert units.pa_to_bar(units.bar_to_pa(x)) == pytest.approx(x, abs=1e-9)


@pytest.mark.parametrize(
    "value, unit, expected",
    [("83.15 mm", "m", 0.08315), ("300 kPa", "Pa", 3e5), ("40 degC", "degC", 40.0), ("313.15 K", "degC", 40.0),
     ("1.2 MN/m", "N/m", 1.2e6), ("6000 rpm", "rad/s", 6000 * 2 * math.pi / 60), (2.5, "m", 2.5), ("-4", "1", -4.0),
     ("35 mPa*s", "Pa*s", 0.035)],
)
def test_to_si(value, unit, expected):
    assert units.to_si(value, unit) == pytest.approx(expected)


@pytest.mark.parametrize(
    "value, unit, expected",
    [("1 Hz", "rad/s", 2 * math.pi), ("1 rps", "rad/s", 2 * math.pi), ("10 Hz", "rad/s", 20 * math.pi),
     ("1 kHz", "rad/s", 2000 * math.pi), ("60 rpm", "Hz", 1.0), ("100 rpm", "Hz", 100 / 60),
     (f"{2 * math.pi} rad/s", "Hz", 1.0), ("360 deg/s", "Hz", 1.0), ("2 Hz/s", "rad/s**2", 4 * math.pi),
     ("5 Hz", "Hz", 5.0), ("3 1/s", "rad/s", 3.0), ("3 1/s", "Hz", 3.0), ("1 N*m/deg", "N*m/rad", 180 / math.pi)],
)
def test_a_frequency_counts_cycles_where_an_angle_is_meant(value, unit, expected):
    """pint takes the radian as 1 and alone read ``1 Hz`` as 1 rad/s and ``60 rpm`` as 6.28 Hz (#33: a silent
    wrong answer).  A frequency in hertz counts cycles of 2 pi rad; ``1/s`` stays the SI radian per second."""
    assert units.to_si(value, unit) == pytest.approx(expected, rel=1e-14)


def test_logged_channels_in_hz_are_cycles_too():
    from clutchlab.io.channels import unit_conversion

    assert unit_conversion("Hz", "rad/s") == pytest.approx((2 * math.pi, 0.0), rel=1e-14)
    assert unit_conversion("U/min", "Hz") == pytest.approx((1 / 60, 0.0), rel=1e-14)
    assert unit_conversion("rad/s", "rad/s") == (1.0, 0.0)


@pytest.mark.parametrize(
    "value, match",
    [("3 kg", "wrong unit"), ("abc mm", "cannot parse"), ("nan m", "not a finite"), ("3 blorps", "cannot parse"),
     (True, "expected a number"), ([1], "expected a number")],
)
def test_to_si_errors_name_file_key_and_value(value, match):
    with pytest.raises(ParameterError, match=match) as exc:
        units.to_si(value, "m", name="r_outer", source="clutch.toml")
    assert "clutch.toml: r_outer" in str(exc.value)
