# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 05 hidden checks: only the autograder holds them (assignments/week05/hidden/
never ships to students). Their inputs come from grading_seed, new for every
submission, so code that is right only for the graders' fixed inputs fails them.

- A shadow ray stops at the light: an object beyond the light (a ceiling above a
  point light, a wall behind a sphere light) casts no shadow.
- No shadow acne: a point on a lit surface, with nothing in the way, is lit (the
  shadow ray must start off the surface it leaves).

False failures: both compare with values computed here for scenes built so that
nothing lies between the points and the light, with tolerances far above rounding;
spawn_ray's offset (rtpy/ray.py) exceeds the rounding of the hit points by design.
A correct solution never fails them (false-failure rate 0).
"""

import math

import numpy as np

from rtpy import Color, Lambertian, PointLight, Quad, Ray, Scene, Sphere, Vec3
from rtpy.grading import points
from rtpy.grading.autograder_seed import grading_rng, grading_seed
from rtpy.integrators import DirectIntegrator
from rtpy.integrators.direct_lighting import sample_one_light
from rtpy.materials import DiffuseLight
from rtpy.render_settings import RenderSettings
from rtpy.sampling import make_generator, use_generator

ALBEDO = Color(0.7, 0.5, 0.3)
SPAWN_HINT = (
    "The shadow ray must start just off the surface: spawn_ray(hit.point, hit.normal, "
    "direction) (rtpy/ray.py) moves its origin by a small offset along the normal, so it "
    "cannot hit the surface it leaves (shadow acne)."
)


def vec(a) -> Vec3:
    return Vec3(*(float(x) for x in a))


def arr(v) -> np.ndarray:
    return np.array(list(v), dtype=float)


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def lambert_point_light(point, normal, light, intensity) -> np.ndarray:
    """albedo / pi * I cos(theta) / d^2 at point, for a light in front of the surface."""
    to_light = light - point
    d2 = to_light @ to_light
    cos = normal @ to_light / math.sqrt(d2)
    return arr(ALBEDO) / math.pi * intensity * cos / d2


def seen_from_above(integrator, scene, point, normal, rng) -> np.ndarray:
    """The direct integrator's radiance at `point`, looked at from just in front of it."""
    tilt = unit(normal + 0.5 * np.cross(normal, unit(rng.normal(size=3))))
    eye = point + 0.05 * tilt
    return arr(integrator.compute_scattering(Ray(vec(eye), vec(unit(point - eye))), scene))


@points(3)
def test_objects_beyond_the_light_cast_no_shadow():
    """shadow rays stop at the light: a ceiling above the light casts no shadow"""
    rng = grading_rng(501)
    integrator = DirectIntegrator(RenderSettings(integrator="direct"))
    floor = Quad(Vec3(-50, 0, -50), Vec3(0, 0, 100), Vec3(100, 0, 0), Lambertian(ALBEDO))
    for _ in range(4):
        light = np.array([rng.uniform(-2, 2), rng.uniform(1, 3), rng.uniform(-2, 2)])
        top = light[1] + rng.uniform(0.2, 2.0)
        ceiling = Quad(Vec3(-50, top, -50), Vec3(100, 0, 0), Vec3(0, 0, 100), Lambertian())
        intensity = rng.uniform(1, 5, 3)
        scene = Scene([floor, ceiling], [PointLight(vec(light), vec(intensity))])
        for _ in range(8):
            point = np.array([light[0] + rng.uniform(-2, 2), 0.0, light[2] + rng.uniform(-2, 2)])
            got = seen_from_above(integrator, scene, point, np.array([0.0, 1.0, 0.0]), rng)
            want = lambert_point_light(point, np.array([0.0, 1.0, 0.0]), light, intensity)
            assert np.allclose(got, want, rtol=1e-6, atol=1e-12), (
                f"direct integrator at floor point {point.round(3)} under a point light at "
                f"{light.round(3)} and a ceiling at height {top:.3f} above it: radiance {got.round(6)}, "
                f"expected albedo / pi * I cos / d^2 = {want.round(6)}. Nothing lies between the point "
                "and the light: the shadow ray must stop at the light (sample_one_light in "
                "rtpy/integrators/direct_lighting.py: Interval(0, distance to the light), not to "
                "infinity), so the ceiling beyond it casts no shadow"
            )
    with use_generator(make_generator(grading_seed(502), 5)):
        for _ in range(4):
            center = np.array([rng.uniform(-2, 2), rng.uniform(1.5, 3), rng.uniform(-2, 2)])
            lamp = Sphere(vec(center), float(rng.uniform(0.1, 0.4)), DiffuseLight(Color(4, 4, 4)))
            wall = Sphere(vec(center + [0, 3.0, 0]), 2.0, Lambertian())  # above and beyond
            scene = Scene([floor, lamp, wall])
            for _ in range(8):
                point = center * [1, 0, 1] + [rng.uniform(-1.5, 1.5), 0.0, rng.uniform(-1.5, 1.5)]
                hit = floor.hit_info(Ray(vec(point + [0, 1e-3, 0]), Vec3(0, -1, 0)), 1e-3)
                incoming = Ray(vec(point + [0, 1, 0]), Vec3(0, -1, 0))
                got = arr(sample_one_light(scene, incoming, hit, scene.lights))
                assert got.min() > 0.0, (
                    f"sample_one_light (rtpy/integrators/direct_lighting.py) at floor point "
                    f"{point.round(3)} under a sphere light at {center.round(3)}, with a sphere "
                    f"above the light: {got.round(6)}, but nothing lies between the point and the "
                    "light. The shadow ray must stop at the light (Interval(0, a little less than "
                    "the distance to the sampled point), not search to infinity"
                )


