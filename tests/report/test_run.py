"""``clutchlab report RUN_DIR``: tables found, figures, metrics, parameters, provenance, self-contained page."""

import json
import re

import numpy as np
import pandas as pd
import pytest

from clutchlab.cli import main
from clutchlab.errors import DataError
from clutchlab.io import atomic_to_csv
from clutchlab.report.run import _groups, find_datasets, metrics_table, report_run_dir


def _time_frame(n=201):
    t = np.linspace(0.0, 2.0, n)
    return pd.DataFrame({"time_s": t, "torque_Nm": 50 * np.sin(t), "force_N": 1000 * t, "temperature_C": 80 + t})


def _sections(html):
    """{section title: html of the section} of a report page."""
    parts = re.split(r"<h2 id='s\d+'>", html)[1:]
    return {p.split("<", 1)[0]: p for p in parts}


def test_csv_with_synthetic_header(tmp_path):
    run = tmp_path / "run"
    frame = _time_frame()
    atomic_to_csv(frame, run / "sim.csv", header_comment="synthetic: virtual rig, seed 1\nprotocol: test")
    atomic_to_csv(frame.assign(torque_Nm=frame["torque_Nm"] + 1), run / "measured.csv", header_comment="rig 3, 2024-05-01")
    messages = []
    index = report_run_dir(run, progress=messages.append)
    assert index == run / "report" / "index.html"
    html = index.read_text(encoding="utf-8")
    sec = _sections(html)
    assert "SYNTHETIC DATA" in sec["Data: sim.csv"] and "synthetic: virtual rig, seed 1" in sec["Data: sim.csv"]
    assert "SYNTHETIC DATA" not in sec["Data: measured.csv"] and "rig 3, 2024-05-01" in sec["Data: measured.csv"]
    assert "SYNTHETIC DATA" in sec["Run summary"]  # the folder holds synthetic data
    from clutchlab import __version__

    assert f"clutchlab {__version__}" in html
    # one figure per CSV (three units -> three axes), embedded, and its PNG beside the page
    assert len(re.findall(r"<img [^>]*src='data:image/png;base64,", html)) == 2
    assert len(list((run / "report" / "figures").glob("*.png"))) == 2
    assert any("reading sim.csv" in m for m in messages) and any("rendering figure 2/2" in m for m in messages)


def test_page_is_self_contained(tmp_path):
    run = tmp_path / "run"
    atomic_to_csv(_time_frame(), run / "a.csv")
    html = report_run_dir(run).read_text(encoding="utf-8")
    urls = re.findall(r"""(?:src|href)\s*=\s*['"]([^'"]*)['"]""", html)
    assert urls and all(u.startswith(("data:image/png;base64,", "#")) for u in urls), urls
    assert "http://" not in html and "https://" not in html and "<link" not in html


def test_metrics_match_numpy(tmp_path):
    run = tmp_path / "run"
    frame = _time_frame()
    frame.loc[5, "force_N"] = np.nan
    atomic_to_csv(frame, run / "a.csv")
    (ds,), failed = find_datasets(run)
    assert not failed and ds.time_column == "time_s"
    m = metrics_table(ds).set_index("channel")
    frame = ds.frame  # as read back (the CSV holds 9 significant digits)
    f = frame["force_N"].to_numpy()
    assert m.loc["force_N", "non-finite"] == 1 and m.loc["force_N", "finite"] == len(f) - 1
    assert m.loc["force_N", "mean"] == pytest.approx(np.nanmean(f), rel=1e-12)
    assert m.loc["torque_Nm", "min"] == pytest.approx(frame["torque_Nm"].min(), rel=1e-12)
    assert m.loc["torque_Nm", "max"] == pytest.approx(frame["torque_Nm"].max(), rel=1e-12)
    assert m.loc["temperature_C", "final"] == pytest.approx(frame["temperature_C"].iloc[-1], rel=1e-12)
    # the metrics table is in the page and as CSV beside it
    index = report_run_dir(run)
    tables = list((index.parent / "tables").glob("*metrics.csv"))
    assert len(tables) == 1 and pd.read_csv(tables[0])["channel"].tolist() == list(frame.columns)


