"""Tests for rtpy.ray: evaluation along the ray and spawning rays off surfaces."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy.ray import Ray, spawn_ray
from rtpy.vec3 import Vec3

coord = st.floats(-1e3, 1e3)


def test_at_known_values():
    r = Ray(Vec3(1.0, 2.0, 3.0), Vec3(0.5, -1.0, 2.0))
    assert r.at(0.0).tolist() == [1.0, 2.0, 3.0]
    assert r.at(2.0).tolist() == [2.0, 0.0, 7.0]
    assert r.at(-1.0).tolist() == [0.5, 3.0, 1.0]


@settings(deadline=None, max_examples=50)
@given(coord, coord, coord, coord, coord, coord, st.floats(-1e3, 1e3))
def test_at_is_origin_plus_t_direction(ox, oy, oz, dx, dy, dz, t):
    p = Ray(Vec3(ox, oy, oz), Vec3(dx, dy, dz)).at(t)
    for got, o, d in zip(p.tolist(), (ox, oy, oz), (dx, dy, dz), strict=True):
        assert math.isclose(got, o + t * d, rel_tol=1e-15, abs_tol=1e-12)


def _offset(point: Vec3, normal: Vec3, direction: Vec3) -> tuple[Ray, float]:
    """The spawned ray and its origin's signed distance from `point` along `normal`."""
    r = spawn_ray(point, normal, direction)
    d = r.origin - point
    return r, d.e0 * normal.e0 + d.e1 * normal.e1 + d.e2 * normal.e2


def test_spawn_ray_goes_to_the_side_of_the_direction():
    n = Vec3(0.0, 1.0, 0.0)
    p = Vec3(0.3, 0.0, -0.2)
    up = Vec3(0.6, 0.8, 0.0)
    down = Vec3(0.6, -0.8, 0.0)
    r_up, off_up = _offset(p, n, up)
    r_down, off_down = _offset(p, n, down)
    assert off_up > 0.0
    assert off_down < 0.0
    # The direction is kept and the origin moves only along the normal.
    assert r_up.direction is up and r_down.direction is down
    assert r_up.origin.e0 == p.e0 and r_up.origin.e2 == p.e2
    # Works with the normal given from the other side too.
    _, off_flip = _offset(p, -n, up)
    assert off_flip < 0.0  # along -n, i.e. still above the surface in world terms


def test_spawn_offset_grows_with_the_magnitude_of_the_point():
    n = Vec3(0.0, 0.0, 1.0)
    d = Vec3(0.0, 0.6, 0.8)
    _, small = _offset(Vec3(0.5, 0.25, 0.0), n, d)
    _, big = _offset(Vec3(1e5, -3e4, 0.0), n, d)
    assert small > 0.0 and big > 0.0
    # Near the origin the offset is tiny; at 1e5 it scales with the coordinates.
    assert small < 1e-6
    assert big > 1e3 * small
    # It must beat float64 rounding of the coordinates there by a wide margin ...
    assert big > 1e3 * math.ulp(1e5)
    # ... and still be invisible at scene scale.
    assert big < 1e-6 * 1e5


def test_spawned_ray_clears_the_plane_it_leaves_at_large_coordinates():
    # Plane z = 1e5 (normal +z), hit point with large coordinates; the spawned
    # origin must lie strictly on the side the direction goes to.
    p = Vec3(123456.789, -98765.4321, 1e5)
    n = Vec3(0.0, 0.0, 1.0)
    r = spawn_ray(p, n, Vec3(0.0, 0.0, -1.0))
    assert r.origin.e2 < 1e5
    r = spawn_ray(p, n, Vec3(0.0, 0.0, 1.0))
    assert r.origin.e2 > 1e5
