"""Load a scene file (TOML, format 1; see the project's scene-format contract).

    scene = load_scene("scenes/cornell.toml")

Everything in the file is checked before anything is built or rendered: unknown
tables and keys, types (booleans are not numbers, NaN and infinities are
refused), value ranges, references between tables, degenerate shapes and
cameras. A file that breaks the contract raises one SceneError whose message
names the file, the table and the key, says what was expected and what was
found, gives the line when it can be found and suggests the nearest valid name
for a misspelt one:

    bad.toml: [materials.glass] ior: expected a number > 0, found -1.5 (line 12)
    bad.toml: [camera] lookat: unknown key (line 3) — did you mean 'look_at'?

Material keys are not listed here: they are the keyword parameters of the
material's constructor (rtpy.materials.MATERIALS), with the constructor's
defaults, so materials registered later load without changes to this module.
The loader never prints.
"""

from __future__ import annotations

import difflib
import inspect
import json
import math
import re
import tomllib
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..camera import Camera
from ..light import PointLight
from ..materials import MATERIALS
from ..quad import Quad
from ..render_settings import INTEGRATOR_NAMES, RenderSettings
from ..scene import Scene
from ..sphere import Sphere
from ..texture import CheckerTexture, ImageTexture, SolidColor, Texture
from ..triangle import Triangle
from ..vec3 import Color, Vec3, cross

__all__ = [
    "MAX_HEIGHT",
    "MAX_RADIANCE",
    "MAX_MAX_DEPTH",
    "MAX_SPP",
    "MAX_TEXTURE_PIXELS",
    "MAX_WIDTH",
    "SceneError",
    "load_scene",
    "load_scene_text",
]

# Sanity limits: larger values would exhaust memory or never finish.
MAX_WIDTH = 16384
MAX_HEIGHT = 16384
MAX_SPP = 1_000_000
MAX_MAX_DEPTH = 500  # the Whitted integrator recurses once per segment
MAX_TEXTURE_PIXELS = 2048 * 2048  # image textures are kept as Python Colors

TOP_LEVEL_TABLES = ("camera", "render", "textures", "materials", "objects", "lights")
CAMERA_KEYS = (
    "look_from",
    "look_at",
    "vup",
    "vfov",
    "aspect_ratio",
    "width",
    "defocus_angle",
    "focus_distance",
)
RENDER_KEYS = (
    "integrator",
    "spp",
    "max_depth",
    "nee",
    "russian_roulette",
    "seed",
    "background",
    "sky",
    "gamma",
    "mis",
)
TEXTURE_KEYS = {
    "solid": ("type", "color"),
    "checker": ("type", "scale", "even", "odd"),
    "image": ("type", "path"),
}
OBJECT_KEYS = {
    "sphere": ("type", "center", "radius", "material"),
    "quad": ("type", "q", "u", "v", "material"),
    "triangle": ("type", "a", "b", "c", "material"),
}
LIGHT_KEYS = {"point": ("type", "position", "intensity")}


# --------------------------------------------------------------------------- errors


class SceneError(Exception):
    """A scene file (or scene name) that cannot be loaded. str(error) is the whole
    message; the parts are also kept as attributes (file, table, key, line,
    suggestion, detail)."""

    def __init__(
        self,
        detail: str,
        *,
        file: str | None = None,
        table: str | None = None,
        key: str | None = None,
        line: int | None = None,
        suggestion: str | None = None,
    ) -> None:
        self.detail = detail
        self.file = file
        self.table = table
        self.key = key
        self.line = line
        self.suggestion = suggestion
        super().__init__(self._format())

    def _format(self) -> str:
        head = ""
        if self.table is not None:
            head = self.table + (f" {self.key}" if self.key is not None else "")
        elif self.key is not None:
            head = self.key
        parts = [p for p in (self.file, head) if p]
        text = ": ".join([*parts, self.detail])
        if self.line is not None:
            text += f" (line {self.line})"
        if self.suggestion is not None:
            text += f" — did you mean '{self.suggestion}'?"
        return text.translate(_ESCAPE_LINE_BREAKS)


# A message is one line: names and strings quoted from the file keep no character
# that str.splitlines (or a terminal) takes for a line break.
_ESCAPE_LINE_BREAKS = str.maketrans(
    {c: repr(c)[1:-1] for c in "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"}
)


