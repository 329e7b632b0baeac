"""Tests for rtpy.bvh: the slab test, bounding boxes, the tree, and that the scene's
BVH queries give exactly the hits of testing every object (brute force)."""

from __future__ import annotations

import functools
import math
import struct
from fractions import Fraction

import pytest
from hypothesis import HealthCheck, Phase, assume, find, given, settings
from hypothesis import strategies as st

import rtpy
import rtpy.bvh
import rtpy.scene
from rtpy.bvh import AABB, BVH, Tree
from rtpy.hittable import Hittable
from rtpy.interval import Interval
from rtpy.materials import Lambertian
from rtpy.quad import Quad
from rtpy.ray import Ray, spawn_ray
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.triangle import Triangle
from rtpy.vec3 import Vec3, cross

from .in_list_order import in_list_order
from .tiers import slow_except
from .vectors import V

MAT = Lambertian()
FORWARD = Interval(0.0, math.inf)
INF = math.inf


def bvh_scene(objects) -> Scene:
    """A scene that uses its BVH however few objects it has."""
    scene = Scene(list(objects))
    scene.bvh_min_objects = 0
    return scene


# --- the slab test -----------------------------------------------------------
# BVH._search tests a node's box when the node comes off its stack; a probe object
# whose box is a given box shows whether a ray got through: the search calls its
# hit_t exactly then.

UNIT_BOX = AABB(V(-1, -1, -1), V(1, 1, 1))


class Probe(Hittable):
    """An object with a given bounding box that counts the calls of its hit_t."""

    def __init__(self, box: AABB) -> None:
        self.box = box
        self.material = MAT
        self.calls = 0

    def bounding_box(self) -> AABB:
        return self.box

    def hit_t(self, ray, t_min, t_max):
        self.calls += 1
        return None


def enters(box: AABB, origin, direction, t_min=0.0, t_max=INF) -> bool:
    """Whether the BVH's box test lets the ray through `box` (the box exactly: no
    rounding margin) for some t in [t_min, t_max]."""
    probe = Probe(box)
    ray = Ray(Vec3(*map(float, origin)), Vec3(*map(float, direction)))
    BVH([probe], margin=0.0).any_hit(ray, t_min, t_max)
    return probe.calls == 1


@pytest.mark.parametrize(
    "origin, direction, t_min, t_max, expected",
    [
        ((0, 0, 5), (0, 0, -1), 0.0, INF, True),  # straight in through the +z face
        ((0, 0, -5), (0, 0, 1), 0.0, INF, True),  # from the other side
        ((0, 0, 5), (0, 0, -2), 0.0, 2.0, True),  # t is in units of the direction's length
        ((0, 0, 5), (0, 0, -2), 0.0, 1.9, False),
        ((0, 0, 5), (0, 0, 1), 0.0, INF, False),  # pointing away
        ((0, 0, 5), (0, 0, -1), 0.0, 3.9, False),  # the box is beyond t_max
        ((0, 0, 5), (0, 0, -1), 0.0, 4.0, True),  # entering exactly at t_max counts
        ((0, 0, 5), (0, 0, -1), 6.0, INF, True),  # t_min inside the box
        ((0, 0, 5), (0, 0, -1), 6.5, INF, False),  # t_min past the box
        ((0, 0, 5), (0, 0, -1), -INF, INF, True),
        ((0, 0, -5), (0, 0, -1), -INF, INF, True),  # behind the origin, when allowed
        ((0, 0, -5), (0, 0, -1), -INF, -6.5, False),
        ((0.5, 0.2, 0), (1, 2, 3), 0.0, INF, True),  # starts inside
        ((0.5, 0.2, 0), (1, 2, 3), 0.25, INF, True),
        ((1, 0, 0), (1, 0, 0), 0.0, INF, True),  # starts on a face, leaving
        ((1, 0, 0), (1, 0, 0), 0.5, INF, False),
        ((2, 0, 0), (-1, 1, 0), 0.0, INF, True),  # grazes the edge x = y = 1 at one point
        ((2, 0.5, 0), (-1, 1, 0), 0.0, INF, False),  # passes the edge by
        ((2, 2, 2), (-1, -1, -1), 0.0, INF, True),  # enters at the corner
        ((3, 0, 3), (-1, 0, -1), 0.0, INF, True),  # diagonally in through the x = z = 1 edge
        ((-1, 3, -1), (1, -1, 1), 0.0, INF, True),  # touches only the corner (1, 1, 1)
        ((-1, 3.5, -1), (1, -1, 1), 0.0, INF, False),
        ((-1, 3, 1), (1, -1, 0), 0.0, INF, True),  # the same in the plane z = 1
        ((-1, 3, 1), (1, -1, 0), 0.0, 1.9, False),
    ],
)
def test_slab_test_analytic(origin, direction, t_min, t_max, expected):
    assert enters(UNIT_BOX, origin, direction, t_min, t_max) == expected


