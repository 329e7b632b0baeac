"""rtpy.render: what a render is asked for, checked once, and the Renderer it makes.

This is the boundary of the render loop for Python and for the command line
(rtpy.cli.main calls prepare_render): every value a caller gives is checked here, a
wrong type raising TypeError and a value out of range ValueError, each naming the
parameter (a render setting's SettingError names the setting, which the command
line turns into its option); the loop below (rtpy.engine.renderer) trusts them.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from ..camera import Camera
from ..render_settings import SETTINGS, RenderSettings, SettingValueError
from ..scene import Scene
from .writer import writer

if TYPE_CHECKING:
    from .rendered_image import RenderedImage
    from .renderer import Renderer

__all__ = ["AspectError", "prepare_render", "render"]


class AspectError(SettingValueError):
    """A width that the camera's aspect ratio turns into an image out of the limits."""

    def __init__(self, width: int, reason: str) -> None:
        self.width, self.reason = width, reason
        super().__init__("width", f"{width} with the camera's aspect ratio: {reason}")


def render(scene: Scene, **options) -> RenderedImage:
    """Render `scene` and return the image (linear array + PIL image).

    Keyword overrides: any [render] setting (integrator, spp, max_depth, nee,
    russian_roulette, seed, gamma, mis, sampler, time_limit), background, sky, the
    camera width, or a whole `camera` (default: the scene's, else rtpy.Camera(): at
    the origin looking down -z, as RTIOW's first images). workers = number of processes
    (rtpy.engine.workers.available_cpus() is how many this process may use). progress=True
    shows a progress bar (a notebook's widget in Jupyter, else text on stderr); none
    by default; quiet is its negation (quiet=False shows it).
    backend = "scalar" (the readable reference) or "numpy" (vectorized, many times
    faster; the same image up to Monte Carlo noise). A setting of the wrong type
    raises TypeError, one out of its range ValueError, naming the setting
    (rtpy.render_settings.SETTINGS lists them with their limits).
    preview shows the image while it renders, at most every preview_seconds: a .png
    or .jpg file name (rewritten atomically), True (in a Jupyter notebook, an output
    that each preview replaces) or a function called with the image so far
    (rtpy.io.preview.preview_target).
    time = seconds (the `time_limit` setting): whole passes until they are spent, at
    least one; the image says how many samples it holds (image.samples_min).
    cluster = "local" (a Dask LocalCluster of `workers` processes), a Dask
    scheduler's address ("tcp://host:8786") or a distributed.Client: the units run
    there (docs/cluster.md; pip install 'rtpy[cluster]'), the same image bit for bit.
    cluster_timeout = the seconds to reach a scheduler (None: CLUSTER_TIMEOUT, 5, of
    rtpy.engine.cluster); an address that is not tcp://HOST:PORT is a ValueError
    naming cluster, before Dask is asked.
    checkpoint = a file where the render keeps its whole passes as it goes and when
    it stops (Ctrl-C, time), removed when it finishes; resume=True continues the
    render kept there (ValueError if it holds another one), bit for bit the image
    of an uninterrupted render (rtpy.engine.render_state).
    """
    renderer = prepare_render(scene, **options)
    try:
        image = renderer.render()
    except NotImplementedError as err:  # a task not written yet: one line, not two tracebacks
        from .unfinished import find_unfinished, what_renders_now

        if find_unfinished(err) is None:
            raise
        now = what_renders_now(renderer, "integrator={!r}")
        raise NotImplementedError(f"{err.args[0]}; {now}") from None
    if renderer.checkpoint is not None and image.stats["stopped"] is None:
        renderer.checkpoint.remove()
    return image


def prepare_render(
    scene: Scene,
    *,
    camera: Camera | None = None,
    width: int | None = None,
    workers: int = 1,
    progress: bool | None = None,
    quiet: bool | None = None,
    background=None,
    sky: bool | None = None,
    backend: str = "scalar",
    preview: object = None,
    preview_seconds: float = 5.0,
    time: float | None = None,
    cluster: object = None,
    cluster_timeout: float | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    resume: bool = False,
    **settings,
) -> Renderer:
    """The Renderer of render(scene, ...), every value checked (render's parameters)."""
    from .._checks import Range, checked, integer
    from .backend import make_backend
    from .renderer import Renderer

    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a Scene, found a {type(scene).__name__}")
    if camera is not None and not isinstance(camera, Camera):
        raise TypeError(f"camera: expected a Camera or None, found a {type(camera).__name__}")
    workers = checked("workers", integer, workers, Range(1))
    show_progress = _show_progress(progress, quiet)
    if time is not None:
        if "time_limit" in settings:
            raise ValueError("time and time_limit are one setting: pass one of them")
        settings["time_limit"] = time
    render_settings = (scene.settings or RenderSettings()).with_overrides(**settings)
    camera = _camera(scene, camera, width)
    scene = _scene_with(scene, background, sky)
    if not (isinstance(preview_seconds, int | float) and preview_seconds >= 0.0):
        raise ValueError(f"preview_seconds must be a number >= 0, got {preview_seconds!r}")
    if not isinstance(resume, bool):
        raise TypeError(f"resume must be True or False, got {resume!r}")
    if resume and checkpoint is None:
        raise ValueError("resume: continues the render kept in a checkpoint: pass checkpoint=")
    chosen = make_backend(backend, scene, camera, render_settings)
    executor = None
    if cluster is not None:
        from .cluster import make_cluster

        executor = make_cluster(cluster, workers, cluster_timeout)
    return Renderer(
        scene,
        camera,
        render_settings,
        workers=workers,
        quiet=not show_progress,
        backend=chosen,
        preview=_preview(preview, scene),
        preview_seconds=float(preview_seconds),
        executor=executor,
        time_limit=render_settings.time_limit,
        checkpoint=_checkpoint(checkpoint, chosen),
        resume=resume,
    )


def _camera(scene: Scene, camera: Camera | None, width) -> Camera:
    # A scene built in code has no camera of its own: RTIOW's first one, at the origin
    # looking down -z, 90 degrees vertical field of view, 400 wide, 16:9.
    camera = camera or scene.camera or Camera()
    if width is None:
        return camera
    width = SETTINGS["width"].check(width)
    try:
        return camera.with_width(width)
    except ValueError as err:
        raise AspectError(width, str(err)) from None


def _scene_with(scene: Scene, background, sky) -> Scene:
    """The scene, or a copy with another background or sky."""
    if background is None and sky is None:
        return scene
    import copy

    scene = copy.copy(scene)
    if background is not None:
        scene.background = SETTINGS["background"].check(background)
    if sky is not None:
        scene.sky = SETTINGS["sky"].check(sky)
    return scene


def _preview(preview, scene: Scene):
    """A function of the image so far, or None: a file name or True made into one by
    the preview writer, rtpy.io.preview's (a function or None is one already: the
    command line's)."""
    if preview is None or (callable(preview) and not isinstance(preview, bool)):
        return preview
    return writer("preview")(preview, scene.files)


def _checkpoint(path, backend):
    if path is None:
        return None
    from .files import check_writable
    from .render_state import Checkpoint

    if not isinstance(path, str | os.PathLike):
        raise TypeError(f"checkpoint must be a file name or None, got {path!r}")
    return Checkpoint(check_writable(path), backend)


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
