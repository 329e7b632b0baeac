# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 05 hidden checks: only the autograder holds them (assignments/week05/hidden/
never ships to students). Their inputs come from grading_seed, new for every
submission, so code that is right only for the graders' fixed inputs fails them.

- A shadow ray stops at the light: an object beyond the light (a ceiling above a
  point light, a wall behind a sphere light) casts no shadow.
- No shadow acne: a point on a lit surface, with nothing in the way, is lit (the
  shadow ray must start off the surface it leaves).

The student's direct integrator and sample_one_light run in the student's process
(the probes radiance and sample_one_light, of the scenes built by ../probes.py); the
expected values are computed here.

False failures: both compare with values computed here for scenes built so that
nothing lies between the points and the light, with tolerances far above rounding;
spawn_ray's offset (rtpy/ray.py) exceeds the rounding of the hit points by design.
A correct solution never fails them (false-failure rate 0).
"""

import math

import numpy as np

from rtpy.grading import points
from rtpy.grading.autograder_seed import grading_rng, grading_seed

ALBEDO = np.array([0.7, 0.5, 0.3])
DIRECT = {"integrator": "direct"}
UP = np.array([0.0, 1.0, 0.0])
SPAWN_HINT = (
    "The shadow ray must start just off the surface: spawn_ray(hit.point, hit.normal, "
    "direction) (rtpy/ray.py) moves its origin by a small offset along the normal, so it "
    "cannot hit the surface it leaves (shadow acne)."
)


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def lambert_point_light(point, normal, light, intensity) -> np.ndarray:
    """albedo / pi * I cos(theta) / d^2 at point, for a light in front of the surface."""
    to_light = light - point
    d2 = to_light @ to_light
    cos = normal @ to_light / math.sqrt(d2)
    return ALBEDO / math.pi * intensity * cos / d2


def answered(got: list, asked: list, what: str) -> list:
    """got, after checking that it has an answer for each of `asked`."""
    assert len(got) == len(asked), f"{what}: {len(got)} answers for {len(asked)} questions"
    return got


def ray_from_above(point, normal, rng) -> list:
    """A camera ray [origin, direction] looking at `point` from just in front of it."""
    tilt = unit(normal + 0.5 * np.cross(normal, unit(rng.normal(size=3))))
    eye = point + 0.05 * tilt
    return [eye, unit(point - eye)]


@points(3)
def test_objects_beyond_the_light_cast_no_shadow(probe):
    """shadow rays stop at the light: a ceiling above the light casts no shadow"""
    rng = grading_rng(501)
    for _ in range(4):
        light = np.array([rng.uniform(-2, 2), rng.uniform(1, 3), rng.uniform(-2, 2)])
        top = light[1] + rng.uniform(0.2, 2.0)
        intensity = rng.uniform(1, 5, 3)
        points_, rays = [], []
        for _ in range(8):
            point = np.array([light[0] + rng.uniform(-2, 2), 0.0, light[2] + rng.uniform(-2, 2)])
            points_.append(point)
            rays.append(ray_from_above(point, UP, rng))
        params = {"albedo": ALBEDO, "light": light, "intensity": intensity, "top": top}
        got = probe.radiance(scene="floor_and_ceiling", params=params, rays=rays, settings=DIRECT)
        answered(got, rays, "DirectIntegrator.compute_scattering")
        for point, value in zip(points_, got, strict=True):
            want = lambert_point_light(point, UP, light, intensity)
            assert np.allclose(value, want, rtol=1e-6, atol=1e-12), (
                f"direct integrator at floor point {point.round(3)} under a point light at "
                f"{light.round(3)} and a ceiling at height {top:.3f} above it: radiance {value.round(6)}, "
                f"expected albedo / pi * I cos / d^2 = {want.round(6)}. Nothing lies between the point "
                "and the light: the shadow ray must stop at the light (sample_one_light in "
                "rtpy/integrators/direct_lighting.py: Interval(0, distance to the light), not to "
                "infinity), so the ceiling beyond it casts no shadow"
            )
    cases, lamps = [], []
    for _ in range(4):
        center = np.array([rng.uniform(-2, 2), rng.uniform(1.5, 3), rng.uniform(-2, 2)])
        radius = float(rng.uniform(0.1, 0.4))
        floor_points = [
            center * [1, 0, 1] + [rng.uniform(-1.5, 1.5), 0.0, rng.uniform(-1.5, 1.5)]
            for _ in range(8)
        ]
        cases.append(
            {"params": {"albedo": ALBEDO, "center": center, "radius": radius},
             "points": floor_points}
        )  # fmt: skip
        lamps.append(center)
    got = probe.sample_one_light(scene="lamp_under_wall", cases=cases, seed=grading_seed(502))
    for case, center, values in zip(
        cases, lamps, answered(got, cases, "sample_one_light"), strict=True
    ):
        answered(values, case["points"], "sample_one_light")
        for point, value in zip(case["points"], values, strict=True):
            assert value.min() > 0.0, (
                f"sample_one_light (rtpy/integrators/direct_lighting.py) at floor point "
                f"{point.round(3)} under a sphere light at {center.round(3)}, with a sphere "
                f"above the light: {value.round(6)}, but nothing lies between the point and the "
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
def test_lit_points_have_no_shadow_acne(probe):
    """no shadow acne: points on a lit sphere and plane are not shadowed by themselves"""
    rng = grading_rng(503)
    asked = []  # (scene, params, [(point, normal)], light, intensity, rays)
    for _ in range(5):
        center, radius, light, cases = sphere_points(rng, 20)
        intensity = rng.uniform(1, 5, 3) * radius**2
        rays = [ray_from_above(point, normal, rng) for point, normal in cases]
        params = {"albedo": ALBEDO, "center": center, "radius": radius, "light": light,
                  "intensity": intensity}  # fmt: skip
        asked.append(("lit_sphere", params, cases, light, intensity, rays))
    for _ in range(3):
        height = float(rng.uniform(-30, 30))
        q = np.array([rng.uniform(-60, -40), height, rng.uniform(-60, -40)])
        light = np.array([rng.uniform(-5, 5), height + rng.uniform(0.5, 4), rng.uniform(-5, 5)])
        intensity = rng.uniform(1, 5, 3)
        cases, rays = [], []
        for _ in range(20):
            point = np.array([rng.uniform(-8, 8), height, rng.uniform(-8, 8)])
            cases.append((point, UP))
            rays.append(ray_from_above(point, UP, rng))
        params = {"albedo": ALBEDO, "corner": q, "light": light, "intensity": intensity}
        asked.append(("lit_floor", params, cases, light, intensity, rays))
    dark = []
    for scene, params, cases, light, intensity, rays in asked:
        got = probe.radiance(scene=scene, params=params, rays=rays, settings=DIRECT)
        answered(got, rays, "DirectIntegrator.compute_scattering")
        for (point, normal), value in zip(cases, got, strict=True):
            want = lambert_point_light(point, normal, light, intensity)
            if not np.allclose(value, want, rtol=1e-4, atol=0):
                dark.append((point, value, want))
    if dark:
        point, got, want = dark[0]
        raise AssertionError(
            f"direct integrator: {len(dark)} of 160 points with nothing between them and a point "
            f"light are darker than albedo / pi * I cos / d^2 (first at {point.round(3)}: "
            f"{got.round(6)} instead of {want.round(6)}). {SPAWN_HINT}"
        )