@pytest.mark.parametrize("zero", [0.0, -0.0])
@pytest.mark.parametrize(
    "origin, expected",
    [
        ((0.3, 5, 0.2), True),  # inside the x and z slabs: only y decides
        ((1, 5, -1), True),  # on the x = 1 face's plane and the z = -1 plane: closed box
        ((-1, 5, 1), True),
        ((1.5, 5, 0), False),  # outside the x slab, moving parallel to it
        ((-1.5, 5, 0), False),
        ((0, 5, -1.0000001), False),
        ((0, 5, 1.0000001), False),
    ],
)
def test_slab_test_with_zero_direction_components(zero, origin, expected):
    # No division by zero, and 0 * inf = nan (the origin on a slab's plane) changes
    # nothing.
    assert enters(UNIT_BOX, origin, (zero, -1.0, zero)) == expected
    assert enters(UNIT_BOX, origin, (zero, -1.0, zero), 0.0, 3.9) is False


def test_slab_test_on_a_flat_box():
    flat = AABB(V(-1, -1, 0), V(1, 1, 0))  # zero thickness in z: still closed
    assert enters(flat, (0, 0, 3), (0, 0, -1))
    assert enters(flat, (0, 0, 3), (0.1, 0, -1))
    assert enters(flat, (0, 0, 0), (1, 0, 0))  # in its plane
    assert not enters(flat, (0, 0, 1e-300), (1, 0, 0))


def test_slab_test_lets_every_ray_through_an_infinite_box():
    everywhere = AABB(V(-INF, -INF, -INF), V(INF, INF, INF))
    for direction in ((0, 0, 1), (0, 0, -1), (1, -2, 3), (-1, 0, 0)):
        assert enters(everywhere, (5, -7, 1e300), direction)


def exact_entry(lo, hi, o, d, t_min: Fraction, t_max: Fraction) -> Fraction | None:
    """The slab test in exact rational arithmetic."""
    for axis in range(3):
        if d[axis] == 0:
            if not lo[axis] <= o[axis] <= hi[axis]:
                return None
            continue
        a = (Fraction(lo[axis]) - Fraction(o[axis])) / Fraction(d[axis])
        b = (Fraction(hi[axis]) - Fraction(o[axis])) / Fraction(d[axis])
        t_min, t_max = max(t_min, min(a, b)), min(t_max, max(a, b))
    return t_min if t_min <= t_max else None


def inside(lo, hi, p) -> bool:
    return all(lo[i] <= p[i] <= hi[i] for i in range(3))


quarter = st.integers(-20, 20).map(lambda k: k / 4)
# Powers of two (and both zeros): with these every float operation of the slab test
# (1 / d included) is exact, so the float answer must equal the rational one.
power_of_two = st.sampled_from([0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.0, -2.0, 4.0, -4.0])


