"""Bad physical input to the E-clutch models: refused with a clear message, never a traceback."""

import numpy as np
import pandas as pd
import pytest

from clutchlab.eclutch import ClutchModel, pedal_reference
from clutchlab.eclutch.characterize import characterize
from clutchlab.eclutch.pressrig import simulate_press_test
from clutchlab.eclutch.scenario import scenario_from_dict
from clutchlab.eclutch.validation import compare
from clutchlab.errors import DataError, ParameterError, SimulationError
from cli_checks import one_line_error




def leaf(s):
    return 2e5 * np.asarray(s, dtype=float)


# ------------------------------------------------------------ press records of reversed sign
@pytest.fixture(scope="module")
def press():
    return simulate_press_test(leaf, 5e-3, friction_N=20.0, friction_rel=0.0)


def test_characterize_refuses_a_negated_displacement(press):
    rec = press.assign(displacement_m=-press["displacement_m"])
    with pytest.raises(DataError, match=r"hysteresis half-width -\d.* the sign of 'displacement_m' looks reversed"):
        characterize(rec)
    assert np.all(characterize(press).hysteresis_half_width[5:-5] > 15.0)   # the same record, right sign


@pytest.mark.parametrize("friction", [20.0, 0.0])
def test_characterize_refuses_a_negated_force(press, friction):
    rec = simulate_press_test(leaf, 5e-3, friction_N=friction, friction_rel=0.0)
    rec["force_N"] = -rec["force_N"]
    with pytest.raises(DataError, match=r"force_N is negative over most of the record \(median -\d"):
        characterize(rec)
    rec["displacement_m"] = -rec["displacement_m"]          # both negated: a mirrored record, still refused
    with pytest.raises(DataError, match="force_N is negative"):
        characterize(rec)


def test_characterize_accepts_zero_friction_without_a_false_alarm():
    rec = simulate_press_test(leaf, 5e-3, friction_N=0.0, friction_rel=0.0, force_noise_N=3.0, seed=4)
    curve = characterize(rec)
    np.testing.assert_allclose(curve.hysteresis_half_width[5:-5], 0.0, atol=1.5)


def test_cli_characterize_negated_displacement(tmp_path, capsys, press):
    path = tmp_path / "neg.csv"
    press.assign(displacement_m=-press["displacement_m"]).to_csv(path, index=False)
    line = one_line_error(capsys, ["eclutch", "characterize", str(path), "-o", str(tmp_path / "c.csv")])
    assert f"{path}: the unloading force lies above the loading force" in line and "'displacement_m'" in line
    assert not (tmp_path / "c.csv").exists()


# ------------------------------------------------------------ validation on a record without excitation
def zero_record(n=50):
    z = np.zeros(n)
    return pd.DataFrame({"time_s": 0.01 * np.arange(n), "bearing_position_m": z, "bearing_force_N": z,
                         "torque_Nm": z})


def test_compare_refuses_an_all_zero_record():
    with pytest.raises(DataError, match=r"bearing_position_m is constant \(0 m\)"):
        compare(ClutchModel.preset(0), zero_record())
    rec = zero_record()
    rec["bearing_position_m"] = np.linspace(0.0, 5e-3, len(rec))   # travel, but no force recorded
    with pytest.raises(DataError, match=r"bearing_force_N is never > 0 on the release branch \(max 0 N\)"):
        compare(ClutchModel.preset(0), rec)


def test_cli_validate_all_zero_record(tmp_path, capsys):
    path = tmp_path / "zero.csv"
    zero_record().to_csv(path, index=False)
    line = one_line_error(capsys, ["eclutch", "validate", str(path)])
    assert f"{path}: bearing_position_m is constant (0 m)" in line


# ------------------------------------------------------------ static curve beyond the characterised travel
def test_static_curve_beyond_the_characterised_range_raises():
    model = ClutchModel.preset(4)
    with pytest.raises(SimulationError, match=r"deflects the 'diaphragm' spring by [\d.]+ mm, outside its "
                                              r"characterised range 0.0049\d*\.\.14.05 mm"):
        model.static_curve(np.linspace(0.0, 0.5, 50))
    far = model.static_curve(np.linspace(0.0, 0.5, 50), extrapolate=True)   # on request: the continuation
    assert far["bearing_force_N"].iloc[-1] > 1e4
    # the whole nominal travel lies within the characterised ranges
    assert model.static_curve(np.linspace(0.0, 9e-3, 50))["bearing_force_N"].max() < 3e3


