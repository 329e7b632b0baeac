"""Tests for rtpy.sphere: intersections against closed forms, precision on huge spheres,
surface coordinates (RTIOW) and light sampling by solid angle."""

from __future__ import annotations

import math
import random
from decimal import Decimal, getcontext

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rtpy.hit_info import HitInfo
from rtpy.interval import Interval
from rtpy.materials import Lambertian
from rtpy.ray import Ray
from rtpy.sphere import Sphere, nearer_root, one_minus_cos_max
from rtpy.testing import chi2_sf

from .vectors import V, dot3, norm3, sub3

MAT = Lambertian()
EVERYWHERE = Interval(0.0, math.inf)


def textbook_roots(o, d, c, r):
    """Both roots of |o + t d - c|^2 = r^2 by the quadratic formula (fine for small scenes)."""
    oc = sub3(o, c)
    a = dot3(d, d)
    b = 2.0 * dot3(d, oc)
    cc = dot3(oc, oc) - r * r
    disc = b * b - 4 * a * cc
    if disc < 0:
        return None
    s = math.sqrt(disc)
    return (-b - s) / (2 * a), (-b + s) / (2 * a)


def exact_first_root(o, d, c, r, t_min=0.0):
    """The smallest root > t_min of |o + t d - c|^2 = r^2, in 60-digit decimal arithmetic
    from the exact float inputs."""
    getcontext().prec = 60
    o = [Decimal(x) for x in o]
    d = [Decimal(x) for x in d]
    c = [Decimal(x) for x in c]
    r = Decimal(r)
    oc = [o[i] - c[i] for i in range(3)]
    a = sum(d[i] * d[i] for i in range(3))
    h = -sum(d[i] * oc[i] for i in range(3))
    cc = sum(oc[i] * oc[i] for i in range(3)) - r * r
    disc = h * h - a * cc
    assert disc >= 0
    s = disc.sqrt()
    for t in sorted(((h - s) / a, (h + s) / a)):
        if t > t_min:
            return float(t)
    return None


def hit(sphere, origin, direction, interval=EVERYWHERE):
    return sphere.intersect(Ray(origin, direction), interval)


# --- analytic hits ---------------------------------------------------------------------


@pytest.mark.parametrize("dist", [2.0, 10.0, 1000.0])
def test_ray_through_center_from_outside(dist):
    c, r = V(1, -2, 3), 1.5
    s = Sphere(c, r, MAT)
    h = hit(s, c + V(0, 0, dist), V(0, 0, -1))
    assert h is not None
    assert h.t == pytest.approx(dist - r, rel=1e-14)
    assert h.point.tolist() == pytest.approx([1.0, -2.0, 3.0 + r], rel=1e-14)
    assert h.normal.tolist() == pytest.approx([0.0, 0.0, 1.0], abs=1e-14)
    assert h.front_face is True
    assert h.material is MAT and h.obj is s


def test_non_unit_direction_scales_t():
    c, r = V(0, 0, 0), 2.0
    s = Sphere(c, r, MAT)
    h = hit(s, V(10, 0, 0), V(-4, 0, 0))
    assert h.t == pytest.approx((10.0 - 2.0) / 4.0, rel=1e-14)
    assert h.point.tolist() == pytest.approx([2.0, 0.0, 0.0], abs=1e-13)


@pytest.mark.parametrize("b", [0.0, 0.3, 0.9, 1.4, 1.499])
def test_offset_parallel_rays(b):
    """Ray along -z at impact parameter b: t = D - sqrt(r^2 - b^2)."""
    c, r, dist = V(-3, 2, 1), 1.5, 7.0
    s = Sphere(c, r, MAT)
    o = c + V(b * 0.6, b * 0.8, dist)
    h = hit(s, o, V(0, 0, -1))
    assert h is not None
    assert h.t == pytest.approx(dist - math.sqrt(r * r - b * b), rel=1e-12)
    expected_n = [b * 0.6 / r, b * 0.8 / r, math.sqrt(r * r - b * b) / r]
    assert h.normal.tolist() == pytest.approx(expected_n, abs=1e-12)


