"""The numpy backend's renderer: tiles of camera samples traced as arrays.

The image is cut into square tiles and each pixel's samples into batches, as in
rtpy/renderer.py, but a unit of work (batch, tile) is large: all samples of the
batch for every pixel of the tile, traced together as one wavefront of at most
MAX_RAYS paths. So memory is bounded by the unit size, not by image size times
spp. Units run batch by batch (an interrupted render covers the whole image
with fewer samples); each draws from its own numpy Generator seeded by
(seed, tile, batch), and sums are combined in a fixed order, so the same seed
gives the same image, bit for bit, with any number of worker processes.
(The scalar and numpy backends draw different random numbers: their images
agree up to Monte Carlo noise, not bit for bit.)
"""

from __future__ import annotations

import ctypes
import math
import multiprocessing
import resource
import signal
import sys

import numpy as np

from ..camera import Camera
from ..io.image import RenderedImage
from ..render_settings import RenderSettings
from ..renderer import Renderer, Unit
from ..renderer import plan_units as scalar_plan_units
from ..scene import Scene
from .camera import CameraRays
from .integrators import BatchIntegrator, Tracer, make_integrator

TILE_SIZE = 32
# Camera samples per unit of work. Large, because after the first bounces few paths
# live and each segment costs hundreds of numpy calls whatever their length: 65,536
# was 1.3x faster than 16,384 on week08_three_balls and ~1.07x on cornell.
MAX_RAYS = 65536


def plan_units(width: int, height: int, spp: int) -> list[Unit]:
    """All units of work, batch-major: each tile's spp split into the fewest batches
    that keep a unit at or under MAX_RAYS samples."""
    n_batches = max(1, math.ceil(spp * TILE_SIZE * TILE_SIZE / MAX_RAYS))
    return scalar_plan_units(width, height, spp, min(n_batches, spp), TILE_SIZE)


def keep_freed_memory() -> None:
    """Ask glibc's malloc to keep freed blocks of up to 32 MB in the heap (Linux; a
    no-op elsewhere). The backend allocates and frees the same temporaries of a few
    hundred KB (arrays over a unit's rays) thousands of times per second; by default
    glibc maps each one freshly from the kernel and unmaps it when it is freed, so
    every page of every temporary faults on first touch: ~1/4 of the render time on
    the development machine. This is malloc's documented tuning (mallopt, the
    MALLOC_MMAP_THRESHOLD_ and MALLOC_TRIM_THRESHOLD_ variables), process-wide: the
    process keeps up to 128 MB of freed memory for reuse instead of returning it."""
    global _malloc_tuned
    if _malloc_tuned or not sys.platform.startswith("linux"):
        return
    _malloc_tuned = True
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(M_MMAP_THRESHOLD, 32 << 20)
        libc.mallopt(M_TRIM_THRESHOLD, 128 << 20)
    except (OSError, AttributeError):  # not glibc: keep the allocator's defaults
        pass


M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # glibc's <malloc.h>
_malloc_tuned = False


def unit_generator(seed: int, unit: Unit) -> np.random.Generator:
    return np.random.default_rng([int(seed), unit.tile, unit.batch])


def render_unit(
    tracer: Tracer, rays: CameraRays, integrator: BatchIntegrator, seed: int, unit: Unit
) -> np.ndarray:
    """Sum of unit.spp radiance samples per pixel of the unit's tile: (h, w, 3)."""
    rng = unit_generator(seed, unit)
    h, w = unit.y1 - unit.y0, unit.x1 - unit.x0
    j, i = np.divmod(np.arange(h * w), w)
    i = np.repeat(i + unit.x0, unit.spp)
    j = np.repeat(j + unit.y0, unit.spp)
    if integrator.uses_center_ray:
        o, d = rays.center_rays(i, j, rng)
    else:
        o, d = rays.jittered_rays(i, j, rng)
    radiance = integrator.compute_scattering(tracer, o, d, rng)
    return radiance.reshape(h, w, unit.spp, 3).sum(axis=2)


# --- worker processes -------------------------------------------------------
_worker_state: tuple | None = None


def _init_worker(scene: Scene, camera: Camera, settings: RenderSettings) -> None:
    global _worker_state
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C
    keep_freed_memory()
    _worker_state = (Tracer(scene), CameraRays(camera), make_integrator(settings), settings.seed)


def _run_unit(unit: Unit) -> tuple[Unit, np.ndarray]:
    tracer, rays, integrator, seed = _worker_state
    return unit, render_unit(tracer, rays, integrator, seed, unit)


def peak_rss_mb() -> float:
    """Peak resident memory in MB of this process and of its finished children (the
    largest of them; Linux reports kilobytes)."""
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return max(own, children) / 1024.0


class NumpyRenderer(Renderer):
    """Renders with the numpy backend; the interface and the result are those of
    rtpy.renderer.Renderer (stats also hold "backend" and "peak_rss_mb")."""

    backend_label = ", numpy"

    def plan_units(self, width: int, height: int, spp: int) -> list[Unit]:
        return plan_units(width, height, spp)

    def uses_center_ray(self) -> bool:
        return make_integrator(self.settings).uses_center_ray

    def render(self) -> RenderedImage:
        keep_freed_memory()
        image = super().render()
        image.stats["backend"] = "numpy"
        image.stats["peak_rss_mb"] = peak_rss_mb()
        return image

    def _run(self, units: list[Unit]):
        if self.workers == 1:
            tracer = Tracer(self.scene)
            rays = CameraRays(self.camera)
            integrator = make_integrator(self.settings)
            for unit in units:
                yield unit, render_unit(tracer, rays, integrator, self.settings.seed, unit)
            return
        pool = multiprocessing.get_context().Pool(
            self.workers, _init_worker, (self.scene, self.camera, self.settings)
        )
        try:
            yield from pool.imap_unordered(_run_unit, units, chunksize=1)
            pool.close()
        except BaseException:
            pool.terminate()
            raise
        finally:
            pool.join()
