"""Units for people in report figures and tables; synthetic provenance travels from source to every output."""

import importlib.util
import re
import struct
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.text import Text

import clutchlab.report.html as report_html
from clutchlab.cli import main
from clutchlab.eclutch.datasets import _data_root
from clutchlab.io import atomic_to_csv, read_measurement, write_measurement
from clutchlab.plotting import SYNTHETIC_GID, is_marked_synthetic, mark_synthetic, new_figure
from clutchlab.report import Figure, Section, write_report
from clutchlab.report.run import Dataset, metrics_table, find_datasets, report_run_dir, scatter_matrix

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("figure_checks", ROOT / "tests" / "figure_checks.py")
figure_checks = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(figure_checks)


def _capture_figures(monkeypatch):
    seen = []
    render = report_html._figure_png

    def capture(fig):
        fig.canvas.draw()
        seen.append(fig)
        return render(fig)

    monkeypatch.setattr(report_html, "_figure_png", capture)
    return seen


def _labels(fig):
    out = []
    for ax in fig.axes:
        out += [ax.get_xlabel(), ax.get_ylabel()]
    return [s for s in out if s]


def test_run_report_writes_units_for_people(tmp_path, monkeypatch):
    t = np.linspace(0.0, 1.0, 50)
    frame = pd.DataFrame({"time_s": t, "line_flow_m3_s": 1e-6 * np.sin(t), "temperature_C": 20 + t,
                          "fluid_temperature_C": 25 + t, "slip_speed_rad_s": 100 * t, "torque_Nm": 5 * t})
    write_measurement(frame, tmp_path / "run" / "r.csv", comment="synthetic: test data")
    seen = _capture_figures(monkeypatch)
    index = report_run_dir(tmp_path / "run", units="si")
    labels = [label for fig in seen for label in _labels(fig)]
    joined = " | ".join(labels)
    for human in ("[m³/s]", "[°C]", "[rad/s]", "[N·m]", "time [s]"):
        assert human in joined, (human, labels)
    assert not re.search(r"_(m3_s|rad_s|Nm|C)\b|\[(m3_s|rad_s|Nm|C)\]", joined), labels
    assert all(figure_checks.figure_problems(fig) == [] for fig in seen)
    assert all(is_marked_synthetic(fig) for fig in seen)
    # the metrics table names the unit as people write it
    m = pd.read_csv(next((index.parent / "tables").glob("*metrics.csv")), keep_default_na=False).set_index("channel")
    assert m.loc["line_flow_m3_s", "unit"] == "m³/s" and m.loc["temperature_C", "unit"] == "°C"
    assert m.loc["torque_Nm", "unit"] == "N·m" and m.loc["slip_speed_rad_s", "unit"] == "rad/s"


