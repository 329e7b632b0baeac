"""run_autograder: grade one submission under Gradescope's layout and always answer.

Under AUTOGRADER_ROOT (default /autograder): source/ holds what
`python -m rtpy assignment autograder` zipped (autograder.json, and repo/: the week's
student repository as generated, with the hidden checks), submission/ the student's
files, results/results.json the answer. This process is the judge: it never imports
the submission. `main()`

1. writes a results.json at once (score 0, "grading did not finish"), replaced
   atomically as results come in, so a run stopped from outside still has one;
2. as root, closes source/, submission/ and results/ to everyone else, and runs the
   student's code as an unprivileged user of this run's own, in a temporary folder
   that user can reach (checked: when it cannot, the autograder says it failed,
   never the student), without network (rtpy.grading.confinement), its writable
   folders small tmpfs of its own where the kernel allows (rtpy.grading.private_space);
3. makes a work copy of repo/ without the hidden checks and the references, puts the
   submission's task files over it (rtpy.grading.autograder_submission) and makes it
   read-only to the sandbox; a task file that does not compile, or whose import
   fails or hangs in the sandbox, is put back to its stub (readable by the sandbox),
   and the results say why: the other files keep their points;
4. runs the graders and the hidden checks of source/ here (rtpy.grading.judge), their
   probes answered by the sandboxed child (rtpy.grading.sandbox) with a fresh
   grading seed, a time limit per test and one for the whole run, which counts from
   the start: tests it leaves no time for are marked not run;
5. writes the results (rtpy.grading.results), with the judge's own folders taken out
   of what the student reads, removes the work copy, ends every process of the
   sandbox user and removes every file it left in the shared temporary folders.
"""

from __future__ import annotations

import json
import os
import re
import secrets
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

from .autograder_seed import SEED_VARIABLE
from .autograder_submission import (
    SubmissionError,
    compile_errors,
    ignored_changes,
    import_problem,
    take_task_files,
    unpack,
)
from .confinement import kill_user, network_closed, remove_user_files, remove_user_ipc
from .graders import HIDDEN, PROBES_FILE, child_config
from .private_space import space_bounded
from .results import gradescope_results, scrub, write_results
from .sandbox import SANDBOX_USER, Child, Isolation, sandbox_ids

CONFIG_FILE = "autograder.json"
LEFT_OUT = (HIDDEN, "reference")  # folders of assignments/weekNN the child never sees
JUDGE_PATH = re.compile(r"""[^\s'"]*rtpy-(?:judge|child)-[^\s'":]*""")  # its own files
TEMP_PLACES = ("/tmp", "/var/tmp", "/dev/shm")  # for the judge's folder when TMPDIR is closed


@dataclass
class Run:
    """The state of grading one submission."""

    config: dict
    source: Path  # source/repo: the instructor's copy
    work: Path  # the child's copy
    home: Path  # the child's own folder
    results_path: Path
    isolation: Isolation
    problems: dict[str, str] = field(default_factory=dict)  # task file -> why it is the stub
    notes: list[str] = field(default_factory=list)  # for the student, above the tests
    log: list[str] = field(default_factory=list)  # for the instructor (stdout)
    seed: str = ""
    judge: object = None
    written: float = 0.0
    started: float = field(default_factory=time.monotonic)
    scratch: Path | None = None  # the judge's folder of this run (never shown)

    @property
    def deadline(self) -> float:
        return self.started + float(self.config["total_timeout"])

    @property
    def week(self) -> str:
        return self.config["week"]

    def results(self, partial: bool) -> dict:
        from .tasks import load_week

        tests = list(self.judge.tests.values()) if self.judge is not None else []
        week_map = load_week(self.source / "assignments" / f"week{self.week}")
        results = gradescope_results(
            tests, week_map, partial=partial, notes=self.notes, problems=self.problems,
            task_functions=self.config.get("task_functions", []),
        )  # fmt: skip
        results["extra_data"] = {"week": self.week, "seed": self.seed, "partial": partial}
        return scrub(results, self.hidden_paths())

    def hidden_paths(self) -> dict[str, str]:
        """The judge's paths, as the student's process may print them -> what the
        student reads instead."""
        shown = {}
        for path, name in ((self.work, ""), (self.home, "<temporary folder>")):
            for form in {str(path), os.path.realpath(path)}:
                shown[form + os.sep] = f"{name}/" if name else ""
                shown[form] = name or "."
        if self.scratch is not None:
            for form in {str(self.scratch), os.path.realpath(self.scratch)}:
                shown[form] = "<grading folder>"
        return shown

    def save(self, partial: bool = True) -> None:
        write_results(self.results_path, self.results(partial))
        self.written = time.monotonic()


