"""The models an FMU can be built of: model name -> ``"module:Class"`` of its co-simulation slave.

Plain data (no imports), so ``import clutchlab.fmu`` and ``clutchlab --help`` stay light; the class is imported
on demand by :func:`clutchlab.fmu.cosim.load_cosimulation`.
"""

#: model name -> "module:Class" of its co-simulation (imported on demand by ``load_cosimulation``)
COSIMULATIONS = {
    "wet": "clutchlab.fmu.wet:WetCoSimulation",
    "emtc": "clutchlab.fmu.emtc:EmtcCoSimulation",
    "eclutch": "clutchlab.fmu.eclutch:EClutchCoSimulation",
    "driveline": "clutchlab.fmu.driveline:DrivelineCoSimulation",
}
