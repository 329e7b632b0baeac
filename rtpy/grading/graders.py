"""Grading the weekly assignments: points per task, a score table, Gradescope JSON, and
a noise-aware comparison of renders with a reference.

A grader is a pytest test in `assignments/weekNN/` marked with its points and the task
of the week's task map (`assignments/weekNN/tasks.toml`, rtpy.grading.tasks) it grades:

    from rtpy.grading import points

    @points(3, task="05.1")
    def test_point_light_sample():
        \"\"\"unit direction, distance, radiance I / d^2\"\"\"   # shown after the task's title
        ...
        assert ok, "PointLight.sample (rtpy/light.py): ... what is wrong, what to do"

A parametrized grader whose cases grade different tasks marks each case instead:
`pytest.param("phong", marks=points(2, task="08.1"))`. A test scores all its points
when it passes and none when it fails; its output is the assertion's message (or the
exception, such as the NotImplementedError of a stub). `python -m rtpy grade WEEK
[--json results.json]` runs them in-process (`grade()`), prints a table grouped by
task with subtotals and writes the results in Gradescope's autograder format: each
test is numbered task.test ("5.1.1", which Gradescope orders and groups by) and named
"<task title>: <first docstring line>". Extension tasks are worth 0 points: their
tests report passed or failed in their own group and do not change the score.

Renders are compared by `assert_render_matches`: R renders with different seeds are
cut into 8 x 8 pixel blocks and each block mean is compared with a stored reference
(rendered by rtpy's solution, `assignments/weekNN/reference/*.npz`) by a z-test
whose variance is the noise both sides measure (each pixel's per-sample variance
from the spread of its R values), Bonferroni-corrected over blocks and channels:
a correct renderer fails with probability below ALPHA, while a missing 1/pdf, a
light counted twice or a missing 1/r^2 shifts whole regions by many sigmas.
"""

from __future__ import annotations

import contextlib
import io
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..io.image import atomic_write
from ..testing.statistics import BlockTest, block_z_test

ALPHA = 1e-3
DEFAULT_POINTS = 1


def points(n: float, task: str | None = None):
    """Mark: the test (or a parametrized case) is worth n points toward `task`, the id
    of a task in the week's task map ("05.1")."""
    import pytest

    return pytest.mark.points(n, task=task)


# --- render comparison ----------------------------------------------------------------
def render_stack(scene, seeds, **settings) -> np.ndarray:
    """(R, H, W, 3) linear renders of scene, one per seed (scalar backend)."""
    import rtpy

    return np.stack([rtpy.render(scene, seed=s, quiet=True, **settings).linear for s in seeds])


def summarize(stack: np.ndarray, spp: int) -> dict[str, np.ndarray]:
    """What a comparison needs of R renders at spp: the mean image, each pixel's
    per-sample variance (spread of the R values times spp) and the sample count."""
    stack = np.asarray(stack, dtype=np.float64)
    if len(stack) < 2:
        raise ValueError("need at least 2 renders to measure the noise")
    return {
        "mean": stack.mean(axis=0),
        "s2": stack.var(axis=0, ddof=1) * spp,
        "samples": np.array(spp * len(stack)),
    }


def compare(graded: dict, reference: dict, alpha: float = ALPHA) -> BlockTest:
    """z-test of 8 x 8 block means, each side's variance from its own measured noise
    (rtpy.testing.statistics.block_z_test)."""
    return block_z_test(
        graded["mean"],
        graded["s2"] / float(graded["samples"]),
        reference["mean"],
        reference["s2"] / float(reference["samples"]),
        alpha,
    )


def load_reference(path: str | Path) -> dict[str, np.ndarray]:
    with np.load(path) as data:
        return {k: data[k] for k in data.files}


def save_reference(path: str | Path, summary: dict[str, np.ndarray]) -> None:
    np.savez_compressed(path, **summary)


def assert_render_matches(stack: np.ndarray, spp: int, reference: dict, what: str) -> None:
    """AssertionError naming the worst block unless the renders agree with the reference."""
    result = compare(summarize(stack, spp), reference)
    assert result.passed, f"{what}: {result.worst()}"


def reference_summary(scene, render: dict, reference: dict) -> dict[str, np.ndarray]:
    """What a grader stores as its reference: the summary of renders of scene with the
    grader's `render` settings, at reference["spp"] with the seeds reference["seeds"]."""
    spp = reference["spp"]
    return summarize(render_stack(scene, reference["seeds"], **dict(render, spp=spp)), spp)


