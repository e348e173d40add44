"""Models 0-4: limits between models, invariants, presets, parameter files, bad input."""

import dataclasses

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab import Curve
from clutchlab.eclutch import (ClutchModel, ComponentCurves, EClutchParameters, Lever, Node, Spring,
                               VirtualClutch, build_model, clutch_torque)
from clutchlab.errors import ParameterError

U = np.linspace(0.0, 9e-3, 121)


@pytest.fixture(scope="module")
def truth():
    return VirtualClutch()


@pytest.fixture(scope="module")
def true_curves(truth):
    """Component curves without measurement errors (the virtual clutch's own laws)."""
    return ComponentCurves(diaphragm=truth.diaphragm_at_tip(), cushion=truth.cushion(),
                           return_springs=truth.return_springs(), pp_spring=truth.pp_spring(),
                           support_ring=truth.support_ring(), yoke_spring=truth.yoke_spring())


def curve_of(n, params, curves):
    return ClutchModel.preset(n, params, curves).static_curve(U)


def max_rel_diff(a, b):
    return float(np.max(np.abs(a.bearing_force_N - b.bearing_force_N)) / b.bearing_force_N.max())


def test_models_add_elements_to_model0(true_curves):
    names = {n: {e.name for e in build_model(n, curves=true_curves).elements} for n in range(5)}
    assert names[0] == {"bearing", "diaphragm", "lever", "return", "cushion"}
    assert names[1] == names[0]  # same elements, the lever becomes compliant
    assert names[2] == names[1] | {"pp_spring"}
    assert names[3] == names[2] | {"support"}
    assert names[4] == names[3]
    assert build_model(0, curves=true_curves).element("lever").rigid
    assert not build_model(1, curves=true_curves).element("lever").rigid
    assert build_model(3, curves=true_curves).element("diaphragm").b == "ground"
    assert build_model(4, curves=true_curves).element("diaphragm").b == "support"
    assert build_model(4, curves=true_curves).element("diaphragm").scale == pytest.approx(1.3)
    assert build_model(4, curves=true_curves).element("support").scale == pytest.approx(20.0)
    nodes = {n: [x.name for x in build_model(n, curves=true_curves).nodes] for n in range(5)}
    assert nodes[2] == nodes[1] + ["edge"] and nodes[3] == nodes[2] + ["support"]


def test_model1_with_stiff_lever_equals_model0(true_curves):
    p = EClutchParameters(k_fl_model1=1e13)
    assert max_rel_diff(curve_of(1, p, true_curves), curve_of(0, p, true_curves)) < 1e-5


def test_model2_with_stiff_pressure_plate_spring_equals_model1(true_curves):
    p = EClutchParameters(k_fl_model1=1.2e6, k_fl_model2=1.2e6)
    stiff = dataclasses.replace(true_curves, pp_spring=Curve.linear(1e13, span=(0.0, 1e-3)))
    assert max_rel_diff(curve_of(2, p, stiff), curve_of(1, p, stiff)) < 1e-5


def test_model3_with_stiff_support_equals_model2(true_curves):
    p = EClutchParameters()
    stiff = dataclasses.replace(true_curves, support_ring=Curve.linear(1e14, span=(0.0, 1e-3)),
                                yoke_spring=Curve.linear(1e14, span=(0.0, 1e-3)))
    assert max_rel_diff(curve_of(3, p, stiff), curve_of(2, p, stiff)) < 1e-5


def test_model4_with_stiff_support_and_unit_scales_equals_model3(true_curves):
    p = EClutchParameters(support_scale=1.0, diaphragm_scale=1.0)
    stiff = dataclasses.replace(true_curves, support_ring=Curve.linear(1e14, span=(0.0, 1e-3)),
                                yoke_spring=Curve.linear(1e14, span=(0.0, 1e-3)))
    assert max_rel_diff(curve_of(4, p, stiff), curve_of(3, p, stiff)) < 1e-5


def test_model4_scaling_differs_from_model3(true_curves):
    p = EClutchParameters()
    assert max_rel_diff(curve_of(4, p, true_curves), curve_of(3, p, true_curves)) > 0.05


def test_models_share_the_engaged_state(true_curves):
    """Compliances added where Model 0 is rigid are assembled carrying Model 0's loads."""
    p = EClutchParameters()
    first = [curve_of(n, p, true_curves).iloc[0] for n in range(4)]
    for row in first[1:]:
        assert row.bearing_force_N == pytest.approx(first[0].bearing_force_N, rel=1e-6)
        assert row.normal_force_N == pytest.approx(first[0].normal_force_N, rel=1e-6)
    assert first[0].bearing_force_N == pytest.approx(p.bearing_preload, rel=1e-6)


def test_static_curve_frame_and_torque(true_curves):
    p = EClutchParameters()
    df = curve_of(4, p, true_curves)
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns[:4]) == ["bearing_position_m", "bearing_force_N", "normal_force_N", "torque_Nm"]
    np.testing.assert_allclose(df.torque_Nm, 2 * df.normal_force_N * p.r_eff * p.mu)
    assert clutch_torque(5000.0, 0.1, 0.3) == pytest.approx(300.0)


@settings(max_examples=examples(12), deadline=None)
@given(n=st.sampled_from([0, 1, 2, 3, 4]), ratio=st.floats(-5.0, -3.2), cushion=st.floats(0.55e-3, 0.8e-3),
       k_fl=st.floats(6e5, 3e6))
