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


def _event_times(res):
    return dict(zip(res.result.events.event, res.result.events.time_s))


def test_piston_stroke_follows_the_tolerance():
    """Off its stop the piston reaches the actuator's speed limit within about a microsecond; the core now
    restarts the step size there (``wet_update`` returns ``RESTART``).  The stroke from leaving the stop to
    the film contact then follows the tolerance; with the step of before the event it was 2.6e-6 s too long
    at every rtol from 1e-5 to 1e-7 (9.1e-4 s at 1e-3), and the whole engagement lagged behind.  Since the events
    are located on the step's own solution (issue #30), the loosest tolerances no longer get the stroke right by
    cancellation (both its ends are off by 1.6-1.9e-6 s at rtol 1e-3, as before): -2.9e-7 s at 1e-3, -1.9e-7 s
    at 1e-4, below 5e-9 s from 1e-5 on."""
    from clutchlab.wet import simulate_engagement

    scen = EngagementProtocol(duration=0.3).scenario(CLUTCH, "speed")
    ref = _event_times(simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, rtol=1e-12, sample_rate=100))
    stroke_ref = ref["contact"] - ref["piston_leaves_stop"]
    for rtol, bound in ((1e-3, 1e-6), (1e-4, 1e-6), (1e-5, 1e-8), (1e-6, 1e-8), (1e-7, 1e-8)):
        ev = _event_times(simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, rtol=rtol, sample_rate=100))
        assert abs(ev["contact"] - ev["piston_leaves_stop"] - stroke_ref) < bound, rtol


@pytest.mark.parametrize("mode, sign", [(W.SLIP, 1.0), (W.SLIP_NEG, -1.0)])
def test_friction_law_is_smooth_through_zero_slip_within_a_slip_mode(speed_system, mode, sign):
    """In a slip mode the friction law reads |v| as the mode's sliding direction gives it (v, or -v): the
    slip acceleration has no kink where the slip speed crosses zero, so the stages of the step that ends
    past a lock-up stay on one smooth function (with |v| itself the second difference at zero was of the
    order of the first)."""
    scen, sysm = speed_system
    x = sysm.x0.copy()
    x[W.S_X] = CLUTCH.piston_h0 + 2e-4    # pressed: contact force and capacity
    m = np.array([mode, W.FREE, W.CONTACT, W.SETTLING], dtype=np.int64)
    eps = 1e-3
    wdot = [evaluate(sysm, 0.5, np.where(np.arange(x.size) == W.S_W, s * eps, x), m=m)[0][W.S_W] for s in (-1, 0, 1)]
    first = abs(wdot[2] - wdot[0]) / 2
    second = abs(wdot[2] - 2 * wdot[1] + wdot[0])
    # smooth: the second difference is O(eps^2), 1.3e-4 of the first (with |v|: 126 times the first)
    assert first > 0 and second < 1e-2 * first


def test_lockup_time_follows_the_tolerance_on_the_bench():
    """The speed-controlled engagement of ``bench_wet.py``/``wp_wet.py``: the lock-up time approaches the
    rtol 1e-12 run decade by decade (measured 1.6e-7, 3.2e-8, 2.4e-9, 6.2e-11 s at rtol 1e-6 ... 1e-9; until
    issue #14: 3.4e-6, 1.1e-7, 1.2e-6, 5.5e-9 s)."""
    from clutchlab.wet import simulate_engagement

    scen = EngagementProtocol(duration=1.0).scenario(CLUTCH, "speed")
    run = lambda rtol: simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, rtol=rtol,  # noqa: E731
                                           sample_rate=100).lockup_time
    ref = run(1e-12)
    errors = [abs(run(rtol) - ref) for rtol in (1e-6, 1e-7, 1e-8, 1e-9)]
    assert all(a > b for a, b in zip(errors, errors[1:])), errors
    assert errors[0] < 1e-6 and errors[2] < 1e-8, errors


def test_the_default_sample_grid_is_shared_but_never_handed_out():
    """``simulate_engagement`` builds its 1 kHz grid once per (duration, rate); the result's times are its own."""
    from clutchlab.wet import simulate_engagement

    scen = EngagementProtocol(duration=0.2).scenario(CLUTCH, "speed")
    a = simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH)
    a.time[:] = -1.0
    b = simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH)
    assert b.time[0] == 0.0 and b.time[-1] == pytest.approx(0.2) and b.time.size == 201
    assert np.all(np.diff(b.time) > 0)


def test_outputs_hook_gives_what_the_right_hand_side_leaves_in_its_scratch(speed_system):
    """``wet_outputs`` writes the outputs straight into the row it is given; ``wet_rhs`` (the driveline's wet
    clutch reads them there) into the scratch of ``p.data``: the same numbers from the same body."""
    scen, sysm = speed_system
    rng = np.random.default_rng(5)
    for _ in range(50):
        x = sysm.x0.copy()
        x[W.S_X] = rng.uniform(-1e-3, 0.03)
        x[W.S_FA] = rng.uniform(0.0, 5000.0)
        x[W.S_W] = rng.uniform(-150.0, 150.0)
        x[W.S_T] = rng.uniform(30.0, 120.0)
        m = np.array([rng.integers(0, len(v)) for v in W.MODE_VALUES], dtype=np.int64)
        t = float(rng.uniform(0.0, 1.0))
        dx, g, y = evaluate(sysm, t, x, m=m)      # rhs first (scratch), then the outputs hook
        assert np.array_equal(y, sysm.params.data[W.W_OUT:W.W_OUT + W.N_OUT])


