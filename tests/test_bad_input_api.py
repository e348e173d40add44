"""Issue #33's bad input that reached users as NumPy's, pint's or Python's own exceptions, and bad values that were
taken: every one is now a :class:`~clutchlab.errors.ClutchlabError` naming the field and the value (the CLI: one
line, exit 2), or a warning where the input is legal but unwise (a fixed step far above the model's fastest time
constant).  Each case here failed before: a ``ValueError``/``TypeError``/``AttributeError`` from NumPy or Python,
or no error at all.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from cli_checks import one_line_error
from clutchlab.errors import ClutchlabError, DataError, ParameterError


def _net():
    from clutchlab.driveline import Driveline

    d = Driveline("x")
    d.inertia("a", J=1.0)
    d.inertia("b", J=1.0)
    return d


def _sweep(spec):
    from clutchlab.sweep import run_sweep

    return run_sweep(spec, "never-written")


def _directions():
    from clutchlab.control import linearize
    from clutchlab.driveline.network import _example_system

    return linearize(_example_system(), directions="rising")


# (call, the exception's class, what its message names)
API = {
    "clutch mu as a string": (lambda: _net().clutch("c", "a", "b", fn_max=10.0, mu="abc"), ParameterError, "c: mu = 'abc'"),
    "clutch mu table ragged": (lambda: _net().clutch("c", "a", "b", fn_max=10.0, mu=[[0.0, 0.3], [1.0]]),
                               ParameterError, "every row of the same length"),
    "spring curve ragged": (lambda: _net().spring("s", "a", "b", curve=[[0.0, 0.0], [1.0]]), ParameterError,
                            "s: curve"),
    "engine map a string": (lambda: _net().engine("e", "a", torque_map="abc"), ParameterError, "e: torque_map"),
    "engine map ragged": (lambda: _net().engine("e", "a", torque_map=[[0.0, 10.0], [100.0]]), ParameterError,
                          "e: torque_map"),
    "engine map a string in its torques": (lambda: _net().engine("e", "a", torque_map=([0.0, 1.0], [0.0, 1.0], "x")),
                                           ParameterError, "torque_map torques"),
    "table signal of strings": (lambda: __import__("clutchlab.driveline", fromlist=["Signal"]).Signal.table(
        "abc", [1.0, 2.0]), ParameterError, "table signal: times"),
    "table signal ragged": (lambda: __import__("clutchlab.driveline", fromlist=["Signal"]).Signal.table(
        [0.0, 1.0], [[1.0], [2.0, 3.0]]), ParameterError, "table signal: values"),
    "parse_driveline(None)": (lambda: __import__("clutchlab.driveline.description", fromlist=["x"]).parse_driveline(
        None, "x.toml"), ParameterError, "x.toml: expected a driveline document"),
    "run_sweep of an int": (lambda: _sweep(3), ParameterError, "sweep spec = 3"),
    "run_sweep of a dict with an unknown table": (lambda: _sweep({"a": 1}), ParameterError, "unknown table [a]"),
    "linearize with directions as a word": (_directions, ParameterError, "directions = 'rising'"),
}


@pytest.mark.parametrize("case", sorted(API))
def test_api_calls_raise_clutchlabs_exceptions_naming_the_field(case):
    call, cls, named = API[case]
    with pytest.raises(cls) as info:
        call()
    assert isinstance(info.value, ClutchlabError) and named in str(info.value), str(info.value)


# ------------------------------------------------------------------------------------------ friction maps (JSON)
GOOD_MAP = {"speed_grid": [0.0, 1.0], "temperature_grid": [40.0, 80.0], "values": [[0.1, 0.12], [0.11, 0.13]]}
BAD_MAPS = {
    "ragged values": ({"values": [[0.1], [0.11, 0.13]]}, "FrictionMap.values"),
    "a string in the grid": ({"speed_grid": [0.0, "x"]}, "FrictionMap.speed_grid"),
    "a list where statistics go": ({"statistics": [1, 2]}, "FrictionMap.statistics"),
    "a string region": ({"region": "abc"}, "FrictionMap.region"),
    "ragged coverage": ({"covered": [[1], [1, 1]]}, "FrictionMap.covered"),
    "a law that is a string": ({"law": "abc"}, "FrictionMap.law"),
    "a grid that is a table": ({"speed_grid": [[0.0, 1.0]]}, "FrictionMap.speed_grid"),
    "mu = 1e6": ({"values": [[0.1, 1e6], [0.11, 0.13]]}, "1e+06 is not a friction coefficient in [0, 2]"),
}


@pytest.mark.parametrize("case", sorted(BAD_MAPS))
def test_a_bad_friction_map_file_is_one_line_naming_the_file_and_the_field(tmp_path, capsys, case):
    from clutchlab.wet.friction import FrictionMap

    change, named = BAD_MAPS[case]
    path = tmp_path / "map.json"
    path.write_text(json.dumps({**GOOD_MAP, **change}))
    with pytest.raises(DataError) as info:
        FrictionMap.from_json(path)
    assert str(path) in str(info.value) and named in str(info.value), str(info.value)
    # through the command line, as the 18 probes went: one line, exit 2, no traceback
    (tmp_path / "d.toml").write_text(
        '[inertia.J]\nJ = "0.5 kg m^2"\nw0 = "100 rad/s"\n'
        '[brake.brake]\nflange = "J"\nfn_max = "200 N"\nmu_map = "map.json"\nradius = "100 mm"\n'
        'temperature = "80 degC"\n')
    line = one_line_error(capsys, ["driveline", "describe", str(tmp_path / "d.toml")])
    assert "map.json" in line and named in line, line
    path.write_text(json.dumps(GOOD_MAP))
    assert FrictionMap.from_json(path).mu(0.5, 60.0) == pytest.approx(0.115)   # (the good map is taken)


# ------------------------------------------------------------------------------------------ Preisach models (JSON)
@pytest.fixture
def preisach_file(tmp_path):
    from clutchlab.hysteresis import Preisach

    path = tmp_path / "magnet.json"
    Preisach(np.linspace(0.0, 2.0, 4), np.tril(np.ones((4, 4))) * 10.0).to_json(path)
    return path


@pytest.mark.parametrize("change, named", [
    ({"airgaps_m": "abc"}, "airgaps_m = 'abc'"),
    ({"airgaps_m": [[1e-3], [1.0, 2.0]]}, "airgaps_m = [[0.001], [1.0, 2.0]]"),
    ({"airgaps_m": {"a": 1}}, "airgaps_m = {'a': 1}"),
    ({"grid_A": "abc"}, "grid_A = 'abc'"),
    ({"tables_N": [[1e300] * 10]}, "1e+300 N is implausible for a magnet's force"),
])
def test_a_bad_preisach_model_file_names_the_file_and_the_field(preisach_file, tmp_path, capsys, change, named):
    from clutchlab.hysteresis import Preisach

    body = json.loads(preisach_file.read_text())
    body.update(change)
    preisach_file.write_text(json.dumps(body))
    with pytest.raises(DataError) as info:
        Preisach.from_json(preisach_file)
    assert str(preisach_file) in str(info.value) and named in str(info.value), str(info.value)
    (tmp_path / "in.csv").write_text("current\n0.0\n1.0\n")
    line = one_line_error(capsys, ["emtc", "preisach", "run", str(preisach_file), str(tmp_path / "in.csv"), "-o",
                                   str(tmp_path / "out.csv")])
    assert named in line, line
    assert not (tmp_path / "out.csv").exists()


def test_forces_of_1e300_n_are_never_written_into_a_preisach_model(tmp_path):
    from clutchlab.hysteresis import Preisach

    with pytest.raises(DataError, match="implausible for a magnet's force"):
        Preisach(np.linspace(0.0, 2.0, 3), np.tril(np.ones((3, 3))) * 1e300)
    with pytest.raises(ParameterError, match="implausible for an air gap"):
        Preisach(np.linspace(0.0, 2.0, 3), np.stack([np.tril(np.ones((3, 3)))] * 2), airgaps=[1e-3, 50.0])


# ------------------------------------------------------------------------------------------ bad values taken before
_WET = ('[inertia.J1]\nJ = "0.2 kg m^2"\nw0 = "100 rad/s"\n[inertia.J2]\nJ = "0.2 kg m^2"\n'
        '[wet_clutch.wc]\na = "J1"\nb = "J2"\nforce = "{force}"\ntemperature0 = "{temperature}"\n')
_ENGINE = ('[inertia.J1]\nJ = "0.2 kg m^2"\n[engine.ice]\nflange = "J1"\n'
           'torque_map = [[0, 100], [600, 150]]\nthrottle = {throttle}\n')


@pytest.mark.parametrize("text, named", [
    (_WET.format(force="1e12 N", temperature="80 degC"), "the force reference reaches 1e+12 N, beyond the actuator's 16000 N"),
    (_WET.format(force="2000 N", temperature="1e6 degC"), "temperature0 = '1e6 degC': is above its range [-60, 600] degC"),
    (_WET.format(force="2000 N", temperature="-100 degC"), "temperature0 = '-100 degC': is below its range [-60, 600] degC"),
    (_ENGINE.format(throttle="2"), "engine.ice.throttle = 2 reaches 2: is above its range [0, 1]"),
    (_ENGINE.format(throttle="-1"), "engine.ice.throttle = -1 reaches -1: is below its range [0, 1]"),
    (_ENGINE.format(throttle='{ ramp = { height = 1.5, duration = "1 s" } }'), "reaches 1.5"),
])
def test_values_outside_their_physical_range_are_refused_by_name(tmp_path, capsys, text, named):
    from clutchlab.driveline.description import load_driveline

    path = tmp_path / "d.toml"
    path.write_text(text)
    with pytest.raises(ParameterError) as info:
        load_driveline(path)
    assert named in str(info.value) and "d.toml" in str(info.value), str(info.value)
    assert named in one_line_error(capsys, ["driveline", "describe", str(path)])


def test_the_values_at_the_ends_of_the_ranges_are_taken(tmp_path):
    from clutchlab.driveline.description import load_driveline

    for text in (_WET.format(force="16000 N", temperature="600 degC"), _WET.format(force="0 N", temperature="-60 degC"),
                 _ENGINE.format(throttle="1"), _ENGINE.format(throttle="0"),
                 _ENGINE.format(throttle='{ input = "pedal" }') + '[input.pedal]\nstart = 0.5\n'):
        (tmp_path / "d.toml").write_text(text)
        load_driveline(tmp_path / "d.toml")


PROFILES = ([0.0, 0.2], [0.0, 2000.0], [0.0], [0.0], 4.0)   # (force and speed profiles, duration)


def test_a_wet_scenario_at_1e6_degc_is_refused():
    from clutchlab.wet.engagement import Scenario

    with pytest.raises(ParameterError, match=r"Scenario.initial_temperature_c = 1000000.0: outside the wet clutch's "
                                             r"temperatures \[-60, 600\] degC"):
        Scenario(*PROFILES, initial_temperature_c=1e6)
    with pytest.raises(ParameterError, match="Scenario.heater_setpoint_c"):
        Scenario(*PROFILES, heater_setpoint_c=-200.0)
    assert Scenario(*PROFILES, initial_temperature_c=150.0).initial_temperature_c == 150.0


def test_an_actuator_reference_beyond_the_csc_travel_is_refused(tmp_path, capsys):
    """50 mm of bearing reference (the CSC travels 10 mm): refused by the API, in a scenario file (naming the
    entry) and in a driveline's E-clutch; within the travel nothing changes."""
    from clutchlab.eclutch.dynamics import EClutch

    with pytest.raises(ParameterError, match=r"'bearing_reference' = 0.05 m is outside the CSC travel \[-0.0015, 0.01\] m"):
        EClutch().simulate({"bearing_reference": ([0.0, 0.1], [0.0, 0.05])}, 0.2)
    with pytest.raises(ParameterError, match="outside the CSC travel"):
        EClutch().as_system({"bearing_reference": 0.05})
    scenario = tmp_path / "s.toml"
    scenario.write_text('[scenario]\nmodel = 4\nt_end = "0.2 s"\n[input]\nkind = "bearing_reference"\n'
                        'time_s = [0, 0.1]\nvalue = ["0 mm", "50 mm"]\n')
    line = one_line_error(capsys, ["eclutch", "simulate", str(scenario), "-o", str(tmp_path / "r.csv")])
    assert "s.toml: [input] value[1] = 0.05 m is outside the CSC travel" in line, line
    scenario.write_text('[scenario]\nmodel = 4\nt_end = "0.2 s"\n[input]\nkind = "pedal"\nrelease_travel = "50 mm"\n'
                        'time_s = [0, 0.1]\nvalue = [0, 1]\n')
    line = one_line_error(capsys, ["eclutch", "simulate", str(scenario), "-o", str(tmp_path / "r.csv")])
    assert "release_travel = 0.05 m is beyond the CSC travel 0.01 m" in line, line
    (tmp_path / "d.toml").write_text('[inertia.J1]\nJ = 1\n[inertia.J2]\nJ = 1\n[eclutch.ec]\na = "J1"\nb = "J2"\n'
                                     'position = "50 mm"\nactuator = true\n')
    line = one_line_error(capsys, ["driveline", "describe", str(tmp_path / "d.toml")])
    assert "ec: input 'bearing_reference' = 0.05 m is outside the CSC travel" in line, line