def test_sweep_folder_parquet_chunks_manifest_and_spec(tmp_path):
    run = tmp_path / "results"
    (run / "chunks").mkdir(parents=True)
    rng = np.random.default_rng(1)
    parts = []
    for k in range(3):
        part = pd.DataFrame({"variant": np.arange(10 * k, 10 * k + 10), "force_N": rng.uniform(1e3, 4e3, 10),
                             "sigma_m": rng.uniform(1e-4, 1e-3, 10)})
        part["lockup_time_s"] = 1e3 / part["force_N"]
        part.to_parquet(run / "chunks" / f"chunk-{k:05d}.parquet")
        parts.append(part)
    (run / "manifest.json").write_text(json.dumps({"target": "wet", "n_variants": 30, "outputs": ["lockup_time_s"],
                                                   "data": "synthetic: clutchlab virtual bench"}))
    (run / "spec.toml").write_text('[sweep]\nmodel = "wet"\nchunk_size = 10\n[grid]\nforce = ["1 kN", "4 kN"]\n')
    (ds,), failed = find_datasets(run)
    assert not failed and len(ds.files) == 3 and len(ds.frame) == 30
    assert ds.frame["variant"].tolist() == list(range(30))  # chunks in file-name order
    html = report_run_dir(run).read_text(encoding="utf-8")
    sec = _sections(html)
    data = next(v for k, v in sec.items() if k.startswith("Data: chunks/"))
    # outputs from the manifest against the inputs (the index column "variant" is not an input)
    assert "outputs lockup_time_s against force_N, sigma_m" in data
    assert "SYNTHETIC DATA" in data  # the manifest says synthetic
    assert "n_variants" in sec["Run summary"] and "synthetic: clutchlab virtual bench" in sec["Run summary"]
    params = sec["Parameters used"]
    assert "spec.toml" in params and "chunk_size" in params and "1 kN" in params


def test_mdf4_file(tmp_path):
    from asammdf import MDF, Signal

    run = tmp_path / "run"
    run.mkdir()
    t = np.linspace(0.0, 1.0, 101)
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.sin(t), t, name="torque_Nm", unit="Nm"), Signal(2 * t, t, name="force_N", unit="N")])
    mdf.header.comment = "synthetic: MDF written by the test"
    mdf.save(run / "rec.mf4", overwrite=True)
    (ds,), failed = find_datasets(run)
    assert ds.format == "MDF4" and ds.time_column == "time_s" and ds.synthetic
    assert ds.frame["force_N"].to_numpy() == pytest.approx(2 * t)


def test_parameter_files_shown_and_validated(tmp_path):
    run = tmp_path / "run"
    atomic_to_csv(_time_frame(), run / "a.csv")
    (run / "wet.toml").write_text('model = "wet"\n[wet]\nr_outer = "83.15 mm"\n[bench]\nsample_rate = "200 Hz"\n')
    (run / "other.toml").write_text('[protocol]\ntype = "engagement"\nforce = "3 kN"\n')
    sec = _sections(report_run_dir(run).read_text(encoding="utf-8"))["Parameters used"]
    assert "wet.toml: valid wet parameters" in sec and "83.15 mm" in sec and "200 Hz" in sec
    assert "other.toml: not a clutchlab model parameter file" in sec and "engagement" in sec


def test_damaged_file_is_named_and_the_rest_reported(tmp_path):
    run = tmp_path / "run"
    atomic_to_csv(_time_frame(), run / "good.csv")
    (run / "bad.parquet").write_bytes(b"PAR1 this is not parquet")
    datasets, failed = find_datasets(run)
    assert [d.name for d in datasets] == ["good.csv"]
    assert failed and failed[0][0].name == "bad.parquet" and "cannot read as Parquet" in failed[0][1]
    html = report_run_dir(run).read_text(encoding="utf-8")
    assert "Not read:" in html and "bad.parquet" in html


def test_errors_and_overwrite(tmp_path, capsys):
    with pytest.raises(DataError, match="no such run directory"):
        report_run_dir(tmp_path / "missing")
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("nothing")
    with pytest.raises(DataError, match="no result tables"):
        report_run_dir(tmp_path / "empty")
    run = tmp_path / "run"
    atomic_to_csv(_time_frame(), run / "a.csv")
    assert main(["report", str(run)]) == 0
    captured = capsys.readouterr()
    assert captured.out.strip() == str(run / "report" / "index.html")
    assert "reading a.csv" in captured.err and "rendering figure" in captured.err
    assert main(["report", str(run)]) == 2
    assert "exists" in capsys.readouterr().err
    # --force rewrites; the report folder inside RUN_DIR is not read as data
    assert main(["report", str(run), "--force"]) == 0
    html = (run / "report" / "index.html").read_text(encoding="utf-8")
    assert html.count("<h2") == 2  # summary + a.csv, no section for report/tables/*.csv
    out = tmp_path / "elsewhere"
    assert main(["report", str(run), "-o", str(out), "--title", "Run 7"]) == 0
    assert "<title>Run 7</title>" in (out / "index.html").read_text(encoding="utf-8")
    assert main(["report", str(tmp_path / "empty")]) == 2
    assert "no result tables" in capsys.readouterr().err


