"""Co-simulation wrappers (clutchlab.fmu.cosim) against the native simulations and closed forms.

Tolerances
----------
* EMTC: the co-simulation runs the same system through the same core with
  the same arithmetic sequence (the controller samples are break times in
  both runs; states, step size and both hysteresis memories are carried), so
  a chain of steps whose communication points are controller samples
  reproduces ``simulate_bench`` to the last bit while the plant inputs
  (throttle, drum speeds) are held; 1e-12 relative leaves room for nothing
  but rounding.  A plant input that jumps at a communication point restarts
  the integration there (the contract's ``restart``), which a native run can
  only approximate by a ramp inside a step: such runs agree to the solver
  tolerance.
* Wet clutch: the adaptive DOPRI 5(4) restarts at every communication point
  while the native run steps across, so the two differ by the integration
  error.  They are compared at the solver tolerance level and the difference
  must shrink with ``rtol`` (a model mismatch would not).
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.errors import ParameterError, SimulationError
from clutchlab.fmu import COSIMULATIONS
from clutchlab.fmu.cosim import CoSimulation, Variable, fmi_unit, load_cosimulation
from clutchlab.fmu.emtc import EmtcCoSimulation
from clutchlab.fmu.wet import WetCoSimulation


# ----------------------------------------------------------------- protocol
@pytest.mark.parametrize("cls", [WetCoSimulation, EmtcCoSimulation])
def test_variables_are_named_with_units(cls):
    names = [v.name for g in (cls.inputs, cls.outputs, cls.parameters) for v in g]
    assert len(names) == len(set(names))
    for v in (*cls.inputs, *cls.outputs, *cls.parameters):
        assert isinstance(v, Variable) and v.unit and v.description
        assert "*" not in v.unit and "^" not in v.unit  # Modelica notation
    assert issubclass(cls, CoSimulation) and cls.name in COSIMULATIONS
    assert load_cosimulation(cls.name) is cls


def test_registry_and_variable_checks():
    with pytest.raises(ParameterError, match="unknown"):
        load_cosimulation("dry")
    with pytest.raises(ParameterError, match="not finite"):
        Variable("x", "1", math.nan)
    assert fmi_unit("kg*m^2") == "kg.m2" and fmi_unit("N*m*s/rad") == "N.m.s/rad"


def test_bad_parameters_inputs_and_steps_raise():
    with pytest.raises(ParameterError, match="clutch.nope"):
        WetCoSimulation(**{"clutch.nope": 1.0})
    with pytest.raises(ParameterError, match="expected 0 or 1"):
        WetCoSimulation(**{"scenario.free_inertia": 0.5})
    with pytest.raises(ParameterError, match=r"'clutch\.sigma' = -1\.0 is outside its range \(0, 100\] \[m\]"):
        WetCoSimulation(**{"clutch.sigma": -1.0})
    with pytest.raises(ParameterError, match="whole number"):
        WetCoSimulation(**{"clutch.n_c": 7.5})
    c = WetCoSimulation()
    with pytest.raises(ParameterError, match="unknown input 'force'"):
        c.do_step(0.0, 0.01, {"force": 1.0})
    with pytest.raises(ParameterError, match="force_reference"):
        c.do_step(0.0, 0.01, {"force_reference": 1e9})
    c.do_step(0.0, 0.01, {})
    with pytest.raises(SimulationError, match="contiguous"):
        c.do_step(0.5, 0.01, {})
    with pytest.raises(SimulationError, match="dt"):
        c.do_step(0.01, 0.0, {})
    e = EmtcCoSimulation()
    for dt in (0.0, -0.002, math.nan, math.inf):
        with pytest.raises(SimulationError, match="dt"):
            e.do_step(0.0, dt, {})
    with pytest.raises(SimulationError, match="contiguous"):
        e.do_step(0.001, 0.002, {})
    with pytest.raises(ParameterError, match="throttle"):
        e.do_step(0.0, 0.002, {"throttle": math.nan})
    with pytest.raises(ParameterError, match="gear"):
        EmtcCoSimulation(**{"scenario.gear": 7.0})


# ----------------------------------------------------------------- wet clutch
def _wet_native(cosim, force_time, force_value, speed_time, speed_value, duration, sample_times, rtol, **kw):
    from clutchlab.wet import engagement as E

    v = cosim.parameter_values
    sc = E.Scenario(force_time=force_time, force_value=force_value, speed_time=speed_time, speed_value=speed_value,
                    duration=duration, motor="free" if v["scenario.free_inertia"] else "speed",
                    initial_slip_speed=v["scenario.initial_slip_speed"],
                    initial_temperature_c=v["scenario.initial_temperature"],
                    fluid_temperature_c=v["scenario.fluid_temperature"],
                    housing_temperature_c=v["scenario.housing_temperature"],
                    heater_setpoint_c=v["scenario.heater_setpoint"])
    return E.simulate_engagement(cosim.clutch, sc, bench=cosim.bench, sample_times=sample_times, rtol=rtol, **kw)


def _run(cosim, inputs, dt, n):
    """Chain of steps; ``inputs(k)`` is held over [k dt, (k+1) dt]; outputs at 0, dt, ..., n dt."""
    rows = [cosim.initial_outputs(inputs(0))]
    for k in range(n):
        rows.append(cosim.do_step(k * dt, dt, inputs(k)))
    return {name: np.array([r[name] for r in rows]) for name in rows[0]}


def _engagement(rtol):
    """Inertia-dynamometer engagement (SAE No. 2): constant 3 kN from t = 0, free inertia, lock-up."""
    c = WetCoSimulation(**{"scenario.free_inertia": 1.0, "solver.rtol": rtol})
    dt, n = 0.01, 60
    out = _run(c, lambda k: {"force_reference": 3000.0, "slip_speed_reference": 0.0}, dt, n)
    tk = np.arange(n + 1) * dt
    nat = _wet_native(c, [0.0], [3000.0], [0.0], [0.0], tk[-1], tk, rtol)
    return c, out, nat


@pytest.fixture(scope="module")
def engagements():
    return {rtol: _engagement(rtol) for rtol in (1e-7, 1e-9)}


def test_wet_engagement_matches_native_within_solver_tolerance(engagements):
    c, out, nat = engagements[1e-7]
    tau = nat.output("clutch_torque_Nm")
    scale = np.max(np.abs(tau))
    # measured 4.9e-5 / 1.3e-6 / 3e-7 at rtol 1e-7 (the native run itself is that far from an rtol 1e-11 run)
    assert np.max(np.abs(out["clutch_torque"] - tau)) < 2e-4 * scale
    assert np.max(np.abs(out["slip_speed"] - nat.state("slip_speed_rad_s"))) < 1e-5 * nat.state("slip_speed_rad_s")[0]
    assert np.max(np.abs(out["temperature"] - nat.state("temperature_C"))) < 1e-4
    lock = [e.time for e in c.events if e.kind == "lock-up"]
    assert len(lock) == 1 and abs(lock[0] - nat.lockup_time) < 1e-5
    assert out["stick"][-1] == 1.0 and out["stick"][0] == 0.0
    assert out["slip_speed"][-1] == 0.0


def test_wet_difference_shrinks_with_tolerance(engagements):
    """FMU-vs-native differences are integration error: ten times tighter rtol, several times smaller."""
    diffs = {}
    for rtol, (_, out, nat) in engagements.items():
        diffs[rtol] = (np.max(np.abs(out["clutch_torque"] - nat.output("clutch_torque_Nm"))),
                       np.max(np.abs(out["slip_speed"] - nat.state("slip_speed_rad_s"))))
    assert diffs[1e-9][0] < diffs[1e-7][0] / 4
    assert diffs[1e-9][1] < diffs[1e-7][1] / 4


def test_wet_free_inertia_energy_balance(engagements):
    """No drive torque: the kinetic energy lost equals the friction work, step after step."""
    c, out, _ = engagements[1e-7]
    j = c.bench.total_inertia
    w = out["slip_speed"]
    lost = 0.5 * j * (w[0] ** 2 - w**2)
    assert np.max(np.abs(lost - out["friction_work"])) < 1e-7 * lost[-1]


def test_wet_steps_of_the_force_reference_are_exact():
    """The actuator force is a first-order lag; under zero-order-hold steps its closed form is exact."""
    c = WetCoSimulation(**{"solver.rtol": 1e-9})
    dt, n = 0.005, 40
    levels = np.where(np.arange(n) < 4, 0.0, np.where(np.arange(n) < 20, 1500.0, 600.0))
    out = _run(c, lambda k: {"force_reference": levels[k], "slip_speed_reference": 157.0796326794897}, dt, n)
    tau_a = c.bench.actuator_time_constant
    fa = np.zeros(n + 1)
    for k in range(n):  # exact discretisation of dF/dt = (F_ref - F) / tau_a
        fa[k + 1] = levels[k] + (fa[k] - levels[k]) * math.exp(-dt / tau_a)
    assert np.max(np.abs(out["actuator_force"] - fa)) < 1e-6 * 1500.0


def test_wet_breakaway_at_a_communication_point():
    """Locked clutch, then a step of the slip reference: the motor torque exceeds the capacity at once."""
    c = WetCoSimulation(**{"scenario.initial_slip_speed": 0.0})
    dt = 0.01
    u = {"force_reference": 2000.0, "slip_speed_reference": 0.0}
    _run(c, lambda k: u, dt, 10)
    assert c.mode == 1  # stick
    out = c.do_step(0.1, dt, {"force_reference": 2000.0, "slip_speed_reference": 100.0})
    assert any(e.kind == "break-away" and e.time == pytest.approx(0.1) for e in c.events)
    assert out["slip_speed"] > 0 and out["stick"] == 0.0


def test_wet_parameters_change_the_result_as_the_native_model():
    c = WetCoSimulation(**{"scenario.free_inertia": 1.0, "bench.motor_inertia": 0.04, "clutch.k1": 200.0})
    assert c.bench.motor_inertia == 0.04 and c.clutch.k1 == 200.0
    dt, n = 0.01, 60
    out = _run(c, lambda k: {"force_reference": 3000.0, "slip_speed_reference": 0.0}, dt, n)
    tk = np.arange(n + 1) * dt
    nat = _wet_native(c, [0.0], [3000.0], [0.0], [0.0], tk[-1], tk, 1e-7)
    lock = [e.time for e in c.events if e.kind == "lock-up"]
    assert abs(lock[0] - nat.lockup_time) < 1e-5
    assert lock[0] < 0.4  # half the inertia locks far sooner than the default (0.48 s)
    assert np.max(np.abs(out["temperature"] - nat.state("temperature_C"))) < 1e-4
    assert out["slip_speed"][-1] == 0.0


# ----------------------------------------------------------------- EMTC
def _emtc_inputs(n, dt):
    """Torque-request steps (sampled by the controller) with the throttle held at 0.6 (a plant input)."""
    tk = np.arange(n + 1) * dt
    torque = np.where(tk < 0.2, 0.0, np.where(tk < 0.6, 300.0, 150.0))
    throttle = np.full(tk.size, 0.6)
    return tk, torque, throttle


def _emtc_native(cosim, tk, torque, throttle_step_time, **overrides):
    """``simulate_bench`` with the torque request as a table and one throttle step 0.1 -> 0.6 (None: 0.6 held)."""
    from clutchlab.emtc.bench import BenchScenario, simulate_bench

    # torque request held over [t_k, t_k+1) (the controller samples it at t_k)
    tt, tv = [], []
    for k in range(len(tk) - 1):
        tt += [tk[k], tk[k + 1] - 1e-9]
        tv += [torque[k], torque[k]]
    if throttle_step_time is None:
        sc = BenchScenario(duration=tk[-1], throttle_start=0.6, throttle_end=0.6)
        return simulate_bench(cosim.magnet, sc, vehicle=cosim.vehicle, actuator=cosim.actuator,
                              coupling=cosim.coupling, torque_reference=(tt, tv), **overrides)
    # the native throttle step is a 1 ns ramp that ends 1 ns before the communication point, where the native run
    # restarts at its controller sample with the new throttle as the co-simulation does (a ramp inside a step would
    # be seen by the step control only through its error estimate, less accurately: 7e-3 rad/s on the slip below)
    t_step = throttle_step_time - 2e-9
    sc = BenchScenario(duration=tk[-1], throttle_start=0.1, throttle_end=0.6, ramp_start=t_step, ramp_end=t_step)
    return simulate_bench(cosim.magnet, sc, vehicle=cosim.vehicle, actuator=cosim.actuator, coupling=cosim.coupling,
                          torque_reference=(tt, tv), **overrides)


def _emtc_compare(out, nat, tk, sample_time):
    idx = np.round(tk / sample_time).astype(int)
    o = nat.kernel_outputs
    s = nat.kernel_states
    pairs = {"coupling_torque": o["t_coupling"], "coil_current": s["i2"], "slip_speed": o["slip_speed"],
             "magnet_force": o["magnet_force"], "armature_position": s["x"], "coupling_mode": o["coupling_mode"],
             "current_command": o["current_command"]}
    for name, ref in pairs.items():
        # the command reported at t_k is the one applied over the last sample before t_k (the controller
        # runs at t_k only in the next step, with the next inputs)
        ref = np.asarray(ref, float)[idx - 1 if name == "current_command" else idx]
        np.testing.assert_allclose(out[name][1:], ref[1:], rtol=1e-12, atol=1e-12 * max(np.max(np.abs(ref)), 1e-300),
                                   err_msg=name)


def test_emtc_chain_reproduces_simulate_bench_exactly():
    c = EmtcCoSimulation()
    dt, n = 0.01, 100
    tk, torque, throttle = _emtc_inputs(n, dt)
    out = _run(c, lambda k: {"torque_request": torque[k], "throttle": throttle[k], "drum_speed_front": 8.0,
                             "drum_speed_rear": 7.7}, dt, n)
    nat = _emtc_native(c, tk, torque, None)
    assert c.n_steps == nat.n_steps
    assert len(c.events) == len(nat.events) >= 1
    _emtc_compare(out, nat, tk, c.sample_time)
    # the coupling engages and transfers the requested torque (Eq. 17) while slipping
    assert np.max(out["coupling_mode"]) >= 1
    assert abs(out["coupling_torque"][55] - 300.0) < 0.05 * 300.0


def test_emtc_parameters_change_the_result_as_the_native_model():
    c = EmtcCoSimulation(**{"actuator.tau1": 0.02, "coupling.mu_k[1]": 0.11, "coupling.mu_k[2]": 0.11})
    assert c.actuator.tau1 == 0.02 and c.coupling.mu_k[:2] == (0.11, 0.11)
    dt, n = 0.02, 40
    tk, torque, throttle = _emtc_inputs(n, dt)
    out = _run(c, lambda k: {"torque_request": torque[k], "throttle": throttle[k], "drum_speed_front": 8.0,
                             "drum_speed_rear": 7.7}, dt, n)
    nat = _emtc_native(c, tk, torque, None)
    _emtc_compare(out, nat, tk, c.sample_time)


def test_emtc_input_step_that_unlocks_agrees_within_solver_tolerance():
    """A throttle step that unlocks the coupling at once: the FMU unlocks at the communication point (its
    restart with the new inputs), the native run inside its 1 ns input ramp just before; the step sequences
    then differ, the results only by the integration error (rtol = 1e-6).  At the point itself the FMU reports
    the outputs before its inputs change, the native run just after: that sample is not compared."""
    c = EmtcCoSimulation(**{"actuator.tau1": 0.012})
    dt, n = 0.01, 60
    tk = np.arange(n + 1) * dt
    torque = np.where(tk < 0.2, 0.0, 300.0)
    throttle = np.where(tk < 0.4, 0.1, 0.6)
    out = _run(c, lambda k: {"torque_request": torque[k], "throttle": throttle[k]}, dt, n)
    nat = _emtc_native(c, tk, torque, 0.4)
    unlock = [t for t, name in c.events if name.startswith("unlock")]
    native_unlock = nat.events.time_s[nat.events.description.str.startswith("unlock")].to_numpy()
    assert len(unlock) == len(native_unlock) == 1 and abs(unlock[0] - 0.4) < 1e-9
    assert abs(native_unlock[0] - unlock[0]) < 2e-9
    keep = np.abs(tk - 0.4) > 1e-9
    idx = np.round(tk / c.sample_time).astype(int)
    slip = nat["slip_speed_rad_s"][idx]
    assert np.max(np.abs(out["slip_speed"] - slip)[keep]) < 1e-4 * np.max(np.abs(slip))
    assert np.max(np.abs(out["coupling_torque"] - nat["coupling_torque_Nm"][idx])[keep]) < 1e-4 * 300.0


def _emtc_master(cosim, dt, duration, torque_at, throttle_at):
    """A fixed-step master: steps of ``dt`` (the last one shorter) up to ``duration``; inputs sampled at each
    step start.  Returns the communication points and the outputs there."""
    n = math.ceil(duration / dt - 1e-9)
    tk = np.minimum(np.arange(n + 1) * dt, duration)
    rows = [cosim.initial_outputs({"torque_request": torque_at(0.0), "throttle": throttle_at(0.0)})]
    for k in range(n):
        u = {"torque_request": torque_at(tk[k]), "throttle": throttle_at(tk[k])}
        rows.append(cosim.do_step(tk[k], tk[k + 1] - tk[k], u))
    return tk, {name: np.array([r[name] for r in rows]) for name in rows[0]}


@pytest.mark.parametrize("dt", [0.001, 0.0003, 0.0007])
def test_emtc_accepts_any_communication_step_and_follows_the_native_run(dt):
    """A 1 ms (0.3 ms, 0.7 ms) master with the 2 ms controller: the controller samples at its own instants
    inside and across steps.  Inputs change at t = 0.042 s and 0.084 s (communication points of every master
    and controller samples), so the native run sees the same inputs; only the integration steps, broken at
    the extra communication points, differ.  Tolerances: the DOPRI 5(4) control (rtol 1e-6, atol 1e-5 A on
    the coil currents); the slip speed (a difference of two shaft speeds near 56 rad/s) carries the error of
    the speeds: the native run itself differs from an rtol = 1e-10 run by 0.024 rad/s in this scenario.
    At t = 0.084 s itself the master reports the outputs before the throttle changes, the native run (its
    ramp 1 ns earlier) after: that point is not compared."""
    c = EmtcCoSimulation()
    torque_at = lambda t: 0.0 if t < 0.042 - 1e-9 else 300.0  # noqa: E731
    throttle_at = lambda t: 0.1 if t < 0.084 - 1e-9 else 0.6  # noqa: E731
    tk, out = _emtc_master(c, dt, 0.1, torque_at, throttle_at)
    ts = c.sample_time
    grid = np.arange(round(0.1 / ts) + 1) * ts
    nat = _emtc_native(c, grid, [torque_at(t) for t in grid], 0.084)
    common = np.flatnonzero((np.abs(tk / ts - np.round(tk / ts)) < 1e-6) & (np.abs(tk - 0.084) > 1e-9))[1:]
    assert len(common) >= 7
    idx = np.round(tk[common] / ts).astype(int)
    o, s = nat.kernel_outputs, nat.kernel_states
    np.testing.assert_allclose(out["coupling_torque"][common], o["t_coupling"].to_numpy()[idx], rtol=0, atol=3e-3)
    np.testing.assert_allclose(out["coil_current"][common], s["i2"].to_numpy()[idx], rtol=0, atol=2e-5)
    np.testing.assert_allclose(out["magnet_force"][common], o["magnet_force"].to_numpy()[idx], rtol=0, atol=0.1)
    np.testing.assert_allclose(out["slip_speed"][common], o["slip_speed"].to_numpy()[idx], rtol=0, atol=0.05)
    np.testing.assert_array_equal(out["coupling_mode"][common], o["coupling_mode"].to_numpy()[idx])
    # the command is sampled exactly as natively: the one applied over the last sample before each point
    np.testing.assert_array_equal(out["current_command"][common], o["current_command"].to_numpy()[idx - 1])
    assert [name for _, name in c.events] == list(nat.events.description)
    np.testing.assert_allclose([t for t, _ in c.events], nat.events.time_s, rtol=0, atol=1e-6)
    assert np.max(out["coupling_torque"]) > 250.0  # the coupling did engage


@settings(max_examples=10, deadline=None)
@given(steps=st.lists(st.tuples(st.floats(1e-4, 5e-3), st.floats(0.0, 450.0)), min_size=1, max_size=12))
def test_emtc_controller_samples_at_its_own_instants_for_any_steps(steps):
    """Any sequence of communication steps: the command reported at t + dt is the one the controller
    computed at the last sample instant k ts <= t + dt (held in between) from the torque request of the
    step containing that instant -- the command depends on the sampled requests only (Eqs. 6-7, 11, 13, 15),
    so it must equal that of a 2 ms chain fed with those requests, bit for bit."""
    c = EmtcCoSimulation()
    ts = c.sample_time
    c.initial_outputs({})
    t = 0.0
    bounds = []
    for dt, level in steps:
        out = c.do_step(t, dt, {"torque_request": level})
        bounds.append((t, t + dt, level))
        t += dt
        k_last = math.floor(t / ts + 1e-9)  # last sample instant at or before t
        on_sample = abs(k_last * ts - t) <= 1e-9 * ts
        # the controller ran at samples 0 .. k_last (not at k_last if the step ends on it: next step's input)
        n_run = k_last if on_sample else k_last + 1
        ref = EmtcCoSimulation()
        cmd = ref.initial_outputs({})["current_command"]
        for k in range(n_run):
            sample = k * ts
            level_k = next(lv for t0, t1, lv in bounds if t0 - 1e-9 * ts <= sample < t1 - 1e-9 * ts)
            cmd = ref.do_step(sample, ts, {"torque_request": level_k})["current_command"]
        assert out["current_command"] == cmd


def test_reset_returns_to_the_initial_state():
    c = EmtcCoSimulation()
    u = {"torque_request": 200.0}
    first = [c.do_step(k * 0.01, 0.01, u)["coupling_torque"] for k in range(20)]
    c.reset()
    again = [c.do_step(k * 0.01, 0.01, u)["coupling_torque"] for k in range(20)]
    assert first == again


def test_public_api_is_documented():
    """Every public callable of clutchlab.fmu names each of its arguments in its docstring."""
    import importlib
    import inspect

    for name in ("clutchlab.fmu", "clutchlab.fmu.cosim", "clutchlab.fmu.export", "clutchlab.fmu.eclutch", "clutchlab.fmu.wet",
                 "clutchlab.fmu.emtc", "clutchlab.fmu.driveline"):
        mod = importlib.import_module(name)
        for attr in mod.__all__:
            obj = getattr(mod, attr)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            doc = inspect.getdoc(obj) or ""
            assert doc.strip(), f"{name}.{attr}"
            if inspect.isfunction(obj):
                args = [p for p in inspect.signature(obj).parameters.values()
                        if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
                assert all(p.name in doc for p in args), f"{name}.{attr}"


# ----------------------------------------------------------------- properties
@settings(max_examples=examples(8), deadline=None)
@given(levels=st.lists(st.floats(0.0, 450.0), min_size=2, max_size=4), m=st.integers(2, 5))
def test_emtc_splitting_a_step_changes_nothing(levels, m):
    """Held inputs: one step of m controller samples equals m steps of one sample, bit for bit."""
    coarse = EmtcCoSimulation()
    fine = EmtcCoSimulation()
    ts = coarse.sample_time
    a = b = None
    for k, level in enumerate(levels):
        u = {"torque_request": level}
        a = coarse.do_step(k * m * ts, m * ts, u)
        for j in range(m):
            b = fine.do_step((k * m + j) * ts, ts, u)
    assert a == b
    assert coarse.n_steps == fine.n_steps


@settings(max_examples=examples(8), deadline=None)
@given(levels=st.lists(st.floats(0.0, 5000.0), min_size=3, max_size=6))
def test_wet_dissipation_and_actuator_closed_form(levels):
    """Any held force sequence: friction work never decreases (dissipation >= 0), the actuator force
    follows its exact first-order-lag discretisation, and the torque opposes the slip."""
    c = WetCoSimulation()
    dt = 0.02
    tau_a = c.bench.actuator_time_constant
    f_exact = levels[0]
    prev = c.initial_outputs({"force_reference": levels[0]})
    for k, level in enumerate(levels):
        out = c.do_step(k * dt, dt, {"force_reference": level})
        f_exact = level + (f_exact - level) * math.exp(-dt / tau_a)
        assert out["actuator_force"] == pytest.approx(f_exact, rel=1e-6, abs=1e-6 * 5000.0)
        assert out["friction_work"] >= prev["friction_work"] - 1e-9
        if out["slip_speed"] > 0 and out["stick"] == 0.0:
            assert out["clutch_torque"] > 0.0 and out["contact_torque"] >= 0.0
        prev = out


@pytest.mark.parametrize("model", ["eclutch", "wet", "emtc"])
def test_a_cosimulation_s_absolute_tolerances_follow_its_rtol(model):
    """Below its default ``rtol`` a co-simulation's absolute tolerances shrink with it (issue #30), as the
    model's own runs' do (validated against independent solutions: tests/eclutch/test_dynamics.py,
    tests/emtc/test_accuracy.py, tests/wet).  The E-clutch's and the EMTC's kept their defaults at every rtol
    until the eighteenth session, so their error stopped following the tolerance (and with it their native
    FMUs' in co-simulation)."""
    from clutchlab.fmu.cosim import load_cosimulation

    cls = load_cosimulation(model)
    rtol = next(v for v in cls.parameters if v.name.endswith("rtol"))

    def atol(value):
        sim = cls(**{rtol.name: value})
        sim.hold_inputs({})
        return np.asarray(sim.simulation.options.atol, dtype=float)

    default = atol(float(rtol.start))
    assert np.all(default > 0)
    np.testing.assert_allclose(atol(float(rtol.start) * 1e-4), default * 1e-4, rtol=1e-12)
    np.testing.assert_array_equal(atol(min(1e-2, float(rtol.start) * 10)), default)
