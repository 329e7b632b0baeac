"""docs/numpy-backend.md's "Formulas written once": a row for every material class the
numpy backend has a kernel for and for every shape, light and environment it mirrors,
and every function the rows name as a single source exists."""

from __future__ import annotations

import re

from rtpy.environment import Environment
from rtpy.light import Light
from rtpy.materials import MATERIALS
from rtpy.mesh import Mesh
from rtpy.numpy_backend.materials import KERNELS, class_name
from rtpy.numpy_backend.scene import KINDS
from rtpy.testing.analytic_scenes import GlowingLambertian

from .markdown import ROOT

PAGE = ROOT / "docs" / "numpy-backend.md"
SECTION = "## Formulas written once"


def table(subsection: str) -> list[list[str]]:
    """The rows (lists of cells) of the table under `### subsection` in the section."""
    text = PAGE.read_text(encoding="utf-8")
    section = text[text.index(SECTION) :]
    section = section[: section.index("\n## ", 1)]
    part = section[section.index(f"### {subsection}") :].split("\n### ", 1)[0]
    rows = [line for line in part.splitlines() if line.startswith("|")]
    return [[c.strip() for c in row.strip("|").split("|")] for row in rows[2:]]


def names(cell: str) -> set[str]:
    return set(re.findall(r"`(\w+)`", cell))


def first_cells(subsection: str) -> set[str]:
    return set().union(*(names(row[0]) for row in table(subsection)))


def test_every_material_with_a_kernel_has_a_row():
    declaring = [*MATERIALS.values(), GlowingLambertian]
    expected = {cls.__name__ for cls in declaring if class_name(cls) in KERNELS}
    assert len(expected) == len(KERNELS)
    assert first_cells("Reflection models") == expected


def test_every_mirrored_shape_light_and_environment_has_a_row():
    mirrored_environments = {
        cls.__name__ for cls in Environment.__subclasses__() if "radiance_array" in cls.__dict__
    }
    lights = {cls.__name__ for cls in Light.__subclasses__()}
    expected = {cls.__name__ for cls in KINDS} | {Mesh.__name__} | lights | mirrored_environments
    assert first_cells("Shapes and lights") == expected


def test_every_single_source_named_exists():
    """A `name` is defined somewhere in rtpy/; a `module.py:name` in that module."""
    package = ROOT / "rtpy"
    modules = {
        p.relative_to(package).as_posix(): p.read_text("utf-8") for p in package.rglob("*.py")
    }

    def defines(text: str, name: str) -> bool:
        return re.search(rf"^\s*(?:def|class) {name}\b", text, re.M) is not None

    named = 0
    for subsection in ("Reflection models", "Shapes and lights"):
        for row in table(subsection):
            for module, name in re.findall(r"`(?:([\w/]+\.py):)?(\w+)`", row[2]):
                named += 1
                if module:
                    assert module in modules and defines(modules[module], name), (module, name)
                else:
                    assert any(defines(text, name) for text in modules.values()), name
    assert named > 20, "the tables name their sources"
