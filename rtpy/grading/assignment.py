"""Weekly assignment repositories, generated from rtpy's own source.

The reference solutions live in rtpy itself, marked as regions inside method bodies
(the way nbgrader and otter-grader mark them):

    def sample(self, p):
        \"\"\"docstring (kept: it is the student's specification)\"\"\"
        # BEGIN SOLUTION week05: direction, distance and radiance I / d^2 seen from p
        ...the reference code...
        # END SOLUTION

The markers are comments, so rtpy runs unchanged. `make_assignment(week, out)` writes
the student repository of that week: all of rtpy with the solution regions of that
week and of every later week replaced by

        # TODO(week05): direction, distance and radiance I / d^2 seen from p
        raise NotImplementedError("week05 task: PointLight.sample ...")

(a later week's region is withheld too: it would hand out that week's answer, and
several of them contain this week's, such as the diffuse part of the week-8 models,
which is Lambertian's BRDF, or the path loop, which contains the direct integrator),
the bundled scenes, docs/, `assignments/weekNN/` (README, task map, graders, scenes,
reference data) and the tests of rtpy that can pass there.

Which tests ship is decided by `assignments/test_weeks.toml`: for each test file,
the weeks whose solution regions it executes, as recorded by running the suite on
an instrumented copy of rtpy (`python -m rtpy assignment map-tests`). A file ships
in week W's repository only when all those weeks are before W (otherwise it would
fail on the stubs); files not listed run no region and always ship.

The numpy backend is withheld from every student repository: its vectorized twins
mirror the solutions of weeks 03-08 (camera rays, intersections, point lights,
textures, the Phong, Blinn-Phong and Cook-Torrance kernels, the path integrator). In
its place the repository holds a stub whose render raises an error that says so; the
scalar backend renders everything, a student's own materials included.
"""

from __future__ import annotations

import ast
import io
import json
import os
import re
import shutil
import tempfile
import textwrap
import tokenize
import tomllib
from dataclasses import dataclass
from pathlib import Path

from .student_readme import student_rtpy_readme, workflow_section
from .tasks import task_numbers
from .weeks import WEEKS, AssignmentError, check_week

__all__ = ["WEEKS", "AssignmentError", "check_week", "make_assignment", "map_tests"]
BEGIN = re.compile(r"^(?P<indent>[ \t]*)# BEGIN SOLUTION week(?P<week>\d\d)(?::\s*(?P<msg>.*))?$")
END = re.compile(r"^[ \t]*# END SOLUTION\s*$")

# What the student repository holds besides rtpy/ (top-level names of the source tree).
COPIED = ("pyproject.toml", ".gitignore", "LICENSE", "scenes", "docs")
TEST_WEEKS_FILE = "assignments/test_weeks.toml"
# Tests of rtpy's own repository only (not mapped): the assignment machinery's (they grade
# every week, make repositories, check task maps and pages), the README's and the layout's.
MACHINERY_TESTS = (
    "tests/docs/test_pages.py",
    "tests/test_layout.py",
    "tests/cli/test_assignment.py",
)  # and tests/grading/*
# Withheld from a student's repository: the instructor's modules (authoring, packaging), and
# engine modules holding a week's answer and their tests (the engine does without them).
INSTRUCTOR_MODULES = (
    "rtpy/grading/assignment.py",
    "rtpy/grading/autograder.py",
    "rtpy/grading/student_readme.py",
    "rtpy/grading/task_pages.py",
    "rtpy/cli/assignment.py",
)
ANSWER_MODULES = ("rtpy/engine/sphere_hits.py",)
ANSWER_TESTS = ("tests/engine/test_sphere_hits.py", "tests/engine/test_prepared_scene.py")
# A test file that uses the numpy backend (withheld from student repositories).
NUMPY_USE = re.compile(r"numpy_backend|[\"']numpy[\"']|rtpy\.BACKENDS")


def machinery(rel: str) -> bool:
    """A test file of the assignment machinery (rtpy's own repository only)."""
    return rel.startswith("tests/grading/") or rel in MACHINERY_TESTS


