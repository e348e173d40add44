"""The engine element, sampled signals, the E-clutch with its actuator dynamics and the launch example.

Closed forms: an engine whose map is linear in speed is a first-order system (exponential approach to the
speed where map torque and load balance); the idle-speed controller's integral settles at the drag it
compensates.  The E-clutch's normal force is checked against the dedicated E-clutch dynamics run
(:class:`clutchlab.eclutch.dynamics.EClutch`, its own Rodas3 integrator) and its torque against
``2 F_n r_eff mu`` ([1] Sec. 3.2).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from clutchlab.driveline import Driveline, Signal
from clutchlab.driveline.description import load_driveline, parse_driveline
from clutchlab.errors import ParameterError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
RPM = math.pi / 30


def test_engine_map_linear_in_speed_is_an_exponential_approach():
    """Map ``T(w) = T0 (1 - w / w_max)`` at full throttle (two speed points, exact linear interpolation), a
    constant load ``L``: ``J w' = T0 - L - (T0 / w_max) w``, so ``w(t) = w_inf + (w0 - w_inf) exp(-t / tau)``
    with ``w_inf = w_max (1 - L / T0)``, ``tau = J w_max / T0``.  The throttle scales linearly between the
    drag row (throttle 0: zero here) and full load."""
    T0, w_max, J, L, w0 = 200.0, 500.0, 0.25, 50.0, 10.0
    d = Driveline("engine")
    d.inertia("crank", J=J, w0=w0)
    d.engine("ice", "crank", ([0.0, w_max], [0.0, 1.0], [[0.0, T0], [0.0, 0.0]]), throttle=1.0)
    d.torque("load", "crank", -L)
    df = d.simulate(1.0, rtol=1e-10, output_step=0.1).to_dataframe()
    w_inf, tau = w_max * (1 - L / T0), J * w_max / T0
    expected = w_inf + (w0 - w_inf) * np.exp(-df["time_s"] / tau)
    np.testing.assert_allclose(df["crank.w_rad_s"], expected, rtol=1e-8)
    np.testing.assert_allclose(df["ice.tau_Nm"], T0 * (1 - df["crank.w_rad_s"] / w_max), rtol=1e-12)
    # half throttle: half the torque
    d2 = Driveline("half")
    d2.inertia("crank", J=J, w0=w0)
    d2.engine("ice", "crank", ([0.0, w_max], [0.0, 1.0], [[0.0, T0], [0.0, 0.0]]), throttle=0.5)
    y = d2.simulate(0.1, output_step=0.1).to_dataframe()
    assert y["ice.tau_Nm"].iloc[0] == pytest.approx(0.5 * T0 * (1 - w0 / w_max), rel=1e-12)


def test_idle_controller_holds_the_idle_speed_against_the_drag():
    """At throttle 0 the map gives the drag ``-D``; the idle PI controller brings the engine from below to its
    set speed, where its integral carries the drag: ``I = D``, output ``D``.  In the linear range (no clip) the
    loop is ``J e'' + kp e' + ki e = 0``-like: it settles within a few ``J / kp``; the run is checked at its
    end.  The input work goes into kinetic energy and the drag (energy balance)."""
    D, J = 12.0, 0.2
    d = Driveline("idle")
    d.inertia("crank", J=J, w0=70.0)
    d.engine("ice", "crank", ([0.0, 600.0], [0.0, 1.0], [[-D, 100.0], [-D, 100.0]]), throttle=0.0,
             idle_speed=84.0, idle_kp=2.0, idle_ki=20.0, idle_torque_max=60.0)
    df = d.simulate(5.0, rtol=1e-10, output_step=0.5).to_dataframe()
    assert df["crank.w_rad_s"].iloc[-1] == pytest.approx(84.0, abs=1e-6)
    assert df["ice.idle_integral_Nm"].iloc[-1] == pytest.approx(D, rel=1e-6)
    assert df["ice.tau_Nm"].iloc[-1] == pytest.approx(0.0, abs=1e-6)     # map -D plus controller +D
    assert abs(df["energy_error_J"]).max() < 1e-8
    # clipped: a controller limited to less than the drag cannot hold idle; its integral does not wind up
    d = Driveline("weak")
    d.inertia("crank", J=J, w0=84.0)
    d.engine("ice", "crank", ([0.0, 600.0], [0.0, 1.0], [[-D, 100.0], [-D, 100.0]]), throttle=0.0,
             idle_speed=84.0, idle_kp=2.0, idle_ki=20.0, idle_torque_max=5.0)
    df = d.simulate(2.0, output_step=0.5).to_dataframe()
    # decelerating at (5 - 12) / J once clipped, and the integral stays near the limit (back-calculation)
    assert df["crank.w_rad_s"].iloc[-1] < 84.0 - 0.5 * 7.0 / J
    assert df["ice.idle_integral_Nm"].iloc[-1] < 5.0 + 1.0


def test_a_sampled_signal_does_not_cut_the_steps():
    """A torque read from 20,001 samples of a sine takes the integrator's own steps (far fewer than the
    samples) and gives the sine's closed form ``w = w0 + (A / (J om)) (1 - cos(om t))`` to the sampling
    error (linear interpolation: ``A (om h)^2 / 8``); the same samples as a table end a step at every sample."""
    A, f, J, T = 5.0, 2.0, 0.5, 2.0
    om = 2 * math.pi * f
    t = np.linspace(0.0, T, 20001)
    runs = {}
    for kind in ("sampled", "table"):
        d = Driveline(kind)
        d.inertia("J", J=J)
        sig = Signal.sampled(t, A * np.sin(om * t)) if kind == "sampled" else Signal.table(t, A * np.sin(om * t))
        d.torque("T", "J", sig)
        runs[kind] = d.simulate(T, rtol=1e-8, sample_times=[0.5, 1.0, 1.5, 2.0])
    times = np.array([0.5, 1.0, 1.5, 2.0])
    exact = A / (J * om) * (1 - np.cos(om * times))
    h = t[1] - t[0]
    for r in runs.values():
        np.testing.assert_allclose(r["J.w_rad_s"], exact, atol=A * (om * h) ** 2 / 8 * T / J + 1e-8)
    assert runs["sampled"].stats["accepted_steps"] < 2000
    assert runs["table"].stats["accepted_steps"] >= 20000
    with pytest.raises(ParameterError, match="breaks must be finite"):
        Signal.sampled([0, 1], [0, 1], breaks=[math.nan])


def test_eclutch_with_its_actuator_takes_the_dynamics_normal_force():
    """With ``actuator=True`` the clutch's normal force is the E-clutch dynamics' (actuator, position control,
    Model 4) under the bearing reference: equal to the dedicated run (from rest, the reference held at its first
    value during the pre-roll) at every sample; between samples linear.  The torque while slipping is
    ``2 F_n r_eff mu``; the static-curve element (no actuator) follows the reference without the lag."""
    from clutchlab.eclutch.dynamics import EClutch
    from clutchlab.eclutch.models import ClutchModel

    ref = Signal.table([0.0, 0.2, 0.6], [8e-3, 8e-3, 1e-3])
    d = Driveline("act")
    d.inertia("engine", J=0.2, w0=150.0).inertia("load", J=1.0)
    d.eclutch("clutch", "load", "engine", position=ref, actuator=True, pre_roll=0.5, actuator_step=2e-3, settle=0.4)
    df = d.simulate(1.0, rtol=1e-9, output_step=0.01).to_dataframe()
    direct = EClutch(clutch=ClutchModel.preset(4)).simulate(
        {"bearing_reference": ([0.0, 0.5, 0.7, 1.1], [8e-3, 8e-3, 8e-3, 1e-3])}, 1.5, output_step=2e-3).to_dataframe()
    fn_direct = np.interp(df["time_s"] + 0.5, direct["time_s"], np.maximum(direct["normal_force_N"], 0.0))
    np.testing.assert_allclose(df["clutch.fn_N"], fn_direct, rtol=1e-9, atol=1e-6)
    assert df["clutch.fn_N"].iloc[0] == 0.0 and df["clutch.fn_N"].iloc[-1] > 1000.0
    cm = ClutchModel.preset(4)
    slip = df["clutch.mode_1"] == 1
    assert slip.sum() > 10
    np.testing.assert_allclose(df["clutch.tau_Nm"][slip], 2 * df["clutch.fn_N"][slip] * cm.r_eff * cm.mu, rtol=1e-12)
    # the actuator lags the reference: the static-curve element clamps earlier
    s = Driveline("static")
    s.inertia("engine", J=0.2, w0=150.0).inertia("load", J=1.0)
    s.eclutch("clutch", "load", "engine", position=ref)
    ds = s.simulate(1.0, rtol=1e-9, output_step=0.01).to_dataframe()
    first = lambda frame: frame["time_s"][frame["clutch.fn_N"] > 0].iloc[0]   # noqa: E731
    assert first(ds) < first(df)
    with pytest.raises(ParameterError, match="constant, a ramp or a table"):
        Driveline("x").inertia("a", J=1).eclutch("c", "a", "ground", position=Signal.sine(1e-3, 1.0), actuator=True)


@pytest.fixture(scope="module")
def launch():
    spec = load_driveline(EXAMPLES / "driveline_eclutch_launch.toml")
    r = spec.driveline.simulate(spec.t_end, rtol=1e-8, output_step=spec.output_step)
    return spec, r


def test_launch_slips_locks_up_and_does_not_stall(launch):
    """The launch: the clutch engages at about 0.67 s, slips while the vehicle accelerates, and locks up once
    (between 2 and 2.5 s) and stays locked; the engine never falls more than 5 % below its idle speed; engine and
    input shaft turn together after lock-up; the vehicle moves off; energy balance within 1e-7 of the work."""
    spec, r = launch
    df = r.to_dataframe()
    ev = r.events
    clutch = ev[ev["element"] == "clutch"]
    assert list(clutch["event"]) == ["backward", "stick"]
    t_engage, t_lock = clutch["time_s"]
    assert 0.6 < t_engage < 0.75 and 2.0 < t_lock < 2.5
    assert df["engine.w_rad_s"].min() > 0.95 * 800 * RPM
    after = df["time_s"] > t_lock + 0.05
    np.testing.assert_allclose(df["flywheel.w_rad_s"][after], df["input_shaft.w_rad_s"][after], rtol=0, atol=1e-6)
    # the gears hold their ratios exactly
    np.testing.assert_allclose(df["input_shaft.w_rad_s"], 3.5 * df["output_shaft.w_rad_s"], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(df["output_shaft.w_rad_s"], 4.2 * df["axle.w_rad_s"], rtol=1e-9, atol=1e-9)
    assert df["vehicle.w_rad_s"].iloc[-1] * 0.3 > 5.0      # above 5 m/s after 5 s
    work = df["input_work_J"].iloc[-1]
    assert abs(df["energy_error_J"]).max() < 1e-7 * work
    # the clutch's heat is the slip phase's: its dissipation stops at lock-up
    diss = df["clutch.dissipated_J"]
    assert diss[after].max() - diss[after].min() < 1e-6 * diss.iloc[-1]


def test_launch_is_converged(launch):
    """The shipped tolerance (1e-6) gives the tight run's lock-up to 5e-5 s (the slip reaches zero at a shallow angle) and speeds to 1e-4 of their range."""
    spec, tight = launch
    loose = spec.driveline.simulate(spec.t_end, rtol=spec.rtol, output_step=spec.output_step)
    lock = lambda r: r.events[(r.events["element"] == "clutch") & (r.events["event"] == "stick")]["time_s"].iloc[0]  # noqa: E731
    assert abs(lock(loose) - lock(tight)) < 5e-5
    a, b = loose.to_dataframe(), tight.to_dataframe()
    for col in ("engine.w_rad_s", "vehicle.w_rad_s"):
        assert np.max(np.abs(a[col] - b[col])) < 1e-4 * np.ptp(b[col])


