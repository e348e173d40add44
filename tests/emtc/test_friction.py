"""Friction (constant, map, LuGre Eqs. 22-24) and drag torque (Eqs. 25-26)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.emtc import FrictionMap, LuGreParameters, coupling_torque, drag_torque, lugre_simulate, lugre_steady_state, stribeck
from clutchlab.errors import DataError, ParameterError

P = LuGreParameters()


def test_stribeck_curve_eq24():
    assert stribeck(0.0, P) == pytest.approx(P.mu_p)
    assert stribeck(1e6, P) == pytest.approx(P.mu_c)
    v = P.v_s
    assert stribeck(v, P) == pytest.approx(P.mu_c + (P.mu_p - P.mu_c) * math.exp(-1.0))


@pytest.mark.parametrize("v", [-20.0, -1.0, 0.3, 2.0, 15.0])
def test_lugre_steady_state_equals_stribeck(v):
    """At constant slip the LuGre coefficient settles on g(v) sgn(v) + sigma2 v (Eqs. 22-24)."""
    t = np.linspace(0.0, 2.0, 2001)
    res = lugre_simulate(t, np.full(t.size, v), P)
    mu_ss, z_ss = lugre_steady_state(v, P)
    assert res.mu[-1] == pytest.approx(math.copysign(stribeck(v, P), v) + P.sigma2 * v, rel=1e-9)
    assert res.mu[-1] == pytest.approx(mu_ss, rel=1e-9)
    assert res.z[-1] == pytest.approx(z_ss, rel=1e-9)


def test_lugre_exact_step_is_independent_of_sampling():
    """The bristle update is the exact solution for constant slip: coarse and fine sampling agree."""
    v = 0.8
    fine = lugre_simulate(np.linspace(0, 0.01, 10001), np.full(10001, v), P)
    coarse = lugre_simulate(np.array([0.0, 0.01]), np.array([v, v]), P)
    assert coarse.z[-1] == pytest.approx(fine.z[-1], rel=1e-12)
    g = stribeck(v, P)
    expect = g / P.sigma0 * (1 - math.exp(-P.sigma0 * v * 0.01 / g))
    assert coarse.z[-1] == pytest.approx(expect, rel=1e-12)


@settings(max_examples=examples(50), deadline=None)
@given(speeds=st.lists(st.floats(-50, 50), min_size=2, max_size=80), dt=st.floats(1e-6, 1.0))
def test_lugre_bristle_state_bounded(speeds, dt):
    t = np.arange(len(speeds)) * dt
    res = lugre_simulate(t, np.array(speeds), P)
    assert np.all(np.abs(res.z) <= P.mu_p / P.sigma0 * (1 + 1e-12))
    assert np.all(np.isfinite(res.mu))


def test_lugre_bad_input():
    with pytest.raises(DataError, match="strictly increasing"):
        lugre_simulate([0.0, 0.0], [1.0, 1.0], P)
    with pytest.raises(DataError, match="non-finite"):
        lugre_simulate([0.0, 1.0], [1.0, np.nan], P)
    with pytest.raises(ParameterError, match="sigma0"):
        LuGreParameters(sigma0=-1.0)


def test_drag_torque_eq25():
    t = drag_torque(12, 0.02, 30.0, 0.2e-3, 0.075, 0.055)
    assert t == pytest.approx(12 * math.pi * 30.0 * 0.02 / (2 * 0.2e-3) * (0.075**4 - 0.055**4), rel=1e-14)
    np.testing.assert_allclose(drag_torque(12, 0.02, np.array([-30.0, 0.0, 60.0]), 0.2e-3, 0.075, 0.055),
                               [-t, 0.0, 2 * t])
    with pytest.raises(ParameterError, match="n_pairs"):
        drag_torque(-1, 0.02, 1.0, 0.2e-3, 0.075, 0.055)
    with pytest.raises(ParameterError, match="n_pairs"):
        drag_torque(2.5, 0.02, 1.0, 0.2e-3, 0.075, 0.055)
    with pytest.raises(ParameterError, match="clearance"):
        drag_torque(2, 0.02, 1.0, 0.0, 0.075, 0.055)
    with pytest.raises(ParameterError, match="r_inner"):
        drag_torque(2, 0.02, 1.0, 1e-4, 0.05, 0.06)


def test_eq26_selects_drag_or_friction():
    np.testing.assert_array_equal(coupling_torque([False, True], [1.0, 1.0], [50.0, 50.0]), [1.0, 50.0])


def test_friction_map_bilinear_and_clamped():
    fm = FrictionMap([0.0, 10.0], [20.0, 100.0], [[0.14, 0.12], [0.10, 0.08]])
    assert fm(5.0, 60.0) == pytest.approx(0.11)
    assert fm(-5.0, 60.0) == pytest.approx(0.11)  # symmetric in the slip direction
    assert fm(50.0, 200.0) == pytest.approx(0.08)  # clamped
    with pytest.raises(DataError, match="shape"):
        FrictionMap([0.0, 10.0], [20.0, 100.0], [[0.1, 0.1]])
    with pytest.raises(DataError, match="strictly increasing"):
        FrictionMap([0.0, 0.0], [20.0, 100.0], [[0.1, 0.1], [0.1, 0.1]])
