"""Batched material kernels (rtpy.numpy_backend.materials) against their scalar twins.

- eval, flat_color, emitted and specular_rays must equal the scalar BRDF(), pdf(),
  flat_color(), emitting() and specular_rays() to 1e-12 relative, on random hits:
  random normals and tangents (also off the surface and along the normal), viewers
  and light directions at grazing angles, below the surface and along the mirror
  direction, random parameters and textured albedos.
- sample draws other random numbers than the scalar scattering(), so it is tested
  for what must hold anyway: every live sample's weight is f cos / pdf and its pdf is
  eval's pdf at its direction; the directions follow that pdf (rtpy.testing's chi2
  test); and the absorbed fraction and the mean weight (the directional albedo)
  agree with the scalar sampler's by z-tests with fixed seeds.
- specular kernels give the scalar directions exactly; glass reflects with
  probability R; the scalar fallback is the scalar material, number for number; and
  the number of kernel calls does not grow with the number of materials.
"""

from __future__ import annotations

import math
import random
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy.materials import (
    BlinnPhong,
    CookTorrance,
    Dielectric,
    DiffuseLight,
    Lambertian,
    Material,
    Metal,
    Mirror,
    OrenNayar,
    Phong,
    Ward,
)
from rtpy.numpy_backend.hits import HitBatch
from rtpy.numpy_backend.materials import KERNELS, MaterialTable, kernel_class
from rtpy.numpy_backend.materials.fallback import ScalarFallback
from rtpy.numpy_backend.materials.glossy import INV_TWO_PI, PhongKernel, positive_power
from rtpy.ray import Ray
from rtpy.sampling import random_cosine_direction, random_double, use_generator
from rtpy.scatter_info import ScatterInfo
from rtpy.testing import (
    SCATTERED,
    Samples,
    chi2_test,
    draw_samples,
    local_direction,
    normal_quantile,
)
from rtpy.texture import CheckerTexture, ImageTexture
from rtpy.vec3 import BLACK, Color, Vec3

REL = 1e-12  # eval, flat_color, emitted, specular_rays against the scalar methods
# sample's pdf and weight against eval at the sampled direction, away from the
# horizon (see check_samples_match_eval): the direction went from the local frame to
# the world and back, which moves it by about 1e-16; sharp lobes (exponent 1e4, width
# 1e-4) turn that into up to about 1e-10 relative.
SAMPLE_REL = 1e-9
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


def local_hits(n: int, theta_deg: float, phi_deg: float = 0.0) -> HitBatch:
    """n copies of rtpy.testing's setup: normal z, tangent x, viewer at (theta, phi)."""
    wo = np.tile(local_direction(theta_deg, phi_deg).tolist(), (n, 1))
    z, x = np.tile([0.0, 0.0, 1.0], (n, 1)), np.tile([1.0, 0.0, 0.0], (n, 1))
    half = np.full(n, 0.5)
    return HitBatch(np.zeros((n, 3)), z, wo, np.ones(n), np.ones(n, bool), half, half, x)


# --- the scalar twins, hit by hit ------------------------------------------------------------


def vec(a) -> Vec3:
    return Vec3(float(a[0]), float(a[1]), float(a[2]))


def scalar_hit(materials, ids, hits: HitBatch, i: int):
    m = materials[ids[i]]
    hit = hits.hit_info(i, m)
    ray_view = Ray(hit.point + vec(hits.wo[i]), vec(-hits.wo[i]))
    return m, hit, ray_view


def scalar_eval(materials, ids, hits: HitBatch, wi: np.ndarray):
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


