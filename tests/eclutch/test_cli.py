"""``clutchlab eclutch`` commands: outputs, plots, one-line errors, no silent overwrite."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from clutchlab.cli import main
from clutchlab.eclutch.datasets import load_press_record


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_static_writes_curves_and_refuses_to_overwrite(tmp_path, capsys):
    out = tmp_path / "m4.csv"
    code, text, _ = run(capsys, "eclutch", "static", "--model", "4", "-o", str(out), "--points", "50",
                        "--plot", str(tmp_path / "m4.png"))
    assert code == 0 and "Model 4" in text
    df = pd.read_csv(out, comment="#")
    assert list(df.columns[:4]) == ["bearing_position_m", "bearing_force_N", "normal_force_N", "torque_Nm"]
    assert len(df) == 50 and df.bearing_position_m.iloc[-1] == pytest.approx(9e-3)
    assert (tmp_path / "m4.png").read_bytes()[:4] == b"\x89PNG"
    before = out.read_bytes()
    code, _, err = run(capsys, "eclutch", "static", "--model", "2", "-o", str(out))
    assert code == 2 and err.startswith("clutchlab: error:") and "exists" in err and err.count("\n") == 1
    assert out.read_bytes() == before
    code, _, _ = run(capsys, "eclutch", "static", "--model", "2", "-o", str(out), "--force")
    assert code == 0 and out.read_bytes() != before


def test_characterize_command(tmp_path, capsys):
    raw = tmp_path / "cushion.csv"
    load_press_record("d").to_csv(raw, index=False)
    code, text, _ = run(capsys, "eclutch", "characterize", str(raw), "-o", str(tmp_path / "c.csv"))
    assert code == 0 and "3 cycles" in text
    curve = pd.read_csv(tmp_path / "c.csv", comment="#")
    assert {"deflection_m", "force_N", "hysteresis_half_width_N"} <= set(curve.columns)
    assert np.all(np.diff(curve.deflection_m) > 0)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["eclutch", "static", "--model", "9", "-o", "x.csv"], "unknown model number 9"),
        (["eclutch", "static", "--model", "1", "--travel", "3 kg", "-o", "x.csv"], "wrong unit"),
        (["eclutch", "static", "--model", "1", "--params", "missing.toml", "-o", "x.csv"], "missing.toml: no such"),
        (["eclutch", "characterize", "missing.csv", "-o", "c.csv"], "missing.csv: no such file"),
    ],
)
def test_errors_are_one_line(tmp_path, capsys, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, *argv)
    assert code == 2
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_bad_record_is_reported_with_column(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rec = load_press_record("e")
    rec.loc[7, "force_N"] = np.nan
    rec.to_csv("bad.csv", index=False)
    code, _, err = run(capsys, "eclutch", "characterize", "bad.csv", "-o", "c.csv")
    assert code == 2 and "force_N" in err and "row 7" in err


def test_validate_and_describe(tmp_path, capsys):
    from importlib import resources

    with resources.as_file(resources.files("clutchlab.eclutch") / "data" / "full_clutch.csv") as path:
        code, text, _ = run(capsys, "eclutch", "validate", str(path), "-o", str(tmp_path / "m.csv"))
    assert code == 0 and "rmse_force_N" in text
    assert len(pd.read_csv(tmp_path / "m.csv")) == 5
    code, text, _ = run(capsys, "eclutch", "describe", "--model", "3")
    assert code == 0 and "pivot support" in text


EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_simulate_fixed_step_follows_the_adaptive_run(tmp_path, capsys):
    """``eclutch simulate --fixed-step "1 ms"`` on the launch example (pedal press, hold, slow release; 1.6 s):
    1600 Rodas3 steps on the 1 ms grid, said in the file's header, and the adaptive run's result.

    Tolerances, measured: bearing position within 4.8 um of the adaptive run (8.6 mm travel; bound 20 um, as the
    fixed-step FMU test: the adaptive runs themselves differ by 2 um between tolerances through the seals'
    stick-slip, tests/numerics/test_fixed_step.py), bearing force within 0.42 % of its peak and clutch torque
    within 0.1 % of its peak (bound 1 % each)."""
    example = str(EXAMPLES / "eclutch_launch.toml")
    adaptive, fixed = tmp_path / "adaptive.csv", tmp_path / "fixed.csv"
    code, _, _ = run(capsys, "eclutch", "simulate", example, "-o", str(adaptive))
    assert code == 0
    code, text, _ = run(capsys, "eclutch", "simulate", example, "-o", str(fixed), "--fixed-step", "1 ms")
    assert code == 0 and "1600 steps (fixed steps of 0.001 s)" in text
    header = [line for line in fixed.read_text().splitlines() if line.startswith("#")]
    assert header[0].startswith("# synthetic:") and any(
        line.startswith("# solver: fixed-step (real-time) mode, step 0.001 s") for line in header)
    assert "fixed-step" not in adaptive.read_text().split("\ntime_s", 1)[0]
    a, f = pd.read_csv(adaptive, comment="#"), pd.read_csv(fixed, comment="#")
    assert len(a) == len(f) == 1601
    np.testing.assert_array_equal(f.time_s, a.time_s)
    assert np.all(np.isfinite(f.select_dtypes("number").to_numpy()))
    assert np.max(np.abs(f.bearing_position_m - a.bearing_position_m)) < 2e-5
    for column in ("bearing_force_N", "torque_Nm"):
        assert np.max(np.abs(f[column] - a[column])) < 0.01 * np.max(np.abs(a[column])), column


@pytest.mark.parametrize("value, message", [("-1ms", "must be a time > 0"), ("abc", "cannot parse quantity")])
def test_simulate_refuses_a_bad_fixed_step(tmp_path, capsys, value, message):
    out = tmp_path / "out.csv"
    code, _, err = run(capsys, "eclutch", "simulate", str(EXAMPLES / "eclutch_launch.toml"), "-o", str(out),
                       "--fixed-step", value)
    assert code == 2 and err.startswith("clutchlab: error: --fixed-step = ") and message in err
    assert err.count("\n") == 1 and "Traceback" not in err and not out.exists()


def test_help_everywhere(capsys):
    for argv in (["--help"], ["eclutch", "--help"], ["eclutch", "static", "--help"], ["demo", "--help"]):
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 0
    assert "usage" in capsys.readouterr().out
