"""Sweep target "emtc": batches of drum-bench runs equal to simulate_bench."""

import numpy as np
import pandas as pd
import pytest

from clutchlab.emtc.bench import BenchScenario, simulate_bench
from clutchlab.emtc.magnet import bundled_magnet
from clutchlab.errors import ParameterError
from clutchlab.sweep import emtc as target


def test_variants_match_simulate_bench():
    variants = pd.DataFrame({"scenario.speed_difference": [0.1, 0.6], "scenario.duration": [1.5, 1.5]})
    variants.index = pd.RangeIndex(2, name="variant_id")
    outs = list(target.OUTPUTS)
    got = target.run_batch(variants, None, outs)
    mag = bundled_magnet()
    for vid, dv in enumerate([0.1, 0.6]):
        res = simulate_bench(mag, BenchScenario(speed_difference=dv, duration=1.5))
        tc = res["coupling_torque_Nm"]
        slip = res["slip_speed_rad_s"]
        assert got.loc[vid, "peak_coupling_torque"] == np.max(np.abs(tc))
        assert got.loc[vid, "mean_coupling_torque"] == np.mean(tc)
        assert got.loc[vid, "final_slip_speed"] == slip[-1]
        assert got.loc[vid, "n_steps"] == res.n_steps
        locks = res.events["time_s"].to_numpy()[res.events["event"].to_numpy() == "lockup"]
        assert (np.isnan(got.loc[vid, "lock_time"]) and locks.size == 0) or got.loc[vid, "lock_time"] == locks[0]


def test_bad_variant_and_table_are_named():
    variants = pd.DataFrame({"scenario.gear": [2.0, 9.0]})
    variants.index = pd.RangeIndex(2, name="variant_id")
    with pytest.raises(ParameterError, match="variant 1"):
        target.check_variants(variants, None)
    with pytest.raises(ParameterError, match=r"s\.toml: unknown table \[vehicel\]"):
        target.describe({"vehicel": {}, "_source": "s.toml"})
    assert "coupling.mu_k" not in target.describe(None)["parameters"]    # tuple fields are not swept
