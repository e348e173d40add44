"""``clutchlab control trim|linearize|bode|design``: outputs, refusals, nothing left behind."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("control")

from cli_checks import one_line_error  # noqa: E402
from clutchlab.cli import main  # noqa: E402


def test_trim_linearize_and_bode_of_the_eclutch(tmp_path, capsys):
    op = tmp_path / "op.json"
    assert main(["control", "trim", "eclutch", "--at", "4 mm", "-o", str(op)]) == 0
    doc = json.loads(op.read_text())
    assert doc["state.bearing_position_m"] == pytest.approx(4e-3, rel=1e-9)
    assert doc["modes"]["friction_mode_bearing"] == "slip_forward"
    assert -12.0 < doc["input.motor_voltage_V"] < 12.0
    lin = tmp_path / "lin.json"
    assert main(["control", "linearize", "eclutch", "--at", "4 mm", "-u", "motor_voltage", "-y", "bearing_position",
                 "-y", "pressure", "-o", str(lin)]) == 0
    m = json.loads(lin.read_text())
    assert m["inputs"] == ["motor_voltage_V"] and m["outputs"] == ["bearing_position_m", "pressure_Pa"]
    assert m["units"]["pressure_Pa"] == "Pa" and np.shape(m["A"]) == (len(m["states"]),) * 2
    # the JSON's matrices give the same DC gain as the Python API
    A, B, C = (np.array(m[k]) for k in "ABC")
    assert (-C @ np.linalg.solve(A, B))[0, 0] == pytest.approx(2.77e-3, rel=0.02)
    png, table, poles = tmp_path / "bode.png", tmp_path / "bode.csv", tmp_path / "poles.csv"
    assert main(["control", "bode", "eclutch", "--at", "1 mm", "--at", "7 mm", "-u", "motor_voltage", "-y",
                 "bearing_position", "-o", str(png), "--table", str(table), "--poles", str(poles),
                 "--fmin", "1 Hz", "--fmax", "200 Hz"]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    t = pd.read_csv(table)
    assert set(t.operating_point) == {"bearing at 1 mm", "bearing at 7 mm"}
    assert t.frequency_Hz.min() == pytest.approx(1.0) and t.frequency_Hz.max() == pytest.approx(200.0)
    p = pd.read_csv(poles)
    assert (p[p.bearing_position_m == 7e-3].pole_real_1_s > 0).any()  # beyond the diaphragm's peak
    capsys.readouterr()


def test_refusals_are_one_line_and_leave_nothing(tmp_path, capsys):
    out = tmp_path / "op.json"
    line = one_line_error(capsys, ["control", "trim", "eclutch", "--at", "40 mm", "-o", str(out)])
    assert "outside the CSC travel" in line and not out.exists()
    line = one_line_error(capsys, ["control", "linearize", "eclutch", "--at", "4 mm", "-u", "volts", "-o",
                                   str(tmp_path / "l.json")])
    assert "unknown input 'volts'" in line
    line = one_line_error(capsys, ["control", "trim", "eclutch", "--target", "bearing_position=4 mm", "-o", str(out)])
    assert "conditions" in line and not out.exists()
    line = one_line_error(capsys, ["control", "trim", "wet", "--at", "4 mm", "-o", str(out)])
    assert "--at is the E-clutch's" in line
    out.write_text("mine")
    line = one_line_error(capsys, ["control", "trim", "eclutch", "--at", "4 mm", "-o", str(out)])
    assert "exists" in line and out.read_text() == "mine"
    line = one_line_error(capsys, ["control", "bode", "eclutch", "--at", "4 mm", "-o", str(tmp_path / "b.png"),
                                   "--fmin", "10 Hz", "--fmax", "1 Hz"])
    assert "fmin" in line and not (tmp_path / "b.png").exists()


def test_generic_trim_of_the_linear_parts_of_a_model(tmp_path, capsys):
    """The generic options on the E-clutch's closed loop: reference held, all states steady."""
    out = tmp_path / "op.json"
    assert main(["control", "trim", "eclutch", "--input", "bearing_reference", "--at", "2 mm", "-o", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["state.bearing_position_m"] == pytest.approx(2e-3, rel=1e-8)
    assert doc["input.bearing_reference_m"] == 2e-3
    capsys.readouterr()


def test_emtc_coil_at_a_current_from_the_command_line(tmp_path, capsys):
    """``--coil-drive current``: the EMTC's coil trimmed at a current and linearised along the rising branch
    of its magnet (the same model as the Python API's); refusals are one line and write nothing."""
    from clutchlab.control import linearize, operating_point
    from clutchlab.emtc.system import BenchOptions, bench_system

    common = ["emtc", "--coil-drive", "current", "--set", "throttle=0.2", "--set", "coil_current_command=1.5 A",
              "--settle", "1 s"]
    op = tmp_path / "op.json"
    assert main(["control", "trim", *common, "-o", str(op)]) == 0, capsys.readouterr()
    doc = json.loads(op.read_text())
    assert doc["state.i2_A"] == pytest.approx(1.5, rel=1e-9) and doc["modes"]["armature_mode"] == "contact"
    lin = tmp_path / "lin.json"
    assert main(["control", "linearize", *common, "-u", "coil_current_command", "-y", "coupling_torque",
                 "--branch", "i2=rising", "-o", str(lin)]) == 0, capsys.readouterr()
    m = json.loads(lin.read_text())
    assert m["directions"] == {"i2": "rising"} and m["states"] == ["i1_A", "i2_A"]
    A, B, C = (np.array(m[k]) for k in "ABC")
    s = bench_system(cosimulation=True, options=BenchOptions(coil_drive="current"))
    point = operating_point(s, inputs={"throttle": 0.2, "coil_current_command": 1.5}, settle=1.0)
    G = linearize(point, inputs=["coil_current_command"], outputs=["coupling_torque"], directions={"i2": "rising"})
    assert (-C @ np.linalg.solve(A, B))[0, 0] == pytest.approx(float(np.squeeze(G.dcgain())), rel=1e-9)
    bad = tmp_path / "bad.json"
    line = one_line_error(capsys, ["control", "trim", "emtc", "--coil-drive", "current", "--set",
                                   "coil_current_command=6 A", "-o", str(bad)])
    assert "coil_current_command = 6 is outside its physical range" in line and not bad.exists()
    line = one_line_error(capsys, ["control", "trim", "wet", "--coil-drive", "current", "-o", str(bad)])
    assert "--coil-drive is the EMTC's" in line
    line = one_line_error(capsys, ["control", "linearize", *common, "--branch", "i2", "-o", str(bad)])
    assert "--branch 'i2'" in line and not bad.exists()


def test_emtc_trimmed_far_from_the_origin_of_time_is_the_same_model(tmp_path, capsys):
    """``--time 1e12 s --settle 0.5 s`` hung (#33): a run starting far past the controller's samples caught up
    with them one sample at a time (1e14 of them).  It now starts at the next sample, and the EMTC, whose
    inputs hold beyond its profiles, linearises there as at 1000 s."""
    out = {}
    for t in ("1e12 s", "1000 s"):
        path = tmp_path / f"lin_{t.split()[0]}.json"
        assert main(["control", "linearize", "emtc", "--time", t, "--settle", "0.5 s", "-o", str(path)]) == 0
        out[t] = json.loads(path.read_text())
    capsys.readouterr()
    assert out["1e12 s"]["operating_point"]["time_s"] == 1e12
    for k in "ABCD":
        a, b = np.array(out["1e12 s"][k]), np.array(out["1000 s"][k])
        assert np.max(np.abs(a - b)) <= 1e-9 * np.max(np.abs(b)), k


SPRING_DAMPER = """
[driveline]
name = "sd"
[input.load]
start = "1 N m"
[inertia.J1]
J = "0.5 kg m^2"
[spring_damper.k]
a = "J1"
b = "ground"
c = "100 N m/rad"
d = "2 N m s/rad"
[torque.T]
flange = "J1"
torque = { input = "load" }
"""


def test_linearize_and_bode_of_a_driveline_name_its_signals_for_python_control(tmp_path, capsys):
    """Every ``control linearize``/``bode`` of a driveline failed with a traceback: python-control refuses the ``.``
    of ``k.tau_Nm`` in a signal name (#33).  The signals are the columns with ``_`` for ``.``, mapped back in
    ``columns``; the model is the closed form of J phi'' = -c phi - d phi' + T: A = [[0, 1], [-c/J, -d/J]],
    B = [0, 1/J], and the spring-damper's torque per load torque is (c + i d w) / (c - J w^2 + i d w)."""
    import control

    from clutchlab.control import linearize
    from clutchlab.control.linear import signal_name
    from clutchlab.driveline.description import load_driveline

    path = tmp_path / "sd.toml"
    path.write_text(SPRING_DAMPER)
    out = tmp_path / "lin.json"
    assert main(["control", "linearize", "driveline", str(path), "-y", "k.tau_Nm", "-o", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["states"][:2] == ["J1_phi_rad", "J1_w_rad_s"] and doc["inputs"] == ["load_Nm"]
    assert doc["outputs"] == ["k_tau_Nm"] and doc["columns"]["k_tau_Nm"] == "k.tau_Nm"
    np.testing.assert_allclose(np.asarray(doc["A"])[:2, :2], [[0.0, 1.0], [-200.0, -4.0]], rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(np.asarray(doc["B"])[:2, 0], [0.0, 2.0], rtol=1e-7, atol=1e-9)
    table = tmp_path / "bode.csv"
    assert main(["control", "bode", "driveline", str(path), "-y", "k.tau_Nm", "-o", str(tmp_path / "bode.png"),
                 "--table", str(table), "--fmin", "0.1 Hz", "--fmax", "10 Hz"]) == 0
    frame = pd.read_csv(table)
    w = 2 * np.pi * frame["frequency_Hz"].to_numpy()
    expected = np.abs((100.0 + 2j * w) / (100.0 - 0.5 * w**2 + 2j * w))
    np.testing.assert_allclose(frame["gain_k_tau_Nm__load_Nm"], expected, rtol=1e-6)
    # python-control's own tools take the model: a unity feedback of the spring torque
    sys = linearize(load_driveline(path).driveline.system(), outputs=["k.tau_Nm"])
    assert signal_name("k.tau_Nm") in sys.output_labels
    again = linearize(load_driveline(path).driveline.system(), outputs=["k_tau_Nm"])   # either spelling
    assert list(again.output_labels) == ["k_tau_Nm"] and np.array_equal(again.C, sys.C)
    loop = control.feedback(sys, 1)
    assert np.all(np.real(control.poles(loop)) < 0)


@pytest.mark.parametrize("option, value, message", [("--settle", "-1 s", "settle = -1.0: must be a time >= 0"),
                                                    ("--time", "inf s", "--time = 'inf s': not a finite number")])
def test_a_negative_settle_or_an_infinite_time_is_refused(tmp_path, capsys, option, value, message):
    """``--settle -1 s`` was silently ignored (#33)."""
    path = tmp_path / "sd.toml"
    path.write_text(SPRING_DAMPER)
    line = one_line_error(capsys, ["control", "linearize", "driveline", str(path), option, value,
                                   "-o", str(tmp_path / "lin.json")])
    assert message in line, line
    assert not (tmp_path / "lin.json").exists()


def test_design_a_pi_and_run_the_closed_loop_from_the_command_line(tmp_path, capsys):
    """#33: ``control design`` as the API has it. The JSON's PI is checked on the linear model the API gives
    (|L(j w_c)| = 1 and the phase margin at the crossover, Astrom and Murray's loop-shaping conditions), and
    its run equals ``closed_loop`` called with the same discrete controller."""
    import control

    from clutchlab.control import linearize
    from clutchlab.control.design import PI
    from clutchlab.control.loop import closed_loop
    from clutchlab.eclutch import EClutch

    pi_json, run = tmp_path / "pi.json", tmp_path / "run.csv"
    assert main(["control", "design", "eclutch", "--at", "4 mm", "-u", "motor_voltage", "-y", "bearing_position",
                 "--crossover", "5 Hz", "--phase-margin", "60 deg", "-o", str(pi_json), "--run", str(run),
                 "--step", "0.2 mm", "--t-end", "0.15 s", "--sample-time", "1 ms"]) == 0
    out = capsys.readouterr().out
    assert "Kp = " in out and "final error" in out
    doc = json.loads(pi_json.read_text())
    assert doc["kp_unit"] == "V/m" and doc["input"] == "motor_voltage_V" and doc["output"] == "bearing_position_m"
    assert doc["operating_output"] == pytest.approx(4e-3, rel=1e-9)
    op = EClutch().operating_point(4e-3)
    G = linearize(op, inputs=["motor_voltage"], outputs=["bearing_position"])
    w = 2 * np.pi * 5.0
    L = complex(np.squeeze(PI(doc["kp"], doc["ti_s"]).tf()(1j * w) * np.squeeze(G(1j * w))))
    assert abs(L) == pytest.approx(1.0, rel=1e-6)
    assert np.degrees(np.angle(L)) == pytest.approx(-180.0 + 60.0, abs=1e-4)
    assert doc["achieved"]["phase_margin_deg"] == pytest.approx(60.0, abs=1e-4)
    assert all(re < 0 for re, _ in doc["closed_loop_poles"])
    ref = closed_loop(op, PI(doc["kp"], doc["ti_s"]).discrete(1e-3), 1e-3, 0.15, measure=["bearing_position"],
                      actuate=["motor_voltage"], reference=4e-3 + 2e-4).frame
    got = pd.read_csv(run, comment="#")
    assert list(got.columns) == list(ref.columns) and len(got) == 151
    for c in ("bearing_position_m", "motor_voltage_V", "reference_bearing_position_m"):
        np.testing.assert_allclose(got[c], ref[c], rtol=1e-8, atol=1e-12, err_msg=c)
    assert got["reference_bearing_position_m"].iloc[0] == pytest.approx(4.2e-3, rel=1e-9)
    assert control.dcgain(G) > 0
    # refusals: one line, nothing written
    for argv, fragment in [
        (["-u", "motor_voltage", "-u", "bearing_reference", "-y", "bearing_position", "--crossover", "5 Hz"],
         "a PI drives one input from one output"),
        (["-u", "motor_voltage", "-y", "bearing_position", "--crossover", "600 Hz", "--run", str(tmp_path / "r.csv")],
         "at or above the Nyquist frequency 500 Hz"),
        (["-u", "motor_voltage", "-y", "bearing_position", "--crossover", "5 Hz", "--phase-margin", "95 deg"],
         "phase_margin_deg = 95"),
    ]:
        argv = ["control", "design", "eclutch", "--at", "4 mm", *argv, "-o", str(tmp_path / "x.json")]
        if "--phase-margin" not in argv:
            argv += ["--phase-margin", "60"]
        assert fragment in one_line_error(capsys, argv)
        assert not (tmp_path / "x.json").exists() and not (tmp_path / "r.csv").exists()
