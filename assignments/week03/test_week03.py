# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 03 graders: Vec3 and Interval utilities, camera rays, the center and jittered
integrators. Run them with `python -m rtpy grade 03`.

Each test is a verdict: it asks the student's code for numbers through `probe`
(the probes are in probes.py beside this file) and decides here, in the judge.
"""

import math
from pathlib import Path

import numpy as np

from rtpy.grading import (
    assert_renders_match,
    points,
    reference_summary,
    scene_uses,
)
from rtpy.testing import chi2_sf

HERE = Path(__file__).parent


@points(3, task="03.1")
def test_cross_and_unit_vector(probe):
    """vec3.cross and vec3.unit_vector at random inputs"""
    rng = np.random.default_rng(3)
    pairs = [(rng.normal(size=3) * 10, rng.normal(size=3) * 10) for _ in range(50)]
    crosses = probe.vec3_cross(cases=pairs)
    units = probe.vec3_unit_vector(cases=[a for a, _ in pairs])
    for (a, b), got, u in zip(pairs, crosses, units, strict=True):
        assert np.allclose(got, np.cross(a, b), rtol=1e-12, atol=1e-12), (
            f"cross (rtpy/vec3.py): cross({a.round(3)}, {b.round(3)}) = {got.round(4)}, "
            f"expected {np.cross(a, b).round(4)} (right-handed: x cross y = z)"
        )
        assert np.allclose(u, a / np.linalg.norm(a), rtol=1e-12), (
            f"unit_vector (rtpy/vec3.py): unit_vector({a.round(3)}) = {u.round(4)}, expected v / |v|"
        )


@points(2, task="03.2")
def test_interval(probe):
    """Interval.contains (closed), surrounds (open), clamp"""
    xs = (-1.0, 2.0, 0.5, 2.0001, -1.5, -3.0, 5.0, 0.25)
    asked = [{"interval": [-1.0, 2.0], "x": x} for x in xs]
    asked += [{"interval": "empty", "x": 0.0}, {"interval": "universe", "x": 1e300}]
    *answers, empty, universe = probe.interval_queries(cases=asked)
    i = dict(zip(xs, answers, strict=True))
    where = "Interval (rtpy/interval.py)"
    assert i[-1.0].contains and i[2.0].contains and i[0.5].contains, (
        f"{where}.contains includes both ends"
    )
    assert not i[2.0001].contains and not i[-1.5].contains, (
        f"{where}.contains: outside is not contained"
    )
    assert i[0.5].surrounds and not i[-1.0].surrounds and not i[2.0].surrounds, (
        f"{where}.surrounds is strict: the ends are not surrounded"
    )
    assert (i[-3.0].clamp, i[5.0].clamp, i[0.25].clamp) == (-1.0, 2.0, 0.25), f"{where}.clamp"
    assert not empty.contains and universe.surrounds, (
        f"{where}: the empty interval contains nothing, the universe surrounds everything"
    )


def random_camera(rng) -> dict:
    """The spec of a camera (assignments/week03/probes.py: make_camera)."""
    look_from = rng.uniform(-3, 3, 3)
    look_at = look_from + rng.normal(size=3)
    return {
        "look_from": look_from,
        "look_at": look_at,
        "vup": [0.0, 1.0, 0.0],
        "vfov": rng.uniform(20, 100),
        "aspect_ratio": 16 / 9,
        "width": int(rng.integers(16, 64)),
        "focus_distance": rng.uniform(0.5, 4),
    }


def image_size(cam: dict) -> tuple[int, int]:
    """(width, height) in pixels: the height follows the aspect ratio (rtpy/camera.py)."""
    return cam["width"], max(1, int(cam["width"] / cam["aspect_ratio"]))


def pixel_position(cam, origin, direction):
    """Fractional pixel coordinates (x, y) where a ray crosses the focus plane,
    computed from the camera's parameters (not from its pixel00/deltas)."""
    lf, la, up = (np.asarray(cam[k], dtype=float) for k in ("look_from", "look_at", "vup"))
    nx, ny = image_size(cam)
    w = (lf - la) / np.linalg.norm(lf - la)
    u = np.cross(up, w)
    u /= np.linalg.norm(u)
    vv = np.cross(w, u)
    height = 2 * math.tan(math.radians(cam["vfov"]) / 2) * cam["focus_distance"]
    width = height * nx / ny
    t = -((origin - lf) @ (-w) - cam["focus_distance"]) / (direction @ (-w))
    p = origin + t * direction - (lf - w * cam["focus_distance"])
    return (p @ u / width + 0.5) * nx - 0.5, (0.5 - p @ vv / height) * ny - 0.5


