"""MDF 4 files written by asammdf: channel selection, conversions, resampling, malformed files."""

import gc
import math
from pathlib import Path

import numpy as np
import pytest
from asammdf import MDF, Signal

from clutchlab.errors import DataError, ParameterError
from clutchlab.io import ChannelMap, read_measurement, write_measurement

from .conftest import (FAST_T, GEAR_T, GEARS, LOGGER_MAP, SLIP_A, SLIP_B, SLOW_T, oil_degf, pressure_bar, torque_nm,
                       write_logger_file)

RPM = 2 * math.pi / 60


def held(t_grid, t_samples, values):
    """Sample-and-hold reference written as a plain loop (independent of the reader's searchsorted)."""
    out = np.empty(len(t_grid))
    for k, t in enumerate(t_grid):
        i = 0
        while i + 1 < len(t_samples) and t_samples[i + 1] <= t:
            i += 1
        out[k] = values[i]
    return out


def test_multi_rate_file_onto_fastest_time_base(logger_file):
    m = read_measurement(logger_file, LOGGER_MAP)
    t = m.time
    # overlap of all channels: [first slow sample, last gear sample]; the 1 kHz raster inside it
    expected_t = FAST_T[(FAST_T >= SLOW_T[0]) & (FAST_T <= GEAR_T[-1])]
    np.testing.assert_array_equal(t, expected_t)
    assert list(m.frame.columns) == ["time_s", "torque_Nm", "pressure_Pa", "slip_speed_rad_s", "temperature_C", "gear"]
    # the 1 kHz channels are taken at their own samples: exact, only unit conversion (bar -> Pa)
    np.testing.assert_allclose(m["torque_Nm"], torque_nm(t), rtol=1e-12)
    np.testing.assert_allclose(m["pressure_Pa"], pressure_bar(t) * 1e5, rtol=1e-12)
    # integer raw values with a*raw + b in rpm, linear in time: linear interpolation is exact, then rpm -> rad/s
    np.testing.assert_allclose(m["slip_speed_rad_s"], (SLIP_A * 100.0 * (t - SLOW_T[0]) + SLIP_B) * RPM, rtol=1e-9)
    # degF -> degC is affine: (140 + 18 t - 32) * 5/9 = 60 + 10 t
    np.testing.assert_allclose(m["temperature_C"], 60.0 + 10.0 * t, rtol=1e-12)
    # the gear is held, not interpolated
    np.testing.assert_array_equal(m["gear"], held(t, GEAR_T, GEARS.astype(float)))
    assert set(np.unique(m["gear"])) <= {1.0, 2.0, 3.0, 4.0}
    assert m.units == {"time_s": "s", "torque_Nm": "N*m", "pressure_Pa": "Pa", "slip_speed_rad_s": "rad/s",
                       "temperature_C": "degC", "gear": "1"}
    src = m.source
    assert src.format == "mdf" and src.synthetic
    assert src.channels["slip_speed_rad_s"].group == 1 and src.channels["slip_speed_rad_s"].samples == SLOW_T.size
    assert src.channels["slip_speed_rad_s"].rate_hz == pytest.approx(100.0)
    assert src.channels["gear"].interpolation == "previous"
    assert "TQ_Clutch" in src.describe() and "rpm -> rad/s" in src.describe()


def test_integer_channel_conversion_matches_asammdf_raw_values(logger_file):
    with MDF(logger_file) as mdf:
        raw = mdf.get("N_Slip", raw=True)
        assert raw.samples.dtype.kind == "i"  # the file really stores integers
        physical = SLIP_A * raw.samples.astype(float) + SLIP_B
    m = read_measurement(logger_file, {"slip_speed_rad_s": "N_Slip"})  # one group: its own time base
    np.testing.assert_array_equal(m.time, SLOW_T)
    np.testing.assert_allclose(m["slip_speed_rad_s"], physical * RPM, rtol=1e-14)


