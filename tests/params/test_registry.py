"""Registry of parameter sets per model, model parameter files and their error messages."""

import dataclasses

import pytest

from clutchlab.errors import ParameterError
from clutchlab.params import ParameterSet, quantity
from clutchlab.params.base import _REGISTERED
from clutchlab.params.registry import MODELS, load_model_file, model_sets, model_toml, preset

EXPECTED = {
    "eclutch": {"eclutch": "EClutchParameters", "virtual_clutch": "VirtualClutch"},
    "wet": {"wet": "WetClutch", "bench": "Bench", "friction": "ParametricFriction", "map_protocol": "MapProtocol",
            "engagement_protocol": "EngagementProtocol"},
    "emtc": {"actuator": "ActuatorParameters", "vehicle": "VehicleParameters", "scenario": "BenchScenario",
             "coupling": "CouplingGeometry", "lugre": "LuGreParameters"},
}
#: sets whose fields do not all name a source yet (the subsystem owner adds them; see docs/parameters.md)
MISSING_SOURCES = {"BenchScenario"}


def all_entries():
    return [e for m in MODELS for e in model_sets(m)]


@pytest.mark.parametrize("model", list(MODELS))
def test_every_existing_set_is_found(model):
    found = {e.table: e.cls.__name__ for e in model_sets(model)}
    assert {t: found.get(t) for t in EXPECTED[model]} == EXPECTED[model]
    assert len(found) == len(model_sets(model))  # table names unique within a model


def test_a_new_set_appears_without_registration_code():
    @dataclasses.dataclass(frozen=True)
    class Damper(ParameterSet):
        __module__ = "clutchlab.emtc.some_new_module"
        kind = "damper"
        damping: float = quantity(10.0, "N*s/m", "damping", source="test", positive=True)

    try:
        tables = {e.table: e.cls for e in model_sets("emtc")}
        assert tables["damper"] is Damper
        assert "damper" not in {e.table for e in model_sets("wet")}
        assert "[damper]" in model_toml("emtc")
    finally:
        _REGISTERED.remove(Damper)
    assert "damper" not in {e.table for e in model_sets("emtc")}


@pytest.mark.parametrize("entry", all_entries(), ids=lambda e: e.cls.__name__)
def test_every_field_has_unit_doc_and_source(entry):
    for name, meta in entry.cls.field_info().items():
        assert meta["unit"] and meta["doc"], (entry.cls.__name__, name)
        if entry.cls.__name__ not in MISSING_SOURCES:
            assert meta["source"], (entry.cls.__name__, name)
        if meta["unit"] in ("kg", "kg*m^2"):
            assert meta["positive"], f"{entry.cls.__name__}.{name}: a mass or inertia must be declared positive"


@pytest.mark.parametrize("model", list(MODELS))
@pytest.mark.parametrize("paper", [False, True])
def test_documented_toml_loads_back_identically(model, paper, tmp_path):
    text = model_toml(model, paper=paper)
    path = tmp_path / f"{model}.toml"
    path.write_text(text)
    loaded_model, sets = load_model_file(path)
    assert loaded_model == model
    assert sets == preset(model, paper)
    # every field is documented in the comment above it, with unit and source
    for table, pset in sets.items():
        for name, meta in pset.field_info().items():
            assert f"# {' '.join(meta['doc'].split())} [{meta['unit']}]" in text, name


def _write(tmp_path, text, name="wet.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("body, message", [
    ('[wet]\nr_outer = "83.15 kg"\n', "[wet] r_outer = '83.15 kg': wrong unit: kg is not a length (it is a mass; expected m)"),
    ('[wet]\ncontact_modulus = "2.3 N"\n', "[wet] contact_modulus = '2.3 N': wrong unit: N is not a pressure"),
    ('[bench]\nmotor_speed_max = "6000 m"\n', "[bench] motor_speed_max = '6000 m': wrong unit: m is not an angular speed"),
    ('[wet]\nr_outer = "83.15 parsecs per fortnight"\n', "[wet] r_outer = '83.15 parsecs per fortnight': wrong unit"),
    ('[wet]\nr_outer = "83.15 furlongz"\n', "[wet] r_outer = '83.15 furlongz': cannot parse quantity"),
    ('[wet]\nn_c = "eight"\n', "[wet] n_c = 'eight': cannot parse quantity"),
    ('[wet]\nn_c = 2.5\n', "[wet] n_c = 2.5: expected a whole number"),
    ('[wet]\nr_outer = true\n', "[wet] r_outer = true: expected a number or a quantity string"),
    ('[wet]\nr_outer = [0.08, 0.09]\n', "[wet] r_outer = [0.08, 0.09]: expected a single value [m]"),
    ('[wet]\nr_outer = nan\n', "[wet] r_outer = nan: not a finite number"),
    ('[wet]\nr_outer = "inf mm"\n', "[wet] r_outer = 'inf mm': not a finite number"),
    ('[wet]\nm_core = "-82 g"\n', "[wet] m_core = -0.082: must be > 0 [kg] (written '-82 g')"),
    ('[wet]\nr_outr = "83 mm"\n', "[wet] unknown parameter 'r_outr' for WetClutch; did you mean 'r_outer'?"),
    ('[wet]\nr_inner = "90 mm"\n', "[wet] WetClutch.r_inner = 0.09: must be < r_outer = 0.08315 [m]"),
    ('[map_protocol]\nfinal_slip_fraction = 1.5\n', "[map_protocol] final_slip_fraction = 1.5: above the upper bound 1.0"),
    ('[wheel]\nr = 1\n', "unknown table [wheel] for model 'wet'"),
    ('[protocol]\nforce = "1 kN"\n', "[protocol] is ambiguous in model 'wet': use [map_protocol] (MapProtocol) or "
                                     "[engagement_protocol] (EngagementProtocol)"),
    ('r_outer = "83 mm"\n', "r_outer = '83 mm' is outside any table"),
    ('model = "wat"\n[wet]\n', "unknown model 'wat'"),
])
def test_file_errors_name_file_table_key_and_value(tmp_path, body, message):
    path = _write(tmp_path, body if body.startswith("model") else 'model = "wet"\n' + body)
    with pytest.raises(ParameterError) as info:
        load_model_file(path)
    assert str(info.value).startswith(f"{path}: ")
    assert message in str(info.value)


