"""What the speed work on the wet engagement (issue #14) must not change, and what it corrected.

Every change made for speed is checked here against the computation it replaced or against an
independent solution; nothing here is timed (the figures are in ``benchmarks/bench_wet.py`` and
``benchmarks/wp_wet.py``).
"""

import numpy as np
import pytest

from clutchlab.system import evaluate
from clutchlab.wet import Bench, ParametricFriction, WetClutch
from clutchlab.wet import system as W
from clutchlab.wet.bench import EngagementProtocol

CLUTCH = WetClutch.paper()
BENCH = Bench()
TRUTH = ParametricFriction.bench_truth()


@pytest.fixture(scope="module")
def speed_system():
    scen = EngagementProtocol(duration=1.0).scenario(CLUTCH, "speed")
    return scen, W.engagement_system(scen, clutch=CLUTCH, bench=BENCH, friction=TRUTH)


def test_profile_segment_memo_gives_the_bisection_value(speed_system):
    """The reference profiles remember the segment read last (``W_FSEG``, ``W_SSEG``); read in any order --
    forwards, backwards, at random, on the corners themselves and beyond the ends -- they give exactly
    what a fresh buffer (bisection) gives."""
    scen, sysm = speed_system
    rng = np.random.default_rng(3)
    corners = np.concatenate([scen.force_time, scen.speed_time])
    ts = np.concatenate([np.linspace(-0.1, 1.1, 301), np.linspace(1.1, -0.1, 97), rng.uniform(-0.1, 1.1, 200),
                         corners, corners[::-1], np.nextafter(corners, np.inf), np.nextafter(corners, -np.inf)])
    x = sysm.x0.copy()
    for t in ts:
        y_memo = evaluate(sysm, float(t), x)[2]               # one buffer for every call: the memo carries on
        fresh = sysm.variant(params=W.fresh_buffers(sysm.params, scen.initial_temperature_c))
        y_fresh = evaluate(fresh, float(t), x)[2]
        assert y_memo[W.O_WREF] == y_fresh[W.O_WREF] and y_memo[W.O_FREF] == y_fresh[W.O_FREF], t
    assert sysm.params.data[W.W_SSEG] >= sysm.params.constants[0]["speed_start"]  # the memo was used
