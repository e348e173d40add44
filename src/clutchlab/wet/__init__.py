"""Wet multi-plate clutch: friction and thermal model, virtual test bench, identification.

Implements Shin, Kim and Choi, "Apparatus for identification of frictional
and thermal characteristics of a wet clutch" (KAIST): Sections 2-4 and
Table 1, extended with the squeeze-film / Greenwood-Williamson engagement
dynamics of Deur et al. (2005).  See ``docs/wet.md``.
"""

from .film import (
    asperity_contact_pressure,
    effective_radius,
    gw_integral,
    mean_film_thickness,
    nominal_separation,
    slip_velocity,
    squeeze_film_coefficient,
    squeeze_film_force,
)
from .viscosity import ViscosityFit, atf_viscosity, fit_viscosity
from .torque import asperity_torque, clutch_torque, viscous_torque
from .thermal import (
    heat_balance,
    pack_heat_capacity,
    steady_state_temperature,
    temperature_step_response,
    thermal_time_constant,
)
from .friction import FrictionMap, ParametricFriction
from .params import Bench, WetClutch
from .engagement import (
    BatchResult,
    EngagementResult,
    Event,
    Scenario,
    simulate,
    simulate_batch,
    simulate_engagement,
)
from .bench import (  # also registers the model "wet" (protocol_system)
    BenchRun,
    EngagementProtocol,
    MapProtocol,
    load_protocol,
    measure,
    read_bench_record,
    run_protocol,
    write_bench_record,
)
from .identify import ThermalFit, fit_parametric_friction, friction_samples, identify_friction_map, identify_thermal

__all__ = [
    "effective_radius", "slip_velocity", "nominal_separation", "mean_film_thickness", "gw_integral",
    "asperity_contact_pressure", "squeeze_film_coefficient", "squeeze_film_force",
    "atf_viscosity", "fit_viscosity", "ViscosityFit",
    "asperity_torque", "viscous_torque", "clutch_torque",
    "heat_balance", "pack_heat_capacity", "thermal_time_constant", "steady_state_temperature",
    "temperature_step_response",
    "ParametricFriction", "FrictionMap",
    "WetClutch", "Bench",
    "Scenario", "Event", "EngagementResult", "BatchResult", "simulate", "simulate_engagement", "simulate_batch",
    "MapProtocol", "EngagementProtocol", "BenchRun", "run_protocol", "measure", "read_bench_record",
    "write_bench_record", "load_protocol",
    "friction_samples", "fit_parametric_friction", "identify_friction_map", "identify_thermal", "ThermalFit",
]
