"""A driveline description file whose numeric component parameters can be changed by name.

The FMU of a driveline (:mod:`clutchlab.fmu.driveline`) and the sweep target ``driveline``
(:mod:`clutchlab.sweep.driveline`) both start from a description file (the format of
:mod:`clutchlab.driveline.description`) and change some of its numbers: ``J1.J``, ``J1.w0``,
``clutch1.fn_max``, ``clutch1.mu``.  A parameter is named ``<component>.<field>`` after the file's
``[<kind>.<component>]`` table; its unit is the field's SI unit
(the declarations of :mod:`clutchlab.driveline.components`,
:func:`clutchlab.driveline.description.tables`).  Every scalar field is one: a number or a quantity
string given in the file, or a field the file leaves out whose default is a number (``w0 = 0``,
``mu = 0.5``, a clutch's ``normal = 1``).  Tables (a ``mu`` table) are not parameters; the scalar numbers
of a signal a field is given as (a sine torque's amplitude and frequency, the duration of a ramp of the
normal force) are :attr:`DrivelineDocument.signal_parameters`, ``<component>.<field>.<parameter>``, which a
sweep varies (an FMU keeps the file's profiles).  The start value of a network input (``[input.throttle] start``)
is the parameter ``throttle.start`` of :attr:`DrivelineDocument.input_starts`, in the unit of the fields
that read the input: a sweep holds it through each run; an FMU has it as its FMI input's start instead.

::

    doc = DrivelineDocument.read("examples/driveline_coupled_clutches.toml")
    doc.parameters["clutch1.fn_max"]          # Parameter(name, unit "N", value 20.0, description)
    spec = doc.load({"clutch1.fn_max": 30.0, "J2.J": 2.0})   # a DrivelineFile, checked by the loader

Every variant is read by the one loader, :func:`~clutchlab.driveline.description.parse_driveline`,
so it is checked as the file itself would be; the changed values go in as SI numbers.

A description can name other files, relative to its folder (the fields whose unit is ``"path"``: an
E-clutch's ``parameters``, a wet clutch's ``clutch``, ``bench`` and ``friction``), and an E-clutch
parameter file can name curve files relative to itself (``[eclutch.curves]``, ``folder`` and one entry
per component).  :meth:`DrivelineDocument.referenced_files` lists them all; the FMU copies them into its
resources, the sweep hashes them.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path

from ..component import range_problem
from ..errors import ParameterError
from ..io.files import read_toml
from ..units import to_si
from .description import (NOT_QUANTITIES, SIGNAL_FIELDS, DrivelineFile, field_units, input_units, parse_driveline,
                          tables)

__all__ = ["Parameter", "DrivelineDocument", "ReferencedFile"]


@dataclass(frozen=True)
class Parameter:
    """A numeric parameter of a driveline description.

    Parameters
    ----------
    name : str
        ``<component>.<field>`` (``"clutch1.fn_max"``).
    unit : str
        SI unit in pint notation (``"N"``, ``"kg*m**2"``, ``"rad/s"``, ``"1"``).
    value : float
        Value in the file (or the field's default) [unit].
    description : str
        One line for people (``"fn_max of clutch clutch1"``).
    minimum, maximum : float, optional
        Its physical range (inclusive), from the component's declaration (:class:`clutchlab.component.Field`).
    positive : bool
        It must be > 0.
    """

    name: str
    unit: str
    value: float
    description: str
    minimum: float | None = None
    maximum: float | None = None
    positive: bool = False

    def range_problem(self, value: float) -> str | None:
        """Why ``value`` [SI] lies outside the parameter's range, or None (:func:`clutchlab.component.range_problem`).

        Parameters
        ----------
        value : float
            The value [SI].
        """
        return range_problem(value, self.minimum, self.maximum, self.positive, self.unit)


@dataclass(frozen=True)
class ReferencedFile:
    """A file (or a folder of curve files) that a driveline description makes the loader read.

    Parameters
    ----------
    source : pathlib.Path
        The file that names it: the description, or an E-clutch parameter file.
    key : str
        Where that file names it (``"wet_clutch.clutch.clutch"``, ``"eclutch.curves.diaphragm.file"``).
    value : str
        The name as written, relative to the folder of ``source``.
    path : pathlib.Path
        The file (or folder) it names, resolved.
    role : str
        ``"file"`` (read as it is), ``"eclutch_parameters"`` (an E-clutch parameter file; its own
        references are in ``children``) or ``"curve_folder"`` (a folder of the component curves
        ``<component>.csv``, listed in ``children``).
    children : tuple of ReferencedFile
        The files this one names in turn.
    """

    source: Path
    key: str
    value: str
    path: Path
    role: str = "file"
    children: tuple = ()

    def files(self) -> list:
        """Every file this reference makes the loader read: itself (a folder: its curve files) and its children's."""
        own = [] if self.role == "curve_folder" else [self.path]
        return own + [f for child in self.children for f in child.files()]


def _resolve(base: Path, value, source, key: str, within, folder: bool = False, what: str = "file") -> Path:
    """``base / value`` resolved; a missing file (or folder), or one outside ``within``, raises ParameterError."""
    if not isinstance(value, str) or not value:
        raise ParameterError(f"{source}: {key} = {value!r}: expected a {what} name")
    target = (base / value).resolve()
    root = None if within is None else Path(within).resolve()
    if root is not None and not target.is_relative_to(root):
        raise ParameterError(f"{source}: {key} = {value!r}: names {target}, outside the folder {root} that the "
                             f"description's files must be in")
    if not (target.is_dir() if folder else target.is_file()):
        raise ParameterError(f"{source}: {key} = {value!r}: no such {what} ({target})")
    return target


def _curve_files(path: Path, within) -> tuple:
    """The curve files an E-clutch parameter file names (``[eclutch.curves]``, read as ``ClutchModel.from_toml``
    reads them)."""
    from ..eclutch.models import COMPONENTS

    data = read_toml(path)
    table = data.get("eclutch", data)
    curves = table.get("curves") if isinstance(table, dict) else None
    if not isinstance(curves, dict):
        return ()  # none (the loader names a malformed table)
    out = []
    if "folder" in curves:
        key = "eclutch.curves.folder"
        folder = _resolve(path.parent, curves["folder"], path, key, within, folder=True, what="folder")
        out.append(ReferencedFile(path, key, curves["folder"], folder, "curve_folder", tuple(
            ReferencedFile(path, f"{key} {name}.csv", f"{name}.csv",
                           _resolve(folder, f"{name}.csv", path, f"{key} ({curves['folder']!r}) {name}.csv", within))
            for name in COMPONENTS)))
    for name in COMPONENTS:
        entry = curves.get(name)
        key = f"eclutch.curves.{name}"
        if isinstance(entry, dict) and "file" in entry:
            entry, key = entry["file"], f"{key}.file"
        if entry is not None:
            out.append(ReferencedFile(path, key, entry, _resolve(path.parent, entry, path, key, within)))
    return tuple(out)


def _is_scalar(value) -> bool:
    return isinstance(value, (int, float, str)) and not isinstance(value, bool)


class DrivelineDocument:
    """A parsed driveline description file: its numeric parameters by name, and variants of it.

    Parameters
    ----------
    document : dict
        The parsed TOML (keys starting with ``_`` are ignored, e.g. a sweep scenario's ``_source``).
    source : str
        The file it came from, named in error messages.

    Raises
    ------
    ParameterError
        A component table that is not a table, or a scalar field whose value cannot be converted to its
        unit (naming the file, the key and the value).  The rest is checked by :meth:`load`.
    """

    def __init__(self, document: dict, source: str):
        self.source = str(source)
        self.document = {k: v for k, v in document.items() if not str(k).startswith("_")}
        params, signals = {}, {}
        head = self.document.get("driveline", {})
        translational = isinstance(head, dict) and head.get("domain") == "translational"
        self._tables = tables("translational" if translational else "rotational")
        self._fields = field_units("translational" if translational else "rotational")
        for kind, (_, fields) in self._tables.items():
            table = self.document.get(kind, {})
            if not isinstance(table, dict):
                continue  # the loader names the error
            for component, comp in table.items():
                if not isinstance(comp, dict):
                    continue
                for field, f in fields.items():
                    if not f.is_numeric:
                        continue
                    value = comp.get(field, f.default)
                    if not _is_scalar(value):
                        continue
                    name = f"{component}.{field}"
                    si = to_si(value, f.unit, name=f"{kind}.{name}", source=self.source)
                    params[name] = Parameter(name, f.unit, si, f"{f.description} ({kind.replace('_', ' ')} "
                                                               f"{component})", f.minimum, f.maximum, f.positive)
                for field, (unit, _) in self._fields[kind].items():
                    self._signal_parameters(kind, component, field, unit, comp.get(field), signals)
        self._own_parameters = params
        self._sets = None   # (the parameter sets' fields: read when first asked for, _set_parameters)
        #: the numbers of the profiles the file gives as signals, ``<component>.<field>.<parameter>``: a sine
        #: torque's ``torque.torque.amplitude`` [N m] and ``frequency`` [Hz], an E-clutch's bearing ramp
        #: ``clutch.position.duration`` [s], a wet clutch's force step ``wet.force.height`` [N] (a sweep varies
        #: them; an FMU keeps its profiles)
        self.signal_parameters = {name: par for name, (par, _) in signals.items()}
        self._signals = {name: where for name, (_, where) in signals.items()}
        # the start values of the network inputs, ``<input>.start`` in the unit of the fields reading the input:
        # held through a run by a sweep (an FMU's inputs have their own start values, so they are apart)
        starts = {}
        declared = self.document.get("input", {})
        units = input_units(self.document, self.source) if isinstance(declared, dict) else {}
        for name, spec in (declared.items() if isinstance(declared, dict) else ()):
            if not isinstance(spec, dict) or name not in units or not _is_scalar(spec.get("start", 0.0)):
                continue   # the loader names the error
            pname = f"{name}.start"
            si = to_si(spec.get("start", 0.0), units[name], name=f"input.{name}.start", source=self.source)
            starts[pname] = Parameter(pname, units[name], si, f"start value of input {name}, held through the run")
        self.input_starts = starts

    @property
    def parameters(self) -> dict:
        """The numeric parameters by name: each component's numeric fields (``<component>.<field>``), then the
        numeric fields of the parameter sets its path fields name (``<component>.<set>.<set field>``: a wet
        clutch's ``clutch`` and ``bench``, an EMTC coupling's ``actuator`` and ``coupling``, read from their files,
        or their defaults where the file names none; :func:`~clutchlab.driveline.components.parameter_sets`).  The
        sets' files are read when this is first asked for (after :meth:`referenced_files` checked where they
        are)."""
        if self._sets is None:   # (once: check_names asks for it per name)
            self._sets = self._set_parameters()
            self._all_parameters = {**self._own_parameters,
                                    **{name: par for name, (par, _) in self._sets.items()}}
        return self._all_parameters

    def _set_parameters(self) -> dict:
        """name -> (Parameter, (kind, component, set, set field)) of the parameter sets' numeric fields."""
        from ..params.base import field_range, model_fields
        from .components import parameter_sets

        out = {}
        base = Path(self.source).parent
        for kind in self._tables:
            table = self.document.get(kind, {})
            sets = parameter_sets(kind) if isinstance(table, dict) else ()
            for component, comp in (table.items() if sets else ()):
                if not isinstance(comp, dict):
                    continue
                for src in sets:
                    value = comp.get(src.field)
                    if value is None:
                        instance = src.default()
                    elif isinstance(value, str) and value:
                        instance = src.read(_resolve(base, value, self.source, f"{kind}.{component}.{src.field}",
                                                     None))
                    else:
                        continue   # (the loader names the error)
                    for f in model_fields(src.cls):
                        v = getattr(instance, f.name)
                        if (f.name in src.unread or isinstance(v, bool)
                                or not isinstance(v, (int, float))):
                            continue
                        name = f"{component}.{src.name}.{f.name}"
                        lo, hi, positive = field_range(f.metadata)
                        out[name] = (Parameter(name, f.metadata["unit"], float(v),
                                               f"{f.metadata.get('doc', f.name)} ({kind.replace('_', ' ')} "
                                               f"{component}, its {src.name})", lo, hi, positive),
                                     (kind, component, src.name, f.name))
        return out

    def _signal_parameters(self, kind, component, field, unit, value, out) -> None:
        """The scalar parameters of a signal the file gives field ``field`` of ``[kind.component]`` (a one-entry
        table ``{ sine = { ... } }``), into ``out``: name -> (Parameter, (kind, component, field, signal kind,
        parameter)).  Lists (a table's times), whole numbers (a pulse's ``nperiod``) and nested signals (a
        product, an input) are not parameters."""
        if not (isinstance(value, dict) and len(value) == 1):
            return
        (sig, spec), = value.items()
        fields = SIGNAL_FIELDS.get(sig)
        if not fields or not isinstance(spec, dict) or unit is None or unit in NOT_QUANTITIES:
            return
        if sig == "table":   # a profile as a whole: stretched in time, scaled in value
            for param, what in (("time_scale", "times"), ("value_scale", "values")):
                name = f"{component}.{field}.{param}"
                out[name] = (Parameter(name, "1", 1.0, f"factor on the {what} of the table of {field} of "
                                                       f"{kind.replace('_', ' ')} {component}"),
                             (kind, component, field, sig, param))
            return
        for param, punit in fields.items():
            if param not in spec or punit == "int" or not _is_scalar(spec[param]):
                continue
            u = unit if punit == "value" else punit
            name = f"{component}.{field}.{param}"
            si = to_si(spec[param], u, name=f"{kind}.{name}", source=self.source)
            out[name] = (Parameter(name, u, si, f"{param} of the {sig} of {field} of {kind.replace('_', ' ')} "
                                                f"{component}"), (kind, component, field, sig, param))

    @classmethod
    def read(cls, path) -> "DrivelineDocument":
        """The description file at ``path`` (TOML; errors name the file).

        Parameters
        ----------
        path : str or Path
            The driveline description.
        """
        return cls(read_toml(path), str(path))

    def referenced_files(self, within=None) -> list:
        """Every file the description names, relative to its folder, and the files those name in turn.

        The fields whose unit is ``"path"`` (:func:`~clutchlab.driveline.description.tables`): an
        E-clutch's ``parameters`` (with the curve files of its ``[eclutch.curves]`` table, relative to
        the parameter file) and a wet clutch's ``clutch``, ``bench`` and ``friction``.

        Parameters
        ----------
        within : str or Path, optional
            A folder every named file must be in (the FMU's ``resources``): a name that leads out of it
            (``..``, an absolute path, a link) is refused.

        Returns
        -------
        list of ReferencedFile
            In the order of the description; the description's own references at the top level.

        Raises
        ------
        ParameterError
            A named file that does not exist (or lies outside ``within``), naming the file that names
            it, the key and the value.
        """
        base = Path(self.source).parent
        out = []
        for kind, fields in self._fields.items():
            table = self.document.get(kind, {})
            if not isinstance(table, dict):
                continue
            for component, comp in table.items():
                if not isinstance(comp, dict):
                    continue
                for field, (unit, _) in fields.items():
                    if unit != "path" or field not in comp:
                        continue
                    key, value = f"{kind}.{component}.{field}", comp[field]
                    path = _resolve(base, value, self.source, key, within)
                    if kind == "eclutch":
                        try:
                            children = _curve_files(path, within)
                        except ParameterError as exc:
                            raise ParameterError(f"{self.source}: {key} = {value!r}: {exc}") from None
                        out.append(ReferencedFile(Path(self.source), key, value, path, "eclutch_parameters", children))
                    else:
                        out.append(ReferencedFile(Path(self.source), key, value, path))
        return out

    def check_names(self, names) -> None:
        """Raise :class:`ParameterError` for the first of ``names`` that is not a parameter of this file.

        Parameters
        ----------
        names : iterable of str
            Parameter names (``"clutch1.fn_max"``, or an input's ``"throttle.start"``).
        """
        for name in names:
            if name not in self.parameters and name not in self.input_starts and name not in self.signal_parameters:
                close = difflib.get_close_matches(str(name), [*self.parameters, *self.input_starts,
                                                              *self.signal_parameters], n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ParameterError(
                    f"{self.source}: {name!r} is not a numeric parameter of this driveline (parameters are "
                    f"<component>.<field> with a number, e.g. {', '.join(list(self.parameters)[:4])}, or "
                    f"<input>.start, or <component>.<field>.<parameter> of a signal){hint}")

    def load(self, changes: dict | None = None) -> DrivelineFile:
        """The driveline of this file with some parameters changed, read by ``load_driveline``.

        Parameters
        ----------
        changes : dict, optional
            ``{parameter name: value in its SI unit}``: component fields (:attr:`parameters`) and input starts
            (:attr:`input_starts`).

        Returns
        -------
        DrivelineFile

        Raises
        ------
        ParameterError
            An unknown parameter name, or a value the loader refuses (a negative inertia): the message
            names the file, the changed values and the key.
        """
        changes = dict(changes or {})
        self.check_names(changes)
        doc = {k: (dict(v) if isinstance(v, dict) else v) for k, v in self.document.items()}
        set_changes = {}
        for name, value in changes.items():
            if self._sets and name in self._sets:   # (a field of a parameter set a component's file names)
                kind, component, which, set_field = self._sets[name][1]
                set_changes.setdefault((kind, component), {}).setdefault(which, {})[set_field] = float(value)
                continue
            if name in self._signals:
                kind, component, field, sig, param = self._signals[name]
                comp = doc[kind][component]
                spec = dict(comp[field][sig])   # (a second change of one signal reads the copy the first one made)
                if sig == "table":
                    what = "times" if param == "time_scale" else "values"
                    unit = "s" if what == "times" else self._fields[kind][field][0]
                    spec[what] = [float(value) * to_si(v, unit, name=f"{kind}.{component}.{field}.table.{what}",
                                                       source=self.source) for v in spec.get(what, [])]
                else:
                    spec[param] = float(value)
                doc[kind] = {**doc[kind], component: {**comp, field: {sig: spec}}}
                continue
            component, field = name.rsplit(".", 1)
            if name in self.input_starts:
                doc["input"] = {**doc["input"], component: {**doc["input"][component], field: float(value)}}
                continue
            kind = next(k for k, table in doc.items() if k in self._fields and isinstance(table, dict)
                        and component in table)
            doc[kind] = {**doc[kind], component: {**doc[kind][component], field: float(value)}}
        return _load_document(doc, self.source, changes, set_changes)


def _load_document(doc: dict, source: str, changes: dict, set_changes: dict | None = None) -> DrivelineFile:
    """:func:`~clutchlab.driveline.description.parse_driveline` of a changed document; its errors name
    ``source`` and the changes."""
    what = ", ".join(f"{k} = {float(v)!r}" for k, v in changes.items())
    return parse_driveline(doc, f"{source} with {what}" if what else source, Path(source).parent, set_changes)
