"""Exported FMUs loaded with FMPy: model description, and results against the native simulations.

FMU vs in-process co-simulation: the FMU runs the very same object through
pythonfmu, so only the FMI value transfer (doubles, no conversion) lies
between them -- equal to 1e-12 relative.  FMU vs native: see the tolerances
in ``test_cosim.py`` (exact for the EMTC, solver tolerance for the wet clutch).
"""

import zipfile
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from clutchlab.errors import ParameterError
from clutchlab.fmu.emtc import EmtcCoSimulation
from clutchlab.fmu.wet import WetCoSimulation
from clutchlab.fmu.export import export_fmu, model_identifier, unit_definition

fmpy = pytest.importorskip("fmpy")


@pytest.mark.parametrize("model,cls", [("wet", WetCoSimulation), ("emtc", EmtcCoSimulation)])
def test_model_description_lists_every_variable_with_causality_and_unit(build_fmu, model, cls):
    import fmpy.validation

    path = build_fmu(model)
    assert fmpy.validation.validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(path), validate=True)
    assert md.fmiVersion == "2.0" and md.coSimulation.modelIdentifier == model_identifier(model)
    assert not md.coSimulation.canBeInstantiatedOnlyOncePerProcess and md.coSimulation.needsExecutionTool
    got = {v.name: v for v in md.modelVariables}
    flag = got.pop("step_error")  # local Boolean read by the shim library after a refused step
    assert (flag.causality, flag.variability, flag.type) == ("local", "discrete", "Boolean")
    expected = ([(v, "parameter", "fixed") for v in cls.parameters] + [(v, "input", "continuous") for v in cls.inputs]
                + [(v, "output", "continuous") for v in cls.outputs])
    assert len(got) == len(expected)
    for var, causality, variability in expected:
        mv = got[var.name]
        assert (mv.causality, mv.variability, mv.type, mv.unit) == (causality, variability, "Real", var.unit)
        if causality != "output":
            assert float(mv.start) == pytest.approx(var.start, rel=1e-15)
        if causality == "parameter":   # the declared range (a parameter set's checks) as min and max
            lo = 0.0 if var.positive and (var.minimum is None or var.minimum < 0) else var.minimum
            assert (mv.min, mv.max) == tuple(None if b is None else repr(float(b)) for b in (lo, var.maximum))
            assert (lo is None or float(mv.start) >= lo) and (var.maximum is None or float(mv.start) <= var.maximum)
    assert {u.name for u in md.unitDefinitions} == {v.unit for v, _, _ in expected}
    assert {o.variable.name for o in md.outputs} == {v.name for v in cls.outputs}


def test_parameter_set_fields_carry_their_checks_as_ranges():
    """A parameter set's checks (bounds, sign, the plausibility limit of the unit) are the FMU's min and max, and
    the co-simulation refuses a value outside them naming it."""
    from clutchlab.fmu.cosim import load_cosimulation

    cls = load_cosimulation("wet")
    v = {p.name: p for p in cls.parameters}
    assert (v["clutch.r_outer"].minimum, v["clutch.r_outer"].maximum, v["clutch.r_outer"].positive) == (0.0, 100.0, True)
    assert (v["bench.ambient_temperature"].minimum, v["bench.ambient_temperature"].maximum) == (-273.15, 1e4)
    with pytest.raises(ParameterError, match=r"'clutch\.r_outer' = -0\.1 is outside its range \(0, 100\] \[m\]"):
        cls(**{"clutch.r_outer": -0.1})


def test_unit_definitions_carry_si_base_units():
    base = unit_definition("N.m").find("BaseUnit").attrib
    assert base == {"kg": "1", "m": "2", "s": "-2"}
    assert unit_definition("degC").find("BaseUnit").attrib == {"K": "1", "offset": "273.15"}
    assert unit_definition("rad/s").find("BaseUnit").attrib == {"rad": "1", "s": "-1"}
    assert unit_definition("kg.m2").find("BaseUnit").attrib == {"kg": "1", "m": "2"}


def test_fmu_needs_installed_clutchlab_and_bundles_only_the_slave(build_fmu):
    with zipfile.ZipFile(build_fmu("wet")) as z:
        names = z.namelist()
        script = z.read("resources/clutchlabwet_slave.py").decode()
        root = ET.fromstring(z.read("modelDescription.xml"))
    assert "binaries/linux64/ClutchlabWet.so" in names
    assert not any(n.startswith("resources/clutchlab/") for n in names)
    assert "from clutchlab.fmu.export import CoSimulationSlave" in script and 'model_key = "wet"' in script
    assert "\nkeep_namespace(globals())" in script  # balances pythonfmu's release at every instantiation
    assert root.find("DefaultExperiment") is not None


def test_export_refuses_overwrite_and_bad_names(tmp_path, build_fmu):
    path = build_fmu("wet")
    with pytest.raises(FileExistsError):
        export_fmu("wet", path)
    with pytest.raises(ParameterError, match=".fmu"):
        export_fmu("wet", tmp_path / "wet.zip")
    with pytest.raises(ParameterError, match="unknown"):
        export_fmu("dry", tmp_path / "dry.fmu")
    assert not (tmp_path / "wet.zip").exists() and not (tmp_path / "dry.fmu").exists()


