"""Operating points and linear models (clutchlab.control) against closed forms and nonlinear simulation."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

control = pytest.importorskip("control")

from clutchlab import eclutch as E  # noqa: E402
from clutchlab.control import (OperatingPointError, frequency_table, linearize, nonlinear_iosystem,  # noqa: E402
                               operating_point, pole_sweep, write_linear_model)
from clutchlab.errors import ParameterError  # noqa: E402
from clutchlab.system import Simulation  # noqa: E402
from core_toys import linear_system  # noqa: E402

finite = st.floats(-3.0, 3.0, allow_nan=False)


def _stable(m):
    """A well-conditioned Hurwitz matrix from any square matrix: -(M M^T + I)."""
    return -(m @ m.T + np.eye(m.shape[0]))


@settings(deadline=None, max_examples=25)
@given(arrays(float, (3, 3), elements=finite), arrays(float, (3, 2), elements=finite),
       arrays(float, 2, elements=finite))
def test_linear_model_gives_its_own_matrices_and_steady_state(m, b, u):
    a = _stable(m)
    s = linear_system(a, np.zeros(3), b)
    op = operating_point(s, inputs={"u0": u[0], "u1": u[1]})
    x_exact = -np.linalg.solve(a, b @ u)  # x' = A x + B u = 0
    np.testing.assert_allclose(op.x, x_exact, rtol=1e-9, atol=1e-9 * (1 + np.abs(x_exact).max()))
    lin = linearize(op)
    assert lin.analytic_jacobian
    assert np.array_equal(lin.A, a)  # the model's analytic Jacobian, exactly
    np.testing.assert_allclose(lin.B, b, rtol=1e-9, atol=1e-9 * (1 + np.abs(b).max()))
    np.testing.assert_allclose(lin.C, np.eye(3), atol=1e-9)
    np.testing.assert_allclose(lin.D, 0.0, atol=1e-9)
    assert lin.state_labels == ["x0_1", "x1_1", "x2_1"] and lin.input_labels == ["u0_1", "u1_1"]


@settings(deadline=None, max_examples=25)
@given(arrays(float, (3, 3), elements=finite), arrays(float, (3, 1), elements=finite))
def test_algebraic_rows_are_eliminated(m, b):
    a = _stable(m)  # the algebraic block a[2, 2] < 0 is non-singular
    s = linear_system(a, np.zeros(3), b, method="rodas", mass=np.array([1.0, 1.0, 0.0]))
    lin = linearize(s, outputs=["x0", "x1", "x2"])
    d, g = [0, 1], [2]
    aaa = a[np.ix_(g, g)]
    a_red = a[np.ix_(d, d)] - a[np.ix_(d, g)] @ np.linalg.solve(aaa, a[np.ix_(g, d)])
    b_red = b[d] - a[np.ix_(d, g)] @ np.linalg.solve(aaa, b[g])
    np.testing.assert_allclose(lin.A, a_red, rtol=1e-9, atol=1e-9 * (1 + np.abs(a_red).max()))
    np.testing.assert_allclose(lin.B, b_red, rtol=1e-7, atol=1e-7 * (1 + np.abs(b_red).max()))
    # the algebraic state as an output: x2 = -aaa^-1 (a[2, d] x_d + b[2] u)
    c_alg = -np.linalg.solve(aaa, a[np.ix_(g, d)])
    np.testing.assert_allclose(lin.C[2], c_alg[0], rtol=1e-7, atol=1e-7 * (1 + np.abs(c_alg).max()))
    assert lin.nstates == 2


def test_trim_solves_for_an_input_holding_a_target():
    a = np.array([[-2.0, 1.0], [0.5, -3.0]])
    b = np.array([[1.0], [0.0]])
    s = linear_system(a, np.zeros(2), b)
    op = operating_point(s, targets={"x1": 0.25}, free_inputs=["u0"])
    # steady: x = -A^-1 B u, and x1 = 0.25 fixes u
    g = -np.linalg.solve(a, b)[:, 0]
    np.testing.assert_allclose(op.u[0], 0.25 / g[1], rtol=1e-10)
    np.testing.assert_allclose(op.x, g * op.u[0], rtol=1e-10)


def test_bad_requests_say_what_is_wrong():
    s = linear_system(np.array([[-1.0]]), np.zeros(1), np.array([[1.0]]))
    with pytest.raises(ParameterError, match="unknown input 'volts'"):
        operating_point(s, inputs={"volts": 1.0})
    with pytest.raises(ParameterError, match="conditions"):
        operating_point(s, targets={"x0": 1.0})  # a target without a free input
    with pytest.raises(ParameterError, match="unknown state/output 'bearing'"):
        linearize(s, outputs=["bearing"])


# ------------------------------------------------------------------ the E-clutch actuator
@pytest.fixture(scope="module")
def frictionless():
    """The E-clutch with the actuator's Coulomb friction off: one mode for small signals either way."""
    return E.EClutch(E.ActuatorParameters(master_seal_friction=0.0, slave_seal_friction=0.0,
                                          seal_pressure_friction=0.0, spindle_efficiency=1.0))


