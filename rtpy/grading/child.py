"""The process that runs a student's code: it computes, and never judges.

The judge (rtpy.grading.sandbox) starts

    python -I -c "<BOOT>" WORK CONFIG START_TIMEOUT

in a copy of the assignment where only the task files are the student's (on
Gradescope as an unprivileged user who cannot read the graders, the hidden checks or
the references, nor write anything but its own temporary folder). This module then

- imports rtpy from that copy, wraps each task method so that returning None, or an
  object that is not of the annotated rtpy class, raises TaskReturnError naming it,
  and imports the probes (rtpy.grading.probes and the week's assignments/weekNN/
  probes.py);
- reads requests, one frame each, from its standard input: {"id", "probe", "inputs",
  "seconds"}; runs the probe with a timer of `seconds` (ProbeTimeout, a
  BaseException, so `except Exception` in the student's code does not swallow it);
- writes one reply per request to its standard output: {"id", "value"} or {"id", "error":
  {"kind": "exception" | "timeout" | "unsendable", "type", "message", "where":
  [function, file, line] or null}}, where names the innermost frame of a task file
  (else of rtpy).

Before any student code runs, the replies' channel is moved to a file descriptor of
its own and standard output is pointed at standard error, which the judge reads and
bounds: what the student's code prints cannot mix with the replies. Nothing it says
is believed: the judge checks every answer's form, and every verdict is made
there.
"""

from __future__ import annotations

import faulthandler
import functools
import importlib
import json
import os
import signal
import sys
import traceback
import types
from pathlib import Path

from .protocol import ProtocolError, encode, read_frame, write_frame


class ProbeTimeout(BaseException):
    """A probe ran past its time (raised from SIGALRM)."""


class TaskReturnError(TypeError):
    """A task method returned None, or an object of the wrong type."""


# --- where in the student's code ------------------------------------------------------
def relative(filename: str, base: Path) -> str | None:
    """filename relative to base as a posix path, or None outside it."""
    try:
        return Path(filename).resolve().relative_to(base).as_posix()
    except (ValueError, OSError, RuntimeError):  # RuntimeError: a symlink loop
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


# --- serving probes ---------------------------------------------------------------------
def _on_alarm(signum, frame) -> None:
    raise ProbeTimeout


def error_reply(exc: BaseException, kind: str, base: Path, task_files: set[str]) -> dict:
    where = student_frame(exc.__traceback__, base, task_files)
    return {
        "kind": kind,
        "type": type(exc).__name__,
        "message": str(exc)[:2000],
        "where": list(where) if where else None,
        "traceback": "".join(traceback.format_exception(exc, limit=-12))[-6000:],
    }


def serve(request: dict, probes: dict, base: Path, task_files: set[str]) -> dict:
    """The reply to one request."""
    reply = {"id": request.get("id")}
    found = probes.get(request.get("probe"))
    if found is None:
        return reply | {"error": {"kind": "unknown", "type": "", "message": "", "where": None}}
    timer = hasattr(signal, "setitimer")  # not on Windows: the judge's deadline alone
    if timer:
        signal.setitimer(signal.ITIMER_REAL, max(0.001, float(request.get("seconds", 60.0))))
    try:
        reply["value"] = found.function(**request.get("inputs", {}))
    except ProbeTimeout as exc:
        reply["error"] = error_reply(exc, "timeout", base, task_files)
    except Exception as exc:  # the student's exception: reported, with where it was raised
        reply["error"] = error_reply(exc, "exception", base, task_files)
    finally:
        if timer:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
    return reply


def load_probes(paths: list[str]) -> dict:
    """rtpy.grading.probes and the probe modules at `paths` (files of the work copy)."""
    from .probes import load_probes as load

    return load(paths)


def main(config_path: str, replies_fd: int) -> None:
    replies = os.fdopen(replies_fd, "wb")
    config = json.loads(Path(config_path).read_text(encoding="utf-8"))
    base = Path.cwd().resolve()
    import rtpy

    if relative(rtpy.__file__, base) is None:
        raise SystemExit(f"rtpy was imported from {rtpy.__file__}, not from {base}")
    task_files = set(config.get("task_files", []))
    install_return_checks(config.get("task_functions", []))
    probes = load_probes(config.get("probe_modules", []))
    faulthandler.cancel_dump_traceback_later()
    if hasattr(signal, "SIGALRM"):
        signal.signal(signal.SIGALRM, _on_alarm)
    requests = sys.stdin.buffer
    while True:
        try:
            request = read_frame(requests)
        except ProtocolError:  # the judge closed the pipe: grading is over
            break
        reply = serve(request, probes, base, task_files)
        try:
            frame = encode(reply)
        except TypeError as exc:  # the probe returned something that is not plain data
            error = error_reply(exc, "unsendable", base, task_files)
            frame = encode({"id": reply["id"], "error": error})
        write_frame(replies, frame)
    os._exit(0)  # a thread the student's code left running cannot keep the process alive


def boot(config_path: str, replies_fd: int) -> None:
    """main(), and the traceback of a failure to start on standard error."""
    try:
        main(config_path, replies_fd)
    except BaseException:
        traceback.print_exc()
        sys.stderr.flush()
        os._exit(3)


# The child's first lines, before anything of rtpy (and so of the student's) is
# imported: the replies' channel moves off standard output, and an import that hangs
# (a loop at a task file's top level) is ended with its stack on standard error.
# Arguments: WORK CONFIG START_TIMEOUT.
BOOT = """import faulthandler, os, sys
replies = os.dup(1)
os.dup2(2, 1)
faulthandler.dump_traceback_later(float(sys.argv[3]), exit=True)
sys.path.insert(0, sys.argv[1])
from rtpy.grading.child import boot
boot(sys.argv[2], replies)
"""
