"""The EMTC magnet: a synthetic "true" hysteretic magnet and the bundled FORC data.

The paper's FORC measurements ([1], Figs. 3-6) are not published, so
clutchlab ships synthetic FORC records generated from a known hysteretic
magnet model (:func:`synthetic_magnet`) by
``python -m clutchlab.emtc.data.generate_forc`` with a fixed seed, and
identifies the Preisach model from them (:func:`bundled_magnet`) exactly as a
user would from measured records.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

from functools import lru_cache
from importlib import resources

import numpy as np

from ..hysteresis import Preisach, forc_table_from_masses, identify_forc_family
from ..io import read_measurement

__all__ = ["CALIBRATION_AIRGAPS", "PAPER_GRID", "synthetic_magnet", "bundled_forc", "bundled_magnet"]

#: calibration airgaps of [1], Sec. 2.1: 0.2 to 1.4 mm in 0.2 mm steps [m]
CALIBRATION_AIRGAPS = np.round(np.arange(0.2, 1.41, 0.2), 10) * 1e-3
#: current grid of [1], Sec. 2.1: 0 to 4.5 A in 0.5 A steps [A]
PAPER_GRID = np.round(np.arange(0.0, 4.51, 0.5), 10)
BUNDLED_FILE = "forc_synthetic.csv"


def synthetic_magnet(airgaps=CALIBRATION_AIRGAPS, step=0.1) -> Preisach:
    """The known "true" hysteretic magnet used to generate the bundled FORC data.

    A classical Preisach model on a fine current grid (0-4.5 A, ``step``) with
    a Gaussian relay density centred at 1.6 A, hysteresis width decreasing and
    reversible share increasing with the airgap, and force scale
    ``4000 N * (0.8 mm / (airgap + 0.6 mm))^2`` (a magnetic circuit whose
    reluctance grows with the airgap).  Values are clutchlab's choice.

    Parameters
    ----------
    airgaps : sequence of float
        Calibration airgaps [m] (default: the paper's 0.2-1.4 mm in 0.2 mm steps).
    step : float
        Current grid step [A].
    """
    grid = np.round(np.arange(0.0, 4.5 + 1e-9, step), 10)
    mid = 0.5 * (grid[:-1] + grid[1:])
    a, b = np.meshgrid(mid, mid, indexing="ij")
    tables = []
    for gap in np.atleast_1d(airgaps):
        s = (gap - 0.2e-3) / 1.2e-3
        width = 0.55 * (1.0 - 0.4 * s)
        dens = np.exp(-(((a + b) / 2 - 1.6) ** 2) / (2 * 1.3**2)) * np.exp(-((a - b) ** 2) / (2 * width**2))
        dens = np.tril(dens, -1)
        line = (0.15 + 0.25 * s) * dens.sum() / mid.size * (0.3 + mid / 4.5)
        F = forc_table_from_masses(grid, dens, line)
        scale = 4000.0 * (0.8e-3 / (gap + 0.6e-3)) ** 2
        tables.append(F * scale / F[-1, -1])
    gaps = np.atleast_1d(airgaps)
    if gaps.size == 1:
        return Preisach(grid, tables[0])
    return Preisach(grid, np.array(tables), gaps)


def bundled_forc():
    """The bundled synthetic FORC records (columns ``airgap`` [m], ``current`` [A], ``force`` [N])."""
    ref = resources.files("clutchlab.emtc.data").joinpath(BUNDLED_FILE)
    with resources.as_file(ref) as path:
        return read_measurement(path, required=["airgap", "current", "force"], time=None,
                                name=f"bundled {BUNDLED_FILE}").frame


@lru_cache(maxsize=1)
def _bundled():
    frame = bundled_forc()
    return identify_forc_family(frame, grid=PAPER_GRID, name=f"bundled {BUNDLED_FILE}")


def bundled_magnet() -> Preisach:
    """Preisach family identified from the bundled synthetic FORC records (a fresh copy)."""
    model, _ = _bundled()
    return Preisach(model.grid, model.tables.copy(), model.airgaps.copy())


def bundled_identification():
    """Per-airgap identification results of the bundled records: list of (airgap, ForcIdentification)."""
    return _bundled()[1]
