"""Kernel of Phong (rtpy/materials/phong.py): the normalised Phong highlight."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import Phong
from ...materials.phong import INV_TWO_PI
from ..onb import local_to_world
from ..sampling import cos_sin_2pi
from .glossy import GlossyKernel, Local, positive_power
from .material import param


def sample_cosine_power(n: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> Local:
    """rtpy.materials.phong.sample_cosine_power: density (n + 1) / (2 pi) cos^n about z."""
    cos_theta = r1 ** (1.0 / (n + 1.0))
    sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
    cos_phi, sin_phi = cos_sin_2pi(r2)
    return sin_theta * cos_phi, sin_theta * sin_phi, cos_theta


def cosine_power_pdf(n: np.ndarray, cos_theta: np.ndarray) -> np.ndarray:
    return (n + 1.0) * INV_TWO_PI * positive_power(cos_theta, n)


class PhongKernel(GlossyKernel):
    """ks (n + 2) / (2 pi) max(0, r . wo)^n, sampled around the mirror direction of wo."""

    def __init__(self, materials: Sequence[Phong]) -> None:
        super().__init__(materials)
        self.exponent = param(self.materials, "exponent")

    @staticmethod
    def cos_to_mirror(wo: Local, wi: Local) -> np.ndarray:
        # r . wo = m . wi with m = (-wo.x, -wo.y, wo.z), the mirror of wo
        return wi[2] * wo[2] - wi[0] * wo[0] - wi[1] * wo[1]

    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        n = self.exponent[slots]
        return (n + 2.0) * INV_TWO_PI * positive_power(self.cos_to_mirror(wo, wi), n)

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        x, y, z = sample_cosine_power(self.exponent[slots], r1, r2)
        wi = local_to_world((-wo[0], -wo[1], wo[2]), x, y, z)
        return wi, np.ones(len(slots), dtype=bool)

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        return cosine_power_pdf(self.exponent[slots], self.cos_to_mirror(wo, wi))
