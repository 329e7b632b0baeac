"""Tests for rtpy.testing.material_checks: correct materials pass check_weights and
check_energy (whose directional albedos by sampling and by quadrature agree, on one
side of the surface or both), and each kind of broken material is caught by the check
meant for it."""

from __future__ import annotations

import pytest

from rtpy.materials import Lambertian
from rtpy.testing import check_energy, check_weights, directional_albedo
from rtpy.vec3 import Color

from ..cores import module_outcomes, outcome
from .materials_to_check import (
    AbsorbsEverything,
    DiffuseTransmitter,
    ForgetsPdf,
    HalfSampler,
    PhongLobe,
    UpperPdfOnly,
    WrongRecordedPdf,
)


@pytest.mark.parametrize("material", [Lambertian(), PhongLobe(1e4, kd=0.5, ks=0.5)])
def test_check_weights_accepts_correct_materials(material):
    for theta in (0.0, 60.0, 89.9):
        assert check_weights(material, theta)


def test_check_weights_catches_a_missing_division_by_the_pdf():
    result = check_weights(ForgetsPdf(), 30.0, n=200)
    assert not result
    assert "200 of 200" in result.detail and "BRDF * cos / pdf" in result.detail


def test_check_weights_fails_when_nothing_scatters():
    """No sample, nothing shown: not a pass."""
    result = check_weights(AbsorbsEverything(), 30.0, n=200)
    assert not result and not result.skipped and "no scattered samples" in result.detail


def test_check_weights_catches_a_wrong_recorded_pdf():
    result = check_weights(WrongRecordedPdf(), 30.0, n=200)
    assert not result and "ScatterInfo.pdf" in result.detail


@pytest.mark.parametrize("inside", [False, True])
def test_check_weights_sees_both_sides(inside):
    result = check_weights(DiffuseTransmitter(), 40.0, inside=inside)
    assert result and result.inside == inside
    assert ("from inside" in str(result)) == inside
    result = check_weights(UpperPdfOnly(), 40.0, n=200, inside=inside)
    assert not result and "pdf() = 0.0" in result.detail


def test_directional_albedo_by_sampling_and_quadrature(heavy, request):
    a, lobe = outcome(heavy, request)
    assert a.sampled == pytest.approx((0.8, 0.5, 0.25), rel=1e-12)
    assert a.quadrature == pytest.approx((0.8, 0.5, 0.25), rel=1e-7)
    # A Phong lobe at 60 degrees: the part of the lobe above the surface times
    # (n+2)/(n+1) <cos theta_i>; for n = 1e4 the lobe is a near-delta at 60 degrees.
    assert lobe.quadrature[0] == pytest.approx(0.5, abs=1e-4)
    assert lobe.sampled[0] == pytest.approx(
        lobe.quadrature[0], abs=5 * lobe.standard_error[0] + 1e-6
    )


def lambertian_and_lobe_albedos():
    """A Lambertian's at 45 degrees, and a Phong lobe's (n = 1e4) at 60 degrees."""
    return (
        directional_albedo(Lambertian(Color(0.8, 0.5, 0.25)), 45.0, n_samples=1000),
        directional_albedo(PhongLobe(1e4), 60.0, n_samples=20_000),
    )


def test_check_energy_accepts_correct_materials(heavy, request):
    white, lobe = outcome(heavy, request)
    assert white
    assert lobe


def energy_of_correct_materials():
    """check_energy of a white Lambertian and of a Phong lobe (n = 10) with kd = ks = 0.5."""
    return (
        check_energy(Lambertian(Color(1.0, 1.0, 1.0)), 30.0, n_samples=2000),
        check_energy(PhongLobe(10.0, kd=0.5, ks=0.5), 30.0, n_samples=20_000),
    )


def test_check_energy_catches_an_albedo_above_one():
    too_bright = Lambertian()
    too_bright.albedo.color = Color(1.3, 1.3, 1.3)  # beyond what the constructor takes
    result = check_energy(too_bright, 30.0, n_samples=2000)
    assert not result and "> 1" in result.detail


def test_check_energy_catches_sampling_that_misses_part_of_the_brdf(heavy, request):
    # HalfSampler passes the chi2 and weights checks: only the energy check sees
    # that the mean weight (albedo / 2) is not the integral of BRDF * cos (albedo).
    weights, result = outcome(heavy, request)
    assert weights
    assert not result and "disagrees" in result.detail


def half_sampler_checks():
    """check_weights and check_energy of HalfSampler at 30 degrees."""
    return check_weights(HalfSampler(), 30.0), check_energy(HalfSampler(), 30.0, n_samples=20_000)


@pytest.mark.parametrize("inside", [False, True])
def test_directional_albedo_of_a_material_that_transmits(heavy, request, inside):
    a, one_sided = outcome(heavy, request)
    assert a.two_sided
    # the mean weight 2 (r + t) |cos| of uniform draws: r + t, within its noise
    assert all(abs(s - 0.8) <= 5 * e for s, e in zip(a.sampled, a.standard_error, strict=True))
    assert a.reflected == pytest.approx((0.3, 0.3, 0.3), rel=1e-7)
    assert a.transmitted == pytest.approx((0.5, 0.5, 0.5), rel=1e-7)
    assert a.transmitted_power == pytest.approx((0.5, 0.5, 0.5), rel=1e-7)  # reciprocal
    assert a.lost == pytest.approx((0.2, 0.2, 0.2), rel=1e-6)
    assert one_sided.quadrature == pytest.approx((0.3, 0.3, 0.3), rel=1e-7)


def transmitter_albedos(inside: bool):
    """DiffuseTransmitter(0.3, 0.5)'s from the side `inside`, then the default one's
    on one side only (from outside)."""
    return (
        directional_albedo(DiffuseTransmitter(0.3, 0.5), 50.0, n_samples=2000, inside=inside),
        directional_albedo(DiffuseTransmitter(), 50.0, n_samples=2000, two_sided=False),
    )


def test_check_energy_on_both_sides(heavy, request):
    inside, too_bright, one_sided = outcome(heavy, request)
    assert inside
    assert not too_bright
    assert "> 1" in too_bright.detail and "transmitted 0.6000" in too_bright.detail
    # The transmitted half, left out of the quadrature, is missing from it.
    assert not one_sided and "disagrees" in one_sided.detail


def energy_on_both_sides():
    """check_energy of a correct transmitter from inside, of one that reflects and
    transmits 0.6 each, and of the default one checked on one side only."""
    return (
        check_energy(DiffuseTransmitter(0.3, 0.5), 30.0, n_samples=2000, inside=True),
        check_energy(DiffuseTransmitter(0.6, 0.6), 30.0, n_samples=2000),
        check_energy(DiffuseTransmitter(), 30.0, n_samples=2000, two_sided=False),
    )


# node id -> the albedos and checks of each selected test, on every core, the longest
# first.
heavy = module_outcomes(
    {
        "test_directional_albedo_by_sampling_and_quadrature": lambertian_and_lobe_albedos,
        "test_check_energy_accepts_correct_materials": energy_of_correct_materials,
        "test_check_energy_on_both_sides": energy_on_both_sides,
        "test_directional_albedo_of_a_material_that_transmits": transmitter_albedos,
        "test_check_energy_catches_sampling_that_misses_part_of_the_brdf": (half_sampler_checks),
    }
)
