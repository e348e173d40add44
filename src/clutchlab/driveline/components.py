"""The network's own component kinds, declared once (:mod:`clutchlab.component`).

Each declaration gives a component's table name in a network file, its fields (ports and parameters with
their unit, default, physical range, description and source) and the function that adds it to a
:class:`~clutchlab.driveline.Driveline`.  The file format (:mod:`clutchlab.driveline.description`), the
parameters of sweeps and FMUs (:mod:`clutchlab.driveline.variants`), ``clutchlab driveline components``
and docs/components.md are generated from these declarations; a component of a package of its own is
declared the same way and registered with :func:`clutchlab.component.register_component` or the
entry-point group ``clutchlab.components`` (docs/architecture.md, "Adding a component").

The ranges are physical, not the ranges of the examples: an inertia, a stiffness or a normal force has no
upper limit here (the parameter sets of the models have theirs, :mod:`clutchlab.params`); a friction
coefficient lies in [0, 2] (dry and wet clutch linings 0.05-0.6, rubber on dry asphalt up to about 1.2), an
efficiency in (0, 1], a static-to-sliding ratio ``peak`` at least 1 (MSL ``peak >= 1``).  The defaults are
those of the :class:`~clutchlab.driveline.Driveline` methods (a test compares them).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..component import Component, Field, register_component
from ..errors import ParameterError
from ..params.base import ABSOLUTE_ZERO_C, FRICTION_COEFFICIENT_MAX, MU_SCALE_MAX, WET_TEMPERATURES_C

__all__ = ["BUILTIN"]

_MSL = "Modelica.Mechanics.Rotational"


def _flange(name, description, required=True):
    return Field(name, "flange", required=required, description=description)


_A = _flange("a", "flange a: the body (an inertia, or \"ground\") on its driving side")
_B = _flange("b", "flange b: the body on its driven side")
_FLANGE = _flange("flange", "the body it acts on")
_SUPPORT = _flange("support", "the body its reaction acts on (default the ground)", required=False)


_MU_TEMPERATURE = Field(
    "mu_temperature", "temperature_table", "1", minimum=0.0,
    description="factor on the friction over the temperature of the thermal mass its losses heat: rows "
                "[T_degC, factor], linear, held beyond them (fade); the element must be in that mass's heat_from",
    source="fade of dry linings; MSL's heat port temperature")


def _friction_fields(fn_required=True, fn_default=None, with_map=True):
    fields = [
        Field("fn_max", "quantity", "N", required=fn_required, default=fn_default, minimum=0.0,
              description="largest normal force; the normal force is fn_max * normal(t)"),
        Field("mu", "characteristic", "1", default=0.5, minimum=0.0, maximum=FRICTION_COEFFICIENT_MAX,
              description="sliding friction coefficient: a number or rows [w_rad_s, mu] over |w_rel|",
              source="physical range: linings and tyres stay below 2"),
        Field("mu_scale", "quantity", "1", default=1.0, minimum=0.0, maximum=MU_SCALE_MAX,
              description="factor on the friction coefficient (a number, a table or a map): a sweep's friction "
                          "level (the scaled coefficient may pass mu's own range by it)"),
        Field("peak", "quantity", "1", default=1.0, minimum=1.0,
              description="static limit over the sliding torque at rest", source=f"{_MSL}.Components.Clutch"),
        Field("cgeo", "quantity", "1", default=1.0, positive=True,
              description="geometry constant: torque = cgeo * fn * mu (MSL's unitless Real; physically an "
                          "effective radius times the number of friction surfaces)"),
        Field("normal", "signal", "1", default=1.0,
              description="normal-force signal, 0-1 (free where <= 0)"),
        _MU_TEMPERATURE,
    ]
    if with_map:
        fields += [
            Field("mu_map", "path", description="a friction map .json of clutchlab wet identify (instead of mu)"),
            Field("radius", "quantity", "m", positive=True,
                  description="radius at which a friction map is read (slip velocity = radius |w_rel|)"),
            Field("temperature", "quantity", "degC", minimum=ABSOLUTE_ZERO_C,
                  description="friction-surface temperature a friction map is read at (left out: its heat port's, "
                              "as the run heats it)"),
        ]
    return tuple(fields)


def _mu_of(args):
    if "mu_map" in args:
        from ..wet.friction import FrictionMap

        if "mu" in args:
            raise ParameterError("give mu or mu_map, not both")
        args["mu"] = FrictionMap.from_json(args.pop("mu_map"))
    return args


def _inertia(net, name, **args):
    if net.domain == "translational":
        net.mass(name, args.pop("J"), v0=args.pop("w0", None), s0=args.pop("phi0", None))
    else:
        net.inertia(name, **args)


def _source(kind):
    def build(net, name, **args):
        flange = args.pop("flange")
        signal = args.pop(kind)
        if kind == "torque" and net.domain == "translational":
            net.force(name, flange, signal, **args)
        else:
            getattr(net, kind)(name, flange, signal, **args)
    return build


def _spring(net, name, **args):
    from ..curves import Curve

    rows = args.pop("curve")
    if len(rows) < 2:
        raise ParameterError(f"curve needs at least 2 rows, got {len(rows)}")
    args["curve"] = Curve([r[0] for r in rows], [r[1] for r in rows], kind=args.pop("interpolation", "linear"),
                          name=name)
    net.spring(name, **args)


@dataclass(frozen=True)
class ParameterSetSource:
    """A parameter set a component's path field names (:func:`parameter_sets`).

    Attributes
    ----------
    field : str
        The component's path field (``"clutch"``, ``"bench"``).
    name : str
        The set's name in the parameters' names (``<component>.<name>.<set field>``).
    cls : type
        Its :class:`~clutchlab.params.ParameterSet` class.
    read : callable
        ``read(path)``: the set in the file the field names.
    default : callable
        ``default()``: the set the component takes when the field is left out.
    unread : tuple of str
        The set's fields the component does not read (not parameters of the network).
    """

    field: str
    name: str
    cls: type
    read: Callable
    default: Callable
    unread: tuple = ()


def parameter_sets(kind: str) -> tuple:
    """The parameter sets the path fields of a component of type ``kind`` name, whose numeric fields are parameters
    of the network (``<component>.<set>.<field>``: a sweep's and a native FMU's, as its own fields are), as
    :class:`ParameterSetSource`.  A wet clutch's ``clutch`` (:class:`~clutchlab.wet.params.WetClutch`, default the
    paper's) and ``bench`` (:class:`~clutchlab.wet.params.Bench`: its actuator, oil loop and housing; not its drive,
    which the network is, nor the virtual rig's sensors); an EMTC coupling's ``actuator``
    (:class:`~clutchlab.emtc.bench.ActuatorParameters`) and ``coupling``
    (:class:`~clutchlab.emtc.torque.CouplingGeometry`), the tables of the scenario file its ``bench`` names (its
    scenario and vehicle are the bench's: the network is the vehicle)."""
    if kind == "wet_clutch":
        from ..wet.params import BENCH_DRIVE, BENCH_SENSORS, Bench, WetClutch

        return (ParameterSetSource("clutch", "clutch", WetClutch, WetClutch.from_toml, WetClutch.paper),
                ParameterSetSource("bench", "bench", Bench, Bench.from_toml, Bench, BENCH_DRIVE + BENCH_SENSORS))
    if kind == "emtc":
        from ..emtc.bench import ActuatorParameters, load_scenario
        from ..emtc.torque import CouplingGeometry

        return (ParameterSetSource("bench", "actuator", ActuatorParameters, lambda p: load_scenario(p)["actuator"],
                                   ActuatorParameters),
                ParameterSetSource("bench", "coupling", CouplingGeometry, lambda p: load_scenario(p)["coupling"],
                                   CouplingGeometry))
    return ()


def set_with(cls, base, changes: dict, where: str):
    """``base`` (a :class:`~clutchlab.params.ParameterSet` of class ``cls``) with some numeric fields changed (SI;
    a whole-number field takes a whole number only), validated again; errors name ``where``."""
    values = {}
    for field, value in changes.items():
        if isinstance(getattr(base, field), int):
            if float(value) != round(float(value)):
                raise ParameterError(f"{where}.{field} = {value!r}: must be a whole number")
            value = int(round(float(value)))
        values[field] = value
    try:
        return base.replace(**values)
    except ParameterError as exc:
        raise ParameterError(f"{where}: {exc}") from None


def _wet_clutch(net, name, **args):
    from ..wet.friction import FrictionMap, ParametricFriction

    changes = args.pop("set_changes", None) or {}
    for src in parameter_sets("wet_clutch"):
        if src.field in args or src.name in changes:
            value = src.read(args[src.field]) if src.field in args else src.default()
            args[src.field] = (set_with(src.cls, value, changes[src.name], f"{name}.{src.name}")
                               if src.name in changes else value)
    if "friction" in args:
        path = args["friction"]
        args["friction"] = (FrictionMap.from_json(path) if path.suffix.lower() == ".json"
                            else ParametricFriction.from_toml(path))
    net.wet_clutch(name, **args)


def _emtc(net, name, **args):
    from ..hysteresis import Preisach

    changes = args.pop("set_changes", None) or {}
    if "bench" in args or changes:
        from ..emtc.bench import load_scenario
        from ..emtc.system import BenchOptions

        sets = {src.name: src for src in parameter_sets("emtc")}
        if "bench" in args:
            path = args.pop("bench")
            bench = load_scenario(path)
            if bench["magnet"] is not None:
                raise ParameterError(f"bench = {path.name!r} names a magnet in its [magnet] table: give the model "
                                     "as this component's magnet field instead")
            args.update(scenario=bench["scenario"], vehicle=bench["vehicle"])
        else:
            bench = {n: src.default() for n, src in sets.items()}
        for n, src in sets.items():
            if n in changes:
                bench[n] = set_with(src.cls, bench[n], changes[n], f"{name}.{n}")
        args["options"] = BenchOptions(actuator=bench["actuator"], coupling=bench["coupling"])
    if "magnet" in args:
        args["magnet"] = Preisach.from_json(args["magnet"])
    net.emtc(name, **args)


def _method(kind):
    def build(net, name, **args):
        getattr(net, kind)(name, **args)
    build.__name__ = f"_{kind}"
    return build


def _clutch_like(kind):
    def build(net, name, **args):
        getattr(net, kind)(name, **_mu_of(args))
    return build


_BOTH = ("rotational", "translational")

#: the built-in component kinds, in the order of the docs
BUILTIN = (
    Component("inertia", "A rigid inertia (a mass in a translational network).", (
        Field("J", "quantity", "kg*m**2", required=True, positive=True, description="moment of inertia"),
        Field("w0", "quantity", "rad/s", default=0.0,
              description="initial speed; left out it follows from the gears and motion sources that bind this "
                          "body to another (0 without any)"),
        Field("phi0", "quantity", "rad", default=0.0,
              description="initial angle; left out it follows from a position source (0 without one)"),
    ), _inertia, f"{_MSL}.Components.Inertia", _BOTH, ("mass", {"J": "m", "w0": "v0", "phi0": "s0"})),
    Component("spring_damper", "A linear spring and a damper in parallel: tau = c (phi_rel - phi_rel0) + d w_rel.", (
        _A, _B,
        Field("c", "quantity", "N*m/rad", default=0.0, minimum=0.0, description="stiffness"),
        Field("d", "quantity", "N*m*s/rad", default=0.0, minimum=0.0, description="damping"),
        Field("phi_rel0", "quantity", "rad", default=0.0, description="unstretched relative angle"),
    ), _method("spring_damper"), f"{_MSL}.Components.SpringDamper", _BOTH),
    Component("spring", "A nonlinear spring (a curve of the relative angle) and a damper in parallel.", (
        _A, _B,
        Field("curve", "curve", "N*m", required=True, description="rows [phi_rel, tau] of the spring"),
        Field("interpolation", "choice", default="linear", choices=("linear", "pchip"),
              description="between the rows: piecewise linear or monotone cubic"),
        Field("d", "quantity", "N*m*s/rad", default=0.0, minimum=0.0, description="damping"),
        Field("phi_rel0", "quantity", "rad", default=0.0, description="unstretched relative angle"),
    ), _spring, "clutchlab.curves.Curve, energy as its exact integral", _BOTH),
    Component("backlash", "A spring-damper behind a gap (MSL ElastoBacklash).", (
        _A, _B,
        Field("c", "quantity", "N*m/rad", required=True, positive=True, description="contact stiffness"),
        Field("b_gap", "quantity", "rad", required=True, positive=True, description="total backlash"),
        Field("d", "quantity", "N*m*s/rad", default=0.0, minimum=0.0, description="contact damping"),
        Field("phi_rel0", "quantity", "rad", default=0.0, description="relative angle of the gap's centre"),
        Field("damping_law", "choice", default="kelvin_voigt", choices=("kelvin_voigt", "msl"),
              description="kelvin_voigt: damping with contact; msl: ElastoBacklash's limited damping"),
    ), _method("backlash"), f"{_MSL}.Components.ElastoBacklash", _BOTH),
    Component("gear", "A gear on a support: ideal, or lossy with MSL LossyGear's efficiencies and bearing friction.", (
        _A, _B,
        Field("ratio", "quantity", "1", required=True, description="w_a / w_b (not 0)"),
        Field("efficiency", "quantity", "1", default=1.0, positive=True, maximum=1.0,
              description="mesh efficiency in both directions (instead of loss_table)"),
        Field("loss_table", "losstable", description="MSL lossTable rows [|w_a|, eta_mf1, eta_mf2, tau_bf1, tau_bf2]"),
        _SUPPORT,
    ), _method("gear"), f"{_MSL}.Components.IdealGear, LossyGear", _BOTH),
    Component("planetary", "A planetary gear set: (1 + ratio) w_carrier = w_sun + ratio w_ring, tau_ring = ratio "
                           "tau_sun; a gear in the carrier's frame, ideal or lossy.", (
        _flange("sun", "the sun's body (\"ground\": held)"),
        _flange("carrier", "the carrier's body (\"ground\": held)"),
        _flange("ring", "the ring's body (\"ground\": held)"),
        Field("ratio", "quantity", "1", required=True, minimum=1.0,
              description="ring teeth over sun teeth (> 1)"),
        Field("efficiency", "quantity", "1", default=1.0, positive=True, maximum=1.0,
              description="the stationary train's mesh efficiency, in the carrier's frame (instead of loss_table)"),
        Field("loss_table", "losstable",
              description="MSL lossTable rows [|w_sun - w_carrier|, eta_mf1, eta_mf2, tau_bf1, tau_bf2]"),
    ), _method("planetary"), f"{_MSL}.Components.IdealPlanetary; LossyGear in the carrier's frame (Pelchen, Otter, "
                             "Schweiger 2002)", ("rotational",)),
    Component("torque_converter", "A hydrodynamic torque converter: impeller torque w_p |w_p| / K(SR)^2, turbine "
                                  "torque TR(SR) times it, the stator's reaction on a support.", (
        _flange("a", "the impeller's body (the engine's side)"),
        _flange("b", "the turbine's body (the gearbox's side)"),
        Field("table", "rows", "1 | rad/s/(N*m)**0.5 | 1", required=True,
              description="rows [SR, K, TR]: speed ratio w_t/w_p in [0, 1), increasing; capacity factor K = "
                          "w_p/sqrt(T_p) (\"150 rpm/(N m)^0.5\"); torque ratio T_t/T_p, TR SR <= 1"),
        Field("coast_table", "rows", "1 | rad/s/(N*m)**0.5",
              description="rows [w_p/w_t, K] while the turbine drives (TR = 1); default the drive table's K"),
        _flange("support", "the housing's body the stator's reaction acts on (default the ground)", required=False),
        Field("k_scale", "quantity", "1", default=1.0, positive=True,
              description="factor on both tables' K: a looser (> 1) or tighter converter, matched to the engine (a "
                          "sweep's or an FMU host's parameter; the torques scale with 1/k_scale^2)"),
    ), _method("torque_converter"), "SAE J643 (K, TR over SR); continuous coast and reversal: "
                                    "clutchlab.driveline.kernel.converter_torques", ("rotational",)),
    Component("torque", "A torque source (a force source in a translational network).", (
        _FLANGE,
        Field("torque", "signal", "N*m", required=True, description="torque on the flange"),
        _SUPPORT,
    ), _source("torque"), f"{_MSL}.Sources.Torque", _BOTH, ("force", {"torque": "force"})),
    Component("speed_torque", "A torque that depends on the flange's speed: tau_nominal |w/w_nominal|^k (k 1 or 2), "
                              "in one direction both ways round or turning with the speed.", (
        _FLANGE,
        Field("tau_nominal", "quantity", "N*m", required=True,
              description="accelerating torque at the nominal speed (negative: a load in positive rotation)"),
        Field("w_nominal", "quantity", "rad/s", required=True, positive=True, description="nominal speed"),
        Field("law", "choice", default="quadratic", choices=("linear", "quadratic"),
              description="the speed's exponent: 1 or 2"),
        Field("torque_direction", "bool", default=True,
              description="the same direction of torque in both directions of rotation (MSL's TorqueDirection)"),
        _SUPPORT,
    ), _method("speed_torque"), f"{_MSL}.Sources.LinearSpeedDependentTorque, QuadraticSpeedDependentTorque",
        ("rotational",)),
    Component("speed", "A speed source: the flange follows the signal, whatever torque it takes.", (
        _FLANGE,
        Field("speed", "signal", "rad/s", required=True, description="speed of the flange (continuous)"),
    ), _source("speed"), f"{_MSL}.Sources.Speed (exact = true)", _BOTH),
    Component("position", "A position source: the flange follows the signal.", (
        _FLANGE,
        Field("position", "signal", "rad", required=True,
              description="angle of the flange (a constant or a sine starting at 0)"),
    ), _source("position"), f"{_MSL}.Sources.Position (exact = true)", _BOTH),
    Component("clutch", "A clutch between two flanges: sliding torque cgeo fn mu(|w_rel|), static limit peak times "
                        "that at rest.", (_A, _B, *_friction_fields()),
              _clutch_like("clutch"), f"{_MSL}.Components.Clutch", _BOTH),
    Component("brake", "A brake between a flange and its support (the ground by default).", (
        _FLANGE, *_friction_fields(), _SUPPORT,
    ), _clutch_like("brake"), f"{_MSL}.Components.Brake", _BOTH),
    Component("synchronizer", "A gear's synchroniser: a cone clutch that pulls the speeds together while the shift "
                              "force pushes the sleeve, then dogs that hold the gear in.", (
        _flange("a", "the shaft the sleeve's hub turns with"),
        _flange("b", "the gear's idler (the body its gear pair turns)"),
        Field("force", "signal", "N", required=True,
              description="shift force on the sleeve: of side's sign it pushes the sleeve towards the gear (held "
                          "in while it lasts); zero or the other sign takes it out (neutral)"),
        Field("cone_radius", "quantity", "m", required=True, positive=True, description="mean radius of the cone"),
        Field("dog_capacity", "quantity", "N*m", required=True, positive=True,
              description="the most torque the engaged dogs hold"),
        Field("mu", "characteristic", "1", default=0.1, minimum=0.0, maximum=FRICTION_COEFFICIENT_MAX,
              description="cone friction coefficient (0.08-0.12 in oil), below tan(cone_angle): a number or rows "
                          "[w_rad_s, mu]"),
        Field("cone_angle", "quantity", "rad", default=0.11344640137963143, positive=True, maximum=0.7853981633974483,
              description="half angle of the cone (\"6.5 deg\")"),
        Field("cones", "int", default=1, minimum=1, maximum=3, description="cone surfaces: 1, 2 or 3"),
        Field("side", "choice", default="positive", choices=("positive", "negative"),
              description="which sign of force pushes the sleeve towards this gear (a 1-2 sleeve: two "
                          "synchronisers on one fork's force, one each side)"),
    ), _method("synchronizer"), "a cone clutch (normal force F / sin(alpha) on n cones: torque n mu F R_c / "
                                "sin(alpha)) and a dog clutch: clutchlab.driveline.kernel.static_limit",
        ("rotational",)),
    Component("bearing_friction", "Bearing friction against a support; never free.", (
        _FLANGE,
        Field("torque", "characteristic", "N*m", default=1.0, minimum=0.0,
              description="sliding torque: a number or rows [w_rad_s, tau] over |w_rel|"),
        Field("peak", "quantity", "1", default=1.0, minimum=1.0, description="static limit over the sliding torque "
                                                                               "at rest"),
        _SUPPORT,
    ), _method("bearing_friction"), f"{_MSL}.Components.BearingFriction", _BOTH),
    Component("one_way_clutch", "A freewheel in parallel with a clutch: flange b may overrun flange a.", (
        _A, _B, *_friction_fields(fn_required=False, fn_default=0.0, with_map=False),
    ), _method("one_way_clutch"), f"{_MSL}.Components.OneWayClutch", _BOTH),
    Component("eclutch", "The dry E-clutch of seed 000: torque 2 F_n r_eff mu, F_n from its axial Model 0-4 at the "
                         "release-bearing position, or from its actuator.", (
        _A, _B,
        Field("position", "signal", "m", required=True,
              description="release-bearing position (0 engaged); with actuator = true its actuator's reference"),
        Field("model", "int", default=4, minimum=0, maximum=4, description="axial model 0-4"),
        Field("parameters", "path", description="an E-clutch parameter file (default the paper's)"),
        Field("travel", "quantity", "m", default=8e-3, positive=True,
              description="bearing travel over which the static curve is solved"),
        Field("points", "int", default=161, minimum=2, description="positions the static curve is solved at"),
        Field("peak", "quantity", "1", default=1.0, minimum=1.0, description="static limit over the sliding torque"),
        Field("actuator", "bool", default=False,
              description="drive the clutch through its hydrostatic actuator and position controller"),
        Field("actuator_step", "quantity", "s", default=1e-3, positive=True,
              description="sample interval of the actuator's normal-force profile"),
        Field("pre_roll", "quantity", "s", default=1.0, minimum=0.0,
              description="actuator run before t = 0 (settles its controller)"),
        Field("settle", "quantity", "s", default=0.5, minimum=0.0, description="actuator run after the reference ends"),
        Field("actuator_in_network", "bool",
              description="integrate the actuator with the network (its reference read at every evaluation: a "
                          "network input may drive it) instead of solving it ahead; left out: where position reads "
                          "an input"),
        _MU_TEMPERATURE,
        Field("wear", "quantity", "m", default=0.0, minimum=0.0, maximum=0.01,
              description="facing wear at the start (both faces): the cushion pre-strain less it",
              source="seed 000, Sec. 7, future work iii"),
        Field("wear_rate", "quantity", "m/J", default=0.0, minimum=0.0, maximum=1e-6,
              description="facing wear per joule the clutch dissipates (wear proportional to friction work)",
              source="Archard's wear law at a constant friction coefficient"),
        Field("wear_max", "quantity", "m", default=1e-3, positive=True, maximum=0.01,
              description="the most wear its shifted curves cover (a run beyond it ends with an error)"),
        Field("expansion", "quantity", "m/K", default=0.0, minimum=0.0, maximum=1e-5,
              description="thermal growth of the pressure-plate and flywheel stack per kelvin of its heat port's "
                          "mass (alpha h: 3.6e-7 for cast iron over 30 mm)",
              source="seed 000, Sec. 7, future work iii"),
        Field("reference_temperature", "quantity", "degC", default=20.0, minimum=-50.0, maximum=500.0,
              description="temperature at which its static curve is the model's (assembly)"),
    ), _method("eclutch"), "seed 000, Sec. 3.2"),
    Component("engine", "A combustion engine: torque map(w, throttle) plus an optional idle-speed PI controller.", (
        _FLANGE,
        Field("torque_map", "map", required=True,
              description="{ speeds, throttles, torques } (bilinear) or full-load rows [[w, T], ...]"),
        Field("throttle", "signal", "1", default=1.0, minimum=0.0, maximum=1.0,
              description="throttle, 0 (closed: the map's drag torque) to 1 (full load)"),
        Field("idle_speed", "quantity", "rad/s", positive=True,
              description="set speed of the idle controller (left out: no controller)"),
        Field("idle_kp", "quantity", "N*m*s/rad", default=2.0, minimum=0.0, description="idle controller's gain"),
        Field("idle_ki", "quantity", "N*m/rad", default=20.0, minimum=0.0,
              description="idle controller's integral gain"),
        Field("idle_torque_max", "quantity", "N*m", default=50.0, minimum=0.0, description="idle torque limit"),
        _SUPPORT,
    ), _method("engine"), "mean-value engine (torque map)"),
    Component("wet_clutch", "The wet clutch of seed 001 with its actuator, piston, squeeze film and temperatures.", (
        _A, _B,
        Field("force", "signal", "N", required=True, description="actuator force reference, a port: any signal in [0, the actuator's maximum]"),
        Field("clutch", "path", description="a wet-clutch parameter file (default WetClutch.paper())"),
        Field("bench", "path", description="a bench parameter file: actuator, oil loop, housing (default Bench())"),
        Field("friction", "path", description="a friction law (.toml) or an identified map (.json)"),
        Field("temperature0", "quantity", "degC", default=80.0, minimum=WET_TEMPERATURES_C[0], maximum=WET_TEMPERATURES_C[1],
              description="initial pack temperature"),
        Field("fluid_temperature0", "quantity", "degC", default=80.0, minimum=WET_TEMPERATURES_C[0], maximum=WET_TEMPERATURES_C[1],
              description="initial oil temperature (the heater's set point)"),
        Field("housing_temperature0", "quantity", "degC", default=80.0, minimum=WET_TEMPERATURES_C[0], maximum=WET_TEMPERATURES_C[1],
              description="initial housing temperature"),
    ), _wet_clutch, "seed 001, Eqs. 1-8"),
    Component("emtc", "The electromagnetic torque-controlled coupling of seed 002 with its controller.", (
        _flange("a", "its input shaft (front)"), _flange("b", "its output shaft (rear)"),
        Field("bench", "path", description="an EMTC scenario file (its [scenario], [vehicle], [actuator], "
                                           "[coupling] tables; no [magnet])"),
        Field("magnet", "path", description="a Preisach model .json (default the bundled synthetic one)"),
        Field("torque_request", "signal", "N*m",
              description="port: the controller's torque reference, sampled every sample time (replaces the map of "
                          "Eq. 31); a network input or any signal"),
        Field("throttle", "signal", "1", minimum=0.0, maximum=1.0,
              description="port: the map's throttle (Eq. 31), sampled every sample time (replaces the scenario's "
                          "ramp)"),
        Field("coil_current", "signal", "A",
              description="port: the coil current set point of a current drive (Fig. 15; no torque controller)"),
    ), _emtc, "seed 002, Eqs. 1-26 and 31"),
    Component("thermal_mass", "A thermal mass that the losses of elements heat, with a conductance to its ambient: "
                              "C dT/dt = sum P_loss - G (T - T_ambient) - its conductors' flows.", (
        Field("capacity", "quantity", "J/K", required=True, positive=True, description="heat capacity"),
        Field("T0", "quantity", "degC", default=20.0, minimum=ABSOLUTE_ZERO_C, description="initial temperature"),
        Field("conductance", "quantity", "W/K", default=0.0, minimum=0.0,
              description="thermal conductance to its ambient (0: insulated)"),
        Field("ambient", "quantity", "degC", default=20.0, minimum=ABSOLUTE_ZERO_C,
              description="the ambient's temperature"),
        Field("heat_from", "names", description="the elements whose losses heat it (their heat ports; each heats "
                                                "one mass; not sources or wet clutches; an EMTC with a friction map reads it at this mass's "
                                                "temperature)"),
    ), _method("thermal_mass"), "Modelica.Thermal.HeatTransfer.Components.HeatCapacitor, ThermalConductor, "
                                f"FixedTemperature; {_MSL}.Interfaces.PartialElementaryConditionalHeatPort", _BOTH),
    Component("thermal_conductor", "A thermal conductor between two thermal masses: heat flow G (T_a - T_b).", (
        Field("a", "thermal", required=True, description="the thermal mass at its port a"),
        Field("b", "thermal", required=True, description="the thermal mass at its port b"),
        Field("conductance", "quantity", "W/K", required=True, minimum=0.0, description="thermal conductance G"),
    ), _method("thermal_conductor"), "Modelica.Thermal.HeatTransfer.Components.ThermalConductor", _BOTH),
)
for _c in BUILTIN:
    register_component(_c)
