"""Sweep targets: what a model has to provide to be swept, and where targets come from.

A target is a ``run_batch`` function,

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

Three optional functions beside it (attributes of the same module or object)
let the spec be checked before anything runs and a resumed sweep be trusted:

* ``describe(scenario) -> {"parameters": {name: si_unit}, "outputs": {name: unit}}``
  -- the parameters that may be swept (values in the spec may carry units and
  are converted to ``si_unit``) and the outputs that can be asked for.  Without
  it, parameter values must be plain numbers and outputs are checked on the
  first chunk;
* ``check_variants(variants, scenario)`` -- raise
  :class:`~clutchlab.errors.ParameterError` naming the variant id, parameter
  and value if a variant cannot be built (``r_inner >= r_outer``, a gear
  that does not exist);
* ``referenced_files(scenario) -> list of paths`` -- every file the scenario
  makes the target read (curves, a Preisach model, an input signal).  Their
  bytes are part of the sweep's hash, so a resumed sweep never mixes results
  of old and new files.  (Strings in the scenario naming an existing file
  beside it are hashed as well, declared or not.)

**A spec names a target, never code.**  Targets come from three places only:
clutchlab's built-in targets (:data:`BUILTIN`), targets registered in this
process with :func:`register_target` (a module or a function object, not an
import path), and installed plugins declaring an entry point in the group
``clutchlab.sweep_targets`` (``name = "package.module"`` or
``"package.module:object"``), which is imported only when a spec names it.
Entry points of distributions found in the working directory or the spec's
folder are ignored (``python -m clutchlab`` puts the working directory on
``sys.path``).  :func:`available_targets` lists the names.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
import importlib.metadata
import threading
import types
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ClutchlabError, ParameterError
from ..params.base import model_fields

__all__ = ["BUILTIN", "ENTRY_POINT_GROUP", "Target", "TargetInfo", "available_targets", "register_target",
           "unregister_target", "resolve_target", "file_digest", "files_in", "sweepable_fields", "vary_parameter_set"]

#: built-in model name -> clutchlab module holding its ``run_batch`` (a constant of this package, never read from a file)
BUILTIN: types.MappingProxyType = types.MappingProxyType({
    "wet": "clutchlab.sweep.wet",
    "emtc": "clutchlab.sweep.emtc",
    "eclutch-static": "clutchlab.sweep.eclutch_static",
    "eclutch": "clutchlab.sweep.eclutch",
    "driveline": "clutchlab.sweep.driveline",
})

#: entry-point group of plugin targets
ENTRY_POINT_GROUP = "clutchlab.sweep_targets"

_HOOKS = ("run_batch", "describe", "check_variants", "referenced_files")
_REGISTERED: dict = {}
_LOCK = threading.Lock()


@dataclass(frozen=True)
class TargetInfo:
    """What a target declares: sweepable parameters (name -> SI unit) and outputs (name -> unit); None if undeclared."""

    parameters: dict | None
    outputs: dict | None


@dataclass(frozen=True)
class Target:
    """A resolved target: its name, where it came from and its functions.

    Picklable (the functions are pickled by reference), so it can be shipped
    to worker processes and Dask workers, where the defining module must be
    importable.

    Attributes
    ----------
    name : str
        Model name as written in the spec.
    origin : str
        ``"built-in"``, ``"registered"`` or ``"entry point NAME = VALUE (DIST VERSION)"``.
    identity : str
        What the sweep's hash records about the target (module, function, plugin version).
    run_batch : callable
        The batch function (see the module docstring).
    describe, check_variants, referenced_files : callable or None
        The optional functions.
    """

    name: str
    origin: str
    identity: str
    run_batch: object = dataclasses.field(repr=False)
    describe_fn: object = dataclasses.field(default=None, repr=False)
    check_fn: object = dataclasses.field(default=None, repr=False)
    files_fn: object = dataclasses.field(default=None, repr=False)

    @property
    def function(self):
        """The ``run_batch`` function."""
        return self.run_batch

    def describe(self, scenario) -> TargetInfo:
        """Declared parameters and outputs for ``scenario`` (``None`` entries where the target declares none)."""
        if self.describe_fn is None:
            return TargetInfo(None, None)
        info = self.describe_fn(scenario)
        return TargetInfo(dict(info.get("parameters", {})), dict(info.get("outputs", {})))

    def check(self, variants: pd.DataFrame, scenario, source: str | None = None) -> None:
        """Run the target's ``check_variants`` if it has one; errors name ``source``."""
        if self.check_fn is not None:
            try:
                self.check_fn(variants, scenario)
            except ParameterError as exc:
                raise ParameterError(f"{source}: {exc}" if source else str(exc)) from None

    def referenced_files(self, scenario) -> list[Path]:
        """Files the target reads for ``scenario`` (its ``referenced_files``; empty without one)."""
        if self.files_fn is None or scenario is None:
            return []
        return [Path(p) for p in self.files_fn(scenario)]

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


