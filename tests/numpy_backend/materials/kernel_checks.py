"""Shared checks of the batched material kernels against their scalar twins: random
hits and directions (grazing angles, the viewer below the surface, tangents along the
normal), the scalar methods hit by hit, random materials of every kind, and the
sampling comparisons. Used by the tests in this folder.
"""

from __future__ import annotations

import math
import random

import numpy as np
from hypothesis import strategies as st

from rtpy.materials import (
    BlinnPhong,
    CookTorrance,
    Dielectric,
    DiffuseLight,
    Lambertian,
    Metal,
    Mirror,
    OrenNayar,
    Phong,
    RoughDielectric,
    Ward,
)
from rtpy.numpy_backend.hit_info import HitBatch
from rtpy.numpy_backend.materials import (
    MaterialTable,
    glossy,
)
from rtpy.numpy_backend.materials.rough_dielectric import RoughDielectricKernel
from rtpy.numpy_backend.scatter_info import ScatterBatch
from rtpy.ray import Ray
from rtpy.sampling import use_generator
from rtpy.scatter_info import ScatterInfo
from rtpy.testing import SCATTERED, Samples, draw_samples, local_direction, normal_quantile
from rtpy.texture import CheckerTexture, ImageTexture
from rtpy.vec3 import Color, Vec3

# The kernels compute BRDF, pdf and a sample's weight with the scalar methods'
# operations in the scalar order, so the results are the scalar ones bit for bit except
# where pow, exp or log1p is called (Phong, Blinn-Phong, Cook-Torrance, Ward): numpy's
# SIMD versions of those (SVML on AVX-512 CPUs) and the C library's round differently,
# by up to 1 ulp here (numpy's own accuracy tests allow a few). A value passes through
# at most four such calls, combined by products, quotients and sums of positive terms,
# each of which keeps a relative difference: LIBM_REL (45 ulp) bounds the result. The
# other kernels must agree bit for bit.
ULP = 2.0**-52  # the spacing of floats in [1, 2)
LIBM_REL = 1e-14
LIBM_KINDS = {"phong", "blinn_phong", "cook_torrance", "ward", "rough_dielectric"}
# Except below TINY: an intermediate that underflows into the subnormal range keeps only
# the absolute spacing 2^-1074 = 4.9e-324 there (a 1 ulp difference of pow is then a
# large relative one), which the model's factors (at most ~1e4 for the materials drawn)
# scale up to far below TINY. Rendering-wise such values are 0.
TINY = 1e-300
REL = 1e-12  # assert_agrees's default
Z_MAX = normal_quantile(1e-4)  # two-sided z-tests; fixed seeds, so never flaky
CHI2_ALPHA = 1e-4

# --- random inputs ---------------------------------------------------------------------------


def unit(a: np.ndarray) -> np.ndarray:
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def perpendicular(rng: np.random.Generator, n: np.ndarray) -> np.ndarray:
    """Random unit vectors perpendicular to the unit vectors n."""
    r = rng.normal(size=n.shape)
    return unit(r - np.sum(r * n, axis=1, keepdims=True) * n)


def grazing(rng: np.random.Generator, n: np.ndarray, sign: float) -> np.ndarray:
    """Unit vectors at angles from 1e-14 to 0.1 radians above (sign 1) or below the plane."""
    eps = 10.0 ** rng.uniform(-14, -1, (len(n), 1))
    return unit(perpendicular(rng, n) + sign * eps * n)


def mix(rng: np.random.Generator, parts: list[tuple[float, np.ndarray]]) -> np.ndarray:
    """Row i from parts[k][1][i], part k chosen with probability parts[k][0]."""
    weights = np.array([w for w, _ in parts])
    choice = rng.choice(len(parts), size=len(parts[0][1]), p=weights / weights.sum())
    out = parts[0][1].copy()
    for k, (_, rows) in enumerate(parts):
        out[choice == k] = rows[choice == k]
    return out