def test_uniform_rate_and_given_time_base(logger_file):
    m = read_measurement(logger_file, LOGGER_MAP, rate=200.0)
    t = m.time
    np.testing.assert_allclose(np.diff(t), 1 / 200.0, rtol=1e-9)
    assert t[0] == SLOW_T[0] and t[-1] <= GEAR_T[-1] + 1e-12 and t[-1] > GEAR_T[-1] - 1 / 200.0
    np.testing.assert_allclose(m["temperature_C"], 60.0 + 10.0 * t, rtol=1e-12)
    # the sine between 1 kHz samples: linear interpolation error <= h^2/8 max|f''| = 1e-6/8 * 50 (2 pi)^2
    assert np.max(np.abs(m["torque_Nm"] - torque_nm(t))) <= 1e-6 / 8 * 50 * (2 * np.pi) ** 2 * 1.01
    assert "200 Hz" in m.source.time_base
    tb = np.linspace(0.5, 1.5, 11)
    m2 = read_measurement(logger_file, LOGGER_MAP, time_base=tb, interpolation="previous")
    np.testing.assert_array_equal(m2.time, tb)
    # "previous" everywhere: the 100 Hz temperature is held at the last sample at or before each time
    np.testing.assert_allclose(m2["temperature_C"], held(tb, SLOW_T, 60.0 + 10.0 * SLOW_T), rtol=1e-12)
    with pytest.raises(DataError, match=r"logger\.mf4.*time_base.*exceeds the span of channel 'Gear'"):
        read_measurement(logger_file, LOGGER_MAP, time_base=np.linspace(0.5, 1.95, 5))
    with pytest.raises(ParameterError, match="rate or time_base"):
        read_measurement(logger_file, LOGGER_MAP, rate=10.0, time_base=tb)
    with pytest.raises(ParameterError, match="rate"):
        read_measurement(logger_file, LOGGER_MAP, rate=-5.0)
    with pytest.raises(ParameterError, match="time_base"):
        read_measurement(logger_file, LOGGER_MAP, time_base=tb[::-1])


def test_identity_read_keeps_file_names_and_units(logger_file):
    m = read_measurement(logger_file, rate=100.0)
    assert set(m.channels) == {"TQ_Clutch", "P_Piston", "N_Slip", "T_Oil", "Status", "Gear"}
    # no name suffix: the file's unit is kept, in pint spelling (pint alone would read "Nm" as nanometre)
    assert m.units["TQ_Clutch"] == "N*m" and m.units["T_Oil"] == "degF" and m.units["N_Slip"] == "rpm"
    assert m.source.channels["T_Oil"].source_unit == "°F"  # the provenance keeps the file's spelling
    np.testing.assert_allclose(m["T_Oil"], oil_degf(m.time), rtol=1e-12)
    assert m.source.skipped == {}


def test_identity_read_skips_a_name_in_several_groups(tmp_path):
    m = read_measurement(write_logger_file(tmp_path / "dup.mf4", duplicate=True), rate=100.0)
    assert "TQ_Clutch" not in m.channels and {"P_Piston", "N_Slip", "T_Oil"} <= set(m.channels)
    assert m.source.skipped["TQ_Clutch"] == ("occurs 2 times (group 0 index 1 [Nm] 'clutch torque'; "
                                             "group 1 index 4 [Nm]); map it with group and index")
    with pytest.raises(DataError, match=r"dup\.mf4: channel 'TQ_Clutch' occurs 2 times"):
        read_measurement(tmp_path / "dup.mf4", required=["TQ_Clutch"])  # asked for: an error, not a skip


def test_duplicate_names_need_a_group(tmp_path):
    path = write_logger_file(tmp_path / "dup.mf4", duplicate=True)
    with pytest.raises(DataError, match=r"dup\.mf4: channel 'TQ_Clutch' \(for 'torque_Nm'\) occurs 2 times "
                                        r"\(group 0 index 1 \[Nm\] 'clutch torque'; group 1 index 4 \[Nm\]\); "
                                        r"give `group` \(and `index`\) in the channel map"):
        read_measurement(path, {"torque_Nm": "TQ_Clutch"})
    fast = read_measurement(path, {"torque_Nm": {"source": "TQ_Clutch", "group": 0}})
    slow = read_measurement(path, {"torque_Nm": {"source": "TQ_Clutch", "group": 1}})
    np.testing.assert_allclose(fast["torque_Nm"], torque_nm(FAST_T), rtol=1e-12)
    np.testing.assert_allclose(slow["torque_Nm"], torque_nm(SLOW_T) + 1.0, rtol=1e-12)
    with pytest.raises(DataError, match=r"'TQ_Clutch' \(for 'torque_Nm'\) is not at group 2 \(it is at group 0 "):
        read_measurement(path, {"torque_Nm": {"source": "TQ_Clutch", "group": 2}})


