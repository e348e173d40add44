"""Co-simulation and FMU stepping: cost per communication step, against a plain-scipy co-simulation.

Run: ``python benchmarks/bench_fmu.py`` (builds a wet FMU in a temporary folder; FMPy runs it in a
fresh Python process, as a pythonfmu FMU can be instantiated only once per process).

Scenario: wet-clutch inertia-dynamometer engagement (3 kN held from t = 0, free inertia, 1500 rpm),
0.45 s (slipping throughout), communication step 1 ms (450 steps) and 10 ms (45 steps).

* native: one uninterrupted :func:`clutchlab.wet.engagement.simulate_engagement` run (rtol 1e-7).
* co-simulation: :class:`clutchlab.fmu.wet.WetCoSimulation`, ``do_step`` per communication step
  (compiled DOPRI resumed from the stored state).
* FMU: the exported FMU through FMPy (time of ``simulate_fmu`` inside the worker process, without the
  interpreter start).
* scipy reference: the same co-simulation written plainly -- ``solve_ivp`` (RK45, the same
  Dormand-Prince pair, rtol 1e-7, the kernel's atol) restarted at every communication point, with a
  Python right-hand side that calls clutchlab's compiled model function (a pure-Python model would be
  slower still).  Accuracy is reported as the largest slip-speed difference to an rtol 1e-11 native run.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from clutchlab.fmu.wet import WetCoSimulation
from clutchlab.numerics import core
from clutchlab.wet import engagement as E
from clutchlab.wet import system as W

T_END = 0.45
FORCE = 3000.0
START = {"scenario.free_inertia": 1.0}


def native(c, tk, rtol):
    v = c.parameter_values
    sc = E.Scenario(force_time=[0.0], force_value=[FORCE], speed_time=[0.0], speed_value=[0.0], duration=T_END,
                    motor="free", initial_slip_speed=v["scenario.initial_slip_speed"],
                    initial_temperature_c=v["scenario.initial_temperature"],
                    fluid_temperature_c=v["scenario.fluid_temperature"],
                    housing_temperature_c=v["scenario.housing_temperature"])
    return E.simulate_engagement(c.clutch, sc, bench=c.bench, sample_times=tk, rtol=rtol,
                                 max_step=0.01 if rtol > 1e-10 else 1e-3)


def cosim(dt, n):
    c = WetCoSimulation(**START)
    u = {"force_reference": FORCE, "slip_speed_reference": 0.0}
    c.initial_outputs(u)
    w = [c.state[W.S_W]]
    for k in range(n):
        w.append(c.do_step(k * dt, dt, u)["slip_speed"])
    return np.array(w)


def scipy_cosim(dt, n):
    c = WetCoSimulation(**START)
    u = {"force_reference": FORCE, "slip_speed_reference": 0.0}
    c.initial_outputs(u)
    sim = c.simulation
    system = sim.system
    y = sim.x.copy()
    uu = sim.u.copy()
    m = sim.m.copy()
    m[W.M_PISTON] = W.FREE  # the force is far above the preload: the piston leaves its stop at once
    g = np.empty(len(system.switching))
    p = system.params

    def rhs(t, yy):
        dy = np.empty(len(system.states))
        core.evaluate(p, t, np.ascontiguousarray(yy), uu, m, dy, g)  # the model's compiled rhs, through the contract
        return dy

    w = [y[W.S_W]]
    for k in range(n):
        sol = solve_ivp(rhs, (k * dt, (k + 1) * dt), y, method="RK45", rtol=1e-7, atol=system.atol, max_step=0.01)
        y = sol.y[:, -1].copy()
        w.append(y[W.S_W])
    return np.array(w)


_WORKER = """
import json, sys, time, os
import numpy as np
import fmpy
spec = json.load(open(sys.argv[1]))
n, dt = spec["n"], spec["dt"]
table = np.zeros(n + 1, dtype=[("time", float), ("force_reference", float), ("slip_speed_reference", float)])
table["time"] = np.arange(n + 1) * dt
table["force_reference"] = spec["force"]
t0 = time.perf_counter()
res = fmpy.simulate_fmu(spec["path"], stop_time=n * dt, step_size=dt, output_interval=dt, input=table,
                        output=["slip_speed"], start_values=spec["start"])
el = time.perf_counter() - t0
np.save(spec["out"], res["slip_speed"])
print(el, flush=True)
os._exit(0)
"""


def fmu(path, dt, n, tmp):
    spec = {"path": str(path), "n": n, "dt": dt, "force": FORCE, "start": START, "out": str(tmp / "w.npy")}
    (tmp / "spec.json").write_text(json.dumps(spec))
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", _WORKER, str(tmp / "spec.json")], capture_output=True, text=True,
                          check=True)
    total = time.perf_counter() - t0
    return float(proc.stdout.strip().splitlines()[-1]), total, np.load(tmp / "w.npy")


def best(fn, repeat=3):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main():
    from clutchlab.fmu.export import export_fmu

    cosim(0.01, 2)  # compile / load caches
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = export_fmu("wet", tmp / "wet.fmu")
        c = WetCoSimulation(**START)
        fmu_times = {}
        for dt in (1e-3, 1e-2):
            n = int(round(T_END / dt))
            tk = np.arange(n + 1) * dt
            ref = native(c, tk, 1e-11).state("slip_speed_rad_s")
            t_nat, nat = best(lambda: native(c, tk, 1e-7))
            t_co, w_co = best(lambda: cosim(dt, n))
            t_sp, w_sp = best(lambda: scipy_cosim(dt, n), repeat=1)
            t_fmu, t_fmu_total, w_fmu = fmu(path, dt, n, tmp)
            fmu_times[n] = t_fmu
            err = lambda w: np.max(np.abs(w - ref))  # noqa: E731
            print(f"\ncommunication step {dt * 1e3:g} ms, {n} steps, {T_END} s simulated")
            print(f"  native simulate_engagement  {t_nat * 1e3:9.2f} ms   slip error {err(nat.state('slip_speed_rad_s')):.2e} rad/s")
            print(f"  co-simulation do_step chain {t_co * 1e3:9.2f} ms   slip error {err(w_co):.2e} rad/s"
                  f"   ({t_co / n * 1e6:.0f} us/step)")
            print(f"  FMU via FMPy                {t_fmu * 1e3:9.2f} ms   slip error {err(w_fmu):.2e} rad/s"
                  f"   (process incl. start {t_fmu_total:.2f} s)")
            print(f"  scipy solve_ivp restarts    {t_sp * 1e3:9.2f} ms   slip error {err(w_sp):.2e} rad/s")
            print(f"  ratios: scipy / co-simulation = {t_sp / t_co:.1f}x, co-simulation / native = {t_co / t_nat:.1f}x")
        (n1, t1), (n2, t2) = sorted(fmu_times.items())
        per_step = (t2 - t1) / (n2 - n1)
        print(f"\nFMU via FMPy: {per_step * 1e6:.0f} us per communication step, {(t1 - n1 * per_step):.2f} s fixed "
              "(unzip, instantiate, import clutchlab and load the compiled kernels)")


if __name__ == "__main__":
    main()
