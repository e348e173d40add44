"""FORC identification from recorded traces (Figs. 2-4 procedure)."""

import numpy as np
import pandas as pd
import pytest

from clutchlab.errors import DataError, IdentificationError
from clutchlab.hysteresis import Preisach, forc_input, forc_table_from_masses, identify_forc, identify_forc_family

GRID = np.linspace(0.0, 4.5, 10)


def true_model(seed=0, scale=1.0):
    rng = np.random.default_rng(seed)
    n = GRID.size - 1
    return Preisach(GRID, forc_table_from_masses(GRID, rng.random((n, n)) * 20 * scale, rng.random(n) * 30 * scale))


def test_forc_input_visits_every_reversal():
    u = forc_input(GRID, step=0.05, dwell=2)
    assert u[0] == 0.0 and u[-1] == 0.0
    peaks = [u[i] for i in range(1, u.size - 1) if u[i] > u[i - 1] and u[i] >= u[i + 1]]
    np.testing.assert_allclose(sorted(set(np.round(peaks, 9))), GRID[1:])


def test_noise_free_trace_recovers_table_exactly():
    """The model is piecewise linear between grid points, so the one-sided line fits are exact."""
    m = true_model(1)
    u = forc_input(GRID, step=0.02)
    res = identify_forc(u, m.simulate(u), GRID)
    np.testing.assert_allclose(res.model.tables[0][np.tril_indices(10)], m.tables[0][np.tril_indices(10)], atol=1e-8)
    assert res.n_reversals == 9


def test_noisy_repeated_trace_recovers_table_with_scatter_statistics():
    m = true_model(2)
    u = forc_input(GRID, step=0.02)
    u = np.concatenate([u, u, u])  # three repetitions of the experiment
    rng = np.random.default_rng(3)
    sigma = 0.05
    res = identify_forc(u, m.simulate(u) + rng.normal(0, sigma, u.size), GRID)
    t = res.table
    assert len(t) == 55 and res.n_reversals == 27
    assert t["n_curves"].min() >= 3
    # error of the mean of >= 3 readings of >= ~10-sample fits: well below the noise
    err = np.abs(res.model.tables[0][np.tril_indices(10)] - m.tables[0][np.tril_indices(10)])
    assert err.max() < 0.1
    # the scatter statistic estimates the reading uncertainty (order sigma / sqrt(samples per side))
    assert 0.2 * sigma / np.sqrt(10) < t["std"].median() < 2 * sigma
    assert t["rms_residual"].median() == pytest.approx(sigma, rel=0.4)
    assert "55 grid points" in res.report()


def test_grid_inferred_from_reversals():
    m = true_model(4)
    u = forc_input(GRID, step=0.02)
    res = identify_forc(u, m.simulate(u))
    np.testing.assert_allclose(res.model.grid, GRID, atol=1e-12)


def test_family_identification_by_airgap():
    gaps = [0.4e-3, 0.8e-3, 1.2e-3]
    u = forc_input(GRID, step=0.03)
    frames = [pd.DataFrame({"airgap": g, "current": u, "force": true_model(5, scale=1.0 / (k + 1)).simulate(u)})
              for k, g in enumerate(gaps)]
    model, results = identify_forc_family(pd.concat(frames, ignore_index=True), grid=GRID)
    assert model.n_airgaps == 3
    np.testing.assert_allclose(model.airgaps, gaps)
    probe = [0.0, 3.0, 1.0]
    assert model.simulate(probe, airgap=0.8e-3)[-1] == pytest.approx(true_model(5, 0.5).simulate(probe)[-1], abs=1e-7)


def test_errors():
    m = true_model(6)
    u = forc_input(GRID, step=0.02)
    f = m.simulate(u)
    with pytest.raises(IdentificationError, match="not on the grid"):
        identify_forc(u, f, GRID + np.r_[0.0, np.full(9, 0.2)])
    with pytest.raises(IdentificationError, match="no reading for F"):
        keep = u <= 4.0 + 1e-9  # the 4.5 A reversal curve is missing
        cut = np.flatnonzero(~keep)[0] - 2
        identify_forc(u[:cut], f[:cut], GRID)
    bad = f.copy()
    bad[10] = np.nan
    with pytest.raises(DataError, match="non-finite value at row 10"):
        identify_forc(u, bad, GRID)
    with pytest.raises(DataError, match="different lengths"):
        identify_forc(u, f[:-1], GRID)
