"""Judder (``clutchlab.control.judder``): the modes of a sliding clutch's driveline against their closed form, a run
against the exact solution of its linear equation, the friction slope read through the contract, the oscillation
measure on a known signal, the command line."""

from __future__ import annotations

import json
import math
import pathlib

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("control")

from cli_checks import one_line_error  # noqa: E402
from clutchlab.cli import main  # noqa: E402
from clutchlab.control import judder_modes, linearize, oscillation, pole_sweep  # noqa: E402
from clutchlab.driveline import Driveline, Signal  # noqa: E402
from clutchlab.errors import ParameterError  # noqa: E402

ROOT = pathlib.Path(__file__).parents[2]

# a disc dragged by a clutch from a drive at a constant speed, held by a shaft to the ground
J, K, D = 0.05, 2000.0, 0.2             # kg m^2, N m/rad, N m s/rad
FN, CGEO, MU0, WE = 1000.0, 0.2, 0.3, 50.0
TAU0 = CGEO * FN * MU0                  # the sliding torque at the drive's speed [N m]
KICK = 1e-4                             # the disc's start beyond its steady angle [rad]


def disc(slope: float, kick: float = KICK) -> Driveline:
    """``mu(|w_rel|) = MU0 + slope (|w_rel| - WE)``, linear over the slip speeds the disc reaches."""
    d = Driveline("judder_disc")
    d.inertia("E", J=1.0, w0=WE)
    d.speed("drive", "E", WE)
    d.inertia("disc", J=J, w0=0.0, phi0=TAU0 / K + kick)
    d.clutch("c", "E", "disc", fn_max=FN, mu=[[0.0, MU0 - slope * WE], [2 * WE, MU0 + slope * WE]], cgeo=CGEO)
    d.spring_damper("shaft", "disc", "ground", c=K, d=D)
    return d


def closed_form(slope: float):
    """``J phi'' + (D + d_f) phi' + K phi = TAU0`` with ``d_f = CGEO FN slope`` (the torque on the disc is
    ``CGEO FN mu(WE - w)``): the growth rate and the damped angular frequency."""
    sigma = -(D + CGEO * FN * slope) / (2 * J)
    return sigma, math.sqrt(K / J - sigma ** 2)


@pytest.mark.parametrize("slope", [-0.004, -0.001, 0.0, 0.004])
def test_the_modes_of_a_sliding_disc_follow_the_closed_form(slope):
    jm = judder_modes(disc(slope).system(1e-10))
    sigma, wd = closed_form(slope)
    assert len(jm.table) == 1, jm.table
    mode = jm.table.iloc[0]
    assert mode.growth_rate_1_s == pytest.approx(sigma, abs=1e-6 * wd)
    assert mode.frequency_Hz == pytest.approx(wd / (2 * math.pi), rel=1e-8)
    assert mode.natural_frequency_Hz == pytest.approx(math.sqrt(K / J) / (2 * math.pi), rel=1e-8)
    assert mode.damping_1 == pytest.approx(-sigma / math.sqrt(K / J), abs=1e-8)
    assert mode.state == "disc.w_rad_s"
    # judder exactly where the clutch's negative damping outweighs the shaft's: CGEO FN slope < -D
    assert jm.unstable == (CGEO * FN * slope < -D) == bool(mode.unstable)
    (row,) = jm.friction.itertuples()
    assert (row.element, row.mode) == ("c", "backward")
    assert row.slip_rad_s == pytest.approx(-WE) and row.tau_Nm == pytest.approx(-TAU0, rel=1e-12)
    assert row.damping_Nms_rad == pytest.approx(CGEO * FN * slope, abs=1e-7)
    assert "JUDDER" in str(jm) if jm.unstable else "JUDDER" not in str(jm)


