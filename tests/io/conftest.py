"""Fixtures: real MDF 4 files written by asammdf itself (not by clutchlab's writer)."""

import struct
from pathlib import Path

import numpy as np
import pytest
from asammdf import MDF, Signal

#: logger layout of the multi-rate test file: 1 kHz, 100 Hz (integer raw values with a linear conversion), 10 Hz
FAST_T = np.arange(0, 2001) * 1e-3          # 0 .. 2.0 s at 1 kHz
SLOW_T = 0.005 + np.arange(0, 200) * 1e-2   # 0.005 .. 1.995 s at 100 Hz (offset: the rasters do not coincide)
GEAR_T = np.arange(0, 20) * 0.1             # 0 .. 1.9 s at 10 Hz
SLIP_A, SLIP_B = 0.5, 10.0                  # physical rpm = 0.5 * raw + 10


def torque_nm(t):
    return 100.0 + 50.0 * np.sin(2 * np.pi * t)


def pressure_bar(t):
    return 2.0 + 3.0 * t


def slip_rpm(t):
    """Physical value of the integer channel: raw = 100 t' (t' = time since the first slow sample)."""
    return SLIP_A * np.round((t - SLOW_T[0]) * 100.0) + SLIP_B


def oil_degf(t):
    return 140.0 + 18.0 * t  # 60 degC + 10 K/s


GEARS = np.array([1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 3, 4, 4, 4, 4, 3, 3, 2, 2], dtype=np.uint8)


def write_logger_file(path, *, duplicate=False, nan_at=None, swap_at=None, comment="synthetic: asammdf test file"):
    """A logger-style MF4: three channel groups at 1 kHz, 100 Hz and 10 Hz."""
    torque = torque_nm(FAST_T)
    if nan_at is not None:
        torque = torque.copy()
        torque[nan_at] = np.nan
    fast_t = FAST_T.copy()
    if swap_at is not None:
        fast_t[swap_at], fast_t[swap_at + 1] = fast_t[swap_at + 1], fast_t[swap_at]
    raw = np.arange(SLOW_T.size, dtype=np.int16)  # integer raw values, physical via a*raw + b
    mdf = MDF(version="4.10")
    mdf.append([Signal(torque, fast_t, name="TQ_Clutch", unit="Nm", comment="clutch torque"),
                Signal(pressure_bar(fast_t), fast_t, name="P_Piston", unit="bar")], comment="fast 1 kHz")
    slow = [Signal(raw, SLOW_T, name="N_Slip", unit="rpm", conversion={"a": SLIP_A, "b": SLIP_B}),
            Signal(oil_degf(SLOW_T), SLOW_T, name="T_Oil", unit="°F"),
            Signal(np.full(SLOW_T.size, 7.0), SLOW_T, name="Status", unit="")]
    if duplicate:
        slow.append(Signal(torque_nm(SLOW_T) + 1.0, SLOW_T, name="TQ_Clutch", unit="Nm"))
    mdf.append(slow, comment="slow 100 Hz")
    mdf.append([Signal(GEARS, GEAR_T, name="Gear", unit="")], comment="gear 10 Hz")
    mdf.header.comment = comment
    out = mdf.save(path, overwrite=True)
    mdf.close()
    return out


LOGGER_MAP = {
    "torque_Nm": "TQ_Clutch",
    "pressure_Pa": "P_Piston",
    "slip_speed_rad_s": "N_Slip",
    "temperature_C": "T_Oil",
    "gear": {"source": "Gear", "unit": "1", "interpolation": "previous"},
}


@pytest.fixture
def logger_file(tmp_path):
    return write_logger_file(tmp_path / "logger.mf4")


# ---------------------------------------------------------------- MDF 4 files as CAN loggers leave them

def _block(data, addr):
    """(id, length, links) of the MDF 4 block at ``addr`` (ASAM MDF 4.1: id char[4], reserved, length, link count)."""
    block_id, _, length, n_links = struct.unpack_from("<4s4sQQ", data, addr)
    return block_id, length, struct.unpack_from(f"<{n_links}Q", data, addr + 24)


