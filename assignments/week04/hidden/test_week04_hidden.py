# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 04 hidden checks: only the autograder holds them (assignments/week04/hidden/
never ships to students). Their inputs come from grading_seed, new for every
submission, so code that is right only for the graders' fixed inputs fails them.

Every ray is built to hit a shape at a known point, well inside it, or to miss it by
a clear margin, from outside (and, for spheres, from inside), so the expected t is
exact and the cases are far from the edges where rounding could decide: a correct
solution never fails these checks (false-failure rate 0).
"""

import math

import numpy as np
import pytest

from rtpy.grading import points
from rtpy.grading.autograder_seed import grading_rng

REL = 1e-7  # relative tolerance on t; rounding is about 1e-15


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def perpendicular(rng, d: np.ndarray) -> np.ndarray:
    """A random unit vector perpendicular to the unit vector d."""
    p = rng.normal(size=3)
    return unit(p - (p @ d) * d)


def check(got, want, where: str) -> None:
    if want is None:
        assert got is None, f"{where}: reported a hit at t = {got}, but the ray misses"
    else:
        assert got is not None and abs(got - want) <= REL * max(1.0, want), (
            f"{where}: t = {got}, expected {want:.9g} (the nearest hit with t_min < t < t_max)"
        )


def checked_hits(probe, asked: list) -> None:
    """Ask shape_hit_t (assignments/week04/probes.py) for the cases of `asked`, a list of
    (case, expected t or None, where), in one call, and check them in order."""
    got = probe.shape_hit_t(cases=[case for case, _, _ in asked])
    for t, (_, want, where) in zip(got, asked, strict=True):
        check(t, want, where)


def ray_case(shape: dict, o, d, t_min: float, t_max: float = math.inf) -> dict:
    return {"shape": shape, "origin": o, "direction": d, "t_min": t_min, "t_max": t_max}


@points(3)
def test_sphere_hits_at_new_rays(probe):
    """Sphere.hit_t: new rays from outside and inside, hits, misses, the interval"""
    rng = grading_rng(401)
    asked = []
    for _ in range(150):
        c, r = rng.uniform(-3, 3, 3), float(rng.uniform(0.3, 2.0))
        d = unit(rng.normal(size=3))
        s = float(rng.choice([rng.uniform(0.0, 0.9), rng.uniform(1.1, 2.0)]))
        b, far = r * s, float(rng.uniform(r + 0.5, r + 6))  # miss distance, along the ray
        o = c + b * perpendicular(rng, d) - far * d
        sphere = {"type": "Sphere", "center": c, "radius": r}
        where = f"Sphere.hit_t (rtpy/sphere.py), center {c.round(3)}, radius {r:.3f}, ray from {o.round(3)} along {d.round(3)}"
        if s > 1:
            asked.append((ray_case(sphere, o, d, 1e-9), None, where))
            continue
        half = math.sqrt(r * r - b * b)
        near, exit_ = far - half, far + half
        asked.append((ray_case(sphere, o, d, 1e-9), near, where))
        asked.append(
            (ray_case(sphere, o, d, 1e-9, near * 0.99), None, f"{where}, t_max below the hit")
        )
        asked.append(
            (
                ray_case(sphere, o, d, near * 1.01 + 1e-3),
                exit_,
                f"{where}, t_min past the first root (the far root)",
            )
        )
        start = c + float(rng.uniform(0, 0.8)) * r * unit(rng.normal(size=3))
        oc = c - start
        h = oc @ d
        want = h + math.sqrt(h * h - (oc @ oc - r * r))  # the root ahead, from inside
        asked.append(
            (ray_case(sphere, start, d, 1e-9), want, f"{where}, from inside at {start.round(3)}")
        )
    checked_hits(probe, asked)


def planar_case(rng, inside: bool, triangle: bool) -> tuple[float, float]:
    """Coordinates (alpha, beta) of a point well inside the quad (0 <= alpha, beta <= 1)
    or triangle (also alpha + beta <= 1), or clearly outside, by a margin of 0.05."""
    while True:
        a, b = (float(x) for x in rng.uniform(-0.6, 1.6, 2))
        lo, hi = min(a, b), max(a, b, a + b if triangle else b)
        if inside and lo >= 0.05 and hi <= 0.95:
            return a, b
        if not inside and (lo < -0.05 or hi > 1.05):
            return a, b


def approach(rng, p: np.ndarray, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(origin, unit direction, distance) of a ray reaching p at least 12 degrees off its plane."""
    while True:
        d = unit(rng.normal(size=3))
        if abs(d @ normal) > 0.2:
            break
    dist = float(rng.uniform(0.5, 6))
    return p - dist * d, d, dist


