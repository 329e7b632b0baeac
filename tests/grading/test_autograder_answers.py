"""No answers given away: a week's tasks are not solved elsewhere in what ships that
week, or the autograder's hidden checks would grade code a student could copy.

`answers_elsewhere` looks, for every task of a week, for a function that ships that
week (rtpy outside the stubbed regions and the numpy backend, the week's graders,
the tests that ship) and calls every function the task's solution calls, as many
times: the trace of a solution written out again, whatever its variable names. What
it finds is either fixed or listed in KNOWN with the reason; the docstrings that
answered a week's written questions are checked by ANSWERED_QUESTIONS.
"""

from __future__ import annotations

import ast
from collections import Counter
from functools import cache
from pathlib import Path

import pytest

from rtpy.grading.assignment import (
    WEEKS,
    _enclosing_functions,
    find_regions,
    shipped_tests,
    withheld,
)

ROOT = Path(__file__).resolve().parents[2]
MIN_CALLS = 3  # shorter solutions have too common a trace to tell

# (week, task, file::function that holds its trace) -> why it stays
KNOWN: dict[tuple[str, str, str], str] = {}  # none left

# file -> a phrase that answered the week's written question and must not come back
ANSWERED_QUESTIONS = {
    "rtpy/materials/blinn_phong.py": "half the angle",  # week 08: why 4 times Phong's exponent
    "rtpy/materials/metal.py": "darkens at grazing",  # week 07: why rough metal darkens
    "rtpy/integrators/jittered.py": "anti-alias",  # week 03: what jitter does at the edges
}


def called(node: ast.AST) -> list[tuple[int, str]]:
    """(line, name) of every function or method called in node."""
    out = []
    for n in ast.walk(node):
        if isinstance(n, ast.Call):
            f = n.func
            name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
            if name:
                out.append((n.lineno, name))
    return out


@cache
def function_calls(path: Path) -> dict[str, Counter]:
    """Qualified name -> the names it calls with their counts, for every function of
    the file (a nested function's calls count for its outer functions too)."""
    source = path.read_text()
    found = called(ast.parse(source))
    return {
        name: Counter(call for line, call in found if first <= line <= last)
        for first, last, name in _enclosing_functions(source)
    }


def solution_calls(root: Path, region) -> Counter:
    lines = (root / region.path).read_text().splitlines()[region.begin + 1 : region.end]
    body = "\n".join(line.removeprefix(region.indent) for line in lines)
    return Counter(name for _, name in called(ast.parse(body)))


def shipped_code(root: Path, week: str) -> list[Path]:
    rtpy = [p for p in (root / "rtpy").rglob("*.py") if "numpy_backend" not in p.parts]
    graders = sorted((root / "assignments" / f"week{week}").glob("*.py"))
    tests = [root / rel for rel in shipped_tests(root, week)[0]]
    return sorted(rtpy) + graders + tests


@cache
def regions_of(root: Path) -> list:
    return find_regions(root)


def answers_elsewhere(root: Path, week: str) -> set[tuple[str, str, str]]:
    """(week, task, file::function) for every shipped function holding a trace of one
    of the week's solutions."""
    regions = regions_of(root)
    stubbed = {(r.path.as_posix(), r.function) for r in regions if withheld(r.week, week)}
    traces = [(r, solution_calls(root, r)) for r in regions if r.week == week]
    traces = [(r, t) for r, t in traces if sum(t.values()) >= MIN_CALLS]
    found = set()
    for path in shipped_code(root, week):
        rel = path.relative_to(root).as_posix()
        for name, held in function_calls(path).items():
            if (rel, name) in stubbed:
                continue
            for region, trace in traces:
                if not trace - held:
                    found.add((week, region.function, f"{rel}::{name}"))
    return found


@pytest.mark.parametrize("week", WEEKS)
@pytest.mark.slow
def test_no_task_is_solved_elsewhere_in_its_week(week):
    found = answers_elsewhere(ROOT, week)
    known = {k for k in KNOWN if k[0] == week}
    assert found - known == set(), "a task's solution ships elsewhere (fix it, or add to KNOWN)"
    assert known - found == set(), "no longer found: drop it from KNOWN"


def test_a_planted_copy_of_a_solution_is_found(tmp_path):
    """A solution written out again under other names, in a function that ships."""
    (tmp_path / "rtpy").mkdir()
    (tmp_path / "rtpy" / "light.py").write_text(
        "def sample(p):\n"
        "    # BEGIN SOLUTION week05: radiance\n"
        "    d = length(p)\n"
        "    return scale(unit(p), 1 / square(d))\n"
        "    # END SOLUTION\n"
    )
    (tmp_path / "rtpy" / "other.py").write_text(
        "def helper(q):\n    r = length(q)\n    k = 1 / square(r)\n    return scale(unit(q), k)\n"
    )
    assert answers_elsewhere(tmp_path, "05") == {("05", "sample", "rtpy/other.py::helper")}
    assert answers_elsewhere(tmp_path, "03") == set()  # another week's: not searched


def test_docstrings_do_not_answer_the_written_questions():
    for rel, phrase in ANSWERED_QUESTIONS.items():
        assert phrase not in (ROOT / rel).read_text().lower(), f"{rel}: {phrase!r}"
