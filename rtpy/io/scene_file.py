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

import json
import math
import re
import tomllib
import warnings
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from .. import _checks as checks
from .._checks import (
    ANY,
    ASPECT_RATIO,
    DEFOCUS_ANGLE,
    LENGTH,
    MAX_RADIANCE,
    RADIANCE,
    UNIT,
    VFOV,
    describe,
    one_line,
    suggest,
)
from ..camera import Camera
from ..engine.plugins import plugin_failure
from ..engine.user_files import read_bytes
from ..light import PointLight
from ..materials import MATERIALS
from ..materials.ranges import MATERIAL_RANGES
from ..mesh import Transform
from ..quad import Quad
from ..render_settings import (
    MAX_MAX_DEPTH,
    MAX_SPP,
    MAX_WIDTH,
    RENDER_KEYS,
    SETTINGS,
    RenderSettings,
)
from ..scene import Scene
from ..sphere import Sphere
from ..texture import CheckerTexture, ImageTexture, SolidColor, Texture
from ..triangle import Triangle
from ..vec3 import Color, Vec3
from .material_params import Param, material_parameters
from .mesh_cache import load_mesh
from .obj import ObjError
from .ply import PlyError
from .scene_tables import SceneError, SceneWarning, TableReader
from .toml_lines import TomlLines, Where, quote_key

__all__ = [
    "MAX_HEIGHT",
    "MAX_MAX_DEPTH",
    "MAX_RADIANCE",
    "MAX_SPP",
    "MAX_TEXTURE_PIXELS",
    "MAX_WIDTH",
    "SceneError",
    "SceneWarning",
    "load_scene",
    "load_scene_text",
]

# Sanity limits: larger values would exhaust memory or never finish. The render
# settings' limits (MAX_SPP, MAX_MAX_DEPTH, MAX_WIDTH) are in rtpy.render_settings.
MAX_HEIGHT = 16384
MAX_TEXTURE_PIXELS = 2048 * 2048  # image textures are kept as Python Colors
MAX_SCENE_BYTES = 64 << 20  # a scene file is text; its meshes are files of their own
MAX_TEXTURE_BYTES = 256 << 20  # the file: far more than such an image's PNG or JPEG

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
TEXTURE_KEYS = {
    "solid": ("type", "color"),
    "checker": ("type", "scale", "even", "odd"),
    "image": ("type", "path"),
}
OBJECT_KEYS = {
    "sphere": ("type", "center", "radius", "material"),
    "quad": ("type", "q", "u", "v", "material"),
    "triangle": ("type", "a", "b", "c", "material"),
    "mesh": ("type", "path", "material", "translate", "rotate", "scale"),
}
LIGHT_KEYS = {"point": ("type", "position", "intensity")}


# --------------------------------------------------------------------------- the loader


