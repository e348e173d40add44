"""Sweep target "eclutch-static": release-curve reductions, M_cl = 2 F_n r_eff mu, lift-off position."""

import numpy as np
import pandas as pd
import pytest
from hypothesis import assume, given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab.eclutch import ClutchModel, EClutchParameters
from clutchlab.sweep import eclutch_static as target


def frame(**cols):
    df = pd.DataFrame(cols)
    df.index = pd.RangeIndex(len(df), name="variant_id")
    return df


SCEN = {"static": {"model": 4, "travel": "9 mm", "points": 91}, "_source": "inline"}


def test_engaged_torque_is_eq_sec32_and_linear_in_mu():
    mus = [0.2, 0.27, 0.35]
    out = target.run_batch(frame(**{"clutch.mu": mus}), SCEN, list(target.OUTPUTS))
    fn = out["engaged_normal_force"].to_numpy()
    assert np.all(fn == fn[0])                                       # mu does not enter the statics
    r_eff = EClutchParameters().r_eff
    np.testing.assert_allclose(out["engaged_torque"], 2 * fn * r_eff * np.array(mus), rtol=1e-14)  # [1] Sec. 3.2


def test_outputs_match_the_static_curve():
    out = target.run_batch(frame(**{"clutch.lever_ratio": [-4.0, -3.6]}), SCEN, list(target.OUTPUTS))
    x = np.linspace(0, 9e-3, 91)
    for vid, ratio in enumerate([-4.0, -3.6]):
        curve = ClutchModel.preset(4, EClutchParameters(lever_ratio=ratio)).static_curve(x)
        fb = curve["bearing_force_N"].to_numpy()
        fn = curve["normal_force_N"].to_numpy()
        assert out.loc[vid, "peak_bearing_force"] == fb.max()
        assert out.loc[vid, "peak_bearing_force_position"] == pytest.approx(x[np.argmax(fb)], abs=1e-15)
        assert out.loc[vid, "end_bearing_force"] == fb[-1]
        lift = out.loc[vid, "lift_off_position"]
        xs = curve["bearing_position_m"].to_numpy()
        j = int(np.flatnonzero(fn <= 0)[0])
        assert xs[j - 1] < lift <= xs[j] + 1e-15                             # between the last clamped and first open sample


@settings(max_examples=examples(50), deadline=None)
@given(x0=st.floats(0.5e-3, 8.5e-3), slope=st.floats(1e5, 1e7), n=st.integers(5, 200))
def test_lift_off_interpolation_is_exact_for_a_linear_clamp_force(x0, slope, n):
    x = np.linspace(0, 9e-3, n)
    assume(x0 > x[1])                                                # two clamped samples give the secant
    fn = np.maximum(slope * (x0 - x), 0.0)                           # clipped at zero, as the network's contact
    if not np.any(fn <= 0):
        assert np.isnan(target.lift_off_position(x, fn))
    else:
        assert target.lift_off_position(x, fn) == pytest.approx(x0, rel=1e-9, abs=1e-15)


def test_scenario_errors():
    from clutchlab.errors import ParameterError

    with pytest.raises(ParameterError, match="model = 7"):
        target.describe({"static": {"model": 7}, "_source": "e.toml"})
    with pytest.raises(ParameterError, match="unknown key 'travle'"):
        target.describe({"static": {"travle": "9 mm"}, "_source": "e.toml"})