def sphere_points(rng, n):
    """(sphere, light position, points on the lit side with their normals)."""
    center = rng.uniform(-40, 40, 3)
    radius = float(rng.uniform(0.5, 5))
    light = center + unit(rng.normal(size=3)) * radius * rng.uniform(2, 6)
    out = []
    while len(out) < n:
        normal = unit(rng.normal(size=3))
        point = center + radius * normal
        if normal @ unit(light - point) > 0.3:  # facing the light: nothing of a sphere hides it
            out.append((point, normal))
    return center, radius, light, out


@points(2)
def test_lit_points_have_no_shadow_acne():
    """no shadow acne: points on a lit sphere and plane are not shadowed by themselves"""
    rng = grading_rng(503)
    integrator = DirectIntegrator(RenderSettings(integrator="direct"))
    dark = []
    for _ in range(5):
        center, radius, light, cases = sphere_points(rng, 20)
        intensity = rng.uniform(1, 5, 3) * radius**2
        scene = Scene(
            [Sphere(vec(center), radius, Lambertian(ALBEDO))],
            [PointLight(vec(light), vec(intensity))],
        )
        for point, normal in cases:
            got = seen_from_above(integrator, scene, point, normal, rng)
            want = lambert_point_light(point, normal, light, intensity)
            if not np.allclose(got, want, rtol=1e-4, atol=0):
                dark.append((point, got, want))
    for _ in range(3):
        height = float(rng.uniform(-30, 30))
        q = np.array([rng.uniform(-60, -40), height, rng.uniform(-60, -40)])
        plane = Quad(vec(q), Vec3(0, 0, 100), Vec3(100, 0, 0), Lambertian(ALBEDO))
        light = np.array([rng.uniform(-5, 5), height + rng.uniform(0.5, 4), rng.uniform(-5, 5)])
        intensity = rng.uniform(1, 5, 3)
        scene = Scene([plane], [PointLight(vec(light), vec(intensity))])
        for _ in range(20):
            point = np.array([rng.uniform(-8, 8), height, rng.uniform(-8, 8)])
            got = seen_from_above(integrator, scene, point, np.array([0.0, 1.0, 0.0]), rng)
            want = lambert_point_light(point, np.array([0.0, 1.0, 0.0]), light, intensity)
            if not np.allclose(got, want, rtol=1e-4, atol=0):
                dark.append((point, got, want))
    if dark:
        point, got, want = dark[0]
        raise AssertionError(
            f"direct integrator: {len(dark)} of 160 points with nothing between them and a point "
            f"light are darker than albedo / pi * I cos / d^2 (first at {point.round(3)}: "
            f"{got.round(6)} instead of {want.round(6)}). {SPAWN_HINT}"
        )
