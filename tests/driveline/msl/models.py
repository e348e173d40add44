"""The MSL examples of the suite as reference networks (``reference.Network``), transcribed from the MSL
4.x sources (``Modelica/Mechanics/Rotational/Examples/*.mo``, ``ModelicaTest/Rotational.mo``) with their
own names and parameters.  Independent of the TOML files in this folder (written separately from the same
sources), so a transcription error in either shows as a difference.

Each entry: ``MODELS[name] = (build, t_end, output_step)`` where ``build()`` returns the network.
"""

from __future__ import annotations

import math

from .reference import Network, constant, product, pulse, ramp, sine, step

PI = math.pi


def coupled_clutches():
    """Examples.CoupledClutches."""
    n = Network()
    for i, w0 in ((1, 10.0), (2, 0.0), (3, 0.0), (4, 0.0)):
        n.inertia(f"J{i}", 1.0, w0)
    n.torque("torque", "J1", sine(10.0, 5.0))
    n.clutch("clutch1", "J1", "J2", 20.0, sine(1.0, 0.2, 1.570796326794897, crosses_zero=True), peak=1.1)
    n.clutch("clutch2", "J2", "J3", 20.0, step(1.0, start=0.4), peak=1.1)
    n.clutch("clutch3", "J3", "J4", 20.0, step(1.0, start=0.9), peak=1.1)
    return n


def friction():
    """Examples.Friction: drive 200 sin(100 t) (f = 50/pi) times a step 1 -> 0 at 0.5 s on inertia3
    (J 1, 100 rad/s); clutch fn_max 160 always engaged to inertia2 (J 0.05, 90 rad/s); spring-damper
    (c 160, d 1) to inertia1 (J 1, 90 rad/s), braked (fn_max 1600) from 0.5 s."""
    n = Network()
    n.inertia("inertia3", 1.0, 100.0).inertia("inertia2", 0.05, 90.0).inertia("inertia1", 1.0, 90.0)
    n.torque("torque", "inertia3", product(sine(200.0, 50.0 / PI), step(-1.0, offset=1.0, start=0.5)))
    n.clutch("clutch", "inertia3", "inertia2", 160.0, constant(1.0))
    n.spring_damper("spring", "inertia2", "inertia1", c=160.0, d=1.0)
    n.brake("brake", "inertia1", 1600.0, step(1.0, start=0.5))
    return n


def lossy_gear_demo1():
    """Examples.LossyGearDemo1: 10 sin(2 pi t) on Inertia1 (J 1), LossyGear ratio 2, eta 0.5, support
    fixed, to Inertia2 (J 1.5) with the load ramp -10 -> -5 N m over 2 s."""
    n = Network()
    n.inertia("Inertia1", 1.0).inertia("Inertia2", 1.5)
    n.torque("torque1", "Inertia1", sine(10.0, 1.0))
    n.torque("torque2", "Inertia2", ramp(5.0, 2.0, offset=-10.0))
    n.gear("gear", "Inertia1", "Inertia2", 2.0, loss_table=[[0, 0.5, 0.5, 0, 0]])
    return n


def lossy_gear_demo2():
    """Examples.LossyGearDemo2: LossyGearDemo1 with a BearingFriction (tau_pos [0, 0.5; 1, 1]) between
    the drive and Inertia1."""
    n = lossy_gear_demo1()
    n.bearing_friction("bearingFriction", "Inertia1", tau_pos=[[0.0, 0.5], [1.0, 1.0]])
    return n


def lossy_gear_demo3():
    """Examples.LossyGearDemo3: Inertia1 and Inertia2 (J 0.001, both 10 rad/s) through a LossyGear
    ratio 1, lossTable [0, 0.25, 0.25, 0.625, 2.5]; torque1 = 0, torque2 = step 1 N m at 0.5 s."""
    n = Network()
    n.inertia("Inertia1", 0.001, 10.0).inertia("Inertia2", 0.001, 10.0)
    n.torque("torque1", "Inertia1", step(0.0))
    n.torque("torque2", "Inertia2", step(1.0, start=0.5))
    n.gear("gear", "Inertia1", "Inertia2", 1.0, loss_table=[[0, 0.25, 0.25, 0.625, 2.5]])
    return n


def one_way_clutch(msl_tau0_max_low=False):
    """Examples.OneWayClutch: 10 sin(2 pi 3 t) on inertiaIn (J 1, -0.5 rad/s) = flange a; inertiaOut
    (J 1, 0) = flange b; fn_max 3, peak 25; engaged by a pulse (1, 50 %, period 1.3 s, from 0.3 s)."""
    n = Network()
    n.inertia("inertiaIn", 1.0, -0.5).inertia("inertiaOut", 1.0, 0.0)
    n.torque("torque", "inertiaIn", sine(10.0, 3.0))
    n.one_way_clutch("oneWayClutch", "inertiaIn", "inertiaOut", fn_max=3.0, peak=25.0,
                     normal=pulse(1.0, 0.5, 1.3, start=0.3, t_end=2.0), msl_tau0_max_low=msl_tau0_max_low)
    return n


