"""Driveline descriptions bundled with clutchlab (the examples of the ``clutchlab demo`` report).

The ``examples/`` folder of the source tree is not installed; these files are.  Each ``NAME.toml`` here
is a byte-for-byte copy of ``examples/driveline_NAME.toml`` (``tests/driveline/test_demo.py`` checks
that they have not drifted apart), so the demo runs the very file a user runs with
``clutchlab driveline simulate``.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["DATA_DIR", "path", "names"]

#: folder of the bundled descriptions
DATA_DIR = Path(__file__).resolve().parent


def path(name: str) -> Path:
    """Absolute path of the bundled description ``name`` (e.g. ``"coupled_clutches.toml"``)."""
    return DATA_DIR / name


def names() -> tuple:
    """File names of every bundled description, sorted."""
    return tuple(sorted(p.name for p in DATA_DIR.glob("*.toml")))