def assert_agrees(actual, expected, what: str, rel: float = REL) -> None:
    """Elementwise |actual - expected| <= rel * max(|actual|, |expected|)."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, what
    ok = (actual == expected) | (
        np.abs(actual - expected) <= rel * np.maximum(np.abs(actual), np.abs(expected))
    )
    if not ok.all():
        bad = np.argwhere(~ok)
        i = tuple(bad[0])
        raise AssertionError(
            f"{what}: {len(bad)} of {ok.size} values differ by more than {rel:g} relative; "
            f"first at {i}: batched {actual[i]!r}, scalar {expected[i]!r}"
        )


# The glossy kernels work in the shading frame and the scalar materials in world space,
# so each rounds the directions differently, by about 1e-16 (more in the frame of a
# tangent nearly along the normal, which loses about 1e-16 / |its part in the surface|
# of orthogonality). That moves an ill-conditioned value by more than REL: a grazing
# direction, the edge of a lobe, a steep exponential, a huge exponent. A hit whose
# values differ by more than REL is compared to within what its conditioning allows:
# the scalar method's largest relative change when wo and wi move by PERTURBATION (a
# rounding budget several times either side's), seen over N_PERTURBED moves, times
# SAFETY. Where even that is coarser than ILL_POSED, or a direction grazes the surface
# (cos below GRAZING) or the tangent lies within GRAZING of the normal, the value is
# rounding noise: there both must only be finite and >= 0.
PERTURBATION = 1e-14
N_PERTURBED = 24
SAFETY = 4.0
ILL_POSED = 1e-6
GRAZING = 1e-6


def scalar_spread(materials, ids, hits: HitBatch, wi: np.ndarray, i: int):
    """The largest relative change of the scalar (BRDF, pdf) of hit i when wo and wi
    move by up to PERTURBATION."""
    m, hit, _ = scalar_hit(materials, ids, hits, i)
    rng = np.random.default_rng(i)

    def values(wo_k, wi_k):
        ray_view, ray_light = Ray(hit.point + vec(wo_k), vec(-wo_k)), Ray(hit.point, vec(wi_k))
        return np.array([*m.BRDF(ray_view, ray_light, hit), m.pdf(ray_view, ray_light, hit)])

    base = values(hits.wo[i], wi[i])
    spread = np.zeros(4)
    for _ in range(N_PERTURBED):
        moved = values(
            unit(hits.wo[i] + PERTURBATION * rng.uniform(-1.0, 1.0, 3)),
            unit(wi[i] + PERTURBATION * rng.uniform(-1.0, 1.0, 3)),
        )
        scale = np.maximum(np.abs(base), np.abs(moved))
        spread = np.maximum(spread, np.abs(moved - base) / np.where(scale > 0.0, scale, 1.0))
    return spread


def check_eval(table: MaterialTable, ids, hits: HitBatch, wi: np.ndarray) -> None:
    f, pdf = table.eval(ids, hits, wi)
    f_s, pdf_s = scalar_eval(table.materials, ids, hits, wi)
    batched, scalar = np.column_stack([f, pdf]), np.column_stack([f_s, pdf_s])
    assert np.all(np.isfinite(batched) & (batched >= 0.0)), "BRDF or pdf: not finite and >= 0"
    n = hits.normal
    cos_o, cos_i = np.sum(n * hits.wo, axis=1), np.sum(n * wi, axis=1)
    in_plane = hits.tangent - np.sum(hits.tangent * n, axis=1, keepdims=True) * n
    grazing = (np.abs(cos_o) < GRAZING) | (np.abs(cos_i) < GRAZING)
    grazing |= np.linalg.norm(in_plane, axis=1) < GRAZING
    scale = np.maximum(np.abs(batched), np.abs(scalar))
    error = np.abs(batched - scalar) / np.where(scale > 0.0, scale, 1.0)
    for i in np.flatnonzero((error > REL).any(axis=1) & ~grazing):
        allowed = np.maximum(REL, SAFETY * scalar_spread(table.materials, ids, hits, wi, i))
        for c, what in enumerate(("BRDF[0]", "BRDF[1]", "BRDF[2]", "pdf")):
            assert allowed[c] > ILL_POSED or error[i, c] <= allowed[c], (
                f"{what} at {i}: batched {batched[i, c]!r}, scalar {scalar[i, c]!r}: "
                f"{error[i, c]:.3g} relative, more than the {allowed[c]:.3g} that rounding "
                f"can explain there"
            )


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
widths = st.one_of(st.sampled_from([1e-6, 1e-4, 1e-3, 0.05, 1.0]), st.floats(1e-3, 1.0))


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
    "diffuse_light": st.builds(DiffuseLight, colors, st.booleans()),
}
NON_SPECULAR = ["lambertian", "oren_nayar", "phong", "blinn_phong", "cook_torrance", "ward"]
seeds = st.integers(0, 2**32 - 1)


# --- eval, flat_color, emitted -------------------------------------------------------------------


@pytest.mark.parametrize("kind", list(MATERIALS))
@settings(max_examples=20)
@given(data=st.data(), seed=seeds)
def test_eval_equals_scalar_brdf_and_pdf(kind, data, seed):
    materials = data.draw(st.lists(MATERIALS[kind], min_size=1, max_size=3))
    rng = np.random.default_rng(seed)
    hits = random_hits(rng, 150)
    ids = rng.integers(len(materials), size=150)
    table = MaterialTable(materials)
    assert {type(k) for k in table.kernels}.isdisjoint({ScalarFallback})
    check_eval(table, ids, hits, random_wi(rng, hits))


class Grey(Lambertian):
    """A student's subclass: dispatched to the scalar fallback, whatever it inherits."""

    def BRDF(self, ray_view, ray_light, hit):
        return super().BRDF(ray_view, ray_light, hit) * 0.5