@pytest.mark.parametrize(
    "o, d",
    [
        ((5.0, 4.0, -3.0), (-1.0, -0.7, 0.55)),
        ((0.1, 9.0, 0.2), (0.01, -1.0, -0.02)),
        ((-6.0, -6.0, -6.0), (1.0, 1.1, 0.9)),
    ],
)
def test_oblique_rays_match_quadratic_formula(o, d):
    c, r = (0.5, -0.25, 0.75), 2.0
    s = Sphere(V(*c), r, MAT)
    roots = textbook_roots(o, d, c, r)
    assert roots is not None
    h = hit(s, V(*o), V(*d))
    assert h is not None
    assert h.t == pytest.approx(roots[0], rel=1e-12)
    assert h.front_face


def test_misses():
    s = Sphere(V(0, 0, 0), 1.0, MAT)
    # Passing by.
    assert hit(s, V(0, 1.5, 5), V(0, 0, -1)) is None
    assert hit(s, V(-5, -5, 0), V(1, 0, 0)) is None
    # Pointing away (the line goes through the sphere, the ray does not).
    assert hit(s, V(0, 0, 5), V(0, 0, 1)) is None
    assert hit(s, V(3, 0, 0), V(1, 0.1, 0)) is None
    assert s.hit_t(Ray(V(0, 0, 5), V(0, 0, 1)), 0.0, math.inf) is None


@pytest.mark.parametrize("rel", [1e-3, 1e-6, 1e-9])
def test_near_tangent_rays(rel):
    r, dist = 2.0, 10.0
    s = Sphere(V(0, 0, 0), r, MAT)
    inside_b = r * (1.0 - rel)
    h = hit(s, V(0, inside_b, dist), V(0, 0, -1))
    assert h is not None
    expected = dist - math.sqrt((r - inside_b) * (r + inside_b))
    assert h.t == pytest.approx(expected, rel=1e-12)
    assert h.front_face
    assert hit(s, V(0, r * (1.0 + rel), dist), V(0, 0, -1)) is None


def test_exact_tangent_if_hit_is_at_touch_point():
    s = Sphere(V(0, 0, 0), 1.0, MAT)
    h = hit(s, V(0, 1, 10), V(0, 0, -1))
    if h is not None:
        assert h.t == pytest.approx(10.0, rel=1e-12)
        assert h.point.tolist() == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)


@pytest.mark.parametrize("direction, t_expected", [((1, 0, 0), 2.5), ((-1, 0, 0), 3.5)])
def test_ray_from_inside_hits_far_side(direction, t_expected):
    c, r = V(1, 1, 1), 3.0
    s = Sphere(c, r, MAT)
    o = c + V(0.5, 0, 0)
    d = V(*direction)
    h = hit(s, o, d)
    assert h is not None
    assert h.t == pytest.approx(t_expected, rel=1e-14)
    assert h.front_face is False
    # The normal faces the ray (points inward here).
    assert h.normal.tolist() == pytest.approx([-direction[0], 0.0, 0.0], abs=1e-14)
    assert h.normal.e0 * d.e0 < 0.0


def test_interval_is_respected():
    s = Sphere(V(0, 0, 0), 1.0, MAT)
    o, d = V(0, 0, 5), V(0, 0, -1)  # roots at t = 4 and t = 6
    assert hit(s, o, d, Interval(0.0, math.inf)).t == pytest.approx(4.0)
    # t_min past the near root: the far one.
    h = hit(s, o, d, Interval(4.5, math.inf))
    assert h.t == pytest.approx(6.0)
    assert h.front_face is False
    # t_max before the near root: nothing.
    assert hit(s, o, d, Interval(0.0, 3.9)) is None
    # Between the roots with both excluded.
    assert hit(s, o, d, Interval(4.1, 5.9)) is None
    # Past both roots.
    assert hit(s, o, d, Interval(6.1, math.inf)) is None
    assert s.hit_t(Ray(o, d), 4.5, 7.0) == pytest.approx(6.0)


