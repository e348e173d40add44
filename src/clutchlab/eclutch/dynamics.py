"""E-clutch dynamics: actuator plus clutch axial Models 0-4 with stick-slip friction.

Haramina et al. [1] build the axial Models 0-4 with masses (m_pp, m_pps, m_ds)
and friction elements (R_f.ds, R_f.pp) in their bond graphs (Figs. 5b, 11) but
validate them with friction switched off; their future work (i) expects
stiction to explain the force stagnation near the peak and the measured
hysteresis, and (iii) thermal expansion and wear.  This module adds both:

* :class:`FrictionParameters` -- the friction elements, with the stick-slip
  state machine of the Modelica Standard Library (stuck holds zero relative
  acceleration while the force it needs stays within the static limit, breaks
  away above it; a zero normal force means no friction);
* :class:`ClutchDynamics` -- the clutch alone, driven by a prescribed bearing
  motion (the situation of the paper's static curves);
* :class:`EClutch` -- actuator ([1] Sec. 2.1, Fig. 5a) and clutch coupled by
  the bearing stiffness k_b ([1] Sec. 3.2), driven by the motor voltage or by
  a bearing-position reference tracked by the E-clutch's position controller;
* :func:`apply_wear_and_expansion` -- wear and thermal offsets (future work iii).

Equations of motion (coordinates ``z``: master piston, CSC/bearing, free
nodes of the network; ``d = d0 + GA q + Gb u`` are the element deflections)::

    m_j dv_j/dt = F_j(z, p, i) + F_f,j      (mass coordinates)
    0           = F_j(z)                    (massless nodes: algebraic)
    F_q = -GA^T f(d),   F_u = -Gb^T f(d) + p_s A_sl + F_pre - k_pre u

integrated by Rodas3 (:mod:`clutchlab.numerics.rosenbrock`), stiffly accurate
so the algebraic rows of massless nodes are solved with the dynamics, with
stick/slip, contact and end-stop events located by re-stepping to within
``event_tol`` seconds.

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, Trans. FAMENA
   48 (2024) 21-35, doi:10.21278/TOF.483057923
.. [2] M. Otter, H. Elmqvist, S. E. Mattsson, "Hybrid modeling in Modelica
   based on the synchronous data flow principle", CACSD 1999 (the friction
   state machine of Modelica.Mechanics.Translational).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np
import pandas as pd

from .._limits import check_allocation, short_repr
from ..errors import ParameterError, SimulationError
from ..params import ParameterSet, quantity
from . import _dynamics_kernel as K
from .actuator import ActuatorParameters
from .models import ClutchModel
from .network import GROUND, AxialNetwork, Lever, Spring, solve_static

__all__ = [
    "FrictionParameters", "FrictionElement", "ClutchDynamics", "EClutch", "DynamicsResult",
    "apply_wear_and_expansion", "pedal_reference", "actuator_test_rig", "EVENT_KINDS", "simulate_batch",
    "BatchResult",
]

EVENT_KINDS = {K.EV_STICK: "stick", K.EV_BREAKAWAY: "breakaway", K.EV_REVERSAL: "slip reversal",
               K.EV_CONTACT_CLOSE: "contact closes", K.EV_CONTACT_OPEN: "contact opens",
               K.EV_STOP_HIT: "end stop hit", K.EV_STOP_LEAVE: "end stop left",
               K.EV_CAVITATION_START: "cavitation starts", K.EV_CAVITATION_END: "cavitation ends"}
_STOPS = ("master rest stop", "master stroke end", "CSC engaged stop", "CSC travel end")
_CHAMBERS = ("master chamber", "CSC chamber")
_REP = "representative (docs/eclutch_dynamics.md)"


@dataclasses.dataclass(frozen=True)
class FrictionParameters(ParameterSet):
    """Friction elements R_f.ds and R_f.pp of the axial models ([1] Sec. 3.2, Figs. 5b, 11).

    ``R_f.ds`` is the friction of the diaphragm spring on its fulcrum rings,
    proportional to the diaphragm force (the paper's conclusion: friction is
    highest where the diaphragm presses hardest on its supports); it acts on
    the diaphragm body -- node ``edge`` of Models 2-4, the pressure plate of
    Models 0-1, where the diaphragm rides on it.  ``R_f.pp`` is the friction of
    the pressure plate in its guides, a constant Coulomb force.
    """

    kind = "eclutch_friction"

    diaphragm_coefficient: float = quantity(0.03, "1", "R_f.ds: kinetic friction per unit diaphragm force", source=_REP, nonnegative=True, bounds=(0.0, 1.0))
    pressure_plate_force: float = quantity(10.0, "N", "R_f.pp: Coulomb friction force of the pressure plate guides", source=_REP, nonnegative=True)
    static_ratio: float = quantity(1.25, "1", "static over kinetic friction (break-away limit)", source=_REP, bounds=(1.0, 5.0))
    diaphragm_viscous: float = quantity(20.0, "N*s/m", "viscous part of R_f.ds", source=_REP, nonnegative=True)
    pressure_plate_viscous: float = quantity(20.0, "N*s/m", "viscous part of R_f.pp", source=_REP, nonnegative=True)

    @classmethod
    def off(cls) -> "FrictionParameters":
        """No friction at all (the setting of [1] Secs. 5-6)."""
        return cls(diaphragm_coefficient=0.0, pressure_plate_force=0.0, static_ratio=1.0, diaphragm_viscous=0.0,
                   pressure_plate_viscous=0.0)


@dataclasses.dataclass(frozen=True)
class FrictionElement:
    """A friction element acting on one node of the network (or on the actuator).

    Kinetic force ``F_c = coulomb + coefficient * |f_normal| + pressure_coefficient * |p|``,
    opposing the slip, plus ``viscous * v``; static limit ``static_ratio * F_c``.

    Parameters
    ----------
    name : str
        Label (``"R_f.ds"``).
    node : str
        Network node name, or ``"master"`` / ``"bearing"`` for the actuator pistons.
    coulomb : float
        Constant Coulomb force [N].
    coefficient : float
        Friction per unit force of ``normal`` [-].
    normal : str or None
        Network element whose force presses the contact.
    pressure_coefficient : float
        Friction per unit chamber pressure [N/Pa] (seals).
    pressure : str or None
        ``"master"`` or ``"slave"`` chamber.
    static_ratio : float
        Static over kinetic friction (>= 1).
    viscous : float
        Viscous coefficient [N s/m].
    """

    name: str
    node: str
    coulomb: float = 0.0
    coefficient: float = 0.0
    normal: str | None = None
    pressure_coefficient: float = 0.0
    pressure: str | None = None
    static_ratio: float = 1.0
    viscous: float = 0.0

    def __post_init__(self):
        for fld in ("coulomb", "coefficient", "pressure_coefficient", "viscous"):
            v = getattr(self, fld)
            if not (np.isfinite(v) and v >= 0):
                raise ParameterError(f"friction element {self.name!r}: {fld} = {v!r} must be finite and >= 0")
        if not (np.isfinite(self.static_ratio) and self.static_ratio >= 1.0):
            raise ParameterError(f"friction element {self.name!r}: static_ratio = {self.static_ratio!r} must be >= 1")
        if self.pressure not in (None, "master", "slave"):
            raise ParameterError(f"friction element {self.name!r}: pressure = {self.pressure!r} (use 'master' or 'slave')")

    @property
    def active(self) -> bool:
        """True if the element can exert any Coulomb force."""
        return self.coulomb > 0 or self.coefficient > 0 or self.pressure_coefficient > 0


def clutch_friction_elements(network: AxialNetwork, friction: FrictionParameters) -> list[FrictionElement]:
    """Place R_f.ds and R_f.pp on the nodes of ``network`` (see :class:`FrictionParameters`)."""
    nodes = {n.name for n in network.nodes}
    ds_node = "edge" if "edge" in nodes else "pp"
    if "pp" not in nodes:
        raise ParameterError(f"{network.name}: friction needs a pressure plate node 'pp'")
    normal = "diaphragm" if any(e.name == "diaphragm" for e in network.elements) else None
    return [
        FrictionElement("R_f.ds", ds_node, coefficient=friction.diaphragm_coefficient, normal=normal,
                        static_ratio=friction.static_ratio, viscous=friction.diaphragm_viscous),
        FrictionElement("R_f.pp", "pp", coulomb=friction.pressure_plate_force, static_ratio=friction.static_ratio,
                        viscous=friction.pressure_plate_viscous),
    ]


def actuator_friction_elements(actuator: ActuatorParameters) -> list[FrictionElement]:
    """Seal and spindle friction of master cylinder and CSC.

    The spindle efficiency eta is represented as friction proportional to the
    axial load, ``(1/eta - 1) |p_m A_mc|``, which dissipates in both power
    directions (an efficiency factor on the motor force would create energy
    when the spindle is back-driven).
    """
    return [
        FrictionElement("master seal + spindle", "master", coulomb=actuator.master_seal_friction,
                        pressure_coefficient=actuator.load_friction * actuator.master_area, pressure="master",
                        static_ratio=1.2, viscous=5.0),
        FrictionElement("CSC seal", "bearing", coulomb=actuator.slave_seal_friction,
                        pressure_coefficient=actuator.seal_pressure_friction, pressure="slave", static_ratio=1.2,
                        viscous=5.0),
    ]


def pedal_reference(pedal, release_travel: float = 8e-3):
    """Bearing-position reference from the clutch-pedal signal of [1] Fig. 1 [m].

    Parameters
    ----------
    pedal : array_like
        Pedal position as a fraction 0 (released pedal: clutch engaged) to 1
        (pedal down: clutch released) [-].
    release_travel : float
        Bearing travel that fully releases the clutch [m].

    Raises
    ------
    ParameterError
        A pedal value that is not finite or lies outside 0..1.

    Notes
    -----
    A linear map, the simplest of the pedal-to-bearing maps an E-clutch
    controller uses; the controller then tracks this reference.
    """
    p = np.asarray(pedal, dtype=float)
    if np.any(~np.isfinite(p)):
        raise ParameterError("pedal signal contains NaN or infinite values")
    bad = np.flatnonzero((p < 0.0) | (p > 1.0))
    if bad.size:  # a pedal beyond its stops is a unit or scaling slip (percent?), never clipped silently
        raise ParameterError(f"pedal[{int(bad[0])}] = {float(p.ravel()[bad[0]])!r}: a pedal position must lie in 0..1")
    return p * release_travel


def apply_wear_and_expansion(model: ClutchModel, *, wear_m: float = 0.0, temperature_rise_k: float = 0.0,
                             expansion_coefficient: float = 12e-6, stack_height_m: float = 0.03) -> ClutchModel:
    """Shift the characteristics by facing wear and thermal expansion ([1] Sec. 7, future work iii).

    Facing wear ``w`` thins the friction plate, so at the same pressure-plate
    position the cushion spring is compressed ``w`` less; thermal expansion of
    pressure plate and flywheel (height ``h``, coefficient ``alpha``) thickens
    the stack by ``alpha dT h``.  The cushion pre-strain of the built model
    becomes ``prestrain - w + alpha dT h``; the bearing origin is *not*
    re-zeroed, so the static curves shift along the bearing position as they
    do on a worn or hot clutch.

    Parameters
    ----------
    model : ClutchModel
        The model to shift.
    wear_m : float
        Facing wear (both faces together) [m], >= 0.
    temperature_rise_k : float
        Temperature rise of pressure plate and flywheel over assembly [K].
    expansion_coefficient : float
        Linear thermal expansion coefficient [1/K] (cast iron ~ 1.2e-5).
    stack_height_m : float
        Axial height of the expanding stack [m].
    """
    for name, v in (("wear_m", wear_m), ("temperature_rise_k", temperature_rise_k),
                    ("expansion_coefficient", expansion_coefficient), ("stack_height_m", stack_height_m)):
        if not np.isfinite(v):
            raise ParameterError(f"apply_wear_and_expansion: {name} = {v!r} is not finite")
    if wear_m < 0:
        raise ParameterError(f"apply_wear_and_expansion: wear_m = {wear_m!r} m must be >= 0")
    net = model.network
    cushion = net.element(net.normal_force)
    shift = -wear_m + expansion_coefficient * temperature_rise_k * stack_height_m
    new = dataclasses.replace(cushion, prestrain=cushion.prestrain + shift)
    return dataclasses.replace(model, network=net.replace_element(cushion.name, new))


def actuator_test_rig(stiffness: float = 3.0e5, preload: float = 80.0, travel: float = 20e-3) -> ClutchModel:
    """The actuator test rig of [1] Fig. 3 ([2]): a linear load spring in place of the clutch.

    Parameters
    ----------
    stiffness : float
        Load spring rate [N/m].
    preload : float
        Load on the bearing at bearing position 0 [N] (equal to the CSC
        preload, so the actuator starts at rest).
    travel : float
        Span of the spring characteristic [m] (extrapolated linearly beyond).

    Returns
    -------
    ClutchModel
        A one-spring "clutch" whose bearing force is ``preload + stiffness * x``.
    """
    from ..curves import Curve
    from .network import Node

    if not (np.isfinite(stiffness) and stiffness > 0):
        raise ParameterError(f"actuator_test_rig: stiffness = {stiffness!r} N/m must be finite and > 0")
    if not (np.isfinite(preload) and preload >= 0):
        raise ParameterError(f"actuator_test_rig: preload = {preload!r} N must be finite and >= 0")
    spring = Curve.linear(stiffness, force_at_zero=preload, span=(-travel, travel), name="load spring")
    net = AxialNetwork((Node("bearing"), Node("pp", 1.0)),
                       (Spring("bearing", "bearing", spring, b="pp"),
                        Spring("cushion", "pp", Curve.linear(1e9, span=(-1e-3, 1e-3), name="rig frame"))),
                       input="bearing", normal_force="cushion", name="actuator test rig (load spring)")
    return ClutchModel(net, r_eff=0.1, mu=0.27)


# ---------------------------------------------------------------------------
# assembly of the dynamic system
# ---------------------------------------------------------------------------

def _node_aligned(network: AxialNetwork) -> dict:
    """Coordinates aligned with nodes: ``x = A q + b u + c`` with ``q`` = positions of the independent nodes.

    The input node and, for every rigid lever, one massless node are the
    dependent ones, so each mass (and each friction element) sits on one
    coordinate of its own and the mass matrix is diagonal.
    """
    a = network._assembly
    names = list(a["node_names"])
    idx = {n: i for i, n in enumerate(names)}
    mass = np.array([n.mass for n in network.nodes])
    G = a["G"]
    prestrain = a["d0"] - G @ a["c"]
    N = len(names)
    rows, ru, rc, dep = [], [], [], []
    r = np.zeros(N)
    r[idx[network.input]] = 1.0
    rows.append(r), ru.append(1.0), rc.append(0.0), dep.append(idx[network.input])
    for e in network.elements:
        if isinstance(e, Lever) and e.rigid:
            g = np.zeros(N)
            for node, coef in e.coefficients().items():
                if node != GROUND:
                    g[idx[node]] += coef
            cands = [i for i in np.flatnonzero(g) if i not in dep]
            cands.sort(key=lambda i: (mass[i] > 0, -abs(g[i])))
            if not cands:
                raise ParameterError(f"{network.name}: rigid lever {e.name!r} over-constrains the nodes")
            if mass[cands[0]] > 0:
                raise ParameterError(
                    f"{network.name}: rigid lever {e.name!r} ties two masses together; give one of its nodes zero mass")
            rows.append(g), ru.append(0.0), rc.append(-e.prestrain), dep.append(cands[0])
    C = np.array(rows)
    ind = [i for i in range(N) if i not in dep]
    CD = C[:, dep]
    CI = C[:, ind]
    inv = np.linalg.inv(CD)
    A = np.zeros((N, len(ind)))
    b = np.zeros(N)
    c = np.zeros(N)
    for k, i in enumerate(ind):
        A[i, k] = 1.0
    A[dep, :] = -inv @ CI
    b[dep] = inv @ np.array(ru)
    c[dep] = inv @ np.array(rc)
    GA = G @ A
    return dict(
        names=names, independent=[names[i] for i in ind], A=A, b=b, c=c,
        GA=np.ascontiguousarray(GA), Gb=np.ascontiguousarray(G @ b), d0=np.ascontiguousarray(prestrain + G @ c),
        mass=mass[ind].astype(float), elements=list(a["element_names"]),
    )


def _curve_energy(curve, scale, unilateral, d_values, d_ref):
    """Elastic energy ``int_{d_ref}^{d} max?(scale*curve)`` [J] (fine trapezoid on the interpolant)."""
    d_values = np.asarray(d_values, dtype=float)
    lo = min(d_values.min(), d_ref)
    hi = max(d_values.max(), d_ref)
    if hi - lo < 1e-15:
        return np.zeros_like(d_values)
    x = np.linspace(lo, hi, 40001)
    fx = scale * curve(x)
    if unilateral:
        fx = np.maximum(fx, 0.0)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (fx[1:] + fx[:-1]) * np.diff(x))])
    return np.interp(d_values, x, cum) - np.interp(d_ref, x, cum)


@dataclasses.dataclass
class DynamicsResult:
    """Result of an E-clutch simulation.

    Attributes
    ----------
    time : ndarray
        Time [s] of the recorded points.
    states : pandas.DataFrame
        Raw state vector (positions, velocities, pressures, current, energies).
    outputs : pandas.DataFrame
        Measured and derived quantities (see :meth:`to_dataframe`).
    events : pandas.DataFrame
        Located events: ``time_s``, ``event``, ``where``.
    stats : dict
        Accepted and rejected steps, right-hand-side evaluations, Jacobians.
    energy_source : callable or DataFrame, optional
        What :attr:`energy` returns: energy bookkeeping per recorded point [J]: ``input_work_J``,
        ``dissipated_J``, ``friction_dissipated_J`` (integrated with the
        states) and ``stored_J`` (computed from the states).
    """

    time: np.ndarray
    states: pd.DataFrame
    outputs: pd.DataFrame
    events: pd.DataFrame
    stats: dict
    energy_source: object = dataclasses.field(default=None, repr=False)

    @property
    def energy(self) -> pd.DataFrame | None:
        """Energy bookkeeping (computed on first use; see the class documentation)."""
        src = self.energy_source
        if callable(src):
            self.energy_source = src()
        return self.energy_source

    def to_dataframe(self) -> pd.DataFrame:
        """One table of time, every state and every output (SI units in the column names)."""
        extra = [c for c in self.states.columns if c not in self.outputs.columns]
        return pd.concat([self.outputs, self.states[extra]], axis=1)

    def energy_balance(self) -> dict:
        """Input work, dissipated energy and change of stored energy over the run [J].

        ``residual = input - dissipated - stored_change``; ``relative`` divides
        it by the input work.
        """
        if self.energy is None:
            raise SimulationError("this result has no energy bookkeeping")
        e = self.energy
        w_in = float(e["input_work_J"].iloc[-1] - e["input_work_J"].iloc[0])
        diss = float(e["dissipated_J"].iloc[-1] - e["dissipated_J"].iloc[0])
        stored = float(e["stored_J"].iloc[-1] - e["stored_J"].iloc[0])
        res = w_in - diss - stored
        return {"input_J": w_in, "dissipated_J": diss, "stored_change_J": stored, "residual_J": res,
                "relative": res / w_in if w_in else np.nan,
                "friction_dissipated_J": float(e["friction_dissipated_J"].iloc[-1] - e["friction_dissipated_J"].iloc[0])}


class _System:
    """Arrays of one dynamic system (clutch network + optional actuator) for the kernel."""

    def __init__(self, model: ClutchModel, actuator: ActuatorParameters | None, friction: list[FrictionElement],
                 prescribed: bool):
        if not isinstance(model, ClutchModel):
            raise ParameterError(f"expected a ClutchModel, got {type(model).__name__}")
        self.model = model
        self.actuator = actuator
        self.prescribed = prescribed
        net = model.network
        asm = _node_aligned(net)
        self.asm = asm
        self.nq = len(asm["independent"])
        self.nz = 2 + self.nq
        self.coord_names = ["master", "bearing"] + asm["independent"]
        kd = net.kernel_data()
        # curve data come from the network's own assembly (same element order)
        self.cx, self.cf, self.cd, self.offsets, self.kinds, self.extraps = kd[3], kd[4], kd[5], kd[6], kd[7], kd[8]
        self.scale = np.ascontiguousarray(kd[9], dtype=float)
        self.unilateral = kd[10]
        self.element_names = asm["elements"]
        act = actuator or ActuatorParameters()
        mass = np.zeros(self.nz)
        mass[0] = act.master_equivalent_mass
        mass[1] = act.slave_mass
        mass[2:] = asm["mass"]
        self.mass = mass
        n = 2 * self.nz + 8
        self.n = n
        mvec = np.ones(n)
        for j in range(2, self.nz):
            if mass[j] == 0.0:
                mvec[j] = 0.0
        self.mvec = mvec
        self.par = self._par(act)
        self._friction(friction)
        typ = np.empty(n)
        typ[: self.nz] = 1e-3
        typ[self.nz: 2 * self.nz] = 1e-2
        b0 = 2 * self.nz
        typ[b0: b0 + 8] = [1e5, 1e-6, 1e5, 1.0, 1e-4, 1.0, 1.0, 1.0]
        self.typ = typ
        atol = np.empty(n)
        atol[: self.nz] = 1e-8
        atol[self.nz: 2 * self.nz] = 1e-5
        atol[b0: b0 + 8] = [10.0, 1e-10, 10.0, 1e-4, 1e-9, 1e-6, 1e-6, 1e-6]
        if not prescribed:
            # with the actuator: 0.1 um, 0.1 mm/s, 100 Pa, 1 mA, ... (far below what a rig resolves; tighter
            # values only resolve stick-slip micro-motions of the seals, see docs/eclutch_dynamics.md)
            atol[: b0 + 5] *= 10.0
        self.atol = atol

    def _par(self, a: ActuatorParameters) -> np.ndarray:
        par = np.zeros(K.N_PAR)
        par[K.P_AMC] = a.master_area
        par[K.P_ASL] = a.slave_area
        par[K.P_MMC] = a.master_equivalent_mass
        par[K.P_MSL] = a.slave_mass
        par[K.P_CM] = a.master_compliance
        par[K.P_CS] = a.slave_compliance
        par[K.P_LH] = a.line_inertance
        par[K.P_RH] = a.line_resistance
        par[K.P_GV] = a.snifting_conductance
        par[K.P_XSN] = a.snifting_port + a.snifting_width
        par[K.P_WSN] = a.snifting_width
        par[K.P_PCAV] = a.vapour_pressure
        par[K.P_CAVF] = 1e3
        par[K.P_R] = a.resistance
        par[K.P_L] = a.inductance
        par[K.P_KT] = a.torque_constant
        par[K.P_VSUP] = a.supply_voltage
        par[K.P_IMAX] = a.current_limit
        par[K.P_KIL] = a.current_limit_gain
        par[K.P_NS] = a.spindle_ratio
        par[K.P_FPRE] = a.csc_preload
        par[K.P_KPRE] = a.csc_spring_rate
        par[K.P_UMIN] = a.slave_min
        par[K.P_UMAX] = a.slave_max
        par[K.P_XMAX] = a.master_stroke
        par[K.P_KSTOP] = a.stop_stiffness
        par[K.P_CSTOP] = a.stop_damping
        par[K.P_KP] = a.kp
        par[K.P_KI] = a.ki
        par[K.P_KD] = a.kd
        par[K.P_KAW] = a.anti_windup
        par[K.P_REFMIN] = a.slave_min
        par[K.P_REFMAX] = a.slave_max
        return par

    def _friction(self, elements):
        nz = self.nz
        self.fr_on = np.zeros(nz, dtype=np.bool_)
        self.fr_c0 = np.zeros(nz)
        self.fr_mun = np.zeros(nz)
        self.fr_nidx = -np.ones(nz, dtype=np.int64)
        self.fr_mup = np.zeros(nz)
        self.fr_pidx = np.zeros(nz, dtype=np.int64)
        self.fr_rs = np.ones(nz)
        self.fr_c = np.zeros(nz)
        self.friction_names = [""] * nz
        for el in elements:
            if not isinstance(el, FrictionElement):
                raise ParameterError(f"friction elements must be FrictionElement, got {type(el).__name__}")
            if el.node not in self.coord_names:
                raise ParameterError(
                    f"friction element {el.name!r}: node {el.node!r} is not a free coordinate "
                    f"(free: {self.coord_names})")
            j = self.coord_names.index(el.node)
            if self.prescribed and j < 2:
                continue  # the actuator is not simulated
            if self.mass[j] <= 0.0:
                raise ParameterError(f"friction element {el.name!r} acts on massless node {el.node!r}; give it a mass")
            self.fr_c[j] += el.viscous
            if not el.active:
                continue
            if self.fr_on[j]:
                # several elements on one coordinate: they stick and slip together
                if el.normal is not None and self.fr_nidx[j] >= 0:
                    raise ParameterError(f"node {el.node!r}: only one normal-force element per node is supported")
            self.fr_on[j] = True
            self.fr_c0[j] += el.coulomb
            if el.normal is not None:
                if el.normal not in self.element_names:
                    raise ParameterError(f"friction element {el.name!r}: normal = {el.normal!r} is not an elastic element "
                                         f"of {self.model.name} ({self.element_names})")
                self.fr_nidx[j] = self.element_names.index(el.normal)
                self.fr_mun[j] = el.coefficient
            if el.pressure is not None:
                self.fr_pidx[j] = 1 if el.pressure == "master" else 2
                self.fr_mup[j] = el.pressure_coefficient
            self.fr_rs[j] = max(self.fr_rs[j], el.static_ratio)
            self.friction_names[j] = (self.friction_names[j] + "+" if self.friction_names[j] else "") + el.name

    def kernel_network(self):
        a = self.asm
        return (a["GA"], a["Gb"], a["d0"], self.cx, self.cf, self.cd, self.offsets, self.kinds, self.extraps,
                self.scale, self.unilateral)

    def kernel_friction(self):
        return (self.fr_on, self.fr_c0, self.fr_mun, self.fr_nidx, self.fr_mup, self.fr_pidx, self.fr_rs, self.fr_c)

    # ------------------------------------------------------------- initial state
    def initial_state(self, u0: float) -> tuple[np.ndarray, np.ndarray]:
        """Static equilibrium at bearing position ``u0`` with the actuator at rest; initial friction modes."""
        st = solve_static(self.model.network, np.array([u0]))
        X = st["node_positions"][0]
        names = st["node_names"]
        y = np.zeros(self.n)
        y[1] = u0
        for k, node in enumerate(self.asm["independent"]):
            y[2 + k] = X[names.index(node)]
        modes = np.zeros(self.nz, dtype=np.int64)
        modes[self.fr_on] = 2  # at rest: stuck; the state machine breaks away if the force exceeds the limit
        return y, modes

    def rest_position(self) -> float:
        """Bearing position at rest [m]: the CSC preload spring balances the clutch's bearing force.

        With the bundled parameters this is 0 (the bearing origin is set at the
        CSC preload); wear and thermal offsets or another preload move it.

        Raises
        ------
        ParameterError
            If no stable rest position lies within the CSC travel (e.g. a CSC
            preload above the clutch's bearing force everywhere: the clutch
            could not stay engaged).
        """
        a = self.actuator
        lo, hi = a.slave_min, a.slave_max

        def g(u):
            return a.csc_preload - a.csc_spring_rate * u - float(solve_static(self.model.network, [u])["input_force"][0])

        if abs(g(0.0)) < 1e-9:
            return 0.0
        grid = np.concatenate([np.linspace(0.0, hi, 201), np.linspace(0.0, lo, 41)[1:]])
        up = solve_static(self.model.network, grid[:201])["input_force"]
        down = solve_static(self.model.network, grid[201:])["input_force"] if lo < 0 else np.empty(0)
        gu = a.csc_preload - a.csc_spring_rate * grid[:201] - up
        gd = a.csc_preload - a.csc_spring_rate * grid[201:] - down
        from scipy.optimize import brentq

        if gu[0] > 0:  # pushed towards release: first stable root (g from + to -) going up
            k = np.flatnonzero((gu[:-1] > 0) & (gu[1:] <= 0))
            if k.size:
                return float(brentq(g, grid[k[0]], grid[k[0] + 1], xtol=1e-13))
        else:  # pulled towards the engaged side
            uu = np.concatenate([[0.0], grid[201:]])
            gg = np.concatenate([[gu[0]], gd])
            k = np.flatnonzero((gg[:-1] <= 0) & (gg[1:] > 0))
            if k.size:
                return float(brentq(g, uu[k[0] + 1], uu[k[0]], xtol=1e-13))
        raise ParameterError(
            f"inconsistent parameters: with csc_preload = {a.csc_preload!r} N the CSC finds no rest position within "
            f"its travel [{lo:g}, {hi:g}] m (the clutch's bearing force at position 0 is {a.csc_preload - g(0.0):.4g} N; "
            "EClutchParameters.bearing_preload and ActuatorParameters.csc_preload should match)")

    # --------------------------------------------------------------------- run
    def run(self, imode, tin, vin, interp, t_end, *, rtol, h_max, max_steps, t_grid, event_tol, y0=None, modes0=None,
            u0=0.0, jac_every=1, atol_scale=1.0):
        if not (np.isfinite(atol_scale) and atol_scale > 0):
            raise ParameterError(f"atol_scale = {atol_scale!r} must be finite and > 0")
        rows, what = ((t_grid.shape[0], f"t_end = {short_repr(t_end)} s at output_step = {short_repr(t_grid[1] - t_grid[0])} s")
                      if t_grid.shape[0] > 1 else (int(max_steps) + 1, f"max_steps = {max_steps!r} recorded steps"))
        # the kernel's records (time, states, auxiliaries, modes), then the outputs computed from them
        check_allocation(rows, 2 * (1 + self.n + K.N_AUX_FIXED + 2 * self.nz), what)
        if y0 is None:
            y0, modes0 = self.initial_state(u0)
        breaks = np.unique(tin[(tin > 0) & (tin < t_end)])
        T, Y, AUX, MODES, evt, evk, evi, stats, yf, mf = K.integrate(
            y0, modes0, 0.0, float(t_end), self.nz, imode, tin, vin, interp, breaks, self.par, self.mass, self.mvec,
            self.typ, *self.kernel_network(), *self.kernel_friction(), float(rtol), self.atol * atol_scale, 1e-5, float(h_max),
            int(max_steps), t_grid, float(event_tol), int(jac_every))
        return T, Y, AUX, MODES, evt, evk, evi, stats, yf, mf

    # ------------------------------------------------------------------ result
    def result(self, imode, tin, vin, interp, T, Y, MODES, evt, evk, evi, stats) -> DynamicsResult:
        AUX, F = K.outputs(T, Y, MODES, self.nz, imode, tin, vin, interp, self.par, self.mass,
                           *self.kernel_network(), *self.kernel_friction())
        nz = self.nz
        b0 = 2 * nz
        cols = [f"z_{c}_m" for c in self.coord_names] + [f"v_{c}_m_s" for c in self.coord_names] + [
            "master_pressure_Pa", "line_flow_m3_s", "pressure_Pa", "motor_current_A", "controller_integral_m_s",
            "input_work_J", "dissipated_J", "friction_dissipated_J"]
        states = pd.DataFrame(Y, columns=cols)
        states.insert(0, "time_s", T)
        a = self.actuator or ActuatorParameters()
        if imode == K.PRESCRIBED:
            u = AUX[:, 3]
            # the prescribed input's slope, right-continuous at the table's breakpoints
            seg = np.clip(np.searchsorted(tin, T, side="right") - 1, 0, max(len(tin) - 2, 0))
            v_u = np.zeros_like(u) if len(tin) < 2 else (vin[seg + 1] - vin[seg]) / (tin[seg + 1] - tin[seg])
            v_u = np.where((T < tin[0]) | (T >= tin[-1]), 0.0, v_u)
        else:
            u = Y[:, 1]
            v_u = Y[:, nz + 1]
        net = self.model.network
        el = self.element_names
        fn = F[:, el.index(net.normal_force)]
        out = {
            "time_s": T,
            "bearing_position_m": u,
            "bearing_velocity_m_s": v_u,
            "bearing_force_clutch_N": AUX[:, 1],
            "normal_force_N": fn,
            "torque_Nm": 2.0 * fn * self.model.r_eff * self.model.mu,
        }
        if imode != K.PRESCRIBED:
            out.update({
                "motor_voltage_V": AUX[:, 0],
                "motor_current_A": Y[:, b0 + 3],
                "motor_speed_rpm": Y[:, nz] / a.spindle_ratio * 60.0 / (2.0 * np.pi),
                "master_position_m": Y[:, 0],
                "master_pressure_Pa": Y[:, b0],
                "line_flow_m3_s": Y[:, b0 + 1],
                "pressure_Pa": Y[:, b0 + 2],
                "bearing_force_N": Y[:, b0 + 2] * a.slave_area,  # F_b = p A_sl, as the rig measures it ([1] Sec. 6)
            })
            if imode == K.POSITION:
                out["reference_m"] = AUX[:, 2]
        for k, node in enumerate(self.asm["independent"]):
            out[f"x_{node}_m"] = Y[:, 2 + k]
        for j in range(nz):
            if self.fr_on[j] or self.fr_c[j] > 0:
                out[f"friction_{self.coord_names[j]}_N"] = AUX[:, K.N_AUX_FIXED + j]
                out[f"stuck_{self.coord_names[j]}"] = MODES[:, j] == 2
        outputs = pd.DataFrame(out)
        rows = []
        for t_, k_, i_ in zip(evt, evk, evi):
            if k_ in (K.EV_STICK, K.EV_BREAKAWAY, K.EV_REVERSAL):
                where = f"{self.coord_names[i_]} ({self.friction_names[i_]})"
            elif k_ in (K.EV_CONTACT_OPEN, K.EV_CONTACT_CLOSE):
                where = el[i_]
            elif k_ in (K.EV_CAVITATION_START, K.EV_CAVITATION_END):
                where = _CHAMBERS[i_]
            else:
                where = _STOPS[i_]
            rows.append((t_, EVENT_KINDS[int(k_)], where))
        events = pd.DataFrame(rows, columns=["time_s", "event", "where"])
        st = {"accepted_steps": int(stats[0]), "rejected_steps": int(stats[1]), "rhs_evaluations": int(stats[2]),
              "jacobians": int(stats[3]), "status": int(stats[4])}
        return DynamicsResult(T, states, outputs, events, st, lambda: self._energy(Y, F, u, v_u, imode))

    def _energy(self, Y, F, u, v_u, imode) -> pd.DataFrame:
        """Stored energy from the states (independent of the integrator's bookkeeping)."""
        nz = self.nz
        b0 = 2 * nz
        a = self.actuator or ActuatorParameters()
        kin = 0.5 * (Y[:, nz: 2 * nz] ** 2 * self.mass[None, :])
        if imode == K.PRESCRIBED:
            kin[:, :2] = 0.0
        stored = kin.sum(axis=1)
        # elastic energy of the network elements
        asm = self.asm
        q = Y[:, 2: nz]
        D = asm["d0"][None, :] + q @ asm["GA"].T + np.outer(u, asm["Gb"])
        net = self.model.network
        for e, name in enumerate(self.element_names):
            elm = net.element(name)
            if isinstance(elm, Lever):
                curve, scl, uni = elm.curve(), 1.0, False
            else:
                curve, scl, uni = elm.curve, elm.scale, elm.unilateral
            stored = stored + _curve_energy(curve, scl, uni, D[:, e], D[0, e])
        if imode != K.PRESCRIBED:
            def cap(p, c):
                pc = a.vapour_pressure
                below = p < pc
                e = 0.5 * p ** 2 * c
                # below the vapour pressure the compliance is 1000 x larger (kernel P_CAVF)
                e_b = 0.5 * pc ** 2 * c + 0.5 * (p ** 2 - pc ** 2) * c * 1e3
                return np.where(below, e_b, e)
            stored = stored + 0.5 * a.inductance * Y[:, b0 + 3] ** 2
            stored = stored + cap(Y[:, b0], a.master_compliance) + cap(Y[:, b0 + 2], a.slave_compliance)
            stored = stored + 0.5 * a.line_inertance * Y[:, b0 + 1] ** 2
            # CSC preload spring: force F_pre - k_pre u on the piston
            stored = stored - (a.csc_preload * u - 0.5 * a.csc_spring_rate * u ** 2)
            # end stops
            ks = a.stop_stiffness
            for pen in (-Y[:, 0], Y[:, 0] - a.master_stroke, a.slave_min - u, u - a.slave_max):
                stored = stored + 0.5 * ks * np.maximum(pen, 0.0) ** 2
        return pd.DataFrame({"input_work_J": Y[:, b0 + 5], "dissipated_J": Y[:, b0 + 6],
                             "friction_dissipated_J": Y[:, b0 + 7], "stored_J": stored})


def _as_table(value, name: str):
    """``(times, values)`` from a scalar, a pair of sequences, a DataFrame or a mapping."""
    if np.isscalar(value):
        v = float(value)
        if not np.isfinite(v):
            raise ParameterError(f"input {name!r} = {value!r} is not finite")
        return np.array([0.0]), np.array([v])
    if isinstance(value, pd.DataFrame):
        cols = list(value.columns)
        if len(cols) != 2:
            raise ParameterError(f"input {name!r}: expected two columns (time_s and values), got {cols}")
        t, v = value.iloc[:, 0].to_numpy(float), value.iloc[:, 1].to_numpy(float)
    elif isinstance(value, Mapping):
        if set(value) != {"time_s", "value"}:
            raise ParameterError(f"input {name!r}: mapping needs keys 'time_s' and 'value', got {sorted(value)}")
        t, v = np.asarray(value["time_s"], float), np.asarray(value["value"], float)
    else:
        try:
            t, v = (np.asarray(x, dtype=float) for x in value)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"input {name!r}: expected (times, values), got {type(value).__name__}") from exc
    if t.ndim != 1 or v.shape != t.shape or t.size == 0:
        raise ParameterError(f"input {name!r}: times and values must be 1-D and of equal length")
    bad = ~(np.isfinite(t) & np.isfinite(v))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ParameterError(f"input {name!r}: row {i} (time {short_repr(t[i])} s, value {short_repr(v[i])}) is not finite")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise ParameterError(f"input {name!r}: times must increase strictly (row {i}: {short_repr(t[i])} s after {short_repr(t[i - 1])} s)")
    if t[0] > 0:
        t = np.concatenate([[0.0], t])
        v = np.concatenate([[v[0]], v])
    return np.ascontiguousarray(t), np.ascontiguousarray(v)


