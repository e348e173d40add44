"""The dual-clutch transmission's controller (clutchlab.control.DctController) on the DCT example with its inputs as
ports: the power upshift's hand-over where the off-going clutch's torque reaches zero, the inertia phase against the
closed form of the engine under its torque and the on-coming clutch's, the power-on downshift to the new gear's
speed, the drive never interrupted, and the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples, pinned

from clutchlab.control import DctController, DctGear, closed_loop, shift_quality
from clutchlab.driveline import Signal
from clutchlab.driveline.description import load_driveline
from clutchlab.errors import ParameterError, SimulationError

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
SCHEDULE = ROOT / "examples" / "driveline_dct_upshift.toml"
H = 1e-3                                           # the controller's sample time [s]
GEARS = {1: DctGear("c1", "c1_command", 3.5), 2: DctGear("c2", "c2_command", 2.0)}
J_E, TORQUE = 0.2, 150.0                           # the engine's inertia [kg m^2] and torque [N m]
CAPACITY = 6000.0 * 0.12 * 0.32                    # a clutch's sliding torque at its full normal force [N m]
RECORD = ["c1.w_rel", "c2.w_rel", "wheels.w", "energy_error", "input_work"]
HOW = dict(output="wheels", engine="engine", radius=0.3)


@pytest.fixture(scope="module")
def dct():
    """The DCT example with its engine torque and its two clutches' factors as network inputs (``replace``)."""
    d = load_driveline(SCHEDULE).driveline.without()
    d.input("torque_command", unit="Nm", start=TORQUE).input("c1_command", unit="1", start=1.0)
    d.input("c2_command", unit="1", start=0.0)
    d = (d.replace("engine_torque", signal=Signal.input("torque_command"))
         .replace("c1", normal=Signal.input("c1_command")).replace("c2", normal=Signal.input("c2_command")))
    return d.system(1e-8)


def _tcu(commands, **kw):
    return DctController(GEARS, 1, commands, torque_input="torque_command", torque=TORQUE, engine_speed="engine.w",
                         output_speed="output_shaft.w", **kw)


def _run(system, tcu, t_end):
    measure = list(tcu.measured) + [c for c in RECORD if c not in tcu.measured]
    return closed_loop(system, tcu, H, t_end, measure=measure, actuate=list(tcu.actuated))


def _phase_at(phases, t):
    k = np.searchsorted(phases.time_s.to_numpy(), t, side="right") - 1
    return phases.phase.to_numpy()[k]


def _event(res, element, event):
    ev = res.events
    return ev.time_s[(ev.element == element) & (ev.event == event)].to_numpy()


