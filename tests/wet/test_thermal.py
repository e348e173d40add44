import math

import numpy as np
import pytest

from clutchlab.errors import ParameterError
from clutchlab.wet import (
    Bench, ParametricFriction, Scenario, WetClutch, heat_balance, pack_heat_capacity, simulate_engagement,
    steady_state_temperature, temperature_step_response, thermal_time_constant,
)


def test_table1_heat_capacity_and_time_constant():
    c = WetClutch.paper()
    # (1.65 g * 1500 + 82.1 g * 500) * 8 = 348.2 J/K
    assert pack_heat_capacity(8, 1.65e-3, 1500, 82.1e-3, 500) == pytest.approx(348.2)
    assert c.heat_capacity == pytest.approx(348.2)
    # tau = 348.2 / (122.2 + 39.94) = 2.1475 s
    assert thermal_time_constant(c.heat_capacity, c.k1, c.k2) == pytest.approx(348.2 / 162.14)


def test_heat_balance_eq8_and_steady_state():
    # at the steady state dT/dt = 0
    t_inf = steady_state_temperature(3900.0, 85.0, 65.0, 122.2, 39.94)
    assert t_inf == pytest.approx((3900 + 122.2 * 85 + 39.94 * 65) / 162.14)
    assert heat_balance(t_inf, 3900.0, 85.0, 65.0, 348.2, 122.2, 39.94) == pytest.approx(0.0, abs=1e-12)
    # hand calculation of Eq. 8
    assert heat_balance(100.0, 1000.0, 80.0, 60.0, 348.2, 122.2, 39.94) == pytest.approx(
        (1000 - 122.2 * 20 - 39.94 * 40) / 348.2)
    with pytest.raises(ParameterError):
        thermal_time_constant(348.2, 0.0, 0.0)


def test_step_response_solves_eq8():
    t = np.linspace(0, 10, 2001)
    temp = temperature_step_response(t, 80.0, 3000.0, 85.0, 65.0, 348.2, 122.2, 39.94)
    dtdt = np.gradient(temp, t)
    np.testing.assert_allclose(dtdt[1:-1], heat_balance(temp, 3000.0, 85.0, 65.0, 348.2, 122.2, 39.94)[1:-1],
                               atol=2e-3)
    tau = thermal_time_constant(348.2, 122.2, 39.94)
    t_inf = steady_state_temperature(3000.0, 85.0, 65.0, 122.2, 39.94)
    assert (temperature_step_response(tau, 80.0, 3000.0, 85.0, 65.0, 348.2, 122.2, 39.94) - t_inf) / (80 - t_inf) == \
        pytest.approx(math.exp(-1))


def test_simulated_pack_cools_with_the_closed_form_time_constant():
    # no force, no slip; reservoir and housing with huge heat capacity: Eq. 8 alone, closed form
    c = WetClutch.paper(k1=90.0, k2=30.0)
    bench = Bench(reservoir_heat_capacity=1e15, housing_heat_capacity=1e15, heater_power_max=0.0)
    scen = Scenario([0.0], [0.0], [0.0], [0.0], duration=8.0, initial_temperature_c=120.0,
                    fluid_temperature_c=70.0, housing_temperature_c=40.0)
    res = simulate_engagement(c, scen, bench=bench, friction=ParametricFriction(), sample_rate=50.0)
    exact = temperature_step_response(res.time, 120.0, 0.0, 70.0, 40.0, c.heat_capacity, 90.0, 30.0)
    np.testing.assert_allclose(res.state("temperature_C"), exact, atol=1e-5)
    # steady state (90*70 + 30*40)/120 = 62.5 degC and tau = 348.2/120 s
    assert exact[-1] == pytest.approx(62.5 + 57.5 * math.exp(-8.0 / (348.2 / 120.0)))
    # the thermistor lags: first-order sensor with the bench's time constant
    assert np.all(res.state("thermistor_temperature_C")[1:] > res.state("temperature_C")[1:])
