"""The task map: what each week of the course asks, as data.

Every week's folder holds `assignments/weekNN/tasks.toml`: the lecture the week
follows, what a student should understand afterwards, and the tasks in the order the
lecture builds them. A task is one course-shaped method or a small group of them (the
solution regions a student writes), with its points and an estimated time:

    lecture = 5
    lecture_title = "lighting and shadows"
    title = "Lighting and shadows"
    goals = ["Explain why a point light's irradiance falls off with 1/r^2.", ...]
    render_time = "2 min"                    # the submission render of a scene, 2 cores

    [[tasks]]
    id = "05.1"                              # week.task; Gradescope numbers it 5.1
    title = "Point light"                    # no ":" (it starts the graders' names)
    methods = ["rtpy.light.PointLight.sample"]
    points = 3                               # the sum of its graders' points
    minutes = 30                             # an estimate for a student
    text = "What to write, the formula, the convention that catches people out."
    extension = false                        # true: optional, 0 points, graded apart
    render = "scenes/x.toml --time 30"       # `rtpy render` of the work done so far

    [[readings]]                             # given code to read, with a question
    title = "How light is counted once"
    code = ["rtpy.integrators.direct_lighting.sample_one_light"]
    text = "..."
    question = "..."

    [[renders]]                              # the course's render list for the week
    scene = "scenes/point_light.toml"        # in the week's folder, or a bundled name
    text = "What to render and what to explain."

The graders name their task (`@points(3, task="05.1")`); `grade()` groups and names
their results by it; rtpy.grading.task_pages writes each week's README and
docs/task-map.md from it; tests/grading/test_tasks.py checks it against the code
(every region of the week belongs to exactly one task, every task's methods hold
that week's regions, the points equal the graders').
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

TASKS_FILE = "tasks.toml"
ROOT = Path(__file__).resolve().parents[2]


class TaskMapError(ValueError):
    """A task map that cannot be read: names the file, the table and the key."""


@dataclass(frozen=True)
class Task:
    id: str  # "05.1"
    title: str
    methods: tuple[str, ...]  # qualified names: "rtpy.light.PointLight.sample"
    points: float
    minutes: int
    text: str
    extension: bool = False
    # what `python -m rtpy render` is given to show the work done once this task is
    # written ("week08_phong --integrator direct"); "" when nothing new renders
    render: str = ""

    @property
    def number(self) -> str:
        """The Gradescope number of the task: "05.1" -> "5.1"."""
        week, _, task = self.id.partition(".")
        return f"{int(week)}.{task}"


@dataclass(frozen=True)
class Reading:
    title: str
    code: tuple[str, ...]  # qualified names of the given code to read
    text: str
    question: str


@dataclass(frozen=True)
class Render:
    scene: str  # relative to the week's folder (a .toml file), else a bundled scene's name
    text: str


@dataclass(frozen=True)
class Week:
    week: str  # "05"
    title: str
    lecture: int
    lecture_title: str
    goals: tuple[str, ...]
    tasks: tuple[Task, ...]
    readings: tuple[Reading, ...]
    renders: tuple[Render, ...]
    # how long the submission render of one scene takes on a 2-core machine
    # (scripts/bench_student.py --weeks measures it): "7 min"; "" when not measured
    render_time: str = ""

    @property
    def graded(self) -> tuple[Task, ...]:
        return tuple(t for t in self.tasks if not t.extension)

    @property
    def extensions(self) -> tuple[Task, ...]:
        return tuple(t for t in self.tasks if t.extension)

    def task(self, task_id: str) -> Task:
        for t in self.tasks:
            if t.id == task_id:
                return t
        raise KeyError(task_id)


# --- reading and checking ---------------------------------------------------------------
class _Table:
    """One TOML table of the map, whose keys are read with their types checked; errors
    name the file, the table and the key."""

    def __init__(self, data: dict, where: str, allowed: set[str]) -> None:
        self.data, self.where = data, where
        unknown = sorted(set(data) - allowed)
        if unknown:
            self.fail(unknown[0], f"unknown key (expected one of {', '.join(sorted(allowed))})")

    def fail(self, key: str, problem: str):
        raise TaskMapError(f"{self.where}: key {key!r}: {problem}")

    def text(self, key: str, default: str | None = None) -> str:
        value = self.data.get(key, default)
        if not isinstance(value, str) or not value.strip():
            self.fail(key, "expected a non-empty string")
        return value.strip()

    def texts(self, key: str, required: bool = True) -> tuple[str, ...]:
        value = self.data.get(key, None if required else [])
        if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
            self.fail(key, "expected a list of non-empty strings")
        if required and not value:
            self.fail(key, "expected at least one entry")
        return tuple(value)

    def number(self, key: str, integer: bool = False) -> float:
        value = self.data.get(key)
        kinds = int if integer else (int, float)
        if isinstance(value, bool) or not isinstance(value, kinds) or value < 0:
            self.fail(key, f"expected {'an integer' if integer else 'a number'} >= 0")
        return value

    def tables(self, key: str, required: bool = True) -> list[dict]:
        value = self.data.get(key, None if required else [])
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            self.fail(key, f"expected an array of tables ([[{key}]])")
        if required and not value:
            self.fail(key, "expected at least one table")
        return value


TASK_KEYS = {"id", "title", "methods", "points", "minutes", "text", "extension", "render"}
WEEK_KEYS = {
    "title",
    "lecture",
    "lecture_title",
    "goals",
    "tasks",
    "readings",
    "renders",
    "render_time",
}


def _task(data: dict, where: str, week: str) -> Task:
    t = _Table(data, where, TASK_KEYS)
    task_id = t.text("id")
    prefix, _, rest = task_id.partition(".")
    if prefix != week or not rest.isdigit():
        t.fail("id", f"expected {week}.N (week {week}, a task number), got {task_id!r}")
    title = t.text("title")
    if ":" in title:
        t.fail("title", "must not contain ':' (it starts the names of the task's graders)")
    extension = t.data.get("extension", False)
    if not isinstance(extension, bool):
        t.fail("extension", "expected true or false")
    points = t.number("points")
    if extension and points != 0:
        t.fail("points", "an extension task is worth 0 points (it is graded apart)")
    methods = t.texts("methods")
    for name in methods:
        if not name.startswith("rtpy."):
            t.fail("methods", f"{name!r}: expected a qualified name starting with rtpy.")
    return Task(
        task_id,
        title,
        methods,
        points,
        t.number("minutes", integer=True),
        t.text("text"),
        extension,
        t.text("render") if "render" in t.data else "",
    )


def load_week(folder: str | Path) -> Week:
    """The task map of one week's folder (assignments/weekNN); TaskMapError naming the
    file, the table and the key of anything it cannot use."""
    folder = Path(folder)
    week = folder.name.removeprefix("week")
    path = folder / TASKS_FILE
    name = f"assignments/{folder.name}/{TASKS_FILE}"
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except OSError as err:
        raise TaskMapError(f"{name}: cannot read: {err.strerror}") from None
    except tomllib.TOMLDecodeError as err:
        raise TaskMapError(f"{name}: not valid TOML: {err}") from None
    top = _Table(data, name, WEEK_KEYS)
    tasks = tuple(
        _task(d, f"{name}: [[tasks]] {i + 1}", week) for i, d in enumerate(top.tables("tasks"))
    )
    ids = [t.id for t in tasks]
    if ids != [f"{week}.{k + 1}" for k in range(len(tasks))]:
        top.fail("tasks", f"ids must be {week}.1, {week}.2, ... in order, got {', '.join(ids)}")
    if any(t.extension for t in tasks[: len(tasks) - sum(t.extension for t in tasks)]):
        top.fail("tasks", "extension tasks come after the graded ones")
    readings = []
    for i, d in enumerate(top.tables("readings", required=False)):
        r = _Table(d, f"{name}: [[readings]] {i + 1}", {"title", "code", "text", "question"})
        readings.append(
            Reading(r.text("title"), r.texts("code"), r.text("text"), r.text("question"))
        )
    renders = []
    for i, d in enumerate(top.tables("renders")):
        r = _Table(d, f"{name}: [[renders]] {i + 1}", {"scene", "text"})
        renders.append(Render(r.text("scene"), r.text("text")))
    return Week(
        week,
        top.text("title"),
        int(top.number("lecture", integer=True)),
        top.text("lecture_title"),
        top.texts("goals"),
        tasks,
        tuple(readings),
        tuple(renders),
        top.text("render_time") if "render_time" in data else "",
    )


def load_weeks(root: str | Path | None = None) -> list[Week]:
    """The task maps of every week folder under root/assignments, in week order."""
    root = Path(root) if root is not None else ROOT
    return [load_week(f) for f in sorted((root / "assignments").glob("week[0-9][0-9]"))]


def method_file(name: str, root: str | Path | None = None) -> tuple[str, str]:
    """("rtpy/light.py", "PointLight.sample") for "rtpy.light.PointLight.sample": the
    longest module prefix that is a file under root, and the rest; ValueError if none."""
    root = Path(root) if root is not None else ROOT
    parts = name.split(".")
    for k in range(len(parts) - 1, 0, -1):
        path = Path(*parts[:k]).with_suffix(".py")
        if (root / path).is_file():
            return path.as_posix(), ".".join(parts[k:])
    raise ValueError(f"{name}: no module of it under {root}")


def task_numbers(root: str | Path | None = None) -> dict[tuple[str, str], str]:
    """(file, function) of every task method of the weeks' task maps under root ->
    the task's number: ("rtpy/materials/phong.py", "Phong.BRDF") -> "8.1"."""
    return {
        method_file(method, root): task.number
        for week in load_weeks(root)
        for task in week.tasks
        for method in task.methods
    }