def test_eclutch_operating_point_refuses_beyond_the_travel():
    ec = E.EClutch()
    with pytest.raises(OperatingPointError, match=r"bearing_position = 0.02 m is outside the CSC travel"):
        ec.operating_point(0.02)
    s = ec.as_system({"voltage": 0.0}, held_input=True)
    with pytest.raises(OperatingPointError, match=r"target bearing_position = 0.012 is outside its physical range"):
        operating_point(s, targets={"bearing_position": 0.012}, free_inputs=["motor_voltage"])
    with pytest.raises(OperatingPointError, match=r"input motor_voltage = 20 is outside its physical range"):
        operating_point(s, inputs={"motor_voltage": 20.0})


def test_eclutch_steady_state_is_a_force_balance(frictionless):
    op = frictionless.operating_point(4e-3)  # voltage input
    assert op.value("bearing_position") == pytest.approx(4e-3, rel=1e-9)
    assert op.value("bearing_velocity") == 0.0 or abs(op.value("bearing_velocity")) < 1e-12
    a = frictionless.actuator
    # the motor stands still: i = V / R
    assert op.value("motor_current") == pytest.approx(op.u[0] / a.resistance, rel=1e-9)
    # the CSC piston: p A_sl + preload spring (F_0 - k x) = clutch force on the bearing
    spring = a.csc_preload - a.csc_spring_rate * 4e-3
    assert op.value("bearing_force") + spring == pytest.approx(op.value("bearing_force_clutch"), rel=1e-9)
    # no flow in the line, equal pressures at both ends
    assert op.value("pressure") == pytest.approx(op.value("master_pressure"), rel=1e-9)
    assert {"input_work", "dissipated", "friction_dissipated"} <= set(op.monitors)


def test_closed_loop_step_matches_the_nonlinear_model(frictionless):
    op = frictionless.operating_point(4e-3, input="bearing_reference")
    lin = linearize(op, outputs=["bearing_position"])
    assert lin.mode["friction_mode_bearing"] == "free"  # no friction element left on the CSC
    assert lin.dcgain() == pytest.approx(1.0, rel=1e-6)  # integral action
    d = 2e-5  # 0.5 % of the position
    T = np.linspace(0.0, 0.3, 301)
    sim = Simulation(op.start(), rtol=1e-8)
    y = [0.0]
    for t in T[1:]:
        sim.advance(t, [op.u[0] + d])
        y.append(sim.x[1] - op.x[1])
    y_lin = control.forced_response(lin, T, np.full(T.size, d)).outputs
    assert np.max(np.abs(np.array(y) - y_lin)) < 0.01 * d


@pytest.mark.parametrize("f", [3.0, 20.0, 60.0])
def test_bode_matches_simulated_sines(frictionless, f):
    op = frictionless.operating_point(4e-3, input="bearing_reference")
    lin = linearize(op, outputs=["bearing_position"])
    Ts, amp, w = 5e-5, 1e-5, 2 * np.pi * f
    n = int(round(2.0 / Ts))
    tt = np.arange(1, n + 1) * Ts
    yy = np.empty(n)
    sim = Simulation(op.start(), rtol=1e-8)
    for k in range(n):  # the input held over each Ts (zero-order hold of the sine)
        sim.advance(tt[k], [op.u[0] + amp * np.sin(w * (tt[k] - Ts))])
        yy[k] = sim.x[1] - op.x[1]
    sel = tt > 1.5  # after the transient (slowest pole about -4.6 1/s)
    M = np.column_stack([np.sin(w * tt[sel]), np.cos(w * tt[sel]), np.ones(sel.sum())])
    a, b, _ = np.linalg.lstsq(M, yy[sel], rcond=None)[0]
    g_sim = (a + 1j * b) / amp
    g_lin = complex(np.squeeze(lin(1j * w))) * np.exp(-1j * w * Ts / 2)  # the hold delays by Ts / 2
    table = frequency_table(lin, [f])
    assert table[f"gain_bearing_position_m__bearing_reference_m"].iloc[0] == pytest.approx(abs(g_lin), rel=1e-12)
    assert abs(g_sim) == pytest.approx(abs(g_lin), rel=1e-3)
    assert abs(np.degrees(np.angle(g_sim / g_lin))) < 0.1


