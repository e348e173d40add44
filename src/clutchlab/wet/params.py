"""Parameter sets of the wet-clutch subsystem.

:class:`WetClutch` holds the clutch of Shin, Kim and Choi [1], Table 1, plus
the quantities the engagement model needs that Table 1 does not give (chosen
and documented: piston position at zero separation, friction area,
Greenwood-Williamson contact data, return spring).  :class:`Bench` holds the
virtual test bench of Fig. 4 (motor, gear, inertia, actuator, sensors, oil
circulation).  Both load from and save to TOML with units.

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import ClassVar

from ..errors import ParameterError
from ..params import ParameterSet, quantity
from ..params.base import WET_TEMPERATURES_C
from .film import effective_radius, gw_pressure_scale, squeeze_film_coefficient
from .thermal import pack_heat_capacity_scalar

__all__ = ["WetClutch", "Bench", "BENCH_SENSORS", "BENCH_DRIVE"]

#: fields of :class:`Bench` that only the virtual rig's measurements read (its sample rate, sensor noise, seed)
BENCH_SENSORS = ("sample_rate", "noise_torque", "noise_speed", "noise_force", "noise_position", "noise_temperature",
                 "noise_fluid_temperature", "seed")
#: fields of :class:`Bench` of its drive (motor, gear, shaft, speed controller): a driveline's wet clutch, whose drive
#: is the network, does not read them
BENCH_DRIVE = ("motor_torque_max", "motor_power_max", "motor_speed_max", "gear_ratio", "motor_inertia",
               "shaft_inertia", "speed_kp", "speed_ki")

T1 = "Shin et al., Table 1"
_RO, _RI = 0.08315, 0.07174
_AREA = math.pi * (_RO**2 - _RI**2)


#: The temperatures [degC] the wet clutch's model takes (:data:`clutchlab.params.base.WET_TEMPERATURES_C`).
TEMPERATURE_RANGE_C = WET_TEMPERATURES_C


def temperature_problem(value: float) -> str | None:
    """Why ``value`` [degC] is not a temperature of the wet clutch's model (:data:`TEMPERATURE_RANGE_C`), or None."""
    lo, hi = TEMPERATURE_RANGE_C
    if not math.isfinite(value):
        return "not finite"
    if not lo <= value <= hi:
        return (f"outside the wet clutch's temperatures [{lo:g}, {hi:g}] degC (from the oil's pour point to "
                "beyond the linings' destruction)")
    return None


