"""Sweep target "wet": equal to the wet subsystem's own batch, variant by variant, whatever shares its batch."""

import math

import numpy as np
import pandas as pd
import pytest

from clutchlab.errors import ParameterError
from clutchlab.sweep import wet as target
from clutchlab.wet import Bench, EngagementProtocol, ParametricFriction, WetClutch, simulate_batch
from clutchlab.wet.bench import load_protocol

OUTS = ["engagement_time", "energy", "peak_temperature_c", "final_temperature_c", "final_slip_speed", "n_steps", "status"]


def frame(**cols):
    df = pd.DataFrame(cols)
    df.index = pd.RangeIndex(len(df), name="variant_id")
    return df


def reference(clutch, protocol=None, bench=None, friction=None, motor="speed", **batch):
    """The same variant through clutchlab.wet.simulate_batch (the subsystem's public batch API)."""
    protocol = protocol or EngagementProtocol(force=3000.0, initial_slip_speed=1500 * math.pi / 30, ramp_time=0.7,
                                              duration=1.2)
    scen = protocol.scenario(clutch, motor=motor)
    res = simulate_batch(clutch, scen, {k: [v] for k, v in batch.items()} or {"mu_scale": [1.0]}, bench=bench,
                         friction=friction or ParametricFriction.bench_truth())
    return res.to_dataframe().iloc[0]


def test_clutch_geometry_variants_match_simulate_batch_exactly():
    radii = [0.080, 0.08315, 0.086]
    out = target.run_batch(frame(**{"clutch.r_outer": radii}), None, OUTS)
    ri = WetClutch().r_inner
    for vid, ro in enumerate(radii):
        # the friction area follows the annulus pi (R_o^2 - R_i^2) (full annulus for the default clutch)
        clutch = WetClutch(r_outer=ro, friction_area=math.pi * (ro**2 - ri**2))
        ref = reference(clutch)
        assert out.loc[vid, "engagement_time"] == ref["lockup_time"]
        assert out.loc[vid, "energy"] == ref["friction_work"]
        assert out.loc[vid, "peak_temperature_c"] == ref["peak_temperature_c"]
        assert out.loc[vid, "final_temperature_c"] == ref["final_temperature_c"]
        assert out.loc[vid, "status"] == 0
    # a bigger disk carries more torque: the friction work rises with R_o (Eq. 4 with r_eff)
    assert np.all(np.diff(out["energy"].to_numpy()) > 0)


def test_batch_multipliers_and_bench_fields_match_simulate_batch():
    out = target.run_batch(frame(**{"batch.mu_scale": [0.9, 1.1], "bench.motor_inertia": [0.08, 0.12]}), None,
                           ["energy", "engagement_time"])
    for vid, (mu, j) in enumerate([(0.9, 0.08), (1.1, 0.12)]):
        ref = reference(WetClutch(), bench=Bench(motor_inertia=j), mu_scale=mu)
        assert out.loc[vid, "energy"] == ref["friction_work"]
        assert out.loc[vid, "engagement_time"] == ref["lockup_time"]


def test_friction_and_protocol_variants_split_into_batches_with_the_same_numbers():
    variants = frame(**{"friction.mu0": [0.12, 0.135, 0.15, 0.135], "protocol.force": [3000.0, 3000.0, 3000.0, 2500.0]})
    together = target.run_batch(variants, None, OUTS)
    alone = pd.concat([target.run_batch(variants.iloc[[k]], None, OUTS) for k in range(4)])
    pd.testing.assert_frame_equal(together, alone, check_exact=True)
    truth = ParametricFriction.bench_truth()
    for vid in range(4):
        prot = EngagementProtocol(force=variants.iloc[vid, 1], initial_slip_speed=1500 * math.pi / 30, ramp_time=0.7,
                                  duration=1.2)
        ref = reference(WetClutch(), protocol=prot, friction=truth.replace(mu0=variants.iloc[vid, 0]))
        # normalised profiles change the step sequence: agreement within the integration tolerance
        # (rtol 1e-6 per step; lock-up at the end of the ramp-down reference is located to ~1e-4 s)
        assert together.loc[vid, "energy"] == pytest.approx(ref["friction_work"], rel=2e-5)
        assert together.loc[vid, "engagement_time"] == pytest.approx(ref["lockup_time"], abs=2e-4)


