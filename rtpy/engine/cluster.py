"""Rendering on a Dask distributed cluster: the executor DaskCluster.

Needs the optional extra: pip install 'rtpy[cluster]' (Dask distributed). A
render is sent to a running scheduler (`--cluster tcp://host:8786`,
rtpy.render(cluster="tcp://host:8786") or a distributed.Client) or to a
LocalCluster of `workers` processes started for it (`--cluster local`).

What travels: the backend (the scene with its textures and meshes, the camera, the
settings), pickled, and the source of the plugins, scattered once to every worker,
which rebuilds it once per render (after running the plugins under the names they
have here); then each unit of work is a task whose result, the sums of its pixels,
comes back to this process, which adds them pass by pass as on one machine. At most
two units per worker thread are pending at a time, so a stop cancels little; a
worker lost mid-render has its units run again elsewhere by Dask, and since every
unit draws from its own generator the image does not change.

Every worker must have the same rtpy (and numpy) as this machine: they are checked
when the render starts. A worker renders one unit at a time whatever its threads
(rtpy's scalar backend draws from one generator per process): start workers with
`--nthreads 1` and as many processes as cores (`--nworkers`).
"""

from __future__ import annotations

import logging
import os
import pickle
import re
import sys
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

from . import signals
from .executor import Executor, Result, WorkerError
from .plugins import load_plugin_source, plugin_sources
from .version import version
from .workers import end_processes

if TYPE_CHECKING:
    import numpy as np

    from .backend import Backend
    from .plan import Unit

__all__ = ["CLUSTER_INSTALL", "CLUSTER_TIMEOUT", "DaskCluster", "make_cluster", "scheduler_address"]

CLUSTER_INSTALL = "pip install 'rtpy[cluster]'"
CONNECT_SECONDS = 30  # for a scheduler to have a worker, a local cluster to start
CLUSTER_TIMEOUT = 5.0  # to reach a scheduler: a lab's network answers in far less
MAX_CLUSTER_TIMEOUT = 1e6  # as the command line's seconds
_HOST = re.compile(r"[A-Za-z0-9_.-]+")
_IPV6 = re.compile(r"[0-9A-Fa-f:.]+(%[A-Za-z0-9_.-]+)?")
POLL_SECONDS = 0.5  # how often a wait for results looks up (Ctrl-C, the clock)


def make_cluster(cluster: object, workers: int = 1, timeout: float | None = None) -> DaskCluster:
    """rtpy.render's `cluster`: "local" (a LocalCluster of `workers` processes), a
    scheduler's address ("tcp://host:8786", checked by scheduler_address before Dask
    sees it) or a distributed.Client; ValueError or TypeError naming `cluster` for
    anything else, or without Dask distributed. `timeout`: the seconds to reach a
    scheduler (rtpy.render's cluster_timeout)."""
    if isinstance(cluster, str) and cluster != "local":
        cluster = scheduler_address(cluster)
    timeout = CLUSTER_TIMEOUT if timeout is None else timeout
    if isinstance(timeout, bool) or not isinstance(timeout, int | float):
        raise TypeError(f"cluster_timeout: expected a number of seconds, got {timeout!r}")
    if not 0.0 < timeout < MAX_CLUSTER_TIMEOUT:
        raise ValueError(
            f"cluster_timeout: expected seconds above 0 and below {MAX_CLUSTER_TIMEOUT:g}, "
            f"got {timeout!r}"
        )
    try:
        import distributed
    except ImportError:
        raise ValueError(f"cluster: needs Dask distributed ({CLUSTER_INSTALL})") from None
    if not isinstance(cluster, str | distributed.Client):
        raise TypeError(
            f'cluster: expected "local", an address or a distributed.Client, got {cluster!r}'
        )
    return DaskCluster(cluster, workers, float(timeout))


def scheduler_address(text: str) -> str:
    """A scheduler's address tcp://HOST:PORT (HOST a name, an IPv4 address or an IPv6
    one in brackets, PORT 1 to 65535) as Dask takes it; ValueError naming `cluster`
    and saying what is wrong otherwise (Dask's own errors name nothing, or come after
    its connect timeout)."""

    def bad(why: str) -> ValueError:
        return ValueError(
            f'cluster: expected "local" or a scheduler\'s address such as tcp://host:8786, '
            f"got {text!r}: {why}"
        )

    scheme, sep, rest = text.partition("://")
    if not sep:
        raise bad("no tcp:// before the host")
    if scheme != "tcp":
        raise bad(f"the scheme is {scheme}://, not tcp://")
    if rest.startswith("["):  # [IPv6]:PORT
        host, bracket, port_part = rest[1:].partition("]")
        if not bracket or not _IPV6.fullmatch(host):
            raise bad("an IPv6 host is written in brackets: [::1]:8786")
        port_part = port_part.removeprefix(":") if port_part.startswith(":") else None
    else:
        host, colon, port_part = rest.partition(":")
        port_part = port_part if colon else None
    if not host:
        raise bad("the host is empty")
    if not rest.startswith("[") and not _HOST.fullmatch(host):
        raise bad(f"{host!r} is not a host name or address")
    if port_part is None or port_part == "":
        raise bad("the port is missing")
    if not (port_part.isascii() and port_part.isdigit()):
        why = "it has two ports" if ":" in port_part else f"the port {port_part!r} is not a number"
        raise bad(why)
    if not 1 <= int(port_part) <= 65535:
        raise bad(f"the port {int(port_part)} is not from 1 to 65535")
    return f"tcp://{'[' + host + ']' if rest.startswith('[') else host}:{int(port_part)}"


