"""Test-only target without ``describe``: ``y = a * x**2`` for plain-number parameters ``a`` and ``x``."""

import pandas as pd


def run_batch(variants, scenario, outputs):
    frame = pd.DataFrame(index=variants.index)
    frame["y"] = variants["a"] * variants["x"] ** 2
    frame["scale"] = float((scenario or {}).get("scale", 1.0))
    return frame[[o for o in outputs if o in frame.columns]]
