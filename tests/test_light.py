"""Tests for rtpy.light: point lights (inverse square) and area lights (one-sided, pdfs)."""

from __future__ import annotations

import math

import pytest

from rtpy.interval import Interval
from rtpy.light import AreaLight, PointLight
from rtpy.materials import DiffuseLight
from rtpy.quad import Quad
from rtpy.ray import Ray
from rtpy.sampling import make_generator, use_generator
from rtpy.sphere import Sphere
from rtpy.vec3 import Color

from .vectors import V, norm3


def test_point_light_sample_on_axis():
    light = PointLight(V(1, 2, 3), Color(4, 8, 12))
    s = light.sample(V(1, 2, 1))
    assert s is not None
    assert s.direction.tolist() == [0.0, 0.0, 1.0]
    assert s.distance == 2.0
    assert s.radiance.tolist() == pytest.approx([1.0, 2.0, 3.0])
    assert isinstance(s.radiance, Color)
    assert s.pdf == 1.0
    assert s.is_delta is True and light.is_delta is True
    assert s.point.tolist() == [1.0, 2.0, 3.0]


@pytest.mark.parametrize("p", [(0.0, 0.0, 0.0), (-3.0, 5.0, 0.5), (10.0, -20.0, 30.0)])
def test_point_light_inverse_square(p):
    pos, intensity = (1.5, -0.5, 2.0), (3.0, 2.0, 1.0)
    light = PointLight(V(*pos), Color(*intensity))
    s = light.sample(V(*p))
    d = [pos[i] - p[i] for i in range(3)]
    dist = norm3(d)
    assert s.distance == pytest.approx(dist, rel=1e-14)
    assert s.direction.tolist() == pytest.approx([x / dist for x in d], abs=1e-14)
    assert s.radiance.tolist() == pytest.approx([x / dist**2 for x in intensity], rel=1e-13)


def test_point_light_at_the_receiving_point_gives_nothing():
    assert PointLight(V(1, 1, 1), Color(1, 1, 1)).sample(V(1, 1, 1)) is None


@pytest.mark.parametrize("distance", [1e-160, 1e-51])
def test_point_light_nearer_than_the_least_distance_gives_nothing(distance):
    """I / d^2 at d = 1e-160 is inf (d^2 underflows to a subnormal); below
    sqrt(MIN_LIGHT_DISTANCE2) = 1e-50 the point counts as the light's position. Just
    above it the radiance is finite and large."""
    light = PointLight(V(0, distance, 0), Color(1e9, 1e9, 1e9))
    assert light.sample(V(0, 0, 0)) is None
    near = PointLight(V(0, 1e-49, 0), Color(1e9, 1e9, 1e9)).sample(V(0, 0, 0))
    assert near.radiance.tolist() == pytest.approx([1e107] * 3, rel=1e-12)


EMIT = Color(5.0, 4.0, 3.0)


def ceiling_lamp(two_sided: bool = False) -> Quad:
    """A 1 x 2 quad at y = 1 facing down: u x v = (1,0,0) x (0,0,2) = (0,-2,0)."""
    return Quad(V(-0.5, 1, -1), V(1, 0, 0), V(0, 0, 2), DiffuseLight(EMIT, two_sided))


def test_area_light_radiance_from_the_front():
    lamp = ceiling_lamp()
    light = AreaLight(lamp)
    assert light.is_delta is False
    p = V(0.2, -1.0, 0.3)
    with use_generator(make_generator(1234)):
        for _ in range(50):
            s = light.sample(p)
            assert s is not None
            assert s.radiance.tolist() == EMIT.tolist()
            assert s.pdf > 0.0 and s.is_delta is False
            assert math.isclose(s.direction.length(), 1.0, abs_tol=1e-12)
            q = s.point.tolist()
            assert q[1] == pytest.approx(1.0, abs=1e-12)
            assert -0.5 - 1e-12 <= q[0] <= 0.5 + 1e-12 and -1 - 1e-12 <= q[2] <= 1 + 1e-12
            # The point lies `distance` along the direction.
            reached = p + s.direction * s.distance
            assert reached.tolist() == pytest.approx(q, abs=1e-12)
            # pdf = dist^2 / (cos_light * area), area = 2, light normal = -y.
            dist = norm3([q[i] - p.tolist()[i] for i in range(3)])
            cos_l = abs(s.direction.e1)
            assert s.pdf == pytest.approx(dist * dist / (cos_l * 2.0), rel=1e-9)


def test_area_light_is_one_sided():
    light = AreaLight(ceiling_lamp())
    above = V(0.1, 3.0, -0.2)
    with use_generator(make_generator(1234)):
        for _ in range(20):
            s = light.sample(above)
            assert s is not None
            assert s.radiance.tolist() == [0.0, 0.0, 0.0]
            assert s.pdf > 0.0


def test_two_sided_area_light_emits_from_the_back():
    light = AreaLight(ceiling_lamp(two_sided=True))
    with use_generator(make_generator(1234)):
        s = light.sample(V(0.1, 3.0, -0.2))
    assert s.radiance.tolist() == EMIT.tolist()


@pytest.mark.parametrize("p", [(0.2, -1.0, 0.3), (3.0, 0.0, 2.0), (0.0, 2.5, 0.0)])
def test_area_light_pdf_matches_sample_pdf(p):
    lamp = ceiling_lamp()
    light = AreaLight(lamp)
    pv = V(*p)
    with use_generator(make_generator(99)):
        for _ in range(30):
            s = light.sample(pv)
            assert s is not None
            h = lamp.intersect(Ray(pv, s.direction), Interval(0.0, math.inf))
            assert h is not None
            assert h.t == pytest.approx(s.distance, rel=1e-12)
            assert light.pdf(pv, h) == pytest.approx(s.pdf, rel=1e-9)


def test_sphere_area_light_pdf_is_uniform_cone():
    c, r = (0.0, 4.0, 0.0), 1.0
    ball = Sphere(V(*c), r, DiffuseLight(EMIT))
    light = AreaLight(ball)
    p = V(0.0, 0.0, 0.0)
    d = 4.0
    cone = 2.0 * math.pi * (1.0 - math.sqrt(d * d - r * r) / d)
    with use_generator(make_generator(3)):
        for _ in range(30):
            s = light.sample(p)
            assert s is not None
            assert s.pdf * cone == pytest.approx(1.0, rel=1e-9)
            assert s.radiance.tolist() == EMIT.tolist()
            h = ball.intersect(Ray(p, s.direction), Interval(0.0, math.inf))
            assert light.pdf(p, h) == pytest.approx(s.pdf, rel=1e-9)
            # The sampled point is on the near side of the sphere.
            q = s.point.tolist()
            assert norm3([q[i] - c[i] for i in range(3)]) == pytest.approx(r, rel=1e-12)
            assert q[1] <= c[1]
