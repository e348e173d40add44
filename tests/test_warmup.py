"""clutchlab warmup: kernel groups compiled ahead of use, in other processes sharing the cache."""

import pytest
from cli_checks import one_line_error

from clutchlab import warmup
from clutchlab.errors import ParameterError


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


def test_failing_group_is_reported(monkeypatch):
    import subprocess
    import sys

    def failing_start(groups, full=False):
        return subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"])

    monkeypatch.setattr(warmup, "start", failing_start)
    with pytest.raises(Exception, match=r"compiling kernel group\(s\) \[\['wet'\]\] failed"):
        warmup.run_parallel(["wet"], jobs=1)
