"""Grading the weekly assignments: points per task, the verdicts graders share (a
noise-aware comparison of renders with a reference), and `grade()`, the local run.

A grader is a pytest test in `assignments/weekNN/` marked with its points and the task
of the week's task map (`assignments/weekNN/tasks.toml`, rtpy.grading.tasks) it grades.
It is a probe and a verdict: it asks the student's code for plain data through the
`probe` fixture (the probes are in rtpy/grading/probes.py and the week's probes.py)
and asserts on the answer, in the judge's process (rtpy.grading.judge):

    from rtpy.grading import points

    @points(3, task="05.1")
    def test_point_light_sample(probe):
        \"\"\"unit direction, distance, radiance I / d^2\"\"\"   # shown after the task's title
        got = probe.point_light_sample(cases=cases)
        assert ok, "PointLight.sample (rtpy/light.py): ... what is wrong, what to do"

A parametrized grader whose cases grade different tasks marks each case instead:
`pytest.param("phong", marks=points(2, task="08.1"))`. A test scores all its points
when it passes and none when it fails; its output is the assertion's message (or the
student's exception, such as the NotImplementedError of a stub).

Renders are compared by `assert_render_matches`: R renders with different seeds are
cut into 8 x 8 pixel blocks and each block mean is compared with a stored reference
(rendered by rtpy's solution, `assignments/weekNN/reference/*.npz`) by a z-test
whose variance is bounded by the reference's noise (each pixel's per-sample
variance, measured when the reference was made: the renders' own counts only
between it and NOISE_CAP times it), Bonferroni-corrected over blocks and channels:
a correct renderer rarely fails (at the rates docs/instructors.md states), while a
missing 1/pdf, a light counted twice, a missing 1/r^2 or an estimator far noisier
than the reference's (even one right on average) moves block means by many of the
reference's sigmas.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ..testing.statistics import BlockTest, block_z_test

ALPHA = 1e-3
# A render's own noise counts, pixel by pixel, between the reference's and this many
# times it: never narrower than the reference's (a correct renderer's sample variance
# from R = 4 renders is often below its true value), and never wide enough to excuse
# an estimator far noisier than the reference's (measured: docs/instructors.md).
NOISE_CAP = 4.0
PROBES_FILE = "probes.py"  # assignments/weekNN/probes.py: the week's probes
# Where a local run (grade()) draws the failed chi-square checks; None elsewhere (the
# autograder, plain pytest): the message then says how to get the picture.
PICTURES: Path | None = None
PICTURES_FOLDER = "rtpy-checks"
HIDDEN = "hidden"  # assignments/weekNN/hidden/: the checks only the autograder holds


def points(n: float, task: str | None = None):
    """Mark: the test (or a parametrized case) is worth n points toward `task`, the id
    of a task in the week's task map ("05.1")."""
    import pytest

    return pytest.mark.points(n, task=task)


# (grader file name, test function) -> the tasks whose methods its scene uses
SCENE_TASKS: dict[tuple[str, str], tuple[str, ...]] = {}


def scene_uses(*tasks: str):
    """Decorator of a grader that renders: besides its own task's, its scene uses the
    methods of these tasks (ids of the week's map). When it fails, its feedback names
    the failed graders of those tasks and of its own, and no others
    (rtpy.grading.results)."""

    def register(function):
        SCENE_TASKS[(Path(function.__code__.co_filename).name, function.__name__)] = tasks
        return function

    return register


def scene_tasks(nodeid: str) -> tuple[str, ...]:
    """The tasks registered with scene_uses for a test's node id (none if unregistered)."""
    file, _, rest = nodeid.partition("::")
    return SCENE_TASKS.get((Path(file).name, rest.partition("[")[0]), ())