def test_wrong_channel_names_fail_naming_file_and_channel(logger_file):
    with pytest.raises(DataError, match=r"logger\.mf4: missing channel 'TQ_Clutc' \(for 'torque_Nm'\); "
                                        r"did you mean 'TQ_Clutch'"):
        read_measurement(logger_file, {"torque_Nm": "TQ_Clutc"})
    with pytest.raises(DataError, match=r"logger\.mf4: missing channel 'force_N'"):
        read_measurement(logger_file, required=["force_N"])
    # optional entries may be absent
    m = read_measurement(logger_file, {"torque_Nm": "TQ_Clutch", "force_N": {"source": "F", "optional": True}})
    assert "force_N" not in m.frame.columns
    with pytest.raises(ParameterError, match="required channel 'force_N' is not in the channel map"):
        read_measurement(logger_file, {"torque_Nm": "TQ_Clutch"}, required=["force_N"])


def test_units_wrong_unknown_or_missing(tmp_path, logger_file):
    with pytest.raises(DataError, match=r"logger\.mf4: channel 'P_Piston': unit 'bar' cannot be converted to 'N\*m'"):
        read_measurement(logger_file, {"torque_Nm": "P_Piston"})
    with pytest.raises(DataError, match=r"channel 'Status' \(for 'force_N'\) carries no unit.*source_unit"):
        read_measurement(logger_file, {"force_N": "Status"})
    m = read_measurement(logger_file, {"force_N": {"source": "Status", "source_unit": "kN"}})
    np.testing.assert_allclose(m["force_N"], 7000.0)
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.ones(5), np.arange(5.0), name="X", unit="blorp")])
    path = mdf.save(tmp_path / "unit.mf4")
    mdf.close()
    with pytest.raises(DataError, match=r"unit\.mf4: channel 'X': unknown unit 'blorp'"):
        read_measurement(path, {"force_N": "X"})


def test_nan_and_non_monotonic_samples(tmp_path):
    path = write_logger_file(tmp_path / "nan.mf4", nan_at=123)
    with pytest.raises(DataError, match=r"nan\.mf4: channel 'TQ_Clutch' \(group 0\) has a non-finite value nan "
                                        r"at sample 123 \(t = 0\.123"):
        read_measurement(path, LOGGER_MAP)
    m = read_measurement(path, {"torque_Nm": "TQ_Clutch"}, allow_nan=["torque_Nm"])
    assert np.isnan(m["torque_Nm"][123]) and np.isfinite(np.delete(m["torque_Nm"], 123)).all()
    path = write_logger_file(tmp_path / "swap.mf4", swap_at=500)
    with pytest.raises(DataError, match=r"swap\.mf4: timestamps of channel 'TQ_Clutch' \(group 0\) must increase "
                                        r"strictly, but sample 501"):
        read_measurement(path, LOGGER_MAP)


def test_channels_without_common_span(tmp_path):
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.ones(5), np.arange(5.0), name="A", unit="N")])
    mdf.append([Signal(np.ones(5), 10 + np.arange(5.0), name="B", unit="N")])
    path = mdf.save(tmp_path / "apart.mf4")
    mdf.close()
    with pytest.raises(DataError, match="share no common time span"):
        read_measurement(path, {"force_N": "A", "force2_N": "B"})


