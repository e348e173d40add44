"""The co-simulations' fast step (``do_step_array``, what the FMU calls) against their general path.

``do_step_array`` checks the step and the inputs with a few comparisons, writes the held inputs in place and
makes one compiled call (``Simulation.step``: the packed session, clutchlab.numerics.session) that advances
and gathers the outputs.  Every test here compares it, bit for bit, with ``do_step`` (dicts) on a
co-simulation whose ``Simulation`` goes through numba's dispatcher with all its arguments at every call
(``_pack = False``), including the errors (same type, same message) and the steps after them.
"""

from pathlib import Path

import numpy as np
import pytest
from session_check import assert_packed_as_compiled

from clutchlab.errors import ParameterError, SimulationError
from clutchlab.fmu.cosim import CoSimulation
from clutchlab.fmu.emtc import EmtcCoSimulation
from clutchlab.fmu.wet import WetCoSimulation

EXAMPLES = Path(__file__).parents[2] / "examples"


def _eclutch():
    from clutchlab.fmu.eclutch import EClutchCoSimulation

    return EClutchCoSimulation()


def _driveline():
    from clutchlab.fmu.driveline import DrivelineCoSimulation

    return DrivelineCoSimulation.for_description(EXAMPLES / "driveline_coupled_clutches.toml")()


# name, factory, input sequences (one per step, in the order of `inputs`), number of steps
CASES = {
    "wet": (lambda: WetCoSimulation(**{"scenario.free_inertia": 1.0}),
            lambda k: [0.0 if k < 5 else 3000.0, 157.0], 60),
    "wet_speed": (lambda: WetCoSimulation(), lambda k: [2500.0, 157.0 if k < 30 else 120.0], 60),
    "emtc": (EmtcCoSimulation, lambda k: [0.0 if k < 8 else 300.0, 0.1, 8.0, 7.7 if k < 20 else 7.5], 40),
    "eclutch": (_eclutch, lambda k: [3e-3 if k < 10 else 5e-3, 0.0], 30),
    "driveline": (_driveline, lambda k: [], 40),
}


def _names(c):
    return [v.name for v in c.inputs]


def _pair(factory, u0):
    """Two co-simulations at t = 0: the fast one and one whose sessions always dispatch."""
    fast, plain = factory(), factory()
    for c in (fast, plain):
        c.initial_outputs(dict(zip(_names(c), u0)))
    plain.simulation._pack = False  # (unpacked: every call dispatches)
    fast.simulation._pack_after = 0  # (packed from the next call)
    return fast, plain


@pytest.mark.parametrize("name", list(CASES))
def test_fast_steps_equal_the_general_path(name):
    factory, inputs, n = CASES[name]
    fast, plain = _pair(factory, inputs(0))
    assert type(fast).do_step_array is not CoSimulation.do_step_array  # (each model has its fast path)
    dt = 1e-3
    for k in range(n):
        y = fast.do_step_array(k * dt, dt, inputs(k))
        ref = plain.do_step(k * dt, dt, dict(zip(_names(plain), inputs(k))))
        assert list(ref) == [v.name for v in plain.outputs]
        assert np.array_equal(y, np.array(list(ref.values()))), k
        assert np.array_equal(fast.simulation.x, plain.simulation.x)
        assert np.array_equal(fast.simulation.m, plain.simulation.m)
    assert fast.simulation._fast[1] is not None and plain.simulation._fast[1] is None
    assert fast.simulation.stats == plain.simulation.stats
    assert list(fast.simulation.events().event) == list(plain.simulation.events().event)
    if hasattr(fast, "events"):
        assert fast.events == plain.events


def _bad_steps(name, c):
    """(t, dt, inputs) of refused steps at the model's time t (each must raise, the model stays put)."""
    t = 5e-3
    u = CASES[name][1](5)
    steps = [(t + 1e-3, 1e-3, u), (t, 0.0, u), (t, -1e-3, u), (t, float("nan"), u), (t, float("inf"), u)]
    if name != "eclutch":  # (EClutchCoSimulation.do_step does not refuse a time that is not finite)
        steps += [(float("nan"), 1e-3, u), (float("inf"), 1e-3, u)]
    for i in range(len(u)):
        for bad in (float("nan"), float("inf"), -float("inf")):
            steps.append((t, 1e-3, [bad if j == i else x for j, x in enumerate(u)]))
    if name.startswith("wet"):
        steps += [(t, 1e-3, [-1.0, u[1]]), (t, 1e-3, [1e9, u[1]])]
    if name == "wet_speed":
        steps.append((t, 1e-3, [u[0], 1e6]))
    if name == "emtc":
        steps += [(t, 1e-3, [u[0], 1.5, u[2], u[3]]), (t, 1e-3, [u[0], -0.1, u[2], u[3]])]
    return steps