@given(
    corners=st.lists(st.tuples(quarter, quarter), min_size=3, max_size=3),
    o=st.tuples(quarter, quarter, quarter),
    d=st.tuples(power_of_two, power_of_two, power_of_two),
    t_range=st.tuples(quarter, quarter).map(sorted),
)
def test_slab_test_equals_the_exact_answer(corners, o, d, t_range):
    assume(any(c != 0.0 for c in d))
    lo = tuple(min(pair) for pair in corners)
    hi = tuple(max(pair) for pair in corners)
    box = AABB(Vec3(*lo), Vec3(*hi))
    t_min, t_max = (Fraction(t) for t in t_range)
    expected = exact_entry(lo, hi, o, d, t_min, t_max)
    assert enters(box, o, d, t_range[0], t_range[1]) == (expected is not None)
    # And the meaning of the exact answer: the first point of the ray segment
    # inside the closed box.
    samples = [t_min + (t_max - t_min) * Fraction(k, 64) for k in range(65)]
    at = [tuple(Fraction(o[i]) + t * Fraction(d[i]) for i in range(3)) for t in samples]
    if expected is None:
        assert not any(inside(lo, hi, p) for p in at)
    else:
        p = tuple(Fraction(o[i]) + expected * Fraction(d[i]) for i in range(3))
        assert inside(lo, hi, p)
        assert not any(inside(lo, hi, q) for t, q in zip(samples, at, strict=True) if t < expected)


# --- shapes -----------------------------------------------------------------

GRID = st.integers(-12, 12).map(lambda k: k / 4)  # dyadic: coincident hits tie exactly
coordinates = st.one_of(GRID, st.floats(-3.0, 3.0, allow_nan=False, allow_infinity=False))
points = st.builds(Vec3, coordinates, coordinates, coordinates)
lengths = st.one_of(st.integers(1, 12).map(lambda k: k / 4), st.floats(0.05, 3.0))
signed_lengths = st.tuples(lengths, st.booleans()).map(lambda x: -x[0] if x[1] else x[0])


def along(axis: int, length: float) -> Vec3:
    e = [0.0, 0.0, 0.0]
    e[axis] = length
    return Vec3(*e)


@st.composite
def spheres(draw) -> Sphere:
    return Sphere(draw(points), draw(lengths), MAT)


@st.composite
def edge_pairs(draw, axis_aligned: bool | None = None) -> tuple[Vec3, Vec3]:
    """Two edge vectors spanning a non-degenerate parallelogram; often (or, with
    axis_aligned=True, always) along two coordinate axes."""
    if axis_aligned or (axis_aligned is None and draw(st.booleans())):
        a, b, _ = draw(st.permutations([0, 1, 2]))
        return along(a, draw(signed_lengths)), along(b, draw(signed_lengths))
    u, v = draw(points), draw(points)
    assume(cross(u, v).length() > 1e-3)
    return u, v


@st.composite
def quads(draw, axis_aligned: bool | None = None) -> Quad:
    u, v = draw(edge_pairs(axis_aligned))
    return Quad(draw(points), u, v, MAT)


@st.composite
def triangles(draw) -> Triangle:
    a = draw(points)
    u, v = draw(edge_pairs())
    return Triangle(a, a + u, a + v, MAT)


shapes = st.one_of(spheres(), quads(), triangles())


def twin(obj: Hittable) -> Hittable:
    """A new object with the same geometry: every ray hits both at the same t."""
    if isinstance(obj, Sphere):
        return Sphere(obj.center, obj.radius, MAT)
    if isinstance(obj, Quad):
        return Quad(obj.q, obj.u, obj.v, MAT)
    return Triangle(obj.a, obj.b, obj.c, MAT)


def neighbour(obj: Hittable, axis: int, radius: float) -> Hittable:
    """An object touching obj: a sphere tangent to it along the axis, the quad
    sharing its edge q + u .. q + u + v, the triangle sharing its edge b .. c."""
    if isinstance(obj, Sphere):
        return Sphere(obj.center + along(axis, obj.radius + radius), radius, MAT)
    if isinstance(obj, Quad):
        return Quad(obj.q + obj.u, obj.u, obj.v, MAT)
    return Triangle(obj.c, obj.b, obj.b + obj.c - obj.a, MAT)


