"""The wet clutch as a driveline element: the network of :mod:`clutchlab.driveline.kernel` with wet clutches
whose torque comes from their own states (piston, actuator force, film, pack and oil temperatures).

The clutch is the engagement model of :mod:`clutchlab.wet.system` (Shin, Kim and Choi, seed 001, Eqs. 1-8;
squeeze film and piston of Deur et al.), unchanged: its hooks are called here on its own states with the
slip speed replaced by the element's relative speed ``w_b - w_a`` (flange a: the outer plates, b: the inner),
with no bench motor (``free_inertia``: the network is the drive).  Its two parts meet through two numbers
per evaluation (:func:`clutchlab.driveline.kernel.set_external`):

* the **sliding torque** ``|tau| = R_eff N_c mu_f F_c + |tau_v|`` (Eqs. 3-6 at the present slip), used by the
  network while the element slides;
* the **static limit** ``R_eff N_c mu_f F_c`` (Eq. 4 at the present slip; at lock-up the slip is zero), the
  torque the element holds while stuck, and also the torque it must cover to lock up (the lock-up limit of
  :func:`~clutchlab.driveline.kernel.set_external` equals it).

The network's friction state machine decides stick and slip (the wet model's own ``lockup``/``breakaway``
switching functions are held off: they watch the bench's shaft, which is now a body of the network); the
network's mode is passed to the wet model, so its friction heat ``tau * w`` is zero while stuck.  The wet
model's piston and film switching functions and events (``contact``, ``separation``, ``piston_reaches_stop``,
``piston_leaves_stop``) are kept, named for the element (``<name>`` and ``<name>.piston``), and so are its
``piston_runs`` / ``piston_turns`` functions (the turn of a running piston ends a step; no event).

States: the network's, then per clutch the wet model's twelve (its ``slip_speed`` follows the element's
relative speed, integrated from the relative acceleration and reset to it at every event; its drive states
stay zero).  Its force is a port: the element's network signal (any signal: a table, a sine, a pulse, a
product, a network input ``{ input = "F" }``) read at every evaluation (:func:`hold`) into the model's
``force_reference`` input on a zero profile, saturated at 0 N, as the EMTC coupling's ports
(:mod:`clutchlab.driveline.emtc`); its corners are the network's breaks, and the actuator starts at the signal's
value at t = 0 (an input's start).  Outputs: the network's, then per clutch the wet model's own twelve (:data:`OUTPUTS`: its eighteen
without the six of its bench, :data:`BENCH_ONLY`).  Any number of wet clutches:
each is packed on its own and evaluated with its own hooks (its parameters one row of a :class:`WetBlock`;
:mod:`clutchlab.driveline.coupled` joins them to the network and its EMTC couplings).
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numba
import numpy as np

from ..numerics.borrow import block_row, row_words, stack_rows
from ..wet import system as W
from . import kernel as K
from .block import buffer_slots, conf_slots

__all__ = ["WetBlock", "block", "N_STATE", "N_SWITCH", "N_MODE", "OUTPUTS", "BENCH_ONLY"]

N_STATE, N_SWITCH, N_MODE = W.N_STATE, W.N_SWITCH, len(W.MODE_NAMES)
#: conf (int64, a row per clutch, :func:`~clutchlab.driveline.block.conf_slots`): the block's head (its first named
#: element ``<name>``, then ``<name>.piston``) and the network signal its force port reads
CONF = conf_slots(("force_port", 1))
F_K, F_ROW, F_X, F_G, F_M, F_EV, F_EL, F_U = CONF.of(
    "friction", "row", "states", "switching", "modes", "events", "element", "force_port")
N_CONF = CONF.total
#: buf (float, :func:`~clutchlab.driveline.block.buffer_slots`): its states with the slip replaced, their
#: derivative, switching values, its model's inputs (the force reference added to its zero profile: the force
#: port's value; no slip reference), outputs
BUF = buffer_slots(W.STATES, W.SWITCHING, W.INPUTS, W.OUTPUTS)
B_X, B_DX, B_G, B_U, B_Y = BUF.of("states", "derivative", "switching", "inputs", "outputs")
N_BUF = BUF.total
#: outputs of the wet model that belong to its bench, as the wet model declares them
#: (:data:`clutchlab.wet.system.BENCH_OUTPUTS`).  A network reports the clutch's own (:data:`OUTPUTS`; #33)
BENCH_ONLY = W.BENCH_OUTPUTS
#: a wet clutch's outputs in a network, ``(quantity, unit, description)``, and their places in the model's
OUTPUTS = tuple(o for o in W.OUTPUTS if o[0] not in BENCH_ONLY)
KEPT = np.array([i for i, o in enumerate(W.OUTPUTS) if o[0] not in BENCH_ONLY], dtype=np.int64)
N_KEPT = len(OUTPUTS)


class WetBlock(NamedTuple):
    """The wet clutches of a network (rows ``j``, none or more): ``params``, their parameters packed by
    :func:`clutchlab.wet.system.pack_parameters` with the inertia dynamometer's free shaft and stacked as rows
    (:func:`clutchlab.numerics.borrow.stack_rows`, as the EMTC block's: any number of clutches, each with its own
    profiles and friction law, is one type), ``conf[j]`` (int64, the layout ``F_*``), ``buf[j]`` (float, scratch
    ``B_*``), ``mbuf[j]`` (int64, its modes) and ``rows[j]`` (float64, the clutch's
    :class:`~clutchlab.wet.system.WetParams` built from its row once per call of the core,
    :func:`clutchlab.numerics.borrow.keep_rows`; read by reference, ``block_row``).  A member
    of :class:`clutchlab.driveline.coupled.CoupledParams`."""

    params: W.WetParams
    conf: np.ndarray
    buf: np.ndarray
    mbuf: np.ndarray
    rows: np.ndarray


@functools.lru_cache(maxsize=1)
def _template():
    """A :class:`~clutchlab.wet.system.WetParams` of the packed kind: the types of an empty :class:`WetBlock`."""
    return W.WetParams(np.zeros(1, dtype=W.CONSTANTS_DTYPE), np.zeros(1))


def block(params, conf) -> WetBlock:
    """The block of the clutches packed as ``params`` (a list of :class:`~clutchlab.wet.system.WetParams`) with their
    layouts ``conf`` (rows ``F_*``); no clutch for empty lists."""
    n = len(params)
    stacked = stack_rows(params, template=None if params else _template())
    return WetBlock(stacked, np.array(conf, dtype=np.int64).reshape(n, N_CONF), np.zeros((n, N_BUF)),
                    np.zeros((n, N_MODE), dtype=np.int64), np.zeros((n, row_words(stacked))))


@numba.njit(cache=True, nogil=True, _nrt=False)
def _clutch(t, x, m, net, w, j):
    """Evaluate wet clutch ``j`` at the network's state: its derivative, switching values and outputs into
    ``w.buf[j]``, its sliding torque and static limit into the network (:func:`kernel.set_external`).
    Returns the element's relative speed [rad/s]."""
    cf = w.conf[j]
    n = net.inertia.shape[0]
    r = cf[F_ROW]
    w_rel = K.relative_speed(net, r, x, n)
    b = w.buf[j]
    xs = b[B_X:B_X + N_STATE]
    for i in range(N_STATE):
        xs[i] = x[cf[F_X] + i]
    xs[W.S_W] = w_rel
    ms = w.mbuf[j]
    for i in range(N_MODE):
        ms[i] = m[cf[F_M] + i]
    mk = m[cf[F_K]]
    ms[W.M_FRICTION] = W.STICK if mk == K.STUCK else (W.SLIP_NEG if mk == K.BACKWARD or (mk == K.FREE and w_rel < 0.0)
                                                    else W.SLIP)
    wp = block_row(w, j)
    W.wet_rhs(t, xs, b[B_U:B_U + 2], ms, wp, b[B_DX:B_DX + N_STATE], b[B_G:B_G + N_SWITCH])
    wk = wp.data
    cap = wk[W.W_OUT + W.O_CAP]
    K.set_external(net, net.elem[r][K.E_AUX], cap + abs(wk[W.W_OUT + W.O_TV]), cap, cap)
    for i in range(W.N_OUT):
        b[B_Y + i] = wk[W.W_OUT + i]
    return w_rel


