"""The E-clutch on the system contract: one entry point, one result, named events, equations written once."""

import numpy as np
import pytest

from clutchlab.result import SimulationResult
from clutchlab import system as contract
from clutchlab.eclutch import ClutchDynamics, ClutchModel, EClutch, FrictionParameters, Scenario, simulate
from clutchlab.eclutch.actuator import current_rate, motor_current_derivative, snifting_opening, vent_opening
from clutchlab.eclutch.models import clutch_torque, torque_of_clamp_force
from clutchlab.eclutch.system import EVENTS, MODE_VALUES
from clutchlab.errors import ParameterError
from clutchlab.units import column_unit

PEDAL = {"bearing_reference": ([0.0, 0.1, 0.3, 0.6, 0.8], [0.0, 0.0, 7e-3, 7e-3, 0.0])}


def test_simulate_returns_a_simulation_result_with_units_and_named_events():
    res = simulate(Scenario(t_end=1.0), output_step=1e-3)
    assert isinstance(res, SimulationResult) and res.ok and res.model == "eclutch"
    assert res.time.size == 1001 and res.time[-1] == pytest.approx(1.0)
    frame = res.to_dataframe()
    for col in ("time_s", "bearing_position_m", "pressure_Pa", "motor_current_A", "controller_integral_V",
                "line_flow_m3_s", "bearing_force_N", "torque_Nm", "motor_speed_rpm", "force_cushion_N",
                "friction_pp_N"):
        assert col in frame.columns, col
    for col in res.state_columns + res.output_columns:
        assert column_unit(col) is not None, col  # every column states its unit
    assert set(frame["friction_mode_pp"]) <= set(MODE_VALUES)
    ev = res.events
    assert list(ev.columns) == ["time_s", "event", "element"]
    assert set(ev.event) <= set(EVENTS) and {"breakaway", "stick", "contact_open", "contact_close"} <= set(ev.event)
    assert set(ev[ev.event == "contact_open"].element) == {"cushion"}
    assert {"master", "bearing", "pp", "edge"} <= set(ev[ev.event == "breakaway"].element)
    # the clutch opens during the pedal press and closes again
    assert res["torque_Nm"][500] < 1.0 < res["torque_Nm"][0]


def test_the_table_view_keeps_its_labels_and_holds_the_result():
    dyn = EClutch(friction=FrictionParameters()).simulate(PEDAL, 1.0)
    assert isinstance(dyn.result, SimulationResult)
    assert len(dyn.events) == len(dyn.result.events)
    assert isinstance(dyn, SimulationResult) and dyn.result is dyn
    assert list(dyn.events.columns[:3]) == ["time_s", "event", "element"]   # the run's, then the rig's labels
    assert "contact_open" in set(dyn.events.event) and "contact opens" in set(dyn.events.description)
    assert "pp (R_f.pp)" in set(dyn.events["where"])
    np.testing.assert_array_equal(dyn.outputs_table.torque_Nm.to_numpy(), dyn["torque_Nm"])
    np.testing.assert_array_equal(dyn["bearing_position_m"], dyn.outputs_table.bearing_position_m.to_numpy())


def test_every_step_without_output_step_in_growing_chunks():
    res = simulate(PEDAL, 1.0)
    assert res.time.size == res.stats["accepted_steps"] + 1  # no 500,001-row reservation: what was stepped
    assert np.all(np.diff(res.time) > 0)


def test_same_options_everywhere_and_h_max_is_max_step():
    ec = EClutch()
    a = ec.simulate({"voltage": ([0.0, 0.01], [0.0, 6.0])}, 0.2, max_step=2e-3)
    b = ec.simulate({"voltage": ([0.0, 0.01], [0.0, 6.0])}, 0.2, h_max=2e-3)
    np.testing.assert_array_equal(a.time, b.time)
    assert np.diff(a.time).max() <= 2e-3 * (1 + 1e-9)
    with pytest.raises(ParameterError, match="h_max"):
        ec.simulate({"voltage": 1.0}, 0.1, max_step=1e-3, h_max=2e-3)
    # the uniform entry point with an input mapping: the default E-clutch (Model 4, friction on)
    c = simulate({"voltage": ([0.0, 0.01], [0.0, 6.0])}, 0.2, max_step=2e-3, rtol=1e-3)
    d = EClutch(friction=FrictionParameters()).simulate({"voltage": ([0.0, 0.01], [0.0, 6.0])}, 0.2, max_step=2e-3)
    np.testing.assert_array_equal(c.time, d.time)
    np.testing.assert_array_equal(c["pressure_Pa"], d.outputs_table.pressure_Pa.to_numpy())


