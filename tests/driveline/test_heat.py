"""Heat ports: thermal masses that the losses of a network's elements heat (issue #31, "design for what comes next").

A thermal mass is MSL's ``HeatCapacitor`` joined to the heat ports of the elements whose losses flow into it
(``useHeatPort = true``: ``heatPort.Q_flow = -lossPower``), with a ``ThermalConductor`` to a ``FixedTemperature``
ambient; ``thermal_conductor`` is a ``ThermalConductor`` between two masses.  Checked against closed forms (a braked
flywheel: a linear loss ramp into a first-order mass; two masses sharing heat), against the heat balance computed
here from the columns (independent of the kernel's own check), on every lossy element kind, and on random networks
(hypothesis): the balance holds, no loss is negative, no mass cools below the coldest of its starts and ambients,
and the mechanical result does not change when masses are added.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from driveline_networks import networks
from hypothesis_budget import examples, pinned

from cli_checks import one_line_error
from clutchlab.cli import main
from clutchlab.driveline import Driveline, Signal
from clutchlab.driveline import kernel as K
from clutchlab.driveline.description import load_driveline, parse_driveline
from clutchlab.driveline.variants import DrivelineDocument
from clutchlab.errors import ParameterError
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "driveline_clutch_heat.toml"

# a flywheel braked by a constant sliding torque: it stops at t_s = w0 J / T_f
J, W0, TF, C, G, TA, T0 = 2.0, 100.0, 4.0, 500.0, 2.0, 25.0, 30.0


def braked(conductance=G, second=None, link=0.0):
    d = Driveline("braked")
    d.inertia("J", J, w0=W0)
    d.brake("B", "J", fn_max=100.0, mu=0.4, cgeo=0.1)   # 100 N x 0.4 x 0.1 = 4 N m
    d.thermal_mass("disc", capacity=C, T0=T0, conductance=conductance, ambient=TA, heat_from=["B"])
    if second is not None:
        d.thermal_mass("housing", capacity=second, T0=T0)
        d.thermal_conductor("link", "disc", "housing", link)
    return d


def closed_form(t):
    """``C dT/dt = P(t) - G (T - T_a)``, ``P = T_f (w0 - T_f t / J)`` until the stop, 0 after."""
    a = G / C
    p0, p1 = TF * W0, -TF * TF / J
    ts = W0 * J / TF
    A, B = (p0 - p1 / a) / (C * a), p1 / (C * a)

    def rising(t):
        return TA + A + B * t + (T0 - TA - A) * np.exp(-a * t)
    return np.where(t <= ts, rising(np.minimum(t, ts)), TA + (rising(ts) - TA) * np.exp(-a * (t - ts)))


@pytest.mark.parametrize("rtol, tol", [(1e-8, 1e-5), (1e-10, 1e-7)])
def test_a_braked_flywheel_heats_its_mass_as_the_closed_form(rtol, tol):
    res = braked().simulate(80.0, rtol=rtol, output_step=0.25)
    df = res.to_dataframe()
    t = df["time_s"].to_numpy()
    T = df["disc.temperature_C"].to_numpy()
    assert np.max(np.abs(T - closed_form(t))) < tol
    # its outputs: the power its brake dissipates into it (T_f w while sliding) and the flow to its ambient
    w = df["J.w_rad_s"].to_numpy()
    sliding = t < W0 * J / TF - 1e-9
    assert np.allclose(df["disc.loss_power_W"].to_numpy()[sliding], TF * w[sliding], rtol=1e-9, atol=1e-9)
    assert np.allclose(df["disc.heat_flow_W"], G * (T - TA), rtol=1e-12, atol=1e-12)
    assert list(res.events.event) == ["stick"]


def test_two_masses_share_the_heat_through_a_conductor():
    """Insulated, joined by a conductor: together they keep the flywheel's kinetic energy (to the integrator's
    rounding: a linear invariant), and after the stop their difference decays at ``G (1/C1 + 1/C2)``."""
    C2, GL = 1500.0, 3.0
    df = braked(conductance=0.0, second=C2, link=GL).simulate(200.0, rtol=1e-10, output_step=0.5).to_dataframe()
    t = df["time_s"].to_numpy()
    T1, T2 = df["disc.temperature_C"].to_numpy(), df["housing.temperature_C"].to_numpy()
    stored = C * (T1 - T0) + C2 * (T2 - T0)
    assert abs(stored[-1] - 0.5 * J * W0 ** 2) < 1e-9 * 0.5 * J * W0 ** 2
    assert np.allclose(stored, df["B.dissipated_J"], rtol=1e-10, atol=1e-8)
    ts = W0 * J / TF
    after = t >= ts + 1.0
    k = GL * (1.0 / C + 1.0 / C2)
    i0 = np.argmax(after)
    want = (T1 - T2)[i0] * np.exp(-k * (t[after] - t[i0]))
    assert np.max(np.abs((T1 - T2)[after] - want)) < 1e-7
    t_eq = T0 + 0.5 * J * W0 ** 2 / (C + C2)   # where both go: the disc from above, the housing from below
    assert abs(T1[-1] - (t_eq + C2 / (C + C2) * want[-1])) < 1e-7
    assert abs(T2[-1] - (t_eq - C / (C + C2) * want[-1])) < 1e-7
    assert np.all(df["disc.heat_out_J"] == 0.0) and np.all(df["disc.heat_flow_W"] == 0.0)   # insulated


def heat_losses_layout(law="msl"):
    """The elements of MSL's ``Rotational.Examples.HeatLosses``, every heat port joined to one node that convects
    to 25 degC (Gc = 20 W/K); a small inertia where MSL joins two elements without one (the lossy gear's flange b
    and the clutch), and the node a thermal mass (MSL's node holds no heat: its capacity here is small)."""
    d = Driveline("heat_losses")
    for i in range(1, 7):
        d.inertia(f"J{i}", 2.0)
    d.inertia("Jg", 0.01)
    d.torque("torque", "J1", Signal.sine(20.0, 5.0))
    d.spring_damper("damper", "ground", "J1", d=10.0)
    d.spring_damper("springDamper", "J1", "J2", c=1e4, d=20.0)
    d.backlash("elastoBacklash", "J2", "J3", c=1e5, b_gap=0.001, d=100.0, damping_law=law)
    d.bearing_friction("bearingFriction", "J3", torque=[[0.0, 1.0], [1.0, 2.0]])
    d.spring_damper("spring3", "J3", "J4", c=1e4)
    d.gear("lossyGear", "J4", "Jg", ratio=2.0, loss_table=[[0.0, 0.8, 0.8, 1.0, 1.0], [1.0, 0.7, 0.7, 2.0, 2.0]])
    normal = Signal.sine(1.0, 0.2)
    d.clutch("clutch", "Jg", "J5", fn_max=10.0, normal=normal)
    d.one_way_clutch("oneWayClutch", "J5", "J6", fn_max=1.0, normal=normal)
    d.brake("brake", "J6", fn_max=2.0, normal=normal)
    lossy = ["damper", "springDamper", "elastoBacklash", "bearingFriction", "spring3", "lossyGear", "clutch",
             "oneWayClutch", "brake"]
    d.thermal_mass("node", capacity=1.0, T0=25.0, conductance=20.0, ambient=25.0, heat_from=lossy)
    return d


@pytest.mark.parametrize("law", ["msl", "kelvin_voigt"])
def test_every_lossy_element_kind_heats_its_mass_with_its_loss(law):
    """The heat the node stores and gives its ambient is the energy every element dissipated (the network's own
    bookkeeping, the sum of the elements' dissipated energies), and the loss power it receives is never
    negative; the kernel's invariant check (its heat balance included) holds at every step."""
    d = heat_losses_layout(law)
    res = d.simulate(1.0, rtol=1e-9, output_step=1e-4, check_invariants=True)
    df = res.to_dataframe()
    lost = df["dissipated_energy_J"].to_numpy()
    heat = 1.0 * (df["node.temperature_C"] - 25.0) + df["node.heat_out_J"]
    assert lost[-1] > 0.3
    (node,) = d.thermal_masses
    for e in node.heat_from:   # every kind contributes (spring3 has no damper)
        assert (df[f"{e}.dissipated_J"].iloc[-1] > 1e-3) == (e != "spring3"), e
    assert np.max(np.abs(heat - lost)) < 1e-7 * lost[-1]
    assert df["node.loss_power_W"].min() > -1e-6 * df["node.loss_power_W"].max()
    # the node follows its loss power: C dT/dt + G (T - 25) = P (the samples' derivative, away from the steps)
    t, T = df["time_s"].to_numpy(), df["node.temperature_C"].to_numpy()
    rate = np.gradient(T, t)
    resid = rate + 20.0 * (T - 25.0) - df["node.loss_power_W"].to_numpy()
    assert np.median(np.abs(resid)) < 1e-3 * df["node.loss_power_W"].abs().max()


def test_adding_thermal_masses_leaves_the_mechanics_as_it_was():
    """The temperatures are outputs of the losses (no friction law reads them): the mechanical columns of the
    launch example with and without its thermal tables agree within the tolerance."""
    doc = tomllib.loads(EXAMPLE.read_text())
    bare = {k: v for k, v in doc.items() if k not in ("thermal_mass", "thermal_conductor")}
    with_heat = parse_driveline(doc, str(EXAMPLE))
    without = parse_driveline(bare, str(EXAMPLE))
    a = with_heat.driveline.simulate(4.0, rtol=1e-10, output_step=5e-3)
    b = without.driveline.simulate(4.0, rtol=1e-10, output_step=5e-3)
    fa, fb = a.to_dataframe(), b.to_dataframe()
    for col in fb.columns:
        if col.endswith("w_rad_s"):
            assert np.max(np.abs(fa[col] - fb[col])) < 1e-6 * np.ptp(fb[col]), col
    assert list(a.events.event) == list(b.events.event)
    assert np.allclose(a.events.time_s, b.events.time_s, atol=1e-8)


def test_the_example_file_keeps_its_heat_balance_and_heats_the_plate(tmp_path):
    out = tmp_path / "heat.csv"
    assert main(["driveline", "simulate", str(EXAMPLE), "-o", str(out)]) == 0
    import pandas as pd

    df = pd.read_csv(out)
    plate, housing = df["plate.temperature_C"].to_numpy(), df["housing.temperature_C"].to_numpy()
    stored = 900.0 * (plate - 40.0) + 5000.0 * (housing - 40.0) + df["housing.heat_out_J"] + df["plate.heat_out_J"]
    assert np.max(np.abs(stored - df["clutch.dissipated_J"])) < 1e-6 * df["clutch.dissipated_J"].iloc[-1]
    assert plate.max() > 80.0 and df["plate.heat_out_J"].abs().max() == 0.0   # (the plate conducts only to the housing)
    # the plate cools after the lock (into the housing, which the air cools)
    lock = float(df["time_s"][df["clutch.mode_1"] == 0].iloc[0])
    after = df["time_s"].to_numpy() > lock + 0.05
    assert np.all(np.diff(plate[after]) < 0.0)


def test_the_thermal_fields_are_sweep_and_fmu_parameters_with_their_units():
    doc = DrivelineDocument.read(EXAMPLE)
    p = doc.parameters
    assert (p["plate.capacity"].unit, p["plate.capacity"].positive, p["plate.capacity"].value) == ("J/K", True, 900.0)
    assert (p["housing.ambient"].unit, p["housing.ambient"].minimum) == ("degC", -273.15)
    assert p["plate_to_housing.conductance"].value == 15.0
    assert "plate.heat_from" not in p
    twice = doc.load({"plate.capacity": 1800.0}).driveline.simulate(2.5, rtol=1e-8, output_step=0.5).to_dataframe()
    once = doc.load({}).driveline.simulate(2.5, rtol=1e-8, output_step=0.5).to_dataframe()
    rise = once["plate.temperature_C"].iloc[-1] - 40.0
    rise2 = twice["plate.temperature_C"].iloc[-1] - 40.0
    assert 0.45 * rise < rise2 < 0.6 * rise
    from clutchlab.sweep.driveline import outputs_of

    outputs = outputs_of(doc.load({}).driveline)
    assert outputs["plate.temperature_max_C"] == "degC" or outputs["plate.temperature_max_C"].endswith("C")


BAD = [
    ({"heat_from": ["nope"]}, r"mem.toml: m: heat_from names 'nope', not an element of 'driveline' \(elements: src, c\)"),
    ({"heat_from": ["src"]}, r"mem.toml: m: heat_from names 'src', a source"),
    ({"capacity": "-1 J/K"}, r"thermal_mass.m.capacity = '-1 J/K'"),
    ({"T0": "-300 degC"}, r"thermal_mass.m.T0 = '-300 degC'"),
    ({"heat_from": "c"}, None),
    ({"heat_from": [1]}, r"thermal_mass.m.heat_from = \[1\]: expected a list of component names"),
]


def _doc(**mass):
    doc = {"inertia": {"J1": {"J": 1.0, "w0": 10.0}, "J2": {"J": 1.0}},
           "torque": {"src": {"flange": "J1", "torque": 1.0}},
           "clutch": {"c": {"a": "J1", "b": "J2", "fn_max": 10.0}},
           "thermal_mass": {"m": dict({"capacity": 10.0}, **mass)}}
    return doc


@pytest.mark.parametrize("fields, message", BAD)
def test_bad_thermal_fields_are_refused_naming_the_file_and_the_field(fields, message):
    if message is None:   # a single name is a list of one
        f = parse_driveline(_doc(**fields), "mem.toml")
        f.driveline.pack()
        return
    with pytest.raises(ParameterError, match=message):
        parse_driveline(_doc(**fields), "mem.toml")


def test_an_element_heats_one_mass_and_a_conductor_joins_known_masses():
    d = Driveline("two")
    d.inertia("J1", 1.0, w0=1.0)
    d.brake("B", "J1", fn_max=1.0)
    d.thermal_mass("m1", 1.0, heat_from=["B"])
    d.thermal_mass("m2", 1.0, heat_from="B")
    with pytest.raises(ParameterError, match="'B', whose losses already heat 'm1'"):
        d.pack()
    d = Driveline("link")
    d.inertia("J1", 1.0)
    d.thermal_mass("m1", 1.0)
    d.thermal_conductor("k", "m1", "m9", 1.0)
    with pytest.raises(ParameterError, match=r"k: b = 'm9' is not a thermal mass of 'link' \(thermal masses: m1\)"):
        d.pack()
    with pytest.raises(ParameterError, match="a and b are both 'm1'"):
        d.thermal_conductor("k2", "m1", "m1", 1.0)
    with pytest.raises(ParameterError, match="component name 'm1' is used twice"):
        d.inertia("m1", 1.0)
    with pytest.raises(ParameterError, match="T0 = -280 degC is not above absolute zero"):
        d.thermal_mass("cold", 1.0, T0=-280.0)


def test_a_wet_clutch_keeps_its_own_thermal_model():
    d = Driveline("wet")
    d.inertia("J1", 1.0, w0=10.0)
    d.inertia("J2", 1.0)
    d.wet_clutch("w", "J1", "J2", force=1000.0)
    d.thermal_mass("m", 10.0, heat_from=["w"])
    with pytest.raises(ParameterError, match="'w', a wet clutch: it carries its own thermal model"):
        d.pack()


def test_a_bad_thermal_file_is_one_line_from_the_command_line(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('[inertia.J1]\nJ = 1\n[thermal_mass.m]\ncapacity = "10 J/K"\nheat_from = ["x"]\n'
                    '[simulation]\nt_end = "1 s"\n')
    line = one_line_error(capsys, ["driveline", "simulate", str(path), "-o", str(tmp_path / "o.csv")])
    assert "bad.toml: m: heat_from names 'x'" in line


def test_the_thermal_states_and_outputs_are_declared_with_their_units():
    d = braked(second=100.0, link=1.0)
    s = d.system()
    names = [(v.name, v.unit) for v in s.states]
    assert ("disc.temperature", "C") in names and ("housing.heat_out", "J") in names
    assert [(v.name, v.unit) for v in s.outputs][-4:] == [("disc.loss_power", "W"), ("disc.heat_flow", "W"),
                                                         ("housing.loss_power", "W"), ("housing.heat_flow", "W")]
    assert "thermal mass disc: C = 500 J/K" in d.describe() and "thermal conductor link: disc - housing" in d.describe()


# ----------------------------------------------------------------- random networks
#: the element kinds that are sources (they dissipate nothing: no heat port)
SOURCES = ("torque", "force", "speed", "position", "speed_torque", "engine")


def _with_masses(d, data):
    """Thermal masses (1-3) over the network's elements that dissipate (not sources), each element heating one
    drawn mass or none, with drawn conductances, ambients and links."""
    nm = data.draw(st.integers(1, 3))
    names = [e.name for e in d.elements if e.kind not in SOURCES + ("wet_clutch", "emtc")]
    owner = {n: data.draw(st.integers(-1, nm - 1)) for n in names}
    for e in d.elements:   # some heated clutches, brakes and one-way clutches fade (the networks are drawn before
        # their masses: the element again with the argument, Driveline.replace)
        if "mu_temperature" in e.arguments and owner.get(e.name, -1) >= 0 and data.draw(st.booleans()):
            lo = data.draw(st.floats(-20.0, 60.0))
            d = d.replace(e.name, mu_temperature=[[lo, data.draw(st.floats(0.0, 1.5))],
                                                  [lo + data.draw(st.floats(1.0, 100.0)),
                                                   data.draw(st.floats(0.0, 1.5))]])
    for k in range(nm):
        d.thermal_mass(f"m{k}", capacity=data.draw(st.floats(0.1, 50.0)), T0=data.draw(st.floats(-20.0, 90.0)),
                       conductance=data.draw(st.sampled_from([0.0, data.draw(st.floats(0.0, 5.0))])),
                       ambient=data.draw(st.floats(-10.0, 40.0)),
                       heat_from=[n for n in names if owner[n] == k])
    for k in range(1, nm):
        if data.draw(st.booleans()):
            d.thermal_conductor(f"l{k}", f"m{k - 1}", f"m{k}", data.draw(st.floats(0.0, 10.0)))
    return d


@settings(max_examples=examples(15), deadline=None, derandomize=pinned())
@given(networks(), st.data())
def test_the_heat_balance_and_its_bounds_hold_on_random_networks(d, data):
    """Whatever the network, its masses and its fading friction elements: the kernel's invariants (its heat balance,
    and a stuck element within its faded limit, included) hold at every step;
    from the columns, the masses store and give away what their elements dissipated, no loss power is negative,
    and no mass falls below the coldest of the starts and ambients (the losses only heat)."""
    d = _with_masses(d, data)
    res = d.simulate(1.0, output_step=2e-3, rtol=1e-9, check_invariants=True)
    df = res.to_dataframe()
    masses = list(d.thermal_masses)
    heat = sum(m.capacity * (df[f"{m.name}.temperature_C"] - m.T0) + df[f"{m.name}.heat_out_J"] for m in masses)
    given = sum(df[f"{n}.dissipated_J"] for m in masses for n in m.heat_from) if any(m.heat_from for m in masses) \
        else 0.0 * heat
    scale = 1.0 + float(np.max(np.abs(given)))
    assert np.max(np.abs(heat - given)) < 1e-7 * scale
    floor = min([m.T0 for m in masses] + [m.ambient for m in masses if m.conductance > 0.0])
    for m in masses:
        assert df[f"{m.name}.loss_power_W"].min() >= -1e-7 * (1.0 + df[f"{m.name}.loss_power_W"].abs().max())
        # (a stuck element's drift power, tau times a relative speed at the rounding floor, may be a hair negative:
        # the balance's tolerance over the mass's capacity)
        assert df[f"{m.name}.temperature_C"].min() >= floor - 1e-9 * (1.0 + abs(floor)) - 1e-7 * scale / m.capacity


def test_a_thermal_mass_linearises_through_the_contract():
    """A load torque (a network input) on the braked flywheel while it slides: the speed integrates it,
    ``1 / (J s)``, and the disc's temperature follows the loss power ``T_f w``: ``T_f / (J s (C s + G))``."""
    import control as ct

    from clutchlab.control import linearize

    d = braked()
    d.input("load", unit="Nm", start=0.0)
    d.torque("load_torque", "J", Signal.input("load"))
    lin = linearize(d.system(1e-10), inputs=["load"], outputs=["J.w", "disc.temperature"])
    assert set(lin.mode.values()) == {"forward"} or set(lin.mode.values()) == {"backward"}, lin.mode
    for s in (0.01j, 0.1j, 10j):
        w = complex(ct.evalfr(lin[0, 0], s))
        temp = complex(ct.evalfr(lin[1, 0], s))
        assert abs(w - 1.0 / (J * s)) < 1e-6 * abs(1.0 / (J * s))
        want = TF / (J * s * (C * s + G))
        assert abs(temp - want) < 1e-6 * abs(want), (s, temp, want)


@pytest.mark.parametrize("rtol", [1e-6, 1e-10])
def test_a_brief_overload_beside_thermal_masses_is_found_as_without_them(rtol):
    """The margin rates of a stuck element near its limit (``kernel._margin_rates``) move a copy of the whole state
    in the work array's scratch: with three masses the network has more states (10) than angles, speeds and one
    per element (6), the scratch's size before the masses came; it holds them all (``kernel.state_bound``), and the
    brake under ``1.0005 sin(2 pi 3 t)`` N m against its 1 N m limit slips and sticks as without them."""
    def dip(masses):
        d = Driveline("dip")
        d.inertia("J", J=1.0, w0=0.0)
        d.brake("b", "J", fn_max=2.0, mu=0.5)
        d.torque("T", "J", Signal.sine(1.0005, 3.0))
        for k in range(masses):
            d.thermal_mass(f"m{k}", 1e-3, heat_from=["b"] if k == 0 else ())
            if k:
                d.thermal_conductor(f"l{k}", f"m{k - 1}", f"m{k}", 1e-3)
        return d
    d = dip(3)
    p = d.pack()
    n, ne, nt = p.inertia.shape[0], p.elem.shape[0], p.thermal.shape[0]
    assert d.initial_state().size == 10 > 2 * n + 2 * ne
    assert K.state_bound(n, ne, nt) >= d.initial_state().size
    got = d.simulate(0.3, output_step=1e-3, rtol=rtol, check_invariants=True)
    want = dip(0).simulate(0.3, output_step=1e-3, rtol=rtol, check_invariants=True)
    assert list(got.events.event) == list(want.events.event) == ["forward", "stick", "backward", "stick"]
    assert np.allclose(got.events.time_s, want.events.time_s, atol=1e-6 if rtol > 1e-8 else 1e-9)
    df = got.to_dataframe()
    heat = sum(1e-3 * (df[f"m{k}.temperature_C"] - 20.0) for k in range(3))
    assert np.max(np.abs(heat - df["b.dissipated_J"])) < 1e-9 + 1e-6 * df["b.dissipated_J"].max()


# ----------------------------------------------------------------- fade: the temperature back into the friction law
def test_a_fading_brake_stops_the_flywheel_as_the_closed_form():
    """Insulated, the disc's temperature follows the kinetic energy whatever the friction, ``T = T0 + J (w0^2 -
    w^2) / (2 C)`` (30 to 50 degC); the fade ``f(T) = 1 - 0.025 (T - 30)`` then makes the braking torque
    ``T_f (0.5 + 5e-5 w^2)``, so ``J dw/dt = -T_f f`` gives ``w(t) = 100 tan(pi/4 - t/100)``: it stops at
    ``25 pi`` s (50 s without the fade)."""
    d = Driveline("fade")
    d.inertia("J", J, w0=W0)
    d.brake("B", "J", fn_max=100.0, mu=0.4, cgeo=0.1, mu_temperature=[[30.0, 1.0], [50.0, 0.5]])
    d.thermal_mass("disc", capacity=C, T0=T0, heat_from=["B"])
    res = d.simulate(90.0, rtol=1e-10, output_step=0.5, check_invariants=True)
    df = res.to_dataframe()
    t, w = df["time_s"].to_numpy(), df["J.w_rad_s"].to_numpy()
    sliding = t < 25 * math.pi
    assert np.max(np.abs(w[sliding] - 100.0 * np.tan(math.pi / 4 - t[sliding] / 100.0))) < 1e-6
    assert list(res.events.event) == ["stick"] and abs(res.events.time_s[0] - 25 * math.pi) < 1e-6
    assert abs(df["disc.temperature_C"].iloc[-1] - 50.0) < 1e-7
    assert np.allclose(df["B.tau_Nm"].abs()[sliding], TF * (0.5 + 5e-5 * w[sliding] ** 2), rtol=1e-7)


def test_a_stuck_brake_breaks_away_where_its_faded_limit_meets_its_load():
    """Brake B1 holds J1 against a 3 N m load (limit 1.2 x 5 N m = 6 N m) while brake B2, slipping at a constant
    10 rad/s under 5 N m, heats their shared mass (10 J/K) at 50 W: T = 20 + 5 t.  B1's fade ``1 - (T - 20)/200``
    brings its limit down to the load at T = 120 degC, t = 20 s: it breaks away there (``forward``), and not before."""
    d = Driveline("fade_limit")
    d.inertia("J1", 1.0)
    d.inertia("J2", 1.0, w0=10.0)
    d.torque("load", "J1", 3.0)
    d.brake("B1", "J1", fn_max=10.0, mu=0.5, peak=1.2, mu_temperature=[[20.0, 1.0], [220.0, 0.0]])
    d.speed("drive", "J2", 10.0)
    d.brake("B2", "J2", fn_max=10.0, mu=0.5)
    d.thermal_mass("pack", capacity=10.0, T0=20.0, heat_from=["B1", "B2"])
    for rtol in (1e-6, 1e-10):
        res = d.simulate(25.0, rtol=rtol, output_step=0.5, check_invariants=True)
        ev = [(t, e) for t, el, e in zip(res.events.time_s, res.events.element, res.events.event) if el == "B1"]
        assert [e for _t, e in ev] == ["forward"], ev
        assert abs(ev[0][0] - 20.0) < 1e-6, (rtol, ev)


def test_the_fade_reaches_linearize():
    """Around the sliding start (w0 = 100 rad/s, T0 = 30 degC, fade ``1.2 - 0.005 T``: 1.05 falling 0.005 per K):
    ``dw/dt = (u - T_f f(T)) / J``, ``C dT/dt = T_f f(T) w - G (T - T_a)``, so from the load u to the speed
    ``(s - a22) / (J (s (s - a22) - a12 a21))`` with ``a12 = -T_f f' / J``, ``a21 = T_f f / C``,
    ``a22 = (T_f f' w0 - G) / C``."""
    import control as ct

    from clutchlab.control import linearize

    d = Driveline("fade_lin")
    d.inertia("J", J, w0=W0)
    d.brake("B", "J", fn_max=100.0, mu=0.4, cgeo=0.1, mu_temperature=[[0.0, 1.2], [100.0, 0.7]])
    d.thermal_mass("disc", capacity=C, T0=T0, conductance=G, ambient=TA, heat_from=["B"])
    d.input("load", unit="Nm", start=0.0)
    d.torque("load_torque", "J", Signal.input("load"))
    lin = linearize(d.system(1e-10), inputs=["load"], outputs=["J.w"])
    f, df = 1.2 - 0.005 * T0, -0.005
    a12, a21, a22 = -TF * df / J, TF * f / C, (TF * df * W0 - G) / C
    for s in (0.01j, 0.1j, 1j):
        want = (s - a22) / (J * (s * (s - a22) - a12 * a21))
        got = complex(ct.evalfr(lin[0, 0], s))
        assert abs(got - want) < 1e-5 * abs(want), (s, got, want)


def test_the_fade_in_a_file_and_its_errors(tmp_path):
    doc = {"inertia": {"J": {"J": J, "w0": W0}},
           "brake": {"B": {"flange": "J", "fn_max": 100.0, "mu": 0.4, "cgeo": 0.1,
                           "mu_temperature": [["30 degC", 1.0], ["50 degC", 0.5]]}},
           "thermal_mass": {"disc": {"capacity": "500 J/K", "T0": "30 degC", "heat_from": ["B"]}}}
    f = parse_driveline(doc, "mem.toml")
    res = f.driveline.simulate(90.0, rtol=1e-10, output_step=1.0)
    assert abs(res.events.time_s[0] - 25 * math.pi) < 1e-6
    bad = dict(doc, thermal_mass={})
    with pytest.raises(ParameterError, match=r"mem.toml: B: mu_temperature reads the temperature of the thermal mass "
                                             r"its losses heat, and none does"):
        parse_driveline(bad, "mem.toml")
    bad = {**doc, "brake": {"B": dict(doc["brake"]["B"], mu_temperature=[[50.0, 1.0], [30.0, 0.5]])}}
    with pytest.raises(ParameterError, match=r"mu_temperature must increase in T"):
        parse_driveline(bad, "mem.toml")
    bad = {**doc, "brake": {"B": dict(doc["brake"]["B"], mu_temperature=[[30.0, 1.0], [50.0, -0.5]])}}
    with pytest.raises(ParameterError, match=r"mem.toml: brake.B.mu_temperature\[1\]\[1\] = -0.5: is below"):
        parse_driveline(bad, "mem.toml")
