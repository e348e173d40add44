"""FMI 2.0 co-simulation export of the clutchlab models (issue #6).

:mod:`clutchlab.fmu.cosim` defines the step-by-step protocol
(:class:`~clutchlab.fmu.cosim.CoSimulation`, :class:`~clutchlab.fmu.cosim.Variable`);
:mod:`~clutchlab.fmu.eclutch`, :mod:`~clutchlab.fmu.wet`, :mod:`~clutchlab.fmu.emtc` and
:mod:`~clutchlab.fmu.driveline` hold the models' slaves; :func:`export_fmu` wraps any model of
:data:`COSIMULATIONS` into an FMU with pythonfmu (``clutchlab export-fmu
{eclutch,wet,emtc} -o NAME.fmu``; a driveline from its description file,
``clutchlab export-fmu driveline FILE.toml``).  See ``docs/fmu.md``.  The model modules
are imported on first use, so ``import clutchlab.fmu`` stays light.
"""

__all__ = ["COSIMULATIONS", "CoSimulation", "Variable", "load_cosimulation", "export_fmu"]

from .registry import COSIMULATIONS


def __getattr__(name):
    if name in ("CoSimulation", "Variable", "load_cosimulation"):
        from . import cosim

        return getattr(cosim, name)
    if name == "export_fmu":
        from .export import export_fmu

        return export_fmu
    raise AttributeError(f"module 'clutchlab.fmu' has no attribute {name!r}")
