"""run_autograder's results (rtpy.grading.autograder_run): every test of the week with
its points and visibility, the reason a task file was not used on the tests it
explains, the failed component graders on a failed render, and a results.json even
when the autograder itself cannot run."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from rtpy.grading.autograder_run import EventReader, Outcome, Run, results_of

CONFIG = {
    "week": "05",
    "task_files": ["rtpy/light.py", "rtpy/scene.py"],
    "task_functions": [
        {"path": "rtpy/light.py", "function": "PointLight.sample"},
        {"path": "rtpy/scene.py", "function": "Scene.find_occlusion"},
    ],
    "test_timeout": 60.0,
    "total_timeout": 480.0,
    "tests": [
        {"nodeid": "a", "name": "PointLight.sample", "points": 3.0, "hidden": False},
        {"nodeid": "b", "name": "Scene.find_occlusion", "points": 2.0, "hidden": False},
        {"nodeid": "c", "name": "render", "points": 4.0, "hidden": False},
        {"nodeid": "d", "name": "beyond the light", "points": 3.0, "hidden": True},
    ],
}


def make_run(tmp_path: Path) -> Run:
    return Run(CONFIG, tmp_path, tmp_path, 0.0, tmp_path / "results.json")


def test_results_show_points_visibility_and_explanations(tmp_path):
    run = make_run(tmp_path)
    run.problems["rtpy/light.py"] = "line 3: SyntaxError: invalid syntax"
    run.outcomes = {
        "a": Outcome(False, "NotImplementedError: week05 task: PointLight.sample: direction"),
        "b": Outcome(True, ""),
        "c": Outcome(False, "direct integrator differs from the reference", renders=True),
        "d": Outcome(False, "sample_one_light: in shadow"),
    }
    results = results_of(run)
    tests = {t["name"]: t for t in results["tests"]}
    assert results["score"] == 2.0 and [t["max_score"] for t in results["tests"]] == [3, 2, 4, 3]
    assert tests["PointLight.sample"]["output"].startswith(
        "rtpy/light.py was not used (line 3: SyntaxError: invalid syntax), so this counts as "
        "not done"
    )
    assert tests["render"]["output"].endswith(
        "these graders, which failed: PointLight.sample. Fix those first."
    )  # the hidden check is not named to the student
    assert tests["beyond the light"]["visibility"] == "after_due_date"
    assert {t["visibility"] for n, t in tests.items() if n != "beyond the light"} == {"visible"}
    assert "Hidden checks (3 of the 12 points)" in results["output"]
    assert results["stdout_visibility"] == "hidden"
    json.dumps(results)  # Gradescope's format is JSON


def test_tests_without_an_outcome_count_as_failed(tmp_path):
    run = make_run(tmp_path)
    run.collection_errors.append("assignments/week05/test_week05.py: ImportError: cannot import")
    results = results_of(run)
    assert results["score"] == 0
    assert all(
        t["status"] == "failed" and "could not be loaded" in t["output"] for t in results["tests"]
    )


def test_the_event_reader_returns_complete_lines_only(tmp_path):
    path = tmp_path / "events.jsonl"
    reader = EventReader(path)
    assert reader.read() == []
    path.write_bytes(b'{"event": "start", "nodeid": "a"}\n{"event": "res')
    assert reader.read() == [{"event": "start", "nodeid": "a"}]
    with open(path, "ab") as f:
        f.write(b'ult", "nodeid": "a"}\n')
    assert reader.read() == [{"event": "result", "nodeid": "a"}]


def test_a_broken_autograder_still_writes_results(tmp_path):
    """No source/autograder.json (a zip that is not an autograder): score 0, and the
    output says it is not the student's fault."""
    env = dict(os.environ, AUTOGRADER_ROOT=str(tmp_path))
    proc = subprocess.run(
        [sys.executable, "-c", "from rtpy.grading.autograder_run import main; main()"],
        env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0
    results = json.loads((tmp_path / "results" / "results.json").read_text())
    assert results["score"] == 0 and "not your code" in results["output"]
