"""Shift quality (clutchlab.driveline.shift): the phases and metrics of a clutch-to-clutch shift against closed forms
of a designed record, and against the events and the clutches' own dissipation in a dual-clutch upshift run."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.driveline.shift import shift_quality
from clutchlab.errors import ParameterError

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
H = 1e-4                 # [s] the record's sample interval
T, W = 200.0, 100.0      # [N m], [rad/s] the clutches' torque and the on-coming clutch's slip before the shift
A0, D, L0, L = 2.0, 1.5, 0.21, 0.3   # the output's acceleration, its dip sin^2 from L0 over L [rad/s^2], [s]
FLARE = 7.0              # [rad/s] the engine's bump, sin^2 over [0.21, 0.31] s (drawn; flare is read from c1's slip)
THR = 0.0237             # (thresholds between samples: the detected instants are the next sample)


def _record(downshift=False):
    """A designed upshift: the off-going clutch hands T over to the on-coming one linearly over [0.2, 0.3] s (the
    torque phase), the on-coming one's slip falls linearly from W to 0 over [0.3, 0.5] s (the inertia phase); the
    output's acceleration dips by D sin^2 over [0.21, 0.51] s; the engine's speed bumps by FLARE, then falls (the
    off-going clutch slides against the way it drove: no flare)."""
    t = np.round(np.arange(0.0, 1.0 + H / 2, H), 12)
    ramp = np.clip((t - 0.2) / 0.1, 0.0, 1.0)
    u = np.clip(t - L0, 0.0, L)
    integral = u / 2 - L / (4 * math.pi) * np.sin(2 * math.pi * u / L)
    bump = np.where((t > 0.21) & (t < 0.31), np.sin(math.pi * (t - 0.21) / 0.1) ** 2, 0.0)
    frame = pd.DataFrame({
        "time_s": t,
        "c1.tau_Nm": T * (1.0 - ramp),
        "c2.tau_Nm": -T * ramp,          # (signs are the clutches' own: magnitudes are read)
        "c1.w_rel_rad_s": np.where(t > 0.3, -50.0 * (t - 0.3), 0.0),
        "c2.w_rel_rad_s": W * np.clip(1.0 - (t - 0.3) / 0.2, 0.0, 1.0),
        "out.w_rad_s": 10.0 + A0 * t - D * integral,
        "engine.w_rad_s": 300.0 + FLARE * bump - 100.0 * np.clip((t - 0.31) / 0.19, 0.0, 1.0),
    })
    return frame


def _e_on(a, b):
    """The closed form of the integral of |tau_on w_on| from a to b (a in the torque phase, b in the inertia phase)."""
    torque = T * W * ((0.3 - 0.2) ** 2 - (a - 0.2) ** 2) / (2 * 0.1)    # T (t-0.2)/0.1 * W over [a, 0.3]
    inertia = T * W * ((b - 0.3) - (b - 0.3) ** 2 / (2 * 0.2))          # T * W (1 - (t-0.3)/0.2) over [0.3, b]
    return torque + inertia


def test_the_phases_and_metrics_of_a_designed_upshift_are_its_closed_forms():
    q = shift_quality(_record(), offgoing="c1", oncoming="c2", output="out", engine="engine", threshold=THR)
    # the instants: the first sample past the threshold's crossing of each ramp
    assert q.order == "upshift"
    assert 0.2 + 0.1 * THR < q.start_s <= 0.2 + 0.1 * THR + H
    assert 0.3 - 0.1 * THR <= q.handover_s < 0.3 - 0.1 * THR + H
    assert 0.5 - 0.2 * THR <= q.lockup_s < 0.5 - 0.2 * THR + H
    assert q.end_s == q.lockup_s
    m = q.metrics
    assert m["shift_time_s"] == pytest.approx(q.lockup_s - q.start_s, abs=1e-12)
    assert m["torque_phase_s"] == pytest.approx(q.handover_s - q.start_s, abs=1e-12)
    assert m["inertia_phase_s"] == pytest.approx(q.lockup_s - q.handover_s, abs=1e-12)
    assert m["acceleration_before_rad_s2"] == pytest.approx(A0, rel=1e-9)
    assert m["acceleration_dip_rad_s2"] == pytest.approx(D, rel=1e-6)
    assert m["acceleration_peak_to_peak_rad_s2"] == pytest.approx(D, rel=1e-6)
    assert m["jerk_peak_rad_s3"] == pytest.approx(D * math.pi / L, rel=1e-4)
    assert m["vdv_rad_s1_75"] == pytest.approx(D * (L * 35.0 / 128.0) ** 0.25, rel=1e-5)   # int sin^8 = 35 L/128
    assert m["lockup_slip_rate_rad_s2"] == pytest.approx(W / 0.2, rel=1e-9)
    assert m["flare_rad_s"] == 0.0   # (c1 slides backward, against the positive torque it drove with)
    assert m["oncoming_energy_J"] == pytest.approx(_e_on(q.start_s, q.lockup_s), rel=1e-6)
    assert m["oncoming_peak_power_W"] == pytest.approx(T * W, rel=1e-12)
    assert m["offgoing_energy_J"] == 0.0 and m["offgoing_peak_power_W"] == 0.0   # (stuck until it carries nothing)
    assert m["tie_up_Nm"] == 0.0


def test_an_off_going_clutch_released_late_ties_up_by_the_torque_it_carries_against_its_drive():
    """The designed record with the off-going clutch braking the engine, -(sin^2) up to 40 N m over [0.31, 0.39] s
    (against the positive torque it drove with): the tie-up is 40 N m; the on-coming clutch's the same as before."""
    f = _record()
    t = f["time_s"].to_numpy()
    f["c1.tau_Nm"] -= np.where((t > 0.31) & (t < 0.39), 40.0 * np.sin(math.pi * (t - 0.31) / 0.08) ** 2, 0.0)
    q = shift_quality(f, offgoing="c1", oncoming="c2", output="out", threshold=THR)
    assert q.metrics["tie_up_Nm"] == pytest.approx(40.0, rel=1e-9)
    f["c1.tau_Nm"] *= -1.0   # (the other sign convention: the same tie-up)
    assert shift_quality(f, offgoing="c1", oncoming="c2", output="out", threshold=THR).metrics[
        "tie_up_Nm"] == pytest.approx(40.0, rel=1e-9)


