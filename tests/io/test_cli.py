"""``clutchlab convert``."""

import subprocess
import sys

import numpy as np

from clutchlab.cli import main
from clutchlab.io import read_measurement

from .conftest import GEAR_T, SLOW_T


def test_convert_mf4_to_csv_with_map_and_rate(tmp_path, logger_file, capsys):
    (tmp_path / "map.toml").write_text('[channels.torque_Nm]\nsource = "TQ_Clutch"\n'
                                       '[channels.temperature_C]\nsource = "T_Oil"\n')
    out = tmp_path / "out.csv"
    assert main(["convert", str(logger_file), "-o", str(out), "--channel-map", str(tmp_path / "map.toml"),
                 "--rate", "50"]) == 0
    assert "TQ_Clutch" in capsys.readouterr().out
    text = out.read_text()
    assert text.startswith("# synthetic:") and "# units: time_s=s, torque_Nm=N*m, temperature_C=degC" in text
    m = read_measurement(out)
    np.testing.assert_allclose(np.diff(m.time), 0.02, rtol=1e-9)
    assert m.time[0] == SLOW_T[0] and m.time[-1] <= SLOW_T[-1]
    np.testing.assert_allclose(m["temperature_C"], 60 + 10 * m.time, rtol=1e-8)
    # refuses to overwrite without --force; with it, converts again (to MDF 4)
    assert main(["convert", str(logger_file), "-o", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["convert", str(out), "-o", str(tmp_path / "again.mf4")]) == 0
    back = read_measurement(tmp_path / "again.mf4")
    np.testing.assert_allclose(back["torque_Nm"], m["torque_Nm"], rtol=1e-12)
    assert main(["convert", str(logger_file), "-o", str(tmp_path / "all.parquet"), "--interpolation", "previous"]) == 0
    allch = read_measurement(tmp_path / "all.parquet")
    assert allch.time[-1] == GEAR_T[-1] and "Gear" in allch.channels


def test_convert_errors_are_one_line(tmp_path, logger_file, capsys):
    assert main(["convert", str(logger_file), "-o", str(tmp_path / "x.csv"), "--rate", "-1"]) == 2
    assert "rate" in capsys.readouterr().err
    (tmp_path / "m.toml").write_text('[channels.torque_Nm]\nsource = "TQ"\n')
    assert main(["convert", str(logger_file), "-o", str(tmp_path / "x.csv"), "--channel-map",
                 str(tmp_path / "m.toml")]) == 2
    err = capsys.readouterr().err
    assert "missing channel 'TQ'" in err and "logger.mf4" in err
    assert not (tmp_path / "x.csv").exists()


def test_truncated_file_gives_one_clean_line_on_stderr(tmp_path, logger_file):
    data = logger_file.read_bytes()
    bad = tmp_path / "cut.mf4"
    bad.write_bytes(data[: len(data) // 3])
    script = "import sys; from clutchlab.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.run([sys.executable, "-c", script, "convert", str(bad), "-o", str(tmp_path / "o.csv")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "cut.mf4: not a readable MDF file" in lines[0], proc.stderr
