# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 04 graders: sphere, quad and triangle intersection, the scene's closest hit.
Run them with `python -m rtpy grade 04`."""

import math
from pathlib import Path

import numpy as np

from rtpy import Camera, Color, Interval, Lambertian, Quad, Ray, Scene, Sphere, Triangle, Vec3
from rtpy.grading import assert_image_matches, deterministic_image, points

HERE = Path(__file__).parent
M = Lambertian()


def v(a):
    return Vec3(*map(float, a))


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


@points(3, task="04.1")
def test_sphere_hit_t():
    """Sphere.hit_t: nearest root inside (t_min, t_max), from outside and inside"""
    rng = np.random.default_rng(4)
    for k in range(300):
        c, r = rng.uniform(-1, 1, 3), rng.uniform(0.3, 2)
        o, d = random_ray(rng, c)
        if k % 5 == 0:
            o = c + rng.normal(size=3) * 0.1 * r  # from inside
        t_min, t_max = (0.0, math.inf) if k % 3 else (rng.uniform(0, 3), rng.uniform(3, 8))
        got = Sphere(v(c), r, M).hit_t(Ray(v(o), v(d)), t_min, t_max)
        check_t(got, sphere_t(o, d, c, r, t_min, t_max), f"Sphere.hit_t (rtpy/sphere.py), case {k}")


@points(2, task="04.1")
def test_sphere_hit_info():
    """Sphere.hit_info: point on the sphere, unit normal facing the ray, front_face"""
    rng = np.random.default_rng(44)
    for k in range(100):
        c, r = rng.uniform(-1, 1, 3), rng.uniform(0.3, 2)
        o, d = random_ray(rng, c, 0.2)
        if k % 2:
            o = c + rng.normal(size=3) * 0.1 * r
        inside = np.linalg.norm(o - c) < r
        t = sphere_t(o, d, c, r, 0.0, math.inf)
        if t is None:
            continue
        hit = Sphere(v(c), r, M).hit_info(Ray(v(o), v(d)), t)
        p, n = np.array(list(hit.point)), np.array(list(hit.normal))
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
def test_quad_hit():
    """Quad.hit_t: the plane, then 0 <= alpha, beta <= 1"""
    rng = np.random.default_rng(5)
    for k in range(300):
        q, u, w = rng.uniform(-1, 1, 3), rng.normal(size=3), rng.normal(size=3)
        o, d = random_ray(rng, q + 0.5 * u + 0.5 * w)
        expected = plane_t(o, d, q, u, w, lambda a, b: 0 <= a <= 1 and 0 <= b <= 1)
        got = Quad(v(q), v(u), v(w), M).hit_t(Ray(v(o), v(d)), 0.0, math.inf)
        check_t(got, expected, f"Quad.hit_t (rtpy/quad.py), case {k}")


@points(3, task="04.3")
def test_triangle_hit():
    """Triangle hit: inside the triangle only (u, v >= 0, u + v <= 1)"""
    rng = np.random.default_rng(6)
    for k in range(300):
        a, b, c = (rng.uniform(-1.5, 1.5, 3) for _ in range(3))
        o, d = random_ray(rng, (a + b + c) / 3)
        expected = plane_t(
            o, d, a, b - a, c - a, lambda bu, bv: bu >= 0 and bv >= 0 and bu + bv <= 1
        )
        got = Triangle(v(a), v(b), v(c), M).hit_t(Ray(v(o), v(d)), 0.0, math.inf)
        check_t(got, expected, f"Triangle._barycentric (rtpy/triangle.py), case {k}")


@points(2, task="04.4")
def test_closest_hit():
    """Scene.find_intersection: the closest of all objects"""
    rng = np.random.default_rng(7)
    behind = 0  # rays that hit more than one object
    for k in range(200):
        spheres = [Sphere(v(rng.uniform(-2, 2, 3)), rng.uniform(0.4, 1.0), M) for _ in range(7)]
        o, d = random_ray(rng, np.zeros(3), 1.0)
        ts = [(s.hit_t(Ray(v(o), v(d)), 0.0, math.inf), i) for i, s in enumerate(spheres)]
        ts = [(t, i) for t, i in ts if t is not None]
        hit = Scene(spheres).find_intersection(Ray(v(o), v(d)), Interval(0.0, math.inf))
        where = f"Scene.find_intersection (rtpy/scene.py), case {k}"
        if not ts:
            assert hit is None, f"{where}: no object is hit, expected None"
            continue
        behind += len(ts) > 1
        t, i = min(ts)
        assert hit is not None and abs(hit.t - t) < 1e-9 * max(1, t), (
            f"{where}: returned the hit at t = {None if hit is None else hit.t}, the closest is at t = {t}"
        )
        assert hit.obj is spheres[i], f"{where}: the hit record must name the closest object"
    assert behind > 20  # the cases test the choice of the closest hit


def shapes_scene():
    red, green, blue = (
        Lambertian(Color(*c)) for c in ((0.8, 0.2, 0.2), (0.2, 0.8, 0.2), (0.2, 0.2, 0.8))
    )
    objects = [
        Quad(Vec3(-3, -0.5, -6), Vec3(6, 0, 0), Vec3(0, 0, 6), Lambertian(Color(0.5, 0.5, 0.5))),
        Sphere(Vec3(-0.9, 0.0, -2.0), 0.5, red),
        Triangle(Vec3(-0.3, -0.5, -2.5), Vec3(0.5, -0.5, -2.5), Vec3(0.1, 0.6, -2.3), green),
        Sphere(Vec3(0.9, 0.1, -2.4), 0.6, blue),
    ]
    camera = Camera(Vec3(0, 0.3, 0.5), Vec3(0, 0, -2), vfov=60, aspect_ratio="16:9", width=48)
    return Scene(objects, sky=True, camera=camera)


REFERENCE = {"name": "center_shapes"}


def make_reference_image():
    return deterministic_image(shapes_scene(), integrator="center")


@points(2, task="04.4")
def test_center_render_matches_reference():
    """center integrator render of spheres, a quad and a triangle matches the reference"""
    image = deterministic_image(shapes_scene(), integrator="center")
    reference = np.load(HERE / "reference" / f"{REFERENCE['name']}.npy")
    assert_image_matches(
        image, reference, "center render", "check which object is closest "
        "(Scene.find_intersection) and the intersection tests", rtol=1e-9, atol=1e-12,
    )  # fmt: skip
