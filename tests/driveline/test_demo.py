"""The driveline section of ``clutchlab demo``: the bundled examples, their events, modes and energy balance."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from clutchlab.driveline import data
from clutchlab.demo.driveline import EXAMPLES, demo_section, mode_intervals
from clutchlab.driveline.description import load_driveline
from clutchlab.report import Figure, Section, Table

ROOT = Path(__file__).resolve().parents[2]


def test_bundled_descriptions_are_the_example_files():
    """Each bundled NAME.toml is byte for byte examples/driveline_NAME.toml, and it is installed."""
    names = data.names()
    assert set(EXAMPLES) <= set(names) and "coupled_clutches.toml" in names
    for name in names:
        example = ROOT / "examples" / f"driveline_{name}"
        assert example.is_file(), f"{name} is bundled but examples/driveline_{name} does not exist"
        assert data.path(name).read_bytes() == example.read_bytes(), f"{name} and {example.name} differ"
    # the folder is a package whose *.toml files are package data (the examples folder is not installed)
    assert (data.DATA_DIR / "__init__.py").is_file()
    package_data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert "*.toml" in package_data.get("*", []) + package_data.get("clutchlab.driveline.data", [])


@pytest.fixture(scope="module")
def section():
    messages = []
    sec = demo_section(progress=messages.append)
    assert messages
    yield sec
    import matplotlib.pyplot as plt

    for item in sec.items:
        if isinstance(item, Figure):
            plt.close(item.figure)


@pytest.fixture(scope="module")
def direct():
    """CoupledClutches from the examples folder, run directly with the file's settings."""
    spec = load_driveline(ROOT / "examples" / "driveline_coupled_clutches.toml")
    return spec.driveline.simulate(spec.t_end, rtol=spec.rtol, max_step=spec.max_step, output_step=spec.output_step)


def test_section_is_a_labelled_simulation_with_every_figure(section):
    assert isinstance(section, Section) and section.synthetic is True
    assert "not measured" in section.provenance and "Simulated" in section.provenance
    names = {i.name for i in section.items if isinstance(i, Figure)}
    for what in ("speeds", "torques", "modes", "energy"):
        assert f"driveline_coupled_clutches_{what}" in names
    text = " ".join(i.text for i in section.items if hasattr(i, "text"))
    assert "Modelica.Mechanics.Rotational.Examples.CoupledClutches" in text and "MSL 4.x" in text
    assert "not measured" in text
    assert section.parameters["coupled_clutches: clutch1"].startswith("[J1] --(clutch1:")


def test_events_table_is_the_simulation_events_in_time_order(section, direct):
    tables = {i.name: i.frame for i in section.items if isinstance(i, Table)}
    ev = tables["driveline_coupled_clutches_events"]
    assert list(ev.columns) == ["time_s", "component", "event"]
    want = direct.events
    assert len(ev) == len(want) == 9  # CoupledClutches' nine mode changes
    assert list(zip(ev.component, ev.event)) == list(zip(want.element, want.event))
    np.testing.assert_allclose(ev.time_s.to_numpy(), want.time_s.to_numpy(), rtol=0, atol=1e-12)
    assert np.all(np.diff(ev.time_s.to_numpy()) > 0)
    # every event is a change of its element's mode: the sampled mode differs before and after it
    t = direct.time
    for row in ev.itertuples():
        modes = direct.mode(row.component)
        before = modes[np.searchsorted(t, row.time_s, side="left") - 1]
        after = modes[np.searchsorted(t, row.time_s, side="right")]
        assert before != after, row


