"""A sweep's summary.csv and summary.png on hand-made tables (no simulation): units as people write them, and
the figure says which parameters and outputs it leaves out."""

import pathlib
import re

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from clutchlab.sweep import summarize
from clutchlab.sweep.runner import _plot
from clutchlab.sweep.spec import SweepSpec

#: swept parameters with their SI units as a target describes them (pint spellings)
PARAMETERS = {"J1.J": "kg*m**2", "spring.c": "N*m/rad", "pump.flow": "m**3/s", "batch.mu_scale": "1",
              "clutch.r_outer": "m", "clutch.r_inner": "m", "clutch.fn_max": "N", "ice.idle_kp": "N*m*s/rad"}
OUTPUTS = {"J_total": "kg*m**2", "shaft.tau_max_Nm": "N*m", "w_final": "rad/s", "dissipated": "J",
           "lash.c_eff": "N*m/rad", "stick_time": "s", "jerk": "rad/s**3"}


def _spec(n_parameters: int, n_outputs: int, n: int = 12):
    names = list(PARAMETERS)[:n_parameters]
    rng = np.random.default_rng(0)
    design = pd.DataFrame({p: rng.uniform(1.0, 2.0, n) for p in names})
    spec = SweepSpec(path=pathlib.Path("<dict>"), model="hand-made", target=None, scenario=None,
                     outputs=tuple(list(OUTPUTS)[:n_outputs]), chunk_size=n, seed=0, kind="monte_carlo",
                     parameters=tuple(names), units={p: PARAMETERS[p] for p in names}, design=design, definition={})
    results = design.copy()
    for k, out in enumerate(spec.outputs):
        results[out] = (k + 1.0) * design[names[0]]
    return spec, results, {o: OUTPUTS[o] for o in spec.outputs}


@pytest.fixture
def drawn(monkeypatch):
    """The figures ``_plot`` renders (caught where it closes them)."""
    seen = []
    close = plt.close

    def keep(fig=None):
        seen.append(fig)
        return close(fig)

    monkeypatch.setattr(plt, "close", keep)
    return seen


def test_summary_writes_units_as_printed():
    """#33 R1b: summary.csv's unit column read ``kg*m**2`` and ``N*m/rad``."""
    spec, results, units = _spec(2, 7)
    table = summarize(results, spec.outputs, units)
    assert table.loc["J_total", "unit"] == "kg·m²" and table.loc["lash.c_eff", "unit"] == "N·m/rad"
    assert table.loc["shaft.tau_max_Nm", "unit"] == "N·m" and table.loc["jerk", "unit"] == "rad/s³"
    assert table.loc["w_final", "unit"] == "rad/s" and table.loc["dissipated", "unit"] == "J"
    assert not any(re.search(r"\*|\^", u) for u in table["unit"])
    assert summarize(results, ["w_final"]).loc["w_final", "unit"] == ""   # no unit given: none written


def test_sweep_figure_shows_four_parameters_with_units_as_printed(drawn):
    spec, results, units = _spec(4, 3)
    png = _plot(results, spec, units)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    (fig,) = drawn
    xlabels = [ax.get_xlabel() for ax in fig.axes if ax.get_xlabel()]
    ylabels = [ax.get_ylabel() for ax in fig.axes if ax.get_ylabel()]
    assert xlabels == ["J1.J [kg·m²]", "spring.c [N·m/rad]", "pump.flow [m³/s]", "batch.mu_scale [1]"]
    assert ylabels == ["J_total [kg·m²]", "shaft.tau_max_Nm [N·m]", "w_final [rad/s]"]
    title = fig._suptitle.get_text()
    assert "not shown" not in title and "first" not in title   # all four parameters are drawn


def test_sweep_figure_names_the_parameters_and_outputs_it_leaves_out(drawn):
    """#33 R1b: "the first 6 of 8 parameters shown" named neither of the two left out."""
    spec, results, units = _spec(8, 7)
    _plot(results, spec, units)
    (fig,) = drawn
    shown = [ax.get_xlabel().split(" [")[0] for ax in fig.axes if ax.get_xlabel()]
    assert shown == list(spec.parameters)[:6]
    title = " ".join(fig._suptitle.get_text().split())
    left_out = re.search(r"not shown: (.*) \(all are in results\.parquet\)", title)
    assert left_out, title
    assert "parameters clutch.fn_max, ice.idle_kp" in left_out.group(1)
    assert "outputs jerk" in left_out.group(1)
