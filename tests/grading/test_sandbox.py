"""The judge's side of the student's process (rtpy.grading.sandbox): answers come back
as plain data; an exception names the student's function, file and line; a child that
loops, dies, floods its output or lies about the protocol costs the call it owed and
nothing else (the next call gets a new child)."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest

from rtpy.grading.sandbox import Child, ChildFailure, Isolation, StudentError

ROOT = Path(__file__).resolve().parents[2]

PROBES = """
import os, sys
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
