"""``clutchlab sweep``: runs a spec, resumes, refuses another spec, one-line errors."""

import pathlib

import pandas as pd
import pytest

from clutchlab.cli import main
from cli_checks import one_line_error

SPEC = """
[sweep]
model = "eclutch-static"
scenario = "static.toml"
outputs = ["engaged_torque", "lift_off_position"]
chunk_size = 2
[grid]
"clutch.mu" = [0.25, 0.3]
"clutch.lever_ratio" = [-4.0, -3.8]
"""


def write(tmp_path, text=SPEC):
    (tmp_path / "static.toml").write_text('[static]\nmodel = 1\ntravel = "9 mm"\npoints = 61\n')
    path = tmp_path / "spec.toml"
    path.write_text(text)
    return path


def test_sweep_command_runs_and_resumes(tmp_path, capsys):
    path = write(tmp_path)
    out = tmp_path / "res"
    assert main(["sweep", str(path), "-o", str(out), "--no-progress"]) == 0
    captured = capsys.readouterr()
    assert captured.out.strip() == str(out / "results.parquet")
    frame = pd.read_parquet(out / "results.parquet")
    assert list(frame["variant_id"]) == [0, 1, 2, 3]
    # M_cl = 2 F_n r_eff mu (Haramina et al., Sec. 3.2): at a fixed lever ratio the torque scales with mu
    t = frame.set_index(["clutch.mu", "clutch.lever_ratio"])["engaged_torque"]
    assert t[(0.3, -4.0)] / t[(0.25, -4.0)] == pytest.approx(0.3 / 0.25, rel=1e-12)
    assert main(["sweep", str(path), "-o", str(out), "--no-progress"]) == 0
    assert "0 chunks computed, 2 reused" in capsys.readouterr().err


def test_sweep_command_errors_are_one_line(tmp_path, capsys):
    path = write(tmp_path, SPEC.replace('"clutch.mu"', '"clutch.muu"'))
    assert main(["sweep", str(path), "-o", str(tmp_path / "res")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("clutchlab: error:") and "clutch.muu" in err and "spec.toml" in err and "\n" not in err
    good = write(tmp_path)
    assert main(["sweep", str(good), "-o", str(tmp_path / "res2"), "--no-progress", "--no-plot"]) == 0
    other = tmp_path / "other.toml"
    other.write_text(SPEC.replace("0.3]", "0.35]"))
    capsys.readouterr()
    assert main(["sweep", str(other), "-o", str(tmp_path / "res2")]) == 2
    assert "different sweep" in capsys.readouterr().err
    assert main(["sweep", str(other), "-o", str(tmp_path / "res2"), "--force", "--no-progress", "--no-plot"]) == 0


def test_refused_sweep_prints_only_its_error(tmp_path, capsys):
    """Every refusal comes before the "N variants ..." start line: the user sees one stderr line."""
    path = write(tmp_path)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("not a sweep\n")
    assert "not a sweep folder" in one_line_error(capsys, ["sweep", str(path), "-o", str(foreign), "--no-progress"])
    assert (foreign / "notes.txt").read_text() == "not a sweep\n" and not (foreign / "manifest.json").exists()
    assert "workers = 0" in one_line_error(capsys, ["sweep", str(path), "-o", str(tmp_path / "w"), "--workers", "0"])
    res = tmp_path / "res"
    assert main(["sweep", str(path), "-o", str(res), "--no-progress", "--no-plot"]) == 0
    assert "4 variants of" in capsys.readouterr().err  # the start line is still there for a sweep that runs
    other = tmp_path / "other.toml"
    other.write_text(SPEC.replace("0.3]", "0.35]"))
    assert "different sweep" in one_line_error(capsys, ["sweep", str(other), "-o", str(res), "--no-progress"])
    stray = res / "chunks" / "chunk-9-of-9.parquet"
    stray.write_bytes(b"not parquet")
    assert "not a chunk of this sweep" in one_line_error(capsys, ["sweep", str(path), "-o", str(res), "--no-progress"])


def test_list_parameters(tmp_path, capsys):
    assert main(["sweep", str(write(tmp_path)), "--list-parameters"]) == 0
    out = capsys.readouterr().out
    assert "clutch.lever_ratio" in out and "[m]" in out and "lift_off_position" in out


EXAMPLES = sorted((pathlib.Path(__file__).parents[2] / "examples").glob("sweep_*.toml"))
SPECS = [p for p in EXAMPLES if p.name != "sweep_wet_engagement.toml"]


@pytest.mark.parametrize("path", SPECS, ids=lambda p: p.name)
def test_example_specs_are_valid(path):
    from clutchlab.sweep import load_spec

    spec = load_spec(path)
    assert spec.n_variants >= 10 and spec.outputs


def test_wet_grid_example_conserves_energy(tmp_path, capsys):
    """On the inertia dynamometer every variant's friction work is J w0^2 / 2 (Shin et al. Eq. 8 source term)."""
    path = next(p for p in SPECS if p.name == "sweep_wet_grid.toml")
    assert main(["sweep", str(path), "-o", str(tmp_path / "res"), "--no-progress", "--no-plot"]) == 0
    frame = pd.read_parquet(tmp_path / "res" / "results.parquet")
    from clutchlab.wet import Bench

    w0 = 1500 * 3.141592653589793 / 30
    assert len(frame) == 36
    assert frame["energy"].to_numpy() == pytest.approx(0.5 * Bench().total_inertia * w0**2, rel=1e-4)
    assert frame["engagement_time"].std() > 0.01                      # but the engagement itself differs
