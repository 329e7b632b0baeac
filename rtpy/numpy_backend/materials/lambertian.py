"""Kernel of Lambertian (rtpy/materials/lambertian.py), and of an emitting Lambertian."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import Lambertian
from ..arrays import put_rows, select
from ..hit_info import HitBatch
from ..onb import local_to_world
from ..sampling import cosine_direction
from ..scatter_info import ScatterBatch
from ..vec3 import components, dot, stack
from .material import INV_PI, AlbedoKernel, color_param


class LambertianKernel(AlbedoKernel):
    """f_r = albedo / pi, sampled cosine-weighted (weight = albedo)."""

    has_brdf = True
    scatters = True

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        n = len(slots)
        r = rng.random((2, n))
        local = cosine_direction(r[0], r[1])  # z = cos(theta) from the normal
        direction = stack(*local_to_world(components(hits.normal), *local))
        # BRDF * cos / pdf = (albedo / pi) * cos / (cos / pi) = albedo
        alive = np.ones(n, dtype=bool)
        return ScatterBatch(direction, self.albedo(slots, hits), local[2] * INV_PI, alive, ~alive)

    def BRDF(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        return self._brdf(slots, hits, self._cos(hits, wi))

    def pdf(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        return np.maximum(0.0, self._cos(hits, wi)) * INV_PI

    def BRDF_and_pdf(self, slots, hits, wi):
        cos = self._cos(hits, wi)
        return self._brdf(slots, hits, cos), np.maximum(0.0, cos) * INV_PI

    @staticmethod
    def _cos(hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        return dot(components(hits.normal), components(wi))

    def _brdf(self, slots: np.ndarray, hits: HitBatch, cos: np.ndarray) -> np.ndarray:
        """albedo / pi where the light is above the surface (cos > 0), else 0."""
        up = select(cos > 0.0)
        if isinstance(up, slice):
            return self.albedo(slots, hits) * INV_PI
        f = np.zeros((len(slots), 3))
        put_rows(f, up, self.albedo(slots.take(up), hits, up) * INV_PI)
        return f


class GlowingLambertianKernel(LambertianKernel):
    """A Lambertian that also emits `emit` from both faces: the closed-form
    "glowing furnace" scene's GlowingLambertian (rtpy/testing/analytic_scenes.py).
    The table finds it by the class's qualified name (table.KERNELS), so neither
    package imports the other."""

    emits = True

    def __init__(self, materials: Sequence[Lambertian]) -> None:
        super().__init__(materials)
        self.emit = color_param(self.materials, "emit")

    def emitting(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return self.emit.take(slots, axis=0)