def _suggest(word: str, choices: Iterable[str]) -> str | None:
    matches = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return matches[0] if matches else None


# --------------------------------------------------------------------------- line numbers

_BARE = r"[A-Za-z0-9_-]+"
_BASIC = r'"(?:[^"\\\n]|\\.)*"'
_LITERAL = r"'[^'\n]*'"
_KEY = rf"(?:{_BARE}|{_BASIC}|{_LITERAL})"
_DOTTED = rf"{_KEY}(?:[ \t]*\.[ \t]*{_KEY})*"
_HEADER_RE = re.compile(rf"^[ \t]*(\[\[|\[)[ \t]*({_DOTTED})[ \t]*(\]\]|\])[ \t]*(?:#.*)?$")
_KEYLINE_RE = re.compile(rf"^[ \t]*({_DOTTED})[ \t]*=")
_KEYPART_RE = re.compile(_KEY)


def _split_dotted(dotted: str) -> tuple[str, ...]:
    parts = []
    for m in _KEYPART_RE.finditer(dotted):
        k = m.group(0)
        if k.startswith('"'):
            try:
                k = json.loads(k)
            except ValueError:
                k = k[1:-1]
        elif k.startswith("'"):
            k = k[1:-1]
        parts.append(k)
    return tuple(parts)


class _Lines:
    """Where tables and keys are in the text. tomllib reports no positions for
    values, so the loader finds them by scanning: the table's header line, then
    the first `key =` line after it (inline tables and dotted keys fall back to
    the line that names the table)."""

    def __init__(self, text: str) -> None:
        self.lines = text.splitlines()
        self.headers: list[tuple[int, tuple[str, ...], bool]] = []  # (0-based line, path, [[ ]])
        in_string: str | None = None
        for i, line in enumerate(self.lines):
            if in_string is not None:
                if line.count(in_string) % 2 == 1:
                    in_string = None
                continue
            m = _HEADER_RE.match(line)
            if m:
                self.headers.append((i, _split_dotted(m.group(2)), m.group(1) == "[["))
                continue
            for quote in ('"""', "'''"):
                if line.count(quote) % 2 == 1:
                    in_string = quote
                    break

    def _section_end(self, start: int) -> int:
        for i, _, _ in self.headers:
            if i > start:
                return i
        return len(self.lines)

    def _key_line(self, start: int, end: int, key: str) -> int | None:
        for i in range(start, end):
            m = _KEYLINE_RE.match(self.lines[i])
            if m and _split_dotted(m.group(1))[:1] == (key,):
                return i + 1
        return None

    def _header(self, path: tuple[str, ...], index: int | None) -> int | None:
        if index is None:
            for i, p, is_array in self.headers:
                if p == path and not is_array:
                    return i
            return None
        arrays = [i for i, p, is_array in self.headers if p == path and is_array]
        return arrays[index] if 0 <= index < len(arrays) else None

    def _in_section(self, path: tuple[str, ...], key: str) -> int | None:
        """The `key =` line in the section of the (non-array) table `path`."""
        if not path:
            first = self.headers[0][0] if self.headers else len(self.lines)
            return self._key_line(0, first, key)
        start = self._header(path, None)
        if start is None:
            return None
        return self._key_line(start + 1, self._section_end(start), key)

    def locate(self, path: tuple[str, ...], index: int | None, key: str | None) -> int | None:
        """1-based line of `key` in table `path` (the index-th [[path]] when index is
        not None), else of the table itself, else None."""
        if not path:
            if key is None:
                return None
            line = self._in_section((), key)
            if line is not None:
                return line
            for i, p, _ in self.headers:
                if p[:1] == (key,):
                    return i + 1
            return None
        start = self._header(path, index)
        if start is not None:
            if key is not None:
                line = self._key_line(start + 1, self._section_end(start), key)
                if line is not None:
                    return line
                for i, p, _ in self.headers:  # a sub-table [path.key]
                    if i > start and p == (*path, key):
                        return i + 1
            return start + 1
        # Defined inline (`name = { ... }`) or by dotted keys in a parent table.
        for k in range(len(path) - 1, -1, -1):
            line = self._in_section(path[:k], path[k])
            if line is not None:
                return line
        if index is None:  # only sub-tables written, e.g. [materials.x] without [materials]
            for i, p, _ in self.headers:
                if p[: len(path)] == path:
                    return i + 1
        return None

    def context(self, line: int) -> tuple[str | None, str | None]:
        """(table label, key) of the given 1-based line, for syntax errors."""
        label = None
        counts: dict[tuple[str, ...], int] = {}
        for i, p, is_array in self.headers:
            if is_array:
                counts[p] = counts.get(p, 0) + 1
            if i + 1 > line:
                break
            label = f"[[{_dotted(p)}]] #{counts[p]}" if is_array else f"[{_dotted(p)}]"
            if i + 1 == line:
                return label, None
        key = None
        if 1 <= line <= len(self.lines):
            m = _KEYLINE_RE.match(self.lines[line - 1])
            if m:
                key = ".".join(_quote_key(k) for k in _split_dotted(m.group(1)))
        return label, key