def test_the_upshift_hands_over_where_the_off_going_clutch_carries_nothing(dct):
    """An upshift at 0.5 s: the off-going c1 stays closed while the on-coming c2 fills and opens at the first sample
    where c1 carries no torque (it carried the drive's sign before), so the two never fight: the tie-up is under a
    tenth of the example's schedule's (14.4 N m), there is no flare, and the shift is no longer.  In the inertia
    phase (c1 open, c2 sliding) the engine, under its held torque and c2's ``u fn_max mu cgeo``, follows the closed
    form ``J_e (w[k+1] - w[k]) / h = T - u C`` sample by sample; the lock comes within a sample of c2's stick; 2nd's
    ratio after; the energy balance."""
    tcu = _tcu([(0.5, 2)])
    res = _run(dct, tcu, 1.3)
    ph = tcu.phases
    assert list(ph.phase) == ["drive", "torque_phase", "inertia_phase", "lock", "drive"]
    df = res.frame
    t = df.time_s.to_numpy()
    phase = _phase_at(ph, t)
    released = ph.time_s[ph.phase == "inertia_phase"].iloc[0]
    k = int(round(released / H))
    tau1 = df["c1.tau_Nm"].to_numpy()
    tau1 = tau1 * np.sign(tau1[int(round(0.5 / H))])   # (in the drive's sign: clutchlab's is flange a's torque)
    assert tau1[k] <= 0.0 < tau1[k - 1] and np.all(tau1[int(round(0.5 / H)):k] > 0.0)
    assert np.all(df["c1_command_1"].to_numpy()[phase == "torque_phase"] == 1.0)
    assert np.all(df["c1_command_1"].to_numpy()[np.isin(phase, ["inertia_phase", "lock"])] == 0.0)
    u2 = df["c2_command_1"].to_numpy()
    inertia = np.flatnonzero(phase[:-1] == "inertia_phase")
    inertia = inertia[(df["c2.mode_1"].to_numpy()[inertia + 1] != 0.0) & (inertia > k)]   # (c2 sliding throughout)
    assert inertia.size > 100
    w = df["engine.w_rad_s"].to_numpy()
    accel = J_E * np.diff(w)[inertia] / H
    np.testing.assert_allclose(accel, df["torque_command_Nm"].to_numpy()[inertia] - u2[inertia] * CAPACITY,
                               rtol=0, atol=1e-6)
    stick = _event(res, "c2", "stick")[0]
    assert 0.0 < ph.time_s[ph.phase == "lock"].iloc[0] - stick <= H + 1e-12
    q = tcu.shift_quality(df, **HOW)[0]
    ref = shift_quality(load_driveline(SCHEDULE).driveline.simulate(1.3, rtol=1e-8, output_step=H).to_dataframe(),
                        offgoing="c1", oncoming="c2", **HOW)
    assert ref.metrics["tie_up_Nm"] > 10.0 and q.metrics["tie_up_Nm"] < 0.1 * ref.metrics["tie_up_Nm"]
    assert q.metrics["flare_rad_s"] < 1e-9
    assert q.metrics["shift_time_s"] <= ref.metrics["shift_time_s"] + 2 * H
    end = df.iloc[-1]
    assert end["engine.w_rad_s"] / end["output_shaft.w_rad_s"] == pytest.approx(2.0, rel=1e-6)
    assert np.abs(df["energy_error_J"]).max() < 1e-7 * df["input_work_J"].abs().max()


def test_a_torque_cut_shortens_the_inertia_phase_and_the_on_coming_clutch_s_heat(dct):
    """Half the engine's torque taken away through the inertia phase: the on-coming clutch's excess capacity pulls
    the engine down faster, so the inertia phase is shorter and the clutch dissipates less (the price: a harder
    lock-up)."""
    q = {}
    for cut in (0.0, 0.5):
        tcu = _tcu([(0.5, 2)], torque_cut=cut)
        res = _run(dct, tcu, 1.3)
        df = res.frame
        phase = _phase_at(tcu.phases, df.time_s.to_numpy())
        assert np.all(df["torque_command_Nm"].to_numpy()[phase == "inertia_phase"] == (1.0 - cut) * TORQUE)
        q[cut] = tcu.shift_quality(df, **HOW)[0].metrics
    assert q[0.5]["inertia_phase_s"] < 0.7 * q[0.0]["inertia_phase_s"]
    assert q[0.5]["oncoming_energy_J"] < 0.7 * q[0.0]["oncoming_energy_J"]
    assert q[0.5]["lockup_slip_rate_rad_s2"] > q[0.0]["lockup_slip_rate_rad_s2"]


