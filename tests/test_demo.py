"""``clutchlab demo``: the main job runs on the bundled data and writes a complete report."""

import importlib.util
import re
from pathlib import Path

import clutchlab.report.html as report_html
from clutchlab.cli import DEMO_SECTIONS, _optional_module, main
from clutchlab.plotting import is_marked_synthetic

_spec = importlib.util.spec_from_file_location("figure_checks", Path(__file__).with_name("figure_checks.py"))
figure_checks = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(figure_checks)
figure_problems = figure_checks.figure_problems


def test_demo_writes_report_with_every_section(tmp_path, capsys, monkeypatch):
    """The whole demo runs once here; every figure is checked as a reviewer would as it is rendered."""
    problems, rendered = [], []
    render = report_html._figure_png

    def checked_render(fig):
        name = fig.axes[0].get_title() or (fig._suptitle.get_text() if fig._suptitle else f"figure {len(rendered)}")
        rendered.append(name)
        problems.extend(figure_problems(fig, name))
        assert is_marked_synthetic(fig), f"{name}: not stamped synthetic"
        return render(fig)

    monkeypatch.setattr(report_html, "_figure_png", checked_render)
    # the kernels of every later section compile in a background process of their own (clutchlab.warmup)
    import os

    from clutchlab import warmup

    started, start = [], warmup.start
    monkeypatch.setattr(warmup, "start", lambda groups: started.append(list(groups)) or start(groups))
    out = tmp_path / "report"
    assert main(["demo", "-o", str(out)]) == 0
    assert len(rendered) >= 10
    assert problems == []
    html = (out / "index.html").read_text()
    sections = [m for m in DEMO_SECTIONS if _optional_module(m) is not None]
    assert "clutchlab.demo.eclutch" in sections
    assert html.count("<h2") == len(sections)
    assert html.count("Data provenance") == len(sections)
    assert len(re.findall(r"synthetic", html, flags=re.I)) >= len(sections)
    pngs = list((out / "figures").glob("*.png"))
    assert len(re.findall(r"data:image/png;base64,", html)) == len(pngs) >= 3
    assert "Model 4" in html and "RMSE" in html
    if (os.cpu_count() or 1) >= 2:
        later = [m.rsplit(".", 1)[1] for m in sections[1:] if m.rsplit(".", 1)[1] in warmup.GROUPS]
        assert sorted(started) == sorted([g] for g in later) and "driveline" in later
    # the driveline section: CoupledClutches from the bundled file, its figures and its tables
    assert "clutchlab.demo.driveline" in sections and "Drivelines" in html and "CoupledClutches" in html
    for what in ("speeds", "torques", "modes", "energy"):
        assert (out / "figures" / f"driveline_coupled_clutches_{what}.png").is_file()
    for what in ("events", "metrics"):
        assert (out / "tables" / f"driveline_coupled_clutches_{what}.csv").is_file()
    # run times are measured with compiled kernels; the compilation is reported on its own
    timing = re.search(r"With the kernels compiled, the 1 s step response took (\d+) ms.*?The first call, which runs "
                       r"the same step, took (\d+) ms, of which ([\d.]+) s went into compiling", html)
    assert timing, "the step-response timing sentence is missing"
    run_ms, first_ms, compile_s = int(timing.group(1)), int(timing.group(2)), float(timing.group(3))
    # the compile time is measured (numba's compile events), a part of the first call; each figure is rounded
    assert run_ms > 0 and compile_s * 1e3 <= first_ms + 50
    # a second run refuses to overwrite without --force
    assert main(["demo", "-o", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
