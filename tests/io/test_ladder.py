"""rtpy.ladder: the scene on every rung of the lecture's ladder, and the labelled strip."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import rtpy
from rtpy.engine.files import OutputError
from rtpy.io.ladder import GAP, LABEL_HEIGHT, RUNGS, ladder, ladder_strip, write_ladder

SMALL = {"backend": "numpy", "width": 24, "spp": 2, "seed": 5, "workers": 1}


@pytest.fixture(scope="module")
def images():
    return ladder("week06_ladder", **SMALL)


def test_every_rung_is_the_render_of_its_settings(images):
    """One image per rung, in order, each the image rtpy.render makes with the rung's
    settings (shading without, then with shadows)."""
    scene = rtpy.load_scene("week06_ladder")
    assert len(images) == len(RUNGS) == 5
    assert [r.settings["integrator"] for r in RUNGS] == [
        "jittered",
        "shading",
        "shading",
        "whitted",
        "path",
    ]
    for rung, image in zip(RUNGS, images, strict=True):
        expected = rtpy.render(scene, **rung.settings, **SMALL)
        np.testing.assert_array_equal(image.linear, expected.linear)


def test_each_rung_shows_something_new(images):
    """On the bundled scene the rungs differ: shading darkens the unlit sides, shadows
    darken the floor further, Whitted fills the mirror and the glass, path tracing
    adds indirect light."""
    colour, shading, shadows, whitted, path = (im.linear.mean() for im in images)
    assert shadows < shading < colour
    assert whitted > shadows
    assert path > whitted


def test_the_ladder_chooses_integrator_and_shadows():
    for key, value in (("integrator", "path"), ("shadows", True)):
        with pytest.raises(TypeError, match=key):
            ladder("week06_ladder", **{key: value})
    assert rtpy.ladder is ladder


def test_strip_places_each_image_under_its_label(images):
    strip = ladder_strip(images)
    w, h = images[0].width, images[0].height
    assert strip.size == (5 * w + 4 * GAP, LABEL_HEIGHT + h)
    pixels = np.asarray(strip)
    for k, image in enumerate(images):
        x = k * (w + GAP)
        np.testing.assert_array_equal(pixels[LABEL_HEIGHT:, x : x + w], np.asarray(image.pil))
        band = pixels[:LABEL_HEIGHT, x : x + w]
        assert (band > 128).any(), f"no label drawn over panel {k}"
    # labels longer than a panel (these are 24 px wide) are cut at its edge: the gaps
    # between panels stay dark
    gaps = [pixels[:, k * (w + GAP) - GAP : k * (w + GAP)] for k in range(1, 5)]
    assert all((gap == gaps[0][0, 0]).all() for gap in gaps) and gaps[0][0, 0].max() < 64


def test_strip_refuses_mismatched_labels_and_sizes(images):
    with pytest.raises(ValueError, match="labels"):
        ladder_strip(images, ["one"])
    other = rtpy.render(rtpy.load_scene("week06_ladder"), **{**SMALL, "width": 16})
    with pytest.raises(ValueError, match="size"):
        ladder_strip([*images[:4], other])


def test_write_ladder_writes_the_strip(images, tmp_path):
    path = write_ladder(tmp_path / "ladder.png", images)
    with Image.open(path) as written:
        np.testing.assert_array_equal(np.asarray(written), np.asarray(ladder_strip(images)))
    with pytest.raises(OutputError):
        write_ladder(tmp_path / "ladder.txt", images)
    assert not (tmp_path / "ladder.txt").exists()
