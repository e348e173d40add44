"""Runner: atomic chunks, resume after a crash or a SIGKILL, worker processes and Dask give the same numbers."""

import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab import __version__
from clutchlab.errors import ClutchlabError, SimulationError
from clutchlab.sweep import load_spec, read_results, run_sweep, summarize
from clutchlab.sweep.runner import CHUNK_DIR, MANIFEST, chunk_path

HERE = pathlib.Path(__file__).parent
SRC = HERE.parents[1] / "src"

SPEC = """
[sweep]
model = "{model}"
outputs = ["engagement_time", "energy", "peak_temperature_c"]
chunk_size = 3
seed = 7
[monte_carlo]
n = 24
"clutch.r_outer" = {{ dist = "uniform", low = "80 mm", high = "86 mm" }}
"batch.mu_scale" = {{ dist = "normal", mean = 1.0, std = 0.05 }}
"""


@pytest.fixture
def test_target(registered_targets):
    """The test-only target (``wet``, failing on request), registered in this process."""
    return registered_targets["wet"]


def spec_file(tmp_path, model="wet", name="spec.toml", text=SPEC):
    path = tmp_path / name
    path.write_text(text.format(model=model))
    return path


def chunk_files(out):
    return sorted((out / CHUNK_DIR).glob("chunk-*.parquet"))


def assert_complete(out, n):
    """Every variant id present exactly once over all chunk files and in results.parquet."""
    ids = np.concatenate([pd.read_parquet(f)["variant_id"].to_numpy() for f in chunk_files(out)])
    np.testing.assert_array_equal(np.sort(ids), np.arange(n))
    combined = pd.read_parquet(out / "results.parquet")
    np.testing.assert_array_equal(combined["variant_id"].to_numpy(), np.arange(n))


