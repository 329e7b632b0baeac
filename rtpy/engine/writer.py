"""How the core writes what a render makes without naming a file format.

RenderedImage.save(path) calls the "image" writer, and rtpy.render turns its
preview= (a file name; True, a notebook) into a function of the image so far with
the "preview" writer. The file formats and the previews are rtpy.io's: rtpy.io.writers
registers them here, and the package imports it (rtpy/__init__.py), as
rtpy.engine.backends registers the backends with rtpy.engine.backend. So the core imports nothing
from the floor above, and a RenderedImage saves as it always has.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["WRITER_KINDS", "WRITERS", "register_writer", "writer"]

# The writers the core calls, by kind, and what each is called with.
WRITER_KINDS = {
    "image": "(path, linear, gamma) -> the Path written (RenderedImage.save)",
    "preview": "(preview, the scene's files) -> a function of the image, or None (rtpy.render)",
}
WRITERS: dict[str, Callable[..., Any]] = {}


def register_writer(kind: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """A decorator: the function is the writer of that kind (one of WRITER_KINDS)."""
    if kind not in WRITER_KINDS:
        raise ValueError(f"no writer kind {kind!r}: one of {', '.join(WRITER_KINDS)}")

    def register(fn: Callable[..., Any]) -> Callable[..., Any]:
        WRITERS[kind] = fn
        return fn

    return register


def writer(kind: str) -> Callable[..., Any]:
    """The registered writer of that kind; RuntimeError when none is."""
    try:
        return WRITERS[kind]
    except KeyError:
        raise RuntimeError(f"no {kind} writer is registered: import rtpy.io.writers") from None