def test_pole_map_over_the_travel_moves_the_line_resonance():
    ec = E.EClutch()
    pts = [(x, ec.operating_point(x)) for x in (1e-3, 4e-3, 7e-3)]
    assert pts[0][1].modes["friction_mode_bearing"] == "slip_forward"  # linearised while sliding
    poles = pole_sweep(pts, inputs=["motor_voltage"], outputs=["bearing_position"], name="bearing_position_m")
    # the hydraulic line's resonance (lightly damped, 60-80 Hz) falls as the clutch gets softer
    line = poles[(poles.pole_imag_1_s > 0) & poles.natural_frequency_Hz.between(50, 90)]
    f = line.groupby("bearing_position_m").natural_frequency_Hz.first()
    assert list(f.index) == [1e-3, 4e-3, 7e-3] and f.is_monotonic_decreasing
    # beyond the diaphragm spring's force peak the open-loop actuator is unstable (negative stiffness)
    assert (poles[poles.bearing_position_m == 7e-3].pole_real_1_s > 0).any()
    assert not (poles[poles.bearing_position_m == 1e-3].pole_real_1_s > 0).any()


def test_linear_model_files(tmp_path):
    s = linear_system(np.array([[-1.0, 0.5], [0.0, -2.0]]), np.zeros(2), np.array([[1.0], [2.0]]))
    lin = linearize(operating_point(s, inputs={"u0": 1.0}))
    p = write_linear_model(lin, tmp_path / "lin.json")
    doc = json.loads(p.read_text())
    assert doc["states"] == ["x0_1", "x1_1"] and doc["A"] == [[-1.0, 0.5], [0.0, -2.0]]
    assert doc["operating_point"]["input.u0_1"] == 1.0
    with pytest.raises(Exception, match="exists"):
        write_linear_model(lin, p)
    q = write_linear_model(lin, tmp_path / "lin.csv")
    rows = q.read_text().splitlines()
    assert rows[0] == "matrix,row,column,value" and "A,x0_1,x1_1,0.5" in rows
    with pytest.raises(ParameterError, match="json or .csv"):
        write_linear_model(lin, tmp_path / "lin.txt")


def test_nonlinear_iosystem_agrees_with_python_control_linearize():
    a = np.array([[-1.0, 2.0], [-2.0, -0.5]])
    b = np.array([[0.0], [1.0]])
    s = linear_system(a, np.zeros(2), b)
    nl = nonlinear_iosystem(s, outputs=["x0"])
    assert nl.state_labels == ["x0_1", "x1_1"] and nl.input_labels == ["u0_1"] and nl.output_labels == ["x0_1"]
    lin = nl.linearize([0.0, 0.0], [0.0])
    np.testing.assert_allclose(lin.A, a, atol=1e-6)
    np.testing.assert_allclose(lin.B, b, atol=1e-6)
    # python-control's own simulation of the wrapper follows the closed form of a constant input
    T = np.linspace(0.0, 2.0, 21)
    resp = control.input_output_response(nl, T, np.ones_like(T), X0=[0.0, 0.0], solve_ivp_kwargs={"rtol": 1e-10,
                                                                                                   "atol": 1e-12})
    x_inf = -np.linalg.solve(a, b[:, 0])
    ref = control.forced_response(control.ss(a, b, [[1.0, 0.0]], [[0.0]]), T, np.ones_like(T)).outputs
    np.testing.assert_allclose(np.ravel(resp.outputs), np.ravel(ref), atol=1e-7)
    assert abs(ref[-1] - x_inf[0]) < 0.1  # nearly settled by then
    with pytest.raises(ParameterError, match="algebraic rows"):
        nonlinear_iosystem(linear_system(a, np.zeros(2), b, method="rodas", mass=np.array([1.0, 0.0])))