def autograder_root() -> Path:
    return Path(os.environ.get("AUTOGRADER_ROOT", "/autograder"))


def load_config(source: Path) -> dict:
    config = json.loads((source / CONFIG_FILE).read_text(encoding="utf-8"))
    for key, variable in (
        ("test_timeout", "RTPY_AUTOGRADER_TEST_TIMEOUT"),
        ("total_timeout", "RTPY_AUTOGRADER_TOTAL_TIMEOUT"),
        ("import_timeout", "RTPY_AUTOGRADER_IMPORT_TIMEOUT"),
    ):
        if os.environ.get(variable):
            config[key] = float(os.environ[variable])  # local runs and tests only
    return config


def main() -> int:
    """Grade $AUTOGRADER_ROOT/submission; 0 whenever a results.json was written."""
    root = autograder_root()
    results_path = root / "results" / "results.json"
    start = time.monotonic()
    results = {"score": 0, "output": "The autograder did not finish (see its stdout).", "tests": []}
    before = signal.signal(signal.SIGTERM, _stop)  # cleans up (the `with` blocks) first
    try:
        return _grade(root, results_path, results, start)
    finally:
        signal.signal(signal.SIGTERM, before)  # as it was (a caller's process, a test's)


def _grade(root: Path, results_path: Path, results: dict, start: float) -> int:
    try:
        write_results(results_path, results)
        config = load_config(root / "source")
        results = grade_submission(root, config, results_path)
    except Exception as err:  # the autograder's own failure: say so, score 0
        traceback.print_exc()
        text = JUDGE_PATH.sub("<grading folder>", repr(err))  # in full on stdout above
        results = {
            "score": 0,
            "output": f"The autograder failed (not your code; tell your instructor): {text}",
            "tests": [],
        }
    results["execution_time"] = round(time.monotonic() - start, 2)
    write_results(results_path, results)
    print(f"rtpy autograder: score {results['score']:g}, results in {results_path}")
    print(f"rtpy autograder: the judge's peak memory {peak_memory() / 2**20:.0f} MiB")
    return 0


def peak_memory() -> int:
    """The judge's own peak resident memory in bytes (0 where not known)."""
    try:
        import resource
    except ImportError:  # Windows
        return 0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak if sys.platform == "darwin" else peak * 1024


def _stop(signum, frame) -> None:
    raise SystemExit(128 + signum)


class Unconfined(Exception):
    """As root, the student's code cannot be run as an unprivileged user."""


def make_user(name: str) -> bool:
    """Make the system user `name` (no home, no shell); whether it exists now."""
    if sandbox_ids(name) is None:
        subprocess.run(
            ["useradd", "--system", "--no-create-home", "--shell", "/usr/sbin/nologin", name],
            capture_output=True,
        )
    return sandbox_ids(name) is not None


def isolation(root: Path, log: list[str]) -> Isolation:
    """How the child is confined here: as root, by a user of this run's own (so that
    ending every process of the user ends this run's alone, even beside other runs
    on the machine), else by SANDBOX_USER (made by setup.sh), with the autograder's
    folders closed to both; without root, not by a user. Either way without network
    where the socket filter can be installed, in a bounded private space of its own
    where the kernel allows (the log says so once where not)."""
    socket_filter, why = network_closed(sys.executable)
    if socket_filter is None:
        log.append(f"the student's code can reach the network: {why}")
    space, why = space_bounded()
    if space is None:
        log.append(
            "the student's code may make any number of files in the shared temporary "
            f"folders (each at most the file size limit; removed at the end): {why}"
        )
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        log.append("not root: the student's code runs as this user (no user isolation)")
        return Isolation(socket_filter=socket_filter)
    user = f"{SANDBOX_USER}-{secrets.token_hex(4)}"
    print(  # before anything changes on the machine (a local run as root, too)
        f"rtpy autograder: running as root: creating the system user {user} for the "
        f"student's code (removed when the run ends; else {SANDBOX_USER}, which stays) and "
        f"closing {root}'s folders to other users",
        flush=True,
    )
    if not make_user(user):
        user = SANDBOX_USER
        if not make_user(user):
            raise Unconfined(f"could not make the user {SANDBOX_USER} (useradd failed)")
    ids = sandbox_ids(user)
    remove_user_files(*ids)  # an earlier run's user may have had this uid
    remove_user_ipc(ids[0])
    close(root)
    return Isolation(user=user, socket_filter=socket_filter, space=space)


def close(root: Path) -> None:
    """Everything of AUTOGRADER_ROOT to root alone (source/, submission/, results/,
    Gradescope's submission_metadata.json), but the Python environment, venv/, which
    the sandbox user runs."""
    os.chmod(root, 0o711)
    for entry in root.iterdir():
        if entry.name != "venv" and not entry.is_symlink():
            os.chmod(entry, 0o700 if entry.is_dir() else 0o600)


