"""Renderer: runs an integrator over every pixel, in tiles, on one or more processes.

The image is cut into square tiles and the samples of each pixel into batches.
One unit of work is (batch, tile); units run batch by batch, so an interrupted
render already covers the whole image with fewer samples. Every unit draws from
its own generator, seeded by (seed, tile, batch), and partial sums are combined
in a fixed order, so the same seed gives the same image, bit for bit, with any
number of worker processes.
"""

from __future__ import annotations

import math
import multiprocessing
import signal
import sys
import time
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from .camera import Camera
from .integrators import make_integrator
from .io.image import RenderedImage
from .render_settings import RenderSettings
from .sampling import make_generator, use_generator
from .scene import Scene

TILE_SIZE = 16
MAX_BATCHES = 8  # samples per pixel are split into at most this many batches


@dataclass(frozen=True)
class Unit:
    tile: int
    batch: int
    x0: int
    y0: int
    x1: int
    y1: int
    spp: int


def plan_units(
    width: int, height: int, spp: int, n_batches: int | None = None, tile: int = TILE_SIZE
) -> list[Unit]:
    """All units of work, batch-major (every tile of batch 0 first): tile x tile pixel
    tiles, each tile's spp split into n_batches batches (default min(spp, MAX_BATCHES))
    that differ by at most 1."""
    n_batches = min(spp, MAX_BATCHES) if n_batches is None else n_batches
    batch_spp = [spp // n_batches + (1 if b < spp % n_batches else 0) for b in range(n_batches)]
    tiles = [
        (x0, y0, min(x0 + tile, width), min(y0 + tile, height))
        for y0 in range(0, height, tile)
        for x0 in range(0, width, tile)
    ]
    return [
        Unit(t, b, *tiles[t], batch_spp[b]) for b in range(n_batches) for t in range(len(tiles))
    ]


def render_unit(scene: Scene, camera: Camera, integrator, seed: int, unit: Unit) -> np.ndarray:
    """Sum of `unit.spp` radiance samples for each pixel of the unit's tile:
    an array (tile height, tile width, 3)."""
    out = np.zeros((unit.y1 - unit.y0, unit.x1 - unit.x0, 3))
    radiance = integrator.compute_scattering
    get_ray = camera.get_center_ray if integrator.uses_center_ray else camera.get_ray
    with use_generator(make_generator(seed, unit.tile, unit.batch)):
        for j in range(unit.y0, unit.y1):
            row = out[j - unit.y0]
            for i in range(unit.x0, unit.x1):
                r = g = b = 0.0
                for _ in range(unit.spp):
                    c = radiance(get_ray(i, j), scene)
                    r += c.e0
                    g += c.e1
                    b += c.e2
                row[i - unit.x0] = (r, g, b)
    return out


class PixelSums:
    """The sums of finished units, added into one image as they arrive.

    Each tile's batches are added in batch order (a unit that arrives before an
    earlier batch of its tile waits), so every pixel's sum is the same for any
    order of arrival, that is for any number of workers, and memory holds one
    image, not every unit of the render.
    """

    def __init__(self, width: int, height: int) -> None:
        self.total = np.zeros((height, width, 3))
        self.counts = np.zeros((height, width), dtype=np.int64)
        self._next_batch: dict[int, int] = {}  # tile -> the batch to add next
        self._waiting: dict[tuple[int, int], tuple[Unit, np.ndarray]] = {}

    def add(self, unit: Unit, sums: np.ndarray) -> None:
        self._waiting[(unit.tile, unit.batch)] = (unit, sums)
        batch = self._next_batch.get(unit.tile, 0)
        while (unit.tile, batch) in self._waiting:
            self._add(*self._waiting.pop((unit.tile, batch)))
            batch += 1
        self._next_batch[unit.tile] = batch

    def finish(self) -> None:
        """Add the units still waiting for an earlier batch (after Ctrl-C)."""
        for key in sorted(self._waiting):
            self._add(*self._waiting.pop(key))

    def _add(self, unit: Unit, sums: np.ndarray) -> None:
        self.total[unit.y0 : unit.y1, unit.x0 : unit.x1] += sums
        self.counts[unit.y0 : unit.y1, unit.x0 : unit.x1] += unit.spp


# --- worker processes -------------------------------------------------------
_worker_state: tuple | None = None


def _init_worker(scene: Scene, camera: Camera, settings: RenderSettings) -> None:
    global _worker_state
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C
    _worker_state = (scene, camera, make_integrator(settings), settings.seed)


def _run_unit(unit: Unit) -> tuple[Unit, np.ndarray]:
    scene, camera, integrator, seed = _worker_state
    return unit, render_unit(scene, camera, integrator, seed, unit)


class Renderer:
    """Renders a scene with a camera and settings.

    workers  number of processes (1 = render in this process)
    quiet    no progress bar (it goes to stderr, with an ETA)
    """

    def __init__(
        self,
        scene: Scene,
        camera: Camera,
        settings: RenderSettings,
        workers: int = 1,
        quiet: bool = True,
    ) -> None:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        self.scene = scene
        self.camera = camera
        self.settings = settings
        self.workers = workers
        self.quiet = quiet

    # What a backend changes: the progress bar's label, how the image is cut into
    # units of work, and the integrator that says whether it traces only centre rays.
    backend_label = ""

    def plan_units(self, width: int, height: int, spp: int) -> list[Unit]:
        return plan_units(width, height, spp)

    def uses_center_ray(self) -> bool:
        return make_integrator(self.settings).uses_center_ray

    def render(self) -> RenderedImage:
        """Render; on Ctrl-C return what was finished (image.interrupted is True)."""
        settings, camera = self.settings, self.camera
        spp = 1 if self.uses_center_ray() else settings.spp
        units = self.plan_units(camera.width, camera.height, spp)
        results = PixelSums(camera.width, camera.height)
        total_paths = camera.width * camera.height * spp
        bar = tqdm(
            total=total_paths,
            unit="path",
            unit_scale=True,
            file=sys.stderr,
            disable=self.quiet,
            desc=f"{self.scene.name} ({settings.integrator}{self.backend_label})",
            dynamic_ncols=True,
        )
        start = time.perf_counter()
        interrupted = False
        work = self._run(units)
        try:
            for unit, sums in work:
                results.add(unit, sums)
                bar.update(sums.shape[0] * sums.shape[1] * unit.spp)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            work.close()  # stops worker processes still running
            bar.close()
        seconds = time.perf_counter() - start
        return self._assemble(results, spp, interrupted, seconds)

    def _run(self, units: list[Unit]):
        if self.workers == 1:
            integrator = make_integrator(self.settings)
            for unit in units:
                yield (
                    unit,
                    render_unit(self.scene, self.camera, integrator, self.settings.seed, unit),
                )
            return
        pool = multiprocessing.get_context().Pool(
            self.workers, _init_worker, (self.scene, self.camera, self.settings)
        )
        try:
            yield from pool.imap_unordered(_run_unit, units, chunksize=1)
            pool.close()
        except BaseException:
            pool.terminate()  # stop the workers at once on Ctrl-C or an error
            raise
        finally:
            pool.join()

    def _assemble(self, results: PixelSums, spp, interrupted, seconds) -> RenderedImage:
        results.finish()
        counts = results.counts
        linear = results.total / np.maximum(counts, 1)[..., None]
        paths = int(counts.sum())
        stats = {
            "seconds": seconds,
            "paths": paths,
            "paths_per_second": paths / seconds if seconds > 0 else math.inf,
            "workers": self.workers,
            "integrator": self.settings.integrator,
        }
        return RenderedImage(
            linear,
            gamma=self.settings.gamma,
            spp=spp,
            samples_min=int(counts.min()),
            samples_max=int(counts.max()),
            interrupted=interrupted,
            stats=stats,
        )
