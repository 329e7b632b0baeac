"""Tests for rtpy.materials.CookTorrance: D, G, F, the BRDF, its density, samples and energy.

Expected values come from the formulas of the scene-format contract, written out
again here with angles (theta = acos(n . w), tan(theta) from math.tan) in world
coordinates, not from the code under test:

    f_r = kd * albedo / pi + ks * D(h) G1(wi) G1(wo) F(wo . h) / (4 (n . wi) (n . wo))
    GGX:      D = a^2 / (pi cos^4 (a^2 + tan^2)^2),   G1 = 2 / (1 + sqrt(1 + a^2 tan^2))
    Beckmann: D = exp(-tan^2 / a^2) / (pi a^2 cos^4), G1 = 1 / (1 + Lambda(1 / (a tan)))
    F = F0 + (1 - F0) (1 - wo . h)^5,  F0 = ((1 - ior) / (1 + ior))^2 or f0
    pdf = p_d cos(theta_i) / pi + (1 - p_d) D(h) cos(theta_h) / (4 (wo . h))

with p_d = kd * max(albedo) / (kd * max(albedo) + ks). Integrals (the
normalisation of D, Smith's projected-area identity, the directional albedo) are
computed by Gauss-Legendre quadrature.
"""

from __future__ import annotations

import math
from functools import partial
from itertools import product

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from rtpy._checks import ROUGHNESS
from rtpy.materials import CookTorrance
from rtpy.vec3 import Color, Vec3

from ..cores import module_outcomes, outcome
from ..tiers import slow_except
from ..vectors import angle, cross3, dot3, unit3
from .directions import (
    ALBEDO,
    BAD_STRENGTHS,
    NORMAL,
    TANGENT,
    X,
    Z,
    brdf,
    check_defaults,
    check_finite,
    check_mean_weight,
    check_nothing_below,
    check_refused,
    check_scattering,
    extreme_pairs,
    half_vector_albedo,
    hemisphere_integral,
    load_material,
    mixture_pdf,
    pdf,
    theta_nodes,
)
from .directions import polar as direction

DISTRIBUTIONS = ("ggx", "beckmann")
BITANGENT = cross3(NORMAL, TANGENT)


def D(m: CookTorrance, h) -> float:
    """m.D on the axis-aligned surface (normal z), h given as a tuple."""
    return m.D(Vec3(*Z), Vec3(*h))


def G1(m: CookTorrance, v) -> float:
    return m.G1(Vec3(*Z), Vec3(*v))


# --- the reference formulas ------------------------------------------------------------


def ref_D(dist: str, a: float, theta_h: float) -> float:
    if theta_h >= math.pi / 2:
        return 0.0
    t2 = math.tan(theta_h) ** 2
    c4 = math.cos(theta_h) ** 4
    if dist == "ggx":
        return a * a / (math.pi * c4 * (a * a + t2) ** 2)
    return math.exp(-t2 / (a * a)) / (math.pi * a * a * c4)


def ref_G1(dist: str, a: float, theta: float) -> float:
    t = math.tan(theta)
    if dist == "ggx":
        return 2.0 / (1.0 + math.sqrt(1.0 + a * a * t * t))
    if t == 0.0:
        return 1.0
    x = 1.0 / (a * t)
    lam = (math.erf(x) - 1.0) / 2.0 + math.exp(-x * x) / (2.0 * x * math.sqrt(math.pi))
    return 1.0 / (1.0 + lam)


def ref_F0(ior: float, f0) -> tuple[float, float, float]:
    if f0 is not None:
        return tuple(f0)
    r = ((1.0 - ior) / (1.0 + ior)) ** 2
    return (r, r, r)


def ref_specular(dist, a, ior, f0, wo, wi, normal=NORMAL) -> list[float]:
    """The specular lobe without ks, from angles."""
    ci, co = dot3(normal, wi), dot3(normal, wo)
    if ci <= 0.0 or co <= 0.0:
        return [0.0, 0.0, 0.0]
    h = unit3(tuple(wi[k] + wo[k] for k in range(3)))
    d = ref_D(dist, a, angle(normal, h))
    g = ref_G1(dist, a, angle(normal, wi)) * ref_G1(dist, a, angle(normal, wo))
    c = dot3(wo, h)
    return [(F0 + (1.0 - F0) * (1.0 - c) ** 5) * d * g / (4.0 * ci * co) for F0 in ref_F0(ior, f0)]


