"""One small description for every axial model of the clutch: nodes and elements.

The clutch of Haramina et al. [1] is a chain of springs, a lever and masses
along the clutch axis.  Models 0-4 of the paper (Figs. 5b, 10, 11) differ only
in which elements they contain, so clutchlab describes each model as an
:class:`AxialNetwork` of

* :class:`Node` -- an axial coordinate (positive towards the flywheel, i.e. in
  the release direction of the bearing) with an optional mass;
* :class:`Spring` -- a nonlinear spring (a :class:`~clutchlab.Curve`) between
  two nodes or a node and the ground, with its pre-strain in the assembled
  clutch, a stiffness scale and an optional unilateral (contact) law;
* :class:`Lever` -- the diaphragm-spring lever with ratio ``i_ds < 0`` between
  its tip (release bearing side), its edge (pressure-plate side) and its pivot
  (the yoke support), rigid or with the lever compliance ``k_fl`` of Eq. (1).

All positions are displacements from the assembled, engaged clutch with the
bearing at zero.  The prescribed node (``input``, the release bearing) is the
abscissa of the static curves; the bearing force is the force needed there.

Static equilibrium is solved directly (:func:`solve_static`): the rigid levers
and the input are eliminated as linear constraints ``x = A q + b u + c``, the
remaining coordinates ``q`` are found by a damped Newton method with a
tangent predictor along the bearing travel (natural-parameter continuation),
compiled with numba.  The stiffness matrix ``(GA)^T K (GA)`` may be indefinite
in the negative-stiffness region of the diaphragm spring; Newton solves the
equilibrium equations there all the same, and the continuation step is halved
until it converges.

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, Trans. FAMENA
   48 (2024) 21-35, doi:10.21278/TOF.483057923
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np

from ..curves import Curve, curve_eval_segment
from .._limits import short_repr
from ..errors import ParameterError, SimulationError
from ..numerics.rosenbrock import lu_factor, lu_solve
from ..system import start_checks_deferred

__all__ = ["Node", "Spring", "Lever", "AxialNetwork", "solve_static", "zero_input", "GROUND"]

GROUND = "ground"


@dataclass(frozen=True)
class Node:
    """An axial coordinate of the clutch.

    Parameters
    ----------
    name : str
        Unique name (``"ground"`` is reserved for the housing/cover/flywheel).
    mass : float
        Lumped mass [kg] moving with the node (used by dynamic models; zero
        means a massless, algebraic node).
    """

    name: str
    mass: float = 0.0

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name or self.name == GROUND:
            raise ParameterError(f"node name {self.name!r} is empty or reserved")
        if not (np.isfinite(self.mass) and self.mass >= 0):
            raise ParameterError(f"node {self.name!r}: mass = {short_repr(self.mass)} kg must be finite and >= 0")


@dataclass(frozen=True)
class Spring:
    """A nonlinear spring between node ``a`` and node ``b`` (or the ground).

    Its deflection is ``d = prestrain + gain * (x_a - x_b)`` [m] and its force
    ``f = scale * curve(d)`` [N] pushes ``a`` back (force on ``a`` is
    ``-gain*f``, on ``b`` ``+gain*f``).  ``gain`` lets a spring act through a
    lever (the diaphragm's Belleville body seen at the finger tips has
    ``gain = i_ds``).

    Parameters
    ----------
    name : str
        Unique element name.
    a, b : str
        Node names; ``b`` defaults to the ground.
    curve : Curve
        Force-deflection characteristic [m -> N].
    prestrain : float
        Deflection in the assembled clutch with all nodes at zero [m].
    scale : float
        Stiffness scale (force multiplied at equal deflection); Model 4 of [1]
        uses 20 for the yoke support and 1.3 for the diaphragm spring.
    unilateral : bool
        Contact law: the spring carries only compression,
        ``f = max(scale*curve(d), 0)``; the contact opens when the force
        reaches zero (lift-off of the pressure plate from the friction plate).
    gain : float
        Kinematic gain from node displacement to deflection (default 1).
    """

    name: str
    a: str
    curve: Curve
    b: str = GROUND
    prestrain: float = 0.0
    scale: float = 1.0
    unilateral: bool = False
    gain: float = 1.0

    def __post_init__(self):
        if not isinstance(self.curve, Curve):
            raise ParameterError(f"spring {self.name!r}: curve must be a clutchlab.Curve, got {type(self.curve).__name__}")
        if not np.isfinite(self.prestrain):
            raise ParameterError(f"spring {self.name!r}: prestrain = {short_repr(self.prestrain)} m is not finite")
        if not (np.isfinite(self.scale) and self.scale > 0):
            raise ParameterError(f"spring {self.name!r}: scale = {short_repr(self.scale)} must be finite and > 0")
        if not (np.isfinite(self.gain) and self.gain != 0):
            raise ParameterError(f"spring {self.name!r}: gain = {short_repr(self.gain)} must be finite and non-zero")
        if self.a == self.b:
            raise ParameterError(f"spring {self.name!r}: both ends on node {self.a!r}")

    def coefficients(self) -> dict[str, float]:
        """Deflection gradient ``{node: dd/dx_node}``."""
        out = {self.a: self.gain}
        out[self.b] = out.get(self.b, 0.0) - self.gain
        return out


@dataclass(frozen=True)
class Lever:
    """Diaphragm-spring lever: ``tip - pivot = i_ds * (edge - pivot)`` when rigid.

    With a finite lever stiffness (the finger compliance ``k_fl`` of [1],
    Eq. 1) the lever deflection ``d = prestrain + (x_tip - x_pivot)
    - i_ds (x_edge - x_pivot)`` carries the force ``f = stiffness(d)``, which
    acts on the tip as ``-f``, on the edge as ``+i_ds f`` and on the pivot as
    ``+(1 - i_ds) f`` (virtual work).  Rigid levers are eliminated as
    constraints.

    Parameters
    ----------
    name : str
        Unique element name.
    tip, edge : str
        Nodes at the finger tips (release bearing) and at the outer edge
        (pressure plate).
    ratio : float
        Lever ratio ``i_ds`` [-], negative: pushing the tips towards the
        flywheel lifts the edge away from it.
    pivot : str
        Pivot node (yoke support), default the ground.
    stiffness : float, Curve or None
        ``None`` for a rigid lever, a constant ``k_fl`` [N/m], or a Curve.
    prestrain : float
        Lever deflection in the assembled clutch [m].
    """

    name: str
    tip: str
    edge: str
    ratio: float
    pivot: str = GROUND
    stiffness: float | Curve | None = None
    prestrain: float = 0.0

    def __post_init__(self):
        if not (np.isfinite(self.ratio) and self.ratio < 0):
            raise ParameterError(f"lever {self.name!r}: ratio i_ds = {short_repr(self.ratio)} must be finite and < 0")
        if len({self.tip, self.edge, self.pivot}) != 3:
            raise ParameterError(f"lever {self.name!r}: tip, edge and pivot must be three different nodes")
        if not np.isfinite(self.prestrain):
            raise ParameterError(f"lever {self.name!r}: prestrain = {short_repr(self.prestrain)} m is not finite")
        s = self.stiffness
        if s is not None and not isinstance(s, Curve):
            if isinstance(s, bool) or not isinstance(s, (int, float)) or not (np.isfinite(s) and s > 0):
                raise ParameterError(f"lever {self.name!r}: stiffness k_fl = {short_repr(s)} N/m must be finite and > 0 (or None: rigid)")

    @property
    def rigid(self) -> bool:
        """True if the lever has no compliance."""
        return self.stiffness is None

    def curve(self) -> Curve:
        """The lever compliance as a Curve (linear for a constant ``k_fl``)."""
        if self.stiffness is None:
            raise ParameterError(f"lever {self.name!r} is rigid")
        if isinstance(self.stiffness, Curve):
            return self.stiffness
        return Curve.linear(float(self.stiffness), name=f"{self.name} k_fl")

    def coefficients(self) -> dict[str, float]:
        """Deflection gradient ``{node: dd/dx_node}``."""
        out = {self.tip: 1.0, self.edge: -self.ratio}
        out[self.pivot] = out.get(self.pivot, 0.0) - (1.0 - self.ratio)
        return out


@dataclass(frozen=True)
class AxialNetwork:
    """A clutch axial model: nodes, elements and the prescribed input node.

    Parameters
    ----------
    nodes : tuple of Node
        Every node except the ground, including the input node.
    elements : tuple of Spring and Lever
        The elastic elements and levers.
    input : str
        Node whose position is prescribed (the release bearing / CSC).
    normal_force : str
        Name of the spring whose force is the clutch normal force F_n (the
        contact of pressure plate and friction plate: the cushion spring).
    name : str
        Label of the model.

    Notes
    -----
    Positions are in metres from the assembled, engaged state, positive
    towards the flywheel (the release direction of the bearing of a push-type
    diaphragm clutch).
    """

    nodes: tuple
    elements: tuple
    input: str = "bearing"
    normal_force: str = "cushion"
    name: str = "axial network"
    _assembly: dict = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "nodes", tuple(self.nodes))
        object.__setattr__(self, "elements", tuple(self.elements))
        names = [n.name for n in self.nodes]
        if len(set(names)) != len(names):
            raise ParameterError(f"network {self.name!r}: duplicate node names in {names}")
        enames = [e.name for e in self.elements]
        if len(set(enames)) != len(enames):
            raise ParameterError(f"network {self.name!r}: duplicate element names in {enames}")
        known = set(names) | {GROUND}
        for e in self.elements:
            for node in e.coefficients():
                if node not in known:
                    raise ParameterError(f"network {self.name!r}: element {e.name!r} refers to unknown node {node!r}")
        if self.input not in names:
            raise ParameterError(f"network {self.name!r}: input node {self.input!r} is not a node")
        springs = {e.name: e for e in self.elements if isinstance(e, Spring)}
        if self.normal_force not in springs:
            raise ParameterError(f"network {self.name!r}: normal_force element {self.normal_force!r} is not a spring")
        object.__setattr__(self, "_assembly", self._assemble())

    # ------------------------------------------------------------ convenience
    def element(self, name: str):
        """Return the element called ``name``."""
        for e in self.elements:
            if e.name == name:
                return e
        raise ParameterError(f"network {self.name!r}: no element {name!r} (has: {[e.name for e in self.elements]})")

    def node(self, name: str) -> Node:
        """Return the node called ``name``."""
        for n in self.nodes:
            if n.name == name:
                return n
        raise ParameterError(f"network {self.name!r}: no node {name!r}")

    def modified(self, *, nodes=(), replace=None, add=(), name: str | None = None) -> "AxialNetwork":
        """Return a copy with extra ``nodes``, elements replaced (``{name: new}``) and ``add``-ed.

        This is how Models 1-4 extend Model 0: each adds nodes (masses) and
        compliances or moves an element to another node.  Replacing with
        ``None`` removes the element.
        """
        nodes, elements = modified_parts(self.nodes, self.elements, extra_nodes=nodes, replace=replace, add=add,
                                         where=f"network {self.name!r}")
        return AxialNetwork(nodes, elements, input=self.input, normal_force=self.normal_force, name=name or self.name)

    def _with_prestrain(self, name: str, prestrain: float) -> "AxialNetwork":
        """A copy with spring ``name``'s pre-strain set to ``prestrain`` [m], its assembly reused: the
        topology, the curves and every check are unchanged, only the spring's rest deflection ``d0`` moves
        (computed as :meth:`_assemble` does, so the copy equals ``replace_element`` bit for bit).  For the
        zeroing's root search, which changes one pre-strain dozens of times per model."""
        old = self.element(name)
        if not isinstance(old, Spring):
            raise ParameterError(f"network {self.name!r}: {name!r} is not a spring")
        a = dict(self._assembly)
        k = a["element_names"].index(name)
        d0 = a["d0"].copy()
        d0[k] = float(prestrain) + a["Gc"][k]
        a["d0"] = d0
        net = object.__new__(AxialNetwork)
        for f in ("nodes", "input", "normal_force", "name"):
            object.__setattr__(net, f, getattr(self, f))
        object.__setattr__(net, "elements", tuple(_replace_spring(e, prestrain=float(prestrain))
                                                  if e.name == name else e for e in self.elements))
        object.__setattr__(net, "_assembly", a)
        return net

    def replace_element(self, name: str, new) -> "AxialNetwork":
        """Return a copy with element ``name`` replaced by ``new`` (``None`` removes it)."""
        return self.modified(replace={name: new})

    def describe(self) -> str:
        """Text listing of nodes and elements (topology of the model)."""
        lines = [f"{self.name}: input node {self.input!r}, normal force from {self.normal_force!r}"]
        for n in self.nodes:
            lines.append(f"  node    {n.name:<10} mass {n.mass:.4g} kg")
        for e in self.elements:
            if isinstance(e, Lever):
                k = "rigid" if e.rigid else (f"k_fl = {e.stiffness:.4g} N/m" if not isinstance(e.stiffness, Curve) else "k_fl curve")
                lines.append(f"  lever   {e.name:<10} tip {e.tip}, edge {e.edge}, pivot {e.pivot}, i_ds = {e.ratio:g}, {k}")
            else:
                kind = "contact" if e.unilateral else "spring"
                lines.append(f"  {kind:<8}{e.name:<10} {e.a} - {e.b}, prestrain {e.prestrain * 1e3:.4g} mm, "
                             f"scale {e.scale:g}, gain {e.gain:g}, curve {e.curve.name!r}")
        return "\n".join(lines)

    # ----------------------------------------------------------------- assembly
    def _assemble(self) -> dict:
        from scipy.linalg import null_space

        names = [n.name for n in self.nodes]
        idx = {n: i for i, n in enumerate(names)}
        N = len(names)
        rows, rhs_u, rhs_c = [], [], []
        # input constraint x_in = u
        r = np.zeros(N)
        r[idx[self.input]] = 1.0
        rows.append(r), rhs_u.append(1.0), rhs_c.append(0.0)
        elastic = []
        for e in self.elements:
            g = np.zeros(N)
            for node, coef in e.coefficients().items():
                if node != GROUND:
                    g[idx[node]] += coef
            if isinstance(e, Lever) and e.rigid:
                rows.append(g), rhs_u.append(0.0), rhs_c.append(-e.prestrain)
            else:
                elastic.append((e, g))
        C = np.array(rows)
        # one SVD for the rank and the pseudo-inverse (what numpy's matrix_rank and pinv each compute)
        u_c, s_c, vt_c = np.linalg.svd(C, full_matrices=False)
        if np.count_nonzero(s_c > s_c.max(initial=0.0) * max(C.shape) * np.finfo(float).eps) < C.shape[0]:
            raise ParameterError(f"network {self.name!r}: rigid levers over-constrain the nodes")
        large = s_c > 1e-15 * s_c.max(initial=0.0)
        inv_s = np.divide(1.0, s_c, where=large, out=np.zeros_like(s_c))
        pinv = np.matmul(vt_c.T, np.multiply(inv_s[:, None], u_c.T))
        b = pinv @ np.array(rhs_u)
        c = pinv @ np.array(rhs_c)
        A = null_space(C)
        if A.shape[1] == 0:
            raise ParameterError(f"network {self.name!r}: no free coordinate left after the constraints")
        G = np.array([g for _, g in elastic])
        GA = G @ A
        # every free coordinate must be held by some element
        if np.linalg.matrix_rank(GA) < A.shape[1]:
            raise ParameterError(f"network {self.name!r}: a node is not connected to any spring (singular network)")
        curves, prestrain, scale, unilateral = [], [], [], []
        for e, _ in elastic:
            if isinstance(e, Lever):
                curves.append(e.curve()), prestrain.append(e.prestrain), scale.append(1.0), unilateral.append(False)
            else:
                curves.append(e.curve), prestrain.append(e.prestrain), scale.append(e.scale), unilateral.append(e.unilateral)
        Gc = G @ c
        offsets = np.zeros(len(curves) + 1, dtype=np.int64)
        for k, cv in enumerate(curves):
            offsets[k + 1] = offsets[k] + cv.deflection.size
        data = [cv.kernel_data() for cv in curves]
        cx = np.concatenate([k[0] for k in data])
        cf = np.concatenate([k[1] for k in data])
        cd = np.concatenate([k[2] for k in data])
        kinds = np.array([k[3] for k in data], dtype=np.int64)
        extraps = np.array([k[4] for k in data], dtype=np.int64)
        return dict(
            node_names=names, element_names=[e.name for e, _ in elastic], A=A, b=b, c=c, G=G,
            GA=np.ascontiguousarray(GA), Gb=np.ascontiguousarray(G @ b), Gc=Gc,
            d0=np.ascontiguousarray(np.array(prestrain) + Gc),
            cx=cx, cf=cf, cd=cd, offsets=offsets, kinds=kinds, extraps=extraps,
            scale=np.array(scale), unilateral=np.array(unilateral, dtype=np.bool_),
        )

    @property
    def n_free(self) -> int:
        """Number of free coordinates after eliminating the input and the rigid levers."""
        return self._assembly["A"].shape[1]

    def kernel_data(self) -> tuple:
        """Arrays for the compiled kernels (see :func:`_static_path`)."""
        a = self._assembly
        return (a["GA"], a["Gb"], a["d0"], a["cx"], a["cf"], a["cd"], a["offsets"], a["kinds"], a["extraps"],
                a["scale"], a["unilateral"])


