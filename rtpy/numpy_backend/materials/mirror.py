"""Kernel of Mirror (rtpy/materials/mirror.py)."""

from __future__ import annotations

import numpy as np

from ..arrays import true
from ..hit_info import HitBatch
from ..scatter_info import ScatterBatch, SpecularRays
from ..vec3 import components, reflect, stack
from .material import AlbedoKernel


class MirrorKernel(AlbedoKernel):
    """The perfect reflection, weight albedo."""

    scatters = True
    has_specular_rays = True

    def reflected(self, hits: HitBatch) -> np.ndarray:
        """(N, 3) mirror directions of the arriving rays."""
        d = components(-hits.wo)  # the arriving ray's direction
        return stack(*reflect(d, components(hits.normal)))

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        n = len(slots)
        weight = self.albedo(slots, hits)
        return ScatterBatch(self.reflected(hits), weight, np.zeros(n), true(n), true(n))

    def specular_rays(self, slots: np.ndarray, hits: HitBatch) -> SpecularRays:
        return [(self.reflected(hits), self.albedo(slots, hits), true(len(slots)))]
