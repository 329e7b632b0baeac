"""The judge's side of the student's process (rtpy.grading.sandbox): answers come back
as plain data; an exception names the student's function, file and line; a child that
loops, dies, floods its output or lies about the protocol costs the call it owed and
nothing else (the next call gets a new child)."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest

from rtpy.grading.sandbox import GRACE, Child, ChildFailure, Isolation, StudentError

ROOT = Path(__file__).resolve().parents[2]

PROBES = """
import os, sys, time
from rtpy.grading.probes import probe
from rtpy.grading.protocol import Float, Plain, encode
from rtpy import loop

@probe(returns=Float)
def double(x):
    return 2.0 * x

@probe(returns=Float)
def spin():
    return loop.spin()

@probe(returns=Float)
def divide(x):
    return loop.divide(x)

@probe(returns=Float)
def stub():
    raise NotImplementedError("week05 task: PointLight.sample: the light (see README)")

@probe(returns=Float)
def crash():
    os._exit(7)

@probe(returns=Float)
def flood():
    for _ in range(400):
        print("x" * 100_000)
    return 1.0

@probe(returns=Plain)
def unsendable():
    return object()

@probe(returns=Float)
def lie():
    frame = encode({"id": 10**6, "value": 1.0})
    for fd in range(3, 30):
        try:
            os.write(fd, frame)
        except OSError:
            pass
    return 1.0

@probe(returns=Float)
def deaf():
    # shrink the request pipe to a page and never read it again
    import fcntl
    import rtpy.grading.protocol as protocol

    fcntl.fcntl(0, 1031, 4096)  # F_SETPIPE_SZ
    protocol._exactly = lambda stream, size: time.sleep(10**6)
    return 1.0

