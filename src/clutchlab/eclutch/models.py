"""Clutch axial Models 0-4 of Haramina et al. [1] as configurations of one network.

Each model is an :class:`~clutchlab.eclutch.network.AxialNetwork`; Models 1-4
are built from Model 0 by adding or replacing elements exactly as the paper's
Figs. 10-11 add compliances and masses:

========  ===========================================================================
Model 0   bearing stiffness k_b; diaphragm spring k_ds (tip to surroundings); rigid
          lever 1/i_ds to the pressure plate m_pp; return springs k_rs; friction
          plate (cushion) contact k_fp ([1] Sec. 3.2, Fig. 5b)
Model 1   adds the lever (finger) compliance k_fl of Eq. (1) from tests 8b-c ([1] Sec. 5.1)
Model 2   adds the pressure-plate spring k_pp (wear compensation) between the diaphragm
          edge (new mass m_pps) and the pressure plate; k_fl from tests 8a/8c ([1] Sec. 5.2)
Model 3   adds the equivalent yoke support k_ys.eq (support ring and yoke support spring in
          series, extrapolated) carrying the lever pivot (new mass m_ds) ([1] Sec. 5.3)
Model 4   diaphragm spring attached to the yoke support instead of the surroundings;
          k_ys.eq scaled by 20, diaphragm spring by 1.3 ([1] Sec. 5.4)
========  ===========================================================================

Friction is off in the static curves, as in [1] Sections 5-6.  The clutch
torque is ``M_cl = 2 F_n r_eff mu`` ([1] Sec. 3.2: two friction surfaces).

References
----------
.. [1] K. Haramina et al., Trans. FAMENA 48 (2024) 21-35, doi:10.21278/TOF.483057923
"""

from __future__ import annotations

import dataclasses
import difflib
from importlib import resources
from pathlib import Path

import numba
import numpy as np
import pandas as pd

from ..curves import Curve
from ..errors import ParameterError, SimulationError
from ..io import read_table
from ..params import ParameterSet, load_toml, quantity
from ..units import to_si
from .network import GROUND, AxialNetwork, Lever, Node, Spring, modified_parts, solve_static, zero_input

__all__ = ["EClutchParameters", "ComponentCurves", "COMPONENTS", "read_component_curve",
           "ClutchModel", "PresetDerivation", "build_model", "clutch_torque", "torque_of_clamp_force", "MODEL_NUMBERS"]

MODEL_NUMBERS = (0, 1, 2, 3, 4)
#: A measured characteristic may be continued beyond its characterised deflection range by this
#: fraction of the range (the curve ends are noisy and fixtures shift them a little); farther is refused.
EXTRAPOLATION_TOLERANCE = 0.05
_BUNDLED = "bundled synthetic press-rig data, characterised (src/clutchlab/eclutch/data)"
_INSPECT = "inspection of the (virtual) assembled clutch, clutchlab.eclutch.virtual"
_PAPER = "Haramina et al. 2024, Sec. 5.4"
_REP = "representative (docs/eclutch.md)"


def clutch_torque(normal_force, r_eff, mu):
    """Clutch torque ``M_cl = 2 F_n r_eff mu`` [N·m] ([1], Sec. 3.2).

    Parameters
    ----------
    normal_force : array_like
        Normal (clamp) force F_n [N].
    r_eff : float
        Effective friction radius [m].
    mu : float
        Friction coefficient [-], constant as in [1].

    Returns
    -------
    torque : ndarray or float
        Transmissible torque [N·m]; the factor 2 counts the two friction
        surfaces of the single friction plate.

    Notes
    -----
    Vectorised :func:`torque_of_clamp_force`, the one implementation of the
    equation (the dynamics' outputs call it too); arguments broadcast.
    """
    fn, r, m = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (normal_force, r_eff, mu)))
    out = np.empty(fn.size)
    _torque_array(np.ascontiguousarray(fn).ravel(), np.ascontiguousarray(r).ravel(), np.ascontiguousarray(m).ravel(),
                  out)
    return out[0] if fn.shape == () else out.reshape(fn.shape)