# One case per task (04.2 Quad, 04.3 Triangle): a stub costs only its own points.
@pytest.mark.parametrize(
    "kind",
    [pytest.param("Quad", marks=points(1.5)), pytest.param("Triangle", marks=points(1.5))],
)
def test_quad_and_triangle_hits_at_new_rays(kind, probe):
    """Quad.hit_t and Triangle.hit_t: new shapes and rays, inside, outside, the interval"""
    rng = grading_rng(402)
    asked = []
    for _ in range(100):
        q = rng.uniform(-3, 3, 3)
        u = rng.uniform(-2, 2, 3)
        v = rng.uniform(-2, 2, 3)
        n = np.cross(u, v)
        if np.linalg.norm(n) < 0.3 * np.linalg.norm(u) * np.linalg.norm(v):
            continue  # nearly parallel edges
        quad = {"type": "Quad", "corner": q, "u": u, "v": v}
        for shape in (quad, {"type": "Triangle", "a": q, "b": q + u, "c": q + v}):
            triangle = shape["type"] == "Triangle"
            inside = bool(rng.integers(2))
            a, b = planar_case(rng, inside, triangle)
            o, d, dist = approach(rng, q + a * u + b * v, unit(n))
            name = "Triangle.hit_t (rtpy/triangle.py)" if triangle else "Quad.hit_t (rtpy/quad.py)"
            where = f"{name}, q {q.round(3)}, u {u.round(3)}, v {v.round(3)}, ray through alpha {a:.3f}, beta {b:.3f}"
            asked.append((ray_case(shape, o, d, 1e-9), dist if inside else None, where))
            if inside:
                asked.append(
                    (
                        ray_case(shape, o, d, 1e-9, dist * 0.99),
                        None,
                        f"{where}, t_max below the hit",
                    )
                )
    checked_hits(probe, [a for a in asked if a[0]["shape"]["type"] == kind])


@points(2)
def test_closest_hit_among_new_spheres(probe):
    """Scene.find_intersection: the nearest of new spheres along a ray, in any order"""
    rng = grading_rng(403)
    cases, expected = [], []
    for _ in range(30):
        o, d = rng.uniform(-2, 2, 3), unit(rng.normal(size=3))
        k = int(rng.integers(3, 9))  # below the BVH's threshold: the loop is tested
        distances = np.sort(rng.uniform(1, 30, k))
        gaps = np.diff(np.concatenate([[0.0], distances]))
        if gaps.min() < 0.5:
            continue
        radii = 0.2 * gaps
        spheres = [[o + t * d, float(r)] for t, r in zip(distances, radii, strict=True)]
        order = rng.permutation(k)
        listed = [spheres[i] for i in order]
        nearest = int(np.argmin(order))  # where the nearest sphere is listed
        t_hit = float(distances[0] - radii[0])
        cases.append({"spheres": listed, "origin": o, "direction": d, "interval": [1e-9, math.inf]})
        cases.append(
            {"spheres": listed, "origin": o, "direction": d, "interval": [1e-9, t_hit * 0.99]}
        )
        expected.append((k, nearest, t_hit, distances[0]))
    got = probe.scene_closest_hit(cases=cases)
    for (k, nearest, t_hit, distance), hit, limited in zip(
        expected, got[::2], got[1::2], strict=True
    ):
        where = f"Scene.find_intersection (rtpy/scene.py) with {k} spheres on a ray, the nearest listed at position {nearest + 1}"
        assert hit is not None, f"{where}: returned None"
        assert abs(hit.t - t_hit) <= REL * distance, (
            f"{where}: hit t = {hit.t:.6g}, expected the nearest sphere at t = {t_hit:.6g}"
        )
        assert hit.index == nearest, (
            f"{where}: the hit at the right t names another object (hit.obj must be the "
            "nearest sphere)"
        )
        assert limited is None, f"{where}: a hit beyond interval.max must not count"