@settings(max_examples=15)
@given(data=st.data(), seed=seeds)
def test_mixed_table_equals_scalar(data, seed):
    """Any mix of kinds (and a fallback) in one table: eval, flat_color, emitted."""
    kinds = st.sampled_from(list(MATERIALS)).flatmap(lambda k: MATERIALS[k])
    materials = data.draw(st.lists(kinds, min_size=1, max_size=12))
    materials.append(Grey(Color(0.2, 0.4, 0.6)))
    rng = np.random.default_rng(seed)
    hits = random_hits(rng, 300)
    ids = rng.integers(len(materials), size=300)
    table = MaterialTable(materials)
    check_eval(table, ids, hits, random_wi(rng, hits))
    flat = scalar_per_hit("flat_color", materials, ids, hits)
    assert_agrees(table.flat_color(ids, hits), flat, "flat_color")
    emitted = scalar_per_hit("emitting", materials, ids, hits)
    assert_agrees(table.emitted(ids, hits), emitted, "emitted")
    np.testing.assert_array_equal(table.specular, [m.is_specular for m in materials])
    np.testing.assert_array_equal(table.emitter, [m.is_emitter for m in materials])


def test_emitted_one_and_two_sided():
    lights = [DiffuseLight(Color(1.0, 2.0, 3.0)), DiffuseLight(Color(4.0, 5.0, 6.0), True)]
    rng = np.random.default_rng(0)
    hits = random_hits(rng, 4)
    hits.front_face[:] = [True, False, True, False]
    ids = np.array([0, 0, 1, 1])
    out = MaterialTable(lights).emitted(ids, hits)
    np.testing.assert_array_equal(out, [[1, 2, 3], [0, 0, 0], [4, 5, 6], [4, 5, 6]])
    np.testing.assert_array_equal(MaterialTable(lights).flat_color(ids, hits), np.ones((4, 3)))


def test_eval_of_an_empty_batch():
    table = MaterialTable([Lambertian(), Phong(ks=0.5)])
    hits = random_hits(np.random.default_rng(0), 0)
    f, pdf = table.eval(np.zeros(0, int), hits, np.zeros((0, 3)))
    assert f.shape == (0, 3) and pdf.shape == (0,)
    assert len(table.sample(np.zeros(0, int), hits, np.random.default_rng(0))) == 0


# --- a wrong kernel is caught ---------------------------------------------------------------------


class PhongWithWrongNormalisation(PhongKernel):
    """(n + 1) / (2 pi) in place of (n + 2) / (2 pi): off by a factor 1 + 1/(n+1)."""

    def specular(self, slots, wo, wi):
        n = self.exponent[slots]
        return (n + 1.0) * INV_TWO_PI * positive_power(self.cos_to_mirror(wo, wi), n)


def test_eval_check_catches_a_wrong_normalisation():
    material = Phong(Color(0.5, 0.5, 0.5), kd=0.5, ks=0.5, exponent=50.0)
    rng = np.random.default_rng(1)
    hits = random_hits(rng, 200)
    wi = random_wi(rng, hits)
    ids = np.zeros(200, int)
    table = MaterialTable([material])
    check_eval(table, ids, hits, wi)  # the right kernel passes
    table.kernels[0] = PhongWithWrongNormalisation(table.kernels[0].materials)
    with pytest.raises(AssertionError, match="BRDF"):
        check_eval(table, ids, hits, wi)


# --- sampling -----------------------------------------------------------------------------


