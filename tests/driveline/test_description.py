"""Driveline TOML descriptions, the ``clutchlab driveline`` command and the shipped examples."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cli_checks import one_line_error
from clutchlab.cli import main
from clutchlab.driveline.description import load_driveline
from clutchlab.errors import ParameterError

from .test_friction import coupled_clutches, friction_network

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_the_examples_describe_the_python_networks():
    """The example files are the networks the friction tests build in Python: the same events, and the
    same trajectories column by column (the file groups its components by kind, so the order differs)."""
    for name, network, t_end in (("driveline_coupled_clutches.toml", coupled_clutches(), 1.5),
                                 ("driveline_test_friction.toml", friction_network(), 1.1)):
        spec = load_driveline(EXAMPLES / name)
        a = spec.driveline.simulate(t_end, rtol=1e-10, output_step=0.01)
        b = network.simulate(t_end, rtol=1e-10, output_step=0.01)
        ea, eb = a.events, b.events
        assert sorted(zip(ea.element, ea.event)) == sorted(zip(eb.element, eb.event))
        np.testing.assert_allclose(np.sort(ea.time_s.to_numpy()), np.sort(eb.time_s.to_numpy()), atol=1e-12)
        fa, fb = a.to_dataframe(), b.to_dataframe()
        assert set(fa.columns) == set(fb.columns)
        for col in fb.columns:
            if not pd.api.types.is_numeric_dtype(fb[col]):  # the modes by name
                assert list(fa[col]) == list(fb[col]), col
            else:
                np.testing.assert_allclose(fa[col].to_numpy(), fb[col].to_numpy(), rtol=1e-9, atol=1e-9, err_msg=col)


def test_simulate_writes_states_outputs_and_events(tmp_path, capsys):
    out, ev, fig = tmp_path / "tf.csv", tmp_path / "ev.csv", tmp_path / "tf.png"
    assert main(["driveline", "simulate", str(EXAMPLES / "driveline_test_friction.toml"), "-o", str(out),
                 "--events", str(ev), "--plot", str(fig)]) == 0
    assert "energy balance" in capsys.readouterr().out
    frame = pd.read_csv(out)
    for col in ("time_s", "inertia.w_rad_s", "inertia.phi_rad", "clutch.tau_Nm", "clutch.w_rel_rad_s",
                "clutch.mode_1", "brake.mode_1", "bearing_friction.tau_Nm", "energy_error_J"):
        assert col in frame, col
    assert len(frame) == 1101 and frame.time_s.iloc[-1] == pytest.approx(1.1)
    events = pd.read_csv(ev)
    assert list(events.columns) == ["time_s", "component", "event"]
    got = {(r.component, r.event): r.time_s for r in events.itertuples()}
    assert got[("bearing_friction", "forward")] == pytest.approx(math.asin(0.1) / (2 * math.pi), abs=1e-6)
    assert got[("clutch", "stick")] == pytest.approx(0.5315198891, abs=1e-6)
    assert fig.stat().st_size > 10_000
    # nothing is overwritten without --force, and a refused command writes nothing
    before = out.read_bytes()
    one_line_error(capsys, ["driveline", "simulate", str(EXAMPLES / "driveline_test_friction.toml"), "-o", str(out)])
    assert out.read_bytes() == before
    assert main(["driveline", "simulate", str(EXAMPLES / "driveline_test_friction.toml"), "-o", str(out),
                 "--output-step", "10 ms", "--t-end", "0.2 s", "--force"]) == 0
    assert len(pd.read_csv(out)) == 21


@pytest.mark.parametrize("killed", ["while writing", "while moving into place"])
def test_simulate_killed_between_its_writes_leaves_one_run(tmp_path, capsys, killed):
    """#33: ``driveline simulate`` wrote its CSV, events and figure one after the other; a run killed between
    two writes left the new CSV beside the old run's events and figure.  Now they replace the old ones together
    (:class:`clutchlab.io.files.OutputSet`): a run killed (``os._exit``, no ``finally``) after writing its first
    file leaves every old output; one killed while moving them into place leaves its journal, and the next run
    finishes the moves first (every output the killed run's).  No run leaves a temporary file behind."""
    import os
    import subprocess
    import sys

    import clutchlab

    out, ev, fig = tmp_path / "tf.csv", tmp_path / "ev.csv", tmp_path / "tf.png"
    argv = ["driveline", "simulate", str(EXAMPLES / "driveline_test_friction.toml"), "-o", str(out),
            "--events", str(ev), "--plot", str(fig)]
    assert main(argv + ["--t-end", "0.2 s"]) == 0
    old = {p: p.read_bytes() for p in (out, ev, fig)}
    assert sorted(tmp_path.iterdir()) == sorted(old)
    if killed == "while writing":   # killed as the second file is to be written
        die = ("real, calls = files.atomic_write_bytes, []\n"
               "def write(*args, **kwargs):\n"
               "    if calls:\n"
               "        os._exit(9)\n"
               "    calls.append(args[0])\n"
               "    return real(*args, **kwargs)\n"
               "files.atomic_write_bytes = write\n")
    else:                           # killed as the events file is to be moved into place
        die = ("real = os.replace\n"
               f"os.replace = lambda a, b: os._exit(9) if os.path.abspath(b) == {str(ev)!r} else real(a, b)\n")
    script = "import os, sys\nimport clutchlab.io.files as files\n" + die + \
        "from clutchlab.cli import main\nmain(sys.argv[1:])\n"
    env = dict(os.environ, PYTHONPATH=str(Path(clutchlab.__file__).resolve().parents[1]), MPLBACKEND="Agg")
    # the new run goes to 0.6 s: the clutch sticks at 0.53 s, an event the old run's file does not have
    run = subprocess.run([sys.executable, "-c", script, *argv, "--t-end", "0.6 s", "--force"], env=env,
                         timeout=600, capture_output=True, text=True)
    assert run.returncode == 9, run.stderr
    if killed == "while writing":
        assert {p: p.read_bytes() for p in old} == old                   # every output the old run's
        assert main(argv + ["--t-end", "0.6 s", "--force"]) == 0           # the next run
    else:
        assert main(argv) == 2   # the next run finishes the killed run's moves, then refuses to overwrite them
        assert "use --force" in capsys.readouterr().err
    frame, events = pd.read_csv(out), pd.read_csv(ev)
    assert frame.time_s.iloc[-1] == pytest.approx(0.6)
    assert ("clutch", "stick") in set(zip(events.component, events.event))
    assert fig.read_bytes() != old[fig]
    assert sorted(tmp_path.iterdir()) == sorted(old)                       # no temporary file left


def test_simulate_fixed_step_follows_the_adaptive_run(tmp_path, capsys):
    """``--fixed-step "1 ms"``: the core's fixed-step mode (1100 frames of 1 ms), said in the file's comment line.

    Tolerance, measured on TestFriction (1.1 s): the speeds follow the adaptive run within 0.036 rad/s (of up to
    3.2 rad/s).  A friction element sticks at the first frame end after the located instant, or one later
    (tests/numerics/test_fixed_step.py): the brake and the clutch (up to 50 N m on 1 kg m^2) can change a speed by
    50 rad/s^2 * 2 ms = 0.1 rad/s before they do, the bound.  The energy balance closes within 4.2e-4 J of the
    14.4 J input work (bound 1e-4 of it); the events are the same, each at a frame end."""
    example = str(EXAMPLES / "driveline_test_friction.toml")
    adaptive, fixed = tmp_path / "adaptive.csv", tmp_path / "fixed.csv"
    ev_a, ev_f = tmp_path / "ev_a.csv", tmp_path / "ev_f.csv"
    assert main(["driveline", "simulate", example, "-o", str(adaptive), "--events", str(ev_a)]) == 0
    assert main(["driveline", "simulate", example, "-o", str(fixed), "--events", str(ev_f), "--fixed-step", "1 ms"]) == 0
    assert "in fixed steps of 0.001 s" in capsys.readouterr().out
    assert fixed.read_text().splitlines()[0].startswith("# solver: fixed-step (real-time) mode, step 0.001 s")
    assert not adaptive.read_text().startswith("#")  # (an adaptive run's file is plain CSV, as before)
    a, f = pd.read_csv(adaptive), pd.read_csv(fixed, comment="#")
    assert list(a.columns) == list(f.columns) and len(f) == len(a) == 1101
    np.testing.assert_array_equal(f.time_s, a.time_s)
    speeds = [c for c in a.columns if c.endswith(".w_rad_s")]
    assert len(speeds) == 4 and max(np.max(np.abs(f[c] - a[c])) for c in speeds) < 0.1
    assert np.max(np.abs(f.energy_error_J)) < 1e-4 * np.max(np.abs(a.input_work_J))
    ea, ef = pd.read_csv(ev_a), pd.read_csv(ev_f)
    assert list(zip(ef.component, ef.event)) == list(zip(ea.component, ea.event)) and len(ef) == 6
    np.testing.assert_allclose(ef.time_s / 1e-3, np.round(ef.time_s / 1e-3), rtol=0, atol=1e-6)  # on frame ends
    assert np.all(ef.time_s >= ea.time_s - 1e-12) and np.all(ef.time_s <= ea.time_s + 2e-3)


@pytest.mark.parametrize("value, message", [("-1ms", "must be a time > 0"), ("abc", "cannot parse quantity"),
                                            ("0 s", "must be a time > 0"), ("1 kg", "wrong unit")])
def test_simulate_refuses_a_bad_fixed_step(tmp_path, capsys, value, message):
    out = tmp_path / "out.csv"
    line = one_line_error(capsys, ["driveline", "simulate", str(EXAMPLES / "driveline_test_friction.toml"),
                                   "-o", str(out), "--fixed-step", value])
    assert f"--fixed-step = {value!r}" in line and message in line
    assert not out.exists()


def test_describe_prints_the_schematic(capsys):
    assert main(["driveline", "describe", str(EXAMPLES / "driveline_coupled_clutches.toml")]) == 0
    text = capsys.readouterr().out
    assert "coupled_clutches: 4 inertias, 4 elements (3 friction)" in text
    assert "[J1] --(clutch1: friction fn_max = 20 N, mu 0.5, peak 1.1" in text
    assert "ground --(torque: torque 10 N m sine at 5 Hz" in text


BASE = """
[inertia.J1]
J = "1 kg m^2"
[inertia.J2]
J = "2 kg m^2"
"""


@pytest.mark.parametrize("body, fragments", [
    ('[clutch.c]\na = "J1"\nb = "J9"\nfn_max = "1 N"\n', ["clutch.c", "'J9' is not an inertia"]),
    ('[clutch.c]\na = "J1"\nb = "J1"\nfn_max = "1 N"\n', ["clutch.c", "both flanges are 'J1'"]),
    ('[clutch.c]\na = "J1"\nfn_max = "1 N"\n', ["clutch.c", "missing field 'b'"]),
    ('[inertia.J3]\nJ = "-1 kg m^2"\n', ["inertia.J3.J = '-1 kg m^2'", "must be > 0"]),
    ('[gearbox.g]\nratio = 3\n', ["unknown table [gearbox]"]),
    ('[clutch.c]\na = "J1"\nb = "J2"\nfn_max = "1 N m"\n', ["clutch.c.fn_max", "wrong unit"]),
    ('[clutch.c]\na = "J1"\nb = "J2"\nfn_max = "1 N"\ncolour = "red"\n', ["clutch.c.colour", "unknown field"]),
    ('[torque.T]\nflange = "J1"\ntorque = { square = { amplitude = 1 } }\n', ["torque.T.torque", "unknown signal 'square'"]),
    ('[torque.T]\nflange = "J1"\ntorque = { sine = { amplitude = "1 N m" } }\n', ["torque.T.torque", "needs an amplitude and a frequency"]),
    ('[simulation]\nt_end = "soon"\n', ["simulation.t_end", "cannot parse"]),
])
def test_bad_descriptions_name_file_key_and_value(tmp_path, capsys, body, fragments):
    path = tmp_path / "bad.toml"
    path.write_text(BASE + body)
    with pytest.raises(ParameterError) as exc:
        load_driveline(path)
    for fragment in fragments + [str(path)]:
        assert fragment in str(exc.value), str(exc.value)
    line = one_line_error(capsys, ["driveline", "simulate", str(path), "-o", str(tmp_path / "out.csv"),
                                   "--t-end", "1 s"])
    assert fragments[-1] in line and not (tmp_path / "out.csv").exists()


@pytest.mark.parametrize("body, fragments", [
    ('[gear.g]\na = "J1"\nb = "J2"\nratio = 0\n', ["gear.g", "ratio = 0"]),
    ('[speed.s]\nflange = "J1"\nspeed = { step = { height = "1 rad/s", start = "1 s" } }\n',
     ["speed.s", "speed step would need an infinite torque"]),
    ('[speed.s]\nflange = "J1"\nspeed = "3 N m"\n', ["speed.s.speed", "wrong unit"]),
    ('[spring.k]\na = "J1"\nb = "J2"\ncurve = 5\n', ["spring.k.curve", "expected rows"]),
    ('[spring.k]\na = "J1"\nb = "J2"\ncurve = [["0 rad", "0 N m"]]\n', ["spring.k", "at least 2 rows"]),
    ('[spring.k]\na = "J1"\nb = "J2"\ncurve = [[0, 0], [1, 2]]\ninterpolation = "spline"\n',
     ["spring.k.interpolation", "expected \"linear\" or \"pchip\""]),
    ('[backlash.l]\na = "J1"\nb = "J2"\nc = "1 N m/rad"\nb_gap = "0 deg"\n', ["backlash.l.b_gap = '0 deg'", "must be > 0"]),
    ('[mass.m]\nm = "1 kg"\n', ["[mass] belongs to a translational driveline"]),
    ('[driveline]\ndomain = "hydraulic"\n', ["driveline.domain = 'hydraulic'"]),
])
def test_bad_element_descriptions_name_file_key_and_value(tmp_path, body, fragments):
    path = tmp_path / "bad.toml"
    path.write_text(BASE + body)
    with pytest.raises(ParameterError) as exc:
        load_driveline(path)
    for fragment in fragments + [str(path)]:
        assert fragment in str(exc.value), str(exc.value)


def test_every_element_reads_with_units_as_the_python_network(tmp_path):
    """A file with one component of each new kind, quantities in other units than SI, gives the network
    built in Python with SI numbers: the same columns and trajectories."""
    from clutchlab.driveline import Driveline, Signal

    path = tmp_path / "all.toml"
    path.write_text("""
[driveline]
name = "all"
[inertia.engine]
J = "2000 kg cm^2"
[inertia.input]
J = "0.05 kg m^2"
[inertia.output]
J = "1 kg m^2"
[inertia.wheel]
J = "3 kg m^2"
[speed.drive]
flange = "engine"
speed = { ramp = { height = "1000 rpm", duration = "0.5 s", offset = "600 rpm" } }
[spring.damper_spring]
a = "engine"
b = "input"
curve = [["-10 deg", "-300 N m"], ["0 deg", "0 N m"], ["10 deg", "200 N m"]]
interpolation = "pchip"
d = "0.5 N m s/rad"
[gear.gearbox]
a = "input"
b = "output"
ratio = 3.5
[backlash.lash]
a = "output"
b = "wheel"
c = "5 kN m/rad"
b_gap = "2 deg"
d = "2 N m s/rad"
[one_way_clutch.freewheel]
a = "ground"
b = "wheel"
""")
    spec = load_driveline(path)
    d = Driveline("all")
    d.inertia("engine", J=0.2).inertia("input", J=0.05).inertia("output", J=1.0).inertia("wheel", J=3.0)
    rpm = math.pi / 30.0
    d.speed("drive", "engine", Signal.ramp(1000 * rpm, 0.5, offset=600 * rpm))
    deg = math.pi / 180.0
    from clutchlab.curves import Curve
    d.spring("damper_spring", "engine", "input", Curve([-10 * deg, 0.0, 10 * deg], [-300.0, 0.0, 200.0], kind="pchip"),
             d=0.5)
    d.gear("gearbox", "input", "output", 3.5)
    d.backlash("lash", "output", "wheel", c=5000.0, b_gap=2 * deg, d=2.0)
    d.one_way_clutch("freewheel", "ground", "wheel")
    a = spec.driveline.simulate(1.0, output_step=0.01).to_dataframe()
    b = d.simulate(1.0, output_step=0.01).to_dataframe()
    assert list(a.columns) == list(b.columns)
    for col in b.columns:
        if pd.api.types.is_numeric_dtype(b[col]):
            np.testing.assert_allclose(a[col], b[col], rtol=1e-12, atol=1e-12, err_msg=col)
    assert abs(a["energy_error_J"]).max() < 1e-6 * a["input_work_J"].abs().max()
    assert "[input] --(gearbox: gear, w_a = 3.5 w_b)-- [output]" in spec.driveline.describe()


def test_a_translational_file_has_masses_forces_and_metre_columns(tmp_path):
    """A sled (10 kg at 2 m/s) on a block (5 kg) held by dry friction (0.3 x 100 N): the sled slides
    forward over the block and both decelerate/accelerate by 30 N until they move together at the
    momentum-conserving speed 2 x 10 / 15 m/s: the sled at -3 m/s^2, the block at +6, the slip of 2 m/s
    closes at 9 m/s^2, after ``t = 2 / 9`` s."""
    path = tmp_path / "sled.toml"
    path.write_text("""
[driveline]
name = "sled"
domain = "translational"
[mass.sled]
m = "10 kg"
v0 = "2 m/s"
[mass.block]
m = "5000 g"
[clutch.contact]
a = "sled"
b = "block"
fn_max = "100 N"
mu = 0.3
""")
    spec = load_driveline(path)
    res = spec.driveline.simulate(0.5, output_step=0.1)
    df = res.to_dataframe()
    for col in ("sled.s_m", "sled.v_m_s", "contact.f_N", "contact.v_rel_m_s", "contact.mode_1"):
        assert col in df, col
    (t, name), = zip(res.events.time_s, res.events.event)
    assert name == "stick" and t == pytest.approx(2.0 / 9.0, abs=1e-9)
    assert df["block.v_m_s"].iloc[-1] == pytest.approx(4.0 / 3.0, rel=1e-10)
    assert "sled: 2 masses, 1 elements" in spec.driveline.describe()


def test_an_eclutch_file_is_the_python_network(tmp_path):
    """``[eclutch.NAME]`` with a position signal in mm, the axial model and its travel: the same network
    as the Python API's ``eclutch``; a missing parameter file and a wrong model are one clear error."""
    from clutchlab.driveline import Driveline, Signal

    path = tmp_path / "ec.toml"
    path.write_text("""
[inertia.engine]
J = "0.2 kg m^2"
w0 = "2000 rpm"
[inertia.input]
J = "0.05 kg m^2"
[eclutch.clutch]
a = "engine"
b = "input"
position = { ramp = { height = "-7 mm", duration = "0.5 s", offset = "7 mm" } }
model = 2
travel = "7 mm"
points = 71
""")
    spec = load_driveline(path)
    d = Driveline("driveline")
    d.inertia("engine", J=0.2, w0=2000 * math.pi / 30).inertia("input", J=0.05)
    d.eclutch("clutch", "engine", "input", position=Signal.ramp(-7e-3, 0.5, offset=7e-3), model=2, travel=7e-3,
              points=71)
    a = spec.driveline.simulate(0.6, output_step=0.05).to_dataframe()
    b = d.simulate(0.6, output_step=0.05).to_dataframe()
    for col in ("engine.w_rad_s", "input.w_rad_s", "clutch.tau_Nm", "clutch.fn_N"):
        np.testing.assert_allclose(a[col], b[col], rtol=1e-12, atol=1e-12, err_msg=col)
    assert a["clutch.fn_N"].max() > 1000.0
    for body, fragment in (('parameters = "nowhere.toml"\n', "clutch.parameters = 'nowhere.toml': no such file"),
                           ('model = 7\n', r"eclutch\.clutch\.model = 7: is above its range \[0, 4\]")):
        bad = tmp_path / "bad.toml"
        bad.write_text(path.read_text().replace("model = 2\n", body))
        with pytest.raises(ParameterError, match=fragment):
            load_driveline(bad)


def test_speeds_and_frequencies_in_hz_or_rpm_are_revolutions():
    """``w0 = "1 Hz"`` is one revolution per second (2 pi rad/s, as ``"1 rps"``; pint alone gives 1 rad/s) and a
    sine at ``frequency = "60 rpm"`` runs at 1 Hz (pint alone: 6.28 Hz).  Closed forms: a free inertia keeps
    2 pi rad/s; one driven by ``sin(2 pi f t)`` N m from rest turns at ``(1 - cos(2 pi f t)) / (2 pi f J)``."""
    import tomllib

    from clutchlab.driveline.description import parse_driveline

    doc = tomllib.loads("""
[driveline]
name = "hz"
[inertia.free]
J = "1 kg m^2"
w0 = "1 Hz"
[inertia.driven]
J = "2 kg m^2"
[torque.sine]
flange = "driven"
torque = { sine = { amplitude = "1 N m", frequency = "60 rpm" } }
""")
    res = parse_driveline(doc, "hz.toml").driveline.simulate(0.5, output_step=0.25)
    frame = res.to_dataframe()
    np.testing.assert_allclose(frame["free.w_rad_s"], 2 * math.pi, rtol=1e-12)
    t = frame["time_s"].to_numpy()
    np.testing.assert_allclose(frame["driven.w_rad_s"], (1 - np.cos(2 * math.pi * t)) / (2 * math.pi * 2.0),
                               rtol=1e-5, atol=1e-9)


@pytest.mark.parametrize("tables, message", [
    ("[inertia.J1]\nJ = 1.0\n[simulation]\nrtol = 0\n", "simulation.rtol = 0: must be in (0, 1)"),
    ("[inertia.J1]\nJ = 1.0\n[simulation]\nt_end = \"-1 s\"\n", "simulation.t_end = '-1 s': must be > 0 [s]"),
    ("[inertia.J1]\nJ = 1.0\n[simulation]\noutput_step = 0\n", "simulation.output_step = 0: must be > 0 [s]"),
    ("[inertia.J1]\nJ = 1.0\nw0 = 2.0\n", "f: a one-way clutch cannot start with flange b slower than flange a")])
def test_describe_refuses_what_simulate_refuses(tmp_path, capsys, tables, message):
    """``describe`` passed ``rtol = 0`` and a one-way clutch started backward, which ``simulate`` refuses (#33)."""
    path = tmp_path / "owc.toml"
    path.write_text('[driveline]\nname = "owc"\n[inertia.J2]\nJ = 1.0\n[one_way_clutch.f]\na = "J1"\nb = "J2"\n'
                    + tables)
    for command in ("describe", "simulate"):
        argv = ["driveline", command, str(path)] + (["-o", str(tmp_path / "o.csv"), "--t-end", "1 s"]
                                                    if command == "simulate" else [])
        line = one_line_error(capsys, argv)
        assert message in line, (command, line)
