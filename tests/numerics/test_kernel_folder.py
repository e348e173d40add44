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


_DECL = "N_SWITCH = {n}\n"
_PKG_KERNEL = ("import numba\nfrom .decl import N_SWITCH\n\n\n@numba.njit(cache=True)\ndef slots(x):\n"
               "    return x * N_SWITCH\n")


def test_a_kernel_reading_another_modules_constant_is_compiled_again_when_that_module_changes(tmp_path):
    """numba keys a cached function by its own file, so a kernel that reads a constant of another module (the
    driveline's coupled network lays out its buffers by the EMTC's number of switching functions) kept the value it
    was compiled with after that module changed: in an editable install after a pull a worker crashed on such a
    stale kernel (the forty-second session).  With clutchlab's guard the kernel's stamp carries the contents of the
    package files it imports (:func:`clutchlab._cache.dependency_stamp`): it compiles again and reads the new value.
    Without the guard the same cache answers with the old one (so the test can fail)."""
    import subprocess
    import sys

    pkg = tmp_path / "pkgx"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "decl.py").write_text(_DECL.format(n=8))
    (pkg / "kernel.py").write_text(_PKG_KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=str(tmp_path))
    guard = f"import clutchlab._cache as c\nc.guard_cross_module_constants({str(pkg)!r})\n"

    def run(head):
        out = subprocess.run([sys.executable, "-c", head + "from pkgx.kernel import slots\nprint(slots(1.0))"],
                             capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
        assert out.returncode == 0, out.stderr[-2000:]
        return out.stdout.split()

    assert run("") == ["8.0"]        # cached by plain numba
    (pkg / "decl.py").write_text(_DECL.format(n=10))   # the declaration changes, the kernel's file does not
    assert run("") == ["8.0"]        # plain numba: the stale kernel (its own file's stamp unchanged)
    assert run(guard) == ["10.0"]    # guarded: compiled again with the new constant (its stamp carries decl's)
    assert run(guard) == ["10.0"]    # (and cached so)
    (pkg / "decl.py").write_text(_DECL.format(n=12))
    assert run(guard) == ["12.0"]    # a guarded cache renews itself


def test_the_dependency_stamp_follows_the_imports(tmp_path):
    """A file's dependency stamp changes with any package file it imports, directly, through another module or
    inside a function, and not with one it does not import nor with its own text (numba's own stamp has that)."""
    from clutchlab._cache import _package_graph, dependency_stamp

    pkg = tmp_path / "pkgy"
    (pkg / "sub").mkdir(parents=True)
    files = {
        "__init__.py": "",
        "a.py": "from .b import X\n\n\ndef f():\n    from .sub import c\n    return c\n",
        "b.py": "from . import d as D\nX = 1\n",
        "d.py": "Y = 2\n",
        "e.py": "Z = 3\n",
        "sub/__init__.py": "",
        "sub/c.py": "from .. import (\n    e,\n)\n",
    }
    for name, text in files.items():
        (pkg / name).write_text(text)

    def stamps():
        _package_graph.cache_clear()
        return {name: dependency_stamp(pkg / name, pkg) for name in files}

    before = stamps()
    assert dependency_stamp(tmp_path / "elsewhere.py", pkg) == ""
    (pkg / "d.py").write_text("Y = 20\n")   # imported by b, so by a; not by c or e
    after = stamps()
    changed = {n for n in files if after[n] != before[n]}
    assert changed == {"a.py", "b.py"}, changed
    (pkg / "e.py").write_text("Z = 30\n")   # imported by sub/c (a parenthesised list), which a imports in f
    again = stamps()
    assert {n for n in files if again[n] != after[n]} == {"a.py", "sub/c.py"}
    (pkg / "a.py").write_text(files["a.py"] + "# an edit\n")   # its own text: not in its dependency stamp
    assert stamps()["a.py"] == again["a.py"]
