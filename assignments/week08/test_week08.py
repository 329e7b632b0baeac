# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 08 graders: the Phong, Blinn-Phong (the course's Blinn) and Cook-Torrance
reflection models, each with its own BRDF(), pdf() and scattering() (one task each), the
path integrator, and the optional Ward extension (0 points). Run them with
`python -m rtpy grade 08`.

Each test is a verdict: it asks the student's code for numbers through `probe` (the
materials through rtpy.grading.remote_material.RemoteMaterial, the scenes built by
probes.py beside this file) and decides here, in the judge. Each names the method it
checks and the likely mistake when it fails. A test run for every model grades each
model's case toward that model's task (`by_model`). The sampling checks are
rtpy.testing's (chi-square test of scattering() against pdf(), weight = BRDF * cos /
pdf, energy, reciprocity) with fewer samples than rtpy's own tests, so grading stays
fast; each is Sidak-corrected over its cases.
"""

import math
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

import rtpy.testing as rt
from rtpy.grading import (
    assert_renders_match,
    points,
    reference_summary,
)
from rtpy.grading.remote_material import RemoteMaterial

HERE = Path(__file__).parent
ALBEDO = [0.5, 0.4, 0.3]


class Model(NamedTuple):
    spec: dict  # the material, with the parameters graded (rtpy.grading.probes.make_material)
    where: str  # Class (file), for the messages
    task: str  # the task of assignments/week08/tasks.toml it grades


MODELS = {
    "phong": Model(
        {"type": "Phong", "albedo": ALBEDO, "kd": 0.5, "ks": 0.4, "exponent": 20.0},
        "Phong (rtpy/materials/phong.py)",
        "08.1",
    ),
    "blinn_phong": Model(
        {"type": "BlinnPhong", "albedo": ALBEDO, "kd": 0.5, "ks": 0.4, "exponent": 60.0},
        "BlinnPhong (rtpy/materials/blinn_phong.py)",
        "08.2",
    ),
    "cook_torrance_ggx": Model(
        {"type": "CookTorrance", "albedo": ALBEDO, "kd": 0.5, "ks": 0.5, "roughness": 0.3},
        "CookTorrance with GGX (rtpy/materials/cook_torrance.py)",
        "08.3",
    ),
    "cook_torrance_beckmann": Model(
        {
            "type": "CookTorrance",
            "albedo": ALBEDO,
            "kd": 0.5,
            "ks": 0.5,
            "roughness": 0.3,
            "distribution": "beckmann",
        },
        "CookTorrance with Beckmann (rtpy/materials/cook_torrance.py)",
        "08.3",
    ),  # fmt: skip
    "ward": Model(  # the optional extension: its pdf() and scattering() (0 points)
        {"type": "Ward", "albedo": ALBEDO, "kd": 0.5, "ks": 0.4, "alpha_x": 0.15, "alpha_y": 0.3},
        "Ward (rtpy/materials/ward.py)",
        "08.5",
    ),
}
ANGLES = (20.0, 70.0)
EXTENSION = "08.5"


def by_model(n, cook_torrance=None, extension=True):
    """The models as parametrized cases, each worth n points toward its model's task
    (each Cook-Torrance distribution `cook_torrance` points, if given; the extension's
    case 0 points, or no case without `extension`)."""
    cases = []
    for name, model in MODELS.items():
        value = cook_torrance if cook_torrance and model.task == "08.3" else n
        if model.task == EXTENSION:
            if not extension:
                continue
            value = 0
        cases.append(pytest.param(name, marks=points(value, task=model.task), id=name))
    return cases


def where(name, method):
    """Class.method (file), with the distribution for Cook-Torrance."""
    cls, _, rest = MODELS[name].where.partition(" ")
    return f"{cls}.{method} {rest}"


def material(probe, name):
    """The model `name` as the checks see it, in the student's process."""
    return RemoteMaterial(probe, MODELS[name].spec)


# The parameters rtpy's models derive from their spec, as rtpy defines them.
MIN_ALPHA = 1e-4  # the smallest width CookTorrance and Ward compute with
F0_DEFAULT = ((1 - 1.5) / (1 + 1.5)) ** 2  # CookTorrance's F0 for its default ior 1.5


