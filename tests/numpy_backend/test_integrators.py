"""Batched integrators: exactly the scalar estimators where they are deterministic
(ray by ray), and unbiased where they are not (furnace tests)."""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np
import pytest

import rtpy
from rtpy import (
    Color,
    Dielectric,
    DiffuseLight,
    Lambertian,
    Mirror,
    PointLight,
    Scene,
    Sphere,
    Vec3,
)
from rtpy.integrators import make_integrator as make_scalar
from rtpy.numpy_backend.camera import CameraRays
from rtpy.numpy_backend.integrators import Tracer, make_integrator, power_heuristic
from rtpy.ray import Ray
from rtpy.render_settings import RenderSettings
from rtpy.sampling import make_generator, use_generator
from rtpy.sampling import power_heuristic as scalar_power_heuristic
from rtpy.testing.analytic_scenes import (
    PLANE_ALBEDO,
    SPHERE_LIGHT_CENTER,
    SPHERE_LIGHT_RADIANCE,
    SPHERE_LIGHT_RADIUS,
    GlowingLambertian,
    plane_sphere_light,
)


def camera_rays(camera, width=24, stride=1):
    cam = camera.with_width(width)
    j, i = np.divmod(np.arange(cam.width * cam.height)[::stride], cam.width)
    return CameraRays(cam).center_rays(i, j)


def scalar_radiance(scene, settings, o, d):
    integrator = make_scalar(settings)
    out = np.empty((len(o), 3))
    with use_generator(make_generator(1)):
        for k in range(len(o)):
            c = integrator.compute_scattering(Ray(Vec3(*o[k]), Vec3(*d[k])), scene)
            out[k] = (c.e0, c.e1, c.e2)
    return out


def batched_radiance(scene, settings, o, d, seed=0):
    return make_integrator(settings).compute_scattering(
        Tracer(scene), o, d, np.random.default_rng(seed)
    )


def test_power_heuristic_matches_scalar():
    rng = np.random.default_rng(0)
    a, b = rng.exponential(size=1000), rng.exponential(size=1000)
    a[:10] = 0.0
    b[:5] = 0.0
    ref = [scalar_power_heuristic(x, y) for x, y in zip(a, b, strict=True)]
    np.testing.assert_array_equal(power_heuristic(a, b), ref)


BUNDLED = ["cornell", "week07_textures", "rtiow_cover", "week05_point_light"]


@pytest.mark.parametrize("name", BUNDLED)
def test_center_is_the_scalar_flat_colour_ray_by_ray(name):
    scene = rtpy.load_scene(name)
    o, d = camera_rays(scene.camera, 32, stride=3)
    settings = RenderSettings(integrator="center")
    got = batched_radiance(scene, settings, o, d)
    ref = scalar_radiance(scene, settings, o, d)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12)


def point_light_scene() -> Scene:
    """Lambertian, mirror and glass under two point lights and a black sky: direct
    and Whitted are deterministic here (BRDF-sampled rays only see black)."""
    return Scene(
        [
            Sphere(Vec3(0, -100.5, -1), 100, Lambertian(Color(0.7, 0.6, 0.5))),
            Sphere(Vec3(-1, 0, -1), 0.5, Lambertian(Color(0.2, 0.3, 0.8))),
            Sphere(Vec3(0, 0, -1.2), 0.5, Mirror(Color(0.9, 0.9, 0.8))),
            Sphere(Vec3(1, 0, -1), 0.5, Dielectric(1.5)),
        ],
        point_lights=[
            PointLight(Vec3(1, 3, 1), Color(5, 5, 5)),
            PointLight(Vec3(-2, 2, 0), Color(2, 1, 1)),
        ],
        camera=rtpy.Camera(Vec3(0, 0.5, 1.5), Vec3(0, 0, -1), vfov=70),
    )


@pytest.mark.parametrize("integrator", ["direct", "whitted"])
def test_deterministic_cases_match_scalar_ray_by_ray(integrator):
    scene = point_light_scene()
    o, d = camera_rays(scene.camera, 40, stride=2)
    settings = RenderSettings(integrator=integrator, max_depth=6)
    # Light choice is random among the two lights: compare expectations by making
    # each light the only one in turn.
    for light in list(scene.point_lights):
        scene.point_lights = [light]
        scene.update_lights()
        got = batched_radiance(scene, settings, o, d)
        ref = scalar_radiance(scene, settings, o, d)
        np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-12)


