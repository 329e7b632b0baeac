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
* Every file is written atomically: the data goes to a temporary file in the
  destination directory which is then renamed over the target, so a crash or
  Ctrl-C never leaves a half-written output file behind.
* Output paths can (and should) be checked with :func:`check_image_path` or
  :func:`check_linear_path` *before* a long render starts, so that a typo in a
  directory name is reported in a second instead of after an hour of rendering.
"""

from __future__ import annotations

import io
import os
import secrets
import stat
from collections.abc import Callable, Collection
from pathlib import Path

import numpy as np
from PIL import Image

from .display import Gamma, as_rgb, check_gamma, linear_to_srgb, png_info, to_8bit

__all__ = [
    "EXR_INSTALL",
    "IMAGE_EXTENSIONS",
    "LINEAR_EXTENSIONS",
    "OUTPUT_EXTENSIONS",
    "OutputError",
    "RenderedImage",
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
    "write_linear",
    "write_npy",
    "write_pfm",
    "write_png",
]

StrPath = str | os.PathLike[str]

#: Extensions for 8-bit, gamma-encoded display output.
IMAGE_EXTENSIONS: tuple[str, ...] = (".png", ".jpg", ".jpeg")
#: Extensions for linear (never gamma-encoded) floating-point output.
LINEAR_EXTENSIONS: tuple[str, ...] = (".npy", ".pfm", ".exr")
#: How to get what .exr output needs.
EXR_INSTALL = "pip install 'rtpy[exr]'"
#: Every extension :meth:`RenderedImage.save` understands.
OUTPUT_EXTENSIONS: tuple[str, ...] = IMAGE_EXTENSIONS + LINEAR_EXTENSIONS

_PIL_FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG"}
_JPEG_QUALITY = 95


class OutputError(Exception):
    """An output file cannot be written; the message names the path and the problem."""


class WriteError(OutputError):
    """Writing an output failed once the work was done (disk full, file too large, I/O
    error); whatever was there before is untouched. ``errno`` is the OSError's."""

    def __init__(self, path: StrPath, err: OSError) -> None:
        super().__init__(f"cannot write '{os.fspath(path)}': {err.strerror or err}")
        self.errno = err.errno


# --------------------------------------------------------------------------- path checks


def _ext(path: Path) -> str:
    return path.suffix.lower()


def _ext_list(extensions: Collection[str]) -> str:
    exts = list(extensions)
    if len(exts) == 1:
        return exts[0]
    return ", ".join(exts[:-1]) + " or " + exts[-1]


def _extension_error(path: StrPath, allowed: Collection[str], role: str) -> OutputError:
    suffix = Path(path).suffix
    what = f"unsupported extension '{suffix}'" if suffix else "no file extension"
    return OutputError(
        f"cannot write '{os.fspath(path)}': {what} for {role} (use {_ext_list(allowed)})"
    )


def check_writable(
    path: StrPath,
    extensions: Collection[str] | None = None,
    role: str = "output",
) -> Path:
    """Check that ``path`` can be written, before any expensive work is done.

    Raises :class:`OutputError` (naming the path) if the parent directory does
    not exist, is not a directory or is not writable, if ``path`` itself is an
    existing directory, or if ``extensions`` is given and the file extension
    (case-insensitive) is not one of them. ``role`` describes the kind of
    output in that last message. Returns ``path`` as a :class:`Path`.
    """
    p = Path(path)
    where = f"cannot write '{os.fspath(path)}'"
    if extensions is not None:
        allowed = tuple(e.lower() for e in extensions)
        if _ext(p) not in allowed:
            raise _extension_error(path, allowed, role)
    parent = p.parent
    try:
        if not parent.exists():
            raise OutputError(f"{where}: directory '{parent}' does not exist")
        if not parent.is_dir():
            raise OutputError(f"{where}: '{parent}' is not a directory")
        if not os.access(parent, os.W_OK | os.X_OK):
            raise OutputError(f"{where}: directory '{parent}' is not writable")
        if p.is_dir():
            raise OutputError(f"{where}: it is an existing directory")
        # What atomic_write will do (name too long, read-only file system, ...).
        tmp = _new_temporary_file(p)
        tmp.unlink()
        _temporary_files.discard(tmp)
    except OSError as e:
        raise OutputError(f"{where}: {e.strerror or e}") from None
    return p


# Temporary files of writes in progress, for a process that must exit at once.
_temporary_files: set[Path] = set()


