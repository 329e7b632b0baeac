"""The Ward kernel: its half-vector sampler equals the scalar one, and grazing viewers
are absorbed as in the scalar sampler."""

from __future__ import annotations

import math

import numpy as np

from rtpy.materials import Ward
from rtpy.numpy_backend.materials import MaterialTable
from rtpy.numpy_backend.materials.ward import WardKernel
from rtpy.vec3 import Color

from .kernel_checks import (
    ULP,
    check_samples_match_brdf_and_pdf,
    compare_with_scalar_sampler,
    perpendicular,
    random_hits,
    unit,
)
from .sampler_checks import AZIMUTH, LIBM_ULPS


def half_vector_differences(width_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """|batched - scalar| of sample_half_vector's local half vectors from the same
    numbers, for widths from 1e-4 to 1 along each axis, and the bound each must keep.

    phi = atan2(alpha_y sin(2 pi r2), alpha_x cos(2 pi r2)): the arguments differ by
    AZIMUTH times the widths, which atan2 divides by the length of its argument, and
    atan2 itself by LIBM_ULPS ulp of phi (at most pi); cos(phi) and sin(phi) add
    LIBM_ULPS ulp. a = cos^2(phi) / alpha_x^2 + sin^2(phi) / alpha_y^2 changes by at
    most (the ratio of the widths) * delta(phi) relative, and tan^2(theta) = -log1p(-r1)
    / a takes that on plus log1p's LIBM_ULPS ulp; theta moves by a quarter of that
    (d theta = sin cos d(tan^2) / (2 tan^2)). A unit vector then moves by at most
    delta(theta) + delta(phi), plus an ulp per operation."""
    rng = np.random.default_rng(7)
    n = 20_000
    widths = [1e-4, 1e-3, 0.05, 0.3, 1.0]
    ax, ay = rng.choice(widths, n), rng.choice(widths, n)
    r1, r2 = rng.random(n), rng.random(n)
    r1[:20], r1[20:40] = 0.0, 1.0 - rng.random(20) * 1e-12
    kernel = WardKernel([Ward()])
    batched = np.stack(kernel.sample_half_vector(ax * width_scale, ay, r1, r2), axis=1)
    scalar = np.array(
        [
            tuple(Ward(alpha_x=x, alpha_y=y).sample_half_vector(u, v))
            for x, y, u, v in zip(ax, ay, r1, r2, strict=True)
        ]
    )
    angle = 2.0 * math.pi * r2
    length = np.hypot(ax * np.cos(angle), ay * np.sin(angle))
    d_phi = math.sqrt(2.0) * np.maximum(ax, ay) * AZIMUTH / length
    d_phi += (LIBM_ULPS * math.pi + 2 * LIBM_ULPS + 2) * ULP
    ratio = np.maximum(ax / ay, ay / ax)
    d_theta = (ratio * d_phi + (2 * LIBM_ULPS + 6) * ULP) / 4.0
    return np.abs(batched - scalar), (d_theta + d_phi + 4 * ULP)[:, None]


def test_half_vector_sampler_equals_scalar():
    difference, bound = half_vector_differences()
    assert (difference <= bound).all()
    # a width off by 1e-9 relative is not rounding
    difference, bound = half_vector_differences(1.0 + 1e-9)
    assert not (difference <= bound).all()


def test_glossy_grazing_viewer_is_absorbed_as_in_scalar():
    """Viewers at 89 degrees: most specular samples fall below the surface."""
    material = Ward(Color(0.5, 0.5, 0.5), kd=0.1, ks=0.9, alpha_x=0.5, alpha_y=0.05)
    batched = compare_with_scalar_sampler(material, 89.0, 90.0)
    assert 0.1 < 1.0 - batched.scattered.mean() < 0.9


def test_samples_keep_their_bounds_where_the_tangent_nearly_lies_along_the_normal():
    """Tangents 1e-8 to 0.1 radians off the normal: the Gram-Schmidt frame leans by up to
    15 ULP / L (kernel_checks.unit_length_bound), and the reflected directions'
    lengths stay within that; attenuation and pdf agree with BRDF() and pdf()."""
    rng = np.random.default_rng(11)
    n = 3000
    hits = random_hits(rng, n)
    off = 10.0 ** rng.uniform(-8.0, -1.0, (n, 1))
    hits.tangent = unit(hits.normal + off * perpendicular(rng, hits.normal))
    table = MaterialTable([Ward(Color(0.5, 0.5, 0.5), 0.0, 1.0, 0.3, 0.05)])
    ids = np.zeros(n, dtype=np.intp)
    check_samples_match_brdf_and_pdf(table, ids, hits, table.scattering(ids, hits, rng))
