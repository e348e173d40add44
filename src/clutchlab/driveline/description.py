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

Component tables: ``inertia`` (J, w0, phi0), ``spring_damper`` (a, b, c, d, phi_rel0), ``torque``
(flange, torque, support), ``clutch`` (a, b, fn_max, mu, peak, cgeo, normal), ``brake`` (flange,
fn_max, mu, peak, cgeo, normal, support) and ``bearing_friction`` (flange, torque, peak, support).
Quantities are numbers in SI or strings with units, converted once here.  A signal is a number or
quantity (a constant) or one of ``{ constant = v }``, ``{ step = { height, start, offset } }``,
``{ ramp = { height, duration, start, offset } }``, ``{ sine = { amplitude, frequency, phase, offset,
start } }``, ``{ table = { times = [...], values = [...] } }`` (times in s, values in the signal's unit).
A friction characteristic (``mu``, a bearing's ``torque``) is a number or a table of rows
``[w_rad_s, value]``.  Every error names the file, the key and the value.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import ParameterError
from ..io.files import read_toml
from ..units import to_si
from .network import Driveline, Signal

__all__ = ["load_driveline", "DrivelineFile"]

#: component tables and their fields: field -> (unit, required); "flange"/"a"/"b"/"support" are names
FIELDS = {
    "inertia": {"J": ("kg*m**2", True), "w0": ("rad/s", False), "phi0": ("rad", False)},
    "spring_damper": {"a": (None, True), "b": (None, True), "c": ("N*m/rad", False), "d": ("N*m*s/rad", False),
                      "phi_rel0": ("rad", False)},
    "torque": {"flange": (None, True), "torque": ("N*m", True), "support": (None, False)},
    "clutch": {"a": (None, True), "b": (None, True), "fn_max": ("N", True), "mu": ("1", False),
               "peak": ("1", False), "cgeo": ("1", False), "normal": ("1", False)},
    "brake": {"flange": (None, True), "fn_max": ("N", True), "mu": ("1", False), "peak": ("1", False),
              "cgeo": ("1", False), "normal": ("1", False), "support": (None, False)},
    "bearing_friction": {"flange": (None, True), "torque": ("N*m", False), "peak": ("1", False),
                         "support": (None, False)},
}
SIGNAL_FIELDS = {
    "constant": None,
    "step": {"height": "value", "start": "s", "offset": "value"},
    "ramp": {"height": "value", "duration": "s", "start": "s", "offset": "value"},
    "sine": {"amplitude": "value", "frequency": "Hz", "phase": "rad", "offset": "value", "start": "s"},
    "table": {"times": "s", "values": "value"},
}
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
    """

    driveline: Driveline
    t_end: float | None = None
    output_step: float | None = None
    rtol: float = 1e-8
    max_step: float | None = None


def _quantity(value, unit, key, src):
    return to_si(value, unit, name=key, source=src)


def _signal(value, unit, key, src) -> Signal:
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
        else:
            args[f] = _quantity(v, u, f"{key}.{kind}.{f}", src)
    try:
        if kind == "table":
            return Signal.table(args.get("times", []), args.get("values", []))
        if kind == "ramp" and "duration" not in args:
            raise ParameterError("ramp needs a duration")
        if kind == "sine" and not {"amplitude", "frequency"} <= set(args):
            raise ParameterError("sine needs an amplitude and a frequency")
        return getattr(Signal, kind)(**args)
    except ParameterError as exc:
        raise ParameterError(f"{src}: {key}: {exc}") from None


def _characteristic(value, unit, key, src):
    if isinstance(value, list):
        rows = []
        for i, row in enumerate(value):
            if not (isinstance(row, list) and len(row) == 2):
                raise ParameterError(f"{src}: {key}[{i}] = {row!r}: expected a row [w_rad_s, value]")
            rows.append([_quantity(row[0], "rad/s", f"{key}[{i}][0]", src), _quantity(row[1], unit, f"{key}[{i}][1]", src)])
        return rows
    return _quantity(value, unit, key, src)


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
    src = str(path)
    doc = read_toml(path)
    known = {"driveline", "simulation", *FIELDS}
    for top in doc:
        if top not in known:
            raise ParameterError(f"{src}: unknown table [{top}] (known: {', '.join(sorted(known))})")
    head = doc.get("driveline", {})
    if not isinstance(head, dict) or any(k != "name" for k in head):
        raise ParameterError(f"{src}: [driveline] takes only name = \"...\"")
    d = Driveline(str(head.get("name", "driveline")))
    sim = doc.get("simulation", {})
    if not isinstance(sim, dict):
        raise ParameterError(f"{src}: [simulation] must be a table")
    for k in sim:
        if k not in SIMULATION_FIELDS:
            raise ParameterError(f"{src}: [simulation] {k}: unknown field (known: {', '.join(SIMULATION_FIELDS)})")
    settings = {k: _quantity(v, SIMULATION_FIELDS[k], f"simulation.{k}", src) for k, v in sim.items()}
    # inertias first: the elements name them
    order = ["inertia"] + [k for k in doc if k in FIELDS and k != "inertia"]
    for kind in order:
        table = doc.get(kind, {})
        if not isinstance(table, dict):
            raise ParameterError(f"{src}: [{kind}] must hold named components ([{kind}.NAME])")
        for name, comp in table.items():
            key = f"{kind}.{name}"
            if not isinstance(comp, dict):
                raise ParameterError(f"{src}: {key} = {comp!r}: expected a table [{key}]")
            fields = FIELDS[kind]
            for f in comp:
                if f not in fields:
                    raise ParameterError(f"{src}: {key}.{f}: unknown field (known: {', '.join(fields)})")
            missing = [f for f, (_, req) in fields.items() if req and f not in comp]
            if missing:
                raise ParameterError(f"{src}: {key}: missing field {missing[0]!r}")
            args = {}
            for f, v in comp.items():
                unit = fields[f][0]
                fkey = f"{key}.{f}"
                if unit is None:
                    if not isinstance(v, str):
                        raise ParameterError(f"{src}: {fkey} = {v!r}: expected the name of an inertia or \"ground\"")
                    args[f] = v
                elif f in ("torque", "normal") and kind != "bearing_friction":
                    args[f] = _signal(v, unit, fkey, src)
                elif f in ("mu",) or (kind == "bearing_friction" and f == "torque"):
                    args[f] = _characteristic(v, unit, fkey, src)
                else:
                    args[f] = _quantity(v, unit, fkey, src)
            try:
                if kind == "inertia":
                    d.inertia(name, **args)
                elif kind == "spring_damper":
                    d.spring_damper(name, **args)
                elif kind == "torque":
                    d.torque(name, args.pop("flange"), args.pop("torque"), **args)
                elif kind == "clutch":
                    d.clutch(name, **args)
                elif kind == "brake":
                    d.brake(name, **args)
                else:
                    d.bearing_friction(name, **args)
            except ParameterError as exc:
                raise ParameterError(f"{src}: [{key}] {exc}") from None
    if not d._inertias:
        raise ParameterError(f"{src}: no [inertia.NAME] table (a driveline needs at least one inertia)")
    return DrivelineFile(d, settings.get("t_end"), settings.get("output_step"), settings.get("rtol", 1e-8),
                         settings.get("max_step"))
