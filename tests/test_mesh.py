"""Tests for rtpy.mesh: SmoothTriangle's interpolated shading normal, Transform's
order of scale, rotations and translation, and Mesh's flat fallback and skipped faces."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtpy.bvh import ROUNDING_MARGIN
from rtpy.cli.bench.meshes import uv_sphere
from rtpy.hit_info import HitInfo
from rtpy.interval import Interval
from rtpy.materials import Lambertian
from rtpy.mesh import Mesh, SmoothTriangle, Transform
from rtpy.ray import Ray
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.triangle import Triangle
from rtpy.vec3 import Vec3, cross, dot, unit_vector

from .in_list_order import in_list_order
from .vectors import V

MAT = Lambertian()
EVERYWHERE = Interval(0.0, math.inf)
A, B, C = V(0, 0, 0), V(2, 0, 0), V(0, 2, 0)  # front face +z
NA, NB, NC = V(0, 0, 1), V(1, 0, 1), V(0, 1, 1)  # tilted toward +x at b, +y at c
SMOOTH = SmoothTriangle(A, B, C, [NA, NB, NC], MAT)


def close(a: Vec3, b: Vec3, tol: float = 1e-12) -> bool:
    return (a - b).length() <= tol


def down_at(x, y):
    return Ray(V(x, y, 3), V(0, 0, -1))


def test_the_shading_normal_is_the_vertex_normal_at_each_vertex():
    for (x, y), n in [((0, 0), NA), ((2, 0), NB), ((0, 2), NC)]:
        hit = SMOOTH.intersect(down_at(x, y), EVERYWHERE)
        assert close(hit.normal, unit_vector(n))


def test_the_shading_normal_inside_is_the_barycentric_mix_normalized():
    hit = SMOOTH.intersect(down_at(0.5, 0.25), EVERYWHERE)  # weights 0.625, 0.25, 0.125
    mix = unit_vector(NA) * 0.625 + unit_vector(NB) * 0.25 + unit_vector(NC) * 0.125
    assert close(hit.normal, unit_vector(mix))
    assert (hit.u, hit.v) == pytest.approx((0.25, 0.125), abs=1e-15)


def test_intersection_front_face_and_light_density_stay_flat():
    flat = Triangle(A, B, C, MAT)
    for ray in (down_at(0.5, 0.25), Ray(V(0.5, 0.25, -4), V(0, 0, 1))):
        smooth_hit, flat_hit = SMOOTH.intersect(ray, EVERYWHERE), flat.intersect(ray, EVERYWHERE)
        assert smooth_hit.t == flat_hit.t and smooth_hit.front_face == flat_hit.front_face
        assert dot(smooth_hit.normal, flat_hit.normal) > 0.9  # on the side the ray came from
    assert SMOOTH.normal == flat.normal
    p = V(1.0, 3.0, 2.0)
    ray = Ray(p, unit_vector(V(0.5, 0.25, 0) - p))
    hit = SMOOTH.intersect(ray, EVERYWHERE)
    assert SMOOTH.direction_pdf(p, hit) == flat.direction_pdf(p, flat.intersect(ray, EVERYWHERE))
    # with the shading normal the density would differ
    assert SMOOTH.direction_pdf(p, hit) != Triangle.direction_pdf(SMOOTH, p, hit)


def test_a_back_hit_sees_the_shading_normal_turned_toward_the_ray():
    hit = SMOOTH.intersect(Ray(V(0.5, 0.25, -4), V(0, 0, 1)), EVERYWHERE)
    front = SMOOTH.intersect(down_at(0.5, 0.25), EVERYWHERE)
    assert not hit.front_face and close(hit.normal, -front.normal)


def test_vertex_normals_against_the_winding_are_turned_to_the_front():
    flipped = SmoothTriangle(A, B, C, [-NA, -NB, -NC], MAT)
    hit = flipped.intersect(down_at(0.5, 0.25), EVERYWHERE)
    assert close(hit.normal, SMOOTH.intersect(down_at(0.5, 0.25), EVERYWHERE).normal)


def test_zero_vertex_normals_are_refused():
    with pytest.raises(ValueError, match="vertex normal nb"):
        SmoothTriangle(A, B, C, [NA, V(0, 0, 0), NC], MAT)


# --------------------------------------------------------------------------- Transform


def test_rotations_are_about_x_then_y_then_z_counterclockwise():
    quarter_turns = [
        ((90, 0, 0), V(0, 1, 0), V(0, 0, 1)),  # about x: y turns to z
        ((0, 90, 0), V(0, 0, 1), V(1, 0, 0)),  # about y: z turns to x
        ((0, 0, 90), V(1, 0, 0), V(0, 1, 0)),  # about z: x turns to y
        ((90, 90, 0), V(0, 1, 0), V(1, 0, 0)),  # y -> z (about x), then z -> x (about y)
        # z -> -y about x, then -y -> x about z (about z first would give -y)
        ((90, 0, 90), V(0, 0, 1), V(1, 0, 0)),
    ]
    for rotate, p, expected in quarter_turns:
        assert close(Transform(rotate=V(*rotate)).point(p), expected, 1e-15)


def test_points_are_scaled_then_rotated_then_translated():
    t = Transform(translate=V(10, 0, 0), rotate=V(0, 0, 90), scale=V(2, 3, 1))
    assert close(t.point(V(1, 1, 5)), V(10 - 3, 2, 5))


@given(
    st.tuples(*[st.floats(-180, 180)] * 3),
    st.tuples(*[st.sampled_from([-2.0, 0.5, 1.0, 3.0])] * 3),
)
def test_normals_stay_perpendicular_to_the_transformed_surface(rotate, scale):
    t = Transform(V(1, 2, 3), V(*rotate), V(*scale))
    a, b, c = V(0.3, -1, 2), V(1.5, 0.2, -0.7), V(-0.4, 0.9, 0.1)
    n = cross(b - a, c - a)
    ta, tb, tc = t.point(a), t.point(b), t.point(c)
    tn = unit_vector(t.normal(n))
    assert abs(dot(tn, unit_vector(tb - ta))) < 1e-9
    assert abs(dot(tn, unit_vector(tc - ta))) < 1e-9


def test_a_zero_scale_is_refused():
    with pytest.raises(ValueError, match="scale"):
        Transform(scale=V(1, 0, 1))


# --------------------------------------------------------------------------- Mesh


def test_faces_with_normals_are_smooth_the_others_flat_and_degenerate_ones_skipped():
    positions = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (2, 0, 0)]
    normals = [(0, 0, 1), (0, 0, 0)]
    triangles = [
        ((0, 0), (1, 0), (2, 0)),  # smooth
        ((0, None), (1, None), (2, None)),  # no normals: flat
        ((0, 0), (1, 1), (2, 0)),  # a zero normal: flat
        ((0, None), (1, None), (3, None)),  # collinear: skipped
    ]
    mesh = Mesh(positions, normals, triangles, MAT, Transform(translate=V(0, 0, -1)))
    assert [type(t) for t in mesh.triangles] == [SmoothTriangle, Triangle, Triangle]
    assert mesh.skipped == 1
    assert mesh.triangles[0].a == V(0, 0, -1) and mesh.triangles[0].material is MAT


def test_an_octahedron_with_the_spheres_normals_shades_like_the_sphere():
    """Vertex normals equal to the (unit) vertex positions: the barycentric mix of the
    normals at a hit is the hit point itself, so the shading normal is the sphere's
    normal in the hit's direction, not the face's."""
    pts = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    faces = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    mesh = Mesh(pts, pts, [tuple((k, k) for k in f) for f in faces], MAT)
    assert len(mesh.triangles) == 8 and mesh.skipped == 0
    rng = random.Random(3)
    for _ in range(200):
        d = unit_vector(V(rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, 1)))
        ray = Ray(d * 5.0, -d)
        hits = [h for t in mesh.triangles if (h := t.intersect(ray, EVERYWHERE)) is not None]
        hit = min(hits, key=lambda h: h.t)
        assert hit.front_face
        assert close(hit.normal, unit_vector(hit.point), 1e-9)
        assert not close(hit.normal, hit.obj.normal, 1e-3) or close(d, hit.obj.normal, 1e-3)


def test_hit_info_of_a_smooth_triangle_is_a_hit_info():
    assert isinstance(SMOOTH.intersect(down_at(0.5, 0.5), EVERYWHERE), HitInfo)


# --------------------------------------------------------------------------- Mesh as one object


SPHERE_FACES = len(uv_sphere(600)[1])


def sphere_and_soup(seed: int = 1) -> Mesh:
    """A UV sphere of about 600 triangles, smooth, then 20 random flat triangles
    crossing it, the first 5 of them again (coincident: ties go to the earlier), and
    a degenerate one."""
    rng = np.random.default_rng(seed)
    positions, faces = uv_sphere(600)
    soup = rng.uniform(-1.5, 1.5, (60, 3))
    soup_faces = len(positions) + np.arange(60).reshape(20, 3)
    soup_faces = np.concatenate([soup_faces, soup_faces[:5], [[0, 0, 1]]])  # repeats, degenerate
    points = np.concatenate([positions, soup])
    corners = np.stack([faces, faces], axis=2)  # smooth: the normal index is the vertex's
    flat = np.stack([soup_faces, np.full(soup_faces.shape, -1)], axis=2)
    triangles = np.concatenate([corners, flat])
    return Mesh(points, positions, triangles, MAT, Transform(V(0.2, 0, -3), V(10, 20, 30)))


def random_queries(rng, n: int):
    origins = rng.uniform(-4, 4, (n, 3)) + [0.0, 0.0, -3.0]
    targets = rng.uniform(-1.2, 1.2, (n, 3)) + [0.2, 0.0, -3.0]
    return [Ray(V(*o), V(*(t - o))) for o, t in zip(origins, targets.tolist(), strict=True)]


def bits(hit) -> tuple | None:
    if hit is None:
        return None
    floats = (hit.t, *hit.point, *hit.normal)
    return (id(hit.obj), hit.front_face, np.array(floats).tobytes())


def test_a_mesh_answers_as_the_list_of_its_triangles():
    mesh = sphere_and_soup()
    assert mesh.skipped == 1 and len(mesh) == SPHERE_FACES + 25
    ground = Sphere(V(0, -101, -3), 100, MAT)
    scene = Scene([ground, mesh])
    listed = Scene([ground, *mesh.triangles])  # the old form: each triangle an object
    rng = np.random.default_rng(2)
    hits = 0
    for ray in random_queries(rng, 200):
        got = scene.find_intersection(ray, EVERYWHERE)
        want = in_list_order(listed).find_intersection(ray, EVERYWHERE)
        assert bits(got) == bits(want)
        hits += got is not None and got.obj is not ground
        for t_max in (0.5, 3.0):
            short = Interval(0.0, t_max)
            assert scene.find_occlusion(ray, short) == listed.find_occlusion(ray, short, True)
    assert hits > 70


def test_coincident_triangles_resolve_to_the_earlier():
    mesh = sphere_and_soup()
    first = SPHERE_FACES + 20
    repeats = {k: k - 20 for k in range(first, first + 5)}  # soup triangles 0-4 again
    rng = np.random.default_rng(3)
    seen = 0
    for ray in random_queries(rng, 3000):
        t = mesh.hit_t(ray, 0.0, math.inf)
        if t is None:
            continue
        hit = mesh.hit_info(ray, t)
        k = next(k for k in range(len(mesh)) if mesh[k] is hit.obj)
        assert k not in repeats
        seen += k in repeats.values()
    assert seen > 0


def test_the_arrays_are_the_triangles_of_the_old_construction():
    """Mesh's vectorized transform, degenerate test and smooth test give the floats
    and the choices of building each triangle as an object (Triangle, SmoothTriangle
    and Transform.point on Vec3s)."""
    mesh = sphere_and_soup()
    t = Transform(V(0.2, 0, -3), V(10, 20, 30))
    k = 0
    for tri in mesh.triangles:
        a = mesh.vertices[mesh.faces[k, 0]]
        assert tri.a.tolist() == a.tolist()
        k += 1
    p = np.random.default_rng(4).normal(size=(50, 3)) * 1e3
    for row, q in zip(t.points(p).tolist(), p.tolist(), strict=True):
        assert row == t.point(V(*q)).tolist()
    for row, q in zip(t.normals(p).tolist(), p.tolist(), strict=True):
        assert row == t.normal(V(*q)).tolist()


@given(st.tuples(*[st.floats(-1, 1)] * 9), st.floats(1e-13, 1e-11))
def test_degenerate_faces_are_those_triangle_refuses(corners, size):
    points = np.array(corners).reshape(3, 3) * size * 1e6
    mesh = Mesh(points, [], [((0, None), (1, None), (2, None))], MAT)
    try:
        Triangle(*(V(*p) for p in points.tolist()), MAT)
        refused = 0
    except ValueError:
        refused = 1
    assert mesh.skipped == refused and len(mesh) == 1 - refused


def test_a_vertex_out_of_range_after_the_transform_is_named():
    with pytest.raises(ValueError, match=r"vertex 2 \(after the transform\)"):
        Mesh([(0, 0, 0), (1.5, 0, 0), (0, 1, 0)], [], [[(0, -1), (1, -1), (2, -1)]], MAT,
             Transform(translate=V(0, 0, 0), scale=V(1e6, 1, 1)))  # fmt: skip


def test_an_emitting_mesh_is_refused_as_one_object():
    from rtpy.materials import DiffuseLight

    mesh = Mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [[(0, -1), (1, -1), (2, -1)]],
                DiffuseLight(Vec3(1, 1, 1)))  # fmt: skip
    with pytest.raises(ValueError, match=r"objects\[1\]: a Mesh whose material emits"):
        Scene([Sphere(V(0, 0, 0), 1, MAT), mesh])
    assert len(Scene(mesh.triangles).area_lights) == 1


def test_a_pickled_mesh_keeps_its_arrays_and_tree_not_its_triangle_objects():
    import pickle

    mesh = sphere_and_soup()
    mesh[3]  # one triangle made as an object
    copy = pickle.loads(pickle.dumps(mesh))
    assert copy._triangles == [None] * len(mesh)
    for name in ("vertices", "faces", "face_normals", "normals"):
        assert np.array_equal(getattr(copy, name), getattr(mesh, name))
    for name in ("lo", "hi", "child", "count", "order"):
        assert np.array_equal(getattr(copy.tree, name), getattr(mesh.tree, name))
    ray = random_queries(np.random.default_rng(5), 1)[0]
    assert copy.hit_t(ray, 0.0, math.inf) == mesh.hit_t(ray, 0.0, math.inf)


def test_the_triangle_boxes_are_the_triangles_own_grown_by_the_bvhs_margin():
    """Mesh.triangle_boxes (numpy, for the tree) is Triangle.bounding_box (the padded
    box of the scalar path) grown by ROUNDING_MARGIN of the mesh's magnitude, as
    rtpy.bvh.BVH grows a scene's boxes: equal up to the rounding of adding the pad and
    the margin in the other order. Triangles in every octant, of sizes 1e-3 to 1e3,
    some flat along an axis (their box's thickness is the pad alone)."""
    rng = np.random.default_rng(11)
    corners = rng.normal(size=(300, 3, 3)) * 10.0 ** rng.integers(-3, 4, (300, 1, 1))
    corners += rng.normal(size=(300, 1, 3)) * 5.0
    corners[::7, :, 2] = corners[::7, :1, 2]  # flat in z
    faces = np.arange(900).reshape(300, 3)
    triangles = np.stack([faces, np.full_like(faces, -1)], axis=2)  # no normals
    mesh = Mesh(corners.reshape(-1, 3), np.zeros((0, 3)), triangles, MAT)
    assert len(mesh) == 300
    lo, hi = mesh.triangle_boxes()
    raw = [mesh[k].bounding_box() for k in range(len(mesh))]
    unpadded = np.abs(corners).max()
    margin = ROUNDING_MARGIN * unpadded
    for k, box in enumerate(raw):
        want_lo = np.array([box.x0, box.y0, box.z0]) - margin
        want_hi = np.array([box.x1, box.y1, box.z1]) + margin
        ulps = 4 * np.spacing(np.abs(corners[k]).max() + margin)
        assert np.all(np.abs(lo[k] - want_lo) <= ulps), k
        assert np.all(np.abs(hi[k] - want_hi) <= ulps), k


@pytest.mark.parametrize("block", [1, 2, 5, 1 << 15])
def test_a_degenerate_face_changes_neither_the_boxes_nor_the_tree(monkeypatch, block):
    """A face left out (collinear corners, here far from the others) is as if it
    were not in the file: the tree's boxes are grown by the magnitude of the faces
    kept alone, whichever blocks of faces the boxes are made in."""
    import rtpy.mesh

    monkeypatch.setattr(rtpy.mesh, "BLOCK", block)
    rng = np.random.default_rng(3)
    points = np.concatenate([rng.normal(size=(12, 3)), [[1e5, 0, 0], [2e5, 0, 0], [3e5, 0, 0]]])
    faces = rng.integers(0, 12, size=(9, 3))
    faces[:, 1] = (faces[:, 0] + 1) % 12  # distinct corners: none degenerate
    faces[:, 2] = (faces[:, 0] + 2) % 12
    with_it = np.insert(faces, 4, [12, 13, 14], axis=0)  # collinear: left out
    meshes = [
        Mesh(points, np.zeros((0, 3)), np.stack([f, np.full_like(f, -1)], axis=2), MAT)
        for f in (faces, with_it)
    ]
    assert [m.skipped for m in meshes] == [0, 1]
    assert np.array_equal(meshes[0].faces, meshes[1].faces)
    for name in ("lo", "hi", "child", "count", "order"):
        assert np.array_equal(getattr(meshes[0].tree, name), getattr(meshes[1].tree, name)), name


def test_building_a_large_mesh_needs_little_more_memory_than_it_keeps():
    """New memory is paid for page by page (docs/performance.md#scene-size), so the
    constructor lets go of each array of the triangles' size once it is used: the
    most memory it holds at once, temporaries included, is at most 4 times what the
    mesh keeps (its vertices, faces and tree). Holding on to the cross products,
    corner copies, centroids and codes took it to 5.5 times; about 3.3 is needed."""
    import tracemalloc

    positions, faces = uv_sphere(100_000)
    triangles = np.stack([faces, faces], axis=2)
    tracemalloc.start()
    try:
        mesh = Mesh(positions, positions, triangles, MAT)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    tree = mesh.tree
    kept = (mesh.vertices, mesh.normals, mesh.faces, mesh.face_normals)
    kept += (tree.lo, tree.hi, tree.child, tree.count, tree.axis, tree.order)
    assert peak <= 4.0 * sum(a.nbytes for a in kept)
