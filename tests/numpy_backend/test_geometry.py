"""Batched geometry kernels against their scalar twins (rtpy/sphere.py, quad.py,
triangle.py, scene.py, ray.py) on random inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy import Lambertian, Quad, Scene, Sphere, Triangle, Vec3
from rtpy.interval import Interval
from rtpy.numpy_backend.geometry import (
    BVH_THRESHOLD,
    Geometry,
    QuadSet,
    SphereSet,
    TriangleSet,
    offset_scale,
    spawn_origins,
)
from rtpy.ray import Ray, spawn_ray
from rtpy.ray import offset_scale as scalar_offset_scale

coord = st.floats(-5.0, 5.0, allow_nan=False)
vec = st.tuples(coord, coord, coord)
unit_pair = st.tuples(st.floats(-1.2, 2.2), st.floats(-1.2, 2.2))
MAT = Lambertian()


def unit(v) -> np.ndarray:
    a = np.array(v, dtype=np.float64)
    n = np.linalg.norm(a)
    return a / n if n > 1e-3 else np.array([0.0, 0.0, 1.0])


def V(a) -> Vec3:
    return Vec3(*map(float, a))


def arr(v: Vec3) -> np.ndarray:
    return np.array([v.e0, v.e1, v.e2])


def ray_toward(origin, target) -> tuple[np.ndarray, np.ndarray]:
    o = np.array(origin, dtype=np.float64)
    return o, unit(np.array(target) - o)


@settings(max_examples=300)
@given(vec, st.floats(0.05, 3.0), vec, vec)
def test_sphere_t_is_bit_identical(center, radius, origin, target):
    sphere = Sphere(V(center), radius, MAT)
    o, d = ray_toward(origin, np.array(center) + np.array(target) * radius / 4)
    s = SphereSet([sphere])
    t = s.pair_t(o[None], d[None], np.array([0]), 0.0, np.array([math.inf]))[0]
    ref = sphere.hit_t(Ray(V(o), V(d)), 0.0, math.inf)
    assert (ref is None and t == math.inf) or t == ref


def _check_planar(shape, prims, o, d, ab):
    """numpy and scalar agree on hit or miss (except within 1e-9 of an edge) and on t."""
    ref = shape.hit_t(Ray(V(o), V(d)), 0.0, math.inf)
    t_all = prims.all_t(o[None], d[None], 0.0)[0, 0]
    t_pair = prims.pair_t(o[None], d[None], np.array([0]), 0.0, np.array([math.inf]))[0]
    for t in (t_all, t_pair):
        if ref is None or t == math.inf:
            if (ref is None) != (t == math.inf):
                assert ab(ref if ref is not None else t) < 1e-9  # on an edge
            continue
        assert t == pytest.approx(ref, rel=1e-12, abs=1e-12)


@settings(max_examples=300)
@given(vec, vec, vec, vec, unit_pair)
def test_quad_t_matches_scalar(q, u, v, origin, ab):
    try:
        quad = Quad(V(q), V(u), V(v), MAT)
    except ValueError:
        return
    if quad.area() < 1e-3:
        return
    target = np.array(q) + ab[0] * np.array(u) + ab[1] * np.array(v)
    o, d = ray_toward(origin, target)
    if abs(d @ arr(quad.normal)) < 1e-3:
        return  # a ray in the quad's plane: which rounding wins is arbitrary

    def edge_distance(t):
        a, b = quad._coords(V(o + t * d))
        return min(abs(a), abs(a - 1), abs(b), abs(b - 1))

    _check_planar(quad, QuadSet([quad]), o, d, edge_distance)


@settings(max_examples=300)
@given(vec, vec, vec, vec, unit_pair)
def test_triangle_t_matches_scalar(a, b, c, origin, uv):
    try:
        tri = Triangle(V(a), V(b), V(c), MAT)
    except ValueError:
        return
    if tri.area() < 1e-3:
        return
    target = np.array(a) + uv[0] * tri_e(tri, 1) + uv[1] * tri_e(tri, 2) * 0.5
    o, d = ray_toward(origin, target)
    if abs(d @ arr(tri.normal)) < 1e-3:
        return  # a ray in the triangle's plane: which rounding wins is arbitrary

    def edge_distance(t):
        r = tri._barycentric(Ray(V(o), V(d)))
        if r is None:  # the scalar missed: how far outside is the numpy hit?
            e1, e2 = tri_e(tri, 1), tri_e(tri, 2)
            p = o + t * d - np.array(a)
            m = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
            bu, bv = np.linalg.solve(m, [p @ e1, p @ e2])
        else:
            bu, bv = r[1], r[2]
        return min(abs(bu), abs(bv), abs(1 - bu - bv), abs(bu - 1))

    _check_planar(tri, TriangleSet([tri]), o, d, edge_distance)


def tri_e(tri, k):
    return arr(tri.e1 if k == 1 else tri.e2)


def random_scene(rng: np.random.Generator, n_spheres: int, n_quads: int, n_tris: int):
    objects = []
    for _ in range(n_spheres):
        objects.append(Sphere(V(rng.uniform(-4, 4, 3)), float(rng.uniform(0.05, 1.0)), MAT))
    for _ in range(n_quads):
        q = rng.uniform(-4, 4, 3)
        objects.append(Quad(V(q), V(rng.uniform(-2, 2, 3)), V(rng.uniform(-2, 2, 3)), MAT))
    for _ in range(n_tris):
        a = rng.uniform(-4, 4, 3)
        b, c = a + rng.uniform(-2, 2, 3), a + rng.normal(0, 1, 3)
        objects.append(Triangle(V(a), V(b), V(c), MAT))
    order = rng.permutation(len(objects))
    return Scene([objects[i] for i in order])


def random_rays(rng, n, spread=6.0):
    o = rng.uniform(-spread, spread, (n, 3))
    d = rng.normal(size=(n, 3))
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)


@pytest.mark.parametrize("sizes", [(5, 4, 3), (BVH_THRESHOLD + 40, 3, 2), (3, 60, 50), (0, 0, 0)])
def test_closest_hit_and_occlusion_match_the_scene(sizes):
    rng = np.random.default_rng(sum(sizes))
    scene = random_scene(rng, *sizes)
    geo = Geometry(scene.objects)
    o, d = random_rays(rng, 400)
    obj, t = geo.closest_hit(o, d)
    t_max = rng.uniform(0.0, 8.0, len(o))
    blocked = geo.occluded(o, d, t_max)
    mismatches = 0
    for i in range(len(o)):
        ray = Ray(V(o[i]), V(d[i]))
        hit = scene.find_intersection(ray, Interval(0.0, math.inf))
        if hit is None:
            mismatches += obj[i] != -1
        elif obj[i] == -1 or scene.objects[obj[i]] is not hit.obj:
            mismatches += 1  # only a near-tie or an edge graze may differ
            assert obj[i] == -1 or abs(t[i] - hit.t) < 1e-9 * max(1.0, hit.t)
        else:
            assert t[i] == pytest.approx(hit.t, rel=1e-12, abs=1e-12)
        ref_blocked = scene.find_occlusion(ray, Interval(0.0, float(t_max[i])))
        mismatches += blocked[i] != ref_blocked
    assert mismatches <= 2  # rays grazing an edge, at most


def test_bvh_gives_the_brute_force_answer():
    rng = np.random.default_rng(7)
    scene = random_scene(rng, 300, 80, 80)
    geo = Geometry(scene.objects)
    assert all(s.bvh is not None for s in geo.sets[:3])
    o, d = random_rays(rng, 2000)
    obj, t = geo.closest_hit(o, d)
    blocked = geo.occluded(o, d, np.full(len(o), 3.0))
    for s in geo.sets[:3]:
        s.bvh = None
    obj2, t2 = geo.closest_hit(o, d)
    np.testing.assert_array_equal(obj, obj2)
    np.testing.assert_allclose(t, t2, rtol=1e-12)  # matrix products vs. pairs: rounding
    np.testing.assert_array_equal(blocked, geo.occluded(o, d, np.full(len(o), 3.0)))


def box_quads(rng: np.random.Generator, size: float) -> list[Quad]:
    """The six faces of a randomly rotated box, as scripts/make_cornell.py writes them."""
    c = rng.uniform(-3, 3, 3)
    axes = np.linalg.qr(rng.normal(size=(3, 3)))[0] * rng.uniform(0.3, 1.0, 3) * size
    quads = []
    for k in range(3):
        e1, e2 = axes[(k + 1) % 3], axes[(k + 2) % 3]
        for side in (-0.5, 0.5):
            q = c + side * axes[k] - 0.5 * (e1 + e2)
            quads.append(Quad(V(q), V(e1), V(e2), MAT))
    return quads


def test_clustered_quads_give_the_brute_force_answer():
    rng = np.random.default_rng(11)
    room = [
        Quad(V(q), V(u), V(v), MAT)
        for q, u, v in (
            ((-6, -6, -6), (12, 0, 0), (0, 0, 12)),
            ((-6, 6, -6), (12, 0, 0), (0, 0, 12)),
            ((-6, -6, -6), (0, 12, 0), (0, 0, 12)),
            ((6, -6, -6), (0, 12, 0), (0, 0, 12)),
            ((-6, -6, 6), (12, 0, 0), (0, 12, 0)),
        )
    ]
    scene = Scene(room + box_quads(rng, 2.0) + box_quads(rng, 1.5) + box_quads(rng, 1.0))
    geo = Geometry(scene.objects)
    quads = geo.sets[1]
    assert quads.parts is not None and len(quads.parts) == 4  # the room, three boxes
    o, d = random_rays(rng, 3000, spread=5.0)
    # Rays from points on the box faces (as bounces are), and rays aimed at box edges.
    corners = quads.corners()[5:].reshape(-1, 3)
    o[:500] = corners[rng.integers(0, len(corners), 500)] + rng.normal(0, 1e-3, (500, 3))
    d[500:1000] = corners[rng.integers(0, len(corners), 500)] - o[500:1000]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    skip = np.where(rng.random(len(o)) < 0.5, rng.integers(0, len(scene.objects), len(o)), -1)
    t_max = rng.uniform(0.0, 12.0, len(o))
    obj, t = geo.closest_hit(o, d)
    blocked = geo.occluded(o, d, t_max, skip=skip)
    geo.sets[1] = QuadSet(scene.objects, cluster=False)
    assert geo.sets[1].parts is None
    obj2, t2 = geo.closest_hit(o, d)
    np.testing.assert_array_equal(obj, obj2)
    np.testing.assert_allclose(t, t2, rtol=1e-12)
    np.testing.assert_array_equal(blocked, geo.occluded(o, d, t_max, skip=skip))


def test_hit_batch_matches_hit_info_uv_and_tangent():
    rng = np.random.default_rng(3)
    scene = random_scene(rng, 20, 10, 10)
    scene.add_object(Sphere(Vec3(0, 0, 0), 1.0, MAT))  # rays from inside hit the back face
    geo = Geometry(scene.objects)
    o, d = random_rays(rng, 1000)
    o[:100] = rng.uniform(-0.3, 0.3, (100, 3))
    obj, t = geo.closest_hit(o, d)
    h = obj >= 0
    hits = geo.hit_batch(obj[h], o[h], d[h], t[h])
    assert not hits.front_face.all() and hits.front_face.any()
    for n, i in enumerate(np.flatnonzero(h)):
        ref = scene.objects[obj[i]].hit_info(Ray(V(o[i]), V(d[i])), float(t[i]))
        np.testing.assert_allclose(hits.point[n], arr(ref.point), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(hits.normal[n], arr(ref.normal), rtol=1e-12, atol=1e-12)
        assert hits.front_face[n] == ref.front_face
        np.testing.assert_allclose(hits.wo[n], -d[i])
        assert hits.u[n] == pytest.approx(ref.u, rel=1e-12, abs=1e-12)
        assert hits.v[n] == pytest.approx(ref.v, rel=1e-12, abs=1e-12)
        np.testing.assert_allclose(hits.tangent[n], arr(ref.tangent), rtol=1e-12, atol=1e-12)


def test_sphere_tangent_at_the_pole_falls_back_to_the_normal_frame():
    s = Sphere(Vec3(1, 2, 3), 2.0, MAT)
    geo = Geometry([s])
    o, d = np.array([[1.0, 10.0, 3.0]]), np.array([[0.0, -1.0, 0.0]])
    obj, t = geo.closest_hit(o, d)
    hits = geo.hit_batch(obj, o, d, t)
    ref = s.hit_info(Ray(V(o[0]), V(d[0])), float(t[0]))
    np.testing.assert_allclose(hits.tangent[0], arr(ref.tangent), atol=1e-15)


class ScalarOnlySphere(Sphere):
    """A shape the batched code does not know: intersected by its scalar methods."""


def test_unknown_shapes_use_their_scalar_methods():
    rng = np.random.default_rng(5)
    scene = random_scene(rng, 4, 2, 2)
    scene.add_object(ScalarOnlySphere(Vec3(0, 0, 0), 1.5, MAT))
    geo = Geometry(scene.objects)
    assert geo.sets[3] is not None
    o, d = random_rays(rng, 200)
    obj, t = geo.closest_hit(o, d)
    for i in range(len(o)):
        hit = scene.find_intersection(Ray(V(o[i]), V(d[i])), Interval(0.0, math.inf))
        assert (hit is None and obj[i] == -1) or scene.objects[obj[i]] is hit.obj
    h = obj >= 0
    hits = geo.hit_batch(obj[h], o[h], d[h], t[h])
    assert np.all(np.einsum("ij,ij->i", hits.normal, hits.wo) >= 0)


@settings(max_examples=200)
@given(vec, vec, vec)
def test_spawn_origins_are_spawn_ray(point, normal, direction):
    p, n, w = (np.array(x, dtype=np.float64)[None] for x in (point, normal, direction))
    ref = spawn_ray(V(point), V(normal), V(direction))
    np.testing.assert_array_equal(spawn_origins(p, n, w)[0], arr(ref.origin))
    assert offset_scale(p)[0] == scalar_offset_scale(V(point))
