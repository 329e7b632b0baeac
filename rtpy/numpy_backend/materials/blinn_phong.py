"""Kernel of Blinn-Phong (rtpy/materials/blinn_phong.py): the half-vector highlight."""

from __future__ import annotations

import numpy as np

from ...materials.blinn_phong import INV_EIGHT_PI
from ..onb import ONB
from ..vec3 import Columns, dot, halfvector, reflect
from .glossy import positive_power, reflected_density
from .material import Bounce
from .phong import PhongKernel, cosine_power_pdf, sample_cosine_power


class BlinnPhongKernel(PhongKernel):
    """Diffuse plus ks (n + 8) / (8 pi) (normal . h)^n at the half vector h; h is
    drawn with density (n + 1) / (2 pi) cos^n around the normal and wo reflected
    about it."""

    def highlight(self, b: Bounce) -> np.ndarray:
        """BlinnPhong.BRDF's highlight: 0 unless ks > 0."""
        cos_h = dot(b.normal, halfvector(b.wo, b.wi))  # may round to <= 0 when both graze
        ks, n = self.ks[b.slots], self.exponent[b.slots]
        return np.where(ks > 0.0, ks * (n + 8.0) * INV_EIGHT_PI * positive_power(cos_h, n), 0.0)

    def highlight_pdf(self, b: Bounce) -> np.ndarray:
        """BlinnPhong.pdf's highlight: the half vector's density over 4 (wo . h)."""
        h = halfvector(b.wo, b.wi)
        density_h = cosine_power_pdf(self.exponent[b.slots], dot(b.normal, h))
        return reflected_density(density_h, b.wo, h)

    def sample_highlight(self, b: Bounce, r1: np.ndarray, r2: np.ndarray) -> Columns:
        """BlinnPhong.scattering's highlight: wo reflected about a half vector drawn
        around the normal."""
        h = ONB(b.normal).to_world(sample_cosine_power(self.exponent[b.slots], r1, r2))
        return reflect(b.d, h)
