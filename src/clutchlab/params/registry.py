"""Which parameter sets make up each model, their presets, and model parameter files.

Every :class:`~clutchlab.params.ParameterSet` subclass registers itself when
its class is defined (``ParameterSet.__init_subclass__``).  A set belongs to
the model whose package defines it: ``clutchlab.wet.*`` sets make up the
``wet`` model, ``clutchlab.eclutch.*`` the ``eclutch`` model and
``clutchlab.emtc.*`` the ``emtc`` model.  A new set appears here as soon as
its module is imported by its package; nothing in this module lists sets.

A *model parameter file* holds one TOML table per set (``[wet]``,
``[bench]``, ...), values with units (``r_outer = "83.15 mm"``), and
optionally ``model = "wet"`` at the top.  :func:`model_toml` writes one that
documents itself (a comment per field with its description, unit and source)
and :func:`load_model_file` reads it back, naming the file, ``[table] key``
and the value at fault on any error.
"""

from __future__ import annotations

import dataclasses
import importlib
import re
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from .base import ParameterSet, load_toml, registered_sets

__all__ = ["MODELS", "SetEntry", "model_sets", "preset", "model_toml", "load_model_file", "show_table",
           "find_entry"]

#: model name -> package whose parameter sets make up the model
MODELS = {"eclutch": "clutchlab.eclutch", "wet": "clutchlab.wet", "emtc": "clutchlab.emtc"}


@dataclasses.dataclass(frozen=True)
class SetEntry:
    """One parameter set of a model.

    Attributes
    ----------
    table : str
        TOML table name in a model file: the set's ``kind``, or its class name
        in snake case where two sets of the model share a ``kind``.
    cls : type
        The :class:`ParameterSet` subclass.
    model : str
        Model name (``eclutch``, ``wet``, ``emtc``).
    """

    table: str
    cls: type
    model: str

    @property
    def has_paper(self) -> bool:
        """Whether the class defines a ``paper()`` preset (the paper's table)."""
        return callable(getattr(self.cls, "paper", None))

    def preset(self, paper: bool = False) -> ParameterSet:
        """The class defaults, or with ``paper=True`` its ``paper()`` preset where it has one."""
        return self.cls.paper() if paper and self.has_paper else self.cls()


def _snake(name: str) -> str:
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def _check_model(model: str) -> str:
    if model not in MODELS:
        raise ParameterError(f"unknown model {model!r} (known: {', '.join(MODELS)})")
    return model


def model_sets(model: str) -> list[SetEntry]:
    """The parameter sets of ``model`` in definition order (imports the model's package)."""
    package = MODELS[_check_model(model)]
    importlib.import_module(package)
    latest: dict[tuple[str, str], type] = {}  # a class defined again (reload, slots=True) replaces the old one
    for c in registered_sets():
        if c.__module__.startswith(package + ".") and c.field_info():
            latest.pop((c.__module__, c.__qualname__), None)
            latest[(c.__module__, c.__qualname__)] = c
    classes = list(latest.values())
    kinds = [c.kind for c in classes]
    return [SetEntry(c.kind if kinds.count(c.kind) == 1 else _snake(c.__name__), c, model) for c in classes]


def find_entry(model: str, table: str) -> SetEntry:
    """The set of ``model`` stored in ``[table]`` (its table name, or its ``kind`` if unambiguous)."""
    entries = model_sets(model)
    for e in entries:
        if e.table == table:
            return e
    by_kind = [e for e in entries if e.cls.kind == table]
    if len(by_kind) > 1:
        raise ParameterError(f"[{table}] is ambiguous in model {model!r}: use "
                             + " or ".join(f"[{e.table}] ({e.cls.__name__})" for e in by_kind))
    if not by_kind:
        raise ParameterError(f"unknown table [{table}] for model {model!r} (known: "
                             + ", ".join(f"[{e.table}]" for e in entries) + ")")
    return by_kind[0]


def preset(model: str, paper: bool = False) -> dict[str, ParameterSet]:
    """``{table: set}`` with every set of ``model`` at its defaults (or its paper preset)."""
    return {e.table: e.preset(paper) for e in model_sets(model)}


def _toml_value(value, unit: str) -> str:
    """A field value as TOML: numbers where dimensionless, ``"value unit"`` strings otherwise.

    Floats are written with ``repr`` so they load back bit for bit.
    """
    def one(v):
        if isinstance(v, int) and not isinstance(v, bool):
            return str(v)
        text = repr(float(v))
        if unit in ("", "1"):
            return text
        return f'"{text} {unit}"'

    if isinstance(value, tuple):
        return "[" + ", ".join(one(v) for v in value) + "]"
    return one(value)


def _comment(text: str) -> str:
    return " ".join(str(text).split())


