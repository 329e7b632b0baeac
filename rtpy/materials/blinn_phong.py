"""Blinn-Phong: a diffuse lobe plus a highlight around the half vector.

    f_r(wi, wo) = kd * albedo / pi + ks * (n + 8) / (8 pi) * max(0, normal . h)^n

with n = exponent and h = halfvector(wo, wi) = normalize(wo + wi): the highlight is
brightest where the surface normal lies halfway between light and viewer. The
half-vector form is Blinn's (1977, "Models of light reflection for computer
synthesized pictures"); the course calls the class Blinn, which is this one. The
factor (n + 8) / (8 pi) is the usual approximate energy normalisation
(Akenine-Moeller, Haines and Hoffman, "Real-Time Rendering"); unlike Phong's
(n + 2) / (2 pi) it is not exact: at normal incidence the highlight reflects ks
for n = 0 but up to 7.5 % more than ks near n = 10 (1.8 % at n = 100), so keep
kd * max(albedo) + ks a little below 1.
"""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..onb import ONB
from ..ray import Ray
from ..sampling import generator, random_cosine_direction
from ..scatter_info import ScatterInfo
from ..vec3 import BLACK, WHITE, Color, dot, halfvector, reflect
from .glossy import INV_PI, diffuse_probability, mixture_pdf, reflected_density, weighted_sample
from .phong import CosinePowerHighlight, cosine_power_pdf, sample_cosine_power

INV_EIGHT_PI = 0.125 / math.pi


class BlinnPhong(CosinePowerHighlight):
    """Diffuse plus a Blinn-Phong highlight.

    albedo    colour (or texture) of the diffuse part
    kd        strength of the diffuse part
    ks        strength of the highlight (white: the highlight has the light's colour)
    exponent  sharpness of the highlight: larger values make a smaller, brighter
              spot. For the same look as Phong with exponent e, use about 4 e.

    Sampling (see rtpy.materials.glossy for the mixture) draws the half vector h
    around the normal with density (n + 1) / (2 pi) * (normal . h)^n and reflects
    wo about it: wi = reflect(-wo, h) = 2 (wo . h) h - wo. Changing variables from h
    to wi divides the density by 4 (wo . h), the Jacobian of the reflection. A half
    vector facing away from the viewer (wo . h <= 0) reflects wo below the surface:
    that sample is absorbed.
    """

    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        """kd * albedo / pi + ks * (n + 8) / (8 pi) * (normal . h)^n with the unit half
        vector h; black unless wo and wi both lie above the surface."""
        # BEGIN SOLUTION week08: diffuse plus (n + 8) / (8 pi) (normal . h)^n at the half vector
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        if dot(normal, wo) <= 0.0 or dot(normal, wi) <= 0.0:
            return BLACK  # reflection only: both directions above the surface
        f = self.albedo.value(hit) * (self.kd * INV_PI)
        # h lies above the surface with wo and wi, but two grazing directions can round
        # normal . h to just below 0, where cos_h**n would be complex
        cos_h = dot(normal, halfvector(wo, wi))
        if self.ks > 0.0 and cos_h > 0.0:
            n = self.exponent
            f = f + WHITE * (self.ks * (n + 8.0) * INV_EIGHT_PI * cos_h**n)
        return f
        # END SOLUTION

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        """Density of scattering() choosing ray_light's direction: the mixture of
        cos(theta_i) / pi and the half vector's density over 4 (wo . h); 0 unless
        wo and wi both lie above the surface."""
        # BEGIN SOLUTION week08: the mixture's density; the half vector's over 4 (wo . h)
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        cos_i = dot(normal, wi)
        if dot(normal, wo) <= 0.0 or cos_i <= 0.0:
            return 0.0
        h = halfvector(wo, wi)
        density_h = cosine_power_pdf(self.exponent, dot(normal, h))  # the half vector's
        highlight = reflected_density(density_h, wo, h)
        return mixture_pdf(diffuse_probability(self, hit), cos_i, highlight)
        # END SOLUTION

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        """The diffuse lobe with probability p_d, else wo reflected about a half
        vector drawn around the normal; weight BRDF * cos / pdf."""
        # BEGIN SOLUTION week08: pick a lobe; the highlight reflects wo about a sampled half vector
        r = generator().random
        if r() < diffuse_probability(self, hit):
            wi = ONB(hit.normal).to_world(random_cosine_direction())
        else:
            h = ONB(hit.normal).to_world(sample_cosine_power(self.exponent, r(), r()))
            wi = reflect(ray_in.direction, h)
        return weighted_sample(self, ray_in, hit, wi)
        # END SOLUTION


Blinn = BlinnPhong
"""The course's name for Blinn-Phong."""
