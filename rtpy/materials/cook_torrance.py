"""Cook-Torrance: a diffuse lobe plus a physically based microfacet highlight.

    f_r(wi, wo) = kd * albedo / pi
                + ks * D(h) * G(wi, wo) * F(wo . h) / (4 (n . wi) (n . wo))

with h = halfvector(wo, wi) = normalize(wo + wi), the half vector. The surface is modelled as a
landscape of tiny perfect mirrors (microfacets); light goes from wi to wo only
via the facets whose normal is h. The three factors say

- D(h): how many facets face along h (the normal distribution function), per
  unit solid angle of h and per unit of macro-surface area, normalised so that
  their projected area is the surface's: integral of D(h) cos(theta_h) dw_h = 1.
  alpha = roughness is its width (about the tangent of the typical facet tilt):
    GGX (Walter et al. 2007, "Microfacet Models for Refraction through Rough
    Surfaces"; the Trowbridge-Reitz distribution of 1975):
        D(h) = alpha^2 / (pi cos^4(theta_h) (alpha^2 + tan^2(theta_h))^2)
    Beckmann (Beckmann and Spizzichino 1963, the one Cook and Torrance used):
        D(h) = exp(-tan^2(theta_h) / alpha^2) / (pi alpha^2 cos^4(theta_h))
  GGX has long tails: a sharp core with a soft halo around the highlight.
  Beckmann falls off like a Gaussian: a highlight without a halo.
- G(wi, wo): the fraction of those facets that are neither hidden from the light
  (shadowing) nor from the viewer (masking). Smith's model, with the G1 that
  matches D (Walter et al. 2007), as the separable product G1(wi) * G1(wo):
    GGX:      G1(v) = 2 / (1 + sqrt(1 + alpha^2 tan^2(theta_v)))
    Beckmann: G1(v) = 1 / (1 + Lambda(a)),  a = 1 / (alpha tan(theta_v)),
              Lambda(a) = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi))
  G1 is 1 when looking straight down and falls to 0 at grazing angles.
- F(wo . h): the fraction of light a facet reflects (Fresnel), by Schlick's
  approximation (Schlick 1994, "An Inexpensive BRDF Model for Physically-based
  Rendering"): F(c) = F0 + (1 - F0) (1 - c)^5, with the reflectance at normal
  incidence F0 = ((1 - ior) / (1 + ior))^2 (about 0.04 for ior 1.5: plastic,
  glass, paint) or a given colour f0 (metals: gold is about [1.0, 0.78, 0.34]).
  Highlights get stronger and whiter toward grazing angles.

The model is Cook and Torrance's (1982, "A Reflectance Model for Computer
Graphics"); D and G are the modern ones of Walter et al. 2007. Only single
scattering is modelled, so very rough surfaces lose some energy (they look a
little darker than they should); they never gain energy.

Sampling (see rtpy.materials.glossy for the diffuse + highlight mixture) draws the
half vector from D(h) cos(theta_h), which is a probability density over the
hemisphere of h precisely because of D's normalisation, and reflects wo about it.
(Sampling only the facets visible from wo, Heitz 2018, wastes fewer samples at
grazing angles; D cos is the simpler textbook method.)
"""

from __future__ import annotations

import math
from typing import Literal

from .._checks import checked, string
from ..hit_info import HitInfo
from ..onb import ONB
from ..ray import Ray
from ..sampling import generator, random_cosine_direction
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import BLACK, WHITE, Color, Vec3, cross, dot, halfvector, reflect
from .glossy import INV_PI, diffuse_probability, mixture_pdf, reflected_density, weighted_sample
from .material import Material, as_texture, check_strengths, material_color, material_number
from .microfacet import (
    beckmann_a,
    beckmann_d,
    beckmann_exponent,
    beckmann_lambda,
    beckmann_tan2,
    cos_sin_of_tan2,
    ggx_d,
    ggx_g1,
    ggx_tan2,
)

DISTRIBUTIONS = ("ggx", "beckmann")
# Widths below this are computed as this (a mirror to every practical purpose):
# D's peak 1 / (pi alpha^2) would overflow for alpha near 1e-154, and long
# before that single rays would carry absurd weights.
MIN_ALPHA = 1e-4


