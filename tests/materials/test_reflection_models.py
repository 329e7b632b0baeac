"""Every reflection model over a grid of parameters and incident angles, checked
the way Mitsuba 3's chi2 tool and pbrt-v4's bsdfs_test check theirs.

For each grid point, 75,000 directions drawn by scattering() are binned on the
sphere and compared with pdf() integrated over each bin (rtpy.testing.chi2_test);
the same samples check that every weight is BRDF * cos / pdf and that the
directional albedo by sampling agrees with a quadrature of BRDF * cos and stays
below the model's bound. The chi-square tests of the whole grid are one family:
each rejects at the Sidak-corrected level, so that a correct implementation of
every model fails somewhere in the grid with probability 0.01.

The tests at the end plant the classic sampling mistakes in real models and
show that the same test at the same level rejects them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest

from rtpy.materials import BlinnPhong, CookTorrance, OrenNayar, Phong, Ward
from rtpy.testing import (
    check_energy,
    check_non_negative_finite,
    check_reciprocity,
    check_weights,
    chi2_test,
    draw_samples,
    sidak_alpha,
)
from rtpy.vec3 import Color, dot, halfvector

from ..cores import module_outcomes, outcome

ALBEDO = Color(0.9, 0.6, 0.3)
ANGLES = (0.0, 45.0, 80.0, 89.9)
N_SAMPLES = 75_000  # rejects a pdf exponent 5% off at p < 1e-12 (planted below)
FAMILY_ALPHA = 0.01

# name -> (constructor, keyword arguments, incident azimuth in degrees)
# The cosine-power lobes, Phong's and Blinn-Phong's: (label, kd, ks, exponent).
EXPONENTS = [
    ("n=1", 0.0, 1.0, 1.0),
    ("n=10 mix", 0.5, 0.5, 10.0),
    ("n=100", 0.0, 1.0, 100.0),
    ("n=1000 mix", 0.3, 0.7, 1000.0),
    ("n=1e4", 0.0, 1.0, 1e4),
]
MODELS: dict[str, tuple[type, dict, float]] = {
    **{
        f"{model} {label}": (cls, dict(kd=kd, ks=ks, exponent=n), 0.0)
        for model, cls in (("phong", Phong), ("blinn", BlinnPhong))
        for label, kd, ks, n in EXPONENTS
    },
    "ggx a=0.01": (CookTorrance, dict(kd=0.0, ks=1.0, roughness=0.01), 0.0),
    "ggx a=0.1 mix": (CookTorrance, dict(kd=0.5, ks=0.5, roughness=0.1), 0.0),
    "ggx a=0.5 f0": (
        CookTorrance,
        dict(kd=0.0, ks=1.0, roughness=0.5, f0=Color(1.0, 0.78, 0.34)),
        0.0,
    ),
    "ggx a=1 mix": (CookTorrance, dict(kd=0.2, ks=0.8, roughness=1.0), 0.0),
    "beckmann a=0.01": (
        CookTorrance,
        dict(kd=0.0, ks=1.0, roughness=0.01, distribution="beckmann"),
        0.0,
    ),
    "beckmann a=0.2 mix": (
        CookTorrance,
        dict(kd=0.5, ks=0.5, roughness=0.2, distribution="beckmann"),
        0.0,
    ),
    "beckmann a=1": (
        CookTorrance,
        dict(kd=0.0, ks=1.0, roughness=1.0, distribution="beckmann"),
        0.0,
    ),
    "ward a=0.01": (Ward, dict(kd=0.0, ks=1.0, alpha_x=0.01), 0.0),
    "ward 0.05x0.4 mix": (Ward, dict(kd=0.5, ks=0.5, alpha_x=0.05, alpha_y=0.4), 30.0),
    "ward a=0.2": (Ward, dict(kd=0.0, ks=1.0, alpha_x=0.2), 0.0),
    "ward 1x0.1 mix": (Ward, dict(kd=0.3, ks=0.7, alpha_x=1.0, alpha_y=0.1), 60.0),
    "oren-nayar 0": (OrenNayar, dict(sigma=0.0), 0.0),
    "oren-nayar 20": (OrenNayar, dict(sigma=20.0), 0.0),
    "oren-nayar 60": (OrenNayar, dict(sigma=60.0), 0.0),
}

CASES = [(name, angle) for name in MODELS for angle in ANGLES]
ALPHA = sidak_alpha(FAMILY_ALPHA, len(CASES))


def make(name: str):
    cls, kwargs, _ = MODELS[name]
    return cls(albedo=ALBEDO, **kwargs)


def albedo_bound(name: str, angle: float) -> float | None:
    """The most light the model may reflect, as its docstring states; None where
    the model promises no bound at that angle."""
    cls, kwargs, _ = MODELS[name]
    diffuse = kwargs.get("kd", 1.0) * max(ALBEDO.e0, ALBEDO.e1, ALBEDO.e2)
    ks = kwargs.get("ks", 0.0)
    if cls is BlinnPhong:  # (n + 8) / (8 pi) overshoots by up to 7.5 % (n near 10)
        return diffuse + 1.076 * ks
    if cls is OrenNayar:  # the qualitative model exceeds the albedo by up to 1.5 %
        return 1.015 * diffuse
    if cls is Ward and angle > 89.0:  # 1 / sqrt(cos theta_o) grows without bound
        return None
    return diffuse + ks


@dataclass
class Outcome:
    chi2_p: float
    chi2_summary: str
    weights: bool
    weights_detail: str
    energy: bool
    energy_skipped: bool
    energy_detail: str


def run_case(case: tuple[str, float]) -> Outcome:
    name, angle = case
    material = make(name)
    phi = MODELS[name][2]
    seed = CASES.index(case)  # independent samples for every test of the family
    samples = draw_samples(material, angle, N_SAMPLES, seed=seed, phi_deg=phi)
    chi2 = chi2_test(material, angle, samples=samples, seed=seed, phi_deg=phi)
    weights = check_weights(material, angle, samples=samples, seed=seed, phi_deg=phi)
    bound = albedo_bound(name, angle)
    energy = check_energy(
        material,
        angle,
        alpha=ALPHA,
        max_albedo=math.inf if bound is None else bound,
        samples=samples,
        seed=seed,
        phi_deg=phi,
    )
    return Outcome(
        chi2.p_value,
        chi2.summary(),
        weights.passed,
        weights.detail,
        energy.passed,
        energy.skipped,
        energy.detail,
    )


# The grid's tests share each case's one run of run_case, on every core.
outcomes = module_outcomes(
    {
        "test_sampling_follows_pdf": run_case,
        "test_weight_is_brdf_cos_over_pdf": run_case,
        "test_albedo_by_sampling_and_quadrature_agree_and_is_bounded": run_case,
    }
)


def case_id(case: tuple[str, float]) -> str:
    return f"{case[0]} @{case[1]:g}deg"


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_sampling_follows_pdf(outcomes, request, case):
    o = outcome(outcomes, request)
    assert o.chi2_p >= ALPHA, f"p = {o.chi2_p:.3g} < {ALPHA:.3g}: {o.chi2_summary}"


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_weight_is_brdf_cos_over_pdf(outcomes, request, case):
    o = outcome(outcomes, request)
    assert o.weights, o.weights_detail


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_albedo_by_sampling_and_quadrature_agree_and_is_bounded(outcomes, request, case):
    o = outcome(outcomes, request)
    assert o.energy, o.energy_detail
    assert not o.energy_skipped, o.energy_detail


@pytest.mark.parametrize("name", list(MODELS))
def test_reciprocal_finite_and_non_negative(name):
    material = make(name)
    assert check_reciprocity(material, n_pairs=500)
    assert check_non_negative_finite(material, n=200)


def test_the_family_level_is_sidak_corrected():
    assert len(CASES) == len(MODELS) * len(ANGLES) >= 90
    assert 1.0 - (1.0 - ALPHA) ** len(CASES) == pytest.approx(FAMILY_ALPHA, rel=1e-9)


# --- planted mistakes: the same test, at the same level, rejects them --------------------


# With kd = 0 (as below) pdf() is the highlight's density alone.


class PhongPdfWithLobeNormalisation(Phong):
    """The sampling pdf normalised like the BRDF, (n + 2) / (2 pi) instead of (n + 1)."""

    def pdf(self, ray_view, ray_light, hit):
        n = self.exponent
        return super().pdf(ray_view, ray_light, hit) * (n + 2.0) / (n + 1.0)


class PhongPdfExponentOff(Phong):
    """pdf() of an exponent 5% above the one scattering() samples: a subtle mistake,
    the size of the grid's resolving power at N_SAMPLES."""

    def pdf(self, ray_view, ray_light, hit):
        n = self.exponent
        self.exponent = 1.05 * n
        try:
            return super().pdf(ray_view, ray_light, hit)
        finally:
            self.exponent = n