# ---------------------------------------------------------------------------
# compiled static solver
# ---------------------------------------------------------------------------

@numba.njit(cache=True, nogil=True, inline="always")
def element_force(e, q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral):
    """Deflection, force and tangent stiffness of elastic element ``e`` of an axial network ([1] Figs. 5b, 10-11).

    The element's deflection is linear in the free coordinates and the input,
    ``d_e = d0_e + Gb_e u + sum_j GA_ej q_j`` [m] (node-aligned coordinates of
    the network, rigid levers eliminated); its force is its characteristic
    curve times its stiffness scale, ``f_e = scale_e F_e(d_e)`` [N], and a
    unilateral element (a contact: the cushion, the release bearing) carries
    no tension, ``f_e = max(f_e, 0)``.  The one implementation of the
    element law: the static solver (:func:`element_forces`) and the dynamics
    (:mod:`clutchlab.eclutch.system`) both call it.

    Parameters
    ----------
    e : int
        Element index (assembly order).
    q : ndarray
        Free coordinates [m].
    u : float
        Input (bearing) position [m].
    GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral
        Assembly arrays of :meth:`AxialNetwork.kernel_data`.

    Returns
    -------
    (d, f, k, f_free) : tuple of float
        Deflection [m], force [N] and tangent stiffness [N/m] after the
        contact law, and the force before it [N] (its sign says whether a
        unilateral element is in contact: the contact's switching function).
    """
    de, fe, ke, free, _seg = element_force_segment(e, q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale,
                                                   unilateral, -1)
    return de, fe, ke, free


