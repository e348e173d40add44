"""Identification refuses what the records cannot determine, and bad sensor lags."""

import math

import pytest

from clutchlab.errors import IdentificationError, ParameterError
from clutchlab.wet import Bench, WetClutch
from clutchlab.wet.bench import EngagementProtocol, MapProtocol, run_protocol
from clutchlab.wet.identify import friction_samples, identify_friction_map, identify_thermal
from cli_checks import one_line_error


@pytest.fixture(scope="module")
def engagement():
    """One engagement (Fig. 14 protocol): slip speeds 0..12 m/s, no cooling phase."""
    return run_protocol(EngagementProtocol(), WetClutch.paper(), Bench(sample_rate=200.0),
                        protocol_type="engagement").record




@pytest.mark.parametrize("lag", [math.nan, math.inf, -0.1])
def test_sensor_lag_must_be_finite_and_nonnegative(engagement, lag):
    clutch = WetClutch.paper()
    for func in (friction_samples, identify_friction_map, identify_thermal):
        with pytest.raises(ParameterError, match=rf"sensor_time_constant = {lag!r}: must be finite and >= 0"):
            func(engagement, clutch, sensor_time_constant=lag)


def test_engagement_alone_does_not_determine_the_friction_law(engagement):
    v_max = friction_samples(engagement, WetClutch.paper())["slip_velocity_m_s"].max()
    with pytest.raises(IdentificationError, match=r"v_s = [\d.]+ m/s lies beyond the fastest recorded slip "
                                                  rf"velocity {v_max:.3g} m/s"):
        identify_friction_map(engagement, WetClutch.paper())


def test_engagement_alone_gives_a_negative_conductance_which_is_refused(engagement):
    with pytest.raises(IdentificationError, match=r"k1 = -[\d.]+ \+/- [\d.]+ W/K is negative"):
        identify_thermal(engagement, WetClutch.paper())


def test_conductance_not_determined_by_the_records_is_refused():
    """No conduction to the housing (k2 = 0): the estimate is noise, its error larger than itself."""
    clutch = WetClutch.paper(k2=0.0)
    bench = Bench(sample_rate=100.0)
    rec = run_protocol(MapProtocol(), clutch, bench, seed=2).record
    with pytest.raises(IdentificationError, match=r"k2 = [-\d.e]+ \+/- [\d.]+ W/K: the standard error is not "
                                                  "smaller than the value"):
        identify_thermal(rec, clutch, sensor_time_constant=bench.thermistor_time_constant)
    # the same records with conduction determine k2
    clutch = WetClutch.paper()
    rec = run_protocol(MapProtocol(), clutch, bench, seed=2).record
    fit = identify_thermal(rec, clutch, sensor_time_constant=bench.thermistor_time_constant)
    assert fit.k2 == pytest.approx(clutch.k2, rel=0.1) and fit.stderr["k2"] < 0.2 * fit.k2


@pytest.mark.parametrize("lag", ["nan", "inf"])
def test_cli_sensor_lag(tmp_path, capsys, engagement, lag):
    rec = tmp_path / "eng.csv"
    engagement.to_csv(rec, index=False)
    line = one_line_error(capsys, ["wet", "identify", str(rec), "-o", str(tmp_path / "m.json"), f"--sensor-lag={lag}"])
    assert f"--sensor-lag = {float(lag)!r}: must be finite and >= 0" in line
    assert not (tmp_path / "m.json").exists()


def test_cli_identify_on_an_engagement_record_exits_2(tmp_path, capsys, engagement):
    rec = tmp_path / "eng.csv"
    engagement.to_csv(rec, index=False)
    line = one_line_error(capsys, ["wet", "identify", str(rec), "-o", str(tmp_path / "m.json")])
    assert "friction law: v_s = " in line and "lies beyond the fastest recorded slip velocity" in line
    assert not (tmp_path / "m.json").exists()
