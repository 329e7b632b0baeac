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

import functools
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
    scene_uses,
)
from rtpy.grading.graders import chi2_picture_note
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


# --- the lobes of the BRDFs ------------------------------------------------------------
# m: the parameters of a model (parameters(spec)); wo, wi: local unit directions, one
# per row (arrays (N, 3), or one direction (3,)), above the surface.


def dots(a, b):
    return np.einsum("...i,...i->...", a, b)


def unit_half(wo, wi):
    h = wo + wi
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


def mirror(wo):
    """wo mirrored about the normal (0, 0, 1)."""
    return wo * np.array([-1.0, -1.0, 1.0])


def phong_lobe(m, wo, wi):
    r = mirror(wi)  # reflect(-wi, normal)
    n = m["exponent"]
    return (n + 2) / (2 * math.pi) * np.maximum(0.0, dots(r, wo)) ** n


def blinn_lobe(m, wo, wi):
    h = unit_half(wo, wi)
    n = m["exponent"]
    return (n + 8) / (8 * math.pi) * np.maximum(0.0, h[..., 2]) ** n


def tan2(v):
    return (1 - v[..., 2] ** 2) / v[..., 2] ** 2


def ct_D(m, h):
    a2 = m["alpha"] ** 2
    if m["distribution"] == "ggx":
        return a2 / (math.pi * h[..., 2] ** 4 * (a2 + tan2(h)) ** 2)
    return np.exp(-tan2(h) / a2) / (math.pi * a2 * h[..., 2] ** 4)


ERF = np.vectorize(math.erf, otypes=[float])


def ct_G1(m, v):
    a2 = m["alpha"] ** 2
    if m["distribution"] == "ggx":
        return 2 / (1 + np.sqrt(1 + a2 * tan2(v)))
    with np.errstate(divide="ignore", invalid="ignore"):
        a = 1 / (m["alpha"] * np.sqrt(tan2(v)))
        lam = (ERF(a) - 1) / 2 + np.exp(-a * a) / (2 * a * math.sqrt(math.pi))
    return 1 / (1 + np.where(np.isfinite(a), lam, 0.0))  # at the normal: no masking


def ct_lobe(m, wo, wi):
    h = unit_half(wo, wi)
    f0 = m["f0"]
    f = f0 + (1 - f0) * ((1 - dots(wo, h)) ** 5)[..., None]
    scale = ct_D(m, h) * ct_G1(m, wo) * ct_G1(m, wi) / (4 * wo[..., 2] * wi[..., 2])
    return scale[..., None] * f


LOBES = {
    "phong": phong_lobe,
    "blinn_phong": blinn_lobe,
    "cook_torrance_ggx": ct_lobe,
    "cook_torrance_beckmann": ct_lobe,
}


def reference_brdf(name, m, wo, wi):
    """The model's BRDF, kd albedo / pi + ks (its lobe), per channel (..., 3)."""
    lobe = LOBES[name](m, wo, wi)
    if np.ndim(lobe) < np.ndim(wi):
        lobe = lobe[..., None]
    return m["kd"] * m["albedo"] / math.pi + m["ks"] * lobe


