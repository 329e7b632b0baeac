"""Random valid scenes render to finite, non-negative pixels on both backends.

Hypothesis draws seeds of whole scene files (tests/hard_cases/scene_strategies.py): random
spheres, quads and (sliver) triangles, materials of every registered kind with
parameters at the edges of their ranges, solid, checker and image textures, point
and area lights (one- and two-sided), pinhole and thin-lens cameras, every
integrator with and without next-event estimation and Russian roulette. Each is
loaded from its TOML text and rendered tiny (at most 8x8 pixels, 1-2 spp, depth
<= 4) by the scalar and the numpy backend. No pixel may be NaN, Inf or negative:
the renderers must guard at the source (a NaN weight, an inf/inf MIS weight, a
1/0 pdf), since the final image is never clamped.

The examples are derandomized (a fixed sequence), so CI is reproducible; set
FUZZ_EXAMPLES=20 to run twenty times as many locally.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from PIL import Image

import rtpy
from rtpy._checks import MAX_RADIANCE
from rtpy.io.scene_file import SceneError, load_scene_text
from tests.io.scene_text import to_toml

from .scene_strategies import fuzz_settings, random_scene, seeds


@pytest.fixture(scope="module")
def scene_dir(tmp_path_factory):
    """A folder holding a 3x2 image texture the scenes may use."""
    folder = tmp_path_factory.mktemp("fuzz_scenes")
    pixels = np.array([[[255, 0, 0], [0, 255, 0], [0, 0, 255]], [[0, 0, 0]] * 3], np.uint8)
    Image.fromarray(pixels).save(folder / "tex.png")
    return folder


def render_both(text: str, folder) -> dict[str, np.ndarray]:
    scene = load_scene_text(text, folder / "fuzz.toml")
    return {b: rtpy.render(scene, backend=b).linear for b in rtpy.BACKENDS}


def bad_pixels(image: np.ndarray) -> str:
    """'' if every value is finite and >= 0, else where it is not."""
    bad = ~np.isfinite(image) | (image < 0)
    if not bad.any():
        return ""
    rows, cols, _ = np.nonzero(bad)
    first = image[rows[0], cols[0]]
    return f"{bad.sum()} bad values, first at pixel ({cols[0]}, {rows[0]}): {first}"


@fuzz_settings(150)
@given(seed=seeds)
def test_random_valid_scenes_render_finite_non_negative_pixels(scene_dir, seed):
    """What a naive renderer gets wrong here: a 0/0 weight where a sampled
    direction grazes the surface, an inf light pdf (sliver triangles, lights in the
    plane of a wall) making the MIS weight inf/inf = NaN, a negative value from an
    unclamped lobe, or a sum of huge radiances overflowing (the regression test
    below). FUZZ_EXAMPLES=30 draws thirty times as many scenes."""
    text = to_toml(random_scene(seed, image_path="tex.png"))
    for backend, image in render_both(text, scene_dir).items():
        assert image.shape[2] == 3
        problem = bad_pixels(image)
        assert not problem, f"{backend} backend: {problem}\n{text}"


def test_the_check_catches_a_nan_pixel():
    """bad_pixels (the fuzz test's check) flags NaN, Inf and negative values."""
    image = np.zeros((2, 3, 3))
    assert bad_pixels(image) == ""
    for value in (np.nan, np.inf, -1e-300):
        image[1, 2, 0] = value
        assert "pixel (2, 1)" in bad_pixels(image)


LIMIT_SCENE = """
[camera]
look_from = [0, 0, 2]
width = 8
[render]
spp = 8
max_depth = 12
russian_roulette = 0
background = [{big}, {big}, {big}]
[materials.lamp]
type = "diffuse_light"
emit = [{big}, {big}, {big}]
two_sided = true
[materials.shiny]
type = "phong"
albedo = [1, 1, 1]
kd = 1
ks = 1
exponent = 1
[[objects]]
type = "sphere"
center = [0, 0, -1]
radius = 0.5
material = "lamp"
[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 4
material = "shiny"
[[lights]]
type = "point"
position = [0, 1, 0]
intensity = [{big}, {big}, {big}]
"""


@pytest.mark.parametrize("integrator", ["path", "whitted", "direct", "shading"])
def test_largest_radiances_and_weights_sum_without_overflow(scene_dir, integrator):
    """Found while testing the fuzzer's limits: emit = 1e308 is finite and >= 0, as
    the contract asks, but the sum of two samples is inf, so the pixel was Inf (and
    kd = 1e300 overflows a path's weight). Radiances (emit, intensity, background)
    are now at most MAX_RADIANCE and kd, ks at most 1; a closed, over-bright scene at those
    limits renders finite pixels on both backends."""
    text = LIMIT_SCENE.format(big=repr(MAX_RADIANCE))
    text = text.replace("[render]", f'[render]\nintegrator = "{integrator}"')
    scene = load_scene_text(text, scene_dir / "limit.toml")
    for backend in rtpy.BACKENDS:
        image = rtpy.render(scene, backend=backend).linear
        assert not bad_pixels(image), backend
        assert image.max() > 0.1 * MAX_RADIANCE
    for before, after in [
        ("emit = [1000000000.0", "emit = [1e308"),
        ("background = [1000000000.0", "background = [1000000000.5"),
        ("intensity = [1000000000.0", "intensity = [1000000000.5"),
        ("kd = 1\n", "kd = 1.5\n"),
        ("ks = 1\n", "ks = 1e300\n"),
    ]:
        key = before.split()[0]
        with pytest.raises(SceneError, match=rf" {key}: expected"):
            load_scene_text(text.replace(before, after), scene_dir / "limit.toml")
