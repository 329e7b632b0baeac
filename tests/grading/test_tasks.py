"""The task maps (rtpy.grading.tasks) against the code they describe.

- every week folder has a map that loads, for the lecture of its number;
- every solution region of a week belongs to exactly one task of that week, and every
  task's methods exist and hold that week's regions (so nothing a student writes is
  outside a task, and no task names code the student does not write);
- the code a reading names exists and is given (holds no region);
- the scenes of the render lists exist and load, and every scene in a week's folder
  is named by its map;
- every grader names a task of its week's map, every task has graders, and the points
  per task are the graders' points (the README states them);
- week 05 asks no multiple importance sampling of the student: no region of the week
  computes an MIS weight; week 08's path loop is where the student applies them.

Malformed maps are refused with the file, the table and the key.
"""

from __future__ import annotations

import importlib
import inspect
from dataclasses import replace
from functools import cache
from pathlib import Path

import pytest

import rtpy
import rtpy.integrators.direct_lighting as direct_lighting
from rtpy.grading.assignment import WEEKS, Region, find_regions
from rtpy.grading.graders import collect_graders
from rtpy.grading.tasks import TaskMapError, load_week, load_weeks, method_file

ROOT = Path(__file__).resolve().parents[2]


@cache
def weeks():
    return {w.week: w for w in load_weeks(ROOT)}


@cache
def regions() -> list[Region]:
    return find_regions(ROOT)


def qualified(region: Region) -> str:
    """rtpy.materials.phong.Phong.BRDF for a region in Phong.BRDF of rtpy/materials/phong.py."""
    return ".".join(region.path.with_suffix("").parts) + "." + region.function


def resolve(name: str):
    """The object a qualified rtpy name stands for (AttributeError if there is none)."""
    path, qualname = method_file(name, ROOT)
    obj = importlib.import_module(path.removesuffix(".py").replace("/", "."))
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj


def test_every_week_has_a_task_map_for_its_lecture():
    assert sorted(weeks()) == list(WEEKS)
    for week, w in weeks().items():
        assert w.lecture == int(week), f"week {week} follows lecture {w.lecture}"
        assert w.graded and all(t.minutes > 0 for t in w.tasks)


def region_problems(regions_, weeks_) -> list[str]:
    """Regions outside every task or in several, and task methods without a region of
    their week."""
    problems = []
    for r in regions_:
        owners = [t.id for t in weeks_[r.week].tasks if qualified(r) in t.methods]
        if len(owners) != 1:
            problems.append(f"{r.path}:{r.begin + 1} {r.function}: in tasks {owners}")
    held = {(r.week, qualified(r)) for r in regions_}
    for week, w in weeks_.items():
        for t in w.tasks:
            problems += [f"{t.id}: {m} holds no week-{week} region" for m in t.methods
                         if (week, m) not in held]  # fmt: skip
    return problems


def test_every_region_belongs_to_exactly_one_task_and_every_task_holds_regions():
    assert region_problems(regions(), weeks()) == []
    for w in weeks().values():
        for t in w.tasks:
            for name in t.methods:
                assert callable(resolve(name)), name
    # the check can fail: a region that no task claims, a task method without a region
    loose = Region(Path("rtpy/light.py"), 0, 2, "05", "x", "AreaLight.sample", "")
    found = region_problems([*regions(), loose], weeks())
    assert found == ["rtpy/light.py:1 AreaLight.sample: in tasks []"]
    without = [r for r in regions() if r.function != "PointLight.sample"]
    assert region_problems(without, weeks()) == [
        "05.1: rtpy.light.PointLight.sample holds no week-05 region"
    ]


def test_readings_name_given_code():
    held = {qualified(r) for r in regions()}
    for w in weeks().values():
        for reading in w.readings:
            for name in reading.code:
                assert callable(resolve(name)), name
                assert name not in held, f"week {w.week}: {name} is a task, not given code"


def test_render_lists_name_scenes_that_load_and_every_scene_shipped_is_named():
    for week, w in weeks().items():
        folder = ROOT / "assignments" / f"week{week}"
        named = set()
        for render in w.renders:
            if render.scene.endswith(".toml"):
                assert (folder / render.scene).is_file(), f"week {week}: {render.scene}"
                named.add(render.scene)
            rtpy.load_scene(str(folder / render.scene) if render.scene.endswith(".toml")
                            else render.scene)  # fmt: skip
        texts = " ".join(r.text + r.question for r in w.readings)
        for path in sorted(folder.glob("scenes/*.toml")):
            rel = path.relative_to(folder).as_posix()
            rtpy.load_scene(str(path))
            assert rel in named or f"week{week}/{rel}" in texts, (
                f"assignments/week{week}/{rel}: not named in the week's task map"
            )


def points_problems(week_map, graders) -> list[str]:
    """Graders without a task of the map, tasks without graders, points that differ
    from the map's, an extension's graders worth points."""
    tasks = {t.id: t for t in week_map.tasks}
    problems = [f"{g.nodeid}: no task {g.task}" for g in graders if g.task not in tasks]
    for task in week_map.tasks:
        points = [g.max_score for g in graders if g.task == task.id]
        if sum(points) != task.points or not points:
            problems.append(f"{task.id}: graders {points}, map {task.points:g}")
        if task.extension and any(points):
            problems.append(f"{task.id}: an extension's graders are worth 0")
    return problems


