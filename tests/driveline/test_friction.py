"""Driveline friction elements against closed forms and an independent solution.

* ModelicaTest ``Rotational.TestFriction`` (MSL 4.x): bearing friction, brake and clutch rows; every
  event time in closed form (derivations in the docstrings below).
* MSL ``Rotational.Examples.CoupledClutches``: every mode change and the final speeds against an
  independent SciPy solution (``coupled_clutches_scipy.py``: DOP853 at rtol 1e-12 with restarts at
  every event, written separately from the package from the MSL source), and the energy balance.
* Several elements stuck at once, in series and in parallel, with closed-form break-away times.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from clutchlab.driveline import Driveline, Signal
from clutchlab.errors import ParameterError
from hypothesis_budget import examples

from . import coupled_clutches_scipy as ref_cc

TWO_PI = 2.0 * math.pi


def friction_network():
    """ModelicaTest.Rotational.TestFriction, its first three rows (J = 1, drive 10 sin(2 pi t) N m each)."""
    d = Driveline("test_friction")
    d.inertia("inertia", J=1.0)
    d.torque("torque", "inertia", Signal.sine(10.0, 1.0))
    d.bearing_friction("bearing_friction", "inertia", torque=1.0)
    d.inertia("inertia1", J=1.0)
    d.torque("torque1", "inertia1", Signal.sine(10.0, 1.0))
    d.brake("brake", "inertia1", fn_max=1.0, mu=0.5, normal=Signal.step(100.0, 0.5))
    d.inertia("inertia2", J=1.0)
    d.torque("torque2", "inertia2", Signal.sine(10.0, 1.0))
    d.inertia("inertia3", J=1.0)
    d.clutch("clutch", "inertia2", "inertia3", fn_max=1.0, mu=0.5, normal=Signal.step(100.0, 0.5))
    return d


@pytest.fixture(scope="module")
def test_friction():
    return friction_network().simulate(1.1, output_step=1e-3, rtol=1e-10)


def _bearing_times():
    """Bearing (1 N m, starts stuck): breaks away when 10 sin(2 pi t0) = 1; slides forward with
    w = (10/2pi)(cos 2pi t0 - cos 2pi t) - (t - t0) until w = 0 at t1, where the drive (-8.75 N m) is far
    beyond the 1 N m limit: it reverses without sticking."""
    t0 = math.asin(0.1) / TWO_PI
    c0 = math.sqrt(0.99)

    def w(t):
        return 10.0 / TWO_PI * (c0 - math.cos(TWO_PI * t)) - (t - t0)

    lo, hi = 0.6, 1.0  # w > 0 at 0.6, < 0 at 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if w(mid) > 0 else (lo, mid)
    return t0, 0.5 * (lo + hi)


def _root(f, lo, hi):
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(lo) * f(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def test_friction_events_have_their_closed_forms(test_friction):
    ev = test_friction.events
    got = {(r.element, r.event): r.time_s for r in ev.itertuples()}
    t0, t1 = _bearing_times()
    # brake: free until 0.5 s (w = (10/2pi)(1 - cos 2pi t)), then 50 N m against the motion
    t_brake = _root(lambda t: 5.0 / math.pi * (1.0 - math.cos(TWO_PI * t)) - 50.0 * (t - 0.5), 0.5001, 0.7)
    # clutch: engages at 0.5 s backward (w_rel = -10/pi), w_rel' = 100 - 10 sin 2pi t
    t_clutch = _root(lambda t: -5.0 / math.pi * (1.0 - math.cos(TWO_PI * t)) + 100.0 * (t - 0.5), 0.5001, 0.6)
    expected = {("bearing_friction", "forward"): t0, ("bearing_friction", "backward"): t1,
                ("brake", "forward"): 0.5, ("brake", "stick"): t_brake,
                ("clutch", "backward"): 0.5, ("clutch", "stick"): t_clutch}
    assert set(got) == set(expected), ev
    for key, t in expected.items():
        assert abs(got[key] - t) < 1e-6, (key, got[key], t)
    # the numbers (rounded closed forms)
    assert abs(t0 - 0.0159421) < 1e-7 and abs(t1 - 0.830285) < 1e-6
    assert abs(t_brake - 0.561328) < 1e-6 and abs(t_clutch - 0.531520) < 1e-6


def test_friction_speeds_follow_the_closed_forms(test_friction):
    df = test_friction.to_dataframe()
    t = df.time_s.to_numpy()
    t0, t1 = _bearing_times()
    w = np.where(t < t0, 0.0, np.where(
        t < t1, 10.0 / TWO_PI * (math.sqrt(0.99) - np.cos(TWO_PI * t)) - (t - t0),
        10.0 / TWO_PI * (math.cos(TWO_PI * t1) - np.cos(TWO_PI * t)) + (t - t1)))
    assert np.max(np.abs(df["inertia.w_rad_s"].to_numpy() - w)) < 1e-7
    # while locked the clutch carries half the drive (two equal inertias) and the brake all of it
    locked = t > 0.57
    np.testing.assert_allclose(df["clutch.tau_Nm"].to_numpy()[locked], -5.0 * np.sin(TWO_PI * t[locked]), atol=1e-7)
    np.testing.assert_allclose(df["brake.tau_Nm"].to_numpy()[locked], 10.0 * np.sin(TWO_PI * t[locked]), atol=1e-7)
    assert np.all(df["clutch.mode_1"].to_numpy()[locked] == 0) and np.all(df["brake.mode_1"].to_numpy()[t < 0.5] == 2)


# ----------------------------------------------------------------- CoupledClutches
def coupled_clutches():
    """MSL Rotational.Examples.CoupledClutches with its own parameters."""
    d = Driveline("coupled_clutches")
    for i, w0 in ((1, 10.0), (2, 0.0), (3, 0.0), (4, 0.0)):
        d.inertia(f"J{i}", J=1.0, w0=w0)
    d.torque("torque", "J1", Signal.sine(10.0, 5.0))
    d.clutch("clutch1", "J1", "J2", fn_max=20.0, mu=0.5, peak=1.1, normal=Signal.sine(1.0, 0.2, phase=math.pi / 2))
    d.clutch("clutch2", "J2", "J3", fn_max=20.0, mu=0.5, peak=1.1, normal=Signal.step(1.0, 0.4))
    d.clutch("clutch3", "J3", "J4", fn_max=20.0, mu=0.5, peak=1.1, normal=Signal.step(1.0, 0.9))
    return d


@pytest.fixture(scope="module")
def reference_cc():
    return ref_cc.reference(1.5)


def test_coupled_clutches_against_an_independent_solution(reference_cc):
    res = coupled_clutches().simulate(1.5, output_step=1e-3, rtol=1e-10)
    got = list(res.events.itertuples())
    want = reference_cc["events"]
    assert [(r.element, r.event) for r in got] == [(e, m) for _, e, m in want]
    for r, (t, _, _) in zip(got, want):
        assert abs(r.time_s - t) < 1e-7, (r, t)
    last = res.to_dataframe().iloc[-1]
    for name in ("J1", "J2", "J3", "J4"):
        assert abs(last[f"{name}.w_rad_s"] - reference_cc["final"][f"{name}.w"]) < 1e-7
    assert abs(last["clutch1.w_rel_rad_s"] - reference_cc["final"]["clutch1.w_rel"]) < 1e-7


def test_coupled_clutches_energy_balance():
    """Input work = dissipated energy + change of the kinetic energy, within 1e-6 of the input work."""
    df = coupled_clutches().simulate(1.5, output_step=1e-3, rtol=1e-8).to_dataframe()
    work = df["input_work_J"].to_numpy()
    lost = sum(df[f"clutch{k}.dissipated_J"].to_numpy() for k in (1, 2, 3))
    kinetic = df["kinetic_energy_J"].to_numpy()
    scale = max(np.max(np.abs(work)), 1e-300)
    assert np.max(np.abs(work - lost - (kinetic - kinetic[0]))) < 1e-6 * scale
    assert np.max(np.abs(df["energy_error_J"].to_numpy())) < 1e-6 * scale
    assert np.all(np.diff(lost) >= -1e-9)  # friction only dissipates


# ----------------------------------------------------------------- several elements stuck at once
def test_series_clutches_stuck_together_break_in_closed_form():
    """J1 -c1- J2 -c2- J3 at rest, all stuck; a ramp torque k t on J1.  Locked: a = k t / (J1+J2+J3);
    c1 carries (J2+J3) a, c2 carries J3 a.  c1 (limit 3 N m) breaks first at t = 3 Jt / ((J2+J3) k)."""
    J1, J2, J3, k = 1.0, 2.0, 0.5, 10.0
    d = Driveline("series")
    d.inertia("J1", J=J1).inertia("J2", J=J2).inertia("J3", J=J3)
    d.torque("drive", "J1", Signal.ramp(k * 10.0, 10.0))
    d.clutch("c1", "J1", "J2", fn_max=6.0, mu=0.5)   # limit 3 N m
    d.clutch("c2", "J2", "J3", fn_max=20.0, mu=0.5)  # limit 10 N m
    res = d.simulate(1.0, output_step=1e-3, rtol=1e-10)
    df = res.to_dataframe()
    jt = J1 + J2 + J3
    t_break = 3.0 * jt / ((J2 + J3) * k)
    ev = res.events
    assert list(zip(ev.element, ev.event)) == [("c1", "backward")]  # J1 runs ahead of J2: w_rel = w2 - w1 < 0
    assert abs(ev.time_s.iloc[0] - t_break) < 1e-8
    t = df.time_s.to_numpy()
    before = t < t_break - 1e-3
    a = k * t[before] / jt
    np.testing.assert_allclose(np.abs(df["c1.tau_Nm"].to_numpy()[before]), (J2 + J3) * a, atol=1e-9)
    np.testing.assert_allclose(np.abs(df["c2.tau_Nm"].to_numpy()[before]), J3 * a, atol=1e-9)


def test_parallel_clutches_share_in_proportion_and_break_together():
    """Two clutches in parallel between J1 and J2 lock the same relative motion (a singular stuck set):
    the torque is split in proportion to the static limits (2 and 4 N m) and both break away together
    when the needed torque reaches 6 N m: J2 a = k t J2 / (J1 + J2) = 6 at t = 6 (J1 + J2) / (J2 k)."""
    J1, J2, k = 1.0, 1.0, 20.0
    d = Driveline("parallel")
    d.inertia("J1", J=J1).inertia("J2", J=J2)
    d.torque("drive", "J1", Signal.ramp(k * 10.0, 10.0))
    d.clutch("small", "J1", "J2", fn_max=4.0, mu=0.5)
    d.clutch("large", "J1", "J2", fn_max=8.0, mu=0.5)
    res = d.simulate(1.0, output_step=1e-3, rtol=1e-10)
    df = res.to_dataframe()
    t_break = 6.0 * (J1 + J2) / (J2 * k)
    ev = res.events
    assert sorted(ev.element) == ["large", "small"] and set(ev.event) == {"backward"}
    assert np.all(np.abs(ev.time_s.to_numpy() - t_break) < 1e-8)
    t = df.time_s.to_numpy()
    before = (t > 0.01) & (t < t_break - 1e-3)
    ratio = df["large.tau_Nm"].to_numpy()[before] / df["small.tau_Nm"].to_numpy()[before]
    np.testing.assert_allclose(ratio, 2.0, rtol=1e-6)
    after = t > t_break + 1e-3
    np.testing.assert_allclose(df["small.tau_Nm"].to_numpy()[after], -2.0, rtol=1e-12)
    np.testing.assert_allclose(df["large.tau_Nm"].to_numpy()[after], -4.0, rtol=1e-12)


# ----------------------------------------------------------------- energy as a property
@st.composite
def networks(draw):
    """A random chain of 2-4 inertias, each link a spring-damper or a clutch, sine torques on some."""
    n = draw(st.integers(2, 4))
    d = Driveline("random")
    for i in range(n):
        d.inertia(f"J{i}", J=draw(st.floats(0.05, 2.0)), w0=draw(st.floats(-20.0, 20.0)))
    for i in range(n - 1):
        if draw(st.booleans()):
            d.spring_damper(f"k{i}", f"J{i}", f"J{i + 1}", c=draw(st.floats(0.0, 200.0)), d=draw(st.floats(0.0, 2.0)))
        else:
            d.clutch(f"c{i}", f"J{i}", f"J{i + 1}", fn_max=draw(st.floats(0.0, 100.0)), mu=draw(st.floats(0.05, 0.6)),
                     peak=draw(st.floats(1.0, 1.5)),
                     normal=Signal.sine(1.0, draw(st.floats(0.1, 3.0)), phase=draw(st.floats(0.0, 6.0))))
    for i in range(n):
        if draw(st.booleans()):
            d.torque(f"T{i}", f"J{i}", Signal.sine(draw(st.floats(0.0, 30.0)), draw(st.floats(0.1, 8.0)),
                                                  phase=draw(st.floats(0.0, 6.0))))
    if draw(st.booleans()):
        d.bearing_friction("bearing", "J0", torque=draw(st.floats(0.0, 5.0)))
    return d


@settings(max_examples=examples(15), deadline=None)
@given(networks())
def test_energy_balance_on_random_networks(d):
    """Whatever the network and its sources: input work = dissipated + stored change, every dissipation
    grows, every clutch mode is one of MSL's."""
    df = d.simulate(1.0, output_step=5e-3, rtol=1e-9).to_dataframe()
    scale = max(1.0, np.max(np.abs(df["input_work_J"])), df["kinetic_energy_J"].iloc[0] + df["spring_energy_J"].iloc[0])
    assert np.max(np.abs(df["energy_error_J"].to_numpy())) < 1e-6 * scale
    for col in df.columns:
        if col.endswith(".dissipated_J"):
            assert np.all(np.diff(df[col].to_numpy()) >= -1e-8 * scale), col
        if col.endswith(".mode_1"):
            assert set(np.unique(df[col])) <= {-1.0, 0.0, 1.0, 2.0}


