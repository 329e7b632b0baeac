"""What run_autograder takes from a submission (rtpy.grading.autograder_submission):
the task files only, found in a folder, a zip or one folder down; a file that cannot
be used is named with the reason."""

from __future__ import annotations

import shutil
import zipfile
from pathlib import Path

import pytest

from rtpy.grading.autograder_submission import (
    SubmissionError,
    compile_errors,
    find_repository,
    ignored_changes,
    import_problem,
    take_task_files,
    unpack,
)
from rtpy.grading.sandbox import Child

ROOT = Path(__file__).resolve().parents[2]

TASKS = ["rtpy/light.py", "rtpy/scene.py"]


def repository(base: Path, light: str = "LIGHT = 1\n") -> Path:
    (base / "rtpy").mkdir(parents=True)
    (base / "rtpy" / "__init__.py").write_text("from . import light, scene\n")
    (base / "rtpy" / "light.py").write_text(light)
    (base / "rtpy" / "scene.py").write_text("SCENE = 2\n")
    (base / "rtpy" / "other.py").write_text("OTHER = 3\n")
    return base


def test_the_repository_may_be_one_folder_down(tmp_path):
    repository(tmp_path / "student-week05-main")
    (tmp_path / "notes").mkdir()
    assert find_repository(tmp_path, TASKS) == tmp_path / "student-week05-main"
    assert find_repository(tmp_path / "notes", TASKS) is None


def test_a_zip_is_unpacked_without_escaping_its_folder(tmp_path):
    sub = tmp_path / "submission"
    sub.mkdir()
    with zipfile.ZipFile(sub / "week05.zip", "w") as z:
        z.writestr("repo/rtpy/light.py", "LIGHT = 1\n")
        z.writestr("../escape.py", "x = 1\n")
        z.writestr("/abs.py", "x = 1\n")
    base = unpack(sub, tmp_path / "scratch")
    assert (base / "repo" / "rtpy" / "light.py").read_text() == "LIGHT = 1\n"
    assert not (tmp_path / "scratch" / "escape.py").exists()
    assert not (tmp_path / "escape.py").exists() and not Path("/abs.py").exists()
    (sub / "week05.zip").write_text("not a zip")
    with pytest.raises(SubmissionError, match="week05.zip: not a zip file"):
        unpack(sub, tmp_path / "scratch2")


def test_only_task_files_are_taken_and_missing_ones_named(tmp_path):
    sub = repository(tmp_path / "sub")
    (sub / "rtpy" / "scene.py").unlink()
    work = repository(tmp_path / "work", light="STUB = 0\n")
    (sub / "rtpy" / "other.py").write_text("OTHER = 'changed'\n")
    taken = take_task_files(sub, TASKS, work)
    assert taken.files == ["rtpy/light.py"]
    assert taken.problems == {"rtpy/scene.py": "not in your submission"}
    assert (work / "rtpy" / "light.py").read_text() == "LIGHT = 1\n"
    assert (work / "rtpy" / "other.py").read_text() == "OTHER = 3\n"  # not a task file
    assert ignored_changes(sub, work, TASKS) == ["rtpy/other.py"]


def test_loose_files_are_found_by_name_and_binary_ones_refused(tmp_path):
    sub = tmp_path / "sub"
    sub.mkdir()
    (sub / "light.py").write_text("LIGHT = 5\n")
    (sub / "scene.py").write_bytes(b"\xff\xfe\x00binary")
    work = repository(tmp_path / "work")
    taken = take_task_files(sub, TASKS, work)
    assert taken.files == ["rtpy/light.py"] and "taken from light.py" in taken.notes[0]
    assert taken.problems == {"rtpy/scene.py": "not a UTF-8 text file"}


def test_a_syntax_error_is_named_with_its_line(tmp_path):
    repository(tmp_path, light="def sample(p):\n    return p +\n")
    assert compile_errors(tmp_path, TASKS) == {
        "rtpy/light.py": "line 2: SyntaxError: invalid syntax: return p +"
    }


def broken_copy(base: Path, light: str) -> Path:
    """rtpy's own source with light.py replaced, for the sandboxed child to import."""
    shutil.copytree(ROOT / "rtpy", base / "rtpy", ignore=shutil.ignore_patterns("__pycache__"))
    (base / "rtpy" / "light.py").write_text(light)
    return base


def checker(work: Path, timeout: float) -> Child:
    return Child(work, {"task_files": TASKS}, start_timeout=timeout)


@pytest.mark.slow
def test_an_import_that_fails_or_hangs_blames_the_file_and_line(tmp_path):
    work = broken_copy(tmp_path / "a", "import math\nLIGHT = 1 / 0\n")
    assert import_problem(checker(work, 30), TASKS, work) == (
        "rtpy/light.py",
        "line 2: ZeroDivisionError: division by zero",
    )
    work = broken_copy(tmp_path / "b", "while True:\n    pass\n")
    # a limit well above a loaded machine's import of the package, so that only the
    # hang can be the file blamed
    rel, message = import_problem(checker(work, 6), TASKS, work)
    assert rel == "rtpy/light.py" and "importing it did not finish within 6 s" in message
    work = broken_copy(tmp_path / "c", (ROOT / "rtpy" / "light.py").read_text())
    assert import_problem(checker(work, 30), TASKS, work) is None


def test_a_symlinked_task_file_is_refused(tmp_path):
    """A task file that is a symbolic link (to any file of the machine) is not read."""
    submission = repository(tmp_path / "submission")
    (submission / "rtpy" / "light.py").unlink()
    (submission / "rtpy" / "light.py").symlink_to("/etc/passwd")
    work = repository(tmp_path / "work")
    taken = take_task_files(submission, TASKS, work)
    refused = "a symbolic link, not a file: submit the file itself"
    assert taken.problems == {"rtpy/light.py": refused}
    assert (work / "rtpy" / "light.py").read_text() == "LIGHT = 1\n"  # the stub stays
    assert taken.files == ["rtpy/scene.py"]


def test_a_file_too_much_for_the_compiler_costs_only_itself(tmp_path):
    """A file whose compiling exhausts the compiler's recursion (and would take the
    judge with it if compiled there) is named; the other file compiles."""
    repository(tmp_path, light="x = " + "+".join(["1"] * 300_000) + "\n")
    assert compile_errors(tmp_path, TASKS) == {
        "rtpy/light.py": "cannot be compiled: the file is too large or too deeply nested "
        "for Python's compiler"
    }


def test_paths_the_child_prints_are_text_never_looked_up(tmp_path):
    """A traceback line naming a symbolic link loop in the child's folders (the
    student's to make) is read as text: blamed when it lies in the work copy, else
    ignored, and never resolved."""
    work = repository(tmp_path / "work")
    loop = tmp_path / "home" / "loop"
    loop.parent.mkdir()
    loop.symlink_to(loop)
    text = (
        "Traceback (most recent call last):\n"
        f'  File "{loop}/rtpy/light.py", line 3, in <module>\n'
        f'  File "{work}/rtpy/../rtpy/light.py", line 2, in <module>\n'
        "ZeroDivisionError: division by zero\n"
    )

    class Printed:  # a child that failed to start and printed `text`
        config: dict = {}
        start_timeout = 1.0

        def call(self, *args):
            from rtpy.grading.sandbox import ChildFailure

            raise ChildFailure("the grading process ended with exit status 3")

        def output(self):
            return text

        def stop(self):
            pass

    assert import_problem(Printed(), TASKS, work) == (
        "rtpy/light.py",
        "line 2: ZeroDivisionError: division by zero",
    )
