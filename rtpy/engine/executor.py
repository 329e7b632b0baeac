"""Executors: where the units of a render run.

The render loop (rtpy.engine.renderer) hands an executor the backend and the units of work
in the plan's order, and adds the sums it gets back; it never knows where they were
computed. Three executors come with rtpy:

- InProcess: this process, one unit after another (workers=1);
- rtpy.engine.workers.WorkerProcesses: worker processes on this machine (workers=N);
- rtpy.engine.cluster.DaskCluster: the workers of a Dask distributed cluster (cluster=...).

Every unit is rendered by the same backend from the same plan, so every executor
gives the same image, bit for bit.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from .backend import Backend
    from .plan import Unit

__all__ = ["Executor", "InProcess", "Result", "WorkerError"]

Result = tuple["Unit", "np.ndarray"]  # a unit and the sums of its pixels


class WorkerError(RuntimeError):
    """The workers cannot render: they cannot rebuild the render (a class the scene
    uses cannot be imported where they run), one ended abruptly, or a cluster cannot
    be reached or refuses the work. The message says which, in one line."""


class Executor:
    """Runs the units of a render.

    run(backend, units, timeout) renders the units it draws from `units` (an iterator in
    the plan's order; an executor draws only a few per worker ahead of those
    finished) with `backend`, started once wherever it renders, and yields
    (unit, sums) as each unit finishes, in any order, or None when `timeout` seconds
    pass without one (so that the loop can look at the clock; None waits as long as
    it takes). Closing the generator, as the loop does when it stops, cancels the
    units not finished and ends whatever the executor started. Failures raise
    WorkerError.

    name             what image.stats["executor"] says
    workers          how many units it renders at once
    startup_seconds  how long its last run took to start (a cluster's processes,
                     reaching a scheduler, sending the scene), before any unit
    """

    name = ""
    workers = 1
    startup_seconds = 0.0

    def run(
        self, backend: Backend, units: Iterator[Unit], timeout: float | None = None
    ) -> Iterator[Result | None]:
        raise NotImplementedError


class InProcess(Executor):
    """This process, one unit after another (a unit is never cut short by `timeout`:
    the loop looks at the clock between units, a few seconds apart at most)."""

    name = "this process"

    def run(
        self, backend: Backend, units: Iterator[Unit], timeout: float | None = None
    ) -> Iterator[Result | None]:
        render_one = backend.start()
        for unit in units:
            yield unit, render_one(unit)