class DaskCluster(Executor):
    """The workers of a Dask cluster: `cluster` is "local", an address or a Client
    (used as it is, not closed after); `timeout` the seconds to reach a scheduler."""

    name = "dask"

    def __init__(self, cluster: object, workers: int = 1, timeout: float = CLUSTER_TIMEOUT):
        self.cluster, self.timeout = cluster, timeout
        self.workers = workers  # the local cluster's processes; a scheduler's threads

    def run(
        self, backend: Backend, units: Iterator[Unit], timeout: float | None = None
    ) -> Iterator[Result | None]:
        import multiprocessing

        import distributed

        before = set(multiprocessing.active_children())
        had_tracker = _resource_tracker_running()
        started = time.perf_counter()
        client, close = None, _nothing
        pending: dict = {}
        try:
            client, close = self._connect(distributed)
            self.workers = _check_workers(client, self.cluster)
            token = uuid.uuid4().hex
            payload = (token, plugin_sources(), pickle.dumps(backend))
            [shared] = client.scatter([payload], broadcast=True, hash=False)
            self.startup_seconds = time.perf_counter() - started
            ahead = 2 * self.workers
            count = 0

            def submit() -> None:
                nonlocal count
                while len(pending) < ahead and (unit := next(units, None)) is not None:
                    key = f"rtpy-{token}-{unit.batch}-{unit.region}"
                    pending[client.submit(_render_unit, shared, unit, key=key, priority=-count)] = 1
                    count += 1

            submit()
            waited = 0.0
            while pending:
                step = POLL_SECONDS if timeout is None else min(POLL_SECONDS, timeout)
                # Dask is called with the signals held (they act when it returns, at
                # most POLL_SECONDS later): a KeyboardInterrupt inside its calls can
                # make it log a traceback (distributed.utils.sync then cancels a
                # future it has not made yet).
                with signals.held():
                    results = _finished(distributed, pending, step)
                    submit()
                if results is None:
                    waited += step
                    if timeout is not None and waited >= timeout:
                        waited = 0.0
                        yield None
                    continue
                waited = 0.0
                yield from results
        finally:
            if pending:
                client.cancel(list(pending))
            pending.clear()
            close()
            end_processes(before, grace=CONNECT_SECONDS)  # a local cluster's, once closed
            if not had_tracker:
                _stop_resource_tracker()

    def _connect(self, distributed) -> tuple[object, Callable[[], None]]:
        """The client, and what ends what was started for this render."""
        if isinstance(self.cluster, distributed.Client):
            return self.cluster, _nothing
        if self.cluster == "local":
            environment = dict(os.environ)  # Dask's nanny sets its workers' variables here
            try:
                cluster = _local_cluster(distributed, self.workers)
            finally:  # started: this process's environment as it was (a library call)
                os.environ.clear()
                os.environ.update(environment)
            try:
                with signals.held():
                    client = distributed.Client(cluster)
            except BaseException:  # a Ctrl-C held meanwhile, or no client
                cluster.close()
                raise

            def close() -> None:
                client.close()
                cluster.close()

            return client, close
        try:
            with signals.held():
                client = distributed.Client(self.cluster, timeout=self.timeout)
        except (OSError, TimeoutError) as err:
            raise WorkerError(
                f"cannot reach the Dask scheduler at {self.cluster} within {self.timeout:g} s "
                f"({err or type(err).__name__}); is it running? (--cluster-timeout or "
                f"cluster_timeout waits longer)"
            ) from None
        return client, client.close


def _nothing() -> None:
    pass


def _resource_tracker_running() -> bool:
    """multiprocessing's resource tracker runs for this process (POSIX: a process
    that processes started by spawn, such as a local cluster's, report to)."""
    from multiprocessing import resource_tracker

    return getattr(resource_tracker._resource_tracker, "_fd", None) is not None


