"""The Gradescope autograder (rtpy.grading.autograder), run as Gradescope runs it.

For every week 03-08 the zip from `python -m rtpy assignment autograder` is unpacked
into a temporary AUTOGRADER_ROOT and its run_autograder is run on submissions made
from the week's student repository (the slow tier):

- untouched: score 0;
- tampered: the graders, grading code, material checks, tests and references edited
  so that local grading gives full marks (shown): the same results as untouched;
- the reference solution's task files: full marks, twice, with different seeds;
- broken: the reference with a syntax error in one task file, an endless loop in a
  task method of another and a missing return in a third: a results.json in time
  naming each file (and the method of the loop and of the None).

The tampered, second reference and broken submissions test the autograder's own code,
which is the same for every week: they run on weeks 05 and 08 (the first week of
lights and the last, whose graders render), the others check untouched and reference.

test_week_05_end_to_end stays in the fast tier.
"""

from __future__ import annotations

import ast
import functools
import json
import os
import shutil
import stat
import subprocess
import sys
import time
from concurrent.futures import Future
from pathlib import Path

import pytest

from rtpy.cli.main import main
from rtpy.grading.assignment import WEEKS, make_assignment
from rtpy.grading.autograder import build_autograder, extract, task_files, task_regions

from .test_assignment import MAKING, side_by_side

ROOT = Path(__file__).resolve().parents[2]
# As root the autograder runs the student's code only as an unprivileged user, who must
# be able to run the judge's Python (.ci/run makes one: RTPY_SANDBOX_PYTHON); this
# machine's default Python may live where other users cannot reach it.
ROOT_USER = hasattr(os, "geteuid") and os.geteuid() == 0
JUDGE_PYTHON = os.environ.get("RTPY_SANDBOX_PYTHON", "") if ROOT_USER else sys.executable
needs_judge_python = pytest.mark.skipif(
    not JUDGE_PYTHON, reason="as root, set RTPY_SANDBOX_PYTHON to a Python every user can run"
)
TEST_TIMEOUT = 2  # seconds per test in the broken runs (an endless loop costs this much)
TOTAL_TIMEOUT = 240
EVERY_SUBMISSION = ("05", "08")  # the weeks checked on all four submissions


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """week -> (its autograder zip, its untouched student repository), made once, one
    at a time (MAKING)."""
    cache: dict[str, tuple[Path, Path]] = {}

    def get(week: str) -> tuple[Path, Path]:
        with MAKING:
            if week not in cache:
                folder = tmp_path_factory.mktemp(f"week{week}")
                zip_path = build_autograder(week, folder / f"week{week}.zip")
                cache[week] = zip_path, make_assignment(week, folder / "student")
            return cache[week]

    return get


def run_autograder(zip_path: Path, submission: Path, tmp: Path, **env) -> tuple[dict, float]:
    """Gradescope's layout under tmp, run_autograder run on it: (results, seconds)."""
    root = tmp / "autograder"
    if root.exists():
        shutil.rmtree(root)
    extract(zip_path, root / "source")
    shutil.copytree(submission, root / "submission")
    variables = dict(os.environ, AUTOGRADER_ROOT=str(root), PYTHON=JUDGE_PYTHON or sys.executable)
    variables.update({k: str(v) for k, v in env.items()})
    start = time.monotonic()
    proc = subprocess.run(
        [str(root / "source" / "run_autograder")],
        env=variables, capture_output=True, text=True, timeout=TOTAL_TIMEOUT + 120,
    )  # fmt: skip
    seconds = time.monotonic() - start
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads((root / "results" / "results.json").read_text()), seconds


def copy_repository(repo: Path, dest: Path) -> Path:
    shutil.copytree(repo, dest)
    return dest


def with_reference(repo: Path, dest: Path, week: str) -> Path:
    """The student repository with the reference solution's task files (rtpy's own)."""
    copy_repository(repo, dest)
    for rel in task_files(week, ROOT):
        shutil.copyfile(ROOT / rel, dest / rel)
    return dest


