"""Kernel of Oren-Nayar (rtpy/materials/oren_nayar.py): the qualitative rough-diffuse model."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import OrenNayar
from ...materials.oren_nayar import MIN_COS
from ..arrays import compose, select
from ..hit_info import HitBatch
from ..onb import ONB
from ..sampling import cosine_direction
from ..scatter_info import ScatterBatch
from ..vec3 import Columns, components, dot, stack, take
from .material import INV_PI, AlbedoKernel, param


class OrenNayarKernel(AlbedoKernel):
    """albedo / pi (A + B max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta)), sampled
    cosine-weighted (weight albedo * factor)."""

    has_brdf = True
    scatters = True
    reads_tangent = True

    def __init__(self, materials: Sequence[OrenNayar]) -> None:
        super().__init__(materials)
        self.A = param(self.materials, "A")
        self.B = param(self.materials, "B")

    def factor(self, slots: np.ndarray, wo: Columns, wi: Columns) -> np.ndarray:
        """A + B max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta) = A + B (projections'
        dot product) / (larger cosine), both directions above the surface."""
        a, b = self.A[slots], self.B[slots]
        cos_phi_sin_sin = wi[0] * wo[0] + wi[1] * wo[1]
        cos_beta = np.maximum(np.maximum(wi[2], wo[2]), MIN_COS)
        rough = (b != 0.0) & (cos_phi_sin_sin > 0.0)
        return np.where(rough, a + b * cos_phi_sin_sin / cos_beta, a)

    def BRDF(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        frame = ONB.from_normal_tangent(hits.normal, hits.tangent)
        wo_l, wi_l = frame.to_local(hits.wo), frame.to_local(wi)
        f = np.zeros((len(slots), 3))
        up = select((wo_l[2] > 0.0) & (wi_l[2] > 0.0))
        s = slots[up]
        k = INV_PI * self.factor(s, take(wo_l, up), take(wi_l, up))
        f[up] = self.albedo(s, hits, up) * k[:, None]
        return f

    def pdf(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        # The density of scattering(), from the world normal as OrenNayar.pdf: 0 where
        # the viewer is below the surface (n . d >= 0 for the arriving direction d = -wo).
        n = components(hits.normal)
        viewer_above = ~(dot(n, components(-hits.wo)) >= 0.0)
        return np.where(viewer_above, np.maximum(0.0, dot(n, components(wi))) * INV_PI, 0.0)

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        frame = ONB.from_normal_tangent(hits.normal, hits.tangent)
        wo = frame.to_local(hits.wo)
        rows = select(wo[2] > 0.0)
        r = rng.random((2, len(slots[rows])))
        wi = cosine_direction(r[0], r[1])
        pdf = wi[2] * INV_PI
        live = select(pdf > 0.0)
        rows, wi, pdf = compose(rows, live), take(wi, live), pdf[live]
        s = slots[rows]
        k = self.factor(s, take(wo, rows), wi)
        direction = stack(*frame.take(rows).to_world(*wi))
        attenuation = self.albedo(s, hits, rows) * k[:, None]
        return ScatterBatch.alive_at(len(slots), rows, direction, attenuation, pdf)
