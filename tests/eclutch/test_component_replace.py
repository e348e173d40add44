"""Replacing one component's characteristic: API (ComponentCurves.replace), parameter file, variant TOML."""

from importlib import resources

import numpy as np
import pandas as pd
import pytest

from clutchlab.cli import main
from clutchlab.eclutch import ClutchModel, ComponentCurves, EClutchParameters, load_variant
from clutchlab.errors import ParameterError

U = np.linspace(0.0, 8e-3, 25)


def _bundled_csv(name):
    return resources.files("clutchlab.eclutch") / "data" / "curves" / f"{name}.csv"


@pytest.fixture(scope="module")
def bundled():
    return ComponentCurves.bundled()


@pytest.mark.parametrize("number", [0, 2, 4])
def test_replacing_a_component_by_itself_reproduces_the_preset(bundled, number):
    with resources.as_file(_bundled_csv("diaphragm")) as path:
        curves = bundled.replace("diaphragm", path, scale=1.0)
    got = ClutchModel.preset(number, curves=curves).static_curve(U)
    ref = ClutchModel.preset(number).static_curve(U)
    for col in ("bearing_force_N", "normal_force_N", "torque_Nm"):
        np.testing.assert_allclose(got[col], ref[col], rtol=1e-9, atol=1e-6)


def test_scaled_diaphragm_model0_satisfies_the_tip_balance_with_the_scaled_curve(bundled):
    # Model 0 closed form (docs/eclutch.md): F_b = F_ds + (F_fp + F_rs) / i_ds with the rigid lever
    p = EClutchParameters()
    model = ClutchModel.preset(0, curves=bundled.replace("diaphragm", bundled.diaphragm, scale=1.3))
    df = model.static_curve(U)
    net = model.network
    x_t, x_pp = df["x_tip_m"].to_numpy(), df["x_pp_m"].to_numpy()
    f_ds = 1.3 * bundled.diaphragm(net.element("diaphragm").prestrain + x_t)
    f_fp = np.maximum(bundled.cushion(net.element("cushion").prestrain + x_pp), 0.0)
    f_rs = bundled.return_springs(net.element("return").prestrain + x_pp)
    np.testing.assert_allclose(df["bearing_force_N"], f_ds + (f_fp + f_rs) / p.lever_ratio, rtol=1e-6, atol=1e-3)
    # the bearing is zeroed again: at position 0 it carries the CSC preload, and the stiffer spring
    # needs more force to release
    assert df["bearing_force_N"].iloc[0] == pytest.approx(p.bearing_preload, abs=1e-6)
    ref = ClutchModel.preset(0).static_curve(U)
    assert df["bearing_force_N"].max() > 1.15 * ref["bearing_force_N"].max()


@pytest.mark.parametrize("preload", [80.0, 120.0])
def test_scaled_component_keeps_the_bearing_preload_in_model4(bundled, preload):
    params = EClutchParameters(bearing_preload=preload)
    df = ClutchModel.preset(4, params, bundled.replace("diaphragm", bundled.diaphragm, scale=1.3)).static_curve(U)
    assert df["bearing_force_N"].iloc[0] == pytest.approx(preload, abs=1e-6)
    # just behind position 0 the bearing contact opens: the force falls below the preload but stays >= 0
    back = ClutchModel.preset(4, params, bundled.replace("diaphragm", bundled.diaphragm, scale=1.3)).static_curve(
        [0.0, -2e-5])
    assert 0.0 <= back["bearing_force_N"].iloc[1] < preload


def _variant(tmp_path, base, extra=""):
    with resources.as_file(_bundled_csv("diaphragm")) as src:
        (tmp_path / "diaphragm.csv").write_bytes(src.read_bytes())
    path = tmp_path / "variant.toml"
    path.write_text(f'[network]\nbase = {base}\n\n[[network.springs]]\nname = "diaphragm"\na = "tip"\n'
                    f'curve = "diaphragm.csv"\n{extra}')
    return path


def test_variant_replacing_model4_diaphragm_keeps_its_scale_node_and_bearing_zero(tmp_path):
    # the bug: the variant dropped the x1.3 scale (and b = "support") and kept the old zero, so the
    # bearing had lifted off (0 N) at position 0 instead of carrying the 80 N preload
    model = load_variant(_variant(tmp_path, 4))
    dia = model.network.element("diaphragm")
    assert dia.scale == pytest.approx(1.3) and dia.b == "support"
    got = model.static_curve(U)
    ref = ClutchModel.preset(4).static_curve(U)
    np.testing.assert_allclose(got["bearing_force_N"], ref["bearing_force_N"], rtol=1e-7, atol=1e-5)
    assert got["bearing_force_N"].iloc[0] == pytest.approx(80.0, abs=1e-6)


def test_variant_scale_matches_the_component_api_in_model0(tmp_path, bundled):
    model = load_variant(_variant(tmp_path, 0, "scale = 1.3\n"))
    api = ClutchModel.preset(0, curves=bundled.replace("diaphragm", bundled.diaphragm, scale=1.3))
    np.testing.assert_allclose(model.static_curve(U)["bearing_force_N"], api.static_curve(U)["bearing_force_N"],
                               rtol=1e-7, atol=1e-5)


def test_variant_bearing_preload_key(tmp_path):
    path = _variant(tmp_path, 4)
    path.write_text(path.read_text().replace("base = 4\n", 'base = 4\nbearing_preload = "0.1 kN"\n'))
    df = load_variant(path).static_curve([0.0])
    assert df["bearing_force_N"].iloc[0] == pytest.approx(100.0, abs=1e-6)


def test_params_file_replaces_a_component_via_cli(tmp_path, bundled):
    with resources.as_file(_bundled_csv("diaphragm")) as src:
        (tmp_path / "mine.csv").write_bytes(src.read_bytes())
    (tmp_path / "my_clutch.toml").write_text(
        '[eclutch]\nbearing_preload = "80 N"\n\n[eclutch.curves]\ndiaphragm = {file = "mine.csv", scale = 1.3}\n')
    out = tmp_path / "curves.csv"
    assert main(["eclutch", "static", "--model", "4", "--params", str(tmp_path / "my_clutch.toml"),
                 "-o", str(out), "--points", "25", "--travel", "8 mm"]) == 0
    got = pd.read_csv(out, comment="#")
    api = ClutchModel.preset(4, curves=bundled.replace("diaphragm", bundled.diaphragm, scale=1.3)).static_curve(U)
    np.testing.assert_allclose(got["bearing_force_N"], api["bearing_force_N"], rtol=1e-7, atol=1e-5)  # CSV digits
    assert got["bearing_force_N"].iloc[0] == pytest.approx(80.0, abs=1e-6)


@pytest.mark.parametrize("call, match", [
    (lambda c: c.replace("diaphram", c.diaphragm), "unknown component 'diaphram'; did you mean 'diaphragm'"),
    (lambda c: c.replace("diaphragm", c.diaphragm, scale=0.0), "scale = 0.0 must be finite and > 0"),
    (lambda c: c.replace("cushion", [1, 2]), "expected a clutchlab.Curve or a CSV path"),
])
def test_replace_errors(bundled, call, match):
    with pytest.raises(ParameterError, match=match):
        call(bundled)


def test_params_file_unknown_component_names_file_and_key(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text('[eclutch.curves]\ndiafragm = "x.csv"\n')
    with pytest.raises(ParameterError, match=r"p.toml: \[eclutch.curves\]: unknown key 'diafragm'; did you mean"):
        ClutchModel.from_toml(4, path)
