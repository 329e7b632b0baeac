"""The Metal kernel with fuzz: the scalar sampler's distribution (z-tests)."""

from __future__ import annotations

import numpy as np
import pytest

from rtpy.materials import Metal
from rtpy.numpy_backend.materials import MaterialTable
from rtpy.vec3 import Color

from .kernel_checks import Z_MAX, local_hits, scalar_scatter, z_two_samples


@pytest.mark.parametrize(("fuzz", "theta"), [(0.3, 30.0), (1.0, 75.0)])
def test_fuzzy_metal_agrees_with_scalar(fuzz, theta):
    metal = Metal(Color(0.8, 0.6, 0.4), fuzz)
    n = 30_000
    hits = local_hits(n, theta, 20.0)
    b = MaterialTable([metal]).scattering(np.zeros(n, int), hits, np.random.default_rng(2))
    scalar = scalar_scatter([metal], np.zeros(6000, int), hits.take(np.arange(6000)), seed=4)
    alive_s = np.array([e is not None for e in scalar], dtype=float)
    assert abs(z_two_samples(b.alive.astype(float), alive_s)) < Z_MAX
    assert (b.direction[b.alive, 2] > 0.0).all() and b.is_specular[b.alive].all()
    np.testing.assert_allclose(np.linalg.norm(b.direction[b.alive], axis=1), 1.0, rtol=1e-12)
    assert not b.attenuation[~b.alive].any()
    d_s = np.array([tuple(e.scattered_ray.direction) for e in scalar if e is not None])
    for c in range(3):
        assert abs(z_two_samples(b.direction[b.alive, c], d_s[:, c])) < Z_MAX