@numba.njit(cache=True, nogil=True, inline="always")
def element_force_segment(e, q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, hint):
    """:func:`element_force` with the curve's segment of a previous look-up as a hint, and the segment used.

    The one implementation of the element law (:func:`element_force` calls it without a hint); the hint
    (:func:`clutchlab.curves.curve_eval_segment`) only spares the search, the result is the same.  Returns
    ``(d, f, k, f_free, segment)``.
    """
    de = d0[e] + Gb[e] * u
    for j in range(GA.shape[1]):
        de += GA[e, j] * q[j]
    fe, ke, seg = curve_eval_segment(cx, cf, cd, offsets[e], offsets[e + 1], kinds[e], extraps[e], de, hint)
    fe *= scale[e]
    ke *= scale[e]
    free = fe
    if unilateral[e] and fe <= 0.0:
        fe = 0.0
        ke = 0.0
    return de, fe, ke, free, seg


@numba.njit(cache=True, nogil=True)
def element_forces(q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f, k, d):
    """Deflections ``d`` [m], forces ``f`` [N] and tangent stiffnesses ``k`` [N/m] of all elastic elements.

    Fills the output arrays with :func:`element_force` of every element.
    """
    for e in range(GA.shape[0]):
        d[e], f[e], k[e], _free = element_force(e, q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale,
                                                unilateral)


