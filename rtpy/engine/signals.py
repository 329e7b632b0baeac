"""SIGINT (Ctrl-C) and SIGTERM on the command line: both stop rtpy the same way.

The command line (rtpy/__main__.py, rtpy.cli.main) handles the two signals from the
moment it starts importing until it exits:

- while it starts (imports, parsing the command line), a signal is only recorded
  (`defer`): an import cut in the middle would end in a traceback; the command then
  stops before doing anything;
- while it works (`stop_on_signals`), the first signal raises KeyboardInterrupt, so a
  render stops and keeps what is finished, a write is undone (rtpy.engine.files);
- a second signal ends the process at once: worker processes are killed, temporary
  files removed, and nothing is half-written.

The exit status is that of a process the signal ended: 128 + its number, 130 for
SIGINT and 143 for SIGTERM (EXIT_STATUS). Windows has no SIGTERM to catch (ending a
process there is TerminateProcess, which no handler sees); Ctrl-C works as above.
A program that imports rtpy keeps its own handlers: nothing here is installed then.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from .exit_status import EXIT_SIGNALLED

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
EXIT_STATUS = EXIT_SIGNALLED  # 130 after SIGINT, 143 after SIGTERM
NOTHING_WRITTEN = "interrupted: nothing was written"

_received: list[int] = []  # the signals received, in order
# While the work is being finished (finish_from_here): how many signals had come
# when it began; None while a first signal raises.
_finishing: int | None = None


def received() -> int | None:
    """The first signal received while rtpy's handlers were installed, or None."""
    return _received[0] if _received else None


def exit_status() -> int:
    """The exit status for a stop: 130 after SIGINT (also a KeyboardInterrupt that no
    signal raised), 143 after SIGTERM."""
    return EXIT_STATUS[received() or signal.SIGINT]


def stopped(what: str) -> int:
    """The end of a command a signal stopped: remove the temporary files of writes it
    cut short, say on stderr what happened (`what`), return the exit status."""
    _remove_temporary_files()
    # rtpy._checks.one_line (a path with a line break stays on one line) when it is
    # imported whole: this may run after an import a signal cut short.
    one_line = getattr(sys.modules.get("rtpy._checks"), "one_line", str)
    print(f"rtpy: {one_line(what)}", file=sys.stderr)
    return exit_status()


def caused_by_interrupt(err: BaseException) -> bool:
    """err is a KeyboardInterrupt or was raised by one: an import that a Ctrl-C cuts
    short may end in an ImportError or a RuntimeError (from __set_name__) from it."""
    seen: BaseException | None = err
    while seen is not None:
        if isinstance(seen, KeyboardInterrupt):
            return True
        seen = seen.__cause__ or seen.__context__
    return False


def defer() -> None:
    """From now on a signal is recorded, not acted on, until `stop_on_signals`; a
    second one ends the process at once. For the command line's start-up."""
    _install(_record)


@contextmanager
def stop_on_signals() -> Iterator[None]:
    """Within: the first SIGINT or SIGTERM raises KeyboardInterrupt (at once if one was
    recorded while starting), a second one ends the process at once (`end_now`). The
    previous handlers are restored after."""
    global _finishing
    if signal.getsignal(signal.SIGINT) not in (_record, _raise):
        _received.clear()  # a new command in this process
    _finishing = None
    try:
        with _handled_by(_raise):
            if _received:
                raise KeyboardInterrupt  # received while starting
            yield
    finally:
        _finishing = None


def finish_from_here(absorbed: bool = False) -> None:
    """From now on (until `raise_again` or the end of `stop_on_signals`) a first
    signal is recorded, not raised: the work is done (the last pass of a render is
    in, or it stopped) and what is left finishes it: ending the workers, writing the
    image. A second signal ends the process at once. Outside rtpy's handlers it
    changes nothing (a program that imports rtpy keeps its own). absorbed: the last
    signal's KeyboardInterrupt came just before and was taken as this finish (the
    render was done), so `raise_again` counts it as recorded meanwhile."""
    global _finishing
    if _finishing is None:
        _finishing = max(0, len(_received) - absorbed)