@numba.njit(cache=True, nogil=True)
def torque_of_clamp_force(normal_force, r_eff, mu):
    """Transmissible torque of the dry single-plate clutch, ``M_cl = 2 F_n r_eff mu`` [N m] ([1], Sec. 3.2).

    Scalar compiled form: normal (clamp) force F_n [N], effective radius r_eff [m], friction coefficient
    mu [-] (constant, as in [1]); the factor 2 counts the two friction faces of the plate.
    """
    return 2.0 * normal_force * r_eff * mu


@numba.njit(cache=True, nogil=True)
def _torque_array(normal_force, r_eff, mu, out):
    for i in range(out.shape[0]):
        out[i] = torque_of_clamp_force(normal_force[i], r_eff[i], mu[i])


@dataclasses.dataclass(frozen=True)
class EClutchParameters(ParameterSet):
    """Scalar parameters of the E-clutch axial Models 0-4 (SI units).

    Defaults are those of the bundled (synthetic) data set: lever stiffnesses
    identified with Eq. (1) from the bundled press-rig records, pre-strains from
    inspection of the virtual clutch, scale factors from [1] Sec. 5.4, and
    representative values for a passenger-car clutch otherwise.  The pre-strains
    of the compliances Models 1-4 add (the fingers, the pressure-plate spring, the
    yoke support) are no parameters: each is derived from the load its rigid
    connection carries in Model 0's engaged state (:meth:`ClutchModel.preset`,
    docs/eclutch.md Sec. 4).  Until the fortieth session ``pp_spring_prestrain``
    and ``support_prestrain`` were fields that nothing read; a file naming them is
    now refused as naming an unknown field.
    """

    kind = "eclutch"

    lever_ratio: float = quantity(-4.0, "1", "diaphragm lever ratio i_ds (< 0)", source=_INSPECT, bounds=(-50.0, -0.05))
    k_fl_model1: float = quantity(1.176e6, "N/m", "lever stiffness k_fl of Model 1 (Eq. 1, tests 8b-c)", source=_BUNDLED, positive=True)
    k_fl_model2: float = quantity(1.17581e6, "N/m", "lever stiffness k_fl of Models 2-4 (Eq. 1, tests 8a/8c)", source=_BUNDLED, positive=True)
    bearing_stiffness: float = quantity(8.0e6, "N/m", "release bearing stiffness k_b", source=_REP, positive=True)
    bearing_preload: float = quantity(80.0, "N", "CSC preload on the bearing at bearing position 0", source=_REP, nonnegative=True)
    diaphragm_prestrain: float = quantity(4.27457e-3, "m", "diaphragm tip deflection in the assembled clutch", source=_INSPECT)
    cushion_prestrain: float = quantity(0.695635e-3, "m", "cushion spring compression in the engaged clutch", source=_INSPECT)
    return_prestrain: float = quantity(7.94563e-3, "m", "return spring pre-stretch in the engaged clutch", source=_INSPECT)
    support_scale: float = quantity(20.0, "1", "Model 4 stiffness scale of the yoke support k_ys.eq", source=_PAPER, positive=True)
    diaphragm_scale: float = quantity(1.3, "1", "Model 4 stiffness scale of the diaphragm spring", source=_PAPER, positive=True)
    support_max_force: float = quantity(12e3, "N", "force up to which k_ys.eq is extrapolated", source=_REP, positive=True)
    r_eff: float = quantity(0.1026, "m", "effective friction radius", source=_REP, positive=True)
    mu: float = quantity(0.27, "1", "friction coefficient (constant)", source=_REP, positive=True, bounds=(0.0, 1.5))
    m_pp: float = quantity(3.5, "kg", "pressure plate mass", source=_REP, positive=True)
    m_pps: float = quantity(0.9, "kg", "diaphragm spring mass (Models 2-4)", source=_REP, positive=True)
    m_ds: float = quantity(0.3, "kg", "yoke support mass (Models 3-4)", source=_REP, positive=True)


COMPONENTS = ("diaphragm", "cushion", "return_springs", "pp_spring", "support_ring", "yoke_spring")


