# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 06 graders: reflect, refract (Snell), Schlick, total internal reflection, the
mirror and the dielectric. Run them with `python -m rtpy grade 06`.

Each test is a verdict: it asks the student's code for numbers through `probe`
(the probes are in probes.py beside this file) and decides here, in the judge. Each
names the method it checks and says what is wrong when it fails.
"""

import math
from pathlib import Path

import numpy as np

from rtpy.grading import assert_image_matches, points, scene_uses

HERE = Path(__file__).parent


def random_incidence(rng):
    """A unit normal n and a unit direction d arriving at the surface (d . n < 0)."""
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    if d @ n > 0:
        d = -d
    return n, d


def schlick(cosine, ratio):
    """Schlick's reflectance, computed here: r0 + (1 - r0)(1 - cos)^5."""
    r0 = ((1 - ratio) / (1 + ratio)) ** 2
    return r0 + (1 - r0) * (1 - cosine) ** 5


@points(2, task="06.1")
def test_reflect(probe):
    """vec3.reflect: v - 2 (v . n) n"""
    rng = np.random.default_rng(6)
    cases = [random_incidence(rng) for _ in range(50)]
    got = probe.week06_reflect(cases=[[d, n] for n, d in cases])
    for (n, d), value in zip(cases, got, strict=True):
        expected = d - 2 * (d @ n) * n
        assert np.allclose(value, expected, atol=1e-12), (
            f"reflect (rtpy/vec3.py): reflect({d.round(3)}, n={n.round(3)}) = {value.round(4)}, "
            f"expected {expected.round(4)} (v - 2 (v . n) n: same angle on the other side of n)"
        )


@points(3, task="06.2")
def test_refract_obeys_snell(probe):
    """vec3.refract: Snell's law, in the plane of incidence, unit length"""
    rng = np.random.default_rng(66)
    cases = []
    for _ in range(100):
        n, d = random_incidence(rng)
        eta = rng.uniform(0.4, 1.6)
        sin_i = np.linalg.norm(np.cross(d, n))
        if eta * sin_i >= 1:
            continue  # total internal reflection: refract is not called
        cases.append((n, d, eta, sin_i))
    got = probe.week06_refract(cases=[[d, n, eta] for n, d, eta, _ in cases])
    for (n, d, eta, sin_i), t in zip(cases, got, strict=True):
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
def test_schlick(probe):
    """dielectric.schlick: r0 + (1 - r0)(1 - cos)^5"""
    rng = np.random.default_rng(7)
    cases = [(rng.uniform(0, 1), rng.uniform(0.3, 3)) for _ in range(50)]
    got = probe.week06_schlick(cases=cases)
    for (c, ratio), value in zip(cases, got, strict=True):
        expected = schlick(c, ratio)
        assert abs(value - expected) < 1e-12, (
            f"schlick (rtpy/materials/dielectric.py): schlick({c:.3f}, {ratio:.3f}) = {value:.6f}, "
            f"expected r0 + (1 - r0)(1 - cos)^5 = {expected:.6f} with r0 = ((1 - eta)/(1 + eta))^2"
        )


def incoming(theta_deg):
    """The ray [origin, direction] arriving at the origin at theta_deg from the normal
    (0, 0, 1), in the x-z plane."""
    t = math.radians(theta_deg)
    return [math.sin(t), 0.0, math.cos(t)], [-math.sin(t), 0.0, -math.cos(t)]


def scatter_case(material, theta_deg, front_face, count):
    """A case of the probe week06_scatter: count scatterings of the ray arriving at
    theta_deg at a hit at the origin with normal (0, 0, 1)."""
    origin, direction = incoming(theta_deg)
    return {"material": material, "origin": origin, "direction": direction,
            "normal": [0.0, 0.0, 1.0], "front_face": front_face, "count": count}  # fmt: skip


def none_message(rows, method):
    """The message for scatterings that returned None (a dielectric or a mirror always
    scatters), or None when every one returned a sample."""
    if (rows[:, 0] == 1.0).all():
        return None
    return (
        f"{method}: returned None; a {method.split('.')[0].lower()} never absorbs, it returns "
        "a ScatterInfo for every ray"
    )


