"""Reference traces of the E-clutch dynamics from the pre-port kernel: run at commit 45cc909.

The input tables carry a knot at every output time (collinear knots: the same input function) so that the
kernel ends a step exactly at each recorded time: the traces hold the integrator's states, not an
interpolation between steps.
"""
import numpy as np
from clutchlab.eclutch import ActuatorParameters, ClutchModel, ClutchDynamics, EClutch, FrictionParameters

RTOL = 1e-10  # tight (with atol_scale 1e-2): the traces stand for the solution, not one tolerance's path
# without friction the solution is smooth between its few events and is converged further (rtol 2e-12,
# atol_scale 1e-4: within 1e-7 of peak of the same kernel at rtol 1e-10, atol_scale 1e-2 is 2e-4 off)


def knotted(times, values, grid, hold=False):
    """The same input with a knot at every grid time (linear, or held for a voltage)."""
    t = np.union1d(times, grid)
    if hold:
        idx = np.searchsorted(times, t, side="right") - 1
        return t, np.asarray(values, float)[np.clip(idx, 0, len(values) - 1)]
    return t, np.interp(t, times, values)


# ---- the scenarios (tests/eclutch/test_regression.py runs the same ones, read from here)
#: bearing reference of the benchmark: 0 -> 7 mm -> 0 [s], [m]
BENCH = ([0.0, 0.1, 0.3, 0.6, 0.8], [0.0, 0.0, 7e-3, 7e-3, 0.0])


def bench_input():
    """Position control input with a knot at every 2.5 ms output time."""
    return {"bearing_reference": knotted(*BENCH, np.arange(401) * 2.5e-3)}


def frictionless_actuator():
    """The actuator without seal or spindle friction (scenario 1)."""
    return ActuatorParameters(master_seal_friction=0.0, slave_seal_friction=0.0, seal_pressure_friction=0.0,
                              spindle_efficiency=1.0)


def voltage_input():
    """Voltage steps into cavitation and back, held, with a knot at every 1 ms output time (scenario 3)."""
    return {"voltage": knotted(np.linspace(0.0, 0.3, 4), [0.0, -12.0, 6.0, 0.0], np.arange(351) * 1e-3, hold=True)}


def prescribed_cycle():
    """Smooth release/engage cycle of the bearing, knots every 2.5 ms (scenario 4): ``(t, x)``."""
    t = np.linspace(0.0, 2.0, 801)
    s = np.where(t <= 1.0, t, 2.0 - t)
    return t, 7.5e-3 * (3 * s ** 2 - 2 * s ** 3)


def main():
    out = {}
    # 1. no friction anywhere: position control, bearing reference 0 -> 7 mm -> 0 (the benchmark input)
    r = EClutch(frictionless_actuator(), ClutchModel.preset(4), FrictionParameters.off()).simulate(
        bench_input(), 1.0, rtol=2e-12, atol_scale=1e-4, output_step=2.5e-3, max_steps=2_000_000)
    out["smooth_time_s"] = r.outputs_table.time_s.to_numpy()
    for c in ["bearing_position_m", "pressure_Pa", "master_pressure_Pa", "master_position_m", "motor_current_A",
              "torque_Nm", "bearing_force_clutch_N"]:
        out[f"smooth__{c}"] = r.outputs_table[c].to_numpy()
    print("smooth", r.stats, len(r.events))
    # 2. the same with friction everywhere (seals, spindle, R_f.ds, R_f.pp): the benchmark scenario
    r = EClutch(clutch=ClutchModel.preset(4), friction=FrictionParameters()).simulate(
        bench_input(), 1.0, rtol=RTOL, atol_scale=1e-2, output_step=2.5e-3, max_steps=2_000_000)
    out["position_time_s"] = r.outputs_table.time_s.to_numpy()
    for c in ["bearing_position_m", "pressure_Pa", "master_position_m", "motor_current_A", "torque_Nm",
              "bearing_force_clutch_N"]:
        out[f"position__{c}"] = r.outputs_table[c].to_numpy()
    print("position", r.stats, len(r.events))
    # 3. voltage steps into cavitation and back (no clutch friction; seal friction on)
    r = EClutch().simulate(voltage_input(), 0.35, rtol=RTOL, atol_scale=1e-2, output_step=1e-3,
                           max_steps=2_000_000)
    out["voltage_time_s"] = r.outputs_table.time_s.to_numpy()
    for c in ["bearing_position_m", "pressure_Pa", "master_pressure_Pa", "motor_current_A", "line_flow_m3_s"]:
        out[f"voltage__{c}"] = r.outputs_table[c].to_numpy()
    out["voltage__input_work_J"] = r.energy["input_work_J"].to_numpy()
    print("voltage", r.stats, len(r.events))
    # 4. clutch alone, prescribed smooth release/engage cycle with friction (hysteresis loop)
    r = ClutchDynamics(ClutchModel.preset(4), FrictionParameters()).simulate(
        prescribed_cycle(), rtol=1e-9, atol_scale=1e-2, output_step=5e-3, max_steps=5_000_000)
    out["prescribed_time_s"] = r.outputs_table.time_s.to_numpy()
    for c in ["bearing_force_clutch_N", "normal_force_N", "x_pp_m", "x_edge_m"]:
        out[f"prescribed__{c}"] = r.outputs_table[c].to_numpy()
    out["prescribed__friction_dissipated_J"] = r.energy["friction_dissipated_J"].to_numpy()
    print("prescribed", r.stats, len(r.events))
    np.savez_compressed("dynamics_reference.npz", **out)


if __name__ == "__main__":
    main()
