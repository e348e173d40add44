"""Controllers in the loop and PI design against python-control's own closed loops."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

control = pytest.importorskip("control")

from clutchlab.control.design import PI, ScheduledPI, pi_for_phase_margin  # noqa: E402
from clutchlab.control.loop import closed_loop  # noqa: E402
from clutchlab.errors import ParameterError  # noqa: E402
from core_toys import linear_system  # noqa: E402

A = np.array([[0.0, 1.0], [-40.0, -3.0]])  # a lightly damped mass-spring, y = x0
B = np.array([[0.0], [40.0]])


def _plant():
    return control.ss(A, B, [[1.0, 0.0]], [[0.0]])


@settings(deadline=None, max_examples=20)
@given(st.floats(0.3, 3.0), st.floats(20.0, 80.0))
def test_pi_reaches_the_phase_margin_at_the_crossover(fc, pm):
    G = _plant()
    try:
        pi = pi_for_phase_margin(G, fc, pm)
    except ParameterError as exc:  # only where a PI cannot do it: the phase needed is outside (-90, 0) deg
        assert "cannot give" in str(exc) or "unstable" in str(exc)
        return
    L = pi.tf() * control.tf(G)
    w = 2 * np.pi * fc
    assert abs(complex(np.squeeze(L(1j * w)))) == pytest.approx(1.0, rel=1e-9)
    phase = np.degrees(np.angle(complex(np.squeeze(L(1j * w)))))
    assert (phase + 180.0 - pm + 180.0) % 360.0 - 180.0 == pytest.approx(0.0, abs=1e-7)
    assert np.all(control.feedback(L, 1).poles().real < 0)


def test_pi_refuses_what_it_cannot_do():
    with pytest.raises(ParameterError, match="cannot give"):
        pi_for_phase_margin(_plant(), 50.0, 60.0)  # far above the resonance the plant has -180 deg
    with pytest.raises(ParameterError, match="in \\(0, 90\\)"):
        pi_for_phase_margin(_plant(), 1.0, 120.0)


@pytest.mark.parametrize("delay", [0, 1])
def test_discrete_loop_equals_the_sampled_data_closed_loop(delay):
    """The loop (model between samples, controller at samples, zero-order hold) against python-control:
    the plant discretised exactly (ZOH) in feedback with the same discrete controller."""
    Ts = 0.01
    s = linear_system(A, np.zeros(2), B)
    C = PI(0.3, 0.1).discrete(Ts)
    r = 0.1
    res = closed_loop(s, C, Ts, 3.0, measure=["x0"], actuate=["u0"], reference=r, rtol=1e-11, delay=delay)
    Gd = control.c2d(_plant(), Ts, "zoh")
    Cs = control.ss(C)
    n = res.frame.shape[0]
    xg, xc, pending = np.zeros(2), np.zeros(Cs.nstates), 0.0
    y_ref, u_ref = np.empty(n), np.empty(n)
    for k in range(n):
        y = float((Gd.C @ xg)[0])
        e = r - y
        out = float((Cs.C @ xc + Cs.D @ [e])[0])
        xc = Cs.A @ xc + Cs.B @ [e]
        applied, pending = (out, out) if delay == 0 else (pending, out)
        y_ref[k], u_ref[k] = y, applied
        xg = Gd.A @ xg + Gd.B[:, 0] * applied
    np.testing.assert_allclose(res.frame["x0_1"], y_ref, atol=1e-8)
    np.testing.assert_allclose(res.frame["u0_1"], u_ref, atol=1e-8)
    assert abs(res.frame["x0_1"].iloc[-100:].mean() - r) < 0.05 * r  # integral action: no offset left
    assert res.frame["reference_x0_1"].eq(r).all()


def test_function_controller_memory_and_saturation():
    Ts = 0.01
    s = linear_system(A, np.zeros(2), B).replace(limits={"u0": (-0.05, 0.05)})
    calls = []

    def bang(t, y, memory):
        memory[0] += 1.0  # counts the samples
        calls.append(memory[0])
        return np.array([1.0 if y[0] < 0.5 else -1.0])

    res = closed_loop(s, bang, Ts, 0.5, measure=["x0"], actuate=["u0"], memory=[0.0])
    assert calls == list(np.arange(1.0, 52.0))
    assert set(np.round(res.frame["u0_1"], 12)) <= {0.05, -0.05} and res.frame["saturated_1"].all()
    # without saturation the output is applied as returned
    free = closed_loop(s, bang, Ts, 0.5, measure=["x0"], actuate=["u0"], saturate=False)
    assert set(free.frame["u0_1"]) <= {1.0, -1.0} and not free.frame["saturated_1"].any()


def test_loop_refuses_bad_requests():
    s = linear_system(A, np.zeros(2), B)
    with pytest.raises(ParameterError, match="c2d"):
        closed_loop(s, PI(1.0, 1.0).tf(), 0.01, 1.0, measure=["x0"], actuate=["u0"])
    with pytest.raises(ParameterError, match="differs from sample_time"):
        closed_loop(s, PI(1.0, 1.0).discrete(0.02), 0.01, 1.0, measure=["x0"], actuate=["u0"])
    with pytest.raises(ParameterError, match="unknown input 'volts'"):
        closed_loop(s, PI(1.0, 1.0).discrete(0.01), 0.01, 1.0, measure=["x0"], actuate=["volts"])
    with pytest.raises(ParameterError, match="sample_time"):
        closed_loop(s, PI(1.0, 1.0).discrete(0.01), 0.0, 1.0, measure=["x0"], actuate=["u0"])


def test_scheduled_pi_interpolates_its_gains():
    pi = ScheduledPI(np.array([0.0, 1.0]), np.array([1.0, 3.0]), np.array([1.0, 1.0]), None, 0.1,
                     lambda t: 1.0)
    mem = np.array([0.0])
    u = pi(0.0, np.array([0.5]), mem)  # kp = 2 at 0.5, e = 0.5
    assert u[0] == pytest.approx(2 * 0.5 + 2 * 0.1 / 1.0 * 0.5)
    assert mem[0] == pytest.approx(0.1)


def test_eclutch_worked_design_linear_prediction_holds_on_the_nonlinear_model():
    """Worked design (1): PI for 60 deg at 5 Hz, scheduled over the travel, at 1 kHz on the nonlinear model."""
    from clutchlab.demo import control as demo

    d = demo.design()
    assert d["ops"][d["touch"]].value("normal_force") == pytest.approx(0.0, abs=80.0)  # near the touch point
    runs = demo.step_runs(d, t_end=0.3)
    for r in runs:
        # the overshoot the linear closed loop predicts, within 2 percentage points
        assert abs(r["overshoot_nonlinear"] - r["overshoot_linear"]) < 2.0, r["position"]
        # and the rise the same: within 3 % of the step over the first 60 ms
        first = r["time_s"] <= 0.06
        assert np.max(np.abs(r["nonlinear"][first] - r["linear"][first])) < 0.03


def test_anhysteretic_magnet_has_no_memory():
    from clutchlab.emtc.magnet import bundled_magnet

    m = bundled_magnet()
    a = m.anhysteretic()
    gap = 0.6e-3
    up = np.linspace(m.grid[0], m.grid[-1], 41)
    down = up[::-1]
    a.reset()
    f_up = a.simulate(up, np.full(up.size, gap))
    f_down = a.simulate(down, np.full(down.size, gap))[::-1]
    np.testing.assert_allclose(f_up, f_down, rtol=1e-12, atol=1e-9)  # the same force rising and falling
    loop = m.major_loop(41, airgap=gap)
    mean = 0.5 * (loop["ascending"] + loop["descending"]).to_numpy()
    np.testing.assert_allclose(f_up, mean, rtol=1e-9, atol=1e-6 * np.abs(mean).max())
    # the plant itself does have hysteresis there
    m.reset()
    h_up = m.simulate(up, np.full(up.size, gap))
    h_down = m.simulate(down, np.full(down.size, gap))[::-1]
    assert np.max(np.abs(h_up - h_down)) > 0.05 * np.abs(h_up).max()


def test_emtc_worked_design_inverse_preisach_removes_the_hysteresis_error():
    """Worked design (2): torque holds reached exactly with the inverse Preisach model, not without it."""
    from clutchlab.demo import control as demo

    holds = demo.emtc_tracking()["holds"]
    comp = holds[holds.controller == "inverse Preisach"]
    plain = holds[holds.controller == "anhysteretic inverse"]
    assert (holds.min_slip_rad_s > 1.0).all()  # slipping throughout: the torque follows the clamp force
    assert comp.torque_error_Nm.abs().max() < 0.01
    falling = plain.reference_Nm.diff().fillna(1.0).to_numpy() < 0  # holds after a falling reference
    assert (plain.torque_error_Nm.to_numpy()[falling] > 10.0).all()  # the descending branch holds more force
    assert (plain.torque_error_Nm.to_numpy()[~falling] < -5.0).all()


def test_loop_on_a_fixed_step_model_converges_to_the_sampled_data_loop():
    """The model in the core's fixed-step mode (Rodas3, order 3) inside the loop: at a tenth of the sample
    time the loop equals the exact sampled-data loop closely, and the error falls as the step does."""
    Ts = 0.01
    s = linear_system(A, np.zeros(2), B)
    C = PI(0.3, 0.1).discrete(Ts)
    exact = closed_loop(s, C, Ts, 1.0, measure=["x0"], actuate=["u0"], reference=0.1, rtol=1e-11).frame["x0_1"]
    errs = []
    for h in (Ts / 2, Ts / 4, Ts / 8):
        run = closed_loop(s, C, Ts, 1.0, measure=["x0"], actuate=["u0"], reference=0.1, fixed_step=h)
        errs.append(float(np.max(np.abs(run.frame["x0_1"] - exact))))
    assert errs[-1] < 1e-4 * 0.1
    assert errs[0] / errs[1] > 5 and errs[1] / errs[2] > 5  # order 3: a factor 8 per halving


def test_wet_worked_design_pi_holds_the_torque_the_feedforward_loses():
    """Worked design (3): the wet engagement's torque, feedforward from trimmed points, PI on the linear model."""
    from clutchlab.demo import control as demo

    wet = demo.wet_torque_control()
    m = wet["metrics"].set_index("controller")
    torques, forces = wet["feedforward"]
    assert np.all(np.diff(forces) > 0)  # more torque needs more force at the design slip speed
    ff, pi, windup = (m.loc[k, "rms_error_Nm"] for k in ("feedforward", "feedforward + PI",
                                                           "feedforward + PI, integrating always"))
    assert pi < 0.4 * ff and pi < 5.0
    assert windup > ff  # integrating through the fill and the ramp winds up: why the band is there
    assert m["lockup_s"].between(0.75, 0.9).all()  # every run locks up as the drive's ramp ends


