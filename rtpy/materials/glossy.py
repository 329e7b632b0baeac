"""GlossyMaterial: a diffuse lobe plus a specular lobe, sampled as a mixture.

f_r(wi, wo) = kd * albedo / pi + ks * specular(wi, wo)

Phong, Blinn-Phong, Cook-Torrance and Ward share this structure and differ only
in the specular lobe, which a subclass gives in the local shading frame:
z along the normal (facing the viewer), x along the surface tangent (the
direction of increasing u). Both directions point away from the surface:
wo toward the viewer, wi toward the light.

Sampling picks the diffuse lobe (cosine-weighted) with probability
p_d = kd * max(albedo) / (kd * max(albedo) + ks), else the specular lobe, so
pdf(wi) = p_d * cos(theta_i) / pi + (1 - p_d) * specular_pdf(wo, wi) and the
sample's weight is f_r * cos(theta_i) / pdf(wi), whichever lobe produced it.
"""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..onb import ONB
from ..ray import Ray, spawn_ray
from ..sampling import generator, random_cosine_direction
from ..scatter_info import ScatterInfo
from ..texture import Texture
from ..vec3 import BLACK, Color
from .material import Material, as_texture

INV_PI = 1.0 / math.pi

# Densities saturate here. A lobe seen at a subnormal grazing cosine can ask for more
# than float64 holds (1 / (4 wo.h) with wo.h = 5e-324); inf would turn the MIS weight
# pdf^2 / (pdf^2 + other^2) into inf / inf. 1e150 keeps pdf^2 finite.
MAX_PDF = 1e150

Local = tuple[float, float, float]  # a unit direction in the shading frame


class GlossyMaterial(Material):
    """Base class; subclasses implement specular, sample_specular and specular_pdf."""

    def __init__(self, albedo: Color | Texture, kd: float, ks: float) -> None:
        if not (isinstance(kd, int | float) and kd >= 0.0 and math.isfinite(kd)):
            raise ValueError(f"kd must be a finite number >= 0, got {kd}")
        if not (isinstance(ks, int | float) and ks >= 0.0 and math.isfinite(ks)):
            raise ValueError(f"ks must be a finite number >= 0, got {ks}")
        self.albedo = as_texture(albedo)
        self.kd = float(kd)
        self.ks = float(ks)

    # --- the specular lobe (subclasses) ---------------------------------------
    def specular(self, wo: Local, wi: Local) -> Color:
        """The specular lobe's f_r (without ks), for wo and wi both above the surface."""
        raise NotImplementedError

    def sample_specular(self, wo: Local, r1: float, r2: float) -> Local | None:
        """A direction wi drawn with density specular_pdf(wo, wi); may lie below the
        surface (the caller then absorbs the sample). None if no direction."""
        raise NotImplementedError

    def specular_pdf(self, wo: Local, wi: Local) -> float:
        """Solid-angle density of sample_specular choosing wi."""
        raise NotImplementedError

    # --- shared machinery -------------------------------------------------------
    def frame(self, hit: HitInfo) -> ONB:
        return hit.frame

    def diffuse_probability(self, albedo: Color) -> float:
        diffuse = self.kd * max(albedo.e0, albedo.e1, albedo.e2)
        total = diffuse + self.ks
        return diffuse / total if total > 0.0 else 1.0

    def _f(self, albedo: Color, wo: Local, wi: Local) -> Color:
        f = albedo * (self.kd * INV_PI)
        if self.ks > 0.0:
            f = f + self.specular(wo, wi) * self.ks
        return f

    def _pdf(self, p_diffuse: float, wo: Local, wi: Local) -> float:
        pdf = p_diffuse * wi[2] * INV_PI
        if p_diffuse < 1.0:
            pdf += (1.0 - p_diffuse) * self.specular_pdf(wo, wi)
        return min(pdf, MAX_PDF)

    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        frame = self.frame(hit)
        wo = frame.to_local(-ray_view.direction)
        wi = frame.to_local(ray_light.direction)
        if wo[2] <= 0.0 or wi[2] <= 0.0:
            return BLACK  # reflection only: both directions above the surface
        return self._f(self.albedo.value(hit), wo, wi)

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        frame = self.frame(hit)
        wo = frame.to_local(-ray_view.direction)
        wi = frame.to_local(ray_light.direction)
        if wo[2] <= 0.0 or wi[2] <= 0.0:
            return 0.0
        return self._pdf(self.diffuse_probability(self.albedo.value(hit)), wo, wi)

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        # BEGIN SOLUTION week08: pick a lobe, sample it; weight = BRDF * cos / pdf of the mixture
        frame = self.frame(hit)
        wo = frame.to_local(-ray_in.direction)
        if wo[2] <= 0.0:
            return None
        albedo = self.albedo.value(hit)
        p_diffuse = self.diffuse_probability(albedo)
        r = generator().random
        if r() < p_diffuse:
            wi = random_cosine_direction()
        else:
            wi = self.sample_specular(wo, r(), r())
        if wi is None or wi[2] <= 0.0:
            return None  # sampled below the surface: no reflected light
        pdf = self._pdf(p_diffuse, wo, wi)
        if not pdf > 0.0:
            return None
        weight = self._f(albedo, wo, wi) * (wi[2] / pdf)
        direction = frame.to_world(*wi)
        return ScatterInfo(spawn_ray(hit.point, hit.normal, direction), weight, pdf)
        # END SOLUTION
