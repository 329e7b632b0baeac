"""`python -m rtpy assignment autograder WEEK OUT.zip`: the week's Gradescope autograder.

The zip holds, at its root:

- setup.sh: Gradescope runs it once, as root, when it builds the autograder's image.
  It finds a Python >= 3.11, installing python3.11 with apt-get when the image has
  none (Gradescope's Ubuntu 22.04 base image has 3.10), makes a virtual environment
  in $AUTOGRADER_ROOT/venv and installs requirements.txt into it with pip, and makes
  the unprivileged user the student's code runs as (rtpy.grading.sandbox);
- run_autograder: run for every submission. It runs run_autograder.py with the
  environment's Python, else $PYTHON, else python3 (so it runs locally and in CI);
- run_autograder.py: checks the Python version and runs rtpy.grading.autograder_run
  from repo/, and writes a results.json saying what is wrong when it cannot start;
- requirements.txt: rtpy's dependencies and pytest, from pyproject.toml;
- autograder.json: the week, its task files and task functions (from the solution
  regions, so it follows the week's cut) and the time limits;
- repo/: the week's student repository as `assignment make` writes it (rtpy with that
  week's and later weeks' tasks as stubs, the scenes, assignments/weekNN/), without
  its tests and docs, plus assignments/weekNN/hidden/, which no student repository has.
"""

from __future__ import annotations

import json
import shutil
import tempfile
import tomllib
import zipfile
from pathlib import Path

from ..io.image import atomic_write, check_writable
from .assignment import AssignmentError, check_week, find_regions, make_assignment, source_root
from .autograder_run import CONFIG_FILE

TEST_TIMEOUT = 60.0  # seconds per test
TOTAL_TIMEOUT = 480.0  # seconds for a whole submission (set Gradescope's limit above it)
IMPORT_TIMEOUT = 60.0  # seconds to import rtpy with the student's files
HIDDEN = "hidden"  # assignments/weekNN/hidden/: the checks only the autograder holds
LEFT_OUT = ("tests", "docs")  # parts of the student repository grading does not need

SETUP_SH = """#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image. Written
# for Gradescope's Ubuntu 22.04 base image, whose python3 is 3.10 while rtpy needs 3.11:
# apt-get installs python3.11 from Ubuntu's archive when there is no Python >= 3.11
# (and a venv module when it lacks one); everything else comes from pip.
set -euo pipefail
ROOT="${AUTOGRADER_ROOT:-/autograder}"
PY=""
for candidate in python3.13 python3.12 python3.11 python3; do
  if command -v "$candidate" >/dev/null 2>&1 &&
     "$candidate" -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
    PY="$candidate"
    break
  fi
done
if [ -z "$PY" ]; then
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y python3.11 python3.11-venv
  PY=python3.11
fi
if ! "$PY" -m venv "$ROOT/venv"; then
  VERSION=$("$PY" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y "python$VERSION-venv"
  rm -rf "$ROOT/venv"
  "$PY" -m venv "$ROOT/venv"
fi
"$ROOT/venv/bin/python" -m pip install --upgrade pip
"$ROOT/venv/bin/python" -m pip install -r "$ROOT/source/requirements.txt"
"$ROOT/venv/bin/python" -c "import numpy, PIL, tqdm, pytest"
# The student's code runs as this user (rtpy.grading.sandbox.SANDBOX_USER), who can
# run the environment's Python but cannot read the graders or write the results.
id -u rtpy-sandbox >/dev/null 2>&1 ||
  useradd --system --no-create-home --shell /usr/sbin/nologin rtpy-sandbox
chmod -R a+rX "$ROOT/venv"
"""

RUN_AUTOGRADER = """#!/bin/sh
# Gradescope runs this for every submission. Locally: AUTOGRADER_ROOT=DIR and, without
# DIR/venv, PYTHON=a Python with rtpy's dependencies (python3 by default).
ROOT="${AUTOGRADER_ROOT:-/autograder}"
PY="$ROOT/venv/bin/python"
[ -x "$PY" ] || PY="${PYTHON:-python3}"
exec "$PY" "$ROOT/source/run_autograder.py"
"""