def _check_run(t_end, rtol, max_steps):
    if not (np.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"t_end = {t_end!r} s must be finite and > 0")
    if not (np.isfinite(rtol) and 1e-12 < rtol < 0.1):
        raise ParameterError(f"rtol = {rtol!r} must be in (1e-12, 0.1)")
    if int(max_steps) < 10:
        raise ParameterError(f"max_steps = {max_steps!r} must be >= 10")


def _grid(output_step, t_end):
    if output_step is None:
        return np.empty(0)
    if not (np.isfinite(output_step) and 0 < output_step <= t_end):
        raise ParameterError(f"output_step = {output_step!r} s must be in (0, t_end]")
    check_allocation(t_end / output_step + 1, 1, f"output_step = {output_step!r} s over t_end = {t_end!r} s")
    n = int(np.floor(t_end / output_step + 1e-9)) + 1
    return np.arange(n) * output_step


class ClutchDynamics:
    """Clutch axial dynamics driven by a prescribed bearing motion.

    Parameters
    ----------
    model : ClutchModel
        Axial Model 0-4 (:meth:`ClutchModel.preset`) or a variant.
    friction : FrictionParameters or list of FrictionElement, optional
        Friction elements (default :meth:`FrictionParameters.off`).

    Notes
    -----
    The bearing position is imposed (a stiff rig drive); the clutch's masses
    m_pp, m_pps, m_ds move under the element forces and friction, massless
    nodes are in equilibrium at every instant.  With friction off and a slow
    ramp the bearing force reproduces the static curve of
    :meth:`ClutchModel.static_curve`; with friction on it traces a hysteresis
    loop whose area is the energy the friction elements dissipate.
    """

    def __init__(self, model: ClutchModel, friction=None):
        friction = FrictionParameters.off() if friction is None else friction
        if isinstance(friction, FrictionParameters):
            friction = clutch_friction_elements(model.network, friction)
        self.model = model
        self.system = _System(model, None, list(friction), prescribed=True)

    def simulate(self, bearing_position, t_end: float | None = None, *, rtol: float = 1e-5, h_max: float = 0.01,
                 max_steps: int = 500_000, output_step: float | None = None, event_tol: float = 1e-9,
                 jac_every: int = 4, atol_scale: float = 1.0) -> DynamicsResult:
        """Simulate with the bearing position prescribed as ``(times [s], positions [m])`` (linear in between).

        Tolerances: ``rtol`` and the default absolute tolerances (10 nm, 10 um/s, 10 Pa, ...) times
        ``atol_scale``; other arguments as in :meth:`EClutch.simulate`.
        """
        tin, vin = _as_table(bearing_position, "bearing_position")
        t_end = float(tin[-1]) if t_end is None else float(t_end)
        _check_run(t_end, rtol, max_steps)
        grid = _grid(output_step, t_end)
        T, Y, AUX, MODES, evt, evk, evi, stats, _yf, _mf = self.system.run(
            K.PRESCRIBED, tin, vin, 0, t_end, rtol=rtol, h_max=h_max, max_steps=max_steps, t_grid=grid,
            event_tol=event_tol, u0=float(vin[0]), jac_every=jac_every, atol_scale=atol_scale)
        res = self.system.result(K.PRESCRIBED, tin, vin, 0, T, Y, MODES, evt, evk, evi, stats)
        _raise_status(res)
        return res


