"""The AMT's transmission controller (clutchlab.control.AmtController) on the AMT example with its inputs as ports:
the sequence of a gear command, the phases that wait on the synchronisers, the cone's torque while it synchronises,
and the refusals."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples, pinned

from cli_checks import one_line_error
from clutchlab.cli import main
from clutchlab.control import AmtController, AmtGear, closed_loop, shift_quality
from clutchlab.driveline import Signal
from clutchlab.driveline.description import load_driveline, parse_driveline
from clutchlab.errors import ParameterError, SimulationError

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "driveline_amt_tcu.toml"   # the same network with its inputs and [tcu] in the file
H = 1e-3                                           # the controller's sample time [s]
GEARS = {1: AmtGear("s1", "fork", 1, ratio=3.5), 2: AmtGear("s2", "fork", -1, ratio=2.0)}
FORK, MU, R_C, ALPHA = 600.0, 0.1, 0.045, math.radians(6.5)   # the example's synchronisers
RECORD = ["s2.tau", "input_shaft.w", "output_shaft.w", "energy_error", "input_work"]
J_E, DRAG, TORQUE_MAX = 0.2, -30.0, 250.0          # the engine's inertia [kg m^2], the drag and full load [N m]
#: the example file's speed matching (its [tcu] table)
MATCH = dict(speed_match=20.0, engine_speed="engine.w", output_speed="output_shaft.w", torque_max=TORQUE_MAX)


@pytest.fixture(scope="module")
def amt():
    """The AMT example with its engine torque, clutch factor and shift fork as network inputs (its own tables
    replaced by ports: ``Driveline.replace``)."""
    d = load_driveline(ROOT / "examples" / "driveline_amt_upshift.toml").driveline.without()
    d.input("torque_command", unit="Nm", start=150.0).input("clutch_command", unit="1", start=1.0)
    d.input("fork", unit="N", start=FORK)
    d = (d.replace("engine_torque", signal=Signal.input("torque_command"))
         .replace("clutch", normal=Signal.input("clutch_command"))
         .replace("s1", force=Signal.input("fork")).replace("s2", force=Signal.input("fork")))
    return d.system(1e-8)


def _tcu(commands, **kw):
    return AmtController(GEARS, 1, commands, clutch_input="clutch_command", torque_input="torque_command",
                         torque=150.0, drag=DRAG, fork_force=kw.pop("fork_force", FORK), **kw)


def _run(system, tcu, t_end, record=()):
    measure = list(tcu.measured) + [c for c in (*RECORD, *record) if c not in tcu.measured]
    return closed_loop(system, tcu, H, t_end, measure=measure, actuate=list(tcu.actuated))


def _event(res, element, event):
    ev = res.events
    return ev.time_s[(ev.element == element) & (ev.event == event)].to_numpy()


def test_a_gear_command_shifts_up_and_down_waiting_on_the_synchronisers(amt):
    """An upshift at 0.4 s and a downshift at 2.2 s: the phases in order; the ramps take their durations (to a
    sample); the sleeve goes in once the off-going synchroniser is free, and the clutch closes once the on-coming one
    is engaged, each within one sample of the network's event; while it synchronises the cone carries
    ``mu F R_c / sin(alpha)``; the gears' ratios after each shift; the energy balance."""
    tcu = _tcu([(0.4, 2), (2.2, 1)])
    res = _run(amt, tcu, 3.5)
    ph = tcu.phases
    shift = ["torque_down", "clutch_open", "neutral", "synchronise", "clutch_close", "drive"]
    assert list(ph.phase) == ["drive"] + shift + shift
    assert list(ph.gear) == [1] + [2] * 6 + [1] * 6
    t = dict()
    for k, (name, gear) in enumerate(zip(ph.phase, ph.gear)):
        t[(name, gear)] = ph.time_s[k]
    for gear, off, on in ((2, "s1", "s2"), (1, "s2", "s1")):
        assert abs(t[("clutch_open", gear)] - t[("torque_down", gear)] - tcu.torque_down) <= H + 1e-12
        assert abs(t[("neutral", gear)] - t[("clutch_open", gear)] - tcu.clutch_open) <= H + 1e-12
        assert abs(t[("drive", gear)] - t[("clutch_close", gear)] - tcu.clutch_close) <= H + 1e-12
        free = _event(res, off, "free")
        free = free[free > t[("neutral", gear)]][0]
        assert 0.0 < t[("synchronise", gear)] - free <= H + 1e-12
        stick = _event(res, on, "stick")
        stick = stick[stick > t[("synchronise", gear)]][0]
        assert 0.0 < t[("clutch_close", gear)] - stick <= H + 1e-12
    df = res.frame
    at = df.set_index(np.round(df.time_s / H).astype(int))
    sync = at.loc[int(round((t[("synchronise", 2)] + tcu.fork_ramp) / H)) + 5]
    assert sync["s2.tau_Nm"] == pytest.approx(-MU * FORK * R_C / math.sin(ALPHA), rel=1e-9)  # (on flange a: -T_c)
    assert sync["fork_N"] == -FORK and sync["clutch_command_1"] == 0.0 and sync["torque_command_Nm"] == -30.0
    for time, ratio in ((0.39, 3.5), (2.1, 2.0), (3.5, 3.5)):
        row = at.loc[int(round(time / H))]
        assert row["input_shaft.w_rad_s"] / row["output_shaft.w_rad_s"] == pytest.approx(ratio, rel=1e-9)
    assert at.loc[int(round(2.1 / H))]["fork_N"] == -FORK and at.loc[390]["fork_N"] == FORK
    assert np.abs(df["energy_error_J"]).max() < 1e-6 * df["input_work_J"].abs().max()


