"""rtpy.materials.glossy: the pieces of the diffuse + highlight mixture that Phong,
Blinn-Phong, Cook-Torrance and Ward share, against their formulas."""

from __future__ import annotations

import math

import pytest

from rtpy.materials import Phong
from rtpy.materials.glossy import (
    MAX_PDF,
    diffuse_probability,
    mixture_pdf,
    reflected_density,
    weighted_sample,
)
from rtpy.materials.material import Material
from rtpy.vec3 import Color, Vec3

from ..vectors import dot3, unit3
from .directions import ALBEDO, ALBEDO_COLOR, NORMAL, direction, make_hit, view_ray


@pytest.mark.parametrize("kd, ks", [(1.0, 0.0), (0.5, 0.5), (0.0, 1.0), (0.3, 1.0), (0.0, 0.0)])
def test_the_diffuse_lobe_is_picked_in_proportion_to_its_strength(kd, ks):
    m = Phong(ALBEDO_COLOR, kd=kd, ks=ks, exponent=10.0)
    diffuse = kd * max(ALBEDO)
    expected = diffuse / (diffuse + ks) if diffuse + ks > 0.0 else 1.0
    assert diffuse_probability(m, make_hit(m)) == pytest.approx(expected, rel=1e-15)


def test_the_mixture_density_weights_each_lobe_by_its_probability():
    assert mixture_pdf(0.25, 0.5, 3.0) == pytest.approx(0.25 * 0.5 / math.pi + 0.75 * 3.0)
    assert mixture_pdf(1.0, 0.5, math.inf) == pytest.approx(0.5 / math.pi)  # no highlight
    assert mixture_pdf(0.0, 0.5, 2.0) == 2.0
    # A highlight density beyond float64 saturates, so that pdf^2 stays finite.
    assert mixture_pdf(0.5, 0.5, math.inf) == MAX_PDF
    assert math.isfinite(MAX_PDF**2)


def test_the_reflected_density_is_the_half_vectors_over_4_wo_h():
    wo = direction(NORMAL, 50.0, 20.0)
    for theta, phi in ((0.0, 0.0), (20.0, 90.0), (60.0, 200.0)):
        h = direction(NORMAL, theta, phi)
        expected = 2.5 / (4.0 * dot3(wo, h)) if dot3(wo, h) > 0.0 else 0.0
        assert reflected_density(2.5, Vec3(*wo), Vec3(*h)) == pytest.approx(expected, rel=1e-15)
    away = tuple(-x for x in wo)
    assert reflected_density(2.5, Vec3(*wo), Vec3(*unit3(away))) == 0.0


class Constant(Material):
    """A made-up BRDF and density, to see weighted_sample use them."""

    def __init__(self, density: float) -> None:
        self.density = density

    def BRDF(self, ray_view, ray_light, hit):
        return Color(0.2, 0.4, 0.6)

    def pdf(self, ray_view, ray_light, hit):
        return self.density


def test_a_sample_weighs_brdf_cos_over_pdf_and_leaves_from_the_surface():
    m = Constant(0.8)
    hit = make_hit(m)
    wo = direction(NORMAL, 30.0, 0.0)
    wi = direction(NORMAL, 40.0, 120.0)
    s = weighted_sample(m, view_ray(wo), hit, Vec3(*wi))
    cos_i = dot3(wi, NORMAL)
    assert s.attenuation.tolist() == pytest.approx([c * cos_i / 0.8 for c in (0.2, 0.4, 0.6)])
    assert s.pdf == 0.8 and s.is_specular is False
    assert s.scattered_ray.direction.tolist() == pytest.approx(list(wi), abs=1e-15)
    origin = s.scattered_ray.origin.tolist()
    assert dot3([o - p for o, p in zip(origin, hit.point.tolist(), strict=True)], NORMAL) >= 0.0
    # Below the surface (a reflection about a half vector facing away), or where pdf()
    # gives no density: absorbed.
    below = direction(NORMAL, 100.0, 0.0)
    assert weighted_sample(m, view_ray(wo), hit, Vec3(*below)) is None
    assert weighted_sample(Constant(0.0), view_ray(wo), hit, Vec3(*wi)) is None
