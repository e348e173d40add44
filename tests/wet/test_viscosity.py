import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.errors import DataError
from clutchlab.wet import WetClutch, atf_viscosity, fit_viscosity

TABLE1 = (0.1502, -0.07838, 0.05815, -0.02184)  # Pa*s, 1/K, Pa*s, 1/K


@pytest.mark.parametrize("temp, expected_mpas", [(40.0, 30.8068), (80.0, 10.4174), (100.0, 6.60637), (0.0, 208.35)])
def test_table1_viscosity(temp, expected_mpas):
    # hand calculation: 150.2 exp(-0.07838 T) + 58.15 exp(-0.02184 T) mPa*s
    assert atf_viscosity(temp, *TABLE1) * 1e3 == pytest.approx(expected_mpas, rel=1e-4)


def test_clutch_viscosity_property_is_table1():
    assert WetClutch.paper().viscosity == pytest.approx(TABLE1)


@settings(max_examples=examples(40), deadline=None)
@given(st.floats(-20, 180), st.floats(0.1, 50))
def test_viscosity_falls_with_temperature(t, dt):
    assert atf_viscosity(t + dt, *TABLE1) < atf_viscosity(t, *TABLE1)


def test_fit_viscosity_recovers_table1_from_noisy_samples():
    rng = np.random.default_rng(7)
    t = np.linspace(20, 130, 40)
    mu = atf_viscosity(t, *TABLE1) * (1 + 0.005 * rng.standard_normal(t.size))
    fit = fit_viscosity(t, mu)
    assert fit.rms_relative_error < 0.01
    np.testing.assert_allclose(fit(t), atf_viscosity(t, *TABLE1), rtol=0.01)
    assert fit.params[1] == pytest.approx(TABLE1[1], rel=0.1)
    assert fit.params[3] == pytest.approx(TABLE1[3], rel=0.1)
    assert "mu1" in fit.report()


def test_fit_viscosity_bad_input():
    with pytest.raises(DataError, match="samples"):
        fit_viscosity([1, 2, 3], [1, 2])
    with pytest.raises(DataError, match="non-positive"):
        fit_viscosity(np.arange(6.0), [0.1, 0.1, -0.1, 0.1, 0.1, 0.1])
    with pytest.raises(DataError, match="5 distinct"):
        fit_viscosity([1, 1, 2, 2, 3, 3], [0.1] * 6)
    with pytest.raises(DataError, match="non-finite"):
        fit_viscosity([1, 2, np.nan, 4, 5], [0.1] * 5)
