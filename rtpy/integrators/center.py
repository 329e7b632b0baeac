"""The "center" integrator (course week 3): flat colour of the first hit."""

from __future__ import annotations

from ..ray import Ray
from ..scene import Scene
from ..vec3 import Color
from .integrator import FORWARD, Integrator


def flat_color(ray: Ray, scene: Scene) -> Color:
    """Emitted radiance if the ray hits an emitter's emitting face, else the
    albedo (texture value) of the surface hit, else the background."""
    # BEGIN SOLUTION week03: emission, else albedo of the first hit, else the background
    hit = scene.find_intersection(ray, FORWARD)
    if hit is None:
        return scene.background_radiance(ray.direction)
    material = hit.material
    if material.is_emitter:
        emitted = material.emitting(hit)
        if not emitted.is_black():
            return emitted
    return material.flat_color(hit)
    # END SOLUTION


class CenterIntegrator(Integrator):
    """One ray through each pixel's center; no lighting at all."""

    name = "center"
    uses_center_ray = True

    def compute_scattering(self, ray: Ray, scene: Scene) -> Color:
        return flat_color(ray, scene)
