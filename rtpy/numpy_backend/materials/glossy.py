"""Kernels of the GlossyMaterial family: Phong, Blinn-Phong, Cook-Torrance, Ward.

GlossyKernel is the batched rtpy.materials.glossy.GlossyMaterial: the shading frame
from the normal and tangent, the diffuse/specular mixture with diffuse probability
kd max(albedo) / (kd max(albedo) + ks), absorption of samples below the surface, and
weight f_r cos / pdf. A subclass gives the specular lobe as the scalar subclass does
(specular, sample_specular, specular_pdf), on local directions: tuples (x, y, z) of
(n,) arrays, z along the normal. Lobes are evaluated only where both directions lie
above the surface (the callers check, as the scalar GlossyMaterial does).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...materials import BlinnPhong, CookTorrance, Phong, Ward
from ...materials.blinn_phong import INV_EIGHT_PI
from ...materials.cook_torrance import INV_SQRT_PI
from ...materials.glossy import MAX_PDF
from ...materials.phong import INV_TWO_PI
from ...materials.ward import MAX_EXPONENT, MIN_COS_PRODUCT
from ..hits import HitBatch
from ..trig import cos_sin_2pi
from .frame import (
    Frame,
    Local,
    compose,
    cosine_direction,
    dot,
    local_to_world,
    select,
    take,
)
from .kernel import AlbedoKernel, ScatterBatch, color_param, param

INV_PI = 1.0 / math.pi


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

    evaluates = True
    scatters = True

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

    def eval(
        self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        frame = Frame.from_normal_tangent(hits.normal, hits.tangent)
        wo_l, wi_l = frame.to_local(hits.wo), frame.to_local(wi)
        f, pdf = np.zeros((len(slots), 3)), np.zeros(len(slots))
        up = select((wo_l[2] > 0.0) & (wi_l[2] > 0.0))  # reflection only
        s, wo_l, wi_l = slots[up], take(wo_l, up), take(wi_l, up)
        albedo = self.albedo(s, hits, up)
        f[up] = self._f(s, albedo, wo_l, wi_l)
        pdf[up] = self._pdf(s, self.diffuse_probability(s, albedo), wo_l, wi_l)
        return f, pdf

    def sample(self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        out = ScatterBatch.absorbed(len(slots))
        frame = Frame.from_normal_tangent(hits.normal, hits.tangent)
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
        out.direction[rows] = frame.take(rows).to_world(*wi)
        out.weight[rows] = weight
        out.pdf[rows] = pdf
        out.alive[rows] = True
        return out


# --- Phong and Blinn-Phong -------------------------------------------------------------


def sample_cosine_power(n: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> Local:
    """rtpy.materials.phong.sample_cosine_power: density (n + 1) / (2 pi) cos^n about z."""
    cos_theta = r1 ** (1.0 / (n + 1.0))
    sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
    cos_phi, sin_phi = cos_sin_2pi(r2)
    return sin_theta * cos_phi, sin_theta * sin_phi, cos_theta


def cosine_power_pdf(n: np.ndarray, cos_theta: np.ndarray) -> np.ndarray:
    return (n + 1.0) * INV_TWO_PI * positive_power(cos_theta, n)


class PhongKernel(GlossyKernel):
    """ks (n + 2) / (2 pi) max(0, r . wo)^n, sampled around the mirror direction of wo."""

    def __init__(self, materials: Sequence[Phong]) -> None:
        super().__init__(materials)
        self.exponent = param(self.materials, "exponent")

    @staticmethod
    def cos_to_mirror(wo: Local, wi: Local) -> np.ndarray:
        # r . wo = m . wi with m = (-wo.x, -wo.y, wo.z), the mirror of wo
        return wi[2] * wo[2] - wi[0] * wo[0] - wi[1] * wo[1]

    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        n = self.exponent[slots]
        return (n + 2.0) * INV_TWO_PI * positive_power(self.cos_to_mirror(wo, wi), n)

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        x, y, z = sample_cosine_power(self.exponent[slots], r1, r2)
        wi = local_to_world((-wo[0], -wo[1], wo[2]), x, y, z)
        return wi, np.ones(len(slots), dtype=bool)

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        return cosine_power_pdf(self.exponent[slots], self.cos_to_mirror(wo, wi))


class BlinnPhongKernel(PhongKernel):
    """ks (n + 8) / (8 pi) max(0, n . h)^n, sampled by drawing h with density
    (n + 1) / (2 pi) cos^n and reflecting wo about it."""

    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        hx, hy, hz = wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]
        length = np.sqrt(hx * hx + hy * hy + hz * hz)
        n = self.exponent[slots]
        return (n + 8.0) * INV_EIGHT_PI * positive_power(hz / length, n)

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        h = sample_cosine_power(self.exponent[slots], r1, r2)
        return reflect_about(wo, h)

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        hx, hy, hz = wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]
        length = np.sqrt(hx * hx + hy * hy + hz * hz)
        ok = length != 0.0
        length = safe(length, ok)
        wo_h = (wo[0] * hx + wo[1] * hy + wo[2] * hz) / length
        ok &= wo_h > 0.0
        pdf = cosine_power_pdf(self.exponent[slots], hz / length) / (4.0 * safe(wo_h, ok))
        return np.where(ok, pdf, 0.0)


# --- Cook-Torrance -----------------------------------------------------------------------


def schlick_fresnel(f0: np.ndarray, cosine: np.ndarray) -> np.ndarray:
    """rtpy.materials.cook_torrance.schlick_fresnel for colours f0 (n, 3)."""
    c = np.minimum(1.0, np.maximum(0.0, cosine))
    m = ((1.0 - c) ** 5)[:, None]
    return f0 + (1.0 - f0) * m


def erfc(x: np.ndarray) -> np.ndarray:
    """math.erfc elementwise: numpy has no erfc, and the scalar twin's own function
    keeps the two backends identical (the callers use it only where it matters)."""
    return np.array([math.erfc(v) for v in x.tolist()], dtype=np.float64)


# G1 of Beckmann is exactly 1.0 for a = 1 / (alpha tan(theta)) >= 6: Lambda(a) is then
# below exp(-36) / (2 * 6 sqrt(pi)) < 2e-17, and 1 + Lambda rounds to 1.
BECKMANN_G1_ONE = 6.0


class CookTorranceKernel(GlossyKernel):
    """ks D(h) G(wi, wo) F(wo . h) / (4 (n . wi) (n . wo)); half vectors drawn from
    D(h) cos(theta_h). D, G1 and the half-vector sampling are the distribution's."""

    def __init__(self, materials: Sequence[CookTorrance]) -> None:
        super().__init__(materials)
        self.alpha = param(self.materials, "alpha")
        self.f0 = color_param(self.materials, "f0")

    def D(self, alpha: np.ndarray, h: Local) -> np.ndarray:
        raise NotImplementedError

    def G1(self, alpha: np.ndarray, v: Local) -> np.ndarray:
        raise NotImplementedError

    def tan2_half_vector(self, alpha: np.ndarray, r1: np.ndarray) -> np.ndarray:
        """tan^2(theta_h) of a half vector drawn from D cos, by the inverted CDF."""
        raise NotImplementedError

    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        alpha = self.alpha[slots]
        cos_o, cos_i = wo[2], wi[2]
        h, ok = half_vector(wo, wi)
        wo_h = dot(wo, h)
        # G1 / cos per direction, as the scalar code: finite at grazing angles
        visibility = (self.G1(alpha, wi) / cos_i) * (self.G1(alpha, wo) / cos_o) * 0.25
        value = schlick_fresnel(self.f0[slots], wo_h) * (self.D(alpha, h) * visibility)[:, None]
        return np.where(ok[:, None], value, 0.0)

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        tan2 = self.tan2_half_vector(self.alpha[slots], r1)
        cos = 1.0 / np.sqrt(1.0 + tan2)
        sin = np.sqrt(tan2) * cos
        cos_phi, sin_phi = cos_sin_2pi(r2)
        return reflect_about(wo, (sin * cos_phi, sin * sin_phi, cos))

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        h, ok = half_vector(wo, wi)
        wo_h = dot(wo, h)
        ok &= wo_h > 0.0
        pdf = self.D(self.alpha[slots], h) * h[2] / (4.0 * safe(wo_h, ok))
        return np.where(ok, pdf, 0.0)


