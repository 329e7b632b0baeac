"""run_autograder (rtpy.grading.autograder_run) writes a results.json even when the
autograder itself cannot run; its runs on every week are tests/grading/test_autograder.py
and tests/grading/test_attacks.py, its results tests/grading/test_results.py."""

from __future__ import annotations

import json
import os
import subprocess
import sys


def test_a_broken_autograder_still_writes_results(tmp_path):
    """No source/autograder.json (a zip that is not an autograder): score 0, and the
    output says it is not the student's fault."""
    env = dict(os.environ, AUTOGRADER_ROOT=str(tmp_path))
    proc = subprocess.run(
        [sys.executable, "-c", "from rtpy.grading.autograder_run import main; main()"],
        env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0
    results = json.loads((tmp_path / "results" / "results.json").read_text())
    assert results["score"] == 0 and "not your code" in results["output"]


def test_as_root_it_says_what_it_creates_before_creating_it(tmp_path, monkeypatch, capsys):
    """A local run as root creates a system user and closes folders: it says so, in
    one line, before doing either (no user is made here: make_user is replaced)."""
    from rtpy.grading import autograder_run

    events = []

    def make_user(name: str) -> bool:
        events.append(("make", capsys.readouterr().out))  # what was said before
        return True

    monkeypatch.setattr(autograder_run.os, "geteuid", lambda: 0)
    monkeypatch.setattr(autograder_run, "make_user", make_user)
    monkeypatch.setattr(autograder_run, "close", lambda root: events.append(("close", "")))
    confined = autograder_run.isolation(tmp_path, [])
    (step, said), *rest = events
    assert step == "make" and [e[0] for e in rest] == ["close"]
    assert said.count("\n") == 1 and f"creating the system user {confined.user}" in said
    assert "removed when the run ends" in said and f"closing {tmp_path}'s folders" in said
