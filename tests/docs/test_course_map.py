"""docs/course-map.md: every rtpy name in the map exists, every row that renames says
why, aliases are the same object, and (given a checkout of the course's code) every
class, method and module-level function of the course has a row.

Names in the rtpy column are written `rtpy.module.Name.attribute` and resolved by
import and getattr; an attribute that instances get in __init__ (`self.width = ...`)
counts as an attribute of its class. Repository paths (`scenes/cornell.toml`) must
exist.

The completeness check reads the course's week-8 code from $RTPY_COURSE_DIR (a checkout
of its RT_*.py files and main.py) and is skipped when that is not set.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import os
import re
import textwrap
from pathlib import Path

import pytest

from .markdown import ROOT, code_spans, sections, tables

MAP = ROOT / "docs" / "course-map.md"
MISSING = object()
NAME = re.compile(r"rtpy(\.[A-Za-z_]\w*)+")  # a dotted name (not a call or an example)


def self_attributes(cls: type) -> set[str]:
    """Names assigned as `self.NAME = ...` in the methods of cls and its bases, and
    their __slots__."""
    names: set[str] = set()
    for klass in cls.__mro__:
        if klass is object:
            continue
        names.update(getattr(klass, "__slots__", ()))
        try:
            source = textwrap.dedent(inspect.getsource(klass))
        except (OSError, TypeError):
            continue
        for node in ast.walk(ast.parse(source)):
            targets = []
            if isinstance(node, ast.Assign):
                targets = node.targets
            elif isinstance(node, ast.AnnAssign | ast.AugAssign):
                targets = [node.target]
            for target in targets:
                for t in target.elts if isinstance(target, ast.Tuple) else [target]:
                    if (
                        isinstance(t, ast.Attribute)
                        and isinstance(t.value, ast.Name)
                        and t.value.id == "self"
                    ):
                        names.add(t.attr)
    return names


def resolve(dotted: str) -> object:
    """The object a dotted rtpy name names (an instance attribute resolves to its
    class); raises LookupError naming the part that is missing."""
    parts = dotted.split(".")
    obj: object = MISSING
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        break
    if obj is MISSING:
        raise LookupError(f"no module {parts[0]!r}")
    rest = parts[i:]
    for k, name in enumerate(rest):
        value = getattr(obj, name, MISSING)
        if value is MISSING:
            last = k == len(rest) - 1
            if last and isinstance(obj, type) and name in self_attributes(obj):
                return obj
            raise LookupError(f"{'.'.join(parts[: i + k])} has no attribute {name!r}")
        obj = value
    return obj


def is_path(token: str) -> bool:
    return "/" in token and " " not in token and not token.startswith("rtpy.")


def map_rows(text: str) -> list[tuple[str, list[str]]]:
    """(section heading, cells) of every table row of the page."""
    return [
        (heading, row)
        for heading, body in sections(text)
        for _, rows in tables(body)
        for row in rows
    ]


def last_name(token: str) -> str:
    """`Hitinfo.getP()` -> getP; `rtpy.hit_info.HitInfo.point` -> point."""
    return token.split("(")[0].rstrip(".").split(".")[-1]


def map_problems(text: str) -> list[str]:
    """Every rtpy name or path that does not resolve, every renaming row without a
    reason, and every alias that is not the same object, one line each."""
    problems = []
    for heading, cells in map_rows(text):
        row = " | ".join(cells)
        names = [t for cell in cells for t in code_spans(cell) if NAME.fullmatch(t)]
        resolved = []
        for name in names:
            try:
                resolved.append(resolve(name))
            except LookupError as e:
                problems.append(f"{heading}: `{name}` does not resolve ({e}): | {row} |")
        for token in (t for cell in cells for t in code_spans(cell)):
            if is_path(token) and not (ROOT / token).exists():
                problems.append(f"{heading}: no file {token}: | {row} |")
        if len(cells) != 3 or not heading.startswith(("RT_", "main")):
            continue
        course, ours, why = cells
        if not ours.startswith("—") and not any(
            NAME.fullmatch(t) or is_path(t) for t in code_spans(ours)
        ):
            problems.append(f"{heading}: no rtpy name, path or '—' in | {row} |")
        course_names = {last_name(t) for t in code_spans(course)}
        our_names = {last_name(t) for t in code_spans(ours)}
        if course_names and not course_names & our_names and not why:
            problems.append(f"{heading}: renamed without a reason: | {row} |")
        if "alias" in why and len(set(map(id, resolved))) > 1:
            problems.append(f"{heading}: an alias that is not the same object: | {row} |")
    return problems


def test_every_name_in_the_course_map_resolves_and_every_rename_says_why():
    problems = map_problems(MAP.read_text(encoding="utf-8"))
    assert not problems, "docs/course-map.md:\n" + "\n".join(problems)


def test_the_map_check_catches_planted_mistakes():
    """A misspelt rtpy name, a missing file, a rename with no reason, an alias that is
    another object."""
    text = MAP.read_text(encoding="utf-8")
    misspelt = text.replace(
        "`rtpy.hit_info.HitInfo.point` | an attribute",
        "`rtpy.hit_info.HitInfo.pointt` | an attribute",
        1,
    )
    no_file = text.replace("`scenes/week08_phong.toml`", "`scenes/week08_phongg.toml`", 1)
    no_reason = text.replace(
        "| `rtpy.vec3.Vec3.length` | RTIOW's name (as above) |", "| `rtpy.vec3.Vec3.length` | |", 1
    )
    not_alias = text.replace(
        "`rtpy.vec3.dot` | RTIOW's name; `Vec3.dot_product` is an alias",
        "`rtpy.vec3.dot`, `rtpy.vec3.cross` | RTIOW's name; `Vec3.dot_product` is an alias",
        1,
    )
    for planted in (misspelt, no_file, no_reason, not_alias):
        assert planted != text, "a planted mistake did not apply: update this test"
    assert any("pointt" in p for p in map_problems(misspelt))
    assert any("week08_phongg" in p for p in map_problems(no_file))
    assert any("renamed without a reason" in p for p in map_problems(no_reason))
    assert any("not the same object" in p for p in map_problems(not_alias))


def test_instance_attributes_resolve_to_their_class_and_others_do_not():
    from rtpy.camera import Camera
    from rtpy.materials.phong import Phong

    assert resolve("rtpy.camera.Camera.width") is Camera  # self.width = int(width)
    assert resolve("rtpy.materials.phong.Phong.albedo") is Phong  # set in a base class
    with pytest.raises(LookupError, match="no attribute 'no_such_thing'"):
        resolve("rtpy.camera.Camera.no_such_thing")


# --- completeness against the course's code ----------------------------------------------
def course_names(folder: Path) -> set[str]:
    """`Class`, `Class.method` and `function` for every class, method (dunders left
    out: operators and constructors map with their class) and module-level function
    of the course's RT_*.py and main.py."""
    names = set()
    for path in sorted([*folder.glob("RT_*.py"), folder / "main.py"]):
        tree = ast.parse(path.read_text(encoding="utf-8", errors="replace"))
        for node in tree.body:
            if isinstance(node, ast.FunctionDef):
                names.add(node.name)
            elif isinstance(node, ast.ClassDef):
                names.add(node.name)
                for item in node.body:
                    if isinstance(item, ast.FunctionDef) and not re.fullmatch(
                        r"__\w+__", item.name
                    ):
                        names.add(f"{node.name}.{item.name}")
    return names


def mapped_course_names(text: str) -> set[str]:
    out = set()
    for heading, cells in map_rows(text):
        if len(cells) == 3 and heading.startswith(("RT_", "main")):
            out.update(t.split("(")[0] for t in code_spans(cells[0]))
    return out


@pytest.mark.skipif(
    not os.environ.get("RTPY_COURSE_DIR"),
    reason="set RTPY_COURSE_DIR to a checkout of the course's week-8 code",
)
def test_every_course_name_has_a_row():
    folder = Path(os.environ["RTPY_COURSE_DIR"])
    expected = course_names(folder)
    assert expected, f"no RT_*.py files in {folder}"
    missing = expected - mapped_course_names(MAP.read_text(encoding="utf-8"))
    assert not missing, "docs/course-map.md has no row for: " + ", ".join(sorted(missing))
