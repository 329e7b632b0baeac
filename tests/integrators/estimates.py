"""A small box scene and per-ray Monte Carlo estimates, for the integrator tests that
compare two estimators of the same radiance.

Statistical checks use fixed seeds and z-tests against the noise measured from the
samples themselves, at a family-wise false-alarm rate of ALPHA (Bonferroni-corrected
over the rays compared at once).
"""

from __future__ import annotations

import contextlib
import math
import statistics

import rtpy
from rtpy import (
    Camera,
    Color,
    DiffuseLight,
    Lambertian,
    Metal,
    PointLight,
    Quad,
    Scene,
    Sphere,
    Vec3,
)
from rtpy.sampling import make_generator, use_generator
from rtpy.testing.statistics import bonferroni_z

from ..cores import on_every_core

ALPHA = 1e-4


def z_limit(n_tests: int) -> float:
    """Two-sided z threshold of each of n_tests z-tests at family-wise level ALPHA."""
    return bonferroni_z(ALPHA, n_tests)


def box_scene() -> tuple[Scene, list]:
    """A box with a red wall, a rough metal and a white ball, lit by a ceiling light
    and a point light; and camera rays that see a surface other than the light."""
    white = Lambertian(Color(0.73, 0.73, 0.73))
    red = Lambertian(Color(0.65, 0.05, 0.05))
    objects = [
        Quad(Vec3(-1, -1, -1), Vec3(2, 0, 0), Vec3(0, 0, -2), white),  # floor
        Quad(Vec3(-1, -1, -3), Vec3(2, 0, 0), Vec3(0, 2, 0), white),  # back wall
        Quad(Vec3(-1, -1, -1), Vec3(0, 0, -2), Vec3(0, 2, 0), red),  # left wall
        Sphere(Vec3(0.3, -0.6, -2.0), 0.4, Metal(Color(0.8, 0.8, 0.8), 0.3)),
        Sphere(Vec3(-0.4, -0.7, -1.6), 0.3, white),
        # a ceiling light facing down (u x v = -y)
        Quad(
            Vec3(-0.4, 0.99, -1.6), Vec3(0, 0, -0.8), Vec3(0.8, 0, 0), DiffuseLight(Color(6, 6, 6))
        ),
    ]
    scene = Scene(objects, [PointLight(Vec3(0.6, 0.5, -1.2), Color(0.5, 0.5, 0.5))])
    camera = Camera(Vec3(0, 0, 1.5), Vec3(0, -0.2, -2), vfov=60, aspect_ratio=1.0, width=40)
    # Camera rays that see a surface other than the light, spread over the image.
    rays = []
    for i, j in [(8, 14), (12, 20), (16, 26), (20, 18), (24, 24), (26, 28), (10, 28), (22, 14)]:
        ray = camera.get_center_ray(i, j)
        hit = scene.find_intersection(ray, rtpy.Interval(0.0, math.inf))
        if hit is not None and not hit.material.is_emitter and not hit.material.is_specular:
            rays.append(ray)
    assert len(rays) >= 5
    return scene, rays


def sample_mean(integrator, ray, scene, n, seed) -> tuple[float, float]:
    """(mean, standard error) of n estimates of the ray's radiance (green channel)."""
    values = []
    with use_generator(make_generator(seed)):
        for _ in range(n):
            values.append(integrator.compute_scattering(ray, scene).e1)
    return statistics.fmean(values), statistics.stdev(values) / math.sqrt(n)


def per_ray_z(scene, rays, a, b, n_a, n_b, seed_a, seed_b, while_b=contextlib.nullcontext):
    """For each ray: (z of mean_a - mean_b, mean_a, se_a, mean_b, se_b), the b
    estimates made inside the context while_b() (a module-level one: the estimates
    run on every core)."""
    jobs = [(a, ray, scene, n_a, seed_a + k, contextlib.nullcontext) for k, ray in enumerate(rays)]
    jobs += [(b, ray, scene, n_b, seed_b + k, while_b) for k, ray in enumerate(rays)]
    means = on_every_core(_sample_mean_inside, jobs)
    return [
        ((m1 - m2) / math.hypot(s1, s2), m1, s1, m2, s2)
        for (m1, s1), (m2, s2) in zip(means[: len(rays)], means[len(rays) :], strict=True)
    ]


def _sample_mean_inside(job) -> tuple[float, float]:
    integrator, ray, scene, n, seed, context = job
    with context():
        return sample_mean(integrator, ray, scene, n, seed)
