"""E-clutch (dry clutch-by-wire) after Haramina et al., Trans. FAMENA 48 (2024) 21-35.

- :func:`characterize`, :func:`lever_stiffness`, :func:`yoke_support_equivalent` -- press-rig identification
- :class:`ClutchModel` -- axial Models 0-4 (:meth:`ClutchModel.preset`) and their static curves
- :class:`AxialNetwork`, :class:`Node`, :class:`Spring`, :class:`Lever` -- describe a model or a variant
- :class:`EClutchParameters`, :class:`ComponentCurves` -- parameters and measured characteristics
- :class:`VirtualClutch` -- the synthetic ground truth behind the bundled data
- :class:`EClutch`, :class:`ClutchDynamics` -- dynamics: actuator + clutch with stick-slip friction
- :class:`ActuatorParameters`, :class:`FrictionParameters` -- actuator and friction parameters
- :func:`load_scenario`, :func:`run_scenario` -- simulation scenarios from TOML
- :func:`simulate` -- the uniform entry point: a scenario in, a :class:`clutchlab.SimulationResult` out
  (the model implements the system contract once, :mod:`clutchlab.eclutch.system`, registered as ``"eclutch"``)
"""

from .actuator import ActuatorParameters
from .characterize import CharacterizedCurve, LeverStiffness, characterize, lever_stiffness, yoke_support_equivalent
from .models import ClutchModel, ComponentCurves, EClutchParameters, build_model, clutch_torque
from .dynamics import (ClutchDynamics, DynamicsResult, EClutch, FrictionElement, FrictionParameters,
                       actuator_test_rig, apply_wear_and_expansion, pedal_reference)
from .network import AxialNetwork, Lever, Node, Spring, solve_static, zero_input
from .scenario import Scenario, load_scenario, run_scenario, simulate
from .variants import load_variant
from .virtual import VirtualClutch

__all__ = [
    "characterize",
    "lever_stiffness",
    "yoke_support_equivalent",
    "CharacterizedCurve",
    "LeverStiffness",
    "ClutchModel",
    "ComponentCurves",
    "EClutchParameters",
    "build_model",
    "clutch_torque",
    "AxialNetwork",
    "Node",
    "Spring",
    "Lever",
    "solve_static",
    "zero_input",
    "VirtualClutch",
    "load_variant",
    "ActuatorParameters",
    "FrictionParameters",
    "FrictionElement",
    "EClutch",
    "ClutchDynamics",
    "DynamicsResult",
    "actuator_test_rig",
    "apply_wear_and_expansion",
    "pedal_reference",
    "Scenario",
    "load_scenario",
    "run_scenario",
    "simulate",
]
