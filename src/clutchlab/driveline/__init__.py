"""One-dimensional driveline networks on the integrator core: inertias, spring-dampers, torque sources
and friction elements between two flanges with the Modelica friction state machine.

See :mod:`clutchlab.driveline.network` (the description API) and :mod:`clutchlab.driveline.kernel`
(the compiled hooks and the friction semantics).
"""

from .network import GROUND, Driveline, Signal

__all__ = ["Driveline", "Signal", "GROUND"]
