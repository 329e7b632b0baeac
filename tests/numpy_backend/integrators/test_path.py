"""The "path" integrator: exactly the scalar one where it is deterministic, unbiased
(furnaces, closed forms, light sampling against BRDF sampling) where it is not."""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np
import pytest

import rtpy
from rtpy import Color, DiffuseLight, Lambertian, Scene, Sphere, Vec3
from rtpy.integrators import make_integrator as make_scalar
from rtpy.numpy_backend.integrators import path as path_module
from rtpy.ray import Ray
from rtpy.render_settings import RenderSettings
from rtpy.sampling import make_generator, use_generator
from rtpy.testing.analytic_scenes import (
    PLANE_ALBEDO,
    SPHERE_LIGHT_CENTER,
    SPHERE_LIGHT_RADIANCE,
    SPHERE_LIGHT_RADIUS,
    GlowingLambertian,
    plane_sphere_light,
)
from rtpy.testing.statistics import BlockTest, block_z_test

from .integrator_checks import batched_radiance, camera_rays, scalar_radiance, z_score


def test_path_with_one_segment_sees_emitters_only():
    scene = rtpy.load_scene("cornell")
    o, d = camera_rays(scene.camera, 32)
    settings = RenderSettings(integrator="path", max_depth=1)
    got = batched_radiance(scene, settings, o, d)
    ref = scalar_radiance(scene, settings, o, d)
    np.testing.assert_array_equal(got, ref)
    assert got.max() == 15.0


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


# The lecture's stop criteria on one scene: no roulette, fixed p_RR, throughput-based.
ROULETTES = {
    "none": {"russian_roulette": 0},
    "fixed": {"russian_roulette": 2, "roulette": "fixed", "roulette_probability": 0.6},
    "throughput": {"russian_roulette": 2},
}
ROULETTE_SEEDS = range(21, 27)


def roulette_renders(kind: str) -> np.ndarray:
    """(R, H, W, 3): cornell, 32 pixels wide, rendered with one seed each of
    ROULETTE_SEEDS and the stop criterion `kind`, in this process."""
    scene = rtpy.load_scene("cornell")
    return np.stack(
        [
            rtpy.render(
                scene,
                backend="numpy",
                workers=1,
                width=32,
                spp=8,
                max_depth=10,
                seed=seed,
                **ROULETTES[kind],
            ).linear
            for seed in ROULETTE_SEEDS
        ]
    )


def same_image(a: np.ndarray, b: np.ndarray) -> BlockTest:
    """block_z_test of two stacks of independent renders, each pixel's mean with the
    variance measured from its own stack (the estimators' variances differ)."""
    var_a, var_b = a.var(axis=0, ddof=1) / len(a), b.var(axis=0, ddof=1) / len(b)
    return block_z_test(a.mean(axis=0), var_a, b.mean(axis=0), var_b, alpha=1e-3)


@pytest.mark.slow
def test_fixed_roulette_converges_to_the_image_without_roulette_and_throughputs():
    """Fixed p_RR = 0.6 from segment 2 on, throughput roulette and no roulette at all
    (the same depth cap) estimate one image: the block means agree (z-test on blocks,
    Bonferroni over blocks and channels); fixed p_RR ends paths, so it is noisier."""
    fixed = roulette_renders("fixed")
    for other in ("none", "throughput"):
        test = same_image(fixed, roulette_renders(other))
        assert test.passed, f"fixed p_RR against {other}: " + test.worst(other)
    assert fixed.var(axis=0).mean() > roulette_renders("none").var(axis=0).mean()


def test_fixed_roulette_without_dividing_by_p_is_flagged(monkeypatch):
    """The planted mistake: survivors not divided by p_RR lose the energy of the paths
    roulette ended, and the z-test on blocks says so."""
    reference = roulette_renders("none")
    monkeypatch.setattr(path_module, "divide", lambda beta, survive: beta)
    test = same_image(roulette_renders("fixed"), reference)
    assert not test.passed
    assert (test.z > test.threshold).any(axis=1).sum() > 1  # many blocks, not one
