"""`python -m rtpy`: see rtpy.io.cli."""

import sys

from .io.cli import main

sys.exit(main(prog="python -m rtpy"))
