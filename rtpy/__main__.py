"""`python -m rtpy`: see rtpy.cli."""

import sys

from .cli import main

sys.exit(main())
