"""The model benches as driveline networks: :func:`drum_bench`, the EMTC paper's AWD vehicle on its drum bench
(Processes 7 (2019) 557, Secs. 3.1 and 4), built from the network's elements and the EMTC coupling
(:meth:`~clutchlab.driveline.Driveline.emtc`), and the tables it tabulates its loads in.
"""

from __future__ import annotations

import numpy as np

from ..emtc.params import BenchScenario, VehicleParameters
from .network import Driveline, Signal

__all__ = ["drum_bench", "engine_curve", "rolling_curve"]


def drum_bench(scenario=None, vehicle=None, *, magnet=None, options=None, name: str = "emtc_awd", into=None,
               prefix: str = "", torque_request=None, throttle=None, coil_current=None):
    """The AWD vehicle with its EMTC on the drum bench of seed 002 (Sec. 4, Eq. 27) as a
    :class:`~clutchlab.driveline.Driveline`: the same equations as :func:`clutchlab.emtc.system.simulate`,
    written as a network.

    Components (SI): ``front_shaft`` and ``rear_shaft`` (the coupling's shafts, ``J_sf``, ``J_sr``),
    ``front_axle`` and ``rear_axle`` (axles and wheels, ``J_wf``, ``J_wr``) joined to them by the gears
    ``front_drive`` and ``rear_drive`` (ratio ``i_r``: the shaft turns ``i_r`` times the wheel, so the
    shafts see ``J_F``, ``J_R`` of Eq. 29); ``engine`` on the front axle (the transmission's output torque
    at the wheels, ``i_g i_0 throttle min(T_max, P / w_e)``, tabulated over the axle speed: exact below the
    power corner, linear between 400 points of the hyperbola above it); the tyres on the drums
    (``tyres_front``, ``tyres_rear``: dampers ``2 C_x r^3 / max(|v_d|, v_floor)`` to the drums
    ``drum_front``, ``drum_rear``, held at ``v_d / r`` by the speed sources ``drum_front_drive``,
    ``drum_rear_drive``), rolling resistance ``f_rr F_z r tanh(w / 0.5 rad/s)`` plus the drum load
    (``rolling_front``, ``rolling_rear``: bearing friction, tabulated, exact above 10 rad/s), and the
    coupling ``emtc`` (:meth:`~clutchlab.driveline.Driveline.emtc`) between the shafts.  Initial speeds:
    free rolling on the drums, as the bench's.  ``scenario``
    (:class:`~clutchlab.emtc.bench.BenchScenario`), ``vehicle``
    (:class:`~clutchlab.emtc.bench.VehicleParameters`), ``magnet`` and ``options`` as
    :func:`clutchlab.emtc.system.simulate`; ``name``: the network's name.  ``into``: a
    :class:`~clutchlab.driveline.Driveline` to add the bench to (several benches, each with its coupling, in one
    network), ``prefix``: put before every component's name (``"front_"``: ``front_emtc``).  ``torque_request``,
    ``throttle`` and ``coil_current``: the coupling's ports (:meth:`~clutchlab.driveline.Driveline.emtc`; a
    :class:`~clutchlab.driveline.Signal` or a number; a network input with ``Signal.input``, declared with
    :meth:`~clutchlab.driveline.Driveline.input`); the throttle port drives the engine too.
    """
    sc = scenario or BenchScenario()
    veh = vehicle or VehicleParameters()
    ic, r = float(veh.rear_final_drive), float(veh.tyre_radius)
    i_tr = float(veh.gear_ratios[sc.gear - 1]) * float(veh.front_final_drive)
    vf, vr = float(sc.drum_speed), float(sc.drum_speed - sc.speed_difference)
    fzf, fzr = veh.axle_loads()
    d = Driveline(name) if into is None else into
    P = prefix
    d.inertia(P + "front_shaft", J=veh.inertia_input_shaft, w0=vf / r * ic)
    d.inertia(P + "rear_shaft", J=veh.inertia_output_shaft, w0=vr / r * ic)
    d.inertia(P + "front_axle", J=veh.inertia_front_axle, w0=vf / r)
    d.inertia(P + "rear_axle", J=veh.inertia_rear_axle, w0=vr / r)
    d.inertia(P + "drum_front", J=1.0, w0=vf / r)
    d.inertia(P + "drum_rear", J=1.0, w0=vr / r)
    d.speed(P + "drum_front_drive", P + "drum_front", vf / r)
    d.speed(P + "drum_rear_drive", P + "drum_rear", vr / r)
    d.gear(P + "front_drive", P + "front_shaft", P + "front_axle", ratio=ic)
    d.gear(P + "rear_drive", P + "rear_shaft", P + "rear_axle", ratio=ic)
    speeds, torques = engine_curve(veh, i_tr)
    ports = dict(torque_request=torque_request, throttle=throttle, coil_current=coil_current)
    d.engine(P + "engine", P + "front_axle", torque_map=np.column_stack([speeds, torques]),
             throttle=throttle if throttle is not None else
             Signal.table([0.0, sc.ramp_start, max(sc.ramp_end, sc.ramp_start + 1e-9)],
                          [sc.throttle_start, sc.throttle_start, sc.throttle_end]))
    for side, v, fz, load in (("front", vf, fzf, sc.drum_load_front), ("rear", vr, fzr, sc.drum_load_rear)):
        k = 2.0 * veh.tyre_slip_stiffness * r / max(abs(v), veh.slip_speed_floor)
        d.spring_damper(f"{P}tyres_{side}", f"{P}{side}_axle", f"{P}drum_{side}", d=k * r * r)
        d.bearing_friction(f"{P}rolling_{side}", f"{P}{side}_axle",
                           torque=rolling_curve(veh.rolling_resistance * fz * r, load))
    d.emtc(P + "emtc", P + "front_shaft", P + "rear_shaft", magnet=magnet, scenario=sc, vehicle=veh, options=options,
           **ports)
    return d


def engine_curve(vehicle, ratio, points: int = 400):
    """Full-load torque at the wheels ``ratio * min(T_max, P / max(w ratio, 1))`` [N m] over the axle speed ``w``
    [rad/s] (the bench's engine, :func:`clutchlab.emtc.system.bench_loads`): flat up to the power corner, then
    ``points`` points of the hyperbola up to 20 times the corner speed (linear between them).

    ``vehicle`` (:class:`~clutchlab.emtc.params.VehicleParameters`) gives ``T_max`` and ``P``; ``ratio`` is the
    gear times the front final drive; returns ``(speeds [rad/s], torques [N m])``."""
    tmax, power = float(vehicle.engine_torque_max), float(vehicle.engine_power)
    corner = max(power / tmax, 1.0) / ratio
    hyper = np.geomspace(corner, 20.0 * corner, points)
    speeds = np.concatenate([[0.0], hyper])
    torques = ratio * np.minimum(tmax, power / np.maximum(speeds * ratio, 1.0))
    return speeds, torques


def rolling_curve(scale, load, width: float = 0.5):
    """Rolling resistance ``scale tanh(w / width) + load`` [N m] as rows ``[w_rad_s, N m]`` (the bench's,
    :func:`clutchlab.emtc.system.bench_loads`): 81 points up to ``4 width``, then to ``40 width``, where the
    tanh is 1 to machine precision."""
    w = np.concatenate([np.linspace(0.0, 4.0 * width, 81), width * np.array([5.0, 6.0, 8.0, 10.0, 20.0, 40.0])])
    return np.column_stack([w, scale * np.tanh(w / width) + load])
