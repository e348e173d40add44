"""Bundled synthetic FORC data: provenance, regeneration, identification against the known truth."""

from importlib import resources

import numpy as np
import pandas as pd

from clutchlab.emtc.data.generate_forc import generate
from clutchlab.emtc.magnet import CALIBRATION_AIRGAPS, PAPER_GRID, bundled_forc, bundled_magnet, synthetic_magnet


def test_bundled_file_is_small_labelled_and_regenerable():
    ref = resources.files("clutchlab.emtc.data").joinpath("forc_synthetic.csv")
    text = ref.read_text()
    assert len(text.encode()) < 400_000
    assert text.startswith("# synthetic:")
    stored = bundled_forc()
    fresh = generate()
    pd.testing.assert_frame_equal(stored.reset_index(drop=True), fresh.astype(float), check_exact=False, rtol=1e-12)


def test_paper_grid_and_airgaps():
    np.testing.assert_allclose(PAPER_GRID, np.arange(0, 4.51, 0.5))
    np.testing.assert_allclose(CALIBRATION_AIRGAPS, np.arange(0.2, 1.41, 0.2) * 1e-3)


def test_identified_model_matches_truth_within_noise():
    model, truth = bundled_magnet(), synthetic_magnet()
    u = np.r_[np.linspace(0, 4.5, 40), np.linspace(4.5, 1.0, 30), np.linspace(1.0, 3.0, 20), np.linspace(3.0, 2.0, 10)]
    for gap in (0.2e-3, 0.5e-3, 0.7e-3, 1.1e-3, 1.4e-3):
        f_true = truth.simulate(u, airgap=gap)
        f_mod = model.simulate(u, airgap=gap)
        # interpolation on the 0.5 A grid plus 0.4 % force noise: within 3 % of full scale
        assert np.max(np.abs(f_mod - f_true)) < 0.03 * f_true.max()
    # the force falls with the airgap (magnetic circuit) in both
    assert model.forc(4.5, 4.5, airgap=0.2e-3) > model.forc(4.5, 4.5, airgap=1.4e-3) * 4