def test_the_power_on_downshift_brings_the_engine_to_the_new_gear_s_speed_before_it_hands_over(dct):
    """A downshift at 1.5 s with the engine driving: the off-going c2 eases to ``slip`` so that the engine speeds up;
    the torque phase starts at the first sample where the engine has reached 1st's speed (``3.5 w_out``), so the
    on-coming c1 closes nearly synchronously (it dissipates under 1 J against the off-going clutch's kilojoules);
    1st's ratio after; the drive is never interrupted (a clutch's factor above 0 at every sample)."""
    tcu = _tcu([(0.5, 2), (1.5, 1)])
    res = _run(dct, tcu, 2.6)
    ph = tcu.phases
    assert list(ph.phase) == ["drive", "torque_phase", "inertia_phase", "lock", "drive", "inertia_phase",
                              "torque_phase", "drive"]
    df = res.frame
    w_e, w_out = df["engine.w_rad_s"].to_numpy(), df["output_shaft.w_rad_s"].to_numpy()
    k = int(round(ph.time_s.iloc[6] / H))
    assert w_e[k] >= 3.5 * w_out[k] and w_e[k - 1] < 3.5 * w_out[k - 1]
    t, end = df.time_s.to_numpy(), ph.time_s.iloc[7]
    hand = (t >= ph.time_s.iloc[6]) & (t < end)   # (the hand-over: c1 up, c2 down from where it was, over 0.1 s)
    ramp = np.clip((t[hand] - ph.time_s.iloc[6]) / tcu.handover, 0.0, 1.0)
    np.testing.assert_allclose(df["c1_command_1"].to_numpy()[hand], ramp, rtol=0, atol=1e-12)
    np.testing.assert_allclose(df["c2_command_1"].to_numpy()[hand], df["c2_command_1"].iloc[k] * (1.0 - ramp),
                               rtol=0, atol=1e-12)
    assert tcu.slip <= df["c2_command_1"].iloc[k] < 1.0
    down = tcu.shift_quality(df, **HOW)[1]
    assert (down.order, down.sequence, down.columns["oncoming"]) == ("downshift", "inertia_first", "c1")
    assert down.metrics["oncoming_energy_J"] < 1.0 < 1000.0 < down.metrics["offgoing_energy_J"]
    u = df[["c1_command_1", "c2_command_1"]].to_numpy()
    assert np.all(u.max(axis=1) > 0.0)
    assert df["c2_command_1"].iloc[-1] == 0.0 and df["c1_command_1"].iloc[-1] == 1.0
    end = df.iloc[-1]
    assert end["engine.w_rad_s"] / end["output_shaft.w_rad_s"] == pytest.approx(3.5, rel=1e-6)


COAST = -40.0                                      # the engine's drag when the driver lifts off [N m]


@pytest.fixture(scope="module")
def coasting():
    """The DCT example coasting in 1st: the engine's torque at its drag, the half shafts wound for it (the drag
    through 1st and the final drive, about 300 N m at the wheels, against the example's 1631 N m of drive)."""
    d = load_driveline(SCHEDULE).driveline.without()
    d.input("torque_command", unit="Nm", start=COAST).input("c1_command", unit="1", start=1.0)
    d.input("c2_command", unit="1", start=0.0)
    d = (d.replace("engine_torque", signal=Signal.input("torque_command"))
         .replace("c1", normal=Signal.input("c1_command")).replace("c2", normal=Signal.input("c2_command"))
         .replace("wheels", phi0=0.03))
    return d.system(1e-8)


def _coast(commands, **kw):
    return DctController(GEARS, 1, commands, torque_input="torque_command", torque=COAST, engine_speed="engine.w",
                         output_speed="output_shaft.w", **kw)


def _sliding_engine(df, rows):
    """``J_e (w[k + 1] - w[k]) / h`` and ``T + u1 C`` at ``rows``: the engine under its torque and c1 sliding with the
    engine slower than the odd shaft (c1 pulls it up), c2 open -- where both are the same, the closed form holds."""
    w = df["engine.w_rad_s"].to_numpy()
    return (J_E * np.diff(w)[rows] / H,
            df["torque_command_Nm"].to_numpy()[rows] + df["c1_command_1"].to_numpy()[rows] * CAPACITY)


