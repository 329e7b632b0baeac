"""run_autograder: grade one submission under Gradescope's layout and always answer.

Under AUTOGRADER_ROOT (default /autograder): source/ holds what
`python -m rtpy assignment autograder` zipped (autograder.json, and repo/: the week's
student repository as generated, with the hidden checks), submission/ the student's
files, results/results.json the answer. `main()`:

1. writes a results.json at once (score 0, "grading did not finish"), replaced
   atomically as results come in, so a run stopped from outside still has one;
2. copies repo/ to a work folder and puts the submission's task files over it
   (rtpy.grading.autograder_submission): every other file, graders and checks
   included, is the assignment's;
3. puts a task file back to its stub when it does not compile or its import fails
   or hangs, and says why;
4. runs the graders and the hidden checks in a child process
   (rtpy.grading.autograder_child) with a fresh grading seed, a time limit per test
   and one for the whole run; a child that crashes or hangs is killed and a new one
   runs the tests left;
5. writes the results: every test of autograder.json with its points, the hidden
   checks with visibility "after_due_date", the problems with the task files on top.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

from ..io.image import atomic_write
from .autograder_seed import SEED_VARIABLE
from .autograder_submission import (
    FRAME,
    SubmissionError,
    child_environment,
    compile_errors,
    ignored_changes,
    import_problem,
    suspicious_lines,
    take_task_files,
    unpack,
)

CONFIG_FILE = "autograder.json"
DUMP_GRACE = 5.0  # seconds between GraderTimeout and the child's faulthandler exit
KILL_GRACE = 10.0  # seconds after the child's own faulthandler exit before it is killed
POLL = 0.05
RESULTS_SIZE = 60_000  # characters of output per test at most


@dataclass
class Outcome:
    passed: bool
    output: str
    renders: bool = False


@dataclass
class Run:
    """The state of grading one submission."""

    config: dict
    work: Path
    scratch: Path
    deadline: float
    results_path: Path
    outcomes: dict[str, Outcome] = field(default_factory=dict)
    problems: dict[str, str] = field(default_factory=dict)  # task file -> why it is the stub
    notes: list[str] = field(default_factory=list)  # for the student, above the tests
    collection_errors: list[str] = field(default_factory=list)
    log: list[str] = field(default_factory=list)  # for the instructor (stdout)
    seed: str = ""  # the grading seed of this run
    written: float = 0.0  # when results.json was last written

    def save(self) -> None:
        """Write what is known so far to results.json."""
        write_results(self.results_path, results_of(self, partial=True))
        self.written = time.monotonic()


def autograder_root() -> Path:
    return Path(os.environ.get("AUTOGRADER_ROOT", "/autograder"))


def load_config(source: Path) -> dict:
    config = json.loads((source / CONFIG_FILE).read_text(encoding="utf-8"))
    for key, variable in (
        ("test_timeout", "RTPY_AUTOGRADER_TEST_TIMEOUT"),
        ("total_timeout", "RTPY_AUTOGRADER_TOTAL_TIMEOUT"),
    ):
        if os.environ.get(variable):
            config[key] = float(os.environ[variable])  # local runs and tests only
    return config


def write_results(path: Path, results: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(results, indent=2) + "\n"
    atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def main() -> int:
    """Grade $AUTOGRADER_ROOT/submission; 0 whenever a results.json was written."""
    root = autograder_root()
    results_path = root / "results" / "results.json"
    start = time.monotonic()
    results = {"score": 0, "output": "The autograder did not finish (see its stdout).", "tests": []}
    try:
        write_results(results_path, results)
        config = load_config(root / "source")
        results = grade_submission(root, config, start, results_path)
    except Exception as err:  # the autograder's own failure: say so, score 0
        traceback.print_exc()
        results = {
            "score": 0,
            "output": f"The autograder failed (not your code; tell your instructor): {err!r}",
            "tests": [],
        }
    results["execution_time"] = round(time.monotonic() - start, 2)
    write_results(results_path, results)
    print(f"rtpy autograder: score {results['score']:g}, results in {results_path}")
    return 0


def grade_submission(root: Path, config: dict, start: float, results_path: Path) -> dict:
    with tempfile.TemporaryDirectory(prefix="rtpy-autograder-") as tmp:
        scratch = Path(tmp)
        work = scratch / "repo"
        pristine = root / "source" / "repo"
        shutil.copytree(pristine, work, ignore=shutil.ignore_patterns("__pycache__"))
        deadline = start + float(config["total_timeout"])
        run = Run(config, work, scratch, deadline, results_path)
        prepare(run, root / "submission", pristine)
        run.save()
        run_tests(run)
        for line in run.log:
            print(line)
        return results_of(run)


def prepare(run: Run, submission: Path, pristine: Path) -> None:
    """Put the usable task files over the work copy; run.problems and run.notes say
    what was taken and what could not be used."""
    task_files = run.config["task_files"]
    try:
        base = unpack(submission, run.scratch)
    except SubmissionError as err:
        run.notes.append(f"Your submission could not be read: {err}. No task counts as done.")
        return
    taken = take_task_files(base, task_files, run.work)
    run.notes.extend(taken.notes)
    run.problems.update(taken.problems)
    for rel, message in compile_errors(run.work, taken.files).items():
        run.problems[rel] = message
        restore(run, pristine, rel)
    usable = [rel for rel in taken.files if rel not in run.problems]
    timeout = float(run.config.get("import_timeout", 60.0))
    while usable:
        found = import_problem(run.work, usable, timeout)
        if found is None:
            break
        rel, message = found
        for blamed in usable if rel is None else [rel]:  # None: cannot tell which file
            run.problems[blamed] = message
            restore(run, pristine, blamed)
        usable = [] if rel is None else [u for u in usable if u != rel]
    for line in suspicious_lines(run.work, usable):
        run.log.append(f"check this line of the submission: {line}")
    run.notes.append(
        f"Graded from your submission: {', '.join(usable) or 'none of the task files'}."
    )
    for rel, message in run.problems.items():
        run.notes.append(f"{rel}: {message}. Its tasks count as not done.")
    ignored = ignored_changes(taken.repository, pristine, task_files)
    if ignored:
        more = f" and {len(ignored) - 10} more" if len(ignored) > 10 else ""
        shown = ", ".join(ignored[:10]) + more
        run.notes.append(f"Changes outside the task files are not graded: {shown}.")


def restore(run: Run, pristine: Path, rel: str) -> None:
    shutil.copyfile(pristine / rel, run.work / rel)


# --- running the tests ----------------------------------------------------------------
def run_tests(run: Run) -> None:
    """Run every test of the config in child processes until each has an outcome or the
    total time is up."""
    config_path = run.scratch / CONFIG_FILE
    config_path.write_text(json.dumps(run.config), encoding="utf-8")
    env = child_environment(run.work)
    run.seed = env[SEED_VARIABLE] = str(secrets.randbits(63))
    run.log.append(f"grading seed {run.seed}")
    remaining = [t["nodeid"] for t in run.config["tests"]]
    attempt = 0
    while remaining and time.monotonic() < run.deadline:
        attempt += 1
        run_child(run, env, config_path, run.scratch / f"events-{attempt}.jsonl", remaining)
        remaining = [n for n in remaining if n not in run.outcomes]
        run.save()
    for nodeid in remaining:
        run.outcomes[nodeid] = Outcome(
            False,
            f"not run: the autograder's time limit of {run.config['total_timeout']:g} s "
            "for the whole submission was reached",
        )


def run_child(run: Run, env: dict, config_path: Path, events: Path, nodeids: list[str]) -> None:
    """One child process over nodeids. A test it started without a result (a crash, a
    kill) gets a failing outcome here; so does every test when it started none."""
    command = [sys.executable, "-m", "rtpy.grading.autograder_child"]
    command += [str(events), str(config_path), *nodeids]
    test_limit = float(run.config["test_timeout"]) + DUMP_GRACE + KILL_GRACE
    load_limit = float(run.config.get("import_timeout", 60.0))
    current, since, started, killed = None, time.monotonic(), set(), ""
    with open(run.scratch / "child.out", "ab") as out:
        proc = subprocess.Popen(command, cwd=run.work, env=env, stdout=out, stderr=out)
        reader = EventReader(events)
        while True:
            for event in reader.read():
                current, since = handle(run, event, current, started), time.monotonic()
            if time.monotonic() - run.written > 2.0:
                run.save()
            if proc.poll() is not None:
                break
            now = time.monotonic()
            if now > run.deadline:
                killed = "the time limit for the whole submission was reached"
            elif current is not None and now - since > test_limit:
                killed = f"it did not finish within {run.config['test_timeout']:g} s"
            elif current is None and now - since > load_limit:
                killed = f"the graders did not load within {load_limit:g} s"
            if killed:
                proc.kill()
                proc.wait()
                break
            time.sleep(POLL)
        for event in reader.read():
            current = handle(run, event, current, started)
    if current is not None and current not in run.outcomes:
        run.outcomes[current] = Outcome(False, crash_message(run, events, proc.returncode, killed))
    if not started:  # the child could not even start the tests
        tail = (run.scratch / "child.out").read_text(errors="replace")[-2000:]
        run.log.append(f"grader process exited with {proc.returncode}:\n{tail}")
        for nodeid in nodeids:
            run.outcomes.setdefault(nodeid, Outcome(False, load_failure(run, killed or tail)))


def handle(run: Run, event: dict, current: str | None, started: set) -> str | None:
    """Record one event; the test now running."""
    kind = event.get("event")
    if kind == "collected":
        run.collection_errors.extend(event.get("errors", []))
    elif kind == "start":
        started.add(event["nodeid"])
        return event["nodeid"]
    elif kind == "result":
        run.outcomes[event["nodeid"]] = Outcome(
            bool(event["passed"]), str(event.get("output", ""))[:RESULTS_SIZE], event["renders"]
        )
        return None
    return current


class EventReader:
    """The complete JSON lines appended to a file since the last read."""

    def __init__(self, path: Path) -> None:
        self.path, self.offset, self.partial = path, 0, b""

    def read(self) -> list[dict]:
        try:
            with open(self.path, "rb") as f:
                f.seek(self.offset)
                data = f.read()
        except FileNotFoundError:
            return []
        self.offset += len(data)
        lines = (self.partial + data).split(b"\n")
        self.partial = lines.pop()
        out = []
        for line in lines:
            try:
                out.append(json.loads(line))
            except ValueError:
                continue
        return out


def crash_message(run: Run, events: Path, status: int | None, killed: str) -> str:
    """Why a test ended without a result: its time limit (with where the student's code
    was, from the faulthandler dump) or a crash."""
    stack = Path(f"{events}.stack")
    where = ""
    if stack.exists():
        for path, line in FRAME.findall(stack.read_text(errors="replace")):
            try:
                rel = Path(path).resolve().relative_to(run.work.resolve()).as_posix()
            except ValueError:
                continue
            if rel in run.config["task_files"]:
                where = f" (it was in {rel}, line {line})"
                break  # faulthandler lists the innermost frame first
    limit = run.config["test_timeout"]
    if killed or (stack.exists() and stack.stat().st_size):
        reason = killed or f"it did not finish within {limit:g} s"
        return f"stopped: {reason}{where}: an endless loop, or code far too slow"
    return (
        f"the grading process crashed while this test ran (exit status {status}): "
        "a crash in Python itself, or the memory ran out"
    )


def load_failure(run: Run, tail: str) -> str:
    errors = "; ".join(run.collection_errors[:3])
    last = [ln for ln in tail.strip().splitlines() if ln.strip()][-1:] or [""]
    return f"the graders could not be loaded: {errors or last[0]}"


# --- the results ----------------------------------------------------------------------
def results_of(run: Run, partial: bool = False) -> dict:
    """Gradescope's results dictionary for what is known so far."""
    tests = []
    failed_components = [
        t["name"]
        for t in run.config["tests"]
        if not t["hidden"]
        and t["nodeid"] in run.outcomes
        and not run.outcomes[t["nodeid"]].passed
        and not run.outcomes[t["nodeid"]].renders
    ]
    problems = run.problems
    for test in run.config["tests"]:
        outcome = run.outcomes.get(test["nodeid"])
        if outcome is None:
            outcome = Outcome(False, "not run yet" if partial else "not run")
            if run.collection_errors:
                outcome.output = f"could not be loaded: {run.collection_errors[0]}"
        output = explain(outcome, problems, run.config, failed_components)
        tests.append(
            {
                "name": test["name"],
                "score": test["points"] if outcome.passed else 0.0,
                "max_score": test["points"],
                "status": "passed" if outcome.passed else "failed",
                "output": output,
                "visibility": "after_due_date" if test["hidden"] else "visible",
            }
        )
    score = sum(t["score"] for t in tests)
    hidden = sum(t["max_score"] for t in tests if t["visibility"] != "visible")
    header = list(run.notes)
    if hidden:
        header.append(
            f"Hidden checks ({hidden:g} of the {sum(t['max_score'] for t in tests):g} points) "
            "use new random inputs on every submission; you see them after the due date."
        )
    return {
        "score": score,
        "output": "\n".join(header),
        "visibility": "visible",
        "stdout_visibility": "hidden",
        "tests": tests,
        "extra_data": {"week": run.config["week"], "seed": run.seed, "partial": partial},
    }


def explain(outcome: Outcome, problems: dict, config: dict, failed_components: list) -> str:
    """A failed test's output, with the file problem that explains a stub's error and,
    for a render, the component graders that failed."""
    if outcome.passed:
        return ""
    text = outcome.output
    for task in config.get("task_functions", []):
        rel = task["path"]
        if rel in problems and f"task: {task['function']}" in text:
            text = f"{rel} was not used ({problems[rel]}), so this counts as not done. {text}"
            break
    if outcome.renders and failed_components:
        shown = "; ".join(failed_components[:6])
        text += (
            f"\nThe render uses the methods of these graders, which failed: {shown}. "
            "Fix those first."
        )
    return text
