"""Parameter sets of the AWD vehicle on the EMTC drum bench ([1], Secs. 3.1 and 4) and the controller's
torque reference map (Eq. 31): frozen, unit-annotated, TOML load/save.

:mod:`clutchlab.emtc.system` packs them for the integrator core; :mod:`clutchlab.emtc.bench` runs them
(:func:`~clutchlab.emtc.bench.simulate_bench`) and re-exports them.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

import dataclasses

import numba
import numpy as np

from ..errors import ParameterError
from ..params import ParameterSet, quantity
from ..system import start_checks_deferred
from ._lookup import bilinear
from .friction import drag_torque

__all__ = ["ActuatorParameters", "VehicleParameters", "BenchScenario", "TorqueMap", "static_axle_load", "GRAVITY"]

#: standard gravity [m/s^2]
GRAVITY = 9.80665
#: how far the lever arms' sum may differ from the wheel base [m] (``VehicleParameters.check`` and the EMTC
#: model's start, ``clutchlab.emtc.system.derive_vehicle``)
GEOMETRY_TOLERANCE = 1e-3


@numba.njit(cache=True, nogil=True)
def static_axle_load(mass, cg_to_other_axle, wheelbase):
    """Static load of one axle [N]: the vehicle's weight ``mass`` [kg] times ``g`` shared by the lever arms,
    ``F_z = m g l_other / L`` ([1], Table 1: the centre of mass ``cg_to_other_axle`` [m] from the *other* axle,
    wheel base ``wheelbase`` [m]); the front axle's with ``l_r``, the rear's with ``l_f``.  Level ground, at rest
    (no load transfer)."""
    return mass * GRAVITY * cg_to_other_axle / wheelbase


@dataclasses.dataclass(frozen=True)
class ActuatorParameters(ParameterSet):
    """Electromagnetic actuator: armature, return spring and coil current control ([1], Eqs. 8-12, Fig. 15).

    Values are representative (clutchlab's choice; the paper gives none).
    """

    kind = "actuator"

    mass: float = quantity(0.15, "kg", "armature mass m0 (Eq. 8)", source="representative", positive=True)
    stiffness: float = quantity(4.0e4, "N/m", "return spring stiffness K_spring (Eq. 9)", source="representative", positive=True)
    preload: float = quantity(50.0, "N", "spring preload F_k0 (Eq. 9)", source="representative", nonnegative=True)
    damping: float = quantity(100.0, "N*s/m", "spring damping c_spring (Eq. 8)", source="representative", nonnegative=True)
    free_travel: float = quantity(0.5e-3, "m", "free travel sigma of the primary clutch (Eq. 9)", source="representative", positive=True)
    airgap_open: float = quantity(1.2e-3, "m", "airgap d at x = 0 (Eq. 12)", source="representative", positive=True)
    tau1: float = quantity(0.010, "s", "first current-control lag tau1 (Fig. 15)", source="representative", positive=True)
    tau2: float = quantity(0.004, "s", "second current-control lag tau2 (Fig. 15)", source="representative", positive=True)

    def check(self) -> None:
        # (a check across parameters that every run's start makes again: deferred to it in a native FMU's trial
        # builds, :func:`clutchlab.system.start_checked_later`, so that no range of one is cut at the other's start)
        if not self.airgap_open > self.free_travel and not start_checks_deferred():
            raise ParameterError(
                f"ActuatorParameters: airgap_open = {self.airgap_open!r} m must exceed free_travel = "
                f"{self.free_travel!r} m (Eq. 12: d > sigma)")

    def kernel_data(self) -> np.ndarray:
        """Array ``[mass, stiffness, preload, damping, free_travel, airgap_open, tau1, tau2]`` (SI)."""
        return np.array([self.mass, self.stiffness, self.preload, self.damping, self.free_travel,
                         self.airgap_open, self.tau1, self.tau2])


@dataclasses.dataclass(frozen=True)
class VehicleParameters(ParameterSet):
    """AWD vehicle on the drum bench; Table 1 of [1] plus representative inertias, tyre and bench data."""

    kind = "vehicle"

    mass: float = quantity(2162.0, "kg", "curb weight", source="[1] Table 1", positive=True)
    cg_to_front: float = quantity(1.1043, "m", "centre of mass to front axle", source="[1] Table 1", positive=True)
    cg_to_rear: float = quantity(1.5957, "m", "centre of mass to rear axle", source="[1] Table 1", positive=True)
    cg_height: float = quantity(0.670, "m", "height of the centre of mass (for the record: the drum bench's axle "
                                "loads are static, [1] Sec. 4)", source="[1] Table 1", positive=True, reference=True)
    wheelbase: float = quantity(2.700, "m", "wheel base", source="[1] Table 1", positive=True)
    gear_ratios: tuple = quantity((4.044, 2.371, 1.556, 1.159, 0.852, 0.672), "1", "transmission gear ratios 1st-6th",
                                  source="[1] Table 1", positive=True)
    reverse_ratio: float = quantity(3.19, "1", "reverse gear ratio (for the record: the scenarios drive forward "
                                    "gears 1-6)", source="[1] Table 1", positive=True, reference=True)
    front_final_drive: float = quantity(3.75, "1", "front main retarder ratio i0", source="[1] Table 1", positive=True)
    rear_final_drive: float = quantity(2.533, "1", "rear main retarder ratio i_r = i_f (Eq. 28)", source="[1] Table 1", positive=True)
    engine_power: float = quantity(125e3, "W", "engine power", source="[1] Table 1", positive=True)
    engine_torque_max: float = quantity(250.0, "N*m", "engine torque limit", source="representative", positive=True)
    tyre_radius: float = quantity(0.3622, "m", "tyre radius of 225/65R17 (0.5*17 in + 0.65*225 mm)", source="[1] Table 1", positive=True)
    inertia_front_axle: float = quantity(3.5, "kg*m^2", "front axle and wheels J_wf (Eq. 27)", source="representative", positive=True)
    inertia_rear_axle: float = quantity(3.3, "kg*m^2", "rear axle and wheels J_wr (Eq. 27)", source="representative", positive=True)
    inertia_input_shaft: float = quantity(0.05, "kg*m^2", "EMTC input shaft J_sf (Eq. 27)", source="representative", positive=True)
    inertia_output_shaft: float = quantity(0.02, "kg*m^2", "EMTC output shaft J_sr (Eq. 27)", source="representative", positive=True)
    tyre_slip_stiffness: float = quantity(1.0e5, "N", "longitudinal slip stiffness per wheel on the drum", source="representative", positive=True)
    slip_speed_floor: float = quantity(1.0, "m/s", "speed floor of the slip definition", source="representative", positive=True)
    rolling_resistance: float = quantity(0.012, "1", "rolling-resistance coefficient on the drums", source="representative", nonnegative=True)
    torsen_stiffness: float = quantity(2000.0, "N*m/rad", "Torsen equivalent stiffness K_s (Eq. 30)", source="representative", nonnegative=True)
    torsen_damping: float = quantity(30.0, "N*m*s/rad", "Torsen equivalent damping D_s (Eq. 30)", source="representative", nonnegative=True)
    drag_pairs: int = quantity(15, "1", "fluid gaps N of the open coupling (Eq. 25)", source="representative", nonnegative=True)
    oil_viscosity: float = quantity(0.02, "Pa*s", "dynamic viscosity of the coupling fluid (Eq. 25)", source="representative", positive=True)
    plate_clearance: float = quantity(0.2e-3, "m", "axial clearance h between discs (Eq. 25)", source="representative", positive=True)
    plate_outer_radius: float = quantity(0.075, "m", "outer radius R_o of the wetted plates (Eq. 25)", source="representative", positive=True)
    plate_inner_radius: float = quantity(0.055, "m", "inner radius R_1 of the wetted plates (Eq. 25)", source="representative", nonnegative=True)

    def check(self) -> None:
        # (checked again by every run's start: deferred to it in a native FMU's trial builds, as the actuator's)
        if abs(self.cg_to_front + self.cg_to_rear - self.wheelbase) > GEOMETRY_TOLERANCE and not start_checks_deferred():
            raise ParameterError(
                f"VehicleParameters: cg_to_front + cg_to_rear = {self.cg_to_front + self.cg_to_rear:.4f} m "
                f"differs from wheelbase = {self.wheelbase:.4f} m")
        if not self.plate_inner_radius < self.plate_outer_radius:
            raise ParameterError("VehicleParameters: plate_inner_radius must be < plate_outer_radius")
        ratios = self.gear_ratios
        if len(ratios) == 0 or any(not r > 0 for r in ratios):
            raise ParameterError(f"VehicleParameters: gear_ratios = {list(ratios)!r}: needs one ratio > 0 per gear, "
                                 "from 1st to top gear")
        if any(not a > b for a, b in zip(ratios, ratios[1:])):
            raise ParameterError(
                f"VehicleParameters: gear_ratios = {list(ratios)!r}: must fall strictly from 1st to top gear")

    def axle_loads(self) -> tuple[float, float]:
        """Static front and rear axle loads [N] (:func:`static_axle_load`)."""
        return (float(static_axle_load(self.mass, self.cg_to_rear, self.wheelbase)),
                float(static_axle_load(self.mass, self.cg_to_front, self.wheelbase)))

    def drag_coefficient(self) -> float:
        """``T_drag / omega`` of Eq. 25 [N*m*s/rad]."""
        return drag_torque(self.drag_pairs, self.oil_viscosity, 1.0, self.plate_clearance, self.plate_outer_radius,
                           self.plate_inner_radius)


@dataclasses.dataclass(frozen=True)
class BenchScenario(ParameterSet):
    """A drum-bench experiment: drum speeds, throttle ramp, gear ([1], Sec. 4, Figs. 16-17)."""

    kind = "scenario"

    duration: float = quantity(4.0, "s", "simulated time", positive=True)
    gear: int = quantity(2, "1", "engaged gear (1-6)", bounds=(1, 6))
    drum_speed: float = quantity(8.0, "m/s", "front drum surface speed", nonnegative=True)
    speed_difference: float = quantity(0.3, "m/s", "front minus rear drum speed", bounds=(-5.0, 5.0))
    throttle_start: float = quantity(0.1, "1", "throttle at t = 0", bounds=(0.0, 1.0))
    throttle_end: float = quantity(0.6, "1", "throttle at the end of the ramp", bounds=(0.0, 1.0))
    ramp_start: float = quantity(0.5, "s", "throttle ramp start", nonnegative=True)
    ramp_end: float = quantity(3.5, "s", "throttle ramp end", nonnegative=True)
    drum_load_front: float = quantity(0.0, "N*m", "extra drum resistance torque, front axle", nonnegative=True)
    drum_load_rear: float = quantity(0.0, "N*m", "extra drum resistance torque, rear axle", nonnegative=True)
    temperature_c: float = quantity(60.0, "degC", "coupling temperature (friction map)", bounds=(-40.0, 200.0))
    sample_time: float = quantity(0.002, "s", "controller and output sample time", positive=True)

    def check(self) -> None:
        if self.ramp_end < self.ramp_start:
            raise ParameterError("BenchScenario: ramp_end must not be before ramp_start")
        if self.sample_time > self.duration:
            raise ParameterError("BenchScenario: sample_time longer than duration")


class TorqueMap:
    """Torque reference ``T_cal = f(throttle, v_x)`` of the EMTC controller ([1], Eq. 31).

    Bilinear in throttle [-] and vehicle speed [m/s], clamped at the edges.
    The default is representative: more torque to the rear at high throttle
    and low speed, fading with speed.
    """

    def __init__(self, throttle=None, speed=None, torque=None):
        if throttle is None:
            throttle = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
            speed = np.array([0.0, 5.0, 10.0, 20.0, 40.0])
            torque = np.outer([0.0, 150.0, 300.0, 450.0, 550.0], [1.0, 0.9, 0.8, 0.5, 0.2])
        self.throttle = np.asarray(throttle, float)
        self.speed = np.asarray(speed, float)
        self.torque = np.asarray(torque, float)
        for name, g in (("throttle", self.throttle), ("speed", self.speed)):
            if g.ndim != 1 or g.size < 2 or np.any(np.diff(g) <= 0) or not np.all(np.isfinite(g)):
                raise ParameterError(f"TorqueMap.{name}: need a strictly increasing grid of at least two values")
        if self.torque.shape != (self.throttle.size, self.speed.size) or not np.all(np.isfinite(self.torque)):
            raise ParameterError(f"TorqueMap.torque: expected finite values of shape {(self.throttle.size, self.speed.size)}")

    def __call__(self, throttle, speed):
        """``T_cal`` [N*m] at throttle [-] and vehicle speed [m/s]."""
        return float(bilinear(self.throttle, self.speed, self.torque, float(throttle), float(speed)))


_DEFAULTS: dict = {}


def _default(cls):
    """Shared default instance (parameter sets are frozen; the map is never modified)."""
    if cls not in _DEFAULTS:
        _DEFAULTS[cls] = cls()
    return _DEFAULTS[cls]
