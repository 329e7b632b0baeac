"""The autograder's side of the process that runs a student's code.

run_autograder (rtpy.grading.autograder_run) starts

    python -m rtpy.grading.autograder_child EVENTS CONFIG [NODEID ...]

in a copy of the assignment where only the task files are the student's. This module
is the pytest plugin of that process. It

- writes one JSON line to EVENTS per event (the tests collected, each test's start
  and result), flushed at once, so a crash or a kill loses only the running test;
- gives every test CONFIG's `test_timeout` seconds: then GraderTimeout (not an
  Exception, so `except Exception` in the student's code does not swallow it) stops
  the test and names where the student's code was; code that swallows it anyway is
  stopped DUMP_GRACE seconds later by faulthandler, which writes every thread's stack
  to EVENTS + ".stack" and ends the process (the parent reads the stack);
- wraps each task method so that returning None, or an object that is not of the
  annotated rtpy class, fails at once with the method's name (TaskReturnError),
  instead of an AttributeError on None somewhere in a grader;
- names the function, file and line of the student's code in the message of an
  exception raised there;
- records which tests render (they call rtpy.grading.graders.render_stack), so that
  a failed render can point to the failed component graders.

With --collect it only lists the tests (what `assignment autograder` stores).
"""

from __future__ import annotations

import faulthandler
import functools
import importlib
import json
import os
import signal
import sys
import types
from pathlib import Path

import pytest

from .autograder_run import DUMP_GRACE

HIDDEN_PART = "/hidden/"  # a test file under assignments/weekNN/hidden/ is a hidden check


class GraderTimeout(BaseException):
    """A test ran past its time limit (raised from SIGALRM)."""


class TaskReturnError(TypeError):
    """A task method returned None, or an object of the wrong type."""


# --- where in the student's code ------------------------------------------------------
def relative(filename: str, base: Path) -> str | None:
    """filename relative to base as a posix path, or None outside it."""
    try:
        return Path(filename).resolve().relative_to(base).as_posix()
    except (ValueError, OSError):
        return None


def student_frame(tb, base: Path, task_files: set[str]) -> tuple[str, str, int] | None:
    """(function, file, line) of the innermost traceback frame in a task file, else in
    rtpy/; None when the exception never passed through rtpy."""
    found = fallback = None
    while tb is not None:
        rel = relative(tb.tb_frame.f_code.co_filename, base)
        here = (tb.tb_frame.f_code.co_qualname, rel, tb.tb_lineno)
        if rel in task_files:
            found = here
        elif rel is not None and rel.startswith("rtpy/"):
            fallback = here
        tb = tb.tb_next
    return found or fallback


def place(frame: tuple[str, str, int] | None) -> str:
    if frame is None:
        return ""
    function, file, line = frame
    return f"{function} ({file}, line {line})"


def describe(exc: BaseException, base: Path, task_files: set[str], timeout: float) -> str:
    """The message a student reads for a test that raised exc."""
    where = place(student_frame(exc.__traceback__, base, task_files))
    if isinstance(exc, GraderTimeout):
        inside = f" (it was in {where})" if where else ""
        return (
            f"did not finish within the {timeout:g} s time limit{inside}: an endless loop, "
            "or code far slower than it needs to be"
        )
    text = str(exc).split("\nassert ")[0].strip()
    if isinstance(exc, AssertionError | TaskReturnError):
        return text or f"{type(exc).__name__} in {where or 'the grader'}"
    if isinstance(exc, NotImplementedError) and "task:" in text:
        return f"NotImplementedError: {text}"  # a stub: the message names the task
    message = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
    return f"{message} (raised in {where})" if where else message


# --- checking what task methods return ------------------------------------------------
def rtpy_classes() -> dict[str, type]:
    """Every class defined in an imported rtpy module, by name."""
    found = {}
    for name, module in list(sys.modules.items()):
        if name == "rtpy" or name.startswith("rtpy."):
            for value in vars(module).values():
                if isinstance(value, type) and value.__module__.startswith("rtpy"):
                    found.setdefault(value.__name__, value)
    return found