@st.composite
def object_lists(draw, max_size: int = 24, kinds=shapes) -> list[Hittable]:
    objects = draw(st.lists(kinds, min_size=1, max_size=max_size))
    for _ in range(draw(st.integers(0, 6))):
        obj = objects[draw(st.integers(0, len(objects) - 1))]
        if draw(st.booleans()):
            objects.append(twin(obj))
        else:
            objects.append(neighbour(obj, draw(st.integers(0, 2)), draw(lengths)))
    return draw(st.permutations(objects))


unit_floats = st.one_of(st.sampled_from([0.0, 0.5, 1.0]), st.floats(0.0, 1.0))


@st.composite
def surface_points(draw, obj: Hittable) -> Vec3:
    """A point on obj, often on an edge, at a corner or on a sphere's pole."""
    if isinstance(obj, Sphere):
        return obj.sample_point(draw(unit_floats), draw(unit_floats))[0]
    if isinstance(obj, Quad):
        return obj.q + obj.u * draw(unit_floats) + obj.v * draw(unit_floats)
    s, t = draw(unit_floats), draw(unit_floats)
    if s + t > 1.0:
        s, t = 1.0 - s, 1.0 - t
    return obj.a + obj.e1 * s + obj.e2 * t


directions = st.builds(Vec3, *[st.floats(-1.0, 1.0)] * 3).filter(lambda d: d.length() > 1e-3)
intervals = st.one_of(
    st.just(FORWARD),
    st.just(Interval(1e-9, INF)),
    st.just(Interval(-INF, INF)),
    st.builds(Interval, st.floats(-5.0, 5.0), st.just(INF)),
    st.builds(Interval, st.just(0.0), st.floats(0.0, 10.0)),
)


@st.composite
def queries(draw, objects: list[Hittable]) -> tuple[Ray, Interval]:
    """A ray and an interval: from anywhere, from inside a sphere or from a surface,
    in a random direction or aimed at a point (edge, corner) of an object."""
    start = draw(st.sampled_from(["anywhere", "inside", "surface"]))
    inner = [o for o in objects if isinstance(o, Sphere)]
    if start == "inside" and inner:
        sphere = draw(st.sampled_from(inner))
        origin = sphere.center + draw(directions) * (0.5 * sphere.radius)
    elif start == "surface":
        origin = draw(surface_points(draw(st.sampled_from(objects))))
    else:
        origin = draw(st.builds(Vec3, *[st.floats(-6.0, 6.0)] * 3))
    if draw(st.booleans()):
        direction = draw(surface_points(draw(st.sampled_from(objects)))) - origin
        assume(direction.length() > 1e-6)
        if draw(st.booleans()):
            direction = direction / direction.length()
    else:
        direction = draw(directions)
    return Ray(origin, direction), draw(intervals)


def bits(x: float) -> bytes:
    return struct.pack("<d", x)


def same_hit(a, b) -> bool:
    """The same HitInfo, field by field, floats bit for bit."""
    if a is None or b is None:
        return a is None and b is None
    return (
        a.obj is b.obj
        and bits(a.t) == bits(b.t)
        and [bits(x) for x in (*a.point, *a.normal)] == [bits(x) for x in (*b.point, *b.normal)]
        and a.front_face == b.front_face
        and a.material is b.material
        and (bits(a.u), bits(a.v)) == (bits(b.u), bits(b.v))
    )


def mismatch(scene: Scene, ray: Ray, interval: Interval) -> str | None:
    """How the scene's BVH queries differ from brute force on this ray, or None."""
    got = scene.find_intersection(ray, interval)
    listed = in_list_order(scene)
    want = listed.find_intersection(ray, interval)
    if not same_hit(got, want):
        return f"find_intersection: BVH {got!r} on {got and got.obj!r}, brute force {want!r}"
    if scene.find_occlusion(ray, interval) != listed.find_occlusion(ray, interval):
        return "find_occlusion differs"
    return None


