"""ScalarFallback: a material without a kernel gives exactly its scalar methods' results."""

from __future__ import annotations

import numpy as np

from rtpy.materials import Lambertian, Material
from rtpy.numpy_backend.materials import MaterialTable, kernel_class
from rtpy.numpy_backend.materials.fallback import ScalarFallback
from rtpy.ray import Ray
from rtpy.sampling import random_cosine_direction, random_double
from rtpy.scatter_info import ScatterInfo
from rtpy.vec3 import BLACK, Color

from .kernel_checks import (
    random_hits,
    random_wi,
    scalar_brdf_and_pdf,
    scalar_per_hit,
    scalar_scatter,
)


class HalfLambertian(Lambertian):
    """A student's subclass overriding the three methods: half the albedo, sampled with
    uniform directions in the hemisphere, absorbed when a coin says so."""

    def scattering(self, ray_in, hit):
        if random_double() < 0.25:
            return None
        x, _, z = random_cosine_direction()
        d = hit.tangent * x + hit.normal * z
        d = d / d.length()
        return ScatterInfo(Ray(hit.point, d), self.albedo.value(hit) * 0.5, 0.3)

    def BRDF(self, ray_view, ray_light, hit):
        return super().BRDF(ray_view, ray_light, hit) * 0.5

    def pdf(self, ray_view, ray_light, hit):
        return 0.75 * super().pdf(ray_view, ray_light, hit)


class Glow(Material):
    """Overrides only emitting() and scattering()."""

    is_emitter = True

    def emitting(self, hit):
        return Color(hit.u, hit.v, 1.0) if hit.front_face else BLACK

    def scattering(self, ray_in, hit):
        return ScatterInfo(Ray(hit.point, hit.normal), Color(0.1, 0.2, 0.3), 0.0, True)


def test_fallback_gives_exactly_the_scalar_results():
    materials = [HalfLambertian(Color(0.8, 0.6, 0.4)), Glow(), Lambertian(Color(0.1, 0.2, 0.3))]
    assert [kernel_class(m) is ScalarFallback for m in materials] == [True, True, False]
    rng = np.random.default_rng(11)
    hits = random_hits(rng, 400)
    ids = rng.integers(3, size=400)
    wi = random_wi(rng, hits)
    table = MaterialTable(materials)
    f_s, pdf_s = scalar_brdf_and_pdf(materials, ids, hits, wi)
    np.testing.assert_array_equal(table.BRDF(ids, hits, wi), f_s)
    np.testing.assert_array_equal(table.pdf(ids, hits, wi), pdf_s)
    np.testing.assert_array_equal(
        table.emitting(ids, hits), scalar_per_hit("emitting", materials, ids, hits)
    )
    np.testing.assert_array_equal(
        table.flat_color(ids, hits), scalar_per_hit("flat_color", materials, ids, hits)
    )

    # Sampling: the fallback's hits, in order, under a random.Random seeded from the rng.
    s1 = table.scattering(ids, hits, np.random.default_rng(5))
    s2 = table.scattering(ids, hits, np.random.default_rng(5))
    for a, b in zip(vars(s1).values(), vars(s2).values(), strict=True):
        np.testing.assert_array_equal(a, b)  # deterministic for a seed
    rows = np.flatnonzero(ids < 2)
    seed = int(np.random.default_rng(5).integers(2**63))
    expected = scalar_scatter(materials, ids[rows], hits.take(rows), seed)
    for row, e in zip(rows, expected, strict=True):
        assert s1.alive[row] == (e is not None)
        if e is not None:
            np.testing.assert_array_equal(s1.direction[row], tuple(e.scattered_ray.direction))
            np.testing.assert_array_equal(s1.attenuation[row], tuple(e.attenuation))
            assert s1.pdf[row] == e.pdf and s1.is_specular[row] == e.is_specular
    assert 0.1 < 1 - s1.alive[ids == 0].mean() < 0.4
