"""The "direct" integrator (course week 5): emission plus one bounce of light."""

from __future__ import annotations

from ..ray import Ray
from ..scene import Scene
from ..vec3 import Color
from .direct_lighting import direct_lighting
from .integrator import FORWARD, Integrator


class DirectIntegrator(Integrator):
    """Emission seen directly plus light arriving after one reflection, from
    point and area lights (with shadow rays) and the background. No indirect
    bounce. This is exactly the "path" estimator with max_depth = 2 (mis = False
    included)."""

    name = "direct"

    def compute_scattering(self, ray: Ray, scene: Scene) -> Color:
        """Radiance arriving along the camera ray: the background when it hits
        nothing, else the emission of the surface hit (seen directly) plus
        direct_lighting there (with the settings' mis)."""
        # BEGIN SOLUTION week05: emission plus direct lighting at the first hit
        hit = scene.find_intersection(ray, FORWARD)
        if hit is None:
            return scene.background_radiance(ray.direction)
        emitted = hit.material.emitting(hit)
        return emitted + direct_lighting(scene, ray, hit, self.settings.mis)
        # END SOLUTION
