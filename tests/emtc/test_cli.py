"""``clutchlab emtc`` commands and the demo section."""

import numpy as np
import pandas as pd
import pytest

from cli_checks import fixed_step_frames
from clutchlab.cli import main
from clutchlab.emtc.magnet import bundled_forc
from clutchlab.hysteresis import Preisach


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def forc_csv(tmp_path_factory):
    frame = bundled_forc()
    path = tmp_path_factory.mktemp("forc") / "forc.csv"
    frame.to_csv(path, index=False)
    return path


def test_identify_run_and_inverse(tmp_path, capsys, forc_csv):
    model_path = tmp_path / "model.json"
    code, out, _ = run(capsys, "emtc", "preisach", "identify", forc_csv, "-o", model_path)
    assert code == 0 and "airgap 0.2 mm" in out and "55 grid points" in out
    model = Preisach.from_json(model_path)
    assert model.n_airgaps == 7
    np.testing.assert_allclose(model.grid, np.arange(0, 4.51, 0.5), atol=0.01)
    # refuses to overwrite, one-line error
    code, _, err = run(capsys, "emtc", "preisach", "identify", forc_csv, "-o", model_path)
    assert code == 2 and err.startswith("clutchlab: error:") and "exists" in err and err.count("\n") == 1
    code, _, _ = run(capsys, "emtc", "preisach", "identify", forc_csv, "-o", model_path, "--force")
    assert code == 0
    # forward run
    inp = tmp_path / "in.csv"
    cur = np.r_[np.linspace(0, 4.0, 30), np.linspace(4.0, 1.0, 20)]
    pd.DataFrame({"current": cur, "airgap": 0.7e-3}).to_csv(inp, index=False)
    out_csv = tmp_path / "out.csv"
    code, _, _ = run(capsys, "emtc", "preisach", "run", model_path, inp, "-o", out_csv)
    assert code == 0
    df = pd.read_csv(out_csv, comment="#")
    np.testing.assert_allclose(df["force_model"], model.simulate(cur, airgap=0.7e-3), rtol=1e-8)
    # inverse run reproduces the current
    inv_in = tmp_path / "target.csv"
    pd.DataFrame({"force": df["force_model"], "airgap": 0.7e-3}).to_csv(inv_in, index=False)
    code, _, _ = run(capsys, "emtc", "preisach", "run", model_path, inv_in, "-o", tmp_path / "inv.csv", "--inverse")
    assert code == 0
    back = pd.read_csv(tmp_path / "inv.csv", comment="#")
    np.testing.assert_allclose(back["current"], cur, atol=1e-6)
    # bad input: current outside the grid -> one-line error
    pd.DataFrame({"current": [0.0, 6.0], "airgap": 0.7e-3}).to_csv(inp, index=False)
    code, _, err = run(capsys, "emtc", "preisach", "run", model_path, inp, "-o", out_csv, "--force")
    assert code == 2 and "outside the Preisach grid" in err
    pd.DataFrame({"current": [0.0, 1.0]}).to_csv(inp, index=False)
    code, _, err = run(capsys, "emtc", "preisach", "run", model_path, inp, "-o", out_csv, "--force")
    assert code == 2 and "missing column 'airgap'" in err


def test_simulate_scenario_with_plot(tmp_path, capsys):
    sc = tmp_path / "s.toml"
    sc.write_text('[scenario]\nduration = "0.5 s"\nspeed_difference = "0 m/s"\nthrottle_end = 0.3\n')
    out = tmp_path / "run.csv"
    code, text, _ = run(capsys, "emtc", "simulate", sc, "-o", out, "--plot", tmp_path / "run.png")
    assert code == 0 and "lock-up" in text
    df = pd.read_csv(out, comment="#")
    assert len(df) == 251 and {"t1_Nm", "t2_Nm", "t3_Nm", "slip_speed_rad_s", "coupling_mode"} <= set(df.columns)
    assert (tmp_path / "run.png").read_bytes()[:4] == b"\x89PNG"
    code, _, err = run(capsys, "emtc", "simulate", sc, "-o", out)
    assert code == 2 and "exists" in err
    sc.write_text("[scenario]\nduration = -1\n")
    code, _, err = run(capsys, "emtc", "simulate", sc, "-o", out, "--force")
    assert code == 2 and "duration" in err