RUN_AUTOGRADER_PY = '''"""Grade the submission in $AUTOGRADER_ROOT/submission (see
repo/rtpy/grading/autograder_run.py); a results.json in every case."""
import json
import os
import sys

ROOT = os.environ.get("AUTOGRADER_ROOT", "/autograder")
SOURCE = os.path.dirname(os.path.abspath(__file__))


def fail(message):
    folder = os.path.join(ROOT, "results")
    os.makedirs(folder, exist_ok=True)
    output = message + " (not your code; tell your instructor)"
    results = {"score": 0, "output": output, "tests": []}
    with open(os.path.join(folder, "results.json"), "w") as f:
        json.dump(results, f, indent=2)
    print(message)
    sys.exit(0)


if sys.version_info < (3, 11):
    fail("The autograder needs Python 3.11 or later, it has " + sys.version.split()[0])
sys.path.insert(0, os.path.join(SOURCE, "repo"))
try:
    from rtpy.grading.autograder_run import main
except Exception as err:
    fail("The autograder could not start: " + repr(err))
sys.exit(main())
'''


def task_regions(week: str, root: Path) -> list:
    """The solution regions of `week`: the student's tasks."""
    return [r for r in find_regions(root) if r.week == week]


def task_files(week: str, root: Path) -> list[str]:
    """The files holding week's tasks (posix paths from the root): the only files the
    autograder takes from a submission."""
    return sorted({r.path.as_posix() for r in task_regions(week, root)})


def requirements(root: Path) -> str:
    """rtpy's dependencies and pytest, one a line, from pyproject.toml."""
    with open(root / "pyproject.toml", "rb") as f:
        project = tomllib.load(f)["project"]
    tests = [d for d in project["optional-dependencies"]["test"] if d.startswith("pytest")]
    return "".join(f"{d}\n" for d in [*project["dependencies"], *tests])


def write_repository(root: Path, week: str, dest: Path) -> None:
    """dest/repo: the student repository with the hidden checks, without LEFT_OUT."""
    repo = make_assignment(week, dest / "repo", root)
    for name in LEFT_OUT:
        shutil.rmtree(repo / name, ignore_errors=True)
    hidden = root / "assignments" / f"week{week}" / HIDDEN
    if hidden.is_dir():
        shutil.copytree(
            hidden,
            repo / "assignments" / f"week{week}" / HIDDEN,
            ignore=shutil.ignore_patterns("__pycache__", "*.pyc"),
        )


def build_autograder(
    week: str | int,
    out: str | Path,
    root: str | Path | None = None,
    test_timeout: float = TEST_TIMEOUT,
    total_timeout: float = TOTAL_TIMEOUT,
) -> Path:
    """Write week's Gradescope autograder to `out` (a .zip), atomically; `out` is
    checked first (OutputError when it cannot be written)."""
    week = check_week(week)
    out = Path(out)
    if out.suffix.lower() != ".zip":
        raise AssignmentError(f"{out}: the autograder is a .zip file")
    check_writable(out)
    for name, value in (("test timeout", test_timeout), ("total timeout", total_timeout)):
        if not 0 < value < 1e6:
            raise AssignmentError(f"{name} {value}: expected seconds > 0")
    root = Path(root) if root is not None else source_root("assignment autograder")
    with tempfile.TemporaryDirectory(prefix="rtpy-autograder-build-") as tmp:
        dest = Path(tmp)
        write_repository(root, week, dest)
        config = {
            "week": week,
            "task_files": task_files(week, root),
            "task_functions": [
                {"path": r.path.as_posix(), "function": r.function}
                for r in task_regions(week, root)
            ],
            "test_timeout": float(test_timeout),
            "total_timeout": float(total_timeout),
            "import_timeout": IMPORT_TIMEOUT,
        }
        files = {
            "setup.sh": SETUP_SH,
            "run_autograder": RUN_AUTOGRADER,
            "run_autograder.py": RUN_AUTOGRADER_PY,
            "requirements.txt": requirements(root),
            CONFIG_FILE: json.dumps(config, indent=2) + "\n",
        }
        atomic_write(out, lambda path: write_zip(path, files, dest / "repo"))
    return out


def write_zip(path: Path, files: dict[str, str], repo: Path) -> None:
    """The zip: `files` at the root (the scripts executable), repo/ below."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, text in files.items():
            info = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))
            mode = 0o755 if name in ("setup.sh", "run_autograder") else 0o644
            info.external_attr = (0o100000 | mode) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, text)
        for file in sorted(repo.rglob("*")):
            if file.is_file() and "__pycache__" not in file.parts:
                archive.write(file, Path("repo", file.relative_to(repo)).as_posix())


def extract(zip_path: Path, dest: Path) -> Path:
    """Unpack an autograder zip as Gradescope does (dest becomes source/), keeping the
    scripts executable; for running it locally."""
    with zipfile.ZipFile(zip_path) as archive:
        archive.extractall(dest)
        for info in archive.infolist():
            mode = (info.external_attr >> 16) & 0o777
            if mode:
                (dest / info.filename).chmod(mode)
    return dest
