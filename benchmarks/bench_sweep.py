"""Sweep throughput, measured in one run.

A Monte Carlo sweep of 2,000 wet-clutch engagements (the bundled engagement
protocol, Shin et al. Fig. 14; clutch outer radius, friction scale and
pressing force sampled) written as Parquet chunks of 250 with summary, run

1. by ``run_sweep`` in this process (each chunk one ``prange`` batch on all cores),
2. as one bare call of the compiled batch kernel with the same variants (the
   machinery's overhead: validation, parameter vectors, chunk files, summary),
3. on a Dask ``LocalCluster`` with 2 worker processes of 1 thread (results
   checked equal to run 1),

against the plain-SciPy reference: ``solve_ivp`` (RK45, the same
Dormand-Prince pair) with a Python right-hand side of the same equations, the
same events and the same tolerances (``rtol`` 1e-6), from
``benchmarks/bench_wet.py``, timed on a sample of variants and scaled to 2,000.

Run: ``python benchmarks/bench_sweep.py``.  Prints the measured ratios.
"""

from __future__ import annotations

import importlib.util
import math
import pathlib
import tempfile
import time

import numpy as np
import pandas as pd

from clutchlab.sweep import run_sweep, spec_from_dict
from clutchlab.sweep import wet as wet_target
from clutchlab.wet import ParametricFriction, WetClutch
from clutchlab.wet.bench import EngagementProtocol
from clutchlab.wet.params import Bench

N = 2000
SPEC = {
    "sweep": {"model": "wet", "outputs": ["engagement_time", "energy", "peak_temperature_c"], "chunk_size": 250,
              "seed": 11},
    "monte_carlo": {
        "n": N,
        "clutch.r_outer": {"dist": "uniform", "low": "80 mm", "high": "86 mm"},
        "batch.mu_scale": {"dist": "normal", "mean": 1.0, "std": 0.05},
        "batch.force_scale": {"dist": "uniform", "low": 0.8, "high": 1.2},
    },
}


def load_bench_wet():
    path = pathlib.Path(__file__).with_name("bench_wet.py")
    spec = importlib.util.spec_from_file_location("bench_wet", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.RTOL = wet_target.RTOL  # the reference at the sweep's tolerance
    return mod


def main():
    spec = spec_from_dict(SPEC)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        run_sweep(spec_from_dict({**SPEC, "monte_carlo": {**SPEC["monte_carlo"], "n": 8}}), tmp / "warm",
                  progress=False, plot=False)  # compile / load the kernels
        t0 = time.perf_counter()
        local = run_sweep(spec, tmp / "local", progress=False, plot=False)
        t_local = time.perf_counter() - t0
        t0 = time.perf_counter()
        bare = wet_target.run_batch(spec.design, None, list(spec.outputs))
        t_bare = time.perf_counter() - t0
        assert np.array_equal(bare.to_numpy(), local.results[list(spec.outputs)].to_numpy(), equal_nan=True)

        from distributed import LocalCluster

        t0 = time.perf_counter()
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                          silence_logs=40) as cluster:
            t_start = time.perf_counter() - t0
            t0 = time.perf_counter()
            dask = run_sweep(spec, tmp / "dask", scheduler=cluster.scheduler_address, progress=False, plot=False)
            t_dask = time.perf_counter() - t0
        pd.testing.assert_frame_equal(dask.results, local.results, check_exact=True)

    bw = load_bench_wet()
    truth = ParametricFriction.bench_truth()
    bench = Bench()
    sample = spec.design.iloc[:: N // 6][:6]
    t_ref = []
    for _, row in sample.iterrows():
        ro = row["clutch.r_outer"]
        ri = WetClutch().r_inner
        clutch = WetClutch(r_outer=ro, friction_area=math.pi * (ro**2 - ri**2))
        proto = EngagementProtocol(force=3000.0 * row["batch.force_scale"], initial_slip_speed=1500 * math.pi / 30,
                                   ramp_time=0.7, duration=1.2)
        scen = proto.scenario(clutch)
        friction = truth.replace(mu0=truth.mu0 * row["batch.mu_scale"], mu_t=truth.mu_t * row["batch.mu_scale"],
                                 mu_e=truth.mu_e * row["batch.mu_scale"])
        t0 = time.perf_counter()
        bw.solve_reference(clutch, bench, scen, friction, np.linspace(0.0, scen.duration, 13))
        t_ref.append(time.perf_counter() - t0)
    t_scipy = float(np.mean(t_ref)) * N

    print(f"wet engagement sweep, {N} Monte Carlo variants, chunks of 250 (8 Parquet files + results + summary)")
    print(f"  run_sweep, this process (prange batches):  {t_local:8.3f} s  ({t_local / N * 1e3:.3f} ms per variant)")
    print(f"  target run_batch on all at once (no files):{t_bare:8.3f} s  -> sweep machinery overhead "
          f"{t_local / t_bare:.2f}x")
    print(f"  Dask LocalCluster 2x1 (start {t_start:.1f} s):     {t_dask:8.3f} s  ({t_dask / t_local:.2f}x the local run;"
          f" identical results)")
    print(f"  solve_ivp RK45, Python RHS, same events/rtol (mean of {len(t_ref)} x {N}): {t_scipy:8.1f} s")
    print(f"  -> run_sweep is {t_scipy / t_local:,.0f}x faster than the plain-SciPy reference")


if __name__ == "__main__":
    main()
