"""Report of a results folder: ``clutchlab report RUN_DIR``.

A *run directory* is any folder of results: a CSV written by ``clutchlab
eclutch simulate`` or ``clutchlab wet simulate`` (``#`` comment lines on top,
``# synthetic: ...`` where the data come from a virtual rig), the Parquet
chunks and ``manifest.json`` of ``clutchlab sweep``, MDF4 measurement files,
or files put there by hand.  :func:`report_run_dir` finds every table in it
and writes a self-contained HTML report with

- for each table, figures: the channels against time where the table has a
  time column (channels grouped by the unit their names end in), otherwise the
  outputs scattered against the first (input) columns;
- a metrics table per table (count, min, max, mean, final value per channel);
- every ``*.toml`` file in the folder as a table (the parameters used);
- the clutchlab version and the data's provenance (comment headers, Parquet
  and MDF metadata, manifest fields), with synthetic data marked as such.

Nothing here is specific to one subsystem; column names are used as found.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from ..errors import DataError, ParameterError
from ..units import NAME_UNITS, column_label, column_unit, unit_label
from .html import Figure, Section, Table, Text, check_report_folder, write_report

__all__ = ["Dataset", "find_datasets", "report_run_dir", "run_sections", "metrics_table", "display_label",
           "scatter_matrix",
           "DEFAULT_OUTPUT", "UNIT_SYSTEMS"]

#: report folder written inside RUN_DIR when no output is given (skipped when scanning)
DEFAULT_OUTPUT = "report"

TABLE_SUFFIXES = {".csv": "CSV", ".parquet": "Parquet", ".mf4": "MDF4", ".mdf": "MDF4"}
_TIME_NAMES = ("time_s", "time", "t_s", "t", "timestamp_s", "timestamps")
MAX_LINES_PER_AXES = 6
MAX_AXES_PER_FIGURE = 4
#: at most this many time-series figures per table (the other channels are named, and in the metrics table)
MAX_FIGURES_PER_TABLE = 10
MAX_PLOT_POINTS = 4000
MAX_SCATTER_POINTS = 5000
MAX_SCATTER_OUTPUTS = 8
MAX_SCATTER_INPUTS = 3
_INDEX_NAMES = ("variant", "variant_id", "index", "id", "run", "run_id", "row", "chunk", "sample")
#: a table of at most this many rows whose first column holds labels is shown as it is, not plotted
MAX_LABELLED_ROWS = 50


@dataclass
class Dataset:
    """A table found in a run directory.

    Attributes
    ----------
    name : str
        Path relative to the run directory (a folder for chunked Parquet).
    format : str
        ``CSV``, ``Parquet`` or ``MDF4``.
    frame : pandas.DataFrame
        The data.
    provenance : list of str
        Header comment lines, file metadata.
    files : list of Path
        The files read (several for Parquet chunks).
    """

    name: str
    format: str
    frame: pd.DataFrame
    provenance: list[str] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)

    @property
    def synthetic(self) -> bool:
        """Whether the provenance says the data are synthetic."""
        return any(re.search(r"\bsynthetic\b", line, re.I) for line in self.provenance)

    @property
    def time_column(self) -> str | None:
        """The time column (``time_s``, ``time``, ...) if the table has a numeric, increasing one."""
        lower = {str(c).lower(): c for c in self.frame.columns}
        for name in _TIME_NAMES:
            col = lower.get(name)
            if col is not None and pd.api.types.is_numeric_dtype(self.frame[col]):
                t = self.frame[col].to_numpy(dtype=float)
                t = t[np.isfinite(t)]
                if t.size >= 2 and np.all(np.diff(t) >= 0):
                    return col
        return None

    def numeric_columns(self) -> list[str]:
        """Numeric (non-boolean) columns with at least one finite value."""
        out = []
        for c in self.frame.columns:
            s = self.frame[c]
            if pd.api.types.is_numeric_dtype(s) and not pd.api.types.is_bool_dtype(s):
                if np.isfinite(s.to_numpy(dtype=float)).any():
                    out.append(c)
        return out


# ---------------------------------------------------------------------- reading
def _read_csv(path: Path, name: str) -> Dataset:
    from ..io.dialect import read_csv

    table = read_csv(path, str(path))   # any dialect (clutchlab.io.dialect); '#' lines and a title are the header
    d = table.dialect
    plain = d.encoding == "utf-8" and d.separator == "," and d.decimal == "." and not d.units_row
    # a unit the file states (unit row, "Kraft [kN]", '# units:') travels in the name, where figures look for it
    frame = table.frame.rename(columns={c: f"{c} [{u}]" for c, u in table.units.items()
                                        if c in table.frame.columns and u and column_unit(str(c)) is None})
    return Dataset(name, "CSV", frame, list(table.comments) + ([] if plain else [f"read as {d.describe()}"]),
                   [path])


def _parquet_provenance(path: Path) -> list[str]:
    import pyarrow.parquet as pq

    meta = pq.read_schema(path).metadata or {}
    out = []
    for key, value in meta.items():
        k = key.decode("utf-8", "replace")
        if k == "pandas" or k.startswith("ARROW:"):
            continue  # pandas' own schema record, not provenance
        v = value.decode("utf-8", "replace")
        out.append(f"{k}: {v if len(v) <= 300 else v[:300] + ' ...'}")
    return out


def _read_parquet(paths: list[Path], name: str) -> Dataset:
    frames, prov = [], []
    for p in paths:
        try:
            frames.append(pd.read_parquet(p))
            for line in _parquet_provenance(p):
                if line not in prov:
                    prov.append(line)
        except Exception as exc:  # pyarrow raises assorted errors on damaged files
            raise DataError(f"{p}: cannot read as Parquet ({exc})") from None
    frame = pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0]
    if len(paths) > 1:
        prov.append(f"{len(paths)} Parquet chunks concatenated in file-name order")
    return Dataset(name, "Parquet", frame, prov, list(paths))


def _read_mdf(path: Path, name: str) -> Dataset:
    try:
        from asammdf import MDF

        with MDF(path) as mdf:
            frame = mdf.to_dataframe(time_from_zero=False, raw=False)
            comment = str(getattr(mdf.header, "comment", "") or "")
    except Exception as exc:  # asammdf raises many error types on foreign files
        raise DataError(f"{path}: cannot read as MDF ({exc})") from None
    frame = frame.reset_index().rename(columns={"timestamps": "time_s"})
    prov = [line.strip() for line in re.sub(r"<[^>]+>", "\n", comment).splitlines() if line.strip()]
    return Dataset(name, "MDF4", frame, prov, [path])


def _outside(path: Path, run_dir: Path) -> bool:
    """True if ``path`` (a link, or in a linked folder) leads out of ``run_dir``: its file is not read (#33: the
    report followed links out of the results folder)."""
    try:
        path.resolve().relative_to(run_dir.resolve())
        return False
    except ValueError:
        return True


#: why a file behind a link out of the results folder is not read
OUTSIDE = "a link to a file outside the results folder: not read"


def _skipped(path: Path, run_dir: Path, output: Path | None) -> bool:
    rel = path.relative_to(run_dir)
    if any(part.startswith(".") for part in rel.parts):
        return True
    if output is not None:
        try:
            path.resolve().relative_to(output.resolve())
            return True
        except ValueError:
            pass
    return False


def find_datasets(run_dir, *, output=None, progress: Callable[[str], None] | None = None):
    """Read every table in ``run_dir`` (recursively).

    Parquet files of one folder that share their columns are one dataset
    (the chunks of a sweep); every other file is its own dataset.  A dataset
    with exactly the rows of another (chunks next to the results file they
    were joined into) is kept once, the smaller number of files winning.  Files that
    cannot be read are returned as ``(path, reason)`` in the second list, so a
    report of a damaged folder still shows what could be read.

    Parameters
    ----------
    run_dir : str or Path
        Folder of results.
    output : str or Path, optional
        Report folder inside ``run_dir`` to leave out.
    progress : callable, optional
        Called with a message per file read.

    Returns
    -------
    (list of Dataset, list of (Path, str))
    """
    run_dir = Path(run_dir)
    output = Path(output) if output is not None else None
    say = progress or (lambda msg: None)
    files = sorted(p for p in run_dir.rglob("*") if p.is_file() and p.suffix.lower() in TABLE_SUFFIXES
                   and not _skipped(p, run_dir, output))
    failed = [(p, OUTSIDE) for p in files if _outside(p, run_dir)]
    files = [p for p in files if not _outside(p, run_dir)]
    datasets = []
    parquet_groups: dict[tuple, list[Path]] = {}
    for n, path in enumerate(files, start=1):
        rel = path.relative_to(run_dir).as_posix()
        kind = TABLE_SUFFIXES[path.suffix.lower()]
        say(f"reading {rel} ({n}/{len(files)})")
        try:
            if kind == "Parquet":
                import pyarrow.parquet as pq

                try:
                    cols = tuple(pq.read_schema(path).names)
                except Exception as exc:  # damaged file
                    raise DataError(f"{path}: cannot read as Parquet ({exc})") from None
                parquet_groups.setdefault((path.parent, cols), []).append(path)
            elif kind == "CSV":
                datasets.append(_read_csv(path, rel))
            else:
                datasets.append(_read_mdf(path, rel))
        except DataError as exc:
            failed.append((path, str(exc)))
    for (folder, _cols), paths in parquet_groups.items():
        name = paths[0].relative_to(run_dir).as_posix() if len(paths) == 1 else \
            (folder.relative_to(run_dir).as_posix() or ".") + f"/ ({len(paths)} chunks)"
        try:
            datasets.append(_read_parquet(paths, name))
        except DataError as exc:
            failed.append((paths[0], str(exc)))
    datasets.sort(key=lambda d: (len(d.files), d.name))
    unique: list[Dataset] = []
    for ds in datasets:  # the chunks of a sweep repeat its results file: keep the single file
        twin = next((u for u in unique if list(u.frame.columns) == list(ds.frame.columns)
                     and len(u.frame) == len(ds.frame) and u.frame.reset_index(drop=True).equals(ds.frame.reset_index(drop=True))), None)
        if twin is None:
            unique.append(ds)
        else:
            twin.provenance.append(f"same rows as {ds.name} (not shown again)")
    unique.sort(key=lambda d: d.name)
    return unique, failed


# ---------------------------------------------------------------------- figures
def _unit_of(column: str) -> str:
    """The unit a channel name states: a ``[unit]`` at its end, else its suffix (``N*m``, ``rad/s``); ``""`` if none."""
    name = str(column)
    m = re.search(r"\[([^\]]+)\]\s*$", name)
    if m:
        return m.group(1).strip()
    unit = column_unit(name)
    return "" if unit is None or name in NAME_UNITS else unit


#: unit systems of a report's figures and tables (the files stay SI)
UNIT_SYSTEMS = ("engineers", "si")


def _display(column, units: str = "si") -> tuple[str, float, float]:
    """(unit shown, scale, offset) of a channel in the chosen unit system (``""`` for none): engineers' units
    (rpm, km/h, bar, °C, mm, kN; :data:`clutchlab.units.ENGINEERS_UNITS`) or the column's own."""
    from ..units import engineers_unit

    unit = _unit_of(column)
    if not unit or units == "si":
        return unit, 1.0, 0.0
    try:
        return engineers_unit(unit)
    except Exception:   # a unit pint does not know: shown as it is
        return unit, 1.0, 0.0


