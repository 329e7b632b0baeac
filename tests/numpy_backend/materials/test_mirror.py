"""The Mirror kernel (and Metal without fuzz): the scalar reflection, bit for bit."""

from __future__ import annotations

import numpy as np

from rtpy.materials import Metal, Mirror
from rtpy.numpy_backend.materials import MaterialTable
from rtpy.vec3 import Color

from .kernel_checks import random_hits, scalar_scatter


def test_mirror_and_sharp_metal_reflect_exactly_as_scalar():
    materials = [Mirror(Color(0.9, 0.8, 0.7)), Metal(Color(0.5, 0.6, 0.7), fuzz=0.0)]
    rng = np.random.default_rng(5)
    hits = random_hits(rng, 500)
    ids = rng.integers(2, size=500)
    s = MaterialTable(materials).scattering(ids, hits, rng)
    expected = scalar_scatter(materials, ids, hits)
    assert s.alive.all() and s.is_specular.all() and not s.pdf.any()
    np.testing.assert_array_equal(s.direction, [tuple(e.scattered_ray.direction) for e in expected])
    np.testing.assert_array_equal(s.attenuation, [tuple(e.attenuation) for e in expected])
