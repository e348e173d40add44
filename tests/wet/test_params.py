import math

import pytest

from clutchlab.errors import ParameterError
from clutchlab.wet import Bench, WetClutch


def test_paper_is_table1_in_si():
    c = WetClutch.paper()
    assert c.n_c == 8 and isinstance(c.n_c, int)
    assert (c.r_outer, c.r_inner) == (0.08315, 0.07174)
    assert c.r_eff == pytest.approx(0.07758, abs=1e-5)
    assert (c.sigma, c.asperity_radius) == (6e-4, 5e-4)
    assert c.viscosity == pytest.approx((0.1502, -0.07838, 0.05815, -0.02184))
    assert (c.m_lining, c.m_core, c.cp_lining, c.cp_core) == pytest.approx((1.65e-3, 82.1e-3, 1500.0, 500.0))
    assert (c.k1, c.k2) == (122.2, 39.94)
    assert c.core_thickness == pytest.approx(1.7e-3)
    assert c.friction_area == pytest.approx(math.pi * (0.08315**2 - 0.07174**2))


def test_every_field_has_unit_doc_and_source():
    for cls in (WetClutch, Bench):
        for name, meta in cls.field_info().items():
            assert meta["unit"] and meta["doc"] and meta["source"], name


def test_overrides_and_validation():
    assert WetClutch.paper(k1=100.0).k1 == 100.0
    with pytest.raises(ParameterError, match="unknown"):
        WetClutch.paper(radius=1.0)
    with pytest.raises(ParameterError, match="r_inner"):
        WetClutch.paper(r_inner=0.09)
    with pytest.raises(ParameterError, match="m_core"):
        WetClutch.paper(m_core=-1.0)
    with pytest.raises(ParameterError, match="friction_area"):
        WetClutch.paper(friction_area=1.0)
    with pytest.raises(ParameterError, match="mu_v2"):
        WetClutch.paper(mu_v2=0.01)


def test_toml_round_trip_and_units(tmp_path):
    c = WetClutch.paper(k1=111.0)
    p = c.to_toml(tmp_path / "wet.toml")
    assert WetClutch.from_toml(p) == c
    with pytest.raises(FileExistsError):
        c.to_toml(p)
    (tmp_path / "mm.toml").write_text('[wet]\nr_outer = "83.15 mm"\nmu_v1 = "150.2 mPa*s"\nn_c = 6\n')
    d = WetClutch.from_toml(tmp_path / "mm.toml")
    assert d.r_outer == pytest.approx(0.08315) and d.mu_v1 == pytest.approx(0.1502) and d.n_c == 6
    (tmp_path / "bad.toml").write_text('[wet]\nr_outer = "83.15 kg"\n')
    with pytest.raises(ParameterError, match="r_outer"):
        WetClutch.from_toml(tmp_path / "bad.toml")
    (tmp_path / "frac.toml").write_text('[wet]\nn_c = 2.5\n')
    with pytest.raises(ParameterError, match="n_c"):
        WetClutch.from_toml(tmp_path / "frac.toml")


def test_bench_derived_quantities():
    b = Bench()
    assert b.drive_torque_max == pytest.approx(240.0)           # 120 N*m through the 1:2 gear
    assert b.drive_speed_max == pytest.approx(3000 * math.pi / 30)  # 6000 rpm / 2
    assert b.total_inertia == pytest.approx(b.shaft_inertia + 4 * b.motor_inertia)


def test_paper_accepts_the_four_viscosity_parameters_at_once():
    from clutchlab.wet import WetClutch

    c = WetClutch.paper(viscosity=(0.2, -0.05, 0.03, -0.02))
    assert c.viscosity == (0.2, -0.05, 0.03, -0.02) and c.mu_v3 == 0.03
    with pytest.raises(ParameterError, match="four Eq. 7 parameters"):
        WetClutch.paper(viscosity=(0.2, -0.05))