def test_demo_section_is_synthetic_and_complete():
    from clutchlab.demo.emtc import demo_section

    msgs = []
    sec = demo_section(progress=msgs.append)
    assert "synthetic" in sec.provenance
    names = {getattr(i, "name", None) for i in sec.items}
    assert {"emtc_loops", "emtc_compensation", "emtc_bench_slipping", "emtc_bench_locked"} <= names
    comp = next(i for i in sec.items if getattr(i, "name", "") == "emtc_compensation_error").frame
    # compensation with the inverse model beats the anhysteretic inverse by a wide margin (Fig. 8)
    assert comp["RMS error [N]"].iloc[0] < 0.3 * comp["RMS error [N]"].iloc[1]
    assert len(msgs) >= 3


def test_simulate_plot_closes_its_figure(tmp_path, capsys):
    """``emtc simulate --plot`` saves the figure and closes it: nothing stays open in the process."""
    import matplotlib.pyplot as plt
    from pathlib import Path

    plt.close("all")
    scenario = Path(__file__).resolve().parents[2] / "examples" / "emtc_scenario.toml"
    png = tmp_path / "run.png"
    code, _, err = run(capsys, "emtc", "simulate", scenario, "-o", tmp_path / "run.csv", "--plot", png)
    assert code == 0, err
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert plt.get_fignums() == []


SHORT_SCENARIO = '[scenario]\nduration = "0.5 s"\nspeed_difference = "0 m/s"\nthrottle_end = 0.3\n'


def test_simulate_fixed_step_follows_the_adaptive_run(tmp_path, capsys):
    """``emtc simulate --fixed-step "1 ms"``: the drum-bench run in 1 ms Rodas3 frames (the 2 ms controller samples
    on frame ends), said in the file's header, close to the adaptive run.

    Tolerances, measured over 0.5 s (armature leaves its rest, contact, lock-up): shaft speeds within 0.020 rad/s of
    the adaptive run (of 56 rad/s; bound 0.1 rad/s, as tests/numerics/test_fixed_step.py), magnet force within
    2.4 N of its 221 N peak (bound 3 %: the armature's contact comes at a frame end)."""
    sc = tmp_path / "s.toml"
    sc.write_text(SHORT_SCENARIO)
    adaptive, fixed = tmp_path / "adaptive.csv", tmp_path / "fixed.csv"
    code, text_a, _ = run(capsys, "emtc", "simulate", sc, "-o", adaptive)
    assert code == 0
    code, text_f, _ = run(capsys, "emtc", "simulate", sc, "-o", fixed, "--fixed-step", "1 ms")
    assert code == 0
    for word in ("armature_leave_rest", "armature_contact", "lockup"):
        assert word in text_a and word in text_f
    a, f = fixed_step_frames(fixed, adaptive, 251)
    for column in ("omega_f_rad_s", "omega_r_rad_s"):
        assert np.all(np.isfinite(f[column])) and np.max(np.abs(f[column] - a[column])) < 0.1, column
    assert np.max(np.abs(f.magnet_force_N - a.magnet_force_N)) < 0.03 * np.max(np.abs(a.magnet_force_N))


@pytest.mark.parametrize("value, message", [("-1ms", "must be a time > 0"), ("abc", "cannot parse quantity")])
def test_simulate_refuses_a_bad_fixed_step(tmp_path, capsys, value, message):
    sc = tmp_path / "s.toml"
    sc.write_text(SHORT_SCENARIO)
    out = tmp_path / "out.csv"
    code, _, err = run(capsys, "emtc", "simulate", sc, "-o", out, "--fixed-step", value)
    assert code == 2 and err.startswith("clutchlab: error: --fixed-step = ") and message in err
    assert err.count("\n") == 1 and "Traceback" not in err and not out.exists()


@pytest.mark.parametrize("tables, message", [
    ("[vehicle]\ngear_ratios = []\n", "VehicleParameters: gear_ratios = []: needs one ratio > 0 per gear"),
    ("[vehicle]\ngear_ratios = [3.0, -1.0]\n", "gear_ratios[1] = -1.0: must be > 0"),
    ("[vehicle]\ngear_ratios = [3.0, 2.0]\n[scenario]\ngear = 4\n",
     "[scenario] gear = 4: the vehicle has gears 1 to 2 ([vehicle] gear_ratios)")])
def test_gears_the_vehicle_lacks_are_one_line_errors(tmp_path, capsys, tables, message):
    """``[vehicle] gear_ratios = []`` passed ``params check`` and gave an IndexError in every run (#33)."""
    from cli_checks import one_line_error

    path = tmp_path / "veh.toml"
    path.write_text(tables)
    line = one_line_error(capsys, ["emtc", "simulate", str(path), "-o", str(tmp_path / "out.csv")])
    assert f"{path}: " in line and message in line
