"""Test-suite configuration.

Under CI (environment variable ``CI`` set, as ``.ci/run`` runs) hypothesis is
derandomised, so a CI run is reproducible; locally every run explores new
examples.  ``HYPOTHESIS_PROFILE=thorough`` runs 20x more examples for the tests
that do not pin their own count.
"""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("thorough", max_examples=2000, deadline=None)
settings.register_profile("dev", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "dev"))
