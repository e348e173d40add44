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
``lock_capacity_exceeded`` switching functions are held off).  Its ``coil_current_grid_line`` (the coil current
crossing a line of the Preisach grid, a kink of the magnet force) and ``coil_current_turn`` (the coil current
turning, where the magnet's memory takes a turning point) are waypoints either way and the network's too: a step
ends just past each, nothing changes mode.  A stuck coupling carries the torque the
network's constraint solve gives it: for the two shafts of the bench, that is Eq. 29's ``T_lock``, and
the Torsen twist of Eq. 30 stays zero (its terms vanish identically while both shafts turn together).

The armature events (``armature_rest``, ``armature_contact``, ``armature_leave_rest``,
``armature_leave_contact``) are kept and named for the element (``<name>.armature``).

Its ports (:meth:`Driveline.emtc <clutchlab.driveline.network.Driveline.emtc>`: ``torque_request``, ``throttle``,
``coil_current``) are network signals, inputs included; :func:`hold` puts their values at the evaluation's time into
the model's inputs (``torque_request``, ``throttle``, ``coil_current_command``), which the packed model reads as its
drum-bench co-simulation does.  A coupling whose losses heat a thermal mass (``heat_from``) is packed with
``temperature_source = TEMPERATURE_INPUT``, and :func:`_coupling` puts the mass's temperature into its input
``coupling_temperature``: its friction map is read there, as the drum bench's is at an input temperature.

States: per coupling its seven (:data:`clutchlab.emtc.system.STATES`; its two shaft speeds follow the flanges,
integrated from their accelerations and reset to them at every event, its Torsen twist stays zero), after the
network's and its wet clutches'.  Outputs: per coupling its :data:`OUTPUTS`.  Any number of couplings per
network, each with its own magnet, maps and controller: their parameters are rows of one :class:`EmtcBlock`,
called here one by one through the EMTC model's own hooks (:mod:`clutchlab.driveline.coupled` joins them to the
network and its wet clutches).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from ..emtc import system as S
from ..numerics import dispatch
from ..numerics.borrow import block_row, row_words, stack_rows
from . import kernel as K
from .block import buffer_slots, conf_slots

__all__ = ["EmtcBlock", "N_STATE", "N_SWITCH", "N_MODE", "OUTPUTS", "OUTPUT_INDEX", "ERROR_STRIDE"]

# (compile-time constants of this module's kernels, read from the EMTC's declarations: a change there renews them,
# clutchlab._cache.guard_cross_module_constants)
N_STATE, N_SWITCH, N_MODE, N_IN = len(S.STATES), len(S.SWITCHING), len(S.MODE_NAMES), len(S.INPUTS)
#: the model inputs its ports hold, in the order of :data:`clutchlab.driveline.network.EMTC_PORTS`: the torque
#: request, the throttle, the coil current set point
PORT_INPUTS = np.array([S.U_TORQUE, S.U_THROTTLE, S.U_COIL], dtype=np.int64)
N_PORT = PORT_INPUTS.size
#: conf (int64, :func:`~clutchlab.driveline.block.conf_slots`): the block's head (its first named element
#: ``<name>.armature``, then ``<name>.coupling``), then the network signal of each of its ports (-1: none;
#: :data:`PORT_INPUTS`)
CONF = conf_slots(("ports", N_PORT))
F_K, F_ROW, F_X, F_G, F_M, F_EV, F_EL, F_PORT = CONF.of(
    "friction", "row", "states", "switching", "modes", "events", "element", "ports")
N_CONF = CONF.total
#: coupling j's model errors are its model's codes minus ``ERROR_STRIDE j`` (clutchlab.emtc.system.ERROR_MESSAGES)
ERROR_STRIDE = 1_000_000
# buf (float): its states with the shaft speeds replaced | their derivative | switching values | inputs (its ports'
# values at the evaluation's time, :func:`hold`; zero for the others) | outputs
BUF = buffer_slots(S.STATES, S.SWITCHING, S.INPUTS, S.OUTPUTS)
B_X, B_DX, B_G, B_U, B_Y = BUF.of("states", "derivative", "switching", "inputs", "outputs")
N_BUF = BUF.total
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


class EmtcBlock(NamedTuple):
    """The EMTC couplings of a network (rows ``j``, none or more): ``params``, their parameters packed by
    :func:`clutchlab.emtc.system.pack_parameters` and stacked as rows (:func:`clutchlab.numerics.borrow.stack_rows`:
    any number of couplings, each with its own magnet and table sizes, is one type; its vehicle data used only by
    its controller's map and its drag data), ``conf[j]`` (int64, the layout ``F_*``), ``buf[j]`` (float, scratch
    ``B_*``), ``mbuf[j]`` (int64, its modes), ``index`` (int64, :data:`OUTPUT_INDEX`) and ``rows[j]`` (float64, the
    coupling's :class:`~clutchlab.emtc.system.EmtcParams` built from its row of ``params`` once per call of the core,
    :func:`clutchlab.numerics.borrow.keep_rows`; its hooks read it by reference, ``block_row``: built at every
    evaluation instead, the rows cost a tenth of an EMTC network's run).  A member of
    :class:`clutchlab.driveline.coupled.CoupledParams`."""

    params: S.EmtcParams
    conf: np.ndarray
    buf: np.ndarray
    mbuf: np.ndarray
    index: np.ndarray
    rows: np.ndarray


