"""Run a sweep in chunks: locally, in worker processes or on a Dask cluster, resumable.

Layout of a results folder::

    results/
      manifest.json            spec hash, input files, n variants, chunk size, clutchlab version, provenance,
                               and per chunk file its SHA-256 and content checksum
      chunks/chunk-00000.parquet   variant_id, parameter columns [SI], outputs -- one file per chunk,
                               its Parquet key-value metadata "clutchlab.sweep" holding the spec hash,
                               the chunk number and the content checksum
      chunks/chunk-00001.parquet
      ...
      results.parquet          all chunks, sorted by variant_id (written when every chunk is done)
      summary.csv              per output: count, n_nan, mean, std, min, quantiles, max
      summary.png              outputs against the swept parameters

Every file is written to a temporary sibling and moved into place
(``os.replace``), so a chunk file either exists complete or not at all; the
manifest records a chunk before the chunk file appears.  On start, a folder
holding the same spec (same hash: the same spec, referenced files, target and
clutchlab version) is resumed: finished chunks are kept and only the missing
ones run; temporary files left by a killed run are removed.  A folder holding
a different spec (or the same spec after a referenced file changed) is refused
unless ``force`` (which starts over).  A chunk file that is unreadable, not
recorded in the manifest, differs from the bytes recorded there, carries
another sweep's hash or values not matching its checksum is refused
(:class:`~clutchlab.errors.DataError` naming the file and the reason): it is
never mixed in, and never deleted for the user.  Worker processes end when the
process that started them dies (``PR_SET_PDEATHSIG`` on Linux, a watchdog on
the parent's pid elsewhere).  Chunks are computed by the calling process (each chunk a
compiled batch across the cores, where the model has one), by
``workers`` processes (:class:`concurrent.futures.ProcessPoolExecutor`), or by
a ``dask.distributed`` cluster; results are always written by the calling
process.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import datetime
import hashlib
import io
import json
import math
import multiprocessing
import os
import re
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .. import __version__
from .._process import die_with_parent
from ..errors import ClutchlabError, DataError, ParameterError
from ..io import atomic_to_csv, atomic_write_bytes, atomic_write_text
from .spec import VARIANT_ID, SweepSpec, check_scheduler, load_spec, spec_from_dict

__all__ = ["run_sweep", "SweepResult", "compute_chunk", "chunk_path", "read_results", "summarize",
           "MANIFEST", "CHUNK_DIR", "PROVENANCE"]

MANIFEST = "manifest.json"
CHUNK_DIR = "chunks"
RESULTS = "results.parquet"
SUMMARY_CSV = "summary.csv"
SUMMARY_PNG = "summary.png"
FORMAT = "clutchlab-sweep/2"
#: Parquet key-value metadata key of a chunk file
CHUNK_METADATA = b"clutchlab.sweep"
PROVENANCE = "synthetic: outputs of clutchlab model simulations (virtual rigs and bundled synthetic data, no measurement)"
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)

#: compiled parallel kernels are not called from two threads at once (Dask workers may be threads)
_RUN_LOCK = threading.Lock()


def chunk_path(output, index: int, n_chunks: int) -> Path:
    """Path of chunk ``index`` in the results folder ``output``: ``output/chunks/chunk-00017.parquet``.

    The number has at least 5 digits, more if ``n_chunks`` needs them.
    """
    width = max(5, len(str(max(n_chunks - 1, 0))))
    return Path(output) / CHUNK_DIR / f"chunk-{index:0{width}d}.parquet"


def compute_chunk(target, scenario, outputs, variants: pd.DataFrame) -> pd.DataFrame:
    """Run one chunk: ``target`` on ``variants`` in ``scenario``, keeping ``outputs``.

    Returns a table with ``variant_id``, the parameter columns and the
    outputs.  This is the task shipped to worker processes and Dask workers
    (it only needs clutchlab and the target module importable there).
    """
    with _RUN_LOCK:
        out = target.run(variants, scenario, outputs)
    frame = variants.copy()
    for name in outputs:
        frame[name] = out[name].to_numpy(dtype=float)
    frame = frame.reset_index()
    frame[VARIANT_ID] = frame[VARIANT_ID].astype(np.int64)
    return frame


def content_checksum(frame: pd.DataFrame) -> str:
    """SHA-256 over the column names, dtypes and values of a chunk table (independent of the file encoding)."""
    h = hashlib.sha256()
    for name in frame.columns:
        values = np.ascontiguousarray(frame[name].to_numpy())
        h.update(json.dumps([str(name), values.dtype.str, int(values.size)]).encode("utf-8"))
        h.update(values.tobytes())
    return h.hexdigest()


def _chunk_bytes(frame: pd.DataFrame, spec_hash: str, index: int, n_chunks: int) -> tuple[bytes, str]:
    """Parquet bytes of a chunk with its metadata, and the content checksum."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    checksum = content_checksum(frame)
    table = pa.Table.from_pandas(frame, preserve_index=False)
    meta = {"format": FORMAT, "spec_hash": spec_hash, "chunk": int(index), "n_chunks": int(n_chunks),
            "checksum": checksum}
    table = table.replace_schema_metadata({**(table.schema.metadata or {}), CHUNK_METADATA: json.dumps(meta).encode()})
    buf = io.BytesIO()
    pq.write_table(table, buf)
    return buf.getvalue(), checksum


