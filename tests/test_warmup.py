"""clutchlab warmup: kernel groups compiled ahead of use, in other processes sharing the cache."""

import pytest
from cli_checks import one_line_error

from clutchlab import warmup
from clutchlab.errors import ParameterError
from processes import proc_stat as _stat


def test_every_demo_section_has_a_group():
    from clutchlab.cli import DEMO_SECTIONS

    assert {name.rsplit(".", 1)[1] for name in DEMO_SECTIONS} <= set(warmup.GROUPS)


def test_unknown_group_is_refused():
    with pytest.raises(ParameterError, match="unknown kernel group.*known: eclutch, wet, emtc"):
        warmup.warm(["wett"])
    with pytest.raises(ParameterError, match="unknown kernel group"):
        warmup.run_parallel(["wet", "nope"])


def test_cli_refuses_bad_requests_in_one_line(capsys):
    assert "unknown group 'nope'" in one_line_error(capsys, ["warmup", "nope"])
    assert "--jobs = 0" in one_line_error(capsys, ["warmup", "-j", "0", "wet"])


def test_group_compiles_in_another_process_and_this_one_loads_it(monkeypatch):
    """The wet group in a background process (as the demo starts it), then the same kernels here."""
    from clutchlab import _compile_notice

    seconds = warmup.run_parallel(["wet"], jobs=1)
    assert seconds > 0
    _compile_notice.install()
    before = _compile_notice.compile_seconds()
    warmup.warm(["wet"])  # loaded from the cache the other process wrote (or already loaded here)
    assert _compile_notice.compile_seconds() - before < 1.0


def test_full_warmup_compiles_the_rare_paths(monkeypatch):
    """``clutchlab warmup`` (:func:`warmup.run_parallel`) starts its processes in full (the functions outlined with
    ``lazy=True`` too: the driveline's repair over several null directions and its invariant check, so that no run
    compiles afterwards); ``python -m clutchlab.warmup --full`` passes it on to :func:`warmup.warm`, and without
    the flag (the demo's background processes, :func:`warmup.start` by default) it is not."""
    import subprocess
    import sys

    started, warmed = [], []

    def recording_start(groups, full=False):
        started.append((list(groups), full))
        return subprocess.Popen([sys.executable, "-c", "pass"])

    monkeypatch.setattr(warmup, "start", recording_start)
    warmup.run_parallel(["wet", "driveline"], jobs=2)
    assert sorted(started) == [(["driveline"], True), (["wet"], True)]
    monkeypatch.setattr(warmup, "warm", lambda groups=None, full=False: warmed.append((groups, full)))
    warmup.main(["--full", "driveline"])
    warmup.main(["wet"])
    assert warmed == [(["driveline"], True), (["wet"], False)]


def test_groups_sharing_functions_are_dealt_to_one_process_in_order(monkeypatch):
    """``clutchlab warmup`` with fewer processes than groups keeps the groups of a lot (:data:`warmup.LOTS`) in one
    process, in their order: the
    components' kernel after the plain network's, whose functions it calls, and the control group after the E-clutch
    and the EMTC, whose kernels it evaluates (in two processes at once each compiled them: measured 2026-12-03,
    the components 115 s alone and 62 s after the driveline, the control group 17 s alone and 2.4 s after them)."""
    import subprocess
    import sys

    started = []

    def recording_start(groups, full=False):
        started.append(list(groups))
        return subprocess.Popen([sys.executable, "-c", "pass"])

    monkeypatch.setattr(warmup, "start", recording_start)
    warmup.run_parallel(None, jobs=2)
    assert sorted(started) == [["driveline", "components"], ["eclutch", "emtc", "control", "wet"]]
    started.clear()
    warmup.run_parallel(["control", "components", "wet"], jobs=2)   # (a lot's members that were asked for)
    assert sorted(started) == [["components"], ["wet", "control"]]   # (lots dealt by cost, the costliest first)
    started.clear()
    warmup.run_parallel(None, jobs=6)   # (a process for every group: each alone, the wall time the longest group's)
    assert sorted(started) == sorted([g] for g in warmup.GROUPS)
    started.clear()
    warmup.run_parallel(None, jobs=1)
    assert started == [["driveline", "components", "eclutch", "emtc", "control", "wet"]]
    assert sorted(g for lot in warmup.LOTS for g in lot) == sorted(warmup.GROUPS)


def test_failing_group_is_reported(monkeypatch):
    import subprocess
    import sys

    def failing_start(groups, full=False):
        return subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"])

    monkeypatch.setattr(warmup, "start", failing_start)
    with pytest.raises(Exception, match=r"compiling kernel group\(s\) \[\['wet'\]\] failed"):
        warmup.run_parallel(["wet"], jobs=1)


@pytest.mark.skipif(not __import__("pathlib").Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_compile_processes_end_when_their_parent_is_killed(tmp_path):
    """#33: ``clutchlab demo`` stopped its background compile processes only in a ``finally``, which SIGKILL
    skips: a killed demo's processes compiled on.  A parent starts them as the demo does (:func:`warmup.start`,
    one per group) and is killed with SIGKILL while they work; they end within seconds.  Their work is a stub
    that compiles nothing: a ``numba`` earlier on the path that says it started and sleeps."""
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    import clutchlab

    stub, started = tmp_path / "stub" / "numba", tmp_path / "started"
    stub.mkdir(parents=True)
    started.mkdir()
    (stub / "__init__.py").write_text("import os, pathlib, time\n"
                                      "pathlib.Path(os.environ['STUB_STARTED'], str(os.getpid())).touch()\n"
                                      "time.sleep(600)\n")
    script = ("import time\nfrom clutchlab import warmup\n"
              "procs = [warmup.start([group]) for group in ('wet', 'emtc')]\n"
              "print(*(p.pid for p in procs), flush=True)\ntime.sleep(600)\n")
    src = Path(clutchlab.__file__).resolve().parents[1]
    env = dict(os.environ, STUB_STARTED=str(started), PYTHONPATH=os.pathsep.join([str(stub.parent), str(src)]))
    parent = subprocess.Popen([sys.executable, "-c", script], env=env, stdout=subprocess.PIPE, text=True)
    children = {}
    try:
        children = {pid: _stat(pid) for pid in map(int, parent.stdout.readline().split())}
        assert len(children) == 2 and all(children.values())
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and len(list(started.iterdir())) < 2:
            time.sleep(0.05)
        assert {int(p.name) for p in started.iterdir()} == set(children)   # both at work (in the stub)
        parent.send_signal(signal.SIGKILL)
        parent.wait(timeout=30)

        def alive(pid):
            st = _stat(pid)
            return st is not None and st[2] == children[pid][2] and st[0] != "Z"   # (not a reused pid, no zombie)

        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and any(map(alive, children)):
            time.sleep(0.05)
        assert not [pid for pid in children if alive(pid)], "compile processes of the killed parent still run"
    finally:
        if parent.poll() is None:
            parent.kill()
            parent.wait()
        for pid, st in children.items():   # never leave a 10-minute sleeper behind, even if the test failed
            now = _stat(pid)
            if st and now and now[2] == st[2] and now[0] != "Z":
                os.kill(pid, signal.SIGKILL)
        parent.stdout.close()
