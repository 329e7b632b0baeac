"""TriangleSet against rtpy/triangle.py and rtpy/mesh.py: the scalar hit_t, to rounding,
and the shading normals and light densities of smooth triangles."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings

from rtpy import Triangle
from rtpy.hit_info import HitInfo
from rtpy.io.bundled import bundled_dir
from rtpy.io.obj import read_obj
from rtpy.mesh import Mesh, SmoothTriangle, Transform
from rtpy.numpy_backend.scene import BatchScene
from rtpy.numpy_backend.triangle import TriangleSet
from rtpy.ray import Ray
from rtpy.scene import Scene
from rtpy.sphere import Sphere

from .geometry_checks import MAT, V, arr, check_planar, planar_shape, unit_pair, vec


@settings(max_examples=300)
@given(vec, vec, vec, vec, unit_pair)
def test_triangle_t_matches_scalar(a, b, c, origin, uv):
    tri = planar_shape(lambda: Triangle(V(a), V(b), V(c), MAT))
    assume(tri is not None)
    e1, e2 = arr(tri.e1), arr(tri.e2)

    def edge_distance(o, d, t):
        r = tri._barycentric(Ray(V(o), V(d)))
        if r is None:  # the scalar missed: how far outside is the numpy hit?
            p = o + t * d - np.array(a)
            m = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
            bu, bv = np.linalg.solve(m, [p @ e1, p @ e2])
        else:
            bu, bv = r[1], r[2]
        return min(abs(bu), abs(bv), abs(1 - bu - bv), abs(bu - 1))

    target = np.array(a) + uv[0] * e1 + uv[1] * e2 * 0.5
    check_planar(tri, TriangleSet([tri]), origin, target, edge_distance)


def teapot_scene():
    """The bundled teapot (smooth triangles), a flat triangle and a sphere."""
    obj = read_obj(bundled_dir() / "teapot.obj")
    mesh = Mesh(obj.positions, obj.normals, obj.triangles, MAT, Transform(rotate=V((-90, 20, 0))))
    flat = Triangle(V((-4, -1, -4)), V((4, -1, -4)), V((0, -1, 4)), MAT)
    return Scene([*mesh.triangles, flat, Sphere(V((0, 4, 0)), 0.5, MAT)])


def test_surface_uv_equals_scalar_on_a_long_thin_triangle():
    """A sliver (edges 5e5 long, 1e-6 apart), on which the normal equations lose every
    digit: the same (u, v) as Triangle.surface_uv, bit for bit, and the right ones.
    Here Cramer's rule divides products of at most 0.5 (and their difference) by the
    determinant 0.5, and the points' own rounding moves them by ~1e-10 along the
    triangle but ~1e-16 across it (the only direction where 1e-6 is the scale), so a
    few ulps of 1 bound the error; 1e-12 leaves room and catches any lost digit."""
    sliver = Triangle(V((1, 0, 0)), V((1 + 5e5, -1e-6, 0)), V((1 + 5e5, 0, 1e-6)), MAT)
    weights = np.array([[0.3, 0.2], [0.0, 1.0], [1.0, 0.0], [0.5, 0.5], [0.1, 0.0]])
    points = arr(sliver.a) + weights[:, :1] * arr(sliver.e1) + weights[:, 1:] * arr(sliver.e2)
    u, v = TriangleSet([sliver]).surface_uv(np.zeros(len(points), dtype=np.int64), points)
    for n, p in enumerate(points):
        hit = HitInfo(V(p), sliver.normal, 1.0, True, MAT, sliver)
        assert (u[n], v[n]) == sliver.surface_uv(hit)
    np.testing.assert_allclose(np.stack([u, v], axis=1), weights, rtol=0, atol=1e-12)


def test_smooth_triangle_hits_match_the_scalar_shading_normals():
    scene = teapot_scene()
    geo = BatchScene(scene)
    assert geo.smooth and geo.sets[2].bvh is not None  # through the triangles' BVH
    rng = np.random.default_rng(5)
    o = rng.normal(size=(600, 3))
    o *= 8.0 / np.linalg.norm(o, axis=1)[:, None]
    d = rng.uniform(-2.0, 2.0, (600, 3)) + [0.0, 1.0, 0.0] - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    obj, t = geo.find_intersection(o, d)
    h = obj >= 0
    hits = geo.hit_batch(obj[h], o[h], d[h], t[h])
    kinds = {type(scene.objects[k]) for k in obj[h]}
    assert kinds >= {SmoothTriangle, Triangle} and hits.front_face.any()
    for n, i in enumerate(np.flatnonzero(h)):
        ref = scene.objects[obj[i]].hit_info(Ray(V(o[i]), V(d[i])), float(t[i]))
        np.testing.assert_allclose(hits.normal[n], arr(ref.normal), rtol=1e-9, atol=1e-9)
        assert hits.front_face[n] == ref.front_face
    # light densities use the geometric normal, as SmoothTriangle.direction_pdf
    k = geo.local[obj[h]]
    p = o[h] + 0.5 * (hits.point - o[h])
    pdf = geo.sets[2].direction_pdf(k, p, hits.point, hits.normal)
    for n, i in enumerate(np.flatnonzero(h)):
        ref_obj = scene.objects[obj[i]]
        if not isinstance(ref_obj, Triangle):
            continue
        ref = ref_obj.hit_info(Ray(V(o[i]), V(d[i])), float(t[i]))
        assert pdf[n] == pytest.approx(ref_obj.direction_pdf(V(p[n]), ref), rel=1e-9)
