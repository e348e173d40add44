"""Networks never run before compile nothing: random TOML drivelines mixing every component kind, each in a fresh
process after ``clutchlab warmup``, with numba's compilations counted (issue #31).

Usage: ``python benchmarks/bench_compositions.py [--networks 20] [--seed 0]``  (a few minutes on 2 cores).

1. An empty numba cache (``NUMBA_CACHE_DIR`` in a temporary folder); ``python -m clutchlab warmup`` on it, timed.
2. ``--networks`` random networks (seeded): a chain of 3-6 inertias, an engine or a torque source on the first, a
   road load on the last, and between them elements drawn from every kind: clutches, spring-dampers, gears,
   one-way clutches, backlash, wet clutches, EMTC couplings and the E-clutch with its actuator (solved ahead, and
   in the network: ``eclutch_network``, the network then on Rodas3); every network
   holds at least one model component, and every kind appears over the set.  Each is written as a driveline
   TOML file.
3. Each file is loaded and simulated for 0.2 s in a fresh Python process that counts numba's compilations
   (``numba:compile`` events, any dispatcher); the goal is zero for every network.

Prints the machine, the warm-up's wall time, per network its components, compilations and wall time of the
run (load and simulate, in the process), and the median with min-max.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np

KINDS = ("clutch", "spring_damper", "gear", "one_way_clutch", "backlash", "wet_clutch", "emtc", "eclutch",
         "eclutch_network")
MODELS = ("wet_clutch", "emtc", "eclutch", "eclutch_network")

_CHILD = textwrap.dedent("""
    import sys, time
    t0 = time.perf_counter()
    from numba.core import event as ev
    count = [0]
    class Count(ev.Listener):
        def on_start(self, event):
            count[0] += 1
        def on_end(self, event):
            pass
    ev.register("numba:compile", Count())
    from clutchlab.driveline.description import load_driveline
    f = load_driveline(sys.argv[1])
    r = f.driveline.simulate(0.2, rtol=1e-8, output_step=1e-3)
    assert r.ok, r.status
    print(count[0], time.perf_counter() - t0)
""")


def _element(kind: str, name: str, a: str, b: str, rng) -> str:
    if kind == "clutch":
        return (f'[clutch.{name}]\na = "{a}"\nb = "{b}"\nfn_max = "{rng.uniform(200, 2000):.0f} N"\nmu = 0.4\n'
                f'peak = 1.1\nnormal = {{ step = {{ height = 1, start = "{rng.uniform(0.0, 0.1):.3f} s" }} }}\n')
    if kind == "spring_damper":
        return (f'[spring_damper.{name}]\na = "{a}"\nb = "{b}"\nc = "{rng.uniform(100, 5000):.0f} N m/rad"\n'
                'd = "2 N m s/rad"\n')
    if kind == "gear":
        return f'[gear.{name}]\na = "{a}"\nb = "{b}"\nratio = {rng.uniform(0.5, 4.0):.3f}\n'
    if kind == "one_way_clutch":   # (the upstream flange as b: it may overrun, so the chain starts consistent)
        return f'[one_way_clutch.{name}]\na = "{b}"\nb = "{a}"\n'
    if kind == "backlash":
        return (f'[backlash.{name}]\na = "{a}"\nb = "{b}"\nc = "{rng.uniform(1e3, 1e4):.0f} N m/rad"\n'
                f'b_gap = "{rng.uniform(0.5, 3):.2f} deg"\nd = "20 N m s/rad"\n')
    if kind == "wet_clutch":
        return (f'[wet_clutch.{name}]\na = "{a}"\nb = "{b}"\n'
                f'force = {{ ramp = {{ height = "{rng.uniform(1000, 4000):.0f} N", duration = "0.1 s" }} }}\n')
    if kind == "emtc":
        return f'[emtc.{name}]\na = "{a}"\nb = "{b}"\n'
    if kind == "eclutch":
        return (f'[eclutch.{name}]\na = "{a}"\nb = "{b}"\nactuator = true\nactuator_step = "2 ms"\n'
                'pre_roll = "0.2 s"\nsettle = "0.05 s"\n'
                'position = { table = { times = [0, 0.05, 0.15], values = ["8 mm", "8 mm", "0 mm"] } }\n')
    if kind == "eclutch_network":   # (its actuator's states integrated with the network's)
        return (f'[eclutch.{name}]\na = "{a}"\nb = "{b}"\nactuator = true\nactuator_in_network = true\n'
                'pre_roll = "0.05 s"\n'
                'position = { table = { times = [0, 0.05, 0.15], values = ["8 mm", "8 mm", "2 mm"] } }\n')
    raise ValueError(kind)


def networks(n: int, seed: int):
    """``n`` random networks as ``(name, components, TOML text)``; each holds a model component, every kind
    appears."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        size = int(rng.integers(3, 7))
        kinds = [str(rng.choice(KINDS)) for _ in range(size - 1)]
        if k < len(KINDS):   # every kind in the first networks
            kinds[0] = KINDS[k]
        if not any(q in MODELS for q in kinds):
            kinds[int(rng.integers(1, len(kinds)))] = MODELS[k % len(MODELS)]
        parts = [f'[driveline]\nname = "random_{k}"\n']
        for i in range(size):
            w0 = f'\nw0 = "{rng.uniform(50, 300):.1f} rad/s"' if i == 0 else ""
            parts.append(f'[inertia.j{i}]\nJ = "{rng.uniform(0.05, 2.0):.3f} kg m^2"{w0}\n')
        if rng.random() < 0.5:
            parts.append('[torque.drive]\nflange = "j0"\ntorque = "80 N m"\n')
        else:
            parts.append('[engine.ice]\nflange = "j0"\ntorque_map = [[0.0, 150.0], [400.0, 200.0], [700.0, 120.0]]\n'
                         'throttle = { ramp = { height = 0.8, duration = "0.1 s" } }\n')
        for i, kind in enumerate(kinds):
            parts.append(_element(kind, f"e{i}", f"j{i}", f"j{i + 1}", rng))
        parts.append(f'[bearing_friction.road]\nflange = "j{size - 1}"\ntorque = "{rng.uniform(5, 40):.1f} N m"\n')
        out.append((f"random_{k}", kinds, "\n".join(parts)))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--networks", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}")
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(tmp, "cache"), MPLBACKEND="Agg")
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "clutchlab", "warmup"], env=env, check=True, capture_output=True)
        print(f"clutchlab warmup on an empty cache: {time.perf_counter() - t0:.1f} s wall")
        rows = []
        for name, kinds, text in networks(args.networks, args.seed):
            path = os.path.join(tmp, f"{name}.toml")
            with open(path, "w") as fh:
                fh.write(text)
            proc = subprocess.run([sys.executable, "-c", _CHILD, path], env=env, capture_output=True, text=True)
            if proc.returncode != 0:
                raise SystemExit(f"{name} ({', '.join(kinds)}) failed:\n{text}\n{proc.stderr[-3000:]}")
            compiles, wall = proc.stdout.split()
            rows.append((name, kinds, int(compiles), float(wall)))
            print(f"  {name:10s} {int(compiles):3d} compilations  {float(wall):6.2f} s   {', '.join(kinds)}")
    walls = [r[3] for r in rows]
    total = sum(r[2] for r in rows)
    print(f"{len(rows)} networks: {total} compilations in all (goal 0); run in a fresh process (imports, load, "
          f"0.2 s simulated) median {statistics.median(walls):.2f} s (min {min(walls):.2f}, max {max(walls):.2f})")


if __name__ == "__main__":
    main()