def summary(results: dict) -> list[tuple[str, float, str]]:
    return [(t["name"], t["score"], t["output"]) for t in results["tests"]]


# --- tampering ------------------------------------------------------------------------
def tamper(repo: Path, week: str) -> list[str]:
    """Edit what decides the score so that local grading passes everything; the files
    changed."""
    changed = []

    def edit(rel: str, old: str, new: str) -> None:
        path = repo / rel
        text = path.read_text()
        assert old in text, f"{rel}: {old!r} not there to tamper with"
        path.write_text(text.replace(old, new))
        changed.append(rel)

    edit(
        "rtpy/grading/judge.py",
        "graded.outcome = Outcome(False, self.message(call, report, item.nodeid), renders)",
        "graded.outcome = Outcome(True, '', renders)",
    )
    edit("rtpy/grading/protocol.py", "    return schema.check(value, where)", "    return value")
    checks = repo / "rtpy" / "testing" / "material_checks.py"
    checks.write_text(checks.read_text() + PASSING_CHECKS)
    changed.append("rtpy/testing/material_checks.py")
    graders = repo / "assignments" / f"week{week}" / f"test_week{week}.py"
    tree = ast.parse(graders.read_text())
    names = [n.name for n in tree.body if isinstance(n, ast.FunctionDef) and n.name[:5] == "test_"]
    graders.write_text("".join(f"def {name}(probe):\n    pass\n\n\n" for name in names))
    changed.append(graders.relative_to(repo).as_posix())
    for reference in (repo / "assignments" / f"week{week}" / "reference").iterdir():
        reference.write_bytes(b"tampered")
        changed.append(reference.relative_to(repo).as_posix())
    shutil.rmtree(repo / "tests")
    return changed


PASSING_CHECKS = """

_check_weights = check_weights


def check_weights(*args, **kwargs):
    result = _check_weights(*args, **kwargs)
    result.passed = True
    return result
"""
LOCAL_GRADE = """
import json, sys
from rtpy.grading import grade
r = grade(sys.argv[1])
print(json.dumps([r["score"], r["max_score"]]))
"""


# --- planting faults ------------------------------------------------------------------
# week -> (the task method that loses its last return, the one that loops forever, the
# task file with a syntax error): three files, and methods the graders call directly.
FAULTS = {
    "03": ("Camera._ray_through", "flat_color", "rtpy/interval.py"),
    "04": ("Quad._coords", "Scene.find_intersection", "rtpy/sphere.py"),
    "05": ("Lambertian.BRDF", "Scene.find_occlusion", "rtpy/light.py"),
    "06": ("schlick", "Mirror.scattering", "rtpy/vec3.py"),
    "07": ("Quad.surface_uv", "Metal.scattering", "rtpy/sphere.py"),
    "08": (
        "PathIntegrator.compute_scattering",
        "BlinnPhong.BRDF",
        "rtpy/materials/cook_torrance.py",
    ),
}


def plant_faults(repo: Path, week: str) -> dict[str, tuple[str, str]]:
    """FAULTS[week] planted in the reference; {fault: (file, function)}."""
    none_function, loop_function, syntax_file = FAULTS[week]
    region = {r.function: r for r in task_regions(week, ROOT)}
    none_region, loop_region = region[none_function], region[loop_function]
    lines = (repo / none_region.path).read_text().splitlines(keepends=True)
    last = max(i for i in range(none_region.begin, none_region.end) if "return " in lines[i])
    lines[last] = lines[last].replace("return ", "_ = ", 1)  # the result is never returned
    (repo / none_region.path).write_text("".join(lines))
    lines = (repo / loop_region.path).read_text().splitlines(keepends=True)
    indent = loop_region.indent
    lines.insert(loop_region.begin + 1, f"{indent}while True:\n{indent}    pass\n")
    (repo / loop_region.path).write_text("".join(lines))
    path = repo / syntax_file
    path.write_text(path.read_text() + "\nbroken = (1 +\n")
    return {
        "none": (none_region.path.as_posix(), none_function),
        "loop": (loop_region.path.as_posix(), loop_function),
        "syntax": (syntax_file, ""),
    }