def _raise_status(res: DynamicsResult):
    if res.stats["status"] == 1:
        raise SimulationError(f"simulation stopped at t = {res.time[-1]:.6g} s: max_steps reached "
                              "(raise max_steps or loosen rtol)")
    if res.stats["status"] == 2:
        raise SimulationError(f"simulation stopped at t = {res.time[-1]:.6g} s: step size underflow "
                              "(inconsistent parameters or an input the model cannot follow)")


class EClutch:
    """The E-clutch: electro-hydrostatic actuator coupled to a clutch axial model.

    Parameters
    ----------
    actuator : ActuatorParameters
        Motor, spindle, master cylinder, line and CSC ([1] Sec. 2.1).
    clutch : ClutchModel
        Axial Model 0-4 or a variant; its bearing element is the release
        bearing stiffness k_b coupling the CSC to the clutch ([1] Sec. 3.2).
    friction : FrictionParameters or list of FrictionElement, optional
        Clutch friction elements (default :meth:`FrictionParameters.off`).
        The actuator's seal and spindle friction are always included
        (:func:`actuator_friction_elements`).
    """

    def __init__(self, actuator: ActuatorParameters | None = None, clutch: ClutchModel | None = None, friction=None):
        self.actuator = actuator or ActuatorParameters()
        if not isinstance(self.actuator, ActuatorParameters):
            raise ParameterError(f"actuator must be ActuatorParameters, got {type(self.actuator).__name__}")
        self.clutch = clutch or ClutchModel.preset(4)
        friction = FrictionParameters.off() if friction is None else friction
        if isinstance(friction, FrictionParameters):
            friction = clutch_friction_elements(self.clutch.network, friction)
        self.friction = list(friction) + actuator_friction_elements(self.actuator)
        self.system = _System(self.clutch, self.actuator, self.friction, prescribed=False)
        #: bearing position at rest [m] (0 unless offsets or the preload move it)
        self.rest_position = self.system.rest_position()

    def simulate(self, inputs, t_end: float, *, rtol: float = 1e-3, h_max: float = 0.01, max_steps: int = 500_000,
                 output_step: float | None = None, event_tol: float = 1e-8, jac_every: int = 10,
                 atol_scale: float = 1.0) -> DynamicsResult:
        """Simulate from rest (clutch engaged, actuator at its rest stop).

        Parameters
        ----------
        inputs : dict
            Exactly one of ``{"voltage": table}`` (motor voltage [V], held
            between samples) or ``{"bearing_reference": table}`` (bearing
            position reference [m], linear between samples, tracked by the
            position controller); a table is ``(times [s], values)``, a
            two-column DataFrame or a scalar (constant).
        t_end : float
            End time [s].
        rtol : float
            Relative tolerance of the Rodas3 integrator.
        h_max : float
            Largest step [s].
        max_steps : int
            Accepted-step budget.
        output_step : float, optional
            Record on a uniform grid (linear interpolation between steps);
            default: every accepted step.
        event_tol : float
            Time tolerance of event location [s].
        jac_every : int
            Reuse the finite-difference Jacobian for up to this many accepted
            steps (it is refreshed after every event and every rejected step).
        atol_scale : float
            Factor on the default absolute tolerances (0.1 um, 0.1 mm/s,
            100 Pa, 1 mA, ...).

        Returns
        -------
        DynamicsResult
            States, outputs (motor current, piston position, pressure, bearing
            position, ``bearing_force_N = p A_sl``, clutch forces, torque),
            events and statistics.
        """
        imode, interp, key, value = _input_mode(inputs)
        tin, vin = _as_table(value, key)
        t_end = float(t_end)
        _check_run(t_end, rtol, max_steps)
        grid = _grid(output_step, t_end)
        T, Y, AUX, MODES, evt, evk, evi, stats, _yf, _mf = self.system.run(
            imode, tin, vin, interp, t_end, rtol=rtol, h_max=h_max, max_steps=max_steps, t_grid=grid,
            event_tol=event_tol, jac_every=jac_every, atol_scale=atol_scale, u0=self.rest_position)
        res = self.system.result(imode, tin, vin, interp, T, Y, MODES, evt, evk, evi, stats)
        _raise_status(res)
        return res


