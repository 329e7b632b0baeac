"""Tests for rtpy.testing.chi_square: correct materials pass Pearson's test of
scattering() against pdf(), and sampling that does not match pdf() fails it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.materials import Lambertian, Mirror
from rtpy.testing import chi2_test, draw_samples
from rtpy.vec3 import Color

from ..cores import module_outcomes, outcome
from ..tiers import slow_except
from .materials_to_check import (
    AbsorbsEverything,
    DiffuseTransmitter,
    HalfSampler,
    OverNormalised,
    PhongLobe,
    SecretAbsorber,
    UniformSampler,
    UpperPdfOnly,
)

ANGLES = (0.0, 30.0, 60.0, 85.0, 89.9)


# --- the chi-square tests of the module, run on every core ------------------------------


def lambertian_chi2(theta: float):
    return chi2_test(Lambertian(Color(0.8, 0.5, 0.25)), theta)


def lobe_chi2(exponent: float, theta: float):
    return chi2_test(PhongLobe(exponent), theta)


def extremely_narrow_lobe_chi2():
    return chi2_test(PhongLobe(1e6), 0.0, n_samples=20_000)


def half_sampler_chi2():
    return chi2_test(HalfSampler(), 40.0, n_samples=50_000)


def seeded_chi2s():
    """Seeds 3, 3 and 4."""
    return [chi2_test(Lambertian(), 30.0, n_samples=5000, seed=seed) for seed in (3, 3, 4)]


def misnormalised_chi2():
    return chi2_test(OverNormalised(), 30.0)


def uniform_sampler_chi2():
    return chi2_test(UniformSampler(), 30.0)


def secret_absorber_chi2():
    return chi2_test(SecretAbsorber(), 30.0)


def transmitter_chi2s(inside: bool):
    """The correct transmitter, then the one whose pdf() forgets the lower half."""
    return (
        chi2_test(DiffuseTransmitter(0.3, 0.5), 50.0, n_samples=20_000, inside=inside),
        chi2_test(UpperPdfOnly(0.3, 0.5), 50.0, n_samples=5000, inside=inside),
    )


# node id -> the chi-square results of each selected test, all on every core, the
# longest first; the narrow lobe tested twice at the same angle runs once.
results = module_outcomes(
    {
        "test_chi2_accepts_an_extremely_narrow_lobe_at_normal_incidence": (
            extremely_narrow_lobe_chi2
        ),
        "test_pdf_integral_is_exact_for_narrow_lobes": lobe_chi2,
        "test_chi2_accepts_a_correct_narrow_lobe": lobe_chi2,
        "test_chi2_accepts_lambertian": lambertian_chi2,
        "test_chi2_rejects_unannounced_absorption": secret_absorber_chi2,
        "test_chi2_rejects_sampling_that_does_not_match_the_pdf": uniform_sampler_chi2,
        "test_chi2_rejects_a_misnormalised_pdf": misnormalised_chi2,
        "test_chi2_covers_the_whole_sphere": transmitter_chi2s,
        "test_chi2_counts_absorbed_samples_as_a_category": half_sampler_chi2,
        "test_chi2_is_deterministic_for_a_seed": seeded_chi2s,
    }
)


def exact_mass_above_horizon(exponent: float, theta_axis_deg: float) -> float:
    """Fraction of a cos^n lobe around an axis at theta_axis that lies above the
    horizon: integral of (n+1) cos^n(a) sin(a) * (fraction of the circle at angle a
    around the axis with z > 0), in the variable t = cos(a)^(n+1)."""
    m = 2_000_000
    t = (np.arange(m) + 0.5) / m
    cos_a = t ** (1.0 / (exponent + 1.0))
    sin_a = np.sqrt(1.0 - cos_a**2)
    ta = math.radians(theta_axis_deg)
    # z = cos a cos ta + sin a sin ta cos b > 0  <=>  cos b > k
    with np.errstate(divide="ignore"):
        k = -(cos_a * math.cos(ta)) / (sin_a * math.sin(ta))
    fraction = np.arccos(np.clip(k, -1.0, 1.0)) / math.pi
    return float(fraction.mean())


@pytest.mark.parametrize(
    ("exponent", "theta"),
    slow_except([(1e4, 0.0), (1e4, 30.0), (1e4, 89.9), (10.0, 85.0)], (1e4, 89.9)),
)
def test_pdf_integral_is_exact_for_narrow_lobes(results, request, exponent, theta):
    r = outcome(results, request)
    exact = exact_mass_above_horizon(exponent, theta)
    assert r.upper_integral == pytest.approx(exact, abs=2e-6)
    assert r.pdf_integral == pytest.approx(exact, abs=2e-6)  # nothing below the surface
    assert r.integration_error < 1e-5
    # ... and it predicts the absorbed fraction.
    absorbed = r.n_absorbed / r.n_samples
    se = math.sqrt(max(exact * (1 - exact), 1e-12) / r.n_samples)
    assert abs((1.0 - absorbed) - r.upper_integral) < 4 * se + 1e-5


# --- chi-square test -------------------------------------------------------------------------


@pytest.mark.parametrize("theta", slow_except(ANGLES, 60.0))
def test_chi2_accepts_lambertian(results, request, theta):
    r = outcome(results, request)
    assert r.p_value > 0.01, r.summary()
    assert r.n_absorbed == 0 and r.expected_absorbed < 1.0
    assert r.pdf_integral == pytest.approx(1.0, abs=1e-6)
    assert r.upper_integral == pytest.approx(1.0, abs=1e-6)
    assert r.observed.sum() == r.n_samples
    assert r.expected.sum() == pytest.approx(r.n_samples, rel=1e-6)
    assert r.dof > 100  # the bins resolve the distribution


@pytest.mark.parametrize(
    ("exponent", "theta"), slow_except([(1e4, 0.0), (1e4, 30.0), (1e4, 89.9)], (1e4, 89.9))
)
def test_chi2_accepts_a_correct_narrow_lobe(results, request, exponent, theta):
    r = outcome(results, request)
    assert r.p_value > 0.01, r.summary()


@pytest.mark.slow
def test_chi2_accepts_an_extremely_narrow_lobe_at_normal_incidence(results, request):
    # The lobe (about 0.06 degrees wide) hides between the quadrature nodes; the
    # sample-guided refinement of chi2_test must find it.
    r = outcome(results, request)
    assert r.p_value > 0.01, r.summary()
    assert r.pdf_integral == pytest.approx(1.0, abs=1e-5)


def test_chi2_counts_absorbed_samples_as_a_category(results, request):
    r = outcome(results, request)
    assert r.p_value > 0.01, r.summary()
    assert r.pdf_integral == pytest.approx(0.5, abs=1e-6)
    assert r.n_absorbed / r.n_samples == pytest.approx(0.5, abs=4 * math.sqrt(0.25 / 50_000))


def test_chi2_is_deterministic_for_a_seed(results, request):
    a, b, c = outcome(results, request)
    assert a.statistic == b.statistic and np.array_equal(a.observed, b.observed)
    assert a.statistic != c.statistic


def test_chi2_rejects_a_misnormalised_pdf(results, request):
    r = outcome(results, request)
    assert r.p_value < 1e-6
    assert r.pdf_integral == pytest.approx(1.1, abs=1e-5)


def test_chi2_rejects_sampling_that_does_not_match_the_pdf(results, request):
    r = outcome(results, request)
    assert r.p_value < 1e-6


def test_chi2_rejects_unannounced_absorption(results, request):
    r = outcome(results, request)
    assert r.p_value < 1e-6
    assert "absorbed" in r.worst


def test_chi2_fails_samples_where_the_pdf_is_zero():
    class ClaimsHalf(Lambertian):  # pdf() 0 for x < 0, but samples go there
        def pdf(self, ray_view, ray_light, hit):
            d = ray_light.direction
            return 2.0 * super().pdf(ray_view, ray_light, hit) if d.e0 > 0.0 else 0.0

    r = chi2_test(ClaimsHalf(), 30.0, n_samples=10_000)
    assert r.p_value == 0.0
    assert "pdf() is 0" in r.message


def test_chi2_fails_a_negative_pdf():
    class NegativePdf(Lambertian):
        def pdf(self, ray_view, ray_light, hit):
            return -super().pdf(ray_view, ray_light, hit)

    r = chi2_test(NegativePdf(), 30.0, n_samples=1000)
    assert r.p_value == 0.0 and "negative or not finite" in r.message


def test_chi2_refuses_specular_materials_and_foreign_samples():
    with pytest.raises(ValueError):
        chi2_test(Mirror(), 30.0)
    samples = draw_samples(Lambertian(), 30.0, 100)
    with pytest.raises(ValueError):
        chi2_test(Lambertian(), 60.0, samples=samples)
    with pytest.raises(ValueError):
        chi2_test(Lambertian(), 30.0, samples=samples, inside=True)


@pytest.mark.parametrize("inside", [False, True])
def test_chi2_covers_the_whole_sphere(results, request, inside):
    """A material that transmits: the bins below the surface count too, from either side."""
    r, forgetful = outcome(results, request)
    assert r.p_value > 0.01, r.summary()
    assert r.upper_integral == pytest.approx(0.375, abs=1e-6)  # r / (r + t) above
    assert r.pdf_integral == pytest.approx(1.0, abs=1e-6)
    assert r.observed[r.observed.shape[0] // 2 :].sum() > 10_000
    assert forgetful.p_value == 0.0 and "pdf() is 0" in forgetful.message


def test_chi2_fails_a_material_that_scatters_nothing():
    """BRDF black, pdf 0, scattering() None is self-consistent, but a check of sampling
    needs samples: every draw absorbed is a failure (p = 0), not p = 1."""
    result = chi2_test(AbsorbsEverything(), 30.0, n_samples=2000, theta_bins=8, phi_bins=8)
    assert result.p_value == 0.0 and not result.passed(1e-9)
    assert "too few scattered samples" in result.summary() and "0 of 2000" in result.summary()


def test_the_diffuse_transmitter_is_no_lambertian_in_disguise():
    """DiffuseTransmitter ships to students: it samples uniformly (its pdf is not
    cos / pi), and without transmission it refuses to be built."""
    with pytest.raises(ValueError, match="t"):
        DiffuseTransmitter(r=0.8, t=0.0)
    result = chi2_test(DiffuseTransmitter(), 30.0, n_samples=20_000, theta_bins=8, phi_bins=8)
    assert result.passed(0.001) and result.pdf_integral == pytest.approx(1.0, abs=1e-4)
