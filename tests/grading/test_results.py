"""The one results builder (rtpy.grading.results): numbered task.test and named by the
task's title in the map's order, hidden checks last and visible after the due date,
the reason a task file was not used on the tests it explains, the failed component
graders on a failed render, and the score table."""

from __future__ import annotations

import json
from pathlib import Path

from rtpy.grading.graders import SCENE_TASKS
from rtpy.grading.judge import Graded, Outcome
from rtpy.grading.results import gradescope_results, score_table
from rtpy.grading.tasks import load_week

ROOT = Path(__file__).resolve().parents[2]
FUNCTIONS = [
    {"path": "rtpy/light.py", "function": "PointLight.sample"},
    {"path": "rtpy/scene.py", "function": "Scene.find_occlusion"},
]


RENDER = "assignments/week05/test_week05.py::test_direct_render_matches_reference"


def graded() -> list[Graded]:
    return [
        Graded("d", "beyond the light", 3.0, None, True, Outcome(False, "in shadow")),
        Graded(RENDER, "render", 4.0, "05.4", False, Outcome(False, "differs", renders=True)),
        Graded("f", "lambertian", 3.0, "05.3", False, Outcome(False, "albedo / pi")),
        Graded("b", "blockers", 2.0, "05.2", False, Outcome(True, "")),
        Graded(
            "a",
            "unit direction",
            3.0,
            "05.1",
            False,
            Outcome(False, "NotImplementedError: week05 task: PointLight.sample: direction"),
        ),  # fmt: skip
        Graded("e", "emission", 1.0, "05.4", False, None),  # never ran
    ]


def test_results_show_numbers_names_points_visibility_and_explanations(monkeypatch):
    monkeypatch.setitem(
        SCENE_TASKS, ("test_week05.py", "test_direct_render_matches_reference"), ("05.1", "05.3")
    )
    week = load_week(ROOT / "assignments" / "week05")
    problems = {"rtpy/light.py": "line 3: SyntaxError: invalid syntax"}
    results = gradescope_results(
        graded(), week, problems=problems, task_functions=FUNCTIONS, notes=["Graded from x."]
    )
    tests = {t["name"]: t for t in results["tests"]}
    assert [t["number"] for t in results["tests"]] == [
        "5.1.1", "5.2.1", "5.3.1", "5.4.1", "5.4.2", "5.5.1"
    ]  # fmt: skip
    assert list(tests) == [
        "Point light: unit direction",
        "Shadow rays: blockers",
        "Lambertian: lambertian",
        "Direct lighting: render",
        "Direct lighting: emission",
        "Hidden checks: beyond the light",
    ]
    assert results["score"] == 2.0 and results["max_score"] == 16.0
    assert tests["Point light: unit direction"]["output"].startswith(
        "rtpy/light.py was not used (line 3: SyntaxError: invalid syntax), so this counts as "
        "not done"
    )
    # every failed grader of the tasks the render's scene uses, with the tasks' methods;
    # not the hidden check
    assert tests["Direct lighting: render"]["output"] == (
        "differs\nThis render's scene uses methods whose own checks failed; fix those first: "
        "5.1 Point light (PointLight.sample): 5.1.1 unit direction. 5.3 Lambertian "
        "(Lambertian.BRDF, Lambertian.pdf, Lambertian.scattering): 5.3.1 lambertian."
    )
    monkeypatch.setitem(SCENE_TASKS, ("test_week05.py", "test_direct_render_matches_reference"), ())
    alone = gradescope_results(graded(), week)["tests"][3]
    assert alone["output"] == "differs"  # a scene of given code only: nobody else blamed
    assert tests["Direct lighting: emission"]["output"] == "not run"
    hidden = tests["Hidden checks: beyond the light"]
    assert hidden["visibility"] == "after_due_date"
    assert {t["visibility"] for t in results["tests"] if t is not hidden} == {"visible"}
    assert results["output"].startswith("Graded from x.\nHidden checks (3 of the 16 points)")
    assert results["stdout_visibility"] == "hidden"
    json.dumps(results)  # Gradescope's format is JSON
    partial = gradescope_results(graded(), week, partial=True)
    assert {t["output"] for t in partial["tests"] if t["name"].endswith("emission")} == {
        "not run yet"
    }


def test_the_table_groups_tests_by_task_with_subtotals():
    week = load_week(ROOT / "assignments" / "week05")
    table = score_table(gradescope_results(graded(), week))
    lines = table.splitlines()
    assert any(line.startswith("5.4 Direct lighting") and line.endswith("0/5") for line in lines)
    assert any(line.strip().startswith("5.4.1 render") for line in lines)
    assert lines[-1].startswith("total") and lines[-1].endswith("2/16")


def test_the_judges_folders_are_taken_out_of_what_the_student_reads():
    from rtpy.grading.results import scrub

    work = "/tmp/rtpy-judge-abc/repo"
    results = {
        "output": f"rtpy/light.py: line 3: FileNotFoundError: '{work}/rtpy/x.npy'",
        "tests": [{"name": "t", "output": f"in {work} and /tmp/rtpy-judge-abc/home/f"}],
    }
    paths = {
        f"{work}/": "",
        work: ".",
        "/tmp/rtpy-judge-abc/home/": "<temporary folder>/",
        "/tmp/rtpy-judge-abc": "<grading folder>",
    }
    shown = scrub(results, paths)
    assert shown["output"] == "rtpy/light.py: line 3: FileNotFoundError: 'rtpy/x.npy'"
    assert shown["tests"][0]["output"] == "in . and <temporary folder>/f"