def test_a_sliding_disc_runs_as_the_solution_of_its_linear_equation():
    """While it slides, the disc's equation is linear (mu is linear in the slip speed), so the network's run is the
    damped (here growing) oscillation ``phi* + KICK exp(sigma t) (cos wd t - sigma/wd sin wd t)``; the oscillation
    measure reads its frequency, and its amplitude within the envelope's growth over one period."""
    slope = -0.004
    sigma, wd = closed_form(slope)
    res = disc(slope).simulate(0.9, rtol=1e-10, output_step=1e-4)
    assert res.events.empty
    df = res.to_dataframe()
    t = df["time_s"].to_numpy()
    exact = TAU0 / K + KICK * np.exp(sigma * t) * (np.cos(wd * t) - sigma / wd * np.sin(wd * t))
    assert np.max(np.abs(df["disc.phi_rad"].to_numpy() - exact)) < 1e-6 * KICK * math.exp(sigma * 0.9)
    # (windows well inside the run: the band-pass's transients at its ends, the end's largest for a growing signal)
    for start, end in ((0.1, 0.3), (0.3, 0.5)):
        osc = oscillation(res, "disc.w_rad_s", (10.0, 100.0), start=start, end=end)
        assert osc.frequency_Hz == pytest.approx(wd / (2 * math.pi), rel=1e-3)
        envelope = KICK * K / (J * wd) * math.exp(sigma * end)    # the speed's amplitude at the window's end
        assert envelope * math.exp(-sigma * 2 * math.pi / wd) * 0.99 < osc.amplitude < envelope * 1.01, (osc, envelope)
        assert osc.column == "disc.w_rad_s" and osc.band_Hz == (10.0, 100.0)


def test_judder_grows_into_stick_slip_with_the_invariants_kept():
    """The growing mode takes the disc up to the drive's speed, where the clutch sticks, breaks away and slides
    again: a stick-slip limit cycle, every step checked (stuck torque within the limit, modes agreeing with the
    speeds, the energy balance)."""
    res = disc(-0.004).simulate(2.0, rtol=1e-8, output_step=1e-3, check_invariants=True)
    ev = res.events[res.events.element == "c"]
    assert (ev.event == "stick").sum() >= 3 and (ev.event == "backward").sum() >= 3, ev
    first = float(ev.time_s[ev.event == "stick"].iloc[0])
    sigma, wd = closed_form(-0.004)
    # the first stick when the linear oscillation's speed amplitude reaches the drive's speed, within a period
    reach = math.log(WE / (KICK * K / (J * wd))) / sigma
    assert reach - 2 * math.pi / wd < first < reach + 2 * math.pi / wd, (first, reach)


def test_the_friction_slope_of_the_example_launch_is_its_lining_s():
    """examples/driveline_judder.toml at 0.6 s: the clutch slides at its full normal force, so its damping is
    ``cgeo fn_max dmu/dw = 0.22 * 3000 * (-0.08 / 150)``, and the first torsional mode (about 11 Hz) grows."""
    from clutchlab.driveline.description import load_driveline

    spec = load_driveline(ROOT / "examples" / "driveline_judder.toml")
    jm = judder_modes(spec.driveline.system(spec.rtol), run_to=0.6)
    clutch = jm.friction.set_index("element").loc["clutch"]
    assert clutch["mode"] == "backward"
    assert clutch["damping_Nms_rad"] == pytest.approx(0.22 * 3000.0 * (-0.08 / 150.0), rel=1e-6)
    (mode,) = jm.table[jm.table.unstable].itertuples()
    assert 9.0 < mode.frequency_Hz < 13.0 and mode.state == "input_shaft.w_rad_s"
    assert jm.operating_point.t == 0.6
    # the state there is the run's own at that time
    res = spec.driveline.simulate(0.6, rtol=spec.rtol, output_step=0.6)
    assert jm.operating_point.value("input_shaft.w") == pytest.approx(
        float(res.to_dataframe()["input_shaft.w_rad_s"].iloc[-1]), rel=1e-9)


def test_the_oscillation_of_a_known_signal():
    t = np.arange(0.0, 2.0 + 1e-9, 1e-3)
    y = 0.3 * np.sin(2 * np.pi * 12.0 * t + 0.4) + 5.0 * t + 2.0 * np.sin(2 * np.pi * 0.5 * t)
    frame = pd.DataFrame({"time_s": t, "x.w_rad_s": y})
    osc = oscillation(frame, "x.w_rad_s", (5.0, 30.0), start=0.5, end=1.5)
    assert osc.amplitude == pytest.approx(0.3, rel=0.01)
    assert osc.rms == pytest.approx(0.3 / math.sqrt(2), rel=0.01)
    assert osc.frequency_Hz == pytest.approx(12.0, rel=1e-3)
    # the ramp and the slow sine alone (10 rad/s of slow motion): what leaks through the band is 1/500 of the 0.3
    slow = 5.0 * t + 2.0 * np.sin(2 * np.pi * 0.5 * t)
    flat = oscillation(pd.DataFrame({"time_s": t, "x.w_rad_s": slow}), "x.w_rad_s", (5.0, 30.0), start=0.5, end=1.5)
    assert flat.amplitude < 0.3 / 500