def _wet_inputs(n):
    k = np.arange(n + 1)
    return {"force_reference": np.where(k < 5, 0.0, np.where(k < 30, 3000.0, 1500.0)),
            "slip_speed_reference": np.where(k < 40, 157.0796326794897, 100.0)}


def test_wet_fmu_reproduces_the_cosimulation(build_fmu, run_fmu, run_cosim):
    dt, n = 0.01, 60
    inputs = _wet_inputs(n)
    names = ["clutch_torque", "slip_speed", "temperature", "mean_film", "actuator_force", "stick"]
    fmu = run_fmu(build_fmu("wet"), inputs, dt, n, names)
    ref = run_cosim(WetCoSimulation(), inputs, dt, n)
    for name in names:
        np.testing.assert_allclose(fmu[name], ref[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(ref[name])),
                                   err_msg=name)
    assert np.max(fmu["clutch_torque"]) > 100.0  # the clutch did engage


def test_wet_fmu_start_values_change_the_result_as_the_native_model(build_fmu, run_fmu):
    from clutchlab.wet import engagement as E

    dt, n = 0.01, 40
    start = {"scenario.free_inertia": 1.0, "bench.motor_inertia": 0.04}
    inputs = {"force_reference": np.full(n + 1, 3000.0), "slip_speed_reference": np.zeros(n + 1)}
    fmu = run_fmu(build_fmu("wet"), inputs, dt, n, ["clutch_torque", "slip_speed", "temperature"], start)
    default = run_fmu(build_fmu("wet"), inputs, dt, n, ["slip_speed"], {"scenario.free_inertia": 1.0})
    c = WetCoSimulation(**start)
    v = c.parameter_values
    tk = np.arange(n + 1) * dt
    sc = E.Scenario(force_time=[0.0], force_value=[3000.0], speed_time=[0.0], speed_value=[0.0], duration=tk[-1],
                    motor="free", initial_slip_speed=v["scenario.initial_slip_speed"],
                    initial_temperature_c=v["scenario.initial_temperature"],
                    fluid_temperature_c=v["scenario.fluid_temperature"],
                    housing_temperature_c=v["scenario.housing_temperature"])
    nat = E.simulate_engagement(c.clutch, sc, bench=c.bench, sample_times=tk)
    tau = nat.output("clutch_torque_Nm")
    assert np.max(np.abs(fmu["clutch_torque"] - tau)) < 2e-4 * np.max(np.abs(tau))
    assert np.max(np.abs(fmu["slip_speed"] - nat.state("slip_speed_rad_s"))) < 1e-5 * 157.08
    assert np.max(np.abs(fmu["temperature"] - nat.state("temperature_C"))) < 1e-4
    # the lighter drive locks up within the run, the default one does not
    assert fmu["slip_speed"][-1] == 0.0 and default["slip_speed"][-1] > 10.0


def test_emtc_fmu_reproduces_simulate_bench(build_fmu, run_fmu):
    from clutchlab.emtc.bench import BenchScenario, simulate_bench

    dt, n = 0.01, 80
    tk = np.arange(n + 1) * dt
    torque = np.where(tk < 0.2, 0.0, np.where(tk < 0.5, 300.0, 120.0))
    throttle = np.full(n + 1, 0.6)  # plant inputs held (a jump restarts the FMU's integration; see test_cosim)
    inputs = {"torque_request": torque, "throttle": throttle, "drum_speed_front": np.full(n + 1, 8.0),
              "drum_speed_rear": np.full(n + 1, 7.7)}
    names = ["coupling_torque", "slip_speed", "coil_current", "magnet_force", "coupling_mode", "torque_capacity"]
    fmu = run_fmu(build_fmu("emtc"), inputs, dt, n, names, {"actuator.tau1": 0.012})
    c = EmtcCoSimulation(**{"actuator.tau1": 0.012})
    tt, tv = [], []
    for k in range(n):
        tt += [tk[k], tk[k + 1] - 1e-9]
        tv += [torque[k], torque[k]]
    sc = BenchScenario(duration=tk[-1], throttle_start=0.6, throttle_end=0.6)
    nat = simulate_bench(c.magnet, sc, actuator=c.actuator, torque_reference=(tt, tv))
    idx = np.round(tk / sc.sample_time).astype(int)
    refs = {"coupling_torque": nat["coupling_torque_Nm"], "slip_speed": nat["slip_speed_rad_s"],
            "coil_current": nat["i2_A"], "magnet_force": nat["magnet_force_N"],
            "coupling_mode": nat.modes[:, 1], "torque_capacity": nat["capacity_locked_Nm"]}
    for name, ref in refs.items():
        ref = np.asarray(ref, float)[idx]
        np.testing.assert_allclose(fmu[name][1:], ref[1:], rtol=1e-12, atol=1e-12 * max(np.max(np.abs(ref)), 1.0),
                                   err_msg=name)
    assert np.max(fmu["coupling_torque"]) > 250.0
