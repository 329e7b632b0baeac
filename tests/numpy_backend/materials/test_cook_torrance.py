"""The Cook-Torrance kernels' half-vector samplers against the scalar one."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.materials import CookTorrance
from rtpy.materials import microfacet as mf
from rtpy.materials.cook_torrance import schlick_weight
from rtpy.numpy_backend.materials import cook_torrance as twin
from rtpy.numpy_backend.materials.cook_torrance import cook_torrance_kernel

from .kernel_checks import ULP
from .sampler_checks import AZIMUTH, LIBM_ULPS


def half_vector_differences(distribution: str, alpha_scale: float = 1.0) -> np.ndarray:
    """|batched - scalar| of sample_half_vector's local half vectors from the same
    numbers, for widths from 1e-4 to 1 (r1 at 0 and near 1)."""
    rng = np.random.default_rng(6)
    n = 20_000
    alpha = rng.choice([1e-4, 1e-3, 0.05, 0.3, 1.0], n)
    r1, r2 = rng.random(n), rng.random(n)
    r1[:20], r1[20:40] = 0.0, 1.0 - rng.random(20) * 1e-12
    material = CookTorrance(roughness=0.5, distribution=distribution)
    kernel = cook_torrance_kernel(material)([material])
    batched = np.stack(kernel.sample_half_vector(alpha * alpha_scale, r1, r2), axis=1)
    scalar = np.array(
        [
            tuple(CookTorrance(roughness=a, distribution=distribution).sample_half_vector(u, v))
            for a, u, v in zip(alpha, r1, r2, strict=True)
        ]
    )
    return np.abs(batched - scalar)


# GGX's tan^2 = alpha^2 r1 / (1 - r1) and the cosines from it are the scalar
# operations, bit for bit: only the azimuth differs. Beckmann's tan^2 comes from
# log1p (LIBM_ULPS ulp), which cos = 1 / sqrt(1 + tan^2) and sin = sqrt(tan^2) cos take
# over halved, plus an ulp per operation.
BOUNDS = {"ggx": AZIMUTH + 2 * ULP, "beckmann": AZIMUTH + (LIBM_ULPS + 4) * ULP}


@pytest.mark.parametrize("distribution", ["ggx", "beckmann"])
def test_half_vector_sampler_equals_scalar(distribution):
    assert (half_vector_differences(distribution) <= BOUNDS[distribution]).all()
    # a width off by 1e-9 relative is not rounding
    wrong = half_vector_differences(distribution, 1.0 + 1e-9)
    assert not (wrong <= BOUNDS[distribution]).all()


def test_the_microfacet_formulas_are_the_scalar_ones_to_the_bit():
    """The numpy copies of rtpy.materials.microfacet's formulas (numpy's sqrt is
    correctly rounded, as math's): the same bits, row by row."""
    rng = np.random.default_rng(8)
    a2 = rng.uniform(1e-4, 1.0, 100)
    cos = rng.uniform(1e-3, 1.0, 100)
    sin2 = 1.0 - cos * cos
    r1 = rng.random(100)
    batched = (
        twin.ggx_g1(a2, cos, sin2),
        twin.beckmann_a(np.sqrt(a2), cos, sin2),
        twin.cos_sin_of_tan2(mf.ggx_tan2(a2, r1))[1],
    )
    for i in range(100):
        a, c, s, r = float(a2[i]), float(cos[i]), float(sin2[i]), float(r1[i])
        one = (
            mf.ggx_g1(a, c, s),
            mf.beckmann_a(math.sqrt(a), c, s),
            mf.cos_sin_of_tan2(mf.ggx_tan2(a, r))[1],
        )
        assert one == tuple(float(b[i]) for b in batched)
    # x ** 5: Python's pow and numpy's power may round differently, by an ulp.
    scalar = np.array([schlick_weight(c - 0.5) for c in cos.tolist()])
    np.testing.assert_array_max_ulp(twin.schlick_weight(cos - 0.5), scalar, maxulp=2)
