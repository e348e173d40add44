"""Conversions kept between processes (:mod:`clutchlab.units`): a unit pint converted once is converted again
without importing pint, to the same number to the last bit, and nothing that is not a plain factor is kept."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import pytest
from hypothesis import given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab import units
from clutchlab.errors import ParameterError

#: (unit as written, SI unit): lengths, pressures, speeds (rpm and Hz count turns), inertias, torques, stiffness,
#: temperatures in their own unit, angles, viscosities, times
PAIRS = [("mm", "m"), ("kPa", "Pa"), ("bar", "Pa"), ("rpm", "rad/s"), ("Hz", "rad/s"), ("kg m^2", "kg*m**2"),
         ("kg*cm**2", "kg*m**2"), ("N m", "N*m"), ("kN/mm", "N/m"), ("degC", "degC"), ("deg", "rad"),
         ("mPa*s", "Pa*s"), ("ms", "s"), ("km/h", "m/s"), ("N*m*s/rad", "N*m*s/rad"), ("percent", "1")]


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    """An empty cache folder for this test, and the process's kept factors forgotten (before and after)."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(units, "_KEPT", None)
    yield tmp_path / "clutchlab-units"
    units._KEPT = None


def _pint(value: str, unit: str) -> float:
    """pint's own conversion of ``value`` (the path every conversion took before factors were kept)."""
    m = units._NUMBER_UNIT.match(value)
    return units.convert(units._registry().Quantity(float(m.group(1)), m.group(2).strip()), unit)


@settings(max_examples=examples(60), deadline=None)
@given(st.sampled_from(PAIRS), st.floats(-1e9, 1e9, allow_nan=False, allow_infinity=False))
def test_a_kept_factor_gives_pints_number_to_the_last_bit(pair, x):
    text, unit = pair
    units.to_si(f"1 {text}", unit)   # (kept from here on, in this process and in the file)
    assert f"{text}|{unit}" in units._kept()
    assert units.to_si(f"{x!r} {text}", unit) == _pint(f"{x!r} {text}", unit)


def test_a_later_process_converts_without_pint(fresh_cache):
    """The first process keeps its factors in the cache folder; a second one reads them and never imports pint, with
    the same numbers; a unit it has not seen brings pint in."""
    code = ("import sys; from clutchlab.units import to_si; "
            "print(repr(to_si('83.15 mm', 'm')), repr(to_si('1500 rpm', 'rad/s')), 'pint' in sys.modules)")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(fresh_cache.parent))
    first = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert first.stdout.split()[2] == "True"
    files = list(fresh_cache.glob("conversions-pint*.json"))
    assert len(files) == 1 and json.loads(files[0].read_text()) == {"mm|m": 0.001, "rpm|rad/s": math.pi / 30}
    second = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert second.stdout.split() == first.stdout.split()[:2] + ["False"]
    other = code.replace("'1500 rpm', 'rad/s'", "'3 bar', 'Pa'")
    third = subprocess.run([sys.executable, "-c", other], capture_output=True, text=True, env=env, check=True)
    assert third.stdout.split()[2] == "True"


def test_only_plain_factors_are_kept(fresh_cache):
    """An offset (degF to degC, degC to K), a number inside the unit, an error: converted by pint, never kept."""
    assert units.to_si("212 degF", "degC") == pytest.approx(100.0)
    assert units.to_si("40 degC", "K") == pytest.approx(313.15)
    with pytest.raises(ParameterError, match="cannot parse"):   # (pint refuses a number inside a unit)
        units.to_si("3 N/(10 mm)", "N/m")
    with pytest.raises(ParameterError, match="wrong unit"):
        units.to_si("3 N", "m")
    assert units._kept() == {}
    assert not list(fresh_cache.glob("*.json")) or json.loads(next(fresh_cache.glob("*.json")).read_text()) == {}


def test_a_damaged_or_foreign_file_is_ignored_and_replaced(fresh_cache):
    """The file is data: one that is not JSON, or whose entries are not finite nonzero numbers, is ignored (its
    entries never convert anything) and rewritten with pint's factors."""
    fresh_cache.mkdir(parents=True)
    path = units._kept_file()
    path.write_text("{not json")
    assert units.to_si("2 mm", "m") == 0.002
    assert json.loads(path.read_text()) == {"mm|m": 0.001}
    units._KEPT = None
    path.write_text(json.dumps({"mm|m": "__import__('os')", "kPa|Pa": float("inf") if False else 0.0,
                                "bar|Pa": [1], "ms|s": True}))
    assert units._kept() == {}   # (no entry survives the check)
    assert units.to_si("2 mm", "m") == 0.002 and units.to_si("1 kPa", "Pa") == 1000.0


def test_a_cache_that_cannot_be_written_changes_nothing(fresh_cache, monkeypatch, tmp_path):
    """Without a writable cache folder (every candidate a file, not a folder) a conversion is pint's, as before, and
    is kept for the process only."""
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(blocker))
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    monkeypatch.setattr("tempfile.tempdir", str(blocker))
    assert units._kept_file() is None
    assert units.to_si("5 mm", "m") == 0.005
    assert units._kept() == {"mm|m": 0.001}
    assert blocker.read_text() == ""
