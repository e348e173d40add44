"""Reading and writing records: CSV, Parquet, DataFrames, round trips, resampling, the subsystem readers."""

import math
from importlib import resources

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab.errors import DataError, ParameterError
from clutchlab.io import read_measurement, read_table, resample, write_measurement

from .conftest import LOGGER_MAP

RPM = 2 * math.pi / 60


def bench_like(n=50):
    t = np.arange(n) * 2e-3
    return pd.DataFrame({"time_s": t, "torque_Nm": 40 + 10 * t, "force_N": 1500 + 0 * t,
                         "temperature_C": 80 + t})


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mf4"])
def test_round_trip_with_units_and_provenance(tmp_path, logger_file, suffix):
    m = read_measurement(logger_file, LOGGER_MAP, rate=100.0)
    out = write_measurement(m, tmp_path / f"rec{suffix}", comment="converted in a test")
    back = read_measurement(out)
    assert list(back.frame.columns) == list(m.frame.columns)
    assert back.units == m.units
    # CSV keeps 9 significant digits (clutchlab.io.atomic_to_csv), Parquet and MDF are exact
    rtol = 5e-9 if suffix == ".csv" else 0.0
    np.testing.assert_allclose(back.frame.to_numpy(), m.frame.to_numpy(), rtol=rtol, atol=1e-12)
    assert back.source.synthetic and "converted in a test" in back.source.comments
    with pytest.raises(FileExistsError):
        write_measurement(m, out)
    again = write_measurement(back, out, overwrite=True)
    assert read_measurement(again).units == m.units
    assert sorted(p.name for p in tmp_path.iterdir()) == ["logger.mf4", f"rec{suffix}"]  # nothing half-written


def test_units_in_a_file_are_converted_to_the_names_units(tmp_path):
    # a CSV in engineering units: the "# units:" line tells the reader, the names say the target
    (tmp_path / "eng.csv").write_text("# synthetic: hand-written\n# units: time_s=ms, speed_rad_s=rpm, "
                                      "torque_Nm=kN*m, temperature_C=degF\n"
                                      "time_s,speed_rad_s,torque_Nm,temperature_C\n0,600,0.5,212\n10,900,1.5,32\n")
    m = read_measurement(tmp_path / "eng.csv")
    np.testing.assert_allclose(m.time, [0.0, 0.01])
    np.testing.assert_allclose(m["speed_rad_s"], [600 * RPM, 900 * RPM])
    np.testing.assert_allclose(m["torque_Nm"], [500.0, 1500.0])
    np.testing.assert_allclose(m["temperature_C"], [100.0, 0.0], atol=1e-12)
    assert m.source.synthetic and m.units["speed_rad_s"] == "rad/s"
    # a logger CSV with its own names: the map renames and converts
    (tmp_path / "log.csv").write_text("t,N_Eng,TQ\n0,1000,5\n0.5,2000,6\n1.0,3000,7\n")
    m = read_measurement(tmp_path / "log.csv",
                         {"time_s": {"source": "t", "source_unit": "s"},
                          "speed_rad_s": {"source": "N_Eng", "source_unit": "rpm"},
                          "torque_Nm": {"source": "TQ", "source_unit": "N*m"}}, rate=4.0)
    np.testing.assert_allclose(m.time, [0, 0.25, 0.5, 0.75, 1.0])
    np.testing.assert_allclose(m["speed_rad_s"], np.array([1000, 1500, 2000, 2500, 3000]) * RPM)
    assert not m.source.synthetic
    with pytest.raises(DataError, match=r"log\.csv: channel 'TQ' \(for 'torque_Nm'\) carries no unit"):
        read_measurement(tmp_path / "log.csv", {"time_s": "t", "torque_Nm": "TQ"})
    with pytest.raises(DataError, match=r"log\.csv: missing column 'time_s'"):
        read_measurement(tmp_path / "log.csv", {"torque_Nm": {"source": "TQ", "source_unit": "N*m"}})
    with pytest.raises(ParameterError, match="group"):
        read_measurement(tmp_path / "log.csv", {"time_s": "t", "torque_Nm": {"source": "TQ", "group": 1}})


