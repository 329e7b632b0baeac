"""One function computed in a forked child process while this one goes on: a file
reader's second core.

    with Forked(parse_vertices, block) as job:   # the child starts on it now
        faces = parse_faces(other_block)         # meanwhile, here
        vertices = job.result()                  # the child's answer (pickled back)

The child is a fork (Linux only), so it gets its arguments, however large, without
copying them. Where no child can help, result() calls the function here instead: on
other systems (fork is unsafe on macOS, absent on Windows), in a process with other
threads (a fork copies only the calling thread, and locks the others hold stay held),
in a daemonic process (multiprocessing allows it no children), when the system
refuses a process, and when the child fails or dies. A child's exception is not
passed on: the call here raises it again, with this process's traceback, so the
answer is always the function's own.

Signals: the child starts with SIGINT and SIGTERM held (rtpy.engine.signals.held), then
ignores SIGINT (a terminal's Ctrl-C goes to every process of the group: this one
stops the work) and ends at once on SIGTERM. Once result() returns or the `with`
block is left, the child is gone.
"""

from __future__ import annotations

import multiprocessing
import signal
import sys
import threading
from collections.abc import Callable
from typing import Any

from ..engine import signals

__all__ = ["Forked", "can_fork"]


def can_fork() -> bool:
    """A child forked here now would be safe and allowed (see the module's doc)."""
    return (
        sys.platform.startswith("linux")
        and threading.active_count() == 1
        and not multiprocessing.current_process().daemon
    )


class Forked:
    """function(*args) computed in a child process forked now, or by result() here
    where that is not possible (can_fork) or not wanted (fork=False: too little work
    to pay for a process)."""

    def __init__(self, function: Callable[..., Any], *args: Any, fork: bool = True) -> None:
        self.function, self.args = function, args
        self.child = self.receive = None
        if not (fork and can_fork()):
            return
        context = multiprocessing.get_context("fork")
        receive, send = context.Pipe(duplex=False)
        child = context.Process(target=_child, args=(send, function, args), daemon=True)
        self.child, self.receive = child, receive  # close() ends it, whatever happens
        try:
            with signals.held():
                child.start()
        except OSError:  # no more processes allowed
            self.close()
        except BaseException:  # a signal held while it started
            self.close()
            raise
        finally:
            send.close()  # the child's end: end-of-file here once the child is gone

    def result(self) -> Any:
        """The function's value: the child's, else computed here."""
        if self.child is None:
            return self.function(*self.args)
        try:
            answer = self.receive.recv()
        except (EOFError, OSError):  # the child failed or was ended
            answer = None
        finally:
            self.close()
        return answer[0] if answer is not None else self.function(*self.args)

    def close(self) -> None:
        """End the child, if it still runs (the caller stops: its answer is not needed)."""
        if self.child is None:
            return
        self.receive.close()
        if self.child.pid is not None:  # started
            self.child.kill()  # (nothing if it has ended)
            self.child.join()
        self.child = None

    def __enter__(self) -> Forked:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


def _child(send, function: Callable[..., Any], args: tuple) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signals.unblock()  # born with them blocked (signals.held)
    try:
        send.send((function(*args),))
    except BaseException:  # noqa: BLE001 - result() calls the function again, here
        return
