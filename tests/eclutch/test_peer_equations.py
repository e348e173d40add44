"""The compiled peer of ``benchmarks/wp_eclutch.py`` (``benchmarks/_peer_eclutch.py``) has clutchlab's E-clutch
equations.

clutchlab holds the massless finger tip as a state with an algebraic row (mass-matrix row 0: ``dx[tip]`` is
the tip's force residual) and its velocity as a state whose row is ``-v_tip``; the peer (like the plain-Python
reference of ``bench_eclutch_dynamics.py``) has no tip state and solves the tip by Newton inside the right-hand
side.  So the comparison: the peer's state -> its tip position (Newton) -> clutchlab's full state with that tip
(tip velocity 0, energy states 0) -> ``clutchlab.system.evaluate``; then the derivatives of the shared states
(the massive coordinates' positions and velocities, p_m, Q, p_s, i, V_I) must agree, and clutchlab's algebraic
residual at the peer's tip must vanish.  The friction modes are drawn too (clutchlab: free 0, slip forward 1,
stuck 2, slip backward 3; the peer: 1, -1, 2).  The right-hand side needs no numbalsoda; the one full run does.
"""

from __future__ import annotations

import importlib.util
import os
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hypothesis_budget import examples

BENCH = os.path.join(os.path.dirname(__file__), "..", "..", "benchmarks")
sys.path.insert(0, os.path.abspath(BENCH))

import _peer_eclutch as peer  # noqa: E402
from clutchlab import system as contract  # noqa: E402
from clutchlab.eclutch import ClutchModel, EClutch, FrictionParameters  # noqa: E402
from clutchlab.eclutch import system as S  # noqa: E402
from clutchlab.eclutch.dynamics import _as_table  # noqa: E402

INPUT = {"bearing_reference": ([0.0, 0.1, 0.3, 0.6, 0.8], [0.0, 0.0, 7e-3, 7e-3, 0.0])}
_CACHE = {}


def _setup():
    if not _CACHE:
        ec = EClutch(clutch=ClutchModel.preset(4), friction=FrictionParameters())
        tin, vin = _as_table(INPUT["bearing_reference"], "bearing_reference")
        system = ec.as_system(INPUT, rtol=1e-3)
        # states along the physical trajectory: a clutchlab run, sampled
        out = ec.simulate(INPUT, 1.0, rtol=1e-3, output_step=0.01)
        _CACHE.update(ec=ec, tin=tin, vin=vin, system=system, out=out.outputs_table)
    return _CACHE


def _trajectory_state(c, k):
    """The peer's (unscaled) state at output row ``k`` of the clutchlab run."""
    o = c["out"]
    ec = c["ec"]
    s = ec.assembly
    col = lambda name: float(o[name].iloc[k])  # noqa: E731
    z = {"master": col("master_position_m"), "bearing": col("bearing_position_m"), "pp": col("x_pp_m"),
         "edge": col("x_edge_m"), "support": col("x_support_m")}
    massive = [j for j in range(s.nz) if s.mass[j] > 0.0]
    names = [s.coord_names[j] for j in massive]
    v = {"master": col("motor_speed_rpm") * 2 * np.pi / 60 * ec.assembly.par[S.P_NS],
         "bearing": col("bearing_velocity_m_s")}
    y = [z[n] for n in names] + [v.get(n, 0.0) for n in names]
    y += [col("master_pressure_Pa"), col("line_flow_m3_s"), col("pressure_Pa"), col("motor_current_A"), 0.0]
    return np.array(y), float(o["time_s"].iloc[k])


_PEER_MODE = {S.FREE: 0.0, S.SLIP_FORWARD: 1.0, S.STUCK: 2.0, S.SLIP_BACKWARD: -1.0}


@settings(deadline=None, max_examples=examples(40))
@given(k=st.integers(0, 100), noise=st.lists(st.floats(-1.0, 1.0), min_size=15, max_size=15),
       mode_draw=st.lists(st.sampled_from([S.SLIP_FORWARD, S.STUCK, S.SLIP_BACKWARD]), min_size=6, max_size=6))
def test_peer_rhs_equals_clutchlab(k, noise, mode_draw):
    c = _setup()
    ec, system = c["ec"], c["system"]
    s = ec.assembly
    nz = s.nz
    y, t = _trajectory_state(c, k)
    # perturbations of the size of the motion: 20 um, 2 mm/s, 0.2 bar, 1e-7 m^3/s, 0.5 A, 0.5 V
    m = (len(y) - 5) // 2
    scale = np.array([2e-5] * m + [2e-3] * m + [2e4, 1e-7, 2e4, 0.5, 0.5])
    y = y + scale * np.array(noise)
    modes_cl = np.array([mode_draw[j] if s.fr_on[j] else S.FREE for j in range(nz)], dtype=np.int64)
    data = peer.pack(ec, c["tin"], c["vin"])
    peer.initial(ec, data)  # tip start guess: the rest position
    o = int(data[peer.H_MODES])
    data[o:o + nz] = [_PEER_MODE[int(md)] for md in modes_cl]
    dy = np.empty_like(y)
    peer.derivatives(data, t, y, dy)
    qa = int(data[peer.H_QALG])
    tip = data[qa: qa + nz - 2]
    # clutchlab's full state with the peer's tip
    massive = [j for j in range(nz) if s.mass[j] > 0.0]
    x = np.zeros(len(system.states))
    for i, j in enumerate(massive):
        x[j] = y[i]
        x[nz + j] = y[m + i]
    for j in range(2, nz):
        if s.mass[j] == 0.0:
            x[j] = tip[j - 2]
    x[2 * nz: 2 * nz + 5] = y[2 * m:]
    seg = int(np.searchsorted(c["tin"], t, side="right"))
    mm = np.append(modes_cl, seg)
    dx, _g, _y = contract.evaluate(system, t, x, None, mm)
    want = np.array([dx[j] for j in massive] + [dx[nz + j] for j in massive] + list(dx[2 * nz: 2 * nz + 5]))
    # rounding only: the forces on a coordinate (up to some kN) cancel, so each row gets an absolute floor of
    # 1e-12 of its largest force over its mass (accelerations) or of its own typical rate
    floor = np.array([1e-12] * m + [1e-12 * 1e4 / s.mass[j] for j in massive] + [1e-3, 1e-12, 1e-3, 1e-9, 1e-12])
    bad = np.abs(dy - want) > 1e-9 * np.abs(want) + floor
    assert not bad.any(), (t, modes_cl, np.flatnonzero(bad), dy, want, dy - want)
    for j in range(2, nz):
        if s.mass[j] == 0.0:
            assert abs(dx[j]) < 1e-8, ("clutchlab's tip residual at the peer's tip", dx[j])


@pytest.mark.skipif(importlib.util.find_spec("numbalsoda") is None,
                    reason="numbalsoda not installed (the bench extra): the peer's full run is not checked")
def test_peer_run_matches_clutchlab():
    c = _setup()
    ec = c["ec"]
    T, FB, n_ev, ok = peer.simulate(ec, c["tin"], c["vin"], 1.0, 1e-6)
    assert ok
    grid = np.linspace(0.0, 1.0, 2001)
    tight = ec.simulate(INPUT, 1.0, rtol=1e-7, output_step=5e-4)
    ref = np.interp(grid, tight.outputs_table.time_s, tight.outputs_table.bearing_force_N)
    err = np.abs(np.interp(grid, T, FB) - ref).max() / np.abs(ref).max()
    # the two integrators resolve the seals' stick-slip differently: F_b agrees to 1 % of its peak
    assert err < 1e-2, err
