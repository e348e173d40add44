"""Toy systems for testing the integrator core on its own (closed-form solutions).

Each toy implements the system contract (:mod:`clutchlab.system`) the way a
clutch model does: a parameter NamedTuple, compiled hooks registered for it,
and a :class:`~clutchlab.system.System` factory.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from clutchlab.numerics import dispatch
from clutchlab.numerics.core import record
from clutchlab.system import System


# ------------------------------------------------------------------ linear test equation / oscillator
class LinearParams(NamedTuple):
    """x' = A x + B u."""

    a: np.ndarray
    b: np.ndarray


@numba.njit(cache=True)
def _lin_rhs(t, x, u, m, p, dx, g):
    n = x.shape[0]
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += p.a[i, j] * x[j]
        for j in range(u.shape[0]):
            s += p.b[i, j] * u[j]
        dx[i] = s


@numba.njit(cache=True)
def _lin_outputs(t, x, u, m, p, y):
    for i in range(y.shape[0]):
        y[i] = x[i]


@numba.njit(cache=True)
def _no_update(t, x, u, m, p, k, log):
    return 0


@numba.njit(cache=True)
def _no_restart(t, x, u, m, p, log):
    return False


@numba.njit(cache=True)
def _no_accept(t, x, u, m, p):
    return 0


@numba.njit(cache=True)
def _no_break(t, m, p):
    return np.inf


@numba.njit(cache=True)
def _lin_jac(t, x, u, m, p, J):
    for i in range(x.shape[0]):
        for j in range(x.shape[0]):
            J[i, j] = p.a[i, j]
    return True


dispatch.register(LinearParams, rhs=_lin_rhs, outputs=_lin_outputs, update=_no_update, restart=_no_restart,
                  accept=_no_accept, next_break=_no_break, jacobian=_lin_jac)


def linear_system(a, x0, b=None, method="dopri", mass=None):
    a = np.atleast_2d(np.asarray(a, dtype=float))
    n = a.shape[0]
    b = np.zeros((n, 0)) if b is None else np.atleast_2d(np.asarray(b, dtype=float))
    states = tuple((f"x{i}", "1") for i in range(n))
    return System("linear", LinearParams(a, b), states, states, np.asarray(x0, float), np.zeros(0, np.int64),
                  np.full(n, 1e-12), inputs=tuple((f"u{i}", "1") for i in range(b.shape[1])), method=method,
                  mass=mass, rtol=1e-8)


# ------------------------------------------------------------------ bouncing ball
class BallParams(NamedTuple):
    """Ball under gravity bouncing on the ground with restitution e."""

    gravity: float
    restitution: float


@numba.njit(cache=True)
def _ball_rhs(t, x, u, m, p, dx, g):
    dx[0] = x[1]
    dx[1] = -p.gravity
    g[0] = x[0]  # height: an event when it falls through zero


@numba.njit(cache=True)
def _ball_update(t, x, u, m, p, k, log):
    x[0] = 0.0
    x[1] = -p.restitution * x[1]
    m[0] += 1
    record(log, t, 0, -1)
    return 1 if m[0] >= 4 else 0  # the fourth bounce is terminal


@numba.njit(cache=True)
def _no_jac(t, x, u, m, p, J):
    return False


dispatch.register(BallParams, rhs=_ball_rhs, outputs=_lin_outputs, update=_ball_update, restart=_no_restart,
                  accept=_no_accept, next_break=_no_break, jacobian=_no_jac)


def ball_system(h0=1.0, e=0.5, method="dopri"):
    return System("ball", BallParams(9.81, e), (("height", "m"), ("velocity", "m_s")),
                  (("height", "m"), ("velocity", "m_s")), np.array([h0, 0.0]), np.zeros(1, np.int64),
                  np.full(2, 1e-12), switching=(("height", -1),), events=("bounce",), mode_names=("bounces",),
                  mode_values=(tuple(str(i) for i in range(5)),), method=method, rtol=1e-10)


# ------------------------------------------------------------------ sine with a directional event and a break
class SineParams(NamedTuple):
    """x' = cos(t): x = sin(t); switching function x (direction per the System); breaks every ``period``."""

    period: float


@numba.njit(cache=True)
def _sine_rhs(t, x, u, m, p, dx, g):
    dx[0] = math.cos(t)
    g[0] = x[0]