def test_scheduled_pi_conditional_integration():
    pi = ScheduledPI(np.array([0.0, 1.0]), np.array([1.0, 1.0]), np.array([1.0, 1.0]), None, 0.1,
                     lambda t: 1.0, integrate_band=0.1)
    mem = np.array([0.0])
    pi(0.0, np.array([0.5]), mem)  # 50 % off: no integration
    assert mem[0] == 0.0
    pi(0.0, np.array([0.95]), mem)  # 5 % off: integrates
    assert mem[0] == pytest.approx(0.1 * 0.05)


def test_function_controller_reference_is_recorded_only_when_given():
    s = linear_system(A, np.zeros(2), B)
    hold = lambda t, y, memory: np.array([0.0])  # noqa: E731
    plain = closed_loop(s, hold, 0.01, 0.1, measure=["x0"], actuate=["u0"])
    assert "reference_x0_1" not in plain.frame
    given = closed_loop(s, hold, 0.01, 0.1, measure=["x0"], actuate=["u0"], reference=lambda t: 2.0 * t)
    np.testing.assert_allclose(given.frame["reference_x0_1"], 2.0 * given.frame["time_s"])


@settings(deadline=None, max_examples=25)
@given(st.floats(0.5, 30.0))
def test_loop_margins_of_a_triple_lag_against_closed_forms(k):
    """L = k / (s + 1)^3: the phase is -180 deg at w = sqrt(3), where |L| = k / 8, so the gain margin is
    8 / k; |L| = 1 at w = sqrt(k^(2/3) - 1) (k > 1), phase margin 180 - 3 atan(w). The closed loop
    (s + 1)^3 + k has two right-half-plane poles for k > 8, which the Nyquist count must give."""
    from clutchlab.control import loop_margins

    row = loop_margins([("lag", control.tf([k], [1.0, 3.0, 3.0, 1.0]))]).iloc[0]
    assert row.gain_margin_dB == pytest.approx(20 * np.log10(8.0 / k), abs=1e-6)
    assert row.phase_crossover_Hz == pytest.approx(np.sqrt(3.0) / (2 * np.pi), rel=1e-6)
    if k > 1.01:
        w = np.sqrt(k ** (2.0 / 3.0) - 1.0)
        assert row.crossover_Hz == pytest.approx(w / (2 * np.pi), rel=1e-6)
        assert row.phase_margin_deg == pytest.approx(180.0 - 3 * np.degrees(np.arctan(w)), abs=1e-5)
    unstable = k > 8.0 + 1e-6
    assert row.closed_loop_rhp_poles_1 == (2 if unstable else 0) or abs(k - 8.0) < 1e-6
    assert row.encirclements_1 == row.closed_loop_rhp_poles_1 and row.open_loop_rhp_poles_1 == 0
    assert row.nyquist_consistent_1 == 1


