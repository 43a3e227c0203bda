"""``python -m facetraj``: the same as the ``facetraj`` command."""

import sys

from .cli import main

sys.exit(main())