def test_a_radius_gives_the_vehicle_acceleration_and_a_filter_keeps_the_metrics_of_a_smooth_record():
    r = 0.3 / 3.5
    q = shift_quality(_record(), offgoing="c1", oncoming="c2", output="out.w_rad_s", radius=r, threshold=THR)
    m = q.metrics
    assert m["acceleration_dip_m_s2"] == pytest.approx(D * r, rel=1e-6)
    assert m["jerk_peak_m_s3"] == pytest.approx(D * r * math.pi / L, rel=1e-4)
    assert m["vdv_m_s1_75"] == pytest.approx(D * r * (L * 35.0 / 128.0) ** 0.25, rel=1e-5)
    assert m["flare_rad_s"] == 0.0
    # a noisy record (a rig's): the filtered acceleration's dip within 2 % where the raw one's is far off
    rng = np.random.default_rng(7)
    noisy = _record()
    noisy["out.w_rad_s"] += rng.normal(0.0, 1e-4, len(noisy))
    raw = shift_quality(noisy, offgoing="c1", oncoming="c2", output="out", threshold=THR)
    filtered = shift_quality(noisy, offgoing="c1", oncoming="c2", output="out", threshold=THR, filter_Hz=20.0)
    assert abs(raw.metrics["acceleration_dip_rad_s2"] - D) > 0.2
    assert filtered.metrics["acceleration_dip_rad_s2"] == pytest.approx(D, rel=0.02)


