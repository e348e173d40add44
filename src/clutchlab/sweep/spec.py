"""Sweep specification: the TOML file, its validation and the deterministic design.

A spec names a model target, an optional scenario file, the outputs to keep,
the chunk size and either a full-factorial ``[grid]`` or a ``[monte_carlo]``
sample.  :func:`load_spec` validates everything against the target before
anything runs (unknown parameter, bad unit, unknown output ->
:class:`~clutchlab.errors.ParameterError` naming the file, the key and the
value) and builds the design: one row per variant, the row number being the
variant's stable id.  Monte Carlo samples are drawn from ``numpy.random``'s
PCG64 generator seeded with ``seed``, parameter after parameter in file order,
so the same spec always yields the same design.

The spec's hash (:attr:`SweepSpec.hash`), which a resumed sweep must match,
covers the normalised spec and design, the target's identity, the clutchlab
version and the bytes of every file the spec references: the scenario file
and every file the scenario makes the target read (:attr:`SweepSpec.inputs`).
"""

from __future__ import annotations

import difflib
import functools
import hashlib
import json
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .. import __version__
from .._limits import short_repr
from ..errors import DataError, ParameterError
from ..params import load_toml
from ..units import to_si
from .targets import Target, file_digest, files_in, resolve_target

__all__ = ["SweepSpec", "load_spec", "check_scheduler", "DISTRIBUTIONS", "VARIANT_ID"]

#: name of the variant-id column (and of the design's index)
VARIANT_ID = "variant_id"

#: Monte Carlo distributions and their keys (values may carry the parameter's unit)
DISTRIBUTIONS = {
    "normal": ("mean", "std"),
    "uniform": ("low", "high"),
    "loguniform": ("low", "high"),
}

