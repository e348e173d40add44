"""Network inputs (``Driveline.input``, ``Signal.input``, ``[input.NAME]``): ports a host holds.

Checked against closed forms of two inertias and a clutch (Coulomb, mu = 0.3, fn_max = 100 N, so 30 N m
sliding and static), never against clutchlab alone: a held input is a constant signal, a change restarts
the run (the stick/slip modes decided again at that instant), the co-simulation reads them as FMI inputs
(the FMU: tests/fmu/test_driveline_fmu.py), and the linear model's B column of a torque input is 1 / (the
inertia it accelerates).
"""

import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import assume, given, settings

from clutchlab.control.linear import OperatingPoint, jacobians
from clutchlab.driveline import Driveline, Signal
from clutchlab.fmu.driveline import DrivelineCoSimulation
from clutchlab.driveline.description import load_driveline, parse_driveline
from clutchlab.errors import ParameterError
from clutchlab.system import Simulation
from driveline_networks import INPUTS_TOML, networks
from hypothesis_budget import examples, pinned


RTOL = 1e-10
TOML = INPUTS_TOML


@pytest.fixture(scope="module")
def description(tmp_path_factory):
    path = tmp_path_factory.mktemp("inputs") / "inputs.toml"
    path.write_text(TOML)
    return path


def _pair(load=None):
    d = Driveline("pair")
    d.inertia("J1", J=1.0, w0=10.0).inertia("J2", J=1.0)
    if load is None:
        d.input("load", unit="Nm", start=2.0)
        load = Signal.product(Signal.input("load"), -1.0)
    d.torque("T", "J2", load)
    d.clutch("c", "J1", "J2", fn_max=100.0, mu=0.3)
    return d


def test_an_input_is_declared_read_and_held_at_its_start(description):
    spec = load_driveline(description)
    system = spec.driveline.system(RTOL)
    assert [(v.name, v.unit) for v in system.inputs] == [("load", "Nm"), ("press", "1")]
    np.testing.assert_array_equal(system.u0, [2.0, 1.0])
    text = spec.driveline.describe()
    assert "input load [Nm], start 2" in text and "normal input press" in text
    # the closed form: 30 N m slip until 10 - 30 t = 28 t, then locked, both decelerating at 2 / 2
    res = spec.driveline.simulate(1.0, rtol=RTOL, output_step=0.25)
    t_lock = 10.0 / 58.0
    w = 10.0 - 30.0 * t_lock - 1.0 * (1.0 - t_lock)
    frame = res.to_dataframe()
    assert frame["J1.w_rad_s"].iloc[-1] == pytest.approx(w, rel=1e-8)
    assert frame["J2.w_rad_s"].iloc[-1] == pytest.approx(w, rel=1e-8)
    assert list(zip(res.events.element, res.events.event)) == [("c", "stick")]
    assert res.events.time_s.iloc[0] == pytest.approx(t_lock, abs=1e-9)


def test_a_held_input_is_the_constant_signal_and_simulate_can_drive_it():
    held = _pair().simulate(1.0, rtol=RTOL, output_step=0.1)
    constant = _pair(Signal.constant(-2.0)).simulate(1.0, rtol=RTOL, output_step=0.1)
    np.testing.assert_array_equal(held.states, constant.states)
    # simulate(inputs=...): a number, a table; the network itself keeps its input
    d = _pair()
    other = d.simulate(1.0, rtol=RTOL, output_step=0.1, inputs={"load": 4.0}).to_dataframe()
    t_lock = 10.0 / 56.0   # with 4 N m: 10 - 30 t = (30 - 4) t, then both at -4 / 2
    assert other["J1.w_rad_s"].iloc[-1] == pytest.approx(10.0 - 30.0 * t_lock - 2.0 * (1.0 - t_lock), rel=1e-8)
    ramp = d.simulate(1.0, rtol=RTOL, output_step=0.1, inputs={"load": ([0.0, 1.0], [0.0, 6.0])})
    assert ramp.to_dataframe()["T.tau_Nm"].iloc[-1] == pytest.approx(-6.0, rel=1e-12)
    assert d.inputs == ("load",) and d.system(RTOL).u0.tolist() == [2.0]
    with pytest.raises(ParameterError, match="'lod' is not an input"):
        d.simulate(1.0, inputs={"lod": 1.0})


