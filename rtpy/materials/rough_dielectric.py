"""Rough dielectric: frosted, ground or etched glass that reflects and refracts
through microfacets (Walter, Marschner, Li and Torrance 2007, "Microfacet Models for
Refraction through Rough Surfaces", EGSR; the week-8 lecture's "BRDF for refraction").

The surface is a landscape of tiny smooth facets, distributed as in Cook-Torrance:
D(m) is the density of facet normals m (GGX or Beckmann, width alpha = roughness) and
G the Smith masking-shadowing term, G = G1(wo) G1(wi) (rtpy.materials.cook_torrance
has both). Each facet is a smooth glass boundary: it reflects the fraction F of the
light and refracts the rest. Light goes from wi to wo through the facets whose normal
is m, the normal that turns one into the other:

    reflection (wi on the viewer's side):   m = normalize(wo + wi)
    refraction (wi on the other side):      m = normalize(eta_o wo + eta_i wi)

(oriented toward the viewer's side), with eta_o and eta_i the indices of refraction
on the sides of wo and of wi. The BSDF (the "BRDF" of this material, for both lobes)
is Walter et al.'s eq. 20 and 21:

    f_r(wo, wi) = F(wo.m) D(m) G / (4 |n.wi| |n.wo|)
    f_t(wo, wi) = tint * (1 - F(wo.m)) D(m) G |wi.m| |wo.m| eta_o^2
                  / (|n.wi| |n.wo| (eta_i wi.m + eta_o wo.m)^2)

with F the exact Fresnel reflectance of a smooth dielectric (unpolarised light), not
Schlick's approximation: Schlick's errs most near total internal reflection, which
light leaving the glass meets on every facet tilted past the critical angle. A facet
must face the viewer (wo.m > 0), and wi must leave it on its own side: in front of
it for reflection (wi.m > 0), behind it for refraction (wi.m < 0); other
directions get 0.

Radiance transport. f_t is not symmetric: radiance entering a denser medium is
compressed into a narrower cone, so it grows by (eta_o / eta_i)^2, the factor eta_o^2
/ (eta_i wi.m + eta_o wo.m)^2 carries (Veach 1997, section 5.2). This is the BSDF for
radiance flowing from wi to wo, the way the path tracer uses it: it starts at the
camera (wo) and draws the direction the light came from (wi). It obeys the
generalised reciprocity f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2. Light passing in
and out of a closed glass object is scaled by eta^2 and by 1 / eta^2, which cancel;
a camera inside glass sees the outside eta^2 times brighter.

Sampling (as Walter et al. propose): a facet normal m with density D(m) cos(theta_m)
(Cook-Torrance's sample_half_vector), then reflection about m with probability
F(wo.m), else refraction through m. A facet that faces away from the viewer, or a
direction that ends on the wrong side of the surface, absorbs the sample. The density
of wi is that of m times the Jacobian |d w_m / d w_i| of the turn (eq. 14 and 17):

    reflection:  pdf = F D(m) cos(theta_m) / (4 |wo.m|)
    refraction:  pdf = (1 - F) D(m) cos(theta_m) eta_i^2 |wi.m| / (eta_i wi.m + eta_o wo.m)^2

so a sample's weight BSDF * |cos(theta_i)| / pdf is G |wo.m| / (|n.wo| cos(theta_m)),
times tint (eta_o / eta_i)^2 after a refraction.

Parameters:
    ior           index of refraction inside (behind the geometric normal) over
                  outside: 1.5 is glass, 1.33 water; below 1, a bubble. Within 1e-6
                  of 1 it is computed as 1 +- 1e-6: at 1 the refracted light goes
                  straight on whatever the facet, a direction without a density.
    roughness     alpha in (0, 1], the width of the facet distribution: the lecture's
                  anti-glare glass is Beckmann 0.023, ground glass GGX 0.394, etched
                  glass GGX 0.553
    distribution  "ggx" (a sharp core with a soft halo) or "beckmann" (no halo)
    tint          colour (or texture) of the light passing through the surface, at
                  each crossing (twice through a solid object); the reflection off
                  the surface stays white, as on real glass

Energy. The model scatters light once, off one facet: light that a facet sends into
a neighbouring facet (which G counts as blocked) is lost, not scattered again. The
fraction of the light arriving from one direction that is lost (measured by
rtpy.testing.directional_albedo; reflected + transmitted + lost = 1):

                         from outside        from inside
    incidence             0 deg   60 deg      0 deg   60 deg
    anti-glare (0.023)    0.0 %    0.0 %      0.0 %    0.0 %
    ground (0.394)        2.0 %    8.1 %     16.5 %   29.1 %
    etched (0.553)        3.9 %   13.8 %     28.7 %   38.5 %

From inside most of it is light that facets tilted past the critical angle reflect
totally, into the surface (facets steeper than 45 degrees at normal incidence),
where a real surface would scatter it again: rough glass looks darker than it should.
"""

