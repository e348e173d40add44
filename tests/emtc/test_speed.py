"""The speed work of issue #14 leaves the drum-bench model's answers where they were.

``data/speed_traces.npz`` holds the model's answers before that work (commit 5eb22d8, written by
``data/make_speed_traces.py``: the figure scenario of the issue with 2 ms and 10 ms controllers, a release with
every armature event, lock-up and unlock with constant and LuGre friction, a friction map and a plant magnet
other than the controller's model), at the default tolerances.  The faster model must give:

* the same trajectories: every state and the recorded outputs at about 60 samples, each column to 1e-9 of its
  largest magnitude, plus 1e-6 of a state's absolute tolerance (the Torsen twist stays near 1e-16 rad in
  these runs); the integration error at rtol 1e-6 is about 1e-7 of the range: a changed equation or a
  changed step would show; the evaluation order of a few sums may change the last bits;
* the same modes at every sample, the same events in the same order at the same instants (to 1e-10 s; the
  core locates them to 1e-12 s) and the same number of accepted steps.

Since issue #30 the core restarts at an event from the step's own solution: the answers then moved within the
integration error (:data:`SINCE_ISSUE_30`, :data:`EVENT_ATOL`), and the LuGre lock-up towards the tight solution.

Nothing here is timed.
"""

from pathlib import Path

import importlib.util

import numpy as np
import pytest

DATA = Path(__file__).with_name("data") / "speed_traces.npz"


def _maker():
    spec = importlib.util.spec_from_file_location("make_speed_traces", DATA.with_name("make_speed_traces.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


MAKER = _maker()
SCENARIOS = list(MAKER.scenarios())
#: the release: when the armature leaves the clutch the magnet force jumps by 0.4 % (the engaged airgap lies
#: halfway between two calibration airgaps, docs/emtc.md), so the last bits of the release instant (1e-13 s
#: apart after unrelated changes to the core's arithmetic) move the flight by about 2e-8 of its range even at
#: rtol 1e-9; until then the states agree to 1e-15.  A changed equation or step still shows (>= 1e-6).
RELATIVE = {"release": 1e-7}
#: since the core restarts at an event from the step's own solution (located on it, not on the dense output:
#: issue #30, docs/driveline.md "Energy"), the answers move within the integration error at rtol 1e-6: the
#: armature's flight right after its events by up to 2.9e-6 of its range (its speed), the coil current and the
#: forces by 3e-7, the rest by 1e-9; the event instants by up to 1.6e-7 s (the lock-up of ``lugre`` by 1.1e-5 s,
#: towards the tight solution: checked against it below).  Modes and accepted steps are unchanged.
#: ``lugre``'s data were regenerated in the twenty-sixth session (the bristles advanced along the slip's path,
#: data/README.md): the earlier update had put its speeds after the unlock 7.9e-5 of their range off.
SINCE_ISSUE_30 = 5e-6
EVENT_ATOL = 2e-7


@pytest.mark.parametrize("name, magnet, scenario, kwargs", SCENARIOS, ids=[s[0] for s in SCENARIOS])
def test_same_trajectories_events_and_steps_as_before(name, magnet, scenario, kwargs):
    from clutchlab.emtc import simulate_bench
    from clutchlab.emtc import system as S

    data = np.load(DATA)
    res = simulate_bench(magnet, scenario, **kwargs)
    r = res.result
    rows = slice(None, None, max(1, r.time.size // 60))
    np.testing.assert_array_equal(r.time[rows], data[f"{name}_time"])
    np.testing.assert_array_equal(r.modes[rows], data[f"{name}_modes"])
    names = [o[0] for o in S.OUTPUTS]
    for label, got, ref, floor in (("state", r.states[rows], data[f"{name}_states"], S.ATOL),
                                   ("output", r.outputs[rows][:, [names.index(o) for o in MAKER.OUTPUTS]],
                                    data[f"{name}_outputs"], np.zeros(len(MAKER.OUTPUTS)))):
        for q in range(ref.shape[1]):
            scale = np.max(np.abs(ref[:, q]))
            err = np.max(np.abs(got[:, q] - ref[:, q])) / max(scale, 1e-300)
            assert err * scale <= max(RELATIVE.get(name, 1e-9), SINCE_ISSUE_30) * scale + 1e-6 * floor[q], \
                f"{name}: {label} {q} differs by {err:.2e} of its range"
    assert list(r.events["event"]) == [str(e) for e in data[f"{name}_event_name"]]
    got, ref = r.events["time_s"].to_numpy(), data[f"{name}_event_time"]
    if name == "lugre":   # the lock-up: see test_lugre_lockup_at_the_default_tolerance_is_where_the_tight_run_has_it
        got, ref = np.delete(got, 2), np.delete(ref, 2)
    np.testing.assert_allclose(got, ref, rtol=0, atol=EVENT_ATOL)
    assert res.n_steps == int(data[f"{name}_steps"][0])


def test_figure_error_against_the_tight_reference_is_no_worse_than_before():
    """The figure of issue #14 at the default tolerances against an independent tight solution: SciPy's DOP853
    at rtol 1e-12 on the Python equations of ``benchmarks/wp_emtc.py`` (the error its work-precision table
    quotes: the worst front/rear shaft speed at the 501 samples).  Before the speed work: 4.71e-6 rad/s (the
    transient of the first 10 ms); it may not grow."""
    import sys

    from clutchlab.emtc import simulate_bench
    from clutchlab.emtc.system import ATOL

    bench = Path(__file__).resolve().parents[2] / "benchmarks"
    sys.path.insert(0, str(bench))
    try:
        spec = importlib.util.spec_from_file_location("wp_emtc_for_test", bench / "wp_emtc.py")
        wp = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(wp)
    finally:
        sys.path.remove(str(bench))
    name, magnet, scenario, kwargs = SCENARIOS[0]
    assert name == "figure"
    ref, _ = wp.reference(magnet, scenario, rtol=1e-12, atol=ATOL * 1e-6, method="DOP853")
    r = simulate_bench(magnet, scenario, **kwargs).result
    assert wp.error(r.states[:, :2], ref) <= 4.75e-6


def test_lugre_lockup_at_the_default_tolerance_is_where_the_tight_run_has_it():
    """The LuGre scenario's lock-up against the same model at rtol 1e-12.  The snapshot above had it 1.08e-5 s
    late (0.0118415 s against 0.0118307 s: located on the dense output, the bristle state it restarted from at the
    armature's contact carried the interpolant's error; the snapshot itself is no longer in the data, regenerated
    for the C1 airgap reading, data/README.md); 1.9e-8 s since the core restarts from the step's own solution at
    events; 3.7e-7 s at rtol 1e-6, 1.9e-9 s at 1e-7, 2.0e-8 s at 1e-8 and 1e-10 s from 1e-9 on since the
    bristles are advanced along the slip's path (twenty-sixth session: the lock-up comes 0.17 ms after the
    armature's contact, within one or two steps at the default tolerance)."""
    from clutchlab.emtc import simulate_bench

    name, magnet, scenario, kwargs = next(s for s in SCENARIOS if s[0] == "lugre")
    tight = simulate_bench(magnet, scenario, rtol=1e-12, **kwargs).result.events
    assert list(tight["event"]) == ["armature_leave_rest", "armature_contact", "lockup", "unlock"]
    for rtol, bound in ((1e-6, 5e-7), (1e-8, 5e-8)):
        ev = simulate_bench(magnet, scenario, rtol=rtol, **kwargs).result.events
        assert list(ev["event"]) == list(tight["event"])
        assert abs(ev["time_s"].iloc[2] - tight["time_s"].iloc[2]) < bound, rtol
