"""Textures: colours that vary over a surface. value(hit) returns a linear Color."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

from ._checks import LENGTH, UNIT, checked_color, checked_number
from .hit_info import HitInfo
from .vec3 import Color

if TYPE_CHECKING:
    import numpy as np


class Texture:
    def value(self, hit: HitInfo) -> Color:
        raise NotImplementedError


class SolidColor(Texture):
    """The same colour everywhere."""

    def __init__(self, color: Color) -> None:
        self.color = checked_color("color", color)

    def value(self, hit: HitInfo) -> Color:
        return self.color


class CheckerTexture(Texture):
    """3-D checker cells of edge `scale` (world units): point p takes `even` when
    floor(px/scale) + floor(py/scale) + floor(pz/scale) is even, else `odd`.
    Solid cells, so it needs no (u, v)."""

    def __init__(self, scale: float, even: Color, odd: Color) -> None:
        self.inv_scale = 1.0 / checked_number("scale", scale, LENGTH)
        self.even = checked_color("even", even)
        self.odd = checked_color("odd", odd)

    def value(self, hit: HitInfo) -> Color:
        # BEGIN SOLUTION week07: 3-D checker cells
        p = hit.point * self.inv_scale
        cell = math.floor(p.x()) + math.floor(p.y()) + math.floor(p.z())
        return self.even if cell % 2 == 0 else self.odd
        # END SOLUTION


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    """The sRGB transfer curve inverted: 8-bit file values (as 0..1) to linear."""
    import numpy as np  # here: the scalar renderer's textures need no numpy

    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


class ImageTexture(Texture):
    """An image wrapped by the hit's (u, v): u = 0 at the left column, v = 0 at the
    bottom row. Nearest-pixel lookup (as RTIOW); u and v are clamped to [0, 1].
    PNG/JPEG pixels are sRGB-encoded and decoded to linear RGB on load."""

    def __init__(self, pixels: np.ndarray) -> None:
        import numpy as np

        pixels = np.asarray(pixels, dtype=np.float64)
        if pixels.ndim != 3 or pixels.shape[2] != 3 or pixels.shape[0] < 1 or pixels.shape[1] < 1:
            raise ValueError(f"image texture needs an (H, W, 3) array, got shape {pixels.shape}")
        if not np.all((pixels >= 0.0) & (pixels <= 1.0)):  # also refuses NaN
            raise ValueError(f"pixels: expected linear colours, each component {UNIT.text()}")
        self.pixels = pixels  # linear RGB, row 0 at the top
        self.height, self.width = pixels.shape[:2]
        # Rows as lists of Colors: the scalar renderer reads one texel at a time,
        # and Python floats are much cheaper to read than numpy scalars.
        self._rows = [[Color(*map(float, px)) for px in row] for row in pixels]

    @classmethod
    def from_file(cls, path: str | Path | BinaryIO) -> ImageTexture:
        """The texture of a PNG or JPEG file (a path, or a file object open in binary)."""
        import numpy as np
        from PIL import Image

        with Image.open(path) as im:
            if im.mode.startswith("I"):  # 16-bit greyscale: 0 .. 65535 (convert would clip)
                grey = np.clip(np.asarray(im, dtype=np.float64) / 65535.0, 0.0, 1.0)
                data = np.stack([grey, grey, grey], axis=2)
            else:
                data = np.asarray(im.convert("RGB"), dtype=np.float64) / 255.0
        return cls(srgb_to_linear(data))

    def value(self, hit: HitInfo) -> Color:
        # BEGIN SOLUTION week07: nearest texel at (u, v), v = 0 at the bottom row
        u = min(1.0, max(0.0, hit.u))
        v = 1.0 - min(1.0, max(0.0, hit.v))  # image rows run top to bottom
        i = min(int(u * self.width), self.width - 1)
        j = min(int(v * self.height), self.height - 1)
        return self._rows[j][i]
        # END SOLUTION
