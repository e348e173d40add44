"""Driveline networks described in TOML files with units.

::

    [driveline]
    name = "coupled_clutches"

    [simulation]              # optional: defaults of `clutchlab driveline simulate`
    t_end = "1.5 s"
    output_step = "1 ms"
    rtol = 1e-8

    [inertia.J1]
    J = "1 kg m^2"
    w0 = "10 rad/s"

    [torque.torque]
    flange = "J1"
    torque = { sine = { amplitude = "10 N m", frequency = "5 Hz" } }

    [clutch.clutch1]
    a = "J1"
    b = "J2"
    fn_max = "20 N"
    mu = 0.5
    peak = 1.1
    normal = { sine = { amplitude = 1, frequency = "0.2 Hz", phase = "90 deg" } }

    [shift]                   # optional: the clutch-to-clutch shift the network makes (a dual-clutch upshift)
    offgoing = "c1"           # friction elements of the network (an AMT's: its synchronisers, and clutch = its
    oncoming = "c2"           # clutch)
    output = "wheels"         # an inertia; engine, the engine's (optional)
    radius = "0.3 m"          # optional, as threshold, settle, pre, start (clutchlab.driveline.shift.shift_quality)

Component tables are the registered component kinds, each declared once with its fields' units,
defaults and physical ranges (:mod:`clutchlab.component`, :mod:`clutchlab.driveline.components`;
``clutchlab driveline components [KIND]``, docs/components.md); a value outside its range is refused
naming the file, the key, the value and the range.  The built-in ones (rotational): ``inertia`` (J, w0,
phi0), ``spring_damper`` (a, b, c, d, phi_rel0),
``spring`` (a, b, curve = rows ``[phi, tau]``, interpolation = "linear" or "pchip", d, phi_rel0),
``backlash`` (a, b, c, b_gap, d, phi_rel0, damping_law = "kelvin_voigt" (default) or "msl": MSL
``ElastoBacklash``'s), ``gear`` (a, b, ratio, efficiency or loss_table = rows ``[|w_a|, eta_mf1, eta_mf2, tau_bf1,
tau_bf2]`` as MSL's ``lossTable``, support = the housing's inertia), ``torque_converter`` (a = the impeller, b = the
turbine, table = rows ``[SR, K, TR]`` with K in any unit of rad/s/sqrt(N m), ``"130 rpm/(N m)^0.5"``, coast_table =
rows ``[SR, K]``, support), ``torque`` (flange, torque, support), ``speed``
(flange, speed), ``position`` (flange, position), ``clutch`` (a, b, fn_max, mu, peak, cgeo, normal; or mu_map = a
friction map ``.json`` of ``clutchlab wet identify`` with radius [m] and
temperature [degC]), ``brake`` (flange, fn_max, mu, peak, cgeo, normal, support; mu_map, radius, temperature),
``bearing_friction``
(flange, torque, peak, support), ``one_way_clutch`` (a, b; fn_max, mu, peak, cgeo, normal: MSL's
``OneWayClutch``), ``synchronizer`` (a = the shaft, b = the gear's idler, force [N] on the sleeve, cone_radius,
dog_capacity, mu, cone_angle, cones, side: an AMT's or manual gearbox's), ``eclutch`` (a, b, position [m], model
0-4, parameters = an E-clutch parameter file relative to this one, travel, points, peak; actuator = true: the
position is the reference of its actuator's position controller, actuator_step, pre_roll, settle), ``engine``
(flange, torque_map = ``{ speeds, throttles, torques }`` or full-load rows ``[[w, T], ...]``, throttle,
idle_speed, idle_kp, idle_ki, idle_torque_max, support) and ``wet_clutch``
(a, b, force [N] = its port, any signal; clutch, bench = wet-clutch parameter files, friction = a
friction law file or an identified map ``.json``; temperature0, fluid_temperature0, housing_temperature0
[degC]) and ``emtc`` (a = its input shaft, b = its output shaft; bench = an EMTC scenario file of
``clutchlab emtc simulate`` (its ``[scenario]``, ``[vehicle]``, ``[actuator]``, ``[coupling]`` tables: the
controller's throttle ramp, gear and sample time, the coupling's data; no ``[magnet]`` table), magnet = a
Preisach model ``.json`` (default the bundled synthetic one); its ports torque_request [N m] (the controller's
torque reference in place of the map of Eq. 31), throttle [1] (the map's throttle in place of the scenario's
ramp), coil_current [A] (a current drive's set point, no torque controller): signals, a network input
``{ input = "NAME" }`` included).  With ``[driveline] domain =
"translational"`` the bodies are ``mass`` (m, v0, s0) and the sources ``force`` (flange, force,
support); every other table is the same, in N, m, m/s, N/m, N s/m.  Quantities are numbers in SI or
strings with units, converted once here.  A signal is a number or
quantity (a constant) or one of ``{ constant = v }``, ``{ step = { height, start, offset } }``,
``{ ramp = { height, duration, start, offset } }``, ``{ sine = { amplitude, frequency, phase, offset,
start } }``, ``{ pulse = { amplitude, width, period, nperiod, offset, start } }`` (width the fraction of
the period it is on, in (0, 1]: ``0.5`` or ``"50 %"``; ``nperiod`` a whole number, -1 unlimited),
``{ trapezoid = { amplitude, rising, width, falling, period, nperiod, offset, start } }`` (times in s,
rising + width + falling <= period), ``{ exponentials = { out_max, rise_time, rise_time_const,
fall_time_const, offset, start } }``, ``{ table = { times = [...], values = [...] } }`` (times in s, values
in the signal's unit) or ``{ product = [S1, S2] }``, S1 a signal in the field's unit (a number, a quantity
or one of these tables) and S2 a dimensionless one (MSL ``Blocks.Sources`` and ``Blocks.Math.Product``),
or ``{ input = "NAME" }``: the network input declared by an ``[input.NAME]`` table (``start``, a quantity
in the unit of the fields that read it, default 0; ``description``), held by whatever drives the network
(``Driveline.simulate``'s ``inputs``, a co-simulation master, an FMU's importer, a controller).  Torque and
force sources, clutches' and brakes' normal signals, an engine's throttle, an E-clutch's bearing position
(without its actuator), a wet clutch's force and an EMTC's ports (any signal) take inputs;
motion sources and the E-clutch with its actuator do not (yet).
A friction characteristic (``mu``, a bearing's ``torque``) is a number or a table of rows
``[w_rad_s, value]``.  Every error names the file, the key and the value.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from ..component import check_range, components
from ..errors import DataError, ParameterError
from ..io.files import read_toml
from ..system import check_rtol
from ..units import to_si
from .network import Driveline, Signal

__all__ = ["load_driveline", "parse_driveline", "DrivelineFile"]

#: a translational driveline: masses and forces, the units of its domain
_TRANSLATE = {"kg*m**2": "kg", "rad/s": "m/s", "rad": "m", "N*m": "N", "N*m/rad": "N/m", "N*m*s/rad": "N*s/m"}


def tables(domain: str = "rotational") -> dict:
    """The component tables of a network file of ``domain``, generated from the registered components
    (:func:`clutchlab.component.components`): ``{table: (Component, {key: Field})}``, the fields in the
    domain's names and units (a translational network's ``mass`` with ``m`` [kg], its clutch's ``mu`` over
    m/s)."""
    out = {}
    for comp in components(domain).values():
        if domain == "rotational":
            out[comp.kind] = (comp, {f.name: f for f in comp.fields})
            continue
        table, renames = comp.translational or (comp.kind, {})
        out[table] = (comp, {renames.get(f.name, f.name): dataclasses.replace(
            f, name=renames.get(f.name, f.name), unit=_TRANSLATE.get(f.unit, f.unit)) for f in comp.fields})
    return out


def field_units(domain: str = "rotational") -> dict:
    """``{table: {key: (unit, required)}}`` of :func:`tables`: the unit of a number, signal or characteristic,
    None for a flange, else the field's kind (``"path"``, ``"int"``, ``"choice"``, ...)."""
    return {table: {k: (None if f.kind == "flange" else f.unit if f.kind in _UNIT_KINDS else f.kind, f.required)
                    for k, f in fields.items()} for table, (_, fields) in tables(domain).items()}


