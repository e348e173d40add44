import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.wet import asperity_torque, clutch_torque, viscous_torque

R, N, A = 0.07758, 8, 5.551e-3


def test_asperity_torque_eq4():
    # 0.07758 * 8 * 0.12 * 1665 = 124.0 N*m
    assert asperity_torque(R, N, 0.12, 1665.0) == pytest.approx(0.07758 * 8 * 0.12 * 1665.0)


def test_viscous_torque_eq5():
    # 0.07758 * 8 * 0.01 Pa*s * 5.551e-3 m^2 * 2.44 m/s / 2e-4 m
    assert viscous_torque(R, N, 0.01, A, 2.44, 2e-4) == pytest.approx(0.07758 * 8 * 0.01 * 5.551e-3 * 2.44 / 2e-4)
    assert viscous_torque(R, N, 0.01, A, -2.44, 2e-4) == pytest.approx(-viscous_torque(R, N, 0.01, A, 2.44, 2e-4))


def test_clutch_torque_eq6_is_sum():
    tau = clutch_torque(R, N, 0.12, 1665.0, 0.01, A, 2.44, 2e-4)
    assert tau == pytest.approx(asperity_torque(R, N, 0.12, 1665.0) + viscous_torque(R, N, 0.01, A, 2.44, 2e-4))


@settings(max_examples=examples(50), deadline=None)
@given(st.floats(-30, 30).filter(lambda v: abs(v) > 1e-6), st.floats(0, 0.3), st.floats(0, 2e4),
       st.floats(1e-3, 0.2), st.floats(1e-7, 1e-2))
def test_torque_opposes_slip(v, mu, force, visc, film):
    tau = clutch_torque(R, N, mu, force, visc, A, v, film)
    assert tau * v >= 0.0  # dissipated power tau * v >= 0
    np.testing.assert_allclose(abs(tau), abs(asperity_torque(R, N, mu, force)) + abs(viscous_torque(R, N, visc, A, v, film)), rtol=1e-12)