def unfinalise(path, *, std_flags=0x05, custom_flags=0x01):
    """Turn a finalised MDF 4.1x file into the form a logger leaves when it stops without finalising.

    The identification block says ``UnFinMF `` with the standard flags
    ``std_flags`` (bit 0: cycle counters of CG blocks, bit 2: length of the
    last DT block not yet updated) and custom flags; as the logger never wrote
    them, every channel group's cycle counter is zeroed and every data group's
    DT block claims to hold no data (length 24, its header only).  Returns the
    file's new bytes.
    """
    data = bytearray(Path(path).read_bytes())
    assert data[:8] == b"MDF     " and data[8:12] >= b"4.10"
    _, _, hd_links = _block(data, 0x40)
    dg = hd_links[0]
    while dg:
        _, _, dg_links = _block(data, dg)
        cg = dg_links[1]
        while cg:
            _, _, cg_links = _block(data, cg)
            struct.pack_into("<Q", data, cg + 24 + 8 * len(cg_links) + 8, 0)  # cg_cycle_count
            cg = cg_links[0]
        if dg_links[2] and data[dg_links[2]:dg_links[2] + 4] == b"##DT":
            struct.pack_into("<Q", data, dg_links[2] + 8, 24)  # dt block length: header only
        dg = dg_links[0]
    data[0:8] = b"UnFinMF "
    struct.pack_into("<HH", data, 60, std_flags, custom_flags)
    Path(path).write_bytes(bytes(data))
    return bytes(data)


def write_can_logger_file(path, *, version="4.11", bus_groups=1, bus_source=True):
    """A CAN-logger-like MF4: a decoded signal group, duplicate names in one group, and a raw CAN frame group.

    Group 0 (100 Hz): ``EngineSpeed`` in ``U/  min`` (as a German logger
    writes it), ``TQ`` twice (index 2: N*m, index 3: kN*m, both as "Nm"
    spellings), ``Label`` text.  Groups 1 .. ``bus_groups``: raw
    ``CAN_DataFrame`` frames (bus event groups with a CAN source, as CANedge
    writes one per frame type); with ``bus_source=False`` written without
    the CAN source, so the group lacks the bus-event flag as in some
    converted files.
    """
    from asammdf import Source
    from asammdf.blocks import v4_constants as v4c

    t = CAN_T
    mdf = MDF(version=version)
    mdf.append([Signal(engine_rpm(t), t, name="EngineSpeed", unit="U/  min", comment="engine speed"),
                Signal(torque_nm(t), t, name="TQ", unit="Nm", comment="<CNcomment><TX>clutch torque</TX></CNcomment>"),
                Signal(torque_nm(t) / 1e3, t, name="TQ", unit="kNm", comment="torque request"),
                Signal(np.array([b"run"] * t.size), t, name="Label", unit="", encoding="utf-8")],
               comment="decoded 100 Hz")
    frames = np.zeros(t.size, dtype=[("CAN_DataFrame.BusChannel", "u1"), ("CAN_DataFrame.ID", "<u4"),
                                     ("CAN_DataFrame.DLC", "u1"), ("CAN_DataFrame.DataLength", "u1"),
                                     ("CAN_DataFrame.DataBytes", "u1", (8,))])
    frames["CAN_DataFrame.ID"] = 0x18F
    frames["CAN_DataFrame.DLC"] = frames["CAN_DataFrame.DataLength"] = 8
    frames["CAN_DataFrame.DataBytes"] = np.arange(t.size * 8).reshape(t.size, 8) % 256
    bus = Source(name="CAN1", path="CAN1", comment="", source_type=v4c.SOURCE_BUS, bus_type=v4c.BUS_TYPE_CAN)
    for _ in range(bus_groups):
        if bus_source:
            mdf.append([Signal(frames, t, name="CAN_DataFrame", source=bus)], acq_name="CAN1", acq_source=bus)
        else:
            mdf.append([Signal(frames, t, name="CAN_DataFrame")], acq_name="CAN1")
    out = mdf.save(path, overwrite=True)
    mdf.close()
    return out


CAN_T = np.arange(0, 50) * 0.01  # 0 .. 0.49 s at 100 Hz


def engine_rpm(t):
    return 800.0 + 2000.0 * t