def ref_brdf(kd, ks, dist, a, ior, f0, wo, wi) -> list[float]:
    if dot3(NORMAL, wi) <= 0.0 or dot3(NORMAL, wo) <= 0.0:
        return [0.0, 0.0, 0.0]
    spec = ref_specular(dist, a, ior, f0, wo, wi)
    return [kd * ALBEDO[k] / math.pi + ks * spec[k] for k in range(3)]


def ref_pdf(kd, ks, dist, a, wo, wi) -> float:
    ci = dot3(NORMAL, wi)
    if ci <= 0.0 or dot3(NORMAL, wo) <= 0.0:
        return 0.0
    h = unit3(tuple(wi[k] + wo[k] for k in range(3)))
    theta_h = angle(NORMAL, h)
    spec = ref_D(dist, a, theta_h) * math.cos(theta_h) / (4.0 * dot3(wo, h))
    return mixture_pdf(kd, ks, ci, spec)


def albedo_by_quadrature(m: CookTorrance, theta_o: float, n_phi: int = 96) -> float:
    """Directional albedo of a material with kd = 0 (so of its lobe, ks and F included)."""
    return half_vector_albedo(m, (math.sin(theta_o), 0.0, math.cos(theta_o)), m.alpha, n_phi)


# --- the BRDF is the formula -------------------------------------------------------------

angles_o = st.floats(0.0, math.radians(89.5))
angles_i = st.floats(0.0, math.radians(89.5))
azimuths = st.floats(0.0, 2.0 * math.pi)
widths = st.floats(0.01, 1.0)
f0s = st.one_of(st.none(), st.tuples(*[st.floats(0.0, 1.0)] * 3))


@given(
    st.floats(0.0, 1.0),
    st.floats(0.0, 1.0),
    st.sampled_from(DISTRIBUTIONS),
    widths,
    st.floats(1.01, 3.0),
    f0s,
    angles_o,
    azimuths,
    angles_i,
    azimuths,
)
def test_brdf_and_pdf_match_the_formulas(kd, ks, dist, a, ior, f0, to, po, ti, pi_):
    m = CookTorrance(Color(*ALBEDO), kd, ks, a, dist, ior, None if f0 is None else Color(*f0))
    wo, wi = direction(to, po), direction(ti, pi_)
    expected = ref_brdf(kd, ks, dist, a, ior, f0, wo, wi)
    assert brdf(m, wo, wi) == pytest.approx(expected, rel=1e-9, abs=1e-12)
    assume(kd + ks > 0.0)
    assert pdf(m, wo, wi) == pytest.approx(ref_pdf(kd, ks, dist, a, wo, wi), rel=1e-9, abs=1e-12)


def test_a_sharp_highlight_at_the_mirror_direction():
    """Mirror configuration, h = n: D = 1 / (pi a^2) for both distributions."""
    for dist in DISTRIBUTIONS:
        m = CookTorrance(Color(*ALBEDO), 0.0, 1.0, 0.1, dist, f0=Color(1.0, 1.0, 1.0))
        wo, wi = direction(0.5, 0.3), direction(0.5, 0.3 + math.pi)
        g1 = ref_G1(dist, 0.1, 0.5)
        expected = 1.0 / (math.pi * 0.01) * g1 * g1 / (4.0 * math.cos(0.5) ** 2)
        assert brdf(m, wo, wi) == pytest.approx([expected] * 3, rel=1e-12)
        # 0.4 rad away from the mirror direction the highlight is far weaker (GGX's
        # tail keeps about 6 percent of the peak there, Beckmann's under 2 percent).
        assert brdf(m, wo, direction(0.9, 0.3 + math.pi))[0] < 0.1 * expected