def test_a_torque_input_that_jumps_past_a_stuck_clutchs_limit_breaks_it_away_at_that_instant():
    """Locked at 10 rad/s, the torque input on J2 jumps from 0 to 100 N m at 0.5 s: the clutch would carry 50 N m >
    30, so it slips from 0.5 s on, J2 at +70 and J1 at +30 rad/s^2 -- decided at the change, not later."""
    d = Driveline("stuck")
    d.inertia("J1", J=1.0, w0=10.0).inertia("J2", J=1.0, w0=10.0)
    d.input("load", unit="Nm", start=0.0)
    d.torque("T", "J2", Signal.input("load"))
    d.clutch("c", "J1", "J2", fn_max=100.0, mu=0.3)
    sim = Simulation(d.system(RTOL))
    sim.advance(0.5)
    assert sim.m[0] == 0 and len(sim.events()) == 0   # stuck, nothing happened
    np.testing.assert_allclose(sim.x[2:4], [10.0, 10.0], rtol=1e-12)
    sim.advance(1.0, [100.0])
    np.testing.assert_allclose(sim.x[2:4], [10.0 + 30.0 * 0.5, 10.0 + 70.0 * 0.5], rtol=1e-9)
    events = sim.events()
    assert list(zip(events.element, events.event)) == [("c", "forward")]
    assert events.time_s.iloc[0] == 0.5


def test_the_cosimulation_takes_the_inputs_as_fmi_inputs(description):
    cls = DrivelineCoSimulation.for_description(description)
    assert [(v.name, v.unit, v.start) for v in cls.inputs] == [("load", "N.m", 2.0), ("press", "1", 1.0)]
    sim = cls()
    y = None
    for k in range(10):   # the clutch closed until 0.5 s (locked at 0.1724 s), then open: J2 decelerates alone
        y = sim.do_step(k * 0.1, 0.1, {"load": 2.0, "press": 1.0 if k < 5 else 0.0})
    w_lock = 10.0 - 30.0 * 10.0 / 58.0 - 1.0 * (0.5 - 10.0 / 58.0)
    assert y["J1.w"] == pytest.approx(w_lock, rel=1e-8)
    assert y["J2.w"] == pytest.approx(w_lock - 2.0 * 0.5, rel=1e-8)
    assert y["c.mode"] == 2   # free (MSL code)


def test_the_linear_model_of_a_torque_input():
    """Locked pair (same speed): a load torque on J2 decelerates both, d(w)/d(T) = -1 / (J1 + J2) with the
    product's -1; slipping (J1 at 10, J2 at 0), it reaches J2 alone: -1 / J2."""
    d = _pair()
    d2 = Driveline("locked")
    d2.inertia("J1", J=1.0, w0=5.0).inertia("J2", J=3.0, w0=5.0)
    d2.input("load", unit="Nm", start=2.0)
    d2.torque("T", "J2", Signal.product(Signal.input("load"), -1.0))
    d2.clutch("c", "J1", "J2", fn_max=100.0, mu=0.3)
    for net, expect in ((d, {"J1.w": 0.0, "J2.w": -1.0}), (d2, {"J1.w": -0.25, "J2.w": -0.25})):
        system = net.system(RTOL)
        op = OperatingPoint(system, 0.0, system.x0.copy(), system.u0.copy(), system.m0.copy())
        jac = jacobians(system, op, ["load"], None)
        names = [v.name for v in system.states]
        for state, b in expect.items():
            assert jac["B"][names.index(state), 0] == pytest.approx(b, abs=1e-9), (net.name, state)


@pytest.mark.parametrize("edit, match", [
    (("[input.press]\nstart = 1.0\n", ""), "no \\[input.press\\] table"),
    (("normal = { input = \"press\" }", "normal = 1.0"), "\\[input.press\\] drives nothing"),
    (("start = 1.0\n", "start = 1.0\nunit = \"bar\"\n"), "input.press.unit: unknown field"),
    (("torque = { product = [ { input = \"load\" }, -1 ] }",
      "torque = { product = [ { input = \"press\" }, { input = \"load\" } ] }"),
     "different units"),
    (("start = \"2 N m\"", "start = \"2 bar\""), "input.load.start"),
    (("normal = { input = \"press\" }", "normal = { input = 3 }"), "expected the name of an \\[input.NAME\\]"),
])
def test_bad_inputs_in_a_file_are_named(tmp_path, edit, match):
    old, new = edit
    assert old in TOML
    path = tmp_path / "bad.toml"
    path.write_text(TOML.replace(old, new, 1))
    with pytest.raises(ParameterError, match=match) as info:
        load_driveline(path).driveline.system(RTOL)
    assert "bad.toml" in str(info.value)


