"""Model variants described in TOML files, without code."""

import numpy as np
import pytest

from clutchlab.cli import main
from clutchlab.eclutch import ClutchModel, EClutchParameters, load_variant
from clutchlab.errors import ParameterError

_VARIANT = """
[network]
name = "Model 2 + compliant support"
base = 2
mu = 0.3

[[network.nodes]]
name = "support"
mass = "0.3 kg"

[[network.levers]]
name = "lever"
tip = "tip"
edge = "edge"
pivot = "support"
ratio = -4.0
stiffness = "{k_fl} N/m"

[[network.springs]]
name = "support"
a = "ground"
b = "support"
stiffness = "1e8 MN/m"
"""
#: the lever of Model 2 with the default k_fl, now pivoting on the new support node
VARIANT = _VARIANT.replace("{k_fl}", repr(EClutchParameters().k_fl_model2))


def test_variant_from_toml_with_a_stiff_support_equals_its_base(tmp_path):
    path = tmp_path / "variant.toml"
    path.write_text(VARIANT)
    model = load_variant(path)
    assert model.mu == pytest.approx(0.3) and model.name == "Model 2 + compliant support"
    assert {e.name for e in model.network.elements} >= {"support", "pp_spring", "lever"}
    u = np.linspace(0, 9e-3, 50)
    base = ClutchModel.preset(2).static_curve(u)
    var = model.static_curve(u)
    np.testing.assert_allclose(var.bearing_force_N, base.bearing_force_N, rtol=1e-5, atol=1e-3)


def test_variant_static_from_cli(tmp_path, capsys):
    path = tmp_path / "variant.toml"
    path.write_text(VARIANT.replace('"1e8 MN/m"', '"40 MN/m"'))
    assert main(["eclutch", "static", "--network", str(path), "-o", str(tmp_path / "v.csv"), "--points", "20"]) == 0
    assert "compliant support" in capsys.readouterr().out


@pytest.mark.parametrize(
    "edit, match",
    [
        (('name = "support"\nmass', 'name = "support"\nmas'), r"network.nodes\[0\]: unknown key 'mas'"),
        (('stiffness = "1e8 MN/m"', 'stiffness = "1e8 MN"'), r"network.springs\[0\].stiffness.*wrong unit"),
        (('stiffness = "1e8 MN/m"', 'curve = "nothere.csv"'), "nothere.csv: no such file"),
        (('pivot = "support"', 'pivot = "moon"'), "unknown node 'moon'"),
        (("base = 2", "base = 7"), "unknown model number 7"),
        (("ratio = -4.0", "ratio = 4.0"), "must be finite and < 0"),
    ],
)
def test_variant_errors_name_file_entry_and_key(tmp_path, edit, match):
    path = tmp_path / "variant.toml"
    path.write_text(VARIANT.replace(*edit))
    with pytest.raises(ParameterError, match=match):
        load_variant(path)
