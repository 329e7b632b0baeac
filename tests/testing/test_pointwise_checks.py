"""Tests for rtpy.testing.pointwise_checks: reciprocity (also across a refracting
surface) and finite values, for correct materials and broken ones."""

from __future__ import annotations

from rtpy.materials import Lambertian, Mirror
from rtpy.testing import check_non_negative_finite, check_reciprocity
from rtpy.vec3 import dot

from .materials_to_check import (
    DiffuseTransmitter,
    NegativeAtGrazing,
    NonReciprocal,
    PhongLobe,
)


def test_check_reciprocity():
    assert check_reciprocity(Lambertian())
    assert check_reciprocity(PhongLobe(100.0, kd=0.3, ks=0.7))
    result = check_reciprocity(NonReciprocal(), n_pairs=200)
    assert not result and "differ" in result.detail


def test_check_non_negative_finite():
    assert check_non_negative_finite(Lambertian())
    assert check_non_negative_finite(PhongLobe(1e4, kd=0.5, ks=0.5))
    assert check_non_negative_finite(Mirror())
    result = check_non_negative_finite(NegativeAtGrazing(), n=10)
    assert not result and "BRDF" in result.detail


class ScaledTransmitter(DiffuseTransmitter):
    """Transmission scaled as radiance is on refraction into a medium of index 1.5:
    f(wo, wi) / n_o^2 = f(wi, wo) / n_i^2 holds, f(wo, wi) = f(wi, wo) does not."""

    def BRDF(self, ray_view, ray_light, hit):
        f = super().BRDF(ray_view, ray_light, hit)
        if dot(hit.normal, ray_light.direction) < 0.0:
            n_o, n_i = (1.0, 1.5) if hit.front_face else (1.5, 1.0)
            f = f * (n_o / n_i)
        return f


def test_check_reciprocity_across_a_refracting_surface():
    assert check_reciprocity(DiffuseTransmitter(), ior=1.0)
    assert check_reciprocity(ScaledTransmitter(), ior=1.5)
    # Without ior only pairs above the surface are drawn: transmission goes unchecked.
    assert check_reciprocity(ScaledTransmitter())
    for ior in (1.0, 2.0):
        result = check_reciprocity(ScaledTransmitter(), n_pairs=200, ior=ior)
        assert not result and "index of refraction squared" in result.detail


def test_check_non_negative_finite_from_inside():
    result = check_non_negative_finite(DiffuseTransmitter(), inside=True)
    assert result and result.inside
