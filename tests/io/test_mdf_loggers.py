"""MDF 4 files as real loggers write them: unfinalised, duplicate names, logger units, raw bus frames, damage.

Every file is written here by asammdf and then, where needed, patched the way a CAN logger that stops
without finalising leaves it (see ``conftest.unfinalise``).
"""

import gc
import io
import logging
import math
import struct

import numpy as np
import pytest
from asammdf import MDF, Signal

from clutchlab.cli import main
from clutchlab.errors import DataError, ParameterError
from clutchlab.io import read_measurement

from .conftest import CAN_T, _block, engine_rpm, torque_nm, unfinalise, write_can_logger_file, write_logger_file

RPM = 2 * math.pi / 60


def one_error_line(capfd):
    """stdout empty, stderr exactly one ``clutchlab: error:`` line; returns that line."""
    out, err = capfd.readouterr()
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("clutchlab: error: "), err
    return lines[0]


@pytest.fixture
def can_file(tmp_path):
    return write_can_logger_file(tmp_path / "can.mf4")


# ---------------------------------------------------------------- unfinalised files

@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # asammdf's own half-built object
def test_the_unfinalised_fixture_needs_finalising(tmp_path, can_file):
    """The patched file is what asammdf must finalise: from a read-only file object it cannot."""
    unfinalise(can_file)
    with open(can_file, "rb") as fh, pytest.raises(io.UnsupportedOperation, match="write"):
        MDF(fh)
    gc.collect()


@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
def test_unfinalised_file_reads_and_is_left_untouched(tmp_path, can_file, capfd, caplog):
    before = unfinalise(can_file)
    assert before[:8] == b"UnFinMF "
    caplog.set_level(logging.DEBUG)
    m = read_measurement(can_file, {"engine_speed_rad_s": "EngineSpeed",
                                    "torque_Nm": {"source": "TQ", "group": 0, "index": 2}})
    np.testing.assert_array_equal(m.time, CAN_T)  # cycle counters recovered from the data block: every sample
    np.testing.assert_allclose(m["engine_speed_rad_s"], engine_rpm(CAN_T) * RPM, rtol=1e-12)
    np.testing.assert_allclose(m["torque_Nm"], torque_nm(CAN_T), rtol=1e-12)
    assert can_file.read_bytes() == before  # finalised in a temporary copy, never in the user's file
    assert capfd.readouterr() == ("", "")  # asammdf's "Attempting finalization" stays quiet ...
    assert not [r for r in caplog.records if r.name.startswith("asammdf")]  # ... and out of the user's logging
    assert sorted(p.name for p in can_file.parent.iterdir()) == ["can.mf4"]
    gc.collect()


def test_unfinalised_file_converts_on_the_command_line(tmp_path, can_file, capfd):
    unfinalise(can_file)
    out = tmp_path / "can.csv"
    assert main(["convert", str(can_file), "-o", str(out)]) == 0
    stdout, stderr = capfd.readouterr()
    assert "EngineSpeed <- EngineSpeed, group 0, 100 Hz [U/  min -> rpm]" in stdout
    assert "Traceback" not in stdout + stderr and "finaliz" not in (stdout + stderr).lower()
    back = read_measurement(out)
    assert back.channels == ("EngineSpeed",) and back.units["EngineSpeed"] == "rpm"
    np.testing.assert_allclose(back["EngineSpeed"], engine_rpm(CAN_T), rtol=1e-8)