def test_registered_model_and_evaluation_through_the_contract():
    system = contract.MODELS["eclutch"]()
    assert system.method == "rodas" and system.mass.min() == 0.0  # massless finger tip: an algebraic row
    dx, g, y = contract.evaluate(system)
    assert np.all(np.isfinite(dx)) and np.all(np.isfinite(g)) and np.all(np.isfinite(y))
    # at rest: no flow, no motion, the clutch's bearing force balances the CSC preload (80 N)
    assert abs(dx[system.state_index("pressure")]) < 1e-6
    assert y[system.output_index("bearing_force_clutch")] == pytest.approx(80.0, abs=1e-6)


def test_cosimulation_session_equals_one_run_at_its_communication_points():
    """A resumed Simulation restarts at each point but integrates the same equations (co-simulation, FMU)."""
    ec = EClutch(friction=FrictionParameters())
    sim = contract.Simulation(ec.as_system({"bearing_reference": 0.0}, held_input=True, rtol=1e-6))
    xs = []
    for k in range(1, 101):
        sim.advance(k * 2e-3, [5e-3 if k > 10 else 0.0])
        xs.append(sim.x[1])
    one = ec.simulate({"bearing_reference": ([0.0, 0.02, 0.02 + 1e-12], [0.0, 0.0, 5e-3])}, 0.2, rtol=1e-6,
                      output_step=2e-3)
    assert np.abs(np.array(xs) - one.outputs_table.bearing_position_m.to_numpy()[1:]).max() < 2e-6
    assert set(sim.events().event) <= set(EVENTS)


def test_batch_is_the_contracts_batch():
    from clutchlab.eclutch.dynamics import simulate_batch

    from clutchlab.eclutch import EClutchParameters

    ecs = [EClutch(clutch=ClutchModel.preset(4, EClutchParameters(lever_ratio=r)), friction=FrictionParameters())
           for r in (-4.2, -3.8)]
    batch = simulate_batch(ecs, PEDAL, 0.4, output_step=2e-3)
    assert isinstance(batch.result, SimulationResult) and batch.result.batch
    assert (batch.stats.jacobians > 0).all() and (batch.stats.events > 0).all()
    assert "variant" in batch.result.events.columns


def test_each_equation_is_one_compiled_function():
    v = np.array([12.0, -3.0, 0.0])
    i = np.array([1.0, 40.0, -2.0])
    w = np.array([0.0, 100.0, -50.0])
    expect = [current_rate(a, b, c, 0.2, 2.5e-4, 0.025) for a, b, c in zip(v, i, w)]
    np.testing.assert_array_equal(motor_current_derivative(v, i, w, 0.2, 2.5e-4, 0.025), expect)
    assert motor_current_derivative(12.0, 1.0, 0.0, 0.2, 2.5e-4, 0.025) == pytest.approx((12.0 - 0.2) / 2.5e-4)
    x = np.linspace(-1e-3, 2e-3, 7)
    np.testing.assert_array_equal(snifting_opening(x, 1e-3, 3e-4), [vent_opening(xx, 1e-3, 3e-4) for xx in x])
    fn = np.array([0.0, 5000.0])
    np.testing.assert_array_equal(clutch_torque(fn, 0.1, 0.3), [torque_of_clamp_force(f, 0.1, 0.3) for f in fn])


def test_prescribed_motion_is_followed_exactly():
    t = np.array([0.0, 0.2, 0.5])
    x = np.array([0.0, 3e-3, 1e-3])
    res = ClutchDynamics(ClutchModel.preset(4)).simulate((t, x), output_step=0.01).result
    np.testing.assert_allclose(res["bearing_position_m"], np.interp(res.time, t, x), atol=1e-15)
    np.testing.assert_allclose(res["prescribed_position_m"], np.interp(res.time, t, x), atol=1e-15)


