"""Oren-Nayar: diffuse reflection from a rough surface.

Oren and Nayar (1994, "Generalization of Lambert's reflectance model") model a
surface as tiny V-shaped Lambertian facets whose slopes have standard deviation
sigma. Facets that face the light and the viewer at once make rough surfaces
(clay, plaster, the full moon) look flatter than Lambertian ones: brighter
toward the rim and when lit from behind the viewer. Their "qualitative" model:

    f_r(wi, wo) = albedo / pi * (A + B * max(0, cos(phi_i - phi_o)) * sin(alpha) * tan(beta))

    A = 1 - 0.5 s^2 / (s^2 + 0.33),   B = 0.45 s^2 / (s^2 + 0.09)

with s = sigma in radians, theta and phi the polar and azimuthal angles of wi
and wo in the local frame, alpha = max(theta_i, theta_o), beta = min(theta_i,
theta_o). sigma = 0 gives A = 1, B = 0: Lambertian.

The qualitative model is an approximation and does not conserve energy
exactly: the directional albedo goes from A * albedo at normal incidence to
(A + B / 2) * albedo at grazing, which exceeds the albedo by up to 1.5 % for
sigma around 11 degrees.
"""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..ray import Ray, spawn_ray
from ..sampling import random_cosine_direction
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import BLACK, Color
from .material import Material, as_texture

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
        if isinstance(sigma, bool) or not isinstance(sigma, int | float):
            raise ValueError(f"sigma must be a number of degrees in [0, 90), got {sigma!r}")
        if not 0.0 <= sigma < 90.0:  # also refuses NaN
            raise ValueError(f"sigma must be a number of degrees in [0, 90), got {sigma}")
        self.albedo = as_texture(albedo)
        self.sigma = float(sigma)
        s2 = math.radians(self.sigma) ** 2
        self.A = 1.0 - 0.5 * s2 / (s2 + 0.33)
        self.B = 0.45 * s2 / (s2 + 0.09)

    def _factor(self, wo: tuple[float, float, float], wi: tuple[float, float, float]) -> float:
        """A + B * max(0, cos(phi_i - phi_o)) * sin(alpha) * tan(beta), both directions
        above the surface (local frame, z = normal)."""
        if self.B == 0.0:
            return self.A
        # cos(phi_i - phi_o) * sin(theta_i) * sin(theta_o) is the dot product of the
        # directions' projections onto the surface, and sin(alpha) * sin(beta) is
        # sin(theta_i) * sin(theta_o), so the product of the three terms is that dot
        # product over cos(beta) = the larger cosine. No angles, no division by 0.
        cos_phi_sin_sin = wi[0] * wo[0] + wi[1] * wo[1]
        if cos_phi_sin_sin <= 0.0:
            return self.A
        cos_beta = max(wi[2], wo[2], MIN_COS)
        return self.A + self.B * cos_phi_sin_sin / cos_beta

    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        frame = hit.frame
        wo = frame.to_local(-ray_view.direction)
        wi = frame.to_local(ray_light.direction)
        if wo[2] <= 0.0 or wi[2] <= 0.0:
            return BLACK
        return self.albedo.value(hit) * (INV_PI * self._factor(wo, wi))

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        n, d, wi = hit.normal, ray_view.direction, ray_light.direction
        if n.e0 * d.e0 + n.e1 * d.e1 + n.e2 * d.e2 >= 0.0:
            return 0.0  # viewer below the surface: scattering() absorbs
        return max(0.0, n.e0 * wi.e0 + n.e1 * wi.e1 + n.e2 * wi.e2) * INV_PI

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        frame = hit.frame
        wo = frame.to_local(-ray_in.direction)
        if wo[2] <= 0.0:
            return None
        wi = random_cosine_direction()
        pdf = wi[2] * INV_PI
        if not pdf > 0.0:
            return None
        # BRDF * cos / pdf = albedo / pi * factor * cos / (cos / pi) = albedo * factor.
        weight = self.albedo.value(hit) * self._factor(wo, wi)
        direction = frame.to_world(*wi)
        return ScatterInfo(spawn_ray(hit.point, hit.normal, direction), weight, pdf)
