"""What run_autograder takes from a submission (rtpy.grading.autograder_submission):
the task files only, found in a folder, a zip or one folder down; a file that cannot
be used is named with the reason."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from rtpy.grading.autograder_submission import (
    SubmissionError,
    compile_errors,
    find_repository,
    ignored_changes,
    import_problem,
    suspicious_lines,
    take_task_files,
    unpack,
)

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


@pytest.mark.slow
def test_an_import_that_fails_or_hangs_blames_the_file_and_line(tmp_path):
    work = repository(tmp_path / "a", light="import math\nLIGHT = 1 / 0\n")
    assert import_problem(work, TASKS, timeout=30) == (
        "rtpy/light.py",
        "line 2: ZeroDivisionError: division by zero",
    )
    work = repository(tmp_path / "b", light="while True:\n    pass\n")
    rel, message = import_problem(work, TASKS, timeout=1)
    assert rel == "rtpy/light.py" and "importing it did not finish within 1 s" in message
    assert import_problem(repository(tmp_path / "c"), TASKS, timeout=30) is None


def test_lines_that_could_tamper_with_grading_are_listed_for_the_instructor(tmp_path):
    light = "import math\nimport rtpy.grading.graders as g  # patch\nx = eval('1')\n# exec it\n"
    repository(tmp_path, light=light)
    assert suspicious_lines(tmp_path, TASKS) == [
        "rtpy/light.py:2: import rtpy.grading.graders as g  # patch",
        "rtpy/light.py:3: x = eval('1')",
    ]
