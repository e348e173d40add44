"""The co-simulation FMUs in the core's fixed-step (real-time) mode: parameter ``solver.fixed_step``."""

import numpy as np
import pytest

from clutchlab.errors import ParameterError
from clutchlab.fmu.cosim import EmtcCoSimulation, WetCoSimulation

fmpy = pytest.importorskip("fmpy")


def _wet_inputs(n):
    k = np.arange(n + 1)
    return {"force_reference": np.where(k < 5, 0.0, np.where(k < 30, 3000.0, 1500.0)),
            "slip_speed_reference": np.where(k < 40, 157.0796326794897, 100.0)}


def test_wet_fmu_runs_fixed_step(build_fmu, run_fmu, run_cosim):
    """A 1 ms frame inside 10 ms communication steps: the FMU reproduces the in-process co-simulation
    in fixed-step mode, which takes exactly ten steps per communication step and follows the adaptive run."""
    dt, n = 0.01, 60
    inputs = _wet_inputs(n)
    names = ["clutch_torque", "slip_speed", "temperature", "actuator_force"]
    start = {"solver.fixed_step": 1e-3}
    fmu = run_fmu(build_fmu("wet"), inputs, dt, n, names, start)
    cosim = WetCoSimulation(**start)
    fixed = run_cosim(cosim, inputs, dt, n)
    assert cosim.n_steps == 10 * n
    adaptive = run_cosim(WetCoSimulation(), inputs, dt, n)
    for name in names:
        np.testing.assert_allclose(fmu[name], fixed[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(fixed[name])),
                                   err_msg=name)
    assert np.max(np.abs(fixed["slip_speed"] - adaptive["slip_speed"])) < 0.01 * 157.08
    assert np.max(fixed["clutch_torque"]) > 100.0


def test_emtc_cosimulation_runs_fixed_step(run_cosim):
    dt, n = 0.01, 30
    inputs = {"torque_request": np.full(n + 1, 300.0), "throttle": np.full(n + 1, 0.6),
              "drum_speed_front": np.full(n + 1, 8.0), "drum_speed_rear": np.full(n + 1, 7.7)}
    fixed_c = EmtcCoSimulation(**{"solver.fixed_step": 1e-3})
    fixed = run_cosim(fixed_c, inputs, dt, n)
    adaptive = run_cosim(EmtcCoSimulation(), inputs, dt, n)
    assert fixed_c.n_steps == 10 * n
    assert np.all(np.isfinite(fixed["coupling_torque"]))
    scale = np.max(np.abs(adaptive["coupling_torque"]))
    assert scale > 50.0
    assert np.max(np.abs(fixed["coupling_torque"] - adaptive["coupling_torque"])) < 0.1 * scale


@pytest.mark.parametrize("bad", [-1e-3, float("inf")])
def test_bad_fixed_step_parameter_is_refused(bad):
    with pytest.raises(ParameterError, match="solver.fixed_step"):
        WetCoSimulation(**{"solver.fixed_step": bad})


def test_eclutch_cosimulation_runs_fixed_step(run_cosim):
    """The E-clutch (stiff, Rodas3 anyway) in 1 ms frames inside 5 ms communication steps follows its adaptive run."""
    from clutchlab.eclutch.cosim import EClutchCoSimulation

    dt, n = 5e-3, 60
    k = np.arange(n + 1)
    inputs = {"bearing_reference": np.where(k < 10, 0.0, 5e-3), "motor_voltage": np.zeros(n + 1)}
    fixed_c = EClutchCoSimulation(**{"solver.fixed_step": 1e-3})
    fixed = run_cosim(fixed_c, inputs, dt, n)
    adaptive = run_cosim(EClutchCoSimulation(), inputs, dt, n)
    assert fixed_c.simulation.stats["accepted_steps"] == 5 * n
    assert np.all(np.isfinite(fixed["bearing_position"]))
    assert np.max(fixed["bearing_position"]) > 3e-3
    assert np.max(np.abs(fixed["bearing_position"] - adaptive["bearing_position"])) < 2e-5