class _Loader(TableReader):
    """Builds the Scene of a parsed scene file, section by section."""

    def __init__(self, text: str, path: Path) -> None:
        super().__init__(text, path)
        self.textures: dict[str, Texture] = {}
        self.materials: dict[str, Any] = {}
        self.files: list[Path] = [path]  # the files the scene reads (Scene.files)

    # --- sections -------------------------------------------------------------------
    def load(self, data: dict) -> Scene:
        for name in data:
            if name not in TOP_LEVEL_TABLES:
                raise SceneError(
                    "unknown table; the tables are " + ", ".join(TOP_LEVEL_TABLES),
                    file=self.file,
                    table=f"[{quote_key(name)}]",
                    line=self.lines.locate((), None, name),
                    suggestion=suggest(name, TOP_LEVEL_TABLES),
                )
        camera = self.camera(self.table(data, "camera"))
        settings, background, sky = self.render(self.table(data, "render"))
        for name, t in self.named_tables(data, "textures").items():
            self.textures[name] = self.texture(Where.table("textures", name), t)
        for name, t in self.named_tables(data, "materials").items():
            self.materials[name] = self.material(Where.table("materials", name), t)
        objects = []
        for i, t in enumerate(self.array_of_tables(data, "objects")):
            w = Where.array("objects", i)
            if t.get("type") == "mesh":
                objects.extend(self.mesh(w, t))
            else:
                objects.append(self.object(w, t))
        lights = [
            self.light(Where.array("lights", i), t)
            for i, t in enumerate(self.array_of_tables(data, "lights"))
        ]
        scene = Scene(
            objects, lights, background, sky, camera=camera, settings=settings, name=self.path.stem
        )
        scene.files = tuple(self.files)
        return scene

    def camera(self, t: dict) -> Camera:
        w = Where.table("camera")
        self.check_keys(w, t, CAMERA_KEYS)
        look_from = self.vec3(w, "look_from", t.get("look_from", [0, 0, 0]))
        look_at = self.vec3(w, "look_at", t.get("look_at", [0, 0, -1]))
        vup = self.vec3(w, "vup", t.get("vup", [0, 1, 0]), checks.edge)
        vfov = self.number(w, "vfov", t.get("vfov", 90), VFOV)
        aspect = self.aspect_ratio(w, t.get("aspect_ratio", 16.0 / 9.0))
        width = self.setting(w, "width", t.get("width", SETTINGS["width"].default))
        defocus = self.number(w, "defocus_angle", t.get("defocus_angle", 0), DEFOCUS_ANGLE)
        focus = self.number(w, "focus_distance", t.get("focus_distance", 10), LENGTH)

        height = width / aspect
        if not height < MAX_HEIGHT + 1:
            raise self.fail(
                w,
                "aspect_ratio",
                f"width {width} / aspect_ratio {checks.num_text(aspect)} gives an image height of "
                f"{checks.num_text(int(height)) if math.isfinite(height) else 'inf'} pixels; "
                f"the most is {MAX_HEIGHT}",
            )
        try:
            return Camera(look_from, look_at, vup, vfov, aspect, width, defocus, focus)
        except (ValueError, ArithmeticError) as e:
            raise self.fail(w, *_blame(str(e), CAMERA_KEYS)) from None

    def aspect_ratio(self, w: Where, v: Any) -> float:
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
            v = a / b
        elif not checks.is_number(v):
            raise self.expected(w, "aspect_ratio", what, v)
        return self.number(w, "aspect_ratio", v, ASPECT_RATIO)

    def render(self, t: dict) -> tuple[RenderSettings, Color, bool]:
        """The settings, the background and sky of a [render] table."""
        w = Where.table("render")
        self.check_keys(w, t, RENDER_KEYS)
        given = {key: self.setting(w, key, v) for key, v in t.items()}
        background = given.pop("background", SETTINGS["background"].default)
        sky = given.pop("sky", SETTINGS["sky"].default)
        return RenderSettings(**given), background, sky

    def texture(self, w: Where, t: dict) -> Texture:
        kind = self.type_of(w, t, TEXTURE_KEYS, "texture")
        self.check_keys(w, t, TEXTURE_KEYS[kind], f'type "{kind}"')
        if kind == "solid":
            return SolidColor(self.color(w, "color", self.require(w, t, "color", "a colour"), UNIT))
        if kind == "checker":
            scale = self.number(w, "scale", t.get("scale", 1), LENGTH)
            even = self.color(w, "even", self.require(w, t, "even", "a colour"), UNIT)
            odd = self.color(w, "odd", self.require(w, t, "odd", "a colour"), UNIT)
            return CheckerTexture(scale, even, odd)
        return self.image(w, t)

    def image(self, w: Where, t: dict) -> Texture:
        rel = self.require(w, t, "path", "the path of a PNG or JPEG file")
        if not isinstance(rel, str) or not rel:
            raise self.expected(w, "path", "the path of a PNG or JPEG file", rel)
        try:
            resolved = self.path.parent / rel
            if resolved.is_dir():
                raise self.fail(w, "path", f"{resolved} is a directory, not an image file")
            if not resolved.exists():
                raise self.fail(w, "path", f"image file not found: {resolved}")
            self.files.append(resolved)
            import io

            from PIL import Image

            data = read_bytes(resolved, MAX_TEXTURE_BYTES)  # a regular file, bounded
            with Image.open(io.BytesIO(data)) as im:
                size = im.size
            if size[0] * size[1] > MAX_TEXTURE_PIXELS:
                raise self.fail(
                    w,
                    "path",
                    f"image {resolved} has {size[0]} x {size[1]} pixels; "
                    f"the most for a texture is {MAX_TEXTURE_PIXELS}",
                )
            return ImageTexture.from_file(io.BytesIO(data))
        except SceneError:
            raise
        except OSError as e:  # not a regular file, too large
            raise self.fail(w, "path", f"cannot read image {resolved}: {e.strerror or e}") from None
        except Exception as e:  # PIL raises many kinds for unreadable files
            raise self.fail(w, "path", f"cannot read image {self.path.parent / rel}: {e}") from None

    def material(self, w: Where, t: dict) -> Any:
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
            raise self.fail(w, *_blame(one_line(str(e)), params)) from None
        except (Exception, SystemExit) as e:  # a plugin's constructor, whatever it raises
            raise self.fail(
                w, "type", f'the "{kind}" constructor failed: {plugin_failure(e)}'
            ) from None

    def material_value(self, w: Where, p: Param, v: Any) -> Any:
        rng = MATERIAL_RANGES.get(p.name, ANY)
        if p.kind == "albedo":
            if isinstance(v, str):
                if v not in self.textures:
                    defined = ", ".join(self.textures) or "none"
                    raise self.fail(
                        w,
                        p.name,
                        f"no texture named {json.dumps(v, ensure_ascii=False)} "
                        f"([textures.{quote_key(v)}]); "
                        f"textures defined: {defined}",
                        suggest(v, self.textures),
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
        if checks.is_number(v) and isinstance(v, float) and not math.isfinite(v):
            raise self.expected(w, p.name, "a finite number", v)
        return v

    def reference(self, w: Where, t: dict) -> Any:
        name = self.require(w, t, "material", "the name of a [materials.NAME] table")
        if not isinstance(name, str):
            raise self.expected(w, "material", "the name of a [materials.NAME] table", name)
        if name not in self.materials:
            defined = ", ".join(self.materials) or "none"
            raise self.fail(
                w,
                "material",
                f"no material named {json.dumps(name, ensure_ascii=False)} "
                f"([materials.{quote_key(name)}]); "
                f"materials defined: {defined}",
                suggest(name, self.materials),
            )
        return self.materials[name]

    def object(self, w: Where, t: dict) -> Any:
        kind = self.type_of(w, t, OBJECT_KEYS, "object")
        self.check_keys(w, t, OBJECT_KEYS[kind], f'type "{kind}"')

        def point(key: str) -> Vec3:
            check = checks.edge if key in ("u", "v") else checks.point
            return self.vec3(w, key, self.require(w, t, key, "an array of 3 numbers"), check)

        if kind == "sphere":
            center = point("center")
            radius = self.require(w, t, "radius", f"a number {LENGTH.text()}")
            radius = self.number(w, "radius", radius, LENGTH)
            material = self.reference(w, t)
            return self.build(w, "radius", lambda m: Sphere(center, radius, m), material)
        # A quad (q, u, v) or a triangle (a, b, c); a degenerate one is blamed on u or a.
        keys = OBJECT_KEYS[kind][1:4]
        corners = [point(key) for key in keys]
        found = ", ".join(f"{k} = {describe(list(p))}" for k, p in zip(keys, corners, strict=True))
        shape = Quad if kind == "quad" else Triangle
        blamed = "u" if kind == "quad" else "a"
        return self.build(
            w, blamed, lambda m: shape(*corners, m), self.reference(w, t), f" ({found})"
        )

    def mesh(self, w: Where, t: dict) -> list:
        """The triangles of a [[objects]] table of type "mesh" (an OBJ or PLY file)."""
        self.check_keys(w, t, OBJECT_KEYS["mesh"], 'type "mesh"')
        what = "the path of a Wavefront OBJ or PLY file"
        rel = self.require(w, t, "path", what)
        if not isinstance(rel, str) or not rel:
            raise self.expected(w, "path", what, rel)
        translate = self.vec3(w, "translate", t.get("translate", [0, 0, 0]))
        rotate = self.vec3(w, "rotate", t.get("rotate", [0, 0, 0]), checks.angles)
        scale = t.get("scale", 1)
        if checks.is_number(scale):
            scale = [scale] * 3
        elif not isinstance(scale, list):
            raise self.expected(w, "scale", "a number or an array of 3 numbers", scale)
        scale = self.vec3(w, "scale", scale, checks.scales)
        material = self.reference(w, t)
        resolved = self.path.parent / rel
        self.files.append(resolved)
        transform = self.build(w, "scale", lambda _: Transform(translate, rotate, scale), None)
        kind, a_kind = ("PLY", "a PLY") if resolved.suffix.lower() == ".ply" else ("OBJ", "an OBJ")
        try:
            mesh, faces = load_mesh(resolved, material, transform)
        except FileNotFoundError:
            raise self.fail(w, "path", f"{kind} file not found: {resolved}") from None
        except IsADirectoryError:
            raise self.fail(w, "path", f"{resolved} is a directory, not {a_kind} file") from None
        except OSError as e:
            raise self.fail(w, "path", f"cannot read {resolved}: {e.strerror or e}") from None
        except (ObjError, PlyError) as e:
            at = f" line {e.line}" if e.line is not None else ""
            raise self.fail(w, "path", f"{resolved}{at}: {e.detail}") from None
        except (ValueError, ArithmeticError) as e:  # a vertex out of range once placed
            raise self.fail(w, "scale", str(e)) from None
        if not len(mesh):
            detail = f"all {faces} faces are degenerate" if faces else "it has no faces"
            raise self.fail(w, "path", f"empty mesh {resolved}: {detail}")
        if mesh.skipped:
            faces = "face" if mesh.skipped == 1 else "faces"
            warnings.warn(
                self.fail(
                    w, "path", f"skipped {mesh.skipped} degenerate {faces} of {resolved}"
                ).as_warning(),
                stacklevel=2,
            )
        # A light is one shape: an emitting mesh is its triangles, each an area light.
        return mesh.triangles if getattr(material, "is_emitter", False) else [mesh]

    def build(
        self, w: Where, key: str, make: Callable[[Any], Any], material: Any, found: str = ""
    ) -> Any:
        try:
            return make(material)
        except (ValueError, ArithmeticError) as e:
            raise self.fail(w, key, f"{e}{found}") from None

    def light(self, w: Where, t: dict) -> PointLight:
        kind = self.type_of(w, t, LIGHT_KEYS, "light")
        self.check_keys(w, t, LIGHT_KEYS[kind], f'type "{kind}"')
        position = self.vec3(w, "position", self.require(w, t, "position", "an array of 3 numbers"))
        intensity = self.color(
            w,
            "intensity",
            self.require(w, t, "intensity", f"a colour, each component {RADIANCE.text()}"),
            RADIANCE,
        )
        return PointLight(position, intensity)


def _blame(message: str, keys: Iterable[str]) -> tuple[str | None, str]:
    """The key a constructor's error message talks about, if it names one, and the
    message: a parameter that starts it ("key: ...") is that key, and is then left
    out of the message (the SceneError names it)."""
    keys = list(keys)
    first = re.match(r"(\w+): ", message)
    if first and first.group(1) in keys:
        return first.group(1), message[first.end() :]
    for key in keys:
        if re.search(rf"\b{re.escape(key)}\b", message):
            return key, message
    return None, message


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
        table, key = TomlLines(text).context(line)
    detail = "TOML syntax error: " + message[:1].lower() + message[1:]
    if column is not None:
        detail += f" at column {column}"
    return SceneError(detail, file=str(path), table=table, key=key, line=line)


def load_scene(path: str | Path) -> Scene:
    """A Scene from a scene file (TOML, UTF-8)."""
    path = Path(path)
    try:
        raw = read_bytes(path, MAX_SCENE_BYTES)  # a regular file (a FIFO is not waited on)
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
