"""Writing rendered images to disk.

Conventions used throughout rtpy:

* A rendered image is an ``(H, W, 3)`` float array of **linear** RGB radiance.
  Row 0 is the **top** of the image and column 0 is the **left**, so pixel
  ``(0, 0)`` is the top-left corner (the same as PIL and most image viewers).
* The display transform is applied **only** when producing 8-bit display output
  (``.png``, ``.jpg``, ``.jpeg``): either a power law ``x ** (1 / gamma)`` (the
  course's gamma 2.0 is the default) or ``gamma = "srgb"``, the sRGB curve. A PNG
  records which: an ``sRGB`` chunk for "srgb", a ``gAMA`` chunk (1 / gamma)
  otherwise. Linear output (``.npy``, ``.pfm``, ``.exr``) is never encoded: it
  stores the radiance values exactly as rendered, unclamped.
* ``.exr`` output needs the optional OpenEXR package (``pip install 'rtpy[exr]'``).
* Every file is written atomically (rtpy.engine.files.atomic_write): a crash or Ctrl-C
  never leaves a half-written output file behind.
* Output paths can (and should) be checked with :func:`check_image_path` or
  :func:`check_linear_path` *before* a long render starts, so that a typo in a
  directory name is reported in a second instead of after an hour of rendering.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from PIL import Image

from ..engine.display import Gamma, as_rgb, linear_to_srgb, png_info, to_8bit
from ..engine.files import (  # the file helpers, importable from here too
    OutputError,
    StrPath,
    WriteError,
    atomic_write,
    check_writable,
    extension_error,
    extension_of,
)
from ..engine.user_files import read_bytes

__all__ = [
    "EXR_INSTALL",
    "IMAGE_EXTENSIONS",
    "LINEAR_EXTENSIONS",
    "OUTPUT_EXTENSIONS",
    "OutputError",
    "WriteError",
    "atomic_write",
    "check_image_path",
    "check_linear_path",
    "check_writable",
    "linear_to_srgb",
    "png_info",
    "read_pfm",
    "to_8bit",
    "write_exr",
    "write_image",
    "write_linear",
    "write_npy",
    "write_pfm",
    "write_png",
]

#: Extensions for 8-bit, gamma-encoded display output.
IMAGE_EXTENSIONS: tuple[str, ...] = (".png", ".jpg", ".jpeg")
#: Extensions for linear (never gamma-encoded) floating-point output.
LINEAR_EXTENSIONS: tuple[str, ...] = (".npy", ".pfm", ".exr")
#: How to get what .exr output needs.
EXR_INSTALL = "pip install 'rtpy[exr]'"
#: Every extension :func:`write_image` understands.
OUTPUT_EXTENSIONS: tuple[str, ...] = IMAGE_EXTENSIONS + LINEAR_EXTENSIONS

_PIL_FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG"}
_JPEG_QUALITY = 95


def check_image_path(path: StrPath) -> Path:
    """:func:`check_writable` for 8-bit display output (``.png``, ``.jpg``, ``.jpeg``)."""
    return check_writable(path, IMAGE_EXTENSIONS, "8-bit image output")


def check_linear_path(path: StrPath) -> Path:
    """:func:`check_writable` for linear float output (``.npy``, ``.pfm``, ``.exr``);
    for ``.exr`` also that the OpenEXR package is installed."""
    p = check_writable(path, LINEAR_EXTENSIONS, "linear output")
    if extension_of(p) == ".exr":
        _openexr(p)
    return p


def _openexr(path: Path):
    """The OpenEXR module, or OutputError saying how to install it."""
    try:
        import OpenEXR
    except ImportError:
        raise OutputError(
            f"cannot write '{os.fspath(path)}': .exr output needs the OpenEXR package "
            f"({EXR_INSTALL})"
        ) from None
    return OpenEXR


# --------------------------------------------------------------------------- writers


def write_png(path: StrPath, linear: np.ndarray, gamma: Gamma) -> Path:
    """Write 8-bit display output, encoded with ``gamma`` (see :func:`to_8bit`).

    The format follows the extension: ``.png`` is written as PNG with the chunk
    that records the transform (:func:`png_info`), ``.jpg`` and ``.jpeg`` as
    JPEG (quality 95).
    """
    p = check_image_path(path)
    pil = Image.fromarray(to_8bit(linear, gamma))
    fmt = _PIL_FORMATS[extension_of(p)]
    if fmt == "JPEG":
        options = {"quality": _JPEG_QUALITY}
    else:
        options = {"pnginfo": png_info(gamma)}

    def write(tmp: Path) -> None:
        pil.save(tmp, format=fmt, **options)

    return atomic_write(p, write)


def write_npy(path: StrPath, linear: np.ndarray) -> Path:
    """Write the linear ``(H, W, 3)`` array as ``.npy``, keeping its dtype (not gamma-encoded)."""
    p = check_writable(path, (".npy",), "NumPy output")
    arr = as_rgb(linear)

    def write(tmp: Path) -> None:
        # Save through a file object: np.save(path) would append ".npy" to the temp name.
        with open(tmp, "wb") as f:
            np.save(f, arr, allow_pickle=False)

    return atomic_write(p, write)


def _pfm_bytes(linear: np.ndarray) -> bytes:
    arr = as_rgb(linear)
    h, w, _ = arr.shape
    header = b"PF\n" + f"{w} {h}\n".encode("ascii") + b"-1.0\n"
    # PFM stores rows from the bottom of the image to the top; "-1.0" = little-endian.
    data = np.ascontiguousarray(arr[::-1], dtype="<f4")
    return header + data.tobytes()


def write_pfm(path: StrPath, linear: np.ndarray) -> Path:
    """Write the linear image as a Portable Float Map (float32, not gamma-encoded).

    The file is ``PF\\n``, ``"{W} {H}\\n"``, ``"-1.0\\n"`` (a negative scale
    means little-endian) and then little-endian float32 RGB rows from the
    bottom row of the image to the top row.
    """
    p = check_writable(path, (".pfm",), "PFM output")
    data = _pfm_bytes(linear)
    return atomic_write(p, lambda tmp: tmp.write_bytes(data))


def write_exr(path: StrPath, linear: np.ndarray) -> Path:
    """Write the linear image as OpenEXR: float32 R, G, B channels, ZIP compression,
    not gamma-encoded. Needs the OpenEXR package (OutputError says how to install it)."""
    p = check_writable(path, (".exr",), "OpenEXR output")
    openexr = _openexr(p)
    arr = np.ascontiguousarray(as_rgb(linear), dtype=np.float32)
    header = {"compression": openexr.ZIP_COMPRESSION, "type": openexr.scanlineimage}

    def write(tmp: Path) -> None:
        try:
            with openexr.File(header, {"RGB": arr}) as f:
                f.write(str(tmp))
        except RuntimeError as err:  # how OpenEXR reports a failed write
            raise OSError(str(err)) from err

    return atomic_write(p, write)


def write_linear(path: StrPath, linear: np.ndarray) -> Path:
    """Write linear output (never gamma-encoded): ``.npy``, ``.pfm`` or ``.exr`` by extension."""
    p = check_linear_path(path)
    if extension_of(p) == ".npy":
        return write_npy(p, linear)
    if extension_of(p) == ".exr":
        return write_exr(p, linear)
    return write_pfm(p, linear)


def read_pfm(path: StrPath) -> np.ndarray:
    """Read a Portable Float Map into an ``(H, W, 3)`` float32 array, top row first.

    Handles both byte orders (by the sign of the scale) and greyscale ``Pf``
    files (replicated to three channels). Raises ``ValueError`` if the file is
    not a valid PFM, OSError if it cannot be read (a FIFO or a device is refused).
    """
    raw = read_bytes(path)  # a regular file (rtpy.engine.user_files)

    def bad(what: str) -> ValueError:
        return ValueError(f"'{os.fspath(path)}' is not a valid PFM file: {what}")

    tokens: list[bytes] = []
    pos = 0
    while len(tokens) < 4:
        while pos < len(raw) and raw[pos : pos + 1].isspace():
            pos += 1
        start = pos
        while pos < len(raw) and not raw[pos : pos + 1].isspace():
            pos += 1
        if start == pos:
            raise bad("truncated header")
        tokens.append(raw[start:pos])
    if pos >= len(raw):
        raise bad("no pixel data")
    pos += 1  # exactly one whitespace byte separates the header from the data

    magic, w_tok, h_tok, scale_tok = tokens
    if magic not in (b"PF", b"Pf"):
        raise bad(f"magic is {magic!r}, expected b'PF' or b'Pf'")
    channels = 3 if magic == b"PF" else 1
    try:
        width, height, scale = int(w_tok), int(h_tok), float(scale_tok)
    except ValueError:
        raise bad("malformed size or scale") from None
    if width <= 0 or height <= 0:
        raise bad(f"size {width}x{height}")
    if scale == 0.0 or not np.isfinite(scale):
        raise bad(f"scale {scale}")

    count = width * height * channels
    if len(raw) - pos < count * 4:
        raise bad(f"expected {count * 4} bytes of pixel data, found {len(raw) - pos}")
    dtype = np.dtype("<f4") if scale < 0 else np.dtype(">f4")
    data = np.frombuffer(raw, dtype=dtype, count=count, offset=pos)
    img = data.reshape(height, width, channels)[::-1].astype(np.float32)  # bottom-up -> top-down
    if channels == 1:
        img = np.repeat(img, 3, axis=2)
    return np.ascontiguousarray(img)


def write_image(path: StrPath, linear: np.ndarray, gamma: Gamma) -> Path:
    """Write by extension and return the path written: .png/.jpg/.jpeg 8-bit, encoded
    with ``gamma``; .npy/.pfm/.exr linear, never encoded. Any other extension raises
    :class:`OutputError`, a failing write :class:`WriteError` (the file that was there
    is untouched)."""
    ext = extension_of(Path(path))
    if ext in IMAGE_EXTENSIONS:
        return write_png(path, linear, gamma)
    if ext in LINEAR_EXTENSIONS:
        return write_linear(path, linear)
    raise extension_error(path, OUTPUT_EXTENSIONS, "image output")
