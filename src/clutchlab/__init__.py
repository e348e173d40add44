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

# numba is imported by the first module that compiles (clutchlab.numerics installs the one-line compile notice
# then), not here: `clutchlab --help` imports neither numba nor a model (tests/test_cli_help.py)


def __getattr__(name):
    # imported on first use: the curves need numba and the result type pandas, which `clutchlab --help` should
    # not pay for
    import importlib

    if name == "SimulationResult":
        from .result import SimulationResult

        return SimulationResult
    if name == "Curve":
        return importlib.import_module(".curves", __name__).Curve
    if name in ("system", "curves"):
        return importlib.import_module(f".{name}", __name__)
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
