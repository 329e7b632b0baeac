"""Light sampling and MIS weights: a sphere light's closed-form irradiance, and the
weights without MIS."""

from __future__ import annotations

import numpy as np

from rtpy import Color, DiffuseLight, Lambertian, PointLight, Scene, Sphere, Vec3
from rtpy.numpy_backend.integrators.direct_lighting import (
    Bounce,
    emission_weight,
    sample_one_light,
)
from rtpy.numpy_backend.scene import BatchScene
from rtpy.render_settings import RenderSettings
from rtpy.testing.analytic_scenes import plane_sphere_light

from .integrator_checks import batched_radiance, camera_rays, z_score


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
    batch = BatchScene(scene)
    obj, t = batch.find_intersection(o[:1], d[:1])
    hit = batch.hit_batch(obj, o[:1], d[:1], t)
    v = center - hit.point[0]
    dist = np.linalg.norm(v)
    expected = albedo * le * (r / dist) ** 2 * (v @ hit.normal[0]) / dist
    L = batched_radiance(scene, RenderSettings(integrator="direct"), o, d, seed=4)
    assert z_score(L, expected).max() < 4.5
    assert abs(L.mean() - expected) < 2e-3 * expected


def test_without_mis_light_samples_weigh_one_and_brdf_found_emission_zero():
    """The numpy kernels with mis = false, against the MIS ones on the same random
    numbers: light samples lose their power-heuristic weight (so are larger, and
    equal where a point light is sampled), and emission found by BRDF sampling after
    a non-specular bounce gets weight 0 (1 after a specular one, as in the scalar
    emission_weight)."""
    scene = plane_sphere_light().scene
    scene.point_lights = [PointLight(Vec3(0, 2, -1), Color(1, 1, 1))]
    scene.update_lights()
    batch = BatchScene(scene)
    o, d = camera_rays(plane_sphere_light().camera, 16)
    obj, t = batch.find_intersection(o, d)
    hits = batch.hit_batch(obj, o, d, t)
    ids = batch.material_id[obj]
    with_mis = sample_one_light(batch, hits, ids, np.random.default_rng(3), True, True)
    without = sample_one_light(batch, hits, ids, np.random.default_rng(3), True, False)
    assert np.all(without >= with_mis) and np.any(without > with_mis * 1.01)
    choice = batch.lights.sample(hits.point, np.random.default_rng(3), True)
    point = choice.is_delta & choice.valid
    assert point.any()
    np.testing.assert_allclose(without[point], with_mis[point], rtol=1e-12)
    specular = np.arange(len(obj)) % 2 == 0
    prev = Bounce(hits.point, np.ones(len(obj)), specular)
    w = emission_weight(batch, obj, hits, prev, 2, mis=False)
    np.testing.assert_array_equal(w, specular.astype(float))