def test_path_with_one_segment_sees_emitters_only():
    scene = rtpy.load_scene("cornell")
    o, d = camera_rays(scene.camera, 32)
    settings = RenderSettings(integrator="path", max_depth=1)
    got = batched_radiance(scene, settings, o, d)
    ref = scalar_radiance(scene, settings, o, d)
    np.testing.assert_array_equal(got, ref)
    assert got.max() == 15.0


def test_direct_is_path_with_two_segments():
    scene = point_light_scene()
    o, d = camera_rays(scene.camera, 24)
    direct = batched_radiance(scene, RenderSettings(integrator="direct"), o, d)
    path = batched_radiance(scene, RenderSettings(integrator="path", max_depth=2), o, d)
    np.testing.assert_allclose(direct, path, rtol=1e-12)


def z_score(samples: np.ndarray, expected) -> np.ndarray:
    mean = samples.mean(axis=0)
    se = samples.std(axis=0, ddof=1) / math.sqrt(len(samples))
    return np.abs(mean - expected) / np.maximum(se, 1e-12)


@pytest.mark.parametrize("integrator", ["direct", "whitted", "path"])
def test_white_furnace_shows_the_albedo(integrator):
    """A convex Lambertian sphere in a uniform white environment reflects exactly
    its albedo (every estimator; path with Russian roulette from segment 2)."""
    albedo = 0.6
    scene = Scene([Sphere(Vec3(0, 0, -3), 1.0, Lambertian(Color(albedo, albedo, albedo)))])
    scene.background = Color(1.0, 1.0, 1.0)
    n = 40000
    o = np.zeros((n, 3))
    d = np.tile([0.0, 0.0, -1.0], (n, 1))
    settings = RenderSettings(integrator=integrator, russian_roulette=2)
    L = batched_radiance(scene, settings, o, d, seed=3)
    if integrator == "whitted":  # direct light of the environment, one bounce: exact
        np.testing.assert_allclose(L.mean(axis=0), albedo, rtol=0.02)
    else:
        assert z_score(L, albedo).max() < 4.5


@pytest.mark.parametrize("nee", [True, False])
def test_glowing_sphere_converges_to_le_over_one_minus_rho(nee):
    """Inside a sphere of albedo rho emitting Le, radiance is Le / (1 - rho)."""
    rho, le = 0.5, Color(0.5, 0.5, 0.5)
    scene = Scene([Sphere(Vec3(0, 0, 0), 2.0, GlowingLambertian(Color(rho, rho, rho), le))])
    n = 20000
    rng = np.random.default_rng(5)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    settings = RenderSettings(integrator="path", max_depth=60, nee=nee, russian_roulette=3)
    L = batched_radiance(scene, settings, np.zeros((n, 3)), d, seed=7)
    assert z_score(L, 0.5 / (1 - rho)).max() < 4.5


def test_area_light_nee_and_brdf_sampling_agree():
    """path with and without light sampling converge to the same pixel values."""
    scene = Scene(
        [
            Sphere(Vec3(0, -100.5, -1), 100, Lambertian(Color(0.6, 0.6, 0.6))),
            Sphere(Vec3(0, 1.2, -1), 0.4, DiffuseLight(Color(6, 6, 6))),
        ]
    )
    n = 60000
    o = np.tile([0.0, 0.2, 0.5], (n, 1))
    target = np.array([[0.3, -0.5, -1.2], [-0.4, -0.5, -0.6]])
    for p in target:
        d = np.tile(p - o[0], (n, 1))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        a = batched_radiance(scene, RenderSettings(integrator="path", nee=True), o, d, seed=1)
        b = batched_radiance(scene, RenderSettings(integrator="path", nee=False), o, d, seed=2)
        se = np.sqrt(a.var(0) / n + b.var(0) / n)
        assert np.all(np.abs(a.mean(0) - b.mean(0)) < 4.5 * se)


def test_sphere_light_nee_gives_the_analytic_irradiance():
    """A Lambertian point under a sphere light of radiance Le, radius r, at distance d
    along a direction at angle theta to the normal reflects albedo Le (r/d)^2 cos(theta)
    (the sphere lies wholly above the horizon). Light sampling alone nearly has no
    variance here, so this is a sharp test of the cone sampling, its pdf, the MIS
    weights and the shadow ray (which the light itself must not block)."""
    albedo, le, r = 0.6, 6.0, 0.4
    center = np.array([0.0, 1.2, -1.0])
    scene = Scene(
        [
            Sphere(Vec3(0, -100.5, -1), 100, Lambertian(Color(albedo, albedo, albedo))),
            Sphere(Vec3(*center), r, DiffuseLight(Color(le, le, le))),
        ]
    )
    n = 40000
    o = np.tile([0.0, 0.2, 0.5], (n, 1))
    d = np.tile(np.array([0.3, -0.5, -1.2]) - o[0], (n, 1))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    tracer = Tracer(scene)
    obj, t = tracer.geometry.closest_hit(o[:1], d[:1])
    hit = tracer.hits(obj, o[:1], d[:1], t)
    v = center - hit.point[0]
    dist = np.linalg.norm(v)
    expected = albedo * le * (r / dist) ** 2 * (v @ hit.normal[0]) / dist
    L = batched_radiance(scene, RenderSettings(integrator="direct"), o, d, seed=4)
    assert z_score(L, expected).max() < 4.5
    assert abs(L.mean() - expected) < 2e-3 * expected


