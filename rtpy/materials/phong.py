"""Phong: a diffuse lobe plus the energy-normalised Phong highlight.

    f_r(wi, wo) = kd * albedo / pi + ks * (n + 2) / (2 pi) * max(0, r . wo)^n

with n = exponent and r = reflect(-wi about the normal), the mirror direction
of the light. The cosine power is Phong's (1975, "Illumination for computer
generated pictures"); the factor (n + 2) / (2 pi) is the normalisation of
Lewis (1994, "Making shaders more physically plausible"), which makes the
highlight reflect all the light (ks) at normal incidence for every exponent,
and less at other angles, where part of the lobe falls below the surface.
"""

from __future__ import annotations

import math

from ..onb import local_to_world
from ..texture import Texture
from ..vec3 import BLACK, WHITE, Color, Vec3
from .glossy import GlossyMaterial, Local

INV_TWO_PI = 0.5 / math.pi


def check_exponent(exponent: float) -> float:
    """The exponent as a float, or ValueError if it is not a finite number >= 0."""
    if isinstance(exponent, bool) or not isinstance(exponent, int | float):
        raise ValueError(f"exponent must be a finite number >= 0, got {exponent!r}")
    if not (exponent >= 0.0 and math.isfinite(exponent)):
        raise ValueError(f"exponent must be a finite number >= 0, got {exponent}")
    return float(exponent)


def sample_cosine_power(exponent: float, r1: float, r2: float) -> Local:
    """A direction around the z axis with density (n + 1) / (2 pi) * cos^n(theta),
    n = exponent, from two uniform numbers in [0, 1).

    Inverting the cumulative distribution of cos(theta), 1 - cos^(n+1), gives
    cos(theta) = r1^(1 / (n + 1)); the azimuth is uniform.
    """
    # BEGIN SOLUTION week08: a direction with density (n + 1) / (2 pi) cos^n
    cos_theta = r1 ** (1.0 / (exponent + 1.0))
    sin_theta = math.sqrt(max(0.0, 1.0 - cos_theta * cos_theta))
    phi = 2.0 * math.pi * r2
    return sin_theta * math.cos(phi), sin_theta * math.sin(phi), cos_theta
    # END SOLUTION


def cosine_power_pdf(exponent: float, cos_theta: float) -> float:
    """Density of sample_cosine_power at a direction cos_theta from the axis
    (0 outside the hemisphere around the axis)."""
    # BEGIN SOLUTION week08: the density (n + 1) / (2 pi) cos^n
    if cos_theta <= 0.0:
        return 0.0
    return (exponent + 1.0) * INV_TWO_PI * cos_theta**exponent
    # END SOLUTION


class Phong(GlossyMaterial):
    """Diffuse plus a normalised Phong highlight around the mirror direction.

    albedo    colour (or texture) of the diffuse part
    kd        strength of the diffuse part
    ks        strength of the highlight (white: the highlight has the light's colour)
    exponent  sharpness of the highlight: 0 spreads it over the whole hemisphere
              around the mirror direction, larger values make a smaller, brighter
              spot (the normalisation keeps its total energy), very large values
              approach a mirror

    kd * max(albedo) + ks <= 1 keeps the surface from reflecting more light than
    it receives. The lobe is 0 where r . wo <= 0, also for exponent 0 (where
    max(0, x)^0 would otherwise be 1 everywhere).

    Sampling: the highlight is drawn around m, the mirror direction of wo, with
    density (n + 1) / (2 pi) * cos^n(angle to m); since r . wo = m . wi, that is
    the lobe's own shape. Directions that fall below the surface are absorbed.
    """

    def __init__(
        self,
        albedo: Color | Texture = Color(0.5, 0.5, 0.5),
        kd: float = 1.0,
        ks: float = 0.0,
        exponent: float = 1.0,
    ) -> None:
        super().__init__(albedo, kd, ks)
        self.exponent = check_exponent(exponent)

    @staticmethod
    def _cos_to_mirror(wo: Local, wi: Local) -> float:
        # r = reflect(-wi) = (-wi.x, -wi.y, wi.z) in the local frame, so
        # r . wo = m . wi with m = (-wo.x, -wo.y, wo.z), the mirror of wo.
        return wi[2] * wo[2] - wi[0] * wo[0] - wi[1] * wo[1]

    def specular(self, wo: Local, wi: Local) -> Color:
        # BEGIN SOLUTION week08: the normalised Phong lobe (n + 2) / (2 pi) max(0, r . wo)^n
        c = self._cos_to_mirror(wo, wi)
        if c <= 0.0:
            return BLACK
        n = self.exponent
        return WHITE * ((n + 2.0) * INV_TWO_PI * c**n)
        # END SOLUTION

    def sample_specular(self, wo: Local, r1: float, r2: float) -> Local | None:
        # BEGIN SOLUTION week08: sample the Phong lobe around the mirror direction of wo
        x, y, z = sample_cosine_power(self.exponent, r1, r2)
        d = local_to_world(Vec3(-wo[0], -wo[1], wo[2]), x, y, z)  # around m
        return d.e0, d.e1, d.e2
        # END SOLUTION

    def specular_pdf(self, wo: Local, wi: Local) -> float:
        return cosine_power_pdf(self.exponent, self._cos_to_mirror(wo, wi))