def half_vector_cosines(ray_view, ray_light, hit) -> tuple[float, float]:
    """(wo . h, normal . h) with h the half vector of the viewer and the light."""
    wo = -ray_view.direction
    h = halfvector(wo, ray_light.direction)
    return dot(wo, h), dot(hit.normal, h)


class BlinnWithoutJacobian(BlinnPhong):
    """The half vector's density used as the density of wi (no 1 / (4 wo.h))."""

    def pdf(self, ray_view, ray_light, hit):
        p = super().pdf(ray_view, ray_light, hit)
        return p * 4.0 * half_vector_cosines(ray_view, ray_light, hit)[0] if p > 0.0 else 0.0


class GGXSampledWithoutCosine(CookTorrance):
    """pdf() claims D(h) / (4 wo.h), forgetting the cos(theta_h) that sampling uses."""

    def pdf(self, ray_view, ray_light, hit):
        p = super().pdf(ray_view, ray_light, hit)
        return p / half_vector_cosines(ray_view, ray_light, hit)[1] if p > 0.0 else 0.0


class WardWithSwappedWidths(Ward):
    """Samples the half vector with alpha_x and alpha_y swapped."""

    def sample_half_vector(self, r1, r2):
        self.ax, self.ay = self.ay, self.ax
        try:
            return super().sample_half_vector(r1, r2)
        finally:
            self.ax, self.ay = self.ay, self.ax


