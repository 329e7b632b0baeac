"""run_autograder (rtpy.grading.autograder_run) writes a results.json even when the
autograder itself cannot run; its runs on every week are tests/grading/test_autograder.py
and tests/grading/test_attacks.py, its results tests/grading/test_results.py."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path


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


def test_a_stub_put_back_is_readable_by_the_sandbox(tmp_path):
    """A task file put back to its stub is readable by every user (the sandbox's
    included), whatever the mode of the file it replaces."""
    from rtpy.grading.autograder_run import _restore

    stub, target = tmp_path / "stub.py", tmp_path / "light.py"
    stub.write_text("STUB = 1\n")
    target.write_text("broken(\n")
    target.chmod(0o600)
    _restore(stub, target)
    assert target.read_text() == "STUB = 1\n"
    assert target.stat().st_mode & 0o777 == 0o644


def test_the_judges_folder_is_one_the_sandbox_can_reach(tmp_path, monkeypatch):
    """A private TMPDIR (0700) is passed over for a folder every user may pass through;
    with none, the autograder's own failure, never the student's."""
    import tempfile

    import pytest

    from rtpy.grading import autograder_run as run

    private = tmp_path / "private"
    private.mkdir(mode=0o700)
    monkeypatch.setattr(tempfile, "tempdir", str(private))
    monkeypatch.setattr(run, "sandbox_ids", lambda user: (12345, 12345))
    chosen = run.reachable_temp("someone")
    assert chosen != str(private)
    assert all(os.stat(p).st_mode & 0o001 for p in [chosen, *map(str, Path(chosen).parents)])
    monkeypatch.setattr(run, "TEMP_PLACES", (str(private),))
    with pytest.raises(run.Unconfined, match="no temporary folder"):
        run.reachable_temp("someone")
    monkeypatch.setattr(run, "sandbox_ids", lambda user: None)
    assert run.reachable_temp(None) is None  # no sandbox user: this Python's default


def test_where_the_network_stays_open_the_instructor_is_told_once(tmp_path, monkeypatch):
    from rtpy.grading import autograder_run as run

    monkeypatch.setattr(run, "network_closed", lambda python: (None, "no socket filter here"))
    monkeypatch.setattr(os, "geteuid", lambda: 1000, raising=False)  # not root: no user made
    log: list[str] = []
    confined = run.isolation(tmp_path, log)
    assert confined.socket_filter is None and confined.user is None
    assert [ln for ln in log if "network" in ln] == [
        "the student's code can reach the network: no socket filter here"
    ]
    monkeypatch.setattr(run, "network_closed", lambda python: ("a filter", ""))
    log.clear()
    assert run.isolation(tmp_path, log).socket_filter == "a filter"
    assert not [ln for ln in log if "network" in ln]


def test_where_the_writable_space_is_not_bounded_the_instructor_is_told_once(tmp_path, monkeypatch):
    from rtpy.grading import autograder_run as run

    monkeypatch.setattr(run, "network_closed", lambda python: ("a filter", ""))
    monkeypatch.setattr(run, "space_bounded", lambda: (None, "the kernel refused (EPERM)"))
    monkeypatch.setattr(os, "geteuid", lambda: 1000, raising=False)
    log: list[str] = []
    assert run.isolation(tmp_path, log).space is None
    told = [ln for ln in log if "number of files" in ln]
    assert len(told) == 1 and told[0].endswith("the kernel refused (EPERM)"), log
    monkeypatch.setattr(run, "space_bounded", lambda: ("a space", ""))
    log.clear()
    run.isolation(tmp_path, log)
    assert not [ln for ln in log if "number of files" in ln]


def test_the_autograders_own_failure_hides_its_folders(tmp_path, monkeypatch, capsys):
    from rtpy.grading import autograder_run as run

    (tmp_path / "source").mkdir()
    (tmp_path / "source" / "autograder.json").write_text('{"week": "05"}')
    monkeypatch.setenv("AUTOGRADER_ROOT", str(tmp_path))
    secret = "/tmp/rtpy-judge-abc123/repo/rtpy/light.py"

    def fail(*args):
        raise run.Unconfined(f"cannot read {secret}: closed")

    monkeypatch.setattr(run, "grade_submission", fail)
    before = signal.getsignal(signal.SIGTERM)
    assert run.main() == 0
    assert signal.getsignal(signal.SIGTERM) is before  # the caller's handler, as it was
    results = json.loads((tmp_path / "results" / "results.json").read_text())
    assert results["output"].startswith("The autograder failed (not your code; tell your")
    assert "cannot read <grading folder>: closed" in results["output"]
    assert secret in capsys.readouterr().err  # the instructor's log has it all


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
    monkeypatch.setattr(autograder_run, "sandbox_ids", lambda user: (54321, 54321))
    monkeypatch.setattr(autograder_run, "remove_user_files", lambda uid, gid: [])
    monkeypatch.setattr(autograder_run, "remove_user_ipc", lambda uid: [])
    monkeypatch.setattr(autograder_run, "close", lambda root: events.append(("close", "")))
    confined = autograder_run.isolation(tmp_path, [])
    (step, said), *rest = events
    assert step == "make" and [e[0] for e in rest] == ["close"]
    assert said.count("\n") == 1 and f"creating the system user {confined.user}" in said
    assert "removed when the run ends" in said and f"closing {tmp_path}'s folders" in said