@given(st.sampled_from(DISTRIBUTIONS), widths, angles_o, azimuths, angles_i, azimuths)
def test_zero_below_the_surface(dist, a, to, po, ti, pi_):
    m = CookTorrance(Color(*ALBEDO), 0.5, 1.0, a, dist)
    wo, wi = direction(to, po), direction(ti, pi_)
    check_nothing_below(m, wo, tuple(-x for x in wi))


@given(
    st.sampled_from(DISTRIBUTIONS),
    widths,
    f0s,
    angles_o,
    azimuths,
    angles_i,
    azimuths,
)
def test_reciprocity(dist, a, f0, ta, pa, tb, pb):
    m = CookTorrance(Color(*ALBEDO), 0.3, 1.0, a, dist, f0=None if f0 is None else Color(*f0))
    wa, wb = direction(ta, pa), direction(tb, pb)
    assert brdf(m, wa, wb) == pytest.approx(brdf(m, wb, wa), rel=1e-12, abs=1e-300)


def test_the_tangent_does_not_matter():
    """D, G and F depend only on angles to the normal: the model is isotropic."""
    m = CookTorrance(Color(*ALBEDO), 0.3, 1.0, 0.3, "beckmann")
    wo, wi = direction(0.4, 0.1), direction(0.7, 2.5)
    turned = tuple(math.cos(1.1) * TANGENT[k] + math.sin(1.1) * BITANGENT[k] for k in range(3))
    assert brdf(m, wo, wi, tangent=turned) == pytest.approx(brdf(m, wo, wi), rel=1e-12)


# --- D, G1 and F on their own --------------------------------------------------------------


@pytest.mark.parametrize("dist", DISTRIBUTIONS)
@pytest.mark.parametrize("a", [0.001, 0.05, 0.1, 0.2, 0.5, 0.8, 1.0])
def test_D_is_normalised(dist, a):
    """Integral of D(h) cos(theta_h) over the hemisphere = 1: the facets' projected
    area is the surface's."""
    m = CookTorrance(roughness=a, distribution=dist)

    def integrand(t, p):
        return D(m, (math.sin(t), 0.0, math.cos(t))) * math.cos(t)

    assert hemisphere_integral(integrand, a) == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("dist", DISTRIBUTIONS)
@pytest.mark.parametrize("a", [0.05, 0.3, 1.0])
def test_D_matches_the_formula(dist, a):
    m = CookTorrance(roughness=a, distribution=dist)
    for theta in np.linspace(0.0, 1.5, 31):
        h = direction(theta, 0.7, Z, X)
        assert D(m, h) == pytest.approx(ref_D(dist, a, theta), rel=1e-10, abs=1e-300)
    assert D(m, (1.0, 0.0, 0.0)) == 0.0  # h in the surface
    assert D(m, (0.0, 0.6, -0.8)) == 0.0  # h below the surface


@pytest.mark.parametrize("dist", DISTRIBUTIONS)
@pytest.mark.parametrize("a", [0.001, 0.1, 0.5, 1.0])
def test_G1_lies_in_0_1_and_is_1_at_normal_incidence(dist, a):
    m = CookTorrance(roughness=a, distribution=dist)
    assert G1(m, (0.0, 0.0, 1.0)) == 1.0
    previous = 1.0
    for theta in np.linspace(0.0, math.pi / 2, 201)[:-1]:
        v = direction(theta, 1.3, Z, X)
        g = G1(m, v)
        assert 0.0 <= g <= 1.0
        assert g <= previous + 1e-15  # less visible the more grazing
        assert g == pytest.approx(ref_G1(dist, a, theta), rel=1e-9, abs=1e-15)
        previous = g
    assert G1(m, (1.0, 0.0, 0.0)) == 0.0  # exactly grazing
    assert G1(m, (0.0, 0.6, -0.8)) == 0.0  # below
    # Near grazing G1 falls like cos(theta) (GGX: about 2 cos / alpha).
    assert G1(m, direction(math.pi / 2 - 1e-9, 0.0, Z, X)) < 1e-5


