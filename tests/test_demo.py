"""``clutchlab demo``: the main job runs on the bundled data and writes a complete report."""

import re

from clutchlab.cli import DEMO_SECTIONS, _optional_module, main


def test_demo_writes_report_with_every_section(tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["demo", "-o", str(out)]) == 0
    html = (out / "index.html").read_text()
    sections = [m for m in DEMO_SECTIONS if _optional_module(m) is not None]
    assert "clutchlab.eclutch.demo" in sections
    assert html.count("<h2") == len(sections)
    assert html.count("Data provenance") == len(sections)
    assert len(re.findall(r"synthetic", html, flags=re.I)) >= len(sections)
    pngs = list((out / "figures").glob("*.png"))
    assert len(re.findall(r"data:image/png;base64,", html)) == len(pngs) >= 3
    assert "Model 4" in html and "RMSE" in html
    # a second run refuses to overwrite without --force
    assert main(["demo", "-o", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