@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
def test_truncated_and_foreign_files_fail_cleanly(tmp_path, logger_file):
    data = logger_file.read_bytes()
    for cut in (10, 64, 1000, len(data) // 2, len(data) - 40):
        bad = tmp_path / f"cut{cut}.mf4"
        bad.write_bytes(data[:cut])
        with pytest.raises(DataError, match=rf"cut{cut}\.mf4: not a readable MDF file"):
            read_measurement(bad, LOGGER_MAP)
    text = tmp_path / "notes.mf4"
    text.write_text("time,torque\n0,1\n")
    with pytest.raises(DataError, match=r"notes\.mf4: not a readable MDF file "
                                        r"\(it starts with b'time,tor', not b'MDF     '\)"):
        read_measurement(text)
    empty = tmp_path / "empty.mf4"
    empty.write_bytes(b"")
    with pytest.raises(DataError, match=r"empty\.mf4: not a readable MDF file \(it is empty\)"):
        read_measurement(empty)
    with pytest.raises(DataError, match="no such file"):
        read_measurement(tmp_path / "absent.mf4")
    gc.collect()  # half-built asammdf objects must not complain when collected (an "Exception ignored" warning)


def test_text_channel_is_rejected_when_mapped(tmp_path):
    mdf = MDF(version="4.10")
    t = np.arange(4.0)
    mdf.append([Signal(np.ones(4), t, name="F", unit="N"),
                Signal(np.array([b"a", b"b", b"c", b"d"]), t, name="Label", unit="", encoding="utf-8")])
    path = mdf.save(tmp_path / "text.mf4")
    mdf.close()
    with pytest.raises(DataError, match=r"text\.mf4: channel 'Label'.*non-numeric"):
        read_measurement(path, {"label": {"source": "Label", "unit": "1"}})
    assert read_measurement(path).channels == ("F",)  # an identity read skips it


def test_mdf_written_by_clutchlab_carries_units_per_channel(tmp_path, logger_file):
    m = read_measurement(logger_file, LOGGER_MAP)
    out = write_measurement(m, tmp_path / "si.mf4", comment="converted for a test")
    with MDF(out) as mdf:
        assert mdf.get("torque_Nm").unit == "N*m" and mdf.get("temperature_C").unit == "degC"
        np.testing.assert_allclose(mdf.get("pressure_Pa").samples, m["pressure_Pa"])
        np.testing.assert_allclose(mdf.get("pressure_Pa").timestamps, m.time)
        assert "synthetic" in mdf.header.description and "converted for a test" in mdf.header.description
    with pytest.raises(FileExistsError):
        write_measurement(m, out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["logger.mf4", "si.mf4"]  # no temporary files left


def test_channel_map_from_toml_reads_the_logger_file(tmp_path, logger_file):
    (tmp_path / "map.toml").write_text(
        '[channels.torque_Nm]\nsource = "TQ_Clutch"\n'
        '[channels.slip_speed_rad_s]\nsource = "N_Slip"\n'
        '[channels.gear]\nsource = "Gear"\nunit = "1"\ninterpolation = "previous"\n')
    cmap = ChannelMap.from_toml(tmp_path / "map.toml")
    m = read_measurement(logger_file, tmp_path / "map.toml")
    assert m.channels == cmap.names == ("torque_Nm", "slip_speed_rad_s", "gear")
    assert m.source.channels["torque_Nm"].source == "TQ_Clutch"


_BAD_MDF_HOST = r"""
import gc, random, sys
from pathlib import Path
from clutchlab.cli import main
data = Path(sys.argv[1]).read_bytes()
out = Path(sys.argv[2])
files = []
for cut in (10, 64, 200, 1000, len(data) // 3, len(data) // 2, len(data) - 40, len(data) - 1):
    files.append(out / f"cut{cut}.mf4")
    files[-1].write_bytes(data[:cut])
rng = random.Random(1)
for k in range(6):   # (20 bytes flipped after the identification block)
    b = bytearray(data)
    for _ in range(20):
        b[rng.randrange(64, len(b))] = rng.randrange(256)
    files.append(out / f"flip{k}.mf4")
    files[-1].write_bytes(bytes(b))
files.append(out / "header_only.mf4")
files[-1].write_bytes(data[:64] + bytes(2000))
codes = [main(["convert", str(f), "-o", str(out / (f.stem + ".csv"))]) for f in files]
gc.collect()
print(codes)
"""


def test_bad_mdf_files_give_one_line_each_and_nothing_at_collection_or_exit(tmp_path):
    """#33: asammdf's own ``__del__`` traceback ("Exception ignored in MDF4.__del__ ... no attribute 'header'")
    was printed after the clean message.  Fifteen bad files (truncated, bytes flipped, a header alone) through
    ``clutchlab convert`` in one process, then a garbage collection and a normal interpreter exit: stderr holds
    exactly one ``clutchlab: error:`` line per file and nothing else (without ``io.mdf._defuse`` it held seven
    such tracebacks)."""
    import subprocess
    import sys

    example = Path(__file__).resolve().parents[2] / "examples" / "press_logger.mf4"
    script = tmp_path / "host.py"
    script.write_text(_BAD_MDF_HOST)
    (tmp_path / "out").mkdir()
    proc = subprocess.run([sys.executable, str(script), str(example), str(tmp_path / "out")], capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == str([2] * 15)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 15 and all(line.startswith("clutchlab: error: ") for line in lines), proc.stderr[-3000:]
    assert not list((tmp_path / "out").glob("*.csv"))
