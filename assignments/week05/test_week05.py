# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 05 graders: point lights with 1/r^2, shadow rays, Lambertian, the light-sampling
estimate and the direct integrator; each names its task of assignments/week05/tasks.toml.

Each test is a verdict: it asks the student's code for numbers through `probe`
(the probes are in probes.py beside this file) and decides here, in the judge. Each
names the method it checks and says what is wrong when it fails.
Run them with `python -m rtpy grade 05`.
"""

import math
from pathlib import Path

import numpy as np

import rtpy.testing as rt
from rtpy.grading import (
    assert_renders_match,
    points,
    reference_summary,
    scene_uses,
)
from rtpy.grading.graders import chi2_picture_note
from rtpy.grading.remote_material import RemoteMaterial

HERE = Path(__file__).parent
RNG_SEED = 2005


def unit(v):
    return v / np.linalg.norm(v)


def local_direction(theta_deg, phi_deg=0.0):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


@points(3, task="05.1")
def test_point_light_sample(probe):
    """PointLight.sample: unit direction, distance, radiance I / d^2"""
    rng = np.random.default_rng(RNG_SEED)
    cases = []
    for _ in range(40):
        pos, p, intensity = rng.uniform(-5, 5, 3), rng.uniform(-5, 5, 3), rng.uniform(0.1, 9, 3)
        cases.append({"position": pos, "point": p, "intensity": intensity})
    for case, s in zip(cases, probe.point_light_sample(cases=cases), strict=True):
        pos, p, intensity = case["position"], case["point"], case["intensity"]
        d = pos - p
        dist = float(np.linalg.norm(d))
        where = (
            f"PointLight.sample (rtpy/light.py) with the light at {pos.round(3)}, p = {p.round(3)}"
        )
        assert s is not None, f"{where}: returned None"
        assert np.allclose(s.direction, d / dist, rtol=1e-9, atol=1e-12), (
            f"{where}: direction {s.direction.round(6)} should be the unit vector from p toward the light "
            f"{(d / dist).round(6)}"
        )
        assert math.isclose(s.distance, dist, rel_tol=1e-9), (
            f"{where}: distance {s.distance} != {dist}"
        )
        ratio = s.radiance / intensity
        assert np.allclose(ratio, 1.0 / dist**2, rtol=1e-9), (
            f"{where}: radiance is intensity * {ratio.mean():.4g}, expected intensity / d^2 = "
            f"intensity * {1 / dist**2:.4g} (a point light falls off with the square of the distance)"
        )
        assert s.is_delta and s.pdf == 1.0, (
            f"{where}: a point light is a delta light: is_delta True, pdf 1"
        )


LAMBERTIAN = {"type": "Lambertian", "albedo": [0.8, 0.5, 0.2]}


@points(3, task="05.3")
def test_lambertian_brdf_and_sampling(probe):
    """BRDF = albedo / pi, pdf = cos / pi, cosine sampling, weight = BRDF * cos / pdf"""
    albedo = np.array(LAMBERTIAN["albedo"])
    material = RemoteMaterial(probe, LAMBERTIAN)
    wo = local_direction(30.0)
    thetas = (0.0, 40.0, 80.0)
    wi = np.array([local_direction(t, 70.0) for t in thetas])
    f = material.brdf(np.tile(wo, (len(wi), 1)), wi)
    for theta, value in zip(thetas, f, strict=True):
        assert np.allclose(value, albedo / math.pi, rtol=1e-9), (
            f"Lambertian.BRDF (rtpy/materials/lambertian.py) = {value.round(6)} at {theta} degrees; "
            "f_r is albedo / pi (the albedo alone would reflect pi times too much light)"
        )
    below = material.brdf(wo[None], local_direction(120.0)[None])[0]
    assert not below.any(), "Lambertian.BRDF: light from below the surface must give 0"
    thetas = (0.0, 40.0, 80.0, 120.0)
    wi = np.array([local_direction(t, 70.0) for t in thetas])
    pdfs = material.pdf(np.tile(wo, (len(wi), 1)), wi)
    for theta, got in zip(thetas, pdfs, strict=True):
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
        passed = chi2.passed(rt.sidak_alpha(0.01, 2))
        picture = f"week05-Lambertian-{theta:g}deg"
        assert passed, (
            f"Lambertian.scattering: directions do not follow pdf = cos / pi: {chi2.summary()}."
            + chi2_picture_note(chi2, theta, material, picture, "Lambertian.scattering", "05")
        )


@points(2, task="05.2")
def test_shadow_rays(probe):
    """Scene.find_occlusion: blockers between the point and the light only"""
    cases = [
        ([[(0, 0, -2), 0.5]], True, "a sphere halfway to the light"),
        ([[(0, 0, -8), 0.5]], False, "a sphere beyond the light"),
        ([[(0, 0, 3), 0.5]], False, "a sphere behind the point"),
        ([[(2, 0, -2), 0.5]], False, "a sphere beside the ray"),
        ([[(2, 0, -2), 0.5], [(0, 0, -3), 0.5]], True, "one blocker among other objects"),
    ]
    asked = [{"spheres": spheres, "interval": [0.0, 5.0]} for spheres, _, _ in cases]
    got = probe.find_occlusion(ray=[[0, 0, 0], [0, 0, -1]], cases=asked)
    for (_, expected, what), answer in zip(cases, got, strict=True):
        assert answer == expected, (
            f"Scene.find_occlusion (rtpy/scene.py) with {what} returned {answer}: any object hit "
            "with t strictly inside the interval blocks the light, nothing else does"
        )


@points(3, task="05.4")
def test_light_sample_estimate(probe):
    """light_sample_estimate: f_r L cos / pdf, black behind the surface or in shadow"""
    rng = np.random.default_rng(RNG_SEED + 2)
    f = np.array([0.2, 0.1, 0.3])
    where = "light_sample_estimate (rtpy/integrators/direct_lighting.py)"
    cases, expectations = [], []
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
        eye = p + unit(np.array([0.3, 1.0, -0.2]))
        mid, r = p + 0.5 * to_light, 0.1 * dist
        beyond = light + 0.5 * to_light
        variants = [  # (objects [center, radius, emits], the light's own shape, blocked?, what)
            ([], None, False, "nothing in the way"),
            ([[mid, r, False]], None, True, "a sphere halfway to the light"),
            ([[beyond, r, False]], None, False, "a sphere beyond the light"),
            ([[mid, r, True]], 0, False, "the light's own shape (light_shape), not tested"),
        ]
        cos = to_light[1] / dist
        for objects, shape, blocked, what in variants:
            cases.append(
                {"point": p, "light": light, "radiance": radiance, "pdf": pdf, "eye": eye,
                 "objects": objects, "light_shape": shape}
            )  # fmt: skip
            expected = f * radiance * cos / pdf if cos > 0 and not blocked else np.zeros(3)
            expectations.append((expected, cos, pdf, what))
    got = probe.light_sample_estimate(cases=cases, f=f)
    for value, (expected, cos, pdf, what) in zip(got, expectations, strict=True):
        assert np.allclose(value, expected, rtol=1e-9, atol=1e-12), (
            f"{where} with the light {'below' if cos <= 0 else 'above'} the surface, "
            f"{what}: {value.round(6)}, expected {expected.round(6)} = f_r * L * cos(theta) "
            f"/ pdf with cos(theta) = {cos:.4f} of the UNIT direction to the light and "
            f"pdf = sample.pdf = {pdf:.4f}; 0 when the light is behind the surface or the "
            "shadow ray (scene.find_occlusion over shadow_interval, ignoring light_shape) "
            "is blocked"
        )


def segment_hits_sphere(a, b, center, radius) -> bool:
    """Does the open segment from a to b pass through the sphere?"""
    d = b - a
    length = np.linalg.norm(d)
    d = d / length
    oc = a - center
    h = d @ oc
    disc = h * h - (oc @ oc - radius * radius)
    if disc < 0:
        return False
    roots = (-h - math.sqrt(disc), -h + math.sqrt(disc))
    return any(1e-9 < t < length for t in roots)


@points(3, task="05.4")
def test_direct_light_on_a_plane_is_exact(probe):
    """direct integrator: albedo/pi * I cos / d^2 on a plane, 0 in the shadow"""
    rng = np.random.default_rng(RNG_SEED + 1)
    albedo, lp, intensity = (
        np.array([0.6, 0.4, 0.9]),
        np.array([0.7, 2.0, 0.3]),
        np.array([3.0, 2.0, 1.0]),
    )
    occluder = (np.array([0.5, 1.0, 0.2]), 0.3)
    rays, targets = [], []
    for k in range(30):
        target = np.array([rng.uniform(-3, 3), 0.0, rng.uniform(-3, 3)])
        if k < 3:  # points in the sphere's shadow
            target = lp + (occluder[0] - lp) * 2.0 + rng.uniform(-0.05, 0.05, 3)
            target[1] = 0.0
        # looked at from just above (below the sphere), from a random direction
        eye = target + 0.05 * unit(np.array([rng.uniform(-1, 1), 1.0, rng.uniform(-1, 1)]))
        rays.append([eye, unit(target - eye)])
        targets.append(target)
    params = {"albedo": albedo, "light": lp, "intensity": intensity,
              "occluder": [occluder[0], occluder[1]]}  # fmt: skip
    got = probe.radiance(
        scene="lit_plane", params=params, rays=rays, settings={"integrator": "direct"}
    )
    for target, value in zip(targets, got, strict=True):
        to_light = lp - target
        dist2 = to_light @ to_light
        cos = to_light[1] / math.sqrt(dist2)
        blocked = segment_hits_sphere(target, lp, *occluder)  # computed here
        expected = (0.0 if blocked else 1.0) * albedo / math.pi * intensity * cos / dist2
        assert np.allclose(value, expected, rtol=1e-6, atol=1e-12), (
            f"direct integrator at floor point {target.round(3)}{' (in shadow)' if blocked else ''}: "
            f"radiance {value.round(6)}, expected albedo/pi * I cos(theta) / d^2 = {expected.round(6)}. "
            "Check PointLight.sample (1/d^2), the cosine with the UNIT direction to the light, "
            "the shadow ray (rtpy/integrators/direct_lighting.py: light_sample_estimate)"
        )


# The graded render: R seeds at SPP samples per pixel, against the reference
# (rendered by rtpy's solution with REFERENCE_SEEDS at REFERENCE_SPP).
RENDER = {"integrator": "direct", "spp": 8, "max_depth": 5}
SEEDS = (1, 2, 3, 4)
REFERENCE = {"name": "direct_area_light", "seeds": tuple(range(100, 108)), "spp": 64}


def make_reference_summary(probe):
    return reference_summary(probe, "area_light", RENDER, REFERENCE)


@points(4, task="05.4")
@scene_uses("05.1", "05.2", "05.3")
def test_direct_render_matches_reference(probe):
    """render with an area and a point light matches the reference (light counted once)"""
    assert_renders_match(
        probe,
        "area_light",
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
def test_direct_sees_emitters_and_background(probe):
    """direct integrator: emission seen directly, background on a miss"""
    emit, background = [2.0, 3.0, 4.0], [0.1, 0.2, 0.3]
    hit, miss = probe.radiance(
        scene="glowing_ball",
        params={"emit": emit, "background": background},
        rays=[[[0, 0, 0], [0, 0, -1]], [[0, 0, 0], [0, 1, 0]]],
        settings={"integrator": "direct"},
    )
    assert np.allclose(hit, emit), (
        f"DirectIntegrator.compute_scattering: a camera ray hitting a light returned {hit}, expected its emission {emit}"
    )
    assert np.allclose(miss, background), (
        f"DirectIntegrator.compute_scattering: a ray that misses everything returned {miss}, expected the background"
    )