def block(params, conf) -> EmtcBlock:
    """The block of the couplings packed as ``params`` (a list of :class:`~clutchlab.emtc.system.EmtcParams`) with
    their layouts ``conf`` (rows ``F_*``); no coupling for empty lists (its types those of
    :func:`~clutchlab.emtc.system.params_template`, built without a compiled function: packed from a magnet, every
    plain network's first run compiled the magnet's tables and the start's derivations, 8 functions, and every later
    process loaded them)."""
    n = len(params)
    stacked = stack_rows(params, template=None if params else S.params_template())
    return EmtcBlock(stacked, np.array(conf, dtype=np.int64).reshape(n, N_CONF), np.zeros((n, N_BUF)),
                     np.zeros((n, N_MODE), dtype=np.int64), OUTPUT_INDEX.copy(), np.zeros((n, row_words(stacked))))


@numba.njit(cache=True, nogil=True, _nrt=False)
def hold(t, net, e):
    """Each coupling's model inputs: its ports' network signals at ``t`` (a network input held by the host, or any
    signal), zero where it has no port.  The caller has brought the network's held inputs up to the core's ``u``
    (:func:`clutchlab.driveline.coupled._hold`: the components are evaluated before the network's right-hand side,
    which would do it)."""
    for j in range(e.conf.shape[0]):
        cf = e.conf[j]
        b = e.buf[j]
        for q in range(N_PORT):
            s = cf[F_PORT + q]
            b[B_U + PORT_INPUTS[q]] = K.signal_at(net, s, t) if s >= 0 else 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _load(x, m, net, e, j):
    """Coupling ``j``'s own states and modes from the network's into ``e.buf[j]``/``e.mbuf[j]``: its shaft speeds
    are the flanges', its coupling mode ``slipping`` while the armature presses (else ``open``), its slip
    direction the network's (stuck: ``positive``; the torque magnitudes do not depend on it)."""
    cf = e.conf[j]
    n = net.inertia.shape[0]
    el = net.elem[cf[F_ROW]]
    b = e.buf[j]
    for i in range(N_STATE):
        b[B_X + i] = x[cf[F_X] + i]
    b[B_X] = K.flange_speed(x, n, el[K.E_A])
    b[B_X + 1] = K.flange_speed(x, n, el[K.E_B])
    b[B_X + 2] = 0.0
    ms = e.mbuf[j]
    ms[_ARM] = m[cf[F_M] + _ARM]
    ms[_CPL] = _SLIPPING if ms[_ARM] == _CONTACT else _OPEN
    ms[_DIR] = _NEGATIVE if m[cf[F_K]] == K.FORWARD else _POSITIVE


@numba.njit(cache=True, nogil=True, _nrt=True)
def _coupling(t, x, m, net, e, j):
    """Evaluate coupling ``j`` at the network's state (:func:`_load`) through its hooks: its derivative,
    switching values and outputs into ``e.buf[j]``, its sliding torque (its output ``coupling_torque``) and
    static and lock-up limits (from ``capacity_locked``) into the network (:func:`kernel.set_external`)."""
    _load(x, m, net, e, j)
    b = e.buf[j]
    xs = b[B_X:B_X + N_STATE]
    us = b[B_U:B_U + N_IN]
    ep = block_row(e, j)
    r = e.conf[j][F_ROW]
    if net.elem[r, K.E_HEAT] >= 0:   # its losses heat a thermal mass: the model's input coupling_temperature is
        # that mass's temperature (its friction map is read there: packed with TEMPERATURE_INPUT, Driveline.emtc)
        us[S.U_TEMP] = K.heat_port_temperature(net, r, x, ep.coupling.temperature_c)
    dispatch.rhs(t, xs, us, e.mbuf[j], ep, b[B_DX:B_DX + N_STATE], b[B_G:B_G + N_SWITCH])
    dispatch.outputs(t, xs, us, e.mbuf[j], ep, b[B_Y:N_BUF])   # (the same point: the model reuses it)
    cap = b[B_Y + _Y_CAP] if e.mbuf[j][_ARM] == _CONTACT else 0.0
    K.set_external(net, net.elem[e.conf[j][F_ROW]][K.E_AUX], abs(b[B_Y + _Y_TC]), ep.coupling.unlock_margin * cap,
                   cap)


