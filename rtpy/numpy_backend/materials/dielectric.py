"""Kernel of Dielectric (rtpy/materials/dielectric.py)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import Dielectric, schlick  # the course function, on arrays as it is
from ..arrays import true
from ..hit_info import HitBatch
from ..scatter_info import ScatterBatch, SpecularRays
from ..vec3 import components, dot, reflect, refract, stack
from .material import AlbedoKernel, param


class DielectricKernel(AlbedoKernel):
    """Reflect with probability R (Schlick), else refract; total internal reflection
    past the critical angle; albedo scales both."""

    scatters = True
    has_specular_rays = True

    def __init__(self, materials: Sequence[Dielectric]) -> None:
        super().__init__(materials)
        self.ior = param(self.materials, "ior")

    def split(self, slots: np.ndarray, hits: HitBatch) -> tuple[np.ndarray, ...]:
        """Dielectric._split: (R, reflected (n, 3), refracted (n, 3), refracts (n,) bool);
        the refracted direction is 0 where total internal reflection leaves none."""
        ior = self.ior[slots]
        ratio = np.where(hits.front_face, 1.0 / ior, ior)  # eta_incident / eta_transmitted
        d, n = components(-hits.wo), components(hits.normal)
        cos_theta = np.minimum(-dot(d, n), 1.0)
        sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
        refracts = ~(ratio * sin_theta > 1.0)
        refracted = stack(*refract(d, n, ratio))
        refracted[~refracts] = 0.0
        reflectance = np.where(refracts, schlick(np.maximum(0.0, cos_theta), ratio), 1.0)
        return reflectance, stack(*reflect(d, n)), refracted, refracts

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        n = len(slots)
        reflectance, reflected, refracted, refracts = self.split(slots, hits)
        transmit = refracts & ~(rng.random(n) < reflectance)
        direction = np.where(transmit[:, None], refracted, reflected)
        return ScatterBatch(direction, self.albedo(slots, hits), np.zeros(n), true(n), true(n))

    def specular_rays(self, slots: np.ndarray, hits: HitBatch) -> SpecularRays:
        reflectance, reflected, refracted, refracts = self.split(slots, hits)
        albedo = self.albedo(slots, hits)
        transmitted = np.where(refracts[:, None], albedo * (1.0 - reflectance[:, None]), 0.0)
        return [
            (reflected, albedo * reflectance[:, None], true(len(slots))),
            (refracted, transmitted, refracts),
        ]