PLANTED = {
    "phong pdf (n+2)": (PhongPdfWithLobeNormalisation(ALBEDO, 0.0, 1.0, 100.0), 30.0, 0.0),
    "phong pdf exponent 5% off": (PhongPdfExponentOff(ALBEDO, 0.0, 1.0, 100.0), 30.0, 0.0),
    "blinn no Jacobian": (BlinnWithoutJacobian(ALBEDO, 0.0, 1.0, 100.0), 30.0, 0.0),
    "ggx pdf without cos": (GGXSampledWithoutCosine(ALBEDO, 0.0, 1.0, 0.5), 45.0, 0.0),
    "ward widths swapped": (WardWithSwappedWidths(ALBEDO, 0.0, 1.0, 0.05, 0.4), 30.0, 30.0),
}


def planted_chi2(name: str) -> tuple[float, str]:
    """The grid's chi-square test on a planted mistake: (p, summary)."""
    material, angle, phi = PLANTED[name]
    r = chi2_test(material, angle, n_samples=N_SAMPLES, phi_deg=phi)
    return r.p_value, r.summary()


planted_outcomes = module_outcomes(
    {"test_the_grid_test_rejects_planted_sampling_mistakes": planted_chi2}
)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(PLANTED))
def test_the_grid_test_rejects_planted_sampling_mistakes(planted_outcomes, request, name):
    p, summary = outcome(planted_outcomes, request)
    assert p < ALPHA, summary
