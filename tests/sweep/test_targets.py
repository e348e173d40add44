"""Targets: built-in, registered through the API, installed plugins (entry points); a spec never names code."""

import os
import pathlib
import pickle
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from clutchlab.cli import main
from clutchlab.errors import ClutchlabError, ParameterError
from clutchlab.sweep import (
    BUILTIN, available_targets, load_spec, register_target, resolve_target, run_sweep, unregister_target,
)
from clutchlab.sweep.targets import Target

from .conftest import PLUGIN_DIST, PLUGIN_VERSION

SRC = pathlib.Path(__file__).parents[2] / "src"

PLAIN = """
[sweep]
model = "{model}"
outputs = ["y"]
chunk_size = 4
[grid]
a = [1.0, 2.0]
x = [0.5, 1.5, 2.5]
"""

EVIL = """
import pathlib
pathlib.Path(__file__).with_name("MARKER").write_text("code of the spec's folder ran")

def run_batch(variants, scenario, outputs):
    return variants
"""


def test_builtin_names_resolve_to_clutchlab_modules():
    assert sorted(BUILTIN) == ["driveline", "eclutch", "eclutch-static", "emtc", "wet"]
    wet = resolve_target("wet")
    assert wet.origin == "built-in" and wet.run_batch.__module__ == "clutchlab.sweep.wet"
    assert wet.describe_fn is not None and wet.check_fn is not None
    assert resolve_target("eclutch").run_batch.__module__ == "clutchlab.sweep.eclutch"
    assert resolve_target("driveline").run_batch.__module__ == "clutchlab.sweep.driveline"
    with pytest.raises(ParameterError, match=r"unknown model.*available: driveline, eclutch, eclutch-static, emtc, wet"):
        resolve_target("hydraulic")


def test_registered_target_without_describe_takes_plain_numbers(tmp_path, registered_targets):
    spec_path = tmp_path / "s.toml"
    spec_path.write_text(PLAIN.format(model="test-parabola"))
    res = run_sweep(spec_path, tmp_path / "out", progress=False, plot=False)
    np.testing.assert_array_equal(res.results["y"], res.results["a"] * res.results["x"] ** 2)
    assert list(res.results["variant_id"]) == list(range(6))
    assert res.spec.target.origin == "registered" and "sweep_plain_target.run_batch" in res.spec.target.identity
    spec_path.write_text(PLAIN.format(model="test-parabola").replace("0.5,", '"0.5 m",'))
    with pytest.raises(ParameterError, match=r"s\.toml.*'x'.*0\.5 m"):
        load_spec(spec_path)


def test_registered_module_brings_its_describe_and_check(tmp_path, registered_targets):
    target = resolve_target("test-wet")
    assert target.describe(None).outputs == resolve_target("wet").describe(None).outputs
    assert "test-wet" in available_targets() and "test-parabola" in available_targets()
    unregister_target("test-wet")
    with pytest.raises(ParameterError, match="unknown model 'test-wet'|model = 'test-wet': unknown model"):
        resolve_target("test-wet")


def test_unknown_output_of_an_undeclared_target_is_caught_on_the_first_chunk(tmp_path, registered_targets):
    spec_path = tmp_path / "s.toml"
    spec_path.write_text(PLAIN.format(model="test-parabola").replace('["y"]', '["y", "z"]'))
    with pytest.raises(ParameterError, match=r"s\.toml.*unknown output 'z'"):
        run_sweep(spec_path, tmp_path / "out", progress=False)


def test_register_target_takes_objects_not_import_paths(registered_targets):
    import sweep_plain_target

    with pytest.raises(ParameterError, match="never imported from a name"):
        register_target("bad", "sweep_plain_target:run_batch")
    with pytest.raises(ParameterError, match="built-in"):
        register_target("wet", sweep_plain_target)
    with pytest.raises(ParameterError, match="already registered"):
        register_target("test-parabola", sweep_plain_target)
    with pytest.raises(ParameterError, match="without ':'"):
        register_target("a:b", sweep_plain_target)
    with pytest.raises(ParameterError, match="run_batch"):
        register_target("nothing", object())
    register_target("test-parabola", sweep_plain_target, replace=True)
    assert resolve_target("test-parabola").run_batch is sweep_plain_target.run_batch


def test_a_target_is_pickled_by_reference_for_workers(registered_targets):
    target = resolve_target("test-wet")
    back = pickle.loads(pickle.dumps(target))
    assert back == target and back.run_batch is target.run_batch and back.check_fn is target.check_fn


def test_a_target_that_changes_the_index_is_refused(registered_targets):
    target = resolve_target("test-parabola")
    variants = pd.DataFrame({"a": [1.0], "x": [2.0]}, index=pd.RangeIndex(1, name="variant_id"))
    assert target.run(variants, {"scale": 3}, ["y", "scale"]).loc[0, "scale"] == 3.0
    shifting = Target("shift", "registered", "shift", lambda v, s, o: pd.DataFrame({"y": [1.0]}))
    with pytest.raises(ClutchlabError, match="different index"):
        shifting.run(variants.set_axis(pd.Index([7], name="variant_id")), None, ["y"])


