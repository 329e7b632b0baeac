"""Hard cases for microfacet (Cook-Torrance, GGX and Beckmann) and Ward highlights at
grazing angles, with very narrow lobes (roughness 0.001).

The textbook formulas divide by the cosines of the two directions (and by the cosine
of the half vector inside tan^2 = sin^2 / cos^2). At cosines of 1e-160 or 1e-300 the
products underflow to 0 and the textbook BRDF is 0 / 0 = NaN or x / 0 = inf; at a
cosine of exactly 0 (a direction in the tangent plane) tan is infinite. rtpy's
formulas are rearranged so that no cosine is divided by (see rtpy/materials/
cook_torrance.py and ward.py): its BRDF and pdf must be finite and >= 0 for every pair
of directions, on the scalar material (BRDF, pdf) and the numpy MaterialTable (BRDF, pdf).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.materials import CookTorrance, Ward
from rtpy.numpy_backend.hit_info import HitBatch
from rtpy.numpy_backend.materials import MaterialTable
from rtpy.ray import Ray
from rtpy.vec3 import Vec3

MATERIALS = {
    "ggx": lambda: CookTorrance(kd=0.0, ks=1.0, roughness=0.001, distribution="ggx"),
    "beckmann": lambda: CookTorrance(kd=0.0, ks=1.0, roughness=0.001, distribution="beckmann"),
    "ward": lambda: Ward(kd=0.0, ks=1.0, alpha_x=0.001),
    "ward anisotropic": lambda: Ward(kd=0.0, ks=1.0, alpha_x=0.001, alpha_y=0.5),
}
BACKENDS = ["scalar", "numpy"]
COSINES = [0.0, 5e-324, 1e-300, 1e-160, 1e-10, 0.5]
AZIMUTHS = [0.0, 2.0, math.pi / 2, math.pi * (1.0 - 1e-9), math.pi]


def grazing_pairs(wo_cosines=COSINES):
    """(wo, wi) in the local frame (normal z, tangent x): wo at azimuth 0, wi at the
    azimuths above (same side, across, mirror and next to it), every pair of cosines
    with at least one below 1e-10."""
    wo, wi = [], []
    for co in wo_cosines:
        for ci in COSINES:
            if min(co, ci) >= 1e-10:
                continue
            for phi in AZIMUTHS:
                wo.append([math.sqrt(1.0 - co * co), 0.0, co])
                s = math.sqrt(1.0 - ci * ci)
                wi.append([s * math.cos(phi), s * math.sin(phi), ci])
    return np.array(wo), np.array(wi)


def rtpy_eval(backend, material, wo: np.ndarray, wi: np.ndarray):
    """(f (N, 3), pdf (N,)) of the material for local directions wo, wi."""
    n = len(wo)
    hits = HitBatch(
        np.zeros((n, 3)),
        np.tile([0.0, 0.0, 1.0], (n, 1)),
        wo,
        np.ones(n),
        np.ones(n, bool),
        np.full(n, 0.5),
        np.full(n, 0.5),
        np.tile([1.0, 0.0, 0.0], (n, 1)),
    )
    if backend == "numpy":
        with np.errstate(all="ignore"):
            table, ids = MaterialTable([material]), np.zeros(n, dtype=np.intp)
            return table.BRDF(ids, hits, wi), table.pdf(ids, hits, wi)
    f, pdf = np.zeros((n, 3)), np.zeros(n)
    for i in range(n):
        hit = hits.hit_info(i, material)
        o = Vec3(*(float(x) for x in wo[i]))  # Python floats: the scalar code path
        ray_view = Ray(o, -o)
        ray_light = Ray(Vec3(0.0, 0.0, 0.0), Vec3(*(float(x) for x in wi[i])))
        f[i] = tuple(material.BRDF(ray_view, ray_light, hit))
        pdf[i] = material.pdf(ray_view, ray_light, hit)
    return f, pdf


# --- the textbook formulas, in IEEE arithmetic (numpy: x / 0 is inf, 0 / 0 is NaN) ----


def _erf(x):
    return np.vectorize(math.erf)(x)


def naive_cook_torrance(material, wo, wi):
    """f = D G F / (4 cos_i cos_o) and pdf = D(h) cos_h / (4 wo . h), with
    tan^2 = (1 - cos^2) / cos^2, Smith G1 as Walter 2007 writes it."""
    alpha = material.alpha
    cos_o, cos_i = wo[:, 2], wi[:, 2]
    h = wo + wi
    h = h / np.linalg.norm(h, axis=1, keepdims=True)
    cos_h = h[:, 2]

    def tan2(c):
        return (1.0 - c * c) / (c * c)

    if material.distribution == "ggx":
        d = alpha**2 / (math.pi * cos_h**4 * (alpha**2 + tan2(cos_h)) ** 2)

        def g1(c):
            return 2.0 / (1.0 + np.sqrt(1.0 + alpha**2 * tan2(c)))
    else:
        d = np.exp(-tan2(cos_h) / alpha**2) / (math.pi * alpha**2 * cos_h**4)

        def g1(c):
            a = 1.0 / (alpha * np.sqrt(tan2(c)))
            lam = (_erf(a) - 1.0) / 2.0 + np.exp(-a * a) / (2.0 * a * math.sqrt(math.pi))
            return 1.0 / (1.0 + lam)

    f0 = material.f0.e0
    fresnel = f0 + (1.0 - f0) * (1.0 - np.sum(wo * h, axis=1)) ** 5
    f = d * g1(cos_i) * g1(cos_o) * fresnel / (4.0 * cos_i * cos_o)
    pdf = d * cos_h / (4.0 * np.sum(wo * h, axis=1))
    return f, pdf


def naive_ward(material, wo, wi):
    """Ward 1992 as printed: exp(-tan^2(theta_h) (cos^2 phi_h / ax^2 + sin^2 phi_h / ay^2))
    / (4 pi ax ay sqrt(cos_i cos_o)), and Walter's pdf p_h / (4 wo . h)."""
    ax, ay = material.ax, material.ay
    h = wo + wi
    h = h / np.linalg.norm(h, axis=1, keepdims=True)
    cos_h = h[:, 2]
    tan2 = (1.0 - cos_h * cos_h) / (cos_h * cos_h)
    phi = np.arctan2(h[:, 1], h[:, 0])
    e = tan2 * (np.cos(phi) ** 2 / ax**2 + np.sin(phi) ** 2 / ay**2)
    f = np.exp(-e) / (4.0 * math.pi * ax * ay * np.sqrt(wi[:, 2] * wo[:, 2]))
    p_h = np.exp(-e) / (math.pi * ax * ay * cos_h**3)
    pdf = p_h / (4.0 * np.sum(wo * h, axis=1))
    return f, pdf


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", list(MATERIALS))
def test_narrow_lobes_at_grazing_angles_are_finite(name, backend):
    """Of these 130 pairs the naive f is NaN or inf for 85 and the naive pdf for 62
    (every model); rtpy's f and pdf are finite and >= 0 for all of them.

    No tolerance: finiteness and sign are exact properties."""
    material = MATERIALS[name]()
    wo, wi = grazing_pairs([c for c in COSINES if c != 5e-324])  # see the next test
    naive = naive_ward if isinstance(material, Ward) else naive_cook_torrance
    with np.errstate(all="ignore"):
        nf, npdf = naive(material, wo, wi)
    broken = ~np.isfinite(nf) | ~np.isfinite(npdf)
    assert broken.sum() >= 10, "the naive formula should give NaN or inf here"

    f, pdf = rtpy_eval(backend, material, wo, wi)
    ok = np.isfinite(f).all(axis=1) & (f >= 0.0).all(axis=1) & np.isfinite(pdf) & (pdf >= 0.0)
    bad = np.flatnonzero(~ok)
    assert bad.size == 0, [(wo[i].tolist(), wi[i].tolist(), f[i].tolist(), pdf[i]) for i in bad[:3]]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", list(MATERIALS))
def test_pdf_is_finite_when_the_viewer_grazes_at_a_subnormal_cosine(name, backend):
    """wo with cos = 5e-324, wi its mirror image at cos 1e-10: the half vector is the
    normal and wo . h = 5e-324. The naive pdf D(h) cos_h / (4 wo . h) is inf here (it
    overflows: the true value, about 1e329, is beyond float64). rtpy's densities
    saturate at MAX_PDF = 1e150 (rtpy/materials/glossy.py), so the pdf and the MIS
    weights built from its square stay finite."""
    material = MATERIALS[name]()
    wo = np.array([[1.0, 0.0, 5e-324]])
    wi = np.array([[-1.0, 1.2246467991473532e-16, 1e-10]])
    naive = naive_ward if isinstance(material, Ward) else naive_cook_torrance
    with np.errstate(all="ignore"):
        _, npdf = naive(material, wo, wi)
    assert np.isinf(npdf).all()  # the naive pdf overflows

    f, pdf = rtpy_eval(backend, material, wo, wi)
    assert np.isfinite(f).all() and (f >= 0.0).all()
    assert np.isfinite(pdf).all() and (pdf >= 0.0).all(), pdf
