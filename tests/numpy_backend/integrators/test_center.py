"""The "center" integrator: the scalar flat colour, ray by ray."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy.render_settings import RenderSettings

from .integrator_checks import batched_radiance, camera_rays, scalar_radiance

BUNDLED = ["cornell", "week07_textures", "rtiow_cover", "week05_point_light"]


@pytest.mark.parametrize("name", BUNDLED)
def test_center_is_the_scalar_flat_colour_ray_by_ray(name):
    scene = rtpy.load_scene(name)
    o, d = camera_rays(scene.camera, 32, stride=3)
    settings = RenderSettings(integrator="center")
    got = batched_radiance(scene, settings, o, d)
    ref = scalar_radiance(scene, settings, o, d)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12)
