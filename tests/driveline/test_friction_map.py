"""A clutch or brake whose mu is a friction map mu(v, T) identified by :mod:`clutchlab.wet`
(:meth:`Driveline.clutch` with ``mu=FrictionMap``, ``radius``, ``temperature``).

Closed forms: a brake stopping a free inertia, ``J dw/dt = -c F mu(r w, T)``.  With mu constant in ``v``
the stop time is ``J w0 / (c F mu)``; with mu linear in ``v`` (``mu0 + k v``) the speed decays as
``w(t) = (w0 + a) exp(-c F k r t / J) - a``, ``a = mu0 / (k r)``, and stops at
``t* = J / (c F k r) ln(1 + w0 / a)`` (written as ``J w0 / (c F mu0) ln(1 + x) / x``, ``x = w0 / a``, which
stays exact as ``k`` goes to zero).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from clutchlab.driveline import Driveline
from clutchlab.driveline.description import load_driveline
from clutchlab.errors import ParameterError
from clutchlab.wet.friction import FrictionMap


def _map(mu_at_40, mu_at_120, slope=0.0, vmax=20.0):
    """mu(v, T) on v in [0.5, vmax] m/s, T in {40, 120} degC: ``mu_T + slope (v - 0.5)``."""
    v = np.linspace(0.5, vmax, 5)
    values = np.array([mu_at_40 + slope * (v - 0.5), mu_at_120 + slope * (v - 0.5)])
    return FrictionMap(v, [40.0, 120.0], values)


def _brake(fmap, J=0.5, w0=100.0, fn=200.0, radius=0.1, temperature=80.0, cgeo=1.0):
    d = Driveline("brake_map")
    d.inertia("J", J=J, w0=w0)
    d.brake("brake", "J", fn_max=fn, mu=fmap, cgeo=cgeo, radius=radius, temperature=temperature)
    return d


def test_map_constant_in_v_stops_at_the_closed_form():
    """mu 0.1 at 40 degC and 0.2 at 120 degC: at 80 degC, 0.15 (linear in T); stop at J w0 / (c F mu)."""
    d = _brake(_map(0.1, 0.2))
    r = d.simulate(3.0, rtol=1e-10)
    stick = r.events[r.events["event"] == "stick"]["time_s"].to_numpy()
    assert stick.size == 1 and abs(stick[0] - 0.5 * 100.0 / (200.0 * 0.15)) < 1e-8


@settings(max_examples=30, deadline=None)
@given(mu0=st.floats(0.05, 0.3), slope=st.floats(0.0, 0.01), radius=st.floats(0.05, 0.2),
       w0=st.floats(20.0, 150.0), temperature=st.floats(40.0, 120.0))
def test_map_linear_in_v_stops_at_the_closed_form(mu0, slope, radius, w0, temperature):
    """mu = mu_T + slope (v - 0.5) inside the grid (v up to 40 m/s covers r w0): the stop time of the
    exponential decay; below v = 0.5 m/s the map is held at mu_T (the closed form then continues at constant
    mu)."""
    fmap = _map(mu0, mu0 * 1.5, slope, vmax=40.0)
    muT = mu0 + (mu0 * 1.5 - mu0) * (temperature - 40.0) / 80.0
    J, fn = 0.5, 200.0
    d = _brake(fmap, J=J, w0=w0, fn=fn, radius=radius, temperature=temperature)
    r = d.simulate(40.0, rtol=1e-10)
    stick = r.events[r.events["event"] == "stick"]["time_s"].to_numpy()
    w_hold = 0.5 / radius                       # below it the map is constant
    # above w_hold, mu = mu_T + slope r (w - w_hold): t1 = J/F int dw / mu = J (w0 - w_hold) / (F mu_T) ln(1 + x) / x
    x = slope * radius * max(w0 - w_hold, 0.0) / muT
    t1 = J * max(w0 - w_hold, 0.0) / (fn * muT) * (math.log1p(x) / x if x > 0.0 else 1.0)
    expected = t1 + J * min(w0, w_hold) / (fn * muT)
    assert stick.size == 1 and abs(stick[0] - expected) < 1e-7 * max(1.0, expected)


def test_the_map_from_a_file_in_toml(tmp_path):
    """``mu_map = "map.json"`` with radius and temperature in a description equals the Python network."""
    fmap = _map(0.1, 0.2, slope=0.002)
    path = tmp_path / "map.json"
    fmap.to_json(path)
    (tmp_path / "d.toml").write_text(
        '[inertia.J]\nJ = "0.5 kg m^2"\nw0 = "100 rad/s"\n'
        '[brake.brake]\nflange = "J"\nfn_max = "200 N"\nmu_map = "map.json"\nradius = "100 mm"\n'
        'temperature = "80 degC"\n')
    r_file = load_driveline(tmp_path / "d.toml").driveline.simulate(2.0, rtol=1e-10)
    r_py = _brake(FrictionMap.from_json(path)).simulate(2.0, rtol=1e-10)
    assert abs(r_file.events["time_s"].iloc[-1] - r_py.events["time_s"].iloc[-1]) < 1e-12
    (tmp_path / "d.toml").write_text(
        '[inertia.J]\nJ = 1\n[brake.brake]\nflange = "J"\nfn_max = 1\nmu = 0.3\nmu_map = "map.json"\n'
        'radius = 0.1\ntemperature = 80\n')
    with pytest.raises(ParameterError, match=r"\[brake\.brake\] give mu or mu_map, not both"):
        load_driveline(tmp_path / "d.toml")


def test_refusals():
    d = Driveline("x")
    d.inertia("J", J=1.0)
    fmap = _map(0.1, 0.2)
    with pytest.raises(ParameterError, match="needs radius"):
        d.brake("b1", "J", fn_max=1.0, mu=fmap, temperature=80.0)
    with pytest.raises(ParameterError, match="radius"):
        d.brake("b2", "J", fn_max=1.0, mu=fmap, radius=-0.1, temperature=80.0)
    with pytest.raises(ParameterError, match="radius = 0.1 is for a friction map"):
        d.brake("b3", "J", fn_max=1.0, mu=0.3, radius=0.1)
    f3 = FrictionMap([0.5, 5.0], [40.0, 120.0], np.full((2, 2, 2), 0.1), force_grid=[100.0, 1000.0])
    with pytest.raises(ParameterError, match="pressing force too"):
        d.clutch("c", "J", None, fn_max=1.0, mu=f3, radius=0.1, temperature=80.0)


# ---- a map read at the temperature of the brake's heat port, as the run heats it (kernel.friction_map)

def _heated_brake(fmap, capacity, T0=40.0, J=0.5, w0=100.0, fn=200.0, radius=0.1):
    d = Driveline("brake_map_heated")
    d.inertia("J", J=J, w0=w0)
    d.brake("brake", "J", fn_max=fn, mu=fmap, radius=radius)   # (no temperature: its mass's)
    d.thermal_mass("disc", capacity=capacity, T0=T0, heat_from=["brake"])
    return d


def test_a_map_at_a_heat_port_whose_mass_holds_its_temperature_is_the_map_at_that_temperature():
    """A mass of 1e12 J/K stays at 80 degC to 1e-8 K: the brake is the one read at a constant 80 degC (within 1e-8
    of the speed's range: the mass's states join the error norm, so the steps differ)."""
    fmap = _map(0.1, 0.2, slope=0.004)
    live = _heated_brake(fmap, capacity=1e12, T0=80.0).simulate(3.0, rtol=1e-10, output_step=0.01).to_dataframe()
    fixed = _brake(fmap, temperature=80.0).simulate(3.0, rtol=1e-10, output_step=0.01).to_dataframe()
    np.testing.assert_allclose(live["J.w_rad_s"], fixed["J.w_rad_s"], rtol=0, atol=1e-8 * 100.0)


def test_a_map_read_at_the_heating_disc_temperature_follows_an_independent_solution():
    """The brake's losses heat its disc (50 J/K) from 40 degC by about 50 K while mu rises with T: SciPy's solution
    of ``J dw/dt = -c F mu(r w, T)``, ``C dT/dt = c F mu(r w, T) w``, with ``mu`` the FrictionMap's own bilinear
    reading (``FrictionMap.mu``), to its stop (where ``w`` reaches 0): the speed and temperature within 1e-7 of
    their ranges and the stop time within 1e-7 s."""
    from scipy.integrate import solve_ivp

    fmap = _map(0.1, 0.2, slope=0.004)
    J, w0, fn, radius, cap = 0.5, 100.0, 200.0, 0.1, 50.0
    res = _heated_brake(fmap, capacity=cap, J=J, w0=w0, fn=fn, radius=radius).simulate(
        3.0, rtol=1e-10, output_step=0.01)
    df = res.to_dataframe()

    def rhs(t, y):
        w, temp = y
        mu = float(fmap.mu(np.array([radius * w]), np.array([temp]))[0])
        return [-fn * mu / J, fn * mu * w / cap]

    def stop(t, y):
        return y[0]
    stop.terminal = True
    ref = solve_ivp(rhs, (0.0, 3.0), [w0, 40.0], method="DOP853", rtol=1e-12, atol=1e-12, events=stop,
                    dense_output=True)
    t_stop = float(ref.t_events[0][0])
    stick = res.events[res.events["event"] == "stick"]["time_s"].to_numpy()
    assert stick.size == 1 and abs(stick[0] - t_stop) < 1e-7
    t = df["time_s"].to_numpy()
    before = t < t_stop
    y = ref.sol(t[before])
    assert np.max(np.abs(df["J.w_rad_s"].to_numpy()[before] - y[0])) < 1e-7 * w0
    temp = df["disc.temperature_C"].to_numpy()
    assert temp[-1] - temp[0] > 40.0   # (it heated enough for mu to move: 0.1 at 40 degC, 0.2 at 120)
    assert np.max(np.abs(temp[before] - y[1])) < 1e-7 * (temp[-1] - temp[0])


def test_a_map_without_a_temperature_needs_a_heat_port_and_takes_no_fade():
    fmap = _map(0.1, 0.2)
    d = Driveline("x")
    d.inertia("J", J=0.5, w0=10.0)
    d.brake("brake", "J", fn_max=200.0, mu=fmap, radius=0.1)
    with pytest.raises(ParameterError, match="brake: a friction map without a temperature is read at the temperature"):
        d.simulate(0.1)
    with pytest.raises(ParameterError, match="mu_temperature would count the temperature twice"):
        d.brake("b2", "J", fn_max=200.0, mu=fmap, radius=0.1, mu_temperature=[[20.0, 1.0], [200.0, 0.8]])


def test_a_map_file_without_a_temperature_reads_the_heat_port_in_toml(tmp_path):
    """``mu_map`` and ``radius`` without ``temperature``, the brake in a thermal mass's ``heat_from``: the run of the
    file equals the Python network built the same way."""
    fmap = _map(0.1, 0.2, slope=0.004)
    fmap.to_json(tmp_path / "map.json")
    (tmp_path / "d.toml").write_text(
        '[inertia.J]\nJ = "0.5 kg m^2"\nw0 = "100 rad/s"\n'
        '[brake.brake]\nflange = "J"\nfn_max = "200 N"\nmu_map = "map.json"\nradius = "100 mm"\n'
        '[thermal_mass.disc]\ncapacity = "50 J/K"\nT0 = "40 degC"\nheat_from = ["brake"]\n')
    r_file = load_driveline(tmp_path / "d.toml").driveline.simulate(3.0, rtol=1e-10)
    r_py = _heated_brake(fmap, capacity=50.0).simulate(3.0, rtol=1e-10)
    assert abs(r_file.events["time_s"].iloc[-1] - r_py.events["time_s"].iloc[-1]) < 1e-12
    assert "at its heat port's temperature" in load_driveline(tmp_path / "d.toml").driveline.describe()
