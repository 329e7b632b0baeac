"""The "whitted" integrator (course week 6): direct light at diffuse surfaces,
perfect reflection and refraction at mirrors and glass."""

from __future__ import annotations

from ..ray import Ray
from ..render_settings import RenderSettings
from ..scene import Scene
from ..vec3 import Color
from .direct import DirectIntegrator
from .integrator import FORWARD, Integrator


class WhittedIntegrator(Integrator):
    """Whitted-style ray tracing (Whitted 1980).

    At a non-specular hit: what the "direct" integrator sees along the ray
    (emission + direct light).
    At a specular hit: recurse along the material's deterministic rays: the
    perfect reflection for mirror and metal (fuzz ignored); for glass both the
    reflected ray (weight R) and the refracted ray (weight 1 - R). Recursion
    stops after max_depth segments.
    """

    name = "whitted"

    def __init__(self, settings: RenderSettings | None = None) -> None:
        super().__init__(settings)
        self.direct = DirectIntegrator(self.settings)

    def compute_scattering(self, ray: Ray, scene: Scene, depth: int = 1) -> Color:
        hit = scene.find_intersection(ray, FORWARD)
        if hit is None:
            return scene.background_radiance(ray.direction)
        material = hit.material
        if not material.is_specular and depth < self.settings.max_depth:
            return self.direct.compute_scattering(ray, scene)  # finds the same hit
        result = material.emitting(hit)
        if depth >= self.settings.max_depth:
            return result
        for next_ray, weight in material.specular_rays(ray, hit):
            result = result + weight * self.compute_scattering(next_ray, scene, depth + 1)
        return result
