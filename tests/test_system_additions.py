"""Additions to the system contract made while porting the wet clutch (see the commits starting "core:").

* ``SimulationResult.events`` may be given as a callable, built on first access (and before pickling);
* ``System.variant`` copies a system with other parameters / initial values without re-checking the rest;
* ``Simulation.stats`` reports the solver counters of a resumable session.
"""

import pickle

import numpy as np
import pandas as pd
import pytest

from clutchlab.errors import ParameterError
from clutchlab.result import SimulationResult
from clutchlab.system import Simulation, simulate, simulate_batch
from core_toys import ball_system


def test_events_are_built_on_first_access_and_before_pickling():
    calls = []

    def build():
        calls.append(1)
        return pd.DataFrame({"time_s": [0.5], "event": ["bounce"], "element": [""]})

    res = SimulationResult(np.zeros(1), np.zeros((1, 1)), np.zeros((1, 0)), np.zeros((1, 0), np.int64), build, 0,
                           ("x_m",), ())
    assert calls == []
    assert list(res.events.event) == ["bounce"] and res.events is res.events and calls == [1]
    again = pickle.loads(pickle.dumps(SimulationResult(np.zeros(1), np.zeros((1, 1)), np.zeros((1, 0)),
                                                       np.zeros((1, 0), np.int64), build, 0, ("x_m",), ())))
    assert list(again.events.event) == ["bounce"]


def test_simulate_and_batch_events_are_the_same_named_frames():
    ball = ball_system()
    res = simulate(ball, 2.0)
    assert list(res.events.columns) == ["time_s", "event", "element"] and (res.events.event == "bounce").all()
    assert len(res.events) == 4  # the fourth bounce is terminal
    batch = simulate_batch([ball, ball.variant(x0=[2.0, 0.0])], 2.0)
    ev = batch.events
    assert list(ev.columns) == ["variant", "time_s", "event", "element"]
    np.testing.assert_allclose(ev.time_s[ev.variant == 0], res.events.time_s, rtol=1e-12)
    assert (ev.variant == 1).sum() == 4 and ev.time_s[ev.variant == 1].iloc[0] == pytest.approx(np.sqrt(4 / 9.81))


def test_variant_shares_the_rest_and_checks_what_it_gets():
    ball = ball_system()
    v = ball.variant(x0=[3.0, 0.0])
    assert v.x0[0] == 3.0 and ball.x0[0] == 1.0 and v.params is ball.params and v.state_columns == ball.state_columns
    with pytest.raises(ParameterError, match="shape"):
        ball.variant(x0=[1.0])
    with pytest.raises(ParameterError, match="BallParams"):
        ball.variant(params=(9.81, 0.5))


def test_simulation_stats_count_the_session():
    sim = Simulation(ball_system())
    sim.advance(0.2)
    first = sim.stats["accepted_steps"]
    sim.advance(0.4)
    assert 0 < first < sim.stats["accepted_steps"] and sim.stats["rhs_evaluations"] > 0
