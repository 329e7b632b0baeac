"""The "shading" integrator (the lecture's second rung): local shading from every light
at the first hit, against the closed form albedo / pi * I * cos(theta) / d^2, with and
without shadow rays."""

from __future__ import annotations

import math
import statistics

import pytest

from rtpy import Color, DiffuseLight, Lambertian, Mirror, PointLight, Quad, Scene, Sphere, Vec3
from rtpy.integrators import make_integrator
from rtpy.ray import Ray
from rtpy.render_settings import RenderSettings
from rtpy.sampling import make_generator, use_generator
from rtpy.testing.analytic_scenes import (
    PLANE_ALBEDO,
    SPHERE_LIGHT_CENTER,
    SPHERE_LIGHT_RADIANCE,
    SPHERE_LIGHT_RADIUS,
    plane_sphere_light,
)
from rtpy.vec3 import dot, unit_vector

from .estimates import z_limit

ALBEDO = Color(0.6, 0.4, 0.2)
INTENSITY = Color(8.0, 6.0, 4.0)
CENTER = Vec3(0.0, 0.0, -3.0)
LIGHT = Vec3(2.0, 3.0, 0.0)


def one_sphere(*blockers) -> Scene:
    """A Lambertian unit sphere at CENTER under one point light at LIGHT."""
    objects = [Sphere(CENTER, 1.0, Lambertian(ALBEDO)), *blockers]
    return Scene(objects, [PointLight(LIGHT, INTENSITY)])


def radiance(scene: Scene, ray: Ray, **settings) -> Color:
    integrator = make_integrator(RenderSettings(integrator="shading", **settings))
    return integrator.compute_scattering(ray, scene)


def hit_point(target: Vec3) -> Vec3:
    """Where the ray from the origin toward `target` first meets the unit sphere at
    CENTER: the nearer root of |t u - CENTER|^2 = 1."""
    u = unit_vector(target)
    b = dot(u, CENTER)
    return u * (b - math.sqrt(b * b - dot(CENTER, CENTER) + 1.0))


def closed_form(target: Vec3) -> list[float]:
    """albedo / pi * I * cos(theta) / d^2 at hit_point(target)."""
    point = hit_point(target)
    to_light = LIGHT - point
    d2 = dot(to_light, to_light)
    cos = max(0.0, dot(point - CENTER, to_light / math.sqrt(d2)))
    return [a / math.pi * i * cos / d2 for a, i in zip(ALBEDO, INTENSITY, strict=True)]


TARGETS = [Vec3(0.0, 0.0, -2.0), Vec3(0.3, 0.4, -2.2), Vec3(-0.4, 0.1, -2.3), Vec3(0, -0.5, -2.5)]


@pytest.mark.parametrize("shadows", [False, True])
@pytest.mark.parametrize("target", TARGETS, ids=range(len(TARGETS)))
def test_one_sphere_one_point_light_matches_the_closed_form(target, shadows):
    """Camera rays from the origin toward points of the sphere see exactly
    albedo / pi * I * cos / d^2 (0 on the side facing away from the light)."""
    ray = Ray(Vec3(0, 0, 0), unit_vector(target))
    got = radiance(one_sphere(), ray, shadows=shadows)
    assert list(got) == pytest.approx(closed_form(target), rel=1e-6, abs=1e-12)


def test_shadows_switch_the_shadow_ray():
    """A ball between the light and the sphere: without shadows it changes nothing,
    with shadows the sphere's lit point is black."""
    target = Vec3(0.3, 0.4, -2.2)
    blocker = Sphere((hit_point(target) + LIGHT) * 0.5, 0.2, Lambertian(ALBEDO))
    ray = Ray(Vec3(0, 0, 0), unit_vector(target))
    expected = closed_form(target)
    assert min(expected) > 0.0
    assert list(radiance(one_sphere(blocker), ray)) == pytest.approx(expected, rel=1e-6)
    assert list(radiance(one_sphere(blocker), ray, shadows=True)) == [0.0, 0.0, 0.0]


def test_every_light_counts_once_and_emitters_and_background_show():
    """Two point lights add; a mirror shows only what it emits (nothing); an emitter
    seen directly shows its emission; a ray that escapes sees the background."""
    lamp = DiffuseLight(Color(3.0, 3.0, 3.0))
    scene = Scene(
        [
            Sphere(CENTER, 1.0, Lambertian(ALBEDO)),
            Sphere(Vec3(3.0, 0.0, -3.0), 1.0, Mirror(Color(1, 1, 1))),
            Quad(Vec3(-4, -1, -4), Vec3(0, 2, 0), Vec3(0, 0, 2), lamp),
        ],
        [PointLight(LIGHT, INTENSITY), PointLight(LIGHT, INTENSITY)],
        background=Color(0.1, 0.2, 0.3),
    )
    scene.area_lights, scene.lights = [], list(scene.point_lights)  # the point lights only
    target = Vec3(0.3, 0.4, -2.2)
    two = radiance(scene, Ray(Vec3(0, 0, 0), unit_vector(target)))
    assert list(two) == pytest.approx([2 * v for v in closed_form(target)], rel=1e-6)
    mirror = radiance(scene, Ray(Vec3(0, 0, 0), unit_vector(Vec3(3.0, 0.0, -2.0))))
    assert list(mirror) == [0.0, 0.0, 0.0]
    assert list(radiance(scene, Ray(Vec3(0, 0, 0), unit_vector(Vec3(-4, 0, -3))))) == [3, 3, 3]
    assert list(radiance(scene, Ray(Vec3(0, 0, 0), Vec3(0, 0, 1)))) == [0.1, 0.2, 0.3]


def test_an_area_light_is_sampled_once_per_ray_without_bias():
    """A plane under a sphere light: the mean of the shading estimate at each point is
    the closed form albedo Le (r / d)^2 cos(theta) (z-tests against the measured noise,
    Bonferroni over the rays and both settings of shadows)."""
    rays = [Vec3(0.3, -0.5, -1.2), Vec3(-0.4, -0.5, -0.6), Vec3(0.0, -0.3, -1.5)]
    origin, n = Vec3(0.0, 0.2, 0.5), 400
    scene = plane_sphere_light().scene
    c, r, le = SPHERE_LIGHT_CENTER, SPHERE_LIGHT_RADIUS, SPHERE_LIGHT_RADIANCE.e0
    limit = z_limit(2 * len(rays))
    for k, target in enumerate(rays):
        ray = Ray(origin, unit_vector(target - origin))
        p = origin + ray.direction * (-origin.e1 / ray.direction.e1)  # on the plane y = 0
        d = (c - p).length()
        expected = PLANE_ALBEDO * le * (r / d) ** 2 * ((c - p).e1 / d)
        for shadows in (False, True):
            with use_generator(make_generator(k)):
                samples = [radiance(scene, ray, shadows=shadows).e0 for _ in range(n)]
            mean = statistics.fmean(samples)
            se = statistics.stdev(samples) / math.sqrt(n)
            assert se > 0 and abs(mean - expected) < limit * se, (k, shadows, mean, expected)