@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
@pytest.mark.parametrize("damage", ["cut", "data link"])
def test_unfinalised_file_beyond_repair_is_one_line(tmp_path, can_file, capfd, damage):
    data = bytearray(unfinalise(can_file))
    if damage == "cut":
        data = data[:len(data) // 3]
    else:  # the first data group's data link points at its channel group: asammdf prints a traceback to stdout
        _, _, hd_links = _block(data, 0x40)
        _, _, dg_links = _block(data, hd_links[0])
        struct.pack_into("<Q", data, hd_links[0] + 24 + 16, dg_links[1])
    bad = tmp_path / "bad.mf4"
    bad.write_bytes(bytes(data))
    assert main(["convert", str(bad), "-o", str(tmp_path / "out.csv")]) == 2
    line = one_error_line(capfd)  # nothing of asammdf's own output reaches the terminal
    assert line.startswith(f"clutchlab: error: {bad}: unfinalised MDF file (flags 0x05) that asammdf cannot "
                           "finalise (")
    assert not (tmp_path / "out.csv").exists()
    assert bad.read_bytes() == bytes(data)
    gc.collect()


def test_asammdf_logging_setup_is_restored(can_file):
    log = logging.getLogger("asammdf")
    handler = logging.NullHandler()
    log.addHandler(handler)
    try:
        before = (log.level, log.propagate, list(log.handlers))
        unfinalise(can_file)
        read_measurement(can_file, {"engine_speed_rad_s": "EngineSpeed"})
        assert (log.level, log.propagate, list(log.handlers)) == before
    finally:
        log.removeHandler(handler)


# ---------------------------------------------------------------- duplicate names, group and index

def test_name_twice_in_one_group_is_selected_by_group_and_index(can_file):
    with pytest.raises(DataError, match=r"can\.mf4: channel 'TQ' \(for 'torque_Nm'\) occurs 2 times "
                                        r"\(group 0 index 2 \[Nm\] 'clutch torque'; "
                                        r"group 0 index 3 \[kNm\] 'torque request'\); "
                                        r"give `group` and `index` in the channel map"):
        read_measurement(can_file, {"torque_Nm": "TQ"})
    with pytest.raises(DataError, match=r"occurs 2 times in group 0 .*give `group` and `index`"):
        read_measurement(can_file, {"torque_Nm": {"source": "TQ", "group": 0}})
    first = read_measurement(can_file, {"torque_Nm": {"source": "TQ", "group": 0, "index": 2}})
    second = read_measurement(can_file, {"torque_Nm": {"source": "TQ", "group": 0, "index": 3}})
    # both stored in a logger spelling of N*m and kN*m: the same torque in N*m
    np.testing.assert_allclose(first["torque_Nm"], torque_nm(CAN_T), rtol=1e-12)
    np.testing.assert_allclose(second["torque_Nm"], torque_nm(CAN_T), rtol=1e-12)
    assert first.source.channels["torque_Nm"].source_unit == "Nm"
    assert second.source.channels["torque_Nm"].source_unit == "kNm"
    assert "torque_Nm <- TQ, group 0" in second.source.describe()


def test_group_and_index_must_point_at_the_named_channel(tmp_path, can_file):
    with pytest.raises(DataError, match=r"channel 'TQ' \(for 'torque_Nm'\) is not at group 0 index 1 "
                                        r"\(it is at group 0 index 2 \[Nm\] 'clutch torque'; group 0 index 3"):
        read_measurement(can_file, {"torque_Nm": {"source": "TQ", "group": 0, "index": 1}})  # EngineSpeed is there
    with pytest.raises(DataError, match=r"'TQ' \(for 'torque_Nm'\) is not at group 5 index 2"):
        read_measurement(can_file, {"torque_Nm": {"source": "TQ", "group": 5, "index": 2}})
    m = read_measurement(can_file, {"torque_Nm": {"source": "TQ", "group": 0, "index": 7, "optional": True},
                                    "engine_speed_rad_s": "EngineSpeed"})
    assert m.channels == ("engine_speed_rad_s",)  # optional and absent at that place: skipped
    with pytest.raises(ParameterError, match=r"index = 2 needs group"):
        read_measurement(can_file, {"torque_Nm": {"source": "TQ", "index": 2}})
    with pytest.raises(ParameterError, match=r"index = -1 must be a non-negative whole number"):
        read_measurement(can_file, {"torque_Nm": {"source": "TQ", "group": 0, "index": -1}})
    (tmp_path / "t.csv").write_text("time_s,TQ\n0,1\n1,2\n")
    with pytest.raises(ParameterError, match=r"'torque_Nm': group and index only apply to MDF files"):
        read_measurement(tmp_path / "t.csv", {"torque_Nm": {"source": "TQ", "group": 0, "index": 1}})


def test_group_and_index_from_a_toml_map_on_the_command_line(tmp_path, can_file, capfd):
    (tmp_path / "map.toml").write_text('[channels.torque_Nm]\nsource = "TQ"\ngroup = 0\nindex = 3\n'
                                       '[channels.engine_speed_rad_s]\nsource = "EngineSpeed"\n')
    out = tmp_path / "out.parquet"
    assert main(["convert", str(can_file), "-o", str(out), "--channel-map", str(tmp_path / "map.toml")]) == 0
    assert capfd.readouterr().err == ""  # with a map nothing is skipped
    back = read_measurement(out)
    np.testing.assert_allclose(back["torque_Nm"], torque_nm(CAN_T), rtol=1e-12)
    (tmp_path / "amb.toml").write_text('[channels.torque_Nm]\nsource = "TQ"\n')
    assert main(["convert", str(can_file), "-o", str(tmp_path / "amb.csv"), "--channel-map",
                 str(tmp_path / "amb.toml")]) == 2
    line = one_error_line(capfd)
    assert "'TQ' (for 'torque_Nm') occurs 2 times (group 0 index 2 [Nm] 'clutch torque'; " in line
    assert not (tmp_path / "amb.csv").exists()


# ---------------------------------------------------------------- logger units

@pytest.mark.parametrize("unit", ["U/  min", "U/min", "U / min", "1/min", "rpm", "RPM", "r/min", "min-1", "[rpm]"])
def test_speed_units_of_loggers_are_revolutions_per_minute(tmp_path, unit):
    t = np.arange(5) * 0.1
    mdf = MDF(version="4.11")
    mdf.append([Signal(np.array([0.0, 60.0, 600.0, 3000.0, 6000.0]), t, name="N", unit=unit)])
    path = mdf.save(tmp_path / "speed.mf4")
    mdf.close()
    m = read_measurement(path, {"speed_rad_s": "N"})
    np.testing.assert_allclose(m["speed_rad_s"], [0.0, 2 * math.pi, 20 * math.pi, 100 * math.pi, 200 * math.pi],
                               rtol=1e-12)
    assert read_measurement(path).units["N"] == "rpm"  # kept in the file's unit, spelled for pint


# ---------------------------------------------------------------- reads without a map

def test_read_without_map_skips_what_cannot_be_converted(tmp_path):
    t = np.arange(10) * 0.01
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.full(10, 2.0), t, name="P", unit="bar"),
                Signal(np.ones(10), t, name="X", unit="blorp"),
                Signal(np.full(10, 50.0), t, name="T_C", unit="°C"),
                Signal(np.full(10, 3.0), t, name="Pos_m", unit="V")])  # name states m, file says V
    path = mdf.save(tmp_path / "mixed.mf4")
    mdf.close()
    m = read_measurement(path)
    assert m.channels == ("P", "T_C")
    np.testing.assert_array_equal(m["P"], 2.0)
    np.testing.assert_array_equal(m["T_C"], 50.0)
    assert m.units == {"time_s": "s", "P": "bar", "T_C": "degC"}
    assert m.source.skipped == {"X": "unknown unit 'blorp'",
                                "Pos_m": "unit 'V' cannot be converted to 'm' (different dimension)"}
    with pytest.raises(DataError, match=r"mixed\.mf4: channel 'X': unknown unit 'blorp'"):
        read_measurement(path, required=["X"])


