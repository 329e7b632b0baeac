"""Renderer: the one render loop, for every backend and every executor.

A backend (rtpy.engine.backend: "scalar" or "numpy", rtpy.engine.backends) plans the render as
passes over the whole image of 1, 1, 2, 4, ... samples per pixel, cut into units of
work of about the same number of paths (rtpy.engine.plan), and renders one unit. An
executor (rtpy.engine.executor) runs the units: in this process, on worker processes
(rtpy.engine.workers) or on a Dask cluster (rtpy.engine.cluster). The loop draws the units from
the plan, adds their sums pass by pass as they arrive (rtpy.engine.pixel_sums), shows
progress and previews, and stops when the passes are done, at Ctrl-C or when the
time limit is spent, keeping the whole passes. With a checkpoint
(rtpy.engine.render_state) it saves them as it goes and continues from them.

Every unit draws from its own generator, seeded by (seed, region, pass), and the
sums are added in pass order, so the image depends on the seed and the options
only: the same, bit for bit, for any number of workers, on a cluster, after any
interruption and resume.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable

import numpy as np

from ..camera import Camera
from ..render_settings import RenderSettings
from ..scene import Scene
from . import signals
from .backend import Backend, make_backend
from .executor import Executor, InProcess
from .memory import peak_memory_mb
from .pixel_sums import PixelSums
from .plan import Plan
from .render_state import CHECKPOINT_SECONDS, Checkpoint
from .rendered_image import RenderedImage
from .workers import WorkerProcesses

# How often a render with a time limit looks at the clock while no unit finishes.
CLOCK_SECONDS = 0.25


class _NoBar:
    """The progress bar of a quiet render: tqdm is not even imported."""

    def update(self, n: int) -> None:
        pass

    def close(self) -> None:
        pass


class Renderer:
    """Renders a scene with a camera and settings (the values as rtpy.render checks
    them).

    workers     processes of this machine (1 = this process), unless `executor`
    quiet       no progress bar (it goes to stderr, with an ETA)
    backend     a registered backend's name (rtpy.BACKENDS) or a Backend
    preview     called with the image rendered so far (a RenderedImage holding the
                samples finished, the pass in progress included) when a unit
                finishes at least preview_seconds after the last call (or the
                start), but not at the end: the caller has the final image
    executor    where the units run (rtpy.engine.executor), e.g. rtpy.engine.cluster.DaskCluster
    time_limit  seconds (0: none): whole passes until they are spent, at least one
    checkpoint  where the render keeps its whole passes (rtpy.engine.render_state): saved
                after passes, at most every CHECKPOINT_SECONDS, and when it stops
    resume      continue from the checkpoint's passes, if it has any
    """

    def __init__(
        self,
        scene: Scene,
        camera: Camera,
        settings: RenderSettings,
        workers: int = 1,
        quiet: bool = True,
        backend: str | Backend = "scalar",
        preview: Callable[[RenderedImage], object] | None = None,
        preview_seconds: float = 5.0,
        *,
        executor: Executor | None = None,
        time_limit: float = 0.0,
        checkpoint: Checkpoint | None = None,
        resume: bool = False,
    ) -> None:
        self.scene, self.camera, self.settings = scene, camera, settings
        self.workers, self.quiet = workers, quiet
        self.preview, self.preview_seconds = preview, preview_seconds
        self.executor, self.time_limit = executor, time_limit
        self.checkpoint, self.resume = checkpoint, resume
        self.saved = False  # the checkpoint holds the last render's units
        if not isinstance(backend, Backend):
            backend = make_backend(backend, scene, camera, settings)
        self.backend = backend

    def render(self, *, then_write: bool = False) -> RenderedImage:
        """Render; after Ctrl-C or the time limit, the whole passes finished
        (image.interrupted is True after Ctrl-C; image.stats["stopped"] says why).

        Under the command line's signal handlers, a first signal once the loop is
        over (the last pass in, the workers being ended) is recorded, not raised
        (rtpy.engine.signals.finish_from_here): then_write=True (the render command,
        which writes the image next) keeps it so until the command ends; otherwise
        it is raised as KeyboardInterrupt when the render returns."""
        signals.raise_again()
        camera, backend = self.camera, self.backend
        spp = 1 if backend.uses_center_ray() else self.settings.spp
        plan = backend.plan(camera.width, camera.height, spp)
        saved = self.checkpoint.load(plan) if self.checkpoint and self.resume else None
        sums = PixelSums(plan, *(saved or ()))
        resumed = sums.passes
        executor = self.executor or self._local(plan.count_units(resumed))
        pixels = camera.width * camera.height
        bar = _NoBar() if self.quiet else self._progress_bar(pixels * spp, sums.paths())
        start = time.perf_counter()
        run = _Run(self, plan, sums, executor, start)
        timeout = CLOCK_SECONDS if self.time_limit else None
        units = (unit for unit in plan.units(resumed) if not sums.holds(unit))
        work = executor.run(backend, units, timeout)
        try:
            self._loop(run, work, bar)
        except BaseException:
            bar.leave = False  # cleared: the failure says its own line (a stub's, a worker's)
            signals.finish_from_here()
            try:
                run.keep()  # a failure (a worker lost, a bug): what is finished, for --resume
            except Exception:  # the failure, not this, is the error to report
                pass
            raise
        finally:
            # The loop is over: a first signal from here on is recorded, not raised, so
            # that the workers are ended whole (bounded: rtpy.engine.workers) and the
            # image, finished or stopped, is returned to be written.
            signals.finish_from_here()
            work.close()  # cancels the units not finished, ends the workers
            bar.close()
        seconds = time.perf_counter() - start
        if run.stopped:
            run.keep()
        whole = sums.whole_samples()
        image = run.image(sums.mean(), whole, whole, False, seconds, paths=whole * pixels)
        if not then_write:
            signals.raise_again()
        return image

    def _loop(self, run: _Run, work, bar) -> None:
        """Add the results of `work` until the last pass is in, the time limit is
        spent or Ctrl-C (run.stopped says which, None when every pass is in: a
        signal once the last unit is added stops nothing)."""
        sums = run.sums
        try:
            for result in work:
                now = time.perf_counter()
                if result is not None:
                    run.add(*result, now)
                    bar.update(result[0].paths)
                if sums.done:
                    signals.finish_from_here()
                    return
                if self.time_limit and now - run.start >= self.time_limit and sums.passes:
                    signals.finish_from_here()
                    run.stopped = "time limit"
                    return
        except KeyboardInterrupt:
            signals.finish_from_here(absorbed=sums.done)
            run.stopped = None if sums.done else "interrupted"

    def _local(self, units: int) -> Executor:
        """This process, or worker processes: no more of them than there are units."""
        workers = min(self.workers, units)
        return WorkerProcesses(workers) if workers > 1 else InProcess()

    def _progress_bar(self, total_paths: int, done: int = 0):
        """A bar of paths, `done` of them done already (a resumed render)."""
        from tqdm.auto import tqdm  # a notebook widget in Jupyter, else text

        return tqdm(
            total=total_paths,
            initial=done,
            unit="path",
            unit_scale=True,
            file=sys.stderr,
            desc=f"{self.scene.name} ({self.settings.integrator}, {self.backend.name})",
            dynamic_ncols=True,
        )


class _Run:
    """What one call of Renderer.render keeps track of: the paths rendered, when it
    last saved and previewed, why it stopped."""

    def __init__(
        self, renderer: Renderer, plan: Plan, sums: PixelSums, executor: Executor, start: float
    ) -> None:
        self.renderer, self.plan, self.sums, self.executor = renderer, plan, sums, executor
        self.start = self.last_preview = self.last_save = start
        self.unsaved = 0  # units added since the checkpoint was saved
        self.saved = False  # the checkpoint holds this run's units
        self.resumed_samples = plan.samples_after(sums.passes)
        self.rendered = 0  # paths traced by this run
        self.stopped: str | None = None  # "interrupted" or "time limit"

    def keep(self) -> None:
        """Save the checkpoint, if there is one and units came since it was saved."""
        checkpoint = self.renderer.checkpoint
        if checkpoint is not None and self.unsaved:
            with signals.finishing_if_handled():  # a signal now lets the save finish
                checkpoint.save(self.sums.total, self.sums.current())
            self.unsaved, self.saved = 0, True
            self.renderer.saved = True

    def add(self, unit, unit_sums: np.ndarray, now: float) -> None:
        r, sums = self.renderer, self.sums
        self.rendered += unit.paths
        sums.add(unit, unit_sums)
        self.unsaved += 1
        if r.checkpoint and not sums.done and now - self.last_save >= CHECKPOINT_SECONDS:
            r.checkpoint.save(sums.total, sums.current())
            self.last_save, self.unsaved, self.saved = now, 0, True
            r.saved = True
        if r.preview and not sums.done and now - self.last_preview >= r.preview_seconds:
            fewest, most = sums.samples_range()
            r.preview(self.image(sums.snapshot(), fewest, most, True, now - self.start))
            self.last_preview = now

    def image(
        self, linear, fewest: int, most: int, partial: bool, seconds: float, paths=None
    ) -> RenderedImage:
        """The RenderedImage of `linear`, each pixel the mean of fewest to most samples."""
        r = self.renderer
        stats = {
            "seconds": seconds,
            "paths": self.sums.paths() if paths is None else paths,
            "paths_rendered": self.rendered,
            "paths_per_second": self.rendered / seconds if seconds > 0 else math.inf,
            "passes": self.sums.passes,
            "resumed_samples": self.resumed_samples,
            "stopped": self.stopped,
            "checkpoint_saved": self.saved,
            "workers": self.executor.workers,
            "executor": self.executor.name,
            "executor_startup_seconds": self.executor.startup_seconds,
            "integrator": r.settings.integrator,
            "backend": r.backend.name,
            "peak_rss_mb": peak_memory_mb(children=True),
        }
        return RenderedImage(
            linear,
            gamma=r.settings.gamma,
            spp=self.plan.spp,
            samples_min=fewest,
            samples_max=most,
            interrupted=partial or self.stopped == "interrupted",
            stats=stats,
        )