def expected_return(function, classes: dict[str, type]) -> tuple[bool, list[type]]:
    """(may return None, the annotated rtpy classes) from the return annotation;
    (True, []) when there is none, and no classes when it names other types."""
    annotation = getattr(function, "__annotations__", {}).get("return")
    if annotation is None:
        return True, []
    if not isinstance(annotation, str):
        annotation = getattr(annotation, "__name__", str(annotation))
    text = annotation.strip()
    if text.startswith("Optional[") and text.endswith("]"):
        text = f"{text[len('Optional[') : -1]} | None"
    parts = [p.strip().strip("'\"") for p in text.split("|")]
    may_be_none = "None" in parts
    names = [p for p in parts if p != "None"]
    if not all(n in classes for n in names):
        return may_be_none, []  # a builtin or generic type: only None is checked
    return may_be_none, [classes[n] for n in names]


def checked(function, label: str, classes: dict[str, type]):
    """function, wrapped to fail with TaskReturnError when it returns None where its
    annotation does not allow it, or an object that is not of an annotated rtpy class
    or one of its rtpy base classes (a Vec3 where a Color is expected is accepted);
    function itself when there is nothing to check."""
    may_be_none, expected = expected_return(function, classes)
    if may_be_none and not expected:
        return function
    allowed = tuple({base for c in expected for base in c.__mro__ if base is not object})
    wanted = " or ".join(sorted(c.__name__ for c in expected)) or "a value"

    @functools.wraps(function)
    def task(*args, **kwargs):
        result = function(*args, **kwargs)
        if result is None:
            if not may_be_none:
                raise TaskReturnError(
                    f"{label} returned None, expected {wanted}: is a `return` missing?"
                )
        elif allowed and not isinstance(result, allowed):
            raise TaskReturnError(
                f"{label} returned a value of type {type(result).__name__}, expected {wanted}"
            )
        return result

    return task


def resolve(path: str, qualname: str):
    """(owner, attribute name, raw attribute) of the function `qualname` of the module
    file `path` (rtpy/a/b.py); None when it is not there (a nested function)."""
    if "<locals>" in qualname:
        return None
    module_name = path.removesuffix(".py").removesuffix("/__init__").replace("/", ".")
    owner = importlib.import_module(module_name)
    *classes, name = qualname.split(".")
    for part in classes:
        owner = getattr(owner, part, None)
        if owner is None:
            return None
    raw = vars(owner).get(name)
    return None if raw is None else (owner, name, raw)


def replace_everywhere(original, replacement) -> None:
    """Replace every reference to `original` held by an rtpy module or a class of one
    (a function imported by name, an alias such as Blinn = BlinnPhong's method)."""
    for name, module in list(sys.modules.items()):
        if not (name == "rtpy" or name.startswith("rtpy.")) or module is None:
            continue
        for key, value in list(vars(module).items()):
            if value is original:
                setattr(module, key, replacement)
            elif isinstance(value, type) and value.__module__.startswith("rtpy"):
                for attr, member in list(vars(value).items()):
                    if member is original:
                        setattr(value, attr, replacement)


def install_return_checks(tasks: list[dict]) -> list[str]:
    """Wrap each task function ({"path", "function"}) with `checked`; the labels of
    those wrapped."""
    import rtpy  # noqa: F401  (every module, so that every reference is seen)

    classes = rtpy_classes()
    wrapped = []
    for task in tasks:
        found = resolve(task["path"], task["function"])
        if found is None:
            continue
        owner, name, raw = found
        kind = type(raw) if isinstance(raw, staticmethod | classmethod) else None
        function = raw.__func__ if kind else raw
        if not isinstance(function, types.FunctionType):
            continue
        label = f"{task['function']} ({task['path']})"
        new = checked(function, label, classes)
        if new is function:
            continue
        replacement = kind(new) if kind else new
        setattr(owner, name, replacement)
        replace_everywhere(raw, replacement)
        if kind:
            replace_everywhere(function, new)
        wrapped.append(label)
    return wrapped


# --- the plugin -----------------------------------------------------------------------
def _on_alarm(signum, frame) -> None:
    raise GraderTimeout


