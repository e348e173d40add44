"""A network with model components: wet clutches (:mod:`clutchlab.driveline.wet`), EMTC couplings
(:mod:`clutchlab.driveline.emtc`) and E-clutches with their actuators (:mod:`clutchlab.driveline.eclutch`), any
number of each, in one compiled kernel.

The network's parameters are a :class:`CoupledParams`: the plain network (:class:`~clutchlab.driveline.kernel.
DrivelineParams`), a :class:`~clutchlab.driveline.wet.WetBlock` of its wet clutches and an
:class:`~clutchlab.driveline.emtc.EmtcBlock` of its couplings and an :class:`~clutchlab.driveline.eclutch.
EClutchBlock` of its E-clutches' actuators, each a block of rows (none or more).  The
couplings' parameter structures are stacked as rows whatever their sizes (:func:`clutchlab.numerics.borrow.
stack_rows`; each coupling its own magnet and maps), so the type, and with it the compiled kernel, is the same for
a dual-clutch transmission of two wet clutches, a front and a rear EMTC, a wet clutch with an EMTC or any other
mix: a network of known component kinds never run before compiles nothing (issue #31).  A network without
components is one too (:meth:`CoupledParams.plain`: empty blocks), so one kernel serves every network: each hook
first asks whether the network has a component row (:func:`_plain`) and, without one, is the plain network's own
hook of :mod:`~clutchlab.driveline.kernel`, linked as before (the same steps and numbers); the components' parts
are called through their addresses (group ``"coupled"``; an actuator's, group ``"eclutch_network"``), so a plain
network never compiles them.

Layout (what :meth:`Driveline.system <clutchlab.driveline.network.Driveline.system>` names): states, switching
functions, modes and named elements are the network's, then each wet clutch's, then each coupling's, then each
actuator's; outputs the network's, then each wet clutch's :data:`~clutchlab.driveline.wet.OUTPUTS`, then each
coupling's :data:`~clutchlab.driveline.emtc.OUTPUTS`, then each actuator's :data:`~clutchlab.driveline.eclutch.
OUTPUTS`; events the network's :data:`~clutchlab.driveline.kernel.EVENTS`, then the wet model's, the EMTC's and the
E-clutch's.  Every evaluation first gives each component's sliding torque and static limit to
the network (:func:`~clutchlab.driveline.kernel.set_external`), then the network's friction state machine decides
stick and slip for all of them at once (one stuck-set solve over the network).
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numba
import numpy as np
from numba.core import types

from ..numerics import dispatch
from ..numerics.borrow import ByRef, keep_rows, member, row
from ..numerics.outline import hook_args, outlined
from . import eclutch as DA
from . import emtc as DE
from . import kernel as K
from . import wet as DW
from .kernel import DrivelineParams

__all__ = ["CoupledParams"]


class CoupledParams(NamedTuple):
    """Packed parameters of a network with model components: the network, its wet clutches, its EMTC couplings."""

    net: DrivelineParams
    wet: DW.WetBlock
    emtc: DE.EmtcBlock
    ecl: DA.EClutchBlock

    @classmethod
    def plain(cls, net: DrivelineParams) -> "CoupledParams":
        """The parameters of a network without model components: its own, with empty blocks of wet clutches and EMTC
        couplings (one type, and one compiled kernel, for every network)."""
        return cls(net, *_no_components())


@functools.lru_cache(maxsize=1)
def _no_components():
    """The empty blocks of a network without model components, built once and shared (built anew, the layout of
    their rows took 3 ms a run: a plain network's run of CoupledClutches is 1.7 ms); none of their arrays has an
    element to write."""
    return DW.block([], []), DE.block([], []), DA.block([], [])


@numba.njit(cache=True, nogil=True, _nrt=False)
def _hold(t, u, net, w, e, a):
    """Every component's ports at ``t`` (a wet clutch's force, an EMTC coupling's torque request, throttle and coil
    current: each a network signal), after the network's held inputs are brought up to the core's ``u`` (the
    components are evaluated before the network's right-hand side, which would do that); the network's signals are
    evaluated at ``t`` here, once for the ports and the network (:func:`~clutchlab.driveline.kernel.refresh_signals`:
    read from the cache, a port costs no signal evaluation of its own)."""
    if u.shape[0] > 0 and K.hold_inputs(net.data, u):
        K.forget_signals(net)
    K.refresh_signals(net, t)
    DW.hold(t, net, w)
    DE.hold(t, net, e)
    DA.hold(t, net, a)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _evaluate(t, x, u, m, net, w, e, a):
    """Every component at the network's state (its ports first, :func:`_hold`): its derivatives and switching values
    into its block's scratch, its torques into the network's.  (Without reference counting: only the EMTC's own
    hooks keep it, called where a network has a coupling.)"""
    _hold(t, u, net, w, e, a)
    if w.conf.shape[0] > 0:
        DW.evaluate(t, x, m, net, w)
    if e.conf.shape[0] > 0:
        DE.evaluate(t, x, m, net, e)
    if a.conf.shape[0] > 0:
        _eclutch_evaluate_outlined(t, x, m, net, a)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _sync(x, m, net, w, e):
    """The components' copies of the network's speeds and friction modes (an event, a restart)."""
    DW.sync(x, m, net, w)
    DE.sync(x, net, e)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _at_rest(x, m, net):
    """True if a friction element or lossy gear of the network is stuck or at rest to 1e-6 of its speeds: the only
    items a stick/slip search looks ahead for (:func:`_with_rates`)."""
    n = net.inertia.shape[0]
    for k in range(net.fric.shape[0]):
        r = net.fric[k]
        if m[k] == K.STUCK or abs(K.relative_speed(net, r, x, n)) <= 1e3 * K.speed_tolerance(net, r, x, n):
            return True
    return net.lossy.shape[0] > 0


@numba.njit(cache=True, nogil=True, _nrt=True)
def _with_rates(t, x, u, m, p):
    """Every component's torques at ``(t, x)`` given to the network (always) with their rates (:func:`kernel.
    set_external_rates`: a forward difference over ``T_RATE`` along the whole system's derivative), before a
    stick/slip search: its look-ahead (the tie-break at ``t + T_TIE``) then sees the components' torques move.  At
    events only, and only where an item is stuck or at rest (:func:`_at_rest`, the items the search looks ahead
    for; one more evaluation of the whole system each)."""
    net = member(p, "net")
    w = member(p, "wet")
    e = member(p, "emtc")
    a = member(p, "ecl")
    if not _at_rest(x, m, net):
        _evaluate_outlined(t, x, u, m, net, w, e, a)   # (the torques at t, without rates)
        return
    nx, ng, nm = _network_sizes(w, e, a)
    dx = np.empty(x.shape[0])
    g = np.empty(ng + w.conf.shape[0] * DW.N_SWITCH + e.conf.shape[0] * DE.N_SWITCH + _switching_count(a))
    _rhs_outlined(t, x, u, m, p, dx, g)
    nj = K.external_count(net)
    v0 = np.empty(3 * nj)
    for j in range(nj):
        for q in range(3):
            v0[3 * j + q] = K.external_value(net, j, q, t)   # (as the components set them: no rate yet)
    t1 = t + K.T_RATE
    _evaluate_outlined(t1, x + K.T_RATE * dx, u, m, net, w, e, a)
    d = np.empty(3 * nj)
    for j in range(nj):
        for q in range(3):
            d[3 * j + q] = (K.external_value(net, j, q, t1) - v0[3 * j + q]) / K.T_RATE
    _evaluate_outlined(t, x, u, m, net, w, e, a)   # (the components' own scratch back at t, as their calls read it)
    for j in range(nj):
        K.set_external_rates(net, j, t, d[3 * j], d[3 * j + 1], d[3 * j + 2])


@numba.njit(cache=True, nogil=True, _nrt=False)
def _model_held(m, before, net):
    """True if the network's search changed a friction element's mode (``before``: the modes before it) and left a
    clutch model (a ``LAW_EXTERNAL`` element: a wet clutch, an EMTC coupling) stuck."""
    changed = False
    held = False
    for k in range(net.fric.shape[0]):
        if m[k] != before[k]:
            changed = True
        if m[k] == K.STUCK and net.elem[net.fric[k], K.E_LAW] == K.LAW_EXTERNAL:
            held = True
    return changed and held


@numba.njit(cache=True, nogil=True, _nrt=False)
def _plain(p):
    """True for the network ``p`` (a reference to its :class:`CoupledParams`) without model components (no wet
    clutch, no EMTC coupling): every hook is then the plain network's own (:mod:`clutchlab.driveline.kernel`), so
    such a network runs as it did on its own parameter type, and a run never compiles the components' functions,
    called through their addresses (a native FMU compiles them all)."""
    return (member(p, "wet").conf.shape[0] == 0 and member(p, "emtc").conf.shape[0] == 0
            and member(p, "ecl").conf.shape[0] == 0)


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_rhs(t, x, u, m, p, dx, g):
    """The right-hand side and switching functions (the core's stages): a plain network's own
    (:func:`kernel.driveline_rhs`, linked into the stages), or with model components :func:`_components_rhs` through
    its address (the components' equations are not linked into the core's loop: one loop serves every network)."""
    if _plain(p):
        K.driveline_rhs(t, x, u, m, member(p, "net"), dx, g)
    else:
        _rhs_outlined(t, x, u, m, p, dx, g)
    return None


@numba.njit(cache=True, nogil=True, _nrt=False)
def _components_rhs(t, x, u, m, p, dx, g):
    """The network's right-hand side and switching functions, then each component's."""
    net = member(p, "net")
    w = member(p, "wet")
    e = member(p, "emtc")
    a = member(p, "ecl")
    _evaluate(t, x, u, m, net, w, e, a)
    K.driveline_rhs(t, x, u, m, net, dx, g)
    acc = K.accelerations(net)
    if w.conf.shape[0] > 0:   # (a kind the network has none of costs no call)
        DW.derivatives(net, w, acc, dx, g)
    if e.conf.shape[0] > 0:
        DE.derivatives(net, e, acc, dx, g)
    if a.conf.shape[0] > 0:
        DA.derivatives(a, dx, g)
    return None


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_outputs(t, x, u, m, p, y):
    """The network's outputs, then each wet clutch's, then each coupling's."""
    net = member(p, "net")
    w = member(p, "wet")
    e = member(p, "emtc")
    a = member(p, "ecl")
    K.observe(net, True)   # (an observer: K.driveline_outputs, which ends the mark)
    _evaluate_outlined(t, x, u, m, net, w, e, a)
    K.driveline_outputs(t, x, u, m, net, y)
    q = y.shape[0] - w.conf.shape[0] * DW.N_KEPT - e.conf.shape[0] * e.index.shape[0] - a.conf.shape[0] * DA.N_OUT
    q = DW.outputs(w, y, q)
    q = DE.outputs(e, y, q)
    if a.conf.shape[0] > 0:
        _eclutch_outputs_outlined(t, x, m, a, y, q)


@numba.njit(cache=True, nogil=True, _nrt=True)
def coupled_update(t, x, u, m, p, k, log):
    """Switching function ``k`` crossed: the network's (:func:`kernel.driveline_update`), a wet clutch's piston or
    film function or a coupling's armature function (the component's own update); then the network's modes at
    the component's new torque."""
    net = member(p, "net")
    w = member(p, "wet")
    e = member(p, "emtc")
    a = member(p, "ecl")
    _sync(x, m, net, w, e)
    nw, ne = w.conf.shape[0], e.conf.shape[0]
    nx, ng, nm = _network_sizes(w, e, a)
    if k < ng:
        before = m.copy()
        _with_rates(t, x, u, m, p)   # (the components' torques at t, and their rates where an item is at rest)
        res = K.driveline_update(t, x, u, m, net, k, log)
        if k < K.N_G * net.fric.shape[0] and _model_held(m, before, net):
            # the search again (at the same instant: it replaces the first, kernel._one_search_per_instant), with the
            # components' rates along the motion the first decided: the rates it read were taken along the motion
            # before the instant, where a clutch model's sliding torque at its reversal falls with its slip.  Two
            # identical wet clutches in series: the first reverses, the second sticks carrying the first's sliding
            # torque, equal to its own capacity at the instant and beyond it at once (the first's slip grows), and
            # the look-ahead at t + T_TIE, reading the first's torque falling, kept the second stuck; it was held
            # beyond its capacity, by up to 1.4 %, for 45 ms (#30)
            _with_rates(t, x, u, m, p)
            K.settle_outlined(t, x, m, net, log, m.copy(), net.fric[k // K.N_G])
        _sync(x, m, net, w, e)
        return res
    _evaluate_outlined(t, x, u, m, net, w, e, a)   # (the component's hook reads its scratch at t)
    if nw > 0 and k < ng + nw * DW.N_SWITCH:
        res = DW.call(t, x, m, w, (k - ng) // DW.N_SWITCH, (k - ng) % DW.N_SWITCH, log)
    elif ne > 0 and k < ng + nw * DW.N_SWITCH + ne * DE.N_SWITCH:
        # (an EMTC's functions, DE.N_SWITCH each: its coil current's grid lines and turns among them)
        ke = k - ng - nw * DW.N_SWITCH
        res = DE.call(t, x, m, net, e, ke // DE.N_SWITCH, ke % DE.N_SWITCH, log)
    else:   # (an E-clutch's actuator: its functions, as many as its model has)
        j = DA.switching_row(a, k)
        if j < 0:
            return 0
        res = _eclutch_call_outlined(t, x, m, a, j, k - a.conf[j][DA.F_G], log)
    if res < 0:
        return res
    _with_rates(t, x, u, m, p)   # the network's modes at the component's new state
    K.settle_outlined(t, x, m, net, log, m.copy(), np.int64(-1))
    _sync(x, m, net, w, e)
    return res


@numba.njit(cache=True, nogil=True, _nrt=True)
def coupled_restart(t, x, u, m, p, log):
    """Each component's restart (a wet clutch's piston and film, a coupling's controller sample when one is due and
    its armature at a start), then the network's modes at their torques."""
    net = member(p, "net")
    w = member(p, "wet")
    e = member(p, "emtc")
    a = member(p, "ecl")
    _sync(x, m, net, w, e)
    _evaluate_outlined(t, x, u, m, net, w, e, a)
    changed = False
    for j in range(w.conf.shape[0]):
        if DW.call(t, x, m, w, j, np.int64(-1), log) != 0:
            changed = True
    for j in range(e.conf.shape[0]):
        if DE.call(t, x, m, net, e, j, np.int64(-1), log) != 0:
            changed = True
    for j in range(a.conf.shape[0]):
        res = _eclutch_call_outlined(t, x, m, a, j, np.int64(-1), log)
        if res != 0:
            changed = True
    _with_rates(t, x, u, m, p)   # (the components' torques at their new states: an actuator's restart moves them)
    if K.driveline_restart(t, x, u, m, net, log):
        changed = True
    _sync(x, m, net, w, e)
    return changed


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_accept(t, x, u, m, p):
    """Each wet clutch's peak-temperature memory, each coupling's commit of its magnet's memory (or its model
    error: a full memory); then, with ``check_invariants``, the network's invariants at the step's state with every
    component's torques at that state (:func:`kernel.driveline_accept`; before issue #31 a network with a wet clutch
    or an EMTC never checked them)."""
    net = member(p, "net")
    w = member(p, "wet")
    e = member(p, "emtc")
    a = member(p, "ecl")
    DW.accept(t, x, u, m, w)
    _hold(t, u, net, w, e, a)
    res = DE.accept(t, x, u, m, net, e)
    if res < 0:
        return res
    changed = 0
    if a.conf.shape[0] > 0:
        changed = _eclutch_accept_outlined(t, x, m, a)
        if changed < 0:
            return changed
    if net.lossy.shape[0] > 0:
        res = K.table_error(x, net)
        if res != 0:
            return res
    res = K.shift_error(x, net)
    if res != 0:
        return res
    if net.check[0] != 0.0:
        K.observe(net, True)   # (a debug option changes no decision: K.driveline_accept ends the mark)
        _evaluate_outlined(t, x, u, m, net, w, e, a)
        res = K.driveline_accept(t, x, u, m, net)
        if res != 0:
            return res
    return changed   # (1: an actuator's stuck coordinate's velocity was set to zero, the core evaluates again)


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_next_break(t, m, p):
    """The next corner of the network's signals or a wet clutch's force profile, or a coupling's next controller
    sample."""
    tb = K.driveline_next_break(t, m, member(p, "net"))
    if _plain(p):
        return tb
    return _components_next_break_outlined(t, m, p, tb)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _components_next_break(t, m, p, tb):
    """:func:`coupled_next_break`'s components (through its address: a plain network never compiles it)."""
    tb = DW.next_break(t, m, member(p, "wet"), tb)
    return DE.next_break(t, member(p, "emtc"), tb)   # (an E-clutch's actuator reads its port: no corner of its own)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _network_sizes(w, e, a):
    """The numbers of the network's own states, switching functions and modes (the first component's offsets)."""
    if w.conf.shape[0] > 0:
        return w.conf[0][DW.F_X], w.conf[0][DW.F_G], w.conf[0][DW.F_M]
    if e.conf.shape[0] > 0:
        return e.conf[0][DE.F_X], e.conf[0][DE.F_G], e.conf[0][DE.F_M]
    return a.conf[0][DA.F_X], a.conf[0][DA.F_G], a.conf[0][DA.F_M]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _switching_count(a):
    """The switching functions of the E-clutches' actuators (each as many as its model has)."""
    n = 0
    for j in range(a.conf.shape[0]):
        n += a.conf[j][DA.F_NG]
    return n


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_watch(t, x, u, m, p, dx, g, k):
    """The network's ``watch`` (:func:`kernel.driveline_watch`: the margin rates of its stuck elements near their
    limits, where the core compares switching functions) on its own states, functions and modes; nothing for a
    component's function.  The network's rate is a difference of its evaluation at ``t`` and at ``t + T_RATE``
    along ``dx``: the components' torques at that second point are evaluated first (every state moved along ``dx``,
    theirs too) and put back at ``t`` after, so the rate has theirs in it.

    Without it (before issue #31 moved the grafts here) a stuck element's turn function stayed at the 0.0 that marks
    it for the watch, and the rate that decides a stuck element at its limit missed the components' torques: a
    bearing friction beside a wet clutch whose drag grew past the bearing's limit, under a falling sine torque,
    stayed stuck at twice its limit (found by the invariant check once it ran for these networks)."""
    w = member(p, "wet")
    e = member(p, "emtc")
    a = member(p, "ecl")
    net = member(p, "net")
    if _plain(p):
        K.driveline_watch(t, x, u, m, net, dx, g, k)
        return
    nx, ng, nm = _network_sizes(w, e, a)
    if k < ng and K.wants_rates(net, m, g, k):   # (rare: a stuck item near its limit)
        _watch_rates_outlined(t, x, u, m, p, dx, g, k)


@numba.njit(cache=True, nogil=True, _nrt=True)
def _watch_rates(t, x, u, m, p, dx, g, k):
    """:func:`coupled_watch`'s rates (reference-counted: it allocates the moved state)."""
    w = member(p, "wet")
    e = member(p, "emtc")
    a = member(p, "ecl")
    nx, ng, nm = _network_sizes(w, e, a)
    net = member(p, "net")
    xs = x + K.T_RATE * dx
    _evaluate_outlined(t + K.T_RATE, xs, u, m, net, w, e, a)
    K.driveline_watch(t, x[:nx], u, m[:nm], net, dx[:nx], g[:ng], k)
    _evaluate_outlined(t, x, u, m, net, w, e, a)


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_prepare(p):
    """Once per call of the core: each wet clutch's and each EMTC coupling's parameter structure built from its row of
    its block (:func:`clutchlab.numerics.borrow.keep_rows`), which their hooks then read by reference; nothing for a
    plain network."""
    if not _plain(p):
        _keep_rows_outlined(p)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _keep_rows(p):
    """:func:`coupled_prepare`'s rows (through its address: a plain network never compiles them)."""
    keep_rows(member(p, "wet"))
    keep_rows(member(p, "emtc"))
    keep_rows(member(p, "ecl"))


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_jacobian(t, x, u, m, p, J):
    """No analytic Jacobian (Dormand-Prince)."""
    return False


# ---- the hooks the core calls at events, samples and step ends, called through their addresses
# (:mod:`clutchlab.numerics.outline`).  Linked, each of them -- with the network's evaluation and both components'
# below it -- was optimised and emitted again in every function of the core that calls it (the core's root finder,
# its event step, its breaks, its three record functions, its loop): measured on ``clutchlab warmup``'s components
# group, the final modules held 4.4 times the code they define (docs/architecture.md).  The step's
# stages still call :func:`coupled_rhs` directly (inlined where LLVM finds it worth it); these run at most once per
# step, where one indirect call is nothing beside the network's evaluation.


@functools.lru_cache(maxsize=1)
def _params_type():
    """numba type of the reference to a :class:`CoupledParams` every hook takes (one type for every network)."""
    empty = CoupledParams.plain(K.params_template())
    return ByRef(numba.typeof(empty))


_F1, _I1 = types.float64[::1], types.int64[::1]


def _member_types():
    """numba types of the references to a :class:`CoupledParams`' members (``member(p, "net")``, ...)."""
    return tuple(ByRef(t) for t in _params_type().pointee.types)


def _hook_args(*rest):
    """The types of a hook's arguments: ``(t, x, u, m, p, *rest)`` (:func:`~clutchlab.numerics.outline.hook_args`)."""
    return hook_args(_params_type(), *rest)


_evaluate_outlined = outlined(_evaluate, lambda: (types.float64, _F1, _F1, _I1, *_member_types()), types.none,
                              group="coupled")
_rhs_outlined = outlined(_components_rhs, lambda: _hook_args(_F1, _F1), types.none, group="coupled")
_outputs_outlined = outlined(coupled_outputs, lambda: _hook_args(_F1), types.none, group="coupled")
_update_outlined = outlined(coupled_update, lambda: _hook_args(types.int64, K._log_type()), types.int64,
                            group="coupled")
_restart_outlined = outlined(coupled_restart, lambda: _hook_args(K._log_type()), types.boolean, group="coupled")
_accept_outlined = outlined(coupled_accept, lambda: _hook_args(), types.int64, group="coupled")
_watch_rates_outlined = outlined(_watch_rates, lambda: _hook_args(_F1, _F1, types.int64), types.none,
                                 group="coupled")
# an E-clutch's actuator model (its hooks, linked into these four: compiled where a network first has one)
_eclutch_evaluate_outlined = outlined(DA.evaluate, lambda: (types.float64, _F1, _I1, _member_types()[0],
                                                            _member_types()[3]), types.none, group="eclutch_network")
_eclutch_call_outlined = outlined(DA.call, lambda: (types.float64, _F1, _I1, _member_types()[3], types.int64,
                                                    types.int64, K._log_type()), types.int64, group="eclutch_network")
_eclutch_accept_outlined = outlined(DA.accept, lambda: (types.float64, _F1, _I1, _member_types()[3]), types.int64,
                                   group="eclutch_network")
_eclutch_outputs_outlined = outlined(DA.outputs, lambda: (types.float64, _F1, _I1, _member_types()[3], _F1,
                                                          types.int64), types.int64, group="eclutch_network")


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_rhs_event(t, x, u, m, p, dx, g):
    """:func:`_components_rhs` through its address (the core's ``rhs_event`` hook: locating a root, the step to it, a
    break); a plain network's own."""
    if _plain(p):
        K.driveline_rhs_event(t, x, u, m, member(p, "net"), dx, g)
    else:
        _rhs_outlined(t, x, u, m, p, dx, g)


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_outputs_hook(t, x, u, m, p, y):
    """:func:`coupled_outputs` through its address (the core's ``outputs`` hook); a plain network's own."""
    if _plain(p):
        K.driveline_outputs(t, x, u, m, member(p, "net"), y)
    else:
        _outputs_outlined(t, x, u, m, p, y)


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_update_hook(t, x, u, m, p, k, log):
    """:func:`coupled_update` through its address (the core's ``update`` hook); a plain network's own."""
    if _plain(p):
        return K.driveline_update(t, x, u, m, member(p, "net"), k, log)
    return _update_outlined(t, x, u, m, p, k, log)


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_restart_hook(t, x, u, m, p, log):
    """:func:`coupled_restart` through its address (the core's ``restart`` hook); a plain network's own."""
    if _plain(p):
        return K.driveline_restart(t, x, u, m, member(p, "net"), log)
    return _restart_outlined(t, x, u, m, p, log)


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_accept_hook(t, x, u, m, p):
    """:func:`coupled_accept` through its address (the core's ``accept`` hook); a plain network's own."""
    if _plain(p):
        return K.driveline_accept(t, x, u, m, member(p, "net"))
    return _accept_outlined(t, x, u, m, p)


@numba.njit(cache=True, nogil=True, _nrt=False)
def coupled_start(t, x, u, m, p):
    """The network's start modes and stored energy from its initial state (:func:`kernel.driveline_start`, through
    its address; the core's ``start`` hook), and what each component derives from its parameters alone, on its
    row (whose numbers are views of the block's): a wet clutch's pack heat capacity, Greenwood-Williamson scale,
    effective radius and squeeze coefficient (:func:`clutchlab.wet.system.wet_start`), an EMTC coupling's current
    lags' rates and controller table at its engaged airgap (:func:`clutchlab.emtc.system.derive_actuator`; a
    refusal as the coupling's error, :func:`~clutchlab.driveline.emtc.error_code`).  So a native FMU takes a host's
    masses, roughness and radii of a wet clutch and the airgaps of a coupling in the network.  The components' own
    modes are their builders' (their restart at the start settles them)."""
    code = K._start_outlined(t, x, u, m, member(p, "net"))
    if code or _plain(p):
        return code
    return _components_start_outlined(t, x, u, m, p)


@numba.njit(cache=True, nogil=True, _nrt=True)
def _components_start(t, x, u, m, p):
    """:func:`coupled_start`'s components: what each derives from its parameters alone (through its address: a
    plain network never runs it).  Reference-counted: the EMTC's derivation allocates its index arrays
    (:func:`clutchlab.emtc.system.derive_actuator`), and a callee without flags of its own compiled first from here
    takes this function's (numba's ``nrt`` is inherited).  A native FMU of a plain network once failed to build on
    an empty cache that way (fifty-seventh session); ``derive_actuator`` now declares ``_nrt=True`` itself
    (fifty-eighth session, tested from a caller without it), and this function keeps the flag it was tested with."""
    w = member(p, "wet")
    for j in range(w.conf.shape[0]):
        code = DW.W.wet_start(t, x, u, m, row(member(w, "params"), j))
        if code:
            return code
    e = member(p, "emtc")
    for j in range(e.conf.shape[0]):
        r = row(member(e, "params"), j)
        code = DE.S.derive_actuator(r.actuator, r.cold, r.layout, r.controller_table)
        if code:
            return DE.error_code(code, j)
    a = member(p, "ecl")
    if a.conf.shape[0] > 0:
        return DA.start(t, x, m, a)
    return 0


_components_start_outlined = outlined(_components_start, lambda: _hook_args(), types.int64, group="coupled")
_components_next_break_outlined = outlined(_components_next_break,
                                           lambda: (types.float64, _I1, _params_type(), types.float64), types.float64,
                                           group="coupled")
_keep_rows_outlined = outlined(_keep_rows, lambda: (_params_type(),), types.none, group="coupled")


dispatch.register(CoupledParams, rhs=coupled_rhs, outputs=coupled_outputs_hook, update=coupled_update_hook,
                  restart=coupled_restart_hook, accept=coupled_accept_hook, next_break=coupled_next_break,
                  jacobian=coupled_jacobian, rhs_event=coupled_rhs_event, watch=coupled_watch,
                  prepare=coupled_prepare, start=coupled_start)
