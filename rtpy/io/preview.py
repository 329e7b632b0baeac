"""Where rtpy.render sends the image while it renders: a file, a notebook, a function.

A preview is the mean of the samples finished so far; passes run over the whole
image, so it is a whole frame that sharpens as the render goes on.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable

from ..engine.files import StrPath
from ..engine.rendered_image import RenderedImage
from .image import check_image_path
from .outputs import check_output

Preview = Callable[[RenderedImage], object]


def preview_target(preview: object, inputs: Iterable[StrPath] = ()) -> Preview | None:
    """render()'s `preview` as a function of the image so far, or None.

    None or False: no preview. A path (str or os.PathLike) to a .png or .jpg: the
    file is rewritten atomically with each preview (checked before the render
    starts, and refused when it is one of `inputs`, the files the scene was read
    from). True: in a Jupyter notebook, one output that each preview replaces.
    A function: called with each preview, a RenderedImage.
    """
    if preview is None or preview is False:
        return None
    if preview is True:
        return notebook_preview()
    if isinstance(preview, str | os.PathLike):
        path = check_output(preview, "preview", inputs, check=check_image_path)
        return lambda image: image.save(path)
    if callable(preview):
        return preview
    raise TypeError(
        f"preview must be a file name, True (a notebook) or a function, got {preview!r}"
    )


def notebook_preview() -> Preview:
    """A function that shows each preview in the notebook's output, replacing the last."""
    try:
        from IPython.display import display
    except ImportError:
        raise ValueError(
            "preview=True shows the image in a Jupyter notebook and needs IPython; "
            "pass a file name or a function instead"
        ) from None
    handle = None

    def show(image: RenderedImage) -> None:
        nonlocal handle
        if handle is None:
            handle = display(image, display_id=True)
        else:
            handle.update(image)

    return show
