"""One option set for every entry point that runs a model (#31): ``rtol``, ``atol``, ``max_step``, ``output_step``
and ``fixed_step``, with one meaning and one check (:func:`clutchlab.system.check_rtol`, ``check_atol``), on the
Python entry points and on every ``simulate`` command."""

from __future__ import annotations

import inspect
import math
from pathlib import Path

import numpy as np
import pytest

from cli_checks import one_line_error
from clutchlab.cli import main
from clutchlab.driveline import Driveline
from clutchlab.eclutch import ClutchDynamics, ClutchModel, EClutch
from clutchlab.eclutch import scenario as eclutch_scenario
from clutchlab.emtc import system as emtc_system
from clutchlab.emtc.bench import simulate_bench
from clutchlab.errors import ParameterError
from clutchlab.system import RTOL_MIN, RUN_OPTIONS, check_atol, check_rtol, simulate
from clutchlab.wet import EngagementProtocol, WetClutch, simulate_engagement
from clutchlab.wet import engagement as wet_engagement
from clutchlab.wet.bench import run_protocol

EXAMPLES = Path(__file__).parents[1] / "examples"

ENTRY_POINTS = {
    "clutchlab.system.simulate": simulate,
    "clutchlab.wet.engagement.simulate": wet_engagement.simulate,
    "clutchlab.wet.simulate_engagement": simulate_engagement,
    "clutchlab.wet.bench.run_protocol": run_protocol,
    "clutchlab.emtc.system.simulate": emtc_system.simulate,
    "clutchlab.emtc.bench.simulate_bench": simulate_bench,
    "clutchlab.eclutch.EClutch.simulate": EClutch.simulate,
    "clutchlab.eclutch.ClutchDynamics.simulate": ClutchDynamics.simulate,
    "clutchlab.eclutch.scenario.simulate": eclutch_scenario.simulate,
    "clutchlab.eclutch.scenario.run_scenario": eclutch_scenario.run_scenario,
    "clutchlab.driveline.Driveline.simulate": Driveline.simulate,
}


@pytest.mark.parametrize("name", sorted(ENTRY_POINTS))
def test_every_entry_point_takes_the_one_option_set(name):
    params = inspect.signature(ENTRY_POINTS[name]).parameters
    missing = [o for o in RUN_OPTIONS if o not in params or params[o].kind is not inspect.Parameter.KEYWORD_ONLY]
    assert not missing, f"{name} lacks keyword options {missing}"
    doc = inspect.getdoc(ENTRY_POINTS[name]) or ""
    assert all(o in doc for o in RUN_OPTIONS), f"{name}: its docstring names every option"


@pytest.mark.parametrize("bad", [0, 0.0, 1, 1.5, -1e-6, math.nan, math.inf, True, "1e-6", None, RTOL_MIN / 2, 1e-16])
def test_rtol_has_one_rule(bad):
    with pytest.raises(ParameterError, match=r"^rtol = "):
        check_rtol(bad)


@pytest.mark.parametrize("good", [RTOL_MIN, 1e-12, 1e-6, 0.5, np.float32(1e-3), 1e-3])
def test_rtol_in_range_is_taken_as_given(good):
    assert check_rtol(good) == float(good)


def test_atol_is_one_value_or_one_per_state():
    np.testing.assert_array_equal(check_atol(1e-6, (3,)), [1e-6] * 3)
    np.testing.assert_array_equal(check_atol([1, 2, 3], (3,)), [1, 2, 3])
    for bad in (0.0, -1.0, math.nan, [1, 2], "x", [1e-6, 0.0, 1e-6]):
        with pytest.raises(ParameterError, match=r"^atol = "):
            check_atol(bad, (3,))


def _refusals():
    """Each entry point called with ``rtol`` ruled out; every call refuses before anything runs (no kernel is
    compiled here)."""
    clutch = WetClutch.paper()
    scen = EngagementProtocol().scenario(clutch)
    d = Driveline("one")
    d.inertia("J", J=1.0, w0=1.0)
    return {
        "clutchlab.wet.engagement.simulate": lambda r: wet_engagement.simulate(scen, rtol=r),
        "clutchlab.wet.simulate_engagement": lambda r: simulate_engagement(clutch, scen, rtol=r),
        "clutchlab.wet.bench.run_protocol": lambda r: run_protocol(EngagementProtocol(), clutch, rtol=r),
        "clutchlab.emtc.system.simulate": lambda r: emtc_system.simulate(rtol=r),
        "clutchlab.emtc.bench.simulate_bench": lambda r: simulate_bench(None, rtol=r),
        "clutchlab.eclutch.EClutch.simulate": lambda r: EClutch().simulate({"voltage": 0.0}, 0.1, rtol=r),
        "clutchlab.eclutch.ClutchDynamics.simulate":
            lambda r: ClutchDynamics(ClutchModel.preset(0)).simulate(([0.0, 1.0], [0.0, 1e-3]), rtol=r),
        "clutchlab.eclutch.scenario.simulate": lambda r: eclutch_scenario.simulate(rtol=r),
        "clutchlab.driveline.Driveline.simulate": lambda r: d.simulate(1.0, rtol=r),
    }