def test_a_coast_upshift_lets_the_engine_fall_under_its_drag_before_it_hands_over(coasting):
    """An upshift while coasting: the engine's drag moves it *towards* 2nd's (lower) speed, so the inertia phase comes
    first: c1 eases to ``coast_slip`` (0: open) and the engine falls under its drag alone, ``J_e (w[k + 1] - w[k]) /
    h = T + u1 C`` at every sample where c1 slides (1e-6 N m); the hand-over starts at the first sample where the
    engine has come down to ``2 w_out``, and c2 then closes nearly synchronously.  The sequence of a power-on
    upshift (torque phase first) cannot do this shift: c2, sliding with the engine above its speed, pushes the drive
    forward while c1 carries the drag backward, so c1's torque never reaches zero (the two clutches fight)."""
    tcu = _coast([(0.3, 2)])
    res = _run(coasting, tcu, 1.3)
    ph = tcu.phases
    assert list(ph.phase) == ["drive", "inertia_phase", "torque_phase", "drive"]
    df = res.frame
    w_e, w_out = df["engine.w_rad_s"].to_numpy(), df["output_shaft.w_rad_s"].to_numpy()
    k = int(round(ph.time_s.iloc[2] / H))
    assert w_e[k] <= 2.0 * w_out[k] and w_e[k - 1] > 2.0 * w_out[k - 1]
    phase = _phase_at(ph, df.time_s.to_numpy())
    rows = np.flatnonzero((phase[:-1] == "inertia_phase") & (df["c1.mode_1"].to_numpy()[1:] != 0.0))
    assert rows.size > 400 and np.all(df["c2_command_1"].to_numpy()[rows] == 0.0)
    accel, closed = _sliding_engine(df, rows)
    np.testing.assert_allclose(accel, closed, rtol=0, atol=1e-6)
    assert np.all(df["c1_command_1"].to_numpy()[(phase == "inertia_phase")][-10:] == tcu.coast_slip)
    q = tcu.shift_quality(df, **HOW)[0]
    # the direction from the speeds; the sequence from the record: c1 lets go of the drag as it opens, before c2
    # locks, with nothing carried in between (coast_slip = 0): no torque phase before the inertia phase (read as
    # "torque_first" before, from the hand-over's coming first alone)
    assert (q.order, q.sequence) == ("upshift", "inertia_first")
    assert q.handover_s < q.lockup_s <= ph.time_s.iloc[2]   # (c2 within the threshold of its slip: early)
    assert q.metrics["torque_phase_s"] == 0.0
    assert q.metrics["inertia_phase_s"] == pytest.approx(q.lockup_s - q.start_s, abs=1e-12)
    assert q.metrics["tie_up_Nm"] < 1.0 and q.metrics["oncoming_energy_J"] < 1.0
    end = df.iloc[-1]
    assert end["engine.w_rad_s"] / end["output_shaft.w_rad_s"] == pytest.approx(2.0, rel=1e-6)
    assert np.abs(df["energy_error_J"]).max() < 1e-7 * df["input_work_J"].abs().max()