def test_negative_radius_refused():
    with pytest.raises(ValueError):
        Sphere(V(0, 0, 0), -1.0, MAT)
    with pytest.raises(ValueError):
        Sphere(V(0, 0, 0), 0.0, MAT)


# --- precision on huge spheres ---------------------------------------------------------


@pytest.mark.parametrize("radius", [1e5, 3e5, 1e6])
@pytest.mark.parametrize("height", [1e5, 1.0, 1e-3])
@pytest.mark.parametrize(
    "direction",
    [
        (0.0, -1.0, 0.0),
        (0.3, -1.0, 0.2),
        (1.0, -0.2, -0.4),
        (1.0, -0.002, 0.3),  # toward the horizon
        (1.0, -1e-4, 0.3),  # grazing
        (0.05, -0.01, 1.0),
    ],
)
def test_huge_sphere_hit_point_lies_on_surface(radius, height, direction):
    """A ground-like sphere seen from far (1e5) and from just above it: the hit lies on
    the surface to 1e-9 relative precision, and t matches a 60-digit solution."""
    c = (1234.5, -radius, -4321.25)
    # Almost straight above the top of the sphere: `height` above the surface (to < 1e-6).
    o = (1235.0, height, -4321.0)
    s = Sphere(V(*c), radius, MAT)
    ray = Ray(V(*o), V(*direction))
    h = s.intersect(ray, Interval(0.0, math.inf))
    # Does the line hit the sphere at all? (decided in exact arithmetic)
    getcontext().prec = 60
    oc = [Decimal(o[i]) - Decimal(c[i]) for i in range(3)]
    dd = [Decimal(x) for x in direction]
    a = sum(x * x for x in dd)
    hh = -sum(dd[i] * oc[i] for i in range(3))
    disc = hh * hh - a * (sum(x * x for x in oc) - Decimal(radius) ** 2)
    if disc < 0 or hh < 0:
        assert h is None
        return
    assert h is not None
    t_exact = exact_first_root(o, direction, c, radius)
    dlen = norm3(direction)
    assert abs(h.t - t_exact) * dlen <= 1e-9 * radius
    p = h.point
    rel = abs(norm3(sub3(p.tolist(), c)) - radius) / radius
    assert rel < 1e-9
    # Not only the re-projected point: o + t d itself is on the surface.
    q = ray.at(h.t)
    rel = abs(norm3(sub3(q.tolist(), c)) - radius) / radius
    assert rel < 1e-9
    assert h.front_face
    assert dot3(h.normal.tolist(), direction) <= 0.0


@pytest.mark.parametrize("dist", [1e4, 1e6, 2e6])
@pytest.mark.parametrize("b", [0.0, 0.5, 0.9, 0.999])
def test_small_sphere_far_away_is_hit_accurately(dist, b):
    """A unit sphere 1e4..2e6 away (up to the most two points of the contract's range
    of coordinates, [-1e6, 1e6], lie apart on one axis): the textbook discriminant
    h^2 - (|oc|^2 - r^2) loses everything to cancellation here; the hit must still be
    accurate to a few ulps of dist."""
    c, o, d = (0.0, 0.0, -dist / 2), (b, 0.0, dist / 2), (0.0, 0.0, -1.0)
    s = Sphere(V(*c), 1.0, MAT)
    ray = Ray(V(*o), V(*d))
    h = s.intersect(ray, EVERYWHERE)
    assert h is not None
    tol = 8 * math.ulp(dist)
    assert abs(h.t - exact_first_root(o, d, c, 1.0)) <= tol
    assert abs(norm3(sub3(ray.at(h.t).tolist(), c)) - 1.0) <= tol
    assert h.normal.tolist() == pytest.approx([b, 0.0, math.sqrt(1 - b * b)], abs=1e-6)


# --- random rays from outside ------------------------------------------------------------

unit_coord = st.floats(-1.0, 1.0)


