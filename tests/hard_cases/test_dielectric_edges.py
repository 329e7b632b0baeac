"""Hard cases for glass: Schlick's reflectance at grazing incidence and refraction at
and beyond the critical angle.

Each test computes the naive formula on the same input, shows that it is wrong, and
checks rtpy's Dielectric (scalar specular_rays) and the numpy DielectricKernel
(MaterialTable.specular_rays) on it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.hit_info import HitInfo
from rtpy.materials import Dielectric
from rtpy.numpy_backend.hit_info import HitBatch
from rtpy.numpy_backend.materials import MaterialTable
from rtpy.ray import Ray
from rtpy.vec3 import Color, Vec3

BACKENDS = ["scalar", "numpy"]
WHITE = Color(1.0, 1.0, 1.0)
NORMAL = np.array([0.0, 0.0, 1.0])


def glass_split(backend, ior, d: np.ndarray, front_face: bool):
    """(R (N,), refracted directions (N, 3), refracts (N,) bool) of white glass for
    arriving unit directions d at a surface with normal +z (facing the ray)."""
    glass = Dielectric(ior, WHITE)
    n = len(d)
    if backend == "scalar":
        r, out, ok = np.zeros(n), np.zeros((n, 3)), np.zeros(n, bool)
        for i, di in enumerate(d):
            hit = HitInfo(Vec3(0.0, 0.0, 0.0), Vec3(*NORMAL), 1.0, front_face, glass)
            rays = glass.specular_rays(Ray(Vec3(0.0, 0.0, 1.0), Vec3(*di)), hit)
            r[i] = rays[0][1].e0  # weight of the reflected ray: albedo * R, albedo 1
            if len(rays) == 2:
                t = rays[1][0].direction
                out[i], ok[i] = (t.e0, t.e1, t.e2), True
        return r, out, ok
    hits = HitBatch(
        np.zeros((n, 3)),
        np.tile(NORMAL, (n, 1)),
        -d,
        np.ones(n),
        np.full(n, front_face),
        np.full(n, 0.5),
        np.full(n, 0.5),
        np.tile([1.0, 0.0, 0.0], (n, 1)),
    )
    (_, weight, _), (refracted, _, refracts) = MaterialTable([glass]).specular_rays(
        np.zeros(n, dtype=np.intp), hits
    )
    return weight[:, 0], refracted, refracts


def naive_schlick(cosine, ior_ratio):
    r0 = ((1.0 - ior_ratio) / (1.0 + ior_ratio)) ** 2
    return r0 + (1.0 - r0) * (1.0 - cosine) ** 5


def naive_refract(d, n, ratio):
    """RTIOW's refract: r_perp = ratio (d + cos n), r_par = -sqrt(1 - |r_perp|^2) n."""
    cos = min(-(d @ n), 1.0)
    perp = ratio * (d + cos * n)
    with np.errstate(invalid="ignore"):
        return perp - np.sqrt(np.float64(1.0 - perp @ perp)) * n


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("front_face", [True, False])
def test_schlick_at_grazing_incidence_stays_in_0_1(backend, front_face):
    """At grazing incidence the cosine -d . n is 0 up to rounding, and rounding can
    make it slightly negative (a direction rounded to just behind the surface, or a
    shading normal). Naive Schlick, r0 + (1 - r0) (1 - cos)^5, then exceeds 1: for
    cos = -1e-10 it is 1 + 4.8e-10 (ior 1.5), a reflected ray carrying more than the
    light that arrived. rtpy clamps the cosine at 0: R is in [0, 1], exactly 1 there."""
    cosines = [-1e-6, -1e-10, -1e-15, -0.0, 0.0, 1e-300, 1e-15, 1e-10]
    d = np.array([[math.sqrt(1.0 - c * c), 0.0, -c] for c in cosines])
    ior = 1.5
    ratio = 1.0 / ior if front_face else ior
    naive = [naive_schlick(-(di @ NORMAL), ratio) for di in d]
    assert max(naive) > 1.0  # the naive formula reflects more than comes in

    r, _, _ = glass_split(backend, ior, d, front_face)
    assert ((r >= 0.0) & (r <= 1.0)).all(), r
    # at cos <= 0 (and at 1e-300, where (1 - cos)^5 rounds to 1) R is exactly 1
    np.testing.assert_array_equal(r[:6], np.ones(6))