def test_convert_without_map_warns_once_per_skipped_channel(tmp_path, can_file, capfd):
    out = tmp_path / "out.mf4"
    assert main(["convert", str(can_file), "-o", str(out)]) == 0
    stdout, stderr = capfd.readouterr()
    warnings = stderr.splitlines()
    assert warnings == [
        f"clutchlab: warning: {can_file}: skipped group 1: raw bus frames (CAN1.CAN_DataFrame, CAN_DataFrame, "
        "CAN_DataFrame.BusChannel, ...), not signals; decode them with a DBC or ARXML file (--dbc, [bus] in a "
        "channel map, databases=) or map their fields explicitly",
        f"clutchlab: warning: {can_file}: skipped TQ: occurs 2 times (group 0 index 2 [Nm] 'clutch torque'; "
        "group 0 index 3 [kNm] 'torque request'); map it with group and index",
        f"clutchlab: warning: {can_file}: skipped Label: non-numeric samples (text, structures or arrays)",
    ]
    assert "skipped Label" in stdout  # the provenance lists them too
    with MDF(out) as back:
        assert back.get("EngineSpeed").unit == "rpm"
        np.testing.assert_allclose(back.get("EngineSpeed").samples, engine_rpm(CAN_T), rtol=1e-12)
        assert "TQ" not in back.channels_db and "CAN_DataFrame.ID" not in back.channels_db


