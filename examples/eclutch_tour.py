"""The one-screen tour of the README, E-clutch part (runs on the bundled synthetic data)."""

import numpy as np

import clutchlab
from clutchlab.eclutch import ClutchModel, characterize
from clutchlab.eclutch.datasets import load_full_clutch_record, load_press_record
from clutchlab.eclutch.validation import compare

# a measured characteristic: validated samples, interpolation, inverse, series/parallel
c = clutchlab.Curve([0, 1e-3, 2e-3], [0, 800, 2400], kind="pchip")
both = clutchlab.curves.series(c, clutchlab.Curve.linear(4e6))  # deflections add at equal force
print(f"series at 1 kN: {both.inverse(1000.0) * 1e3:.4f} mm = {c.inverse(1000.0) * 1e3:.4f} + {1000 / 4e6 * 1e3:.4f} mm")

# press-rig record -> characteristic (branches and cycles averaged, hysteresis removed)
cushion = characterize(load_press_record("d"))
print(f"cushion spring: {cushion.n_cycles} cycles, hysteresis half-width {cushion.hysteresis_half_width.mean():.1f} N")

# the paper's Models 0-4: static curves by Newton continuation (friction off)
model = ClutchModel.preset(2)
curves = model.static_curve(np.linspace(0, 9e-3, 200))  # bearing force, normal force, torque
print(f"Model 2: peak bearing force {curves.bearing_force_N.max():.0f} N, engaged torque {curves.torque_Nm.iloc[0]:.0f} N*m")
print(compare(model, load_full_clutch_record()))  # RMSE against the full-clutch record
