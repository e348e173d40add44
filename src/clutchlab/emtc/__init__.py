"""EMTC: electromagnetic torque-controlled coupling of an AWD driveline.

Preisach magnet force (:mod:`clutchlab.hysteresis`), armature and current
control, torque transfer of the three friction elements in slipping and
locked modes, friction and drag torque, and the vehicle on a drum bench.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from .torque import (
    UNLOCK_MARGIN,
    CouplingGeometry,
    locked_capacities,
    locked_case,
    locked_torques,
    slipping_capacities,
    slipping_torques,
)
from .friction import (
    FrictionMap,
    LuGreParameters,
    LuGreResult,
    coupling_torque,
    drag_torque,
    lugre_simulate,
    lugre_steady_state,
    stribeck,
)
from .bench import (
    ActuatorParameters,
    BenchResult,
    BenchScenario,
    TorqueMap,
    VehicleParameters,
    load_scenario,
    simulate_bench,
)
from .magnet import bundled_magnet, synthetic_magnet
from .system import BenchOptions, bench_system, simulate

__all__ = [
    "UNLOCK_MARGIN",
    "CouplingGeometry",
    "slipping_torques",
    "slipping_capacities",
    "locked_torques",
    "locked_capacities",
    "locked_case",
    "FrictionMap",
    "LuGreParameters",
    "LuGreResult",
    "stribeck",
    "lugre_steady_state",
    "lugre_simulate",
    "drag_torque",
    "coupling_torque",
    "ActuatorParameters",
    "VehicleParameters",
    "BenchScenario",
    "TorqueMap",
    "BenchResult",
    "simulate_bench",
    "load_scenario",
    "bundled_magnet",
    "synthetic_magnet",
    "BenchOptions",
    "bench_system",
    "simulate",
]
