"""Driveline networks shared by several test modules (and by scripts they run in fresh processes)."""

from __future__ import annotations

from hypothesis import assume
from hypothesis import strategies as st

from clutchlab.driveline import Driveline, Signal
from clutchlab.emtc import FrictionMap
from clutchlab.emtc.system import BenchOptions
from clutchlab.errors import ParameterError


def indeterminate_loop() -> Driveline:
    """The rigid loop of ``test_a_statically_indeterminate_loop_holds_while_any_split_holds``: a one-way clutch (with
    a 0.5 N m clutch), a loss-table gear, a self-locking gear (efficiency 0.25, ratio -3) and a clutch closing it,
    a bearing friction on the first inertia and a 3 N m sine at 1 Hz.  From 0.5766 s seven stuck members on four
    inertias: a null space of three dimensions (``kernel._repair_space``)."""
    d = Driveline("loop")
    for i in range(4):
        d.inertia(f"J{i}", J=1.0, w0=(0.0 if i == 0 else None))
    d.one_way_clutch("f0", "J0", "J1", fn_max=1.0, mu=0.5, peak=1.0, normal=Signal.step(1.0, 0.0))
    d.gear("g1", "J1", "J2", ratio=-1.0, loss_table=[[0.0, 1.0, 0.5, 0.5, 0.0], [20.0, 1.0, 0.5, 0.75, 0.0]])
    d.gear("g2", "J2", "J3", ratio=-3.0, efficiency=0.25)
    d.clutch("loop", "J0", "J3", fn_max=3.0, mu=0.5)
    d.bearing_friction("bearing", "J0", torque=1.0, peak=1.0)
    d.torque("T1", "J1", Signal.sine(3.0, 1.0))
    return d


def gear_loop(gears, extra=(), amp=3.0) -> Driveline:
    """A rigid loop like :func:`indeterminate_loop` with a chain of lossy gears: J0, a one-way clutch (with a 0.5 N m
    clutch) to J1, gear ``k`` (``(ratio, efficiency)``) from J``k`` to J``k+1``, a clutch (1.5 N m) closing the
    loop to J0, a 1 N m bearing friction on J0, ``extra`` bearing frictions ``(i, limit)`` on J``i``, and a sine of
    ``amp`` N m at 1 Hz on J1.  From rest every member is stuck (``kernel._repair_space``): with three or more
    gears the split search covers every combination of their band pieces (``kernel._pieces_margin``)."""
    ng = len(gears)
    d = Driveline("gear_loop")
    for i in range(ng + 2):
        d.inertia(f"J{i}", J=1.0, w0=(0.0 if i == 0 else None))
    d.one_way_clutch("f0", "J0", "J1", fn_max=1.0, mu=0.5, peak=1.0, normal=Signal.step(1.0, 0.0))
    for k, (ratio, eta) in enumerate(gears):
        d.gear(f"g{k + 1}", f"J{k + 1}", f"J{k + 2}", ratio=ratio, efficiency=eta)
    d.clutch("loop", "J0", f"J{ng + 1}", fn_max=3.0, mu=0.5)
    d.bearing_friction("bearing", "J0", torque=1.0, peak=1.0)
    for c, (i, limit) in enumerate(extra):
        d.bearing_friction(f"b{c}", f"J{i}", torque=limit, peak=1.0)
    d.torque("T1", "J1", Signal.sine(amp, 1.0))
    return d


#: two inertias and a Coulomb clutch (30 N m) with two network inputs: a load torque on J2 (through a product with
#: -1) and the clutch's normal signal (tests/driveline/test_inputs.py, tests/fmu/test_driveline_fmu.py)
INPUTS_TOML = """
[driveline]
name = "inputs"

[simulation]
t_end = "1 s"
output_step = "0.1 s"
rtol = 1e-10

[input.load]
start = "2 N m"
description = "load torque on J2"

[input.press]
start = 1.0

[inertia.J1]
J = 1.0
w0 = "10 rad/s"

[inertia.J2]
J = 1.0

[torque.T]
flange = "J2"
torque = { product = [ { input = "load" }, -1 ] }

[clutch.c]
a = "J1"
b = "J2"
fn_max = "100 N"
mu = 0.3
normal = { input = "press" }
"""