def _input_mode(inputs):
    if not isinstance(inputs, Mapping) or len(inputs) != 1:
        raise ParameterError("inputs must be a mapping with exactly one of 'voltage' or 'bearing_reference'")
    (key, value), = inputs.items()
    if key == "voltage":
        return K.VOLTAGE, 1, key, value
    if key == "bearing_reference":
        return K.POSITION, 0, key, value
    raise ParameterError(f"unknown input {key!r}; use 'voltage' [V] or 'bearing_reference' [m]")


@dataclasses.dataclass
class BatchResult:
    """Results of :func:`simulate_batch` on a common time grid.

    Attributes
    ----------
    time : ndarray
        Output grid [s].
    outputs : dict of str to ndarray
        ``(n_variants, n_times)`` arrays: ``bearing_position_m``, ``bearing_force_N`` (``p A_sl``),
        ``pressure_Pa``, ``master_pressure_Pa``, ``motor_current_A``, ``motor_voltage_V``,
        ``master_position_m``, ``normal_force_N``, ``torque_Nm``, ``input_work_J``, ``dissipated_J``,
        ``friction_dissipated_J`` (and ``reference_m`` under position control).
    stats : pandas.DataFrame
        Accepted/rejected steps, right-hand sides, Jacobians, status and event count per variant.
    """

    time: np.ndarray
    outputs: dict
    stats: pd.DataFrame

    def to_dataframe(self, variant: int) -> pd.DataFrame:
        """The outputs of one variant as a table."""
        data = {"time_s": self.time}
        data.update({k: v[variant] for k, v in self.outputs.items()})
        return pd.DataFrame(data)


