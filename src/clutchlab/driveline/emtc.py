"""The EMTC coupling as a driveline element: the network of :mod:`clutchlab.driveline.kernel` with the
electromagnetic torque-controlled coupling of seed 002 between two of its flanges.

The coupling is the model of :mod:`clutchlab.emtc.system` (Processes 7 (2019) 557, Eqs. 1-26 and 31),
unchanged and called through the system contract (:mod:`clutchlab.numerics.dispatch`): its coil current
lags, the Preisach magnet (Eqs. 1-5) at the airgap of its armature (Eqs. 8-12), the ball-cam and the three
friction elements (Eqs. 13-21), the drag of the open coupling (Eq. 25) and its controller (the torque
reference of Eq. 31 or a table, the commanded force of Eqs. 13, 15 and 11, the inverse Preisach model of
Eqs. 6-7, sampled every ``sample_time``).  Flange a is the coupling's input (front) shaft, flange b its
output (rear) shaft: the coupling's slip speed is ``w_a - w_b`` (``omega_f - omega_r``), minus the
element's relative speed ``w_b - w_a``.

What the drum bench's own model does with its two shafts (the vehicle loads of Eq. 27, the lock torque
of Eq. 29, the Torsen twist of Eq. 30, the lock-up and unlock decisions of Fig. 11) is the network's
here.  The two parts meet through three numbers per evaluation (:func:`clutchlab.driveline.kernel.set_external`):

* the **sliding torque**: while the armature presses the primary clutch, ``|T1 + T2 + T3|`` of the
  slipping mode (Eqs. 13-15, 17, with the coupling's kinetic coefficients or friction map); while it
  does not, the drag ``|T_drag|`` of Eq. 25 at the present slip (Eq. 26);
* the **static limit**: ``1.02 T_cap_L`` (Eq. 21 with the unlock margin of Fig. 11) while the armature
  presses, 0 while it does not (an open coupling holds nothing: at zero slip it passes through): a stuck
  coupling breaks away beyond it;
* the **lock-up limit** ``T_cap_L``: the torque the coupling must cover to lock when its slip reaches zero
  (below it the slip reverses, Fig. 11).

The network's friction state machine decides stick and slip (the bench model's ``slip_speed_zero`` and
``lock_capacity_exceeded`` switching functions are held off).  A stuck coupling carries the torque the
network's constraint solve gives it: for the two shafts of the bench, that is Eq. 29's ``T_lock``, and
the Torsen twist of Eq. 30 stays zero (its terms vanish identically while both shafts turn together).

The armature events (``armature_rest``, ``armature_contact``, ``armature_leave_rest``,
``armature_leave_contact``) are kept and named for the element (``<name>.armature``).

States: the network's, then the coupling's seven (:data:`clutchlab.emtc.system.STATES`; its two shaft
speeds follow the flanges, integrated from their accelerations and reset to them at every event, its
Torsen twist stays zero).  Outputs: the network's, then the coupling's :data:`OUTPUTS`.  One EMTC per
network (its parameters are one :class:`~clutchlab.emtc.system.EmtcParams`).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from ..emtc import system as S
from ..numerics import dispatch
from ..numerics.borrow import byref
from .kernel import DrivelineParams
from . import kernel as K

__all__ = ["EmtcDrivelineParams", "N_STATE", "N_SWITCH", "N_MODE", "OUTPUTS", "OUTPUT_INDEX"]

N_STATE, N_SWITCH, N_MODE, N_IN = len(S.STATES), len(S.SWITCHING), len(S.MODE_NAMES), len(S.INPUTS)
# conf (int64): the friction index of the coupling, its element row, then the offsets of its states, switching
# functions and modes in the whole system's, the number of the network's events and the index of its first named
# element (``<name>.armature``, then ``<name>.coupling``)
F_K, F_ROW, F_X, F_G, F_M, F_EV, F_EL = range(7)
# buf (float): its states with the shaft speeds replaced | their derivative | switching values | inputs (zero) |
# outputs
B_X, B_DX, B_G, B_U = 0, N_STATE, 2 * N_STATE, 2 * N_STATE + N_SWITCH
B_Y = B_U + N_IN
N_BUF = B_Y + len(S.OUTPUTS)
#: the coupling's outputs in a network (the bench model's others describe its vehicle: here the network's)
OUTPUTS = tuple(o for o in S.OUTPUTS if o[0] in ("airgap", "magnet_force", "fn1", "capacity_locked",
                                                 "current_command", "torque_reference", "throttle",
                                                 "command_feasible"))
OUTPUT_INDEX = np.array([[o[0] for o in S.OUTPUTS].index(q[0]) for q in OUTPUTS], dtype=np.int64)
# what the network reads of the coupling: its published outputs, modes and switching functions (by name)
_Y_TC = [o[0] for o in S.OUTPUTS].index("coupling_torque")
_Y_CAP = [o[0] for o in S.OUTPUTS].index("capacity_locked")
_ARM, _CPL, _DIR = (S.MODE_NAMES.index(q) for q in ("armature_mode", "coupling_mode", "slip_direction"))
_CONTACT = S.MODE_VALUES[_ARM].index("contact")
_OPEN, _SLIPPING = (S.MODE_VALUES[_CPL].index(q) for q in ("open", "slipping"))
_NEGATIVE, _POSITIVE = (S.MODE_VALUES[_DIR].index(q) for q in ("negative", "positive"))
_REST = S.MODE_VALUES[_ARM].index("rest")
# the bench's switching functions the network takes over
_SLIP_ZERO, _UNLOCK = ([q[0] for q in S.SWITCHING].index(q) for q in ("slip_speed_zero", "lock_capacity_exceeded"))


class EmtcDrivelineParams(NamedTuple):
    """Packed parameters of a driveline with an EMTC coupling: the network, the coupling's parameters packed
    by :func:`clutchlab.emtc.system.pack_parameters` (its vehicle data used only by its controller's map and
    its drag data), ``conf`` (int64, the layout ``F_*``), ``buf`` (float, scratch ``B_*``), ``mbuf`` (int64,
    its modes) and ``index`` (int64, :data:`OUTPUT_INDEX`)."""

    net: DrivelineParams
    emtc: S.EmtcParams
    conf: np.ndarray
    buf: np.ndarray
    mbuf: np.ndarray
    index: np.ndarray


@numba.njit(cache=True, nogil=True)
def _load(x, m, p):
    """The coupling's own states and modes from the network's into ``p.buf``/``p.mbuf``: its shaft speeds
    are the flanges', its coupling mode ``slipping`` while the armature presses (else ``open``), its slip
    direction the network's (stuck: ``positive``; the torque magnitudes do not depend on it)."""
    cf = p.conf
    net = byref(p.net)
    n = net.inertia.shape[0]
    e = net.elem[cf[F_ROW]]
    b = p.buf
    for i in range(N_STATE):
        b[B_X + i] = x[cf[F_X] + i]
    b[B_X] = K._speed(x, n, e[K.E_A])
    b[B_X + 1] = K._speed(x, n, e[K.E_B])
    b[B_X + 2] = 0.0
    ms = p.mbuf
    ms[_ARM] = m[cf[F_M] + _ARM]
    ms[_CPL] = _SLIPPING if ms[_ARM] == _CONTACT else _OPEN
    ms[_DIR] = _NEGATIVE if m[cf[F_K]] == K.FORWARD else _POSITIVE


