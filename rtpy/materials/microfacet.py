"""The microfacet formulas of GGX and Beckmann, for Cook-Torrance and the rough
dielectric, in both backends.

Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces",
section 5, with alpha the width (rtpy/materials/cook_torrance.py explains them):

    GGX:      D = alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2)
              G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2))
              tan^2(theta_h) = alpha^2 r1 / (1 - r1)          (sampling D cos)
    Beckmann: D = exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4)
              G1 = 1 / (1 + Lambda(a)),  a = 1 / (alpha tan),
              Lambda(a) = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi))
              tan^2(theta_h) = -alpha^2 ln(1 - r1)

Each is written with cos^2 and sin^2 = |normal x v|^2 rather than tan^2, and
multiplied out so that no cosine is divided by: finite at grazing angles and for tiny
widths. The functions are the arithmetic alone, for one direction: the callers decide
what lies below the horizon (where D and G1 are 0). The numpy backend has its own
vectorized copies of those that call math's functions
(rtpy/numpy_backend/materials/cook_torrance.py), the same operations in the same order.
"""

from __future__ import annotations

import math

INV_SQRT_PI = 1.0 / math.sqrt(math.pi)


def ggx_d(a2, cos2, sin2):
    """GGX's D at a half vector of cos^2 cos2 and sin^2 sin2 from the normal (alpha^2 =
    a2): alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2) multiplied out by cos^4."""
    k = a2 * cos2 + sin2
    return a2 / (math.pi * k * k)


def beckmann_exponent(a2, cos2, sin2):
    """tan^2 / alpha^2, the exponent of Beckmann's D (the caller keeps a2 cos2 nonzero,
    and D is 0, by underflow, where this passes 700)."""
    return sin2 / (a2 * cos2)


def beckmann_d(a2, cos2, exponent):
    """Beckmann's D, exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4), from its exponent."""
    return math.exp(-exponent) / (math.pi * a2 * cos2 * cos2)


def ggx_g1(a2, cos, sin2):
    """GGX's Smith masking of a direction above the surface (cos > 0):
    2 / (1 + sqrt(1 + alpha^2 tan^2)) multiplied through by cos."""
    return 2.0 * cos / (cos + math.sqrt(cos * cos + a2 * sin2))


def beckmann_a(alpha, cos, sin2):
    """a = 1 / (alpha tan(theta)) of a direction off the normal (sin2 > 0)."""
    return cos / (alpha * math.sqrt(sin2))


def beckmann_lambda(a):
    """Beckmann's Lambda(a) for a > 0, with erf(a) - 1 = -erfc(a), which does not
    cancel for large a; G1 = 1 / (1 + max(0, Lambda))."""
    return 0.5 * (INV_SQRT_PI * math.exp(-a * a) / a - math.erfc(a))


def ggx_tan2(a2, r1):
    """tan^2(theta_h) of a half vector with density D cos, from a uniform r1 in [0, 1)."""
    return a2 * r1 / (1.0 - r1)


def beckmann_tan2(a2, r1):
    """tan^2(theta_h) of a half vector with density D cos, from a uniform r1 in [0, 1)."""
    return -a2 * math.log1p(-r1)


def cos_sin_of_tan2(tan2):
    """(cos, sin) of the angle whose tangent squared is tan2."""
    cos = 1.0 / math.sqrt(1.0 + tan2)
    return cos, math.sqrt(tan2) * cos