@numba.njit(cache=True)
def _sine_update(t, x, u, m, p, k, log):
    record(log, t, 0, k)
    return 0


@numba.njit(cache=True)
def _sine_restart(t, x, u, m, p, log):
    m[0] += 1  # counts the break times seen
    return False


@numba.njit(cache=True)
def _sine_break(t, m, p):
    if p.period <= 0.0:
        return np.inf
    return (math.floor(t / p.period + 1e-9) + 1.0) * p.period


dispatch.register(SineParams, rhs=_sine_rhs, outputs=_lin_outputs, update=_sine_update, restart=_sine_restart,
                  accept=_no_accept, next_break=_sine_break, jacobian=_no_jac)


def sine_system(direction=0, period=0.0, method="dopri"):
    return System("sine", SineParams(period), (("x", "1"),), (("x", "1"),), np.zeros(1), np.zeros(1, np.int64),
                  np.full(1, 1e-12), switching=(("x", direction),), events=("zero",), mode_names=("restarts",),
                  mode_values=(tuple(str(i) for i in range(1000)),), method=method, rtol=1e-10)


# ------------------------------------------------------------------ Coulomb stick-slip: mass on a moving belt
class BeltParams(NamedTuple):
    """Mass m on spring k to ground, Coulomb friction to a belt at speed v_b (static mu_s, kinetic mu_k)."""

    mass: float
    stiffness: float
    belt_speed: float
    normal_force: float
    mu_s: float
    mu_k: float


SLIP_FWD, STUCK, SLIP_BWD = 0, 1, 2  # relative to the belt: mass slower than the belt = forward friction


@numba.njit(cache=True)
def _belt_rhs(t, x, u, m, p, dx, g):
    spring = -p.stiffness * x[0]
    if m[0] == STUCK:
        dx[0] = p.belt_speed
        dx[1] = 0.0
        g[0] = abs(spring) - p.mu_s * p.normal_force  # break-away when the spring exceeds static friction
        g[1] = -1.0
    else:
        sgn = 1.0 if m[0] == SLIP_FWD else -1.0
        dx[0] = x[1]
        dx[1] = (spring + sgn * p.mu_k * p.normal_force) / p.mass
        g[0] = -1.0
        g[1] = sgn * (x[1] - p.belt_speed)  # relative speed reaches zero: rises through 0
    

@numba.njit(cache=True)
def _belt_update(t, x, u, m, p, k, log):
    if k == 0:
        m[0] = SLIP_BWD if -p.stiffness * x[0] > 0.0 else SLIP_FWD  # spring pushes the mass ahead of the belt: backward friction
        record(log, t, 0, 0)
    else:
        x[1] = p.belt_speed
        if abs(p.stiffness * x[0]) <= p.mu_s * p.normal_force:
            m[0] = STUCK
            record(log, t, 1, 0)
        else:
            m[0] = SLIP_BWD if m[0] == SLIP_FWD else SLIP_FWD
            record(log, t, 2, 0)
    return 0


@numba.njit(cache=True)
def _belt_accept(t, x, u, m, p):
    if m[0] == STUCK:
        x[1] = p.belt_speed
    return 0


dispatch.register(BeltParams, rhs=_belt_rhs, outputs=_lin_outputs, update=_belt_update, restart=_no_restart,
                  accept=_belt_accept, next_break=_no_break, jacobian=_no_jac)


def belt_system(method="dopri", mass=1.0, k=100.0, vb=0.1, fn=10.0, mu_s=0.5, mu_k=0.3):
    return System("belt", BeltParams(mass, k, vb, fn, mu_s, mu_k), (("position", "m"), ("velocity", "m_s")),
                  (("position", "m"), ("velocity", "m_s")), np.array([0.0, vb]), np.array([STUCK], np.int64),
                  np.full(2, 1e-12), switching=(("breakaway", 1), ("stick", 1)),
                  events=("breakaway", "stick", "reversal"), mode_names=("friction",),
                  mode_values=(("forward", "stick", "backward"),), method=method, rtol=1e-10,
                  fd_scale=np.array([1e-3, 1e-2]))


# ------------------------------------------------------------------ chain of masses (sparse Jacobian, no analytic one)
class ChainParams(NamedTuple):
    """n unit masses in a chain of springs k (fixed ends) with dampers c, a cubic spring at each node."""

    stiffness: float
    damping: float
    cubic: float


