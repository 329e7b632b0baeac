"""Worker processes: the executor that renders the units of a render on other
processes of this machine, under every start method.

A worker process receives the backend (the scene, camera and settings) once, when
it starts. Under the `fork` start method it inherits the object; under `spawn` and
`forkserver` (the defaults on Windows and macOS, and on Linux from Python 3.14) it
receives the pickled bytes and rebuilds the backend after loading the plugins the
parent loaded (rtpy.engine.plugins), since the scene's material classes may live in them.
A worker that cannot rebuild it reports why with every unit it is given, so the
render stops at once with one message rather than a pool restarting workers forever.
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import signal
import sys
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import TYPE_CHECKING

from . import signals
from .executor import Executor, Result, WorkerError
from .memory import give_back_freed_memory
from .plugins import PLUGINS, load_listed_plugins

if TYPE_CHECKING:
    import numpy as np

    from .backend import Backend
    from .plan import Unit

__all__ = [
    "START_ADVICE",
    "WorkerError",
    "WorkerProcesses",
    "available_cpus",
    "cannot_rebuild",
    "end_processes",
]

_render_one: Callable[[Unit], np.ndarray] | None = None
_start_error = ""
# Windows waits on at most 63 handles at once; ProcessPoolExecutor refuses more than
# 61 workers there.
WINDOWS_MAX_WORKERS = 61


def available_cpus() -> int:
    """The number of CPUs this process may run on (its affinity mask or, on Python
    3.13+, also its -X cpu_count limit), the machine's count where the system does
    not say, and 1 where nothing does."""
    count = getattr(os, "process_cpu_count", None)  # Python 3.13+
    if count is not None:
        return count() or 1
    if hasattr(os, "sched_getaffinity"):  # Linux and some other Unix systems
        return len(os.sched_getaffinity(0)) or 1
    return os.cpu_count() or 1


START_ADVICE = (
    "Every class a scene uses must be importable by its module's name: define it in a "
    ".py file and import it (or load the file with rtpy.load_plugin, --plugin FILE.py "
    'on the command line), keep a script\'s rendering under `if __name__ == "__main__":`, '
    "or render with one worker."
)


def cannot_rebuild(reason: str, method: str) -> WorkerError:
    """The error saying why workers started by `method` cannot rebuild the scene."""
    return WorkerError(
        f"the worker processes (start method {method!r}) cannot rebuild the scene: "
        f"{reason}. {START_ADVICE}"
    )


def _init_worker(plugins: dict[str, str], backend: Backend | bytes) -> None:
    global _render_one, _start_error
    # The parent handles Ctrl-C (the terminal sends it to every process of the
    # group); SIGTERM ends a worker at once and quietly, as the parent's
    # _stop_workers does (a handler inherited from the parent by fork would raise
    # KeyboardInterrupt and print its traceback).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signals.unblock()  # born with them blocked (signals.held)
    try:
        load_listed_plugins(plugins)
        if isinstance(backend, bytes):
            backend = pickle.loads(backend)
        _render_one = backend.start()
    except Exception as err:
        _start_error = f"{type(err).__name__}: {err}"


def _run_unit(unit: Unit) -> tuple[Unit, np.ndarray]:
    if _render_one is None:
        raise WorkerError(_start_error)
    return unit, _render_one(unit)


def _stop_workers(executor: ProcessPoolExecutor) -> None:
    """End the executor's worker processes now, in the middle of their units."""
    terminate = getattr(executor, "terminate_workers", None)  # Python 3.14+
    if terminate is not None:
        terminate()
        return
    # Python 3.11-3.13 have no public way: the executor's own table of its processes
    processes = list(executor._processes.values())
    for process in processes:
        process.terminate()
    for process in processes:
        process.join()
    # A worker ended in the middle of sending its result (a large image of sums) leaves
    # the executor's thread waiting for the rest of the message. With every writer gone,
    # the parent's copy of the pipe's write end included, it reads end-of-file instead
    # and the executor shuts down; otherwise shutdown() would wait forever.
    executor._result_queue._writer.close()


class WorkerProcesses(Executor):
    """`workers` processes of this machine, started by the default start method
    (multiprocessing.get_context()) when a render starts and ended when it stops;
    each has two units at a time ahead of it."""

    name = "worker processes"

    def __init__(self, workers: int) -> None:
        self.workers = workers

    def run(
        self, backend: Backend, units: Iterator[Unit], timeout: float | None = None
    ) -> Iterator[Result | None]:
        context = multiprocessing.get_context()
        method = context.get_start_method()
        try:
            payload = backend if method == "fork" else pickle.dumps(backend)
        except (pickle.PicklingError, AttributeError, TypeError) as err:  # a local class
            raise cannot_rebuild(f"{type(err).__name__}: {err}", method) from None
        workers = (
            min(self.workers, WINDOWS_MAX_WORKERS) if sys.platform == "win32" else self.workers
        )
        if method == "fork":  # the workers copy no page of a block freed here
            give_back_freed_memory()
        if method == "forkserver":  # started now, not with the signals blocked below
            from multiprocessing import forkserver

            forkserver.ensure_running()
        before = set(multiprocessing.active_children())
        executor = None
        pending: dict[Future, Unit] = {}
        try:
            # A signal while the processes start waits until they all are in the
            # executor's table, so that stopping the pool stops every one of them
            # (they start with the first units submitted).
            with signals.held():
                executor = ProcessPoolExecutor(
                    workers,
                    mp_context=context,
                    initializer=_init_worker,
                    initargs=(dict(PLUGINS), payload),
                )
                _submit(executor, pending, units, 2 * workers)
            while pending:
                done, _ = wait(pending, timeout=timeout, return_when=FIRST_COMPLETED)
                if not done:
                    yield None
                for future in done:
                    del pending[future]
                    result = future.result()
                    _submit(executor, pending, units, 2 * workers)
                    yield result
        except WorkerError as err:
            _stop_workers(executor)
            raise cannot_rebuild(str(err), method) from None
        except BrokenProcessPool:
            raise WorkerError(
                f"a worker process (start method {method!r}) ended abruptly: it was killed, "
                f"ran out of memory or failed while starting (its error is above). {START_ADVICE}"
            ) from None
        except BaseException:
            if executor is not None:
                _stop_workers(executor)  # at once on Ctrl-C, an error or a stop
            raise
        finally:
            if executor is not None:
                executor.shutdown(wait=True, cancel_futures=True)
            end_processes(before)


def _submit(executor: ProcessPoolExecutor, pending: dict, units: Iterator[Unit], ahead: int):
    """Submit units until `ahead` are pending (or there are no more)."""
    while len(pending) < ahead:
        unit = next(units, None)
        if unit is None:
            return
        pending[executor.submit(_run_unit, unit)] = unit


def end_processes(before: set, grace: float = 0.0) -> None:
    """End and join the child processes started since the children `before` were
    (those the executor did not: one it was starting when it failed or was stopped),
    after `grace` seconds for them to end on their own."""
    left = set(multiprocessing.active_children()) - before
    for process in left:
        process.join(grace)
    for process in left:
        process.terminate()
        process.join()