#: field kinds whose value carries the field's unit
_UNIT_KINDS = ("quantity", "signal", "characteristic", "curve")
#: field kinds that are not quantities: a choice among words, a whole number, a file (relative to the description)
NOT_QUANTITIES = ("choice", "int", "path", "bool", "map", "losstable", "thermal", "names", "temperature_table",
                  "rows")
SIGNAL_FIELDS = {
    "constant": None,
    "step": {"height": "value", "start": "s", "offset": "value"},
    "ramp": {"height": "value", "duration": "s", "start": "s", "offset": "value"},
    "sine": {"amplitude": "value", "frequency": "Hz", "phase": "rad", "offset": "value", "start": "s"},
    "pulse": {"amplitude": "value", "width": "1", "period": "s", "nperiod": "int", "offset": "value", "start": "s"},
    "trapezoid": {"amplitude": "value", "rising": "s", "width": "s", "falling": "s", "period": "s", "nperiod": "int",
                  "offset": "value", "start": "s"},
    "exponentials": {"out_max": "value", "rise_time": "s", "rise_time_const": "s", "fall_time_const": "s",
                     "offset": "value", "start": "s"},
    "table": {"times": "s", "values": "value"},
    "product": None,
    "input": None,
}
#: the parameters a signal needs (the others have defaults)
SIGNAL_REQUIRED = {"step": (), "ramp": ("height", "duration"), "sine": ("amplitude", "frequency"),
                   "pulse": ("amplitude", "width", "period"),
                   "trapezoid": ("amplitude", "rising", "width", "falling", "period"),
                   "exponentials": ("out_max", "rise_time", "rise_time_const", "fall_time_const"),
                   "table": ("times", "values")}
SIMULATION_FIELDS = {"t_end": "s", "output_step": "s", "rtol": "1", "max_step": "s"}


