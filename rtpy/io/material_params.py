"""The scene-file keys of a material: the keyword parameters of its constructor.

Material keys are not listed anywhere: a material class registered with
rtpy.materials.register_material loads from scene files with its constructor's
parameters as keys and its defaults as defaults, and the parameter's annotation
(or default) says what type of value the key takes. Their ranges are
rtpy.materials.ranges.MATERIAL_RANGES.
"""

from __future__ import annotations

import inspect
import re
from dataclasses import dataclass
from typing import Any

from ..vec3 import Vec3

__all__ = ["Param", "material_parameters"]


@dataclass(frozen=True)
class Param:
    name: str
    kind: str  # "albedo" (colour or texture name), "color", "bool", "int", "float", "str", "any"
    required: bool
    choices: tuple[str, ...] = ()


def _annotation_text(ann: Any) -> str:
    if ann is inspect.Parameter.empty:
        return ""
    if isinstance(ann, str):
        return ann
    return inspect.formatannotation(ann)


def _param_kind(p: inspect.Parameter) -> tuple[str, tuple[str, ...]]:
    text = _annotation_text(p.annotation)
    names = {t.rsplit(".", 1)[-1] for t in re.findall(r"[A-Za-z_][\w.]*", text)}
    choices: tuple[str, ...] = ()
    if "Literal" in names:
        m = re.search(r"Literal\[(.*?)\]", text)
        if m:
            choices = tuple(re.findall(r"""['"]([^'"]*)['"]""", m.group(1)))
            return "str", choices
    if p.name == "albedo" or "Texture" in names:
        return "albedo", choices
    if names & {"Color", "Vec3", "Point3"}:
        return "color", choices
    if "bool" in names:
        return "bool", choices
    if "float" in names:
        return "float", choices
    if "int" in names:
        return "int", choices
    if "str" in names:
        return "str", choices
    d = p.default
    if isinstance(d, bool):
        return "bool", choices
    if isinstance(d, int | float):
        return "float", choices  # an unannotated `k=1` still takes 1.5
    if isinstance(d, str):
        return "str", choices
    if isinstance(d, Vec3):
        return "color", choices
    return "any", choices


def material_parameters(cls: type) -> dict[str, Param]:
    """The scene keys of a material class: its constructor's keyword parameters."""
    params = {}
    for p in inspect.signature(cls).parameters.values():
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD, p.POSITIONAL_ONLY) or p.name == "type":
            continue
        kind, choices = _param_kind(p)
        params[p.name] = Param(p.name, kind, p.default is inspect.Parameter.empty, choices)
    return params
