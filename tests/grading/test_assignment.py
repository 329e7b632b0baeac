"""Student repositories generated from the solution regions (rtpy.grading.assignment).

What is checked, for every week 03-08, in a repository written by
`python -m rtpy assignment make WEEK OUT` (one subprocess per week, with the
repository's own rtpy first on the path):

- every grader of that week fails (score 0), each with the NotImplementedError of a
  stub that names the week's task — proof that the graders can fail;
- with that week's solutions put back (what a student who did every task has), the
  graders give full marks with the code the repository ships as given (for week 05:
  light counted once by the given MIS around the student's light sampling), and every
  scene of the week's render list renders;
- the rtpy tests shipped there pass: each test file runs in the first week it ships
  in (where the most code around it is stubbed; later weeks stub less, and a file
  ships only when it executes no stubbed region), so every shipped file is run once;
- no solution line of that week or a later one is left in the repository, every
  earlier week's solution is, and the numpy backend's solution code is absent.

`assignments/test_weeks.toml` decides which tests ship (see rtpy/grading/assignment.py).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import tomllib
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import pytest

from rtpy.cli.main import main
from rtpy.grading.assignment import (
    ANSWER_MODULES,
    INSTRUCTOR_MODULES,
    NUMPY_USE,
    TEST_WEEKS_FILE,
    WEEKS,
    AssignmentError,
    find_regions,
    make_assignment,
    map_tests,
    never_mapped,
    regions_in,
    rewrite,
    shipped_tests,
    student_pytest_options,
    weeks_of_tests,
)

ROOT = Path(__file__).resolve().parents[2]


def first_shipped(week: str) -> list[str]:
    """The test files that ship in `week` and in no earlier week."""
    earlier = {p for w in WEEKS if int(w) < int(week) for p in shipped_tests(ROOT, w)[0]}
    kept = shipped_tests(ROOT, week)[0]
    return [p for p in kept if Path(p).name.startswith("test_") and p not in earlier]


DRIVER = """
import json, sys
import pytest
from rtpy.grading import grade
results = grade(sys.argv[1])
shipped = sys.argv[2:]
# -m "": every shipped test, the slow ones too (the repository's default leaves them out)
status = pytest.main(["-q", "-p", "no:cacheprovider", "-m", "", *shipped]) if shipped else 0
print(json.dumps({"grade": results, "shipped": int(status)}))
"""


def test_every_week_has_regions_inside_functions():
    regions = find_regions(ROOT)
    assert {r.week for r in regions} == set(WEEKS)
    for r in regions:
        assert r.function and r.message, r
        assert r.end > r.begin + 1, f"{r.path}:{r.begin + 1}: empty region"


def test_every_test_file_is_mapped():
    """assignments/test_weeks.toml covers every test file (a new test file needs
    `python -m rtpy assignment map-tests`, or it would ship to weeks it fails in)."""
    mapped = set(weeks_of_tests(ROOT))
    for path in (ROOT / "tests").rglob("test_*.py"):
        rel = path.relative_to(ROOT).as_posix()
        if never_mapped(rel):
            continue
        if NUMPY_USE.search(path.read_text()):
            continue  # uses the numpy backend: never ships
        assert rel in mapped, f"{rel} is not in assignments/test_weeks.toml: run map-tests"


def test_unbalanced_markers_are_refused(tmp_path):
    (tmp_path / "rtpy").mkdir()
    bad = tmp_path / "rtpy" / "bad.py"
    bad.write_text("def f():\n    # BEGIN SOLUTION week05: x\n    return 1\n")
    with pytest.raises(AssignmentError, match="without END"):
        regions_in(bad, tmp_path)
    bad.write_text("x = 1\n# BEGIN SOLUTION week05: x\nx = 2\n# END SOLUTION\n")
    with pytest.raises(AssignmentError, match="inside a function"):
        regions_in(bad, tmp_path)


def test_the_known_weeks_are_the_assignment_folders():
    folders = sorted(p.name[4:] for p in (ROOT / "assignments").glob("week[0-9][0-9]"))
    assert list(WEEKS) == folders


def test_bad_week_and_non_empty_output_are_refused(tmp_path, capsys):
    assert main(["assignment", "make", "09", str(tmp_path / "out")]) == 2
    assert "expected one of 03" in capsys.readouterr().err
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("")
    assert main(["assignment", "make", "05", str(tmp_path / "full")]) == 2
    assert "not an empty directory" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full"]  # nothing half-written


def test_student_pytest_options_refuse_a_pyproject_without_them(tmp_path):
    """The student repository's pyproject.toml gets its pytest options by replacing
    rtpy's; a pyproject where one is missing is refused, not silently left as it is."""
    pyproject = tmp_path / "pyproject.toml"
    pyproject.write_text('[tool.pytest.ini_options]\ntestpaths = ["tests"]\naddopts = "-ra"\n')
    with pytest.raises(AssignmentError, match="addopts"):
        student_pytest_options(pyproject)


