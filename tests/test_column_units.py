"""Units of column names: one table for the units line of files, axis labels and report tables (nomenclature.md)."""

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from clutchlab.io import read_measurement, write_measurement
from clutchlab.io.channels import canonical_unit, unit_conversion
from clutchlab.units import COLUMN_UNITS, column_label, column_unit, unit_label

NOMENCLATURE = Path(__file__).resolve().parents[1] / "docs" / "nomenclature.md"


def _suffix_table():
    """Rows of the "Unit suffixes" table of docs/nomenclature.md: (suffixes, unit for people, unit in files)."""
    text = NOMENCLATURE.read_text(encoding="utf-8")
    block = text.split("## Unit suffixes", 1)[1].split("\n## ", 1)[0]
    rows = []
    for line in block.splitlines():
        m = re.match(r"^\|\s*(`_[^|]+)\|\s*([^|]+?)\s*\|\s*`([^`]+)`\s*\|$", line)
        if m:
            suffixes = re.findall(r"`_([^`]+)`", m.group(1))
            rows.append((suffixes, m.group(2), m.group(3)))
    return rows


ROWS = _suffix_table()
DOC_SUFFIXES = [(s, human, file_unit) for suffixes, human, file_unit in ROWS for s in suffixes]


def test_nomenclature_lists_exactly_the_suffixes_of_the_code():
    assert len(ROWS) > 30
    assert sorted(s for s, _, _ in DOC_SUFFIXES) == sorted(COLUMN_UNITS)


@pytest.mark.parametrize("suffix, human, file_unit", DOC_SUFFIXES, ids=[s for s, _, _ in DOC_SUFFIXES])
def test_every_suffix_of_nomenclature(suffix, human, file_unit):
    name = f"some_quantity_{suffix}"
    assert column_unit(name) == file_unit  # the units line of CSV outputs
    assert canonical_unit(name) == file_unit  # what the readers convert to
    assert unit_label(suffix) == human  # axis labels and report tables
    assert unit_label(file_unit) == human
    assert column_label(name) == f"some_quantity [{human}]"
    # the unit people read and the unit written in files are the same unit
    assert unit_conversion(human, file_unit) == pytest.approx((1.0, 0.0))


def test_units_named_in_the_issue():
    assert column_unit("line_flow_m3_s") == "m**3/s"  # was "s": the shortest suffix won
    assert unit_label("rad_s") == "rad/s" and unit_label("C") == "°C" and unit_label("m3_s") == "m³/s"
    assert unit_label("Nm") == "N·m" and unit_label("1") == "dimensionless"
    assert column_label("slip_speed_rad_s") == "slip_speed [rad/s]"
    assert column_label("temperature_C") == "temperature [°C]"
    assert column_label("coupling_mode") == "coupling_mode" and column_unit("coupling_mode") is None
    assert column_label("time") == "time [s]"


@pytest.mark.parametrize("name, label", [
    ("ice.idle_kp", "ice.idle_kp"),                       # a parameter without a unit suffix
    ("clutch1.fn_max", "clutch1.fn_max"),
    ("coupling_mode", "coupling_mode"),
    ("ice.idle_kp_Nm", "ice.idle_kp [N·m]"),              # underscores before a unit suffix
    ("slip_speed_rad_s", "slip_speed [rad/s]"),
    ("vehicle.w_jerk_rad_s3", "vehicle.w_jerk [rad/s³]"),
    ("line_flow_m3_s", "line_flow [m³/s]"),
    ("peak_temperature_c", "peak_temperature [°C]"),
])
def test_column_label_keeps_the_underscores_of_a_name(name, label):
    """#33 R3: a name is what people type in a spec or a query (``ice.idle_kp``); labels keep it as it is
    spelled and turn only the unit suffix into a unit."""
    assert column_label(name) == label


@given(stem=st.from_regex(r"[a-z]{1,8}(_[a-z]{1,8}){0,2}", fullmatch=True), suffix=st.sampled_from(sorted(COLUMN_UNITS)))
def test_the_longest_suffix_wins(stem, suffix):
    """Whatever the words before it, a name ending in a suffix of the table states that suffix's unit,
    unless a longer suffix of the table also matches (the longer one wins)."""
    name = f"{stem}_{suffix}"
    parts = name.split("_")
    longest = next("_".join(parts[k:]) for k in range(1, len(parts)) if "_".join(parts[k:]) in COLUMN_UNITS)
    assert len(longest) >= len(suffix)
    assert column_unit(name) == COLUMN_UNITS[longest][0]
    assert column_label(name).endswith(f"[{COLUMN_UNITS[longest][1]}]")


def test_units_line_of_a_csv_output(tmp_path):
    frame = pd.DataFrame({"time_s": [0.0, 1.0], "line_flow_m3_s": [1e-6, 2e-6], "temperature_C": [20.0, 21.0],
                          "torque_Nm": [1.0, 2.0], "throttle_1": [0.1, 0.2], "mode": ["open", "locked"]})
    path = write_measurement(frame, tmp_path / "out.csv")
    units_line = next(line for line in path.read_text(encoding="utf-8").splitlines() if line.startswith("# units:"))
    assert units_line == ("# units: time_s=s, line_flow_m3_s=m**3/s, temperature_C=degC, torque_Nm=N*m, "
                          "throttle_1=1, mode=")
    back = read_measurement(path)
    assert back.units["line_flow_m3_s"] == "m**3/s"
    np.testing.assert_array_equal(back.frame["line_flow_m3_s"], frame["line_flow_m3_s"])
    assert list(back.frame["mode"]) == ["open", "locked"]


def test_pint_spellings_outside_the_tables_are_printed_for_people():
    """Sweep summaries showed ``[kg*m**2]`` (#33)."""
    assert unit_label("kg*m**2") == "kg·m²" and unit_label("N*m/rad") == "N·m/rad"
    assert unit_label("m**3/s") == "m³/s" and unit_label("N*s/m") == "N·s/m" and unit_label("1/s") == "1/s"