def _wet_slipping(slip):
    """The wet bench with its slip speed held at ``slip`` [rad/s] by the drive and no force profile, and its
    four temperatures at the start (held in the trims: they are not steady while the pack slips)."""
    from clutchlab.wet.engagement import Scenario
    from clutchlab.wet.system import engagement_system

    sc = Scenario(force_time=[0.0, 1.0], force_value=[0.0, 0.0], speed_time=[0.0, 1.0], speed_value=[slip, slip],
                  duration=5.0, motor="speed", initial_slip_speed=slip)
    s = engagement_system(sc)
    temps = {n: float(s.x0[s.state_index(n)]) for n in ("temperature", "fluid_temperature", "housing_temperature",
                                                        "thermistor_temperature")}
    return s, temps


@pytest.mark.parametrize("slip, torque, tol", [(10.0, 20.0, 0.01), (100.0, 100.0, 0.02)])
def test_wet_clutch_small_signal_step_matches_the_nonlinear_model(slip, torque, tol):
    """The wet pack slipping (the bench's speed controller holds the slip): trim the force for the torque,
    then a 2 N force step of the nonlinear model minus the unperturbed run against the linear model.

    At 10 rad/s and 20 N*m the pack heats by 0.6 K/s: 1 % of the response (measured 0.25 %). At 100 rad/s
    and 100 N*m it heats by 29 K/s: the temperatures are held in the trim, not steady, so the model is a
    linearisation along a drifting trajectory: 2 % (measured 0.9 %).
    """
    s, temps = _wet_slipping(slip)
    op = operating_point(s, states=temps, targets={"clutch_torque": torque}, free_inputs=["force_reference"],
                         inputs={"force_reference": 1500.0}, t=0.5, settle=2.0)
    assert op.modes == {"friction": "slip_positive", "piston": "free", "film": "contact", "piston_run": "settling"}
    assert op.value("clutch_torque") == pytest.approx(torque, rel=1e-8)
    assert op.value("slip_speed") == pytest.approx(slip, rel=1e-8)  # the drive holds the speed
    G = linearize(op, inputs=["force_reference"], outputs=["clutch_torque"])
    assert np.all(G.poles().real < 0)
    T = np.linspace(0.0, 0.15, 151)

    def run(du):
        sim = Simulation(op.start(), rtol=1e-10, t0=op.t)
        k = s.output_index("clutch_torque")
        y = [sim.outputs()[k]]
        for t in T[1:]:
            sim.advance(op.t + t, op.u + np.array([du, 0.0]))
            y.append(sim.outputs()[k])
        return np.array(y)

    d = 2.0
    response = run(d) - run(0.0)  # the temperatures are held in the trim, not steady: subtract their drift
    linear = np.ravel(control.forced_response(G, T, np.full(T.size, d)).outputs)
    assert np.max(np.abs(response - linear)) < tol * abs(linear[-1])


def _sine_gain(op, inp, read, f, amp, *, Ts=5e-5, t_total=0.5, t_fit=0.2):
    """Simulated frequency response at ``f`` [Hz]: the run with a small sine on input ``inp`` (held over
    each ``Ts``) minus the unperturbed run, fitted by a sine, a cosine and a linear drift after ``t_fit``;
    the hold's half-sample delay is taken out."""
    w = 2 * np.pi * f
    n = int(round(t_total / Ts))
    tt = np.arange(1, n + 1) * Ts
    runs = []
    for a in (amp, 0.0):
        sim = Simulation(op.start(), rtol=1e-9, t0=op.t)
        y = np.empty(n)
        for k in range(n):
            u = op.u.copy()
            u[inp] += a * np.sin(w * (tt[k] - Ts))
            sim.advance(op.t + tt[k], u)
            y[k] = read(sim)
        runs.append(y)
    d = runs[0] - runs[1]
    sel = tt > t_fit
    M = np.column_stack([np.sin(w * tt[sel]), np.cos(w * tt[sel]), np.ones(sel.sum()), tt[sel]])
    c = np.linalg.lstsq(M, d[sel], rcond=None)[0]
    return (c[0] + 1j * c[1]) / amp * np.exp(1j * w * Ts / 2)


@pytest.fixture(scope="module")
def emtc_point():
    """The EMTC's AWD vehicle on the drum bench, coupling open, throttle 0.2: all states steady."""
    from clutchlab.emtc.system import bench_system

    s = bench_system(cosimulation=True)
    op = operating_point(s, inputs={"throttle": 0.2}, settle=1.0)
    return op


