"""Tests for rtpy.materials.Phong: the BRDF, its density, its samples and its energy.

Expected values come from the formula of the scene-format contract, written out
again here in world coordinates (r = reflect(-wi about n)), not from the code
under test:

    f_r = kd * albedo / pi + ks * (n + 2) / (2 pi) * max(0, r . wo)^n
    pdf = p_d * cos(theta_i) / pi + (1 - p_d) * (n + 1) / (2 pi) * max(0, m . wi)^n

with p_d = kd * max(albedo) / (kd * max(albedo) + ks) and m the mirror image of wo.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from rtpy.io.scene_file import SceneError
from rtpy.materials import Phong
from rtpy.materials.phong import cosine_power_pdf, sample_cosine_power
from rtpy.sampling import make_generator, use_generator
from rtpy.vec3 import Color

from ..cores import module_outcomes, outcome
from ..tiers import slow_except
from ..vectors import dot3
from .directions import (
    ALBEDO,
    BAD_STRENGTHS,
    NORMAL,
    alive_fraction,
    approx3,
    check_brdf_and_pdf,
    check_defaults,
    check_finite,
    check_nothing_below,
    check_scattering,
    direction,
    frame,
    light_ray,
    load_material,
    make_hit,
    mirror,
    mixture_pdf,
    phis,
    sphere_integral,
    thetas,
    view_ray,
    weights,
)
from .directions import brdf as model_brdf
from .directions import pdf as model_pdf

# --- the formulas ---------------------------------------------------------------------


def lobe_cos(wo, wi, normal):
    """r . wo with r = reflect(-wi about n), written as in the contract."""
    v = tuple(-x for x in wi)  # -wi points toward the surface
    k = 2.0 * dot3(v, normal)
    r = tuple(v[i] - k * normal[i] for i in range(3))
    return dot3(r, wo)


def expected_brdf(kd, ks, n, wo, wi, normal=NORMAL):
    if dot3(wo, normal) <= 0.0 or dot3(wi, normal) <= 0.0:
        return [0.0, 0.0, 0.0]
    c = lobe_cos(wo, wi, normal)
    spec = (n + 2.0) / (2.0 * math.pi) * c**n if c > 0.0 else 0.0
    return [kd * a / math.pi + ks * spec for a in ALBEDO]


def expected_pdf(kd, ks, n, wo, wi, normal=NORMAL):
    cos_i = dot3(wi, normal)
    if dot3(wo, normal) <= 0.0 or cos_i <= 0.0:
        return 0.0
    c = dot3(mirror(wo, normal), wi)  # m . wi, another route to r . wo
    return mixture_pdf(kd, ks, cos_i, (n + 1.0) / (2.0 * math.pi) * c**n if c > 0.0 else 0.0)


# --- strategies -----------------------------------------------------------------------

exponents = st.one_of(st.sampled_from([0.0, 1.0, 2.0, 10.0, 100.0]), st.floats(0.0, 500.0))


# --- BRDF and pdf ---------------------------------------------------------------------


@given(weights, weights, exponents, thetas, phis, thetas, phis)
def test_brdf_and_pdf_match_the_formulas(kd, ks, n, to, po, ti, pi_):
    wo, wi = direction(NORMAL, to, po), direction(NORMAL, ti, pi_)
    assume(abs(lobe_cos(wo, wi, NORMAL)) > 1e-6)  # away from the lobe's edge (0^n)
    m = Phong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    check_brdf_and_pdf(m, wo, wi, expected_brdf(kd, ks, n, wo, wi), expected_pdf(kd, ks, n, wo, wi))


@given(weights, weights, exponents, thetas, phis, st.floats(90.001, 180.0), phis)
def test_zero_below_the_surface(kd, ks, n, to, po, ti, pi_):
    m = Phong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    check_nothing_below(m, direction(NORMAL, to, po), direction(NORMAL, ti, pi_))


def test_the_highlight_peaks_at_the_mirror_direction():
    m = Phong(Color(*ALBEDO), kd=0.0, ks=1.0, exponent=50.0)
    hit = make_hit(m)
    wo = direction(NORMAL, 35.0, 20.0)
    peak = m.BRDF(view_ray(wo), light_ray(mirror(wo, NORMAL)), hit).e0
    assert peak == pytest.approx(52.0 / (2.0 * math.pi), rel=1e-12)
    off = m.BRDF(view_ray(wo), light_ray(direction(NORMAL, 35.0, 20.0 + 180.0 + 10.0)), hit).e0
    assert 0.0 < off < peak


@given(weights, weights, exponents, thetas, phis, thetas, phis)
def test_reciprocity(kd, ks, n, ta, pa, tb, pb):
    m = Phong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    a, b = direction(NORMAL, ta, pa), direction(NORMAL, tb, pb)
    assume(abs(lobe_cos(a, b, NORMAL)) > 1e-6)
    assert model_brdf(m, a, b) == approx3(model_brdf(m, b, a), rel=1e-9)


# --- sampling -------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kd, ks, n",
    [(0.5, 0.5, 20.0), (0.2, 0.8, 3.0), (0.0, 1.0, 0.0), (1.0, 0.0, 5.0), (0.3, 0.6, 1e4)],
)
@pytest.mark.parametrize("theta_o", [0.0, 40.0, 80.0])
@pytest.mark.slow
def test_scattering_weight_is_brdf_cos_over_pdf(heavy, request, kd, ks, n, theta_o):
    assert outcome(heavy, request) > 500


def check_weights(kd: float, ks: float, n: float, theta_o: float) -> int:
    """check_scattering of 1500 samples; the number of them reflected above."""
    m = Phong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    wo = direction(NORMAL, theta_o, 30.0)
    brdf, pdf = partial(expected_brdf, kd, ks, n, wo), partial(expected_pdf, kd, ks, n, wo)
    return len(check_scattering(m, wo, brdf, pdf, 1500, (7, int(theta_o))))


@pytest.mark.parametrize("n", [0.0, 1.0, 8.0, 100.0])
def test_sample_cosine_power_draws_the_cos_power_density(n):
    """E[cos] = (n + 1) / (n + 2) and E[cos^2] = (n + 1) / (n + 3) for the density
    (n + 1) / (2 pi) cos^n around z, and the azimuth is uniform."""
    rng = np.random.default_rng(11)
    samples = [sample_cosine_power(n, r1, r2).tolist() for r1, r2 in rng.random((20000, 2))]
    for v in samples[:1000]:
        assert math.isclose(dot3(v, v), 1.0, abs_tol=1e-12)
    check_cos_power_moments(np.array(samples), n, (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0, 0, 1))


def check_cos_power_moments(samples: np.ndarray, n: float, side, up, axis) -> None:
    """Directions (k, 3) drawn with density (n + 1) / (2 pi) cos^n around the axis."""
    cs, k = samples @ np.array(axis), len(samples)
    for power, mean in ((1, (n + 1) / (n + 2)), (2, (n + 1) / (n + 3))):
        values = cs**power
        assert abs(values.mean() - mean) < 5.0 * values.std() / math.sqrt(k) + 1e-12
    for v in (samples @ np.array(side), samples @ np.array(up)):
        assert abs(v.mean()) < 5.0 * math.sqrt(0.5 / k)


@pytest.mark.parametrize(
    "n, theta_o",
    slow_except([(1.0, 0.0), (8.0, 0.0), (100.0, 50.0), (1000.0, 80.0)], (100.0, 50.0)),
)
def test_the_highlight_is_drawn_around_the_mirror_direction(heavy, request, n, theta_o):
    """kd = 0: scattering() draws the cosine power around m, the mirror direction of
    wo (where the lobe stays above the surface, as here, nothing is absorbed)."""
    absorbed, wi = outcome(heavy, request)
    assert absorbed == 0
    axis = mirror(direction(NORMAL, theta_o, 30.0), NORMAL)
    check_cos_power_moments(wi, n, *frame(axis), axis)


def highlight_samples(n: float, theta_o: float) -> tuple[int, np.ndarray]:
    """20,000 samples with kd = 0: (how many were absorbed, the directions (k, 3) of
    the others)."""
    m = Phong(kd=0.0, ks=1.0, exponent=n)
    hit = make_hit(m)
    wo = direction(NORMAL, theta_o, 30.0)
    with use_generator(make_generator(11, int(n))):
        samples = [m.scattering(view_ray(wo), hit) for _ in range(20000)]
    kept = [s for s in samples if s is not None]
    wi = np.array([s.scattered_ray.direction.tolist() for s in kept])
    return len(samples) - len(kept), wi


@pytest.mark.parametrize("n", [0.0, 0.5, 1.0, 30.0, 1000.0, 1e4])
def test_cosine_power_pdf_integrates_to_one_over_the_sphere(n):
    axis = direction(NORMAL, 60.0, 10.0)
    total = sphere_integral(lambda w: cosine_power_pdf(n, dot3(w, axis)), axis)
    assert total == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize(
    "kd, n, theta_o",
    slow_except([(0.0, 1.0, 45.0), (0.0, 30.0, 85.0), (0.4, 8.0, 70.0)], (0.4, 8.0, 70.0)),
)
def test_pdf_integrates_to_the_fraction_of_samples_not_absorbed(heavy, request, kd, n, theta_o):
    """Samples below the surface are absorbed, and pdf() is 0 there: over the sphere
    pdf() integrates to the probability that scattering() returns a sample."""
    total, alive, k = outcome(heavy, request)
    assert 0.0 < total < 1.0
    assert abs(alive - total) < 5.0 * math.sqrt(total * (1.0 - total) / k)


def pdf_integral_and_alive_fraction(kd: float, n: float, theta_o: float):
    """(pdf() over the sphere, the fraction of k samples not absorbed, k = 20,000)."""
    m = Phong(Color(*ALBEDO), kd=kd, ks=1.0 - kd, exponent=n)
    wo = direction(NORMAL, theta_o, 0.0)
    total = sphere_integral(lambda wi: model_pdf(m, wo, wi), mirror(wo, NORMAL))
    k = 20000
    return total, alive_fraction(m, wo, k, seed=int(n + theta_o)), k


@pytest.mark.parametrize("n", slow_except([0.0, 0.8, 1.0, 8.0, 30.0, 1000.0], 8.0))
def test_energy_the_normalised_lobe_reflects_at_most_everything(heavy, request, n):
    """Integral of the specular f_r * cos(theta_i) over the hemisphere (the directional
    albedo of the lobe with ks = 1): exactly 1 at normal incidence, less elsewhere."""
    head_on, *albedos = outcome(heavy, request)
    assert head_on == pytest.approx(1.0, abs=1e-6)
    previous = 1.0
    for a in albedos:
        assert 0.0 < a <= 1.0 + 1e-6
        if n > 0.0:
            # The lobe comes nearer the horizon, so a larger part of it is cut off.
            assert a <= previous + 1e-6
        previous = a


def lobe_albedos(n: float) -> list[float]:
    """The lobe's directional albedo (ks = 1) at 0, 30, 60 and 85 degrees."""
    m = Phong(Color(*ALBEDO), kd=0.0, ks=1.0, exponent=n)
    hit = make_hit(m)

    def albedo(theta_o):
        wo = direction(NORMAL, theta_o, 0.0)

        def f_cos(wi):
            cos_i = dot3(wi, NORMAL)
            return m.BRDF(view_ray(wo), light_ray(wi), hit).e0 * cos_i if cos_i > 0 else 0.0

        return sphere_integral(f_cos, mirror(wo, NORMAL))

    return [albedo(theta_o) for theta_o in (0.0, 30.0, 60.0, 85.0)]


