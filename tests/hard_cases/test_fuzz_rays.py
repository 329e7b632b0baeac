"""Random rays against every primitive, on both backends: finite hits on the surface.

Hypothesis draws seeds; each makes one sphere, quad or triangle at a random size
(10^-3 to 10^5) and place (up to 10^5 from the origin), and 40 rays: from random
points around it, from points on its surface (as spawned rays start), from inside
a sphere, in the plane of a quad or triangle, and aimed at a point inside it. The
scalar shape (`intersect`) and the numpy geometry (`BatchScene.find_intersection`
+ `hit_batch`) must report only hits with a finite t > 0, a finite point on the
surface (to the rounding of the coordinates' size), a unit normal facing the ray,
and (u, v) in [0, 1]; a ray aimed from outside at a point well inside the shape,
not grazing it, must hit it no farther than that point.

What naive formulas get wrong here: the textbook quadratic loses the root of a
big sphere far away to cancellation (the hit is off the surface), Moller-Trumbore
without a relative parallel test reports hits far from a triangle for rays in
its plane, and a quad's (a, b) by division returns NaN for a ray in its plane.
The extensions of tests/test_sphere.py, test_quad.py, test_triangle.py and
tests/numpy_backend/test_sphere.py etc., which aim rays at modest shapes or compare
the backends, to any ray at any scale.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given

from rtpy import Lambertian, Quad, Scene, Sphere, Triangle, Vec3
from rtpy.interval import Interval
from rtpy.numpy_backend.scene import BatchScene
from rtpy.ray import Ray

from .scene_strategies import fuzz_settings, seeds

N_RAYS = 40
# Hits are o + t d rounded (the sphere puts it back on the surface): allow 1e-9 of
# the size of the numbers involved (double rounding is 1e-16; this is far from the
# naive formulas' errors, which are 1e-3 and more of the size).
REL = 1e-9


def random_shape(rng: np.random.Generator):
    scale = 10.0 ** rng.uniform(-3, 5)
    offset = rng.normal(size=3) * 10.0 ** rng.uniform(-3, 5)
    kind = rng.choice(["sphere", "quad", "triangle"])
    mat = Lambertian()
    if kind == "sphere":
        return Sphere(Vec3(*offset), scale, mat)
    e1, e2 = rng.normal(size=(2, 3)) * scale
    if rng.random() < 0.3:
        e1[rng.integers(3)] = 0.0  # axis-aligned edges, as in the Cornell box
        e2[:] = 0.0
        e2[[i for i in range(3) if e1[i] == 0.0][0]] = scale
    if kind == "quad":
        return Quad(Vec3(*offset), Vec3(*e1), Vec3(*e2), mat)
    return Triangle(Vec3(*offset), Vec3(*(offset + e1)), Vec3(*(offset + e2)), mat)


def arr(v: Vec3) -> np.ndarray:
    return np.array([v.e0, v.e1, v.e2])


def frame(shape):
    """(corner, edge 1, edge 2) of a quad or triangle."""
    if isinstance(shape, Quad):
        return arr(shape.q), arr(shape.u), arr(shape.v)
    return arr(shape.a), arr(shape.e1), arr(shape.e2)


def inner_point(shape, rng, margin: float) -> np.ndarray:
    """A point inside the shape (at least `margin`, relative, from its edges)."""
    if isinstance(shape, Sphere):
        v = rng.normal(size=3)
        return arr(shape.center) + v / np.linalg.norm(v) * shape.radius * rng.uniform(0, 1 - margin)
    q, e1, e2 = frame(shape)
    a, b = rng.uniform(margin, 1 - margin, 2)
    if isinstance(shape, Triangle) and a + b > 1 - margin:
        a, b = (1 - margin - a) * 0.5 + margin / 2, (1 - margin - b) * 0.5 + margin / 2
    return q + a * e1 + b * e2


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_rays(shape, rng: np.random.Generator):
    """(origins, directions, aimed): rays of every kind; aimed[i] is the distance to
    a point well inside the shape the ray must reach, or nan."""
    size = shape.radius if isinstance(shape, Sphere) else np.linalg.norm(frame(shape)[1])
    centre = inner_point(shape, rng, 0.0)
    o = np.empty((N_RAYS, 3))
    d = unit(rng.normal(size=(N_RAYS, 3)))
    aimed = np.full(N_RAYS, np.nan)
    for i in range(N_RAYS):
        how = i % 4
        if how == 0:  # from anywhere around
            o[i] = centre + rng.normal(size=3) * size * 10.0 ** rng.uniform(-1, 2)
        elif how == 1:  # from a point of the surface (or inside a sphere)
            o[i] = inner_point(shape, rng, 0.0)
            if isinstance(shape, Sphere) and rng.random() < 0.5:
                o[i] = arr(shape.center) + unit(o[i] - arr(shape.center)) * shape.radius
        elif how == 2 and not isinstance(shape, Sphere):  # in the plane
            q, e1, e2 = frame(shape)
            o[i] = q + rng.uniform(-1, 2) * e1 + rng.uniform(-1, 2) * e2
            d[i] = unit(rng.uniform(-1, 1) * e1 + rng.uniform(-1, 1) * e2)
        else:  # aimed from outside at a point well inside
            target = inner_point(shape, rng, 0.05)
            o[i] = target - d[i] * size * 10.0 ** rng.uniform(0.5, 2)
            if isinstance(shape, Sphere):
                aimed[i] = np.linalg.norm(target - o[i])
            else:
                n = arr(shape.normal)
                if abs(d[i] @ n) > 0.05:  # not grazing
                    aimed[i] = np.linalg.norm(target - o[i])
    return o, d, aimed


def surface_error(shape, p: np.ndarray) -> float:
    """How far p is from the shape, and outside its edges (in its own units)."""
    if isinstance(shape, Sphere):
        return abs(np.linalg.norm(p - arr(shape.center)) - shape.radius)
    q, e1, e2 = frame(shape)
    n = arr(shape.normal)
    rel = p - q
    off_plane = abs(rel @ n)
    g = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
    a, b = np.linalg.solve(g, [rel @ e1, rel @ e2])
    outside = max(0.0, -a, -b, a + b - 1 if isinstance(shape, Triangle) else max(a, b) - 1)
    return off_plane + outside * np.linalg.norm(e1 + e2)


def check_hit(shape, o, d, t, point, normal, u, v, aimed) -> str:
    """'' if the hit is sound, else what is wrong."""
    values = np.concatenate([[t, u, v], point, normal])
    if not np.isfinite(values).all():
        return f"non-finite hit {values}"
    if not t > 0.0:
        return f"t = {t}"
    size = np.abs(o).max() + t + np.abs(point).max()
    if surface_error(shape, point) > REL * size:
        return f"point off the surface by {surface_error(shape, point):.3g} (size {size:.3g})"
    if abs(np.linalg.norm(normal) - 1.0) > 1e-12 or normal @ d > 1e-12:
        return f"normal {normal} not unit or not facing the ray {d}"
    if not (-1e-9 <= u <= 1 + 1e-9 and -1e-9 <= v <= 1 + 1e-9):
        return f"(u, v) = ({u}, {v})"
    if not math.isnan(aimed) and t > aimed + REL * size:
        return f"t = {t} beyond the aimed-at point at {aimed}"
    return ""


def scalar_hits(shape, o, d):
    for i in range(len(o)):
        ray = Ray(Vec3(*o[i]), Vec3(*d[i]))
        hit = shape.intersect(ray, Interval(0.0, math.inf))
        if hit is None:
            yield i, None
            continue
        u, v = shape.surface_uv(hit)
        yield i, (hit.t, arr(hit.point), arr(hit.normal), u, v)


def numpy_hits(shape, o, d):
    geo = BatchScene(Scene([shape]))
    geo.need_uv = True
    obj, t = geo.find_intersection(o, d)
    hit = np.flatnonzero(obj >= 0)
    batch = geo.hit_batch(obj[hit], o[hit], d[hit], t[hit])
    found = dict(zip(hit.tolist(), range(len(hit)), strict=True))
    for i in range(len(o)):
        k = found.get(i)
        if k is None:
            yield i, None
        else:
            yield i, (batch.t[k], batch.point[k], batch.normal[k], batch.u[k], batch.v[k])


@fuzz_settings(40)
@given(seed=seeds)
def test_random_rays_hit_every_primitive_soundly_on_both_backends(seed):
    rng = np.random.default_rng(seed)
    shape = random_shape(rng)
    o, d, aimed = random_rays(shape, rng)
    with np.errstate(all="ignore"):  # the kernels mask their own special cases
        for backend, hits in (("scalar", scalar_hits), ("numpy", numpy_hits)):
            for i, hit in hits(shape, o, d):
                where = f"{backend} {type(shape).__name__} ray {i}: o={o[i]!r} d={d[i]!r}"
                if hit is None:
                    assert math.isnan(aimed[i]), f"{where}: missed the point it aims at"
                    continue
                problem = check_hit(shape, o[i], d[i], *hit, aimed[i])
                assert not problem, f"{where}: {problem}"


def test_the_check_rejects_naive_hits():
    """check_hit flags a NaN t, a hit behind the origin, a point off the surface by
    1e-6 of its size, a normal facing away and a miss of the aimed-at point."""
    s = Sphere(Vec3(0, 0, 0), 1e5, Lambertian())
    o, d = np.array([0.0, 0.0, 3e5]), np.array([0.0, 0.0, -1.0])
    p, n = np.array([0.0, 0.0, 1e5]), np.array([0.0, 0.0, 1.0])
    assert check_hit(s, o, d, 2e5, p, n, 0.5, 0.5, 2e5) == ""
    assert "non-finite" in check_hit(s, o, d, math.nan, p, n, 0.5, 0.5, math.nan)
    assert "t =" in check_hit(s, o, d, -1.0, p, n, 0.5, 0.5, math.nan)
    assert "off the surface" in check_hit(s, o, d, 2e5, p * (1 + 1e-6), n, 0.5, 0.5, math.nan)
    assert "facing" in check_hit(s, o, d, 2e5, p, -n, 0.5, 0.5, math.nan)
    assert "beyond" in check_hit(s, o, d, 2e5, p, n, 0.5, 0.5, 1.5e5)