def test_channels_grouped_by_unit_suffix():
    groups = _groups(["torque_Nm", "speed_rad_s", "drag_Nm", "x_m", "count", "y_m", "temperature_C"])
    assert groups == [("N*m", ["torque_Nm", "drag_Nm"]), ("rad/s", ["speed_rad_s"]), ("m", ["x_m", "y_m"]),
                      ("", ["count"]), ("degC", ["temperature_C"])]
    # names without a unit: grouped by stem (EMTC run: omega_f/omega_r, i1/i2, t1..t3)
    groups = _groups(["omega_f", "omega_r", "theta", "i1", "i2", "t1", "t2", "t3", "t_coupling", "x", "xdot"])
    assert groups == [("", ["omega_f", "omega_r"]), ("", ["theta"]), ("", ["i1", "i2"]), ("", ["t1", "t2", "t3"]),
                      ("", ["t_coupling"]), ("", ["x"]), ("", ["xdot"])]
    many = _groups([f"f{i}_N" for i in range(8)])
    assert [len(c) for _, c in many] == [6, 2]


def test_table_without_time_or_outputs(tmp_path):
    run = tmp_path / "run"
    atomic_to_csv(pd.DataFrame({"deflection_m": np.linspace(0, 1e-3, 20), "force_N": np.linspace(0, 500, 20)}),
                  run / "curve.csv")
    atomic_to_csv(pd.DataFrame({"name": ["a", "b"], "value": [1.0, 2.0]}), run / "labels.csv")
    atomic_to_csv(pd.DataFrame({"value": [1.0, 2.0, 4.0]}), run / "single.csv")
    html = report_run_dir(run).read_text(encoding="utf-8")
    sec = _sections(html)
    assert "outputs force_N against deflection_m" in sec["Data: curve.csv"]
    assert "<img" not in sec["Data: labels.csv"] and "shown as it is" in sec["Data: labels.csv"]
    # one numeric column: nothing to scatter, the metrics still
    assert "<img" not in sec["Data: single.csv"] and "Metrics per channel" in sec["Data: single.csv"]
    assert "<td>2.333</td>" in sec["Data: single.csv"]  # mean of 1, 2, 4


def test_sweep_results_file_and_its_chunks_shown_once(tmp_path):
    run = tmp_path / "sweep"
    (run / "chunks").mkdir(parents=True)
    rows = pd.DataFrame({"variant_id": np.arange(12), "clutch.r_outer": np.repeat([0.08, 0.083, 0.086], 4),
                         "protocol.force": np.tile([2.5e3, 3e3, 3.5e3, 4e3], 3)})
    rows["engagement_time"] = 1.0 / rows["protocol.force"] * 1e3
    for k in range(2):
        rows.iloc[6 * k:6 * k + 6].to_parquet(run / "chunks" / f"chunk-{k:05d}.parquet")
    rows.to_parquet(run / "results.parquet")
    (run / "manifest.json").write_text(json.dumps({
        "parameters": {"clutch.r_outer": "m", "protocol.force": "N"}, "outputs": ["engagement_time"],
        "provenance": "synthetic: outputs of clutchlab model simulations"}))
    atomic_to_csv(pd.DataFrame({"output": ["engagement_time"], "unit": ["s"], "mean": [1.0]}), run / "summary.csv",
                  header_comment="synthetic: sweep summary")
    datasets, _ = find_datasets(run)
    assert [d.name for d in datasets] == ["results.parquet", "summary.csv"]
    assert "same rows as chunks/ (2 chunks) (not shown again)" in datasets[0].provenance
    html = report_run_dir(run).read_text(encoding="utf-8")
    sec = _sections(html)
    data = sec["Data: results.parquet"]
    assert "SYNTHETIC DATA" in data and "synthetic according to the run manifest" in data
    # inputs from the manifest's parameters, outputs from its outputs
    assert "outputs engagement_time against clutch.r_outer, protocol.force [synthetic data]" in data
    # the small labelled summary is shown as a table, not plotted
    assert "<img" not in sec["Data: summary.csv"] and "shown as it is" in sec["Data: summary.csv"]
    files = re.search(r"Tables found.*?</table>", html, re.S).group(0)
    assert files.count("<td>yes</td>") == 2


def test_a_table_holding_inf_or_1e308_is_reported_not_a_traceback(tmp_path):
    """A CSV holding +-1e308 made matplotlib's tick search overflow, a traceback for the whole report (#33): values
    beyond ``PLOT_LIMIT`` are left out of the figures (the caption says how many), the metrics keep them, the
    mean without overflow."""
    import math

    from clutchlab.report.run import PLOT_LIMIT

    run = tmp_path / "run"
    run.mkdir()
    (run / "a.csv").write_text("time_s,force_N\n0,1\n1,inf\n2,3\n")
    (run / "b.csv").write_text("time_s,force_N\n0,1\n1,1e308\n2,-1e308\n")
    (run / "c.csv").write_text("time_s,force_N\n0,1e308\n1,1e308\n2,1e308\n")
    html = report_run_dir(run).read_text(encoding="utf-8")
    assert html.count(f"values beyond ±{PLOT_LIMIT:.0e} not drawn") >= 2
    tables = {ds.name: metrics_table(ds).set_index("channel") for ds in find_datasets(run)[0]}
    assert tables["c.csv"].loc["force_N", "mean"] == 1e308 and math.isfinite(tables["b.csv"].loc["force_N", "mean"])
    assert tables["a.csv"].loc["force_N", "non-finite"] == 1