def _new_temporary_file(target: Path) -> Path:
    """Create the empty temporary file atomic_write writes before renaming it to
    target, next to it (its name cut so that it is no longer than any name the file
    system takes). The name is listed in ``_temporary_files`` before the file exists,
    so that a signal at any moment finds every file it must remove."""
    while True:
        tmp = target.parent / f".{target.name[:200]}.{secrets.token_hex(4)}.tmp"
        _temporary_files.add(tmp)
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
            return tmp
        except FileExistsError:
            _temporary_files.discard(tmp)
        except OSError:  # not created (on a KeyboardInterrupt it may be: it stays listed)
            _temporary_files.discard(tmp)
            raise


def check_image_path(path: StrPath) -> Path:
    """:func:`check_writable` for 8-bit display output (``.png``, ``.jpg``, ``.jpeg``)."""
    return check_writable(path, IMAGE_EXTENSIONS, "8-bit image output")


def check_linear_path(path: StrPath) -> Path:
    """:func:`check_writable` for linear float output (``.npy``, ``.pfm``, ``.exr``);
    for ``.exr`` also that the OpenEXR package is installed."""
    p = check_writable(path, LINEAR_EXTENSIONS, "linear output")
    if _ext(p) == ".exr":
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


# --------------------------------------------------------------------------- atomic writes


def _new_file_mode() -> int:
    """Permission bits a newly created file would get (0o666 minus the umask)."""
    # os.umask can only be read by setting it; restore it immediately.
    umask = os.umask(0o022)
    os.umask(umask)
    return 0o666 & ~umask


def atomic_write(path: StrPath, write_fn: Callable[[Path], object]) -> Path:
    """Write ``path`` atomically by way of a temporary file in the same directory.

    ``write_fn(tmp_path)`` must write the complete file to ``tmp_path``; the
    temporary file is then renamed over ``path`` with :func:`os.replace`. If
    anything fails (including ``KeyboardInterrupt``) the temporary file is
    removed, the exception propagates (an OSError as :class:`WriteError`), and
    ``path`` is left untouched: either absent or with its previous content.
    Returns ``path`` as a :class:`Path`.
    """
    target = Path(path)
    try:
        # Existing targets keep their permissions; new ones get the usual umask-based
        # mode rather than the private 0o600 that tempfile uses.
        mode = stat.S_IMODE(os.stat(target).st_mode)
    except OSError:
        mode = _new_file_mode()
    try:
        tmp_path = _new_temporary_file(target)
    except OSError as err:
        raise WriteError(target, err) from err
    try:
        write_fn(tmp_path)
        with open(tmp_path, "rb+") as f:  # make sure the data is on disk before renaming
            os.fsync(f.fileno())
        os.chmod(tmp_path, mode)
        os.replace(tmp_path, target)
    except BaseException as err:
        tmp_path.unlink(missing_ok=True)
        if isinstance(err, OSError):
            raise WriteError(target, err) from err
        raise
    finally:
        _temporary_files.discard(tmp_path)
    return target


def remove_temporary_files() -> None:
    """Delete the temporary files of writes in progress (the targets are untouched).
    For a signal handler that ends the process without unwinding (os._exit)."""
    for path in list(_temporary_files):
        try:
            path.unlink(missing_ok=True)
        except OSError:
            pass


# --------------------------------------------------------------------------- writers


def write_png(path: StrPath, linear: np.ndarray, gamma: Gamma) -> Path:
    """Write 8-bit display output, encoded with ``gamma`` (see :func:`to_8bit`).

    The format follows the extension: ``.png`` is written as PNG with the chunk
    that records the transform (:func:`png_info`), ``.jpg`` and ``.jpeg`` as
    JPEG (quality 95).
    """
    p = check_image_path(path)
    pil = Image.fromarray(to_8bit(linear, gamma))
    fmt = _PIL_FORMATS[_ext(p)]
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
    if _ext(p) == ".npy":
        return write_npy(p, linear)
    if _ext(p) == ".exr":
        return write_exr(p, linear)
    return write_pfm(p, linear)


def read_pfm(path: StrPath) -> np.ndarray:
    """Read a Portable Float Map into an ``(H, W, 3)`` float32 array, top row first.

    Handles both byte orders (by the sign of the scale) and greyscale ``Pf``
    files (replicated to three channels). Raises ``ValueError`` if the file is
    not a valid PFM.
    """
    raw = Path(path).read_bytes()

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


# --------------------------------------------------------------------------- result object


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
        raises :class:`OutputError`, a failing write :class:`WriteError` (the file
        that was there is untouched).
        """
        ext = _ext(Path(path))
        if ext in IMAGE_EXTENSIONS:
            return write_png(path, self.linear, self.gamma)
        if ext in LINEAR_EXTENSIONS:
            return write_linear(path, self.linear)
        raise _extension_error(path, OUTPUT_EXTENSIONS, "image output")

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
