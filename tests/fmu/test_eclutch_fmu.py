"""FMU of the E-clutch dynamics (``clutchlab.fmu.eclutch.EClutchCoSimulation``, written against the protocol).

Runs against the lead's class: the FMU loaded with FMPy must reproduce the
in-process co-simulation (the same object behind pythonfmu, so equal to
1e-12) for inputs held at their start values and then stepped to half of
them; the model description must list every variable with its unit.
"""

import numpy as np

from clutchlab.fmu.cosim import CoSimulation, Variable, load_cosimulation
from clutchlab.fmu.export import DEFAULT_EXPERIMENT


def _cls():
    # imported per test (not at collection) so that a missing class fails these tests, not the whole run
    from clutchlab.fmu.eclutch import EClutchCoSimulation

    return EClutchCoSimulation


def test_eclutch_follows_the_protocol():
    EClutchCoSimulation = _cls()
    assert issubclass(EClutchCoSimulation, CoSimulation) and EClutchCoSimulation.name == "eclutch"
    assert load_cosimulation("eclutch") is EClutchCoSimulation
    for group in (EClutchCoSimulation.inputs, EClutchCoSimulation.outputs, EClutchCoSimulation.parameters):
        for v in group:
            assert isinstance(v, Variable) and v.unit
    assert EClutchCoSimulation.inputs and EClutchCoSimulation.outputs


def test_eclutch_fmu_reproduces_the_cosimulation(build_fmu, run_fmu, run_cosim):
    import fmpy
    import fmpy.validation

    EClutchCoSimulation = _cls()
    path = build_fmu("eclutch")
    assert fmpy.validation.validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(path))
    units = {v.name: v.unit for v in md.modelVariables}
    for v in (*EClutchCoSimulation.inputs, *EClutchCoSimulation.outputs, *EClutchCoSimulation.parameters):
        assert units[v.name] == v.unit
    _, dt = DEFAULT_EXPERIMENT["eclutch"]
    n = 50
    k = np.arange(n + 1)
    inputs = {v.name: np.where(k < n // 2, v.start, 0.5 * v.start) for v in EClutchCoSimulation.inputs}
    names = [v.name for v in EClutchCoSimulation.outputs]
    fmu = run_fmu(path, inputs, dt, n, names)
    ref = run_cosim(EClutchCoSimulation(), inputs, dt, n)
    for name in names:
        scale = max(np.max(np.abs(ref[name])), 1e-300)
        np.testing.assert_allclose(fmu[name][1:], ref[name][1:], rtol=1e-12, atol=1e-12 * scale, err_msg=name)


def test_eclutch_reset_repeats_the_run():
    c = _cls()()
    _, dt = DEFAULT_EXPERIMENT["eclutch"]
    u = {v.name: v.start for v in c.inputs}
    first = [c.do_step(i * dt, dt, u) for i in range(10)]
    c.reset()
    again = [c.do_step(i * dt, dt, u) for i in range(10)]
    assert first == again