def test_next_break_from_the_memo_is_the_full_search(speed_system):
    """``wet_next_break`` starts its search at the profile segment read last; from any memo it returns the
    first corner after ``t``."""
    scen, sysm = speed_system
    corners = np.union1d(scen.force_time, scen.speed_time)
    m = sysm.m0.copy()
    rng = np.random.default_rng(7)
    for t in np.concatenate([corners, rng.uniform(-0.1, 1.1, 100), np.nextafter(corners, -np.inf)]):
        p = W.fresh_buffers(sysm.params, scen.initial_temperature_c)
        expected = corners[corners > t][0] if np.any(corners > t) else np.inf
        for memo in (0.0, float(p.constants[0]["speed_start"]), float(p.constants[0]["speed_start"] + 30)):
            p.data[W.W_SSEG] = memo
            assert W.wet_next_break(float(t), m, p) == expected, (t, memo)


def test_wet_hooks_are_compiled_without_reference_counting():
    """The wet clutch's hooks (and what they call on their own) are declared ``_nrt=False``
    (``clutchlab.wet.system._HOOK``): they allocate no array and keep none, and the reference-count calls
    were a quarter of a right-hand side's time.  Guard against a hook losing the option."""
    from clutchlab.numerics import dispatch

    hooks = dispatch._MODELS[W.WetParams]
    assert set(hooks) == set(dispatch.HOOKS) | {"start"}   # (start: the derived constants, wet_start)
    for name, fn in hooks.items():
        assert dispatch._options_key(fn) == ("numpy", False, False), name


def _tanh_exact(x):
    """tanh to 40 significant digits (decimal; e^2x - 1 carried to as many more digits as x is small),
    rounded to the nearest double."""
    import math
    from decimal import Decimal, localcontext

    with localcontext() as ctx:
        ctx.prec = 40 + (int(-math.log10(abs(x))) if 0.0 < abs(x) < 1.0 else 0)
        e = (2 * Decimal(x)).exp()
        return float((e - 1) / (e + 1))


def test_tanh_is_as_accurate_as_the_library_one():
    """``wet.system.tanh`` (the piston's speed limit): within 2 ulp of a 40-digit evaluation over the whole
    range, like ``math.tanh``; odd, exact at 0, saturated at +-1, NaN through."""
    import math

    rng = np.random.default_rng(11)
    xs = np.concatenate([rng.uniform(-0.7, 0.7, 4000), rng.uniform(-25.0, 25.0, 4000),
                         np.logspace(-300, 1.5, 2000), [0.624999999, 0.625, 0.6250000001, 21.99, 22.0, 22.01]])
    worst, worst_lib = 0.0, 0.0
    for x in xs:
        exact = _tanh_exact(float(x))
        ulp = math.ulp(exact) if exact != 0.0 else 5e-324
        worst = max(worst, abs(W.tanh(float(x)) - exact) / ulp)
        worst_lib = max(worst_lib, abs(math.tanh(float(x)) - exact) / ulp)
        assert W.tanh(float(-x)) == -W.tanh(float(x))
    assert worst <= 2.0, (worst, worst_lib)      # measured 1 ulp (math.tanh: 1 ulp)
    assert W.tanh(0.0) == 0.0 and W.tanh(40.0) == 1.0 and W.tanh(-1e308) == -1.0
    assert math.isnan(W.tanh(float("nan")))


@pytest.mark.parametrize("motor", ["speed", "free"])
def test_energy_balance_closes_and_the_friction_work_follows_the_tolerance(motor):
    """Eq. 8's balance (friction work = heat into the pack + heat out) closes to roundoff at every tolerance,
    and the friction work at the default rtol 1e-7 is within 1e-7 of an rtol 1e-10 run (measured 7e-8 for
    the speed-controlled bench, 5e-9 for the dynamometer; until issue #14 the bench's was 1.1e-5 off: the
    piston's lag after leaving its stop)."""
    from clutchlab.wet import simulate_engagement

    scen = EngagementProtocol(duration=1.0).scenario(CLUTCH, motor)
    work = {}
    for rtol in (1e-4, 1e-7, 1e-10):
        eb = simulate_engagement(CLUTCH, scen, bench=BENCH, friction=TRUTH, rtol=rtol,
                                 sample_rate=100).energy_balance()
        assert abs(eb["residual"]) < 1e-12, (rtol, eb)
        work[rtol] = eb["friction_work"]
    assert abs(work[1e-7] - work[1e-10]) < 1e-7 * work[1e-10]
    assert abs(work[1e-4] - work[1e-10]) < 1e-5 * work[1e-10]