@numba.njit(cache=True, nogil=True)
def _residual(q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f, k, d, r):
    """Generalised force residual ``r = (GA)^T f(d)``; returns its Euclidean norm [N]."""
    element_forces(q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f, k, d)
    rn = 0.0
    for j in range(GA.shape[1]):
        s = 0.0
        for e in range(GA.shape[0]):
            s += GA[e, j] * f[e]
        r[j] = s
        rn += s * s
    return np.sqrt(rn)


@numba.njit(cache=True, nogil=True)
def _solve_in_place(J, b):
    """``b <- J^-1 b`` by LU with partial pivoting (``J`` is overwritten); False if ``J`` is singular.

    The small dense solve of the core (numba's ``np.linalg.solve`` costs seconds of compilation).
    """
    piv = np.empty(J.shape[0], dtype=np.int64)
    if not lu_factor(J, piv):
        return False
    lu_solve(J, piv, b)
    return True


@numba.njit(cache=True, nogil=True)
def _newton(q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f_tol, x_tol, max_iter):
    """Damped Newton on ``(GA)^T f(d) = 0``; returns (converged, iterations)."""
    n_el = GA.shape[0]
    n_q = GA.shape[1]
    f = np.empty(n_el)
    k = np.empty(n_el)
    d = np.empty(n_el)
    r = np.empty(n_q)
    rt = np.empty(n_q)
    J = np.empty((n_q, n_q))
    qt = np.empty(n_q)
    for it in range(max_iter):
        rn = _residual(q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f, k, d, r)
        if not np.isfinite(rn):
            return False, it
        if rn <= f_tol:
            return True, it
        for i in range(n_q):
            for j in range(n_q):
                s = 0.0
                for e in range(n_el):
                    s += GA[e, i] * k[e] * GA[e, j]
                J[i, j] = s
        # regularise a singular tangent (e.g. all contacts open on one node)
        for i in range(n_q):
            J[i, i] += 1e-9 * (abs(J[i, i]) + 1.0)
        dq = r.copy()
        if not _solve_in_place(J, dq):
            return False, it
        step = 1.0
        for _ls in range(30):
            for j in range(n_q):
                qt[j] = q[j] - step * dq[j]
            rtn = _residual(qt, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f, k, d, rt)
            if np.isfinite(rtn) and rtn < (1.0 - 1e-4 * step) * rn:
                break
            step *= 0.5
        # after 30 halvings the (tiny) step is taken anyway: a contact kink may block the line search
        dmax = 0.0
        for j in range(n_q):
            dmax = max(dmax, abs(qt[j] - q[j]))
            q[j] = qt[j]
        if dmax <= x_tol:
            rn = _residual(q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f, k, d, r)
            return rn <= 1e3 * f_tol, it
    return False, max_iter


