"""An EMTC coupling's ports in a network (:meth:`clutchlab.driveline.Driveline.emtc`, issue #31 "inputs are ports"):
``torque_request``, ``throttle`` and ``coil_current``, each a signal or a network input that a host, a controller or
an FMU's importer holds.

References are independent of the network: the drum bench's own model (:func:`clutchlab.emtc.system.run`, its
controller reading a prescribed torque reference table) for the torque request, and the closed form of the coil's
two current lags (Fig. 15) for a current drive.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from clutchlab.driveline import Driveline, Signal
from clutchlab.driveline.bench import drum_bench
from clutchlab.driveline.description import load_driveline
from clutchlab.emtc import system as S
from clutchlab.emtc.bench import BenchScenario, load_scenario
from clutchlab.errors import ParameterError
from clutchlab.system import simulate

from .test_coupled import RTOL, _bench, _check_emtc, _times

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def bench():
    base = load_scenario(EXAMPLES / "emtc_scenario.toml")
    return base["vehicle"], base["scenario"].replace(duration=0.6)


def test_a_held_torque_request_drives_the_controller_as_the_bench_reference_does(bench):
    """A network input held at 120 N m on the coupling's ``torque_request`` port (run through the system contract,
    the input at its start value) gives the drum bench's own run whose controller reads the constant reference table
    120 N m: speeds, coupling torque, currents, magnet force, armature events and lock-up."""
    vehicle, sc = bench
    d = drum_bench(sc, vehicle, torque_request=Signal.input("T"))
    d.input("T", unit="Nm", start=120.0)
    system = d.system(RTOL)
    assert [(v.name, v.unit) for v in system.inputs] == [("T", "Nm")]
    times = _times(sc.duration)
    r = simulate(system, sc.duration, rtol=RTOL, sample_times=times)
    assert r.ok
    N = r.to_dataframe()
    assert np.allclose(N["emtc.torque_reference_Nm"].dropna(), 120.0)
    ref = _bench(sc, vehicle, S.BenchOptions(torque_reference=((0.0, 10.0), (120.0, 120.0))))
    _check_emtc(ref, N, r.events, "")


def test_a_torque_request_table_given_to_the_run_equals_the_bench_with_that_table(bench):
    """The same port driven by :meth:`Driveline.simulate`'s ``inputs`` with a table (a request that rises, falls and
    holds): the controller samples it every sample time, as the bench's controller samples the same table."""
    vehicle, sc = bench
    table = ((0.0, 0.15, 0.35, 0.6), (0.0, 200.0, 60.0, 60.0))
    d = drum_bench(sc, vehicle, torque_request=Signal.input("T"))
    d.input("T", unit="Nm")
    times = _times(sc.duration)
    r = d.simulate(sc.duration, rtol=RTOL, sample_times=times, inputs={"T": table})
    assert r.ok
    ref = _bench(sc, vehicle, S.BenchOptions(torque_reference=table))
    _check_emtc(ref, r.to_dataframe(), r.events, "")


def test_a_throttle_port_feeds_the_map_as_the_scenario_s_ramp_does(bench):
    """The scenario's throttle ramp given to the ``throttle`` port instead (the map of Eq. 31 then reads the port;
    ``drum_bench`` gives the port to its engine too): the drum bench's own run with that ramp, and the throttle
    output is the port's value."""
    vehicle, sc = bench
    ramp = Signal.table([0.0, sc.ramp_start, sc.ramp_end], [sc.throttle_start, sc.throttle_start, sc.throttle_end])
    d = drum_bench(sc, vehicle, throttle=ramp)
    times = _times(sc.duration)
    r = d.simulate(sc.duration, rtol=RTOL, sample_times=times)
    assert r.ok
    N = r.to_dataframe()
    _check_emtc(_bench(sc, vehicle, S.BenchOptions()), N, r.events, "")
    expect = np.interp(times, [0.0, sc.ramp_start, sc.ramp_end], [sc.throttle_start, sc.throttle_start, sc.throttle_end])
    np.testing.assert_allclose(N["emtc.throttle_1"], expect, rtol=0, atol=1e-12)   # (the port's value at each time)
    assert d.system(RTOL).params.emtc.params.throttle.data.size == 0   # (the map reads the port, not a packed ramp)


def _pair(coil_current, w0=50.0):
    """An EMTC between two shafts turning together, the front one driven at a constant speed, the rear one free."""
    d = Driveline("coil")
    d.inertia("f", J=0.05, w0=w0).inertia("r", J=0.05, w0=w0)
    d.speed("drive", "f", w0)
    d.emtc("c", "f", "r", coil_current=coil_current)
    return d


