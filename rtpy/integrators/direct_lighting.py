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
from ..interval import Interval
from ..light import Light
from ..ray import Ray, offset_scale, spawn_ray
from ..sampling import power_heuristic, random_double
from ..scene import Scene
from ..vec3 import BLACK, Color, dot
from .integrator import FORWARD


def sample_one_light(
    scene: Scene, ray_in: Ray, hit: HitInfo, lights: list[Light], mis: bool = True
) -> Color:
    """Light-sampling estimate of the radiance reflected toward -ray_in.direction
    by light arriving directly from `lights`: one light picked uniformly, one
    direction toward it, weight f_r * L * cos(theta_i) / pdf (times the MIS weight
    for area lights; with mis = False the weight is 1: light sampling alone)."""
    # BEGIN SOLUTION week05: one light, one shadow ray, f_r * L * cos / pdf
    n_lights = len(lights)
    light = lights[min(int(random_double() * n_lights), n_lights - 1)]
    sample = light.sample(hit.point)
    if sample is None or sample.radiance.is_black():
        return BLACK
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
    # The light itself is not tested: its shapes (spheres sampled on the cap facing
    # the point, flat quads and triangles) cannot hide the sampled point from it,
    # while rounding near the sampled point could make it seem to, most where the
    # light is seen at a slant. Other objects count up to just short of the light.
    t_max = sample.distance - offset_scale(sample.point) - offset_scale(hit.point)
    light_shape = getattr(light, "shape", None)
    if scene.find_occlusion(shadow_ray, Interval(0.0, t_max), ignore=light_shape):
        return BLACK
    pdf = sample.pdf / n_lights  # choosing this light, then this direction
    if sample.is_delta or not mis:
        return f * sample.radiance * (cos_i / pdf)
    weight = power_heuristic(pdf, hit.material.pdf(ray_in, shadow_ray, hit))
    return f * sample.radiance * (cos_i * weight / pdf)
    # END SOLUTION


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
    # BEGIN SOLUTION week05: light sampling plus the BRDF-sampled bounce, light counted once
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
    # END SOLUTION