def check_samples_match_eval(table: MaterialTable, ids, hits: HitBatch, s) -> None:
    """Every live sample: weight = f cos / pdf and pdf = eval's pdf at its direction;
    dead samples carry nothing."""
    assert not s.specular.any()
    dead = ~s.alive
    assert not s.weight[dead].any() and not s.pdf[dead].any()
    live = np.flatnonzero(s.alive)
    d, n, wo = s.direction[live], hits.normal[live], hits.wo[live]
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, rtol=1e-12)
    f, pdf = table.eval(ids[live], hits.take(live), d)
    cos_i, cos_o = np.sum(d * n, axis=1), np.sum(wo * n, axis=1)
    assert np.isfinite(s.weight[live]).all() and (s.pdf[live] > 0.0).all()
    # The round trip of a direction through the world frame moves the half vector by
    # about 1e-16 / cos(theta_o); a lobe of width 1e-4 magnifies that by up to 1e9.
    # Within 1e-6 of the horizon the round trip may even cross it.
    for lowest, rel in ((0.05, SAMPLE_REL), (1e-6, 1e-3)):
        k = (cos_i > lowest) & (cos_o > lowest)
        assert (pdf[k] > 0.0).all()
        expected = f[k] * (cos_i[k] / pdf[k])[:, None]
        assert_agrees(s.pdf[live][k], pdf[k], "sample pdf vs eval", rel)
        assert_agrees(s.weight[live][k], expected, "sample weight vs f cos / pdf", rel)


@pytest.mark.parametrize("kind", NON_SPECULAR)
@settings(max_examples=8)
@given(data=st.data(), seed=seeds)
def test_sample_weight_and_pdf_match_eval(kind, data, seed):
    materials = data.draw(st.lists(MATERIALS[kind], min_size=1, max_size=3))
    rng = np.random.default_rng(seed)
    hits = random_hits(rng, 2000)
    ids = rng.integers(len(materials), size=2000)
    table = MaterialTable(materials)
    check_samples_match_eval(table, ids, hits, table.sample(ids, hits, rng))


def z_two_samples(a: np.ndarray, b: np.ndarray) -> float:
    """z of the difference of the means of two independent samples; the means' own
    rounding (1e-12 relative) counts as noise, so constant samples compare equal."""
    diff = a.mean() - b.mean()
    rounding = 1e-12 * max(abs(a.mean()), abs(b.mean()))
    var = a.var(ddof=1) / len(a) + b.var(ddof=1) / len(b) + rounding**2
    return 0.0 if var == 0.0 else diff / math.sqrt(var)


def batched_samples(material, theta: float, n: int, seed: int, phi: float = 0.0) -> Samples:
    """The batched sampler's draws in rtpy.testing's setup, as rtpy.testing.Samples."""
    s = MaterialTable([material]).sample(
        np.zeros(n, int), local_hits(n, theta, phi), np.random.default_rng(seed)
    )
    status = np.where(s.alive, SCATTERED, 1).astype(np.int8)
    nan = np.where(s.alive, 0.0, np.nan)
    return Samples(
        theta, phi, s.direction + nan[:, None], s.weight + nan[:, None], s.pdf + nan, status, 0.0
    )


def compare_with_scalar_sampler(material, theta, phi=0.0, n_scalar=8000, n_batched=100_000):
    """z-tests of the absorbed fraction and the mean weight (absorbed = 0) against the
    scalar sampler in the same setup; returns the batched samples."""
    scalar = draw_samples(material, theta, n_scalar, seed=7, phi_deg=phi)
    batched = batched_samples(material, theta, n_batched, seed=8, phi=phi)
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
]


def head(s: Samples, n: int) -> Samples:
    return Samples(
        s.incident_deg, s.phi_deg, s.directions[:n], s.weights[:n], s.pdfs[:n], s.status[:n], 0.0
    )


@pytest.mark.parametrize(
    ("material", "theta"),
    SAMPLING_CASES,
    ids=["lambertian", "oren_nayar", "phong", "blinn_phong", "ggx", "beckmann", "ward"],
)
def test_sampler_agrees_with_scalar_and_follows_pdf(material, theta):
    phi = 30.0  # off the tangent axis: anisotropy and the frame's orientation count
    batched = compare_with_scalar_sampler(material, theta, phi)
    result = chi2_test(material, theta, phi_deg=phi, samples=head(batched, 30_000))
    assert result.passed(CHI2_ALPHA), result.summary()


class PhongWithWrongSampler(PhongKernel):
    """Draws the highlight with a sharper cosine power than its pdf claims."""

    def sample_specular(self, slots, wo, r1, r2):
        return super().sample_specular(slots, wo, r1 ** (1.0 / 3.0), r2)