def simulate_batch(eclutches, inputs, t_end: float, *, output_step: float = 1e-3, rtol: float = 1e-3,
                   h_max: float = 0.01, max_steps: int = 500_000, event_tol: float = 1e-8,
                   jac_every: int = 10) -> BatchResult:
    """Simulate many E-clutch variants in parallel, one Rodas3 solver per variant (numba ``prange``).

    Parameters
    ----------
    eclutches : sequence of EClutch
        The variants, e.g. a sweep of lever ratio and stiffness scales.  They
        must share the model structure (same nodes, elements and component
        curves, same friction placement); scalar parameters, masses, lever
        ratios, pre-strains, stiffness scales and actuator parameters may differ.
    inputs : dict
        As in :meth:`EClutch.simulate` (one input for every variant).
    t_end, output_step : float
        End time and output grid step [s].
    rtol, h_max, max_steps, event_tol, jac_every
        As in :meth:`EClutch.simulate`.

    Returns
    -------
    BatchResult
    """
    ecs = list(eclutches)
    if not ecs:
        raise ParameterError("simulate_batch: no variants given")
    for k, ec in enumerate(ecs):
        if not isinstance(ec, EClutch):
            raise ParameterError(f"simulate_batch: variant {k} is a {type(ec).__name__}, not an EClutch")
    imode, interp, key, value = _input_mode(inputs)
    tin, vin = _as_table(value, key)
    t_end = float(t_end)
    _check_run(t_end, rtol, max_steps)
    grid = _grid(output_step, t_end)
    s0 = ecs[0].system
    shared = ("cx", "cf", "cd", "offsets", "kinds", "extraps", "unilateral", "fr_on", "fr_nidx", "fr_pidx", "mvec")
    for k, ec in enumerate(ecs[1:], start=1):
        s = ec.system
        if s.nz != s0.nz or len(s.element_names) != len(s0.element_names):
            raise ParameterError(f"simulate_batch: variant {k} has another model structure than variant 0")
        for name in shared:
            a, b = getattr(s, name), getattr(s0, name)
            if a.shape != b.shape or not np.array_equal(a, b):
                raise ParameterError(f"simulate_batch: variant {k} differs from variant 0 in {name!r} "
                                     "(component curves and friction placement must be shared)")
    Y0 = np.empty((len(ecs), s0.n))
    M0 = np.empty((len(ecs), s0.nz), dtype=np.int64)
    for k, ec in enumerate(ecs):
        y, m = ec.system.initial_state(ec.rest_position)
        Y0[k], M0[k] = y, m
    st = [ec.system for ec in ecs]
    stack = lambda name: np.ascontiguousarray(np.stack([getattr(s, name) for s in st]))  # noqa: E731
    asm = lambda name: np.ascontiguousarray(np.stack([s.asm[name] for s in st]))  # noqa: E731
    breaks = np.unique(tin[(tin > 0) & (tin < t_end)])
    OUT, AUX, F, STATS, NEV = K.integrate_batch(
        Y0, M0, t_end, s0.nz, imode, tin, vin, interp, breaks, stack("par"), stack("mass"), s0.mvec, s0.typ,
        asm("GA"), asm("Gb"), asm("d0"), s0.cx, s0.cf, s0.cd, s0.offsets, s0.kinds, s0.extraps, stack("scale"),
        s0.unilateral, s0.fr_on, stack("fr_c0"), stack("fr_mun"), s0.fr_nidx, stack("fr_mup"), s0.fr_pidx,
        stack("fr_rs"), stack("fr_c"), float(rtol), s0.atol, 1e-5, float(h_max), int(max_steps), grid,
        float(event_tol), int(jac_every))
    nz = s0.nz
    b0 = 2 * nz
    a_sl = np.array([ec.actuator.slave_area for ec in ecs])[:, None]
    r_eff = np.array([ec.clutch.r_eff * ec.clutch.mu for ec in ecs])[:, None]
    nf = s0.element_names.index(ecs[0].clutch.network.normal_force)
    out = {
        "bearing_position_m": OUT[:, :, 1], "bearing_velocity_m_s": OUT[:, :, nz + 1],
        "pressure_Pa": OUT[:, :, b0 + 2], "master_pressure_Pa": OUT[:, :, b0],
        "bearing_force_N": OUT[:, :, b0 + 2] * a_sl, "bearing_force_clutch_N": AUX[:, :, 1],
        "motor_current_A": OUT[:, :, b0 + 3], "motor_voltage_V": AUX[:, :, 0],
        "master_position_m": OUT[:, :, 0], "normal_force_N": F[:, :, nf], "torque_Nm": 2.0 * F[:, :, nf] * r_eff,
        "input_work_J": OUT[:, :, b0 + 5], "dissipated_J": OUT[:, :, b0 + 6],
        "friction_dissipated_J": OUT[:, :, b0 + 7],
    }
    if imode == K.POSITION:
        out["reference_m"] = AUX[:, :, 2]
    stats = pd.DataFrame(STATS, columns=["accepted_steps", "rejected_steps", "rhs_evaluations", "jacobians",
                                         "status"])
    stats["events"] = NEV
    return BatchResult(grid, out, stats)