@pytest.mark.parametrize("week", WEEKS)
def test_graders_name_the_tasks_and_their_points_are_the_maps(week):
    graders = collect_graders(week, ROOT)
    assert points_problems(weeks()[week], graders) == []
    if week == "08":  # the check can fail
        first, *rest = graders
        planted = [replace(first, max_score=first.max_score + 1), *rest]
        k = next(k for k, g in enumerate(planted) if g.task == "08.5")
        planted[k] = replace(planted[k], max_score=1.0)  # an extension's grader
        planted.append(replace(first, nodeid="x::test_new", task="08.9"))
        assert points_problems(weeks()[week], planted) == [
            "x::test_new: no task 08.9",
            f"{first.task}: graders {[g.max_score for g in planted if g.task == first.task]}, "
            f"map {weeks()[week].task(first.task).points:g}",
            "08.5: graders [1.0, 0.0, 0.0], map 0",
            "08.5: an extension's graders are worth 0",
        ]


def region_text(region: Region) -> str:
    lines = (ROOT / region.path).read_text().splitlines()
    return "\n".join(lines[region.begin : region.end + 1])


MIS = ("power_heuristic", "emission_weight")


def test_week05_asks_no_mis_and_week08s_path_loop_applies_it():
    week05 = [r for r in regions() if r.week == "05"]
    assert week05
    for r in week05:
        assert not any(name in region_text(r) for name in MIS), f"{r.function} computes MIS"
    (path_loop,) = [r for r in regions() if r.function == "PathIntegrator.compute_scattering"]
    assert path_loop.week == "08" and "emission_weight(" in region_text(path_loop)
    # the check can fail: the given combination of the strategies holds MIS
    given = inspect.getsource(direct_lighting.sample_one_light)
    assert "power_heuristic" in given and "emission_weight" in inspect.getsource(
        direct_lighting.direct_lighting
    )


GOOD = """
title = "T"
lecture = 5
lecture_title = "t"
goals = ["g"]
[[tasks]]
id = "05.1"
title = "A task"
methods = ["rtpy.light.PointLight.sample"]
points = 3
minutes = 30
text = "t"
[[renders]]
scene = "week05_point_light"
text = "t"
"""


@pytest.mark.parametrize(
    "change,words",
    [
        (("points = 3", "points = -1"), "[[tasks]] 1: key 'points': expected a number >= 0"),
        (('id = "05.1"', 'id = "06.1"'), "[[tasks]] 1: key 'id': expected 05.N"),
        (('id = "05.1"', 'id = "05.2"'), "key 'tasks': ids must be 05.1"),
        (('title = "A task"', 'title = "A: task"'), "key 'title': must not contain ':'"),
        (("text = \"t\"\n[[renders]]", "extension = true\ntext = \"t\"\n[[renders]]"),
         "key 'points': an extension task is worth 0 points"),
        (('methods = ["rtpy.', 'methods = ["'), "key 'methods': 'light.PointLight.sample'"),
        (("minutes = 30", "minutes = 0.5"), "key 'minutes': expected an integer"),
        (('goals = ["g"]', "goals = []"), "key 'goals': expected at least one entry"),
        (('lecture = 5', 'lecture = 5\ncolour = 1'), "key 'colour': unknown key"),
        (("[[renders]]", "[renders]"), "key 'renders': expected an array of tables"),
        (('title = "T"', 'title = "T'), "not valid TOML"),
    ],
)  # fmt: skip
def test_a_bad_map_is_refused_naming_the_file_table_and_key(tmp_path, change, words):
    folder = tmp_path / "assignments" / "week05"
    folder.mkdir(parents=True)
    (folder / "tasks.toml").write_text(GOOD)
    assert load_week(folder).task("05.1").points == 3  # the good map loads
    old, new = change
    assert old in GOOD
    (folder / "tasks.toml").write_text(GOOD.replace(old, new, 1))
    with pytest.raises(TaskMapError) as info:
        load_week(folder)
    assert str(info.value).startswith("assignments/week05/tasks.toml") and words in str(
        info.value
    ), str(info.value)


def test_a_missing_map_and_a_name_outside_rtpy_are_refused(tmp_path):
    with pytest.raises(TaskMapError, match="tasks.toml: cannot read"):
        load_week(tmp_path / "week05")
    assert method_file("rtpy.materials.phong.Phong.BRDF", ROOT) == (
        "rtpy/materials/phong.py",
        "Phong.BRDF",
    )
    with pytest.raises(ValueError, match="no module"):
        method_file("rtpy.nowhere.f", ROOT)


def test_every_region_has_the_number_of_its_task():
    """The stubs of a student repository name their task's number (rtpy.engine.unfinished
    reads it back when a render reaches one): every region's method is in a task."""
    from rtpy.grading.tasks import task_numbers

    numbers = task_numbers(ROOT)
    assert numbers[("rtpy/materials/phong.py", "Phong.BRDF")] == "8.1"
    assert numbers[("rtpy/light.py", "PointLight.sample")] == "5.1"
    for r in find_regions(ROOT):
        number = numbers[(r.path.as_posix(), r.function)]
        assert number.startswith(f"{int(r.week)}."), (r.function, number)