def _refuse(path: Path, reason: str):
    raise DataError(f"{path}: {reason}; not used (delete this file to compute the chunk again, "
                    "or pass force=True / --force to start the sweep over)")


def _verified_chunk(path: Path, manifest: dict) -> tuple[pd.DataFrame, dict]:
    """Read a chunk file and check it against the manifest: (table, its metadata) or :class:`DataError`."""
    import pyarrow.parquet as pq

    try:
        data = path.read_bytes()
        table = pq.read_table(io.BytesIO(data))
    except Exception as exc:  # any parse failure: the file is not a chunk
        _refuse(path, f"not a readable Parquet file ({type(exc).__name__})")
    try:
        meta = json.loads(table.schema.metadata[CHUNK_METADATA])
        spec_hash, index, checksum = str(meta["spec_hash"]), int(meta["chunk"]), str(meta["checksum"])
    except (TypeError, KeyError, ValueError):
        _refuse(path, "no clutchlab sweep metadata (not written by clutchlab sweep)")
    if spec_hash != manifest.get("spec_hash"):
        _refuse(path, f"written by another sweep (spec hash {spec_hash[:12]}, this sweep {str(manifest.get('spec_hash'))[:12]})")
    entry = (manifest.get("chunks") or {}).get(path.name)
    if not isinstance(entry, dict):
        _refuse(path, f"not recorded in {MANIFEST} (copied here, or from another run)")
    if hashlib.sha256(data).hexdigest() != entry.get("sha256"):
        _refuse(path, f"its bytes differ from those recorded in {MANIFEST} (changed after it was written)")
    frame = table.to_pandas()
    if content_checksum(frame) != checksum or checksum != entry.get("checksum"):
        _refuse(path, "its values do not match its checksum")
    return frame, {**meta, "chunk": index}


# ----------------------------------------------------------------- progress
class _Bar:
    """Chunks done / total with the time left: tqdm if installed, else a plain line on stderr."""

    def __init__(self, total: int, done: int, enabled: bool):
        self.total, self.done, self.enabled = total, done, enabled
        self.t0 = time.perf_counter()
        self.start_done = done
        self._tqdm = None
        if not enabled:
            return
        try:
            from tqdm import tqdm
        except ImportError:
            self._draw()
        else:
            self._tqdm = tqdm(total=total, initial=done, unit="chunk", desc="sweep", file=sys.stderr,
                              dynamic_ncols=True, smoothing=0.1)

    def _draw(self):
        n_new = self.done - self.start_done
        elapsed = time.perf_counter() - self.t0
        left = (self.total - self.done) * elapsed / n_new if n_new else float("nan")
        width = 30
        filled = int(width * self.done / max(self.total, 1))
        eta = f"{left:.0f} s left" if math.isfinite(left) else "time left unknown"
        end = "\n" if self.done >= self.total else ""
        print(f"\rsweep [{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} chunks, {eta}   ",
              end=end, file=sys.stderr, flush=True)

    def update(self):
        self.done += 1
        if not self.enabled:
            return
        if self._tqdm is not None:
            self._tqdm.update(1)
        else:
            self._draw()

    def close(self):
        if self._tqdm is not None:
            self._tqdm.close()