def test_a_shift_s_direction_comes_from_the_engine_s_speed_and_its_sequence_from_its_phases():
    """The designed upshift's record with the engine's speed made to rise across the shift (a coast downshift runs its
    torque phase first): ``order`` is the direction the engine's speed over the output's takes, ``"downshift"``, and
    ``sequence`` the phases' order, ``"torque_first"``; its text names both.  Without the engine column the order is
    the sequence's name as a power-on shift's; the designed downshift (inertia phase first) with an engine whose
    speed over the output's falls is a coast upshift's reading."""
    f = _record()
    t = f["time_s"].to_numpy()
    f["engine.w_rad_s"] = 150.0 + 100.0 * np.clip((t - 0.3) / 0.2, 0.0, 1.0)
    q = shift_quality(f, offgoing="c1", oncoming="c2", output="out", engine="engine", threshold=THR)
    assert (q.order, q.sequence) == ("downshift", "torque_first")
    assert str(q).startswith("downshift (torque phase first) from ") and q.to_dict()["sequence"] == "torque_first"
    plain = shift_quality(f, offgoing="c1", oncoming="c2", output="out", threshold=THR)
    assert (plain.order, plain.sequence) == ("upshift", "torque_first")
    d = _record()
    d["c1.w_rel_rad_s"] = np.where(t > 0.15, 20.0, 0.0)
    d["c1.tau_Nm"] = T * np.clip(1.0 - (t - 0.5) / 0.1, 0.0, 1.0)
    d["c2.tau_Nm"] = T * np.clip((t - 0.5) / 0.1, 0.0, 1.0)
    coast = shift_quality(d, offgoing="c1", oncoming="c2", output="out", engine="engine", threshold=THR)
    assert (coast.order, coast.sequence) == ("upshift", "inertia_first")   # (the record's engine falls by 100 rad/s)


def test_a_downshift_runs_its_inertia_phase_first():
    """The same record with the off-going clutch sliding from 0.15 s (the engine speeds up) and still carrying its
    torque until 0.6 s, after the on-coming one has locked at 0.5 s."""
    f = _record()
    t = f["time_s"].to_numpy()
    f["c1.w_rel_rad_s"] = np.where(t > 0.15, 20.0, 0.0)
    f["c1.tau_Nm"] = T * np.clip(1.0 - (t - 0.5) / 0.1, 0.0, 1.0)
    f["c2.tau_Nm"] = T * np.clip((t - 0.5) / 0.1, 0.0, 1.0)
    q = shift_quality(f, offgoing="c1", oncoming="c2", output="out", threshold=THR)
    assert q.order == "downshift"
    assert q.metrics["flare_rad_s"] == 20.0   # (its slip the way it drove: the engine running ahead of the old gear)
    assert 0.15 <= q.start_s <= 0.15 + 1.5 * H   # (the off-going clutch's slip, before the on-coming one's torque)
    assert 0.6 - 0.1 * THR <= q.handover_s < 0.6 - 0.1 * THR + H
    assert q.metrics["inertia_phase_s"] == pytest.approx(q.lockup_s - q.start_s)
    assert q.metrics["torque_phase_s"] == pytest.approx(q.handover_s - q.lockup_s)
    assert q.metrics["offgoing_energy_J"] == pytest.approx(
        20.0 * T * ((q.handover_s - q.start_s) - (q.handover_s - 0.5) ** 2 / (2 * 0.1)), rel=1e-6)


