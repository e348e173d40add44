"""The E-clutch with its actuator as a driveline component: the dry clutch of seed 000 whose clamp force comes from
the actuator's own states, integrated with the network's.

The actuator is the E-clutch dynamics of :mod:`clutchlab.eclutch.system` ([1] Sec. 2-3: the electro-hydrostatic
actuator under its position controller, the hydraulic line, the CSC and the axial Model 0-4), unchanged and called
through the system contract (:mod:`clutchlab.numerics.dispatch`) on its own states and modes, with its held input
``bearing_reference`` (the position controller's reference [m]) read from the component's port, a network signal
(a table, a ramp, a product, a network input ``{ input = "pedal" }`` a host or a controller drives) at every
evaluation (:func:`hold`).  The axial dynamics do not depend on the rotation (one-way coupling): the network reads
the actuator, never the other way round.  The two parts meet through the clamp force ``F_n`` of the axial model's
normal element at the evaluation's state (the right-hand side's element forces, as the model's own stages read
them), given to the network as a clutch model's torques (:func:`clutchlab.driveline.kernel.set_external`):

* the **sliding torque** ``M_cl = 2 F_n r_eff mu`` ([1] Sec. 3.2, :func:`clutchlab.eclutch.models.
  torque_of_clamp_force`; ``F_n`` held at 0 where the plate lifts off), used while the element slides;
* the **static limit** and the **lock-up limit** ``peak M_cl`` (the element's ``peak``), as a clutch of the network
  holds.

The network's friction state machine decides stick and slip of the plate; the actuator's own friction coordinates
(the master seal and spindle, the bearing, the clutch's cushion and levers) keep theirs, with their events
(``stick``, ``breakaway``, ``contact_close``, ``stop_hit``, ``cavitation_start``, ...) named
``<name>.<coordinate>``, ``<name>.<element>``, ``<name>.<chamber>`` or ``<name>.<stop>``.

The actuator's line and CSC make it stiff (lightly damped modes at 6-23 krad/s) and its massless nodes are
algebraic rows, so a network with such a component is integrated by Rodas3 with the actuator's mass matrix
(:meth:`Driveline.system <clutchlab.driveline.network.Driveline.system>`).  States: per component the actuator's
(:meth:`clutchlab.eclutch.system.Assembly.state_variables`), after the network's, its wet clutches' and its EMTC
couplings'; outputs: per component :data:`OUTPUTS`.  Any number of them, each its own model: their parameters are
rows of one :class:`EClutchBlock` (:func:`clutchlab.numerics.borrow.stack_rows`), so the compiled kernel is the same
for any number (:mod:`clutchlab.driveline.coupled` joins them to the network and its other components).

[1] seed 000 (the E-clutch paper), ``../shared/seeds/``.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numba
import numpy as np

from ..eclutch import system as ES
from ..eclutch.models import torque_of_clamp_force
from ..numerics import dispatch
from ..numerics.borrow import block_row, row_words, stack_rows
from ..numerics.layout import slots
from . import kernel as K
from .block import conf_slots

__all__ = ["EClutchBlock", "block", "OUTPUTS", "ERROR_STRIDE", "element_names"]

#: conf (int64, a row per component, :func:`~clutchlab.driveline.block.conf_slots`): the block's head, the network
#: signal its reference port reads, then its model's sizes: states, switching functions, modes (its coordinates'
#: friction modes and the input segment), coordinates and axial elements (its events' elements)
CONF = conf_slots(("reference_port", 1), ("n_states", 1), ("n_switching", 1), ("n_modes", 1), ("n_coordinates", 1),
                  ("n_elements", 1), ("n_outputs", 1))
(F_K, F_ROW, F_X, F_G, F_M, F_EV, F_EL, F_U, F_NX, F_NG, F_NM, F_NZ, F_NEL, F_NY) = CONF.of(
    "friction", "row", "states", "switching", "modes", "events", "element", "reference_port", "n_states",
    "n_switching", "n_modes", "n_coordinates", "n_elements", "n_outputs")
N_CONF = CONF.total
#: the component's outputs in a network: the model's named outputs and its reference (the held input)
OUTPUTS = ES.OUTPUTS + (ES.INPUT_OUTPUTS["position"],)
N_OUT = len(OUTPUTS)
#: buf (float, a row per component, as wide as the largest): its model's input (the reference), derivatives,
#: switching values and every output of its model, at the last evaluation
B_U, B_DX = slots(("input", 1), ("derivative", 0)).of("input", "derivative")
#: component j's model errors are its model's codes minus ``ERROR_STRIDE j`` (:data:`clutchlab.eclutch.system.
#: ERROR_MESSAGES`)
ERROR_STRIDE = 1_000_000


class EClutchBlock(NamedTuple):
    """The E-clutches with their actuators of a network (rows ``j``, none or more): ``params``, their
    :class:`~clutchlab.eclutch.system.EClutchParams` (position mode, the held input) stacked as rows
    (:func:`clutchlab.numerics.borrow.stack_rows`: any number of them, each with its own axial model, is one type),
    ``conf[j]`` (int64, the layout ``F_*``), ``buf[j]`` (float, scratch ``B_*``) and ``rows[j]`` (float64, the
    component's :class:`~clutchlab.eclutch.system.EClutchParams` built from its row once per call of the core,
    :func:`clutchlab.numerics.borrow.keep_rows`, read by reference, ``block_row``: so its hooks are the very
    specialisations the E-clutch's own sessions run, by reference; by value they were compiled again as callees of
    this block, and numba's cache then gave a Python call of ``eclutch_start`` that callee's code, which crashed
    the process).  A member of :class:`clutchlab.driveline.coupled.CoupledParams`."""

    params: ES.EClutchParams
    conf: np.ndarray
    buf: np.ndarray
    rows: np.ndarray


@functools.lru_cache(maxsize=1)
def _template():
    return ES.params_template()


def block(params, conf) -> EClutchBlock:
    """The block of the E-clutches packed as ``params`` (a list of :class:`~clutchlab.eclutch.system.EClutchParams`)
    with their layouts ``conf`` (rows ``F_*``); none for empty lists."""
    n = len(params)
    conf = np.array(conf, dtype=np.int64).reshape(n, N_CONF)
    width = int(max((1 + c[F_NX] + c[F_NG] + c[F_NY] for c in conf), default=1))
    stacked = stack_rows(params, template=None if params else _template())
    return EClutchBlock(stacked, conf, np.zeros((n, width)), np.zeros((n, row_words(stacked))))


def element_names(name: str, assembly) -> tuple:
    """The names an E-clutch ``name``'s events take (:func:`_rename`): its friction coordinates, its axial elements,
    its two chambers and its four end stops, each ``<name>.<part>``."""
    return tuple(f"{name}.{q}" for q in (*assembly.coord_names, *assembly.element_names, *ES.CHAMBERS, *ES.STOPS))


@numba.njit(cache=True, nogil=True, _nrt=False)
def hold(t, net, a):
    """Each component's model input: the bearing reference [m], the network signal its port reads at ``t`` (a
    network input as the host holds it: the caller has brought the held inputs up to the core's ``u``)."""
    for j in range(a.conf.shape[0]):
        a.buf[j][B_U] = K.signal_at(net, a.conf[j][F_U], t)


