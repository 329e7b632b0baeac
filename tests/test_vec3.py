"""Tests for rtpy.vec3: algebraic identities checked with hypothesis, reflect, refract and
halfvector."""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rtpy.vec3 import (
    BLACK,
    WHITE,
    Color,
    Vec3,
    cross,
    dot,
    halfvector,
    reflect,
    refract,
    unit_vector,
)

EPS = 2.220446049250313e-16

coord = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)
vectors = st.builds(Vec3, coord, coord, coord)
colors = st.builds(Color, coord, coord, coord)
nonzero_scalars = st.floats(min_value=1e-3, max_value=1e3).flatmap(
    lambda m: st.sampled_from([m, -m])
)


def comps(v: Vec3) -> tuple[float, float, float]:
    return (v.e0, v.e1, v.e2)


def norm(v: Vec3) -> float:
    # hypot, not sqrt of the squares: those underflow to 0 for components below 1e-154,
    # and a tolerance scaled by a zero norm fails a correct cross product.
    return math.hypot(v.e0, v.e1, v.e2)


def close_vec(a: Vec3, b: Vec3, abs_tol: float) -> bool:
    pairs = zip(comps(a), comps(b), strict=True)
    return all(math.isclose(x, y, rel_tol=1e-12, abs_tol=abs_tol) for x, y in pairs)


def random_unit(theta: float, phi: float) -> Vec3:
    return Vec3(math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))


# --- components and construction ---------------------------------------------


def test_accessors_and_defaults():
    v = Vec3(1.5, -2.0, 3.25)
    assert (v.x(), v.y(), v.z()) == (1.5, -2.0, 3.25)
    assert (v[0], v[1], v[2]) == (1.5, -2.0, 3.25)
    assert list(v) == [1.5, -2.0, 3.25]
    assert v.tolist() == [1.5, -2.0, 3.25]
    assert len(v) == 3
    assert comps(Vec3()) == (0.0, 0.0, 0.0)


def test_color_accessors_and_constants():
    c = Color(0.1, 0.2, 0.3)
    assert (c.r(), c.g(), c.b()) == (0.1, 0.2, 0.3)
    assert comps(BLACK) == (0.0, 0.0, 0.0) and BLACK.is_black()
    assert comps(WHITE) == (1.0, 1.0, 1.0) and not WHITE.is_black()


def test_equality_and_unhashable():
    assert Vec3(1.0, 2.0, 3.0) == Vec3(1.0, 2.0, 3.0)
    assert Vec3(1.0, 2.0, 3.0) != Vec3(1.0, 2.0, 3.5)
    with pytest.raises(TypeError):
        hash(Vec3(1.0, 2.0, 3.0))


# --- arithmetic properties -------------------------------------------------------


@settings(deadline=None, max_examples=60)
@given(vectors, vectors)
def test_addition_commutes(a, b):
    assert comps(a + b) == comps(b + a)


@settings(deadline=None, max_examples=60)
@given(vectors, vectors)
def test_add_then_subtract_gives_back(a, b):
    r = (a + b) - b
    scale = max(norm(a), norm(b), 1.0)
    assert close_vec(r, a, abs_tol=4 * EPS * scale)


@settings(deadline=None, max_examples=60)
@given(vectors)
def test_unary_minus(a):
    n = -a
    assert comps(n) == (-a.e0, -a.e1, -a.e2)
    assert comps(a + n) == (0.0, 0.0, 0.0)


@settings(deadline=None, max_examples=60)
@given(vectors, nonzero_scalars)
def test_division_by_scalar(a, s):
    q = a / s
    for got, x in zip(comps(q), comps(a), strict=True):
        assert math.isclose(got, x / s, rel_tol=4 * EPS, abs_tol=1e-300)


@settings(deadline=None, max_examples=60)
@given(vectors, st.floats(min_value=-1e3, max_value=1e3))
def test_scalar_multiplication_both_sides(a, s):
    assert comps(a * s) == (a.e0 * s, a.e1 * s, a.e2 * s)
    assert comps(s * a) == (a.e0 * s, a.e1 * s, a.e2 * s)


@settings(deadline=None, max_examples=60)
@given(vectors, vectors)
def test_componentwise_multiply(a, b):
    assert comps(a * b) == (a.e0 * b.e0, a.e1 * b.e1, a.e2 * b.e2)


@settings(deadline=None, max_examples=60)
@given(vectors, vectors)
def test_dot_is_symmetric_and_matches_formula(a, b):
    assert dot(a, b) == dot(b, a)
    expected = a.e0 * b.e0 + a.e1 * b.e1 + a.e2 * b.e2
    assert math.isclose(dot(a, b), expected, rel_tol=1e-12, abs_tol=1e-9)


