"""The Lambertian kernels: Lambertian, and the closed-form scenes' GlowingLambertian,
which the table finds by the class's full name (it imports nothing from rtpy.testing)."""

from __future__ import annotations

import numpy as np

from rtpy.numpy_backend.materials import MaterialTable, kernel_class
from rtpy.numpy_backend.materials.fallback import ScalarFallback
from rtpy.numpy_backend.materials.lambertian import GlowingLambertianKernel
from rtpy.testing.analytic_scenes import GlowingLambertian
from rtpy.vec3 import Color

from .kernel_checks import check_brdf_and_pdf, random_hits, random_wi, scalar_per_hit


class Dimmer(GlowingLambertian):
    """A subclass may change anything: it gets the scalar fallback."""


def test_glowing_lambertian_has_its_kernel_and_equals_scalar():
    materials = [
        GlowingLambertian(Color(0.5, 0.4, 0.3), Color(1.0, 2.0, 3.0)),
        GlowingLambertian(Color(0.1, 0.2, 0.3), Color(0.5, 0.5, 0.5)),
    ]
    assert kernel_class(materials[0]) is GlowingLambertianKernel
    assert kernel_class(Dimmer(Color(0.5, 0.5, 0.5), Color(1, 1, 1))) is ScalarFallback
    rng = np.random.default_rng(4)
    hits = random_hits(rng, 300)
    ids = rng.integers(2, size=300)
    table = MaterialTable(materials)
    np.testing.assert_array_equal(
        table.emitting(ids, hits), scalar_per_hit("emitting", materials, ids, hits)
    )
    check_brdf_and_pdf(table, ids, hits, random_wi(rng, hits), rel=0.0)  # bit for bit
    assert table.is_emitter.all() and not table.inert.any()
