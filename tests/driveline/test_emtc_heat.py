"""An EMTC coupling's heat port (seed 002, Sec. 5: "the thermal model of EMTC is also worth investigating ...
especially in the trapped situation"): its losses heat a thermal mass of the network, and its friction map is read
at that mass's temperature.

The coupling slips at a constant speed difference (both shafts driven by speed sources: a trapped vehicle, one axle
spinning) with its coil at a constant current, so its torque depends on its friction coefficient alone once the
current lags and the armature have settled: at any time of the heated run it must be the torque of the same
coupling held at that instant's temperature (an independent run through the scenario's ``temperature_c``)."""

from __future__ import annotations

import pathlib
import tomllib

import numpy as np
import pytest

from clutchlab.driveline import Driveline
from clutchlab.driveline.description import parse_driveline
from clutchlab.emtc import system as S
from clutchlab.emtc.bench import BenchScenario
from clutchlab.emtc.friction import FrictionMap

RTOL = 1e-9
SLIP, W0 = 10.0, 50.0                          # rad/s
#: a lining that fades: mu from 0.14 at 20 degC to 0.08 at 220 degC, the same at every slip speed
FADE = FrictionMap(slip_speed=[0.0, 20.0], temperature_c=[20.0, 220.0], mu=[[0.14, 0.08], [0.14, 0.08]])


def trapped(capacity=None, temperature=20.0, friction_map=FADE) -> Driveline:
    d = Driveline("trapped")
    d.inertia("f", J=0.05, w0=W0).inertia("r", J=0.05, w0=W0 - SLIP)
    d.speed("drive_f", "f", W0)
    d.speed("drive_r", "r", W0 - SLIP)
    d.emtc("c", "f", "r", coil_current=2.0, options=S.BenchOptions(friction_map=friction_map),
           scenario=BenchScenario(temperature_c=temperature))
    if capacity is not None:
        d.thermal_mass("m", capacity, T0=temperature, heat_from=["c"])
    return d


@pytest.fixture(scope="module")
def heated():
    return trapped(200.0).simulate(1.0, rtol=RTOL, output_step=1e-3).to_dataframe()


def test_the_coupling_heats_its_mass_by_the_work_of_its_torque(heated):
    """``C (T - T0)`` is the coupling's dissipated energy at every sample (the balance the integrator keeps), and
    that energy is the integral of ``tau w_rel`` over the samples (trapezoid, 1 ms)."""
    f = heated
    stored = 200.0 * (f["m.temperature_C"] - 20.0)
    np.testing.assert_allclose(stored, f["c.dissipated_J"], rtol=1e-9, atol=1e-9)
    power = (f["c.tau_Nm"] * f["c.w_rel_rad_s"]).to_numpy()
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(f["time_s"].to_numpy()))])
    assert work[-1] > 4000.0 and f["m.temperature_C"].iloc[-1] > 40.0           # a trapped coupling gets hot
    np.testing.assert_allclose(work[100:], f["c.dissipated_J"].to_numpy()[100:], rtol=1e-3)


@pytest.mark.parametrize("at", [0.3, 0.6, 1.0])
def test_its_friction_map_is_read_at_the_mass_s_temperature(heated, at):
    """The heated run's torque at ``at`` is the torque of the coupling held at the mass's temperature of that
    instant (a run without the mass, its scenario at that temperature, settled after 0.3 s): the map follows the
    heat port, and the fade is large (the torque falls by more than 10 % over the run)."""
    row = heated.iloc[int(round(at / 1e-3))]
    held = trapped(None, temperature=float(row["m.temperature_C"])).simulate(0.3, rtol=RTOL, output_step=0.3)
    tau_held = float(held.to_dataframe()["c.tau_Nm"].iloc[-1])
    assert row["c.tau_Nm"] == pytest.approx(tau_held, rel=1e-7)
    assert abs(heated["c.tau_Nm"].iloc[-1]) < 0.9 * abs(heated["c.tau_Nm"].iloc[100])


def test_a_coupling_without_a_map_heats_its_mass_and_keeps_its_torque():
    """With the kinetic coefficients (no temperature in its friction law) the mass heats and the torque is the
    coupling's without it; a mass too large to warm is the run without one, with its friction map."""
    plain = trapped(None, friction_map=None).simulate(0.3, rtol=RTOL, output_step=0.01).to_dataframe()
    hot = trapped(20.0, friction_map=None).simulate(0.3, rtol=RTOL, output_step=0.01).to_dataframe()
    # (the mass's states join the step-size control, so the steps differ: equal within the run's tolerance)
    np.testing.assert_allclose(hot["c.tau_Nm"], plain["c.tau_Nm"], rtol=1e-8, atol=1e-6)
    assert hot["m.temperature_C"].iloc[-1] > 40.0
    cold = trapped(1e12).simulate(0.3, rtol=RTOL, output_step=0.01).to_dataframe()
    alone = trapped(None).simulate(0.3, rtol=RTOL, output_step=0.01).to_dataframe()
    np.testing.assert_allclose(cold["c.tau_Nm"], alone["c.tau_Nm"], rtol=1e-7, atol=1e-6)


def test_the_awd_example_with_its_coupling_heating_a_mass():
    """In a file: the AWD vehicle on the drum bench with the coupling's losses heating a 300 J/K mass; the mass
    stores what the coupling dissipated, less what it gave its ambient."""
    examples = pathlib.Path(__file__).resolve().parents[2] / "examples"
    text = (examples / "driveline_emtc_awd.toml").read_text()
    text += ('\n[thermal_mass.coupling_housing]\ncapacity = "300 J/K"\nT0 = "60 degC"\nconductance = "2 W/K"\n'
             'ambient = "20 degC"\nheat_from = ["emtc"]\n')
    spec = parse_driveline(tomllib.loads(text), "awd_heat.toml", examples)
    f = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, output_step=spec.output_step).to_dataframe()
    stored = 300.0 * (f["coupling_housing.temperature_C"] - 60.0) + f["coupling_housing.heat_out_J"]
    np.testing.assert_allclose(stored, f["emtc.dissipated_J"], rtol=1e-8, atol=1e-6)
    assert f["emtc.dissipated_J"].iloc[-1] > 0.0