def test_bad_records_are_refused_with_the_reason():
    f = _record()
    with pytest.raises(ParameterError, match="no column 'c3.tau_Nm'"):
        shift_quality(f, offgoing="c1", oncoming="c3", output="out")
    with pytest.raises(ParameterError, match="output 'shaft': no column"):
        shift_quality(f, offgoing="c1", oncoming="c2", output="shaft")
    g = f.copy()
    g.loc[len(g) // 2:, "c2.w_rel_rad_s"] = 5.0
    with pytest.raises(ParameterError, match="c2 does not lock within the record"):
        shift_quality(g, offgoing="c1", oncoming="c2", output="out")
    g = f.drop(index=[100])
    with pytest.raises(ParameterError, match="constant interval"):
        shift_quality(g, offgoing="c1", oncoming="c2", output="out")
    g = f.copy()
    g.loc[3, "out.w_rad_s"] = np.nan
    with pytest.raises(Exception, match="out.w_rad_s"):
        shift_quality(g, offgoing="c1", oncoming="c2", output="out")
    with pytest.raises(ParameterError, match="threshold"):
        shift_quality(f, offgoing="c1", oncoming="c2", output="out", threshold=0.7)
    with pytest.raises(ParameterError, match="start = 2.0 s is outside the record"):
        shift_quality(f, offgoing="c1", oncoming="c2", output="out", start=2.0)


def test_a_csv_record_and_the_result_s_forms(tmp_path):
    path = tmp_path / "rig.csv"
    _record().to_csv(path, index=False)
    q = shift_quality(str(path), offgoing="c1", oncoming="c2", output="out", threshold=THR)
    ref = shift_quality(_record(), offgoing="c1", oncoming="c2", output="out", threshold=THR)
    for k, v in ref.metrics.items():
        assert q.metrics[k] == pytest.approx(v, rel=1e-9, nan_ok=True), k
    doc = json.loads(json.dumps(q.to_dict(), allow_nan=False))
    assert doc["order"] == "upshift" and doc["metrics"]["lockup_slip_rate_rad_s2"] == pytest.approx(W / 0.2)
    table = q.table()
    assert list(table["metric"]) == list(q.metrics)
    assert table.set_index("metric").loc["jerk_peak_rad_s3", "unit"] == "rad_s3"
    assert "lock-up at" in str(q)


def test_a_dual_clutch_upshift_run_against_its_events_and_its_clutches_heat():
    """The dual-clutch upshift of examples/driveline_dct_upshift.toml: with a fine threshold the lock-up the columns
    give is the on-coming clutch's stick event and the hand-over the off-going clutch's release (its normal force
    gone) to a sample; at the default threshold the lock-up is early by at most the threshold's share of the slip
    over its rate at lock-up; the energies are the clutches' own dissipated energy over the shift within 1e-3."""
    from clutchlab.driveline.description import load_driveline

    spec = load_driveline("examples/driveline_dct_upshift.toml")
    res = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, output_step=spec.output_step)
    frame = res.to_dataframe()
    ev = res.events
    stick = float(ev[(ev["element"] == "c2") & (ev["event"] == "stick")]["time_s"].iloc[0])
    free = float(ev[(ev["element"] == "c1") & (ev["event"] == "free")]["time_s"].iloc[0])
    start = float(ev[(ev["element"] == "c2") & (ev["event"] == "backward")]["time_s"].iloc[0])
    h = spec.output_step
    fine = shift_quality(res, offgoing="c1", oncoming="c2", output="wheels", engine="engine", radius=0.3,
                         threshold=1e-4)
    assert fine.order == "upshift"
    assert start <= fine.start_s <= start + h + 1e-9
    assert stick - h <= fine.lockup_s <= stick + h
    assert free - h <= fine.handover_s <= free + h
    q = shift_quality(res, offgoing="c1", oncoming="c2", output="wheels", engine="engine", radius=0.3)
    w_ref = max(frame["c1.w_rel_rad_s"].abs().max(), frame["c2.w_rel_rad_s"].abs().max())
    early = 0.02 * w_ref / q.metrics["lockup_slip_rate_rad_s2"]
    assert stick - early - 2 * h <= q.lockup_s <= stick
    t = frame["time_s"]
    heat = {c: float(np.interp(q.end_s, t, frame[f"{c}.dissipated_J"]) - np.interp(q.start_s, t,
                                                                                 frame[f"{c}.dissipated_J"]))
            for c in ("c1", "c2")}
    scale = sum(heat.values())   # (c1 slides for 7 ms, a few samples: its heat is read to the samples' error)
    for side, c in (("offgoing", "c1"), ("oncoming", "c2")):
        assert q.metrics[f"{side}_energy_J"] == pytest.approx(heat[c], rel=1e-3, abs=1e-6 * scale), side
    assert q.metrics["oncoming_energy_J"] > 1000.0
    assert q.metrics["acceleration_dip_m_s2"] > 0.5 and q.metrics["jerk_peak_m_s3"] > 10.0