@settings(deadline=None, max_examples=150)
@given(
    st.tuples(st.floats(-100, 100), st.floats(-100, 100), st.floats(-100, 100)),
    st.floats(0.01, 100.0),
    st.tuples(unit_coord, unit_coord, unit_coord),
    st.floats(1.01, 100.0),
    st.tuples(unit_coord, unit_coord, unit_coord),
    st.booleans(),
)
def test_random_rays_aimed_at_the_sphere_hit_it(c, r, og, k, tg, normalize):
    ln, lt = norm3(og), norm3(tg)
    assume(ln > 1e-2 and lt > 1e-2)
    og = tuple(x / ln for x in og)
    tg = tuple(x / lt for x in tg)
    o = tuple(c[i] + og[i] * r * k for i in range(3))
    target = tuple(c[i] + tg[i] * r for i in range(3))
    d = sub3(target, o)
    if normalize:
        dl = norm3(d)
        d = tuple(x / dl for x in d)
    # Skip lines that only graze the silhouette: distance from center to the line < r.
    oc = sub3(c, o)
    proj = dot3(oc, d) / dot3(d, d)
    f = norm3(tuple(oc[i] - proj * d[i] for i in range(3)))
    assume(f < r * (1.0 - 1e-6))

    s = Sphere(V(*c), r, MAT)
    h = s.intersect(Ray(V(*o), V(*d)), Interval(0.0, math.inf))
    assert h is not None
    assert abs(norm3(sub3(h.point.tolist(), c)) - r) <= 1e-9 * r
    assert dot3(h.normal.tolist(), d) <= 0.0
    assert h.front_face
    assert math.isclose(h.normal.length(), 1.0, abs_tol=1e-12)
    t_exact = exact_first_root(o, d, c, r)
    assert abs(h.t - t_exact) * norm3(d) <= 1e-9 * (r * k + r)
    # The target is on the sphere, so the first hit is no farther than it.
    t_target = 1.0 if not normalize else norm3(sub3(target, o))
    assert h.t <= t_target * (1.0 + 1e-9)


# --- surface coordinates ------------------------------------------------------------------


@pytest.mark.parametrize(
    "offset, u, v",
    [
        ((1, 0, 0), 0.5, 0.5),  # +x
        ((0, 0, -1), 0.75, 0.5),  # -z
        ((0, 0, 1), 0.25, 0.5),  # +z
        ((0, 1, 0), 0.5, 1.0),  # north pole
        ((0, -1, 0), 0.5, 0.0),  # south pole
    ],
)
def test_surface_uv_from_hits_as_rtiow(offset, u, v):
    c, r = V(1, 2, 3), 2.0
    s = Sphere(c, r, MAT)
    off = V(*offset)
    h = hit(s, c + off * 10.0, -off)
    assert h is not None
    if offset[1] != 0:  # at the poles only v is defined
        assert h.v == pytest.approx(v, abs=1e-12)
    else:
        assert (h.u, h.v) == pytest.approx((u, v), abs=1e-12)


def test_surface_uv_minus_x_is_the_seam():
    c, r = V(0, 0, 0), 1.0
    s = Sphere(c, r, MAT)
    h = hit(s, V(-5, 0, 0), V(1, 0, 0))
    assert h.v == pytest.approx(0.5)
    assert min(h.u, 1.0 - h.u) == pytest.approx(0.0, abs=1e-12)


@settings(deadline=None, max_examples=60)
@given(st.floats(0.01, 2 * math.pi - 0.01), st.floats(0.01, math.pi - 0.01))
def test_surface_uv_spherical_angles(phi, theta):
    """RTIOW: phi from -x toward +z around +y, theta from -y:
    n = (-cos phi sin theta, -cos theta, sin phi sin theta) has (u, v) = (phi/2pi, theta/pi)."""
    c, r = V(3, -1, 2), 0.5
    s = Sphere(c, r, MAT)
    n = V(-math.cos(phi) * math.sin(theta), -math.cos(theta), math.sin(phi) * math.sin(theta))
    hi = HitInfo(c + n * r, n, 1.0, True, MAT, s)
    assert hi.u == pytest.approx(phi / (2 * math.pi), abs=1e-9)
    assert hi.v == pytest.approx(theta / math.pi, abs=1e-9)