# ----------------------------------------------------------------- bad descriptions
@pytest.mark.parametrize("build, match", [
    (lambda d: d.clutch("c", "J1", "nowhere", fn_max=1.0), "flange b = 'nowhere' is not an inertia"),
    (lambda d: d.clutch("c", "J1", "J1", fn_max=1.0), "both flanges are 'J1'"),
    (lambda d: d.inertia("J3", J=-1.0), "J = -1.0 must be > 0"),
    (lambda d: d.inertia("J1", J=1.0), "component name 'J1' is used twice"),
    (lambda d: d.clutch("c", "J1", "J2", fn_max=1.0, peak=0.5), "peak = 0.5 must be >= 1"),
    (lambda d: d.clutch("c", "J1", "J2", fn_max=float("nan")), "fn_max = nan is not finite"),
    (lambda d: d.clutch("c", "J1", "J2", fn_max=1.0, mu=[[0.1, 0.5]]), "mu table must start at w = 0"),
    (lambda d: d.torque("T", "ground", 1.0), "needs an inertia as its flange"),
    (lambda d: d.torque("T", "J1", "ten"), "expected a number or a Signal"),
])
def test_bad_descriptions_give_one_clear_error(build, match):
    d = Driveline("bad")
    d.inertia("J1", J=1.0).inertia("J2", J=1.0)
    with pytest.raises(ParameterError, match=match):
        build(d)


