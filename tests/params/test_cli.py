"""``clutchlab params show|check``."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from clutchlab.cli import main
from clutchlab.params.registry import load_model_file, preset


def test_show_table_has_values_units_and_sources(capsys):
    assert main(["params", "show", "wet", "--paper"]) == 0
    out = capsys.readouterr().out
    assert "[wet]  paper preset WetClutch.paper()" in out
    line = next(ln for ln in out.splitlines() if ln.split()[:1] == ["r_outer"])
    assert line.split()[1:3] == ["0.08315", "m"] and "Shin et al., Table 1" in line
    assert "[bench]  defaults Bench()" in out  # no paper() preset: the defaults, said so
    assert main(["params", "show", "emtc"]) == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if ln.split()[:1] == ["mass"] and "curb" in ln)
    assert line.split()[1:3] == ["2162", "kg"] and "[1] Table 1" in line


@pytest.mark.parametrize("model", ["eclutch", "wet", "emtc"])
def test_show_toml_round_trip_and_check(model, tmp_path, capsys):
    assert main(["params", "show", model, "--toml"]) == 0
    path = tmp_path / f"{model}.toml"
    path.write_text(capsys.readouterr().out)
    assert load_model_file(path) == (model, preset(model))
    assert main(["params", "check", str(path)]) == 0
    assert f"valid {model} parameters" in capsys.readouterr().out


def test_show_output_file_and_overwrite(tmp_path, capsys):
    path = tmp_path / "wet.toml"
    assert main(["params", "show", "wet", "--paper", "-o", str(path)]) == 0
    assert load_model_file(path)[1] == preset("wet", paper=True)
    assert main(["params", "show", "wet", "-o", str(path)]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["params", "show", "wet", "-o", str(path), "--force"]) == 0


def test_check_reports_file_table_key_and_value(tmp_path, capsys):
    path = tmp_path / "wet.toml"
    path.write_text('[wet]\nr_outer = "83.15 kg"\n')
    assert main(["params", "check", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"clutchlab: error: {path}: [wet] r_outer = '83.15 kg': wrong unit: kg is not a length" in err
    path.write_text('[actuator]\nmass = "150 g"\n')
    assert main(["params", "check", str(path)]) == 0  # the model is inferred from the tables
    assert "valid emtc parameters ([actuator] 8 fields)" in capsys.readouterr().out
    assert main(["params", "check", str(path), "--model", "wet"]) == 2
    assert "unknown table [actuator] for model 'wet'" in capsys.readouterr().err
    assert main(["params", "check", str(tmp_path / "missing.toml")]) == 2
    assert "no such parameter file" in capsys.readouterr().err


@pytest.mark.parametrize("value, text", [
    (20240601, "20240601"), (8, "8"), (0.08315, "0.08315"), (2.3e6, "2.3e6"), (3e-11, "3e-11"),
    (1.5e-5, "1.5e-5"), (628.3185307, "628.319"), (-95000.0, "-95000"), (12.0, "12"), (0.0, "0"),
])
def test_numbers_print_as_a_person_reads_them(value, text):
    from clutchlab.params.registry import format_number

    assert format_number(value) == text


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e30, max_value=1e30))
def test_formatted_numbers_read_back_to_six_digits(value):
    from clutchlab.params.registry import format_number

    assert float(format_number(value)) == pytest.approx(value, rel=5e-6, abs=1e-300)


def test_params_show_prints_the_seed_as_an_integer_and_readable_units(capsys):
    assert main(["params", "show", "wet"]) == 0
    rows = {ln.split()[0]: ln.split()[1:3] for ln in capsys.readouterr().out.splitlines() if ln.startswith("  ")}
    assert rows["seed"] == ["20240601", "1"]
    assert rows["contact_modulus"] == ["2.3e6", "Pa"] and rows["friction_area"][1] == "m^2"