@numba.njit(cache=True, nogil=True)
def _coupling(t, x, m, p):
    """Evaluate the coupling at the network's state (:func:`_load`) through its hooks: its derivative,
    switching values and outputs into ``p.buf``, its sliding torque (its output ``coupling_torque``) and
    static and lock-up limits (from ``capacity_locked``) into the network (:func:`kernel.set_external`)."""
    _load(x, m, p)
    b = p.buf
    xs = b[B_X:B_X + N_STATE]
    us = b[B_U:B_U + N_IN]
    dispatch.rhs(t, xs, us, p.mbuf, byref(p.emtc), b[B_DX:B_DX + N_STATE], b[B_G:B_G + N_SWITCH])
    dispatch.outputs(t, xs, us, p.mbuf, byref(p.emtc), b[B_Y:N_BUF])   # (the same point: the model reuses it)
    net = byref(p.net)
    cap = b[B_Y + _Y_CAP] if p.mbuf[_ARM] == _CONTACT else 0.0
    K.set_external(net, net.elem[p.conf[F_ROW]][K.E_AUX], abs(b[B_Y + _Y_TC]), p.emtc.coupling.unlock_margin * cap,
                   cap)


@numba.njit(cache=True, nogil=True)
def emtc_driveline_rhs(t, x, u, m, p, dx, g):
    """The network's right-hand side and switching functions, then the coupling's (its shaft speeds follow
    the flanges' accelerations; its lock-up and unlock functions are held off)."""
    _coupling(t, x, m, p)
    net = byref(p.net)
    K.driveline_rhs(t, x, u, m, net, dx, g)
    acc, _tau = K._acc_tau(net)
    cf = p.conf
    b = p.buf
    e = net.elem[cf[F_ROW]]
    for i in range(N_STATE):
        dx[cf[F_X] + i] = b[B_DX + i]
    dx[cf[F_X]] = 0.0 if e[K.E_A] < 0 else acc[e[K.E_A]]
    dx[cf[F_X] + 1] = 0.0 if e[K.E_B] < 0 else acc[e[K.E_B]]
    dx[cf[F_X] + 2] = 0.0
    for i in range(N_SWITCH):
        g[cf[F_G] + i] = b[B_G + i]
    g[cf[F_G] + _SLIP_ZERO] = 1.0
    g[cf[F_G] + _UNLOCK] = 1.0
    return None


