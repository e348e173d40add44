"""Comparing runs (#33): ``clutchlab report RUN_A RUN_B ...`` overlays runs or sweeps, names them in the legend,
plots and tabulates their differences, in engineers' units; rendered in Chromium like every report."""

import numpy as np
import pandas as pd
import pytest

from clutchlab.cli import main
from clutchlab.errors import DataError, ParameterError
from clutchlab.io import atomic_to_csv
from clutchlab.report.compare import compare_sections
from clutchlab.report.html import Figure, Table, Text

T_A = np.linspace(0.0, 1.0, 201)
T_B = np.linspace(0.0, 1.2, 97)        # another time base, and a longer run


def _speed(t):
    return 100.0 * (1.0 - np.exp(-3.0 * t))      # rad/s


def _write_runs(root):
    a, b = root / "baseline", root / "stiffer"
    for folder, t, gain, extra in ((a, T_A, 1.0, True), (b, T_B, 1.1, False)):
        folder.mkdir()
        frame = pd.DataFrame({"time_s": t, "speed_rad_s": gain * _speed(t), "pressure_Pa": 2e5 + 1e5 * t,
                              "force_N": 3000.0 * t + (50.0 if gain > 1 else 0.0)})
        if extra:
            frame["only_here_1"] = 1.0
        atomic_to_csv(frame, folder / "run.csv", header_comment="synthetic: written by the test-suite")
        sweep = pd.DataFrame({"force_N": np.linspace(1e3, 4e3, 12)})
        sweep["lockup_time_s"] = gain * 1e3 / sweep["force_N"]
        atomic_to_csv(sweep, folder / "sweep.csv", header_comment="synthetic: sweep")
    (a / "extra.csv").write_text("time_s,x_1\n0,1\n1,2\n")
    return a, b


@pytest.fixture(autouse=True)
def _close_figures():
    """compare_sections hands its figures to the caller: close them after each test."""
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return _write_runs(tmp_path_factory.mktemp("runs"))


def _items(sections, kind):
    return [i for s in sections for i in s.items if isinstance(i, kind)]


def test_overlays_differences_and_metrics_in_engineers_units(runs):
    a, b = runs
    sections = compare_sections([a, b], names=["base", "stiff"])
    titles = [s.title for s in sections]
    assert titles == ["Runs compared", "Compared: run.csv", "Compared: sweep.csv"]
    texts = " | ".join(t.text for t in _items(sections, Text))
    assert "extra.csv: only in base" in texts and "only_here_1" in texts
    figures = [f for f in _items(sections[1:2], Figure)]
    assert [f.name for f in figures] == ["c1_run.csv_overlay_1", "c1_run.csv_difference_1"]
    overlay, difference = (f.figure for f in figures)
    axes = overlay.axes
    assert [ax.get_ylabel() for ax in axes] == ["speed [rpm]", "pressure [bar]", "force [kN]"]
    assert [t.get_text() for t in axes[0].get_legend().get_texts()] == ["base", "stiff"]
    # the overlay draws each run on its own time base, in rpm
    x, y = axes[0].lines[1].get_data()
    np.testing.assert_allclose(y, 1.1 * _speed(T_B) * 30 / np.pi)
    # the difference: stiff - base on base's time base, where both have data (all of it: stiff runs longer)
    x, y = difference.axes[0].lines[0].get_data()
    np.testing.assert_allclose(x, T_A)
    want = (np.interp(T_A, T_B, 1.1 * _speed(T_B)) - _speed(T_A)) * 30 / np.pi
    np.testing.assert_allclose(y, want, rtol=1e-6, atol=1e-6)      # (the CSV keeps 9 digits)
    assert difference.axes[2].get_ylabel() == "Δ force [kN]"
    np.testing.assert_allclose(difference.axes[2].lines[0].get_data()[1], 0.05, rtol=1e-9)   # 50 N
    metrics = next(t.frame for t in _items(sections[1:2], Table))
    stiff_force = metrics[(metrics.channel == "force_N") & (metrics.run == "stiff")].iloc[0]
    assert stiff_force["unit"] == "kN"
    np.testing.assert_allclose(stiff_force["final"], (3000 * 1.2 + 50) / 1e3)
    np.testing.assert_allclose(stiff_force["max |Δ| vs base"], 0.05, rtol=1e-9)
    speed = metrics[(metrics.channel == "speed_rad_s") & (metrics.run == "stiff")].iloc[0]
    np.testing.assert_allclose(speed["max |Δ| vs base"], np.max(np.abs(want)), rtol=1e-6)
    pressure = metrics[(metrics.channel == "pressure_Pa") & (metrics.run == "base")].iloc[0]
    assert pressure["unit"] == "bar" and pressure["min"] == pytest.approx(2.0) and pressure["max"] == pytest.approx(3.0)
    # the same in SI
    si = compare_sections([a, b], names=["base", "stiff"], units="si")
    axes = _items(si[1:2], Figure)[0].figure.axes
    assert [ax.get_ylabel() for ax in axes] == ["speed [rad/s]", "pressure [Pa]", "force [N]"]