def test_the_clutch_waits_for_a_slower_synchronisation(amt):
    """A quarter of the fork's force: the cone's torque is a quarter, so the input shaft takes about four times as
    long to reach 2nd's speed (its inertia against the vehicle's, some 130 times larger on that shaft), and the
    clutch still closes only once 2nd is in, within one sample."""
    times = {}
    for force in (FORK, FORK / 4):
        tcu = _tcu([(0.4, 2)], fork_force=force)
        res = _run(amt, tcu, 2.0)
        ph = tcu.phases.set_index("phase").time_s
        stick = _event(res, "s2", "stick")[0]
        assert 0.0 < ph["clutch_close"] - stick <= H + 1e-12
        # (the push rises over its ramp, held a sample at a time: the ramp loses about half its length)
        times[force] = stick - (ph["synchronise"] + 0.5 * tcu.fork_ramp)
    assert times[FORK / 4] / times[FORK] == pytest.approx(4.0, rel=0.02)


def test_the_controller_s_shift_is_measured_as_the_schedule_s_and_interrupts_the_drive_for_less(amt):
    """``shift_quality`` reads the closed loop's record as it reads a run (the same column names): the gear is in
    where 2nd engages, and since the controller closes the clutch as soon as it is, the drive is interrupted for less
    than under the example's schedule, which waits to 1.05 s whatever the cone does."""
    tcu = _tcu([(0.4, 2)])
    cols = ["clutch.tau", "clutch.w_rel", "s1.tau", "s1.w_rel", "s2.tau", "s2.w_rel", "wheels.w", "engine.w"]
    res = closed_loop(amt, tcu, H, 2.0, measure=list(tcu.measured) + cols, actuate=list(tcu.actuated))
    how = dict(clutch="clutch", offgoing="s1", oncoming="s2", output="wheels", engine="engine", radius=0.3, start=0.4)
    q = shift_quality(res.frame, **how)
    schedule = load_driveline(ROOT / "examples" / "driveline_amt_upshift.toml").driveline
    ref = shift_quality(schedule.simulate(2.0, rtol=1e-8, output_step=H).to_dataframe(), **how)
    assert (q.kind, q.order) == ("interrupted", "upshift")
    # (an interrupted shift's lock-up: the gear in, where the slip is within its threshold on the 1 ms samples)
    assert abs(q.lockup_s - _event(res, "s2", "stick")[0]) <= 2 * H
    assert q.metrics["torque_interruption_s"] < 0.6 * ref.metrics["torque_interruption_s"]
    assert q.metrics["shift_time_s"] < ref.metrics["shift_time_s"] - 0.1


SHIFT_COLUMNS = ["clutch.tau", "clutch.w_rel", "s1.tau", "s1.w_rel", "s2.tau", "s2.w_rel", "wheels.w", "engine.w"]