def _quote_key(k: str) -> str:
    return k if re.fullmatch(_BARE, k) else json.dumps(k, ensure_ascii=False)


def _dotted(path: Iterable[str]) -> str:
    return ".".join(_quote_key(k) for k in path)


@dataclass(frozen=True)
class _Where:
    """A table of the file: its label in messages and where to find it."""

    label: str  # "[camera]", "[materials.glass]", "[[objects]] #3"
    path: tuple[str, ...]
    index: int | None = None  # 0-based, for arrays of tables

    @staticmethod
    def table(*path: str) -> _Where:
        return _Where(f"[{_dotted(path)}]", tuple(path))

    @staticmethod
    def array(name: str, index: int) -> _Where:
        return _Where(f"[[{_quote_key(name)}]] #{index + 1}", (name,), index)


# --------------------------------------------------------------------------- values


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def _num_text(v: int | float) -> str:
    if isinstance(v, int):
        return str(v) if v.bit_length() <= 64 else "a very large integer"
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return str(int(v)) if v.is_integer() and abs(v) < 1e15 else repr(v)


def _short(text: str, limit: int = 60) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _describe(v: Any) -> str:
    """What was found, for messages."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return _num_text(v)
    if isinstance(v, float):
        return _num_text(v) if not v.is_integer() else repr(v)
    if isinstance(v, str):
        return "the string " + _short(json.dumps(v, ensure_ascii=False))
    if isinstance(v, list):
        if len(v) <= 4 and all(_is_number(x) or isinstance(x, bool) for x in v):
            return "[" + ", ".join(_describe(x) for x in v) + "]"
        return f"an array of {len(v)} item{'s' if len(v) != 1 else ''}"
    if isinstance(v, dict):
        return "a table"
    return f"a {type(v).__name__}"  # dates and times


@dataclass(frozen=True)
class _Range:
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False

    def __contains__(self, x: float) -> bool:
        if self.lo is not None and (x <= self.lo if self.lo_open else x < self.lo):
            return False
        return not (self.hi is not None and (x >= self.hi if self.hi_open else x > self.hi))

    def text(self) -> str:
        lo = None if self.lo is None else _num_text(self.lo)
        hi = None if self.hi is None else _num_text(self.hi)
        if lo is not None and hi is not None:
            return f"in {'(' if self.lo_open else '['}{lo}, {hi}{')' if self.hi_open else ']'}"
        if lo is not None:
            return f"{'>' if self.lo_open else '>='} {lo}"
        if hi is not None:
            return f"{'<' if self.hi_open else '<='} {hi}"
        return ""


ANY = _Range()
POSITIVE = _Range(0, None, lo_open=True)
NON_NEGATIVE = _Range(0)
# Radiance (emit, intensity, background) and the kd / ks weights are bounded so that
# no sum of samples can overflow: a path's weight grows at most about 2x a bounce
# with kd, ks <= 1, so even 10^6 samples of 500 bounces stay below 1e30 * 1e157.
MAX_RADIANCE = 1e30
RADIANCE = _Range(0, MAX_RADIANCE)
UNIT = _Range(0, 1)

# Ranges of material parameters by name, for numbers and for each colour component.
# Constructors may check more; their ValueErrors become SceneErrors too.
MATERIAL_RANGES: dict[str, _Range] = {
    "albedo": UNIT,
    "f0": UNIT,
    "emit": RADIANCE,
    "ior": POSITIVE,
    "fuzz": NON_NEGATIVE,
    "kd": UNIT,
    "ks": UNIT,
    "exponent": NON_NEGATIVE,
    "roughness": POSITIVE,
    "alpha_x": POSITIVE,
    "alpha_y": POSITIVE,
    "sigma": NON_NEGATIVE,
}


# --------------------------------------------------------------------------- material signatures


@dataclass(frozen=True)
class _Param:
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


def material_parameters(cls: type) -> dict[str, _Param]:
    """The scene keys of a material class: its constructor's keyword parameters."""
    params = {}
    for p in inspect.signature(cls).parameters.values():
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD, p.POSITIONAL_ONLY) or p.name == "type":
            continue
        kind, choices = _param_kind(p)
        params[p.name] = _Param(p.name, kind, p.default is inspect.Parameter.empty, choices)
    return params