@numba.njit(cache=True, nogil=True, _nrt=True)
def _clutch(t, x, m, net, a, j):
    """Evaluate component ``j`` on its states and modes in the network's: its derivatives and switching values into
    ``a.buf[j]``, its clamp force's torques into the network (:func:`kernel.set_external`)."""
    cf = a.conf[j]
    nx, ng = cf[F_NX], cf[F_NG]
    b = a.buf[j]
    ep = block_row(a, j)
    xo, mo = cf[F_X], cf[F_M]
    d0 = B_DX
    dispatch.rhs(t, x[xo:xo + nx], b[B_U:B_U + 1], m[mo:mo + cf[F_NM]], ep, b[d0:d0 + nx], b[d0 + nx:d0 + nx + ng])
    fn = max(ep.work[ES.W_F, ep.normal_element], 0.0)   # (the plate lifted off: no clamp force)
    r = cf[F_ROW]
    slide = torque_of_clamp_force(fn, ep.r_eff, ep.mu)
    limit = net.coef[r, K.C_PEAK] * slide
    K.set_external(net, net.elem[r, K.E_AUX], slide, limit, limit)


@numba.njit(cache=True, nogil=True, _nrt=True)
def evaluate(t, x, m, net, a):
    """Evaluate every component (:func:`_clutch`)."""
    for j in range(a.conf.shape[0]):
        _clutch(t, x, m, net, a, j)


@numba.njit(cache=True, nogil=True, _nrt=False)
def derivatives(a, dx, g):
    """Each component's derivatives and switching values (of its last evaluation) into the whole system's."""
    for j in range(a.conf.shape[0]):
        cf = a.conf[j]
        nx = cf[F_NX]
        K.copy_component(dx, g, a.buf[j], cf[F_X], cf[F_G], nx, cf[F_NG], B_DX, B_DX + nx)


