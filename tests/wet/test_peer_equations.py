"""The compiled peer of ``benchmarks/wp_wet.py`` (``benchmarks/_peer_wet.py``) has clutchlab's equations.

Its right-hand side (the ``numba.njit`` twin ``model`` and the ``cfunc`` numbalsoda calls, through ctypes)
is compared with :func:`clutchlab.system.evaluate` on the wet engagement's system at random states,
inputs, modes and times, for two scenarios (speed-controlled bench, inertia dynamometer) and two clutches
and friction laws.  Neither needs numbalsoda; one full integration against the SciPy reference of
``benchmarks/bench_wet.py`` runs only where numbalsoda is installed (the ``bench`` extra).
"""

from __future__ import annotations

import ctypes
import importlib.util
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.system import evaluate
from clutchlab.wet import Bench, ParametricFriction, WetClutch
from clutchlab.wet import system as W
from clutchlab.wet.bench import EngagementProtocol

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))
import _peer_wet as peer  # noqa: E402  (imports no numbalsoda)

HAS_NUMBALSODA = importlib.util.find_spec("numbalsoda") is not None

_DP = ctypes.POINTER(ctypes.c_double)


def _cases():
    """(clutchlab system, peer parameter array) for each configuration (built once)."""
    out = []
    proto = EngagementProtocol(duration=1.0)
    configs = [
        (WetClutch.paper(), ParametricFriction.bench_truth(), "speed"),
        (WetClutch.paper(k1=100.0, k2=55.0), ParametricFriction(mu0=0.14, mu_t=1.0e-3, mu_e=-0.035, v_s=0.5,
                                                                t_ref=90.0), "free"),
    ]
    for clutch, law, motor in configs:
        scen = proto.scenario(clutch, motor)
        bench = Bench()
        sysm = W.engagement_system(scen, clutch=clutch, bench=bench, friction=law)
        out.append((sysm, peer.pack(clutch, bench, scen, law), clutch))
    return out


CASES = _cases()

finite = dict(allow_nan=False, allow_infinity=False)
states = st.tuples(
    st.floats(-1e-3, 0.03, **finite),        # piston position [m] (h0 = 12 mm: open, contact, compressed)
    st.floats(0.0, 16000.0, **finite),       # actuator force [N]
    st.floats(-200.0, 200.0, **finite),      # slip speed [rad/s]
    st.floats(-300.0, 300.0, **finite),      # controller integral [N m]
    st.floats(20.0, 150.0, **finite),        # pack temperature [degC]
    st.floats(20.0, 120.0, **finite),        # reservoir
    st.floats(20.0, 120.0, **finite),        # housing
    st.floats(20.0, 150.0, **finite),        # thermistor
    st.floats(0.0, 1e4, **finite), st.floats(0.0, 1e4, **finite), st.floats(0.0, 1e4, **finite),
    st.floats(-1e4, 1e4, **finite),          # energies [J]
)
inputs = st.tuples(st.floats(-500.0, 500.0, **finite), st.floats(-20.0, 20.0, **finite))
modes = st.tuples(*(st.integers(0, len(values) - 1) for values in W.MODE_VALUES))


def _peer_model(p, t, x, u, m):
    q = p.copy()
    q[peer.P_FMODE], q[peer.P_PMODE] = m[0], m[1]
    q[peer.P_UFORCE], q[peer.P_USPEED] = u
    dx = np.empty(peer.N)
    g = np.empty(peer.NG)
    peer.model(t, np.array(x), q, dx, g)
    return dx, g


def _close(a, b):
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-300)


@settings(deadline=None, max_examples=examples(150))
@given(case=st.integers(0, len(CASES) - 1), t=st.floats(0.0, 1.2, **finite), x=states, u=inputs, m=modes)
def test_model_matches_clutchlab(case, t, x, u, m):
    sysm, p, _ = CASES[case]
    dx_ref, g_ref, _ = evaluate(sysm, t, np.array(x), np.array(u), np.array(m, dtype=np.int64))
    dx, g = _peer_model(p, t, x, u, m)
    _close(dx, dx_ref)
    _close(g, g_ref[:peer.NG])