def test_sampling_checks_catch_a_wrong_sampler(monkeypatch):
    material = Phong(Color(0.2, 0.2, 0.2), kd=0.2, ks=0.8, exponent=10.0)
    monkeypatch.setitem(KERNELS, Phong, PhongWithWrongSampler)
    batched = batched_samples(material, 70.0, 30_000, seed=1)
    assert not chi2_test(material, 70.0, samples=batched).passed(CHI2_ALPHA)
    with pytest.raises(AssertionError, match="absorbed fraction|albedo"):
        compare_with_scalar_sampler(material, 70.0)


def test_glossy_grazing_viewer_is_absorbed_as_in_scalar():
    """Viewers at 89 degrees: most specular samples fall below the surface."""
    material = Ward(Color(0.5, 0.5, 0.5), kd=0.1, ks=0.9, alpha_x=0.5, alpha_y=0.05)
    batched = compare_with_scalar_sampler(material, 89.0, 90.0)
    assert 0.1 < 1.0 - batched.scattered.mean() < 0.9


# --- specular materials ---------------------------------------------------------------------------


def scalar_scatter(materials, ids, hits: HitBatch, seed: int = 0) -> list[ScatterInfo | None]:
    out = []
    with use_generator(random.Random(seed)):
        for i in range(len(ids)):
            m, hit, ray_in = scalar_hit(materials, ids, hits, i)
            out.append(m.scattering(ray_in, hit))
    return out


def test_mirror_and_sharp_metal_reflect_exactly_as_scalar():
    materials = [Mirror(Color(0.9, 0.8, 0.7)), Metal(Color(0.5, 0.6, 0.7), fuzz=0.0)]
    rng = np.random.default_rng(5)
    hits = random_hits(rng, 500)
    ids = rng.integers(2, size=500)
    s = MaterialTable(materials).sample(ids, hits, rng)
    expected = scalar_scatter(materials, ids, hits)
    assert s.alive.all() and s.specular.all() and not s.pdf.any()
    np.testing.assert_array_equal(s.direction, [tuple(e.scattered_ray.direction) for e in expected])
    np.testing.assert_array_equal(s.weight, [tuple(e.attenuation) for e in expected])


@settings(max_examples=10)
@given(data=st.data(), seed=seeds)
def test_specular_rays_equal_scalar(data, seed):
    kinds = st.sampled_from(["mirror", "metal", "dielectric", "lambertian", "phong"])
    materials = data.draw(st.lists(kinds.flatmap(lambda k: MATERIALS[k]), min_size=1, max_size=6))
    rng = np.random.default_rng(seed)
    hits = random_hits(rng, 300)
    ids = rng.integers(len(materials), size=300)
    entries = MaterialTable(materials).specular_rays(ids, hits)
    for i in range(300):
        m, hit, ray_in = scalar_hit(materials, ids, hits, i)
        rays = m.specular_rays(ray_in, hit)
        for k, (direction, weight, mask) in enumerate(entries):
            assert mask[i] == (k < len(rays))
            if k < len(rays):
                assert_agrees(direction[i], tuple(rays[k][0].direction), f"ray {k} direction")
                assert_agrees(weight[i], tuple(rays[k][1]), f"ray {k} weight")
            else:
                assert not direction[i].any() and not weight[i].any()
        assert len(rays) <= len(entries)


def test_dielectric_reflects_with_probability_schlick():
    glass = Dielectric(1.5, Color(0.9, 1.0, 0.8))
    rng = np.random.default_rng(9)
    hits = random_hits(rng, 100_000)
    table = MaterialTable([glass])
    ids = np.zeros(len(hits), int)
    s = table.sample(ids, hits, rng)
    (reflected, _, _), (refracted, _, refracts) = table.specular_rays(ids, hits)
    reflectance = table.kernels[0].split(ids, hits)[0]
    assert s.alive.all() and s.specular.all()
    np.testing.assert_array_equal(s.weight, np.tile([0.9, 1.0, 0.8], (len(hits), 1)))
    went_back = (s.direction == reflected).all(axis=1)
    went_through = (s.direction == refracted).all(axis=1) & refracts
    assert (went_back | went_through).all()
    assert went_back[~refracts].all()  # total internal reflection
    assert 0.01 < (~refracts).mean() < 0.5
    z = (went_back.sum() - reflectance.sum()) / math.sqrt(np.sum(reflectance * (1 - reflectance)))
    assert abs(z) < Z_MAX
    # and the same fraction as the scalar sampler, for a grazing ray into the glass
    for theta, inside in ((80.0, False), (30.0, True)):
        one = local_hits(20_000, theta)
        one.front_face[:] = not inside
        b = table.sample(np.zeros(20_000, int), one, rng)
        back_b = b.direction[:, 2] > 0.0
        scalar = scalar_scatter([glass], np.zeros(4000, int), one.take(np.arange(4000)), seed=3)
        back_s = np.array([e.scattered_ray.direction.e2 > 0.0 for e in scalar])
        assert abs(z_two_samples(back_b.astype(float), back_s.astype(float))) < Z_MAX