@dataclass
class DrivelineFile:
    """A driveline read from a file: the network and the ``[simulation]`` defaults.

    Parameters
    ----------
    driveline : Driveline
        The network.
    t_end : float or None
        End time [s] from ``[simulation]``.
    output_step : float or None
        Sample interval [s].
    rtol : float
        Relative tolerance (default 1e-8).
    max_step : float or None
        Largest step [s].
    shift : dict or None
        The ``[shift]`` table: the keyword arguments of :func:`clutchlab.driveline.shift.shift_quality` for the
        shift the network makes, clutch-to-clutch or an AMT's with ``clutch`` (``clutchlab control shift FILE``,
        the sweep's ``shift.<metric>``).
    tcu : dict or None
        The ``[tcu]`` table: its ``type`` (``"amt"`` or ``"dct"``), the keyword arguments of its controller
        (:class:`clutchlab.control.AmtController`, an automated manual transmission's, :data:`TCU_FIELDS`;
        :class:`clutchlab.control.DctController`, a dual-clutch transmission's, :data:`DCT_FIELDS`: a gear command
        carried out; names checked against the network, quantities in SI) and its ``sample_time`` [s]
        (``clutchlab control tcu FILE``).
    """

    driveline: Driveline
    t_end: float | None = None
    output_step: float | None = None
    rtol: float = 1e-8
    max_step: float | None = None
    shift: dict | None = None
    tcu: dict | None = None


#: the fields of a ``[tcu]`` table (:class:`clutchlab.control.AmtController`'s arguments and the controller's sample
#: time): name -> unit of a quantity, or the kind of a value that is not one
TCU_FIELDS = {"gears": "gears", "start_gear": "gear", "commands": "commands", "torque_input": "input",
              "clutch_input": "input", "torque": "demand", "drag": "N*m", "fork_force": "N", "torque_down": "s",
              "clutch_open": "s", "fork_ramp": "s", "clutch_close": "s", "sync_timeout": "s", "sample_time": "s",
              "speed_match": "N*m*s/rad", "engine_speed": "variable", "output_speed": "variable", "torque_max": "N*m",
              "type": "type"}
#: the fields of one gear of a ``[tcu]`` table's ``gears``
TCU_GEAR_FIELDS = ("synchronizer", "fork", "side", "ratio")
#: the fields of a ``[tcu]`` table with ``type = "dct"`` (:class:`clutchlab.control.DctController`'s arguments and the
#: controller's sample time)
DCT_FIELDS = {"type": "type", "gears": "gears", "start_gear": "gear", "commands": "commands", "torque_input": "input",
              "torque": "demand", "engine_speed": "variable", "output_speed": "variable", "fill": "1", "handover": "s",
              "rise": "s", "restore": "s", "torque_cut": "1", "slip": "1", "coast_slip": "1", "shift_timeout": "s",
              "sample_time": "s"}
#: the fields of one gear of a dual-clutch ``[tcu]`` table's ``gears``
DCT_GEAR_FIELDS = ("clutch", "input", "ratio")
#: the transmission controllers a ``[tcu]`` table's ``type`` names (``"amt"`` where it names none)
TCU_TYPES = ("amt", "dct")


def _quantity(value, unit, key, src):
    return to_si(value, unit, name=key, source=src)


#: the column suffix (clutchlab.units.COLUMN_UNITS) of an input driving a field of this unit
_INPUT_SUFFIX = {"N*m": "Nm", "N": "N", "1": "1", "rad/s": "rad_s", "m/s": "m_s", "rad": "rad", "m": "m", "A": "A"}
#: the fields of an [input.NAME] table
INPUT_FIELDS = ("start", "description")


def _signal(value, unit, key, src, uses=None) -> Signal:
    """The signal of field ``key`` (values in ``unit``); an input it reads is noted in ``uses``: name -> [(unit,
    key), ...]."""
    if not isinstance(value, dict):
        return Signal.constant(_quantity(value, unit, key, src))
    if len(value) != 1:
        raise ParameterError(f"{src}: {key} = {value!r}: expected one of {', '.join(SIGNAL_FIELDS)} "
                             "(e.g. {{ sine = {{ amplitude = ..., frequency = ... }} }})")
    kind, spec = next(iter(value.items()))
    if kind not in SIGNAL_FIELDS:
        raise ParameterError(f"{src}: {key}: unknown signal {kind!r} (known: {', '.join(SIGNAL_FIELDS)})")
    if kind == "constant":
        return Signal.constant(_quantity(spec, unit, f"{key}.constant", src))
    if kind == "input":
        if not isinstance(spec, str) or not spec:
            raise ParameterError(f"{src}: {key}.input = {spec!r}: expected the name of an [input.NAME] table")
        if uses is not None:
            uses.setdefault(spec, []).append((unit, key))
        return Signal.input(spec)
    if kind == "product":   # [a signal in the field's unit, a dimensionless one]
        if not isinstance(spec, list) or len(spec) != 2:
            raise ParameterError(f"{src}: {key}.product = {spec!r}: expected two signals [S1, S2] (S1 in the "
                                 "field's unit, S2 dimensionless)")
        return Signal.product(_signal(spec[0], unit, f"{key}.product[0]", src, uses),
                              _signal(spec[1], "1", f"{key}.product[1]", src, uses))
    if not isinstance(spec, dict):
        raise ParameterError(f"{src}: {key}.{kind} = {spec!r}: expected a table of its parameters")
    fields = SIGNAL_FIELDS[kind]
    unknown = [f for f in spec if f not in fields]
    if unknown:
        raise ParameterError(f"{src}: {key}.{kind}: unknown parameter {unknown[0]!r} (known: {', '.join(fields)})")
    args = {}
    for f, v in spec.items():
        u = unit if fields[f] == "value" else fields[f]
        if kind == "table":
            if not isinstance(v, list):
                raise ParameterError(f"{src}: {key}.table.{f} = {v!r}: expected a list")
            args[f] = [_quantity(x, u, f"{key}.table.{f}[{i}]", src) for i, x in enumerate(v)]
        elif u == "int":
            if not isinstance(v, int) or isinstance(v, bool):
                raise ParameterError(f"{src}: {key}.{kind}.{f} = {v!r}: expected a whole number (-1: unlimited)")
            args[f] = v
        else:
            args[f] = _quantity(v, u, f"{key}.{kind}.{f}", src)
    try:
        if kind == "table":
            return Signal.table(args.get("times", []), args.get("values", []))
        if kind == "ramp" and "duration" not in args:
            raise ParameterError("ramp needs a duration")
        if kind == "sine" and not {"amplitude", "frequency"} <= set(args):
            raise ParameterError("sine needs an amplitude and a frequency")
        missing = [f for f in SIGNAL_REQUIRED[kind] if f not in args]
        if missing:
            raise ParameterError(f"{kind} needs {', '.join(missing)} (it has {', '.join(args) or 'none'})")
        return getattr(Signal, kind)(**args)
    except ParameterError as exc:
        raise ParameterError(f"{src}: {key}: {exc}") from None


