# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 08 graders: Phong, Blinn-Phong and Cook-Torrance BRDF() and scattering(), and
the path integrator. Run them with `python -m rtpy grade 08`.

The sampling checks are rtpy.testing's (chi-square test of scattering() against
pdf(), weight = BRDF * cos / pdf, energy, reciprocity) with fewer samples than
rtpy's own tests, so grading stays fast; each is Sidak-corrected over its cases.
"""

import math
from pathlib import Path

import numpy as np
import pytest

import rtpy.testing as rt
from rtpy import Camera, Color, Lambertian, Quad, Scene, Sphere, Vec3
from rtpy.grading import assert_render_matches, load_reference, points, render_stack, summarize
from rtpy.materials import BlinnPhong, CookTorrance, DiffuseLight, Phong

HERE = Path(__file__).parent
ALBEDO = Color(0.5, 0.4, 0.3)

MODELS = {
    "phong": lambda: Phong(ALBEDO, kd=0.5, ks=0.4, exponent=20.0),
    "blinn_phong": lambda: BlinnPhong(ALBEDO, kd=0.5, ks=0.4, exponent=60.0),
    "cook_torrance_ggx": lambda: CookTorrance(ALBEDO, kd=0.5, ks=0.5, roughness=0.3),
    "cook_torrance_beckmann": lambda: CookTorrance(
        ALBEDO, kd=0.5, ks=0.5, roughness=0.3, distribution="beckmann"
    ),
}
WHERE = {
    "phong": "Phong (rtpy/materials/phong.py)",
    "blinn_phong": "BlinnPhong (rtpy/materials/blinn_phong.py)",
    "cook_torrance_ggx": "CookTorrance with GGX (rtpy/materials/cook_torrance.py)",
    "cook_torrance_beckmann": "CookTorrance with Beckmann (rtpy/materials/cook_torrance.py)",
}
ANGLES = (20.0, 70.0)


def random_pairs(n, seed):
    """n pairs (wo, wi) of local unit directions above the surface."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        pair = []
        for _ in range(2):
            cos = rng.uniform(0.05, 1.0)
            phi = rng.uniform(0, 2 * math.pi)
            s = math.sqrt(1 - cos * cos)
            pair.append(np.array([s * math.cos(phi), s * math.sin(phi), cos]))
        out.append(pair)
    return out


def brdf(material, wo, wi):
    hit = rt.local_hit(material)
    return np.array(list(material.BRDF(rt.view_ray(Vec3(*wo)), rt.light_ray(Vec3(*wi)), hit)))


def lobe_check(name, formula):
    material = MODELS[name]()
    for wo, wi in random_pairs(60, seed=8):
        expected = material.kd * np.array(list(ALBEDO)) / math.pi + material.ks * formula(
            material, wo, wi
        )
        got = brdf(material, wo, wi)
        assert np.allclose(got, expected, rtol=1e-6, atol=1e-12), (
            f"{WHERE[name]}: BRDF(wo={wo.round(3)}, wi={wi.round(3)}) = {got.round(6)}, expected "
            f"{expected.round(6)} (kd * albedo / pi + ks * the specular lobe)"
        )


@points(2)
def test_phong_brdf():
    """Phong BRDF: (n + 2) / (2 pi) max(0, r . wo)^n"""

    def phong(m, wo, wi):
        r = np.array([-wi[0], -wi[1], wi[2]])  # reflect wi about the normal
        return (m.exponent + 2) / (2 * math.pi) * max(0.0, r @ wo) ** m.exponent

    lobe_check("phong", phong)


@points(2)
def test_blinn_phong_brdf():
    """Blinn-Phong BRDF: (n + 8) / (8 pi) (n . h)^n with the unit half vector"""

    def blinn(m, wo, wi):
        h = (wo + wi) / np.linalg.norm(wo + wi)
        return (m.exponent + 8) / (8 * math.pi) * max(0.0, h[2]) ** m.exponent

    lobe_check("blinn_phong", blinn)


def ct_formula(m, wo, wi):
    h = (wo + wi) / np.linalg.norm(wo + wi)
    a2 = m.alpha**2

    def tan2(v):
        return (1 - v[2] ** 2) / v[2] ** 2

    if m.distribution == "ggx":
        d = a2 / (math.pi * h[2] ** 4 * (a2 + tan2(h)) ** 2)

        def g1(v):
            return 2 / (1 + math.sqrt(1 + a2 * tan2(v)))

    else:
        d = math.exp(-tan2(h) / a2) / (math.pi * a2 * h[2] ** 4)

        def g1(v):
            a = 1 / (m.alpha * math.sqrt(tan2(v)))
            lam = (math.erf(a) - 1) / 2 + math.exp(-a * a) / (2 * a * math.sqrt(math.pi))
            return 1 / (1 + lam)

    f0 = np.array(list(m.f0))
    f = f0 + (1 - f0) * (1 - wo @ h) ** 5
    return d * g1(wo) * g1(wi) * f / (4 * wo[2] * wi[2])


@points(3)
@pytest.mark.parametrize("name", ["cook_torrance_ggx", "cook_torrance_beckmann"])
def test_cook_torrance_brdf(name):
    """Cook-Torrance BRDF: D G F / (4 cos_i cos_o)"""
    lobe_check(name, ct_formula)


