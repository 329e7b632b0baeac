"""Kernel of Ward (rtpy/materials/ward.py): the anisotropic Gaussian highlight."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...materials import Ward
from ...materials.ward import MAX_EXPONENT, MIN_COS_PRODUCT, squared_slopes
from ..onb import ONB
from ..sampling import cos_sin_2pi
from ..vec3 import Columns, dot, halfvector, reflect
from .cook_torrance import cos_sin_of_tan2
from .glossy import GlossyKernel, reflected_density
from .material import Bounce, param

# The formulas of rtpy/materials/ward.py that call math's functions, on arrays: the
# same operations in the same order, with numpy's.


def half_vector_tan2(r1, cos_phi, sin_phi, ax, ay) -> np.ndarray:
    """ward.half_vector_tan2: -ln(1 - r1) / (cos^2 / alpha_x^2 + sin^2 / alpha_y^2)."""
    a = cos_phi * cos_phi / (ax * ax) + sin_phi * sin_phi / (ay * ay)
    return -np.log1p(-r1) / a


def highlight_lobe(exponent, cos_i, cos_o, ax, ay) -> np.ndarray:
    """ward.highlight_lobe: exp(-exponent) / (4 pi alpha_x alpha_y sqrt(cos_i cos_o))."""
    root = np.sqrt(np.maximum(cos_i * cos_o, MIN_COS_PRODUCT))
    return np.exp(-exponent) / (4.0 * math.pi * ax * ay * root)


def half_vector_density(exponent, cos, ax, ay) -> np.ndarray:
    """ward.half_vector_density: exp(-exponent) / (pi alpha_x alpha_y cos^3)."""
    return np.exp(-exponent) / (math.pi * ax * ay * cos**3)


class WardKernel(GlossyKernel):
    """Diffuse plus ks exp(-slope exponent of h) / (4 pi alpha_x alpha_y sqrt(cos_i
    cos_o)), anisotropic in the shading frame hit.frame; half vectors drawn from
    Walter 2005's density in that frame, wo reflected about them."""

    reads_tangent = True  # the frame's first axis

    def __init__(self, materials: Sequence[Ward]) -> None:
        super().__init__(materials)
        self.ax = param(self.materials, "ax")
        self.ay = param(self.materials, "ay")

    def slope_exponent(self, ax, ay, frame: ONB, h: Columns) -> np.ndarray:
        """Ward.slope_exponent: (hx^2 / alpha_x^2 + hy^2 / alpha_y^2) / hz^2 with h's
        coordinates in the frame, for h of any length; infinite in the tangent plane."""
        numerator = squared_slopes(dot(h, frame.u), dot(h, frame.v), ax, ay)
        hz = dot(h, frame.w)
        hz2 = hz * hz
        flat = hz2 == 0.0
        exponent = numerator / np.where(flat, 1.0, hz2)
        return np.where(flat, np.where(numerator > 0.0, np.inf, 0.0), exponent)

    def sample_half_vector(self, ax, ay, r1: np.ndarray, r2: np.ndarray) -> Columns:
        """Ward.sample_half_vector: local (x along the tangent, y, z along the normal)."""
        cos_angle, sin_angle = cos_sin_2pi(r2)
        phi = np.arctan2(ay * sin_angle, ax * cos_angle)
        cos_phi, sin_phi = np.cos(phi), np.sin(phi)
        tan2 = half_vector_tan2(r1, cos_phi, sin_phi, ax, ay)
        cos, sin = cos_sin_of_tan2(tan2)
        return sin * cos_phi, sin * sin_phi, cos

    def half_vector_pdf(self, ax, ay, frame: ONB, h: Columns) -> np.ndarray:
        """Ward.half_vector_pdf: p_h of the unit half vectors h, 0 below the surface."""
        cos = dot(h, frame.w)
        exponent = self.slope_exponent(ax, ay, frame, h)
        ok = (cos > 0.0) & ~(exponent > MAX_EXPONENT)
        cos = np.where(ok, cos, 1.0)
        p = half_vector_density(np.where(ok, exponent, 0.0), cos, ax, ay)
        return np.where(ok, p, 0.0)

    def highlight(self, b: Bounce) -> np.ndarray:
        """Ward.BRDF's highlight: 0 unless ks > 0 and the exponent is at most
        MAX_EXPONENT."""
        ax, ay = self.ax[b.slots], self.ay[b.slots]
        wo, wi = b.wo, b.wi
        h = (wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2])  # h before normalising
        exponent = self.slope_exponent(ax, ay, b.frame, h)
        lit = (self.ks[b.slots] > 0.0) & (exponent <= MAX_EXPONENT)
        exponent = np.where(lit, exponent, 0.0)
        lobe = highlight_lobe(exponent, b.cos_i, b.cos_o, ax, ay)
        return np.where(lit, self.ks[b.slots] * lobe, 0.0)

    def highlight_pdf(self, b: Bounce) -> np.ndarray:
        """Ward.pdf's highlight: p_h(h) over 4 (wo . h)."""
        h = halfvector(b.wo, b.wi)
        density_h = self.half_vector_pdf(self.ax[b.slots], self.ay[b.slots], b.frame, h)
        return reflected_density(density_h, b.wo, h)

    def sample_highlight(self, b: Bounce, r1: np.ndarray, r2: np.ndarray) -> Columns:
        """Ward.scattering's highlight: wo reflected about a half vector drawn in the
        shading frame."""
        local = self.sample_half_vector(self.ax[b.slots], self.ay[b.slots], r1, r2)
        return reflect(b.d, b.frame.to_world(local))