def _phase_at(phases, t):
    """The phase and selected gear of each sample time ``t`` (a phase entered at a sample holds from that sample)."""
    k = np.searchsorted(phases.time_s.to_numpy(), t, side="right") - 1
    return phases.phase.to_numpy()[k], phases.gear.to_numpy()[k]


def test_speed_matching_blips_the_engine_to_the_new_gear_s_speed_on_the_downshift(amt):
    """``speed_match``: while the clutch is open the engine's torque is ``clip(k (ratio w_out - w_e), drag,
    torque_max)`` of the speeds measured at that sample (read back from the record), and the engine, free of the
    open clutch, integrates it: ``J_e (w_e[k+1] - w_e[k]) / h = T_k`` over each held sample (the network's solution
    against the closed form of an inertia under a held torque); while the clutch closes (its factor ``s``) the torque
    is ``(1 - s)`` the matching's and ``s`` the demand.  On the downshift the blip brings the engine to 1st's
    speed before the clutch closes: it closes with under 10 rad/s of slip (257 rad/s at the drag), the clutch's heat
    falls from 4.6 kJ to under 1 % of it, the jerk and the shift time by a third or more; on the upshift the engine at
    its drag does not come down to 2nd's speed before the clutch closes, and the shift is the one without (heat
    within 0.1 %)."""
    runs, quality, phases = {}, {}, {}
    how = dict(clutch="clutch", output="wheels", engine="engine", radius=0.3)
    for name, kw in (("drag", {}), ("match", MATCH)):
        tcu = _tcu([(0.4, 2), (2.2, 1)], **kw)
        runs[name] = res = _run(amt, tcu, 3.5, record=SHIFT_COLUMNS)
        quality[name] = {q.order: q for q in tcu.shift_quality(res.frame, **how)}
        phases[name] = tcu.phases
    df = runs["match"].frame
    t = df.time_s.to_numpy()
    phase, gear = _phase_at(phases["match"], t)
    w_e, w_out = df["engine.w_rad_s"].to_numpy(), df["output_shaft.w_rad_s"].to_numpy()
    torque = df["torque_command_Nm"].to_numpy()
    ratio = np.where(gear == 1, 3.5, 2.0)
    open_ = np.isin(phase, ["neutral", "synchronise"])
    law = np.clip(MATCH["speed_match"] * (ratio * w_out - w_e), DRAG, TORQUE_MAX)
    assert open_.sum() > 250
    np.testing.assert_allclose(torque[open_], law[open_], rtol=1e-12, atol=1e-12)
    assert torque.min() == DRAG and torque.max() == TORQUE_MAX   # (both limits reached: the drag and the blip)
    closing, factor = phase == "clutch_close", df["clutch_command_1"].to_numpy()   # (blended into the demand)
    np.testing.assert_allclose(torque[closing], ((1.0 - factor) * law + factor * 150.0)[closing], rtol=1e-12,
                               atol=1e-12)
    free = np.flatnonzero(df["clutch_command_1"].to_numpy()[:-1] == 0.0)   # (the clutch open over [t_k, t_k+1])
    accel = J_E * np.diff(w_e)[free] / np.diff(t)[free]
    np.testing.assert_allclose(accel, torque[free], rtol=0, atol=1e-7)   # (2e-11 N m measured)
    for name, slip in (("match", (0.0, 10.0)), ("drag", (200.0, 300.0))):
        ph = phases[name]
        closes = ph.time_s[(ph.phase == "clutch_close") & (ph.gear == 1)].iloc[0]
        row = runs[name].frame.set_index(np.round(runs[name].frame.time_s / H).astype(int)).loc[round(closes / H)]
        assert slip[0] <= abs(row["clutch.w_rel_rad_s"]) <= slip[1], name
    down, ref = quality["match"]["downshift"].metrics, quality["drag"]["downshift"].metrics
    assert ref["clutch_energy_J"] > 4000.0 and down["clutch_energy_J"] < 0.01 * ref["clutch_energy_J"]
    assert down["jerk_peak_m_s3"] < 0.5 * ref["jerk_peak_m_s3"]
    assert down["shift_time_s"] < 0.67 * ref["shift_time_s"]
    up, ref = quality["match"]["upshift"].metrics, quality["drag"]["upshift"].metrics
    assert up["clutch_energy_J"] == pytest.approx(ref["clutch_energy_J"], rel=1e-3)


