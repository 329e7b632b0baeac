"""Kernel: the batched twin of one material class (rtpy/materials/material.py).

A kernel serves every instance of its material class in a scene: it holds their
parameters as arrays indexed by slot (the instance's position in `materials`), and
each method gets the slot of every hit and gathers the parameters it needs, so one
call serves any number of instances. The methods are the scalar Material's, for N
hits at once:

    flat_color(slots, hits)        -> (N, 3)   Material.flat_color
    emitting(slots, hits)          -> (N, 3)   Material.emitting
    BRDF(slots, hits, wi)          -> (N, 3)   Material.BRDF, wi (N, 3) toward the light
    pdf(slots, hits, wi)           -> (N,)     Material.pdf
    BRDF_and_pdf(slots, hits, wi)  -> both, sharing the work (for light sampling)
    scattering(slots, hits, rng)   -> ScatterBatch   Material.scattering
    specular_rays(slots, hits)     -> SpecularRays   Material.specular_rays

The viewer's direction is hits.wo (-ray_view.direction), and the light's is wi
(ray_light.direction). The defaults are those of the scalar Material base class: no
scattering, no BRDF, no emission, white flat colour; the flags let the table skip
calls that would return them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...materials.material import Material
from ..arrays import Rows
from ..hit_info import HitBatch
from ..scatter_info import ScatterBatch, SpecularRays
from ..texture import TextureTable

INV_PI = 1.0 / math.pi


class Kernel:
    """Batched twin of one material class, for all its instances in a table."""

    has_brdf = False  # BRDF() and pdf() can be non-zero (not a delta material)
    scatters = False  # scattering() can return live samples
    emits = False  # emitting() can be non-zero
    has_specular_rays = False  # specular_rays() can return rays
    reads_tangent = False  # a method reads hits.tangent (a shading frame)
    reads_uv = False  # a method reads hits.u, hits.v (a texture)

    def __init__(self, materials: Sequence[Material]) -> None:
        self.materials = list(materials)

    def flat_color(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return np.ones((len(slots), 3))

    def emitting(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return np.zeros((len(slots), 3))

    def BRDF(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        return np.zeros((len(slots), 3))

    def pdf(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        return np.zeros(len(slots))

    def BRDF_and_pdf(
        self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(BRDF(), pdf()) at once, what light sampling asks for; kernels whose two
        share work (a shading frame, a cosine) override it."""
        return self.BRDF(slots, hits, wi), self.pdf(slots, hits, wi)

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        return ScatterBatch.absorbed(len(slots))

    def specular_rays(self, slots: np.ndarray, hits: HitBatch) -> SpecularRays:
        return []


class AlbedoKernel(Kernel):
    """A kernel whose materials have a texture `albedo` (the flat colour)."""

    def __init__(self, materials: Sequence[Material]) -> None:
        super().__init__(materials)
        self.albedo_table = TextureTable([m.albedo for m in self.materials])
        self.reads_uv = self.albedo_table.reads_uv

    def albedo(self, slots: np.ndarray, hits: HitBatch, rows: Rows = slice(None)) -> np.ndarray:
        """(n, 3) albedo of the instances `slots` at the hits `rows` of `hits`."""
        return self.albedo_table.value(slots, hits, rows)

    def flat_color(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return self.albedo(slots, hits)


def param(materials: Sequence[Material], name: str) -> np.ndarray:
    """(M,) float array of one scalar parameter of every instance."""
    return np.array([float(getattr(m, name)) for m in materials])


def color_param(materials: Sequence[Material], name: str) -> np.ndarray:
    """(M, 3) float array of one colour parameter of every instance."""
    return np.array([tuple(getattr(m, name)) for m in materials], dtype=np.float64).reshape(-1, 3)
