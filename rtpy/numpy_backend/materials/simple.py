"""Kernels of the course's materials: Lambertian, Mirror, Metal, Dielectric, DiffuseLight."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...materials import Dielectric, DiffuseLight, Lambertian, Metal, Mirror
from ...testing.analytic_scenes import GlowingLambertian
from ..arrays import put_rows, where_rows
from ..hits import HitBatch
from .frame import (
    components,
    cosine_direction,
    dot,
    local_to_world,
    reflect,
    select,
    stack,
    take,
    uniform_sphere,
)
from .kernel import AlbedoKernel, Kernel, ScatterBatch, SpecularRays, color_param, param

INV_PI = 1.0 / math.pi


def _true(n: int) -> np.ndarray:
    return np.ones(n, dtype=bool)


class LambertianKernel(AlbedoKernel):
    """Lambertian: f_r = albedo / pi, cosine-weighted sampling (weight = albedo)."""

    evaluates = True
    scatters = True

    def sample(self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        n = len(slots)
        r = rng.random((2, n))
        x, y, z = cosine_direction(r[0], r[1])
        direction = stack(*local_to_world(components(hits.normal), x, y, z))
        return ScatterBatch(direction, self.albedo(slots, hits), z * INV_PI, _true(n), ~_true(n))

    def eval(
        self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        cos = dot(components(hits.normal), components(wi))
        up = select(cos > 0.0)
        if isinstance(up, slice):
            f = self.albedo(slots, hits) * INV_PI
        else:
            f = np.zeros((len(slots), 3))
            put_rows(f, up, self.albedo(slots.take(up), hits, up) * INV_PI)
        return f, np.maximum(0.0, cos) * INV_PI


class MirrorKernel(AlbedoKernel):
    """Mirror: the perfect reflection, weight albedo."""

    scatters = True
    has_specular_rays = True

    def reflected(self, hits: HitBatch) -> np.ndarray:
        d = components(-hits.wo)  # the arriving ray's direction
        return stack(*reflect(d, components(hits.normal)))

    def sample(self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        n = len(slots)
        weight = self.albedo(slots, hits)
        return ScatterBatch(self.reflected(hits), weight, np.zeros(n), _true(n), _true(n))

    def specular_rays(self, slots: np.ndarray, hits: HitBatch) -> SpecularRays:
        return [(self.reflected(hits), self.albedo(slots, hits), _true(len(slots)))]


class MetalKernel(MirrorKernel):
    """Metal: unit(reflection + fuzz * uniform unit vector), absorbed below the surface;
    the Whitted ray is the perfect reflection."""

    def __init__(self, materials: Sequence[Metal]) -> None:
        super().__init__(materials)
        self.fuzz = param(self.materials, "fuzz")

    def sample(self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        out = super().sample(slots, hits, rng)
        fuzz = self.fuzz[slots]
        fuzzy = np.flatnonzero(fuzz > 0.0)
        if len(fuzzy) == 0:
            return out
        r = rng.random((2, len(fuzzy)))
        s = uniform_sphere(r[0], r[1])
        f = fuzz[fuzzy]
        d = components(out.direction[fuzzy])
        d = (d[0] + s[0] * f, d[1] + s[1] * f, d[2] + s[2] * f)
        alive = ~((np.abs(d[0]) < 1e-12) & (np.abs(d[1]) < 1e-12) & (np.abs(d[2]) < 1e-12))
        length2 = np.where(alive, dot(d, d), 1.0)
        k = 1.0 / np.sqrt(length2)
        d = (d[0] * k, d[1] * k, d[2] * k)
        alive &= dot(d, take(components(hits.normal), fuzzy)) > 0.0  # else absorbed
        out.direction[fuzzy] = np.where(alive[:, None], stack(*d), 0.0)
        out.weight[fuzzy] *= alive[:, None]
        out.alive[fuzzy] = alive
        out.specular[fuzzy] = alive
        return out


class DielectricKernel(AlbedoKernel):
    """Dielectric: reflect with probability R (Schlick), else refract; total internal
    reflection past the critical angle; albedo scales both."""

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
        # rtpy.vec3.refract (its cos_theta is the one above)
        k = ratio
        perp = tuple((d[c] + n[c] * cos_theta) * k for c in range(3))
        s = -np.sqrt(np.abs(1.0 - dot(perp, perp)))
        refracted = stack(perp[0] + n[0] * s, perp[1] + n[1] * s, perp[2] + n[2] * s)
        refracted[~refracts] = 0.0
        # Schlick's reflectance (rtpy.materials.schlick); 1 under total internal reflection
        r0 = (1.0 - ratio) / (1.0 + ratio)
        r0 = r0 * r0
        reflectance = r0 + (1.0 - r0) * (1.0 - np.maximum(0.0, cos_theta)) ** 5
        reflectance = np.where(refracts, reflectance, 1.0)
        return reflectance, stack(*reflect(d, n)), refracted, refracts

    def sample(self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        n = len(slots)
        reflectance, reflected, refracted, refracts = self.split(slots, hits)
        refract = refracts & ~(rng.random(n) < reflectance)
        direction = np.where(refract[:, None], refracted, reflected)
        return ScatterBatch(direction, self.albedo(slots, hits), np.zeros(n), _true(n), _true(n))

    def specular_rays(self, slots: np.ndarray, hits: HitBatch) -> SpecularRays:
        reflectance, reflected, refracted, refracts = self.split(slots, hits)
        albedo = self.albedo(slots, hits)
        transmitted = np.where(refracts[:, None], albedo * (1.0 - reflectance[:, None]), 0.0)
        return [
            (reflected, albedo * reflectance[:, None], _true(len(slots))),
            (refracted, transmitted, refracts),
        ]


class DiffuseLightKernel(Kernel):
    """DiffuseLight: emits `emit` from the front face (or both), scatters nothing."""

    emits = True

    def __init__(self, materials: Sequence[DiffuseLight]) -> None:
        super().__init__(materials)
        self.emit = color_param(self.materials, "emit")
        self.two_sided = np.array([bool(m.two_sided) for m in self.materials])

    def emitted(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        on = hits.front_face | self.two_sided.take(slots)
        return where_rows(on, self.emit.take(slots, axis=0))


class GlowingLambertianKernel(LambertianKernel):
    """The analytic scenes' GlowingLambertian: the Lambertian kernel plus uniform
    emission from both faces (without it those scenes would call the scalar
    methods per ray, about 50 times slower)."""

    emits = True

    def __init__(self, materials: Sequence[GlowingLambertian]) -> None:
        super().__init__(materials)
        self.emit = color_param(self.materials, "emit")

    def emitted(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return self.emit.take(slots, axis=0)


SIMPLE_KERNELS = {
    Lambertian: LambertianKernel,
    GlowingLambertian: GlowingLambertianKernel,
    Mirror: MirrorKernel,
    Metal: MetalKernel,
    Dielectric: DielectricKernel,
    DiffuseLight: DiffuseLightKernel,
}
