# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 06 graders: reflect, refract (Snell), Schlick, total internal reflection, the
mirror and the dielectric. Run them with `python -m rtpy grade 06`."""

import math
from pathlib import Path

import numpy as np

import rtpy.materials.dielectric as dielectric
import rtpy.vec3 as vec3
from rtpy import Camera, Color, HitInfo, Lambertian, PointLight, Quad, Ray, Scene, Sphere, Vec3
from rtpy.grading import assert_image_matches, deterministic_image, points
from rtpy.materials import Dielectric, Mirror
from rtpy.sampling import make_generator, use_generator

HERE = Path(__file__).parent


def v(a):
    return Vec3(*map(float, a))


def arr(x):
    return np.array(list(x))


def random_incidence(rng):
    """A unit normal n and a unit direction d arriving at the surface (d . n < 0)."""
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    if d @ n > 0:
        d = -d
    return n, d


@points(2, task="06.1")
def test_reflect():
    """vec3.reflect: v - 2 (v . n) n"""
    rng = np.random.default_rng(6)
    for _ in range(50):
        n, d = random_incidence(rng)
        got = arr(vec3.reflect(v(d), v(n)))
        expected = d - 2 * (d @ n) * n
        assert np.allclose(got, expected, atol=1e-12), (
            f"reflect (rtpy/vec3.py): reflect({d.round(3)}, n={n.round(3)}) = {got.round(4)}, "
            f"expected {expected.round(4)} (v - 2 (v . n) n: same angle on the other side of n)"
        )


@points(3, task="06.2")
def test_refract_obeys_snell():
    """vec3.refract: Snell's law, in the plane of incidence, unit length"""
    rng = np.random.default_rng(66)
    for _ in range(100):
        n, d = random_incidence(rng)
        eta = rng.uniform(0.4, 1.6)
        sin_i = np.linalg.norm(np.cross(d, n))
        if eta * sin_i >= 1:
            continue  # total internal reflection: refract is not called
        t = arr(vec3.refract(v(d), v(n), eta))
        where = f"refract (rtpy/vec3.py) with eta = {eta:.3f} at incidence {math.degrees(math.asin(sin_i)):.1f} degrees"
        assert abs(np.linalg.norm(t) - 1) < 1e-9, (
            f"{where}: the refracted direction must be a unit vector"
        )
        assert t @ n < 0, f"{where}: the refracted ray must go through the surface (t . n < 0)"
        sin_t = np.linalg.norm(np.cross(t, n))
        assert abs(sin_t - eta * sin_i) < 1e-9, (
            f"{where}: sin(theta_t) = {sin_t:.6f}, Snell's law gives eta sin(theta_i) = {eta * sin_i:.6f}"
        )
        assert abs(np.cross(d, n) @ t) < 1e-9, (
            f"{where}: the refracted ray leaves the plane of incidence"
        )


@points(2, task="06.3")
def test_schlick():
    """dielectric.schlick: r0 + (1 - r0)(1 - cos)^5"""
    rng = np.random.default_rng(7)
    for _ in range(50):
        c, ratio = rng.uniform(0, 1), rng.uniform(0.3, 3)
        r0 = ((1 - ratio) / (1 + ratio)) ** 2
        expected = r0 + (1 - r0) * (1 - c) ** 5
        got = dielectric.schlick(c, ratio)
        assert abs(got - expected) < 1e-12, (
            f"schlick (rtpy/materials/dielectric.py): schlick({c:.3f}, {ratio:.3f}) = {got:.6f}, "
            f"expected r0 + (1 - r0)(1 - cos)^5 = {expected:.6f} with r0 = ((1 - eta)/(1 + eta))^2"
        )


def glass_hit(front_face, material):
    return HitInfo(Vec3(0, 0, 0), Vec3(0, 0, 1), 1.0, front_face, material)


def incoming(theta_deg):
    t = math.radians(theta_deg)
    return Ray(Vec3(math.sin(t), 0, math.cos(t)), Vec3(-math.sin(t), 0, -math.cos(t)))