def _characteristic(value, unit, key, src, x_unit="rad/s", table_only=False):
    if isinstance(value, list):
        rows = []
        for i, row in enumerate(value):
            if not (isinstance(row, list) and len(row) == 2):
                raise ParameterError(f"{src}: {key}[{i}] = {row!r}: expected a row [{x_unit}, {unit}]")
            rows.append([_quantity(row[0], x_unit, f"{key}[{i}][0]", src), _quantity(row[1], unit, f"{key}[{i}][1]", src)])
        return rows
    if table_only:
        raise ParameterError(f"{src}: {key} = {value!r}: expected rows [[{x_unit}, {unit}], ...]")
    return _quantity(value, unit, key, src)


#: the columns of a gear's loss table (MSL ``LossyGear.lossTable``) and their units
LOSS_TABLE_COLUMNS = ("w", "eta_mf1", "eta_mf2", "tau_bf1", "tau_bf2")


def _loss_table(value, key, src, speed_unit="rad/s", torque_unit="N*m"):
    """A gear's loss table: rows ``[|w_a|, eta_mf1, eta_mf2, tau_bf1, tau_bf2]`` (speed, two efficiencies, two
    bearing friction torques), each entry a number in SI or a quantity with its unit, converted to SI."""
    return _rows(value, "|".join((speed_unit, "1", "1", torque_unit, torque_unit)), key, src, LOSS_TABLE_COLUMNS)


def _rows(value, units, key, src, names=None):
    """A table of rows (a ``"rows"`` field): one entry per column of ``units`` (a number in SI or a quantity with its
    unit), converted to SI; errors show the columns by ``names`` (default their units)."""
    units = [u.strip() for u in units.split("|")]
    shown = "[" + ", ".join(names or units) + "]"
    if not isinstance(value, list) or not value:
        raise ParameterError(f"{src}: {key} = {value!r}: expected rows {shown}")
    out = []
    for i, row in enumerate(value):
        if not (isinstance(row, list) and len(row) == len(units)):
            raise ParameterError(f"{src}: {key}[{i}] = {row!r}: expected a row of {len(units)} {shown}")
        out.append([_quantity(v, u, f"{key}[{i}][{j}]", src) for j, (v, u) in enumerate(zip(row, units))])
    return out


def _engine_map(value, key, src):
    """An engine's torque map: ``{ speeds = [...], throttles = [...], torques = [[...], ...] }`` (a row of
    torques per speed) or the full-load rows ``[[w, T], ...]``, converted to SI."""
    if isinstance(value, list):
        return _characteristic(value, "N*m", key, src, table_only=True)
    if not isinstance(value, dict) or set(value) != {"speeds", "throttles", "torques"}:
        raise ParameterError(f"{src}: {key}: expected {{ speeds = [...], throttles = [...], torques = [[...], ...] }} "
                             "or rows [[speed, torque], ...]")
    for f in ("speeds", "throttles", "torques"):
        if not isinstance(value[f], list) or not value[f]:
            raise ParameterError(f"{src}: {key}.{f} = {value[f]!r}: expected a non-empty list")
    speeds = [_quantity(v, "rad/s", f"{key}.speeds[{i}]", src) for i, v in enumerate(value["speeds"])]
    throttles = [_quantity(v, "1", f"{key}.throttles[{i}]", src) for i, v in enumerate(value["throttles"])]
    rows = []
    for i, row in enumerate(value["torques"]):
        if not isinstance(row, list) or len(row) != len(throttles):
            raise ParameterError(f"{src}: {key}.torques[{i}] = {row!r}: expected a row of {len(throttles)} torques "
                                 "(one per throttle)")
        rows.append([_quantity(v, "N*m", f"{key}.torques[{i}][{j}]", src) for j, v in enumerate(row)])
    return (speeds, throttles, rows)


