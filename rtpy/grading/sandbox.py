"""The judge's side of the process that runs a student's code (rtpy.grading.child).

`Child` starts that process, sends it one request at a time and reads its reply, each
with a deadline (a child that stops reading its requests cannot block the judge
either): a child that is late, dies, closes the pipe or breaks the protocol is
stopped (its whole process group, and on Linux as root every process of the sandbox
user, killed by the judge itself: rtpy.grading.confinement), and the call raises
ChildFailure; the next call starts a new child. Only plain data crosses
(rtpy.grading.protocol), and a reply is read only up to the size its request's form
implies. The child's own output is read into a bounded buffer for the instructor's
log, so printing cannot flood or block anything.

Isolation (`Isolation`): as root (Gradescope), the child runs as an unprivileged user
(SANDBOX_USER) in a work copy it can read but not change, with its own temporary
folder, limits on CPU time, memory, file size and processes (setrlimit), a scrubbed
environment, Python's isolated mode, and its own session. Such a child cannot signal
the judge, read what is readable by root alone (the autograder's source: graders,
hidden checks, references; results/) or write anything outside its folder and the
shared temporary folders (emptied of its files at the end), and where the kernel
allows, those folders and its own are small tmpfs of a mount namespace of its own
(rtpy.grading.private_space: bounded in bytes and files, gone with the child). On
Linux a seccomp filter refuses it every socket but a local one (no network).
Without root (a laptop) the same protocol, limits, filter and session, but the user
is the judge's:
docs/instructors.md says what that leaves open.

`InProcess` runs the probes in the judge's own process, through the same codec: for
rtpy's tests, where planted mistakes patch rtpy in place, and for making references.
"""

from __future__ import annotations

import json
import os
import queue
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from .child import BOOT, ProbeTimeout, error_reply, load_probes, serve
from .confinement import kill_user
from .protocol import (
    REPLY_FRAME,
    ProtocolError,
    Schema,
    decode,
    encode,
    most_values,
    printable,
    read_body,
    read_size,
)

SANDBOX_USER = "rtpy-sandbox"
GRACE = 5.0  # seconds past a probe's own time limit before the child is killed
START_TIMEOUT = 60.0  # seconds for the child to import rtpy and the probes
OUTPUT_LIMIT = 64 * 1024  # characters of the child's output kept (the first and the last)


class ChildFailure(Exception):
    """The child did not answer: it was too slow, died or broke the protocol. Its
    message is the judge's own, for the student."""


class StudentError(Exception):
    """The student's code raised (or returned what cannot be sent); the message is
    worded by the judge."""

    def __init__(self, message: str, where: tuple[str, str, int] | None = None) -> None:
        super().__init__(message)
        self.where = where


@dataclass
class Isolation:
    """How the child is confined. user: the name of the unprivileged user to run as
    (used only by a root judge); memory_mb, cpu_seconds, file_mb, processes: its
    resource limits (None: no limit)."""

    user: str | None = None
    memory_mb: int | None = 4096
    cpu_seconds: int | None = None
    file_mb: int | None = 64
    processes: int | None = 16
    home: Path | None = None  # the child's HOME and TMPDIR (its user's, when it has one)
    socket_filter: object = None  # a confinement.SocketFilter installed before Python starts
    space: object = None  # a private_space.PrivateSpace: the writable space bounded (root)

    def preexec(self, space=None, ids: tuple[int, int] | None = None, cwd: Path | None = None):
        """The function subprocess runs in the child before it starts Python: with a
        space (private_space.PrivateSpace.for_child), its mounts are made as root, then
        the child becomes the user `ids` and goes back to `cwd` (its folder, mounted
        again)."""
        import resource

        limits = [
            (resource.RLIMIT_CORE, 0),
            (resource.RLIMIT_AS, self.memory_mb and self.memory_mb * 2**20),
            (resource.RLIMIT_CPU, self.cpu_seconds),
            (resource.RLIMIT_FSIZE, self.file_mb and self.file_mb * 2**20),
        ]
        if self.user is not None:  # per user: meaningful only for a user of its own
            limits.append((resource.RLIMIT_NPROC, self.processes))
        socket_filter = self.socket_filter

        def apply() -> None:
            if space is not None:
                space.enter()
                os.setgroups([])
                os.setgid(ids[1])
                os.setuid(ids[0])
                os.chdir(cwd)
            for kind, value in limits:
                if value is not None:
                    resource.setrlimit(kind, (value, value))
            if socket_filter is not None:
                socket_filter.install()

        return apply


