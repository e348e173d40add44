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
    "value, match",
    [("3 kg", "wrong unit"), ("abc mm", "cannot parse"), ("nan m", "not a finite"), ("3 blorps", "cannot parse"),
     (True, "expected a number"), ([1], "expected a number")],
)
def test_to_si_errors_name_file_key_and_value(value, match):
    with pytest.raises(ParameterError, match=match) as exc:
        units.to_si(value, "m", name="r_outer", source="clutch.toml")
    assert "clutch.toml: r_outer" in str(exc.value)