def test_the_command_line_reads_a_record_and_writes_json_or_csv_together_or_not_at_all(tmp_path, capsys):
    from cli_checks import one_line_error

    from clutchlab.cli import main

    rig = tmp_path / "rig.csv"
    _record().to_csv(rig, index=False)
    js, csv = tmp_path / "shift.json", tmp_path / "shift.csv"
    common = ["control", "shift", str(rig), "--offgoing", "c1", "--oncoming", "c2", "--shaft", "out",
              "--engine", "engine", "--threshold", str(THR), "--radius", "300 mm"]
    assert main([*common, "-o", str(js)]) == 0
    doc = json.loads(js.read_text())
    assert doc["metrics"]["acceleration_dip_m_s2"] == pytest.approx(D * 0.3, rel=1e-6)
    assert doc["metrics"]["flare_rad_s"] == 0.0
    assert "lock-up at" in capsys.readouterr().out
    assert main([*common, "-o", str(csv), "--settle", "100 ms", "--start", "0.2 s"]) == 0
    table = pd.read_csv(csv, comment="#").set_index("metric")
    assert table.loc["jerk_peak_m_s3", "unit"] == "m_s3" and table.loc["shift_time_s", "value"] == pytest.approx(
        0.5 - 0.2 * THR - 0.2, abs=2 * H)
    before = js.read_text()
    line = one_line_error(capsys, [*common, "-o", str(js), "--plot", str(tmp_path / "s.png")])   # (exists: --force)
    assert "exists" in line and js.read_text() == before and not (tmp_path / "s.png").exists()
    assert main([*common, "-o", str(js), "--plot", str(tmp_path / "s.png"), "--force"]) == 0
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    line = one_line_error(capsys, [*common[:-2], "--radius", "3 s", "-o", str(tmp_path / "x.json")])
    assert "--radius" in line and not (tmp_path / "x.json").exists()
    line = one_line_error(capsys, [*common[:6], "c9", *common[7:], "-o", str(tmp_path / "y.json")])
    assert f"{rig}: no column 'c9.tau_Nm'" in line and not (tmp_path / "y.json").exists()   # (the file named)
    line = one_line_error(capsys, ["control", "shift", str(tmp_path / "rig.xlsx"), "--offgoing", "c1", "--oncoming",
                                   "c2", "--shaft", "out"])
    assert "expected a driveline description (.toml) or a record (.csv, .parquet, .mf4)" in line
    line = one_line_error(capsys, ["control", "shift", str(tmp_path / "rig.mf4"), "--offgoing", "c1", "--oncoming",
                                   "c2", "--shaft", "out"])
    assert "rig.mf4: no such file" in line
    line = one_line_error(capsys, ["control", "shift", "examples/driveline_dct_upshift.toml", "--offgoing", "c1",
                                   "--oncoming", "c2", "--shaft", "wheels", "--rate", "1 kHz"])
    assert "--channel-map, --rate and --dbc read a record" in line


def test_the_shift_figure_shades_the_phases_and_marks_the_dip():
    from clutchlab.control.plots import shift_figure

    q = shift_quality(_record(), offgoing="c1", oncoming="c2", output="out", engine="engine", threshold=THR)
    fig = shift_figure(q, title="t")
    for ax in fig.axes:
        spans = [p for p in ax.patches]
        assert len(spans) == 2                               # the torque phase and the inertia phase
        box = spans[0].get_window_extent(fig.canvas.get_renderer()).transformed(ax.transData.inverted())
        assert (box.x0, box.x1) == pytest.approx((q.start_s, q.handover_s), abs=1e-9)
    labels = [line.get_label() for line in fig.axes[2].get_lines()]
    assert labels[0] == "acceleration" and labels[2].startswith("dip 1.5")
    np.testing.assert_allclose(fig.axes[0].get_lines()[0].get_ydata().max(), (300.0 + FLARE) * 30.0 / math.pi,
                               rtol=1e-9)   # the engine in rpm
    assert list(q.trace.columns[:3]) == ["time_s", "acceleration_rad_s2", "jerk_rad_s3"]


