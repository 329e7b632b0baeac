"""Plain-tuple vector helpers for the tests, written independently of rtpy.vec3, so that
expected values do not come from the code under test; and a check of planar hits."""

from __future__ import annotations

import math
import random

import pytest
from hypothesis import strategies as st

from rtpy.interval import Interval
from rtpy.ray import Ray
from rtpy.vec3 import Vec3

# Points in a box around the origin, where the tests' shapes lie.
ORIGINS = st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(-5, 5))


def V(x, y, z) -> Vec3:
    return Vec3(float(x), float(y), float(z))


def dot3(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross3(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def sub3(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def norm3(a) -> float:
    return math.sqrt(dot3(a, a))


def unit3(a):
    k = 1.0 / norm3(a)
    return (a[0] * k, a[1] * k, a[2] * k)


def angle(a, b) -> float:
    """Angle between two vectors, accurate for small angles (atan2 of |a x b| and a.b)."""
    return math.atan2(norm3(cross3(a, b)), dot3(a, b))


def check_planar_hit(shape, origin, target, n, uv, inside: bool) -> None:
    """The ray from origin through target, the point of a planar shape (normal n, any
    length) at surface coordinates uv, hits it at t = 1 with those (u, v), on the face
    the ray sees, with the unit normal facing the ray. Rays that cross the plane at a
    slant (|cos| < 0.05) are not checked; points not strictly inside may be missed
    (edges may round either way)."""
    d = sub3(target, origin)
    if abs(dot3(d, n)) < 0.05 * norm3(d) * norm3(n):
        return
    h = shape.intersect(Ray(V(*origin), V(*d)), Interval(0.0, math.inf))
    if not inside and h is None:
        return
    assert h is not None
    assert h.t == pytest.approx(1.0, rel=1e-9)
    assert (h.u, h.v) == pytest.approx(uv, abs=1e-9)
    front = dot3(d, n) < 0.0
    assert h.front_face is front
    assert h.normal.tolist() == pytest.approx([x if front else -x for x in unit3(n)], abs=1e-12)


def planar_samples(shape, n: int, seed: int, corner, normal):
    """n points drawn by shape.sample_point, each checked to come with the shape's unit
    normal and to lie in its plane (through corner, with normal `normal` of any length)."""
    rng = random.Random(seed)
    unit_n = unit3(normal)
    for _ in range(n):
        p, nrm = shape.sample_point(rng.random(), rng.random())
        assert max(abs(x - y) for x, y in zip(nrm.tolist(), unit_n, strict=True)) < 1e-14
        point = p.tolist()
        assert abs(dot3(sub3(point, corner), unit_n)) < 1e-12
        yield point
