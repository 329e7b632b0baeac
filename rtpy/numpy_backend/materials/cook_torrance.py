"""Kernels of Cook-Torrance (rtpy/materials/cook_torrance.py): one per microfacet
distribution (GGX, Beckmann), so that no kernel branches per hit."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...materials import CookTorrance
from ...materials.cook_torrance import INV_SQRT_PI
from ..sampling import cos_sin_2pi
from ..vec3 import dot
from .glossy import GlossyKernel, Local, half_vector, reflect_about, safe
from .material import color_param, param


def schlick_fresnel(f0: np.ndarray, cosine: np.ndarray) -> np.ndarray:
    """rtpy.materials.cook_torrance.schlick_fresnel for colours f0 (n, 3)."""
    c = np.minimum(1.0, np.maximum(0.0, cosine))
    m = ((1.0 - c) ** 5)[:, None]
    return f0 + (1.0 - f0) * m


def erfc(x: np.ndarray) -> np.ndarray:
    """math.erfc elementwise: numpy has no erfc, and the scalar twin's own function
    keeps the two backends identical (the callers use it only where it matters)."""
    return np.array([math.erfc(v) for v in x.tolist()], dtype=np.float64)


# G1 of Beckmann is exactly 1.0 for a = 1 / (alpha tan(theta)) >= 6: Lambda(a) is then
# below exp(-36) / (2 * 6 sqrt(pi)) < 2e-17, and 1 + Lambda rounds to 1.
BECKMANN_G1_ONE = 6.0


class CookTorranceKernel(GlossyKernel):
    """ks D(h) G(wi, wo) F(wo . h) / (4 (n . wi) (n . wo)); half vectors drawn from
    D(h) cos(theta_h). D, G1 and the half-vector sampling are the distribution's."""

    def __init__(self, materials: Sequence[CookTorrance]) -> None:
        super().__init__(materials)
        self.alpha = param(self.materials, "alpha")
        self.f0 = color_param(self.materials, "f0")

    def D(self, alpha: np.ndarray, h: Local) -> np.ndarray:
        """The distribution of unit half vectors h; 0 at and below the horizon."""
        cos2 = h[2] * h[2]
        ok = (h[2] > 0.0) & (cos2 != 0.0)
        sin2 = h[0] * h[0] + h[1] * h[1]
        d, ok = self.distribution(alpha * alpha, safe(cos2, ok), sin2, ok)
        return np.where(ok, d, 0.0)

    def distribution(self, a2, cos2, sin2, ok) -> tuple[np.ndarray, np.ndarray]:
        """(D, where it is defined) from alpha^2 and the half vectors' cos^2 and sin^2
        (cos^2 is 1 where not ok, which is where D is 0)."""
        raise NotImplementedError

    def G1(self, alpha: np.ndarray, v: Local) -> np.ndarray:
        raise NotImplementedError

    def tan2_half_vector(self, alpha: np.ndarray, r1: np.ndarray) -> np.ndarray:
        """tan^2(theta_h) of a half vector drawn from D cos, by the inverted CDF."""
        raise NotImplementedError

    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        alpha = self.alpha[slots]
        cos_o, cos_i = wo[2], wi[2]
        h, ok = half_vector(wo, wi)
        wo_h = dot(wo, h)
        # G1 / cos per direction, as the scalar code: finite at grazing angles
        visibility = (self.G1(alpha, wi) / cos_i) * (self.G1(alpha, wo) / cos_o) * 0.25
        value = schlick_fresnel(self.f0[slots], wo_h) * (self.D(alpha, h) * visibility)[:, None]
        return np.where(ok[:, None], value, 0.0)

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        tan2 = self.tan2_half_vector(self.alpha[slots], r1)
        cos = 1.0 / np.sqrt(1.0 + tan2)
        sin = np.sqrt(tan2) * cos
        cos_phi, sin_phi = cos_sin_2pi(r2)
        return reflect_about(wo, (sin * cos_phi, sin * sin_phi, cos))

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        h, ok = half_vector(wo, wi)
        wo_h = dot(wo, h)
        ok &= wo_h > 0.0
        pdf = self.D(self.alpha[slots], h) * h[2] / (4.0 * safe(wo_h, ok))
        return np.where(ok, pdf, 0.0)


class GGXKernel(CookTorranceKernel):
    def distribution(self, a2, cos2, sin2, ok):
        k = safe(a2 * cos2 + sin2, ok)
        return a2 / (math.pi * k * k), ok

    def G1(self, alpha: np.ndarray, v: Local) -> np.ndarray:
        cos = v[2]
        up = cos > 0.0
        sin2 = v[0] * v[0] + v[1] * v[1]
        c = safe(cos, up)
        g = 2.0 * c / (c + np.sqrt(c * c + alpha * alpha * sin2))
        return np.where(up, np.where(sin2 == 0.0, 1.0, g), 0.0)

    def tan2_half_vector(self, alpha: np.ndarray, r1: np.ndarray) -> np.ndarray:
        return alpha * alpha * r1 / (1.0 - r1)


class BeckmannKernel(CookTorranceKernel):
    def distribution(self, a2, cos2, sin2, ok):
        exponent = sin2 / (a2 * cos2)  # tan^2 / alpha^2
        ok = ok & ~(exponent > 700.0)
        return np.exp(-np.where(ok, exponent, 0.0)) / (math.pi * a2 * cos2 * cos2), ok

    def G1(self, alpha: np.ndarray, v: Local) -> np.ndarray:
        cos = v[2]
        sin2 = v[0] * v[0] + v[1] * v[1]
        g = np.where(cos > 0.0, 1.0, 0.0)  # 1 also where sin2 = 0 and where a >= 6
        slanted = np.flatnonzero((cos > 0.0) & (sin2 != 0.0))
        a = cos[slanted] / (alpha[slanted] * np.sqrt(sin2[slanted]))  # 1 / (alpha tan)
        g[slanted[a == 0.0]] = 0.0
        near = (a != 0.0) & (a < BECKMANN_G1_ONE)
        a = a[near]
        lam = 0.5 * (INV_SQRT_PI * np.exp(-a * a) / a - erfc(a))
        g[slanted[near]] = 1.0 / (1.0 + np.maximum(0.0, lam))
        return g

    def tan2_half_vector(self, alpha: np.ndarray, r1: np.ndarray) -> np.ndarray:
        return -(alpha * alpha) * np.log1p(-r1)


def cook_torrance_kernel(material: CookTorrance) -> type[CookTorranceKernel]:
    """The kernel of a CookTorrance instance: its distribution's."""
    return GGXKernel if material.distribution == "ggx" else BeckmannKernel
