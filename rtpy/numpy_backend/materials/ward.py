"""Kernel of Ward (rtpy/materials/ward.py): the anisotropic Gaussian highlight."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...materials import Ward
from ...materials.ward import MAX_EXPONENT, MIN_COS_PRODUCT
from ..sampling import cos_sin_2pi
from ..vec3 import dot
from .glossy import GlossyKernel, Local, half_vector, reflect_about, safe
from .material import param


class WardKernel(GlossyKernel):
    """ks exp(-slope exponent) / (4 pi alpha_x alpha_y sqrt(cos_i cos_o)), anisotropic in
    the tangent frame; half vectors drawn from Walter 2005's density."""

    def __init__(self, materials: Sequence[Ward]) -> None:
        super().__init__(materials)
        self.ax = param(self.materials, "ax")
        self.ay = param(self.materials, "ay")

    @staticmethod
    def slope_exponent(ax: np.ndarray, ay: np.ndarray, h: Local) -> np.ndarray:
        """(hx^2 / ax^2 + hy^2 / ay^2) / hz^2 for any (unnormalised) h; infinite in the
        tangent plane."""
        sx, sy = h[0] / ax, h[1] / ay
        hz2 = h[2] * h[2]
        numerator = sx * sx + sy * sy
        flat = hz2 == 0.0
        e = numerator / safe(hz2, ~flat)
        return np.where(flat, np.where(numerator > 0.0, np.inf, 0.0), e)

    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        ax, ay = self.ax[slots], self.ay[slots]
        h = (wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2])  # the ratios are all that count
        exponent = self.slope_exponent(ax, ay, h)
        ok = ~(exponent > MAX_EXPONENT)
        cos_product = np.maximum(wi[2] * wo[2], MIN_COS_PRODUCT)
        value = np.exp(-np.where(ok, exponent, 0.0)) / (
            4.0 * math.pi * ax * ay * np.sqrt(cos_product)
        )
        return np.where(ok, value, 0.0)

    def half_vector_pdf(self, ax: np.ndarray, ay: np.ndarray, h: Local) -> np.ndarray:
        up = h[2] > 0.0
        exponent = self.slope_exponent(ax, ay, h)
        ok = up & ~(exponent > MAX_EXPONENT)
        p = np.exp(-np.where(ok, exponent, 0.0)) / (math.pi * ax * ay * safe(h[2], ok) ** 3)
        return np.where(ok, p, 0.0)

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        ax, ay = self.ax[slots], self.ay[slots]
        cos_angle, sin_angle = cos_sin_2pi(r2)
        phi = np.arctan2(ay * sin_angle, ax * cos_angle)
        cos_phi, sin_phi = np.cos(phi), np.sin(phi)
        a = cos_phi * cos_phi / (ax * ax) + sin_phi * sin_phi / (ay * ay)
        tan2 = -np.log1p(-r1) / a
        cos = 1.0 / np.sqrt(1.0 + tan2)
        sin = np.sqrt(tan2) * cos
        return reflect_about(wo, (sin * cos_phi, sin * sin_phi, cos))

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        h, ok = half_vector(wo, wi)
        wo_h = dot(wo, h)
        ok &= wo_h > 0.0
        pdf = self.half_vector_pdf(self.ax[slots], self.ay[slots], h) / (4.0 * safe(wo_h, ok))
        return np.where(ok, pdf, 0.0)