def never_mapped(rel: str) -> bool:
    """Test files no week ships nor maps: the withheld modules' and the machinery's."""
    return rel.startswith("tests/numpy_backend/") or rel in ANSWER_TESTS or machinery(rel)


NUMPY_STUB = '''"""The numpy backend is withheld from the weekly assignment repositories: its
vectorized twins contain the solutions. Render with the scalar backend (the default)."""

WITHHELD = "{message}"
'''
NUMPY_RENDER_STUB = '''"""Withheld: see rtpy/numpy_backend/__init__.py."""


class NumpyBackend:
    def __init__(self, *args, **kwargs) -> None:
        raise NotImplementedError("{message}")
'''
WITHHELD_MESSAGE = (
    "the numpy backend is withheld from the week {week} assignment repository (its "
    "vectorized code contains the solutions); render with the scalar backend (the default)"
)
HIDDEN_FOLDER = "hidden"  # assignments/weekNN/hidden/: checks only the autograder holds


@dataclass(frozen=True)
class Region:
    """One solution region: lines [begin, end] (0-based, the marker lines included)."""

    path: Path  # relative to the source root
    begin: int
    end: int
    week: str
    message: str
    function: str  # qualified name of the enclosing function, e.g. "PointLight.sample"
    indent: str

    def stub(self, task: str | None = None) -> list[str]:
        """The lines that replace the region: a TODO and a NotImplementedError naming
        the week's task, its number (`task`, "8.1") and file, split to fit 100 columns
        (rtpy.engine.unfinished reads them back when a render reaches the stub)."""
        what = f"{self.function}: {self.message}" if self.message else self.function
        where = f"task {task}, {self.path.as_posix()}" if task else self.path.as_posix()
        text = f"week{self.week} task: {what} ({where}; see assignments/week{self.week}/README.md)"
        width = max(40, 92 - len(self.indent))
        parts = textwrap.wrap(text, width, drop_whitespace=False) or [text]
        return [
            f"{self.indent}# TODO(week{self.week}): {self.message or 'implement this'}\n",
            f"{self.indent}raise NotImplementedError(\n",
            *(f"{self.indent}    {json.dumps(part)}\n" for part in parts),
            f"{self.indent})\n",
        ]


def _enclosing_functions(source: str) -> list[tuple[int, int, str]]:
    """(first line, last line, qualified name) of every function, 1-based."""
    out = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                name = f"{prefix}{child.name}"
                if not isinstance(child, ast.ClassDef):
                    out.append((child.lineno, child.end_lineno or child.lineno, name))
                visit(child, f"{name}.")

    visit(ast.parse(source), "")
    return out


def _comment_lines(source: str) -> set[int]:
    """0-based numbers of the lines that hold only a comment."""
    tokens = tokenize.generate_tokens(io.StringIO(source).readline)
    return {t.start[0] - 1 for t in tokens if t.type == tokenize.COMMENT}


def regions_in(path: Path, root: Path) -> list[Region]:
    """The solution regions of one file; AssignmentError on unbalanced markers."""
    text = path.read_text()
    if "# BEGIN SOLUTION" not in text and "# END SOLUTION" not in text:
        return []  # no marker (most files): no need to tokenize
    lines = text.splitlines(keepends=True)
    functions = None
    regions, open_at = [], None
    rel = path.relative_to(root)
    comments = _comment_lines(text)
    for i, line in enumerate(lines):
        if i not in comments:
            continue  # marker text inside a string is not a marker
        m = BEGIN.match(line.rstrip("\n"))
        if m:
            if open_at is not None:
                raise AssignmentError(f"{rel}:{i + 1}: BEGIN SOLUTION inside another region")
            open_at = (i, m)
        elif END.match(line):
            if open_at is None:
                raise AssignmentError(f"{rel}:{i + 1}: END SOLUTION without BEGIN")
            begin, m = open_at
            if functions is None:
                functions = _enclosing_functions(text)
            inner = [f for f in functions if f[0] < begin + 1 <= f[1]]
            if not inner:
                raise AssignmentError(f"{rel}:{begin + 1}: a region must lie inside a function")
            function = max(inner, key=lambda f: f[0])[2]
            week = m.group("week")
            msg = (m.group("msg") or "").strip()
            regions.append(Region(rel, begin, i, week, msg, function, m.group("indent")))
            open_at = None
    if open_at is not None:
        raise AssignmentError(f"{rel}:{open_at[0] + 1}: BEGIN SOLUTION without END")
    return regions