@settings(max_examples=examples(8), deadline=None, derandomize=pinned())
@given(st.lists(st.tuples(st.floats(0.05, 2.0), st.sampled_from([1, 2])), min_size=1, max_size=3),
       st.floats(300.0, 1200.0), st.booleans())
def test_the_controller_never_closes_the_clutch_onto_neutral_whatever_the_commands(amt, commands, force, match):
    """Random gear commands (up to three, at random times, some of the gear engaged) and fork forces: the phases keep
    their order and each shift ends in the gear it selected; wherever the clutch's factor is above 0 a gear is in
    (a synchroniser engaged at that sample and the next: the clutch never closes onto a gearbox in neutral); the fork
    pushes only towards the gear a shift leaves or the one it selects; the run ends in the last gear commanded; the
    energy balance holds.  (A synchronisation here takes at most about 0.45 s: the input shaft's 0.017 kg m^2 over
    at most 300 rad/s under at least a 300 N fork's 12 N m; the timeout is not what is tested.)"""
    tcu = _tcu(commands, fork_force=force, sync_timeout=2.0, **(MATCH if match else {}))
    res = _run(amt, tcu, 5.0)
    ph = tcu.phases
    cycle = ["drive", "torque_down", "clutch_open", "neutral", "synchronise", "clutch_close"]
    assert [cycle.index(p) for p in ph.phase] == [k % 6 for k in range(len(ph))]
    assert ph.phase.iloc[-1] == "drive" and ph.gear.iloc[-1] == sorted(commands, key=lambda c: c[0])[-1][1]
    df = res.frame
    engaged = ((df["s1.mode_1"] == 0.0) | (df["s2.mode_1"] == 0.0)).to_numpy()
    closing = (df["clutch_command_1"] > 0.0).to_numpy()
    assert np.all(engaged[closing]) and np.all(engaged[1:][closing[:-1]])
    fork = df["fork_N"].to_numpy()
    assert np.all(np.abs(fork) <= force * (1.0 + 1e-12))
    torque = df["torque_command_Nm"].to_numpy()   # (the speed matching within its limits, the drag without it)
    assert torque.min() >= DRAG and torque.max() <= (TORQUE_MAX if match else 150.0)
    pushed = np.select([fork > 0.0, fork < 0.0], [1, 2], 0)   # the gear the fork pushes towards (0: neither)
    t = df.time_s.to_numpy()
    left = 1                                                   # the gear of the last drive phase
    for k, (t0, phase, gear) in enumerate(zip(ph.time_s, ph.phase, ph.gear)):
        t1 = ph.time_s.iloc[k + 1] if k + 1 < len(ph) else np.inf
        assert set(pushed[(t >= t0) & (t < t1)]) <= {0, left, gear}, (phase, t0)
        if phase == "drive":
            left = gear
    assert np.abs(df["energy_error_J"]).max() < 1e-6 * df["input_work_J"].abs().max()


def test_each_shift_of_a_run_is_listed_and_measured_with_its_own_synchronisers(amt):
    """``AmtController.shifts``: one row per shift (its command, its return to drive, the gears and synchronisers it
    leaves and selects; a shift the run cut short has no end); ``AmtController.shift_quality``: each shift that ended,
    measured on the record between its neighbours with its own synchronisers and its command as its start (the
    upshift's equals ``shift_quality`` on the record up to the downshift); the shift's own names are refused."""
    tcu = _tcu([(0.4, 2), (2.2, 1)])
    cols = ["clutch.tau", "clutch.w_rel", "s1.tau", "s1.w_rel", "s2.tau", "s2.w_rel", "wheels.w", "engine.w"]
    res = closed_loop(amt, tcu, H, 2.6, measure=list(tcu.measured) + cols, actuate=list(tcu.actuated))
    shifts = tcu.shifts
    assert list(shifts.columns) == ["start_s", "end_s", "from_gear", "to_gear", "offgoing", "oncoming"]
    assert shifts[["start_s", "from_gear", "to_gear", "offgoing", "oncoming"]].values.tolist() == [
        [0.4, 1, 2, "s1", "s2"], [2.2, 2, 1, "s2", "s1"]]
    assert shifts.end_s[0] == pytest.approx(1.33, abs=1e-12) and math.isnan(shifts.end_s[1])   # (cut at 2.6 s)
    how = dict(clutch="clutch", output="wheels", engine="engine", radius=0.3)
    (up,) = tcu.shift_quality(res.frame, **how)
    ref = shift_quality(res.frame[res.frame.time_s < 2.2], offgoing="s1", oncoming="s2", start=0.4, **how)
    assert up.metrics == ref.metrics and (up.start_s, up.lockup_s, up.end_s) == (ref.start_s, ref.lockup_s, ref.end_s)
    with pytest.raises(ParameterError, match="offgoing, start come from each shift"):
        tcu.shift_quality(res.frame, offgoing="s1", start=0.4, **how)
    with pytest.raises(ParameterError, match="give clutch"):
        tcu.shift_quality(res.frame, output="wheels")


