"""The diffuse + highlight mixture that Phong, Blinn-Phong, Cook-Torrance and Ward share.

Each of these models reflects

    f_r(wi, wo) = kd * albedo / pi + ks * (its highlight lobe)

and writes its own BRDF(), pdf() and scattering() in world space, with
wo = -ray_view.direction (toward the viewer) and wi = ray_light.direction (toward
the light), both pointing away from the surface. scattering() picks the diffuse
lobe (cosine-weighted around the normal) with probability

    p_d = kd * max(albedo) / (kd * max(albedo) + ks),

else it draws a direction from the highlight, so a direction's density is the
mixture

    pdf(wi) = p_d * cos(theta_i) / pi + (1 - p_d) * (the highlight's density of wi)

and a sample's weight is BRDF * cos(theta_i) / pdf(wi), whichever lobe drew it.
The functions below are those shared pieces; the models call them. Drawing from
one lobe chosen at random and weighing by the density of the whole mixture is the
one-sample model of combining sampling strategies (Veach 1997, "Robust Monte Carlo
Methods for Light Transport Simulation", chapter 9; pbrt, 3rd ed., section 14.1,
samples a BSDF of several lobes the same way).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..hit_info import HitInfo
from ..ray import Ray, spawn_ray
from ..scatter_info import ScatterInfo
from ..vec3 import Vec3, dot

if TYPE_CHECKING:
    from .material import Material

INV_PI = 1.0 / math.pi

# Densities saturate here. A lobe seen at a subnormal grazing cosine can ask for more
# than float64 holds (1 / (4 wo.h) with wo.h = 5e-324); inf would turn the MIS weight
# pdf^2 / (pdf^2 + other^2) into inf / inf. 1e150 keeps pdf^2 finite.
MAX_PDF = 1e150


def diffuse_probability(material: Material, hit: HitInfo) -> float:
    """p_d = kd * max(albedo) / (kd * max(albedo) + ks) of a material with albedo, kd
    and ks at this hit (1 when both lobes are black)."""
    diffuse = material.kd * material.albedo.value(hit).max_component()
    total = diffuse + material.ks
    return diffuse / total if total > 0.0 else 1.0


def mixture_pdf(p_diffuse: float, cos_i: float, highlight_pdf: float) -> float:
    """p_d * cos(theta_i) / pi + (1 - p_d) * highlight_pdf, at most MAX_PDF: the
    density of a direction drawn from the diffuse lobe with probability p_d, else
    from the highlight (Veach 1997, chapter 9)."""
    pdf = p_diffuse * cos_i * INV_PI
    if p_diffuse < 1.0:  # (highlight_pdf may be inf at a grazing half vector)
        pdf += (1.0 - p_diffuse) * highlight_pdf
    return min(pdf, MAX_PDF)


def reflected_density(half_vector_density: float, wo: Vec3, h: Vec3) -> float:
    """The density of wi = reflect(-wo, h) when the unit half vector h is drawn with
    half_vector_density: that times the Jacobian d(w_h) / d(w_i) = 1 / (4 (wo . h)) of
    the reflection (Torrance and Sparrow 1967, "Theory for Off-Specular Reflection
    from Roughened Surfaces"; derived again by Walter et al. 2007, "Microfacet Models
    for Refraction through Rough Surfaces"); 0 when h faces away from wo."""
    wo_h = dot(wo, h)
    if wo_h <= 0.0:
        return 0.0
    return half_vector_density / (4.0 * wo_h)


def weighted_sample(material: Material, ray_in: Ray, hit: HitInfo, wi: Vec3) -> ScatterInfo | None:
    """The ScatterInfo of the direction wi that material.scattering() drew: the ray
    toward wi and the weight BRDF * cos(theta_i) / pdf, with the material's own BRDF()
    and pdf(): the Monte Carlo estimator of the reflection integral for one sample.
    None (absorbed) when wi lies below the surface (a reflection about a half vector
    that faces away from the viewer does) or pdf() gives it no density."""
    cos_i = dot(hit.normal, wi)
    if cos_i <= 0.0:
        return None  # drawn below the surface: no reflected light
    ray_light = spawn_ray(hit.point, hit.normal, wi)
    pdf = material.pdf(ray_in, ray_light, hit)
    if not pdf > 0.0:
        return None
    weight = material.BRDF(ray_in, ray_light, hit) * (cos_i / pdf)
    return ScatterInfo(ray_light, weight, pdf)
