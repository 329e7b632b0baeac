"""Tests for rtpy.materials.RoughDielectric: Fresnel, the BSDF and its density against
Walter et al. 2007 written out again, sampling, reciprocity, energy, and planted mistakes.

The reference formulas below use angles and the indices of refraction of the two sides
(n_o on the viewer's side, n_i on the light's), as the paper writes them, not the
relative eta of the code under test:

    Fresnel: Snell's sin(t_t) = sin(t_i) / eta, r_s = -sin(t_i - t_t) / sin(t_i + t_t),
             r_p = tan(t_i - t_t) / tan(t_i + t_t), F = (r_s^2 + r_p^2) / 2
    reflection:  m = normalize(wo + wi)
                 f = F D G / (4 |n.wi| |n.wo|),            pdf = F D cos(t_m) / (4 |wo.m|)
    refraction:  m = +-normalize(n_i wi + n_o wo), toward the viewer's side
                 f = |wi.m| |wo.m| n_o^2 (1 - F) G D / (|n.wi| |n.wo| (n_i wi.m + n_o wo.m)^2)
                 pdf = (1 - F) D cos(t_m) n_i^2 |wi.m| / (n_i wi.m + n_o wo.m)^2

with D and G1 of tests/materials/test_cook_torrance.py and G = G1(wo) G1(wi), each
direction's angle measured from the normal on its own side.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from rtpy.materials import MATERIALS, RoughDielectric
from rtpy.materials import rough_dielectric as module
from rtpy.testing import (
    MaterialReport,
    check_material,
    check_reciprocity,
    check_weights,
    chi2_test,
    directional_albedo,
    draw_samples,
)
from rtpy.vec3 import Color, dot

from ..cores import module_outcomes, outcome
from ..tiers import slow_except
from ..vectors import angle, dot3, unit3
from .directions import (
    NORMAL,
    X,
    Z,
    check_refused,
    hemisphere_integral,
    light_ray,
    load_material,
    make_hit,
    mirror,
    view_ray,
)
from .directions import polar as direction
from .test_cook_torrance import ref_D, ref_G1

# The lecture's glasses (Walter et al. 2007, fitted to measurements), ior 1.5.
GLASSES = {
    "anti_glare": ("beckmann", 0.023),
    "ground": ("ggx", 0.394),
    "etched": ("ggx", 0.553),
}


def glass(name: str, ior: float = 1.5) -> RoughDielectric:
    distribution, roughness = GLASSES[name]
    return RoughDielectric(ior, roughness, distribution)


def bsdf(m, wo, wi, inside=False, normal=NORMAL) -> list[float]:
    hit = make_hit(m, normal, front_face=not inside)
    return m.BRDF(view_ray(wo), light_ray(wi), hit).tolist()


def density(m, wo, wi, inside=False, normal=NORMAL) -> float:
    return m.pdf(view_ray(wo), light_ray(wi), make_hit(m, normal, front_face=not inside))


# --- the reference formulas ------------------------------------------------------------


def ref_fresnel(cos_i: float, eta: float) -> float:
    """Fresnel's equations from the angles; eta = n_t / n_i."""
    t_i = math.acos(min(1.0, cos_i))
    s = math.sin(t_i) / eta
    if s >= 1.0:
        return 1.0
    if t_i == 0.0:
        return ((eta - 1.0) / (eta + 1.0)) ** 2
    t_t = math.asin(s)
    r_s = -math.sin(t_i - t_t) / math.sin(t_i + t_t)
    r_p = math.tan(t_i - t_t) / math.tan(t_i + t_t)
    return 0.5 * (r_s * r_s + r_p * r_p)


def ref_facet(ior, wo, wi, inside, normal=NORMAL):
    """(m, n_o, n_i) for the pair, or None where no facet turns wo into wi."""
    n_o, n_other = (ior, 1.0) if inside else (1.0, ior)
    cos_i = dot3(normal, wi)
    if cos_i > 0.0:
        m, n_i = unit3(tuple(wo[k] + wi[k] for k in range(3))), n_o
    else:
        n_i = n_other
        m = unit3(tuple(-(n_i * wi[k] + n_o * wo[k]) for k in range(3)))
        if dot3(m, normal) < 0.0:
            m = tuple(-x for x in m)
    if dot3(m, normal) <= 0.0 or dot3(wo, m) <= 0.0 or (dot3(wi, m) > 0.0) != (cos_i > 0.0):
        return None
    return m, n_o, n_i