def test_a_coast_downshift_hands_the_drag_over_and_then_pulls_the_engine_up(coasting):
    """A downshift while coasting: the drag moves the engine *away* from 1st's (higher) speed, so the torque phase
    comes first: c1 fills until c2 carries no drag (c1, sliding with the engine below its speed, pulls the engine up
    and brakes the output, the drag's direction), then c2 opens and c1 rises from the factor it had at the hand-over
    to 1 over ``rise`` (no step: a coast's drag is handed over early, at a low factor), pulling the engine up to 1st's
    speed, ``J_e (w[k + 1] - w[k]) / h = T + u1 C`` (1e-6 N m); the lock within a sample of c1's stick."""
    tcu = _coast([(0.3, 2), (1.4, 1)])
    res = _run(coasting, tcu, 2.2)
    ph = tcu.phases
    assert list(ph.phase) == ["drive", "inertia_phase", "torque_phase", "drive", "torque_phase", "inertia_phase",
                              "lock", "drive"]
    df = res.frame
    phase = _phase_at(ph, df.time_s.to_numpy())
    after = df.time_s.to_numpy() >= 1.4
    k = int(round(ph.time_s.iloc[5] / H))
    tau2 = df["c2.tau_Nm"].to_numpy() * np.sign(df["c2.tau_Nm"].iloc[int(round(1.4 / H))])
    assert tau2[k] <= 0.0 < tau2[k - 1]
    u1 = df["c1_command_1"].to_numpy()
    handed = tcu.fill * (ph.time_s.iloc[5] - 1.4) / tcu.handover
    assert handed < 0.5 * tcu.fill and u1[k] == pytest.approx(handed, abs=1e-12)
    shifting = np.flatnonzero(after & np.isin(phase, ["torque_phase", "inertia_phase"]))
    steps = np.abs(np.diff(u1[shifting]))
    assert steps.max() <= max(tcu.fill / tcu.handover, (1.0 - handed) / tcu.rise) * H + 1e-12
    rows = np.flatnonzero(after[:-1] & (phase[:-1] == "inertia_phase") & (df["c1.mode_1"].to_numpy()[1:] != 0.0))
    assert rows.size > 50 and np.all(df["c2_command_1"].to_numpy()[rows] == 0.0)
    accel, closed = _sliding_engine(df, rows)
    np.testing.assert_allclose(accel, closed, rtol=0, atol=1e-6)
    stick = _event(res, "c1", "stick")
    stick = stick[stick > 1.4][0]
    assert 0.0 < ph.time_s.iloc[6] - stick <= H + 1e-12
    down = tcu.shift_quality(df, **HOW)[1]
    assert (down.order, down.sequence, down.columns["oncoming"]) == ("downshift", "torque_first", "c1")
    end = df.iloc[-1]
    assert end["engine.w_rad_s"] / end["output_shaft.w_rad_s"] == pytest.approx(3.5, rel=1e-6)
    assert np.abs(df["energy_error_J"]).max() < 1e-7 * df["input_work_J"].abs().max()


def test_a_tip_out_makes_the_next_shift_a_coast_shift(dct):
    """The driver's demand as rows: 150 N m, lifted off to -40 N m (the drag) over 1.2-1.25 s.  The upshift at 0.5 s
    is a power-on one (its torque phase first); the downshift at 1.6 s, after the tip-out, a coast one, also torque
    phase first (a power-on downshift would start with its inertia phase): c1 takes the drag over, then pulls the
    engine up to 1st's speed, ``J_e (w[k + 1] - w[k]) / h = T + u1 C`` while it slides alone.  Between the shifts the
    engine's torque is the demand at each sample."""
    demand = [(0.0, TORQUE), (1.2, TORQUE), (1.25, COAST)]
    tcu = DctController(GEARS, 1, [(0.5, 2), (1.6, 1)], torque_input="torque_command", torque=demand,
                        engine_speed="engine.w", output_speed="output_shaft.w")
    assert tcu.torque == ((0.0, TORQUE), (1.2, TORQUE), (1.25, COAST))
    res = _run(dct, tcu, 2.4)
    ph = tcu.phases
    assert list(ph.phase) == ["drive", "torque_phase", "inertia_phase", "lock", "drive", "torque_phase",
                              "inertia_phase", "lock", "drive"]
    df = res.frame
    t = df.time_s.to_numpy()
    phase = _phase_at(ph, t)
    drive = phase == "drive"
    np.testing.assert_allclose(df["torque_command_Nm"].to_numpy()[drive],
                               np.interp(t[drive], *zip(*demand)), rtol=0, atol=1e-12)
    rows = np.flatnonzero((t[:-1] > 1.6) & (phase[:-1] == "inertia_phase") & (df["c1.mode_1"].to_numpy()[1:] != 0.0))
    assert rows.size > 20 and np.all(df["c2_command_1"].to_numpy()[rows] == 0.0)
    accel, closed = _sliding_engine(df, rows)
    np.testing.assert_allclose(accel, closed, rtol=0, atol=1e-6)
    down = tcu.shift_quality(df, **HOW)[1]
    assert (down.order, down.sequence) == ("downshift", "torque_first")
    end = df.iloc[-1]
    assert end["engine.w_rad_s"] / end["output_shaft.w_rad_s"] == pytest.approx(3.5, rel=1e-6)


