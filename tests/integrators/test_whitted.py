"""The "whitted" integrator: direct light at diffuse surfaces, the deterministic rays
of mirrors and glass."""

from __future__ import annotations

import numpy as np

import rtpy
from rtpy import Camera, Color, DiffuseLight, Lambertian, PointLight, Quad, Scene, Sphere, Vec3


def test_whitted_equals_direct_without_specular_materials():
    """Without mirrors or glass, Whitted ray tracing is direct lighting."""
    white = Lambertian(Color(0.7, 0.7, 0.7))
    scene = Scene(
        [
            Sphere(Vec3(0, -100.5, -1), 100, white),
            Sphere(Vec3(0, 0, -1), 0.5, white),
            Sphere(Vec3(0, 1.5, -1), 0.3, DiffuseLight(Color(5, 5, 5))),
        ],
        [PointLight(Vec3(1, 1, 0), Color(1, 1, 1))],
    )
    camera = Camera(Vec3(0, 0.5, 1), Vec3(0, 0, -1), vfov=60, width=16)
    direct = rtpy.render(scene, camera=camera, integrator="direct", spp=2, seed=3)
    whitted = rtpy.render(scene, camera=camera, integrator="whitted", spp=2, seed=3)
    np.testing.assert_array_equal(direct.linear, whitted.linear)


def test_whitted_follows_perfect_mirror():
    """A mirror facing the camera shows what is behind the camera, scaled by its albedo."""
    mirror = Quad(
        Vec3(-5, -5, -2), Vec3(10, 0, 0), Vec3(0, 10, 0), rtpy.Mirror(Color(0.5, 0.6, 0.7))
    )
    scene = Scene([mirror], background=Color(2.0, 2.0, 2.0))
    camera = Camera(Vec3(0, 0, 0), Vec3(0, 0, -1), vfov=30, width=8)
    image = rtpy.render(scene, camera=camera, integrator="whitted", spp=1)
    np.testing.assert_allclose(
        image.linear, np.broadcast_to([1.0, 1.2, 1.4], image.linear.shape), rtol=1e-12
    )