def test_links_out_of_the_results_folder_are_named_not_read(tmp_path):
    """The report followed links out of the results folder (#33): a table or parameter file behind such a link is
    listed as not read; a link inside the folder is read."""
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.csv").write_text("time_s,x_1\n0,1\n1,2\n")
    (outside / "secret.toml").write_text("key = 1\n")
    run = tmp_path / "run"
    run.mkdir()
    (run / "mine.csv").write_text("time_s,y_1\n0,1\n1,2\n")
    (run / "link.csv").symlink_to(outside / "secret.csv")
    (run / "link.toml").symlink_to(outside / "secret.toml")
    (run / "again.csv").symlink_to(run / "mine.csv")
    datasets, failed = find_datasets(run)
    assert [d.name for d in datasets] == ["again.csv"]   # (mine.csv has the same rows: shown once)
    assert [(p.name, why) for p, why in failed] == [("link.csv", "a link to a file outside the results folder: "
                                                                  "not read")]
    html = report_run_dir(run).read_text(encoding="utf-8")
    assert "link.toml: a link to a file outside the results folder" in html and "secret" not in html


def test_columns_a_scatter_matrix_leaves_out_are_named_in_its_caption(tmp_path):
    """A fourth sweep parameter was left out of the scatter matrix without a word (#33)."""
    run = tmp_path / "run"
    run.mkdir()
    names = [f"p{k}_1" for k in range(12)]
    rows = "\n".join(",".join(str((k + 1) * (r + 1) % 7 + r) for k in range(12)) for r in range(5))
    (run / "variants.csv").write_text(",".join(names) + "\n" + rows + "\n")
    html = report_run_dir(run).read_text(encoding="utf-8")
    assert "not drawn (the matrix takes 3 inputs and 8 outputs): p11_1" in html


def test_a_table_without_time_has_no_final_value():
    """"final" metrics were shown for Monte Carlo rows, which have no last one (#33); a time series keeps it."""
    from clutchlab.report.run import Dataset

    samples = Dataset("mc", "CSV", pd.DataFrame({"variant_id": [0, 1, 2], "energy_J": [3.0, 1.0, 2.0]}), [], [])
    run = Dataset("run", "CSV", pd.DataFrame({"time_s": [0.0, 1.0], "energy_J": [1.0, 2.0]}), [], [])
    assert "final" not in metrics_table(samples).columns
    assert metrics_table(run).set_index("channel").loc["energy_J", "final"] == 2.0


def test_a_logger_file_of_many_channels_draws_a_bounded_number_of_figures(tmp_path):
    """#33: a CSV of 3,000 channels made 125 figures (74 MB, 1.45 GB): at most MAX_FIGURES_PER_TABLE figures
    per table are drawn, the rest are named, and every channel keeps its metrics row."""
    from clutchlab.report.html import Figure, Text
    from clutchlab.report.run import MAX_AXES_PER_FIGURE, MAX_FIGURES_PER_TABLE, run_sections

    run = tmp_path / "run"
    run.mkdir()
    t = np.linspace(0.0, 1.0, 20)
    frame = pd.DataFrame({"time_s": t, **{f"sig{k}_{u}": t * k for k in range(300) for u in ("N",)}})
    frame.to_csv(run / "logger.csv", index=False)
    (section,) = [s for s in run_sections(run) if s.title == "Data: logger.csv"]
    figures = [i for i in section.items if isinstance(i, Figure)]
    assert len(figures) == MAX_FIGURES_PER_TABLE
    drawn = sum(len(ax.lines) for f in figures for ax in f.figure.axes)
    assert drawn == MAX_FIGURES_PER_TABLE * MAX_AXES_PER_FIGURE * 6       # six lines per axes
    (note,) = [i.text for i in section.items if isinstance(i, Text)]
    assert f"{300 - drawn} of 300 channels not drawn" in note and f"sig{drawn}_N, " in note
    metrics = [i.frame for i in section.items if hasattr(i, "frame") and "channel" in getattr(i, "frame").columns]
    assert len(metrics[0]) == 301          # every channel and the time
    import matplotlib.pyplot as plt

    plt.close("all")
