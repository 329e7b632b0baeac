"""Tests for rtpy.triangle: hits, edges and vertices, faces, barycentric (u, v),
degenerate triangles and uniform area sampling."""

from __future__ import annotations

import math
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy._checks import MIN_AREA
from rtpy.hit_info import HitInfo
from rtpy.interval import Interval
from rtpy.materials import Lambertian
from rtpy.ray import Ray
from rtpy.testing import chi2_sf
from rtpy.triangle import Triangle

from .vectors import ORIGINS, V, check_planar_hit, cross3, dot3, norm3, planar_samples, sub3

MAT = Lambertian()
EVERYWHERE = Interval(0.0, math.inf)


def barycentric_bc(a, b, c, p):
    """Weights of b and c at p (in the triangle's plane) from signed sub-triangle areas."""
    n = cross3(sub3(b, a), sub3(c, a))
    nn = dot3(n, n)
    wb = dot3(cross3(sub3(p, a), sub3(c, a)), n) / nn  # area(a, p, c) / area(a, b, c)
    wc = dot3(cross3(sub3(b, a), sub3(p, a)), n) / nn  # area(a, b, p) / area(a, b, c)
    return wb, wc


# Right triangle (0,0), (2,0), (0,2) in the plane z = 0; front face +z; exact arithmetic.
TRI = Triangle(V(0, 0, 0), V(2, 0, 0), V(0, 2, 0), MAT)


def down_at(x, y):
    return Ray(V(x, y, 3), V(0, 0, -1))


def test_hit_inside():
    h = TRI.intersect(down_at(0.5, 0.25), EVERYWHERE)
    assert h is not None
    assert h.t == 3.0
    assert h.point.tolist() == [0.5, 0.25, 0.0]
    assert h.normal.tolist() == [0.0, 0.0, 1.0]
    assert h.front_face is True
    assert (h.u, h.v) == pytest.approx((0.25, 0.125), abs=1e-15)
    assert h.obj is TRI and h.material is MAT


def test_back_face():
    h = TRI.intersect(Ray(V(0.5, 0.25, -4), V(0, 0, 1)), EVERYWHERE)
    assert h is not None
    assert h.t == 4.0
    assert h.front_face is False
    assert h.normal.tolist() == [0.0, 0.0, -1.0]
    assert (h.u, h.v) == pytest.approx((0.25, 0.125), abs=1e-15)


@pytest.mark.parametrize("x, y", [(1.5, 1.5), (-0.1, 0.5), (0.5, -0.1), (3.0, 0.0), (1.01, 1.0)])
def test_miss_outside(x, y):
    assert TRI.intersect(down_at(x, y), EVERYWHERE) is None


@pytest.mark.parametrize(
    "x, y, u, v",
    [
        (1.0, 0.0, 0.5, 0.0),  # edge a-b
        (0.0, 1.0, 0.0, 0.5),  # edge a-c
        (1.0, 1.0, 0.5, 0.5),  # edge b-c
        (0.0, 0.0, 0.0, 0.0),  # vertex a
        (2.0, 0.0, 1.0, 0.0),  # vertex b
        (0.0, 2.0, 0.0, 1.0),  # vertex c
    ],
)
def test_edges_and_vertices_count_as_hits(x, y, u, v):
    h = TRI.intersect(down_at(x, y), EVERYWHERE)
    assert h is not None
    assert h.t == 3.0
    assert (h.u, h.v) == pytest.approx((u, v), abs=1e-15)


def test_parallel_ray_misses():
    assert TRI.intersect(Ray(V(-1, 0.5, 0), V(1, 0, 0)), EVERYWHERE) is None
    assert TRI.intersect(Ray(V(-1, 0.5, 1), V(1, 0.3, 0)), EVERYWHERE) is None


def test_pointing_away_and_interval():
    assert TRI.intersect(Ray(V(0.5, 0.5, 3), V(0, 0, 1)), EVERYWHERE) is None
    assert TRI.intersect(down_at(0.5, 0.5), Interval(0.0, 2.9)) is None
    assert TRI.intersect(down_at(0.5, 0.5), Interval(3.1, 10.0)) is None
    assert TRI.intersect(down_at(0.5, 0.5), Interval(2.9, 3.1)).t == 3.0


A0, B0, C0 = (0.5, -1.0, 2.0), (2.5, 0.0, 1.5), (1.0, 1.5, 3.0)
GENERAL = Triangle(V(*A0), V(*B0), V(*C0), MAT)


@settings(deadline=None, max_examples=100)
@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0), ORIGINS)
def test_general_triangle_hit_has_barycentric_uv(s, t, origin):
    wb, wc = (s, t) if s + t <= 1.0 else (1.0 - s, 1.0 - t)
    target = tuple(A0[i] + wb * (B0[i] - A0[i]) + wc * (C0[i] - A0[i]) for i in range(3))
    inside = wb > 1e-9 and wc > 1e-9 and wb + wc < 1 - 1e-9
    check_planar_hit(GENERAL, origin, target, cross3(sub3(B0, A0), sub3(C0, A0)), (wb, wc), inside)