def random_hits(rng: np.random.Generator, n: int) -> HitBatch:
    normal = unit(rng.normal(size=(n, 3)))
    random_wo = unit(rng.normal(size=(n, 3)))
    random_wo *= np.sign(np.sum(random_wo * normal, axis=1, keepdims=True))
    wo = mix(
        rng,
        [
            (0.6, random_wo),
            (0.2, grazing(rng, normal, 1.0)),
            (0.05, normal),
            (0.05, perpendicular(rng, normal)),  # in the plane, up to rounding
            (0.05, -random_wo),  # the viewer below the surface: no reflection
        ],
    )
    tangent = mix(
        rng,
        [
            (0.5, perpendicular(rng, normal)),  # what the shapes give
            (0.3, unit(rng.normal(size=(n, 3)))),  # made perpendicular by the frame
            (0.1, normal * rng.choice([-1.0, 1.0], (n, 1))),  # no direction in the plane
            (0.1, unit(normal + 1e-10 * rng.normal(size=(n, 3)))),  # nearly so
        ],
    )
    return HitBatch(
        point=rng.uniform(-10.0, 10.0, (n, 3)),
        normal=normal,
        wo=wo,
        t=rng.uniform(0.1, 10.0, n),
        front_face=rng.random(n) < 0.5,
        u=rng.random(n),
        v=rng.random(n),
        tangent=tangent,
    )


def random_wi(rng: np.random.Generator, hits: HitBatch) -> np.ndarray:
    n, wo = hits.normal, hits.wo
    mirror = 2.0 * np.sum(wo * n, axis=1, keepdims=True) * n - wo
    near_mirror = unit(
        mirror + 10.0 ** rng.uniform(-6, -0.5, (len(n), 1)) * rng.normal(size=n.shape)
    )
    return mix(
        rng,
        [
            (0.35, unit(rng.normal(size=n.shape))),
            (0.1, grazing(rng, n, 1.0)),
            (0.1, grazing(rng, n, -1.0)),
            (0.15, near_mirror),
            (0.05, mirror),
            (0.05, wo),
            (0.05, -wo),
            (0.05, n),
            (0.05, -n),
            (0.05, perpendicular(rng, n)),
        ],
    )


def local_hits(n: int, theta_deg: float, phi_deg: float = 0.0, inside: bool = False) -> HitBatch:
    """n copies of rtpy.testing's setup: normal z, tangent x, viewer at (theta, phi);
    the back face with inside=True."""
    wo = np.tile(local_direction(theta_deg, phi_deg).tolist(), (n, 1))
    z, x = np.tile([0.0, 0.0, 1.0], (n, 1)), np.tile([1.0, 0.0, 0.0], (n, 1))
    half, front = np.full(n, 0.5), np.full(n, not inside)
    return HitBatch(np.zeros((n, 3)), z, wo, np.ones(n), front, half, half, x)


# --- the scalar twins, hit by hit ------------------------------------------------------------


def vec(a) -> Vec3:
    return Vec3(float(a[0]), float(a[1]), float(a[2]))


def scalar_hit(materials, ids, hits: HitBatch, i: int):
    m = materials[ids[i]]
    hit = hits.hit_info(i, m)
    ray_view = Ray(hit.point + vec(hits.wo[i]), vec(-hits.wo[i]))
    return m, hit, ray_view


def scalar_brdf_and_pdf(materials, ids, hits: HitBatch, wi: np.ndarray):
    f, pdf = np.empty((len(ids), 3)), np.empty(len(ids))
    for i in range(len(ids)):
        m, hit, ray_view = scalar_hit(materials, ids, hits, i)
        ray_light = Ray(hit.point, vec(wi[i]))
        f[i] = tuple(m.BRDF(ray_view, ray_light, hit))
        pdf[i] = m.pdf(ray_view, ray_light, hit)
    return f, pdf


def scalar_per_hit(method: str, materials, ids, hits: HitBatch) -> np.ndarray:
    return np.array(
        [tuple(getattr(materials[ids[i]], method)(hits.hit_info(i))) for i in range(len(ids))]
    ).reshape(-1, 3)