@pytest.mark.parametrize("bad, message", [(0.0, "must be in (0, 1)"), (1.0, "must be in (0, 1)"),
                                          (1e-16, "100 machine epsilons")])
def test_every_entry_point_refuses_a_bad_rtol_alike(bad, message):
    """The E-clutch took (1e-12, 0.1) and the others (0, 1) (#31): now one rule and one message everywhere."""
    for name, call in _refusals().items():
        with pytest.raises(ParameterError, match="rtol") as err:
            call(bad)
        assert message in str(err.value), (name, str(err.value))


def test_the_eclutch_takes_atol_and_its_error_control_follows_it():
    """``EClutch.simulate`` and ``ClutchDynamics.simulate`` had no ``atol`` (#31).  A bearing reference step under
    the position controller at a loose rtol, where the absolute part of the error control decides: the steps grow
    as ``atol`` tightens and the settled bearing position converges (measured: 1.0e-6 m apart from atol 1 to 1e-10,
    3e-9 m from 1e-6 to 1e-10; the trajectory as a whole is held by the loose rtol as well)."""
    ec = EClutch()
    ref = {"bearing_reference": ([0.0, 0.2, 0.6], [0.0, 6e-3, 6e-3])}
    runs = {a: ec.simulate(ref, 0.6, rtol=1e-2, atol=a, output_step=0.01) for a in (1.0, 1e-6, 1e-10)}
    end = {a: float(r.outputs_table["bearing_position_m"].iloc[-1]) for a, r in runs.items()}
    steps = [runs[a].stats["accepted_steps"] for a in (1.0, 1e-6, 1e-10)]
    assert steps[0] < steps[1] < steps[2], steps
    loose, tight = abs(end[1.0] - end[1e-10]), abs(end[1e-6] - end[1e-10])
    assert tight < 0.05 * loose, (loose, tight)
    dyn = ClutchDynamics(ClutchModel.preset(0))
    with pytest.raises(ParameterError, match="atol and atol_scale"):
        dyn.simulate(([0.0, 1.0], [0.0, 1e-3]), atol=1e-9, atol_scale=0.1)
    with pytest.raises(ParameterError, match="atol = "):
        EClutch().simulate({"voltage": 0.0}, 0.1, atol=-1.0)


def test_the_wet_engagement_takes_output_step_and_atol():
    clutch = WetClutch.paper()
    scen = EngagementProtocol(duration=0.3).scenario(clutch)
    res = simulate_engagement(clutch, scen, output_step=0.02, atol=1e-6)
    np.testing.assert_allclose(res.time, np.arange(16) * 0.02, atol=1e-12)
    with pytest.raises(ParameterError, match="sample_rate and output_step|output_step and sample_rate"):
        simulate_engagement(clutch, scen, output_step=0.02, sample_rate=100.0)


def test_the_emtc_bench_takes_output_step_and_max_step():
    from clutchlab.emtc.bench import BenchScenario
    from clutchlab.emtc.magnet import bundled_magnet

    sc = BenchScenario(duration=0.2)
    res = simulate_bench(bundled_magnet(), sc, output_step=0.05, max_step=1e-3)
    np.testing.assert_allclose(res.time, [0.0, 0.05, 0.1, 0.15, 0.2], atol=1e-12)
    assert res.result.stats["accepted_steps"] >= 200   # no step longer than 1 ms over 0.2 s
    assert np.all(np.isfinite(res.to_dataframe()["coupling_torque_Nm"]))


def test_every_simulate_command_takes_the_run_options(capsys):
    """``--rtol``, ``--atol``, ``--max-step``, ``--output-step``, ``--fixed-step`` on the four simulate commands,
    each refused in one line when it is not a value of its kind."""
    for command in ("eclutch", "wet", "emtc", "driveline"):
        try:
            main([command, "simulate", "--help"])
        except SystemExit:
            pass
        text = capsys.readouterr().out
        for flag in ("--rtol", "--atol", "--max-step", "--output-step", "--fixed-step"):
            assert flag in text, (command, flag)
    example = str(EXAMPLES / "driveline_test_friction.toml")
    for flags, message in ((["--rtol", "0"], "--rtol = 0"), (["--rtol", "abc"], "--rtol"),
                           (["--atol", "-1"], "--atol = -1"), (["--max-step", "1"], "--max-step"),
                           (["--output-step", "0 s"], "--output-step")):
        line = one_line_error(capsys, ["driveline", "simulate", example, "-o", "never.csv", *flags])
        assert message in line, line


def test_driveline_simulate_with_run_options_says_so(tmp_path):
    example = str(EXAMPLES / "driveline_test_friction.toml")
    out = tmp_path / "run.csv"
    assert main(["driveline", "simulate", example, "-o", str(out), "--t-end", "0.2 s", "--output-step", "10 ms",
                 "--rtol", "1e-6", "--atol", "1e-9", "--max-step", "5 ms"]) == 0
    first = out.read_text().splitlines()[0]
    assert first.startswith("#") and "rtol = 1e-06" in first and "max_step = 0.005 s" in first, first


