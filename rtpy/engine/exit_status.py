"""The exit statuses of rtpy's commands (`python -m rtpy render`, `bench`,
`assignment`, `grade`): one table for all of them, as docs/scene-format.md lists it.

0 done; 1 the work failed (the worker processes, or writing an output: one line names
the file, and an output that was there is untouched); 2 bad input (a scene file, an
option, an output path, a saved render that --resume cannot continue: nothing is
written); 128 + the signal's number when a signal stopped the command, 130 for
SIGINT (Ctrl-C) and 143 for SIGTERM (rtpy.engine.signals).
"""

from __future__ import annotations

import signal

__all__ = [
    "EXIT_BAD_INPUT",
    "EXIT_DONE",
    "EXIT_SIGNALLED",
    "EXIT_WORKERS_FAILED",
    "EXIT_WRITE_FAILED",
]

EXIT_DONE = 0
EXIT_WORKERS_FAILED = 1
EXIT_WRITE_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_SIGNALLED = {signal.SIGINT: 128 + signal.SIGINT, signal.SIGTERM: 128 + signal.SIGTERM}