def test_the_start_derives_the_actuator_s_compliances_and_line_from_the_fields_beside_them():
    """``derive_actuator`` (the packing's and the core's ``start``; a native FMU runs it again after a host set the
    line, the fluid, the hose, a volume, the spindle or the piston's mass) gives the chamber compliances
    ``V / beta + C_hose / 2``, the line's inertance ``rho l / A`` and Hagen-Poiseuille resistance
    ``128 mu l / (pi d^4)``, the snifting edge (port + width), the spindle ratio ``lead / 2 pi`` and the equivalent
    mass ``m + J / n_s^2`` from the fields packed beside them: the closed forms, with parameters far from the
    defaults."""
    import math

    from clutchlab.eclutch import system as S
    from clutchlab.eclutch.actuator import ActuatorParameters

    a = ActuatorParameters(line_diameter=4e-3, line_length=1.5, bulk_modulus=3e8, hose_compliance=4e-13,
                           fluid_density=990.0, fluid_viscosity=0.012, slave_volume=8e-6, snifting_width=4e-4,
                           lead=5e-3, master_mass=0.15, rotor_inertia=2e-5, master_diameter=0.019,
                           spindle_efficiency=0.8)
    par = S._actuator_vector(a)
    expected = {S.P_AMC: math.pi * 0.019 ** 2 / 4, S.P_CM: a.master_volume / 3e8 + 2e-13, S.P_CS: 8e-6 / 3e8 + 2e-13,
                S.P_LH: 990.0 * 1.5 / (math.pi * 4e-3 ** 2 / 4), S.P_RH: 128 * 0.012 * 1.5 / (math.pi * 4e-3 ** 4),
                S.P_XSN: a.snifting_port + 4e-4, S.P_NS: 5e-3 / (2 * math.pi),
                S.P_MMC: 0.15 + 2e-5 / (5e-3 / (2 * math.pi)) ** 2}
    for k, value in expected.items():
        assert par[k] == pytest.approx(value, rel=1e-14), S.ACTUATOR_VECTOR[k]
        par[k] = 0.0
    from clutchlab.eclutch.dynamics import ClutchDynamics, EClutch
    from clutchlab.eclutch.models import ClutchModel

    p = EClutch(a).assembly.params(S.POSITION, np.empty(0), np.empty(0), 0)
    assert np.array_equal(p.par, S._actuator_vector(a))
    coord = p.coord
    mu_pressure = coord[S.CO_MU_PRESSURE, 0]
    for k in expected:   # (erased: the start writes them again)
        p.par[k] = 0.0
    coord[[S.CO_MASS, S.CO_MU_PRESSURE], 0] = 0.0
    others = coord.copy()
    x, m = np.zeros(2 * p.nz + 8), np.zeros(p.nz + 1, dtype=np.int64)
    assert S.eclutch_start(0.0, x, np.zeros(1), m, p) == 0
    for k, value in expected.items():
        assert p.par[k] == pytest.approx(value, rel=1e-14), S.ACTUATOR_VECTOR[k]
    assert coord[S.CO_MASS, 0] == p.par[S.P_MMC]   # (the master's mass)
    # the master seal + spindle's friction per pressure: the spindle's loss per load (1 / eta - 1) times the area,
    # as the packing has it (actuator_friction_elements)
    assert coord[S.CO_MU_PRESSURE, 0] == pytest.approx((1 / 0.8 - 1) * math.pi * 0.019 ** 2 / 4, rel=1e-14)
    assert coord[S.CO_MU_PRESSURE, 0] == mu_pressure
    coord[[S.CO_MASS, S.CO_MU_PRESSURE], 0] = 0.0
    assert np.array_equal(coord, others) and not x.any() and not m.any()   # (a run of its own: its state as given)
    # a bearing moved by a prescribed input: no actuator, no seal friction on the master
    p = ClutchDynamics(ClutchModel.preset(4)).assembly.params(S.PRESCRIBED, np.zeros(1), np.zeros(1), 0)
    assert S.eclutch_start(0.0, np.zeros(2 * p.nz + 8), np.zeros(1), np.zeros(p.nz + 1, dtype=np.int64), p) == 0
    assert p.coord[S.CO_MU_PRESSURE, 0] == 0.0


