"""An E-clutch in a driveline whose working point facing wear and thermal expansion move (seed 000, Sec. 7, future
work iii; :meth:`clutchlab.driveline.Driveline.eclutch`, :func:`clutchlab.driveline.kernel.shifted_curve`).

Each run is compared with the axial model's own static curve, re-solved for the wear or temperature the run reached
(:func:`clutchlab.eclutch.dynamics.apply_wear_and_expansion`), and with a SciPy solution of the wear law written
out again from those curves: never with the network's table itself.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from clutchlab.driveline import Driveline
from clutchlab.driveline.description import load_driveline
from clutchlab.driveline.network import SHIFT_TOLERANCE
from clutchlab.eclutch import ClutchModel
from clutchlab.eclutch.dynamics import apply_wear_and_expansion
from clutchlab.errors import ParameterError, SimulationError

MODEL = ClutchModel.preset(4)
PEAK = float(MODEL.static_curve([0.0])["normal_force_N"].iloc[0])   # the engaged clamp force [N]


def _force(u, wear=0.0, rise=0.0, expansion=0.0):
    """The axial model's clamp force [N] at bearing position ``u`` [m], worn ``wear`` [m], its stack ``rise`` [K]
    above the reference temperature at ``expansion`` [m/K]."""
    m = apply_wear_and_expansion(MODEL, wear_m=wear, temperature_rise_k=rise, expansion_coefficient=1.0,
                                 stack_height_m=expansion)
    return max(float(m.static_curve([u])["normal_force_N"].iloc[0]), 0.0)


def test_a_slipping_clutch_wears_as_the_axial_model_and_the_wear_law_say():
    """Flange a turns at 100 rad/s and flange b is held, so the clutch slides throughout; it wears ``wear_rate`` per
    joule from an initial 50 um, so its clamp force falls as the wear grows by 0.3 mm.  Against SciPy's solution of
    ``dw/dt = k mu 2 r_eff F_n(u, w) |dw|`` with ``F_n`` re-solved by the axial model at each wear: the wear within
    1e-4 of its growth, the force within the table's tolerance of the peak force (the table halves its levels until
    its midpoints are there)."""
    k, u, slip = 1e-7, 3e-3, 100.0
    d = Driveline("worn")
    d.inertia("e", J=1.0, w0=slip).inertia("v", J=1.0)
    d.speed("drive", "e", slip)
    d.speed("hold", "v", 0.0)
    d.eclutch("c", "e", "v", position=u, wear=5e-5, wear_rate=k)
    df = d.simulate(1.5, output_step=0.05, rtol=1e-9, check_invariants=True).to_dataframe()
    gain = MODEL.mu * 2.0 * MODEL.r_eff * slip
    ref = solve_ivp(lambda t, w: [k * gain * _force(u, wear=w[0])], (0.0, 1.5), [5e-5], rtol=1e-10, atol=1e-14,
                    dense_output=True)
    t = df["time_s"].to_numpy()
    wear = 5e-5 + k * df["c.dissipated_J"].to_numpy()
    w_ref = ref.sol(t)[0]
    assert w_ref[-1] - w_ref[0] > 2.5e-4   # (it wore, across several of its table's levels)
    assert np.max(np.abs(wear - w_ref)) <= 1e-4 * (w_ref[-1] - w_ref[0])
    fn = df["c.fn_N"].to_numpy()
    for i in range(0, t.size, 5):
        assert abs(fn[i] - _force(u, wear=w_ref[i])) <= SHIFT_TOLERANCE * PEAK, t[i]
    assert fn[0] - fn[-1] > 0.2 * fn[0]


def test_a_hot_clutch_clamps_harder_as_its_stack_expands():
    """A launch whose losses heat a small thermal mass by about 170 K: the stack grows ``expansion (T - T_ref)``
    (over +50 um, where Model 4's curve has a kink that moves along the travel) and the clamp force at the sampled
    temperatures is the axial model's re-solved there."""
    e = 3.6e-7
    d = Driveline("hot")
    d.inertia("engine", J=1.0, w0=200.0).inertia("vehicle", J=5.0)
    d.eclutch("c", "engine", "vehicle", position=0.5e-3, expansion=e, mu_temperature=[[20.0, 1.0], [400.0, 1.0]])
    d.thermal_mass("plate", capacity=100.0, T0=20.0, heat_from=["c"])
    df = d.simulate(0.6, output_step=0.02, rtol=1e-9, check_invariants=True).to_dataframe()
    temp = df["plate.temperature_C"].to_numpy()
    assert temp[-1] - temp[0] > 150.0
    fn = df["c.fn_N"].to_numpy()
    for i in range(0, temp.size, 3):
        assert abs(fn[i] - _force(0.5e-3, rise=temp[i] - 20.0, expansion=e)) <= SHIFT_TOLERANCE * PEAK, i
    assert fn[-1] > fn[0] + 50.0


def _lift_shift(u):
    """The working-point shift [m] at which the axial model's clamp force at ``u`` [m] falls to zero (bisection on
    the model's own curve)."""
    lo, hi = 0.0, 5e-4   # (free at lo, engaged at hi)
    assert _force(u) == 0.0 and _force(u, rise=hi, expansion=1.0) > 0.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _force(u, rise=mid, expansion=1.0) > 0.0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def test_a_cooling_clutch_lets_go_where_its_lift_off_passes_the_bearing():
    """Just beyond its cold lift-off (6.45 mm against 6.35 mm), the clutch starts hot (300 degC, its stack 0.1 mm
    longer): engaged, it holds a free inertia to the driven one.  Its mass cools to the ambient exponentially
    (nothing slides, nothing heats it), so the clutch opens where the lift-off passes the bearing: at ``t = C/G
    ln((T0 - T_a)/(T* - T_a))``, ``T*`` from the axial model's own curve (bisection), within 1e-4 s."""
    e, u, cap, cond = 3.6e-7, 6.45e-3, 500.0, 50.0
    d = Driveline("cooling")
    d.inertia("e", J=1.0, w0=50.0).inertia("v", J=1.0, w0=50.0)
    d.speed("drive", "e", 50.0)
    d.eclutch("c", "e", "v", position=u, expansion=e)
    d.thermal_mass("plate", capacity=cap, T0=300.0, conductance=cond, ambient=20.0, heat_from=["c"])
    res = d.simulate(20.0, output_step=0.5, rtol=1e-9, check_invariants=True)
    t_star = _lift_shift(u) / e + 20.0
    expected = cap / cond * math.log((300.0 - 20.0) / (t_star - 20.0))
    ev = res.events
    free = ev[(ev["element"] == "c") & (ev["event"] == "free")]["time_s"].to_numpy()
    assert free.size == 1
    assert abs(free[0] - expected) < 1e-4 * expected + 1e-4


def test_wear_and_expansion_refusals_name_the_clutch():
    d = Driveline("r")
    d.inertia("e", J=1.0, w0=10.0).inertia("v", J=1.0)
    d.eclutch("c", "e", "v", position=1e-3, expansion=3.6e-7)
    with pytest.raises(ParameterError, match="c: expansion = .* needs the temperature of a thermal mass"):
        d.simulate(0.1)
    d = Driveline("r")
    d.inertia("e", J=1.0, w0=10.0).inertia("v", J=1.0)
    with pytest.raises(ParameterError, match="c: wear = 0.002 m is beyond wear_max"):
        d.eclutch("c", "e", "v", position=1e-3, wear=2e-3)
    with pytest.raises(ParameterError, match="c: wear_rate and expansion need the clutch without its actuator"):
        d.eclutch("c", "e", "v", position=1e-3, wear_rate=1e-9, actuator=True)
    # worn past wear_max while it runs: an error naming it, not a force held at the table's end
    d = Driveline("r")
    d.inertia("e", J=1.0, w0=100.0).inertia("v", J=1.0)
    d.speed("drive", "e", 100.0)
    d.speed("hold", "v", 0.0)
    d.eclutch("c", "e", "v", position=1e-3, wear_rate=1e-6, wear_max=2e-5)
    with pytest.raises(SimulationError, match="c: its wear and thermal expansion moved its working point beyond"):
        d.simulate(1.0)


def test_a_driveline_file_takes_wear_with_units(tmp_path):
    path = tmp_path / "worn.toml"
    path.write_text('''
[driveline]
name = "worn"
[simulation]
t_end = "0.2 s"
[inertia.e]
J = 1.0
w0 = "100 rad/s"
[inertia.v]
J = 1.0
[eclutch.c]
a = "e"
b = "v"
position = "1 mm"
wear = "0.1 mm"
wear_rate = "2e-9 m/J"
''')
    spec = load_driveline(str(path))
    df = spec.driveline.simulate(spec.t_end, output_step=0.1).to_dataframe()
    wear = 1e-4 + 2e-9 * df["c.dissipated_J"].to_numpy()
    for i in range(len(df)):
        assert abs(df["c.fn_N"].iloc[i] - _force(1e-3, wear=wear[i])) <= SHIFT_TOLERANCE * PEAK
    assert df["c.fn_N"].iloc[0] < _force(1e-3) - 300.0   # (the initial wear took its share)


def test_a_sweep_over_the_initial_wear_follows_the_axial_model(tmp_path):
    """The wear fields are sweep parameters from the declaration: a launch at a fixed bearing position (the clutch
    slides with the constant torque ``mu 2 r_eff F_n(u, w)`` until both inertias turn together) swept over the
    initial wear.  Its lock time is ``J1 J2 w0 / ((J1 + J2) T)`` with ``F_n`` the axial model's at each wear."""
    import pandas as pd

    from clutchlab.cli import main

    (tmp_path / "launch.toml").write_text('''
[driveline]
name = "launch"
[simulation]
t_end = "4 s"
rtol = 1e-9
[inertia.engine]
J = 0.5
w0 = "100 rad/s"
[inertia.vehicle]
J = 2.0
[eclutch.c]
a = "engine"
b = "vehicle"
position = "4 mm"
''')
    (tmp_path / "sweep.toml").write_text('''
[sweep]
model = "driveline"
scenario = "launch.toml"
outputs = ["c.last_stick_s", "c.peak_tau_Nm"]

[grid]
"c.wear" = ["0 mm", "0.1 mm", "0.25 mm"]
''')
    out = tmp_path / "res"
    assert main(["sweep", str(tmp_path / "sweep.toml"), "-o", str(out), "--workers", "1", "--no-progress",
                 "--no-plot"]) == 0
    frame = pd.read_parquet(out / "results.parquet")
    assert sorted(frame["c.wear"]) == pytest.approx([0.0, 1e-4, 2.5e-4])
    for row in frame.to_dict("records"):
        torque = MODEL.mu * 2.0 * MODEL.r_eff * _force(4e-3, wear=row["c.wear"])
        assert row["c.peak_tau_Nm"] == pytest.approx(torque, rel=SHIFT_TOLERANCE * PEAK / torque)
        assert row["c.last_stick_s"] == pytest.approx(0.5 * 2.0 * 100.0 / (2.5 * torque), rel=2 * SHIFT_TOLERANCE *
                                                      PEAK / torque)
    assert frame["c.last_stick_s"].is_monotonic_increasing == (list(frame["c.wear"]) == sorted(frame["c.wear"]))
