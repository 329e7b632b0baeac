"""Kernels of RoughDielectric (rtpy/materials/rough_dielectric.py): one per microfacet
distribution, whose D, G1 and facet sampling are the Cook-Torrance kernels'."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import RoughDielectric
from ...materials import rough_dielectric as scalar
from ...materials.glossy import MAX_PDF
from ...materials.rough_dielectric import (
    fresnel_unpolarised,
    refracted_sin2,
    refraction_jacobian,
)
from ..arrays import compose, select
from ..hit_info import HitBatch
from ..onb import ONB
from ..scatter_info import ScatterBatch
from ..texture import TextureTable
from ..vec3 import Columns, components, dot, halfvector, negative, reflect, refract, stack, take
from .cook_torrance import BeckmannKernel, CookTorranceKernel, GGXKernel
from .material import Kernel, param


def fresnel_dielectric(cos_i: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """rough_dielectric.fresnel_dielectric: the exact Fresnel reflectance at incidence
    cosines cos_i in (0, 1], eta = n_t / n_i; 1 under total internal reflection."""
    sin2_t = refracted_sin2(cos_i, eta)
    tir = sin2_t >= 1.0
    cos_t = np.sqrt(np.where(tir, 0.0, 1.0 - sin2_t))
    return np.where(tir, 1.0, fresnel_unpolarised(cos_i, cos_t, eta))


def reflection_jacobian(wo_m: np.ndarray) -> np.ndarray:
    """rough_dielectric.reflection_jacobian, 1 / (4 |wo.m|), on arrays."""
    with np.errstate(over="ignore"):  # wo.m subnormal: inf, saturated by the pdf
        return scalar.reflection_jacobian(wo_m)


def where3(mask: np.ndarray, a: Columns, b: Columns) -> Columns:
    return np.where(mask, a[0], b[0]), np.where(mask, a[1], b[1]), np.where(mask, a[2], b[2])


class Facets:
    """Hits and light directions past the scalar methods' first checks (the viewer
    above the surface, wi off it), with the facet normal m that turns wo into wi:
    the rows `rows` of a batch, as columns, where m exists."""

    def __init__(self, kernel, slots, hits: HitBatch, wi: np.ndarray) -> None:
        normal, wo, wi = components(hits.normal), components(hits.wo), components(wi)
        cos_o, cos_i = dot(normal, wo), dot(normal, wi)
        k = select((cos_o > 0.0) & (cos_i != 0.0))
        normal, wo, wi, cos_o, cos_i = take(normal, k), take(wo, k), take(wi, k), cos_o[k], cos_i[k]
        eta = kernel.eta(slots[k], hits.front_face[k])
        reflects = cos_i > 0.0
        with np.errstate(invalid="ignore", divide="ignore"):  # the other lobe's m: not used
            m_t = halfvector(wo, (wi[0] * eta, wi[1] * eta, wi[2] * eta))  # wo + wi eta
            m_t = where3(dot(normal, m_t) < 0.0, negative(m_t), m_t)
            m = where3(reflects, halfvector(wo, wi), m_t)
        wo_m, wi_m = dot(wo, m), dot(wi, m)
        ok = select((dot(normal, m) > 0.0) & (wo_m > 0.0) & ((wi_m > 0.0) == reflects))
        self.rows = compose(k, ok)
        self.slots = slots[self.rows]
        self.normal, self.wo, self.wi, self.m = (
            take(normal, ok),
            take(wo, ok),
            take(wi, ok),
            take(m, ok),
        )
        self.cos_o, self.cos_i, self.eta = cos_o[ok], cos_i[ok], eta[ok]
        self.wo_m, self.wi_m = wo_m[ok], wi_m[ok]
        self.reflects = reflects[ok]
        self.alpha = kernel.alpha[self.slots]
        self.fresnel = fresnel_dielectric(self.wo_m, self.eta)
        self.d = kernel.facets.D(self.alpha, self.normal, self.m)

    def spread(self, values: np.ndarray, n: int) -> np.ndarray:
        out = np.zeros((n, *values.shape[1:]))
        out[self.rows] = values
        return out


class RoughDielectricKernel(Kernel):
    """Reflection and refraction through microfacets with the exact Fresnel
    reflectance; facet normals drawn from D(m) cos(theta_m), then reflection with
    probability F, else refraction. The distribution's D, G1 and sampler are those of
    facet_kernel."""

    has_brdf = True
    scatters = True
    facet_kernel: type[CookTorranceKernel]

    def __init__(self, materials: Sequence[RoughDielectric]) -> None:
        super().__init__(materials)
        self.facets = self.facet_kernel([m.facets for m in self.materials])
        self.alpha = param(self.materials, "alpha")
        self.inside_ior = param(self.materials, "inside_ior")
        self.tint_table = TextureTable([m.tint for m in self.materials])
        self.reads_uv = self.tint_table.reads_uv

    def flat_color(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return self.tint_table.value(slots, hits)

    def eta(self, slots: np.ndarray, front_face: np.ndarray) -> np.ndarray:
        """RoughDielectric.eta: the index beyond the surface over the viewer's side's."""
        ior = self.inside_ior[slots]
        return np.where(front_face, ior, 1.0 / ior)

    def brdf_at(self, f: Facets, hits: HitBatch) -> np.ndarray:
        """RoughDielectric.BRDF at the rows of f: (n, 3)."""
        g_o = self.facets.G1(f.alpha, f.normal, f.wo) / f.cos_o
        n_i = where3(f.reflects, f.normal, negative(f.normal))
        g_i = self.facets.G1(f.alpha, n_i, f.wi) / np.abs(f.cos_i)
        reflected = f.fresnel * f.d * g_o * g_i * 0.25
        denominator = f.eta * f.wi_m + f.wo_m
        transmitted = ((1.0 - f.fresnel) * f.d * g_o * g_i * np.abs(f.wi_m) * f.wo_m) / (
            denominator * denominator
        )
        tint = self.tint_table.value(f.slots, hits, f.rows)
        return np.where(f.reflects[:, None], reflected[:, None], tint * transmitted[:, None])

    def pdf_at(self, f: Facets) -> np.ndarray:
        """RoughDielectric.pdf at the rows of f: (n,)."""
        density_m = f.d * dot(f.normal, f.m)
        reflected = f.fresnel * density_m * reflection_jacobian(f.wo_m)
        transmitted = (1.0 - f.fresnel) * density_m * refraction_jacobian(f.wo_m, f.wi_m, f.eta)
        return np.minimum(np.where(f.reflects, reflected, transmitted), MAX_PDF)

    def BRDF(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        f = Facets(self, slots, hits, wi)
        return f.spread(self.brdf_at(f, hits), len(slots))

    def pdf(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        f = Facets(self, slots, hits, wi)
        return f.spread(self.pdf_at(f), len(slots))

    def BRDF_and_pdf(self, slots, hits, wi):
        f = Facets(self, slots, hits, wi)
        return f.spread(self.brdf_at(f, hits), len(slots)), f.spread(self.pdf_at(f), len(slots))

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        """RoughDielectric.scattering: three uniform numbers per hit whose viewer lies
        above the surface (the facet's two, then the lobe's); the others absorb."""
        n = len(slots)
        normal, wo = components(hits.normal), components(hits.wo)
        d = negative(wo)
        above = np.flatnonzero(dot(normal, d) < 0.0)
        normal, d, s = take(normal, above), take(d, above), slots[above]
        r = rng.random((3, len(above)))
        local = self.facets.sample_half_vector(self.alpha[s], r[0], r[1])
        m = ONB(normal).to_world(local)
        wo_m = -dot(d, m)
        eta = self.eta(s, hits.front_face[above])
        facing = wo_m > 0.0
        fresnel = fresnel_dielectric(np.where(facing, wo_m, 1.0), eta)
        reflects = r[2] < fresnel
        with np.errstate(invalid="ignore"):  # refraction under total internal reflection
            wi = where3(reflects, reflect(d, m), refract(d, m, 1.0 / eta))
        cos_i = dot(normal, wi)
        live = facing & np.where(reflects, cos_i > 0.0, cos_i < 0.0)
        rows = above[live]
        wi = stack(*take(wi, live))
        part = hits.take(rows)
        f = Facets(self, slots[rows], part, wi)
        pdf = self.pdf_at(f)
        weight = self.brdf_at(f, part) * (np.abs(f.cos_i) / pdf)[:, None]
        keep = pdf > 0.0
        return ScatterBatch.alive_at(
            n, rows[f.rows][keep], wi[f.rows][keep], weight[keep], pdf[keep]
        )


class RoughGGXKernel(RoughDielectricKernel):
    facet_kernel = GGXKernel


class RoughBeckmannKernel(RoughDielectricKernel):
    facet_kernel = BeckmannKernel


def rough_dielectric_kernel(material: RoughDielectric) -> type[RoughDielectricKernel]:
    """The kernel of a RoughDielectric instance: its distribution's."""
    return RoughGGXKernel if material.distribution == "ggx" else RoughBeckmannKernel