def assert_renders_match(scene, seeds, render: dict, reference: str | Path, what: str) -> None:
    """Renders of scene, one per seed with the `render` settings, agree with the
    reference summary stored at `reference` (assert_render_matches)."""
    stack = render_stack(scene, seeds, **render)
    assert_render_matches(stack, render["spp"], load_reference(reference), what)


def deterministic_image(scene, **settings) -> np.ndarray:
    """The render at spp 1 with seed 0, for graders that compare an image with their
    reference to rounding: the "center" integrator's, or one jittered sample per pixel
    of an integrator that draws no other random number (Whitted's with point lights)."""
    return render_stack(scene, (0,), spp=1, **settings)[0]


def assert_image_matches(
    image: np.ndarray, reference: np.ndarray, what: str, hint: str, rtol: float, atol: float
) -> None:
    """For deterministic renders: at most 1 % of the pixels may differ from the
    reference beyond rtol/atol (a pixel centre exactly on an edge may round either
    way); otherwise an AssertionError naming the first wrong pixel and `hint`."""
    wrong = ~np.isclose(image, reference, rtol=rtol, atol=atol).all(axis=2)
    if wrong.mean() <= 0.01:
        return
    row, column = np.argwhere(wrong)[0]
    raise AssertionError(
        f"{what}: {wrong.sum()} of {wrong.size} pixels differ from the reference "
        f"(first at row {row}, column {column}): {hint}"
    )


# --- running graders ------------------------------------------------------------------
@dataclass
class GraderResult:
    name: str  # the first line of the test's docstring, with a parametrized case's id
    nodeid: str
    max_score: float
    task: str | None = None  # the id of the task it grades ("05.1")
    score: float = 0.0
    output: str = ""
    passed: bool = False


@dataclass(eq=False)
class PointsPlugin:
    """pytest plugin: every collected test's points and task, and whether it passed."""

    results: dict[str, GraderResult] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)  # graders that could not be loaded

    def pytest_collectreport(self, report) -> None:
        if report.failed:
            self.errors.append(f"{report.nodeid}: {failure_message(report)}")

    def pytest_configure(self, config) -> None:
        config.addinivalue_line("markers", "points(n, task): points a grader test is worth")

    def pytest_collection_modifyitems(self, items) -> None:
        for item in items:
            mark = item.get_closest_marker("points")
            value = float(mark.args[0]) if mark else DEFAULT_POINTS
            task = mark.kwargs.get("task") if mark else None
            doc = (getattr(item.function, "__doc__", None) or "").strip().splitlines()
            name = doc[0] if doc else item.name
            if "[" in item.name:
                name += item.name[item.name.index("[") :]
            self.results[item.nodeid] = GraderResult(name, item.nodeid, value, task)

    def pytest_runtest_logreport(self, report) -> None:
        result = self.results.get(report.nodeid)
        if result is None:
            return
        if report.failed:
            result.score, result.passed = 0.0, False
            result.output = failure_message(report)
        elif report.when == "call" and report.passed and not result.output:
            result.score, result.passed = result.max_score, True


def failure_message(report) -> str:
    """The exception's message without pytest's reinterpretation of the assert."""
    crash = getattr(report.longrepr, "reprcrash", None)
    text = crash.message if crash is not None else str(report.longrepr)
    return text.split("\nassert ")[0].strip()


def grader_dir(week: str, root: Path | None = None) -> Path:
    """assignments/weekNN under the current directory, else next to the rtpy package."""
    for base in [root] if root else [Path.cwd(), Path(__file__).resolve().parents[2]]:
        path = base / "assignments" / f"week{week}"
        if path.is_dir():
            return path
    raise FileNotFoundError(f"assignments/week{week}: not found in {Path.cwd()} or beside rtpy")


def run_graders(folder: Path, extra_args: tuple[str, ...] = ()) -> PointsPlugin:
    """Run (or with "--collect-only", collect) the graders of a week's folder in this
    process; the plugin holds their results. The hidden checks (the folder's hidden/,
    in rtpy's own repository only) are the autograder's: they are left out."""
    import pytest

    plugin = PointsPlugin()
    pytest.main(
        # quiet: the score table shows each failure's message (pytest on the folder
        # shows the tracebacks)
        [
            str(folder),
            "-qq",
            "-p",
            "no:cacheprovider",
            "--tb=no",
            "-o",
            "addopts=",
            "--ignore",
            str(folder / "hidden"),
            *extra_args,
        ],  # fmt: skip
        plugins=[plugin],
    )
    return plugin


