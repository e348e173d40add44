"""ParameterSet base: units metadata, validation, TOML round trip, clear errors."""

import dataclasses
from pathlib import Path

import pytest

from clutchlab.eclutch import EClutchParameters, VirtualClutch
from clutchlab.errors import ParameterError
from clutchlab.params import ParameterSet, quantity


@dataclasses.dataclass(frozen=True)
class Toy(ParameterSet):
    kind = "toy"
    r_outer: float = quantity(0.08, "m", "outer radius", positive=True)
    r_inner: float = quantity(0.06, "m", "inner radius", positive=True)
    n: int = quantity(3, "1", "number of plates", positive=True)
    visc: tuple = quantity((0.01, 2.0), "1", "coefficients")

    def check(self):
        if not self.r_inner < self.r_outer:
            raise ParameterError(f"Toy: r_inner = {self.r_inner!r} m must be < r_outer = {self.r_outer!r} m")


@pytest.mark.parametrize("cls", [Toy, EClutchParameters, VirtualClutch])
def test_every_field_has_unit_and_doc(cls):
    for name, meta in cls.field_info().items():
        assert meta["unit"], name
        assert meta["doc"], name


def test_validation_errors():
    with pytest.raises(ParameterError, match="r_inner = 0.09 m must be < r_outer"):
        Toy(r_inner=0.09)
    with pytest.raises(ParameterError, match=r"Toy.r_outer = -1.0: must be > 0"):
        Toy(r_outer=-1.0)
    with pytest.raises(ParameterError, match="not finite"):
        Toy(r_outer=float("nan"))
    with pytest.raises(ParameterError, match="unknown parameter"):
        Toy().replace(radius=1.0)


def test_toml_round_trip_with_units(tmp_path):
    t = Toy(r_outer=0.09, n=5, visc=(0.02, 3.0))
    path = t.to_toml(tmp_path / "toy.toml")
    text = path.read_text()
    assert "[toy]" in text and '"0.09 m"' in text
    assert Toy.from_toml(path) == t
    with pytest.raises(FileExistsError):
        t.to_toml(path)
    t.to_toml(path, overwrite=True)


def test_from_dict_converts_units_and_reports_source():
    t = Toy.from_dict({"r_outer": "83.15 mm", "n": 4, "visc": ["0.5", 1]}, source="x.toml")
    assert t.r_outer == pytest.approx(0.08315) and t.n == 4 and isinstance(t.n, int)
    with pytest.raises(ParameterError, match="x.toml: n = 2.5: expected a whole number"):
        Toy.from_dict({"n": 2.5}, source="x.toml")
    with pytest.raises(ParameterError, match="x.toml: Toy: r_inner = 0.1 m must be < r_outer"):
        Toy.from_dict({"r_inner": "100 mm"}, source="x.toml")
    with pytest.raises(ParameterError, match="x.toml: unknown parameter 'r_out'"):
        Toy.from_dict({"r_out": 1}, source="x.toml")


def test_describe_lists_units():
    text = EClutchParameters().describe()
    assert "lever_ratio" in text and "N/m" in text and "Haramina" in text


def test_subclasses_register_themselves():
    from clutchlab.params.base import registered_sets

    assert Toy in registered_sets() and EClutchParameters in registered_sets()


def test_from_toml_names_file_table_key_and_value(tmp_path):
    path = tmp_path / "toy.toml"
    path.write_text('[toy]\nr_outer = "80 kg"\n')
    with pytest.raises(ParameterError) as info:
        Toy.from_toml(path)
    assert str(info.value) == f"{path}: [toy] r_outer = '80 kg': wrong unit: kg is not a length (it is a mass; expected m)"
    path.write_text('[toy]\nvisc = 0.5\n')
    with pytest.raises(ParameterError, match=r"\[toy\] visc = 0.5: expected a list of values \[1\]"):
        Toy.from_toml(path)
    path.write_text('[toy]\nvisc = [0.5, "x"]\n')
    with pytest.raises(ParameterError, match=r"\[toy\] visc\[1\] = 'x': cannot parse quantity"):
        Toy.from_toml(path)
    path.write_text('[toy]\nr_inner = "70 mm"\nr_outer = "0.065 m"\n')
    with pytest.raises(ParameterError, match=r"toy.toml: \[toy\] Toy: r_inner = 0.07 m must be < r_outer = 0.065 m"):
        Toy.from_toml(path)
    path.write_text('r_outer = "90 mm"\n')  # a file without the table is read from the top level
    assert Toy.from_toml(path).r_outer == pytest.approx(0.09)


def test_a_reference_number_the_model_does_not_read_is_no_parameter():
    """A paper's table entry the equations do not read (``quantity(..., reference=True)``: the wet clutch's core
    thickness beside its core's mass, the EMTC vehicle's centre-of-mass height and reverse ratio) stays in the set
    and its files, but is no parameter of an FMU, a sweep or a network, where a value would change nothing (the
    native exporter found each changing no number of its model)."""
    import dataclasses

    from clutchlab.driveline.variants import DrivelineDocument
    from clutchlab.emtc.params import VehicleParameters
    from clutchlab.fmu.emtc import EmtcCoSimulation
    from clutchlab.fmu.wet import WetCoSimulation
    from clutchlab.params.base import is_reference
    from clutchlab.sweep.targets import sweepable_fields
    from clutchlab.wet.params import WetClutch

    marked = {(cls.__name__, f.name) for cls in (WetClutch, VehicleParameters) for f in dataclasses.fields(cls)
              if is_reference(f)}
    assert marked == {("WetClutch", "core_thickness"), ("VehicleParameters", "cg_height"),
                      ("VehicleParameters", "reverse_ratio")}
    assert WetClutch(core_thickness=2e-3).core_thickness == 2e-3   # (kept, and checked, in the set)
    wet = {v.name for v in WetCoSimulation.parameters}
    emtc = {v.name for v in EmtcCoSimulation.parameters}
    assert "clutch.core_thickness" not in wet and "clutch.m_core" in wet
    assert {"vehicle.cg_height", "vehicle.reverse_ratio"}.isdisjoint(emtc) and "vehicle.cg_to_front" in emtc
    assert "clutch.core_thickness" not in sweepable_fields("clutch", WetClutch)
    doc = DrivelineDocument.read(Path(__file__).resolve().parents[2] / "examples" / "driveline_wet_sae2.toml")
    assert "clutch.clutch.core_thickness" not in doc.parameters and "clutch.clutch.m_core" in doc.parameters
