"""clutchlab: modelling, simulation and identification of automotive clutches.

Public API (curated):

- :class:`Curve`, :mod:`clutchlab.curves` -- measured force-deflection characteristics
- :mod:`clutchlab.eclutch` -- dry clutch-by-wire (Haramina et al. 2024)
- :mod:`clutchlab.wet` -- wet multi-plate clutch (Shin, Kim, Choi)
- :mod:`clutchlab.emtc` -- electromagnetic torque-controlled coupling (Processes 2019)
- :mod:`clutchlab.errors` -- exception hierarchy
- :mod:`clutchlab.system` -- the system contract every model implements; :func:`clutchlab.system.simulate`
- :class:`SimulationResult` -- the one result of every simulation
"""

__version__ = "0.1.0"

from .errors import ClutchlabError, DataError, IdentificationError, ParameterError, SimulationError  # noqa: E402
from .curves import Curve  # noqa: E402
from . import curves  # noqa: E402
from . import _compile_notice  # noqa: E402

_compile_notice.install()  # one stderr line when kernels are compiled (never at import)



def __getattr__(name):
    # imported on first use: the result type needs pandas, which `clutchlab --help` should not pay for
    if name == "SimulationResult":
        from .result import SimulationResult

        return SimulationResult
    if name == "system":
        import importlib

        return importlib.import_module(".system", __name__)
    raise AttributeError(f"module 'clutchlab' has no attribute {name!r}")


__all__ = [
    "__version__",
    "SimulationResult",
    "Curve",
    "curves",
    "ClutchlabError",
    "ParameterError",
    "DataError",
    "SimulationError",
    "IdentificationError",
]
