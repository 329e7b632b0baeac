"""Cook-Torrance: a diffuse lobe plus a physically based microfacet highlight.

    f_r(wi, wo) = kd * albedo / pi
                + ks * D(h) * G(wi, wo) * F(wo . h) / (4 (n . wi) (n . wo))

with h = normalize(wi + wo), the half vector. The surface is modelled as a
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

Sampling draws the half vector from D(h) cos(theta_h), which is a probability
density over the hemisphere of h precisely because of D's normalisation, and
reflects wo about it. (Sampling only the facets visible from wo, Heitz 2018,
wastes fewer samples at grazing angles; D cos is the simpler textbook method.)
"""

from __future__ import annotations

import math
from typing import Literal

from ..texture import Texture
from ..vec3 import Color
from .glossy import GlossyMaterial, Local

INV_PI = 1.0 / math.pi
INV_SQRT_PI = 1.0 / math.sqrt(math.pi)

DISTRIBUTIONS = ("ggx", "beckmann")
MAX_ROUGHNESS = 1.0
# Widths below this are computed as this (a mirror to every practical purpose):
# D's peak 1 / (pi alpha^2) would overflow for alpha near 1e-154, and long
# before that single rays would carry absurd weights.
MIN_ALPHA = 1e-4


def schlick_fresnel(f0: Color, cosine: float) -> Color:
    """Schlick's Fresnel reflectance F0 + (1 - F0) (1 - cos)^5, per colour channel."""
    # BEGIN SOLUTION week08: Schlick's F per colour channel
    c = min(1.0, max(0.0, cosine))
    m = (1.0 - c) ** 5
    return Color(f0.e0 + (1.0 - f0.e0) * m, f0.e1 + (1.0 - f0.e1) * m, f0.e2 + (1.0 - f0.e2) * m)
    # END SOLUTION


def f0_from_ior(ior: float) -> float:
    """Reflectance at normal incidence of a boundary from vacuum (ior 1) to ior."""
    r = (1.0 - ior) / (1.0 + ior)
    return r * r


