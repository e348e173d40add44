"""Scenarios from TOML, the simulate CLI, batches in parallel, the co-simulation slave and the sweep target."""

import numpy as np
import pandas as pd
import pytest

from clutchlab.cli import main
from clutchlab.eclutch import ClutchModel, EClutch, EClutchParameters, FrictionParameters, load_scenario, run_scenario
from clutchlab.eclutch.dynamics import simulate_batch
from clutchlab.errors import ParameterError

SCENARIO = """
[scenario]
model = 4
t_end = "0.6 s"
output_step = "2 ms"

[input]
kind = "pedal"
time_s = [0.0, 0.05, 0.2, 0.35, 0.5]
value = [0, 0, 1, 1, 0]
release_travel = "7 mm"

[eclutch_friction]
pressure_plate_force = "15 N"
"""


@pytest.fixture
def scenario_file(tmp_path):
    p = tmp_path / "launch.toml"
    p.write_text(SCENARIO)
    return p


def test_scenario_units_are_converted(scenario_file):
    sc = load_scenario(scenario_file)
    assert sc.t_end == pytest.approx(0.6)
    assert sc.output_step == pytest.approx(2e-3)
    assert sc.release_travel == pytest.approx(7e-3)
    assert sc.friction.pressure_plate_force == pytest.approx(15.0)
    t, ref = sc.input_table()
    assert ref.max() == pytest.approx(7e-3)
    res = run_scenario(sc)
    o = res.outputs_table
    assert len(o) == 301
    assert float(np.interp(0.33, o.time_s, o.bearing_position_m)) == pytest.approx(7e-3, abs=0.4e-3)


@pytest.mark.parametrize("patch, message", [
    (("t_end = \"0.6 s\"", "t_end = \"0.6 kg\""), "t_end"),
    (("kind = \"pedal\"", "kind = \"torque\""), "kind"),
    (("model = 4", "model = 7"), "model"),
    (("value = [0, 0, 1, 1, 0]", "value = [0, 0, 1, 1]"), "time_s has 5 values"),
    (("time_s = [0.0, 0.05, 0.2, 0.35, 0.5]", "time_s = [0.0, 0.05, 0.02, 0.35, 0.5]"), "increase strictly"),
    (("pressure_plate_force = \"15 N\"", "pressure_plate_force = \"-15 N\""), "pressure_plate_force"),
    (("[eclutch_friction]", "[eclutch_fiction]"), "unknown table"),
])
def test_scenario_errors_name_file_key_and_value(tmp_path, patch, message):
    p = tmp_path / "bad.toml"
    p.write_text(SCENARIO.replace(*patch))
    with pytest.raises(ParameterError, match=message) as exc:
        load_scenario(p)
    assert "bad.toml" in str(exc.value)