def test_many_skipped_channels_end_in_one_summary_line(tmp_path, capfd):
    t = np.arange(4) * 0.1
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.ones(4), t, name="F", unit="N")]
               + [Signal(np.ones(4), t, name=f"X{k}", unit="blorp") for k in range(13)])
    path = mdf.save(tmp_path / "many.mf4")
    mdf.close()
    assert main(["convert", str(path), "-o", str(tmp_path / "out.csv")]) == 0
    lines = capfd.readouterr().err.splitlines()
    assert len(lines) == 11 and all(line.startswith(f"clutchlab: warning: {path}: skipped X") for line in lines[:10])
    assert lines[10] == f"clutchlab: warning: {path}: ... and 3 more skipped (all listed in the provenance above)"


@pytest.mark.parametrize("bus_source", [True, False])
def test_raw_bus_frame_groups_are_reported_once(tmp_path, bus_source):
    path = write_can_logger_file(tmp_path / "frames.mf4", bus_groups=3, bus_source=bus_source)
    with MDF(path) as mdf:  # the fixture is what it claims: CG flag bit 1 (bus event) set or not
        assert all(bool(mdf.groups[g].channel_group.flags & 2) == bus_source for g in (1, 2, 3))
    m = read_measurement(path)
    assert m.channels == ("EngineSpeed",)
    bus = [k for k in m.source.skipped if k.startswith("group")]
    assert bus == ["groups 1-3"] and m.source.skipped["groups 1-3"].startswith("raw bus frames (")
    assert "CAN_DataFrame.BusChannel" in m.source.skipped["groups 1-3"]


def test_raw_bus_frames_can_be_mapped_field_by_field(can_file):
    m = read_measurement(can_file, {"frame_id": {"source": "CAN_DataFrame.ID", "unit": "1"},
                                    "dlc": {"source": "CAN_DataFrame.DLC", "unit": "1"}})
    np.testing.assert_array_equal(m["frame_id"], 0x18F)
    np.testing.assert_array_equal(m["dlc"], 8)
    with pytest.raises(DataError, match=r"can\.mf4: channel 'CAN_DataFrame\.DataBytes' \(for 'data'\) in group 1 "
                                        r"has non-numeric samples \(2-D samples\) \(raw bus frames: decode them"):
        read_measurement(can_file, {"data": {"source": "CAN_DataFrame.DataBytes", "unit": "1"}})


def test_a_file_of_only_raw_frames_fails_with_the_reason(tmp_path, capfd):
    path = write_can_logger_file(tmp_path / "frames.mf4")
    with MDF(path) as mdf:
        only = mdf.filter([(None, 1, i) for i in range(1, len(mdf.groups[1].channels))])
        only.save(tmp_path / "raw.mf4")
        only.close()
    assert main(["convert", str(tmp_path / "raw.mf4"), "-o", str(tmp_path / "out.csv")]) == 2
    line = one_error_line(capfd)
    assert line.startswith(f"clutchlab: error: {tmp_path / 'raw.mf4'}: no channel could be read (1 skipped; "
                           "group 0: raw bus frames")


# ---------------------------------------------------------------- damaged files through the command line

@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
@pytest.mark.parametrize("damage", ["half", "header", "garbage", "empty", "zeros"])
def test_damaged_files_give_one_line_and_no_output(tmp_path, damage, capfd):
    data = write_logger_file(tmp_path / "good.mf4").read_bytes()
    bad = tmp_path / "bad.mf4"
    bad.write_bytes({"half": data[:len(data) // 2], "header": data[:64], "garbage": bytes(range(256)) * 20,
                     "empty": b"", "zeros": data[:64] + bytes(len(data) - 64)}[damage])
    assert main(["convert", str(bad), "-o", str(tmp_path / "out.csv")]) == 2
    line = one_error_line(capfd)
    assert line.startswith(f"clutchlab: error: {bad}: ") and "MDF file" in line
    assert not (tmp_path / "out.csv").exists()
    gc.collect()
