"""Write ``speed_traces.npz``: the drum-bench model's answers before the speed work of issue #14.

Provenance: run on commit 5eb22d8 (main before the branch ``speed-emtc``) with
``PYTHONPATH=src python tests/emtc/data/make_speed_traces.py``.  ``tests/emtc/test_speed.py`` checks that the
faster model gives the same trajectories (every sample, every state and output) and the same event times.
Rerunning it on a later commit would replace the reference by the answer it is meant to check: don't, unless the
physics changed on purpose (then say so in the README: rerun once, in the twenty-fifth session, for the C1 airgap
reading).

Scenarios, each at the default tolerances (rtol 1e-6, the figure of issue #14 is run so; ``release`` at
1e-9), recorded at the
controller samples and kept at about 60 of them (every state, the outputs of :data:`OUTPUTS`, the modes), with
the named events and the number of accepted steps:

* ``figure``: the work-precision scenario of ``benchmarks/bench_emtc.py`` / ``wp_emtc.py`` (1 s, 2 ms controller);
* ``figure_10ms``: the same with a 10 ms controller;
* ``release``: a prescribed reference that engages the coupling and drops to zero (the armature leaves the
  clutch, flies back and rests: every armature event), at rtol 1e-9: the magnet force jumps by 0.4 % (0.9 N)
  when the armature leaves the clutch (the airgap interpolation through the three nearest calibration airgaps
  takes another triple on either side of the engaged airgap 0.7 mm, the midpoint of 0.6 and 0.8 mm), and at
  the default tolerances the first step after that event has an error the estimate does not see (the armature's
  speed 4e-5 m/s off): which step is accepted there, and the armature's flight at the default tolerances with
  it, turns on the last bits of the evaluation;
* ``lock_unlock``, ``lugre``: the lock-up and unlock scenarios of ``regression_traces.npz`` (3 s);
* ``friction_map``: the figure scenario with a friction map ``mu(|slip|, T)``;
* ``plant_mismatch``: the figure scenario with the synthetic "true" magnet as the plant and the identified model in
  the controller.
"""

import sys
from pathlib import Path

import numpy as np

from clutchlab.emtc import BenchScenario, FrictionMap, LuGreParameters, bundled_magnet, simulate_bench
from clutchlab.emtc import system as S
from clutchlab.emtc.magnet import synthetic_magnet

OUTPUTS = ("magnet_force", "fn1", "coupling_torque", "lock_torque", "current_command")
FIGURE = dict(duration=1.0, speed_difference=0.3, throttle_start=0.1, throttle_end=0.6, ramp_start=0.1,
              ramp_end=0.9, sample_time=0.002)


def scenarios():
    """``(name, magnet, scenario, simulate_bench keywords)``."""
    magnet = bundled_magnet()
    yield "figure", magnet, BenchScenario(**FIGURE), {}
    yield "figure_10ms", magnet, BenchScenario(**dict(FIGURE, sample_time=0.01)), {}
    yield "release", magnet, BenchScenario(**dict(FIGURE, duration=0.3)), {
        "torque_reference": ([0.0, 0.08, 0.1, 1.0], [150.0, 150.0, 0.0, 0.0]), "rtol": 1e-9, "atol": S.ATOL * 1e-3}
    yield "lock_unlock", magnet, BenchScenario(duration=3.0, speed_difference=0.0, throttle_start=0.0,
                                               throttle_end=0.9, ramp_start=0.3, ramp_end=2.8), {
        "torque_reference": ([0.0, 10.0], [250.0, 250.0])}
    yield "lugre", magnet, BenchScenario(duration=3.0, speed_difference=0.0, throttle_start=0.0, throttle_end=0.9,
                                         ramp_start=0.3, ramp_end=2.8), {
        "torque_reference": ([0.0, 10.0], [150.0, 150.0]), "lugre": LuGreParameters()}
    yield "friction_map", magnet, BenchScenario(**FIGURE), {
        "friction_map": FrictionMap(slip_speed=[0.0, 1.0, 5.0], temperature_c=[20.0, 100.0],
                                    mu=[[0.13, 0.12], [0.12, 0.11], [0.11, 0.10]])}
    yield "plant_mismatch", synthetic_magnet(), BenchScenario(**FIGURE), {"controller_model": magnet}


def main():
    # ``python make_speed_traces.py NAME ...`` rewrites only the named scenarios and keeps the others' data
    only = set(sys.argv[1:])
    path = Path(__file__).with_name("speed_traces.npz")
    data = dict(np.load(path)) if only else {}
    for name, magnet, sc, kw in scenarios():
        if only and name not in only:
            continue
        res = simulate_bench(magnet, sc, **kw)
        r = res.result
        rows = slice(None, None, max(1, r.time.size // 60))
        cols = [[o[0] for o in S.OUTPUTS].index(o) for o in OUTPUTS]
        data[f"{name}_time"] = r.time[rows]
        data[f"{name}_states"] = r.states[rows]
        data[f"{name}_outputs"] = r.outputs[rows][:, cols]
        data[f"{name}_modes"] = r.modes[rows]
        data[f"{name}_event_time"] = r.events["time_s"].to_numpy()
        data[f"{name}_event_name"] = r.events["event"].to_numpy().astype(str)
        data[f"{name}_steps"] = np.array([res.n_steps])
        print(name, res.n_steps, list(r.events["event"]))
    np.savez_compressed(path, **data)


if __name__ == "__main__":
    main()