def test_csv_errors_name_file_column_and_row(tmp_path):
    rec = bench_like()
    bad = rec.copy()
    bad.loc[7, "temperature_C"] = np.nan
    bad.to_csv(tmp_path / "nan.csv", index=False)
    with pytest.raises(DataError, match=r"nan\.csv: column 'temperature_C' has a non-finite .* at row 7"):
        read_measurement(tmp_path / "nan.csv", required=["temperature_C"])
    # ... unless allowed; channels not required pass NaN through, as read_table does
    for kw in (dict(allow_nan=["temperature_C"], required=["temperature_C"]), {}):
        assert np.isnan(read_measurement(tmp_path / "nan.csv", **kw)["temperature_C"][7])
    text = rec.astype(object)
    text.loc[3, "force_N"] = "1.5 kN"
    text.to_csv(tmp_path / "text.csv", index=False)
    with pytest.raises(DataError, match=r"text\.csv: column 'force_N' has a non-finite or non-numeric value '1.5 kN' "
                                        r"at row 3"):
        read_measurement(tmp_path / "text.csv", required=["force_N"])
    back = rec.copy()
    back.loc[12, "time_s"] = back.loc[10, "time_s"]
    back.to_csv(tmp_path / "back.csv", index=False)
    with pytest.raises(DataError, match=r"back\.csv: time_s must increase strictly, but row 12 has 0\.02 after "
                                        r"0\.022"):
        read_measurement(tmp_path / "back.csv")
    (tmp_path / "units.csv").write_text("# units: time_s=s, force_N=furlong\ntime_s,force_N\n0,1\n1,2\n")
    with pytest.raises(DataError, match=r"units\.csv: channel 'force_N': unit 'furlong' cannot be converted to 'N'"):
        read_measurement(tmp_path / "units.csv", required=["force_N"])
    # not asked for: skipped with the reason; nothing else to read is still an error
    with pytest.raises(DataError, match=r"units\.csv: no channel could be read \(1 skipped; force_N: unit 'furlong' "
                                        r"cannot be converted to 'N'"):
        read_measurement(tmp_path / "units.csv")
    (tmp_path / "units2.csv").write_text("# units: time_s=s, force_N=zorch, x_m=mm\ntime_s,force_N,x_m\n0,1,1\n1,2,2\n")
    with pytest.raises(DataError, match=r"units2\.csv: channel 'force_N': unknown unit 'zorch'"):
        read_measurement(tmp_path / "units2.csv", required=["force_N"])
    m = read_measurement(tmp_path / "units2.csv")
    assert m.channels == ("x_m",) and m.source.skipped == {"force_N": "unknown unit 'zorch'"}
    np.testing.assert_allclose(m["x_m"], [1e-3, 2e-3])
    (tmp_path / "bin.csv").write_bytes(b"\xff\xfe\x00garbage\x00\x81")
    with pytest.raises(DataError, match=r"bin\.csv: cannot read as CSV"):
        read_measurement(tmp_path / "bin.csv")
    with pytest.raises(DataError, match=r"unknown record format '\.xlsx'"):
        (tmp_path / "r.xlsx").write_text("x")
        read_measurement(tmp_path / "r.xlsx")


def test_identity_read_passes_other_columns_through_like_read_table(tmp_path):
    rec = bench_like()
    rec["note"] = "ok"
    rec.loc[4, "force_N"] = np.nan
    rec.to_csv(tmp_path / "r.csv", index=False)
    m = read_measurement(tmp_path / "r.csv", required=["time_s", "torque_Nm"])
    old = read_table(tmp_path / "r.csv", ["time_s", "torque_Nm"])
    assert list(m.frame.columns) == list(old.columns)
    pd.testing.assert_frame_equal(m.frame, old, check_dtype=False)


