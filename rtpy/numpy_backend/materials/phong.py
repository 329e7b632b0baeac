"""Kernel of Phong (rtpy/materials/phong.py): the normalised Phong highlight."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import Phong
from ...materials.phong import INV_TWO_PI, cosine_power_density
from ..onb import ONB
from ..sampling import cos_sin_2pi
from ..vec3 import Columns, dot, negative, reflect
from .glossy import GlossyKernel, positive_power
from .material import Bounce, param


def cosine_power_angle(exponent: np.ndarray, r1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """phong.cosine_power_angle on arrays: (cos, sin) of theta, cos = r1^(1 / (n + 1))."""
    cos_theta = r1 ** (1.0 / (exponent + 1.0))
    return cos_theta, np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))


def sample_cosine_power(exponent: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> Columns:
    """phong.sample_cosine_power: local (x, y, z) with density (n + 1) / (2 pi) cos^n
    around z."""
    cos_theta, sin_theta = cosine_power_angle(exponent, r1)
    cos_phi, sin_phi = cos_sin_2pi(r2)
    return sin_theta * cos_phi, sin_theta * sin_phi, cos_theta


def cosine_power_pdf(exponent: np.ndarray, cos_theta: np.ndarray) -> np.ndarray:
    """phong.cosine_power_pdf: (n + 1) / (2 pi) cos^n, 0 outside the hemisphere."""
    return cosine_power_density(exponent, positive_power(cos_theta, exponent))


class PhongKernel(GlossyKernel):
    """Diffuse plus ks (n + 2) / (2 pi) max(0, r . wo)^n, r = reflect(-wi, normal);
    the highlight is drawn around m = reflect(-wo, normal)."""

    def __init__(self, materials: Sequence[Phong]) -> None:
        super().__init__(materials)
        self.exponent = param(self.materials, "exponent")

    def highlight(self, b: Bounce) -> np.ndarray:
        """Phong.BRDF's highlight: 0 unless ks > 0 and r . wo > 0."""
        cos_r = dot(reflect(negative(b.wi), b.normal), b.wo)
        ks, n = self.ks[b.slots], self.exponent[b.slots]
        return np.where(ks > 0.0, ks * (n + 2.0) * INV_TWO_PI * positive_power(cos_r, n), 0.0)

    def highlight_pdf(self, b: Bounce) -> np.ndarray:
        """Phong.pdf's highlight: cos^n around m, the mirror direction of wo."""
        mirror = reflect(b.d, b.normal)
        return cosine_power_pdf(self.exponent[b.slots], dot(mirror, b.wi))

    def sample_highlight(self, b: Bounce, r1: np.ndarray, r2: np.ndarray) -> Columns:
        """Phong.scattering's highlight: a cosine power around the mirror direction."""
        mirror = reflect(b.d, b.normal)
        return ONB(mirror).to_world(sample_cosine_power(self.exponent[b.slots], r1, r2))
