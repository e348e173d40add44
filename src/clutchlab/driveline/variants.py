"""A driveline description file whose numeric component parameters can be changed by name.

The FMU of a driveline (:mod:`clutchlab.driveline.cosim`) and the sweep target ``driveline``
(:mod:`clutchlab.driveline.sweep`) both start from a description file (the format of
:mod:`clutchlab.driveline.description`) and change some of its numbers: ``J1.J``, ``J1.w0``,
``clutch1.fn_max``, ``clutch1.mu``.  A parameter is named ``<component>.<field>`` after the file's
``[<kind>.<component>]`` table; its unit is the field's SI unit
(:data:`clutchlab.driveline.description.FIELDS`).  Every scalar field is one: a number or a quantity
string given in the file, or a field the file leaves out whose default is a number (``w0 = 0``,
``mu = 0.5``, a clutch's ``normal = 1``).  Tables (a ``mu`` table) and signals (a sine torque, a step
of the normal force) are not parameters.

::

    doc = DrivelineDocument.read("examples/driveline_coupled_clutches.toml")
    doc.parameters["clutch1.fn_max"]          # Parameter(name, unit "N", value 20.0, description)
    spec = doc.load({"clutch1.fn_max": 30.0, "J2.J": 2.0})   # a DrivelineFile, checked by the loader

Every variant is read by the one loader, :func:`~clutchlab.driveline.description.parse_driveline`,
so it is checked as the file itself would be; the changed values go in as SI numbers.
"""

from __future__ import annotations

import difflib
import inspect
from dataclasses import dataclass
from pathlib import Path

from ..errors import ParameterError
from ..io.files import read_toml
from ..units import to_si
from .description import FIELDS, NOT_QUANTITIES, TRANSLATIONAL_FIELDS, DrivelineFile, parse_driveline
from .network import Driveline

__all__ = ["Parameter", "DrivelineDocument"]


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
    """

    name: str
    unit: str
    value: float
    description: str


def _is_scalar(value) -> bool:
    return isinstance(value, (int, float, str)) and not isinstance(value, bool)


def _defaults(kind: str) -> dict:
    """Number defaults of the fields of ``kind`` (the keyword defaults of the ``Driveline`` method of that name)."""
    method = getattr(Driveline, kind, None)
    if method is None:
        return {}
    out = {p.name: p.default for p in inspect.signature(method).parameters.values()
           if isinstance(p.default, (int, float)) and not isinstance(p.default, bool)}
    # a body's initial speed and angle left out follow from its gears and sources, else rest: 0 to vary from
    out.update({p.name: 0.0 for p in inspect.signature(method).parameters.values()
                if p.default is None and p.name in ("w0", "phi0", "v0", "s0")})
    return out


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
        params = {}
        head = self.document.get("driveline", {})
        translational = isinstance(head, dict) and head.get("domain") == "translational"
        self._fields = TRANSLATIONAL_FIELDS if translational else FIELDS
        for kind, fields in self._fields.items():
            table = self.document.get(kind, {})
            if not isinstance(table, dict):
                continue  # the loader names the error
            defaults = _defaults(kind)
            for component, comp in table.items():
                if not isinstance(comp, dict):
                    continue
                for field, (unit, _) in fields.items():
                    if unit is None or unit in NOT_QUANTITIES:
                        continue
                    value = comp.get(field, defaults.get(field))
                    if not _is_scalar(value):
                        continue
                    name = f"{component}.{field}"
                    si = to_si(value, unit, name=f"{kind}.{name}", source=self.source)
                    params[name] = Parameter(name, unit, si, f"{field} of {kind.replace('_', ' ')} {component}")
        self.parameters = params

    @classmethod
    def read(cls, path) -> "DrivelineDocument":
        """The description file at ``path`` (TOML; errors name the file).

        Parameters
        ----------
        path : str or Path
            The driveline description.
        """
        return cls(read_toml(path), str(path))

    def check_names(self, names) -> None:
        """Raise :class:`ParameterError` for the first of ``names`` that is not a parameter of this file.

        Parameters
        ----------
        names : iterable of str
            Parameter names (``"clutch1.fn_max"``).
        """
        for name in names:
            if name not in self.parameters:
                close = difflib.get_close_matches(str(name), list(self.parameters), n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ParameterError(
                    f"{self.source}: {name!r} is not a numeric parameter of this driveline (parameters are "
                    f"<component>.<field> with a number, e.g. {', '.join(list(self.parameters)[:4])}){hint}")

    def load(self, changes: dict | None = None) -> DrivelineFile:
        """The driveline of this file with some parameters changed, read by ``load_driveline``.

        Parameters
        ----------
        changes : dict, optional
            ``{parameter name: value in its SI unit}``.

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
        for name, value in changes.items():
            component, field = name.rsplit(".", 1)
            kind = next(k for k, table in doc.items() if k in self._fields and isinstance(table, dict)
                        and component in table)
            doc[kind] = {**doc[kind], component: {**doc[kind][component], field: float(value)}}
        return _load_document(doc, self.source, changes)


def _load_document(doc: dict, source: str, changes: dict) -> DrivelineFile:
    """:func:`~clutchlab.driveline.description.parse_driveline` of a changed document; its errors name
    ``source`` and the changes."""
    what = ", ".join(f"{k} = {float(v)!r}" for k, v in changes.items())
    return parse_driveline(doc, f"{source} with {what}" if what else source, Path(source).parent)
