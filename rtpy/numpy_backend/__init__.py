"""Vectorized numpy backend: renders the same images as the scalar renderer (up to
Monte Carlo noise), tracing many rays per numpy call."""

from .hits import HitBatch
from .materials import MaterialTable, ScatterBatch
from .textures import TextureTable

__all__ = ["HitBatch", "MaterialTable", "ScatterBatch", "TextureTable"]