def assert_agrees(actual, expected, what: str, rel=REL, scale=None) -> None:
    """Elementwise |actual - expected| <= rel * scale + TINY, by default scale =
    max(|actual|, |expected|) (relative agreement); rel may be an array. A value
    computed as a difference can only agree relative to the size of what was
    subtracted: pass that as scale."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, what
    if scale is None:
        scale = np.maximum(np.abs(actual), np.abs(expected))
    allowed = np.asarray(rel) * np.asarray(scale) + TINY
    ok = (actual == expected) | (np.abs(actual - expected) <= allowed)
    if not ok.all():
        bad = np.argwhere(~ok)
        i = tuple(bad[0])
        raise AssertionError(
            f"{what}: {len(bad)} of {ok.size} values differ by more than allowed; first at "
            f"{i}: batched {actual[i]!r}, scalar {expected[i]!r}, allowed "
            f"{np.broadcast_to(allowed, ok.shape)[i]:.3g}"
        )


def check_brdf_and_pdf(
    table: MaterialTable, ids, hits: HitBatch, wi: np.ndarray, rel: float = LIBM_REL
) -> None:
    """BRDF() and pdf() equal the scalar methods, to `rel` (0: bit for bit), and
    BRDF_and_pdf() equals them both."""
    f, pdf = table.BRDF(ids, hits, wi), table.pdf(ids, hits, wi)
    f_s, pdf_s = scalar_brdf_and_pdf(table.materials, ids, hits, wi)
    batched, scalar = np.column_stack([f, pdf]), np.column_stack([f_s, pdf_s])
    assert np.all(np.isfinite(batched) & (batched >= 0.0)), "BRDF or pdf: not finite and >= 0"
    what = ("BRDF", "BRDF", "BRDF", "pdf")
    for c in range(4):
        if rel == 0.0:
            np.testing.assert_array_equal(batched[:, c], scalar[:, c], err_msg=what[c])
        else:
            assert_agrees(batched[:, c], scalar[:, c], what[c], rel)
    both = table.BRDF_and_pdf(ids, hits, wi)
    np.testing.assert_array_equal(both[0], f)
    np.testing.assert_array_equal(both[1], pdf)


# --- random materials ------------------------------------------------------------------------

unit_floats = st.floats(0.0, 1.0, allow_subnormal=False)  # colours, kd, ks
colors = st.tuples(unit_floats, unit_floats, unit_floats).map(lambda c: Color(*c))


@st.composite
def albedos(draw):
    kind = draw(st.sampled_from(["color", "color", "checker", "image"]))
    if kind == "color":
        return draw(colors)
    if kind == "checker":
        return CheckerTexture(draw(st.sampled_from([0.3, 1.0, 4.0])), draw(colors), draw(colors))
    seed = draw(st.integers(0, 2**32 - 1))
    return ImageTexture(np.random.default_rng(seed).random((3, 4, 3)))


exponents = st.one_of(st.sampled_from([0.0, 0.5, 1.0, 8.0, 100.0, 1e4]), st.floats(0.0, 2000.0))
widths = st.one_of(st.sampled_from([1e-4, 1e-3, 0.05, 1.0]), st.floats(1e-3, 1.0))


strengths = st.sampled_from([0.0, 1.0]) | unit_floats
kd_ks = st.tuples(strengths, strengths)
cook_torrance = st.builds(
    lambda a, k, alpha, distribution, ior, f0: CookTorrance(a, *k, alpha, distribution, ior, f0),
    albedos(),
    kd_ks,
    widths,
    st.sampled_from(["ggx", "beckmann"]),
    st.floats(1.0, 3.0),
    st.none() | colors,
)


MATERIALS = {
    "lambertian": albedos().map(Lambertian),
    "oren_nayar": st.builds(OrenNayar, albedos(), st.sampled_from([0.0, 89.9]) | st.floats(0, 89)),
    "phong": st.builds(lambda a, k, n: Phong(a, *k, n), albedos(), kd_ks, exponents),
    "blinn_phong": st.builds(lambda a, k, n: BlinnPhong(a, *k, n), albedos(), kd_ks, exponents),
    "cook_torrance": cook_torrance,
    "ward": st.builds(
        lambda a, k, ax, ay: Ward(a, *k, ax, ay), albedos(), kd_ks, widths, st.none() | widths
    ),
    "mirror": albedos().map(Mirror),
    "metal": st.builds(Metal, albedos(), st.sampled_from([0.0, 0.3, 1.0, 2.0])),
    "dielectric": st.builds(Dielectric, st.floats(0.5, 2.5), albedos()),
    "rough_dielectric": st.builds(
        RoughDielectric,
        st.sampled_from([1.0, 1.5]) | st.floats(0.5, 2.5),
        widths,
        st.sampled_from(["ggx", "beckmann"]),
        albedos(),
    ),
    "diffuse_light": st.builds(DiffuseLight, colors, st.booleans()),
}


def random_table(data, kind: str, seed: int, n: int):
    """(table, ids, hits, rng): a MaterialTable of 1 to 3 random materials of one kind
    (hypothesis draws them from `data`), n random hits with their material ids, and
    the generator that drew them."""
    table = MaterialTable(data.draw(st.lists(MATERIALS[kind], min_size=1, max_size=3)))
    rng = np.random.default_rng(seed)
    hits = random_hits(rng, n)
    return table, rng.integers(len(table.materials), size=n), hits, rng


NON_SPECULAR = [
    "lambertian",
    "oren_nayar",
    "phong",
    "blinn_phong",
    "cook_torrance",
    "ward",
    "rough_dielectric",
]
seeds = st.integers(0, 2**32 - 1)

# --- sampling -----------------------------------------------------------------------------


def scalar_dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a . b of (n, 3) arrays, summed x + y + z as rtpy.vec3.dot."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1] + a[:, 2] * b[:, 2]


def unit_length_bound(
    table: MaterialTable, ids: np.ndarray, normal: np.ndarray, tangent: np.ndarray
) -> np.ndarray:
    """The most | |d| - 1 | a sampled direction d may have, per row: 1e-14 (45 ulp),
    plus, where the kernel reads the tangent (Ward's shading frame), 15 ULP / L with L
    the length of the tangent's part perpendicular to the normal.

    ONB.from_normal_tangent makes u = t - n (t . n) (Gram-Schmidt). With u = 2^-53 the
    unit roundoff (Higham, Accuracy and Stability of Numerical Algorithms, 2002, eq.
    3.5: a dot product of length 3 errs by at most gamma_3 = 3u times |t| |n|), the
    computed u differs from the exact perpendicular part p by at most 3u + u + u = 5u
    (t . n, the product n (t . n), the subtraction), and p . n = (t . n)(1 - |n|^2) is
    at most 10u for a normal of length 1 +- 5u (a / |a|: the sum of squares, its
    square root, the division). So the normalised u leans toward n by e <= 15u / L;
    the frame's other products are 1 or 0 to O(u), which the 1e-14 covers as it does
    for the frames built around the normal alone. A half vector h = x u + y v + z n
    with x^2 + y^2 + z^2 = 1 has |h|^2 = 1 + 2 x z e, within e of 1, and its
    reflection wi = d - 2 (d . h) h of a unit d has |wi|^2 = 1 + 4 (d . h)^2 (|h|^2 - 1):
    | |wi| - 1 | <= 2 e = 30u / L = 15 ULP / L. Below L = 1e-9 the frame is
    ONB(normal)'s; the margin of 1e-14 leaves the rows whose L the kernel may round to
    the other side of 1e-9 under the bound of the Gram-Schmidt frame."""
    reads_tangent = np.array([k.reads_tangent for k in table.kernels])[table.kind[ids]]
    along = np.sum(tangent * normal, axis=1, keepdims=True)
    length = np.linalg.norm(tangent - normal * along, axis=1)
    gram_schmidt = reads_tangent & (length >= 1e-9 - 1e-14)
    lean = 15.0 * ULP / np.maximum(length, 1e-9 - 1e-14)
    return 1e-14 + np.where(gram_schmidt, lean, 0.0)


def check_samples_match_brdf_and_pdf(
    table: MaterialTable, ids, hits: HitBatch, s: ScatterBatch
) -> None:
    """Every live sample: attenuation = f |cos| / pdf and pdf = pdf() at its direction;
    dead samples carry nothing. The glossy and rough dielectric kernels compute the
    weight as BRDF() * (|cos| / pdf()) at the direction they return: bit for bit.
    Lambertian and Oren-Nayar take cos(theta_i) and the pdf from the local sample's z,
    which the world direction's normal . d matches to the rounding of the frame and of
    the dot product, a few ulp of 1: 8 ULP / cos(theta_i) relative."""
    assert not s.is_specular.any()
    dead = ~s.alive
    assert not s.attenuation[dead].any() and not s.pdf[dead].any()
    live = np.flatnonzero(s.alive)
    d = s.direction[live]
    length_error = np.abs(np.linalg.norm(d, axis=1) - 1.0)
    bound = unit_length_bound(table, ids[live], hits.normal[live], hits.tangent[live])
    assert (length_error <= bound).all(), (
        f"sampled directions not unit: | |d| - 1 | up to {length_error.max():.3g}, "
        f"{np.count_nonzero(length_error > bound)} rows beyond their bound"
    )
    part = hits.take(live)
    f, pdf = table.BRDF(ids[live], part, d), table.pdf(ids[live], part, d)
    cos_i = np.abs(scalar_dot(d, part.normal))
    assert np.isfinite(s.attenuation[live]).all() and (s.pdf[live] > 0.0).all()
    assert (pdf > 0.0).all()
    exact = (glossy.GlossyKernel, RoughDielectricKernel)
    exact_kernel = np.array([isinstance(k, exact) for k in table.kernels])
    rel = np.where(exact_kernel[table.kind[ids[live]]], 0.0, 8.0 * ULP / cos_i)
    assert_agrees(s.pdf[live], pdf, "sample pdf vs pdf()", rel)
    expected = f * (cos_i / pdf)[:, None]
    assert_agrees(s.attenuation[live], expected, "sample weight vs f cos / pdf", rel[:, None])


def z_two_samples(a: np.ndarray, b: np.ndarray) -> float:
    """z of the difference of the means of two independent samples; the means' own
    rounding (1e-12 relative) counts as noise, so constant samples compare equal."""
    diff = a.mean() - b.mean()
    rounding = 1e-12 * max(abs(a.mean()), abs(b.mean()))
    var = a.var(ddof=1) / len(a) + b.var(ddof=1) / len(b) + rounding**2
    return 0.0 if var == 0.0 else diff / math.sqrt(var)


def batched_samples(
    material, theta: float, n: int, seed: int, phi: float = 0.0, inside: bool = False
) -> Samples:
    """The batched sampler's draws in rtpy.testing's setup, as rtpy.testing.Samples."""
    s = MaterialTable([material]).scattering(
        np.zeros(n, int), local_hits(n, theta, phi, inside), np.random.default_rng(seed)
    )
    status = np.where(s.alive, SCATTERED, 1).astype(np.int8)
    nan = np.where(s.alive, 0.0, np.nan)
    return Samples(
        theta,
        phi,
        s.direction + nan[:, None],
        s.attenuation + nan[:, None],
        s.pdf + nan,
        status,
        0.0,
        inside,
    )


def compare_with_scalar_sampler(
    material, theta, phi=0.0, n_scalar=8000, n_batched=100_000, inside=False
):
    """z-tests of the absorbed fraction and the mean weight (absorbed = 0) against the
    scalar sampler in the same setup; returns the batched samples."""
    scalar = draw_samples(material, theta, n_scalar, seed=7, phi_deg=phi, inside=inside)
    batched = batched_samples(material, theta, n_batched, seed=8, phi=phi, inside=inside)
    alive_s, alive_b = scalar.scattered.astype(float), batched.scattered.astype(float)
    p = (alive_s.sum() + alive_b.sum()) / (len(alive_s) + len(alive_b))
    if 0.0 < p < 1.0:
        z = (alive_b.mean() - alive_s.mean()) / math.sqrt(
            p * (1 - p) * (1 / n_scalar + 1 / n_batched)
        )
        assert abs(z) < Z_MAX, (
            f"absorbed fraction: scalar {1 - alive_s.mean()}, batched {1 - alive_b.mean()}"
        )
    else:
        assert alive_s.mean() == alive_b.mean()
    for c in range(3):
        w_s = np.nan_to_num(scalar.weights[:, c])
        w_b = np.nan_to_num(batched.weights[:, c])
        z = z_two_samples(w_b, w_s)
        assert abs(z) < Z_MAX, f"albedo[{c}]: scalar {w_s.mean()}, batched {w_b.mean()}, z {z:.2f}"
    return batched


SAMPLING_CASES = [
    (Lambertian(Color(0.8, 0.5, 0.2)), 30.0),
    (OrenNayar(Color(0.8, 0.5, 0.2), sigma=40.0), 70.0),
    (Phong(Color(0.6, 0.5, 0.4), kd=0.4, ks=0.5, exponent=20.0), 60.0),
    (BlinnPhong(Color(0.6, 0.5, 0.4), kd=0.3, ks=0.6, exponent=80.0), 75.0),
    (CookTorrance(Color(0.5, 0.5, 0.5), kd=0.5, ks=1.0, roughness=0.3), 80.0),
    (
        CookTorrance(kd=0.0, ks=1.0, roughness=0.4, distribution="beckmann", f0=Color(1, 0.8, 0.3)),
        50.0,
    ),
    (Ward(Color(0.5, 0.6, 0.7), kd=0.3, ks=0.6, alpha_x=0.1, alpha_y=0.4), 65.0),
    (RoughDielectric(1.5, 0.394, "ggx", Color(0.9, 0.8, 0.6)), 70.0),
]


def head(s: Samples, n: int) -> Samples:
    return Samples(
        s.incident_deg,
        s.phi_deg,
        s.directions[:n],
        s.weights[:n],
        s.pdfs[:n],
        s.status[:n],
        0.0,
        s.inside,
    )


def scalar_scatter(materials, ids, hits: HitBatch, seed: int = 0) -> list[ScatterInfo | None]:
    out = []
    with use_generator(random.Random(seed)):
        for i in range(len(ids)):
            m, hit, ray_in = scalar_hit(materials, ids, hits, i)
            out.append(m.scattering(ray_in, hit))
    return out