def test_metrics_and_energy_balance(section, direct):
    tables = {i.name: i.frame for i in section.items if isinstance(i, Table)}
    m = dict(zip(*tables["driveline_coupled_clutches_metrics"][["quantity", "value"]].T.to_numpy()))
    last = direct.to_dataframe().iloc[-1]
    for j in ("J1", "J2", "J3", "J4"):
        assert m[f"final speed of {j} [rad/s]"] == pytest.approx(last[f"{j}.w_rad_s"], abs=1e-12)
    for c in ("clutch1", "clutch2", "clutch3"):
        assert m[f"energy dissipated in {c} [J]"] == pytest.approx(last[f"{c}.dissipated_J"], abs=1e-12)
    frame = direct.to_dataframe()
    err = float(frame["energy_error_J"].abs().max())
    assert m["max |energy-balance error| [J]"] == pytest.approx(err, rel=1e-12)
    # the balance checked from its terms, not from the model's own error column: input work = dissipated +
    # change of the stored energy, within 1e-7 of the energy dissipated (1.7e-6 J of 39.9 J at rtol 1e-8)
    stored = frame["kinetic_energy_J"] + frame["spring_energy_J"]
    balance = frame["input_work_J"] - frame["dissipated_energy_J"] - (stored - stored.iloc[0])
    scale = float(frame["dissipated_energy_J"].iloc[-1])
    assert np.max(np.abs(balance)) < 1e-7 * scale
    assert err < 1e-7 * scale
    assert m["events [-]"] == 9


def test_mode_lanes_switch_at_the_events_and_match_the_samples(direct):
    spans = mode_intervals(direct)
    assert set(spans) == set(direct.mode_names)
    t = direct.time
    ev = direct.events
    for name, iv in spans.items():
        assert iv[0][0] == t[0] and iv[-1][1] == t[-1]
        assert all(a[1] == b[0] and a[2] != b[2] for a, b in zip(iv, iv[1:]))
        np.testing.assert_array_equal([s for s, _, _ in iv[1:]], ev.time_s[ev.element == name].to_numpy())
        sampled = direct.mode(name)
        for start, stop, mode in iv:
            inside = (t > start + 1e-9) & (t < stop - 1e-9)
            assert np.all(sampled[inside] == mode), (name, start, stop, mode)


_SIGNATURES = """
import gc, json
from numba.core.dispatcher import Dispatcher
from clutchlab import warmup
from clutchlab.demo.driveline import EXAMPLES, run_example

def signatures():
    return {(id(d), str(s)) for d in gc.get_objects() if isinstance(d, Dispatcher) for s in d.signatures}

warmup.warm(["eclutch", "driveline"])
warm = signatures()
for name in EXAMPLES:
    run_example(name)
print(json.dumps({"warm": len(warm), "new": sorted(s for _, s in signatures() - warm)}))
"""


def test_warmup_group_compiles_what_the_section_runs():
    """``clutchlab warmup driveline`` prepares every compiled specialisation the demo's runs use but the
    E-clutch dynamics of the launch's actuator, which are the ``eclutch`` group's (the demo's first section,
    run before this one): in a fresh process, after the two groups, running the examples adds no signature
    to any numba dispatcher (a missing one would be compiled, or loaded, in the demo's main process instead of
    the background)."""
    import json
    import os
    import subprocess
    import sys

    env = dict(os.environ, CLUTCHLAB_COMPILE_NOTICE="0", MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, "-c", _SIGNATURES], capture_output=True, text=True, env=env, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["warm"] > 0
    assert out["new"] == []


def test_the_dual_clutch_upshift_shows_its_shift_quality(section):
    """The DCT example's shift: its figure, and its metrics' table equal to shift_quality of a direct run."""
    from clutchlab.driveline.shift import shift_quality

    names = {i.name for i in section.items if isinstance(i, Figure)}
    assert "driveline_dct_upshift_shift" in names and "driveline_dct_upshift_speeds" in names
    tables = {i.name: i.frame for i in section.items if isinstance(i, Table)}
    shown = tables["driveline_dct_upshift_shift_quality"].set_index("metric")
    spec = load_driveline(ROOT / "examples" / "driveline_dct_upshift.toml")
    res = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, max_step=spec.max_step, output_step=spec.output_step)
    q = shift_quality(res, **spec.shift)   # (the file's [shift] table)
    for k, v in q.metrics.items():
        assert shown.loc[k, "value"] == pytest.approx(v, rel=1e-9, nan_ok=True), k
    assert shown.loc["jerk_peak_m_s3", "unit"] == "m_s3"
    text = " ".join(i.text for i in section.items if hasattr(i, "text"))
    assert f"the inertia phase {1e3 * q.metrics['inertia_phase_s']:.0f} ms" in text