def _field_value(field, v, fkey, src, base, uses, speed_unit, angle_unit):
    """The value of one field of a component table, converted to SI and checked against its declaration
    (:class:`clutchlab.component.Field`): its kind, its unit, its words, its range."""
    kind = field.kind
    if kind == "flange":
        if not isinstance(v, str):
            raise ParameterError(f"{src}: {fkey} = {v!r}: expected the name of an inertia or \"ground\"")
        return v
    if kind == "thermal":
        if not isinstance(v, str) or not v:
            raise ParameterError(f"{src}: {fkey} = {v!r}: expected the name of a thermal mass")
        return v
    if kind == "names":
        if isinstance(v, str):
            v = [v]
        if not isinstance(v, list) or not all(isinstance(n, str) and n for n in v):
            raise ParameterError(f"{src}: {fkey} = {v!r}: expected a list of component names ([\"C1\", \"D1\"])")
        return tuple(v)
    if kind == "signal":
        sig = _signal(v, field.unit, fkey, src, uses)
        if field.minimum is not None or field.maximum is not None or field.positive:
            for bound in dict.fromkeys(sig.bounds()):   # (an input's values: its host's, see [input.NAME])
                problem = None if bound is None else field.range_problem(bound)
                if problem:
                    shown = sig.describe("" if field.unit == "1" else field.unit)
                    raise ParameterError(f"{src}: {fkey} = {shown} reaches {bound:g}: {problem}")
        return sig
    if kind == "characteristic":
        value = _characteristic(v, field.unit, fkey, src, x_unit=speed_unit)
        for i, y in ([(None, value)] if isinstance(value, float) else enumerate(r[1] for r in value)):
            problem = field.range_problem(y)
            if problem:
                raise ParameterError(f"{src}: {fkey}" + ("" if i is None else f"[{i}][1]") + " = "
                                     + (f"{v!r}" if i is None else f"{v[i][1]!r}") + f": {problem}")
        return value
    if kind == "curve":
        return _characteristic(v, field.unit, fkey, src, x_unit=angle_unit, table_only=True)
    if kind == "temperature_table":
        rows = _characteristic(v, field.unit, fkey, src, x_unit="degC", table_only=True)
        for i, (_temp, y) in enumerate(rows):
            problem = field.range_problem(y)
            if problem:
                raise ParameterError(f"{src}: {fkey}[{i}][1] = {v[i][1]!r}: {problem}")
        return rows
    if kind == "choice":
        if v not in field.choices:
            raise ParameterError(f"{src}: {fkey} = {v!r}: expected " + " or ".join(f'"{c}"' for c in field.choices))
        return v
    if kind == "bool":
        if not isinstance(v, bool):
            raise ParameterError(f"{src}: {fkey} = {v!r}: expected true or false")
        return v
    if kind == "map":
        return _engine_map(v, fkey, src)
    if kind == "losstable":
        return _loss_table(v, fkey, src, speed_unit, "N*m" if speed_unit == "rad/s" else "N")
    if kind == "rows":
        return _rows(v, field.unit, fkey, src)
    if kind == "int":
        if not isinstance(v, int) or isinstance(v, bool):
            raise ParameterError(f"{src}: {fkey} = {v!r}: expected a whole number")
        return int(check_range(field, v, f"{src}: {fkey}"))
    if kind == "path":
        if not isinstance(v, str) or not v:
            raise ParameterError(f"{src}: {fkey} = {v!r}: expected a file name")
        target = (base / v).resolve()
        if not target.is_file():
            raise ParameterError(f"{src}: {fkey} = {v!r}: no such file ({target})")
        return target
    value = _quantity(v, field.unit, fkey, src)
    problem = field.range_problem(value)
    if problem:
        raise ParameterError(f"{src}: {fkey} = {v!r}: {problem}")
    return value


def input_units(doc: dict, source: str) -> dict:
    """The pint unit of each network input of a parsed description: that of the first field reading it
    (``{ input = "NAME" }``), ``{name: unit}``.  A field the loader would refuse is left out (the loader names
    it: :func:`parse_driveline`)."""
    head = doc.get("driveline", {})
    translational = isinstance(head, dict) and head.get("domain") == "translational"
    known = tables("translational" if translational else "rotational")
    uses: dict = {}
    for kind, table in doc.items():
        if kind not in known or not isinstance(table, dict):
            continue
        signals = [f for f in known[kind][1].values() if f.kind == "signal"]
        for name, comp in table.items():
            for f in signals:
                if isinstance(comp, dict) and f.name in comp:
                    try:
                        _signal(comp[f.name], f.unit, f"{kind}.{name}.{f.name}", source, uses)
                    except ParameterError:
                        pass
    return {n: u[0][0] for n, u in uses.items()}


def _declare_inputs(d: Driveline, declared: dict, uses: dict, src: str) -> None:
    """The ``[input.NAME]`` tables: each input takes the unit of the fields that read it (``{ input = "NAME" }``),
    its ``start`` a quantity in that unit (default 0); an input read nowhere, or read by fields of two units, or
    read without a table, is an error naming the key."""
    for name, (unit, key) in ((n, u[0]) for n, u in uses.items()):
        if name not in declared:
            raise ParameterError(f"{src}: {key}.input = {name!r}: no [input.{name}] table (inputs: "
                                 f"{', '.join(declared) or 'none'})")
    for name in declared:   # (every input's unit first: a clash names both fields, not a start it makes wrong)
        units = sorted({u for u, _ in uses.get(name, ())})
        if len(units) > 1:
            raise ParameterError(f"{src}: [input.{name}] is read by fields of different units ({', '.join(units)}: "
                                 f"{', '.join(k for _, k in uses[name])})")
    for name, spec in declared.items():
        key = f"input.{name}"
        for f in spec:
            if f not in INPUT_FIELDS:
                raise ParameterError(f"{src}: {key}.{f}: unknown field (known: {', '.join(INPUT_FIELDS)}; the unit "
                                     "is that of the fields the input drives)")
        if name not in uses:
            raise ParameterError(f"{src}: [{key}] drives nothing (read it in a signal field: {{ input = \"{name}\" }})")
        unit = uses[name][0][0]
        start = _quantity(spec.get("start", 0.0), unit, f"{key}.start", src)
        description = spec.get("description", "")
        if not isinstance(description, str):
            raise ParameterError(f"{src}: {key}.description = {description!r}: expected text")
        try:
            d.input(name, unit=_INPUT_SUFFIX.get(unit, "1"), start=start,
                    description=description or f"input {name} [{unit}] ({', '.join(k for _, k in uses[name])})")
        except ParameterError as exc:
            raise ParameterError(f"{src}: [{key}] {exc}") from None


