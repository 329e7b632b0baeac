"""NumpyBackend: the numpy backend of rtpy.engine.renderer's one render loop.

The loop (rtpy/engine/renderer.py) and the plan (rtpy/engine/plan.py) are the scalar backend's:
passes over the image cut into units of work, each unit drawing from its own
generator seeded by (seed, region, pass), sums added in pass order, so the same
seed gives the same image, bit for bit, wherever the units run. What differs is the
unit: all its samples for every pixel of its band of rows are traced together as
one wavefront of at most MAX_RAYS paths (numpy's cost per call is paid per segment
of a wavefront, so small wavefronts are slow), and memory is bounded by the unit
size, not by image size times spp. (The scalar and numpy backends draw different
random numbers: their images agree up to Monte Carlo noise, not bit for bit.)
Registered as "numpy" by rtpy.engine.backends.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

import numpy as np

from ..engine.backend import Backend
from ..engine.plan import Plan, Unit
from .camera import CameraRays
from .integrators import BatchIntegrator, make_integrator
from .sampler import BATCH_SAMPLERS, LaneSampler
from .sampling import make_generator
from .scene import BatchScene

# Camera samples per unit of work. Large, because after the first bounces few paths
# live and each segment costs hundreds of numpy calls whatever their length; the
# arrays of a unit's rays (a few MB each) bound the memory of a render.
MAX_RAYS = 65536


def render_unit(
    scene: BatchScene,
    rays: CameraRays,
    integrator: BatchIntegrator,
    seed: int,
    unit: Unit,
    sampler: str = "independent",
) -> np.ndarray:
    """Sum of unit.spp radiance samples per pixel of the unit's region: (h, w, 3).
    Every draw comes from the unit's generator, or with another sampler from a
    LaneSampler that knows which pixel sample each lane is."""
    rng = make_generator(seed, unit.region, unit.batch)
    h, w = unit.y1 - unit.y0, unit.x1 - unit.x0
    j, i = np.divmod(np.arange(h * w), w)
    i = np.repeat(i + unit.x0, unit.spp)
    j = np.repeat(j + unit.y0, unit.spp)
    camera_rng = rng
    if sampler != "independent":
        spp = 1 if integrator.uses_center_ray else integrator.settings.spp
        index = np.tile(np.arange(unit.first_sample, unit.first_sample + unit.spp), h * w)
        rng = LaneSampler(BATCH_SAMPLERS[sampler](seed, spp), j * rays.width + i, index, rng)
        camera_rng = rng.camera()
    if integrator.uses_center_ray:
        o, d = rays.center_rays(i, j, camera_rng)
    else:
        o, d = rays.jittered_rays(i, j, camera_rng)
    radiance = integrator.compute_scattering(o, d, scene, rng)
    return radiance.reshape(h, w, unit.spp, 3).sum(axis=2)


class NumpyBackend(Backend):
    """Renders a unit of work as arrays: the scene as a BatchScene, camera rays from
    CameraRays, the integrator's batched twin."""

    name = "numpy"
    paths_per_unit = MAX_RAYS

    def make_integrator(self) -> BatchIntegrator:
        return make_integrator(self.settings)

    def plan(self, width: int, height: int, spp: int) -> Plan:
        return Plan(width, height, spp, MAX_RAYS)  # read now: a test may make it smaller

    def start(self) -> Callable[[Unit], np.ndarray]:
        scene, rays = BatchScene(self.scene), CameraRays(self.camera)
        integrator = self.make_integrator()
        settings = self.settings
        return partial(
            render_unit, scene, rays, integrator, settings.seed, sampler=settings.sampler
        )
