"""Reading the files a user names: meshes, resume states, cached arrays, plugins.

A path may name anything: a FIFO (opening it waits for a writer, forever), a device
such as /dev/zero (endless), a directory, or a damaged file whose header declares an
array of a billion gigabytes. Every read of such a file goes through here:

* open_regular opens regular files only, without waiting (a FIFO is refused at once:
  NotAFileError, an OSError whose strerror says what the path is);
* read_bytes reads at most the size the file had when opened (and at most `limit`
  bytes, FileTooLargeError beyond), so a growing or endless file cannot exhaust memory;
* read_array reads one .npy array (a file, or a member of an .npz) after checking its
  header against the bytes that are really there, so a damaged or crafted header is a
  ValueError, never a huge allocation.
"""

from __future__ import annotations

import errno
import math
import os
import stat
import zipfile
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

from .files import StrPath

if TYPE_CHECKING:
    import numpy as np

__all__ = [
    "FileTooLargeError",
    "NotAFileError",
    "load_npy",
    "open_regular",
    "read_array",
    "read_arrays",
    "read_bytes",
    "read_text",
]


class NotAFileError(OSError):
    """The path names something other than a regular file (a FIFO, a device, a socket)."""


class FileTooLargeError(OSError):
    """The file holds more bytes than the reader takes."""


def _kind(mode: int) -> str:
    """What a file of st_mode `mode` is, for a message."""
    for test, name in (
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a regular file"


def _refuse(path: StrPath, mode: int) -> OSError:
    if stat.S_ISDIR(mode):
        return IsADirectoryError(errno.EISDIR, "it is a directory", os.fspath(path))
    kind = _kind(mode)
    what = kind if kind.startswith("not") else f"it is {kind}, not a regular file"
    return NotAFileError(errno.EINVAL, what, os.fspath(path))


def open_regular(path: StrPath) -> BinaryIO:
    """The regular file at `path`, open for reading in binary. OSError as open()'s when
    it cannot be opened; IsADirectoryError for a directory and NotAFileError for any
    other kind of file, without opening it (a FIFO would wait) or reading it."""
    mode = os.stat(path).st_mode
    if not stat.S_ISREG(mode):
        raise _refuse(path, mode)
    # O_NONBLOCK: a FIFO put in the file's place since the stat does not make open wait.
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise _refuse(path, mode)
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def _read_open(f: BinaryIO, path: StrPath, limit: int | None) -> bytes:
    size = os.fstat(f.fileno()).st_size
    if limit is not None and size > limit:
        raise FileTooLargeError(
            errno.EFBIG, f"it has {size} bytes, the most read is {limit}", os.fspath(path)
        )
    try:
        return f.read(size)
    except MemoryError:  # (the buffer is allocated before anything is read)
        raise FileTooLargeError(
            errno.ENOMEM, f"it has {size} bytes, more than the memory free", os.fspath(path)
        ) from None


def read_bytes(path: StrPath, limit: int | None = None) -> bytes:
    """The bytes of the regular file at `path` (open_regular's errors): as many as its
    size when opened, FileTooLargeError when that is more than `limit`."""
    with open_regular(path) as f:
        return _read_open(f, path, limit)


def read_text(path: StrPath, limit: int | None = None) -> str:
    """read_bytes as UTF-8 text (UnicodeDecodeError, a ValueError, if it is not)."""
    return read_bytes(path, limit).decode("utf-8")


def read_array(f: BinaryIO, size: int, name: str = "array") -> np.ndarray:
    """The .npy array in the file object `f` of `size` bytes from where it stands: its
    header checked first (a numeric or string dtype, not an object; a shape whose bytes
    are exactly those that follow), so that a damaged header is a ValueError naming
    `name` rather than an allocation of what it declares. EOFError is a ValueError too."""
    import numpy as np  # (not at import: plugins are read without numpy)

    fmt = np.lib.format
    try:
        version = fmt.read_magic(f)
        read_header = fmt.read_array_header_1_0 if version == (1, 0) else fmt.read_array_header_2_0
        shape, fortran, dtype = read_header(f)
    except (ValueError, EOFError, OSError, SyntaxError, TypeError) as err:
        raise ValueError(f"{name}: not an array file ({err})") from None
    if dtype.hasobject or dtype.itemsize == 0:
        raise ValueError(f"{name}: holds {dtype}, not numbers")
    count = math.prod(shape)
    expected = count * dtype.itemsize
    left = size - f.tell() if hasattr(f, "tell") else size
    if expected != left:
        raise ValueError(f"{name}: its header declares {expected} bytes of data, it has {left}")
    data = bytearray(f.read(expected))
    if len(data) != expected:
        raise ValueError(f"{name}: it ends after {len(data)} of {expected} bytes")
    array = np.frombuffer(data, dtype=dtype, count=count)
    return array.reshape(shape, order="F" if fortran else "C")


def read_arrays(path: StrPath, names: tuple[str, ...], limit: int) -> dict[str, np.ndarray]:
    """The arrays `names` of the .npz file at `path` (open_regular's errors; at most
    `limit` bytes of data each, as its zip says): ValueError for a damaged or crafted
    file (not a zip, a member missing, a header that lies)."""
    with open_regular(path) as f:
        try:
            archive = zipfile.ZipFile(f)
        except (zipfile.BadZipFile, EOFError) as err:
            raise ValueError(f"not an .npz file ({err})") from None
        with archive:
            arrays = {}
            for name in names:
                try:
                    info = archive.getinfo(f"{name}.npy")
                except KeyError:
                    raise ValueError(f"it has no array {name!r}") from None
                if info.file_size > limit:
                    raise ValueError(f"{name}: {info.file_size} bytes, the most read is {limit}")
                try:
                    with archive.open(info) as member:
                        arrays[name] = read_array(member, info.file_size, name)
                except (zipfile.BadZipFile, EOFError, NotImplementedError) as err:
                    raise ValueError(f"{name}: damaged ({err})") from None
            return arrays


def load_npy(path: Path, limit: int | None = None) -> np.ndarray:
    """The array of the .npy file at `path` (read_array's checks; FileTooLargeError
    beyond `limit` bytes)."""
    with open_regular(path) as f:
        size = os.fstat(f.fileno()).st_size
        if limit is not None and size > limit:
            raise FileTooLargeError(errno.EFBIG, f"it has {size} bytes", os.fspath(path))
        return read_array(f, size, path.name)