# Edges 5e5 long and 1e-6 apart at their ends: |e1|^2 |e2|^2 - (e1 . e2)^2 = 0.5
# cancels to 0 in floating point, though the area is 0.35.
SLIVER = Triangle(V(1, 0, 0), V(1 + 5e5, -1e-6, 0), V(1 + 5e5, 0, 1e-6), MAT)


@pytest.mark.parametrize("wb, wc", [(0.3, 0.2), (0.0, 1.0), (1.0, 0.0), (0.5, 0.5), (0.0, 0.0)])
def test_long_thin_triangle_has_finite_uv_in_the_unit_square(wb, wc):
    """The sliver's (u, v): no division by the cancelled determinant, values in [0, 1]
    (their accuracy is lost to the numerators' cancellation: a precision effect)."""
    point = SLIVER.a + SLIVER.e1 * wb + SLIVER.e2 * wc
    hit = HitInfo(point, SLIVER.normal, 1.0, True, MAT, SLIVER)
    assert all(0.0 <= x <= 1.0 for x in SLIVER.surface_uv(hit))


@pytest.mark.parametrize("wb, wc", [(0.6, 0.6), (-0.05, 0.5), (0.5, -0.05), (1.2, -0.1)])
def test_general_triangle_miss_outside(wb, wc):
    target = tuple(A0[i] + wb * (B0[i] - A0[i]) + wc * (C0[i] - A0[i]) for i in range(3))
    n = cross3(sub3(B0, A0), sub3(C0, A0))
    origin = tuple(target[i] + 2.0 * n[i] for i in range(3))
    assert GENERAL.intersect(Ray(V(*origin), V(*(-x for x in n))), EVERYWHERE) is None


@pytest.mark.parametrize(
    "a, b, c",
    [
        ((0, 0, 0), (1, 1, 1), (2, 2, 2)),
        ((0, 0, 0), (0, 0, 0), (0, 1, 0)),
        ((1, 2, 3), (1, 2, 3), (1, 2, 3)),
        ((0, 0, 0), (1, 0, 0), (-3, 0, 0)),
    ],
)
def test_degenerate_triangle_raises(a, b, c):
    with pytest.raises(ValueError):
        Triangle(V(*a), V(*b), V(*c), MAT)


def test_a_triangle_of_twice_its_area_below_min_area_is_degenerate():
    # (b - a) x (c - a) = (0, 0, t): twice the area is t exactly.
    assert Triangle(V(0, 0, 0), V(1, 0, 0), V(1, MIN_AREA, 0), MAT)._area == MIN_AREA / 2
    with pytest.raises(ValueError, match="triangle a, b, c is degenerate"):
        Triangle(V(0, 0, 0), V(1, 0, 0), V(1, MIN_AREA / 2, 0), MAT)


def test_area():
    assert TRI.area() == pytest.approx(2.0)
    expected = 0.5 * norm3(cross3(sub3(B0, A0), sub3(C0, A0)))
    assert GENERAL.area() == pytest.approx(expected, rel=1e-14)


def test_sample_point_is_uniform_over_the_triangle():
    """Chi-square over the 16 equal sub-triangles of a 4 x 4 barycentric subdivision."""
    n_samples = 16000
    counts: dict[tuple[int, int, bool], int] = {}
    n = cross3(sub3(B0, A0), sub3(C0, A0))
    for pt in planar_samples(GENERAL, n_samples, 31337, A0, n):
        wb, wc = barycentric_bc(A0, B0, C0, pt)
        assert wb >= -1e-12 and wc >= -1e-12 and wb + wc <= 1 + 1e-12
        fb, fc = wb * 4, wc * 4
        i, j = min(3, int(fb)), min(3, int(fc))
        up = (fb - i) + (fc - j) < 1.0
        if i + j > 3:  # rounding at the hypotenuse
            i, j, up = (i - 1, j, False) if i > j else (i, j - 1, False)
        key = (i, j, up)
        counts[key] = counts.get(key, 0) + 1
    # 10 upward cells (i + j <= 3) and 6 downward cells (i + j <= 2), all of equal area.
    cells = [(i, j, True) for i in range(4) for j in range(4 - i)]
    cells += [(i, j, False) for i in range(3) for j in range(3 - i)]
    assert len(cells) == 16
    assert set(counts) <= set(cells)
    expected = n_samples / 16
    chi2 = sum((counts.get(k, 0) - expected) ** 2 / expected for k in cells)
    assert chi2_sf(chi2, 15) > 0.001


def test_direction_pdf_matches_dist2_over_cos_area():
    rng = random.Random(8)
    p = (1.0, 0.0, -2.0)
    n = cross3(sub3(B0, A0), sub3(C0, A0))
    area = 0.5 * norm3(n)
    nn = tuple(x / norm3(n) for x in n)
    checked = 0
    for _ in range(40):
        res = GENERAL.sample_direction(V(*p), rng.random(), rng.random())
        assert res is not None
        d, pdf = res
        h = GENERAL.intersect(Ray(V(*p), d), EVERYWHERE)
        if h is None:
            continue
        checked += 1
        dist = norm3(sub3(h.point.tolist(), p))
        expected = dist * dist / (abs(dot3(d.tolist(), nn)) * area)
        assert pdf == pytest.approx(expected, rel=1e-9)
        assert GENERAL.direction_pdf(V(*p), h) == pytest.approx(expected, rel=1e-9)
    assert checked >= 36
