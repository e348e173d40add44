"""Test-suite configuration.

Hypothesis profiles live in ``tests/_support/hypothesis_budget.py``: under CI
(environment variable ``CI`` set, as ``.ci/run`` runs) hypothesis is
derandomised, so a CI run is reproducible; locally every run explores new
examples, three times as many; ``HYPOTHESIS_PROFILE=thorough`` draws twenty
times as many.  Tests that fix their own count use ``examples(N)`` so every
profile reaches them.  The compile notice is switched off (see below).
"""

import os

from hypothesis_budget import load

load()
# The compile notice names every compilation longer than 2 s on stderr; which test compiles first depends on
# the order and the worker, so tests that check a command's stderr line by line would see it by chance.  Off
# for the suite; tests/test_compile_notice.py checks it in subprocesses that switch it on.
os.environ["CLUTCHLAB_COMPILE_NOTICE"] = "0"