def schlick_weight(cosine: float) -> float:
    """(1 - cos)^5, cos clamped to [0, 1]: the weight of 1 - F0 in Schlick's Fresnel
    reflectance."""
    return (1.0 - min(1.0, max(0.0, cosine))) ** 5


def schlick_fresnel(f0: Color, cosine: float) -> Color:
    """Schlick's Fresnel reflectance F0 + (1 - F0) (1 - cos)^5, per colour channel
    (Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering")."""
    return f0 + (WHITE - f0) * schlick_weight(cosine)


def f0_from_ior(ior: float) -> float:
    """Reflectance at normal incidence of a boundary from vacuum (ior 1) to ior."""
    r = (1.0 - ior) / (1.0 + ior)
    return r * r


class CookTorrance(Material):
    """Diffuse plus a Cook-Torrance microfacet highlight.

    albedo        colour (or texture) of the diffuse part
    kd            strength of the diffuse part
    ks            strength of the highlight
    roughness     alpha, the width of the facet distribution, in (0, 1]: 0.01 is
                  nearly a mirror (a small, very bright highlight and sharp
                  reflections), 0.2 is polished plastic, 0.5 and above look matte
                  with a broad, dim sheen. (Some renderers use alpha = roughness^2
                  to spread the slider's effect; here alpha = roughness.)
    distribution  "ggx" (a highlight with a soft halo) or "beckmann" (no halo)
    ior           index of refraction that sets F0 = ((1 - ior) / (1 + ior))^2:
                  1.5 gives 0.04, the weak, white highlight of dielectrics
    f0            if given, the colour of the reflection at normal incidence
                  instead (overrides ior): coloured, strong highlights of metals

    For a metal use kd = 0, ks = 1 and f0 = the metal's colour; for plastic use
    kd = 1, ks = 1 and the default ior.
    """

    def __init__(
        self,
        albedo: Color | Texture = Color(0.5, 0.5, 0.5),
        kd: float = 1.0,
        ks: float = 0.0,
        roughness: float = 0.5,
        distribution: Literal["ggx", "beckmann"] = "ggx",
        ior: float = 1.5,
        f0: Color | None = None,
    ) -> None:
        self.albedo = as_texture(albedo)
        self.kd, self.ks = check_strengths(kd, ks)
        self.roughness = material_number("roughness", roughness)
        self.alpha = max(self.roughness, MIN_ALPHA)
        self.distribution = checked("distribution", string, distribution, DISTRIBUTIONS)
        self.ior = material_number("ior", ior)
        if f0 is not None:
            f0 = material_color("f0", f0)
        if f0 is None:
            r0 = f0_from_ior(self.ior)
            f0 = Color(r0, r0, r0)
        self.f0 = f0

    # --- the three factors ----------------------------------------------------------
    # tan^2(theta) = sin^2 / cos^2 is written with sin^2 = |normal x v|^2, which keeps
    # its precision near the normal (1 - cos^2 would not), and the formulas are
    # rearranged so that no cosine is ever divided by: they stay finite at grazing
    # angles (where tan is infinite) and for tiny widths.

    def D(self, normal: Vec3, h: Vec3) -> float:
        """Microfacet density along the unit half vector h (0 below the surface): the
        GGX or Beckmann D of the module docstring (rtpy/materials/microfacet.py)."""
        cos = dot(normal, h)
        cos2 = cos * cos
        if cos <= 0.0 or cos2 == 0.0:
            return 0.0
        sin2 = cross(normal, h).length_squared()
        a2 = self.alpha * self.alpha
        if self.distribution == "ggx":
            return ggx_d(a2, cos2, sin2)
        if a2 * cos2 == 0.0:  # underflow for tiny widths at the horizon: exp(-inf)
            return 0.0
        exponent = beckmann_exponent(a2, cos2, sin2)
        if exponent > 700.0:  # exp underflows; the cos^4 below would lose to it anyway
            return 0.0
        return beckmann_d(a2, cos2, exponent)

    def G1(self, normal: Vec3, v: Vec3) -> float:
        """Smith's masking of the unit direction v (1 at the normal, 0 at grazing), the
        G1 that matches D (rtpy/materials/microfacet.py)."""
        cos = dot(normal, v)
        if cos <= 0.0:
            return 0.0
        sin2 = cross(normal, v).length_squared()
        if sin2 == 0.0:
            return 1.0
        if self.distribution == "ggx":
            return ggx_g1(self.alpha * self.alpha, cos, sin2)
        a = beckmann_a(self.alpha, cos, sin2)
        if a == 0.0:
            return 0.0
        return 1.0 / (1.0 + max(0.0, beckmann_lambda(a)))

    def F(self, cosine: float) -> Color:
        """Fresnel reflectance of a facet seen at incidence cosine wo . h."""
        return schlick_fresnel(self.f0, cosine)

    def sample_half_vector(self, r1: float, r2: float) -> Vec3:
        """A half vector with density D(h) cos(theta_h), from two uniform numbers in
        [0, 1), as local coordinates (x, y, z) around the normal (z).

        Inverting the cumulative distribution of theta_h gives
            GGX:      tan^2(theta_h) = alpha^2 r1 / (1 - r1)
            Beckmann: tan^2(theta_h) = -alpha^2 ln(1 - r1)
        and phi_h = 2 pi r2 (D is the same in every direction around the normal):
        the sampling formulas of Walter et al. 2007, section 5.
        """
        a2 = self.alpha * self.alpha
        tan2 = ggx_tan2(a2, r1) if self.distribution == "ggx" else beckmann_tan2(a2, r1)
        cos, sin = cos_sin_of_tan2(tan2)
        phi = 2.0 * math.pi * r2
        return Vec3(sin * math.cos(phi), sin * math.sin(phi), cos)

    # --- BRDF, density and sampling -------------------------------------------------
    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        """kd * albedo / pi + ks * D(h) G(wi, wo) F(wo . h) / (4 cos_i cos_o), with
        G = G1(wi) G1(wo); black unless wo and wi both lie above the surface."""
        # BEGIN SOLUTION week08: diffuse plus D G F / (4 cos_i cos_o)
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        cos_o, cos_i = dot(normal, wo), dot(normal, wi)
        if cos_o <= 0.0 or cos_i <= 0.0:
            return BLACK  # reflection only: both directions above the surface
        f = self.albedo.value(hit) * (self.kd * INV_PI)
        if self.ks > 0.0:
            h = halfvector(wo, wi)
            # Each G1 divided by its own cosine: G1 vanishes like its cosine at grazing
            # angles, so each ratio stays finite (at most about 2 / alpha) even where the
            # product cos_i cos_o would underflow to 0.
            visibility = (self.G1(normal, wi) / cos_i) * (self.G1(normal, wo) / cos_o) * 0.25
            f = f + self.F(dot(wo, h)) * (self.ks * self.D(normal, h) * visibility)
        return f
        # END SOLUTION

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        """Density of scattering() choosing ray_light's direction: the mixture of
        cos(theta_i) / pi and D(h) cos(theta_h) / (4 (wo . h)), the half vector's
        density times the Jacobian d(w_h) / d(w_i) = 1 / (4 (wo . h)) of the
        reflection wi = reflect(-wo, h); 0 unless wo and wi lie above the surface."""
        # BEGIN SOLUTION week08: the mixture's density; D(h) cos(theta_h) / (4 wo . h)
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        cos_i = dot(normal, wi)
        if dot(normal, wo) <= 0.0 or cos_i <= 0.0:
            return 0.0
        h = halfvector(wo, wi)
        density_h = self.D(normal, h) * dot(normal, h)  # D(h) cos(theta_h), the half vector's
        highlight = reflected_density(density_h, wo, h)
        return mixture_pdf(diffuse_probability(self, hit), cos_i, highlight)
        # END SOLUTION

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        """The diffuse lobe with probability p_d, else wo reflected about a half
        vector drawn from D(h) cos(theta_h); weight BRDF * cos / pdf."""
        # BEGIN SOLUTION week08: pick a lobe; the highlight reflects wo about a facet normal
        r = generator().random
        if r() < diffuse_probability(self, hit):
            wi = ONB(hit.normal).to_world(random_cosine_direction())
        else:
            h = ONB(hit.normal).to_world(self.sample_half_vector(r(), r()))
            # A facet turned away from the viewer reflects wo below the surface (absorbed).
            wi = reflect(ray_in.direction, h)
        return weighted_sample(self, ray_in, hit, wi)
        # END SOLUTION