def ref_bsdf_and_pdf(dist, a, ior, wo, wi, inside, normal=NORMAL) -> tuple[float, float]:
    """Walter et al. eq. 20 and 21 (f) and 14 and 17 (pdf), white tint."""
    cos_o, cos_i = dot3(normal, wo), dot3(normal, wi)
    facet = ref_facet(ior, wo, wi, inside, normal)
    if cos_o <= 0.0 or cos_i == 0.0 or facet is None:
        return 0.0, 0.0
    m, n_o, n_i = facet
    n_other = 1.0 if inside else ior
    d = ref_D(dist, a, angle(normal, m))
    below = tuple(-x for x in normal)
    g = ref_G1(dist, a, angle(normal, wo)) * ref_G1(
        dist, a, angle(normal if cos_i > 0 else below, wi)
    )
    f_r = ref_fresnel(dot3(wo, m), n_other / n_o)
    wo_m, wi_m = dot3(wo, m), dot3(wi, m)
    if cos_i > 0.0:
        return f_r * d * g / (4.0 * cos_i * cos_o), f_r * d * dot3(normal, m) / (4.0 * wo_m)
    squared = (n_i * wi_m + n_o * wo_m) ** 2
    f = abs(wi_m) * wo_m / (abs(cos_i) * cos_o) * n_o**2 * (1.0 - f_r) * g * d / squared
    p = (1.0 - f_r) * d * dot3(normal, m) * n_i**2 * abs(wi_m) / squared
    return f, p


# --- parameters -------------------------------------------------------------------------


def test_scene_files_know_it_with_its_defaults():
    assert MATERIALS["rough_dielectric"] is RoughDielectric
    m = RoughDielectric()
    assert (m.ior, m.roughness, m.distribution) == (1.5, 0.1, "ggx")
    hit = make_hit(m)
    assert m.tint.value(hit).tolist() == [1.0, 1.0, 1.0]
    assert m.flat_color(hit).tolist() == [1.0, 1.0, 1.0]  # what "center" shows
    assert m.is_specular is False and m.is_emitter is False
    keys = 'type = "rough_dielectric"\nior = 1.33\nroughness = 0.4\ndistribution = "beckmann"'
    loaded = load_material(keys + "\ntint = [0.9, 0.95, 1]")
    assert (loaded.ior, loaded.roughness, loaded.distribution) == (1.33, 0.4, "beckmann")
    assert loaded.flat_color(make_hit(loaded)).tolist() == [0.9, 0.95, 1.0]


@pytest.mark.parametrize(
    "keys, words",
    [
        ("ior = 0", ["ior", "in [0.01, 100]"]),
        ("roughness = 0", ["roughness", "in [0.0001, 1]"]),
        ("roughness = 1.5", ["roughness", "in [0.0001, 1]"]),
        ('distribution = "phong"', ["distribution", '"ggx", "beckmann"']),
        ("tint = [0.5, 1.2, 0.5]", ["tint", "[0, 1]"]),
    ],
)
def test_scene_files_refuse_bad_parameters(keys, words):
    check_refused("rough_dielectric", keys, words)


@pytest.mark.parametrize("ior", [0.0, -1.5, math.nan, math.inf, "1.5"])
def test_python_refuses_a_bad_ior(ior):
    with pytest.raises(
        (TypeError, ValueError), match=r"^ior: expected a (finite )?number in \[0.01, 100\]"
    ):
        RoughDielectric(ior)


def test_an_ior_of_one_is_computed_a_millionth_away():
    """At ior 1 the refracted light goes straight on whatever the facet: no density."""
    assert RoughDielectric(1.0).inside_ior == 1.0 + 1e-6
    assert RoughDielectric(1.0 - 1e-9).inside_ior == 1.0 - 1e-6
    assert RoughDielectric(1.0 + 2e-6).inside_ior == 1.0 + 2e-6
    assert RoughDielectric(1.0).ior == 1.0


# --- Fresnel --------------------------------------------------------------------------------


