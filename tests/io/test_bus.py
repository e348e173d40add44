"""CAN bus logs (#33): raw CAN frames in an MDF 4 file, decoded with a DBC into signals and read like channels.

The DBC is our own (below); the frames are encoded **by hand** from its definitions (Intel and Motorola bit
layouts, factor, offset, sign), independently of canmatrix and asammdf, which decode them; the decoded
signals must equal the physical values the frames were made from, converted to SI.
"""

import numpy as np
import pandas as pd
import pytest
from asammdf import MDF, Signal
from asammdf.blocks import v4_constants as v4c
from asammdf.blocks.source_utils import Source

from clutchlab.cli import main
from clutchlab.errors import DataError, ParameterError
from clutchlab.io import ChannelMap, read_measurement

DBC = '''VERSION ""

NS_ :

BS_:

BU_: ECU TCU

BO_ 399 Engine: 8 ECU
 SG_ EngineSpeed : 0|16@1+ (0.25,0) [0|16383.75] "rpm" TCU
 SG_ EngineTorque : 16|12@1- (0.5,0) [-1024|1023.5] "Nm" TCU

BO_ 400 Clutch: 8 TCU
 SG_ ClutchPressure : 0|16@1+ (0.001,0) [0|65.535] "bar" ECU
 SG_ OilTemp : 16|8@1+ (1,-40) [-40|215] "degC" ECU
 SG_ SlipSpeed : 31|16@0- (0.5,0) [-16384|16383.5] "rpm" ECU

'''
#: (start bit, size, little endian, signed, factor, offset) of each signal, as the DBC above says
LAYOUT = {
    "EngineSpeed": (0, 16, True, False, 0.25, 0.0),
    "EngineTorque": (16, 12, True, True, 0.5, 0.0),
    "ClutchPressure": (0, 16, True, False, 0.001, 0.0),
    "OilTemp": (16, 8, True, False, 1.0, -40.0),
    "SlipSpeed": (31, 16, False, True, 0.5, 0.0),
}
T_ENGINE = np.arange(0, 201) * 0.01          # 100 Hz
T_CLUTCH = 0.003 + np.arange(0, 100) * 0.02  # 50 Hz, another raster
T_OTHER = np.arange(0, 20) * 0.1             # an ID no database defines


def physical(t):
    """The signals' physical values before quantisation (DBC units)."""
    return {"EngineSpeed": 800.0 + 2000.0 * t, "EngineTorque": -100.0 + 150.0 * t,
            "ClutchPressure": 2.0 + 10.0 * t, "OilTemp": 60.0 + 5.0 * t, "SlipSpeed": 300.0 - 400.0 * t}


def quantised(name, values):
    start, size, little, signed, factor, offset = LAYOUT[name]
    return np.round((values - offset) / factor) * factor + offset


