"""rtpy.engine.files: atomic writes (never a half-written file, whatever fails or signals)
and the check of a path before the work that writes it."""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

import pytest

from rtpy.engine import files
from rtpy.engine.files import OutputError, WriteError, atomic_write, check_writable


def listing(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir())


class Boom(Exception):
    pass


def test_atomic_write_success_uses_temp_in_same_dir(tmp_path: Path) -> None:
    target = tmp_path / "out.bin"
    seen: list[Path] = []

    def write(tmp: Path) -> None:
        seen.append(tmp)
        assert tmp.parent == tmp_path
        assert tmp.name.startswith(".out.bin.") and tmp.name.endswith(".tmp")
        assert not target.exists()  # the target only appears at the end
        tmp.write_bytes(b"hello")

    assert atomic_write(target, write) == target
    assert target.read_bytes() == b"hello"
    assert len(seen) == 1 and not seen[0].exists()
    assert listing(tmp_path) == ["out.bin"]


@pytest.mark.parametrize("exc", [Boom("disk full"), KeyboardInterrupt()])
def test_atomic_write_failure_leaves_no_file(tmp_path: Path, exc: BaseException) -> None:
    target = tmp_path / "out.png"

    def write(tmp: Path) -> None:
        tmp.write_bytes(b"half a PNG")
        raise exc

    with pytest.raises(type(exc)):
        atomic_write(target, write)
    assert not target.exists()
    assert listing(tmp_path) == []


def test_atomic_write_failure_keeps_old_content(tmp_path: Path) -> None:
    target = tmp_path / "out.png"
    target.write_bytes(b"old image")

    def write(tmp: Path) -> None:
        tmp.write_bytes(b"new, partial")
        raise Boom("crash")

    with pytest.raises(Boom):
        atomic_write(target, write)
    assert target.read_bytes() == b"old image"
    assert listing(tmp_path) == ["out.png"]


def test_atomic_write_replaces_existing(tmp_path: Path) -> None:
    target = tmp_path / "out.txt"
    target.write_bytes(b"old")
    atomic_write(target, lambda tmp: tmp.write_bytes(b"new"))
    assert target.read_bytes() == b"new"
    assert listing(tmp_path) == ["out.txt"]


@pytest.mark.parametrize(
    "code", [errno.ENOSPC, errno.EFBIG, errno.EIO, errno.EACCES, errno.EROFS, errno.ENAMETOOLONG]
)
def test_an_os_error_half_way_is_one_write_error_and_keeps_the_old_file(
    tmp_path: Path, code: int
) -> None:
    """A disk that fills (or any OSError) after some bytes are written: WriteError,
    one line naming the file and the reason, no temporary file, the old file as it was."""
    target = tmp_path / "out.png"
    target.write_bytes(b"old image")

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as f:
            f.write(b"new, partial")
            f.flush()
            raise OSError(code, os.strerror(code))

    with pytest.raises(WriteError) as info:
        atomic_write(target, write)
    assert str(info.value) == f"cannot write '{target}': {os.strerror(code)}"
    assert info.value.errno == code and isinstance(info.value, OutputError)
    assert target.read_bytes() == b"old image"
    assert listing(tmp_path) == ["out.png"]


def test_a_temporary_file_that_cannot_be_made_is_a_write_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def full(*args: object) -> int:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "open", full)
    with pytest.raises(WriteError, match="No space left on device|ENOSPC"):
        atomic_write(tmp_path / "out.npy", lambda tmp: None)
    assert listing(tmp_path) == []


def test_a_signal_as_the_temporary_file_appears_finds_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A second Ctrl-C removes the temporary files of writes in progress and exits;
    if it lands just after the temporary file is created, before atomic_write
    returns to Python code, that file must already be listed."""
    real_open = os.open

    def open_then_signal(path, flags, *args):
        fd = real_open(path, flags, *args)
        os.close(fd)
        files.remove_temporary_files()  # what the signal handler does before os._exit
        raise Boom("exited")

    monkeypatch.setattr(files.os, "open", open_then_signal)
    with pytest.raises(Boom):
        atomic_write(tmp_path / "out.npy", lambda tmp: tmp.write_bytes(b"data"))
    assert listing(tmp_path) == []


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
def test_atomic_write_file_mode(tmp_path: Path) -> None:
    old_umask = os.umask(0o022)
    try:
        new = tmp_path / "new.bin"
        atomic_write(new, lambda tmp: tmp.write_bytes(b"x"))
        # Not tempfile's private 0o600: a normal file for the current umask.
        assert stat.S_IMODE(new.stat().st_mode) == 0o644
        existing = tmp_path / "existing.bin"
        existing.write_bytes(b"old")
        existing.chmod(0o640)
        atomic_write(existing, lambda tmp: tmp.write_bytes(b"new"))
        assert stat.S_IMODE(existing.stat().st_mode) == 0o640
    finally:
        os.umask(old_umask)


def test_check_writable_names_the_extensions_it_takes(tmp_path: Path) -> None:
    assert check_writable(tmp_path / "state.npz") == tmp_path / "state.npz"
    with pytest.raises(OutputError, match=r"unsupported extension '\.txt' for notes \(use \.md\)"):
        check_writable(tmp_path / "a.txt", (".md",), "notes")
    with pytest.raises(OutputError, match="does not exist"):
        check_writable(tmp_path / "missing" / "a.npz")
    assert listing(tmp_path) == []