@pytest.mark.parametrize(
    "dist, a, theta_o_deg",
    slow_except(
        product(DISTRIBUTIONS, [0.05, 0.3, 1.0], [0.0, 40.0, 75.0, 88.0]),
        ("ggx", 0.3, 75.0),
        ("beckmann", 0.05, 40.0),
    ),
)
def test_G1_matches_D_by_smiths_projected_area_identity(heavy, request, dist, a, theta_o_deg):
    """Integral of G1(wo) max(0, wo . h) D(h) d(w_h) = cos(theta_o): the visible
    facets, projected onto the view direction, cover exactly the visible surface.
    This holds only when G1 is the Smith term belonging to D."""
    projected = outcome(heavy, request)
    assert projected == pytest.approx(math.cos(math.radians(theta_o_deg)), abs=2e-4)


def projected_area(dist: str, a: float, theta_o_deg: float) -> float:
    """G1(wo) times the integral of max(0, wo . h) D(h) over the half vectors."""
    m = CookTorrance(roughness=a, distribution=dist)
    t_o = math.radians(theta_o_deg)
    wo = (math.sin(t_o), 0.0, math.cos(t_o))

    def integrand(t, p):
        s = math.sin(t)
        h = (s * math.cos(p), s * math.sin(p), math.cos(t))
        return max(0.0, dot3(wo, h)) * D(m, h)

    return G1(m, wo) * hemisphere_integral(integrand, a, n_phi=512, phi_offset=0.003)


def test_schlick_fresnel_at_normal_and_grazing_incidence():
    m = CookTorrance(ior=1.5)
    assert m.F(1.0).tolist() == pytest.approx([0.04] * 3, rel=1e-12)  # ((1 - 1.5) / 2.5)^2
    assert m.F(0.0).tolist() == pytest.approx([1.0] * 3, rel=1e-12)
    assert m.F(0.5).tolist() == pytest.approx([0.04 + 0.96 / 32] * 3, rel=1e-12)
    gold = CookTorrance(f0=Color(1.0, 0.78, 0.34), ior=1.5)  # f0 overrides ior
    assert gold.F(1.0).tolist() == pytest.approx([1.0, 0.78, 0.34])
    assert gold.F(0.0).tolist() == pytest.approx([1.0, 1.0, 1.0])
    assert gold.F(0.8).tolist() == pytest.approx(
        [c + (1.0 - c) * 0.2**5 for c in (1.0, 0.78, 0.34)], rel=1e-12
    )
    water = CookTorrance(ior=1.33)
    assert water.F(1.0).e0 == pytest.approx((0.33 / 2.33) ** 2, rel=1e-12)


# --- sampling ------------------------------------------------------------------------------


@pytest.mark.parametrize("dist", DISTRIBUTIONS)
@pytest.mark.parametrize(
    "kd, ks, a, theta_o",
    [
        (0.7, 0.6, 0.3, 0.4),
        (0.0, 1.0, 0.05, 1.2),
        (1.0, 0.2, 1.0, 0.0),
        (0.0, 1.0, 0.5, 1.55),
    ],
)
def test_scattering_weight_is_brdf_cos_over_pdf(dist, kd, ks, a, theta_o):
    m = CookTorrance(Color(*ALBEDO), kd, ks, a, dist)
    wo = direction(theta_o, 0.8)
    brdf_of = partial(ref_brdf, kd, ks, dist, a, 1.5, None, wo)
    seed = (7, int(a * 100), int(theta_o * 100))
    cosines = check_scattering(m, wo, brdf_of, partial(ref_pdf, kd, ks, dist, a, wo), 400, seed)
    assert kd == 0.0 or cosines


@pytest.mark.parametrize("dist", DISTRIBUTIONS)
@pytest.mark.parametrize("a, theta_o_deg", [(0.05, 30.0), (0.3, 0.0), (0.3, 70.0), (1.0, 45.0)])
@pytest.mark.slow
def test_mean_sample_weight_is_the_albedo_by_quadrature(heavy, request, dist, a, theta_o_deg):
    """The mean of BRDF * cos / pdf over the sampler's directions (absorbed samples
    count 0) estimates the directional albedo exactly when the sampler draws with
    the density pdf() claims: compare with quadrature."""
    outcome(heavy, request)


