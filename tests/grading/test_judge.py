"""The judge (rtpy.grading.judge): runs graders in this process with the student's
code behind `probe`, words every outcome, keeps each test to its time and stops
starting tests when the whole run's time is spent."""

from __future__ import annotations

import textwrap
import time

import pytest

from rtpy.grading.judge import Judge, judge, probe_registry
from rtpy.grading.sandbox import InProcess

PROBES = """
import time
from rtpy.grading.probes import probe
from rtpy.grading.protocol import Float, List

@probe(returns=Float)
def judge_test_square(x):
    return x * x

@probe(returns=Float)
def judge_test_sleep(seconds):
    time.sleep(seconds)
    return 0.0

@probe(returns=List(Float))
def judge_test_wrong_form():
    return "not a list"
"""

GRADERS = '''
import pytest
from rtpy.grading import points

@points(2, task="05.1")
def test_square(probe):
    """squares"""
    assert probe.judge_test_square(x=3.0) == 9.0

@points(1, task="05.1")
def test_wrong(probe):
    """a wrong square"""
    got = probe.judge_test_square(x=2.0)
    assert got == 5.0, f"square(2) = {got}, expected 5"

def test_form(probe):
    """wrong form"""
    probe.judge_test_wrong_form()

def test_grader_bug(probe):
    """a bug of the grader"""
    {}["missing"]

@pytest.mark.parametrize("n", [1, 2])
def test_slow(probe, n):
    """slow"""
    probe.judge_test_sleep(seconds=3.0)
'''


def run(tmp_path, name: str = "test_judged.py", **limits) -> Judge:
    folder = tmp_path / "assignments" / "week05"
    folder.mkdir(parents=True)
    (folder / "probes.py").write_text(PROBES)
    (folder / name).write_text(textwrap.dedent(GRADERS))
    (folder / "conftest.py").write_text("from rtpy.grading.judge import probe  # noqa: F401\n")
    registry = probe_registry([folder / "probes.py"])
    runner = InProcess({"probe_modules": [str(folder / "probes.py")]}, tmp_path)
    return judge(Judge(runner, registry, **limits), [str(folder)])


def test_outcomes_are_worded_by_the_judge(tmp_path):
    plugin = run(tmp_path, test_timeout=1.0, total_timeout=0.5)
    out = {g.nodeid.split("::")[-1]: g for g in plugin.tests.values()}
    assert out["test_square"].outcome.passed and out["test_square"].max_score == 2.0
    assert out["test_square"].task == "05.1" and out["test_square"].name == "squares"
    assert out["test_wrong"].outcome.output == "square(2) = 4.0, expected 5"
    assert out["test_form"].outcome.output.startswith("the student's code answered in the wrong")
    assert "tell your instructor" in out["test_grader_bug"].outcome.output
    assert any("KeyError" in line for line in plugin.log)  # the traceback, for the instructor
    slow = out["test_slow[1]"].outcome.output
    assert "did not finish within its time limit" in slow  # the probe's own timer, 1 s
    assert out["test_slow[2]"].outcome.output.startswith("not run: the time limit of 0.5 s")
    assert out["test_slow[1]"].name == "slow[1]"


@pytest.mark.slow
def test_a_test_under_way_ends_with_the_total_time(tmp_path):
    """The whole run's time bounds the test under way too: its probe gets what is left
    of it, and the tests after it are marked not run."""
    start = time.monotonic()
    plugin = run(tmp_path, "test_judged_total.py", test_timeout=30.0, total_timeout=2.0)
    assert time.monotonic() - start < 2.0 + 1.0  # the slow test alone would take 3 s
    out = {g.nodeid.split("::")[-1]: g.outcome for g in plugin.tests.values()}
    assert "did not finish" in out["test_slow[1]"].output, out
    assert out["test_slow[2]"].output.startswith("not run: the time limit of 2 s")
