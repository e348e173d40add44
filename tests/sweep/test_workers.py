"""Worker processes end with the sweep that started them, even when it is killed with SIGKILL."""

import os
import pathlib
import signal
import subprocess
import sys
import time

import pytest

from clutchlab.sweep.runner import _die_with_parent
from processes import proc_stat as _stat

SRC = pathlib.Path(__file__).parents[2] / "src"

SPEC = """
[sweep]
model = "plugin-wet"
outputs = ["energy"]
chunk_size = 1
[grid]
"batch.mu_scale" = [0.9, 1.0, 1.1, 1.2]
"""

pytestmark = pytest.mark.skipif(not pathlib.Path("/proc/self/stat").exists(), reason="needs Linux /proc")


def _children(pid):
    """{child pid: start time} of the living children of ``pid``."""
    out = {}
    for entry in pathlib.Path("/proc").iterdir():
        if entry.name.isdigit():
            st = _stat(int(entry.name))
            if st is not None and st[1] == pid and st[0] != "Z":
                out[int(entry.name)] = st[2]
    return out


def _alive(pid, start):
    st = _stat(pid)
    return st is not None and st[2] == start and st[0] != "Z"   # same process (not a reused pid), not a zombie


def test_workers_die_when_the_sweep_is_sigkilled(tmp_path, plugins):
    spec = tmp_path / "spec.toml"
    spec.write_text(SPEC)
    started = tmp_path / "started"
    started.mkdir()
    env = dict(os.environ, CLUTCHLAB_SWEEP_TEST_DELAY="600", CLUTCHLAB_SWEEP_TEST_STARTED=str(started),
               PYTHONPATH=os.pathsep.join([str(plugins), str(SRC), os.environ.get("PYTHONPATH", "")]))
    env.pop("CLUTCHLAB_SWEEP_TEST_FAIL_ID", None)
    proc = subprocess.Popen([sys.executable, "-m", "clutchlab", "sweep", str(spec), "-o", str(tmp_path / "out"),
                             "--workers", "2", "--no-progress"],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    children = {}
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and proc.poll() is None and len(list(started.iterdir())) < 2:
            time.sleep(0.05)
        assert proc.poll() is None, f"sweep ended early: {proc.stderr.read().decode()}"
        workers = {int(p.name) for p in started.iterdir()}
        children = _children(proc.pid)
        assert len(workers) == 2 and workers <= set(children)   # both workers are busy in a chunk, children of proc
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and any(_alive(p, s) for p, s in children.items()):
            time.sleep(0.05)
        survivors = [p for p, s in children.items() if _alive(p, s)]
        assert not survivors, f"processes of the killed sweep still running: {survivors}"
    finally:
        if proc.poll() is None:
            proc.kill()
        for pid, start in children.items():   # never leave a 10-minute sleeper behind, even if the test failed
            if _alive(pid, start):
                os.kill(pid, signal.SIGKILL)
        proc.stderr.close()


def test_a_worker_whose_parent_is_already_gone_exits_at_once():
    code = ("import sys; sys.path.insert(0, %r)\n"
            "from clutchlab.sweep.runner import _die_with_parent\n"
            "_die_with_parent(-5)\n"
            "print('still running')\n") % str(SRC)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1 and "still running" not in proc.stdout


def test_the_watchdog_ends_a_worker_whose_parent_dies_without_pdeathsig():
    """The portable fallback alone: prctl disabled, the parent (a shell) SIGKILLed, the worker ends by itself."""
    code = ("import ctypes, os, sys, time; sys.path.insert(0, %r)\n"
            "from clutchlab.sweep.runner import _die_with_parent\n"
            "def no_libc(*a, **k): raise OSError('no libc')\n"
            "ctypes.CDLL = no_libc\n"                                # no prctl: only the watchdog is left
            "_die_with_parent(os.getppid(), poll=0.05)\n"
            "print(os.getpid(), flush=True)\n"
            "time.sleep(600)\n") % str(SRC)
    shell = subprocess.Popen(["/bin/sh", "-c", f'"{sys.executable}" -c "$0" & wait', code],
                             stdout=subprocess.PIPE, text=True)
    worker = None
    try:
        worker = int(shell.stdout.readline())
        start = _stat(worker)[2]
        os.kill(shell.pid, signal.SIGKILL)
        shell.wait(timeout=30)
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and _alive(worker, start):
            time.sleep(0.05)
        assert not _alive(worker, start)
    finally:
        if shell.poll() is None:
            shell.kill()
        if worker is not None and _stat(worker) is not None and _stat(worker)[0] != "Z":
            os.kill(worker, signal.SIGKILL)
        shell.stdout.close()


def test_die_with_parent_keeps_a_worker_with_a_living_parent():
    _die_with_parent(os.getppid(), poll=0.01)   # this process's parent is alive: nothing happens
    time.sleep(0.1)
