"""Tests for rtpy.quad: hits, edges, faces, (u, v), degenerate quads and area sampling."""

from __future__ import annotations

import math
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy._checks import MIN_AREA
from rtpy.interval import Interval
from rtpy.materials import Lambertian
from rtpy.quad import Quad
from rtpy.ray import Ray
from rtpy.testing import chi2_sf

from .vectors import ORIGINS, V, check_planar_hit, cross3, dot3, norm3, planar_samples, sub3

MAT = Lambertian()
EVERYWHERE = Interval(0.0, math.inf)


def solve_ab(q, u, v, p):
    """(a, b) with p = q + a u + b v, from the 2x2 normal equations (Cramer's rule)."""
    d = sub3(p, q)
    uu, uv, vv = dot3(u, u), dot3(u, v), dot3(v, v)
    du, dv = dot3(d, u), dot3(d, v)
    det = uu * vv - uv * uv
    return (du * vv - dv * uv) / det, (dv * uu - du * uv) / det


# The square [-1, 1]^2 in the plane z = -2, front face +z. With these numbers the
# (a, b) coordinates are computed exactly, so edges are exact.
SQ = Quad(V(-1, -1, -2), V(2, 0, 0), V(0, 2, 0), MAT)


def down_at(x, y, z0=5.0):
    return Ray(V(x, y, z0), V(0, 0, -1))


def test_hit_inside_front_face():
    h = SQ.intersect(down_at(0.5, -0.25), EVERYWHERE)
    assert h is not None
    assert h.t == 7.0
    assert h.point.tolist() == [0.5, -0.25, -2.0]
    assert h.normal.tolist() == [0.0, 0.0, 1.0]
    assert h.front_face is True
    assert (h.u, h.v) == pytest.approx((0.75, 0.375), abs=1e-15)
    assert h.material is MAT and h.obj is SQ


def test_back_face_flips_the_normal():
    h = SQ.intersect(Ray(V(0.5, -0.25, -10), V(0, 0, 1)), EVERYWHERE)
    assert h is not None
    assert h.t == 8.0
    assert h.front_face is False
    assert h.normal.tolist() == [0.0, 0.0, -1.0]
    assert (h.u, h.v) == pytest.approx((0.75, 0.375), abs=1e-15)


@pytest.mark.parametrize("x, y", [(1.5, 0.0), (0.0, -1.5), (-1.0000001, 0.0), (2.0, 2.0)])
def test_miss_outside(x, y):
    assert SQ.intersect(down_at(x, y), EVERYWHERE) is None


@pytest.mark.parametrize(
    "x, y, a, b",
    [
        (-1.0, 0.0, 0.0, 0.5),
        (1.0, 0.0, 1.0, 0.5),
        (0.0, -1.0, 0.5, 0.0),
        (0.0, 1.0, 0.5, 1.0),
        (-1.0, -1.0, 0.0, 0.0),
        (1.0, -1.0, 1.0, 0.0),
        (-1.0, 1.0, 0.0, 1.0),
        (1.0, 1.0, 1.0, 1.0),
    ],
)
def test_edges_and_corners_count_as_hits(x, y, a, b):
    h = SQ.intersect(down_at(x, y), EVERYWHERE)
    assert h is not None
    assert h.t == 7.0
    assert (h.u, h.v) == (a, b)


def test_just_outside_each_edge_misses():
    eps = 1e-9
    for x, y in ((-1 - eps, 0), (1 + eps, 0), (0, -1 - eps), (0, 1 + eps)):
        assert SQ.intersect(down_at(x, y), EVERYWHERE) is None


def test_parallel_ray_misses():
    assert SQ.intersect(Ray(V(-5, 0, -2), V(1, 0, 0)), EVERYWHERE) is None  # in the plane
    assert SQ.intersect(Ray(V(-5, 0, 0), V(1, 0.2, 0)), EVERYWHERE) is None  # above it


def test_ray_pointing_away_and_interval():
    assert SQ.intersect(Ray(V(0, 0, 5), V(0, 0, 1)), EVERYWHERE) is None
    assert SQ.intersect(down_at(0, 0), Interval(0.0, 6.9)) is None
    assert SQ.intersect(down_at(0, 0), Interval(7.1, math.inf)) is None
    assert SQ.intersect(down_at(0, 0), Interval(6.9, 7.1)).t == 7.0


Q0 = (0.5, 1.0, -3.0)
U0 = (1.0, 0.5, 0.2)
V0 = (-0.3, 1.0, 0.7)
OBLIQUE = Quad(V(*Q0), V(*U0), V(*V0), MAT)


@settings(deadline=None, max_examples=100)
@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0), ORIGINS)
def test_oblique_quad_hit_at_a_b(a, b, origin):
    target = tuple(Q0[i] + a * U0[i] + b * V0[i] for i in range(3))
    inside = 1e-9 < a < 1 - 1e-9 and 1e-9 < b < 1 - 1e-9
    check_planar_hit(OBLIQUE, origin, target, cross3(U0, V0), (a, b), inside)