@numba.njit(cache=True, nogil=True, _nrt=False)
def hold(t, net, w):
    """Each clutch's force port at ``t``: its model's ``force_reference`` input (added to its zero profile) is the
    value of the network signal it reads (any signal; a network input as the host holds it: the caller has brought
    the network's held inputs up to the core's ``u``), saturated at 0 (an actuator pushes; a negative reference
    releases it; the model saturates at its maximum)."""
    for j in range(w.conf.shape[0]):
        w.buf[j][B_U + W.U_FORCE] = max(K.signal_at(net, w.conf[j][F_U], t), 0.0)


@numba.njit(cache=True, nogil=True, _nrt=False)
def evaluate(t, x, m, net, w):
    """Evaluate every wet clutch (:func:`_clutch`)."""
    for j in range(w.conf.shape[0]):
        _clutch(t, x, m, net, w, j)


@numba.njit(cache=True, nogil=True, _nrt=False)
def derivatives(net, w, acc, dx, g):
    """Each clutch's derivatives and switching functions after the network's right-hand side (its slip speed
    follows the element's relative acceleration ``acc``; its lock-up and break-away functions are held off)."""
    for j in range(w.conf.shape[0]):
        cf = w.conf[j]
        b = w.buf[j]
        e = net.elem[cf[F_ROW]]
        K.copy_component(dx, g, b, cf[F_X], cf[F_G], N_STATE, N_SWITCH, B_DX, B_G)
        dx[cf[F_X] + W.S_W] = (0.0 if e[K.E_B] < 0 else acc[e[K.E_B]]) - (0.0 if e[K.E_A] < 0 else acc[e[K.E_A]])
        dx[cf[F_X] + W.S_I] = 0.0
        dx[cf[F_X] + W.S_ED] = 0.0
        g[cf[F_G] + W.G_LOCKUP] = 1.0
        g[cf[F_G] + W.G_BREAKAWAY] = -1.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def outputs(w, y, q):
    """Each clutch's own outputs (:data:`OUTPUTS`: the model's without its bench's) into ``y`` from ``q`` on;
    returns the index after them."""
    for j in range(w.conf.shape[0]):
        for i in range(N_KEPT):
            y[q + i] = w.buf[j][B_Y + KEPT[i]]
        q += N_KEPT
    return q