def one_way_clutch_disengaged(msl_tau0_max_low=False):
    """Examples.OneWayClutchDisengaged: 0.3 + 10 sin(2 pi 2 t) on inertiaIn (J 1, -0.5 rad/s), the load
    -0.3 N m on inertiaOut (J 1, 0); the one-way clutch (fn_max 3, peak 25) never engaged."""
    n = Network()
    n.inertia("inertiaIn", 1.0, -0.5).inertia("inertiaOut", 1.0, 0.0)
    n.torque("torque", "inertiaIn", sine(10.0, 2.0, offset=0.3))
    n.torque("torqueLoad", "inertiaOut", constant(-0.3))
    n.one_way_clutch("oneWayClutch", "inertiaIn", "inertiaOut", fn_max=3.0, peak=25.0, normal=constant(0.0),
                     msl_tau0_max_low=msl_tau0_max_low)
    return n


def test_friction(msl_tau0_max_low=False):
    """ModelicaTest.Rotational.TestFriction, all four rows (every inertia J 1, drive 10 sin(2 pi t))."""
    n = Network()
    for nm in ("inertia", "inertia1", "inertia2", "inertia3", "inertia4", "inertia5"):
        n.inertia(nm, 1.0)
    n.torque("torque", "inertia", sine(10.0, 1.0))
    n.bearing_friction("bearingFriction", "inertia", 1.0)
    n.torque("torque1", "inertia1", sine(10.0, 1.0))
    n.brake("brake", "inertia1", 1.0, step(100.0, start=0.5))
    n.torque("torque2", "inertia2", sine(10.0, 1.0))
    n.clutch("clutch", "inertia2", "inertia3", 1.0, step(100.0, start=0.5))
    n.torque("torque3", "inertia4", sine(10.0, 1.0))
    # oneWayClutch.flange_b is inertia4 (driven), flange_a inertia5
    n.one_way_clutch("oneWayClutch", "inertia5", "inertia4", fn_max=1.0, normal=step(100.0, start=0.5),
                     msl_tau0_max_low=msl_tau0_max_low)
    return n


def test_friction_torque_row():
    """ModelicaTest.Rotational.TestFrictionPosition, its torque row: 0.5 + 25 sin(2 pi t + pi/4) through
    a BearingFriction (tau_pos 5, peak 1.001) on an inertia (J 1) starting at -2 rad/s."""
    n = Network()
    n.inertia("inertia", 1.0, -2.0)
    n.torque("torque", "inertia", sine(25.0, 1.0, 0.78539816339745, offset=0.5))
    n.bearing_friction("bearingFriction1", "inertia", [[0.0, 5.0], [100.0, 5.0]], peak=1.001)
    return n


def first():
    """Examples.First: 10 sin(2 pi 5 t) on inertia1 (J 0.1), IdealGear ratio 10 (support fixed) to
    inertia2 (J 2), spring c 1e4 to inertia3 (J 2), damper d 10 from inertia2 to the ground."""
    n = Network()
    n.inertia("inertia1", 0.1).inertia("inertia2", 2.0).inertia("inertia3", 2.0)
    n.torque("torque", "inertia1", sine(10.0, 5.0))
    n.gear("idealGear", "inertia1", "inertia2", 10.0)
    n.spring_damper("spring", "inertia2", "inertia3", c=1e4)
    n.spring_damper("damper", "inertia2", "ground", d=10.0)
    return n


def simple_drive_train():
    """ModelicaTest.Rotational.ForUsersGuide.SimpleDriveTrain: sin(2 pi t) on J1 (0.2), IdealGear ratio 5
    (support fixed) to J2 (5)."""
    n = Network()
    n.inertia("J1", 0.2).inertia("J2", 5.0)
    n.torque("torque", "J1", sine(1.0, 1.0))
    n.gear("gear", "J1", "J2", 5.0)
    return n


def support_torque1():
    """ModelicaTest.Rotational.ForUsersGuide.SupportTorque1: sin(2 pi t) on inertia3 (J 1), IdealGear
    ratio 1 to inertia4 (J 1) with a BearingFriction (1 N m, support fixed) on that shaft: the drive only
    touches the limit (at 0.25 s), so everything stays at rest."""
    n = Network()
    n.inertia("inertia3", 1.0).inertia("inertia4", 1.0)
    n.torque("torque2", "inertia3", sine(1.0, 1.0))
    n.gear("idealGear2", "inertia3", "inertia4", 1.0)
    n.bearing_friction("bearingFriction1", "inertia4", 1.0)
    return n