@settings(max_examples=examples(6), deadline=None, derandomize=pinned())
@given(st.lists(st.tuples(st.floats(0.05, 2.5), st.sampled_from([1, 2])), min_size=1, max_size=3),
       st.floats(0.0, 0.6), st.floats(0.55, 1.0))
def test_a_power_shift_never_interrupts_the_drive_whatever_the_commands(dct, commands, cut, fill):
    """Random gear commands (those during a shift wait for it), torque cuts and fills: the phases follow an upshift's or a downshift's sequence and the
    run ends in the last gear commanded; at every sample a clutch's factor is above 0 and both are within [0, 1]; the
    engine's torque stays within ``[(1 - cut) T, T]``; the energy balance holds."""
    tcu = _tcu(commands, torque_cut=cut, fill=fill, shift_timeout=2.0)
    res = _run(dct, tcu, 6.0)   # (three shifts from 2.5 s on end by then: a downshift at speed takes about 1 s)
    ph = tcu.phases
    seq, before, k = list(ph.phase), 1, 1
    up, down = ["torque_phase", "inertia_phase", "lock", "drive"], ["inertia_phase", "torque_phase", "drive"]
    while k < len(seq):
        gear = ph.gear.iloc[k]
        want = up if GEARS[gear].ratio < GEARS[before].ratio else down
        assert seq[k:k + len(want)] == want[:len(seq) - k], (k, seq)
        k, before = k + len(want), gear
    last = sorted(commands, key=lambda c: c[0])[-1][1]
    assert seq[-1] == "drive" and ph.gear.iloc[-1] == last
    df = res.frame
    u = df[["c1_command_1", "c2_command_1"]].to_numpy()
    assert np.all(u.max(axis=1) > 0.0) and u.min() >= 0.0 and u.max() <= 1.0
    torque = df["torque_command_Nm"].to_numpy()
    assert torque.min() >= (1.0 - cut) * TORQUE - 1e-9 and torque.max() <= TORQUE
    assert np.abs(df["energy_error_J"]).max() < 1e-6 * df["input_work_J"].abs().max()


def test_the_controller_s_decisions_do_not_move_with_the_tolerance(dct):
    """Its decisions are taken at its samples from the network's values, so a tighter integration takes every one at
    the same sample (rtol 1e-8 and 1e-11: the phases equal), and the run moves by the integration's error only."""
    runs = {}
    for rtol in (1e-8, 1e-11):
        tcu = _tcu([(0.5, 2), (1.5, 1)])
        measure = list(tcu.measured) + ["wheels.w"]
        runs[rtol] = (closed_loop(dct, tcu, H, 2.6, measure=measure, actuate=list(tcu.actuated), rtol=rtol),
                      tcu.phases)
    (a, pa), (b, pb) = runs[1e-8], runs[1e-11]
    assert pa.equals(pb)
    w = a.frame["engine.w_rad_s"]
    assert np.abs(w - b.frame["engine.w_rad_s"]).max() < 1e-8 * np.abs(w).max()   # (7e-12 measured)


def test_a_hand_over_that_cannot_happen_stops_the_run(dct):
    """An on-coming clutch filled to 5 % cannot take the engine's torque over: the off-going one keeps carrying it,
    and the run stops after ``shift_timeout`` with an error naming the shift."""
    with pytest.raises(SimulationError, match=r"from gear 1 \(c1\) to 2 \(c2\) has not handed the torque over"):
        _run(dct, _tcu([(0.5, 2)], fill=0.05, shift_timeout=0.3), 1.5)


