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
from ..hits import HitBatch
from .kernel import Kernel, ScatterBatch, SpecularRays


def _vec(a: np.ndarray) -> Vec3:
    return Vec3(float(a[0]), float(a[1]), float(a[2]))


class ScalarFallback(Kernel):
    """Per-hit calls of the scalar methods of arbitrary materials."""

    evaluates = True
    scatters = True
    emits = True
    has_specular_rays = True

    def _hit(self, slots: np.ndarray, hits: HitBatch, i: int):
        material = self.materials[slots[i]]
        hit = hits.hit_info(i, material)
        wo = hits.wo[i]
        t = float(hits.t[i])
        origin = Vec3(hit.point.e0 + t * wo[0], hit.point.e1 + t * wo[1], hit.point.e2 + t * wo[2])
        ray_in = Ray(origin, Vec3(-float(wo[0]), -float(wo[1]), -float(wo[2])))
        return material, hit, ray_in

    def flat_color(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        out = np.empty((len(slots), 3))
        for i in range(len(slots)):
            material, hit, _ = self._hit(slots, hits, i)
            out[i] = tuple(material.flat_color(hit))
        return out

    def emitted(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        out = np.empty((len(slots), 3))
        for i in range(len(slots)):
            material, hit, _ = self._hit(slots, hits, i)
            out[i] = tuple(material.emitting(hit))
        return out

    def eval(
        self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        f, pdf = np.empty((len(slots), 3)), np.empty(len(slots))
        for i in range(len(slots)):
            material, hit, ray_view = self._hit(slots, hits, i)
            ray_light = Ray(hit.point, _vec(wi[i]))
            f[i] = tuple(material.BRDF(ray_view, ray_light, hit))
            pdf[i] = material.pdf(ray_view, ray_light, hit)
        return f, pdf

    def sample(self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        out = ScatterBatch.absorbed(len(slots))
        with use_generator(random.Random(int(rng.integers(2**63)))):
            for i in range(len(slots)):
                material, hit, ray_in = self._hit(slots, hits, i)
                s = material.scattering(ray_in, hit)
                if s is None:
                    continue
                out.direction[i] = tuple(s.scattered_ray.direction)
                out.weight[i] = tuple(s.attenuation)
                out.pdf[i] = s.pdf
                out.alive[i] = True
                out.specular[i] = bool(s.is_specular)
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
