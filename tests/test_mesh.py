"""Tests for rtpy.mesh: SmoothTriangle's interpolated shading normal, Transform's
order of scale, rotations and translation, and Mesh's flat fallback and skipped faces."""

from __future__ import annotations

import math
import random

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtpy.hit_info import HitInfo
from rtpy.interval import Interval
from rtpy.materials import Lambertian
from rtpy.mesh import Mesh, SmoothTriangle, Transform
from rtpy.ray import Ray
from rtpy.triangle import Triangle
from rtpy.vec3 import Vec3, cross, dot, unit_vector

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


def test_from_obj_reads_a_file(tmp_path):
    path = tmp_path / "quad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n")
    mesh = Mesh.from_obj(path, MAT, Transform(scale=V(2, 2, 2)))
    assert [type(t) for t in mesh.triangles] == [SmoothTriangle, SmoothTriangle]
    assert mesh.triangles[1].c == V(0, 2, 0)