# --------------------------------------------------------------------------- the loader


class _Loader:
    def __init__(self, text: str, path: Path) -> None:
        self.text = text
        self.path = path
        self.file = str(path)
        self.lines = _Lines(text)
        self.textures: dict[str, Texture] = {}
        self.materials: dict[str, Any] = {}

    # --- errors ---------------------------------------------------------------
    def fail(
        self, where: _Where | None, key: str | None, detail: str, suggestion: str | None = None
    ) -> SceneError:
        if where is None:
            line = self.lines.locate((), None, key)
            table = None
        else:
            line = self.lines.locate(where.path, where.index, key)
            table = where.label
        return SceneError(
            detail, file=self.file, table=table, key=key, line=line, suggestion=suggestion
        )

    def expected(self, where: _Where, key: str, what: str, found: Any) -> SceneError:
        return self.fail(where, key, f"expected {what}, found {_describe(found)}")

    def check_keys(self, where: _Where, table: dict, valid: Iterable[str], what: str = "") -> None:
        valid = list(valid)
        for key in table:
            if key not in valid:
                listed = ", ".join(valid)
                for_what = f" for {what}" if what else ""
                raise self.fail(
                    where,
                    key,
                    f"unknown key{for_what}; valid keys: {listed}",
                    _suggest(key, valid),
                )

    def require(self, where: _Where, table: dict, key: str, what: str) -> Any:
        if key not in table:
            raise self.fail(where, key, f"missing required key (expected {what})")
        return table[key]

    # --- scalar values ----------------------------------------------------------
    def number(self, where: _Where, key: str, v: Any, rng: _Range = ANY) -> float:
        what = f"a number {rng.text()}".rstrip()
        if not _is_number(v):
            raise self.expected(where, key, what, v)
        try:
            x = float(v)
        except OverflowError:
            x = math.inf
        if not math.isfinite(x):
            raise self.expected(where, key, f"a finite number {rng.text()}".rstrip(), v)
        if x not in rng:
            raise self.expected(where, key, what, v)
        return x

    def integer(self, where: _Where, key: str, v: Any, rng: _Range = ANY, limit: str = "") -> int:
        what = f"an integer {rng.text()}".rstrip() + limit
        if isinstance(v, float) and math.isfinite(v) and v.is_integer():
            raise self.fail(
                where,
                key,
                f"expected {what}, found {v!r} (write {int(v)} without the decimal point)",
            )
        if not isinstance(v, int) or isinstance(v, bool):
            raise self.expected(where, key, what, v)
        if v not in rng:
            raise self.expected(where, key, what, v)
        return v

    def boolean(self, where: _Where, key: str, v: Any) -> bool:
        if not isinstance(v, bool):
            raise self.expected(where, key, "true or false", v)
        return v

    def string(self, where: _Where, key: str, v: Any, choices: tuple[str, ...] = ()) -> str:
        listed = ", ".join(f'"{c}"' for c in choices)
        what = f"one of {listed}" if choices else "a string"
        if not isinstance(v, str):
            raise self.expected(where, key, what, v)
        if choices and v not in choices:
            raise self.fail(
                where, key, f"expected {what}, found {_describe(v)}", _suggest(v, choices)
            )
        return v

    def triple(self, where: _Where, key: str, v: Any, rng: _Range = ANY) -> tuple[float, ...]:
        each = f", each {rng.text()}" if rng.text() else ""
        what = f"an array of 3 finite numbers{each}"
        if not isinstance(v, list) or len(v) != 3:
            raise self.expected(where, key, what, v)
        out = []
        for i, x in enumerate(v):
            if not _is_number(x):
                why = " (booleans are not numbers)" if isinstance(x, bool) else ""
                raise self.fail(
                    where,
                    key,
                    f"expected {what}, found {_describe(x)} as component {i + 1}{why}",
                )
            try:
                f = float(x)
            except OverflowError:
                f = math.inf
            if not math.isfinite(f) or f not in rng:
                raise self.fail(
                    where,
                    key,
                    f"expected {what}, found {_describe(v)} (component {i + 1} is {_describe(x)})",
                )
            out.append(f)
        return tuple(out)

    def vec3(self, where: _Where, key: str, v: Any) -> Vec3:
        return Vec3(*self.triple(where, key, v))

    def color(self, where: _Where, key: str, v: Any, rng: _Range = ANY) -> Color:
        return Color(*self.triple(where, key, v, rng))

    # --- tables -------------------------------------------------------------------
    def table(self, data: dict, name: str) -> dict:
        t = data.get(name, {})
        if not isinstance(t, dict):
            raise self.fail(_Where.table(name), None, f"expected a table, found {_describe(t)}")
        return t

    def named_tables(self, data: dict, name: str) -> dict[str, dict]:
        t = self.table(data, name)
        for sub, value in t.items():
            if not isinstance(value, dict):
                where = _Where.table(name)
                raise self.fail(
                    where,
                    sub,
                    f"expected a table [{name}.{_quote_key(sub)}] with a `type` key, "
                    f"found {_describe(value)}",
                )
        return t

    def array_of_tables(self, data: dict, name: str) -> list[dict]:
        v = data.get(name, [])
        if not isinstance(v, list):
            raise self.fail(
                _Where(f"[[{name}]]", (name,)),
                None,
                f"expected an array of tables, found {_describe(v)} "
                f"(write [[{name}]] before each one, not [{name}])",
            )
        for i, item in enumerate(v):
            if not isinstance(item, dict):
                raise self.fail(
                    _Where.array(name, i), None, f"expected a table, found {_describe(item)}"
                )
        return v

    def type_of(self, where: _Where, table: dict, kinds: Iterable[str], what: str) -> str:
        kinds = tuple(kinds)
        listed = ", ".join(f'"{k}"' for k in kinds)
        if "type" not in table:
            raise self.fail(
                where, "type", f"missing required key (the {what} type: one of {listed})"
            )
        v = table["type"]
        if not isinstance(v, str):
            raise self.expected(where, "type", f"a {what} type: one of {listed}", v)
        if v not in kinds:
            raise self.fail(
                where,
                "type",
                f"unknown {what} type {json.dumps(v, ensure_ascii=False)}; "
                f"expected one of {listed}",
                _suggest(v, kinds),
            )
        return v

    # --- sections -------------------------------------------------------------------
    def load(self, data: dict) -> Scene:
        for name in data:
            if name not in TOP_LEVEL_TABLES:
                raise SceneError(
                    "unknown table; the tables are " + ", ".join(TOP_LEVEL_TABLES),
                    file=self.file,
                    table=f"[{_quote_key(name)}]",
                    line=self.lines.locate((), None, name),
                    suggestion=_suggest(name, TOP_LEVEL_TABLES),
                )
        camera = self.camera(self.table(data, "camera"))
        settings, background, sky = self.render(self.table(data, "render"))
        for name, t in self.named_tables(data, "textures").items():
            self.textures[name] = self.texture(_Where.table("textures", name), t)
        for name, t in self.named_tables(data, "materials").items():
            self.materials[name] = self.material(_Where.table("materials", name), t)
        objects = [
            self.object(_Where.array("objects", i), t)
            for i, t in enumerate(self.array_of_tables(data, "objects"))
        ]
        lights = [
            self.light(_Where.array("lights", i), t)
            for i, t in enumerate(self.array_of_tables(data, "lights"))
        ]
        return Scene(
            objects=objects,
            point_lights=lights,
            background=background,
            sky=sky,
            camera=camera,
            settings=settings,
            name=self.path.stem,
        )

    def camera(self, t: dict) -> Camera:
        w = _Where.table("camera")
        self.check_keys(w, t, CAMERA_KEYS)
        look_from = self.vec3(w, "look_from", t.get("look_from", [0, 0, 0]))
        look_at = self.vec3(w, "look_at", t.get("look_at", [0, 0, -1]))
        vup = self.vec3(w, "vup", t.get("vup", [0, 1, 0]))
        vfov = self.number(w, "vfov", t.get("vfov", 90), _Range(0, 180, True, True))
        aspect = self.aspect_ratio(w, t.get("aspect_ratio", 16.0 / 9.0))
        width = self.integer(
            w,
            "width",
            t.get("width", 400),
            _Range(1, MAX_WIDTH),
            " (larger images are refused)",
        )
        defocus = self.number(
            w, "defocus_angle", t.get("defocus_angle", 0), _Range(0, 180, False, True)
        )
        focus = self.number(w, "focus_distance", t.get("focus_distance", 10), POSITIVE)

        height = width / aspect
        if not height < MAX_HEIGHT + 1:
            raise self.fail(
                w,
                "aspect_ratio",
                f"width {width} / aspect_ratio {_num_text(aspect)} gives an image height of "
                f"{_num_text(int(height)) if math.isfinite(height) else 'inf'} pixels; "
                f"the most is {MAX_HEIGHT}",
            )
        view = look_from - look_at
        if view.is_black():
            raise self.fail(
                w,
                "look_at",
                f"look_at must differ from look_from (both are {_describe(list(look_from))})",
            )
        if not math.isfinite(view.length()):
            raise self.fail(w, "look_at", "look_from and look_at are too far apart")
        if vup.is_black() or not math.isfinite(vup.length()):
            raise self.fail(
                w, "vup", f"expected a non-zero up vector, found {_describe(list(vup))}"
            )
        side = cross(vup, view / view.length())
        if not side.length() >= 1e-9 * vup.length():
            raise self.fail(
                w,
                "vup",
                f"vup {_describe(list(vup))} is parallel to the view direction "
                "(look_at - look_from); choose an up vector across it",
            )
        try:
            return Camera(look_from, look_at, vup, vfov, aspect, width, defocus, focus)
        except (ValueError, ArithmeticError) as e:
            raise self.fail(w, _guess_key(str(e), CAMERA_KEYS), str(e)) from None

    def aspect_ratio(self, w: _Where, v: Any) -> float:
        what = 'a number > 0 or a string "W:H" (such as "16:9")'
        if isinstance(v, str):
            m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*[:/]\s*([0-9.eE+-]+)\s*", v)
            a = b = math.nan
            if m:
                try:
                    a, b = float(m.group(1)), float(m.group(2))
                except ValueError:
                    pass
            if not (math.isfinite(a) and math.isfinite(b) and a > 0 and b > 0):
                raise self.expected(w, "aspect_ratio", what, v)
            ratio = a / b
            if not (math.isfinite(ratio) and ratio > 0):
                raise self.expected(w, "aspect_ratio", what, v)
            return ratio
        if not _is_number(v):
            raise self.expected(w, "aspect_ratio", what, v)
        return self.number(w, "aspect_ratio", v, POSITIVE)

    def render(self, t: dict) -> tuple[RenderSettings, Color, bool]:
        w = _Where.table("render")
        self.check_keys(w, t, RENDER_KEYS)
        kwargs: dict[str, Any] = {}
        if "integrator" in t:
            kwargs["integrator"] = self.string(w, "integrator", t["integrator"], INTEGRATOR_NAMES)
        if "spp" in t:
            kwargs["spp"] = self.integer(
                w, "spp", t["spp"], _Range(1, MAX_SPP), " (larger counts are refused)"
            )
        if "max_depth" in t:
            kwargs["max_depth"] = self.integer(
                w,
                "max_depth",
                t["max_depth"],
                _Range(1, MAX_MAX_DEPTH),
                " (deeper paths are refused)",
            )
        if "nee" in t:
            kwargs["nee"] = self.boolean(w, "nee", t["nee"])
        if "mis" in t:
            kwargs["mis"] = self.boolean(w, "mis", t["mis"])
        if "russian_roulette" in t:
            kwargs["russian_roulette"] = self.integer(
                w, "russian_roulette", t["russian_roulette"], NON_NEGATIVE
            )
        if "seed" in t:
            kwargs["seed"] = self.integer(w, "seed", t["seed"], NON_NEGATIVE)
        if "gamma" in t:
            kwargs["gamma"] = self.number(w, "gamma", t["gamma"], POSITIVE)
        background = self.color(w, "background", t.get("background", [0, 0, 0]), RADIANCE)
        sky = self.boolean(w, "sky", t.get("sky", False))
        try:
            settings = RenderSettings(**kwargs)
        except (ValueError, TypeError) as e:
            raise self.fail(w, _guess_key(str(e), RENDER_KEYS), str(e)) from None
        return settings, background, sky

    def texture(self, w: _Where, t: dict) -> Texture:
        kind = self.type_of(w, t, TEXTURE_KEYS, "texture")
        self.check_keys(w, t, TEXTURE_KEYS[kind], f'type "{kind}"')
        if kind == "solid":
            return SolidColor(self.color(w, "color", self.require(w, t, "color", "a colour"), UNIT))
        if kind == "checker":
            scale = self.number(w, "scale", t.get("scale", 1), POSITIVE)
            even = self.color(w, "even", self.require(w, t, "even", "a colour"), UNIT)
            odd = self.color(w, "odd", self.require(w, t, "odd", "a colour"), UNIT)
            return CheckerTexture(scale, even, odd)
        return self.image(w, t)

    def image(self, w: _Where, t: dict) -> Texture:
        rel = self.require(w, t, "path", "the path of a PNG or JPEG file")
        if not isinstance(rel, str) or not rel:
            raise self.expected(w, "path", "the path of a PNG or JPEG file", rel)
        try:
            resolved = self.path.parent / rel
            if resolved.is_dir():
                raise self.fail(w, "path", f"{resolved} is a directory, not an image file")
            if not resolved.is_file():
                raise self.fail(w, "path", f"image file not found: {resolved}")
            from PIL import Image

            with Image.open(resolved) as im:
                size = im.size
            if size[0] * size[1] > MAX_TEXTURE_PIXELS:
                raise self.fail(
                    w,
                    "path",
                    f"image {resolved} has {size[0]} x {size[1]} pixels; "
                    f"the most for a texture is {MAX_TEXTURE_PIXELS}",
                )
            return ImageTexture.from_file(resolved)
        except SceneError:
            raise
        except Exception as e:  # PIL raises many kinds for unreadable files
            raise self.fail(w, "path", f"cannot read image {self.path.parent / rel}: {e}") from None

    def material(self, w: _Where, t: dict) -> Any:
        kind = self.type_of(w, t, MATERIALS, "material")
        cls = MATERIALS[kind]
        params = material_parameters(cls)
        self.check_keys(w, t, ["type", *params], f'type "{kind}"')
        kwargs = {}
        for p in params.values():
            if p.name not in t:
                if p.required:
                    raise self.fail(w, p.name, f'missing required key of a "{kind}" material')
                continue
            kwargs[p.name] = self.material_value(w, p, t[p.name])
        try:
            return cls(**kwargs)
        except (ValueError, TypeError, ArithmeticError) as e:
            raise self.fail(w, _guess_key(str(e), params), str(e)) from None

    def material_value(self, w: _Where, p: _Param, v: Any) -> Any:
        rng = MATERIAL_RANGES.get(p.name, ANY)
        if p.kind == "albedo":
            if isinstance(v, str):
                if v not in self.textures:
                    defined = ", ".join(self.textures) or "none"
                    raise self.fail(
                        w,
                        p.name,
                        f"no texture named {json.dumps(v, ensure_ascii=False)} "
                        f"([textures.{_quote_key(v)}]); "
                        f"textures defined: {defined}",
                        _suggest(v, self.textures),
                    )
                return self.textures[v]
            if not isinstance(v, list):
                each = f" (each {rng.text()})" if rng.text() else ""
                raise self.expected(
                    w, p.name, f"an array of 3 numbers{each} or the name of a texture", v
                )
            return self.color(w, p.name, v, rng)
        if p.kind == "color":
            return self.color(w, p.name, v, rng)
        if p.kind == "bool":
            return self.boolean(w, p.name, v)
        if p.kind == "int":
            return self.integer(w, p.name, v, rng)
        if p.kind == "float":
            return self.number(w, p.name, v, rng)
        if p.kind == "str":
            return self.string(w, p.name, v, p.choices)
        if _is_number(v) and isinstance(v, float) and not math.isfinite(v):
            raise self.expected(w, p.name, "a finite number", v)
        return v

    def reference(self, w: _Where, t: dict) -> Any:
        name = self.require(w, t, "material", "the name of a [materials.NAME] table")
        if not isinstance(name, str):
            raise self.expected(w, "material", "the name of a [materials.NAME] table", name)
        if name not in self.materials:
            defined = ", ".join(self.materials) or "none"
            raise self.fail(
                w,
                "material",
                f"no material named {json.dumps(name, ensure_ascii=False)} "
                f"([materials.{_quote_key(name)}]); "
                f"materials defined: {defined}",
                _suggest(name, self.materials),
            )
        return self.materials[name]

    def object(self, w: _Where, t: dict) -> Any:
        kind = self.type_of(w, t, OBJECT_KEYS, "object")
        self.check_keys(w, t, OBJECT_KEYS[kind], f'type "{kind}"')

        def point(key: str) -> Vec3:
            return self.vec3(w, key, self.require(w, t, key, "an array of 3 numbers"))

        if kind == "sphere":
            center = point("center")
            radius = self.require(w, t, "radius", "a number > 0")
            radius = self.number(w, "radius", radius, POSITIVE)
            material = self.reference(w, t)
            return self.build(w, "radius", lambda m: Sphere(center, radius, m), material)
        if kind == "quad":
            q, u, v = point("q"), point("u"), point("v")
            return self.build(
                w,
                "u",
                lambda m: Quad(q, u, v, m),
                self.reference(w, t),
                f" (u = {_describe(list(u))}, v = {_describe(list(v))})",
            )
        a, b, c = point("a"), point("b"), point("c")
        return self.build(
            w,
            "a",
            lambda m: Triangle(a, b, c, m),
            self.reference(w, t),
            f" (a = {_describe(list(a))}, b = {_describe(list(b))}, c = {_describe(list(c))})",
        )

    def build(
        self, w: _Where, key: str, make: Callable[[Any], Any], material: Any, found: str = ""
    ) -> Any:
        try:
            return make(material)
        except (ValueError, ArithmeticError) as e:
            raise self.fail(w, key, f"{e}{found}") from None

    def light(self, w: _Where, t: dict) -> PointLight:
        kind = self.type_of(w, t, LIGHT_KEYS, "light")
        self.check_keys(w, t, LIGHT_KEYS[kind], f'type "{kind}"')
        position = self.vec3(w, "position", self.require(w, t, "position", "an array of 3 numbers"))
        intensity = self.color(
            w,
            "intensity",
            self.require(w, t, "intensity", f"a colour, each component in [0, {MAX_RADIANCE:g}]"),
            RADIANCE,
        )
        return PointLight(position, intensity)


