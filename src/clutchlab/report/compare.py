"""Compare runs: ``clutchlab report RUN_A RUN_B [...]`` overlays two or more runs or sweeps in one report.

A *run* is a results folder (as for a single report) or one table file (CSV, Parquet, MDF 4).  Tables
of the runs are matched by their path inside the run (``results.csv`` of each folder), or, when every
run is a single table, with each other.  For every matched table the report shows

- **overlays**: each channel the runs share in its own axes, one line per run, named in the legend
  (tables with time); outputs against inputs, one colour per run (sweeps and other tables without time);
- **differences** (tables with time): each run minus the first, on the first run's time base over the
  span both cover (linear interpolation), so that a small change is seen at the scale of the change;
- a **metrics table**: per channel and run min, max, mean, final, and the largest difference from the
  first run;

in engineers' units (rpm, km/h, bar, °C, mm, kN: :data:`clutchlab.units.ENGINEERS_UNITS`) unless
``units="si"``.  Channels only some runs have, and tables only some runs have, are listed, not dropped
silently.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from ..errors import DataError, ParameterError
from ..units import unit_label
from .html import Figure, Section, Table, Text, check_report_folder, write_report
from .run import (DEFAULT_OUTPUT, MAX_PLOT_POINTS, TABLE_SUFFIXES, UNIT_SYSTEMS, Dataset,
                  _display, _io_columns, _left_out, _mean, _plottable, _read_csv, _read_mdf, _read_parquet, _stem,
                  display_label, find_datasets, scatter_matrix)

__all__ = ["compare_runs", "compare_sections", "MAX_RUNS", "MAX_COMPARED_CHANNELS"]

#: most runs one comparison overlays (more lines per axes are not readable)
MAX_RUNS = 8
#: most channels of one table compared (the others are named in the caption)
MAX_COMPARED_CHANNELS = 16
_AXES_PER_FIGURE = 4


@dataclass
class _Run:
    name: str
    path: Path
    datasets: list[Dataset]
    failed: list


def _read_run(path: Path, name: str, output: Path | None, progress) -> _Run:
    if path.is_dir():
        datasets, failed = find_datasets(path, output=output, progress=progress)
        return _Run(name, path, datasets, failed)
    if not path.is_file():
        raise DataError(f"{path}: no such run folder or table file")
    kind = TABLE_SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise DataError(f"{path}: not a results folder or a table ({', '.join(TABLE_SUFFIXES)})")
    if kind == "CSV":
        ds = _read_csv(path, path.name)
    elif kind == "Parquet":
        ds = _read_parquet([path], path.name)
    else:
        ds = _read_mdf(path, path.name)
    return _Run(name, path, [ds], [])


def _names(paths: list[Path], names) -> list[str]:
    if names is not None:
        names = [str(n) for n in names]
        if len(names) != len(paths):
            raise ParameterError(f"{len(names)} names for {len(paths)} runs: give one per run")
        if len(set(names)) != len(names) or not all(n.strip() for n in names):
            raise ParameterError(f"run names must be distinct and non-empty, got {names}")
        return names
    stems = [p.stem if p.is_file() else p.resolve().name for p in paths]
    if len(set(stems)) == len(stems):
        return stems
    return [str(p) for p in paths]


def _label(column, shown: str) -> str:
    return display_label(column, shown) if shown else str(column)


def _channels(frames: list[pd.DataFrame], skip: set) -> tuple[list[str], list[str]]:
    """Numeric channels every run's table has (in the first run's order), and those only some have."""
    def numeric(f):
        return [c for c in f.columns if pd.api.types.is_numeric_dtype(f[c]) and not pd.api.types.is_bool_dtype(f[c])
                and c not in skip]
    first = numeric(frames[0])
    common = [c for c in first if all(c in f.columns and c in numeric(f) for f in frames[1:])]
    everywhere = set().union(*(set(numeric(f)) for f in frames))
    return common, sorted(map(str, everywhere - set(common)))


def _time_overlays(key: str, label: str, tables: list[tuple[str, Dataset]], units: str) -> list:
    from ..plotting import new_figure

    times = [ds.time_column for _, ds in tables]
    common, partial = _channels([ds.frame for _, ds in tables], set(times))
    left = common[MAX_COMPARED_CHANNELS:]
    common = common[:MAX_COMPARED_CHANNELS]
    items: list = []
    if not common:
        items.append(Text(f"{key}: the runs share no numeric channel besides time"))
        return items
    series = []
    for (run, ds), tcol in zip(tables, times):
        stride = max(1, math.ceil(len(ds.frame) / MAX_PLOT_POINTS))
        series.append((run, ds, tcol, stride))
    base_run, base, base_t, _ = series[0]
    t0 = base.frame[base_t].to_numpy(dtype=float)
    rows = []
    for kind in ("overlay", "difference"):
        if kind == "difference" and len(series) < 2:
            continue
        for k in range(0, len(common), _AXES_PER_FIGURE):
            part = common[k:k + _AXES_PER_FIGURE]
            fig, axes = new_figure(len(part), 1, width=8.0, height=1.9 * len(part) + 0.6, sharex=True,
                                   squeeze=False)
            wild = 0
            for ax, c in zip(axes[:, 0], part):
                shown, scale, offset = _display(c, units)
                y0 = base.frame[c].to_numpy(dtype=float)
                for j, (run, ds, tcol, stride) in enumerate(series):
                    t = ds.frame[tcol].to_numpy(dtype=float)
                    y = ds.frame[c].to_numpy(dtype=float)
                    if kind == "overlay":
                        ty, n1 = _plottable(t[::stride])
                        yy, n2 = _plottable(y[::stride] * scale + offset)
                        wild += n1 + n2
                        ax.plot(ty, yy, lw=0.9, label=run, color=f"C{j}")
                    elif j > 0:
                        inside = (t0 >= np.nanmin(t)) & (t0 <= np.nanmax(t))
                        d = np.full(t0.shape, np.nan)
                        ok = np.isfinite(t) & np.isfinite(y)
                        if inside.any() and ok.sum() >= 2:
                            d[inside] = (np.interp(t0[inside], t[ok], y[ok]) - y0[inside]) * scale
                        stride0 = max(1, math.ceil(t0.size / MAX_PLOT_POINTS))
                        dd, n = _plottable(d[::stride0])
                        wild += n
                        ax.plot(t0[::stride0], dd, lw=0.9, label=f"{run} − {base_run}", color=f"C{j}")
                name = _label(c, shown)
                ax.set_ylabel(name if kind == "overlay" else f"Δ {name}", fontsize=8)
                ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
                ax.grid(alpha=0.3)
                ax.tick_params(labelsize=7)
            axes[-1, 0].set_xlabel("time [s]", fontsize=8)
            n = k // _AXES_PER_FIGURE + 1
            total = math.ceil(len(common) / _AXES_PER_FIGURE)
            what = ("overlay of " + ", ".join(r for r, *_ in series) if kind == "overlay" else
                    f"each run minus {base_run}, on {base_run}'s time base where both have data")
            cap = f"{key}: {', '.join(map(str, part))}; {what}" + (f" (part {n} of {total})" if total > 1 else "")
            cap += _left_out(wild)
            if any(ds.synthetic for _, ds in tables):
                cap += " [synthetic data]"
            fig.tight_layout()
            items.append(Figure(f"{label}_{kind}_{n}", fig, cap))
    for c in common:
        shown, scale, offset = _display(c, units)
        y0 = base.frame[c].to_numpy(dtype=float)
        for j, (run, ds, tcol, _) in enumerate(series):
            t = ds.frame[tcol].to_numpy(dtype=float)
            y = ds.frame[c].to_numpy(dtype=float)
            fin = y[np.isfinite(y)]
            row = {"channel": str(c), "unit": unit_label(shown) if shown else "", "run": run}
            if fin.size:
                row.update({"min": fin.min() * scale + offset, "max": fin.max() * scale + offset,
                            "mean": _mean(fin) * scale + offset,
                            "final": fin[-1] * scale + offset})
            if j > 0:
                ok = np.isfinite(t) & np.isfinite(y)
                inside = (t0 >= np.nanmin(t)) & (t0 <= np.nanmax(t)) & np.isfinite(y0)
                if inside.any() and ok.sum() >= 2:
                    d = np.interp(t0[inside], t[ok], y[ok]) - y0[inside]
                    row[f"max |Δ| vs {base_run}"] = float(np.max(np.abs(d))) * abs(scale)
            rows.append(row)
    cols = ["channel", "unit", "run", "min", "max", "mean", "final", f"max |Δ| vs {base_run}"]
    frame = pd.DataFrame(rows).reindex(columns=[c for c in cols if c in pd.DataFrame(rows).columns])
    items.append(Table(f"{label}_metrics", frame, caption=f"{key}: metrics per channel and run"
                       + (" (engineers' units)" if units == "engineers" else " (SI)")))
    notes = []
    if left:
        notes.append(f"not compared (at most {MAX_COMPARED_CHANNELS} channels): {', '.join(map(str, left))}")
    if partial:
        notes.append(f"channels only some runs have (not compared): {', '.join(partial)}")
    items += [Text(f"{key}: {n}") for n in notes]
    return items


def _scatter_overlays(key: str, label: str, tables: list[tuple[str, Dataset]], units: str) -> list:
    inputs, outputs, left = _io_columns(tables[0][1], {})
    inputs = [c for c in inputs if all(c in ds.frame.columns for _, ds in tables)]
    outputs = [c for c in outputs if all(c in ds.frame.columns for _, ds in tables)]
    if not inputs or not outputs:
        return [Text(f"{key}: no inputs and outputs the runs share to draw")]
    fig, wild = scatter_matrix(tables, inputs, outputs, units)
    cap = (f"{key}: outputs {', '.join(map(str, outputs))} against {', '.join(map(str, inputs))}, one colour per "
           f"run ({', '.join(r for r, _ in tables)})" + _left_out(wild) + left)
    if any(ds.synthetic for _, ds in tables):
        cap += " [synthetic data]"
    rows = []
    for c in outputs:
        shown, scale, offset = _display(c, units)
        for run, ds in tables:
            v = ds.frame[c].to_numpy(dtype=float)
            fin = v[np.isfinite(v)]
            rows.append({"output": str(c), "unit": unit_label(shown) if shown else "", "run": run, "rows": len(v),
                         "min": fin.min() * scale + offset if fin.size else np.nan,
                         "max": fin.max() * scale + offset if fin.size else np.nan,
                         "mean": _mean(fin) * scale + offset if fin.size else np.nan})
    return [Figure(f"{label}_scatter", fig, cap),
            Table(f"{label}_metrics", pd.DataFrame(rows), caption=f"{key}: outputs per run")]


def compare_sections(sources, *, names=None, output=None, units: str = "engineers",
                     progress: Callable[[str], None] | None = None) -> list[Section]:
    """The sections of a comparison report (module docstring).

    Parameters
    ----------
    sources : sequence of str or Path
        Two to :data:`MAX_RUNS` results folders or table files.
    names : sequence of str, optional
        One legend name per run (default: the folder or file names).
    output : Path, optional
        Report folder to leave out when scanning the runs.
    units : {"engineers", "si"}
        Figures and tables in engineers' units (rpm, bar, °C, mm, kN, km/h) or SI.
    progress : callable, optional
        Called with a message per step.

    Returns
    -------
    list of Section
    """
    paths = [Path(s) for s in sources]
    if len(paths) < 2:
        raise ParameterError(f"comparing needs at least two runs, got {len(paths)}")
    if len(paths) > MAX_RUNS:
        raise ParameterError(f"{len(paths)} runs: at most {MAX_RUNS} can be overlaid in one report")
    if units not in UNIT_SYSTEMS:
        raise ParameterError(f"units = {units!r}: expected one of {', '.join(UNIT_SYSTEMS)}")
    run_names = _names(paths, names)
    say = progress or (lambda msg: None)
    runs = []
    for path, name in zip(paths, run_names):
        say(f"reading run {name} ({path})")
        runs.append(_read_run(path, name, Path(output) if output is not None else None, progress))
    for run in runs:
        if not run.datasets:
            why = f" ({run.failed[0][1]})" if run.failed else ""
            raise DataError(f"{run.path}: no table to compare{why}")

    if all(len(r.datasets) == 1 for r in runs):
        keys = {"/".join(dict.fromkeys(r.datasets[0].name for r in runs)): [(r.name, r.datasets[0]) for r in runs]}
        only: dict[str, list[str]] = {}
    else:
        by_name: dict[str, list[tuple[str, Dataset]]] = {}
        for r in runs:
            for ds in r.datasets:
                by_name.setdefault(ds.name, []).append((r.name, ds))
        keys = {k: v for k, v in by_name.items() if len(v) >= 2}
        only = {k: [r for r, _ in v] for k, v in by_name.items() if len(v) < 2}
    if not keys:
        raise DataError("the runs share no table to compare (tables are matched by their path inside the run; "
                        f"found: {', '.join(sorted(only))})")

    any_synth = any(ds.synthetic for r in runs for ds in r.datasets)
    summary = pd.DataFrame([{"run": r.name, "path": str(r.path.resolve()), "tables": len(r.datasets),
                             "synthetic": "yes" if any(ds.synthetic for ds in r.datasets) else "no"} for r in runs])
    items: list = [Table("runs", summary, caption="Runs compared, in legend order (differences are against the "
                                                  "first)")]
    for key, owners in only.items():
        items.append(Text(f"{key}: only in {', '.join(owners)} (not compared)"))
    for r in runs:
        for path, reason in r.failed:
            items.append(Text(f"{r.name}: not read: {reason}"))
    prov = ("SYNTHETIC DATA: some or all of these runs come from clutchlab's virtual rigs or simulations."
            if any_synth else "No run declares itself synthetic; provenance as given by each table.")
    sections = [Section("Runs compared", items, provenance=prov, synthetic=any_synth)]
    for n, (key, tables) in enumerate(keys.items(), start=1):
        say(f"comparing {key} ({n}/{len(keys)})")
        label = f"c{n}_{_stem(key)}"
        timed = all(ds.time_column is not None for _, ds in tables)
        body = _time_overlays(key, label, tables, units) if timed else _scatter_overlays(key, label, tables, units)
        synth = any(ds.synthetic for _, ds in tables)
        text = "; ".join(f"{run}: {ds.format} {ds.name}" + (" (synthetic)" if ds.synthetic else "")
                         for run, ds in tables)
        sections.append(Section(f"Compared: {key}", body, provenance=("SYNTHETIC: " if synth else "") + text,
                                synthetic=synth))
    return sections


def compare_runs(sources, output=None, *, names=None, units: str = "engineers", overwrite: bool = False,
                 progress: Callable[[str], None] | None = None, title: str | None = None) -> Path:
    """Write a self-contained HTML report comparing two or more runs (module docstring).

    Parameters
    ----------
    sources : sequence of str or Path
        Results folders or table files (CSV, Parquet, MDF 4); the first is the reference of the differences.
    output : str or Path, optional
        Report folder (default: ``report`` inside the first run's folder, or beside its file).
    names : sequence of str, optional
        Legend names of the runs.
    units : {"engineers", "si"}
        Units of figures and tables.
    overwrite : bool
        Replace a report folder clutchlab wrote before.
    progress : callable, optional
        Called with a message per step.
    title : str, optional
        Page title.

    Returns
    -------
    pathlib.Path
        The report's ``index.html``.
    """
    paths = [Path(s) for s in sources]
    if output is None:
        first = paths[0] if paths and paths[0].is_dir() else (paths[0].parent if paths else Path("."))
        output = first / DEFAULT_OUTPUT
    output = Path(output)
    check_report_folder(output, overwrite)
    for p in paths:
        if p.exists() and output.exists() and (p.resolve() == output.resolve()
                                               or output.resolve() in p.resolve().parents):
            raise ParameterError(f"{output}: holds the run {p}: not replaced; give another folder")
    sections = compare_sections(paths, names=names, output=output, units=units, progress=progress)
    if progress:
        progress(f"writing {output}")
    runs = sections[0].items[0].frame["run"].tolist()
    return write_report(sections, output, title=title or f"clutchlab comparison: {' vs '.join(runs)}",
                        overwrite=overwrite, progress=progress)
