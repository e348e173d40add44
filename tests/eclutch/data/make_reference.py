"""Reference traces of the E-clutch dynamics from the pre-port kernel (commit 45cc909)."""
import numpy as np
from clutchlab.eclutch import ClutchModel, EClutch, FrictionParameters, ClutchDynamics

out = {}
# 1. position control, pedal release 7 mm and re-engage, friction everywhere (the benchmark scenario)
ec = EClutch(clutch=ClutchModel.preset(4), friction=FrictionParameters())
inp = {"bearing_reference": ([0.0, 0.1, 0.3, 0.6, 0.8], [0.0, 0.0, 7e-3, 7e-3, 0.0])}
r = ec.simulate(inp, 1.0, rtol=1e-8, atol_scale=1e-2, output_step=2.5e-3)
o = r.outputs
cols1 = ["bearing_position_m", "pressure_Pa", "master_position_m", "motor_current_A", "torque_Nm", "bearing_force_clutch_N"]
out["position_time_s"] = o.time_s.to_numpy()
for c in cols1:
    out[f"position__{c}"] = o[c].to_numpy()
print("position", r.stats, len(r.events))
# 2. voltage steps into cavitation and back (no clutch friction; seal friction on)
ec2 = EClutch()
r2 = ec2.simulate({"voltage": (np.linspace(0.0, 0.3, 4), [0.0, -12.0, 6.0, 0.0])}, 0.35, rtol=1e-8, atol_scale=1e-2,
                  output_step=1e-3)
o2 = r2.outputs
cols2 = ["bearing_position_m", "pressure_Pa", "master_pressure_Pa", "motor_current_A", "line_flow_m3_s"]
out["voltage_time_s"] = o2.time_s.to_numpy()
for c in cols2:
    out[f"voltage__{c}"] = o2[c].to_numpy()
out["voltage__input_work_J"] = r2.energy["input_work_J"].to_numpy()
print("voltage", r2.stats, len(r2.events))
# 3. clutch alone, prescribed smooth release/engage cycle with friction (hysteresis loop)
t = np.linspace(0.0, 2.0, 801)
s = np.where(t <= 1.0, t, 2.0 - t)
x = 7.5e-3 * (3 * s ** 2 - 2 * s ** 3)
r3 = ClutchDynamics(ClutchModel.preset(4), FrictionParameters()).simulate((t, x), rtol=1e-8, atol_scale=1e-2,
                                                                          output_step=5e-3)
o3 = r3.outputs
cols3 = ["bearing_force_clutch_N", "normal_force_N", "x_pp_m", "x_edge_m", "friction_edge_N"]
out["prescribed_time_s"] = o3.time_s.to_numpy()
for c in cols3:
    out[f"prescribed__{c}"] = o3[c].to_numpy()
out["prescribed__friction_dissipated_J"] = r3.energy["friction_dissipated_J"].to_numpy()
ev = r3.events
out["prescribed_events"] = np.array([(ev.event == "stick").sum(), (ev.event == "breakaway").sum()])
print("prescribed", r3.stats, len(r3.events), ev.event.value_counts().to_dict())
np.savez_compressed("/work/wt/eclutch/tests/eclutch/data/dynamics_reference.npz", **out)
