"""Driveline networks shared by several test modules (and by scripts they run in fresh processes)."""

from __future__ import annotations

from clutchlab.driveline import Driveline, Signal


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
