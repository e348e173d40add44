"""One-dimensional driveline networks on the integrator core: inertias, spring-dampers, torque sources
and friction elements between two flanges with the Modelica friction state machine.

See :mod:`clutchlab.driveline.network` (the description API) and :mod:`clutchlab.driveline.kernel`
(the compiled hooks and the friction semantics).
Its component kinds are declared in :mod:`clutchlab.driveline.components` (registered when this package is
imported) on the contract of :mod:`clutchlab.component`.
"""

from .network import GROUND, Driveline, ElementInfo, InertiaInfo, Signal
from .components import BUILTIN

__all__ = ["Driveline", "Signal", "GROUND", "BUILTIN", "ElementInfo", "InertiaInfo"]