@pytest.mark.parametrize("a, b", [(1.05, 0.5), (-0.05, 0.5), (0.5, 1.05), (0.5, -0.05), (2, 2)])
def test_oblique_quad_miss_outside(a, b):
    target = tuple(Q0[i] + a * U0[i] + b * V0[i] for i in range(3))
    n = cross3(U0, V0)
    origin = tuple(target[i] + 3.0 * n[i] for i in range(3))
    d = tuple(-x for x in n)
    assert OBLIQUE.intersect(Ray(V(*origin), V(*d)), EVERYWHERE) is None


@pytest.mark.parametrize(
    "u, v",
    [
        ((1, 0, 0), (2, 0, 0)),
        ((1, 2, 3), (-2, -4, -6)),
        ((0, 0, 0), (0, 1, 0)),
        ((1, 0, 0), (0, 0, 0)),
    ],
)
def test_degenerate_quad_raises(u, v):
    with pytest.raises(ValueError):
        Quad(V(0, 0, 0), V(*u), V(*v), MAT)


def test_a_quad_of_area_below_min_area_is_degenerate():
    # u x v = (0, 0, t): the area is t exactly, and both edges are long enough.
    assert Quad(V(0, 0, 0), V(1, 0, 0), V(1, MIN_AREA, 0), MAT)._area == MIN_AREA
    with pytest.raises(ValueError, match="quad is degenerate"):
        Quad(V(0, 0, 0), V(1, 0, 0), V(1, MIN_AREA / 2, 0), MAT)


def test_area():
    assert SQ.area() == pytest.approx(4.0)
    assert OBLIQUE.area() == pytest.approx(norm3(cross3(U0, V0)), rel=1e-14)


def test_sample_point_is_uniform_over_the_quad():
    n_samples = 16000
    counts = [[0] * 4 for _ in range(4)]
    for pt in planar_samples(OBLIQUE, n_samples, 2024, Q0, cross3(U0, V0)):
        a, b = solve_ab(Q0, U0, V0, pt)
        # In the plane (planar_samples checks that) and inside the parallelogram.
        assert -1e-12 <= a <= 1 + 1e-12 and -1e-12 <= b <= 1 + 1e-12
        counts[min(3, int(a * 4))][min(3, int(b * 4))] += 1
    expected = n_samples / 16
    chi2 = sum((c - expected) ** 2 / expected for row in counts for c in row)
    assert chi2_sf(chi2, 15) > 0.001


@pytest.mark.parametrize("p", [(0.3, 4.0, 2.0), (-2.0, -1.0, -6.0), (5.0, 5.0, -1.0)])
def test_direction_pdf_is_dist2_over_cos_area(p):
    rng = random.Random(7)
    nrm = cross3(U0, V0)
    area = norm3(nrm)
    nrm = tuple(x / area for x in nrm)
    checked = 0
    for _ in range(50):
        res = OBLIQUE.sample_direction(V(*p), rng.random(), rng.random())
        assert res is not None
        d, pdf = res
        assert math.isclose(d.length(), 1.0, abs_tol=1e-12)
        h = OBLIQUE.intersect(Ray(V(*p), d), EVERYWHERE)
        if h is None:
            continue  # a sample on the very edge can round off the quad
        checked += 1
        q = h.point.tolist()
        dist = norm3(sub3(q, p))
        cos = abs(dot3(d.tolist(), nrm))
        expected = dist * dist / (cos * area)
        assert pdf == pytest.approx(expected, rel=1e-9)
        assert OBLIQUE.direction_pdf(V(*p), h) == pytest.approx(expected, rel=1e-9)
    assert checked >= 45


def test_direction_pdf_known_value():
    # Unit-area square 1 below the point, seen straight on: pdf = 1^2 / (1 * 4).
    h = SQ.intersect(down_at(0.0, 0.0, -1.0), EVERYWHERE)
    assert SQ.direction_pdf(V(0, 0, -1), h) == pytest.approx(0.25)
    # At 45 degrees: dist^2 = 2, cos = 1/sqrt 2 -> 2 sqrt 2 / 4.
    h = SQ.intersect(Ray(V(-1, 0, -1), V(1, 0, -1)), EVERYWHERE)
    assert h.point.tolist() == pytest.approx([0.0, 0.0, -2.0])
    assert SQ.direction_pdf(V(-1, 0, -1), h) == pytest.approx(2 * math.sqrt(2) / 4)


def test_sample_direction_from_the_plane_is_refused():
    # A point in the quad's own plane sees it edge on: no useful sample.
    assert SQ.sample_direction(V(5, 0, -2), 0.5, 0.5) is None