@st.composite
def scenes_with_queries(draw, max_objects: int = 24, rays: int = 12, kinds=shapes):
    scene = bvh_scene(draw(object_lists(max_objects, kinds)))
    return scene, [draw(queries(scene.objects)) for _ in range(rays)]


def first_mismatch(example) -> str | None:
    scene, rays = example
    for ray, interval in rays:
        found = mismatch(scene, ray, interval)
        if found is not None:
            return f"{ray!r} {interval!r}: {found}"
    return None


@pytest.mark.slow
@settings(max_examples=200, suppress_health_check=[HealthCheck.too_slow])
@given(scenes_with_queries())
def test_bvh_hits_equal_brute_force_hits(example):
    assert first_mismatch(example) is None


@settings(max_examples=100, suppress_health_check=[HealthCheck.too_slow])
@given(scenes_with_queries(max_objects=4, rays=6))
def test_bvh_hits_equal_brute_force_hits_in_tiny_scenes(example):
    assert first_mismatch(example) is None


@settings(max_examples=25, suppress_health_check=[HealthCheck.too_slow])
@given(scenes_with_queries(max_objects=16, rays=6))
def test_the_readable_builders_tree_finds_the_same_closest_hits(example):
    scene, rays = example
    fast, readable = BVH(scene.objects, readable=False), BVH(scene.objects, readable=True)
    for ray, interval in rays:
        lo, hi = interval.min, interval.max
        assert fast.closest_hit(ray, lo, hi) == readable.closest_hit(ray, lo, hi)
        assert fast.any_hit(ray, lo, hi) == readable.any_hit(ray, lo, hi)


@given(shapes, st.lists(st.tuples(unit_floats, unit_floats), max_size=20))
def test_bounding_box_contains_the_shape(shape, samples):
    box = shape.bounding_box()
    if isinstance(shape, Sphere):
        c, r = shape.center, shape.radius
        extremes = [c + along(axis, sign * r) for axis in range(3) for sign in (-1.0, 1.0)]
    elif isinstance(shape, Quad):
        extremes = [shape.q, shape.q + shape.u, shape.q + shape.v, shape.q + shape.u + shape.v]
    else:
        extremes = [shape.a, shape.b, shape.c]
    for p in extremes + [shape.sample_point(r1, r2)[0] for r1, r2 in samples]:
        assert box.contains(p), (p, box)
    # Never flat (axis-aligned quads and triangles are padded), and never much
    # bigger than the shape.
    exact = AABB.from_points(*extremes)
    assert box.x0 < box.x1 and box.y0 < box.y1 and box.z0 < box.z1
    slack = 1e-6 * exact.magnitude()
    assert box.x0 >= exact.x0 - slack and box.x1 <= exact.x1 + slack
    assert box.y0 >= exact.y0 - slack and box.y1 <= exact.y1 + slack
    assert box.z0 >= exact.z0 - slack and box.z1 <= exact.z1 + slack


def test_axis_aligned_quad_box_is_padded():
    box = Quad(V(0, 0, 2), V(1, 0, 0), V(0, 1, 0), MAT).bounding_box()
    assert box.z0 < 2.0 < box.z1


def test_base_hittable_has_no_box():
    assert Hittable().bounding_box() is None


# --- the checks can fail ----------------------------------------------------

FIND = settings(max_examples=2000, phases=[Phase.generate], database=None, derandomize=True)


def unpadded_quad_box(self: Quad) -> AABB:
    return AABB.from_points(self.q, self.q + self.u, self.q + self.v, self.q + self.u + self.v)