def parameters(spec):
    """The spec's parameters with the defaults and derived values the formulas use:
    CookTorrance's alpha = roughness (rtpy's convention, not roughness^2) and f0."""
    p = {"distribution": "ggx", **spec, "albedo": np.array(spec["albedo"], dtype=float)}
    if "roughness" in p:
        p["alpha"] = max(p["roughness"], MIN_ALPHA)
        p["f0"] = np.full(3, F0_DEFAULT)
    if "alpha_x" in p:
        p["ax"] = max(p["alpha_x"], MIN_ALPHA)
        p["ay"] = max(p.get("alpha_y", p["alpha_x"]), MIN_ALPHA)
    return p


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


def unit_half(wo, wi):
    return (wo + wi) / np.linalg.norm(wo + wi)


def mirror(wo):
    """wo mirrored about the normal (0, 0, 1)."""
    return np.array([-wo[0], -wo[1], wo[2]])


# --- the lobes of the BRDFs ------------------------------------------------------------
# m: the parameters of a model (parameters(spec)), wo and wi: local unit directions.


def phong_lobe(m, wo, wi):
    r = mirror(wi)  # reflect(-wi, normal)
    n = m["exponent"]
    return (n + 2) / (2 * math.pi) * max(0.0, r @ wo) ** n


def blinn_lobe(m, wo, wi):
    h = unit_half(wo, wi)
    n = m["exponent"]
    return (n + 8) / (8 * math.pi) * max(0.0, h[2]) ** n


def tan2(v):
    return (1 - v[2] ** 2) / v[2] ** 2


def ct_D(m, h):
    a2 = m["alpha"] ** 2
    if m["distribution"] == "ggx":
        return a2 / (math.pi * h[2] ** 4 * (a2 + tan2(h)) ** 2)
    return math.exp(-tan2(h) / a2) / (math.pi * a2 * h[2] ** 4)


def ct_G1(m, v):
    a2 = m["alpha"] ** 2
    if m["distribution"] == "ggx":
        return 2 / (1 + math.sqrt(1 + a2 * tan2(v)))
    a = 1 / (m["alpha"] * math.sqrt(tan2(v)))
    lam = (math.erf(a) - 1) / 2 + math.exp(-a * a) / (2 * a * math.sqrt(math.pi))
    return 1 / (1 + lam)


def ct_lobe(m, wo, wi):
    h = unit_half(wo, wi)
    f0 = m["f0"]
    f = f0 + (1 - f0) * (1 - wo @ h) ** 5
    return ct_D(m, h) * ct_G1(m, wo) * ct_G1(m, wi) * f / (4 * wo[2] * wi[2])


LOBES = {
    "phong": phong_lobe,
    "blinn_phong": blinn_lobe,
    "cook_torrance_ggx": ct_lobe,
    "cook_torrance_beckmann": ct_lobe,
}


def lobe_check(probe, name, mistakes):
    m = parameters(MODELS[name].spec)
    pairs = random_pairs(60, seed=8)
    wo, wi = (np.array(side) for side in zip(*pairs, strict=True))
    got = material(probe, name).brdf(wo, wi)
    for (wo, wi), value in zip(pairs, got, strict=True):
        expected = m["kd"] * m["albedo"] / math.pi + m["ks"] * LOBES[name](m, wo, wi)
        assert np.allclose(value, expected, rtol=1e-6, atol=1e-12), (
            f"{where(name, 'BRDF')}: BRDF(wo={wo.round(3)}, wi={wi.round(3)}) = {value.round(6)}, "
            f"expected {expected.round(6)} = kd * albedo / pi + ks * the highlight. {mistakes}"
        )


@points(3, task="08.1")
def test_phong_brdf(probe):
    """Phong.BRDF: kd albedo / pi + ks (n + 2) / (2 pi) max(0, r . wo)^n"""
    lobe_check(
        probe,
        "phong",
        "Check r = reflect(-wi, normal) (wi points away from the surface, reflect wants "
        "the direction toward it), the normalisation (n + 2) / (2 pi) and the 1 / pi of "
        "the diffuse part.",
    )


@points(3, task="08.2")
def test_blinn_phong_brdf(probe):
    """BlinnPhong.BRDF: kd albedo / pi + ks (n + 8) / (8 pi) (normal . h)^n"""
    lobe_check(
        probe,
        "blinn_phong",
        "Check that h is the unit half vector halfvector(wo, wi) with wo = -ray_view.direction, "
        "and the normalisation (n + 8) / (8 pi).",
    )


