"""Regenerate the wet-clutch regression traces (``engagement_traces.npz``).

Run from the repository root: ``python tests/wet/data/generate_traces.py``.  The stored file was
written by the compiled Dormand-Prince loop of ``clutchlab.wet.engagement`` *before* the port onto
the integrator core (commit 45cc909); see README.md in this folder.
"""

from __future__ import annotations

import pathlib

import numpy as np

from clutchlab.wet import Bench, ParametricFriction, Scenario, WetClutch, simulate_engagement
from clutchlab.wet.bench import EngagementProtocol

RTOL = 1e-10
MAX_STEP = 1e-3
STATES = ("piston_position_m", "slip_speed_rad_s", "temperature_C", "friction_work_J")
OUTPUTS = ("clutch_torque_Nm", "contact_force_N", "drive_torque_Nm")


def scenarios():
    """The three representative runs: name -> (scenario, sample times)."""
    clutch = WetClutch.paper()
    proto = EngagementProtocol()
    return {
        # protocol (b): bench motor on the smoothed ramp-down, contact and lock-up
        "bench": (proto.scenario(clutch, "speed"), np.linspace(0.0, 1.2, 241)),
        # protocol (c): inertia dynamometer, contact and lock-up
        "dyno": (proto.scenario(clutch, "free"), np.linspace(0.0, 1.2, 241)),
        # pressed at standstill, then the motor is asked to turn: break-away
        "breakaway": (Scenario([0.0, 0.2], [0.0, 1500.0], [0.0, 1.0, 1.5], [0.0, 0.0, 20.0], duration=2.5),
                      np.linspace(0.0, 2.5, 251)),
    }


def main():
    clutch = WetClutch.paper()
    bench = Bench()
    truth = ParametricFriction.bench_truth()
    data = {}
    for name, (scen, ts) in scenarios().items():
        res = simulate_engagement(clutch, scen, bench=bench, friction=truth, sample_times=ts, rtol=RTOL,
                                  max_step=MAX_STEP)
        data[f"{name}/time_s"] = res.time
        for col in STATES:
            data[f"{name}/{col}"] = res.state(col)
        for col in OUTPUTS:
            data[f"{name}/{col}"] = res.output(col)
        data[f"{name}/event_time_s"] = np.array([e.time for e in res.event_list])
        data[f"{name}/event"] = np.array([e.kind for e in res.event_list])
    out = pathlib.Path(__file__).with_name("engagement_traces.npz")
    np.savez_compressed(out, **data)
    print(f"{out}: {out.stat().st_size} bytes")


if __name__ == "__main__":
    main()
