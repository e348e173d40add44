"""How many examples the property tests draw, by hypothesis profile.

Profiles (chosen by ``HYPOTHESIS_PROFILE``, else ``ci`` when the environment
variable ``CI`` is set, as ``.ci/run`` does, else ``dev``):

- ``ci``: derandomised, so a CI run is reproducible; each test's own count.
- ``dev`` (a developer's run): new random examples every run, 3x the count.
- ``thorough``: 20x the count (and 2,000 for tests that set none).

Tests that fix their count write ``@settings(max_examples=examples(N))`` so the
profile scales them too; a bare ``max_examples=N`` would pin it in every profile.
"""

from __future__ import annotations

import os

from hypothesis import settings

#: multiplier of each test's own example count, per profile
FACTORS = {"ci": 1, "dev": 3, "thorough": 20}


def profile() -> str:
    """Name of the active profile."""
    return os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev")


def examples(n: int) -> int:
    """Example count for a test whose CI count is ``n``."""
    return int(n) * FACTORS.get(profile(), 1)


def load() -> None:
    """Register the profiles and load the active one (called by ``tests/conftest.py``)."""
    settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
    settings.register_profile("thorough", max_examples=2000, deadline=None, print_blob=True)
    settings.register_profile("dev", max_examples=300, deadline=None, print_blob=True)
    settings.load_profile(profile())
