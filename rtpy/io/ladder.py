"""The lecture's ladder: one scene rendered on every rung of "what colour does this ray
see?", from the colour of the first hit to path tracing, and the labelled strip of
those images (`python -m rtpy ladder`, docs/scene-format.md).

Each rung adds what the one before lacks: shading tells materials apart, shadow rays
ground the objects, Whitted ray tracing follows mirrors and glass, path tracing adds
the light that arrives after any number of diffuse bounces.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from PIL import Image

    from ..engine.rendered_image import RenderedImage
    from ..scene import Scene

__all__ = ["RUNGS", "Rung", "ladder", "ladder_strip", "write_ladder"]


@dataclass(frozen=True)
class Rung:
    """One rung: its label in the strip and the render settings that make it."""

    label: str
    settings: dict[str, Any]


RUNGS: tuple[Rung, ...] = (
    Rung("1 colour", {"integrator": "jittered"}),
    Rung("2 shading", {"integrator": "shading", "shadows": False}),
    Rung("2 shading + shadows", {"integrator": "shading", "shadows": True}),
    Rung("3 Whitted", {"integrator": "whitted"}),
    Rung("4 path tracing", {"integrator": "path"}),
)
# The settings the ladder chooses per rung: a caller may not set them.
CHOSEN = ("integrator", "shadows")
LABEL_HEIGHT = 22  # pixels of the band above each panel that holds its label
GAP = 4  # pixels between panels


def ladder(scene: Scene | str | Path, **options) -> list[RenderedImage]:
    """The scene (a Scene, a scene file or a bundled scene's name) rendered on every
    rung of RUNGS, in order, by rtpy.render with `options` (backend, workers, width,
    spp, seed, ...: anything rtpy.render takes except the integrator and shadows,
    which each rung sets; TypeError naming them)."""
    from ..engine.render_request import render
    from .bundled import resolve_scene
    from .scene_file import load_scene

    for key in CHOSEN:
        if key in options:
            raise TypeError(f"{key}: set by each rung of the ladder, not by its caller")
    if isinstance(scene, (str, Path)):
        scene = load_scene(resolve_scene(str(scene)))
    images = []
    for rung in RUNGS:
        image = render(scene, **rung.settings, **options)
        images.append(image)
        if image.interrupted:  # Ctrl-C: the rungs rendered so far, the last one partial
            break
    return images


def _font(size: int):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1: the fixed bitmap font
        return ImageFont.load_default()


def ladder_strip(images: list[RenderedImage], labels: list[str] | None = None) -> Image.Image:
    """One 8-bit RGB image: the images side by side (each gamma-encoded with its own
    gamma), GAP pixels apart, each under a band holding its label (RUNGS' labels by
    default). ValueError if the images differ in size or the labels in number."""
    from PIL import Image, ImageDraw

    labels = [r.label for r in RUNGS] if labels is None else list(labels)
    if not images or len(labels) != len(images):
        raise ValueError(f"labels: expected one per image ({len(images)}), got {len(labels)}")
    width, height = images[0].width, images[0].height
    if any((im.width, im.height) != (width, height) for im in images):
        raise ValueError("images: expected images of one size")
    n, dark = len(images), (24, 24, 24)
    strip = Image.new("RGB", (n * width + (n - 1) * GAP, LABEL_HEIGHT + height), dark)
    font = _font(LABEL_HEIGHT - 8)
    for k, (image, label) in enumerate(zip(images, labels, strict=True)):
        x = k * (width + GAP)
        band = Image.new("RGB", (width, LABEL_HEIGHT), dark)  # a long label is cut at its panel
        ImageDraw.Draw(band).text((4, 4), label, fill=(235, 235, 235), font=font)
        strip.paste(band, (x, 0))
        strip.paste(image.pil, (x, LABEL_HEIGHT))
    return strip


def write_ladder(path: str | Path, images: list[RenderedImage]) -> Path:
    """Write ladder_strip(images) to path (.png or .jpg), atomically; returns the path.
    OutputError for another extension, WriteError when the write fails."""
    from ..engine.files import atomic_write, extension_of
    from .image import check_image_path

    p = check_image_path(path)
    strip = ladder_strip(images)
    fmt = "JPEG" if extension_of(p) in (".jpg", ".jpeg") else "PNG"
    return atomic_write(p, lambda tmp: strip.save(tmp, format=fmt))