def _hooks(obj, what: str) -> dict:
    """``{hook: callable or None}`` of a module / object with ``run_batch``, or of a bare ``run_batch`` function."""
    if isinstance(obj, str):
        raise ParameterError(f"{what}: got the string {obj!r}; pass the module or function object "
                             "(targets are never imported from a name)")
    if callable(getattr(obj, "run_batch", None)):
        hooks = {h: getattr(obj, h, None) for h in _HOOKS}
        for h, fn in hooks.items():
            if fn is not None and not callable(fn):
                raise ParameterError(f"{what}: {h} is not callable")
        return hooks
    if callable(obj) and not isinstance(obj, type):
        return {"run_batch": obj, "describe": None, "check_variants": None, "referenced_files": None}
    raise ParameterError(f"{what}: expected a module or object with a run_batch function, or the function itself")


def _qualname(fn) -> str:
    return f"{getattr(fn, '__module__', '?')}.{getattr(fn, '__qualname__', type(fn).__name__)}"


def _make(name, origin, identity, hooks) -> Target:
    return Target(name, origin, identity, hooks["run_batch"], hooks["describe"], hooks["check_variants"],
                  hooks["referenced_files"])


def register_target(name: str, target, *, replace: bool = False) -> None:
    """Make ``name`` usable as ``model`` in a spec (in this process).

    Parameters
    ----------
    name : str
        Model name used in specs (no ``:``; not one of :data:`BUILTIN`).
    target : module, object or callable
        A module or object with a ``run_batch`` function (and optionally
        ``describe``, ``check_variants``, ``referenced_files``; see the module
        docstring), or the ``run_batch`` function itself.  For worker
        processes and Dask the functions must be importable module-level
        functions.
    replace : bool
        Replace an existing registration of ``name``.

    Raises
    ------
    ParameterError
        A bad name, an import path given as a string, or a name already taken.
    """
    if not isinstance(name, str) or not name or ":" in name or name != name.strip():
        raise ParameterError(f"register_target({name!r}): expected a plain name without ':'")
    if name in BUILTIN:
        raise ParameterError(f"register_target({name!r}): {name!r} is a built-in target")
    hooks = _hooks(target, f"register_target({name!r})")
    with _LOCK:
        if name in _REGISTERED and not replace:
            raise ParameterError(f"register_target({name!r}): already registered (pass replace=True)")
        _REGISTERED[name] = hooks


def unregister_target(name: str) -> None:
    """Forget a target registered with :func:`register_target`.

    Parameters
    ----------
    name : str
        The registered name (nothing happens if it is not registered).
    """
    with _LOCK:
        _REGISTERED.pop(name, None)


def _untrusted_dirs(source) -> set:
    try:
        dirs = {Path.cwd().resolve()}
    except OSError:  # the working directory was removed: nothing is found there either
        dirs = set()
    if source is not None and str(source) not in ("<spec>", "<dict>"):
        dirs.add(Path(source).resolve().parent)
    return dirs


def _entry_points(source=None) -> dict:
    """``{name: [entry points]}`` of installed plugins, leaving out distributions in untrusted folders."""
    untrusted = _untrusted_dirs(source)
    found: dict = {}
    for dist in importlib.metadata.distributions():
        try:
            eps = [ep for ep in dist.entry_points if ep.group == ENTRY_POINT_GROUP]
        except Exception:  # pragma: no cover - a broken dist-info: not a plugin
            continue
        if not eps:
            continue
        try:
            home = Path(str(dist.locate_file(""))).resolve()
        except Exception:  # pragma: no cover
            continue
        if home in untrusted:
            continue
        for ep in eps:
            found.setdefault(ep.name, []).append((ep, dist))
    return found


