# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 03 hidden checks: only the autograder holds them (assignments/week03/hidden/
never ships to students). Their inputs come from grading_seed, new for every
submission, so code that is right only for the graders' fixed inputs fails them.

False failures: the vector, interval and camera-ray checks are exact up to rounding
(inputs drawn well away from degenerate cases, tolerances a thousand times the
rounding error): a correct solution never fails them. The jitter check is a
chi-square test at ALPHA: a correct get_ray fails it with probability ALPHA per
submission.
"""

import math

import numpy as np

from rtpy import Camera, Interval, Vec3
from rtpy.grading import points
from rtpy.grading.autograder_seed import grading_rng, grading_seed
from rtpy.sampling import make_generator, use_generator
from rtpy.testing import chi2_sf
from rtpy.vec3 import cross, unit_vector

ALPHA = 1e-4


def vec(a) -> Vec3:
    return Vec3(*(float(x) for x in a))


def arr(v) -> np.ndarray:
    return np.array(list(v), dtype=float)


@points(2)
def test_vector_utilities_at_new_inputs():
    """cross, unit_vector and Interval at new random inputs"""
    rng = grading_rng(301)
    for _ in range(200):
        a, b = rng.uniform(-10, 10, 3), rng.uniform(-10, 10, 3)
        got, want = arr(cross(vec(a), vec(b))), np.cross(a, b)
        scale = np.linalg.norm(a) * np.linalg.norm(b)
        assert np.allclose(got, want, rtol=0, atol=1e-12 * scale), (
            f"cross (rtpy/vec3.py)({a.round(4)}, {b.round(4)}) = {got.round(6)}, expected {want.round(6)}"
        )
        got, want = arr(unit_vector(vec(a))), a / np.linalg.norm(a)
        assert np.allclose(got, want, rtol=0, atol=1e-12), (
            f"unit_vector (rtpy/vec3.py)({a.round(4)}) = {got.round(6)}, expected {want.round(6)}"
        )
    for _ in range(100):
        lo, hi = sorted(float(x) for x in rng.uniform(-5, 5, 2))
        interval = Interval(lo, hi)
        for x in (float(rng.uniform(-6, 6)), lo, hi):
            where = f"Interval({lo:.4f}, {hi:.4f}) (rtpy/interval.py) at x = {x:.4f}"
            assert bool(interval.contains(x)) == (lo <= x <= hi), (
                f"{where}: contains is min <= x <= max"
            )
            assert bool(interval.surrounds(x)) == (lo < x < hi), (
                f"{where}: surrounds is min < x < max"
            )
            assert interval.clamp(x) == min(max(x, lo), hi), (
                f"{where}: clamp(x) = {interval.clamp(x)}"
            )


def new_camera(rng) -> Camera:
    """A camera with random placement, field of view and image size."""
    look_from = rng.uniform(-5, 5, 3)
    look_at = look_from + rng.uniform(0.5, 3) * unit(rng.normal(size=3))
    vup = unit(rng.normal(size=3))
    while abs(vup @ unit(look_at - look_from)) > 0.9:  # not near the view direction
        vup = unit(rng.normal(size=3))
    return Camera(
        vec(look_from),
        vec(look_at),
        vec(vup),
        vfov=float(rng.uniform(20, 120)),
        aspect_ratio=float(rng.uniform(0.5, 2.0)),
        width=int(rng.integers(4, 40)),
        focus_distance=float(rng.uniform(0.5, 5)),
    )


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def viewport(cam: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(center of pixel (0, 0), one pixel right, one pixel down) on the focus plane,
    computed here from the camera's parameters."""
    eye = arr(cam.look_from)
    w = unit(eye - arr(cam.look_at))
    u = unit(np.cross(arr(cam.vup), w))
    v = np.cross(w, u)
    height = 2 * math.tan(math.radians(cam.vfov) / 2) * cam.focus_distance
    width = height * cam.width / cam.height
    right, down = u * width / cam.width, -v * height / cam.height
    corner = eye - w * cam.focus_distance - u * width / 2 + v * height / 2
    return corner + (right + down) / 2, right, down


@points(2)
def test_center_rays_of_a_new_camera():
    """Camera.get_center_ray: through the pixel's center, for a new random camera"""
    rng = grading_rng(302)
    for _ in range(5):
        cam = new_camera(rng)
        pixel00, right, down = viewport(cam)
        for _ in range(10):
            i, j = int(rng.integers(cam.width)), int(rng.integers(cam.height))
            ray = cam.get_center_ray(i, j)
            want = unit(pixel00 + i * right + j * down - arr(cam.look_from))
            got = arr(ray.direction)
            assert np.allclose(arr(ray.origin), arr(cam.look_from), atol=1e-12), (
                "Camera.get_center_ray (rtpy/camera.py): the ray starts at look_from"
            )
            assert np.allclose(got, want, atol=1e-9), (
                f"Camera.get_center_ray({i}, {j}) (rtpy/camera.py) of a {cam.width}x{cam.height} camera: "
                f"direction {got.round(6)}, expected the unit vector toward the pixel's center "
                f"{want.round(6)}; pixel (0, 0) is the top-left one"
            )


@points(2)
def test_jittered_rays_of_a_new_camera():
    """Camera.get_ray: uniform over the pixel, for a new random camera"""
    rng = grading_rng(303)
    cam = new_camera(rng)
    pixel00, right, down = viewport(cam)
    i, j, n = int(rng.integers(cam.width)), int(rng.integers(cam.height)), 4000
    eye, w = arr(cam.look_from), unit(arr(cam.look_from) - arr(cam.look_at))
    offsets = np.empty((n, 2))
    with use_generator(make_generator(grading_seed(304), 3)):
        for k in range(n):
            ray = cam.get_ray(i, j)
            o, d = arr(ray.origin), arr(ray.direction)
            t = ((eye - w * cam.focus_distance - o) @ w) / (d @ w)  # to the focus plane
            p = o + t * d - pixel00
            offsets[k] = (p @ right / (right @ right) - i, p @ down / (down @ down) - j)
    where = f"Camera.get_ray({i}, {j}) (rtpy/camera.py) of a {cam.width}x{cam.height} camera"
    assert np.all(np.abs(offsets) <= 0.5 + 1e-9), (
        f"{where}: rays leave the pixel's square: offsets from its center reach "
        f"{np.abs(offsets).max():.3f} pixels (at most 0.5)"
    )
    counts, _, _ = np.histogram2d(*offsets.T, bins=4, range=[[-0.5, 0.5], [-0.5, 0.5]])
    expected = n / 16
    p = chi2_sf(float(((counts - expected) ** 2 / expected).sum()), 15)
    assert p > ALPHA, f"{where}: positions are not uniform over the pixel (chi-square p = {p:.2g})"
