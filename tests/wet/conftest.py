"""Shared fixtures of the wet-clutch tests: bench records generated with non-default parameters."""

import pytest

from clutchlab.wet import Bench, ParametricFriction, WetClutch

#: clutch in the test rig: Table 1 with other conductances (not the defaults)
TEST_CLUTCH = dict(k1=100.0, k2=55.0)
#: the true friction law of the test records (neither the defaults nor the bench truth)
TEST_TRUTH = ParametricFriction(mu0=0.14, mu_t=1.0e-3, mu_e=-0.035, v_s=0.5, t_ref=90.0)


@pytest.fixture(scope="session")
def test_records():
    """Three friction-map experiments at 100 Hz on a clutch with k1 = 100, k2 = 55 W/K."""
    import math

    from clutchlab.wet.bench import MapProtocol, run_protocol

    clutch = WetClutch.paper(**TEST_CLUTCH)
    bench = Bench(sample_rate=100.0)
    cases = [(1665.0, 300, 85.0, 65.0, 11), (2500.0, 200, 60.0, 45.0, 12), (1200.0, 400, 100.0, 75.0, 13)]
    runs = [run_protocol(MapProtocol(force=f, slip_speed=rpm * math.pi / 30, fluid_temperature=tf,
                                     housing_temperature=th), clutch, bench, TEST_TRUTH, seed=s)
            for f, rpm, tf, th, s in cases]
    return clutch, bench, runs
