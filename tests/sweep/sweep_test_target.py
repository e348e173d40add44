"""Test-only sweep target (registered as ``test-wet``, installed as the plugin ``plugin-wet``; see conftest.py).

It is the built-in ``wet`` target (same parameters, outputs and numbers),
slowed down by ``CLUTCHLAB_SWEEP_TEST_DELAY`` seconds per chunk so a test can
kill a sweep between two chunks, and failing on the variant whose id is in
``CLUTCHLAB_SWEEP_TEST_FAIL_ID`` so a test can interrupt a sweep in-process.
With ``CLUTCHLAB_SWEEP_TEST_STARTED`` set to a folder, each process running a
chunk leaves a file named by its pid there first (so a test knows which
processes compute chunks).
"""

import os
import time

from clutchlab.errors import SimulationError
from clutchlab.sweep import wet

describe = wet.describe
check_variants = wet.check_variants


def run_batch(variants, scenario, outputs):
    started = os.environ.get("CLUTCHLAB_SWEEP_TEST_STARTED")
    if started:
        with open(os.path.join(started, str(os.getpid())), "a"):
            pass
    delay = float(os.environ.get("CLUTCHLAB_SWEEP_TEST_DELAY", "0"))
    if delay > 0:
        time.sleep(delay)
    fail = os.environ.get("CLUTCHLAB_SWEEP_TEST_FAIL_ID")
    if fail is not None and int(fail) in variants.index:
        raise SimulationError(f"test target: variant {fail} fails on purpose")
    return wet.run_batch(variants, scenario, outputs)