class CookTorrance(GlossyMaterial):
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
        super().__init__(albedo, kd, ks)
        if not (isinstance(roughness, int | float) and 0.0 < roughness <= MAX_ROUGHNESS):
            raise ValueError(
                f"roughness must be a number in (0, {MAX_ROUGHNESS:g}], got {roughness!r}"
            )
        if distribution not in DISTRIBUTIONS:
            raise ValueError(f'distribution must be "ggx" or "beckmann", got {distribution!r}')
        if not (isinstance(ior, int | float) and ior > 0.0 and math.isfinite(ior)):
            raise ValueError(f"ior must be a finite number > 0, got {ior!r}")
        if f0 is not None:
            components = list(f0)
            if len(components) != 3 or not all(
                isinstance(c, int | float) and 0.0 <= c <= 1.0 for c in components
            ):
                raise ValueError(f"f0 components must lie in [0, 1], got {components!r}")
            f0 = Color(*(float(c) for c in components))
        self.roughness = float(roughness)
        self.alpha = max(self.roughness, MIN_ALPHA)
        self.distribution = distribution
        self.ior = float(ior)
        if f0 is None:
            r0 = f0_from_ior(self.ior)
            f0 = Color(r0, r0, r0)
        self.f0 = f0

    # --- the three factors ----------------------------------------------------------
    # Directions are local (z = normal). tan^2(theta) = sin^2 / cos^2 is written with
    # sin^2 = x^2 + y^2, which keeps its precision near the normal, and the formulas
    # are rearranged so that no cosine is ever divided by: they stay finite at
    # grazing angles (where tan is infinite) and for tiny widths.

    def D(self, h: Local) -> float:
        """Microfacet density along the unit half vector h (0 below the surface)."""
        # BEGIN SOLUTION week08: GGX and Beckmann normal distributions
        cos2 = h[2] * h[2]
        if h[2] <= 0.0 or cos2 == 0.0:
            return 0.0
        sin2 = h[0] * h[0] + h[1] * h[1]
        a2 = self.alpha * self.alpha
        if self.distribution == "ggx":
            # alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2), multiplied out by cos^4:
            k = a2 * cos2 + sin2
            return a2 / (math.pi * k * k)
        denominator = a2 * cos2
        if denominator == 0.0:  # underflow for tiny widths at the horizon: exp(-inf)
            return 0.0
        exponent = sin2 / denominator  # tan^2 / alpha^2
        if exponent > 700.0:  # exp underflows; the cos^4 below would lose to it anyway
            return 0.0
        return math.exp(-exponent) / (math.pi * a2 * cos2 * cos2)
        # END SOLUTION

    def G1(self, v: Local) -> float:
        """Smith's masking of the unit direction v (1 at the normal, 0 at grazing)."""
        # BEGIN SOLUTION week08: Smith masking G1 for GGX and Beckmann
        cos = v[2]
        if cos <= 0.0:
            return 0.0
        sin2 = v[0] * v[0] + v[1] * v[1]
        if sin2 == 0.0:
            return 1.0
        a2 = self.alpha * self.alpha
        if self.distribution == "ggx":
            # 2 / (1 + sqrt(1 + alpha^2 tan^2)), multiplied through by cos:
            return 2.0 * cos / (cos + math.sqrt(cos * cos + a2 * sin2))
        a = cos / (self.alpha * math.sqrt(sin2))  # 1 / (alpha tan(theta))
        if a == 0.0:
            return 0.0
        # erf(a) - 1 = -erfc(a), without the cancellation for large a.
        lam = 0.5 * (INV_SQRT_PI * math.exp(-a * a) / a - math.erfc(a))
        return 1.0 / (1.0 + max(0.0, lam))
        # END SOLUTION

    def G(self, wo: Local, wi: Local) -> float:
        """Shadowing-masking: the separable Smith product G1(wi) G1(wo)."""
        return self.G1(wi) * self.G1(wo)

    def F(self, cosine: float) -> Color:
        """Fresnel reflectance of a facet seen at incidence cosine wo . h."""
        return schlick_fresnel(self.f0, cosine)

    # --- the lobe, its sampling and its density -------------------------------------
    def specular(self, wo: Local, wi: Local) -> Color:
        # BEGIN SOLUTION week08: D G F / (4 cos_i cos_o)
        cos_o, cos_i = wo[2], wi[2]
        if cos_o <= 0.0 or cos_i <= 0.0:
            return Color(0.0, 0.0, 0.0)
        h = _half_vector(wo, wi)
        if h is None:
            return Color(0.0, 0.0, 0.0)
        wo_h = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2]
        # D G F / (4 cos_i cos_o), with each G1 divided by its own cosine: G1 vanishes
        # like its cosine at grazing angles, so each ratio stays finite (at most
        # about 2 / alpha) even where the product cos_i cos_o would underflow to 0.
        visibility = (self.G1(wi) / cos_i) * (self.G1(wo) / cos_o) * 0.25
        return self.F(wo_h) * (self.D(h) * visibility)
        # END SOLUTION

    def sample_half_vector(self, r1: float, r2: float) -> Local:
        """A half vector with density D(h) cos(theta_h), from two uniform numbers in [0, 1).

        Inverting the cumulative distribution of theta_h gives
            GGX:      tan^2(theta_h) = alpha^2 r1 / (1 - r1)
            Beckmann: tan^2(theta_h) = -alpha^2 ln(1 - r1)
        and phi_h = 2 pi r2 (D is the same in every direction around the normal).
        """
        # BEGIN SOLUTION week08: a half vector with density D(h) cos(theta_h)
        a2 = self.alpha * self.alpha
        if self.distribution == "ggx":
            tan2 = a2 * r1 / (1.0 - r1)
        else:
            tan2 = -a2 * math.log1p(-r1)
        cos = 1.0 / math.sqrt(1.0 + tan2)
        sin = math.sqrt(tan2) * cos
        phi = 2.0 * math.pi * r2
        return sin * math.cos(phi), sin * math.sin(phi), cos
        # END SOLUTION

    def sample_specular(self, wo: Local, r1: float, r2: float) -> Local | None:
        hx, hy, hz = self.sample_half_vector(r1, r2)
        wo_h = wo[0] * hx + wo[1] * hy + wo[2] * hz
        if wo_h <= 0.0:
            return None  # a facet turned away from the viewer reflects nothing toward it
        k = 2.0 * wo_h
        return k * hx - wo[0], k * hy - wo[1], k * hz - wo[2]

    def specular_pdf(self, wo: Local, wi: Local) -> float:
        """D(h) cos(theta_h) / (4 (wo . h)): the half vector's density times the
        Jacobian d(w_h) / d(w_i) = 1 / (4 (wo . h)) of the reflection wi = reflect(wo, h)."""
        # BEGIN SOLUTION week08: D(h) cos(theta_h) / (4 wo . h)
        h = _half_vector(wo, wi)
        if h is None:
            return 0.0
        wo_h = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2]
        if wo_h <= 0.0:
            return 0.0
        return self.D(h) * h[2] / (4.0 * wo_h)
        # END SOLUTION


def _half_vector(wo: Local, wi: Local) -> Local | None:
    """normalize(wo + wi), or None when wi = -wo."""
    x, y, z = wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]
    length = math.sqrt(x * x + y * y + z * z)
    if length == 0.0:
        return None
    return x / length, y / length, z / length