def remove_user(user: str | None, log: list[str]) -> None:
    """End every process of this run's user, remove its files from the shared temporary
    folders, and remove the user (not SANDBOX_USER)."""
    ids = sandbox_ids(user)
    if ids is None:
        return
    if not kill_user(ids[0]):
        log.append(f"some processes of {user} could not be ended")
    removed = remove_user_files(*ids) + [f"{kind} {n}" for kind, n in remove_user_ipc(ids[0])]
    if removed:
        log.append(f"removed what the student's code left: {', '.join(removed[:10])}")
    if user != SANDBOX_USER:
        subprocess.run(["userdel", user], capture_output=True)


REACH = """import os, sys, numpy
os.listdir(os.path.join(sys.argv[1], "rtpy"))
open(os.path.join(sys.argv[1], "rtpy", "__init__.py")).close()
open(os.path.join(sys.argv[2], "reach"), "w").close()
os.unlink(os.path.join(sys.argv[2], "reach"))
"""


def python_problem(isolation_: Isolation, python: str, work: Path, home: Path) -> str:
    """Why the sandbox user cannot start this Python with numpy (its folders may be
    closed to others), read the work copy or write its home, or ""."""
    ids = sandbox_ids(isolation_.user)
    if ids is None:
        return ""
    try:
        proc = subprocess.run(
            [python, "-I", "-c", REACH, str(work), str(home)], user=ids[0], group=ids[1],
            extra_groups=[], cwd="/", capture_output=True, text=True,
            env={"PATH": "/usr/bin:/bin"}, timeout=60,
        )  # fmt: skip
    except (OSError, subprocess.TimeoutExpired) as err:
        return repr(err)
    return "" if proc.returncode == 0 else proc.stderr.strip()[-300:]


def make_work_copy(source: Path, dest: Path, week: str) -> Path:
    """The child's copy of repo/: without LEFT_OUT (hidden checks, references) and any
    week but `week`'s graders."""

    def ignore(folder: str, names: list[str]) -> set[str]:
        here = Path(folder)
        left = {n for n in names if n == "__pycache__"}
        if here.parent.name == "assignments" and here.name.startswith("week"):
            left |= {n for n in names if n in LEFT_OUT}
        return left

    shutil.copytree(source, dest, ignore=ignore)
    return dest


def seal(work: Path, home: Path, isolation_: Isolation) -> None:
    """The work copy readable by all and writable by root only; home the sandbox
    user's alone."""
    for path in [work, *work.rglob("*")]:
        mode = 0o755 if path.is_dir() else 0o644
        os.chmod(path, mode, follow_symlinks=False)
    ids = sandbox_ids(isolation_.user)
    if ids is not None:
        os.chown(home, *ids)
        os.chmod(home, 0o700)
        os.chmod(home.parent, 0o711)


def reachable_temp(user: str | None) -> str | None:
    """Where the judge makes its folder: the temporary folder when every user may pass
    through it and its parents (the sandbox's user must reach the work copy), else the
    first of /tmp, /var/tmp, /dev/shm that is; None (this Python's default) without a
    sandbox user."""
    if sandbox_ids(user) is None:
        return None
    for candidate in (tempfile.gettempdir(), *TEMP_PLACES):
        path = Path(os.path.realpath(candidate))
        try:
            if path.is_dir() and all(os.stat(p).st_mode & 0o001 for p in [path, *path.parents]):
                return str(path)
        except OSError:
            continue
    raise Unconfined("no temporary folder that the sandbox's user can reach (/tmp is closed)")


def grade_submission(root: Path, config: dict, results_path: Path) -> dict:
    log: list[str] = []
    started = time.monotonic()
    confined = isolation(root, log)
    confined.cpu_seconds = int(float(config["total_timeout"])) + 60  # each child's CPU time
    user = confined.user
    try:
        with tempfile.TemporaryDirectory(prefix="rtpy-judge-", dir=reachable_temp(user)) as tmp:
            scratch = Path(tmp)
            source = root / "source" / "repo"
            work = make_work_copy(source, scratch / "repo", config["week"])
            home = scratch / "home"
            home.mkdir()
            confined.home = home
            run = Run(config, source, work, home, results_path, confined, log=log)
            run.started, run.scratch = started, scratch
            try:
                prepare(run, root / "submission", scratch)
                seal(work, home, confined)
                run.save()
                run_tests(run)
                return run.results(partial=False)
            finally:
                remove_user(user, log)
    finally:
        for line in log:
            print(line)