def check_mean_weight_against_quadrature(dist: str, a: float, theta_o_deg: float) -> None:
    m = CookTorrance(kd=0.0, ks=1.0, roughness=a, distribution=dist, f0=Color(1.0, 1.0, 1.0))
    t_o = math.radians(theta_o_deg)
    wo = direction(t_o, 0.8)
    check_mean_weight(
        m, wo, albedo_by_quadrature(m, t_o), 6000, (11, int(a * 100), int(theta_o_deg))
    )


@pytest.mark.parametrize("dist", DISTRIBUTIONS)
@pytest.mark.parametrize("a", [0.01, 0.3, 1.0])
def test_the_half_vector_sampler_inverts_the_cdf_of_D_cos(dist, a):
    """P(theta_h <= t) for the sampler, from r1, against the integral of D cos."""
    m = CookTorrance(roughness=a, distribution=dist)
    for r1 in (0.0, 0.1, 0.5, 0.9, 0.999):
        h = m.sample_half_vector(r1, 0.3).tolist()
        assert dot3(h, h) == pytest.approx(1.0, abs=1e-12)
        t_h = math.acos(min(1.0, h[2]))
        thetas, weights = theta_nodes(a)
        cdf = sum(
            w * math.sin(t) * ref_D(dist, a, t) * math.cos(t) * 2.0 * math.pi
            for t, w in zip(thetas, weights, strict=True)
            if t <= t_h
        )
        # The quadrature is exact only at its own nodes, so compare loosely...
        assert cdf <= r1 + 0.02
        # ... and exactly through the closed forms of the CDF.
        t2 = math.tan(t_h) ** 2
        exact = t2 / (a * a + t2) if dist == "ggx" else 1.0 - math.exp(-t2 / (a * a))
        assert exact == pytest.approx(r1, abs=1e-9)
        assert math.atan2(h[1], h[0]) == pytest.approx(2.0 * math.pi * 0.3, abs=1e-12) or r1 == 0


# --- numerics at the extremes --------------------------------------------------------------


@pytest.mark.parametrize("dist", DISTRIBUTIONS)
@pytest.mark.parametrize("a", [ROUGHNESS.lo, 0.001, 0.01, 1.0])
def test_tiny_roughness_and_grazing_angles_give_finite_values(dist, a):
    m = CookTorrance(Color(*ALBEDO), 0.2, 1.0, a, dist)
    check_finite(m, extreme_pairs((0.0, 0.3, math.pi - 1e-7, math.pi)), 50)
    # The extreme draws of the sampler itself.
    for r1 in (0.0, 1e-300, 0.5, 1.0 - 2.0**-53):
        h = m.sample_half_vector(r1, 0.99).tolist()
        assert all(math.isfinite(x) for x in h) and h[2] >= 0.0
    # The BRDF at cos = 1e-12 on one side stays finite and non-negative.
    f = brdf(m, (math.sqrt(1.0 - 1e-24), 0.0, 1e-12), (-0.6, 0.0, 0.8), Z, X)
    assert all(math.isfinite(x) and x >= 0.0 for x in f)


# --- energy --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "dist, a", slow_except(product(DISTRIBUTIONS, [0.05, 0.2, 0.5, 1.0]), ("beckmann", 1.0))
)
def test_the_lobe_reflects_at_most_everything(heavy, request, dist, a):
    """kd = 0, ks = 1 and F = 1 (f0 white): the directional albedo is <= 1 at every
    viewing angle (single scattering loses energy; nothing creates it)."""
    albedos, plastic = outcome(heavy, request)
    for value in albedos:
        assert 0.0 < value <= 1.0 + 1e-3
    if a <= 0.05:
        assert albedos[0] > 0.98  # a smooth surface reflects nearly everything head-on
    if a == 1.0:
        assert albedos[0] < 0.9  # a very rough one loses what bounces between facets
    # The plastic default (F0 = 0.04) reflects little head-on.
    assert plastic < 0.05


