"""Direct lighting: one light sample (next-event estimation) and the MIS weight of
emission that BRDF sampling finds, against answers known in closed form."""

from __future__ import annotations

import math

import pytest

import rtpy
from rtpy import Color, DiffuseLight, Lambertian, Quad, RenderSettings, Scene, Sphere, Vec3
from rtpy.integrators import make_integrator
from rtpy.integrators.direct_lighting import emission_weight, sample_one_light
from rtpy.sampling import make_generator, use_generator
from rtpy.testing.analytic_scenes import (
    PLANE_ALBEDO,
    POINT_LIGHT_INTENSITY,
    POINT_LIGHT_POSITION,
    plane_point_light,
)
from rtpy.vec3 import dot, unit_vector

from .estimates import sample_mean, z_limit


def test_point_light_on_plane_is_exact_per_pixel():
    """direct = albedo/pi * I * cos(theta) / d^2 at every pixel's center ray.
    The course code has no 1/d^2 and an unnormalised cosine: both would fail."""
    # The plane's quad has u x v pointing down; a Lambertian plane is two-sided,
    # which the test relies on only through hit.normal facing the camera.
    analytic = plane_point_light()
    scene, camera = analytic.scene, analytic.camera
    albedo, intensity = PLANE_ALBEDO, POINT_LIGHT_INTENSITY
    light_pos = POINT_LIGHT_POSITION
    assert scene.point_lights[0].intensity == intensity
    integrator = make_integrator(RenderSettings(integrator="direct"))
    checked = 0
    with use_generator(make_generator(7)):
        for j in range(camera.height):
            for i in range(camera.width):
                ray = camera.get_center_ray(i, j)
                got = integrator.compute_scattering(ray, scene)
                o, d = ray.origin, ray.direction
                if d.e1 >= 0:
                    assert got == Color(0, 0, 0)
                    continue
                t = -o.e1 / d.e1
                p = (o.e0 + t * d.e0, 0.0, o.e2 + t * d.e2)
                to_light = (light_pos.e0 - p[0], light_pos.e1, light_pos.e2 - p[2])
                d2 = sum(c * c for c in to_light)
                cos_theta = to_light[1] / math.sqrt(d2)
                for ch, inten in enumerate((intensity.e0, intensity.e1, intensity.e2)):
                    expected = albedo / math.pi * inten * cos_theta / d2
                    assert got[ch] == pytest.approx(expected, rel=1e-9)
                checked += 1
    assert checked > 100


def test_sphere_light_seen_at_a_slant_gives_the_analytic_radiance():
    """A Lambertian point lit by a sphere light (radiance Le, radius r, centre at
    distance d, at angle theta to the normal, wholly above the horizon) reflects
    albedo * Le * (r / d)^2 * cos(theta). The light's samples near its silhouette
    are seen at a slant; a shadow ray that the light itself may block (the margin
    before the light shorter than the rounding of the spawned origin) comes out
    about 6 % too dark here."""
    albedo, le, r = 0.6, 6.0, 0.4
    center = Vec3(0.0, 1.2, -1.0)
    ground = Sphere(Vec3(0, -100.5, -1), 100, Lambertian(Color(albedo, albedo, albedo)))
    scene = Scene([ground, Sphere(center, r, DiffuseLight(Color(le, le, le)))])
    origin = Vec3(0.0, 0.2, 0.5)
    ray = rtpy.Ray(origin, unit_vector(Vec3(0.3, -0.5, -1.2) - origin))
    hit = scene.find_intersection(ray, rtpy.Interval(1e-9, math.inf))
    assert hit is not None and hit.obj is ground
    to_light = center - hit.point
    d = to_light.length()
    expected = albedo * le * (r / d) ** 2 * dot(to_light, hit.normal) / d
    mean, se = sample_mean(
        make_integrator(RenderSettings(integrator="direct")), ray, scene, 6000, 7
    )
    assert abs(mean - expected) < z_limit(1) * se + 1e-9 * expected, (mean, se, expected)


def test_emission_weight_is_the_power_heuristic_against_light_sampling():
    """Emission met by a BRDF-sampled ray: weight 1 after the camera or a specular
    bounce or with no light sampled (nothing else counts it), 0 with light sampling
    alone (mis off: light sampling counts it), else the power heuristic of the
    BRDF's pdf against the light's pdf for that direction (divided by the number of
    lights, as one light is picked)."""
    lamp = Quad(Vec3(-1, 2, -2), Vec3(2, 0, 0), Vec3(0, 0, 1), DiffuseLight(Color(4, 4, 4)))
    scene = Scene([lamp])
    p = Vec3(0.0, 0.0, -1.5)
    hit = scene.find_intersection(rtpy.Ray(p, Vec3(0, 1, 0)), rtpy.Interval(0.0, math.inf))
    light_pdf = lamp.direction_pdf(p, hit)
    assert light_pdf == pytest.approx(2.0**2 / (1.0 * 2.0))  # d^2 / (cos * area)
    brdf_pdf = 0.3
    assert emission_weight(scene, hit, p, brdf_pdf, True, 2) == 1.0
    assert emission_weight(scene, hit, p, brdf_pdf, False, 0) == 1.0
    assert emission_weight(scene, hit, p, brdf_pdf, False, 2, mis=False) == 0.0
    expected = brdf_pdf**2 / (brdf_pdf**2 + (light_pdf / 2) ** 2)
    assert emission_weight(scene, hit, p, brdf_pdf, False, 2) == pytest.approx(expected, rel=1e-12)


def test_light_choice_of_one_picks_the_last_light():
    """A sampler can give the light choice 1.0 (its strata round up): then the last of
    the lights is sampled, with the weight of one choice in len(lights)."""

    class Ones:
        def random(self) -> float:
            return 1.0

    albedo = Color(0.5, 0.5, 0.5)
    lights = [
        rtpy.PointLight(Vec3(0.0, 1.0, 0.0), Color(1.0, 1.0, 1.0)),
        rtpy.PointLight(Vec3(0.0, 2.0, 0.0), Color(4.0, 8.0, 12.0)),
    ]
    scene = Scene(point_lights=lights)
    hit = rtpy.HitInfo(Vec3(0.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0), 1.0, True, Lambertian(albedo))
    ray_in = rtpy.Ray(Vec3(0.0, 1.0, 1.0), unit_vector(Vec3(0.0, -1.0, -1.0)))
    with use_generator(Ones()):
        got = sample_one_light(scene, ray_in, hit, scene.lights)
    # f_r * I / d^2 * cos / pdf times 2 choices: albedo / pi * I / 4 * 1 / 1 * 2
    expected = [a / math.pi * i / 4.0 * 2.0 for a, i in zip(albedo, (4.0, 8.0, 12.0), strict=True)]
    assert list(got) == pytest.approx(expected, rel=1e-12)