_SWEEP_KEYS = ("model", "scenario", "outputs", "chunk_size", "seed")
_TABLES = ("sweep", "grid", "monte_carlo")


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep specification with its design.

    Attributes
    ----------
    path : Path
        The spec file (``"<dict>"`` when built from a mapping).
    model : str
        Target name as written in the spec.
    target : Target
        The resolved target.
    scenario : dict or None
        Parsed scenario TOML with ``"_source"`` (its absolute path) added, or
        ``None`` for the model's bundled default scenario.
    outputs : tuple of str
        Output names kept per variant.
    chunk_size : int
        Variants per chunk (one compiled batch each).
    seed : int
        Seed of the Monte Carlo sample.
    kind : {"grid", "monte_carlo"}
        Design type.
    parameters : tuple of str
        Swept parameter names (columns of ``design``), in file order.
    units : dict
        SI unit of every swept parameter.
    design : pandas.DataFrame
        One row per variant (index ``variant_id`` = row number), SI values.
    definition : dict
        Normalised design definition (SI values), part of the hash.
    inputs : tuple of (str, str, str)
        ``(label, absolute path, SHA-256 of the bytes)`` of every file the
        spec references (the label is the path relative to the spec's folder).
    """

    path: Path
    model: str
    target: Target
    scenario: dict | None
    outputs: tuple
    chunk_size: int
    seed: int
    kind: str
    parameters: tuple
    units: dict
    design: pd.DataFrame
    definition: dict = field(repr=False)
    inputs: tuple = ()

    @property
    def n_variants(self) -> int:
        """Number of variants in the design."""
        return int(len(self.design))

    @property
    def n_chunks(self) -> int:
        """Number of chunks (the last one may be short)."""
        return int(math.ceil(self.n_variants / self.chunk_size))

    def chunk(self, index: int) -> pd.DataFrame:
        """Variants of chunk ``index`` (rows ``index*chunk_size`` up to the next chunk)."""
        if not 0 <= index < self.n_chunks:
            raise ParameterError(f"chunk index {index} outside 0..{self.n_chunks - 1}")
        return self.design.iloc[index * self.chunk_size:(index + 1) * self.chunk_size]

    @functools.cached_property
    def hash(self) -> str:
        """SHA-256 over the normalised spec, the design values, the target, the clutchlab version and the input files."""
        scen = None if self.scenario is None else {k: v for k, v in self.scenario.items() if not k.startswith("_")}
        body = {
            "target": self.target.identity,
            "clutchlab": __version__,
            "inputs": {label: digest for label, _, digest in self.inputs},
            "scenario": scen,
            "outputs": list(self.outputs),
            "chunk_size": self.chunk_size,
            "seed": self.seed,
            "design": self.definition,
            "design_values": hashlib.sha256(np.ascontiguousarray(self.design.to_numpy(dtype=float)).tobytes()).hexdigest(),
        }
        text = json.dumps(body, sort_keys=True, default=str)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()

    def changed_inputs(self) -> list[str]:
        """Labels of the referenced files whose bytes differ now from when the spec was loaded (or that are gone)."""
        changed = []
        for label, path, digest in self.inputs:
            try:
                now = file_digest(path)
            except OSError:
                now = None
            if now != digest:
                changed.append(label)
        return changed


def _inputs(target, scenario, scen_path, base_dir, where) -> tuple:
    """``(label, path, sha256)`` of the scenario file and of every file it makes the target read."""
    paths = []
    if scen_path is not None:
        paths.append(scen_path)
        try:
            declared = target.referenced_files(scenario)
        except ParameterError as exc:
            raise ParameterError(f"{where}: {exc}") from None
        paths += [p if p.is_absolute() else (scen_path.parent / p) for p in declared]
        paths += files_in(scenario)
    out, seen = [], set()
    for p in paths:
        p = Path(p).resolve()
        if p in seen:
            continue
        seen.add(p)
        try:
            digest = file_digest(p)
        except OSError as exc:
            raise DataError(f"{where}: cannot read {p}, referenced by the spec ({exc.strerror or exc})") from None
        out.append((Path(os.path.relpath(p, base_dir)).as_posix(), str(p), digest))
    return tuple(sorted(out))


def _suggest(name, known):
    close = difflib.get_close_matches(name, list(known), n=3)
    return f"did you mean {', '.join(close)}?" if close else f"{len(known)} known; see docs/sweeps.md"


def _int(value, where, name, minimum):
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise ParameterError(f"{where}: {name} = {value!r}: expected a whole number >= {minimum}")
    return int(value)


def _parameter_unit(target_params, key, value, where, table):
    if not isinstance(key, str) or key not in target_params:
        raise ParameterError(
            f"{where}: [{table}] unknown parameter {key!r} = {value!r} for this model ({_suggest(key, target_params)})")
    return target_params[key]


def _grid(table, params, where):
    values, units = {}, {}
    if not table:
        raise ParameterError(f"{where}: [grid] is empty: give at least one parameter with a list of values")
    for key, raw in table.items():
        unit = _parameter_unit(params, key, raw, where, "grid")
        raw_list = raw if isinstance(raw, list) else [raw]
        if not raw_list:
            raise ParameterError(f"{where}: [grid] {key!r} = {raw!r}: needs at least one value")
        vals = [to_si(v, unit, name=f"[grid] {key!r}", source=where) for v in raw_list]
        if len(set(vals)) != len(vals):
            raise ParameterError(f"{where}: [grid] {key!r} = {raw!r}: repeated value")
        values[key] = vals
        units[key] = unit
    keys = list(values)
    sizes = [len(values[k]) for k in keys]
    n = math.prod(sizes)
    _check_size(n, len(keys), where, "[grid] (" + " x ".join(map(str, sizes)) + " values)")
    # the full product, the last key varying fastest, built column by column (n * len(keys) floats, no rows)
    columns = {}
    for i, k in enumerate(keys):
        inner, outer = math.prod(sizes[i + 1:]), math.prod(sizes[:i])
        columns[k] = np.tile(np.repeat(np.asarray(values[k], dtype=float), inner), outer)
    design = pd.DataFrame(columns, columns=keys)
    return design, units, {"grid": {k: values[k] for k in keys}}


#: most variants a sweep may have: its design, results and manifest grow with them (a grid of 2e9 variants
#: built 5.4 GB in memory before anything stopped it, #33)
MAX_VARIANTS = 10_000_000


def _check_size(n: int, n_params: int, where: str, what: str) -> None:
    """Refuse a design of more than :data:`MAX_VARIANTS` variants before building it, with its memory."""
    if n > MAX_VARIANTS:
        gb = n * (n_params + 4) * 8 / 1e9   # the design's floats, the variant ids and a few outputs each
        raise ParameterError(f"{where}: {what} gives {n:.3g} variants, more than {MAX_VARIANTS:.0e} (about {gb:.3g} "
                             "GB for the design and results alone): thin the grid or split the sweep")


def _distribution_value(spec, key, pkey, unit, where):
    if pkey not in spec:
        raise ParameterError(f"{where}: [monte_carlo] {key!r} = {spec!r}: missing {pkey!r}")
    target_unit = unit
    if pkey == "std" and unit == "degC":
        target_unit = "delta_degC"  # a spread of a temperature is a temperature difference
    return to_si(spec[pkey], target_unit, name=f"[monte_carlo] {key!r}.{pkey}", source=where)


def _monte_carlo(table, params, seed, where):
    table = dict(table)
    if "n" not in table:
        raise ParameterError(f"{where}: [monte_carlo] needs n = <number of samples>")
    n = _int(table.pop("n"), where, "[monte_carlo] n", 1)
    if not table:
        raise ParameterError(f"{where}: [monte_carlo] has no parameter to sample")
    _check_size(n, len(table), where, f"[monte_carlo] n = {n}")
    rng = np.random.Generator(np.random.PCG64(seed))
    columns, units, definition = {}, {}, {}
    for key, spec in table.items():
        unit = _parameter_unit(params, key, spec, where, "monte_carlo")
        if not isinstance(spec, dict) or "dist" not in spec:
            raise ParameterError(f"{where}: [monte_carlo] {key!r} = {spec!r}: expected {{ dist = \"normal\", mean = ..., std = ... }}"
                                 f" or {{ dist = \"uniform\", low = ..., high = ... }}")
        dist = spec["dist"]
        if dist not in DISTRIBUTIONS:
            raise ParameterError(f"{where}: [monte_carlo] {key!r}.dist = {dist!r}: expected one of {', '.join(DISTRIBUTIONS)}")
        extra = set(spec) - {"dist", *DISTRIBUTIONS[dist]}
        if extra:
            raise ParameterError(f"{where}: [monte_carlo] {key!r}: unknown key {sorted(extra)[0]!r} for dist = {dist!r} "
                                 f"(expected {', '.join(DISTRIBUTIONS[dist])})")
        a, b = (_distribution_value(spec, key, p, unit, where) for p in DISTRIBUTIONS[dist])
        if dist == "normal":
            if not b > 0:
                raise ParameterError(f"{where}: [monte_carlo] {key!r}.std = {spec['std']!r}: must be > 0")
            sample = rng.normal(a, b, n)
        else:
            if not b > a:
                raise ParameterError(f"{where}: [monte_carlo] {key!r}: high = {spec['high']!r} must exceed low = {spec['low']!r}")
            if dist == "uniform":
                sample = rng.uniform(a, b, n)
            else:
                if not a > 0:
                    raise ParameterError(f"{where}: [monte_carlo] {key!r}.low = {spec['low']!r}: loguniform needs low > 0")
                sample = np.exp(rng.uniform(math.log(a), math.log(b), n))
        columns[key] = sample
        units[key] = unit
        definition[key] = {"dist": dist, DISTRIBUTIONS[dist][0]: a, DISTRIBUTIONS[dist][1]: b}
    design = pd.DataFrame(columns)
    return design, units, {"monte_carlo": {"n": n, **definition}}


#: Dask scheduler address: [protocol://]host:port
_SCHEDULER = re.compile(r"^(?:(?:tcp|tls|ucx|ws|wss)://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})/?$")


def check_scheduler(scheduler):
    """Check a Dask scheduler address before anything is written.

    Parameters
    ----------
    scheduler : str, dask.distributed.Client or None
        ``tcp://HOST:PORT`` (also ``tls://``, ``ucx://``, ``ws://``, ``wss://``
        or a bare ``HOST:PORT``; port 1-65535), or a client (passed through).

    Returns
    -------
    The argument, unchanged.

    Raises
    ------
    ParameterError
        Anything else, naming the value.
    """
    if scheduler is None or hasattr(scheduler, "submit"):
        return scheduler
    m = _SCHEDULER.match(scheduler) if isinstance(scheduler, str) else None
    if m is None or not 0 < int(m.group(2)) < 65536:
        raise ParameterError(f"--scheduler {short_repr(scheduler)}: expected a Dask scheduler address "
                             "tcp://HOST:PORT (port 1-65535)")
    return scheduler


def load_spec(path) -> SweepSpec:
    """Read and validate a sweep spec TOML file and build its design.

    Parameters
    ----------
    path : str or Path
        The spec file (see ``docs/sweeps.md``); ``scenario`` inside it is
        relative to the spec file.

    Returns
    -------
    SweepSpec

    Raises
    ------
    ParameterError
        Missing or unknown keys, unknown model, parameter or output, values
        that do not parse or have the wrong unit, an empty design, a
        variant the model rejects -- naming the file, the key and the value.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"sweep spec = {short_repr(path)}: expected the path of a spec file (or a SweepSpec, "
                             f"or its tables as a dict), not {type(path).__name__}")
    path = Path(path)
    data = load_toml(path)
    return spec_from_dict(data, source=path)


