"""``python -m clutchlab``: the same as the ``clutchlab`` command."""

import sys

from .cli import main

sys.exit(main())