def test_the_equality_check_catches_a_quad_box_without_padding(monkeypatch):
    # Flat boxes and no rounding margin: a quad's hit test accepts points a few ulps
    # outside its edges (its (a, b) coordinates round), which the exact box test
    # rejects, so hits are lost or go to the wrong one of two coincident quads.
    monkeypatch.setattr(Quad, "bounding_box", unpadded_quad_box)
    monkeypatch.setattr(rtpy.scene, "BVH", functools.partial(BVH, margin=0.0))
    example = find(
        scenes_with_queries(kinds=quads(axis_aligned=True)),
        lambda ex: first_mismatch(ex) is not None,
        settings=FIND,
    )
    assert first_mismatch(example) is not None


def test_the_equality_check_catches_a_sphere_box_that_is_too_small(monkeypatch):
    def shrunk(self: Sphere) -> AABB:
        c, r = self.center, self.radius * 0.999
        return AABB(Vec3(c.e0 - r, c.e1 - r, c.e2 - r), Vec3(c.e0 + r, c.e1 + r, c.e2 + r))

    monkeypatch.setattr(Sphere, "bounding_box", shrunk)
    example = find(
        scenes_with_queries(kinds=spheres()),
        lambda ex: first_mismatch(ex) is not None,
        settings=FIND,
    )
    assert first_mismatch(example) is not None


def test_the_equality_check_catches_a_missing_tie_rule(monkeypatch):
    # A BVH that keeps the first object it meets on equal t (instead of the one
    # earliest in the list) differs from brute force on coincident objects.
    class LaterObjectsFirst(BVH):
        """Meets the objects in reverse list order and keeps the first one found."""

        def closest_hit(self, ray, t_min, t_max):
            best = None
            for index in sorted(self.tree.order.tolist(), reverse=True):
                t = self.objects[index].hit_t(ray, t_min, t_max if best is None else best[1])
                if t is not None:
                    best = (index, t)
            return best

    monkeypatch.setattr(rtpy.scene, "BVH", LaterObjectsFirst)
    example = find(scenes_with_queries(), lambda ex: first_mismatch(ex) is not None, settings=FIND)
    assert "find_intersection" in first_mismatch(example)


# --- ties -------------------------------------------------------------------


def test_coincident_objects_resolve_to_the_earliest(monkeypatch):
    monkeypatch.setattr(rtpy.bvh, "LEAF_SIZE", 1)  # every object in its own leaf
    objects = [Sphere(V(0, 0, -5), 1.0, MAT) for _ in range(9)]
    scene = bvh_scene(objects)
    for direction in (V(0, 0, -1), V(0.1, 0.05, -1), V(-0.1, 0, -1)):
        hit = scene.find_intersection(Ray(V(0, 0, 0), direction), FORWARD)
        assert hit.obj is objects[0]


def test_equal_t_found_later_in_the_tree_still_wins_by_list_order(monkeypatch):
    # A small quad (index 0) lies inside a big coplanar one (index 1), each in a
    # leaf; the split puts the big one on the right, the side a ray running toward
    # -x meets first, so the BVH tests it first. The small quad, hit at the same t
    # afterwards, must replace it.
    monkeypatch.setattr(rtpy.bvh, "LEAF_SIZE", 1)
    small = Quad(V(-0.5, -0.5, -2), V(1, 0, 0), V(0, 1, 0), MAT)
    big = Quad(V(-50, -50, -2), V(100, 0, 0), V(0, 100, 0), MAT)
    scene = bvh_scene([small, big])
    order = []
    for obj in (small, big):
        original = obj.hit_t

        def logged(ray, t_min, t_max, obj=obj, original=original):
            order.append(obj)
            return original(ray, t_min, t_max)

        obj.hit_t = logged
    ray = Ray(V(0.25, 0.125, 0), V(-0.01, 0, -1))
    hit = scene.find_intersection(ray, FORWARD)
    assert order == [big, small]
    assert hit.obj is small and hit.t == 2.0
    assert same_hit(hit, in_list_order(scene).find_intersection(ray, FORWARD))


