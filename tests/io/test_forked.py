"""rtpy.io.forked: a function computed in a forked child, or here where no child can
help; the same answer either way, and no child left behind."""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import threading

import pytest

from rtpy.io import forked
from rtpy.io.forked import Forked, can_fork

linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forks on Linux only")


def pid_and(value):
    return os.getpid(), value


def fail_in_the_child(parent: int):
    if os.getpid() != parent:
        raise RuntimeError("a failure in the child only")
    return "computed here"


def die_in_the_child(parent: int):
    if os.getpid() != parent:
        os.kill(os.getpid(), signal.SIGKILL)
    return "computed here"


def always_fails():
    raise ValueError("the function's own error")


@linux
def test_the_child_computes_and_its_answer_comes_back():
    with Forked(pid_and, list(range(100_000))) as job:
        pid, value = job.result()
    assert pid != os.getpid()  # planted mistake: a Forked that never forks fails here
    assert value == list(range(100_000))
    assert multiprocessing.active_children() == []


@pytest.mark.parametrize("function", [fail_in_the_child, die_in_the_child])
def test_a_child_that_fails_or_dies_leaves_the_work_to_this_process(function):
    with Forked(function, os.getpid()) as job:
        assert job.result() == "computed here"
    assert multiprocessing.active_children() == []


def test_the_functions_error_is_raised_here():
    with Forked(always_fails) as job, pytest.raises(ValueError, match="own error"):
        job.result()


def test_no_child_when_not_wanted_or_not_safe():
    with Forked(pid_and, 1, fork=False) as job:
        assert job.child is None and job.result() == (os.getpid(), 1)
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        assert not can_fork()  # another thread: a fork would copy this one only
        with Forked(pid_and, 2) as job:
            assert job.child is None and job.result() == (os.getpid(), 2)
    finally:
        stop.set()
        other.join()


@linux
def test_a_refused_process_leaves_the_work_here(monkeypatch):
    def refuse(self):
        raise OSError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(multiprocessing.get_context("fork").Process, "start", refuse)
    monkeypatch.setattr(forked, "can_fork", lambda: True)
    with Forked(pid_and, 3) as job:
        assert job.child is None and job.result() == (os.getpid(), 3)


CTRL_C = """
import multiprocessing, os, sys, time
from rtpy.io.forked import Forked

def wait_forever(ready_fd):
    os.write(ready_fd, b"ready\\n")
    while True:
        time.sleep(1)

try:
    with Forked(wait_forever, 1) as job:
        job.result()
except KeyboardInterrupt:
    print("stopped;", len(multiprocessing.active_children()), "children")
"""


@linux
def test_ctrl_c_stops_the_work_and_ends_the_child():
    """A terminal's Ctrl-C reaches both processes: the child ignores it, this one
    stops waiting (KeyboardInterrupt) and ends the child on leaving the block."""
    proc = subprocess.Popen(
        [sys.executable, "-c", CTRL_C],
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    assert proc.stdout.readline() == "ready\n"  # the child runs (it writes to stdout)
    os.killpg(proc.pid, signal.SIGINT)
    out, _ = proc.communicate(timeout=30)
    assert proc.returncode == 0 and out == "stopped; 0 children\n"
