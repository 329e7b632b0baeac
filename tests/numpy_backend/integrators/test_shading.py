"""The "shading" integrator: the scalar estimator ray by ray where it is deterministic
(point lights), the same mean where it samples area lights."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.render_settings import RenderSettings
from rtpy.testing.analytic_scenes import plane_sphere_light
from rtpy.testing.statistics import bonferroni_z

from .integrator_checks import batched_radiance, camera_rays, point_light_scene, scalar_radiance


@pytest.mark.parametrize("shadows", [False, True])
def test_point_lights_match_scalar_ray_by_ray(shadows):
    """Every point light is sampled exactly (no light choice): the batched radiance
    equals the scalar one ray by ray, with both lights at once; shadows darken some
    rays and no ray gets brighter."""
    scene = point_light_scene()
    o, d = camera_rays(scene.camera, 40, stride=2)
    settings = RenderSettings(integrator="shading", shadows=shadows)
    got = batched_radiance(scene, settings, o, d)
    np.testing.assert_allclose(got, scalar_radiance(scene, settings, o, d), rtol=1e-9, atol=1e-12)
    if shadows:
        free = batched_radiance(scene, RenderSettings(integrator="shading"), o, d)
        assert (got <= free).all() and (got < free).any()


def test_area_light_mean_matches_scalar_and_the_closed_form():
    """A plane under a sphere light, per camera ray: the batched and the scalar means
    agree and both match albedo Le (r / d)^2 cos(theta) (the numpy backend's estimate
    of the exact image), z-tests at 1e-4 with Bonferroni."""
    analytic = plane_sphere_light()
    o, d = camera_rays(analytic.camera, 12, stride=23)
    expected = analytic.ray_radiance(o, d)
    settings = RenderSettings(integrator="shading", shadows=True)
    n_np, n_sc = 4000, 300
    limit = bonferroni_z(1e-4, 2 * len(o))
    for k in range(len(o)):
        ray_o, ray_d = np.tile(o[k], (n_np, 1)), np.tile(d[k], (n_np, 1))
        a = batched_radiance(analytic.scene, settings, ray_o, ray_d, seed=k)[:, 0]
        b = scalar_radiance(analytic.scene, settings, ray_o[:n_sc], ray_d[:n_sc])[:, 0]
        se_a, se_b = a.std(ddof=1) / math.sqrt(n_np), b.std(ddof=1) / math.sqrt(n_sc)
        assert abs(a.mean() - b.mean()) < limit * math.hypot(se_a, se_b), k
        assert abs(a.mean() - expected[k, 0]) < limit * se_a, k
