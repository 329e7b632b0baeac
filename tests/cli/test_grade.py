"""`grade WEEK`: the week is ASCII digits of a known week, a results file is checked
before any grading, a failing write is one line."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest

import rtpy.grading.graders as graders
import rtpy.grading.results as results_module
from rtpy.cli.main import main


@pytest.mark.parametrize("week", ["³", "٥", "０５", "5" * 5000, "+5", " 5", "5\n"])
def test_a_week_that_is_not_ascii_digits_exits_2_in_one_line(tmp_path, capsys, week):
    argv = ["grade", week, "--json", str(tmp_path / "out")]
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
