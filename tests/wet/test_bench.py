import math

import numpy as np
import pandas as pd
import pytest

from clutchlab.errors import DataError, ParameterError
from clutchlab.wet import Bench, ParametricFriction, WetClutch
from clutchlab.wet.bench import (
    RECORD_COLUMNS, EngagementProtocol, MapProtocol, load_protocol, read_bench_record, run_protocol, smoothed_ramp,
    write_bench_record,
)
from clutchlab.wet.data import DATA_DIR, ENGAGEMENT_RECORD, MAP_RECORDS

from .conftest import TEST_TRUTH


def test_map_protocol_record_shape(test_records):
    clutch, bench, runs = test_records
    run = runs[0]
    rec = run.record
    assert tuple(rec.columns) == RECORD_COLUMNS
    assert rec["time_s"].iloc[1] - rec["time_s"].iloc[0] == pytest.approx(1.0 / bench.sample_rate)
    proto = run.protocol
    t = rec["time_s"].to_numpy()
    true_w = run.result.state("slip_speed_rad_s")
    hold = (t > proto.preload_time + proto.spin_up_time + 1.0) & (t < proto.preload_time + proto.spin_up_time + proto.hold_time)
    # speed held at 300 rpm while the surface heats, as in Fig. 13
    np.testing.assert_allclose(true_w[hold], 300 * math.pi / 30, rtol=2e-3)
    temp = run.result.state("temperature_C")
    i_peak = np.argmax(temp)
    assert proto.preload_time + proto.spin_up_time + 5.0 < t[i_peak] < proto.preload_time + proto.spin_up_time + proto.hold_time + 5.0
    assert temp[i_peak] - temp[0] > 15.0
    # fluid and housing temperatures differ (Sec. 2.3)
    assert np.all(rec["fluid_temperature_C"] - rec["housing_temperature_C"] > 10.0)


def test_sensor_noise_levels_and_seed(test_records):
    clutch, bench, runs = test_records
    run = runs[0]
    res = run.result
    d_torque = run.record["torque_Nm"] - res.output("sensor_torque_Nm")
    d_temp = run.record["temperature_C"] - res.state("thermistor_temperature_C")
    assert np.std(d_torque) == pytest.approx(bench.noise_torque, rel=0.1)
    assert np.std(d_temp) == pytest.approx(bench.noise_temperature, rel=0.1)
    again = run_protocol(run.protocol, clutch, bench, TEST_TRUTH, seed=11)
    pd.testing.assert_frame_equal(again.record, run.record)
    other = run_protocol(run.protocol, clutch, bench, TEST_TRUTH, seed=99)
    assert not np.allclose(other.record["torque_Nm"], run.record["torque_Nm"])


def test_engagement_protocols_b_and_c_differ():
    clutch = WetClutch.paper()
    proto = EngagementProtocol(duration=1.0)
    b = run_protocol(proto, clutch, Bench(sample_rate=500.0), protocol_type="engagement")
    c = run_protocol(proto, clutch, Bench(sample_rate=500.0), protocol_type="inertia_dynamometer")
    # the force rises over 0.2 s in both
    fref = b.result.output("force_reference_N")
    t = b.result.time
    assert fref[np.searchsorted(t, proto.force_delay + proto.force_rise_time)] == pytest.approx(proto.force)
    # the dynamometer can only decelerate: it locks earlier; the bench follows the reference
    assert c.result.lockup_time < b.result.lockup_time
    assert np.all(c.result.output("drive_torque_Nm") == 0.0)
    ref = smoothed_ramp(t, proto.ramp_start, proto.ramp_time, proto.initial_slip_speed)
    assert np.max(np.abs(b.result.state("slip_speed_rad_s") - ref)) < 0.05 * proto.initial_slip_speed
    with pytest.raises(ParameterError, match="protocol_type"):
        run_protocol(proto, clutch, protocol_type="friction_map")


def test_record_round_trip_and_synthetic_header(tmp_path, test_records):
    run = test_records[2][0]
    p = write_bench_record(run, tmp_path / "r.csv")
    text = p.read_text().splitlines()
    assert text[0].startswith("# synthetic:")
    back = read_bench_record(p)
    np.testing.assert_allclose(back.to_numpy(), run.record.to_numpy(), rtol=1e-8, atol=1e-12)
    with pytest.raises(FileExistsError):
        write_bench_record(run, p)


def test_read_bench_record_errors(tmp_path, test_records):
    rec = test_records[2][0].record.iloc[:50]
    with pytest.raises(DataError, match="no such file"):
        read_bench_record(tmp_path / "missing.csv")
    rec.drop(columns=["force_N"]).to_csv(tmp_path / "a.csv", index=False)
    with pytest.raises(DataError, match=r"a\.csv.*missing column 'force_N'"):
        read_bench_record(tmp_path / "a.csv")
    bad = rec.copy()
    bad.loc[7, "temperature_C"] = np.nan
    bad.to_csv(tmp_path / "b.csv", index=False)
    with pytest.raises(DataError, match=r"b\.csv.*'temperature_C'.*row 7"):
        read_bench_record(tmp_path / "b.csv")
    back = rec.copy()
    back.loc[5, "time_s"] = back.loc[3, "time_s"]
    back.to_csv(tmp_path / "c.csv", index=False)
    with pytest.raises(DataError, match="time_s.*increasing"):
        read_bench_record(tmp_path / "c.csv")
    rec.iloc[:5].to_csv(tmp_path / "d.csv", index=False)
    with pytest.raises(DataError, match="at least 10"):
        read_bench_record(tmp_path / "d.csv")


def test_load_protocol(tmp_path):
    proto, ptype, clutch, bench, friction = load_protocol(DATA_DIR / "map_protocol.toml")
    assert ptype == "friction_map" and isinstance(proto, MapProtocol)
    assert proto.slip_speed == pytest.approx(300 * math.pi / 30)
    assert bench.sample_rate == 200.0 and clutch == WetClutch.paper()
    assert friction == ParametricFriction.bench_truth()
    (tmp_path / "p.toml").write_text('[protocol]\ntype = "engagement"\nforce = "4 kN"\n[friction]\nmu0 = 0.1\n')
    proto, ptype, *_, friction = load_protocol(tmp_path / "p.toml")
    assert proto.force == 4000.0 and friction.mu0 == 0.1 and friction.v_s == ParametricFriction.bench_truth().v_s
    for body, msg in [('[protocol]\ntype = "warp"\n', "type"), ('[protocol]\ntype = "engagement"\nspeed = 3\n', "unknown"),
                      ('[protocol]\ntype = "engagement"\n[oil]\nx=1\n', "unknown table"), ("[wet]\nn_c = 8\n", "missing"),
                      ('[protocol]\ntype = "engagement"\nforce = "4 m"\n', "force")]:
        (tmp_path / "x.toml").write_text(body)
        with pytest.raises(ParameterError, match=msg):
            load_protocol(tmp_path / "x.toml")


def test_bundled_data_is_small_and_synthetic():
    files = [DATA_DIR / n for n in MAP_RECORDS + (ENGAGEMENT_RECORD,)]
    assert sum(f.stat().st_size for f in files) < 1_000_000
    for f in files:
        assert f.read_text().startswith("# synthetic:")
        assert len(read_bench_record(f)) > 500