class ChildPlugin:
    """pytest plugin: events, time limits, messages (see the module docstring)."""

    def __init__(self, events: Path, config: dict, collect_only: bool = False) -> None:
        self.events = open(events, "a", encoding="utf-8")  # noqa: SIM115 (for the session)
        self.stack = open(f"{events}.stack", "w", encoding="utf-8")  # noqa: SIM115
        self.base = Path.cwd().resolve()
        self.config = config
        self.timeout = float(config.get("test_timeout", 60.0))
        self.task_files = set(config.get("task_files", []))
        self.collect_only = collect_only
        self.errors: list[str] = []
        self.failure: dict[str, str] = {}
        self.renders: set[str] = set()
        self.current: str | None = None

    def emit(self, **event) -> None:
        self.events.write(json.dumps(event) + "\n")
        self.events.flush()

    def pytest_configure(self, config) -> None:
        config.addinivalue_line("markers", "points(n): points a grader test is worth")
        if not self.collect_only:
            install_return_checks(self.config.get("task_functions", []))
            self.watch_renders()

    def watch_renders(self) -> None:
        """Record the tests that call render_stack (the render graders)."""
        from . import graders

        original = graders.render_stack

        @functools.wraps(original)
        def render_stack(*args, **kwargs):
            if self.current is not None:
                self.renders.add(self.current)
            return original(*args, **kwargs)

        replace_everywhere(original, render_stack)

    def pytest_collectreport(self, report) -> None:
        if report.failed:
            crash = getattr(report.longrepr, "reprcrash", None)
            text = crash.message if crash is not None else str(report.longrepr)
            self.errors.append(f"{report.nodeid}: {text.strip()}")

    def pytest_collection_finish(self, session) -> None:
        self.emit(
            event="collected", tests=[collected_test(i) for i in session.items], errors=self.errors
        )

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(self, item, nextitem):
        self.current = item.nodeid
        self.emit(event="start", nodeid=item.nodeid)
        previous = signal.signal(signal.SIGALRM, _on_alarm)
        signal.setitimer(signal.ITIMER_REAL, self.timeout)
        faulthandler.dump_traceback_later(self.timeout + DUMP_GRACE, exit=True, file=self.stack)
        try:
            yield
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            faulthandler.cancel_dump_traceback_later()
            signal.signal(signal.SIGALRM, previous)
            self.current = None
        self.emit(
            event="result",
            nodeid=item.nodeid,
            passed=item.nodeid not in self.failure,
            output=self.failure.get(item.nodeid, ""),
            renders=item.nodeid in self.renders,
        )

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_makereport(self, item, call):
        report = (yield).get_result()
        if item.nodeid in self.failure or not (report.failed or report.skipped):
            return
        if report.skipped:
            reason = report.longrepr[-1] if isinstance(report.longrepr, tuple) else ""
            self.failure[item.nodeid] = f"skipped: {reason}"
            return
        exc = call.excinfo.value if call.excinfo is not None else None
        if exc is None:
            message = str(report.longrepr).strip().splitlines()[-1:] or ["failed"]
            message = message[0]
        else:
            message = describe(exc, self.base, self.task_files, self.timeout)
        self.failure[item.nodeid] = message if call.when == "call" else f"({call.when}) {message}"


def collected_test(item) -> dict:
    """What the parent needs of a collected test: its id, the name shown (the first line
    of its docstring), its points and whether it is a hidden check."""
    mark = item.get_closest_marker("points")
    doc = (getattr(item.function, "__doc__", None) or "").strip().splitlines()
    name = doc[0] if doc else item.name
    if "[" in item.name:
        name += item.name[item.name.index("[") :]
    return {
        "nodeid": item.nodeid,
        "name": name,
        "points": float(mark.args[0]) if mark else 1.0,
        "hidden": HIDDEN_PART in f"/{item.nodeid}",
    }


def pytest_args(nodeids: list[str], collect_only: bool) -> list[str]:
    return [
        "-q",
        "-p",
        "no:cacheprovider",
        "--tb=no",
        "-o",
        "addopts=",
        "--continue-on-collection-errors",
        *(["--collect-only"] if collect_only else []),
        *nodeids,
    ]


def main(argv: list[str] | None = None) -> int:
    import pytest

    args = list(sys.argv[1:] if argv is None else argv)
    collect_only = "--collect" in args
    args = [a for a in args if a != "--collect"]
    events, config_path, *nodeids = args
    config = json.loads(Path(config_path).read_text(encoding="utf-8"))
    import rtpy

    here = Path.cwd().resolve()
    if relative(rtpy.__file__, here) is None:
        raise SystemExit(f"rtpy was imported from {rtpy.__file__}, not from {here}")
    plugin = ChildPlugin(Path(events), config, collect_only)
    status = pytest.main(pytest_args(nodeids, collect_only), plugins=[plugin])
    plugin.emit(event="done", status=int(status))
    os._exit(0)  # a thread the student's code left running cannot keep the process alive


if __name__ == "__main__":
    sys.exit(main())
