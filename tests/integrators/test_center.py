"""The "center" integrator: the flat colour of the first hit through each pixel's center."""

from __future__ import annotations

import numpy as np

import rtpy
from rtpy import Camera, Color, DiffuseLight, Lambertian, Quad, Scene, Vec3


def test_center_shows_albedo_emission_and_background():
    light = Quad(Vec3(-1, -1, -3), Vec3(1, 0, 0), Vec3(0, 2, 0), DiffuseLight(Color(3, 2, 1)))
    wall = Quad(Vec3(0, -1, -3), Vec3(1, 0, 0), Vec3(0, 2, 0), Lambertian(Color(0.2, 0.4, 0.6)))
    scene = Scene([light, wall], background=Color(0.1, 0.1, 0.1))
    camera = Camera(Vec3(0, 0, 0), Vec3(0, 0, -1), vfov=90, aspect_ratio=2.0, width=40)
    image = rtpy.render(scene, camera=camera, integrator="center")
    middle = camera.height // 2
    np.testing.assert_array_equal(image.linear[middle, 18], [3, 2, 1])  # the light
    np.testing.assert_array_equal(image.linear[middle, 21], [0.2, 0.4, 0.6])  # the wall
    np.testing.assert_array_equal(image.linear[middle, 0], [0.1, 0.1, 0.1])  # background
    assert image.spp == 1