@numba.njit(cache=True, nogil=True)
def _tangent(q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral):
    """dq/du along the equilibrium path: ``-J^{-1} (GA)^T K Gb``."""
    n_el = GA.shape[0]
    n_q = GA.shape[1]
    f = np.empty(n_el)
    k = np.empty(n_el)
    d = np.empty(n_el)
    element_forces(q, u, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f, k, d)
    J = np.empty((n_q, n_q))
    rhs = np.empty(n_q)
    for i in range(n_q):
        s = 0.0
        for e in range(n_el):
            s += GA[e, i] * k[e] * Gb[e]
        rhs[i] = -s
        for j in range(n_q):
            s = 0.0
            for e in range(n_el):
                s += GA[e, i] * k[e] * GA[e, j]
            J[i, j] = s
        J[i, i] += 1e-9 * (abs(J[i, i]) + 1.0)
    if not _solve_in_place(J, rhs):
        rhs[:] = np.nan
    return rhs


@numba.njit(cache=True, nogil=True)
def _static_path(u_grid, q0, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, f_tol, x_tol):
    """Equilibria along ``u_grid`` by continuation; returns (q, forces, deflections, status)."""
    n_u = u_grid.shape[0]
    n_q = GA.shape[1]
    n_el = GA.shape[0]
    Q = np.empty((n_u, n_q))
    F = np.empty((n_u, n_el))
    D = np.empty((n_u, n_el))
    kk = np.empty(n_el)
    q = q0.copy()
    u_prev = u_grid[0]
    status = 0
    for i in range(n_u):
        target = u_grid[i]
        n_sub = 1
        ok = False
        q_start = q.copy()
        while n_sub <= 4096:
            for j in range(n_q):   # (element by element: a slice assignment's error is built in Python)
                q[j] = q_start[j]
            uc = u_prev
            ok = True
            for s in range(n_sub):
                un = u_prev + (target - u_prev) * (s + 1) / n_sub
                if i > 0 or s > 0:
                    tq = _tangent(q, uc, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral)
                    for j in range(n_q):
                        q[j] += tq[j] * (un - uc)
                conv, _it = _newton(q, un, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral,
                                    f_tol, x_tol, 60)
                if not conv:
                    ok = False
                    break
                uc = un
            if ok:
                break
            n_sub *= 4
        if not ok:
            status = i + 1
            return Q[:i], F[:i], D[:i], status
        for j in range(n_q):
            Q[i, j] = q[j]
        element_forces(q, target, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral, F[i], kk, D[i])
        u_prev = target
    return Q, F, D, status


