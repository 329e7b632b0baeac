"""Phong: a diffuse lobe plus the energy-normalised Phong highlight.

    f_r(wi, wo) = kd * albedo / pi + ks * (n + 2) / (2 pi) * max(0, r . wo)^n

with n = exponent and r = reflect(-wi, normal), the mirror direction of the light.
The cosine power is Phong's (1975, "Illumination for computer generated
pictures"); the factor (n + 2) / (2 pi) is the normalisation of Lewis (1994,
"Making shaders more physically plausible"), which makes the highlight reflect
all the light (ks) at normal incidence for every exponent, and less at other
angles, where part of the lobe falls below the surface.
"""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..onb import ONB
from ..ray import Ray
from ..sampling import generator, random_cosine_direction
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import BLACK, WHITE, Color, Vec3, dot, reflect
from .glossy import INV_PI, diffuse_probability, mixture_pdf, weighted_sample
from .material import Material, as_texture, check_strengths, material_number

INV_TWO_PI = 0.5 / math.pi


def check_exponent(exponent: float) -> float:
    """The exponent as a float in its range (MATERIAL_RANGES), or TypeError or
    ValueError naming it."""
    return material_number("exponent", exponent)


def sample_cosine_power(exponent: float, r1: float, r2: float) -> Vec3:
    """A direction around the z axis with density (n + 1) / (2 pi) * cos^n(theta),
    n = exponent, from two uniform numbers in [0, 1), as local coordinates (x, y, z)
    (ONB(axis).to_world turns it around an axis).

    Inverting the cumulative distribution of cos(theta), 1 - cos^(n+1), gives
    cos(theta) = r1^(1 / (n + 1)); the azimuth is uniform (Lafortune and Willems
    1994, "Using the Modified Phong Reflectance Model for Physically Based
    Rendering", KU Leuven report CW 197).
    """
    cos_theta, sin_theta = cosine_power_angle(exponent, r1)
    phi = 2.0 * math.pi * r2
    return Vec3(sin_theta * math.cos(phi), sin_theta * math.sin(phi), cos_theta)


def cosine_power_pdf(exponent: float, cos_theta: float) -> float:
    """Density (n + 1) / (2 pi) * cos^n(theta) of sample_cosine_power at a direction
    cos_theta from the axis, 0 outside the hemisphere around the axis (Lafortune and
    Willems 1994)."""
    if cos_theta <= 0.0:
        return 0.0
    return cosine_power_density(exponent, cos_theta**exponent)


def cosine_power_angle(exponent: float, r1: float) -> tuple[float, float]:
    """(cos, sin) of theta drawn with density (n + 1) / (2 pi) cos^n(theta) from a uniform
    r1: cos(theta) = r1^(1 / (n + 1)), inverting the distribution 1 - cos^(n + 1)."""
    cos_theta = r1 ** (1.0 / (exponent + 1.0))
    return cos_theta, math.sqrt(max(0.0, 1.0 - cos_theta * cos_theta))


def cosine_power_density(exponent, power):
    """(n + 1) / (2 pi) cos^n(theta), from power = cos^n(theta)."""
    return (exponent + 1.0) * INV_TWO_PI * power


class CosinePowerHighlight(Material):
    """Diffuse plus a highlight shaped by a power of a cosine: the parameters Phong
    and Blinn-Phong share (their docstrings say what each means)."""

    def __init__(
        self,
        albedo: Color | Texture = Color(0.5, 0.5, 0.5),
        kd: float = 1.0,
        ks: float = 0.0,
        exponent: float = 1.0,
    ) -> None:
        self.albedo = as_texture(albedo)
        self.kd, self.ks = check_strengths(kd, ks)
        self.exponent = check_exponent(exponent)


class Phong(CosinePowerHighlight):
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

    Sampling (see rtpy.materials.glossy for the mixture): the highlight is drawn
    around m = reflect(-wo, normal), the mirror direction of the viewer, with
    density (n + 1) / (2 pi) * max(0, m . wi)^n; since m . wi = r . wo, that is
    the lobe's own shape. Directions that fall below the surface are absorbed.
    """

    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        """kd * albedo / pi + ks * (n + 2) / (2 pi) * max(0, r . wo)^n with
        r = reflect(-wi, normal); black unless wo and wi both lie above the surface."""
        # BEGIN SOLUTION week08: diffuse plus the normalised lobe around r = reflect(-wi, normal)
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        if dot(normal, wo) <= 0.0 or dot(normal, wi) <= 0.0:
            return BLACK  # reflection only: both directions above the surface
        f = self.albedo.value(hit) * (self.kd * INV_PI)
        cos_r = dot(reflect(-wi, normal), wo)
        if self.ks > 0.0 and cos_r > 0.0:
            n = self.exponent
            f = f + WHITE * (self.ks * (n + 2.0) * INV_TWO_PI * cos_r**n)
        return f
        # END SOLUTION

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        """Density of scattering() choosing ray_light's direction: the mixture of
        cos(theta_i) / pi and (n + 1) / (2 pi) * max(0, m . wi)^n with
        m = reflect(-wo, normal); 0 unless wo and wi both lie above the surface."""
        # BEGIN SOLUTION week08: the mixture's density; the highlight's is cos^n around m
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        cos_i = dot(normal, wi)
        if dot(normal, wo) <= 0.0 or cos_i <= 0.0:
            return 0.0
        mirror = reflect(ray_view.direction, normal)  # m, the mirror direction of wo
        highlight = cosine_power_pdf(self.exponent, dot(mirror, wi))
        return mixture_pdf(diffuse_probability(self, hit), cos_i, highlight)
        # END SOLUTION

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        """The diffuse lobe with probability p_d, else the highlight: a cosine power
        around m = reflect(ray_in.direction, normal); weight BRDF * cos / pdf."""
        # BEGIN SOLUTION week08: pick a lobe; the highlight is drawn around the mirror direction
        r = generator().random
        if r() < diffuse_probability(self, hit):
            wi = ONB(hit.normal).to_world(random_cosine_direction())
        else:
            mirror = reflect(ray_in.direction, hit.normal)
            wi = ONB(mirror).to_world(sample_cosine_power(self.exponent, r(), r()))
        return weighted_sample(self, ray_in, hit, wi)
        # END SOLUTION