def test_the_oscillation_refuses_what_it_cannot_read():
    t = np.arange(0.0, 1.0, 1e-3)
    frame = pd.DataFrame({"time_s": t, "x.w_rad_s": np.sin(60 * t)})
    with pytest.raises(ParameterError, match=r"no column 'y.w_rad_s'"):
        oscillation(frame, "y.w_rad_s", (5.0, 30.0))
    with pytest.raises(ParameterError, match=r"below|Nyquist frequency 500 Hz"):
        oscillation(frame, "x.w_rad_s", (5.0, 600.0))
    with pytest.raises(ParameterError, match=r"0 < low < high"):
        oscillation(frame, "x.w_rad_s", (30.0, 5.0))
    uneven = frame.assign(time_s=t ** 1.5)
    with pytest.raises(ParameterError, match=r"constant interval"):
        oscillation(uneven, "x.w_rad_s", (5.0, 30.0))
    with pytest.raises(ParameterError, match=r"at least 16"):
        oscillation(frame.iloc[:10], "x.w_rad_s", (5.0, 30.0))


def test_a_system_without_inputs_has_modes_but_no_linear_model():
    """python-control cannot hold a model with outputs and no inputs: linearize says so; the poles (pole_sweep)
    and judder_modes work without inputs."""
    system = disc(0.004).system(1e-10)
    with pytest.raises(ParameterError, match=r"needs at least one input"):
        linearize(system)
    poles = pole_sweep([(0.0, judder_modes(system).operating_point)])
    sigma, wd = closed_form(0.004)
    assert np.any(np.abs(poles.pole_real_1_s + 1j * poles.pole_imag_1_s - (sigma + 1j * wd)) < 1e-5 * wd)