def _stem_of(column: str) -> str:
    """Name without a trailing index (``i1`` -> ``i``, ``fn2`` -> ``fn``, ``omega_f`` -> ``omega``)."""
    return re.sub(r"(?:_?\d+|_[A-Za-z])$", "", str(column)) or str(column)


def _words(column) -> str:
    """A channel name without its unit suffix, spelled as it is (``slip_speed_rad_s`` -> ``slip_speed``)."""
    return re.sub(r"\s*\[[^\]]*\]\s*$", "", column_label(column)) or str(column)


def display_label(column, shown: str) -> str:
    """Axis label of a channel shown in the unit ``shown`` (``speed [rpm]``); the name alone without a unit."""
    return f"{_words(column)} [{unit_label(shown)}]" if shown else column_label(column)


def _axis_label(unit: str, cols: list[str]) -> str:
    """y label of an axes of channels ``cols``: their common name (underscores kept) and the unit for people."""
    if not unit:
        return _stem_of(cols[0])
    if len(cols) == 1:
        return f"{_words(cols[0])} [{unit_label(unit)}]"
    return f"[{unit_label(unit)}]"


def _groups(columns: list[str]) -> list[tuple[str, list[str]]]:
    """Channels grouped into axes by the unit their names end in.

    Names without a unit suffix are grouped by their stem (``omega_f`` and
    ``omega_r``, ``t1`` to ``t3``); each group has at most
    ``MAX_LINES_PER_AXES`` lines.  Returns ``(label, columns)`` pairs, the
    label being the unit (or ``""`` for a stem group).
    """
    keyed: dict[tuple[str, str], list[str]] = {}
    for c in columns:
        unit = _unit_of(c)
        keyed.setdefault(("unit", unit) if unit else ("stem", _stem_of(c)), []).append(c)
    out: list[tuple[str, list[str]]] = []
    for (how, key), cols in keyed.items():
        for i in range(0, len(cols), MAX_LINES_PER_AXES):
            out.append((key if how == "unit" else "", cols[i:i + MAX_LINES_PER_AXES]))
    order = {c: i for i, c in enumerate(columns)}
    out.sort(key=lambda g: order[g[1][0]])
    return out


