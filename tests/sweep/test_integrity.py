"""A resumed sweep never mixes results: changed input files, tampered, foreign or unknown chunks are refused."""

import hashlib
import json
import pathlib
import shutil
from importlib import resources

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from clutchlab.errors import DataError
from clutchlab.sweep import load_spec, read_results, register_target, run_sweep, unregister_target
from clutchlab.sweep.runner import CHUNK_DIR, MANIFEST, chunk_path

PARABOLA = """
[sweep]
model = "{model}"
scenario = "scenario.toml"
outputs = ["y", "scale"]
chunk_size = 2
[grid]
a = [1.0, 2.0]
x = [0.5, 1.5, 2.5]
"""

STATIC = """
[sweep]
model = "eclutch-static"
scenario = "static.toml"
outputs = ["engaged_torque", "lift_off_position"]
chunk_size = 1
[grid]
"clutch.mu" = [0.25, 0.3]
"""


def parabola_folder(tmp_path, model, scale=2.0):
    """Spec + scenario (``scale``, and a data file the target never declares but the scenario names)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "table.csv").write_text("t,v\n0,1\n")
    (tmp_path / "scenario.toml").write_text(f'scale = {scale}\ntable = "table.csv"\n')
    spec = tmp_path / "spec.toml"
    spec.write_text(PARABOLA.format(model=model))
    return spec


def state(out):
    """Name -> (inode, mtime, bytes) of every file in a results folder, to show a refusal changed nothing."""
    return {str(p.relative_to(out)): (p.stat().st_ino, p.stat().st_mtime_ns, p.read_bytes())
            for p in sorted(out.rglob("*")) if p.is_file() and p.name != ".lock"}


def run(spec, out, **kw):
    return run_sweep(spec, out, progress=False, plot=False, **kw)


# ----------------------------------------------------------------- referenced files are part of the hash
def test_changed_curve_file_is_refused_and_force_uses_the_new_curve(tmp_path):
    curves = tmp_path / "curves"
    with resources.as_file(resources.files("clutchlab.eclutch") / "data" / "curves") as bundled:
        shutil.copytree(bundled, curves)
    (tmp_path / "static.toml").write_text('[eclutch.curves]\nfolder = "curves"\n[static]\nmodel = 0\npoints = 61\n')
    spec = tmp_path / "spec.toml"
    spec.write_text(STATIC)
    assert "curves/diaphragm.csv" in [label for label, _, _ in load_spec(spec).inputs]
    out = tmp_path / "out"
    first = run(spec, out)
    before = state(out)
    # a stiffer diaphragm: every force 10 % higher
    path = curves / "diaphragm.csv"
    lines = path.read_text().splitlines()
    k = lines.index("deflection_m,force_N") + 1
    lines[k:] = [f"{d},{float(f) * 1.1!r}" for d, f in (line.split(",") for line in lines[k:])]
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(FileExistsError, match=r"different sweep \(curves/diaphragm\.csv changed since it started\)"):
        run(spec, out)
    assert state(out) == before
    again = run(spec, out, force=True)
    assert again.computed == [0, 1] and again.reused == []
    # the new curve is used in this process (no cached old curve): the lift-off position moves
    assert not np.allclose(again.results["lift_off_position"], first.results["lift_off_position"], rtol=1e-9, atol=0)


@pytest.mark.parametrize("change", ["scenario value", "scenario comment", "undeclared data file"])
def test_any_change_of_a_referenced_file_refuses_the_resume_of_an_interrupted_sweep(
        tmp_path, registered_targets, change):
    spec = parabola_folder(tmp_path, registered_targets["parabola"])
    out = tmp_path / "out"
    run(spec, out)
    chunk_path(out, 2, 3).unlink()        # as if interrupted before the last chunk
    (out / "results.parquet").unlink()
    if change == "scenario value":
        (tmp_path / "scenario.toml").write_text('scale = 3.0\ntable = "table.csv"\n')
        changed = "scenario.toml"
    elif change == "scenario comment":
        (tmp_path / "scenario.toml").write_text('# same values\nscale = 2.0\ntable = "table.csv"\n')
        changed = "scenario.toml"
    else:
        (tmp_path / "table.csv").write_text("t,v\n0,2\n")
        changed = "table.csv"
    before = state(out)
    with pytest.raises(FileExistsError, match=rf"different sweep \({changed} changed since it started\)"):
        run(spec, out)
    assert state(out) == before and not chunk_path(out, 2, 3).exists()


def test_a_file_changed_while_the_sweep_runs_stops_it_before_its_chunk_is_kept(tmp_path):
    spec = parabola_folder(tmp_path, "touching")
    table = tmp_path / "table.csv"

    def touching(variants, scenario, outputs):  # edits a referenced file while chunk 1 runs
        if 2 in variants.index:
            table.write_text("t,v\n0,5\n")
        return pd.DataFrame({"y": variants["a"] * variants["x"] ** 2, "scale": 1.0}, index=variants.index)

    register_target("touching", touching)
    try:
        with pytest.raises(DataError, match=r"spec\.toml: table\.csv changed while the sweep ran; chunk 1"):
            run(spec, tmp_path / "out")
    finally:
        unregister_target("touching")
    manifest = json.loads((tmp_path / "out" / MANIFEST).read_text())
    assert sorted(manifest["chunks"]) == ["chunk-00000.parquet"]
    assert [p.name for p in sorted((tmp_path / "out" / CHUNK_DIR).glob("chunk-*"))] == ["chunk-00000.parquet"]


# ----------------------------------------------------------------- chunk files are checked against the manifest
@pytest.fixture
def finished(tmp_path, registered_targets):
    spec = parabola_folder(tmp_path / "a", registered_targets["parabola"])
    out = tmp_path / "a" / "out"
    res = run(spec, out)
    return spec, out, res


def test_chunks_record_the_spec_hash_and_checksum_in_parquet_metadata_and_the_manifest(finished):
    spec, out, res = finished
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["inputs"] == {"scenario.toml": hashlib.sha256((spec.parent / "scenario.toml").read_bytes()).hexdigest(),
                                  "table.csv": hashlib.sha256((spec.parent / "table.csv").read_bytes()).hexdigest()}
    for k in range(3):
        path = chunk_path(out, k, 3)
        meta = json.loads(pq.read_schema(path).metadata[b"clutchlab.sweep"])
        assert meta["spec_hash"] == res.spec.hash == manifest["spec_hash"] and meta["chunk"] == k
        entry = manifest["chunks"][path.name]
        assert entry["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
        assert entry["checksum"] == meta["checksum"]


def _flip_byte(path):
    data = bytearray(path.read_bytes())
    i = len(data) // 3
    data[i] ^= 0x01
    path.write_bytes(bytes(data))


def _tamper_values(path, out, update_manifest):
    """Change one output value, keeping the chunk's metadata (and, if asked, re-recording the file's bytes)."""
    table = pq.read_table(path)
    frame = table.to_pandas()
    frame.loc[0, "y"] += 1.0
    import pyarrow as pa

    new = pa.Table.from_pandas(frame, preserve_index=False).replace_schema_metadata(table.schema.metadata)
    pq.write_table(new, path)
    if update_manifest:
        manifest = json.loads((out / MANIFEST).read_text())
        manifest["chunks"][path.name]["sha256"] = hashlib.sha256(path.read_bytes()).hexdigest()
        (out / MANIFEST).write_text(json.dumps(manifest))


@pytest.mark.parametrize("tamper, reason", [
    ("flip a byte", "not a readable Parquet file|its bytes differ from those recorded|its values do not match"),
    ("garbage", "not a readable Parquet file"),
    ("edit a value", "its bytes differ from those recorded in manifest.json"),
    ("edit a value and the manifest", "its values do not match its checksum"),
    ("plain parquet", "no clutchlab sweep metadata"),
])
def test_a_tampered_chunk_is_refused_on_resume_and_on_reading(finished, tamper, reason):
    spec, out, _ = finished
    path = chunk_path(out, 1, 3)
    if tamper == "flip a byte":
        _flip_byte(path)
    elif tamper == "garbage":
        path.write_bytes(b"not parquet")
    elif tamper == "plain parquet":
        pd.read_parquet(path).to_parquet(path, index=False)
    else:
        _tamper_values(path, out, update_manifest=tamper.endswith("manifest"))
    (out / "results.parquet").unlink()
    before = state(out)
    with pytest.raises(DataError, match=rf"chunk-00001\.parquet: ({reason}).*not used"):
        run(spec, out)
    assert state(out) == before
    with pytest.raises(DataError, match=rf"chunk-00001\.parquet: ({reason})"):
        read_results(out)


def test_a_chunk_of_another_sweep_is_refused(tmp_path, finished, registered_targets):
    spec, out, _ = finished
    other_spec = parabola_folder(tmp_path / "b", registered_targets["parabola"], scale=5.0)
    other = tmp_path / "b" / "out"
    run(other_spec, other)
    chunk_path(out, 2, 3).unlink()
    (out / "results.parquet").unlink()
    shutil.copy(chunk_path(other, 2, 3), chunk_path(out, 2, 3))
    before = state(out)
    with pytest.raises(DataError, match=r"chunk-00002\.parquet: written by another sweep"):
        run(spec, out)
    assert state(out) == before


def test_a_chunk_of_the_same_spec_not_recorded_in_this_manifest_is_refused(tmp_path, finished, registered_targets):
    """A chunk from a folder running the very same spec carries the same hash -- but this manifest never recorded it."""
    spec, out, _ = finished
    twin = tmp_path / "a" / "twin"
    run(spec, twin)
    chunk_path(out, 0, 3).unlink()
    manifest = json.loads((out / MANIFEST).read_text())
    del manifest["chunks"]["chunk-00000.parquet"]
    (out / MANIFEST).write_text(json.dumps(manifest))
    shutil.copy(chunk_path(twin, 0, 3), chunk_path(out, 0, 3))
    with pytest.raises(DataError, match=r"chunk-00000\.parquet: not recorded in manifest\.json"):
        run(spec, out)
    (out / CHUNK_DIR / "chunk-00000.parquet").unlink()                # the user removes it: computed again
    res = run(spec, out)
    assert res.computed == [0] and res.reused == [1, 2]
    pd.testing.assert_frame_equal(res.results, read_results(twin), check_exact=True)


def test_an_extra_chunk_file_is_refused(finished):
    spec, out, _ = finished
    shutil.copy(chunk_path(out, 0, 3), out / CHUNK_DIR / "chunk-00099.parquet")
    with pytest.raises(DataError, match=r"chunk-00099\.parquet: not a chunk of this sweep"):
        run(spec, out)


def test_the_hash_follows_file_contents_not_the_folder_they_are_in(tmp_path, registered_targets):
    spec = parabola_folder(tmp_path / "here", registered_targets["parabola"])
    moved = tmp_path / "there"
    shutil.copytree(tmp_path / "here", moved)
    assert load_spec(moved / "spec.toml").hash == load_spec(spec).hash
    (moved / "table.csv").write_text("t,v\n0,1\n1,1\n")
    assert load_spec(moved / "spec.toml").hash != load_spec(spec).hash


def test_the_run_report_shows_the_chunk_records_as_one_manifest_row(finished):
    from clutchlab.report.html import Table
    from clutchlab.report.run import run_sections

    _, out, _ = finished
    tables = [item for sec in run_sections(out) for item in sec.items
              if isinstance(item, Table) and item.name == "manifest"]
    assert len(tables) == 1
    rows = tables[0].frame
    chunk_rows = rows[rows["field"].str.startswith("chunks")]
    assert chunk_rows["value"].tolist() == ["3 chunk files recorded (SHA-256 and content checksum)"]
    assert "inputs.table.csv" in rows["field"].tolist()
