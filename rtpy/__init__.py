"""rtpy: a ray tracer in Python for teaching.

    import rtpy
    scene = rtpy.load_scene("cornell")        # a path or a bundled scene's name
    image = rtpy.render(scene, spp=16, width=200)
    image.save("cornell.png")                 # image.linear is the float array

The modules follow the course's structure: vec3 / interval / ray / hit_info /
scatter_info (utilities), camera, sphere / quad / triangle / scene (hittables),
materials, light, texture, integrators; the render engine is rtpy.engine.
docs/course-map.md says where each name of the course's code is;
docs/scene-format.md is the scene-file format.

This module is the package's front door (see tests/test_layout.py's FLOORS): it
exports the API of every floor, and imports rtpy.engine.backends and rtpy.io.writers
so that the engine finds its backends and its image writers (rtpy.engine.backend,
rtpy.engine.writer) by registration.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .engine import signals

if signals.starting_the_command_line():
    signals.defer()  # before the imports below: see rtpy/engine/signals.py

from .camera import Camera
from .engine.backends import BACKENDS
from .engine.plugins import load_plugin
from .engine.render_request import render
from .hit_info import HitInfo
from .interval import Interval
from .io import writers as _writers  # noqa: F401 (registers RenderedImage.save's formats)
from .light import PointLight
from .materials import (
    Blinn,
    BlinnPhong,
    CookTorrance,
    Dielectric,
    DiffuseLight,
    Lambertian,
    Material,
    Metal,
    Mirror,
    OrenNayar,
    Phong,
    RoughDielectric,
    Ward,
    register_material,
)
from .mesh import Mesh, SmoothTriangle, Transform
from .quad import Quad
from .ray import Ray
from .render_settings import SETTINGS, RenderSettings
from .scatter_info import ScatterInfo
from .scene import Scene
from .sphere import Sphere
from .texture import CheckerTexture, ImageTexture, SolidColor, Texture
from .triangle import Triangle
from .vec3 import Color, Point3, Vec3

if TYPE_CHECKING:
    from .engine.rendered_image import RenderedImage
    from .engine.renderer import Renderer

# Imported on first use: `import rtpy` loads neither numpy, Pillow nor tqdm, which
# only rendering and writing images need (a command starts sooner without them).
_LAZY = {
    "RenderedImage": ".engine.rendered_image",
    "Renderer": ".engine.renderer",
    "ladder": ".io.ladder",
    "mesh_from_obj": ".io.obj",
    "mesh_from_ply": ".io.ply",
}


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        value = getattr(import_module(_LAZY[name], __name__), name)
    elif name == "__version__":
        from .engine.version import version

        value = version()
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY, "__version__"})


def load_scene(path_or_name: str):
    """Load a scene file (TOML, see docs/scene-format.md) or a bundled scene by name."""
    from .io.bundled import resolve_scene
    from .io.scene_file import load_scene as _load

    return _load(resolve_scene(str(path_or_name)))


__all__ = [
    # the course's utilities
    "Vec3",
    "Color",
    "Point3",
    "Interval",
    "Ray",
    "HitInfo",
    "ScatterInfo",
    # the scene
    "Camera",
    "Scene",
    "Sphere",
    "Quad",
    "Triangle",
    "SmoothTriangle",
    "Mesh",
    "Transform",
    "mesh_from_obj",
    "mesh_from_ply",
    "PointLight",
    # materials and textures
    "Material",
    "Lambertian",
    "Mirror",
    "Metal",
    "Dielectric",
    "RoughDielectric",
    "DiffuseLight",
    "Phong",
    "Blinn",
    "BlinnPhong",
    "OrenNayar",
    "CookTorrance",
    "Ward",
    "register_material",
    "Texture",
    "SolidColor",
    "CheckerTexture",
    "ImageTexture",
    # rendering
    "BACKENDS",
    "SETTINGS",
    "RenderSettings",
    "Renderer",
    "RenderedImage",
    "load_plugin",
    "load_scene",
    "render",
    "ladder",
]