from __future__ import annotations

import math
from typing import Literal

from ..hit_info import HitInfo
from ..onb import ONB
from ..ray import Ray, spawn_ray
from ..sampling import generator
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import BLACK, WHITE, Color, Vec3, dot, halfvector, reflect, refract, unit_vector
from .cook_torrance import CookTorrance
from .glossy import MAX_PDF
from .material import Material, as_texture, material_number

# An ior closer to 1 than this is computed as 1 +- this (see RoughDielectric).
MIN_IOR_GAP = 1e-6


def fresnel_dielectric(cos_i: float, eta: float) -> float:
    """The exact Fresnel reflectance of unpolarised light at a smooth boundary, for
    light arriving at incidence cosine cos_i (in (0, 1]) from the side of index n_i,
    with eta = n_t / n_i the index beyond the boundary over this side's. 1 under total
    internal reflection (sin(theta_t) = sin(theta_i) / eta >= 1)."""
    sin2_t = refracted_sin2(cos_i, eta)
    if sin2_t >= 1.0:
        return 1.0
    return fresnel_unpolarised(cos_i, math.sqrt(1.0 - sin2_t), eta)


# The formulas below work on floats and on numpy arrays alike: the numpy backend's
# rough dielectric computes with them.


def refracted_sin2(cos_i, eta):
    """sin^2 of the refracted angle by Snell's law, sin_t = sin_i / eta (>= 1: total
    internal reflection)."""
    return (1.0 - cos_i * cos_i) / (eta * eta)


def fresnel_unpolarised(cos_i, cos_t, eta):
    """The mean of the s- and p-polarised Fresnel reflectances of the boundary between
    the incidence cosine cos_i and the refracted cosine cos_t."""
    r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (r_s * r_s + r_p * r_p)


def reflection_jacobian(wo_m: float) -> float:
    """|d w_m / d w_i| = 1 / (4 |wo.m|) of wi = reflect(-wo, m) (Walter et al. eq. 14)."""
    return 0.25 / wo_m


def refraction_jacobian(wo_m: float, wi_m: float, eta: float) -> float:
    """|d w_m / d w_i| = eta^2 |wi.m| / (eta wi.m + wo.m)^2 of wi refracted from -wo
    through m, eta = eta_i / eta_o (Walter et al. eq. 17 divided through by eta_o^2)."""
    denominator = eta * wi_m + wo_m
    return eta * eta * abs(wi_m) / (denominator * denominator)


