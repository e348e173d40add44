"""Parameter values beyond physical plausibility are refused on construction (every entry point)."""

import dataclasses

import pytest

from clutchlab.errors import ParameterError
from clutchlab.params.base import MAGNITUDE_LIMIT, PLAUSIBLE_LIMITS
from clutchlab.params.registry import MODELS, model_sets
from clutchlab.wet import WetClutch
from cli_checks import one_line_error

ENTRIES = [e for m in MODELS for e in model_sets(m)]




def test_huge_radius_is_refused_not_overflowed():
    with pytest.raises(ParameterError, match=r"WetClutch\.r_outer = 1e\+300: implausible for a length"):
        WetClutch(r_outer=1e300)
    with pytest.raises(ParameterError, match=r"r_outer = 1e\+300"):
        WetClutch.paper().replace(r_outer=1e300)
    with pytest.raises(ParameterError, match="not finite"):
        WetClutch(r_outer=float("inf"))


def test_huge_radius_in_a_file_names_file_table_key_and_value(tmp_path, capsys):
    path = tmp_path / "wet.toml"
    path.write_text("[wet]\nr_outer = 1e300\n")
    line = one_line_error(capsys, ["params", "check", str(path)])
    assert f"{path}: [wet] r_outer = 1e+300: implausible for a length" in line
    # also where a command loads it
    line = one_line_error(capsys, ["wet", "identify", "absent.csv", "--clutch", str(path), "-o",
                                   str(tmp_path / "map.json")])
    assert "[wet] r_outer = 1e+300" in line
    assert not (tmp_path / "map.json").exists()


def test_unit_slip_in_a_file_is_caught(tmp_path):
    path = tmp_path / "wet.toml"
    path.write_text('[wet]\nr_outer = "83.15 km"\n')   # km for mm
    with pytest.raises(ParameterError, match=r"r_outer = 83150\.0: implausible .*written '83.15 km'"):
        WetClutch.from_toml(path)


def test_temperature_below_absolute_zero_is_refused():
    from clutchlab.wet.friction import ParametricFriction

    with pytest.raises(ParameterError, match="t_ref = -300.0: below the absolute zero"):
        ParametricFriction(t_ref=-300.0)


@pytest.mark.parametrize("entry", ENTRIES, ids=[f"{e.model}.{e.table}" for e in ENTRIES])
def test_every_unbounded_field_has_a_limit_above_its_default(entry):
    """The limits never refuse a preset, and every field without bounds refuses 1e300."""
    preset = entry.preset(paper=True)
    for name, meta in entry.cls.field_info().items():
        if meta["bounds"] != (None, None):
            continue
        limit = PLAUSIBLE_LIMITS.get(meta["unit"], (MAGNITUDE_LIMIT, ""))[0]
        value = getattr(preset, name)
        for v in value if isinstance(value, tuple) else (value,):
            assert abs(v) <= limit / 10, (name, v, limit)   # a decade of headroom at least
        huge = tuple(1e300 for _ in value) if isinstance(value, tuple) else (
            int(1e300) if isinstance(value, int) else 1e300)
        with pytest.raises(ParameterError, match=rf"{name}(\[0\])? = .*implausible"):
            dataclasses.replace(preset, **{name: huge})
