"""Bundled synthetic bench records of the wet-clutch subsystem (see ``generate.py``).

Every file here was produced by clutchlab's virtual bench with a fixed seed;
none of it is measured data.
"""

__all__ = ["path"]

from pathlib import Path

DATA_DIR = Path(__file__).resolve().parent

#: the friction-map records (protocol (a)) used by the demo
MAP_RECORDS = ("map_300rpm_85C.csv", "map_200rpm_60C.csv", "map_400rpm_100C.csv")
#: the engagement record (protocol (b))
ENGAGEMENT_RECORD = "engagement_bench.csv"


def path(name: str) -> Path:
    """Absolute path of a bundled file."""
    return DATA_DIR / name
