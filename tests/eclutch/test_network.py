"""Axial network: closed forms, lever kinematics, energy consistency, bad input."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from clutchlab import Curve
from clutchlab.eclutch.network import GROUND, AxialNetwork, Lever, Node, Spring, solve_static, zero_input
from clutchlab.errors import ParameterError


def linear_model0(k_b=5e6, p_b=1e-4, k_ds=2e5, p_ds=6e-3, i=-4.0, k_fp=8e6, c0=0.6e-3, k_rs=3e4, r0=8e-3):
    lin = Curve.linear
    nodes = (Node("bearing"), Node("tip"), Node("pp", 3.0))
    elements = (
        Spring("bearing", "bearing", lin(k_b), b="tip", prestrain=p_b, unilateral=True),
        Spring("diaphragm", "tip", lin(k_ds), prestrain=p_ds),
        Lever("lever", "tip", "pp", i),
        Spring("cushion", "pp", lin(k_fp), prestrain=c0, unilateral=True),
        Spring("return", "pp", lin(k_rs), prestrain=r0),
    )
    return AxialNetwork(nodes, elements, name="linear Model 0")


def hand_solution(u, k_b=5e6, p_b=1e-4, k_ds=2e5, p_ds=6e-3, i=-4.0, k_fp=8e6, c0=0.6e-3, k_rs=3e4, r0=8e-3):
    """Hand-derived Model 0 with linear springs (see docs/eclutch.md, 'Model 0 closed form').

    With q = x_pp and x_tip = i q, equilibrium of the pressure plate through the rigid lever:
    i [k_b (p_b + u - i q) - k_ds (p_ds + i q)] - k_fp (c0 + q) [contact] - k_rs (r0 + q) = 0.
    """
    def q_of(u, contact):
        kf = k_fp if contact else 0.0
        return (i * k_b * (p_b + u) - i * k_ds * p_ds - kf * c0 - k_rs * r0) / (i * i * (k_b + k_ds) + kf + k_rs)

    q = q_of(u, True)
    open_ = c0 + q <= 0
    q = np.where(open_, q_of(u, False), q)
    fb = k_b * (p_b + u - i * q)
    fn = np.where(open_, 0.0, k_fp * (c0 + q))
    return q, fb, fn


def test_model0_linear_closed_form():
    net = linear_model0()
    u = np.linspace(0.0, 9e-3, 181)
    st = solve_static(net, u)
    q, fb, fn = hand_solution(u)
    names = st["element_names"]
    np.testing.assert_allclose(st["input_force"], fb, rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(st["forces"][:, names.index("cushion")], fn, rtol=1e-9, atol=1e-6)
    x = dict(zip(st["node_names"], st["node_positions"].T))
    np.testing.assert_allclose(x["pp"], q, rtol=1e-9, atol=1e-13)
    # rigid lever kinematics: tip = i_ds * pp
    np.testing.assert_allclose(x["tip"], -4.0 * x["pp"], rtol=1e-12, atol=1e-15)
    assert (fn == 0).any() and (fn > 0).any(), "the path must cross lift-off"


def test_compliant_lever_deflection_and_pivot_reaction():
    k_fl = 7e5
    net = linear_model0()
    lev = Lever("lever", "tip", "pp", -4.0, stiffness=k_fl)
    net1 = net.replace_element("lever", lev)
    st = solve_static(net1, np.linspace(0, 5e-3, 11))
    x = dict(zip(st["node_names"], st["node_positions"].T))
    names = st["element_names"]
    f_lever = st["forces"][:, names.index("lever")]
    # Eq. (1): lever deflection = tip - i_ds * pp (pivot fixed) carries f = k_fl * deflection
    np.testing.assert_allclose(f_lever, k_fl * (x["tip"] + 4.0 * x["pp"]), rtol=1e-9, atol=1e-6)
    # tip equilibrium: bearing force = diaphragm force + lever force
    f = st["forces"]
    np.testing.assert_allclose(st["input_force"], f[:, names.index("diaphragm")] + f_lever, rtol=1e-9, atol=1e-6)


def test_bearing_force_is_the_derivative_of_stored_energy():
    """Static path is conservative: the work of the bearing equals the change of elastic energy."""
    s = np.linspace(-2e-3, 20e-3, 221)
    bell = Curve(s, 4e5 * s * ((9e-3 - s) * (9e-3 - s / 2) + 25e-6) / (81e-6 + 25e-6), kind="pchip")
    c = np.linspace(0, 1e-3, 51)
    cushion = Curve(c, 170 * np.expm1(5000 * c), kind="pchip")
    nodes = (Node("bearing"), Node("tip"), Node("pp", 3.0), Node("support", 0.3))
    elements = (
        Spring("bearing", "bearing", Curve.linear(8e6), b="tip", prestrain=1e-5, unilateral=True),
        Spring("diaphragm", "tip", bell, b="support", prestrain=4.5e-3),
        Lever("lever", "tip", "pp", -4.0, pivot="support", stiffness=1.2e6),
        Spring("cushion", "pp", cushion, prestrain=0.7e-3, unilateral=True),
        Spring("return", "pp", Curve.linear(3e4), prestrain=8e-3),
        Spring("support", GROUND, Curve.linear(3e7), b="support", prestrain=1e-4),
    )
    net = AxialNetwork(nodes, elements)
    u = np.linspace(0.0, 9e-3, 3001)
    st = solve_static(net, u)
    work = np.trapezoid(st["input_force"], u)

    def energy(k):
        total = 0.0
        for j, name in enumerate(st["element_names"]):
            e = net.element(name)
            curve = Curve.linear(e.stiffness) if isinstance(e, Lever) else e.curve
            d0, d1 = st["deflections"][0, j], st["deflections"][k, j]
            grid = np.linspace(d0, d1, 4001)
            f = curve(grid)
            if isinstance(e, Spring) and e.unilateral:
                f = np.maximum(f, 0.0)
            total += np.trapezoid(f, grid)
        return total

    assert work == pytest.approx(energy(-1), rel=2e-5)


def test_zero_input_sets_the_engaged_bearing_force():
    net = zero_input(linear_model0(), "bearing", 80.0)
    assert solve_static(net, [0.0])["input_force"][0] == pytest.approx(80.0, rel=1e-8)


@settings(deadline=None, max_examples=30)
@given(force=st.floats(1.0, 2000.0), k_b=st.floats(1e6, 2e7), p_b=st.floats(-2e-3, 2e-3))
def test_zero_input_root_equals_brents_from_the_bracket(force, k_b, p_b):
    """The zeroing's secant steps (from the spring's own pre-strain) find the pre-strain Brent's method
    finds from the wide bracket, to its tolerance, and the input force is the one asked for; its network is
    the one replace_element gives (the assembly reused, bit for bit)."""
    from scipy.optimize import brentq

    base = linear_model0(k_b=k_b, p_b=p_b)
    net = zero_input(base, "bearing", force)
    p = net.element("bearing").prestrain

    def residual(x):
        return float(solve_static(base._with_prestrain("bearing", x), [0.0])["input_force"][0]) - force

    assert p == pytest.approx(brentq(residual, -0.05, 0.05, xtol=1e-13, rtol=1e-12), abs=3e-13)
    assert solve_static(net, [0.0])["input_force"][0] == pytest.approx(force, rel=1e-8)
    again = base.replace_element("bearing", Spring("bearing", "bearing", base.element("bearing").curve, b="tip",
                                                   prestrain=p, unilateral=True))
    for key in ("GA", "Gb", "d0", "cx", "cf"):
        assert np.array_equal(net._assembly[key], again._assembly[key])


def test_zeroing_secant_hands_a_flat_residual_to_the_bracket():
    """The compiled secant steps give up (NaN) where the input force is flat in the pre-strain (the bearing
    contact open) or a step leaves the interval, and converge to the root of a closed contact (the force
    linear in the pre-strain: the hand solution's root); zero_input then brackets and still finds it."""
    from clutchlab.eclutch.network import _zeroing_root

    base = linear_model0()
    a = base._assembly
    k = a["element_names"].index("bearing")

    def root(x0, lo=-0.05, hi=0.05, force=80.0):
        kernel = list(base.kernel_data())
        kernel[2] = kernel[2].copy()
        return _zeroing_root(x0, x0 + 1e-6, lo, hi, 1e-13, 1e-12, k, a["Gc"][k], a["Gb"], force, np.zeros(1),
                             np.zeros(base.n_free), *kernel)

    assert np.isnan(root(-0.02))  # contact open at both starting points: flat, no root
    assert np.isnan(root(1e-4, lo=-1e-5, hi=1e-5))  # the first step leaves the interval
    p = root(1e-4)
    # hand solution: the bearing force k_b (p_b - i q) at u = 0 with the contact closed equals 80 N
    k_b, k_ds, p_ds, i, k_fp, c0, k_rs, r0 = 5e6, 2e5, 6e-3, -4.0, 8e6, 0.6e-3, 3e4, 8e-3
    q = (i * k_b * p - i * k_ds * p_ds - k_fp * c0 - k_rs * r0) / (i * i * (k_b + k_ds) + k_fp + k_rs)
    assert k_b * (p - i * q) == pytest.approx(80.0, rel=1e-9)
    assert zero_input(base._with_prestrain("bearing", -0.02), "bearing", 80.0).element("bearing").prestrain == \
        pytest.approx(p, abs=1e-12)


@pytest.mark.parametrize(
    "build, match",
    [
        (lambda: Node("m", mass=-1.0), "mass = -1.0"),
        (lambda: Node("ground"), "reserved"),
        (lambda: Lever("l", "a", "b", 2.0), "must be finite and < 0"),
        (lambda: Lever("l", "a", "b", -2.0, stiffness=-5.0), "k_fl"),
        (lambda: Spring("s", "a", Curve.linear(1.0), scale=0.0), "scale"),
        (lambda: Spring("s", "a", [0, 1]), "must be a clutchlab.Curve"),
        (lambda: AxialNetwork((Node("bearing"),), (Spring("s", "nowhere", Curve.linear(1.0)),)), "unknown node 'nowhere'"),
        (lambda: AxialNetwork((Node("bearing"), Node("x")), (Spring("cushion", "bearing", Curve.linear(1.0)),)), "not connected"),
        (lambda: AxialNetwork((Node("bearing"), Node("bearing")), ()), "duplicate node"),
        (lambda: linear_model0().element("clutch"), "no element 'clutch'"),
    ],
)
def test_bad_networks_raise_clear_errors(build, match):
    with pytest.raises(ParameterError, match=match):
        build()


def test_bad_input_positions():
    with pytest.raises(ParameterError, match="finite"):
        solve_static(linear_model0(), [0.0, np.nan])


@pytest.mark.parametrize(
    "build, shown",
    [
        (lambda: Node("m", mass=np.float64(-1.5)), "mass = -1.5 kg"),
        (lambda: Lever("l", "a", "b", np.float64(2.5)), "i_ds = 2.5 must"),
        (lambda: Lever("l", "a", "b", -2.0, stiffness=np.float64(-5.0)), "k_fl = -5.0 N/m"),
        (lambda: Spring("s", "a", Curve.linear(1.0), scale=np.float64(0.0)), "scale = 0.0 must"),
        (lambda: Spring("s", "a", Curve.linear(1.0), gain=np.float32(0.0)), "gain = 0.0 must"),
        (lambda: zero_input(linear_model0(), "bearing", np.float64(-3.0)), "force = -3.0 N"),
        (lambda: zero_input(linear_model0(), "bearing", 80.0, bracket=np.array([0.01, 0.02])),
         "within [0.01, 0.02] m"),
    ],
)
def test_network_errors_show_numpy_scalars_as_plain_numbers(build, shown):
    """NumPy 2 reprs (``np.float64(1.5)``) must not leak into the messages."""
    with pytest.raises(ParameterError) as info:
        build()
    msg = str(info.value)
    assert shown in msg
    assert "np." not in msg and "float64" not in msg and "float32" not in msg


def test_the_zeroing_shortcut_equals_a_rebuilt_network():
    """The zeroing's root search moves one pre-strain without assembling the network again: the shortcut's
    arrays equal those of the network rebuilt with that pre-strain bit for bit (so the zeroed models are
    unchanged), on Model 4 with its lever, pivot and unilateral contacts."""
    import dataclasses

    from clutchlab.eclutch import ClutchModel

    net = ClutchModel.preset(4).network
    for name in ("bearing", "diaphragm"):
        el = net.element(name)
        for p in (-1.3e-3, 0.0, el.prestrain, 2.7e-3):
            fast = net._with_prestrain(name, p)
            slow = net.replace_element(name, dataclasses.replace(el, prestrain=p))
            for a, b in zip(fast.kernel_data(), slow.kernel_data(), strict=True):
                np.testing.assert_array_equal(a, b)
            assert fast.elements == slow.elements
            u = np.array([0.0, 2e-3])
            np.testing.assert_array_equal(solve_static(fast, u)["input_force"], solve_static(slow, u)["input_force"])
    with pytest.raises(ParameterError, match="not a spring"):
        net._with_prestrain("lever", 0.0)
