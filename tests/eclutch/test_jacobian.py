"""The E-clutch's analytic Jacobian and time derivative (``clutchlab.eclutch.system.jacobian``, ``time_derivative``)
against central differences of its right-hand side, through the contract.

The states are drawn around a run's trajectory (position control and an open-loop voltage table, the actuator
simulated; and the bearing motion prescribed), perturbed, in random friction modes.  A column is compared where
the difference stencil crosses no kink: no switching function changes sign across it (contacts, stops,
cavitation, current limit, snifting port) and no chamber pressure crosses zero (the seals' friction is
``mu_p |p|``).  The comparison allows for the stencil's rounding (``100 eps |f| / delta``) and a relative 1e-4.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hypothesis_budget import examples

from clutchlab import system as contract
from clutchlab.eclutch import ClutchModel, EClutch, FrictionParameters
from clutchlab.eclutch.dynamics import ClutchDynamics
from clutchlab.numerics.core import evaluate_jacobian

INPUTS = {
    "position": {"bearing_reference": ([0.0, 0.1, 0.3, 0.6, 0.8], [0.0, 0.0, 7e-3, 7e-3, 0.0])},
    "voltage": {"voltage": ([0.0, 0.05, 0.3, 0.31, 0.6], [0.0, 6.0, 6.0, -6.0, -6.0])},
}
_RUNS = {}
EPS = np.finfo(float).eps


def _run(kind):
    if kind not in _RUNS:
        if kind == "prescribed":
            cd = ClutchDynamics(ClutchModel.preset(4), friction=FrictionParameters())
            system = cd.as_system(([0.0, 0.2, 0.5], [0.0, 7e-3, 2e-3]))
            typ = cd.assembly.typ
        else:
            ec = EClutch(clutch=ClutchModel.preset(4), friction=FrictionParameters())
            system = ec.as_system(INPUTS[kind], rtol=1e-3)
            typ = ec.assembly.typ
        run = contract.simulate(system, 1.0 if kind != "prescribed" else 0.5, outputs=False)
        _RUNS[kind] = (system, run, typ)
    return _RUNS[kind]


def _pressure_columns(system):
    return [i for i, v in enumerate(system.states) if v.unit == "Pa"]


@settings(max_examples=examples(40), deadline=None)
@given(kind=st.sampled_from(["position", "voltage", "prescribed"]), row=st.floats(0.0, 1.0),
       seed=st.integers(0, 2**32 - 1))
def test_jacobian_equals_central_differences(kind, row, seed):
    system, run, typ = _run(kind)
    rng = np.random.default_rng(seed)
    k = int(row * (len(run.time) - 1))
    t = float(run.time[k])
    x = run.states[k] * (1.0 + 0.1 * rng.standard_normal(len(system.states)))
    m = run.modes[k].copy()
    m[:-1] = rng.integers(0, 4, m.size - 1)  # friction modes: free, slip forward, stuck, slip backward
    u = system.u0.copy()
    J = np.zeros((x.size, x.size))
    assert evaluate_jacobian(system.params, t, x, u, m, J)
    pressures = _pressure_columns(system)
    compared = 0
    for c in range(x.size):
        d = 1e-6 * max(abs(x[c]), typ[c])
        if c in pressures and abs(x[c]) <= 2 * d:
            continue
        xp, xm = x.copy(), x.copy()
        xp[c] += d
        xm[c] -= d
        fp, gp, _ = contract.evaluate(system, t, xp, u, m)
        fm, gm, _ = contract.evaluate(system, t, xm, u, m)
        if np.any(np.sign(gp) != np.sign(gm)):
            continue
        col = (fp - fm) / (2 * d)
        tol = 1e-4 * np.abs(col) + 100 * EPS * np.maximum(np.abs(fp), np.abs(fm)) / d + 1e-6 * np.abs(col).max()
        bad = np.abs(J[:, c] - col) > tol + 1e-300
        assert not bad.any(), (kind, t, m, system.states[c].name, [system.states[r].name for r in np.flatnonzero(bad)],
                               J[bad, c], col[bad])
        compared += 1
    assert compared >= x.size // 2


@pytest.mark.parametrize("kind", ["position", "voltage"])
def test_time_derivative_equals_a_difference_in_time(kind):
    """df/dt at fixed state: the reference (or voltage) ramp through the controller and the drive."""
    from clutchlab.eclutch.system import time_derivative

    system, run, _ = _run(kind)
    u = system.u0.copy()
    checked = 0
    for k in range(0, len(run.time), 5):
        t = float(run.time[k])
        x = run.states[k].copy()
        m = run.modes[k].copy()
        ft = np.zeros(x.size)
        assert time_derivative(t, x, u, m, system.params, ft)
        dt = 1e-7
        fp, gp, _ = contract.evaluate(system, t + dt, x, u, m)
        fm, gm, _ = contract.evaluate(system, t - dt, x, u, m)
        if np.any(np.sign(gp) != np.sign(gm)):
            continue
        fd = (fp - fm) / (2 * dt)
        np.testing.assert_allclose(ft, fd, rtol=1e-5, atol=1e-6 * np.abs(fd).max() + 1e-9)
        checked += 1
    assert checked > 10


def test_prescribed_motion_leaves_the_time_derivative_to_the_core():
    from clutchlab.eclutch.system import time_derivative

    system, run, _ = _run("prescribed")
    ft = np.zeros(len(system.states))
    assert not time_derivative(0.1, run.states[5].copy(), system.u0, run.modes[5].copy(), system.params, ft)