def assert_same_results(a, b):
    """Results of two runs in *different processes* agree to 1e-12 relative.

    Within one process the runs are bitwise identical (test_resume_after_a_crash...). Across processes
    (a SIGKILLed and resumed CLI run, worker processes, Dask workers) one CI run on a cold numba cache
    showed differences in the last bit of a few energies; the cause was not found (see the closing note of
    the session that added this), so these comparisons allow 1e-12 -- far below any physical or numerical
    tolerance, and still failing for any real mix-up of variants or chunks.
    """
    pd.testing.assert_frame_equal(a, b, check_exact=False, rtol=1e-12, atol=0.0)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted local run of the wet spec."""
    tmp = tmp_path_factory.mktemp("ref")
    return run_sweep(spec_file(tmp), tmp / "out", progress=False)


def test_local_run_writes_chunks_manifest_and_summary(reference, tmp_path):
    out = reference.output
    spec = reference.spec
    assert [p.name for p in chunk_files(out)] == [f"chunk-{k:05d}.parquet" for k in range(8)]
    assert_complete(out, 24)
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["spec_hash"] == spec.hash and manifest["n_variants"] == 24 and manifest["chunk_size"] == 3
    assert manifest["clutchlab_version"] == __version__ and manifest["provenance"].startswith("synthetic")
    chunk = pd.read_parquet(chunk_path(out, 5, 8))
    assert list(chunk.columns) == ["variant_id", "clutch.r_outer", "batch.mu_scale", "engagement_time", "energy",
                                   "peak_temperature_c"]
    # parameter columns are the design (SI), outputs finite for this engagement
    np.testing.assert_array_equal(chunk[["clutch.r_outer", "batch.mu_scale"]].to_numpy(), spec.chunk(5).to_numpy())
    assert np.all(np.isfinite(reference.results[list(spec.outputs)].to_numpy()))
    # summary.csv holds the statistics of results.parquet
    summary = pd.read_csv(out / "summary.csv", comment="#").set_index("output")
    e = reference.results["energy"].to_numpy()
    assert summary.loc["energy", "count"] == 24 and summary.loc["energy", "n_nan"] == 0
    np.testing.assert_allclose(summary.loc["energy", ["mean", "std", "min", "median", "max"]].to_numpy(dtype=float),
                               [e.mean(), e.std(ddof=1), e.min(), np.median(e), e.max()], rtol=1e-8)
    assert summary.loc["energy", "unit"] == "J"
    png = (out / "summary.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    assert not list(out.glob(".*.tmp")) and not list((out / CHUNK_DIR).glob(".*.tmp"))


def test_summarize_counts_nan_and_quantiles():
    frame = pd.DataFrame({"a": [1.0, 2.0, 3.0, 4.0, np.nan]})
    s = summarize(frame, ["a"], {"a": "s"})
    assert s.loc["a", "count"] == 4 and s.loc["a", "n_nan"] == 1
    assert s.loc["a", "median"] == 2.5 and s.loc["a", "q25"] == 1.75 and s.loc["a", "std"] == pytest.approx(np.std([1, 2, 3, 4], ddof=1))


def test_resume_after_a_crash_runs_only_the_missing_chunks(tmp_path, test_target, monkeypatch, reference):
    path = spec_file(tmp_path, model=test_target)
    out = tmp_path / "out"
    monkeypatch.setenv("CLUTCHLAB_SWEEP_TEST_FAIL_ID", "13")          # chunk 4 fails
    with pytest.raises(SimulationError, match=r"spec\.toml.*variant 13"):
        run_sweep(path, out, progress=False)
    first = {p.name: p.stat().st_mtime_ns for p in chunk_files(out)}
    assert sorted(first) == [f"chunk-{k:05d}.parquet" for k in range(4)]  # chunks 0-3 were kept
    assert not (out / "results.parquet").exists()
    monkeypatch.delenv("CLUTCHLAB_SWEEP_TEST_FAIL_ID")
    res = run_sweep(path, out, progress=False)
    assert res.reused == [0, 1, 2, 3] and res.computed == [4, 5, 6, 7]
    assert {p.name: p.stat().st_mtime_ns for p in chunk_files(out)[:4]} == first   # not rewritten
    assert_complete(out, 24)
    pd.testing.assert_frame_equal(res.results, reference.results, check_exact=True)


def test_sigkill_mid_sweep_then_resume(tmp_path, plugins, reference):
    """Kill the process computing the chunks (SIGKILL), rerun: every variant once, values of the uninterrupted run.

    The target is the installed test plugin (entry point ``plugin-wet``), found the same way by the CLI
    subprocess and by this process.
    """
    path = spec_file(tmp_path, model="plugin-wet")
    out = tmp_path / "out"
    env = dict(os.environ, CLUTCHLAB_SWEEP_TEST_DELAY="0.4",
               PYTHONPATH=os.pathsep.join([str(plugins), str(SRC), os.environ.get("PYTHONPATH", "")]))
    env.pop("CLUTCHLAB_SWEEP_TEST_FAIL_ID", None)
    proc = subprocess.Popen([sys.executable, "-m", "clutchlab.cli", "sweep", str(path), "-o", str(out), "--no-progress"],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            if (out / CHUNK_DIR).is_dir() and len(chunk_files(out)) >= 2:
                break
            time.sleep(0.02)
        assert proc.poll() is None, f"sweep ended before it could be killed: {proc.stderr.read().decode()}"
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL
    survivors = {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in chunk_files(out)}
    assert 2 <= len(survivors) < 8 and not (out / "results.parquet").exists()
    # a partial temporary file, as a kill during a write leaves it, is ignored and removed
    stale = out / CHUNK_DIR / ".chunk-00007.parquet.x1y2.tmp"
    stale.write_bytes(b"PAR1 half a file")
    res = run_sweep(path, out, progress=False)
    assert len(res.reused) == len(survivors) and len(res.reused) + len(res.computed) == 8
    assert {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in chunk_files(out) if p.name in survivors} == survivors
    assert not stale.exists()
    assert_complete(out, 24)
    assert_same_results(res.results, reference.results)


def test_dask_local_cluster_gives_the_local_results(tmp_path, reference):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster:
        res = run_sweep(spec_file(tmp_path), tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False)
    assert res.computed == list(range(8))
    assert_same_results(res.results, reference.results)
    for k in range(8):
        assert_same_results(pd.read_parquet(chunk_path(res.output, k, 8)),
                            pd.read_parquet(chunk_path(reference.output, k, 8)))


def test_worker_processes_give_the_local_results(tmp_path, reference):
    res = run_sweep(spec_file(tmp_path), tmp_path / "proc", workers=2, progress=False)
    assert_same_results(res.results, reference.results)


def test_other_spec_is_refused_unless_forced(tmp_path):
    out = tmp_path / "out"
    small = SPEC.replace("n = 24", "n = 6")
    run_sweep(spec_file(tmp_path, text=small), out, progress=False, plot=False)
    other = spec_file(tmp_path, name="other.toml", text=small.replace("seed = 7", "seed = 8"))
    with pytest.raises(FileExistsError, match="different sweep"):
        run_sweep(other, out, progress=False)
    res = run_sweep(other, out, force=True, progress=False, plot=False)
    assert res.computed == [0, 1] and json.loads((out / MANIFEST).read_text())["spec_hash"] == load_spec(other).hash
    assert_complete(out, 6)


def test_foreign_folder_is_refused(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(FileExistsError, match="not a sweep folder"):
        run_sweep(spec_file(tmp_path, text=SPEC.replace("n = 24", "n = 3")), out, progress=False)


def test_force_removes_the_sweeps_own_chunks_and_never_a_users_file(tmp_path):
    """Starting over (``--force``) removed the whole ``chunks/`` folder, user files in it too (#33): now it removes
    the chunks a sweep writes and refuses, before removing anything, a folder holding anything else."""
    out = tmp_path / "out"
    small = SPEC.replace("n = 24", "n = 6")
    run_sweep(spec_file(tmp_path, text=small), out, progress=False, plot=False)
    other = spec_file(tmp_path, name="other.toml", text=small.replace("seed = 7", "seed = 8"))
    (out / "chunks" / "my_notes.txt").write_text("keep me")
    before = sorted(p.name for p in (out / "chunks").iterdir())
    with pytest.raises(FileExistsError, match=r"holds 'my_notes\.txt', which the sweep did not write: not removed"):
        run_sweep(other, out, force=True, progress=False, plot=False)
    assert sorted(p.name for p in (out / "chunks").iterdir()) == before
    (out / "chunks" / "my_notes.txt").unlink()
    res = run_sweep(other, out, force=True, progress=False, plot=False)
    assert res.computed == [0, 1]
    assert_complete(out, 6)


def test_a_deleted_chunk_is_computed_again(tmp_path):
    out = tmp_path / "out"
    path = spec_file(tmp_path, text=SPEC.replace("n = 24", "n = 6"))
    first = run_sweep(path, out, progress=False, plot=False)
    chunk_path(out, 1, 2).unlink()
    res = run_sweep(path, out, progress=False, plot=False)
    assert res.reused == [0] and res.computed == [1]
    pd.testing.assert_frame_equal(res.results, first.results, check_exact=True)
    pd.testing.assert_frame_equal(read_results(out), first.results, check_exact=True)


def test_a_running_sweep_locks_its_folder(tmp_path):
    import fcntl

    out = tmp_path / "out"
    out.mkdir()
    with open(out / ".lock", "a+") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        with pytest.raises(ClutchlabError, match="another sweep"):
            run_sweep(spec_file(tmp_path, text=SPEC.replace("n = 24", "n = 3")), out, progress=False)


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("small")
    path = spec_file(tmp, text=SPEC.replace("n = 24", "n = 10").replace("chunk_size = 3", "chunk_size = 2"))
    return path, run_sweep(path, tmp / "full", progress=False, plot=False).results


@settings(max_examples=examples(12), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lost=st.sets(st.integers(0, 4)), stale=st.booleans())
def test_any_set_of_missing_chunks_is_redone_exactly(tmp_path_factory, small_run, lost, stale):
    """Whatever chunks an interruption lost, the resume computes exactly those and the results are unchanged."""
    path, full = small_run
    out = tmp_path_factory.mktemp("resume") / "out"
    run_sweep(path, out, progress=False, plot=False)
    for k in lost:
        chunk_path(out, k, 5).unlink()
        if stale:
            (out / CHUNK_DIR / f".chunk-{k:05d}.parquet.abc.tmp").write_bytes(b"partial")
    (out / "results.parquet").unlink()
    res = run_sweep(path, out, progress=False, plot=False)
    assert res.computed == sorted(lost) and res.reused == sorted(set(range(5)) - lost)
    assert_complete(out, 10)
    assert not list((out / CHUNK_DIR).glob(".*.tmp"))
    pd.testing.assert_frame_equal(res.results, full, check_exact=True)


def test_a_temporary_folder_in_the_results_folder_is_not_a_partial_file(tmp_path):
    """A report written into a sweep's folder assembles itself in a hidden ``.NAME.PID.XXXXXXXX.tmp`` folder
    (clutchlab.io.files.temporary_folder, #33); the sweep's clean-up of its own partial ``.*.tmp`` files on
    start removes those files and leaves such a folder to its owner (``unlink`` on it raised IsADirectoryError,
    and the sweep could not resume)."""
    from clutchlab.sweep.runner import _clean_temporaries

    (tmp_path / CHUNK_DIR).mkdir()
    partial = tmp_path / CHUNK_DIR / ".chunk-00001.parquet.x1y2.tmp"
    partial.write_bytes(b"PAR1 half a file")
    folder = tmp_path / ".report.4194305.abcdefgh.tmp"
    (folder / "figures").mkdir(parents=True)
    assert _clean_temporaries(tmp_path) == [partial]
    assert not partial.exists() and (folder / "figures").is_dir()
