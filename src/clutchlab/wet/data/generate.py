"""Regenerate the bundled synthetic bench records.

Run ``python -m clutchlab.wet.data.generate [--force]``.  The clutch is
Table 1 of Shin et al. (``WetClutch.paper()``), its true friction law
``ParametricFriction.bench_truth()``, the bench ``Bench()`` with its fixed
noise seed; the map records are simulated at 1 kHz and stored at 50 Hz to
keep the files small, the engagement record at 500 Hz.
"""

from __future__ import annotations

__all__ = ["generate", "main"]

import argparse
import math

from ..bench import EngagementProtocol, MapProtocol, run_protocol, write_bench_record
from ..friction import ParametricFriction
from ..params import Bench, WetClutch
from . import DATA_DIR, ENGAGEMENT_RECORD, MAP_RECORDS

#: (file, protocol, noise seed) of the friction-map records
MAP_CASES = (
    (MAP_RECORDS[0], MapProtocol(), 101),
    (MAP_RECORDS[1], MapProtocol(force=2500.0, slip_speed=200 * math.pi / 30, fluid_temperature=60.0,
                                 housing_temperature=45.0), 102),
    (MAP_RECORDS[2], MapProtocol(force=1200.0, slip_speed=400 * math.pi / 30, fluid_temperature=100.0,
                                 housing_temperature=75.0), 103),
)


def generate(overwrite: bool = False, outdir=DATA_DIR) -> list:
    """Write the bundled records into ``outdir``; returns the paths."""
    clutch = WetClutch.paper()
    truth = ParametricFriction.bench_truth()
    out = []
    for name, protocol, seed in MAP_CASES:
        run = run_protocol(protocol, clutch, Bench(sample_rate=1000.0), truth, seed=seed)
        out.append(write_bench_record(run, outdir / name, overwrite=overwrite, every=20))
    run = run_protocol(EngagementProtocol(), clutch, Bench(sample_rate=500.0), truth, protocol_type="engagement",
                       seed=104)
    out.append(write_bench_record(run, outdir / ENGAGEMENT_RECORD, overwrite=overwrite))
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--force", action="store_true", help="overwrite the existing files")
    args = parser.parse_args(argv)
    for p in generate(overwrite=args.force):
        print(p)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
