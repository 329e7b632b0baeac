"""The "direct" integrator: the scalar estimator, and "path" with two segments."""

from __future__ import annotations

import numpy as np

from rtpy.render_settings import RenderSettings

from .integrator_checks import batched_radiance, camera_rays, check_ray_by_ray, point_light_scene


def test_deterministic_case_matches_scalar_ray_by_ray():
    check_ray_by_ray("direct")


def test_direct_is_path_with_two_segments():
    scene = point_light_scene()
    o, d = camera_rays(scene.camera, 24)
    direct = batched_radiance(scene, RenderSettings(integrator="direct"), o, d)
    path = batched_radiance(scene, RenderSettings(integrator="path", max_depth=2), o, d)
    np.testing.assert_allclose(direct, path, rtol=1e-12)
