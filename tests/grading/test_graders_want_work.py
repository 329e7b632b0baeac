"""No marks for nothing: every week's graders, visible and hidden, score 0 on a
submission that does not do the week's tasks.

Two submissions, each replacing every method of every graded task of the week (the
methods of assignments/weekNN/tasks.toml) in this process:

- "nothing": a material reflects nothing (BRDF() black, pdf() 0, scattering() None),
  an integrator returns black, and every other method the zero of what it should
  return (a zero vector, 0.0, False, None);
- "constant": every method answers its first answer again, whatever it is asked
  (the right type, and right for one input).

The whole week is graded (`grade(week, hidden=True)` with the probes answered here)
and must score 0 (the 0-point extensions aside).
"""

from __future__ import annotations

import importlib
import inspect
import sys
from pathlib import Path

import pytest

from rtpy.grading.graders import grade
from rtpy.grading.tasks import load_weeks, method_file
from rtpy.vec3 import Color, Vec3

ROOT = Path(__file__).resolve().parents[2]
WEEKS = {w.week: w for w in load_weeks(ROOT)}


def owner_of(name: str):
    """(the class or module holding the qualified name, the attribute's name)."""
    path, function = method_file(name, ROOT)
    owner = importlib.import_module(path.removesuffix(".py").replace("/", "."))
    *classes, attribute = function.split(".")
    for cls in classes:
        owner = getattr(owner, cls)
    return owner, attribute


def zero_like(value):
    """The zero of value's kind: black, the zero vector, 0.0, False, a tuple of zeros;
    None for anything else (a ray, a hit, a sample)."""
    if isinstance(value, Color):
        return Color(0.0, 0.0, 0.0)
    if isinstance(value, Vec3):
        return Vec3(0.0, 0.0, 0.0)
    if isinstance(value, bool):
        return False
    if isinstance(value, int | float):
        return 0.0
    if isinstance(value, tuple):
        return tuple(zero_like(v) for v in value)
    return None


def nothing(attribute: str, original):
    """The method that does nothing: a material's BRDF black, pdf 0, scattering None."""
    fixed = {"BRDF": Color(0.0, 0.0, 0.0), "pdf": 0.0, "scattering": None}

    def replacement(*args, **kwargs):
        if attribute in fixed:
            return fixed[attribute]
        return zero_like(original(*args, **kwargs))

    return replacement


def constant(attribute: str, original):
    """The method that answers its first answer to everything."""
    first = []

    def replacement(*args, **kwargs):
        if not first:
            first.append(original(*args, **kwargs))
        return first[0]

    return replacement


def patch_week(mp, week: str, make) -> None:
    """Every method of the week's graded tasks replaced by make(attribute, original);
    a module-level function also in every rtpy module that imported it by name."""
    for task in WEEKS[week].graded:
        for name in task.methods:
            owner, attribute = owner_of(name)
            original = inspect.getattr_static(owner, attribute)
            replacement = make(attribute, getattr(owner, attribute))
            mp.setattr(owner, attribute, replacement)
            if inspect.ismodule(owner):
                for module_name, module in list(sys.modules.items()):
                    if module_name.startswith("rtpy") and getattr(module, attribute, None) is (
                        original
                    ):
                        mp.setattr(module, attribute, replacement)


def earned(results: dict) -> list[str]:
    return [f"{t['number']} {t['name']}" for t in results["tests"] if t["score"] > 0]


@pytest.mark.slow
@pytest.mark.parametrize("make", [nothing, constant], ids=["nothing", "constant"])
@pytest.mark.parametrize("week", sorted(WEEKS))
def test_a_week_not_done_scores_zero(monkeypatch, tmp_path, week, make):
    monkeypatch.chdir(tmp_path)  # grade() draws failed chi-square checks here
    patch_week(monkeypatch, week, make)
    results = grade(week, ROOT, in_process=True, hidden=True)
    assert results["score"] == 0, f"week {week}, {make.__name__}: points for {earned(results)}"
    assert results["max_score"] > 0


def test_the_submissions_replace_the_methods(monkeypatch):
    """The two submissions are what they say: week 08's Phong reflects nothing, and a
    constant vec3.cross answers its first answer to everything (the replacements take
    effect where the graders call them)."""
    from rtpy import vec3
    from rtpy.materials import Phong

    patch_week(monkeypatch, "08", nothing)
    assert Phong().BRDF(None, None, None) == Color(0.0, 0.0, 0.0)
    assert Phong().scattering(None, None) is None and Phong().pdf(None, None, None) == 0.0
    monkeypatch.undo()
    patch_week(monkeypatch, "03", constant)
    first = vec3.cross(Vec3(1, 0, 0), Vec3(0, 1, 0))
    assert vec3.cross(Vec3(0, 1, 0), Vec3(0, 0, 1)) == first == Vec3(0, 0, 1)


