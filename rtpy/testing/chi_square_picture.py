"""A picture of a chi-square test of scattering() against pdf(): what a student looks
at when the numbers of a failed check say little.

chi2_picture writes one PNG (pillow only) with, left to right: the observed counts
per bin over the sphere of directions, the counts pdf() expects, both on one colour
scale, and their difference in standard deviations, (observed - expected) /
sqrt(expected), blue where too few samples fell, red where too many; rows are the
equal-area bins of cos(theta) from the normal (top) to the far side (bottom),
columns phi from 0 to 360 degrees (the viewer is at phi = 0, so a mirror lobe lies
at phi = 180). Given the material, a last panel is a polar plot in the plane of
incidence: BRDF * cos and pdf() over the directions of the upper hemisphere, each
scaled to its own maximum (for a good sampler the two curves have the same shape),
with the viewer's direction as a grey line.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .chi_square import Chi2Result
from .local_setup import local_direction

__all__ = ["chi2_picture"]

# Colour maps: a perceptual ramp for counts, a diverging one for the difference.
RAMP = np.array([(68, 1, 84), (59, 82, 139), (33, 145, 140), (94, 201, 98), (253, 231, 37)])
DIVERGING = np.array([(33, 102, 172), (247, 247, 247), (178, 24, 43)])
LIMIT = 5.0  # the difference's colour saturates at this many standard deviations
PANEL = 320  # width of a histogram panel in pixels
TITLE = 18  # height of a panel's title
MARGIN = 10
BRDF_COLOR, PDF_COLOR, GREY = (230, 120, 20), (40, 90, 200), (150, 150, 150)


def _colors(values: np.ndarray, ramp: np.ndarray) -> np.ndarray:
    """RGB (uint8) of values in [0, 1], interpolated along the ramp's anchors."""
    x = np.clip(values, 0.0, 1.0) * (len(ramp) - 1)
    k = np.minimum(x.astype(int), len(ramp) - 2)
    t = (x - k)[..., None]
    return (ramp[k] * (1 - t) + ramp[k + 1] * t).round().astype(np.uint8)


def _heatmap(rgb: np.ndarray, width: int):
    """A bins image scaled up to `width` pixels, each bin a block of pixels."""
    from PIL import Image

    rows, columns = rgb.shape[:2]
    cell = max(1, width // columns)
    return Image.fromarray(rgb, "RGB").resize((columns * cell, rows * cell), Image.NEAREST)


def _panels(result: Chi2Result) -> list[tuple[str, object]]:
    observed, expected = result.observed, result.expected
    top = max(float(observed.max()), float(expected.max()), 1e-12)
    counts = [_heatmap(_colors(a / top, RAMP), PANEL) for a in (observed, expected)]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(expected > 0, (observed - expected) / np.sqrt(expected), 0.0)
    z = np.where((expected <= 0) & (observed > 0), LIMIT, z)  # samples where pdf() is 0
    return [
        (f"observed (max {observed.max():.0f})", counts[0]),
        (f"expected from pdf() (max {expected.max():.0f})", counts[1]),
        (
            f"difference in std devs (+-{LIMIT:g})",
            _heatmap(_colors((z / LIMIT + 1) / 2, DIVERGING), PANEL),
        ),
    ]  # fmt: skip


def _polar(subject, incident_deg: float, phi_deg: float, inside: bool, size: int):
    """The plane of incidence: BRDF * cos and pdf() over the upper half, polar."""
    from PIL import Image, ImageDraw

    image = Image.new("RGB", (size, size // 2 + 20), "white")
    draw = ImageDraw.Draw(image)
    cx, cy, radius = size // 2, size // 2 + 5, size // 2 - 10
    angles = np.radians(np.linspace(-89.5, 89.5, 359))
    phi = math.radians(phi_deg)
    # wi at signed angle t from the normal in the plane of the viewer (phi_deg)
    wi = np.column_stack(
        [np.sin(angles) * math.cos(phi), np.sin(angles) * math.sin(phi), np.cos(angles)]
    )
    wo = np.broadcast_to(local_direction(incident_deg, phi_deg).tolist(), wi.shape)
    f_cos = np.asarray(subject.brdf(wo, wi, inside=inside), float).mean(axis=1) * wi[:, 2]
    pdf = np.asarray(subject.pdf(wo, wi, inside=inside), float)
    draw.arc([cx - radius, cy - radius, cx + radius, cy + radius], 180, 360, fill=GREY)
    draw.line([cx - radius, cy, cx + radius, cy], fill=GREY)
    t = math.radians(incident_deg)
    draw.line([cx, cy, cx + radius * math.sin(t), cy - radius * math.cos(t)], fill=GREY, width=2)
    for values, color in ((f_cos, BRDF_COLOR), (pdf, PDF_COLOR)):
        values = np.where(np.isfinite(values), np.maximum(values, 0.0), 0.0)
        top = values.max()
        if top <= 0:
            continue
        r = radius * values / top
        points = list(
            zip((cx + r * np.sin(angles)).tolist(), (cy - r * np.cos(angles)).tolist(), strict=True)
        )
        draw.line(points, fill=color, width=2)
    draw.text((4, cy + 4), "BRDF*cos", fill=BRDF_COLOR)
    draw.text((size - 40, cy + 4), "pdf()", fill=PDF_COLOR)
    return image


def chi2_picture(
    result: Chi2Result,
    path: str | Path,
    incident_deg: float,
    subject=None,
    phi_deg: float = 0.0,
    inside: bool = False,
    title: str = "",
) -> Path:
    """Write the picture of a chi-square test (see the module's docstring) to `path`, a
    PNG, and return it. subject: the material tested (an rtpy Material or a
    MaterialSubject) for the polar plot in the plane of incidence; None: no plot."""
    from PIL import Image, ImageDraw

    from .subject import as_subject

    panels = _panels(result)
    if subject is not None:
        polar = _polar(as_subject(subject), incident_deg, phi_deg, inside, PANEL)
        panels.append(("plane of incidence, each scaled to its max", polar))
    width = sum(p.width for _, p in panels) + MARGIN * (len(panels) + 1)
    height = max(p.height for _, p in panels) + 2 * TITLE + 2 * MARGIN
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    heading = title or "scattering() against pdf()"
    heading += f" at {incident_deg:g} degrees: p = {result.p_value:.2g}"
    draw.text((MARGIN, 2), heading, fill="black")
    x = MARGIN
    for label, panel in panels:
        draw.text((x, TITLE + 2), label, fill="black")
        image.paste(panel, (x, 2 * TITLE + MARGIN // 2))
        x += panel.width + MARGIN
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    image.save(path, format="PNG")
    return path