def raise_again() -> None:
    """Undo `finish_from_here`: signals raise KeyboardInterrupt again, and one
    recorded meanwhile raises it now (a command that goes on to other work, such as
    bench's next render, stops as the signal asked)."""
    global _finishing
    before, _finishing = _finishing, None
    recorded = before is not None and len(_received) > before
    if recorded and signal.getsignal(signal.SIGINT) is _raise:
        raise KeyboardInterrupt


@contextmanager
def finishing() -> Iterator[None]:
    """Within (inside `stop_on_signals`): a first signal is recorded, not raised, for
    work that is better finished than undone (writing a finished image); the
    command then ends with its status. A second one ends the process at once."""
    with _handled_by(_record):
        yield


@contextmanager
def finishing_if_handled() -> Iterator[None]:
    """`finishing` where rtpy's handlers stop the work (its command line); nothing
    elsewhere: a program that imports rtpy keeps its own handlers (a Ctrl-C there
    undoes the write, as any atomic write, rtpy.engine.files)."""
    if threading.current_thread() is threading.main_thread() and (
        signal.getsignal(signal.SIGINT) is _raise
    ):
        with finishing():
            yield
    else:
        yield


@contextmanager
def held() -> Iterator[None]:
    """Within: SIGINT and SIGTERM are held, not handled (the process started within
    is born with them blocked); after, each one held goes to the handler installed
    before, whatever it is (a program's own, Python's KeyboardInterrupt, rtpy's).
    For code that a KeyboardInterrupt must not cut in the middle, such as starting
    a pool's processes, where fork runs Python code whose exceptions are lost."""
    if threading.current_thread() is not threading.main_thread():
        yield  # only the main thread handles signals
        return
    caught: list[int] = []
    try:
        with _handled_by(lambda signum, frame: caught.append(signum)):
            _block(True)
            try:
                yield
            finally:
                _block(False)  # a signal pending meanwhile is caught now
    finally:
        for signum in caught:
            signal.raise_signal(signum)


@contextmanager
def _handled_by(handler) -> Iterator[None]:
    """Within: `handler` handles SIGINT and SIGTERM; the previous handlers after."""
    previous = {signum: signal.getsignal(signum) for signum in STOP_SIGNALS}
    _install(handler)
    try:
        yield
    finally:
        for signum, before in previous.items():
            signal.signal(signum, before)


def _block(block: bool) -> None:
    """Block SIGINT and SIGTERM in this thread (pending, not lost), or unblock them
    (POSIX; Windows has no signal masks)."""
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_BLOCK if block else signal.SIG_UNBLOCK, STOP_SIGNALS)


def unblock() -> None:
    """Deliver SIGINT and SIGTERM again, in a process started within `held`."""
    _block(False)


def _install(handler) -> None:
    for signum in STOP_SIGNALS:
        signal.signal(signum, handler)


def _record(signum: int, frame) -> None:
    if _received:
        end_now()
    _received.append(signum)


def _raise(signum: int, frame) -> None:
    _record(signum, frame)
    if _finishing is None:
        raise KeyboardInterrupt


def end_now() -> None:
    """End the process at once, without unwinding: kill the worker processes, remove
    the temporary files of writes in progress (their targets are untouched), say so."""
    # Only what is imported already, and whole: this may run in the middle of an import.
    active_children = getattr(sys.modules.get("multiprocessing"), "active_children", list)
    children = active_children()
    for child in children:
        child.kill()
    for child in children:
        child.join()  # none is left running, or a zombie, when this process ends
    _remove_temporary_files()
    os.write(2, b"\nrtpy: interrupted again: stopped at once, nothing more written\n")
    os._exit(exit_status())


def _remove_temporary_files() -> None:
    """rtpy.engine.files.remove_temporary_files, if that module is imported (whole)."""
    remove = getattr(sys.modules.get("rtpy.engine.files"), "remove_temporary_files", None)
    if remove is not None:
        remove()


def starting_the_command_line() -> bool:
    """rtpy is being imported to run its command line (`python -m rtpy`, whose
    package is imported while sys.argv[0] is still "-m", or the `rtpy` script), not
    by a program of its own."""
    argv0 = sys.argv[0] if sys.argv else ""
    if argv0 == "-m":
        orig = getattr(sys, "orig_argv", [])
        return any(a == "-m" and b == "rtpy" for a, b in zip(orig, orig[1:], strict=False))
    return os.path.splitext(os.path.basename(argv0))[0] in ("rtpy", "rtpy-script")