def stub(qualified: str):
    def raises(*args, **kwargs):
        raise NotImplementedError(f"week08 task: {qualified}")

    return raises


@pytest.mark.slow
def test_a_stub_costs_its_own_task_and_feedback_names_what_the_check_uses(monkeypatch, tmp_path):
    """Week 08 with Blinn-Phong still a stub and a sampling mistake in Phong.scattering
    (the highlight drawn around the normal): Cook-Torrance keeps every point, visible
    and hidden; the hidden Blinn-Phong cases fail alone; the failed render names every
    failed grader of the models in its scene and the furnace (one given material) none;
    Phong's mistake is blamed on scattering(), its BRDF keeps its points."""
    from rtpy.materials import BlinnPhong

    from .test_graders import source

    for name in ("BRDF", "pdf", "scattering"):
        monkeypatch.setattr(BlinnPhong, name, stub(f"BlinnPhong.{name}"))
    source("phong_highlight_around_the_normal")(monkeypatch)
    monkeypatch.chdir(tmp_path)  # grade() draws failed chi-square checks here
    results = grade("08", ROOT, in_process=True, hidden=True)
    tests = {t["number"]: t for t in results["tests"]}
    by_name = {t["name"]: t for t in results["tests"]}
    task = {
        n: sum(t["score"] for t in results["tests"] if t["number"].startswith(n + "."))
        for n in ("8.1", "8.2", "8.3")
    }
    assert task["8.2"] == 0 and task["8.3"] == 14, task
    hidden = {
        n.rpartition("[")[2].rstrip("]"): t for n, t in by_name.items() if "new parameters" in n
    }
    assert {k: t["score"] > 0 for k, t in hidden.items() if "CookTorrance" in k} == {
        "CookTorrance": True
    }
    assert all(t["score"] == 0 for n, t in by_name.items() if n.endswith("[BlinnPhong]"))
    assert (
        by_name["Phong: Phong.BRDF: kd albedo / pi + ks (n + 2) / (2 pi) max(0, r . wo)^n"]["score"]
        == 3
    )
    for t in results["tests"]:
        if t["number"].startswith("8.1.") and t["status"] == "failed":
            assert "Phong.scattering" in t["output"] and "Phong.BRDF" not in t["output"], t
    render = next(t for t in results["tests"] if "three glossy balls" in t["name"])
    failed_82 = [n for n, t in tests.items() if n.startswith("8.2.") and t["status"] == "failed"]
    assert render["status"] == "failed" and len(failed_82) == 5
    for number in failed_82:
        assert number in render["output"]
    assert "8.1 Phong (Phong.BRDF, Phong.pdf, Phong.scattering)" in render["output"]
    assert "8.3" not in render["output"].partition("fix those first")[2]  # Cook-Torrance is right
    furnace = next(t for t in results["tests"] if t["name"].endswith("L = Le / (1 - albedo)"))
    assert furnace["status"] == "passed"


# (week, the task whose methods are stubs, hidden cases that keep their points, those lost)
ONE_STUB = [
    ("03", "03.2", ["[vectors]"], ["[intervals]"]),
    ("04", "04.3", ["[Quad]"], ["[Triangle]"]),
    ("06", "06.2", ["[reflect]"], ["[refract]"]),
    ("08", "08.2", ["[Phong]", "[CookTorrance]"], ["[BlinnPhong]"]),
]


@pytest.mark.slow
@pytest.mark.parametrize("week,task,kept,lost", ONE_STUB, ids=[t for _, t, _, _ in ONE_STUB])
def test_a_stub_costs_no_hidden_points_of_another_task(
    monkeypatch, tmp_path, week, task, kept, lost
):
    """Hidden checks are per task: with one task's methods stubs (NotImplementedError),
    the hidden cases of the other tasks keep their points."""
    monkeypatch.chdir(tmp_path)
    for name in WEEKS[week].task(task).methods:
        owner, attribute = owner_of(name)
        monkeypatch.setattr(owner, attribute, stub(name))
        if inspect.ismodule(owner):  # and where other rtpy modules imported it by name
            for module_name, module in list(sys.modules.items()):
                found = getattr(module, attribute, None) if module_name.startswith("rtpy") else None
                if callable(found) and getattr(found, "__module__", "") == owner.__name__:
                    monkeypatch.setattr(module, attribute, stub(name))
    results = grade(week, ROOT, in_process=True, hidden=True)
    hidden = {t["name"]: t for t in results["tests"] if t["visibility"] != "visible"}
    for case in kept:
        scores = [t["score"] for n, t in hidden.items() if n.endswith(case)]
        assert scores and all(x > 0 for x in scores), (case, scores)
    for case in lost:
        scores = [t["score"] for n, t in hidden.items() if n.endswith(case)]
        assert scores and not any(scores), (case, scores)
