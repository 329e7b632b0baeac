"""The scalar backend: the readable reference of rtpy's render loop.

A unit of work (rtpy.engine.plan.Unit) is rendered the way the course renders an image:
for every pixel of the unit's region, for every sample, one camera ray through the
integrator's compute_scattering, and the colours summed. Every random number comes
from the unit's own generator (or a sampler told which pixel sample each path is),
so the image depends on the seed alone (rtpy.engine.plan).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

import numpy as np

from ..camera import Camera
from ..integrators import make_integrator
from ..sampler import SAMPLERS
from ..sampling import make_generator, use_generator
from ..scene import Scene
from .backend import Backend
from .plan import Unit
from .prepared_scene import prepared_scene

__all__ = ["ScalarBackend", "render_unit"]


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
    width = camera.width
    with use_generator(source):
        for j in range(unit.y0, unit.y1):
            for i in range(unit.x0, unit.x1):
                r = g = b = 0.0
                pixel = j * width + i
                for index in samples:
                    if start is not None:
                        start(pixel, index)
                    c = radiance(get_ray(i, j), scene)
                    r += c.e0
                    g += c.e1
                    b += c.e2
                sums.append((r, g, b))
    return np.array(sums, dtype=np.float64).reshape(unit.y1 - unit.y0, unit.x1 - unit.x0, 3)


class ScalarBackend(Backend):
    """The readable reference: one Ray at a time through the scalar integrators, in
    units of at most 4,096 paths (a fraction of a second to a few seconds each).
    Spheres are hit and sphere lights sampled per component, the course's numbers
    (rtpy.engine.prepared_scene). Registered as "scalar" by rtpy.engine.backends."""

    name = "scalar"
    paths_per_unit = 4096

    def make_integrator(self):
        return make_integrator(self.settings)

    def start(self) -> Callable[[Unit], np.ndarray]:
        integrator = self.make_integrator()
        settings = self.settings
        return partial(
            render_unit,
            prepared_scene(self.scene),
            self.camera,
            integrator,
            settings.seed,
            sampler=settings.sampler,
        )
