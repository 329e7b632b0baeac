"""Blinn-Phong: a diffuse lobe plus a highlight around the half vector.

    f_r(wi, wo) = kd * albedo / pi + ks * (n + 8) / (8 pi) * max(0, n . h)^n

with n = exponent and h = normalize(wi + wo), the half vector: the highlight is
brightest where the surface normal lies halfway between light and viewer. The
half-vector form is Blinn's (1977, "Models of light reflection for computer
synthesized pictures"). The factor (n + 8) / (8 pi) is the usual approximate
energy normalisation (Akenine-Moeller, Haines and Hoffman, "Real-Time
Rendering"); unlike Phong's (n + 2) / (2 pi) it is not exact: at normal
incidence the highlight reflects ks for n = 0 but up to 7.5 % more than ks
near n = 10 (1.8 % at n = 100), so keep kd * max(albedo) + ks a little below 1.
"""

from __future__ import annotations

import math

from ..texture import Texture
from ..vec3 import WHITE, Color
from .glossy import GlossyMaterial, Local
from .phong import check_exponent, cosine_power_pdf, sample_cosine_power

INV_EIGHT_PI = 0.125 / math.pi


class BlinnPhong(GlossyMaterial):
    """Diffuse plus a Blinn-Phong highlight.

    albedo    colour (or texture) of the diffuse part
    kd        strength of the diffuse part
    ks        strength of the highlight (white: the highlight has the light's colour)
    exponent  sharpness of the highlight: larger values make a smaller, brighter
              spot. For the same look as Phong with exponent e, use about 4 e
              (the angle between h and the normal is about half the angle
              between r and wo).

    Sampling draws the half vector h around the normal with density
    (n + 1) / (2 pi) * (n . h)^n and reflects wo about it: wi = 2 (wo . h) h - wo.
    Changing variables from h to wi divides the density by 4 (wo . h), the
    Jacobian of the reflection. A half vector facing away from the viewer
    (wo . h <= 0) gives no reflected direction: that sample is absorbed.
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

    def specular(self, wo: Local, wi: Local) -> Color:
        # BEGIN SOLUTION week08: the Blinn-Phong lobe (n + 8) / (8 pi) (n . h)^n
        hx, hy, hz = wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]
        length = math.sqrt(hx * hx + hy * hy + hz * hz)
        cos_h = hz / length  # wo and wi above the surface, so hz > 0
        n = self.exponent
        return WHITE * ((n + 8.0) * INV_EIGHT_PI * cos_h**n)
        # END SOLUTION

    def sample_specular(self, wo: Local, r1: float, r2: float) -> Local | None:
        # BEGIN SOLUTION week08: sample a half vector, reflect wo about it
        hx, hy, hz = sample_cosine_power(self.exponent, r1, r2)
        wo_h = wo[0] * hx + wo[1] * hy + wo[2] * hz
        if wo_h <= 0.0:
            return None
        k = 2.0 * wo_h
        return k * hx - wo[0], k * hy - wo[1], k * hz - wo[2]
        # END SOLUTION

    def specular_pdf(self, wo: Local, wi: Local) -> float:
        # BEGIN SOLUTION week08: the half-vector density / (4 wo . h)
        hx, hy, hz = wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]
        length = math.sqrt(hx * hx + hy * hy + hz * hz)
        if length == 0.0:
            return 0.0  # wi = -wo: no half vector
        wo_h = (wo[0] * hx + wo[1] * hy + wo[2] * hz) / length
        if wo_h <= 0.0:
            return 0.0
        return cosine_power_pdf(self.exponent, hz / length) / (4.0 * wo_h)
        # END SOLUTION
