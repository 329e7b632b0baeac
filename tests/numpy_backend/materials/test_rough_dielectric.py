"""The RoughDielectric kernels: the exact Fresnel reflectance as the scalar function, and
the sampler against the scalar one for the lecture's glasses from both sides. (BRDF, pdf
and scattering from the same numbers are compared with every other kind in
test_table.py.)"""

from __future__ import annotations

import numpy as np
import pytest

from rtpy.materials import RoughDielectric
from rtpy.materials import rough_dielectric as scalar
from rtpy.numpy_backend.materials.rough_dielectric import (
    RoughBeckmannKernel,
    RoughGGXKernel,
    fresnel_dielectric,
    rough_dielectric_kernel,
)
from rtpy.testing import chi2_test

from ...cores import module_outcomes, outcome
from ...tiers import slow_except
from .kernel_checks import CHI2_ALPHA, compare_with_scalar_sampler, head


def test_fresnel_equals_the_scalar_function_bit_for_bit():
    rng = np.random.default_rng(4)
    cos_i = np.concatenate([rng.random(5000), [1.0, 1e-300, 0.5, 0.745355992499929]])
    eta = np.concatenate([rng.choice([1.5, 1 / 1.5, 1.33, 0.5, 2.5], 5000), [1.5, 1.5, 1.0, 1.5]])
    eta[-1] = 1.0 / 1.5  # at the critical angle from inside, up to rounding
    expected = [scalar.fresnel_dielectric(c, e) for c, e in zip(cos_i, eta, strict=True)]
    np.testing.assert_array_equal(fresnel_dielectric(cos_i, eta), expected)
    assert (fresnel_dielectric(cos_i, eta) == 1.0).any()  # total internal reflection seen


def test_one_kernel_per_distribution():
    assert rough_dielectric_kernel(RoughDielectric(distribution="ggx")) is RoughGGXKernel
    assert rough_dielectric_kernel(RoughDielectric(distribution="beckmann")) is RoughBeckmannKernel


GLASSES = [
    RoughDielectric(1.5, 0.023, "beckmann"),
    RoughDielectric(1.5, 0.394, "ggx"),
    RoughDielectric(1.5, 0.553, "ggx"),
]
CASES = [(k, theta, inside) for k in range(3) for theta in (0.0, 45.0, 80.0) for inside in (0, 1)]


def sampler_check(glass: int, theta: float, inside: int) -> None:
    """The batched sampler against the scalar one, and the chi-square test of its
    samples."""
    material = GLASSES[glass]
    batched = compare_with_scalar_sampler(material, theta, 30.0, inside=bool(inside))
    result = chi2_test(
        material, theta, phi_deg=30.0, samples=head(batched, 30_000), inside=bool(inside)
    )
    assert result.passed(CHI2_ALPHA), result.summary()


# The selected cases' sampler_check, on every core.
sampler_checks = module_outcomes(
    {"test_sampler_agrees_with_scalar_and_follows_the_pdf": sampler_check}
)


@pytest.mark.parametrize("glass, theta, inside", slow_except(CASES, (1, 45.0, 1), (0, 80.0, 0)))
@pytest.mark.slow
def test_sampler_agrees_with_scalar_and_follows_the_pdf(
    sampler_checks, request, glass, theta, inside
):
    outcome(sampler_checks, request)
