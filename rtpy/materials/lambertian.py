"""Lambertian: ideal diffuse reflection, f_r = albedo / pi."""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..onb import ONB
from ..ray import Ray, spawn_ray
from ..sampling import random_cosine_direction
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import BLACK, Color, dot
from .material import Material, as_texture

INV_PI = 1.0 / math.pi


class Lambertian(Material):
    """Reflects equally in all directions: f_r = albedo / pi.

    Sampling is cosine-weighted, pdf = cos(theta) / pi, so the weight
    BRDF * cos / pdf is exactly the albedo.
    """

    def __init__(self, albedo: Color | Texture = Color(0.5, 0.5, 0.5)) -> None:
        self.albedo = as_texture(albedo)

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        """A cosine-weighted direction around hit.normal (pdf = cos(theta) / pi), the
        ray leaving the surface toward it (spawn_ray), its weight BRDF * cos / pdf and
        its pdf."""
        # BEGIN SOLUTION week05: cosine-weighted direction, weight = BRDF * cos / pdf
        local = random_cosine_direction()  # z = cos(theta) from the normal
        direction = ONB(hit.normal).to_world(local)
        # BRDF * cos / pdf = (albedo / pi) * cos / (cos / pi) = albedo
        return ScatterInfo(
            spawn_ray(hit.point, hit.normal, direction), self.albedo.value(hit), local.z() * INV_PI
        )
        # END SOLUTION

    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        """f_r = albedo / pi for light arriving from above the surface (ray_light's
        direction, toward the light, on the side of hit.normal), black from below."""
        # BEGIN SOLUTION week05: f_r = albedo / pi above the surface
        if dot(hit.normal, ray_light.direction) <= 0.0:
            return BLACK  # light below the surface
        return self.albedo.value(hit) * INV_PI
        # END SOLUTION

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        """The density cos(theta) / pi with which scattering() picks ray_light's
        direction (0 below the surface)."""
        # BEGIN SOLUTION week05: cos(theta) / pi above the surface, 0 below
        return max(0.0, dot(hit.normal, ray_light.direction)) * INV_PI
        # END SOLUTION
