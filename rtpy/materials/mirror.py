"""Mirror: perfect specular reflection."""

from __future__ import annotations

from ..hit_info import HitInfo
from ..ray import Ray, spawn_ray
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import Color, reflect
from .material import Material, as_texture


class Mirror(Material):
    """Reflects every ray about the normal; the reflected light is scaled by albedo.
    A delta BRDF: sampled only (weight = albedo, no cosine, no pdf)."""

    is_specular = True

    def __init__(self, albedo: Color | Texture = Color(1.0, 1.0, 1.0)) -> None:
        self.albedo = as_texture(albedo)

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        # BEGIN SOLUTION week06: the perfect mirror ray, weight albedo
        direction = reflect(ray_in.direction, hit.normal)
        return ScatterInfo(
            spawn_ray(hit.point, hit.normal, direction), self.albedo.value(hit), 0.0, True
        )
        # END SOLUTION

    def specular_rays(self, ray_in: Ray, hit: HitInfo) -> list[tuple[Ray, Color]]:
        s = self.scattering(ray_in, hit)
        return [(s.scattered_ray, s.attenuation)]
