"""rtpy.engine.writer: the core writes images through the writers registered with it, and
says what to import when none is."""

from __future__ import annotations

import pytest

from rtpy.engine import writer as writer_module
from rtpy.engine.writer import WRITER_KINDS, WRITERS, register_writer, writer


@pytest.fixture
def saved_writers():
    saved = dict(WRITERS)
    yield
    WRITERS.clear()
    WRITERS.update(saved)


def test_a_registered_writer_is_the_one_the_core_calls(saved_writers):
    @register_writer("image")
    def fake(path, linear, gamma):
        return path

    assert writer("image") is fake and writer("image")("x.png", None, 2.0) == "x.png"


def test_without_a_writer_the_error_says_what_registers_one(saved_writers):
    WRITERS.pop("preview", None)
    with pytest.raises(RuntimeError, match=r"^no preview writer is registered: import rtpy\.io"):
        writer("preview")


def test_only_the_kinds_the_core_calls_can_be_registered():
    with pytest.raises(ValueError, match="no writer kind 'video': one of image, preview"):
        register_writer("video")
    assert set(WRITER_KINDS) == {"image", "preview"} and writer_module.__all__