def test_the_torque_converter_launch_shows_its_operating_points(section):
    """The converter example: its figure, and its text's torque ratio and efficiency equal to the operating points of
    a direct run, which follow the file's table (K in rpm/sqrt(N m), TR) where the impeller drives."""
    from clutchlab.driveline.plots import converter_points

    names = {i.name for i in section.items if isinstance(i, Figure)}
    assert "driveline_torque_converter_converter" in names and "driveline_torque_converter_speeds" in names
    # the automatic's upshift: its converter and its shift, as any file with a converter and a [shift] table
    assert {"driveline_at_upshift_converter", "driveline_at_upshift_shift"} <= names
    spec = load_driveline(ROOT / "examples" / "driveline_torque_converter.toml")
    res = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, max_step=spec.max_step, output_step=spec.output_step)
    pts = converter_points(res.to_dataframe(), "converter")
    sr = pts["speed_ratio_1"].to_numpy()
    table = np.array([[0.0, 130, 2.1], [0.2, 133, 1.8], [0.4, 140, 1.5], [0.6, 155, 1.25], [0.8, 200, 1.02],
                      [0.85, 230, 1.0], [0.9, 300, 1.0]])
    inside = sr <= 0.9
    assert inside.sum() > 100
    assert np.allclose(pts["capacity_factor_rpm_sqrtNm"][inside], np.interp(sr[inside], table[:, 0], table[:, 1]),
                       rtol=1e-9)
    assert np.allclose(pts["torque_ratio_1"], np.interp(sr, table[:, 0], table[:, 2]), rtol=1e-9)
    text = " ".join(i.text for i in section.items if hasattr(i, "text"))
    assert f"by up to {pts['torque_ratio_1'].max():.2f}" in text
    # the share of the impeller's work passed on: 1 - lost / taken, the impeller's work from the engine's speed
    df = res.to_dataframe()
    power, t = (-df["converter.tau_Nm"] * df["engine.w_rad_s"]).to_numpy(), df["time_s"].to_numpy()
    taken = float(np.sum(0.5 * np.diff(t) * (power[1:] + power[:-1])))
    lost = df["converter.dissipated_J"].iloc[-1]
    assert 0.0 < lost < taken
    assert f"its impeller took {taken / 1e3:.1f} kJ, of which it passed {100 * (1 - lost / taken):.0f} %" in text


def test_the_amt_upshift_shows_its_interrupted_shift(section):
    """The AMT example: its shift's figure and its metrics' table equal to shift_quality of a direct run (an
    interrupted shift, through the file's [shift] table with its clutch), and the text's numbers from them."""
    from clutchlab.driveline.shift import shift_quality

    names = {i.name for i in section.items if isinstance(i, Figure)}
    assert {"driveline_amt_upshift_shift", "driveline_amt_upshift_speeds"} <= names
    tables = {i.name: i.frame for i in section.items if isinstance(i, Table)}
    shown = tables["driveline_amt_upshift_shift_quality"].set_index("metric")
    spec = load_driveline(ROOT / "examples" / "driveline_amt_upshift.toml")
    res = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, max_step=spec.max_step, output_step=spec.output_step)
    q = shift_quality(res, **spec.shift)
    assert q.kind == "interrupted" and list(shown.index) == list(q.metrics)
    for k, v in q.metrics.items():
        assert shown.loc[k, "value"] == pytest.approx(v, rel=1e-9, nan_ok=True), k
    text = " ".join(i.text for i in section.items if hasattr(i, "text"))
    assert f"the drive is interrupted for {1e3 * q.metrics['torque_interruption_s']:.0f} ms" in text
