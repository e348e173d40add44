"""Reading a multi-rate MDF 4 record: clutchlab.io.read_measurement vs asammdf's own to_dataframe.

A logger-style file (60 s; 4 channels at 10 kHz, 4 at 1 kHz with integer raw values and a linear
conversion, 2 at 100 Hz) is read onto a 1 kHz time base.  The reference is what a user would write
with asammdf alone: ``MDF(path).to_dataframe(channels, raster=1e-3)`` (which also interpolates onto
the raster) followed by the unit scaling done by hand.  clutchlab adds channel mapping, checks
(NaN, monotonic time, units) and provenance; the ratio shows what they cost.  The same for a CSV of
the resampled record against ``pandas.read_csv``.

Run: ``python benchmarks/bench_io.py``
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from asammdf import MDF, Signal

from clutchlab.io import read_measurement, write_measurement

DURATION = 60.0
RPM = 2 * math.pi / 60


def make_file(folder: Path) -> Path:
    rng = np.random.default_rng(1)
    mdf = MDF(version="4.10")
    t1 = np.arange(0, DURATION, 1e-4)
    mdf.append([Signal(rng.normal(size=t1.size).cumsum(), t1, name=f"Fast{k}", unit="Nm") for k in range(4)])
    t2 = np.arange(0, DURATION, 1e-3) + 2e-4
    mdf.append([Signal((np.arange(t2.size) % 30000).astype(np.int32), t2, name=f"Cnt{k}", unit="rpm",
                       conversion={"a": 0.1, "b": 0.0}) for k in range(4)])
    t3 = np.arange(0, DURATION, 1e-2) + 5e-3
    mdf.append([Signal(60 + rng.normal(size=t3.size), t3, name=f"Temp{k}", unit="°C") for k in range(2)])
    path = Path(mdf.save(folder / "bench.mf4"))
    mdf.close()
    return path


CMAP = {**{f"torque{k}_Nm": f"Fast{k}" for k in range(4)},
        **{f"speed{k}_rad_s": f"Cnt{k}" for k in range(4)},
        **{f"temperature{k}_C": f"Temp{k}" for k in range(2)}}


def reference(path: Path) -> pd.DataFrame:
    with MDF(path) as mdf:
        df = mdf.to_dataframe(channels=list(CMAP.values()), raster=1e-3, time_from_zero=False)
    out = pd.DataFrame({"time_s": df.index.to_numpy()})
    for name, src in CMAP.items():
        v = df[src].to_numpy(dtype=float)
        out[name] = v * RPM if name.startswith("speed") else v
    return out


def best(fn, repeat=5):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = make_file(Path(tmp))
        ours = read_measurement(path, CMAP, rate=1000.0)
        ref = reference(path)
        # same values where the time bases coincide (asammdf's raster starts at the first sample of any group)
        common = np.intersect1d(np.round(ours.time, 9), np.round(ref["time_s"].to_numpy(), 9))
        a = ours.frame.set_index(np.round(ours.time, 9)).loc[common]
        b = ref.set_index(np.round(ref["time_s"].to_numpy(), 9)).loc[common]
        diff = max(float(np.max(np.abs(a[c].to_numpy() - b[c].to_numpy()))) for c in CMAP)
        t_ours = best(lambda: read_measurement(path, CMAP, rate=1000.0))
        t_ref = best(lambda: reference(path))
        print(f"MDF 4, {DURATION:g} s, 10 channels at 10 kHz / 1 kHz / 100 Hz -> 1 kHz ({len(ours)} rows)")
        print(f"  read_measurement        {t_ours * 1e3:8.1f} ms")
        print(f"  asammdf to_dataframe    {t_ref * 1e3:8.1f} ms   ratio ours/reference = {t_ours / t_ref:.2f}")
        print(f"  max difference on {common.size} common times: {diff:.3g}")
        csv = write_measurement(ours, Path(tmp) / "rec.csv")
        t_csv = best(lambda: read_measurement(csv))
        t_pd = best(lambda: pd.read_csv(csv, comment="#"))
        print(f"CSV of the result ({csv.stat().st_size / 1e6:.1f} MB)")
        print(f"  read_measurement        {t_csv * 1e3:8.1f} ms")
        print(f"  pandas.read_csv         {t_pd * 1e3:8.1f} ms   ratio = {t_csv / t_pd:.2f}")


if __name__ == "__main__":
    main()