def test_a_locked_loop_is_resolved():
    """J1 and J2 each braked to the ground and clutched to each other: stuck together the three
    constraints are dependent (a loop).  The torques still balance every inertia (brake 1 + clutch =
    drive on J1, brake 2 = clutch on J2), follow the split by the static limits (the minimiser of
    sum(tau^2 / limit) along the loop, in closed form below) while that split is well within the limits, and
    stay within every limit as long as some split holds: static friction holds while it can.  Brake 1 (2 N m)
    and the clutch-plus-brake-2 path (at most min(3, 4) N m) hold up to a drive of 5 N m, at t = 0.5 s, where
    brake 1 and the clutch break away together and brake 2 holds J2."""
    lim_b1, lim_c, lim_b2 = 2.0, 3.0, 4.0
    k = 10.0
    d = Driveline("loop")
    d.inertia("J1", J=1.0).inertia("J2", J=2.0)
    d.torque("drive", "J1", Signal.ramp(k * 10.0, 10.0))
    d.brake("b1", "J1", fn_max=2 * lim_b1, mu=0.5)
    d.brake("b2", "J2", fn_max=2 * lim_b2, mu=0.5)
    d.clutch("c", "J1", "J2", fn_max=2 * lim_c, mu=0.5)
    res = d.simulate(1.0, output_step=1e-3, rtol=1e-10)
    df = res.to_dataframe()
    t = df.time_s.to_numpy()
    t_first = res.events.time_s.iloc[0]
    stuck = (t > 0.0) & (t < t_first - 1e-3)
    T = k * t[stuck]
    b1, c, b2 = (df[f"{n}.tau_Nm"].to_numpy()[stuck] for n in ("b1", "c", "b2"))
    # balance: J1 gets drive - b1 + c (b1: -tau on flange b = J1; c: +tau on flange a = J1); J2 gets -c - b2
    np.testing.assert_allclose(T - b1 + c, 0.0, atol=1e-7)
    np.testing.assert_allclose(-c - b2, 0.0, atol=1e-7)
    assert np.max(np.abs(df["J1.w_rad_s"].to_numpy()[stuck])) < 1e-9
    # within every limit while stuck
    for tq, lim in ((b1, lim_b1), (c, lim_c), (b2, lim_b2)):
        assert np.all(np.abs(tq) <= lim * (1 + 1e-12))
    # the split along the loop: b1 = x, and the path clutch + brake 2 carries T - x; minimise
    # x^2/lim_b1 + (T - x)^2 (1/lim_c + 1/lim_b2)  ->  x = T s / (1/lim_b1 + s), s = 1/lim_c + 1/lim_b2; that split
    # reaches brake 1's limit at T = 2.6: below it (with the 1 % margin of the feasible range) it is the split
    s = 1.0 / lim_c + 1.0 / lim_b2
    prop = T * s / (1.0 / lim_b1 + s)
    inside = prop < lim_b1 - 0.01 * (lim_b1 + min(lim_c, lim_b2) - T) * 2
    assert inside.sum() > 200
    np.testing.assert_allclose(b1[inside], prop[inside], rtol=1e-6, atol=1e-9)
    # the loop holds until no split holds: T = lim_b1 + min(lim_c, lim_b2)
    # (the margin the split keeps shrinks with the feasible range: brake 1 may go first by rounding, 1e-8 s early)
    assert abs(t_first - (lim_b1 + min(lim_c, lim_b2)) / k) < 1e-7
    first = res.events[res.events.time_s < t_first + 1e-7]
    assert set(zip(first.element, first.event)) == {("b1", "forward"), ("c", "backward")}