@points(2, task="06.3")
def test_total_internal_reflection(probe):
    """Dielectric: from inside beyond the critical angle every ray reflects"""
    glass = {"type": "Dielectric", "ior": 1.5}
    critical = math.degrees(math.asin(1 / 1.5))
    thetas = (critical + 1, 60.0, 85.0)
    cases = [scatter_case(glass, theta, False, 50) for theta in thetas]
    cases.append(scatter_case(glass, critical - 5, False, 50))
    *beyond, below = probe.week06_scatter(cases=cases, generator=[6, 1])
    for theta, rows in zip(thetas, beyond, strict=True):
        message = none_message(rows, "Dielectric.scattering (rtpy/materials/dielectric.py)")
        assert message is None, message
        assert (rows[:, 3] > 0).all(), (
            f"Dielectric.scattering (rtpy/materials/dielectric.py): inside glass at {theta:.1f} "
            f"degrees (critical angle {critical:.1f}) a ray refracted out: beyond the critical "
            "angle eta sin(theta) > 1 and the ray must reflect (total internal reflection)"
        )
    message = none_message(below, "Dielectric.scattering (rtpy/materials/dielectric.py)")
    assert message is None, message
    assert (below[:, 3] < 0).sum() > 0, (
        "Dielectric.scattering: below the critical angle light must also leave the glass"
    )


@points(2, task="06.3")
def test_dielectric_reflects_with_probability_schlick(probe):
    """Dielectric.scattering: reflect with probability R, refract otherwise, weight albedo"""
    albedo = [0.9, 0.95, 1.0]
    glass = {"type": "Dielectric", "ior": 1.5, "albedo": albedo}
    n, thetas = 4000, (10.0, 75.0)
    cases = [scatter_case(glass, theta, True, n) for theta in thetas]
    got = probe.week06_scatter(cases=cases, generator=[6, 2])
    for theta, rows in zip(thetas, got, strict=True):
        message = none_message(rows, "Dielectric.scattering (rtpy/materials/dielectric.py)")
        assert message is None, message
        wrong = ~np.isclose(rows[:, 4:7], albedo).all(axis=1)
        assert not wrong.any(), (
            "Dielectric.scattering: the weight is the albedo, with no cosine and no R factor "
            f"(R is the probability of reflecting); got {rows[np.argmax(wrong), 4:7].round(6)}"
        )
        reflected = int((rows[:, 3] > 0).sum())
        r = schlick(math.cos(math.radians(theta)), 1 / 1.5)
        z = (reflected / n - r) / math.sqrt(r * (1 - r) / n)
        assert abs(z) < 4.0, (
            f"Dielectric.scattering at {theta} degrees reflects {reflected / n:.3f} of rays, "
            f"Schlick's R is {r:.3f} (z = {z:.1f}); refracted rays must not be absorbed or clamped"
        )


@points(2, task="06.1")
def test_mirror(probe):
    """Mirror.scattering: the reflected ray, weight albedo (no cosine)"""
    mirror = {"type": "Mirror", "albedo": [0.9, 0.8, 0.7]}
    thetas = (0.0, 45.0, 80.0)
    got = probe.week06_scatter(cases=[scatter_case(mirror, theta, True, 1) for theta in thetas])
    for theta, rows in zip(thetas, got, strict=True):
        message = none_message(rows, "Mirror.scattering (rtpy/materials/mirror.py)")
        assert message is None, message
        (_, *direction, r, g, b, specular) = rows[0]
        t = math.radians(theta)
        assert np.allclose(direction, [-math.sin(t), 0, math.cos(t)], atol=1e-12), (
            f"Mirror.scattering (rtpy/materials/mirror.py) at {theta} degrees: not the mirror direction"
        )
        assert np.allclose([r, g, b], [0.9, 0.8, 0.7]), (
            f"Mirror.scattering at {theta} degrees: weight {np.round([r, g, b], 6)}; a mirror reflects "
            "albedo of the light, with no cosine factor"
        )
        assert specular == 1.0, "Mirror.scattering: the sample is specular (is_specular=True)"


# Whitted with a point light and a pinhole is deterministic; spp 1 shows each pixel's
# jittered sample, so the seed fixes the image.
REFERENCE = {"name": "whitted_optics"}
RENDER = {"integrator": "whitted", "max_depth": 8, "spp": 1}


def render_optics(probe):
    return probe.render(scene="week06_optics", seeds=[0], settings=RENDER)[0]


def make_reference_image(probe):
    return render_optics(probe)


@points(3, task="06.3")
@scene_uses("06.1", "06.2")
def test_whitted_render_matches_reference(probe):
    """whitted render of a glass and a mirror ball matches the reference"""
    image = render_optics(probe)
    reference = np.load(HERE / "reference" / f"{REFERENCE['name']}.npy", allow_pickle=False)
    assert_image_matches(
        image, reference, "whitted render", "glass that renders dark or opaque means "
        "refracted rays are lost; check reflect, refract, schlick and Dielectric._split",
        rtol=1e-6, atol=1e-9,
    )  # fmt: skip