def test_a_tighter_rtol_brings_a_systems_absolute_tolerances_down_through_the_contract():
    """Issue #30: ``simulate(system, rtol=...)`` below the system's own rtol scales its absolute tolerances by
    ``rtol / system.rtol`` (``follow_rtol``, once in ``System.options``), so the error against the closed form
    follows the tolerance.  An undamped oscillator (J = 1 kg m^2 on 100 N m/rad) from 0.01 rad/s, a system built at
    rtol 1e-4 (its atol 1e-4: the angle's amplitude is 1e-3 rad): ``w = w0 cos(10 t)``.  With the absolute
    tolerances kept at the system's (what every contract-level run did), the error stays at 8.6 % of w0 at rtol
    1e-6, 1e-8 and 1e-10 alike; following them it is 5e-4, 7e-6, 9e-8."""
    from clutchlab.driveline import Driveline
    from clutchlab.system import follow_rtol, simulate

    d = Driveline("oscillator")
    d.inertia("J", J=1.0, w0=1e-2)
    d.spring_damper("c", "J", "ground", c=100.0)
    system = d.system(rtol=1e-4)
    assert np.all(system.options(rtol=1e-9).atol == follow_rtol(system.atol, 1e-9, 1e-4))
    assert np.all(system.options(rtol=1e-3).atol == system.atol)      # (at and above its rtol: its own)
    assert np.all(system.options(rtol=1e-9, atol=1e-3).atol == 1e-3)  # (a given atol is taken as it is)

    def error(rtol, atol=None):
        r = simulate(system, 1.0, rtol=rtol, atol=atol, output_step=0.01)
        w = r.states[:, system.state_index("J.w")]
        return float(np.max(np.abs(w - 1e-2 * np.cos(10.0 * r.time)))) / 1e-2

    followed = [error(rtol) for rtol in (1e-6, 1e-8, 1e-10)]
    kept = [error(rtol, system.atol) for rtol in (1e-6, 1e-8, 1e-10)]
    assert followed[0] > 30 * followed[1] > 900 * followed[2] and followed[2] < 1e-6, followed
    assert min(kept) > 0.05, kept   # (the floor the fixed absolute tolerances set)


def _short_runs():
    """Each model's own entry point on a short run (the kernels are the ones the rest of the suite compiles)."""
    from clutchlab.emtc import BenchScenario, bundled_magnet

    clutch = WetClutch.paper()
    return {
        "clutchlab.wet.simulate_engagement":
            lambda: simulate_engagement(clutch, EngagementProtocol(duration=0.3).scenario(clutch), output_step=0.01),
        "clutchlab.emtc.bench.simulate_bench": lambda: simulate_bench(bundled_magnet(), BenchScenario(duration=0.1)),
        "clutchlab.eclutch.EClutch.simulate":
            lambda: EClutch().simulate({"bearing_reference": ([0.0, 0.05], [0.0, 4e-3])}, 0.1, output_step=0.01),
        "clutchlab.eclutch.ClutchDynamics.simulate":
            lambda: ClutchDynamics(ClutchModel.preset(0)).simulate(([0.0, 0.1], [0.0, 4e-3]), output_step=0.01),
    }


@pytest.mark.parametrize("name", sorted(_short_runs()))
def test_every_model_entry_point_returns_a_simulation_result(name):
    """#31: the public entry points return a :class:`~clutchlab.SimulationResult` (a subclass with what the model
    adds), not a view of their own: its arrays, unit-suffixed columns, named events and the one ``to_dataframe``
    contract hold for each, and it pickles whole (a sweep worker returns it)."""
    import pickle

    from clutchlab.result import SimulationResult

    res = _short_runs()[name]()
    assert isinstance(res, SimulationResult) and type(res) is not SimulationResult, type(res)
    assert res.ok and res.model and isinstance(res.states, np.ndarray) and isinstance(res.outputs, np.ndarray)
    n = res.time.size
    assert res.states.shape == (n, len(res.state_columns)) and res.outputs.shape == (n, len(res.output_columns))
    assert res.modes.shape == (n, len(res.mode_names)) and res.modes.dtype.kind == "i"
    for col in res.state_columns + res.output_columns:
        assert res[col].shape == (n,), col
    assert list(res.events.columns[:3]) == ["time_s", "event", "element"]
    assert all(isinstance(e, str) and e.isidentifier() for e in res.events["event"]), list(res.events["event"])
    assert res.stats["accepted_steps"] > 0
    frame = res.to_dataframe()
    assert "time_s" in frame.columns and len(frame) == n
    back = pickle.loads(pickle.dumps(res))
    assert type(back) is type(res)
    np.testing.assert_array_equal(back.states, res.states)
    assert back.events.equals(res.events)
    assert back.to_dataframe().equals(frame)