def test_run_report_keeps_the_underscores_of_channel_names(tmp_path, monkeypatch):
    """#33 R3: axis labels and legends spell a name as it is typed (``ice.idle_kp``, ``clutch.fn_max``),
    with and without a unit suffix; only the suffix becomes a unit."""
    t = np.linspace(0.0, 1.0, 50)
    frame = pd.DataFrame({"time_s": t, "ice.idle_kp": 0.5 + 0 * t, "clutch.fn_max_N": 2000 * t,
                          "clutch.fn_min_N": 1000 * t, "slip_speed_rad_s": 100 * t})
    write_measurement(frame, tmp_path / "run" / "r.csv", comment="synthetic: test data")
    seen = _capture_figures(monkeypatch)
    report_run_dir(tmp_path / "run", units="si")
    ylabels = [ax.get_ylabel() for fig in seen for ax in fig.axes]
    legends = [t.get_text() for fig in seen for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert "ice.idle_kp" in ylabels and "slip_speed [rad/s]" in ylabels, ylabels
    assert {"clutch.fn_max", "clutch.fn_min"} <= set(legends), legends
    assert not any(s in " | ".join(ylabels + legends) for s in ("idle kp", "fn max", "fn min", "slip speed"))


def test_run_report_shows_engineers_units_by_default(tmp_path, monkeypatch):
    """#33: figures and tables in rpm, bar, kN, mm, l/min, km/h, °C; the files stay SI."""
    t = np.linspace(0.0, 1.0, 50)
    frame = pd.DataFrame({"time_s": t, "slip_speed_rad_s": 100 * t, "pressure_Pa": 3e5 + 0 * t,
                          "force_N": 2000 * t, "travel_m": 8e-3 * t, "line_flow_m3_s": 1e-5 + 0 * t,
                          "vehicle_speed_m_s": 10 * t, "oil_K": 353.15 + 0 * t, "torque_Nm": 5 * t})
    write_measurement(frame, tmp_path / "run" / "r.csv", comment="synthetic: test data")
    seen = _capture_figures(monkeypatch)
    index = report_run_dir(tmp_path / "run")
    axes = {ax.get_ylabel(): ax for fig in seen for ax in fig.axes if ax.get_ylabel()}
    for label, value in [("slip_speed [rpm]", 100 * 30 / np.pi), ("pressure [bar]", 3.0), ("force [kN]", 2.0),
                         ("travel [mm]", 8.0), ("line_flow [l/min]", 0.6), ("vehicle_speed [km/h]", 36.0),
                         ("oil [°C]", 80.0), ("torque [N·m]", 5.0)]:
        assert label in axes, (label, list(axes))
        assert axes[label].lines[0].get_ydata()[-1] == pytest.approx(value, rel=1e-9)
    m = pd.read_csv(next((index.parent / "tables").glob("*metrics.csv")), keep_default_na=False).set_index("channel")
    assert m.loc["slip_speed_rad_s", "unit"] == "rpm" and m.loc["slip_speed_rad_s", "max"] == pytest.approx(
        100 * 30 / np.pi, rel=1e-9)
    assert m.loc["oil_K", "unit"] == "°C" and m.loc["oil_K", "final"] == pytest.approx(80.0)
    assert m.loc["pressure_Pa", "unit"] == "bar" and m.loc["pressure_Pa", "mean"] == pytest.approx(3.0)


def test_metrics_unit_column_for_unknown_names(tmp_path):
    atomic_to_csv(pd.DataFrame({"time_s": [0.0, 1.0], "count": [1.0, 2.0], "throttle_1": [0.1, 0.2]}),
                  tmp_path / "a.csv")
    (ds,), _ = find_datasets(tmp_path)
    m = metrics_table(ds).set_index("channel")
    assert m.loc["count", "unit"] == "" and m.loc["throttle_1", "unit"] == "dimensionless"


def _png_dpi(png: bytes) -> float:
    k = png.index(b"pHYs")
    ppm_x, _, unit = struct.unpack(">IIB", png[k + 4:k + 13])
    assert unit == 1  # pixels per metre
    return ppm_x * 0.0254


@pytest.mark.parametrize("synthetic", [True, False])
def test_report_figures_at_print_resolution_and_stamped_if_synthetic(tmp_path, synthetic):
    fig, ax = new_figure()
    ax.plot([0, 1], [0, 1], label="a")
    sec = Section("s", [Figure("line", fig, "a line")], provenance="synthetic: test" if synthetic else "measured")
    write_report([sec], tmp_path / "rep")
    png = (tmp_path / "rep" / "figures" / "line.png").read_bytes()
    assert _png_dpi(png) == pytest.approx(150, abs=0.5)
    assert is_marked_synthetic(fig) is synthetic


def test_mark_synthetic_once():
    fig, _ = new_figure()
    assert not is_marked_synthetic(fig)
    mark_synthetic(mark_synthetic(fig))
    assert is_marked_synthetic(fig)
    assert sum("SYNTHETIC" in t.get_text() for t in fig.findobj(Text)) == 1


def _report_scatter_matrix():
    rng = np.random.default_rng(0)
    names = ["clutch.r_outer", "protocol.force", "clutch.mu_scale"]
    ds = Dataset("results.parquet", "parquet", pd.DataFrame({n: rng.uniform(1.0, 2.0, 40) for n in names}))
    return scatter_matrix([("results", ds)], names, names, "engineers")[0]


def _panels(layout):
    fig, axes = new_figure(2, 2, width=7.0, height=3.0, squeeze=False, layout=layout)
    for ax in axes.ravel():
        ax.plot([0.0, 1e3], [0.0, 1.0])
        ax.set_ylabel("torque [N·m]")
    for ax in axes[-1]:
        ax.set_xlabel("protocol.force [kN]", fontsize=8)
    return fig


@pytest.mark.parametrize("make", [_report_scatter_matrix, lambda: _panels("constrained"), lambda: _panels(None)],
                         ids=["report scatter matrix (tight layout)", "constrained layout", "no layout engine"])
def test_synthetic_stamp_covers_no_label(make):
    """#33 R4: the stamp sat at figure coordinates (0.995, 0.005), over the x label of the bottom-right axes;
    drawn, it overlaps no axes' labels, tick labels, title or legend, nor any other text of the figure, and it
    is inside what a ``bbox_inches="tight"`` save writes."""
    fig = mark_synthetic(make())
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    stamp = next(a for a in fig.get_children() if a.get_gid() == SYNTHETIC_GID)
    box = stamp.get_window_extent(renderer)
    assert box.width > 0 and box.height > 0
    for ax in fig.axes:
        texts = [ax.xaxis.label, ax.yaxis.label, ax.title, *ax.get_xticklabels(), *ax.get_yticklabels()]
        hit = [t.get_text() for t in texts if t.get_visible() and t.get_text()
               and box.overlaps(t.get_window_extent(renderer))]
        assert not hit, hit
        assert not box.overlaps(ax.get_tightbbox(renderer))   # labels, tick labels, title, legend together
    for other in fig.get_children():
        if other is not stamp and other is not fig.patch and isinstance(other, Text) and other.get_text():
            assert not box.overlaps(other.get_window_extent(renderer)), other.get_text()
    saved = fig.get_tightbbox(renderer).transformed(fig.dpi_scale_trans)   # the tight save, in pixels
    assert saved.x0 <= box.x0 and box.x1 <= saved.x1 + 1e-6 and saved.y0 <= box.y0 + 1e-6 and box.y1 <= saved.y1
    if fig.get_layout_engine() is not None:   # a layout engine leaves it room inside the figure
        assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1 and fig.bbox.y0 <= box.y0


def test_eclutch_simulate_output_is_synthetic_and_units_right(tmp_path, capsys):
    out = tmp_path / "run" / "launch.csv"
    out.parent.mkdir()
    png = tmp_path / "launch.png"
    assert main(["eclutch", "simulate", str(ROOT / "examples" / "eclutch_launch.toml"), "-o", str(out),
                 "--plot", str(png)]) == 0
    rec = read_measurement(out)
    assert rec.source.synthetic
    units_line = next(line for line in out.read_text(encoding="utf-8").splitlines() if line.startswith("# units:"))
    assert "line_flow_m3_s=m**3/s" in units_line and "=s," not in units_line.replace("time_s=s,", "")
    assert rec.units["line_flow_m3_s"] == "m**3/s"
    # the report of that folder marks it synthetic
    html = report_run_dir(out.parent).read_text(encoding="utf-8")
    assert "SYNTHETIC DATA" in html and "SYNTHETIC: CSV launch.csv" in html


def test_characterize_carries_the_synthetic_mark_of_its_record(tmp_path, capsys):
    synthetic = _data_root() / "press" / "e_return_springs.csv"
    out = tmp_path / "curve.csv"
    assert main(["eclutch", "characterize", str(synthetic), "-o", str(out), "--plot", str(tmp_path / "c.png")]) == 0
    assert read_measurement(out, time=None).source.synthetic
    # the same record without its synthetic header: the curve is not marked
    measured = tmp_path / "measured.csv"
    measured.write_text("".join(line for line in synthetic.read_text(encoding="utf-8").splitlines(keepends=True)
                                if not line.startswith("# synthetic")), encoding="utf-8")
    out2 = tmp_path / "curve2.csv"
    assert main(["eclutch", "characterize", str(measured), "-o", str(out2)]) == 0
    assert not read_measurement(out2, time=None).source.synthetic
    np.testing.assert_array_equal(pd.read_csv(out, comment="#"), pd.read_csv(out2, comment="#"))


def test_figure_checks_flag_what_a_reviewer_would():
    """The checker used on the demo report finds each problem it is meant to find (and none on a good figure)."""
    x = np.linspace(0.0, 1.0, 200)
    fig, ax = new_figure()
    ax.plot(x, x, label="a")
    ax.plot(x, 1 - x)
    ax.set_xlabel("time_s")
    ax.set_ylabel("speed [rad_s]")
    ax.set_title("a long title cut ...")
    ax.legend(loc="center")
    text = "\n".join(figure_checks.figure_problems(fig))
    for what in ("'time_s' has no unit", "raw column suffix", "is cut", "not labelled", "legend covers data"):
        assert what in text, (what, text)
    good, ax = new_figure()
    ax.plot(x, x, label="a")
    ax.plot(x, 1 - x, label="b")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("slip speed [rad/s]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0))
    assert figure_checks.figure_problems(good) == []
