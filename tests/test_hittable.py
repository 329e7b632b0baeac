"""rtpy.hittable.Hittable: the interface of scene objects, and its defaults: intersect()
from hit_t() and hit_info(), and light sampling by area converted to solid angle."""

from __future__ import annotations

import math

import pytest

from rtpy.hit_info import HitInfo
from rtpy.hittable import Hittable
from rtpy.interval import Interval
from rtpy.materials import Lambertian
from rtpy.ray import Ray

from .vectors import V, norm3, sub3, unit3


class Floor(Hittable):
    """The square [0, 2] x [0, 2] of the plane y = 0, with normal +y: the least a shape
    implements to be hit and to be an area light."""

    material = Lambertian()

    def hit_t(self, ray, t_min, t_max):
        if ray.direction.e1 == 0.0:
            return None
        t = -ray.origin.e1 / ray.direction.e1
        p = ray.at(t)
        inside = 0.0 <= p.e0 <= 2.0 and 0.0 <= p.e2 <= 2.0
        return t if inside and t_min < t < t_max else None

    def hit_info(self, ray, t):
        front = ray.direction.e1 < 0.0
        normal = V(0, 1, 0) if front else V(0, -1, 0)
        return HitInfo(ray.at(t), normal, t, front, self.material, self)

    def area(self):
        return 4.0

    def sample_point(self, r1, r2):
        return V(2.0 * r1, 0.0, 2.0 * r2), V(0, 1, 0)


def test_intersect_is_hit_info_at_hit_t_inside_the_interval():
    floor = Floor()
    ray = Ray(V(1, 2, 1), V(0.1, -1, 0.2))
    hit = floor.intersect(ray, Interval(0.0, math.inf))
    assert hit.t == pytest.approx(2.0) and hit.obj is floor and hit.front_face
    assert hit.point.tolist() == pytest.approx([1.2, 0.0, 1.4])
    assert floor.intersect(ray, Interval(0.0, 1.5)) is None  # beyond t_max
    assert floor.intersect(Ray(V(5, 2, 1), V(0, -1, 0)), Interval(0.0, math.inf)) is None


def test_the_defaults_of_a_shape_that_implements_nothing_more():
    floor = Floor()
    hit = floor.intersect(Ray(V(1, 2, 1), V(0, -1, 0)), Interval(0.0, math.inf))
    assert floor.bounding_box() is None  # unbounded: the BVH tests it on every ray
    assert floor.surface_uv(hit) == (0.0, 0.0) and floor.surface_tangent(hit) is None
    bare = Hittable()
    with pytest.raises(NotImplementedError):
        bare.hit_t(Ray(V(0, 0, 0), V(0, 0, 1)), 0.0, 1.0)
    for method, args in (("area", ()), ("sample_point", (0.5, 0.5))):
        with pytest.raises(NotImplementedError, match="Hittable cannot be an area light"):
            getattr(bare, method)(*args)


@pytest.mark.parametrize("p", [(1.0, 1.0, 1.0), (-3.0, 0.5, 4.0), (0.3, -2.0, 1.9)])
def test_light_sampling_converts_the_area_density_to_solid_angle(p):
    """Direction toward the sampled point, with pdf d^2 / (|cos theta_light| area);
    direction_pdf gives the same density for that point, and sample_hit finds the
    point at t = d."""
    floor = Floor()
    for r1, r2 in ((0.1, 0.2), (0.5, 0.5), (0.9, 0.3)):
        q = (2.0 * r1, 0.0, 2.0 * r2)
        d = sub3(q, p)
        dist = norm3(d)
        expected_pdf = dist**2 / (abs(d[1]) / dist * 4.0)
        direction, pdf = floor.sample_direction(V(*p), r1, r2)
        assert direction.tolist() == pytest.approx(list(unit3(d)), abs=1e-15)
        assert pdf == pytest.approx(expected_pdf, rel=1e-12)
        sampled, hit_pdf, hit = floor.sample_hit(V(*p), r1, r2)
        assert hit_pdf == pdf and hit.t == pytest.approx(dist, rel=1e-12)
        assert hit.point.tolist() == pytest.approx(list(q), abs=1e-12)
        assert floor.direction_pdf(V(*p), hit) == pytest.approx(expected_pdf, rel=1e-12)


def test_points_nearer_the_sampled_point_than_the_least_distance_give_no_sample():
    """At 1e-160 from the sampled point the pdf d^2 / (|cos| area) is 1e-320, a
    subnormal, and the sample's weight 1 / pdf inf; such points are not sampled, and
    direction_pdf gives them density 0, as sample_direction does."""
    floor = Floor()
    for height in (1e-160, 1e-51):
        p = V(1.0, height, 1.0)  # above the point that (0.5, 0.5) samples
        assert floor.sample_direction(p, 0.5, 0.5) is None
        hit = HitInfo(V(1.0, 0.0, 1.0), V(0, 1, 0), height, True, floor.material, floor)
        assert floor.direction_pdf(p, hit) == 0.0
    direction, pdf = floor.sample_direction(V(1.0, 1e-49, 1.0), 0.5, 0.5)
    assert direction.tolist() == [0.0, -1.0, 0.0] and pdf == pytest.approx(1e-98 / 4.0)


def test_points_in_the_lights_plane_give_no_sample():
    floor = Floor()
    assert floor.sample_direction(V(5.0, 0.0, 1.0), 0.5, 0.5) is None
    assert floor.sample_direction(V(1.0, 0.0, 1.0), 0.5, 0.5) is None  # the point itself
    assert floor.sample_hit(V(5.0, 0.0, 1.0), 0.5, 0.5) is None
    on_plane = HitInfo(V(1.0, 0.0, 1.0), V(0, 1, 0), 1.0, True, floor.material, floor)
    assert floor.direction_pdf(V(5.0, 0.0, 1.0), on_plane) == 0.0
