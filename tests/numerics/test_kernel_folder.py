"""Where the generated kernel modules go: the shared temporary folder's fallback is this user's own (#33).

Its modules are imported and numba's cache pickles read from it, so a folder another user made first (or a
link planted in its place) must never be used."""

from __future__ import annotations

import os
import stat
import tempfile

import pytest

from clutchlab.numerics import entry


@pytest.fixture
def only_the_shared_folder(tmp_path, monkeypatch):
    """No NUMBA_CACHE_DIR, a cache home that cannot be a folder (a file), the temporary folder in tmp_path."""
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    shared = tmp_path / "tmp"
    shared.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(shared))
    return shared / f"clutchlab-kernels-{os.getuid()}"


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX ownership")
def test_the_shared_fallback_is_created_private(only_the_shared_folder):
    assert entry.kernel_dir() == only_the_shared_folder
    assert stat.S_IMODE(os.lstat(only_the_shared_folder).st_mode) == 0o700


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX ownership")
def test_an_existing_open_folder_of_this_user_is_made_private(only_the_shared_folder):
    only_the_shared_folder.mkdir()
    os.chmod(only_the_shared_folder, 0o777)
    assert entry.kernel_dir() == only_the_shared_folder
    assert stat.S_IMODE(os.lstat(only_the_shared_folder).st_mode) == 0o700


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX ownership")
def test_a_link_in_its_place_is_refused(only_the_shared_folder, tmp_path):
    elsewhere = tmp_path / "planted"
    elsewhere.mkdir(mode=0o777)
    only_the_shared_folder.symlink_to(elsewhere, target_is_directory=True)
    with pytest.raises(OSError, match="a link or a file.*refused.*NUMBA_CACHE_DIR"):
        entry.kernel_dir()


@pytest.mark.skipif(not hasattr(os, "getuid") or os.getuid() != 0, reason="needs root to give a folder away")
def test_a_folder_another_user_made_is_refused(only_the_shared_folder):
    only_the_shared_folder.mkdir(mode=0o777)
    os.chown(only_the_shared_folder, 65534, 65534)
    with pytest.raises(OSError, match="belongs to another user.*refused"):
        entry.kernel_dir()


_RECORDS_V1 = "from typing import NamedTuple\n\n\nclass VehicleData(NamedTuple):\n    mass: float\n"
_RECORDS_V2 = "from typing import NamedTuple\n\n\nclass Vehicle(NamedTuple):\n    mass: float\n    extra: float = 0.0\n"
_KERNEL = ("import numba\nfrom records import {cls}\n\n\n@numba.njit(cache=True)\ndef weight(v):\n"
           "    return v.mass * 9.80665\n\n\nprint(weight({cls}(2.0)))\n")


def _importer(folder):
    """``run(head)``: a fresh Python that runs ``head`` and then imports ``kernel`` from ``folder``, with its own
    numba cache there."""
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(folder / "cache"), PYTHONPATH=str(folder))

    def run(head):
        return subprocess.run([sys.executable, "-c", head + "import kernel"], capture_output=True, text=True,
                              env=env, cwd=folder, timeout=300)

    run.folder = folder
    return run


def _stale_then_compiled_again(run, upgrade, printed, failure):
    """The kernel runs and caches; after ``upgrade`` plain numba fails on the cache with ``failure``, with clutchlab
    imported it compiles again and prints ``printed``, and then numba alone reads the fresh cache."""
    first = run("")
    assert first.returncode == 0 and first.stdout.split() == [printed], first.stderr[-2000:]
    assert list(run.folder.joinpath("cache").rglob("*.nbi"))   # (the index written)
    upgrade()
    plain = run("")
    assert plain.returncode != 0 and failure in plain.stderr, plain.stderr[-2000:]
    guarded = run("import clutchlab.numerics\n")
    assert guarded.returncode == 0 and guarded.stdout.split() == [printed], guarded.stderr[-2000:]
    again = run("")   # (the fresh cache written over the stale one: numba alone reads it now)
    assert again.returncode == 0 and again.stdout.split() == [printed], again.stderr[-2000:]


def test_a_cache_index_naming_a_class_an_upgrade_removed_is_compiled_again(tmp_path):
    """numba unpickles a cached function's index before it compares the source's stamp, so an index an older
    version wrote naming a class since renamed raised ``AttributeError: Can't get attribute ...`` (an upgrade over
    an existing cache; the EMTC's ``VehicleData`` became a record).  With clutchlab imported the stale index is a
    miss: the function compiles again and runs.  Without it the same cache fails (so the test can fail)."""
    (tmp_path / "records.py").write_text(_RECORDS_V1)
    (tmp_path / "kernel.py").write_text(_KERNEL.format(cls="VehicleData"))
    run = _importer(tmp_path)


    def upgrade():   # the class renamed, the kernel with it
        (tmp_path / "records.py").write_text(_RECORDS_V2)
        (tmp_path / "kernel.py").write_text(_KERNEL.format(cls="Vehicle"))

    _stale_then_compiled_again(run, upgrade, "19.6133", "Can't get attribute 'VehicleData'")


_INNER = ("import numba\nimport numpy as np\nTABLE = np.array([1.0, 2.0])\n\n\n@numba.njit(cache=True)\ndef h(x):\n"
          "    if x < 0:\n        raise ValueError('negative')\n    return x * TABLE[1]\n")
_HELPERS = "import numba\nfrom {inner} import h\n\n\n@numba.njit(cache=True)\ndef g(x):\n    return h(x) + 1.0\n"
_CALLER = ("import numba\nfrom helpers import g\n\n\n@numba.njit(cache=True)\ndef weight(x):\n    return g(x) * 2.0\n\n\n"
           "print(weight(2.0))\n")


def test_cached_data_naming_a_module_an_upgrade_renamed_is_compiled_again(tmp_path):
    """A cached function whose own file did not change keeps its index, but its data names the modules of the
    compiled functions it calls (numba rebuilds their environments by importing them): after
    ``clutchlab.hysteresis._kernels`` became ``clutchlab.hysteresis.kernels``, the wet clutch's network function
    raised ``ModuleNotFoundError`` from an existing cache.  With clutchlab imported such data is a miss: the
    function compiles again and runs.  Without it the same cache fails (so the test can fail)."""
    (tmp_path / "inner.py").write_text(_INNER)
    (tmp_path / "helpers.py").write_text(_HELPERS.format(inner="inner"))
    (tmp_path / "kernel.py").write_text(_CALLER)
    run = _importer(tmp_path)


    def upgrade():   # the callee's module renamed, the caller's file unchanged
        (tmp_path / "inner.py").rename(tmp_path / "inner2.py")
        (tmp_path / "helpers.py").write_text(_HELPERS.format(inner="inner2"))

    _stale_then_compiled_again(run, upgrade, "10.0", "No module named 'inner'")