def near_critical(ratio, n, seed, spread):
    """n unit directions arriving at sin(theta) = (1 + x) / ratio, x uniform in
    [-spread, spread] (a few ulps of 1), at random azimuths."""
    rng = np.random.default_rng(seed)
    s = (1.0 + rng.uniform(-spread, spread, n)) / ratio
    s = np.minimum(s, 1.0)
    phi = rng.uniform(0.0, 2.0 * math.pi, n)
    d = np.column_stack([s * np.cos(phi), s * np.sin(phi), -np.sqrt(1.0 - s * s)])
    return d / np.linalg.norm(d, axis=1, keepdims=True)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("ior", [1.33, 1.5, 2.4])
def test_refraction_at_the_critical_angle_is_never_nan(backend, ior):
    """Leaving glass (ratio = ior) within a few ulps of the critical angle: the test
    for total internal reflection, ratio sin(theta) > 1, says 'refracts', yet
    |r_perp|^2 = ratio^2 (1 - cos^2) computed another way rounds to 1 + 2e-16 or so,
    and the naive sqrt(1 - |r_perp|^2) is sqrt of a negative number: NaN (for 29 to
    161 of the 800 to 1300 of these 2000 rays that refract). rtpy takes
    sqrt(|1 - |r_perp|^2|): a finite unit direction that grazes the surface on the
    far side.

    Tolerance on |direction| = 1: 1e-12, far above the few ulps of rounding and far
    below any real error (a NaN, or a zero or doubled vector)."""
    d = near_critical(ior, 2000, seed=11, spread=4e-16)
    r, out, ok = glass_split(backend, ior, d, front_face=False)
    naive = [naive_refract(d[i], NORMAL, ior) for i in range(len(d)) if ok[i]]
    assert sum(np.isnan(v).any() for v in naive) >= 10  # the naive formula gives NaN

    assert ok.sum() >= 500  # many of these rays do refract
    assert np.isfinite(out).all() and np.isfinite(r).all()
    length = np.linalg.norm(out[ok], axis=1)
    np.testing.assert_allclose(length, 1.0, rtol=0.0, atol=1e-12)
    assert (out[ok, 2] <= 0.0).all()  # through the surface, not back into the glass
    assert ((r >= 0.0) & (r <= 1.0)).all()


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("ior", [1.33, 1.5, 2.4])
def test_total_internal_reflection_beyond_the_critical_angle(backend, ior):
    """Beyond the critical angle (and exactly at grazing, sin = 1) no light is
    transmitted: naive refraction without the total-internal-reflection test takes
    sqrt(1 - ratio^2 sin^2) of a negative number and returns NaN for every one of
    these rays. rtpy reflects everything: R = 1, no refracted ray."""
    rng = np.random.default_rng(12)
    s = np.concatenate([1.0 / ior + rng.uniform(1e-12, 1.0 - 1.0 / ior, 200), [1.0]])
    phi = rng.uniform(0.0, 2.0 * math.pi, len(s))
    d = np.column_stack([s * np.cos(phi), s * np.sin(phi), -np.sqrt(1.0 - s * s)])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    sin = np.hypot(d[:, 0], d[:, 1])
    beyond = ior * sin > 1.0
    assert beyond.sum() >= 195  # normalising can only move a few onto the critical angle
    d = d[beyond]
    assert all(np.isnan(naive_refract(di, NORMAL, ior)).any() for di in d)

    r, out, ok = glass_split(backend, ior, d, front_face=False)
    assert not ok.any()
    np.testing.assert_array_equal(r, np.ones(len(d)))
    assert np.isfinite(out).all()
