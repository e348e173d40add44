"""Benchmark: static curves of E-clutch Model 4 (issue: 1,000 points in well under 50 ms).

Measures, in one run and after compilation:

* the compiled Newton continuation (:func:`clutchlab.eclutch.network.solve_static`)
  for 1,000 bearing positions of Model 4, and
* a plain-SciPy reference of the same equilibrium: ``scipy.optimize.root``
  (hybr) at every bearing position with a Python residual built from the
  same network arrays and warm-started from the previous point,

and prints both times and their ratio.  Run: ``python benchmarks/bench_eclutch_static.py``.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import root

from clutchlab.eclutch import ClutchModel
from clutchlab.eclutch.network import solve_static


def reference_path(network, u):
    """SciPy reference: one ``root`` solve per bearing position, Python residual."""
    a = network._assembly
    curves = []
    for j in range(len(a["element_names"])):
        lo, hi = a["offsets"][j], a["offsets"][j + 1]
        curves.append((a["cx"][lo:hi], a["cf"][lo:hi], a["cd"][lo:hi], a["kinds"][j]))
    from clutchlab.curves import _eval_numpy

    def forces(q, ui):
        d = a["d0"] + a["Gb"] * ui + a["GA"] @ q
        f = np.empty_like(d)
        for j, (xs, fs, ds, kind) in enumerate(curves):
            f[j] = a["scale"][j] * _eval_numpy(xs, fs, ds, kind, d[j])[0]
            if a["unilateral"][j] and f[j] < 0:
                f[j] = 0.0
        return f

    q = np.zeros(network.n_free)
    out = np.empty(u.size)
    for k, ui in enumerate(u):
        sol = root(lambda qq: a["GA"].T @ forces(qq, ui), q, method="hybr", options={"xtol": 1e-12})
        q = sol.x
        out[k] = forces(q, ui) @ a["Gb"]
    return out


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return min(times), result


def main():
    model = ClutchModel.preset(4)
    net = model.network
    u = np.linspace(0.0, 9e-3, 1000)
    solve_static(net, u)  # compile (or load the numba cache)
    t_compiled, st = best_of(lambda: solve_static(net, u), 20)
    t_ref, f_ref = best_of(lambda: reference_path(net, u), 1)
    err = np.max(np.abs(st["input_force"] - f_ref))
    print("E-clutch Model 4 static curve, 1,000 bearing positions")
    print(f"  compiled Newton continuation : {1e3 * t_compiled:8.2f} ms   (goal: well under 50 ms)")
    print(f"  scipy.optimize.root reference: {1e3 * t_ref:8.2f} ms")
    print(f"  speed-up                     : {t_ref / t_compiled:8.1f} x")
    print(f"  max |F_b difference|         : {err:.2e} N")
    t_model, _ = best_of(lambda: model.static_curve(u), 20)
    print(f"  ClutchModel.static_curve (DataFrame incl.): {1e3 * t_model:.2f} ms")


if __name__ == "__main__":
    main()
