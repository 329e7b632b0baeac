"""rtpy.engine.user_files: regular files only, read without waiting on a FIFO, at most
their size, and arrays whose headers are checked before anything is allocated."""

from __future__ import annotations

import io
import os
import zipfile

import numpy as np
import pytest

from rtpy.engine.user_files import (
    FileTooLargeError,
    NotAFileError,
    load_npy,
    open_regular,
    read_array,
    read_arrays,
    read_bytes,
)

fifo_only = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")


@fifo_only
def test_a_fifo_is_refused_at_once_not_waited_on(tmp_path):
    fifo = tmp_path / "mesh.obj"
    os.mkfifo(fifo)  # no writer: opening it for reading in blocking mode would wait
    with pytest.raises(NotAFileError, match="FIFO") as caught:
        read_bytes(fifo)
    assert caught.value.filename == str(fifo)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_an_endless_device_is_refused_without_reading():
    with pytest.raises(NotAFileError, match="character device"):
        open_regular("/dev/zero")


def test_a_directory_is_refused_as_a_directory(tmp_path):
    with pytest.raises(IsADirectoryError):
        read_bytes(tmp_path)


def test_a_regular_file_is_read_whole_and_its_size_bounded(tmp_path):
    path = tmp_path / "a.bin"
    path.write_bytes(b"0123456789")
    assert read_bytes(path) == b"0123456789"
    assert read_bytes(path, limit=10) == b"0123456789"
    with pytest.raises(FileTooLargeError, match="10 bytes"):
        read_bytes(path, limit=9)


def npy_bytes(array) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def test_an_array_is_read_as_numpy_saved_it(tmp_path):
    for array in (np.arange(12.0).reshape(3, 4), np.asfortranarray(np.eye(3)), np.array("k")):
        data = npy_bytes(array)
        back = read_array(io.BytesIO(data), len(data))
        assert back.dtype == array.dtype and np.array_equal(back, array)
    path = tmp_path / "a.npy"
    np.save(path, np.arange(5))
    assert load_npy(path).tolist() == [0, 1, 2, 3, 4]


def header(shape, descr="<f8") -> bytes:
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buffer, {"descr": descr, "fortran_order": False, "shape": shape}
    )
    return buffer.getvalue()


@pytest.mark.parametrize(
    "data, why",
    [
        (b"", "not an array file"),
        (b"not an array", "not an array file"),
        (header((10**6, 10**6)), "declares 8000000000000 bytes"),
        (header((4,)) + b"\0" * 31, "declares 32 bytes of data, it has 31"),
        (header((2,), "|O"), "not numbers"),
    ],
    ids=["empty", "text", "huge shape", "one byte short", "objects"],
)
def test_a_damaged_or_crafted_header_is_a_value_error_not_an_allocation(data, why):
    with pytest.raises(ValueError, match=why):
        read_array(io.BytesIO(data), len(data), "sums")


def test_the_arrays_of_an_npz_are_read_checked(tmp_path):
    path = tmp_path / "state.npz"
    np.savez(path, sums=np.ones((2, 3)), key=np.array("{}"))
    arrays = read_arrays(path, ("sums", "key"), limit=1000)
    assert arrays["sums"].shape == (2, 3) and str(arrays["key"]) == "{}"
    with pytest.raises(ValueError, match="no array 'current'"):
        read_arrays(path, ("current",), limit=1000)
    with pytest.raises(ValueError, match="the most read is 10"):
        read_arrays(path, ("sums",), limit=10)
    crafted = tmp_path / "crafted.npz"
    with zipfile.ZipFile(crafted, "w") as z:
        z.writestr("sums.npy", header((10**5, 10**5, 4)))
    with pytest.raises(ValueError, match="declares"):
        read_arrays(crafted, ("sums",), limit=10**9)
    (tmp_path / "text.npz").write_text("not a zip")
    with pytest.raises(ValueError, match="not an .npz file"):
        read_arrays(tmp_path / "text.npz", ("sums",), limit=10)
