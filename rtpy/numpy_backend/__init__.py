"""Vectorized numpy backend: renders the same images as the scalar renderer (up to
Monte Carlo noise), tracing many rays per numpy call."""

from .hits import HitBatch
from .materials import MaterialTable, ScatterBatch
from .textures import TextureTable

__all__ = ["HitBatch", "MaterialTable", "ScatterBatch", "TextureTable"]

# Geometry, camera, lights, integrators and the renderer.
from .camera import CameraRays  # noqa: E402
from .geometry import Geometry  # noqa: E402
from .integrators import INTEGRATORS, Tracer  # noqa: E402
from .lights import LightTable  # noqa: E402
from .render import NumpyRenderer  # noqa: E402

__all__ += ["INTEGRATORS", "CameraRays", "Geometry", "LightTable", "NumpyRenderer", "Tracer"]