@probe(returns=Float)
def bomb(size):
    # a reply of `size` bytes of [{},{},...] on the replies' channel
    import struct

    frame = sys._getframe()
    while "replies" not in frame.f_locals:
        frame = frame.f_back
    fd = frame.f_locals["replies"].fileno()
    body = b"[" + b"{}," * ((size - 2) // 3) + b"{}]"
    os.write(fd, struct.pack(">I", len(body)))
    view = memoryview(body)
    while view:
        view = view[os.write(fd, view):]
    return 1.0

@probe(returns=Float)
def hog():
    block = bytearray(8 * 2**30)
    return float(len(block))
"""

LOOP = "def spin():\n    while True:\n        pass\n\n\ndef divide(x):\n    return 1 / x\n"


@pytest.fixture
def child(tmp_path):
    repo = tmp_path / "repo"
    shutil.copytree(ROOT / "rtpy", repo / "rtpy", ignore=shutil.ignore_patterns("__pycache__"))
    (repo / "rtpy" / "loop.py").write_text(LOOP)
    (repo / "probes.py").write_text(PROBES)
    config = {"task_files": ["rtpy/loop.py"], "probe_modules": [str(repo / "probes.py")]}
    child = Child(repo, config, Isolation(memory_mb=2048))
    yield child
    child.stop()


def test_answers_and_the_students_exceptions(child):
    assert child.call("double", {"x": 1.25}, 30) == 2.5
    with pytest.raises(StudentError) as caught:
        child.call("divide", {"x": 0}, 30)
    assert str(caught.value) == (
        "ZeroDivisionError: division by zero (raised in divide (rtpy/loop.py, line 7))"
    )
    assert caught.value.where == ("divide", "rtpy/loop.py", 7)
    with pytest.raises(StudentError, match=r"^NotImplementedError: week05 task: PointLight"):
        child.call("stub", {}, 30)
    with pytest.raises(StudentError, match="not a number or a vector"):
        child.call("unsendable", {}, 30)
    assert child.call("double", {"x": 2}, 30) == 4.0  # the same child, still answering


@pytest.mark.slow
def test_an_endless_loop_is_stopped_naming_where_it_was(child):
    start = time.monotonic()
    with pytest.raises(ChildFailure, match=r"it was in spin \(rtpy/loop.py, line [23]\)"):
        child.call("spin", {}, 1.0)
    assert time.monotonic() - start < 30
    assert child.call("double", {"x": 3}, 30) == 6.0


def test_a_child_that_dies_or_lies_costs_one_call(child):
    with pytest.raises(ChildFailure, match="exit status 7"):
        child.call("crash", {}, 30)
    assert child.call("double", {"x": 1}, 30) == 2.0  # a new child
    with pytest.raises(ChildFailure, match="not asked"):
        child.call("lie", {}, 30)
    assert child.call("double", {"x": 5}, 30) == 10.0


def test_a_flood_of_output_is_bounded_and_memory_is_limited(child):
    assert child.call("flood", {}, 60) == 1.0
    assert child.call("double", {"x": 1}, 30) == 2.0
    assert len(child.output()) <= 70_000  # 40 MB printed, 64 KiB kept
    with pytest.raises(StudentError, match="MemoryError"):
        child.call("hog", {}, 30)


@pytest.mark.slow
def test_a_child_that_stops_reading_cannot_block_the_judge(child):
    """After its answer the child shrinks its request pipe and stops reading: the next,
    larger request is not written by its deadline, and the child is stopped."""
    assert child.call("deaf", {}, 30) == 1.0
    start = time.monotonic()
    child.deadline = start + 2.0
    with pytest.raises(ChildFailure, match="did not read what it was asked within 30 s"):
        child.call("double", {"x": 1.0, "padding": "x" * 1_000_000}, 30.0)
    assert time.monotonic() - start < 2.0 + 3.0
    child.deadline = None
    assert child.call("double", {"x": 4}, 30) == 8.0  # a new child


@pytest.mark.slow
def test_no_call_outlives_the_childs_deadline(child):
    child.deadline = time.monotonic() + 2.0
    start = time.monotonic()
    with pytest.raises(ChildFailure, match="did not finish"):
        child.call("spin", {}, 30.0)
    assert time.monotonic() - start < 4.0
    with pytest.raises(ChildFailure, match="not asked: the time limit"):
        child.call("double", {"x": 1}, 30.0)


BOMB = """
import json, resource, sys, time
from pathlib import Path
from rtpy.grading.protocol import Float
from rtpy.grading.sandbox import Child, ChildFailure, Isolation

repo = Path(sys.argv[1])
config = {"task_files": ["rtpy/loop.py"], "probe_modules": [str(repo / "probes.py")]}
child = Child(repo, config, Isolation(memory_mb=2048))
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
start = time.monotonic()
try:
    child.call("bomb", {"size": int(sys.argv[2])}, 60, Float)
    outcome = "answered"
except ChildFailure as err:
    outcome = str(err)
finally:
    child.stop()
grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - before
print(json.dumps([outcome, time.monotonic() - start, grown]))
"""


@pytest.mark.parametrize(
    "size, refused",
    [(200 * 2**20, "bytes announced"), (8 * 2**20, "more than the 10,001 values asked for")],
)
@pytest.mark.slow
def test_a_reply_far_larger_than_asked_is_refused_cheaply(child, size, refused):
    """A reply of [{},{},...] (200 MiB, beyond any answer; 8 MiB, within the frame
    limit) to a request for one number: refused before it is parsed, fast, the judge's
    memory barely touched."""
    import json
    import subprocess
    import sys

    proc = subprocess.run(
        [sys.executable, "-c", BOMB, str(child.work), str(size)], capture_output=True,
        text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    outcome, seconds, grown = json.loads(proc.stdout.strip().splitlines()[-1])
    assert refused in outcome
    assert seconds < 1.0 + GRACE  # read, refused, the child stopped (2 s to see it exit)
    # the judge's peak grew by at most what reading a frame of 64 MiB takes, never by
    # what parsing it does (an empty dict per 3 bytes: about 25 times the reply)
    bound = min(4 * size, 64 * 2**20) + 32 * 2**20
    assert grown < bound, f"the judge's peak grew by {grown / 2**20:.0f} MiB"
