"""Writing files so that none is ever half written, and checking before long work
that a path can be written.

* atomic_write writes a file by way of a temporary file beside it, renamed over
  the target once it is complete and on disk: a crash, Ctrl-C or a full disk
  leaves the target as it was (absent, or with its previous content).
* check_writable checks a path before the work that produces it starts, so that
  a typo in a folder's name is reported in a second, not after an hour of
  rendering.
* remove_temporary_files is for a process that must end at once (rtpy.engine.signals):
  the temporary files of the writes in progress are listed from the moment they
  exist.

Every error is an OutputError naming the path (WriteError once the work is done).
"""

from __future__ import annotations

import os
import secrets
import stat
from collections.abc import Callable, Collection
from pathlib import Path

__all__ = [
    "OutputError",
    "StrPath",
    "WriteError",
    "atomic_write",
    "check_writable",
    "extension_error",
    "extension_of",
    "remove_temporary_files",
]

StrPath = str | os.PathLike[str]


class OutputError(Exception):
    """An output file cannot be written; the message names the path and the problem."""


class WriteError(OutputError):
    """Writing an output failed once the work was done (disk full, file too large, I/O
    error); whatever was there before is untouched. ``errno`` is the OSError's."""

    def __init__(self, path: StrPath, err: OSError) -> None:
        super().__init__(f"cannot write '{os.fspath(path)}': {err.strerror or err}")
        self.errno = err.errno


def extension_of(path: Path) -> str:
    """The file extension, lower case (".png")."""
    return path.suffix.lower()


def _extension_list(extensions: Collection[str]) -> str:
    exts = list(extensions)
    if len(exts) == 1:
        return exts[0]
    return ", ".join(exts[:-1]) + " or " + exts[-1]


def extension_error(path: StrPath, allowed: Collection[str], role: str) -> OutputError:
    """The error for a path whose extension is not one of `allowed` (for `role` output)."""
    suffix = Path(path).suffix
    what = f"unsupported extension '{suffix}'" if suffix else "no file extension"
    return OutputError(
        f"cannot write '{os.fspath(path)}': {what} for {role} (use {_extension_list(allowed)})"
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
        if extension_of(p) not in allowed:
            raise extension_error(path, allowed, role)
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