def test_a_coil_current_port_makes_a_current_drive_whose_lags_follow_the_closed_form():
    """``coil_current`` held at 1.5 A: the two current lags of Fig. 15 (``i1' = (i_set - i1) / tau1``,
    ``i2' = (i1 - i2) / tau2``, both from the magnet's lowest grid current) follow their closed form, and the
    command is the port's value at every sample (no torque controller)."""
    d = _pair(Signal.input("i"))
    d.input("i", unit="A", start=1.5)
    system = d.system(1e-10)
    assert [(v.name, v.unit) for v in system.inputs] == [("i", "A")]
    p = system.params.emtc.params
    tau1, tau2 = float(p.actuator.data["tau1"][0]), float(p.actuator.data["tau2"][0])   # (one record per coupling)
    assert tau1 != tau2
    i0 = float(system.x0[[v.name for v in system.states].index("c.i2")])
    times = np.linspace(0.001, 0.05, 50)
    r = simulate(system, 0.05, rtol=1e-10, sample_times=times)
    assert r.ok
    N = r.to_dataframe()
    ic = 1.5
    i1 = ic + (i0 - ic) * np.exp(-times / tau1)
    i2 = ic + (i0 - ic) * (tau1 * np.exp(-times / tau1) - tau2 * np.exp(-times / tau2)) / (tau1 - tau2)
    np.testing.assert_allclose(N["c.i1_A"], i1, rtol=0, atol=1e-7)
    np.testing.assert_allclose(N["c.i2_A"], i2, rtol=0, atol=1e-7)
    np.testing.assert_allclose(N["c.current_command_A"], ic, rtol=0, atol=0)


def test_a_coil_current_signal_steps_the_lags_at_its_step():
    """A port given a step (not an input): the command jumps at the step time and the lags start from there."""
    d = _pair(Signal.step(2.0, 0.01))
    r = d.simulate(0.03, rtol=1e-10, sample_times=[0.005, 0.0099, 0.0101, 0.02, 0.03])
    assert r.ok
    N = r.to_dataframe()
    assert list(N["c.current_command_A"]) == [0.0, 0.0, 2.0, 2.0, 2.0]
    i1 = N["c.i1_A"].to_numpy()
    assert i1[1] == pytest.approx(i1[0], abs=1e-3) and i1[4] > i1[3] > i1[2] > i1[1]


def test_ports_in_a_toml_network_are_inputs_with_their_units(tmp_path):
    """In a TOML network the ports read ``[input.NAME]`` tables like any signal field; the inputs carry the ports'
    units (N m, A) and a bad combination is refused naming the coupling."""
    text = """
[simulation]
t_end = "0.05 s"

[inertia.f]
J = 0.05
w0 = "50 rad/s"

[inertia.r]
J = 0.05
w0 = "50 rad/s"

[speed.drive]
flange = "f"
speed = "50 rad/s"

[input.T]
start = "80 N*m"

[emtc.c]
a = "f"
b = "r"
torque_request = { input = "T" }
"""
    path = tmp_path / "ports.toml"
    path.write_text(text)
    net = load_driveline(path).driveline
    system = net.system(1e-8)
    assert [(v.name, v.unit) for v in system.inputs] == [("T", "Nm")]
    assert "torque_request" in net.describe()
    r = simulate(system, 0.05, rtol=1e-8, output_step=0.01)
    assert r.ok and np.allclose(r["c.torque_reference_Nm"][r.time > 0.0], 80.0)
    # a co-simulation master (the FMU's slave) holds the request: the controller takes each new value at its next
    # sample (every 2 ms: the default scenario's controller), no earlier
    from clutchlab.fmu.driveline import DrivelineCoSimulation

    cls = DrivelineCoSimulation.for_description(path)
    assert [(v.name, v.unit, v.start) for v in cls.inputs] == [("T", "N.m", 80.0)]
    sim = cls()
    sim.initial_outputs({})
    assert load_driveline(path).driveline.elements[-1].arguments["scenario"] is None   # (the default scenario's)
    sample = BenchScenario().sample_time
    assert sample == pytest.approx(0.002)
    dt, change = 0.0005, 21                                       # the request steps to 150 N m at t = 10.5 ms
    refs = [sim.do_step(k * dt, dt, {"T": 80.0 if k < change else 150.0})["c.torque_reference"] for k in range(40)]
    for k, v in enumerate(refs):
        t = (k + 1) * dt
        if abs(t - 0.012) > 1e-9:                                 # (the sample at 12 ms itself: either side)
            assert v == (80.0 if t < 0.012 else 150.0), (t, v)  # held until the controller's next sample
    bad = path.with_name("bad.toml")
    bad.write_text(text.replace('torque_request = { input = "T" }',
                                'torque_request = { input = "T" }\ncoil_current = "1 A"'))
    with pytest.raises(ParameterError, match="c: torque_request and coil_current"):
        load_driveline(bad).driveline.system(1e-8)


def test_a_torque_request_and_a_reference_table_are_refused():
    d = Driveline("x")
    d.inertia("f", J=1.0).inertia("r", J=1.0)
    with pytest.raises(ParameterError, match="torque_request and options.torque_reference"):
        d.emtc("c", "f", "r", options=S.BenchOptions(torque_reference=((0.0, 1.0), (1.0, 1.0))), torque_request=5.0)
    with pytest.raises(ParameterError, match="coil_drive"):
        d.emtc("c", "f", "r", options=dataclasses.replace(S.BenchOptions(), coil_drive="current"), coil_current=1.0)