def load_driveline(path) -> DrivelineFile:
    """Read a driveline TOML file (format in this module's docstring).

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    DrivelineFile

    Raises
    ------
    ParameterError
        Unknown tables, components or fields, missing fields, wrong units, bad values, unknown flanges
        -- naming the file, the key and the value.
    """
    return parse_driveline(read_toml(path), str(path), Path(path).parent)


def parse_driveline(doc: dict, source: str, base=None, set_changes: dict | None = None) -> DrivelineFile:
    """A driveline from a parsed TOML document (the format of :func:`load_driveline`).

    Parameters
    ----------
    doc : dict
        The document, as ``tomllib`` reads it.
    source : str
        What to name in error messages (the file, or the file and the changes of a variant).
    base : str or Path, optional
        Folder that files named in the document are relative to (default: the folder of ``source``).
    set_changes : dict, optional
        ``{(kind, component): {set: {set field: value}}}``: numeric fields of the parameter sets a component's
        path fields name, changed (:func:`clutchlab.driveline.components.parameter_sets`;
        :meth:`~clutchlab.driveline.variants.DrivelineDocument.load`).

    Returns
    -------
    DrivelineFile
    """
    src = str(source)
    if not isinstance(doc, dict):
        raise ParameterError(f"{src}: expected a driveline document (a table of component tables, as tomllib "
                             f"reads a file), not {type(doc).__name__}")
    base = Path(base) if base is not None else Path(src).parent
    by_domain = {dom: tables(dom) for dom in ("rotational", "translational")}
    known = {"driveline", "simulation", "input", "shift", "tcu", *by_domain["rotational"],
             *by_domain["translational"]}
    for top in doc:
        if top not in known:
            raise ParameterError(f"{src}: unknown table [{top}] (known: {', '.join(sorted(known))})")
    head = doc.get("driveline", {})
    if not isinstance(head, dict) or any(k not in ("name", "domain") for k in head):
        raise ParameterError(f"{src}: [driveline] takes only name = \"...\" and domain = \"rotational\" or \"translational\"")
    domain = head.get("domain", "rotational")
    if domain not in ("rotational", "translational"):
        raise ParameterError(f"{src}: driveline.domain = {domain!r}: expected \"rotational\" or \"translational\"")
    d = Driveline(str(head.get("name", "driveline")), domain=domain)
    table_fields = by_domain[domain]
    speed_unit = "rad/s" if domain == "rotational" else "m/s"
    angle_unit = "rad" if domain == "rotational" else "m"
    sim = doc.get("simulation", {})
    if not isinstance(sim, dict):
        raise ParameterError(f"{src}: [simulation] must be a table")
    for k in sim:
        if k not in SIMULATION_FIELDS:
            raise ParameterError(f"{src}: [simulation] {k}: unknown field (known: {', '.join(SIMULATION_FIELDS)})")
    settings = {k: _quantity(v, SIMULATION_FIELDS[k], f"simulation.{k}", src) for k, v in sim.items()}
    for k, v in settings.items():   # (refused here, so describe and simulate refuse alike: #33)
        if not (0.0 < v < 1.0 if k == "rtol" else v > 0.0):
            raise ParameterError(f"{src}: simulation.{k} = {sim[k]!r}: must be "
                                 + ("in (0, 1)" if k == "rtol" else "> 0 [s]"))
        if k == "rtol":
            check_rtol(v, f"{src}: simulation.rtol")   # (the one rule of every model: at least RTOL_MIN)
    for top in doc:
        if top in known and top not in table_fields and top not in ("driveline", "simulation", "input", "shift",
                                                                     "tcu"):
            other = "translational" if domain == "rotational" else "rotational"
            raise ParameterError(f"{src}: [{top}] belongs to a {other} driveline (this one is {domain}; set "
                                 f"[driveline] domain)")
    # bodies first: the elements name them
    body = "inertia" if domain == "rotational" else "mass"
    order = [body] + [k for k in doc if k in table_fields and k != body]
    declared = doc.get("input", {})
    if not isinstance(declared, dict) or not all(isinstance(v, dict) for v in declared.values()):
        raise ParameterError(f"{src}: [input] must hold named inputs ([input.NAME] with start, description)")
    uses: dict = {}
    for kind in order:
        table = doc.get(kind, {})
        if not isinstance(table, dict):
            raise ParameterError(f"{src}: [{kind}] must hold named components ([{kind}.NAME])")
        for name, comp in table.items():
            key = f"{kind}.{name}"
            if not isinstance(comp, dict):
                raise ParameterError(f"{src}: {key} = {comp!r}: expected a table [{key}]")
            comp_decl, fields = table_fields[kind]
            for f in comp:
                if f not in fields:
                    raise ParameterError(f"{src}: {key}.{f}: unknown field (known: {', '.join(fields)})")
            missing = [f for f, field in fields.items() if field.required and f not in comp]
            if missing:
                raise ParameterError(f"{src}: {key}: missing field {missing[0]!r}")
            renames = (comp_decl.translational or (kind, {}))[1] if domain == "translational" else {}
            back = {v: k for k, v in renames.items()}
            args = {back.get(f, f): _field_value(fields[f], v, f"{key}.{f}", src, base, uses, speed_unit, angle_unit)
                    for f, v in comp.items()}
            if set_changes and (kind, name) in set_changes:
                args["set_changes"] = set_changes[(kind, name)]
            n_before = len(d._elements)
            try:
                comp_decl.build(d, name, **args)
            except (ParameterError, DataError) as exc:
                raise ParameterError(f"{src}: [{key}] {exc}") from None
            for e in d._elements[n_before:]:   # (Driveline.elements: the file's component type, cone_clutch)
                e.kind_name = kind
    if not d._inertias:
        raise ParameterError(f"{src}: no [{body}.NAME] table (a driveline needs at least one {body})")
    try:   # the heat ports name elements anywhere in the file: checked once all are built
        d._heat_rows()
    except ParameterError as exc:
        raise ParameterError(f"{src}: {exc}") from None
    _declare_inputs(d, declared, uses, src)
    return DrivelineFile(d, settings.get("t_end"), settings.get("output_step"), settings.get("rtol", 1e-8),
                         settings.get("max_step"), _shift(doc.get("shift"), d, src), _tcu(doc.get("tcu"), d, src))