def encode(payload, name, values):
    """Put each sample's raw value into its frame's bytes, bit by bit, as the DBC's layout says."""
    start, size, little, signed, factor, offset = LAYOUT[name]
    raw = np.round((np.asarray(values) - offset) / factor).astype(np.int64)
    raw = raw & ((1 << size) - 1)                 # two's complement for signed signals
    for row, r in enumerate(raw):
        pos = start
        for k in range(size):
            if little:                            # Intel: bit k of the value at bit start + k
                bit, where = (int(r) >> k) & 1, start + k
            else:                                 # Motorola: MSB at the start bit, then the sawtooth order
                bit, where = (int(r) >> (size - 1 - k)) & 1, pos
                pos = pos + 15 if pos % 8 == 0 else pos - 1
            payload[row, where // 8] |= bit << (where % 8)


def frames(ident, payload, bus_channel=1):
    f = np.zeros(len(payload), dtype=[("CAN_DataFrame.BusChannel", "u1"), ("CAN_DataFrame.ID", "<u4"),
                                      ("CAN_DataFrame.DLC", "u1"), ("CAN_DataFrame.DataLength", "u1"),
                                      ("CAN_DataFrame.DataBytes", "u1", (8,))])
    f["CAN_DataFrame.BusChannel"] = bus_channel
    f["CAN_DataFrame.ID"] = ident
    f["CAN_DataFrame.DLC"] = f["CAN_DataFrame.DataLength"] = 8
    f["CAN_DataFrame.DataBytes"] = payload
    return f


@pytest.fixture(scope="module")
def bus_log(tmp_path_factory):
    """A logger's MF4: one analog channel, and the raw CAN frames of three IDs on bus channel 1 (synthetic)."""
    folder = tmp_path_factory.mktemp("bus")
    (folder / "pt.dbc").write_text(DBC)
    engine = np.zeros((T_ENGINE.size, 8), np.uint8)
    clutch = np.zeros((T_CLUTCH.size, 8), np.uint8)
    pe, pc = physical(T_ENGINE), physical(T_CLUTCH)
    for name in ("EngineSpeed", "EngineTorque"):
        encode(engine, name, pe[name])
    for name in ("ClutchPressure", "OilTemp", "SlipSpeed"):
        encode(clutch, name, pc[name])
    stamps = np.concatenate([T_ENGINE, T_CLUTCH, T_OTHER])
    order = np.argsort(stamps, kind="stable")
    all_frames = np.concatenate([frames(0x18F, engine), frames(0x190, clutch),
                                 frames(0x7FF, np.full((T_OTHER.size, 8), 0xAA, np.uint8))])[order]
    mdf = MDF(version="4.11")
    mdf.append([Signal(20.0 + T_ENGINE, T_ENGINE, name="Ambient", unit="°C")], comment="analog")
    bus = Source(name="CAN1", path="CAN1", comment="", source_type=v4c.SOURCE_BUS, bus_type=v4c.BUS_TYPE_CAN)
    mdf.append([Signal(all_frames, stamps[order], name="CAN_DataFrame", source=bus)], acq_name="CAN1",
               acq_source=bus)
    mdf.header.comment = "synthetic: CAN bus log written by clutchlab's tests"
    mdf.save(folder / "log.mf4", overwrite=True)
    mdf.close()
    return folder


MAP = {"engine_speed_rad_s": "EngineSpeed", "torque_Nm": "EngineTorque", "pressure_Pa": "ClutchPressure",
       "temperature_C": "OilTemp", "slip_speed_rad_s": "SlipSpeed", "ambient_C": "Ambient"}
SI = {"EngineSpeed": np.pi / 30, "EngineTorque": 1.0, "ClutchPressure": 1e5, "OilTemp": 1.0, "SlipSpeed": np.pi / 30}


def test_can_frames_decode_with_the_dbc_to_the_values_they_were_encoded_from(bus_log):
    meas = read_measurement(bus_log / "log.mf4", MAP, databases=[bus_log / "pt.dbc"])
    t = meas["time_s"]
    # onto the fastest channel's timestamps (100 Hz) over the span all channels share
    assert t[0] >= T_CLUTCH[0] and t[-1] <= T_CLUTCH[-1] and np.allclose(np.diff(t), 0.01)
    for column, name in [("engine_speed_rad_s", "EngineSpeed"), ("torque_Nm", "EngineTorque")]:
        want = quantised(name, physical(t)[name]) * SI[name]           # sampled at their own frames' times
        np.testing.assert_allclose(meas[column], want, rtol=1e-12, atol=1e-9)
    for column, name in [("pressure_Pa", "ClutchPressure"), ("temperature_C", "OilTemp"),
                         ("slip_speed_rad_s", "SlipSpeed")]:
        own = quantised(name, physical(T_CLUTCH)[name]) * SI[name]     # at 50 Hz, carried linearly onto 100 Hz
        np.testing.assert_allclose(meas[column], np.interp(t, T_CLUTCH, own), rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(meas["ambient_C"], 20.0 + t)           # the file's own channel, beside them
    assert meas.source.bus == ("2 messages decoded with pt.dbc: Clutch 0x190, Engine 0x18F; "
                               "1 ID of the log in no database: 0x7FF")
    assert "bus log: 2 messages decoded" in meas.source.describe()
    assert meas.source.channels["pressure_Pa"].source_unit == "bar"   # the DBC's unit, converted


def test_the_same_frames_decode_alike_with_the_database_as_arxml(bus_log, tmp_path):
    """#33 "decode them with a DBC (or ARXML)": the test's DBC written as AUTOSAR XML by canmatrix decodes the same
    bus log to the same values, units and messages (the ARXML names its frames FRAME_<message>)."""
    import canmatrix.formats

    canmatrix.formats.dumpp({"": canmatrix.formats.loadp_flat(str(bus_log / "pt.dbc"))}, str(tmp_path / "pt.arxml"))
    assert b"AUTOSAR" in (tmp_path / "pt.arxml").read_bytes()[:2000]
    by_dbc = read_measurement(bus_log / "log.mf4", MAP, databases=[bus_log / "pt.dbc"])
    by_arxml = read_measurement(bus_log / "log.mf4", MAP, databases=[tmp_path / "pt.arxml"])
    for column in MAP:
        np.testing.assert_array_equal(by_arxml[column], by_dbc[column], err_msg=column)
        assert by_arxml.source.channels[column].source_unit == by_dbc.source.channels[column].source_unit
    assert by_arxml.source.bus == ("2 messages decoded with pt.arxml: FRAME_Clutch 0x190, FRAME_Engine 0x18F; "
                                   "1 ID of the log in no database: 0x7FF")


def test_a_map_names_its_databases_and_convert_takes_dbc(bus_log, tmp_path, capsys):
    cmap = bus_log / "map.toml"
    cmap.write_text("[bus]\ncan = ['pt.dbc']\n\n[channels.torque_Nm]\nsource = 'EngineTorque'\n"
                    "[channels.pressure_Pa]\nsource = 'ClutchPressure'\n")
    meas = read_measurement(bus_log / "log.mf4", cmap)
    assert meas.channels == ("torque_Nm", "pressure_Pa") and meas.source.bus.startswith("2 messages")
    assert ChannelMap.from_dict(ChannelMap.from_toml(cmap).to_dict()).bus == ChannelMap.from_toml(cmap).bus
    # convert without map: every decoded signal under its own name, no "raw bus frames" warning
    assert main(["convert", str(bus_log / "log.mf4"), "--dbc", str(bus_log / "pt.dbc"),
                 "-o", str(tmp_path / "signals.csv")]) == 0
    captured = capsys.readouterr()
    assert "raw bus frames" not in captured.err
    assert "bus log: 2 messages decoded with pt.dbc" in captured.out
    out = pd.read_csv(tmp_path / "signals.csv", comment="#")
    assert {"EngineSpeed", "EngineTorque", "ClutchPressure", "OilTemp", "SlipSpeed", "Ambient"} <= set(out.columns)


def test_without_a_database_the_frames_are_named_and_a_signal_asked_for_says_what_is_missing(bus_log):
    meas = read_measurement(bus_log / "log.mf4")
    assert meas.channels == ("Ambient",)
    assert any("raw bus frames" in reason and "DBC" in reason for reason in meas.source.skipped.values())
    with pytest.raises(DataError, match=r"missing channel 'EngineTorque' \(for 'torque_Nm'\); its raw bus "
                                        r"frames are not decoded: give a bus database"):
        read_measurement(bus_log / "log.mf4", {"torque_Nm": "EngineTorque"})
    # a database for another bus channel decodes nothing here: said in the error
    other = {"bus": {"can": [{"file": str(bus_log / "pt.dbc"), "channel": 2}]},
             "channels": {"torque_Nm": "EngineTorque"}}
    with pytest.raises(DataError, match=r"missing channel 'EngineTorque'.*bus log: 0 messages decoded with "
                                        r"pt\.dbc \(channel 2\)"):
        read_measurement(bus_log / "log.mf4", other)


def test_bad_databases_are_one_clear_error(bus_log, tmp_path):
    bad = tmp_path / "bad.dbc"
    bad.write_text("this is not a DBC file\n")
    with pytest.raises(DataError, match=r"bad\.dbc: (cannot read the bus database|the bus database defines no "
                                        r"messages)"):
        read_measurement(bus_log / "log.mf4", databases=[bad])
    with pytest.raises(DataError, match=r"nope\.dbc: no such bus database file"):
        read_measurement(bus_log / "log.mf4", databases=[tmp_path / "nope.dbc"])
    (tmp_path / "x.txt").write_text("x")
    with pytest.raises(DataError, match=r"unknown bus database format '\.txt'"):
        read_measurement(bus_log / "log.mf4", databases=[tmp_path / "x.txt"])
    with pytest.raises(ParameterError, match=r"\[bus\] has unknown key 'flexray'"):
        ChannelMap.from_dict({"bus": {"flexray": ["a.xml"]}, "channels": {"torque_Nm": "T"}})
    with pytest.raises(ParameterError, match=r"channel = -1 must be a bus channel number"):
        ChannelMap.from_dict({"bus": {"can": [{"file": "a.dbc", "channel": -1}]}, "channels": {"torque_Nm": "T"}})
    # a file without bus frames: the database changes nothing, and says so
    from clutchlab.io import write_measurement

    write_measurement(pd.DataFrame({"time_s": [0.0, 1.0], "torque_Nm": [1.0, 2.0]}), tmp_path / "plain.mf4")
    plain = read_measurement(tmp_path / "plain.mf4", databases=[bus_log / "pt.dbc"])
    assert plain.source.bus == "no raw bus frames in the file to decode with pt.dbc"
    assert plain.channels == ("torque_Nm",)
    rc = main(["convert", str(bus_log / "log.mf4"), "--dbc", str(bad), "-o", str(tmp_path / "o.csv")])
    assert rc == 2 and not (tmp_path / "o.csv").exists()
