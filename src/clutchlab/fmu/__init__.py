"""FMI 2.0 co-simulation export of the clutchlab models (issue #6).

:mod:`clutchlab.fmu.cosim` defines the step-by-step protocol
(:class:`~clutchlab.fmu.cosim.CoSimulation`, :class:`~clutchlab.fmu.cosim.Variable`)
and the wet-clutch and EMTC slaves; :func:`export_fmu` wraps any model of
:data:`COSIMULATIONS` into an FMU with pythonfmu (``clutchlab export-fmu
{eclutch,wet,emtc} -o NAME.fmu``; a driveline from its description file,
``clutchlab export-fmu driveline FILE.toml``).  See ``docs/fmu.md``.  The model modules
are imported on first use, so ``import clutchlab.fmu`` stays light.
"""

__all__ = ["COSIMULATIONS", "CoSimulation", "Variable", "load_cosimulation", "export_fmu"]

#: model name -> "module:Class" of its co-simulation (imported on demand by ``load_cosimulation``)
COSIMULATIONS = {
    "wet": "clutchlab.fmu.cosim:WetCoSimulation",
    "emtc": "clutchlab.fmu.cosim:EmtcCoSimulation",
    "eclutch": "clutchlab.eclutch.cosim:EClutchCoSimulation",
    "driveline": "clutchlab.driveline.cosim:DrivelineCoSimulation",
}


def __getattr__(name):
    if name in ("CoSimulation", "Variable", "load_cosimulation"):
        from . import cosim

        return getattr(cosim, name)
    if name == "export_fmu":
        from .export import export_fmu

        return export_fmu
    raise AttributeError(f"module 'clutchlab.fmu' has no attribute {name!r}")