def test_sweeps_are_overlaid_one_colour_per_run(runs):
    a, b = runs
    sections = compare_sections([a, b])
    fig = _items(sections[2:3], Figure)[0]
    ax = fig.figure.axes[0]
    assert ax.get_xlabel() == "force [kN]" and ax.get_ylabel() == "lockup_time [s]"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["baseline", "stiffer"]
    np.testing.assert_allclose(ax.collections[1].get_offsets()[:, 1], 1.1e3 / np.linspace(1e3, 4e3, 12))
    assert "one colour per run (baseline, stiffer)" in fig.caption


def test_single_files_are_runs_too_and_bad_requests_are_refused(runs, tmp_path):
    a, b = runs
    sections = compare_sections([a / "run.csv", b / "run.csv"], names=["A", "B"])
    assert [s.title for s in sections] == ["Runs compared", "Compared: run.csv"]
    with pytest.raises(ParameterError, match="at least two runs"):
        compare_sections([a])
    with pytest.raises(ParameterError, match="1 names for 2 runs"):
        compare_sections([a, b], names=["x"])
    with pytest.raises(ParameterError, match="distinct"):
        compare_sections([a, b], names=["x", "x"])
    with pytest.raises(ParameterError, match="units = 'imperial'"):
        compare_sections([a, b], units="imperial")
    with pytest.raises(DataError, match="no such run folder or table file"):
        compare_sections([a, tmp_path / "nope"])
    lonely = tmp_path / "lonely"
    lonely.mkdir()
    (lonely / "other.csv").write_text("time_s,y_1\n0,1\n1,2\n")
    with pytest.raises(DataError, match="the runs share no table to compare"):
        compare_sections([a, lonely])


def test_the_comparison_report_renders_in_chromium(browser, check_page, runs, tmp_path, capsys):
    a, b = runs
    out = tmp_path / "cmp"
    assert main(["report", str(a), str(b), "--name", "base", "--name", "stiff", "-o", str(out)]) == 0
    index = out / "index.html"
    assert capsys.readouterr().out.strip() == str(index)
    n = len(list((out / "figures").glob("*.png")))
    assert n == 3      # run.csv: overlay and difference; sweep.csv: scatter
    state = browser.render(index.as_uri())
    assert check_page(state, n) == []
    assert "base vs stiff" in state["title"]
    html = index.read_text(encoding="utf-8")
    assert "SYNTHETIC" in html and "Compared: run.csv" in html
    # written by clutchlab: replaced with --force, refused without; --name only for comparisons
    assert main(["report", str(a), str(b), "-o", str(out)]) == 2
    assert main(["report", str(a), str(b), "-o", str(out), "--force", "--units", "si"]) == 0
    assert main(["report", str(a), "--name", "x", "-o", str(tmp_path / "one")]) == 2
    assert "--name names the runs of a comparison" in capsys.readouterr().err