def _is_index(column) -> bool:
    return str(column).lower() in _INDEX_NAMES


def _labelled(ds: Dataset) -> bool:
    """A small table whose first column holds labels (a summary such as ``output, unit, mean, ...``)."""
    frame = ds.frame
    if frame.empty or len(frame) > MAX_LABELLED_ROWS or ds.time_column is not None:
        return False
    first = frame[frame.columns[0]]
    return not pd.api.types.is_numeric_dtype(first) and first.is_unique


def _stem(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_") or "table"


#: values beyond this magnitude are not drawn (no SI quantity of a clutch reaches it; a column holding +-1e308
#: made matplotlib's tick search overflow, a traceback for the whole report: #33)
PLOT_LIMIT = 1e150


def _plottable(values) -> tuple[np.ndarray, int]:
    """``values`` as floats with the non-finite ones and those beyond :data:`PLOT_LIMIT` as NaN, and how many
    finite values were left out."""
    v = np.asarray(values, dtype=float).copy()
    wild = np.isfinite(v) & (np.abs(v) > PLOT_LIMIT)
    v[wild | ~np.isfinite(v)] = np.nan
    return v, int(wild.sum())


def _left_out(n: int) -> str:
    return f"; {n} values beyond ±{PLOT_LIMIT:.0e} not drawn" if n else ""


def _time_series_figures(ds: Dataset, label: str, units: str = "si") -> list:
    from ..plotting import new_figure

    tcol = ds.time_column
    channels = [c for c in ds.numeric_columns() if c != tcol]
    if not channels:
        return []
    frame = ds.frame
    stride = max(1, math.ceil(len(frame) / MAX_PLOT_POINTS))
    t, wild = _plottable(frame[tcol].to_numpy(dtype=float)[::stride])
    groups = _groups(channels)
    figures: list = []
    drawn = MAX_FIGURES_PER_TABLE * MAX_AXES_PER_FIGURE
    if len(groups) > drawn:
        # a logger file of 3,000 channels made 125 figures, 74 MB and 1.45 GB of memory (#33): the first ones
        # are drawn, the rest named; every channel keeps its row in the metrics table
        rest = [str(c) for _, cols in groups[drawn:] for c in cols]
        shown = ", ".join(rest[:20]) + (f", ... ({len(rest) - 20} more)" if len(rest) > 20 else "")
        figures.append(Text(f"{ds.name}: {len(rest)} of {len(channels)} channels not drawn (at most "
                            f"{MAX_FIGURES_PER_TABLE} figures of {MAX_AXES_PER_FIGURE} axes per table; all are "
                            f"in the metrics table): {shown}"))
        groups = groups[:drawn]
    for k in range(0, len(groups), MAX_AXES_PER_FIGURE):
        part = groups[k:k + MAX_AXES_PER_FIGURE]
        fig, axes = new_figure(len(part), 1, width=8.0, height=1.9 * len(part) + 0.6, sharex=True, squeeze=False)
        left_out = wild
        for ax, (unit, cols) in zip(axes[:, 0], part):
            shown, scale, offset = _display(cols[0], units) if unit else ("", 1.0, 0.0)
            for c in cols:
                y, n = _plottable(frame[c].to_numpy(dtype=float)[::stride] * scale + offset)
                left_out += n
                ax.plot(t, y, lw=0.9, label=_words(c) if unit else str(c))
            ax.set_ylabel(_axis_label(shown, cols), fontsize=8)
            if len(cols) > 1:  # one line: the axis label names it
                ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=7)
        axes[-1, 0].set_xlabel(column_label(tcol) if _unit_of(tcol) else f"{tcol} [s]", fontsize=8)
        n = k // MAX_AXES_PER_FIGURE + 1
        total = math.ceil(len(groups) / MAX_AXES_PER_FIGURE)
        names = ", ".join(str(c) for _, cols in part for c in cols)
        cap = f"{ds.name}: {names} against {tcol}" + (f" (part {n} of {total})" if total > 1 else "")
        if stride > 1:
            cap += f"; every {stride}th of {len(frame)} samples plotted"
        cap += _left_out(left_out)
        if ds.synthetic:
            cap += " [synthetic data]"
        fig.tight_layout()
        figures.append(Figure(f"{label}_timeseries_{n}", fig, cap))
    return figures


