"""Sweep targets: what a model has to provide to be swept, and the registry of models.

A target is a function, named by an import path ``"package.module:function"``,

.. code-block:: python

    run_batch(variants: pandas.DataFrame, scenario: dict | None, outputs: list[str]) -> pandas.DataFrame

``variants`` has one row per variant (index ``variant_id``, the stable id of
the variant in the design) and one float column per swept parameter, named as
in the spec (``"clutch.r_outer"``) and in SI units (temperatures in degC where
the field says so).  ``scenario`` is the parsed scenario TOML (a dict, with
the key ``"_source"`` holding its absolute path for messages and relative
paths) or ``None`` for the model's bundled default.  The function returns a
DataFrame with the same index and one float column per name in ``outputs``
(NaN where a variant has no value, e.g. no lock-up).

Two optional functions in the same module let the spec be checked before
anything runs:

* ``describe(scenario) -> {"parameters": {name: si_unit}, "outputs": {name: unit}}``
  -- the parameters that may be swept (values in the spec may carry units and
  are converted to ``si_unit``) and the outputs that can be asked for.  Without
  it, parameter values must be plain numbers and outputs are checked on the
  first chunk;
* ``check_variants(variants, scenario)`` -- raise
  :class:`~clutchlab.errors.ParameterError` naming the variant id, parameter
  and value if a variant cannot be built (``r_inner >= r_outer``, a gear
  that does not exist).

Built-in targets are listed in :data:`TARGETS`; :func:`register_target` adds
more (the spec may also name an import path directly as ``model``).
"""

from __future__ import annotations

import dataclasses
import importlib
import threading
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..errors import ClutchlabError, ParameterError

__all__ = ["TARGETS", "Target", "TargetInfo", "register_target", "resolve_target", "sweepable_fields",
           "vary_parameter_set"]

#: model name -> import path of its ``run_batch``
TARGETS: dict[str, str] = {
    "wet": "clutchlab.sweep.wet:run_batch",
    "emtc": "clutchlab.sweep.emtc:run_batch",
    "eclutch-static": "clutchlab.sweep.eclutch_static:run_batch",
    "eclutch": "clutchlab.eclutch.sweep:run_batch",  # E-clutch dynamics (issue #5), available once that module exists
}

_LOADED: dict = {}
_LOAD_LOCK = threading.Lock()


def register_target(name: str, path: str) -> None:
    """Make ``name`` usable as ``model`` in a spec, running the function at import path ``path``.

    Parameters
    ----------
    name : str
        Model name used in specs.
    path : str
        ``"package.module:function"`` of a ``run_batch`` function (see the module docstring).
    """
    if not isinstance(path, str) or path.count(":") != 1:
        raise ParameterError(f"register_target({name!r}, {path!r}): expected 'package.module:function'")
    TARGETS[name] = path


@dataclass(frozen=True)
class TargetInfo:
    """What a target declares: sweepable parameters (name -> SI unit) and outputs (name -> unit); None if undeclared."""

    parameters: dict | None
    outputs: dict | None


@dataclass(frozen=True)
class Target:
    """A resolved target: model name and import path (picklable; the function is imported on first use)."""

    name: str
    path: str

    def _module_and_function(self):
        with _LOAD_LOCK:
            if self.path not in _LOADED:
                mod_name, _, func_name = self.path.partition(":")
                try:
                    mod = importlib.import_module(mod_name)
                except ModuleNotFoundError as exc:
                    raise ParameterError(f"model {self.name!r}: cannot import {mod_name!r} ({exc})") from None
                func = getattr(mod, func_name, None)
                if not callable(func):
                    raise ParameterError(f"model {self.name!r}: {mod_name!r} has no function {func_name!r}")
                _LOADED[self.path] = (mod, func)
            return _LOADED[self.path]

    @property
    def function(self):
        """The ``run_batch`` function."""
        return self._module_and_function()[1]

    def describe(self, scenario) -> TargetInfo:
        """Declared parameters and outputs for ``scenario`` (``None`` entries where the target declares none)."""
        mod, _ = self._module_and_function()
        if not hasattr(mod, "describe"):
            return TargetInfo(None, None)
        info = mod.describe(scenario)
        return TargetInfo(dict(info.get("parameters", {})), dict(info.get("outputs", {})))

    def check(self, variants: pd.DataFrame, scenario, source: str | None = None) -> None:
        """Run the target's ``check_variants`` if it has one; errors name ``source``."""
        mod, _ = self._module_and_function()
        if hasattr(mod, "check_variants"):
            try:
                mod.check_variants(variants, scenario)
            except ParameterError as exc:
                raise ParameterError(f"{source}: {exc}" if source else str(exc)) from None

    def run(self, variants: pd.DataFrame, scenario, outputs) -> pd.DataFrame:
        """Call ``run_batch`` and check its answer (same index, every output, numeric)."""
        out = self.function(variants, scenario, list(outputs))
        if not isinstance(out, pd.DataFrame):
            raise ClutchlabError(f"model {self.name!r}: run_batch returned {type(out).__name__}, expected a DataFrame")
        if not out.index.equals(variants.index):
            raise ClutchlabError(f"model {self.name!r}: run_batch returned a different index than the variants it got")
        missing = [o for o in outputs if o not in out.columns]
        if missing:
            raise ParameterError(f"model {self.name!r}: unknown output {missing[0]!r} (run_batch returned "
                                 f"{', '.join(map(str, out.columns))})")
        return out.loc[:, list(outputs)].astype(float)