def lobe_check(probe, name, mistakes):
    m = parameters(MODELS[name].spec)
    pairs = random_pairs(60, seed=8)
    wo, wi = (np.array(side) for side in zip(*pairs, strict=True))
    got = material(probe, name).brdf(wo, wi)
    for (wo, wi), value in zip(pairs, got, strict=True):
        expected = reference_brdf(name, m, wo, wi)
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
    hz = h[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        exponent = ((h[..., 0] / m["ax"]) ** 2 + (h[..., 1] / m["ay"]) ** 2) / hz**2
        value = np.exp(-exponent) / (math.pi * m["ax"] * m["ay"] * hz**3)
    return np.where((hz > 0) & (exponent <= WARD_MAX_EXPONENT), value, 0.0)


def highlight_pdf(name, m, wo, wi):
    if name == "phong":
        n = m["exponent"]
        return (n + 1) / (2 * math.pi) * np.maximum(0.0, dots(mirror(wo), wi)) ** n
    h = unit_half(wo, wi)
    if name == "blinn_phong":
        n = m["exponent"]
        return (n + 1) / (2 * math.pi) * h[..., 2] ** n / (4 * dots(wo, h))
    if name == "ward":
        return ward_half_vector_pdf(m, h) / (4 * dots(wo, h))
    return ct_D(m, h) * h[..., 2] / (4 * dots(wo, h))


def diffuse_share(m):
    """p_d = kd max(albedo) / (kd max(albedo) + ks): how often the diffuse lobe draws."""
    diffuse = m["kd"] * m["albedo"].max()
    return diffuse / (diffuse + m["ks"])


def reference_pdf(name, m, wo, wi):
    """The model's pdf(): the mixture p_d cos / pi + (1 - p_d) (the highlight's)."""
    p_d = diffuse_share(m)
    return p_d * wi[..., 2] / math.pi + (1 - p_d) * highlight_pdf(name, m, wo, wi)


GRID = 600  # nodes per axis of the quadrature over the hemisphere (cos theta, phi)


@functools.cache
def _hemisphere(name, spec_items, theta):
    spec = dict(spec_items)
    spec["albedo"] = list(spec["albedo"])
    m = parameters(spec)
    mu = (np.arange(GRID) + 0.5) / GRID
    phi = (np.arange(GRID) + 0.5) / GRID * 2 * math.pi
    mu, phi = (a.ravel() for a in np.meshgrid(mu, phi))
    s = np.sqrt(1 - mu * mu)
    wi = np.column_stack([s * np.cos(phi), s * np.sin(phi), mu])
    wo = np.broadcast_to(rt.local_direction(theta).tolist(), wi.shape)
    area = 2 * math.pi / GRID**2  # d(cos theta) d(phi) of a node
    scattered = float(reference_pdf(name, m, wo, wi).sum() * area)
    albedo = None
    if name in LOBES:
        albedo = (reference_brdf(name, m, wo, wi) * mu[:, None]).sum(axis=0) * area
    return scattered, albedo


def reference_integrals(name, spec, theta):
    """(the share of draws the model scatters, its directional albedo per channel)
    with the viewer at theta degrees: integrals over the upper hemisphere of pdf()
    and of BRDF * cos, by the midpoint rule on a GRID x GRID grid in (cos theta,
    phi), good to ~1e-4 for the graded lobes. The albedo is None for Ward (its
    BRDF is given code, not graded)."""
    items = tuple(sorted((k, tuple(v) if isinstance(v, list) else v) for k, v in spec.items()))
    return _hemisphere(name, items, float(theta))


@pytest.mark.parametrize("name", by_model(2))
def test_pdf(name, probe):
    """pdf() = p_d cos / pi + (1 - p_d) (the highlight's density)"""
    m = parameters(MODELS[name].spec)
    p_d = diffuse_share(m)
    pairs = random_pairs(60, seed=9)
    wo, wi = (np.array(side) for side in zip(*pairs, strict=True))
    got = material(probe, name).pdf(wo, wi)
    for (wo, wi), value in zip(pairs, got, strict=True):
        expected = float(reference_pdf(name, m, wo, wi))
        assert math.isclose(value, expected, rel_tol=1e-6, abs_tol=1e-12), (
            f"{where(name, 'pdf')}(wo={wo.round(3)}, wi={wi.round(3)}) = {value:.6g}, expected "
            f"{expected:.6g}: the mixture p_d cos(theta_i) / pi + (1 - p_d) (the highlight's "
            f"density), p_d = kd max(albedo) / (kd max(albedo) + ks) = {p_d:.4g} "
            f"(mixture_pdf in rtpy/materials/glossy.py); {PDF_MISTAKES[name]}"
        )


def scatters_as_the_reference(result, name, spec, theta, what):
    """ "" if the share of draws that scattered (result: a Chi2Result) agrees with the
    model's (reference_integrals) within 5 binomial standard errors and the
    quadrature's 3e-3, else why not: a check of sampling needs samples, as many as
    the model makes."""
    expected, _ = reference_integrals(name, spec, theta)
    n = result.n_samples
    got = (n - result.n_absorbed - result.n_specular) / n
    allowed = 5 * math.sqrt(max(expected * (1 - expected), 0.0) / n) + 3e-3
    if abs(got - expected) <= allowed:
        return ""
    return (
        f"{what} returned a direction for {got:.1%} of {n} draws, the model for "
        f"{expected:.1%} (only a highlight direction below the surface is absorbed): "
        "scattering() must return a ScatterInfo for every direction it draws above the "
        "surface, and pdf() must integrate to that share"
    )


SAMPLING_HINTS = {
    "phong": "draw the highlight with sample_cosine_power around the mirror direction "
    "m = reflect(ray_in.direction, normal), and the diffuse lobe with probability p_d",
    "blinn_phong": "draw a half vector h with sample_cosine_power around the normal and "
    "reflect wo about it; its density needs the Jacobian 1 / (4 wo . h)",
    "cook_torrance_ggx": "draw h with sample_half_vector (density D cos(theta_h)) and reflect "
    "wo about it; its density needs the Jacobian 1 / (4 wo . h)",
    "ward": "draw h with sample_half_vector in hit.frame and reflect wo about it; its "
    "density needs the Jacobian 1 / (4 wo . h)",
}
SAMPLING_HINTS["cook_torrance_beckmann"] = SAMPLING_HINTS["cook_torrance_ggx"]


def sampling_problem(subject, name, spec, theta, alpha, seed, what, picture=True):
    """Nothing ("") if scattering() draws with density pdf() (chi-square at alpha,
    10,000 draws) and scatters as often as the model does, else what is wrong. what:
    Class.method (file) for the message; picture: draw a failed check
    (rtpy.grading.graders.chi2_picture_note), not for checks a student cannot run."""
    result = rt.chi2_test(subject, theta, n_samples=10_000, theta_bins=8, phi_bins=16, seed=seed)
    at = f"{what} at {theta:.3g} degrees"
    if not result.passed(alpha):
        file = f"week08-{spec['type']}-{theta:.3g}deg".replace(".", "_")
        note = chi2_picture_note(result, theta, subject, file, what, "08") if picture else ""
        return (
            f"{at} draws directions that do not follow pdf() (p = {result.p_value:.2g}): "
            f"{result.summary()}. Check the lobe sampling and its density: "
            f"{SAMPLING_HINTS[name]}.{note}"
        )
    return scatters_as_the_reference(result, name, spec, theta, at)


def weight_problem(subject, name, spec, theta, n, seed, what):
    """ "" if every weight of n draws is the draw's BRDF() * cos / pdf() and, for a
    graded model, the model's own BRDF * cos / pdf at that direction, else what is
    wrong (what: Class.method (file) for the message)."""
    samples = subject.draw(theta, n, seed=seed)
    at = f"{what} at {theta:.3g} degrees"
    result = rt.check_weights(subject, theta, n=n, samples=samples)
    if not result.passed:
        return (
            f"{at}: the attenuation must be BRDF * cos(theta_i) / pdf of the lobe mixture "
            f"(weighted_sample in rtpy/materials/glossy.py): {result.detail}"
        )
    if name not in LOBES:
        return ""
    idx = np.flatnonzero(samples.scattered)
    wi = samples.directions[idx]
    wo = np.broadcast_to(rt.local_direction(theta).tolist(), wi.shape)
    m = parameters(spec)
    with np.errstate(divide="ignore", invalid="ignore"):
        pdf = reference_pdf(name, m, wo, wi)
        expected = reference_brdf(name, m, wo, wi) * (wi[:, 2] / pdf)[:, None]
    got = samples.weights[idx]
    bad = (wi[:, 2] <= 0) | ~np.isclose(got, expected, rtol=1e-6, atol=1e-12).all(axis=1)
    if not bad.any():
        return ""
    k = int(np.argmax(bad))
    own_f = subject.brdf(wo[k : k + 1], wi[k : k + 1])[0]
    own_p = subject.pdf(wo[k : k + 1], wi[k : k + 1])[0]
    wrong = [
        method
        for method, own, model in (
            ("BRDF()", own_f, reference_brdf(name, m, wo[k], wi[k])),
            ("pdf()", own_p, pdf[k]),
        )
        if not np.allclose(own, model, rtol=1e-6, atol=1e-12)
    ] or ["BRDF() or pdf()"]
    return (
        f"{at}: {int(bad.sum())} of {len(idx)} weights are not the model's BRDF * cos / pdf, "
        f"e.g. wi = {wi[k].round(4)}: {got[k].round(6)}, the model's {expected[k].round(6)}. "
        f"The weights agree with your own BRDF() and pdf(); your {' and '.join(wrong)} "
        f"{'differ' if len(wrong) > 1 else 'differs'} from the model there: fix that first "
        "(its check above says how)"
    )


def energy_problem(subject, name, spec, theta, seed):
    """ "" if the directional albedo, by quadrature of BRDF() * cos and by the mean
    weight of 10,000 draws of scattering(), is the model's, else what is wrong and
    which method to look at (BRDF() when the quadrature is off, else scattering())."""
    a = rt.directional_albedo(subject, theta, n_samples=10_000, seed=seed)
    _, expected = reference_integrals(name, spec, theta)
    allowance = 10 * a.quadrature_error + 2e-3
    z = rt.normal_quantile(0.01)
    for ch, q, e in zip("RGB", a.quadrature, expected, strict=True):
        if not abs(q - e) <= allowance:
            return (
                f"{where(name, 'BRDF')} at {theta:.3g} degrees: the directional albedo (the "
                f"integral of BRDF * cos over the hemisphere) is {q:.4f} in {ch}, the model's "
                f"{e:.4f}: check BRDF() (its own check above)"
            )
    for ch, s, se, q in zip("RGB", a.sampled, a.standard_error, a.quadrature, strict=True):
        if not abs(s - q) <= z * se + allowance:
            return (
                f"{where(name, 'scattering')} at {theta:.3g} degrees: the mean weight of its "
                f"draws, {s:.4f} +- {se:.4f} in {ch}, is not the albedo {q:.4f} of BRDF() * cos "
                "(BRDF() is the model's): the directions drawn or their weights are off "
                "(a direction returned too often, or absorbed where it should not be)"
            )
    return ""


@pytest.mark.parametrize("name", by_model(2, cook_torrance=1))
def test_sampling_follows_pdf(name, probe):
    """scattering() draws directions with density pdf() (chi-square)"""
    subject = material(probe, name)
    alpha = rt.sidak_alpha(0.01, len(MODELS) * len(ANGLES))
    for theta in ANGLES:
        problem = sampling_problem(
            subject, name, MODELS[name].spec, theta, alpha, 8, where(name, "scattering")
        )
        assert not problem, problem


@pytest.mark.parametrize("name", by_model(2, cook_torrance=1))
def test_weight_is_brdf_cos_over_pdf(name, probe):
    """scattering() weight = BRDF * cos / pdf"""
    subject = material(probe, name)
    for theta in ANGLES:
        problem = weight_problem(
            subject, name, MODELS[name].spec, theta, 200, 8, where(name, "scattering")
        )
        assert not problem, problem


@pytest.mark.parametrize("name", by_model(1, extension=False))
def test_energy_and_reciprocity(name, probe):
    """the model's albedo, and BRDF(wo, wi) = BRDF(wi, wo)"""
    subject = material(probe, name)
    result = rt.check_reciprocity(subject, n_pairs=200, seed=8)
    assert result.passed, f"{where(name, 'BRDF')} is not reciprocal: {result.detail}"
    for theta in ANGLES:
        problem = energy_problem(subject, name, MODELS[name].spec, theta, 8)
        assert not problem, problem


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
@scene_uses("08.1", "08.2", "08.3")
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
FURNACE_PARAMS = {
    "material": {"type": "GlowingDiffuse", "rho": 0.5, "le": [0.5, 0.5, 0.5]},
    "eye": [0.2, 0.1, -0.3],
    "look_at": [0.0, 0.0, -1.0],
}
# The spread of a correct path tracer's furnace pixels (each the mean of FURNACE's spp
# paths), measured once with rtpy's solution (make_furnace_spread, written by
# scripts/make_assignment_references.py): the visible furnace's, and per unit Le for
# the glowing furnace at the albedos SPREAD_RHOS (the pixels' distribution does not
# depend on where the camera is inside the sphere, only on the albedo).
SPREAD = {"name": "furnace_spread", "seeds": tuple(range(200, 264))}
SPREAD_RHOS = (0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65)
NOISE_RATIO = 2.0  # the largest spread of the pixels allowed, times the reference's
FURNACE_Z = 4.5


def make_furnace_spread(probe):
    seeds = list(SPREAD["seeds"])
    stack = probe.render(
        scene="week08_furnace", params=FURNACE_PARAMS, seeds=seeds, settings=FURNACE
    )
    per_le = []
    for rho in SPREAD_RHOS:
        params = {"albedo": [rho] * 3, "emit": [1.0] * 3, "eye": [0, 0, 0], "look_at": [0, 0, -1]}
        glowing = probe.render(
            scene="week08_glowing_furnace", params=params, seeds=seeds, settings=FURNACE
        )
        per_le.append(glowing[..., 0].std(ddof=1))
    return {
        "visible": np.array(stack[..., 0].std(ddof=1)),
        "rho": np.array(SPREAD_RHOS),
        "per_le": np.array(per_le),
    }


MORE_REFERENCES = {SPREAD["name"]: make_furnace_spread}


def furnace_spread(rho=None, le=None):
    """The reference spread of a furnace pixel: the visible furnace's (no arguments),
    else the glowing furnace's at albedo rho and emission le, the larger of the two
    tabulated albedos around rho (the spread grows with the albedo)."""
    table = np.load(HERE / "reference" / f"{SPREAD['name']}.npz")
    if rho is None:
        return float(table["visible"])
    rhos, per_le = table["rho"], table["per_le"]
    if not rhos[0] <= rho <= rhos[-1]:
        raise ValueError(f"rho: {rho} is outside the tabulated albedos {rhos[0]}-{rhos[-1]}")
    k = min(int(np.searchsorted(rhos, rho)), len(rhos) - 1)
    return float(max(per_le[k], per_le[max(k - 1, 0)])) * le


def furnace_problem(values, rho, le, spread, what):
    """ "" if the furnace's pixel values have the mean Le / (1 - rho) and a spread no
    larger than NOISE_RATIO times `spread` (a correct path tracer's), else what is
    wrong. The z-test's standard error is the reference's spread over sqrt(pixels):
    the submission's own noise never widens it."""
    expected = le / (1 - rho)
    if not np.isfinite(values).all():
        return f"{what}: some pixel values are NaN or infinite"
    mean, own = float(values.mean()), float(values.std(ddof=1))
    se = spread / math.sqrt(values.size)
    z = (mean - expected) / se
    scene = (
        f"{what}: inside a closed sphere of albedo {rho:.3g} emitting {le:.3g}, every pixel "
        f"must converge to Le / (1 - albedo) = {expected:.4g}"
    )
    if own > NOISE_RATIO * spread:
        return (
            f"{scene}; the pixel values spread {own:.4g} around their mean {mean:.4g}, a correct "
            f"path tracer's {spread:.4g}: an estimate that is right only on average, with a "
            "weight that is not BRDF * cos / pdf (or a random factor), is too noisy"
        )
    if not abs(z) < FURNACE_Z:
        return (
            f"{scene}; got {mean:.4f} +- {se:.4f} (z = {z:.1f}, the +- from a correct path "
            "tracer's noise). Too low: Russian roulette survivors not divided by their "
            "survival probability, or paths cut short; too high: emission counted twice "
            "(light sampling plus the bounce that hits it)"
        )
    return ""


@points(4, task="08.4")
@scene_uses()  # one glowing diffuse material, given code
def test_path_furnace(probe):
    """path integrator: inside a glowing sphere L = Le / (1 - albedo)"""
    material = FURNACE_PARAMS["material"]
    stack = probe.render(
        scene="week08_furnace", params=FURNACE_PARAMS, seeds=[1, 2], settings=FURNACE
    )
    values = stack[..., 0].ravel()
    assert values.size == 2 * 8 * 8, f"the furnace has {values.size} pixel values, expected 128"
    problem = furnace_problem(
        values,
        material["rho"],
        material["le"][0],
        furnace_spread(),
        "PathIntegrator.compute_scattering (rtpy/integrators/path.py)",
    )
    assert not problem, problem