@numba.njit(cache=True, nogil=True, _nrt=True)
def outputs(t, x, m, a, y, q):
    """Each component's outputs (:data:`OUTPUTS`: its model's, its massless nodes in equilibrium) into ``y`` from
    ``q`` on; returns the index after them."""
    for j in range(a.conf.shape[0]):
        cf = a.conf[j]
        nx, ng = cf[F_NX], cf[F_NG]
        b = a.buf[j]
        xo, mo = cf[F_X], cf[F_M]
        y0 = B_DX + nx + ng
        ys = b[y0:y0 + cf[F_NY]]
        dispatch.outputs(t, x[xo:xo + nx], b[B_U:B_U + 1], m[mo:mo + cf[F_NM]], block_row(a, j), ys)
        for i in range(N_OUT):
            y[q + i] = ys[i]
        q += N_OUT
    return q


@numba.njit(cache=True, nogil=True, _nrt=False)
def _rename(log, start, cf):
    """Component ``cf``'s events recorded from ``start`` on: codes after the network's, elements after its names
    (:func:`element_names`: coordinates, axial elements, chambers, stops)."""
    nz, nel = cf[F_NZ], cf[F_NEL]
    for i in range(start, min(log.count[0], log.time.shape[0])):
        code = log.code[i]
        if code == ES.EV_CONTACT_CLOSE or code == ES.EV_CONTACT_OPEN:
            off = nz
        elif code == ES.EV_CAVITATION_START or code == ES.EV_CAVITATION_END:
            off = nz + nel
        elif code == ES.EV_STOP_HIT or code == ES.EV_STOP_LEAVE:
            off = nz + nel + len(ES.CHAMBERS)
        else:
            off = 0
        log.code[i] = code + cf[F_EV]
        log.element[i] += cf[F_EL] + off


@numba.njit(cache=True, nogil=True, _nrt=False)
def error_code(code, j):
    """Component ``j``'s model error ``code`` as the network's: ``code - ERROR_STRIDE j``, so the message names it."""
    return code - ERROR_STRIDE * j


@numba.njit(cache=True, nogil=True, _nrt=True)
def call(t, x, m, a, j, k, log):
    """Component ``j``'s model hook on its own states and modes (``k >= 0``: its update for its switching function
    ``k``; ``k < 0``: its restart, 1 if it changed something), its events renamed; a model error as
    :func:`error_code`."""
    cf = a.conf[j]
    b = a.buf[j]
    xo, mo = cf[F_X], cf[F_M]
    xs = x[xo:xo + cf[F_NX]]
    ms = m[mo:mo + cf[F_NM]]
    us = b[B_U:B_U + 1]
    ep = block_row(a, j)
    start = log.count[0]
    if k >= 0:
        res = dispatch.update(t, xs, us, ms, ep, k, log)
    else:
        res = 1 if dispatch.restart(t, xs, us, ms, ep, log) else 0
    _rename(log, start, cf)
    return error_code(res, j) if res < 0 else res


@numba.njit(cache=True, nogil=True, _nrt=True)
def accept(t, x, m, a):
    """Each component's accepted step (its stuck coordinates' velocities exactly zero): 1 if one changed a state,
    else 0, or the first model error."""
    changed = 0
    for j in range(a.conf.shape[0]):
        cf = a.conf[j]
        xo, mo = cf[F_X], cf[F_M]
        res = dispatch.accept(t, x[xo:xo + cf[F_NX]], a.buf[j][B_U:B_U + 1], m[mo:mo + cf[F_NM]],
                              block_row(a, j))
        if res < 0:
            return error_code(res, j)
        if res > 0:
            changed = 1
    return changed


@numba.njit(cache=True, nogil=True, _nrt=True)
def start(t, x, m, a):
    """What each component derives from its parameters alone (:func:`clutchlab.eclutch.system.eclutch_start`: the
    actuator's compliances, line inertance and resistance, master area and mass), on its row; the first model
    error, else 0."""
    for j in range(a.conf.shape[0]):
        cf = a.conf[j]
        xo, mo = cf[F_X], cf[F_M]
        code = dispatch.start(t, x[xo:xo + cf[F_NX]], a.buf[j][B_U:B_U + 1], m[mo:mo + cf[F_NM]],
                              block_row(a, j))
        if code:
            return error_code(code, j)
    return 0


@numba.njit(cache=True, nogil=True, _nrt=False)
def switching_row(a, k):
    """The component whose switching functions hold the system's function ``k`` (-1 if none)."""
    for j in range(a.conf.shape[0]):
        cf = a.conf[j]
        if cf[F_G] <= k < cf[F_G] + cf[F_NG]:
            return j
    return -1