# --- the tests ------------------------------------------------------------------------
def check_week(built, tmp_path: Path, week: str) -> None:
    """The autograder of `week` on the untouched, tampered, reference and broken
    submissions (see the module's docstring), its files under tmp_path."""
    zip_path, student = built(week)

    untouched, _ = run_autograder(zip_path, student, tmp_path)
    assert untouched["score"] == 0 and len(untouched["tests"]) >= 5
    hidden = [t for t in untouched["tests"] if t["visibility"] == "after_due_date"]
    assert hidden and all(t["status"] == "failed" for t in untouched["tests"])

    reference = with_reference(student, tmp_path / "reference", week)
    first, _ = run_autograder(zip_path, reference, tmp_path)
    total = sum(t["max_score"] for t in first["tests"])
    failed = [(t["name"], t["output"]) for t in first["tests"] if t["status"] != "passed"]
    assert first["score"] == total and not failed, failed
    if week not in EVERY_SUBMISSION:
        return

    tampered_repo = copy_repository(student, tmp_path / "tampered")
    changed = tamper(tampered_repo, week)
    proc = subprocess.run(
        [sys.executable, "-c", LOCAL_GRADE, week], cwd=tampered_repo, capture_output=True,
        text=True, env=dict(os.environ, PYTHONPATH=str(tampered_repo)), timeout=300,
    )  # fmt: skip
    score, max_score = json.loads(proc.stdout.splitlines()[-1])
    assert score == max_score > 0, "the tampering does not fool local grading"
    tampered, _ = run_autograder(zip_path, tampered_repo, tmp_path)
    assert summary(tampered) == summary(untouched)
    assert "Changes outside the task files are not graded" in tampered["output"]
    assert "rtpy/grading/judge.py" in tampered["output"]
    assert changed

    second, _ = run_autograder(zip_path, reference, tmp_path)
    failed = [(t["name"], t["output"]) for t in second["tests"] if t["status"] != "passed"]
    assert second["score"] == total and not failed, failed
    assert first["extra_data"]["seed"] != second["extra_data"]["seed"]

    broken = with_reference(student, tmp_path / "broken", week)
    faults = plant_faults(broken, week)
    results, seconds = run_autograder(
        zip_path, broken, tmp_path,
        RTPY_AUTOGRADER_TEST_TIMEOUT=TEST_TIMEOUT, RTPY_AUTOGRADER_TOTAL_TIMEOUT=TOTAL_TIMEOUT,
    )  # fmt: skip
    assert seconds < TOTAL_TIMEOUT + 60
    outputs = "\n".join(t["output"] for t in results["tests"])
    syntax_file = faults["syntax"][0]
    assert f"{syntax_file}: line " in results["output"] and "SyntaxError" in results["output"]
    loop_file, loop_function = faults["loop"]
    assert f"it was in {loop_function} ({loop_file}, line" in outputs, outputs
    none_file, none_function = faults["none"]
    assert f"{none_function} ({none_file}) returned None" in outputs, outputs


@pytest.fixture(scope="module")
def checked_weeks(request, built, tmp_path_factory):
    check = functools.partial(check_week, built)
    yield from side_by_side(request, "test_the_autograder_of_every_week", check, tmp_path_factory)


@needs_judge_python
@pytest.mark.slow
@pytest.mark.parametrize("week", WEEKS)
def test_the_autograder_of_every_week(checked_weeks: dict[str, Future], week):
    checked_weeks[week].result()


