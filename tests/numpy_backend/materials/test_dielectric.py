"""The Dielectric kernel: reflection with probability Schlick's R, as the scalar sampler,
and the Whitted rays' weights where they cancel."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.materials import Dielectric
from rtpy.numpy_backend.materials import MaterialTable, dielectric
from rtpy.numpy_backend.materials.dielectric import schlick
from rtpy.vec3 import Color

from .kernel_checks import (
    Z_MAX,
    assert_agrees,
    grazing,
    local_hits,
    random_hits,
    scalar_hit,
    scalar_scatter,
    z_two_samples,
)


def test_dielectric_reflects_with_probability_schlick():
    glass = Dielectric(1.5, Color(0.9, 1.0, 0.8))
    rng = np.random.default_rng(9)
    hits = random_hits(rng, 100_000)
    table = MaterialTable([glass])
    ids = np.zeros(len(hits), int)
    s = table.scattering(ids, hits, rng)
    (reflected, _, _), (refracted, _, refracts) = table.specular_rays(ids, hits)
    reflectance = table.kernels[0].split(ids, hits)[0]
    assert s.alive.all() and s.is_specular.all()
    np.testing.assert_array_equal(s.attenuation, np.tile([0.9, 1.0, 0.8], (len(hits), 1)))
    went_back = (s.direction == reflected).all(axis=1)
    went_through = (s.direction == refracted).all(axis=1) & refracts
    assert (went_back | went_through).all()
    assert went_back[~refracts].all()  # total internal reflection
    assert 0.01 < (~refracts).mean() < 0.5
    z = (went_back.sum() - reflectance.sum()) / math.sqrt(np.sum(reflectance * (1 - reflectance)))
    assert abs(z) < Z_MAX
    # and the same fraction as the scalar sampler, for a grazing ray into the glass
    for theta, inside in ((80.0, False), (30.0, True)):
        one = local_hits(20_000, theta)
        one.front_face[:] = not inside
        b = table.scattering(np.zeros(20_000, int), one, rng)
        back_b = b.direction[:, 2] > 0.0
        scalar = scalar_scatter([glass], np.zeros(4000, int), one.take(np.arange(4000)), seed=3)
        back_s = np.array([e.scattered_ray.direction.e2 > 0.0 for e in scalar])
        assert abs(z_two_samples(back_b.astype(float), back_s.astype(float))) < Z_MAX


def transmitted_weights(hits, glass):
    """(batched, scalar) weights of the refracted Whitted ray, albedo (1 - R), per hit."""
    ids = np.zeros(len(hits), int)
    _, (_, batched, refracts) = MaterialTable([glass]).specular_rays(ids, hits)
    assert refracts.all()
    scalar = []
    for i in range(len(hits)):
        m, hit, ray_in = scalar_hit([glass], ids, hits, i)
        scalar.append(tuple(m.specular_rays(ray_in, hit)[1][1]))
    return batched, np.array(scalar)


def test_transmitted_weight_at_grazing_incidence_agrees_to_the_albedo(monkeypatch):
    """ior 1 and grazing viewers: R = (1 - cos)^5 is close to 1, and 1 - R magnifies
    the last-bit difference between numpy's and the C library's pow. The weights
    agree to 1e-12 of the albedo; a real mistake (an exponent of 5.001) does not."""
    rng = np.random.default_rng(1)
    hits = random_hits(rng, 2000)
    hits.wo[:] = grazing(rng, hits.normal, 1.0)
    glass = Dielectric(1.0, Color(0.2, 0.5, 1.0))
    albedo = np.tile([0.2, 0.5, 1.0], (len(hits), 1))
    batched, scalar = transmitted_weights(hits, glass)
    assert_agrees(batched, scalar, "transmitted weight", scale=albedo)

    def wrong(cosine, ior_ratio):
        return schlick(cosine, ior_ratio) ** 1.0002  # (1 - cos)^5.001 for ior 1

    monkeypatch.setattr(dielectric, "schlick", wrong)
    batched, scalar = transmitted_weights(hits, glass)
    with pytest.raises(AssertionError, match="transmitted weight"):
        assert_agrees(batched, scalar, "transmitted weight", scale=albedo)