def sandbox_ids(user: str | None) -> tuple[int, int] | None:
    """(uid, gid) of `user` when this process is root and the user exists, else None."""
    if user is None or not hasattr(os, "geteuid") or os.geteuid() != 0:
        return None
    import pwd

    try:
        entry = pwd.getpwnam(user)
    except KeyError:
        return None
    return entry.pw_uid, entry.pw_gid


def child_environment(work: Path, home: Path | None) -> dict[str, str]:
    """The scrubbed environment of the child: nothing of the judge's but a minimal PATH."""
    env = {
        "PATH": "/usr/local/bin:/usr/bin:/bin",
        "LANG": "C.UTF-8",
        "PYTHONDONTWRITEBYTECODE": "1",
        "PYTHONIOENCODING": "utf-8",
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
        "MPLBACKEND": "Agg",
    }
    if home is not None:
        env.update(HOME=str(home), TMPDIR=str(home))
    if sys.platform == "win32":  # Python needs these to start there
        for key in ("SYSTEMROOT", "SYSTEMDRIVE", "TEMP", "TMP"):
            if key in os.environ:
                env[key] = os.environ[key]
    return env


class Replies:
    """The child's replies, read by a thread into a queue (portable: no select on
    pipes), so the judge can wait for one with a deadline. Each is read only up to
    `limit` bytes and `values` commas (set for the request it answers)."""

    def __init__(self, stream) -> None:
        self.queue: queue.Queue = queue.Queue()
        self.limit, self.values = REPLY_FRAME, most_values(None, None)
        threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream) -> None:
        while True:
            try:
                size = read_size(stream)  # then the limits of the request it answers
                self.queue.put(read_body(stream, size, self.limit, self.values))
            except (ProtocolError, OSError, ValueError, MemoryError) as err:
                self.queue.put(ProtocolError(str(err)))
                return

    def get(self, deadline: float):
        try:
            item = self.queue.get(timeout=max(0.0, deadline - time.monotonic()))
        except queue.Empty:
            raise TimeoutError from None
        if isinstance(item, Exception):
            raise item
        return item


