"""Tests for rtpy.materials.BlinnPhong: the BRDF, its density, its samples and its energy.

Expected values come from the formulas, written out again here in world
coordinates, not from the code under test:

    f_r = kd * albedo / pi + ks * (n + 8) / (8 pi) * max(0, n . h)^n,  h = normalize(wi + wo)
    pdf = p_d * cos(theta_i) / pi + (1 - p_d) * (n + 1) / (2 pi) * (n . h)^n / (4 (wo . h))

with p_d = kd * max(albedo) / (kd * max(albedo) + ks).
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import rtpy
from rtpy.io.scene_file import SceneError
from rtpy.materials import Blinn, BlinnPhong
from rtpy.sampling import make_generator, use_generator
from rtpy.vec3 import Color

from ..cores import module_outcomes, outcome
from ..tiers import slow_except
from ..vectors import dot3
from . import directions
from .directions import ALBEDO, NORMAL, direction, half, light_ray, make_hit, mirror, view_ray
from .directions import brdf as model_brdf
from .directions import pdf as model_pdf

thetas, phis, weights = directions.thetas, directions.phis, directions.weights

# --- the formulas ---------------------------------------------------------------------


def expected_brdf(kd, ks, n, wo, wi, normal=NORMAL):
    if dot3(wo, normal) <= 0.0 or dot3(wi, normal) <= 0.0:
        return [0.0, 0.0, 0.0]
    spec = (n + 8.0) / (8.0 * math.pi) * max(0.0, dot3(normal, half(wo, wi))) ** n
    return [kd * a / math.pi + ks * spec for a in ALBEDO]


def expected_pdf(kd, ks, n, wo, wi, normal=NORMAL):
    cos_i = dot3(wi, normal)
    if dot3(wo, normal) <= 0.0 or cos_i <= 0.0:
        return 0.0
    h = half(wo, wi)
    pdf_h = (n + 1.0) / (2.0 * math.pi) * dot3(normal, h) ** n
    return directions.mixture_pdf(kd, ks, cos_i, pdf_h / (4.0 * dot3(wo, h)))


def lobe_albedo_at_normal_incidence(n):
    """Integral of (n + 8) / (8 pi) cos^n(theta / 2) cos(theta) over the hemisphere, in
    closed form: with x = cos(theta / 2), cos(theta) = 2 x^2 - 1, d(omega) = 8 pi x dx."""
    a = math.sqrt(0.5)
    return (n + 8.0) * (2.0 * (1 - a ** (n + 4)) / (n + 4) - (1 - a ** (n + 2)) / (n + 2))


exponents = st.one_of(st.sampled_from([0.0, 1.0, 4.0, 40.0, 400.0]), st.floats(0.0, 1000.0))


# --- BRDF and pdf ---------------------------------------------------------------------


@given(weights, weights, exponents, thetas, phis, thetas, phis)
def test_brdf_and_pdf_match_the_formulas(kd, ks, n, to, po, ti, pi_):
    wo, wi = direction(NORMAL, to, po), direction(NORMAL, ti, pi_)
    m = BlinnPhong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    directions.check_brdf_and_pdf(
        m, wo, wi, expected_brdf(kd, ks, n, wo, wi), expected_pdf(kd, ks, n, wo, wi)
    )


@given(weights, weights, exponents, thetas, phis, st.floats(90.001, 180.0), phis)
def test_zero_below_the_surface(kd, ks, n, to, po, ti, pi_):
    m = BlinnPhong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    directions.check_nothing_below(m, direction(NORMAL, to, po), direction(NORMAL, ti, pi_))


def test_two_grazing_directions_give_a_real_finite_brdf():
    """Both directions just above the surface: normal . h rounds to -5.6e-17 here, and
    a fractional power of it would be complex."""
    normal = (-0.8108823945056095, -0.08583116976570461, -0.5788806030413352)
    wo = (0.5610554380483579, 0.16723413221270034, -0.810709282332101)
    wi = (0.18944846166244864, -0.9744194287380152, -0.12089688693929125)
    assert dot3(wo, normal) > 0.0 and dot3(wi, normal) > 0.0
    m = BlinnPhong(Color(*ALBEDO), kd=0.5, ks=0.5, exponent=2.5)
    f = model_brdf(m, wo, wi, normal=normal)
    assert all(isinstance(x, float) and math.isfinite(x) for x in f)
    assert f == pytest.approx([0.5 * a / math.pi for a in ALBEDO], rel=1e-12)


def test_the_highlight_peaks_where_the_half_vector_is_the_normal():
    m = BlinnPhong(Color(*ALBEDO), kd=0.0, ks=1.0, exponent=64.0)
    hit = make_hit(m)
    wo = direction(NORMAL, 50.0, 20.0)
    peak = m.BRDF(view_ray(wo), light_ray(mirror(wo, NORMAL)), hit).e0
    assert peak == pytest.approx(72.0 / (8.0 * math.pi), rel=1e-12)
    off = m.BRDF(view_ray(wo), light_ray(direction(NORMAL, 40.0, 200.0)), hit).e0
    assert 0.0 < off < peak


@given(weights, weights, exponents, thetas, phis, thetas, phis)
def test_reciprocity(kd, ks, n, ta, pa, tb, pb):
    m = BlinnPhong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    a, b = direction(NORMAL, ta, pa), direction(NORMAL, tb, pb)
    assert model_brdf(m, a, b) == directions.approx3(model_brdf(m, b, a), rel=1e-9)


# --- sampling -------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kd, ks, n",
    [(0.5, 0.5, 80.0), (0.2, 0.8, 3.0), (0.0, 1.0, 0.0), (1.0, 0.0, 5.0), (0.3, 0.6, 1e4)],
)
@pytest.mark.parametrize("theta_o", [0.0, 40.0, 80.0])
@pytest.mark.slow
def test_scattering_weight_is_brdf_cos_over_pdf(heavy, request, kd, ks, n, theta_o):
    reflected = outcome(heavy, request)
    assert reflected > 300  # for n = 0 most reflections about h go below the surface


def check_weights(kd: float, ks: float, n: float, theta_o: float) -> int:
    """check_scattering of 1500 samples; the number of them reflected above."""
    m = BlinnPhong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    wo = direction(NORMAL, theta_o, 30.0)
    brdf, pdf = partial(expected_brdf, kd, ks, n, wo), partial(expected_pdf, kd, ks, n, wo)
    return len(directions.check_scattering(m, wo, brdf, pdf, 1500, (7, int(theta_o))))


@pytest.mark.parametrize("n", slow_except([50.0, 200.0, 1000.0], 200.0))
def test_the_half_vectors_follow_the_cos_power_density(heavy, request, n):
    """kd = 0 at normal incidence: wi is wo reflected about h, and h = half(wo, wi) has
    E[n . h] = (n + 1) / (n + 2) and E[(n . h)^2] = (n + 1) / (n + 3) (these lobes keep
    every wi above the surface)."""
    absorbed, cs = outcome(heavy, request)
    assert absorbed == 0
    k = len(cs)
    for power, mean in ((1, (n + 1) / (n + 2)), (2, (n + 1) / (n + 3))):
        values = cs**power
        assert abs(values.mean() - mean) < 5.0 * values.std() / math.sqrt(k) + 1e-12


def half_vector_cosines(n: float) -> tuple[int, np.ndarray]:
    """20,000 samples at normal incidence with kd = 0: (how many were absorbed, n . h of
    the others)."""
    m = BlinnPhong(kd=0.0, ks=1.0, exponent=n)
    hit = make_hit(m)
    wo = NORMAL
    with use_generator(make_generator(5, int(n))):
        samples = [m.scattering(view_ray(wo), hit) for _ in range(20000)]
    kept = [s for s in samples if s is not None]
    cs = np.array([dot3(NORMAL, half(wo, s.scattered_ray.direction.tolist())) for s in kept])
    return len(samples) - len(kept), cs


@pytest.mark.parametrize(
    "kd, n, theta_o",
    slow_except(
        [(0.0, 0.0, 60.0), (0.0, 3.0, 70.0), (0.0, 20.0, 85.0), (0.3, 1.0, 45.0)], (0.0, 20.0, 85.0)
    ),
)
@pytest.mark.slow
def test_pdf_integrates_to_the_fraction_of_samples_not_absorbed(heavy, request, kd, n, theta_o):
    """A half vector facing away from the viewer, or a reflection below the surface,
    gives no sample, and pdf() counts neither: over the sphere pdf() integrates to the
    probability that scattering() returns a sample."""
    total, alive, k = outcome(heavy, request)
    assert 0.0 < total < 1.0
    assert abs(alive - total) < 5.0 * math.sqrt(total * (1.0 - total) / k)


def pdf_integral_and_alive_fraction(kd: float, n: float, theta_o: float):
    """(pdf() over the sphere, the fraction of k samples not absorbed, k = 20,000)."""
    m = BlinnPhong(Color(*ALBEDO), kd=kd, ks=1.0 - kd, exponent=n)
    wo = direction(NORMAL, theta_o, 0.0)
    below = tuple(-x for x in wo)
    total = directions.polar_integral(
        lambda wi: model_pdf(m, wo, wi), below, peak=mirror(wo, NORMAL)
    )
    k = 20000
    return total, directions.alive_fraction(m, wo, k, seed=int(n + theta_o)), k


@pytest.mark.parametrize("n", slow_except([0.0, 1.0, 2.0, 10.0, 100.0], 10.0))
def test_energy_at_normal_incidence_matches_the_closed_form(heavy, request, n):
    """(n + 8) / (8 pi) only approximates the normalisation: at normal incidence the lobe
    reflects the closed-form amount, 1 for n = 0 and up to ~7.5 % more near n = 10."""
    albedo = outcome(heavy, request)
    assert albedo == pytest.approx(lobe_albedo_at_normal_incidence(n), abs=1e-6)
    assert albedo < 1.08


def albedo_at_normal_incidence(n: float) -> float:
    """The lobe's directional albedo at normal incidence, by quadrature."""
    m = BlinnPhong(Color(*ALBEDO), kd=0.0, ks=1.0, exponent=n)
    hit = make_hit(m)
    wo = NORMAL

    def f_cos(wi):
        cos_i = dot3(wi, NORMAL)
        return m.BRDF(view_ray(wo), light_ray(wi), hit).e0 * cos_i if cos_i > 0 else 0.0

    return directions.polar_integral(f_cos, NORMAL, peak=NORMAL)