@dataclasses.dataclass(frozen=True)
class WetClutch(ParameterSet):
    """Wet multi-plate clutch (paper-based lining on steel core disks), SI units.

    ``WetClutch.paper()`` returns Table 1 of Shin et al.; the default values of
    the fields Table 1 lacks are clutchlab's choices, reasoned in ``docs/wet.md``.
    """

    kind: ClassVar[str] = "wet"

    n_c: int = quantity(8, "1", "number of clutches N_c", source=T1, positive=True)
    r_outer: float = quantity(_RO, "m", "outer radius of the clutch disk R_o", source=T1, positive=True)
    r_inner: float = quantity(_RI, "m", "inner radius of the clutch disk R_i", source=T1, positive=True)
    core_thickness: float = quantity(1.7e-3, "m", "core disk thickness (for the record: the model reads the core's "
                                     "mass, m_core)", source=T1, positive=True, reference=True)
    sigma: float = quantity(6e-4, "m", "RMS roughness of the friction material sigma", source=T1, positive=True)
    asperity_radius: float = quantity(5e-4, "m", "asperity tip radius beta", source=T1, positive=True)
    mu_v1: float = quantity(0.1502, "Pa*s", "viscosity parameter mu_v1 (Eq. 7)", source=T1, positive=True)
    mu_v2: float = quantity(-0.07838, "1/K", "viscosity exponent mu_v2 (Eq. 7, per degC)", source=T1)
    mu_v3: float = quantity(0.05815, "Pa*s", "viscosity parameter mu_v3 (Eq. 7)", source=T1, positive=True)
    mu_v4: float = quantity(-0.02184, "1/K", "viscosity exponent mu_v4 (Eq. 7, per degC)", source=T1)
    m_lining: float = quantity(1.65e-3, "kg", "mass of paper-based lining per clutch", source=T1, positive=True)
    m_core: float = quantity(82.1e-3, "kg", "mass of core disk per clutch", source=T1, positive=True)
    cp_lining: float = quantity(1500.0, "J/(kg*K)", "specific heat capacity of lining", source=T1, positive=True)
    cp_core: float = quantity(500.0, "J/(kg*K)", "specific heat capacity of core disk", source=T1, positive=True)
    k1: float = quantity(122.2, "W/K", "generalised conductance pack -> cooling oil (convection)", source=T1, nonnegative=True)
    k2: float = quantity(39.94, "W/K", "generalised conductance pack -> housing (conduction)", source=T1, nonnegative=True)
    friction_area: float = quantity(_AREA, "m^2", "nominal friction area of one face A_f",
                                    source="clutchlab: full annulus pi (R_o^2 - R_i^2), grooves neglected", positive=True)
    piston_h0: float = quantity(12e-3, "m", "piston position x_p,h0 at zero nominal separation",
                                source="clutchlab: 2.5 sigma open clearance per interface x N_c", positive=True)
    asperity_density: float = quantity(1.333e5, "1/m^2", "asperity density eta (GW)",
                                       source="clutchlab: eta*sigma*beta = 0.04 (GW typical 0.03-0.05)", positive=True)
    contact_modulus: float = quantity(2.3e6, "Pa", "composite elastic modulus E' of lining asperities (GW)",
                                      source="clutchlab: 300 kPa carried at h = -1.5 sigma", positive=True)
    squeeze_flow_factor: float = quantity(0.2, "1", "squeeze resistance of the grooved pack relative to a smooth annulus",
                                          source="clutchlab: grooves drain the film (Deur et al. 2005 use flow factors)",
                                          positive=True)
    spring_stiffness: float = quantity(1.0e4, "N/m", "piston return spring stiffness", source="clutchlab", nonnegative=True)
    spring_preload: float = quantity(200.0, "N", "piston return spring preload at x_p = 0", source="clutchlab", nonnegative=True)

    def check(self) -> None:
        if self.r_inner >= self.r_outer:
            raise ParameterError(f"WetClutch.r_inner = {self.r_inner!r}: must be < r_outer = {self.r_outer!r} [m]")
        full = math.pi * (self.r_outer**2 - self.r_inner**2)
        if self.friction_area > full * (1 + 1e-9):
            raise ParameterError(
                f"WetClutch.friction_area = {self.friction_area!r}: larger than the annulus pi(R_o^2-R_i^2) = {full:.6g} [m^2]")
        if self.mu_v2 >= 0 or self.mu_v4 >= 0:
            raise ParameterError(f"WetClutch.mu_v2/mu_v4 = {self.mu_v2!r}/{self.mu_v4!r}: viscosity must fall with temperature (< 0) [1/K]")

    @classmethod
    def paper(cls, **overrides) -> "WetClutch":
        """Table 1 of Shin et al. (SI units), with optional field overrides.

        ``viscosity=(mu_v1, mu_v2, mu_v3, mu_v4)`` sets the four Eq. 7
        parameters at once ([Pa*s], [1/K], [Pa*s], [1/K]); they are stored as
        four fields because their units differ.
        """
        if "viscosity" in overrides:
            visc = overrides.pop("viscosity")
            try:
                mu1, mu2, mu3, mu4 = visc
            except (TypeError, ValueError):
                raise ParameterError(f"WetClutch.viscosity = {visc!r}: expected the four Eq. 7 parameters") from None
            overrides.update(mu_v1=mu1, mu_v2=mu2, mu_v3=mu3, mu_v4=mu4)
        return cls().replace(**overrides) if overrides else cls()

    # ------------------------------------------------------------- derived
    @property
    def viscosity(self) -> tuple[float, float, float, float]:
        """The four Eq. 7 parameters (mu_v1 [Pa*s], mu_v2 [1/K], mu_v3 [Pa*s], mu_v4 [1/K])."""
        return (self.mu_v1, self.mu_v2, self.mu_v3, self.mu_v4)

    @functools.cached_property
    def r_eff(self) -> float:
        """Torque effective radius [m] (Eq. (1'))."""
        return effective_radius(self.r_outer, self.r_inner)   # (the compiled start's number, wet_start)

    @property
    def heat_capacity(self) -> float:
        """Heat capacity of the pack ``{(m c_p)_lining + (m c_p)_core} N_c`` [J/K] (Eq. 8)."""
        return pack_heat_capacity_scalar(float(self.n_c), self.m_lining, self.cp_lining, self.m_core, self.cp_core)

    @functools.cached_property
    def gw_scale(self) -> float:
        """Greenwood-Williamson pressure scale ``4/3 E' eta sqrt(beta) sigma^1.5`` [Pa]."""
        return gw_pressure_scale(self.sigma, self.asperity_radius, self.asperity_density, self.contact_modulus)

    @functools.cached_property
    def squeeze_coefficient(self) -> float:
        """Squeeze-film factor ``squeeze_flow_factor * K`` [m^4] (smooth-annulus K times the groove factor)."""
        return self.squeeze_flow_factor * squeeze_film_coefficient(self.r_outer, self.r_inner)   # (as wet_start)


