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
from ..arrays import Rows, compose, put_rows, rows, select
from ..hit_info import HitBatch
from ..onb import ONB
from ..scatter_info import ScatterBatch, SpecularRays
from ..texture import TextureTable
from ..vec3 import Columns, components, dot, negative, take

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

    def above(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray | None = None) -> Bounce:
        """The hits whose viewer lies above the surface (normal . wo > 0), where
        scattering() can draw a direction; given the light's directions wi (N, 3), the
        hits where wi lies above too, where BRDF() can be non-zero (the check the
        scalar methods make first)."""
        normal, wo = components(hits.normal), components(hits.wo)
        cos_o = dot(normal, wo)
        up = cos_o > 0.0
        if wi is not None:
            wi = components(wi)
            cos_i = dot(normal, wi)
            up &= cos_i > 0.0
        k = select(up)
        s = slots[k]
        b = Bounce(s, hits, k, take(normal, k), take(wo, k), cos_o[k], self.albedo(s, hits, k))
        return b if wi is None else b.toward(take(wi, k), cos_i[k])


class Bounce:
    """Hits as the scalar BRDF(), pdf() and scattering() see them past their first
    check, the viewer above the surface: Columns (see vec3.py) of the rows `rows` of
    a HitBatch `hits`.

    slots          (n,) each hit's material slot
    normal, wo     hit.normal and -ray_view.direction, the unit direction to the viewer
    cos_o          normal . wo (> 0)
    albedo         (n, 3) the albedo's value at each hit
    wi, cos_i      ray_light.direction and normal . wi, once given (toward()); None before
    frame          hit.frame, the shading frame from the normal and the hit's tangent,
                   made on first use
    """

    __slots__ = (
        "slots",
        "hits",
        "rows",
        "normal",
        "wo",
        "cos_o",
        "albedo",
        "wi",
        "cos_i",
        "_frame",
    )

    def __init__(
        self,
        slots: np.ndarray,
        hits: HitBatch,
        rows: Rows,
        normal: Columns,
        wo: Columns,
        cos_o: np.ndarray,
        albedo: np.ndarray,
    ) -> None:
        self.slots, self.hits, self.rows = slots, hits, rows
        self.normal, self.wo, self.cos_o, self.albedo = normal, wo, cos_o, albedo
        self.wi = self.cos_i = None
        self._frame = None

    def __len__(self) -> int:
        return len(self.slots)

    @property
    def d(self) -> Columns:
        """ray_view.direction = -wo, toward the surface."""
        return negative(self.wo)

    @property
    def frame(self) -> ONB:
        if self._frame is None:
            tangent = take(components(self.hits.tangent), self.rows)
            self._frame = ONB.from_normal_tangent(self.normal, tangent)
        return self._frame

    def toward(self, wi: Columns, cos_i: np.ndarray) -> Bounce:
        """These hits with the light's direction wi, cos_i = normal . wi."""
        b = Bounce(self.slots, self.hits, self.rows, self.normal, self.wo, self.cos_o, self.albedo)
        b.wi, b.cos_i, b._frame = wi, cos_i, self._frame
        return b

    def take(self, k: Rows) -> Bounce:
        """The hits k of these."""
        if isinstance(k, slice):
            return self
        b = Bounce(
            self.slots[k],
            self.hits,
            compose(self.rows, k),
            take(self.normal, k),
            take(self.wo, k),
            self.cos_o[k],
            rows(self.albedo, k),
        )
        if self.wi is not None:
            b.wi, b.cos_i = take(self.wi, k), self.cos_i[k]
        if self._frame is not None:
            b._frame = self._frame.take(k)
        return b

    def spread(self, values: np.ndarray, n: int) -> np.ndarray:
        """(n,) or (n, 3) zeros with these hits' `values` at their rows."""
        if isinstance(self.rows, slice):
            return values
        out = np.zeros((n, *values.shape[1:]))
        if values.ndim == 2:
            put_rows(out, self.rows, values)
        else:
            out[self.rows] = values
        return out


def param(materials: Sequence[Material], name: str) -> np.ndarray:
    """(M,) float array of one scalar parameter of every instance."""
    return np.array([float(getattr(m, name)) for m in materials])


def color_param(materials: Sequence[Material], name: str) -> np.ndarray:
    """(M, 3) float array of one colour parameter of every instance."""
    return np.array([tuple(getattr(m, name)) for m in materials], dtype=np.float64).reshape(-1, 3)
