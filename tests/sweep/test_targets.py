"""Target registry: built-in names, import paths, targets that declare nothing, the answer check."""

import pathlib

import numpy as np
import pandas as pd
import pytest

from clutchlab.errors import ClutchlabError, ParameterError
from clutchlab.sweep import TARGETS, load_spec, register_target, resolve_target, run_sweep

HERE = pathlib.Path(__file__).parent

PLAIN = """
[sweep]
model = "{model}"
outputs = ["y"]
chunk_size = 4
[grid]
a = [1.0, 2.0]
x = [0.5, 1.5, 2.5]
"""


@pytest.fixture
def plain(monkeypatch):
    monkeypatch.syspath_prepend(str(HERE))
    return "sweep_plain_target:run_batch"


def test_builtin_names_resolve_to_import_paths():
    assert resolve_target("wet").path == "clutchlab.sweep.wet:run_batch"
    assert TARGETS["eclutch"] == "clutchlab.eclutch.sweep:run_batch"
    with pytest.raises(ParameterError, match="unknown model"):
        resolve_target("hydraulic")


def test_import_path_target_without_describe_takes_plain_numbers(tmp_path, plain):
    spec_path = tmp_path / "s.toml"
    spec_path.write_text(PLAIN.format(model=plain))
    res = run_sweep(spec_path, tmp_path / "out", progress=False, plot=False)
    np.testing.assert_array_equal(res.results["y"], res.results["a"] * res.results["x"] ** 2)
    assert list(res.results["variant_id"]) == list(range(6))
    spec_path.write_text(PLAIN.format(model=plain).replace("0.5,", '"0.5 m",'))
    with pytest.raises(ParameterError, match=r"s\.toml.*'x'.*0\.5 m"):
        load_spec(spec_path)


def test_unknown_output_of_an_undeclared_target_is_caught_on_the_first_chunk(tmp_path, plain):
    spec_path = tmp_path / "s.toml"
    spec_path.write_text(PLAIN.format(model=plain).replace('["y"]', '["y", "z"]'))
    with pytest.raises(ParameterError, match=r"s\.toml.*unknown output 'z'"):
        run_sweep(spec_path, tmp_path / "out", progress=False)


def test_registered_name_is_usable_in_a_spec(tmp_path, plain, monkeypatch):
    monkeypatch.setitem(TARGETS, "parabola", plain)
    register_target("parabola", plain)
    spec_path = tmp_path / "s.toml"
    spec_path.write_text(PLAIN.format(model="parabola"))
    assert load_spec(spec_path).target.path == plain
    with pytest.raises(ParameterError, match="package.module:function"):
        register_target("bad", "no_colon_here")


def test_a_target_that_changes_the_index_is_refused(plain):
    target = resolve_target(plain)
    variants = pd.DataFrame({"a": [1.0], "x": [2.0]}, index=pd.RangeIndex(1, name="variant_id"))
    assert target.run(variants, {"scale": 3}, ["y", "scale"]).loc[0, "scale"] == 3.0
    shifted = variants.set_axis(pd.Index([7], name="variant_id"))
    from clutchlab.sweep.targets import Target

    class Shifting(Target):
        @property
        def function(self):
            return lambda v, s, o: pd.DataFrame({"y": [1.0]})

    with pytest.raises(ClutchlabError, match="different index"):
        Shifting("shift", plain).run(shifted, None, ["y"])