def test_engine_and_actuator_file_errors(tmp_path):
    base = {"inertia": {"e": {"J": "0.2 kg m^2", "w0": "800 rpm"}},
            "engine": {"ice": {"flange": "e", "torque_map": {"speeds": ["0 rpm", "6000 rpm"], "throttles": [0, 1],
                                                            "torques": [["-5 N m", "100 N m"], ["-20 N m"]]}}}}
    with pytest.raises(ParameterError, match=r"engine\.ice\.torque_map\.torques\[1\].*one per throttle"):
        parse_driveline(base, "x.toml", tmp_path)
    base["engine"]["ice"]["torque_map"]["torques"][1] = ["-20 N m", "90 kg"]
    with pytest.raises(ParameterError, match=r"torque_map\.torques\[1\]\[1\]"):
        parse_driveline(base, "x.toml", tmp_path)
    base["engine"]["ice"]["torque_map"]["torques"][1] = ["-20 N m", "90 N m"]
    base["engine"]["ice"]["idle_speed"] = "800 rpm"
    f = parse_driveline(base, "x.toml", tmp_path)
    assert "idle controller at 83.7758 rad/s" in f.driveline.describe()
    base["engine"]["ice"]["torque_map"] = [["0 rpm", "100 N m"], ["6000 rpm", "80 N m"]]   # full-load rows
    f = parse_driveline(base, "x.toml", tmp_path)
    y = f.driveline.simulate(0.01, output_step=0.01).to_dataframe()
    assert y["ice.tau_Nm"].iloc[0] == pytest.approx(100.0 - 20.0 * 800 / 6000, rel=1e-12)   # throttle 1 by default
    ecl = {"inertia": {"a": {"J": "1 kg m^2"}}, "eclutch": {"c": {"a": "a", "b": "ground", "position": "8 mm",
                                                                  "actuator": "yes"}}}
    with pytest.raises(ParameterError, match=r"eclutch\.c\.actuator = 'yes': expected true or false"):
        parse_driveline(ecl, "x.toml", tmp_path)
    with pytest.raises(ParameterError, match="strictly increasing"):
        Driveline("x").inertia("e", J=1).engine("ice", "e", ([0.0, 0.0], [0.0, 1.0], [[0, 1], [0, 1]]))