def test_what_an_input_cannot_drive_is_refused_by_name():
    d = Driveline("refuse")
    d.inertia("J1", J=1.0)
    d.input("w", unit="rad_s")
    with pytest.raises(ParameterError, match="motion source cannot follow a network input"):
        d.speed("S", "J1", Signal.input("w"))
    d.torque("T", "J1", Signal.input("x"))
    with pytest.raises(ParameterError, match="reads input 'x', which 'refuse' does not declare"):
        d.system(RTOL)
    with pytest.raises(ParameterError, match="declared twice"):
        d.input("w")
    with pytest.raises(ParameterError, match="not a column unit"):
        d.input("q", unit="furlong")
    with pytest.raises(ParameterError, match="cannot be a network input"):
        Signal.input("pos").breakpoints("e: position", "m")
    assert math.isfinite(_pair().system(RTOL).u0[0])


def test_a_controller_drives_a_torque_input_in_the_loop():
    """A proportional speed controller, sampled every h = 10 ms, sets the torque input of an inertia J = 2 kg m^2
    (zero-order hold): w_k = r - (r - w_0) (1 - h K / J)^k exactly, the integral of a held torque being exact."""
    from clutchlab.control import closed_loop

    J, K, h, r = 2.0, 40.0, 0.01, 5.0
    d = Driveline("speed_loop")
    d.inertia("J1", J=J, w0=1.0)
    d.input("T", unit="Nm")
    d.torque("drive", "J1", Signal.input("T"))
    res = closed_loop(d.system(RTOL), lambda t, y, mem: [K * (r - y[0])], h, 0.2, measure=["J1.w"],
                      actuate=["T"], compiled=False)
    k = np.arange(21)   # (the frame is sampled at the controller's instants)
    np.testing.assert_allclose(res.frame["time_s"].to_numpy(), k * h, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.frame["J1.w_rad_s"].to_numpy(), r - (r - 1.0) * (1.0 - h * K / J) ** k, rtol=1e-9)


def test_an_input_reaches_a_network_with_a_wet_clutch():
    """The wet clutch's graft passes the network's inputs through: a load torque input on the dynamometer of
    examples/driveline_wet_sae2.toml, held at -20 N m by a session, is the run with the load given to simulate; and
    it slows the dynamometer by 20 N m / 0.33 kg m^2 more than the run without it while the clutch is open (0.05 s)."""
    examples = Path(__file__).resolve().parents[2] / "examples"
    text = (examples / "driveline_wet_sae2.toml").read_text()
    text += '\n[input.load]\nstart = "0 N m"\n\n[torque.drag]\nflange = "dyno"\ntorque = { input = "load" }\n'
    d = parse_driveline(tomllib.loads(text), "wet_in.toml", examples).driveline
    sim = Simulation(d.system(1e-8))
    sim.advance(0.05, [-20.0])
    w_open = sim.x[sim.system.state_index("dyno.w")]
    free = d.simulate(0.05, rtol=1e-8, output_step=0.05).to_dataframe()["dyno.w_rad_s"].to_numpy()[-1]
    # (not exactly: the open clutch's viscous drag follows the lower speed, 1.5e-4 of the difference)
    assert free - w_open == pytest.approx(20.0 / 0.33 * 0.05, rel=1e-3)
    sim.advance(0.3)
    held = d.simulate(0.3, rtol=1e-8, output_step=0.3, inputs={"load": -20.0}).to_dataframe()
    assert sim.x[sim.system.state_index("dyno.w")] == pytest.approx(held["dyno.w_rad_s"].to_numpy()[-1], rel=1e-7)


def _wet_sae2(force, start=None):
    examples = Path(__file__).resolve().parents[2] / "examples"
    text = (examples / "driveline_wet_sae2.toml").read_text()
    old = 'force = { table = { times = [0.0, 0.05, 0.25], values = ["0 N", "0 N", "3 kN"] } }'
    assert old in text
    text = text.replace(old, force) + ("" if start is None else f'\n[input.F]\nstart = "{start}"\n')
    return parse_driveline(tomllib.loads(text), "wet_force.toml", examples).driveline


