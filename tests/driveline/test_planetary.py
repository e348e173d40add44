"""The planetary gear set (`Driveline.planetary`, `[planetary.NAME]`) and the automatic transmission built with it.

MSL ``IdealPlanetary``: ``(1 + ratio) phi_carrier = phi_sun + ratio phi_ring``, ``ring.tau = ratio sun.tau``,
``carrier.tau = -(1 + ratio) sun.tau``.  Checked against closed forms written here from those equations: three
inertias under constant torques accelerate uniformly (the Lagrangian in the carrier's and the ring's speeds), a
lossy set with its carrier held is a lossy reverse gear (``J_r a_r = -ratio eta (T - J_s a_s)``); the automatic
transmission's gears follow Willis's equation (1st: the sun held, 2nd: the set locked); the file's refusals.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from clutchlab.driveline import Driveline
from clutchlab.driveline.description import load_driveline
from clutchlab.driveline.shift import shift_quality
from clutchlab.errors import ParameterError

ROOT = Path(__file__).resolve().parents[2]
JS, JC, JR, R = 0.02, 0.3, 0.5, 2.4


def three(ts=0.0, tc=0.0, tr=0.0, **kw):
    d = Driveline("set").inertia("S", JS).inertia("C", JC).inertia("R", JR)
    d.planetary("p", "S", "C", "R", R, **kw)
    for name, flange, tq in (("Ts", "S", ts), ("Tc", "C", tc), ("Tr", "R", tr)):
        if tq:
            d.torque(name, flange, tq)
    return d


@pytest.mark.parametrize("ts, tc, tr", [(10.0, 0.0, 0.0), (0.0, 5.0, -3.0), (4.0, -20.0, 7.0)])
def test_an_ideal_set_under_constant_torques_follows_its_lagrangian(ts, tc, tr):
    """Coordinates (w_c, w_r), w_s = (1 + R) w_c - R w_r: M a = Q with M = [[J_c + J_s (1 + R)^2, -J_s R (1 + R)],
    [-J_s R (1 + R), J_r + J_s R^2]] and Q = [T_c + (1 + R) T_s, T_r - R T_s]; the torque the sun's shaft puts into
    the set is its source's less what accelerates it, and the ring's and the carrier's are R and -(1 + R) times it."""
    m = np.array([[JC + JS * (1 + R) ** 2, -JS * R * (1 + R)], [-JS * R * (1 + R), JR + JS * R ** 2]])
    ac, ar = np.linalg.solve(m, [tc + (1 + R) * ts, tr - R * ts])
    a_s = (1 + R) * ac - R * ar
    df = three(ts, tc, tr).simulate(1.0, output_step=0.25, rtol=1e-10).to_dataframe()
    t = df["time_s"].to_numpy()
    for col, a in (("S", a_s), ("C", ac), ("R", ar)):
        assert np.allclose(df[f"{col}.w_rad_s"], a * t, rtol=1e-10, atol=1e-12), col
        assert np.allclose(df[f"{col}.phi_rad"], 0.5 * a * t ** 2, rtol=1e-10, atol=1e-12), col
    sun_tau = ts - JS * a_s                  # MSL sun.tau: the torque the sun's shaft puts into the set
    assert np.allclose(-df["p.tau_Nm"], sun_tau, rtol=1e-10, atol=1e-12)
    # the set acts on each inertia with minus its flange's torque: ring.tau = R sun.tau, carrier.tau = -(1 + R) sun.tau
    assert JR * ar == pytest.approx(tr - R * sun_tau, rel=1e-10, abs=1e-12)
    assert JC * ac == pytest.approx(tc + (1 + R) * sun_tau, rel=1e-10, abs=1e-12)
    assert abs(df["energy_error_J"]).max() < 1e-9 * max(1.0, df["input_work_J"].abs().max())


