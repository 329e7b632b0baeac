"""rtpy.io.preview: where render() sends the image while it renders."""

from __future__ import annotations

import sys
import types

import numpy as np
import pytest
from PIL import Image

import rtpy
from rtpy.engine.files import OutputError
from rtpy.engine.rendered_image import RenderedImage
from rtpy.io.preview import notebook_preview, preview_target


def image(value: float) -> RenderedImage:
    return RenderedImage(np.full((4, 6, 3), value), gamma=2.0, spp=1)


def test_no_preview():
    assert preview_target(None) is None and preview_target(False) is None


def test_a_file_is_rewritten_with_each_preview(tmp_path):
    path = tmp_path / "preview.png"
    show = preview_target(str(path))
    for value in (0.25, 1.0):
        show(image(value))
        with Image.open(path) as im:
            assert im.size == (6, 4)
            assert np.asarray(im)[0, 0, 0] == round(255 * value**0.5)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["preview.png"]  # no temporary files


def test_a_file_that_cannot_be_written_is_refused_before_the_render(tmp_path):
    with pytest.raises(OutputError, match="preview.npy"):
        preview_target(tmp_path / "preview.npy")
    with pytest.raises(OutputError, match="does not exist"):
        preview_target(tmp_path / "missing" / "preview.png")


def test_a_preview_over_one_of_the_scenes_files_is_refused(tmp_path):
    """As the CLI's --preview: rtpy.render(scene, preview=...) never overwrites a file
    the scene was read from (here its image texture), whatever the extension."""
    texture = tmp_path / "wood.png"
    Image.new("RGB", (2, 2), (200, 120, 40)).save(texture)
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(
        '[camera]\nwidth = 4\naspect_ratio = 1.0\n\n[textures.wood]\ntype = "image"\n'
        'path = "wood.png"\n\n[materials.m]\ntype = "lambertian"\nalbedo = "wood"\n\n'
        '[[objects]]\ntype = "sphere"\ncenter = [0, 0, -2]\nradius = 1\nmaterial = "m"\n'
    )
    scene = rtpy.load_scene(scene_file)
    before = texture.read_bytes()
    with pytest.raises(OutputError, match="preview .*wood.png: would overwrite .*an input"):
        rtpy.render(scene, spp=1, preview=texture)
    assert texture.read_bytes() == before


def test_a_function_is_called_as_it_is():
    seen = []
    assert preview_target(seen.append) == seen.append


def test_anything_else_is_a_type_error():
    with pytest.raises(TypeError, match="preview"):
        preview_target(3)


def test_the_notebook_output_is_replaced_by_each_preview(monkeypatch):
    calls = []

    class Handle:
        def update(self, obj):
            calls.append(("update", obj))

    def display(obj, display_id=False):
        calls.append(("display", obj))
        assert display_id is True
        return Handle()

    ipython = types.ModuleType("IPython")
    ipython.display = types.ModuleType("IPython.display")
    ipython.display.display = display
    monkeypatch.setitem(sys.modules, "IPython", ipython)
    monkeypatch.setitem(sys.modules, "IPython.display", ipython.display)
    first, second, third = image(0.1), image(0.2), image(0.3)
    show = preview_target(True)
    for im in (first, second, third):
        show(im)
    assert calls == [("display", first), ("update", second), ("update", third)]


def test_a_notebook_preview_without_ipython_says_what_to_pass(monkeypatch):
    monkeypatch.setitem(sys.modules, "IPython", None)
    monkeypatch.setitem(sys.modules, "IPython.display", None)
    with pytest.raises(ValueError, match="file name or a function"):
        notebook_preview()
