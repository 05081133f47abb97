"""``python -m pounding …`` is the same as the ``pounding`` console script."""

import sys

from .cli import console_main

sys.exit(console_main())
