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


# --- MeshSet: a mesh's triangles from its arrays --------------------------------------


def mesh_and_triangles():
    """A mesh (the teapot, smooth, and some flat triangles) and its triangles as objects."""
    from ..test_mesh import sphere_and_soup

    mesh = sphere_and_soup(seed=7)
    return mesh, mesh.triangles


def test_mesh_rows_equal_the_triangles_rows_bit_for_bit():
    from rtpy.numpy_backend.triangle import MeshSet

    mesh, triangles = mesh_and_triangles()
    rows, loose = MeshSet(mesh), TriangleSet(triangles)
    k = np.arange(len(mesh))
    for got, want in zip(rows._plucker(k), loose._plucker(k), strict=True):
        assert np.array_equal(got, want)
    for got, want in zip(rows._frame(k), loose._frame(k), strict=True):
        assert np.array_equal(got, want)
    (smooth, normals), (smooth2, normals2) = rows._vertex_normals(k), loose._vertex_normals(k)
    assert np.array_equal(smooth, smooth2) and 0 < smooth.sum() < len(k)
    assert np.array_equal(normals[smooth], normals2[smooth])  # (flat rows are not read)
    assert np.array_equal(rows.area(k), loose.area(k))
    assert np.array_equal(rows.surface_tangent(k, None)[0], loose.surface_tangent(k, None)[0])
    assert np.array_equal(rows._edges(k)[1], loose._edges(k)[1])


def scenes_with_and_without_the_mesh():
    mesh, triangles = mesh_and_triangles()
    ground = Sphere(V((0, -101, -3)), 100, MAT)
    light = Triangle(V((-1, 3, -2)), V((1, 3, -2)), V((0, 3, -4)), MAT)
    return Scene([ground, mesh, light]), Scene([ground, *triangles, light])


def test_a_mesh_scene_answers_as_the_scene_of_its_triangles():
    with_mesh, listed = scenes_with_and_without_the_mesh()
    a, b = BatchScene(with_mesh), BatchScene(listed)
    assert len(a.sets) == 5 and a.sets[2] is not None  # the loose triangle, then the mesh
    rng = np.random.default_rng(8)
    o = rng.uniform(-4, 4, (4000, 3)) + [0.0, 0.0, -3.0]
    d = rng.uniform(-1.2, 1.2, (4000, 3)) + [0.2, 0.0, -3.0] - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    prim_a, t_a = a.find_intersection(o, d)
    prim_b, t_b = b.find_intersection(o, d)
    # the primitives are numbered alike: the mesh's triangles in the objects' place
    assert np.array_equal(prim_a, prim_b) and np.array_equal(t_a, t_b)
    h = prim_a >= 0
    assert h.sum() > 1000
    hits_a = a.hit_batch(prim_a[h], o[h], d[h], t_a[h])
    hits_b = b.hit_batch(prim_b[h], o[h], d[h], t_b[h])
    for name in ("point", "normal", "front_face"):
        assert np.array_equal(getattr(hits_a, name), getattr(hits_b, name))
    t_max = rng.uniform(0.0, 6.0, len(o))
    ignore = np.where(rng.random(len(o)) < 0.3, prim_a, -1)
    assert np.array_equal(
        a.find_occlusion(o, d, t_max, ignore), b.find_occlusion(o, d, t_max, ignore)
    )


@pytest.mark.parametrize("backend", ["numpy", "scalar"])
def test_a_mesh_renders_the_image_of_its_triangles_bit_for_bit(backend):
    import rtpy

    with_mesh, listed = scenes_with_and_without_the_mesh()
    camera = rtpy.Camera(V((0, 1, 2)), V((0.2, 0, -3)), width=24 if backend == "scalar" else 64)
    kw = dict(camera=camera, spp=2, seed=11, backend=backend, max_depth=4)
    one, two = rtpy.render(with_mesh, **kw), rtpy.render(listed, **kw)
    assert np.array_equal(one.linear, two.linear)


def test_coincident_triangles_give_the_earliest_through_the_bvh():
    # 40 copies of one triangle and 40 of another behind it: every ray that hits gets
    # the first copy, as brute force's nearest() (the earliest of the smallest t)
    front = [Triangle(V((-1, -1, -2)), V((1, -1, -2)), V((0, 1, -2)), MAT) for _ in range(40)]
    back = [Triangle(V((-1, -1, -3)), V((1, -1, -3)), V((0, 1, -3)), MAT) for _ in range(40)]
    geo = BatchScene(Scene(back + front))
    assert geo.sets[2].bvh is not None
    rng = np.random.default_rng(9)
    d = np.column_stack([rng.uniform(-0.4, 0.4, (500, 2)), -np.ones(500)])
    d /= np.linalg.norm(d, axis=1)[:, None]
    obj, t = geo.find_intersection(np.zeros((500, 3)), d)
    assert (obj[t < np.inf] == 40).all() and (t < np.inf).sum() > 100


@pytest.mark.slow
@pytest.mark.parametrize("method", ["spawn", "forkserver"])
def test_numpy_workers_receive_the_mesh_and_its_tree_and_never_build_one(tmp_path, method):
    """tests/test_mesh_workers.py's check (a plugin makes a tree built outside the parent an
    error) on the numpy backend, whose workers make a BatchScene of the mesh."""
    from ..test_mesh_workers import run_no_rebuild

    done = run_no_rebuild(tmp_path, method, "numpy")
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[0] == "numpy same image"


@pytest.mark.parametrize("backend", ["numpy", "scalar"])
def test_a_mesh_of_degenerate_faces_only_renders_as_nothing(backend):
    import rtpy

    line = Mesh([(0, 0, -2), (1, 0, -2), (2, 0, -2)], [], [[(0, -1), (1, -1), (2, -1)]], MAT)
    assert len(line) == 0 and line.skipped == 1
    scene = Scene([line, Sphere(V((0, 0, -3)), 0.5, MAT)], sky=True)
    camera = rtpy.Camera(V((0, 0, 0)), V((0, 0, -1)), width=8)
    image = rtpy.render(scene, camera=camera, spp=1, backend=backend)
    alone = rtpy.render(Scene([Sphere(V((0, 0, -3)), 0.5, MAT)], sky=True), camera=camera, spp=1,
                        backend=backend)  # fmt: skip
    assert np.array_equal(image.linear, alone.linear)
