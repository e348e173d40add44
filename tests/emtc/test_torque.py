"""Torque transfer of the three friction elements (Eqs. 13-21)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.emtc import (
    CouplingGeometry,
    locked_capacities,
    locked_case,
    locked_torques,
    slipping_capacities,
    slipping_torques,
)
from clutchlab.errors import ParameterError

G = CouplingGeometry()
# a geometry with a3 = 2 lambda mu_s3 R3 / (3R) < 1/2: the third element saturates first (Fig. 12, Tcap1 > Tcap3)
G_B = CouplingGeometry(cam_ratio=2.5)


def coeffs(g, fn1):
    c1 = 2 / 3 * g.mu_s1 * g.radius1 * g.pairs1 * fn1
    a2 = 2 / 3 * g.mu_s2 * g.radius2 * g.pairs2 * g.cam_ratio / g.cam_radius
    a3 = 2 / 3 * g.mu_s3 * g.radius3 * g.cam_ratio / g.cam_radius
    return c1, a2, a3


def test_slipping_closed_form_eq15_and_consistency_with_eqs13_14():
    fn1 = 800.0
    t1, t2, t3 = slipping_torques(fn1, 3.0, G)
    lam, R = G.cam_ratio, G.cam_radius
    assert t1 == pytest.approx(2 / 3 * G.mu_k1 * G.radius1 * fn1 * G.pairs1, rel=1e-14)
    den = 3 * R - 2 * lam * G.mu_k3 * G.radius3
    assert t2 == pytest.approx(2 * lam * G.mu_k2 * G.radius2 * G.pairs2 / den * t1, rel=1e-14)
    assert t3 == pytest.approx(2 * lam * G.mu_k3 * G.radius3 / den * t1, rel=1e-14)
    fn2 = lam / R * (t1 + t3)  # Eq. 14
    assert t2 == pytest.approx(2 / 3 * G.mu_k2 * G.radius2 * fn2 * G.pairs2, rel=1e-12)  # Eq. 13
    assert t3 == pytest.approx(2 / 3 * G.mu_k3 * G.radius3 * fn2, rel=1e-12)
    # sign of the slip speed (Eq. 15), zero force -> zero torque
    assert slipping_torques(fn1, -0.1, G) == pytest.approx((-t1, -t2, -t3))
    assert slipping_torques(0.0, 1.0, G) == (0.0, 0.0, 0.0)


def test_slipping_capacities_eq16_17():
    t = slipping_torques(500.0, 1.0, G)
    caps, total = slipping_capacities(500.0, 1.0, G)
    assert caps == pytest.approx((G.mu_s1 / G.mu_k1 * t[0], G.mu_s2 / G.mu_k2 * t[1], G.mu_s3 / G.mu_k3 * t[2]))
    assert total == pytest.approx(sum(caps))


def test_locked_case_a_equal_split_eq18():
    t = locked_torques(1000.0, 30.0, G)
    assert t == pytest.approx((10.0, 10.0, 10.0))
    assert locked_case(1000.0, 30.0, G).startswith("a:")


def test_locked_case_b_third_element_saturated_eq19():
    fn1 = 1000.0
    c1, a2, a3 = coeffs(G_B, fn1)
    assert a3 < 0.5
    T = 40.0
    t = locked_torques(fn1, T, G_B)
    lam, R, mu, r3 = G_B.cam_ratio, G_B.cam_radius, G_B.mu_s3, G_B.radius3
    tl3 = lam * mu * r3 * T / (3 * R - lam * mu * r3)  # Eq. 19
    assert t[2] == pytest.approx(tl3, rel=1e-12)
    assert t[0] == pytest.approx((T - tl3) / 2) and t[1] == pytest.approx((T - tl3) / 2)
    assert t[2] == pytest.approx(2 / 3 * mu * r3 * lam / R * (t[0] + t[2]), rel=1e-12)  # T3 = T_cap_l3
    assert locked_case(fn1, T, G_B).startswith("b:")


def test_locked_case_c_eq20():
    fn1 = 300.0
    c1, a2, a3 = coeffs(G, fn1)
    T = 80.0
    t = locked_torques(fn1, T, G)
    lam, R = G.cam_ratio, G.cam_radius
    den = 3 * R - 2 * lam * G.mu_s3 * G.radius3
    assert t[0] == pytest.approx(c1, rel=1e-12)  # T_l1 = T_cap_l1
    assert t[2] == pytest.approx(2 * lam * G.mu_s3 * G.radius3 / den * c1, rel=1e-12)  # Eq. 20
    assert t[1] == pytest.approx(T - t[0] - t[2], rel=1e-12)
    caps, total = locked_capacities(fn1, G)
    assert caps[1] == pytest.approx(2 * lam * G.mu_s2 * G.radius2 * G.pairs2 / den * c1, rel=1e-12)  # Eq. 20
    assert total == pytest.approx(sum(caps))
    assert locked_case(fn1, T, G).startswith("c:")


def test_locked_mirrored_case_primary_saturates_first():
    fn1 = 300.0
    c1, a2, a3 = coeffs(G, fn1)
    assert a3 > 0.5
    T = 3 * c1 + 1.0  # just above the equal-split limit of the primary clutch
    t = locked_torques(fn1, T, G)
    assert t[0] == pytest.approx(c1)
    assert t[1] == pytest.approx((T - c1) / 2) and t[2] == pytest.approx((T - c1) / 2)
    assert locked_case(fn1, T, G).startswith("b'")


def test_locked_beyond_capacity_and_margin():
    fn1 = 500.0
    _, total = locked_capacities(fn1, G)
    assert locked_torques(fn1, 1.001 * total, G) is None
    t = locked_torques(fn1, 1.01 * total, G, margin=1.02)
    assert sum(t) == pytest.approx(1.01 * total)
    assert locked_torques(fn1, 1.03 * total, G, margin=1.02) is None
    assert locked_torques(0.0, 1.0, G) is None
    assert locked_torques(0.0, 0.0, G) == (0.0, 0.0, 0.0)


@settings(max_examples=examples(200), deadline=None)
@given(fn1=st.floats(1.0, 3000.0), frac=st.floats(-1.0, 1.0), cam=st.floats(1.0, 5.5))
def test_locked_sum_and_capacities_never_exceeded(fn1, frac, cam):
    g = CouplingGeometry(cam_ratio=cam)
    _, total = locked_capacities(fn1, g)
    T = frac * total
    t = locked_torques(fn1, T, g)
    assert t is not None
    assert sum(t) == pytest.approx(T, abs=1e-9 * total)
    c1, a2, a3 = coeffs(g, fn1)
    fn2_ratio = abs(t[0] + t[2])
    caps = (c1, a2 * fn2_ratio, a3 * fn2_ratio)  # capacities with F_n2 = lambda/R (T1 + T3)
    for x, c in zip(t, caps):
        assert abs(x) <= c + 1e-9 * total
        assert x * T >= -1e-12  # every element carries torque in the direction of T_lock
    # antisymmetry
    assert locked_torques(fn1, -T, g) == pytest.approx(tuple(-x for x in t), abs=1e-9 * total)


@pytest.mark.parametrize("geom", [G, G_B])
def test_locked_split_is_continuous_across_case_boundaries(geom):
    fn1 = 700.0
    _, total = locked_capacities(fn1, geom)
    T = np.linspace(0.0, total, 20001)
    tt = np.array([locked_torques(fn1, x, geom) for x in T])
    cases = [locked_case(fn1, x, geom) for x in T[::50]]
    assert len(set(cases)) >= 3  # the sweep passes through several distribution cases
    jumps = np.abs(np.diff(tt, axis=0)).max()
    assert jumps <= 2.0 * (T[1] - T[0]) * 1.0001  # Lipschitz: no element jumps at a case boundary


def test_geometry_signature_of_the_issue_and_toml_round_trip(tmp_path):
    g = CouplingGeometry(mu_k=(0.11, 0.12, 0.09), mu_s=(0.12, 0.13, 0.10), radius=(0.06, 0.07, 0.05),
                         pairs=(3, 8), cam_ratio=4.0, cam_radius=0.035)
    assert (g.mu_k1, g.mu_s3, g.radius2, g.pairs1, g.pairs2) == (0.11, 0.10, 0.07, 3, 8)
    assert CouplingGeometry.from_toml(g.to_toml(tmp_path / "coupling.toml")) == g


def test_geometry_validation():
    with pytest.raises(ParameterError, match="self-lock"):
        CouplingGeometry(cam_ratio=20.0)
    with pytest.raises(ParameterError, match="static friction"):
        CouplingGeometry(mu_s=(0.1, 0.13, 0.11), mu_k=(0.12, 0.12, 0.10))
    with pytest.raises(ParameterError, match=r"pairs\[0\] = -2.0: must be > 0"):
        CouplingGeometry(pairs=(-2, 10))
    with pytest.raises(ParameterError, match="pairs2 = 10.5: expected a whole number"):
        CouplingGeometry(pairs=(4, 10.5))
    with pytest.raises(ParameterError, match="mu_k.*expected 3 values"):
        CouplingGeometry(mu_k=(0.1, 0.1))
    with pytest.raises(ParameterError, match="fn1"):
        slipping_torques(-1.0, 1.0, G)
    with pytest.raises(ParameterError, match="t_lock"):
        locked_torques(1.0, np.nan, G)
    assert CouplingGeometry.from_dict({"radius": ["65 mm", "70 mm", "6 cm"]}).radius3 == pytest.approx(0.06)
