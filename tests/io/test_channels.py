"""Channel maps and unit conversion."""

import math

import pytest
from hypothesis import given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab.errors import DataError, ParameterError
from clutchlab.io import ChannelMap, ChannelSpec, canonical_unit, unit_conversion
from clutchlab.units import normalise_unit


@pytest.mark.parametrize("name, unit", [
    ("time_s", "s"), ("slip_speed_rad_s", "rad/s"), ("torque_Nm", "N*m"), ("temperature_C", "degC"),
    ("fluid_temperature_C", "degC"), ("bearing_position_m", "m"), ("pressure_Pa", "Pa"), ("force_N", "N"),
    ("speed_rpm", "rpm"), ("current", "A"), ("airgap", "m"), ("gear", None), ("force_model", None),
])
def test_canonical_unit_follows_the_nomenclature(name, unit):
    assert canonical_unit(name) == unit


@pytest.mark.parametrize("source, target, scale, offset", [
    ("rpm", "rad/s", 2 * math.pi / 60, 0.0),
    ("1/min", "rad/s", 2 * math.pi / 60, 0.0),
    ("Nm", "N*m", 1.0, 0.0),            # a logger's "Nm" is a newton metre, not a nanometre
    ("kNm", "N*m", 1e3, 0.0),
    ("bar", "Pa", 1e5, 0.0),
    ("mm", "m", 1e-3, 0.0),
    ("°C", "degC", 1.0, 0.0),
    ("degF", "degC", 5 / 9, -160 / 9),  # (F - 32) * 5/9
    ("degC", "K", 1.0, 273.15),
    ("%", "", 0.01, 0.0),
    ("-", "1", 1.0, 0.0),
])
def test_unit_conversion_values(source, target, scale, offset):
    a, b = unit_conversion(source, target)
    assert a == pytest.approx(scale, rel=1e-12)
    assert b == pytest.approx(offset, rel=1e-12, abs=1e-12)


def test_unit_conversion_errors_name_channel_and_unit():
    with pytest.raises(DataError, match=r"f\.mf4: channel 'TQ': unknown unit 'blorp'"):
        unit_conversion("blorp", "N*m", name="TQ", where="f.mf4")
    with pytest.raises(DataError, match=r"channel 'TQ': unit 'bar' cannot be converted to 'N\*m'"):
        unit_conversion("bar", "N*m", name="TQ")
    with pytest.raises(ParameterError):
        unit_conversion("bar", "N*m", name="TQ", error=ParameterError)


UNITS = ["rpm", "rad/s", "deg/s", "degC", "degF", "K", "bar", "kPa", "Pa", "psi"]


@settings(max_examples=examples(60), deadline=None)
@given(st.sampled_from(UNITS), st.sampled_from(UNITS), st.floats(-1e4, 1e4))
def test_conversion_round_trip_is_identity(u, v, x):
    try:
        a, b = unit_conversion(u, v)
    except DataError:
        return  # different dimension
    c, d = unit_conversion(v, u)
    assert c * (a * x + b) + d == pytest.approx(x, rel=1e-12, abs=1e-9)


def test_channel_map_from_dict_and_toml(tmp_path):
    cmap = ChannelMap.from_dict({"torque_Nm": "TQ", "slip_speed_rad_s": {"source": "N", "source_unit": "rpm"},
                                 "gear": {"source": "G", "unit": "1", "interpolation": "previous", "optional": True}})
    assert cmap.names == ("torque_Nm", "slip_speed_rad_s", "gear")
    assert cmap["torque_Nm"].unit == "N*m" and cmap["slip_speed_rad_s"].unit == "rad/s"
    assert cmap["gear"].optional and cmap["gear"].interpolation == "previous"
    (tmp_path / "m.toml").write_text('[channels.torque_Nm]\nsource = "TQ"\n[channels.slip_speed_rad_s]\n'
                                     'source = "N"\nsource_unit = "rpm"\n'
                                     '[channels.gear]\nsource = "G"\nunit = "1"\ninterpolation = "previous"\n'
                                     'optional = true\n')
    again = ChannelMap.from_toml(tmp_path / "m.toml")
    assert again.to_dict() == cmap.to_dict()
    assert ChannelMap.from_dict(cmap.to_dict()).to_dict() == cmap.to_dict()
    assert ChannelMap.coerce(tmp_path / "m.toml").names == cmap.names and ChannelMap.coerce(None) is None