def check_regions(repo: Path, week: str) -> None:
    """Week `week` and later: the region's code is gone and a stub naming the week's
    task and the function stands in its place. Earlier weeks: the code is there."""
    for r in find_regions(ROOT):
        block = "".join((ROOT / r.path).read_text().splitlines(keepends=True)[r.begin + 1 : r.end])
        text = (repo / r.path).read_text()
        if int(r.week) >= int(week):
            assert block not in text, f"{r.path}: {r.function}: week {r.week} solution shipped"
            assert f'"week{r.week} task: {r.function}:' in text, (
                f"{r.path}: no stub for {r.function}"
            )
        else:
            assert block in text, f"{r.path}: {r.function}: week {r.week} solution missing"


# make_assignment reads the process's umask by setting it: one at a time
MAKING = threading.Lock()


def check_student_repository(tmp_path: Path, week: str) -> None:
    """The week's repository as the module's docstring says, its files under tmp_path."""
    with MAKING:
        repo = make_assignment(week, tmp_path / f"week{week}")
    check_regions(repo, week)
    assert not (repo / "rtpy" / "numpy_backend" / "scene.py").exists()
    assert "MIT License" in (repo / "LICENSE").read_text()  # MIT asks for it in copies
    with open(repo / "pyproject.toml", "rb") as f:  # pip install needs every listed package
        tool = tomllib.load(f)["tool"]
    setup, options = tool["setuptools"], tool["pytest"]["ini_options"]
    assert options["testpaths"] == ["tests", "assignments"]
    assert "-m 'not slow'" in options["addopts"]  # the student's everyday loop
    assert 'python -m pytest -m ""' in (repo / "README.md").read_text()  # and everything
    for package in setup["packages"]:
        folder = setup["package-dir"].get(package, package.replace(".", "/"))
        assert (repo / folder).is_dir() and any((repo / folder).iterdir()), package
    assert (repo / "assignments" / f"week{week}" / "README.md").exists()
    assert (repo / "assignments" / f"week{week}" / "tasks.toml").exists()  # grade() reads it
    kept, left = shipped_tests(ROOT, week)
    assert sorted(str(p.relative_to(repo)) for p in (repo / "tests").rglob("*.py")) == kept
    assert left and all(not (repo / p).exists() for p in left)

    report, proc = run_driver(repo, DRIVER, week, *first_shipped(week))
    tests = report["grade"]["tests"]
    assert len(tests) >= 5
    for t in tests:
        assert t["score"] == 0, f"week {week}: {t['name']} passes on the stubs"
        assert "NotImplementedError" in t["output"] and f"week{week} task" in t["output"], t
    assert report["shipped"] == 0, f"week {week}: shipped tests failed:\n{proc.stdout[-3000:]}"

    solve(repo, week)
    scenes = [
        str(p.relative_to(repo))
        for p in (repo / "assignments" / f"week{week}").glob("scenes/*.toml")
    ]
    report, proc = run_driver(repo, SOLVED_DRIVER, week, str(tmp_path / "render.png"), *scenes)
    graded = report["grade"]
    assert graded["score"] == graded["max_score"] > 0, f"week {week} solved: {graded}"
    assert all(t["status"] == "passed" for t in graded["tests"]), graded
    assert scenes and report["renders"] == [0] * len(scenes), (scenes, proc.stderr[-3000:])


def side_by_side(request, test_name: str, check, tmp_path_factory) -> Iterator[dict]:
    """Generator of a module fixture: week -> the Future of check(folder, week) for the
    weeks of `test_name` selected. The weeks run side by side, one per core (each is
    a chain of subprocesses); each week's test takes its own outcome, so a failure is
    reported on that week's test."""
    weeks = [
        item.callspec.params["week"]
        for item in request.session.items
        if item.originalname == test_name
    ]
    pool = ThreadPoolExecutor(max(1, min(len(weeks), os.cpu_count() or 1)))
    try:
        yield {w: pool.submit(check, tmp_path_factory.mktemp(f"week{w}-"), w) for w in weeks}
    finally:
        pool.shutdown(cancel_futures=True)


@pytest.fixture(scope="module")
def checked_repositories(request, tmp_path_factory):
    yield from side_by_side(
        request, "test_student_repository", check_student_repository, tmp_path_factory
    )


@pytest.mark.slow
@pytest.mark.parametrize("week", WEEKS)
def test_student_repository(checked_repositories: dict[str, Future], week):
    checked_repositories[week].result()


def run_driver(repo: Path, driver: str, *args: str) -> tuple[dict, subprocess.CompletedProcess]:
    """Run a driver script in the repository with its own rtpy first on the path: the
    JSON report it prints last, and the process."""
    proc = subprocess.run(
        [sys.executable, "-c", driver, *args],
        cwd=repo,
        env=dict(os.environ, PYTHONPATH=str(repo)),
        capture_output=True,
        text=True,
        timeout=600,
    )
    return json.loads(proc.stdout.strip().splitlines()[-1]), proc