@settings(deadline=None, max_examples=examples(60))
@given(case=st.integers(0, len(CASES) - 1), t=st.floats(0.0, 1.2, **finite), x=states, u=inputs, m=modes)
def test_cfunc_matches_clutchlab(case, t, x, u, m):
    """The function numbalsoda calls: scaled states in, scaled rates out, modes and inputs in ``p``."""
    sysm, p, _ = CASES[case]
    dx_ref, _, _ = evaluate(sysm, t, np.array(x), np.array(u), np.array(m, dtype=np.int64))
    q = p.copy()
    q[peer.P_FMODE], q[peer.P_PMODE] = m[0], m[1]
    q[peer.P_UFORCE], q[peer.P_USPEED] = u
    scale = q[peer.P_SCALE:peer.P_SCALE + peer.N]
    uu = np.array(x) / scale
    du = np.full(peer.N, np.nan)
    peer.rhs.ctypes(float(t), uu.ctypes.data_as(_DP), du.ctypes.data_as(_DP), q.ctypes.data_as(_DP))
    np.testing.assert_allclose(du * scale, dx_ref, rtol=1e-12, atol=1e-300)


def test_layout_and_scales():
    """The peer's scaled states make numbalsoda's scalar atol clutchlab's per-state absolute tolerances."""
    for _, p, clutch in CASES:
        assert p[peer.P_LEN] == p.size
        scale = p[peer.P_SCALE:peer.P_SCALE + peer.N]
        for rtol in (1e-3, 1e-7, 1e-9):
            np.testing.assert_allclose(min(rtol, 1e-7) * scale, W.absolute_tolerance(clutch, rtol), rtol=1e-15)
    # constants read by name: every one the peer uses exists in clutchlab's record
    assert set(peer.CONSTANT_NAMES) <= set(W.CONSTANTS_DTYPE.names)


def test_rhs_runs_without_numbalsoda():
    """The module imports, and its right-hand side runs, where numbalsoda cannot be imported (CI)."""
    code = (
        "import sys; sys.modules['numbalsoda'] = None\n"  # `import numbalsoda` now raises ImportError
        f"sys.path.insert(0, {str(BENCHMARKS)!r})\n"
        "import numpy as np, _peer_wet as P\n"
        "from clutchlab.wet import Bench, WetClutch, system as W\n"
        "from clutchlab.wet.bench import EngagementProtocol\n"
        "c = WetClutch.paper(); s = EngagementProtocol().scenario(c)\n"
        "p = P.pack(c, Bench(), s); dx = np.empty(12); g = np.empty(5)\n"
        "P.model(0.1, W.initial_state(s), p, dx, g)\n"
        "assert np.all(np.isfinite(dx))\n"
        "try:\n    P.Peer(c, Bench(), s)\nexcept ImportError:\n    print('driver needs numbalsoda')\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "driver needs numbalsoda" in done.stdout


@pytest.mark.filterwarnings("ignore:Cannot cache compiled function")
@pytest.mark.skipif(not HAS_NUMBALSODA, reason="numbalsoda (the 'bench' extra, built with gfortran) is not "
                                               "installed: the peer's driver cannot run")
def test_peer_run_matches_scipy_reference():
    """One whole engagement by the peer (LSODA from compiled code, its own event location) against the
    SciPy solution of ``wp_wet.py`` (DOP853 at rtol 1e-10, bench_wet's Python right-hand side)."""
    from bench_wet import make_python_model
    from wp_wet import solve_scipy

    clutch, bench, law = WetClutch.paper(), Bench(), ParametricFriction.bench_truth()
    scen = EngagementProtocol(duration=1.0).scenario(clutch, "speed")
    grid = np.arange(1001) / 1000.0
    pr = peer.Peer(clutch, bench, scen, law, grid=grid)
    out = pr.solve(1e-8, window=0.1)
    ys, lock_ref, _ = solve_scipy(make_python_model(clutch, bench, scen, law), W.initial_state(scen),
                                  scen.duration, grid, "DOP853", 1e-10, W.absolute_tolerance(clutch, 1e-10))
    assert [n for n, _ in pr.events()] == ["piston_leaves_stop", "lockup"]
    assert abs(pr.lockup_time() - lock_ref) < 1e-6                        # s (measured 3e-8)
    assert np.max(np.abs(out[:, W.S_W] - ys[:, W.S_W])) < 1e-4            # rad/s, of 157 (measured 3e-6)
    assert np.max(np.abs(out[:, W.S_T] - ys[:, W.S_T])) < 1e-5            # K
    assert np.max(np.abs(out[:, W.S_X] - ys[:, W.S_X])) < 1e-8            # m
    assert math.isclose(out[-1, W.S_EF], ys[-1, W.S_EF], rel_tol=1e-6)    # friction work