# --- render comparison ----------------------------------------------------------------
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
    (rtpy.testing.statistics.block_z_test): for two renders of equal standing."""
    return block_z_test(
        graded["mean"],
        graded["s2"] / float(graded["samples"]),
        reference["mean"],
        reference["s2"] / float(reference["samples"]),
        alpha,
    )


def compare_with_reference(stack: np.ndarray, spp: int, reference: dict, alpha: float = ALPHA):
    """z-test of the block means of R renders at spp against the reference, the noise
    of each side from the reference's per-sample variance: the renders' own variance
    counts pixel by pixel only between the reference's and NOISE_CAP times it, so
    that a correct render's rare bright paths widen the test a little where they
    fall, and a noisier estimator cannot widen it further (BlockTest)."""
    stack = np.asarray(stack, dtype=np.float64)
    s2 = reference["s2"]
    own = stack.var(axis=0, ddof=1) * spp
    graded = np.clip(own, s2, NOISE_CAP * s2)
    return block_z_test(
        stack.mean(axis=0),
        graded / float(spp * len(stack)),
        reference["mean"],
        s2 / float(reference["samples"]),
        alpha,
    )


def load_reference(path: str | Path) -> dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


def save_reference(path: str | Path, summary: dict[str, np.ndarray]) -> None:
    np.savez_compressed(path, **summary)


def reference_summary(probe, scene: str, render: dict, reference: dict) -> dict:
    """What a render grader stores as its reference: the summary of renders of the
    probes' scene `scene` with the grader's `render` settings, at reference["spp"]
    with the seeds reference["seeds"] (made with rtpy's solution behind `probe`)."""
    spp = reference["spp"]
    settings = dict(render, spp=spp)
    return summarize(
        probe.render(scene=scene, seeds=list(reference["seeds"]), settings=settings), spp
    )


def assert_render_matches(stack: np.ndarray, spp: int, reference: dict, what: str) -> None:
    """AssertionError naming the worst block unless the renders agree with the reference
    (and have its shape, and only finite, non-negative pixels). The noise allowed is
    bounded by the reference's (compare_with_reference), whatever the renders' own
    spread: a noisier estimator fails, and is told so."""
    stack = np.asarray(stack, dtype=np.float64)
    want = reference["mean"].shape
    assert stack.ndim == 4 and stack.shape[1:] == want, (
        f"{what}: the renders have the shape {stack.shape[1:]}, expected {want}"
    )
    assert np.isfinite(stack).all() and (stack >= 0).all(), (
        f"{what}: some pixels are negative, infinite or NaN"
    )
    result = compare_with_reference(stack, spp, reference)
    if result.passed:
        return
    spread = noise_ratio(stack, spp, reference)
    noisy = (
        f" Its renders are {spread:.3g} times as noisy as the reference's: an estimator "
        "right on average but far noisier (a weight that is huge where it should be "
        "small, a missing sample of the light) fails too."
        if spread > 2.0
        else ""
    )
    assert result.passed, f"{what}: {result.worst()}.{noisy}"


def noise_ratio(stack: np.ndarray, spp: int, reference: dict) -> float:
    """How many times the reference's standard deviation the renders spread, over the
    whole image (only for the message: the verdict never uses it)."""
    if len(stack) < 2:
        return 1.0
    own = float(stack.var(axis=0, ddof=1).sum()) * spp
    return float(np.sqrt(own / max(float(reference["s2"].sum()), 1e-300)))


def assert_renders_match(probe, scene: str, seeds, render: dict, reference, what: str) -> None:
    """Renders of the probes' scene `scene`, one per seed with the `render` settings,
    agree with the reference summary stored at the path `reference`
    (assert_render_matches)."""
    stack = probe.render(scene=scene, seeds=list(seeds), settings=render)
    assert_render_matches(stack, render["spp"], load_reference(reference), what)


def assert_image_matches(
    image: np.ndarray, reference: np.ndarray, what: str, hint: str, rtol: float, atol: float
) -> None:
    """For deterministic renders: at most 1 % of the pixels may differ from the
    reference beyond rtol/atol (a pixel centre exactly on an edge may round either
    way); otherwise an AssertionError naming the first wrong pixel and `hint`."""
    assert image.shape == reference.shape, (
        f"{what}: the image has the shape {image.shape}, expected {reference.shape}"
    )
    wrong = ~np.isclose(image, reference, rtol=rtol, atol=atol).all(axis=2)
    if wrong.mean() <= 0.01:
        return
    row, column = np.argwhere(wrong)[0]
    raise AssertionError(
        f"{what}: {wrong.sum()} of {wrong.size} pixels differ from the reference "
        f"(first at row {row}, column {column}): {hint}"
    )


def chi2_picture_note(result, incident_deg: float, subject, name: str, what: str, week: str) -> str:
    """What a failed chi-square grader adds to its message: the picture of the check it
    drew (rtpy.testing.chi_square_picture) in a local run, else how to get one.
    name: the file's name (no suffix); what: the method checked, for the title."""
    if PICTURES is None:
        return (
            f" To see this check as a picture, run `python -m rtpy grade {week}` in your "
            f"repository: it draws it in {PICTURES_FOLDER}/{name}.png."
        )
    from ..testing.chi_square_picture import chi2_picture

    path = PICTURES / f"{name}.png"
    try:
        chi2_picture(result, path, incident_deg, subject=subject, title=what)
    except OSError as err:
        return f" (The picture of this check could not be written to {path}: {err.strerror}.)"
    return f" Picture of this check: {path.as_posix()}"


# --- running graders here -------------------------------------------------------------
def grader_dir(week: str, root: Path | None = None) -> Path:
    """assignments/weekNN under the current directory, else next to the rtpy package."""
    for base in [root] if root else [Path.cwd(), Path(__file__).resolve().parents[2]]:
        path = base / "assignments" / f"week{week}"
        if path.is_dir():
            return path
    raise FileNotFoundError(f"assignments/week{week}: not found in {Path.cwd()} or beside rtpy")


def child_config(folder: Path, work: Path, task_functions: list[dict] | None = None) -> dict:
    """What the student's process needs: the week's probe module (inside work)."""
    probes = folder / PROBES_FILE
    rel = probes.resolve().relative_to(folder.parents[1].resolve())
    config = {"probe_modules": [str(work / rel)] if probes.is_file() else []}
    if task_functions is not None:
        config["task_functions"] = task_functions
        config["task_files"] = sorted({t["path"] for t in task_functions})
    return config


def local_runner(folder: Path, in_process: bool = False):
    """The process that answers the probes of a local run: a child process in the
    repository of `folder` (assignments/weekNN), or this process."""
    from .sandbox import Child, InProcess
    from .tasks import TASKS_FILE, load_week, method_file

    repo = folder.parents[1].resolve()
    functions = None
    if (folder / TASKS_FILE).is_file():
        methods = [m for task in load_week(folder).tasks for m in task.methods]
        functions = []
        for name in methods:
            path, function = method_file(name, repo)
            functions.append({"path": path, "function": function})
    config = child_config(folder, repo, functions)
    return InProcess(config, repo) if in_process else Child(repo, config)


def run_graders(folder: Path, paths: list[str], runner=None, collect_only: bool = False):
    """The Judge after running (or collecting) the graders at paths."""
    from .judge import Judge, judge, probe_registry

    probes = folder / PROBES_FILE
    registry = probe_registry([probes] if probes.is_file() else [])
    plugin = Judge(runner, registry, collect_only=collect_only)
    try:
        return judge(plugin, paths)
    finally:
        if runner is not None:
            runner.stop()


def collect_graders(week: str, root: Path | None = None) -> list:
    """The week's graders (rtpy.grading.judge.Graded) with their points and tasks,
    collected without running them (not the hidden checks)."""
    folder = grader_dir(week, root)
    paths = [str(p) for p in sorted(folder.glob("test_*.py"))]
    return list(run_graders(folder, paths, collect_only=True).tests.values())


def grade(
    week: str, root: Path | None = None, in_process: bool = False, hidden: bool = False
) -> dict:
    """Run week's graders here, the student's code in a child process (or, for rtpy's
    own tests, in_process); the results dictionary (rtpy.grading.results). The hidden
    checks (the folder's hidden/, in rtpy's own repository only) are the autograder's:
    they run only with hidden=True. A failed chi-square grader draws its picture in
    PICTURES_FOLDER of the current directory."""
    from .results import gradescope_results
    from .tasks import TASKS_FILE, load_week

    global PICTURES
    folder = grader_dir(week, root)
    start = time.perf_counter()
    paths = [str(p) for p in sorted(folder.glob("test_*.py"))]
    if hidden:
        paths += [str(p) for p in sorted((folder / HIDDEN).glob("test_*.py"))]
    PICTURES = Path(PICTURES_FOLDER)  # relative: the student's own folder, named as such
    try:
        plugin = run_graders(folder, paths, local_runner(folder, in_process))
    finally:
        PICTURES = None
    week_map = load_week(folder) if (folder / TASKS_FILE).is_file() else None
    results = gradescope_results(list(plugin.tests.values()), week_map)
    results["execution_time"] = round(time.perf_counter() - start, 2)
    if plugin.errors or not plugin.tests:
        # Gradescope shows the top-level output; the score is 0, not 0 of 0.
        results["score"] = 0
        results["output"] = "The graders could not be loaded (is rtpy importable?):\n" + (
            "\n".join(plugin.errors) or f"no tests found in {folder}"
        )
    return results


def local_probe(week: str, root: Path | None = None, in_process: bool = True):
    """The `probe` of week's graders outside pytest, answered in this process (or a
    child): for making references and for rtpy's own tests of the graders."""
    from .judge import probe_registry, probes_outside_pytest

    folder = grader_dir(week, root)
    probes = folder / PROBES_FILE
    registry = probe_registry([probes] if probes.is_file() else [])
    return probes_outside_pytest(local_runner(folder, in_process), registry)
