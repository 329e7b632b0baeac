"""The "path" integrator (course weeks 8 and 11): unbiased path tracing."""

from __future__ import annotations

from ..ray import Ray
from ..sampling import random_double
from ..scene import Scene
from ..vec3 import Color
from .direct_lighting import emission_weight, sample_one_light
from .integrator import FORWARD, Integrator


class PathIntegrator(Integrator):
    """Estimates the rendering equation along one random path per camera ray.

    At every vertex: add the emission found there (MIS-weighted against light
    sampling), add a light-sampling estimate (next-event estimation), then
    continue along the direction scattering() samples, multiplying the path
    throughput `beta` by its weight BRDF * cos / pdf.

    max_depth counts ray segments, the camera ray included. After segment
    `russian_roulette` a path survives with probability q (survival_probability)
    and is then divided by q, which ends weak paths early without bias.
    With nee = False, area lights are found only by BRDF sampling (the course's
    week-5 "random scattering"); point lights can only be reached by sampling
    them, so they are still sampled. With mis = False (and nee on), lights are
    found only by light sampling: emission that a BRDF-sampled ray meets after a
    non-specular bounce is not added (after the camera or a specular bounce it is,
    since no light sampling happened there).
    """

    name = "path"

    def compute_scattering(self, ray: Ray, scene: Scene) -> Color:
        """Radiance arriving along the camera ray, estimated along one random path
        (the class docstring): emission times emission_weight, sample_one_light at
        non-specular hits, the throughput times each scattering() weight, Russian
        roulette."""
        # BEGIN SOLUTION week08: path loop: emission (MIS), light sampling, throughput, roulette
        settings = self.settings
        max_depth, rr_start = settings.max_depth, settings.russian_roulette
        lights = scene.lights if settings.nee else scene.point_lights
        n_mis = len(lights) if settings.nee else 0  # lights that MIS weights account for
        mis = settings.mis
        result = Color(0.0, 0.0, 0.0)
        beta = Color(1.0, 1.0, 1.0)
        prev_point, prev_pdf, prev_specular = None, 0.0, True  # the camera "bounce"
        segment = 1
        while True:
            hit = scene.find_intersection(ray, FORWARD)
            if hit is None:
                result = result + beta * scene.background_radiance(ray.direction)
                break
            material = hit.material
            if material.is_emitter:
                emitted = material.emitting(hit)
                if not emitted.is_black():
                    w = emission_weight(scene, hit, prev_point, prev_pdf, prev_specular, n_mis, mis)
                    result = result + beta * emitted * w
            if segment >= max_depth:
                break
            if lights and not material.is_specular:
                result = result + beta * sample_one_light(scene, ray, hit, lights, mis)
            scatter = material.scattering(ray, hit)
            if scatter is None:
                break
            beta = beta * scatter.attenuation
            if not beta.max_component() > 0.0:
                break
            prev_point, prev_pdf, prev_specular = hit.point, scatter.pdf, scatter.is_specular
            ray = scatter.scattered_ray
            if rr_start and segment >= rr_start:
                survive = self.survival_probability(beta)
                if random_double() >= survive:
                    break
                beta = beta / survive
            segment += 1
        return result
        # END SOLUTION

    def survival_probability(self, beta: Color) -> float:
        """Russian roulette's q for a path of throughput beta: min(0.95, max(beta))
        (roulette = "throughput": weak paths end sooner), or the lecture's fixed p_RR
        (roulette = "fixed": roulette_probability, whatever the path carries)."""
        if self.settings.roulette == "fixed":
            return self.settings.roulette_probability
        return min(0.95, beta.max_component())