def test_judder_from_the_command_line(tmp_path, capsys):
    example = str(ROOT / "examples" / "driveline_judder.toml")
    out = tmp_path / "judder.json"
    assert main(["control", "judder", "driveline", example, "--run-to", "0.6 s", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "JUDDER" in text and "clutch backward" in text
    doc = json.loads(out.read_text())
    assert doc["unstable"] is True and doc["time_s"] == 0.6 and doc["modes"]["clutch"] == "backward"
    assert any(m["unstable"] for m in doc["oscillating_modes"])
    # the steady slide of the disc, trimmed in its sliding mode (a file of the network above), written as CSV
    net = tmp_path / "disc.toml"
    net.write_text(f"""
[inertia.E]
J = 1.0
w0 = {WE}
[speed.drive]
flange = "E"
speed = {WE}
[inertia.disc]
J = {J}
[clutch.c]
a = "E"
b = "disc"
fn_max = {FN}
cgeo = {CGEO}
mu = [[0.0, {MU0 + 0.004 * WE}], [{2 * WE}, {MU0 - 0.004 * WE}]]
[spring_damper.shaft]
a = "disc"
b = "ground"
c = {K}
d = {D}
""")
    csv = tmp_path / "modes.csv"
    assert main(["control", "judder", "driveline", str(net), "--mode", "c=backward", "-o", str(csv)]) == 0
    table = pd.read_csv(csv)
    sigma, wd = closed_form(-0.004)
    assert len(table) == 1 and table.growth_rate_1_s[0] == pytest.approx(sigma, abs=1e-5 * wd)
    assert "JUDDER" in capsys.readouterr().out
    # refusals: one line, exit 2, nothing written
    line = one_line_error(capsys, ["control", "judder", "driveline", example, "--run-to", "0.6 s", "-o",
                                   str(tmp_path / "j.txt")])
    assert "expected a .json or .csv file" in line
    line = one_line_error(capsys, ["control", "judder", "driveline", example, "--run-to", "0.6 s", "--set",
                                   "x=1", "-o", str(tmp_path / "j.json")])
    assert "drop the trim options" in line
    line = one_line_error(capsys, ["control", "judder", "driveline", example, "--run-to", "0.6 s", "-o", str(out)])
    assert "exists" in line or "--force" in line
    assert not (tmp_path / "j.txt").exists() and not (tmp_path / "j.json").exists()


def test_a_timeline_along_the_example_launch(tmp_path, capsys):
    """The clutch's damping follows its normal force, a ramp from 0.1 to 0.4 s: ``-0.352 N m s/rad`` times
    ``(t - 0.1) / 0.3`` while it slides, NaN while it is free (before 0.1 s) or stuck (after the lock-up at
    0.66 s); the first mode grows exactly where its damping ratio is negative."""
    from clutchlab.control import judder_timeline
    from clutchlab.driveline.description import load_driveline

    spec = load_driveline(ROOT / "examples" / "driveline_judder.toml")
    system = spec.driveline.system(spec.rtol)
    times = [0.05, 0.2, 0.3, 0.5, 0.8]
    tl = judder_timeline(system, times)
    assert list(tl.time_s) == times
    full = 0.22 * 3000.0 * (-0.08 / 150.0)
    want = [math.nan, full / 3, full * 2 / 3, full, math.nan]
    np.testing.assert_allclose(tl["clutch.damping_Nms_rad"], want, rtol=1e-6)
    assert list(tl.unstable) == [False, False, True, True, False]
    assert ((tl.growth_rate_1_s > 0) == tl.unstable).all() and ((tl.damping_1 < 0) == tl.unstable).all()
    # the same rows as a single analysis at that time (within the run's tolerance: stopping at the earlier times
    # changes its steps)
    single = judder_modes(system, run_to=0.5)
    assert tl.growth_rate_1_s[3] == pytest.approx(single.table.growth_rate_1_s.max(), rel=1e-6)
    with pytest.raises(ParameterError, match=r"increasing"):
        judder_timeline(system, [0.3, 0.2])
    out, png = tmp_path / "timeline.csv", tmp_path / "timeline.png"
    assert main(["control", "judder", "driveline", str(ROOT / "examples" / "driveline_judder.toml"),
                 "--run-to", "0.2 s", "--run-to", "0.5 s", "-o", str(out), "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    table = pd.read_csv(out)
    assert list(table.time_s) == [0.2, 0.5] and table["clutch.damping_Nms_rad"][1] == pytest.approx(full, rel=1e-6)
    assert "clutch.damping_Nms_rad" in capsys.readouterr().out
    js = tmp_path / "timeline.json"   # (standard JSON: the clutch's damping while it is free is null, not NaN)
    assert main(["control", "judder", "driveline", str(ROOT / "examples" / "driveline_judder.toml"),
                 "--run-to", "0.05 s", "--run-to", "0.5 s", "-o", str(js)]) == 0
    rows = json.loads(js.read_text(), parse_constant=lambda c: pytest.fail(f"{c} in the JSON"))["timeline"]
    assert rows[0]["clutch.damping_Nms_rad"] is None and rows[1]["clutch.damping_Nms_rad"] == pytest.approx(full)
    line = one_line_error(capsys, ["control", "judder", "driveline", str(ROOT / "examples" / "driveline_judder.toml"),
                                   "--run-to", "0.5 s", "--run-to", "0.2 s"])
    assert "must increase" in line
    line = one_line_error(capsys, ["control", "judder", "driveline", str(ROOT / "examples" / "driveline_judder.toml"),
                                   "--run-to", "0.5 s", "--plot", str(tmp_path / "one.png")])
    assert "--plot draws a timeline" in line and not (tmp_path / "one.png").exists()


def test_the_judder_figure_shades_where_a_mode_grows():
    from clutchlab.control.plots import judder_figure

    timeline = pd.DataFrame({"time_s": [0.0, 0.1, 0.2, 0.3], "frequency_Hz": [10.0, 10.5, 10.8, 3.5],
                             "damping_1": [0.05, -0.01, -0.05, 0.1], "growth_rate_1_s": [-3.0, 0.7, 3.4, -2.2],
                             "state": ["x.w_rad_s"] * 4, "unstable": [False, True, True, False],
                             "c.damping_Nms_rad": [np.nan, -0.2, -0.35, np.nan]})
    fig = judder_figure(timeline, title="t")
    spans = [p for p in fig.axes[0].patches]
    assert len(spans) == 2                                    # the two times a mode grows, shaded to the next
    assert [line.get_label() for line in fig.axes[2].get_lines()][0] == "c"
    np.testing.assert_allclose(fig.axes[0].get_lines()[0].get_ydata(), [5.0, -1.0, -5.0, 10.0])   # in percent