def test_cli_static_500_mm(tmp_path, capsys):
    out = tmp_path / "s.csv"
    line = one_line_error(capsys, ["eclutch", "static", "--model", "1", "--travel", "500 mm", "--points", "20",
                                   "-o", str(out)])
    assert "Model 1: bearing position" in line and "'diaphragm' spring" in line and "extrapolation" in line
    assert "--extrapolate" in line
    assert not out.exists()
    # on request (#33: the API's extrapolate=True had no CLI option): the API's continuation, said in the header
    from clutchlab.cli import main

    assert main(["eclutch", "static", "--model", "1", "--travel", "500 mm", "--points", "20", "--extrapolate",
                 "-o", str(out)]) == 0
    got = pd.read_csv(out, comment="#")
    ref = ClutchModel.preset(1).static_curve(np.linspace(0.0, 0.5, 20), extrapolate=True)
    np.testing.assert_allclose(got["bearing_force_N"], ref["bearing_force_N"], rtol=1e-8)   # (9 digits in the file)
    assert "--extrapolate: characteristics may be continued linearly" in out.read_text()


# ------------------------------------------------------------ pedal beyond its stops
def test_pedal_reference_refuses_values_outside_0_1():
    np.testing.assert_allclose(pedal_reference([0.0, 0.5, 1.0], 8e-3), [0.0, 4e-3, 8e-3])
    with pytest.raises(ParameterError, match=r"pedal\[2\] = 5.0: a pedal position must lie in 0..1"):
        pedal_reference([0.0, 0.5, 5.0])
    with pytest.raises(ParameterError, match=r"pedal\[0\] = -0.1"):
        pedal_reference([-0.1, 0.5])


def scenario(value, **extra):
    return {"scenario": {"model": 4, "t_end": "1 s"},
            "input": {"kind": "pedal", "time_s": [0.0, 0.5, 1.0], "value": value, **extra}}


def test_scenario_pedal_out_of_range_names_file_key_and_value(tmp_path):
    with pytest.raises(ParameterError, match=r"launch.toml: \[input\] value\[1\] = 5.0: a pedal position"):
        scenario_from_dict(scenario([0.0, 5.0, 0.0]), source="launch.toml")
    with pytest.raises(ParameterError, match=r"\[input\] value\[2\] = nan"):
        scenario_from_dict(scenario([0.0, 0.5, float("nan")]), source="launch.toml")
    with pytest.raises(ParameterError, match=r"release_travel = -0.008 m: must be finite and > 0"):
        scenario_from_dict(scenario([0.0, 0.5, 0.0], release_travel="-8 mm"), source="launch.toml")
    (tmp_path / "pedal.csv").write_text("time_s,value\n0,0\n0.5,0.5\n1,1.5\n")
    with pytest.raises(ParameterError, match=r"pedal.csv: row 2 value = 1.5"):
        scenario_from_dict({"scenario": {"model": 4, "t_end": "1 s"}, "input": {"kind": "pedal", "file": "pedal.csv"}},
                           source=str(tmp_path / "s.toml"))
    # a bearing-position input is no fraction: 5 mm is fine
    sc = scenario_from_dict({"scenario": {"model": 4, "t_end": "1 s"},
                             "input": {"kind": "bearing_position", "time_s": [0.0, 1.0], "value": ["0 mm", "5 mm"]}})
    assert sc.value[-1] == pytest.approx(5e-3)


def test_cli_simulate_pedal_of_5(tmp_path, capsys):
    path = tmp_path / "launch.toml"
    path.write_text('[scenario]\nmodel = 4\nt_end = "1 s"\n[input]\nkind = "pedal"\n'
                    'time_s = [0.0, 0.5, 1.0]\nvalue = [0.0, 5, 0.0]\n')
    line = one_line_error(capsys, ["eclutch", "simulate", str(path), "-o", str(tmp_path / "r.csv")])
    assert f"{path}: [input] value[1] = 5.0: a pedal position must lie in 0..1" in line
    assert not (tmp_path / "r.csv").exists()