def _check_table(table, name, fields, required, src) -> None:
    """A top-level table ``[name]`` of known ``fields`` with its ``required`` ones (errors name the file, the table and
    the field)."""
    if not isinstance(table, dict):
        raise ParameterError(f"{src}: [{name}] must be a table ({', '.join(required)}, ...)")
    for k in table:
        if k not in fields:
            raise ParameterError(f"{src}: {name}.{k}: unknown field (known: {', '.join(fields)})")
    for k in required:
        if k not in table:
            raise ParameterError(f"{src}: [{name}]: missing field {k!r}")


def _gear_number(value, key, src):
    """A gear's number: a whole number (a TOML key "1" or a value 1)."""
    try:
        g = int(value)
    except (TypeError, ValueError):
        g = None
    if g is None or isinstance(value, bool) or str(g) != str(value).strip():
        raise ParameterError(f"{src}: {key} = {value!r}: expected a gear's number (a whole number)")
    return g


def _tcu(table, d: Driveline, src: str):
    """The ``[tcu]`` table: its ``type`` (``"amt"``, the default, or ``"dct"``), the keyword arguments of its
    controller (:class:`clutchlab.control.AmtController`, :class:`clutchlab.control.DctController`) for the network's
    gear command and its ``sample_time`` (names checked against the network: the gears' synchronisers or clutches, the
    network inputs it sets, the speeds it reads; quantities in SI; an AMT's gear as ``(synchronizer, fork, side,
    ratio)``, a DCT's as ``(clutch, input, ratio)``), or None without one.  The controller checks the rest as it is
    built."""
    if table is None:
        return None
    kind_of = table.get("type", "amt") if isinstance(table, dict) else "amt"
    if kind_of not in TCU_TYPES:
        raise ParameterError(f"{src}: tcu.type = {kind_of!r}: expected one of {', '.join(TCU_TYPES)}")
    dct = kind_of == "dct"
    fields = DCT_FIELDS if dct else TCU_FIELDS
    _check_table(table, "tcu", fields, ("gears", "start_gear", "commands", "torque_input", "torque")
                 + (("engine_speed", "output_speed") if dct else ("clutch_input",)), src)
    out = {"type": kind_of}
    variables = None   # (the network's states and outputs, listed once, where a field names one)
    for k, v in table.items():
        kind, key = fields[k], f"tcu.{k}"
        if kind == "type":
            continue
        if kind == "gears":
            if not isinstance(v, dict) or not v:
                raise ParameterError(f"{src}: {key} must be a table of gears, e.g. 1 = " + (
                    "{ clutch = \"c1\", input = \"c1_command\", ratio = 3.5 }" if dct else
                    "{ synchronizer = \"s1\", fork = \"fork\", side = 1 }"))
            out[k] = {_gear_number(g, f"{key}.{g}", src): (_dct_gear if dct else _amt_gear)(spec, d, f"{key}.{g}", src)
                      for g, spec in v.items()}
        elif kind == "gear":
            out[k] = _gear_number(v, key, src)
        elif kind == "commands":
            if not isinstance(v, list) or not all(isinstance(c, list) and len(c) == 2 for c in v):
                raise ParameterError(f"{src}: {key} must be rows [time, gear], e.g. [[\"0.4 s\", 2]]")
            out[k] = [(_quantity(t, "s", f"{key}[{i}]", src), _gear_number(g, f"{key}[{i}]", src))
                      for i, (t, g) in enumerate(v)]
        elif kind == "input":
            _network_input(v, d, key, src)
            out[k] = v
        elif kind == "demand":   # a torque, or rows [time, torque] (the driver's tip-in or tip-out)
            if isinstance(v, list):
                if not all(isinstance(r, list) and len(r) == 2 for r in v):
                    raise ParameterError(f"{src}: {key} must be a torque or rows [time, torque], e.g. "
                                         "[[\"0 s\", \"150 N m\"], [\"1 s\", \"-40 N m\"]]")
                out[k] = [(_quantity(a, "s", f"{key}[{i}]", src), _quantity(b, "N*m", f"{key}[{i}]", src))
                          for i, (a, b) in enumerate(v)]
            else:
                out[k] = _quantity(v, "N*m", key, src)
        elif kind == "variable":
            if variables is None:
                variables = d.variables()
            states, outputs = variables
            if not isinstance(v, str) or v not in {name for name, *_ in (*states, *outputs)}:
                speeds = ", ".join(name for name, unit, _ in states if unit in ("rad_s", "m_s"))
                raise ParameterError(f"{src}: {key} = {v!r}: expected a state or output of the network, a speed "
                                     f"({speeds or 'none'})")
            out[k] = v
        else:
            out[k] = _quantity(v, kind, key, src)
    if not out.get("sample_time", 1.0) > 0.0:
        raise ParameterError(f"{src}: tcu.sample_time = {table['sample_time']!r}: must be > 0 [s]")
    return out