@pytest.mark.parametrize("body, message", [
    ('[vehicle]\ngear_ratios = [4.0, 2.4, 2.6, 1.2, 0.9, 0.7]\n', "gear_ratios = [4.0, 2.4, 2.6, 1.2, 0.9, 0.7]: must fall"),
    ('[vehicle]\ngear_ratios = 4.0\n', "[vehicle] gear_ratios = 4.0: expected a list of values [1]"),
    ('[vehicle]\nmass = "-2162 kg"\n', "[vehicle] mass = -2162.0: must be > 0 [kg]"),
    ('[lugre]\nmu_p = 0.1\nmu_c = 0.12\n', "[lugre] LuGreParameters: mu_p = 0.1 < mu_c = 0.12"),
    ('[coupling]\nradius = ["65 mm", "70 mm", "-6 cm"]\n', "[coupling] radius[2] = -0.06: must be > 0 [m] (written '-6 cm')"),
    ('[actuator]\nairgap_open = "0.4 mm"\n', "[actuator] ActuatorParameters: airgap_open = 0.0004 m must exceed free_travel"),
])
def test_emtc_file_errors(tmp_path, body, message):
    path = _write(tmp_path, body, "emtc.toml")
    with pytest.raises(ParameterError) as info:
        load_model_file(path, "emtc")
    assert str(info.value).startswith(f"{path}: ") and message in str(info.value)


def test_eclutch_consistency_checks(tmp_path):
    path = _write(tmp_path, '[virtual_clutch]\nyoke_spring_height = "1 mm"\n', "ec.toml")
    with pytest.raises(ParameterError, match=r"\[virtual_clutch\] VirtualClutch: yoke_spring_height / "
                                             r"yoke_spring_thickness = 1.538 must be < sqrt\(2\)"):
        load_model_file(path)
    path = _write(tmp_path, '[eclutch]\nm_pp = "0 kg"\n', "ec2.toml")
    with pytest.raises(ParameterError, match=r"\[eclutch\] m_pp = 0.0: must be > 0 \[kg\] \(written '0 kg'\)"):
        load_model_file(path)


def test_units_converted_once(tmp_path):
    path = _write(tmp_path, 'model = "wet"\n[wet]\nr_outer = "83.15 mm"\ncontact_modulus = "3 bar"\n'
                            '[map_protocol]\nslip_speed = "300 rpm"\nfluid_temperature = "358.15 K"\n'
                            '[bench]\nactuator_force_max = "16 kN"\n')
    _, sets = load_model_file(path)
    assert sets["wet"].r_outer == pytest.approx(0.08315, rel=1e-14)
    assert sets["wet"].contact_modulus == pytest.approx(3e5, rel=1e-14)
    assert sets["map_protocol"].slip_speed == pytest.approx(300 * 2 * 3.141592653589793 / 60, rel=1e-14)
    assert sets["map_protocol"].fluid_temperature == pytest.approx(85.0, rel=1e-12)
    assert sets["bench"].actuator_force_max == pytest.approx(16e3, rel=1e-14)


def test_model_inferred_or_required(tmp_path):
    path = _write(tmp_path, '[wet]\nr_outer = "84 mm"\n', "x.toml")
    assert load_model_file(path)[0] == "wet"
    path = _write(tmp_path, '[wet]\n[lugre]\n', "y.toml")
    with pytest.raises(ParameterError, match="do not belong to one model"):
        load_model_file(path)
    path = _write(tmp_path, 'model = "wet"\n[wet]\n', "z.toml")
    with pytest.raises(ParameterError, match="model = 'wet' but model 'emtc' was asked for"):
        load_model_file(path, "emtc")
