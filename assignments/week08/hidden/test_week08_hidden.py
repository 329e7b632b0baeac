# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 08 hidden checks: only the autograder holds them (assignments/week08/hidden/
never ships to students). Their inputs come from grading_seed, new for every
submission, so code that is right only for the graders' fixed inputs fails them.

Each reflection model gets new parameters (exponent, roughness, distribution, kd, ks,
albedo) and a new angle of incidence. The models are asked through RemoteMaterial
(the student's process draws and evaluates, the checks run here); the furnace renders
the scene week08_glowing_furnace of probes.py.

Each model's checks are cases of their own (one point each), so a stub costs only its
own model's points. The checks and their reference models are the visible graders'
(test_week08.py: sampling_problem, weight_problem, furnace_problem).

False failures: the weight check (BRDF * cos / pdf, rtpy.testing.check_weights, and
the model's own BRDF * cos / pdf) is exact up to rounding and never fails a correct
model. The sampling check is a chi-square test per model, Sidak-corrected so that the
three together fail a correct submission with probability ALPHA (the parameter ranges
keep every bin's expected count high enough for the chi-square approximation), plus
the share of draws that scatter within 5 binomial standard errors (and 3e-3) of the
model's: 6e-7 per model. The furnace compares the mean of PIXELS pixel values, each
the mean of 8 paths, with Le / (1 - albedo) at |z| < 4.5, the standard error from a
correct path tracer's spread at that albedo (the larger of the two tabulated albedos
around it, reference/furnace_spread.npz): a two-sided normal tail of 7e-6 at most; and
it fails pixels spreading more than twice as much as a correct path tracer's (over
40 runs the largest ratio was 1.22). Together: below 2e-4 per submission.
"""

from pathlib import Path

import pytest

import rtpy.testing as rt
from rtpy.grading import points
from rtpy.grading.autograder_seed import grading_rng, grading_seed
from rtpy.grading.remote_material import RemoteMaterial

HERE = Path(__file__).parent
ALPHA = 1e-4
FILES = {
    "Phong": "rtpy/materials/phong.py",
    "BlinnPhong": "rtpy/materials/blinn_phong.py",
    "CookTorrance": "rtpy/materials/cook_torrance.py",
}


def new_models(rng) -> list[dict]:
    """The specs of one Phong, Blinn-Phong and Cook-Torrance material with new
    parameters (rtpy.grading.probes.make_material)."""
    albedo = [float(x) for x in rng.uniform(0.2, 0.9, 3)]
    kd = float(rng.uniform(0.2, 0.6))
    ks = float(rng.uniform(0.2, 0.9 - kd * max(albedo)))
    common = {"albedo": albedo, "kd": kd, "ks": ks}
    return [
        {"type": "Phong", **common, "exponent": float(rng.uniform(5, 60))},
        {"type": "BlinnPhong", **common, "exponent": float(rng.uniform(20, 200))},
        {
            "type": "CookTorrance",
            **common,
            "roughness": float(rng.uniform(0.15, 0.6)),
            "distribution": str(rng.choice(["ggx", "beckmann"])),
        },
    ]


def described(spec: dict) -> str:
    name = spec["type"]
    params = ", ".join(
        f"{k}={spec[k]:.3g}" if isinstance(spec[k], float) else f"{k}={spec[k]}"
        for k in ("kd", "ks", "exponent", "roughness", "distribution")
        if k in spec
    )
    return f"{name}({params}) ({FILES[name]})"


def visible_graders():
    """test_week08.py beside this folder (its reference models and checks), loaded once."""
    import importlib.util
    import sys

    name = "rtpy_week08_visible_graders"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, HERE.parent / "test_week08.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


# One case per model, each toward the model's own task: a stub costs only its points.
NAMES = {"Phong": "phong", "BlinnPhong": "blinn_phong", "CookTorrance": "cook_torrance_ggx"}
BY_MODEL = [pytest.param(k, id=type_name) for k, type_name in enumerate(NAMES)]


def new_model(rng, k: int) -> tuple[str, dict]:
    """The visible graders' name of model k of new_models(rng) and its spec."""
    spec = new_models(rng)[k]
    return NAMES[spec["type"]], spec


@points(1)
@pytest.mark.parametrize("k", BY_MODEL)
def test_sampling_follows_pdf_at_new_parameters(k, probe):
    """scattering() draws directions with density pdf(), new parameters (chi-square)"""
    rng = grading_rng(801)
    name, spec = new_model(rng, k)
    thetas = rng.uniform(10, 70, len(NAMES))  # one angle per model
    alpha = rt.sidak_alpha(ALPHA, len(NAMES))
    problem = visible_graders().sampling_problem(
        RemoteMaterial(probe, spec),
        name,
        spec,
        float(thetas[k]),
        alpha,
        grading_seed(810 + k),
        f"{described(spec)}.scattering",
        picture=False,
    )
    assert not problem, problem


@points(1)
@pytest.mark.parametrize("k", BY_MODEL)
def test_weight_is_brdf_cos_over_pdf_at_new_parameters(k, probe):
    """scattering() weight = BRDF * cos / pdf, new parameters"""
    rng = grading_rng(802)
    name, spec = new_model(rng, k)
    theta = float(rng.uniform(5, 80, len(NAMES))[k])
    subject = RemoteMaterial(probe, spec)
    problem = visible_graders().weight_problem(
        subject, name, spec, theta, 300, grading_seed(820 + k), f"{described(spec)}.scattering"
    )
    assert not problem, problem
    result = rt.check_reciprocity(subject, n_pairs=300, seed=grading_seed(830 + k))
    assert result.passed, f"{described(spec)}.BRDF is not reciprocal: {result.detail}"


PIXELS = 2 * 8 * 8
FURNACE = {"integrator": "path", "spp": 8, "max_depth": 100, "russian_roulette": 3}


@points(2)
def test_path_furnace_at_new_seeds(probe):
    """path integrator: inside a glowing sphere L = Le / (1 - albedo), new seeds"""
    rng = grading_rng(803)
    rho, le = float(rng.uniform(0.3, 0.6)), float(rng.uniform(0.2, 1.0))
    eye = rng.uniform(-0.5, 0.5, 3)
    params = {
        "albedo": [rho] * 3,
        "emit": [le] * 3,
        "eye": eye,
        "look_at": eye + rng.normal(size=3),
    }
    seeds = [grading_seed(840), grading_seed(841)]
    stack = probe.render(
        scene="week08_glowing_furnace", params=params, seeds=seeds, settings=FURNACE
    )
    values = stack[..., 0].ravel()
    assert values.size == PIXELS, f"the furnace has {values.size} pixel values, expected {PIXELS}"
    graders = visible_graders()
    problem = graders.furnace_problem(
        values,
        rho,
        le,
        graders.furnace_spread(rho, le),
        "PathIntegrator.compute_scattering (rtpy/integrators/path.py)",
    )
    assert not problem, problem
