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
import pytest

from rtpy.grading import points
from rtpy.grading.autograder_seed import grading_rng, grading_seed
from rtpy.testing import chi2_sf

ALPHA = 1e-4


# One case per task (03.1 vectors, 03.2 intervals): a stub costs only its own points.
@pytest.mark.parametrize(
    "part",
    [pytest.param("vectors", marks=points(1)), pytest.param("intervals", marks=points(1))],
)
def test_vector_utilities_at_new_inputs(part, probe):
    """cross, unit_vector and Interval at new random inputs"""
    rng = grading_rng(301)
    pairs = [(rng.uniform(-10, 10, 3), rng.uniform(-10, 10, 3)) for _ in range(200)]
    if part == "intervals":
        interval_checks(probe, rng)
        return
    crosses = probe.vec3_cross(cases=pairs)
    units = probe.vec3_unit_vector(cases=[a for a, _ in pairs])
    for (a, b), got, unit_a in zip(pairs, crosses, units, strict=True):
        want = np.cross(a, b)
        scale = np.linalg.norm(a) * np.linalg.norm(b)
        assert np.allclose(got, want, rtol=0, atol=1e-12 * scale), (
            f"cross (rtpy/vec3.py)({a.round(4)}, {b.round(4)}) = {got.round(6)}, expected {want.round(6)}"
        )
        got, want = unit_a, a / np.linalg.norm(a)
        assert np.allclose(got, want, rtol=0, atol=1e-12), (
            f"unit_vector (rtpy/vec3.py)({a.round(4)}) = {got.round(6)}, expected {want.round(6)}"
        )


def interval_checks(probe, rng) -> None:
    """Interval.contains, surrounds and clamp at new intervals and points."""
    cases = []
    for _ in range(100):
        lo, hi = sorted(float(x) for x in rng.uniform(-5, 5, 2))
        for x in (float(rng.uniform(-6, 6)), lo, hi):
            cases.append({"interval": [lo, hi], "x": x})
    for case, got in zip(cases, probe.interval_queries(cases=cases), strict=True):
        (lo, hi), x = case["interval"], case["x"]
        where = f"Interval({lo:.4f}, {hi:.4f}) (rtpy/interval.py) at x = {x:.4f}"
        assert got.contains == (lo <= x <= hi), f"{where}: contains is min <= x <= max"
        assert got.surrounds == (lo < x < hi), f"{where}: surrounds is min < x < max"
        assert got.clamp == min(max(x, lo), hi), f"{where}: clamp(x) = {got.clamp}"


def new_camera(rng) -> dict:
    """The spec of a camera with random placement, field of view and image size
    (assignments/week03/probes.py: make_camera)."""
    look_from = rng.uniform(-5, 5, 3)
    look_at = look_from + rng.uniform(0.5, 3) * unit(rng.normal(size=3))
    vup = unit(rng.normal(size=3))
    while abs(vup @ unit(look_at - look_from)) > 0.9:  # not near the view direction
        vup = unit(rng.normal(size=3))
    return {
        "look_from": look_from,
        "look_at": look_at,
        "vup": vup,
        "vfov": float(rng.uniform(20, 120)),
        "aspect_ratio": float(rng.uniform(0.5, 2.0)),
        "width": int(rng.integers(4, 40)),
        "focus_distance": float(rng.uniform(0.5, 5)),
    }


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def image_size(cam: dict) -> tuple[int, int]:
    """(width, height) in pixels: the height follows the aspect ratio (rtpy/camera.py)."""
    return cam["width"], max(1, int(cam["width"] / cam["aspect_ratio"]))


def viewport(cam: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(center of pixel (0, 0), one pixel right, one pixel down) on the focus plane,
    computed here from the camera's parameters."""
    eye = np.asarray(cam["look_from"], dtype=float)
    nx, ny = image_size(cam)
    w = unit(eye - np.asarray(cam["look_at"], dtype=float))
    u = unit(np.cross(np.asarray(cam["vup"], dtype=float), w))
    v = np.cross(w, u)
    height = 2 * math.tan(math.radians(cam["vfov"]) / 2) * cam["focus_distance"]
    width = height * nx / ny
    right, down = u * width / nx, -v * height / ny
    corner = eye - w * cam["focus_distance"] - u * width / 2 + v * height / 2
    return corner + (right + down) / 2, right, down


@points(2)
def test_center_rays_of_a_new_camera(probe):
    """Camera.get_center_ray: through the pixel's center, for a new random camera"""
    rng = grading_rng(302)
    cases = []
    for _ in range(5):
        cam = new_camera(rng)
        nx, ny = image_size(cam)
        for _ in range(10):
            cases.append({"camera": cam, "pixel": [int(rng.integers(nx)), int(rng.integers(ny))]})
    for case, (origin, got) in zip(cases, probe.camera_center_rays(cases=cases), strict=True):
        cam, (i, j) = case["camera"], case["pixel"]
        pixel00, right, down = viewport(cam)
        want = unit(pixel00 + i * right + j * down - cam["look_from"])
        nx, ny = image_size(cam)
        assert np.allclose(origin, cam["look_from"], atol=1e-12), (
            "Camera.get_center_ray (rtpy/camera.py): the ray starts at look_from"
        )
        assert np.allclose(got, want, atol=1e-9), (
            f"Camera.get_center_ray({i}, {j}) (rtpy/camera.py) of a {nx}x{ny} camera: "
            f"direction {got.round(6)}, expected the unit vector toward the pixel's center "
            f"{want.round(6)}; pixel (0, 0) is the top-left one"
        )


@points(2)
def test_jittered_rays_of_a_new_camera(probe):
    """Camera.get_ray: uniform over the pixel, for a new random camera"""
    rng = grading_rng(303)
    cam = new_camera(rng)
    nx, ny = image_size(cam)
    pixel00, right, down = viewport(cam)
    i, j, n = int(rng.integers(nx)), int(rng.integers(ny)), 4000
    eye, w = cam["look_from"], unit(cam["look_from"] - cam["look_at"])
    rays = probe.camera_jittered_rays(
        camera=cam, pixel=[i, j], n=n, seed=grading_seed(304), stream=3
    )
    where = f"Camera.get_ray({i}, {j}) (rtpy/camera.py) of a {nx}x{ny} camera"
    assert len(rays) == n, f"{where}: asked for {n} rays, got {len(rays)}"
    o, d = rays[:, 0], rays[:, 1]
    t = ((eye - w * cam["focus_distance"] - o) @ w) / (d @ w)  # to the focus plane
    p = o + t[:, None] * d - pixel00
    offsets = np.column_stack([p @ right / (right @ right) - i, p @ down / (down @ down) - j])
    assert np.all(np.abs(offsets) <= 0.5 + 1e-9), (
        f"{where}: rays leave the pixel's square: offsets from its center reach "
        f"{np.abs(offsets).max():.3f} pixels (at most 0.5)"
    )
    counts, _, _ = np.histogram2d(*offsets.T, bins=4, range=[[-0.5, 0.5], [-0.5, 0.5]])
    expected = n / 16
    p = chi2_sf(float(((counts - expected) ** 2 / expected).sum()), 15)
    assert p > ALPHA, f"{where}: positions are not uniform over the pixel (chi-square p = {p:.2g})"