def test_nee_only_matches_scalar_and_the_exact_irradiance():
    """mis = false (lights by light sampling alone), ray by ray: the numpy and the
    scalar estimators have the same mean, and both the closed form
    albedo Le (r/d)^2 cos(theta) of a plane under a sphere light (z-tests against
    the measured noise, Bonferroni over rays and comparisons)."""
    analytic = plane_sphere_light()
    scene = analytic.scene
    o, d = camera_rays(analytic.camera, 12, stride=17)
    # each centre ray's exact radiance (red channel)
    center = np.array([SPHERE_LIGHT_CENTER.e0, SPHERE_LIGHT_CENTER.e1, SPHERE_LIGHT_CENTER.e2])
    p = o - (o[:, 1] / d[:, 1])[:, None] * d  # on the plane y = 0
    v = center - p
    dist = np.linalg.norm(v, axis=1)
    le = SPHERE_LIGHT_RADIANCE.e0
    expected = PLANE_ALBEDO * le * (SPHERE_LIGHT_RADIUS / dist) ** 2 * (v[:, 1] / dist)
    settings = RenderSettings(integrator="path", mis=False, max_depth=4)
    n_np, n_sc = 4000, 400
    limit = NormalDist().inv_cdf(1 - 1e-4 / (2 * 3 * len(o)))
    integrator = make_scalar(settings)
    for k in range(len(o)):
        L = batched_radiance(scene, settings, np.tile(o[k], (n_np, 1)), np.tile(d[k], (n_np, 1)))
        with use_generator(make_generator(k)):
            ray = Ray(Vec3(*o[k]), Vec3(*d[k]))
            S = np.array([integrator.compute_scattering(ray, scene).e0 for _ in range(n_sc)])
        m_np, se_np = L[:, 0].mean(), L[:, 0].std(ddof=1) / math.sqrt(n_np)
        m_sc, se_sc = S.mean(), S.std(ddof=1) / math.sqrt(n_sc)
        want = expected[k]
        assert abs(m_np - m_sc) < limit * math.hypot(se_np, se_sc), (k, m_np, m_sc)
        assert abs(m_np - want) < limit * se_np, (k, m_np, want)
        assert abs(m_sc - want) < limit * se_sc, (k, m_sc, want)


def test_without_mis_light_samples_weigh_one_and_brdf_found_emission_zero():
    """The numpy kernels with mis = false, against the MIS ones on the same random
    numbers: light samples lose their power-heuristic weight (so are larger, and
    equal where a point light is sampled), and emission found by BRDF sampling after
    a non-specular bounce gets weight 0 (1 after a specular one, as in the scalar
    emission_weight)."""
    scene = plane_sphere_light().scene
    scene.point_lights = [PointLight(Vec3(0, 2, -1), Color(1, 1, 1))]
    scene.update_lights()
    tracer = Tracer(scene)
    o, d = camera_rays(plane_sphere_light().camera, 16)
    obj, t = tracer.geometry.closest_hit(o, d)
    hits = tracer.hits(obj, o, d, t)
    ids = tracer.geometry.material_id[obj]
    with_mis = tracer.sample_one_light(hits, ids, np.random.default_rng(3), True, True)
    without = tracer.sample_one_light(hits, ids, np.random.default_rng(3), True, False)
    assert np.all(without >= with_mis) and np.any(without > with_mis * 1.01)
    lights = tracer.lights
    rng = np.random.default_rng(3)
    _choice = lights.sample(hits.point, rng, True)
    point = _choice.delta & _choice.valid
    assert point.any()
    np.testing.assert_allclose(without[point], with_mis[point], rtol=1e-12)
    specular = np.arange(len(obj)) % 2 == 0
    w = tracer.emission_weight(obj, hits, hits.point, np.ones(len(obj)), specular, 2, mis=False)
    np.testing.assert_array_equal(w, specular.astype(float))
