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
