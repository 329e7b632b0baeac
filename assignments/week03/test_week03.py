# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 03 graders: Vec3 and Interval utilities, camera rays, the center and jittered
integrators. Run them with `python -m rtpy grade 03`."""

import math
from pathlib import Path

import numpy as np

import rtpy.integrators.center as center
import rtpy.vec3 as vec3
from rtpy import Camera, Color, HitInfo, Interval, Scene, Vec3
from rtpy.grading import assert_renders_match, points, reference_summary
from rtpy.materials import DiffuseLight, Lambertian
from rtpy.testing import chi2_sf

HERE = Path(__file__).parent


def v(a):
    return Vec3(*map(float, a))


@points(3, task="03.1")
def test_cross_and_unit_vector():
    """vec3.cross and vec3.unit_vector at random inputs"""
    rng = np.random.default_rng(3)
    for _ in range(50):
        a, b = rng.normal(size=3) * 10, rng.normal(size=3) * 10
        got = np.array(list(vec3.cross(v(a), v(b))))
        assert np.allclose(got, np.cross(a, b), rtol=1e-12, atol=1e-12), (
            f"cross (rtpy/vec3.py): cross({a.round(3)}, {b.round(3)}) = {got.round(4)}, "
            f"expected {np.cross(a, b).round(4)} (right-handed: x cross y = z)"
        )
        u = np.array(list(vec3.unit_vector(v(a))))
        assert np.allclose(u, a / np.linalg.norm(a), rtol=1e-12), (
            f"unit_vector (rtpy/vec3.py): unit_vector({a.round(3)}) = {u.round(4)}, expected v / |v|"
        )


@points(2, task="03.2")
def test_interval():
    """Interval.contains (closed), surrounds (open), clamp"""
    i = Interval(-1.0, 2.0)
    where = "Interval (rtpy/interval.py)"
    assert i.contains(-1.0) and i.contains(2.0) and i.contains(0.5), (
        f"{where}.contains includes both ends"
    )
    assert not i.contains(2.0001) and not i.contains(-1.5), (
        f"{where}.contains: outside is not contained"
    )
    assert i.surrounds(0.5) and not i.surrounds(-1.0) and not i.surrounds(2.0), (
        f"{where}.surrounds is strict: the ends are not surrounded"
    )
    assert (i.clamp(-3.0), i.clamp(5.0), i.clamp(0.25)) == (-1.0, 2.0, 0.25), f"{where}.clamp"
    assert not Interval.empty().contains(0.0) and Interval.universe().surrounds(1e300), (
        f"{where}: the empty interval contains nothing, the universe surrounds everything"
    )


def random_camera(rng):
    look_from = rng.uniform(-3, 3, 3)
    look_at = look_from + rng.normal(size=3)
    return Camera(
        v(look_from),
        v(look_at),
        Vec3(0, 1, 0),
        vfov=rng.uniform(20, 100),
        aspect_ratio="16:9",
        width=int(rng.integers(16, 64)),
        focus_distance=rng.uniform(0.5, 4),
    )


def pixel_position(cam, origin, direction):
    """Fractional pixel coordinates (x, y) where a ray crosses the focus plane,
    computed from the camera's parameters (not from its pixel00/deltas)."""
    lf, la, up = (np.array(list(x)) for x in (cam.look_from, cam.look_at, cam.vup))
    w = (lf - la) / np.linalg.norm(lf - la)
    u = np.cross(up, w)
    u /= np.linalg.norm(u)
    vv = np.cross(w, u)
    height = 2 * math.tan(math.radians(cam.vfov) / 2) * cam.focus_distance
    width = height * cam.width / cam.height
    t = -((origin - lf) @ (-w) - cam.focus_distance) / (direction @ (-w))
    p = origin + t * direction - (lf - w * cam.focus_distance)
    return (p @ u / width + 0.5) * cam.width - 0.5, (0.5 - p @ vv / height) * cam.height - 0.5


@points(3, task="03.3")
def test_center_ray():
    """Camera.get_center_ray: from the eye through the pixel's center, unit direction"""
    rng = np.random.default_rng(33)
    for _ in range(20):
        cam = random_camera(rng)
        i, j = int(rng.integers(0, cam.width)), int(rng.integers(0, cam.height))
        ray = cam.get_center_ray(i, j)
        o, d = np.array(list(ray.origin)), np.array(list(ray.direction))
        where = f"Camera.get_center_ray({i}, {j}) (rtpy/camera.py)"
        assert np.allclose(o, list(cam.look_from)), f"{where}: the ray starts at look_from"
        assert abs(np.linalg.norm(d) - 1) < 1e-9, f"{where}: the direction must be a unit vector"
        x, y = pixel_position(cam, o, d)
        assert abs(x - i) < 1e-6 and abs(y - j) < 1e-6, (
            f"{where}: the ray goes through pixel position ({x:.3f}, {y:.3f}), not the pixel's "
            f"center ({i}, {j}); pixel (0, 0) is the top-left one"
        )


