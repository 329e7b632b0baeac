"""rtpy.engine.backend: the Backend protocol and the registry the loop finds backends in by
name (a student's plugin can register one)."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy.engine.backend import BACKEND_REGISTRY, Backend, make_backend, register_backend


def small_scene() -> tuple[rtpy.Scene, rtpy.Camera]:
    """One ball under the sky, 24 x 13 pixels (this file ships with week 4, before
    the renderer's tests do)."""
    ball = rtpy.Sphere(rtpy.Vec3(0, 0, -1), 0.5, rtpy.Lambertian())
    return rtpy.Scene([ball], sky=True), rtpy.Camera(width=24)


class Flat(Backend):
    """Every sample is 0.5: a backend of one's own."""

    name = "flat"
    paths_per_unit = 64

    def uses_center_ray(self) -> bool:
        return False

    def start(self):
        return lambda unit: np.full((unit.y1 - unit.y0, unit.x1 - unit.x0, 3), 0.5 * unit.spp)


def test_a_registered_backend_is_found_by_its_name(monkeypatch):
    monkeypatch.setitem(BACKEND_REGISTRY, "flat", None)  # taken out again after the test
    register_backend("flat")(Flat)
    scene, camera = small_scene()
    image = rtpy.render(scene, camera=camera, spp=3, backend="flat")
    np.testing.assert_array_equal(image.linear, 0.5)
    assert image.stats["backend"] == "flat" and image.samples_min == 3
    assert Flat(scene, camera, rtpy.RenderSettings()).plan(8, 8, 3).paths_per_unit == 64


def test_an_unknown_name_lists_the_registered_ones():
    scene, camera = small_scene()
    with pytest.raises(ValueError, match=r"^backend must be one of scalar, numpy; got 'gpu'$"):
        make_backend("gpu", scene, camera, rtpy.RenderSettings())
    with pytest.raises(ValueError, match="an identifier"):
        register_backend("my backend")