@numba.njit(cache=True)
def _chain_rhs(t, x, u, m, p, dx, g):
    n = x.shape[0] // 2
    for i in range(n):
        left = x[i - 1] if i > 0 else 0.0
        right = x[i + 1] if i < n - 1 else 0.0
        dx[i] = x[n + i]
        dx[n + i] = (p.stiffness * (left - 2.0 * x[i] + right) - p.damping * x[n + i] - p.cubic * x[i] ** 3)


dispatch.register(ChainParams, rhs=_chain_rhs, outputs=_lin_outputs, update=_no_update, restart=_no_restart,
                  accept=_no_accept, next_break=_no_break, jacobian=_no_jac)


def chain_system(n=8, pattern=True):
    pat = None
    if pattern:
        pat = np.zeros((2 * n, 2 * n), dtype=bool)
        for i in range(n):
            pat[i, n + i] = True
            for j in (i - 1, i, i + 1):
                if 0 <= j < n:
                    pat[n + i, j] = True
            pat[n + i, n + i] = True
    x0 = np.zeros(2 * n)
    x0[0] = 0.1
    states = tuple((f"x{i}", "m") for i in range(n)) + tuple((f"v{i}", "m_s") for i in range(n))
    return System("chain", ChainParams(1e4, 5.0, 1e5), states, states, x0, np.zeros(0, np.int64), np.full(2 * n, 1e-9),
                  method="rodas", jac_pattern=pat, fd_scale=np.full(2 * n, 1e-3), rtol=1e-6)


# ------------------------------------------------------------------ a speed that jumps to its limit after an event
class RampParams(NamedTuple):
    """x' = 0 until t = ``t_event`` (an event), then x' = v_max tanh((t - t_event) / tau): the speed reaches
    its limit within a few ``tau`` (the wet clutch's piston leaving its stop).  ``codes``: what ``update``
    returns for each of the two switching functions (both t - t_event, rising)."""

    t_event: float
    tau: float
    v_max: float
    codes: tuple


@numba.njit(cache=True)
def _ramp_rhs(t, x, u, m, p, dx, g):
    dx[0] = p.v_max * math.tanh((t - p.t_event) / p.tau) if m[0] == 1 else 0.0
    g[0] = t - p.t_event
    g[1] = t - p.t_event


@numba.njit(cache=True)
def _ramp_update(t, x, u, m, p, k, log):
    m[0] = 1
    record(log, t, k, -1)
    return p.codes[k]


dispatch.register(RampParams, rhs=_ramp_rhs, outputs=_lin_outputs, update=_ramp_update, restart=_no_restart,
                  accept=_no_accept, next_break=_no_break, jacobian=_no_jac)


def ramp_system(codes=(0, 0), t_event=0.0723, tau=1e-6, v_max=0.1, atol=1e-8):
    """x(t) = v_max tau ln cosh((t - t_event) / tau) after the event."""
    return System("ramp", RampParams(t_event, tau, v_max, tuple(int(c) for c in codes)), (("x", "m"),),
                  (("x", "m"),), np.zeros(1), np.zeros(1, np.int64), np.full(1, atol),
                  switching=(("start", 1), ("start_too", 1)), events=("start", "start_too"), mode_names=("moving",),
                  mode_values=(("no", "yes"),), rtol=1e-8, max_step=0.01)


# ------------------------------------------------------------------ the oscillator with hooks compiled without reference counting
class LinearNoRefcountParams(NamedTuple):
    """:class:`LinearParams` again, its hooks declared with ``numba.njit(_nrt=False)``."""

    a: np.ndarray
    b: np.ndarray


_lin_rhs_no_nrt = numba.njit(_nrt=False)(_lin_rhs.py_func)
_lin_outputs_no_nrt = numba.njit(_nrt=False)(_lin_outputs.py_func)
dispatch.register(LinearNoRefcountParams, rhs=_lin_rhs_no_nrt, outputs=_lin_outputs_no_nrt, update=_no_update,
                  restart=_no_restart, accept=_no_accept, next_break=_no_break, jacobian=_lin_jac)


def linear_system_no_refcount(a, x0, method="dopri"):
    base = linear_system(a, x0, method=method)
    return base.replace(params=LinearNoRefcountParams(*base.params))