@settings(max_examples=examples(25), deadline=None)
@given(torque=st.floats(1.0, 5e3), slip=st.floats(1.0, 500.0), t1=st.floats(0.05, 0.5),
       torque_phase=st.floats(0.02, 0.3), inertia_phase=st.floats(0.05, 0.6), threshold=st.floats(0.005, 0.2),
       h=st.sampled_from([1e-4, 5e-4, 1e-3]))
def test_the_phases_of_any_designed_upshift_are_found_within_their_bounds(torque, slip, t1, torque_phase,
                                                                          inertia_phase, threshold, h):
    """Random linear hand-overs and slip ramps: each instant lies within the threshold's share of its ramp and one
    sample of the true one, on the side the threshold puts it, and the on-coming clutch's heat is the closed form
    over the detected window to the trapezoid rule's error on one kink."""
    t2, t3 = t1 + torque_phase, t1 + torque_phase + inertia_phase
    t = np.arange(0.0, t3 + 0.3, h)
    ramp = np.clip((t - t1) / torque_phase, 0.0, 1.0)
    w_on = slip * np.clip(1.0 - (t - t2) / inertia_phase, 0.0, 1.0)
    frame = pd.DataFrame({"time_s": t, "c1.tau_Nm": torque * (1.0 - ramp), "c2.tau_Nm": torque * ramp,
                          "c1.w_rel_rad_s": np.zeros_like(t), "c2.w_rel_rad_s": w_on, "out.w_rad_s": 3.0 * t})
    q = shift_quality(frame, offgoing="c1", oncoming="c2", output="out", threshold=threshold)
    eps = 1e-9
    assert t1 + threshold * torque_phase - eps <= q.start_s <= t1 + threshold * torque_phase + h + eps
    assert t2 - threshold * torque_phase - eps <= q.handover_s <= t2 - threshold * torque_phase + h + eps
    assert t3 - threshold * inertia_phase - eps <= q.lockup_s <= t3 - threshold * inertia_phase + h + eps
    assert q.order == "upshift" and q.metrics["acceleration_dip_rad_s2"] == pytest.approx(0.0, abs=1e-6)
    assert q.metrics["lockup_slip_rate_rad_s2"] == pytest.approx(slip / inertia_phase, rel=1e-6)

    def heat(a, b):   # integral of torque * ramp * w_on from a to b (a in the torque phase, b in the inertia phase)
        up = torque * slip * ((t2 - t1) ** 2 - (a - t1) ** 2) / (2 * torque_phase)
        down = torque * slip * ((b - t2) - (b - t2) ** 2 / (2 * inertia_phase))
        return up + down

    kink = torque * slip * h   # (the trapezoid's error over the interval holding the hand-over's kink)
    assert q.metrics["oncoming_energy_J"] == pytest.approx(heat(q.start_s, q.lockup_s), abs=kink)


