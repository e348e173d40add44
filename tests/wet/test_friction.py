import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.errors import DataError
from clutchlab.wet import FrictionMap, ParametricFriction
from clutchlab.wet.friction import mu_kernel


def test_parametric_law_formula():
    law = ParametricFriction(mu0=0.13, mu_t=8e-4, mu_e=-0.03, v_s=0.6, t_ref=100.0)
    assert law.mu(0.0, 100.0) == pytest.approx(0.10)
    assert law.mu(1e6, 110.0) == pytest.approx(0.138)
    assert law.mu(0.6, 90.0) == pytest.approx(0.13 - 0.008 - 0.03 * np.exp(-1))
    assert law.mu(-0.6, 90.0) == law.mu(0.6, 90.0)  # depends on |v|
    assert ParametricFriction(mu0=0.01, mu_t=1e-3).mu(5.0, 0.0) == 0.0  # clipped at zero


def test_bench_truth_differs_from_defaults():
    assert ParametricFriction.bench_truth().to_dict() != ParametricFriction().to_dict()


def bilinear(v, t):
    return 0.1 + 0.01 * v + 5e-4 * (t - 80) + 1e-4 * v * (t - 80)


def test_map_reproduces_bilinear_function_and_clamps():
    gv = np.array([0.0, 0.5, 1.5, 3.0])
    gt = np.array([60.0, 90.0, 120.0])
    vv, tt = np.meshgrid(gv, gt)
    m = FrictionMap(gv, gt, bilinear(vv, tt))
    v = np.array([0.2, 1.0, 2.9])
    t = np.array([65.0, 100.0, 119.0])
    np.testing.assert_allclose(m.mu(v, t), bilinear(v, t), rtol=1e-12)
    assert m.mu(10.0, 200.0) == pytest.approx(bilinear(3.0, 120.0))  # constant beyond the grid
    assert m.mu(-1.0, 90.0) == pytest.approx(bilinear(1.0, 90.0))    # |v|


@settings(max_examples=examples(30), deadline=None)
@given(st.floats(0, 4), st.floats(40, 140), st.floats(0, 5000))
def test_kernel_lookup_equals_python(v, t, f):
    gv = np.array([0.0, 0.5, 1.5, 3.0])
    gt = np.array([60.0, 90.0, 120.0])
    gf = np.array([500.0, 3000.0])
    vv, tt = np.meshgrid(gv, gt)
    vals = np.stack([bilinear(vv, tt), bilinear(vv, tt) * 1.1])
    m3 = FrictionMap(gv, gt, vals, force_grid=gf)
    assert mu_kernel(v, t, f, *m3.kernel_data()) == pytest.approx(m3.mu(v, t, f), rel=1e-12)
    m2 = FrictionMap(gv, gt, vals[0])
    assert mu_kernel(v, t, f, *m2.kernel_data()) == pytest.approx(m2.mu(v, t), rel=1e-12)
    law = ParametricFriction.bench_truth()
    assert mu_kernel(v, t, f, *law.kernel_data()) == pytest.approx(law.mu(v, t), rel=1e-12)


def test_map_json_round_trip(tmp_path):
    gv = np.array([0.0, 1.0, 2.0])
    gt = np.array([60.0, 100.0])
    vv, tt = np.meshgrid(gv, gt)
    m = FrictionMap(gv, gt, bilinear(vv, tt), covered=np.array([[1, 1, 0], [1, 0, 0]], bool),
                    law=ParametricFriction(), statistics={"rmse": 1e-3}, region={"temperature_C": [60, 100]})
    p = m.to_json(tmp_path / "map.json")
    with pytest.raises(FileExistsError):
        m.to_json(p)
    back = FrictionMap.from_json(p)
    np.testing.assert_array_equal(back.values, m.values)
    np.testing.assert_array_equal(back.covered, m.covered)
    assert back.law == m.law and back.statistics == m.statistics


def test_map_bad_input(tmp_path):
    with pytest.raises(DataError, match="speed_grid"):
        FrictionMap([0.0, 0.0], [1.0], [[0.1, 0.1]])
    with pytest.raises(DataError, match="shape"):
        FrictionMap([0.0, 1.0], [1.0, 2.0], [[0.1, 0.1]])
    with pytest.raises(DataError, match="finite"):
        FrictionMap([0.0, 1.0], [1.0], [[0.1, np.nan]])
    m3 = FrictionMap([0.0, 1.0], [1.0], [[[0.1, 0.1]], [[0.2, 0.2]]], force_grid=[0.0, 1.0])
    with pytest.raises(DataError, match="force"):
        m3.mu(0.5, 1.0)
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(DataError, match="JSON"):
        FrictionMap.from_json(tmp_path / "bad.json")
    (tmp_path / "lack.json").write_text('{"speed_grid": [0, 1]}')
    with pytest.raises(DataError, match="temperature_grid"):
        FrictionMap.from_json(tmp_path / "lack.json")


def test_the_speed_slopes_of_a_map_are_its_own():
    """``d mu/d v`` between speed nodes of a map linear in v per temperature (falling at 60 degC, rising at 100):
    the slopes exactly, the measured intervals only in the verdict, a 3-D map per force."""
    v = np.array([0.0, 0.5, 1.5, 3.0])
    temps = np.array([60.0, 100.0])
    values = np.array([0.14 - 0.004 * v, 0.11 + 0.006 * v])
    covered = np.ones_like(values, dtype=bool)
    covered[0, 3] = False                      # the hot end of the falling row filled from the law
    fmap = FrictionMap(v, temps, values, covered=covered)
    table = fmap.speed_slopes()
    assert list(table.columns) == ["temperature_C", "speed_from_m_s", "speed_to_m_s", "dmu_dv_s_m", "covered"]
    assert len(table) == 6
    np.testing.assert_allclose(table.dmu_dv_s_m, [-0.004] * 3 + [0.006] * 3, rtol=1e-12)
    assert list(table.covered) == [True, True, False, True, True, True]
    verdict = fmap.shudder_summary()
    assert verdict["intervals"] == 5 and verdict["falling"] == 2 and verdict["shudder_prone"]
    assert verdict["min_dmu_dv_s_m"] == pytest.approx(-0.004) and verdict["at_temperature_C"] == 60.0
    rising = FrictionMap(v, temps, np.array([0.11 + 0.006 * v, 0.12 + 0.001 * v]))
    assert not rising.shudder_summary()["shudder_prone"]
    cube = FrictionMap(v, temps, np.stack([values, values + 0.01]), force_grid=[500.0, 1500.0])
    t3 = cube.speed_slopes()
    assert list(t3.columns)[0] == "force_N" and len(t3) == 12 and set(t3.force_N) == {500.0, 1500.0}
    none = FrictionMap(v, temps, values, covered=np.zeros_like(values, dtype=bool)).shudder_summary()
    assert none["intervals"] == 0 and none["min_dmu_dv_s_m"] is None and not none["shudder_prone"]
