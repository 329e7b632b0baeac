"""`assignment make`, `assignment autograder` and `grade`: the week is ASCII digits of a
known week, the outputs are checked before any work, a failing write is one line."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rtpy.grading.assignment as assignment
import rtpy.grading.autograder as autograder
import rtpy.grading.graders as graders
import rtpy.grading.results as results_module
from rtpy.cli.main import main
from rtpy.grading.assignment import WEEKS, AssignmentError, check_week


@settings(max_examples=150)
@given(
    week=st.one_of(
        st.text(max_size=50),
        st.integers(-10, 20).map(str),
        st.from_regex(r"\A0{0,5}[0-9]{1,2}\Z"),
        st.sampled_from(WEEKS),
    )
)
def test_a_week_is_ascii_digits_of_a_known_week_or_one_line_listing_them(week):
    known = week.isascii() and week.isdigit() and int(week) in {int(w) for w in WEEKS}
    try:
        text = check_week(week)
    except AssignmentError as e:
        assert len(str(e).splitlines()) == 1 and str(e).endswith(", ".join(WEEKS))
        assert not known
        return
    assert known and int(text) == int(week) and text in WEEKS


@pytest.mark.parametrize("week", ["³", "٥", "０５", "5" * 5000, "+5", " 5", "5\n"])
@pytest.mark.parametrize("command", [["grade"], ["assignment", "make"]])
def test_a_week_that_is_not_ascii_digits_exits_2_in_one_line(tmp_path, capsys, command, week):
    argv = [*command, week] + ([str(tmp_path / "out")] if "make" in command else [])
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("rtpy: error: week ") and len(err.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


@pytest.fixture
def no_grading(monkeypatch):
    """grade() replaced by a result at once (the graders are tested elsewhere); the
    weeks it was asked for."""
    asked = []

    def grade(week, *args, **kwargs):
        asked.append(week)
        return {"score": 1.0, "max_score": 1.0, "tests": [{"name": "t", "status": "passed"}]}

    monkeypatch.setattr(graders, "grade", grade)
    monkeypatch.setattr(results_module, "score_table", lambda results: "table")
    return asked


def test_grade_json_that_cannot_be_written_is_refused_before_grading(tmp_path, capsys, no_grading):
    (tmp_path / "file").write_text("")
    assert main(["grade", "05", "--json", str(tmp_path / "file" / "results.json")]) == 2
    assert no_grading == []
    err = capsys.readouterr().err
    assert "is not a directory" in err and len(err.splitlines()) == 1
    assert main(["grade", "5", "--json", str(tmp_path / "results.json")]) == 0
    assert no_grading == ["05"]
    assert json.loads((tmp_path / "results.json").read_text())["score"] == 1.0


def full_disk(tmp: Path) -> None:
    """What a write does when the disk fills half-way."""
    tmp.write_bytes(b"half")
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_grade_json_on_a_full_disk_is_one_line_and_keeps_the_old_file(
    tmp_path, capsys, monkeypatch, no_grading
):
    out = tmp_path / "results.json"
    out.write_text("old")
    real = results_module.atomic_write
    monkeypatch.setattr(results_module, "atomic_write", lambda path, write: real(path, full_disk))
    assert main(["grade", "05", "--json", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == f"rtpy: error: cannot write '{out}': {os.strerror(errno.ENOSPC)}\n"
    assert out.read_text() == "old" and list(tmp_path.iterdir()) == [out]


def test_assignment_make_on_a_full_disk_is_one_line_exit_1_and_writes_nothing(
    tmp_path, capsys, monkeypatch
):
    def write_repository(root, week, dest):
        full_disk(dest / "README.md")

    source = tmp_path / "source"
    (source / "assignments" / "week05").mkdir(parents=True)
    monkeypatch.setattr(assignment, "source_root", lambda command: source)
    monkeypatch.setattr(assignment, "_write_repository", write_repository)
    out = tmp_path / "week05"
    assert main(["assignment", "make", "05", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == f"rtpy: error: cannot write '{out}': {os.strerror(errno.ENOSPC)}\n"
    assert list(tmp_path.iterdir()) == [source]


def test_an_autograder_that_cannot_be_written_is_refused_before_any_work(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.setattr(autograder, "source_root", lambda command: pytest.fail("work started"))
    (tmp_path / "a_dir.zip").mkdir()
    assert main(["assignment", "autograder", "05", str(tmp_path / "a_dir.zip")]) == 2
    err = capsys.readouterr().err
    assert "existing directory" in err and len(err.splitlines()) == 1
    assert [p.name for p in tmp_path.iterdir()] == ["a_dir.zip"]