# ----------------------------------------------------------------- installed plugins (entry points)
def test_entry_point_plugins_are_listed_without_import_and_loaded_when_named(tmp_path, plugins):
    mod = f"{PLUGIN_DIST}.slow"
    sys.modules.pop(mod, None)
    names = available_targets()
    assert {"plugin-wet", "plugin-parabola"} <= set(names)
    assert mod not in sys.modules                      # listing imports nothing
    target = resolve_target("plugin-wet")
    assert mod in sys.modules and target.run_batch.__module__ == mod
    assert target.origin == f"entry point plugin-wet = {mod} ({PLUGIN_DIST} {PLUGIN_VERSION})"
    assert target.describe_fn is not None and target.check_fn is not None      # module form: all hooks
    parabola = resolve_target("plugin-parabola")                               # module:function form
    assert parabola.run_batch.__module__ == f"{PLUGIN_DIST}.plain" and parabola.describe_fn is None
    spec_path = tmp_path / "s.toml"
    spec_path.write_text(PLAIN.format(model="plugin-parabola"))
    res = run_sweep(spec_path, tmp_path / "out", progress=False, plot=False)
    np.testing.assert_array_equal(res.results["y"], res.results["a"] * res.results["x"] ** 2)


def test_a_plugin_that_fails_to_import_is_a_one_line_error(tmp_path, monkeypatch):
    site = tmp_path / "site"
    (site / "broken-0.1.dist-info").mkdir(parents=True)
    (site / "broken-0.1.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: broken\nVersion: 0.1\n")
    (site / "broken-0.1.dist-info" / "entry_points.txt").write_text("[clutchlab.sweep_targets]\nbroken = no_such_mod_q\n")
    monkeypatch.syspath_prepend(str(site))
    with pytest.raises(ParameterError, match=r"model = 'broken': cannot load the entry point broken = no_such_mod_q "
                                             r"\(broken 0\.1\): ModuleNotFoundError"):
        resolve_target("broken")


# ----------------------------------------------------------------- a spec never names code
def _evil_folder(tmp_path, model, spec_elsewhere=False):
    """A folder holding a module with a side effect and a dist-info pointing at it, and a spec naming it.

    The spec is in that folder, or (``spec_elsewhere``) in another one.
    """
    folder = tmp_path / "project"
    folder.mkdir()
    (folder / "evil.py").write_text(EVIL)
    info = folder / "evil-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: evil\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[clutchlab.sweep_targets]\nevil = evil\n")
    spec = (tmp_path / "elsewhere" if spec_elsewhere else folder) / "spec.toml"
    spec.parent.mkdir(exist_ok=True)
    spec.write_text(PLAIN.format(model=model))
    return folder, spec


@pytest.mark.parametrize("model", ["evil:run_batch", "evil", "os:system", "evil.run_batch"])
@pytest.mark.parametrize("list_parameters", [False, True])
@pytest.mark.parametrize("spec_elsewhere", [False, True])
def test_a_spec_naming_a_module_runs_none_of_its_code(tmp_path, monkeypatch, capsys, model, list_parameters,
                                                      spec_elsewhere):
    folder, spec = _evil_folder(tmp_path, model, spec_elsewhere)
    monkeypatch.syspath_prepend(str(folder))          # as PYTHONPATH=. or python -m in that folder
    monkeypatch.chdir(folder if spec_elsewhere else tmp_path)
    argv = ["sweep", str(spec), *(["--list-parameters"] if list_parameters else ["-o", str(tmp_path / "out")])]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("clutchlab: error:") and "\n" not in err
    assert f"model = {model!r}: unknown model (available: driveline, eclutch, eclutch-static, emtc, wet" in err
    assert not (folder / "MARKER").exists() and "evil" not in sys.modules
    assert not (tmp_path / "out").exists()


def test_python_m_clutchlab_in_the_spec_folder_runs_none_of_its_code(tmp_path):
    """The reported attack: ``python -m clutchlab`` with the spec's folder as working directory and on PYTHONPATH."""
    folder, spec = _evil_folder(tmp_path, "evil:run_batch")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([".", str(SRC)]))
    for model in ("evil:run_batch", "evil"):
        spec.write_text(PLAIN.format(model=model))
        proc = subprocess.run([sys.executable, "-m", "clutchlab", "sweep", "spec.toml", "--list-parameters"],
                              cwd=folder, env=env, capture_output=True, text=True, timeout=300)
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("clutchlab: error: spec.toml: [sweep] model = ")
        assert "unknown model (available: driveline, eclutch, eclutch-static, emtc, wet" in lines[0]
        assert not (folder / "MARKER").exists()
