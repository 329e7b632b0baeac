"""`python -m rtpy`: see rtpy.cli.main; signals from start-up to exit: rtpy.engine.signals."""

import gc
import os
import sys

from .engine import memory, signals

signals.defer()  # rtpy/__init__.py did it already when run as `python -m rtpy`
memory.small_pages_for_numpy()  # this process is rtpy's own: before numpy is imported
memory.tune_for_large_scenes()  # and a render's memory policy (never for a library call)

from .cli.main import main  # noqa: E402 (imported with the signals deferred)


def end(status: int) -> None:
    """Exit with `status`. After a signal, without the interpreter's finalization: a
    KeyboardInterrupt that ended code run by exec of a string (as dataclasses does)
    makes `python -m` exit as if killed by SIGINT, whatever the status."""
    if signals.received() is None:
        # The interpreter's finalization runs full garbage collections over every
        # object left (numpy's and rtpy's modules): 20 ms of a small render. Frozen
        # objects are skipped; the memory goes back to the system at exit anyway.
        gc.freeze()
        sys.exit(status)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe or stream: nothing more to say
            pass
    os._exit(status)


if signals.received() is not None:  # while starting: stop before doing anything
    end(signals.stopped(signals.NOTHING_WRITTEN))
end(main(prog="python -m rtpy"))
