"""The writers rtpy.io gives the core (rtpy.engine.writer): RenderedImage.save writes the
file formats of rtpy.io.image, and rtpy.render's preview= goes through
rtpy.io.preview. Each is imported when first used: `import rtpy` imports this
module, and loads neither numpy nor Pillow for it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..engine.writer import register_writer

if TYPE_CHECKING:
    from collections.abc import Iterable
    from pathlib import Path

    import numpy as np

    from ..engine.display import Gamma
    from ..engine.files import StrPath
    from .preview import Preview

__all__ = ["preview_target", "write_image"]


@register_writer("image")
def write_image(path: StrPath, linear: np.ndarray, gamma: Gamma) -> Path:
    """rtpy.io.image.write_image: the format by the extension."""
    from .image import write_image

    return write_image(path, linear, gamma)


@register_writer("preview")
def preview_target(preview: object, inputs: Iterable[StrPath] = ()) -> Preview | None:
    """rtpy.io.preview.preview_target: a file, a notebook's output or a function."""
    from .preview import preview_target

    return preview_target(preview, inputs)
