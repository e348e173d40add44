"""Thermal masses in a driveline FMU (tests/driveline/test_heat.py runs them in clutchlab): their fields are FMU
parameters with the units and ranges of their declaration, their temperatures are outputs, and the FMU run in
a host (FMPy in a fresh process) equals the in-process co-simulation, with a changed capacity taking effect."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from clutchlab.fmu.driveline import DrivelineCoSimulation
from clutchlab.fmu.export import export_fmu

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "driveline_clutch_heat.toml"


def test_the_heat_example_fmu_carries_its_thermal_parameters_and_runs_in_a_host(tmp_path, run_fmu, run_cosim):
    import fmpy
    import fmpy.validation

    path = tmp_path / "heat.toml"
    path.write_text(EXAMPLE.read_text().replace('t_end = "4 s"', 't_end = "3 s"'))
    fmu = export_fmu("driveline", tmp_path / "heat.fmu", description=path)
    assert fmpy.validation.validate_fmu(str(fmu)) == []
    md = {v.name: v for v in fmpy.read_model_description(str(fmu), validate=True).modelVariables}
    cap = md["plate.capacity"]
    assert (cap.causality, cap.unit, float(cap.min), float(cap.start)) == ("parameter", "J/K", 0.0, 900.0)
    assert md["plate_to_housing.conductance"].unit == "W/K" and md["housing.ambient"].unit == "degC"
    assert md["plate.temperature"].causality == "output" and md["plate.temperature"].unit == "degC"
    # the vehicle's initial speed, left out of the file, follows the gearbox's through the final gear: the network's
    # start derives it (kernel.derive_speeds), so it is no parameter, and a host sets the gearbox's speed and the
    # gear's ratio together (before, both speeds were fixed at export: the vehicle's was gearbox.w0 / final.ratio,
    # a quotient of two parameters, written at the build)
    assert "vehicle.w0" not in md
    assert (md["gearbox.w0"].causality, md["gearbox.w0"].variability) == ("parameter", "fixed")
    assert (md["final.ratio"].causality, md["final.ratio"].variability) == ("parameter", "fixed")
    start = {"plate.capacity": 1800.0, "gearbox.w0": 6.0, "final.ratio": 10.0}
    names = ["engine.w", "gearbox.w", "vehicle.w", "plate.temperature", "housing.temperature", "plate.loss_power",
             "clutch.dissipated"]
    dt, n = 0.01, 300
    got = run_fmu(fmu, {}, dt, n, names, start)
    ref = run_cosim(DrivelineCoSimulation.for_description(path)(**start), {}, dt, n)
    for name in names:
        np.testing.assert_allclose(got[name], ref[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(ref[name])),
                                   err_msg=name)
    assert (got["gearbox.w"][0], got["vehicle.w"][0]) == (6.0, 1.0 / 10.0 * 6.0)   # (w_b = (1 / ratio) w_a)
    # the host's capacity holds: the plate and housing keep the clutch's losses (the housing's air loss is small)
    stored = 1800.0 * (got["plate.temperature"] - 40.0) + 5000.0 * (got["housing.temperature"] - 40.0)
    assert stored[-1] == pytest.approx(got["clutch.dissipated"][-1], rel=0.02)
    assert got["plate.temperature"].max() < 70.0   # (900 J/K: 88 degC)
