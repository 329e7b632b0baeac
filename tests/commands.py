"""Running rtpy's command line in a child process, as a user does, for the tests that
need a real process (exit codes, signals): start it, and read what it says until the
moment a test waits for."""

from __future__ import annotations

import os
import subprocess
import sys
import time


def rtpy_command(*args: str) -> list[str]:
    """The argv of `python -m rtpy ARGS` with this interpreter."""
    return [sys.executable, "-m", "rtpy", *args]


def run_cli(*args: str, timeout: float = 120, cwd=None) -> subprocess.CompletedProcess:
    """`python -m rtpy ARGS` to its end (in the directory cwd, else the current one); the
    timeout only ends a child that hangs."""
    return subprocess.run(
        rtpy_command(*args), capture_output=True, text=True, timeout=timeout, cwd=cwd
    )


def read_until(proc: subprocess.Popen, done, timeout: float = 120) -> str:
    """Read the child's stderr until done(what was read) holds; returns what it read.
    The deadline only ends a test whose child never gets there."""
    deadline = time.monotonic() + timeout
    seen = ""
    while time.monotonic() < deadline:
        chunk = os.read(proc.stderr.fileno(), 4096).decode()
        if not chunk:
            break  # the process ended
        seen += chunk
        if done(seen):
            return seen
    raise AssertionError(f"not seen within {timeout} s: {seen}")


def modules_imported_by(code: str) -> set[str]:
    """The top-level modules and rtpy subpackages that `code`, run in a fresh
    interpreter, imports beyond what the interpreter starts with."""
    script = (
        "import sys\n"
        "before = set(sys.modules)\n"
        f"{code}\n"
        "print(' '.join(sorted(set(sys.modules) - before)))\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0, result.stderr
    return set(result.stdout.split())
