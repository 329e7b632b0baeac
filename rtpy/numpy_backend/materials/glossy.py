"""GlossyKernel: the batched rtpy.materials.glossy.GlossyMaterial.

The shading frame from the normal and tangent, the diffuse/specular mixture with
diffuse probability kd max(albedo) / (kd max(albedo) + ks), absorption of samples
below the surface, and weight f_r cos / pdf. A subclass (phong.py, blinn_phong.py,
cook_torrance.py, ward.py) gives the specular lobe as the scalar subclass does
(specular, sample_specular, specular_pdf), on local directions: Columns (x, y, z)
of (n,) arrays, z along the normal. Lobes are evaluated only where both directions
lie above the surface (the callers check, as the scalar GlossyMaterial does).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials.glossy import MAX_PDF
from ..arrays import compose, select
from ..hit_info import HitBatch
from ..onb import ONB
from ..sampling import cosine_direction
from ..scatter_info import ScatterBatch
from ..vec3 import Columns, stack, take
from .material import INV_PI, AlbedoKernel, param

Local = Columns  # directions in the shading frame, one per hit


def positive_power(c: np.ndarray, n: np.ndarray) -> np.ndarray:
    """c**n where c > 0, else 0."""
    up = c > 0.0
    return np.where(up, np.power(np.where(up, c, 1.0), n), 0.0)


def safe(x: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """x where ok, else 1: a denominator or argument that is harmless where the result
    is replaced anyway."""
    return np.where(ok, x, 1.0)


def reflect_about(wo: Local, h: Local) -> tuple[Local, np.ndarray]:
    """wi = 2 (wo . h) h - wo, and where it exists (wo . h > 0)."""
    wo_h = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2]
    k = 2.0 * wo_h
    return (k * h[0] - wo[0], k * h[1] - wo[1], k * h[2] - wo[2]), wo_h > 0.0


def half_vector(wo: Local, wi: Local) -> tuple[Local, np.ndarray]:
    """normalize(wo + wi) and where it exists (wi != -wo)."""
    x, y, z = wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]
    length = np.sqrt(x * x + y * y + z * z)
    ok = length != 0.0
    length = safe(length, ok)
    return (x / length, y / length, z / length), ok


class GlossyKernel(AlbedoKernel):
    """Batched GlossyMaterial; subclasses give the lobe."""

    has_brdf = True
    scatters = True
    reads_tangent = True

    def __init__(self, materials: Sequence) -> None:
        super().__init__(materials)
        self.kd = param(self.materials, "kd")
        self.ks = param(self.materials, "ks")

    # --- the specular lobe (subclasses) ---------------------------------------------
    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        """The lobe's f_r without ks: (n,) for a white lobe or (n, 3)."""
        raise NotImplementedError

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        """Directions wi drawn with density specular_pdf, and where there is one
        (False where the scalar sample_specular returns None)."""
        raise NotImplementedError

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        raise NotImplementedError

    # --- shared machinery -----------------------------------------------------------
    def diffuse_probability(self, slots: np.ndarray, albedo: np.ndarray) -> np.ndarray:
        diffuse = self.kd[slots] * albedo.max(axis=1)
        total = diffuse + self.ks[slots]
        return np.where(total > 0.0, diffuse / safe(total, total > 0.0), 1.0)

    def _f(self, slots: np.ndarray, albedo: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        f = albedo * (self.kd[slots] * INV_PI)[:, None]
        ks = self.ks[slots]
        glossy = select(ks > 0.0)
        s = self.specular(slots[glossy], take(wo, glossy), take(wi, glossy))
        s = s if s.ndim == 2 else s[:, None]
        f[glossy] = f[glossy] + s * ks[glossy, None]
        return f

    def _pdf(self, slots: np.ndarray, p_diffuse: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        pdf = p_diffuse * wi[2] * INV_PI
        mixed = select(p_diffuse < 1.0)
        with np.errstate(over="ignore"):  # saturated below, as the scalar _pdf
            p_specular = self.specular_pdf(slots[mixed], take(wo, mixed), take(wi, mixed))
        pdf[mixed] = pdf[mixed] + (1.0 - p_diffuse[mixed]) * p_specular
        return np.minimum(pdf, MAX_PDF, out=pdf)

    def _evaluate(self, slots, hits: HitBatch, wi: np.ndarray, want_f: bool, want_pdf: bool):
        """(f_r or None, pdf or None): BRDF() and pdf() in the shading frame, non-zero
        only where both directions lie above the surface (reflection only)."""
        frame = ONB.from_normal_tangent(hits.normal, hits.tangent)
        wo_l, wi_l = frame.to_local(hits.wo), frame.to_local(wi)
        up = select((wo_l[2] > 0.0) & (wi_l[2] > 0.0))
        s, wo_l, wi_l = slots[up], take(wo_l, up), take(wi_l, up)
        albedo = self.albedo(s, hits, up)
        f = pdf = None
        if want_f:
            f = np.zeros((len(slots), 3))
            f[up] = self._f(s, albedo, wo_l, wi_l)
        if want_pdf:
            pdf = np.zeros(len(slots))
            pdf[up] = self._pdf(s, self.diffuse_probability(s, albedo), wo_l, wi_l)
        return f, pdf

    def BRDF(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        return self._evaluate(slots, hits, wi, True, False)[0]

    def pdf(self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        return self._evaluate(slots, hits, wi, False, True)[1]

    def BRDF_and_pdf(self, slots, hits, wi):
        return self._evaluate(slots, hits, wi, True, True)

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        n = len(slots)
        frame = ONB.from_normal_tangent(hits.normal, hits.tangent)
        wo = frame.to_local(hits.wo)
        rows = select(wo[2] > 0.0)  # the viewer below the surface: absorbed
        slots, wo = slots[rows], take(wo, rows)
        albedo = self.albedo(slots, hits, rows)
        p_diffuse = self.diffuse_probability(slots, albedo)

        r = rng.random((3, len(slots)))
        wi = cosine_direction(r[1], r[2])
        found = np.ones(len(slots), dtype=bool)
        lobe = np.flatnonzero(~(r[0] < p_diffuse))  # the specular lobe's samples
        if len(lobe):
            r1, r2 = r[1, lobe], r[2, lobe]
            wi_s, found_s = self.sample_specular(slots[lobe], take(wo, lobe), r1, r2)
            for c in range(3):
                wi[c][lobe] = wi_s[c]
            found[lobe] = found_s

        keep = select(found & (wi[2] > 0.0))  # below the surface: absorbed
        slots, wo, wi = slots[keep], take(wo, keep), take(wi, keep)
        pdf = self._pdf(slots, p_diffuse[keep], wo, wi)
        live = select(pdf > 0.0)
        slots, wo, wi, pdf = slots[live], take(wo, live), take(wi, live), pdf[live]
        keep = compose(keep, live)

        weight = self._f(slots, albedo[keep], wo, wi) * (wi[2] / pdf)[:, None]
        rows = compose(rows, keep)
        direction = stack(*frame.take(rows).to_world(*wi))
        return ScatterBatch.alive_at(n, rows, direction, weight, pdf)
