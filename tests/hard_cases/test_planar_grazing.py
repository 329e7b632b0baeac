"""Hard cases for quads and triangles: rays in the shape's plane, and rays through
shared edges and vertices.

Each test computes the naive formula on the same input, shows that it is wrong, and
checks rtpy's scalar Quad / Triangle and the numpy QuadSet / TriangleSet (hit_t, and
closest_hit, which goes through all_t: a different formula).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy import Lambertian, Quad, Triangle, Vec3
from rtpy.numpy_backend.quad import QuadSet
from rtpy.numpy_backend.triangle import TriangleSet
from rtpy.ray import Ray

MAT = Lambertian()
BACKENDS = ["scalar", "numpy hit_t", "numpy closest_hit"]
SHAPES = ["quad", "triangle"]
# A hit reported for a ray lying in the plane must be a point of the shape. Allowed
# distance: numpy quads accept hits up to 1e-9 edge lengths outside (EDGE_A in
# rtpy/numpy_backend/quad.py) and the edges here are shorter than 10; rounding of
# o + t d at coordinates below 50 is about 1e-14. The naive far hits are 1e-3 to 6
# away.
NEAR = 1e-8


def shape_t(backend, shape, o: np.ndarray, d: np.ndarray) -> np.ndarray:
    """t of each ray's hit with the shape (inf for a miss), t_min = 0, on one backend."""
    if backend == "scalar":
        ts = [
            shape.hit_t(Ray(Vec3(*a), Vec3(*b)), 0.0, math.inf) for a, b in zip(o, d, strict=True)
        ]
        return np.array([math.inf if t is None else t for t in ts])
    s = QuadSet([shape]) if isinstance(shape, Quad) else TriangleSet([shape])
    t_max = np.full(len(o), math.inf)
    with np.errstate(invalid="ignore", divide="ignore"):
        if backend == "numpy hit_t":
            return s.hit_t(o, d, np.zeros(len(o), dtype=np.intp), 0.0, t_max)
        return s.closest_hit(o, d, 0.0, t_max)[0]


def arr(v: Vec3) -> np.ndarray:
    return np.array([v.e0, v.e1, v.e2])


def make(kind, a, e1, e2):
    if kind == "quad":
        return Quad(Vec3(*a), Vec3(*e1), Vec3(*e2), MAT)
    return Triangle(Vec3(*a), Vec3(*(a + e1)), Vec3(*(a + e2)), MAT)


def edges(shape):
    """(corner, edge 1, edge 2) as the shape stores them."""
    if isinstance(shape, Quad):
        return arr(shape.q), arr(shape.u), arr(shape.v)
    return arr(shape.a), arr(shape.e1), arr(shape.e2)


def distance_to_shape(p, shape) -> float:
    """Distance from p to the quad or triangle: to its plane if p projects inside,
    else to the nearest edge segment."""
    a, e1, e2 = edges(shape)
    n = np.cross(e1, e2)
    n /= np.linalg.norm(n)
    h = (p - a) @ n
    g = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
    u, v = np.linalg.solve(g, [(p - a) @ e1, (p - a) @ e2])
    if isinstance(shape, Quad):
        inside = 0.0 <= u <= 1.0 and 0.0 <= v <= 1.0
        corners = [a, a + e1, a + e1 + e2, a + e2]
    else:
        inside = u >= 0.0 and v >= 0.0 and u + v <= 1.0
        corners = [a, a + e1, a + e2]
    if inside:
        return abs(h)

    def segment(x, y):
        s = np.clip((p - x) @ (y - x) / ((y - x) @ (y - x)), 0.0, 1.0)
        return np.linalg.norm(x + s * (y - x) - p)

    return min(segment(corners[i], corners[(i + 1) % len(corners)]) for i in range(len(corners)))


def naive_triangle_t(shape, o, d):
    """Moller-Trumbore with only det == 0 taken as parallel (as often written), in
    IEEE arithmetic (numpy scalars), the rejection tests as in the original paper."""
    a, e1, e2 = edges(shape)
    with np.errstate(all="ignore"):
        p = np.cross(d, e2)
        det = e1 @ p
        if det == 0.0:
            return None
        inv = 1.0 / det
        s = o - a
        u = (s @ p) * inv
        if u < 0.0 or u > 1.0:
            return None
        q = np.cross(s, e1)
        v = (d @ q) * inv
        if v < 0.0 or u + v > 1.0:
            return None
        return (e2 @ q) * inv


def in_plane_rays(kind, n, seed):
    """n tilted shapes (random corner and edges) and, for each, a ray whose origin and
    direction lie in the shape's plane (up to rounding), from outside through it."""
    rng = np.random.default_rng(seed)
    shapes, o, d = [], [], []
    for _ in range(n):
        shape = make(kind, rng.normal(size=3) * 10.0, rng.normal(size=3), rng.normal(size=3))
        a, e1, e2 = edges(shape)
        origin = a - 1.5 * e1 + 0.3 * e2
        direction = a + (e1 + e2) / 3.0 - origin
        shapes.append(shape)
        o.append(origin)
        d.append(direction / np.linalg.norm(direction))
    return shapes, np.array(o), np.array(d)


