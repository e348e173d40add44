"""Speed-dependent torque sources (`Driveline.speed_torque`, `[speed_torque.NAME]`; MSL
``Sources.LinearSpeedDependentTorque``, ``QuadraticSpeedDependentTorque``) against their closed forms on one inertia.

Linear, signed by the speed: ``J dw/dt = tau_n w / w_n``, so ``w = w0 exp(tau_n t / (J w_n))``.  Quadratic, signed
(a drag): ``J dw/dt = -c w |w|`` with ``c = -tau_n / w_n^2``, so ``w = w0 / (1 + c |w0| t / J)``.  Quadratic in one
direction both ways round (MSL's ``TorqueDirection``, a negative ``tau_n``): turning backward it is driven backward
faster, ``J dw/dt = -c w^2``, ``w = w0 / (1 + c w0 t / J)`` with ``w0 < 0``.  The source's work is the kinetic energy
it took (the energy balance), MSL's SimpleGearShift in the MSL suite uses the quadratic one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from clutchlab.driveline import Driveline
from clutchlab.driveline.description import load_driveline
from clutchlab.errors import ParameterError

J, W0 = 2.0, 30.0


def _run(w0, **kw):
    d = Driveline("s").inertia("J", J, w0=w0).speed_torque("T", "J", **kw)
    return d, d.simulate(1.0, output_step=0.1, rtol=1e-11).to_dataframe()


def test_linear_signed_grows_or_decays_exponentially():
    for tau_n in (-5.0, 3.0):
        _, df = _run(W0, tau_nominal=tau_n, w_nominal=10.0, law="linear", torque_direction=False)
        t = df["time_s"].to_numpy()
        assert np.allclose(df["J.w_rad_s"], W0 * np.exp(tau_n * t / (J * 10.0)), rtol=1e-9)


@pytest.mark.parametrize("w0", [W0, -W0])
def test_quadratic_signed_is_a_drag_both_ways_round(w0):
    c = 20.0 / 10.0 ** 2
    _, df = _run(w0, tau_nominal=-20.0, w_nominal=10.0, law="quadratic", torque_direction=False)
    t = df["time_s"].to_numpy()
    assert np.allclose(df["J.w_rad_s"], w0 / (1.0 + c * abs(w0) * t / J), rtol=1e-9)
    work = df["T.work_J"].iloc[-1]
    assert work == pytest.approx(0.5 * J * (df["J.w_rad_s"].iloc[-1] ** 2 - w0 ** 2), rel=1e-8)
    assert abs(df["energy_error_J"]).max() < 1e-8 * abs(work)


def test_quadratic_in_one_direction_drives_a_backward_flange_on():
    """MSL's default (TorqueDirection = true): tau = tau_n (w/w_n)^2 whatever the sign of w, so a load in positive
    rotation pushes a flange turning backward further back (it reaches -inf at t = J / (c |w0|): run short of it)."""
    c = 20.0 / 10.0 ** 2
    d = Driveline("s").inertia("J", J, w0=-5.0).speed_torque("T", "J", -20.0, 10.0)
    df = d.simulate(0.5, output_step=0.1, rtol=1e-11).to_dataframe()
    t = df["time_s"].to_numpy()
    assert np.allclose(df["J.w_rad_s"], -5.0 / (1.0 - c * 5.0 * t / J), rtol=1e-9)
    assert "quadratic speed-dependent torque -20 N m at 10 rad/s, both ways round" in d.describe()


def test_the_file_table_and_its_refusals(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text('[driveline]\nname = "s"\n[inertia.J]\nJ = 2\nw0 = "300 rpm"\n'
                 '[speed_torque.fan]\nflange = "J"\ntau_nominal = "-20 N m"\nw_nominal = "100 rpm"\n')
    d = load_driveline(f).driveline
    df = d.simulate(0.5, output_step=0.1, rtol=1e-11).to_dataframe()
    c = 20.0 / (100 * math.pi / 30) ** 2
    w0 = 300 * math.pi / 30
    assert np.allclose(df["J.w_rad_s"], w0 / (1.0 + c * w0 * df["time_s"] / J), rtol=1e-9)
    f.write_text(f.read_text().replace('w_nominal = "100 rpm"', 'w_nominal = "0 rpm"'))
    with pytest.raises(ParameterError, match=r"s\.toml.*w_nominal"):
        load_driveline(f)
    with pytest.raises(ParameterError, match="law = 'cubic'"):
        Driveline("x").inertia("J", 1.0).speed_torque("T", "J", 1.0, 1.0, law="cubic")