def _stop_resource_tracker() -> None:
    """Stop the resource tracker that a local cluster started, and wait for it: it
    would end on its own only after this process, so it outlived the render."""
    from multiprocessing import resource_tracker

    stop = getattr(resource_tracker._resource_tracker, "_stop", None)
    if stop is not None:
        stop()


def _local_cluster(distributed, workers: int):
    """A LocalCluster of `workers` processes of one thread each, started with SIGINT
    ignored until they exist (POSIX): they inherit that, so a terminal's Ctrl-C,
    which goes to every process of the group, reaches this process alone, which
    stops the render and closes the cluster. This process handles SIGINT again as
    soon as the processes are started (a Ctrl-C in those tenths of a second is
    lost); it waits for them on the thread that starts the cluster."""
    import multiprocessing
    import signal

    def start():
        return distributed.LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # any free port: none is taken for granted
            silence_logs=logging.ERROR,
        )

    if threading.current_thread() is not threading.main_thread() or sys.platform == "win32":
        return start()  # only the main thread sets handlers; Windows has no inheritance
    started: dict[str, object] = {}
    finished = threading.Event()  # waited on, not the thread: an interrupted join can lie

    def run() -> None:
        try:
            started["cluster"] = start()
        except BaseException as err:  # raised again on this process's thread
            started["error"] = err
        finally:
            finished.set()

    before = set(multiprocessing.active_children())
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        threading.Thread(target=run, name="rtpy local cluster", daemon=True).start()
        deadline = time.monotonic() + CONNECT_SECONDS
        while not finished.is_set() and time.monotonic() < deadline:
            if len(set(multiprocessing.active_children()) - before) >= workers:
                break
            finished.wait(0.01)  # the cluster is up, or its processes appear
    finally:
        signal.signal(signal.SIGINT, previous)
    try:
        finished.wait()
    except BaseException:  # Ctrl-C while the workers start: close it once started
        finished.wait()
        if "cluster" in started:
            started["cluster"].close()
        raise
    if "error" in started:
        raise started["error"]
    return started["cluster"]


def _check_workers(client, cluster: object) -> int:
    """The worker threads of the cluster, once it has one; WorkerError if it has none
    or one has another rtpy, numpy or Python than this machine."""
    try:
        client.wait_for_workers(1, timeout=CONNECT_SECONDS)
    except TimeoutError:
        raise WorkerError(
            f"the Dask scheduler at {cluster} has no workers after {CONNECT_SECONDS} s: "
            f"start `dask worker ADDRESS --nthreads 1` on the machines"
        ) from None
    here = _versions()
    for worker, there in client.run(_versions).items():
        if tuple(there) != here:
            raise WorkerError(
                f"the worker {worker} has rtpy {there[0]}, numpy {there[1]}, Python {there[2]}; "
                f"this machine rtpy {here[0]}, numpy {here[1]}, Python {here[2]}: every worker "
                f"needs the same (pip install the same rtpy there)"
            )
    return max(1, sum(client.nthreads().values()))


def _versions() -> tuple[str, str, str]:
    import platform

    import numpy

    return version(), numpy.__version__, platform.python_version()


def _finished(distributed, pending: dict, timeout: float) -> list[Result] | None:
    """The results of the pending futures done within `timeout` seconds, taken out of
    `pending`; None if none is."""
    try:
        done = distributed.wait(list(pending), timeout=timeout, return_when="FIRST_COMPLETED")
    except TimeoutError:
        return None
    for future in done.done:
        del pending[future]
    return [_result(future, distributed) for future in done.done]


def _result(future, distributed) -> Result:
    """The future's (unit, sums); WorkerError for a worker's failure."""
    try:
        return future.result()
    except WorkerError as err:
        raise WorkerError(f"a worker of the Dask cluster cannot rebuild the scene: {err}") from None
    except distributed.KilledWorker as err:
        raise WorkerError(f"the Dask cluster lost the workers of a unit of work: {err}") from None


# --- on the workers -------------------------------------------------------------------

_started: dict[str, Callable[[Unit], np.ndarray]] = {}  # token -> the render's unit renderer
_one_at_a_time = threading.Lock()  # a worker's threads take turns (one generator per process)


def _render_unit(payload: tuple[str, dict, bytes], unit: Unit) -> Result:
    """Render `unit` of the render `payload` describes, rebuilding it on the first unit."""
    token, plugins, backend = payload
    with _one_at_a_time:
        render_one = _started.get(token)
        if render_one is None:
            try:
                for name, (path, source) in plugins.items():
                    load_plugin_source(name, source, path)
                render_one = pickle.loads(backend).start()
            except Exception as err:
                raise WorkerError(f"{type(err).__name__}: {err}") from None
            _started.clear()  # one render at a time: the last one's scene goes
            _started[token] = render_one
        return unit, render_one(unit)
