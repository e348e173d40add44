"""``characterize`` on a logger's own channel names and units (channel map), and the static-curve figure."""

import numpy as np
import pytest

from clutchlab.cli import main
from clutchlab.eclutch import ClutchModel, VirtualClutch, characterize
from clutchlab.eclutch.pressrig import simulate_press_test

MAP = """
[channels.time_s]
source = "Zeit"
[channels.force_N]
source = "Kraft"
[channels.displacement_m]
source = "Weg"
"""


@pytest.fixture(scope="module")
def record():
    return simulate_press_test(VirtualClutch().diaphragm_at_tip(), 12e-3, cycles=3, samples_per_stroke=40, seed=7)


def _write_logger_csv(path, record, force_unit="kN", force_factor=1e-3, disp_unit="mm", disp_factor=1e3):
    lines = ["# a logger export", f"# units: Zeit=s, Kraft={force_unit}, Weg={disp_unit}", "Zeit,Kraft,Weg"]
    lines += [f"{t!r},{f * force_factor!r},{x * disp_factor!r}"
              for t, f, x in zip(record.time_s, record.force_N, record.displacement_m)]
    path.write_text("\n".join(lines) + "\n")


def test_channel_map_and_units_give_the_curve_of_the_si_record(tmp_path, record):
    _write_logger_csv(tmp_path / "raw.csv", record)
    (tmp_path / "map.toml").write_text(MAP)
    ref = characterize(record, n_grid=30)
    got = characterize(tmp_path / "raw.csv", channel_map=tmp_path / "map.toml", n_grid=30)
    np.testing.assert_allclose(got.deflection, ref.deflection, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(got.force, ref.force, rtol=1e-9, atol=1e-6)


def test_cli_characterize_with_channel_map(tmp_path, record, capsys):
    _write_logger_csv(tmp_path / "raw.csv", record, force_unit="daN", force_factor=0.1)
    (tmp_path / "map.toml").write_text(MAP)
    out = tmp_path / "curve.csv"
    assert main(["eclutch", "characterize", str(tmp_path / "raw.csv"), "--channel-map", str(tmp_path / "map.toml"),
                 "-o", str(out), "--points", "30", "--plot", str(tmp_path / "curve.png")]) == 0
    import pandas as pd

    got = pd.read_csv(out, comment="#")
    ref = characterize(record, n_grid=30)
    np.testing.assert_allclose(got["force_N"], ref.force, rtol=1e-6, atol=1e-3)   # daN -> N converted
    assert (tmp_path / "curve.png").read_bytes()[:4] == b"\x89PNG"


def test_cli_characterize_without_the_map_names_the_missing_channel(tmp_path, record, capsys):
    _write_logger_csv(tmp_path / "raw.csv", record)
    out = tmp_path / "curve.csv"
    assert main(["eclutch", "characterize", str(tmp_path / "raw.csv"), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("clutchlab: error:") and "raw.csv" in err and "force_N" in err and "--channel-map" in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


def test_refused_plot_leaves_nothing_behind(tmp_path, capsys):
    (tmp_path / "fig.png").write_text("mine")
    out = tmp_path / "curves.csv"
    assert main(["eclutch", "static", "--model", "0", "-o", str(out), "--plot", str(tmp_path / "fig.png")]) == 2
    assert not out.exists() and (tmp_path / "fig.png").read_text() == "mine"


def test_static_figure_has_three_labelled_panels_with_the_curves():
    from clutchlab.plotting import static_curves_panels

    df = ClutchModel.preset(1).static_curve(np.linspace(0, 8e-3, 20))
    fig = static_curves_panels({"Model 1": df})
    axes = fig.axes
    assert [ax.get_ylabel() for ax in axes] == ["bearing force [N]", "normal (clamp) force [kN]",
                                                "clutch torque [N·m]"]
    assert axes[-1].get_xlabel() == "release bearing position [mm]"
    for ax, col, factor in zip(axes, ("bearing_force_N", "normal_force_N", "torque_Nm"), (1.0, 1e-3, 1.0)):
        x, y = ax.lines[0].get_data()
        np.testing.assert_allclose(x, df["bearing_position_m"] * 1e3)
        np.testing.assert_allclose(y, df[col] * factor)
    import matplotlib.pyplot as plt

    plt.close(fig)