# node id -> the sampling and quadratures of each selected test, on every core, the
# longest first.
heavy = module_outcomes(
    {
        "test_energy_the_normalised_lobe_reflects_at_most_everything": lobe_albedos,
        "test_pdf_integrates_to_the_fraction_of_samples_not_absorbed": (
            pdf_integral_and_alive_fraction
        ),
        "test_the_highlight_is_drawn_around_the_mirror_direction": highlight_samples,
        "test_scattering_weight_is_brdf_cos_over_pdf": check_weights,
    }
)


# --- extremes -------------------------------------------------------------------------


@pytest.mark.parametrize("n", [0.0, 1.0, 1e4])
def test_grazing_angles_and_huge_exponents_give_finite_values(n):
    m = Phong(Color(*ALBEDO), kd=0.5, ks=0.5, exponent=n)
    hit = make_hit(m)
    lights = [direction(NORMAL, ti, pi_) for ti in (0.0, 45.0, 89.99) for pi_ in (10, 190)]
    views = [direction(NORMAL, to, 10.0) for to in (0.0, 60.0, 89.99)]
    check_finite(m, [(wo, [*lights, mirror(wo, NORMAL)]) for wo in views], 300)
    # At the mirror direction the huge lobe is large but finite.
    wo = direction(NORMAL, 89.99, 10.0)
    f = m.BRDF(view_ray(wo), light_ray(mirror(wo, NORMAL)), hit).e0
    assert f == pytest.approx(0.5 * ALBEDO[0] / math.pi + 0.5 * (n + 2) / (2 * math.pi), rel=1e-6)