@points(2, task="08.3")
@pytest.mark.parametrize("name", ["cook_torrance_ggx", "cook_torrance_beckmann"])
def test_cook_torrance_brdf(name, probe):
    """CookTorrance.BRDF: kd albedo / pi + ks D G F / (4 cos_i cos_o)"""
    lobe_check(
        probe,
        name,
        "Check D(h) at the unit half vector, G = G1(wi) G1(wo), F = self.F(wo . h) and "
        "the 4 cos_i cos_o below.",
    )


PDF_MISTAKES = {
    "phong": "the highlight's density is (n + 1) / (2 pi) max(0, m . wi)^n around the mirror "
    "direction m = reflect(ray_view.direction, normal) (not around the normal, and (n + 1), "
    "not the BRDF's (n + 2))",
    "blinn_phong": "the highlight's density is the half vector's, (n + 1) / (2 pi) "
    "(normal . h)^n, times the Jacobian 1 / (4 wo . h) of the reflection about h",
    "cook_torrance_ggx": "the highlight's density is D(h) cos(theta_h) / (4 wo . h): the "
    "half vector's density D cos and the Jacobian of the reflection",
}
PDF_MISTAKES["cook_torrance_beckmann"] = PDF_MISTAKES["cook_torrance_ggx"]
PDF_MISTAKES["ward"] = (
    "the highlight's density is the half vector's, half_vector_pdf(hit.frame, h), times the "
    "Jacobian 1 / (4 wo . h) of the reflection about h"
)
WARD_MAX_EXPONENT = 700.0  # Ward's half_vector_pdf is 0 beyond this slope exponent


def ward_half_vector_pdf(m, h):
    """Ward.half_vector_pdf (given code) in the test setup's frame (u = x, v = y, w = z):
    exp(-(hx^2 / ax^2 + hy^2 / ay^2) / hz^2) / (pi ax ay hz^3)."""
    exponent = ((h[0] / m["ax"]) ** 2 + (h[1] / m["ay"]) ** 2) / h[2] ** 2
    if h[2] <= 0 or exponent > WARD_MAX_EXPONENT:
        return 0.0
    return math.exp(-exponent) / (math.pi * m["ax"] * m["ay"] * h[2] ** 3)


def highlight_pdf(name, m, wo, wi):
    if name == "phong":
        n = m["exponent"]
        return (n + 1) / (2 * math.pi) * max(0.0, mirror(wo) @ wi) ** n
    h = unit_half(wo, wi)
    if name == "blinn_phong":
        n = m["exponent"]
        return (n + 1) / (2 * math.pi) * h[2] ** n / (4 * (wo @ h))
    if name == "ward":
        return ward_half_vector_pdf(m, h) / (4 * (wo @ h))
    return ct_D(m, h) * h[2] / (4 * (wo @ h))


@pytest.mark.parametrize("name", by_model(2))
def test_pdf(name, probe):
    """pdf() = p_d cos / pi + (1 - p_d) (the highlight's density)"""
    m = parameters(MODELS[name].spec)
    diffuse = m["kd"] * m["albedo"].max()
    p_d = diffuse / (diffuse + m["ks"])
    pairs = random_pairs(60, seed=9)
    wo, wi = (np.array(side) for side in zip(*pairs, strict=True))
    got = material(probe, name).pdf(wo, wi)
    for (wo, wi), value in zip(pairs, got, strict=True):
        expected = p_d * wi[2] / math.pi + (1 - p_d) * highlight_pdf(name, m, wo, wi)
        assert math.isclose(value, expected, rel_tol=1e-6, abs_tol=1e-12), (
            f"{where(name, 'pdf')}(wo={wo.round(3)}, wi={wi.round(3)}) = {value:.6g}, expected "
            f"{expected:.6g}: the mixture p_d cos(theta_i) / pi + (1 - p_d) (the highlight's "
            f"density), p_d = kd max(albedo) / (kd max(albedo) + ks) = {p_d:.4g} "
            f"(mixture_pdf in rtpy/materials/glossy.py); {PDF_MISTAKES[name]}"
        )


