"""rtpy.engine.rendered_image: what a render returns, its 8-bit view, display in Jupyter,
and saving by extension."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from rtpy.engine.display import to_8bit
from rtpy.engine.files import OutputError
from rtpy.engine.rendered_image import RenderedImage
from rtpy.io.image import read_pfm

from ..io.test_image import PNG_SIGNATURE, listing, random_image


def make_result(h: int = 3, w: int = 5) -> RenderedImage:
    return RenderedImage(random_image(h, w, seed=7) / 4.0, gamma=2.2, spp=16)


def test_rendered_image_attributes() -> None:
    img = RenderedImage(np.zeros((3, 5, 3), dtype=np.float32), spp=8)
    assert img.linear.dtype == np.float64
    assert (img.width, img.height) == (5, 3)
    assert img.gamma == 2.0
    assert img.spp == 8 and img.samples_min == 8 and img.samples_max == 8
    assert img.interrupted is False
    assert img.stats == {}
    partial = RenderedImage(
        np.zeros((2, 2, 3)),
        spp=64,
        samples_min=3,
        samples_max=4,
        interrupted=True,
        stats={"seconds": 1.5},
    )
    assert (partial.samples_min, partial.samples_max) == (3, 4)
    assert partial.interrupted is True
    assert partial.stats["seconds"] == 1.5


def test_rendered_image_rejects_bad_shape() -> None:
    with pytest.raises(ValueError, match="shape"):
        RenderedImage(np.zeros((3, 5)))


def test_rendered_image_pil_size_and_origin() -> None:
    linear = np.zeros((3, 5, 3))
    linear[0, 4] = [1.0, 0.0, 0.0]  # top-right pixel red
    linear[2, 0] = [0.0, 0.0, 1.0]  # bottom-left pixel blue
    result = RenderedImage(linear)
    pil = result.pil
    assert isinstance(pil, Image.Image)
    assert pil.mode == "RGB"
    assert pil.size == (5, 3)  # (W, H)
    assert pil.getpixel((4, 0)) == (255, 0, 0)
    assert pil.getpixel((0, 2)) == (0, 0, 255)
    assert pil.getpixel((0, 0)) == (0, 0, 0)
    assert np.array_equal(np.asarray(result.to_pil()), np.asarray(pil))


def test_rendered_image_pil_uses_gamma() -> None:
    result = RenderedImage(np.full((1, 1, 3), 0.25), gamma=2.0)
    assert result.pil.getpixel((0, 0)) == (128, 128, 128)
    assert RenderedImage(np.full((1, 1, 3), 0.25), gamma=1.0).pil.getpixel((0, 0)) == (64,) * 3


def test_rendered_image_repr_png() -> None:
    result = make_result()
    data = result._repr_png_()
    assert isinstance(data, bytes)
    assert data.startswith(PNG_SIGNATURE)
    with Image.open(io.BytesIO(data)) as pil:
        assert pil.size == (5, 3)
        assert np.array_equal(np.asarray(pil), to_8bit(result.linear, result.gamma))


def test_rendered_image_repr() -> None:
    text = repr(make_result(h=3, w=5))
    assert "5x3" in text and "spp=16" in text and "interrupted=False" in text
    partial = RenderedImage(
        np.zeros((2, 2, 3)), spp=64, samples_min=3, samples_max=4, interrupted=True
    )
    assert "interrupted=True" in repr(partial)


def test_rendered_image_save_all_extensions(tmp_path: Path) -> None:
    result = make_result()
    expected_8bit = to_8bit(result.linear, result.gamma)
    for name in ["a.png", "b.jpg", "c.jpeg", "d.npy", "e.pfm"]:
        assert result.save(tmp_path / name) == tmp_path / name
    assert listing(tmp_path) == ["a.png", "b.jpg", "c.jpeg", "d.npy", "e.pfm"]
    with Image.open(tmp_path / "a.png") as pil:
        assert np.array_equal(np.asarray(pil), expected_8bit)
    for name in ["b.jpg", "c.jpeg"]:
        with Image.open(tmp_path / name) as pil:
            assert pil.format == "JPEG" and pil.size == (5, 3)
    # Linear outputs hold the raw values: no clamping, no gamma.
    assert np.array_equal(np.load(tmp_path / "d.npy"), result.linear)
    assert np.array_equal(read_pfm(tmp_path / "e.pfm"), result.linear.astype(np.float32))


def test_rendered_image_save_unsupported(tmp_path: Path) -> None:
    path = tmp_path / "out.bmp"
    with pytest.raises(OutputError, match="out.bmp"):
        make_result().save(path)
    assert listing(tmp_path) == []


def test_rendered_image_save_missing_directory(tmp_path: Path) -> None:
    with pytest.raises(OutputError, match="does not exist"):
        make_result().save(tmp_path / "missing" / "out.png")


@pytest.mark.parametrize("gamma", [1e-5, 5e-324])
def test_a_tiny_gamma_in_range_saves_and_shows(tmp_path, gamma):
    image = RenderedImage(np.full((2, 3, 3), 0.5), gamma=gamma)
    image.save(tmp_path / "x.png")
    with Image.open(tmp_path / "x.png") as im:
        assert im.size == (3, 2) and "gamma" not in im.info
    assert image.pil.size == (3, 2)
