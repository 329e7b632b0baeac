"""Metal: reflection blurred by a fuzz sphere (the course's and RTIOW's model)."""

from __future__ import annotations

from ..hit_info import HitInfo
from ..ray import Ray, spawn_ray
from ..sampling import random_unit_vector
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import Color, dot, reflect, unit_vector
from .material import Material, as_texture, material_number


class Metal(Material):
    """Scatters toward unit(reflect(d) + fuzz * random unit vector).

    fuzz = 0 is a mirror; larger fuzz blurs the reflection (fuzz 1 is very
    rough). Directions that end up below the surface are absorbed. Sampled only:
    this model has no closed-form BRDF, so integrators treat it as specular (no
    light sampling at it).
    """

    is_specular = True

    def __init__(self, albedo: Color | Texture = Color(0.5, 0.5, 0.5), fuzz: float = 0.0) -> None:
        self.albedo = as_texture(albedo)
        self.fuzz = material_number("fuzz", fuzz)

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        # BEGIN SOLUTION week07: reflection plus fuzz * random unit vector
        direction = reflect(ray_in.direction, hit.normal)
        if self.fuzz > 0.0:
            direction = direction + random_unit_vector() * self.fuzz
            if direction.near_zero(1e-12):
                return None
            direction = unit_vector(direction)
            if dot(direction, hit.normal) <= 0.0:
                return None  # pushed below the surface: absorbed
        return ScatterInfo(
            spawn_ray(hit.point, hit.normal, direction), self.albedo.value(hit), 0.0, True
        )
        # END SOLUTION

    def specular_rays(self, ray_in: Ray, hit: HitInfo) -> list[tuple[Ray, Color]]:
        # Whitted follows the perfect reflection and ignores fuzz.
        direction = reflect(ray_in.direction, hit.normal)
        return [(spawn_ray(hit.point, hit.normal, direction), self.albedo.value(hit))]