def _guess_key(message: str, keys: Iterable[str]) -> str | None:
    """The key a constructor's error message talks about, if it names one."""
    for key in keys:
        if re.search(rf"\b{re.escape(key)}\b", message):
            return key
    return None


# --------------------------------------------------------------------------- entry points


def load_scene_text(text: str, path: str | Path) -> Scene:
    """A Scene from the text of a scene file. `path` names the file in messages,
    gives the scene its name (the file's stem) and is where image-texture paths
    are relative to."""
    path = Path(path)
    if text.startswith("\ufeff"):
        text = text[1:]
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise _syntax_error(str(e), text, path) from None
    except (ValueError, RecursionError) as e:  # huge integer literals, absurd nesting
        raise SceneError(f"cannot parse the file: {e}", file=str(path)) from None
    return _Loader(text, path).load(data)


def _syntax_error(message: str, text: str, path: Path) -> SceneError:
    line = column = None
    m = re.search(r"\s*\(at line (\d+), column (\d+)\)", message)
    if m:
        line, column = int(m.group(1)), int(m.group(2))
        message = message[: m.start()] + message[m.end() :]
    elif "(at end of document)" in message:
        line = max(1, len(text.splitlines()))
        message = message.replace(" (at end of document)", " at the end of the file")
    table = key = None
    if line is not None:
        table, key = _Lines(text).context(line)
    detail = "TOML syntax error: " + message[:1].lower() + message[1:]
    if column is not None:
        detail += f" at column {column}"
    return SceneError(detail, file=str(path), table=table, key=key, line=line)


def load_scene(path: str | Path) -> Scene:
    """A Scene from a scene file (TOML, UTF-8)."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise SceneError("no such scene file", file=str(path)) from None
    except IsADirectoryError:
        raise SceneError("is a directory, not a scene file", file=str(path)) from None
    except OSError as e:
        raise SceneError(f"cannot read the scene file: {e.strerror or e}", file=str(path)) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = raw[: e.start].count(b"\n") + 1
        raise SceneError(
            f"not UTF-8 text (byte {e.start}: {e.reason})", file=str(path), line=line
        ) from None
    return load_scene_text(text, path)
