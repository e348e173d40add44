"""The compiled peer of the work-precision benchmark (benchmarks/_peer_emtc.py) integrates clutchlab's EMTC
drum-bench equations.

* Its right-hand side and switching functions (the numba ``cfunc`` given to numbalsoda, called here through
  ctypes, and the plain compiled model behind it) against :func:`clutchlab.system.evaluate` of the
  ``emtc_bench`` system at random states, times, drum speeds, current commands, modes and magnet
  histories.  numbalsoda is not needed for this (it is the benchmark's extra, not in CI).
* A whole peer run against the SciPy reference of benchmarks/wp_emtc.py, only where numbalsoda is installed.
"""

from __future__ import annotations

import ctypes
import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.emtc import ActuatorParameters, BenchScenario, bench_system, bundled_magnet
from clutchlab.emtc import system as S
from clutchlab.hysteresis import kernels as K
from clutchlab.system import evaluate

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"


def _load(name):
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, BENCH / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


peer = _load("_peer_emtc")
MAGNET = bundled_magnet()
SCENARIO = BenchScenario(duration=1.0, speed_difference=0.3, throttle_start=0.1, throttle_end=0.6, ramp_start=0.1,
                         ramp_end=0.9, sample_time=0.002)
_P = ctypes.POINTER(ctypes.c_double)
RHS = ctypes.CFUNCTYPE(None, ctypes.c_double, _P, _P, _P)(peer.rhs.address)


def _commit_history(tables, grid, stack, prefix, history):
    """Commit the coil currents ``history`` from a fresh memory; returns (length, last input)."""
    length, u = 0, float(grid[0])
    for v in history:
        v = min(max(v, grid[0]), grid[-1])
        length = K.commit(tables, grid, stack, prefix, length, u, v)
        u = v
    return length, u


def _cfunc_dy(t, y, d):
    """dy/dt through the cfunc (scaled state in, scaled derivative out)."""
    scale = d[peer.D_SCALE:peer.D_SCALE + 7]
    z = np.ascontiguousarray(y / scale)
    dz = np.zeros(7)
    RHS(float(t), z.ctypes.data_as(_P), dz.ctypes.data_as(_P), d.ctypes.data_as(_P))
    return dz * scale


currents = st.floats(-0.5, 5.0, allow_nan=False)


def _grid_line(i, grid):
    """``(-1)**k (i - grid[k]) (grid[k+1] - i) / (grid[k+1] - grid[k])`` in the grid's cell ``k`` holding ``i``,
    ``i - grid[0]`` below it, ``(-1)**(n-1) (i - grid[n-1])`` above (``emtc.system.grid_line_function``)."""
    n = len(grid)
    if i <= grid[0]:
        return i - grid[0]
    if i >= grid[-1]:
        return (-1) ** (n - 1) * (i - grid[-1])
    k = int(np.searchsorted(grid, i, side="right")) - 1
    return (-1) ** k * (i - grid[k]) * (grid[k + 1] - i) / (grid[k + 1] - grid[k])


@settings(deadline=None, max_examples=examples(60))
@given(t=st.floats(0.0, 1.2), wf=st.floats(-10.0, 90.0), dw=st.floats(-3.0, 3.0), theta=st.floats(-0.05, 0.05),
       xa=st.floats(-1e-4, 6e-4), xd=st.floats(-0.5, 0.5), i1=currents, i2=currents, icmd=st.floats(0.0, 4.5),
       vf=st.floats(-2.0, 15.0), vr=st.floats(-2.0, 15.0), arm=st.integers(0, 2), cpl=st.integers(0, 2),
       direction=st.integers(0, 1), history=st.lists(st.floats(0.0, 4.5), max_size=6))
