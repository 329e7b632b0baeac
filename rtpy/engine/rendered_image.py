"""RenderedImage: what a render returns, the linear image and how it was made.

The image is an ``(H, W, 3)`` float64 array of linear RGB radiance, row 0 at the
top; the display transform (gamma) is applied only for 8-bit output and display
(rtpy.engine.display). ``save`` writes any of rtpy.io.image's formats, through the writer
rtpy.io registers (rtpy.engine.writer).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from PIL import Image

from .display import Gamma, as_rgb, check_gamma, png_info, to_8bit
from .files import StrPath
from .writer import writer

__all__ = ["RenderedImage"]


class RenderedImage:
    """The result of a render.

    Attributes:
        linear: ``(H, W, 3)`` float64 array of **linear** RGB; pixel ``(0, 0)``
            is the top-left corner (row index = y going down, column = x).
        gamma: display transform, a gamma > 0 or "srgb", used **only** for 8-bit
            output (:attr:`pil`, ``.png``/``.jpg``); linear output is never encoded.
        spp: requested samples per pixel.
        samples_min, samples_max: fewest and most samples any pixel actually
            holds (both default to ``spp``; smaller after an interrupted render).
        interrupted: True if the render was stopped before finishing.
        stats: free-form statistics, e.g. ``seconds``, ``paths``, ``paths_per_second``.
    """

    def __init__(
        self,
        linear: np.ndarray,
        gamma: Gamma = 2.0,
        spp: int = 0,
        samples_min: int | None = None,
        samples_max: int | None = None,
        interrupted: bool = False,
        stats: dict | None = None,
    ) -> None:
        self.linear: np.ndarray = np.asarray(as_rgb(linear), dtype=np.float64)
        self.gamma: Gamma = check_gamma(gamma)
        self.spp: int = int(spp)
        self.samples_min: int = self.spp if samples_min is None else int(samples_min)
        self.samples_max: int = self.spp if samples_max is None else int(samples_max)
        self.interrupted: bool = bool(interrupted)
        self.stats: dict = {} if stats is None else dict(stats)

    @property
    def width(self) -> int:
        """Image width in pixels (``linear.shape[1]``)."""
        return int(self.linear.shape[1])

    @property
    def height(self) -> int:
        """Image height in pixels (``linear.shape[0]``)."""
        return int(self.linear.shape[0])

    @property
    def pil(self) -> Image.Image:
        """An 8-bit RGB PIL image, gamma-encoded with :attr:`gamma`."""
        return Image.fromarray(to_8bit(self.linear, self.gamma))

    def to_pil(self) -> Image.Image:
        """Same as :attr:`pil`."""
        return self.pil

    def save(self, path: StrPath) -> Path:
        """Save by extension and return the path written.

        ``.png``/``.jpg``/``.jpeg`` are 8-bit and encoded with :attr:`gamma`;
        ``.npy``/``.pfm``/``.exr`` are linear and never encoded. Any other extension
        raises :class:`~rtpy.engine.files.OutputError`, a failing write
        :class:`~rtpy.engine.files.WriteError` (the file that was there is untouched).
        """
        return writer("image")(path, self.linear, self.gamma)  # rtpy.io.image's formats

    def _repr_png_(self) -> bytes:
        """PNG bytes of the 8-bit image, so Jupyter displays a RenderedImage inline."""
        buf = io.BytesIO()
        self.pil.save(buf, format="PNG", pnginfo=png_info(self.gamma))
        return buf.getvalue()

    def __repr__(self) -> str:
        samples = f"spp={self.spp}"
        if (self.samples_min, self.samples_max) != (self.spp, self.spp):
            samples += f", samples={self.samples_min}..{self.samples_max}"
        return (
            f"RenderedImage({self.width}x{self.height}, {samples}, interrupted={self.interrupted})"
        )