def resolve_target(model: str, source: str | None = None) -> Target:
    """The :class:`Target` for a model name in :data:`TARGETS` or an import path ``"module:function"``.

    Parameters
    ----------
    model : str
        Model name (``"wet"``, ``"emtc"``, ``"eclutch-static"``, ...) or ``"package.module:function"``.
    source : str, optional
        Spec file, named in error messages.

    Raises
    ------
    ParameterError
        Unknown name, or the module or function cannot be imported.
    """
    where = f"{source}: " if source else ""
    if model in TARGETS:
        path = TARGETS[model]
    elif isinstance(model, str) and model.count(":") == 1 and all(model.split(":")):
        path = model
    else:
        raise ParameterError(f"{where}[sweep] model = {model!r}: unknown model (known: {', '.join(TARGETS)}, "
                             f"or 'package.module:function')")
    target = Target(model, path)
    try:
        target.function
    except ParameterError as exc:
        raise ParameterError(f"{where}[sweep] model = {model!r}: {exc}") from None
    return target


# ----------------------------------------------------------------- helpers for built-in targets
def sweepable_fields(prefix: str, cls) -> dict[str, str]:
    """``{"prefix.field": unit}`` for the scalar fields of a parameter-set class.

    Parameters
    ----------
    prefix : str
        Namespace of the fields in a spec (``"clutch"``).
    cls : type
        A :class:`~clutchlab.params.ParameterSet` subclass; tuple-valued fields are left out.
    """
    out = {}
    for f in dataclasses.fields(cls):
        if "unit" not in f.metadata or isinstance(f.default, tuple):
            continue
        out[f"{prefix}.{f.name}"] = f.metadata["unit"]
    return out


def vary_parameter_set(base, prefix: str, row: dict, variant_id) -> object:
    """``base`` with the fields named ``prefix.<field>`` in ``row`` replaced (validated again).

    Parameters
    ----------
    base : ParameterSet
        The set of the scenario.
    prefix : str
        Namespace of its fields in the spec (``"clutch"``).
    row : dict
        ``{parameter name: SI value}`` of one variant; other namespaces are ignored.
    variant_id : int
        Id of the variant, named in error messages.

    Notes
    -----
    Whole-number fields (``n_c``, ``gear``) must get whole values.  A value the
    set rejects raises :class:`ParameterError` naming the variant.
    """
    changes = {}
    n = len(prefix) + 1
    for key, value in row.items():
        if key.startswith(prefix + "."):
            name = key[n:]
            field = next((f for f in dataclasses.fields(base) if f.name == name), None)
            if field is not None and isinstance(field.default, int) and not isinstance(field.default, bool):
                if not float(value).is_integer():
                    raise ParameterError(f"variant {variant_id}: {key} = {value!r}: expected a whole number")
                value = int(value)
            else:
                value = float(value)
            changes[name] = value
    if not changes:
        return base
    try:
        return base.replace(**changes)
    except ParameterError as exc:
        raise ParameterError(f"variant {variant_id}: {exc}") from None


def rows(variants: pd.DataFrame):
    """``(variant_id, {column: value})`` for every variant."""
    cols = list(variants.columns)
    values = variants.to_numpy(dtype=float)
    for vid, vals in zip(variants.index, values):
        yield vid, dict(zip(cols, vals))


def check_outputs(model: str, outputs, known) -> None:
    """Raise ParameterError naming the first of ``outputs`` that ``model`` does not know.

    Parameters
    ----------
    model : str
        Target name used in the message.
    outputs : iterable of str
        Requested outputs.
    known : mapping or iterable of str
        The target's outputs.
    """
    unknown = [o for o in outputs if o not in known]
    if unknown:
        raise ParameterError(f"{model}: unknown output {unknown[0]!r} (known: {', '.join(known)})")


def nan_frame(index, outputs) -> pd.DataFrame:
    """All-NaN output table."""
    return pd.DataFrame(np.full((len(index), len(outputs)), np.nan), index=index, columns=list(outputs))