@pytest.mark.parametrize("number", [0, 1, 2, 3, 4])
def test_a_co_simulation_s_start_derives_the_clutch_as_build_model_does(number):
    """A co-simulation's start (``eclutch_start`` with ``at_start``: a native FMU runs it after a host set the
    parameters) derives the preset's pre-deflections -- the bearing zeroed at its preload, the lever's ``F / k_fl``,
    the pressure-plate spring's and the support's by their curves' inverses, Model 4's bearing zeroed again -- the
    CSC's rest position and the static state and friction modes there, as the Python build does
    (``models.build_model`` on the networks' own assemblies, ``Assembly.rest_position``, ``initial_state``): erased,
    they come back to 1e-15 m.  With parameters away from the defaults, and a CSC preload above the clutch's, so
    the bearing rests released."""
    from clutchlab.eclutch import system as S
    from clutchlab.eclutch.actuator import ActuatorParameters
    from clutchlab.eclutch.dynamics import EClutch, FrictionParameters
    from clutchlab.eclutch.models import ClutchModel, EClutchParameters

    clutch = EClutchParameters(lever_ratio=-3.6, diaphragm_prestrain=4.6e-3, cushion_prestrain=0.75e-3,
                               return_prestrain=7.5e-3, bearing_stiffness=6e6, k_fl_model1=1.4e6, k_fl_model2=1.3e6,
                               support_scale=15.0, diaphragm_scale=1.2, bearing_preload=70.0)
    ec = EClutch(ActuatorParameters(csc_preload=90.0), ClutchModel.preset(number, clutch), FrictionParameters())
    a = ec.assembly
    assert ec.rest_position > 1e-6
    p = a.params(S.POSITION, np.empty(0), np.empty(0), 0, at_start=True)
    x0, m0 = a.initial_state(ec.rest_position)
    names = a.element_names
    derived = [names.index(e) for e in ("bearing", "lever", "pp_spring", "support") if e in names]
    assert len(derived) == {0: 1, 1: 2, 2: 3, 3: 4, 4: 4}[number]
    packed = p.net[S.NE_D0].copy()
    p.net[S.NE_D0, derived] = 0.0
    x, m = np.zeros_like(x0), np.full(a.nz + 1, 7, dtype=np.int64)
    assert S.eclutch_start(0.0, x, np.zeros(1), m, p) == 0
    np.testing.assert_allclose(p.net[S.NE_D0], packed, rtol=0, atol=1e-15)
    assert p.net[S.NE_D0, derived].min() != 0.0 or number == 0
    assert p.clutch[S.CL_REST] == pytest.approx(ec.rest_position, rel=1e-12)
    np.testing.assert_allclose(x[1:a.nz], x0[1:a.nz], rtol=0, atol=1e-15)
    assert np.array_equal(m[:a.nz], m0[:a.nz]) and m[a.nz] == 7   # (the input row is the restart's)
    assert (m[:a.nz] == S.STUCK).sum() >= 2   # (the seals and the clutch's friction start stuck)
    # a run that is not a co-simulation's starts from its packing: the start leaves the clutch and the state alone
    p = a.params(S.POSITION, np.empty(0), np.empty(0), 0)
    p.net[S.NE_D0, derived] = 0.0
    x = np.zeros_like(x0)
    assert S.eclutch_start(0.0, x, np.zeros(1), m, p) == 0
    assert not p.net[S.NE_D0, derived].any() and not x.any()


def test_a_network_of_your_own_derives_no_clutch_at_the_start():
    """A :class:`ClutchModel` around a network that is not the preset's (or without a derivation) packs no
    derivation (number -1): the start keeps its pre-deflections, and still finds the rest state."""
    import dataclasses

    from clutchlab.eclutch import system as S
    from clutchlab.eclutch.dynamics import EClutch
    from clutchlab.eclutch.models import ClutchModel

    preset = ClutchModel.preset(2)
    for model in (dataclasses.replace(preset, derivation=None),
                  dataclasses.replace(preset, network=ClutchModel.preset(2).network)):
        a = EClutch(clutch=model).assembly
        assert a.clutch_int[S.CLI_NUMBER] == -1
        p = a.params(S.POSITION, np.empty(0), np.empty(0), 0, at_start=True)
        packed = p.net.copy()
        x0, m0 = a.initial_state(0.0)
        x, m = np.zeros_like(x0), np.zeros(a.nz + 1, dtype=np.int64)
        assert S.eclutch_start(0.0, x, np.zeros(1), m, p) == 0
        assert np.array_equal(p.net, packed)
        np.testing.assert_allclose(x, x0, rtol=0, atol=1e-15)
        assert np.array_equal(m, np.append(m0[:a.nz], 0))


def test_the_start_refuses_a_clutch_no_run_can_start_from():
    """The start's model errors, each with its message (``ERROR_MESSAGES``): a bearing preload no pre-strain of the
    bearing reaches, a CSC preload with no rest position in the travel."""
    from clutchlab.eclutch import system as S
    from clutchlab.eclutch.dynamics import EClutch

    p = EClutch().assembly.params(S.POSITION, np.empty(0), np.empty(0), 0, at_start=True)
    x, m = np.zeros(2 * p.nz + 8), np.zeros(p.nz + 1, dtype=np.int64)
    for field, value, code in ((S.CL_PRELOAD, 1e5, S.ERR_ZEROING), (None, None, S.ERR_REST)):
        q = EClutch().assembly.params(S.POSITION, np.empty(0), np.empty(0), 0, at_start=True)
        if field is not None:
            q.clutch[field] = value
        else:
            q.par[S.P_FPRE] = 1e4   # (the CSC pushes 10 kN: beyond every force of the clutch within the travel)
        assert S.eclutch_start(0.0, x, np.zeros(1), m, q) == code
        assert S.ERROR_MESSAGES[code]
    assert S.eclutch_start(0.0, x, np.zeros(1), m, p) == 0
