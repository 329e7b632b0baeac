"""`assignment make` and `assignment autograder`: the week is ASCII digits of a known
week, the outputs are checked before any work, a failing write is one line."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest

import rtpy.grading.assignment as assignment
import rtpy.grading.autograder as autograder
from rtpy.cli.main import main


@pytest.mark.parametrize("week", ["³", "٥", "０５", "5" * 5000, "+5", " 5", "5\n"])
def test_a_week_that_is_not_ascii_digits_exits_2_in_one_line(tmp_path, capsys, week):
    argv = ["assignment", "make", week, str(tmp_path / "out")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("rtpy: error: week ") and len(err.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def full_disk(tmp: Path) -> None:
    """What a write does when the disk fills half-way."""
    tmp.write_bytes(b"half")
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


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
