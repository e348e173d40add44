"""Property tests: TOML round trips of random valid parameter sets, in SI and in other units."""

import math

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.errors import ParameterError
from clutchlab.params.registry import MODELS, load_model_file, model_sets, model_toml

ENTRIES = [e for m in MODELS for e in model_sets(m)]


def _value_strategy(default, meta):
    lo, hi = meta["bounds"]
    if isinstance(default, int) and not isinstance(default, bool):
        low = lo if lo is not None else (1 if meta["positive"] else 0)
        return st.integers(int(low), int(hi) if hi is not None else max(int(low) + 10, 2 * default))
    if default == 0:
        a, b = 0.0, 1.0
    else:
        a, b = sorted((0.5 * default, 2.0 * default))
    a = max(a, lo) if lo is not None else a
    b = min(b, hi) if hi is not None else b
    return st.floats(a, b, allow_nan=False, allow_infinity=False)


@st.composite
def perturbed_set(draw):
    """A set of some model with one to three fields drawn at random (kept only if the set is valid)."""
    entry = draw(st.sampled_from(ENTRIES))
    base = entry.cls()
    info = entry.cls.field_info()
    names = draw(st.lists(st.sampled_from(sorted(info)), min_size=1, max_size=3, unique=True))
    changes = {}
    for name in names:
        default = getattr(base, name)
        if isinstance(default, tuple):
            changes[name] = tuple(draw(_value_strategy(d, info[name])) for d in default)
        else:
            changes[name] = draw(_value_strategy(default, info[name]))
    try:
        return entry, base.replace(**changes)
    except ParameterError:
        assume(False)


@settings(max_examples=examples(60), deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(perturbed_set())
def test_documented_toml_round_trip_is_exact(tmp_path_factory, drawn):
    entry, pset = drawn
    path = tmp_path_factory.mktemp("rt") / "p.toml"
    path.write_text(model_toml(entry.model, {entry.table: pset}))
    model, sets = load_model_file(path)
    assert model == entry.model and sets == {entry.table: pset}  # floats bit for bit (repr), ints as ints


@settings(max_examples=examples(60), deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(perturbed_set())
def test_to_toml_from_toml_round_trip(tmp_path_factory, drawn):
    _, pset = drawn
    path = pset.to_toml(tmp_path_factory.mktemp("rt") / "p.toml")
    assert type(pset).from_toml(path) == pset


# (table, field, SI value strategy, how to write it in another unit, relative tolerance)
RPM = 2.0 * math.pi / 60.0
CONVERSIONS = [
    ("wet", "r_outer", st.floats(0.0832, 0.3), lambda v: f"{v * 1e3!r} mm"),
    ("wet", "core_thickness", st.floats(1e-4, 5e-3), lambda v: f"{v * 1e6!r} um"),
    ("wet", "contact_modulus", st.floats(1e5, 1e8), lambda v: f"{v / 1e3!r} kPa"),
    ("wet", "contact_modulus", st.floats(1e5, 1e8), lambda v: f"{v / 1e5!r} bar"),
    ("wet", "m_core", st.floats(1e-3, 1.0), lambda v: f"{v * 1e3!r} g"),
    ("bench", "motor_speed_max", st.floats(10.0, 2000.0), lambda v: f"{v / RPM!r} rpm"),
    ("bench", "ambient_temperature", st.floats(-40.0, 150.0), lambda v: f"{v + 273.15!r} K"),
    ("bench", "ambient_temperature", st.floats(-40.0, 150.0), lambda v: f"{v * 9 / 5 + 32!r} degF"),
    ("map_protocol", "fluid_temperature", st.floats(-40.0, 150.0), lambda v: f"{v!r} degC"),
    ("map_protocol", "slip_speed", st.floats(1.0, 600.0), lambda v: f"{v / RPM!r} rpm"),
    ("map_protocol", "force", st.floats(100.0, 1e4), lambda v: f"{v / 1e3!r} kN"),
    ("bench", "motor_inertia", st.floats(1e-3, 1.0), lambda v: f"{v * 1e4!r} kg*cm^2"),
]


@pytest.mark.parametrize("table, name, values, write", CONVERSIONS, ids=[f"{c[1]}-{c[3](1.0).split()[-1]}" for c in CONVERSIONS])
@settings(max_examples=examples(25), deadline=None)
@given(data=st.data())
def test_unit_strings_convert_to_si(tmp_path_factory, table, name, values, write, data):
    value = data.draw(values)
    text = write(value)
    path = tmp_path_factory.mktemp("units") / "wet.toml"
    path.write_text(f'model = "wet"\n[{table}]\n{name} = "{text}"\n')
    _, sets = load_model_file(path)
    got = getattr(sets[table], name)
    assert got == pytest.approx(value, rel=1e-12, abs=1e-9), text
    # and the SI value written back by the documented TOML loads bit for bit
    path2 = path.with_name("si.toml")
    path2.write_text(model_toml("wet", sets))
    assert load_model_file(path2)[1] == sets

