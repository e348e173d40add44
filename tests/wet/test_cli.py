import json

import pytest

from cli_checks import fixed_step_frames
from clutchlab.cli import main
from clutchlab.wet import FrictionMap
from clutchlab.wet.data import DATA_DIR, MAP_RECORDS


def test_simulate_writes_record_and_refuses_overwrite(tmp_path, capsys):
    out = tmp_path / "eng.csv"
    assert main(["wet", "simulate", str(DATA_DIR / "engagement_protocol.toml"), "-o", str(out)]) == 0
    assert out.read_text().startswith("# synthetic:")
    assert "lock-up" in capsys.readouterr().out
    assert main(["wet", "simulate", str(DATA_DIR / "engagement_protocol.toml"), "-o", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["wet", "simulate", str(DATA_DIR / "engagement_protocol.toml"), "-o", str(out), "--force"]) == 0


def test_identify_writes_map_and_plot(tmp_path, capsys):
    recs = [str(DATA_DIR / n) for n in MAP_RECORDS]
    out = tmp_path / "map.json"
    png = tmp_path / "map.png"
    assert main(["wet", "identify", *recs, "-o", str(out), "--plot", str(png), "--sensor-lag", "0.2"]) == 0
    fmap = FrictionMap.from_json(out)
    assert fmap.law.mu_t == pytest.approx(8e-4, rel=0.05)  # the bench's true law
    data = json.loads(out.read_text())
    assert data["thermal"]["k1_W_K"] == pytest.approx(122.2, rel=0.03)
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert "covered cells" in capsys.readouterr().out


def test_cli_errors_are_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[protocol]\ntype = "warp"\n')
    assert main(["wet", "simulate", str(bad), "-o", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("clutchlab: error:") and "warp" in err and err.count("\n") == 1
    assert main(["wet", "identify", str(tmp_path / "none.csv"), "-o", str(tmp_path / "m.json")]) == 2
    assert "no such file" in capsys.readouterr().err
    assert main(["wet", "params"]) == 0
    assert "r_outer" in capsys.readouterr().out


def test_simulate_fixed_step_follows_the_adaptive_run(tmp_path, capsys):
    """``wet simulate --fixed-step "1 ms"``: the engagement protocol in 1 ms Rodas3 frames, said in the record's
    header; the same sensor noise (seed), so the records differ by the model's run only.

    Tolerances, measured (1.2 s, contact at 0.192 s, lock-up at 0.83 s): slip speed within 0.034 rad/s of the
    adaptive run (of 157 rad/s; bound 0.1 rad/s), thermistor temperature within 0.043 K (bound 0.1 K); the events
    are the same, each at the first frame end after the adaptive instant, or the next one for the contact: at 1 ms
    it falls on a frame end in exact arithmetic, where its switching function is +-1e-18 and rounding decides
    (tests/numerics/test_fixed_step.py)."""
    import numpy as np

    protocol = str(DATA_DIR / "engagement_protocol.toml")
    adaptive, fixed = tmp_path / "adaptive.csv", tmp_path / "fixed.csv"
    assert main(["wet", "simulate", protocol, "-o", str(adaptive)]) == 0
    capsys.readouterr()
    assert main(["wet", "simulate", protocol, "-o", str(fixed), "--fixed-step", "1 ms"]) == 0
    out = capsys.readouterr().out
    assert "in fixed steps of 0.001 s" in out and "lock-up at 0.83 s" in out
    assert "contact at 0.193 s" in out or "contact at 0.194 s" in out
    a, f = fixed_step_frames(fixed, adaptive, 1201)
    assert np.max(np.abs(f.slip_speed_rad_s - a.slip_speed_rad_s)) < 0.1
    assert np.max(np.abs(f.temperature_C - a.temperature_C)) < 0.1


@pytest.mark.parametrize("value, message", [("-1ms", "must be a time > 0"), ("abc", "cannot parse quantity")])
def test_simulate_refuses_a_bad_fixed_step(tmp_path, capsys, value, message):
    out = tmp_path / "out.csv"
    code = main(["wet", "simulate", str(DATA_DIR / "engagement_protocol.toml"), "-o", str(out),
                 "--fixed-step", value])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("clutchlab: error: --fixed-step = ") and message in err
    assert err.count("\n") == 1 and "Traceback" not in err and not out.exists()
