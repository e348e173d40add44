"""``clutchlab wet simulate --plot``: a figure of the record; a refused figure leaves nothing behind."""

import pathlib

from clutchlab.cli import main

PROTOCOL = pathlib.Path(__file__).parents[2] / "examples" / "wet_engagement.toml"


def test_refused_plot_writes_no_record(tmp_path, capsys):
    (tmp_path / "fig.png").write_text("mine")
    out = tmp_path / "record.csv"
    assert main(["wet", "simulate", str(PROTOCOL), "-o", str(out), "--plot", str(tmp_path / "fig.png")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("clutchlab: error:") and "fig.png" in err
    assert not out.exists() and (tmp_path / "fig.png").read_text() == "mine"


def test_plot_shows_the_record_with_units(tmp_path, monkeypatch):
    import clutchlab.wet.plots as plots

    seen = {}
    original = plots.map_traces_figure

    def spy(record, title=""):
        fig = original(record, title=title)
        seen["labels"] = [ax.get_ylabel() for ax in fig.axes]
        seen["torque"] = fig.axes[1].lines[0].get_ydata()
        seen["record"] = record
        seen["fig"] = fig
        return fig

    monkeypatch.setattr(plots, "map_traces_figure", spy)
    assert main(["wet", "simulate", str(PROTOCOL), "-o", str(tmp_path / "r.csv"), "--plot", str(tmp_path / "r.png")]) == 0
    assert (tmp_path / "r.png").read_bytes()[:4] == b"\x89PNG"
    assert "torque [N·m]" in seen["labels"] and "slip [rpm]" in seen["labels"] and "T [°C]" in seen["labels"]
    assert (seen["torque"] == seen["record"]["torque_Nm"].to_numpy()).all()
    # the virtual bench is synthetic: the figure carries the stamp and the record its header lines
    from clutchlab.plotting import is_marked_synthetic

    assert is_marked_synthetic(seen["fig"])
    assert (tmp_path / "r.csv").read_text().startswith("# synthetic:")