def test_torque_non_increasing_with_release_and_zero_after_liftoff(true_curves, n, ratio, cushion, k_fl):
    p = EClutchParameters(lever_ratio=ratio, cushion_prestrain=cushion, k_fl_model1=k_fl, k_fl_model2=k_fl)
    u = np.linspace(0.0, 12e-3, 241)
    df = ClutchModel.preset(n, p, true_curves).static_curve(u)
    torque = df.torque_Nm.to_numpy()
    assert np.all(np.diff(torque) <= 1e-6 * torque[0])
    if n <= 2:  # pivot on the cover: 12 mm of release travel lifts the pressure plate off
        assert torque[-1] == 0.0
    # (Models 3-4 pivot on the compliant yoke support, which may absorb part of the travel)
    if torque[-1] == 0.0:
        off = np.flatnonzero(torque == 0.0)[0]
        assert np.all(torque[off:] == 0.0), "once lifted off, the clutch stays open"


def test_user_variant_without_new_code(true_curves):
    """A variant: Model 0 plus a compliant support, described with the public building blocks."""
    base = build_model(0, curves=true_curves)
    variant = base.modified(
        nodes=(Node("support", 0.3),),
        replace={"lever": Lever("lever", "tip", "pp", -4.0, pivot="support")},
        add=(Spring("support", "ground", Curve.linear(5e7), b="support", prestrain=1e-4),),
        name="Model 0 + support")
    df = ClutchModel(variant).static_curve(U)
    assert df.bearing_force_N.max() > 500 and "x_support_m" in df


def test_presets_use_inspected_prestrains(truth):
    insp = truth.inspection()
    p = EClutchParameters()
    assert p.diaphragm_prestrain == pytest.approx(insp["diaphragm"], rel=1e-3)
    assert p.cushion_prestrain == pytest.approx(insp["cushion"], rel=1e-3)
    assert p.return_prestrain == pytest.approx(insp["return"], rel=1e-3)


@pytest.mark.parametrize("bad", [5, -1, 2.5, "4", True])
def test_unknown_model_number(bad, true_curves):
    with pytest.raises(ParameterError, match="unknown model number"):
        ClutchModel.preset(bad, curves=true_curves)


def test_parameter_file_round_trip_and_errors(tmp_path, true_curves):
    p = EClutchParameters(lever_ratio=-3.8)
    path = p.to_toml(tmp_path / "eclutch.toml")
    assert EClutchParameters.from_toml(path) == p
    with pytest.raises(FileExistsError):
        p.to_toml(path)
    bad = tmp_path / "bad.toml"
    bad.write_text('[eclutch]\nlever_ratio = -4\nk_fl_model1 = "1.2 kg"\n')
    with pytest.raises(ParameterError, match=r"bad.toml: k_fl_model1 = '1.2 kg': wrong unit"):
        ClutchModel.from_toml(1, bad)
    bad.write_text('[eclutch]\nlever_ratio = 4\n')
    with pytest.raises(ParameterError, match=r"bad.toml.*lever_ratio = 4.0.*upper bound"):
        ClutchModel.from_toml(1, bad)
    bad.write_text('[eclutch]\nlever_rato = -4\n')
    with pytest.raises(ParameterError, match="unknown parameter 'lever_rato'"):
        ClutchModel.from_toml(1, bad)
    bad.write_text('[eclutch]\nm_pp = "-3 kg"\n')
    with pytest.raises(ParameterError, match="m_pp = -3.0: must be > 0"):
        ClutchModel.from_toml(1, bad)
    bad.write_text('[eclutch\n')
    with pytest.raises(ParameterError, match="not valid TOML"):
        ClutchModel.from_toml(1, bad)
    good = tmp_path / "units.toml"
    good.write_text('[eclutch]\nk_fl_model1 = "1.3 MN/m"\nr_eff = "105 mm"\n')
    m = ClutchModel.from_toml(1, good)
    assert m.r_eff == pytest.approx(0.105)
    assert m.network.element("lever").stiffness == pytest.approx(1.3e6)


def test_every_parameter_changes_some_model():
    """No dead parameter: each field of EClutchParameters, changed by 10 %, changes the network or the friction
    numbers of at least one of Models 0-4, built from the bundled press-rig curves (whose yoke support is measured
    below ``support_max_force``, so it is extrapolated there) (until the fortieth session ``pp_spring_prestrain`` and
    ``support_prestrain`` were fields nothing read: Models 2-4 derive those pre-strains from Model 0's engaged
    loads, so a value in a file, a sweep or an FMU changed nothing)."""
    base = EClutchParameters()

    def numbers(obj):   # (every number of a network, its elements and their curves, in order)
        if isinstance(obj, Curve):
            return [*np.asarray(obj.deflection, float), *np.asarray(obj.force, float)]
        if dataclasses.is_dataclass(obj):
            return [v for fl in dataclasses.fields(obj) for v in numbers(getattr(obj, fl.name))]
        if isinstance(obj, (tuple, list)):
            return [v for item in obj for v in numbers(item)]
        return [float(obj)] if isinstance(obj, (int, float, np.floating)) and not isinstance(obj, bool) else []

    def built(params):
        out = []
        for n in range(5):
            model = ClutchModel.preset(n, params)
            out += numbers(model.network) + [float(model.r_eff), float(model.mu)]
        return np.array(out)

    reference = built(base)
    assert np.array_equal(built(base), reference)   # (the same parameters build the same numbers)
    for f in dataclasses.fields(EClutchParameters):
        value = getattr(base, f.name)
        changed = built(base.replace(**{f.name: value * 1.1 if value else 1e-4}))
        assert changed.shape != reference.shape or not np.array_equal(changed, reference), f.name
