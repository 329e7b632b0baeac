"""The "shading" integrator (lecture 6's second rung, course week 6): local shading
of the first hit by every light, with or without shadow rays.

Not the rendering equation: no light arrives after a bounce, so mirrors and glass
(whose BRDF is a delta) show only what they emit, and nothing is lit indirectly.
"""

from __future__ import annotations

from ..hit_info import HitInfo
from ..light import Light
from ..ray import Ray
from ..scene import Scene
from ..vec3 import BLACK, Color, dot
from .direct_lighting import light_sample_estimate
from .integrator import FORWARD, Integrator


def light_from(scene: Scene, ray: Ray, hit: HitInfo, light: Light, shadows: bool) -> Color:
    """The radiance reflected at `hit` toward -ray.direction by one sample of one light:

        f_r(wi, wo) * L * cos(theta_i) / pdf

    (a point light: L = I / d^2 and pdf = 1, so Lambertian gives albedo / pi * I *
    cos(theta_i) / d^2). With shadows, light_sample_estimate: black when the shadow ray
    is blocked. Without, nothing blocks the light: every point facing it is lit."""
    sample = light.sample(hit.point)
    if sample is None or sample.radiance.is_black():
        return BLACK
    if shadows:
        return light_sample_estimate(scene, ray, hit, sample, light.shape)
    wi = sample.direction
    f = hit.material.BRDF(ray, Ray(hit.point, wi), hit)
    return f * sample.radiance * (abs(dot(hit.normal, wi)) / sample.pdf)


class ShadingIntegrator(Integrator):
    """What the camera ray sees: the background if it hits nothing, else the emission
    of the surface hit plus, at a non-specular surface, light_from every light (point
    lights exactly, area lights by one sample each), shadow rays only when the
    settings' `shadows` is true."""

    name = "shading"

    def compute_scattering(self, ray: Ray, scene: Scene) -> Color:
        hit = scene.find_intersection(ray, FORWARD)
        if hit is None:
            return scene.background_radiance(ray.direction)
        result = hit.material.emitting(hit)
        if hit.material.is_specular:
            return result
        for light in scene.lights:
            result = result + light_from(scene, ray, hit, light, self.settings.shadows)
        return result