@pytest.mark.parametrize(("fuzz", "theta"), [(0.3, 30.0), (1.0, 75.0)])
def test_fuzzy_metal_agrees_with_scalar(fuzz, theta):
    metal = Metal(Color(0.8, 0.6, 0.4), fuzz)
    n = 30_000
    hits = local_hits(n, theta, 20.0)
    b = MaterialTable([metal]).sample(np.zeros(n, int), hits, np.random.default_rng(2))
    scalar = scalar_scatter([metal], np.zeros(6000, int), hits.take(np.arange(6000)), seed=4)
    alive_s = np.array([e is not None for e in scalar], dtype=float)
    assert abs(z_two_samples(b.alive.astype(float), alive_s)) < Z_MAX
    assert (b.direction[b.alive, 2] > 0.0).all() and b.specular[b.alive].all()
    np.testing.assert_allclose(np.linalg.norm(b.direction[b.alive], axis=1), 1.0, rtol=1e-12)
    assert not b.weight[~b.alive].any()
    d_s = np.array([tuple(e.scattered_ray.direction) for e in scalar if e is not None])
    for c in range(3):
        assert abs(z_two_samples(b.direction[b.alive, c], d_s[:, c])) < Z_MAX


# --- the scalar fallback -------------------------------------------------------------------------


class HalfLambertian(Lambertian):
    """A student's subclass overriding the three methods: half the albedo, sampled with
    uniform directions in the hemisphere, absorbed when a coin says so."""

    def scattering(self, ray_in, hit):
        if random_double() < 0.25:
            return None
        x, _, z = random_cosine_direction()
        d = hit.tangent * x + hit.normal * z
        d = d / d.length()
        return ScatterInfo(Ray(hit.point, d), self.albedo.value(hit) * 0.5, 0.3)

    def BRDF(self, ray_view, ray_light, hit):
        return super().BRDF(ray_view, ray_light, hit) * 0.5

    def pdf(self, ray_view, ray_light, hit):
        return 0.75 * super().pdf(ray_view, ray_light, hit)


class Glow(Material):
    """Overrides only emitting() and scattering()."""

    is_emitter = True

    def emitting(self, hit):
        return Color(hit.u, hit.v, 1.0) if hit.front_face else BLACK

    def scattering(self, ray_in, hit):
        return ScatterInfo(Ray(hit.point, hit.normal), Color(0.1, 0.2, 0.3), 0.0, True)


def test_unknown_classes_use_the_scalar_fallback():
    assert kernel_class(HalfLambertian()) is ScalarFallback
    assert kernel_class(Glow()) is ScalarFallback
    assert kernel_class(Lambertian()) is not ScalarFallback
    broken = Lambertian()
    broken.albedo = Color(0.1, 0.2, 0.3)  # not a texture: only the scalar code knows
    assert kernel_class(broken) is ScalarFallback


