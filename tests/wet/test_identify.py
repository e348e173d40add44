import numpy as np
import pytest

from clutchlab.errors import DataError, IdentificationError
from clutchlab.wet import Bench, ParametricFriction, WetClutch
from clutchlab.wet.bench import MapProtocol, run_protocol
from clutchlab.wet.identify import friction_samples, identify_friction_map, identify_thermal

from .conftest import TEST_CLUTCH, TEST_TRUTH


def test_records_use_non_default_parameters(test_records):
    clutch, _, runs = test_records
    assert (clutch.k1, clutch.k2) != (WetClutch.paper().k1, WetClutch.paper().k2)
    assert TEST_TRUTH != ParametricFriction() and TEST_TRUTH != ParametricFriction.bench_truth()


def test_friction_map_recovers_the_true_law(test_records):
    clutch, bench, runs = test_records
    fmap = identify_friction_map([r.record for r in runs], clutch, sensor_time_constant=bench.thermistor_time_constant)
    law = fmap.law
    assert law.mu_t == pytest.approx(TEST_TRUTH.mu_t, rel=0.03)
    assert law.mu_e == pytest.approx(TEST_TRUTH.mu_e, rel=0.05)
    assert law.v_s == pytest.approx(TEST_TRUTH.v_s, rel=0.05)
    assert law.mu(10.0, law.t_ref) == pytest.approx(TEST_TRUTH.mu(10.0, law.t_ref), abs=1e-3)
    # the optimiser did not start at the answer: the initial guess comes from the data
    guess = fmap.statistics["initial_guess"]
    assert abs(guess["v_s"] - TEST_TRUTH.v_s) > 0.1
    # the table over the covered region matches the true map
    vv, tt = np.meshgrid(fmap.speed_grid, fmap.temperature_grid)
    err = (fmap.values - TEST_TRUTH.mu(vv, tt))[fmap.covered]
    assert fmap.covered.sum() >= 20
    assert np.max(np.abs(err)) < 3e-3
    v = np.linspace(*fmap.region["slip_velocity_m_s"], 30)
    t = np.linspace(*fmap.region["temperature_C"], 30)
    np.testing.assert_allclose(law.mu(*np.meshgrid(v, t)), TEST_TRUTH.mu(*np.meshgrid(v, t)), atol=1e-3)
    st = fmap.statistics
    assert st["r2"] > 0.99 and st["rmse"] < 2e-3 and set(st["stderr"]) == {"mu0", "mu_t", "mu_e", "v_s"}
    assert fmap.region["temperature_C"][0] < 60 and fmap.region["temperature_C"][1] > 105


def test_viscous_torque_is_subtracted(test_records):
    clutch, bench, runs = test_records
    s = friction_samples(runs[0].record, clutch)
    assert s["viscous_torque_Nm"].abs().max() > 0.5
    # ignoring the viscous torque (a thinner clutch film) would bias mu_f upwards
    thick = friction_samples(runs[0].record, clutch.replace(sigma=6e-3))
    assert thick["mu_f"].mean() > s["mu_f"].mean()


def test_thermal_identification_recovers_k1_k2(test_records):
    clutch, bench, runs = test_records
    fit = identify_thermal([r.record for r in runs], clutch, sensor_time_constant=bench.thermistor_time_constant)
    assert fit.k1 == pytest.approx(TEST_CLUTCH["k1"], rel=0.03)
    assert fit.k2 == pytest.approx(TEST_CLUTCH["k2"], rel=0.03)
    for k in ("k1", "k2"):
        lo, hi = fit.ci95[k]
        assert lo < getattr(fit, k) < hi and 0 < fit.stderr[k] < 0.05 * getattr(fit, k)
    assert "k1" in fit.report()


def test_thermal_needs_distinct_fluid_and_housing_temperatures(test_records):
    clutch, bench, runs = test_records
    rec = runs[0].record.copy()
    rec["housing_temperature_C"] = rec["fluid_temperature_C"]
    with pytest.raises(IdentificationError, match="fluid and housing"):
        identify_thermal(rec, clutch)


def test_identification_bad_input(tmp_path, test_records):
    clutch, bench, runs = test_records
    with pytest.raises(DataError, match="missing column"):
        identify_friction_map(runs[0].record.drop(columns=["piston_position_m"]), clutch)
    still = runs[0].record.iloc[:200]  # preload only: no slip
    with pytest.raises(IdentificationError, match="samples"):
        identify_friction_map(still, clutch)
    with pytest.raises(DataError, match="no bench records"):
        identify_friction_map([], clutch)


def test_noise_free_record_gives_near_exact_law():
    quiet = Bench(sample_rate=50.0, noise_torque=0, noise_speed=0, noise_force=0, noise_position=0,
                  noise_temperature=0, noise_fluid_temperature=0)
    clutch = WetClutch.paper()
    runs = [run_protocol(MapProtocol(fluid_temperature=tf, housing_temperature=th), clutch, quiet, TEST_TRUTH)
            for tf, th in ((85.0, 65.0), (55.0, 40.0))]
    fmap = identify_friction_map([r.record for r in runs], clutch, sensor_time_constant=quiet.thermistor_time_constant,
                                 min_count=5)
    assert fmap.law.mu_t == pytest.approx(TEST_TRUTH.mu_t, rel=0.01)
    assert fmap.law.v_s == pytest.approx(TEST_TRUTH.v_s, rel=0.02)