@pytest.mark.parametrize("name", by_model(2, cook_torrance=1))
def test_sampling_follows_pdf(name, probe):
    """scattering() draws directions with density pdf() (chi-square)"""
    subject = material(probe, name)
    alpha = rt.sidak_alpha(0.01, len(MODELS) * len(ANGLES))
    for theta in ANGLES:
        result = rt.chi2_test(subject, theta, n_samples=10_000, theta_bins=8, phi_bins=16, seed=8)
        assert result.passed(alpha), (
            f"{where(name, 'scattering')} at {theta} degrees draws directions that do not follow "
            f"pdf() (p = {result.p_value:.2g}): {result.summary()}. Check the lobe sampling and "
            "its density (a half-vector density needs the Jacobian 1 / (4 wo . h))"
        )


@pytest.mark.parametrize("name", by_model(2, cook_torrance=1))
def test_weight_is_brdf_cos_over_pdf(name, probe):
    """scattering() weight = BRDF * cos / pdf"""
    subject = material(probe, name)
    for theta in ANGLES:
        result = rt.check_weights(subject, theta, n=200, seed=8)
        assert result.passed, (
            f"{where(name, 'scattering')} at {theta} degrees: the attenuation must be "
            "BRDF * cos(theta_i) / pdf of the lobe mixture (weighted_sample in "
            f"rtpy/materials/glossy.py): {result.detail}"
        )


@pytest.mark.parametrize("name", by_model(1, extension=False))
def test_energy_and_reciprocity(name, probe):
    """albedo <= 1 and BRDF(wo, wi) = BRDF(wi, wo)"""
    subject = material(probe, name)
    result = rt.check_reciprocity(subject, n_pairs=200, seed=8)
    assert result.passed, f"{where(name, 'BRDF')} is not reciprocal: {result.detail}"
    for theta in ANGLES:
        result = rt.check_energy(subject, theta, n_samples=10_000, seed=8)
        assert result.passed, f"{where(name, 'BRDF')} at {theta} degrees: {result.detail}"


# The graded render: R seeds at SPP samples per pixel of the scene week08_glossy_balls
# (probes.py), against the reference (rendered by rtpy's solution with REFERENCE_SEEDS
# at REFERENCE_SPP).
RENDER = {"integrator": "path", "spp": 8, "max_depth": 5}
SEEDS = (1, 2, 3, 4)
REFERENCE = {"name": "path_three_balls", "seeds": tuple(range(100, 108)), "spp": 64}
SCENE = "week08_glossy_balls"


def make_reference_summary(probe):
    return reference_summary(probe, SCENE, RENDER, REFERENCE)


@points(4, task="08.4")
def test_path_render_matches_reference(probe):
    """path integrator: three glossy balls under a quad light match the reference"""
    assert_renders_match(
        probe,
        SCENE,
        SEEDS,
        RENDER,
        HERE / "reference" / f"{REFERENCE['name']}.npz",
        "path integrator (rtpy/integrators/path.py) with the week's materials differs from "
        "the reference beyond its noise. Too bright: light counted twice (MIS weight of "
        "emission found by a bounce) or a weight without 1/pdf; too dark: Russian roulette "
        "without dividing by the survival probability, or a lobe that loses energy",
    )


FURNACE = {"integrator": "path", "spp": 8, "max_depth": 100, "russian_roulette": 3}


@points(4, task="08.4")
def test_path_furnace(probe):
    """path integrator: inside a glowing sphere L = Le / (1 - albedo)"""
    rho, le = 0.5, 0.5
    params = {
        "material": {"type": "GlowingDiffuse", "rho": rho, "le": [le, le, le]},
        "eye": [0.2, 0.1, -0.3],
        "look_at": [0.0, 0.0, -1.0],
    }
    stack = probe.render(scene="week08_furnace", params=params, seeds=[1, 2], settings=FURNACE)
    values = stack[..., 0].ravel()
    mean, se = values.mean(), values.std(ddof=1) / math.sqrt(values.size)
    z = (mean - le / (1 - rho)) / se
    assert values.size == 2 * 8 * 8 and np.isfinite(values).all() and abs(z) < 4.5, (
        f"PathIntegrator.compute_scattering (rtpy/integrators/path.py): inside a closed sphere of albedo "
        f"{rho} emitting {le}, every pixel must converge to Le / (1 - albedo) = "
        f"{le / (1 - rho):g}; got {mean:.4f} +- {se:.4f} (z = {z:.1f}). Too low: Russian "
        "roulette survivors not divided by their survival probability, or paths cut short; "
        "too high: emission counted twice (light sampling plus the bounce that hits it)"
    )