class RoughDielectric(Material):
    """A rough boundary between two dielectrics: reflection and refraction through
    microfacets, with the exact Fresnel reflectance (see the module's docstring for
    the formulas and the parameters)."""

    def __init__(
        self,
        ior: float = 1.5,
        roughness: float = 0.1,
        distribution: Literal["ggx", "beckmann"] = "ggx",
        tint: Color | Texture = Color(1.0, 1.0, 1.0),
    ) -> None:
        ior = material_number("ior", ior)
        # The facets' D, G1 and sampling are Cook-Torrance's (which checks roughness
        # and distribution).
        self.facets = CookTorrance(kd=0.0, ks=1.0, roughness=roughness, distribution=distribution)
        self.ior = float(ior)
        self.roughness = self.facets.roughness
        self.alpha = self.facets.alpha
        self.distribution = distribution
        self.tint = as_texture(tint, "tint")
        if abs(self.ior - 1.0) < MIN_IOR_GAP:
            self.inside_ior = 1.0 + math.copysign(MIN_IOR_GAP, self.ior - 1.0)
        else:
            self.inside_ior = self.ior

    def flat_color(self, hit: HitInfo) -> Color:
        return self.tint.value(hit)

    def eta(self, hit: HitInfo) -> float:
        """The index of refraction beyond the surface over that on the viewer's side:
        ior when the viewer is outside (hit.front_face), 1 / ior inside."""
        return self.inside_ior if hit.front_face else 1.0 / self.inside_ior

    def facet_normal(self, normal: Vec3, wo: Vec3, wi: Vec3, eta: float) -> Vec3 | None:
        """The facet normal m that turns wo into wi, on the viewer's side of the
        surface; None when no facet does (m in the surface, the facet facing away from
        the viewer, or wi on the wrong side of it)."""
        reflects = dot(normal, wi) > 0.0
        if reflects:
            m = halfvector(wo, wi)
        else:
            m = unit_vector(wo + wi * eta)  # never 0: |eta - 1| >= MIN_IOR_GAP
            if dot(normal, m) < 0.0:
                m = -m
        if dot(normal, m) <= 0.0 or dot(wo, m) <= 0.0 or (dot(wi, m) > 0.0) != reflects:
            return None
        return m

    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        """The BSDF f(wo, wi) for radiance arriving from wi, either side of the
        surface: F D G / (4 |cos_i| cos_o) for reflection, tint (1 - F) D G |wi.m|
        |wo.m| / (|cos_i| cos_o (eta wi.m + wo.m)^2) for refraction, where eta =
        eta_i / eta_o (so that eta_o^2 has been divided out)."""
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        cos_o, cos_i = dot(normal, wo), dot(normal, wi)
        if cos_o <= 0.0 or cos_i == 0.0:
            return BLACK
        eta = self.eta(hit)
        m = self.facet_normal(normal, wo, wi, eta)
        if m is None:
            return BLACK
        wo_m, wi_m = dot(wo, m), dot(wi, m)
        fresnel = fresnel_dielectric(wo_m, eta)
        # G1 of wi from its own side; each G1 over its own cosine stays finite at grazing
        # angles (see CookTorrance.BRDF).
        g_o = self.facets.G1(normal, wo) / cos_o
        g_i = self.facets.G1(normal if cos_i > 0.0 else -normal, wi) / abs(cos_i)
        d = self.facets.D(normal, m)
        if cos_i > 0.0:
            return WHITE * (fresnel * d * g_o * g_i * 0.25)
        denominator = eta * wi_m + wo_m
        f = (1.0 - fresnel) * d * g_o * g_i * abs(wi_m) * wo_m / (denominator * denominator)
        return self.tint.value(hit) * f

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        """Density of scattering() choosing ray_light's direction: the facet normal's
        density D(m) cos(theta_m), times the probability of the lobe (F or 1 - F),
        times the Jacobian of reflection or refraction."""
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        cos_i = dot(normal, wi)
        if dot(normal, wo) <= 0.0 or cos_i == 0.0:
            return 0.0
        eta = self.eta(hit)
        m = self.facet_normal(normal, wo, wi, eta)
        if m is None:
            return 0.0
        wo_m = dot(wo, m)
        fresnel = fresnel_dielectric(wo_m, eta)
        density_m = self.facets.D(normal, m) * dot(normal, m)
        if cos_i > 0.0:
            pdf = fresnel * density_m * reflection_jacobian(wo_m)
        else:
            pdf = (1.0 - fresnel) * density_m * refraction_jacobian(wo_m, dot(wi, m), eta)
        return min(pdf, MAX_PDF)

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        """A facet normal m from D(m) cos(theta_m); reflection about m with probability
        F(wo.m), else refraction through it; weight BSDF * |cos(theta_i)| / pdf."""
        normal, d = hit.normal, ray_in.direction
        if dot(normal, d) >= 0.0:
            return None  # the viewer below the surface: nothing scatters toward it
        r = generator().random
        m = ONB(normal).to_world(self.facets.sample_half_vector(r(), r()))
        wo_m = -dot(d, m)
        if wo_m <= 0.0:
            return None  # a facet turned away from the viewer
        eta = self.eta(hit)
        if r() < fresnel_dielectric(wo_m, eta):
            wi = reflect(d, m)
            if dot(normal, wi) <= 0.0:
                return None  # reflected into the surface
        else:
            wi = refract(d, m, 1.0 / eta)
            if dot(normal, wi) >= 0.0:
                return None  # refracted to the viewer's side of the surface
        ray_light = spawn_ray(hit.point, normal, wi)
        pdf = self.pdf(ray_in, ray_light, hit)
        if not pdf > 0.0:
            return None
        weight = self.BRDF(ray_in, ray_light, hit) * (abs(dot(normal, wi)) / pdf)
        return ScatterInfo(ray_light, weight, pdf)