def test_rhs_matches_clutchlab(t, wf, dw, theta, xa, xd, i1, i2, icmd, vf, vr, arm, cpl, direction, history):
    system = bench_system(MAGNET, SCENARIO)
    p = system.params
    plen, pu = _commit_history(p.plant_tables, p.plant_grid, p.plant_stack, p.plant_prefix, history)
    p.imem[S.IM_PLEN] = plen
    p.fmem[S.FM_PU] = pu
    p.fmem[S.FM_CMD] = icmd  # the command the controller holds
    p.fmem[S.FM_KEY] = np.nan
    x = np.array([wf, wf - dw, theta, xa, xd, i1, i2])
    u = system.u0.copy()
    u[S.U_DRUM_FRONT], u[S.U_DRUM_REAR] = vf, vr
    m = np.array([arm, cpl, direction], dtype=np.int64)
    dx_cl, g_cl, y_cl = evaluate(system, t, x, u, m)

    d = peer.pack(MAGNET, SCENARIO)
    tables = peer._tables(d)
    d[peer.D_PLEN], d[peer.D_PU] = _commit_history(tables, peer._grid(d), peer._stack(d), peer._prefix(d), history)
    d[peer.D_ICMD] = icmd
    d[peer.D_VF], d[peer.D_VR] = vf, vr
    d[peer.D_ARM], d[peer.D_CPL], d[peer.D_DIR] = arm, cpl, direction
    dy, gsw = np.zeros(7), np.zeros(6)
    fm, tc, _, _ = peer.model(t, x, dy, gsw, d)

    # the magnet force and the coupling torque (outputs of the contract), then dx and the switching functions;
    # clutchlab's kernels are compiled with fastmath (reassociation), so agreement is to rounding, not bits
    assert fm == pytest.approx(y_cl[2], rel=1e-10, abs=1e-9)
    assert tc == pytest.approx(y_cl[8], rel=1e-10, abs=1e-9)
    np.testing.assert_allclose(dy, dx_cl, rtol=1e-9, atol=1e-7)
    # the mode changes' functions (the peer's six); the coil current's waypoints are clutchlab's alone,
    # checked against their definition written out here
    modes = [k for k, (_name, d) in enumerate(S.SWITCHING) if abs(d) < 3]   # (3, 4: waypoints)
    np.testing.assert_allclose(gsw, g_cl[modes], rtol=1e-9, atol=1e-9)
    names = [q[0] for q in S.SWITCHING]
    assert g_cl[names.index("coil_current_grid_line")] == pytest.approx(_grid_line(i2, MAGNET.grid), rel=1e-12,
                                                                        abs=1e-15)
    # and the coil current's turn: i2' = (i1 - i2) / tau2 through zero, 1e-9 A past it from the side the current
    # last moved to (a fresh run: rising)
    assert g_cl[names.index("coil_current_turn")] == pytest.approx(x[5] - x[6] + 1e-9, rel=0, abs=1e-15)
    # the cfunc numbalsoda calls (scaled state) gives the same derivative
    np.testing.assert_allclose(_cfunc_dy(t, x, d), dy, rtol=1e-12, atol=1e-12)


def test_peer_run_matches_scipy_reference():
    if not peer.HAVE_NUMBALSODA:
        pytest.skip("numbalsoda is not installed (the benchmarks' extra): the peer's driver cannot run")
    wp = _load("wp_emtc")
    sc = BenchScenario(duration=0.2, speed_difference=0.3, throttle_start=0.1, throttle_end=0.6, ramp_start=0.05,
                       ramp_end=0.15, sample_time=0.002)
    ref, _ = wp.reference(MAGNET, sc, rtol=1e-10, atol=S.ATOL * 1e-4, method="DOP853")
    out, calls = wp.peer_runner(MAGNET, sc)(1e-10)
    assert calls >= ref.shape[0] - 1
    np.testing.assert_allclose(out[:, 0], ref[:, 0], atol=1e-12)
    # the armature leaves its rest stop and reaches the clutch within the run: the events were located
    assert out[-1, 4] == ActuatorParameters().free_travel
    assert np.max(np.abs(out[:, 1:3] - ref[:, 1:3])) < 1e-5  # shaft speeds [rad/s]
    assert np.max(np.abs(out[:, 6:8] - ref[:, 6:8])) < 1e-5  # coil currents [A]