@numba.njit(cache=True, nogil=True)
def emtc_driveline_outputs(t, x, u, m, p, y):
    """The network's outputs, then the coupling's (:data:`OUTPUTS`)."""
    _coupling(t, x, m, p)
    K.driveline_outputs(t, x, u, m, byref(p.net), y)
    b = p.buf
    q = y.shape[0] - p.index.shape[0]
    for i in range(p.index.shape[0]):
        y[q + i] = b[B_Y + p.index[i]]


@numba.njit(cache=True, nogil=True)
def _sync(x, m, p):
    """The coupling's shaft-speed states reset to its flanges' speeds, its twist to zero (an event, a restart)."""
    net = byref(p.net)
    n = net.inertia.shape[0]
    cf = p.conf
    e = net.elem[cf[F_ROW]]
    x[cf[F_X]] = K._speed(x, n, e[K.E_A])
    x[cf[F_X] + 1] = K._speed(x, n, e[K.E_B])
    x[cf[F_X] + 2] = 0.0


@numba.njit(cache=True, nogil=True)
def _write_back(x, m, p, start, log):
    """The coupling's armature and current states and its armature mode from ``p.buf``/``p.mbuf`` into the
    network's, its events from ``start`` on renamed (codes after the network's, elements after its names)."""
    cf = p.conf
    for i in range(3, N_STATE):
        x[cf[F_X] + i] = p.buf[B_X + i]
    m[cf[F_M] + _ARM] = p.mbuf[_ARM]
    for i in range(start, min(log.count[0], log.time.shape[0])):
        log.code[i] += cf[F_EV]
        log.element[i] += cf[F_EL]


@numba.njit(cache=True, nogil=True)
def emtc_driveline_update(t, x, u, m, p, k, log):
    """Switching function ``k`` crossed: the network's (:func:`kernel.driveline_update`) or one of the
    coupling's armature functions (its own update: rest stop, contact, leaving them); then the network's
    modes at the coupling's new torque."""
    _sync(x, m, p)
    _coupling(t, x, m, p)
    ng = p.conf[F_G]
    if k < ng:
        res = K.driveline_update(t, x, u, m, byref(p.net), k, log)
        _sync(x, m, p)
        return res
    _load(x, m, p)
    b = p.buf
    start = log.count[0]
    res = dispatch.update(t, b[B_X:B_X + N_STATE], b[B_U:B_U + N_IN], p.mbuf, byref(p.emtc), k - ng, log)
    _write_back(x, m, p, start, log)
    if res < 0:
        return res
    _coupling(t, x, m, p)
    K.settle_outlined(t, x, m, byref(p.net), log, m.copy(), np.int64(-1))
    _sync(x, m, p)
    return res


@numba.njit(cache=True, nogil=True)
def emtc_driveline_restart(t, x, u, m, p, log):
    """The coupling's restart (its controller sample when one is due; the armature's modes at a start), then
    the network's modes at its torque."""
    _sync(x, m, p)
    _load(x, m, p)
    b = p.buf
    start = log.count[0]
    changed = dispatch.restart(t, b[B_X:B_X + N_STATE], b[B_U:B_U + N_IN], p.mbuf, byref(p.emtc), log)
    _write_back(x, m, p, start, log)
    _coupling(t, x, m, p)
    if K.driveline_restart(t, x, u, m, byref(p.net), log):
        changed = True
    _sync(x, m, p)
    return changed


@numba.njit(cache=True, nogil=True)
def emtc_driveline_accept(t, x, u, m, p):
    """The coupling's commit of its plant magnet's memory (or its model error: a full memory)."""
    _load(x, m, p)
    b = p.buf
    return dispatch.accept(t, b[B_X:B_X + N_STATE], b[B_U:B_U + N_IN], p.mbuf, byref(p.emtc))


@numba.njit(cache=True, nogil=True)
def emtc_driveline_next_break(t, m, p):
    """The next corner of the network's signals or the coupling's next controller sample."""
    return min(K.driveline_next_break(t, m, byref(p.net)), dispatch.next_break(t, p.mbuf, byref(p.emtc)))


@numba.njit(cache=True, nogil=True)
def emtc_driveline_jacobian(t, x, u, m, p, J):
    """No analytic Jacobian (Dormand-Prince)."""
    return False


dispatch.register(EmtcDrivelineParams, rhs=emtc_driveline_rhs, outputs=emtc_driveline_outputs,
                  update=emtc_driveline_update, restart=emtc_driveline_restart, accept=emtc_driveline_accept,
                  next_break=emtc_driveline_next_break, jacobian=emtc_driveline_jacobian)


# ------------------------------------------------------------------ the drum bench as a network
