"""Kernels of Cook-Torrance (rtpy/materials/cook_torrance.py): one per microfacet
distribution (GGX, Beckmann), so that no kernel branches per hit."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...materials import CookTorrance, microfacet
from ..onb import ONB
from ..sampling import cos_sin_2pi
from ..vec3 import Columns, cross, dot, halfvector, reflect
from .glossy import GlossyKernel, reflected_density
from .material import Bounce, color_param, param

# The formulas of rtpy/materials/microfacet.py and cook_torrance.py that call math's
# functions, on arrays: the same operations in the same order, with numpy's.


def schlick_weight(cosine: np.ndarray) -> np.ndarray:
    """cook_torrance.schlick_weight: (1 - cos)^5, cos clamped to [0, 1]."""
    return (1.0 - np.minimum(1.0, np.maximum(0.0, cosine))) ** 5


def beckmann_d(a2, cos2, exponent) -> np.ndarray:
    """microfacet.beckmann_d: exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4)."""
    return np.exp(-exponent) / (math.pi * a2 * cos2 * cos2)


def ggx_g1(a2, cos, sin2) -> np.ndarray:
    """microfacet.ggx_g1: 2 / (1 + sqrt(1 + alpha^2 tan^2)) multiplied through by cos."""
    return 2.0 * cos / (cos + np.sqrt(cos * cos + a2 * sin2))


def beckmann_a(alpha, cos, sin2) -> np.ndarray:
    """microfacet.beckmann_a: 1 / (alpha tan(theta))."""
    return cos / (alpha * np.sqrt(sin2))


def beckmann_lambda(a: np.ndarray) -> np.ndarray:
    """microfacet.beckmann_lambda: Lambda(a) for a > 0, with math's erfc (erfc below)."""
    return 0.5 * (microfacet.INV_SQRT_PI * np.exp(-a * a) / a - erfc(a))


def beckmann_tan2(a2, r1) -> np.ndarray:
    """microfacet.beckmann_tan2: tan^2(theta_h) = -alpha^2 ln(1 - r1)."""
    return -a2 * np.log1p(-r1)


