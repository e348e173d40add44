"""Test targets for sweeps, made available the two ways a real target can be: registered, or an installed plugin.

``registered_targets`` registers the test modules ``sweep_test_target`` (the
``wet`` target, slowed down or failing on request) and ``sweep_plain_target``
(``y = a x^2``, no ``describe``) through :func:`clutchlab.sweep.register_target`
as ``test-wet`` and ``test-parabola``.

``plugin_site`` builds a tiny installed distribution in a temporary folder
(a package ``clutchlab_sweep_testplugin`` with copies of those modules and a
``.dist-info`` whose ``entry_points.txt`` declares ``plugin-wet`` (a module)
and ``plugin-parabola`` (a ``module:function``) in the group
``clutchlab.sweep_targets``); ``plugins`` puts it on ``sys.path`` for this
process, and subprocesses get it through ``PYTHONPATH``.
"""

import pathlib
import shutil

import pytest

from clutchlab.sweep import register_target, unregister_target

HERE = pathlib.Path(__file__).parent
PLUGIN_DIST = "clutchlab_sweep_testplugin"
PLUGIN_VERSION = "1.2.3"


@pytest.fixture
def registered_targets(monkeypatch):
    """Register ``test-wet`` and ``test-parabola``; undone after the test."""
    monkeypatch.syspath_prepend(str(HERE))
    monkeypatch.delenv("CLUTCHLAB_SWEEP_TEST_FAIL_ID", raising=False)
    monkeypatch.delenv("CLUTCHLAB_SWEEP_TEST_DELAY", raising=False)
    import sweep_plain_target
    import sweep_test_target

    register_target("test-wet", sweep_test_target)
    register_target("test-parabola", sweep_plain_target.run_batch)
    yield {"wet": "test-wet", "parabola": "test-parabola"}
    unregister_target("test-wet")
    unregister_target("test-parabola")


@pytest.fixture(scope="session")
def plugin_site(tmp_path_factory):
    """A folder holding an installed plugin distribution (package + ``.dist-info`` with entry points)."""
    site = tmp_path_factory.mktemp("site")
    pkg = site / PLUGIN_DIST
    pkg.mkdir()
    (pkg / "__init__.py").write_text('"""Test plugin of clutchlab sweep targets."""\n')
    shutil.copy(HERE / "sweep_test_target.py", pkg / "slow.py")
    shutil.copy(HERE / "sweep_plain_target.py", pkg / "plain.py")
    info = site / f"{PLUGIN_DIST}-{PLUGIN_VERSION}.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {PLUGIN_DIST}\nVersion: {PLUGIN_VERSION}\n")
    (info / "entry_points.txt").write_text(
        "[clutchlab.sweep_targets]\n"
        f"plugin-wet = {PLUGIN_DIST}.slow\n"
        f"plugin-parabola = {PLUGIN_DIST}.plain:run_batch\n")
    return site


@pytest.fixture
def plugins(monkeypatch, plugin_site):
    """The test plugin installed for this process (its folder on ``sys.path``); returns the folder."""
    monkeypatch.syspath_prepend(str(plugin_site))
    monkeypatch.delenv("CLUTCHLAB_SWEEP_TEST_FAIL_ID", raising=False)
    monkeypatch.delenv("CLUTCHLAB_SWEEP_TEST_DELAY", raising=False)
    return plugin_site
