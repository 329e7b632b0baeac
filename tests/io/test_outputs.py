"""rtpy.io.outputs: an output that is an input or another output is refused whatever its
name looks like, and output folders are checked before any work."""

from __future__ import annotations

import errno
import os
import re
import sys
import tempfile

import pytest

from rtpy.io.image import OutputError, check_image_path
from rtpy.io.outputs import check_folder, check_output, same_file


def test_same_file_of_existing_files_follows_links_and_relative_paths(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.png").write_bytes(b"a")
    (tmp_path / "b.png").write_bytes(b"b")
    (tmp_path / "sub").mkdir()
    assert same_file(tmp_path / "a.png", "a.png")
    assert same_file("sub/../a.png", tmp_path / "a.png")
    assert not same_file(tmp_path / "a.png", tmp_path / "b.png")
    if hasattr(os, "symlink") and sys.platform != "win32":
        os.symlink(tmp_path / "a.png", tmp_path / "link.jpg")
        assert same_file(tmp_path / "link.jpg", "a.png")


def test_same_file_of_new_files_is_one_folder_and_one_name_up_to_case(tmp_path):
    """Two outputs not written yet: the same when a case-insensitive file system
    would make them one file; an existing file and a new one always differ."""
    (tmp_path / "sub").mkdir()
    assert same_file(tmp_path / "out.png", tmp_path / "sub" / ".." / "OUT.png")
    assert not same_file(tmp_path / "out.png", tmp_path / "sub" / "out.png")
    assert not same_file(tmp_path / "out.png", tmp_path / "out.jpg")
    (tmp_path / "old.png").write_bytes(b"")
    assert same_file(tmp_path / "old.png", tmp_path / "old.png")
    assert same_file(tmp_path / "old.png", tmp_path / "OLD.png") == os.path.exists(
        tmp_path / "OLD.png"
    )  # one file exactly when the file system finds it by the other case


@pytest.mark.parametrize("name", ["scene.png", "scene.toml", "SCENE.PNG"])
def test_an_input_is_refused_whatever_its_extension(tmp_path, name):
    scene = tmp_path / "scene.png"
    scene.write_text("[camera]\n")
    (tmp_path / "scene.toml").write_text("[camera]\n")
    target = tmp_path / name
    inputs = [tmp_path / "scene.toml", scene]
    if os.path.exists(target):  # SCENE.PNG on a case-sensitive file system is another file
        with pytest.raises(OutputError, match=r"^-o .*: would overwrite .*, an input$"):
            check_output(target, "-o", inputs)
    else:
        assert check_output(target, "-o", inputs) == target
    assert scene.read_text() == "[camera]\n"


def test_another_output_is_refused_and_the_check_is_applied(tmp_path):
    out = tmp_path / "out.png"
    with pytest.raises(OutputError, match="^--preview .*: it needs a file of its own$"):
        check_output(tmp_path / "OUT.png", "--preview", others=[out], check=check_image_path)
    with pytest.raises(OutputError, match="extension"):
        check_output(tmp_path / "out.npy", "--preview", check=check_image_path)
    assert check_output(out, "-o", check=check_image_path) == out
    assert list(tmp_path.iterdir()) == []


def test_a_folder_that_exists_or_can_be_made_is_accepted_and_not_made(tmp_path):
    assert check_folder(tmp_path, "--out") == tmp_path
    assert check_folder(tmp_path / "new" / "deeper", "--out") == tmp_path / "new" / "deeper"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("below", ["", "sub", "sub/deeper"])
def test_a_folder_at_or_under_a_file_is_refused_in_one_line(tmp_path, below):
    (tmp_path / "file").write_text("")
    path = tmp_path / "file" / below if below else tmp_path / "file"
    with pytest.raises(OutputError, match=r"^--out .*file.*: .*file is not a folder$") as e:
        check_folder(path, "--out")
    assert "\n" not in str(e.value)


def test_a_folder_where_no_file_can_be_made_is_refused(tmp_path, monkeypatch):
    """A read-only file system (as root every permission check passes, so only trying
    to create a file tells)."""

    def read_only(*args, **kwargs):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    monkeypatch.setattr(tempfile, "TemporaryFile", read_only)
    with pytest.raises(OutputError, match=re.escape(f"({os.strerror(errno.EROFS)})")):
        check_folder(tmp_path / "bench", "--out")


@pytest.mark.skipif(
    not hasattr(os, "geteuid") or os.geteuid() == 0, reason="needs POSIX permissions, non-root"
)
def test_a_read_only_folder_is_refused(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        with pytest.raises(OutputError, match="cannot write there"):
            check_folder(locked / "bench", "--out")
    finally:
        locked.chmod(0o700)
