"""CoupledClutches' equations compiled with numba, for the compiled peer of ``bench_driveline.py``.

The same equations as ``tests/driveline/coupled_clutches_scipy.py`` (``solve_torques``, ``make_rhs``,
``make_events``), written once more as ``numba.njit`` functions of the mode vector, so that SciPy's
integrators (LSODA: the Fortran ODEPACK code; RK45, DOP853) call a compiled right-hand side and
compiled switching functions through a thin Python wrapper.  Mode logic at events stays the
reference's own (Python, run only at events).
"""

from __future__ import annotations

import math

import numba
import numpy as np

import coupled_clutches_scipy as ref

_CODES = {ref.FWD: 1, ref.BWD: -1, ref.STICK: 0, ref.FREE: 2}


@numba.njit(cache=True)
def _torques(t, y, modes, tau, a):
    """Clutch torques and inertia accelerations for a fixed mode vector (codes 1, -1, 0 stuck, 2 free)."""
    f1 = math.sin(2.0 * math.pi * 0.2 * t + 1.570796326794897)
    f = (f1, 1.0 if t >= 0.4 else 0.0, 1.0 if t >= 0.9 else 0.0)
    drive = 10.0 * math.sin(2.0 * math.pi * 5.0 * t)
    F = np.zeros(4)
    F[0] = drive
    stuck = np.empty(3, dtype=np.int64)
    ns = 0
    for k in range(3):
        tau[k] = 0.0
        if modes[k] == 1:
            tau[k] = 10.0 * f[k]
        elif modes[k] == -1:
            tau[k] = -10.0 * f[k]
        elif modes[k] == 0:
            stuck[ns] = k
            ns += 1
    for k in range(3):    # B[k, k] = 1, B[k + 1, k] = -1
        F[k] += tau[k]
        F[k + 1] -= tau[k]
    if ns > 0:
        A = np.zeros((ns, ns))
        b = np.zeros(ns)
        for i in range(ns):
            ki = stuck[i]
            b[i] = -(F[ki] - F[ki + 1])           # -B_S^T M^-1 F0 (J = 1)
            for j in range(ns):
                kj = stuck[j]
                v = 0.0
                if ki == kj:
                    v = 2.0
                elif abs(ki - kj) == 1:
                    v = -1.0
                A[i, j] = v
        x = np.linalg.solve(A, b)
        for i in range(ns):
            ki = stuck[i]
            tau[ki] = x[i]
            F[ki] += x[i]
            F[ki + 1] -= x[i]
    for i in range(4):
        a[i] = F[i]


@numba.njit(cache=True)
def _rhs(t, y, modes):
    tau = np.empty(3)
    a = np.empty(4)
    _torques(t, y, modes, tau, a)
    dy = np.empty(12)
    for i in range(4):
        dy[i] = a[i]
        dy[4 + i] = y[i]
    dy[8] = 10.0 * math.sin(2.0 * math.pi * 5.0 * t) * y[0]
    for k in range(3):
        dy[9 + k] = tau[k] * (y[k + 1] - y[k])
    return dy


@numba.njit(cache=True)
def _stuck_torque(t, y, modes, k):
    tau = np.empty(3)
    a = np.empty(4)
    _torques(t, y, modes, tau, a)
    return tau[k]


def make_rhs(modes):
    """The reference's ``make_rhs`` with a compiled body."""
    codes = np.array([_CODES[m] for m in modes], dtype=np.int64)

    def rhs(t, y):
        return _rhs(t, y, codes)
    return rhs


def make_events(modes):
    """The reference's ``make_events`` with compiled torques (the stick functions are plain differences)."""
    codes = np.array([_CODES[m] for m in modes], dtype=np.int64)
    evs = []

    def add(fun, direction, desc):
        fun.terminal = True
        fun.direction = direction
        evs.append((fun, desc))

    for k in range(3):
        m = modes[k]
        if m in (ref.FWD, ref.BWD):
            def g(t, y, k=k):
                return y[k + 1] - y[k]
            add(g, -1.0 if m == ref.FWD else 1.0, ("wrel", k))
        elif m == ref.STICK:
            def gf(t, y, k=k):
                return _stuck_torque(t, y, codes, k) - ref.tau0_max(ref.f_norm(t)[k])

            def gb(t, y, k=k):
                return -_stuck_torque(t, y, codes, k) - ref.tau0_max(ref.f_norm(t)[k])
            add(gf, 1.0, ("break", k, ref.FWD))
            add(gb, 1.0, ("break", k, ref.BWD))

    def gfree(t, y):
        return ref.f1(t)
    add(gfree, 0.0, ("f1",))
    return evs