def test_signals_drive_as_their_closed_forms():
    """A table torque 0 -> 4 N m over 1 s then held, on J = 2: w = t^2 for t < 1, then 1 + 2 (t - 1);
    a sine from 0.5 s with an offset on a second inertia: w = offset t + the integral of the sine."""
    d = Driveline("signals")
    d.inertia("J1", J=2.0).inertia("J2", J=1.0)
    d.torque("T1", "J1", Signal.table([0.0, 1.0, 2.0], [0.0, 4.0, 4.0]))
    d.torque("T2", "J2", Signal.sine(3.0, 2.0, phase=0.3, offset=0.5, start=0.5))
    df = d.simulate(2.0, output_step=0.01, rtol=1e-10).to_dataframe()
    t = df.time_s.to_numpy()
    np.testing.assert_allclose(df["J1.w_rad_s"], np.where(t < 1.0, t ** 2, 1.0 + 2.0 * (t - 1.0)), atol=1e-8)
    w = 2 * math.pi * 2.0
    after = np.clip(t - 0.5, 0.0, None)
    expect = 0.5 * t + np.where(t > 0.5, 3.0 / w * (math.cos(0.3) - np.cos(w * after + 0.3)), 0.0)
    np.testing.assert_allclose(df["J2.w_rad_s"], expect, atol=1e-8)
    assert Signal.table([0.0, 1.0], [0.0, 4.0]).describe() == "table of 2 points from 0 to 1 s"