def test_a_wet_clutchs_force_is_a_network_input():
    """The wet clutch's force as a network input (its model's force_reference on a zero profile): held at its
    start it is the run of that constant profile, column for column; driven by a session (a host, an FMU, a
    controller) with a step at 0.05 s it follows the run of the profile that steps within 1 us (and without it the
    dynamometer keeps its speed but for the open clutch's drag); a negative reference releases, as zero."""
    held = _wet_sae2('force = { input = "F" }', "3 kN")
    profile = _wet_sae2('force = "3 kN"')
    a = held.simulate(0.3, rtol=1e-8, output_step=1e-3).to_dataframe()
    b = profile.simulate(0.3, rtol=1e-8, output_step=1e-3).to_dataframe()
    assert list(a.columns) == list(b.columns)
    for col in a.columns:
        if not pd.api.types.is_numeric_dtype(b[col]):   # the mode names
            assert list(a[col]) == list(b[col]), col
            continue
        np.testing.assert_allclose(a[col], b[col], rtol=1e-12, atol=1e-12 * max(1.0, np.max(np.abs(b[col]))),
                                   err_msg=col)
    stepped = _wet_sae2('force = { input = "F" }', "0 N")
    system = stepped.system(1e-8)
    sim = Simulation(system)
    sim.advance(0.05, [0.0])
    sim.advance(0.4, [3000.0])
    ref = stepped.simulate(0.4, rtol=1e-8, output_step=0.4,
                           inputs={"F": ([0.0, 0.05, 0.05 + 1e-6, 1.0], [0.0, 0.0, 3000.0, 3000.0])}).to_dataframe()
    n = system.state_index("dyno.w")
    w = sim.x[n]
    assert w == pytest.approx(ref["dyno.w_rad_s"].to_numpy()[-1], rel=1e-5)
    assert w < 0.5 * 1500 * math.pi / 30   # the input engaged the clutch: it braked the dynamometer
    untouched = _wet_sae2('force = { input = "F" }', "0 N")
    sim0 = Simulation(untouched.system(1e-8))
    sim0.advance(0.4, [0.0])
    assert sim0.x[n] > 0.99 * 1500 * math.pi / 30   # without it, only the open clutch's drag
    # a negative force reference releases (the actuator pushes only): as zero
    sim_neg = Simulation(untouched.system(1e-8))
    sim_neg.advance(0.4, [-5000.0])
    np.testing.assert_allclose(sim_neg.x, sim0.x, rtol=1e-12, atol=1e-12)


def test_a_wet_clutchs_force_port_takes_a_product_with_an_input():
    """The force is a port, so an input in a product works (before, only one bare input): twice an input held at
    1.5 kN is the run of a constant 3 kN to the last digits; and the actuator starts at the product's start."""
    doubled = _wet_sae2('force = { product = [{ input = "F" }, 2] }', "1.5 kN")
    profile = _wet_sae2('force = "3 kN"')
    a = doubled.simulate(0.3, rtol=1e-8, output_step=1e-2).to_dataframe()
    b = profile.simulate(0.3, rtol=1e-8, output_step=1e-2).to_dataframe()
    assert a["clutch.actuator_force_N"].iloc[0] == 3000.0
    for col in b.columns:
        if pd.api.types.is_numeric_dtype(b[col]):
            np.testing.assert_allclose(a[col], b[col], rtol=1e-12, atol=1e-12 * max(1.0, np.max(np.abs(b[col]))),
                                       err_msg=col)
    # driven by a host: the product follows the held input
    sim = Simulation(doubled.system(1e-8))
    sim.advance(0.3, [1500.0])
    assert sim.x[sim.system.state_index("dyno.w")] == pytest.approx(b["dyno.w_rad_s"].to_numpy()[-1], rel=1e-9)