def test_simulate_cli_writes_results_and_plot(scenario_file, tmp_path, capsys):
    out = tmp_path / "run.csv"
    png = tmp_path / "run.png"
    assert main(["eclutch", "simulate", str(scenario_file), "-o", str(out), "--plot", str(png)]) == 0
    frame = pd.read_csv(out, comment="#")
    assert {"time_s", "bearing_position_m", "bearing_force_N", "pressure_Pa", "motor_current_A",
            "torque_Nm"} <= set(frame.columns)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # never overwrites without --force; a bad file is one line and exit code 2
    assert main(["eclutch", "simulate", str(scenario_file), "-o", str(out)]) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text(SCENARIO.replace("model = 4", "model = 9"))
    assert main(["eclutch", "simulate", str(bad), "-o", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("clutchlab: error:") and "model" in err


def test_simulate_cli_parquet_with_units(scenario_file, tmp_path):
    import pyarrow.parquet as pq

    out = tmp_path / "run.parquet"
    assert main(["eclutch", "simulate", str(scenario_file), "-o", str(out)]) == 0
    table = pq.read_table(out)
    assert "pressure_Pa" in table.column_names
    meta = table.schema.field("pressure_Pa").metadata or {}
    assert b"Pa" in b"".join(meta.values())


def test_batch_equals_single_runs():
    ecs = [EClutch(clutch=ClutchModel.preset(4, EClutchParameters(lever_ratio=r)), friction=FrictionParameters())
           for r in (-4.2, -3.9, -3.6)]
    inp = {"bearing_reference": ([0.0, 0.05, 0.2, 0.4, 0.5], [0.0, 0.0, 7e-3, 7e-3, 0.0])}
    batch = simulate_batch(ecs, inp, 0.6, output_step=2e-3)
    assert (batch.stats.status == 0).all()
    for k, ec in enumerate(ecs):
        single = ec.simulate(inp, 0.6, output_step=2e-3).outputs_table
        np.testing.assert_array_equal(batch.outputs["bearing_force_N"][k], single.bearing_force_N.to_numpy())
        np.testing.assert_allclose(batch.outputs["torque_Nm"][k], single.torque_Nm.to_numpy(), rtol=1e-14)
    # a larger lever ratio magnitude needs less bearing force for the same clamp load
    peaks = batch.outputs["bearing_force_N"].max(axis=1)
    assert peaks[0] < peaks[1] < peaks[2]


def test_batch_of_variants_built_while_earlier_ones_run_equals_the_list():
    """A generator of variants is built chunk by chunk while the chunks before it run: the same outputs
    and counters as the list; a variant of another structure is refused by its number."""
    ratios = (-4.2, -3.9, -3.6, -4.0, -3.7)
    make = lambda: (EClutch(clutch=ClutchModel.preset(4, EClutchParameters(lever_ratio=r)),  # noqa: E731
                            friction=FrictionParameters()) for r in ratios)
    inp = {"bearing_reference": ([0.0, 0.05, 0.2, 0.4, 0.5], [0.0, 0.0, 7e-3, 7e-3, 0.0])}
    listed = simulate_batch(list(make()), inp, 0.6, output_step=2e-3)
    drawn = simulate_batch(make(), inp, 0.6, output_step=2e-3, chunk=2)
    for key, value in listed.outputs.items():
        np.testing.assert_array_equal(drawn.outputs[key], value, err_msg=key)
    assert drawn.stats.equals(listed.stats) and len(drawn.stats) == len(ratios)
    mixed = iter([EClutch(clutch=ClutchModel.preset(4)), EClutch(clutch=ClutchModel.preset(1))])
    with pytest.raises(ParameterError, match="variant 1 has another model structure"):
        simulate_batch(mixed, {"voltage": 0.0}, 0.1, chunk=1)

def test_batch_rejects_different_structures():
    with pytest.raises(ParameterError, match="structure"):
        simulate_batch([EClutch(clutch=ClutchModel.preset(4)), EClutch(clutch=ClutchModel.preset(1))],
                       {"voltage": 0.0}, 0.1)


def test_cosimulation_continues_the_native_solution():
    from clutchlab.fmu.eclutch import EClutchCoSimulation

    def gap(rtol):
        c = EClutchCoSimulation(rtol=rtol)
        steps = [c.do_step(k * 2e-3, 2e-3, {"bearing_reference": 5e-3}) for k in range(150)]
        native = EClutch(friction=FrictionParameters()).simulate({"bearing_reference": 5e-3}, 0.3, output_step=2e-3,
                                                                 rtol=rtol)
        x = np.array([s["bearing_position"] for s in steps])
        return np.abs(x - native.outputs_table.bearing_position_m.to_numpy()[1:]).max(), steps, native

    # restarting at each communication point changes the steps, not the solution beyond the tolerance:
    # the gap shrinks with the tolerance (a model mismatch would not)
    loose, _, _ = gap(1e-3)
    tight, steps, native = gap(1e-6)
    assert tight < 1e-6 and tight < loose / 3, (loose, tight)
    assert steps[-1]["bearing_force"] == pytest.approx(native.outputs_table.bearing_force_N.iloc[-1], rel=1e-3)
    with pytest.raises(ParameterError, match="control_mode"):
        EClutchCoSimulation(control_mode=3.0)


def test_sweep_target_outputs():
    from clutchlab.sweep.eclutch import run_batch

    variants = pd.DataFrame({"clutch.lever_ratio": [-4.2, -3.8], "friction.pressure_plate_force": [0.0, 40.0]},
                            index=pd.Index([0, 1], name="variant_id"))
    out = run_batch(variants, None, ["peak_bearing_force", "release_time", "friction_dissipated", "input_work"])
    assert list(out.index) == [0, 1]
    assert np.all(np.isfinite(out.to_numpy()))
    assert out.loc[0, "peak_bearing_force"] < out.loc[1, "peak_bearing_force"]
    assert out.loc[1, "friction_dissipated"] > out.loc[0, "friction_dissipated"]
    with pytest.raises(ParameterError, match="unknown output"):
        run_batch(variants, None, ["lap_time"])
    with pytest.raises(ParameterError, match="variant 1"):
        run_batch(variants.assign(**{"actuator.slave_mass": [0.2, -1.0]}), None, ["input_work"])


@pytest.mark.parametrize("name", ["eclutch_launch.toml", "eclutch_hysteresis.toml"])
def test_example_scenarios_run(name):
    import pathlib

    sc = load_scenario(pathlib.Path(__file__).parents[2] / "examples" / name)
    res = run_scenario(sc)
    o = res.outputs_table
    assert o.time_s.iloc[-1] == pytest.approx(sc.t_end)
    assert o.bearing_position_m.max() > 6e-3  # both release the clutch
    assert o.torque_Nm.iloc[-1] > 0.9 * o.torque_Nm.iloc[0]  # and engage it again
