"""The CI profile's draws do not depend on what the process imported before (``hypothesis_budget``).

Hypothesis mixes the literal constants of the process's own modules into its draws; clutchlab's tests import its
packages when they first need them, so without the CI profile's switch a derandomised property draws other
examples in a pytest-xdist worker than alone, and a CI failure cannot be reproduced locally.  Each run is a fresh
process: one draws alone, one after importing a module full of constants the strategy permits.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

SUPPORT = Path(__file__).parent / "_support"

DRAW = textwrap.dedent("""
    import json, sys
    sys.path[:0] = [{support!r}, {here!r}]
    import hypothesis_budget
    if {switch}:
        hypothesis_budget.load()
    else:
        from hypothesis import settings
        settings.register_profile("plain", derandomize=True, deadline=None)
        settings.load_profile("plain")
    if {preload}:
        import many_constants  # noqa: F401  (a local module whose literals the strategy permits)
    from hypothesis import given, settings, strategies as st
    seen = []

    @settings(max_examples=200, database=None)
    @given(st.floats(0.1, 10.0))
    def draw(x):
        seen.append(x)

    draw()
    print(json.dumps(seen))
""")


def _draws(tmp_path: Path, switch: bool, preload: bool) -> list:
    (tmp_path / "many_constants.py").write_text(
        "VALUES = (" + ", ".join(f"{1 + k / 997:.6f}" for k in range(400)) + ")\n")
    code = DRAW.format(support=str(SUPPORT), here=str(tmp_path), switch=switch, preload=preload)
    env = {**os.environ, "CI": "true"}
    env.pop("HYPOTHESIS_PROFILE", None)
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=120, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_ci_draws_do_not_depend_on_the_modules_imported_before(tmp_path):
    from hypothesis.internal.conjecture import providers

    if not (hasattr(providers, "_get_local_constants") and hasattr(providers, "Constants")):
        pytest.skip("this hypothesis has no local constants to switch off")
    # the hazard exists with this hypothesis: the same derandomised test draws otherwise after the import
    assert _draws(tmp_path, switch=False, preload=False) != _draws(tmp_path, switch=False, preload=True)
    # and the CI profile removes it
    assert _draws(tmp_path, switch=True, preload=False) == _draws(tmp_path, switch=True, preload=True)


def test_the_pinned_properties_draw_at_random_only_in_the_draws_profile(monkeypatch):
    """``pinned()`` (the ``derandomize`` of the properties whose random draws find the open rounding-floor family)
    is True in the ``ci``, ``dev`` and ``thorough`` profiles and False in ``draws``, which scales like
    ``thorough``."""
    sys.path.insert(0, str(SUPPORT))
    import hypothesis_budget as hb

    for name, pinned, factor in (("ci", True, 1), ("dev", True, 3), ("thorough", True, 20), ("draws", False, 20)):
        monkeypatch.setenv("HYPOTHESIS_PROFILE", name)
        assert hb.profile() == name and hb.pinned() is pinned and hb.examples(10) == 10 * factor