@points(3, task="03.3")
def test_center_ray(probe):
    """Camera.get_center_ray: from the eye through the pixel's center, unit direction"""
    rng = np.random.default_rng(33)
    cases = []
    for _ in range(20):
        cam = random_camera(rng)
        nx, ny = image_size(cam)
        cases.append({"camera": cam, "pixel": [int(rng.integers(0, nx)), int(rng.integers(0, ny))]})
    for case, (o, d) in zip(cases, probe.camera_center_rays(cases=cases), strict=True):
        cam, (i, j) = case["camera"], case["pixel"]
        where = f"Camera.get_center_ray({i}, {j}) (rtpy/camera.py)"
        assert np.allclose(o, cam["look_from"]), f"{where}: the ray starts at look_from"
        assert abs(np.linalg.norm(d) - 1) < 1e-9, f"{where}: the direction must be a unit vector"
        x, y = pixel_position(cam, o, d)
        assert abs(x - i) < 1e-6 and abs(y - j) < 1e-6, (
            f"{where}: the ray goes through pixel position ({x:.3f}, {y:.3f}), not the pixel's "
            f"center ({i}, {j}); pixel (0, 0) is the top-left one"
        )


@points(3, task="03.5")
def test_jittered_ray(probe):
    """Camera.get_ray: uniform over the pixel's square"""
    cam = random_camera(np.random.default_rng(7))
    i, j, n = 3, 2, 4000
    rays = probe.camera_jittered_rays(camera=cam, pixel=[i, j], n=n, seed=3, stream=0)
    where = f"Camera.get_ray({i}, {j}) (rtpy/camera.py)"
    assert len(rays) == n, f"{where}: asked for {n} rays, got {len(rays)}"
    assert np.all(np.abs(np.linalg.norm(rays[:, 1], axis=1) - 1) < 1e-9), (
        "Camera.get_ray: the direction must be a unit vector"
    )
    xs, ys = np.array([pixel_position(cam, o, d) for o, d in rays]).T
    xs, ys = xs - i, ys - j
    assert (
        xs.min() >= -0.5 - 1e-9
        and xs.max() <= 0.5 + 1e-9
        and ys.min() >= -0.5 - 1e-9
        and ys.max() <= 0.5 + 1e-9
    ), (
        f"{where}: rays leave the pixel's square (offsets {xs.min():.2f}..{xs.max():.2f}, "
        f"{ys.min():.2f}..{ys.max():.2f}; the center is offset 0, the square is -0.5..0.5)"
    )
    counts, _, _ = np.histogram2d(xs, ys, bins=4, range=[[-0.5, 0.5], [-0.5, 0.5]])
    expected = n / 16
    p = chi2_sf(float(((counts - expected) ** 2 / expected).sum()), 15)
    assert p > 1e-3, f"{where}: positions are not uniform over the pixel (chi-square p = {p:.2g})"


@points(3, task="03.4")
def test_flat_color(probe):
    """center integrator (flat_color): emission, else albedo, else background"""
    background, albedo, emit = [0.1, 0.2, 0.3], [0.7, 0.3, 0.2], [4.0, 3.0, 2.0]
    cases = [  # a ray that hits nothing, a diffuse surface, a light's front and back
        None,
        {"material": {"type": "Lambertian", "albedo": albedo}, "front_face": True},
        {"material": {"type": "DiffuseLight", "emit": emit}, "front_face": True},
        {"material": {"type": "DiffuseLight", "emit": emit}, "front_face": False},
    ]
    miss, diffuse, lit, back = probe.flat_color_of_hits(cases=cases, background=background)
    where = "flat_color (rtpy/integrators/center.py)"
    assert list(miss) == background, (
        f"{where}: a ray that hits nothing shows the background, got {miss}"
    )
    assert list(diffuse) == albedo, (
        f"{where}: a diffuse surface shows its albedo {albedo}, got {diffuse}"
    )
    assert list(lit) == emit, (
        f"{where}: a light's emitting face shows its emission {emit}, got {lit}"
    )
    assert list(back) == [1.0, 1.0, 1.0], (
        f"{where}: the back of a one-sided light emits nothing and has no albedo: white, got {back}"
    )


# The graded render: R seeds at SPP samples per pixel, against the reference
# (rendered by rtpy's solution with REFERENCE_SEEDS at REFERENCE_SPP).
RENDER = {"integrator": "jittered", "spp": 4}
SEEDS = (1, 2, 3, 4)
REFERENCE = {"name": "jittered_sky", "seeds": tuple(range(100, 108)), "spp": 32}


def make_reference_summary(probe):
    return reference_summary(probe, "week03_sky", RENDER, REFERENCE)


@points(2, task="03.5")
@scene_uses("03.1", "03.3")
def test_sky_render_matches_reference(probe):
    """jittered render of the sky matches the reference (camera rays and pixel jitter)"""
    assert_renders_match(
        probe,
        "week03_sky",
        SEEDS,
        RENDER,
        HERE / "reference" / f"{REFERENCE['name']}.npz",
        "jittered render of the sky (rtpy/camera.py: _ray_through, get_ray) differs from the "
        "reference beyond its noise: rays through the wrong points of the pixels (pixel "
        "(0, 0) is the top-left one; a jittered sample is uniform over -0.5..0.5 around the "
        "center) or directions that are not unit vectors",
    )