class GGXKernel(CookTorranceKernel):
    def D(self, alpha: np.ndarray, h: Local) -> np.ndarray:
        cos2 = h[2] * h[2]
        ok = (h[2] > 0.0) & (cos2 != 0.0)
        sin2 = h[0] * h[0] + h[1] * h[1]
        a2 = alpha * alpha
        k = safe(a2 * cos2 + sin2, ok)
        return np.where(ok, a2 / (math.pi * k * k), 0.0)

    def G1(self, alpha: np.ndarray, v: Local) -> np.ndarray:
        cos = v[2]
        up = cos > 0.0
        sin2 = v[0] * v[0] + v[1] * v[1]
        c = safe(cos, up)
        g = 2.0 * c / (c + np.sqrt(c * c + alpha * alpha * sin2))
        return np.where(up, np.where(sin2 == 0.0, 1.0, g), 0.0)

    def tan2_half_vector(self, alpha: np.ndarray, r1: np.ndarray) -> np.ndarray:
        return alpha * alpha * r1 / (1.0 - r1)


class BeckmannKernel(CookTorranceKernel):
    def D(self, alpha: np.ndarray, h: Local) -> np.ndarray:
        cos2 = h[2] * h[2]
        ok = (h[2] > 0.0) & (cos2 != 0.0)
        sin2 = h[0] * h[0] + h[1] * h[1]
        a2 = alpha * alpha
        cos2 = safe(cos2, ok)
        exponent = sin2 / (a2 * cos2)  # tan^2 / alpha^2
        ok &= ~(exponent > 700.0)
        d = np.exp(-np.where(ok, exponent, 0.0)) / (math.pi * a2 * cos2 * cos2)
        return np.where(ok, d, 0.0)

    def G1(self, alpha: np.ndarray, v: Local) -> np.ndarray:
        cos = v[2]
        sin2 = v[0] * v[0] + v[1] * v[1]
        g = np.where(cos > 0.0, 1.0, 0.0)  # 1 also where sin2 = 0 and where a >= 6
        slanted = np.flatnonzero((cos > 0.0) & (sin2 != 0.0))
        a = cos[slanted] / (alpha[slanted] * np.sqrt(sin2[slanted]))  # 1 / (alpha tan)
        g[slanted[a == 0.0]] = 0.0
        near = (a != 0.0) & (a < BECKMANN_G1_ONE)
        a = a[near]
        lam = 0.5 * (INV_SQRT_PI * np.exp(-a * a) / a - erfc(a))
        g[slanted[near]] = 1.0 / (1.0 + np.maximum(0.0, lam))
        return g

    def tan2_half_vector(self, alpha: np.ndarray, r1: np.ndarray) -> np.ndarray:
        return -(alpha * alpha) * np.log1p(-r1)