@pytest.mark.parametrize("change, message", [
    (dict(gears={1: DctGear("c1", "c1_command", 3.5)}),
     r"gears must be \{gear number: DctGear\(clutch, input, ratio\)\}, at least 2"),
    (dict(gears={1: DctGear("c1", "u", 3.5), 2: DctGear("c1", "v", 2.0)}), r"a clutch and an input of its own"),
    (dict(start_gear=3), r"start_gear = 3 is not among the gears \[1, 2\]"),
    (dict(commands=[(0.5, 4)]), r"the command at 0\.5 s selects gear 4"),
    (dict(fill=1.5), r"fill = 1\.5 must be <= 1"),
    (dict(fill=0.0), r"DctController: fill = 0\.0 must be finite and > 0"),
    (dict(torque_cut=1.0), r"torque_cut = 1\.0 must be < 1"),
    (dict(slip=-0.1), r"DctController: slip = -0\.1 must be finite and >= 0"),
    (dict(coast_slip=1.0), r"DctController: coast_slip = 1\.0 must be < 1"),
    (dict(handover=float("nan")), r"handover = nan must be finite and > 0"),
    (dict(engine_speed=""), r"engine_speed = '' must be a name"),
    (dict(torque=math.inf), r"torque = inf must be a finite number"),
    (dict(torque=[(0.0, 150.0), (0.0, -40.0)]), r"rows \(time \[s\], torque \[N m\]\) of finite numbers with "
                                                r"increasing times"),
])
def test_bad_settings_are_refused_naming_them(change, message):
    kw = dict(gears=GEARS, start_gear=1, commands=[(0.5, 2)], torque_input="torque_command", torque=TORQUE,
              engine_speed="engine.w", output_speed="output_shaft.w")
    kw.update(change)
    with pytest.raises(ParameterError, match=message):
        DctController(**kw)
    with pytest.raises(ParameterError, match=r"ratio = 0 must be a finite number > 0"):
        DctGear("c1", "c1_command", 0)


EXAMPLE = ROOT / "examples" / "driveline_dct_tcu.toml"   # the same network with its inputs and [tcu] in the file