@dataclasses.dataclass(frozen=True)
class Bench(ParameterSet):
    """Virtual test bench of Shin et al., Fig. 4 (motor, gear, inertia, actuator, sensors, oil loop).

    Ratings from Sec. 3.1 (32 kW / 120 N*m / 6000 rpm motor through a 1:2
    gear, 16 kN linear actuator, 2 kW heater); the rest are clutchlab's
    representative choices (see ``docs/wet.md``).  Inertias and torques are
    referred to the clutch shaft unless named ``motor_``.
    """

    kind: ClassVar[str] = "bench"

    motor_torque_max: float = quantity(120.0, "N*m", "drive motor torque limit (motor shaft)", source="Sec. 3.1", positive=True)
    motor_power_max: float = quantity(32e3, "W", "drive motor power limit", source="Sec. 3.1", positive=True)
    motor_speed_max: float = quantity(6000 * math.pi / 30, "rad/s", "drive motor speed limit (motor shaft)", source="Sec. 3.1", positive=True)
    gear_ratio: float = quantity(2.0, "1", "torque amplification motor -> clutch shaft (1:2 gear)", source="Sec. 3.1", positive=True)
    motor_inertia: float = quantity(0.08, "kg*m^2", "motor + flywheel (inertia 1) at the motor shaft", source="clutchlab", positive=True)
    shaft_inertia: float = quantity(0.01, "kg*m^2", "clutch-side inertia between torque sensor and clutch", source="clutchlab", positive=True)
    speed_kp: float = quantity(20.0, "N*m*s/rad", "speed controller proportional gain (clutch shaft)", source="clutchlab", nonnegative=True)
    speed_ki: float = quantity(400.0, "N*m/rad", "speed controller integral gain (clutch shaft)", source="clutchlab", nonnegative=True)
    actuator_force_max: float = quantity(16e3, "N", "linear actuator force limit", source="Sec. 3.1", positive=True)
    actuator_time_constant: float = quantity(0.01, "s", "closed-loop force control lag", source="clutchlab", positive=True)
    actuator_speed_max: float = quantity(0.1, "m/s", "actuator no-load speed", source="clutchlab", positive=True)
    thermistor_time_constant: float = quantity(0.2, "s", "thermistor lag in the core disk", source="clutchlab", positive=True)
    reservoir_heat_capacity: float = quantity(2.0e4, "J/K", "oil reservoir + circulating oil", source="clutchlab", positive=True)
    heater_power_max: float = quantity(2000.0, "W", "reservoir heater power", source="Sec. 3.3", nonnegative=True)
    heater_gain: float = quantity(400.0, "W/K", "reservoir thermostat gain", source="clutchlab", nonnegative=True)
    reservoir_cooling: float = quantity(6.0, "W/K", "natural cooling of the reservoir", source="clutchlab", nonnegative=True)
    housing_heat_capacity: float = quantity(1.2e4, "J/K", "rig housing", source="clutchlab", positive=True)
    housing_cooling: float = quantity(25.0, "W/K", "natural cooling of the housing", source="clutchlab", nonnegative=True)
    fluid_housing_conductance: float = quantity(15.0, "W/K", "oil -> housing conductance", source="clutchlab", nonnegative=True)
    ambient_temperature: float = quantity(25.0, "degC", "laboratory temperature", source="clutchlab")
    sample_rate: float = quantity(1000.0, "Hz", "data acquisition rate", source="clutchlab", positive=True)
    noise_torque: float = quantity(0.3, "N*m", "torque sensor noise (std)", source="clutchlab", nonnegative=True)
    noise_speed: float = quantity(0.05, "rad/s", "encoder speed noise (std)", source="clutchlab", nonnegative=True)
    noise_force: float = quantity(5.0, "N", "load cell noise (std)", source="clutchlab", nonnegative=True)
    noise_position: float = quantity(2e-6, "m", "piston position noise (std)", source="clutchlab", nonnegative=True)
    noise_temperature: float = quantity(0.05, "K", "thermistor noise (std)", source="clutchlab", nonnegative=True)
    noise_fluid_temperature: float = quantity(0.1, "K", "fluid/housing sensor noise (std)", source="clutchlab", nonnegative=True)
    seed: int = quantity(20240601, "1", "random seed of the sensor noise", source="clutchlab", nonnegative=True)

    @property
    def drive_torque_max(self) -> float:
        """Motor torque limit referred to the clutch shaft [N*m]."""
        return self.motor_torque_max * self.gear_ratio

    @property
    def drive_speed_max(self) -> float:
        """Motor speed limit referred to the clutch shaft [rad/s]."""
        return self.motor_speed_max / self.gear_ratio

    @property
    def total_inertia(self) -> float:
        """Rotating inertia at the clutch shaft [kg*m^2]."""
        return self.shaft_inertia + self.motor_inertia * self.gear_ratio**2