def test_eclutch_loops_satisfy_the_nyquist_criterion():
    """The E-clutch position loops of worked design 1: the designed phase margin at the designed crossover,
    stable closed loops, and where the actuator is open-loop unstable (beyond the force peak) one
    counter-clockwise encirclement of -1 (N = -1), as Z = N + P = 0 requires."""
    from clutchlab.control import loop_margins
    from clutchlab.demo import control as demo
    from clutchlab.control.plots import nyquist_figure

    d = demo.design()
    loops = [(f"{x * 1e3:g} mm", control.ss(p.tf()) * G) for x, p, G in zip(demo.POSITIONS, d["pis"], d["models"])]
    m = loop_margins(loops)
    np.testing.assert_allclose(m.phase_margin_deg, demo.PHASE_MARGIN_DEG, atol=1e-6)
    np.testing.assert_allclose(m.crossover_Hz, demo.CROSSOVER_HZ, rtol=1e-6)
    assert (m.closed_loop_rhp_poles_1 == 0).all() and (m.nyquist_consistent_1 == 1).all()
    unstable = m.open_loop_rhp_poles_1 > 0
    assert unstable.any() and not unstable.all()  # the open loop is unstable beyond the force peak only
    assert (m.encirclements_1[unstable] == -m.open_loop_rhp_poles_1[unstable]).all()
    fig = nyquist_figure(loops[:2])
    ax = fig.axes[0]
    assert ax.get_xlabel() == "Re L(jω) [1]" and ax.get_legend() is not None
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_the_phase_table_is_continuous_and_starts_within_one_turn():
    """The Bode phase jumped to -600 deg (#33): ``frequency_table``'s phase is unwrapped (continuous) and its first
    point in [-270, 90) deg.  Closed forms: -1/(s+1)^3 has the phase -180 - 3 atan(w) deg (np.angle starts it at
    +180, so unwrapping alone gave 360 deg too much); s/(s+1), 90 - atan(w)."""
    import control

    from clutchlab.control import frequency_table

    G = control.ss(control.tf([-1.0], [1.0, 3.0, 3.0, 1.0]))
    f = np.logspace(-3, 2, 300)
    phase = frequency_table(G, f).filter(like="phase_deg_").iloc[:, 0].to_numpy()
    np.testing.assert_allclose(phase, -180.0 - 3.0 * np.degrees(np.arctan(2 * np.pi * f)), atol=1e-6)
    lead = frequency_table(control.ss(control.tf([1.0, 0.0], [1.0, 1.0])), f).filter(like="phase_deg_").iloc[:, 0]
    np.testing.assert_allclose(lead.to_numpy(), 90.0 - np.degrees(np.arctan(2 * np.pi * f)), atol=1e-6)