# ----------------------------------------------------------------- folder handling
@contextlib.contextmanager
def _exclusive(output: Path):
    """Hold an OS lock on ``output/.lock`` (released by the OS if the process dies)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not on POSIX: no lock
        yield
        return
    lock = output / ".lock"
    fh = open(lock, "a+")
    held = False
    try:
        try:
            fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            # a lock file removed by the previous holder after we opened it locks nothing: same inode?
            held = lock.exists() and os.path.samestat(os.fstat(fh.fileno()), os.stat(lock))
        except OSError:
            pass
        if not held:
            raise ClutchlabError(f"{output}: another sweep is running in this folder")
        yield
    finally:
        if held:
            lock.unlink(missing_ok=True)  # while still holding it: no .lock stays behind
        fh.close()


def _clean_temporaries(output: Path) -> list[Path]:
    removed = []
    for folder in (output, output / CHUNK_DIR):
        if folder.is_dir():
            for tmp in folder.glob(".*.tmp"):
                if tmp.is_dir() and not tmp.is_symlink():
                    continue   # (a temporary folder, e.g. of a report written in here: clutchlab.io.files's)
                tmp.unlink(missing_ok=True)
                removed.append(tmp)
    return removed


def _manifest(spec: SweepSpec) -> dict:
    return {
        "format": FORMAT,
        "spec_hash": spec.hash,
        "spec_file": str(Path(spec.path).resolve()) if str(spec.path) != "<dict>" else "<dict>",
        "inputs": {label: digest for label, _, digest in spec.inputs},
        "model": spec.model,
        "target": spec.target.identity,
        "scenario": spec.scenario.get("_source") if spec.scenario else "bundled default of the model",
        "design": spec.kind,
        "seed": spec.seed,
        "n_variants": spec.n_variants,
        "chunk_size": spec.chunk_size,
        "n_chunks": spec.n_chunks,
        "parameters": dict(spec.units),
        "outputs": list(spec.outputs),
        "clutchlab_version": __version__,
        "provenance": PROVENANCE,
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "chunks": {},
    }


def _load_manifest(output: Path) -> dict | None:
    """The manifest of ``output`` if it is a readable manifest of this format, else None."""
    try:
        old = json.loads((output / MANIFEST).read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(old, dict) or old.get("format") != FORMAT or not isinstance(old.get("chunks"), dict) \
            or not isinstance(old.get("spec_hash"), str):
        return None
    return old


def _difference(old: dict | None, spec: SweepSpec) -> str:
    """Why the sweep in a folder is not ``spec``, in a few words."""
    if old is None:
        return "written by another clutchlab version or damaged"
    inputs = old.get("inputs") if isinstance(old.get("inputs"), dict) else {}
    now = {label: digest for label, _, digest in spec.inputs}
    changed = sorted(k for k in set(inputs) | set(now) if inputs.get(k) != now.get(k))
    if changed:
        return f"{', '.join(changed)} changed since it started"
    if old.get("target") != spec.target.identity:
        return f"target {old.get('target')!r} != {spec.target.identity!r}"
    return f"spec hash {old['spec_hash'][:12]} != {spec.hash[:12]}"


def _prepare(spec: SweepSpec, output: Path, force: bool) -> dict:
    """Create, resume or (with ``force``) reset the results folder; return its manifest."""
    mpath = output / MANIFEST
    if output.exists() and not output.is_dir():
        raise FileExistsError(f"{output} exists and is not a folder")
    if mpath.exists():
        old = _load_manifest(output)
        same = old is not None and old["spec_hash"] == spec.hash
        if same and not force:
            (output / CHUNK_DIR).mkdir(exist_ok=True)
            return old
        if not same and not force:
            raise FileExistsError(f"{output} holds a different sweep ({_difference(old, spec)}); "
                                  "pass force=True (CLI: --force) to start over")
    elif output.exists() and any(p.name != ".lock" for p in output.iterdir()) and not force:
        raise FileExistsError(f"{output} exists and is not a sweep folder (no {MANIFEST}); "
                              "pass force=True (CLI: --force) to use it")
    # start over: remove what a previous sweep wrote, and nothing else (a file of the user's in chunks/ stops it)
    chunks = output / CHUNK_DIR
    if chunks.is_symlink() or (chunks.exists() and not chunks.is_dir()):
        raise FileExistsError(f"{chunks} is not a folder the sweep wrote (a link or a file): not removed")
    if chunks.is_dir():
        ours = [p for p in chunks.iterdir() if p.is_file() and not p.is_symlink()
                and re.fullmatch(r"\.?chunk-\d+\.parquet(\.[\w.-]*tmp)?", p.name)]
        foreign = sorted(p.name for p in chunks.iterdir() if p not in ours)
        if foreign:
            raise FileExistsError(f"{chunks} holds {foreign[0]!r}, which the sweep did not write: not removed (even "
                                  "with --force); move it, or give another output folder")
        for path in ours:
            path.unlink()
    for name in (RESULTS, SUMMARY_CSV, SUMMARY_PNG, MANIFEST):
        (output / name).unlink(missing_ok=True)
    (output / CHUNK_DIR).mkdir(parents=True, exist_ok=True)
    manifest = _manifest(spec)
    _save_manifest(output, manifest)
    return manifest


def _save_manifest(output: Path, manifest: dict) -> None:
    atomic_write_text(output / MANIFEST, json.dumps(manifest, indent=2) + "\n", overwrite=True)


def _existing_chunks(spec: SweepSpec, output: Path, manifest: dict) -> list[int]:
    """Chunks already done, each checked against the manifest and the design; anything else is refused."""
    expected = {chunk_path(output, k, spec.n_chunks).name: k for k in range(spec.n_chunks)}
    columns = [VARIANT_ID, *spec.parameters, *spec.outputs]
    done = []
    for path in sorted((output / CHUNK_DIR).glob("chunk-*.parquet")):
        if path.name not in expected:
            _refuse(path, f"not a chunk of this sweep ({spec.n_chunks} chunks)")
        k = expected[path.name]
        frame, meta = _verified_chunk(path, manifest)
        if meta["chunk"] != k or list(frame.columns) != columns \
                or not np.array_equal(frame[VARIANT_ID].to_numpy(), spec.chunk(k).index.to_numpy()):
            _refuse(path, f"does not hold the variants and columns of chunk {k} of this sweep")
        done.append(k)
    return sorted(done)


# ----------------------------------------------------------------- executors
def _die_with_parent(parent_pid: int, poll: float = 0.5) -> None:
    """End this worker when ``parent_pid`` dies, even by SIGKILL (:func:`clutchlab._process.die_with_parent`)."""
    die_with_parent(parent_pid, poll, name="clutchlab-sweep-parent-watchdog")


def _worker_init(parent_pid: int | None = None, components=()):
    """Die with the parent; one compiled thread per worker process (the processes are the parallelism); the
    parent's registered components (:func:`clutchlab.component.component_sources`: a component registered by a
    module of the user's, not only by an installed package's entry point, is known to the workers too)."""
    if parent_pid is not None:
        _die_with_parent(parent_pid)
    from ..component import load_component_sources

    load_component_sources(components)
    try:
        import numba

        numba.set_num_threads(1)
    except Exception:  # pragma: no cover - numba missing or layer not yet chosen
        pass


def _run_local(spec, todo, write, bar):
    for k in todo:
        write(k, compute_chunk(spec.target, spec.scenario, spec.outputs, spec.chunk(k)))
        bar.update()


def _run_processes(spec, todo, write, bar, workers):
    ctx = multiprocessing.get_context("spawn")  # no fork of a process that may hold compiled thread pools
    from ..component import component_sources

    with cf.ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_worker_init,
                                initargs=(os.getpid(), component_sources())) as pool:
        futures = {pool.submit(compute_chunk, spec.target, spec.scenario, spec.outputs, spec.chunk(k)): k for k in todo}
        try:
            for fut in cf.as_completed(futures):
                write(futures[fut], fut.result())
                bar.update()
        except BaseException:
            for fut in futures:
                fut.cancel()
            raise


def _run_dask(spec, todo, write, bar, scheduler):
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise ClutchlabError("--scheduler needs dask.distributed: pip install 'clutchlab[dask]'") from None
    own = not hasattr(scheduler, "submit")
    try:
        client = Client(scheduler, timeout="20s") if own else scheduler
    except OSError as exc:
        raise ClutchlabError(f"cannot reach the Dask scheduler {scheduler!r} ({exc})") from None
    try:
        futures = {}
        for k in todo:
            fut = client.submit(compute_chunk, spec.target, spec.scenario, spec.outputs, spec.chunk(k),
                                key=f"clutchlab-sweep-{spec.hash[:16]}-chunk-{k}", retries=1)
            futures[fut] = k
        try:
            for fut in as_completed(list(futures)):
                write(futures[fut], fut.result())
                bar.update()
        except BaseException:
            client.cancel(list(futures))
            raise
    finally:
        if own:
            client.close()


# ----------------------------------------------------------------- results
@dataclass
class SweepResult:
    """Result of :func:`run_sweep`.

    Attributes
    ----------
    output : Path
        Results folder.
    spec : SweepSpec
        The spec that ran.
    computed : list of int
        Chunks computed by this call.
    reused : list of int
        Chunks found finished and kept (resume).
    results : pandas.DataFrame
        All variants (``variant_id``, parameters [SI], outputs), sorted by id.
    summary : pandas.DataFrame
        Statistics per output (index: output name).
    """

    output: Path
    spec: SweepSpec
    computed: list
    reused: list
    results: pd.DataFrame
    summary: pd.DataFrame

    def to_dataframe(self) -> pd.DataFrame:
        """All variants as a DataFrame (``results``)."""
        return self.results


def read_results(output) -> pd.DataFrame:
    """Read every chunk of the results folder ``output``, sorted by ``variant_id`` (finished or interrupted sweep).

    Every chunk file is checked against ``manifest.json`` first (recorded
    there, same bytes, this sweep's hash, values matching the checksum);
    :class:`~clutchlab.errors.DataError` names the first that is not.
    """
    output = Path(output)
    folder = output / CHUNK_DIR
    manifest = _load_manifest(output)
    if manifest is None:
        raise DataError(f"{output}: no readable {MANIFEST} of a clutchlab sweep ({FORMAT})")
    files = sorted(folder.glob("chunk-*.parquet"))
    if not files:
        raise DataError(f"{output}: no chunk files in {folder}")
    frame = pd.concat([_verified_chunk(f, manifest)[0] for f in files], ignore_index=True)
    if frame[VARIANT_ID].duplicated().any():
        raise DataError(f"{output}: chunks hold variant {int(frame[VARIANT_ID][frame[VARIANT_ID].duplicated()].iloc[0])} twice")
    return frame.sort_values(VARIANT_ID, kind="stable").reset_index(drop=True)


def summarize(results: pd.DataFrame, outputs, units: dict | None = None) -> pd.DataFrame:
    """Statistics of each of ``outputs`` over the rows of ``results``.

    Parameters
    ----------
    results : pandas.DataFrame
        One row per variant.
    outputs : list of str
        Columns to summarise.
    units : dict, optional
        Unit per output (pint spelling, ``"kg*m**2"``), written into the table as printed (``"kg·m²"``).

    Returns
    -------
    pandas.DataFrame
        Index ``output``; columns ``unit``, ``count`` (finite values),
        ``n_nan``, ``mean``, ``std`` (ddof 1), ``min``, ``q05``, ``q25``,
        ``median``, ``q75``, ``q95`` (linear interpolation,
        :func:`numpy.quantile`, over the finite values) and ``max``.
    """
    rows = []
    for name in outputs:
        v = results[name].to_numpy(dtype=float)
        f = v[np.isfinite(v)]
        unit = (units or {}).get(name)
        row = {"output": name, "unit": _printed(unit) if unit else "", "count": int(f.size),
               "n_nan": int(v.size - f.size)}
        if f.size:
            q = np.quantile(f, QUANTILES)
            row.update(mean=float(f.mean()), std=float(f.std(ddof=1)) if f.size > 1 else float("nan"),
                       min=float(f.min()), q05=q[0], q25=q[1], median=q[2], q75=q[3], q95=q[4], max=float(f.max()))
        else:
            row.update({k: float("nan") for k in ("mean", "std", "min", "q05", "q25", "median", "q75", "q95", "max")})
        rows.append(row)
    return pd.DataFrame(rows).set_index("output")


def _printed(unit) -> str:
    """A unit in an axis label as printed (``kg·m²``, not pint's ``kg*m**2``; ``1`` for none)."""
    from ..units import unit_label

    return "1" if unit in (None, "", "1") else unit_label(unit)


#: at most this many swept parameters (columns) and outputs (rows) in ``summary.png``
MAX_PLOT_PARAMETERS = MAX_PLOT_OUTPUTS = 6


def _figure(results: pd.DataFrame, spec: SweepSpec, units: dict):
    """The figure of ``summary.png``: each output against each swept parameter, in units as printed; the title
    names every parameter and output left out."""
    import textwrap

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    params = list(spec.parameters)[:MAX_PLOT_PARAMETERS]
    outs = list(spec.outputs)[:MAX_PLOT_OUTPUTS]
    fig, axes = plt.subplots(len(outs), len(params), figsize=(3.4 * len(params) + 0.6, 2.7 * len(outs) + 0.8),
                             squeeze=False, constrained_layout=True)
    alpha = float(np.clip(30.0 / max(len(results), 1) ** 0.5, 0.15, 0.9))
    for i, out in enumerate(outs):
        for j, par in enumerate(params):
            ax = axes[i, j]
            x = results[par].to_numpy(dtype=float)
            y = results[out].to_numpy(dtype=float)
            ax.scatter(x, y, s=8, alpha=alpha, color="tab:blue", edgecolors="none")
            if spec.kind == "grid":
                means = results.groupby(par)[out].mean()
                ax.plot(means.index.to_numpy(dtype=float), means.to_numpy(dtype=float), color="tab:red", lw=1.2,
                        label="mean over the other parameters")
                if i == 0 and j == 0 and len(params) > 1:
                    ax.legend(fontsize=7)
            if i == len(outs) - 1:
                ax.set_xlabel(f"{par} [{_printed(spec.units.get(par))}]", fontsize=8)
            if j == 0:
                ax.set_ylabel(f"{out} [{_printed(units.get(out))}]", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
    # #33: "the first 6 of 8 parameters" named none of the two left out
    cut = [f"{what} {', '.join(map(str, every[len(shown):]))}" for shown, every, what in
           ((params, list(spec.parameters), "parameters"), (outs, list(spec.outputs), "outputs"))
           if len(shown) < len(every)]
    note = f"not shown: {'; '.join(cut)} (all are in results.parquet)" if cut else ""
    width = max(60, int(fig.get_figwidth() * 72 / 6.0))   # characters of 10 pt across the figure
    fig.suptitle("\n".join([f"sweep of {spec.model!r}: {spec.n_variants} variants "
                            f"({spec.kind.replace('_', ' ')}; synthetic)"] + textwrap.wrap(note, width)), fontsize=10)
    return fig


def _plot(results: pd.DataFrame, spec: SweepSpec, units: dict) -> bytes:
    """``summary.png`` (:func:`_figure`) as PNG bytes."""
    import matplotlib.pyplot as plt

    fig = _figure(results, spec, units)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return buf.getvalue()


def _finish(spec: SweepSpec, output: Path, make_plot: bool):
    results = read_results(output)
    info = spec.target.describe(spec.scenario)
    units = info.outputs or {}
    buf = io.BytesIO()
    results.to_parquet(buf, index=False, engine="pyarrow")
    atomic_write_bytes(output / RESULTS, buf.getvalue(), overwrite=True)
    summary = summarize(results, spec.outputs, units)
    header = (f"{PROVENANCE}\nclutchlab {__version__} sweep of {spec.model!r}, {spec.n_variants} variants, "
              f"spec hash {spec.hash[:16]}\nquantiles linear over finite values; std with ddof=1")
    atomic_to_csv(summary.reset_index(), output / SUMMARY_CSV, overwrite=True, header_comment=header)
    if make_plot:
        atomic_write_bytes(output / SUMMARY_PNG, _plot(results, spec, units), overwrite=True)
    return results, summary


def run_sweep(spec, output, *, workers: int | None = None, scheduler=None, force: bool = False,
              progress: bool = True, plot: bool = True, log=None) -> SweepResult:
    """Run (or resume) a sweep and write its results folder.

    Parameters
    ----------
    spec : SweepSpec or str or Path or dict
        The spec (or its TOML file, read with :func:`~clutchlab.sweep.spec.load_spec`, or its tables as a
        dict, read with :func:`~clutchlab.sweep.spec.spec_from_dict`).
    output : str or Path
        Results folder (created; resumed if it holds the same spec).
    workers : int, optional
        Run chunks in this many worker processes (default: in this process,
        each chunk one compiled batch across the cores where the model has one).
    scheduler : str or dask.distributed.Client, optional
        Address of a Dask scheduler (``"tcp://host:8786"``) or a client: the
        chunks become Dask tasks; results are written here.
    force : bool
        Start over in a folder holding another (or the same) sweep.
    progress : bool
        Show a progress bar (chunks done / total, time left) on stderr.
    plot : bool
        Write ``summary.png``.
    log : callable, optional
        Called with one-line messages (start, cleanup, resume); the first comes only after every
        check that can refuse the sweep (arguments, lock, folder, existing chunks) has passed.

    Returns
    -------
    SweepResult

    Raises
    ------
    FileExistsError
        The folder holds a different sweep (or other files) and ``force`` is false.
    ParameterError
        Bad spec, or a variant the model rejects (naming the spec file, chunk and variant).
    """
    if isinstance(spec, dict):   # (a spec's tables as a TOML file holds them; files named relative to here)
        spec = spec_from_dict(spec)
    elif not isinstance(spec, SweepSpec):
        spec = load_spec(spec)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ParameterError(f"workers = {workers!r}: expected a whole number >= 1")
    if workers is not None and scheduler is not None:
        raise ParameterError("give either workers or scheduler, not both")
    check_scheduler(scheduler)
    log = log or (lambda msg: None)
    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    with _exclusive(output):
        changed = spec.changed_inputs()
        if changed:
            raise DataError(f"{spec.path}: {', '.join(changed)} changed after the spec was loaded; load it again")
        manifest = _prepare(spec, output, force)
        removed = _clean_temporaries(output)
        done = _existing_chunks(spec, output, manifest)
        todo = [k for k in range(spec.n_chunks) if k not in set(done)]
        # every refusal (arguments, lock, changed inputs, foreign folder, bad chunk files) came before this
        # first message: a refused sweep prints its error alone
        log(f"{spec.n_variants} variants of {spec.model!r} in {spec.n_chunks} chunks of {spec.chunk_size} -> {output}")
        if removed:
            log(f"removed {len(removed)} partial file(s) left by an interrupted run")
        if done:
            log(f"resuming: {len(done)} of {spec.n_chunks} chunks already done")

        def write(k, frame):
            changed = spec.changed_inputs()
            if changed:  # never record a chunk that may have read the new contents under the old hash
                raise DataError(f"{spec.path}: {', '.join(changed)} changed while the sweep ran; chunk {k} and "
                                "later ones were not kept (the folder now holds a different sweep: --force to start over)")
            path = chunk_path(output, k, spec.n_chunks)
            data, checksum = _chunk_bytes(frame, spec.hash, k, spec.n_chunks)
            manifest["chunks"][path.name] = {"sha256": hashlib.sha256(data).hexdigest(), "checksum": checksum}
            _save_manifest(output, manifest)  # recorded first: a kill between the two leaves a missing chunk, redone
            atomic_write_bytes(path, data, overwrite=True)

        bar = _Bar(spec.n_chunks, len(done), progress)
        try:
            if todo:
                try:
                    if scheduler is not None:
                        _run_dask(spec, todo, write, bar, scheduler)
                    elif workers is not None and workers > 1:
                        _run_processes(spec, todo, write, bar, workers)
                    else:
                        _run_local(spec, todo, write, bar)
                except ClutchlabError as exc:
                    msg = str(exc)
                    raise type(exc)(msg if msg.startswith(str(spec.path)) else f"{spec.path}: {msg}") from None
        finally:
            bar.close()
        results, summary = _finish(spec, output, plot)
    n_ids = results[VARIANT_ID].to_numpy()
    if not np.array_equal(n_ids, np.arange(spec.n_variants)):
        raise DataError(f"{output}: chunks do not hold every variant exactly once")
    return SweepResult(output, spec, todo, done, results, summary)