def test_force_and_speed_levels_share_one_batch(monkeypatch):
    """Protocol force / initial slip levels become per-variant scale factors: one kernel call for the chunk."""
    calls = []
    real = target.simulate_batch

    def spy(systems, *args, **kwargs):
        calls.append(len(systems))
        return real(systems, *args, **kwargs)

    monkeypatch.setattr(target, "simulate_batch", spy)
    variants = frame(**{"protocol.force": [2500.0, 3000.0, 3500.0],
                        "protocol.initial_slip_speed": [150.0, 160.0, 170.0]})
    out = target.run_batch(variants, None, ["energy", "engagement_time"])
    assert calls == [3]
    for vid in range(3):
        prot = EngagementProtocol(force=variants.iloc[vid, 0], initial_slip_speed=variants.iloc[vid, 1],
                                  ramp_time=0.7, duration=1.2)
        ref = reference(WetClutch(), protocol=prot)
        assert out.loc[vid, "energy"] == pytest.approx(ref["friction_work"], rel=2e-5)
        assert out.loc[vid, "engagement_time"] == pytest.approx(ref["lockup_time"], abs=2e-4)


def test_bundled_scenario_is_the_wet_engagement_protocol():
    from importlib import resources

    path = resources.files("clutchlab.wet") / "data" / "engagement_protocol.toml"
    protocol, ptype, clutch, bench, friction = load_protocol(path)
    ref = reference(clutch, protocol=protocol, bench=bench, friction=friction)
    out = target.run_batch(frame(**{"batch.mu_scale": [1.0]}), None, ["energy"])
    assert out.loc[0, "energy"] == ref["friction_work"]


def test_inertia_dynamometer_scenario_energy_is_the_kinetic_energy_lost():
    """SAE No. 2 (no motor): the friction work equals the kinetic energy lost, J w0^2 / 2 at lock-up."""
    scenario = {"protocol": {"type": "inertia_dynamometer", "force": "3 kN", "initial_slip_speed": "800 rpm",
                             "duration": "3 s"}, "_source": "inline"}
    out = target.run_batch(frame(**{"bench.motor_inertia": [0.05, 0.08]}), scenario, OUTS)
    for vid, jm in enumerate([0.05, 0.08]):
        j = Bench(motor_inertia=jm).total_inertia
        w0 = 800 * math.pi / 30
        assert out.loc[vid, "final_slip_speed"] == 0.0 and np.isfinite(out.loc[vid, "engagement_time"])
        assert out.loc[vid, "energy"] == pytest.approx(0.5 * j * w0**2, rel=1e-4)
    assert out.loc[1, "engagement_time"] > out.loc[0, "engagement_time"]   # more inertia, longer engagement


def test_describe_lists_namespaced_fields_and_rejects_bad_scenarios():
    info = target.describe(None)
    assert info["parameters"]["clutch.r_outer"] == "m"
    assert info["parameters"]["protocol.initial_slip_speed"] == "rad/s"
    assert info["parameters"]["friction.mu0"] == "1"
    assert set(info["outputs"]) == set(OUTS)
    with pytest.raises(ParameterError, match=r"x\.toml: unknown table \[wett\]"):
        target.describe({"wett": {}, "protocol": {"type": "engagement"}, "_source": "x.toml"})
    with pytest.raises(ParameterError, match="type = 'nope'"):
        target.describe({"protocol": {"type": "nope"}, "_source": "x.toml"})
    with pytest.raises(ParameterError, match="variant 1: batch.mu_scale"):
        target.check_variants(frame(**{"batch.mu_scale": [1.0, -1.0]}), None)
