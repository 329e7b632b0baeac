"""Tests for rtpy.materials.Ward: the anisotropic BRDF, its density, samples and energy.

Expected values come from the formulas of the scene-format contract and Walter's
2005 notes, written out again here with angles in world coordinates (theta_h =
acos(n . h), phi_h = atan2(h . b, h . t) in the frame t = the surface's u
direction, b = n x t), not from the code under test:

    f_r = kd * albedo / pi
        + ks * exp(-tan^2(theta_h) (cos^2(phi_h) / ax^2 + sin^2(phi_h) / ay^2))
             / (4 pi ax ay sqrt(cos(theta_i) cos(theta_o)))
    p_h = exp(-tan^2(theta_h) (cos^2(phi_h) / ax^2 + sin^2(phi_h) / ay^2))
          / (pi ax ay cos^3(theta_h))
    pdf = p_d cos(theta_i) / pi + (1 - p_d) p_h / (4 (wo . h))

with p_d = kd * max(albedo) / (kd * max(albedo) + ks). Integrals (the
normalisation of p_h, the directional albedo) are computed by Gauss-Legendre
quadrature in theta and the trapezoidal rule in phi.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from rtpy._checks import ROUGHNESS
from rtpy.materials import Ward
from rtpy.onb import ONB
from rtpy.vec3 import Color, Vec3

from ..cores import module_outcomes, outcome
from ..tiers import slow_except
from ..vectors import angle, cross3, dot3, unit3
from . import directions
from .directions import (
    ALBEDO,
    BAD_STRENGTHS,
    X,
    Z,
    half_vector_albedo,
    hemisphere_integral,
    light_ray,
    mixture_pdf,
    view_ray,
)

# A tilted surface with its own tangent: the highlight is anisotropic.
NORMAL = unit3((-0.2, 0.9, 0.4))
TANGENT = unit3(cross3(NORMAL, (1.0, 0.0, 0.0)))
BITANGENT = cross3(NORMAL, TANGENT)
AXES = ONB.from_normal_tangent(Vec3(*Z), Vec3(*X))  # the axis-aligned shading frame


def direction(theta: float, phi: float, normal=NORMAL, tangent=TANGENT):
    """World direction at polar angle theta from the normal, azimuth phi from the tangent."""
    return directions.polar(theta, phi, normal, tangent)


def make_hit(material, normal=NORMAL, tangent=TANGENT):
    return directions.make_hit(material, normal, tangent)


def brdf(m, wo, wi, normal=NORMAL, tangent=TANGENT) -> list[float]:
    return directions.brdf(m, wo, wi, normal, tangent)


def pdf(m, wo, wi, normal=NORMAL, tangent=TANGENT) -> float:
    return directions.pdf(m, wo, wi, normal, tangent)


# --- the reference formulas ------------------------------------------------------------


def ref_exponent(ax, ay, h, normal=NORMAL, tangent=TANGENT) -> float:
    b = cross3(normal, tangent)
    theta_h = angle(normal, h)
    phi_h = math.atan2(dot3(h, b), dot3(h, tangent))
    return math.tan(theta_h) ** 2 * (math.cos(phi_h) ** 2 / ax**2 + math.sin(phi_h) ** 2 / ay**2)


def ref_specular(ax, ay, wo, wi, tangent=TANGENT) -> float:
    ci, co = dot3(NORMAL, wi), dot3(NORMAL, wo)
    if ci <= 0.0 or co <= 0.0:
        return 0.0
    h = unit3(tuple(wi[k] + wo[k] for k in range(3)))
    e = ref_exponent(ax, ay, h, tangent=tangent)
    return math.exp(-e) / (4.0 * math.pi * ax * ay * math.sqrt(ci * co))


def ref_brdf(kd, ks, ax, ay, wo, wi) -> list[float]:
    if dot3(NORMAL, wi) <= 0.0 or dot3(NORMAL, wo) <= 0.0:
        return [0.0, 0.0, 0.0]
    spec = ref_specular(ax, ay, wo, wi)
    return [kd * ALBEDO[k] / math.pi + ks * spec for k in range(3)]


def ref_p_h(ax, ay, h, normal=NORMAL, tangent=TANGENT) -> float:
    theta_h = angle(normal, h)
    if theta_h >= math.pi / 2:
        return 0.0
    e = ref_exponent(ax, ay, h, normal, tangent)
    return math.exp(-e) / (math.pi * ax * ay * math.cos(theta_h) ** 3)


def ref_pdf(kd, ks, ax, ay, wo, wi) -> float:
    ci = dot3(NORMAL, wi)
    if ci <= 0.0 or dot3(NORMAL, wo) <= 0.0:
        return 0.0
    h = unit3(tuple(wi[k] + wo[k] for k in range(3)))
    return mixture_pdf(kd, ks, ci, ref_p_h(ax, ay, h) / (4.0 * dot3(wo, h)))


def albedo_by_quadrature(m: Ward, theta_o: float, phi_o: float = 0.0, n_phi: int = 128):
    """Directional albedo of a Ward material with kd = 0 (so of its lobe, ks included)."""
    s = math.sin(theta_o)
    wo = (s * math.cos(phi_o), s * math.sin(phi_o), math.cos(theta_o))
    return half_vector_albedo(m, wo, min(m.ax, m.ay), n_phi)


# --- the BRDF is the formula -------------------------------------------------------------

polar = st.floats(0.0, math.radians(89.5))
azimuths = st.floats(0.0, 2.0 * math.pi)
widths = st.floats(0.01, 1.0)


@given(
    st.floats(0.0, 1.0),
    st.floats(0.0, 1.0),
    widths,
    st.one_of(st.none(), widths),
    polar,
    azimuths,
    polar,
    azimuths,
)
def test_brdf_and_pdf_match_the_formulas(kd, ks, ax, ay, to, po, ti, pi_):
    m = Ward(Color(*ALBEDO), kd, ks, ax, ay)
    ay_used = ax if ay is None else ay
    wo, wi = direction(to, po), direction(ti, pi_)
    expected = ref_brdf(kd, ks, ax, ay_used, wo, wi)
    assert brdf(m, wo, wi) == pytest.approx(expected, rel=1e-9, abs=1e-300)
    assume(kd + ks > 0.0)
    assert pdf(m, wo, wi) == pytest.approx(
        ref_pdf(kd, ks, ax, ay_used, wo, wi), rel=1e-9, abs=1e-300
    )


@given(widths, widths, polar, azimuths, polar, azimuths)
def test_turning_the_tangent_by_90_degrees_swaps_alpha_x_and_alpha_y(ax, ay, to, po, ti, pi_):
    """phi_h is measured from the surface's u direction: with the tangent turned by 90
    degrees (to b = n x t), alpha_x acts along what was y, so Ward(ax, ay) on the turned
    frame is Ward(ay, ax) on the original one."""
    wo, wi = direction(to, po), direction(ti, pi_)
    turned = BITANGENT
    a = Ward(Color(*ALBEDO), 0.3, 1.0, ax, ay)
    b = Ward(Color(*ALBEDO), 0.3, 1.0, ay, ax)
    assert brdf(a, wo, wi, tangent=turned) == pytest.approx(brdf(b, wo, wi), rel=1e-9)
    assert pdf(a, wo, wi, tangent=turned) == pytest.approx(pdf(b, wo, wi), rel=1e-9)
    # And both are the formula with phi_h measured from the turned tangent.
    expected = ref_specular(ax, ay, wo, wi, tangent=turned)
    assert a.BRDF(view_ray(wo), light_ray(wi), make_hit(a, tangent=turned)).e0 == pytest.approx(
        0.3 * ALBEDO[0] / math.pi + expected, rel=1e-9
    )


def test_the_highlight_is_stretched_along_the_rougher_axis():
    """alpha_x = 0.4, alpha_y = 0.05: moving the light away from the mirror direction
    along x keeps much more of the highlight than moving it as far along y."""
    m = Ward(Color(*ALBEDO), 0.0, 1.0, 0.4, 0.05)
    wo = direction(0.0, 0.0)
    along_x, along_y = direction(0.3, 0.0), direction(0.3, math.pi / 2)
    fx, fy = brdf(m, wo, along_x)[0], brdf(m, wo, along_y)[0]
    assert fx == pytest.approx(ref_specular(0.4, 0.05, wo, along_x), rel=1e-12)
    assert fy == pytest.approx(ref_specular(0.4, 0.05, wo, along_y), rel=1e-12)
    assert fx > 1e3 * fy  # exp(-tan^2(0.15) / 0.4^2) against exp(-tan^2(0.15) / 0.05^2)
    # With the tangent turned by 90 degrees the streak turns with it.
    assert brdf(m, wo, along_y, tangent=BITANGENT)[0] == pytest.approx(fx, rel=1e-12)
    # The mirror direction (h = n) is the peak: 1 / (4 pi ax ay cos(theta_o)).
    wo, wi = direction(0.6, 1.0), direction(0.6, 1.0 + math.pi)
    peak = 1.0 / (4.0 * math.pi * 0.4 * 0.05 * math.cos(0.6))
    assert brdf(m, wo, wi)[0] == pytest.approx(peak, rel=1e-12)


@given(widths, widths, polar, azimuths, polar, azimuths)
def test_zero_below_the_surface(ax, ay, to, po, ti, pi_):
    m = Ward(Color(*ALBEDO), 0.5, 1.0, ax, ay)
    wo, wi = direction(to, po), direction(ti, pi_)
    below_i = tuple(-x for x in wi)
    directions.check_nothing_below(m, wo, below_i, NORMAL, TANGENT)
    assert m.half_vector_pdf(make_hit(m).frame, Vec3(*below_i)) == 0.0


@given(widths, widths, polar, azimuths, polar, azimuths)
def test_reciprocity(ax, ay, ta, pa, tb, pb):
    m = Ward(Color(*ALBEDO), 0.3, 1.0, ax, ay)
    wa, wb = direction(ta, pa), direction(tb, pb)
    assert brdf(m, wa, wb) == pytest.approx(brdf(m, wb, wa), rel=1e-12, abs=1e-300)


# --- the half-vector density and its sampler ---------------------------------------------

WIDTH_PAIRS = [(0.001, 0.001), (0.05, 0.05), (0.2, 0.2), (0.05, 0.4), (1.0, 0.1), (0.5, 1.0)]


@pytest.mark.parametrize("ax, ay", WIDTH_PAIRS)
def test_the_half_vector_density_is_normalised(heavy, request, ax, ay):
    assert outcome(heavy, request) == pytest.approx(1.0, abs=1e-6)


def half_vector_density_integral(ax: float, ay: float) -> float:
    m = Ward(alpha_x=ax, alpha_y=ay)

    def integrand(t, p):
        s = math.sin(t)
        return m.half_vector_pdf(AXES, Vec3(s * math.cos(p), s * math.sin(p), math.cos(t)))

    return hemisphere_integral(integrand, min(ax, ay), n_phi=256)


@pytest.mark.parametrize("ax, ay", WIDTH_PAIRS)
def test_the_half_vector_density_is_the_formula(ax, ay):
    m = Ward(alpha_x=ax, alpha_y=ay)
    for theta in np.linspace(0.0, 1.5, 16):
        for phi in np.linspace(0.0, 2.0 * math.pi, 13):
            h = direction(theta, phi, Z, X)
            assert m.half_vector_pdf(AXES, Vec3(*h)) == pytest.approx(
                ref_p_h(ax, ay, h, Z, X), rel=1e-9, abs=1e-300
            )


@pytest.mark.parametrize("ax, ay", WIDTH_PAIRS)
def test_the_sampler_inverts_walters_cdf(ax, ay):
    """Walter's inversion: exp(-slope exponent of h) = 1 - r1, and
    tan(phi_h) = (ay / ax) tan(2 pi r2) with phi_h in the quadrant of 2 pi r2."""
    m = Ward(alpha_x=ax, alpha_y=ay)
    for r1 in (0.0, 0.1, 0.5, 0.9, 0.999):
        for r2 in (0.05, 0.2, 0.3, 0.45, 0.55, 0.7, 0.8, 0.95):
            h = m.sample_half_vector(r1, r2).tolist()
            assert dot3(h, h) == pytest.approx(1.0, abs=1e-12)
            assert h[2] > 0.0
            if r1 == 0.0:
                assert h == pytest.approx((0.0, 0.0, 1.0), abs=1e-12)
                continue
            assert math.exp(-ref_exponent(ax, ay, h, Z, X)) == pytest.approx(1.0 - r1, rel=1e-9)
            phi = math.atan2(h[1], h[0])
            assert math.tan(phi) == pytest.approx(ay / ax * math.tan(2 * math.pi * r2), rel=1e-9)
            quadrant = int(r2 * 4.0)  # 0..3: the quadrant of 2 pi r2
            assert int((phi % (2.0 * math.pi)) / (math.pi / 2)) == quadrant


@pytest.mark.parametrize(
    "kd, ks, ax, ay, theta_o",
    [
        (0.7, 0.6, 0.2, 0.2, 0.4),
        (0.0, 1.0, 0.05, 0.4, 1.2),
        (1.0, 0.2, 1.0, 0.3, 0.0),
        (0.0, 1.0, 0.5, 0.5, 1.55),
    ],
)
def test_scattering_weight_is_brdf_cos_over_pdf(kd, ks, ax, ay, theta_o):
    m = Ward(Color(*ALBEDO), kd, ks, ax, ay)
    wo = direction(theta_o, 0.8)
    brdf_of, pdf_of = partial(ref_brdf, kd, ks, ax, ay, wo), partial(ref_pdf, kd, ks, ax, ay, wo)
    seed = (5, int(ax * 100), int(theta_o * 100))
    directions.check_scattering(m, wo, brdf_of, pdf_of, 400, seed, NORMAL, TANGENT)


@pytest.mark.parametrize(
    "ax, ay, theta_o_deg, phi_o",
    [
        (0.05, 0.05, 30.0, 0.0),
        (0.2, 0.2, 0.0, 0.0),
        (0.2, 0.2, 70.0, 0.0),
        (0.05, 0.4, 45.0, 0.0),
        (0.05, 0.4, 45.0, math.pi / 2),
        (1.0, 0.5, 60.0, 1.0),
    ],
)
@pytest.mark.slow
def test_mean_sample_weight_is_the_albedo_by_quadrature(heavy, request, ax, ay, theta_o_deg, phi_o):
    """The mean of BRDF * cos / pdf over the sampler's directions (absorbed samples
    count 0) is the directional albedo exactly when the sampler draws with the
    density pdf() claims."""
    outcome(heavy, request)


def check_mean_weight_against_quadrature(ax: float, ay: float, theta_o_deg: float, phi_o: float):
    m = Ward(kd=0.0, ks=1.0, alpha_x=ax, alpha_y=ay)
    t_o = math.radians(theta_o_deg)
    expected = albedo_by_quadrature(m, t_o, phi_o, n_phi=256)
    seed = (13, int(ax * 100), int(theta_o_deg), int(phi_o * 10))
    wo = direction(t_o, phi_o)
    directions.check_mean_weight(m, wo, expected, 6000, seed, NORMAL, TANGENT)


# --- numerics at the extremes --------------------------------------------------------------


@pytest.mark.parametrize(
    "ax, ay", [(ROUGHNESS.lo, ROUGHNESS.lo), (0.001, 0.001), (0.001, 1.0), (1.0, 1.0)]
)
def test_tiny_widths_and_grazing_angles_give_finite_values(ax, ay):
    m = Ward(Color(*ALBEDO), 0.2, 1.0, ax, ay)
    pairs = directions.extreme_pairs(
        (0.0, 0.3, math.pi / 2, math.pi - 1e-7, math.pi), NORMAL, TANGENT
    )
    directions.check_finite(m, pairs, 50, NORMAL, TANGENT)
    for r1 in (0.0, 1e-300, 0.5, 1.0 - 2.0**-53):
        for r2 in (0.0, 0.25, 0.5, 0.75, 1.0 - 2.0**-53):
            h = m.sample_half_vector(r1, r2).tolist()
            assert all(math.isfinite(x) for x in h) and h[2] >= 0.0
    # cos = 1e-12 on one side: large (1 / sqrt(cos)) but finite; on both sides too.
    grazing = (math.sqrt(1.0 - 1e-24), 0.0, 1e-12)
    for wi in ((-0.6, 0.0, 0.8), (-grazing[0], 0.0, 1e-12), (0.0, grazing[0], 1e-12)):
        f = brdf(m, grazing, wi, Z, X)[0]
        assert math.isfinite(f) and f >= 0.0
        assert math.isfinite(pdf(m, grazing, wi, Z, X))


def test_the_lobe_at_grazing_angles_is_large_but_finite():
    """Light and viewer both 1e-12 above the horizon, opposite each other: h = n, the
    exponent is 0 and f = 1 / (4 pi ax ay 1e-12)."""
    m = Ward(kd=0.0, ks=1.0, alpha_x=0.2)
    c = 1e-12
    s = math.sqrt(1.0 - c * c)
    assert brdf(m, (s, 0.0, c), (-s, 0.0, c), Z, X)[0] == pytest.approx(
        1.0 / (4.0 * math.pi * 0.04 * c), rel=1e-9
    )


# --- energy --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "ax, ay",
    slow_except([(0.05, 0.05), (0.2, 0.2), (0.5, 0.5), (1.0, 1.0), (0.05, 0.4)], (0.05, 0.4)),
)
def test_the_lobe_reflects_at_most_everything_away_from_the_horizon(heavy, request, ax, ay):
    """kd = 0, ks = 1: the directional albedo is <= 1 for views up to 89 degrees."""
    albedos = outcome(heavy, request)
    for value in albedos:
        assert 0.0 < value <= 1.0
    if ax == ay == 0.05:
        assert albedos[0] == pytest.approx(1.0, abs=0.01)  # narrow lobes: nearly ks head-on
        # ... and about cos(theta_o) at an angle (Ward's 1 / sqrt(cos cos) normalisation).
        assert albedos[1] == pytest.approx(math.cos(math.radians(30.0)), abs=0.01)


def lobe_albedos(ax: float, ay: float) -> list[float]:
    """The lobe's directional albedo (kd = 0, ks = 1) at 0, 30, 60, 80 and 89 degrees."""
    m = Ward(kd=0.0, ks=1.0, alpha_x=ax, alpha_y=ay)
    return [albedo_by_quadrature(m, math.radians(t)) for t in (0.0, 30.0, 60.0, 80.0, 89.0)]