def solve_static(network: AxialNetwork, input_positions, *, q0=None, force_tol: float = 1e-7, x_tol: float = 1e-14):
    """Static equilibria of ``network`` along the prescribed input positions.

    Parameters
    ----------
    network : AxialNetwork
        The clutch model.
    input_positions : array_like
        Positions of the input node (release bearing) [m], visited in order
        (continuation follows this path, so pass a monotone travel; a release
        followed by an engagement is fine).
    q0 : array_like, optional
        Initial guess of the free coordinates at the first position (default
        zeros: the assembled state).
    force_tol : float
        Residual force tolerance [N].
    x_tol : float
        Position-increment tolerance [m].

    Returns
    -------
    dict
        ``input`` [m], ``node_positions`` (n x nodes) [m], ``forces`` and
        ``deflections`` of the elastic elements (n x elements) [N], [m],
        ``input_force`` [N] (the bearing force), ``node_names``,
        ``element_names``.

    Raises
    ------
    SimulationError
        If Newton fails even with 4096 continuation sub-steps (e.g. a
        snap-through that position control cannot follow).
    """
    u = np.ascontiguousarray(np.atleast_1d(np.asarray(input_positions, dtype=float)))
    if u.ndim != 1 or u.size == 0 or not np.all(np.isfinite(u)):
        raise ParameterError("input positions must be a non-empty 1-D array of finite values [m]")
    a = network._assembly
    q = np.zeros(network.n_free) if q0 is None else np.asarray(q0, dtype=float).copy()
    # first point: walk from the assembled state (u = 0) to u[0] so that Newton starts close
    if u[0] != 0.0 and q0 is None:
        pre = np.linspace(0.0, u[0], 9)
        Qp, _, _, st = _static_path(pre, q, *network.kernel_data(), force_tol, x_tol)
        if st == 0:
            q = Qp[-1].copy()
    Q, F, D, status = _static_path(u, q, *network.kernel_data(), force_tol, x_tol)
    if status:
        raise SimulationError(
            f"{network.name}: static equilibrium not found at input position {short_repr(u[status - 1])} m "
            "(snap-through or an element without stiffness)"
        )
    X = Q @ a["A"].T + np.outer(u, a["b"]) + a["c"]
    input_force = F @ a["Gb"]
    return dict(input=u, node_positions=X, forces=F, deflections=D, input_force=input_force,
                node_names=list(a["node_names"]), element_names=list(a["element_names"]))