@points(3, task="03.5")
def test_jittered_ray():
    """Camera.get_ray: uniform over the pixel's square"""
    from rtpy.sampling import make_generator, use_generator

    cam = random_camera(np.random.default_rng(7))
    i, j, n = 3, 2, 4000
    xs, ys = [], []
    with use_generator(make_generator(3, 0)):
        for _ in range(n):
            ray = cam.get_ray(i, j)
            d = np.array(list(ray.direction))
            assert abs(np.linalg.norm(d) - 1) < 1e-9, (
                "Camera.get_ray: the direction must be a unit vector"
            )
            x, y = pixel_position(cam, np.array(list(ray.origin)), d)
            xs.append(x - i)
            ys.append(y - j)
    xs, ys = np.array(xs), np.array(ys)
    where = f"Camera.get_ray({i}, {j}) (rtpy/camera.py)"
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


class FakeScene:
    """A scene whose every ray hits `hit` (or nothing), for flat_color."""

    def __init__(self, hit, background=None):
        self.hit, self.background = hit, background or Color(0.1, 0.2, 0.3)

    def find_intersection(self, ray, interval):
        return self.hit

    def background_radiance(self, direction):
        return self.background


@points(3, task="03.4")
def test_flat_color():
    """center integrator (flat_color): emission, else albedo, else background"""
    from rtpy import Ray

    ray = Ray(Vec3(0, 0, 0), Vec3(0, 0, -1))
    where = "flat_color (rtpy/integrators/center.py)"
    got = center.flat_color(ray, FakeScene(None))
    assert list(got) == [0.1, 0.2, 0.3], (
        f"{where}: a ray that hits nothing shows the background, got {got}"
    )
    albedo = Color(0.7, 0.3, 0.2)
    hit = HitInfo(Vec3(0, 0, -1), Vec3(0, 0, 1), 1.0, True, Lambertian(albedo))
    got = center.flat_color(ray, FakeScene(hit))
    assert list(got) == list(albedo), (
        f"{where}: a diffuse surface shows its albedo {albedo}, got {got}"
    )
    emit = Color(4.0, 3.0, 2.0)
    lit = HitInfo(Vec3(0, 0, -1), Vec3(0, 0, 1), 1.0, True, DiffuseLight(emit))
    got = center.flat_color(ray, FakeScene(lit))
    assert list(got) == list(emit), (
        f"{where}: a light's emitting face shows its emission {emit}, got {got}"
    )
    back = HitInfo(Vec3(0, 0, -1), Vec3(0, 0, 1), 1.0, False, DiffuseLight(emit))
    got = center.flat_color(ray, FakeScene(back))
    assert list(got) == [1.0, 1.0, 1.0], (
        f"{where}: the back of a one-sided light emits nothing and has no albedo: white, got {got}"
    )


def sky_scene():
    camera = Camera(Vec3(0, 0, 0), Vec3(0, 0.3, -1), vfov=90, aspect_ratio="16:9", width=32)
    return Scene([], sky=True, camera=camera)  # no objects: nothing to hit before week 4


RENDER = {"integrator": "jittered", "spp": 4}
SEEDS = (1, 2, 3, 4)
REFERENCE = {"name": "jittered_sky", "seeds": tuple(range(100, 108)), "spp": 32}


def make_reference_summary():
    return reference_summary(sky_scene(), RENDER, REFERENCE)


@points(2, task="03.5")
def test_sky_render_matches_reference():
    """jittered render of the sky matches the reference (camera rays and pixel jitter)"""
    assert_renders_match(
        sky_scene(),
        SEEDS,
        RENDER,
        HERE / "reference" / f"{REFERENCE['name']}.npz",
        "jittered render of the sky (rtpy/camera.py: _ray_through, get_ray) differs from the "
        "reference beyond its noise: rays through the wrong points of the pixels (pixel "
        "(0, 0) is the top-left one; a jittered sample is uniform over -0.5..0.5 around the "
        "center) or directions that are not unit vectors",
    )