def read_component_curve(path, name: str | None = None) -> Curve:
    """Read one component characteristic from a CSV file (columns ``deflection_m`` [m], ``force_N`` [N]).

    The output of ``clutchlab eclutch characterize`` (extra columns are
    ignored); interpolated with PCHIP like the bundled curves.
    """
    path = Path(path)
    frame = read_table(path, ["deflection_m", "force_N"])
    return Curve(frame["deflection_m"].to_numpy(), frame["force_N"].to_numpy(), kind="pchip", name=name or path.stem)


@dataclasses.dataclass(frozen=True)
class ComponentCurves:
    """The measured component characteristics the models are built from ([1] Fig. 9).

    Attributes
    ----------
    diaphragm : Curve
        Diaphragm spring at the tips, leaning on the pressure plate (Fig. 9a).
    cushion : Curve
        Friction plate / cushion spring (Fig. 9d).
    return_springs : Curve
        Return leaf springs (Fig. 9e).
    pp_spring : Curve
        Pressure plate with wear-compensation mechanism (Fig. 9f).
    support_ring : Curve
        Yoke support ring (Fig. 9g, Sec. 4.5).
    yoke_spring : Curve
        Yoke support spring (Fig. 9h, Sec. 4.6).
    """

    diaphragm: Curve
    cushion: Curve
    return_springs: Curve
    pp_spring: Curve
    support_ring: Curve
    yoke_spring: Curve

    def __post_init__(self):
        for name in COMPONENTS:
            if not isinstance(getattr(self, name), Curve):
                raise ParameterError(f"component curve {name!r} must be a clutchlab.Curve")

    def support_equivalent(self, max_force: float) -> Curve:
        """k_ys.eq of Model 3: ring and yoke support spring in series, extrapolated to ``max_force`` [N].

        See :func:`~clutchlab.eclutch.characterize.yoke_support_equivalent` ([1] Sec. 5.3).
        """
        from .characterize import yoke_support_equivalent

        return yoke_support_equivalent(self.support_ring, self.yoke_spring, max_force_N=max_force,
                                       name="yoke support k_ys.eq")

    @classmethod
    def from_folder(cls, folder) -> "ComponentCurves":
        """Read ``<component>.csv`` files (columns ``deflection_m``, ``force_N``) from a folder."""
        folder = Path(folder)
        return cls(**{name: read_component_curve(folder / f"{name}.csv", name) for name in COMPONENTS})

    def replace(self, component: str, curve, *, scale: float = 1.0) -> "ComponentCurves":
        """A copy with one component's characteristic replaced (e.g. by your own press-rig curve).

        Build the model from the result with :meth:`ClutchModel.preset`: every
        model is assembled again around the new curve and its bearing is zeroed
        at ``EClutchParameters.bearing_preload`` (80 N by default), so the
        bearing force at bearing position 0 stays the CSC preload.  Model 4's
        own stiffness factors (``diaphragm_scale``, ``support_scale``) still
        apply on top of ``scale``.

        Parameters
        ----------
        component : str
            One of :data:`COMPONENTS` (``"diaphragm"``, ``"cushion"``,
            ``"return_springs"``, ``"pp_spring"``, ``"support_ring"``,
            ``"yoke_spring"``).
        curve : Curve, str or Path
            The new characteristic: a :class:`~clutchlab.Curve` (e.g. from
            :func:`~clutchlab.eclutch.characterize`) or a CSV file with columns
            ``deflection_m`` [m] and ``force_N`` [N] (the output of
            ``clutchlab eclutch characterize``).  Deflection is measured the way
            the bundled press-rig curves are (docs/pressrig.md).
        scale : float
            Stiffness factor [-] applied to the curve (force at equal
            deflection, :meth:`Curve.scale`); default 1.

        Returns
        -------
        ComponentCurves
            A new set; ``self`` is unchanged.

        Raises
        ------
        ParameterError
            Unknown component, a curve that is neither a Curve nor a file, or a
            scale that is not finite and > 0.
        """
        if component not in COMPONENTS:
            close = difflib.get_close_matches(str(component), COMPONENTS, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ParameterError(f"unknown component {component!r}{hint} (known: {', '.join(COMPONENTS)})")
        if isinstance(curve, (str, Path)):
            curve = read_component_curve(curve, component)
        elif not isinstance(curve, Curve):
            raise ParameterError(f"component {component!r}: expected a clutchlab.Curve or a CSV path, "
                                 f"got {type(curve).__name__}")
        if isinstance(scale, bool) or not isinstance(scale, (int, float, np.floating)) or not (np.isfinite(scale) and scale > 0):
            raise ParameterError(f"component {component!r}: scale = {scale!r} must be finite and > 0")
        if scale != 1.0:
            curve = curve.scale(float(scale))
        return dataclasses.replace(self, **{component: curve})

    @classmethod
    def bundled(cls) -> "ComponentCurves":
        """The characterised curves shipped with clutchlab (synthetic, from the virtual press rig).

        Read once per process (the curves are immutable): every preset and variant shares them."""
        if cls is ComponentCurves and _BUNDLED:
            return _BUNDLED[0]
        with resources.as_file(resources.files("clutchlab.eclutch") / "data" / "curves") as folder:
            out = cls.from_folder(folder)
        if cls is ComponentCurves:
            _BUNDLED.append(out)
        return out


#: the bundled component curves, once read (:meth:`ComponentCurves.bundled`)
_BUNDLED: list = []


def _curves_from_table(spec, path: Path) -> ComponentCurves:
    """Component curves of an ``[eclutch.curves]`` table (see :meth:`ClutchModel.from_toml`)."""
    where = f"{path}: [eclutch.curves]"
    if not isinstance(spec, dict) or not spec:
        raise ParameterError(f"{where} must be a table with 'folder' and/or component entries")
    unknown = sorted(set(spec) - {"folder", *COMPONENTS})
    if unknown:
        close = difflib.get_close_matches(unknown[0], COMPONENTS, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ParameterError(f"{where}: unknown key {unknown[0]!r}{hint} (allowed: folder, {', '.join(COMPONENTS)})")
    if "folder" in spec:
        curves = ComponentCurves.from_folder(path.parent / str(spec["folder"]))
    else:
        curves = ComponentCurves.bundled()
    for name in COMPONENTS:
        if name not in spec:
            continue
        entry = spec[name]
        if isinstance(entry, str):
            entry = {"file": entry}
        if not isinstance(entry, dict) or "file" not in entry or set(entry) - {"file", "scale"}:
            raise ParameterError(f"{where} {name} = {entry!r}: expected a CSV file name or "
                                 "{file = \"curve.csv\", scale = 1.0}")
        scale = to_si(entry.get("scale", 1.0), "1", name=f"[eclutch.curves] {name}.scale", source=str(path))
        try:
            curves = curves.replace(name, path.parent / str(entry["file"]), scale=scale)
        except ParameterError as exc:
            raise ParameterError(f"{where} {name}: {exc}") from None
    return curves


def _model0(p: EClutchParameters, c: ComponentCurves) -> AxialNetwork:
    k_b = Curve.linear(p.bearing_stiffness, span=(0.0, 1e-3), name="bearing k_b")
    nodes = (Node("bearing"), Node("tip"), Node("pp", p.m_pp))
    elements = (
        Spring("bearing", "bearing", k_b, b="tip", unilateral=True),
        Spring("diaphragm", "tip", c.diaphragm, prestrain=p.diaphragm_prestrain),
        Lever("lever", "tip", "pp", p.lever_ratio),
        Spring("return", "pp", c.return_springs, prestrain=p.return_prestrain),
        Spring("cushion", "pp", c.cushion, prestrain=p.cushion_prestrain, unilateral=True),
    )
    return AxialNetwork(nodes, elements, input="bearing", normal_force="cushion", name="Model 0")


def _engaged_loads(p: EClutchParameters, c: ComponentCurves) -> dict[str, float]:
    """Forces in the rigid connections of Model 0 at bearing position 0 (engaged, bearing at preload).

    The compliances that Models 1-3 add where Model 0 is rigid are assembled
    carrying these loads, so every model starts from the same engaged state
    (same clamp load, same bearing preload) and differs only in its slopes.
    """
    net = zero_input(_model0(p, c), "bearing", p.bearing_preload)
    st = solve_static(net, np.array([0.0]))
    f = dict(zip(st["element_names"], st["forces"][0]))
    lever = f["bearing"] - f["diaphragm"]  # tip balance: force the fingers carry (N, < 0: pulled back)
    return {"lever": lever, "pp_spring": f["cushion"] + f["return"], "support": -(1.0 - p.lever_ratio) * lever,
            "net": net}


def _model1(p, c, loads):
    # + lever compliance k_fl (Eq. 1): the tip becomes a free, massless node
    net = loads["net"]
    return _parts(net.nodes, net.elements, "Model 1",
                  replace={"lever": Lever("lever", "tip", "pp", p.lever_ratio, stiffness=p.k_fl_model1,
                                          prestrain=loads["lever"] / p.k_fl_model1)})


def _model2(p, c, loads):
    # + pressure-plate spring k_pp between the diaphragm edge (mass m_pps) and the pressure plate
    nodes, elements, _ = _model1(p, c, loads)
    return _parts(nodes, elements, "Model 2", extra_nodes=(Node("edge", p.m_pps),),
                  replace={"lever": Lever("lever", "tip", "edge", p.lever_ratio, stiffness=p.k_fl_model2,
                                          prestrain=loads["lever"] / p.k_fl_model2)},
                  add=(Spring("pp_spring", "edge", c.pp_spring, b="pp", unilateral=True,
                              prestrain=float(c.pp_spring.inverse(loads["pp_spring"]))),))


def _model3(p, c, loads, support_scale=1.0):
    # + equivalent yoke support k_ys.eq carrying the lever pivot (mass m_ds)
    k_ys = c.support_equivalent(p.support_max_force)
    nodes, elements, _ = _model2(p, c, loads)
    return _parts(nodes, elements, "Model 3", extra_nodes=(Node("support", p.m_ds),),
                  replace={"lever": Lever("lever", "tip", "edge", p.lever_ratio, pivot="support",
                                          stiffness=p.k_fl_model2, prestrain=loads["lever"] / p.k_fl_model2)},
                  add=(Spring("support", GROUND, k_ys, b="support", scale=support_scale,
                              prestrain=float(k_ys.inverse(loads["support"] / support_scale))),))


def _model4(p, c, loads):
    # diaphragm spring towards the yoke support; k_ys.eq x20, diaphragm x1.3 (Sec. 5.4)
    nodes, elements, _ = _model3(p, c, loads, support_scale=p.support_scale)
    return _parts(nodes, elements, "Model 4",
                  replace={"diaphragm": Spring("diaphragm", "tip", c.diaphragm, b="support",
                                               prestrain=p.diaphragm_prestrain, scale=p.diaphragm_scale)})


def _parts(nodes, elements, name, **changes):
    """(nodes, elements, name) of a model derived from another's; Models 1-4 chain these and only the
    last is assembled into a network (:func:`.network.modified_parts`)."""
    return (*modified_parts(nodes, elements, where=name, **changes), name)


_BUILDERS = {1: _model1, 2: _model2, 3: _model3, 4: _model4}


def build_model(number: int, params: EClutchParameters | None = None, curves: ComponentCurves | None = None) -> AxialNetwork:
    """The axial network of Model ``number`` (0-4), with the bearing zeroed at the CSC preload.

    Parameters
    ----------
    number : int
        Model number of [1] (0, 1, 2, 3 or 4).
    params : EClutchParameters, optional
        Scalars (default: the bundled defaults).
    curves : ComponentCurves, optional
        Component characteristics (default: the bundled synthetic ones).
    """
    if isinstance(number, bool) or not isinstance(number, (int, np.integer)) or int(number) not in MODEL_NUMBERS:
        raise ParameterError(f"unknown model number {number!r}; Haramina et al. define Models 0, 1, 2, 3 and 4")
    params = params or EClutchParameters()
    curves = curves or ComponentCurves.bundled()
    loads = _engaged_loads(params, curves)
    if int(number) == 0:
        return loads["net"]
    nodes, elements, name = _BUILDERS[int(number)](params, curves, loads)
    net = AxialNetwork(nodes, elements, input="bearing", normal_force="cushion", name=name)
    if int(number) == 4:  # the scaled diaphragm changes the engaged state: zero the bearing again
        net = zero_input(net, "bearing", params.bearing_preload)
    return net


@dataclasses.dataclass(frozen=True)
class PresetDerivation:
    """What Model ``number`` derives from its parameters, for the compiled start to derive it again.

    :func:`build_model` zeroes Model 0's bearing at ``bearing_preload``, solves Model 0's engaged state at bearing
    position 0 and gives each compliance Models 1-4 add the pre-strain at which it carries its share of that state
    (the lever ``F_lever / k_fl``; the pressure-plate spring and the yoke support by their curves' inverses), then
    zeroes Model 4's bearing again.  :func:`clutchlab.eclutch.system.derive_clutch` repeats that chain, compiled,
    from copies of these numbers and Model 0's assembly, so a native FMU derives the network a host's pre-strains,
    lever ratio, stiffnesses and preload give (docs/fmu.md).

    Attributes
    ----------
    number : int
        Model number (0-4).
    model0 : AxialNetwork
        Model 0 before its bearing is zeroed (the engaged state's network).
    network : AxialNetwork
        The network the derivation belongs to (a model built around another network derives nothing).
    bearing_preload : float
        Bearing force at bearing position 0 [N].
    lever_ratio : float
        ``i_ds`` [-].
    k_fl : float
        Lever stiffness of the model (Model 1: ``k_fl_model1``, Models 2-4: ``k_fl_model2``) [N/m].
    support_scale : float
        Scale of the yoke support the support's pre-strain is found with (Model 3: 1, Model 4:
        ``support_scale``) [-].
    """

    number: int
    model0: AxialNetwork
    network: AxialNetwork
    bearing_preload: float
    lever_ratio: float
    k_fl: float
    support_scale: float

    @classmethod
    def of(cls, number: int, p: EClutchParameters, curves: ComponentCurves,
           network: AxialNetwork) -> "PresetDerivation":
        """The derivation of Model ``number`` built with ``p`` and ``curves`` as ``network``."""
        return cls(int(number), _model0(p, curves), network, float(p.bearing_preload), float(p.lever_ratio),
                   float(p.k_fl_model1 if number == 1 else p.k_fl_model2),
                   float(p.support_scale if number == 4 else 1.0))


@dataclasses.dataclass(frozen=True)
class ClutchModel:
    """An E-clutch axial model: network plus torque parameters.

    Use :meth:`preset` for the paper's Models 0-4 or build a variant from an
    :class:`AxialNetwork` of your own.

    Parameters
    ----------
    network : AxialNetwork
        Nodes and elements, with input node (bearing) and normal-force element.
    r_eff : float
        Effective friction radius [m].
    mu : float
        Friction coefficient [-].
    number : int or None
        Model number of [1] for presets.
    derivation : PresetDerivation or None
        How a preset derived its network from its parameters (set by :meth:`preset`; a co-simulation's start
        derives it again, so a native FMU takes a host's pre-strains and preloads); None for a network of your own,
        and ignored unless ``network`` is the one it was derived for.
    """

    network: AxialNetwork
    r_eff: float = 0.1026
    mu: float = 0.27
    number: int | None = None
    #: how a preset derives its network from its parameters (:class:`PresetDerivation`): the compiled start of
    #: the dynamics derives it again (:func:`clutchlab.eclutch.system.derive_clutch`); None for a network of
    #: your own
    derivation: "PresetDerivation | None" = dataclasses.field(default=None, compare=False, repr=False)

    def __post_init__(self):
        if not isinstance(self.network, AxialNetwork):
            raise ParameterError("ClutchModel.network must be an AxialNetwork")
        for name in ("r_eff", "mu"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ParameterError(f"ClutchModel.{name} = {v!r} must be finite and > 0")

    @classmethod
    def preset(cls, n: int, params: EClutchParameters | None = None, curves: ComponentCurves | None = None) -> "ClutchModel":
        """Model ``n`` (0-4) of [1] with the bundled default parameters (or the given ones)."""
        params = params or EClutchParameters()
        network = build_model(n, params, curves)
        return cls(network, r_eff=params.r_eff, mu=params.mu, number=int(n),
                   derivation=PresetDerivation.of(int(n), params, curves or ComponentCurves.bundled(), network))

    @classmethod
    def from_toml(cls, n: int, path) -> "ClutchModel":
        """Model ``n`` with parameters from a TOML file.

        The file has an ``[eclutch]`` table of :class:`EClutchParameters`
        (values may carry units, e.g. ``lever_ratio = -3.8``,
        ``k_fl_model1 = "1.2 MN/m"``) and optionally an ``[eclutch.curves]``
        table of component curves, paths relative to the parameter file:
        ``folder = "curves/"`` (a folder with all six ``<component>.csv``
        files) and/or one entry per component to replace, a CSV file
        (``diaphragm = "my_diaphragm.csv"``) or a table with a stiffness
        factor (``diaphragm = {file = "my_diaphragm.csv", scale = 1.3}``),
        see :meth:`ComponentCurves.replace`.  The bearing is zeroed at
        ``bearing_preload`` with the new curves.
        """
        data = load_toml(path)
        table = dict(data.get("eclutch", data))
        curves = None
        if "curves" in table:
            curves = _curves_from_table(table.pop("curves"), Path(path))
        params = EClutchParameters.from_dict(table, source=str(path))
        return cls.preset(n, params, curves)

    @property
    def name(self) -> str:
        """Display name."""
        return self.network.name

    def static_curve(self, bearing_position_m, *, extrapolate: bool = False) -> pd.DataFrame:
        """Static curves (friction off): bearing force, normal force and torque vs bearing position.

        Solves the static equilibrium directly by Newton continuation along
        the given bearing positions (see :func:`~clutchlab.eclutch.network.solve_static`).

        Parameters
        ----------
        bearing_position_m : array_like
            Release bearing positions [m], from the engaged clutch (0) in the
            release direction.
        extrapolate : bool
            Accept equilibria in which a measured characteristic (a curve of
            more than two samples) is deflected beyond its characterised range
            by more than :data:`EXTRAPOLATION_TOLERANCE` of the range (its
            linear continuation is then an assumption, not a measurement).
            Default ``False``: such positions raise.  Straight-line
            characteristics, the lever and a unilateral contact that has
            opened are never extrapolations.

        Returns
        -------
        pandas.DataFrame
            Columns ``bearing_position_m``, ``bearing_force_N``,
            ``normal_force_N``, ``torque_Nm`` and the node positions
            ``x_<node>_m``.
        """
        st = solve_static(self.network, bearing_position_m)
        if not extrapolate:
            self._refuse_extrapolation(st)
        fn = st["forces"][:, st["element_names"].index(self.network.normal_force)]
        out = pd.DataFrame({
            "bearing_position_m": st["input"],
            "bearing_force_N": st["input_force"],
            "normal_force_N": fn,
            "torque_Nm": clutch_torque(fn, self.r_eff, self.mu),
        })
        for j, node in enumerate(st["node_names"]):
            if node != self.network.input:
                out[f"x_{node}_m"] = st["node_positions"][:, j]
        return out

    def _refuse_extrapolation(self, st: dict) -> None:
        """Raise if an equilibrium deflects a measured characteristic beyond its characterised range."""
        elements = {e.name: e for e in self.network.elements}
        for j, name in enumerate(st["element_names"]):
            e = elements[name]
            if isinstance(e, Lever) or e.curve.deflection.size <= 2:
                continue  # linear by construction: valid at any deflection
            x = e.curve.deflection
            lo, hi = float(x[0]), float(x[-1])
            tol = EXTRAPOLATION_TOLERANCE * (hi - lo)
            d = st["deflections"][:, j]
            beyond = (d > hi + tol) | (d < lo - tol)
            if e.unilateral:
                beyond &= st["forces"][:, j] > 0.0  # an open contact carries nothing
            if beyond.any():
                i = int(np.flatnonzero(beyond)[0])
                raise SimulationError(
                    f"{self.name}: bearing position {st['input'][i] * 1e3:.4g} mm deflects the {name!r} spring "
                    f"by {d[i] * 1e3:.4g} mm, outside its characterised range {lo * 1e3:.4g}..{hi * 1e3:.4g} mm "
                    f"(curve {e.curve.name!r}): the result would be an extrapolation; shorten the travel "
                    "(or pass extrapolate=True; clutchlab eclutch static: --extrapolate)")