def test_ray_in_the_plane_of_coplanar_triangles():
    # Found by the property test: a ray starting on one triangle and running in
    # the plane it shares with its neighbours. Moller-Trumbore's det was rounding
    # noise, and brute force reported a "hit" at t = -0.0, 3 units from triangle
    # 2, which no box can contain. Triangle now treats such rays as parallel.
    a = V(-1.0773574356499704, -0.5207559457521471, 4.75)
    b = V(-0.3227501586549413, -3.140671325866939, 0.25)
    c = V(-2.4001075943049117, -3.520755945752147, 2.75)
    objects = [
        Triangle(a, b, c, MAT),
        Triangle(a, b, c, MAT),
        Triangle(V(1.0, -0.14067132586693898, 2.25), b, a, MAT),
        Triangle(c, b, V(-1.6455003173098826, -6.140671325866939, -1.75), MAT),
    ]
    origin = V(-1.264074230175989, -4.480459250674289, -0.13773435885498242)
    direction = V(-0.09364692189594584, 0.5390520440149776, 0.8370502660310725)
    ray, everywhere = Ray(origin, direction), Interval(-INF, INF)
    assert objects[2].hit_t(ray, -INF, INF) is None
    assert mismatch(bvh_scene(objects), ray, everywhere) is None


# --- the tree ---------------------------------------------------------------


def check_tree(tree: Tree, boxes: list[AABB]) -> None:
    """Every box in exactly one leaf of at most LEAF_SIZE, inside the leaf's box, and
    every node's box inside its parent's."""
    lo, hi, child, count = tree.lo.tolist(), tree.hi.tolist(), tree.child, tree.count
    seen = []
    for node in range(len(tree)):
        box = AABB(Vec3(*lo[node]), Vec3(*hi[node]))
        if count[node] == 0:
            for c in (child[node], child[node] + 1):
                assert contains_box(box, AABB(Vec3(*lo[c]), Vec3(*hi[c])))
            continue
        assert 1 <= count[node] <= rtpy.bvh.LEAF_SIZE
        for index in tree.order[child[node] : child[node] + count[node]].tolist():
            assert contains_box(box, boxes[index])
            seen.append(index)
    assert sorted(seen) == list(range(len(boxes)))


def contains_box(outer: AABB, inner: AABB) -> bool:
    return outer.contains(inner.lo) and outer.contains(inner.hi)


@pytest.mark.parametrize("readable", slow_except([False, True], False))
@given(objects=object_lists(max_size=40))
def test_tree_holds_every_object_once_inside_nested_boxes(readable, objects):
    bvh = BVH(objects, readable=readable)
    check_tree(bvh.tree, [o.bounding_box() for o in objects])


def test_nearer_child_first_and_interval_shrinks():
    # 64 spheres in a row along the ray: the first one hides the rest, so the BVH
    # should test only a few of them.
    objects = [Sphere(V(3 * i, 0, 0), 1.0, MAT) for i in range(64)]
    calls = []
    for obj in objects:
        original = obj.hit_t

        def counted(ray, t_min, t_max, original=original):
            calls.append(1)
            return original(ray, t_min, t_max)

        obj.hit_t = counted
    scene = bvh_scene(objects)
    for origin, direction, first in (
        (V(-10, 0, 0), V(1, 0, 0), 0),
        (V(300, 0, 0), V(-1, 0, 0), 63),
    ):
        calls.clear()
        hit = scene.find_intersection(Ray(origin, direction), FORWARD)
        assert hit.obj is objects[first]
        assert len(calls) <= 2 * rtpy.bvh.LEAF_SIZE


class Plane(Hittable):
    """y = 0, unbounded: no bounding box."""

    def __init__(self) -> None:
        self.material = MAT

    def hit_t(self, ray, t_min, t_max):
        if ray.direction.e1 == 0.0:
            return None
        t = -ray.origin.e1 / ray.direction.e1
        return t if t_min < t < t_max else None

    def hit_info(self, ray, t):
        return rtpy.HitInfo(ray.at(t), V(0, 1, 0), t, ray.direction.e1 < 0.0, MAT, self)


