"""Direct lighting: light that reaches a point straight from the light sources.

Two strategies estimate it, and multiple importance sampling (MIS, Veach 1997)
combines them so that each works where it is good:
- light sampling (next-event estimation): pick a light, pick a direction
  toward it, send a shadow ray; best for small and point lights;
- BRDF sampling: follow the direction scattering() picks and see whether it
  hits a light; best for glossy surfaces and big lights.
Each area-light contribution is weighted by the power heuristic, so the two
estimates add up to the right answer and light is never counted twice.
Point lights can only be reached by light sampling (weight 1).
"""

from __future__ import annotations

from ..hit_info import HitInfo
from ..hittable import Hittable
from ..interval import Interval
from ..light import Light, LightSample
from ..ray import Ray, offset_scale, spawn_ray
from ..sampling import power_heuristic, random_double
from ..scene import Scene
from ..vec3 import BLACK, Color, dot
from .integrator import FORWARD


def light_sample_estimate(
    scene: Scene, ray_in: Ray, hit: HitInfo, sample: LightSample, light_shape: Hittable | None
) -> Color:
    """The light-sampling estimate of one sample of one light: the radiance reflected
    toward -ray_in.direction by light from that light arriving along sample.direction,

        f_r(wi, wo) * L * cos(theta_i) / pdf

    with L = sample.radiance, pdf = sample.pdf (the density with which the light
    chose the direction; 1 for a point light) and cos(theta_i) = |hit.normal .
    sample.direction| (a unit vector; a light behind the surface reaches the point only
    through a material that transmits, such as rough glass: every other BRDF is black
    there). Black when f_r is black or something blocks the shadow ray: a ray that
    leaves the surface (spawn_ray) toward
    the light, tested by scene.find_occlusion over shadow_interval(hit, sample), not
    testing light_shape, the light's own shape (None for a point light)."""
    # BEGIN SOLUTION week05: shadow ray toward the light, f_r * L * cos / pdf
    normal, wi = hit.normal, sample.direction
    # A light behind the surface counts only through a BRDF that transmits (rough glass);
    # every other BRDF is 0 there.
    cos_i = abs(dot(normal, wi))
    if cos_i == 0.0:
        return BLACK
    shadow_ray = spawn_ray(hit.point, normal, wi)
    f = hit.material.BRDF(ray_in, shadow_ray, hit)
    if f.is_black():
        return BLACK
    if scene.find_occlusion(shadow_ray, shadow_interval(hit, sample), ignore=light_shape):
        return BLACK
    return f * sample.radiance * (cos_i / sample.pdf)
    # END SOLUTION


def shadow_interval(hit: HitInfo, sample: LightSample) -> Interval:
    """Where on a shadow ray from hit.point toward sample.point a blocker casts a
    shadow: from its start to just short of the light. The margins are the offsets
    of the spawned origin and of the sampled point (offset_scale): an object that
    touches the light there (a ceiling around a quad lamp) does not block it."""
    return Interval(0.0, sample.distance - offset_scale(sample.point) - offset_scale(hit.point))


def sample_one_light(
    scene: Scene, ray_in: Ray, hit: HitInfo, lights: list[Light], mis: bool = True
) -> Color:
    """Light-sampling estimate of the radiance reflected toward -ray_in.direction
    by light arriving directly from `lights`: one light picked uniformly, one
    direction toward it (light.sample), its light_sample_estimate divided by the
    probability 1 / len(lights) of picking that light, times the MIS weight for
    area lights (with mis = False the weight is 1: light sampling alone)."""
    n_lights = len(lights)
    k = int(random_double() * n_lights)
    light = lights[k] if k < n_lights else lights[-1]  # k = n: a sampler gave 1.0 (rounding)
    sample = light.sample(hit.point)
    if sample is None or sample.radiance.is_black():
        return BLACK
    # An area light's own shape is not tested by the shadow ray: a sphere sampled on
    # the cap facing the point, a flat quad or triangle cannot hide the sampled point
    # from it, while rounding near that point could make it seem to, most where the
    # light is seen at a slant.
    estimate = light_sample_estimate(scene, ray_in, hit, sample, light.shape)
    if sample.is_delta or not mis or estimate.is_black():
        return estimate * n_lights
    # The power heuristic against the density with which BRDF sampling picks the same
    # direction: emission_weight gives that strategy the complementary weight.
    pdf = sample.pdf / n_lights  # choosing this light, then this direction
    weight = power_heuristic(pdf, hit.material.pdf(ray_in, Ray(hit.point, sample.direction), hit))
    return estimate * (n_lights * weight)


def emission_weight(
    scene: Scene,
    hit: HitInfo,
    prev_point,
    prev_pdf: float,
    prev_specular: bool,
    n_lights: int,
    mis: bool = True,
) -> float:
    """MIS weight of emission found by BRDF sampling: the ray that reached `hit`
    left `prev_point` with solid-angle pdf `prev_pdf`. Emission seen directly by
    the camera or after a specular bounce could not have been light-sampled and
    keeps weight 1; so does emission when light sampling is off (n_lights = 0).
    With mis = False light sampling alone accounts for it: weight 0."""
    if prev_specular or n_lights == 0:
        return 1.0
    if not mis:
        return 0.0
    light_pdf = hit.obj.direction_pdf(prev_point, hit) / n_lights
    return power_heuristic(prev_pdf, light_pdf)


def direct_lighting(scene: Scene, ray_in: Ray, hit: HitInfo, mis: bool = True) -> Color:
    """Radiance reflected at `hit` toward -ray_in.direction after exactly one
    bounce: light sampling plus BRDF sampling, combined by MIS (mis = False: the
    lights by light sampling alone). A BRDF-sampled ray that escapes sees the
    background. At specular materials only the sampled ray is followed."""
    material = hit.material
    lights = scene.lights
    result = BLACK
    if lights and not material.is_specular:
        result = sample_one_light(scene, ray_in, hit, lights, mis)
    scatter = material.scattering(ray_in, hit)
    if scatter is None:
        return result
    next_hit = scene.find_intersection(scatter.scattered_ray, FORWARD)
    if next_hit is None:
        return result + scatter.attenuation * scene.background_radiance(
            scatter.scattered_ray.direction
        )
    if next_hit.material.is_emitter:
        emitted = next_hit.material.emitting(next_hit)
        if not emitted.is_black():
            w = emission_weight(
                scene, next_hit, hit.point, scatter.pdf, scatter.is_specular, len(lights), mis
            )
            result = result + scatter.attenuation * emitted * w
    return result