def _io_columns(ds: Dataset, manifest: dict) -> tuple[list[str], list[str], str]:
    """The inputs and outputs of the scatter matrix, and what was left out of it (for the caption)."""
    numeric = [c for c in ds.numeric_columns() if not _is_index(c)]
    declared = manifest.get("outputs") if isinstance(manifest.get("outputs"), list) else None
    params = manifest.get("parameters")
    params = list(params) if isinstance(params, (dict, list)) else []
    if declared:
        outputs = [c for c in numeric if c in declared]
        if outputs:
            inputs = [c for c in numeric if c in params] or [c for c in numeric if c not in outputs]
            left = [c for c in (*inputs[MAX_SCATTER_INPUTS:], *outputs[MAX_SCATTER_OUTPUTS:])]
            return inputs[:MAX_SCATTER_INPUTS], outputs[:MAX_SCATTER_OUTPUTS], _not_drawn(left)
    if len(numeric) < 2:
        return [], [], ""
    n_in = max(1, min(MAX_SCATTER_INPUTS, len(numeric) // 2))
    return numeric[:n_in], numeric[n_in:n_in + MAX_SCATTER_OUTPUTS], _not_drawn(numeric[n_in + MAX_SCATTER_OUTPUTS:])


def _not_drawn(columns) -> str:
    """The caption's note of columns a scatter matrix leaves out (#33: a fourth sweep parameter was left out
    without a word)."""
    if not columns:
        return ""
    return f"; not drawn (the matrix takes {MAX_SCATTER_INPUTS} inputs and {MAX_SCATTER_OUTPUTS} outputs): " + \
        ", ".join(map(str, columns))


def scatter_matrix(tables: list, inputs: list[str], outputs: list[str], units: str = "si"):
    """Outputs (rows) against inputs (columns) of one or more tables, one colour and marker per table.

    Parameters
    ----------
    tables : list of (str, Dataset)
        The tables and their legend names (a legend only for two or more); each drawn with at most
        :data:`MAX_SCATTER_POINTS` rows, drawn at random (seed 0).
    inputs, outputs : list of str
        Columns every table has.
    units : {"si", "engineers"}
        Units of the axes.

    Returns
    -------
    (figure, int)
        The figure, and how many values beyond :data:`PLOT_LIMIT` it leaves out.
    """
    from ..plotting import new_figure

    several = len(tables) > 1
    fig, axes = new_figure(len(outputs), len(inputs), width=2.9 * len(inputs) + (1.6 if several else 1.0),
                           height=2.1 * len(outputs) + 0.5, squeeze=False)
    left_out = 0
    for i, out in enumerate(outputs):
        for j, inp in enumerate(inputs):
            ax = axes[i, j]
            (iu, isc, ioff), (ou, osc, ooff) = _display(inp, units), _display(out, units)
            for r, (name, ds) in enumerate(tables):
                frame = ds.frame
                if len(frame) > MAX_SCATTER_POINTS:
                    frame = frame.sample(MAX_SCATTER_POINTS, random_state=0)
                x, nx = _plottable(frame[inp].to_numpy(dtype=float) * isc + ioff)
                y, ny = _plottable(frame[out].to_numpy(dtype=float) * osc + ooff)
                left_out += nx + ny
                style = dict(color=f"C{r}", marker="os^Dv<>p"[r % 8], label=name) if several else {}
                ax.scatter(x, y, s=6, alpha=0.6, **style)
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=7)
            if i == len(outputs) - 1:
                ax.set_xlabel(display_label(inp, iu), fontsize=8)
            if j == 0:
                ax.set_ylabel(display_label(out, ou), fontsize=8)
    if several:
        axes[0, -1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.tight_layout()
    return fig, left_out


def _scatter_figures(ds: Dataset, label: str, manifest: dict, units: str = "si") -> list[Figure]:
    inputs, outputs, left = _io_columns(ds, manifest)
    if not inputs or not outputs:
        return []
    fig, left_out = scatter_matrix([(ds.name, ds)], inputs, outputs, units)
    cap = f"{ds.name}: outputs {', '.join(map(str, outputs))} against {', '.join(map(str, inputs))}"
    if len(ds.frame) > MAX_SCATTER_POINTS:
        cap += f"; {MAX_SCATTER_POINTS} of {len(ds.frame)} rows drawn at random (seed 0)"
    cap += _left_out(left_out) + left
    if ds.synthetic:
        cap += " [synthetic data]"
    return [Figure(f"{label}_scatter", fig, cap)]


# ---------------------------------------------------------------------- tables
def metrics_table(ds: Dataset, units: str = "si") -> pd.DataFrame:
    """Count of finite values, min, max, mean and final (last finite) value of every numeric channel of ``ds``.

    Parameters
    ----------
    ds : Dataset
        The table.
    units : {"si", "engineers"}
        The columns' own (SI) units, or engineers' units (rpm, km/h, bar, °C, mm, kN).

    Returns
    -------
    pandas.DataFrame
        One row per channel: ``channel, unit`` (for people: rad/s, °C, N·m), ``finite, non-finite, min, max,
        mean, final``; ``final`` (the value at the end of the run) only for a time series: the rows of a table
        without time (sweep variants, Monte Carlo samples) have no order that makes one last (#33).
    """
    rows = []
    for c in ds.numeric_columns():
        v = ds.frame[c].to_numpy(dtype=float)
        ok = np.isfinite(v)
        fin = v[ok]
        unit, scale, offset = _display(c, units)
        rows.append({"channel": str(c), "unit": unit_label(unit) if unit else "",
                     "finite": int(ok.sum()), "non-finite": int((~ok).sum()),
                     "min": float(fin.min()) * scale + offset, "max": float(fin.max()) * scale + offset,
                     "mean": _mean(fin) * scale + offset, "final": float(fin[-1]) * scale + offset})
    columns = ["channel", "unit", "finite", "non-finite", "min", "max", "mean", "final"]
    if ds.time_column is None:
        columns.remove("final")
    return pd.DataFrame(rows, columns=columns)


def _mean(values) -> float:
    """The mean of finite ``values`` without overflow (a column of 1e308 has the mean 1e308, not inf)."""
    scale = float(np.abs(values).max()) if values.size else 0.0
    return float(np.mean(values / scale) * scale) if scale > 0 else 0.0


def _flatten(data, prefix=""):
    for key, value in data.items():
        name = f"{prefix}.{key}" if prefix else str(key)
        if isinstance(value, dict):
            yield from _flatten(value, name)
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for i, item in enumerate(value):
                yield from _flatten(item, f"{name}[{i}]")
        else:
            yield name, value


def _toml_value_text(value) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value_text(v) for v in value) + "]"
    return str(value)


def parameter_tables(run_dir: Path, output: Path | None) -> tuple[list, list[str]]:
    """One report Table per ``*.toml`` in ``run_dir`` (and messages for files that cannot be read)."""
    from ..params.base import load_toml
    from ..params.registry import load_model_file

    items, problems = [], []
    for path in sorted(p for p in run_dir.rglob("*.toml") if p.is_file() and not _skipped(p, run_dir, output)):
        rel = path.relative_to(run_dir).as_posix()
        if _outside(path, run_dir):
            problems.append(f"{rel}: {OUTSIDE}")
            continue
        try:
            data = load_toml(path)
        except ParameterError as exc:
            problems.append(str(exc))
            continue
        rows = []
        for key, value in _flatten(data):
            table, _, name = key.rpartition(".")
            rows.append({"table": f"[{table}]" if table else "", "key": name, "value": _toml_value_text(value)})
        try:
            model, _ = load_model_file(path)
            note = f"valid {model} parameters (clutchlab params check)"
        except ParameterError:
            note = "not a clutchlab model parameter file; shown as written"
        items.append(Table(f"params_{_stem(rel)}", pd.DataFrame(rows, columns=["table", "key", "value"]),
                           caption=f"{rel}: {note}"))
    return items, problems


def _read_manifests(run_dir: Path, output: Path | None) -> dict[str, dict]:
    out = {}
    for path in sorted(run_dir.rglob("manifest.json")):
        if _skipped(path, run_dir, output) or _outside(path, run_dir):
            continue
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise DataError(f"{path}: cannot read as JSON ({exc})") from None
        if isinstance(data, dict):
            out[path.relative_to(run_dir).as_posix()] = data
    return out


def _manifest_rows(name: str, data: dict) -> list[dict]:
    rows = []
    if isinstance(data.get("chunks"), dict):  # a sweep's per-chunk checksums: one row, not two per chunk
        data = {**data, "chunks": f"{len(data['chunks'])} chunk files recorded (SHA-256 and content checksum)"}
    for key, value in _flatten(data):
        text = json.dumps(value) if not isinstance(value, str) else value
        rows.append({"file": name, "field": key, "value": text if len(text) <= 200 else text[:200] + " ..."})
    return rows


def _manifest_synthetic(data: dict) -> bool:
    return bool(re.search(r"\bsynthetic\b", json.dumps(data), re.I))


# ---------------------------------------------------------------------- assembly
def run_sections(run_dir, *, output=None, progress: Callable[[str], None] | None = None,
                 units: str = "engineers") -> list[Section]:
    """The report sections of a run directory (see the module docstring).

    Parameters
    ----------
    run_dir : str or Path
        Folder of results.
    output : str or Path, optional
        Report folder inside ``run_dir`` to leave out when scanning.
    progress : callable, optional
        Called with a message per file read and per table plotted.
    units : {"engineers", "si"}
        Units of the figures and metrics: engineers' units (rpm, km/h, bar, °C, mm, kN) or the columns' SI
        units.  The files stay SI.

    Returns
    -------
    list of Section
        Run summary, one section per table, and the parameter files.

    Raises
    ------
    DataError
        ``run_dir`` does not exist or holds no table and no parameter file.
    """
    from .. import __version__

    run_dir = Path(run_dir)
    say = progress or (lambda msg: None)
    if units not in UNIT_SYSTEMS:
        raise ParameterError(f"units = {units!r}: expected one of {', '.join(UNIT_SYSTEMS)}")
    if not run_dir.is_dir():
        raise DataError(f"{run_dir}: no such run directory")
    output = Path(output) if output is not None else None
    say(f"scanning {run_dir}")
    datasets, failed = find_datasets(run_dir, output=output, progress=progress)
    manifests = _read_manifests(run_dir, output)
    params, toml_problems = parameter_tables(run_dir, output)
    if not datasets and not params and not manifests:
        why = f"; unreadable: {failed[0][1]}" if failed else ""
        raise DataError(f"{run_dir}: no result tables (*.csv, *.parquet, *.mf4) or parameter files (*.toml) found{why}")
    manifest = next(iter(manifests.values()), {})
    manifest_synth = any(_manifest_synthetic(m) for m in manifests.values())

    for ds in datasets:  # sweep output (Parquet) is synthetic when its manifest says so
        if ds.format == "Parquet" and manifest_synth and not ds.synthetic:
            ds.provenance.insert(0, "synthetic according to the run manifest")
    any_synth = any(d.synthetic for d in datasets) or manifest_synth

    summary_rows = [{"item": "run directory", "value": str(run_dir.resolve())},
                    {"item": "clutchlab version", "value": __version__}]
    files = pd.DataFrame([{"dataset": d.name, "format": d.format, "rows": len(d.frame), "columns": len(d.frame.columns),
                           "time column": d.time_column or "-", "synthetic": "yes" if d.synthetic else "no"}
                          for d in datasets], columns=["dataset", "format", "rows", "columns", "time column", "synthetic"])
    items = [Table("summary", pd.DataFrame(summary_rows)), Table("datasets", files, caption="Tables found")]
    for path, reason in failed:
        items.append(Text(f"Not read: {reason}"))
    for problem in toml_problems:
        items.append(Text(f"Parameter file not read: {problem}"))
    rows = [r for name, data in manifests.items() for r in _manifest_rows(name, data)]
    if rows:
        items.append(Table("manifest", pd.DataFrame(rows), caption="Run manifest"))
    prov = ("SYNTHETIC DATA: some or all of these results come from clutchlab's virtual rigs or simulations, "
            "not from measurements (see each table's provenance)." if any_synth else
            "No file in this folder declares itself synthetic; provenance as given by each table.")
    sections = [Section("Run summary", items, provenance=prov, synthetic=any_synth)]

    for n, ds in enumerate(datasets, start=1):
        say(f"figures and metrics of {ds.name} ({n}/{len(datasets)}, {len(ds.frame)} rows)")
        label = f"d{n}_{_stem(ds.name)}"
        ds_items: list = []
        if _labelled(ds):
            ds_items.append(Table(label, ds.frame, caption=f"{ds.name}: a small labelled table, shown as it is"))
        else:
            if ds.time_column is not None:
                ds_items += _time_series_figures(ds, label, units)
            else:
                ds_items += _scatter_figures(ds, label, manifest, units)
            ds_items.append(Table(f"{label}_metrics", metrics_table(ds, units), caption="Metrics per channel"
                                  + (" (engineers' units)" if units == "engineers" else "")))
        synth = ds.synthetic
        lines = ds.provenance or ["no provenance recorded in the file"]
        text = ("SYNTHETIC: " if synth else "") + f"{ds.format} {ds.name}; " + " | ".join(lines)
        sections.append(Section(f"Data: {ds.name}", ds_items, provenance=text, synthetic=synth))
    if params:
        sections.append(Section("Parameters used", params))
    return sections


def report_run_dir(run_dir, output=None, *, overwrite: bool = False,
                   progress: Callable[[str], None] | None = None, title: str | None = None,
                   units: str = "engineers") -> Path:
    """Write a self-contained HTML report of a results folder.

    Parameters
    ----------
    run_dir : str or Path
        Folder of results (CSV, Parquet chunks, MDF4, TOML, manifest.json).
    output : str or Path, optional
        Report folder to write; default ``RUN_DIR/report`` (left out when
        scanning, so a report can be written again with ``overwrite``).
    overwrite : bool
        Replace an existing report folder.
    progress : callable, optional
        Called with one message per step (``clutchlab report`` prints them on
        stderr).
    title : str, optional
        Page title; default ``"clutchlab report: <RUN_DIR name>"``.
    units : {"engineers", "si"}
        Units of figures and metrics (rpm, km/h, bar, °C, mm, kN, or the columns' SI units).

    Returns
    -------
    pathlib.Path
        The report's ``index.html``.

    Raises
    ------
    DataError
        No such folder, or nothing to report in it.
    FileExistsError
        The report folder exists and ``overwrite`` is false.
    """
    run_dir = Path(run_dir)
    output = Path(output) if output is not None else run_dir / DEFAULT_OUTPUT
    check_report_folder(output, overwrite)   # (before the scan: a folder of the user's is never replaced)
    if run_dir.exists() and output.exists() and (run_dir.resolve() == output.resolve()
                                                 or output.resolve() in run_dir.resolve().parents):
        raise ParameterError(f"{output}: holds the results folder {run_dir}: not replaced; give another folder")
    sections = run_sections(run_dir, output=output, progress=progress, units=units)
    if progress:
        progress(f"writing {output}")
    return write_report(sections, output, title=title or f"clutchlab report: {run_dir.resolve().name}",
                        overwrite=overwrite, progress=progress)
