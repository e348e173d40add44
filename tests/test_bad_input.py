"""Bad input at the edges: files, outputs, resources and the command line.

Every case runs the ``clutchlab`` command (in-process through
:func:`clutchlab.cli.main`, a few in a subprocess to prove that no traceback
reaches the terminal) and checks: exit code 2, exactly one stderr line
``clutchlab: error: ...`` of at most 400 characters naming the file, field
and value at fault, and no new file in the working folder (a refused command
leaves nothing behind: no output, no hidden temporary file, no ``.lock``).
"""

from __future__ import annotations

import errno
import io
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

import clutchlab
from clutchlab._limits import MEMORY_ENV, check_allocation, memory_budget, one_line, short_repr
from clutchlab.cli import MESSAGE_LIMIT, error_message, main
from clutchlab.errors import DataError, ParameterError
from clutchlab.io import write_measurement
from clutchlab.io.files import atomic_write_text, check_writable, read_json, read_toml, remove_stale_temporaries

SRC = Path(clutchlab.__file__).resolve().parents[1]
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _listing(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def refused(argv, folder: Path, capsys, *fragments: str, log: str | None = None) -> str:
    """Run the CLI; assert a one-line error containing ``fragments`` and no new file in ``folder``.

    ``log``: prefix of progress lines the command may print before the error.
    """
    before = _listing(folder)
    capsys.readouterr()
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert rc == 2, err
    lines = [line for line in err.splitlines() if log is None or not line.startswith(log)]
    assert len(lines) == 1, err
    assert lines[0].startswith("clutchlab: error: "), err
    assert "Traceback" not in err
    assert len(lines[0]) <= 320, len(lines[0])
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    assert _listing(folder) == before, _listing(folder) ^ before
    return lines[0]


@pytest.fixture
def work(tmp_path, monkeypatch):
    """A fresh working folder as the current directory."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _record(path: Path, n: int = 50) -> Path:
    t = np.arange(n) * 1e-3
    frame = pd.DataFrame({"time_s": t, "force_N": 100.0 * np.sin(40 * t) + 200.0,
                          "displacement_m": 1e-3 * np.sin(40 * t)})
    write_measurement(frame, path)
    return path


# ----------------------------------------------------------------------------- files that cannot be read

def test_header_only_csv(work, capsys):
    (work / "empty.csv").write_text("time_s,force_N,displacement_m\n")
    refused(["convert", "empty.csv", "-o", "out.csv"], work, capsys, "empty.csv", "no samples")
    refused(["eclutch", "characterize", "empty.csv", "-o", "curve.csv"], work, capsys, "empty.csv", "no samples")


@pytest.mark.parametrize("argv", [
    ["params", "check", "bad.toml"],
    ["eclutch", "simulate", "bad.toml", "-o", "out.csv"],
    ["wet", "simulate", "bad.toml", "-o", "out.csv"],
    ["emtc", "simulate", "bad.toml", "-o", "out.csv"],
    ["sweep", "bad.toml", "-o", "results"],
    ["export-fmu", "driveline", "bad.toml", "-o", "bad.fmu"],
])
def test_toml_not_utf8(work, capsys, argv):
    (work / "bad.toml").write_bytes(b"[scenario]\nmodel = 4\n# caf\xe9 in Latin-1\n")
    refused(argv, work, capsys, "bad.toml", "not a UTF-8 text file", "xe9")


@pytest.mark.parametrize("argv", [
    ["params", "check", "deep.toml"],
    ["eclutch", "simulate", "deep.toml", "-o", "out.csv"],
    ["convert", "rec.csv", "--channel-map", "deep.toml", "-o", "out.csv"],
])
def test_toml_nested_too_deeply(work, capsys, argv):
    _record(work / "rec.csv")
    (work / "deep.toml").write_text("x = " + "[" * 50_000 + "]" * 50_000 + "\n")
    refused(argv, work, capsys, "deep.toml", "nested too deeply")


def test_json_not_utf8_deep_or_invalid(work, capsys):
    _record(work / "rec.csv")
    (work / "latin.json").write_bytes(b'{"kind": "caf\xe9"}')
    (work / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    (work / "broken.json").write_text('{"kind": ')
    (work / "list.json").write_text("[1, 2]")
    refused(["emtc", "preisach", "run", "latin.json", "rec.csv", "-o", "o.csv"], work, capsys,
            "latin.json", "not a UTF-8 text file")
    refused(["emtc", "preisach", "run", "deep.json", "rec.csv", "-o", "o.csv"], work, capsys,
            "deep.json", "nested too deeply")
    refused(["emtc", "preisach", "run", "broken.json", "rec.csv", "-o", "o.csv"], work, capsys,
            "broken.json", "not valid JSON")
    refused(["emtc", "preisach", "run", "list.json", "rec.csv", "-o", "o.csv"], work, capsys,
            "list.json", "not a clutchlab Preisach model")
    with pytest.raises(DataError, match="deep.json: JSON nested too deeply"):
        from clutchlab.wet.friction import FrictionMap

        FrictionMap.from_json(work / "deep.json")
    with pytest.raises(DataError, match="list.json: expected a friction map"):
        FrictionMap.from_json(work / "list.json")


def test_reader_errors_name_the_file(tmp_path):
    (tmp_path / "a.toml").write_text("x = = 1\n")
    with pytest.raises(ParameterError, match=r"a.toml: not valid TOML \(") as info:
        read_toml(tmp_path / "a.toml")
    assert "\n" not in str(info.value)
    with pytest.raises(DataError, match="nope.json: no such JSON file"):
        read_json(tmp_path / "nope.json")
    with pytest.raises(ParameterError, match="is a folder, not a TOML file"):
        read_toml(tmp_path)


# ----------------------------------------------------------------------------- wrong types in scenario files

@pytest.mark.parametrize("body, fragments", [
    ('scenario = "x"\n', ["scen.toml", "scenario = 'x'", "expected a table"]),
    ('[input]\nkind = ["pedal"]\ntime_s = [0, 1]\nvalue = [0, 1]\n', ["scen.toml", "[input] kind = ['pedal']"]),
    ('[input]\nkind = "pedal"\nfile = 3\n', ["scen.toml", "[input] file = 3", "path of a CSV file"]),
    ('[input]\nkind = "pedal"\nfile = "missing.csv"\n', ["scen.toml", "missing.csv", "no such file"]),
    ('input = [1, 2]\n', ["scen.toml", "input = [1, 2]", "expected a table"]),
])
def test_eclutch_scenario_types(work, capsys, body, fragments):
    (work / "scen.toml").write_text(body)
    refused(["eclutch", "simulate", "scen.toml", "-o", "out.csv"], work, capsys, *fragments)


@pytest.mark.parametrize("body, fragments", [
    ('scenario = "x"\n', ["scen.toml", "'x'"]),
    ('[magnet]\nmodel = 3\n', ["scen.toml", "[magnet] model = 3"]),
    ('magnet = "m.json"\n', ["scen.toml", "[magnet]", "'m.json'"]),
])
def test_emtc_scenario_types(work, capsys, body, fragments):
    (work / "scen.toml").write_text(body)
    refused(["emtc", "simulate", "scen.toml", "-o", "out.csv"], work, capsys, *fragments)


def test_wet_protocol_types(work, capsys):
    (work / "p.toml").write_text('protocol = "x"\n')
    refused(["wet", "simulate", "p.toml", "-o", "out.csv"], work, capsys, "p.toml", "[protocol]")
    (work / "p.toml").write_text('[protocol]\ntype = ["engagement"]\n')
    refused(["wet", "simulate", "p.toml", "-o", "out.csv"], work, capsys, "p.toml", "type = ['engagement']")


def test_huge_value_gives_a_short_message(work, capsys):
    (work / "scen.toml").write_text('[scenario]\nmodel = "' + "4" * 1_000_000 + '"\n')
    line = refused(["eclutch", "simulate", "scen.toml", "-o", "out.csv"], work, capsys, "scen.toml", "model = ")
    assert "..." in line
    big = np.arange(10_000_000, dtype=float)
    for value in (big, big.tolist()):
        with pytest.raises(ParameterError) as info:
            clutchlab.units.to_si(value, "m", name="[input] value")
        assert len(str(info.value)) < 200 and "[input] value" in str(info.value)


# ----------------------------------------------------------------------------- memory estimated before allocating

def test_allocation_checks_fire_before_memory_is_used(work, capsys, monkeypatch):
    from clutchlab.eclutch.models import ClutchModel

    monkeypatch.setenv(MEMORY_ENV, "1M")

    def must_not_run(*args, **kwargs):
        raise AssertionError("computed although the estimate exceeds the budget")

    monkeypatch.setattr(ClutchModel, "static_curve", must_not_run)
    refused(["eclutch", "static", "--model", "1", "--points", "100000", "-o", "out.csv"], work, capsys,
            "--points 100000", "memory budget of 1 MB", MEMORY_ENV)
    # under the budget the same command reaches the computation
    monkeypatch.setenv(MEMORY_ENV, "1G")
    with pytest.raises(AssertionError, match="computed although"):
        main(["eclutch", "static", "--model", "1", "--points", "100000", "-o", "out.csv"])


def test_huge_rate(work, capsys, monkeypatch):
    monkeypatch.setenv(MEMORY_ENV, "64M")
    _record(work / "rec.csv")
    refused(["convert", "rec.csv", "-o", "out.csv", "--rate", "1e9"], work, capsys,
            "rec.csv", "rate = 1e+09 Hz", "memory budget")


def test_non_finite_or_degenerate_arguments(work, capsys):
    _record(work / "rec.csv")
    refused(["convert", "rec.csv", "-o", "out.csv", "--rate", "1e-9"], work, capsys, "rec.csv", "rate = 1e-09 Hz",
            "single sample")
    refused(["wet", "identify", "rec.csv", "-o", "map.json", "--sensor-lag", "nan"], work, capsys,
            "--sensor-lag = nan")
    refused(["emtc", "preisach", "identify", "rec.csv", "-o", "m.json", "--grid", "0,1,nan"], work, capsys,
            "--grid '0,1,nan'", "finite")


def test_huge_duration_emtc(work, capsys, monkeypatch):
    from clutchlab.emtc import system as emtc_system

    monkeypatch.setenv(MEMORY_ENV, "256M")
    monkeypatch.setattr(emtc_system, "run", lambda *a, **k: (_ for _ in ()).throw(AssertionError("ran")))
    (work / "scen.toml").write_text('[scenario]\nduration = "1e6 s"\nramp_end = "1 s"\n')
    refused(["emtc", "simulate", "scen.toml", "-o", "out.csv"], work, capsys,
            "duration = 1000000.0 s", "sample_time = 0.002 s", "memory budget")


def test_huge_duration_wet(work, capsys, monkeypatch):
    monkeypatch.setenv(MEMORY_ENV, "256M")
    (work / "p.toml").write_text('[protocol]\ntype = "engagement"\nduration = "1e6 s"\n')
    refused(["wet", "simulate", "p.toml", "-o", "out.csv"], work, capsys,
            "duration = 1000000.0 s", "sample_rate", "memory budget")


def test_huge_output_grid_eclutch(work, capsys, monkeypatch):
    monkeypatch.setenv(MEMORY_ENV, "256M")
    text = (EXAMPLES / "eclutch_launch.toml").read_text().replace('t_end = "1.6 s"', 't_end = "1e6 s"')
    text = text.replace('output_step = "1 ms"', 'output_step = "1 us"')
    (work / "scen.toml").write_text(text)
    refused(["eclutch", "simulate", "scen.toml", "-o", "out.csv"], work, capsys, "scen.toml",
            "t_end = '1e6 s' at output_step = '1 us'", "memory budget")
    from clutchlab.eclutch.dynamics import EClutch  # the library checks too, naming the arguments

    with pytest.raises(ParameterError, match="output_step = 1e-06 s over t_end = 1000000.0 s"):
        EClutch.__new__(EClutch).simulate({"voltage": ([0.0, 1.0], [0.0, 0.0])}, 1e6, output_step=1e-6)


def test_memory_budget_setting(monkeypatch):
    monkeypatch.setenv(MEMORY_ENV, "3 GB")
    assert memory_budget() == 3 * 1024**3
    assert check_allocation(1000, 10, "x") == 80_000
    for bad in ("lots", "-1G", "0", "1 parsec"):
        monkeypatch.setenv(MEMORY_ENV, bad)
        with pytest.raises(ParameterError, match=MEMORY_ENV):
            memory_budget()
    # a budget below 64 KiB is not meaningful: tables up to that size pass, larger ones are refused
    monkeypatch.setenv(MEMORY_ENV, "1K")
    assert check_allocation(100, 80, "x") == 64_000
    with pytest.raises(ParameterError, match="memory budget of 1 KB"):
        check_allocation(100, 82, "x")
    monkeypatch.delenv(MEMORY_ENV)
    assert memory_budget() > 0
    with pytest.raises(ParameterError, match="what: would need"):
        check_allocation(1e30, 1, "what")
    with pytest.raises(ParameterError, match="not finite"):
        check_allocation(float("inf"), 1, "what")


# ----------------------------------------------------------------------------- outputs

def test_output_parent_is_a_file(work, capsys):
    (work / "afile").write_text("x")
    refused(["params", "show", "wet", "-o", "afile/x.toml"], work, capsys, "afile", "is a file, not a folder")
    refused(["eclutch", "static", "--model", "1", "-o", "afile/sub/x.csv"], work, capsys, "afile", "is a file")


def test_output_is_a_folder(work, capsys):
    (work / "folder").mkdir()
    refused(["params", "show", "wet", "-o", "folder"], work, capsys, "folder", "is a folder")


def test_existing_output_says_use_force(work, capsys):
    (work / "out.toml").write_text("mine")
    line = refused(["params", "show", "wet", "-o", "out.toml"], work, capsys, "out.toml", "use --force")
    assert "overwrite" not in line
    assert (work / "out.toml").read_text() == "mine"
    with pytest.raises(FileExistsError, match="pass overwrite=True"):  # the library speaks Python
        check_writable(work / "out.toml")


def test_refused_plot_leaves_no_output(work, capsys):
    (work / "fig.png").write_bytes(b"mine")
    refused(["eclutch", "static", "--model", "1", "--points", "5", "-o", "new.csv", "--plot", "fig.png"], work,
            capsys, "fig.png", "use --force")
    refused(["eclutch", "static", "--model", "1", "--points", "5", "-o", "same.png", "--plot", "same.png"], work,
            capsys, "same.png", "given twice")


def _fail_on(monkeypatch, name, err):
    import clutchlab.io.files as files

    def fail(*args, **kwargs):
        raise OSError(err, os.strerror(err))

    monkeypatch.setattr(files.os, name, fail)


@pytest.mark.parametrize("name, err, reason", [
    ("fsync", errno.ENOSPC, "no space left on the device"),
    ("replace", errno.EROFS, "read-only file system"),
    ("replace", errno.EACCES, "Permission denied"),
])
def test_disk_full_or_read_only(work, capsys, monkeypatch, name, err, reason):
    _fail_on(monkeypatch, name, err)
    refused(["params", "show", "wet", "-o", "out.toml"], work, capsys, "out.toml", reason)


def test_unwritable_folder_refused_before_work(work, capsys, monkeypatch):
    import clutchlab.io.files as files

    (work / "ro").mkdir()
    real_access = os.access
    # the test may run as root, for whom mode bits do not deny writing: report the folder read-only
    monkeypatch.setattr(files.os, "access", lambda p, mode: False if Path(p).resolve() == work / "ro" else real_access(p, mode))
    refused(["params", "show", "wet", "-o", "ro/x.toml"], work, capsys, "ro", "folder is not writable")
    refused(["params", "show", "wet", "-o", "ro/sub/x.toml"], work, capsys, "ro", "folder is not writable")
    assert main(["params", "show", "wet", "-o", "rw/x.toml"]) == 0


def test_last_resort_errors_are_one_line(work, capsys, monkeypatch):
    import clutchlab.params.registry as registry

    for exc, fragment in ((MemoryError(), "out of memory"), (RecursionError(), "nested too deeply"),
                          (UnicodeDecodeError("utf-8", b"\xff", 0, 1, "invalid start byte"), "not UTF-8"),
                          (IsADirectoryError(errno.EISDIR, "Is a directory", "some/dir"), "some/dir")):
        def boom(*args, _exc=exc, **kwargs):
            raise _exc

        monkeypatch.setattr(registry, "load_model_file", boom)
        refused(["params", "check", "x.toml"], work, capsys, fragment)


@given(st.text(max_size=2000), st.integers(min_value=20, max_value=400))
def test_one_line_is_short_and_single(text, limit):
    out = one_line(text, limit)
    assert len(out) <= limit
    assert "\n" not in out and "\r" not in out
    assert out == " ".join(text.split()) or " ... " in out


@given(st.one_of(st.text(max_size=5000), st.lists(st.floats(allow_nan=True), max_size=500),
                 st.dictionaries(st.text(max_size=20), st.integers(), max_size=50), st.binary(max_size=2000)))
def test_short_repr_is_short(value):
    assert len(short_repr(value, 60)) <= 80


def test_error_message_truncates():
    assert len(error_message(DataError("x" * 10_000_000))) <= MESSAGE_LIMIT <= 400


# ----------------------------------------------------------------------------- corrupted or absurd records

def test_parquet_corrupted_page_is_detected(work, capsys):
    t = np.arange(2000) * 1e-3
    write_measurement(pd.DataFrame({"time_s": t, "force_N": np.linspace(0.0, 500.0, t.size)}), work / "rec.parquet")
    import pyarrow.parquet as pq

    meta = pq.ParquetFile(work / "rec.parquet").metadata
    col = meta.row_group(0).column(1)
    data = bytearray((work / "rec.parquet").read_bytes())
    start = col.dictionary_page_offset if col.has_dictionary_page else col.data_page_offset
    offset = start + col.total_compressed_size // 2
    data[offset:offset + 4] = bytes(b ^ 0xFF for b in data[offset:offset + 4])
    (work / "rec.parquet").write_bytes(bytes(data))
    refused(["convert", "rec.parquet", "-o", "out.csv"], work, capsys, "rec.parquet", "corrupted Parquet")


def test_parquet_without_checksums_absurd_value(work, capsys):
    import pyarrow as pa
    import pyarrow.parquet as pq

    force = np.linspace(0.0, 500.0, 100)
    force[37] = 9e242  # a corrupted page of a file written without checksums
    table = pa.table({"time_s": np.arange(100) * 1e-3, "force_N": force})
    pq.write_table(table, work / "logger.parquet", use_dictionary=False)
    # the only channel: nothing to read (#33: a channel nobody asked for is skipped, not the whole file)
    refused(["convert", "logger.parquet", "-o", "out.csv"], work, capsys,
            "logger.parquet", "no channel could be read", "force_N", "9e+242", "row 37")
    # asked for by a channel map: an error naming the channel
    (work / "map.toml").write_text("[channels.force_N]\nsource = 'force_N'\n")
    refused(["convert", "logger.parquet", "--channel-map", "map.toml", "-o", "out.csv"], work, capsys,
            "logger.parquet", "'force_N'", "9e+242", "row 37")
    # beside a good channel: skipped with a warning, the good one written
    table = pa.table({"time_s": np.arange(100) * 1e-3, "force_N": force, "torque_Nm": np.ones(100)})
    pq.write_table(table, work / "logger.parquet", use_dictionary=False)
    assert main(["convert", "logger.parquet", "-o", "out.csv"]) == 0
    assert "skipped force_N: an implausible value 9e+242 N at row 37" in capsys.readouterr().err
    assert list(pd.read_csv(work / "out.csv", comment="#").columns) == ["time_s", "torque_Nm"]


def test_temperature_below_absolute_zero(work, capsys):
    (work / "rec.csv").write_text("time_s,temperature_C\n0,20\n0.1,-300\n0.2,21\n")
    refused(["convert", "rec.csv", "-o", "out.csv"], work, capsys, "rec.csv", "temperature_C", "-300",
            "absolute zero", "row 1")
    (work / "rec.csv").write_text("time_s,temperature_C\n0,20\n0.1,-270\n0.2,21\n")  # cold but possible
    assert main(["convert", "rec.csv", "-o", "out.csv"]) == 0


# ----------------------------------------------------------------------------- hidden temporaries, locks

def test_stale_temporary_removed_on_next_write(tmp_path):
    target = tmp_path / "out.csv"
    stale = tmp_path / ".out.csv.4194305.abcdefgh.tmp"  # above any Linux pid_max: that writer is gone
    stale.write_text("half")
    alive = tmp_path / f".out.csv.{os.getpid()}.abcdefgh.tmp"  # a running writer's file stays
    alive.write_text("busy")
    other = tmp_path / ".other.csv.4194305.abcdefgh.tmp"
    other.write_text("another output's")
    atomic_write_text(target, "a,b\n")
    assert not stale.exists() and alive.exists() and other.exists()
    assert target.read_text() == "a,b\n"
    assert remove_stale_temporaries(target) == []


def test_temporary_of_a_killed_writer_is_removed(tmp_path):
    target = tmp_path / "out.txt"
    script = textwrap.dedent(f"""
        import os, time
        import clutchlab.io.files as files
        files.os.replace = lambda *a: time.sleep(600)  # killed between writing and renaming
        files.atomic_write_text({str(target)!r}, "data")
    """)
    env = dict(os.environ, PYTHONPATH=str(SRC))
    proc = subprocess.Popen([sys.executable, "-c", script], env=env)
    try:
        for _ in range(600):
            if list(tmp_path.glob(".out.txt.*.tmp")) or proc.poll() is not None:
                break
            time.sleep(0.1)
        assert list(tmp_path.glob(".out.txt.*.tmp")), "the writer never created its temporary file"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    atomic_write_text(target, "again")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


def test_outputs_of_a_run_are_replaced_together_or_not_at_all(tmp_path):
    """:class:`OutputSet` (#33): an error while a run writes its outputs leaves every old one and no temporary
    folder; so does an output that appeared during the run (not replaced without ``overwrite``); a normal run
    replaces them all and leaves nothing else.  (Killed runs: tests/driveline/test_description.py.)"""
    from clutchlab.io.files import OutputExistsError, OutputSet

    a, b = tmp_path / "a.csv", tmp_path / "b.png"
    a.write_text("old a")
    b.write_text("old b")
    outputs = OutputSet([a, b, None], overwrite=True)
    with pytest.raises(RuntimeError, match="the figure failed"):
        with outputs:
            atomic_write_text(outputs.staged(a), "new a")
            raise RuntimeError("the figure failed")
    assert (a.read_text(), b.read_text()) == ("old a", "old b") and sorted(tmp_path.iterdir()) == [a, b]
    c, d = tmp_path / "c.csv", tmp_path / "d.csv"
    outputs = OutputSet([d, c])
    c.write_text("the user's, written while the run ran")
    with pytest.raises(OutputExistsError):
        with outputs:
            atomic_write_text(outputs.staged(d), "new d")
            atomic_write_text(outputs.staged(c), "new c")
    assert c.read_text().startswith("the user's") and sorted(tmp_path.iterdir()) == [a, b, c]
    with OutputSet([a, b], overwrite=True) as outputs:
        atomic_write_text(outputs.staged(a), "new a")
        atomic_write_text(outputs.staged(b), "new b")
    assert (a.read_text(), b.read_text()) == ("new a", "new b") and sorted(tmp_path.iterdir()) == [a, b, c]


def test_sweep_refused_leaves_no_lock(work, capsys):
    (work / "results").mkdir()
    (work / "results" / "notes.txt").write_text("mine")
    refused(["sweep", EXAMPLES / "sweep_eclutch_static.toml", "-o", "results"], work, capsys,
            "results", "use --force", log="clutchlab sweep: ")
    refused(["sweep", EXAMPLES / "sweep_eclutch_static.toml", "-o", "new", "--scheduler", "not a url"], work,
            capsys, "--scheduler 'not a url'", "tcp://HOST:PORT")


# ----------------------------------------------------------------------------- no traceback in a real process

@pytest.mark.parametrize("files, argv, fragment", [
    ({"empty.csv": b"time_s,force_N\n"}, ["convert", "empty.csv", "-o", "out.csv"], "no samples"),
    ({"deep.toml": b"x = " + b"[" * 50_000 + b"]" * 50_000}, ["params", "check", "deep.toml"], "nested too deeply"),
    ({"bad.toml": b"a = '\xff'\n"}, ["params", "check", "bad.toml"], "not a UTF-8"),
])
def test_subprocess_no_traceback(tmp_path, files, argv, fragment):
    for name, body in files.items():
        (tmp_path / name).write_bytes(body)
    before = _listing(tmp_path)
    env = dict(os.environ, PYTHONPATH=str(SRC))
    proc = subprocess.run([sys.executable, "-m", "clutchlab.cli", *argv], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("clutchlab: error: ") and fragment in lines[0], proc.stderr
    assert _listing(tmp_path) == before


def test_short_repr_shows_numpy_scalars_as_plain_numbers():
    import numpy as np

    assert short_repr(np.float64(1.5)) == "1.5"
    assert short_repr(np.int64(3)) == "3"
    assert short_repr(np.bool_(True)) == "True"
    assert short_repr(np.array(2.25)) == "2.25"
    assert short_repr("abc") == "'abc'"
    assert short_repr(np.arange(10.0)).startswith("ndarray(shape=(10,)")