@given(st.floats(1e-6, 1.0), st.floats(0.3, 3.0))
def test_fresnel_is_the_exact_formula(cos_i, eta):
    assume(abs(eta - 1.0) > 1e-6)
    expected = ref_fresnel(cos_i, eta)
    assume(abs(math.sin(math.acos(cos_i)) / eta - 1.0) > 1e-9)  # not at the critical angle
    assert module.fresnel_dielectric(cos_i, eta) == pytest.approx(expected, rel=1e-9, abs=1e-15)


def test_fresnel_at_known_angles():
    f = module.fresnel_dielectric
    assert f(1.0, 1.5) == pytest.approx(0.04, rel=1e-12)  # ((1.5 - 1) / (1.5 + 1))^2
    assert f(1.0, 1.0 / 1.5) == pytest.approx(0.04, rel=1e-12)  # the same from inside
    brewster = math.atan(1.5)  # r_p = 0 there: F = r_s^2 / 2
    r_s = (math.cos(brewster) - 1.5 * math.sqrt(1 - math.sin(brewster) ** 2 / 2.25)) / (
        math.cos(brewster) + 1.5 * math.sqrt(1 - math.sin(brewster) ** 2 / 2.25)
    )
    assert f(math.cos(brewster), 1.5) == pytest.approx(r_s**2 / 2, rel=1e-12)
    critical = math.asin(1.0 / 1.5)
    assert f(math.cos(critical - 1e-3), 1.0 / 1.5) < 1.0
    assert f(math.cos(critical + 1e-9), 1.0 / 1.5) == 1.0  # total internal reflection
    assert f(1e-300, 1.5) == pytest.approx(1.0)  # grazing


@given(st.floats(0.0, 1.5), st.floats(1.01, 2.5))
def test_fresnel_is_the_same_from_both_sides(t_i, eta):
    """Light refracted from angle t_i to t_t is reflected as much as light going back
    from t_t to t_i (Stokes): what makes f_t reciprocal but for the eta^2."""
    t_t = math.asin(math.sin(t_i) / eta)
    f = module.fresnel_dielectric
    assert f(math.cos(t_i), eta) == pytest.approx(f(math.cos(t_t), 1.0 / eta), rel=1e-9)


# --- the BSDF and its density are the paper's formulas ------------------------------------

iors = st.one_of(st.floats(0.6, 0.95), st.floats(1.05, 2.5))


@given(
    st.sampled_from(["ggx", "beckmann"]),
    st.floats(0.01, 1.0),
    iors,
    st.booleans(),
    st.floats(0.0, 1.56),
    st.floats(0.0, 2.0 * math.pi),
    st.floats(0.0, math.pi),
    st.floats(0.0, 2.0 * math.pi),
)
def test_bsdf_and_pdf_are_walters_formulas(dist, a, ior, inside, t_o, p_o, t_i, p_i):
    m = RoughDielectric(ior, a, dist)
    wo, wi = direction(t_o, p_o), direction(t_i, p_i)
    assume(abs(dot3(NORMAL, wi)) > 1e-9)
    facet = ref_facet(ior, wo, wi, inside)
    if facet is not None:  # not at a facet's edge, where rounding decides
        mf = facet[0]
        assume(min(dot3(NORMAL, mf), dot3(wo, mf), abs(dot3(wi, mf))) > 1e-7)
        n_view, n_other = (ior, 1.0) if inside else (1.0, ior)
        sin_t = math.sqrt(max(0.0, 1.0 - dot3(wo, mf) ** 2)) * n_view / n_other
        assume(abs(sin_t - 1.0) > 1e-7)  # not at the critical angle
    f, p = ref_bsdf_and_pdf(dist, a, ior, wo, wi, inside)
    assert bsdf(m, wo, wi, inside) == pytest.approx([f] * 3, rel=1e-8, abs=1e-300)
    assert density(m, wo, wi, inside) == pytest.approx(p, rel=1e-8, abs=1e-300)


