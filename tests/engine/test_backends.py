"""rtpy.engine.backends: the scalar and numpy backends registered by name, each imported
when a render asks for it."""

from __future__ import annotations

import rtpy
from rtpy.engine.backends import BACKENDS
from rtpy.engine.scalar_backend import ScalarBackend
from rtpy.numpy_backend.renderer import NumpyBackend

from ..commands import modules_imported_by
from .test_renderer import small_scene


def test_the_two_backends_rtpy_comes_with():
    assert BACKENDS == rtpy.BACKENDS == ("scalar", "numpy")
    scene, camera = small_scene()
    settings = rtpy.RenderSettings()
    made = [rtpy.Renderer(scene, camera, settings, backend=name).backend for name in BACKENDS]
    assert [type(b) for b in made] == [ScalarBackend, NumpyBackend]
    assert [b.name for b in made] == list(BACKENDS)


def test_a_scalar_render_loads_none_of_the_numpy_backend():
    code = (
        "import rtpy\n"
        "scene = rtpy.Scene([rtpy.Sphere(rtpy.Vec3(0, 0, -1), 0.5, rtpy.Lambertian())])\n"
        "rtpy.render(scene, camera=rtpy.Camera(width=4), spp=1)\n"
    )
    loaded = modules_imported_by(code)
    assert "rtpy.engine.scalar_backend" in loaded and "rtpy.numpy_backend" not in loaded
