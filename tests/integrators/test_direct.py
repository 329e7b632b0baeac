"""The "direct" integrator: emission plus one bounce of light."""

from __future__ import annotations

import numpy as np

import rtpy
from rtpy import Camera, Vec3

from .estimates import box_scene


def test_direct_equals_path_with_max_depth_2():
    """ "direct" is exactly "path" with max_depth 2: same seed, same numbers."""
    scene, _ = box_scene()
    camera = Camera(Vec3(0, 0, 1.5), Vec3(0, -0.2, -2), vfov=60, aspect_ratio=1.0, width=16)
    direct = rtpy.render(scene, camera=camera, integrator="direct", spp=4, seed=5)
    path = rtpy.render(scene, camera=camera, integrator="path", max_depth=2, spp=4, seed=5)
    assert direct.linear.max() > 0
    np.testing.assert_allclose(direct.linear, path.linear, rtol=1e-12, atol=1e-15)