@settings(deadline=None, max_examples=60)
@given(vectors, vectors)
def test_cross_anticommutes(a, b):
    ab, ba = cross(a, b), cross(b, a)
    assert comps(ab) == comps(-ba)


@settings(deadline=None, max_examples=60)
@given(vectors, vectors)
def test_cross_is_orthogonal_to_both_inputs(a, b):
    c = cross(a, b)
    # |dot(c, a)| is a sum of products of size |a|^2 |b|; rounding is relative to that.
    tol = 16 * EPS * norm(a) * norm(a) * norm(b) + 1e-300
    assert abs(dot(c, a)) <= tol
    tol = 16 * EPS * norm(b) * norm(b) * norm(a) + 1e-300
    assert abs(dot(c, b)) <= tol


def test_cross_of_basis_is_right_handed():
    x, y, z = Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)
    assert comps(cross(x, y)) == (0, 0, 1)
    assert comps(cross(y, z)) == (1, 0, 0)
    assert comps(cross(z, x)) == (0, 1, 0)


@settings(deadline=None, max_examples=60)
@given(vectors, vectors)
def test_lagrange_identity(a, b):
    lhs = cross(a, b).length_squared() + dot(a, b) ** 2
    rhs = a.length_squared() * b.length_squared()
    assert math.isclose(lhs, rhs, rel_tol=1e-12, abs_tol=1e-300)


@settings(deadline=None, max_examples=60)
@given(vectors)
def test_unit_vector_has_length_one_and_same_direction(a):
    assume(norm(a) > 1e-3)
    u = unit_vector(a)
    assert math.isclose(u.length(), 1.0, rel_tol=0, abs_tol=4 * EPS)
    # Parallel and same orientation: a = |a| u.
    assert close_vec(u * norm(a), a, abs_tol=8 * EPS * norm(a))


def test_unit_vector_of_zero_raises():
    with pytest.raises(ZeroDivisionError):
        unit_vector(Vec3(0.0, 0.0, 0.0))


@settings(deadline=None, max_examples=60)
@given(vectors)
def test_length_squared_is_length_squared(a):
    assert math.isclose(a.length() ** 2, a.length_squared(), rel_tol=4 * EPS, abs_tol=1e-300)
    assert a.length_squared() == a.e0 * a.e0 + a.e1 * a.e1 + a.e2 * a.e2


def test_length_of_known_vector():
    assert Vec3(3.0, 4.0, 12.0).length() == 13.0
    assert Vec3(3.0, 4.0, 12.0).length_squared() == 169.0


def test_near_zero():
    assert Vec3(0.0, 0.0, 0.0).near_zero()
    assert Vec3(1e-9, -1e-9, 5e-9).near_zero()
    assert not Vec3(1e-9, -2e-8, 0.0).near_zero()
    assert not Vec3(0.0, 0.0, -1e-7).near_zero()
    # eps is a strict bound, and a custom eps can be given.
    assert not Vec3(1e-8, 0.0, 0.0).near_zero()
    assert Vec3(0.05, -0.05, 0.0).near_zero(0.1)
    assert not Vec3(0.05, -0.2, 0.0).near_zero(0.1)


def test_max_component_and_is_black():
    assert Vec3(-1.0, 7.0, 3.0).max_component() == 7.0
    assert Color(0.0, 0.0, 0.0).is_black()
    assert not Color(0.0, 1e-300, 0.0).is_black()


# --- Color keeps its type ----------------------------------------------------------


@settings(deadline=None, max_examples=60)
@given(colors, colors, st.floats(min_value=0.5, max_value=2.0))
def test_color_arithmetic_stays_color(a, b, s):
    for r in (a + b, a - b, -a, a * b, a * s, s * a, a / s, a + Vec3(1.0, 2.0, 3.0)):
        assert type(r) is Color
    assert comps(a * s) == (a.e0 * s, a.e1 * s, a.e2 * s)


def test_vec3_arithmetic_stays_vec3():
    a = Vec3(1.0, 2.0, 3.0)
    for r in (a + a, a - a, -a, a * a, a * 2.0, 2.0 * a, a / 2.0):
        assert type(r) is Vec3


# --- reflect and refract -------------------------------------------------------------

angles = st.floats(min_value=0.0, max_value=math.pi)
azimuths = st.floats(min_value=0.0, max_value=2.0 * math.pi)