@points(2, task="06.3")
def test_total_internal_reflection():
    """Dielectric: from inside beyond the critical angle every ray reflects"""
    glass = Dielectric(1.5)
    critical = math.degrees(math.asin(1 / 1.5))
    with use_generator(make_generator(6, 1)):
        for theta in (critical + 1, 60.0, 85.0):
            for _ in range(50):
                s = glass.scattering(incoming(theta), glass_hit(False, glass))
                d = arr(s.scattered_ray.direction)
                assert d[2] > 0, (
                    f"Dielectric.scattering (rtpy/materials/dielectric.py): inside glass at {theta:.1f} "
                    f"degrees (critical angle {critical:.1f}) a ray refracted out: beyond the critical "
                    "angle eta sin(theta) > 1 and the ray must reflect (total internal reflection)"
                )
        refracted = 0
        for _ in range(50):
            s = glass.scattering(incoming(critical - 5), glass_hit(False, glass))
            refracted += arr(s.scattered_ray.direction)[2] < 0
        assert refracted > 0, (
            "Dielectric.scattering: below the critical angle light must also leave the glass"
        )


@points(2, task="06.3")
def test_dielectric_reflects_with_probability_schlick():
    """Dielectric.scattering: reflect with probability R, refract otherwise, weight albedo"""
    glass = Dielectric(1.5, Color(0.9, 0.95, 1.0))
    n = 4000
    with use_generator(make_generator(6, 2)):
        for theta in (10.0, 75.0):
            ray = incoming(theta)
            reflected = 0
            for _ in range(n):
                s = glass.scattering(ray, glass_hit(True, glass))
                assert np.allclose(arr(s.attenuation), [0.9, 0.95, 1.0]), (
                    "Dielectric.scattering: the weight is the albedo, with no cosine and no R factor "
                    f"(R is the probability of reflecting); got {s.attenuation}"
                )
                reflected += arr(s.scattered_ray.direction)[2] > 0
            cos = math.cos(math.radians(theta))
            r = dielectric.schlick(cos, 1 / 1.5)
            z = (reflected / n - r) / math.sqrt(r * (1 - r) / n)
            assert abs(z) < 4.0, (
                f"Dielectric.scattering at {theta} degrees reflects {reflected / n:.3f} of rays, "
                f"Schlick's R is {r:.3f} (z = {z:.1f}); refracted rays must not be absorbed or clamped"
            )


@points(2, task="06.1")
def test_mirror():
    """Mirror.scattering: the reflected ray, weight albedo (no cosine)"""
    m = Mirror(Color(0.9, 0.8, 0.7))
    for theta in (0.0, 45.0, 80.0):
        s = m.scattering(incoming(theta), glass_hit(True, m))
        t = math.radians(theta)
        assert np.allclose(
            arr(s.scattered_ray.direction), [-math.sin(t), 0, math.cos(t)], atol=1e-12
        ), (
            f"Mirror.scattering (rtpy/materials/mirror.py) at {theta} degrees: not the mirror direction"
        )
        assert np.allclose(arr(s.attenuation), [0.9, 0.8, 0.7]), (
            f"Mirror.scattering at {theta} degrees: weight {s.attenuation}; a mirror reflects "
            "albedo of the light, with no cosine factor"
        )
        assert s.is_specular, "Mirror.scattering: the sample is specular (is_specular=True)"


def optics_scene():
    objects = [
        Quad(Vec3(-4, -0.5, -6), Vec3(8, 0, 0), Vec3(0, 0, 6), Lambertian(Color(0.6, 0.6, 0.6))),
        Quad(Vec3(-4, -0.5, -5), Vec3(8, 0, 0), Vec3(0, 4, 0), Lambertian(Color(0.3, 0.5, 0.7))),
        Sphere(Vec3(-0.7, 0.0, -2.2), 0.5, Dielectric(1.5)),
        Sphere(Vec3(0.7, 0.0, -2.6), 0.5, Mirror(Color(0.9, 0.9, 0.9))),
    ]
    camera = Camera(Vec3(0, 0.4, 0.5), Vec3(0, 0, -2.4), vfov=55, aspect_ratio="16:9", width=48)
    return Scene(objects, [PointLight(Vec3(0.5, 2.5, -1.0), Color(8, 8, 8))], camera=camera)


REFERENCE = {"name": "whitted_optics"}


def make_reference_image():
    return deterministic_image(optics_scene(), integrator="whitted", max_depth=8)


@points(3, task="06.3")
def test_whitted_render_matches_reference():
    """whitted render of a glass and a mirror ball matches the reference"""
    # Whitted with a point light and a pinhole is deterministic; spp 1 shows
    # each pixel's jittered sample, so the seed fixes the image.
    image = deterministic_image(optics_scene(), integrator="whitted", max_depth=8)
    reference = np.load(HERE / "reference" / f"{REFERENCE['name']}.npy")
    assert_image_matches(
        image, reference, "whitted render", "glass that renders dark or opaque means "
        "refracted rays are lost; check reflect, refract, schlick and Dielectric._split",
        rtol=1e-6, atol=1e-9,
    )  # fmt: skip
