# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 07 graders: sphere and quad (u, v), checker and image textures, metal fuzz.
Run them with `python -m rtpy grade 07`."""

import math
from pathlib import Path

import numpy as np

from rtpy import (
    Camera,
    CheckerTexture,
    Color,
    HitInfo,
    ImageTexture,
    Quad,
    Ray,
    Scene,
    Sphere,
    Vec3,
)
from rtpy.grading import assert_image_matches, deterministic_image, points
from rtpy.materials import Lambertian, Metal
from rtpy.sampling import make_generator, use_generator

HERE = Path(__file__).parent


def v(a):
    return Vec3(*map(float, a))


def arr(x):
    return np.array(list(x))


@points(2, task="07.1")
def test_sphere_uv():
    """Sphere.surface_uv: u = phi / 2 pi from -x around +y, v = theta / pi from -y"""
    rng = np.random.default_rng(7)
    c, r = np.array([0.3, -0.2, 0.5]), 1.7
    sphere = Sphere(v(c), r, Lambertian())
    for _ in range(50):
        theta, phi = rng.uniform(0.01, math.pi - 0.01), rng.uniform(0.01, 2 * math.pi - 0.01)
        # theta from -y, phi from -x toward +z... : point = (-cos phi sin theta, -cos theta, sin phi sin theta)
        p = c + r * np.array(
            [-math.cos(phi) * math.sin(theta), -math.cos(theta), math.sin(phi) * math.sin(theta)]
        )
        hit = HitInfo(v(p), v((p - c) / r), 1.0, True, sphere.material, sphere)
        u, vv = sphere.surface_uv(hit)
        assert abs(u - phi / (2 * math.pi)) < 1e-9 and abs(vv - theta / math.pi) < 1e-9, (
            f"Sphere.surface_uv (rtpy/sphere.py) at {p.round(3)}: (u, v) = ({u:.4f}, {vv:.4f}), expected "
            f"({phi / (2 * math.pi):.4f}, {theta / math.pi:.4f}): u = phi / (2 pi) with phi measured "
            "from -x around +y (toward +z first), v = theta / pi with theta from -y"
        )


@points(2, task="07.1")
def test_quad_uv():
    """Quad.surface_uv: p = q + u * U + v * V"""
    rng = np.random.default_rng(77)
    for _ in range(50):
        q, uu, vv = rng.uniform(-1, 1, 3), rng.normal(size=3), rng.normal(size=3)
        a, b = rng.uniform(0, 1, 2)
        quad = Quad(v(q), v(uu), v(vv), Lambertian())
        p = q + a * uu + b * vv
        hit = HitInfo(v(p), quad.normal, 1.0, True, quad.material, quad)
        got = quad.surface_uv(hit)
        assert abs(got[0] - a) < 1e-9 and abs(got[1] - b) < 1e-9, (
            f"Quad.surface_uv (rtpy/quad.py): the point q + {a:.3f} u + {b:.3f} v got (u, v) = "
            f"({got[0]:.4f}, {got[1]:.4f})"
        )


@points(2, task="07.2")
def test_checker_texture():
    """CheckerTexture.value: 3-D cells of edge `scale`"""
    rng = np.random.default_rng(8)
    even, odd = Color(0.9, 0.9, 0.9), Color(0.1, 0.2, 0.3)
    for _ in range(200):
        scale = rng.uniform(0.2, 2)
        p = rng.uniform(-5, 5, 3)
        tex = CheckerTexture(scale, even, odd)
        got = tex.value(HitInfo(v(p), Vec3(0, 1, 0), 1.0, True, None))
        cell = int(sum(math.floor(x / scale) for x in p))
        expected = even if cell % 2 == 0 else odd
        assert list(got) == list(expected), (
            f"CheckerTexture.value (rtpy/texture.py) at {p.round(3)}, scale {scale:.3f}: got {got}, "
            f"expected the {'even' if cell % 2 == 0 else 'odd'} colour (floor(x/s) + floor(y/s) + "
            "floor(z/s) even or odd; floor, not int, so negative coordinates work)"
        )


@points(2, task="07.2")
def test_image_texture():
    """ImageTexture.value: nearest texel, u from the left, v from the bottom row"""
    h, w = 5, 7
    pixels = np.arange(h * w * 3, dtype=float).reshape(h, w, 3) / (h * w * 3)
    tex = ImageTexture(pixels)
    rng = np.random.default_rng(9)
    for _ in range(100):
        u, vv = rng.uniform(0, 1, 2)
        hit = HitInfo(Vec3(0, 0, 0), Vec3(0, 1, 0), 1.0, True, None, None, u, vv)
        i, j = min(int(u * w), w - 1), min(int((1 - vv) * h), h - 1)
        got = arr(tex.value(hit))
        assert np.allclose(got, pixels[j, i]), (
            f"ImageTexture.value (rtpy/texture.py) at (u, v) = ({u:.3f}, {vv:.3f}) gave {got.round(4)}, "
            f"expected the texel in column {i}, row {j} (row 0 is the image's top, v = 0 its bottom)"
        )


@points(3, task="07.3")
def test_metal_fuzz():
    """Metal.scattering: reflection + fuzz * random unit vector, absorbed below the surface"""
    n = np.array([0.0, 0.0, 1.0])
    t = math.radians(75)  # grazing: fuzz can push directions below the surface
    ray = Ray(Vec3(math.sin(t), 0, math.cos(t)), Vec3(-math.sin(t), 0, -math.cos(t)))
    r = np.array([-math.sin(t), 0, math.cos(t)])
    hit = HitInfo(Vec3(0, 0, 0), v(n), 1.0, True, None)
    where = "Metal.scattering (rtpy/materials/metal.py)"
    s = Metal(Color(0.8, 0.6, 0.4), 0.0).scattering(ray, hit)
    assert np.allclose(arr(s.scattered_ray.direction), r, atol=1e-12), (
        f"{where}: fuzz 0 must be a perfect mirror"
    )
    for fuzz in (0.1, 0.5):
        metal = Metal(Color(0.8, 0.6, 0.4), fuzz)
        angles, absorbed, n_samples = [], 0, 3000
        with use_generator(make_generator(7, int(fuzz * 10))):
            for _ in range(n_samples):
                s = metal.scattering(ray, hit)
                if s is None:
                    absorbed += 1
                    continue
                d = arr(s.scattered_ray.direction)
                assert abs(np.linalg.norm(d) - 1) < 1e-9, (
                    f"{where}: the direction must be a unit vector"
                )
                assert d @ n > 0, (
                    f"{where}: a fuzzed direction below the surface must be absorbed (None)"
                )
                assert np.allclose(arr(s.attenuation), [0.8, 0.6, 0.4]), (
                    f"{where}: the weight is the albedo"
                )
                angles.append(math.degrees(math.acos(min(1.0, d @ r))))
        angles = np.array(angles)
        # The fuzz point is uniform on a sphere of radius fuzz around the mirror
        # direction; directions below the surface are absorbed. Compare with that
        # distribution: the absorbed fraction, the largest and the mean angle.
        rng = np.random.default_rng(1)
        ref = rng.normal(size=(200_000, 3))
        ref = r + fuzz * ref / np.linalg.norm(ref, axis=1)[:, None]
        above = ref @ n > 0
        p_absorbed = 1 - above.mean()
        z = (absorbed / n_samples - p_absorbed) / math.sqrt(
            max(p_absorbed * (1 - p_absorbed), 1e-4) / n_samples
        )
        assert abs(z) < 4.5, (
            f"{where} with fuzz {fuzz} at 75 degrees: {absorbed} of {n_samples} samples absorbed, expected "
            f"about {p_absorbed * n_samples:.0f} (directions pushed below the surface return None)"
        )
        ref = ref[above]
        limit = math.degrees(math.asin(fuzz)) + 1e-6
        assert angles.max() <= limit, (
            f"{where} with fuzz {fuzz}: a direction {angles.max():.1f} degrees from the mirror "
            f"direction; reflect + fuzz * (a unit vector) stays within asin(fuzz) = {limit:.1f} degrees"
        )
        ref_angles = np.degrees(np.arccos(np.clip(ref @ r / np.linalg.norm(ref, axis=1), -1, 1)))
        z = (angles.mean() - ref_angles.mean()) / (ref_angles.std() / math.sqrt(len(angles)))
        assert abs(z) < 4.5, (
            f"{where} with fuzz {fuzz}: mean angle to the mirror direction {angles.mean():.2f} degrees, "
            f"expected {ref_angles.mean():.2f} for a uniform random unit vector times fuzz (z = {z:.1f})"
        )


def texture_scene():
    checker = Lambertian(CheckerTexture(0.5, Color(0.9, 0.9, 0.9), Color(0.2, 0.3, 0.1)))
    image = Lambertian(ImageTexture(np.random.default_rng(3).uniform(0, 1, (8, 16, 3))))
    objects = [
        Quad(Vec3(-4, -0.5, -6), Vec3(8, 0, 0), Vec3(0, 0, 6), checker),
        Sphere(Vec3(-0.7, 0.1, -2.2), 0.6, image),
        Quad(Vec3(0.2, -0.4, -2.5), Vec3(1.0, 0, 0.2), Vec3(0, 1.0, 0), image),
    ]
    camera = Camera(Vec3(0, 0.5, 0.5), Vec3(0, 0, -2.3), vfov=55, aspect_ratio="16:9", width=48)
    return Scene(objects, sky=True, camera=camera)


REFERENCE = {"name": "center_textures"}


def make_reference_image():
    return deterministic_image(texture_scene(), integrator="center")


@points(2, task="07.2")
def test_texture_render_matches_reference():
    """center render of checker and image textures matches the reference"""
    image = deterministic_image(texture_scene(), integrator="center")
    reference = np.load(HERE / "reference" / f"{REFERENCE['name']}.npy")
    assert_image_matches(
        image, reference, "center render with textures",
        "check the (u, v) of spheres and quads and the texture lookups", rtol=1e-9, atol=1e-12,
    )  # fmt: skip
