"""Sweep spec: validation messages, the deterministic design, chunking and the spec hash."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab.errors import ParameterError
from clutchlab.sweep import load_spec, spec_from_dict
from clutchlab.sweep.spec import VARIANT_ID


def write(tmp_path, text, name="spec.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


GRID = """
[sweep]
model = "wet"
outputs = ["engagement_time", "energy"]
chunk_size = 4
[grid]
"clutch.r_outer" = ["80 mm", "83.15 mm", "86 mm"]
"protocol.force" = ["2.5 kN", 3000.0]
"""


def test_grid_design_is_full_factorial_in_si_units(tmp_path):
    spec = load_spec(write(tmp_path, GRID))
    assert spec.kind == "grid" and spec.n_variants == 6 and spec.n_chunks == 2
    assert spec.parameters == ("clutch.r_outer", "protocol.force")
    assert spec.units == {"clutch.r_outer": "m", "protocol.force": "N"}
    # row number is the id; the last key varies fastest; units converted once (mm -> m, kN -> N)
    expected = list(itertools.product([0.080, 0.08315, 0.086], [2500.0, 3000.0]))
    np.testing.assert_allclose(spec.design.to_numpy(), np.array(expected), rtol=1e-15)
    assert spec.design.index.name == VARIANT_ID
    assert list(spec.design.index) == list(range(6))
    assert len(spec.chunk(1)) == 2 and list(spec.chunk(1).index) == [4, 5]


def test_unknown_parameter_names_file_key_and_value(tmp_path):
    path = write(tmp_path, GRID.replace('"clutch.r_outer"', '"clutch.r_outr"'))
    with pytest.raises(ParameterError) as exc:
        load_spec(path)
    msg = str(exc.value)
    assert str(path) in msg and "clutch.r_outr" in msg and "80 mm" in msg and "clutch.r_outer" in msg


def test_bad_unit_names_file_key_and_value(tmp_path):
    path = write(tmp_path, GRID.replace('"80 mm"', '"80 kg"'))
    with pytest.raises(ParameterError) as exc:
        load_spec(path)
    msg = str(exc.value)
    assert str(path) in msg and "clutch.r_outer" in msg and "80 kg" in msg and "unit" in msg


def test_unknown_output_is_named(tmp_path):
    path = write(tmp_path, GRID.replace('"energy"', '"energie"'))
    with pytest.raises(ParameterError, match=r"spec\.toml.*'energie'.*known: engagement_time"):
        load_spec(path)


@pytest.mark.parametrize("text, match", [
    (GRID.replace('model = "wet"', 'model = "nosuch"'), "unknown model"),
    (GRID.replace('model = "wet"', 'model = "no_such_module_xyz:run"'), r"unknown model \(available: driveline, eclutch, "),
    (GRID + "\n[monte_carlo]\nn = 3\n", "exactly one of"),
    (GRID.replace("chunk_size = 4", "chunk_size = 0"), "chunk_size"),
    (GRID.replace("chunk_size = 4", "chunk_size = 4\nchunks = 3"), "unknown key 'chunks'"),
    (GRID.replace('"protocol.force" = ["2.5 kN", 3000.0]', '"protocol.force" = ["2.5 kN", "2500 N"]'), "repeated"),
    (GRID.replace('"clutch.r_outer" = ["80 mm", "83.15 mm", "86 mm"]', '"clutch.r_outer" = ["70 mm"]'),
     "variant 0: .*r_inner"),
    (GRID.replace('"protocol.force" = ["2.5 kN", 3000.0]', '"clutch.n_c" = [7.5]'), "whole number"),
    (GRID.replace('"protocol.force" = ["2.5 kN", 3000.0]', '"protocol.force" = ["20 kN"]'), "actuator"),
])
def test_bad_specs_raise_parameter_error_naming_the_file(tmp_path, text, match):
    path = write(tmp_path, text)
    with pytest.raises(ParameterError, match=match) as exc:
        load_spec(path)
    assert str(path) in str(exc.value)


def test_missing_scenario_file_is_named(tmp_path):
    path = write(tmp_path, GRID.replace('model = "wet"', 'model = "wet"\nscenario = "nope.toml"'))
    with pytest.raises(ParameterError, match="nope.toml"):
        load_spec(path)


def test_scenario_is_relative_to_the_spec_and_used(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "dyno.toml").write_text('[protocol]\ntype = "inertia_dynamometer"\nforce = "2 kN"\n')
    path = write(tmp_path / "sub", GRID.replace('model = "wet"', 'model = "wet"\nscenario = "dyno.toml"'))
    spec = load_spec(path)
    assert spec.scenario["protocol"]["type"] == "inertia_dynamometer"
    assert spec.scenario["_source"] == str((tmp_path / "sub" / "dyno.toml").resolve())


MC = """
[sweep]
model = "wet"
outputs = ["energy"]
chunk_size = 100
seed = {seed}
[monte_carlo]
n = 2000
"friction.mu0" = {{ dist = "normal", mean = 0.135, std = 0.005 }}
"protocol.initial_slip_speed" = {{ dist = "uniform", low = "1500 rpm", high = "2500 rpm" }}
"clutch.k1" = {{ dist = "loguniform", low = "100 W/K", high = "150 W/K" }}
"""


def test_monte_carlo_is_reproducible_and_has_the_asked_distributions(tmp_path):
    a = load_spec(write(tmp_path, MC.format(seed=1), "a.toml"))
    b = load_spec(write(tmp_path, MC.format(seed=1), "b.toml"))
    c = load_spec(write(tmp_path, MC.format(seed=2), "c.toml"))
    assert a.design.equals(b.design) and a.hash == b.hash
    assert not np.allclose(a.design.to_numpy(), c.design.to_numpy()) and a.hash != c.hash
    n = 2000
    mu = a.design["friction.mu0"].to_numpy()
    assert abs(mu.mean() - 0.135) < 4 * 0.005 / math.sqrt(n)           # 4 standard errors
    assert abs(mu.std(ddof=1) / 0.005 - 1) < 4 / math.sqrt(2 * n)
    w = a.design["protocol.initial_slip_speed"].to_numpy()
    lo, hi = 1500 * math.pi / 30, 2500 * math.pi / 30                  # rpm -> rad/s once, at the edge
    assert w.min() >= lo and w.max() <= hi
    assert abs(w.mean() - (lo + hi) / 2) < 4 * (hi - lo) / math.sqrt(12 * n)
    k1 = a.design["clutch.k1"].to_numpy()
    logs = np.log(k1)
    assert k1.min() >= 100 and k1.max() <= 150
    assert abs(logs.mean() - (math.log(100) + math.log(150)) / 2) < 4 * math.log(1.5) / math.sqrt(12 * n)


def test_monte_carlo_temperature_spread_is_a_difference(tmp_path):
    text = MC.format(seed=3).replace('"friction.mu0" = { dist = "normal", mean = 0.135, std = 0.005 }',
                                     '"protocol.fluid_temperature" = { dist = "normal", mean = "80 degC", std = "2 K" }')
    spec = load_spec(write(tmp_path, text))
    t = spec.design["protocol.fluid_temperature"].to_numpy()
    assert abs(t.mean() - 80.0) < 4 * 2.0 / math.sqrt(2000)
    assert abs(t.std(ddof=1) - 2.0) < 0.2


@pytest.mark.parametrize("entry, match", [
    ('{ dist = "gamma", mean = 1, std = 1 }', "dist = 'gamma'"),
    ('{ dist = "normal", mean = 0.1 }', "missing 'std'"),
    ('{ dist = "normal", mean = 0.1, std = -1 }', "must be > 0"),
    ('{ dist = "uniform", low = 0.2, high = 0.1 }', "must exceed"),
    ('{ dist = "uniform", low = 0.1, high = 0.2, mean = 3 }', "unknown key 'mean'"),
    ('0.12', "expected"),
])
def test_bad_distributions(tmp_path, entry, match):
    text = MC.format(seed=1).replace('{ dist = "normal", mean = 0.135, std = 0.005 }', entry)
    with pytest.raises(ParameterError, match=match):
        load_spec(write(tmp_path, text))


def test_hash_follows_what_changes_the_results(tmp_path):
    base = load_spec(write(tmp_path, GRID, "a.toml"))
    same = load_spec(write(tmp_path, GRID.replace('"80 mm"', '"0.08 m"'), "b.toml"))
    assert same.hash == base.hash                                       # same SI design, other spelling
    for changed in (GRID.replace("chunk_size = 4", "chunk_size = 5"),
                    GRID.replace('"engagement_time", "energy"', '"energy", "engagement_time"'),
                    GRID.replace('"86 mm"', '"86.5 mm"')):
        assert load_spec(write(tmp_path, changed, "c.toml")).hash != base.hash


values = st.lists(st.floats(0.5, 2.0, allow_nan=False), min_size=1, max_size=4, unique=True)


@settings(max_examples=examples(40), deadline=None)
@given(a=values, b=values, c=values, chunk=st.integers(1, 20))
def test_grid_covers_every_combination_once_and_chunks_partition_the_ids(a, b, c, chunk):
    data = {"sweep": {"model": "wet", "outputs": ["energy"], "chunk_size": chunk},
            "grid": {"batch.force_scale": a, "batch.mu_scale": b, "batch.speed_scale": c}}
    spec = spec_from_dict(data)
    combos = set(map(tuple, spec.design.to_numpy()))
    assert spec.n_variants == len(a) * len(b) * len(c) == len(combos)
    assert combos == set(itertools.product(a, b, c))
    assert list(map(tuple, spec.design.to_numpy())) == list(itertools.product(a, b, c))   # the last key fastest
    ids = np.concatenate([spec.chunk(k).index.to_numpy() for k in range(spec.n_chunks)])
    np.testing.assert_array_equal(ids, np.arange(spec.n_variants))
    assert all(len(spec.chunk(k)) == chunk for k in range(spec.n_chunks - 1))


def test_a_design_too_large_to_build_is_refused_before_it_is_built():
    """A grid of 2e9 variants was built in memory (5.4 GB before a limit stopped it; #33): more than
    ``MAX_VARIANTS`` (1e7) is refused at once, with the count and an estimate of the memory, for grids and Monte
    Carlo alike."""
    import time

    axis = [1.0 + k / 1000 for k in range(1000)]
    t0 = time.perf_counter()
    with pytest.raises(ParameterError, match=r"\(1000 x 1000 x 2000 values\) gives 2e\+09 variants, more than "
                                             r"1e\+07 \(about 112 GB"):
        spec_from_dict({"sweep": {"model": "wet", "outputs": ["energy"]},
                        "grid": {"batch.force_scale": axis, "batch.mu_scale": axis,
                                 "batch.speed_scale": [1.0 + k / 1000 for k in range(2000)]}})
    with pytest.raises(ParameterError, match=r"\[monte_carlo\] n = 20000000 gives 2e\+07 variants"):
        spec_from_dict({"sweep": {"model": "wet", "outputs": ["energy"], "seed": 1},
                        "monte_carlo": {"n": 20_000_000,
                                        "batch.force_scale": {"dist": "uniform", "low": 0.9, "high": 1.1}}})
    assert time.perf_counter() - t0 < 5.0
