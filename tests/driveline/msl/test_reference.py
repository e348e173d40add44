"""The reference engine (``reference.py``) against closed forms derived by hand from the MSL equations, and
against the separate CoupledClutches solution (``tests/driveline/coupled_clutches_scipy.py``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from .. import coupled_clutches_scipy as ref_cc
from . import models
from .reference import FWD, STUCK

TWO_PI = 2.0 * math.pi


def _times(result, element, mode=None):
    return [t for t, e, m in result.events if e == element and (mode is None or m == mode)]


def test_test_friction_rows_at_their_closed_form_events():
    """TestFriction: the bearing (1 N m) breaks away when 10 sin(2 pi t) = 1 and reverses at 0.830285 s;
    the brake (50 N m from 0.5 s) locks at 0.561328 s, the clutch and the one-way clutch at 0.531520 s
    (the values of tests/driveline/test_friction.py, derived there).  The one-way clutch overruns from
    t = 0, so inertia5 stays at rest until 0.5 s; with MSL's tau0_max_low (1e-4 mu cgeo fn_max = 5e-5 N m)
    the overrun starts when half the drive reaches it, 5e-5 / (0.5 * 10 * 2 pi) = 1.59e-6 s later."""
    r = models.test_friction().simulate(1.1, np.linspace(0, 1.1, 1101))
    assert _times(r, "bearingFriction") == pytest.approx([math.asin(0.1) / TWO_PI, 0.830285], abs=1e-6)
    assert _times(r, "brake", STUCK) == pytest.approx([0.561328], abs=1e-6)
    assert _times(r, "clutch", STUCK) == pytest.approx([0.531520], abs=1e-6)
    assert _times(r, "oneWayClutch", STUCK) == pytest.approx([0.531520], abs=1e-6)
    assert np.abs(r.columns["inertia5.w_rad_s"][:500]).max() < 1e-12
    msl = models.test_friction(msl_tau0_max_low=True).simulate(0.1, [0.0, 0.1])
    (t_over,) = [t for t, e, m in msl.log if e == "oneWayClutch" and m == FWD]
    assert t_over == pytest.approx(math.asin(1e-5) / TWO_PI, rel=1e-6)


def test_coupled_clutches_as_the_separate_scipy_solution():
    """The same nine mode changes within 1e-9 s and the same final speeds as coupled_clutches_scipy.py."""
    r = models.coupled_clutches().simulate(1.5, np.linspace(0, 1.5, 16))
    other = ref_cc.reference()
    assert [e[1:] for e in r.events] == [e[1:] for e in other["events"]]
    assert [e[0] for e in r.events] == pytest.approx([e[0] for e in other["events"]], abs=1e-9)
    for i in range(1, 5):
        assert r.columns[f"J{i}.w_rad_s"][-1] == pytest.approx(other["final"][f"J{i}.w"], abs=1e-8)


def test_one_way_clutch_disengaged_locks_and_overruns_in_closed_form():
    """Free wheel, inertias J = 1: overrunning from w_rel = 0.5 rad/s, w_in = -0.5 + 0.3 t + (10 / 4 pi)
    (1 - cos 4 pi t), w_out = -0.3 t until they meet (lock); locked, both accelerate with
    (0.3 + 10 sin 4 pi t - 0.3) / 2 and the clutch holds tau = -0.3 - 5 sin 4 pi t, which turns positive
    (overrun) at t = (pi + asin 0.06) / 4 pi = 0.2547775 s."""
    r = models.one_way_clutch_disengaged().simulate(0.3, np.linspace(0, 0.3, 301))

    def gap(t):
        return -0.5 + 0.3 * t + 10.0 / (2 * TWO_PI) * (1 - math.cos(2 * TWO_PI * t)) + 0.3 * t

    t_lock = brentq(gap, 0.01, 0.2, xtol=1e-14)
    assert r.events[:2] == [pytest.approx((t_lock, "oneWayClutch", STUCK), abs=1e-9),
                            pytest.approx(((math.pi + math.asin(0.06)) / (2 * TWO_PI), "oneWayClutch", FWD),
                                          abs=1e-9)]


def test_lossy_gear_demos_break_away_at_the_closed_form_instants():
    """LossyGearDemo1 at rest (locked): rolls forward when eta tau_a beats the load, 0.5 * 10 sin(2 pi t) =
    (10 - 2.5 t) / 2 (MSL: sa = tau_a + tau_b / ratio > tauLossMax_p = (1 - eta) tau_a).  LossyGearDemo2:
    the same with the bearing at its 0.5 N m limit, 0.5 (10 sin(2 pi t) - 0.5) = (10 - 2.5 t) / 2 (0.2304 s,
    the figure of MSL's reference result quoted in issue #30).  LossyGearDemo3: tau_a = m / (1 + k) = 0.5 N m
    while rolling, both inertias (J 0.001) stop at 10 / (0.5 / 0.001) = 0.02 s and stay locked."""
    r1 = models.lossy_gear_demo1().simulate(0.5, [0.0, 0.5])
    t1 = brentq(lambda t: 5 * math.sin(TWO_PI * t) - (10 - 2.5 * t) / 2, 0.1, 0.25, xtol=1e-14)
    assert _times(r1, "gear", FWD) == pytest.approx([t1], abs=1e-9)
    r2 = models.lossy_gear_demo2().simulate(0.5, [0.0, 0.5])
    t2 = brentq(lambda t: 0.5 * (10 * math.sin(TWO_PI * t) - 0.5) - (10 - 2.5 * t) / 2, 0.2, 0.25, xtol=1e-14)
    assert t2 == pytest.approx(0.2304, abs=1e-4)
    assert [t for t in _times(r2, "gear", FWD) if t > 0.2] == pytest.approx([t2], abs=1e-9)
    r3 = models.lossy_gear_demo3().simulate(1.0, np.linspace(0, 1, 11))
    assert r3.events == [pytest.approx((0.02, "gear", STUCK), abs=1e-9)]
    assert np.abs(r3.columns["Inertia1.w_rad_s"][1:]).max() < 1e-9


def test_simple_drive_train_and_directions_in_closed_form():
    """A sine torque on J1 geared (ratio i) to J2: w1 = (1 - cos 2 pi t) / (2 pi Jeff), Jeff = J1 + J2 / i^2,
    w2 = w1 / i; the gear's torque on flange a is -(J2 / i^2) dw1/dt."""
    r = models.simple_drive_train().simulate(1.1, np.linspace(0, 1.1, 111))
    t = r.time
    w1 = (1 - np.cos(TWO_PI * t)) / (TWO_PI * 0.4)
    assert np.allclose(r.columns["J1.w_rad_s"], w1, atol=1e-10)
    assert np.allclose(r.columns["J2.w_rad_s"], w1 / 5, atol=1e-10)
    assert np.allclose(r.columns["gear.tau_Nm"], -0.2 * np.sin(TWO_PI * t) / 0.4, atol=1e-9)
    d = models.directions().simulate(2.0, np.linspace(0, 2, 201))
    for drive, jeff in (("J1", 0.4), ("J3", 0.2 + 5 * 0.2 ** 2), ("J5", 0.2 + 5 * 0.2 ** 2)):
        wd = (1 - np.cos(TWO_PI * d.time)) / (TWO_PI * jeff)
        assert np.allclose(d.columns[f"{drive}.w_rad_s"], wd, atol=1e-10)
    assert np.allclose(d.columns["J4.w_rad_s"], 0.2 * d.columns["J3.w_rad_s"], atol=1e-12)


def test_backlash_rows_in_closed_form():
    """Row 1, a damped oscillator (J 5, c 20e3, d 50) released at pi/2: phi = pi/2 e^(-z w t) (cos wd t +
    z w / wd sin wd t).  Row 2 (the ElastoBacklash), undamped variant: in contact from pi/2 it swings
    harmonically about the edge pi/8 until it leaves the contact at the edge with speed
    w (pi/2 - pi/8) (energy), then coasts through the 45 deg gap."""
    r = models.backlash().simulate(1.0, np.linspace(0, 1, 1001))
    w, z = math.sqrt(20e3 / 5), 50 / (2 * math.sqrt(20e3 * 5))
    wd = w * math.sqrt(1 - z * z)
    t = r.time
    phi = math.pi / 2 * np.exp(-z * w * t) * (np.cos(wd * t) + z * w / wd * np.sin(wd * t))
    assert np.allclose(r.columns["inertia1.phi_rad"], phi, atol=1e-9)
    n = models.Network().inertia("J", 5.0, 0.0, math.pi / 2)
    n.backlash("b", "ground", "J", c=20e3, d=0.0, b_gap=math.pi / 4)
    t_edge = math.acos(0.0) / w                      # deflection pi/2 - pi/8 -> 0: a quarter period
    u = n.simulate(t_edge + 0.01, [t_edge, t_edge + 0.01])
    v = -w * (math.pi / 2 - math.pi / 8)
    assert u.columns["J.w_rad_s"] == pytest.approx([v, v], abs=1e-8)
    assert u.columns["J.phi_rad"][1] == pytest.approx(math.pi / 8 + 0.01 * v, abs=1e-9)


def test_friction_with_a_speed_table_and_peak():
    """TestFrictionPosition's torque row: the inertia starts at -2 rad/s sliding backward against 5 N m
    (+5 N m on it), w = -2 + 5 t + 0.5 t + (25 / 2 pi)(cos(pi/4) - cos(2 pi t + pi/4)) until w = 0."""
    r = models.test_friction_torque_row().simulate(1.1, [0.0, 1.1])

    def w(t):
        return -2 + 5.5 * t + 25 / TWO_PI * (math.cos(math.pi / 4) - math.cos(TWO_PI * t + math.pi / 4))
    t0 = brentq(w, 1e-3, 0.3, xtol=1e-14)
    stuck_or_fwd = [e for e in r.log if e[0] > 0][0]
    assert stuck_or_fwd[0] == pytest.approx(t0, abs=1e-9)


def test_a_strict_network_holds_an_indeterminate_pair_while_some_split_holds():
    """Two clutches in parallel (limits 1 and 3 N m) between J1 = 1 and J2 = 3 kg m^2 at rest, a torque ramp 10 t
    N m on J1: the pair carries ``J2 / (J1 + J2) 10 t = 7.5 t`` and holds until that reaches the sum of the limits,
    t = 4 / 7.5 s, where both break away together (closed form).  MSL's equations are singular here; the
    least-squares split (the non-strict network) halves the load and lets the weaker clutch go at t = 1 / 3.75 s
    (the same motion, another label), the strict network's linear program (``Network._holding_split``) does not."""
    def pair(strict):
        from . import reference as R

        net = R.Network(strict=strict)
        net.inertia("J1", 1.0).inertia("J2", 3.0)
        net.clutch("c1", "J1", "J2", fn_max=2.0, normal=R.constant(1.0), mu=0.5)
        net.clutch("c2", "J1", "J2", fn_max=6.0, normal=R.constant(1.0), mu=0.5)
        net.torque("T", "J1", R.ramp(10.0, 1.0))
        return net.simulate(1.0, np.linspace(0.0, 1.0, 11))

    strict = pair(True)
    assert sorted(e for _t, e, _m in strict.events) == ["c1", "c2"]
    assert [t for t, _e, _m in strict.events] == pytest.approx([4.0 / 7.5] * 2, abs=1e-9)
    assert all(m == "backward" for _t, _e, m in strict.events)        # (w_rel = w2 - w1 < 0: J1 driven)
    loose = pair(False)
    assert _times(loose, "c1") == pytest.approx([1.0 / 3.75], abs=1e-9)
    np.testing.assert_allclose(strict.columns["J1.w_rad_s"], loose.columns["J1.w_rad_s"], atol=1e-9)