@pytest.mark.parametrize("mapping, match", [
    ({"torque_Nm": {"source": "TQ", "scale": 2}}, "unknown key 'scale'"),
    ({"torque_Nm": {"source": "TQ", "unit": "kN*m"}}, "contradicts the unit the name states"),
    ({"gear": "G"}, "'gear'.*states no unit"),
    ({"torque_Nm": {"source": "TQ", "source_unit": "bar"}}, "'torque_Nm'.*'bar' cannot be converted"),
    ({"torque_Nm": {"source": "TQ", "source_unit": "blorp"}}, "unknown unit 'blorp'"),
    ({"torque_Nm": {"source": "TQ", "group": -1}}, "group"),
    ({"torque_Nm": {"source": "TQ", "interpolation": "cubic"}}, "interpolation = 'cubic'"),
    ({"torque_Nm": 3}, "expected a source name or a table"),
    ({"channels": {"torque_Nm": "TQ"}, "extra": {}}, "unknown table 'extra'"),
])
def test_channel_map_errors(mapping, match):
    with pytest.raises(ParameterError, match=match):
        ChannelMap.from_dict(mapping, name="map.toml")


def test_channel_map_file_errors(tmp_path):
    with pytest.raises(ParameterError, match="no such"):
        ChannelMap.from_toml(tmp_path / "absent.toml")
    (tmp_path / "bad.toml").write_text("[channels.torque_Nm\n")
    with pytest.raises(ParameterError, match=r"bad\.toml: not valid TOML"):
        ChannelMap.from_toml(tmp_path / "bad.toml")
    with pytest.raises(ParameterError, match="mapped twice"):
        ChannelMap([ChannelSpec("torque_Nm", "A"), ChannelSpec("torque_Nm", "B")])
    with pytest.raises(ParameterError, match="channel_map"):
        ChannelMap.coerce(42)


# ---------------------------------------------------------------- logger spellings of units

@pytest.mark.parametrize("spelling, unit", [
    ("U/  min", "rpm"), ("U / min", "rpm"), ("u/min", "rpm"), ("UpM", "rpm"), ("1/min", "rpm"), ("1 / min", "rpm"),
    ("min-1", "rpm"), ("min^-1", "rpm"), ("min⁻¹", "rpm"), ("r/min", "rpm"), ("rev/min", "rpm"), ("RPM", "rpm"),
    (" rpm ", "rpm"), ("[rpm]", "rpm"),
    ("Nm", "N*m"), ("N m", "N*m"), ("N.m", "N*m"), ("N·m", "N*m"), ("NM", "N*m"), ("[Nm]", "N*m"),
    ("kNm", "kN*m"), ("mNm", "mN*m"),
    ("°C", "degC"), ("° C", "degC"), ("℃", "degC"), ("degC", "degC"), ("deg C", "degC"), ("°F", "degF"),
    ("bar", "bar"), ("mbar", "mbar"), ("µs", "us"), ("m/s²", "m/s**2"),
    ("-", ""), ("[-]", ""), ("1", ""), ("", ""), ("%", "percent"),
])
def test_logger_unit_spellings(spelling, unit):
    assert normalise_unit(spelling) == unit


@pytest.mark.parametrize("source, target, scale, offset", [
    ("U/  min", "rad/s", 2 * math.pi / 60, 0.0),  # pint alone: enzyme units per minute
    ("1/min", "rad/s", 2 * math.pi / 60, 0.0),    # pint alone: 1/60 Hz, i.e. 1/60 rad/s
    ("mNm", "N*m", 1e-3, 0.0),                    # pint alone: "millinumber metre"
    ("° C", "K", 1.0, 273.15),
    ("bar", "Pa", 1e5, 0.0),
    ("[Nm]", "N*m", 1.0, 0.0),
])
def test_logger_spellings_convert_correctly(source, target, scale, offset):
    s, o = unit_conversion(source, target)
    assert s == pytest.approx(scale, rel=1e-12) and o == pytest.approx(offset, rel=1e-12, abs=1e-12)


_BLANKS = st.text(alphabet=" \t\u00a0", max_size=3)


@settings(deadline=None)
@given(_BLANKS, st.sampled_from(["U", "u", "1", "r", "rev"]), _BLANKS, _BLANKS)
def test_whitespace_never_turns_revolutions_into_enzyme_units(lead, numerator, around, trail):
    spelled = f"{lead}{numerator}{around}/{around}min{trail}"
    assert normalise_unit(spelled) == "rpm"
    assert unit_conversion(spelled, "rad/s") == pytest.approx((2 * math.pi / 60, 0.0))


@settings(deadline=None)
@given(st.text(max_size=12))
def test_any_unit_text_converts_or_raises_data_error(text):
    try:
        scale, offset = unit_conversion(text, text, name="X", where="f.mf4")
    except DataError as exc:
        assert str(exc).startswith("f.mf4: channel 'X': ")
    else:
        assert math.isfinite(scale) and math.isfinite(offset)