def zero_input(network: AxialNetwork, element: str, force: float, *, bracket=(-0.05, 0.05)) -> AxialNetwork:
    """Shift the pre-strain of ``element`` so the input force at input position 0 equals ``force``.

    This sets the origin of the bearing travel to the engaged clutch with the
    bearing pressed by the CSC preload ``force`` [N], the usual zero of a
    release-bearing position sensor.

    Parameters
    ----------
    network : AxialNetwork
        The model.
    element : str
        Spring whose pre-strain is shifted (the bearing contact).
    force : float
        Input force wanted at input position 0 [N].
    bracket : (float, float)
        Pre-strain interval searched by Brent's method [m].

    Returns
    -------
    AxialNetwork
        A new network with the shifted pre-strain.
    """
    from scipy.optimize import brentq

    el = network.element(element)
    if not isinstance(el, Spring):
        raise ParameterError(f"zero_input: element {element!r} must be a spring")
    if not (np.isfinite(force) and force >= 0):
        raise ParameterError(f"zero_input: force = {short_repr(force)} N must be finite and >= 0")

    # the residual is solve_static(network with pre-strain p, [0.0])["input_force"][0] - force, computed
    # without building that network: only the element's rest deflection d0 moves (as _with_prestrain
    # sets it, so the root is the same to the last bit)
    a = network._assembly
    k = a["element_names"].index(element)
    kernel = list(network.kernel_data())
    d0 = kernel[2] = kernel[2].copy()
    gc, gb = a["Gc"][k], a["Gb"]
    u0, q0 = np.zeros(1), np.zeros(network.n_free)

    def residual(p):
        return _zeroing_residual(float(p), k, gc, gb, float(force), u0, q0, *kernel)

    lo, hi = bracket
    # the input force is linear in the pre-strain while the contact is closed: secant steps from the
    # element's own pre-strain find the root in a few solves (Brent's method from the wide bracket took
    # 17-18, most of them where the contact is open and the force is flat), compiled in one call; Brent's
    # method remains the fallback and gives the refusal
    p = _zeroing_root(float(el.prestrain), float(el.prestrain) + 1e-6, lo, hi, 1e-13, 1e-12, k, gc, gb,
                      float(force), u0, q0, *kernel)
    p = None if np.isnan(p) else p
    if p is None:
        r_lo, r_hi = residual(lo), residual(hi)
        if not (np.isfinite(r_lo) and np.isfinite(r_hi)) or r_lo * r_hi > 0:
            if start_checks_deferred():   # (a native FMU's trial build: its start refuses it, derive_clutch)
                return network
            raise ParameterError(f"zero_input: cannot reach an input force of {short_repr(force)} N by shifting {element!r} within [{short_repr(lo)}, {short_repr(hi)}] m")
        p = brentq(residual, lo, hi, xtol=1e-13, rtol=1e-12)
    return network._with_prestrain(element, p)  # (equals replace_element bit for bit, without assembling again)