@numba.njit(cache=True, nogil=True, _nrt=False)
def _rename(log, start, w, j):
    """Clutch ``j``'s events recorded from ``start`` on: codes after the network's, elements after its names."""
    for i in range(start, min(log.count[0], log.time.shape[0])):
        log.code[i] += w.conf[j][F_EV]
        log.element[i] += w.conf[j][F_EL]


@numba.njit(cache=True, nogil=True, _nrt=False)
def sync(x, m, net, w):
    """Each clutch's slip-speed state reset to its element's relative speed, and its friction mode to the
    network's (at an event or a restart)."""
    n = net.inertia.shape[0]
    for j in range(w.conf.shape[0]):
        cf = w.conf[j]
        w_rel = K.relative_speed(net, cf[F_ROW], x, n)
        x[cf[F_X] + W.S_W] = w_rel
        mk = m[cf[F_K]]
        m[cf[F_M] + W.M_FRICTION] = W.STICK if mk == K.STUCK else (
            W.SLIP_NEG if mk == K.BACKWARD or (mk == K.FREE and w_rel < 0.0) else W.SLIP)


@numba.njit(cache=True, nogil=True, _nrt=False)
def call(t, x, m, w, j, k, log):
    """Clutch ``j``'s model hook on its own states and modes (``k >= 0``: its update for switching function
    ``k``; ``k < 0``: its restart), its events renamed; the states and the piston, film and piston-run modes
    written back."""
    cf = w.conf[j]
    b = w.buf[j]
    xs = b[B_X:B_X + N_STATE]
    ms = w.mbuf[j]
    start = log.count[0]
    res = 0
    if k >= 0:
        res = W.wet_update(t, xs, b[B_U:B_U + 2], ms, block_row(w, j), k, log)
    elif W.wet_restart(t, xs, b[B_U:B_U + 2], ms, block_row(w, j), log):
        res = 1
    _rename(log, start, w, j)
    for i in range(N_STATE):
        if i != W.S_W:
            x[cf[F_X] + i] = xs[i]
    for i in range(N_MODE):  # the piston, film and piston-run modes (the friction mode is the network's)
        if i != W.M_FRICTION:
            m[cf[F_M] + i] = ms[i]
    return res


@numba.njit(cache=True, nogil=True, _nrt=False)
def accept(t, x, u, m, w):
    """Each wet clutch's peak-temperature memory."""
    for j in range(w.conf.shape[0]):
        o = w.conf[j][F_X]
        W.wet_accept(t, x[o:o + N_STATE], u, m, block_row(w, j))


@numba.njit(cache=True, nogil=True, _nrt=False)
def next_break(t, m, w, tb):
    """The earlier of ``tb`` and the next corner of a clutch's force profile."""
    for j in range(w.conf.shape[0]):
        tb = min(tb, W.wet_next_break(t, m, block_row(w, j)))
    return tb