@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
def test_parquet_units_and_malformed_file(tmp_path):
    import pyarrow.parquet as pq

    rec = bench_like()
    out = write_measurement(rec, tmp_path / "r.parquet", units={"force_N": "N"}, comment="synthetic: test")
    schema = pq.read_schema(out)
    assert schema.field("torque_Nm").metadata[b"unit"] == b"N*m"
    assert read_measurement(out).source.synthetic
    data = out.read_bytes()
    (tmp_path / "cut.parquet").write_bytes(data[: len(data) // 2])
    with pytest.raises(DataError, match=r"cut\.parquet: not a readable Parquet file"):
        read_measurement(tmp_path / "cut.parquet")


def test_table_without_time(tmp_path):
    frame = pd.DataFrame({"airgap": [1e-3, 1e-3], "current": [0.0, 1.0], "force": [0.0, 10.0]})
    m = read_measurement(frame, required=["current", "force"], time=None)
    assert m.time is None and m.units["current"] == "A"
    with pytest.raises(ParameterError, match="needs a time column"):
        read_measurement(frame, time=None, rate=10.0)
    with pytest.raises(DataError, match="an MDF file needs a time column"):
        write_measurement(m, tmp_path / "t.mf4")
    out = write_measurement(m, tmp_path / "t.csv")
    assert read_measurement(out, time=None).units == {"airgap": "m", "current": "A", "force": "N"}


@settings(max_examples=examples(40), deadline=None)
@given(st.lists(st.floats(1e-3, 1.0), min_size=2, max_size=30), st.floats(-5, 5), st.floats(-5, 5),
       st.lists(st.floats(0, 1), min_size=1, max_size=20))
def test_resample_properties(steps, slope, intercept, where):
    ts = np.concatenate([[0.0], np.cumsum(steps)])
    grid = np.sort(np.array(where) * ts[-1])
    # linear interpolation reproduces a straight line exactly
    np.testing.assert_allclose(resample(ts, intercept + slope * ts, grid), intercept + slope * grid, atol=1e-9)
    # sample-and-hold returns recorded samples, the latest at or before each time: monotone input stays monotone
    ys = np.cumsum(np.abs(np.sin(ts * 7)))
    held = resample(ts, ys, grid, "previous")
    assert np.isin(held, ys).all() and np.all(np.diff(held) >= 0)
    idx = np.array([np.max(np.flatnonzero(ts <= g)) for g in grid])
    np.testing.assert_array_equal(held, ys[idx])
    with pytest.raises(ParameterError, match="interpolation"):
        resample(ts, ys, grid, "cubic")


# ---------------------------------------------------------------- the subsystem readers go through this layer

def test_wet_bench_record_from_a_logger_mf4(tmp_path):
    from asammdf import MDF, Signal

    from clutchlab.wet.bench import RECORD_COLUMNS, read_bench_record, write_bench_record

    with resources.as_file(resources.files("clutchlab.wet") / "data" / "engagement_bench.csv") as p:
        rec = read_bench_record(p)
    t = rec["time_s"].to_numpy()
    mdf = MDF(version="4.10")
    # the logger records speed in rpm, force in kN, torque as int32 counts of 0.01 N m, temperatures in degC
    mdf.append([Signal(rec["slip_speed_rad_s"].to_numpy() / RPM, t, name="nSlip", unit="rpm"),
                Signal(np.round(rec["torque_Nm"].to_numpy() * 100).astype(np.int32), t, name="TqCnt", unit="Nm",
                       conversion={"a": 0.01, "b": 0.0}),
                Signal(rec["force_N"].to_numpy() / 1e3, t, name="F", unit="kN"),
                Signal(rec["piston_position_m"].to_numpy() * 1e3, t, name="x", unit="mm")])
    mdf.append([Signal(rec[c].to_numpy(), t, name=c.replace("_C", ""), unit="°C")
                for c in ("temperature_C", "fluid_temperature_C", "housing_temperature_C")])
    path = mdf.save(tmp_path / "bench.mf4")
    mdf.close()
    cmap = {"slip_speed_rad_s": "nSlip", "torque_Nm": "TqCnt", "force_N": "F", "piston_position_m": "x",
            "temperature_C": "temperature", "fluid_temperature_C": "fluid_temperature",
            "housing_temperature_C": "housing_temperature"}
    back = read_bench_record(path, cmap)
    assert list(back.columns) == list(RECORD_COLUMNS)
    np.testing.assert_allclose(back["torque_Nm"], rec["torque_Nm"], atol=0.005 + 1e-9)  # counts of 0.01 N m
    for c in ("slip_speed_rad_s", "force_N", "piston_position_m", "temperature_C"):
        np.testing.assert_allclose(back[c], rec[c], rtol=1e-12, atol=1e-15)
    with pytest.raises(DataError, match=r"bench\.mf4: missing channel 'nslip' \(for 'slip_speed_rad_s'\)"):
        read_bench_record(path, {**cmap, "slip_speed_rad_s": "nslip"})
    # and written as MDF 4 or Parquet by the bench writer, read back unchanged
    for suffix in (".mf4", ".parquet"):
        out = write_bench_record(rec, tmp_path / f"again{suffix}")
        np.testing.assert_allclose(read_bench_record(out).to_numpy(), rec.to_numpy(), rtol=1e-12)
        assert read_measurement(out).source.synthetic


def test_full_clutch_record_through_a_channel_map(tmp_path):
    from clutchlab.eclutch.datasets import load_full_clutch_record
    from clutchlab.eclutch.validation import read_full_clutch_record

    rec = load_full_clutch_record()
    logger = pd.DataFrame({"t_ms": rec["time_s"] * 1e3, "s_bearing": rec["bearing_position_m"] * 1e3,
                           "F_b": rec["bearing_force_N"] / 1e3, "M": rec["torque_Nm"]})
    write_measurement(logger, tmp_path / "fc.parquet", units={"t_ms": "ms", "s_bearing": "mm", "F_b": "kN", "M": "Nm"},
                      time="t_ms")
    back = read_full_clutch_record(tmp_path / "fc.parquet",
                                   channel_map={"time_s": "t_ms", "bearing_position_m": "s_bearing",
                                                "bearing_force_N": "F_b", "torque_Nm": "M"})
    for c in ("time_s", "bearing_position_m", "bearing_force_N", "torque_Nm"):
        np.testing.assert_allclose(back[c], rec[c], rtol=1e-12, atol=1e-12)


def test_emtc_forc_table_reader_accepts_parquet(tmp_path):
    from clutchlab.emtc.magnet import bundled_forc

    forc = bundled_forc()
    out = write_measurement(forc, tmp_path / "forc.parquet", time=None)
    back = read_measurement(out, required=["airgap", "current", "force"], time=None)
    pd.testing.assert_frame_equal(back.frame, forc)
    assert back.units == {"airgap": "m", "current": "A", "force": "N"}


def test_a_column_named_twice_is_an_error_not_a_renamed_channel(tmp_path):
    """pandas renamed the second ``torque_Nm`` to ``torque_Nm.1`` and read it as another channel (#33)."""
    from clutchlab.io import read_measurement
    from clutchlab.report.run import find_datasets

    path = tmp_path / "run" / "twice.csv"
    path.parent.mkdir()
    path.write_text("# units: time_s=s\ntime_s,torque_Nm,torque_Nm\n0,1,2\n1,3,4\n")
    with pytest.raises(DataError, match=r"twice\.csv: column 'torque_Nm' appears twice in the header"):
        read_measurement(path)
    datasets, failed = find_datasets(path.parent)
    assert not datasets and "column 'torque_Nm' appears twice" in failed[0][1]


def test_an_implausible_channel_nobody_asked_for_is_skipped_not_the_whole_file(tmp_path, capsys):
    """#33: a UNIX time in ns (1.7e18) or a conversion overflowing to -inf in one channel of a file read
    without a map is a warning and the rest of the file, not a refusal; asked for, it stays an error."""
    from clutchlab.cli import main

    path = tmp_path / "log.csv"
    path.write_text("# units: big_N=kN\ntime_s,stamp,force_N,big_N\n0,1.7e18,1,-1e306\n1,1.7e18,2,-1e306\n")
    m = read_measurement(path)
    assert m.channels == ("force_N",)
    assert "implausible value 1.7e+18" in m.source.skipped["stamp"]
    assert "implausible value -inf N" in m.source.skipped["big_N"]
    with pytest.raises(DataError, match=r"channel 'stamp' has an implausible value 1\.7e\+18"):
        read_measurement(path, required=["stamp"])
    assert main(["convert", str(path), "-o", str(tmp_path / "out.parquet")]) == 0
    err = capsys.readouterr().err
    assert "skipped stamp: an implausible value" in err and "skipped big_N" in err
    assert read_measurement(tmp_path / "out.parquet").channels == ("force_N",)
    # the time column is never skipped: the error suggests its unit
    path.write_text("time_s,force_N\n1.7e18,1\n1.8e18,2\n")
    with pytest.raises(DataError, match=r"if it is a UNIX time in ns, us or ms, state the unit \(a '# units: "
                                        r"time_s=ns' line"):
        read_measurement(path)
    path.write_text("# units: time_s=ns\ntime_s,force_N\n1.7e18,1\n1.8e18,2\n")
    np.testing.assert_allclose(read_measurement(path)["time_s"], [1.7e9, 1.8e9])