def test_a_synchronisation_that_cannot_finish_stops_the_run(amt):
    with pytest.raises(SimulationError, match=r"s2 has not engaged gear 2 within sync_timeout = 0\.2 s of the push"):
        _run(amt, _tcu([(0.4, 2)], fork_force=5.0, sync_timeout=0.2), 2.0)


def test_a_command_of_the_gear_engaged_is_no_shift_and_a_new_run_starts_again(amt):
    tcu = _tcu([(0.2, 1)])
    res = _run(amt, tcu, 0.5)
    assert list(tcu.phases.phase) == ["drive"] and (res.frame["fork_N"] == FORK).all()
    tcu = _tcu([(0.4, 2)])
    _run(amt, tcu, 1.2)
    first = tcu.phases
    _run(amt, tcu, 1.2)
    assert tcu.phases.equals(first)


@pytest.mark.parametrize("change, message", [
    (dict(start_gear=3), r"start_gear = 3 is not among the gears \[1, 2\]"),
    (dict(commands=[(0.4, 5)]), r"the command at 0\.4 s selects gear 5"),
    (dict(commands=[0.4]), r"a command 0\.4 must be \(time \[s\], gear\)"),
    (dict(commands=[("soon", 2)]), r"the command \('soon', 2\): its time must be a finite number"),
    (dict(drag=10.0), r"drag = 10\.0 must be finite and <= 0"),
    (dict(torque=math.nan), r"AmtController: torque = nan must be a finite number"),
    (dict(clutch_open=0.0), r"clutch_open = 0\.0 must be finite and > 0"),
    (dict(fork_force=float("nan")), r"fork_force = nan must be finite and > 0"),
    (dict(gears={1: AmtGear("s1", "fork"), 2: AmtGear("s1", "fork", -1)}), r"two gears share a synchroniser"),
    (dict(speed_match=-1.0), r"speed_match = -1\.0 must be finite and >= 0"),
    (dict(speed_match=20.0, output_speed="output_shaft.w"), r"speed_match = 20\.0 needs engine_speed, the name of "
                                                            r"an output \(got None\)"),
    (dict(MATCH, gears={1: AmtGear("s1", "fork"), 2: AmtGear("s2", "fork", -1, 2.0)}),
     r"speed_match needs every gear's ratio; gear\(s\) \[1\] have none"),
    (dict(MATCH, torque_max=-5.0), r"torque_max = -5\.0 must be finite and >= 0"),
])
def test_bad_settings_are_refused_naming_them(change, message):
    kw = dict(gears=GEARS, start_gear=1, commands=[(0.4, 2)], clutch_input="clutch_command",
              torque_input="torque_command", torque=150.0, drag=-30.0)
    kw.update(change)
    with pytest.raises(ParameterError, match=message):
        AmtController(**kw)
    with pytest.raises(ParameterError, match="side = 0 must be 1 or -1"):
        AmtGear("s1", "fork", 0)
    with pytest.raises(ParameterError, match="ratio = 0 must be a finite number, not 0"):
        AmtGear("s1", "fork", 1, 0)