def collect_graders(week: str, root: Path | None = None) -> list[GraderResult]:
    """The week's graders with their points and tasks, collected without running them
    (pytest's list of them is not printed)."""
    with contextlib.redirect_stdout(io.StringIO()):
        plugin = run_graders(grader_dir(week, root), ("--collect-only",))
    return list(plugin.results.values())


def gradescope_tests(graders: list[GraderResult], week_map) -> list[dict]:
    """Gradescope's test entries, in the order of the week's tasks: numbered task.test
    ("5.1.1") and named "<task title>: <test>". Graders of a task the map does not
    have (or without a map) come last, named and numbered by themselves."""
    tasks = {t.id: t for t in week_map.tasks} if week_map is not None else {}
    order = list(tasks)
    graders = sorted(graders, key=lambda g: order.index(g.task) if g.task in tasks else len(order))
    tests, counts = [], {}
    for g in graders:
        test = {"name": g.name}
        task = tasks.get(g.task)
        if task is not None:
            counts[task.id] = counts.get(task.id, 0) + 1
            test = {"name": f"{task.title}: {g.name}", "number": f"{task.number}.{counts[task.id]}"}
        test.update(
            score=g.score,
            max_score=g.max_score,
            status="passed" if g.passed else "failed",
            output=g.output,
        )
        tests.append(test)
    return tests


def grade(week: str, extra_args: tuple[str, ...] = (), root: Path | None = None) -> dict:
    """Run week's graders in this process; the Gradescope results dictionary."""
    from .tasks import TASKS_FILE, load_week

    folder = grader_dir(week, root)
    start = time.perf_counter()
    plugin = run_graders(folder, extra_args)
    week_map = load_week(folder) if (folder / TASKS_FILE).is_file() else None
    tests = gradescope_tests(list(plugin.results.values()), week_map)
    results = {
        "score": sum(t["score"] for t in tests),
        "max_score": sum(t["max_score"] for t in tests),
        "execution_time": round(time.perf_counter() - start, 2),
        "tests": tests,
    }
    if plugin.errors or not tests:
        # Gradescope shows the top-level output; the score is 0, not 0 of 0.
        results["score"] = 0
        results["output"] = "The graders could not be loaded (is rtpy importable?):\n" + (
            "\n".join(plugin.errors) or f"no tests found in {folder}"
        )
    return results


def score_table(results: dict) -> str:
    """The results as a table: each task's line with its subtotal, then its tests with
    the output of those that failed (a 0-point extension test shows passed/failed)."""
    if "output" in results:
        return results["output"]
    groups: dict[str, list[dict]] = {}
    for t in results["tests"]:
        groups.setdefault(t.get("number", "").rpartition(".")[0], []).append(t)
    rows = []  # (indent, label, points, output)
    for number, tests in groups.items():
        if number:
            title = tests[0]["name"].partition(": ")[0]
            got, most = sum(t["score"] for t in tests), sum(t["max_score"] for t in tests)
            rows.append((0, f"{number} {title}", f"{got:g}/{most:g}", ""))
        for t in tests:
            label = f"{t['number']} {t['name'].partition(': ')[2]}" if number else t["name"]
            pts = f"{t['score']:g}/{t['max_score']:g}" if t["max_score"] else t["status"]
            rows.append((4 if number else 0, label, pts, t["output"]))
    width = max([indent + len(label) for indent, label, _, _ in rows] + [4])
    lines = [f"{'task / test':<{width}}  points", "-" * (width + 8)]
    for indent, label, pts, output in rows:
        lines.append(f"{' ' * indent}{label:<{width - indent}}  {pts}")
        lines.extend(f"{' ' * (indent + 4)}{line}" for line in output.splitlines()[:6])
    lines.append("-" * (width + 8))
    lines.append(f"{'total':<{width}}  {results['score']:g}/{results['max_score']:g}")
    return "\n".join(lines)


def write_json(results: dict, path: str | Path) -> None:
    text = json.dumps(results, indent=2) + "\n"
    atomic_write(path, lambda tmp: tmp.write_text(text))
