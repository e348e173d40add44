"""The toy cone clutch (tests/_support/cone_clutch.py, a component added from outside) in a driveline FMU: its
parameters come from its declaration with their units and ranges (``min``/``max`` in the modelDescription),
and the FMU runs in a host process that finds the component through the entry point of an installed package
(a dist-info on its path), as a tool importing the FMU would.  The run against the closed form:
tests/driveline/test_components.py.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

import cone_clutch
from clutchlab import component as C
from clutchlab.errors import ParameterError
from clutchlab.fmu.driveline import DrivelineCoSimulation
from clutchlab.fmu.export import export_fmu

SUPPORT = Path(cone_clutch.__file__).resolve().parent

J1, J2, W0, F, R, MU = 0.1, 0.3, 100.0, 500.0, 0.05, 0.3

CONE = cone_clutch.EXAMPLE.replace('t_end = "0.4 s"', 't_end = "0.3 s"')


@pytest.fixture
def cone():
    C.register_component(cone_clutch.CONE_CLUTCH)
    yield cone_clutch.CONE_CLUTCH
    C.unregister_component("cone_clutch")


def _installed(tmp_path) -> str:
    """A site folder in which the cone clutch is an installed package's entry point; its PYTHONPATH."""
    info = tmp_path / "site" / "clutchlab_cone_example-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: clutchlab-cone-example\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[clutchlab.components]\ncone_clutch = cone_clutch:CONE_CLUTCH\n")
    return os.pathsep.join([str(tmp_path / "site"), str(SUPPORT), os.environ.get("PYTHONPATH", "")])


def test_the_cone_clutch_fmu_has_its_declared_parameters_and_runs_in_a_host(tmp_path, monkeypatch, cone, run_fmu,
                                                                              run_cosim):
    import fmpy
    import fmpy.validation

    path = tmp_path / "cone.toml"
    path.write_text(CONE)
    cls = DrivelineCoSimulation.for_description(path)
    fmu = export_fmu("driveline", tmp_path / "cone.fmu", description=path)
    assert fmpy.validation.validate_fmu(str(fmu)) == []
    md = {v.name: v for v in fmpy.read_model_description(str(fmu), validate=True).modelVariables}
    alpha = md["c.alpha"]
    assert (alpha.causality, alpha.unit, float(alpha.min), float(alpha.max)) == ("parameter", "rad", 0.0, math.pi / 2)
    assert float(alpha.start) == pytest.approx(cone_clutch.ALPHA)
    assert (float(md["c.mu"].min), float(md["c.mu"].max)) == (0.0, 2.0)
    assert (md["c.r_mean"].unit, float(md["c.r_mean"].max)) == ("m", 2.0)
    assert md["J1.w0"].min is None and md["J1.w0"].max is None   # no range declared: none written
    # the importer's value outside the range is refused when the model is built, naming it and the range
    with pytest.raises(ParameterError, match=r"'c\.alpha' = 2\.0 is outside its range \(0, 1\.5708\] \[rad\]"):
        cls(**{"c.alpha": 2.0})
    # a host process: it knows the cone clutch only through the installed package's entry point
    monkeypatch.setenv("PYTHONPATH", _installed(tmp_path))
    start = {"c.alpha": math.radians(15.0), "c.r_mean": 0.06}
    names = ["J1.w", "J2.w", "c.tau", "c.mode", "c.dissipated", "energy_error"]
    dt, n = 1e-3, 300
    got = run_fmu(fmu, {}, dt, n, names, start)
    ref = run_cosim(cls(**start), {}, dt, n)
    for name in names:
        np.testing.assert_allclose(got[name], ref[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(ref[name])),
                                   err_msg=name)
    torque = MU * F * 0.06 / math.sin(math.radians(15.0))
    t_lock = W0 / (torque * (1 / J1 + 1 / J2))
    t = np.arange(n + 1) * dt
    np.testing.assert_allclose(np.abs(got["c.tau"][t < t_lock - dt]), torque, rtol=1e-9)   # the changed values hold
    np.testing.assert_allclose(got["J2.w"][t > t_lock + dt], J1 * W0 / (J1 + J2), rtol=1e-8)
