"""Renderer: runs an integrator over every pixel, unit by unit, on one or more processes.

One loop (Renderer) serves both backends: a Backend plans the units of work and
renders one unit (ScalarBackend here, ray by ray; the numpy backend's in
rtpy/numpy_backend/renderer.py, a whole unit as arrays), and the loop runs the
units on worker processes (rtpy.workers), shows progress, handles Ctrl-C and assembles
the image.

The image is cut into regions (square tiles for the scalar backend, bands of rows
sized by the number of paths for the numpy backend) and the samples of each pixel
into batches. One unit of work is (batch, region); units run batch by batch, so an
interrupted render already covers the whole image with fewer samples. Every unit
draws from its own generator, seeded by (seed, region, batch), and partial sums are
combined in a fixed order, so the same seed gives the same image, bit for bit, with
any number of worker processes.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from .camera import Camera
from .integrators import make_integrator
from .io.image import RenderedImage
from .render_settings import BACKENDS, RenderSettings
from .sampler import SAMPLERS
from .sampling import make_generator, use_generator
from .scene import Scene
from .testing.statistics import peak_memory_mb
from .workers import run_on_workers

TILE_SIZE = 16
MAX_BATCHES = 8  # samples per pixel are split into at most this many batches
MAX_PASS_SPP = 16  # plan_bands: spp / MAX_BATCHES samples a pass, at most this (but to fill a unit)


@dataclass(frozen=True)
class Unit:
    """Samples batch `batch` (spp of them per pixel) of the pixels x0 <= i < x1,
    y0 <= j < y1, which are region `region` of the plan; every batch of a plan has
    the same regions."""

    region: int
    batch: int
    x0: int
    y0: int
    x1: int
    y1: int
    spp: int
    first_sample: int = 0  # the index of the batch's first sample in each pixel


def plan_units(
    width: int, height: int, spp: int, n_batches: int | None = None, tile: int = TILE_SIZE
) -> list[Unit]:
    """All units of work, batch-major (every tile of batch 0 first): tile x tile pixel
    tiles, each tile's spp split into n_batches batches (default min(spp, MAX_BATCHES))
    that differ by at most 1."""
    n_batches = min(spp, MAX_BATCHES) if n_batches is None else n_batches
    tiles = [
        (x0, y0, min(x0 + tile, width), min(y0 + tile, height))
        for y0 in range(0, height, tile)
        for x0 in range(0, width, tile)
    ]
    return _units(tiles, spp, n_batches)


def plan_bands(width: int, height: int, spp: int, paths_per_unit: int) -> list[Unit]:
    """All units of work, batch-major, each of at most paths_per_unit camera paths and
    of about that many whatever the image size and spp. A batch is a pass over the
    whole image, so an interrupted render has the same samples in every pixel, give or
    take a pass. A pass holds as many samples per pixel as fill one unit, and at
    least spp / MAX_BATCHES of them up to MAX_PASS_SPP: a unit returns one sum per
    pixel, and fewer, longer passes return less per path. A pass is cut into bands of
    whole rows of equal height or, where one row holds more paths than a unit, each
    row into pieces of equal width."""
    fill = paths_per_unit // (width * height)
    longer = min(math.ceil(spp / MAX_BATCHES), MAX_PASS_SPP, paths_per_unit)
    spp_per_pass = min(spp, max(1, fill, longer))
    n_batches = math.ceil(spp / spp_per_pass)
    pixels = max(1, paths_per_unit // math.ceil(spp / n_batches))  # per unit
    if pixels >= width:
        rows = _even_step(height, pixels // width)
        regions = [(0, y0, width, min(y0 + rows, height)) for y0 in range(0, height, rows)]
    else:
        cols = _even_step(width, pixels)
        regions = [
            (x0, y, min(x0 + cols, width), y + 1)
            for y in range(height)
            for x0 in range(0, width, cols)
        ]
    return _units(regions, spp, n_batches)


def _even_step(length: int, at_most: int) -> int:
    """The step that cuts `length` into the fewest pieces of at most `at_most`, with
    sizes as equal as whole numbers allow (the last piece is the smallest)."""
    pieces = math.ceil(length / at_most)
    return math.ceil(length / pieces)


def _units(regions: list[tuple[int, int, int, int]], spp: int, n_batches: int) -> list[Unit]:
    """Batch-major units over regions (x0, y0, x1, y1): spp split into n_batches batches
    that differ by at most 1."""
    batch_spp = [spp // n_batches + (1 if b < spp % n_batches else 0) for b in range(n_batches)]
    return [
        Unit(r, b, *regions[r], batch_spp[b], sum(batch_spp[:b]))
        for b in range(n_batches)
        for r in range(len(regions))
    ]


def render_unit(
    scene: Scene, camera: Camera, integrator, seed: int, unit: Unit, sampler: str = "independent"
) -> np.ndarray:
    """Sum of `unit.spp` radiance samples for each pixel of the unit's region:
    an array (region height, region width, 3). Every draw comes from the unit's
    generator, or with another sampler (rtpy.sampler) from that sampler, told which
    pixel sample each path is."""
    sums = []  # (r, g, b) per pixel, row by row: one array at the end, not one write per pixel
    radiance = integrator.compute_scattering
    get_ray = camera.get_center_ray if integrator.uses_center_ray else camera.get_ray
    samples = range(unit.first_sample, unit.first_sample + unit.spp)
    source = make_generator(seed, unit.region, unit.batch)
    start = None
    if sampler != "independent":
        spp = 1 if integrator.uses_center_ray else integrator.settings.spp
        source = SAMPLERS[sampler](seed, spp, camera.defocus_angle > 0.0, fallback=source)
        start = source.start_pixel_sample
    with use_generator(source):
        for j in range(unit.y0, unit.y1):
            for i in range(unit.x0, unit.x1):
                r = g = b = 0.0
                for index in samples:
                    if start:
                        start(j * camera.width + i, index)
                    c = radiance(get_ray(i, j), scene)
                    r += c.e0
                    g += c.e1
                    b += c.e2
                sums.append((r, g, b))
    return np.array(sums, dtype=np.float64).reshape(unit.y1 - unit.y0, unit.x1 - unit.x0, 3)


class PixelSums:
    """The sums of finished units, added into one image as they arrive.

    Each region's batches are added in batch order (a unit that arrives before an
    earlier batch of its region waits), so every pixel's sum is the same for any
    order of arrival, that is for any number of workers, and memory holds one
    image, not every unit of the render. A batch is a pass over the image, and no
    region is added more than one pass ahead of the passes every region has
    finished (a unit further ahead, from a worker that ran ahead of one still busy,
    waits too), so every pixel has the same samples, give or take one pass, at any
    moment. Each pixel's count of samples is a fourth channel beside its sums, added
    with them in one array operation: a Ctrl-C that interrupts an addition anywhere
    leaves every sum with its own count.
    """

    def __init__(self, width: int, height: int, regions: int) -> None:
        self.total = np.zeros((height, width, 4))  # r, g, b sums and the samples they hold
        self.passes = 0  # the batches every one of the `regions` regions has added
        self._regions = regions
        self._next_batch: dict[int, int] = {}  # region -> the batch to add next
        self._added: dict[int, int] = {}  # batch -> the regions that have added it
        self._waiting: dict[tuple[int, int], tuple[Unit, np.ndarray]] = {}

    def add(self, unit: Unit, sums: np.ndarray) -> None:
        self._waiting[(unit.region, unit.batch)] = (unit, sums)
        ready = [(unit.region, unit.batch)]
        while ready:
            region, batch = key = ready.pop()
            if key not in self._waiting or batch != self._next_batch.get(region, 0):
                continue
            if batch > self.passes:  # more than one pass ahead
                continue
            self._add(*self._waiting.pop(key))
            self._next_batch[region] = batch + 1
            self._added[batch] = self._added.get(batch, 0) + 1
            ready.append((region, batch + 1))
            if batch == self.passes and self._added[batch] == self._regions:
                self.passes += 1  # the units of the next pass may be added now
                ready.extend(k for k in self._waiting if k[1] == self.passes)

    def finish(self) -> None:
        """Drop the units still waiting (after Ctrl-C): each is more than one pass
        ahead of the passes finished, or waits for such a unit."""
        self._waiting.clear()

    def _add(self, unit: Unit, sums: np.ndarray) -> None:
        counted = np.concatenate([sums, np.full((*sums.shape[:2], 1), float(unit.spp))], axis=2)
        self.total[unit.y0 : unit.y1, unit.x0 : unit.x1] += counted

    @property
    def counts(self) -> np.ndarray:
        """Samples added per pixel, an array (height, width)."""
        return self.total[..., 3].astype(np.int64)

    @property
    def paths(self) -> int:
        """Samples added over all pixels."""
        return int(self.counts.sum())

    def samples_range(self) -> tuple[int, int]:
        """The fewest and the most samples a pixel has."""
        counts = self.counts
        return int(counts.min()), int(counts.max())

    def snapshot(self) -> np.ndarray:
        """The mean of each pixel's samples added so far, as a new array (the sums are
        left as they are, for more samples to be added)."""
        return self._divide(self.total.copy())

    def mean(self) -> np.ndarray:
        """The mean of each pixel's samples (black without one), an array (height,
        width, 3), computed in place after finish(): `total` becomes it (call it once)."""
        self.finish()
        return self._divide(self.total)

    def _divide(self, total: np.ndarray) -> np.ndarray:
        """The sums of `total` (the image of sums and counts, or a copy) divided, in
        place, by their counts; black where there are none."""
        sums, counts = total[..., :3], total[..., 3:]
        np.divide(sums, counts, out=sums, where=counts > 0)
        return sums


# --- backends ---------------------------------------------------------------------


class Backend:
    """A way of rendering units of work; Renderer's one loop drives every backend.

    A backend plans the units (how the image and the samples are cut) and renders one
    unit; the loop does the rest, the same for all: worker processes, the progress
    bar, Ctrl-C and the assembly of the image. The backend is pickled to every worker
    process, which calls start() once and then renders units.

    name  the backend's name in rtpy.BACKENDS (the progress bar and image.stats show it)
    """

    name = ""

    def __init__(self, scene: Scene, camera: Camera, settings: RenderSettings) -> None:
        self.scene = scene
        self.camera = camera
        self.settings = settings

    def make_integrator(self):
        """The integrator the settings name, in this backend's kind."""
        raise NotImplementedError

    def uses_center_ray(self) -> bool:
        """The integrator traces one ray through each pixel's center (spp = 1)."""
        return self.make_integrator().uses_center_ray

    def plan_units(self, width: int, height: int, spp: int) -> list[Unit]:
        """All units of work, batch-major, covering every pixel with spp samples."""
        return plan_units(width, height, spp)

    def start(self) -> Callable[[Unit], np.ndarray]:
        """Prepare this process to render (called once in each process that renders)
        and return the function that renders one unit: the sum of unit.spp radiance
        samples per pixel of its region, an array (height, width, 3)."""
        raise NotImplementedError