def backlash():
    """Examples.Backlash, rows 1 and 2: inertia1 / inertia2 (J 5) starting at pi/2 rad on a spring-damper
    (c 20e3, d 50) / an ElastoBacklash (c 20e3, d 50, b 45 deg) to the ground."""
    n = Network()
    n.inertia("inertia1", 5.0, 0.0, 1.570796326794897).inertia("inertia2", 5.0, 0.0, 1.570796326794897)
    n.spring_damper("springDamper", "ground", "inertia1", c=20e3, d=50.0)
    n.backlash("elastoBacklash", "ground", "inertia2", c=20e3, d=50.0, b_gap=0.7853981633974483)
    return n


def test_bearing_conversion():
    """ModelicaTest.Rotational.TestBearingConversion, its friction and gear rows (row 1 joins massless
    flanges by gears; the rest are sources, Gearbox, IdealGearR2T): nothing drives them, so every inertia stays at rest and every torque is 0."""
    n = Network()
    for nm in ("inertia1", "inertia2", "inertia3", "inertia4", "inertia5", "inertia6", "inertia7"):
        n.inertia(nm, 1.0)
    n.bearing_friction("bearingFriction1", "inertia1", 1.0)
    n.brake("brake", "inertia2", 1.0, sine(1.0, 1.0, crosses_zero=True))
    n.brake("brake1", "inertia3", 1.0, sine(1.0, 1.0, crosses_zero=True))
    n.gear("lossyGear", "inertia4", "inertia5", 1.0, loss_table=[[0, 1, 1, 0, 0]])
    n.gear("lossyGear1", "inertia6", "inertia7", 1.0, loss_table=[[0, 1, 1, 0, 0]])
    return n


def directions():
    """ModelicaTest.Rotational.ForUsersGuide.Directions: three rows of sin(2 pi t) on J1/J3/J5 (0.2) geared
    to J2/J4/J6 (5) by IdealGear ratio 5, 1/5 (J3 on the gear's flange b) and 1/5."""
    n = Network()
    for nm, J in (("J1", 0.2), ("J2", 5.0), ("J3", 0.2), ("J4", 5.0), ("J5", 0.2), ("J6", 5.0)):
        n.inertia(nm, J)
    for src, nm in (("torque", "J1"), ("torque1", "J3"), ("torque2", "J5")):
        n.torque(src, nm, sine(1.0, 1.0))
    n.gear("gear", "J1", "J2", 5.0)
    n.gear("gear1", "J4", "J3", 0.2)
    n.gear("gear2", "J6", "J5", 0.2)
    return n


#: SimpleGearShift's ring flange is massless in MSL; a clutchlab element joins inertias, so the ring has this one
#: (in both runs: the reference solves the same network, and in 1st the held ring does not move)
RING_J = 1e-3


def simple_gear_shift():
    """Examples.SimpleGearShift: a 20 N m step at 0.5 s on the engine (J 1) on the sun of an IdealPlanetary (ratio
    75/50), the load (J 10, QuadraticSpeedDependentTorque -20 N m at 100 rpm) on its carrier; the Brake (cgeo 2,
    fn_max 100) holds the ring with 1 - ramp, the Clutch (cgeo 2, fn_max 100) locks sun and ring with the ramp
    (height 1 from 2 s over 0.1 s); mu 0.5, peak 1 (MSL's defaults)."""
    n = Network()
    n.inertia("engine", 1.0).inertia("ring", RING_J).inertia("load", 10.0)
    n.torque("torqueStep", "engine", step(20.0, 0.0, 0.5))
    n.planetary("idealPlanetary", "engine", "load", "ring", 75.0 / 50.0)
    n.quadratic_torque("quadraticSpeedDependentTorque", "load", -20.0, 10.471975511966)
    n.clutch("clutch", "engine", "ring", 100.0, ramp(1.0, 0.1, 0.0, 2.0), mu=0.5, cgeo=2.0)
    n.brake("brake", "ring", 100.0, ramp(-1.0, 0.1, 1.0, 2.0), mu=0.5, cgeo=2.0)
    return n


MODELS = {
    "coupled_clutches": (coupled_clutches, 1.5, 1e-3),
    "friction": (friction, 3.0, 1e-3),
    "lossy_gear_demo1": (lossy_gear_demo1, 0.5, 1e-3),
    "lossy_gear_demo2": (lossy_gear_demo2, 0.5, 1e-3),
    "lossy_gear_demo3": (lossy_gear_demo3, 1.0, 1e-3),
    "one_way_clutch": (one_way_clutch, 2.0, 1e-3),
    "one_way_clutch_disengaged": (one_way_clutch_disengaged, 2.0, 1e-3),
    "test_friction": (test_friction, 1.1, 1e-3),
    "test_friction_position": (test_friction_torque_row, 1.1, 1e-3),
    "first": (first, 1.0, 1e-3),
    "simple_drive_train": (simple_drive_train, 1.1, 1e-3),
    "support_torque1": (support_torque1, 1.1, 1e-3),
    "directions": (directions, 2.0, 1e-3),
    "backlash": (backlash, 1.0, 1e-3),
    "test_bearing_conversion": (test_bearing_conversion, 0.5, 1e-3),
    "simple_gear_shift": (simple_gear_shift, 5.0, 1e-2),
}
