"""``python -m pounding …`` is the same as the ``pounding`` console script."""

import sys

from .cli import main

sys.exit(main())