def new_child(run: Run) -> Child:
    """A child in the work copy, which no call outlives the run's total time limit."""
    folder = run.work / "assignments" / f"week{run.week}"
    config = child_config(folder, run.work, run.config.get("task_functions", []))
    left = max(1.0, run.deadline - time.monotonic())
    timeout = min(float(run.config.get("import_timeout", 60.0)), left)
    config["import_timeout"] = timeout
    child = Child(run.work, config, run.isolation, log=run.log, start_timeout=timeout)
    child.deadline = run.deadline
    child.config_dir = run.scratch  # the judge's, reachable (TMPDIR may be closed to the child)
    return child


def prepare(run: Run, submission: Path, scratch: Path) -> None:
    """Put the usable task files over the work copy; run.problems and run.notes say
    what was taken and what could not be used."""
    seal(run.work, run.home, run.isolation)
    problem = python_problem(run.isolation, sys.executable, run.work, run.home)
    if problem:  # the student's code never runs as root
        raise Unconfined(
            f"the user {run.isolation.user} cannot run {sys.executable} in the work copy "
            f"({problem}); as root the autograder runs a student's code only as an "
            "unprivileged user: install Python where every user can run it, as setup.sh "
            "does, and let every user pass through the temporary folder"
        )
    task_files = run.config["task_files"]
    pristine = run.source
    try:
        base = unpack(submission, scratch)
    except SubmissionError as err:
        run.notes.append(f"Your submission could not be read: {err}. No task counts as done.")
        return
    taken = take_task_files(base, task_files, run.work)
    run.notes.extend(taken.notes)
    run.problems.update(taken.problems)
    for rel, message in compile_errors(run.work, taken.files).items():
        run.problems[rel] = message
        _restore(pristine / rel, run.work / rel)
    usable = [rel for rel in taken.files if rel not in run.problems]
    seal(run.work, run.home, run.isolation)
    while usable and time.monotonic() < run.deadline:
        found = import_problem(new_child(run), usable, run.work)
        if found is None:
            break
        rel, message = found
        if rel is None:  # cannot tell which file: the first whose stub imports
            rel = culprit(run, usable)
        for blamed in usable if rel is None else [rel]:
            run.problems[blamed] = message
            _restore(pristine / blamed, run.work / blamed)
        usable = [] if rel is None else [u for u in usable if u != rel]
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


def culprit(run: Run, usable: list[str]) -> str | None:
    """The task file whose stub, put in its place, lets everything import; None when
    none does. Fails as the autograder's own failure when even all the stubs do not
    import (the sandbox cannot read its copy)."""
    saved = {rel: (run.work / rel).read_bytes() for rel in usable}
    try:
        for rel in usable:
            _restore(run.source / rel, run.work / rel)
            if import_problem(new_child(run), [u for u in usable if u != rel], run.work) is None:
                return rel
            _write(run.work / rel, saved[rel])
        for rel in usable:
            _restore(run.source / rel, run.work / rel)
        found = import_problem(new_child(run), [], run.work)
        if found is not None:
            raise Unconfined(f"the assignment's own files do not import in the sandbox: {found[1]}")
        return None
    finally:
        for rel, data in saved.items():  # the caller puts back the culprit's stub
            _write(run.work / rel, data)


def _restore(stub: Path, target: Path) -> None:
    """target back to the assignment's stub, readable by the sandbox's user."""
    _write(target, stub.read_bytes())


def _write(target: Path, data: bytes) -> None:
    os.chmod(target, stat.S_IWUSR | stat.S_IRUSR)
    target.write_bytes(data)
    os.chmod(target, 0o644)


def run_tests(run: Run) -> None:
    """The week's graders and hidden checks, judged here."""
    from .judge import Judge, judge, probe_registry

    folder = run.source / "assignments" / f"week{run.week}"
    os.environ[SEED_VARIABLE] = run.seed = str(secrets.randbits(63))
    run.log.append(f"grading seed {run.seed}")
    probes = folder / PROBES_FILE
    child = new_child(run)
    run.judge = Judge(
        child,
        probe_registry([probes] if probes.is_file() else []),
        test_timeout=float(run.config["test_timeout"]),
        total_timeout=float(run.config["total_timeout"]),
        started=run.started,
        progress=lambda: run.save() if time.monotonic() - run.written > 2.0 else None,
    )
    paths = [str(p) for p in sorted(folder.glob("test_*.py"))]
    paths += [str(p) for p in sorted((folder / HIDDEN).glob("test_*.py"))]
    try:
        judge(run.judge, paths)
    finally:
        child.stop()
    run.log.extend(run.judge.log)
    if run.judge.errors:
        run.log.append("graders that could not be loaded:\n" + "\n".join(run.judge.errors))