@settings(deadline=None, max_examples=60)
@given(vectors, angles, azimuths)
def test_reflect_preserves_length_and_flips_normal_component(v, theta, phi):
    # Below ~1e-150 the squared length underflows into subnormal floats and the
    # identity can only hold to the subnormal spacing: outside the tested domain.
    assume(norm(v) > 1e-100)
    n = random_unit(theta, phi)
    r = reflect(v, n)
    scale = norm(v)
    assert math.isclose(r.length(), v.length(), rel_tol=1e-12, abs_tol=1e-12 * scale)
    assert math.isclose(dot(r, n), -dot(v, n), rel_tol=1e-12, abs_tol=1e-12 * scale)
    # The tangential part is unchanged: r - v is along n.
    diff = r - v
    assert cross(diff, n).length() <= 1e-12 * scale + 1e-300


def test_reflect_known_case():
    r = reflect(Vec3(1.0, -1.0, 0.0), Vec3(0.0, 1.0, 0.0))
    assert comps(r) == (1.0, 1.0, 0.0)


@settings(deadline=None, max_examples=60)
@given(
    st.floats(min_value=0.0, max_value=math.pi / 2 - 1e-3),
    azimuths,
    st.floats(min_value=0.4, max_value=2.5),
    angles,
    azimuths,
)
def test_refract_obeys_snell(theta_i, phi, eta, n_theta, n_phi):
    """eta = eta_i / eta_t; sin(theta_t) = eta sin(theta_i) below the critical angle."""
    assume(eta * math.sin(theta_i) < 1.0 - 1e-6)
    n = random_unit(n_theta, n_phi)
    # Build an incident unit direction pointing toward the surface (against n).
    helper = Vec3(1.0, 0.0, 0.0) if abs(n.e0) < 0.9 else Vec3(0.0, 1.0, 0.0)
    t1 = unit_vector(cross(n, helper))
    t2 = cross(n, t1)
    tangent = t1 * math.cos(phi) + t2 * math.sin(phi)
    d = tangent * math.sin(theta_i) - n * math.cos(theta_i)
    out = refract(d, n, eta)

    assert math.isclose(out.length(), 1.0, abs_tol=1e-12)
    # Transmitted: continues to the far side of the surface.
    cos_t = -dot(out, n)
    assert cos_t > 0.0
    sin_t = cross(out, n).length()  # accurate also near normal incidence
    expected_sin_t = eta * math.sin(theta_i)
    assert math.isclose(sin_t, expected_sin_t, abs_tol=1e-9)
    # Direction stays in the plane of incidence and on the same tangential side.
    assert abs(dot(out, cross(n, tangent))) < 1e-9
    if theta_i > 1e-6:
        assert dot(out, tangent) > 0.0


def test_refract_normal_incidence_goes_straight():
    out = refract(Vec3(0.0, 0.0, -1.0), Vec3(0.0, 0.0, 1.0), 1.0 / 1.5)
    assert close_vec(out, Vec3(0.0, 0.0, -1.0), abs_tol=1e-15)


def test_refract_known_case_45_degrees():
    # sin 45 / 1.5 = sin(theta_t), from air into glass.
    s = math.sqrt(0.5)
    out = refract(Vec3(s, -s, 0.0), Vec3(0.0, 1.0, 0.0), 1.0 / 1.5)
    sin_t = s / 1.5
    expected = Vec3(sin_t, -math.sqrt(1.0 - sin_t * sin_t), 0.0)
    assert close_vec(out, expected, abs_tol=1e-14)


@given(
    st.floats(0.0, math.pi),
    st.floats(0.0, 2 * math.pi),
    st.floats(0.0, math.pi),
    st.floats(0.0, 2 * math.pi),
)
def test_halfvector_is_the_unit_bisector(t1, p1, t2, p2):
    view, light = random_unit(t1, p1), random_unit(t2, p2)
    s = view + light
    assume(norm(s) > 1e-6)
    h = halfvector(view, light)
    assert math.isclose(norm(h), 1.0, abs_tol=1e-12)
    assert math.isclose(dot(h, view), dot(h, light), abs_tol=1e-12)  # equal angles
    assert close_vec(cross(h, s), Vec3(), abs_tol=1e-12 * norm(s))  # along view + light
    assert dot(h, s) > 0.0


def test_halfvector_known_case_and_no_half_vector_for_opposite_directions():
    h = halfvector(Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0))
    assert comps(h) == pytest.approx((math.sqrt(0.5), math.sqrt(0.5), 0.0), abs=1e-15)
    with pytest.raises(ZeroDivisionError):
        halfvector(Vec3(0.0, 0.0, 1.0), Vec3(0.0, 0.0, -1.0))
