"""The diffuse + highlight mixture of the glossy kernels: the batched rtpy.materials.glossy.

The scalar Phong, BlinnPhong, CookTorrance and Ward write BRDF(), pdf() and
scattering() in world space, each in the same shape. GlossyKernel writes that shape
once, on Bounces (material.py: the hits with wo, and wi, as columns), and a model's
kernel gives the lines that differ, in the scalar model's order:

    BRDF()        black unless wo and wi both lie above the surface; else
                  kd * albedo / pi plus highlight(b), the model's highlight term (ks
                  included, 0 where the scalar model adds nothing)
    pdf()         0 unless both lie above; else mixture_pdf(diffuse_probability,
                  cos_i, highlight_pdf(b)), with the highlight's density of wi
    scattering()  the diffuse lobe (a cosine-weighted direction around the normal)
                  with probability p_d, else sample_highlight(b, r1, r2); then
                  weighted_sample

The functions below are the scalar module's helpers on arrays. Per hit whose viewer
lies above the surface, scattering() draws three uniform numbers, as the scalar one
does: the lobe's choice, then the two that make the direction.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials.glossy import INV_PI, MAX_PDF
from ..arrays import max3, select
from ..hit_info import HitBatch
from ..onb import ONB
from ..sampling import cosine_direction
from ..scatter_info import ScatterBatch
from ..vec3 import Columns, dot, stack
from .material import AlbedoKernel, Bounce, param


def positive_power(c: np.ndarray, n: np.ndarray) -> np.ndarray:
    """c**n where c > 0, else 0 (the scalar models' `if cos <= 0.0: return 0.0`)."""
    up = c > 0.0
    return np.where(up, np.power(np.where(up, c, 1.0), n), 0.0)


def diffuse_probability(kernel: GlossyKernel, b: Bounce) -> np.ndarray:
    """glossy.diffuse_probability: p_d = kd max(albedo) / (kd max(albedo) + ks) per
    hit (1 where both lobes are black)."""
    diffuse = kernel.kd[b.slots] * max3(b.albedo)
    total = diffuse + kernel.ks[b.slots]
    positive = total > 0.0
    return np.where(positive, diffuse / np.where(positive, total, 1.0), 1.0)


def mixture_pdf(p_diffuse: np.ndarray, cos_i: np.ndarray, highlight_pdf: np.ndarray):
    """glossy.mixture_pdf: p_d cos(theta_i) / pi + (1 - p_d) highlight_pdf, at most
    MAX_PDF."""
    pdf = p_diffuse * cos_i * INV_PI
    mixed = p_diffuse < 1.0  # (highlight_pdf may be inf at a grazing half vector)
    with np.errstate(invalid="ignore"):  # 0 * inf where not mixed: not used
        pdf = np.where(mixed, pdf + (1.0 - p_diffuse) * highlight_pdf, pdf)
    return np.minimum(pdf, MAX_PDF, out=pdf)


def reflected_density(half_vector_density: np.ndarray, wo: Columns, h: Columns) -> np.ndarray:
    """glossy.reflected_density: the density of wi = reflect(-wo, h) when the unit half
    vector h is drawn with half_vector_density, that over 4 (wo . h); 0 where h faces
    away from wo."""
    wo_h = dot(wo, h)
    facing = wo_h > 0.0
    with np.errstate(over="ignore"):  # wo . h subnormal: inf, saturated by mixture_pdf
        density = half_vector_density / (4.0 * np.where(facing, wo_h, 1.0))
    return np.where(facing, density, 0.0)


def weighted_sample(kernel: GlossyKernel, b: Bounce, wi: Columns, n: int) -> ScatterBatch:
    """glossy.weighted_sample for the n hits of a batch, b those whose viewer lies
    above the surface and wi the directions drawn there: the weight
    BRDF * cos(theta_i) / pdf with the kernel's own BRDF and pdf; absorbed where wi
    lies below the surface or pdf gives it no density."""
    cos_i = dot(b.normal, wi)
    b = b.toward(wi, cos_i).take(select(cos_i > 0.0))  # else drawn below the surface
    pdf = kernel.pdf_above(b)
    live = select(pdf > 0.0)
    b, pdf = b.take(live), pdf[live]
    weight = kernel.BRDF_above(b) * (b.cos_i / pdf)[:, None]
    return ScatterBatch.alive_at(n, b.rows, stack(*b.wi), weight, pdf)


class GlossyKernel(AlbedoKernel):
    """Batched diffuse + highlight models; a subclass gives the highlight."""

    has_brdf = True
    scatters = True

    def __init__(self, materials: Sequence) -> None:
        super().__init__(materials)
        self.kd = param(self.materials, "kd")
        self.ks = param(self.materials, "ks")

    # --- the model's own lines ------------------------------------------------------
    def highlight(self, b: Bounce) -> np.ndarray:
        """The term BRDF() adds to kd * albedo / pi: (n,) for a white highlight, or
        (n, 3)."""
        raise NotImplementedError

    def highlight_pdf(self, b: Bounce) -> np.ndarray:
        """The density with which the highlight lobe of scattering() draws b.wi."""
        raise NotImplementedError

    def sample_highlight(self, b: Bounce, r1: np.ndarray, r2: np.ndarray) -> Columns:
        """Directions wi drawn from the highlight lobe, from two uniform numbers each."""
        raise NotImplementedError

    # --- BRDF, pdf and scattering: the shape the scalar models share ----------------
    def BRDF_above(self, b: Bounce) -> np.ndarray:
        """BRDF() where wo and wi both lie above the surface: kd * albedo / pi plus the
        highlight."""
        f = b.albedo * (self.kd[b.slots] * INV_PI)[:, None]
        highlight = self.highlight(b)
        return f + (highlight if highlight.ndim == 2 else highlight[:, None])

    def pdf_above(self, b: Bounce) -> np.ndarray:
        """pdf() where wo and wi both lie above the surface: the mixture's density."""
        return mixture_pdf(diffuse_probability(self, b), b.cos_i, self.highlight_pdf(b))

    def BRDF(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        b = self.above(slots, hits, wi)
        return b.spread(self.BRDF_above(b), len(slots))

    def pdf(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        b = self.above(slots, hits, wi)
        return b.spread(self.pdf_above(b), len(slots))

    def BRDF_and_pdf(self, slots, hits, wi):
        b = self.above(slots, hits, wi)
        return b.spread(self.BRDF_above(b), len(slots)), b.spread(self.pdf_above(b), len(slots))

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        """The diffuse lobe with probability p_d, else the highlight's; weight
        BRDF * cos / pdf. Hits whose viewer lies below the surface are absorbed (their
        pdf() is 0) and draw no numbers."""
        b = self.above(slots, hits)
        r = rng.random((3, len(b)))
        wi = ONB(b.normal).to_world(cosine_direction(r[1], r[2]))
        lobe = np.flatnonzero(~(r[0] < diffuse_probability(self, b)))
        if len(lobe):
            wi_h = self.sample_highlight(b.take(lobe), r[1, lobe], r[2, lobe])
            for c in range(3):
                wi[c][lobe] = wi_h[c]
        return weighted_sample(self, b, wi, len(slots))