def test_emtc_operating_point_and_small_signal_step(emtc_point):
    op = emtc_point
    assert op.modes == {"armature_mode": "rest", "coupling_mode": "open", "slip_direction": "positive"}
    dx = __import__("clutchlab.system", fromlist=["evaluate"]).evaluate(op.system, op.t, op.x, op.u, op.m)[0]
    assert np.all(np.abs(dx[:2]) < 1e-9)  # shaft speeds steady: engine and tyres balance on the drums
    G = linearize(op, inputs=["drum_speed_front", "drum_speed_rear"], outputs=["omega_f", "omega_r"])
    assert G.state_labels == ["omega_f_rad_s", "omega_r_rad_s"]  # coil and armature read by nothing while open
    # the evaluation through the contract sees its inputs (the EMTC's cache of the last point keys on them)
    assert abs(G.B[0, 0]) > 1.0
    d = 0.01  # m/s on the front drum
    T = np.linspace(0.0, 0.3, 301)

    def run(du):
        sim = Simulation(op.start(), rtol=1e-10, t0=op.t)
        y = [sim.x[:2].copy()]
        for t in T[1:]:
            u = op.u.copy()
            u[op.system.input_index("drum_speed_front")] += du
            sim.advance(op.t + t, u)
            y.append(sim.x[:2].copy())
        return np.array(y)

    response = run(d) - run(0.0)
    linear = control.forced_response(G, T, np.vstack([np.full(T.size, d), np.zeros(T.size)])).outputs
    for k in range(2):
        assert np.max(np.abs(response[:, k] - linear[k])) < 0.01 * np.abs(linear[k]).max()


@pytest.fixture(scope="module")
def emtc_coil():
    """The EMTC's coil driven at 1.5 A (current drive: the command is the held input), armature in
    contact, the coupling slipping on the drums (speed difference of the bench scenario)."""
    from clutchlab.emtc.system import BenchOptions, bench_system

    s = bench_system(cosimulation=True, options=BenchOptions(coil_drive="current"))
    return operating_point(s, inputs={"throttle": 0.2, "coil_current_command": 1.5}, settle=1.0)


def test_emtc_coil_trimmed_at_a_current(emtc_coil):
    """The coil at a current: both current lags at the command, the armature held at its stop by the contact
    mode (not required steady: frozen), and the magnet force that of the Preisach model driven up to
    1.5 A at the engaged airgap, computed on its own."""
    from clutchlab.emtc.magnet import bundled_magnet

    op = emtc_coil
    assert op.modes == {"armature_mode": "contact", "coupling_mode": "slipping", "slip_direction": "positive"}
    for name in ("i1", "i2", "current_command"):
        assert op.value(name) == pytest.approx(1.5, rel=1e-9)
    assert {"x_armature", "v_armature"} <= set(op.monitors)
    magnet = bundled_magnet()
    magnet.reset()
    gap = op.value("airgap")
    expected = magnet.simulate(np.linspace(0.0, 1.5, 31), np.full(31, gap))[-1]
    assert op.value("magnet_force") == pytest.approx(expected, rel=1e-9)
    assert op.value("coupling_torque") > 50.0
    with pytest.raises(OperatingPointError, match=r"coil_current_command = 6 is outside its physical range"):
        operating_point(op.system, inputs={"throttle": 0.2, "coil_current_command": 6.0})
    with pytest.raises(ParameterError, match="'rising' or 'falling'"):
        linearize(op, inputs=["coil_current_command"], outputs=["coupling_torque"], directions={"i2": "up"})


@pytest.mark.parametrize("direction, sign", [("rising", 1.0), ("falling", -1.0), ("mean", 1.0)])
def test_emtc_coil_command_step_on_each_branch(emtc_coil, direction, sign):
    """Linear model from the coil command to the coupling torque along the magnet's hysteresis branch: a
    small step up follows the rising branch, a step down the falling one (their slopes differ by a factor
    of about 3 at this point), each within 1 % of the step; without a direction the model has the mean
    slope, which neither step follows."""
    op = emtc_coil
    G = linearize(op, inputs=["coil_current_command"], outputs=["coupling_torque"],
                  directions=None if direction == "mean" else {"i2": direction})
    assert G.directions == ({} if direction == "mean" else {"i2": direction})
    assert G.state_labels == ["i1_A", "i2_A"]  # the current lags; the armature held, the speeds unread
    d = sign * 0.01  # A
    T = np.linspace(0.0, 0.1, 101)
    k = op.system.output_index("coupling_torque")
    j = op.system.input_index("coil_current_command")

    def run(du):
        sim = Simulation(op.start(), rtol=1e-10, t0=op.t)  # each start has the point's magnet memory
        y = [sim.outputs()[k]]
        u = op.u.copy()
        u[j] += du
        for t in T[1:]:
            sim.advance(op.t + t, u)
            y.append(sim.outputs()[k])
        return np.array(y)

    response = run(d) - run(0.0)
    linear = np.ravel(control.forced_response(G, T, np.full(T.size, d)).outputs)
    err = np.max(np.abs(response - linear)) / np.abs(response).max()
    if direction == "mean":
        assert err > 0.2  # hysteresis: the mean slope is off for a one-way step
    else:
        assert err < 0.01


