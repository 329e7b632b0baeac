"""Oren-Nayar: diffuse reflection from a rough surface.

Oren and Nayar (1994, "Generalization of Lambert's reflectance model") model a
surface as tiny V-shaped Lambertian facets whose slopes have standard deviation
sigma. Facets that face the light and the viewer at once make rough surfaces
(clay, plaster, the full moon) look flatter than Lambertian ones: brighter
toward the rim and when lit from behind the viewer. Their "qualitative" model:

    f_r(wi, wo) = albedo / pi * (A + B * max(0, cos(phi_i - phi_o)) * sin(alpha) * tan(beta))

    A = 1 - 0.5 s^2 / (s^2 + 0.33),   B = 0.45 s^2 / (s^2 + 0.09)

with s = sigma in radians, theta and phi the polar and azimuthal angles of wi
and wo about the normal, alpha = max(theta_i, theta_o), beta = min(theta_i,
theta_o). sigma = 0 gives A = 1, B = 0: Lambertian.

The qualitative model is an approximation and does not conserve energy
exactly: the directional albedo goes from A * albedo at normal incidence to
(A + B / 2) * albedo at grazing, which exceeds the albedo by up to 1.5 % for
sigma around 11 degrees.
"""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..ray import Ray
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import BLACK, Color, dot
from .lambertian import Lambertian
from .material import Material, as_texture, material_number

INV_PI = 1.0 / math.pi

# Below this cosine both directions count as lying in the surface: the term
# tan(beta) / (sin(theta_i) sin(theta_o)) is 1 / cos(beta), which must stay finite.
MIN_COS = 1e-12


class OrenNayar(Material):
    """Rough diffuse reflection (Oren-Nayar qualitative model).

    albedo  colour (or texture) of the surface
    sigma   roughness: the standard deviation of the facet slopes in degrees,
            0 <= sigma < 90. 0 is Lambertian; larger values flatten the shading
            (darker toward the normal, brighter at grazing and back-lit angles).
            Typical rough materials lie between 10 and 40.

    Sampling is cosine-weighted, pdf = cos(theta_i) / pi, as for Lambertian.
    """

    def __init__(self, albedo: Color | Texture = Color(0.5, 0.5, 0.5), sigma: float = 20.0) -> None:
        self.albedo = as_texture(albedo)
        self.sigma = material_number("sigma", sigma)  # degrees
        s2 = math.radians(self.sigma) ** 2
        self.A = 1.0 - 0.5 * s2 / (s2 + 0.33)
        self.B = 0.45 * s2 / (s2 + 0.09)

    def factor(self, cos_o: float, cos_i: float, cos_oi: float) -> float:
        """A + B * max(0, cos(phi_i - phi_o)) * sin(alpha) * tan(beta) for directions
        wo and wi above the surface, from cos_o = normal . wo, cos_i = normal . wi and
        cos_oi = wo . wi."""
        if self.B == 0.0:
            return self.A
        # cos(phi_i - phi_o) * sin(theta_i) * sin(theta_o) is the dot product of the
        # directions' projections onto the surface, wo . wi - cos_o cos_i, and
        # sin(alpha) * sin(beta) is sin(theta_i) * sin(theta_o), so the product of the
        # three terms is that dot product over cos(beta) = the larger cosine. No
        # angles, no division by 0.
        projected = cos_oi - cos_o * cos_i
        if projected <= 0.0:
            return self.A
        return rough_factor(self.A, self.B, projected, max(cos_i, cos_o, MIN_COS))

    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        """albedo / pi * factor; black unless wo and wi both lie above the surface."""
        normal, wo, wi = hit.normal, -ray_view.direction, ray_light.direction
        cos_o, cos_i = dot(normal, wo), dot(normal, wi)
        if cos_o <= 0.0 or cos_i <= 0.0:
            return BLACK
        return self.albedo.value(hit) * (INV_PI * self.factor(cos_o, cos_i, dot(wo, wi)))

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        normal = hit.normal
        if dot(normal, ray_view.direction) >= 0.0:
            return 0.0  # viewer below the surface: scattering() absorbs
        return max(0.0, dot(normal, ray_light.direction)) * INV_PI

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        """Lambertian's sample (a cosine-weighted direction, weight albedo) with its
        weight times factor: BRDF * cos / pdf = albedo / pi * factor * cos / (cos / pi)."""
        normal = hit.normal
        cos_o = -dot(normal, ray_in.direction)
        if cos_o <= 0.0:
            return None  # viewer below the surface
        sample = Lambertian.scattering(self, ray_in, hit)  # uses only self.albedo
        if sample is None:
            return None
        wi = sample.scattered_ray.direction
        cos_i = dot(normal, wi)
        if not (cos_i > 0.0 and sample.pdf > 0.0):
            return None
        factor = self.factor(cos_o, cos_i, -dot(ray_in.direction, wi))
        return ScatterInfo(sample.scattered_ray, sample.attenuation * factor, sample.pdf)


def rough_factor(a, b, projected, larger_cosine):
    """A + B (wo . wi - cos_o cos_i) / max(cos_o, cos_i): Oren-Nayar's factor where the
    projections' dot product is positive (floats, or arrays in the numpy kernel)."""
    return a + b * projected / larger_cosine