# node id -> the quadratures and sampling of each selected test, on every core, the
# longest first.
heavy = module_outcomes(
    {
        "test_mean_sample_weight_is_the_albedo_by_quadrature": (
            check_mean_weight_against_quadrature
        ),
        "test_the_lobe_reflects_at_most_everything_away_from_the_horizon": lobe_albedos,
        "test_the_half_vector_density_is_normalised": half_vector_density_integral,
    }
)


def test_wards_normalisation_exceeds_1_at_the_horizon():
    """Documents a property of Ward's original model (not a bug of this code): the
    factor 1 / sqrt(cos(theta_o)) makes the albedo grow without bound as the viewer
    approaches the horizon."""
    m = Ward(kd=0.0, ks=1.0, alpha_x=0.5)
    assert albedo_by_quadrature(m, math.radians(89.99)) > 1.5


# --- construction and scene files ----------------------------------------------------------


def test_defaults_and_registration():
    directions.check_defaults(Ward, "ward", kd=1.0, ks=0.0, alpha_x=0.2, alpha_y=0.2)
    assert Ward(alpha_x=0.3).alpha_y == 0.3
    assert Ward(alpha_x=0.3, alpha_y=0.1).alpha_y == 0.1


@pytest.mark.parametrize(
    "kwargs, message",
    [
        *BAD_STRENGTHS,
        ({"alpha_x": 0.0}, "alpha_x"),
        ({"alpha_x": -0.1}, "alpha_x"),
        ({"alpha_x": 1.5}, "alpha_x"),
        ({"alpha_x": math.nan}, "alpha_x"),
        ({"alpha_y": 0.0}, "alpha_y"),
        ({"alpha_y": 2.0}, "alpha_y"),
        ({"alpha_y": math.inf}, "alpha_y"),
    ],
)
def test_constructor_refuses_bad_parameters(kwargs, message):
    with pytest.raises((TypeError, ValueError), match=message):
        Ward(**kwargs)


