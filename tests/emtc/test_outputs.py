"""EMTC outputs follow docs/nomenclature.md: unit suffixes on every column, modes and events as names."""

import numpy as np
import pandas as pd
import pytest

from clutchlab.cli import main
from clutchlab.emtc import BenchScenario, bundled_magnet, simulate_bench
from clutchlab.emtc.bench import ARMATURE_MODE_NAMES, COLUMN_NAMES, EVENT_KEYS, MODE_NAMES
from clutchlab.io import read_measurement
from clutchlab.units import column_unit

# columns that hold names or flags, not quantities
NAMED = {"armature_mode", "coupling_mode", "locked_case", "command_feasible"}


@pytest.fixture(scope="module")
def locked_run():
    sc = BenchScenario(duration=2.0, speed_difference=0.0, throttle_start=0.0, throttle_end=0.9,
                       ramp_start=0.2, ramp_end=1.9)
    return simulate_bench(bundled_magnet(), sc, torque_reference=([0.0, 10.0], [120.0, 120.0]))


def test_every_column_has_a_unit_suffix_and_modes_are_names(locked_run):
    df = locked_run.to_dataframe()
    assert list(df.columns) == list(COLUMN_NAMES.values())
    for c in df.columns:
        assert (c in NAMED) == (column_unit(c) is None), c
    assert set(df["coupling_mode"]) <= set(MODE_NAMES.values()) and "locked" in set(df["coupling_mode"])
    assert set(df["armature_mode"]) <= set(ARMATURE_MODE_NAMES.values())
    assert df["coupling_mode"].map(type).eq(str).all() and df["armature_mode"].map(type).eq(str).all()
    # the names are the kernel codes translated, sample by sample; quantities are the kernel's values
    out, st = locked_run.kernel_outputs, locked_run.kernel_states
    assert (df["coupling_mode"] == out["coupling_mode"].map(MODE_NAMES)).all()
    assert (df["coupling_mode"] == locked_run.coupling_modes).all()
    np.testing.assert_array_equal(df["coupling_torque_Nm"], out["t_coupling"])
    np.testing.assert_array_equal(df["omega_f_rad_s"], st["omega_f"])
    np.testing.assert_array_equal(df["time_s"], locked_run.time)
    locked = df["coupling_mode"] == "locked"
    assert (df.loc[locked, "locked_case"] != "").all() and (df.loc[~locked, "locked_case"] == "").all()


def test_events_are_named(locked_run):
    ev = locked_run.events
    assert {"time_s", "event", "description", "armature_mode", "coupling_mode"} <= set(ev.columns)
    assert set(ev["event"]) <= set(EVENT_KEYS.values())
    lock = ev[ev["event"] == "lockup"]
    assert len(lock) == 1 and lock["coupling_mode"].iloc[0] == "locked"
    # after the lock-up event the samples are locked
    df = locked_run.to_dataframe()
    after = df[(df["time_s"] > lock["time_s"].iloc[0] + 1e-9)]
    assert after["coupling_mode"].iloc[0] == "locked"
    # the run's own columns first (a BenchResult is a SimulationResult); no integer event codes
    assert list(ev.columns[:3]) == ["time_s", "event", "element"]
    assert not {"time", "kind", "name"} & set(ev.columns)


def test_simulate_csv_has_units_names_and_synthetic_mark(tmp_path, capsys):
    sc = tmp_path / "s.toml"
    sc.write_text('[scenario]\nduration = "0.5 s"\nspeed_difference = "0 m/s"\nthrottle_end = 0.3\n')
    out = tmp_path / "run.csv"
    assert main(["emtc", "simulate", str(sc), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "lockup" in text
    rec = read_measurement(out)
    assert rec.source.synthetic
    assert rec.units["coupling_torque_Nm"] == "N*m" and rec.units["slip_speed_rad_s"] == "rad/s"
    assert rec.units["throttle_1"] == "1" and rec.units["airgap_m"] == "m"
    df = pd.read_csv(out, comment="#")
    assert list(df.columns) == list(COLUMN_NAMES.values())
    assert set(df["coupling_mode"]) <= set(MODE_NAMES.values())
    assert "locked" in set(df["coupling_mode"])
