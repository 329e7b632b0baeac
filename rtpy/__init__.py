"""rtpy: a ray tracer in Python for teaching.

    import rtpy
    scene = rtpy.load_scene("cornell")        # a path or a bundled scene's name
    image = rtpy.render(scene, spp=16, width=200)
    image.save("cornell.png")                 # image.linear is the float array

The modules follow the course's structure: vec3 / interval / ray / hit_info /
scatter_info (utilities), camera, sphere / quad / triangle / scene (hittables),
materials, light, texture, integrators, renderer. docs/course-map.md says where
each name of the course's code is; docs/scene-format.md is the scene-file format.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import signals

if signals.starting_the_command_line():
    signals.defer()  # before the imports below: see rtpy/signals.py

from .camera import Camera
from .hit_info import HitInfo
from .interval import Interval
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
    Ward,
    register_material,
)
from .mesh import Mesh, SmoothTriangle, Transform
from .plugins import load_plugin
from .quad import Quad
from .ray import Ray
from .render_settings import BACKENDS, SETTINGS, RenderSettings
from .scatter_info import ScatterInfo
from .scene import Scene
from .sphere import Sphere
from .texture import CheckerTexture, ImageTexture, SolidColor, Texture
from .triangle import Triangle
from .vec3 import Color, Point3, Vec3

if TYPE_CHECKING:
    from .io.image import RenderedImage
    from .renderer import Renderer

# Imported on first use: `import rtpy` loads neither numpy, Pillow nor tqdm, which
# only rendering and writing images need (a command starts sooner without them).
_LAZY = {"RenderedImage": ".io.image", "Renderer": ".renderer"}


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        value = getattr(import_module(_LAZY[name], __name__), name)
    elif name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            value = version("rtpy")  # pyproject.toml's version, as installed
        except PackageNotFoundError:  # a source tree that was never installed
            value = "0+unknown"
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


def render(
    scene: Scene,
    *,
    camera: Camera | None = None,
    width: int | None = None,
    workers: int = 1,
    progress: bool | None = None,
    quiet: bool | None = None,
    background: Color | None = None,
    sky: bool | None = None,
    backend: str = "scalar",
    preview: object = None,
    preview_seconds: float = 5.0,
    **settings,
) -> RenderedImage:
    """Render `scene` and return the image (linear array + PIL image).

    Keyword overrides: any [render] setting (integrator, spp, max_depth, nee,
    russian_roulette, seed, gamma, mis), background, sky, the camera width, or a
    whole `camera`. workers = number of processes (rtpy.workers.available_cpus()
    is how many this process may use). progress=True shows a progress bar (a
    notebook's widget in Jupyter, else text on stderr); none by default; quiet is
    its negation (quiet=False shows it).
    backend = "scalar" (the readable reference) or "numpy" (vectorized, many times
    faster; the same image up to Monte Carlo noise). A setting of the wrong type
    raises TypeError, one out of its range ValueError, naming the setting
    (rtpy.render_settings.SETTINGS lists them with their limits).
    preview shows the image while it renders, at most every preview_seconds: a .png
    or .jpg file name (rewritten atomically), True (in a Jupyter notebook, an output
    that each preview replaces) or a function called with the image so far
    (rtpy.io.preview.preview_target).
    """
    from .io.preview import preview_target
    from .io.values import Range, checked, integer
    from .renderer import Renderer

    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a Scene, found a {type(scene).__name__}")
    if camera is not None and not isinstance(camera, Camera):
        raise TypeError(f"camera: expected a Camera or None, found a {type(camera).__name__}")
    workers = checked("workers", integer, workers, Range(1))
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(BACKENDS)}; got {backend!r}")
    show_progress = _show_progress(progress, quiet)
    base = scene.settings or RenderSettings()
    render_settings = base.with_overrides(**settings)
    camera = camera or scene.camera
    if camera is None:
        raise ValueError("the scene has no camera: pass camera=rtpy.Camera(...)")
    if width is not None:
        camera = camera.with_width(SETTINGS["width"].check(width))
    if background is not None or sky is not None:
        import copy

        scene = copy.copy(scene)
        if background is not None:
            scene.background = SETTINGS["background"].check(background)
        if sky is not None:
            scene.sky = SETTINGS["sky"].check(sky)
    renderer = Renderer(
        scene,
        camera,
        render_settings,
        workers=workers,
        quiet=not show_progress,
        backend=backend,
        preview=preview_target(preview, scene.files),
        preview_seconds=preview_seconds,
    )
    return renderer.render()


def _show_progress(progress: bool | None, quiet: bool | None) -> bool:
    """render()'s progress and quiet (either, or both when they agree) -> show a bar."""
    for name, value in (("progress", progress), ("quiet", quiet)):
        if value is not None and not isinstance(value, bool):
            raise TypeError(f"{name} must be True or False, got {value!r}")
    if progress is not None and quiet is not None and progress == quiet:
        raise ValueError(f"progress={progress} contradicts quiet={quiet}: pass one of them")
    if progress is not None:
        return progress
    return quiet is False


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
    "PointLight",
    # materials and textures
    "Material",
    "Lambertian",
    "Mirror",
    "Metal",
    "Dielectric",
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
    "RenderSettings",
    "Renderer",
    "RenderedImage",
    "load_plugin",
    "load_scene",
    "render",
]