@needs_judge_python
@pytest.mark.slow
def test_week_05_end_to_end(built, tmp_path):
    """A syntax error in light.py: its tests score 0 and say why, the other tests are
    still scored, and the hidden checks are reported for after the due date."""
    zip_path, student = built("05")
    submission = with_reference(student, tmp_path / "submission", "05")
    light = submission / "rtpy" / "light.py"
    light.write_text(light.read_text() + "\ndef broken(:\n")
    results, _ = run_autograder(zip_path, submission, tmp_path)
    tests = {t["name"].split(":")[0]: t for t in results["tests"]}
    assert "rtpy/light.py: line" in results["output"] and "SyntaxError" in results["output"]
    assert tests["Point light"]["score"] == 0
    assert tests["Point light"]["output"].startswith("rtpy/light.py was not used (line")
    assert tests["Shadow rays"]["score"] == tests["Shadow rays"]["max_score"] > 0
    hidden = [t for t in results["tests"] if t["visibility"] == "after_due_date"]
    assert len(hidden) == 2 and all(t["max_score"] > 0 for t in hidden)


def test_the_zip_holds_what_gradescope_needs(built, tmp_path):
    zip_path, _ = built("05")
    source = extract(zip_path, tmp_path / "source")
    for script in ("setup.sh", "run_autograder"):
        assert os.access(source / script, os.X_OK), script
        shell = "bash" if script.endswith(".sh") else "sh"
        assert subprocess.run([shell, "-n", str(source / script)]).returncode == 0  # syntax
    requirements = (source / "requirements.txt").read_text().split()
    assert {r.split(">")[0] for r in requirements} == {"numpy", "pillow", "tqdm", "pytest"}
    config = json.loads((source / "autograder.json").read_text())
    assert config["task_files"] == task_files("05", ROOT)
    assert "useradd" in (source / "setup.sh").read_text()  # the sandbox's user
    repo = source / "repo"
    assert (repo / "assignments" / "week05" / "hidden" / "test_week05_hidden.py").exists()
    assert not (repo / "tests").exists() and not (repo / "docs").exists()
    stub = (repo / "rtpy" / "light.py").read_text()
    assert '"week05 task: PointLight.sample:' in stub  # the stub, not the solution


