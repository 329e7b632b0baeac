"""Tests for rtpy.onb: the frame is orthonormal and right-handed for every unit normal."""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rtpy.onb import ONB
from rtpy.vec3 import Vec3, cross, dot

TOL = 1e-12


def check_frame(w: Vec3) -> None:
    f = ONB(w)
    u, v = f.u, f.v
    assert f.w is w
    for a in (u, v):
        assert math.isclose(a.length(), 1.0, abs_tol=TOL)
    assert abs(dot(u, v)) < TOL
    assert abs(dot(u, w)) < TOL
    assert abs(dot(v, w)) < TOL
    # Right-handed: u x v = w.
    c = cross(u, v)
    assert abs(c.e0 - w.e0) < TOL and abs(c.e1 - w.e1) < TOL and abs(c.e2 - w.e2) < TOL
    # to_world maps the local axes to (u, v, w) and is linear; to_local undoes it.
    assert f.to_world(Vec3(0.0, 0.0, 1.0)).tolist() == pytest.approx(w.tolist(), abs=1e-15)
    x = f.to_world(Vec3(0.3, -0.4, 0.5))
    expected = u * 0.3 + v * -0.4 + w * 0.5
    assert x.tolist() == pytest.approx(expected.tolist(), abs=1e-15)
    assert f.to_local(x).tolist() == pytest.approx([0.3, -0.4, 0.5], abs=1e-15)
    # Lengths are preserved (orthonormal).
    assert math.isclose(x.length(), math.sqrt(0.5), abs_tol=TOL)


@pytest.mark.parametrize(
    "w",
    [
        (0.0, 0.0, 1.0),
        (0.0, 0.0, -1.0),
        (0.0, 0.0, -0.0),  # not unit; skipped below
        (1.0, 0.0, 0.0),
        (-1.0, 0.0, 0.0),
        (0.0, 1.0, 0.0),
        (0.0, -1.0, 0.0),
        (1.0, 0.0, -0.0),
        (0.0, 1.0, -0.0),
    ],
)
def test_axis_normals(w):
    v = Vec3(*w)
    if v.length() == 0.0:
        return
    check_frame(v)


@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("eps", [1e-3, 1e-8, 1e-12, 1e-16])
def test_near_the_poles(sign, eps):
    for ax, ay in ((eps, 0.0), (0.0, eps), (eps, -eps), (-eps, eps)):
        z = sign * math.sqrt(1.0 - ax * ax - ay * ay)
        check_frame(Vec3(ax, ay, z))
    # Slightly on the other side of the equator of z, too.
    s = math.sqrt(1.0 - eps * eps)
    check_frame(Vec3(s, 0.0, sign * eps))


@settings(deadline=None, max_examples=150)
@given(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_random_unit_normals(x, y, z):
    n = math.sqrt(x * x + y * y + z * z)
    assume(n > 1e-3)
    check_frame(Vec3(x / n, y / n, z / n))


@settings(deadline=None, max_examples=100)
@given(
    st.floats(-1.0, 1.0),
    st.floats(-1.0, 1.0),
    st.floats(-1.0, 1.0),
    st.tuples(st.floats(-2, 2), st.floats(-2, 2), st.floats(-2, 2)),
)
def test_to_world_keeps_lengths_and_puts_local_z_on_the_axis(x, y, z, local):
    n = math.sqrt(x * x + y * y + z * z)
    assume(n > 1e-3)
    w = Vec3(x / n, y / n, z / n)
    a, b, c = local
    got = ONB(w).to_world(Vec3(a, b, c))
    assert got.length() == pytest.approx(math.sqrt(a * a + b * b + c * c), abs=1e-12)
    assert dot(got, w) == pytest.approx(c, abs=1e-12)


@pytest.mark.parametrize("w", [(0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (1e-9, 0.0, -1.0)])
def test_to_world_at_the_poles(w):
    v = Vec3(*w)
    got = ONB(v).to_world(Vec3(0.0, 0.0, 1.0))
    assert got.tolist() == pytest.approx(list(w), abs=1e-15)
    got = ONB(v).to_world(Vec3(0.6, 0.8, 0.0))
    assert abs(dot(got, v)) < 1e-12
    assert got.length() == pytest.approx(1.0, abs=1e-12)


@settings(deadline=None, max_examples=100)
@given(
    st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)),
    st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)),
)
def test_from_normal_tangent_keeps_the_tangent_direction(normal, tangent):
    n, t = Vec3(*normal), Vec3(*tangent)
    assume(n.length() > 1e-3 and t.length() > 1e-3)
    n, t = n / n.length(), t / t.length()  # the shapes' tangents are unit vectors
    in_plane = t - n * dot(t, n)
    # Gram-Schmidt loses about 1e-16 / (the in-plane fraction of the tangent) of
    # orthogonality: keep that fraction above 1e-3 to check to TOL.
    assume(in_plane.length() > 1e-3)
    f = ONB.from_normal_tangent(n, t)
    check_frame_axes(f, n)
    # u is the tangent's part in the surface, made unit
    assert f.u.tolist() == pytest.approx((in_plane / in_plane.length()).tolist(), abs=TOL)


def check_frame_axes(f: ONB, w: Vec3) -> None:
    assert f.w is w
    for a, b in ((f.u, f.v), (f.u, w), (f.v, w)):
        assert abs(dot(a, b)) < TOL
    assert cross(f.u, f.v).tolist() == pytest.approx(w.tolist(), abs=TOL)


def test_from_normal_tangent_along_the_normal_falls_back_to_any_frame():
    n = Vec3(0.0, 0.6, 0.8)
    for t in (n, -n, n * 3.0, Vec3(0.0, 0.0, 0.0)):
        check_frame_axes(ONB.from_normal_tangent(n, t), n)
