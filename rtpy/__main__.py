"""`python -m rtpy`: see rtpy.io.cli; signals from start-up to exit: rtpy.signals."""

import sys

from . import signals

signals.defer()  # rtpy/__init__.py did it already when run as `python -m rtpy`

from .io.cli import main  # noqa: E402 (imported with the signals deferred)

if signals.received() is not None:  # while starting: stop before doing anything
    sys.exit(signals.stopped(signals.NOTHING_WRITTEN))
sys.exit(main(prog="python -m rtpy"))
