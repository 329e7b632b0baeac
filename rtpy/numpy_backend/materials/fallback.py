"""ScalarFallback: any material without a kernel, run through its scalar methods per hit.

A material class the table does not know (a student's class, or a subclass of a known
one: dispatch is by exact type, since a subclass may change anything) still renders:
each of its hits becomes a scalar HitInfo and Rays, and the material's own methods
are called. The arriving ray is rebuilt as origin = point + t wo, direction -wo;
a light ray starts at the hit point. Sampling draws from a random.Random seeded from
the numpy generator, so a render stays deterministic for a seed.
"""

from __future__ import annotations

import random

import numpy as np

from ...ray import Ray
from ...sampling import use_generator
from ...vec3 import Vec3
from ..hit_info import HitBatch
from ..scatter_info import ScatterBatch, SpecularRays
from ..vec3 import to_vec3
from .material import Kernel


class ScalarFallback(Kernel):
    """Per-hit calls of the scalar methods of arbitrary materials."""

    has_brdf = True
    scatters = True
    emits = True
    has_specular_rays = True
    reads_tangent = True
    reads_uv = True

    def _hit(self, slots: np.ndarray, hits: HitBatch, i: int):
        """(material, HitInfo, the arriving ray) of hit i."""
        material = self.materials[slots[i]]
        hit = hits.hit_info(i, material)
        wo = hits.wo[i]
        t = float(hits.t[i])
        origin = Vec3(hit.point.e0 + t * wo[0], hit.point.e1 + t * wo[1], hit.point.e2 + t * wo[2])
        ray_in = Ray(origin, Vec3(-float(wo[0]), -float(wo[1]), -float(wo[2])))
        return material, hit, ray_in

    def _per_hit(self, slots: np.ndarray, hits: HitBatch, value, wi: np.ndarray | None = None):
        """value(material, hit, ray_in, ray_light) for every hit, as an array (ray_light
        is the ray toward wi[i], or None without wi)."""
        out = []
        for i in range(len(slots)):
            material, hit, ray_in = self._hit(slots, hits, i)
            ray_light = None if wi is None else Ray(hit.point, to_vec3(wi[i]))
            out.append(value(material, hit, ray_in, ray_light))
        return np.array(out, dtype=np.float64)

    def flat_color(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        colors = self._per_hit(slots, hits, lambda m, hit, ray, _: tuple(m.flat_color(hit)))
        return colors.reshape(-1, 3)

    def emitting(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        colors = self._per_hit(slots, hits, lambda m, hit, ray, _: tuple(m.emitting(hit)))
        return colors.reshape(-1, 3)

    def BRDF(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        f = self._per_hit(slots, hits, lambda m, hit, ray, to: tuple(m.BRDF(ray, to, hit)), wi)
        return f.reshape(-1, 3)

    def pdf(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        return self._per_hit(slots, hits, lambda m, hit, ray, light: m.pdf(ray, light, hit), wi)

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        out = ScatterBatch.absorbed(len(slots))
        with use_generator(random.Random(int(rng.integers(2**63)))):
            for i in range(len(slots)):
                material, hit, ray_in = self._hit(slots, hits, i)
                s = material.scattering(ray_in, hit)
                if s is None:
                    continue
                out.direction[i] = tuple(s.scattered_ray.direction)
                out.attenuation[i] = tuple(s.attenuation)
                out.pdf[i] = s.pdf
                out.alive[i] = True
                out.is_specular[i] = bool(s.is_specular)
        return out

    def specular_rays(self, slots: np.ndarray, hits: HitBatch) -> SpecularRays:
        n = len(slots)
        entries: SpecularRays = []
        for i in range(n):
            material, hit, ray_in = self._hit(slots, hits, i)
            for k, (ray, weight) in enumerate(material.specular_rays(ray_in, hit)):
                if k == len(entries):
                    entries.append((np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, bool)))
                entries[k][0][i] = tuple(ray.direction)
                entries[k][1][i] = tuple(weight)
                entries[k][2][i] = True
        return entries