class ScalarBackend(Backend):
    """The readable reference: one Ray at a time through the scalar integrators."""

    name = "scalar"

    def make_integrator(self):
        return make_integrator(self.settings)

    def start(self) -> Callable[[Unit], np.ndarray]:
        integrator = self.make_integrator()
        settings = self.settings
        return partial(
            render_unit,
            self.scene,
            self.camera,
            integrator,
            settings.seed,
            sampler=settings.sampler,
        )


def make_backend(name: str, scene: Scene, camera: Camera, settings: RenderSettings) -> Backend:
    """The backend called `name` (one of BACKENDS) for a render."""
    if name == "scalar":
        return ScalarBackend(scene, camera, settings)
    if name == "numpy":
        # Imported here: student repositories hold a stub of the numpy backend.
        from .numpy_backend.renderer import NumpyBackend

        return NumpyBackend(scene, camera, settings)
    raise ValueError(f"backend must be one of {', '.join(BACKENDS)}; got {name!r}")


class _NoBar:
    """The progress bar of a quiet render: tqdm is not even imported."""

    def update(self, n: int) -> None:
        pass

    def close(self) -> None:
        pass


class Renderer:
    """Renders a scene with a camera and settings.

    workers  number of processes (1 = render in this process)
    quiet    no progress bar (it goes to stderr, with an ETA)
    backend  "scalar" (the readable reference) or "numpy" (vectorized; the same image
             up to Monte Carlo noise)
    preview  called with the image rendered so far (a RenderedImage of the finished
             samples) when a unit finishes at least preview_seconds after the last
             call (or the start), but not at the end: the caller has the final image
    """

    def __init__(
        self,
        scene: Scene,
        camera: Camera,
        settings: RenderSettings,
        workers: int = 1,
        quiet: bool = True,
        backend: str = "scalar",
        preview: Callable[[RenderedImage], object] | None = None,
        preview_seconds: float = 5.0,
    ) -> None:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        if preview is not None and not callable(preview):
            raise TypeError(f"preview must be callable or None, got {preview!r}")
        if not (isinstance(preview_seconds, int | float) and preview_seconds >= 0.0):
            raise ValueError(f"preview_seconds must be a number >= 0, got {preview_seconds!r}")
        self.preview, self.preview_seconds = preview, float(preview_seconds)
        self.scene = scene
        self.camera = camera
        self.settings = settings
        self.workers = workers
        self.quiet = quiet
        self.backend = make_backend(backend, scene, camera, settings)

    def render(self) -> RenderedImage:
        """Render; on Ctrl-C return what was finished (image.interrupted is True)."""
        settings, camera, backend = self.settings, self.camera, self.backend
        spp = 1 if backend.uses_center_ray() else settings.spp
        units = backend.plan_units(camera.width, camera.height, spp)
        results = PixelSums(camera.width, camera.height, len({u.region for u in units}))
        total_paths = camera.width * camera.height * spp
        bar = _NoBar() if self.quiet else self._progress_bar(total_paths)
        start = last_preview = time.perf_counter()
        interrupted = False
        work = self._run(units)
        try:
            for done, (unit, sums) in enumerate(work, 1):
                results.add(unit, sums)
                bar.update(sums.shape[0] * sums.shape[1] * unit.spp)
                now = time.perf_counter()
                if (
                    self.preview
                    and done < len(units)
                    and now - last_preview >= self.preview_seconds
                ):
                    self.preview(self._image(results.snapshot(), results, spp, True, now - start))
                    last_preview = now
        except KeyboardInterrupt:
            interrupted = True
        finally:
            work.close()  # stops worker processes still running
            bar.close()
        seconds = time.perf_counter() - start
        return self._assemble(results, spp, interrupted, seconds)

    def _progress_bar(self, total_paths: int):
        from tqdm.auto import tqdm  # a notebook widget in Jupyter, else text

        return tqdm(
            total=total_paths,
            unit="path",
            unit_scale=True,
            file=sys.stderr,
            desc=f"{self.scene.name} ({self.settings.integrator}, {self.backend.name})",
            dynamic_ncols=True,
        )

    def _run(self, units: list[Unit]):
        workers = min(self.workers, len(units))
        if workers > 1:
            yield from run_on_workers(self.backend, units, workers)
            return
        render_one = self.backend.start()
        for unit in units:
            yield unit, render_one(unit)

    def _assemble(self, results: PixelSums, spp, interrupted, seconds) -> RenderedImage:
        results.finish()
        return self._image(results.mean(), results, spp, interrupted, seconds)

    def _image(self, linear, results: PixelSums, spp, partial, seconds) -> RenderedImage:
        """The RenderedImage of `linear`, the mean of the samples `results` holds."""
        paths, (fewest, most) = results.paths, results.samples_range()
        stats = {
            "seconds": seconds,
            "paths": paths,
            "paths_per_second": paths / seconds if seconds > 0 else math.inf,
            "workers": self.workers,
            "integrator": self.settings.integrator,
            "backend": self.backend.name,
            "peak_rss_mb": peak_memory_mb(children=True),
        }
        return RenderedImage(
            linear,
            gamma=self.settings.gamma,
            spp=spp,
            samples_min=fewest,
            samples_max=most,
            interrupted=partial,
            stats=stats,
        )