def test_an_operating_point_takes_a_quantity_string(eclutch_operating_points):
    """``EClutch.operating_point("4 mm")`` is the operating point at 0.004 m (a ValueError before); a quantity of
    the wrong kind is refused by name."""
    op_string, op_number = eclutch_operating_points
    np.testing.assert_array_equal(op_string.x, op_number.x)
    from clutchlab.eclutch.dynamics import EClutch

    with pytest.raises(ParameterError, match="bearing_position = '4 kg': wrong unit"):
        EClutch().operating_point("4 kg")


@pytest.fixture(scope="module")
def eclutch_operating_points():
    from clutchlab.eclutch.dynamics import EClutch

    e = EClutch()
    return e.operating_point("4 mm"), e.operating_point(0.004)


# ------------------------------------------------------------------------------------------ a fixed step far too long
def test_a_fixed_step_far_above_the_fastest_time_constant_is_warned_about(capsys, tmp_path):
    """An inertia on a damper (tau = J / d = 2 ms): a 0.5 s fixed step is 250 tau, said in one warning naming
    the step and tau (the run goes on: Rodas3 stays stable); 1 ms is not.  The command line says it in one
    line."""
    from clutchlab.driveline import Driveline
    from clutchlab.system import FixedStepWarning, fastest_time_constant, simulate

    d = Driveline("damped")
    d.inertia("J1", J=2.0, w0=10.0)
    d.spring_damper("d", "J1", "ground", c=0.0, d=1000.0)
    system = d.system()
    assert fastest_time_constant(system) == pytest.approx(2e-3, rel=1e-6)
    with pytest.warns(FixedStepWarning, match=r"fixed_step = 0.5 s is 250 times the model's fastest time constant at "
                                              r"its start \(0.002 s\)"):
        simulate(system, 1.0, fixed_step=0.5, output_step=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error", FixedStepWarning)
        simulate(system, 0.01, fixed_step=1e-3)
    # a free inertia has no time constant: any step
    free = Driveline("free")
    free.inertia("J1", J=2.0, w0=10.0)
    assert fastest_time_constant(free.system()) == float("inf")
    path = tmp_path / "d.toml"
    path.write_text('[inertia.J1]\nJ = "2 kg m^2"\nw0 = "10 rad/s"\n[spring_damper.d]\na = "J1"\nb = "ground"\n'
                    'c = 0\nd = "1000 N m s/rad"\n[simulation]\nt_end = "1 s"\n')
    from clutchlab.cli import main

    assert main(["driveline", "simulate", str(path), "-o", str(tmp_path / "r.csv"), "--fixed-step", "0.5 s",
                 "--output-step", "0.5 s"]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(err) == 1 and err[0].startswith("clutchlab: warning: ") and "250 times" in err[0], err
