"""docs/numpy-backend.md, "Formulas written once": the "Shapes and lights" table has a
row for every shape and light class the numpy backend mirrors, and each single
source it names exists."""

from __future__ import annotations

import importlib
import re

import rtpy.environment
import rtpy.light
from rtpy.numpy_backend.scene import KINDS

from .markdown import ROOT, sections, tables

PAGE = ROOT / "docs" / "numpy-backend.md"
HEADER = ["shape or light", "formulas", "single source (module:function)", "twins kept and why"]
SOURCE = re.compile(r"`(rtpy(?:\.\w+)+):(\w+(?:\.\w+)*)`")


def mirrored() -> set[str]:
    """The classes with a numpy twin: the shapes the batched scene sorts into sets,
    Mesh (a set of its own), the lights of rtpy/light.py, the environments with a
    radiance_array of their own, and the sampling functions."""
    names = {cls.__name__ for cls in KINDS} | {"Mesh", "sampling functions"}
    names |= {
        cls.__name__
        for cls in vars(rtpy.light).values()
        if isinstance(cls, type)
        and issubclass(cls, rtpy.light.Light)
        and cls is not rtpy.light.Light
    }
    names |= {
        cls.__name__
        for cls in vars(rtpy.environment).values()
        if isinstance(cls, type)
        and issubclass(cls, rtpy.environment.Environment)
        and "radiance_array" in vars(cls)
    }
    return names


def table(text: str) -> list[list[str]]:
    """The rows of the "Shapes and lights" table."""
    (written_once,) = [
        body for heading, body in sections(text) if heading == "Formulas written once"
    ]
    (body,) = [
        body for heading, body in sections(written_once, 3) if heading == "Shapes and lights"
    ]
    (rows,) = [rows for header, rows in tables(body) if header == HEADER]
    return rows


def missing_rows(text: str) -> set[str]:
    return mirrored() - {row[0].strip("`") for row in table(text)}


def test_every_mirrored_shape_and_light_has_a_row():
    assert not missing_rows(PAGE.read_text(encoding="utf-8"))


def test_a_missing_row_is_found():
    text = PAGE.read_text(encoding="utf-8")
    planted = "\n".join(line for line in text.splitlines() if not line.startswith("| `Quad` |"))
    assert missing_rows(planted) == {"Quad"}


def test_the_single_sources_exist():
    for row in table(PAGE.read_text(encoding="utf-8")):
        for module, name in SOURCE.findall(row[2]):
            found = importlib.import_module(module)
            for part in name.split("."):
                found = getattr(found, part)
            assert callable(found), f"{module}:{name}"
