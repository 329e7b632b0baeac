"""Tests for rtpy.materials.OrenNayar (qualitative model).

Expected values come from the formula with explicit angles, computed here in
world coordinates, not from the code under test:

    f_r = albedo / pi * (A + B * max(0, cos(phi_i - phi_o)) * sin(alpha) * tan(beta))
    A = 1 - 0.5 s^2 / (s^2 + 0.33),  B = 0.45 s^2 / (s^2 + 0.09),  s = radians(sigma)
    alpha = max(theta_i, theta_o),  beta = min(theta_i, theta_o)
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtpy.io.scene_file import SceneError
from rtpy.materials import Lambertian, OrenNayar
from rtpy.sampling import make_generator, use_generator
from rtpy.vec3 import Color

from ..cores import module_outcomes, outcome
from ..vectors import dot3
from .directions import (
    ALBEDO,
    NORMAL,
    brdf,
    check_defaults,
    check_finite,
    check_nothing_below,
    check_scattering,
    direction,
    light_ray,
    load_material,
    make_hit,
    phis,
    thetas,
    view_ray,
)


def coefficients(sigma_deg):
    s2 = math.radians(sigma_deg) ** 2
    return 1.0 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09)


def expected_factor(sigma, wo, wi, normal=NORMAL):
    """A + B * max(0, cos(phi_i - phi_o)) * sin(alpha) * tan(beta), with explicit angles."""
    a, b = coefficients(sigma)
    po = [wo[k] - dot3(wo, normal) * normal[k] for k in range(3)]  # projections onto
    pi_ = [wi[k] - dot3(wi, normal) * normal[k] for k in range(3)]  # the tangent plane
    lo, li = math.sqrt(dot3(po, po)), math.sqrt(dot3(pi_, pi_))
    # atan2 rather than acos: accurate for angles near 0 too
    theta_o, theta_i = math.atan2(lo, dot3(wo, normal)), math.atan2(li, dot3(wi, normal))
    if lo < 1e-12 or li < 1e-12:
        return a  # one direction along the normal: beta = 0, tan(beta) = 0
    cos_dphi = dot3(po, pi_) / (lo * li)
    alpha, beta = max(theta_i, theta_o), min(theta_i, theta_o)
    return a + b * max(0.0, cos_dphi) * math.sin(alpha) * math.tan(beta)


def expected_brdf(sigma, wo, wi, normal=NORMAL):
    if dot3(wo, normal) <= 0.0 or dot3(wi, normal) <= 0.0:
        return [0.0, 0.0, 0.0]
    k = expected_factor(sigma, wo, wi, normal) / math.pi
    return [a * k for a in ALBEDO]


sigmas = st.one_of(st.sampled_from([0.0, 10.0, 20.0, 45.0]), st.floats(0.0, 89.9))


# --- BRDF and pdf ---------------------------------------------------------------------


@given(sigmas, thetas, phis, thetas, phis)
def test_brdf_and_pdf_match_the_formula(sigma, to, po, ti, pi_):
    m = OrenNayar(Color(*ALBEDO), sigma=sigma)
    hit = make_hit(m)
    wo, wi = direction(NORMAL, to, po), direction(NORMAL, ti, pi_)
    f = m.BRDF(view_ray(wo), light_ray(wi), hit)
    assert f.tolist() == pytest.approx(expected_brdf(sigma, wo, wi), rel=1e-8, abs=1e-12)
    p = m.pdf(view_ray(wo), light_ray(wi), hit)
    assert p == pytest.approx(dot3(wi, NORMAL) / math.pi, rel=1e-12, abs=1e-15)


@given(sigmas, thetas, phis, st.floats(90.001, 180.0), phis)
def test_zero_below_the_surface(sigma, to, po, ti, pi_):
    m = OrenNayar(Color(*ALBEDO), sigma=sigma)
    check_nothing_below(m, direction(NORMAL, to, po), direction(NORMAL, ti, pi_))


@given(sigmas, thetas, phis, thetas, phis)
def test_reciprocity(sigma, ta, pa, tb, pb):
    m = OrenNayar(Color(*ALBEDO), sigma=sigma)
    a, b = direction(NORMAL, ta, pa), direction(NORMAL, tb, pb)
    assert brdf(m, a, b) == pytest.approx(brdf(m, b, a), rel=1e-12)


def test_rough_surfaces_look_flatter():
    """Back-lit (light behind the viewer) and toward the rim, a rough surface reflects
    more than a Lambertian one; lit from the side opposite the viewer, less."""
    m = OrenNayar(Color(*ALBEDO), sigma=30.0)
    hit = make_hit(m)
    lambert = ALBEDO[0] / math.pi
    wo = direction(NORMAL, 70.0, 0.0)
    retro = m.BRDF(view_ray(wo), light_ray(wo), hit).e0
    opposite = m.BRDF(view_ray(wo), light_ray(direction(NORMAL, 70.0, 180.0)), hit).e0
    assert retro > lambert > opposite
    a, b = coefficients(30.0)
    assert opposite == pytest.approx(a * lambert, rel=1e-12)
    assert retro == pytest.approx(
        lambert * (a + b * math.sin(1.2217304763960306) ** 2 / math.cos(1.2217304763960306)),
        rel=1e-9,
    )


# --- sigma = 0 is Lambertian ----------------------------------------------------------


def test_sigma_zero_is_exactly_lambertian():
    on = OrenNayar(Color(*ALBEDO), sigma=0.0)
    lam = Lambertian(Color(*ALBEDO))
    assert (on.A, on.B) == (1.0, 0.0)
    hit = make_hit(on)
    for to, po, ti, pi_ in [(0, 0, 30, 0), (45, 10, 60, 190), (80, 0, 80, 0), (89.99, 5, 12, 7)]:
        wo, wi = direction(NORMAL, to, po), direction(NORMAL, ti, pi_)
        assert on.BRDF(view_ray(wo), light_ray(wi), hit) == lam.BRDF(
            view_ray(wo), light_ray(wi), hit
        )
        assert on.pdf(view_ray(wo), light_ray(wi), hit) == lam.pdf(view_ray(wo), light_ray(wi), hit)
    wo = direction(NORMAL, 35.0, 40.0)
    with use_generator(make_generator(21)) as g1:
        ours = [on.scattering(view_ray(wo), hit) for _ in range(200)]
    with use_generator(make_generator(21)) as g2:
        theirs = [lam.scattering(view_ray(wo), hit) for _ in range(200)]
    assert g1.random() == g2.random()  # both drew the same random numbers
    for s, t in zip(ours, theirs, strict=True):
        assert s.attenuation == t.attenuation
        assert s.pdf == t.pdf
        assert s.scattered_ray.direction.tolist() == pytest.approx(
            t.scattered_ray.direction.tolist(), abs=1e-12
        )


# --- sampling -------------------------------------------------------------------------


@pytest.mark.parametrize("sigma", [0.0, 20.0, 60.0, 89.0])
@pytest.mark.parametrize("theta_o", [0.0, 45.0, 85.0, 89.99])
@pytest.mark.slow
def test_scattering_weight_is_brdf_cos_over_pdf(heavy, request, sigma, theta_o):
    n = 2000
    cosines = outcome(heavy, request)
    assert len(cosines) == n  # nothing is absorbed
    cos_sum = sum(cosines)
    # Cosine-weighted: E[cos] = 2/3, variance 1/2 - 4/9.
    assert abs(cos_sum / n - 2 / 3) < 5 * math.sqrt((0.5 - 4 / 9) / n)


def check_weights(sigma: float, theta_o: float) -> list[float]:
    """check_scattering of 2000 samples; the cosines of those reflected."""
    m = OrenNayar(Color(*ALBEDO), sigma=sigma)
    wo = direction(NORMAL, theta_o, 75.0)
    brdf = partial(expected_brdf, sigma, wo)
    return check_scattering(
        m, wo, brdf, lambda wi: dot3(wi, NORMAL) / math.pi, 2000, (5, int(theta_o))
    )


# --- energy ---------------------------------------------------------------------------


def expected_albedo_factor(sigma, theta_o_deg):
    """Directional albedo / albedo = A + (2 B / pi) * integral over theta_i of
    sin(alpha) tan(beta) cos(theta_i) sin(theta_i) (the azimuth integral of
    max(0, cos(dphi)) is 2), done here in one dimension with explicit angles."""
    a, b = coefficients(sigma)
    to = math.radians(theta_o_deg)
    t = np.linspace(0.0, 0.5 * math.pi, 200_001)
    integrand = np.sin(np.maximum(t, to)) * np.tan(np.minimum(t, to)) * np.cos(t) * np.sin(t)
    return a + 2.0 * b / math.pi * float(np.trapezoid(integrand, t))


GL_X, GL_W = np.polynomial.legendre.leggauss(16)


def hemisphere_integral(f, theta_breaks, phi_breaks):
    """Integral of f(theta, phi) sin(theta) over cells [theta] x [phi] (Gauss-Legendre)."""
    total = 0.0
    for t0, t1 in zip(theta_breaks[:-1], theta_breaks[1:], strict=True):
        ht = 0.5 * (t1 - t0)
        for x, wx in zip(GL_X, GL_W, strict=True):
            t = t0 + ht * (x + 1.0)
            for p0, p1 in zip(phi_breaks[:-1], phi_breaks[1:], strict=True):
                hp = 0.5 * (p1 - p0)
                for y, wy in zip(GL_X, GL_W, strict=True):
                    total += wx * wy * ht * hp * f(t, p0 + hp * (y + 1.0)) * math.sin(t)
    return total


@pytest.mark.parametrize("sigma", [10.0, 20.0, 60.0])
@pytest.mark.parametrize("theta_o", [0.0, 30.0, 70.0, 89.99])
def test_directional_albedo(heavy, request, sigma, theta_o):
    """The integral of BRDF * cos over the hemisphere: A * albedo at normal incidence,
    rising toward (A + B / 2) * albedo at grazing. The qualitative model does not
    conserve energy exactly: for small sigma, A + B / 2 is a little above 1."""
    value = outcome(heavy, request)
    assert value == pytest.approx(expected_albedo_factor(sigma, theta_o), rel=1e-6)
    a, b = coefficients(sigma)
    if theta_o == 0.0:
        assert value == pytest.approx(a, rel=1e-9)
    assert a - 1e-9 <= value <= a + 0.5 * b + 1e-6


def albedo_by_quadrature(sigma: float, theta_o: float) -> float:
    """The directional albedo of a white Oren-Nayar surface, by Gauss-Legendre cells
    between the kinks of the integrand."""
    m = OrenNayar(Color(1.0, 1.0, 1.0), sigma=sigma)
    hit = make_hit(m)
    wo = direction(NORMAL, theta_o, 0.0)

    def f_cos(theta, phi):
        wi = direction(NORMAL, math.degrees(theta), math.degrees(phi))
        return m.BRDF(view_ray(wo), light_ray(wi), hit).e0 * math.cos(theta)

    to = math.radians(theta_o)
    theta_breaks = sorted({0.0, to, 0.5 * math.pi, *(k * math.pi / 12 for k in range(7))})
    phi_breaks = [k * math.pi / 4 for k in range(9)]  # kinks of max(0, cos) at pi/2, 3 pi/2
    return hemisphere_integral(f_cos, theta_breaks, phi_breaks)


# node id -> the sampling and quadratures of each selected test, on every core.
heavy = module_outcomes(
    {
        "test_scattering_weight_is_brdf_cos_over_pdf": check_weights,
        "test_directional_albedo": albedo_by_quadrature,
    }
)


# --- extremes -------------------------------------------------------------------------


@pytest.mark.parametrize("sigma", [0.0, 20.0, 89.9])
@pytest.mark.parametrize("normal", [NORMAL, (0.0, 0.0, 1.0)])
def test_grazing_angles_give_finite_values(sigma, normal):
    m = OrenNayar(Color(*ALBEDO), sigma=sigma)
    hit = make_hit(m, normal)
    grazing = [direction(normal, 89.99, p) for p in (0.0, 0.01, 90.0, 180.0)]
    if normal[2] == 1.0:  # 1e-300 above the surface, and 1e-300 at another azimuth
        grazing += [(1.0, 0.0, 1e-300), (0.6, 0.8, 1e-300)]
    lights = [*grazing, direction(normal, 30.0, 0.0)]
    check_finite(m, [(wo, lights) for wo in [*grazing, direction(normal, 0.0, 0.0)]], 200, normal)
    # Both at 89.99 degrees, same azimuth: the formula's large but finite value.
    wo = direction(normal, 89.99, 0.0)
    f = m.BRDF(view_ray(wo), light_ray(wo), hit).e0
    a, b = coefficients(sigma)
    t = math.radians(89.99)
    assert f == pytest.approx(ALBEDO[0] / math.pi * (a + b * math.sin(t) * math.tan(t)), rel=1e-6)


# --- construction and loading ---------------------------------------------------------


def test_defaults_and_registration():
    check_defaults(OrenNayar, "oren_nayar", sigma=20.0)


@pytest.mark.parametrize("sigma", [-1.0, -1e-9, 90.0, 95.0, math.nan, math.inf, "20", True])
def test_constructor_refuses_bad_sigma(sigma):
    with pytest.raises(
        (TypeError, ValueError), match=r"^sigma: expected a (finite )?number in \[0, 90\)"
    ):
        OrenNayar(Color(*ALBEDO), sigma=sigma)


def test_the_loader_accepts_an_oren_nayar_material():
    keys = 'type = "oren_nayar"\nalbedo = [0.6, 0.45, 0.3]\nsigma = 35'
    m = load_material(keys, "clay")
    assert isinstance(m, OrenNayar)
    assert m.albedo.color == Color(0.6, 0.45, 0.3)
    assert m.sigma == 35.0
    assert load_material(keys.replace("\nsigma = 35", ""), "clay").sigma == 20.0
    with pytest.raises(SceneError, match=r"clay.toml: \[materials.clay\] sigma: .*\[0, 90\)"):
        load_material(keys.replace("sigma = 35", "sigma = 90"), "clay")
