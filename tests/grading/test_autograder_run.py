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
