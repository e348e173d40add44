"""How many examples the property tests draw, by hypothesis profile.

Profiles (chosen by ``HYPOTHESIS_PROFILE``, else ``ci`` when the environment
variable ``CI`` is set, as ``.ci/run`` does, else ``dev``):

- ``ci``: derandomised, so a CI run is reproducible; each test's own count.  Its draws
  do not depend on what the process imported before (:func:`without_local_constants`),
  so a CI worker draws what a local ``CI=true`` run of the same test draws.
- ``dev`` (a developer's run): new random examples every run, 3x the count.
- ``thorough``: 20x the count (and 2,000 for tests that set none).
- ``draws``: as ``thorough``, and the properties pinned to derandomised draws in every other profile
  (:func:`pinned`: their random draws find the open rounding-floor family) draw at random too, so
  ``--hypothesis-seed=N`` varies them (the random-network draws of issue #30).

Tests that fix their count write ``@settings(max_examples=examples(N))`` so the
profile scales them too; a bare ``max_examples=N`` would pin it in every profile.
"""

from __future__ import annotations

import os

from hypothesis import settings

#: multiplier of each test's own example count, per profile
FACTORS = {"ci": 1, "dev": 3, "thorough": 20, "draws": 20}


def profile() -> str:
    """Name of the active profile."""
    return os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev")


def examples(n: int) -> int:
    """Example count for a test whose CI count is ``n``."""
    return int(n) * FACTORS.get(profile(), 1)


def pinned() -> bool:
    """``derandomize`` for a property pinned to derandomised draws: True but in the ``draws`` profile.

    A property whose random draws find networks of the open rounding-floor family (docs/driveline.md, "Open")
    writes ``@settings(derandomize=pinned())``: a developer's run stays reproducible, and ``HYPOTHESIS_PROFILE=draws
    python -m pytest --hypothesis-seed=N`` draws new networks (a ``derandomize=True`` in the decorator overrides
    every profile, so before this a seed did not vary them).
    """
    return profile() != "draws"


def without_local_constants() -> bool:
    """Draw no constants from the process's own modules; True if hypothesis has them to switch off.

    Hypothesis (6.1xx) mixes into its draws the literal constants of every local module in ``sys.modules``, and
    clutchlab imports its packages and compiled entry modules when a test first needs them, so a derandomised
    property drew other examples depending on what its pytest-xdist worker had run before (measured 2026-12-01:
    the components' tolerance property drew J0 = 1.556 kg m^2 alone and 1.3 after ``test_invariants.py``, and CI
    failed on networks a local run never drew).  Done once, before any test draws, so hypothesis's cache of
    permitted constants never holds a local one.
    """
    from hypothesis.internal.conjecture import providers

    if not (hasattr(providers, "_get_local_constants") and hasattr(providers, "Constants")):
        return False
    empty = providers.Constants()
    providers._get_local_constants = lambda: empty
    return True


def load() -> None:
    """Register the profiles and load the active one (called by ``tests/conftest.py``)."""
    settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
    settings.register_profile("thorough", max_examples=2000, deadline=None, print_blob=True)
    settings.register_profile("dev", max_examples=300, deadline=None, print_blob=True)
    settings.register_profile("draws", max_examples=2000, deadline=None, print_blob=True, derandomize=False)
    settings.load_profile(profile())
    if profile() == "ci":
        without_local_constants()
