"""The display transform: linear radiance to the 8-bit values of PNG and JPEG output.

A transform (Gamma) is a gamma > 0, encoding x ** (1 / gamma) (the course's 2.0 is
rtpy's default), or "srgb", the sRGB curve. A PNG records which one it used: an
sRGB chunk, or a gAMA chunk holding 1 / gamma.
"""

from __future__ import annotations

import struct

import numpy as np
from PIL import PngImagePlugin

__all__ = ["Gamma", "as_rgb", "check_gamma", "linear_to_srgb", "png_info", "to_8bit"]

#: A display transform: a gamma > 0 (x ** (1 / gamma)) or "srgb".
Gamma = float | str


def as_rgb(linear: np.ndarray, name: str = "linear") -> np.ndarray:
    """The image as an array, or ValueError (naming `name`) unless it is (H, W, 3), not empty."""
    arr = np.asarray(linear)
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise ValueError(f"{name} must have shape (H, W, 3), got {arr.shape}")
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise ValueError(f"{name} must not be empty, got shape {arr.shape}")
    return arr


def check_gamma(gamma: Gamma) -> Gamma:
    """The transform as rtpy uses it ("srgb" or a float), or TypeError/ValueError naming gamma."""
    if gamma == "srgb":
        return gamma
    if isinstance(gamma, str | bool):
        raise TypeError(f'gamma must be a positive number or "srgb", got {gamma!r}')
    gamma = float(gamma)
    if not (np.isfinite(gamma) and gamma > 0.0):
        raise ValueError(f"gamma must be a positive finite number, got {gamma!r}")
    return gamma


def linear_to_srgb(x: np.ndarray) -> np.ndarray:
    """The sRGB transfer curve (IEC 61966-2-1) for linear values in [0, 1]: linear
    below 0.0031308, then 1.055 x^(1/2.4) - 0.055 (rtpy.texture.srgb_to_linear inverted)."""
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def to_8bit(linear: np.ndarray, gamma: Gamma) -> np.ndarray:
    """Convert an ``(H, W, 3)`` linear RGB image to ``uint8`` for display.

    Values are clamped to ``[0, 1]`` (NaN counts as 0, +inf as 1), encoded
    with ``x ** (1 / gamma)`` (``gamma == 1`` means no encoding) or, for
    ``gamma == "srgb"``, the sRGB curve (:func:`linear_to_srgb`), scaled by
    255 and rounded to the nearest integer (halves round up).
    """
    gamma = check_gamma(gamma)
    x = np.array(as_rgb(linear), dtype=np.float64)  # a copy: the input is never modified
    x[np.isnan(x)] = 0.0
    np.clip(x, 0.0, 1.0, out=x)
    if gamma == "srgb":
        x = linear_to_srgb(x)
    elif gamma != 1.0:
        np.power(x, 1.0 / gamma, out=x)
    return np.floor(x * 255.0 + 0.5).astype(np.uint8)


# A PNG integer is 1 to 2^31 - 1 in a gAMA chunk (0 is invalid).
PNG_INTEGER_MAX = 2**31 - 1


def png_info(gamma: Gamma) -> PngImagePlugin.PngInfo:
    """The PNG chunks that record a display transform: sRGB (rendering intent 0,
    perceptual) for "srgb", else gAMA, the file's gamma 1 / gamma times 100000, when
    that is a PNG integer (for a gamma from about 4.7e-5 to 1e5); beyond, no chunk (the
    pixels are encoded all the same; a viewer assumes its default)."""
    gamma = check_gamma(gamma)
    info = PngImagePlugin.PngInfo()
    if gamma == "srgb":
        info.add(b"sRGB", bytes([0]))
        return info
    recorded = 100000.0 / gamma  # inf for the smallest gammas
    if 1.0 <= recorded <= PNG_INTEGER_MAX:
        info.add(b"gAMA", struct.pack(">I", round(recorded)))
    return info