def test_a_rig_s_mdf_log_through_a_channel_map_gives_the_record_s_metrics(tmp_path, capsys):
    """The designed record as a rig logs it (MDF 4, the logger's names, rpm, km/h): read through a channel map into
    clutchlab's names and SI units, with the vehicle's speed in m/s as the output, the metrics are those of the
    record in rad/s with the tyre's radius, to the unit conversions' rounding."""
    from clutchlab.cli import main
    from clutchlab.io import read_measurement
    from clutchlab.io.mdf import write_mdf

    f, r, rpm = _record(), 0.3, 30.0 / math.pi
    channels = {"T_K1": f["c1.tau_Nm"], "T_K2": f["c2.tau_Nm"], "dn_K1": rpm * f["c1.w_rel_rad_s"],
                "dn_K2": rpm * f["c2.w_rel_rad_s"], "n_mot": rpm * f["engine.w_rad_s"],
                "v_fzg": 3.6 * r * f["out.w_rad_s"]}
    units = {"T_K1": "Nm", "T_K2": "Nm", "dn_K1": "rpm", "dn_K2": "rpm", "n_mot": "rpm", "v_fzg": "km/h"}
    log = write_mdf(tmp_path / "rig.mf4", f["time_s"].to_numpy(), {k: np.asarray(v) for k, v in channels.items()},
                    units, comment="synthetic: the designed record of tests/control_design/test_shift.py")
    names = {"c1.tau_Nm": "T_K1", "c2.tau_Nm": "T_K2", "c1.w_rel_rad_s": "dn_K1", "c2.w_rel_rad_s": "dn_K2",
             "engine.w_rad_s": "n_mot", "vehicle.v_m_s": "v_fzg"}
    (tmp_path / "map.toml").write_text("".join(f'[channels."{k}"]\nsource = "{v}"\n\n' for k, v in names.items()))
    ref = shift_quality(f, offgoing="c1", oncoming="c2", output="out", engine="engine", radius=r, threshold=THR)
    rec = read_measurement(log, tmp_path / "map.toml")
    q = shift_quality(rec, offgoing="c1", oncoming="c2", output="vehicle.v_m_s", engine="engine", threshold=THR)
    assert (q.start_s, q.handover_s, q.lockup_s) == (ref.start_s, ref.handover_s, ref.lockup_s)
    for k, v in ref.metrics.items():
        assert q.metrics[k] == pytest.approx(v, rel=1e-6, abs=1e-9), k   # (the jerk: a second difference)
    with pytest.raises(ParameterError, match="is a speed in m/s: give no radius"):
        shift_quality(rec, offgoing="c1", oncoming="c2", output="vehicle.v_m_s", radius=r)
    out = tmp_path / "shift.json"
    assert main(["control", "shift", str(log), "--channel-map", str(tmp_path / "map.toml"), "--rate", "10 kHz",
                 "--offgoing", "c1", "--oncoming", "c2", "--shaft", "vehicle.v_m_s", "--threshold", str(THR),
                 "-o", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["metrics"]["acceleration_dip_m_s2"] == pytest.approx(D * r, rel=1e-6)
    assert doc["lockup_s"] == pytest.approx(ref.lockup_s, abs=1e-9)
    capsys.readouterr()


@pytest.mark.parametrize("release", ["in time", "late", "early"])
def test_a_late_release_ties_up_and_an_early_one_flares_in_the_dual_clutch_upshift(tmp_path, release):
    """The example's upshift with the off-going clutch's release moved: released late (over 0.75-0.87 s, after the
    on-coming clutch has taken the torque) it brakes the engine against the on-coming one, a tie-up of more than
    100 N m and no flare; released early (over 0.3-0.42 s, before the on-coming one is applied) the engine runs up
    free, a flare of more than 30 rad/s and no tie-up; the example's own timing has neither beyond a few percent of
    the drive."""
    text = (ROOT / "examples" / "driveline_dct_upshift.toml").read_text()
    times = {"in time": "[0.0, 0.5, 0.62]", "late": "[0.0, 0.75, 0.87]", "early": "[0.0, 0.3, 0.42]"}[release]
    text = text.replace("normal = { table = { times = [0.0, 0.5, 0.62], values = [1.0, 1.0, 0.0] } }",
                        f"normal = {{ table = {{ times = {times}, values = [1.0, 1.0, 0.0] }} }}")
    (tmp_path / "dct.toml").write_text(text)
    from clutchlab.driveline.description import load_driveline

    spec = load_driveline(tmp_path / "dct.toml")
    res = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, output_step=spec.output_step)
    q = shift_quality(res, offgoing="c1", oncoming="c2", output="wheels", engine="engine", radius=0.3)
    m = q.metrics
    if release == "late":
        assert m["tie_up_Nm"] > 100.0 and m["flare_rad_s"] < 5.0
    elif release == "early":
        assert m["flare_rad_s"] > 30.0 and m["tie_up_Nm"] < 1.0
    else:
        assert m["tie_up_Nm"] < 20.0 and m["flare_rad_s"] < 6.0


def test_the_file_s_shift_table_feeds_the_command_line_and_the_sweep_s_shift_outputs(tmp_path, capsys):
    """The example's [shift] table: `clutchlab control shift FILE` needs no names, and the driveline sweep's
    `shift.<metric>` outputs over the off-going clutch's release stretched in time (its table's time_scale) equal
    shift_quality of each variant's own run; released early (0.6) it flares, late (1.3) it ties up."""
    import tomllib

    from cli_checks import one_line_error

    from clutchlab.cli import main
    from clutchlab.driveline.description import load_driveline, parse_driveline
    from clutchlab.driveline.variants import DrivelineDocument
    from clutchlab.sweep import driveline as S

    path = ROOT / "examples" / "driveline_dct_upshift.toml"
    spec = load_driveline(path)
    assert spec.shift == {"offgoing": "c1", "oncoming": "c2", "output": "wheels", "engine": "engine", "radius": 0.3}
    out = tmp_path / "shift.json"
    png = tmp_path / "shift.png"
    assert main(["control", "shift", str(path), "-o", str(out), "--plot", str(png)]) == 0   # (names from the file)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()
    ref = shift_quality(spec.driveline.simulate(spec.t_end, rtol=spec.rtol, output_step=spec.output_step),
                        **spec.shift)
    assert json.loads(out.read_text())["metrics"]["jerk_peak_m_s3"] == pytest.approx(ref.metrics["jerk_peak_m_s3"],
                                                                                    rel=1e-12)
    scenario = {**tomllib.loads(path.read_text()), "_source": str(path)}
    described = S.describe(scenario)["outputs"]
    assert described["shift.tie_up_Nm"] == "N*m" and "shift.jerk_peak_m_s3" in described
    outputs = ["shift.flare_rad_s", "shift.tie_up_Nm", "shift.jerk_peak_m_s3", "shift.shift_time_s", "status"]
    variants = pd.DataFrame({"c1.normal.time_scale": [0.6, 1.0, 1.3]}).rename_axis("variant_id")
    got = S.run_batch(variants, scenario, outputs)
    doc = DrivelineDocument(scenario, scenario["_source"])
    for vid, row in variants.iterrows():
        one = doc.load(row.to_dict())
        q = shift_quality(one.driveline.simulate(one.t_end, rtol=one.rtol, output_step=one.output_step),
                          **one.shift)
        for name in outputs[:-1]:
            assert got.loc[vid, name] == pytest.approx(q.metrics[name.removeprefix("shift.")], rel=1e-6, abs=1e-9)
    assert got.loc[0, "shift.flare_rad_s"] > 30.0 and got.loc[2, "shift.tie_up_Nm"] > 100.0
    # the table's refusals, naming the file and the key
    text = tomllib.loads(path.read_text())
    for change, message in (({"offgoing": "c9"}, "shift.offgoing = 'c9': expected the name of a friction element"),
                            ({"output": "c1"}, "shift.output = 'c1': expected the name of an inertia"),
                            ({"radius": "3 s"}, "shift.radius"), ({"gear": 2}, "shift.gear: unknown field")):
        bad = {**text, "shift": {**text["shift"], **change}}
        with pytest.raises(ParameterError, match=message):
            parse_driveline(bad, "dct.toml")
    line = one_line_error(capsys, ["control", "shift", str(ROOT / "examples" / "driveline_coupled_clutches.toml")])
    assert "give --offgoing, --oncoming, --shaft (or a [shift] table in the driveline file)" in line