# --- sampling as a light ----------------------------------------------------------------------


def cone_cos_max(p, c, r) -> float:
    d = norm3(sub3(c, p))
    return math.sqrt(d * d - r * r) / d


@pytest.mark.parametrize("dist", [1.5, 3.0, 50.0, 1e4])
def test_sample_direction_from_outside_lies_in_cone_with_constant_pdf(dist):
    c, r = (0.5, -1.0, 2.0), 0.75
    p = (c[0] + dist * 0.6, c[1] - dist * 0.8, c[2])
    s = Sphere(V(*c), r, MAT)
    cos_max = cone_cos_max(p, c, r)
    # 1 - cos_max computed without cancellation
    one_minus = (r * r / dist**2) / (1.0 + cos_max)
    cone_solid_angle = 2.0 * math.pi * one_minus
    axis = tuple(x / dist for x in sub3(c, p))
    hits = 0
    n = 0
    for i in range(20):
        for j in range(20):
            r1, r2 = (i + 0.5) / 20, (j + 0.37) / 20
            res = s.sample_direction(V(*p), r1, r2)
            assert res is not None
            d, pdf = res
            n += 1
            assert math.isclose(d.length(), 1.0, abs_tol=1e-12)
            assert dot3(d.tolist(), axis) >= cos_max - 1e-12
            assert pdf * cone_solid_angle == pytest.approx(1.0, rel=1e-9)
            h = s.intersect(Ray(V(*p), d), Interval(0.0, math.inf))
            if h is not None:
                hits += 1
                assert s.direction_pdf(V(*p), h) == pytest.approx(pdf, rel=1e-9)
    # Directions in the cone hit the sphere (bar rounding at the silhouette).
    assert hits >= n - 2


def test_sample_direction_is_uniform_in_the_cone():
    """cos(theta) of the samples is uniform on [cos_max, 1] (equal solid angle per bin)."""
    c, r = (0.0, 0.0, 0.0), 1.0
    p = (0.0, 0.0, 2.5)
    s = Sphere(V(*c), r, MAT)
    cos_max = cone_cos_max(p, c, r)
    rng = random.Random(99)
    bins = [0] * 8
    n = 8000
    sx = sy = 0.0
    for _ in range(n):
        d, _ = s.sample_direction(V(*p), rng.random(), rng.random())
        cos_t = -d.e2  # axis is -z
        k = min(7, int((1.0 - cos_t) / (1.0 - cos_max) * 8))
        bins[k] += 1
        sx += d.e0
        sy += d.e1
    expected = n / 8
    chi2 = sum((b - expected) ** 2 / expected for b in bins)
    assert chi2_sf(chi2, 7) > 0.001
    # Azimuth unbiased: the mean transverse component is ~0 (|component| <= sin_max).
    sin_max = r / 2.5
    assert abs(sx / n) < 4 * sin_max / math.sqrt(2 * n)
    assert abs(sy / n) < 4 * sin_max / math.sqrt(2 * n)


def test_direction_pdf_integrates_to_one_over_directions():
    """E over directions drawn from a wider cone q of pdf(w) / q(w) is 1."""
    c, r = (0.0, 0.0, 0.0), 1.0
    p = (0.0, 2.0, 0.0)  # cone half-angle 30 degrees
    s = Sphere(V(*c), r, MAT)
    rng = random.Random(5)
    cos_wide = 0.5  # a 60 degree cone around -y contains the sphere
    q = 1.0 / (2.0 * math.pi * (1.0 - cos_wide))
    n = 20000
    acc = acc2 = 0.0
    for _ in range(n):
        cos_t = 1.0 - rng.random() * (1.0 - cos_wide)
        sin_t = math.sqrt(1.0 - cos_t * cos_t)
        phi = 2.0 * math.pi * rng.random()
        d = V(sin_t * math.cos(phi), -cos_t, sin_t * math.sin(phi))
        h = s.intersect(Ray(V(*p), d), Interval(0.0, math.inf))
        x = s.direction_pdf(V(*p), h) / q if h is not None else 0.0
        acc += x
        acc2 += x * x
    mean = acc / n
    var = acc2 / n - mean * mean
    assert abs(mean - 1.0) < 4.0 * math.sqrt(var / n)