SOLVED_DRIVER = """
import json, sys
from rtpy.grading import grade
from rtpy.cli.main import main
results = grade(sys.argv[1])
out = sys.argv[2]
renders = [main(["render", s, "--width", "16", "--spp", "1", "--max-depth", "3", "-o", out])
           for s in sys.argv[3:]]
print(json.dumps({"grade": results, "renders": renders}))
"""


def solve(repo: Path, week: str) -> None:
    """Put week's solution regions back into its repository (later weeks stay stubs)."""
    for path in sorted((ROOT / "rtpy").rglob("*.py")):
        rel = path.relative_to(ROOT)
        if rel.parts[1] != "numpy_backend" and any(r.week == week for r in regions_in(path, ROOT)):
            text = rewrite(path, ROOT, lambda r: r.stub() if int(r.week) > int(week) else None)
            (repo / rel).write_text(text)


@pytest.mark.slow
def test_map_tests_of_some_files_records_their_weeks_and_keeps_the_rest(tmp_path):
    """map-tests FILES runs only those files on the instrumented copy: their entries
    are replaced by the weeks they execute, every other entry is kept."""
    (tmp_path / "rtpy").mkdir()
    (tmp_path / "rtpy" / "__init__.py").write_text("from __future__ import annotations\n")
    (tmp_path / "rtpy" / "shade.py").write_text(
        "def twice(x):\n    # BEGIN SOLUTION week05: twice\n    return 2 * x\n    # END SOLUTION\n"
    )
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "test_shade.py").write_text(
        "from rtpy.shade import twice\n\n\ndef test_twice():\n    assert twice(2) == 4\n"
    )
    (tmp_path / "tests" / "test_other.py").write_text("def test_nothing():\n    assert True\n")
    (tmp_path / "assignments").mkdir()
    (tmp_path / TEST_WEEKS_FILE).write_text(
        '[tests]\n"tests/test_other.py" = [7]\n"tests/test_shade.py" = [3]\n'
    )
    weeks = map_tests(tmp_path, files=("tests/test_shade.py",))
    assert weeks == {"tests/test_other.py": {"07"}, "tests/test_shade.py": {"05"}}
    on_disk = weeks_of_tests(tmp_path)
    assert on_disk == {"tests/test_other.py": ["07"], "tests/test_shade.py": ["05"]}
    # The numpy backend's tests are never mapped (the backend is withheld), also
    # when named: nothing runs and the table stays as it was.
    before = (tmp_path / TEST_WEEKS_FILE).read_text()
    weeks = map_tests(tmp_path, files=("tests/numpy_backend/test_sampling.py",))
    assert weeks == {"tests/test_other.py": {"07"}, "tests/test_shade.py": {"05"}}
    assert (tmp_path / TEST_WEEKS_FILE).read_text() == before


# Every module of the repository's rtpy imported there: none needs a withheld one.
IMPORT_ALL = """
import pkgutil, importlib, rtpy
names = [m.name for m in pkgutil.walk_packages(rtpy.__path__, "rtpy.")]
names = [n for n in names if n != "rtpy.__main__"]  # importing it runs the CLI
for name in names:
    importlib.import_module(name)
print(len(names))
"""


@pytest.mark.slow
def test_a_student_repository_holds_no_authoring_or_packaging(tmp_path):
    """Week 08's repository: none of INSTRUCTOR_MODULES, nothing shipped that names
    them, no `assignment` in `python -m rtpy`, and `rtpy grade 08` grading there."""
    with MAKING:
        repo = make_assignment("08", tmp_path / "week08")
    for rel in INSTRUCTOR_MODULES + ANSWER_MODULES:
        assert (ROOT / rel).exists() and not (repo / rel).exists(), rel

    def rtpy_there(*args: str) -> subprocess.CompletedProcess:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        return subprocess.run(
            [sys.executable, *args],
            cwd=repo,
            env=dict(env, PYTHONPATH=str(repo)),
            capture_output=True,
            text=True,
            timeout=300,
        )

    imported = rtpy_there("-c", IMPORT_ALL)
    assert imported.returncode == 0 and int(imported.stdout) > 50, imported.stderr
    usage = rtpy_there("-m", "rtpy", "--help")
    assert usage.returncode == 0 and "grade" in usage.stdout, usage.stderr
    assert "assignment" not in usage.stdout
    assert (
        rtpy_there("-m", "rtpy", "assignment", "make", "08", "out").returncode == 2
    )  # no such command
    graded = rtpy_there("-m", "rtpy", "grade", "08", "--json", str(tmp_path / "results.json"))
    results = json.loads((tmp_path / "results.json").read_text())
    assert graded.returncode == 1, graded.stderr  # the stubs fail every grader
    assert len(results["tests"]) >= 5 and results["score"] == 0
    assert "NotImplementedError" in graded.stdout and "week08 task" in graded.stdout