# node id -> the sampling and quadratures of each selected test, on every core, the
# longest first.
heavy = module_outcomes(
    {
        "test_energy_at_normal_incidence_matches_the_closed_form": albedo_at_normal_incidence,
        "test_the_half_vectors_follow_the_cos_power_density": half_vector_cosines,
        "test_pdf_integrates_to_the_fraction_of_samples_not_absorbed": (
            pdf_integral_and_alive_fraction
        ),
        "test_scattering_weight_is_brdf_cos_over_pdf": check_weights,
    }
)


# --- extremes -------------------------------------------------------------------------


@pytest.mark.parametrize("n", [0.0, 1.0, 1e4])
def test_grazing_angles_and_huge_exponents_give_finite_values(n):
    m = BlinnPhong(Color(*ALBEDO), kd=0.5, ks=0.5, exponent=n)
    hit = make_hit(m)
    views = [direction(NORMAL, to, 10.0) for to in (0.0, 60.0, 89.99)]
    grazing = [direction(NORMAL, 89.99, pi_) for pi_ in (10, 100, 190)]
    directions.check_finite(m, [(wo, [*grazing, NORMAL, mirror(wo, NORMAL)]) for wo in views], 300)
    wo = direction(NORMAL, 89.99, 10.0)
    f = m.BRDF(view_ray(wo), light_ray(mirror(wo, NORMAL)), hit).e0
    assert f == pytest.approx(0.5 * ALBEDO[0] / math.pi + 0.5 * (n + 8) / (8 * math.pi), rel=1e-6)
    # wi = -wo (no half vector) has no density, and nothing breaks.
    assert model_pdf(m, wo, tuple(-x for x in wo)) == 0.0