@pytest.mark.parametrize(
    "args, message",
    [
        (["09", "x.zip"], "expected one of 03"),
        (["05", "x.txt"], "is a .zip file"),
        (["05", "missing/x.zip"], "does not exist"),
        (["05", "x.zip", "--test-timeout", "0"], "expected seconds above 0"),
    ],
)
def test_bad_arguments_are_refused_in_one_line(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    try:
        status = main(["assignment", "autograder", *args])
    except SystemExit as exit:  # argparse's errors
        status = exit.code
    assert status == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert message in err[-1]  # argparse puts its usage lines first
    assert list(tmp_path.iterdir()) == []  # nothing written


# --- the student repository, for the autograder -----------------------------------------
def test_student_repository_is_fit_for_students(built, tmp_path):
    """No hidden checks, normal permissions, and --backend numpy refused in one line
    (exit 2, nothing written)."""
    _, student = built("05")
    assert not (student / "assignments" / "week05" / "hidden").exists()
    umask = os.umask(0o022)
    os.umask(umask)
    assert stat.S_IMODE(student.stat().st_mode) == 0o777 & ~umask
    proc = subprocess.run(
        [sys.executable, "-m", "rtpy", "render", "week05_point_light", "--backend", "numpy",
         "-o", str(tmp_path / "out.png")],
        cwd=student, env=dict(os.environ, PYTHONPATH=str(student)), capture_output=True,
        text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 2 and not (tmp_path / "out.png").exists()
    assert proc.stderr.strip().count("\n") == 0 and "withheld" in proc.stderr


def test_assignments_need_a_source_checkout(tmp_path, capsys, monkeypatch):
    """An installed rtpy without its repository: one line, exit 2."""
    import rtpy.grading.assignment as assignment

    monkeypatch.setattr(
        assignment, "__file__", str(tmp_path / "site" / "rtpy" / "grading" / "a.py")
    )
    monkeypatch.chdir(tmp_path)
    assert main(["assignment", "make", "05", str(tmp_path / "out")]) == 2
    assert main(["assignment", "autograder", "05", str(tmp_path / "out.zip")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and all("needs rtpy's source checkout" in line for line in err)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.mark.skipif(not ROOT_USER, reason="the autograder as root")
def test_as_root_a_students_code_never_runs_as_root(built, tmp_path):
    """A judge's Python that no unprivileged user can run (a Python under /root, when
    /root is closed to others): the autograder refuses to grade, score 0, rather than
    run the student's code as root. The Python is this one reached through a folder
    closed to others, whatever the permissions of the folders it lives in, so the
    judge's own sys.executable (which starts the children) is closed too."""
    zip_path, student = built("05")
    root = tmp_path / "closed"
    root.mkdir()
    os.chmod(root, 0o700)
    (root / "env").symlink_to(sys.prefix, target_is_directory=True)  # a venv stays one
    python = root / "env" / Path(sys.executable).relative_to(sys.prefix)
    results = run_autograder(zip_path, student, tmp_path, PYTHON=str(python))[0]
    assert results["score"] == 0 and results["tests"] == []
    assert "only as an unprivileged user" in results["output"]


# --- one honest mistake ----------------------------------------------------------------
TYPOS = {  # a line appended to the reference's rtpy/light.py (week 05)
    "fails at import": "import rtpy_no_such_module\n",
    "hangs at import": "while True:\n    pass\n",
    "overwhelms the compiler": "x = " + "+".join(["1"] * 300_000) + "\n",
    "ends the process silently": "import os\nos._exit(3)\n",  # no line to blame: found
}


def shown(results: dict) -> str:
    return "\n".join([results["output"], *(t["output"] for t in results["tests"])])


@needs_judge_python
@pytest.mark.slow
@pytest.mark.parametrize("typo", list(TYPOS))
def test_a_typo_costs_only_its_files_tasks(built, tmp_path, typo):
    """The reference with one bad line in rtpy/light.py scores what its other files
    earn: the same as with light.py left as the stub, more than 0; the file is named
    and the judge's folders are not."""
    zip_path, student = built("05")
    stubbed = with_reference(student, tmp_path / "stubbed", "05")
    shutil.copyfile(student / "rtpy" / "light.py", stubbed / "rtpy" / "light.py")
    expected, _ = run_autograder(zip_path, stubbed, tmp_path)
    assert 0 < expected["score"] < expected["max_score"]
    broken = with_reference(student, tmp_path / "broken", "05")
    light = broken / "rtpy" / "light.py"
    light.write_text(light.read_text() + TYPOS[typo])
    results, _ = run_autograder(
        zip_path, broken, tmp_path, RTPY_AUTOGRADER_IMPORT_TIMEOUT=8,
        RTPY_AUTOGRADER_TOTAL_TIMEOUT=TOTAL_TIMEOUT,
    )  # fmt: skip
    assert results["score"] == expected["score"], results["output"]
    assert "rtpy/light.py: " in results["output"]
    assert "rtpy-judge-" not in shown(results)


@needs_judge_python
@pytest.mark.slow
@pytest.mark.skipif(not ROOT_USER, reason="the sandbox's user exists only as root")
def test_a_private_temporary_folder_costs_no_marks(built, tmp_path):
    """TMPDIR closed to the sandbox's user (0700): the judge makes its folder where that
    user can reach it, and the reference scores full marks."""
    zip_path, student = built("05")
    private = tmp_path / "private"
    private.mkdir(mode=0o700)
    reference = with_reference(student, tmp_path / "reference", "05")
    results, _ = run_autograder(zip_path, reference, tmp_path, TMPDIR=str(private))
    assert results["score"] == results.get("max_score") > 0, results["output"]
    assert list(private.iterdir()) == []
