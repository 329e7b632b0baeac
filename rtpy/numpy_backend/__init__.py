"""The numpy backend: renders the scalar renderer's images (up to Monte Carlo noise),
tracing many rays per numpy call. Its modules mirror rtpy's, file for file where a
twin exists (docs/numpy-backend.md has the table); render with
rtpy.render(..., backend="numpy")."""

from .camera import CameraRays
from .hit_info import HitBatch
from .integrators import INTEGRATORS, BatchIntegrator, make_integrator
from .light import LightTable
from .materials import MaterialTable
from .renderer import NumpyBackend
from .scatter_info import ScatterBatch
from .scene import BatchScene
from .texture import TextureTable

__all__ = [
    "INTEGRATORS",
    "BatchIntegrator",
    "BatchScene",
    "CameraRays",
    "HitBatch",
    "LightTable",
    "MaterialTable",
    "NumpyBackend",
    "ScatterBatch",
    "TextureTable",
    "make_integrator",
]
