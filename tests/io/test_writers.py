"""rtpy.io.writers: `import rtpy` registers rtpy.io's image formats and previews with
the core (rtpy.engine.writer), and loads them only when first used."""

from __future__ import annotations

import numpy as np

import rtpy
from rtpy.engine.writer import writer
from rtpy.io import writers
from rtpy.io.image import read_pfm

from ..commands import modules_imported_by


def test_import_rtpy_registers_rtpy_io_s_writers():
    assert rtpy._writers is writers
    assert writer("image") is writers.write_image
    assert writer("preview") is writers.preview_target


def test_the_image_writer_writes_by_extension(tmp_path):
    linear = np.full((2, 3, 3), 0.25)
    assert writers.write_image(tmp_path / "a.pfm", linear, 2.0) == tmp_path / "a.pfm"
    assert np.array_equal(read_pfm(tmp_path / "a.pfm"), linear)
    image = rtpy.RenderedImage(linear)
    assert image.save(tmp_path / "b.png") == tmp_path / "b.png"


def test_the_preview_writer_is_rtpy_io_preview_s(tmp_path):
    assert writers.preview_target(None) is None
    show = writers.preview_target(tmp_path / "p.png")
    show(rtpy.RenderedImage(np.zeros((2, 2, 3))))
    assert (tmp_path / "p.png").exists()


def test_registering_loads_neither_the_formats_nor_the_previews():
    loaded = modules_imported_by("import rtpy.io.writers")
    assert "rtpy.engine.writer" in loaded
    assert not loaded & {"rtpy.io.image", "rtpy.io.preview", "numpy", "PIL"}
