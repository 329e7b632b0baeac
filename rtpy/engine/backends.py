"""The backends rtpy comes with, registered by name (rtpy.engine.backend.register_backend):

- "scalar": the readable reference, one Ray at a time through the course's
  integrators (rtpy.engine.scalar_backend);
- "numpy": its vectorized twin, tracing many rays per numpy call
  (rtpy.numpy_backend), the same image up to Monte Carlo noise.

Each is imported when a render asks for it: a command that renders with the scalar
backend loads none of the numpy backend, and the weekly assignment repositories hold
a stub of the numpy backend whose NumpyBackend says it is withheld.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .backend import BACKEND_REGISTRY, register_backend

if TYPE_CHECKING:
    from .backend import Backend

__all__ = ["BACKENDS"]


@register_backend("scalar")
def make_scalar(scene, camera, settings) -> Backend:
    """The readable reference (rtpy.engine.scalar_backend.ScalarBackend)."""
    from .scalar_backend import ScalarBackend

    return ScalarBackend(scene, camera, settings)


@register_backend("numpy")
def make_numpy(scene, camera, settings) -> Backend:
    """The vectorized twin (rtpy.numpy_backend.renderer.NumpyBackend)."""
    from ..numpy_backend.renderer import NumpyBackend

    return NumpyBackend(scene, camera, settings)


BACKENDS: tuple[str, ...] = tuple(BACKEND_REGISTRY)  # the names rtpy comes with
