"""Backends: ways of rendering a unit of work, registered by name.

The render loop (rtpy.engine.renderer) drives every backend the same way: it asks the
backend for the plan of a render (how the image and the samples are cut into units
of work, rtpy.engine.plan) and has an executor (rtpy.engine.executor) run the units, each by the
backend's start() in the process that runs it. A backend is registered under its
name with @register_backend; rtpy.engine.backends registers the two that come with rtpy,
"scalar" (the readable reference) and "numpy" (its vectorized twin).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from .plan import Plan, Unit

if TYPE_CHECKING:
    import numpy as np

    from ..camera import Camera
    from ..render_settings import RenderSettings
    from ..scene import Scene

__all__ = ["BACKEND_REGISTRY", "Backend", "make_backend", "register_backend"]


class Backend:
    """A way of rendering units of work; rtpy.engine.renderer's one loop drives every backend.

    A backend plans the units and renders one unit; the loop does the rest, the same
    for all: the executor (this process, worker processes, a cluster), the progress
    bar, previews, Ctrl-C, time limits, resuming and the assembly of the image. The
    backend is pickled to every worker, which calls start() once and then renders
    units.

    name            the name it is registered under (the progress bar and image.stats
                    show it)
    paths_per_unit  the most camera paths in one unit of work
    """

    name = ""
    paths_per_unit = 4096

    def __init__(self, scene: Scene, camera: Camera, settings: RenderSettings) -> None:
        self.scene = scene
        self.camera = camera
        self.settings = settings

    def make_integrator(self):
        """The integrator the settings name, in this backend's kind."""
        raise NotImplementedError

    def uses_center_ray(self) -> bool:
        """The integrator traces one ray through each pixel's center (spp = 1)."""
        return self.make_integrator().uses_center_ray

    def plan(self, width: int, height: int, spp: int) -> Plan:
        """The passes and units of work covering every pixel with spp samples."""
        return Plan(width, height, spp, self.paths_per_unit)

    def start(self) -> Callable[[Unit], np.ndarray]:
        """Prepare this process to render (called once in each process that renders)
        and return the function that renders one unit: the sum of unit.spp radiance
        samples per pixel of its region, an array (height, width, 3)."""
        raise NotImplementedError


# name -> what makes the backend: a Backend class, or a function taking the same
# (scene, camera, settings) that returns one.
BACKEND_REGISTRY: dict[str, Callable[..., Backend]] = {}


def register_backend(name: str):
    """Decorator: register a Backend class (or a function that makes one) as `name`."""
    if not (isinstance(name, str) and name.isidentifier()):
        raise ValueError(f"a backend's name must be an identifier, got {name!r}")

    def decorate(make: Callable[..., Backend]) -> Callable[..., Backend]:
        BACKEND_REGISTRY[name] = make
        return make

    return decorate


def make_backend(name: str, scene: Scene, camera: Camera, settings: RenderSettings) -> Backend:
    """The backend registered as `name`, for a render; ValueError naming the
    registered ones if there is none."""
    make = BACKEND_REGISTRY.get(name) if isinstance(name, str) else None
    if make is None:
        names = ", ".join(BACKEND_REGISTRY)
        raise ValueError(f"backend must be one of {names}; got {name!r}")
    return make(scene, camera, settings)