@pytest.mark.parametrize("f", [2.0, 20.0, 60.0])
def test_emtc_bode_matches_simulated_sines(emtc_point, f):
    G = linearize(emtc_point, inputs=["drum_speed_front"], outputs=["omega_f"])
    g_sim = _sine_gain(emtc_point, 2, lambda sim: sim.x[0], f, 0.01)
    g_lin = complex(np.squeeze(G(2j * np.pi * f)))
    assert abs(g_sim) == pytest.approx(abs(g_lin), rel=1e-3)
    assert abs(np.degrees(np.angle(g_sim / g_lin))) < 0.1


@pytest.mark.parametrize("f", [2.0, 10.0, 40.0])
def test_wet_bode_matches_simulated_sines(f):
    """The wet pack slipping slowly (10 rad/s, 20 N*m: it heats at about 0.6 K/s, so the point stays put)."""
    s, temps = _wet_slipping(10.0)
    op = operating_point(s, states=temps, targets={"clutch_torque": 20.0}, free_inputs=["force_reference"],
                         inputs={"force_reference": 1500.0}, t=0.5, settle=2.0)
    G = linearize(op, inputs=["force_reference"], outputs=["clutch_torque"])
    k = s.output_index("clutch_torque")
    g_sim = _sine_gain(op, 0, lambda sim: sim.outputs()[k], f, 2.0, t_total=1.0, t_fit=0.5)
    g_lin = complex(np.squeeze(G(2j * np.pi * f)))
    assert abs(g_sim) == pytest.approx(abs(g_lin), rel=1e-2)
    assert abs(np.degrees(np.angle(g_sim / g_lin))) < 0.5


def test_pressure_per_motor_current_is_the_spindle_at_low_frequency(frictionless):
    """Bode of pressure over motor current (voltage-driven actuator): at low frequency the motor stands and
    its torque is all on the spindle, p A_mc = k_t (2 pi / lead) i (efficiency 1 here)."""
    op = frictionless.operating_point(4e-3)
    G = linearize(op, inputs=["motor_voltage"], outputs=["pressure", "motor_current"])
    table = frequency_table(G, [0.01, 1.0, 70.0], over="motor_current_A")
    a = frictionless.actuator
    area = np.pi * a.master_diameter ** 2 / 4
    expected = a.torque_constant * 2 * np.pi / a.lead / area  # Pa per A
    assert table["gain_pressure_Pa__motor_current_A"].iloc[0] == pytest.approx(expected, rel=1e-3)
    # at the line's resonance the pressure at the CSC no longer follows the current
    assert abs(table["gain_dB_pressure_Pa__motor_current_A"].iloc[2]
               - table["gain_dB_pressure_Pa__motor_current_A"].iloc[0]) > 3.0
    with pytest.raises(ParameterError, match="not an output"):
        frequency_table(G, [1.0], over="torque_Nm")


def test_trim_continues_to_a_far_target():
    """From the wet pack's 20 N*m point to 80 N*m with few Newton iterations allowed per solve: the direct
    solve stops, the continuation over the target reaches it, and the point is the one a direct solve with
    many iterations finds."""
    s, temps = _wet_slipping(10.0)
    op20 = operating_point(s, states=temps, targets={"clutch_torque": 20.0}, free_inputs=["force_reference"],
                           inputs={"force_reference": 1500.0}, t=0.5, settle=2.0)
    start = dict(states=temps, targets={"clutch_torque": 80.0}, free_inputs=["force_reference"],
                 inputs={"force_reference": op20.u[0]}, guess=op20.x, modes=op20.modes, t=0.5)
    far = operating_point(s, max_iterations=8, **start)
    assert far.iterations > 8  # the continuation's iterations, summed
    direct = operating_point(s, max_iterations=200, **start)
    assert far.value("clutch_torque") == pytest.approx(80.0, rel=1e-8)
    assert far.u[0] == pytest.approx(direct.u[0], rel=1e-7)