@numba.njit(cache=True, nogil=True)
def _zeroing_residual(p, k, gc, gb, force, u0, q0, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral):
    """Input force at input position 0 minus ``force`` [N] with element ``k``'s pre-strain ``p`` [m] (its rest
    deflection ``d0[k] = p + gc``, as :meth:`AxialNetwork._with_prestrain` sets it; ``d0`` is changed);
    NaN where no equilibrium is found."""
    d0[k] = p + gc
    _, F, _, status = _static_path(u0, q0, GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral,
                                   1e-7, 1e-14)
    if status:
        return np.nan
    s = 0.0
    for e in range(F.shape[1]):
        s += F[0, e] * gb[e]
    return s - force


@numba.njit(cache=True, nogil=True)
def _zeroing_root(x0, x1, lo, hi, xtol, rtol, k, gc, gb, force, u0, q0, GA, Gb, d0, cx, cf, cd, offsets, kinds,
                  extraps, scale, unilateral):
    """The pre-strain [m] of :func:`zero_input` by secant steps from ``x0``, ``x1`` within ``[lo, hi]``
    (residual :func:`_zeroing_residual`), or NaN (no convergence in 12 steps, a flat or non-finite residual,
    a step out of the interval): the caller then brackets.

    Converged when a step is below ``xtol + rtol |x|`` (Brent's criterion) and the residual changes sign
    across the last step or vanishes at its end, so the root is that of the residual, not of a flat stretch.
    """
    data = (GA, Gb, d0, cx, cf, cd, offsets, kinds, extraps, scale, unilateral)
    f0 = _zeroing_residual(x0, k, gc, gb, force, u0, q0, *data)
    f1 = _zeroing_residual(x1, k, gc, gb, force, u0, q0, *data)
    for _ in range(12):
        if not (np.isfinite(f0) and np.isfinite(f1)) or f1 == f0:
            return np.nan
        x2 = x1 - f1 * (x1 - x0) / (f1 - f0)
        if not (lo <= x2 <= hi):
            return np.nan
        if abs(x2 - x1) <= xtol + rtol * abs(x2):
            f2 = _zeroing_residual(x2, k, gc, gb, force, u0, q0, *data)
            if f2 == 0.0 or np.sign(f2) != np.sign(f1) or abs(f2) <= abs(f1):
                return x2
            return np.nan
        x0, f0, x1 = x1, f1, x2
        f1 = _zeroing_residual(x2, k, gc, gb, force, u0, q0, *data)
    return np.nan


def modified_parts(nodes: tuple, elements: tuple, *, extra_nodes=(), replace=None, add=(),
                   where: str = "network") -> tuple:
    """The nodes and elements of :meth:`AxialNetwork.modified`, without assembling a network.

    ``extra_nodes`` are appended, elements are replaced (``{name: new}``; ``None`` removes one) and
    ``add`` is appended.  Models 1-4 chain three or four such changes; only the last result is
    assembled (each assembly costs two SVDs and a null space).  ``where`` names the network in errors.
    """
    replace = dict(replace or {})
    known = {e.name for e in elements}
    for key in replace:
        if key not in known:
            raise ParameterError(f"{where}: no element {key!r} (has: {[e.name for e in elements]})")
    out = tuple(replace.get(e.name, e) for e in elements)
    return tuple(nodes) + tuple(extra_nodes), tuple(e for e in out if e is not None) + tuple(add)


def _replace_spring(spring: Spring, **changes) -> Spring:
    import dataclasses

    return dataclasses.replace(spring, **changes)
