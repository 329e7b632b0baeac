"""Batched light sampling against rtpy/light.py and the shapes' sample_direction /
direction_pdf, with the same uniform numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from rtpy import Color, DiffuseLight, Lambertian, PointLight, Quad, Scene, Sphere, Triangle, Vec3
from rtpy.hit_info import HitInfo
from rtpy.numpy_backend.hittable import PrimitiveSet
from rtpy.numpy_backend.light import LightSamples
from rtpy.numpy_backend.scene import BatchScene
from rtpy.sampling import use_generator
from rtpy.triangle import PARALLEL_TOLERANCE

from .geometry_checks import V, arr
from .test_camera import Replay

coord = st.floats(-4.0, 4.0, allow_nan=False)
vec = st.tuples(coord, coord, coord)
# Away from 0 and 1: a sample exactly on a quad's or triangle's edge may hit or miss
# it by rounding, differently in the two implementations.
unit = st.floats(1e-6, 1.0 - 1e-6)
LIGHT = DiffuseLight(Color(3.0, 2.0, 1.0))


def shapes(center, size, a, b):
    """A sphere, and a quad and a triangle when a, b span a usable parallelogram."""
    c, s = np.array(center), size
    out = [Sphere(V(c), s, LIGHT)]
    ua, ub = np.array(a) * s, np.array(b) * s
    if np.linalg.norm(np.cross(ua, ub)) > 1e-2 * (1 + np.linalg.norm(ua) * np.linalg.norm(ub)):
        out.append(Quad(V(c), V(ua), V(ub), LIGHT))
        out.append(Triangle(V(c), V(c + ua), V(c + ub), LIGHT))
    return out


def table(shape):
    """The LightTable of a scene of one shape, and the BatchScene."""
    scene = BatchScene(Scene([shape]))
    scene.need_uv = scene.need_tangent = True
    return scene.lights, scene


@settings(max_examples=150)
@given(vec, st.floats(0.1, 2.0), vec, vec, vec, unit, unit)
# a thin triangle seen at |cos| = 1.04e-6: the scalar relative parallel test misses it
@example((0.0, 0.0, 0.0), 1.0, (0.0, 1.0, 0.0), (1e-6, 1.0, 1.0), (0.0, 0.0, 1.0), 0.5, 0.5)
def test_area_light_sample_matches_area_light(center, size, a, b, p, r1, r2):
    for shape in shapes(center, size, a, b):
        lights, geo = table(shape)
        pp = np.array([p], dtype=np.float64)
        # The shape's own sample_direction, then the full AreaLight.sample.
        prims, local, _ = geo.set_of(np.array([0]))[0]
        d, pdf, valid = prims.sample_direction(local, pp, np.array([r1]), np.array([r2]))
        ref = shape.sample_direction(V(p), r1, r2)
        assert bool(valid[0]) == (ref is not None)
        if ref is not None:
            np.testing.assert_allclose(d[0], arr(ref[0]), rtol=1e-12, atol=1e-12)
            assert pdf[0] == pytest.approx(ref[1], rel=1e-12)
        out = empty_samples(1)
        lights.sample_area(pp, np.array([0]), np.array([r1]), np.array([r2]), out, np.array([0]))
        with use_generator(Replay([r1, r2])):
            s = scene_light(shape).sample(V(p))
        if s is None:  # unless p lies in a planar light's plane (a sample worth nothing)
            grazing = abs(np.dot(out.direction[0], shape_normal(shape, None, out.point[0])))
            assert not out.valid[0] or not out.pdf[0] > 0 or grazing < grazing_limit(shape)
            continue
        if not out.valid[0]:  # a grazing direction rounding moved off the shape
            assert abs(np.dot(arr(s.direction), shape_normal(shape, s))) < grazing_limit(shape)
            continue
        np.testing.assert_allclose(out.direction[0], arr(s.direction), rtol=1e-12, atol=1e-12)
        if abs(np.dot(arr(s.direction), shape_normal(shape, s))) < grazing_limit(shape):
            continue  # grazing: the scalar code's tracing to the point is ill-conditioned
        assert out.distance[0] == pytest.approx(s.distance, rel=1e-9)
        assert out.pdf[0] == pytest.approx(s.pdf, rel=1e-12)
        np.testing.assert_allclose(out.radiance[0], arr(s.radiance))
        np.testing.assert_allclose(out.point[0], arr(s.point), rtol=1e-9, atol=1e-9)


def shape_normal(shape, s, point=None):
    if isinstance(shape, Sphere):
        n = (arr(s.point) if point is None else point) - arr(shape.center)
        return n / np.linalg.norm(n)
    return arr(shape.normal)


def grazing_limit(shape) -> float:
    """|cos| between a direction and the shape's plane below which the scalar
    code may count the direction as parallel (a miss). A triangle's relative
    parallel test, det^2 <= (tol |e1| |e2|)^2 |d|^2 with |det| = |d| |e1 x e2| |cos|,
    misses up to |cos| = tol |e1| |e2| / |e1 x e2|: more than tol for thin triangles."""
    if isinstance(shape, Triangle):
        e1, e2 = arr(shape.e1), arr(shape.e2)
        sine = np.linalg.norm(np.cross(e1, e2)) / (np.linalg.norm(e1) * np.linalg.norm(e2))
        return 1.01 * PARALLEL_TOLERANCE / sine
    return 1e-6


def scene_light(shape):
    return Scene([shape]).area_lights[0]


def empty_samples(n):
    z = np.zeros
    return LightSamples(z((n, 3)), z(n), z((n, 3)), z(n), z(n, bool), z((n, 3)), z(n, bool))


@settings(max_examples=150)
@given(vec, st.floats(0.1, 2.0), vec, vec, vec, unit, unit)
def test_direction_pdf_matches_scalar(center, size, a, b, p, r1, r2):
    for shape in shapes(center, size, a, b):
        lights, geo = table(shape)
        q, n = shape.sample_point(r1, r2)
        hit = HitInfo(q, n, 1.0, True, LIGHT, shape)
        ref = shape.direction_pdf(V(p), hit)
        got = lights.direction_pdf(np.array([0]), np.array([p]), arr(q)[None], arr(n)[None])[0]
        assert got == pytest.approx(ref, rel=1e-12)


def test_light_choice_and_point_lights():
    scene = Scene(
        [Sphere(Vec3(0, 3, 0), 0.5, LIGHT), Sphere(Vec3(0, -1, 0), 0.5, Lambertian())],
        point_lights=[
            PointLight(Vec3(1, 2, 3), Color(4, 5, 6)),
            PointLight(Vec3(-1, 0, 0), Color(1, 1, 1)),
        ],
    )
    lights = BatchScene(scene).lights
    assert (lights.n_point, lights.n_area, lights.n) == (2, 1, 3)
    n = 30000
    p = np.tile([0.0, 0.0, 0.0], (n, 1))
    s = lights.sample(p, np.random.default_rng(2))
    assert s.valid.all()
    frac = [np.mean(s.is_delta & (s.point[:, 0] == x)) for x in (1, -1)]
    np.testing.assert_allclose(frac, 1 / 3, atol=4 * math.sqrt(2 / 9 / n))
    ref = scene.point_lights[0].sample(Vec3(0, 0, 0))
    k = np.flatnonzero(s.is_delta & (s.point[:, 0] == 1))[0]
    np.testing.assert_array_equal(s.direction[k], arr(ref.direction))
    np.testing.assert_array_equal(s.radiance[k], arr(ref.radiance))
    assert s.distance[k] == ref.distance and s.pdf[k] == 1.0
    only_points = lights.sample(p[:1000], np.random.default_rng(3), include_area=False)
    assert only_points.is_delta.all()


def test_points_nearer_a_light_than_the_least_distance_give_no_sample():
    """As the scalar PointLight.sample and Hittable.sample_direction: at 1e-160 from a
    point light (or from the point sampled on an area light) I / d^2 and 1 / pdf are
    inf; below 1e-50 the sample is invalid and direction_pdf 0. At 1e-49 they are
    the scalar numbers."""
    heights = np.array([1e-160, 1e-51, 1e-49])
    p = np.column_stack([np.zeros(3), heights, np.zeros(3)])
    scene = Scene([], point_lights=[PointLight(Vec3(0, 0, 0), Color(1e9, 1e9, 1e9))])
    s = BatchScene(scene).lights.sample(p, np.random.default_rng(0))
    np.testing.assert_array_equal(s.valid, [False, False, True])
    ref = scene.point_lights[0].sample(V(p[2]))
    np.testing.assert_array_equal(s.radiance[2], arr(ref.radiance))
    quad = Quad(Vec3(-1, 0, -1), Vec3(2, 0, 0), Vec3(0, 0, 2), LIGHT)  # (0.5, 0.5) -> origin
    lights, _ = table(quad)
    out = empty_samples(3)
    half = np.full(3, 0.5)
    lights.sample_area(p, np.zeros(3, dtype=np.int64), half, half, out, np.arange(3))
    np.testing.assert_array_equal(out.valid, [False, False, True])
    assert out.pdf[2] == quad.sample_direction(V(p[2]), 0.5, 0.5)[1]
    origin, normal = np.zeros((3, 3)), np.tile([0.0, 1.0, 0.0], (3, 1))
    pdf = lights.direction_pdf(np.zeros(3, dtype=np.int64), p, origin, normal)
    assert pdf[0] == pdf[1] == 0.0 and pdf[2] > 0.0


def test_one_sided_light_seen_from_behind_gives_no_radiance():
    quad = Quad(Vec3(-1, 2, -1), Vec3(2, 0, 0), Vec3(0, 0, 2), LIGHT)  # normal -y... or +y
    lights, _ = table(quad)
    above = np.array([[0.0, 5.0, 0.0]]) if arr(quad.normal)[1] > 0 else np.array([[0.0, -5.0, 0.0]])
    below = -above + np.array([[0.0, 4.0, 0.0]])
    for p, lit in ((above, True), (below, False)):
        out = empty_samples(1)
        lights.sample_area(p, np.array([0]), np.array([0.3]), np.array([0.6]), out, np.array([0]))
        assert out.valid[0]
        assert (out.radiance[0].max() > 0) == lit


@pytest.mark.parametrize("name", ["cornell", "week08_three_balls"])
def test_single_light_fast_path_matches_the_general_path(name):
    """sample_single (one DiffuseLight area light: a quad, a sphere) gives what the
    general sample() gives from the same random numbers, sample for sample (a
    sphere's distance and point to rounding, see SphereSet.sample_light)."""
    import rtpy

    lights = BatchScene(rtpy.load_scene(name)).lights
    assert lights.single is not None
    rng = np.random.default_rng(5)
    lo, hi = (0.0, 555.0) if name == "cornell" else (-2.0, 2.0)
    p = rng.uniform(lo, hi, (4000, 3))
    fast = lights.sample(p, np.random.default_rng(9))
    lights.single = None
    general = lights.sample(p, np.random.default_rng(9))
    np.testing.assert_array_equal(fast.valid, general.valid)
    assert fast.valid.mean() > 0.5
    v = fast.valid
    for field in ("direction", "radiance", "pdf", "is_delta", "obj"):
        np.testing.assert_array_equal(getattr(fast, field)[v], getattr(general, field)[v])
    # A sphere's distance follows from the sampled angle, not a trace: equal to rounding.
    np.testing.assert_allclose(fast.distance[v], general.distance[v], rtol=1e-12)
    np.testing.assert_allclose(fast.point[v], general.point[v], rtol=1e-12, atol=1e-12)
    # Both faces are seen: lit samples and samples from behind a one-sided light.
    lit = fast.radiance[v].max(axis=1) > 0
    assert lit.any() and (name == "week08_three_balls" or not lit.all())


@settings(max_examples=150)
@given(vec, st.floats(0.05, 3.0), st.lists(st.tuples(vec, unit, unit), min_size=1, max_size=20))
def test_sphere_fused_sample_light_matches_the_general_path(center, radius, samples):
    """SphereSet.sample_light for one sphere (int k) against the general
    PrimitiveSet.sample_light (sample_direction, then hit_t traces to the sphere):
    the same directions and pdfs bit for bit; the fused path's distance from the
    sampled angle agrees with the trace to 1e-9 (the scalar tests' tolerance), and so
    do the points and normals. Where the trace misses by rounding, the direction grazes
    the sphere (on the cone's edge). Points inside the sphere take the general path."""
    geo = BatchScene(Scene([Sphere(V(center), radius, LIGHT)]))
    prims = geo.sets[0]
    p = np.array([s[0] for s in samples], dtype=np.float64)
    r1 = np.array([s[1] for s in samples])
    r2 = np.array([s[2] for s in samples])
    d, pdf, valid, t, point, normal = prims.sample_light(0, p, r1, r2)
    gd, gpdf, gvalid, gt, gpoint, gnormal = PrimitiveSet.sample_light(prims, 0, p, r1, r2)
    np.testing.assert_array_equal(d, gd)
    np.testing.assert_array_equal(pdf, gpdf)
    both = valid & gvalid
    np.testing.assert_allclose(t[both], gt[both], rtol=1e-9)
    np.testing.assert_allclose(point[both], gpoint[both], rtol=1e-9, atol=1e-9 * radius)
    np.testing.assert_allclose(normal[both], gnormal[both], rtol=0, atol=1e-7)
    for i in np.flatnonzero(valid != gvalid):
        assert valid[i]  # only the trace may miss, and only at grazing incidence
        assert abs(float(np.dot(normal[i], d[i]))) < 1e-4
    assert np.all(np.isfinite(t[valid])) and np.all(t[valid] > 0)