# ----------------------------------------------------------------- random networks (test_invariants, test_inputs)
@st.composite
def networks(draw, with_unrelated=False, with_components=False, settled_only=False):
    """A random network: a chain of 2-4 inertias whose links are springs, backlash, gears (ideal, a constant
    efficiency in (0.2, 1], or a loss table with bearing friction), clutches, one-way clutches (plain or with a
    clutch), synchronisers (their sleeves pushed by a sine, a pulse or a constant, or never), torque converters (with
    or without a coast table), planetary sets (the link's inertias the sun and the
    ring, a carrier of its own, sometimes held by a brake that lets go); sometimes a clutch closing a loop from the
    first to the last, a second clutch in parallel with one,
    bearing friction or a brake on an inertia; sine, ramp or step torques; started at rest or with the first
    inertia turning.  ``with_components``: links may also be wet clutches (their force port a ramp, a constant, a
    sine, a pulse or the product of a network input and a ramp) and EMTC couplings (their default scenario and
    controller, or a port: a torque request ramp, a throttle ramp, a coil current step or a network input;
    sometimes with a friction map that fades with temperature and a thermal mass its losses heat, whose temperature
    the map is read at) and E-clutches (seed 000, Model 0-4 static curves under a bearing ramp or sine; sometimes
    worn, wearing and expanding with a thermal mass they heat: their working point shifts during the run), and at
    least one link is one of them.  ``settled_only``: none of the elements whose decisions at zero speed or at
    their limit are the open rounding-floor family of docs/driveline.md (lossy gears, bearing friction, brakes), and
    no synchronisers (their limit jumps with their force's sign)."""
    n = draw(st.integers(2, 4))
    d = Driveline("random")
    w0 = draw(st.sampled_from([0.0, 0.0, 3.0, -2.0]))
    for i in range(n):
        d.inertia(f"J{i}", J=draw(st.floats(0.05, 2.0)), w0=(w0 if i == 0 else None))
    forced = draw(st.integers(0, n - 2)) if with_components else -1
    for i in range(n - 1):
        a, b = f"J{i}", f"J{i + 1}"
        kinds = ["spring", "backlash", "gear", "clutch", "oneway", "owc", "converter", "planetary"] + (
            [] if settled_only else ["lossy", "table", "synchro"])
        if with_components:
            kinds += ["wet", "emtc", "eclutch"]
        kind = draw(st.sampled_from(["wet", "emtc", "eclutch"] if i == forced else kinds))
        if kind == "wet":   # its force port: any signal within [0, 8 kN], or a network input (held at its start)
            top = draw(st.floats(300.0, 3000.0))
            force = draw(st.sampled_from([
                Signal.ramp(top, draw(st.floats(0.05, 0.4)), start=draw(st.floats(0.0, 0.3))),
                Signal.constant(top),
                Signal.sine(0.5 * top, draw(st.floats(1.0, 6.0)), offset=0.5 * top),
                Signal.pulse(top, 0.5, draw(st.floats(0.1, 0.4)), start=draw(st.floats(0.0, 0.2))),
                Signal.product(Signal.input(f"w{i}_force"), Signal.ramp(1.0, 0.2))]))
            if force.input_names():
                d.input(f"w{i}_force", unit="N", start=top)
            d.wet_clutch(f"w{i}", a, b, force=force)
        elif kind == "emtc":   # sometimes through a port: a torque request, a throttle or a current drive
            port = draw(st.sampled_from(["", "torque_request", "throttle", "coil_current", "input"]))
            ports = {"torque_request": {"torque_request": Signal.ramp(draw(st.floats(20.0, 300.0)), 0.3)},
                     "throttle": {"throttle": Signal.ramp(draw(st.floats(0.1, 0.9)), 0.4, offset=0.1)},
                     "coil_current": {"coil_current": Signal.step(draw(st.floats(0.3, 2.0)),
                                                                  draw(st.floats(0.0, 0.3)))},
                     "input": {"torque_request": Signal.input(f"e{i}_request")}, "": {}}[port]
            if port == "input":
                d.input(f"e{i}_request", unit="Nm", start=draw(st.floats(0.0, 200.0)))
            heated = draw(st.booleans())
            options = None
            if heated:   # its friction map fades over 100 K, read at the temperature of the mass it heats
                fade = draw(st.floats(0.5, 1.0))
                options = BenchOptions(friction_map=FrictionMap(
                    [0.0, 5.0, 50.0], [0.0, 150.0], [[0.11, 0.11 * fade], [0.10, 0.10 * fade], [0.09, 0.09 * fade]]))
            d.emtc(f"e{i}", a, b, options=options, **ports)
            if heated:
                d.thermal_mass(f"h{i}", draw(st.floats(5.0, 500.0)), T0=draw(st.floats(20.0, 90.0)),
                               conductance=draw(st.floats(0.0, 5.0)), heat_from=(f"e{i}",))
        elif kind == "eclutch":   # the bearing released (8 mm) to engaged (0), or breathing about a point
            stroke = draw(st.floats(1e-3, 8e-3))
            position = draw(st.sampled_from([
                Signal.ramp(-stroke, draw(st.floats(0.05, 0.4)), start=draw(st.floats(0.0, 0.2)), offset=stroke),
                Signal.sine(0.5 * stroke, draw(st.floats(1.0, 6.0)), offset=draw(st.floats(0.5, 1.0)) * stroke),
                Signal.constant(stroke)]))
            model = draw(st.integers(0, 4))
            shifted = model != 3 and draw(st.booleans())   # (Model 3 lifts off beyond 10 mm once worn)
            if shifted:   # worn, wearing with its friction work and expanding with the mass it heats (Sec. 7, iii)
                d.eclutch(f"x{i}", a, b, position, model=model, points=41, travel=10e-3, wear_max=4e-4,
                          wear=draw(st.floats(0.0, 1e-4)), wear_rate=draw(st.sampled_from([0.0, 1e-9, 5e-8])),
                          expansion=draw(st.sampled_from([0.0, 3.6e-7])))
                d.thermal_mass(f"h{i}", draw(st.floats(50.0, 2000.0)), T0=draw(st.floats(20.0, 80.0)),
                               conductance=draw(st.floats(0.0, 5.0)), heat_from=(f"x{i}",))
            else:
                d.eclutch(f"x{i}", a, b, position, model=model, points=41)
        elif kind == "converter":   # K of 1-10 rad/s/sqrt(N m): 1-100 N m at 10 rad/s; TR 1-2.5 at stall
            k0, tr0 = draw(st.floats(1.0, 10.0)), draw(st.floats(1.0, 2.5))
            table = [[0.0, k0, tr0], [0.5, 1.2 * k0, 0.5 * (1.0 + tr0)], [0.9, 3.0 * k0, 1.0]]
            coast = [[0.0, 1.1 * k0], [0.9, 3.0 * k0]] if draw(st.booleans()) else None
            d.torque_converter(f"v{i}", a, b, table, coast_table=coast)
        elif kind == "planetary":   # sun a, ring b, the carrier an inertia of its own (at rest at the start)
            d.inertia(f"P{i}", J=draw(st.floats(0.05, 1.0)))
            d.planetary(f"s{i}", a, f"P{i}", b, ratio=draw(st.floats(1.2, 4.0)),
                        efficiency=draw(st.sampled_from([1.0, 1.0, 0.95])) if not settled_only else 1.0)
            if not settled_only and draw(st.booleans()):   # the carrier held by a brake, released later
                d.brake(f"pb{i}", f"P{i}", fn_max=draw(st.floats(1.0, 40.0)), mu=0.5,
                        normal=Signal.ramp(-1.0, 0.2, start=draw(st.floats(0.1, 0.6)), offset=1.0))
        elif kind == "spring":
            d.spring_damper(f"k{i}", a, b, c=draw(st.floats(1.0, 200.0)), d=draw(st.floats(0.0, 2.0)))
        elif kind == "backlash":
            d.backlash(f"k{i}", a, b, c=draw(st.floats(10.0, 500.0)), b_gap=draw(st.floats(0.01, 0.3)),
                       d=draw(st.floats(0.0, 2.0)))
        elif kind in ("gear", "lossy", "table"):
            ratio = draw(st.floats(0.3, 4.0)) * draw(st.sampled_from([-1.0, 1.0]))
            if kind == "gear":
                d.gear(f"g{i}", a, b, ratio=ratio)
            elif kind == "lossy":
                d.gear(f"g{i}", a, b, ratio=ratio, efficiency=draw(st.floats(0.2, 1.0)))
            else:
                e1, e2 = draw(st.floats(0.3, 1.0)), draw(st.floats(0.3, 0.999))
                bf1, bf2 = draw(st.floats(0.0, 2.0)), draw(st.floats(0.0, 2.0))   # (e2 < 1: a split of bf exists)
                d.gear(f"g{i}", a, b, ratio=ratio, loss_table=[[0.0, e1, e2, bf1, bf2],
                                                               [20.0, min(1.0, e1 + 0.05), e2, bf1 * 1.5, bf2]])
        elif kind == "clutch":
            d.clutch(f"c{i}", a, b, fn_max=draw(st.floats(0.0, 60.0)), mu=0.5, peak=draw(st.floats(1.0, 1.5)),
                     normal=draw(st.sampled_from([1.0, Signal.ramp(1.0, 0.3, start=0.1),
                                                  Signal.sine(1.0, 2.0, phase=1.0)])))
        elif kind == "synchro":   # its sleeve pushed (a sine's positive half-waves, a pulse, held) or never
            force = draw(st.sampled_from([Signal.sine(draw(st.floats(50.0, 400.0)), draw(st.floats(0.5, 4.0))),
                                          Signal.pulse(draw(st.floats(50.0, 400.0)), 0.5, draw(st.floats(0.2, 0.6)),
                                                       start=draw(st.floats(0.0, 0.2))),
                                          Signal.constant(draw(st.floats(50.0, 400.0))), Signal.constant(0.0)]))
            d.synchronizer(f"y{i}", a, b, force, cone_radius=draw(st.floats(0.02, 0.06)),
                           dog_capacity=draw(st.floats(2.0, 80.0)), mu=draw(st.floats(0.05, 0.11)),
                           cones=draw(st.integers(1, 3)))
        elif kind == "oneway":
            d.one_way_clutch(f"f{i}", a, b)
        else:
            d.one_way_clutch(f"f{i}", a, b, fn_max=draw(st.floats(1.0, 20.0)), mu=0.5, peak=draw(st.floats(1.0, 2.0)),
                             normal=Signal.step(1.0, draw(st.floats(0.0, 0.5))))
    if n >= 3 and draw(st.booleans()):
        d.clutch("loop", "J0", f"J{n - 1}", fn_max=draw(st.floats(1.0, 40.0)), mu=0.5)
    if not settled_only and draw(st.booleans()):
        j = draw(st.integers(0, n - 1))
        d.bearing_friction("bearing", f"J{j}", torque=draw(st.floats(0.1, 3.0)), peak=draw(st.floats(1.0, 1.3)))
    if not settled_only and draw(st.booleans()):
        j = draw(st.integers(0, n - 1))
        d.brake("brake", f"J{j}", fn_max=draw(st.floats(1.0, 30.0)), mu=0.4,
                normal=Signal.step(1.0, draw(st.floats(0.1, 0.6))))
    for i in range(n):
        if draw(st.booleans()):
            amp = draw(st.floats(-30.0, 30.0))
            sig = draw(st.sampled_from(["sine", "ramp", "step"]))
            s = (Signal.sine(amp, draw(st.floats(0.3, 5.0))) if sig == "sine" else
                 Signal.ramp(amp, draw(st.floats(0.1, 1.0))) if sig == "ramp" else Signal.step(amp, draw(
                     st.floats(0.0, 0.5))))
            d.torque(f"T{i}", f"J{i}", s)
    if with_unrelated:
        d.inertia("U", J=draw(st.floats(0.1, 2.0)), w0=draw(st.floats(-5.0, 5.0)))
        d.brake("Ubrake", "U", fn_max=draw(st.floats(1.0, 30.0)), mu=0.5)
        d.torque("UT", "U", Signal.sine(draw(st.floats(0.0, 40.0)), draw(st.floats(0.5, 7.0))))
    try:
        d.system()
    except ParameterError as exc:     # a one-way clutch started with b slower than a
        assume("one-way" not in str(exc))
        raise
    return d