def test_unbounded_objects_are_tested_on_every_ray():
    plane = Plane()
    objects = [Sphere(V(i, 0, -3), 0.4, MAT) for i in range(-5, 6)]
    objects.insert(4, plane)
    objects.append(Sphere(V(0, 0, -3), 0.4, MAT))  # coincident with objects[6]
    bvh = BVH(objects)
    assert bvh.unbounded == [4]
    scene = bvh_scene(objects)
    for direction in (V(0, -1, -1), V(0, 0, -1), V(0.3, -0.01, -1), V(0, 1, 0)):
        ray = Ray(V(0, 0.5, 0), direction)
        assert mismatch(scene, ray, FORWARD) is None
    assert scene.find_intersection(Ray(V(0, 0.5, 0), V(0, -1, 0)), FORWARD).obj is plane


def test_empty_and_single_object():
    ray = Ray(V(0, 0, 0), V(0, 0, -1))
    assert BVH([]).closest_hit(ray, 0.0, INF) is None
    assert not BVH([]).any_hit(ray, 0.0, INF)
    sphere = Sphere(V(0, 0, -3), 1.0, MAT)
    assert BVH([sphere]).closest_hit(ray, 0.0, INF) == (0, 2.0)
    assert BVH([sphere]).any_hit(ray, 0.0, INF)


# --- the scene's cache ------------------------------------------------------


def row_of_spheres(n: int, z: float = -5.0) -> list[Sphere]:
    return [Sphere(V(2 * i, 0, z), 0.5, MAT) for i in range(n)]


def test_small_scenes_test_every_object():
    scene = Scene(row_of_spheres(Scene.bvh_min_objects - 1))
    assert scene.find_intersection(Ray(V(0, 0, 0), V(0, 0, -1)), FORWARD) is not None
    assert scene._bvh is None


def test_bvh_is_built_once_and_rebuilt_when_objects_change():
    scene = Scene(row_of_spheres(12))
    ray = Ray(V(0, 0, 0), V(0, 0, -1))
    assert scene.find_intersection(ray, FORWARD).obj is scene.objects[0]
    bvh = scene.bvh()
    assert scene.bvh() is bvh  # cached

    nearer = Sphere(V(0, 0, -2), 0.5, MAT)
    scene.add_object(nearer)  # Scene.add_object
    assert scene.find_intersection(ray, FORWARD).obj is nearer
    assert scene.bvh() is not bvh

    nearest = Sphere(V(0, 0, -1), 0.25, MAT)
    scene.objects[3] = nearest  # a change to the list itself
    assert scene.find_intersection(ray, FORWARD).obj is nearest
    assert scene.find_occlusion(ray, Interval(0.0, 0.8))

    scene.objects = row_of_spheres(12, z=-9.0)  # a new list
    assert scene.find_intersection(ray, FORWARD).t == pytest.approx(8.5)

    del scene.objects[:]
    scene.objects.extend(row_of_spheres(12, z=-7.0))
    assert scene.find_intersection(ray, FORWARD).t == pytest.approx(6.5)


def test_bundled_cover_scene_matches_brute_force():
    # Camera rays and one bounce each, on the ~480-sphere scene the BVH is for.
    scene = rtpy.load_scene("rtiow_cover")
    assert len(scene.objects) >= scene.bvh_min_objects
    camera = scene.camera.with_width(24)
    for j in range(0, camera.height, 2):
        for i in range(0, camera.width, 2):
            ray = camera.get_center_ray(i, j)
            assert mismatch(scene, ray, FORWARD) is None
            hit = scene.find_intersection(ray, FORWARD)
            if hit is not None:
                bounce = spawn_ray(hit.point, hit.normal, hit.normal + V(0.3, 0.2, -0.1))
                assert mismatch(scene, bounce, FORWARD) is None