def spec_from_dict(data: dict, *, source=None) -> SweepSpec:
    """Build a :class:`SweepSpec` from a parsed spec mapping (see :func:`load_spec`).

    Parameters
    ----------
    data : dict
        The spec as :mod:`tomllib` returns it (tables ``sweep`` and ``grid`` or ``monte_carlo``).
    source : str or Path, optional
        The spec file: named in error messages; a relative ``scenario`` is
        taken relative to its folder (to the working directory without one).
    """
    where = str(source) if source is not None else "<spec>"
    base_dir = Path(source).resolve().parent if source is not None else Path.cwd()
    unknown = [k for k in data if k not in _TABLES]
    if unknown:
        raise ParameterError(f"{where}: unknown table [{unknown[0]}] (known: {', '.join(_TABLES)})")
    sweep = data.get("sweep")
    if not isinstance(sweep, dict):
        raise ParameterError(f"{where}: missing [sweep] table")
    bad = [k for k in sweep if k not in _SWEEP_KEYS]
    if bad:
        raise ParameterError(f"{where}: [sweep] unknown key {bad[0]!r} = {sweep[bad[0]]!r} (known: {', '.join(_SWEEP_KEYS)})")
    if "model" not in sweep:
        raise ParameterError(f"{where}: [sweep] needs model = \"wet\" | \"emtc\" | \"eclutch-static\" | \"eclutch\" | "
                             "\"driveline\" "
                             "(or a registered or plugin target name)")
    model = sweep["model"]
    if not isinstance(model, str):
        raise ParameterError(f"{where}: [sweep] model = {model!r}: expected a string")
    target = resolve_target(model, source=where)
    scenario = scen_path = None
    if "scenario" in sweep:
        scen_raw = sweep["scenario"]
        if not isinstance(scen_raw, str) or not scen_raw:
            raise ParameterError(f"{where}: [sweep] scenario = {scen_raw!r}: expected a file name")
        scen_path = (base_dir / scen_raw).resolve()
        if not scen_path.exists():
            raise ParameterError(f"{where}: [sweep] scenario = {scen_raw!r}: no such file {scen_path}")
        scenario = dict(load_toml(scen_path))
        scenario["_source"] = str(scen_path)
    info = target.describe(scenario)
    inputs = _inputs(target, scenario, scen_path, base_dir, where)
    outputs = sweep.get("outputs")
    if not isinstance(outputs, list) or not outputs or not all(isinstance(o, str) for o in outputs):
        raise ParameterError(f"{where}: [sweep] outputs = {outputs!r}: expected a non-empty list of output names")
    if len(set(outputs)) != len(outputs):
        raise ParameterError(f"{where}: [sweep] outputs = {outputs!r}: repeated name")
    if info.outputs is not None:
        for o in outputs:
            if o not in info.outputs:
                raise ParameterError(f"{where}: [sweep] outputs: unknown output {o!r} for model {model!r} "
                                     f"(known: {', '.join(info.outputs)})")
    chunk_size = _int(sweep.get("chunk_size", 250), where, "[sweep] chunk_size", 1)
    seed = _int(sweep.get("seed", 0), where, "[sweep] seed", 0)
    has_grid, has_mc = "grid" in data, "monte_carlo" in data
    if has_grid == has_mc:
        raise ParameterError(f"{where}: give exactly one of [grid] (full factorial) or [monte_carlo] (random sample)")
    params = info.parameters
    if params is None:
        params = _PlainNumbers()
    if has_grid:
        design, units, definition = _grid(data["grid"], params, where)
        kind = "grid"
    else:
        design, units, definition = _monte_carlo(data["monte_carlo"], params, seed, where)
        kind = "monte_carlo"
    overlap = set(design.columns) & set(outputs)
    if overlap:
        raise ParameterError(f"{where}: {sorted(overlap)[0]!r} is both a swept parameter and an output")
    design.index = pd.RangeIndex(len(design), name=VARIANT_ID)
    target.check(design, scenario, source=where)
    return SweepSpec(path=Path(source) if source is not None else Path("<dict>"), model=model, target=target,
                     scenario=scenario, outputs=tuple(outputs), chunk_size=chunk_size, seed=seed, kind=kind,
                     parameters=tuple(design.columns), units=units, design=design, definition=definition,
                     inputs=inputs)


class _PlainNumbers(dict):
    """Parameter table of a target that declares none: any name, plain numbers only (unit "1")."""

    def __contains__(self, key):
        return isinstance(key, str)

    def __getitem__(self, key):
        return "1"
