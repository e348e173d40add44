"""``clutchlab export-fmu``: writes a loadable FMU, refuses to overwrite without --force."""

import zipfile

import pytest

from clutchlab.cli import main


def test_export_fmu_command(tmp_path, capsys):
    import fmpy

    out = tmp_path / "emtc.fmu"
    assert main(["export-fmu", "emtc", "-o", str(out)]) == 0
    assert capsys.readouterr().out.strip() == str(out)
    md = fmpy.read_model_description(str(out), validate=True)
    assert md.coSimulation.modelIdentifier == "ClutchlabEmtc"
    stamp = out.stat().st_mtime_ns
    assert main(["export-fmu", "emtc", "-o", str(out)]) == 2
    assert "exists" in capsys.readouterr().err and out.stat().st_mtime_ns == stamp
    assert main(["export-fmu", "emtc", "-o", str(out), "--force"]) == 0
    with zipfile.ZipFile(out) as z:
        assert z.testzip() is None
    assert [p.name for p in tmp_path.iterdir()] == ["emtc.fmu"]  # no temporary files left behind


def test_export_fmu_default_name_and_bad_model(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["export-fmu", "wet"]) == 0
    assert (tmp_path / "wet.fmu").is_file()
    with pytest.raises(SystemExit):
        main(["export-fmu", "dry"])
    assert main(["export-fmu", "wet", "-o", "wet.txt"]) == 2
    assert ".fmu" in capsys.readouterr().err