def test_tint_colours_only_the_light_that_passes():
    m = RoughDielectric(1.5, 0.3, "ggx", Color(0.2, 0.5, 1.0))
    white = RoughDielectric(1.5, 0.3, "ggx")
    wo = direction(0.4, 0.0)
    through, back = direction(2.8, math.pi), direction(0.5, math.pi)
    f, g = bsdf(m, wo, through), bsdf(white, wo, through)
    assert f == pytest.approx([0.2 * g[0], 0.5 * g[0], g[0]], rel=1e-12) and g[0] > 0.0
    assert bsdf(m, wo, back) == bsdf(white, wo, back) and bsdf(m, wo, back)[0] > 0.0


def test_no_light_reaches_a_viewer_below_the_surface():
    m = glass("ground")
    below = direction(2.0, 0.3)
    for wi in (direction(0.3, 1.0), direction(2.5, 1.0)):
        assert bsdf(m, below, wi) == [0.0, 0.0, 0.0] and density(m, below, wi) == 0.0
    assert m.scattering(view_ray(below), make_hit(m)) is None


# --- sampling -----------------------------------------------------------------------------

SAMPLING_CASES = [
    (name, theta, inside)
    for name in GLASSES
    for theta in (0.0, 30.0, 60.0, 85.0)
    for inside in (False, True)
]


@pytest.mark.parametrize(
    "name, theta, inside",
    slow_except(SAMPLING_CASES, ("ground", 30.0, False), ("anti_glare", 30.0, True)),
)
@pytest.mark.slow
def test_scattering_draws_the_pdf_and_weighs_by_it(slow_outcomes, request, name, theta, inside):
    chi2_passed, chi2_summary, weights_passed, weights_detail = outcome(slow_outcomes, request)
    assert chi2_passed, chi2_summary
    assert weights_passed, weights_detail


def sampling_outcome(name: str, theta: float, inside: bool) -> tuple[bool, str, bool, str]:
    """The chi-square test of 30,000 samples at level 1e-3 and the weights check on the
    same samples: (chi2 passed, its summary, weights passed, their detail)."""
    m = glass(name)
    samples = draw_samples(m, theta, 30_000, seed=5, inside=inside)
    result = chi2_test(m, theta, samples=samples, inside=inside)
    weights = check_weights(m, theta, samples=samples, inside=inside)
    return result.passed(1e-3), result.summary(), weights.passed, weights.detail


# --- radiance transport: the eta^2 --------------------------------------------------------


@pytest.mark.parametrize("inside", [False, True])
def test_refraction_scales_radiance_by_eta_squared(inside):
    """At normal incidence through a nearly smooth surface the refracted samples weigh
    (n_o / n_i)^2 G |wo.m| / (|n.wo| cos(t_m)), within 2e-3 of (n_o / n_i)^2: a camera
    outside sees light from inside the glass 2.25 times dimmer, from inside 2.25 times
    brighter (the BSDF is the one for radiance arriving from wi)."""
    s = draw_samples(glass("anti_glare"), 0.0, 5000, inside=inside)
    through = s.weights[s.transmitted, 0]
    assert len(through) > 4000
    expected = 2.25 if inside else 1.0 / 2.25
    assert np.allclose(through, expected, rtol=2e-3)
    assert (through <= expected * (1.0 + 1e-12)).all()  # G only takes away (and rounding)


def test_generalised_reciprocity_holds_and_plain_reciprocity_does_not():
    """f(wo, wi) / n_o^2 = f(wi, wo) / n_i^2 across the surface; the plain symmetry
    BRDF(wo, wi) = BRDF(wi, wo) fails there, by the factor 2.25 (the checker's power)."""
    m = glass("ground")
    assert check_reciprocity(m, n_pairs=600, ior=1.5)
    assert not check_reciprocity(m, n_pairs=600, ior=1.0)
    wo, wi = direction(0.3, 0.0), direction(2.7, math.pi)  # viewer outside, light inside
    forward = bsdf(m, wo, wi)[0]
    # The other way round: the viewer inside at wi, whose hit normal faces it.
    below = tuple(-x for x in NORMAL)
    hit = make_hit(m, below, front_face=False)
    backward = m.BRDF(view_ray(wi), light_ray(wo), hit).e0
    assert forward > 0.0
    assert forward / 1.0**2 == pytest.approx(backward / 1.5**2, rel=1e-12)


# --- energy ----------------------------------------------------------------------------


