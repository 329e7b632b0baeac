"""Kernel of Blinn-Phong (rtpy/materials/blinn_phong.py): the half-vector highlight."""

from __future__ import annotations

import numpy as np

from ...materials.blinn_phong import INV_EIGHT_PI
from .glossy import Local, positive_power, reflect_about, safe
from .phong import PhongKernel, cosine_power_pdf, sample_cosine_power


class BlinnPhongKernel(PhongKernel):
    """ks (n + 8) / (8 pi) max(0, n . h)^n, sampled by drawing h with density
    (n + 1) / (2 pi) cos^n and reflecting wo about it."""

    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        hx, hy, hz = wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]
        length = np.sqrt(hx * hx + hy * hy + hz * hz)
        n = self.exponent[slots]
        return (n + 8.0) * INV_EIGHT_PI * positive_power(hz / length, n)

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        h = sample_cosine_power(self.exponent[slots], r1, r2)
        return reflect_about(wo, h)

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        hx, hy, hz = wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]
        length = np.sqrt(hx * hx + hy * hy + hz * hz)
        ok = length != 0.0
        length = safe(length, ok)
        wo_h = (wo[0] * hx + wo[1] * hy + wo[2] * hz) / length
        ok &= wo_h > 0.0
        pdf = cosine_power_pdf(self.exponent[slots], hz / length) / (4.0 * safe(wo_h, ok))
        return np.where(ok, pdf, 0.0)