def test_sample_direction_from_inside_uses_area_pdf():
    c, r = (0.0, 0.0, 0.0), 2.0
    p = (0.3, -0.2, 0.5)
    s = Sphere(V(*c), r, MAT)
    area = 4.0 * math.pi * r * r
    for r1, r2 in ((0.1, 0.2), (0.5, 0.5), (0.9, 0.7), (0.33, 0.99)):
        res = s.sample_direction(V(*p), r1, r2)
        assert res is not None
        d, pdf = res
        h = s.intersect(Ray(V(*p), d), Interval(0.0, math.inf))
        assert h is not None and not h.front_face
        q = h.point.tolist()
        dist = norm3(sub3(q, p))
        n_out = tuple(x / r for x in sub3(q, c))
        cos_l = abs(dot3(n_out, d.tolist()))
        assert pdf == pytest.approx(dist * dist / (cos_l * area), rel=1e-9)
        assert s.direction_pdf(V(*p), h) == pytest.approx(pdf, rel=1e-9)


def test_sample_point_uniform_on_sphere():
    c, r = V(1, 2, 3), 0.5
    s = Sphere(c, r, MAT)
    assert s.area() == pytest.approx(4 * math.pi * 0.25)
    rng = random.Random(3)
    n = 4000
    zsum = 0.0
    for _ in range(n):
        p, nrm = s.sample_point(rng.random(), rng.random())
        off = (p - c).tolist()
        assert norm3(off) == pytest.approx(r, rel=1e-12)
        assert nrm.tolist() == pytest.approx([x / r for x in off], abs=1e-12)
        zsum += nrm.e2
    # Archimedes: z of a uniform point on the sphere is uniform on [-1, 1].
    assert abs(zsum / n) < 4 * math.sqrt(1.0 / 3.0 / n)


# --- the cone's formulas, shared with the numpy backend --------------------------------


@pytest.mark.parametrize("r_over_d", [0.5, 1e-3, 1e-9, 1e-150])
def test_one_minus_cos_max_keeps_its_precision_for_tiny_cones(r_over_d):
    """1 - cos_max against exact decimals; the naive 1 - sqrt(1 - s^2) is 0 below 1e-8."""
    getcontext().prec = 60
    s2 = Decimal(r_over_d * r_over_d)
    exact = s2 / (1 + (1 - s2).sqrt())  # = 1 - sqrt(1 - s^2), in 60 digits
    got = one_minus_cos_max(r_over_d * r_over_d, 1.0)
    assert float(abs(Decimal(got) - exact) / exact) < 4e-16


@given(
    st.floats(1.5, 1e6),
    st.floats(0.0, 1.0, exclude_max=True),
)
def test_nearer_root_meets_the_sphere_first(distance, r1):
    """The point at the root lies on the sphere, and it is the nearer of its two points."""
    radius = 1.0
    d2, r2 = distance * distance, radius * radius
    cos_t = 1.0 - r1 * one_minus_cos_max(r2, d2)
    sin2_t = max(0.0, 1.0 - cos_t * cos_t)
    t = nearer_root(d2, r2, distance, cos_t, sin2_t)
    # The point p + t w, with the center at distance D along the axis: its distance to
    # the center by the law of cosines.
    to_center2 = t * t - 2.0 * t * distance * cos_t + d2
    assert to_center2 == pytest.approx(r2, rel=1e-6, abs=1e-9 * d2)
    assert t <= distance * cos_t + 1e-9 * distance  # before the chord's midpoint