def find_regions(root: Path) -> list[Region]:
    """Every solution region under root/rtpy, in file and line order."""
    root = Path(root)
    out = []
    for path in sorted((root / "rtpy").rglob("*.py")):
        out.extend(regions_in(path, root))
    return out


def withheld(region_week: str, week: str) -> bool:
    """Is a region of region_week replaced by a stub in week's repository?"""
    return int(region_week) >= int(week)


def rewrite(path: Path, root: Path, replace) -> str:
    """The file's text with every region r replaced by replace(r) (a list of lines,
    or None to keep the region as it is)."""
    lines = path.read_text().splitlines(keepends=True)
    for region in reversed(regions_in(path, root)):
        new = replace(region)
        if new is not None:
            lines[region.begin : region.end + 1] = new
    return "".join(lines)


def weeks_of_tests(root: Path) -> dict[str, list[str]]:
    """tests/... path -> the weeks whose solution regions that test file runs."""
    path = Path(root) / TEST_WEEKS_FILE
    if not path.exists():
        return {}
    with open(path, "rb") as f:
        table = tomllib.load(f).get("tests", {})
    return {k: [f"{int(w):02d}" for w in v] for k, v in table.items()}


def shipped_tests(root: Path, week: str) -> tuple[list[str], list[str]]:
    """(test files shipped in week's repository, test files left out), as tests/... paths.
    Tests of the numpy backend, and any test file that uses it (NUMPY_USE), are left
    out (the backend is withheld), and so are MACHINERY_TESTS."""
    mapping = weeks_of_tests(root)
    kept, left = [], []
    for path in sorted((Path(root) / "tests").rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        needs = mapping.get(rel, [])
        if (
            never_mapped(rel)
            or NUMPY_USE.search(path.read_text())
            or any(withheld(w, week) for w in needs)
        ):
            left.append(rel)
        else:
            kept.append(rel)
    return kept, left


# The student repository's pytest options: `python -m pytest` runs the graders too, and
# leaves out the slow tier (`python -m pytest -m ""` runs everything).
STUDENT_PYTEST_OPTIONS = {
    'testpaths = ["tests"]': 'testpaths = ["tests", "assignments"]',
    'addopts = "-ra --strict-markers"': "addopts = \"-ra --strict-markers -m 'not slow'\"",
}


def student_pytest_options(pyproject: Path) -> None:
    """Rewrite pyproject's pytest options as STUDENT_PYTEST_OPTIONS says; AssignmentError
    where an option to change is not there."""
    text = pyproject.read_text()
    for old, new in STUDENT_PYTEST_OPTIONS.items():
        if old not in text:
            raise AssignmentError(f"{pyproject.name}: no `{old}` to change for the students")
        text = text.replace(old, new)
    pyproject.write_text(text)


def source_root(command: str) -> Path:
    """The rtpy source checkout that assignments are made from: the one this rtpy is
    imported from, else the current directory; AssignmentError in one line when
    neither has assignments/ (an installed rtpy without its repository)."""
    for base in (Path(__file__).resolve().parents[2], Path.cwd()):
        if (base / "assignments").is_dir() and (base / "rtpy").is_dir():
            return base
    raise AssignmentError(
        f"{command} needs rtpy's source checkout (rtpy/ and assignments/): run it in a "
        "clone of rtpy's repository"
    )


def normal_permissions(path: Path) -> None:
    """Give a folder made by tempfile.mkdtemp (0700) the mode a new folder gets."""
    umask = os.umask(0o022)
    os.umask(umask)
    os.chmod(path, 0o777 & ~umask)


def make_assignment(week: str | int, out_dir: str | Path, root: str | Path | None = None) -> Path:
    """Write week's student repository to out_dir (which must not exist or be empty).
    Everything is written to a temporary directory next to it and renamed at the end,
    so a failure leaves nothing half-written."""
    week = check_week(week)
    root = Path(root) if root is not None else source_root("assignment make")
    out = Path(out_dir)
    src = root / "assignments" / f"week{week}"
    if not src.is_dir():
        raise AssignmentError(f"{src}: no such assignment folder")
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise AssignmentError(f"{out}: exists and is not an empty directory")
    if not out.parent.is_dir():
        raise AssignmentError(f"{out.parent}: no such directory")
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}-", dir=out.parent))
    try:
        normal_permissions(tmp)
        _write_repository(root, week, tmp)
        if out.exists():
            out.rmdir()
        os.replace(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out


def _write_repository(root: Path, week: str, dest: Path) -> None:
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info")
    # rtpy with the stubs, the numpy backend and the instructor's modules withheld
    numbers = task_numbers(root)  # (file, function) -> "8.1"

    def stub(r: Region) -> list[str] | None:
        return (
            r.stub(numbers.get((r.path.as_posix(), r.function))) if withheld(r.week, week) else None
        )

    for path in sorted((root / "rtpy").rglob("*.py")):
        rel = path.relative_to(root)
        if rel.parts[1] == "numpy_backend" or rel.as_posix() in INSTRUCTOR_MODULES + ANSWER_MODULES:
            continue
        target = dest / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(rewrite(path, root, stub))
    numpy_dir = root / "rtpy" / "numpy_backend"
    message = WITHHELD_MESSAGE.format(week=week)
    for package in sorted(numpy_dir.rglob("__init__.py")):  # pyproject lists every package
        stub = dest / package.relative_to(root)
        stub.parent.mkdir(parents=True, exist_ok=True)
        stub.write_text(NUMPY_STUB.replace("{message}", message))
    stub = dest / "rtpy" / "numpy_backend" / "renderer.py"
    stub.write_text(NUMPY_RENDER_STUB.replace("{message}", message))
    for name in COPIED:
        path = root / name
        if path.is_dir():
            shutil.copytree(path, dest / name, ignore=ignore)
        elif path.exists():
            shutil.copy2(path, dest / name)
    student_pytest_options(dest / "pyproject.toml")
    # the week's own folder without its hidden checks, and the tests that can pass
    shutil.copytree(
        root / "assignments" / f"week{week}",
        dest / "assignments" / f"week{week}",
        ignore=shutil.ignore_patterns("__pycache__", "*.pyc", HIDDEN_FOLDER),
    )
    kept, left = shipped_tests(root, week)
    for rel in kept:
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(root / rel, dest / rel)
    readme = (root / "assignments" / f"week{week}" / "README.md").read_text()
    task_files = sorted({r.path.as_posix() for r in find_regions(root) if r.week == week})
    left_out = [r for r in left if not machinery(r) and not r.endswith("__init__.py")]
    (dest / "README.md").write_text(readme + workflow_section(week, task_files, left_out))
    (dest / "rtpy-README.md").write_text(student_rtpy_readme((root / "README.md").read_text()))


# --- which tests need which weeks ---------------------------------------------------
REGION_LOG_MODULE = '''"""Instrumentation for map_tests: records which regions each test file runs.
A region's probe costs one dict lookup once its week is recorded for the current test
file; the plugin re-arms every week when a new file starts."""
import builtins
import os

CURRENT = [os.environ.get("RTPY_REGION_TEST", "?")]
armed = dict.fromkeys(("03", "04", "05", "06", "07", "08"), True)


def hit(week):
    armed[week] = False
    path = os.environ.get("RTPY_REGION_LOG")
    if path:
        with open(path, "a") as f:
            f.write(CURRENT[0] + "\\t" + week + "\\n")


builtins._rtpy_armed, builtins._rtpy_hit = armed, hit  # the probes' names
'''

REGION_LOG_PLUGIN = """import os

import rtpy._region_log as log


def pytest_runtest_setup(item):
    name = item.nodeid.split("::")[0]
    if name != log.CURRENT[0]:
        log.CURRENT[0] = name
        os.environ["RTPY_REGION_TEST"] = name  # for command-line subprocesses
        for week in log.armed:
            log.armed[week] = True
"""


def _write_instrumented_copy(root: Path, dest: Path) -> None:
    """rtpy, the tests and what they read, copied to dest with a probe before every
    solution region that records the week in the log of the test file running it."""
    for path in sorted((root / "rtpy").rglob("*.py")):
        target = dest / path.relative_to(root)
        target.parent.mkdir(parents=True, exist_ok=True)

        def record(r: Region) -> list[str]:
            lines = (root / r.path).read_text().splitlines(keepends=True)
            probe = f'{r.indent}_rtpy_armed["{r.week}"] and _rtpy_hit("{r.week}")\n'
            return [probe, *lines[r.begin : r.end + 1]]

        target.write_text(rewrite(path, root, record))
    (dest / "rtpy" / "_region_log.py").write_text(REGION_LOG_MODULE)
    init = dest / "rtpy" / "__init__.py"
    head = "from __future__ import annotations\n"
    init.write_text(init.read_text().replace(head, head + "from . import _region_log\n", 1))
    (dest / "region_log_plugin.py").write_text(REGION_LOG_PLUGIN)
    for name in (*COPIED, "tests", "README.md"):
        path = root / name
        if path.is_dir():
            shutil.copytree(path, dest / name, ignore=shutil.ignore_patterns("__pycache__"))
        elif path.exists():
            shutil.copy2(path, dest / name)


def map_tests(
    root: str | Path | None = None,
    pytest_args: tuple[str, ...] = (),
    files: tuple[str, ...] = (),
) -> dict[str, set[str]]:
    """Run rtpy's tests (the numpy backend's excepted) on a copy of the tree whose
    solution regions record each test file that runs them, also from worker and
    command-line subprocesses; returns {test file: the weeks it runs} and writes
    it to assignments/test_weeks.toml. With `files` (tests/... paths) only those
    run, and only their entries are replaced (the quick way after adding a file)."""
    import subprocess
    import sys

    root = Path(root) if root is not None else Path(__file__).resolve().parents[2]
    if files:  # the numpy backend's tests and the machinery's are never mapped
        given = [Path(f).as_posix() for f in files]
        files = tuple(f for f in given if not never_mapped(f))
        if not files:
            return {k: set(v) for k, v in weeks_of_tests(root).items()}
    with tempfile.TemporaryDirectory(prefix="rtpy-map-tests-") as tmp:
        dest = Path(tmp)
        _write_instrumented_copy(root, dest)
        log = dest / "regions.log"
        env = dict(os.environ, RTPY_REGION_LOG=str(log), PYTHONPATH=str(dest))
        subprocess.run(
            [
                sys.executable,
                "-m",
                "pytest",
                "-q",
                "-p",
                "region_log_plugin",
                "-p",
                "no:cacheprovider",
                "--ignore=tests/numpy_backend",
                "--ignore=tests/grading",
                *(f"--ignore={t}" for t in MACHINERY_TESTS),
                *pytest_args,
                *(files or ("tests",)),
            ],
            cwd=dest,
            env=env,
            check=False,
        )
        weeks: dict[str, set[str]] = {}
        if files:  # keep every other file's entry
            weeks = {k: set(v) for k, v in weeks_of_tests(root).items() if k not in files}
            weeks.update({Path(f).as_posix(): set() for f in files})
        for line in log.read_text().splitlines() if log.exists() else []:
            test, week = line.split("\t")
            if test.startswith("tests/"):
                weeks.setdefault(test, set()).add(week)
        for path in [] if files else sorted((root / "tests").rglob("test_*.py")):
            rel = path.relative_to(root).as_posix()
            if not never_mapped(rel):
                weeks.setdefault(rel, set())  # runs no region: ships every week
    body = "".join(
        f'"{k}" = [{", ".join(str(int(w)) for w in sorted(v))}]\n' for k, v in sorted(weeks.items())
    )
    (root / TEST_WEEKS_FILE).write_text(
        "# The weeks whose solution regions each test file runs, recorded by\n"
        "# `python -m rtpy assignment map-tests` (see rtpy/grading/assignment.py). A file ships\n"
        "# in week W's repository only if all its weeks are before W.\n[tests]\n" + body
    )
    return weeks