def test_the_file_s_controller_runs_from_the_command_line_as_the_python_one(dct, tmp_path, capsys):
    """``clutchlab control tcu`` on ``examples/driveline_dct_tcu.toml`` (``type = "dct"``): the same phases and run
    as the Python controller with the file's settings, every shift's quality from its [shift] table (each with its
    own clutches); nothing is overwritten without --force."""
    import json

    import pandas as pd

    from clutchlab.cli import main

    out, phases, quality = tmp_path / "run.csv", tmp_path / "phases.csv", tmp_path / "quality.json"
    argv = ["control", "tcu", str(EXAMPLE), "-o", str(out), "--phases", str(phases), "--quality", str(quality)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "8 phases of DctController" in printed and "upshift (torque phase first) from 0.5000 s" in printed
    assert "downshift (inertia phase first) from 1.5000 s" in printed
    report = json.loads(quality.read_text())
    assert [(q["order"], q["start_s"], q["columns"]["offgoing"], q["columns"]["oncoming"]) for q in report] == [
        ("upshift", 0.5, "c1", "c2"), ("downshift", 1.5, "c2", "c1")]
    tcu = _tcu([(0.5, 2), (1.5, 1)])
    res = _run(dct, tcu, 2.6)
    got = pd.read_csv(phases)
    assert list(got.phase) == list(tcu.phases.phase) and list(got.gear) == list(tcu.phases.gear)
    np.testing.assert_allclose(got.time_s, tcu.phases.time_s, rtol=0, atol=1e-12)
    run = pd.read_csv(out)
    for col in ("engine.w_rad_s", "c1.tau_Nm", "c2_command_1", "torque_command_Nm"):
        np.testing.assert_allclose(run[col], res.frame[col], rtol=1e-8, atol=1e-9)   # (the CSV's 9 digits)
    assert main(argv) != 0 and "--force" in capsys.readouterr().err


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.update(type="cvt"), r"tcu\.type = 'cvt': expected one of amt, dct"),
    (lambda t: t.update(clutch_input="c1_command"), r"tcu\.clutch_input: unknown field \(known: type, gears, "),
    (lambda t: t.pop("engine_speed"), r"\[tcu\]: missing field 'engine_speed'"),
    (lambda t: t["gears"]["2"].update(clutch="wheels"), r"tcu\.gears\.2\.clutch = 'wheels': expected a clutch of the "
                                                        r"network \(c1, c2\)"),
    (lambda t: t["gears"]["2"].update(input="fork"), r"tcu\.gears\.2\.input = 'fork': expected a network input"),
    (lambda t: t["gears"]["2"].pop("ratio"), r"tcu\.gears\.2 must be \{ clutch = \.\.\., input = \.\.\., ratio"),
    (lambda t: t["gears"]["2"].update(ratio=-2.0), r"tcu\.gears\.2\.ratio = -2\.0: expected the gear's ratio"),
    (lambda t: t.update(handover="0.1 N"), r"tcu\.handover"),
    (lambda t: t.update(output_speed="output_shaft.v"), r"tcu\.output_speed = 'output_shaft\.v': expected a state"),
])
def test_a_bad_dct_table_is_refused_naming_the_file_and_the_field(edit, message):
    import tomllib

    from clutchlab.driveline.description import parse_driveline

    doc = tomllib.loads(EXAMPLE.read_text())
    edit(doc["tcu"])
    with pytest.raises(ParameterError, match=message):
        parse_driveline(doc, "dct.toml")


def test_the_file_s_coast_slip_and_demand_rows_reach_the_controller():
    """``[tcu] coast_slip`` (a coast upshift's off-going factor) is read with the other fields and given to the
    controller (left out, the controller's default: 0, the off-going clutch opens); ``torque`` may be rows [time,
    torque] with units (a tip-out), converted to SI; rows that are not pairs are refused naming the field."""
    import tomllib

    from clutchlab.driveline.description import parse_driveline

    doc = tomllib.loads(EXAMPLE.read_text())
    assert DctController.from_table(parse_driveline(doc, "dct.toml").tcu).coast_slip == 0.0
    doc["tcu"]["coast_slip"] = 0.1
    doc["tcu"]["torque"] = [["0 s", "150 N m"], ["1200 ms", "150 N m"], ["1.25 s", "-40 N m"]]
    tcu = DctController.from_table(parse_driveline(doc, "dct.toml").tcu)
    assert tcu.coast_slip == 0.1 and tcu.torque == ((0.0, 150.0), (1.2, 150.0), (1.25, -40.0))
    assert tcu.demand(1.225) == pytest.approx(55.0) and tcu.demand(9.0) == -40.0
    doc["tcu"]["torque"] = [["0 s", "150 N m", "1 s"]]
    with pytest.raises(ParameterError, match=r"dct\.toml: tcu\.torque must be a torque or rows \[time, torque\]"):
        parse_driveline(doc, "dct.toml")


def test_the_command_line_refuses_a_controller_it_cannot_build(tmp_path, capsys):
    from cli_checks import one_line_error

    bad = tmp_path / "dct.toml"
    bad.write_text(EXAMPLE.read_text().replace("fill = 0.7 ", "fill = 1.7 "))
    line = one_line_error(capsys, ["control", "tcu", str(bad), "-o", str(tmp_path / "run.csv")])
    assert "dct.toml: [tcu] DctController: fill = 1.7 must be <= 1" in line
    assert not (tmp_path / "run.csv").exists()