def test_a_lossy_set_with_its_carrier_held_is_a_lossy_reverse_gear():
    """Carrier on the ground, the sun driven by T: rolling with the sun driving, ``J_r a_r = -R eta T_a`` with
    ``T_a = T - J_s a_s`` and ``a_s = -R a_r`` (LossyGear's quadrant 1 in the carrier's frame)."""
    eta, T = 0.9, 6.0
    d = (Driveline("held").inertia("S", JS).inertia("R", JR).torque("T", "S", T)
         .planetary("p", "S", "ground", "R", R, efficiency=eta))
    df = d.simulate(0.5, output_step=0.1, rtol=1e-10).to_dataframe()
    ar = -R * eta * T / (JR + eta * JS * R ** 2)
    t = df["time_s"].to_numpy()
    assert np.allclose(df["R.w_rad_s"], ar * t, rtol=1e-9, atol=1e-12)
    assert np.allclose(df["S.w_rad_s"], -R * ar * t, rtol=1e-9, atol=1e-12)
    lost = (1 - eta) * (T + JS * R * ar) * (-R * ar) * t ** 2 / 2    # (1 - eta) T_a w_a, integrated
    assert np.allclose(df["p.dissipated_J"], lost, rtol=1e-8, atol=1e-12)
    info = {e.name: e for e in d.elements}["p"]
    assert (info.kind, info.flange_a, info.flange_b, info.support) == ("planetary", "S", "R", "ground")
    assert "planetary, ring/sun teeth 2.4, sun S, ring R, carrier ground" in d.describe()


def test_the_automatic_transmission_s_gears_follow_willis():
    """The example: in 1st (b1 holding the sun) the carrier turns at ratio/(1 + ratio) of the ring, 12:1 overall from
    the turbine to the wheels; after the upshift (c2 locking sun and ring) the set turns as one, 8:1."""
    spec = load_driveline(ROOT / "examples" / "driveline_at_upshift.toml")
    res = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, output_step=spec.output_step)
    df = res.to_dataframe()
    first = df[df["time_s"] < 1.0]
    second = df[df["time_s"] > 1.3]
    assert np.allclose(first["sun.w_rad_s"], 0.0, atol=1e-9)
    assert np.allclose(first["carrier.w_rad_s"], 2.0 / 3.0 * first["ring.w_rad_s"], rtol=1e-9)
    assert np.allclose(first["turbine.w_rad_s"], 12.0 * first["axle.w_rad_s"], rtol=1e-9)
    for member in ("sun", "carrier"):
        assert np.allclose(second[f"{member}.w_rad_s"], second["ring.w_rad_s"], rtol=1e-7), member
    assert np.allclose(second["turbine.w_rad_s"], 8.0 * second["axle.w_rad_s"], rtol=1e-7)
    events = list(zip(res.events.element, res.events.event))
    assert events == [("c2", "forward"), ("b1", "forward"), ("b1", "free"), ("c2", "stick")]
    q = shift_quality(res, **spec.shift)
    assert q.order == "upshift" and q.metrics["tie_up_Nm"] < 20.0
    # in 1st the brake holds what the set puts on the sun (the sun at rest, its inertia carries nothing)
    mid = first[first["time_s"] > 0.5]
    assert np.allclose(np.abs(mid["b1.tau_Nm"]), np.abs(mid["set.tau_Nm"]), rtol=1e-6)
    assert mid["b1.tau_Nm"].abs().min() > 50.0


@pytest.mark.parametrize("kw, message", [
    ({"ratio": 1.0}, "ring has more teeth than its sun"),
    ({"ratio": -2.0}, "must be > 0"),
    ({"ratio": 2.0, "efficiency": 1.2}, "efficiency"),
])
def test_bad_sets_are_refused(kw, message):
    with pytest.raises(ParameterError, match=message):
        Driveline("x").inertia("S", 1.0).inertia("C", 1.0).inertia("R", 1.0).planetary("p", "S", "C", "R", **kw)
    with pytest.raises(ParameterError, match="rotational"):
        Driveline("t", domain="translational").mass("a", 1.0).mass("b", 1.0).planetary("p", "a", "ground", "b", 2.0)


def test_the_file_table(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text('[driveline]\nname = "p"\n[inertia.S]\nJ = 0.02\n[inertia.C]\nJ = 0.3\n[inertia.R]\nJ = 0.5\n'
                 '[torque.T]\nflange = "S"\ntorque = "10 N m"\n'
                 '[planetary.p]\nsun = "S"\ncarrier = "C"\nring = "R"\nratio = 2.4\n')
    a = load_driveline(f).driveline.simulate(0.5, output_step=0.1).to_dataframe()
    b = three(10.0).simulate(0.5, output_step=0.1).to_dataframe()
    assert np.array_equal(a["R.w_rad_s"].to_numpy(), b["R.w_rad_s"].to_numpy())
    f.write_text(f.read_text().replace("ratio = 2.4", "ratio = 0.5"))
    with pytest.raises(ParameterError, match=r"p\.toml.*ratio"):
        load_driveline(f)
    assert math.isfinite(a["C.w_rad_s"].iloc[-1])