def load_ward(keys: str) -> Ward:
    return directions.load_material(f'type = "ward"\n{keys}', "brushed")


def test_the_loader_reads_ward_with_and_without_alpha_y():
    m = load_ward("")
    assert isinstance(m, Ward)
    assert (m.kd, m.ks, m.alpha_x, m.alpha_y) == (1.0, 0.0, 0.2, 0.2)
    m = load_ward("albedo = [0.2, 0.2, 0.25]\nkd = 0.1\nks = 1\nalpha_x = 0.05")
    assert (m.kd, m.ks, m.alpha_x, m.alpha_y) == (0.1, 1.0, 0.05, 0.05)
    m = load_ward("ks = 1\nalpha_x = 0.4\nalpha_y = 0.05")
    assert (m.alpha_x, m.alpha_y) == (0.4, 0.05)


@pytest.mark.parametrize(
    "keys, words",
    [
        ("alpha_x = 0", ["alpha_x", "in [0.0001, 1]"]),
        ("alpha_y = -0.1", ["alpha_y", "in [0.0001, 1]"]),
        ("alpha_y = 3", ["alpha_y", "in [0.0001, 1]"]),
        ('alpha_y = "x"', ["alpha_y"]),
        ("alpha = 0.1", ["did you mean"]),
        ("roughness = 0.1", ["unknown key"]),
    ],
)
def test_the_loader_refuses_bad_values(keys, words):
    directions.check_refused("ward", keys, words, "brushed")
