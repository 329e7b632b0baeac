# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 04 graders: sphere, quad and triangle intersection, the scene's closest hit.
Run them with `python -m rtpy grade 04`.

Each test is a verdict: it asks the student's code for numbers through `probe`
(the probes are in probes.py beside this file) and decides here, in the judge.
"""

import math
from pathlib import Path

import numpy as np

from rtpy.grading import assert_image_matches, points, scene_uses

HERE = Path(__file__).parent


def random_ray(rng, toward, spread=1.5):
    o = rng.uniform(-4, 4, 3)
    d = toward + rng.normal(size=3) * spread - o
    return o, d / np.linalg.norm(d)


def sphere_t(o, d, c, r, t_min, t_max):
    """Reference: the smallest root of |o + t d - c|^2 = r^2 in (t_min, t_max)."""
    oc = o - c
    b, cc = d @ oc, oc @ oc - r * r
    disc = b * b - cc
    if disc < 0:
        return None
    for t in sorted((-b - math.sqrt(disc), -b + math.sqrt(disc))):
        if t_min < t < t_max:
            return t
    return None


def check_t(got, expected, where):
    if expected is None:
        assert got is None, (
            f"{where}: reported a hit at t = {got}, but the ray misses in the interval"
        )
    else:
        assert got is not None and abs(got - expected) <= 1e-7 * max(1, abs(expected)), (
            f"{where}: t = {got}, expected {expected:.9g} (the nearest hit with t_min < t < t_max)"
        )


def ray_case(shape: dict, o, d, t_min: float = 0.0, t_max: float = math.inf) -> dict:
    """A case of the probe shape_hit_t (assignments/week04/probes.py)."""
    return {"shape": shape, "origin": o, "direction": d, "t_min": t_min, "t_max": t_max}


@points(3, task="04.1")
def test_sphere_hit_t(probe):
    """Sphere.hit_t: nearest root inside (t_min, t_max), from outside and inside"""
    rng = np.random.default_rng(4)
    cases, expected = [], []
    for k in range(300):
        c, r = rng.uniform(-1, 1, 3), rng.uniform(0.3, 2)
        o, d = random_ray(rng, c)
        if k % 5 == 0:
            o = c + rng.normal(size=3) * 0.1 * r  # from inside
        t_min, t_max = (0.0, math.inf) if k % 3 else (rng.uniform(0, 3), rng.uniform(3, 8))
        cases.append(ray_case({"type": "Sphere", "center": c, "radius": r}, o, d, t_min, t_max))
        expected.append(sphere_t(o, d, c, r, t_min, t_max))
    for k, (got, want) in enumerate(zip(probe.shape_hit_t(cases=cases), expected, strict=True)):
        check_t(got, want, f"Sphere.hit_t (rtpy/sphere.py), case {k}")


@points(2, task="04.1")
def test_sphere_hit_info(probe):
    """Sphere.hit_info: point on the sphere, unit normal facing the ray, front_face"""
    rng = np.random.default_rng(44)
    cases = []
    for k in range(100):
        c, r = rng.uniform(-1, 1, 3), rng.uniform(0.3, 2)
        o, d = random_ray(rng, c, 0.2)
        if k % 2:
            o = c + rng.normal(size=3) * 0.1 * r
        t = sphere_t(o, d, c, r, 0.0, math.inf)
        if t is None:
            continue
        cases.append({"center": c, "radius": r, "origin": o, "direction": d, "t": t})
    for case, hit in zip(cases, probe.sphere_hit_info(cases=cases), strict=True):
        c, r, o, d, t = (case[k] for k in ("center", "radius", "origin", "direction", "t"))
        inside = np.linalg.norm(o - c) < r
        p, n = hit.point, hit.normal
        where = (
            f"Sphere.hit_info (rtpy/sphere.py) for a ray from {'inside' if inside else 'outside'}"
        )
        assert np.allclose(p, o + t * d, atol=1e-7), f"{where}: point {p} is not o + t d"
        assert abs(np.linalg.norm(n) - 1) < 1e-9, f"{where}: the normal must be a unit vector"
        outward = (p - c) / r
        assert hit.front_face == (not inside), f"{where}: front_face should be {not inside}"
        assert np.allclose(n, outward if not inside else -outward, atol=1e-7), (
            f"{where}: the normal must face the arriving ray (outward from outside, inward from inside)"
        )


def plane_t(o, d, corner, e1, e2, inside):
    """t > 0 where the ray o + t d meets the plane corner + a e1 + b e2 at a point with
    inside(a, b), else None (also for a ray parallel to the plane)."""
    n = np.cross(e1, e2)
    if abs(n @ d) <= 1e-9:
        return None
    t = n @ (corner - o) / (n @ d)
    a, b = np.linalg.lstsq(np.stack([e1, e2], 1), o + t * d - corner, rcond=None)[0]
    return t if t > 0 and inside(a, b) else None


@points(3, task="04.2")
def test_quad_hit(probe):
    """Quad.hit_t: the plane, then 0 <= alpha, beta <= 1"""
    rng = np.random.default_rng(5)
    cases, expected = [], []
    for _ in range(300):
        q, u, w = rng.uniform(-1, 1, 3), rng.normal(size=3), rng.normal(size=3)
        o, d = random_ray(rng, q + 0.5 * u + 0.5 * w)
        expected.append(plane_t(o, d, q, u, w, lambda a, b: 0 <= a <= 1 and 0 <= b <= 1))
        cases.append(ray_case({"type": "Quad", "corner": q, "u": u, "v": w}, o, d))
    for k, (got, want) in enumerate(zip(probe.shape_hit_t(cases=cases), expected, strict=True)):
        check_t(got, want, f"Quad.hit_t (rtpy/quad.py), case {k}")


@points(3, task="04.3")
def test_triangle_hit(probe):
    """Triangle hit: inside the triangle only (u, v >= 0, u + v <= 1)"""
    rng = np.random.default_rng(6)
    cases, expected = [], []
    for _ in range(300):
        a, b, c = (rng.uniform(-1.5, 1.5, 3) for _ in range(3))
        o, d = random_ray(rng, (a + b + c) / 3)
        expected.append(
            plane_t(o, d, a, b - a, c - a, lambda bu, bv: bu >= 0 and bv >= 0 and bu + bv <= 1)
        )
        cases.append(ray_case({"type": "Triangle", "a": a, "b": b, "c": c}, o, d))
    for k, (got, want) in enumerate(zip(probe.shape_hit_t(cases=cases), expected, strict=True)):
        check_t(got, want, f"Triangle._barycentric (rtpy/triangle.py), case {k}")


@points(2, task="04.4")
def test_closest_hit(probe):
    """Scene.find_intersection: the closest of all objects"""
    rng = np.random.default_rng(7)
    cases, closest = [], []
    for _ in range(200):
        spheres = [(rng.uniform(-2, 2, 3), rng.uniform(0.4, 1.0)) for _ in range(7)]
        o, d = random_ray(rng, np.zeros(3), 1.0)
        ts = [(sphere_t(o, d, c, r, 0.0, math.inf), i) for i, (c, r) in enumerate(spheres)]
        closest.append([(t, i) for t, i in ts if t is not None])  # computed here
        cases.append({"spheres": spheres, "origin": o, "direction": d, "interval": [0.0, math.inf]})
    behind = 0  # rays that hit more than one object
    got = probe.scene_closest_hit(cases=cases)
    for k, (hit, ts) in enumerate(zip(got, closest, strict=True)):
        where = f"Scene.find_intersection (rtpy/scene.py), case {k}"
        if not ts:
            assert hit is None, f"{where}: no object is hit, expected None"
            continue
        behind += len(ts) > 1
        t, i = min(ts)
        assert hit is not None and abs(hit.t - t) < 1e-9 * max(1, t), (
            f"{where}: returned the hit at t = {None if hit is None else hit.t}, the closest is at t = {t}"
        )
        assert hit.index == i, f"{where}: the hit record must name the closest object"
    assert behind > 20  # the cases test the choice of the closest hit


REFERENCE = {"name": "center_shapes"}
CENTER = {"integrator": "center", "spp": 1}  # one ray through each pixel's center, seed 0


def make_reference_image(probe):
    return probe.render(scene="week04_shapes", seeds=[0], settings=CENTER)[0]


@points(2, task="04.4")
@scene_uses("04.1", "04.2", "04.3")
def test_center_render_matches_reference(probe):
    """center integrator render of spheres, a quad and a triangle matches the reference"""
    image = probe.render(scene="week04_shapes", seeds=[0], settings=CENTER)[0]
    reference = np.load(HERE / "reference" / f"{REFERENCE['name']}.npy", allow_pickle=False)
    assert_image_matches(
        image, reference, "center render", "check which object is closest "
        "(Scene.find_intersection) and the intersection tests", rtol=1e-9, atol=1e-12,
    )  # fmt: skip
