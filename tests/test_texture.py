"""Tests for rtpy.texture: solid colours, 3-D checker cells and image textures."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rtpy.hit_info import HitInfo
from rtpy.materials import Lambertian
from rtpy.texture import CheckerTexture, ImageTexture, SolidColor, srgb_to_linear
from rtpy.vec3 import Color, Vec3

EVEN = Color(1.0, 1.0, 1.0)
ODD = Color(0.0, 0.0, 0.0)


def hit_at(point=(0.0, 0.0, 0.0), u=None, v=None) -> HitInfo:
    return HitInfo(Vec3(*point), Vec3(0.0, 0.0, 1.0), 1.0, True, Lambertian(), None, u, v)


def test_solid_color():
    c = Color(0.1, 0.2, 0.3)
    assert SolidColor(c).value(hit_at((5.0, -3.0, 2.0), 0.3, 0.7)) is c


@pytest.mark.parametrize(
    "point, scale, parity",
    [
        ((0.5, 0.5, 0.5), 1.0, "even"),
        ((1.5, 0.5, 0.5), 1.0, "odd"),
        ((1.5, 1.5, 0.5), 1.0, "even"),
        ((1.5, 1.5, 1.5), 1.0, "odd"),
        # Negative coordinates use floor: floor(-0.5) = -1 (int() would give 0).
        ((-0.5, 0.5, 0.5), 1.0, "odd"),
        ((-0.5, -0.5, 0.5), 1.0, "even"),
        ((-0.5, -0.5, -0.5), 1.0, "odd"),
        ((-1.5, 0.2, 0.2), 1.0, "even"),
        ((-0.25, 0.75, 0.0), 1.0, "odd"),
        # Scale is the cell edge length.
        ((1.5, 0.5, 0.5), 2.0, "even"),
        ((2.5, 0.5, 0.5), 2.0, "odd"),
        ((-0.5, 0.5, 0.5), 2.0, "odd"),
        ((-2.5, 0.5, 0.5), 2.0, "even"),
        ((0.3, 0.3, 0.3), 0.25, "odd"),  # floor(1.2) * 3 = 3
        ((0.3, 0.3, 0.6), 0.25, "even"),  # 1 + 1 + 2 = 4
        ((-0.1, -0.1, -0.1), 0.25, "odd"),  # -1 * 3 = -3
    ],
)
def test_checker_parity(point, scale, parity):
    tex = CheckerTexture(scale, EVEN, ODD)
    expected = EVEN if parity == "even" else ODD
    assert tex.value(hit_at(point)) is expected


def test_checker_cell_boundaries():
    tex = CheckerTexture(1.0, EVEN, ODD)
    # Integer coordinates belong to the cell above them: floor(1.0) = 1.
    assert tex.value(hit_at((1.0, 0.5, 0.5))) is ODD
    assert tex.value(hit_at((0.999999, 0.5, 0.5))) is EVEN
    assert tex.value(hit_at((-1e-12, 0.5, 0.5))) is ODD


def test_checker_ignores_uv():
    tex = CheckerTexture(1.0, EVEN, ODD)
    assert tex.value(hit_at((0.5, 0.5, 0.5), 0.0, 0.0)) is tex.value(hit_at((0.5, 0.5, 0.5), 1, 1))


@pytest.mark.parametrize("scale", [0.0, -1.0])
def test_checker_rejects_bad_scale(scale):
    with pytest.raises(ValueError):
        CheckerTexture(scale, EVEN, ODD)


# A 3-row x 4-column image, row 0 at the top; every texel distinct.
PIXELS = np.array([[[r / 10.0, c / 10.0, (r * 4 + c) / 100.0] for c in range(4)] for r in range(3)])
H, W = 3, 4


def texel(row: int, col: int) -> list[float]:
    return PIXELS[row, col].tolist()


@pytest.fixture()
def tex() -> ImageTexture:
    return ImageTexture(PIXELS)


def test_image_corners(tex):
    assert tex.value(hit_at(u=0.0, v=0.0)).tolist() == texel(H - 1, 0)  # bottom-left
    assert tex.value(hit_at(u=1.0, v=1.0)).tolist() == texel(0, W - 1)  # top-right
    assert tex.value(hit_at(u=0.0, v=1.0)).tolist() == texel(0, 0)  # top-left
    assert tex.value(hit_at(u=1.0, v=0.0)).tolist() == texel(H - 1, W - 1)  # bottom-right
    assert tex.value(hit_at(u=0.9999, v=0.9999)).tolist() == texel(0, W - 1)


@pytest.mark.parametrize("col", range(W))
@pytest.mark.parametrize("k", range(H))
def test_image_nearest_lookup_at_texel_centres_and_inside(tex, col, k):
    """Texel column `col`, k-th row from the bottom, covers u in [col/W, (col+1)/W) and
    v in [k/H, (k+1)/H)."""
    row = H - 1 - k
    for du in (0.05, 0.5, 0.95):
        for dv in (0.05, 0.5, 0.95):
            u, v = (col + du) / W, (k + dv) / H
            got = tex.value(hit_at(u=u, v=v))
            assert isinstance(got, Color)
            assert got.tolist() == texel(row, col)


def test_image_clamps_uv(tex):
    assert tex.value(hit_at(u=-0.3, v=-2.0)).tolist() == texel(H - 1, 0)
    assert tex.value(hit_at(u=1.7, v=5.0)).tolist() == texel(0, W - 1)


@pytest.mark.parametrize("shape", [(2, 2), (2, 2, 4), (0, 2, 3), (2, 0, 3)])
def test_image_rejects_bad_shapes(shape):
    with pytest.raises(ValueError):
        ImageTexture(np.zeros(shape))


@pytest.mark.parametrize("value", [-0.1, 1.5, np.nan, np.inf])
def test_image_refuses_pixels_outside_0_1(value):
    pixels = np.full((2, 2, 3), 0.5)
    pixels[1, 0, 2] = value
    with pytest.raises(ValueError, match=r"^pixels: .*in \[0, 1\]"):
        ImageTexture(pixels)


def srgb_decode(value: int) -> float:
    c = value / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def test_from_file_round_trip_with_srgb_decoding(tmp_path):
    data = np.array(
        [
            [[255, 0, 128], [0, 0, 0], [10, 11, 200]],
            [[128, 128, 128], [255, 255, 255], [1, 64, 254]],
        ],
        dtype=np.uint8,
    )
    path = tmp_path / "tiny.png"
    Image.fromarray(data, "RGB").save(path)
    tex = ImageTexture.from_file(path)
    assert (tex.height, tex.width) == (2, 3)
    # Top-left texel is (255, 0, 128): u = 0, v = 1.
    got = tex.value(hit_at(u=0.0, v=1.0)).tolist()
    assert got[0] == pytest.approx(1.0, abs=1e-15)
    assert got[1] == 0.0
    assert got[2] == pytest.approx(((128 / 255 + 0.055) / 1.055) ** 2.4, rel=1e-12)
    for row in range(2):
        for col in range(3):
            u, v = (col + 0.5) / 3, 1.0 - (row + 0.5) / 2
            got = tex.value(hit_at(u=u, v=v)).tolist()
            expected = [srgb_decode(int(x)) for x in data[row, col]]
            assert got == pytest.approx(expected, rel=1e-12, abs=1e-15)
    # 10/255 lies on the linear segment of the curve.
    assert tex.value(hit_at(u=0.9, v=0.9)).r() == pytest.approx(10 / 255 / 12.92, rel=1e-12)


def test_srgb_to_linear_known_points():
    x = np.array([0.0, 0.04045, 0.5, 1.0])
    got = srgb_to_linear(x)
    assert got[0] == 0.0
    assert got[1] == pytest.approx(0.04045 / 12.92)
    assert got[2] == pytest.approx(((0.5 + 0.055) / 1.055) ** 2.4)
    assert got[3] == pytest.approx(1.0)
    # Monotone.
    xs = np.linspace(0.0, 1.0, 1001)
    assert np.all(np.diff(srgb_to_linear(xs)) > 0)


def test_a_16_bit_greyscale_png_reads_its_levels_not_white(tmp_path):
    """Pillow opens a 16-bit greyscale PNG in mode I;16 (0 .. 65535), which convert
    to RGB clips at 255: every texel but black would read white."""
    levels = np.array([[0, 32768, 65535], [1000, 20000, 50000]], dtype=np.uint16)
    path = tmp_path / "grey16.png"
    Image.fromarray(levels).save(path)
    with Image.open(path) as im:
        assert im.mode.startswith("I")  # the file is what this test is about
    tex = ImageTexture.from_file(path)
    for row in range(2):
        for col in range(3):
            u, v = (col + 0.5) / 3, 1.0 - (row + 0.5) / 2
            got = tex.value(hit_at(u=u, v=v)).tolist()
            level = srgb_to_linear(np.array(levels[row, col] / 65535.0))
            assert got == pytest.approx([float(level)] * 3, rel=1e-12, abs=1e-15)
    mid = tex.value(hit_at(u=0.5, v=0.75)).r()
    assert mid == pytest.approx(0.214, abs=0.002)  # the sRGB mid-grey, in linear
