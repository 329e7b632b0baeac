"""rtpy.engine.render_request: rtpy.render's values, checked once at the boundary, each
refusal naming its parameter; the Renderer it makes holds them as rtpy uses them."""

from __future__ import annotations

import importlib.util
import re

import pytest

import rtpy
from rtpy import Camera, Color
from rtpy.engine.render_request import AspectError, prepare_render
from rtpy.render_settings import SettingError

from .test_backend import small_scene

# rtpy.render checks a cluster by asking Dask distributed (an optional extra:
# pip install 'rtpy[cluster]'), which a student's `.[test]` install does not have.
needs_dask = pytest.mark.skipif(
    importlib.util.find_spec("distributed") is None,
    reason="checking cluster= needs Dask distributed (pip install 'rtpy[cluster]')",
)


@pytest.mark.parametrize(
    "kwargs,error,message",
    [
        ({"camera": "front"}, TypeError, "camera: expected a Camera or None, found a str"),
        ({"workers": 0}, ValueError, "workers: "),
        ({"spp": 0}, SettingError, "spp: expected an integer in [1, 1000000]"),
        ({"background": [1, 2]}, SettingError, "background: "),
        ({"width": 0}, SettingError, "width: "),
        ({"resume": "yes"}, TypeError, "resume must be True or False"),
        ({"backend": "gpu"}, ValueError, "backend must be one of scalar, numpy; got 'gpu'"),
        ({"preview_seconds": -1}, ValueError, "preview_seconds must be a number >= 0"),
        pytest.param({"cluster": 3}, TypeError, "cluster: expected", marks=needs_dask),
    ],
)
def test_every_value_is_refused_naming_its_parameter(kwargs, error, message):
    scene, camera = small_scene()
    with pytest.raises(error, match="^" + re.escape(message)):
        prepare_render(scene, **{"camera": camera, **kwargs})


def test_a_scene_is_a_scene():
    with pytest.raises(TypeError, match="scene: expected a Scene, found a str"):
        prepare_render("cornell")


def test_a_scene_built_in_code_gets_the_default_camera():
    """No camera passed, none in the scene: rtpy.Camera(), at the origin looking down
    -z (tests/engine/test_renderer.py renders the README's example with it)."""
    renderer = prepare_render(rtpy.Scene([], sky=True))
    assert vars(renderer.camera) == vars(Camera())
    own = Camera(width=8)
    assert prepare_render(rtpy.Scene([], camera=own)).camera is own


def test_a_width_the_aspect_ratio_makes_too_tall_names_the_width():
    scene = rtpy.Scene([], camera=Camera(aspect_ratio=0.001, width=4))
    with pytest.raises(AspectError) as info:
        prepare_render(scene, width=16384)
    assert info.value.key == "width" and info.value.width == 16384
    assert str(info.value).startswith("width: 16384 with the camera's aspect ratio: ")


def test_the_renderer_holds_the_values_as_rtpy_uses_them():
    scene, camera = small_scene()
    renderer = prepare_render(
        scene, camera=camera, width=20, spp=3, background=[0.25, 0.5, 1], sky=False,
        time=2.5, workers=2, quiet=False,
    )  # fmt: skip
    assert (renderer.camera.width, renderer.settings.spp, renderer.workers) == (20, 3, 2)
    assert renderer.scene.background == Color(0.25, 0.5, 1) and scene.sky is True
    assert renderer.time_limit == 2.5 == renderer.settings.time_limit
    assert not renderer.quiet and renderer.checkpoint is None and renderer.executor is None