def test_the_file_s_controller_runs_from_the_command_line_as_the_python_one(amt, tmp_path, capsys):
    """``clutchlab control tcu`` on ``examples/driveline_amt_tcu.toml`` (its inputs declared as ports, its [tcu]
    table the controller above): the same phases, the same run to rounding, the network's events, the upshift's
    quality from its [shift] table (the record up to the downshift's command); nothing is overwritten without
    --force."""
    out, phases, events = tmp_path / "run.csv", tmp_path / "phases.csv", tmp_path / "events.csv"
    quality = tmp_path / "quality.json"
    argv = ["control", "tcu", str(EXAMPLE), "-o", str(out), "--phases", str(phases), "--events", str(events),
            "--quality", str(quality)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "13 phases of AmtController" in printed and "upshift (interrupted) from 0.4000 s" in printed
    assert "downshift (interrupted) from 2.2000 s" in printed   # (every shift's quality, its own synchronisers)
    report = __import__("json").loads(quality.read_text())
    assert [(q["order"], q["start_s"], q["columns"]["offgoing"], q["columns"]["oncoming"]) for q in report] == [
        ("upshift", 0.4, "s1", "s2"), ("downshift", 2.2, "s2", "s1")]
    tcu = _tcu([(0.4, 2), (2.2, 1)], **MATCH)
    res = _run(amt, tcu, 3.5)
    got = pd.read_csv(phases)
    assert list(got.phase) == list(tcu.phases.phase) and list(got.gear) == list(tcu.phases.gear)
    np.testing.assert_allclose(got.time_s, tcu.phases.time_s, rtol=0, atol=1e-12)
    run = pd.read_csv(out)
    for col in ("input_shaft.w_rad_s", "s2.tau_Nm", "fork_N", "clutch_command_1", "torque_command_Nm"):
        np.testing.assert_allclose(run[col], res.frame[col], rtol=1e-8, atol=1e-9)   # (the CSV's 9 digits)
    assert {"s1.mode_1", "s2.mode_1", "wheels.w_rad_s", "energy_error_J"} <= set(run.columns)
    ev = pd.read_csv(events)
    assert list(ev.event[ev.element == "s2"]) == list(res.events.event[res.events.element == "s2"])
    assert main(argv) != 0 and "--force" in capsys.readouterr().err


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.update(extra=1), r"tcu\.extra: unknown field"),
    (lambda t: t.pop("torque"), r"\[tcu\]: missing field 'torque'"),
    (lambda t: t["gears"]["2"].update(synchronizer="clutch"), r"tcu\.gears\.2\.synchronizer = 'clutch': expected a "
                                                               r"synchronizer of the network \(s1, s2\)"),
    (lambda t: t["gears"]["2"].update(fork="fork2"), r"tcu\.gears\.2\.fork = 'fork2': expected a network input"),
    (lambda t: t["gears"]["2"].update(side=2), r"tcu\.gears\.2\.side = 2: expected 1 or -1"),
    (lambda t: t["gears"].update(x=t["gears"].pop("2")), r"tcu\.gears\.x = 'x': expected a gear's number"),
    (lambda t: t.update(commands=[["0.4 s"]]), r"tcu\.commands must be rows \[time, gear\]"),
    (lambda t: t.update(commands=[["0.4 kg", 2]]), r"tcu\.commands\[0\]"),
    (lambda t: t.update(clutch_input="throttle"), r"tcu\.clutch_input = 'throttle': expected a network input"),
    (lambda t: t.update(fork_force="600 N m"), r"tcu\.fork_force"),
    (lambda t: t["gears"]["1"].update(synchronizer=["s1"]), r"tcu\.gears\.1\.synchronizer = \['s1'\]: expected a "),
    (lambda t: t.update(sample_time="0 ms"), r"tcu\.sample_time = '0 ms': must be > 0"),
    (lambda t: t.update(engine_speed="engine.speed"), r"tcu\.engine_speed = 'engine\.speed': expected a state or "
                                                      r"output of the network, a speed \(engine\.w, input_shaft\.w, "),
    (lambda t: t.update(output_speed=["output_shaft.w"]), r"tcu\.output_speed = \['output_shaft\.w'\]: expected a "),
    (lambda t: t.update(torque_input=["torque_command"]), r"tcu\.torque_input = \['torque_command'\]: expected a "),
    (lambda t: t["gears"]["2"].update(ratio=0), r"tcu\.gears\.2\.ratio = 0: expected the gear's ratio"),
    (lambda t: t["gears"]["2"].update(ratio="2 m"), r"tcu\.gears\.2\.ratio"),
    (lambda t: t.update(speed_match="20 N m"), r"tcu\.speed_match"),
])
def test_a_bad_tcu_table_is_refused_naming_the_file_and_the_field(edit, message, tmp_path, capsys):
    doc = tomllib.loads(EXAMPLE.read_text())
    edit(doc["tcu"])
    with pytest.raises(ParameterError, match=message):
        parse_driveline(doc, "amt.toml")


