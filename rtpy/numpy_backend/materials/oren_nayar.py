"""Kernel of Oren-Nayar (rtpy/materials/oren_nayar.py): the qualitative rough-diffuse model."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import OrenNayar
from ...materials.oren_nayar import MIN_COS, rough_factor
from ..arrays import select
from ..hit_info import HitBatch
from ..onb import ONB
from ..sampling import cosine_direction
from ..scatter_info import ScatterBatch
from ..vec3 import components, dot, stack
from .material import INV_PI, AlbedoKernel, param


class OrenNayarKernel(AlbedoKernel):
    """albedo / pi (A + B max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta)), sampled
    cosine-weighted (weight albedo * factor)."""

    has_brdf = True
    scatters = True

    def __init__(self, materials: Sequence[OrenNayar]) -> None:
        super().__init__(materials)
        self.A = param(self.materials, "A")
        self.B = param(self.materials, "B")

    def factor(self, slots, cos_o: np.ndarray, cos_i: np.ndarray, cos_oi: np.ndarray):
        """OrenNayar.factor: A + B max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta) from
        cos_o = normal . wo, cos_i = normal . wi and cos_oi = wo . wi, both directions
        above the surface: A + B (the projections' dot product) / (the larger cosine)."""
        a, b = self.A[slots], self.B[slots]
        projected = cos_oi - cos_o * cos_i
        rough = (b != 0.0) & (projected > 0.0)
        larger = np.maximum(np.maximum(cos_i, cos_o), MIN_COS)
        return np.where(rough, rough_factor(a, b, projected, larger), a)

    def BRDF(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        """albedo / pi * factor; black unless wo and wi both lie above the surface."""
        b = self.above(slots, hits, wi)
        k = INV_PI * self.factor(b.slots, b.cos_o, b.cos_i, dot(b.wo, b.wi))
        return b.spread(b.albedo * k[:, None], len(slots))

    def pdf(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        # 0 where the viewer is below the surface (n . d >= 0 for the arriving
        # direction d = -wo): scattering() absorbs there.
        normal = components(hits.normal)
        viewer_above = ~(dot(normal, components(-hits.wo)) >= 0.0)
        return np.where(viewer_above, np.maximum(0.0, dot(normal, components(wi))) * INV_PI, 0.0)

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        """A cosine-weighted direction around the normal; the weight BRDF * cos / pdf
        is albedo * factor. Hits whose viewer lies below the surface are absorbed and
        draw no numbers."""
        b = self.above(slots, hits)
        r = rng.random((2, len(b)))
        local = cosine_direction(r[0], r[1])  # z = cos(theta_i)
        wi = ONB(b.normal).to_world(local)
        cos_i = dot(b.normal, wi)
        live = select((cos_i > 0.0) & (local[2] > 0.0))
        b = b.toward(wi, cos_i).take(live)
        factor = self.factor(b.slots, b.cos_o, b.cos_i, dot(b.wo, b.wi))
        weight = b.albedo * factor[:, None]
        return ScatterBatch.alive_at(
            len(slots), b.rows, stack(*b.wi), weight, local[2][live] * INV_PI
        )