@settings(max_examples=examples(10), deadline=None, derandomize=pinned())
@given(networks())
def test_a_held_input_changes_nothing_but_its_value_on_random_networks(d):
    """Every torque source of a random network (test_invariants.networks) multiplied by an input packed at 0.5 and
    held at 1 by a session: the run is the network's own, bit for bit, final state and events (the hold reaches
    every evaluation: a run that read the packed 0.5 anywhere would differ)."""
    held = d.without()   # (a copy: the network drawn is left as it is)
    names = []
    for e in d.elements:
        if e.kind == "torque":
            names.append(f"in_{e.name}")
            held.input(names[-1], unit="Nm", start=0.5)
            held = held.replace(e.name, signal=Signal.product(Signal.input(names[-1]), e.arguments["signal"]))
    assume(names)
    a, b = Simulation(d.system(1e-9)), Simulation(held.system(1e-9))
    a.advance(1.0)
    b.advance(1.0, np.ones(len(names)))
    np.testing.assert_array_equal(a.x, b.x)
    ea, eb = a.events(), b.events()
    assert list(zip(ea.time_s, ea.element, ea.event)) == list(zip(eb.time_s, eb.element, eb.event))


def test_the_cli_drives_inputs_with_values_quantities_and_csv_traces(tmp_path, description, capsys):
    """``clutchlab driveline simulate --input``: ``load`` held at 4 N m (a quantity) and ``press`` at 0.5 (a plain
    number) give the closed form: the clutch slides with 0.3 * 100 N * 0.5 = 15 N m, J1 decelerating at 15 and
    J2 accelerating at 15 - 4 = 11 rad/s^2, so they meet at t = 10 / 26; then both decelerate at 4 / 2.  The same
    values as CSV traces (time_s and a column named with its unit suffix) give the same run; bad options are one
    line each."""
    import pandas as pd

    from cli_checks import one_line_error
    from clutchlab.cli import main

    out = tmp_path / "held.csv"
    assert main(["driveline", "simulate", str(description), "-o", str(out), "--input", "load=4 N m",
                 "--input", "press=0.5"]) == 0
    frame = pd.read_csv(out)
    t_lock = 10.0 / 26.0
    w = 10.0 - 15.0 * t_lock - 2.0 * (1.0 - t_lock)
    assert frame["J1.w_rad_s"].iloc[-1] == pytest.approx(w, rel=1e-8)
    assert frame["J2.w_rad_s"].iloc[-1] == pytest.approx(w, rel=1e-8)
    assert frame["T.tau_Nm"].iloc[-1] == pytest.approx(-4.0, rel=1e-12)
    (tmp_path / "press.csv").write_text("# synthetic: a constant clutch command\ntime_s,press_1\n0,0.5\n2,0.5\n")
    (tmp_path / "load.csv").write_text("time_s,load_Nm\n0,4\n0.5,4\n2,4\n")
    traced = tmp_path / "traced.csv"
    assert main(["driveline", "simulate", str(description), "-o", str(traced), "--input",
                 f"press={tmp_path / 'press.csv'}", "--input", f"load={tmp_path / 'load.csv'}"]) == 0
    again = pd.read_csv(traced)
    np.testing.assert_allclose(again["J1.w_rad_s"], frame["J1.w_rad_s"], rtol=1e-8, atol=1e-9)
    capsys.readouterr()
    (tmp_path / "speed.csv").write_text("time_s,load_rad_s\n0,4\n1,4\n")
    (tmp_path / "nounit.csv").write_text("time_s,load\n0,4\n1,4\n")
    (tmp_path / "back.csv").write_text("time_s,load_Nm\n0,4\n0,4\n")
    for option, match in (("nope=1", "has no input 'nope' (inputs: load, press)"),
                          ("load", "expected NAME=VALUE"),
                          ("load=3 kg", "--input load = '3 kg': wrong unit"),
                          ("load=nan", "not a finite number"),
                          (f"load={tmp_path / 'speed.csv'}", "load_rad_s"),
                          (f"load={tmp_path / 'nounit.csv'}", "does not name its unit"),
                          (f"load={tmp_path / 'back.csv'}", "strictly increasing"),
                          (f"load={tmp_path / 'missing.csv'}", "no such file")):
        line = one_line_error(capsys, ["driveline", "simulate", str(description), "-o", str(tmp_path / "x.csv"),
                                       "--input", option])
        assert match in line, line
    line = one_line_error(capsys, ["driveline", "simulate", str(description), "-o", str(tmp_path / "x.csv"),
                                   "--input", "load=1", "--input", "load=2"])
    assert "given twice" in line