def test_the_command_line_refuses_a_file_without_a_tcu_and_a_controller_it_cannot_build(tmp_path, capsys):
    line = one_line_error(capsys, ["control", "tcu", str(ROOT / "examples" / "driveline_amt_upshift.toml")])
    assert "driveline_amt_upshift.toml: no [tcu] table" in line
    bad = tmp_path / "amt.toml"
    bad.write_text(EXAMPLE.read_text().replace('drag = "-30 N m"', 'drag = "30 N m"'))
    line = one_line_error(capsys, ["control", "tcu", str(bad), "-o", str(tmp_path / "run.csv")])
    assert "amt.toml: [tcu] AmtController: drag = 30.0 must be finite and <= 0" in line
    assert not (tmp_path / "run.csv").exists()
    text = EXAMPLE.read_text()
    at = text.index("\n[tcu]")   # (1st's ratio in the controller's table, not the network's gear)
    bad.write_text(text[:at] + text[at:].replace("ratio = 3.5", "# ratio = 3.5"))
    line = one_line_error(capsys, ["control", "tcu", str(bad), "-o", str(tmp_path / "run.csv")])
    assert "amt.toml: [tcu] AmtController: speed_match needs every gear's ratio; gear(s) [1] have none" in line
    assert not (tmp_path / "run.csv").exists()


def test_the_amt_s_demand_may_be_rows_and_its_torque_follows_them(amt):
    """The driver's demand as rows (the DCT controller's :meth:`~clutchlab.control.GearCommand.demand`): held
    constant, the same run as the number, sample for sample; rising from 100 to 150 N m over 0.1-0.3 s before an
    upshift at 0.4 s, the engine's torque is the demand at each sample in gear, the torque's ramp down starts from
    the demand at each sample, and the full-load bound of the speed matching defaults to the largest demand."""
    flat = _tcu([(0.4, 2)], **MATCH)
    rows = AmtController(GEARS, 1, [(0.4, 2)], clutch_input="clutch_command", torque_input="torque_command",
                         torque=[(0.0, 150.0), (5.0, 150.0)], drag=DRAG, fork_force=FORK, **MATCH)
    a, b = _run(amt, flat, 1.2), _run(amt, rows, 1.2)
    assert a.frame.equals(b.frame) and flat.phases.equals(rows.phases)
    demand = [(0.0, 100.0), (0.1, 100.0), (0.3, 150.0)]
    tip = AmtController(GEARS, 1, [(0.4, 2)], clutch_input="clutch_command", torque_input="torque_command",
                        torque=demand, drag=DRAG, fork_force=FORK)
    assert tip.torque_max == 150.0 and tip.demand(0.2) == pytest.approx(125.0)
    res = _run(amt, tip, 1.2)
    df = res.frame
    t = df.time_s.to_numpy()
    first = t < 0.4
    np.testing.assert_allclose(df["torque_command_Nm"].to_numpy()[first], np.interp(t[first], *zip(*demand)),
                               rtol=0, atol=1e-12)
    down = (t >= 0.4) & (t < 0.4 + tip.torque_down)
    ramp = 1.0 - (t[down] - 0.4) / tip.torque_down
    np.testing.assert_allclose(df["torque_command_Nm"].to_numpy()[down], 150.0 * ramp, rtol=0, atol=1e-9)
    with pytest.raises(ParameterError, match=r"AmtController: torque = \[\(0\.0, 1\.0\), \(0\.0, 2\.0\)\] must be"):
        AmtController(GEARS, 1, [(0.4, 2)], clutch_input="clutch_command", torque_input="torque_command",
                      torque=[(0.0, 1.0), (0.0, 2.0)], drag=DRAG)
