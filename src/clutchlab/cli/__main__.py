"""``python -m clutchlab.cli``: the same as ``clutchlab`` and ``python -m clutchlab``."""

import sys

from . import main

sys.exit(main())
