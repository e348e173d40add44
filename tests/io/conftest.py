"""Fixtures: real MDF 4 files written by asammdf itself (not by clutchlab's writer)."""

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
