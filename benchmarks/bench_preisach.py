"""Preisach forward model: steps per second, and ratio against a naive relay-grid model.

Run: ``python benchmarks/bench_preisach.py``.

* clutchlab: :meth:`clutchlab.hysteresis.Preisach.simulate` (compiled, alternating
  extrema memory with wiping-out, O(1) amortised per step) on the paper's
  0-4.5 A / 0.5 A grid, random-walk input.
* reference: the same model as a grid of elementary relays (every relay
  switched every step, compiled with numba as well -- a plain-numpy loop over
  time would be slower still), refined until its output matches clutchlab's to
  0.5 % of the force range on the same input.
"""

from __future__ import annotations

import time

import numba
import numpy as np

from clutchlab.emtc.magnet import PAPER_GRID, synthetic_magnet
from clutchlab.hysteresis import Preisach


@numba.njit(cache=True)
def relay_grid_simulate(alpha, beta, weight, offset, u, out):
    """Naive classical Preisach: switch every relay at every step."""
    state = np.zeros(alpha.shape[0])
    for k in range(u.shape[0]):
        v = u[k]
        f = offset
        for r in range(alpha.shape[0]):
            if v >= alpha[r]:
                state[r] = 1.0
            elif v <= beta[r]:
                state[r] = 0.0
            f += weight[r] * state[r]
        out[k] = f


def relay_grid(model: Preisach, m: int):
    """Relays of the interpolated model on a grid refined ``m`` times (masses = Everett mixed differences)."""
    g = model.grid
    fine = np.unique(np.concatenate([np.linspace(g[i], g[i + 1], m + 1) for i in range(g.size - 1)]))
    n = fine.size

    def P(a, b):  # Everett function: F(a, a) - F(a, b)
        return model.forc(a, a) - model.forc(a, b)

    A, B = np.meshgrid(fine, fine, indexing="ij")
    low = B <= A
    Pg = np.zeros((n, n))
    Pg[low] = P(A[low], B[low])
    alpha, beta, w = [], [], []
    for i in range(n - 1):
        for j in range(i + 1):
            if j < i:  # square sub-cell: mixed difference
                mass = Pg[i + 1, j] - Pg[i, j] - Pg[i + 1, j + 1] + Pg[i, j + 1]
            else:  # diagonal sub-cell: triangle mass
                mass = Pg[i + 1, i]
            alpha.append(0.5 * (fine[i] + fine[i + 1]))
            beta.append(0.5 * (fine[j] + fine[j + 1]) if j < i else 0.5 * (fine[i] + fine[i + 1]))
            w.append(mass)
    return np.array(alpha), np.array(beta), np.array(w), float(model.forc(g[0], g[0]))


def random_walk(n, seed=1, sigma=0.05):
    x = np.cumsum(np.random.default_rng(seed).normal(0.0, sigma, n)) % 9.0
    return np.where(x > 4.5, 9.0 - x, x)


def main():
    model = synthetic_magnet(airgaps=[0.8e-3], step=0.5)  # consistent table on the paper grid
    assert np.allclose(model.grid, PAPER_GRID)
    n = 10_000_000
    u = random_walk(n)
    model.simulate(u[:1000])  # compile
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        y = model.simulate(u)
        best = min(best, time.perf_counter() - t0)
    rate = n / best
    print(f"clutchlab Preisach: {n:,} random-walk steps in {best:.3f} s = {rate / 1e6:.1f} M steps/s "
          f"(memory length at the end: {model.state.extrema.size})")

    span = float(np.ptp(y))
    n_ref = 200_000
    ref_out = np.empty(n_ref)
    for m in (2, 4, 8, 16, 32):
        alpha, beta, w, off = relay_grid(model, m)
        relay_grid_simulate(alpha, beta, w, off, u[:100], ref_out[:100])
        relay_grid_simulate(alpha, beta, w, off, u[:n_ref], ref_out)
        err = float(np.max(np.abs(ref_out - y[:n_ref]))) / span
        if err <= 5e-3:
            break
    t0 = time.perf_counter()
    relay_grid_simulate(alpha, beta, w, off, u[:n_ref], ref_out)
    t_ref = time.perf_counter() - t0
    ref_rate = n_ref / t_ref
    print(f"naive relay grid ({alpha.size} relays, refinement {m}, max error {100 * err:.3f} % of range): "
          f"{ref_rate / 1e6:.3f} M steps/s")
    print(f"ratio clutchlab / naive relay grid at matched accuracy: {rate / ref_rate:.0f}x")
    print(f"target >= 10 M steps/s: {'met' if rate >= 10e6 else 'NOT met'}")


if __name__ == "__main__":
    main()
