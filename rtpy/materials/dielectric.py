"""Dielectric: smooth glass or water that reflects and refracts."""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..ray import Ray, spawn_ray
from ..sampling import random_double
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import Color, dot, reflect, refract
from .material import Material, as_texture, material_number


def schlick(cosine: float, ior_ratio: float) -> float:
    """Schlick's approximation of the Fresnel reflectance at incidence cosine
    `cosine` for a relative index of refraction `ior_ratio`."""
    # BEGIN SOLUTION week06: Schlick's Fresnel approximation
    r0 = (1.0 - ior_ratio) / (1.0 + ior_ratio)
    r0 = r0 * r0
    return r0 + (1.0 - r0) * (1.0 - cosine) ** 5
    # END SOLUTION


class Dielectric(Material):
    """Smooth boundary with index of refraction `ior` (outside is vacuum, ior 1).

    A ray reflects with probability R = Schlick(cos theta_incident, ior) and
    refracts otherwise; past the critical angle (total internal reflection) it
    always reflects. `albedo` scales both. As in RTIOW, radiance is not scaled
    by 1/eta^2 on refraction. Sampled only (delta).
    """

    is_specular = True

    def __init__(self, ior: float = 1.5, albedo: Color | Texture = Color(1.0, 1.0, 1.0)) -> None:
        self.ior = material_number("ior", ior)
        self.albedo = as_texture(albedo)

    def _split(self, ray_in: Ray, hit: HitInfo) -> tuple[float, Ray, Ray | None]:
        """(R, reflected ray, refracted ray or None under total internal reflection)."""
        # BEGIN SOLUTION week06: (R, reflected ray, refracted ray or None under TIR)
        ratio = 1.0 / self.ior if hit.front_face else self.ior  # eta_incident / eta_transmitted
        d, n = ray_in.direction, hit.normal
        cos_theta = min(-dot(d, n), 1.0)
        sin_theta = math.sqrt(max(0.0, 1.0 - cos_theta * cos_theta))
        reflected = spawn_ray(hit.point, n, reflect(d, n))
        if ratio * sin_theta > 1.0:
            return 1.0, reflected, None
        refracted = spawn_ray(hit.point, n, refract(d, n, ratio))
        return schlick(max(0.0, cos_theta), ratio), reflected, refracted
        # END SOLUTION

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        # BEGIN SOLUTION week06: reflect with probability R, else refract
        reflectance, reflected, refracted = self._split(ray_in, hit)
        albedo = self.albedo.value(hit)
        if refracted is None or random_double() < reflectance:
            return ScatterInfo(reflected, albedo, 0.0, True)
        return ScatterInfo(refracted, albedo, 0.0, True)
        # END SOLUTION

    def specular_rays(self, ray_in: Ray, hit: HitInfo) -> list[tuple[Ray, Color]]:
        reflectance, reflected, refracted = self._split(ray_in, hit)
        albedo = self.albedo.value(hit)
        if refracted is None:
            return [(reflected, albedo)]
        return [(reflected, albedo * reflectance), (refracted, albedo * (1.0 - reflectance))]