def _outcome(fn):
    try:
        return fn()
    except (ParameterError, SimulationError) as exc:
        return type(exc), str(exc)


@pytest.mark.parametrize("name", ["wet", "emtc", "eclutch", "driveline"])
def test_the_session_tables_of_the_models_are_written_as_numba_writes_them(name):
    factory, inputs, _ = CASES[name]
    c = factory()
    c.initial_outputs(dict(zip(_names(c), inputs(0))))
    assert_packed_as_compiled(c.simulation)


@pytest.mark.parametrize("name", list(CASES))
def test_refused_steps_raise_as_do_step_and_the_run_goes_on(name):
    """Every refused step raises the error do_step raises (type and message), changes nothing, and the steps
    after it equal the general path's."""
    factory, inputs, _ = CASES[name]
    fast, plain = _pair(factory, inputs(0))
    dt = 1e-3
    for k in range(5):
        y = fast.do_step_array(k * dt, dt, inputs(k)).copy()
        plain.do_step(k * dt, dt, dict(zip(_names(plain), inputs(k))))
    for t, h, u in _bad_steps(name, fast):
        x = fast.simulation.x.copy()
        got = _outcome(lambda: fast.do_step_array(t, h, u))
        want = _outcome(lambda: plain.do_step(t, h, dict(zip(_names(plain), u))))
        assert isinstance(want, tuple) and got == want, (t, h, u)
        assert np.array_equal(fast.simulation.x, x) and np.array_equal(fast.simulation.reported(), y)
    for k in range(5, 10):
        y = fast.do_step_array(k * dt, dt, inputs(k))
        ref = plain.do_step(k * dt, dt, dict(zip(_names(plain), inputs(k))))
        assert np.array_equal(y, np.array(list(ref.values())))


def test_a_failed_step_leaves_the_outputs_of_the_last_good_one():
    """The array the FMU reads is written only by a step that succeeds (docs/fmu.md: the model stays at the
    last valid point)."""
    c = WetCoSimulation(**{"scenario.free_inertia": 1.0, "solver.max_step": 1e-3})
    c.initial_outputs({"force_reference": 3000.0})
    y = c.do_step_array(0.0, 1e-3, [3000.0, 157.0])
    kept = y.copy()
    c.simulation._opt = c.simulation._opt._replace(max_steps=c.simulation.stats["accepted_steps"] + 2)
    with pytest.raises(SimulationError, match="between t = 0.001 and 1.001 s"):
        c.do_step_array(1e-3, 1.0, [3000.0, 157.0])
    assert np.array_equal(y, kept)


def test_the_first_step_without_initial_outputs_starts_the_model():
    fast, plain = WetCoSimulation(), WetCoSimulation()
    y = fast.do_step_array(0.0, 1e-3, [2000.0, 100.0])
    ref = plain.do_step(0.0, 1e-3, {"force_reference": 2000.0, "slip_speed_reference": 100.0})
    assert np.array_equal(y, np.array(list(ref.values())))


def test_the_default_fast_step_goes_through_do_step():
    """A co-simulation that only has do_step (the protocol's minimum) still serves the FMU."""

    class Echo(CoSimulation):
        from clutchlab.fmu.cosim import Variable

        inputs = (Variable("a", "1", 0.0), Variable("b", "1", 0.0))
        outputs = (Variable("sum", "1", 0.0), Variable("t", "s", 0.0))

        def __init__(self, **values):
            self.t = 0.0

        def reset(self):
            self.t = 0.0

        def do_step(self, t, dt, inputs):
            self.t = t + dt
            return {"t": self.t, "sum": inputs["a"] + inputs["b"]}

    y = Echo().do_step_array(0.0, 0.5, [1.0, 2.0])
    assert np.array_equal(y, [3.0, 0.5])