# --- Ward ------------------------------------------------------------------------------------


class WardKernel(GlossyKernel):
    """ks exp(-slope exponent) / (4 pi alpha_x alpha_y sqrt(cos_i cos_o)), anisotropic in
    the tangent frame; half vectors drawn from Walter 2005's density."""

    def __init__(self, materials: Sequence[Ward]) -> None:
        super().__init__(materials)
        self.ax = param(self.materials, "ax")
        self.ay = param(self.materials, "ay")

    @staticmethod
    def slope_exponent(ax: np.ndarray, ay: np.ndarray, h: Local) -> np.ndarray:
        """(hx^2 / ax^2 + hy^2 / ay^2) / hz^2 for any (unnormalised) h; infinite in the
        tangent plane."""
        sx, sy = h[0] / ax, h[1] / ay
        hz2 = h[2] * h[2]
        numerator = sx * sx + sy * sy
        flat = hz2 == 0.0
        e = numerator / safe(hz2, ~flat)
        return np.where(flat, np.where(numerator > 0.0, np.inf, 0.0), e)

    def specular(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        ax, ay = self.ax[slots], self.ay[slots]
        h = (wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2])  # the ratios are all that count
        exponent = self.slope_exponent(ax, ay, h)
        ok = ~(exponent > MAX_EXPONENT)
        cos_product = np.maximum(wi[2] * wo[2], MIN_COS_PRODUCT)
        value = np.exp(-np.where(ok, exponent, 0.0)) / (
            4.0 * math.pi * ax * ay * np.sqrt(cos_product)
        )
        return np.where(ok, value, 0.0)

    def half_vector_pdf(self, ax: np.ndarray, ay: np.ndarray, h: Local) -> np.ndarray:
        up = h[2] > 0.0
        exponent = self.slope_exponent(ax, ay, h)
        ok = up & ~(exponent > MAX_EXPONENT)
        p = np.exp(-np.where(ok, exponent, 0.0)) / (math.pi * ax * ay * safe(h[2], ok) ** 3)
        return np.where(ok, p, 0.0)

    def sample_specular(
        self, slots: np.ndarray, wo: Local, r1: np.ndarray, r2: np.ndarray
    ) -> tuple[Local, np.ndarray]:
        ax, ay = self.ax[slots], self.ay[slots]
        cos_angle, sin_angle = cos_sin_2pi(r2)
        phi = np.arctan2(ay * sin_angle, ax * cos_angle)
        cos_phi, sin_phi = np.cos(phi), np.sin(phi)
        a = cos_phi * cos_phi / (ax * ax) + sin_phi * sin_phi / (ay * ay)
        tan2 = -np.log1p(-r1) / a
        cos = 1.0 / np.sqrt(1.0 + tan2)
        sin = np.sqrt(tan2) * cos
        return reflect_about(wo, (sin * cos_phi, sin * sin_phi, cos))

    def specular_pdf(self, slots: np.ndarray, wo: Local, wi: Local) -> np.ndarray:
        h, ok = half_vector(wo, wi)
        wo_h = dot(wo, h)
        ok &= wo_h > 0.0
        pdf = self.half_vector_pdf(self.ax[slots], self.ay[slots], h) / (4.0 * safe(wo_h, ok))
        return np.where(ok, pdf, 0.0)


def cook_torrance_kernel(material: CookTorrance) -> type[CookTorranceKernel]:
    return GGXKernel if material.distribution == "ggx" else BeckmannKernel


GLOSSY_KERNELS = {
    Phong: PhongKernel,
    BlinnPhong: BlinnPhongKernel,
    CookTorrance: cook_torrance_kernel,
    Ward: WardKernel,
}