def available_targets(source=None) -> list[str]:
    """Names a spec may give as ``model``: built-in, registered, then installed plugins (sorted each).

    Parameters
    ----------
    source : str or Path, optional
        The spec file; plugins installed in its folder are not offered.

    Notes
    -----
    Lists entry points from the installed metadata without importing any of them.
    """
    with _LOCK:
        registered = sorted(_REGISTERED)
    plugins = sorted(n for n in _entry_points(source) if n not in BUILTIN and n not in registered)
    return [*sorted(BUILTIN), *registered, *plugins]


def resolve_target(model: str, source: str | None = None) -> Target:
    """The :class:`Target` named ``model``: built-in, registered, or an installed plugin's entry point.

    Parameters
    ----------
    model : str
        Model name (``"wet"``, ``"emtc"``, ``"eclutch-static"``, ``"eclutch"``, ``"driveline"``, a registered
        or plugin name).
    source : str, optional
        Spec file, named in error messages.

    Raises
    ------
    ParameterError
        Unknown name (the message lists the available ones; an import path
        such as ``"module:function"`` is an unknown name), or a plugin that
        cannot be loaded.
    """
    from .. import __version__

    where = f"{source}: " if source else ""
    if not isinstance(model, str):
        raise ParameterError(f"{where}[sweep] model = {model!r}: expected a target name")
    if model in BUILTIN:
        module = importlib.import_module(BUILTIN[model])
        return _make(model, "built-in", f"clutchlab {__version__} built-in {model} ({BUILTIN[model]})",
                     _hooks(module, f"built-in target {model!r}"))
    with _LOCK:
        hooks = _REGISTERED.get(model)
    if hooks is not None:
        return _make(model, "registered", f"registered {model} ({_qualname(hooks['run_batch'])})", hooks)
    plugins = _entry_points(source).get(model, []) if ":" not in model else []
    if not plugins:
        hint = (f"; a spec names a target, never code (plugins: entry-point group {ENTRY_POINT_GROUP!r}, "
                "docs/sweeps.md)") if ":" in model or "." in model else ""
        raise ParameterError(f"{where}[sweep] model = {model!r}: unknown model "
                             f"(available: {', '.join(available_targets(source))}){hint}")
    if len(plugins) > 1:
        dists = ", ".join(f"{d.metadata['Name']} {d.version}" for _, d in plugins)
        raise ParameterError(f"{where}[sweep] model = {model!r}: provided by more than one installed plugin ({dists})")
    ep, dist = plugins[0]
    label = f"entry point {ep.name} = {ep.value} ({dist.metadata['Name']} {dist.version})"
    try:
        obj = ep.load()
    except Exception as exc:  # a plugin that does not import is the plugin's error, reported in one line
        raise ParameterError(f"{where}[sweep] model = {model!r}: cannot load the {label}: "
                             f"{type(exc).__name__}: {exc}") from None
    return _make(model, label, label, _hooks(obj, f"{where}[sweep] model = {model!r}: {label}"))


def file_digest(path) -> str:
    """SHA-256 (hex) of the bytes of the file ``path``."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def files_in(scenario) -> list[Path]:
    """Existing files named by string values anywhere in ``scenario``, relative to its ``_source`` folder.

    The catch-all behind a target's ``referenced_files``: a plugin that does
    not declare its files still has those it names in the scenario hashed.
    """
    if not scenario or "_source" not in scenario:
        return []
    base = Path(scenario["_source"]).parent
    found = []

    def walk(value):
        if isinstance(value, dict):
            for k, v in value.items():
                if not str(k).startswith("_"):
                    walk(v)
        elif isinstance(value, list):
            for v in value:
                walk(v)
        elif isinstance(value, str) and value and len(value) < 4096 and "\0" not in value:
            try:
                p = (base / value).resolve()
                if p.is_file():
                    found.append(p)
            except (OSError, ValueError):
                pass

    walk(scenario)
    return found


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
    for f in model_fields(cls):
        if isinstance(f.default, tuple):
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
        import difflib

        names = list(known)
        close = difflib.get_close_matches(str(unknown[0]), names, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        listed = ", ".join(names[:12]) + (f", ... ({len(names)} in all: clutchlab sweep SPEC --list-parameters)"
                                          if len(names) > 12 else "")
        raise ParameterError(f"{model}: unknown output {unknown[0]!r}{hint} (known: {listed})")


def nan_frame(index, outputs) -> pd.DataFrame:
    """All-NaN output table."""
    return pd.DataFrame(np.full((len(index), len(outputs)), np.nan), index=index, columns=list(outputs))