def model_toml(model: str, sets: dict[str, ParameterSet] | None = None, *, paper: bool = False) -> str:
    """A self-documenting TOML file with every set of ``model``.

    Parameters
    ----------
    model : str
        ``eclutch``, ``wet`` or ``emtc``.
    sets : dict, optional
        ``{table: set}`` to write; default: :func:`preset` of the model.
    paper : bool
        Use the paper presets (``paper()``) where a set has one.

    Returns
    -------
    str
        TOML text: ``model = "<model>"``, then one table per set, each field
        preceded by a comment with its description, unit and source.  Loading
        it with :func:`load_model_file` gives back equal sets.
    """
    if sets is None:
        sets = preset(model, paper)
    lines = [
        f"# clutchlab parameters of the {model} model" + (" (paper presets)" if paper else ""),
        "# Values are SI; any unit of the same dimension may be written instead",
        '# (e.g. "83.15 mm", "300 kPa", "3 bar", "1500 rpm", "85 degC").  Check with: clutchlab params check FILE',
        f'model = "{model}"',
    ]
    for table, pset in sets.items():
        doc = (type(pset).__doc__ or "").strip().splitlines()
        lines += ["", f"# {type(pset).__name__}: {_comment(doc[0]) if doc else ''}".rstrip(), f"[{table}]"]
        for name, meta in pset.field_info().items():
            src = f"; source: {_comment(meta['source'])}" if meta.get("source") else ""
            lines.append(f"# {_comment(meta['doc'])} [{meta['unit']}]{src}")
            lines.append(f"{name} = {_toml_value(getattr(pset, name), meta['unit'])}")
    return "\n".join(lines) + "\n"


def _infer_model(path, tables: list[str]) -> str:
    candidates = []
    for model in MODELS:
        names = set()
        for e in model_sets(model):
            names |= {e.table, e.cls.kind}
        if tables and set(tables) <= names:
            candidates.append(model)
    if len(candidates) == 1:
        return candidates[0]
    if not candidates:
        raise ParameterError(f"{path}: tables {', '.join(f'[{t}]' for t in tables) or '(none)'} do not belong "
                             f"to one model ({', '.join(MODELS)}); write model = \"...\" at the top")
    raise ParameterError(f"{path}: tables {', '.join(f'[{t}]' for t in tables)} fit models "
                         f"{' and '.join(candidates)}; write model = \"...\" at the top or give --model")


def load_model_file(path, model: str | None = None) -> tuple[str, dict[str, ParameterSet]]:
    """Read and validate a model parameter file.

    Parameters
    ----------
    path : str or Path
        TOML file with one table per parameter set (and optionally
        ``model = "..."``).
    model : str, optional
        Model the file belongs to; default: its ``model`` key, else the one
        model whose tables it uses.

    Returns
    -------
    (str, dict)
        The model name and ``{table: set}`` for the tables present (sets not
        in the file are not returned).

    Raises
    ------
    ParameterError
        Naming the file, ``[table] key`` and the value at fault.
    """
    path = Path(path)
    data = load_toml(path)
    declared = data.pop("model", None)
    if declared is not None and not isinstance(declared, str):
        raise ParameterError(f"{path}: model = {declared!r}: expected one of {', '.join(MODELS)}")
    stray = [k for k, v in data.items() if not isinstance(v, dict)]
    if stray:
        raise ParameterError(f"{path}: {stray[0]} = {data[stray[0]]!r} is outside any table; parameters go in "
                             "a table such as [wet]")
    if model is not None and declared is not None and model != declared:
        raise ParameterError(f"{path}: model = {declared!r} but model {model!r} was asked for")
    model = model or declared or _infer_model(path, list(data))
    try:
        _check_model(model)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None
    out = {}
    for table, values in data.items():
        try:
            entry = find_entry(model, table)
        except ParameterError as exc:
            raise ParameterError(f"{path}: {exc}") from None
        out[entry.table] = entry.cls.from_dict(values, source=str(path), table=table)
    return model, out


def format_number(value) -> str:
    """A parameter value as a person reads it: integers as integers, floats to 6 significant digits.

    Plain decimals between 1e-4 and 1e6 (``0.08315``, ``32000``), otherwise
    scientific notation without padding (``2.3e6``, ``3e-11``); ``20240601``
    (a seed) stays an integer.
    """
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    v = float(value)
    if v == 0.0 or not np.isfinite(v):
        return f"{v:g}"
    if 1e-4 <= abs(v) < 1e6:
        text = f"{v:.6g}"
        return text if "e" not in text else f"{v:.6f}".rstrip("0").rstrip(".")
    mantissa, exponent = f"{v:.6e}".split("e")
    return f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"


def format_unit(unit: str) -> str:
    """A pint unit string for reading: ``kg*m**2`` -> ``kg*m^2``; dimensionless ``1`` stays ``1``."""
    return unit.replace("**", "^")


def show_table(model: str, sets: dict[str, ParameterSet] | None = None, *, paper: bool = False) -> str:
    """Plain-text table of every set of ``model``: name, value, unit, source and description.

    Parameters
    ----------
    model : str
        ``eclutch``, ``wet`` or ``emtc``.
    sets : dict, optional
        ``{table: set}`` to show; default: :func:`preset` of the model.
    paper : bool
        Show the paper presets (``paper()``) where a set has one.
    """
    if sets is None:
        sets = preset(model, paper)
    entries = {e.table: e for e in model_sets(model)}
    out = []
    for table, pset in sets.items():
        entry = entries.get(table)
        how = ("paper preset " + type(pset).__name__ + ".paper()" if paper and entry is not None and entry.has_paper
               else "defaults " + type(pset).__name__ + "()")
        out.append(f"[{table}]  {how}")
        rows = [("name", "value", "unit", "source", "description")]
        for name, meta in pset.field_info().items():
            value = getattr(pset, name)
            val = ", ".join(format_number(v) for v in value) if isinstance(value, tuple) else format_number(value)
            rows.append((name, val, format_unit(meta["unit"]), meta.get("source") or "-", meta["doc"]))
        widths = [max(len(r[i]) for r in rows) for i in range(4)]
        for r in rows:
            out.append("  " + "  ".join(r[i].ljust(widths[i]) if i != 1 else r[i].rjust(widths[i]) for i in range(4))
                       + "  " + r[4])
        out.append("")
    return "\n".join(out)
