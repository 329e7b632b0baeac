"""rtpy.engine.exit_status: the statuses docs/scene-format.md promises, and the signals'."""

from __future__ import annotations

import re
import signal
from pathlib import Path

from rtpy.engine import exit_status, signals

DOC = Path(__file__).resolve().parents[2] / "docs" / "scene-format.md"


def test_the_statuses_are_those_the_docs_list():
    text = " ".join(DOC.read_text().split())
    line = re.search(r"Exit status: 0 done, 1 the work failed.*?130 .*?143", text)
    assert line, "docs/scene-format.md lists the exit statuses"
    assert (exit_status.EXIT_DONE, exit_status.EXIT_WORKERS_FAILED) == (0, 1)
    assert (exit_status.EXIT_WRITE_FAILED, exit_status.EXIT_BAD_INPUT) == (1, 2)
    assert exit_status.EXIT_SIGNALLED == {signal.SIGINT: 130, signal.SIGTERM: 143}
    assert signals.EXIT_STATUS is exit_status.EXIT_SIGNALLED