def visible_facet_loss(m: RoughDielectric, theta_deg: float, inside: bool) -> float:
    """The light a single-scattering microfacet surface loses, integrated over the facet
    normals: facets seen from wo weigh D(m) G1(wo) max(0, wo.m) / cos(t_o) (Smith's
    visible normals, which integrate to 1), and the light a facet reflects (F) or
    refracts (1 - F) leaves unblocked with probability G1(wi), 0 when wi ends on the
    wrong side. loss = 1 - integral of both."""
    dist, a, ior = m.distribution, m.alpha, m.ior
    n_o, n_other = (ior, 1.0) if inside else (1.0, ior)
    t_o = math.radians(theta_deg)
    wo = (math.sin(t_o), 0.0, math.cos(t_o))
    g_o = ref_G1(dist, a, t_o)

    def integrand(t, p):
        mf = direction(t, p, Z, X)
        c = dot3(wo, mf)
        if c <= 0.0:
            return 0.0  # a facet the viewer cannot see
        f_r = ref_fresnel(c, n_other / n_o)
        z_r = mirror(wo, mf)[2]
        kept = f_r * ref_G1(dist, a, math.acos(z_r)) if z_r > 0.0 else 0.0
        if f_r < 1.0:
            eta = n_o / n_other  # Snell, through the facet
            cos_t = math.sqrt(1.0 - eta * eta * (1.0 - c * c))
            refracted = tuple(-eta * wo[k] + (eta * c - cos_t) * mf[k] for k in range(3))
            if refracted[2] < 0.0:
                kept += (1.0 - f_r) * ref_G1(dist, a, math.acos(-refracted[2]))
        return ref_D(dist, a, t) * g_o * c / math.cos(t_o) * kept

    # At normal incidence the integrand has kinks at the polar angles of the facets that
    # reflect totally (the critical angle) and that reflect into the surface (45 deg).
    kinks = (math.asin(min(1.0, n_other / n_o)), 0.25 * math.pi) if theta_deg == 0.0 else ()
    return 1.0 - hemisphere_integral(integrand, a, n_phi=256, phi_offset=0.01, breaks=kinks)


@pytest.mark.parametrize(
    "name, theta, inside",
    slow_except(
        [(n, t, s) for n in GLASSES for t in (0.0, 60.0) for s in (False, True)],
        ("ground", 60.0, False),
    ),
)
@pytest.mark.slow
def test_the_light_lost_is_what_the_facets_block(slow_outcomes, request, name, theta, inside):
    """reflected + transmitted + lost = 1, where lost (from rtpy.testing's quadrature of
    the BSDF over the directions) is the visible-facet integral of what G1 blocks: the
    documented loss of single scattering, computed over m instead of wi (so the
    Jacobians, F and the eta^2 are checked by an independent route)."""
    lost, quadrature_error, expected = outcome(slow_outcomes, request)
    assert lost == pytest.approx(expected, abs=10 * quadrature_error + 2e-4)
    assert -1e-12 <= expected < 1.0


def loss_outcome(name: str, theta: float, inside: bool) -> tuple[float, float, float]:
    """(the light lost by rtpy.testing's albedo, its quadrature error, the light lost by
    visible_facet_loss)."""
    m = glass(name)
    a = directional_albedo(m, theta, n_samples=20_000, inside=inside)
    return a.lost[0], a.quadrature_error, visible_facet_loss(m, theta, inside)


# --- planted mistakes: each formula's check catches it ----------------------------------


def fresnel_swapped(cos_i, eta):
    """Fresnel with the sides swapped: eta = n_viewer / n_other."""
    return FRESNEL(cos_i, 1.0 / eta)


FRESNEL = module.fresnel_dielectric


def test_a_jacobian_without_eta_squared_fails_the_chi2_test(slow_outcomes, request):
    assert not outcome(slow_outcomes, request)


def jacobian_without_eta_squared(wo_m, wi_m, eta):
    denominator = eta * wi_m + wo_m
    return abs(wi_m) / (denominator * denominator)


def jacobian_without_wi_dot_m(wo_m, wi_m, eta):
    return eta * eta / (eta * wi_m + wo_m) ** 2


def reflection_jacobian_without_wo_dot_m(wo_m):
    return 0.25