# --- construction and loading ---------------------------------------------------------


def test_defaults_and_registration():
    directions.check_defaults(BlinnPhong, "blinn_phong", kd=1.0, ks=0.0, exponent=1.0)
    assert Blinn is BlinnPhong is rtpy.Blinn  # the course's name, importable from rtpy too


@pytest.mark.parametrize(
    "kwargs, message",
    [
        *directions.BAD_STRENGTHS,
        ({"exponent": -0.5}, r"exponent: expected a number in \[0, 1000000\], found -0.5"),
        ({"exponent": math.nan}, "exponent: expected a"),
        ({"exponent": math.inf}, "exponent: expected a"),
    ],
)
def test_constructor_refuses_bad_parameters(kwargs, message):
    with pytest.raises((TypeError, ValueError), match=message):
        BlinnPhong(Color(*ALBEDO), **kwargs)


def test_the_loader_accepts_a_blinn_phong_material():
    keys = 'type = "blinn_phong"\nalbedo = [0.1, 0.2, 0.6]\nkd = 0.7\nks = 0.3\nexponent = 120'
    m = directions.load_material(keys)
    assert isinstance(m, BlinnPhong)
    assert m.albedo.color == Color(0.1, 0.2, 0.6)
    assert (m.kd, m.ks, m.exponent) == (0.7, 0.3, 120.0)
    with pytest.raises(SceneError, match=r"\[materials.shiny\] ks: expected a number in \[0, 1\]"):
        directions.load_material(keys.replace("ks = 0.3", "ks = -0.3"))
