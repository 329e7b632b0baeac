"""Tests for rtpy.io.image: the file formats and the checks of output paths."""

from __future__ import annotations

import io
import os
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from rtpy.engine.rendered_image import RenderedImage
from rtpy.io.image import (
    OutputError,
    WriteError,
    check_image_path,
    check_linear_path,
    check_writable,
    read_pfm,
    to_8bit,
    write_linear,
    write_npy,
    write_pfm,
    write_png,
)

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def rgb(values: list[float]) -> np.ndarray:
    """A 1 x N image whose pixels are grey with the given values."""
    v = np.asarray(values, dtype=np.float64)
    return np.repeat(v[None, :, None], 3, axis=2)


def random_image(h: int, w: int, seed: int = 0) -> np.ndarray:
    """Distinct, un-rounded values in every pixel and channel, some outside [0, 1]."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.5, 4.0, size=(h, w, 3))


def listing(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir())


# --------------------------------------------------------------------------- PFM


@pytest.mark.parametrize("h, w", [(1, 1), (2, 3), (3, 2), (1, 5), (5, 1), (7, 4)])
def test_pfm_round_trip(tmp_path: Path, h: int, w: int) -> None:
    img = random_image(h, w, seed=h * 10 + w)
    path = tmp_path / "img.pfm"
    assert write_pfm(path, img) == path
    back = read_pfm(path)
    assert back.dtype == np.float32
    assert back.shape == (h, w, 3)
    assert np.array_equal(back, img.astype(np.float32))


def test_pfm_header_and_row_order(tmp_path: Path) -> None:
    h, w = 3, 5
    img = random_image(h, w, seed=1)
    path = tmp_path / "img.pfm"
    write_pfm(path, img)
    raw = path.read_bytes()
    header = b"PF\n5 3\n-1.0\n"
    assert raw[: len(header)] == header
    assert len(raw) == len(header) + h * w * 3 * 4
    data = np.frombuffer(raw[len(header) :], dtype="<f4").reshape(h, w, 3)
    # Row 0 in the file is the BOTTOM image row; the last file row is the top.
    assert np.array_equal(data[0], img[-1].astype(np.float32))
    assert np.array_equal(data[-1], img[0].astype(np.float32))
    assert np.array_equal(data[::-1], img.astype(np.float32))


def test_pfm_keeps_values_outside_0_1_and_no_gamma(tmp_path: Path) -> None:
    img = rgb([-2.0, 0.25, 1000.0])
    path = tmp_path / "hdr.pfm"
    write_pfm(path, img)
    assert read_pfm(path)[0, :, 0].tolist() == [-2.0, 0.25, 1000.0]


def test_read_pfm_big_endian(tmp_path: Path) -> None:
    img = random_image(2, 3, seed=2).astype(np.float32)
    path = tmp_path / "be.pfm"
    path.write_bytes(b"PF\n3 2\n1.0\n" + np.ascontiguousarray(img[::-1], dtype=">f4").tobytes())
    back = read_pfm(path)
    assert back.dtype == np.float32
    assert np.array_equal(back, img)


def test_read_pfm_greyscale(tmp_path: Path) -> None:
    grey = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]], dtype=np.float32)  # 3 rows, 2 cols
    path = tmp_path / "grey.pfm"
    path.write_bytes(b"Pf\n2 3\n-1.0\n" + grey[::-1].astype("<f4").tobytes())
    back = read_pfm(path)
    assert back.shape == (3, 2, 3)
    for c in range(3):
        assert np.array_equal(back[..., c], grey)


@pytest.mark.parametrize(
    "content",
    [
        b"P6\n1 1\n255\n\x00\x00\x00",  # not a PFM
        b"PF\n2 2\n-1.0\n" + b"\x00" * 12,  # truncated data
        b"PF\n2\n",  # truncated header
        b"PF\nx 2\n-1.0\n" + b"\x00" * 48,  # bad width
    ],
)
def test_read_pfm_rejects_invalid(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "bad.pfm"
    path.write_bytes(content)
    with pytest.raises(ValueError, match="bad.pfm"):
        read_pfm(path)


# --------------------------------------------------------------------------- npy / png / jpg


def test_npy_round_trip_keeps_float64(tmp_path: Path) -> None:
    img = random_image(3, 4, seed=3)
    path = tmp_path / "img.npy"
    write_npy(path, img)
    assert listing(tmp_path) == ["img.npy"]  # np.save did not add a second ".npy"
    back = np.load(path)
    assert back.dtype == np.float64
    assert back.shape == (3, 4, 3)
    assert np.array_equal(back, img)


def test_write_linear_dispatches_by_extension(tmp_path: Path) -> None:
    img = random_image(2, 3, seed=4)
    write_linear(tmp_path / "a.npy", img)
    write_linear(tmp_path / "b.PFM", img)
    assert np.array_equal(np.load(tmp_path / "a.npy"), img)
    assert (tmp_path / "b.PFM").read_bytes().startswith(b"PF\n3 2\n-1.0\n")
    assert np.array_equal(read_pfm(tmp_path / "b.PFM"), img.astype(np.float32))
    with pytest.raises(OutputError, match="c.png"):
        write_linear(tmp_path / "c.png", img)


@pytest.mark.parametrize("gamma", [1.0, 2.0, 2.2])
def test_png_round_trip(tmp_path: Path, gamma: float) -> None:
    img = random_image(3, 5, seed=5) / 4.0
    path = tmp_path / "img.png"
    write_png(path, img, gamma)
    with Image.open(path) as pil:
        assert pil.format == "PNG"
        assert pil.mode == "RGB"
        assert pil.size == (5, 3)
        back = np.asarray(pil)
    assert np.array_equal(back, to_8bit(img, gamma))


@pytest.mark.parametrize("name", ["img.jpg", "img.jpeg", "IMG.JPG"])
def test_jpeg_written_by_extension(tmp_path: Path, name: str) -> None:
    img = np.full((4, 6, 3), 0.25)
    path = tmp_path / name
    write_png(path, img, 2.0)
    with Image.open(path) as pil:
        assert pil.format == "JPEG"
        assert pil.size == (6, 4)
        back = np.asarray(pil).astype(int)
    assert np.all(np.abs(back - 128) <= 2)  # lossy, but a flat image survives closely


def test_write_png_rejects_linear_extension(tmp_path: Path) -> None:
    with pytest.raises(OutputError, match="img.pfm"):
        write_png(tmp_path / "img.pfm", rgb([0.5]), 2.0)
    assert listing(tmp_path) == []


class Boom(Exception):
    pass


def test_failed_write_png_leaves_no_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def fail(self: Image.Image, *args: object, **kwargs: object) -> None:
        raise Boom("encoder crashed")

    monkeypatch.setattr(Image.Image, "save", fail)
    with pytest.raises(Boom):
        write_png(tmp_path / "img.png", rgb([0.5]), 2.0)
    assert listing(tmp_path) == []


# --------------------------------------------------------------------------- path checks


def test_check_writable_good_paths(tmp_path: Path) -> None:
    assert check_image_path(tmp_path / "x.png") == tmp_path / "x.png"
    assert check_image_path(str(tmp_path / "x.JPEG")) == tmp_path / "x.JPEG"
    assert check_linear_path(tmp_path / "x.pfm") == tmp_path / "x.pfm"
    assert check_linear_path(tmp_path / "x.npy") == tmp_path / "x.npy"
    (tmp_path / "exists.png").write_bytes(b"old")
    assert check_image_path(tmp_path / "exists.png") == tmp_path / "exists.png"
    assert check_writable(tmp_path / "anything.xyz") == tmp_path / "anything.xyz"
    assert listing(tmp_path) == ["exists.png"]  # checking creates nothing


def test_check_writable_relative_path_in_cwd(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert check_image_path("x.png") == Path("x.png")


def test_check_writable_missing_directory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError) as info:
        check_image_path("out/x.png")
    assert str(info.value) == "cannot write 'out/x.png': directory 'out' does not exist"


def test_check_writable_parent_is_a_file(tmp_path: Path) -> None:
    (tmp_path / "notadir").write_bytes(b"")
    path = tmp_path / "notadir" / "x.png"
    with pytest.raises(OutputError, match="not a directory") as info:
        check_image_path(path)
    assert str(path) in str(info.value)


def test_check_writable_path_is_directory(tmp_path: Path) -> None:
    path = tmp_path / "render.png"
    path.mkdir()
    with pytest.raises(OutputError, match="directory") as info:
        check_image_path(path)
    assert str(path) in str(info.value)


@pytest.mark.parametrize(
    "check, name",
    [
        (check_image_path, "x.bmp"),
        (check_image_path, "x.pfm"),
        (check_image_path, "x"),
        (check_linear_path, "x.png"),
        (check_linear_path, "x.tiff"),
    ],
)
def test_check_writable_unsupported_extension(tmp_path: Path, check, name: str) -> None:
    path = tmp_path / name
    with pytest.raises(OutputError, match="extension") as info:
        check(path)
    assert str(path) in str(info.value)


def test_check_writable_not_writable(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Simulated, because permission bits do not stop root from writing.
    monkeypatch.setattr(os, "access", lambda *args, **kwargs: False)
    path = tmp_path / "x.png"
    with pytest.raises(OutputError, match="not writable") as info:
        check_image_path(path)
    assert str(path) in str(info.value)


@pytest.mark.skipif(
    os.name != "posix" or os.geteuid() == 0, reason="needs POSIX permissions, non-root"
)
def test_check_writable_read_only_directory(tmp_path: Path) -> None:
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        with pytest.raises(OutputError, match="not writable"):
            check_image_path(ro / "x.png")
    finally:
        ro.chmod(0o700)


# --------------------------------------------------------------------------- sRGB and PNG chunks


@pytest.mark.parametrize("gamma, info", [(2.0, {"gamma": 0.5}), (2.2, {"gamma": 0.45455})])
def test_png_records_its_gamma(tmp_path: Path, gamma: float, info: dict) -> None:
    write_png(tmp_path / "a.png", rgb([0.5]), gamma)
    with Image.open(tmp_path / "a.png") as pil:
        assert {k: pil.info[k] for k in ("gamma", "srgb") if k in pil.info} == info


def test_png_records_srgb(tmp_path: Path) -> None:
    result = RenderedImage(rgb([0.25, 0.5]), gamma="srgb")
    result.save(tmp_path / "a.png")
    for source in (tmp_path / "a.png", io.BytesIO(result._repr_png_())):
        with Image.open(source) as pil:
            assert pil.info.get("srgb") == 0 and "gamma" not in pil.info
            assert np.array_equal(np.asarray(pil), to_8bit(result.linear, "srgb"))


# --------------------------------------------------------------------------- OpenEXR


def test_exr_round_trip(tmp_path: Path) -> None:
    openexr = pytest.importorskip("OpenEXR")
    img = random_image(3, 5, seed=9)
    assert RenderedImage(img).save(tmp_path / "a.exr") == tmp_path / "a.exr"
    write_linear(tmp_path / "b.EXR", img)
    for name in ("a.exr", "b.EXR"):
        with openexr.File(str(tmp_path / name)) as f:
            back = f.channels()["RGB"].pixels
        np.testing.assert_array_equal(back, img.astype(np.float32))  # unclamped, no gamma
    assert listing(tmp_path) == ["a.exr", "b.EXR"]


def test_a_failed_exr_write_is_one_write_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """OpenEXR reports a failed write (disk full, I/O error) as a RuntimeError, not an
    OSError: it becomes the same one-line WriteError, and the existing file stays."""
    openexr = pytest.importorskip("OpenEXR")

    class FullDisk:
        def __init__(self, *args):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def write(self, path):
            Path(path).write_bytes(b"v/1\x01")  # the start of a file, as OpenEXR writes
            raise RuntimeError(f'Cannot write image file "{path}". No space left on device')

    out = tmp_path / "a.exr"
    out.write_bytes(b"before")
    monkeypatch.setattr(openexr, "File", FullDisk)
    with pytest.raises(WriteError) as info:
        write_linear(out, random_image(3, 5, seed=9))
    message = str(info.value)
    assert message.startswith(f"cannot write '{out}': ") and "No space left" in message
    assert "\n" not in message
    assert out.read_bytes() == b"before" and listing(tmp_path) == ["a.exr"]


def test_exr_without_openexr_says_how_to_install(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "OpenEXR", None)  # import OpenEXR fails
    for attempt in (check_linear_path, lambda p: RenderedImage(random_image(3, 5)).save(p)):
        with pytest.raises(OutputError) as info:
            attempt(tmp_path / "a.exr")
        message = str(info.value)
        assert "a.exr" in message and "pip install 'rtpy[exr]'" in message
        assert "\n" not in message
    assert listing(tmp_path) == []


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_read_pfm_refuses_a_fifo_at_once(tmp_path):
    from rtpy.engine.user_files import NotAFileError

    os.mkfifo(tmp_path / "x.pfm")
    with pytest.raises(NotAFileError, match="FIFO"):
        read_pfm(tmp_path / "x.pfm")