def chi2_passes_with(attribute: str, planted, theta: float) -> bool:
    """Whether ground glass passes the chi-square test (20,000 samples at theta, level
    1e-3) with the module's `attribute` replaced by `planted` (in this process, for
    the test only)."""
    original = getattr(module, attribute)
    setattr(module, attribute, planted)
    try:
        return chi2_test(glass("ground"), theta, n_samples=20_000).passed(1e-3)
    finally:
        setattr(module, attribute, original)


def chi2_passes_without_eta_squared() -> bool:
    return chi2_passes_with("refraction_jacobian", jacobian_without_eta_squared, 30.0)


def chi2_passes_without_the_dot_m(lobe: str) -> bool:
    if lobe == "reflection":
        return chi2_passes_with("reflection_jacobian", reflection_jacobian_without_wo_dot_m, 60.0)
    return chi2_passes_with("refraction_jacobian", jacobian_without_wi_dot_m, 60.0)


def test_fresnel_on_the_wrong_side_fails_reciprocity_and_the_formulas(monkeypatch):
    monkeypatch.setattr(module, "fresnel_dielectric", fresnel_swapped)
    m = glass("ground")
    assert not check_reciprocity(m, n_pairs=200, ior=1.5)
    wo, wi = direction(0.9, 0.0), direction(2.6, math.pi)
    f, _ = ref_bsdf_and_pdf("ggx", 0.394, 1.5, wo, wi, False)
    assert bsdf(m, wo, wi) != pytest.approx([f] * 3, rel=1e-3)


@pytest.mark.parametrize("lobe", slow_except(["reflection", "refraction"], "refraction"))
def test_a_pdf_without_the_sampled_directions_dot_m_fails_the_chi2_test(
    slow_outcomes, request, lobe
):
    """The Jacobians' |wo.m| (reflection) and |wi.m| (refraction), the dot product of
    the sampled direction with the facet normal in Walter et al.'s notation."""
    assert not outcome(slow_outcomes, request)


class InvertedScaling(RoughDielectric):
    """Refraction scaled by n_i^2 instead of n_o^2: the BSDF for importance, not for
    radiance."""

    def BRDF(self, ray_view, ray_light, hit):
        f = super().BRDF(ray_view, ray_light, hit)
        if dot(hit.normal, ray_light.direction) < 0.0:
            f = f * self.eta(hit) ** 2
        return f


def test_the_transport_direction_is_checked():
    """The sampler weighs its samples with its own BSDF, so the chi2 and weights checks
    cannot see which direction radiance flows; reciprocity across the surface can."""
    m = InvertedScaling(1.5, 0.394)
    assert check_weights(m, 30.0, n=300)
    assert not check_reciprocity(m, n_pairs=200, ior=1.5)


# --- check_material: the "done when" ---------------------------------------------


CHECKED_ANGLES = (0.0, 45.0, 80.0, 89.9)


def check_glass(name: str) -> MaterialReport:
    """check_material on a lecture glass from both sides, 50,000 samples per angle."""
    return check_material(glass(name), incident_angles=CHECKED_ANGLES, n_samples=50_000)


# node id -> the outcome of each selected test's heavy part, all of them on every core,
# the longest (the glasses, then the losses) first.
slow_outcomes = module_outcomes(
    {
        "test_check_material_passes_the_lecture_glasses": check_glass,
        "test_the_light_lost_is_what_the_facets_block": loss_outcome,
        "test_scattering_draws_the_pdf_and_weighs_by_it": sampling_outcome,
        "test_a_jacobian_without_eta_squared_fails_the_chi2_test": (
            chi2_passes_without_eta_squared
        ),
        "test_a_pdf_without_the_sampled_directions_dot_m_fails_the_chi2_test": (
            chi2_passes_without_the_dot_m
        ),
    }
)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(GLASSES))
def test_check_material_passes_the_lecture_glasses(slow_outcomes, request, name):
    angles = CHECKED_ANGLES
    report = outcome(slow_outcomes, request)
    assert report.passed, str(report)
    sides = [(c.incident_deg, c.inside) for c in report.checks if c.check == "chi2"]
    assert sides == [(t, inside) for inside in (False, True) for t in angles]
    text = str(report)
    assert "across the surface with ior 1.5" in text and "finite >= 0   all in" in text
    assert "transmitted" in text and "lost" in text
