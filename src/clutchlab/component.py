"""Components declared once, as data: the component contract of networks.

A component kind -- an inertia, a clutch, a gear, a wet clutch, a cone clutch of your own -- is declared
once, as a :class:`Component`: its table name in a network file, one line for people, its fields
(:class:`Field`: ports and parameters, each with its kind, SI unit, whether it is required, its default,
its physical range, a description and a source) and the function that builds it into a network from
those fields.  Everything else is generated from the declaration:

- the keys of a network file's ``[<kind>.<name>]`` table, their units, the conversion of quantities with
  units (``"83 mm"``), required fields, choices, and the range check of every number, with errors naming
  the file, the key, the value and the range (:mod:`clutchlab.driveline.description`);
- the parameters a sweep varies and an FMU exposes, ``<component>.<field>`` with unit, default, range
  and description (:class:`clutchlab.driveline.variants.DrivelineDocument`; an FMU writes the range as
  the variable's ``min`` and ``max``);
- the docs' tables of components (:func:`component_table`, docs/components.md) and
  ``clutchlab driveline components``.

A component is registered with :func:`register_component` (in the module that declares it), or, for a
component in a package of its own, through the entry-point group ``clutchlab.components``
(:data:`ENTRY_POINT_GROUP`; its object is the :class:`Component`)::

    [project.entry-points."clutchlab.components"]
    cone_clutch = "my_package.cone:CONE_CLUTCH"

An entry point names code installed with a package, never a file a user reads in: a network file names
component kinds, and only registered kinds are known.  The entry points are read once, when a kind is
first looked up (so an FMU's host, which runs a Python of its own, finds the same components as the
exporting machine if the package is installed there).

This module is the contract's layer: it imports only the foundation.  The network that builds components
(:mod:`clutchlab.driveline`) sits above it and registers the built-in kinds when it is imported
(:mod:`clutchlab.driveline.components`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

from .errors import ParameterError

__all__ = ["Field", "Component", "FIELD_KINDS", "ENTRY_POINT_GROUP", "register_component", "component",
           "components", "component_table", "check_range", "unregister_component", "component_sources",
           "load_component_sources", "range_problem", "range_text"]

#: what a field holds; "flange" fields are the component's ports (the name of a body, or "ground")
FIELD_KINDS = {
    "flange": "the name of a body (an inertia or mass) or \"ground\": a port of the component",
    "quantity": "a number in SI or a string with units (\"83 mm\")",
    "signal": "a quantity, or a signal table ({ ramp = {...} }, { input = \"NAME\" }, ...) in the field's unit",
    "characteristic": "a number, or a table of rows [w, value] over the relative speed",
    "curve": "a table of rows [angle, value]",
    "choice": "one of the field's words",
    "bool": "true or false",
    "int": "a whole number",
    "path": "a file, relative to the network file",
    "map": "a table of its own format (the field's description)",
    "losstable": "rows [|w_a|, eta_mf1, eta_mf2, tau_bf1, tau_bf2] (MSL lossTable)",
    "rows": "a table of rows, one number or quantity per column; the field's unit gives the columns' units, "
            "separated by \"|\" (\"1 | rad/s/(N*m)**0.5 | 1\")",
    "thermal": "the name of a thermal mass ([thermal_mass.NAME]): a heat port of the component",
    "names": "a list of the names of other components of the network",
    "temperature_table": "a table of rows [T, value] over a temperature (T in degC or with its unit)",
}
#: the field kinds whose value can be a plain number: the parameters of a file (sweeps, FMUs)
NUMERIC_KINDS = ("quantity", "signal", "characteristic")
#: the entry-point group a package registers its components in
ENTRY_POINT_GROUP = "clutchlab.components"


@dataclasses.dataclass(frozen=True)
class Field:
    """One field of a component: a port or a parameter.

    Parameters
    ----------
    name : str
        Key in the component's table (``"fn_max"``) and the last part of its parameter name
        (``clutch1.fn_max``).
    kind : str
        One of :data:`FIELD_KINDS`.
    unit : str
        SI unit in pint notation of a number (``"N"``, ``"kg*m**2"``, ``"rad/s"``, ``"degC"``, ``"1"``);
        for a signal or characteristic, the unit of its values; for ``"rows"``, each column's, separated by
        ``"|"``.  Ignored by the other kinds.
    required : bool
        The table must give it.
    default : float, str, bool or None
        The value the component takes when the file leaves the field out (SI); ``None``: none, or one the
        component works out (a body's initial speed: from its gears and sources).  A number default makes a
        field left out a parameter with that start value.
    minimum, maximum : float, optional
        Physical range (inclusive, SI): a value outside it is refused where it is read (a file, a sweep, an
        FMU's start value), naming the field, the value and the range.
    positive : bool
        The value must be > 0 (a strict lower bound; with ``minimum`` both apply).
    description : str
        One line for people.
    source : str
        Where the default or the range comes from (a paper's table, MSL, reasoning).
    choices : tuple of str
        The words a ``"choice"`` field takes.
    """

    name: str
    kind: str = "quantity"
    unit: str = "1"
    required: bool = False
    default: Any = None
    minimum: float | None = None
    maximum: float | None = None
    positive: bool = False
    description: str = ""
    source: str = ""
    choices: tuple = ()

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ParameterError(f"Field.name = {self.name!r}: expected a name (letters, digits, _)")
        if self.kind not in FIELD_KINDS:
            raise ParameterError(f"field {self.name}: kind = {self.kind!r}: expected one of {', '.join(FIELD_KINDS)}")
        if self.kind == "choice" and not self.choices:
            raise ParameterError(f"field {self.name}: a choice needs its words (choices = (...))")
        for what in ("minimum", "maximum"):
            v = getattr(self, what)
            if v is not None and not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)):
                raise ParameterError(f"field {self.name}: {what} = {v!r}: expected a finite number")
        if self.minimum is not None and self.maximum is not None and self.minimum > self.maximum:
            raise ParameterError(f"field {self.name}: minimum {self.minimum!r} > maximum {self.maximum!r}")
        if self.default is not None and (self.is_numeric or self.kind == "int") \
                and isinstance(self.default, (int, float)) and not isinstance(self.default, bool):
            problem = self.range_problem(float(self.default))
            if problem:
                raise ParameterError(f"field {self.name}: default {self.default!r} {problem}")

    @property
    def is_port(self) -> bool:
        """The field names a body the component connects to."""
        return self.kind == "flange"

    @property
    def is_numeric(self) -> bool:
        """The field can hold a plain number (a parameter of the file when it does)."""
        return self.kind in NUMERIC_KINDS

    def range_problem(self, value: float) -> str | None:
        """Why ``value`` (SI) is outside the field's range, or None."""
        return range_problem(value, self.minimum, self.maximum, self.positive,
                             self.unit if self.is_numeric else "1")

    def range_text(self) -> str:
        """The range as people read it: ``[0, 2]``, ``> 0 N``, ``>= 1``, ``any``."""
        return range_text(self.minimum, self.maximum, self.positive, self.unit if self.is_numeric else "1")


def range_text(minimum=None, maximum=None, positive: bool = False, unit: str = "1") -> str:
    """A range as people read it: ``[0, 2]``, ``(0, 1]``, ``> 0 N``, ``>= -273.15 degC``, ``any``.

    Parameters
    ----------
    minimum, maximum : float, optional
        Inclusive bounds [``unit``].
    positive : bool
        A strict lower bound of 0.
    unit : str
        Unit shown after the range (none for ``"1"``).
    """
    u = f" {unit}" if unit and unit != "1" else ""
    open_zero = positive and (minimum is None or minimum <= 0.0)
    if open_zero or minimum is not None:
        low = "(0" if open_zero else f"[{minimum:g}"
        if maximum is not None:
            return f"{low}, {maximum:g}]{u}"
        return f"> 0{u}" if open_zero else f">= {minimum:g}{u}"
    if maximum is not None:
        return f"<= {maximum:g}{u}"
    return "any"


def range_problem(value: float, minimum=None, maximum=None, positive: bool = False, unit: str = "1") -> str | None:
    """Why ``value`` lies outside a range (:func:`range_text`), or None: the one check of a component's field, a
    file's parameter and an FMU's parameter.

    Parameters
    ----------
    value : float
        The value [``unit``].
    minimum, maximum : float, optional
        Inclusive bounds.
    positive : bool
        A strict lower bound of 0.
    unit : str
        Its unit, named in the message.
    """
    if not math.isfinite(value):
        return "is not finite"
    if positive and not value > 0.0:
        return f"must be > 0 [{unit}]"
    if minimum is not None and value < minimum:
        return f"is below its range {range_text(minimum, maximum, positive, unit)}"
    if maximum is not None and value > maximum:
        return f"is above its range {range_text(minimum, maximum, positive, unit)}"
    return None


def check_range(field: Field, value: float, where: str) -> float:
    """``value`` if it lies in ``field``'s range, else :class:`ParameterError` naming ``where``, the value and
    the range.

    Parameters
    ----------
    field : Field
        The declaration.
    value : float
        The value [SI].
    where : str
        What to name in the error (the file and key).
    """
    problem = field.range_problem(float(value))
    if problem:
        raise ParameterError(f"{where} = {value!r}: {problem}")
    return value


@dataclasses.dataclass(frozen=True)
class Component:
    """A component kind declared once.

    Parameters
    ----------
    kind : str
        Its table in a network file (``[cone_clutch.c1]``) and its name in the registry.
    description : str
        One line for people (what it is, its law, its reference).
    fields : tuple of Field
        Its ports and parameters, in the order they are documented.
    build : callable
        ``build(network, name, **fields)``: adds the component to a network (a
        :class:`~clutchlab.driveline.Driveline`) from the fields the file gives, converted to SI (a flange as
        its name, a signal as a :class:`~clutchlab.driveline.Signal`, a characteristic as a number or rows
        ``[[w, value], ...]``, a path as an absolute ``Path``).  It raises :class:`ParameterError` for values
        the declaration cannot check alone.
    source : str
        The reference of its law (a paper and equation, an MSL class).
    domains : tuple of str
        The network domains it exists in: ``("rotational",)`` or ``("rotational", "translational")`` (then
        its units are those of a translational network there: N for N*m, m/s for rad/s).
    translational : tuple, optional
        ``(table name, {field: field name})`` of its form in a translational network when they differ
        (an inertia is a ``mass`` with ``m``, ``v0``, ``s0``).
    """

    kind: str
    description: str
    fields: tuple
    build: Callable
    source: str = ""
    domains: tuple = ("rotational",)
    translational: tuple | None = None

    def __post_init__(self):
        if not isinstance(self.kind, str) or not self.kind.isidentifier():
            raise ParameterError(f"Component.kind = {self.kind!r}: expected a name (letters, digits, _)")
        object.__setattr__(self, "fields", tuple(self.fields))
        names = [f.name for f in self.fields]
        for f in self.fields:
            if not isinstance(f, Field):
                raise ParameterError(f"component {self.kind}: {f!r} is not a Field")
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ParameterError(f"component {self.kind}: field {twice[0]!r} is declared twice")
        if not callable(self.build):
            raise ParameterError(f"component {self.kind}: build = {self.build!r} is not callable")
        for d in self.domains:
            if d not in ("rotational", "translational"):
                raise ParameterError(f"component {self.kind}: domain {d!r}: expected rotational or translational")

    def field(self, name: str) -> Field:
        """The field called ``name``."""
        for f in self.fields:
            if f.name == name:
                return f
        raise ParameterError(f"component {self.kind}: no field {name!r} (fields: "
                             f"{', '.join(f.name for f in self.fields)})")

    @property
    def ports(self) -> tuple:
        """Its flange fields."""
        return tuple(f for f in self.fields if f.is_port)

    @property
    def parameters(self) -> tuple:
        """Its fields that hold numbers (the parameters a file gives or defaults)."""
        return tuple(f for f in self.fields if f.is_numeric)


#: table names of a network file that are not components
RESERVED = ("driveline", "simulation", "input")

_REGISTRY: dict[str, Component] = {}
_ENTRY_POINTS_READ = False


def register_component(comp: Component, *, replace: bool = False) -> Component:
    """Register ``comp`` under its kind (the table name of network files).

    Parameters
    ----------
    comp : Component
        The declaration.
    replace : bool
        Replace a component of that kind already registered (default: refuse, naming it).

    Returns
    -------
    Component
        ``comp`` (so a module can write ``CONE = register_component(Component(...))``).
    """
    if not isinstance(comp, Component):
        raise ParameterError(f"register_component({comp!r}): expected a Component")
    names = {comp.kind, *((comp.translational[0],) if comp.translational else ())}
    taken = {c.translational[0]: c.kind for c in _REGISTRY.values() if c.translational and c is not comp}
    for name in sorted(names):
        if name in RESERVED:
            raise ParameterError(f"component kind {name!r}: a table of every network file ({', '.join(RESERVED)})")
        if name in taken and not replace:
            raise ParameterError(f"component kind {name!r} is the translational form of {taken[name]!r}")
    old = _REGISTRY.get(comp.kind)
    if old is not None and old is not comp and not replace:
        raise ParameterError(f"component kind {comp.kind!r} is registered already (by "
                             f"{getattr(old.build, '__module__', '?')}); pass replace=True to replace it")
    _REGISTRY[comp.kind] = comp
    return comp


def unregister_component(kind: str) -> Component | None:
    """Remove the component registered as ``kind`` (a notebook redefining one, a test cleaning up); the
    removed declaration, or None."""
    return _REGISTRY.pop(kind, None)


def _read_entry_points() -> None:
    global _ENTRY_POINTS_READ
    if _ENTRY_POINTS_READ:
        return
    _ENTRY_POINTS_READ = True
    from importlib.metadata import entry_points

    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            comp = ep.load()
        except Exception as exc:  # noqa: BLE001 -- a broken plug-in names itself, it does not stop the others
            raise ParameterError(f"component entry point {ep.name} = {ep.value!r} ({ENTRY_POINT_GROUP}) does not "
                                 f"load: {type(exc).__name__}: {exc}") from None
        if callable(comp) and not isinstance(comp, Component):
            comp = comp()
        if not isinstance(comp, Component):
            raise ParameterError(f"component entry point {ep.name} = {ep.value!r} is a {type(comp).__name__}, "
                                 "not a clutchlab.component.Component")
        if _REGISTRY.get(comp.kind) is not comp:
            register_component(comp)


def components(domain: str | None = None) -> dict:
    """Every registered component, ``{kind: Component}`` (the built-in ones once :mod:`clutchlab.driveline` is
    imported, those registered since, and those of the entry-point group :data:`ENTRY_POINT_GROUP`), in
    registration order.

    Parameters
    ----------
    domain : {"rotational", "translational"}, optional
        Only those that exist in this domain.
    """
    _read_entry_points()
    return {k: c for k, c in _REGISTRY.items() if domain is None or domain in c.domains}


def component(kind: str) -> Component:
    """The component registered as ``kind``; :class:`ParameterError` with the known kinds otherwise."""
    known = components()
    if kind not in known:
        import difflib

        close = [k for k in known if k.startswith(str(kind))] or difflib.get_close_matches(str(kind), list(known),
                                                                                              n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ParameterError(f"unknown component kind {kind!r} (known: {', '.join(known)}){hint}")
    return known[kind]


def component_sources() -> tuple:
    """Where the registered components are declared, ``((module, attribute or None), ...)``: the module of each
    one's ``build`` function and the module attribute that holds the declaration (None: importing the module
    registers it).  A script run as ``__main__`` is left out.  What a worker process loads to know the same
    components as its parent (:func:`load_component_sources`; a sweep's worker processes)."""
    import sys

    out = []
    for comp in _REGISTRY.values():
        module = getattr(comp.build, "__module__", None)
        if not module or module == "__main__":
            continue
        attr = next((k for k, v in vars(sys.modules[module]).items() if v is comp), None) \
            if module in sys.modules else None
        if (module, attr) not in out:
            out.append((module, attr))
    return tuple(out)


def load_component_sources(sources) -> None:
    """Import the modules of :func:`component_sources` (of a parent process) and register the declarations
    they hold.

    Parameters
    ----------
    sources : iterable of (str, str or None)
        ``(module, attribute)`` pairs from the parent's registry, never from a file.
    """
    import importlib

    for module, attr in sources:
        mod = importlib.import_module(module)
        if attr is not None:
            comp = getattr(mod, attr)
            if _REGISTRY.get(comp.kind) is not comp:
                register_component(comp, replace=True)


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _default_text(f: Field) -> str:
    if f.required:
        return "required"
    if f.default is None:
        return "-"
    if isinstance(f.default, bool):
        return "true" if f.default else "false"
    if isinstance(f.default, float):
        return f"{f.default:g}"
    return str(f.default)


def _unit_text(f: Field) -> str:
    if f.kind in ("quantity", "signal", "characteristic", "curve", "rows"):
        return f.unit
    if f.kind == "choice":
        return " / ".join(f.choices)
    return "-"


def component_table(kind: str) -> str:
    """The Markdown table of a component's fields: field, kind, unit, default, range, description (the
    docs' tables and ``clutchlab driveline components KIND`` print it)."""
    comp = component(kind)
    lines = [f"### `{comp.kind}`", "", comp.description + (f" ({comp.source})" if comp.source else ""), "",
             "| field | kind | unit | default | range | description |", "| --- | --- | --- | --- | --- | --- |"]
    for f in comp.fields:
        desc = f.description + (f" Source: {f.source}." if f.source else "")
        rng = f.range_text() if f.is_numeric else "-"
        lines.append(f"| `{f.name}` | {f.kind} | {_cell(_unit_text(f))} | {_cell(_default_text(f))} | "
                     f"{_cell(rng)} | {_cell(desc)} |")
    return "\n".join(lines) + "\n"