@points(3)
@pytest.mark.parametrize("name", list(MODELS))
def test_sampling_follows_pdf(name):
    """scattering() draws directions with density pdf() (chi-square)"""
    material = MODELS[name]()
    alpha = rt.sidak_alpha(0.01, len(MODELS) * len(ANGLES))
    for theta in ANGLES:
        result = rt.chi2_test(material, theta, n_samples=10_000, theta_bins=8, phi_bins=16, seed=8)
        assert result.passed(alpha), (
            f"{WHERE[name]}.scattering at {theta} degrees draws directions that do not follow "
            f"pdf() (p = {result.p_value:.2g}): {result.summary()}. Check the lobe sampling and "
            "its density (a half-vector density needs the Jacobian 1 / (4 wo . h))"
        )


@points(3)
@pytest.mark.parametrize("name", list(MODELS))
def test_weight_is_brdf_cos_over_pdf(name):
    """scattering() weight = BRDF * cos / pdf"""
    material = MODELS[name]()
    for theta in ANGLES:
        result = rt.check_weights(material, theta, n=200, seed=8)
        assert result.passed, (
            f"{WHERE[name]}.scattering at {theta} degrees: the attenuation must be "
            f"BRDF * cos(theta_i) / pdf of the lobe mixture: {result.detail}"
        )


@points(2)
@pytest.mark.parametrize("name", list(MODELS))
def test_energy_and_reciprocity(name):
    """albedo <= 1 and BRDF(wo, wi) = BRDF(wi, wo)"""
    material = MODELS[name]()
    result = rt.check_reciprocity(material, n_pairs=200, seed=8)
    assert result.passed, f"{WHERE[name]}.BRDF is not reciprocal: {result.detail}"
    for theta in ANGLES:
        result = rt.check_energy(material, theta, n_samples=10_000, seed=8)
        assert result.passed, f"{WHERE[name]} at {theta} degrees: {result.detail}"


def three_balls():
    ground = Lambertian(Color(0.5, 0.5, 0.5))
    objects = [
        Quad(Vec3(-4, 0, -6), Vec3(8, 0, 0), Vec3(0, 0, 6), ground),
        Sphere(Vec3(-1.1, 0.5, -2.5), 0.5, Phong(Color(0.7, 0.2, 0.2), kd=0.6, ks=0.3, exponent=8)),
        Sphere(
            Vec3(0.0, 0.5, -2.5), 0.5, BlinnPhong(Color(0.2, 0.7, 0.2), kd=0.6, ks=0.3, exponent=30)
        ),
        Sphere(
            Vec3(1.1, 0.5, -2.5),
            0.5,
            CookTorrance(Color(0.2, 0.2, 0.7), kd=0.6, ks=0.4, roughness=0.2),
        ),
        Quad(Vec3(-0.8, 2.5, -3.0), Vec3(1.6, 0, 0), Vec3(0, 0, 1.0), DiffuseLight(Color(5, 5, 5))),
    ]
    camera = Camera(Vec3(0, 1.2, 0.8), Vec3(0, 0.5, -2.5), vfov=50, aspect_ratio="16:9", width=32)
    return Scene(objects, background=Color(0.05, 0.05, 0.08), camera=camera)


RENDER = {"integrator": "path", "spp": 8, "max_depth": 5}
SEEDS = (1, 2, 3, 4)
REFERENCE = {"name": "path_three_balls", "seeds": tuple(range(100, 108)), "spp": 64}


def make_reference_summary():
    settings = dict(RENDER, spp=REFERENCE["spp"])
    return summarize(render_stack(three_balls(), REFERENCE["seeds"], **settings), REFERENCE["spp"])


@points(4)
def test_path_render_matches_reference():
    """path integrator: three glossy balls under a quad light match the reference"""
    stack = render_stack(three_balls(), SEEDS, **RENDER)
    assert_render_matches(
        stack,
        RENDER["spp"],
        load_reference(HERE / "reference" / f"{REFERENCE['name']}.npz"),
        "path integrator (rtpy/integrators/path.py) with the week's materials differs from "
        "the reference beyond its noise. Too bright: light counted twice (MIS weight of "
        "emission found by a bounce) or a weight without 1/pdf; too dark: Russian roulette "
        "without dividing by the survival probability, or a lobe that loses energy",
    )


class GlowingDiffuse(Lambertian):
    """A Lambertian surface that also emits Le from both faces (for the furnace)."""

    is_emitter = True

    def __init__(self, rho: float, le: float) -> None:
        super().__init__(Color(rho, rho, rho))
        self.le = Color(le, le, le)

    def emitting(self, hit):
        return self.le


@points(3)
def test_path_furnace():
    """path integrator: inside a glowing sphere L = Le / (1 - albedo)"""
    rho, le = 0.5, 0.5
    scene = Scene(
        [Sphere(Vec3(0, 0, 0), 2.0, GlowingDiffuse(rho, le))],
        camera=Camera(Vec3(0.2, 0.1, -0.3), Vec3(0, 0, -1), vfov=90, aspect_ratio=1.0, width=8),
    )
    stack = render_stack(scene, (1, 2), integrator="path", spp=8, max_depth=100, russian_roulette=3)
    values = stack[..., 0].ravel()
    mean, se = values.mean(), values.std(ddof=1) / math.sqrt(values.size)
    z = (mean - le / (1 - rho)) / se
    assert abs(z) < 4.5, (
        f"PathIntegrator.compute_scattering (rtpy/integrators/path.py): inside a closed sphere of albedo "
        f"{rho} emitting {le}, every pixel must converge to Le / (1 - albedo) = "
        f"{le / (1 - rho):g}; got {mean:.4f} +- {se:.4f} (z = {z:.1f}). Too low: Russian "
        "roulette survivors not divided by their survival probability, or paths cut short; "
        "too high: emission counted twice (light sampling plus the bounce that hits it)"
    )