@numba.njit(cache=True, nogil=True, _nrt=True)
def evaluate(t, x, m, net, e):
    """Evaluate every coupling (:func:`_coupling`)."""
    for j in range(e.conf.shape[0]):
        _coupling(t, x, m, net, e, j)


@numba.njit(cache=True, nogil=True, _nrt=False)
def derivatives(net, e, acc, dx, g):
    """Each coupling's derivatives and switching functions after the network's right-hand side (its shaft speeds
    follow the flanges' accelerations ``acc``; its lock-up and unlock functions are held off)."""
    for j in range(e.conf.shape[0]):
        cf = e.conf[j]
        b = e.buf[j]
        el = net.elem[cf[F_ROW]]
        K.copy_component(dx, g, b, cf[F_X], cf[F_G], N_STATE, N_SWITCH, B_DX, B_G)
        dx[cf[F_X]] = 0.0 if el[K.E_A] < 0 else acc[el[K.E_A]]
        dx[cf[F_X] + 1] = 0.0 if el[K.E_B] < 0 else acc[el[K.E_B]]
        dx[cf[F_X] + 2] = 0.0
        g[cf[F_G] + _SLIP_ZERO] = 1.0
        g[cf[F_G] + _UNLOCK] = 1.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def outputs(e, y, q):
    """Each coupling's outputs (:data:`OUTPUTS`) into ``y`` from ``q`` on; returns the index after them."""
    for j in range(e.conf.shape[0]):
        b = e.buf[j]
        for i in range(e.index.shape[0]):
            y[q + i] = b[B_Y + e.index[i]]
        q += e.index.shape[0]
    return q


@numba.njit(cache=True, nogil=True, _nrt=False)
def sync(x, net, e):
    """Each coupling's shaft-speed states reset to its flanges' speeds, its twist to zero (an event, a restart)."""
    n = net.inertia.shape[0]
    for j in range(e.conf.shape[0]):
        cf = e.conf[j]
        el = net.elem[cf[F_ROW]]
        x[cf[F_X]] = K.flange_speed(x, n, el[K.E_A])
        x[cf[F_X] + 1] = K.flange_speed(x, n, el[K.E_B])
        x[cf[F_X] + 2] = 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _write_back(x, m, e, j, start, log):
    """Coupling ``j``'s armature and current states and its armature mode from ``e.buf[j]``/``e.mbuf[j]`` into the
    network's, its events from ``start`` on renamed (codes after the network's, elements after its names)."""
    cf = e.conf[j]
    for i in range(3, N_STATE):
        x[cf[F_X] + i] = e.buf[j][B_X + i]
    m[cf[F_M] + _ARM] = e.mbuf[j][_ARM]
    for i in range(start, min(log.count[0], log.time.shape[0])):
        log.code[i] += cf[F_EV]
        log.element[i] += cf[F_EL]


@numba.njit(cache=True, nogil=True, _nrt=False)
def error_code(code, j):
    """Coupling ``j``'s model error ``code`` (:data:`clutchlab.emtc.system.ERROR_MESSAGES`) as the network's:
    ``code - ERROR_STRIDE j``, so the message names the coupling."""
    return code - ERROR_STRIDE * j


@numba.njit(cache=True, nogil=True, _nrt=True)
def call(t, x, m, net, e, j, k, log):
    """Coupling ``j``'s model hook on its own states and modes (``k >= 0``: its update for switching function
    ``k``; ``k < 0``: its restart, 1 if it changed something), its events renamed, its states and armature mode
    written back; a model error as :func:`error_code`."""
    _load(x, m, net, e, j)
    b = e.buf[j]
    start = log.count[0]
    ep = block_row(e, j)
    if k >= 0:
        res = dispatch.update(t, b[B_X:B_X + N_STATE], b[B_U:B_U + N_IN], e.mbuf[j], ep, k, log)
    else:
        res = 1 if dispatch.restart(t, b[B_X:B_X + N_STATE], b[B_U:B_U + N_IN], e.mbuf[j], ep, log) else 0
    _write_back(x, m, e, j, start, log)
    return error_code(res, j) if res < 0 else res


@numba.njit(cache=True, nogil=True, _nrt=True)
def accept(t, x, u, m, net, e):
    """Each coupling's commit of its plant magnet's memory; the first model error (a full memory), else 0."""
    for j in range(e.conf.shape[0]):
        _load(x, m, net, e, j)
        b = e.buf[j]
        res = dispatch.accept(t, b[B_X:B_X + N_STATE], b[B_U:B_U + N_IN], e.mbuf[j], block_row(e, j))
        if res < 0:
            return error_code(res, j)
    return 0


@numba.njit(cache=True, nogil=True, _nrt=True)
def next_break(t, e, tb):
    """The earlier of ``tb`` and a coupling's next controller sample."""
    for j in range(e.conf.shape[0]):
        tb = min(tb, dispatch.next_break(t, e.mbuf[j], block_row(e, j)))
    return tb
