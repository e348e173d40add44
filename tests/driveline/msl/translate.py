"""A clutchlab :class:`~clutchlab.driveline.Driveline` translated into the reference engine (:mod:`.reference`), which
imports nothing of clutchlab: its elements' kinds and arguments (:attr:`~clutchlab.driveline.Driveline.elements`,
SI) called as the engine's builders.  Used by the random-network comparison
(``tests/driveline/test_reference_networks.py``) and by the networks of random draws pinned against the engine."""

from __future__ import annotations

import numpy as np

from clutchlab.driveline import kernel as K

from . import reference as R


def _signal(s, t_end=2.0):
    """A :class:`~clutchlab.driveline.Signal` (or a number) as a reference signal (a pulse's corners listed up to
    ``t_end`` [s]); None for one the reference does not have."""
    if isinstance(s, (int, float)):
        return R.constant(float(s))
    kind, *a = s.row
    if kind == K.SIG_CONST:
        return R.constant(a[0])
    if kind == K.SIG_STEP:
        height, start, offset = a
        return R.step(height, offset, start)
    if kind == K.SIG_RAMP:
        height, duration, start, offset = a
        return R.ramp(height, duration, offset, start)
    if kind == K.SIG_SINE:
        amplitude, f, phase, offset, start = a
        return R.sine(amplitude, f, phase, offset, start, crosses_zero=True)
    if kind == K.SIG_PULSE:
        amplitude, width, period, nperiod, offset, start = a
        return R.pulse(amplitude, width, period, int(nperiod), offset, start, t_end=t_end)
    return None


def _table(v):
    """A number or a characteristic ``[[w, value], ...]`` as the reference takes it; None for a table whose last two
    rows fall (clutchlab holds an extrapolation below zero at zero, the reference's MSL ``LastTwoPoints`` does not:
    only tables that cannot reach it are compared) or one with a negative row."""
    if isinstance(v, (int, float)):
        return float(v)
    rows = np.atleast_2d(np.asarray(v, dtype=float))
    if rows.ndim != 2 or rows.shape[1] != 2 or np.any(rows[:, 1] < 0.0):
        return None
    if len(rows) >= 2 and rows[-1, 1] < rows[-2, 1]:
        return None
    return [list(map(float, r)) for r in rows]


def to_reference(d, strict=True):
    """The network ``d`` as a :class:`reference.Network` (``strict``: :attr:`reference.Network.strict`), its initial
    speeds clutchlab's (the speeds a description leaves out are carried along the gears:
    :meth:`~clutchlab.driveline.Driveline.initial_state`; :func:`kinematics_hold` checks they satisfy every
    constraint); None if it has an element the reference does not know."""
    x0 = d.initial_state()
    names = [i.name for i in d.inertias]
    n = len(names)
    net = R.Network(strict=strict)
    for k, info in enumerate(d.inertias):
        net.inertia(info.name, info.arguments["J"], w0=float(x0[n + k]), phi0=float(x0[k]))
    for e in d.elements:
        a, b, args = e.flange_a, e.flange_b, e.arguments
        if e.kind == "spring_damper":
            net.spring_damper(e.name, a, b, c=args["c"], d=args["d"])
        elif e.kind == "backlash":
            net.backlash(e.name, a, b, c=args["c"], d=args["d"], b_gap=args["b_gap"],
                         law="msl" if args.get("damping_law") == "msl" else "kelvin_voigt")
        elif e.kind == "gear":
            table = args.get("loss_table")
            if table is None and args.get("efficiency", 1.0) != 1.0:
                eta = args["efficiency"]
                table = [[0.0, eta, eta, 0.0, 0.0]]
            net.gear(e.name, a, b, args["ratio"], support=e.support, loss_table=table)
        elif e.kind in ("clutch", "brake"):
            normal = _signal(args["normal"])
            mu = _table(args["mu"])
            if (normal is None or mu is None or args.get("mu_scale", 1.0) != 1.0
                    or args.get("mu_temperature") is not None):
                return None
            net.clutch(e.name, a, b, fn_max=args["fn_max"], normal=normal, mu=mu, peak=args["peak"],
                       cgeo=args["cgeo"])
        elif e.kind == "synchronizer":
            force = _signal(args["force"])
            if force is None or not isinstance(args["mu"], (int, float)):
                return None
            net.synchronizer(e.name, a, b, force, args["cone_radius"], args["dog_capacity"], mu=args["mu"],
                             cone_angle=args["cone_angle"], cones=args["cones"], side=args["side"])
        elif e.kind == "bearing_friction":
            torque = _table(args["torque"])
            if torque is None:
                return None
            net.bearing_friction(e.name, b, tau_pos=torque, peak=args["peak"], support=a)
        elif e.kind == "one_way_clutch":
            normal = _signal(args["normal"])
            if normal is None or not isinstance(args["mu"], (int, float)):
                return None
            net.one_way_clutch(e.name, a, b, fn_max=args["fn_max"], normal=normal, mu=args["mu"],
                               peak=args["peak"], cgeo=args["cgeo"])
        elif e.kind == "torque":
            sig = _signal(args["signal"])
            if sig is None:
                return None
            net.torque(e.name, b, sig, support=None if a == "ground" else a)
        elif e.kind == "torque_converter":
            if args["k_scale"] != 1.0:
                return None
            net.torque_converter(e.name, a, b, args["table"], coast=args["coast_table"], support=e.support)
        elif e.kind == "planetary":
            if args.get("efficiency", 1.0) != 1.0 or args.get("loss_table") is not None:
                return None
            net.planetary(e.name, a, e.support, b, args["ratio"])
        else:
            return None
    return net


def kinematics_hold(net):
    """Every gear's and planetary set's speed constraint at the reference's initial speeds (to 1e-9)."""
    w = np.asarray(net.w0)

    def at(i):
        return 0.0 if i is None else w[i]
    for el in net.elements:
        if el.kind in ("gear", "lossy_gear"):
            r = el.p["ratio"]
            if abs((at(el.a) - at(el.s)) - r * (at(el.b) - at(el.s))) > 1e-9 * (1.0 + np.abs(w).max()):
                return False
        elif el.kind == "planetary":
            r = el.p["ratio"]
            if abs((1.0 + r) * at(el.s) - at(el.a) - r * at(el.b)) > 1e-9 * (1.0 + np.abs(w).max()):
                return False
    return True