def cos_sin_of_tan2(tan2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """microfacet.cos_sin_of_tan2: (cos, sin) of the angle whose tangent squared is tan2."""
    cos = 1.0 / np.sqrt(1.0 + tan2)
    return cos, np.sqrt(tan2) * cos


def schlick_fresnel(f0: np.ndarray, cosine: np.ndarray) -> np.ndarray:
    """cook_torrance.schlick_fresnel for colours f0 (n, 3) (its F0 + (1 - F0) m on rows
    of colours, where the scalar model has Color arithmetic)."""
    m = schlick_weight(cosine)[:, None]
    return f0 + (1.0 - f0) * m


def erfc(x: np.ndarray) -> np.ndarray:
    """math.erfc elementwise (numpy has no erfc): the scalar model's own function keeps
    the two backends identical (the callers use it only where it matters)."""
    return np.array([math.erfc(v) for v in x.tolist()], dtype=np.float64)


# G1 of Beckmann is exactly 1.0 for a = 1 / (alpha tan(theta)) >= 6: Lambda(a) is then
# below exp(-36) / (2 * 6 sqrt(pi)) < 2e-17, and 1 + Lambda rounds to 1.
BECKMANN_G1_ONE = 6.0


class CookTorranceKernel(GlossyKernel):
    """Diffuse plus ks D(h) G(wi, wo) F(wo . h) / (4 cos_i cos_o); half vectors drawn
    from D(h) cos(theta_h) around the normal, wo reflected about them. D, G1 and the
    half vector's tan^2 are the distribution's (the subclasses)."""

    def __init__(self, materials: Sequence[CookTorrance]) -> None:
        super().__init__(materials)
        self.alpha = param(self.materials, "alpha")
        self.f0 = color_param(self.materials, "f0")

    # --- the three factors ----------------------------------------------------------
    def D(self, alpha: np.ndarray, normal: Columns, h: Columns) -> np.ndarray:
        """CookTorrance.D: the density of facets along the unit half vectors h (0 at
        and below the horizon)."""
        cos = dot(normal, h)
        cos2 = cos * cos
        ok = (cos > 0.0) & (cos2 != 0.0)
        c = cross(normal, h)
        sin2 = dot(c, c)
        return self.distribution(alpha * alpha, np.where(ok, cos2, 1.0), sin2, ok)

    def distribution(self, a2, cos2, sin2, ok) -> np.ndarray:
        """D from alpha^2 and the half vectors' cos^2 and sin^2, 0 where not ok (where
        cos^2 is 1, a harmless placeholder)."""
        raise NotImplementedError

    def G1(self, alpha: np.ndarray, normal: Columns, v: Columns) -> np.ndarray:
        """CookTorrance.G1: Smith's masking of the unit directions v."""
        raise NotImplementedError

    def tan2_half_vector(self, alpha: np.ndarray, r1: np.ndarray) -> np.ndarray:
        """tan^2(theta_h) of a half vector drawn from D cos, by the inverted CDF."""
        raise NotImplementedError

    def sample_half_vector(self, alpha: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> Columns:
        """CookTorrance.sample_half_vector: local (x, y, z) around the normal (z)."""
        cos, sin = cos_sin_of_tan2(self.tan2_half_vector(alpha, r1))
        cos_phi, sin_phi = cos_sin_2pi(r2)
        return sin * cos_phi, sin * sin_phi, cos

    # --- the highlight ----------------------------------------------------------------
    def highlight(self, b: Bounce) -> np.ndarray:
        """CookTorrance.BRDF's highlight F(wo . h) ks D(h) G1(wi) G1(wo) / (4 cos_i cos_o)."""
        alpha, normal = self.alpha[b.slots], b.normal
        h = halfvector(b.wo, b.wi)
        # Each G1 over its own cosine: finite at grazing angles (see the scalar model).
        g_i, g_o = self.G1(alpha, normal, b.wi), self.G1(alpha, normal, b.wo)
        visibility = (g_i / b.cos_i) * (g_o / b.cos_o) * 0.25
        fresnel = schlick_fresnel(self.f0[b.slots], dot(b.wo, h))
        return fresnel * (self.ks[b.slots] * self.D(alpha, normal, h) * visibility)[:, None]

    def highlight_pdf(self, b: Bounce) -> np.ndarray:
        """CookTorrance.pdf's highlight: D(h) cos(theta_h) over 4 (wo . h)."""
        h = halfvector(b.wo, b.wi)
        density_h = self.D(self.alpha[b.slots], b.normal, h) * dot(b.normal, h)
        return reflected_density(density_h, b.wo, h)

    def sample_highlight(self, b: Bounce, r1: np.ndarray, r2: np.ndarray) -> Columns:
        """CookTorrance.scattering's highlight: wo reflected about a facet normal."""
        h = ONB(b.normal).to_world(self.sample_half_vector(self.alpha[b.slots], r1, r2))
        return reflect(b.d, h)


class GGXKernel(CookTorranceKernel):
    def distribution(self, a2, cos2, sin2, ok):
        return np.where(ok, microfacet.ggx_d(a2, cos2, sin2), 0.0)  # cos2 is 1 where not ok: k > 0

    def G1(self, alpha, normal, v):
        cos = dot(normal, v)
        up = cos > 0.0
        c = cross(normal, v)
        sin2 = dot(c, c)
        g = ggx_g1(alpha * alpha, np.where(up, cos, 1.0), sin2)
        return np.where(up, np.where(sin2 == 0.0, 1.0, g), 0.0)

    def tan2_half_vector(self, alpha, r1):
        return microfacet.ggx_tan2(alpha * alpha, r1)


class BeckmannKernel(CookTorranceKernel):
    def distribution(self, a2, cos2, sin2, ok):
        ok = ok & (a2 * cos2 != 0.0)  # underflow for tiny widths at the horizon
        exponent = microfacet.beckmann_exponent(a2, np.where(ok, cos2, 1.0), sin2)
        ok &= ~(exponent > 700.0)  # exp underflows
        d = beckmann_d(a2, cos2, np.where(ok, exponent, 0.0))
        return np.where(ok, d, 0.0)

    def G1(self, alpha, normal, v):
        cos = dot(normal, v)
        c = cross(normal, v)
        sin2 = dot(c, c)
        g = np.where(cos > 0.0, 1.0, 0.0)  # 1 also where sin2 = 0 and where a >= 6
        slanted = np.flatnonzero((cos > 0.0) & (sin2 != 0.0))
        a = beckmann_a(alpha[slanted], cos[slanted], sin2[slanted])
        g[slanted[a == 0.0]] = 0.0
        near = (a != 0.0) & (a < BECKMANN_G1_ONE)
        a = a[near]
        with np.errstate(over="ignore"):  # subnormal a: lam = inf, G1 = 0 (as in Python)
            lam = beckmann_lambda(a)
        g[slanted[near]] = 1.0 / (1.0 + np.maximum(0.0, lam))
        return g

    def tan2_half_vector(self, alpha, r1):
        return beckmann_tan2(alpha * alpha, r1)


def cook_torrance_kernel(material: CookTorrance) -> type[CookTorranceKernel]:
    """The kernel of a CookTorrance instance: its distribution's."""
    return GGXKernel if material.distribution == "ggx" else BeckmannKernel