def test_exponent_zero_is_uniform_around_the_mirror_direction():
    assert cosine_power_pdf(0.0, 0.8) == pytest.approx(1.0 / (2.0 * math.pi))
    assert cosine_power_pdf(0.0, 1e-9) == pytest.approx(1.0 / (2.0 * math.pi))
    assert cosine_power_pdf(0.0, 0.0) == 0.0  # at 90 degrees from the axis
    assert cosine_power_pdf(0.0, -0.6) == 0.0  # behind it
    m = Phong(kd=0.0, ks=1.0, exponent=0.0)
    hit = make_hit(m)
    wo = direction(NORMAL, 37.0, 0.0)
    r = mirror(wo, NORMAL)
    near, far = direction(NORMAL, 10.0, 180.0), direction(NORMAL, 80.0, 0.0)
    assert dot3(near, r) > 0.0 > dot3(far, r)  # one on each side of the lobe's edge
    assert m.BRDF(view_ray(wo), light_ray(near), hit).tolist() == approx3([1.0 / math.pi] * 3)
    assert m.BRDF(view_ray(wo), light_ray(far), hit).tolist() == [0.0, 0.0, 0.0]


# --- construction and loading ---------------------------------------------------------


def test_defaults_and_registration():
    check_defaults(Phong, "phong", kd=1.0, ks=0.0, exponent=1.0)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        *BAD_STRENGTHS,
        ({"exponent": -1.0}, r"exponent: expected a number in \[0, 1000000\], found -1.0"),
        ({"exponent": math.nan}, "exponent: expected a"),
        ({"exponent": math.inf}, "exponent: expected a"),
        ({"exponent": "10"}, "exponent: expected a"),
        ({"exponent": True}, "exponent: expected a"),
    ],
)
def test_constructor_refuses_bad_parameters(kwargs, message):
    with pytest.raises((TypeError, ValueError), match=message):
        Phong(Color(*ALBEDO), **kwargs)


SHINY = 'type = "phong"\nalbedo = [0.7, 0.15, 0.1]\nkd = 0.6\nks = 0.4\nexponent = 8'


def test_the_loader_accepts_a_phong_material():
    m = load_material(SHINY)
    assert isinstance(m, Phong)
    assert m.albedo.color == Color(0.7, 0.15, 0.1)
    assert (m.kd, m.ks, m.exponent) == (0.6, 0.4, 8.0)


def test_the_loader_uses_the_defaults_and_refuses_bad_values():
    m = load_material(SHINY.replace("kd = 0.6\nks = 0.4\nexponent = 8", ""))
    assert (m.kd, m.ks, m.exponent) == (1.0, 0.0, 1.0)
    with pytest.raises(SceneError, match=r"\[materials.shiny\] exponent: .*in \[0, 1000000\]"):
        load_material(SHINY.replace("exponent = 8", "exponent = -2"))
    with pytest.raises(SceneError, match=r"\[materials.shiny\] shininess: unknown key"):
        load_material(SHINY.replace("exponent = 8", "shininess = 8"))
