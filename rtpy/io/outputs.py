"""Output paths of a command, checked before any work starts: each one writable
(rtpy.io.image.check_writable), none of them one of the command's inputs or another
output, and output folders writable or creatable."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

from ..engine.files import OutputError, StrPath, check_writable

__all__ = ["check_folder", "check_output", "same_file"]


def same_file(a: StrPath, b: StrPath) -> bool:
    """a and b name one file. When both exist, os.path.samefile says (links, and names
    that differ in case on a case-insensitive file system); when one exists and the
    other not, they differ; when neither exists yet, they are one when they are in
    one folder and their names differ at most in case (one file on a case-insensitive
    file system)."""
    try:
        exists = os.path.exists(a), os.path.exists(b)
        if all(exists):
            return os.path.samefile(a, b)
        if any(exists):
            return False
        a, b = Path(a).absolute(), Path(b).absolute()
        return a.name.casefold() == b.name.casefold() and os.path.samefile(a.parent, b.parent)
    except (OSError, ValueError):
        return False


def check_output(
    path: StrPath,
    option: str,
    inputs: Iterable[StrPath] = (),
    others: Iterable[StrPath] = (),
    check: Callable[[StrPath], Path] = check_writable,
) -> Path:
    """check(path) (check_writable or a check for one kind of file), and OutputError
    naming `option` when path is one of `inputs` (files the command reads) or `others`
    (its other outputs), whatever its extension. Returns path as a Path."""
    p = check(path)
    for other in inputs:
        if same_file(p, other):
            raise OutputError(
                f"{option} {os.fspath(path)}: would overwrite {os.fspath(other)}, an input"
            )
    for other in others:
        if same_file(p, other):
            raise OutputError(f"{option} {os.fspath(path)}: it needs a file of its own")
    return p


def check_folder(path: StrPath, option: str) -> Path:
    """An output folder: an existing folder where a file can be created, or a path
    whose nearest existing ancestor is such a folder (the folder is created when
    the command writes). OutputError naming `option` otherwise."""
    p = Path(path)
    where = f"{option} {os.fspath(path)}"
    try:
        base = p.absolute()
        while not os.path.lexists(base) and base.parent != base:
            base = base.parent
        if not base.is_dir():
            raise OutputError(f"{where}: {base} is not a folder")
        with tempfile.TemporaryFile(dir=base):  # what writing there needs
            pass
    except OSError as e:
        raise OutputError(f"{where}: cannot write there ({e.strerror or e})") from None
    return p
