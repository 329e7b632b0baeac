# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 05 graders: point lights with 1/r^2, shadow rays, Lambertian, the light-sampling
estimate and the direct integrator; each names its task of assignments/week05/tasks.toml.

Each test names the method it checks and says what is wrong when it fails.
Run them with `python -m rtpy grade 05`.
"""

import math
from pathlib import Path

import numpy as np

import rtpy.integrators.direct_lighting as direct_lighting
import rtpy.testing as rt
from rtpy import Color, HitInfo, Interval, Lambertian, PointLight, Quad, Ray, Scene, Sphere, Vec3
from rtpy.grading import assert_renders_match, points, reference_summary
from rtpy.integrators import DirectIntegrator
from rtpy.light import LightSample
from rtpy.materials import DiffuseLight
from rtpy.render_settings import RenderSettings
from rtpy.vec3 import BLACK, dot

HERE = Path(__file__).parent
RNG_SEED = 2005


def unit(v):
    return v / np.linalg.norm(v)


@points(3, task="05.1")
def test_point_light_sample():
    """PointLight.sample: unit direction, distance, radiance I / d^2"""
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(40):
        pos, p, intensity = rng.uniform(-5, 5, 3), rng.uniform(-5, 5, 3), rng.uniform(0.1, 9, 3)
        s = PointLight(Vec3(*pos), Color(*intensity)).sample(Vec3(*p))
        d = pos - p
        dist = float(np.linalg.norm(d))
        where = (
            f"PointLight.sample (rtpy/light.py) with the light at {pos.round(3)}, p = {p.round(3)}"
        )
        assert s is not None, f"{where}: returned None"
        assert np.allclose(list(s.direction), d / dist, rtol=1e-9, atol=1e-12), (
            f"{where}: direction {s.direction} should be the unit vector from p toward the light "
            f"{(d / dist).round(6)}"
        )
        assert math.isclose(s.distance, dist, rel_tol=1e-9), (
            f"{where}: distance {s.distance} != {dist}"
        )
        ratio = np.array(list(s.radiance)) / intensity
        assert np.allclose(ratio, 1.0 / dist**2, rtol=1e-9), (
            f"{where}: radiance is intensity * {ratio.mean():.4g}, expected intensity / d^2 = "
            f"intensity * {1 / dist**2:.4g} (a point light falls off with the square of the distance)"
        )
        assert s.is_delta and s.pdf == 1.0, (
            f"{where}: a point light is a delta light: is_delta True, pdf 1"
        )


@points(3, task="05.3")
def test_lambertian_brdf_and_sampling():
    """BRDF = albedo / pi, pdf = cos / pi, cosine sampling, weight = BRDF * cos / pdf"""
    albedo = Color(0.8, 0.5, 0.2)
    material = Lambertian(albedo)
    hit = rt.local_hit(material)
    for theta in (0.0, 40.0, 80.0):
        f = material.BRDF(rt.incident_ray(30.0), rt.light_ray(rt.local_direction(theta, 70.0)), hit)
        assert np.allclose(list(f), np.array(list(albedo)) / math.pi, rtol=1e-9), (
            f"Lambertian.BRDF (rtpy/materials/lambertian.py) = {f}; f_r is albedo / pi "
            "(the albedo alone would reflect pi times too much light)"
        )
    below = material.BRDF(rt.incident_ray(30.0), rt.light_ray(rt.local_direction(120.0)), hit)
    assert below.is_black(), "Lambertian.BRDF: light from below the surface must give 0"
    for theta in (0.0, 40.0, 80.0, 120.0):
        got = material.pdf(
            rt.incident_ray(30.0), rt.light_ray(rt.local_direction(theta, 70.0)), hit
        )
        expected = max(0.0, math.cos(math.radians(theta))) / math.pi
        assert math.isclose(got, expected, rel_tol=1e-9, abs_tol=1e-15), (
            f"Lambertian.pdf (rtpy/materials/lambertian.py) at {theta} degrees from the normal "
            f"= {got:.6g}, expected cos(theta) / pi = {expected:.6g} (0 below the surface)"
        )
    for theta in (10.0, 60.0):
        weights = rt.check_weights(material, theta, n=300, seed=5)
        assert weights.passed, (
            "Lambertian.scattering: the attenuation must be BRDF * cos / pdf (= albedo with "
            f"cosine sampling) and pdf = cos / pi: {weights.detail}"
        )
        chi2 = rt.chi2_test(material, theta, n_samples=20_000, theta_bins=8, phi_bins=8, seed=5)
        assert chi2.passed(rt.sidak_alpha(0.01, 2)), (
            f"Lambertian.scattering: directions do not follow pdf = cos / pi: {chi2.summary()}"
        )


@points(2, task="05.2")
def test_shadow_rays():
    """Scene.find_occlusion: blockers between the point and the light only"""
    m = Lambertian()
    ray = Ray(Vec3(0, 0, 0), Vec3(0, 0, -1))
    cases = [
        (
            [Sphere(Vec3(0, 0, -2), 0.5, m)],
            Interval(0.0, 5.0),
            True,
            "a sphere halfway to the light",
        ),
        ([Sphere(Vec3(0, 0, -8), 0.5, m)], Interval(0.0, 5.0), False, "a sphere beyond the light"),
        ([Sphere(Vec3(0, 0, 3), 0.5, m)], Interval(0.0, 5.0), False, "a sphere behind the point"),
        ([Sphere(Vec3(2, 0, -2), 0.5, m)], Interval(0.0, 5.0), False, "a sphere beside the ray"),
        (
            [Sphere(Vec3(2, 0, -2), 0.5, m), Sphere(Vec3(0, 0, -3), 0.5, m)],
            Interval(0.0, 5.0),
            True,
            "one blocker among other objects",
        ),
    ]
    for objects, interval, expected, what in cases:
        got = Scene(objects).find_occlusion(ray, interval)
        assert got == expected, (
            f"Scene.find_occlusion (rtpy/scene.py) with {what} returned {got}: any object hit "
            "with t strictly inside the interval blocks the light, nothing else does"
        )


def lit_plane_scene(occluder: bool):
    albedo = Color(0.6, 0.4, 0.9)
    floor = Quad(Vec3(-50, 0, -50), Vec3(0, 0, 100), Vec3(100, 0, 0), Lambertian(albedo))
    objects = [floor]
    if occluder:
        objects.append(Sphere(Vec3(0.5, 1.0, 0.2), 0.3, Lambertian()))
    light = PointLight(Vec3(0.7, 2.0, 0.3), Color(3.0, 2.0, 1.0))
    return Scene(objects, [light]), albedo, light


class FlatBRDF:
    """A stand-in material with f_r = f above the surface, so that the estimate's grader
    does not depend on Lambertian."""

    is_specular = False

    def __init__(self, f: Color) -> None:
        self.f = f

    def BRDF(self, ray_view, ray_light, hit):
        return self.f if dot(hit.normal, ray_light.direction) > 0.0 else BLACK


@points(3, task="05.4")
def test_light_sample_estimate():
    """light_sample_estimate: f_r L cos / pdf, black behind the surface or in shadow"""
    rng = np.random.default_rng(RNG_SEED + 2)
    f = Color(0.2, 0.1, 0.3)
    where = "light_sample_estimate (rtpy/integrators/direct_lighting.py)"
    for k in range(40):
        p = np.array([rng.uniform(-2, 2), 0.0, rng.uniform(-2, 2)])
        light = p + rng.uniform(0.5, 3) * unit(
            np.array([rng.uniform(-1, 1), 1.0, rng.uniform(-1, 1)])
        )
        if k % 5 == 4:
            light[1] = -light[1]  # the light below the surface
        to_light = light - p
        dist = float(np.linalg.norm(to_light))
        radiance, pdf = rng.uniform(0.5, 4, 3), rng.uniform(0.05, 5.0)
        sample = LightSample(
            Vec3(*(to_light / dist)), dist, Color(*radiance), pdf, False, Vec3(*light)
        )
        hit = HitInfo(Vec3(*p), Vec3(0, 1, 0), 1.0, True, FlatBRDF(f))
        eye = p + unit(np.array([0.3, 1.0, -0.2]))
        ray_in = Ray(Vec3(*eye), Vec3(*unit(p - eye)))
        mid, r = p + 0.5 * to_light, 0.1 * dist
        cases = [  # (objects, the light's own shape, blocked?, what)
            ([], None, False, "nothing in the way"),
            ([Sphere(Vec3(*mid), r, Lambertian())], None, True, "a sphere halfway to the light"),
            ([Sphere(Vec3(*(light + 0.5 * to_light)), r, Lambertian())], None, False,
             "a sphere beyond the light"),
        ]  # fmt: skip
        own = Sphere(Vec3(*mid), r, DiffuseLight(Color(1, 1, 1)))
        cases.append(([own], own, False, "the light's own shape (light_shape), not tested"))
        cos = to_light[1] / dist
        for objects, shape, blocked, what in cases:
            got = np.array(
                list(
                    direct_lighting.light_sample_estimate(
                        Scene(objects), ray_in, hit, sample, shape
                    )
                )
            )
            expected = np.zeros(3)
            if cos > 0 and not blocked:
                expected = np.array(list(f)) * radiance * cos / pdf
            assert np.allclose(got, expected, rtol=1e-9, atol=1e-12), (
                f"{where} with the light {'below' if cos <= 0 else 'above'} the surface, "
                f"{what}: {got.round(6)}, expected {expected.round(6)} = f_r * L * cos(theta) "
                f"/ pdf with cos(theta) = {cos:.4f} of the UNIT direction to the light and "
                f"pdf = sample.pdf = {pdf:.4f}; 0 when the light is behind the surface or the "
                "shadow ray (scene.find_occlusion over shadow_interval, ignoring light_shape) "
                "is blocked"
            )


@points(3, task="05.4")
def test_direct_light_on_a_plane_is_exact():
    """direct integrator: albedo/pi * I cos / d^2 on a plane, 0 in the shadow"""
    rng = np.random.default_rng(RNG_SEED + 1)
    scene, albedo, light = lit_plane_scene(occluder=True)
    integrator = DirectIntegrator(RenderSettings(integrator="direct"))
    lp = np.array(list(light.position))
    for k in range(30):
        target = np.array([rng.uniform(-3, 3), 0.0, rng.uniform(-3, 3)])
        if k < 3:  # points in the sphere's shadow
            target = (
                lp + (np.array([0.5, 1.0, 0.2]) - lp) * (2.0 / 1.0) + rng.uniform(-0.05, 0.05, 3)
            )
            target[1] = 0.0
        # looked at from just above (below the sphere), from a random direction
        eye = target + 0.05 * unit(np.array([rng.uniform(-1, 1), 1.0, rng.uniform(-1, 1)]))
        d = unit(target - eye)
        got = np.array(list(integrator.compute_scattering(Ray(Vec3(*eye), Vec3(*d)), scene)))
        to_light = lp - target
        dist2 = to_light @ to_light
        cos = to_light[1] / math.sqrt(dist2)
        blocked = (  # computed here, not by the code being graded
            scene.objects[1].hit_t(
                Ray(Vec3(*target), Vec3(*unit(to_light))), 1e-9, math.sqrt(dist2)
            )
            is not None
        )
        expected = 0.0 if blocked else 1.0
        expected = (
            expected
            * np.array(list(albedo))
            / math.pi
            * np.array(list(light.intensity))
            * cos
            / dist2
        )
        assert np.allclose(got, expected, rtol=1e-6, atol=1e-12), (
            f"direct integrator at floor point {target.round(3)}{' (in shadow)' if blocked else ''}: "
            f"radiance {got.round(6)}, expected albedo/pi * I cos(theta) / d^2 = {expected.round(6)}. "
            "Check PointLight.sample (1/d^2), the cosine with the UNIT direction to the light, "
            "the shadow ray (rtpy/integrators/direct_lighting.py: light_sample_estimate)"
        )


def area_light_scene():
    red, white = Lambertian(Color(0.7, 0.2, 0.2)), Lambertian(Color(0.7, 0.7, 0.7))
    objects = [
        Quad(Vec3(-3, 0, -5), Vec3(6, 0, 0), Vec3(0, 0, 5), white),
        Sphere(Vec3(-0.6, 0.5, -2.5), 0.5, red),
        Sphere(Vec3(0.8, 0.4, -2.0), 0.4, white),
        Sphere(Vec3(0.0, 2.2, -2.2), 0.4, DiffuseLight(Color(6.0, 6.0, 5.0))),
    ]
    camera = rtpy_camera()
    return Scene(objects, [PointLight(Vec3(1.5, 1.5, -1.0), Color(1.5, 1.5, 1.5))], camera=camera)


def rtpy_camera():
    from rtpy import Camera

    return Camera(Vec3(0, 1.0, 0.5), Vec3(0, 0.6, -2.5), vfov=60, aspect_ratio="16:9", width=32)


# The graded render: R seeds at SPP samples per pixel, against the reference
# (rendered by rtpy's solution with REFERENCE_SEEDS at REFERENCE_SPP).
RENDER = {"integrator": "direct", "spp": 8, "max_depth": 5}
SEEDS = (1, 2, 3, 4)
REFERENCE = {"name": "direct_area_light", "seeds": tuple(range(100, 108)), "spp": 64}


def make_reference_summary():
    return reference_summary(area_light_scene(), RENDER, REFERENCE)


@points(4, task="05.4")
def test_direct_render_matches_reference():
    """render with an area and a point light matches the reference (light counted once)"""
    assert_renders_match(
        area_light_scene(),
        SEEDS,
        RENDER,
        HERE / "reference" / f"{REFERENCE['name']}.npz",
        "direct integrator (rtpy/integrators/direct.py, direct_lighting.py) differs from the "
        "reference beyond its noise. Too bright: emission added twice in "
        "DirectIntegrator.compute_scattering (direct_lighting already weighs the light a "
        "scattered ray finds); too dark near the area light: light_sample_estimate without "
        "its 1/pdf, or a shadow ray blocked by the light itself (pass light_shape as "
        "ignore and use shadow_interval); dark speckles on lit surfaces (shadow acne): the "
        "shadow ray must leave through spawn_ray(hit.point, hit.normal, direction), whose "
        "offset keeps it off the surface it starts on",
    )


@points(1, task="05.4")
def test_direct_sees_emitters_and_background():
    """direct integrator: emission seen directly, background on a miss"""
    emit = Color(2.0, 3.0, 4.0)
    scene = Scene(
        [Sphere(Vec3(0, 0, -3), 1.0, DiffuseLight(emit))], background=Color(0.1, 0.2, 0.3)
    )
    integrator = DirectIntegrator(RenderSettings(integrator="direct"))
    got = integrator.compute_scattering(Ray(Vec3(0, 0, 0), Vec3(0, 0, -1)), scene)
    assert np.allclose(list(got), list(emit)), (
        f"DirectIntegrator.compute_scattering: a camera ray hitting a light returned {got}, expected its emission {emit}"
    )
    got = integrator.compute_scattering(Ray(Vec3(0, 0, 0), Vec3(0, 1, 0)), scene)
    assert np.allclose(list(got), [0.1, 0.2, 0.3]), (
        f"DirectIntegrator.compute_scattering: a ray that misses everything returned {got}, expected the background"
    )