def _network_input(v, d: Driveline, key: str, src: str) -> None:
    if not isinstance(v, str) or v not in d.inputs:
        raise ParameterError(f"{src}: {key} = {v!r}: expected a network input ([input.NAME]: "
                             f"{', '.join(d.inputs) or 'none'})")


def _amt_gear(spec, d: Driveline, where: str, src: str) -> tuple:
    """An AMT's gear of a ``[tcu]`` table: ``(synchronizer, fork, side, ratio)``."""
    synchros = {e.name for e in d.elements if e.kind == "synchronizer"}
    if not isinstance(spec, dict) or any(f not in TCU_GEAR_FIELDS for f in spec) \
            or not {"synchronizer", "fork"} <= set(spec):
        raise ParameterError(f"{src}: {where} must be {{ synchronizer = ..., fork = ..., side = 1 or -1 }}")
    if not isinstance(spec["synchronizer"], str) or spec["synchronizer"] not in synchros:
        raise ParameterError(f"{src}: {where}.synchronizer = {spec['synchronizer']!r}: expected a "
                             f"synchronizer of the network ({', '.join(sorted(synchros)) or 'none'})")
    _network_input(spec["fork"], d, f"{where}.fork", src)
    side = spec.get("side", 1)
    if side not in (1, -1) or isinstance(side, bool):
        raise ParameterError(f"{src}: {where}.side = {side!r}: expected 1 or -1")
    ratio = spec.get("ratio")
    if ratio is not None:
        ratio = _quantity(ratio, "1", f"{where}.ratio", src)
        if ratio == 0.0:
            raise ParameterError(f"{src}: {where}.ratio = {spec['ratio']!r}: expected the gear's ratio "
                                 "(the clutch's driven speed over the output speed), not 0")
    return spec["synchronizer"], spec["fork"], int(side), ratio


def _dct_gear(spec, d: Driveline, where: str, src: str) -> tuple:
    """A dual-clutch transmission's gear of a ``[tcu]`` table: ``(clutch, input, ratio)``."""
    clutches = {e.name for e in d.elements if e.kind == "clutch"}
    if not isinstance(spec, dict) or set(spec) != set(DCT_GEAR_FIELDS):
        raise ParameterError(f"{src}: {where} must be {{ clutch = ..., input = ..., ratio = ... }}")
    if not isinstance(spec["clutch"], str) or spec["clutch"] not in clutches:
        raise ParameterError(f"{src}: {where}.clutch = {spec['clutch']!r}: expected a clutch of the network "
                             f"({', '.join(sorted(clutches)) or 'none'})")
    _network_input(spec["input"], d, f"{where}.input", src)
    ratio = _quantity(spec["ratio"], "1", f"{where}.ratio", src)
    if not ratio > 0.0:
        raise ParameterError(f"{src}: {where}.ratio = {spec['ratio']!r}: expected the gear's ratio (the clutch's "
                             "driven speed over the output speed), > 0")
    return spec["clutch"], spec["input"], ratio


def _shift(table, d: Driveline, src: str):
    """The ``[shift]`` table: the keyword arguments of :func:`clutchlab.driveline.shift.shift_quality` for the shift
    the network makes (names checked against it, quantities in SI), or None without one."""
    from .shift import SHIFT_FIELDS

    if table is None:
        return None
    _check_table(table, "shift", SHIFT_FIELDS, ("offgoing", "oncoming", "output"), src)
    friction, bodies = set(d.friction_names), set(d.inertia_names)
    out = {}
    for k, v in table.items():
        if SHIFT_FIELDS[k] is not None:
            out[k] = _quantity(v, SHIFT_FIELDS[k], f"shift.{k}", src)
            continue
        kinds = friction if k in ("offgoing", "oncoming", "clutch") else bodies
        if not isinstance(v, str) or v not in kinds:
            what = "a friction element" if k in ("offgoing", "oncoming", "clutch") else "an inertia"
            raise ParameterError(f"{src}: shift.{k} = {v!r}: expected the name of {what} of the network "
                                 f"({', '.join(sorted(kinds))})")
        out[k] = v
    return out
