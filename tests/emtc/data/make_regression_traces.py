"""Write ``regression_traces.npz``: reference traces of the EMTC drum-bench model before the port to the core.

Provenance: run on the model code of commit 45cc909 (the last one with the model's own Dormand-Prince loop,
``emtc/_bench_kernel.py``), ``python tests/emtc/data/make_regression_traces.py``.  Rerunning it on a
later commit would overwrite the pre-port reference with the ported model's answer: don't, unless the
physics changed on purpose (then say so in the README: rerun once, in the twenty-fifth session, on the ported model
with the C1 airgap reading).

Three scenarios, each at rtol = 1e-9 (tight: the integration error is far below the tolerances of the
regression test), 8 columns subsampled to at most 250 rows, and the named events.
"""

import sys
from pathlib import Path

import numpy as np

from clutchlab.emtc import BenchScenario, LuGreParameters, bundled_magnet, simulate_bench

COLUMNS = ("time_s", "omega_f_rad_s", "omega_r_rad_s", "i2_A", "x_armature_m", "magnet_force_N",
           "coupling_torque_Nm", "current_command_A")


def scenarios():
    yield "slipping", BenchScenario(duration=2.0, speed_difference=0.3, throttle_start=0.1, throttle_end=0.6,
                                    ramp_start=0.2, ramp_end=1.8), {}
    yield "lock_unlock", BenchScenario(duration=3.0, speed_difference=0.0, throttle_start=0.0, throttle_end=0.9,
                                       ramp_start=0.3, ramp_end=2.8), {"torque_reference": ([0.0, 10.0], [250.0, 250.0])}
    yield "lugre", BenchScenario(duration=3.0, speed_difference=0.0, throttle_start=0.0, throttle_end=0.9,
                                 ramp_start=0.3, ramp_end=2.8), {"torque_reference": ([0.0, 10.0], [150.0, 150.0]),
                                                                 "lugre": LuGreParameters()}


def main():
    magnet = bundled_magnet()
    # ``python make_regression_traces.py NAME ...`` rewrites only the named scenarios and keeps the others' data
    only = set(sys.argv[1:])
    path = Path(__file__).with_name("regression_traces.npz")
    data = dict(np.load(path)) if only else {}
    for name, sc, kw in scenarios():
        if only and name not in only:
            continue
        res = simulate_bench(magnet, sc, rtol=1e-9, **kw)
        df = res.to_dataframe()
        step = max(1, len(df) // 250)
        data[f"{name}_columns"] = np.array(COLUMNS)
        data[f"{name}_values"] = df[list(COLUMNS)].to_numpy()[::step]
        data[f"{name}_event_time"] = res.events["time_s"].to_numpy()
        data[f"{name}_event_name"] = res.events["event"].to_numpy().astype(str)
    np.savez_compressed(path, **data)


if __name__ == "__main__":
    main()