@pytest.mark.parametrize("backend", BACKENDS)
def test_rays_in_the_plane_report_no_hit_far_from_the_triangle(backend):
    """A ray lying in the plane of a tilted triangle has det = e1 . (d x e2) equal to
    rounding noise (about 1e-16) rather than 0, so the naive Moller-Trumbore divides
    noise by noise: u, v and t are arbitrary, and of 300 such rays the naive test
    reports 20 hits 0.004 to 6 units away from triangles of size about 2 (t of the
    wrong point of the line). rtpy's Triangle treats |det| below 1e-6 |e1| |e2| |d| as
    parallel, and so does the numpy TriangleSet. (Quads have no such case: Quad.hit_t
    recomputes (a, b) from the point o + t d it reports, so its hits are points of the
    quad whatever t is.)"""
    kind = "triangle"
    shapes, o, d = in_plane_rays(kind, 300, seed=7)
    naive = [naive_triangle_t(s, o[i], d[i]) for i, s in enumerate(shapes)]
    naive_far = [
        distance_to_shape(o[i] + t * d[i], shapes[i]) for i, t in enumerate(naive) if t is not None
    ]
    assert max(naive_far) > 1.0  # the naive formula reports hits far away
    far = []
    for i, shape in enumerate(shapes):
        t = shape_t(backend, shape, o[i : i + 1], d[i : i + 1])[0]
        assert not math.isnan(t)
        if math.isfinite(t):
            dist = distance_to_shape(o[i] + t * d[i], shape)
            if dist > NEAR:
                far.append(dist)
    assert not far, f"{len(far)} hits off the shape, up to {max(far):.3g} away"


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("kind", SHAPES)
def test_ray_along_the_plane_from_inside_it_is_not_a_nan_hit(kind, backend):
    """A ray exactly in the plane z = 0 of an axis-aligned shape, starting in the plane:
    n . d = 0 and n . o - D = 0, so the naive t = 0 / 0 is NaN. Naive range tests
    written `t < t_min or t > t_max` (and `a < 0 or a > 1`) are all False for NaN and
    let it through as a hit at t = NaN; so does Moller-Trumbore without a det test (u =
    0 * inf). rtpy reports a miss on every backend, never NaN."""
    shape = make(
        "quad" if kind == "quad" else "triangle",
        np.zeros(3),
        np.array([2.0, 0, 0]),
        np.array([0, 2.0, 0]),
    )
    o = np.array([[-1.0, 0.5, 0.0], [0.5, 0.5, 0.0], [0.25, -1.0, 0.0]])
    d = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]])

    with np.errstate(all="ignore"):
        for oi, di in zip(o, d, strict=True):
            if kind == "quad":
                n = arr(shape.normal)
                t = (shape.d - n @ oi) / np.float64(n @ di)
                a, b = shape._coords(Vec3(*(oi + t * di)))
                reported = not (t < 0.0 or t > math.inf) and not (a < 0 or a > 1 or b < 0 or b > 1)
            else:
                a0, e1, e2 = edges(shape)
                inv = 1.0 / np.float64(e1 @ np.cross(di, e2))
                u = ((oi - a0) @ np.cross(di, e2)) * inv
                t = (e2 @ np.cross(oi - a0, e1)) * inv
                reported = not (u < 0.0 or u > 1.0)
            assert reported and math.isnan(t)  # the naive code reports a NaN hit

    t = shape_t(backend, shape, o, d)
    assert np.isinf(t).all(), t


def shared_edge_pairs(kind):
    """Two shapes sharing an edge (a unit square split in two), with rays straight
    down through points of the shared edge and through the shared corners."""
    z = np.zeros(3)
    x, y = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    if kind == "quad":
        pair = [make("quad", z, x, y), make("quad", x, x, y)]
        points = [[1.0, 0.5, 0.0], [1.0, 0.25, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]
    else:
        pair = [make("triangle", z, x, y), make("triangle", x + y, -x, -y)]
        points = [[0.5, 0.5, 0.0], [0.25, 0.75, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    o = np.array(points) + np.array([0.0, 0.0, 1.0])
    d = np.tile([0.0, 0.0, -1.0], (len(points), 1))
    return pair, o, d


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("kind", SHAPES)
def test_rays_through_a_shared_edge_or_vertex_hit(kind, backend):
    """Rays through the edge or the corner two shapes share. With strict inequalities
    (0 < u, u + v < 1: 'inside' taken literally) the naive test rejects the point in
    both shapes and the ray slips through the seam: light leaks through a closed
    mesh. rtpy's tests are inclusive: at least one shape reports the hit, at t = 1
    exactly (the points and directions are exact in binary)."""
    pair, o, d = shared_edge_pairs(kind)
    for oi, di in zip(o, d, strict=True):
        hits = 0
        for shape in pair:
            a, e1, e2 = edges(shape)
            # the exact coordinates of the point (numbers here are exact in binary)
            g = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
            u, v = np.linalg.solve(g, [(oi + di - a) @ e1, (oi + di - a) @ e2])
            if kind == "quad":
                hits += 0.0 < u < 1.0 and 0.0 < v < 1.0
            else:
                hits += 0.0 < u and 0.0 < v and u + v < 1.0
        assert hits == 0  # the naive strict test leaks

    best = np.minimum(*(shape_t(backend, s, o, d) for s in pair))
    np.testing.assert_array_equal(best, np.ones(len(o)))
