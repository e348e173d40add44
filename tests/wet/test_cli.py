import json

import pytest

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