def lobe_albedos(dist: str, a: float) -> tuple[list[float], float]:
    """The lobe's directional albedo with F = 1 at 0, 30, 60, 80 and 89 degrees, and
    head-on with the plastic default F0."""
    m = CookTorrance(kd=0.0, ks=1.0, roughness=a, distribution=dist, f0=Color(1.0, 1.0, 1.0))
    albedos = [albedo_by_quadrature(m, math.radians(t)) for t in (0.0, 30.0, 60.0, 80.0, 89.0)]
    plastic = CookTorrance(kd=0.0, ks=1.0, roughness=a, distribution=dist)
    return albedos, albedo_by_quadrature(plastic, 0.0)


# node id -> the quadratures and sampling of each selected test, on every core, the
# longest first.
heavy = module_outcomes(
    {
        "test_mean_sample_weight_is_the_albedo_by_quadrature": (
            check_mean_weight_against_quadrature
        ),
        "test_the_lobe_reflects_at_most_everything": lobe_albedos,
        "test_G1_matches_D_by_smiths_projected_area_identity": projected_area,
    }
)


# --- construction and scene files ----------------------------------------------------------


def test_defaults_and_registration():
    defaults = dict(kd=1.0, ks=0.0, roughness=0.5, distribution="ggx", ior=1.5)
    m = check_defaults(CookTorrance, "cook_torrance", **defaults)
    assert m.f0.tolist() == pytest.approx([0.04] * 3)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        *BAD_STRENGTHS,
        ({"roughness": 0.0}, "roughness"),
        ({"roughness": -0.2}, "roughness"),
        ({"roughness": 1.5}, "roughness"),
        ({"roughness": math.nan}, "roughness"),
        ({"distribution": "phong"}, "distribution"),
        ({"distribution": "GGX"}, "distribution"),
        ({"ior": 0.0}, "ior"),
        ({"ior": -1.5}, "ior"),
        ({"ior": math.inf}, "ior"),
        ({"f0": Color(1.2, 0.5, 0.5)}, "f0"),
        ({"f0": Color(0.5, -0.1, 0.5)}, "f0"),
        ({"f0": Color(0.5, 0.5, math.nan)}, "f0"),
    ],
)
def test_constructor_refuses_bad_parameters(kwargs, message):
    with pytest.raises((TypeError, ValueError), match=message):
        CookTorrance(**kwargs)


def load_cook_torrance(keys: str) -> CookTorrance:
    return load_material(f'type = "cook_torrance"\n{keys}')


def test_the_loader_reads_cook_torrance_with_and_without_optional_keys():
    m = load_cook_torrance("")
    assert isinstance(m, CookTorrance)
    assert (m.kd, m.ks, m.roughness, m.distribution) == (1.0, 0.0, 0.5, "ggx")
    assert m.f0.tolist() == pytest.approx([0.04] * 3)
    m = load_cook_torrance(
        'albedo = [0.9, 0.6, 0.2]\nkd = 0\nks = 1\nroughness = 0.1\ndistribution = "beckmann"\n'
        "f0 = [1.0, 0.78, 0.34]"
    )
    assert (m.kd, m.ks, m.roughness, m.distribution) == (0.0, 1.0, 0.1, "beckmann")
    assert m.f0.tolist() == [1.0, 0.78, 0.34]
    m = load_cook_torrance("ior = 1.33\nroughness = 1")
    assert m.f0.e0 == pytest.approx((0.33 / 2.33) ** 2)


@pytest.mark.parametrize(
    "keys, words",
    [
        ('distribution = "beckman"', ["distribution", "did you mean 'beckmann'"]),
        ("roughness = 0", ["roughness", "in [0.0001, 1]"]),
        ("roughness = 2", ["roughness", "in [0.0001, 1]"]),
        ("f0 = [1.5, 0.5, 0.5]", ["f0"]),
        ("f0 = 0.5", ["f0"]),
        ("ior = -1", ["ior"]),
        ("rougness = 0.2", ["did you mean 'roughness'"]),
    ],
)
def test_the_loader_refuses_bad_values(keys, words):
    check_refused("cook_torrance", keys, words)