@dataclass
class Child:
    """The student's process, started on first use.

    work: the folder holding the rtpy the student's code is part of; config: what the
    child needs (task_files, task_functions, probe_modules: paths inside work)."""

    work: Path
    config: dict
    isolation: Isolation = field(default_factory=Isolation)
    python: str = sys.executable
    log: list[str] = field(default_factory=list)  # for the instructor
    start_timeout: float = START_TIMEOUT  # seconds to import rtpy and the probes
    deadline: float | None = None  # time.monotonic() past which no call waits
    config_dir: Path | None = None  # where its configuration is written (the judge's, readable)
    _proc: subprocess.Popen | None = None
    _replies: Replies | None = None
    _output: list[bytes] = field(default_factory=list)
    _next_id: int = 0
    _config_file: Path | None = None

    # --- the process -------------------------------------------------------------
    def start(self) -> None:
        home = self.isolation.home
        # A file of the judge's own, never in the child's folders: as root the judge
        # would follow a link the student's code left there.
        fd, name = tempfile.mkstemp(prefix="rtpy-child-", suffix=".json", dir=self.config_dir)
        os.close(fd)
        config_path = self._config_file = Path(name)
        os.chmod(config_path, 0o644)
        config_path.write_text(json.dumps(self.config), encoding="utf-8")
        command = [self.python, "-I", "-c", BOOT, str(self.work), str(config_path)]
        command.append(str(self.start_timeout))
        options: dict = {}
        ids = sandbox_ids(self.isolation.user)
        space = self.isolation.space if ids is not None else None
        if space is not None:  # the user is taken in preexec, after the mounts
            python = os.path.abspath(self.python)
            prefixes = {Path(p).parents[1] for p in (python, os.path.realpath(python))}
            keep = [self.work, config_path, *prefixes]
            space = space.for_child(keep, home, ids)
        elif ids is not None:
            options.update(user=ids[0], group=ids[1], extra_groups=[])
        if os.name == "posix":
            preexec = self.isolation.preexec(space, ids, self.work)
            options.update(start_new_session=True, preexec_fn=preexec)
        self._proc = subprocess.Popen(
            command,
            cwd=self.work,
            env=child_environment(self.work, home),
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            **options,
        )
        self._replies = Replies(self._proc.stdout)
        self._output = []
        threading.Thread(target=self._drain, args=(self._proc.stderr,), daemon=True).start()

    def _drain(self, stream) -> None:
        """Keep the first and the last OUTPUT_LIMIT // 2 bytes of the child's output."""
        kept, tail = 0, b""
        for chunk in iter(lambda: stream.read1(65536), b""):
            if kept < OUTPUT_LIMIT // 2:
                self._output.append(chunk[: OUTPUT_LIMIT // 2 - kept])
                kept += len(self._output[-1])
            else:
                tail = (tail + chunk)[-OUTPUT_LIMIT // 2 :]
        if tail:
            self._output.append(b"\n[...]\n" + tail)

    def output(self) -> str:
        return b"".join(self._output).decode("utf-8", errors="replace")

    def stop(self) -> None:
        """End the child and everything it started (killed first: closing a pipe it does
        not read could block)."""
        proc, self._proc = self._proc, None
        if proc is None:
            return
        kill_tree(proc, self.isolation.user)
        try:
            proc.stdin.close()
        except OSError:
            pass
        if self._config_file is not None:
            self._config_file.unlink(missing_ok=True)
            self._config_file = None
        output = self.output().strip()
        if output:
            self.log.append(f"the student's process printed:\n{output[-4000:]}")

    # --- one request ----------------------------------------------------------------
    def call(self, probe: str, inputs: dict, seconds: float, returns: Schema | None = None):
        """The probe's value for inputs, computed within `seconds`; StudentError when
        the student's code raised, ChildFailure when the child did not answer. The
        reply may be as large as an answer of the form `returns` (for as many cases
        or seeds as inputs holds) can be."""
        if self.deadline is not None and time.monotonic() >= self.deadline:
            raise ChildFailure("not asked: the time limit for the whole submission was reached")
        deadline = time.monotonic() + seconds + GRACE
        if self._proc is None:
            self.start()
            deadline += self.start_timeout
        if self.deadline is not None:
            deadline = min(deadline, self.deadline)
        self._next_id += 1
        request = {"id": self._next_id, "probe": probe, "inputs": inputs, "seconds": seconds}
        asked = [len(v) for k, v in inputs.items() if k in ("cases", "seeds") and is_list(v)]
        self._replies.values = most_values(returns, max(asked) if asked else None)
        try:
            sent = send_within(self._proc.stdin, encode(request), deadline)
        except OSError:
            raise ChildFailure(self._ended("before it was asked anything")) from None
        if not sent:
            self.stop()
            raise ChildFailure(f"did not read what it was asked within {seconds:g} s: stopped")
        try:
            reply = self._replies.get(deadline)
        except TimeoutError:
            self.stop()
            raise ChildFailure(f"did not finish within {seconds:g} s: stopped") from None
        except ProtocolError as err:
            raise ChildFailure(self._ended(str(err))) from None
        return answer(reply, self._next_id, self)

    def _ended(self, what: str) -> str:
        """The judge's words for a child that stopped answering (it is stopped)."""
        proc = self._proc
        status = None
        if proc is not None:
            try:
                status = proc.wait(timeout=2.0)
            except subprocess.TimeoutExpired:
                pass
        self.stop()
        if status is None:
            return f"the grading process broke the protocol ({what}), and was stopped"
        if status < 0:
            name = signal.Signals(-status).name if -status in signal.valid_signals() else status
            return f"the grading process was ended by signal {name} (the memory ran out?)"
        return f"the grading process ended with exit status {status}"


def answer(reply, request_id: int, child) -> object:
    """The value of a reply, or the StudentError / ChildFailure it stands for."""
    if not isinstance(reply, dict) or reply.get("id") != request_id:
        child.stop()
        raise ChildFailure("the grading process answered something that was not asked")
    if "value" in reply and "error" not in reply:
        return reply["value"]
    raise student_error(reply.get("error"), child.config.get("task_files", []))


NAME = re.compile(r"[A-Za-z_][\w.<>]{0,99}")
FILE = re.compile(r"rtpy/[\w/]{1,150}\.py")


def where_text(where, task_files) -> tuple[str, tuple[str, str, int] | None]:
    """(" (raised in f (file, line n))", the frame) for a reported frame that names a
    plausible function, an rtpy file and a line; ("", None) for anything else."""
    if not (isinstance(where, list) and len(where) == 3):
        return "", None
    function, file, line = where
    if not (isinstance(function, str) and NAME.fullmatch(function)):
        return "", None
    if not (isinstance(file, str) and (file in task_files or FILE.fullmatch(file))):
        return "", None
    if not (isinstance(line, int) and not isinstance(line, bool) and 0 < line < 10**6):
        return "", None
    return f"{function} ({file}, line {line})", (function, file, line)


def student_error(error, task_files) -> Exception:
    """The exception a reply's error stands for, worded by the judge: the student's
    exception type and (bounded) message, with where it was raised."""
    if not isinstance(error, dict):
        return ChildFailure("the grading process sent an error the judge cannot read")
    kind, where = error.get("kind"), error.get("where")
    place, frame = where_text(where, task_files)
    if kind == "timeout":
        inside = f" (it was in {place})" if place else ""
        return ChildFailure(
            f"did not finish within its time limit{inside}: an endless loop, or code far "
            "slower than it needs to be"
        )
    if kind == "unknown":
        return ChildFailure("the grading process does not know this probe")
    name = error.get("type")
    name = name if isinstance(name, str) and NAME.fullmatch(name) else "an exception"
    message = printable(error.get("message") if isinstance(error.get("message"), str) else "")
    if kind == "unsendable":
        return StudentError(f"returned a value that is not a number or a vector: {message}")
    if name in ("AssertionError", "TaskReturnError"):
        text = message or f"{name} in {place or 'the code'}"
    elif name == "NotImplementedError" and "task:" in message:
        text = f"NotImplementedError: {message}"  # a stub: the message names the task
    else:
        text = f"{name}: {message}" if message else name
        if place:
            text += f" (raised in {place})"
    error_ = StudentError(text, frame)
    trace = error.get("traceback")
    if isinstance(trace, str) and trace:  # shown by plain pytest, never in results
        error_.add_note("The student's process said:\n" + printable(trace, 6000))
    return error_


def is_list(value) -> bool:
    return isinstance(value, list | tuple)


def send_within(stream, frame: bytes, deadline: float) -> bool:
    """Write frame to the child's request pipe by a thread of its own (unbuffered: the
    pipe's buffered writer is never used, so closing it cannot block); whether it was
    all written by the deadline. OSError when the pipe is closed."""
    fd = stream.fileno()
    failed: list[OSError] = []

    def write() -> None:
        view = memoryview(frame)
        try:
            while view:
                view = view[os.write(fd, view) :]
        except OSError as err:
            failed.append(err)

    writer = threading.Thread(target=write, daemon=True)
    writer.start()
    writer.join(max(0.0, deadline - time.monotonic()))
    if failed:
        raise failed[0]
    return not writer.is_alive()


def kill_tree(proc: subprocess.Popen, user: str | None) -> None:
    """Kill proc's process group, then, as root with a sandbox user, every process of
    that user (a descendant that left the group), from this process, and reap proc."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError, AttributeError):
        proc.kill()
    ids = sandbox_ids(user)
    if ids is not None:
        kill_user(ids[0])
    proc.wait()


@dataclass
class InProcess:
    """The probes run in this process, through the same codec (for tests and for
    making references): no isolation at all."""

    config: dict
    work: Path = field(default_factory=Path.cwd)
    log: list[str] = field(default_factory=list)
    _probes: dict | None = None

    def call(self, probe: str, inputs: dict, seconds: float, returns: Schema | None = None):
        if self._probes is None:
            self._probes = load_probes(self.config.get("probe_modules", []))
        request = decode(
            encode({"id": 1, "probe": probe, "inputs": inputs, "seconds": seconds})[4:]
        )
        task_files = set(self.config.get("task_files", []))
        timed = hasattr(signal, "SIGALRM") and threading.current_thread() is threading.main_thread()
        previous = signal.signal(signal.SIGALRM, _on_alarm) if timed else None
        try:
            reply = serve(request, self._probes, self.work.resolve(), task_files)
        finally:
            if timed:
                signal.signal(signal.SIGALRM, previous)
        try:
            frame = encode(reply)
        except TypeError as exc:
            error = error_reply(exc, "unsendable", self.work.resolve(), task_files)
            frame = encode({"id": 1, "error": error})
        return answer(decode(frame[4:]), 1, self)

    def stop(self) -> None:
        pass


def _on_alarm(signum, frame) -> None:
    raise ProbeTimeout
