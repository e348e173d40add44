"""Test-suite configuration.

Hypothesis profiles live in ``tests/_support/hypothesis_budget.py``: under CI
(environment variable ``CI`` set, as ``.ci/run`` runs) hypothesis is
derandomised, so a CI run is reproducible; locally every run explores new
examples, three times as many; ``HYPOTHESIS_PROFILE=thorough`` draws twenty
times as many.  Tests that fix their own count use ``examples(N)`` so every
profile reaches them.
"""

from hypothesis_budget import load

load()