def test_fallback_gives_exactly_the_scalar_results():
    materials = [HalfLambertian(Color(0.8, 0.6, 0.4)), Glow(), Lambertian(Color(0.1, 0.2, 0.3))]
    rng = np.random.default_rng(11)
    hits = random_hits(rng, 400)
    ids = rng.integers(3, size=400)
    wi = random_wi(rng, hits)
    table = MaterialTable(materials)
    f, pdf = table.eval(ids, hits, wi)
    f_s, pdf_s = scalar_eval(materials, ids, hits, wi)
    np.testing.assert_array_equal(f, f_s)
    np.testing.assert_array_equal(pdf, pdf_s)
    np.testing.assert_array_equal(
        table.emitted(ids, hits), scalar_per_hit("emitting", materials, ids, hits)
    )
    np.testing.assert_array_equal(
        table.flat_color(ids, hits), scalar_per_hit("flat_color", materials, ids, hits)
    )

    # Sampling: the fallback's hits, in order, under a random.Random seeded from the rng.
    s1 = table.sample(ids, hits, np.random.default_rng(5))
    s2 = table.sample(ids, hits, np.random.default_rng(5))
    for a, b in zip(vars(s1).values(), vars(s2).values(), strict=True):
        np.testing.assert_array_equal(a, b)  # deterministic for a seed
    rows = np.flatnonzero(ids < 2)
    seed = int(np.random.default_rng(5).integers(2**63))
    expected = scalar_scatter(materials, ids[rows], hits.take(rows), seed)
    for row, e in zip(rows, expected, strict=True):
        assert s1.alive[row] == (e is not None)
        if e is not None:
            np.testing.assert_array_equal(s1.direction[row], tuple(e.scattered_ray.direction))
            np.testing.assert_array_equal(s1.weight[row], tuple(e.attenuation))
            assert s1.pdf[row] == e.pdf and s1.specular[row] == e.is_specular
    assert 0.1 < 1 - s1.alive[ids == 0].mean() < 0.4


# --- the number of kernel calls does not grow with the number of materials ---------------------


def cover_like(n: int) -> list[Material]:
    """n materials of five classes, each with its own parameters (like the RTIOW cover)."""
    rng = np.random.default_rng(n)
    out: list[Material] = []
    for i in range(n):
        c, x = Color(*rng.random(3)), float(rng.random())
        kind = i % 5
        if kind == 0:
            out.append(Lambertian(c))
        elif kind == 1:
            out.append(Metal(c, x))
        elif kind == 2:
            out.append(Dielectric(1.0 + x))
        elif kind == 3:
            out.append(Phong(c, 0.5, 0.5, 100.0 * x))
        else:
            out.append(CookTorrance(c, 0.5, 0.5, 0.01 + 0.99 * x))
    return out


METHODS = ("flat_color", "emitted", "eval", "sample", "specular_rays")


def run_all(table: MaterialTable, ids, hits, wi) -> None:
    table.flat_color(ids, hits)
    table.emitted(ids, hits)
    table.eval(ids, hits, wi)
    table.sample(ids, hits, np.random.default_rng(0))
    table.specular_rays(ids, hits)


def test_kernel_calls_are_bounded_by_the_material_classes():
    table = MaterialTable(cover_like(500))
    assert len(table.kernels) == 5
    calls = dict.fromkeys(METHODS, 0)
    for kernel in table.kernels:
        for name in METHODS:
            method = getattr(kernel, name)

            def spy(*args, _method=method, _name=name):
                calls[_name] += 1
                return _method(*args)

            setattr(kernel, name, spy)
    rng = np.random.default_rng(0)
    hits = random_hits(rng, 5000)
    ids = rng.integers(500, size=5000)
    run_all(table, ids, hits, random_wi(rng, hits))
    # one call per class present that has something to compute
    assert calls == {"flat_color": 5, "emitted": 0, "eval": 3, "sample": 5, "specular_rays": 2}

    calls.update(dict.fromkeys(METHODS, 0))
    lambertian = np.flatnonzero([type(m) is Lambertian for m in table.materials])
    run_all(table, rng.choice(lambertian, 5000), hits, random_wi(rng, hits))
    assert calls == {"flat_color": 1, "emitted": 0, "eval": 1, "sample": 1, "specular_rays": 0}


def count_calls(fn) -> int:
    """Python and C function calls (numpy's included) made while fn() runs."""
    count = 0

    def profile(frame, event, arg):
        nonlocal count
        if event in ("call", "c_call"):
            count += 1

    sys.setprofile(profile)
    try:
        fn()
    finally:
        sys.setprofile(None)
    return count


def test_numpy_calls_do_not_grow_with_the_number_of_materials():
    rng = np.random.default_rng(3)
    hits = random_hits(rng, 2000)
    wi = random_wi(rng, hits)
    kind = rng.integers(5, size=2000)
    few, many = MaterialTable(cover_like(5)), MaterialTable(cover_like(500))
    ids_many = kind + 5 * rng.integers(100, size=2000)  # the same class per hit
    n_few = count_calls(lambda: run_all(few, kind, hits, wi))
    n_many = count_calls(lambda: run_all(many, ids_many, hits, wi))
    assert n_many == n_few
